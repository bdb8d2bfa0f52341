//! Direct lighting at a path vertex (pbrt-v4 `PathIntegrator::SampleLd`;
//! book section 13.4.3): a light chosen by the light sampler, a point on it,
//! and a shadow ray, weighted against BSDF sampling by multiple importance
//! sampling; plus the vertex's cached offset ray origins the light sample,
//! the shadow ray and the next bounce share.

use super::bsdf_stage::BsdfAnswers;
use super::Scene;
use crate::bxdf::BSDF;
use crate::light::{Light, LightLiSample, LightSampleContext};
use crate::lightsampler::{LightChoice, LightSampler, SampledLight};
use crate::shape::{sample_solid_angle_points, SolidAnglePoint, SolidAngleQuery};
use crate::simd::SimdLevel;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::tuple::*;

/// A path vertex's ray origins, offset off the surface toward either of
/// its sides (pbrt-v4's `OffsetRayOrigin`), each computed at most once:
/// the light sample's reference point, the shadow ray and the next bounce
/// usually leave by the same side. The offset depends on the direction
/// only through that side, so a cached origin is the one a fresh
/// computation would give.
pub(crate) struct VertexOrigins<'a> {
    /// The surface point.
    pub si: &'a SurfaceInteraction,
    /// Origins for directions with `dot(w, n) ≥ 0` and `< 0` (or NaN
    /// tests, which count as the first side, as in `offset_ray_origin`).
    sides: [Option<Point3f>; 2],
}

impl<'a> VertexOrigins<'a> {
    /// No origin computed yet.
    #[inline]
    pub fn new(si: &'a SurfaceInteraction) -> Self {
        VertexOrigins {
            si,
            sides: [None, None],
        }
    }

    /// The origins `sides` computed for `si` earlier ([`Self::sides`]).
    #[inline]
    pub fn with_sides(si: &'a SurfaceInteraction, sides: [Option<Point3f>; 2]) -> Self {
        VertexOrigins { si, sides }
    }

    /// The origins computed so far, to continue with later
    /// ([`Self::with_sides`]).
    #[inline]
    pub fn sides(&self) -> [Option<Point3f>; 2] {
        self.sides
    }

    /// `si.offset_ray_origin(w)`.
    #[inline(always)]
    pub fn toward(&mut self, w: Vector3f) -> Point3f {
        // The test `offset_ray_origin` makes.
        let side = (dot(w, self.si.n) < 0.0) as usize;
        match self.sides[side] {
            Some(p) => p,
            None => {
                let p = self.si.offset_ray_origin(w);
                self.sides[side] = Some(p);
                p
            }
        }
    }

    /// `si.spawn_ray(d)`.
    #[inline]
    pub fn spawn_ray(&mut self, d: Vector3f) -> Ray {
        Ray::with_time(self.toward(d), d, self.si.time, None)
    }
}

/// A light sample's contribution waiting for its shadow ray: `ld` counts
/// when nothing blocks `ray` in (0, `t_max`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadowQuery {
    /// The shadow ray, from the vertex toward the point on the light.
    pub ray: Ray,
    /// Its extent.
    pub t_max: Float,
    /// The unoccluded contribution.
    pub ld: SampledSpectrum,
}

/// Samples direct lighting at a surface hit with multiple importance
/// sampling (pbrt-v4 `PathIntegrator::SampleLd`), given its two sampler
/// draws: `u` chooses the light and `u_light` the point on it. `origins`
/// holds the vertex's offset ray origins (shared with the shadow ray and
/// the next bounce).
#[inline]
pub(crate) fn sample_ld(
    scene: &Scene,
    light_sampler: &LightSampler,
    origins: &mut VertexOrigins,
    bsdf: &BSDF,
    lambda: &SampledWavelengths,
    u: Float,
    u_light: Point2f,
) -> SampledSpectrum {
    // In three steps, which the wavefront loop runs apart (answering its
    // lanes' requests together): the request, the light's sample, the
    // shadow query.
    let req = light_request(origins, bsdf, u, u_light);
    let query = answer_light(scene, light_sampler, &req, lambda)
        .and_then(|a| light_shadow_query(scene, origins, bsdf, &a, &BsdfAnswers::default()));
    match query {
        Some(q) if !scene.intersect_p(&q.ray, q.t_max) => q.ld,
        _ => SampledSpectrum::new(0.0),
    }
}

