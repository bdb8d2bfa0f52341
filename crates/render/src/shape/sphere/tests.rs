use super::testing::*;
use super::*;
use crate::rng::Rng;

fn implicit(r: f64) -> impl Fn([f64; 3]) -> f64 {
    move |p| p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r
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
    assert!(Sphere::new(t, false, 0.0, -1.0, 1.0, 360.0).is_err());
    assert!(Sphere::new(t, false, -1.0, -1.0, 1.0, 360.0).is_err());
    assert!(Sphere::new(t, false, Float::NAN, -1.0, 1.0, 360.0).is_err());
    assert!(Sphere::new(t, false, 1.0, 2.0, 3.0, 360.0).is_err());
    assert!(Sphere::new(t, false, 1.0, 0.5, 0.5, 360.0).is_err());
    assert!(Sphere::new(t, false, 1.0, -1.0, 1.0, 0.0).is_err());
    assert!(Sphere::new(t, false, 1.0, -1.0, Float::INFINITY, 360.0).is_err());
    let s = Sphere::new(t, false, 1.0, 3.0, -3.0, 720.0).unwrap();
    assert_eq!((s.z_min, s.z_max), (-1.0, 1.0));
    assert!((s.phi_max - 2.0 * PI).abs() < 1e-6);
}

#[test]
fn reintersect_full_and_partial() {
    let mut rng = Rng::with_sequence(1);
    for i in 0..40 {
        let t = rigid(&mut rng);
        let r = 0.2 + 2.0 * uf(&mut rng);
        let (z0, z1, ph) = if i % 2 == 0 {
            (-r, r, 360.0)
        } else {
            (
                -r + 2.0 * r * uf(&mut rng) * 0.5,
                r - r * uf(&mut rng) * 0.5,
                60.0 + 300.0 * uf(&mut rng),
            )
        };
        let s = Sphere::new(t, i % 3 == 0, r, z0, z1, ph).unwrap();
        check_reintersect(
            &s,
            &mut rng,
            300,
            Leaving::Outward(if i % 3 == 0 { -1.0 } else { 1.0 }),
        );
        check_reference(
            &s,
            &t,
            &mut rng,
            500,
            &implicit(r as f64),
            &clip(s.z_min as f64, s.z_max as f64, ph as f64),
        );
    }
}

#[test]
fn tiny_and_distant_spheres_are_hit() {
    // pbrt-v4's accurate discriminant: rays from far away still hit.
    let s = Sphere::new(
        Transform::translate(Vector3f::new(0.0, 0.0, 1e3)),
        false,
        5e-2,
        -1.0,
        1.0,
        360.0,
    )
    .unwrap();
    let h = s
        .intersect(
            &Ray::new(Point3f::default(), Vector3f::new(0.0, 0.0, 1.0)),
            Float::INFINITY,
        )
        .unwrap();
    assert!((h.t_hit - (1e3 - 5e-2)).abs() < 1e-3);
}

#[test]
fn misses_outside_clipping() {
    let s = Sphere::new(Transform::identity(), false, 1.0, -0.5, 0.5, 90.0).unwrap();
    // Through the polar cap, cut away.
    assert!(!s.intersect_p(
        &Ray::new(Point3f::new(0.1, 0.1, 5.0), Vector3f::new(0.0, 0.0, -1.0)),
        Float::INFINITY
    ));
    // Outside the φ sweep (third quadrant).
    // Outside the φ sweep: enters at φ = 210°, leaves at φ = 330°.
    assert!(!s.intersect_p(
        &Ray::new(Point3f::new(-5.0, -0.5, 0.0), Vector3f::new(1.0, 0.0, 0.0)),
        Float::INFINITY
    ));
    // Inside the sweep it hits; the second root is used when the first is cut.
    let h = s
        .intersect(
            &Ray::new(Point3f::new(-5.0, 0.5, 0.0), Vector3f::new(1.0, 0.0, 0.0)),
            Float::INFINITY,
        )
        .unwrap();
    assert!((h.intr.p().x - 0.75f32.sqrt()).abs() < 1e-4);
    // t_max before the hit.
    assert!(!s.intersect_p(
        &Ray::new(Point3f::new(5.0, 0.5, 0.0), Vector3f::new(-1.0, 0.0, 0.0)),
        1.0
    ));
}

