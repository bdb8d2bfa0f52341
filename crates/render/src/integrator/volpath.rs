//! The volumetric path tracer (pbrt-v4 `VolPathIntegrator`; book section
//! 14.2): delta tracking through media against their majorants with
//! spectral MIS over the rescaled path probabilities `r_u` and `r_l`,
//! light sampling through media and interfaces by ratio tracking, medium
//! emission, and subsurface scattering through the materials' BSSRDFs.

use super::bsdf_stage::{BsdfAnswers, BsdfQuery};
use super::diffuse_lanes::{lane_surface, LaneShade, LaneVertices, SurfaceOut};
use super::direct::ShadowQuery;
use super::direct::{light_request, LightAnswer, LightRequest};
use super::direct::{light_sample_culled, surface_light_context};
use super::vertex::{li_by_vertices, Begin, VertexIntegrator, VertexStep};
use super::volume::{
    hit_medium_toward, medium_toward, segment_rng, shadow_transmittance, ShadowTransmittance,
};
use super::{skip_intersection, RayIntegrator, Scene, VertexOrigins};
use crate::bssrdf::{Bssrdf, SeparableBssrdf};
use crate::bxdf::{BxDFReflTransFlags, DielectricBxDF, TransportMode, BSDF};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::medium::{sample_t_maj, HGPhaseFunction};
use crate::primitive::{HitRecord, MediumInterface, PrimitiveIntersection};
use crate::rng::{mix_bits, Rng};
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::{Float, INV_PI};
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::{
    spawn_ray_from_origin_to_surface, MediumId, Ray, RayDifferential, SHADOW_EPSILON,
};
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
        match shadow_transmittance(scene, ray, ls.p_light, ls.n_light, lambda) {
            Some(st) => ld_value(
                light.light_type().is_delta(),
                beta,
                f_hat,
                ls.l,
                st,
                r_p,
                light_pdf,
                scatter_pdf,
            ),
            None => zero,
        }
    }
}

/// A probe-ray hit kept by the reservoir: the surface point light enters
/// through.
#[derive(Clone, Copy)]
struct ProbeHit {
    si: SurfaceInteraction,
}

/// The state of a path being traced: the locals of pbrt-v4's
/// `VolPathIntegrator::Li`, updated at every vertex.
pub(crate) struct VolPathState {
    /// The ray leaving the last vertex (the camera ray at first).
    ray: RayDifferential,
    /// The radiance gathered so far.
    l: SampledSpectrum,
    /// The path throughput.
    beta: SampledSpectrum,
    /// The rescaled unidirectional path probability.
    r_u: SampledSpectrum,
    /// The rescaled light-sampling path probability.
    r_l: SampledSpectrum,
    /// The last bounce was specular (or passed an interface).
    specular_bounce: bool,
    /// Some bounce so far was not specular (for BSDF regularization).
    any_non_specular: bool,
    /// Scattering events so far.
    depth: i32,
    /// The product of the squared relative indices of refraction crossed.
    eta_scale: Float,
    /// The last scattering vertex, for MIS densities of emission hit.
    prev_ctx: LightSampleContext,
}

impl RayIntegrator for VolPathIntegrator {
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        li_by_vertices(self, scene, ray, lambda, sampler, visible)
    }
}

impl VertexIntegrator for VolPathIntegrator {
    type State = VolPathState;
    type Scratch = VolPathScratch;

    #[inline(always)]
    fn start(&self, ray: RayDifferential) -> VolPathState {
        VolPathState {
            ray,
            l: SampledSpectrum::new(0.0),
            beta: SampledSpectrum::new(1.0),
            r_u: SampledSpectrum::new(1.0),
            r_l: SampledSpectrum::new(1.0),
            specular_bounce: false,
            any_non_specular: false,
            depth: 0,
            eta_scale: 1.0,
            prev_ctx: LightSampleContext::default(),
        }
    }

    #[inline(always)]
    fn ray(s: &VolPathState) -> &RayDifferential {
        &s.ray
    }

    #[inline(always)]
    fn radiance(s: &mut VolPathState) -> &mut SampledSpectrum {
        &mut s.l
    }

