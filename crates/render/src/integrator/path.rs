//! The path tracer (pbrt-v4 `PathIntegrator`; book section 13.4): next-event
//! estimation with multiple importance sampling, Russian roulette and
//! optional BSDF regularization.

use super::bsdf_stage::{BsdfAnswers, BsdfQuery};
use super::diffuse_lanes::{lane_surface, LaneShade, LaneVertices, SurfaceOut};
use super::direct::{light_request, light_shadow_query, LightAnswer, LightRequest, ShadowQuery};
use super::vertex::{li_by_vertices, Begin, VertexIntegrator, VertexStep};
use super::{skip_intersection, RayIntegrator, Scene, VertexOrigins};
use crate::bxdf::{DielectricBxDF, BSDF};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::lightsampler::LightSampler;
use crate::primitive::{HitRecord, PrimitiveIntersection};
use crate::sampler::Sampler;
use crate::sampling::power_heuristic;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::{Float, INV_PI};
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// The state of a path being traced: the locals of pbrt-v4's
/// `PathIntegrator::Li` (and the path fields of its wavefront
/// `RayWorkItem`), updated at every vertex.
pub(crate) struct PathState {
    /// The ray leaving the last vertex (the camera ray at first).
    pub(crate) ray: RayDifferential,
    /// The radiance gathered so far.
    pub(crate) l: SampledSpectrum,
    /// The path throughput: the product of BSDF values and cosines over
    /// sampling probabilities, and Russian roulette's weights.
    pub(crate) beta: SampledSpectrum,
    /// Scattering events so far.
    pub(crate) depth: i32,
    /// The BSDF sampling density of the last bounce's direction, for MIS
    /// weights of emission the ray hits.
    pub(crate) p_b: Float,
    /// The product of the squared relative indices of refraction crossed,
    /// taken out of `beta` for Russian roulette.
    pub(crate) eta_scale: Float,
    /// The last bounce was specular (or passed through an interface): hit
    /// emission is not MIS-weighted against light sampling.
    pub(crate) specular_bounce: bool,
    /// Some bounce so far was not specular (for BSDF regularization).
    pub(crate) any_non_specular: bool,
    /// The last scattering vertex, for the light sampler's MIS density of
    /// emission the ray hits.
    pub(crate) prev_ctx: LightSampleContext,
}

impl PathState {
    /// The state of a path starting with a camera ray.
    #[inline(always)]
    pub(crate) fn new(ray: RayDifferential) -> Self {
        PathState {
            ray,
            l: SampledSpectrum::new(0.0),
            beta: SampledSpectrum::new(1.0),
            depth: 0,
            p_b: 1.0,
            eta_scale: 1.0,
            specular_bounce: false,
            any_non_specular: false,
            prev_ctx: LightSampleContext::default(),
        }
    }
}

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
        visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        li_by_vertices(self, scene, ray, lambda, sampler, visible)
    }
}

/// A surface vertex between its two halves: the hit, its BSDF, the
/// offset origins computed so far and the BSDF's sampler draws.
#[derive(Default)]
pub(crate) struct SurfaceScratch {
    hit: Option<PrimitiveIntersection>,
    bsdf: Option<BSDF>,
    sides: [Option<Point3f>; 2],
    u: Float,
    u2: Point2f,
    answers: BsdfAnswers,
    /// ωo of a staged vertex (which has no `hit`).
    wo: Vector3f,
}

impl VertexIntegrator for PathIntegrator {
    type State = PathState;
    type Scratch = SurfaceScratch;

    #[inline(always)]
    fn start(&self, ray: RayDifferential) -> PathState {
        PathState::new(ray)
    }

    #[inline(always)]
    fn ray(s: &PathState) -> &RayDifferential {
        &s.ray
    }

    #[inline(always)]
    fn radiance(s: &mut PathState) -> &mut SampledSpectrum {
        &mut s.l
    }

