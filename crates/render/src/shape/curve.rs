//! Curves (pbrt-v4 section 6.7; pbrt-v4 `shapes.h` `Curve`, `CurveCommon`,
//! `shapes.cpp` `Curve::Create`): thin cubic Bézier curves with a width
//! that varies linearly along them, for hair, fur and grass.
//!
//! A curve is intersected in a coordinate system where the ray runs down
//! +z from the origin: the curve is split recursively (to a depth chosen
//! from the control polygon's flatness) until each piece is nearly a line
//! segment, which is then tested against the ray's (x, y) = (0, 0).
//!
//! Three kinds exist. `Flat` curves always face the ray; `Cylinder` curves
//! are the same flat surface with a shading normal rotated across the width
//! so they shade like tubes; `Ribbon` curves are oriented by normals given
//! at the two ends and interpolated spherically in between.
//!
//! pbrt-v4 does not sample curves (its `Curve::Sample` aborts). Here they
//! are area-sampled so they can be area lights: see [`Curve::sample_area`].

use std::sync::Arc;

use super::{
    area_sample_to_solid_angle, ShapeError, ShapeIntersection, ShapeMethods, ShapeSample,
    ShapeSampleContext,
};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

/// How a curve's surface is oriented.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveType {
    /// A flat strip that always faces the incoming ray.
    Flat,
    /// A flat strip facing the ray, shaded as if it were a tube.
    Cylinder,
    /// A strip oriented by the normals given at its ends.
    Ribbon,
}

impl CurveType {
    /// The type named by a scene file's `"type"` parameter.
    pub fn from_name(name: &str) -> Option<CurveType> {
        match name {
            "flat" => Some(CurveType::Flat),
            "cylinder" => Some(CurveType::Cylinder),
            "ribbon" => Some(CurveType::Ribbon),
            _ => None,
        }
    }
}

/// What all the pieces split from one cubic Bézier segment share.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveCommon {
    /// The kind of curve.
    pub curve_type: CurveType,
    /// Cubic Bézier control points in object space.
    pub cp_obj: [Point3f; 4],
    /// Widths at u = 0 and u = 1 (object space).
    pub width: [Float; 2],
    /// Unit normals at the two ends (ribbons only; zero otherwise).
    pub n: [Normal3f; 2],
    /// Angle between `n[0]` and `n[1]`.
    pub normal_angle: Float,
    /// 1 / sin(`normal_angle`), for spherical interpolation of the normal.
    pub inv_sin_normal_angle: Float,
    /// Rendering-from-object transformation.
    pub render_from_object: Transform,
    /// Object-from-rendering transformation.
    pub object_from_render: Transform,
    /// Whether the surface normal is flipped.
    pub reverse_orientation: bool,
    /// Whether `render_from_object` changes handedness.
    pub transform_swaps_handedness: bool,
}

impl CurveCommon {
    /// Shared data for one cubic segment. `n` (ribbons) is normalized here;
    /// zero normals are the caller's responsibility ([`create_curves`]
    /// rejects them).
    pub fn new(
        cp_obj: [Point3f; 4],
        width0: Float,
        width1: Float,
        curve_type: CurveType,
        n: Option<[Normal3f; 2]>,
        render_from_object: &Transform,
        reverse_orientation: bool,
    ) -> Self {
        let (n, normal_angle, inv_sin_normal_angle) = match n {
            Some([a, b]) => {
                let a = a.try_normalize().unwrap_or_default();
                let b = b.try_normalize().unwrap_or_default();
                let angle = a.angle_between(b);
                ([a, b], angle, 1.0 / angle.sin())
            }
            None => ([Normal3f::default(); 2], 0.0, 0.0),
        };
        CurveCommon {
            curve_type,
            cp_obj,
            width: [width0, width1],
            n,
            normal_angle,
            inv_sin_normal_angle,
            render_from_object: *render_from_object,
            object_from_render: render_from_object.inverse(),
            reverse_orientation,
            transform_swaps_handedness: render_from_object.swaps_handedness(),
        }
    }

    /// The width at curve parameter `u`.
    #[inline]
    pub fn width_at(&self, u: Float) -> Float {
        lerp(u, self.width[0], self.width[1])
    }