/// What choosing and sampling a light needs of a surface vertex.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightRequest {
    /// The light-sampling context ([`surface_light_context`]).
    pub ctx: LightSampleContext,
    /// The draw that chooses the light.
    pub u: Float,
    /// The draw that chooses the point on it.
    pub u_light: Point2f,
    /// For a BSDF that is zero across hemispheres, its shading normal and
    /// ωo's component along it (light culling, [`light_culled`]).
    pub hemisphere: Option<(Vector3f, Float)>,
}

/// A chosen light and its sample, before the BSDF and the shadow ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightAnswer {
    /// The light's index.
    pub light: u32,
    /// The probability of choosing it.
    pub p: Float,
    /// Its sample.
    pub ls: LightLiSample,
}

/// The light request of a surface vertex with the BSDF `bsdf`.
#[inline]
pub(crate) fn light_request(
    origins: &mut VertexOrigins,
    bsdf: &BSDF,
    u: Float,
    u_light: Point2f,
) -> LightRequest {
    let ctx = surface_light_context(origins, bsdf);
    let hemisphere = bsdf.bxdf.zero_across_hemispheres().then(|| {
        let z = bsdf.shading_frame.z;
        (z, dot(origins.si.wo, z))
    });
    LightRequest {
        ctx,
        u,
        u_light,
        hemisphere,
    }
}

/// Chooses a light for `req` and samples it: `None` when the choice
/// fails, is culled, or its sample carries nothing.
#[inline]
pub(crate) fn answer_light(
    scene: &Scene,
    light_sampler: &LightSampler,
    req: &LightRequest,
    lambda: &SampledWavelengths,
) -> Option<LightAnswer> {
    let sampled = unculled(scene, req, light_sampler.sample(&req.ctx, req.u))?;
    let light = &scene.lights[sampled.light as usize];
    answer_with(
        sampled,
        light.sample_li(&req.ctx, req.u_light, lambda, true),
    )
}

/// The light the light sampler chose for `req`, unless it is culled.
#[inline(always)]
fn unculled(
    scene: &Scene,
    req: &LightRequest,
    sampled: Option<SampledLight>,
) -> Option<SampledLight> {
    let sampled = sampled?;
    (!light_culled(scene, sampled.light, req.ctx.p(), req.hemisphere)).then_some(sampled)
}

/// The answer of a chosen light and its sample, if that carries light.
#[inline(always)]
fn answer_with(sampled: SampledLight, ls: Option<LightLiSample>) -> Option<LightAnswer> {
    let ls = ls?;
    if ls.l.is_black() || ls.pdf == 0.0 {
        return None;
    }
    Some(LightAnswer {
        light: sampled.light,
        p: sampled.p,
        ls,
    })
}

/// The buffers of [`answer_lights`], kept from batch to batch.
#[derive(Default)]
pub(crate) struct LightBatch {
    choices: Vec<LightChoice>,
    chosen: Vec<Option<SampledLight>>,
    queries: Vec<SolidAngleQuery>,
    pending: Vec<(usize, SampledLight)>,
    points: Vec<SolidAnglePoint>,
}

/// [`answer_light`] of every request in `requests` (`lambda(k)` gives
/// request `k`'s wavelengths), into `out` (cleared first): the same
/// answers, with the light BVH's descent and the triangle lights'
/// solid-angle samples, the costly parts, taken lane-parallel at
/// `level`'s width.
pub(crate) fn answer_lights<'w>(
    scene: &Scene,
    light_sampler: &LightSampler,
    level: SimdLevel,
    requests: &[LightRequest],
    lambda: impl Fn(usize) -> &'w SampledWavelengths,
    batch: &mut LightBatch,
    out: &mut Vec<Option<LightAnswer>>,
) {
    out.clear();
    batch.queries.clear();
    batch.pending.clear();
    // Every request's light, chosen together where the sampler descends a
    // BVH (lane-parallel).
    batch.chosen.clear();
    if let LightSampler::Bvh(bvh) = light_sampler {
        batch.choices.clear();
        batch
            .choices
            .extend(requests.iter().map(|r| LightChoice::new(&r.ctx, r.u)));
        bvh.sample_batch(level, &batch.choices, &mut batch.chosen);
    } else {
        batch
            .chosen
            .extend(requests.iter().map(|r| light_sampler.sample(&r.ctx, r.u)));
    }
    for (k, req) in requests.iter().enumerate() {
        let Some(sampled) = unculled(scene, req, batch.chosen[k]) else {
            out.push(None);
            continue;
        };
        let light = &scene.lights[sampled.light as usize];
        if let Light::DiffuseArea(area) = light {
            if let Some(q) = area.triangle_query(&req.ctx, req.u_light) {
                batch.queries.push(q);
                batch.pending.push((k, sampled));
                out.push(None);
                continue;
            }
        }
        let ls = light.sample_li(&req.ctx, req.u_light, lambda(k), true);
        out.push(answer_with(sampled, ls));
    }
    sample_solid_angle_points(level, &batch.queries, &mut batch.points);
    for (&(k, sampled), point) in batch.pending.iter().zip(&batch.points) {
        let Light::DiffuseArea(area) = &scene.lights[sampled.light as usize] else {
            continue;
        };
        let req = &requests[k];
        let ls = area.sample_li_from_point(&req.ctx, req.u_light, point, lambda(k));
        out[k] = answer_with(sampled, ls);
    }
}