    #[inline(always)]
    fn bsdf_query<'a>(
        s: &PathState,
        scratch: &'a SurfaceScratch,
        light: Option<&LightAnswer>,
    ) -> Option<BsdfQuery<'a>> {
        let bsdf = scratch.bsdf.as_ref()?;
        Some(BsdfQuery {
            bsdf,
            wo_light: scratch.hit.as_ref().map_or(scratch.wo, |h| h.si.wo),
            wi_light: light.map(|a| a.ls.wi),
            wo: -s.ray.ray.d,
            u: scratch.u,
            u2: scratch.u2,
        })
    }

    #[inline(always)]
    fn bsdf_answers(scratch: &mut SurfaceScratch) -> &mut BsdfAnswers {
        &mut scratch.answers
    }

    /// The first half of one vertex of pbrt-v4's `PathIntegrator::Li`: the
    /// ray `s.ray` ended at `record` (`None`: it escaped). Adds emission to
    /// `s.l`, builds the BSDF and takes the vertex's sampler draws; a
    /// non-specular BSDF then asks for a light sample.
    #[inline(always)]
    fn begin(
        &self,
        scene: &Scene,
        s: &mut PathState,
        record: Option<HitRecord>,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        visible: Option<&mut VisibleSurface>,
        scratch: &mut SurfaceScratch,
    ) -> Begin {
        const DONE: Begin = Begin::Step(VertexStep::DONE);
        let light_sampler: &LightSampler = &scene.light_sampler;
        // Built in place and used by reference: the intersection and the
        // BSDF are large. (Assigned straight from the call, so that the
        // call writes into the scratch: through `Option::and_then` it was
        // built on the stack and copied.)
        scratch.hit = match record {
            Some(h) => scene.aggregate.interaction(&s.ray.ray, &h),
            None => None,
        };
        let Some(hit) = scratch.hit.as_mut() else {
            // Escaped: infinite lights, weighted by MIS unless the last
            // bounce could not have been light-sampled.
            for &li in &scene.infinite_lights {
                let light = &scene.lights[li as usize];
                let le = light.le(&s.ray.ray, lambda);
                if le.is_black() {
                    continue;
                }
                if s.depth == 0 || s.specular_bounce {
                    s.l += s.beta * le;
                } else {
                    let p_l = light_sampler.pmf(&s.prev_ctx, li)
                        * light.pdf_li(&s.prev_ctx, s.ray.ray.d, true);
                    let w_b = power_heuristic(1.0, s.p_b, 1.0, p_l);
                    s.l += s.beta * le * w_b;
                }
            }
            return DONE;
        };
        // Emission from an area light that was hit.
        let le = scene.le(hit, -s.ray.ray.d, lambda);
        if !le.is_black() {
            if s.depth == 0 || s.specular_bounce {
                s.l += s.beta * le;
            } else if let Some(al) = hit.area_light {
                let light = &scene.lights[al as usize];
                let p_l = light_sampler.pmf(&s.prev_ctx, al)
                    * light.pdf_li(&s.prev_ctx, s.ray.ray.d, true);
                let w_l = power_heuristic(1.0, s.p_b, 1.0, p_l);
                s.l += s.beta * le * w_l;
            }
        }
        scratch.bsdf = scene.get_bsdf(hit, &s.ray, lambda, sampler);
        let Some(bsdf) = scratch.bsdf.as_mut() else {
            s.specular_bounce = true;
            s.ray = skip_intersection(&s.ray, hit);
            return Begin::Step(VertexStep::NEXT);
        };
        if s.depth == 0 {
            if let Some(v) = visible {
                *v = scene.visible_surface(hit, bsdf);
            }
        }
        if self.regularize && s.any_non_specular {
            bsdf.regularize();
        }
        if s.depth == self.max_depth {
            return DONE;
        }
        s.depth += 1;
        // Sampler draws in pbrt-v4's order: the light's two, then the
        // BSDF's two (taken together when there is a light sample).
        if bsdf.flags().is_non_specular() {
            let (u_light, u_light_2d, u, u2) = sampler.get_vertex_samples();
            (scratch.u, scratch.u2) = (u, u2);
            let mut origins = VertexOrigins::new(&hit.si);
            let req = light_request(&mut origins, bsdf, u_light, u_light_2d);
            scratch.sides = origins.sides();
            Begin::Light(req)
        } else {
            (scratch.u, scratch.u2) = (sampler.get_1d(), sampler.get_2d());
            scratch.sides = [None, None];
            Begin::Step(self.finish(scene, s, lambda, sampler, scratch, None))
        }
    }

    /// The second half: the light sample's shadow query, then the BSDF
    /// sample that continues the path, and Russian roulette.
    #[inline(always)]
    fn finish(
        &self,
        scene: &Scene,
        s: &mut PathState,
        _lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut SurfaceScratch,
        light: Option<&LightAnswer>,
    ) -> VertexStep {
        let (Some(hit), Some(bsdf)) = (scratch.hit.as_ref(), scratch.bsdf.as_ref()) else {
            return VertexStep::DONE;
        };
        let si = &hit.si;
        let pre = std::mem::take(&mut scratch.answers);
        let mut origins = VertexOrigins::with_sides(si, scratch.sides);
        let shadow = light
            .and_then(|a| light_shadow_query(scene, &mut origins, bsdf, a, &pre))
            .map(|q| ShadowQuery {
                ld: s.beta * q.ld,
                ..q
            });
        let (u, u2) = (scratch.u, scratch.u2);
        s.prev_ctx = LightSampleContext::from_si(si);
        let wo = -s.ray.ray.d;
        let Some((bs, p_b)) = pre.sample(bsdf, wo, u, u2) else {
            return VertexStep { shadow, done: true };
        };
        s.beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
        s.p_b = p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        s.ray = RayDifferential::new(origins.spawn_ray(bs.wi));
        russian_roulette(s, || sampler.get_1d(), shadow)
    }

    #[inline(always)]
    fn lane_hit(
        &self,
        scene: &Scene,
        s: &PathState,
        record: &HitRecord,
        lambda: &SampledWavelengths,
        gbuffer: bool,
        out: &mut LaneVertices,
    ) -> Option<LaneShade> {
        // The vertices `begin` ends (the last one) or that draw or write
        // more than a lane vertex does are left to it; so are specular
        // ones where regularization would roughen the BSDF.
        if s.depth >= self.max_depth || scene.force_diffuse || (gbuffer && s.depth == 0) {
            return None;
        }
        let as_built = !(self.regularize && s.any_non_specular);
        lane_surface(scene, record, s.ray.ray.d, lambda, as_built, out)
    }

    /// `begin` and `finish` for a specular vertex: the depth, the BSDF's
    /// sampler draws and its sample (the scalar BSDF's own, in the frame
    /// the surface kernel built), the next ray and Russian roulette.
    #[inline(always)]
    fn specular_step(
        &self,
        s: &mut PathState,
        scratch: &mut SurfaceScratch,
        surface: &SurfaceOut,
        bxdf: DielectricBxDF,
        sampler: &mut Sampler,
    ) -> VertexStep {
        scratch.hit = None;
        scratch.bsdf = None;
        s.depth += 1;
        surface.write_context(&mut s.prev_ctx);
        let wo = -s.ray.ray.d;
        let Some((bs, p_b, next)) = surface.specular_sample(bxdf, wo, s.ray.ray.time, sampler)
        else {
            return VertexStep::DONE;
        };
        s.beta *= bs.f * (abs_dot(bs.wi, surface.ns) / bs.pdf);
        s.p_b = p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        s.ray = RayDifferential::new(next);
        russian_roulette(s, || sampler.get_1d(), None)
    }

    /// `begin`'s steps for a diffuse vertex: the depth, the sampler draws,
    /// the light request (the surface kernel built the interaction and the
    /// BSDF's frame at slot `k`).
    #[inline(always)]
    fn diffuse_begin(
        &self,
        s: &mut PathState,
        scratch: &mut SurfaceScratch,
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
        s: &mut PathState,
        lanes: &LaneVertices,
        k: usize,
        light: Option<&LightAnswer>,
        draw: impl FnOnce() -> Float,
    ) -> VertexStep {
        let time = s.ray.ray.time;
        let shadow = light.and_then(|a| {
            let (f, pdf_light) = lanes.light_answers(k);
            lane_shadow_query(scene, s, lanes, k, a, f, pdf_light)
        });
        lanes.write_context(k, &mut s.prev_ctx);
        let Some((wi, pdf, cos_over_pdf)) = lanes.sample(k) else {
            return VertexStep { shadow, done: true };
        };
        let f = lanes.r(k) * INV_PI;
        if f.is_black() {
            return VertexStep { shadow, done: true };
        }
        s.beta *= f * cos_over_pdf;
        s.p_b = pdf;
        s.specular_bounce = false;
        s.any_non_specular = true;
        s.ray = RayDifferential::new(lanes.spawn_ray(k, wi, time));
        russian_roulette(s, draw, shadow)
    }

    #[inline(always)]
    fn staged_begin(
        &self,
        s: &mut PathState,
        scratch: &mut SurfaceScratch,
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

    /// `finish` for a staged vertex.
    #[inline(always)]
    fn staged_finish(
        &self,
        scene: &Scene,
        s: &mut PathState,
        scratch: &mut SurfaceScratch,
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
        // `light_shadow_query`.
        let shadow = light.and_then(|a| {
            let (f, pdf_light) = lanes.staged_light(k, bsdf, &pre, wo, a.ls.wi)?;
            lane_shadow_query(scene, s, lanes, k, a, f, pdf_light)
        });
        lanes.write_context(k, &mut s.prev_ctx);
        let Some((bs, p_b)) = pre.sample(bsdf, -s.ray.ray.d, scratch.u, scratch.u2) else {
            return VertexStep { shadow, done: true };
        };
        s.beta *= bs.f * (abs_dot(bs.wi, ns) / bs.pdf);
        s.p_b = p_b;
        s.specular_bounce = bs.is_specular();
        s.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        s.ray = RayDifferential::new(lanes.spawn_ray(k, bs.wi, time));
        russian_roulette(s, draw, shadow)
    }
}

