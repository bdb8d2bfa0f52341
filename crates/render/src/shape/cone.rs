//! Cones (pbrt-v3 `shapes/cone.cpp`, book 3rd edition section 3.8.1; not
//! in pbrt-v4): apex at (0, 0, `height`), base circle of radius `radius` in
//! the plane z = 0, swept to `φ_max`.

use super::sphere::{
    nearest_hit, object_ray, object_wo, phi_max_radians, positive_atan2, ray_point_fi,
    render_normal, require_finite, solve_quadratic, transforms, weingarten,
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

/// A cone about the object-space z axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Object-to-render transformation (its inverse, which it holds too,
    /// is the render-to-object one: one transformation, not two, per shape).
    pub render_from_object: Transform,
    /// Whether normals point inward.
    pub reverse_orientation: bool,
    /// Whether `render_from_object` changes handedness.
    pub transform_swaps_handedness: bool,
    height: Float,
    radius: Float,
    phi_max: Float,
}

impl Cone {
    /// A cone with pbrt-v3's parameters, `phi_max` in degrees clamped to
    /// [0, 360]. Fails for a non-positive or non-finite height or radius, a
    /// zero sweep or a singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        height: Float,
        radius: Float,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "cone";
        require_finite(S, "height", height)?;
        require_finite(S, "radius", radius)?;
        if height <= 0.0 {
            return Err(ShapeError(format!(
                "cone: \"height\" must be positive, got {height}"
            )));
        }
        if radius <= 0.0 {
            return Err(ShapeError(format!(
                "cone: \"radius\" must be positive, got {radius}"
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        Ok(Cone {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            height,
            radius,
            phi_max,
        })
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    fn basic_intersect(
        &self,
        r: &Ray,
        t_max: Float,
    ) -> Option<(Interval, Point3f, Float, Point3fi)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        // x² + y² = k (z − h)², k = (r/h)².
        let k = (Interval::new(self.radius) / Interval::new(self.height)).sqr();
        let oz = oi.z - self.height;
        let a = di.x.sqr() + di.y.sqr() - k * di.z.sqr();
        let b = (di.x * oi.x + di.y * oi.y - k * di.z * oz) * 2.0;
        let c = oi.x.sqr() + oi.y.sqr() - k * oz.sqr();
        let (t0, t1) = solve_quadratic(a, b, c)?;
        let (o, d) = (oi.midpoint(), di.midpoint());
        let (t, (p, phi)) = nearest_hit(t0, t1, t_max, |t| {
            let p = o + d * t.midpoint();
            let phi = positive_atan2(p.y, p.x);
            (p.z >= 0.0 && p.z <= self.height && phi <= self.phi_max).then_some((p, phi))
        })?;
        Some((t, p, phi, ray_point_fi(oi, di, t)))
    }

    fn interaction(
        &self,
        p: Point3f,
        phi: Float,
        p_fi: Point3fi,
        wo: Vector3f,
        time: Float,
    ) -> SurfaceInteraction {
        let v = p.z / self.height;
        let uv = Point2f::new(phi / self.phi_max, v);
        let (c, s) = (phi.cos(), phi.sin());
        let dpdu = Vector3f::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        // pbrt-v3's −(x, y)/(1 − v) is −r(cos φ, sin φ) on the surface;
        // this form stays finite at the apex.
        let dpdv = Vector3f::new(-self.radius * c, -self.radius * s, self.height);
        let d2pduu = Vector3f::new(p.x, p.y, 0.0) * (-self.phi_max * self.phi_max);
        let d2pduv = Vector3f::new(s, -c, 0.0) * (self.phi_max * self.radius);
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, d2pduv, Vector3f::default());
        SurfaceInteraction::new(
            Point3fi::from_value_and_error(p, p_fi.error()),
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
}

impl ShapeMethods for Cone {
    fn bounds(&self) -> Bounds3f {
        let r = self.radius;
        self.render_from_object.apply_bounds(&Bounds3f::new(
            Point3f::new(-r, -r, 0.0),
            Point3f::new(r, r, self.height),
        ))
    }

    fn normal_bounds(&self) -> DirectionCone {
        DirectionCone::entire_sphere()
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        let (t, p, phi, p_fi) = self.basic_intersect(ray, t_max)?;
        let wo = object_wo(&self.render_from_object.inverse(), ray);
        Some(ShapeIntersection {
            intr: self.interaction(p, phi, p_fi, wo, ray.time),
            t_hit: t.midpoint(),
        })
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        self.basic_intersect(ray, t_max).is_some()
    }

    /// Object-space lateral area r·√(h² + r²)·φ_max/2.
    fn area(&self) -> Float {
        self.radius * (sqr(self.height) + sqr(self.radius)).sqrt() * self.phi_max / 2.0
    }

    /// Uniform by area: the area element grows linearly with the distance
    /// from the apex, so 1 − v = √(1 − u₀) inverts the area CDF in height;
    /// φ is uniform.
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let s = (1.0 - u.x).max(0.0).sqrt();
        let v = 1.0 - s;
        let rho = self.radius * s;
        let phi = u.y * self.phi_max;
        let (c, sn) = (phi.cos(), phi.sin());
        let p = Point3f::new(rho * c, rho * sn, v * self.height);
        let p_error = Vector3f::from(p).abs() * gamma(5);
        let n = render_normal(
            &self.render_from_object,
            Normal3f::new(self.height * c, self.height * sn, self.radius),
            self.flip(),
        )?;
        Some(ShapeSample {
            pi: self
                .render_from_object
                .apply_point_fi(Point3fi::from_value_and_error(p, p_error)),
            n,
            uv: Point2f::new(u.y, v),
            time: 0.0,
            pdf: 1.0 / self.area(),
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

    fn implicit(h: f64, r: f64) -> impl Fn([f64; 3]) -> f64 {
        move |p| p[0] * p[0] + p[1] * p[1] - (r / h).powi(2) * (h - p[2]).powi(2)
    }

    fn clip(h: f64, phimax_deg: f64) -> impl Fn([f64; 3]) -> bool {
        move |p| {
            let phi = p[1].atan2(p[0]).rem_euclid(2.0 * std::f64::consts::PI);
            p[2] >= 0.0 && p[2] <= h && phi <= phimax_deg.to_radians()
        }
    }

    #[test]
    fn degenerate_input_is_rejected() {
        let t = Transform::identity();
        assert!(Cone::new(t, false, 0.0, 1.0, 360.0).is_err());
        assert!(Cone::new(t, false, 1.0, 0.0, 360.0).is_err());
        assert!(Cone::new(t, false, -1.0, 1.0, 360.0).is_err());
        assert!(Cone::new(t, false, 1.0, Float::NAN, 360.0).is_err());
        assert!(Cone::new(t, false, 1.0, 1.0, 0.0).is_err());
        assert!(Cone::new(t, false, 1.0, 1.0, Float::INFINITY).is_err());
    }

    #[test]
    fn reintersect_and_reference() {
        let mut rng = Rng::with_sequence(31);
        for i in 0..40 {
            let t = rigid(&mut rng);
            let h = 0.2 + 2.0 * uf(&mut rng);
            let r = 0.2 + 2.0 * uf(&mut rng);
            let ph = if i % 2 == 0 {
                360.0
            } else {
                60.0 + 300.0 * uf(&mut rng)
            };
            let c = Cone::new(t, i % 3 == 0, h, r, ph).unwrap();
            check_reintersect(
                &c,
                &mut rng,
                300,
                Leaving::Outward(if i % 3 == 0 { -1.0 } else { 1.0 }),
            );
            check_reference(
                &c,
                &t,
                &mut rng,
                500,
                &implicit(h as f64, r as f64),
                &clip(h as f64, ph as f64),
            );
        }
    }

    #[test]
    fn misses_and_orientation() {
        let c = Cone::new(Transform::identity(), false, 1.0, 1.0, 90.0).unwrap();
        let x = Vector3f::new(1.0, 0.0, 0.0);
        // Above the apex, outside the sweep.
        assert!(!c.intersect_p(&Ray::new(Point3f::new(-5.0, 0.0, 1.5), x), Float::INFINITY));
        assert!(!c.intersect_p(&Ray::new(Point3f::new(-5.0, -0.2, 0.5), x), Float::INFINITY));
        let h = c
            .intersect(&Ray::new(Point3f::new(-5.0, 0.2, 0.5), x), Float::INFINITY)
            .unwrap();
        assert!((h.intr.p().x - (0.25f32 - 0.04).sqrt()).abs() < 1e-4);
        assert!(h.intr.n.x > 0.0 && h.intr.n.z > 0.0);
        let flip = Transform::scale(1.0, 1.0, -1.0);
        let ray = Ray::new(Point3f::new(5.0, 0.0, -0.5), Vector3f::new(-1.0, 0.0, 0.0));
        let n = Cone::new(flip, false, 1.0, 1.0, 360.0)
            .unwrap()
            .intersect(&ray, Float::INFINITY)
            .unwrap()
            .intr
            .n;
        assert!(n.x < -0.5);
        let n = Cone::new(flip, true, 1.0, 1.0, 360.0)
            .unwrap()
            .intersect(&ray, Float::INFINITY)
            .unwrap()
            .intr
            .n;
        assert!(n.x > 0.5);
    }

    #[test]
    fn area_and_sampling() {
        let mut rng = Rng::with_sequence(32);
        for (i, &(h, r, ph)) in [(1.0, 1.0, 360.0), (2.0, 0.5, 360.0), (0.5, 1.5, 120.0)]
            .iter()
            .enumerate()
        {
            let t = rigid(&mut rng);
            let c = Cone::new(t, i == 1, h, r, ph).unwrap();
            check_area_sampling(&c, &mut rng, 3000);
            check_solid_angle(
                &c,
                t.apply_point(Point3f::new(0.0, 0.0, -0.5 * h)),
                &mut rng,
                20000,
            );
        }
    }
}