    #[inline(always)]
    fn bsdf_query<'a>(
        _s: &VolPathState,
        scratch: &'a VolPathScratch,
        light: Option<&LightAnswer>,
    ) -> Option<BsdfQuery<'a>> {
        let bsdf = scratch.bsdf.as_ref()?;
        let wo = scratch.hit.as_ref().map_or(scratch.wo, |h| h.si.wo);
        Some(BsdfQuery {
            bsdf,
            wo_light: wo,
            wi_light: light.map(|a| a.ls.wi),
            wo,
            u: scratch.u,
            u2: scratch.u2,
        })
    }

    #[inline(always)]
    fn bsdf_answers(scratch: &mut VolPathScratch) -> &mut BsdfAnswers {
        &mut scratch.answers
    }

    /// The first half of one pass of pbrt-v4's `VolPathIntegrator::Li`
    /// loop: delta tracking through the ray's medium up to `record`, then
    /// the surface there up to its light sample. In scenes without media
    /// or interfaces the surface's light sample is asked for
    /// ([`Begin::Light`]) and its shadow ray left to the caller; every
    /// other light sample is traced here.
    #[allow(clippy::too_many_arguments)]
    fn begin(
        &self,
        scene: &Scene,
        s: &mut VolPathState,
        record: Option<HitRecord>,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        visible: Option<&mut VisibleSurface>,
        scratch: &mut VolPathScratch,
    ) -> Begin {
        let light_sampler = &scene.light_sampler;
        let max_depth = self.max_depth;
        if let Some(m) = s.ray.ray.medium {
            // Delta tracking through the medium up to the surface: only
            // the surface's distance is needed unless the ray gets
            // there, so its interaction is built afterwards.
            let medium = &scene.media[m as usize];
            let mut scattered = false;
            let mut terminated = false;
            let t_max = record.as_ref().map_or(Float::INFINITY, |h| h.t_hit);
            let mut rng = segment_rng(sampler);
            let u = sampler.get_1d();
            let r = s.ray.ray;
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
                    if s.beta.is_black() {
                        terminated = true;
                        return false;
                    }
                    // Emission at the collision, as if it were an absorption.
                    if s.depth < max_depth && !mp.le.is_black() {
                        let pdf = sigma_maj[0] * t_maj[0];
                        let betap = s.beta * t_maj / pdf;
                        let r_e = s.r_u * sigma_maj * t_maj / pdf;
                        if !r_e.is_black() {
                            s.l += betap * mp.sigma_a * mp.le / r_e.average();
                        }
                    }
                    let um = rng.uniform_float();
                    match sample_event(mp.sigma_a[0], mp.sigma_s[0], sigma_maj[0], um) {
                        0 => {
                            terminated = true;
                            false
                        }
                        1 => {
                            if s.depth >= max_depth {
                                terminated = true;
                                return false;
                            }
                            s.depth += 1;
                            let pdf = t_maj[0] * mp.sigma_s[0];
                            s.beta *= t_maj * mp.sigma_s / pdf;
                            s.r_u *= t_maj * mp.sigma_s / pdf;
                            if !s.beta.is_black() && !s.r_u.is_black() {
                                let (u_l, u_l2) = (sampler.get_1d(), sampler.get_2d());
                                let vertex = LdVertex::Medium {
                                    p,
                                    wo,
                                    time: r.time,
                                    phase: mp.phase,
                                    medium: Some(m),
                                };
                                s.l += self
                                    .sample_ld(scene, vertex, lambda_ref, u_l, u_l2, s.beta, s.r_u);
                                let u = sampler.get_2d();
                                match mp.phase.sample_p(wo, u) {
                                    Some(ps) if ps.pdf > 0.0 => {
                                        s.beta *= ps.p / ps.pdf;
                                        s.r_l = s.r_u / ps.pdf;
                                        s.prev_ctx = LightSampleContext::from_point(p);
                                        scattered = true;
                                        s.ray = RayDifferential::new(Ray::with_time(
                                            p,
                                            ps.wi,
                                            r.time,
                                            Some(m),
                                        ));
                                        s.specular_bounce = false;
                                        s.any_non_specular = true;
                                    }
                                    _ => terminated = true,
                                }
                            }
                            false
                        }
                        _ => {
                            let sigma_n = (sigma_maj - mp.sigma_a - mp.sigma_s).clamp_zero();
                            let pdf = t_maj[0] * sigma_n[0];
                            s.beta *= t_maj * sigma_n / pdf;
                            if pdf == 0.0 {
                                s.beta = SampledSpectrum::new(0.0);
                            }
                            s.r_u *= t_maj * sigma_n / pdf;
                            s.r_l *= t_maj * sigma_maj / pdf;
                            !s.beta.is_black() && !s.r_u.is_black()
                        }
                    }
                },
            );
            if terminated || s.beta.is_black() || s.r_u.is_black() || s.r_u.has_nan() {
                return Begin::Step(VertexStep::DONE);
            }
            if scattered {
                return Begin::Step(VertexStep::NEXT);
            }
            if !(t_maj[0] > 0.0) {
                return Begin::Step(VertexStep::DONE);
            }
            s.beta *= t_maj / t_maj[0];
            s.r_u *= t_maj / t_maj[0];
            s.r_l *= t_maj / t_maj[0];
        }
        // Assigned straight from the call, which then writes into the
        // scratch (see `PathIntegrator::begin`).
        scratch.hit = match record {
            Some(h) => scene.aggregate.interaction(&s.ray.ray, &h),
            None => None,
        };
        let Some(hit) = scratch.hit.as_mut() else {
            // Escaped: infinite lights.
            for &li in &scene.infinite_lights {
                let light = &scene.lights[li as usize];
                let le = light.le(&s.ray.ray, lambda);
                if le.is_black() {
                    continue;
                }
                if s.depth == 0 || s.specular_bounce {
                    s.l += s.beta * le / s.r_u.average();
                } else {
                    let p_l = light_sampler.pmf(&s.prev_ctx, li)
                        * light.pdf_li(&s.prev_ctx, s.ray.ray.d, true);
                    let r_l = s.r_l * p_l;
                    s.l += s.beta * le / (s.r_u + r_l).average();
                }
            }
            return Begin::Step(VertexStep::DONE);
        };
        // Emission from a surface that was hit.
        let le = scene.le(hit, -s.ray.ray.d, lambda);
        if !le.is_black() {
            if s.depth == 0 || s.specular_bounce {
                s.l += s.beta * le / s.r_u.average();
            } else if let Some(al) = hit.area_light {
                let light = &scene.lights[al as usize];
                let p_l = light_sampler.pmf(&s.prev_ctx, al)
                    * light.pdf_li(&s.prev_ctx, s.ray.ray.d, true);
                s.r_l *= p_l;
                s.l += s.beta * le / (s.r_u + s.r_l).average();
            }
        }
        scratch.bsdf = scene.get_bsdf(hit, &s.ray, lambda, sampler);
        let Some(bsdf) = scratch.bsdf.as_mut() else {
            s.ray = skip_intersection(&s.ray, hit);
            return Begin::Step(VertexStep::NEXT);
        };
        if s.depth == 0 {
            if let Some(v) = visible {
                *v = scene.visible_surface(hit, bsdf);
            }
        }
        if s.depth >= max_depth {
            return Begin::Step(VertexStep::DONE);
        }
        s.depth += 1;
        if self.regularize && s.any_non_specular {
            bsdf.regularize();
        }
        let ray_medium = s.ray.ray.medium;
        scratch.ray_medium = ray_medium;
        let mut origins = VertexOrigins::new(&hit.si);
        if bsdf.flags().is_non_specular() {
            let (u_light, u_light_2d, u, u2) = sampler.get_vertex_samples();
            (scratch.u, scratch.u2) = (u, u2);
            if !scene.has_volumes {
                // A plain occlusion test: answered with the other paths'.
                let req = light_request(&mut origins, bsdf, u_light, u_light_2d);
                scratch.sides = origins.sides();
                return Begin::Light(req);
            }
            let vertex = LdVertex::Surface {
                origins: &mut origins,
                bsdf,
                interface: hit.medium_interface,
                ray_medium,
            };
            s.l += self.sample_ld(scene, vertex, lambda, u_light, u_light_2d, s.beta, s.r_u);
        } else {
            (scratch.u, scratch.u2) = (sampler.get_1d(), sampler.get_2d());
        }
        scratch.sides = origins.sides();
        Begin::Step(self.finish(scene, s, lambda, sampler, scratch, None))
    }

    /// The second half: the light sample's shadow query (when asked
    /// for), the BSDF sample that continues the path, subsurface
    /// scattering and Russian roulette.
    fn finish(
        &self,
        scene: &Scene,
        s: &mut VolPathState,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut VolPathScratch,
        light: Option<&LightAnswer>,
    ) -> VertexStep {
        let (Some(hit), Some(bsdf)) = (scratch.hit.as_ref(), scratch.bsdf.as_ref()) else {
            return VertexStep::DONE;
        };
        let si = &hit.si;
        let ray_medium = scratch.ray_medium;
        let pre = std::mem::take(&mut scratch.answers);
        let mut origins = VertexOrigins::with_sides(si, scratch.sides);
        let shadow =
            light.and_then(|a| surface_shadow_query(scene, &mut origins, bsdf, a, s, &pre));
        let (u, u2) = (scratch.u, scratch.u2);
        let done = VertexStep { shadow, done: true };
        s.prev_ctx = LightSampleContext::from_si(si);
        let wo = si.wo;
        let Some((bs, p_b)) = pre.sample(bsdf, wo, u, u2) else {
            return done;
        };
        s.beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
        s.r_l = s.r_u / p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        let mut next = origins.spawn_ray(bs.wi);
        next.medium = hit_medium_toward(hit, ray_medium, bs.wi);
        s.ray = RayDifferential::new(next);

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
                    s.ray.ray.time,
                    lambda,
                    sampler,
                    &mut s.beta,
                    &mut s.r_u,
                    &mut s.r_l,
                    &mut s.l,
                    &mut s.prev_ctx,
                ) {
                    Some((next_ray, specular)) => {
                        s.ray = next_ray;
                        s.specular_bounce = specular;
                        s.any_non_specular = true;
                    }
                    None => return done,
                }
            }
        }

        russian_roulette(s, || sampler.get_1d(), done.shadow)
    }

    #[inline(always)]
    fn lane_hit(
        &self,
        scene: &Scene,
        s: &VolPathState,
        record: &HitRecord,
        lambda: &SampledWavelengths,
        gbuffer: bool,
        out: &mut LaneVertices,
    ) -> Option<LaneShade> {
        // Only where `begin` asks for the light sample (no media, no
        // interfaces: the ray's medium is none and stays none), and not
        // where it ends the path or writes the visible surface.
        if scene.has_volumes
            || s.ray.ray.medium.is_some()
            || s.depth >= self.max_depth
            || scene.force_diffuse
            || (gbuffer && s.depth == 0)
        {
            return None;
        }
        // Specular vertices too, but where regularization would roughen
        // the BSDF.
        let as_built = !(self.regularize && s.any_non_specular);
        lane_surface(scene, record, s.ray.ray.d, lambda, as_built, out)
    }

    /// `begin` and `finish` for a specular vertex in a scene without
    /// media: the depth, the BSDF's draws and its sample from ωo (the
    /// scalar BSDF's own, in the frame the surface kernel built), the
    /// path's probabilities, the next ray (its medium stays none: there
    /// are no interfaces) and Russian roulette; no subsurface scattering
    /// (a `dielectric` has none).
    #[inline(always)]
    fn specular_step(
        &self,
        s: &mut VolPathState,
        scratch: &mut VolPathScratch,
        surface: &SurfaceOut,
        bxdf: DielectricBxDF,
        sampler: &mut Sampler,
    ) -> VertexStep {
        scratch.hit = None;
        scratch.bsdf = None;
        s.depth += 1;
        surface.write_context(&mut s.prev_ctx);
        let Some((bs, p_b, next)) =
            surface.specular_sample(bxdf, surface.wo, s.ray.ray.time, sampler)
        else {
            return VertexStep::DONE;
        };
        s.beta *= bs.f * (abs_dot(bs.wi, surface.ns) / bs.pdf);
        s.r_l = s.r_u / p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        // Without media or interfaces the next ray's medium stays none.
        s.ray = RayDifferential::new(next);
        russian_roulette(s, || sampler.get_1d(), None)
    }

    // The BSDF sample leaves from ωo itself here (the path tracer negates
    // the ray's direction).
    const DIFFUSE_SAMPLE_FROM_WO: bool = true;

    #[inline(always)]
    fn diffuse_begin(
        &self,
        s: &mut VolPathState,
        scratch: &mut VolPathScratch,
        lanes: &mut LaneVertices,
        k: usize,
        r: SampledSpectrum,
        draws: (Float, Point2f, Float, Point2f),
    ) -> LightRequest {
        s.depth += 1;
        scratch.hit = None;
        scratch.bsdf = None;
        lanes.begin(k, r, draws)
    }

    /// `finish` for a diffuse vertex, given the BSDF's answers.
    #[inline(always)]
    fn diffuse_finish(
        &self,
        scene: &Scene,
        s: &mut VolPathState,
        lanes: &LaneVertices,
        k: usize,
        light: Option<&LightAnswer>,
        draw: impl FnOnce() -> Float,
    ) -> VertexStep {
        let time = s.ray.ray.time;
        let shadow = light.and_then(|a| {
            let (f_hat, pdf_light) = lanes.light_answers(k);
            lane_shadow_query(scene, s, lanes, k, a, f_hat, pdf_light)
        });
        let done = VertexStep { shadow, done: true };
        lanes.write_context(k, &mut s.prev_ctx);
        let Some((wi, pdf, cos_over_pdf)) = lanes.sample(k) else {
            return done;
        };
        let f = lanes.r(k) * INV_PI;
        if f.is_black() {
            return done;
        }
        s.beta *= f * cos_over_pdf;
        s.r_l = s.r_u / pdf;
        s.specular_bounce = false;
        s.any_non_specular = true;
        // Without media the next ray's medium is none, as the hit's.
        s.ray = RayDifferential::new(lanes.spawn_ray(k, wi, time));
        russian_roulette(s, draw, shadow)
    }

    #[inline(always)]
    fn staged_begin(
        &self,
        s: &mut VolPathState,
        scratch: &mut VolPathScratch,
        lanes: &LaneVertices,
        k: usize,
        bsdf: BSDF,
        draws: (Float, Point2f, Float, Point2f),
    ) -> LightRequest {
        s.depth += 1;
        scratch.hit = None;
        let req;
        (req, scratch.wo, scratch.u, scratch.u2) = lanes.staged_begin(k, &bsdf, draws);
        scratch.bsdf = Some(bsdf);
        req
    }

    /// `finish` for a staged vertex (no media: its next ray's medium is
    /// none; no subsurface scattering: its materials have none).
    #[inline(always)]
    fn staged_finish(
        &self,
        scene: &Scene,
        s: &mut VolPathState,
        scratch: &mut VolPathScratch,
        lanes: &LaneVertices,
        k: usize,
        light: Option<&LightAnswer>,
        draw: impl FnOnce() -> Float,
    ) -> VertexStep {
        let Some(bsdf) = scratch.bsdf.as_ref() else {
            return VertexStep::DONE;
        };
        let pre = std::mem::take(&mut scratch.answers);
        let (wo, ns, time) = (scratch.wo, lanes.ns(k), s.ray.ray.time);
        // `surface_shadow_query`.
        let shadow = light.and_then(|a| {
            let (f_hat, scatter_pdf) = lanes.staged_light(k, bsdf, &pre, wo, a.ls.wi)?;
            lane_shadow_query(scene, s, lanes, k, a, f_hat, scatter_pdf)
        });
        let done = VertexStep { shadow, done: true };
        lanes.write_context(k, &mut s.prev_ctx);
        let Some((bs, p_b)) = pre.sample(bsdf, wo, scratch.u, scratch.u2) else {
            return done;
        };
        s.beta *= bs.f * (abs_dot(bs.wi, ns) / bs.pdf);
        s.r_l = s.r_u / p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        s.ray = RayDifferential::new(lanes.spawn_ray(k, bs.wi, time));
        russian_roulette(s, draw, done.shadow)
    }
}

