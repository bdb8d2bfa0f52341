//! The render-ready scene (pbrt-v4 `Integrator`'s scene members and its
//! `Intersect`, `IntersectP` and `Unoccluded`; book section 1.3.3, and
//! `SurfaceInteraction::GetBSDF` of section 10.1.1): the camera, film,
//! sampler, geometry, lights and materials an integrator renders with, and
//! the ray queries it makes of them, counted for `--stats`.

use super::direct::VertexOrigins;
use crate::bxdf::BSDF;
use crate::camera::Camera;
use crate::film::{Film, VisibleSurface};
use crate::filter::Filter;
use crate::light::{Light, LightCull};
use crate::lightsampler::LightSampler;
use crate::material::MaterialSet;
use crate::medium::Medium;
use crate::primitive::{HitRecord, PrimitiveAggregate, PrimitiveIntersection};
use crate::sampler::{SampleSource, Sampler};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::{CameraDifferentials, SurfaceInteraction};
use rpbrt_geometry::ray::{
    spawn_ray_from_origin_to_surface, spawn_ray_to_surface, Ray, RayDifferential, SHADOW_EPSILON,
};
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use std::sync::atomic::{AtomicU64, Ordering};

/// Counters shared by all threads (for `--stats`).
#[derive(Debug, Default)]
pub struct RayCounters {
    /// Camera rays generated.
    pub camera_rays: AtomicU64,
    /// Closest-hit queries (camera and indirect rays).
    pub intersection_rays: AtomicU64,
    /// Shadow (any-hit) queries.
    pub shadow_rays: AtomicU64,
}

thread_local! {
    /// This thread's closest-hit and shadow query counts not yet added to
    /// a scene's shared [`RayCounters`]: counting in shared atomics would
    /// bounce their cache line between threads on every ray.
    static LOCAL_RAY_COUNTS: std::cell::Cell<(u64, u64)> = const { std::cell::Cell::new((0, 0)) };
}

impl RayCounters {
    /// Forgets the calling thread's pending counts (at the start of a
    /// unit of work whose counts [`RayCounters::flush_local`] will add).
    pub(crate) fn reset_local() {
        LOCAL_RAY_COUNTS.with(|c| c.set((0, 0)));
    }

    /// Adds the calling thread's pending counts to these counters.
    pub(crate) fn flush_local(&self) {
        let (closest, shadow) = LOCAL_RAY_COUNTS.with(|c| c.replace((0, 0)));
        self.intersection_rays.fetch_add(closest, Ordering::Relaxed);
        self.shadow_rays.fetch_add(shadow, Ordering::Relaxed);
    }
}

/// Everything an integrator needs to trace rays and shade hits.
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// The film (written by the render loop).
    pub film: Film,
    /// The sampler prototype (cloned per tile).
    pub sampler: Sampler,
    /// The pixel filter.
    pub filter: Filter,
    /// All geometry under its acceleration structure (shared: an
    /// interactive render's viewers pick points with it while it renders).
    pub aggregate: std::sync::Arc<PrimitiveAggregate>,
    /// All lights; area lights are referenced by index from primitives.
    pub lights: Vec<Light>,
    /// Indices of the infinite lights in `lights`.
    pub infinite_lights: Vec<u32>,
    /// Per light, the tests that recognise samples of it that cannot
    /// contribute (triangle emitters only; see [`LightCull`]).
    pub light_cull: Vec<Option<LightCull>>,
    /// The light sampler chosen by the integrator.
    pub light_sampler: LightSampler,
    /// The materials, indexed by the primitives' material ids.
    pub materials: MaterialSet,
    /// The participating media, indexed by the rays' and primitives'
    /// medium ids.
    pub media: Vec<Medium>,
    /// True when the scene has media or `interface` surfaces: shadow rays
    /// must then pass through interfaces and be attenuated by media.
    pub has_volumes: bool,
    /// Camera information for texture-filtering footprints of rays without
    /// differentials.
    pub camera_differentials: CameraDifferentials,
    /// Samples per pixel (for the footprint scale).
    pub samples_per_pixel: i32,
    /// `--disable-texture-filtering`.
    pub disable_texture_filtering: bool,
    /// `--force-diffuse`.
    pub force_diffuse: bool,
    /// Ray counters.
    pub counters: RayCounters,
}

