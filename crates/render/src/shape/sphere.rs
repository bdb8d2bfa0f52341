//! Spheres (book section 6.2; pbrt-v4 `shapes.h` `Sphere`), possibly cut
//! by `zmin`/`zmax` planes and a `phimax` sweep.
//!
//! This file also holds the helpers the quadrics share (ray transformation
//! with error intervals, the conservative quadratic solve, the
//! nearest-hit-with-clipping logic and the Weingarten equations), and, for
//! tests, the harness every quadric's tests run.

use super::{area_sample_to_solid_angle, pdf_by_intersection, ShapeError, ShapeIntersection};
use super::{ShapeMethods, ShapeSample, ShapeSampleContext};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::interval::Interval;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::{spherical_direction, DirectionCone};
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{Bounds3f, Frame};

// ---- helpers shared by the quadrics ----

/// Rejects non-finite parameters with a message naming the shape.
pub(super) fn require_finite(shape: &str, name: &str, v: Float) -> Result<(), ShapeError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ShapeError(format!(
            "{shape}: \"{name}\" must be finite, got {v}"
        )))
    }
}

/// `phimax` in degrees, clamped to [0, 360] like pbrt, converted to
/// radians; a zero sweep has no surface and is an error.
pub(super) fn phi_max_radians(shape: &str, degrees: Float) -> Result<Float, ShapeError> {
    require_finite(shape, "phimax", degrees)?;
    let d = clamp(degrees, 0.0, 360.0);
    if d <= 0.0 {
        return Err(ShapeError(format!(
            "{shape}: \"phimax\" must be positive, got {degrees}"
        )));
    }
    Ok(radians(d))
}

/// The ray's origin and direction in object space, carrying the rounding
/// error of the transformation as intervals (pbrt-v4 transforms `Point3fi`
/// and `Vector3fi` rather than the ray, so that the quadratic's
/// coefficients bound that error too).
#[inline]
pub(super) fn object_ray(object_from_render: &Transform, r: &Ray) -> (Point3fi, Vector3fi) {
    (
        object_from_render.apply_point_fi(Point3fi::from(r.o)),
        object_from_render.apply_vector_fi(Vector3fi::from(r.d)),
    )
}

/// x² + y² + z² over intervals.
#[inline]
pub(super) fn sum_sq(x: Interval, y: Interval, z: Interval) -> Interval {
    x.sqr() + y.sqr() + z.sqr()
}

/// The two roots of a·t² + b·t + c from a discriminant interval already
/// known not to be negative, by the cancellation-free form
/// q = −(b ± √Δ)/2, t0 = q/a, t1 = c/q; ordered by lower bound.
pub(super) fn roots_from_discriminant(
    a: Interval,
    b: Interval,
    c: Interval,
    discrim: Interval,
) -> (Interval, Interval) {
    let root = discrim.sqrt();
    let q = if b.midpoint() < 0.0 {
        (b - root) * -0.5
    } else {
        (b + root) * -0.5
    };
    let mut t0 = q / a;
    let mut t1 = c / q;
    if t0.low > t1.low {
        std::mem::swap(&mut t0, &mut t1);
    }
    (t0, t1)
}

/// The conservative quadratic solve of pbrt-v3's `EFloat` `Quadratic`,
/// used by the quadrics whose coefficients have no simpler discriminant:
/// whether there are roots is decided in double precision from the
/// coefficients' midpoints; the root intervals bound all their error.
pub(super) fn solve_quadratic(
    a: Interval,
    b: Interval,
    c: Interval,
) -> Option<(Interval, Interval)> {
    let (am, bm, cm) = (
        a.midpoint() as f64,
        b.midpoint() as f64,
        c.midpoint() as f64,
    );
    let d = bm * bm - 4.0 * am * cm;
    if d.is_nan() || d < 0.0 {
        return None;
    }
    let mut discrim = b.sqr() - Interval::new(4.0) * a * c;
    // The midpoint test said the roots exist; keep the interval consistent
    // with that decision.
    discrim.low = discrim.low.max(0.0);
    discrim.high = discrim.high.max(d as Float);
    Some(roots_from_discriminant(a, b, c, discrim))
}

