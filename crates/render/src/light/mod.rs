//! Light sources (book chapter 12; pbrt-v4 `lights.h/.cpp`, `base/light.h`):
//! point, spot, goniometric, projection, distant, diffuse area, uniform,
//! image and portal image infinite lights, all in rendering space.
//!
//! [`Light`] is a closed enum whose methods delegate in one line to the
//! concrete lights. Emission spectra are stored densely sampled (pbrt-v4's
//! `LightBase::LookupSpectrum`) together with a `scale` that already
//! includes pbrt-v4's photometric normalisation (`scale /=
//! SpectrumToPhotometric(spectrum)`) and any `power` / `illuminance`
//! target; see [`create`].

use std::sync::Arc;

use rpbrt_geometry::{
    dot, safe_acos, Bounds3f, DirectionCone, Float, MediumId, Normal3f, Point2f, Point3f, Point3fi,
    Ray, SurfaceInteraction, Vector3f,
};

use crate::simd::F32Lanes;
use crate::spectrum::{
    DenselySampledSpectrum, RgbColorSpace, RgbIlluminantSpectrum, SampledSpectrum,
    SampledWavelengths, Spectrum, RGB,
};

mod area;
pub mod create;
mod cull;
mod distant;
mod infinite;
mod point;
mod portal;
#[cfg(test)]
mod tests;

pub use area::{AreaEmission, DiffuseAreaLight};
pub use create::{create_area_light, create_light, LightDialect, AREA_LIGHT_NAMES, LIGHT_NAMES};
pub use cull::LightCull;
pub use distant::DistantLight;
pub use infinite::{ImageInfiniteLight, UniformInfiniteLight};
pub use point::{GoniometricLight, PointLight, ProjectionLight, SpotLight};
pub use portal::{
    portal_frame, PortalImageInfiniteLight, SummedAreaTable, WindowedPiecewiseConstant2D,
};

/// How a light emits, which decides how integrators may sample it (pbrt-v4
/// `LightType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightType {
    /// Emits from a single point (point, spot, goniometric, projection).
    DeltaPosition,
    /// Emits along a single direction (distant).
    DeltaDirection,
    /// Emits from a surface.
    Area,
    /// Emits from infinitely far away, reached by rays that leave the scene.
    Infinite,
}

impl LightType {
    /// True for lights described by a delta distribution (position or
    /// direction): they cannot be hit by rays.
    #[inline]
    pub fn is_delta(self) -> bool {
        matches!(self, LightType::DeltaPosition | LightType::DeltaDirection)
    }
}

/// The reference point a light is sampled from (pbrt-v4
/// `LightSampleContext`): a point with error bounds and, at surfaces, the
/// geometric and shading normals (zero in participating media).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSampleContext {
    /// The point with its rounding-error intervals.
    pub pi: Point3fi,
    /// Geometric normal (zero away from surfaces).
    pub n: Normal3f,
    /// Shading normal (zero away from surfaces).
    pub ns: Normal3f,
}

impl LightSampleContext {
    /// The context of a surface hit.
    #[inline]
    pub fn from_si(si: &SurfaceInteraction) -> Self {
        LightSampleContext {
            pi: si.pi,
            n: si.n,
            ns: si.shading.n,
        }
    }

    /// A context at a point in space (no surface).
    #[inline]
    pub fn from_point(p: Point3f) -> Self {
        LightSampleContext {
            pi: Point3fi::from(p),
            n: Normal3f::default(),
            ns: Normal3f::default(),
        }
    }

    /// The reference point.
    #[inline]
    pub fn p(&self) -> Point3f {
        self.pi.midpoint()
    }
}

/// Incident radiance sampled from a light (pbrt-v4 `LightLiSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLiSample {
    /// Incident radiance (or, for delta lights, the delta's weight).
    pub l: SampledSpectrum,
    /// Unit direction from the reference point toward the light.
    pub wi: Vector3f,
    /// Density of `wi` by solid angle (1 for delta lights).
    pub pdf: Float,
    /// The point on the light (for the shadow ray).
    pub p_light: Point3fi,
    /// Surface normal at `p_light` (zero for non-area lights).
    pub n_light: Normal3f,
}

