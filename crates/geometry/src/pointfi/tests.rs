use super::*;

#[test]
fn interval_points() {
    let p =
        Point3fi::from_value_and_error(Point3f::new(1.0, 2.0, 3.0), Vector3f::new(0.1, 0.0, 0.2));
    assert_eq!(p.midpoint(), Point3f::new(1.0, 2.0, 3.0));
    let e = p.error();
    assert!(e.x >= 0.1 && e.y == 0.0 && e.z >= 0.2);
    assert!(!p.is_exact());
    let q = Point3fi::from(Point3f::new(0.0, 0.0, 0.0));
    assert!(q.is_exact());
}
