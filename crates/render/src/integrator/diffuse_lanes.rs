//! The wavefront's diffuse vertex: the commonest path vertex of all, a
//! hit on a triangle of a plain `diffuse` material, its reflectance a
//! constant or a texture, taken lane-parallel from the hit to the next
//! ray, without building the general surface interaction and BSDF the
//! scalar vertex builds (about 400 bytes a vertex, most of which this
//! vertex never reads).
//!
//! Two kernels, each a fixed sequence of the IEEE operations the scalar
//! code performs, so that every width gives the scalar vertex's bits:
//!
//! 1. [`surfaces`], after the closest hits: the hit point and its error
//!    bound, ωo, the interpolated shading normal, the shading tangents
//!    and the BSDF's frame (pbrt-v4's `Triangle::InteractionFromIntersection`
//!    and `BSDF` constructor). What follows per lane (the point's
//!    interval, the reflectance, the sampler draws and the light
//!    request) runs the scalar code itself. A textured reflectance is
//!    looked up there too, in the context the scalar interaction would
//!    give the texture (its differentials computed by the same code), the
//!    pass's lookups prepared first and their image texels prefetched.
//! 2. [`scatters`], after the light stage: the Lambertian BSDF's value and
//!    density toward the light sample, and its cosine-weighted sample of
//!    the next direction (pbrt-v4's `DiffuseBxDF` through `BSDF::f`,
//!    `BSDF::PDF` and `BSDF::Sample_f`).
//!
//! A pass's vertices are held as columns ([`LaneVertices`]): the kernels
//! load and store vectors of consecutive vertices, and each vertex's
//! halves read its entries in place, so nothing is gathered from or
//! scattered back to per-path structs.
//!
//! The surface kernel also serves the specular vertex of a smooth
//! `dielectric` of constant index ([`lane_surface`]): on its surface
//! the scalar BSDF's own sampling runs per lane, in the BSDF's frame the
//! kernel built, with no general interaction built at all. And it serves
//! the staged vertex of a `conductor`, `dielectric` or coated material of
//! constant textures: its BxDF, the same at every point, is put in that
//! frame ([`LaneVertices::bsdf`]), and the BSDF stage answers its
//! queries as it answers the scalar vertices'.
//!
//! Lanes where the scalar code takes a rare branch (a shading normal
//! perpendicular to the tangent, derivatives rescaled) are flagged and
//! take the scalar vertex instead.

use super::bsdf_stage::BsdfAnswers;
use super::direct::LightRequest;
use super::Scene;
use crate::bxdf::lanes::MAX_LANES;
use crate::bxdf::{BSDFSample, BxDF, BxDFFlags, DielectricBxDF, BSDF};
use crate::light::LightSampleContext;
use crate::primitive::{HitRecord, TextureParts, TriangleHit};
use crate::sampler::Sampler;
use crate::simd::math::{self, V3};
use crate::simd::{dispatch, F32Lanes, Kernel, SimdLevel};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TextureEvalContext;
use rpbrt_geometry::float::{gamma, Float, INV_PI, PI_OVER_4};
use rpbrt_geometry::frame::Frame;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::interval::Interval;
use rpbrt_geometry::pointfi::Point3fi;
use rpbrt_geometry::ray::{spawn_ray_from_origin_to_surface, Ray, RayDifferential, SHADOW_EPSILON};
use rpbrt_geometry::tuple::*;

/// What a vertex that the surface kernel builds shades with.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LaneShade {
    /// A diffuse vertex: a plain `diffuse` material of constant, not
    /// black, reflectance (this, at the path's wavelengths).
    Diffuse(SampledSpectrum),
    /// A diffuse vertex of a plain `diffuse` material whose reflectance
    /// is a texture ([`MaterialSet::textured_diffuse`]), this one: the
    /// texture is looked up after the surface kernel
    /// ([`LaneVertices::textured_reflectance`]).
    ///
    /// [`MaterialSet::textured_diffuse`]: crate::material::MaterialSet::textured_diffuse
    Textured(u32),
    /// A specular vertex: a constant specular `dielectric` material
    /// ([`MaterialSet::constant_specular_dielectric`]), its BxDF.
    ///
    /// [`MaterialSet::constant_specular_dielectric`]: crate::material::MaterialSet::constant_specular_dielectric
    Specular(DielectricBxDF),
    /// A staged vertex: a material of constant textures whose BSDF
    /// queries the BSDF stage answers
    /// ([`MaterialSet::is_constant_staged`]), this one.
    ///
    /// [`MaterialSet::is_constant_staged`]: crate::material::MaterialSet::is_constant_staged
    Staged(u32),
}

/// How a hit `record` by a ray of direction `d` shades when it is a vertex
/// the lanes take: a triangle without an area light, in a mesh without
/// shading tangents, of a material [`LaneShade`] covers (its specular and
/// staged kinds only where `as_built`: the vertex shades with the BSDF as
/// the material builds it, not regularized); the surface kernel's input
/// then takes the next slot of `out`. `None`: the scalar vertex takes it.
#[inline(always)]
pub(crate) fn lane_surface(
    scene: &Scene,
    record: &HitRecord,
    d: Vector3f,
    lambda: &SampledWavelengths,
    as_built: bool,
    out: &mut LaneVertices,
) -> Option<LaneShade> {
    let hit = scene.aggregate.triangle_hit(record)?;
    if hit.area_light.is_some() {
        return None;
    }
    let material = hit.material?;
    let shade = match scene.materials.constant_diffuse(material) {
        Some(spectrum) => {
            // `DiffuseMaterial::get_bxdf`; a black reflectance makes a
            // BSDF without flags, which the scalar vertex handles.
            let r = spectrum.sample(lambda).clamp(0.0, 1.0);
            if r.is_black() {
                return None;
            }
            LaneShade::Diffuse(r)
        }
        None if scene.materials.textured_diffuse(material).is_some() => {
            LaneShade::Textured(material)
        }
        None if as_built => match scene
            .materials
            .constant_specular_dielectric(material, lambda)
        {
            Some(bxdf) => LaneShade::Specular(bxdf),
            None if scene.materials.is_constant_staged(material) => LaneShade::Staged(material),
            None => return None,
        },
        None => return None,
    };
    if !out.push(&hit, d) {
        return None;
    }
    if let LaneShade::Textured(_) = shade {
        out.texture[out.len - 1] = hit.texture_parts();
    }
    Some(shade)
}

