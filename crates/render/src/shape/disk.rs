//! Disks (book section 6.4; pbrt-v4 `shapes.h` `Disk`): the annulus
//! `inner_radius ≤ ρ ≤ radius` in the plane z = `height`, swept to `φ_max`.

use super::sphere::{
    object_ray, object_wo, phi_max_radians, positive_atan2, render_normal, require_finite,
    transforms,
};
use super::{area_sample_to_solid_angle, pdf_by_intersection, ShapeError, ShapeIntersection};
use super::{ShapeMethods, ShapeSample, ShapeSampleContext};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

/// A disk (or annulus) perpendicular to the object-space z axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    /// Object-to-render transformation (its inverse, which it holds too,
    /// is the render-to-object one: one transformation, not two, per shape).
    pub render_from_object: Transform,
    /// Whether the normal points toward −z.
    pub reverse_orientation: bool,
    /// Whether `render_from_object` changes handedness.
    pub transform_swaps_handedness: bool,
    height: Float,
    radius: Float,
    inner_radius: Float,
    phi_max: Float,
}

impl Disk {
    /// A disk with pbrt's parameters, `phi_max` in degrees clamped to
    /// [0, 360]. Fails for non-finite values, a non-positive radius, a
    /// negative inner radius or one not below the radius, a zero sweep or
    /// a singular transformation.
    pub fn new(
        render_from_object: Transform,
        reverse_orientation: bool,
        height: Float,
        radius: Float,
        inner_radius: Float,
        phi_max: Float,
    ) -> Result<Self, ShapeError> {
        const S: &str = "disk";
        require_finite(S, "height", height)?;
        require_finite(S, "radius", radius)?;
        require_finite(S, "innerradius", inner_radius)?;
        if radius <= 0.0 {
            return Err(ShapeError(format!(
                "disk: \"radius\" must be positive, got {radius}"
            )));
        }
        if inner_radius < 0.0 || inner_radius >= radius {
            return Err(ShapeError(format!(
                "disk: \"innerradius\" must be in [0, radius = {radius}), got {inner_radius}"
            )));
        }
        let phi_max = phi_max_radians(S, phi_max)?;
        let (render_from_object, _, swaps) = transforms(S, render_from_object)?;
        Ok(Disk {
            render_from_object,
            reverse_orientation,
            transform_swaps_handedness: swaps,
            height,
            radius,
            inner_radius,
            phi_max,
        })
    }

    fn flip(&self) -> bool {
        self.reverse_orientation ^ self.transform_swaps_handedness
    }

    fn basic_intersect(&self, r: &Ray, t_max: Float) -> Option<(Float, Point3f, Float)> {
        let (oi, di) = object_ray(&self.render_from_object.inverse(), r);
        let (o, d) = (oi.midpoint(), di.midpoint());
        // Rays parallel to the plane never hit it.
        if d.z == 0.0 {
            return None;
        }
        let t = (self.height - o.z) / d.z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = o + d * t;
        let dist2 = p.x * p.x + p.y * p.y;
        if dist2 > self.radius * self.radius || dist2 < self.inner_radius * self.inner_radius {
            return None;
        }
        let phi = positive_atan2(p.y, p.x);
        if phi > self.phi_max {
            return None;
        }
        Some((t, p, phi))
    }

    fn interaction(
        &self,
        mut p: Point3f,
        phi: Float,
        wo: Vector3f,
        time: Float,
    ) -> SurfaceInteraction {
        let r_hit = (p.x * p.x + p.y * p.y).sqrt();
        let uv = Point2f::new(
            phi / self.phi_max,
            (self.radius - r_hit) / (self.radius - self.inner_radius),
        );
        // At the very centre ∂p/∂u vanishes; use a tiny radius there so
        // the normal stays defined.
        let rr = r_hit.max(1e-5 * self.radius);
        let (c, s) = (phi.cos(), phi.sin());
        let dpdu = Vector3f::new(-self.phi_max * rr * s, self.phi_max * rr * c, 0.0);
        let dpdv = Vector3f::new(c, s, 0.0) * (self.inner_radius - self.radius);
        // The hit lies exactly in the plane: no error in any coordinate.
        p.z = self.height;
        SurfaceInteraction::new(
            Point3fi::from(p),
            uv,
            wo,
            dpdu,
            dpdv,
            Normal3f::default(),
            Normal3f::default(),
            time,
            self.flip(),
        )
        .transform(&self.render_from_object)
    }
}

impl ShapeMethods for Disk {
    fn bounds(&self) -> Bounds3f {
        let r = self.radius;
        self.render_from_object.apply_bounds(&Bounds3f::new(
            Point3f::new(-r, -r, self.height),
            Point3f::new(r, r, self.height),
        ))
    }