/// A point on an area light's surface (the `Interaction` of pbrt-v4's
/// `LightLeSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSurfacePoint {
    /// The point with its rounding-error intervals.
    pub pi: Point3fi,
    /// The surface normal there (oriented as the shape's intersections).
    pub n: Normal3f,
    /// Surface (u, v) of the point.
    pub uv: Point2f,
}

/// A ray of emitted light sampled from a light (pbrt-v4 `LightLeSample`),
/// for methods that trace paths from the lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLeSample {
    /// Emitted radiance along the ray (area and infinite lights) or, for
    /// delta lights, the intensity (point-like) or radiance (distant)
    /// whose delta distribution the ray samples, as pbrt-v4.
    pub l: SampledSpectrum,
    /// The ray: unit direction, its time, and the medium it starts in
    /// (for area lights the one on the side of the surface it leaves by;
    /// the origin is offset off the surface).
    pub ray: Ray,
    /// The point on the surface for area lights; `None` for other lights.
    pub surface: Option<LightSurfacePoint>,
    /// Density of the ray's origin: per unit area on the light's surface
    /// (area lights) or on the disk the ray is sampled through (distant
    /// and infinite lights); 1 for the delta position of point-like lights.
    pub pdf_pos: Float,
    /// Density of the ray's direction per unit solid angle (1 for the
    /// delta direction of distant lights).
    pub pdf_dir: Float,
}

/// A bound on a light's position, emitted power and emission directions,
/// used by the BVH light sampler (pbrt-v4 `LightBounds`, book section
/// 12.6.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Spatial bounds of the emitter.
    pub bounds: Bounds3f,
    /// Principal emission direction (unit).
    pub w: Vector3f,
    /// Bound on emitted power.
    pub phi: Float,
    /// Cosine of the spread of surface normals around `w`.
    pub cos_theta_o: Float,
    /// Cosine of the angle beyond the normals over which light is emitted.
    pub cos_theta_e: Float,
    /// Whether light leaves both sides of the surface.
    pub two_sided: bool,
}

impl Default for LightBounds {
    /// Bounds of nothing: zero power.
    fn default() -> Self {
        LightBounds {
            bounds: Bounds3f::default(),
            w: Vector3f::new(0.0, 0.0, 1.0),
            phi: 0.0,
            cos_theta_o: 1.0,
            cos_theta_e: 1.0,
            two_sided: false,
        }
    }
}

/// cos(max(0, a − b)) from the sines and cosines of `a` and `b`.
#[inline]
fn cos_sub_clamped(sin_a: Float, cos_a: Float, sin_b: Float, cos_b: Float) -> Float {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(max(0, a − b)) from the sines and cosines of `a` and `b`.
#[inline]
fn sin_sub_clamped(sin_a: Float, cos_a: Float, sin_b: Float, cos_b: Float) -> Float {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

#[inline]
fn safe_sqrt1m(c: Float) -> Float {
    (1.0 - c * c).max(0.0).sqrt()
}

impl LightBounds {
    /// Bounds from their parts; `w` is normalised.
    pub fn new(
        bounds: Bounds3f,
        w: Vector3f,
        phi: Float,
        cos_theta_o: Float,
        cos_theta_e: Float,
        two_sided: bool,
    ) -> Self {
        LightBounds {
            bounds,
            w: w.try_normalize().unwrap_or(Vector3f::new(0.0, 0.0, 1.0)),
            phi,
            cos_theta_o,
            cos_theta_e,
            two_sided,
        }
    }

    /// The centre of the spatial bounds.
    #[inline]
    pub fn centroid(&self) -> Point3f {
        self.bounds.lerp(Point3f::new(0.5, 0.5, 0.5))
    }

    /// A conservative estimate of the light's contribution at `p` with
    /// surface normal `n` (zero normal: a point in a medium), exactly as
    /// pbrt-v4's `LightBounds::Importance`.
    pub fn importance(&self, p: Point3f, n: Normal3f) -> Float {
        PreparedLightBounds::new(self).importance(p, n)
    }

    /// The bounds of both (pbrt-v4 `Union(LightBounds, LightBounds)`):
    /// zero-power bounds are ignored.
    pub fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
        if a.phi == 0.0 {
            return *b;
        }
        if b.phi == 0.0 {
            return *a;
        }
        let cone = DirectionCone::union(
            &DirectionCone::new(a.w, a.cos_theta_o),
            &DirectionCone::new(b.w, b.cos_theta_o),
        );
        LightBounds::new(
            a.bounds.union(&b.bounds),
            cone.w,
            a.phi + b.phi,
            cone.cos_theta,
            a.cos_theta_e.min(b.cos_theta_e),
            a.two_sided || b.two_sided,
        )
    }
}

/// [`LightBounds`] with the quantities [`LightBounds::importance`] derives
/// from the bounds alone computed once (the BVH light sampler evaluates
/// the importance of the same nodes at every shading point). Importance
/// values are bit-identical to [`LightBounds::importance`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreparedLightBounds {
    /// The bounds.
    pub bounds: LightBounds,
    centroid: Point3f,
    half_diagonal: Float,
    sphere_center: Point3f,
    sphere_radius2: Float,
    sin_theta_o: Float,
}

