//! Paraboloids (pbrt-v3 `shapes/paraboloid.cpp`, book 3rd edition section
//! 3.8.2; not in pbrt-v4): z = k(x² + y²) with radius `radius` at
//! z = `z_max`, clipped to `z_min ≤ z ≤ z_max`, swept to `φ_max`.

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

/// A paraboloid of revolution about the object-space z axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paraboloid {
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

impl Paraboloid {
    /// A paraboloid with pbrt-v3's parameters: `z_min`/`z_max` put in
    /// order and `z_min` clamped to 0 (the surface has no points below),
    /// `phi_max` in degrees clamped to [0, 360]. Fails for non-finite
    /// values, a non-positive radius or `z_max`, an empty z range, a zero
    /// sweep or a singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        radius: Float,
        z_min: Float,
        z_max: Float,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "paraboloid";
        require_finite(S, "radius", radius)?;
        require_finite(S, "zmin", z_min)?;
        require_finite(S, "zmax", z_max)?;
        if radius <= 0.0 {
            return Err(ShapeError(format!(
                "paraboloid: \"radius\" must be positive, got {radius}"
            )));
        }
        let zhi = z_min.max(z_max);
        let zlo = z_min.min(z_max).max(0.0);
        if zhi <= 0.0 || zlo >= zhi {
            return Err(ShapeError(format!(
                "paraboloid: empty z range [{z_min}, {z_max}] (the surface lies in z ≥ 0)"
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        Ok(Paraboloid {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            radius,
            z_min: zlo,
            z_max: zhi,
            phi_max,
        })
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    /// k of z = k ρ².
    fn k(&self) -> Float {
        self.z_max / (self.radius * self.radius)
    }

    fn basic_intersect(
        &self,
        r: &Ray,
        t_max: Float,
    ) -> Option<(Interval, Point3f, Float, Point3fi)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        let k = Interval::new(self.z_max) / Interval::new(self.radius).sqr();
        let a = k * (di.x.sqr() + di.y.sqr());
        let b = k * (di.x * oi.x + di.y * oi.y) * 2.0 - di.z;
        let c = k * (oi.x.sqr() + oi.y.sqr()) - oi.z;
        let (t0, t1) = solve_quadratic(a, b, c)?;
        let (o, d) = (oi.midpoint(), di.midpoint());
        let (t, (p, phi)) = nearest_hit(t0, t1, t_max, |t| {
            let p = o + d * t.midpoint();
            let phi = positive_atan2(p.y, p.x);
            (p.z >= self.z_min && p.z <= self.z_max && phi <= self.phi_max).then_some((p, phi))
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
        let dz = self.z_max - self.z_min;
        let uv = Point2f::new(phi / self.phi_max, (p.z - self.z_min) / dz);
        // The z parameterization is singular at the apex; keep it finite.
        let z = p.z.max(1e-6 * self.z_max);
        let dpdu = Vector3f::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let dpdv = Vector3f::new(p.x / (2.0 * z), p.y / (2.0 * z), 1.0) * dz;
        let d2pduu = Vector3f::new(p.x, p.y, 0.0) * (-self.phi_max * self.phi_max);
        let d2pduv = Vector3f::new(-p.y / (2.0 * z), p.x / (2.0 * z), 0.0) * (dz * self.phi_max);
        let d2pdvv = Vector3f::new(p.x / (4.0 * z * z), p.y / (4.0 * z * z), 0.0) * (-dz * dz);
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, d2pduv, d2pdvv);
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

impl ShapeMethods for Paraboloid {
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

    /// Object-space area φ_max/(12k²)·[(4kz + 1)^{3/2}] from z_min to
    /// z_max, the surface-of-revolution integral (pbrt-v3's formula).
    fn area(&self) -> Float {
        let r2 = self.radius * self.radius;
        let k4 = 4.0 * self.z_max / r2;
        (r2 * r2 * self.phi_max / (12.0 * self.z_max * self.z_max))
            * ((k4 * self.z_max + 1.0).powf(1.5) - (k4 * self.z_min + 1.0).powf(1.5))
    }

    /// Uniform by area: the area per unit height is ∝ √(4kz + 1), whose
    /// CDF (4kz + 1)^{3/2} inverts in closed form; φ is uniform.
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let k = self.k() as f64;
        let cdf = |z: f64| (4.0 * k * z + 1.0).powf(1.5);
        let w = (1.0 - u.x as f64) * cdf(self.z_min as f64) + u.x as f64 * cdf(self.z_max as f64);
        let z = ((w.powf(2.0 / 3.0) - 1.0) / (4.0 * k)).clamp(self.z_min as f64, self.z_max as f64);
        let rho = (z / k).sqrt() as Float;
        let phi = u.y * self.phi_max;
        let p = Point3f::new(rho * phi.cos(), rho * phi.sin(), z as Float);
        let p_error = Vector3f::from(p).abs() * gamma(5);
        // ∂p/∂u × ∂p/∂v ∝ (x, y, −1/(2k)).
        let n_obj = Normal3f::new(p.x, p.y, (-0.5 / k) as Float);
        let n = render_normal(&self.render_from_object, n_obj, self.flip())?;
        Some(ShapeSample {
            pi: self
                .render_from_object
                .apply_point_fi(Point3fi::from_value_and_error(p, p_error)),
            n,
            uv: Point2f::new(u.y, (p.z - self.z_min) / (self.z_max - self.z_min)),
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

    fn implicit(k: f64) -> impl Fn([f64; 3]) -> f64 {
        move |p| k * (p[0] * p[0] + p[1] * p[1]) - p[2]
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
        assert!(Paraboloid::new(t, false, 0.0, 0.0, 1.0, 360.0).is_err());
        assert!(Paraboloid::new(t, false, 1.0, -2.0, -1.0, 360.0).is_err());
        assert!(Paraboloid::new(t, false, 1.0, 0.5, 0.5, 360.0).is_err());
        assert!(Paraboloid::new(t, false, 1.0, 0.0, Float::NAN, 360.0).is_err());
        assert!(Paraboloid::new(t, false, 1.0, 0.0, 1.0, 0.0).is_err());
        let p = Paraboloid::new(t, false, 1.0, 2.0, -1.0, 360.0).unwrap();
        assert_eq!((p.z_min, p.z_max), (0.0, 2.0));
    }

    #[test]
    fn reintersect_and_reference() {
        let mut rng = Rng::with_sequence(41);
        for i in 0..40 {
            let t = rigid(&mut rng);
            let r = 0.2 + 2.0 * uf(&mut rng);
            let z1 = 0.2 + 2.0 * uf(&mut rng);
            let z0 = if i % 2 == 0 {
                0.0
            } else {
                0.5 * z1 * uf(&mut rng)
            };
            let ph = if i % 4 < 2 {
                360.0
            } else {
                60.0 + 300.0 * uf(&mut rng)
            };
            let p = Paraboloid::new(t, i % 3 == 0, r, z0, z1, ph).unwrap();
            check_reintersect(
                &p,
                &mut rng,
                300,
                Leaving::Outward(if i % 3 == 0 { -1.0 } else { 1.0 }),
            );
            let k = z1 as f64 / (r as f64 * r as f64);
            check_reference(
                &p,
                &t,
                &mut rng,
                500,
                &implicit(k),
                &clip(z0 as f64, z1 as f64, ph as f64),
            );
        }
    }

    #[test]
    fn misses_and_orientation() {
        let p = Paraboloid::new(Transform::identity(), false, 1.0, 0.25, 1.0, 90.0).unwrap();
        let x = Vector3f::new(1.0, 0.0, 0.0);
        // Below z_min, above z_max, outside the sweep.
        assert!(!p.intersect_p(&Ray::new(Point3f::new(-5.0, 0.1, 0.1), x), Float::INFINITY));
        assert!(!p.intersect_p(&Ray::new(Point3f::new(-5.0, 0.1, 1.5), x), Float::INFINITY));
        assert!(!p.intersect_p(&Ray::new(Point3f::new(-5.0, -0.1, 0.5), x), Float::INFINITY));
        let h = p
            .intersect(&Ray::new(Point3f::new(-5.0, 0.1, 0.5), x), Float::INFINITY)
            .unwrap();
        assert!((h.intr.p().x - (0.5f32 - 0.01).sqrt()).abs() < 1e-4);
        assert!(h.intr.n.x > 0.0 && h.intr.n.z < 0.0);
        let flip = Transform::scale(1.0, 1.0, -1.0);
        let ray = Ray::new(Point3f::new(5.0, 0.0, -0.5), Vector3f::new(-1.0, 0.0, 0.0));
        let n = Paraboloid::new(flip, false, 1.0, 0.0, 1.0, 360.0)
            .unwrap()
            .intersect(&ray, Float::INFINITY)
            .unwrap()
            .intr
            .n;
        assert!(n.x < -0.5);
        let n = Paraboloid::new(flip, true, 1.0, 0.0, 1.0, 360.0)
            .unwrap()
            .intersect(&ray, Float::INFINITY)
            .unwrap()
            .intr
            .n;
        assert!(n.x > 0.5);
    }

    #[test]
    fn area_and_sampling() {
        let mut rng = Rng::with_sequence(42);
        for (i, &(r, z0, z1, ph)) in [
            (1.0, 0.0, 1.0, 360.0),
            (0.5, 0.3, 2.0, 360.0),
            (1.5, 0.0, 0.5, 120.0),
        ]
        .iter()
        .enumerate()
        {
            let t = rigid(&mut rng);
            let p = Paraboloid::new(t, i == 1, r, z0, z1, ph).unwrap();
            check_area_sampling(&p, &mut rng, 3000);
            // From inside the convex solid every ray meets the surface once
            // at most.
            check_solid_angle(
                &p,
                t.apply_point(Point3f::new(0.0, 0.0, 0.5 * (z0 + z1))),
                &mut rng,
                20000,
            );
        }
    }
}
