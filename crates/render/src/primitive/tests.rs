use super::*;
use crate::rng::Rng;
use crate::shape::{triangle, Sphere, TriangleMesh};
use rpbrt_geometry::tuple::*;

fn sphere_prim(xf: Transform, r: Float) -> Primitive {
    let s = Sphere::new(xf, false, r, -r, r, 360.0).unwrap();
    Primitive::Geometric(GeometricPrimitive {
        shape: Shape::Sphere(Box::new(s)),
        material: Some(0),
        area_light: None,
        medium_interface: None,
        alpha: Alpha::Opaque,
    })
}

fn random_triangles(rng: &mut Rng, n: usize, xf: &Transform) -> Vec<Primitive> {
    let mut p = Vec::new();
    for _ in 0..n * 3 {
        p.push(Point3f::new(
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
        ));
    }
    let idx: Vec<u32> = (0..(n * 3) as u32).collect();
    let (mesh, _) = TriangleMesh::new(xf, false, idx, p, vec![], vec![], vec![], vec![]).unwrap();
    triangle::triangles(&mesh)
        .into_iter()
        .map(|t| {
            Primitive::Geometric(GeometricPrimitive {
                shape: Shape::Triangle(t),
                material: Some(1),
                area_light: None,
                medium_interface: None,
                alpha: Alpha::Opaque,
            })
        })
        .collect()
}

fn random_ray(rng: &mut Rng) -> Ray {
    let o = Point3f::new(
        rng.uniform_float() * 20.0 - 10.0,
        rng.uniform_float() * 20.0 - 10.0,
        -12.0,
    );
    let target = Point3f::new(
        rng.uniform_float() * 6.0 - 3.0,
        rng.uniform_float() * 6.0 - 3.0,
        rng.uniform_float() * 6.0 - 3.0,
    );
    Ray::with_time(o, target - o, rng.uniform_float(), None)
}

#[test]
fn instances_match_direct_geometry() {
    let xf = Transform::translate(Vector3f::new(0.5, -0.3, 1.0))
        * Transform::rotate(35.0, Vector3f::new(1.0, 2.0, 0.5))
        * Transform::scale(1.2, 0.8, 1.0);
    let mut rng = Rng::new(1, 0);
    let direct = PrimitiveAggregate::new(
        random_triangles(&mut rng, 200, &xf),
        &AccelParams::default(),
    );
    let mut rng = Rng::new(1, 0);
    let inner = Arc::new(PrimitiveAggregate::new(
        random_triangles(&mut rng, 200, &Transform::identity()),
        &AccelParams::default(),
    ));
    let inst = PrimitiveAggregate::new(
        vec![Primitive::Instances(Box::new(InstanceSet::one(inner, xf)))],
        &AccelParams::default(),
    );
    let mut rng = Rng::new(2, 0);
    let mut hits = 0;
    for _ in 0..3000 {
        let r = random_ray(&mut rng);
        let a = direct.intersect(&r, Float::INFINITY);
        let b = inst.intersect(&r, Float::INFINITY);
        assert_eq!(a.is_some(), b.is_some());
        assert_eq!(
            direct.intersect_p(&r, Float::INFINITY),
            inst.intersect_p(&r, Float::INFINITY)
        );
        if let (Some(a), Some(b)) = (a, b) {
            hits += 1;
            assert!(
                (a.t_hit - b.t_hit).abs() < 1e-3 * a.t_hit.max(1.0),
                "{} {}",
                a.t_hit,
                b.t_hit
            );
            assert!((a.si.p() - b.si.p()).length() < 1e-3);
            assert!(dot(a.si.n, b.si.n) > 0.999);
            assert_eq!(b.material, Some(1));
        }
    }
    assert!(hits > 500);
}

