//! The facts of pbrt-v4's `vecmath_test.cpp` and `transform_test.cpp`,
//! carried over with the same inputs and expectations.

use rpbrt_geometry::sampling_for_tests::*;
use rpbrt_geometry::*;

fn rng(seed: u64) -> impl FnMut() -> Float {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        ((s >> 40) as Float) / (1u64 << 24) as Float
    }
}

#[test]
fn vector2_basics() {
    let vf = Vector2f::new(-1.0, 10.0);
    assert_eq!(vf, Vector2f::from(Vector2i::new(-1, 10)));
    assert_ne!(vf, Vector2f::new(-1.0, 100.0));
    assert_eq!(Vector2f::new(-2.0, 20.0), vf + vf);
    assert_eq!(Vector2f::new(0.0, 0.0), vf - vf);
    assert_eq!(Vector2f::new(-2.0, 20.0), vf * 2.0);
    assert_eq!(Vector2f::new(-2.0, 20.0), 2.0 * vf);
    assert_eq!(Vector2f::new(-0.5, 5.0), vf / 2.0);
    assert_eq!(Vector2f::new(1.0, 10.0), vf.abs());
    assert_eq!(vf, Vector2f::new(-1.5, 9.9).ceil());
    assert_eq!(vf, Vector2f::new(-0.5, 10.01).floor());
    assert_eq!(
        Vector2f::new(-20.0, 10.0),
        vf.min(Vector2f::new(-20.0, 20.0))
    );
    assert_eq!(
        Vector2f::new(-1.0, 20.0),
        vf.max(Vector2f::new(-20.0, 20.0))
    );
    assert_eq!(-1.0, vf.min_component_value());
    assert_eq!(-10.0, (-vf).min_component_value());
    assert_eq!(10.0, vf.max_component_value());
    assert_eq!(1.0, (-vf).max_component_value());
    assert_eq!(1, vf.max_dimension());
    assert_eq!(0, (-vf).max_dimension());
    assert_eq!(Vector2f::new(10.0, -1.0), vf.permute([1, 0]));
    assert_eq!(Vector2f::new(10.0, 10.0), vf.permute([1, 1]));
}

#[test]
fn vector3_basics() {
    let vf = Vector3f::new(-1.0, 10.0, 2.0);
    assert_eq!(Vector3f::new(-2.0, 20.0, 4.0), vf + vf);
    assert_eq!(Vector3f::new(-0.5, 5.0, 1.0), vf / 2.0);
    assert_eq!(vf, Vector3f::new(-1.5, 9.9, 1.01).ceil());
    assert_eq!(vf, Vector3f::new(-0.5, 10.01, 2.99).floor());
    assert_eq!(
        Vector3f::new(-20.0, 10.0, 1.5),
        vf.min(Vector3f::new(-20.0, 20.0, 1.5))
    );
    assert_eq!(
        Vector3f::new(-1.0, 20.0, 2.0),
        vf.max(Vector3f::new(-20.0, 20.0, 0.0))
    );
    assert_eq!(-1.0, vf.min_component_value());
    assert_eq!(-10.0, (-vf).min_component_value());
    assert_eq!(1, vf.max_dimension());
    assert_eq!(0, (-vf).max_dimension());
    assert_eq!(0, vf.min_dimension());
    assert_eq!(1, (-vf).min_dimension());
    assert_eq!(Vector3f::new(10.0, -1.0, 2.0), vf.permute([1, 0, 2]));
    assert_eq!(Vector3f::new(2.0, -1.0, 10.0), vf.permute([2, 0, 1]));
    assert_eq!(Vector3f::new(10.0, 10.0, -1.0), vf.permute([1, 1, 0]));
}

#[test]
fn invert_bilinear_matches_pbrt() {
    let bilerp = |u: Point2f, v: &[Point2f; 4]| {
        let a = Point2f::lerp(u.y, v[0], v[2]);
        let b = Point2f::lerp(u.y, v[1], v[3]);
        Point2f::lerp(u.x, a, b)
    };
    let mut r = rng(1);
    let simple = [
        Point2f::new(0.0, 0.0),
        Point2f::new(1.0, 0.0),
        Point2f::new(0.0, 1.0),
        Point2f::new(1.0, 1.0),
    ];
    let other = [
        Point2f::new(10.0, -4.0),
        Point2f::new(10.0, -9.0),
        Point2f::new(15.0, -4.0),
        Point2f::new(15.0, -9.0),
    ];
    for v in [simple, other] {
        for _ in 0..10000 {
            let u = Point2f::new(r(), r());
            let up = bilerp(u, &v);
            assert!(u.distance(invert_bilinear(up, v)) < 1e-5);
        }
    }
}