    /// The ribbon normal at `u` (spherical interpolation of the end
    /// normals) and its derivative with respect to `u`.
    pub fn ribbon_normal(&self, u: Float) -> (Normal3f, Normal3f) {
        let theta = self.normal_angle;
        let s = theta.sin();
        if theta == 0.0 {
            return (self.n[0], Normal3f::default());
        }
        if s.abs() < 1e-4 || !self.inv_sin_normal_angle.is_finite() {
            // (Anti)parallel ends: spherical interpolation is undefined, so
            // fall back to normalized linear interpolation.
            let l = self.n[0] * (1.0 - u) + self.n[1] * u;
            let n = l.try_normalize().unwrap_or(self.n[0]);
            return (n, self.n[1] - self.n[0]);
        }
        let inv = self.inv_sin_normal_angle;
        let w0 = ((1.0 - u) * theta).sin() * inv;
        let w1 = (u * theta).sin() * inv;
        let d0 = -theta * ((1.0 - u) * theta).cos() * inv;
        let d1 = theta * (u * theta).cos() * inv;
        (
            self.n[0] * w0 + self.n[1] * w1,
            self.n[0] * d0 + self.n[1] * d1,
        )
    }

    /// Whether to negate `dpdu × dpdv` for the geometric normal.
    ///
    /// Ribbons follow pbrt-v4: reverse orientation XOR a handedness swap.
    /// For flat and cylinder curves `dpdu × dpdv` always points along the
    /// ray (away from its origin), so it is negated once more: their normal
    /// faces the viewer unless the orientation is reversed, which lets them
    /// be one-sided area lights. (pbrt-v4 does not negate it; it has no
    /// curve lights.)
    #[inline]
    fn flip_normal(&self) -> bool {
        let base = self.reverse_orientation ^ self.transform_swaps_handedness;
        match self.curve_type {
            CurveType::Ribbon => base,
            CurveType::Flat | CurveType::Cylinder => !base,
        }
    }
}

/// One piece of a cubic Bézier curve: the part with u in [`u_min`, `u_max`].
///
/// [`u_min`]: Curve::u_min
/// [`u_max`]: Curve::u_max
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The segment this piece belongs to.
    pub common: Arc<CurveCommon>,
    /// Start of the piece's parameter range.
    pub u_min: Float,
    /// End of the piece's parameter range.
    pub u_max: Float,
}

/// The part of the (object-space) surface used for sampling at one (u, v):
/// the point and its partial derivatives.
struct SurfacePoint {
    p: Point3f,
    dpdu: Vector3f,
    dpdv: Vector3f,
}

impl Curve {
    /// The piece of `common` with u in [`u_min`, `u_max`].
    pub fn new(common: Arc<CurveCommon>, u_min: Float, u_max: Float) -> Self {
        Curve {
            common,
            u_min,
            u_max,
        }
    }

    /// The object-space control points of this piece.
    fn piece_control_points(&self) -> [Point3f; 4] {
        cubic_bezier_control_points(&self.common.cp_obj, self.u_min, self.u_max)
    }

    /// Shared body of `intersect` and `intersect_p`: `si` is `None` for
    /// shadow rays, which stop at the first hit.
    fn intersect_ray(
        &self,
        r: &Ray,
        t_max: Float,
        mut si: Option<&mut Option<ShapeIntersection>>,
    ) -> bool {
        let c = &*self.common;
        // The ray in object space; the origin is not nudged (unlike
        // `Transform::apply_ray`) so that t is the same in both spaces.
        let ray = Ray::with_time(
            c.object_from_render.apply_point(r.o),
            c.object_from_render.apply_vector(r.d),
            r.time,
            r.medium,
        );
        if ray.d.length_squared() == 0.0 || ray.has_nan() || t_max.is_nan() || t_max <= 0.0 {
            return false;
        }
        let cp_obj = self.piece_control_points();

        // Orient the ray frame so the chord of the curve lies along x: the
        // curve's bounds are then thin in y and most rays are culled early.
        let ray_from_object = match ray_frame(&ray, cp_obj[3] - cp_obj[0]) {
            Some(t) => t,
            None => return false,
        };
        let cp = cp_obj.map(|p| ray_from_object.apply_point(p));

        let max_width = c.width_at(self.u_min).max(c.width_at(self.u_max));
        let ray_length = ray.d.length();
        let z_max = ray_length * t_max;
        if !overlaps_ray(&cp, max_width, z_max) {
            return false;
        }

        // Refinement depth from the control polygon's flatness (second
        // differences), so that the final pieces are within about width/20
        // of straight lines.
        let mut l0: Float = 0.0;
        for i in 0..2 {
            let d =
                Vector3f::from(cp[i]) - Vector3f::from(cp[i + 1]) * 2.0 + Vector3f::from(cp[i + 2]);
            l0 = l0.max(d.x.abs()).max(d.y.abs()).max(d.z.abs());
        }
        let mut max_depth = 0;
        if l0 > 0.0 {
            let eps = c.width[0].max(c.width[1]) * 0.05;
            let r0 = log2_int(SQRT2 * 6.0 * l0 / (8.0 * eps)) / 2;
            max_depth = r0.clamp(0, 10);
        }

        let ctx = RecursionContext {
            curve: self,
            ray: &ray,
            ray_length,
            t_max,
            ray_from_object: &ray_from_object,
        };
        ctx.recurse(&cp, self.u_min, self.u_max, max_depth, &mut si)
    }

