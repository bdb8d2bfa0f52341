//! The wavefront's diffuse vertex: the commonest path vertex of all, a
//! hit on a triangle of a plain `diffuse` material with a constant
//! reflectance, taken lane-parallel from the hit to the next ray, without
//! building the general surface interaction and BSDF the scalar vertex
//! builds (about 400 bytes a vertex, most of which this vertex never
//! reads).
//!
//! Two kernels, each a fixed sequence of the IEEE operations the scalar
//! code performs, so that every width gives the scalar vertex's bits:
//!
//! 1. [`surfaces`], after the closest hits: the hit point and its error
//!    bound, ωo, the interpolated shading normal, the shading tangents
//!    and the BSDF's frame (pbrt-v4's `Triangle::InteractionFromIntersection`
//!    and `BSDF` constructor). What follows per lane (the point's
//!    interval, the reflectance, the sampler draws and the light
//!    request) runs the scalar code itself.
//! 2. [`scatters`], after the light stage: the Lambertian BSDF's value and
//!    density toward the light sample, and its cosine-weighted sample of
//!    the next direction (pbrt-v4's `DiffuseBxDF` through `BSDF::f`,
//!    `BSDF::PDF` and `BSDF::Sample_f`).
//!
//! The surface kernel also serves the specular vertex of a smooth
//! `dielectric` of constant index ([`lane_surface`]): on its surface
//! the scalar BSDF's own sampling runs per lane, in the BSDF's frame the
//! kernel built, with no general interaction built at all.
//!
//! Lanes where the scalar code takes a rare branch (a shading normal
//! perpendicular to the tangent, derivatives rescaled) are flagged and
//! take the scalar vertex instead.

use super::bsdf_stage::BsdfAnswers;
use super::direct::{LightAnswer, LightRequest};
use super::Scene;
use crate::bxdf::lanes::{gather_f, gather_s, MAX_LANES, S4};
use crate::bxdf::{BSDFSample, BxDF, DielectricBxDF, BSDF};
use crate::light::LightSampleContext;
use crate::primitive::{HitRecord, TriangleHit};
use crate::sampler::Sampler;
use crate::simd::math::{self, V3};
use crate::simd::{dispatch, F32Lanes, Kernel, SimdLevel};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::{gamma, Float, INV_PI, PI_OVER_4};
use rpbrt_geometry::frame::Frame;
use rpbrt_geometry::interval::Interval;
use rpbrt_geometry::pointfi::Point3fi;
use rpbrt_geometry::ray::{spawn_ray_from_origin_to_surface, Ray, SHADOW_EPSILON};
use rpbrt_geometry::tuple::*;

/// What a vertex that the surface kernel builds shades with.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LaneShade {
    /// A diffuse vertex: a plain `diffuse` material of constant, not
    /// black, reflectance (this, at the path's wavelengths).
    Diffuse(SampledSpectrum),
    /// A specular vertex: a constant specular `dielectric` material
    /// ([`MaterialSet::constant_specular_dielectric`]), its BxDF.
    ///
    /// [`MaterialSet::constant_specular_dielectric`]: crate::material::MaterialSet::constant_specular_dielectric
    Specular(DielectricBxDF),
}

/// How a hit `record` by a ray of direction `d` shades when it is a vertex
/// the lanes take: a triangle without an area light, in a mesh without
/// shading tangents, of a material [`LaneShade`] covers (its specular kind
/// only where `specular` allows it); the surface kernel's input is written
/// to `out`. `None`: the scalar vertex takes it (`out` is then
/// unspecified).
#[inline(always)]
pub(crate) fn lane_surface(
    scene: &Scene,
    record: &HitRecord,
    d: Vector3f,
    lambda: &SampledWavelengths,
    specular: bool,
    out: &mut SurfaceIn,
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
        None if specular => LaneShade::Specular(
            scene
                .materials
                .constant_specular_dielectric(material, lambda)?,
        ),
        None => return None,
    };
    out.fill(&hit, d).then_some(shade)
}

/// What [`surfaces`] needs of one triangle hit.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SurfaceIn {
    /// The barycentrics.
    b: [Float; 3],
    /// The vertices.
    p: [Point3f; 3],
    /// The vertex normals (zero when the mesh has none).
    n: [Normal3f; 3],
    /// The mesh has vertex normals.
    shading: bool,
    /// The triangle's geometric normal and ∂p/∂u.
    ng: Normal3f,
    dpdu: Vector3f,
    /// The ray's direction.
    d: Vector3f,
}