/// A run of instances as one set gives the entries, hits and shadow
/// answers that each instance as a primitive of its own gives, bit for
/// bit: affine placements kept without their last rows, a projective one
/// turning the set's placements whole, a set built backwards and
/// reversed.
#[test]
fn instance_set_matches_separate_instances() {
    let mut rng = Rng::new(5, 0);
    let objects = [
        Arc::new(PrimitiveAggregate::new(
            random_triangles(&mut rng, 40, &Transform::identity()),
            &AccelParams::default(),
        )),
        Arc::new(PrimitiveAggregate::new(
            vec![sphere_prim(Transform::identity(), 0.8)],
            &AccelParams::default(),
        )),
    ];
    let mut placements = Vec::new();
    for k in 0..30 {
        let v = |rng: &mut Rng| rng.uniform_float() * 8.0 - 4.0;
        let xf = Transform::translate(Vector3f::new(v(&mut rng), v(&mut rng), v(&mut rng)))
            * Transform::rotate(360.0 * rng.uniform_float(), Vector3f::new(0.3, 1.0, 0.2))
            * Transform::scale(0.3, 0.25 + 0.1 * rng.uniform_float(), 0.3);
        placements.push((k % 2, xf));
    }
    let mut projective = *Transform::scale(0.3, 0.3, 0.3).matrix();
    projective.m[3] = [0.01, 0.0, 0.0, 1.0];
    let projective = match Transform::from_matrix(projective) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    for (kind, placed) in [
        ("affine", placements.clone()),
        ("projective", {
            let mut p = placements.clone();
            p.insert(17, (0, projective));
            p
        }),
    ] {
        let mut set = InstanceSet::new();
        let ids = objects.clone().map(|o| set.add_object(o));
        for &(k, xf) in &placed {
            set.push(ids[k], xf);
        }
        assert_eq!(set.render_from_object.bytes_each() == 48, kind == "affine");
        for (i, &(_, xf)) in placed.iter().enumerate() {
            // Affine instances keep their inverses bit for bit (the
            // forward matrices recomputed); the projective one both.
            let got = set.render_from_object.get(i);
            assert_eq!(got.inverse_matrix(), xf.inverse_matrix(), "{kind} {i}");
            assert!(
                kind == "affine" || i != 17 || got.same_bits(&xf),
                "{kind} {i}"
            );
        }
        let mut backwards = InstanceSet::new();
        let ids = objects.clone().map(|o| backwards.add_object(o));
        for &(k, xf) in placed.iter().rev() {
            backwards.push(ids[k], xf);
        }
        backwards.reverse();
        let one_set = PrimitiveAggregate::new(
            vec![Primitive::Instances(Box::new(set))],
            &AccelParams::default(),
        );
        let reversed = PrimitiveAggregate::new(
            vec![Primitive::Instances(Box::new(backwards))],
            &AccelParams::default(),
        );
        let separate = PrimitiveAggregate::new(
            placed
                .iter()
                .map(|&(k, xf)| {
                    Primitive::Instances(Box::new(InstanceSet::one(objects[k].clone(), xf)))
                })
                .collect(),
            &AccelParams::default(),
        );
        assert_eq!(one_set.entry_count(), placed.len());
        assert_eq!(one_set.bounds(), separate.bounds());
        let mut hits = 0;
        for _ in 0..2000 {
            let r = random_ray(&mut rng);
            let a = separate.intersect_record(&r, Float::INFINITY);
            for agg in [&one_set, &reversed] {
                assert_eq!(agg.intersect_record(&r, Float::INFINITY), a, "{kind}");
                assert_eq!(
                    agg.intersect_p(&r, Float::INFINITY),
                    separate.intersect_p(&r, Float::INFINITY)
                );
                let (x, y) = (
                    agg.intersect(&r, Float::INFINITY),
                    separate.intersect(&r, Float::INFINITY),
                );
                assert_eq!(x.is_some(), y.is_some());
                if let (Some(x), Some(y)) = (x, y) {
                    assert_eq!(x.t_hit.to_bits(), y.t_hit.to_bits());
                    assert_eq!(x.si.p(), y.si.p());
                    assert_eq!(x.material, y.material);
                }
            }
            hits += usize::from(a.is_some());
        }
        assert!(hits > 200, "{kind}: {hits}");
    }
}