    /// The surface sampled by [`ShapeMethods::sample_area`] at global curve
    /// parameter `u` and across-width parameter `v`, in object space.
    ///
    /// Ribbons use their own surface. Flat and cylinder curves have no
    /// fixed surface (they turn to face each ray), so they are sampled as
    /// the strip facing `toward` (the reference point, in object space) or,
    /// without one, as a strip of fixed orientation perpendicular to the
    /// segment's chord.
    fn sampling_surface(
        &self,
        u: Float,
        v: Float,
        toward: Option<Point3f>,
    ) -> Option<SurfacePoint> {
        let c = &*self.common;
        let (pc, d1) = evaluate_cubic_bezier(&c.cp_obj, u);
        let d2 = cubic_bezier_second_derivative(&c.cp_obj, u);
        if d1.length_squared() == 0.0 {
            return None;
        }
        // x is the unnormalized width direction, dx its u-derivative.
        let (x, dx) = match c.curve_type {
            CurveType::Ribbon => {
                let (n, dn) = c.ribbon_normal(u);
                (cross(n, d1), cross(dn, d1) + cross(n, d2))
            }
            CurveType::Flat | CurveType::Cylinder => {
                let (f, df) = match toward {
                    Some(q) => {
                        let to = q - pc;
                        let dist = to.length();
                        if dist == 0.0 {
                            return None;
                        }
                        let f = to / dist;
                        (f, -(d1 - f * dot(f, d1)) / dist)
                    }
                    None => (fixed_facing(&c.cp_obj), Vector3f::default()),
                };
                (cross(d1, f), cross(d2, f) + cross(d1, df))
            }
        };
        let len = x.length();
        if len.is_nan() || len <= 0.0 {
            return None;
        }
        let b = x / len;
        let db = (dx - b * dot(b, dx)) / len;
        let s = v - 0.5;
        let w = c.width_at(u);
        let dw = c.width[1] - c.width[0];
        Some(SurfacePoint {
            p: pc + b * (s * w),
            dpdu: d1 + (b * dw + db * w) * s,
            dpdv: b * w,
        })
    }

    /// A sample at (`u`, `v`) on the sampling surface with its density per
    /// unit area in rendering space.
    fn sample_at(&self, u: Float, v: Float, toward: Option<Point3f>) -> Option<ShapeSample> {
        let c = &*self.common;
        let sp = self.sampling_surface(u, v, toward)?;
        let t = &c.render_from_object;
        let dpdu = t.apply_vector(sp.dpdu);
        let dpdv = t.apply_vector(sp.dpdv);
        let nv = cross(dpdu, dpdv);
        let jac = nv.length();
        let du = self.u_max - self.u_min;
        if jac.is_nan() || jac <= 0.0 || du.is_nan() || du <= 0.0 {
            return None;
        }
        let mut n = Normal3f::from(nv / jac);
        if c.flip_normal() {
            n = -n;
        }
        let pdf = 1.0 / (du * jac);
        if !pdf.is_finite() {
            return None;
        }
        Some(ShapeSample {
            pi: Point3fi::from(t.apply_point(sp.p)),
            n,
            uv: Point2f::new(u, v),
            time: 0.0,
            pdf,
        })
    }
}

/// What stays fixed through the recursive intersection of one ray.
struct RecursionContext<'a> {
    curve: &'a Curve,
    ray: &'a Ray,
    ray_length: Float,
    t_max: Float,
    ray_from_object: &'a Transform,
}