/// `surface_shadow_query` at slot `k` of the lane vertices, given the
/// BSDF's value (times the cosine) and density toward light sample `a`.
#[inline(always)]
fn lane_shadow_query(
    scene: &Scene,
    s: &VolPathState,
    lanes: &LaneVertices,
    k: usize,
    a: &LightAnswer,
    f_hat: SampledSpectrum,
    scatter_pdf: Float,
) -> Option<ShadowQuery> {
    if f_hat.is_black() {
        return None;
    }
    let (ray, t_max) = lanes.shadow_ray(k, s.ray.ray.time, a.ls.p_light, a.ls.n_light);
    let ld = unoccluded_ld(scene, a, s, f_hat, scatter_pdf);
    Some(ShadowQuery { ray, t_max, ld })
}

/// The end of a surface vertex: Russian roulette on the throughput
/// (without the refraction scale and the path's probability), after its
/// draw (`draw`, the vertex's next 1-D draw); the path ends where the
/// throughput is black.
#[inline(always)]
fn russian_roulette(
    s: &mut VolPathState,
    draw: impl FnOnce() -> Float,
    shadow: Option<ShadowQuery>,
) -> VertexStep {
    let done = VertexStep { shadow, done: true };
    if s.beta.is_black() {
        return done;
    }
    let rr_beta = s.beta * s.eta_scale / s.r_u.average();
    let u_rr = draw();
    let m = rr_beta.max_component_value();
    if m < 1.0 && s.depth > 1 {
        let q = (1.0 - m).max(0.0);
        if u_rr < q {
            return done;
        }
        s.beta /= 1.0 - q;
    }
    VertexStep {
        shadow: done.shadow,
        done: false,
    }
}