/// An aggregate holding one sphere moving along x from −2 to 2, held
/// directly (`Moving::One`) or under an aggregate of its own.
fn moving_sphere(own_aggregate: bool) -> PrimitiveAggregate {
    let start = Transform::translate(Vector3f::new(-2.0, 0.0, 0.0));
    let end = Transform::translate(Vector3f::new(2.0, 0.0, 0.0));
    let at = AnimatedTransform::new(start, 0.0, end, 1.0);
    let sphere = sphere_prim(Transform::identity(), 0.5);
    let primitive = if own_aggregate {
        Moving::Many(Arc::new(PrimitiveAggregate::new(
            vec![sphere],
            &AccelParams::default(),
        )))
    } else {
        Moving::of(&mut vec![sphere], &AccelParams::default()).expect("one primitive")
    };
    assert_eq!(matches!(primitive, Moving::One(_)), !own_aggregate);
    PrimitiveAggregate::new(
        vec![Primitive::Animated(Box::new(AnimatedPrimitive::new(
            primitive, at,
        )))],
        &AccelParams::default(),
    )
}

/// A single moving shape is held without an aggregate of its own: the
/// same hits, bit for bit, as under one (fixed-seed random rays at random
/// times).
#[test]
fn single_moving_shape_hits_as_under_an_aggregate() {
    let (one, many) = (moving_sphere(false), moving_sphere(true));
    assert_eq!(one.bounds(), many.bounds());
    let mut rng = Rng::new(11, 0);
    let mut hits = 0;
    for _ in 0..20000 {
        let o = Point3f::new(
            rng.uniform_float() * 6.0 - 3.0,
            rng.uniform_float() * 2.0 - 1.0,
            -5.0,
        );
        let d = Vector3f::new(
            rng.uniform_float() * 0.4 - 0.2,
            rng.uniform_float() * 0.4 - 0.2,
            1.0,
        );
        let r = Ray::with_time(o, d, rng.uniform_float(), None);
        let (a, b) = (
            one.intersect(&r, Float::INFINITY),
            many.intersect(&r, Float::INFINITY),
        );
        assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            assert_eq!(a.t_hit.to_bits(), b.t_hit.to_bits());
            assert_eq!(a.si.p(), b.si.p());
            assert_eq!(a.si.n, b.si.n);
            hits += 1;
        }
        assert_eq!(
            one.intersect_p(&r, Float::INFINITY),
            many.intersect_p(&r, Float::INFINITY)
        );
    }
    assert!(hits > 1000, "{hits}");
}

