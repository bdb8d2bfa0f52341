//! Spectral rendering: sampled spectra and wavelengths, spectral
//! distributions, CIE colour matching, RGB colour spaces and the RGB to
//! spectrum conversion of Jakob and Hanika (pbrt-v4 book sections 4.5 and
//! 4.6; pbrt-v4 `util/spectrum.h`, `util/color.h`, `util/colorspace.h`).

use rpbrt_geometry::Float;

pub mod cie;
mod color;
mod colorspace;
mod named;
mod param;
pub mod rgb2spec_opt;
mod sampled;
mod spectra;
#[cfg(test)]
mod tests;

pub use cie::CIE_Y_INTEGRAL;
pub use color::{sigmoid, ColorMatrix, RgbSigmoidPolynomial, RGB, XYZ};
pub use colorspace::{
    convert_rgb_color_space, RgbColorSpace, RgbToSpectrumTable, RGB_TO_SPECTRUM_RES,
};
pub use named::{named_spectrum, named_spectrum_names};
pub use param::{parse_spectrum_text, read_spectrum_file, spectrum_from_param, SpectrumType};
pub use sampled::{
    sample_visible_wavelengths, visible_wavelengths_pdf, SampledSpectrum, SampledWavelengths,
};
pub use spectra::{
    blackbody, inner_product, spectrum_to_photometric, spectrum_to_xyz, BlackbodySpectrum,
    DenselySampledSpectrum, PiecewiseLinearSpectrum, RgbAlbedoSpectrum, RgbIlluminantSpectrum,
    RgbUnboundedSpectrum, Spectrum,
};

/// How many wavelengths each path carries.
pub const N_SPECTRUM_SAMPLES: usize = 4;
/// The shortest wavelength rendered, in nm.
pub const LAMBDA_MIN: Float = 360.0;
/// The longest wavelength rendered, in nm.
pub const LAMBDA_MAX: Float = 830.0;

/// `lambda.round() as i64` (to the nearest nm, halves away from zero)
/// without a call to the C library's `roundf`, which the x86-64 baseline
/// lacks an instruction for: for 1 ≤ λ < 2^23, λ + ½ is exact or rounds
/// without crossing an integer, so truncating it is the same (checked for
/// every float in that range).
#[inline(always)]
pub(crate) fn round_nm(lambda: Float) -> i64 {
    if (1.0..8_388_608.0).contains(&lambda) {
        (lambda + 0.5) as i64
    } else {
        lambda.round() as i64
    }
}