/// The shadow query of a light sample at a surface vertex: the BSDF's
/// value toward it, weighted by multiple importance sampling; `None` when
/// the BSDF is zero there.
#[inline]
pub(crate) fn light_shadow_query(
    scene: &Scene,
    origins: &mut VertexOrigins,
    bsdf: &BSDF,
    a: &LightAnswer,
    pre: &BsdfAnswers,
) -> Option<ShadowQuery> {
    let si = origins.si;
    let ls = &a.ls;
    let wo = si.wo;
    let wi = ls.wi;
    let f = pre.light_f(bsdf, wo, wi) * abs_dot(wi, si.shading.n);
    if f.is_black() {
        return None;
    }
    let light = &scene.lights[a.light as usize];
    let (ray, t_max) = scene.shadow_ray_from(origins, ls.p_light, ls.n_light);
    let p_l = a.p * ls.pdf;
    let ld = if light.light_type().is_delta() {
        ls.l * f / p_l
    } else {
        let p_b = pre.light_pdf(bsdf, wo, wi);
        let w_l = crate::sampling::power_heuristic(1.0, p_l, 1.0, p_b);
        ls.l * f * (w_l / p_l)
    };
    Some(ShadowQuery { ray, t_max, ld })
}

/// The light-sampling context of a surface vertex, its point nudged off
/// the surface to the side the BSDF can receive light from (pbrt-v4
/// `SampleLd`'s start), with the vertex's cached offset origins.
#[inline]
pub(crate) fn surface_light_context(
    origins: &mut VertexOrigins,
    bsdf: &BSDF,
) -> LightSampleContext {
    let si = origins.si;
    let mut ctx = LightSampleContext::from_si(si);
    let flags = bsdf.flags();
    if flags.is_reflective() && !flags.is_transmissive() {
        ctx.pi = Point3fi::from(origins.toward(si.wo));
    } else if flags.is_transmissive() && !flags.is_reflective() {
        ctx.pi = Point3fi::from(origins.toward(-si.wo));
    }
    ctx
}

/// True when a sample of light `light` cannot contribute at the surface
/// point `si` seen from the light-sampling point `p`: the light emits
/// nothing toward it, or it lies wholly behind a BSDF that is zero across
/// hemispheres (triangle emitters only; see [`crate::light::LightCull`]).
#[inline]
pub(crate) fn light_sample_culled(
    scene: &Scene,
    light: u32,
    p: Point3f,
    bsdf: &BSDF,
    si: &SurfaceInteraction,
) -> bool {
    let Some(Some(cull)) = scene.light_cull.get(light as usize) else {
        return false;
    };
    if cull.faces_away_from(p) {
        return true;
    }
    if bsdf.bxdf.zero_across_hemispheres() {
        let z = bsdf.shading_frame.z;
        if cull.behind(p, z, dot(si.wo, z)) {
            return true;
        }
    }
    false
}

/// [`light_sample_culled`] given the BSDF's [`LightRequest::hemisphere`].
#[inline]
pub(crate) fn light_culled(
    scene: &Scene,
    light: u32,
    p: Point3f,
    hemisphere: Option<(Vector3f, Float)>,
) -> bool {
    let Some(Some(cull)) = scene.light_cull.get(light as usize) else {
        return false;
    };
    if cull.faces_away_from(p) {
        return true;
    }
    matches!(hemisphere, Some((z, wo_z)) if cull.behind(p, z, wo_z))
}