/// The box test of moving primitives never turns away a ray that the
/// exact test hits: fixed-seed rays passing within a few millionths of a
/// moving sphere's silhouette (more than 5,000 of the 30,000 hit), at radii and
/// positions over many orders of magnitude and at random times, each
/// with no limit and with a limit just past its hit.
#[test]
fn moving_box_test_keeps_every_hit() {
    let mut rng = Rng::new(29, 0);
    let v = |rng: &mut Rng, s: Float| {
        Vector3f::new(
            (rng.uniform_float() - 0.5) * s,
            (rng.uniform_float() - 0.5) * s,
            (rng.uniform_float() - 0.5) * s,
        )
    };
    let mut grazing = 0;
    let two = |e: i32| (2.0 as Float).powi(e);
    for k in 0..600 {
        let radius = two(k % 23 - 11);
        let far = two(k % 19 - 4) * radius.max(1.0);
        let a = v(&mut rng, 2.0 * far);
        let b = a + v(&mut rng, 6.0 * radius);
        let at = AnimatedTransform::new(Transform::translate(a), 0.0, Transform::translate(b), 1.0);
        let moving = AnimatedPrimitive::new(
            Moving::One(sphere_prim(Transform::identity(), radius)),
            at.clone(),
        );
        for _ in 0..50 {
            let time = rng.uniform_float();
            let center = Point3f::from(at.translation_at(time).expect("translations"));
            let d = (v(&mut rng, 2.0) + Vector3f::new(0.0, 0.0, 0.01)).normalize() * two(k % 5 - 2);
            let (side, _) = coordinate_system(d.normalize());
            let by = radius * (1.0 + (rng.uniform_float() - 0.5) * 4e-6);
            let o = center + side * by - d * (radius * (1.0 + 4.0 * rng.uniform_float()));
            let ray = Ray::with_time(o, d, time, None);
            let exact = |t_max: Float| {
                let (r, t) = at.interpolate(time).apply_inverse_ray(&ray, t_max);
                moving.primitive.intersect(&r, t)
            };
            let Some(hit) = exact(Float::INFINITY) else {
                continue;
            };
            grazing += 1;
            assert!(moving.may_hit(&ray, Float::INFINITY), "{k}: {ray:?}");
            let just_past = hit.t_hit * (1.0 + 1e-6);
            if exact(just_past).is_some() {
                assert!(moving.may_hit(&ray, just_past), "{k}: {ray:?}");
            }
        }
    }
    assert!(grazing > 5000, "{grazing}");
}

#[test]
fn animated_primitive_follows_its_motion() {
    let agg = moving_sphere(false);
    // The bounds cover the whole motion.
    let b = agg.bounds();
    assert!(b.p_min.x <= -2.5 && b.p_max.x >= 2.5);
    for (time, x) in [(0.0, -2.0), (0.25, -1.0), (0.5, 0.0), (1.0, 2.0)] {
        let r = Ray::with_time(
            Point3f::new(x, 0.0, -10.0),
            Vector3f::new(0.0, 0.0, 1.0),
            time,
            None,
        );
        let hit = agg
            .intersect(&r, Float::INFINITY)
            .expect("moving sphere hit");
        assert!((hit.t_hit - 9.5).abs() < 1e-3, "t={time}: {}", hit.t_hit);
        assert!((hit.si.p().x - x).abs() < 1e-3);
        // At the same time, a ray through where the sphere is not misses.
        let miss = Ray::with_time(
            Point3f::new(x + 1.0, 0.0, -10.0),
            Vector3f::new(0.0, 0.0, 1.0),
            time,
            None,
        );
        assert!(agg.intersect(&miss, Float::INFINITY).is_none());
        assert!(!agg.intersect_p(&miss, Float::INFINITY));
    }
}

#[test]
fn constant_alpha_is_stochastic_and_deterministic() {
    let s = Sphere::new(Transform::identity(), false, 1.0, -1.0, 1.0, 360.0).unwrap();
    let prim = GeometricPrimitive {
        shape: Shape::Sphere(Box::new(s)),
        material: Some(0),
        area_light: None,
        medium_interface: None,
        alpha: Alpha::Constant(0.3),
    };
    let mut rng = Rng::new(5, 0);
    let mut kept = 0;
    let n = 20000;
    for _ in 0..n {
        let o = Point3f::new(
            rng.uniform_float() * 0.2 - 0.1,
            rng.uniform_float() * 0.2 - 0.1,
            -5.0,
        );
        let r = Ray::new(o, Vector3f::new(0.0, 0.0, 1.0));
        let a = prim.intersect(&r, Float::INFINITY).is_some();
        assert_eq!(a, prim.intersect(&r, Float::INFINITY).is_some());
        assert_eq!(a, prim.intersect_p(&r, Float::INFINITY));
        kept += a as usize;
    }
    let frac = kept as f64 / n as f64;
    assert!((frac - 0.3).abs() < 0.02, "{frac}");
}

#[test]
fn empty_aggregate_hits_nothing() {
    let agg = PrimitiveAggregate::new(Vec::new(), &AccelParams::default());
    let r = Ray::new(Point3f::default(), Vector3f::new(0.0, 0.0, 1.0));
    assert!(agg.intersect(&r, Float::INFINITY).is_none());
    assert!(!agg.intersect_p(&r, Float::INFINITY));
}