impl RecursionContext<'_> {
    /// Tests the piece with ray-space control points `cp` covering
    /// [`u0`, `u1`]; splits it `depth` more times before the line test.
    fn recurse(
        &self,
        cp: &[Point3f; 4],
        u0: Float,
        u1: Float,
        depth: i32,
        si: &mut Option<&mut Option<ShapeIntersection>>,
    ) -> bool {
        let c = &*self.curve.common;
        if depth > 0 {
            let split = subdivide_cubic_bezier(cp);
            let u = [u0, (u0 + u1) * 0.5, u1];
            let mut any = false;
            for seg in 0..2 {
                let cps = [
                    split[3 * seg],
                    split[3 * seg + 1],
                    split[3 * seg + 2],
                    split[3 * seg + 3],
                ];
                let max_width = c.width_at(u[seg]).max(c.width_at(u[seg + 1]));
                // Closer hits found so far shrink the z range to search.
                let t_limit = match si.as_deref() {
                    Some(Some(h)) => h.t_hit,
                    _ => self.t_max,
                };
                if !overlaps_ray(&cps, max_width, self.ray_length * t_limit) {
                    continue;
                }
                let hit = self.recurse(&cps, u[seg], u[seg + 1], depth - 1, si);
                if hit && si.is_none() {
                    return true;
                }
                any |= hit;
            }
            return match si.as_deref() {
                Some(found) => found.is_some(),
                None => any,
            };
        }

        // The ray's point (0, 0) must lie between the lines through the
        // piece's ends perpendicular to its end tangents (so neighbouring
        // pieces do not both report the hit).
        let edge = (cp[1].y - cp[0].y) * -cp[0].y + cp[0].x * (cp[0].x - cp[1].x);
        if edge < 0.0 {
            return false;
        }
        let edge = (cp[2].y - cp[3].y) * -cp[3].y + cp[3].x * (cp[3].x - cp[2].x);
        if edge < 0.0 {
            return false;
        }

        // Treat the piece as the line from cp[0] to cp[3]; w is the line
        // parameter closest to (0, 0).
        let seg_dir = Vector2f::new(cp[3].x - cp[0].x, cp[3].y - cp[0].y);
        let denom = seg_dir.length_squared();
        if denom == 0.0 {
            return false;
        }
        let w = dot(Vector2f::new(-cp[0].x, -cp[0].y), seg_dir) / denom;
        let u = clamp(lerp(w, u0, u1), u0, u1);
        let mut hit_width = c.width_at(u);
        let mut n_hit = Normal3f::default();
        if c.curve_type == CurveType::Ribbon {
            // A ribbon seen edge-on is narrower by |cos| of its normal to
            // the ray.
            n_hit = c.ribbon_normal(u).0;
            hit_width *= abs_dot(n_hit, self.ray.d) / self.ray_length;
        }

        let (pc, dpcdw) = evaluate_cubic_bezier(cp, clamp(w, 0.0, 1.0));
        let pt_curve_dist2 = pc.x * pc.x + pc.y * pc.y;
        if pt_curve_dist2 > hit_width * hit_width * 0.25 {
            return false;
        }
        let z_max = self.ray_length * self.t_max;
        if pc.z < 0.0 || pc.z > z_max {
            return false;
        }

        let out = match si {
            Some(out) => out,
            None => return true,
        };
        let t_hit = pc.z / self.ray_length;
        if let Some(prev) = out.as_ref() {
            if t_hit > prev.t_hit {
                return false;
            }
        }
        // v runs across the width; which side of the centreline the hit is
        // on comes from the sign of the 2-D cross product with the tangent.
        let pt_curve_dist = pt_curve_dist2.sqrt();
        let edge_func = dpcdw.x * -pc.y + pc.x * dpcdw.y;
        let v = if edge_func > 0.0 {
            0.5 + pt_curve_dist / hit_width
        } else {
            0.5 - pt_curve_dist / hit_width
        };

        let (_, mut dpdu) = evaluate_cubic_bezier(&c.cp_obj, u);
        if dpdu.length_squared() == 0.0 {
            // Degenerate tangent (coincident control points): use the
            // piece's chord, mapped back to object space.
            dpdu = self
                .ray_from_object
                .apply_inverse_vector(Vector3f::new(seg_dir.x, seg_dir.y, 0.0));
            if dpdu.length_squared() == 0.0 {
                return false;
            }
        }
        let dpdv = if c.curve_type == CurveType::Ribbon {
            match cross(n_hit, dpdu).try_normalize() {
                Some(d) => d * hit_width,
                None => return false,
            }
        } else {
            let dpdu_plane = self.ray_from_object.apply_vector(dpdu);
            let mut dpdv_plane =
                match Vector3f::new(-dpdu_plane.y, dpdu_plane.x, 0.0).try_normalize() {
                    Some(d) => d * hit_width,
                    None => return false,
                };
            if c.curve_type == CurveType::Cylinder {
                // Rotating dpdv about the tangent from -90 to 90 degrees
                // across the width makes the normal sweep like a tube's.
                let theta = lerp(v, -90.0, 90.0);
                dpdv_plane = Transform::rotate(-theta, dpdu_plane).apply_vector(dpdv_plane);
            }
            self.ray_from_object.apply_inverse_vector(dpdv_plane)
        };

        let p_error = Vector3f::new(hit_width, hit_width, hit_width) * 2.0;
        let pi = Point3fi::from_value_and_error(self.ray.at(t_hit), p_error);
        let intr = SurfaceInteraction::new(
            pi,
            Point2f::new(u, v),
            -self.ray.d,
            dpdu,
            dpdv,
            Normal3f::default(),
            Normal3f::default(),
            self.ray.time,
            c.flip_normal(),
        )
        .transform(&c.render_from_object);
        **out = Some(ShapeIntersection { intr, t_hit });
        true
    }
}