#[test]
fn angle_between_is_precise() {
    assert_eq!(
        0.0,
        Vector3f::new(1.0, 0.0, 0.0).angle_between(Vector3f::new(1.0, 0.0, 0.0))
    );
    assert!(
        (Vector3f::new(0.0, 0.0, 1.0).angle_between(Vector3f::new(0.0, 0.0, -1.0)) - PI).abs()
            < 1e-6
    );
    let x = Vector3f::new(1.0, -3.0, 10.0).normalize();
    assert_eq!(0.0, x.angle_between(x));
    assert!((x.angle_between(-x) - PI).abs() < 3e-7);
    for opposite in [false, true] {
        let mut r = rng(if opposite { 10_000_000 } else { 7 });
        for _ in 0..100_000 {
            let mut a =
                Vector3f::new(-1.0 + 2.0 * r(), -1.0 + 2.0 * r(), -1.0 + 2.0 * r()).normalize();
            let b = Vector3f::new(-1.0 + 2.0 * r(), -1.0 + 2.0 * r(), -1.0 + 2.0 * r()).normalize();
            if opposite {
                a = Vector3f::new(a.x.copysign(-b.x), a.y.copysign(-b.y), a.z.copysign(-b.z));
            }
            let (ad, bd) = (
                [a.x as f64, a.y as f64, a.z as f64],
                [b.x as f64, b.y as f64, b.z as f64],
            );
            let la = (ad[0] * ad[0] + ad[1] * ad[1] + ad[2] * ad[2]).sqrt();
            let lb = (bd[0] * bd[0] + bd[1] * bd[1] + bd[2] * bd[2]).sqrt();
            let d = (ad[0] * bd[0] + ad[1] * bd[1] + ad[2] * bd[2]) / (la * lb);
            let precise = d.clamp(-1.0, 1.0).acos();
            let err = ((precise - a.angle_between(b) as f64) / precise).abs();
            assert!(err < 5e-6, "{a:?} {b:?} {err}");
        }
    }
    let a = Vector3f::new(1.0, 1.0, 1.0).normalize();
    let b = Vector3f::new(-1.0, -1.0001, -1.0).normalize();
    let (ad, bd) = ([1.0f64, 1.0, 1.0], [-1.0f64, -1.0001, -1.0]);
    let n = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let precise = ((ad[0] * bd[0] + ad[1] * bd[1] + ad[2] * bd[2]) / (n(ad) * n(bd)))
        .clamp(-1.0, 1.0)
        .acos();
    assert!(
        (a.angle_between(b) as f64 - precise).abs() < 1e-6,
        "{} {}",
        a.angle_between(b),
        precise
    );
}

#[test]
fn coordinate_system_matches_duff() {
    let error = |a: Vector3f, b: Vector3f, c: Vector3f| {
        let sq = |x: Float| (x as f64) * (x as f64);
        (sq(a.length() - 1.0)
            + sq(b.length() - 1.0)
            + sq(c.length() - 1.0)
            + sq(dot(a, b))
            + sq(dot(b, c))
            + sq(dot(c, a)))
            / 6.0
    };
    for v in [
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(-1.0, 0.0, 0.0),
        Vector3f::new(0.0, 1.0, 0.0),
        Vector3f::new(0.0, -1.0, 0.0),
        Vector3f::new(0.0, 0.0, 1.0),
        Vector3f::new(0.0, 0.0, -1.0),
    ] {
        let (a, b) = v.coordinate_system();
        for c in 0..3 {
            if v[c] != 0.0 {
                assert_eq!(0.0, a[c]);
                assert_eq!(0.0, b[c]);
            }
        }
    }
    for v in [
        Vector3f::new(0.00038527316, 0.00038460016, -0.99999988079),
        Vector3f::new(-0.00019813581, -0.00008946839, -0.99999988079),
    ] {
        let (a, b) = v.coordinate_system();
        assert!(error(v, a, b) < 1e-10);
    }
    let mut r = rng(3);
    for _ in 0..1000 {
        let v = uniform_sphere(Point2f::new(r(), r()));
        let (a, b) = v.coordinate_system();
        assert!(error(v, a, b) < 1e-10);
    }
}

