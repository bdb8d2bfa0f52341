use super::*;
use crate::rng::Rng;
use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf};
use rpbrt_geometry::frame::Frame;

fn ru(r: &mut Rng) -> Point2f {
    Point2f::new(r.uniform_float(), r.uniform_float())
}
fn rp(r: &mut Rng, s: Float) -> Point3f {
    Point3f::new(
        s * (2.0 * r.uniform_float() - 1.0),
        s * (2.0 * r.uniform_float() - 1.0),
        s * (2.0 * r.uniform_float() - 1.0),
    )
}
fn patch(p: [Point3f; 4]) -> BilinearPatch {
    let (m, _) = BilinearPatchMesh::new(
        &Transform::default(),
        false,
        vec![],
        p.to_vec(),
        vec![],
        vec![],
        vec![],
    )
    .expect("mesh");
    BilinearPatch::new(m, 0)
}
/// A 2 × 1.5 rectangle in the plane z = 0.5, rotated about z.
fn rectangle() -> BilinearPatch {
    let (c, s) = (0.8, 0.6);
    let ex = Vector3f::new(2.0 * c, 2.0 * s, 0.0);
    let ey = Vector3f::new(-1.5 * s, 1.5 * c, 0.0);
    let o = Point3f::new(-0.3, 0.2, 0.5);
    patch([o, o + ex, o + ey, o + ex + ey])
}
fn twisted() -> BilinearPatch {
    patch([
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.3),
        Point3f::new(0.1, 1.0, 0.8),
        Point3f::new(1.2, 1.1, -0.4),
    ])
}

#[test]
fn planar_rectangle_hits_match_plane() {
    let blp = rectangle();
    assert!(blp.is_rectangle());
    assert!((blp.area() - 3.0).abs() < 1e-5);
    let p = blp.vertices();
    let mut r = Rng::new(20, 0);
    for _ in 0..5000 {
        let (u, v) = (r.uniform_float(), r.uniform_float());
        let target = bilerp(&p, u, v);
        let o = Point3f::new(
            rp(&mut r, 3.0).x,
            rp(&mut r, 3.0).y,
            if r.uniform_float() < 0.5 { 3.0 } else { -2.0 },
        );
        let ray = Ray::new(o, target - o);
        let si = blp.intersect(&ray, Float::INFINITY).expect("hit");
        assert!(blp.intersect_p(&ray, Float::INFINITY));
        assert!((si.t_hit - 1.0).abs() < 1e-4, "t {}", si.t_hit);
        assert!((si.intr.p().z - 0.5).abs() < 1e-5);
        assert!(
            (si.intr.uv - Point2f::new(u, v)).length() < 1e-4,
            "{:?} vs {u} {v}",
            si.intr.uv
        );
        assert!((si.intr.n.z.abs() - 1.0).abs() < 1e-5 && si.intr.n.z > 0.0);
        assert!(blp.intersect(&ray, 0.999).is_none());
    }
    // Rays beside the rectangle miss it.
    let ray = Ray::new(Point3f::new(10.0, 10.0, 3.0), Vector3f::new(0.0, 0.0, -1.0));
    assert!(
        blp.intersect(&ray, Float::INFINITY).is_none() && !blp.intersect_p(&ray, Float::INFINITY)
    );
}

#[test]
fn twisted_patch_hits_satisfy_bilinear_equation() {
    let blp = twisted();
    assert!(!blp.is_rectangle());
    let p = blp.vertices();
    let mut r = Rng::new(21, 0);
    let mut at_target = 0;
    for _ in 0..5000 {
        let (u, v) = (r.uniform_float(), r.uniform_float());
        let target = bilerp(&p, u, v);
        let o = rp(&mut r, 4.0);
        let ray = Ray::new(o, target - o);
        let si = blp
            .intersect(&ray, Float::INFINITY)
            .unwrap_or_else(|| panic!("ray {ray:?} aimed at ({u}, {v}) missed"));
        assert!(blp.intersect_p(&ray, Float::INFINITY));
        let (uv, t) =
            intersect_bilinear_patch(&ray, Float::INFINITY, p[0], p[1], p[2], p[3]).expect("hit");
        // The hit lies on the ray and on the patch, no further than the
        // aimed-at point.
        let on_patch = bilerp(&p, uv.x, uv.y);
        assert!(
            (on_patch - ray.at(t)).length() < 1e-4,
            "{on_patch:?} {:?}",
            ray.at(t)
        );
        assert!((si.intr.p() - on_patch).length() < 1e-4);
        assert!(t <= 1.0 + 1e-2, "t {t}");
        if (t - 1.0).abs() < 1e-4 {
            at_target += 1;
            assert!(
                (uv - Point2f::new(u, v)).length() < 5e-3,
                "{uv:?} vs {u} {v}"
            );
        }
        // The normal is perpendicular to the surface partials.
        let (dpdu, dpdv) = partials(&p, uv.x, uv.y);
        assert!(
            dot(si.intr.n, dpdu).abs() < 1e-4 * dpdu.length()
                && dot(si.intr.n, dpdv).abs() < 1e-4 * dpdv.length()
        );
    }
    assert!(at_target > 4000, "{at_target}");
}