/// pbrt's choice of the nearest hit of a quadric: `t0`, unless it is
/// behind the origin or rejected by `hit_at` (clipping by z and φ), then
/// `t1`; both must lie before `t_max`. `hit_at` receives the ray
/// parameter and returns the hit data when the point lies on the clipped
/// surface.
pub(super) fn nearest_hit<H>(
    t0: Interval,
    t1: Interval,
    t_max: Float,
    mut hit_at: impl FnMut(Interval) -> Option<H>,
) -> Option<(Interval, H)> {
    if t0.high > t_max || t1.low <= 0.0 {
        return None;
    }
    let mut t = t0;
    let mut is_t1 = false;
    if t.low <= 0.0 {
        t = t1;
        is_t1 = true;
        if t.high > t_max {
            return None;
        }
    }
    if t.midpoint().is_finite() {
        if let Some(h) = hit_at(t) {
            return Some((t, h));
        }
    }
    if is_t1 || t1.high > t_max || !t1.midpoint().is_finite() {
        return None;
    }
    hit_at(t1).map(|h| (t1, h))
}

/// atan2(y, x) remapped to [0, 2π).
#[inline]
pub(super) fn positive_atan2(y: Float, x: Float) -> Float {
    let phi = y.atan2(x);
    if phi < 0.0 {
        phi + 2.0 * PI
    } else {
        phi
    }
}

/// ∂n/∂u and ∂n/∂v from the first and second partial derivatives of the
/// surface by the Weingarten equations (book section 6.2.3).
pub(super) fn weingarten(
    dpdu: Vector3f,
    dpdv: Vector3f,
    d2pduu: Vector3f,
    d2pduv: Vector3f,
    d2pdvv: Vector3f,
) -> (Normal3f, Normal3f) {
    let big_e = dot(dpdu, dpdu);
    let big_f = dot(dpdu, dpdv);
    let big_g = dot(dpdv, dpdv);
    let n = match cross(dpdu, dpdv).try_normalize() {
        Some(n) => n,
        None => return (Normal3f::default(), Normal3f::default()),
    };
    let e = dot(n, d2pduu);
    let f = dot(n, d2pduv);
    let g = dot(n, d2pdvv);
    let egf2 = difference_of_products(big_e, big_g, big_f, big_f);
    let inv = 1.0 / egf2;
    if !inv.is_finite() {
        return (Normal3f::default(), Normal3f::default());
    }
    let dndu = dpdu * ((f * big_f - e * big_g) * inv) + dpdv * ((e * big_f - f * big_e) * inv);
    let dndv = dpdu * ((g * big_f - f * big_g) * inv) + dpdv * ((f * big_f - g * big_e) * inv);
    (Normal3f::from(dndu), Normal3f::from(dndv))
}

/// The hit point o + t·d in interval arithmetic: the error bound of a
/// point computed with the ray equation (pbrt-v3's cone, paraboloid and
/// hyperboloid).
#[inline]
pub(super) fn ray_point_fi(o: Point3fi, d: Vector3fi, t: Interval) -> Point3fi {
    o + d * t
}

/// Transforms an object-space normal to rendering space and orients it the
/// way intersections orient theirs (flipped by reverse orientation XOR a
/// handedness swap), so sampled and intersected normals agree.
#[inline]
pub(super) fn render_normal(
    render_from_object: &Transform,
    n_obj: Normal3f,
    flip: bool,
) -> Option<Normal3f> {
    let n = render_from_object.apply_normal(n_obj).try_normalize()?;
    Some(if flip { -n } else { n })
}

/// Direction toward the ray's origin, in object space, normalized.
#[inline]
pub(super) fn object_wo(object_from_render: &Transform, r: &Ray) -> Vector3f {
    object_from_render
        .apply_vector(-r.d)
        .try_normalize()
        .unwrap_or_default()
}

/// Common constructor work: the transformation pair and handedness.
pub(super) fn transforms(
    shape: &str,
    render_from_object: Transform,
) -> Result<(Transform, Transform, bool), ShapeError> {
    let m = render_from_object.matrix().m;
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(ShapeError(format!(
            "{shape}: the object-to-render transformation is not finite"
        )));
    }
    let object_from_render = render_from_object.inverse();
    if object_from_render
        .matrix()
        .m
        .iter()
        .flatten()
        .any(|v| !v.is_finite())
    {
        return Err(ShapeError(format!(
            "{shape}: the object-to-render transformation is singular"
        )));
    }
    let swaps = render_from_object.swaps_handedness();
    Ok((render_from_object, object_from_render, swaps))
}

// ---- the sphere ----

