//! Measured scattering properties of named media (pbrt-v4
//! `GetMediumScatteringProperties` in `media.cpp`), for homogeneous media's
//! `preset` and the `subsurface` material's `name`.

use crate::spectrum::{RgbColorSpace, RgbUnboundedSpectrum, Spectrum, RGB};

mod subsurface_table;

pub use subsurface_table::{MeasuredMedium, MEASURED_MEDIA};

/// σa and σs (reduced scattering σ's) in mm⁻¹ of a measured medium by name
/// (e.g. `"Skin1"`, `"Wholemilk"`, `"Ketchup"`), as unbounded sRGB spectra.
pub fn get_medium_scattering_properties(name: &str) -> Option<(Spectrum, Spectrum)> {
    let m = MEASURED_MEDIA.iter().find(|m| m.name == name)?;
    let cs = RgbColorSpace::srgb();
    let spec = |c: [f32; 3]| {
        Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, RGB::new(c[0], c[1], c[2])))
    };
    Some((spec(m.sigma_a), spec(m.sigma_prime_s)))
}

/// The names of the measured media, in table order.
pub fn measured_medium_names() -> impl Iterator<Item = &'static str> {
    MEASURED_MEDIA.iter().map(|m| m.name)
}
