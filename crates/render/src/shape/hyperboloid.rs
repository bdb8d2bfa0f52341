//! Hyperboloids (pbrt-v3 `shapes/hyperboloid.cpp`, book 3rd edition
//! section 3.8.3; not in pbrt-v4): the surface swept by revolving the
//! segment from `p1` to `p2` about the z axis through `φ_max`.
//!
//! pbrt-v3 fits the implicit form a(x² + y²) − c z² = 1 with an iterative
//! search that is only exact when the segment's closest approach to the
//! axis lies at z = 0, and never terminates for segments through the axis
//! (its default `p1 = (0,0,0)`, `p2 = (1,1,1)` among them). Here the swept
//! surface is used as it is: with v = (z − z₁)/(z₂ − z₁) the squared
//! distance from the axis is the quadratic ρ²(v) = αv² + βv + γ of the
//! segment's points, which is still a quadric, equal to pbrt-v3's where
//! its fit is exact, and covers cones and cylinders too. The (u, v)
//! parameterization, φ measured from the segment's point at that height,
//! and the derivatives are pbrt-v3's.

use super::sphere::{
    nearest_hit, object_ray, object_wo, phi_max_radians, positive_atan2, ray_point_fi,
    render_normal, solve_quadratic, transforms, weingarten,
};
use super::{area_sample_to_solid_angle, pdf_by_intersection, ShapeError, ShapeIntersection};
use super::{ShapeMethods, ShapeSample, ShapeSampleContext};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::interval::Interval;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

/// A hyperboloid of one sheet (or cone, or cylinder) swept by a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hyperboloid {
    /// Object-to-render transformation (its inverse, which it holds too,
    /// is the render-to-object one: one transformation, not two, per shape).
    pub render_from_object: Transform,
    /// Whether normals point the other way.
    pub reverse_orientation: bool,
    /// Whether `render_from_object` changes handedness.
    pub transform_swaps_handedness: bool,
    p1: Point3f,
    p2: Point3f,
    z_min: Float,
    z_max: Float,
    r_max: Float,
    phi_max: Float,
    /// ρ²(v) = αv² + βv + γ.
    alpha: Float,
    beta: Float,
    gamma: Float,
    /// |∂p/∂u × ∂p/∂v|² / φ_max² = q0 + q1 v + q2 v², in double precision
    /// for the area and its inverse CDF.
    q: [f64; 3],
    area: Float,
}

