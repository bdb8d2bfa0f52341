use super::*;
use proptest::prelude::*;

fn v3() -> impl Strategy<Value = Vector3f> {
    (-100.0f32..100.0, -100.0f32..100.0, -100.0f32..100.0)
        .prop_map(|(x, y, z)| Vector3f::new(x, y, z))
}
fn p3() -> impl Strategy<Value = Point3f> {
    v3().prop_map(Point3f::from)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha, ..ProptestConfig::default() })]
    #[test]
    fn point_vector_identities(p in p3(), q in p3()) {
        let v = q - p;
        let r = p + v;
        prop_assert!((r - q).length() <= 1e-4 * (1.0 + Vector3f::from(q).length()));
    }

    #[test]
    fn normalize_is_unit(v in v3()) {
        prop_assume!(v.length() > 1e-3);
        prop_assert!((v.normalize().length() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn cross_is_perpendicular(a in v3(), b in v3()) {
        prop_assume!(a.length() > 1e-2 && b.length() > 1e-2);
        let (a, b) = (a.normalize(), b.normalize());
        let c = cross(a, b);
        prop_assert!(dot(c, a).abs() < 1e-5);
        prop_assert!(dot(c, b).abs() < 1e-5);
    }

    #[test]
    fn coordinate_system_is_orthonormal(v in v3()) {
        prop_assume!(v.length() > 1e-3);
        let v = v.normalize();
        let (a, b) = v.coordinate_system();
        prop_assert!((a.length() - 1.0).abs() < 1e-4 && (b.length() - 1.0).abs() < 1e-4);
        prop_assert!(dot(a, v).abs() < 1e-4 && dot(b, v).abs() < 1e-4 && dot(a, b).abs() < 1e-4);
    }

    #[test]
    fn angle_between_matches_acos(a in v3(), b in v3()) {
        prop_assume!(a.length() > 1e-2 && b.length() > 1e-2);
        let (a, b) = (a.normalize(), b.normalize());
        let reference = (dot(a, b) as f64).clamp(-1.0, 1.0).acos();
        prop_assert!((a.angle_between(b) as f64 - reference).abs() < 2e-3);
    }

    #[test]
    fn gram_schmidt_is_perpendicular(a in v3(), w in v3()) {
        prop_assume!(w.length() > 1e-2);
        let w = w.normalize();
        prop_assert!(dot(a.gram_schmidt(w), w).abs() < 1e-3 * (1.0 + a.length()));
    }
}

#[test]
fn angle_between_extremes() {
    let a = Vector3f::new(1.0, 0.0, 0.0);
    assert_eq!(a.angle_between(a), 0.0);
    assert!((a.angle_between(-a) - PI).abs() < 1e-6);
    let b = Vector3f::new(1.0, 1e-4, 0.0).normalize();
    assert!((a.angle_between(b) - 1e-4).abs() < 1e-8);
}

#[test]
fn component_ops() {
    let v = Vector3f::new(-1.0, 3.0, 2.0);
    assert_eq!(v.max_dimension(), 1);
    assert_eq!(v.max_component_value(), 3.0);
    assert_eq!(v.abs(), Vector3f::new(1.0, 3.0, 2.0));
    assert_eq!(v.permute([2, 0, 1]), Vector3f::new(2.0, -1.0, 3.0));
    assert_eq!(
        Point3f::new(1.5, -0.5, 2.0).floor(),
        Point3f::new(1.0, -1.0, 2.0)
    );
    let n = Normal3f::new(0.0, 0.0, 1.0);
    assert_eq!(
        n.face_forward(Vector3f::new(0.0, 0.0, -1.0)),
        Normal3f::new(0.0, 0.0, -1.0)
    );
    assert_eq!(Vector3f::new(0.0, 0.0, 0.0).try_normalize(), None);
    let p = Point2f::new(1.0, 2.0) - Point2f::new(0.5, 0.5);
    assert_eq!(p, Vector2f::new(0.5, 1.5));
    assert_eq!(Point2i::new(3, 4) - Point2i::new(1, 1), Vector2i::new(2, 3));
}