impl SurfaceIn {
    /// Writes the input of a hit on `hit` by a ray of direction `d`;
    /// false for meshes with shading tangents (left to the scalar vertex).
    /// Field by field, in place: a whole input built on the stack and
    /// copied would be written in 8- and 4-byte pieces and read back in
    /// 16-byte ones, which stalls on store forwarding.
    #[inline(always)]
    pub(crate) fn fill(&mut self, hit: &TriangleHit, d: Vector3f) -> bool {
        let mesh = hit.tri.mesh;
        if mesh.s.is_some() {
            return false;
        }
        let v = mesh.vertex_indices(hit.tri.tri_index as usize);
        for (p, &k) in self.p.iter_mut().zip(&v) {
            *p = mesh.p[k];
        }
        match &mesh.n {
            Some(nn) => {
                for (n, &k) in self.n.iter_mut().zip(&v) {
                    *n = nn[k];
                }
                self.shading = true;
            }
            None => {
                self.n = [Normal3f::default(); 3];
                self.shading = false;
            }
        }
        self.b = hit.b;
        hit.frame_parts(&mut self.ng, &mut self.dpdu);
        self.d = d;
        true
    }
}

/// The surface at a hit, as the scalar interaction and BSDF have it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SurfaceOut {
    /// The hit point's interval, and its midpoint (what the interaction
    /// reads as its point).
    pub pi: Point3fi,
    pub p: Point3f,
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
    /// False where the scalar code takes a branch this kernel does not:
    /// the lane must take the scalar vertex.
    pub ok: bool,
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

/// A diffuse vertex between its two halves: what the second half reads
/// of the surface, the BSDF and the sampler draws.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DiffuseVertex {
    /// The hit point's interval and its midpoint.
    pub pi: Point3fi,
    p: Point3f,
    /// Geometric and shading normals.
    pub n: Normal3f,
    pub ns: Normal3f,
    /// ωo (normalized).
    pub wo: Vector3f,
    /// The ray's time.
    pub time: Float,
    /// The BSDF's frame and reflectance.
    pub frame: Frame,
    pub r: SampledSpectrum,
    /// The BSDF sample's draws.
    pub u2: Point2f,
    /// The offset origins to the side of `n` and to the other side.
    sides: [Point3f; 2],
}

impl DiffuseVertex {
    /// The first half of a diffuse vertex (after the integrator has
    /// counted it): this vertex becomes the one of surface `s` hit at
    /// `time` with reflectance `r`, its sampler draws taken; returns its
    /// light request. (Written in place, field by field, for the reason
    /// [`SurfaceIn::fill`] gives.)
    #[inline(always)]
    pub(crate) fn begin(
        &mut self,
        s: &SurfaceOut,
        time: Float,
        r: SampledSpectrum,
        sampler: &mut Sampler,
    ) -> LightRequest {
        let (u_light, u_light_2d, _, u2) = sampler.get_vertex_samples();
        self.pi = s.pi;
        self.p = s.p;
        self.n = s.n;
        self.ns = s.ns;
        self.wo = s.wo;
        self.time = time;
        self.frame.x = s.x;
        self.frame.y = s.y;
        self.frame.z = Vector3f::from(s.ns);
        self.r = r;
        self.u2 = u2;
        self.sides[0] = s.sides[0];
        self.sides[1] = s.sides[1];
        // The light-sampling context: the point offset toward ωo (the
        // BSDF only reflects), the normals; read from `s`, not from the
        // fields just written.
        let z = Vector3f::from(s.ns);
        LightRequest {
            ctx: LightSampleContext {
                pi: Point3fi::from(s.sides[(dot(s.wo, s.n) < 0.0) as usize]),
                n: s.n,
                ns: s.ns,
            },
            u: u_light,
            u_light: u_light_2d,
            hemisphere: Some((z, dot(s.wo, z))),
        }
    }

    /// The context of this vertex for the next vertex's MIS weights.
    #[inline(always)]
    pub(crate) fn write_context(&self, ctx: &mut LightSampleContext) {
        // Field by field (see `SurfaceIn::fill`).
        ctx.pi = self.pi;
        ctx.n = self.n;
        ctx.ns = self.ns;
    }

    /// The ray origin offset off the surface toward `w`'s side.
    #[inline(always)]
    pub(crate) fn toward(&self, w: Vector3f) -> Point3f {
        self.sides[(dot(w, self.n) < 0.0) as usize]
    }

    /// The ray leaving the vertex toward `wi`.
    #[inline(always)]
    pub(crate) fn spawn_ray(&self, wi: Vector3f) -> Ray {
        Ray::with_time(self.toward(wi), wi, self.time, None)
    }