/// `light_shadow_query` at slot `k` of the lane vertices, given the
/// BSDF's value (times the cosine) and density toward light sample `a`,
/// its contribution multiplied by the path's throughput.
#[inline(always)]
fn lane_shadow_query(
    scene: &Scene,
    s: &PathState,
    lanes: &LaneVertices,
    k: usize,
    a: &LightAnswer,
    f: SampledSpectrum,
    pdf_light: Float,
) -> Option<ShadowQuery> {
    if f.is_black() {
        return None;
    }
    let ls = &a.ls;
    let (ray, t_max) = lanes.shadow_ray(k, s.ray.ray.time, ls.p_light, ls.n_light);
    let p_l = a.p * ls.pdf;
    let ld = if scene.lights[a.light as usize].light_type().is_delta() {
        ls.l * f / p_l
    } else {
        let w_l = power_heuristic(1.0, p_l, 1.0, pdf_light);
        ls.l * f * (w_l / p_l)
    };
    Some(ShadowQuery {
        ray,
        t_max,
        ld: s.beta * ld,
    })
}

/// The end of a vertex: Russian roulette on the throughput (without the
/// refraction scale; `draw` gives the vertex's next 1-D draw, taken only
/// where the roulette runs), then the path ends where it is black.
#[inline(always)]
fn russian_roulette(
    s: &mut PathState,
    draw: impl FnOnce() -> Float,
    shadow: Option<ShadowQuery>,
) -> VertexStep {
    let rr_beta = s.beta * s.eta_scale;
    let m = rr_beta.max_component_value();
    if m < 1.0 && s.depth > 1 {
        let q = (1.0 - m).max(0.0);
        if draw() < q {
            return VertexStep { shadow, done: true };
        }
        s.beta /= 1.0 - q;
    }
    let done = s.beta.is_black();
    VertexStep { shadow, done }
}
