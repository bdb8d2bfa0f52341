//! The volumetric path tracer (pbrt-v4 `VolPathIntegrator`; book section
//! 14.2): delta tracking through media against their majorants with
//! spectral MIS over the rescaled path probabilities `r_u` and `r_l`,
//! light sampling through media and interfaces by ratio tracking, medium
//! emission, and subsurface scattering through the materials' BSSRDFs.

use super::direct::{light_sample_culled, surface_light_context};
use super::volume::{
    hit_medium_toward, medium_toward, segment_rng, shadow_transmittance, ShadowTransmittance,
};
use super::{skip_intersection, RayIntegrator, Scene, VertexOrigins};
use crate::bssrdf::{Bssrdf, SeparableBssrdf};
use crate::bxdf::{BxDFReflTransFlags, TransportMode, BSDF};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::medium::{sample_t_maj, HGPhaseFunction};
use crate::primitive::MediumInterface;
use crate::rng::{mix_bits, Rng};
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::{spawn_ray_from_origin_to_surface, MediumId, Ray, RayDifferential};
use rpbrt_geometry::tuple::*;

/// pbrt-v4's `volpath` integrator.
#[derive(Clone, Debug)]
pub struct VolPathIntegrator {
    /// Maximum number of scattering events (surface and medium).
    pub max_depth: i32,
    /// Which light sampler to use ("bvh", "power", "uniform").
    pub light_sampler_name: String,
    /// Roughen near-specular BSDFs after the first non-specular bounce.
    pub regularize: bool,
}

/// Where direct lighting is sampled: a surface vertex (with its BSDF and
/// the media on its sides) or a real scattering event in a medium.
enum LdVertex<'v, 'a> {
    Surface {
        origins: &'v mut VertexOrigins<'a>,
        bsdf: &'v BSDF,
        interface: Option<MediumInterface>,
        ray_medium: Option<MediumId>,
    },
    Medium {
        p: Point3f,
        wo: Vector3f,
        time: Float,
        phase: HGPhaseFunction,
        medium: Option<MediumId>,
    },
}

/// The selection probabilities of absorption, real and null scattering
/// at a tentative collision, with `u` choosing one (pbrt-v4
/// `SampleDiscrete({pAbsorb, pScatter, pNull}, u)`).
#[inline]
pub(crate) fn sample_event(sigma_a: Float, sigma_s: Float, sigma_maj: Float, u: Float) -> u8 {
    let p_absorb = sigma_a / sigma_maj;
    let p_scatter = sigma_s / sigma_maj;
    let p_null = (1.0 - p_absorb - p_scatter).max(0.0);
    let sum = p_absorb + p_scatter + p_null;
    if sum.is_nan() || sum <= 0.0 {
        return 2;
    }
    let up = u * sum;
    if up < p_absorb {
        0
    } else if up < p_absorb + p_scatter {
        1
    } else {
        2
    }
}