#[test]
fn bounds_iteration_and_distance() {
    let b = Bounds2i::new(Point2i::new(0, 1), Point2i::new(2, 3));
    let e: Vec<Point2i> = vec![
        Point2i::new(0, 1),
        Point2i::new(1, 1),
        Point2i::new(0, 2),
        Point2i::new(1, 2),
    ];
    assert_eq!(b.iter().collect::<Vec<_>>(), e);
    assert_eq!(
        Bounds2i::new(Point2i::new(0, 0), Point2i::new(0, 10))
            .iter()
            .count(),
        0
    );
    assert_eq!(
        Bounds2i::new(Point2i::new(0, 0), Point2i::new(4, 0))
            .iter()
            .count(),
        0
    );
    assert_eq!(Bounds2i::default().iter().count(), 0);

    let b = Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(1.0, 1.0, 1.0));
    for p in [
        Point3f::new(0.5, 0.5, 0.5),
        Point3f::new(0.0, 1.0, 1.0),
        Point3f::new(0.25, 0.8, 1.0),
        Point3f::new(0.0, 0.25, 0.8),
        Point3f::new(0.7, 0.0, 0.8),
    ] {
        assert_eq!(0.0, b.distance(p));
    }
    assert_eq!(5.0, b.distance(Point3f::new(6.0, 1.0, 1.0)));
    assert_eq!(10.0, b.distance(Point3f::new(0.0, -10.0, 1.0)));
    assert_eq!(2.0, b.distance(Point3f::new(0.5, 0.5, 3.0)));
    assert_eq!(3.0, b.distance(Point3f::new(0.5, 0.5, -3.0)));
    assert_eq!(2.0, b.distance(Point3f::new(0.5, 3.0, 0.5)));
    assert_eq!(3.0, b.distance(Point3f::new(0.5, -3.0, 0.5)));
    assert_eq!(2.0, b.distance(Point3f::new(3.0, 0.5, 0.5)));
    assert_eq!(3.0, b.distance(Point3f::new(-3.0, 0.5, 0.5)));
    assert_eq!(
        (3 * 3 + 7 * 7 + 10 * 10) as Float,
        b.distance_squared(Point3f::new(4.0, 8.0, -10.0))
    );
    assert_eq!(
        (6 * 6 + 10 * 10 + 7 * 7) as Float,
        b.distance_squared(Point3f::new(-6.0, -10.0, 8.0))
    );
    let b = Bounds3f::new(Point3f::new(-1.0, -3.0, 5.0), Point3f::new(2.0, -2.0, 18.0));
    assert_eq!(0.0, b.distance(Point3f::new(-0.99, -2.0, 5.0)));
    assert_eq!(
        (2 * 2 + 6 * 6 + 4 * 4) as Float,
        b.distance_squared(Point3f::new(-3.0, -9.0, 22.0))
    );
}

#[test]
fn bounds_union() {
    let a = Bounds2f::new(Point2f::new(-10.0, -10.0), Point2f::new(0.0, 20.0));
    let b = Bounds2f::default();
    assert_eq!(a, a.union(&b));
    assert_eq!(b, b.union(&b));
    let d = Bounds2f::new(Point2f::new(-15.0, 10.0), Point2f::new(-15.0, 10.0));
    assert_eq!(
        Bounds2f::new(Point2f::new(-15.0, -10.0), Point2f::new(0.0, 20.0)),
        a.union(&d)
    );
    let a = Bounds3f::new(
        Point3f::new(-10.0, -10.0, 5.0),
        Point3f::new(0.0, 20.0, 10.0),
    );
    let b = Bounds3f::default();
    assert_eq!(a, a.union(&b));
    assert_eq!(b, b.union(&b));
    let d = Bounds3f::from_point(Point3f::new(-15.0, 10.0, 30.0));
    assert_eq!(
        Bounds3f::new(
            Point3f::new(-15.0, -10.0, 5.0),
            Point3f::new(0.0, 20.0, 30.0)
        ),
        a.union(&d)
    );
}