/// The shadow query of a light sample at a surface vertex of a path
/// through a scene without media or interfaces: the contribution
/// [`VolPathIntegrator::sample_ld`] gives there with a transmittance of
/// one (the same bits), if nothing blocks the ray.
fn surface_shadow_query(
    scene: &Scene,
    origins: &mut VertexOrigins,
    bsdf: &BSDF,
    a: &LightAnswer,
    s: &VolPathState,
    pre: &BsdfAnswers,
) -> Option<ShadowQuery> {
    let si = origins.si;
    let ls = &a.ls;
    let wi = ls.wi;
    let f_hat = pre.light_f(bsdf, si.wo, wi) * abs_dot(wi, si.shading.n);
    if f_hat.is_black() {
        return None;
    }
    let scatter_pdf = pre.light_pdf(bsdf, si.wo, wi);
    let p_to = ls.p_light.midpoint();
    let pf = origins.toward(p_to - si.p());
    let ray = spawn_ray_from_origin_to_surface(pf, si.time, p_to, ls.p_light.error(), ls.n_light);
    let ld = unoccluded_ld(scene, a, s, f_hat, scatter_pdf);
    Some(ShadowQuery {
        ray,
        t_max: 1.0 - SHADOW_EPSILON,
        ld,
    })
}

/// The contribution of light sample `a` at a surface vertex of a path in
/// state `s` through a scene without media or interfaces, if nothing
/// blocks it: [`ld_value`] with a transmittance of one.
#[inline(always)]
fn unoccluded_ld(
    scene: &Scene,
    a: &LightAnswer,
    s: &VolPathState,
    f_hat: SampledSpectrum,
    scatter_pdf: Float,
) -> SampledSpectrum {
    let one = SampledSpectrum::new(1.0);
    ld_value(
        scene.lights[a.light as usize].light_type().is_delta(),
        s.beta,
        f_hat,
        a.ls.l,
        ShadowTransmittance {
            t_ray: one,
            r_u: one,
            r_l: one,
        },
        s.r_u,
        a.p * a.ls.pdf,
        scatter_pdf,
    )
}