impl PreparedLightBounds {
    /// Precomputes the parts of the importance that depend on `lb` alone.
    pub fn new(lb: &LightBounds) -> Self {
        let (sphere_center, radius) = lb.bounds.bounding_sphere();
        PreparedLightBounds {
            bounds: *lb,
            centroid: lb.centroid(),
            half_diagonal: lb.bounds.diagonal().length() / 2.0,
            sphere_center,
            sphere_radius2: radius * radius,
            sin_theta_o: safe_sqrt1m(lb.cos_theta_o),
        }
    }

    /// The numbers [`importance_lanes`] reads, in its order.
    #[inline(always)]
    fn fields(&self) -> [Float; 16] {
        let b = &self.bounds;
        [
            self.centroid.x,
            self.centroid.y,
            self.centroid.z,
            self.half_diagonal,
            b.w.x,
            b.w.y,
            b.w.z,
            if b.two_sided { 1.0 } else { 0.0 },
            self.sphere_center.x,
            self.sphere_center.y,
            self.sphere_center.z,
            self.sphere_radius2,
            self.sin_theta_o,
            b.cos_theta_o,
            b.cos_theta_e,
            b.phi,
        ]
    }

    /// pbrt-v4's `LightBounds::Importance` (see [`LightBounds::importance`]).
    #[inline(always)]
    pub fn importance(&self, p: Point3f, n: Normal3f) -> Float {
        let lb = &self.bounds;
        let pc = self.centroid;
        let d2 = p.distance_squared(pc).max(self.half_diagonal);
        let wi = (p - pc).try_normalize().unwrap_or_default();
        let mut cos_theta_w = dot(lb.w, wi);
        if lb.two_sided {
            cos_theta_w = cos_theta_w.abs();
        }
        let sin_theta_w = safe_sqrt1m(cos_theta_w);
        // Angle subtended by the bounds' bounding sphere as seen from p
        // (the whole sphere of directions from inside it).
        let ds2 = p.distance_squared(self.sphere_center);
        let cos_theta_b = if ds2 < self.sphere_radius2 {
            -1.0
        } else {
            rpbrt_geometry::safe_sqrt(1.0 - self.sphere_radius2 / ds2)
        };
        let sin_theta_b = safe_sqrt1m(cos_theta_b);
        // θ' = max(0, θ_w − θ_o − θ_b), in two clamped steps.
        let (sin_theta_o, cos_theta_o) = (self.sin_theta_o, lb.cos_theta_o);
        let cos_theta_x = cos_sub_clamped(sin_theta_w, cos_theta_w, sin_theta_o, cos_theta_o);
        let sin_theta_x = sin_sub_clamped(sin_theta_w, cos_theta_w, sin_theta_o, cos_theta_o);
        let cos_theta_p = cos_sub_clamped(sin_theta_x, cos_theta_x, sin_theta_b, cos_theta_b);
        if cos_theta_p <= lb.cos_theta_e {
            return 0.0;
        }
        let mut importance = lb.phi * cos_theta_p / d2;
        if n != Normal3f::default() {
            let cos_theta_i = dot(wi, Vector3f::from(n)).abs();
            let sin_theta_i = safe_sqrt1m(cos_theta_i);
            importance *= cos_sub_clamped(sin_theta_i, cos_theta_i, sin_theta_b, cos_theta_b);
        }
        importance.max(0.0)
    }
}

