//! pbrt-v4's named spectra (`"spectrum eta" "glass-BK7"` and so on):
//! measured metal and glass data and standard illuminants (pbrt-v4
//! `util/spectrum.cpp`, `GetNamedSpectrum`).

use std::sync::{Arc, OnceLock};

use rpbrt_geometry::Float;

use super::spectra::{PiecewiseLinearSpectrum, Spectrum};

#[path = "data/glass.rs"]
mod glass;
#[path = "data/illuminants.rs"]
mod illuminants;
#[path = "data/metals.rs"]
mod metals;

/// Where a named spectrum's samples live.
enum Data {
    /// Interleaved `(nm, value)` pairs.
    Interleaved(&'static [Float]),
    /// Wavelengths and values in separate tables.
    Split(&'static [Float], &'static [Float]),
}

/// A named spectrum: its data and whether to normalise it to unit
/// luminance (illuminants only).
struct Entry {
    name: &'static str,
    data: Data,
    normalize: bool,
}

const fn illum(name: &'static str, data: &'static [Float]) -> Entry {
    Entry {
        name,
        data: Data::Interleaved(data),
        normalize: true,
    }
}

const fn glass(name: &'static str, data: &'static [Float]) -> Entry {
    Entry {
        name,
        data: Data::Interleaved(data),
        normalize: false,
    }
}

const fn metal(name: &'static str, lambda: &'static [Float], v: &'static [Float]) -> Entry {
    Entry {
        name,
        data: Data::Split(lambda, v),
        normalize: false,
    }
}

use metals::{CUZN_LAMBDA, METAL_LAMBDA, MGO_LAMBDA, TIO2_LAMBDA};

const ENTRIES: &[Entry] = &[
    glass("glass-BK7", &glass::BK7),
    glass("glass-BAF10", &glass::BAF10),
    glass("glass-FK51A", &glass::FK51A),
    glass("glass-LASF9", &glass::LASF9),
    glass("glass-F5", &glass::SF5),
    glass("glass-F10", &glass::SF10),
    glass("glass-F11", &glass::SF11),
    metal("metal-Ag-eta", &METAL_LAMBDA, &metals::AG_ETA),
    metal("metal-Ag-k", &METAL_LAMBDA, &metals::AG_K),
    metal("metal-Al-eta", &METAL_LAMBDA, &metals::AL_ETA),
    metal("metal-Al-k", &METAL_LAMBDA, &metals::AL_K),
    metal("metal-Au-eta", &METAL_LAMBDA, &metals::AU_ETA),
    metal("metal-Au-k", &METAL_LAMBDA, &metals::AU_K),
    metal("metal-Cu-eta", &METAL_LAMBDA, &metals::CU_ETA),
    metal("metal-Cu-k", &METAL_LAMBDA, &metals::CU_K),
    metal("metal-CuZn-eta", &CUZN_LAMBDA, &metals::CUZN_ETA),
    metal("metal-CuZn-k", &CUZN_LAMBDA, &metals::CUZN_K),
    metal("metal-MgO-eta", &MGO_LAMBDA, &metals::MGO_ETA),
    metal("metal-MgO-k", &MGO_LAMBDA, &metals::MGO_K),
    metal("metal-TiO2-eta", &TIO2_LAMBDA, &metals::TIO2_ETA),
    metal("metal-TiO2-k", &TIO2_LAMBDA, &metals::TIO2_K),
    illum("stdillum-A", &illuminants::STDILLUM_A),
    illum("stdillum-D50", &illuminants::STDILLUM_D50),
    illum("stdillum-D65", &illuminants::STDILLUM_D65),
    illum("stdillum-F1", &illuminants::STDILLUM_F1),
    illum("stdillum-F2", &illuminants::STDILLUM_F2),
    illum("stdillum-F3", &illuminants::STDILLUM_F3),
    illum("stdillum-F4", &illuminants::STDILLUM_F4),
    illum("stdillum-F5", &illuminants::STDILLUM_F5),
    illum("stdillum-F6", &illuminants::STDILLUM_F6),
    illum("stdillum-F7", &illuminants::STDILLUM_F7),
    illum("stdillum-F8", &illuminants::STDILLUM_F8),
    illum("stdillum-F9", &illuminants::STDILLUM_F9),
    illum("stdillum-F10", &illuminants::STDILLUM_F10),
    illum("stdillum-F11", &illuminants::STDILLUM_F11),
    illum("stdillum-F12", &illuminants::STDILLUM_F12),
    illum("illum-acesD60", &illuminants::ILLUM_ACES_D60),
];

fn all() -> &'static [(&'static str, Spectrum)] {
    static ALL: OnceLock<Vec<(&'static str, Spectrum)>> = OnceLock::new();
    ALL.get_or_init(|| {
        ENTRIES
            .iter()
            .filter_map(|e| {
                let s = match e.data {
                    Data::Interleaved(d) => {
                        PiecewiseLinearSpectrum::from_interleaved(d, e.normalize)
                    }
                    Data::Split(l, v) => {
                        let d: Vec<Float> = l.iter().zip(v).flat_map(|(&a, &b)| [a, b]).collect();
                        PiecewiseLinearSpectrum::from_interleaved(&d, e.normalize)
                    }
                }
                .ok()?;
                Some((e.name, Spectrum::PiecewiseLinear(Arc::new(s))))
            })
            .collect()
    })
}

/// The named spectrum `name`, if pbrt-v4 defines it.
pub fn named_spectrum(name: &str) -> Option<Spectrum> {
    all()
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| s.clone())
}

/// Every named spectrum's name.
pub fn named_spectrum_names() -> impl Iterator<Item = &'static str> {
    ENTRIES.iter().map(|e| e.name)
}