/// The components of a point, vector or normal.
macro_rules! xyz {
    ($v:expr) => {{
        let v = $v;
        [v.x, v.y, v.z]
    }};
}

/// Column indices of [`LaneVertices`]: a vector's components, and a
/// spectrum's wavelengths, are consecutive columns.
mod col {
    // The surface kernel's input: the barycentrics, the triangle's
    // vertices and vertex normals (vertex `j`'s component `a` at
    // `P + 3j + a`), the geometric normal and ∂p/∂u, the ray's direction.
    pub const B: usize = 0;
    pub const P: usize = B + 3;
    pub const N: usize = P + 9;
    pub const NG: usize = N + 9;
    pub const DPDU: usize = NG + 3;
    pub const D: usize = DPDU + 3;
    // Its output: the point's interval and midpoint, the offset origins
    // to the side of the geometric normal and to the other side, that
    // normal (on the shading normal's side), the shading normal, ωo and
    // the BSDF frame's x and y axes.
    pub const LO: usize = D + 3;
    pub const HI: usize = LO + 3;
    pub const MID: usize = HI + 3;
    pub const SIDE0: usize = MID + 3;
    pub const SIDE1: usize = SIDE0 + 3;
    pub const N_OUT: usize = SIDE1 + 3;
    pub const NS: usize = N_OUT + 3;
    pub const WO: usize = NS + 3;
    pub const X: usize = WO + 3;
    pub const Y: usize = X + 3;
    // The scatter kernel's other input: the reflectance, the BSDF
    // sample's draws and the light sample's direction.
    pub const R: usize = Y + 3;
    pub const U2: usize = R + 4;
    pub const WI: usize = U2 + 2;
    // Its output: the BSDF's value (times the cosine) and density toward
    // the light sample; the sampled direction, its density and cosine
    // over density.
    pub const F_LIGHT: usize = WI + 3;
    pub const PDF_LIGHT: usize = F_LIGHT + 4;
    pub const WI_S: usize = PDF_LIGHT + 1;
    pub const PDF: usize = WI_S + 3;
    pub const COS_OVER_PDF: usize = PDF + 1;
    pub const COUNT: usize = COS_OVER_PDF + 1;
}

/// Slots of [`LaneVertices`]: the most vertices a wavefront pass takes in
/// lanes.
pub(crate) const LANE_SLOTS: usize = 256;

/// A column's entries: the slots and [`MAX_LANES`] spare ones.
const STRIDE: usize = LANE_SLOTS + MAX_LANES;

/// The vertices of one wavefront pass that the surface kernel takes, as
/// columns: slot `k`'s value of column `c` is at `data[c][k]`. The
/// kernels load and store whole vectors of consecutive slots, with no
/// gathering from per-path structs, and the halves of a vertex read the
/// slot's entries in place. Each column ends in [`MAX_LANES`] spare
/// entries, so that a vector loads at any slot (what lanes past the last
/// slot compute is never read). (The sizes are constants, so that the
/// many reads of one slot share one bounds check.)
pub(crate) struct LaneVertices {
    data: Box<[[Float; STRIDE]; col::COUNT]>,
    /// Slots taken.
    len: usize,
    /// Per slot: the mesh has vertex normals; the surface kernel took it
    /// (false where the scalar code takes a branch the kernel does not:
    /// the scalar vertex takes it); the BSDF sample exists.
    shading: [bool; STRIDE],
    ok: [bool; STRIDE],
    sampled: [bool; STRIDE],
    /// Per textured diffuse slot: the hit's parameterization, and the
    /// texture lookup's context.
    texture: Box<[TextureParts; STRIDE]>,
    contexts: Box<[TextureEvalContext; STRIDE]>,
}

impl Default for LaneVertices {
    fn default() -> Self {
        LaneVertices {
            data: Box::new([[0.0; STRIDE]; col::COUNT]),
            len: 0,
            shading: [false; STRIDE],
            ok: [false; STRIDE],
            sampled: [false; STRIDE],
            texture: Box::new([TextureParts::default(); STRIDE]),
            contexts: Box::new([TextureEvalContext::default(); STRIDE]),
        }
    }
}

impl LaneVertices {
    /// Every slot free again.
    #[inline]
    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    #[inline(always)]
    fn at(&self, c: usize, k: usize) -> Float {
        self.data[c][k]
    }

    #[inline(always)]
    fn set(&mut self, c: usize, k: usize, v: Float) {
        self.data[c][k] = v;
    }

    #[inline(always)]
    fn set3(&mut self, c: usize, k: usize, v: [Float; 3]) {
        for (a, x) in v.into_iter().enumerate() {
            self.set(c + a, k, x);
        }
    }

    #[inline(always)]
    fn get3(&self, c: usize, k: usize) -> [Float; 3] {
        [self.at(c, k), self.at(c + 1, k), self.at(c + 2, k)]
    }

    #[inline(always)]
    fn vector(&self, c: usize, k: usize) -> Vector3f {
        let [x, y, z] = self.get3(c, k);
        Vector3f::new(x, y, z)
    }

    #[inline(always)]
    fn point(&self, c: usize, k: usize) -> Point3f {
        let [x, y, z] = self.get3(c, k);
        Point3f::new(x, y, z)
    }