/// [`PreparedLightBounds::importance`] of two bounds at once, bit for bit:
/// the same operations in the same order, lane by lane, with the branches
/// turned into selections, so that the compiler can evaluate both (the
/// two children of a light-BVH node) in the same vector instructions.
#[inline(always)]
pub fn importance2(
    a: &PreparedLightBounds,
    b: &PreparedLightBounds,
    p: Point3f,
    n: Normal3f,
) -> [Float; 2] {
    // Four lanes (the second bounds repeated) map onto one SSE register.
    const L: usize = 4;
    macro_rules! lanes {
        (|$pb:ident| $e:expr) => {{
            let f = |$pb: &PreparedLightBounds| $e;
            let (x, y) = (f(a), f(b));
            [x, y, y, y]
        }};
    }
    let sel = |c: bool, x: Float, y: Float| if c { x } else { y };
    let (cx, cy, cz) = (
        lanes!(|q| q.centroid.x),
        lanes!(|q| q.centroid.y),
        lanes!(|q| q.centroid.z),
    );
    let half_diagonal = lanes!(|q| q.half_diagonal);
    let (wx, wy, wz) = (
        lanes!(|q| q.bounds.w.x),
        lanes!(|q| q.bounds.w.y),
        lanes!(|q| q.bounds.w.z),
    );
    let two_sided = lanes!(|q| if q.bounds.two_sided { 1.0 } else { 0.0 });
    let (sx, sy, sz) = (
        lanes!(|q| q.sphere_center.x),
        lanes!(|q| q.sphere_center.y),
        lanes!(|q| q.sphere_center.z),
    );
    let r2 = lanes!(|q| q.sphere_radius2);
    let sin_o = lanes!(|q| q.sin_theta_o);
    let cos_o = lanes!(|q| q.bounds.cos_theta_o);
    let cos_e = lanes!(|q| q.bounds.cos_theta_e);
    let phi = lanes!(|q| q.bounds.phi);
    let has_n = n != Normal3f::default();
    // Step by step over the lanes, so that each step is one vector
    // operation.
    let map = |f: &dyn Fn(usize) -> Float| -> [Float; L] { std::array::from_fn(f) };
    let dx = map(&|i| p.x - cx[i]);
    let dy = map(&|i| p.y - cy[i]);
    let dz = map(&|i| p.z - cz[i]);
    let len2 = map(&|i| dx[i] * dx[i] + dy[i] * dy[i] + dz[i] * dz[i]);
    let d2 = map(&|i| len2[i].max(half_diagonal[i]));
    let l = map(&|i| len2[i].sqrt());
    let ok = map(&|i| {
        if l[i] > 0.0 && l[i] < Float::INFINITY {
            1.0
        } else {
            0.0
        }
    });
    let wix = map(&|i| sel(ok[i] != 0.0, dx[i] / l[i], 0.0));
    let wiy = map(&|i| sel(ok[i] != 0.0, dy[i] / l[i], 0.0));
    let wiz = map(&|i| sel(ok[i] != 0.0, dz[i] / l[i], 0.0));
    let cos_w = map(&|i| wx[i] * wix[i] + wy[i] * wiy[i] + wz[i] * wiz[i]);
    let cos_w = map(&|i| sel(two_sided[i] != 0.0, cos_w[i].abs(), cos_w[i]));
    let sin_w = map(&|i| safe_sqrt1m(cos_w[i]));
    let ex = map(&|i| p.x - sx[i]);
    let ey = map(&|i| p.y - sy[i]);
    let ez = map(&|i| p.z - sz[i]);
    let ds2 = map(&|i| ex[i] * ex[i] + ey[i] * ey[i] + ez[i] * ez[i]);
    let root = map(&|i| rpbrt_geometry::safe_sqrt(1.0 - r2[i] / ds2[i]));
    let cos_b = map(&|i| sel(ds2[i] < r2[i], -1.0, root[i]));
    let sin_b = map(&|i| safe_sqrt1m(cos_b[i]));
    let cos_x = map(&|i| cos_sub_clamped_sel(sin_w[i], cos_w[i], sin_o[i], cos_o[i]));
    let sin_x = map(&|i| sin_sub_clamped_sel(sin_w[i], cos_w[i], sin_o[i], cos_o[i]));
    let cos_p = map(&|i| cos_sub_clamped_sel(sin_x[i], cos_x[i], sin_b[i], cos_b[i]));
    let mut imp = map(&|i| phi[i] * cos_p[i] / d2[i]);
    if has_n {
        let cos_i = map(&|i| (wix[i] * n.x + wiy[i] * n.y + wiz[i] * n.z).abs());
        let sin_i = map(&|i| safe_sqrt1m(cos_i[i]));
        let f = map(&|i| cos_sub_clamped_sel(sin_i[i], cos_i[i], sin_b[i], cos_b[i]));
        imp = map(&|i| imp[i] * f[i]);
    }
    let out = map(&|i| sel(cos_p[i] <= cos_e[i], 0.0, imp[i].max(0.0)));
    [out[0], out[1]]
}