#[test]
fn equal_area_randoms_and_edges() {
    let mut r = rng(5);
    for _ in 0..100 {
        let v = uniform_sphere(Point2f::new(r(), r()));
        let c = equal_area_sphere_to_square(v);
        let vp = equal_area_square_to_sphere(c);
        assert!(vp.length() > 0.9999 && vp.length() < 1.0001);
        assert!(dot(v, vp) > 0.9999);
    }
    let check = |a: Point2f, b: Point2f| {
        let av = equal_area_square_to_sphere(a);
        let bv = equal_area_square_to_sphere(wrap_equal_area_square_f(b));
        assert!(dot(av, bv) > 0.99, "{a:?} {b:?}");
    };
    check(Point2f::new(0.25, 0.01), Point2f::new(0.25, -0.01));
    check(Point2f::new(0.89, 0.01), Point2f::new(0.89, -0.01));
    check(Point2f::new(0.25, 0.99), Point2f::new(0.25, 1.01));
    check(Point2f::new(0.89, 0.99), Point2f::new(0.89, 1.01));
    check(Point2f::new(0.01, 0.66), Point2f::new(-0.01, 0.66));
    check(Point2f::new(0.01, 0.15), Point2f::new(-0.01, 0.15));
    check(Point2f::new(0.99, 0.66), Point2f::new(1.01, 0.66));
    check(Point2f::new(0.99, 0.15), Point2f::new(1.01, 0.15));
    check(Point2f::new(0.01, 0.01), Point2f::new(-0.01, -0.01));
    check(Point2f::new(0.99, 0.01), Point2f::new(1.01, -0.01));
    check(Point2f::new(0.01, 0.99), Point2f::new(-0.01, 1.01));
    check(Point2f::new(0.99, 0.99), Point2f::new(1.01, 1.01));
}

#[test]
fn direction_cone_union_basics() {
    let c = DirectionCone::union(
        &DirectionCone::new(Vector3f::new(0.0, 0.0, 1.0), (PI / 2.0).cos()),
        &DirectionCone::new(Vector3f::new(0.1, 0.1, 1.0), 0.1f32.cos()),
    );
    assert_eq!(c.w, Vector3f::new(0.0, 0.0, 1.0));
    assert_eq!(c.cos_theta, (PI / 2.0).cos());
    let c = DirectionCone::union(
        &DirectionCone::new(Vector3f::new(0.1, 0.1, 1.0), 0.1f32.cos()),
        &DirectionCone::new(Vector3f::new(0.0, 0.0, 1.0), (PI / 2.0).cos()),
    );
    assert_eq!(c.w, Vector3f::new(0.0, 0.0, 1.0));
    let w = Vector3f::new(1.0, 0.5, -0.25);
    let c = DirectionCone::union(
        &DirectionCone::new(w, 0.12f32.cos()),
        &DirectionCone::new(w, 0.03f32.cos()),
    );
    assert!((c.w - w.normalize()).length() < 1e-6);
    assert!((c.cos_theta - 0.12f32.cos()).abs() < 1e-6);
    let c = DirectionCone::union(
        &DirectionCone::new(w, 0.1f32.cos()),
        &DirectionCone::new(w, 0.2f32.cos()),
    );
    assert!((c.cos_theta - 0.2f32.cos()).abs() < 1e-6);
    let c = DirectionCone::union(
        &DirectionCone::new(Vector3f::new(-1.0, -1.0, -1.0), (PI / 2.0).cos()),
        &DirectionCone::new(Vector3f::new(1.0, 1.0, 1.0), (PI / 2.0).cos()),
    );
    assert_eq!(c.cos_theta, -1.0);
    let c = DirectionCone::union(
        &DirectionCone::new(Vector3f::new(-1.0, -1.0, -1.0), (1.01 * PI / 2.0).cos()),
        &DirectionCone::new(Vector3f::new(1.001, 1.0, 1.0), (1.01 * PI / 2.0).cos()),
    );
    assert_eq!(c.cos_theta, -1.0);
    let c = DirectionCone::union(
        &DirectionCone::new(Vector3f::new(1.0, 0.0, 0.0), 1e-3f32.cos()),
        &DirectionCone::new(Vector3f::new(0.0, 1.0, 0.0), 1e-3f32.cos()),
    );
    assert!((dot(c.w, Vector3f::new(1.0, 1.0, 0.0).normalize()) - 1.0).abs() < 1e-5);
    assert!((((PI / 2.0 + 2e-3) / 2.0).cos() - c.cos_theta).abs() < 1e-3);
}