impl VolPathIntegrator {
    /// Light-sampled direct lighting at a vertex, attenuated by the media
    /// and interfaces on the way (pbrt-v4 `VolPathIntegrator::SampleLd`):
    /// `beta` and `r_p` are the path's throughput and rescaled
    /// unidirectional probability at the vertex.
    #[allow(clippy::too_many_arguments)]
    fn sample_ld(
        &self,
        scene: &Scene,
        vertex: LdVertex,
        lambda: &SampledWavelengths,
        u: Float,
        u_light: Point2f,
        beta: SampledSpectrum,
        r_p: SampledSpectrum,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::new(0.0);
        let mut vertex = vertex;
        let ctx = match &mut vertex {
            LdVertex::Surface { origins, bsdf, .. } => surface_light_context(origins, bsdf),
            LdVertex::Medium { p, .. } => LightSampleContext::from_point(*p),
        };
        let Some(sampled) = scene.light_sampler.sample(&ctx, u) else {
            return zero;
        };
        if let LdVertex::Surface { origins, bsdf, .. } = &vertex {
            if light_sample_culled(scene, sampled.light, ctx.p(), bsdf, origins.si) {
                return zero;
            }
        }
        let light = &scene.lights[sampled.light as usize];
        let Some(ls) = light.sample_li(&ctx, u_light, lambda, true) else {
            return zero;
        };
        if ls.l.is_black() || ls.pdf == 0.0 {
            return zero;
        }
        let light_pdf = sampled.p * ls.pdf;
        let wi = ls.wi;
        let p_to = ls.p_light.midpoint();
        let (f_hat, scatter_pdf, ray) = match vertex {
            LdVertex::Surface {
                origins,
                bsdf,
                interface,
                ray_medium,
            } => {
                let si = origins.si;
                let f = bsdf.f(si.wo, wi, TransportMode::Radiance) * abs_dot(wi, si.shading.n);
                if f.is_black() {
                    return zero;
                }
                let pdf = bsdf.pdf(si.wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
                let pf = origins.toward(p_to - si.p());
                let mut ray = spawn_ray_from_origin_to_surface(
                    pf,
                    si.time,
                    p_to,
                    ls.p_light.error(),
                    ls.n_light,
                );
                ray.medium = medium_toward(interface, si.n, ray_medium, ray.d);
                (f, pdf, ray)
            }
            LdVertex::Medium {
                p,
                wo,
                time,
                phase,
                medium,
            } => {
                let v = phase.p(wo, wi);
                if v == 0.0 {
                    return zero;
                }
                let mut ray =
                    spawn_ray_from_origin_to_surface(p, time, p_to, ls.p_light.error(), ls.n_light);
                ray.medium = medium;
                (SampledSpectrum::new(v), phase.pdf(wo, wi), ray)
            }
        };
        let Some(ShadowTransmittance { t_ray, r_u, r_l }) =
            shadow_transmittance(scene, ray, ls.p_light, ls.n_light, lambda)
        else {
            return zero;
        };
        let r_l = r_l * r_p * light_pdf;
        let r_u = r_u * r_p * scatter_pdf;
        if light.light_type().is_delta() {
            beta * f_hat * t_ray * ls.l / r_l.average()
        } else {
            beta * f_hat * t_ray * ls.l / (r_l + r_u).average()
        }
    }
}

/// A probe-ray hit kept by the reservoir: the surface point light enters
/// through.
#[derive(Clone, Copy)]
struct ProbeHit {
    si: SurfaceInteraction,
}

impl RayIntegrator for VolPathIntegrator {
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        mut visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let light_sampler = &scene.light_sampler;
        let max_depth = self.max_depth;
        let mut ray = ray;
        let mut l = SampledSpectrum::new(0.0);
        let mut beta = SampledSpectrum::new(1.0);
        let mut r_u = SampledSpectrum::new(1.0);
        let mut r_l = SampledSpectrum::new(1.0);
        let mut specular_bounce = false;
        let mut any_non_specular = false;
        let mut depth = 0i32;
        let mut eta_scale: Float = 1.0;
        let mut prev_ctx = LightSampleContext::default();
        loop {
            let mut closest;
            if let Some(m) = ray.ray.medium {
                // Delta tracking through the medium up to the surface: only
                // the surface's distance is needed unless the ray gets
                // there, so its interaction is built afterwards.
                let record = scene.intersect_record(&ray.ray, Float::INFINITY);
                let medium = &scene.media[m as usize];
                let mut scattered = false;
                let mut terminated = false;
                let t_max = record.as_ref().map_or(Float::INFINITY, |h| h.t_hit);
                let mut rng = segment_rng(sampler);
                let u = sampler.get_1d();
                let r = ray.ray;
                let wo = -r.d.normalize();
                let lambda_ref: &SampledWavelengths = lambda;
                let t_maj = sample_t_maj(
                    medium,
                    &r,
                    t_max,
                    u,
                    &mut rng,
                    lambda_ref,
                    |p, mp, sigma_maj, t_maj, rng| {
                        if beta.is_black() {
                            terminated = true;
                            return false;
                        }
                        // Emission at the collision, as if it were an absorption.
                        if depth < max_depth && !mp.le.is_black() {
                            let pdf = sigma_maj[0] * t_maj[0];
                            let betap = beta * t_maj / pdf;
                            let r_e = r_u * sigma_maj * t_maj / pdf;
                            if !r_e.is_black() {
                                l += betap * mp.sigma_a * mp.le / r_e.average();
                            }
                        }
                        let um = rng.uniform_float();
                        match sample_event(mp.sigma_a[0], mp.sigma_s[0], sigma_maj[0], um) {
                            0 => {
                                terminated = true;
                                false
                            }
                            1 => {
                                if depth >= max_depth {
                                    terminated = true;
                                    return false;
                                }
                                depth += 1;
                                let pdf = t_maj[0] * mp.sigma_s[0];
                                beta *= t_maj * mp.sigma_s / pdf;
                                r_u *= t_maj * mp.sigma_s / pdf;
                                if !beta.is_black() && !r_u.is_black() {
                                    let (u_l, u_l2) = (sampler.get_1d(), sampler.get_2d());
                                    let vertex = LdVertex::Medium {
                                        p,
                                        wo,
                                        time: r.time,
                                        phase: mp.phase,
                                        medium: Some(m),
                                    };
                                    l += self
                                        .sample_ld(scene, vertex, lambda_ref, u_l, u_l2, beta, r_u);
                                    let u = sampler.get_2d();
                                    match mp.phase.sample_p(wo, u) {
                                        Some(ps) if ps.pdf > 0.0 => {
                                            beta *= ps.p / ps.pdf;
                                            r_l = r_u / ps.pdf;
                                            prev_ctx = LightSampleContext::from_point(p);
                                            scattered = true;
                                            ray = RayDifferential::new(Ray::with_time(
                                                p,
                                                ps.wi,
                                                r.time,
                                                Some(m),
                                            ));
                                            specular_bounce = false;
                                            any_non_specular = true;
                                        }
                                        _ => terminated = true,
                                    }
                                }
                                false
                            }
                            _ => {
                                let sigma_n = (sigma_maj - mp.sigma_a - mp.sigma_s).clamp_zero();
                                let pdf = t_maj[0] * sigma_n[0];
                                beta *= t_maj * sigma_n / pdf;
                                if pdf == 0.0 {
                                    beta = SampledSpectrum::new(0.0);
                                }
                                r_u *= t_maj * sigma_n / pdf;
                                r_l *= t_maj * sigma_maj / pdf;
                                !beta.is_black() && !r_u.is_black()
                            }
                        }
                    },
                );
                if terminated || beta.is_black() || r_u.is_black() || r_u.has_nan() {
                    return l;
                }
                if scattered {
                    continue;
                }
                if !(t_maj[0] > 0.0) {
                    return l;
                }
                beta *= t_maj / t_maj[0];
                r_u *= t_maj / t_maj[0];
                r_l *= t_maj / t_maj[0];
                closest = record.and_then(|h| scene.aggregate.interaction(&r, &h));
            } else {
                closest = scene.intersect(&ray.ray, Float::INFINITY);
            }

            let Some(hit) = closest.as_mut() else {
                // Escaped: infinite lights.
                for &li in &scene.infinite_lights {
                    let light = &scene.lights[li as usize];
                    let le = light.le(&ray.ray, lambda);
                    if le.is_black() {
                        continue;
                    }
                    if depth == 0 || specular_bounce {
                        l += beta * le / r_u.average();
                    } else {
                        let p_l = light_sampler.pmf(&prev_ctx, li)
                            * light.pdf_li(&prev_ctx, ray.ray.d, true);
                        let r_l = r_l * p_l;
                        l += beta * le / (r_u + r_l).average();
                    }
                }
                break;
            };
            // Emission from a surface that was hit.
            let le = scene.le(hit, -ray.ray.d, lambda);
            if !le.is_black() {
                if depth == 0 || specular_bounce {
                    l += beta * le / r_u.average();
                } else if let Some(al) = hit.area_light {
                    let light = &scene.lights[al as usize];
                    let p_l =
                        light_sampler.pmf(&prev_ctx, al) * light.pdf_li(&prev_ctx, ray.ray.d, true);
                    r_l *= p_l;
                    l += beta * le / (r_u + r_l).average();
                }
            }
            let mut bsdf_slot = scene.get_bsdf(hit, &ray, lambda, sampler);
            let Some(bsdf) = bsdf_slot.as_mut() else {
                ray = skip_intersection(&ray, hit);
                continue;
            };
            if depth == 0 {
                if let Some(v) = visible.take() {
                    *v = scene.visible_surface(hit, bsdf);
                }
            }
            if depth >= max_depth {
                return l;
            }
            depth += 1;
            if self.regularize && any_non_specular {
                bsdf.regularize();
            }
            let ray_medium = ray.ray.medium;
            let si = &hit.si;
            let mut origins = VertexOrigins::new(si);
            let (u, u2) = if bsdf.flags().is_non_specular() {
                let (u_light, u_light_2d, u, u2) = sampler.get_vertex_samples();
                let vertex = LdVertex::Surface {
                    origins: &mut origins,
                    bsdf,
                    interface: hit.medium_interface,
                    ray_medium,
                };
                l += self.sample_ld(scene, vertex, lambda, u_light, u_light_2d, beta, r_u);
                (u, u2)
            } else {
                (sampler.get_1d(), sampler.get_2d())
            };
            prev_ctx = LightSampleContext::from_si(si);
            let wo = si.wo;
            let Some(bs) =
                bsdf.sample_f(wo, u, u2, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            else {
                break;
            };
            beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
            r_l = if bs.pdf_is_proportional {
                r_u / bsdf.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            } else {
                r_u / bs.pdf
            };
            specular_bounce = bs.is_specular();
            any_non_specular |= !bs.is_specular();
            if bs.is_transmission() {
                eta_scale *= bs.eta * bs.eta;
            }
            let mut next = origins.spawn_ray(bs.wi);
            next.medium = hit_medium_toward(hit, ray_medium, bs.wi);
            ray = RayDifferential::new(next);

            // Subsurface scattering: light leaving through the boundary
            // re-emerges elsewhere on the same material.
            if bs.is_transmission() {
                if let Some(bssrdf) = hit
                    .material
                    .and_then(|m| scene.materials.get_bssrdf(m, &hit.si, lambda))
                {
                    match self.subsurface(
                        scene,
                        &bssrdf,
                        hit.material,
                        ray.ray.time,
                        lambda,
                        sampler,
                        &mut beta,
                        &mut r_u,
                        &mut r_l,
                        &mut l,
                        &mut prev_ctx,
                    ) {
                        Some((next_ray, specular)) => {
                            ray = next_ray;
                            specular_bounce = specular;
                            any_non_specular = true;
                        }
                        None => break,
                    }
                }
            }

            // Russian roulette.
            if beta.is_black() {
                break;
            }
            let rr_beta = beta * eta_scale / r_u.average();
            let u_rr = sampler.get_1d();
            let m = rr_beta.max_component_value();
            if m < 1.0 && depth > 1 {
                let q = (1.0 - m).max(0.0);
                if u_rr < q {
                    break;
                }
                beta /= 1.0 - q;
            }
        }
        l
    }
}

impl VolPathIntegrator {
    /// Samples where light that entered a subsurface material leaves it
    /// (pbrt-v4 `VolPathIntegrator::Li`'s BSSRDF block): a probe segment,
    /// one of its hits on the same material chosen uniformly (a weighted
    /// reservoir), direct lighting there and a new direction through the
    /// exit point's BSDF. Updates the path state; `None` ends the path.
    #[allow(clippy::too_many_arguments)]
    fn subsurface(
        &self,
        scene: &Scene,
        bssrdf: &Bssrdf,
        material: Option<u32>,
        time: Float,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
        beta: &mut SampledSpectrum,
        r_u: &mut SampledSpectrum,
        r_l: &mut SampledSpectrum,
        l: &mut SampledSpectrum,
        prev_ctx: &mut LightSampleContext,
    ) -> Option<(RayDifferential, bool)> {
        let uc = sampler.get_1d();
        let up = sampler.get_2d();
        let seg = bssrdf.sample_sp(uc, up)?;
        let seed = mix_bits(sampler.get_1d().to_bits() as u64);
        let mut rng = Rng::with_sequence(seed);
        let mut chosen: Option<ProbeHit> = None;
        let mut weight_sum: Float = 0.0;
        let mut count = 0u32;
        let mut r = Ray::with_time(seg.p0, seg.p1 - seg.p0, time, None);
        // Bounded: each hit moves the origin forward along the segment; the
        // cap guards against a degenerate loop.
        for _ in 0..256 {
            if r.d == Vector3f::default() {
                break;
            }
            let Some(h) = scene.intersect(&r, 1.0) else {
                break;
            };
            if h.material == material {
                // A weighted reservoir with unit weights.
                weight_sum += 1.0;
                count += 1;
                if rng.uniform_float() < 1.0 / weight_sum {
                    chosen = Some(ProbeHit { si: h.si });
                }
            }
            r = h.si.spawn_ray_to(seg.p1);
        }
        let ProbeHit { si: mut pi } = chosen?;
        let sample = bssrdf.probe_intersection_to_sample(&(&pi).into());
        if sample.sp.is_black() || sample.pdf.is_black() {
            return None;
        }
        let pdf = sample.pdf[0] / count as Float;
        if !(pdf > 0.0) {
            return None;
        }
        *beta *= sample.sp / pdf;
        *r_u *= sample.pdf / sample.pdf[0];
        pi.wo = sample.wo;
        *prev_ctx = LightSampleContext::from_si(&pi);
        let mut sw = sample.sw;
        if self.regularize {
            sw.regularize();
        }
        let mut origins = VertexOrigins::new(&pi);
        let (u_light, u_light_2d, u, u2) = sampler.get_vertex_samples();
        let vertex = LdVertex::Surface {
            origins: &mut origins,
            bsdf: &sw,
            interface: None,
            ray_medium: None,
        };
        *l += self.sample_ld(scene, vertex, lambda, u_light, u_light_2d, *beta, *r_u);
        let bs = sw.sample_f(
            pi.wo,
            u,
            u2,
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        )?;
        *beta *= bs.f * (abs_dot(bs.wi, pi.shading.n) / bs.pdf);
        *r_l = *r_u / bs.pdf;
        Some((
            RayDifferential::new(origins.spawn_ray(bs.wi)),
            bs.is_specular(),
        ))
    }
}