/// [`PreparedLightBounds::importance`] of up to `L::N` bounds at as many
/// points at once (lane `i`: `bounds[i]` at `p[i]` with normal `n[i]`;
/// missing lanes are computed on empty bounds and mean nothing), bit for
/// bit: [`importance2`]'s operations, lane-wise. The BVH light sampler's
/// batched descent ([`crate::lightsampler::BvhLightSampler::sample_batch`])
/// evaluates one child of each lane's node with it.
#[inline(always)]
pub(crate) fn importance_lanes<L: F32Lanes>(
    bounds: &[&PreparedLightBounds],
    p: &[L; 3],
    n: &[L; 3],
) -> L {
    const MAX: usize = crate::simd::MAX_LANES;
    let empty = PreparedLightBounds::default();
    // The bounds' fields, one row per field, gathered in one pass over
    // the lanes (a plain loop: closures here become calls per lane).
    let mut rows = [[0.0 as Float; MAX]; 16];
    for i in 0..L::N {
        let q = bounds.get(i).copied().unwrap_or(&empty);
        for (row, f) in rows.iter_mut().zip(q.fields()) {
            row[i] = f;
        }
    }
    let mut lanes = [L::splat(0.0); 16];
    for (l, row) in lanes.iter_mut().zip(&rows) {
        *l = L::load(row);
    }
    importance_of_fields(lanes, p, n)
}

/// [`importance_lanes`] where every lane has the same bounds `b`.
#[inline(always)]
pub(crate) fn importance_lanes_uniform<L: F32Lanes>(
    b: &PreparedLightBounds,
    p: &[L; 3],
    n: &[L; 3],
) -> L {
    let mut lanes = [L::splat(0.0); 16];
    for (l, f) in lanes.iter_mut().zip(b.fields()) {
        *l = L::splat(f);
    }
    importance_of_fields(lanes, p, n)
}