    #[inline(always)]
    fn normal(&self, c: usize, k: usize) -> Normal3f {
        let [x, y, z] = self.get3(c, k);
        Normal3f::new(x, y, z)
    }

    #[inline(always)]
    fn spectrum(&self, c: usize, k: usize) -> SampledSpectrum {
        SampledSpectrum {
            values: std::array::from_fn(|w| self.at(c + w, k)),
        }
    }

    #[inline(always)]
    fn load<L: F32Lanes>(&self, c: usize, k: usize) -> L {
        L::load(&self.data[c][k..])
    }

    #[inline(always)]
    fn load3<L: F32Lanes>(&self, c: usize, k: usize) -> V3<L> {
        V3 {
            x: self.load(c, k),
            y: self.load(c + 1, k),
            z: self.load(c + 2, k),
        }
    }

    #[inline(always)]
    fn store<L: F32Lanes>(&mut self, c: usize, k: usize, v: L) {
        v.store(&mut self.data[c][k..]);
    }

    #[inline(always)]
    fn store3<L: F32Lanes>(&mut self, c: usize, k: usize, v: V3<L>) {
        self.store(c, k, v.x);
        self.store(c + 1, k, v.y);
        self.store(c + 2, k, v.z);
    }

    /// The lane mask of `flags` at slots `k..`, of which `n` are taken.
    #[inline(always)]
    fn mask<L: F32Lanes>(flags: &[bool], k: usize, n: usize) -> L::Mask {
        L::from_bits(
            flags[k..k + n]
                .iter()
                .enumerate()
                .fold(0, |m, (i, &f)| m | ((f as u32) << i)),
        )
    }

    /// Takes the next slot for the surface kernel's input: a hit on `hit`
    /// by a ray of direction `d`. False (no slot taken) for meshes with
    /// shading tangents, which the scalar vertex takes, and when every
    /// slot is taken.
    #[inline(always)]
    pub(crate) fn push(&mut self, hit: &TriangleHit, d: Vector3f) -> bool {
        let mesh = hit.tri.mesh;
        let k = self.len;
        if mesh.s.is_some() || k >= LANE_SLOTS {
            return false;
        }
        let v = mesh.vertex_indices(hit.tri.tri_index as usize);
        for (j, &i) in v.iter().enumerate() {
            self.set3(col::P + 3 * j, k, xyz!(mesh.p[i]));
        }
        match &mesh.n {
            Some(nn) => {
                for (j, &i) in v.iter().enumerate() {
                    self.set3(col::N + 3 * j, k, xyz!(nn[i]));
                }
                self.shading[k] = true;
            }
            None => {
                for j in 0..3 {
                    self.set3(col::N + 3 * j, k, [0.0; 3]);
                }
                self.shading[k] = false;
            }
        }
        for (j, &b) in hit.b.iter().enumerate() {
            self.set(col::B + j, k, b);
        }
        let (mut ng, mut dpdu) = (Normal3f::default(), Vector3f::default());
        hit.frame_parts(&mut ng, &mut dpdu);
        self.set3(col::NG, k, xyz!(ng));
        self.set3(col::DPDU, k, xyz!(dpdu));
        self.set3(col::D, k, xyz!(d));
        self.len += 1;
        true
    }

    /// Whether the surface kernel took slot `k` (if not, the scalar vertex
    /// takes it).
    #[inline(always)]
    pub(crate) fn ok(&self, k: usize) -> bool {
        self.ok[k]
    }

    /// The hit point's interval at slot `k`.
    #[inline(always)]
    fn pi(&self, k: usize) -> Point3fi {
        let (lo, hi) = (self.get3(col::LO, k), self.get3(col::HI, k));
        let i = |a: usize| Interval {
            low: lo[a],
            high: hi[a],
        };
        Point3fi::new(i(0), i(1), i(2))
    }

    /// The surface at slot `k`, whole (for the specular vertex).
    pub(crate) fn surface_out(&self, k: usize) -> SurfaceOut {
        SurfaceOut {
            pi: self.pi(k),
            sides: [self.point(col::SIDE0, k), self.point(col::SIDE1, k)],
            n: self.normal(col::N_OUT, k),
            ns: self.normal(col::NS, k),
            wo: self.vector(col::WO, k),
            x: self.vector(col::X, k),
            y: self.vector(col::Y, k),
        }
    }

    /// The first half of the diffuse vertex at slot `k` (after the
    /// integrator has counted it), of reflectance `r`, given its sampler
    /// draws (`Sampler::get_vertex_samples`; the BSDF's are kept for the
    /// scatter kernel): its light request.
    #[inline(always)]
    pub(crate) fn begin(
        &mut self,
        k: usize,
        r: SampledSpectrum,
        draws: (Float, Point2f, Float, Point2f),
    ) -> LightRequest {
        let (u_light, u_light_2d, _, u2) = draws;
        for (w, &v) in r.values.iter().enumerate() {
            self.set(col::R + w, k, v);
        }
        self.set(col::U2, k, u2.x);
        self.set(col::U2 + 1, k, u2.y);
        // A Lambertian BSDF only reflects and is zero across hemispheres.
        self.request(k, BxDFFlags::DIFFUSE_REFLECTION, true, u_light, u_light_2d)
    }

