//! pbrt-v4's `simplevolpath` (`SimpleVolPathIntegrator`; book section
//! 14.1.2): a reference estimator for media alone. Delta tracking chooses
//! absorption (collecting the medium's emission), real scattering
//! (sampling the phase function) or null scattering at each tentative
//! collision with the hero wavelength's probabilities; surfaces only
//! emit or pass rays through interfaces. No light sampling, no MIS.

use super::volume::segment_rng;
use super::{skip_intersection, RayIntegrator, Scene};
use crate::film::VisibleSurface;
use crate::medium::sample_t_maj;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::{Ray, RayDifferential};
use rpbrt_geometry::tuple::*;

/// pbrt-v4's `simplevolpath` integrator. Scenes whose surfaces scatter
/// light, or with delta lights, are refused when it is created.
#[derive(Clone, Debug)]
pub struct SimpleVolPathIntegrator {
    /// Maximum number of real scattering events.
    pub max_depth: i32,
}

impl RayIntegrator for SimpleVolPathIntegrator {
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let mut l = SampledSpectrum::new(0.0);
        let mut beta: Float = 1.0;
        let mut depth = 0i32;
        let mut ray = ray;
        // The walk follows the hero wavelength only.
        lambda.terminate_secondary();
        let lambda: &SampledWavelengths = lambda;
        loop {
            let hit = scene.intersect(&ray.ray, Float::INFINITY);
            let mut scattered = false;
            let mut terminated = false;
            if let Some(m) = ray.ray.medium {
                let mut rng = segment_rng(sampler);
                let t_max = hit.as_ref().map_or(Float::INFINITY, |h| h.t_hit);
                let u = sampler.get_1d();
                let mut u_mode = sampler.get_1d();
                let r = ray.ray;
                let wo = -r.d.normalize();
                sample_t_maj(
                    &scene.media[m as usize],
                    &r,
                    t_max,
                    u,
                    &mut rng,
                    lambda,
                    |p, mp, sigma_maj, _, rng| {
                        let p_absorb = mp.sigma_a[0] / sigma_maj[0];
                        let p_scatter = mp.sigma_s[0] / sigma_maj[0];
                        if u_mode < p_absorb {
                            l += beta * mp.le;
                            terminated = true;
                            false
                        } else if u_mode < p_absorb + p_scatter {
                            if depth >= self.max_depth {
                                terminated = true;
                                return false;
                            }
                            depth += 1;
                            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
                            match mp.phase.sample_p(wo, u) {
                                Some(ps) if ps.pdf > 0.0 => {
                                    beta *= ps.p / ps.pdf;
                                    ray = RayDifferential::new(Ray::with_time(
                                        p,
                                        ps.wi,
                                        r.time,
                                        Some(m),
                                    ));
                                    scattered = true;
                                }
                                _ => terminated = true,
                            }
                            false
                        } else {
                            u_mode = rng.uniform_float();
                            true
                        }
                    },
                );
            }
            if terminated {
                return l;
            }
            if scattered {
                continue;
            }
            let Some(mut hit) = hit else {
                for &li in &scene.infinite_lights {
                    l += beta * scene.lights[li as usize].le(&ray.ray, lambda);
                }
                return l;
            };
            l += beta * scene.le(&hit, -ray.ray.d, lambda);
            let mut lambda_copy = *lambda;
            if scene
                .get_bsdf(&mut hit, &ray, &mut lambda_copy, sampler)
                .is_some()
            {
                // Surfaces that scatter are refused at creation; one that
                // does not (a black diffuse emitter) ends the path.
                return l;
            }
            ray = skip_intersection(&ray, &hit);
        }
    }
}