/// The object-to-ray-space transformation: the ray starts at the origin
/// and runs down +z, and `up` (the curve chord crossed with the ray) is +y,
/// so the chord lies along x.
fn ray_frame(ray: &Ray, chord: Vector3f) -> Option<Transform> {
    let target = ray.o + ray.d;
    let dx = cross(ray.d, chord);
    if dx.length_squared() > 0.0 {
        if let Ok(t) = Transform::look_at(ray.o, target, dx) {
            return Some(t);
        }
    }
    // The chord is parallel to the ray (or degenerate): any orientation of
    // the xy plane will do.
    let d = ray.d.try_normalize()?;
    let (up, _) = d.coordinate_system();
    Transform::look_at(ray.o, target, up).ok()
}

/// Whether the box around `cp` grown by half of `max_width` overlaps the
/// ray's segment from z = 0 to `z_max` along the z axis (y first: it is
/// usually the thinnest extent).
fn overlaps_ray(cp: &[Point3f; 4], max_width: Float, z_max: Float) -> bool {
    let hw = 0.5 * max_width;
    let (mut lo, mut hi) = (cp[0], cp[0]);
    for p in &cp[1..] {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    !(hi.y + hw < 0.0
        || lo.y - hw > 0.0
        || hi.x + hw < 0.0
        || lo.x - hw > 0.0
        || hi.z + hw < 0.0
        || lo.z - hw > z_max)
}

/// A fixed unit direction perpendicular to the chord of `cp` (used as the
/// facing direction when sampling flat curves without a reference point).
fn fixed_facing(cp: &[Point3f; 4]) -> Vector3f {
    let chord = [cp[3] - cp[0], cp[2] - cp[1], cp[1] - cp[0]]
        .into_iter()
        .find_map(|v| v.try_normalize())
        .unwrap_or(Vector3f::new(0.0, 0.0, 1.0));
    chord.coordinate_system().0
}

/// Rounded base-2 logarithm of a positive value, as pbrt-v4's `Log2Int`
/// for floats (rounding in log space); large for infinite input.
fn log2_int(v: Float) -> i32 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if !v.is_finite() {
        return 1 << 20;
    }
    (v.log2() + 0.5).floor() as i32
}

// ---- Bézier and B-spline helpers (pbrt-v4 `util/math.h`) ----

/// The blossom p(u0, u1, u2) of a cubic Bézier: de Casteljau with a
/// different parameter at each level.
fn blossom_cubic_bezier(p: &[Point3f; 4], u0: Float, u1: Float, u2: Float) -> Point3f {
    let a = [
        Point3f::lerp(u0, p[0], p[1]),
        Point3f::lerp(u0, p[1], p[2]),
        Point3f::lerp(u0, p[2], p[3]),
    ];
    let b = [Point3f::lerp(u1, a[0], a[1]), Point3f::lerp(u1, a[1], a[2])];
    Point3f::lerp(u2, b[0], b[1])
}