    /// The single direction of the disk's normal.
    fn normal_bounds(&self) -> DirectionCone {
        match render_normal(
            &self.render_from_object,
            Normal3f::new(0.0, 0.0, 1.0),
            self.flip(),
        ) {
            Some(n) => DirectionCone::from_direction(Vector3f::from(n)),
            None => DirectionCone::entire_sphere(),
        }
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

    /// Object-space area φ_max/2·(r² − r_i²), as pbrt.
    fn area(&self) -> Float {
        self.phi_max * 0.5 * (sqr(self.radius) - sqr(self.inner_radius))
    }

    /// ρ² uniform in [r_i², r²] and φ uniform in [0, φ_max]: uniform over
    /// the annulus sector (pbrt-v4 samples the whole disk instead).
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let rho = lerp(u.x, sqr(self.inner_radius), sqr(self.radius)).sqrt();
        let phi = u.y * self.phi_max;
        let p = Point3f::new(rho * phi.cos(), rho * phi.sin(), self.height);
        let n = render_normal(
            &self.render_from_object,
            Normal3f::new(0.0, 0.0, 1.0),
            self.flip(),
        )?;
        Some(ShapeSample {
            pi: self.render_from_object.apply_point_fi(Point3fi::from(p)),
            n,
            uv: Point2f::new(u.y, (self.radius - rho) / (self.radius - self.inner_radius)),
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

    fn clip(h: f64, r: f64, ri: f64, phimax_deg: f64) -> impl Fn([f64; 3]) -> bool {
        move |p| {
            let _ = h;
            let phi = p[1].atan2(p[0]).rem_euclid(2.0 * std::f64::consts::PI);
            let d2 = p[0] * p[0] + p[1] * p[1];
            d2 <= r * r && d2 >= ri * ri && phi <= phimax_deg.to_radians()
        }
    }

    #[test]
    fn degenerate_input_is_rejected() {
        let t = Transform::identity();
        assert!(Disk::new(t, false, 0.0, 0.0, 0.0, 360.0).is_err());
        assert!(Disk::new(t, false, 0.0, 1.0, 1.0, 360.0).is_err());
        assert!(Disk::new(t, false, 0.0, 1.0, -0.5, 360.0).is_err());
        assert!(Disk::new(t, false, Float::NAN, 1.0, 0.0, 360.0).is_err());
        assert!(Disk::new(t, false, 0.0, 1.0, 0.0, 0.0).is_err());
        assert!(Disk::new(t, false, 0.0, 1.0, 0.5, 90.0).is_ok());
    }

    #[test]
    fn reintersect_and_reference() {
        let mut rng = Rng::with_sequence(21);
        for i in 0..40 {
            let t = rigid(&mut rng);
            let h = 2.0 * uf(&mut rng) - 1.0;
            let r = 0.2 + 2.0 * uf(&mut rng);
            let ri = if i % 2 == 0 {
                0.0
            } else {
                0.8 * r * uf(&mut rng)
            };
            let ph = if i % 4 < 2 {
                360.0
            } else {
                60.0 + 300.0 * uf(&mut rng)
            };
            let d = Disk::new(t, i % 3 == 0, h, r, ri, ph).unwrap();
            check_reintersect(&d, &mut rng, 300, Leaving::Never);
            let (hf, rf, rif) = (h as f64, r as f64, ri as f64);
            check_reference(
                &d,
                &t,
                &mut rng,
                500,
                &move |p| p[2] - hf,
                &clip(hf, rf, rif, ph as f64),
            );
        }
    }

    #[test]
    fn misses_and_normals() {
        let d = Disk::new(Transform::identity(), false, 1.0, 1.0, 0.5, 90.0).unwrap();
        let down = Vector3f::new(0.0, 0.0, -1.0);
        // In the hole, outside the radius, outside the sweep, parallel.
        assert!(!d.intersect_p(
            &Ray::new(Point3f::new(0.2, 0.2, 5.0), down),
            Float::INFINITY
        ));
        assert!(!d.intersect_p(
            &Ray::new(Point3f::new(0.9, 0.9, 5.0), down),
            Float::INFINITY
        ));
        assert!(!d.intersect_p(
            &Ray::new(Point3f::new(-0.6, 0.3, 5.0), down),
            Float::INFINITY
        ));
        assert!(!d.intersect_p(
            &Ray::new(Point3f::new(0.6, 0.3, 1.0), Vector3f::new(1.0, 0.0, 0.0)),
            Float::INFINITY
        ));
        let h = d
            .intersect(
                &Ray::new(Point3f::new(0.6, 0.3, 5.0), down),
                Float::INFINITY,
            )
            .unwrap();
        assert_eq!(h.intr.p().z, 1.0);
        assert!((h.t_hit - 4.0).abs() < 1e-6);
        assert!(h.intr.n.z > 0.99);
        assert!(!d.intersect_p(&Ray::new(Point3f::new(0.6, 0.3, 5.0), down), 3.9));
        let t = Transform::identity();
        let flip = Transform::scale(1.0, 1.0, -1.0);
        let nz = |d: Disk| {
            let n = d
                .intersect(
                    &Ray::new(Point3f::new(0.6, 0.3, 5.0), down),
                    Float::INFINITY,
                )
                .unwrap()
                .intr
                .n;
            assert!((Vector3f::from(n) - d.normal_bounds().w).length() < 1e-6);
            n.z
        };
        assert!(nz(Disk::new(t, true, 0.0, 1.0, 0.0, 360.0).unwrap()) < -0.99);
        // Scale(1, 1, −1) maps the object +z normal to −z; the handedness
        // swap then flips it back to +z.
        assert!(nz(Disk::new(flip, false, 0.0, 1.0, 0.0, 360.0).unwrap()) > 0.99);
        assert!(nz(Disk::new(flip, true, 0.0, 1.0, 0.0, 360.0).unwrap()) < -0.99);
        assert!(nz(Disk::new(t, false, 0.0, 1.0, 0.0, 360.0).unwrap()) > 0.99);
    }

    #[test]
    fn area_and_sampling() {
        let mut rng = Rng::with_sequence(22);
        for (i, &(ri, ph)) in [(0.0, 360.0), (0.4, 360.0), (0.3, 120.0)]
            .iter()
            .enumerate()
        {
            let t = rigid(&mut rng);
            let d = Disk::new(t, i == 1, 0.5, 1.2, ri, ph).unwrap();
            check_area_sampling(&d, &mut rng, 3000);
            check_solid_angle(
                &d,
                t.apply_point(Point3f::new(0.3, -0.2, 1.5)),
                &mut rng,
                20000,
            );
            check_solid_angle(
                &d,
                t.apply_point(Point3f::new(3.0, 1.0, -0.5)),
                &mut rng,
                20000,
            );
        }
    }
}
