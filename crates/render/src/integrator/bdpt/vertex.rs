//! Path vertices of bidirectional path tracing (pbrt-v4 `Vertex` in
//! `cpu/integrators.cpp`; book section 16.3 of the third edition): where a
//! vertex is, what scatters or emits there, and the area densities with
//! which either subpath samples it.

use crate::bxdf::{BxDFReflTransFlags, TransportMode, BSDF};
use crate::integrator::volume::medium_toward;
use crate::integrator::Scene;
use crate::light::{Light, LightType};
use crate::medium::HGPhaseFunction;
use crate::primitive::MediumInterface;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::{Float, PI};
use rpbrt_geometry::ray::{offset_ray_origin, spawn_ray_to_surface, MediumId, Ray};
use rpbrt_geometry::tuple::*;

/// What a vertex is (pbrt-v4 `VertexType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VertexKind {
    /// On the camera's lens.
    Camera,
    /// On a light, or where a camera ray left the scene (infinite lights).
    Light,
    /// A surface scattering event.
    Surface,
    /// A medium scattering event.
    Medium,
}

/// One vertex of a camera or light subpath.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vertex {
    /// What it is.
    pub kind: VertexKind,
    /// The subpath's throughput up to and including this vertex.
    pub beta: SampledSpectrum,
    /// The point, with its rounding-error bounds.
    pub pi: Point3fi,
    /// The path's time.
    pub time: Float,
    /// The geometric normal (zero away from surfaces).
    pub n: Normal3f,
    /// The shading normal (zero away from surfaces).
    pub ns: Normal3f,
    /// Surface coordinates (emission lookups).
    pub uv: Point2f,
    /// Toward the previous vertex (surface and medium vertices).
    pub wo: Vector3f,
    /// The media on both sides, when the surface separates two.
    pub interface: Option<MediumInterface>,
    /// The medium the vertex lies in (or the arriving ray's, at surfaces).
    pub medium: Option<MediumId>,
    /// The BSDF of a surface vertex.
    pub bsdf: Option<BSDF>,
    /// The phase function of a medium vertex.
    pub phase: HGPhaseFunction,
    /// Light vertices: the light (`None`: an escaped camera ray, standing
    /// for all infinite lights); surface vertices: the area light there.
    pub light: Option<u32>,
    /// Sampled by a specular bounce (a Dirac delta in its density).
    pub delta: bool,
    /// Area density of sampling this vertex from its subpath's side.
    pub pdf_fwd: Float,
    /// Area density of sampling it from the other side.
    pub pdf_rev: Float,
}

impl Vertex {
    /// A vertex at `p` with everything else empty.
    pub(crate) fn new(kind: VertexKind, pi: Point3fi, time: Float, beta: SampledSpectrum) -> Self {
        Vertex {
            kind,
            beta,
            pi,
            time,
            n: Normal3f::default(),
            ns: Normal3f::default(),
            uv: Point2f::default(),
            wo: Vector3f::default(),
            interface: None,
            medium: None,
            bsdf: None,
            phase: HGPhaseFunction::default(),
            light: None,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
        }
    }

    /// The point.
    #[inline]
    pub(crate) fn p(&self) -> Point3f {
        self.pi.midpoint()
    }

    /// True at surfaces (a nonzero geometric normal).
    #[inline]
    pub(crate) fn is_on_surface(&self) -> bool {
        self.n != Normal3f::default()
    }

    /// The medium on the side `w` points into (pbrt-v4 `GetMedium(w)`).
    #[inline]
    pub(crate) fn medium_toward(&self, w: Vector3f) -> Option<MediumId> {
        medium_toward(self.interface, self.n, self.medium, w)
    }

    /// A ray leaving the vertex along `d` (pbrt-v4 `SpawnRay`).
    #[inline]
    pub(crate) fn spawn_ray(&self, d: Vector3f) -> Ray {
        let o = if self.is_on_surface() {
            offset_ray_origin(self.p(), self.pi.error(), self.n, d)
        } else {
            self.p()
        };
        Ray::with_time(o, d, self.time, self.medium_toward(d))
    }