    /// The shadow ray toward a light sample's point `to_p` (normal `to_n`)
    /// and its extent.
    #[inline(always)]
    pub(crate) fn shadow_ray(&self, to_p: Point3fi, to_n: Normal3f) -> (Ray, Float) {
        let p_to = to_p.midpoint();
        let pf = self.toward(p_to - self.p);
        let r = spawn_ray_from_origin_to_surface(pf, self.time, p_to, to_p.error(), to_n);
        (r, 1.0 - SHADOW_EPSILON)
    }
}

/// The components of a point, vector or normal.
macro_rules! xyz {
    ($v:expr) => {{
        let v = $v;
        [v.x, v.y, v.z]
    }};
}

/// Lanes of a 3-vector per item.
#[inline(always)]
fn gather_v<L: F32Lanes>(n: usize, f: impl Fn(usize) -> [Float; 3]) -> V3<L> {
    V3 {
        x: gather_f(n, |i| f(i)[0]),
        y: gather_f(n, |i| f(i)[1]),
        z: gather_f(n, |i| f(i)[2]),
    }
}

/// The lanes of `x`, stored.
#[inline(always)]
fn stored<L: F32Lanes>(x: L) -> [Float; MAX_LANES] {
    let mut a = [0.0; MAX_LANES];
    x.store(&mut a);
    a
}

/// The lanes of a vector, stored: one array per component.
struct Stored3([[Float; MAX_LANES]; 3]);

impl Stored3 {
    #[inline(always)]
    fn new<L: F32Lanes>(v: V3<L>) -> Self {
        Stored3([stored(v.x), stored(v.y), stored(v.z)])
    }
    #[inline(always)]
    fn vector(&self, i: usize) -> Vector3f {
        Vector3f::new(self.0[0][i], self.0[1][i], self.0[2][i])
    }
    #[inline(always)]
    fn normal(&self, i: usize) -> Normal3f {
        Normal3f::new(self.0[0][i], self.0[1][i], self.0[2][i])
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

/// `if m { -v } else { v }` (a sign flip, as `face_forward`).
#[inline(always)]
fn flip_if<L: F32Lanes>(m: L::Mask, v: V3<L>) -> V3<L> {
    let neg = V3 {
        x: v.x.neg(),
        y: v.y.neg(),
        z: v.z.neg(),
    };
    V3::select(m, neg, v)
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

/// [`surfaces`] of at most one width's items.
struct Surfaces<'a> {
    items: &'a [SurfaceIn],
    out: &'a mut [SurfaceOut],
}

impl Kernel for Surfaces<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let it = self.items;
        let n = it.len();
        let s = L::splat;
        let zero = s(0.0);
        let b0: L = gather_f(n, |i| it[i].b[0]);
        let b1: L = gather_f(n, |i| it[i].b[1]);
        let b2: L = gather_f(n, |i| it[i].b[2]);
        let p0 = gather_v::<L>(n, |i| xyz!(it[i].p[0]));
        let p1 = gather_v::<L>(n, |i| xyz!(it[i].p[1]));
        let p2 = gather_v::<L>(n, |i| xyz!(it[i].p[2]));
        let ng = gather_v::<L>(n, |i| xyz!(it[i].ng));
        let dpdu = gather_v::<L>(n, |i| xyz!(it[i].dpdu));
        let d = gather_v::<L>(n, |i| xyz!(it[i].d));
        let shading = L::from_bits(
            it.iter()
                .enumerate()
                .fold(0, |m, (i, x)| m | ((x.shading as u32) << i)),
        );

        // The point, its error bound and ωo (`Triangle::interaction`).
        let (pb0, pb1, pb2) = (p0.scale(b0), p1.scale(b1), p2.scale(b2));
        let p = pb0.add(pb1).add(pb2);
        let p_error = abs_v(pb0)
            .add(abs_v(pb1))
            .add(abs_v(pb2))
            .scale(s(gamma(7)));
        let (wo, wo_ok) = V3 {
            x: d.x.neg(),
            y: d.y.neg(),
            z: d.z.neg(),
        }
        .try_normalize();
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
        let n0 = gather_v::<L>(n, |i| xyz!(it[i].n[0]));
        let n1 = gather_v::<L>(n, |i| xyz!(it[i].n[1]));
        let n2 = gather_v::<L>(n, |i| xyz!(it[i].n[2]));
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

        // The BSDF frame: x along the shading tangent, z the shading
        // normal (`Frame::from_xz`).
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
        let back = V3 {
            x: offset.x.neg(),
            y: offset.y.neg(),
            z: offset.z.neg(),
        };
        let side0 = round_off_v(mid.add(offset), offset);
        let side1 = round_off_v(mid.add(back), back);

        let okb = L::bits(ok);
        let (lo, hi) = (
            Stored3::new(V3 {
                x: lx,
                y: ly,
                z: lz,
            }),
            Stored3::new(V3 {
                x: hx,
                y: hy,
                z: hz,
            }),
        );
        let mid = Stored3::new(mid);
        let (side0, side1) = (Stored3::new(side0), Stored3::new(side1));
        let (n_out, ns, wo) = (Stored3::new(n_out), Stored3::new(ns), Stored3::new(wo));
        let (x, y) = (Stored3::new(x), Stored3::new(y));
        for (i, o) in self.out.iter_mut().enumerate().take(n) {
            let (l, h) = (lo.vector(i), hi.vector(i));
            *o = SurfaceOut {
                pi: Point3fi::new(
                    Interval {
                        low: l.x,
                        high: h.x,
                    },
                    Interval {
                        low: l.y,
                        high: h.y,
                    },
                    Interval {
                        low: l.z,
                        high: h.z,
                    },
                ),
                p: Point3f::from(mid.vector(i)),
                sides: [
                    Point3f::from(side0.vector(i)),
                    Point3f::from(side1.vector(i)),
                ],
                n: n_out.normal(i),
                ns: ns.normal(i),
                wo: wo.vector(i),
                x: x.vector(i),
                y: y.vector(i),
                ok: (okb >> i) & 1 != 0,
            };
        }
    }
}