    /// Prepares the texture lookup of the textured diffuse vertex at slot
    /// `k`, of material `material`, hit by `ray`: its context, the scalar
    /// vertex's (from the interaction's point, normal, ∂p/∂u, ∂p/∂v and
    /// (u, v), with the screen-space differentials computed from them),
    /// and a prefetch of the image texels it reads, so that the lookups
    /// of a pass wait on memory together rather than one after another.
    #[inline(always)]
    pub(crate) fn texture_lookup(
        &mut self,
        scene: &Scene,
        k: usize,
        material: u32,
        ray: &RayDifferential,
    ) {
        let Some(m) = scene.materials.textured_diffuse(material) else {
            return;
        };
        let t = &self.texture[k];
        let mut si = SurfaceInteraction {
            pi: self.pi(k),
            n: self.normal(col::N_OUT, k),
            uv: t.uv,
            dpdu: t.dpdu,
            dpdv: t.dpdv,
            face_index: t.face_index,
            ..Default::default()
        };
        scene.texture_differentials(material, &mut si, ray);
        let ctx = TextureEvalContext::from_si(&si);
        m.reflectance.prefetch(&ctx);
        self.contexts[k] = ctx;
    }

    /// The reflectance of the textured diffuse vertex at slot `k`, of
    /// material `material`, looked up in the context
    /// [`LaneVertices::texture_lookup`] prepared; `None` where it is
    /// black (a BSDF without flags, which the scalar vertex handles).
    #[inline(always)]
    pub(crate) fn textured_reflectance(
        &self,
        scene: &Scene,
        k: usize,
        material: u32,
        lambda: &SampledWavelengths,
    ) -> Option<SampledSpectrum> {
        let m = scene.materials.textured_diffuse(material)?;
        let r = m.reflectance_at(&self.contexts[k], lambda);
        (!r.is_black()).then_some(r)
    }

    /// The BSDF of the staged vertex at slot `k`: `bxdf` in the frame the
    /// surface kernel built (`BSDF::new`'s).
    #[inline(always)]
    pub(crate) fn bsdf(&self, k: usize, bxdf: BxDF) -> BSDF {
        BSDF {
            bxdf,
            shading_frame: Frame {
                x: self.vector(col::X, k),
                y: self.vector(col::Y, k),
                z: Vector3f::from(self.ns(k)),
            },
        }
    }

    /// The first half of the staged vertex at slot `k`, of BSDF `bsdf`,
    /// given its four sampler draws: its light request
    /// (`light_request`'s), and what its second half keeps: ωo and the
    /// BSDF sample's two draws.
    #[inline(always)]
    pub(crate) fn staged_begin(
        &self,
        k: usize,
        bsdf: &BSDF,
        draws: (Float, Point2f, Float, Point2f),
    ) -> (LightRequest, Vector3f, Float, Point2f) {
        let (u_light, u_light_2d, u, u2) = draws;
        let zero_across = bsdf.bxdf.zero_across_hemispheres();
        let req = self.request(k, bsdf.flags(), zero_across, u_light, u_light_2d);
        (req, self.wo(k), u, u2)
    }

    /// The staged vertex at slot `k`'s BSDF `bsdf` toward a light sample's
    /// direction `wi` (from ωo `wo`), from the BSDF stage's answers `pre`:
    /// its value times `|wi · ns|` and its density; `None` where the value
    /// is black (no shadow ray).
    #[inline(always)]
    pub(crate) fn staged_light(
        &self,
        k: usize,
        bsdf: &BSDF,
        pre: &BsdfAnswers,
        wo: Vector3f,
        wi: Vector3f,
    ) -> Option<(SampledSpectrum, Float)> {
        let f = pre.light_f(bsdf, wo, wi) * abs_dot(wi, self.ns(k));
        (!f.is_black()).then(|| (f, pre.light_pdf(bsdf, wo, wi)))
    }

    /// The light request at slot `k` of a BSDF of `flags` whose frame's z
    /// axis is the shading normal (`surface_light_context`'s point: offset
    /// toward ωo where the BSDF only reflects, away where it only
    /// transmits); `zero_across`: the BSDF is zero across hemispheres.
    #[inline(always)]
    fn request(
        &self,
        k: usize,
        flags: BxDFFlags,
        zero_across: bool,
        u: Float,
        u_light: Point2f,
    ) -> LightRequest {
        let (n, ns, wo) = (self.normal(col::N_OUT, k), self.ns(k), self.wo(k));
        let pi = match (flags.is_reflective(), flags.is_transmissive()) {
            (true, false) => Point3fi::from(self.toward(k, wo)),
            (false, true) => Point3fi::from(self.toward(k, -wo)),
            _ => self.pi(k),
        };
        let z = Vector3f::from(ns);
        LightRequest {
            ctx: LightSampleContext { pi, n, ns },
            u,
            u_light,
            hemisphere: zero_across.then(|| (z, dot(wo, z))),
        }
    }

    /// ωo at slot `k`.
    #[inline(always)]
    pub(crate) fn wo(&self, k: usize) -> Vector3f {
        self.vector(col::WO, k)
    }

    /// The shading normal at slot `k`.
    #[inline(always)]
    pub(crate) fn ns(&self, k: usize) -> Normal3f {
        self.normal(col::NS, k)
    }

    /// Sets the light sample's direction at slot `k` for the scatter
    /// kernel (any, without a light sample: its answers are then not
    /// read).
    #[inline(always)]
    pub(crate) fn set_light_direction(&mut self, k: usize, wi: Vector3f) {
        self.set3(col::WI, k, xyz!(wi));
    }

    /// Writes the vertex at slot `k` as the light-sampling context of the
    /// next vertex's MIS weights (`LightSampleContext::from_si`).
    #[inline(always)]
    pub(crate) fn write_context(&self, k: usize, ctx: &mut LightSampleContext) {
        ctx.pi = self.pi(k);
        ctx.n = self.normal(col::N_OUT, k);
        ctx.ns = self.normal(col::NS, k);
    }

    /// The ray origin at slot `k` offset off the surface toward `w`'s
    /// side.
    #[inline(always)]
    fn toward(&self, k: usize, w: Vector3f) -> Point3f {
        let side = (dot(w, self.normal(col::N_OUT, k)) < 0.0) as usize;
        self.point([col::SIDE0, col::SIDE1][side], k)
    }