#[test]
fn primitive_enum_stays_small() {
    // Millions of triangles are primitives: keep the enum near the size of
    // a geometric primitive.
    assert!(
        std::mem::size_of::<Primitive>() <= 80,
        "Primitive is {} bytes",
        std::mem::size_of::<Primitive>()
    );
}

#[test]
fn a_medium_transition_has_different_media_on_its_sides() {
    let mi = |inside, outside| MediumInterface { inside, outside };
    assert!(!mi(Some(1), Some(1)).is_transition());
    assert!(!mi(None, None).is_transition());
    assert!(mi(Some(1), None).is_transition());
    assert!(mi(Some(0), Some(2)).is_transition());
}

/// `intersect` is the two steps `intersect_record` and `interaction`
/// composed, bit for bit: triangles, spheres, an instance and an
/// alpha-masked sphere.
#[test]
fn intersect_is_record_then_interaction() {
    let mut rng = Rng::new(7, 0);
    let mut prims = random_triangles(&mut rng, 300, &Transform::identity());
    prims.push(sphere_prim(
        Transform::translate(Vector3f::new(1.0, 0.5, -1.0)),
        1.2,
    ));
    prims.push(sphere_prim(
        Transform::translate(Vector3f::new(-1.5, -1.0, 0.5)),
        0.7,
    ));
    let inner = Arc::new(PrimitiveAggregate::new(
        random_triangles(&mut rng, 50, &Transform::identity()),
        &AccelParams::default(),
    ));
    prims.push(Primitive::Instances(Box::new(InstanceSet::one(
        inner,
        Transform::translate(Vector3f::new(0.0, 2.0, 2.0)) * Transform::scale(0.5, 0.5, 0.5),
    ))));
    let Primitive::Geometric(mut masked) =
        sphere_prim(Transform::translate(Vector3f::new(0.0, -2.0, -2.0)), 1.0)
    else {
        unreachable!()
    };
    masked.alpha = Alpha::Constant(0.5);
    prims.push(Primitive::Geometric(masked));
    let agg = PrimitiveAggregate::new(prims, &AccelParams::default());
    let mut rng = Rng::new(8, 0);
    let (mut triangles, mut others) = (0, 0);
    for _ in 0..5000 {
        let r = random_ray(&mut rng);
        let t_max = if rng.uniform_float() < 0.2 {
            12.0
        } else {
            Float::INFINITY
        };
        let fused = agg.intersect(&r, t_max);
        let record = agg.intersect_record(&r, t_max);
        let two_steps = record.and_then(|h| agg.interaction(&r, &h));
        // Debug output shows every bit of the floats (and -0).
        assert_eq!(format!("{fused:?}"), format!("{two_steps:?}"));
        if let (Some(f), Some(h)) = (fused, record) {
            assert_eq!(f.t_hit.to_bits(), h.t_hit.to_bits());
            if matches!(h.kind, HitKind::Triangle(..)) {
                triangles += 1;
            } else {
                others += 1;
            }
        } else {
            assert!(record.is_none());
        }
    }
    assert!(triangles > 500 && others > 200, "{triangles} {others}");
}

/// A mesh of `n` random triangles and a few degenerate ones (a repeated
/// vertex, three collinear points), which no aggregate may return.
fn random_mesh(rng: &mut Rng, n: usize) -> Arc<TriangleMesh> {
    let mut p = Vec::new();
    for _ in 0..n * 3 {
        p.push(Point3f::new(
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
        ));
    }
    let mut idx: Vec<u32> = (0..(n * 3) as u32).collect();
    let k = p.len() as u32;
    p.extend([
        Point3f::new(-1.0, -1.0, 0.0),
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
    ]);
    // Degenerate triangles between good ones, so that entries after them
    // shift.
    idx.splice(30..30, [k, k + 1, k + 2, 4, 4, 5]);
    let xf = Transform::identity();
    let (mesh, warnings) = TriangleMesh::new(&xf, false, idx, p, vec![], vec![], vec![], vec![])
        .expect("a valid mesh");
    assert!(
        warnings.iter().any(|w| w.contains("skipping 2 of")),
        "{warnings:?}"
    );
    mesh
}