/// The importance, lane-wise, of bounds given as their
/// [`PreparedLightBounds::fields`].
#[inline(always)]
fn importance_of_fields<L: F32Lanes>(f: [L; 16], p: &[L; 3], n: &[L; 3]) -> L {
    let [c0, c1, c2, half_diagonal, w0, w1, w2, two_sided, s0, s1, s2, r2, sin_o, cos_o, cos_e, phi] =
        f;
    let (c, w, sc) = ([c0, c1, c2], [w0, w1, w2], [s0, s1, s2]);
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let d = [p[0].sub(c[0]), p[1].sub(c[1]), p[2].sub(c[2])];
    let len2 = dot3_l(&d, &d);
    let d2 = len2.max(half_diagonal);
    let l = len2.sqrt();
    let ok = L::and(l.gt(zero), l.lt(L::splat(Float::INFINITY)));
    let wi = [
        L::select(ok, d[0].div(l), zero),
        L::select(ok, d[1].div(l), zero),
        L::select(ok, d[2].div(l), zero),
    ];
    let cos_w = dot3_l(&w, &wi);
    let cos_w = L::select(two_sided.eq(one), cos_w.abs(), cos_w);
    let sin_w = safe_sqrt1m_l(cos_w);
    let e = [p[0].sub(sc[0]), p[1].sub(sc[1]), p[2].sub(sc[2])];
    let ds2 = dot3_l(&e, &e);
    let root = one.sub(r2.div(ds2)).max(zero).sqrt();
    let cos_b = L::select(ds2.lt(r2), L::splat(-1.0), root);
    let sin_b = safe_sqrt1m_l(cos_b);
    let cos_x = cos_sub_l(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub_l(sin_w, cos_w, sin_o, cos_o);
    let cos_p = cos_sub_l(sin_x, cos_x, sin_b, cos_b);
    let imp = phi.mul(cos_p).div(d2);
    // At a point with a normal, the cosine at the receiver too.
    let no_n = L::and(L::and(n[0].eq(zero), n[1].eq(zero)), n[2].eq(zero));
    let cos_i = dot3_l(&wi, n).abs();
    let sin_i = safe_sqrt1m_l(cos_i);
    let f = cos_sub_l(sin_i, cos_i, sin_b, cos_b);
    let imp = L::select(no_n, imp, imp.mul(f));
    L::select(cos_p.le(cos_e), zero, imp.max(zero))
}

/// `sqrt(max(0, 1 − c²))`, lane-wise.
#[inline(always)]
fn safe_sqrt1m_l<L: F32Lanes>(c: L) -> L {
    L::splat(1.0).sub(c.mul(c)).max(L::splat(0.0)).sqrt()
}

/// [`cos_sub_clamped_sel`], lane-wise.
#[inline(always)]
fn cos_sub_l<L: F32Lanes>(sin_a: L, cos_a: L, sin_b: L, cos_b: L) -> L {
    let v = cos_a.mul(cos_b).add(sin_a.mul(sin_b));
    L::select(cos_a.gt(cos_b), L::splat(1.0), v)
}

/// [`sin_sub_clamped_sel`], lane-wise.
#[inline(always)]
fn sin_sub_l<L: F32Lanes>(sin_a: L, cos_a: L, sin_b: L, cos_b: L) -> L {
    let v = sin_a.mul(cos_b).sub(cos_a.mul(sin_b));
    L::select(cos_a.gt(cos_b), L::splat(0.0), v)
}

/// The dot product of two lane vectors, summed x, y, z in order.
#[inline(always)]
fn dot3_l<L: F32Lanes>(a: &[L; 3], b: &[L; 3]) -> L {
    a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
}

/// [`cos_sub_clamped`] by selection.
#[inline(always)]
fn cos_sub_clamped_sel(sin_a: Float, cos_a: Float, sin_b: Float, cos_b: Float) -> Float {
    let v = cos_a * cos_b + sin_a * sin_b;
    if cos_a > cos_b {
        1.0
    } else {
        v
    }
}

/// [`sin_sub_clamped`] by selection.
#[inline(always)]
fn sin_sub_clamped_sel(sin_a: Float, cos_a: Float, sin_b: Float, cos_b: Float) -> Float {
    let v = sin_a * cos_b - cos_a * sin_b;
    if cos_a > cos_b {
        0.0
    } else {
        v
    }
}

/// A light source: a closed set of variants, each method a one-line
/// delegation (pbrt-v4 `Light`).
#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point light.
    Point(PointLight),
    /// Spotlight with smooth falloff.
    Spot(SpotLight),
    /// Point light modulated by an equal-area goniometric diagram.
    Goniometric(Box<GoniometricLight>),
    /// Point light projecting an image.
    Projection(Box<ProjectionLight>),
    /// Directional light from infinitely far away.
    Distant(DistantLight),
    /// Diffuse emission from a shape's surface.
    DiffuseArea(Box<DiffuseAreaLight>),
    /// Constant radiance from every direction.
    UniformInfinite(UniformInfiniteLight),
    /// Environment map in pbrt-v4's equal-area octahedral layout.
    ImageInfinite(Box<ImageInfiniteLight>),
    /// Environment map seen only through a rectangular portal.
    PortalImageInfinite(Box<PortalImageInfiniteLight>),
}

macro_rules! dispatch {
    ($self:expr, $l:ident => $e:expr) => {
        match $self {
            Light::Point($l) => $e,
            Light::Spot($l) => $e,
            Light::Goniometric($l) => $e,
            Light::Projection($l) => $e,
            Light::Distant($l) => $e,
            Light::DiffuseArea($l) => $e,
            Light::UniformInfinite($l) => $e,
            Light::ImageInfinite($l) => $e,
            Light::PortalImageInfinite($l) => $e,
        }
    };
}

