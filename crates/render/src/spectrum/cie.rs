//! CIE 1931 colour matching: the X, Y, Z matching functions and Monte Carlo
//! estimates of tristimulus values from sampled spectra (pbrt-v4 book
//! section 4.6.1).

use std::sync::{Arc, OnceLock};

use rpbrt_geometry::Float;

use super::color::XYZ;
use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::spectra::{DenselySampledSpectrum, Spectrum};
use super::N_SPECTRUM_SAMPLES;

#[path = "data/cie.rs"]
mod table;

pub use table::{CIE_X, CIE_Y, CIE_Z, N_CIE_SAMPLES};

/// `∫ ȳ(λ) dλ` over the tabulated range: the Y of a constant-1 spectrum
/// before normalisation.
pub const CIE_Y_INTEGRAL: Float = 106.856_895;

/// The first tabulated wavelength.
pub const CIE_LAMBDA_START: i32 = 360;

fn dense(table: &'static [f32; N_CIE_SAMPLES]) -> Spectrum {
    Spectrum::DenselySampled(Arc::new(DenselySampledSpectrum::from_values(
        CIE_LAMBDA_START,
        table.to_vec(),
    )))
}

/// The x̄ matching function as a spectrum.
pub fn x() -> &'static Spectrum {
    static S: OnceLock<Spectrum> = OnceLock::new();
    S.get_or_init(|| dense(&CIE_X))
}

/// The ȳ matching function as a spectrum.
pub fn y() -> &'static Spectrum {
    static S: OnceLock<Spectrum> = OnceLock::new();
    S.get_or_init(|| dense(&CIE_Y))
}

/// The z̄ matching function as a spectrum.
pub fn z() -> &'static Spectrum {
    static S: OnceLock<Spectrum> = OnceLock::new();
    S.get_or_init(|| dense(&CIE_Z))
}

/// The table index for `lambda` rounded to the nearest nm, if tabulated.
#[inline]
fn index(lambda: Float) -> Option<usize> {
    let i = super::round_nm(lambda) - CIE_LAMBDA_START as i64;
    (i >= 0 && (i as usize) < N_CIE_SAMPLES).then_some(i as usize)
}

/// `(x̄, ȳ, z̄)` at `lambda` nm (rounded to the nearest nm; zero outside).
#[inline]
pub fn xyz_matching(lambda: Float) -> [Float; 3] {
    match index(lambda) {
        Some(i) => [CIE_X[i], CIE_Y[i], CIE_Z[i]],
        None => [0.0; 3],
    }
}

impl SampledSpectrum {
    /// The Monte Carlo estimate of this spectrum's luminance Y from its
    /// values at `lambda` (each term divided by its sampling density).
    #[inline]
    pub fn y(&self, lambda: &SampledWavelengths) -> Float {
        let mut sum = 0.0;
        for i in 0..N_SPECTRUM_SAMPLES {
            if lambda.pdf[i] != 0.0 {
                let ybar = index(lambda[i]).map_or(0.0, |j| CIE_Y[j]);
                sum += ybar * self[i] / lambda.pdf[i];
            }
        }
        sum / N_SPECTRUM_SAMPLES as Float / CIE_Y_INTEGRAL
    }

    /// The Monte Carlo estimate of this spectrum's XYZ value.
    #[inline]
    pub fn to_xyz(&self, lambda: &SampledWavelengths) -> XYZ {
        let mut sum = [0.0; 3];
        for i in 0..N_SPECTRUM_SAMPLES {
            if lambda.pdf[i] != 0.0 {
                let m = xyz_matching(lambda[i]);
                let w = self[i] / lambda.pdf[i];
                for c in 0..3 {
                    sum[c] += m[c] * w;
                }
            }
        }
        XYZ::from_array(sum) / (N_SPECTRUM_SAMPLES as Float * CIE_Y_INTEGRAL)
    }
}