/// A light sample's contribution (pbrt-v4 `VolPathIntegrator::SampleLd`'s
/// end): `beta` and `r_p` are the path's throughput and rescaled
/// unidirectional probability at the vertex.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn ld_value(
    delta: bool,
    beta: SampledSpectrum,
    f_hat: SampledSpectrum,
    l: SampledSpectrum,
    st: ShadowTransmittance,
    r_p: SampledSpectrum,
    light_pdf: Float,
    scatter_pdf: Float,
) -> SampledSpectrum {
    let ShadowTransmittance { t_ray, r_u, r_l } = st;
    let r_l = r_l * r_p * light_pdf;
    let r_u = r_u * r_p * scatter_pdf;
    if delta {
        beta * f_hat * t_ray * l / r_l.average()
    } else {
        beta * f_hat * t_ray * l / (r_l + r_u).average()
    }
}

/// A surface vertex between its two halves (see
/// [`crate::integrator::path`]'s `SurfaceScratch`), with the medium the
/// ray arrived in.
#[derive(Default)]
pub(crate) struct VolPathScratch {
    hit: Option<PrimitiveIntersection>,
    bsdf: Option<BSDF>,
    sides: [Option<Point3f>; 2],
    u: Float,
    u2: Point2f,
    ray_medium: Option<MediumId>,
    answers: BsdfAnswers,
    /// ωo of a staged vertex (which has no `hit`).
    wo: Vector3f,
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