/// The surfaces of `items` into `out` (cleared first), at `level`'s width.
pub(crate) fn surfaces(level: SimdLevel, items: &[SurfaceIn], out: &mut Vec<SurfaceOut>) {
    out.clear();
    out.resize(items.len(), SurfaceOut::default());
    let width = level.lanes().max(1);
    for (items, out) in items.chunks(width).zip(out.chunks_mut(width)) {
        dispatch(level, Surfaces { items, out });
    }
}

/// What [`scatters`] needs of one vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ScatterIn {
    /// The BSDF frame (z: the shading normal).
    frame: Frame,
    /// ωo (normalized) toward the light sample; the ray's direction, whose
    /// negation is ωo for the BSDF sample (as the scalar vertex has them).
    wo: Vector3f,
    d: Vector3f,
    /// The light sample's direction (any, without a light sample: its
    /// answers are then not read).
    wi: Vector3f,
    /// The reflectance and the BSDF sample's draws.
    r: SampledSpectrum,
    u2: Point2f,
}

impl ScatterIn {
    /// The input of vertex `v`, reached along direction `d`, given its
    /// light sample.
    #[inline(always)]
    pub(crate) fn new(v: &DiffuseVertex, d: Vector3f, light: Option<&LightAnswer>) -> Self {
        ScatterIn {
            frame: v.frame,
            wo: v.wo,
            d,
            wi: light.map_or(Vector3f::default(), |a| a.ls.wi),
            r: v.r,
            u2: v.u2,
        }
    }
}

/// The BSDF's answers at one vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ScatterOut {
    /// `bsdf.f(ωo, ωi) · |ωi · ns|` and `bsdf.pdf(ωo, ωi)` toward the
    /// light sample.
    pub f_light: SampledSpectrum,
    pub pdf_light: Float,
    /// The BSDF sample (`bsdf.sample_f`): its direction in rendering
    /// space, its density, and `|ωi · ns| / pdf`; `None` where the scalar
    /// method returns none.
    pub sample: Option<(Vector3f, Float, Float)>,
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

/// [`scatters`] of at most one width's items.
struct Scatters<'a> {
    items: &'a [ScatterIn],
    out: &'a mut [ScatterOut],
}

