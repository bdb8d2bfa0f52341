//! A medium of constant density (pbrt-v4 `HomogeneousMedium`; book section
//! 11.4.1): the same absorption, scattering and emission everywhere, one
//! majorant segment per ray.

use super::majorant::HomogeneousMajorantIterator;
use super::{scaled_spectrum, ConcreteMedium, HGPhaseFunction, MediumProperties};
use crate::spectrum::{DenselySampledSpectrum, SampledSpectrum, SampledWavelengths, Spectrum};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::tuple::Point3f;

/// A homogeneous medium: coefficients in inverse scene units.
#[derive(Clone, Debug)]
pub struct HomogeneousMedium {
    sigma_a: DenselySampledSpectrum,
    sigma_s: DenselySampledSpectrum,
    le: DenselySampledSpectrum,
    phase: HGPhaseFunction,
    emissive: bool,
}

impl HomogeneousMedium {
    /// A medium with absorption `sigma_a` and scattering `sigma_s`, both
    /// multiplied by `sigma_scale`, emitting `le × le_scale`, scattering
    /// with Henyey–Greenstein asymmetry `g`.
    pub fn new(
        sigma_a: &Spectrum,
        sigma_s: &Spectrum,
        sigma_scale: Float,
        le: &Spectrum,
        le_scale: Float,
        g: Float,
    ) -> Self {
        let le = scaled_spectrum(le, le_scale);
        HomogeneousMedium {
            sigma_a: scaled_spectrum(sigma_a, sigma_scale),
            sigma_s: scaled_spectrum(sigma_s, sigma_scale),
            emissive: le.max_value() > 0.0,
            le,
            phase: HGPhaseFunction::new(g),
        }
    }

    /// Whether the medium emits light.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        self.emissive
    }
}

impl ConcreteMedium for HomogeneousMedium {
    type Majorants<'a> = HomogeneousMajorantIterator;

    #[inline]
    fn sample_point(&self, _p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        MediumProperties {
            sigma_a: self.sigma_a.sample(lambda),
            sigma_s: self.sigma_s.sample(lambda),
            phase: self.phase,
            le: if self.emissive {
                self.le.sample(lambda)
            } else {
                SampledSpectrum::new(0.0)
            },
        }
    }

    #[inline]
    fn sample_ray(
        &self,
        _ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> HomogeneousMajorantIterator {
        let sigma_t = self.sigma_a.sample(lambda) + self.sigma_s.sample(lambda);
        HomogeneousMajorantIterator::new(0.0, t_max, sigma_t)
    }
}