#[test]
fn spawned_rays_do_not_reintersect() {
    let mut r = Rng::new(22, 0);
    for blp in [rectangle(), twisted()] {
        let p = blp.vertices();
        for _ in 0..3000 {
            let target = bilerp(&p, r.uniform_float(), r.uniform_float());
            let o = rp(&mut r, 5.0);
            let Some(si) = blp.intersect(&Ray::new(o, target - o), Float::INFINITY) else {
                continue;
            };
            for _ in 0..4 {
                let d = sample_uniform_sphere(ru(&mut r));
                let spawned = si.intr.spawn_ray(d);
                if let Some(again) = blp.intersect(&spawned, Float::INFINITY) {
                    // A curved patch may be hit again, but never next to
                    // where the ray left it.
                    assert!(!blp.is_rectangle(), "re-hit a rectangle");
                    // (Grazing rays may genuinely come back within a
                    // short distance on a curved surface.)
                    if abs_dot(d, si.intr.n) < 0.05 {
                        continue;
                    }
                    assert!(
                        (again.intr.p() - si.intr.p()).length() > 1e-3,
                        "re-hit at {:?} from {:?} t {} d {d:?} n {:?} o {:?} err {:?}",
                        again.intr.p(),
                        si.intr.p(),
                        again.t_hit,
                        si.intr.n,
                        spawned.o,
                        si.intr.p_error()
                    );
                }
            }
        }
    }
}

#[test]
fn areas() {
    assert!((rectangle().area() - 3.0).abs() < 1e-5);
    // A planar parallelogram has constant |∂p/∂u × ∂p/∂v|.
    let par = patch([
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(2.0, 0.0, 0.0),
        Point3f::new(0.5, 1.0, 0.0),
        Point3f::new(2.5, 1.0, 0.0),
    ]);
    assert!(!par.is_rectangle());
    assert!((par.area() - 2.0).abs() < 1e-5, "{}", par.area());
    // A triangle-shaped patch (collapsed edge).
    let tri = patch([
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
    ]);
    assert!((tri.area() - 0.5).abs() < 1e-5, "{}", tri.area());
    // The twisted patch against a fine midpoint rule.
    let blp = twisted();
    let p = blp.vertices();
    let n = 600;
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let (dpdu, dpdv) = partials(
                &p,
                (i as Float + 0.5) / n as Float,
                (j as Float + 0.5) / n as Float,
            );
            sum += cross(dpdu, dpdv).length() as f64;
        }
    }
    let reference = sum / (n * n) as f64;
    assert!(
        (blp.area() as f64 - reference).abs() < 1e-5 * reference,
        "{} vs {reference}",
        blp.area()
    );
}

#[test]
fn area_sampling() {
    let mut r = Rng::new(23, 0);
    for blp in [rectangle(), twisted()] {
        let p = blp.vertices();
        let n = 100_000;
        let mut inv = 0.0f64;
        for _ in 0..n {
            let ss = blp.sample_area(ru(&mut r)).expect("sample");
            inv += 1.0 / ss.pdf as f64;
            assert!((bilerp(&p, ss.uv.x, ss.uv.y) - ss.p()).length() < 1e-4);
            assert!((ss.pdf - blp.pdf_area_at(ss.uv)).abs() < 1e-4 * ss.pdf);
        }
        let est = inv / n as f64;
        assert!(
            (est - blp.area() as f64).abs() < 0.01 * blp.area() as f64,
            "E[1/pdf] {est} vs {}",
            blp.area()
        );
    }
}

