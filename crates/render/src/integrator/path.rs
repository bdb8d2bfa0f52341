//! The path tracer (pbrt-v4 `PathIntegrator`; book section 13.4): next-event
//! estimation with multiple importance sampling, Russian roulette and
//! optional BSDF regularization.

use super::{sample_ld, skip_intersection, RayIntegrator, Scene, VertexOrigins};
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::lightsampler::LightSampler;
use crate::sampler::Sampler;
use crate::sampling::power_heuristic;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// pbrt-v4's `path` integrator.
#[derive(Clone, Debug)]
pub struct PathIntegrator {
    /// Maximum number of scattering events.
    pub max_depth: i32,
    /// Which light sampler to use ("bvh", "power", "uniform").
    pub light_sampler_name: String,
    /// Roughen near-specular BSDFs after the first non-specular bounce.
    pub regularize: bool,
}

impl RayIntegrator for PathIntegrator {
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        mut visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let light_sampler: &LightSampler = &scene.light_sampler;
        let mut ray = ray;
        let mut l = SampledSpectrum::new(0.0);
        let mut beta = SampledSpectrum::new(1.0);
        let mut depth = 0;
        let mut p_b: Float = 1.0;
        let mut eta_scale: Float = 1.0;
        let mut specular_bounce = false;
        let mut any_non_specular = false;
        let mut prev_ctx = LightSampleContext::default();
        loop {
            // Matched by reference: moving the (large) intersection out of
            // the `Option` would copy it.
            let mut closest = scene.intersect(&ray.ray, Float::INFINITY);
            let Some(hit) = closest.as_mut() else {
                // Escaped: infinite lights, weighted by MIS unless the last
                // bounce could not have been light-sampled.
                for &li in &scene.infinite_lights {
                    let light = &scene.lights[li as usize];
                    let le = light.le(&ray.ray, lambda);
                    if le.is_black() {
                        continue;
                    }
                    if depth == 0 || specular_bounce {
                        l += beta * le;
                    } else {
                        let p_l = light_sampler.pmf(&prev_ctx, li)
                            * light.pdf_li(&prev_ctx, ray.ray.d, true);
                        let w_b = power_heuristic(1.0, p_b, 1.0, p_l);
                        l += beta * le * w_b;
                    }
                }
                break;
            };
            // Emission from an area light that was hit.
            let le = scene.le(hit, -ray.ray.d, lambda);
            if !le.is_black() {
                if depth == 0 || specular_bounce {
                    l += beta * le;
                } else if let Some(al) = hit.area_light {
                    let light = &scene.lights[al as usize];
                    let p_l =
                        light_sampler.pmf(&prev_ctx, al) * light.pdf_li(&prev_ctx, ray.ray.d, true);
                    let w_l = power_heuristic(1.0, p_b, 1.0, p_l);
                    l += beta * le * w_l;
                }
            }
            // Borrowed in place: moving the (large) BSDF out would copy it.
            let mut bsdf_slot = scene.get_bsdf(hit, &ray, lambda, sampler);
            let Some(bsdf) = bsdf_slot.as_mut() else {
                specular_bounce = true;
                ray = skip_intersection(&ray, hit);
                continue;
            };
            if depth == 0 {
                if let Some(v) = visible.take() {
                    *v = scene.visible_surface(hit, bsdf);
                }
            }
            if self.regularize && any_non_specular {
                bsdf.regularize();
            }
            if depth == self.max_depth {
                break;
            }
            depth += 1;
            let si = &hit.si;
            let mut origins = VertexOrigins::new(si);
            // Sampler draws in pbrt-v4's order: the light's two, then the
            // BSDF's two (taken together when there is a light sample).
            let (u, u2) = if bsdf.flags().is_non_specular() {
                let (u_light, u_light_2d, u, u2) = sampler.get_vertex_samples();
                let ld = sample_ld(
                    scene,
                    light_sampler,
                    &mut origins,
                    bsdf,
                    lambda,
                    u_light,
                    u_light_2d,
                );
                l += beta * ld;
                (u, u2)
            } else {
                (sampler.get_1d(), sampler.get_2d())
            };
            prev_ctx = LightSampleContext::from_si(si);
            let wo = -ray.ray.d;
            let Some(bs) =
                bsdf.sample_f(wo, u, u2, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            else {
                break;
            };
            beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
            p_b = if bs.pdf_is_proportional {
                bsdf.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            } else {
                bs.pdf
            };
            specular_bounce = bs.is_specular();
            any_non_specular |= !bs.is_specular();
            if bs.is_transmission() {
                eta_scale *= bs.eta * bs.eta;
            }
            ray = RayDifferential::new(origins.spawn_ray(bs.wi));
            let rr_beta = beta * eta_scale;
            let m = rr_beta.max_component_value();
            if m < 1.0 && depth > 1 {
                let q = (1.0 - m).max(0.0);
                if sampler.get_1d() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            if beta.is_black() {
                break;
            }
        }
        l
    }
}