    /// The ray leaving slot `k`'s vertex toward `wi` at `time`.
    #[inline(always)]
    pub(crate) fn spawn_ray(&self, k: usize, wi: Vector3f, time: Float) -> Ray {
        Ray::with_time(self.toward(k, wi), wi, time, None)
    }

    /// The shadow ray from slot `k`'s vertex at `time` toward a light
    /// sample's point `to_p` (normal `to_n`), and its extent.
    #[inline(always)]
    pub(crate) fn shadow_ray(
        &self,
        k: usize,
        time: Float,
        to_p: Point3fi,
        to_n: Normal3f,
    ) -> (Ray, Float) {
        let p_to = to_p.midpoint();
        let pf = self.toward(k, p_to - self.point(col::MID, k));
        let r = spawn_ray_from_origin_to_surface(pf, time, p_to, to_p.error(), to_n);
        (r, 1.0 - SHADOW_EPSILON)
    }

    /// The reflectance at slot `k`.
    #[inline(always)]
    pub(crate) fn r(&self, k: usize) -> SampledSpectrum {
        self.spectrum(col::R, k)
    }

    /// `bsdf.f(ωo, ωi) · |ωi · ns|` and `bsdf.pdf(ωo, ωi)` toward slot
    /// `k`'s light sample.
    #[inline(always)]
    pub(crate) fn light_answers(&self, k: usize) -> (SampledSpectrum, Float) {
        (self.spectrum(col::F_LIGHT, k), self.at(col::PDF_LIGHT, k))
    }

    /// Slot `k`'s BSDF sample (`bsdf.sample_f`): its direction in
    /// rendering space, its density, and `|ωi · ns| / pdf`; `None` where
    /// the scalar method returns none.
    #[inline(always)]
    pub(crate) fn sample(&self, k: usize) -> Option<(Vector3f, Float, Float)> {
        self.sampled[k].then(|| {
            (
                self.vector(col::WI_S, k),
                self.at(col::PDF, k),
                self.at(col::COS_OVER_PDF, k),
            )
        })
    }
}

/// The surface at a hit, as the scalar interaction and BSDF have it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SurfaceOut {
    /// The hit point's interval.
    pub pi: Point3fi,
    /// The ray origins offset off the surface (`offset_ray_origin`) to
    /// the side of `n` and to the other side.
    pub sides: [Point3f; 2],
    /// The geometric normal, on the shading normal's side.
    pub n: Normal3f,
    /// The shading normal.
    pub ns: Normal3f,
    /// ωo, normalized.
    pub wo: Vector3f,
    /// The BSDF frame's x and y axes (its z axis is `ns`).
    pub x: Vector3f,
    pub y: Vector3f,
}

impl SurfaceOut {
    /// The vertex's BSDF sample on this surface when it is specular (a
    /// [`LaneShade::Specular`] vertex): `bxdf` in the frame the kernel
    /// built, sampled from `wo` with the vertex's draws (a 1-D, then a
    /// 2-D one) as the scalar vertex samples its BSDF, with its MIS
    /// density and the next ray, leaving at `time` to the side of the
    /// sampled direction (`VertexOrigins::spawn_ray`'s test).
    #[inline(always)]
    pub(crate) fn specular_sample(
        &self,
        bxdf: DielectricBxDF,
        wo: Vector3f,
        time: Float,
        sampler: &mut Sampler,
    ) -> Option<(BSDFSample, Float, Ray)> {
        let (u, u2) = (sampler.get_1d(), sampler.get_2d());
        let bsdf = BSDF {
            bxdf: BxDF::Dielectric(bxdf),
            shading_frame: Frame {
                x: self.x,
                y: self.y,
                z: Vector3f::from(self.ns),
            },
        };
        let (bs, p_b) = BsdfAnswers::default().sample(&bsdf, wo, u, u2)?;
        let o = self.sides[(dot(bs.wi, self.n) < 0.0) as usize];
        Some((bs, p_b, Ray::with_time(o, bs.wi, time, None)))
    }

    /// Writes the vertex's light-sampling context
    /// (`LightSampleContext::from_si`).
    #[inline(always)]
    pub(crate) fn write_context(&self, ctx: &mut LightSampleContext) {
        ctx.pi = self.pi;
        ctx.n = self.n;
        ctx.ns = self.ns;
    }
}

/// Component-wise |v|.
#[inline(always)]
fn abs_v<L: F32Lanes>(v: V3<L>) -> V3<L> {
    V3 {
        x: v.x.abs(),
        y: v.y.abs(),
        z: v.z.abs(),
    }
}

/// `-v`.
#[inline(always)]
fn neg_v<L: F32Lanes>(v: V3<L>) -> V3<L> {
    V3 {
        x: v.x.neg(),
        y: v.y.neg(),
        z: v.z.neg(),
    }
}

/// `if m { -v } else { v }` (a sign flip, as `face_forward`).
#[inline(always)]
fn flip_if<L: F32Lanes>(m: L::Mask, v: V3<L>) -> V3<L> {
    V3::select(m, neg_v(v), v)
}

/// Each component of `v` one float up where `o`'s is positive, one down
/// where it is negative (the rounding of `offset_ray_origin`).
#[inline(always)]
fn round_off_v<L: F32Lanes>(v: V3<L>, o: V3<L>) -> V3<L> {
    V3 {
        x: round_off_l(v.x, o.x),
        y: round_off_l(v.y, o.y),
        z: round_off_l(v.z, o.z),
    }
}

/// [`round_off_v`] of one component.
#[inline(always)]
fn round_off_l<L: F32Lanes>(v: L, o: L) -> L {
    let zero = L::splat(0.0);
    let down = L::select(o.lt(zero), math::next_float_down(v), v);
    L::select(o.gt(zero), math::next_float_up(v), down)
}

