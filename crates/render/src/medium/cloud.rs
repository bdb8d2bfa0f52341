//! A procedural cloud (pbrt-v4 `CloudMedium`, the `"cloud"` medium; book
//! section 11.4.2, "Procedurally Defined Media"): sums of Perlin noise,
//! optionally with the lookup point perturbed by the noise's gradient for
//! wisps, thinning with height. The density stays in `[0, 1]`, so the
//! coefficients themselves bound the extinction and one majorant segment
//! covers the ray's stretch inside the bounds.

use super::create::{coefficient, grid_bounds, non_negative, phase_asymmetry};
use super::majorant::HomogeneousMajorantIterator;
use super::{ConcreteMedium, HGPhaseFunction, MediumProperties};
use crate::params::ParamReader;
use crate::spectrum::{DenselySampledSpectrum, SampledSpectrum, SampledWavelengths, Spectrum};
use crate::texture::noise::{dnoise, noise_p};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use rpbrt_parser::Diagnostic;

/// The parts of a [`CloudMedium`].
#[derive(Clone, Debug)]
pub struct CloudMediumParts {
    /// The medium's box, in medium space.
    pub bounds: Bounds3f,
    /// From medium space to rendering space.
    pub render_from_medium: Transform,
    /// Absorption at unit density.
    pub sigma_a: Spectrum,
    /// Scattering at unit density.
    pub sigma_s: Spectrum,
    /// Multiplies `sigma_a` and `sigma_s`.
    pub sigma_scale: Float,
    /// Henyey–Greenstein asymmetry.
    pub g: Float,
    /// Scales the noise before clamping to `[0, 1]`.
    pub density: Float,
    /// How strongly the lookup point is perturbed (0 for none).
    pub wispiness: Float,
    /// Spatial frequency of the noise, in medium-space units.
    pub frequency: Float,
}

/// pbrt-v4's `cloud` medium.
#[derive(Clone, Debug)]
pub struct CloudMedium {
    bounds: Bounds3f,
    medium_from_render: Transform,
    phase: HGPhaseFunction,
    sigma_a: DenselySampledSpectrum,
    sigma_s: DenselySampledSpectrum,
    density: Float,
    wispiness: Float,
    frequency: Float,
}

impl CloudMedium {
    /// The medium of `parts`.
    pub fn new(parts: CloudMediumParts) -> Self {
        let mut sigma_a = DenselySampledSpectrum::new(&parts.sigma_a);
        let mut sigma_s = DenselySampledSpectrum::new(&parts.sigma_s);
        sigma_a.scale(parts.sigma_scale);
        sigma_s.scale(parts.sigma_scale);
        CloudMedium {
            bounds: parts.bounds,
            medium_from_render: parts.render_from_medium.inverse(),
            phase: HGPhaseFunction::new(parts.g),
            sigma_a,
            sigma_s,
            density: parts.density,
            wispiness: parts.wispiness,
            frequency: parts.frequency,
        }
    }

    /// Creates the medium from `MakeNamedMedium "cloud"` parameters
    /// (pbrt-v4 `CloudMedium::Create`, plus the `"scale"` the other media
    /// have).
    pub fn create(mp: &ParamReader, render_from_medium: &Transform) -> Result<Self, Diagnostic> {
        let finite = |name: &str, default: Float| -> Result<Float, Diagnostic> {
            let v = mp.float(name, default)?;
            if !v.is_finite() {
                return Err(mp.error_at(name, format!("\"{name}\" must be finite, got {v}")));
            }
            Ok(v)
        };
        let density = finite("density", 1.0)?;
        let g = phase_asymmetry(mp)?;
        let wispiness = finite("wispiness", 1.0)?;
        let frequency = finite("frequency", 5.0)?;
        let sigma_a = coefficient(mp, "sigma_a")?;
        let sigma_s = coefficient(mp, "sigma_s")?;
        let sigma_scale = non_negative(mp, "scale", 1.0)?;
        let bounds = grid_bounds(mp)?;
        Ok(CloudMedium::new(CloudMediumParts {
            bounds,
            render_from_medium: *render_from_medium,
            sigma_a,
            sigma_s,
            sigma_scale,
            g,
            density,
            wispiness,
            frequency,
        }))
    }

    /// The medium's box, in medium space.
    pub fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    /// The cloud's density at a medium-space point, in `[0, 1]` (pbrt-v4
    /// `CloudMedium::Density`).
    pub fn density(&self, p: Point3f) -> Float {
        let mut pp = Point3f::from(Vector3f::from(p) * self.frequency);
        if self.wispiness > 0.0 {
            // Two octaves of the noise's gradient push the lookup point
            // around.
            let mut omega = 0.05 * self.wispiness;
            let mut lambda = 10.0;
            for _ in 0..2 {
                let q = Point3f::from(Vector3f::from(pp) * lambda);
                pp += dnoise(q) * omega;
                omega *= 0.5;
                lambda *= 1.99;
            }
        }
        let mut d = 0.0;
        let mut omega = 0.5;
        let mut lambda = 1.0;
        for _ in 0..5 {
            d += omega * noise_p(Point3f::from(Vector3f::from(pp) * lambda));
            omega *= 0.5;
            lambda *= 1.99;
        }
        // Thinner with height: nothing above y = 1, solid below y = 0.
        let d = ((1.0 - p.y) * 4.5 * self.density * d).clamp(0.0, 1.0);
        let d = d + 2.0 * (0.5 - p.y).max(0.0);
        // NaN (from a non-finite point) counts as empty.
        if d > 0.0 {
            d.min(1.0)
        } else {
            0.0
        }
    }
}

impl ConcreteMedium for CloudMedium {
    type Majorants<'a> = HomogeneousMajorantIterator;

    #[inline]
    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        let d = self.density(self.medium_from_render.apply_point(p));
        MediumProperties {
            sigma_a: self.sigma_a.sample(lambda) * d,
            sigma_s: self.sigma_s.sample(lambda) * d,
            phase: self.phase,
            le: SampledSpectrum::new(0.0),
        }
    }

    #[inline]
    fn sample_ray(
        &self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> HomogeneousMajorantIterator {
        let (ray, t_max) = self.medium_from_render.apply_ray(ray, t_max);
        let Some((t0, t1)) = self.bounds.intersect_p(ray.o, ray.d, t_max) else {
            return HomogeneousMajorantIterator::empty();
        };
        let sigma_t = self.sigma_a.sample(lambda) + self.sigma_s.sample(lambda);
        HomogeneousMajorantIterator::new(t0, t1, sigma_t)
    }
}