impl Hyperboloid {
    /// A hyperboloid with pbrt-v3's parameters, `phi_max` in degrees
    /// clamped to [0, 360]. Fails for non-finite points, `p1 == p2`, both
    /// points on the axis (no area), both at the same height (a flat
    /// annulus: use a disk), a zero sweep or a singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        p1: Point3f,
        p2: Point3f,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "hyperboloid";
        for (name, p) in [("p1", p1), ("p2", p2)] {
            if !p.is_finite() {
                return Err(ShapeError(format!(
                    "hyperboloid: \"{name}\" must be finite, got {p:?}"
                )));
            }
        }
        if p1 == p2 {
            return Err(ShapeError(
                "hyperboloid: \"p1\" and \"p2\" are the same point".into(),
            ));
        }
        if p1.x == 0.0 && p1.y == 0.0 && p2.x == 0.0 && p2.y == 0.0 {
            return Err(ShapeError(
                "hyperboloid: \"p1\" and \"p2\" both lie on the z axis".into(),
            ));
        }
        if p1.z == p2.z {
            return Err(ShapeError(format!(
                "hyperboloid: \"p1\" and \"p2\" both have z = {}: the surface is a flat annulus (use a disk)",
                p1.z
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        let (dx, dy, dz) = (
            (p2.x - p1.x) as f64,
            (p2.y - p1.y) as f64,
            (p2.z - p1.z) as f64,
        );
        let alpha = dx * dx + dy * dy;
        let beta = 2.0 * (p1.x as f64 * dx + p1.y as f64 * dy);
        let gamma = (p1.x as f64).powi(2) + (p1.y as f64).powi(2);
        // |∂p/∂u × ∂p/∂v|² = φ_max²(ρ² Δz² + (p·∂p/∂v)²_xy), and the latter
        // dot product is dρ²/dv / 2 = αv + β/2.
        let q = [
            gamma * dz * dz + beta * beta / 4.0,
            beta * dz * dz + alpha * beta,
            alpha * dz * dz + alpha * alpha,
        ];
        let area = (phi_max as f64 * (antiderivative(q, 1.0) - antiderivative(q, 0.0))) as Float;
        if !(area > 0.0 && area.is_finite()) {
            return Err(ShapeError(format!(
                "hyperboloid: no surface area for p1 = {p1:?}, p2 = {p2:?}"
            )));
        }
        let r1 = (p1.x * p1.x + p1.y * p1.y).sqrt();
        let r2 = (p2.x * p2.x + p2.y * p2.y).sqrt();
        Ok(Hyperboloid {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            p1,
            p2,
            z_min: p1.z.min(p2.z),
            z_max: p1.z.max(p2.z),
            // ρ² is convex in v, so the widest circle is at an end.
            r_max: r1.max(r2),
            phi_max,
            alpha: alpha as Float,
            beta: beta as Float,
            gamma: gamma as Float,
            q,
            area,
        })
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    /// φ of `p` measured from the segment's point at the same height, and
    /// that height's parameter v.
    fn phi_v(&self, p: Point3f) -> (Float, Float) {
        let v = (p.z - self.p1.z) / (self.p2.z - self.p1.z);
        let pr = Point3f::lerp(v, self.p1, self.p2);
        (
            positive_atan2(pr.x * p.y - p.x * pr.y, p.x * pr.x + p.y * pr.y),
            v,
        )
    }

    fn basic_intersect(
        &self,
        r: &Ray,
        t_max: Float,
    ) -> Option<(Interval, Point3f, Float, Float, Point3fi)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        let dz = self.p2.z - self.p1.z;
        // v along the ray: v0 + t·vd.
        let v0 = (oi.z - self.p1.z) / dz;
        let vd = di.z / dz;
        let a = di.x.sqr() + di.y.sqr() - vd.sqr() * self.alpha;
        let b = (di.x * oi.x + di.y * oi.y) * 2.0 - (v0 * vd * (2.0 * self.alpha) + vd * self.beta);
        let c = oi.x.sqr() + oi.y.sqr()
            - (v0.sqr() * self.alpha + v0 * self.beta + Interval::new(self.gamma));
        let (t0, t1) = solve_quadratic(a, b, c)?;
        let (o, d) = (oi.midpoint(), di.midpoint());
        let (t, (p, phi, v)) = nearest_hit(t0, t1, t_max, |t| {
            let p = o + d * t.midpoint();
            let (phi, v) = self.phi_v(p);
            (p.z >= self.z_min && p.z <= self.z_max && phi <= self.phi_max).then_some((p, phi, v))
        })?;
        Some((t, p, phi, v, ray_point_fi(oi, di, t)))
    }

    fn derivatives(&self, p: Point3f, phi: Float) -> (Vector3f, Vector3f) {
        let (c, s) = (phi.cos(), phi.sin());
        let d = self.p2 - self.p1;
        let dpdu = Vector3f::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let dpdv = Vector3f::new(d.x * c - d.y * s, d.x * s + d.y * c, d.z);
        (dpdu, dpdv)
    }

    fn interaction(
        &self,
        p: Point3f,
        phi: Float,
        v: Float,
        p_fi: Point3fi,
        wo: Vector3f,
        time: Float,
    ) -> SurfaceInteraction {
        let (dpdu, dpdv) = self.derivatives(p, phi);
        let d2pduu = Vector3f::new(p.x, p.y, 0.0) * (-self.phi_max * self.phi_max);
        let d2pduv = Vector3f::new(-dpdv.y, dpdv.x, 0.0) * self.phi_max;
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, d2pduv, Vector3f::default());
        SurfaceInteraction::new(
            Point3fi::from_value_and_error(p, p_fi.error()),
            Point2f::new(phi / self.phi_max, v),
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

    /// The v whose share of the area (from v = 0) is `u`: Newton's method
    /// on the closed-form CDF, safeguarded by bisection.
    fn sample_v(&self, u: f64) -> f64 {
        let f0 = antiderivative(self.q, 0.0);
        let total = antiderivative(self.q, 1.0) - f0;
        let target = u * total;
        let (mut lo, mut hi, mut v) = (0.0f64, 1.0f64, u);
        for _ in 0..60 {
            let f = antiderivative(self.q, v) - f0 - target;
            if f.abs() <= 1e-14 * total {
                break;
            }
            if f > 0.0 {
                hi = v;
            } else {
                lo = v;
            }
            let df = (self.q[0] + v * (self.q[1] + v * self.q[2]))
                .max(0.0)
                .sqrt();
            let next = v - f / df;
            v = if df > 0.0 && next > lo && next < hi {
                next
            } else {
                0.5 * (lo + hi)
            };
        }
        v.clamp(0.0, 1.0)
    }
}

/// ∫ √(q0 + q1 v + q2 v²) dv, with q2 ≥ 0 and a non-positive
/// discriminant (the integrand is the length of a cross product).
fn antiderivative(q: [f64; 3], v: f64) -> f64 {
    let [q0, q1, q2] = q;
    if q2 <= 1e-300 {
        // Then q1 = 0 as well: a constant area element (a cylinder).
        return q0.max(0.0).sqrt() * v;
    }
    let s = v + q1 / (2.0 * q2);
    let m = ((q0 - q1 * q1 / (4.0 * q2)) / q2).max(0.0);
    let root = (s * s + m).sqrt();
    let log_term = if m > 0.0 {
        m * (s / m.sqrt()).asinh()
    } else {
        0.0
    };
    0.5 * q2.sqrt() * (s * root + log_term)
}

impl ShapeMethods for Hyperboloid {
    fn bounds(&self) -> Bounds3f {
        let r = self.r_max;
        self.render_from_object.apply_bounds(&Bounds3f::new(
            Point3f::new(-r, -r, self.z_min),
            Point3f::new(r, r, self.z_max),
        ))
    }

    fn normal_bounds(&self) -> DirectionCone {
        DirectionCone::entire_sphere()
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        let (t, p, phi, v, p_fi) = self.basic_intersect(ray, t_max)?;
        let wo = object_wo(&self.render_from_object.inverse(), ray);
        Some(ShapeIntersection {
            intr: self.interaction(p, phi, v, p_fi, wo, ray.time),
            t_hit: t.midpoint(),
        })
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        self.basic_intersect(ray, t_max).is_some()
    }

    /// Object-space area φ_max ∫₀¹ |∂p/∂v × (−y, x, 0)| dv in closed form
    /// (exact for every segment, where pbrt-v3's polynomial assumes its
    /// implicit fit).
    fn area(&self) -> Float {
        self.area
    }

    /// Uniform by area: v by inverting the closed-form area CDF, φ
    /// uniform (the area element does not depend on φ).
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let v = self.sample_v(u.x as f64) as Float;
        let phi = u.y * self.phi_max;
        let pr = Point3f::lerp(v, self.p1, self.p2);
        let (c, s) = (phi.cos(), phi.sin());
        let p = Point3f::new(pr.x * c - pr.y * s, pr.x * s + pr.y * c, pr.z);
        let p_error = Vector3f::from(p).abs() * gamma(6);
        let (dpdu, dpdv) = self.derivatives(p, phi);
        let n = render_normal(
            &self.render_from_object,
            Normal3f::from(cross(dpdu, dpdv)),
            self.flip(),
        )?;
        Some(ShapeSample {
            pi: self
                .render_from_object
                .apply_point_fi(Point3fi::from_value_and_error(p, p_error)),
            n,
            uv: Point2f::new(u.y, v),
            time: 0.0,
            pdf: 1.0 / self.area,
        })
    }

    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        let mut ss = self.sample_area(u)?;
        ss.time = ctx.time;
        area_sample_to_solid_angle(ctx, ss)
    }

    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        pdf_by_intersection(self, ctx, wi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::sphere::testing::*;
    use super::*;
    use crate::rng::Rng;

    /// The implicit function and clipping test of the swept segment,
    /// written independently in double precision.
    fn reference(
        p1: Point3f,
        p2: Point3f,
        phimax_deg: f64,
    ) -> (impl Fn([f64; 3]) -> f64, impl Fn([f64; 3]) -> bool) {
        let a = [p1.x as f64, p1.y as f64, p1.z as f64];
        let b = [p2.x as f64, p2.y as f64, p2.z as f64];
        let gen = move |z: f64| {
            let v = (z - a[2]) / (b[2] - a[2]);
            (a[0] + v * (b[0] - a[0]), a[1] + v * (b[1] - a[1]))
        };
        let f = move |p: [f64; 3]| {
            let (gx, gy) = gen(p[2]);
            p[0] * p[0] + p[1] * p[1] - (gx * gx + gy * gy)
        };
        let on = move |p: [f64; 3]| {
            let (gx, gy) = gen(p[2]);
            let phi = (gx * p[1] - p[0] * gy)
                .atan2(p[0] * gx + p[1] * gy)
                .rem_euclid(2.0 * std::f64::consts::PI);
            p[2] >= a[2].min(b[2]) && p[2] <= a[2].max(b[2]) && phi <= phimax_deg.to_radians()
        };
        (f, on)
    }

    #[test]
    fn degenerate_input_is_rejected() {
        let t = Transform::identity();
        let p = Point3f::new;
        assert!(Hyperboloid::new(t, false, p(1.0, 0.0, 0.0), p(1.0, 0.0, 0.0), 360.0).is_err());
        assert!(Hyperboloid::new(t, false, p(0.0, 0.0, 0.0), p(0.0, 0.0, 1.0), 360.0).is_err());
        assert!(Hyperboloid::new(t, false, p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0), 360.0).is_err());
        assert!(
            Hyperboloid::new(t, false, p(Float::NAN, 0.0, 0.0), p(0.0, 1.0, 1.0), 360.0).is_err()
        );
        assert!(Hyperboloid::new(t, false, p(1.0, 0.0, 0.0), p(0.0, 1.0, 1.0), 0.0).is_err());
        // pbrt-v3's default, a cone through the origin, on which its
        // fitting loop never ends.
        let h = Hyperboloid::new(t, false, p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0), 360.0).unwrap();
        let cone_area = 2.0f32.sqrt() * 3.0f32.sqrt() * PI;
        assert!((h.area() - cone_area).abs() < 1e-4 * cone_area);
    }

    #[test]
    fn special_cases_match_closed_forms() {
        let t = Transform::identity();
        let p = Point3f::new;
        // A vertical segment sweeps a cylinder.
        let h = Hyperboloid::new(t, false, p(0.5, 0.5, -1.0), p(0.5, 0.5, 1.0), 360.0).unwrap();
        let r = 0.5f32.sqrt();
        assert!((h.area() - 2.0 * PI * r * 2.0).abs() < 1e-4);
        // Symmetric about z = 0: pbrt-v3's implicit fit a ρ² − c z² = 1 is
        // exact here (ρ² = (1 + z²)/2 for this segment).
        let h = Hyperboloid::new(t, false, p(1.0, 0.0, -1.0), p(0.0, 1.0, 1.0), 360.0).unwrap();
        let hit = h
            .intersect(
                &Ray::new(p(5.0, 0.0, 0.5), Vector3f::new(-1.0, 0.0, 0.0)),
                Float::INFINITY,
            )
            .unwrap();
        assert!((hit.intr.p().x - (1.25f32 / 2.0).sqrt()).abs() < 1e-4);
    }

    #[test]
    fn reintersect_and_reference() {
        let mut rng = Rng::with_sequence(51);
        for i in 0..40 {
            let t = rigid(&mut rng);
            let mut pt = || {
                Point3f::new(
                    2.0 * uf(&mut rng) - 1.0,
                    2.0 * uf(&mut rng) - 1.0,
                    2.0 * uf(&mut rng) - 1.0,
                )
            };
            let (p1, mut p2) = (pt(), pt());
            // Keep the segment away from horizontal, where v = (z − z₁)/Δz
            // magnifies float error beyond the reference's tolerance.
            if (p2.z - p1.z).abs() < 0.3 {
                p2.z = p1.z + 0.3;
            }
            let ph = if i % 2 == 0 {
                360.0
            } else {
                60.0 + 300.0 * uf(&mut rng)
            };
            let h = Hyperboloid::new(t, i % 3 == 0, p1, p2, ph).unwrap();
            check_reintersect(&h, &mut rng, 300, Leaving::FarOnly);
            let (f, on) = reference(p1, p2, ph as f64);
            check_reference(&h, &t, &mut rng, 500, &f, &on);
        }
    }

    #[test]
    fn orientation_flips_normals() {
        let p = Point3f::new;
        let ray = Ray::new(p(5.0, 0.0, 0.5), Vector3f::new(-1.0, 0.0, 0.0));
        let nx = |t: Transform, rev: bool| {
            let h = Hyperboloid::new(t, rev, p(1.0, 0.0, -1.0), p(0.0, 1.0, 1.0), 360.0).unwrap();
            h.intersect(&ray, Float::INFINITY).unwrap().intr.n.x
        };
        let (id, flip) = (Transform::identity(), Transform::scale(1.0, 1.0, -1.0));
        let base = nx(id, false);
        assert!(base.abs() > 0.5);
        assert!(nx(id, true) * base < 0.0);
        assert!(nx(flip, false) * base < 0.0);
        assert!(nx(flip, true) * base > 0.0);
    }

    #[test]
    fn area_and_sampling() {
        let mut rng = Rng::with_sequence(52);
        let p = Point3f::new;
        let cases = [
            (p(1.0, 0.0, -1.0), p(0.0, 1.0, 1.0), 360.0),
            (p(0.3, 0.0, -0.5), p(1.0, 0.8, 1.5), 360.0),
            (p(0.0, 0.0, 0.0), p(1.0, 0.0, 1.0), 250.0),
            (p(0.6, 0.2, -1.0), p(0.6, 0.2, 0.5), 90.0),
        ];
        for (i, &(p1, p2, ph)) in cases.iter().enumerate() {
            let t = rigid(&mut rng);
            let h = Hyperboloid::new(t, i == 1, p1, p2, ph).unwrap();
            check_area_sampling(&h, &mut rng, 3000);
        }
        // From the waist's centre of a symmetric hyperboloid every ray
        // meets it at most once.
        let t = rigid(&mut rng);
        let h = Hyperboloid::new(t, false, p(1.0, 0.0, -1.0), p(0.0, 1.0, 1.0), 360.0).unwrap();
        check_solid_angle(&h, t.apply_point(p(0.0, 0.0, 0.0)), &mut rng, 20000);
        let h = Hyperboloid::new(t, true, p(1.0, 0.0, -1.0), p(0.0, 1.0, 1.0), 200.0).unwrap();
        check_solid_angle(&h, t.apply_point(p(0.0, 0.0, 0.0)), &mut rng, 20000);
    }
}