/// Control points of the part of a cubic Bézier with u in [u_min, u_max].
fn cubic_bezier_control_points(p: &[Point3f; 4], u_min: Float, u_max: Float) -> [Point3f; 4] {
    if u_min == 0.0 && u_max == 1.0 {
        return *p;
    }
    [
        blossom_cubic_bezier(p, u_min, u_min, u_min),
        blossom_cubic_bezier(p, u_min, u_min, u_max),
        blossom_cubic_bezier(p, u_min, u_max, u_max),
        blossom_cubic_bezier(p, u_max, u_max, u_max),
    ]
}

/// Splits a cubic Bézier at u = 1/2; points 0..=3 and 3..=6 are the halves.
fn subdivide_cubic_bezier(cp: &[Point3f; 4]) -> [Point3f; 7] {
    let m = |a: Point3f, b: Point3f| Point3f::lerp(0.5, a, b);
    let p01 = m(cp[0], cp[1]);
    let p12 = m(cp[1], cp[2]);
    let p23 = m(cp[2], cp[3]);
    let p012 = m(p01, p12);
    let p123 = m(p12, p23);
    let mid = m(p012, p123);
    [cp[0], p01, p012, mid, p123, p23, cp[3]]
}

/// The point at `u` and the derivative there. Where the derivative
/// vanishes (coincident end control points) the chord direction stands in.
fn evaluate_cubic_bezier(cp: &[Point3f; 4], u: Float) -> (Point3f, Vector3f) {
    let a = [
        Point3f::lerp(u, cp[0], cp[1]),
        Point3f::lerp(u, cp[1], cp[2]),
        Point3f::lerp(u, cp[2], cp[3]),
    ];
    let b = [Point3f::lerp(u, a[0], a[1]), Point3f::lerp(u, a[1], a[2])];
    let mut deriv = (b[1] - b[0]) * 3.0;
    if deriv.length_squared() == 0.0 {
        deriv = cp[3] - cp[0];
    }
    (Point3f::lerp(u, b[0], b[1]), deriv)
}

/// The second derivative of a cubic Bézier at `u`.
fn cubic_bezier_second_derivative(cp: &[Point3f; 4], u: Float) -> Vector3f {
    let v = |p: Point3f| Vector3f::from(p);
    let d0 = v(cp[2]) - v(cp[1]) * 2.0 + v(cp[0]);
    let d1 = v(cp[3]) - v(cp[2]) * 2.0 + v(cp[1]);
    (d0 * (1.0 - u) + d1 * u) * 6.0
}

/// The cubic Bézier tracing the same curve as a quadratic one.
fn elevate_quadratic_bezier_to_cubic(cp: &[Point3f; 3]) -> [Point3f; 4] {
    [
        cp[0],
        Point3f::lerp(2.0 / 3.0, cp[0], cp[1]),
        Point3f::lerp(1.0 / 3.0, cp[1], cp[2]),
        cp[2],
    ]
}

/// The quadratic Bézier equal to one uniform quadratic B-spline segment.
fn quadratic_bspline_to_bezier(cp: &[Point3f; 3]) -> [Point3f; 3] {
    [
        Point3f::lerp(0.5, cp[0], cp[1]),
        cp[1],
        Point3f::lerp(0.5, cp[1], cp[2]),
    ]
}

/// The cubic Bézier equal to one uniform cubic B-spline segment.
fn cubic_bspline_to_bezier(cp: &[Point3f; 4]) -> [Point3f; 4] {
    // Blossom labels: the B-spline points are p(0,1,2) .. p(3,4,5); the
    // Bézier points are p(2,2,2), p(2,2,3), p(2,3,3), p(3,3,3).
    let p122 = Point3f::lerp(2.0 / 3.0, cp[0], cp[1]);
    let p223 = Point3f::lerp(1.0 / 3.0, cp[1], cp[2]);
    let p233 = Point3f::lerp(2.0 / 3.0, cp[1], cp[2]);
    let p334 = Point3f::lerp(1.0 / 3.0, cp[2], cp[3]);
    [
        Point3f::lerp(0.5, p122, p223),
        p223,
        p233,
        Point3f::lerp(0.5, p233, p334),
    ]
}