/// [`surfaces`] as a kernel.
struct Surfaces<'a>(&'a mut LaneVertices);

impl Kernel for Surfaces<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let mut k = 0;
        while k < self.0.len {
            surface_lanes::<L>(self.0, k);
            k += L::N;
        }
    }
}

/// The surface kernel on the slots from `k`, `L::N` of them.
#[inline(always)]
fn surface_lanes<L: F32Lanes>(v: &mut LaneVertices, k: usize) {
    let n = (v.len - k).min(L::N);
    let s = L::splat;
    let zero = s(0.0);
    let b0: L = v.load(col::B, k);
    let b1: L = v.load(col::B + 1, k);
    let b2: L = v.load(col::B + 2, k);
    let p0 = v.load3::<L>(col::P, k);
    let p1 = v.load3::<L>(col::P + 3, k);
    let p2 = v.load3::<L>(col::P + 6, k);
    let ng = v.load3::<L>(col::NG, k);
    let dpdu = v.load3::<L>(col::DPDU, k);
    let d = v.load3::<L>(col::D, k);
    let shading = LaneVertices::mask::<L>(&v.shading, k, n);

    // The point, its error bound and ωo (`Triangle::interaction`).
    let (pb0, pb1, pb2) = (p0.scale(b0), p1.scale(b1), p2.scale(b2));
    let p = pb0.add(pb1).add(pb2);
    let p_error = abs_v(pb0)
        .add(abs_v(pb1))
        .add(abs_v(pb2))
        .scale(s(gamma(7)));
    let (wo, wo_ok) = neg_v(d).try_normalize();
    let wo = V3::select(
        wo_ok,
        wo,
        V3 {
            x: zero,
            y: zero,
            z: zero,
        },
    );

    // The shading geometry of meshes with vertex normals: the
    // interpolated normal (the geometric one where it vanishes), the
    // tangent ∂p/∂u made perpendicular to it, and the geometric normal
    // turned to its side.
    let n0 = v.load3::<L>(col::N, k);
    let n1 = v.load3::<L>(col::N + 3, k);
    let n2 = v.load3::<L>(col::N + 6, k);
    let nsum = n0.scale(b0).add(n1.scale(b1)).add(n2.scale(b2));
    let nonzero = nsum.dot(nsum).gt(zero);
    let ns = V3::select(L::and(shading, nonzero), nsum.normalize(), ng);
    let ts = ns.cross(dpdu);
    let ts2 = ts.dot(ts);
    let ss = ts.cross(ns);
    let ss = V3::select(shading, ss, dpdu);
    let n_out = V3::select(shading, flip_if::<L>(ng.dot(ns).lt(zero), ng), ng);
    // Lanes with normals whose tangent cross product vanishes, or whose
    // derivatives the interaction would rescale, go to the scalar code.
    let big = s(1e16);
    let rare = L::or(L::not(ts2.gt(zero)), L::or(ss.dot(ss).gt(big), ts2.gt(big)));
    let ok = L::not(L::and(shading, rare));

    // The BSDF frame: x along the shading tangent, z the shading normal
    // (`Frame::from_xz`).
    let x = ss.normalize();
    let y = ns.cross(x);

    // The point as the interaction holds it (an interval, read back as
    // its midpoint and half-width) and the ray origins offset off the
    // surface to either side (`offset_ray_origin`).
    let (lx, hx) = math::interval_from_value_and_error(p.x, p_error.x);
    let (ly, hy) = math::interval_from_value_and_error(p.y, p_error.y);
    let (lz, hz) = math::interval_from_value_and_error(p.z, p_error.z);
    let two = s(2.0);
    let mid = V3 {
        x: lx.add(hx).div(two),
        y: ly.add(hy).div(two),
        z: lz.add(hz).div(two),
    };
    let err = V3 {
        x: hx.sub(lx).div(two),
        y: hy.sub(ly).div(two),
        z: hz.sub(lz).div(two),
    };
    let offset = n_out.scale(abs_v(n_out).dot(err));
    let side0 = round_off_v(mid.add(offset), offset);
    let back = neg_v(offset);
    let side1 = round_off_v(mid.add(back), back);

    v.store3(
        col::LO,
        k,
        V3 {
            x: lx,
            y: ly,
            z: lz,
        },
    );
    v.store3(
        col::HI,
        k,
        V3 {
            x: hx,
            y: hy,
            z: hz,
        },
    );
    v.store3(col::MID, k, mid);
    v.store3(col::SIDE0, k, side0);
    v.store3(col::SIDE1, k, side1);
    v.store3(col::N_OUT, k, n_out);
    v.store3(col::NS, k, ns);
    v.store3(col::WO, k, wo);
    v.store3(col::X, k, x);
    v.store3(col::Y, k, y);
    let okb = L::bits(ok);
    for (i, o) in v.ok[k..k + n].iter_mut().enumerate() {
        *o = (okb >> i) & 1 != 0;
    }
}

/// The surface kernel at `level`'s width over every slot taken: the hit
/// point and its error bound, ωo, the interpolated shading normal, the
/// shading tangents and the BSDF's frame.
pub(crate) fn surfaces(level: SimdLevel, v: &mut LaneVertices) {
    dispatch(level, Surfaces(v));
}

/// `v` in the frame of axes `x`, `y`, `z` (`Frame::to_local`). (A function,
/// not a closure: a closure would be compiled without the kernel's
/// instruction set, its lane operations not inlined.)
#[inline(always)]
fn to_local<L: F32Lanes>(x: V3<L>, y: V3<L>, z: V3<L>, v: V3<L>) -> V3<L> {
    V3 {
        x: v.dot(x),
        y: v.dot(y),
        z: v.dot(z),
    }
}

/// [`scatters`] as a kernel.
struct Scatters<'a> {
    v: &'a mut LaneVertices,
    from_wo: bool,
}