#[test]
fn sample_pdf_matches_pdf_and_integrates_to_one() {
    let mut r = Rng::new(24, 0);
    let mut spherical = 0;
    for blp in [rectangle(), twisted()] {
        for k in 0..6 {
            let dist = if k < 4 { 2.5 } else { 150.0 };
            let mut ctx = ShapeSampleContext::from_point(
                Point3f::from(Vector3f::from(rp(&mut r, 1.0)).normalize() * dist),
                0.0,
            );
            if k % 2 == 1 {
                let n = Normal3f::from(sample_uniform_sphere(ru(&mut r)));
                ctx.n = n;
                ctx.ns = n;
            }
            let (_, sa) = blp.solid_angle_from(ctx.p());
            if blp.is_rectangle() && sa > MIN_SPHERICAL_SAMPLE_AREA {
                spherical += 1;
            }
            let n = 4000;
            let mut bad = 0;
            for _ in 0..n {
                let Some(ss) = blp.sample(&ctx, ru(&mut r)) else {
                    continue;
                };
                assert!(ss.pdf > 0.0 && ss.pdf.is_finite());
                // Skip samples hidden behind another part of the patch:
                // pdf() sees only the nearest crossing.
                let wi = ss.p() - ctx.p();
                match blp.intersect(&ctx.spawn_ray(wi), Float::INFINITY) {
                    Some(first) if (first.intr.p() - ss.p()).length() < 1e-3 => {}
                    _ => continue,
                }
                let pdf = blp.pdf(&ctx, wi);
                if (pdf - ss.pdf).abs() > 1e-2 * ss.pdf {
                    bad += 1;
                }
            }
            assert!(
                bad < n / 50,
                "{bad} of {n} sample pdfs disagree with pdf() rect {} k {k} sa {sa}",
                blp.is_rectangle()
            );

            // ∫ pdf dω = 1 for rectangles. (For curved patches the
            // density has an infinite-variance spike at the silhouette,
            // where cos θ → 0, so a uniform estimate is meaningless.)
            if blp.is_rectangle() {
                let cone = DirectionCone::bound_subtended_directions(&blp.bounds(), ctx.p());
                let frame = Frame::from_z(cone.w);
                let m = 40_000;
                let total: f64 = (0..m)
                    .map(|_| {
                        let w = frame.from_local(sample_uniform_cone(ru(&mut r), cone.cos_theta));
                        blp.pdf(&ctx, w) as f64
                    })
                    .sum::<f64>()
                    / (m as f64 * uniform_cone_pdf(cone.cos_theta) as f64);
                assert!(
                    (total - 1.0).abs() < 0.04,
                    "∫pdf = {total} (solid angle {sa})"
                );
            }
        }
    }
    assert!(spherical > 0);
}

#[test]
fn degenerate_patches_are_skipped() {
    let nan = Float::NAN;
    let p = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
        Point3f::new(2.0, 0.0, 0.0),
        Point3f::new(3.0, 0.0, 0.0),
        Point3f::new(nan, 0.0, 0.0),
    ];
    // good, collinear, all-equal, NaN corner
    let idx = vec![0, 1, 2, 3, 0, 1, 4, 5, 2, 2, 2, 2, 0, 1, 6, 3];
    let (m, warnings) =
        BilinearPatchMesh::new(&Transform::default(), false, idx, p, vec![], vec![], vec![])
            .expect("mesh");
    assert!(
        warnings.iter().any(|w| w.contains("skipping 3 of 4")),
        "{warnings:?}"
    );
    let good = patches(&m);
    assert_eq!(good.len(), 1);
    let mut r = Rng::new(25, 0);
    let ctx = ShapeSampleContext::from_point(Point3f::new(0.2, 0.2, 1.0), 0.0);
    for i in 1..4 {
        let b = BilinearPatch::new(m.clone(), i);
        for _ in 0..200 {
            let o = rp(&mut r, 2.0);
            let ray = Ray::new(o, rp(&mut r, 1.0) - o);
            assert!(
                b.intersect(&ray, Float::INFINITY).is_none()
                    && !b.intersect_p(&ray, Float::INFINITY)
            );
            let u = ru(&mut r);
            if let Some(s) = b.sample_area(u) {
                assert!(s.pdf.is_finite());
            }
            if let Some(s) = b.sample(&ctx, u) {
                assert!(s.pdf.is_finite() && !s.p().has_nan());
            }
            let pdf = b.pdf(&ctx, sample_uniform_sphere(u));
            assert!(pdf.is_finite() && pdf >= 0.0);
        }
    }
}