/// The same scene as primitives of their own per triangle and as mesh
/// primitives: every hit is the same, bit for bit, with and without the
/// vertex and frame caches, with few primitives (entries found by binary
/// search) and many (by table), opaque and alpha-masked.
#[test]
fn mesh_primitives_hit_as_their_triangles_do() {
    let mut rng = Rng::new(11, 0);
    let meshes = [random_mesh(&mut rng, 150), random_mesh(&mut rng, 60)];
    let alphas = [Alpha::Opaque, Alpha::Constant(0.6)];
    let per_triangle = |spheres: usize| -> Vec<Primitive> {
        let mut prims = Vec::new();
        for (mesh, alpha) in meshes.iter().zip(&alphas) {
            prims.extend(triangle::triangles(mesh).into_iter().map(|t| {
                Primitive::Geometric(GeometricPrimitive {
                    shape: Shape::Triangle(t),
                    material: Some(3),
                    area_light: None,
                    medium_interface: None,
                    alpha: alpha.clone(),
                })
            }));
            for k in 0..spheres {
                let at = Vector3f::new(k as Float * 0.3 - 2.0, 1.5, 0.5);
                prims.push(sphere_prim(Transform::translate(at), 0.2));
            }
        }
        prims
    };
    let as_meshes = |spheres: usize| -> Vec<Primitive> {
        let mut prims = Vec::new();
        for (mesh, alpha) in meshes.iter().zip(&alphas) {
            prims.push(Primitive::Mesh(MeshPrimitive {
                mesh: mesh.clone(),
                material: Some(3),
                medium_interface: None,
                alpha: alpha.clone(),
            }));
            for k in 0..spheres {
                let at = Vector3f::new(k as Float * 0.3 - 2.0, 1.5, 0.5);
                prims.push(sphere_prim(Transform::translate(at), 0.2));
            }
        }
        prims
    };
    let params = AccelParams::default();
    for spheres in [2, 20] {
        let reference = PrimitiveAggregate::new(per_triangle(spheres), &params);
        let uncached_reference =
            PrimitiveAggregate::with_cache_limits(per_triangle(spheres), &params, 0, 0);
        let cached = PrimitiveAggregate::new(as_meshes(spheres), &params);
        let vertices_only =
            PrimitiveAggregate::with_cache_limits(as_meshes(spheres), &params, usize::MAX, 0);
        let uncached = PrimitiveAggregate::with_cache_limits(as_meshes(spheres), &params, 0, 0);
        assert_eq!(cached.primitives().len(), 2 + 2 * spheres);
        assert_eq!(cached.entry_count(), 150 + 60 + 4 + 2 * spheres);
        assert_eq!(cached.primitive_count(), reference.primitive_count());
        assert_eq!(cached.bounds(), reference.bounds());
        let mut rng = Rng::new(12, 0);
        let mut hits = 0;
        for _ in 0..4000 {
            let r = random_ray(&mut rng);
            let t_max = if rng.uniform_float() < 0.2 {
                12.0
            } else {
                Float::INFINITY
            };
            let want = format!("{:?}", reference.intersect(&r, t_max));
            hits += usize::from(want != "None");
            let want_p = reference.intersect_p(&r, t_max);
            for agg in [&uncached_reference, &cached, &vertices_only, &uncached] {
                assert_eq!(format!("{:?}", agg.intersect(&r, t_max)), want);
                let record = agg.intersect_record(&r, t_max);
                let two_steps = record.and_then(|h| agg.interaction(&r, &h));
                assert_eq!(format!("{two_steps:?}"), want);
                assert_eq!(agg.intersect_p(&r, t_max), want_p);
            }
        }
        assert!(hits > 1000, "{hits}");
    }
}