/// A sphere of radius `radius` about the object-space origin, clipped to
/// `z_min ≤ z ≤ z_max` and `φ ≤ φ_max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Object-to-render transformation (its inverse, which it holds too,
    /// is the render-to-object one: one transformation, not two, per shape).
    pub render_from_object: Transform,
    /// Whether normals point inward.
    pub reverse_orientation: bool,
    /// Whether `render_from_object` changes handedness.
    pub transform_swaps_handedness: bool,
    radius: Float,
    z_min: Float,
    z_max: Float,
    theta_z_min: Float,
    theta_z_max: Float,
    phi_max: Float,
    /// Rendering-space radius when the solid-angle cone sampling of the
    /// whole sphere applies (a full sphere under a similarity transform).
    cone_radius: Option<Float>,
}

impl Sphere {
    /// A sphere with pbrt's parameters: `z_min`/`z_max` are swapped into
    /// order and clamped to [−radius, radius], `phi_max` (degrees) clamped
    /// to [0, 360]. Fails for a non-positive or non-finite radius, an empty
    /// z range, a zero sweep or a singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        radius: Float,
        z_min: Float,
        z_max: Float,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "sphere";
        require_finite(S, "radius", radius)?;
        require_finite(S, "zmin", z_min)?;
        require_finite(S, "zmax", z_max)?;
        if radius <= 0.0 {
            return Err(ShapeError(format!(
                "sphere: \"radius\" must be positive, got {radius}"
            )));
        }
        let zlo = clamp(z_min.min(z_max), -radius, radius);
        let zhi = clamp(z_min.max(z_max), -radius, radius);
        if zlo >= zhi {
            return Err(ShapeError(format!(
                "sphere: empty z range [{z_min}, {z_max}] for radius {radius}"
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        let full = zlo <= -radius && zhi >= radius && phi_max >= 2.0 * PI;
        let cone_radius = if full {
            uniform_scale(&render_from_object).map(|s| s * radius)
        } else {
            None
        };
        Ok(Sphere {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            radius,
            z_min: zlo,
            z_max: zhi,
            theta_z_min: clamp(zlo / radius, -1.0, 1.0).acos(),
            theta_z_max: clamp(zhi / radius, -1.0, 1.0).acos(),
            phi_max,
            cone_radius,
        })
    }

    /// The radius in object space.
    pub fn radius(&self) -> Float {
        self.radius
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    fn clipped(&self, p: Point3f, phi: Float) -> bool {
        (self.z_min > -self.radius && p.z < self.z_min)
            || (self.z_max < self.radius && p.z > self.z_max)
            || phi > self.phi_max
    }

    /// The hit point refined onto the sphere and its φ.
    fn point_at(&self, o: Point3f, d: Vector3f, t: Float) -> (Point3f, Float) {
        let mut p = o + d * t;
        let len = Vector3f::from(p).length();
        if len > 0.0 {
            p *= self.radius / len;
        }
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * self.radius;
        }
        (p, positive_atan2(p.y, p.x))
    }

    /// pbrt-v4's `BasicIntersect`: the object-space hit, its φ and `t`.
    fn basic_intersect(&self, r: &Ray, t_max: Float) -> Option<(Float, Point3f, Float)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        let a = sum_sq(di.x, di.y, di.z);
        let b = (di.x * oi.x + di.y * oi.y + di.z * oi.z) * 2.0;
        let rad = Interval::new(self.radius);
        let c = sum_sq(oi.x, oi.y, oi.z) - rad.sqr();
        // b² − 4ac rewritten as 4a(r − |o − (b/2a)d|)(r + |…|): the
        // closest point of the ray to the centre, far more accurate than
        // the direct difference for distant, nearly tangent rays.
        let f = b / (a * 2.0);
        let fp = oi - di * f;
        let len = sum_sq(fp.x, fp.y, fp.z).sqrt();
        let discrim = Interval::new(4.0) * a * (rad - len) * (rad + len);
        if discrim.low < 0.0 {
            return None;
        }
        let (t0, t1) = roots_from_discriminant(a, b, c, discrim);
        let (o, d) = (oi.midpoint(), di.midpoint());
        let (t, (p, phi)) = nearest_hit(t0, t1, t_max, |t| {
            let (p, phi) = self.point_at(o, d, t.midpoint());
            (!self.clipped(p, phi)).then_some((p, phi))
        })?;
        Some((t.midpoint(), p, phi))
    }

    fn uv_of(&self, p: Point3f, phi: Float) -> Point2f {
        let theta = safe_acos(p.z / self.radius);
        Point2f::new(
            phi / self.phi_max,
            (theta - self.theta_z_min) / (self.theta_z_max - self.theta_z_min),
        )
    }

    fn interaction(&self, p: Point3f, phi: Float, wo: Vector3f, time: Float) -> SurfaceInteraction {
        let uv = self.uv_of(p, phi);
        let z_radius = (p.x * p.x + p.y * p.y).sqrt();
        let (cos_phi, sin_phi) = (p.x / z_radius, p.y / z_radius);
        let cos_theta = p.z / self.radius;
        let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
        let dtheta = self.theta_z_max - self.theta_z_min;
        let dpdu = Vector3f::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let dpdv = Vector3f::new(p.z * cos_phi, p.z * sin_phi, -self.radius * sin_theta) * dtheta;
        let d2pduu = Vector3f::new(p.x, p.y, 0.0) * (-self.phi_max * self.phi_max);
        let d2pduv = Vector3f::new(-sin_phi, cos_phi, 0.0) * (dtheta * p.z * self.phi_max);
        let d2pdvv = Vector3f::from(p) * (-dtheta * dtheta);
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, d2pduv, d2pdvv);
        let p_error = Vector3f::from(p).abs() * gamma(5);
        SurfaceInteraction::new(
            Point3fi::from_value_and_error(p, p_error),
            uv,
            wo,
            dpdu,
            dpdv,
            dndu,
            dndv,
            time,
            self.flip(),
        )
        .transform(&self.render_from_object)
    }

    /// Whether the reference point is inside the sphere, judged from the
    /// offset origin like pbrt-v4 (so points on the surface count as
    /// inside when their rays leave inward).
    fn ctx_inside(&self, ctx: &ShapeSampleContext, center: Point3f, radius: Float) -> bool {
        let origin = ctx.offset_ray_origin(center - ctx.p());
        origin.distance_squared(center) <= radius * radius
    }
}

/// The common scale factor of a similarity transformation (rotation,
/// translation, uniform scale), or `None` when it scales unevenly.
fn uniform_scale(t: &Transform) -> Option<Float> {
    let lx = t.apply_vector(Vector3f::new(1.0, 0.0, 0.0)).length();
    let ly = t.apply_vector(Vector3f::new(0.0, 1.0, 0.0)).length();
    let lz = t.apply_vector(Vector3f::new(0.0, 0.0, 1.0)).length();
    let ex = Vector3f::new(1.0, 0.0, 0.0);
    let ey = Vector3f::new(0.0, 1.0, 0.0);
    let orthogonal = dot(t.apply_vector(ex), t.apply_vector(ey)).abs() <= 1e-4 * lx * ly
        && dot(
            t.apply_vector(ex),
            t.apply_vector(Vector3f::new(0.0, 0.0, 1.0)),
        )
        .abs()
            <= 1e-4 * lx * lz
        && dot(
            t.apply_vector(ey),
            t.apply_vector(Vector3f::new(0.0, 0.0, 1.0)),
        )
        .abs()
            <= 1e-4 * ly * lz;
    let same = (lx - ly).abs() <= 1e-4 * lx && (lx - lz).abs() <= 1e-4 * lx;
    (orthogonal && same && lx > 0.0).then_some(lx)
}

impl ShapeMethods for Sphere {
    fn bounds(&self) -> Bounds3f {
        let r = self.radius;
        self.render_from_object.apply_bounds(&Bounds3f::new(
            Point3f::new(-r, -r, self.z_min),
            Point3f::new(r, r, self.z_max),
        ))
    }