/// The largest split depth accepted; deeper splits only cost memory.
const MAX_SPLIT_DEPTH: i32 = 12;

/// Builds the curve pieces of a `"curve"` shape as pbrt-v4's
/// `Curve::Create` does: checks the control-point count for the basis and
/// degree, converts every segment to a cubic Bézier (B-spline segments to
/// Bézier form, quadratics elevated), interpolates the widths over the
/// segments, hands each ribbon segment its two end normals and splits each
/// segment into 2^`split_depth` pieces. Returns the pieces and warnings.
#[allow(clippy::too_many_arguments)]
pub fn create_curves(
    render_from_object: &Transform,
    reverse_orientation: bool,
    p: &[Point3f],
    basis: &str,
    degree: i32,
    ty: &str,
    n: &[Normal3f],
    width0: Float,
    width1: Float,
    split_depth: i32,
) -> Result<(Vec<Curve>, Vec<String>), ShapeError> {
    let err = |m: String| Err(ShapeError(m));
    let mut warnings = Vec::new();
    if degree != 2 && degree != 3 {
        return err(format!(
            "curve: invalid degree {degree}: only degree 2 and 3 curves are supported"
        ));
    }
    let deg = degree as usize;
    if basis != "bezier" && basis != "bspline" {
        return err(format!(
            "curve: invalid basis \"{basis}\": only \"bezier\" and \"bspline\" are supported"
        ));
    }
    let curve_type = match CurveType::from_name(ty) {
        Some(t) => t,
        None => {
            return err(format!(
                "curve: unknown type \"{ty}\": expected \"flat\", \"cylinder\" or \"ribbon\""
            ))
        }
    };
    if !(width0.is_finite() && width1.is_finite()) || width0 < 0.0 || width1 < 0.0 {
        return err(format!(
            "curve: widths must be finite and non-negative (width0 {width0}, width1 {width1})"
        ));
    }
    if let Some(i) = p.iter().position(|q| !q.is_finite()) {
        return err(format!(
            "curve: control point {i} is not finite ({:?})",
            p[i]
        ));
    }
    let n_segments = if basis == "bezier" {
        if p.len() < deg + 1 || !(p.len() - 1 - deg).is_multiple_of(deg) {
            return err(format!(
                "curve: invalid number of control points {}: the degree {degree} Bezier basis \
                 needs {} + k * {degree} of them, for k >= 0",
                p.len(),
                deg + 1
            ));
        }
        (p.len() - 1) / deg
    } else {
        if p.len() < deg + 1 {
            return err(format!(
                "curve: invalid number of control points {}: the degree {degree} b-spline \
                 basis needs at least {}",
                p.len(),
                deg + 1
            ));
        }
        p.len() - deg
    };

    let mut normals: &[Normal3f] = n;
    if curve_type == CurveType::Ribbon {
        if n.is_empty() {
            return err("curve: ribbon curves need normals \"N\" at the segment ends".into());
        }
        if n.len() != n_segments + 1 {
            return err(format!(
                "curve: invalid number of normals {}: ribbon curves with {n_segments} \
                 segments need {}",
                n.len(),
                n_segments + 1
            ));
        }
        if let Some(i) = n
            .iter()
            .position(|v| !v.is_finite() || v.length_squared() == 0.0)
        {
            return err(format!(
                "curve: normal {i} is zero or not finite ({:?})",
                n[i]
            ));
        }
    } else if !n.is_empty() {
        warnings.push("curve: normals \"N\" are only used with \"ribbon\" curves; ignored".into());
        normals = &[];
    }

    let sd = if split_depth < 0 {
        return err(format!("curve: split depth {split_depth} is negative"));
    } else if split_depth > MAX_SPLIT_DEPTH {
        warnings.push(format!(
            "curve: split depth {split_depth} is too large; using {MAX_SPLIT_DEPTH}"
        ));
        MAX_SPLIT_DEPTH
    } else {
        split_depth
    };
    let pieces = 1usize << sd;

    let mut curves = Vec::with_capacity(n_segments * pieces);
    let mut offset = 0;
    for seg in 0..n_segments {
        let bezier = if basis == "bezier" {
            let b = if deg == 2 {
                elevate_quadratic_bezier_to_cubic(&[p[offset], p[offset + 1], p[offset + 2]])
            } else {
                [p[offset], p[offset + 1], p[offset + 2], p[offset + 3]]
            };
            offset += deg;
            b
        } else {
            let b = if deg == 2 {
                let q = quadratic_bspline_to_bezier(&[p[offset], p[offset + 1], p[offset + 2]]);
                elevate_quadratic_bezier_to_cubic(&q)
            } else {
                cubic_bspline_to_bezier(&[p[offset], p[offset + 1], p[offset + 2], p[offset + 3]])
            };
            offset += 1;
            b
        };
        if bezier.iter().all(|q| *q == bezier[0]) {
            warnings.push(format!("curve: segment {seg} has zero length; skipped"));
            continue;
        }
        let seg_normals = if normals.is_empty() {
            None
        } else {
            Some([normals[seg], normals[seg + 1]])
        };
        let w0 = lerp(seg as Float / n_segments as Float, width0, width1);
        let w1 = lerp((seg + 1) as Float / n_segments as Float, width0, width1);
        let common = Arc::new(CurveCommon::new(
            bezier,
            w0,
            w1,
            curve_type,
            seg_normals,
            render_from_object,
            reverse_orientation,
        ));
        for i in 0..pieces {
            let u_min = i as Float / pieces as Float;
            let u_max = (i + 1) as Float / pieces as Float;
            curves.push(Curve::new(common.clone(), u_min, u_max));
        }
    }
    Ok((curves, warnings))
}