/// A mesh primitive met outside an aggregate is its closest triangle.
#[test]
fn a_lone_mesh_primitive_is_its_closest_triangle() {
    let mut rng = Rng::new(13, 0);
    let mesh = random_mesh(&mut rng, 40);
    let lone = Primitive::Mesh(MeshPrimitive {
        mesh: mesh.clone(),
        material: Some(1),
        medium_interface: None,
        alpha: Alpha::Opaque,
    });
    let agg = PrimitiveAggregate::new(vec![lone.clone()], &AccelParams::default());
    assert_eq!(lone.bounds(), agg.bounds());
    let mut hits = 0;
    for _ in 0..2000 {
        let r = random_ray(&mut rng);
        let a = lone.intersect(&r, Float::INFINITY);
        let b = agg.intersect(&r, Float::INFINITY);
        assert_eq!(a.map(|h| h.t_hit), b.map(|h| h.t_hit));
        assert_eq!(lone.intersect_p(&r, Float::INFINITY), b.is_some());
        hits += usize::from(b.is_some());
    }
    assert!(hits > 300, "{hits}");
}

/// A batch of shadow rays gets the single rays' answers, searched
/// interleaved or one ray at a time, at every SIMD level, in batches of
/// several lengths, through the vertex cache or without it, with spheres
/// and alpha-masked triangles among the entries.
#[test]
fn shadow_ray_batches_answer_as_single_rays() {
    let mut rng = Rng::new(21, 0);
    // More entries than `PREFETCH_MIN_ENTRIES`: the interleaved search's
    // condition.
    let big = random_mesh(&mut rng, 9000);
    let masked = random_mesh(&mut rng, 200);
    let prims = || -> Vec<Primitive> {
        let mut prims = vec![
            Primitive::Mesh(MeshPrimitive {
                mesh: big.clone(),
                material: Some(1),
                medium_interface: None,
                alpha: Alpha::Opaque,
            }),
            Primitive::Mesh(MeshPrimitive {
                mesh: masked.clone(),
                material: Some(2),
                medium_interface: None,
                alpha: Alpha::Constant(0.5),
            }),
        ];
        for k in 0..3 {
            let at = Vector3f::new(k as Float - 1.0, 0.5, -2.5);
            prims.push(sphere_prim(Transform::translate(at), 0.4));
        }
        prims
    };
    let params = AccelParams::default();
    let cached = PrimitiveAggregate::new(prims(), &params);
    let uncached = PrimitiveAggregate::with_cache_limits(prims(), &params, 0, 0);
    // Rays from outside the cube of triangles: the shorter ones stop
    // before it, the longer ones end inside it or pass through.
    let rays: Vec<(Ray, Float)> = (0..3000)
        .map(|k| {
            let t_max = [0.6, 0.8, 0.85, 1.0, Float::INFINITY][k % 5];
            (random_ray(&mut rng), t_max)
        })
        .collect();
    for agg in [&cached, &uncached] {
        assert!(agg.prefetch_pays());
        let want: Vec<bool> = rays.iter().map(|(r, t)| agg.intersect_p(r, *t)).collect();
        let blocked = want.iter().filter(|&&b| b).count();
        assert!((300..2700).contains(&blocked), "{blocked} of 3000 blocked");
        for level in SimdLevel::available() {
            for interleave in [false, true] {
                for chunk in [7, 256, rays.len()] {
                    let (mut out, mut got) = (Vec::new(), Vec::new());
                    for batch in rays.chunks(chunk) {
                        agg.intersect_ps(batch, level, interleave, &mut out);
                        got.extend_from_slice(&out);
                    }
                    assert!(
                        got == want,
                        "{level:?}, interleaved {interleave}, batches of {chunk}"
                    );
                }
            }
        }
    }
}