    fn normal_bounds(&self) -> DirectionCone {
        DirectionCone::entire_sphere()
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        let (t_hit, p, phi) = self.basic_intersect(ray, t_max)?;
        let wo = object_wo(&self.render_from_object.inverse(), ray);
        Some(ShapeIntersection {
            intr: self.interaction(p, phi, wo, ray.time),
            t_hit,
        })
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        self.basic_intersect(ray, t_max).is_some()
    }

    /// Object-space area φ_max·r·(z_max − z_min) (Archimedes), as pbrt.
    fn area(&self) -> Float {
        self.phi_max * self.radius * (self.z_max - self.z_min)
    }

    /// Uniform by area over the clipped sphere: z uniform in
    /// [z_min, z_max] (equal-area zones) and φ uniform in [0, φ_max].
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let z = lerp(u.x, self.z_min, self.z_max);
        let phi = u.y * self.phi_max;
        let rho = safe_sqrt(self.radius * self.radius - z * z);
        let mut p = Point3f::new(rho * phi.cos(), rho * phi.sin(), z);
        let len = Vector3f::from(p).length();
        if len > 0.0 {
            p *= self.radius / len;
        }
        let p_error = Vector3f::from(p).abs() * gamma(5);
        let n = render_normal(
            &self.render_from_object,
            Normal3f::new(p.x, p.y, p.z),
            self.flip(),
        )?;
        let uv = self.uv_of(p, positive_atan2(p.y, p.x).min(self.phi_max));
        Some(ShapeSample {
            pi: self
                .render_from_object
                .apply_point_fi(Point3fi::from_value_and_error(p, p_error)),
            n,
            uv,
            time: 0.0,
            pdf: 1.0 / self.area(),
        })
    }