impl Scene {
    /// Renders from `camera` from now on (a camera moved by an interactive
    /// render: [`crate::camera::Camera::placed`]), with what depends on it:
    /// the minimum differentials and a G-buffer film's camera space. The
    /// geometry, lights and media stay where the scene put them.
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera_differentials = camera.camera_differentials();
        self.film.place_camera(&camera.base().camera_transform);
        self.camera = camera;
    }

    /// The bounds of the geometry.
    pub fn bounds(&self) -> Bounds3f {
        self.aggregate.bounds()
    }

    /// The closest hit along `ray` in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        LOCAL_RAY_COUNTS.with(|c| {
            let (closest, shadow) = c.get();
            c.set((closest + 1, shadow));
        });
        self.aggregate.intersect(ray, t_max)
    }

    /// The closest hit along `ray` in (0, t_max) without its interaction
    /// (build it with `aggregate.interaction` when needed: bit for bit the
    /// one [`Scene::intersect`] gives).
    #[inline]
    pub fn intersect_record(&self, ray: &Ray, t_max: Float) -> Option<HitRecord> {
        LOCAL_RAY_COUNTS.with(|c| {
            let (closest, shadow) = c.get();
            c.set((closest + 1, shadow));
        });
        self.aggregate.intersect_record(ray, t_max)
    }

    /// [`Scene::intersect_record`] of each ray in `rays` (with no bound on
    /// the ray parameter), into `out` (cleared first): a batch of rays
    /// traced together. The first `coherent` rays are traced as packets of
    /// `level`'s width (camera rays through the same few pixels); the
    /// rest one by one.
    pub fn intersect_records(
        &self,
        rays: &[Ray],
        coherent: usize,
        level: crate::simd::SimdLevel,
        out: &mut Vec<Option<HitRecord>>,
    ) {
        LOCAL_RAY_COUNTS.with(|c| {
            let (closest, shadow) = c.get();
            c.set((closest + rays.len() as u64, shadow));
        });
        out.clear();
        out.resize(rays.len(), None);
        let coherent = coherent.min(rays.len());
        let width = level.lanes();
        if width > 1 {
            for (r, o) in rays[..coherent]
                .chunks(width)
                .zip(out[..coherent].chunks_mut(width))
            {
                self.aggregate.intersect_records_packet(r, level, o);
            }
        } else {
            for (r, o) in rays[..coherent].iter().zip(&mut out[..coherent]) {
                *o = self.aggregate.intersect_record(r, Float::INFINITY);
            }
        }
        for (r, o) in rays[coherent..].iter().zip(&mut out[coherent..]) {
            *o = self.aggregate.intersect_record(r, Float::INFINITY);
        }
    }

    /// Whether anything blocks each ray of `rays` in (0, its t_max), into
    /// `out` (cleared first): [`Scene::intersect_p`] of a batch of rays,
    /// `interleave`d or not ([`PrimitiveAggregate::intersect_ps`]).
    ///
    /// [`PrimitiveAggregate::intersect_ps`]: crate::primitive::PrimitiveAggregate::intersect_ps
    pub fn intersect_ps(
        &self,
        rays: &[(Ray, Float)],
        level: crate::simd::SimdLevel,
        interleave: bool,
        out: &mut Vec<bool>,
    ) {
        LOCAL_RAY_COUNTS.with(|c| {
            let (closest, shadow) = c.get();
            c.set((closest, shadow + rays.len() as u64));
        });
        self.aggregate.intersect_ps(rays, level, interleave, out);
    }

    /// Whether anything blocks `ray` in (0, t_max).
    #[inline]
    pub fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        LOCAL_RAY_COUNTS.with(|c| {
            let (closest, shadow) = c.get();
            c.set((closest, shadow + 1));
        });
        self.aggregate.intersect_p(ray, t_max)
    }

    /// The shadow ray [`Scene::unoccluded`] traces, with the surface
    /// point's offset origin taken from `origins` (the same ray), and its
    /// extent.
    #[inline]
    pub(crate) fn shadow_ray_from(
        &self,
        origins: &mut VertexOrigins,
        to_p: Point3fi,
        to_n: Normal3f,
    ) -> (Ray, Float) {
        let si = origins.si;
        let p_to = to_p.midpoint();
        let pf = origins.toward(p_to - si.p());
        let r = spawn_ray_from_origin_to_surface(pf, si.time, p_to, to_p.error(), to_n);
        (r, 1.0 - SHADOW_EPSILON)
    }

    /// True when nothing blocks the segment between a surface point and a
    /// point on a light (pbrt-v4 `Integrator::Unoccluded`).
    #[inline]
    pub fn unoccluded(&self, from: &SurfaceInteraction, to_p: Point3fi, to_n: Normal3f) -> bool {
        let r = spawn_ray_to_surface(
            from.p(),
            from.p_error(),
            from.n,
            from.time,
            to_p.midpoint(),
            to_p.error(),
            to_n,
        );
        !self.intersect_p(&r, 1.0 - SHADOW_EPSILON)
    }

    /// Emitted radiance of the surface hit by a ray, toward `w`.
    #[inline]
    pub fn le(
        &self,
        hit: &PrimitiveIntersection,
        w: Vector3f,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        match hit.area_light {
            Some(l) => self.lights[l as usize].l(hit.si.p(), hit.si.n, hit.si.uv, w, lambda),
            None => SampledSpectrum::new(0.0),
        }
    }

    /// pbrt-v4's `SurfaceInteraction::GetBSDF`: computes the screen-space
    /// differentials (when the material can use them), then asks the material for its BSDF (`None` for
    /// interfaces between media, which the ray passes through).
    pub fn get_bsdf<S: SampleSource>(
        &self,
        hit: &mut PrimitiveIntersection,
        ray: &RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut S,
    ) -> Option<BSDF> {
        let material = hit.material?;
        self.texture_differentials(material, &mut hit.si, ray);
        // Returned as is (not unwrapped and rewrapped): the BSDF is large
        // and this lets it be built in the caller's slot.
        let bsdf = self.materials.get_bsdf(material, &mut hit.si, lambda);
        if self.force_diffuse {
            // pbrt-v4's --force-diffuse: a diffuse BSDF with the material's
            // estimated albedo (two extra sampler dimensions, as pbrt-v4).
            let bsdf = bsdf?;
            let uc = sampler.get_1d();
            let u = sampler.get_2d();
            return Some(MaterialSet::force_diffuse(&bsdf, &hit.si, uc, u));
        }
        bsdf
    }

    /// The screen-space differentials of `si` (hit by `ray`) where
    /// `material` reads them: they only feed texture filtering and bump
    /// mapping, and materials that do neither get the same BSDF without
    /// them.
    #[inline]
    pub(crate) fn texture_differentials(
        &self,
        material: u32,
        si: &mut SurfaceInteraction,
        ray: &RayDifferential,
    ) {
        if self.materials.needs_differentials(material) {
            let spp_scale = (1.0 / (self.samples_per_pixel.max(1) as Float).sqrt()).max(0.125);
            si.compute_differentials(
                ray,
                Some(&self.camera_differentials),
                spp_scale,
                self.disable_texture_filtering,
            );
        }
    }

    /// The first visible surface of a camera path, for G-buffer films
    /// (pbrt-v4 `VisibleSurface`, with the BSDF's albedo estimated from 16
    /// fixed stratified samples).
    pub fn visible_surface(&self, hit: &PrimitiveIntersection, bsdf: &BSDF) -> VisibleSurface {
        const N: usize = 16;
        let mut uc = [0.0; N];
        let mut u = [Point2f::default(); N];
        for i in 0..N {
            // A (0,2)-net: Hammersley points with a shifted 1-D dimension.
            uc[i] = ((i as Float + 0.5) / N as Float + 0.37).fract();
            u[i] = Point2f::new(
                (i as Float + 0.5) / N as Float,
                (i as u32).reverse_bits() as Float / 4_294_967_296.0 + 0.5 / N as Float,
            );
        }
        let si = &hit.si;
        VisibleSurface {
            p: si.p(),
            n: si.n.face_forward(si.wo),
            ns: si.shading.n.face_forward(si.wo),
            uv: si.uv,
            time: si.time,
            dpdx: si.dpdx,
            dpdy: si.dpdy,
            albedo: bsdf.rho_hd(si.wo, &uc, &u),
            set: true,
        }
    }
}

/// Continues a ray through a surface without scattering (pbrt-v4
/// `SurfaceInteraction::SkipIntersection`): a new ray from the hit in the
/// same direction, its differentials advanced to the surface.
#[inline]
pub(crate) fn skip_intersection(
    ray: &RayDifferential,
    hit: &PrimitiveIntersection,
) -> RayDifferential {
    let mut next = RayDifferential::new(hit.si.spawn_ray(ray.ray.d));
    next.ray.medium = super::volume::hit_medium_toward(hit, ray.ray.medium, ray.ray.d);
    if ray.has_differentials {
        let t = hit.t_hit;
        next.has_differentials = true;
        next.rx_origin = ray.rx_origin + ray.rx_direction * t;
        next.ry_origin = ray.ry_origin + ray.ry_direction * t;
        next.rx_direction = ray.rx_direction;
        next.ry_direction = ray.ry_direction;
    }
    next
}