#[test]
fn direction_cone_bounds_boxes_and_closest_vector() {
    let b = Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(1.0, 1.0, 1.0));
    let c = DirectionCone::bound_subtended_directions(&b, Point3f::new(0.1, 0.2, 0.3));
    assert_eq!(c.cos_theta, -1.0);
    let c = DirectionCone::bound_subtended_directions(&b, Point3f::new(-0.5, 0.5, 0.5));
    let theta = c.cos_theta.acos() as f64;
    let precise = ((0.5f64 * 0.5 + 0.5 * 0.5).sqrt() / 0.5).atan();
    assert!(
        theta >= 1.0001 * precise && theta < 1.1 * precise,
        "{theta} {precise}"
    );
    let mut r = rng(512);
    for _ in 0..300 {
        let l = |r: &mut dyn FnMut() -> Float| {
            Point3f::new(-1.0 + 2.0 * r(), -1.0 + 2.0 * r(), -1.0 + 2.0 * r())
        };
        let b = Bounds3f::new(l(&mut r), l(&mut r));
        let p = Point3f::new(-4.0 + 8.0 * r(), -4.0 + 8.0 * r(), -4.0 + 8.0 * r());
        let c = DirectionCone::bound_subtended_directions(&b, p);
        if b.inside(p) {
            assert_eq!(c.cos_theta, -1.0);
            continue;
        }
        for _ in 0..300 {
            let w = uniform_sphere(Point2f::new(r(), r()));
            if b.intersect_p(p, w, Float::INFINITY).is_some() {
                assert!(c.inside(w));
            }
        }
    }
    let mut r = rng(9);
    for _ in 0..100 {
        let dc = DirectionCone::new(uniform_sphere(Point2f::new(r(), r())), -1.0 + 2.0 * r());
        for _ in 0..100 {
            let w = uniform_sphere(Point2f::new(r(), r()));
            let closest = dc.closest_vector_in_cone(w);
            if dc.inside(w) {
                assert!(dot(closest, w) > 0.999);
            } else {
                let sin_theta = safe_sqrt(1.0 - dc.cos_theta * dc.cos_theta);
                let f = Frame::from_z(dc.w);
                let mut best = -2.0;
                let mut wbest = Vector3f::default();
                for k in 0..1000 {
                    let phi = (k as Float + 0.5) / 1000.0 * 2.0 * PI;
                    let wc = f.from_local(spherical_direction(sin_theta, dc.cos_theta, phi));
                    if dot(wc, w) > best {
                        best = dot(wc, w);
                        wbest = wc;
                    }
                }
                assert!(dot(wbest, closest) > 0.999);
            }
        }
    }
}

#[test]
fn interval_points_and_octahedral_vectors() {
    let p = Point3fi::from(Point3f::new(1.0, 2.0, 3.0));
    let q = Point3fi::from(Point3f::new(6.0, 9.0, 1.0));
    let v = Vector3fi::from(Vector3f::new(4.0, 5.0, 6.0));
    let p2 = (p + v) - v;
    assert_eq!(p2.midpoint(), p.midpoint());
    assert!(v.dot(v).contains(77.0));
    assert!(p.distance_squared(q).contains(25.0 + 49.0 + 4.0));
    let c = v.cross(v);
    assert!(c.x.contains(0.0) && c.y.contains(0.0) && c.z.contains(0.0));
    for i in 0..65535u32 {
        let u = Point2f::new(
            (i as Float + 0.5) / 65535.0,
            (i.reverse_bits() as f64 / 4294967296.0) as Float,
        );
        let v = uniform_sphere(u);
        let v2 = spherical::OctahedralVector::new(v).to_vector();
        assert!(v2.length() > 0.999 && v2.length() < 1.001);
        assert!((1.0 - dot(v2, v)).abs() < 0.001);
    }
}

#[test]
fn transform_facts() {
    // pbrt-v4 transform_test: RotateFromTo maps from to to, and Rotate's
    // inverse is its transpose.
    let mut r = rng(11);
    for _ in 0..100 {
        let from = uniform_sphere(Point2f::new(r(), r()));
        let to = uniform_sphere(Point2f::new(r(), r()));
        let xf = Transform::rotate_from_to(from, to);
        assert!((xf.apply_vector(from) - to).length() < 1e-4);
    }
    let t = Transform::translate(Vector3f::new(1.0, 2.0, 3.0)) * Transform::scale(2.0, 3.0, 4.0);
    let p = t.apply_point(Point3f::new(1.0, 1.0, 1.0));
    assert_eq!(p, Point3f::new(3.0, 5.0, 7.0));
    assert_eq!(t.apply_inverse_point(p), Point3f::new(1.0, 1.0, 1.0));
}