    /// Uniform inside the cone of directions the whole sphere subtends
    /// when the reference point is outside (pbrt-v4, including its
    /// small-angle care); otherwise area sampling converted to solid angle.
    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        let center = self.render_from_object.apply_point(Point3f::default());
        let radius = match self.cone_radius {
            Some(r) if !self.ctx_inside(ctx, center, r) => r,
            _ => {
                let mut ss = self.sample_area(u)?;
                ss.time = ctx.time;
                return area_sample_to_solid_angle(ctx, ss);
            }
        };
        let dc = ctx.p().distance(center);
        let sin_theta_max = radius / dc;
        let sin2_theta_max = sin_theta_max * sin_theta_max;
        let cos_theta_max = safe_sqrt(1.0 - sin2_theta_max);
        let mut one_minus_cos_theta_max = 1.0 - cos_theta_max;
        let mut cos_theta = (cos_theta_max - 1.0) * u.x + 1.0;
        let mut sin2_theta = 1.0 - cos_theta * cos_theta;
        if sin2_theta_max < SIN2_SMALL_ANGLE {
            // 1 − cos θ loses all precision for tiny cones: use the Taylor
            // expansion in sin²θ instead.
            sin2_theta = sin2_theta_max * u.x;
            cos_theta = (1.0 - sin2_theta).sqrt();
            one_minus_cos_theta_max = sin2_theta_max / 2.0;
        }
        // The angle α at the centre between the axis and the sampled point.
        let cos_alpha = sin2_theta / sin_theta_max
            + cos_theta * safe_sqrt(1.0 - sin2_theta / sqr(sin_theta_max));
        let sin_alpha = safe_sqrt(1.0 - cos_alpha * cos_alpha);
        let phi = u.y * 2.0 * PI;
        let w = spherical_direction(sin_alpha, cos_alpha, phi);
        let frame = Frame::from_z((center - ctx.p()).normalize());
        let nv = frame.from_local(-w);
        let p = center + nv * radius;
        let p_error = Vector3f::from(p).abs() * gamma(5);
        let n = Normal3f::from(nv);
        let n = if self.flip() { -n } else { n };
        let p_obj = self.render_from_object.apply_inverse_point(p);
        let uv = self.uv_of(p_obj, positive_atan2(p_obj.y, p_obj.x));
        if one_minus_cos_theta_max <= 0.0 {
            return None;
        }
        Some(ShapeSample {
            pi: Point3fi::from_value_and_error(p, p_error),
            n,
            uv,
            time: ctx.time,
            pdf: 1.0 / (2.0 * PI * one_minus_cos_theta_max),
        })
    }

    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        let center = self.render_from_object.apply_point(Point3f::default());
        let radius = match self.cone_radius {
            Some(r) if !self.ctx_inside(ctx, center, r) => r,
            _ => return pdf_by_intersection(self, ctx, wi),
        };
        let to_center = center - ctx.p();
        let d2 = to_center.length_squared();
        let sin2_theta_max = radius * radius / d2;
        // Unlike pbrt-v4, directions that miss the sphere have density
        // zero, so the density integrates to one over the sphere of
        // directions. Tested on the line's distance to the centre, with a
        // little slack for the rounding of sampled directions.
        let w = match wi.try_normalize() {
            Some(w) => w,
            None => return 0.0,
        };
        if dot(w, to_center) <= 0.0
            || cross(w, to_center).length_squared() > radius * radius * (1.0 + 1e-3)
        {
            return 0.0;
        }
        let cos_theta_max = safe_sqrt(1.0 - sin2_theta_max);
        let one_minus = if sin2_theta_max < SIN2_SMALL_ANGLE {
            sin2_theta_max / 2.0
        } else {
            1.0 - cos_theta_max
        };
        1.0 / (2.0 * PI * one_minus)
    }
}

/// sin²(1.5°): below it the cone is sampled through its Taylor expansion.
const SIN2_SMALL_ANGLE: Float = 0.000_685_23;