    /// A ray from this vertex to `to`, ending just short of it (pbrt-v4
    /// `SpawnRayTo(Interaction)`).
    #[inline]
    pub(crate) fn spawn_ray_to(&self, to: &Vertex) -> Ray {
        let mut r = spawn_ray_to_surface(
            self.p(),
            self.pi.error(),
            self.n,
            self.time,
            to.p(),
            to.pi.error(),
            to.n,
        );
        r.medium = self.medium_toward(r.d);
        r
    }

    /// The scene light this vertex stands for, if any.
    #[inline]
    fn scene_light<'a>(&self, scene: &'a Scene) -> Option<&'a Light> {
        self.light.map(|l| &scene.lights[l as usize])
    }

    /// The BSDF or phase function value toward `next` (pbrt-v4 `Vertex::f`).
    pub(crate) fn f(&self, next: &Vertex, mode: TransportMode) -> SampledSpectrum {
        let Some(wi) = (next.p() - self.p()).try_normalize() else {
            return SampledSpectrum::new(0.0);
        };
        match self.kind {
            VertexKind::Surface => match &self.bsdf {
                Some(b) => b.f(self.wo, wi, mode),
                None => SampledSpectrum::new(0.0),
            },
            VertexKind::Medium => SampledSpectrum::new(self.phase.p(self.wo, wi)),
            _ => SampledSpectrum::new(0.0),
        }
    }

    /// Whether a connection may end here (pbrt-v4 `IsConnectible`).
    pub(crate) fn is_connectible(&self, scene: &Scene) -> bool {
        match self.kind {
            VertexKind::Medium | VertexKind::Camera => true,
            VertexKind::Light => self
                .scene_light(scene)
                .is_none_or(|l| l.light_type() != LightType::DeltaDirection),
            VertexKind::Surface => self.bsdf.is_some_and(|b| b.flags().is_non_specular()),
        }
    }

    /// True for light vertices and surfaces that emit (pbrt-v4 `IsLight`).
    #[inline]
    pub(crate) fn is_light(&self) -> bool {
        self.kind == VertexKind::Light || (self.kind == VertexKind::Surface && self.light.is_some())
    }

    /// True for a light vertex on a delta light (pbrt-v4 `IsDeltaLight`).
    pub(crate) fn is_delta_light(&self, scene: &Scene) -> bool {
        self.kind == VertexKind::Light
            && self
                .scene_light(scene)
                .is_some_and(|l| l.light_type().is_delta())
    }

    /// True for a light vertex at infinity: an escaped camera ray, an
    /// infinite or a distant light (pbrt-v4 `IsInfiniteLight`).
    pub(crate) fn is_infinite_light(&self, scene: &Scene) -> bool {
        self.kind == VertexKind::Light
            && self.scene_light(scene).is_none_or(|l| {
                matches!(
                    l.light_type(),
                    LightType::Infinite | LightType::DeltaDirection
                )
            })
    }

    /// Radiance emitted from this vertex toward `v` (pbrt-v4 `Vertex::Le`).
    pub(crate) fn le(
        &self,
        scene: &Scene,
        v: &Vertex,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::new(0.0);
        if !self.is_light() {
            return zero;
        }
        let Some(w) = (v.p() - self.p()).try_normalize() else {
            return zero;
        };
        if self.is_infinite_light(scene) {
            let ray = Ray::new(self.p(), -w);
            let mut le = zero;
            for &li in &scene.infinite_lights {
                le += scene.lights[li as usize].le(&ray, lambda);
            }
            le
        } else if let (VertexKind::Surface, Some(l)) = (self.kind, self.scene_light(scene)) {
            l.l(self.p(), self.n, self.uv, w, lambda)
        } else {
            zero
        }
    }

    /// Converts a solid-angle density at this vertex toward `next` into an
    /// area density at `next` (pbrt-v4 `ConvertDensity`).
    pub(crate) fn convert_density(&self, pdf: Float, next: &Vertex, scene: &Scene) -> Float {
        if next.is_infinite_light(scene) {
            return pdf;
        }
        let w = next.p() - self.p();
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let inv_dist2 = 1.0 / d2;
        let mut pdf = pdf;
        if next.is_on_surface() {
            pdf *= abs_dot(Vector3f::from(next.n), w * inv_dist2.sqrt());
        }
        pdf * inv_dist2
    }

    /// The area density at `next` of sampling it from this vertex, having
    /// arrived from `prev` (pbrt-v4 `Vertex::PDF`).
    pub(crate) fn pdf(&self, scene: &Scene, prev: Option<&Vertex>, next: &Vertex) -> Float {
        if self.kind == VertexKind::Light {
            return self.pdf_light(scene, next);
        }
        let Some(wn) = (next.p() - self.p()).try_normalize() else {
            return 0.0;
        };
        let wp = match prev {
            Some(prev) => match (prev.p() - self.p()).try_normalize() {
                Some(w) => w,
                None => return 0.0,
            },
            None => Vector3f::default(),
        };
        let pdf = match self.kind {
            VertexKind::Camera => scene.camera.pdf_we(&self.spawn_ray(wn)).1,
            VertexKind::Surface => match &self.bsdf {
                Some(b) => b.pdf(wp, wn, TransportMode::Radiance, BxDFReflTransFlags::ALL),
                None => 0.0,
            },
            VertexKind::Medium => self.phase.p(wp, wn),
            VertexKind::Light => 0.0,
        };
        self.convert_density(pdf, next, scene)
    }

    /// The area density at `v` of a light subpath starting at this light
    /// vertex and heading to `v` (pbrt-v4 `PDFLight`).
    pub(crate) fn pdf_light(&self, scene: &Scene, v: &Vertex) -> Float {
        let w = v.p() - self.p();
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let inv_dist2 = 1.0 / d2;
        let w = w * inv_dist2.sqrt();
        let mut pdf = if self.is_infinite_light(scene) {
            // Rays from infinity start on a disk the size of the scene.
            let (_, radius) = scene.bounds().bounding_sphere();
            1.0 / (PI * radius * radius)
        } else if let Some(light) = self.scene_light(scene) {
            let pdf_dir = if self.is_on_surface() {
                light.pdf_le_surface(self.p(), self.n, w).1
            } else {
                light
                    .pdf_le(&Ray::with_time(self.p(), w, self.time, None))
                    .1
            };
            pdf_dir * inv_dist2
        } else {
            0.0
        };
        if v.is_on_surface() {
            pdf *= abs_dot(Vector3f::from(v.n), w);
        }
        pdf
    }

    /// The density of starting a light subpath at this vertex: choosing its
    /// light and the point on it (pbrt-v4 `PDFLightOrigin`); `v` is the
    /// next vertex toward the camera.
    pub(crate) fn pdf_light_origin(&self, scene: &Scene, v: &Vertex) -> Float {
        let Some(w) = (v.p() - self.p()).try_normalize() else {
            return 0.0;
        };
        if self.is_infinite_light(scene) {
            return infinite_light_density(scene, w);
        }
        let Some(li) = self.light else {
            return 0.0;
        };
        let light = &scene.lights[li as usize];
        let pdf_choice = scene.light_sampler.pmf_no_ctx(li);
        let pdf_pos = if self.is_on_surface() {
            light.pdf_le_surface(self.p(), self.n, w).0
        } else {
            light
                .pdf_le(&Ray::with_time(self.p(), w, self.time, None))
                .0
        };
        pdf_pos * pdf_choice
    }
}

/// The density of choosing, among the infinite lights, direction `-w`
/// (pbrt-v4 `InfiniteLightDensity`): each infinite light's solid-angle
/// density times the light sampler's probability of choosing it.
pub(crate) fn infinite_light_density(scene: &Scene, w: Vector3f) -> Float {
    let ctx = crate::light::LightSampleContext::default();
    scene
        .infinite_lights
        .iter()
        .map(|&li| {
            scene.lights[li as usize].pdf_li(&ctx, -w, false) * scene.light_sampler.pmf_no_ctx(li)
        })
        .sum()
}
