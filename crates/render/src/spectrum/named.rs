//! pbrt-v4's named spectra (`"spectrum eta" "glass-BK7"` and so on):
//! measured metal and glass data and standard illuminants (pbrt-v4
//! `util/spectrum.cpp`, `GetNamedSpectrum`).

use std::sync::{Arc, OnceLock};

use rpbrt_geometry::Float;

use super::spectra::{PiecewiseLinearSpectrum, Spectrum};

#[path = "data/illuminants.rs"]
mod illuminants;

/// A named spectrum's source data: interleaved `(nm, value)` pairs and
/// whether to normalise it to unit luminance (illuminants).
struct Entry {
    name: &'static str,
    data: &'static [Float],
    normalize: bool,
}

const fn illum(name: &'static str, data: &'static [Float]) -> Entry {
    Entry {
        name,
        data,
        normalize: true,
    }
}

const ENTRIES: &[Entry] = &[
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
                let s = PiecewiseLinearSpectrum::from_interleaved(e.data, e.normalize).ok()?;
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
