//! Cylinders (book section 6.3; pbrt-v4 `shapes.h` `Cylinder`): the open
//! tube of radius `radius` about the z axis between `z_min` and `z_max`,
//! swept to `φ_max`.

use super::sphere::{
    nearest_hit, object_ray, object_wo, phi_max_radians, positive_atan2, render_normal,
    require_finite, roots_from_discriminant, transforms, weingarten,
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

/// A cylinder about the object-space z axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
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
    phi_max: Float,
}

impl Cylinder {
    /// A cylinder with pbrt's parameters: `z_min`/`z_max` are put in
    /// order, `phi_max` (degrees) clamped to [0, 360]. Fails for a
    /// non-positive or non-finite radius, equal z bounds, a zero sweep or a
    /// singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        radius: Float,
        z_min: Float,
        z_max: Float,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "cylinder";
        require_finite(S, "radius", radius)?;
        require_finite(S, "zmin", z_min)?;
        require_finite(S, "zmax", z_max)?;
        if radius <= 0.0 {
            return Err(ShapeError(format!(
                "cylinder: \"radius\" must be positive, got {radius}"
            )));
        }
        if z_min == z_max {
            return Err(ShapeError(format!(
                "cylinder: \"zmin\" and \"zmax\" are both {z_min}"
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        Ok(Cylinder {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            radius,
            z_min: z_min.min(z_max),
            z_max: z_min.max(z_max),
            phi_max,
        })
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    /// The hit point refined onto the tube, and its φ.
    fn point_at(&self, o: Point3f, d: Vector3f, t: Float) -> (Point3f, Float) {
        let mut p = o + d * t;
        let hit_rad = (p.x * p.x + p.y * p.y).sqrt();
        if hit_rad > 0.0 {
            p.x *= self.radius / hit_rad;
            p.y *= self.radius / hit_rad;
        }
        (p, positive_atan2(p.y, p.x))
    }

    fn basic_intersect(&self, r: &Ray, t_max: Float) -> Option<(Float, Point3f, Float)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        let a = di.x.sqr() + di.y.sqr();
        let b = (di.x * oi.x + di.y * oi.y) * 2.0;
        let rad = Interval::new(self.radius);
        let c = oi.x.sqr() + oi.y.sqr() - rad.sqr();
        // The accurate discriminant of pbrt-v4: 4a(r − ρ)(r + ρ) with ρ
        // the distance of the ray's closest approach to the axis.
        let f = b / (a * 2.0);
        let fx = oi.x - f * di.x;
        let fy = oi.y - f * di.y;
        let rho = (fx.sqr() + fy.sqr()).sqrt();
        let discrim = Interval::new(4.0) * a * (rad + rho) * (rad - rho);
        if discrim.low.is_nan() || discrim.low < 0.0 {
            return None;
        }
        let (t0, t1) = roots_from_discriminant(a, b, c, discrim);
        let (o, d) = (oi.midpoint(), di.midpoint());
        let (t, (p, phi)) = nearest_hit(t0, t1, t_max, |t| {
            let (p, phi) = self.point_at(o, d, t.midpoint());
            (p.z >= self.z_min && p.z <= self.z_max && phi <= self.phi_max).then_some((p, phi))
        })?;
        Some((t.midpoint(), p, phi))
    }

    fn interaction(&self, p: Point3f, phi: Float, wo: Vector3f, time: Float) -> SurfaceInteraction {
        let uv = Point2f::new(
            phi / self.phi_max,
            (p.z - self.z_min) / (self.z_max - self.z_min),
        );
        let dpdu = Vector3f::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let dpdv = Vector3f::new(0.0, 0.0, self.z_max - self.z_min);
        let d2pduu = Vector3f::new(p.x, p.y, 0.0) * (-self.phi_max * self.phi_max);
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, Vector3f::default(), Vector3f::default());
        let p_error = Vector3f::new(p.x, p.y, 0.0).abs() * gamma(3);
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
}

impl ShapeMethods for Cylinder {
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

    /// Object-space area (z_max − z_min)·r·φ_max, as pbrt.
    fn area(&self) -> Float {
        (self.z_max - self.z_min) * self.radius * self.phi_max
    }

    /// z and φ uniform: the tube's area element is constant.
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let z = lerp(u.x, self.z_min, self.z_max);
        let phi = u.y * self.phi_max;
        let (p, _) = self.point_at(
            Point3f::new(self.radius * phi.cos(), self.radius * phi.sin(), z),
            Vector3f::default(),
            0.0,
        );
        let p_error = Vector3f::new(p.x, p.y, 0.0).abs() * gamma(3);
        let n = render_normal(
            &self.render_from_object,
            Normal3f::new(p.x, p.y, 0.0),
            self.flip(),
        )?;
        Some(ShapeSample {
            pi: self
                .render_from_object
                .apply_point_fi(Point3fi::from_value_and_error(p, p_error)),
            n,
            uv: Point2f::new(u.y, u.x),
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

    fn implicit(r: f64) -> impl Fn([f64; 3]) -> f64 {
        move |p| p[0] * p[0] + p[1] * p[1] - r * r
    }

    fn clip(zmin: f64, zmax: f64, phimax_deg: f64) -> impl Fn([f64; 3]) -> bool {
        move |p| {
            let phi = p[1].atan2(p[0]).rem_euclid(2.0 * std::f64::consts::PI);
            p[2] >= zmin && p[2] <= zmax && phi <= phimax_deg.to_radians()
        }
    }

    #[test]
    fn degenerate_input_is_rejected() {
        let t = Transform::identity();
        assert!(Cylinder::new(t, false, 0.0, -1.0, 1.0, 360.0).is_err());
        assert!(Cylinder::new(t, false, -2.0, -1.0, 1.0, 360.0).is_err());
        assert!(Cylinder::new(t, false, Float::NAN, -1.0, 1.0, 360.0).is_err());
        assert!(Cylinder::new(t, false, 1.0, 1.0, 1.0, 360.0).is_err());
        assert!(Cylinder::new(t, false, 1.0, -1.0, 1.0, -5.0).is_err());
        assert!(Cylinder::new(t, false, 1.0, Float::NEG_INFINITY, 1.0, 360.0).is_err());
        let c = Cylinder::new(t, false, 1.0, 2.0, -1.0, 400.0).unwrap();
        assert_eq!((c.z_min, c.z_max), (-1.0, 2.0));
    }

    #[test]
    fn reintersect_and_reference() {
        let mut rng = Rng::with_sequence(11);
        for i in 0..40 {
            let t = rigid(&mut rng);
            let r = 0.2 + 2.0 * uf(&mut rng);
            let (z0, z1) = (-2.0 * uf(&mut rng), 0.1 + 2.0 * uf(&mut rng));
            let ph = if i % 2 == 0 {
                360.0
            } else {
                60.0 + 300.0 * uf(&mut rng)
            };
            let c = Cylinder::new(t, i % 3 == 0, r, z0, z1, ph).unwrap();
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
                &implicit(r as f64),
                &clip(z0 as f64, z1 as f64, ph as f64),
            );
        }
    }

    #[test]
    fn misses_outside_clipping() {
        let c = Cylinder::new(Transform::identity(), false, 1.0, 0.0, 1.0, 90.0).unwrap();
        // Below the z range.
        assert!(!c.intersect_p(
            &Ray::new(Point3f::new(-5.0, 0.5, -0.5), Vector3f::new(1.0, 0.0, 0.0)),
            Float::INFINITY
        ));
        // Outside the sweep (φ = 210° and 330°).
        assert!(!c.intersect_p(
            &Ray::new(Point3f::new(-5.0, -0.5, 0.5), Vector3f::new(1.0, 0.0, 0.0)),
            Float::INFINITY
        ));
        // First root cut (φ = 150°), second kept (φ = 30°).
        let h = c
            .intersect(
                &Ray::new(Point3f::new(-5.0, 0.5, 0.5), Vector3f::new(1.0, 0.0, 0.0)),
                Float::INFINITY,
            )
            .unwrap();
        assert!((h.intr.p().x - 0.75f32.sqrt()).abs() < 1e-4);
        assert!(h.intr.n.x > 0.8);
    }

    #[test]
    fn orientation_flips_normals() {
        let ray = Ray::new(Point3f::new(5.0, 0.0, 0.5), Vector3f::new(-1.0, 0.0, 0.0));
        let n = |c: Cylinder| c.intersect(&ray, Float::INFINITY).unwrap().intr.n.x;
        let t = Transform::identity();
        let flip = Transform::scale(1.0, 1.0, -1.0);
        assert!(n(Cylinder::new(t, false, 1.0, 0.0, 1.0, 360.0).unwrap()) > 0.99);
        assert!(n(Cylinder::new(t, true, 1.0, 0.0, 1.0, 360.0).unwrap()) < -0.99);
        assert!(n(Cylinder::new(flip, false, 1.0, -1.0, 0.0, 360.0).unwrap()) < -0.99);
        assert!(n(Cylinder::new(flip, true, 1.0, -1.0, 0.0, 360.0).unwrap()) > 0.99);
    }

    #[test]
    fn area_and_sampling() {
        let mut rng = Rng::with_sequence(12);
        for (i, &(z0, z1, ph)) in [(-1.0, 1.0, 360.0), (0.0, 0.5, 360.0), (-1.0, 2.0, 100.0)]
            .iter()
            .enumerate()
        {
            let t = rigid(&mut rng);
            let c = Cylinder::new(t, i == 2, 0.7, z0, z1, ph).unwrap();
            check_area_sampling(&c, &mut rng, 3000);
            // From a point on the axis beyond the tube every ray meets it at
            // most once.
            check_solid_angle(
                &c,
                t.apply_point(Point3f::new(0.0, 0.0, z1 + 0.7)),
                &mut rng,
                20000,
            );
        }
        let c =
            Cylinder::new(Transform::scale(1.0, 1.0, -1.0), true, 1.0, 0.0, 1.0, 360.0).unwrap();
        check_area_sampling(&c, &mut rng, 1000);
    }
}