#[cfg(test)]
pub(super) mod testing {
    //! The harness every quadric's tests run (after pbrt-v4
    //! `shapes_test.cpp`): re-intersection, an independent
    //! double-precision solve, area by Crofton's formula, area sampling
    //! and solid-angle densities.

    use super::super::{ShapeMethods, ShapeSampleContext};
    use crate::rng::Rng;
    use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf};
    use rpbrt_geometry::float::*;
    use rpbrt_geometry::ray::Ray;
    use rpbrt_geometry::spherical::DirectionCone;
    use rpbrt_geometry::transform::Transform;
    use rpbrt_geometry::tuple::*;
    use rpbrt_geometry::Bounds3f;
    use rpbrt_geometry::Frame;

    /// A uniform float.
    pub fn uf(rng: &mut Rng) -> Float {
        rng.uniform_float()
    }

    /// A uniform 2-D sample.
    pub fn u2(rng: &mut Rng) -> Point2f {
        Point2f::new(rng.uniform_float(), rng.uniform_float())
    }

    /// A uniform direction.
    pub fn dir(rng: &mut Rng) -> Vector3f {
        sample_uniform_sphere(u2(rng))
    }

    /// A random rigid transformation: rotation about a random axis then a
    /// translation.
    pub fn rigid(rng: &mut Rng) -> Transform {
        let axis = dir(rng);
        let angle = 360.0 * uf(rng);
        let t = Vector3f::new(uf(rng) - 0.5, uf(rng) - 0.5, uf(rng) - 0.5) * 4.0;
        Transform::translate(t) * Transform::rotate(angle, axis)
    }

    /// A random point of the box.
    pub fn point_in(b: &Bounds3f, rng: &mut Rng) -> Point3f {
        b.lerp(Point3f::new(uf(rng), uf(rng), uf(rng)))
    }

    /// What rays leaving a hit point may do.
    #[derive(Clone, Copy)]
    pub enum Leaving {
        /// Never hit the shape again, whatever their direction.
        Never,
        /// Never hit it again when leaving on the side of `sign · n`
        /// (the outside of a convex solid).
        Outward(Float),
        /// May hit it again, but never close to where they left.
        FarOnly,
    }

    fn big_sphere(b: &Bounds3f) -> (Point3f, Float) {
        let (c, r) = b.bounding_sphere();
        (c, r.max(1e-3))
    }

    /// Rays from outside the bounds aimed into them: hits agree between
    /// `intersect` and `intersect_p`, lie on the ray, and rays spawned
    /// from them in random directions behave as `leaving` says.
    pub fn check_reintersect<S: ShapeMethods>(s: &S, rng: &mut Rng, n: usize, leaving: Leaving) {
        let b = s.bounds();
        let (c, r) = big_sphere(&b);
        let mut hits = 0;
        for _ in 0..n {
            let o = c + dir(rng) * (r * (1.5 + 3.0 * uf(rng)));
            let target = point_in(&b, rng);
            let ray = Ray::new(o, target - o);
            let hit = s.intersect(&ray, Float::INFINITY);
            assert_eq!(
                hit.is_some(),
                s.intersect_p(&ray, Float::INFINITY),
                "intersect vs intersect_p"
            );
            let Some(h) = hit else { continue };
            hits += 1;
            assert!(h.t_hit > 0.0 && h.t_hit.is_finite());
            let p = h.intr.p();
            assert!(
                p.distance(ray.at(h.t_hit)) < 1e-3 * r,
                "hit point off the ray"
            );
            assert!(b.expand(1e-3 * r).inside(p), "hit point outside the bounds");
            assert!(
                !s.intersect_p(&ray, h.t_hit * (1.0 - 1e-3)),
                "a hit before t_hit"
            );
            assert!((h.intr.n.length() - 1.0).abs() < 1e-3, "normal not unit");
            for _ in 0..20 {
                let w = dir(rng);
                let out = h.intr.spawn_ray(w);
                match leaving {
                    Leaving::Never => assert!(!s.intersect_p(&out, Float::INFINITY), "re-hit"),
                    Leaving::Outward(sign) => {
                        if dot(w, h.intr.n) * sign > 0.0 {
                            assert!(
                                !s.intersect_p(&out, Float::INFINITY),
                                "re-hit leaving outward"
                            );
                        }
                    }
                    Leaving::FarOnly => {}
                }
                if let Some(h2) = s.intersect(&out, Float::INFINITY) {
                    assert!(h2.intr.p().distance(p) > 1e-4 * r, "self-intersection");
                }
            }
        }
        assert!(
            hits > n / 50,
            "too few hits ({hits} of {n}) for the test to mean much"
        );
    }

    /// The hit of `ray` found independently in double precision: `f` is
    /// the object-space implicit function (quadratic along a line, so
    /// three samples give its coefficients), `on` the clipping test.
    pub fn reference_hit(
        render_from_object: &Transform,
        ray: &Ray,
        f: &dyn Fn([f64; 3]) -> f64,
        on: &dyn Fn([f64; 3]) -> bool,
    ) -> Option<f64> {
        let mi = render_from_object.inverse_matrix().m;
        let ap = |p: [f64; 3], w: f64| -> [f64; 3] {
            let mut r = [0.0; 3];
            for (i, ri) in r.iter_mut().enumerate() {
                *ri = mi[i][0] as f64 * p[0]
                    + mi[i][1] as f64 * p[1]
                    + mi[i][2] as f64 * p[2]
                    + w * mi[i][3] as f64;
            }
            r
        };
        let o = ap([ray.o.x as f64, ray.o.y as f64, ray.o.z as f64], 1.0);
        let d = ap([ray.d.x as f64, ray.d.y as f64, ray.d.z as f64], 0.0);
        let at = |t: f64| [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        let (f0, f1, fm) = (f(at(0.0)), f(at(1.0)), f(at(-1.0)));
        let (a, b, c) = ((f1 + fm) / 2.0 - f0, (f1 - fm) / 2.0, f0);
        let mut roots = Vec::new();
        if a.abs() < 1e-12 * (b.abs() + c.abs()) {
            if b != 0.0 {
                roots.push(-c / b);
            }
        } else {
            let disc = b * b - 4.0 * a * c;
            if disc >= 0.0 {
                let q = -0.5 * (b + b.signum() * disc.sqrt());
                roots.push(q / a);
                if q != 0.0 {
                    roots.push(c / q);
                }
            }
        }
        roots.sort_by(|x, y| x.total_cmp(y));
        roots.into_iter().find(|&t| t > 0.0 && on(at(t)))
    }

    /// Compares hits with [`reference_hit`]; disagreements are tolerated
    /// only for the few rays grazing a clipping boundary.
    pub fn check_reference<S: ShapeMethods>(
        s: &S,
        render_from_object: &Transform,
        rng: &mut Rng,
        n: usize,
        f: &dyn Fn([f64; 3]) -> f64,
        on: &dyn Fn([f64; 3]) -> bool,
    ) {
        let b = s.bounds();
        let (c, r) = big_sphere(&b);
        let (mut disagree, mut hits) = (0, 0);
        for _ in 0..n {
            let o = c + dir(rng) * (r * (1.2 + 2.0 * uf(rng)));
            let ray = Ray::new(o, point_in(&b, rng) - o);
            let got = s.intersect(&ray, Float::INFINITY).map(|h| h.t_hit as f64);
            let want = reference_hit(render_from_object, &ray, f, on);
            match (got, want) {
                (Some(g), Some(w)) => {
                    hits += 1;
                    if (g - w).abs() > 1e-3 * w.abs().max(1.0) {
                        disagree += 1;
                    }
                }
                (None, None) => {}
                _ => disagree += 1,
            }
        }
        assert!(hits > n / 50, "too few hits: {hits}");
        assert!(
            disagree * 250 <= n,
            "{disagree} of {n} rays disagree with the reference"
        );
    }

    /// The area of the surface by Crofton's formula: a uniformly random
    /// line through a sphere of radius R crosses a surface of area A
    /// A / (2πR²) times on average. Needs a rigid `render_from_object`.
    pub fn crofton_area<S: ShapeMethods>(s: &S, rng: &mut Rng, n: usize) -> f64 {
        let (c, r) = big_sphere(&s.bounds());
        let mut crossings = 0u64;
        for _ in 0..n {
            let w = dir(rng);
            let (e1, e2) = w.coordinate_system();
            let d = crate::sampling::sample_uniform_disk_polar(u2(rng));
            let o = c + e1 * (d.x * r) + e2 * (d.y * r) - w * (2.0 * r);
            let ray = Ray::new(o, w);
            if let Some(h) = s.intersect(&ray, 4.0 * r) {
                crossings += 1;
                if s.intersect(&h.intr.spawn_ray(w), Float::INFINITY).is_some() {
                    crossings += 1;
                }
            }
        }
        2.0 * std::f64::consts::PI * (r as f64).powi(2) * crossings as f64 / n as f64
    }

    /// Area sampling: density 1/area, points on the surface (a ray aimed
    /// at each finds it), normals and (u, v) agreeing with intersections,
    /// and the area matching Crofton's estimate.
    pub fn check_area_sampling<S: ShapeMethods>(s: &S, rng: &mut Rng, n: usize) {
        let area = s.area() as f64;
        let est = crofton_area(s, rng, 20 * n);
        assert!(
            (est - area).abs() < 0.03 * area,
            "area {area} vs Crofton estimate {est}"
        );
        let (_, r) = big_sphere(&s.bounds());
        let mut inv_pdf = 0.0f64;
        for _ in 0..n {
            let Some(ss) = s.sample_area(u2(rng)) else {
                continue;
            };
            inv_pdf += 1.0 / ss.pdf as f64;
            assert!((ss.pdf - s.pdf_area()).abs() <= 1e-5 * ss.pdf);
            let p = ss.p();
            let nv = Vector3f::from(ss.n);
            let o = p + nv * (1e-2 * r);
            let Some(h) = s.intersect(&Ray::new(o, -nv), Float::INFINITY) else {
                panic!("no hit aimed at sampled point {p:?}");
            };
            assert!(
                h.intr.p().distance(p) < 2e-3 * r,
                "sampled point off the surface: {p:?} vs {:?}",
                h.intr.p()
            );
            assert!(
                dot(h.intr.n, ss.n) > 0.99,
                "sampled normal {:?} vs hit normal {:?}",
                ss.n,
                h.intr.n
            );
            let du = (h.intr.uv.x - ss.uv.x).abs();
            assert!(
                du.min(1.0 - du) < 1e-2 && (h.intr.uv.y - ss.uv.y).abs() < 1e-2,
                "uv {:?} vs {:?}",
                ss.uv,
                h.intr.uv
            );
        }
        let mean = inv_pdf / n as f64;
        assert!(
            (mean - area).abs() < 1e-3 * area,
            "E[1/pdf] = {mean}, area {area}"
        );
    }

    /// Solid-angle sampling from `p`, where every direction meets the
    /// surface at most once: the density integrates to one over the sphere
    /// of directions, samples carry the density `pdf` reports, and
    /// E[1/pdf] over samples is the subtended solid angle.
    pub fn check_solid_angle<S: ShapeMethods>(s: &S, p: Point3f, rng: &mut Rng, n: usize) {
        let ctx = ShapeSampleContext::from_point(p, 0.0);
        // Directions are drawn uniformly in the cone bounding the shape (or
        // over the whole sphere from inside its bounds) so that small
        // shapes get enough of them.
        let cone = DirectionCone::bound_subtended_directions(&s.bounds(), p);
        let cos_max = if cone.cos_theta > -1.0 + 1e-3 {
            cone.cos_theta
        } else {
            -1.0
        };
        let frame = Frame::from_z(cone.w);
        let dir_pdf = uniform_cone_pdf(cos_max) as f64;
        let (mut integral, mut omega) = (0.0f64, 0.0f64);
        let m = 10 * n;
        for _ in 0..m {
            let w = frame.from_local(sample_uniform_cone(u2(rng), cos_max));
            integral += s.pdf(&ctx, w) as f64 / dir_pdf;
            if s.intersect_p(&ctx.spawn_ray(w), Float::INFINITY) {
                omega += 1.0 / dir_pdf;
            }
        }
        let integral = integral / m as f64;
        assert!((integral - 1.0).abs() < 0.03, "∫ pdf dω = {integral}");
        let omega = omega / m as f64;
        let mut inv = 0.0f64;
        let mut count = 0;
        for _ in 0..n {
            let Some(ss) = s.sample(&ctx, u2(rng)) else {
                continue;
            };
            count += 1;
            inv += 1.0 / ss.pdf as f64;
            let wi = (ss.p() - p).normalize();
            let pdf = s.pdf(&ctx, wi);
            assert!(
                (pdf - ss.pdf).abs() <= 2e-2 * ss.pdf,
                "sample pdf {} vs pdf() {}",
                ss.pdf,
                pdf
            );
        }
        assert!(count * 100 >= n * 99, "too many failed samples");
        let est = inv / n as f64;
        assert!(
            (est - omega).abs() < 0.03 * omega,
            "E[1/pdf] {est} vs solid angle {omega}"
        );
    }
}

#[cfg(test)]
mod tests;