impl Light {
    /// The kind of emission.
    #[inline]
    pub fn light_type(&self) -> LightType {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Goniometric(_) | Light::Projection(_) => {
                LightType::DeltaPosition
            }
            Light::Distant(_) => LightType::DeltaDirection,
            Light::DiffuseArea(_) => LightType::Area,
            Light::UniformInfinite(_) | Light::ImageInfinite(_) | Light::PortalImageInfinite(_) => {
                LightType::Infinite
            }
        }
    }

    /// Samples a direction toward the light from `ctx`. With
    /// `allow_incomplete_pdf`, lights may skip directions that other
    /// sampling (BSDF sampling under MIS) covers well.
    #[inline]
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        lambda: &SampledWavelengths,
        allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        dispatch!(self, l => l.sample_li(ctx, u, lambda, allow_incomplete_pdf))
    }

    /// The solid-angle density with which [`sample_li`](Self::sample_li)
    /// picks `wi` (zero for delta lights).
    #[inline]
    pub fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        wi: Vector3f,
        allow_incomplete_pdf: bool,
    ) -> Float {
        dispatch!(self, l => l.pdf_li(ctx, wi, allow_incomplete_pdf))
    }

    /// Emitted radiance of an area light at surface point `p` (normal `n`,
    /// surface coordinates `uv`) toward `w`; zero for other lights.
    #[inline]
    pub fn l(
        &self,
        p: Point3f,
        n: Normal3f,
        uv: Point2f,
        w: Vector3f,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            Light::DiffuseArea(l) => l.l(p, n, uv, w, lambda),
            _ => SampledSpectrum::new(0.0),
        }
    }

    /// Radiance an infinite light sends along a ray that left the scene;
    /// zero for other lights.
    #[inline]
    pub fn le(&self, ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::UniformInfinite(l) => l.le(ray, lambda),
            Light::ImageInfinite(l) => l.le(ray, lambda),
            Light::PortalImageInfinite(l) => l.le(ray, lambda),
            _ => SampledSpectrum::new(0.0),
        }
    }

    /// Total emitted power.
    #[inline]
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        dispatch!(self, l => l.phi(lambda))
    }

    /// Called once the scene is known: distant and infinite lights record
    /// the scene's bounding sphere.
    #[inline]
    pub fn preprocess(&mut self, scene_bounds: &Bounds3f) {
        match self {
            Light::Distant(l) => l.preprocess(scene_bounds),
            Light::UniformInfinite(l) => l.preprocess(scene_bounds),
            Light::ImageInfinite(l) => l.preprocess(scene_bounds),
            Light::PortalImageInfinite(l) => l.preprocess(scene_bounds),
            _ => {}
        }
    }

    /// Samples a ray leaving the light (pbrt-v4 `SampleLe`): `u1` and
    /// `u2` choose the origin and direction (which one does what depends
    /// on the light, as in pbrt-v4), `time` is the ray's time. `None` when
    /// no ray could be sampled (zero density, a masked-out point).
    #[inline]
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        dispatch!(self, l => l.sample_le(u1, u2, lambda, time))
    }

    /// The densities `(pdf_pos, pdf_dir)` with which
    /// [`sample_le`](Self::sample_le) would produce `ray` (pbrt-v4
    /// `PDF_Le(ray)`); `(0, 0)` for area lights, which need
    /// [`pdf_le_surface`](Self::pdf_le_surface). As in pbrt-v4, point-like
    /// lights report `pdf_pos = 0` (their position is a delta) and distant
    /// lights `pdf_dir = 0` (their direction is).
    #[inline]
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        match self {
            Light::Point(l) => l.pdf_le(ray),
            Light::Spot(l) => l.pdf_le(ray),
            Light::Goniometric(l) => l.pdf_le(ray),
            Light::Projection(l) => l.pdf_le(ray),
            Light::Distant(l) => l.pdf_le(ray),
            Light::DiffuseArea(_) => (0.0, 0.0),
            Light::UniformInfinite(l) => l.pdf_le(ray),
            Light::ImageInfinite(l) => l.pdf_le(ray),
            Light::PortalImageInfinite(l) => l.pdf_le(ray),
        }
    }

    /// The densities `(pdf_pos, pdf_dir)` with which an area light's
    /// [`sample_le`](Self::sample_le) would leave point `p` (normal `n`)
    /// toward `w` (pbrt-v4 `PDF_Le(Interaction, w)`); `(0, 0)` for other
    /// lights.
    #[inline]
    pub fn pdf_le_surface(&self, p: Point3f, n: Normal3f, w: Vector3f) -> (Float, Float) {
        match self {
            Light::DiffuseArea(l) => l.pdf_le_surface(p, n, w),
            _ => (0.0, 0.0),
        }
    }

    /// Bounds for the BVH light sampler; `None` for lights at infinity.
    #[inline]
    pub fn bounds(&self) -> Option<LightBounds> {
        dispatch!(self, l => l.bounds())
    }

    /// The medium the light sits in (outside medium for area lights).
    #[inline]
    pub fn medium(&self) -> Option<MediumId> {
        dispatch!(self, l => l.medium())
    }
}