impl Kernel for Scatters<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let it = self.items;
        let n = it.len();
        let s = L::splat;
        let zero = s(0.0);
        let fx = gather_v::<L>(n, |i| xyz!(it[i].frame.x));
        let fy = gather_v::<L>(n, |i| xyz!(it[i].frame.y));
        let fz = gather_v::<L>(n, |i| xyz!(it[i].frame.z));
        let r = gather_s::<L>(n, |i| it[i].r);
        let f = S4([
            r.0[0].mul(s(INV_PI)),
            r.0[1].mul(s(INV_PI)),
            r.0[2].mul(s(INV_PI)),
            r.0[3].mul(s(INV_PI)),
        ]);

        // Toward the light: `BSDF::f` (zero for a grazing ωo or across
        // hemispheres) times the cosine, and `BSDF::pdf`.
        let wo = to_local(fx, fy, fz, gather_v::<L>(n, |i| xyz!(it[i].wo)));
        let wi_r = gather_v::<L>(n, |i| xyz!(it[i].wi));
        let wi = to_local(fx, fy, fz, wi_r);
        let same = L::and(wo.z.mul(wi.z).gt(zero), L::not(wo.z.eq(zero)));
        let cos = wi_r.dot(fz).abs();
        let f_light = [
            L::select(same, f.0[0], zero).mul(cos),
            L::select(same, f.0[1], zero).mul(cos),
            L::select(same, f.0[2], zero).mul(cos),
            L::select(same, f.0[3], zero).mul(cos),
        ];
        let pdf_light = L::select(same, wi.z.abs().mul(s(INV_PI)), zero);

        // The sample: a cosine-weighted direction on ωo's side (the
        // concentric disk lifted to the hemisphere).
        let d = gather_v::<L>(n, |i| xyz!(it[i].d));
        let wo_s = to_local(
            fx,
            fy,
            fz,
            V3 {
                x: d.x.neg(),
                y: d.y.neg(),
                z: d.z.neg(),
            },
        );
        let ux: L = gather_f(n, |i| it[i].u2.x);
        let uy: L = gather_f(n, |i| it[i].u2.y);
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

        let sb = L::bits(sampled);
        let f_light = [
            stored(f_light[0]),
            stored(f_light[1]),
            stored(f_light[2]),
            stored(f_light[3]),
        ];
        let (pdf_light, pdf, cos_over_pdf) = (stored(pdf_light), stored(pdf), stored(cos_over_pdf));
        let wi_s = Stored3::new(wi_s);
        for (i, o) in self.out.iter_mut().enumerate().take(n) {
            *o = ScatterOut {
                f_light: SampledSpectrum {
                    values: [f_light[0][i], f_light[1][i], f_light[2][i], f_light[3][i]],
                },
                pdf_light: pdf_light[i],
                sample: ((sb >> i) & 1 != 0).then(|| (wi_s.vector(i), pdf[i], cos_over_pdf[i])),
            };
        }
    }
}

/// The BSDF answers of `items` into `out` (cleared first), at `level`'s
/// width.
pub(crate) fn scatters(level: SimdLevel, items: &[ScatterIn], out: &mut Vec<ScatterOut>) {
    out.clear();
    out.resize(items.len(), ScatterOut::default());
    let width = level.lanes().max(1);
    for (items, out) in items.chunks(width).zip(out.chunks_mut(width)) {
        dispatch(level, Scatters { items, out });
    }
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
            let mut input = SurfaceIn::default();
            assert!(input.fill(&hit, d), "no shading tangents");
            let wi = vector(&mut rng, 1.0).normalize();
            let u2 = Point2f::new(rng.uniform_float(), rng.uniform_float());
            for level in SimdLevel::available() {
                let mut out = Vec::new();
                surfaces(level, &[input; 3], &mut out);
                let s = out[1];
                if !s.ok {
                    continue;
                }
                taken += 1;
                let bits = |v: Vector3f| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                assert_eq!(s.pi, si.pi, "{level:?} case {case}");
                let pbits = |p: Point3f| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                assert_eq!(pbits(s.p), pbits(si.p()));
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

                let input = ScatterIn {
                    frame: bsdf.shading_frame,
                    wo: si.wo,
                    d,
                    wi,
                    r,
                    u2,
                };
                let mut out = Vec::new();
                scatters(level, &[input; 5], &mut out);
                let o = out[3];
                let mode = TransportMode::Radiance;
                let all = BxDFReflTransFlags::ALL;
                let f = bsdf.f(si.wo, wi, mode) * abs_dot(wi, si.shading.n);
                assert_eq!(o.f_light, f, "{level:?} case {case}");
                let pdf = bsdf.pdf(si.wo, wi, mode, all);
                assert_eq!(o.pdf_light.to_bits(), pdf.to_bits());
                let bs = bsdf.sample_f(-d, 0.5, u2, mode, all);
                match (o.sample, bs) {
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
                compared += 1;
            }
        }
        let levels = SimdLevel::available().len();
        assert!(taken > 2900 * levels, "{taken}");
        assert!(compared == taken && sampled > 2500 * levels, "{sampled}");
    }
}