#[test]
fn validation_errors() {
    let id = Transform::default();
    let p4 = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
    ];
    let msg = |r: Result<(Arc<BilinearPatchMesh>, Vec<String>), ShapeError>| {
        r.err().map(|e| e.0).unwrap_or_default()
    };
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![0, 1, 2, 9],
        p4.clone(),
        vec![],
        vec![],
        vec![]
    ))
    .contains("out of range"));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![0, 1, 2],
        p4.clone(),
        vec![],
        vec![],
        vec![]
    ))
    .contains("multiple of 4"));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![0, 1, 1, 0],
        p4[..2].to_vec(),
        vec![],
        vec![],
        vec![]
    ))
    .contains("at least 3"));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![],
        p4[..3].to_vec(),
        vec![],
        vec![],
        vec![]
    ))
    .contains("indices"));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![],
        p4.clone(),
        vec![Normal3f::new(0.0, 0.0, 1.0)],
        vec![],
        vec![]
    ))
    .contains("\"N\""));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![],
        p4.clone(),
        vec![],
        vec![Point2f::default(); 3],
        vec![]
    ))
    .contains("\"uv\""));
    assert!(msg(BilinearPatchMesh::new(
        &id,
        false,
        vec![],
        p4.clone(),
        vec![],
        vec![],
        vec![1, 2]
    ))
    .contains("face indices"));
    let (m, w) =
        BilinearPatchMesh::new(&id, false, vec![], p4, vec![], vec![], vec![3]).expect("one patch");
    assert!(w.is_empty());
    assert_eq!(m.indices, vec![0, 1, 2, 3]);
}

#[test]
fn orientation_shading_and_texture_coordinates() {
    let id = Transform::default();
    let p4 = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
    ];
    let ray = Ray::new(Point3f::new(0.25, 0.75, 1.0), Vector3f::new(0.0, 0.0, -1.0));
    let hit = |m: Arc<BilinearPatchMesh>| {
        BilinearPatch::new(m, 0)
            .intersect(&ray, Float::INFINITY)
            .expect("hit")
            .intr
    };

    let (m, _) = BilinearPatchMesh::new(&id, false, vec![], p4.clone(), vec![], vec![], vec![4])
        .expect("mesh");
    let si = hit(m.clone());
    assert!(si.n.z > 0.99 && si.face_index == 4);
    assert!((si.uv - Point2f::new(0.25, 0.75)).length() < 1e-5);
    assert!(BilinearPatch::new(m, 0).normal_bounds().w.z > 0.99);
    let (m, _) = BilinearPatchMesh::new(&id, true, vec![], p4.clone(), vec![], vec![], vec![])
        .expect("mesh");
    assert!(hit(m.clone()).n.z < -0.99);
    assert!(BilinearPatch::new(m, 0).normal_bounds().w.z < -0.99);

    // Tilted vertex normals become the shading normal; the geometric
    // normal follows their side.
    let ns = vec![Normal3f::new(0.3, 0.0, -1.0).normalize(); 4];
    let (m, _) =
        BilinearPatchMesh::new(&id, false, vec![], p4.clone(), ns, vec![], vec![]).expect("mesh");
    let si = hit(m);
    assert!(si.n.z < -0.99);
    assert!((si.shading.n - Normal3f::new(0.3, 0.0, -1.0).normalize()).length() < 1e-4);
    assert!(dot(si.shading.dpdu, si.shading.n).abs() < 1e-4);

    // Texture coordinates are interpolated bilinearly.
    let uv = vec![
        Point2f::new(0.0, 0.0),
        Point2f::new(2.0, 0.0),
        Point2f::new(0.0, 4.0),
        Point2f::new(2.0, 4.0),
    ];
    let (m, _) = BilinearPatchMesh::new(&id, false, vec![], p4, vec![], uv, vec![]).expect("mesh");
    let si = hit(m);
    assert!(
        (si.uv - Point2f::new(0.5, 3.0)).length() < 1e-4,
        "{:?}",
        si.uv
    );
    assert!(
        (si.dpdu - Vector3f::new(0.5, 0.0, 0.0)).length() < 1e-5,
        "{:?}",
        si.dpdu
    );
    assert!(
        (si.dpdv - Vector3f::new(0.0, 0.25, 0.0)).length() < 1e-5,
        "{:?}",
        si.dpdv
    );
}

#[test]
fn area_density_at_a_point_matches_area_sampling() {
    let mut r = Rng::with_sequence(31);
    for bp in [twisted(), rectangle()] {
        let p = bp.vertices();
        for _ in 0..500 {
            let ss = bp.sample_area(ru(&mut r)).expect("sample");
            let pdf = bp.pdf_area_at_point(ss.p());
            assert!((pdf - ss.pdf).abs() <= 1e-3 * ss.pdf, "{pdf} vs {}", ss.pdf);
            // The patch parameters of a point come back from the point.
            let uv = ru(&mut r);
            let back = bp.invert_point(bilerp(&p, uv.x, uv.y));
            assert!((back - uv).length() < 1e-4, "{uv:?} -> {back:?}");
        }
    }
}