/// The scene's bounding sphere as infinite and distant lights need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSphere {
    /// Centre of the scene's bounding sphere.
    pub center: Point3f,
    /// Radius of the scene's bounding sphere.
    pub radius: Float,
}

impl Default for SceneSphere {
    fn default() -> Self {
        SceneSphere {
            center: Point3f::new(0.0, 0.0, 0.0),
            radius: 0.0,
        }
    }
}

impl SceneSphere {
    /// The bounding sphere of `b`.
    pub fn from_bounds(b: &Bounds3f) -> Self {
        let (center, radius) = b.bounding_sphere();
        SceneSphere { center, radius }
    }
}

impl SceneSphere {
    /// A ray of direction `w` (unit) through a point sampled uniformly by
    /// `u` on the disk of the scene's bounding sphere perpendicular to
    /// `w`, starting a radius before the disk (outside the sphere), and
    /// the density of that point per unit disk area (pbrt-v4's infinite
    /// and distant lights' `SampleLe`).
    pub fn sample_ray_through_disk(&self, w: Vector3f, u: Point2f, time: Float) -> (Ray, Float) {
        let frame = rpbrt_geometry::Frame::from_z(-w);
        let cd = crate::sampling::sample_uniform_disk_concentric(u);
        let p_disk = self.center + frame.from_local(Vector3f::new(cd.x, cd.y, 0.0)) * self.radius;
        let ray = Ray::with_time(p_disk - w * self.radius, w, time, None);
        (ray, self.disk_pdf())
    }

    /// The density per unit area of a point on the disk of the scene's
    /// bounding sphere: 1/(π r²).
    #[inline]
    pub fn disk_pdf(&self) -> Float {
        1.0 / (rpbrt_geometry::PI * self.radius * self.radius)
    }
}

/// pbrt-v4's `SmoothStep`: 0 below `a`, 1 above `b`, a cubic in between.
#[inline]
pub fn smooth_step(x: Float, a: Float, b: Float) -> Float {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Emission from a stored spectrum (pbrt-v4 `LookupSpectrum`: densely
/// sampled at 1 nm).
pub(crate) fn dense(s: &Spectrum) -> Spectrum {
    match s {
        Spectrum::Constant(_) | Spectrum::DenselySampled(_) => s.clone(),
        _ => Spectrum::DenselySampled(Arc::new(DenselySampledSpectrum::new(s))),
    }
}

/// The emission spectrum of RGB `rgb` (negative components clamped) in
/// colour space `cs`, sampled at `lambda`.
#[inline]
pub(crate) fn rgb_illuminant(
    cs: &RgbColorSpace,
    rgb: [Float; 3],
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    let rgb = RGB::new(rgb[0].max(0.0), rgb[1].max(0.0), rgb[2].max(0.0));
    RgbIlluminantSpectrum::new(cs, rgb).sample(lambda)
}

/// The luminance (Y) weights of a colour space's RGB primaries.
#[inline]
pub(crate) fn luminance_vector(cs: &RgbColorSpace) -> [Float; 3] {
    cs.xyz_from_rgb.m[1]
}

/// `acos` clamped to [-1, 1].
#[inline]
pub(crate) fn acos_c(x: Float) -> Float {
    safe_acos(x)
}
