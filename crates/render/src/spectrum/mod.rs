//! Spectral rendering: sampled spectra and wavelengths, spectral
//! distributions, CIE colour matching, RGB colour spaces and the RGB to
//! spectrum conversion of Jakob and Hanika (pbrt-v4 book sections 4.5 and
//! 4.6; pbrt-v4 `util/spectrum.h`, `util/color.h`, `util/colorspace.h`).

use rpbrt_geometry::Float;

mod color;
mod sampled;

pub use color::{sigmoid, ColorMatrix, RgbSigmoidPolynomial, RGB, XYZ};
pub use sampled::{
    sample_visible_wavelengths, visible_wavelengths_pdf, SampledSpectrum, SampledWavelengths,
};

/// How many wavelengths each path carries.
pub const N_SPECTRUM_SAMPLES: usize = 4;
/// The shortest wavelength rendered, in nm.
pub const LAMBDA_MIN: Float = 360.0;
/// The longest wavelength rendered, in nm.
pub const LAMBDA_MAX: Float = 830.0;