impl ShapeMethods for Curve {
    fn bounds(&self) -> Bounds3f {
        let c = &*self.common;
        let cp = self.piece_control_points();
        let b = cp[1..]
            .iter()
            .fold(Bounds3f::from_point(cp[0]), |b, p| b.union_point(*p));
        let w = c.width_at(self.u_min).max(c.width_at(self.u_max));
        c.render_from_object.apply_bounds(&b.expand(0.5 * w))
    }

    fn normal_bounds(&self) -> DirectionCone {
        DirectionCone::entire_sphere()
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        let mut si = None;
        self.intersect_ray(ray, t_max, Some(&mut si));
        si
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        self.intersect_ray(ray, t_max, None)
    }

    /// pbrt-v4's approximation: the length of the piece's control polygon
    /// times its average width (object space).
    fn area(&self) -> Float {
        let c = &*self.common;
        let cp = self.piece_control_points();
        let avg_width = 0.5 * (c.width_at(self.u_min) + c.width_at(self.u_max));
        let length: Float = (0..3).map(|i| cp[i].distance(cp[i + 1])).sum();
        length * avg_width
    }

    /// Uniform in the parameter domain [`u_min`, `u_max`] × [0, 1]; the
    /// density per unit area is 1 / ((u_max − u_min) |∂p/∂u × ∂p/∂v|) on
    /// the sampled strip (see `sampling_surface`). pbrt-v4 has no curve
    /// sampling, so this is rpbrt's own: exact for the strip, at the cost
    /// of a non-uniform density.
    ///
    /// [`u_min`]: Curve::u_min
    /// [`u_max`]: Curve::u_max
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        self.sample_at(lerp(u[0], self.u_min, self.u_max), u[1], None)
    }

    /// Area sampling of the strip facing `ctx` (for flat and cylinder
    /// curves: what a ray from `ctx` would see), converted to solid angle.
    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        let toward = self.common.object_from_render.apply_point(ctx.p());
        let mut ss = self.sample_at(lerp(u[0], self.u_min, self.u_max), u[1], Some(toward))?;
        ss.time = ctx.time;
        area_sample_to_solid_angle(ctx, ss)
    }

    /// Intersects the ray from `ctx` toward `wi` and converts the area
    /// density of [`ShapeMethods::sample`] at the hit's (u, v) to solid
    /// angle.
    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        let ray = ctx.spawn_ray(wi);
        let isect = match self.intersect(&ray, Float::INFINITY) {
            Some(i) => i,
            None => return 0.0,
        };
        let toward = self.common.object_from_render.apply_point(ctx.p());
        let uv = isect.intr.uv;
        self.sample_at(uv[0], uv[1], Some(toward))
            .and_then(|ss| area_sample_to_solid_angle(ctx, ss))
            .map_or(0.0, |ss| ss.pdf)
    }
}

#[cfg(test)]
mod tests;