impl Kernel for Scatters<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let mut k = 0;
        while k < self.v.len {
            scatter_lanes::<L>(self.v, k, self.from_wo);
            k += L::N;
        }
    }
}

/// The scatter kernel on the slots from `k`, `L::N` of them.
#[inline(always)]
fn scatter_lanes<L: F32Lanes>(v: &mut LaneVertices, k: usize, from_wo: bool) {
    let n = (v.len - k).min(L::N);
    let s = L::splat;
    let zero = s(0.0);
    let fx = v.load3::<L>(col::X, k);
    let fy = v.load3::<L>(col::Y, k);
    let fz = v.load3::<L>(col::NS, k);
    let f: [L; 4] = std::array::from_fn(|w| v.load::<L>(col::R + w, k).mul(s(INV_PI)));

    // Toward the light: `BSDF::f` (zero for a grazing ωo or across
    // hemispheres) times the cosine, and `BSDF::pdf`.
    let wo_r = v.load3::<L>(col::WO, k);
    let wo = to_local(fx, fy, fz, wo_r);
    let wi_r = v.load3::<L>(col::WI, k);
    let wi = to_local(fx, fy, fz, wi_r);
    let same = L::and(wo.z.mul(wi.z).gt(zero), L::not(wo.z.eq(zero)));
    let cos = wi_r.dot(fz).abs();
    for (w, &fw) in f.iter().enumerate() {
        v.store(col::F_LIGHT + w, k, L::select(same, fw, zero).mul(cos));
    }
    let pdf_light = L::select(same, wi.z.abs().mul(s(INV_PI)), zero);
    v.store(col::PDF_LIGHT, k, pdf_light);

    // The sample: a cosine-weighted direction on ωo's side (the
    // concentric disk lifted to the hemisphere), from ωo itself or from
    // the negated ray direction, as the integrator's scalar vertex takes
    // it.
    let wo_s = if from_wo {
        wo
    } else {
        to_local(fx, fy, fz, neg_v(v.load3::<L>(col::D, k)))
    };
    let ux: L = v.load(col::U2, k);
    let uy: L = v.load(col::U2 + 1, k);
    let ox = s(2.0).mul(ux).sub(s(1.0));
    let oy = s(2.0).mul(uy).sub(s(1.0));
    let center = L::and(ox.eq(zero), oy.eq(zero));
    let x_major = ox.abs().gt(oy.abs());
    let radius = L::select(x_major, ox, oy);
    let phi = s(PI_OVER_4).mul(L::select(x_major, oy.div(ox), ox.div(oy)));
    // The library's sine and cosine, as the scalar sample takes them.
    let mut sin = [0.0f32; MAX_LANES];
    let mut cos_phi = [0.0f32; MAX_LANES];
    let mut phis = [0.0f32; MAX_LANES];
    phi.store(&mut phis);
    for i in 0..n {
        (sin[i], cos_phi[i]) = phis[i].sin_cos();
    }
    let (sin, cos_phi) = (L::load(&sin), L::load(&cos_phi));
    let cos_t = L::select(x_major, cos_phi, sin);
    let sin_t = L::select(x_major, sin, cos_phi);
    let dx = L::select(center, zero, radius.mul(cos_t));
    let dy = L::select(center, zero, radius.mul(sin_t));
    let z = s(1.0).sub(dx.mul(dx)).sub(dy.mul(dy)).max(zero).sqrt();
    let z = L::select(wo_s.z.lt(zero), z.neg(), z);
    let pdf = z.abs().mul(s(INV_PI));
    let sampled = L::and(
        L::not(wo_s.z.eq(zero)),
        L::and(L::not(pdf.eq(zero)), L::not(z.eq(zero))),
    );
    // Back to rendering space (`Frame::from_local`).
    let wi_s = fx.scale(dx).add(fy.scale(dy)).add(fz.scale(z));
    let cos_over_pdf = wi_s.dot(fz).abs().div(pdf);
    v.store3(col::WI_S, k, wi_s);
    v.store(col::PDF, k, pdf);
    v.store(col::COS_OVER_PDF, k, cos_over_pdf);
    let sb = L::bits(sampled);
    for (i, o) in v.sampled[k..k + n].iter_mut().enumerate() {
        *o = (sb >> i) & 1 != 0;
    }
}