#[test]
fn orientation_flips_normals() {
    let ray = Ray::new(Point3f::new(0.0, 0.0, 5.0), Vector3f::new(0.0, 0.0, -1.0));
    let n = |s: Sphere| s.intersect(&ray, Float::INFINITY).unwrap().intr.n.z;
    let t = Transform::identity();
    assert!(n(Sphere::new(t, false, 1.0, -1.0, 1.0, 360.0).unwrap()) > 0.99);
    assert!(n(Sphere::new(t, true, 1.0, -1.0, 1.0, 360.0).unwrap()) < -0.99);
    let flip = Transform::scale(1.0, 1.0, -1.0);
    assert!(n(Sphere::new(flip, false, 1.0, -1.0, 1.0, 360.0).unwrap()) < -0.99);
    assert!(n(Sphere::new(flip, true, 1.0, -1.0, 1.0, 360.0).unwrap()) > 0.99);
}

#[test]
fn area_and_area_sampling() {
    let mut rng = Rng::with_sequence(2);
    for (i, &(z0, z1, ph)) in [(-1.0, 1.0, 360.0), (-0.3, 0.8, 360.0), (-1.0, 0.2, 125.0)]
        .iter()
        .enumerate()
    {
        let t = rigid(&mut rng);
        let s = Sphere::new(t, i == 1, 1.5, 1.5 * z0, 1.5 * z1, ph).unwrap();
        check_area_sampling(&s, &mut rng, 3000);
    }
    let s = Sphere::new(
        Transform::scale(1.0, 1.0, -1.0),
        true,
        1.0,
        -1.0,
        1.0,
        360.0,
    )
    .unwrap();
    check_area_sampling(&s, &mut rng, 1000);
}

#[test]
fn solid_angle_sampling() {
    let mut rng = Rng::with_sequence(3);
    let t = rigid(&mut rng);
    let c = t.apply_point(Point3f::default());
    // Outside: cone sampling, near and far (the small-angle branch).
    let s = Sphere::new(t, false, 1.0, -1.0, 1.0, 360.0).unwrap();
    check_solid_angle(&s, c + Vector3f::new(0.3, 2.0, -1.0), &mut rng, 20000);
    check_solid_angle(&s, c + Vector3f::new(30.0, 20.0, -10.0), &mut rng, 20000);
    // Inside: area sampling.
    check_solid_angle(&s, c + Vector3f::new(0.3, 0.2, -0.1), &mut rng, 20000);
    // A partial sphere seen from its centre: area sampling.
    let s = Sphere::new(t, true, 1.0, -0.5, 0.9, 200.0).unwrap();
    check_solid_angle(&s, c, &mut rng, 20000);
    // Uniformly scaled: cone sampling with the scaled radius.
    let t2 = t * Transform::scale(2.0, 2.0, 2.0);
    let s = Sphere::new(t2, false, 1.0, -1.0, 1.0, 360.0).unwrap();
    check_solid_angle(&s, c + Vector3f::new(3.0, 2.0, -1.0), &mut rng, 20000);
}

#[test]
fn bounds_and_derivatives() {
    let s = Sphere::new(
        Transform::translate(Vector3f::new(1.0, 2.0, 3.0)),
        false,
        2.0,
        -1.0,
        2.0,
        360.0,
    )
    .unwrap();
    let b = s.bounds();
    assert_eq!(b.p_min, Point3f::new(-1.0, 0.0, 2.0));
    assert_eq!(b.p_max, Point3f::new(3.0, 4.0, 5.0));
    assert_eq!(s.normal_bounds().cos_theta, -1.0);
    // dn/du on a sphere is dp/du / r.
    let h = s
        .intersect(
            &Ray::new(Point3f::new(5.0, 2.5, 3.2), Vector3f::new(-1.0, 0.0, 0.0)),
            Float::INFINITY,
        )
        .unwrap();
    let i = h.intr;
    let want = i.dpdu / 2.0;
    assert!((Vector3f::from(i.dndu) - want).length() < 1e-4 * want.length().max(1.0));
    let want = i.dpdv / 2.0;
    assert!((Vector3f::from(i.dndv) - want).length() < 1e-4 * want.length().max(1.0));
}