/// The scatter kernel at `level`'s width over every slot taken: the
/// Lambertian BSDF's value and density toward the light sample, and its
/// cosine-weighted sample of the next direction, from ωo (`from_wo`) or
/// from the negated ray direction (pbrt-v4's `DiffuseBxDF` through
/// `BSDF::f`, `BSDF::PDF` and `BSDF::Sample_f`).
pub(crate) fn scatters(level: SimdLevel, v: &mut LaneVertices, from_wo: bool) {
    dispatch(level, Scatters { v, from_wo });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bxdf::{BxDF, BxDFReflTransFlags, DiffuseBxDF, TransportMode, BSDF};
    use crate::rng::Rng;
    use crate::shape::triangle::TriangleOf;
    use crate::shape::TriangleMesh;
    use rpbrt_geometry::ray::offset_ray_origin;

    fn vector(rng: &mut Rng, scale: Float) -> Vector3f {
        let mut c = || (2.0 * rng.uniform_float() - 1.0) * scale;
        Vector3f::new(c(), c(), c())
    }

    /// Both kernels, at every width this processor runs, give what the
    /// scalar triangle interaction and diffuse BSDF give, bit for bit, on
    /// thousands of random hits (meshes with and without vertex normals,
    /// normals turned away, either orientation) and light directions.
    #[test]
    fn kernels_match_the_scalar_interaction_and_bsdf() {
        let mut rng = Rng::new(5, 0);
        let (mut compared, mut sampled, mut taken) = (0, 0, 0);
        for case in 0..3000 {
            let normals = case % 3 != 0;
            let n = vector(&mut rng, 1.0);
            let mesh = TriangleMesh {
                indices: vec![0, 1, 2],
                p: (0..3)
                    .map(|_| Point3f::from(vector(&mut rng, 10.0)))
                    .collect(),
                n: normals.then(|| {
                    (0..3)
                        .map(|_| {
                            let flip = if rng.uniform_float() < 0.1 { -1.0 } else { 1.0 };
                            Normal3f::from((n + vector(&mut rng, 0.3)) * flip)
                        })
                        .collect()
                }),
                s: None,
                uv: None,
                face_indices: None,
                reverse_orientation: case % 2 == 0,
                transform_swaps_handedness: case % 5 == 0,
            };
            let tri = TriangleOf {
                mesh: &mesh,
                tri_index: 0,
            };
            let frame = tri.frame();
            let (b1, b2) = (rng.uniform_float(), rng.uniform_float());
            let (b1, b2) = if b1 + b2 > 1.0 {
                (1.0 - b1, 1.0 - b2)
            } else {
                (b1, b2)
            };
            let b0 = 1.0 - b1 - b2;
            let d = vector(&mut rng, 1.0) * (0.5 + rng.uniform_float());
            let ray = Ray::new(Point3f::default(), d);
            let si = tri.interaction_at_hit_with_frame(&frame, b0, b1, b2, &ray);
            let r = SampledSpectrum {
                values: [0.1, 0.5, 0.9, 1.0].map(|v| v * rng.uniform_float()),
            };
            let bsdf = BSDF::new(
                si.shading.n,
                si.shading.dpdu,
                BxDF::Diffuse(DiffuseBxDF::new(r)),
            );
            let hit = TriangleHit {
                tri,
                frame: Some(&frame),
                b: [b0, b1, b2],
                material: None,
                area_light: None,
            };
            let wi = vector(&mut rng, 1.0).normalize();
            let u2 = Point2f::new(rng.uniform_float(), rng.uniform_float());
            for level in SimdLevel::available() {
                // Slots 0..3 with the same hit, so that slot 1 has
                // neighbours in its vector; then slots of another vertex
                // up to a whole vector and one more.
                let mut v = LaneVertices::default();
                for _ in 0..3 {
                    assert!(v.push(&hit, d), "no shading tangents");
                }
                for _ in 3..17 {
                    assert!(v.push(&hit, -d));
                }
                surfaces(level, &mut v);
                if !v.ok(1) {
                    continue;
                }
                let s = v.surface_out(1);
                taken += 1;
                let bits = |v: Vector3f| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                assert_eq!(s.pi, si.pi, "{level:?} case {case}");
                let pbits = |p: Point3f| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                assert_eq!(pbits(v.point(col::MID, 1)), pbits(si.p()));
                for (k, w) in [Vector3f::from(si.n), -Vector3f::from(si.n)]
                    .into_iter()
                    .enumerate()
                {
                    let want = offset_ray_origin(si.p(), si.p_error(), si.n, w);
                    assert_eq!(
                        pbits(s.sides[k]),
                        pbits(want),
                        "{level:?} case {case} side {k}"
                    );
                }
                assert_eq!(bits(Vector3f::from(s.n)), bits(Vector3f::from(si.n)));
                assert_eq!(
                    bits(Vector3f::from(s.ns)),
                    bits(Vector3f::from(si.shading.n))
                );
                assert_eq!(bits(s.wo), bits(si.wo));
                assert_eq!(
                    bits(s.x),
                    bits(bsdf.shading_frame.x),
                    "{level:?} case {case}"
                );
                assert_eq!(bits(s.y), bits(bsdf.shading_frame.y));
                let mut ctx = LightSampleContext::default();
                v.write_context(1, &mut ctx);
                assert_eq!(ctx.pi, si.pi);

                // The scatter kernel, from the negated ray direction (the
                // path tracer) and from ωo (the volumetric one: the same
                // direction here, normalized).
                for from_wo in [false, true] {
                    for k in 0..v.len {
                        let u = Point2f::new(0.5, 0.5);
                        let u2 = if k == 1 { u2 } else { u };
                        v.begin(k, r, (0.5, u, 0.5, u2));
                        v.set_light_direction(k, wi);
                    }
                    scatters(level, &mut v, from_wo);
                    let mode = TransportMode::Radiance;
                    let all = BxDFReflTransFlags::ALL;
                    let f = bsdf.f(si.wo, wi, mode) * abs_dot(wi, si.shading.n);
                    let (f_light, pdf_light) = v.light_answers(1);
                    assert_eq!(f_light, f, "{level:?} case {case}");
                    let pdf = bsdf.pdf(si.wo, wi, mode, all);
                    assert_eq!(pdf_light.to_bits(), pdf.to_bits());
                    assert_eq!(v.r(1), r);
                    let wo = if from_wo { si.wo } else { -d };
                    let bs = bsdf.sample_f(wo, 0.5, u2, mode, all);
                    match (v.sample(1), bs) {
                        (Some((w, p, c)), Some(bs)) => {
                            assert_eq!(bits(w), bits(bs.wi), "{level:?} case {case}");
                            assert_eq!(p.to_bits(), bs.pdf.to_bits());
                            let want = abs_dot(bs.wi, si.shading.n) / bs.pdf;
                            assert_eq!(c.to_bits(), want.to_bits());
                            assert_eq!(bs.f, r * INV_PI);
                            sampled += 1;
                        }
                        (None, None) => {}
                        (got, want) => panic!("{level:?} case {case}: {got:?} against {want:?}"),
                    }
                }
                compared += 1;
            }
        }
        let levels = SimdLevel::available().len();
        assert!(taken > 2900 * levels, "{taken}");
        assert!(compared == taken && sampled > 5000 * levels, "{sampled}");
    }
}
