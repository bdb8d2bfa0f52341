use super::*;
use crate::rng::Rng;
use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf};
use rpbrt_geometry::frame::Frame;
use std::collections::HashMap;

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
fn mesh(p: Vec<Point3f>, indices: Vec<u32>) -> Arc<TriangleMesh> {
    TriangleMesh::new(
        &Transform::default(),
        false,
        indices,
        p,
        vec![],
        vec![],
        vec![],
        vec![],
    )
    .expect("valid mesh")
    .0
}
fn single(p0: Point3f, p1: Point3f, p2: Point3f) -> Triangle {
    Triangle::new(mesh(vec![p0, p1, p2], vec![]), 0)
}
fn random_triangle(r: &mut Rng) -> Triangle {
    loop {
        let t = single(rp(r, 1.0), rp(r, 1.0), rp(r, 1.0));
        if t.area() > 0.05 {
            return t;
        }
    }
}
fn hit_any(tris: &[Triangle], ray: &Ray) -> bool {
    tris.iter().any(|t| t.intersect_p(ray, Float::INFINITY))
}

/// A sphere-like closed mesh: an octahedron subdivided `levels` times,
/// vertices shared between neighbouring triangles.
fn subdivided_octahedron(levels: u32) -> Arc<TriangleMesh> {
    let mut p = vec![
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(-1.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(0.0, -1.0, 0.0),
        Point3f::new(0.0, 0.0, 1.0),
        Point3f::new(0.0, 0.0, -1.0),
    ];
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::new();
        for t in &tris {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                m[k] = *mid.entry((a, b)).or_insert_with(|| {
                    let q = p[a as usize] + p[b as usize];
                    p.push(Point3f::from(Vector3f::from(q).normalize()));
                    (p.len() - 1) as u32
                });
            }
            next.extend([
                [t[0], m[0], m[2]],
                [m[0], t[1], m[1]],
                [m[2], m[1], t[2]],
                [m[0], m[1], m[2]],
            ]);
        }
        tris = next;
    }
    // Move it off the origin so that coordinates are not symmetric.
    let p = p
        .into_iter()
        .map(|q| q * 3.7 + Vector3f::new(0.3, -1.1, 2.9))
        .collect();
    mesh(p, tris.into_iter().flatten().collect())
}

#[test]
fn watertight_closed_mesh() {
    let m = subdivided_octahedron(3);
    let tris = triangles(&m);
    assert_eq!(tris.len(), m.n_triangles());
    let mut r = Rng::new(10, 0);
    let center = Point3f::new(0.3, -1.1, 2.9);
    for i in 0..4000 {
        let o = center + Vector3f::from(rp(&mut r, 1.0));
        // Aim at vertices, at points on edges, or anywhere.
        let d = match i % 3 {
            0 => m.p[r.uniform_bounded(m.p.len() as u32) as usize] - o,
            1 => {
                let t = r.uniform_bounded(m.n_triangles() as u32) as usize;
                let v = m.vertices(t);
                let k = r.uniform_bounded(3) as usize;
                v[k] + (v[(k + 1) % 3] - v[k]) * r.uniform_float() - o
            }
            _ => sample_uniform_sphere(ru(&mut r)),
        };
        let ray = Ray::new(o, d);
        assert!(hit_any(&tris, &ray), "ray {ray:?} escaped the closed mesh");
    }
}

#[test]
fn watertight_grid_edges_and_vertices() {
    // A bumpy n×n grid; rays through its shared edges and vertices.
    let n = 8;
    let mut r = Rng::new(11, 0);
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            p.push(Point3f::new(
                i as Float * 0.37,
                j as Float * 0.41,
                0.2 * r.uniform_float(),
            ));
        }
    }
    let mut idx = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            idx.extend([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]);
        }
    }
    let m = mesh(p, idx.into_iter().map(|x| x as u32).collect());
    let tris = triangles(&m);
    for _ in 0..4000 {
        let (i, j) = (
            1 + r.uniform_bounded(n as u32 - 1) as usize,
            1 + r.uniform_bounded(n as u32 - 1) as usize,
        );
        let a = m.p[j * (n + 1) + i];
        let neighbours = [
            m.p[j * (n + 1) + i + 1],
            m.p[(j + 1) * (n + 1) + i],
            m.p[(j + 1) * (n + 1) + i + 1],
        ];
        let b = neighbours[r.uniform_bounded(3) as usize];
        let target = if r.uniform_float() < 0.3 {
            a
        } else {
            a + (b - a) * r.uniform_float()
        };
        let o = Point3f::new(
            target.x + rp(&mut r, 2.0).x,
            target.y + rp(&mut r, 2.0).y,
            if r.uniform_float() < 0.5 { 3.0 } else { -3.0 },
        );
        let ray = Ray::new(o, target - o);
        assert!(
            hit_any(&tris, &ray),
            "ray {ray:?} slipped through the grid at {target:?}"
        );
    }
}

#[test]
fn spawned_rays_do_not_reintersect() {
    let mut r = Rng::new(12, 0);
    let mut hits = 0;
    for _ in 0..2000 {
        let tri = random_triangle(&mut r);
        let [p0, p1, p2] = tri.vertices();
        let b = sample_uniform_triangle(ru(&mut r));
        let target = p0 * b[0] + p1 * b[1] + p2 * b[2];
        let o = rp(&mut r, 8.0);
        let Some(si) = tri.intersect(&Ray::new(o, target - o), Float::INFINITY) else {
            continue;
        };
        hits += 1;
        for _ in 0..5 {
            let d = sample_uniform_sphere(ru(&mut r));
            let spawned = si.intr.spawn_ray(d);
            assert!(
                !tri.intersect_p(&spawned, Float::INFINITY),
                "re-hit from {:?} toward {d:?}",
                si.intr.p()
            );
        }
    }
    assert!(hits > 1900, "{hits}");
}

/// Double-precision Möller–Trumbore: (b0, b1, b2, t).
fn brute_force(ray: &Ray, v: [Point3f; 3]) -> Option<(f64, f64, f64, f64)> {
    let f = |p: Point3f| [p.x as f64, p.y as f64, p.z as f64];
    let (p0, p1, p2, o) = (f(v[0]), f(v[1]), f(v[2]), f(ray.o));
    let d = [ray.d.x as f64, ray.d.y as f64, ray.d.z as f64];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cr = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dt = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (e1, e2) = (sub(p1, p0), sub(p2, p0));
    let pv = cr(d, e2);
    let det = dt(e1, pv);
    if det == 0.0 {
        return None;
    }
    let tv = sub(o, p0);
    let b1 = dt(tv, pv) / det;
    let q = cr(tv, e1);
    let b2 = dt(d, q) / det;
    Some((1.0 - b1 - b2, b1, b2, dt(e2, q) / det))
}

#[test]
fn agrees_with_double_precision_brute_force() {
    let mut r = Rng::new(13, 0);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..20_000 {
        let tri = random_triangle(&mut r);
        let o = rp(&mut r, 4.0);
        let ray = Ray::new(o, rp(&mut r, 1.0) - o);
        let got = tri.intersect(&ray, Float::INFINITY);
        assert_eq!(got.is_some(), tri.intersect_p(&ray, Float::INFINITY));
        let Some((b0, b1, b2, t)) = brute_force(&ray, tri.vertices()) else {
            continue;
        };
        let margin = b0.min(b1).min(b2);
        if margin > 1e-4 && t > 1e-4 {
            let si = got.expect("brute force hit missed");
            assert!(
                ((si.t_hit as f64 - t) / t).abs() < 1e-4,
                "t {} vs {t}",
                si.t_hit
            );
            let e = si.intr.p() - ray.at(t as Float);
            assert!(e.length() < 1e-4 * (1.0 + Vector3f::from(si.intr.p()).length()));
            hits += 1;
        } else if margin < -1e-4 || t < -1e-4 {
            assert!(got.is_none(), "brute force miss hit");
            misses += 1;
        }
        // Limiting t_max below the hit must remove it.
        if let Some(si) = got {
            assert!(tri.intersect(&ray, si.t_hit * 0.999).is_none());
        }
    }
    assert!(hits > 1000 && misses > 1000, "{hits} {misses}");
}

#[test]
fn bad_triangles_are_skipped_and_never_hit() {
    let nan = Float::NAN;
    let p = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(2.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
        Point3f::new(nan, 0.0, 0.0),
        Point3f::new(Float::INFINITY, 1.0, 0.0),
    ];
    // good, collinear, repeated vertex, NaN vertex, infinite vertex.
    let idx = vec![0, 1, 3, 0, 1, 2, 0, 0, 3, 4, 1, 3, 5, 1, 3];
    let (m, warnings) = TriangleMesh::new(
        &Transform::default(),
        false,
        idx,
        p,
        vec![],
        vec![],
        vec![],
        vec![],
    )
    .expect("mesh");
    assert!(
        warnings.iter().any(|w| w.contains("skipping 4 of 5")),
        "{warnings:?}"
    );
    assert!(
        warnings.iter().any(|w| w.contains("not finite")),
        "{warnings:?}"
    );
    let good = triangles(&m);
    assert_eq!(good.len(), 1);
    assert_eq!(good[0].tri_index, 0);
    let mut r = Rng::new(14, 0);
    let ctx = ShapeSampleContext::from_point(Point3f::new(0.2, 0.2, 1.0), 0.0);
    for i in 1..5 {
        let t = Triangle::new(m.clone(), i);
        for _ in 0..200 {
            let o = rp(&mut r, 2.0);
            let ray = Ray::new(o, rp(&mut r, 1.0) - o);
            assert!(t.intersect(&ray, Float::INFINITY).is_none());
            assert!(!t.intersect_p(&ray, Float::INFINITY));
            let u = ru(&mut r);
            if let Some(s) = t.sample_area(u) {
                assert!(s.pdf.is_finite());
            }
            if let Some(s) = t.sample(&ctx, u) {
                assert!(s.pdf.is_finite() && !s.p().has_nan());
            }
            let pdf = t.pdf(&ctx, sample_uniform_sphere(u));
            assert!(pdf.is_finite() && pdf >= 0.0);
        }
    }
}

#[test]
fn validation_errors() {
    let id = Transform::default();
    let p3 = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
    ];
    let p4 = [p3.clone(), vec![Point3f::new(1.0, 1.0, 0.0)]].concat();
    let new = |idx: Vec<u32>,
               p: Vec<Point3f>,
               s: Vec<Vector3f>,
               n: Vec<Normal3f>,
               uv: Vec<Point2f>,
               f: Vec<i32>| TriangleMesh::new(&id, false, idx, p, s, n, uv, f);
    let msg = |r: Result<(Arc<TriangleMesh>, Vec<String>), ShapeError>| {
        r.err().map(|e| e.0).unwrap_or_default()
    };
    assert!(msg(new(
        vec![0, 1, 5],
        p3.clone(),
        vec![],
        vec![],
        vec![],
        vec![]
    ))
    .contains("out of range"));
    assert!(msg(new(
        vec![0, 1, 2, 3],
        p4.clone(),
        vec![],
        vec![],
        vec![],
        vec![]
    ))
    .contains("multiple of 3"));
    assert!(msg(new(
        vec![0, 1],
        p3[..2].to_vec(),
        vec![],
        vec![],
        vec![],
        vec![]
    ))
    .contains("at least 3"));
    assert!(msg(new(vec![], p4.clone(), vec![], vec![], vec![], vec![])).contains("indices"));
    assert!(msg(new(
        vec![],
        p3.clone(),
        vec![],
        vec![Normal3f::new(0.0, 0.0, 1.0)],
        vec![],
        vec![]
    ))
    .contains("\"N\""));
    assert!(msg(new(
        vec![],
        p3.clone(),
        vec![Vector3f::default(); 2],
        vec![],
        vec![],
        vec![]
    ))
    .contains("\"S\""));
    assert!(msg(new(
        vec![],
        p3.clone(),
        vec![],
        vec![],
        vec![Point2f::default(); 4],
        vec![]
    ))
    .contains("\"uv\""));
    assert!(
        msg(new(vec![], p3.clone(), vec![], vec![], vec![], vec![1, 2])).contains("face indices")
    );
    // Flawed per-vertex data is mended with a warning, not refused.
    let (m, w) = new(
        vec![],
        p3.clone(),
        vec![],
        vec![Normal3f::new(Float::NAN, 0.0, 1.0); 3],
        vec![],
        vec![],
    )
    .expect("NaN normals render");
    assert!(m.n.is_none(), "all-NaN normals fall back to geometric ones");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("geometric normals"), "{w:?}");
    let (m, w) = new(vec![], p3, vec![], vec![], vec![], vec![7]).expect("one triangle");
    assert!(w.is_empty());
    assert_eq!(m.indices, vec![0, 1, 2]);
    assert_eq!(m.face_indices, Some(vec![7]));
}

#[test]
fn interaction_geometry_and_orientation() {
    let p = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
    ];
    let ray = Ray::new(Point3f::new(0.7, 0.2, 2.0), Vector3f::new(0.0, 0.0, -1.0));
    let id = Transform::default();
    let hit = |m: Arc<TriangleMesh>| {
        Triangle::new(m, 0)
            .intersect(&ray, Float::INFINITY)
            .expect("hit")
            .intr
    };

    let (m, _) = TriangleMesh::new(
        &id,
        false,
        vec![],
        p.clone(),
        vec![],
        vec![],
        vec![],
        vec![5],
    )
    .expect("mesh");
    let si = hit(m.clone());
    // Default uvs make (u, v) = (x, y) here.
    assert!((si.uv - Point2f::new(0.7, 0.2)).length() < 1e-5);
    assert!((si.dpdu - Vector3f::new(1.0, 0.0, 0.0)).length() < 1e-5);
    assert!((si.dpdv - Vector3f::new(0.0, 1.0, 0.0)).length() < 1e-5);
    assert!((Vector3f::from(si.n) - Vector3f::new(0.0, 0.0, 1.0)).length() < 1e-6);
    assert_eq!(si.face_index, 5);
    assert!((si.wo - Vector3f::new(0.0, 0.0, 1.0)).length() < 1e-6);
    assert!(si.p_error().length() > 0.0 && si.p_error().length() < 1e-5);
    assert!((Triangle::new(m, 0).normal_bounds().w - Vector3f::from(si.n)).length() < 1e-6);

    let (m, _) = TriangleMesh::new(&id, true, vec![], p.clone(), vec![], vec![], vec![], vec![])
        .expect("mesh");
    assert!(hit(m.clone()).n.z < 0.0);
    assert!(Triangle::new(m, 0).normal_bounds().w.z < 0.0);

    // Per-vertex normals decide the side, reversed by ReverseOrientation.
    let down = vec![Normal3f::new(0.0, 0.0, -1.0); 3];
    let (m, _) = TriangleMesh::new(
        &id,
        false,
        vec![],
        p.clone(),
        vec![],
        down.clone(),
        vec![],
        vec![],
    )
    .expect("mesh");
    let si = hit(m);
    assert!(si.n.z < 0.0 && si.shading.n.z < 0.0);
    let (m, _) = TriangleMesh::new(&id, true, vec![], p.clone(), vec![], down, vec![], vec![])
        .expect("mesh");
    let si = hit(m);
    assert!(si.n.z > 0.0 && si.shading.n.z > 0.0);

    // Interpolated shading normals and their derivatives.
    let tilted = vec![
        Normal3f::new(0.0, 0.0, 1.0),
        Normal3f::new(1.0, 0.0, 1.0).normalize(),
        Normal3f::new(0.0, 1.0, 1.0).normalize(),
    ];
    let (m, _) = TriangleMesh::new(
        &id,
        false,
        vec![],
        p.clone(),
        vec![],
        tilted,
        vec![],
        vec![],
    )
    .expect("mesh");
    let si = hit(m);
    assert!(
        si.shading.n.x > 0.0 && si.shading.n.y > 0.0 && (si.shading.n.length() - 1.0).abs() < 1e-5
    );
    assert!(si.shading.dndu.length() > 0.0);
    assert!(dot(si.shading.dpdu, si.shading.n).abs() < 1e-5);

    // A mirroring transformation swaps handedness; normals stay outward.
    let (m, _) = TriangleMesh::new(
        &Transform::scale(-1.0, 1.0, 1.0),
        false,
        vec![],
        p,
        vec![],
        vec![],
        vec![],
        vec![],
    )
    .expect("mesh");
    assert!(m.transform_swaps_handedness);
    let mirrored = Ray::new(Point3f::new(-0.7, 0.2, 2.0), Vector3f::new(0.0, 0.0, -1.0));
    let si = Triangle::new(m, 0)
        .intersect(&mirrored, Float::INFINITY)
        .expect("hit")
        .intr;
    assert!(si.n.z > 0.0);

    // Degenerate uvs fall back to a frame around the normal.
    let (m, _) = TriangleMesh::new(
        &id,
        false,
        vec![],
        vec![
            Point3f::new(0.0, 0.0, 0.0),
            Point3f::new(1.0, 0.0, 0.0),
            Point3f::new(1.0, 1.0, 0.0),
        ],
        vec![],
        vec![],
        vec![Point2f::new(0.5, 0.5); 3],
        vec![],
    )
    .expect("mesh");
    let si = hit(m);
    assert!(si.dpdu.length() > 0.0 && si.dpdv.length() > 0.0 && !si.dpdu.has_nan());
    assert!(dot(si.dpdu, si.n).abs() < 1e-5);
}

#[test]
fn solid_angle_matches_monte_carlo() {
    let mut r = Rng::new(15, 0);
    for _ in 0..4 {
        let tri = random_triangle(&mut r);
        let p = rp(&mut r, 1.5);
        let sa = tri.solid_angle(p);
        let n = 100_000;
        let hits = (0..n)
            .filter(|_| {
                tri.intersect_p(
                    &Ray::new(p, sample_uniform_sphere(ru(&mut r))),
                    Float::INFINITY,
                )
            })
            .count();
        let frac = hits as Float / n as Float;
        let sigma = 4.0 * PI * (frac * (1.0 - frac) / n as Float).sqrt();
        assert!(
            (4.0 * PI * frac - sa).abs() < 4.0 * sigma + 1e-3,
            "mc {} sa {sa}",
            4.0 * PI * frac
        );
    }
}

fn contexts(r: &mut Rng, tri: &Triangle) -> Vec<ShapeSampleContext> {
    let mut v = Vec::new();
    for k in 0..4 {
        let scale = if k < 2 { 2.0 } else { 60.0 };
        let mut ctx = ShapeSampleContext::from_point(
            Point3f::from(Vector3f::from(rp(r, 1.0)).normalize() * scale)
                + Vector3f::from(tri.vertices()[0]),
            0.0,
        );
        if k % 2 == 1 {
            let n = Normal3f::from(sample_uniform_sphere(ru(r)));
            ctx.n = n;
            ctx.ns = n;
        }
        v.push(ctx);
    }
    v
}

#[test]
fn sample_pdf_matches_pdf_and_integrates_to_one() {
    let mut r = Rng::new(16, 0);
    let (mut spherical, mut by_area) = (0, 0);
    for _ in 0..6 {
        let tri = random_triangle(&mut r);
        for ctx in contexts(&mut r, &tri) {
            let sa = tri.solid_angle(ctx.p());
            if sa < MIN_SPHERICAL_SAMPLE_AREA {
                by_area += 1;
            } else {
                spherical += 1;
            }
            let n = 4000;
            let (mut bad, mut inv_pdf_sum) = (0, 0.0f64);
            for _ in 0..n {
                let Some(ss) = tri.sample(&ctx, ru(&mut r)) else {
                    continue;
                };
                assert!(ss.pdf > 0.0 && ss.pdf.is_finite());
                let wi = (ss.p() - ctx.p()).normalize();
                let pdf = tri.pdf(&ctx, wi);
                if (pdf - ss.pdf).abs() > 1e-2 * ss.pdf {
                    bad += 1;
                }
                inv_pdf_sum += 1.0 / ss.pdf as f64;
            }
            assert!(
                bad < n / 100,
                "{bad} of {n} sample pdfs disagree with pdf() (solid angle {sa})"
            );
            // E[1/pdf] is the solid angle.
            let est = inv_pdf_sum / n as f64;
            assert!(
                (est - sa as f64).abs() < 0.05 * sa as f64,
                "E[1/pdf] {est} vs {sa}"
            );

            // ∫ pdf dω = 1, by uniform directions in a cone around the
            // triangle.
            let cone = DirectionCone::bound_subtended_directions(&tri.bounds(), ctx.p());
            let frame = Frame::from_z(cone.w);
            let m = 50_000;
            let total: f64 = (0..m)
                .map(|_| {
                    let w = frame.from_local(sample_uniform_cone(ru(&mut r), cone.cos_theta));
                    tri.pdf(&ctx, w) as f64
                })
                .sum::<f64>()
                / (m as f64 * uniform_cone_pdf(cone.cos_theta) as f64);
            assert!(
                (total - 1.0).abs() < 0.04,
                "∫pdf = {total} (solid angle {sa})"
            );
        }
    }
    assert!(spherical > 0 && by_area > 0, "{spherical} {by_area}");
}

#[test]
fn area_sampling() {
    let mut r = Rng::new(17, 0);
    for _ in 0..10 {
        let tri = random_triangle(&mut r);
        let [p0, p1, p2] = tri.vertices();
        let n = 2000;
        let mut inv = 0.0f64;
        for _ in 0..n {
            let ss = tri.sample_area(ru(&mut r)).expect("sample");
            inv += 1.0 / ss.pdf as f64;
            // The point lies in the triangle's plane, inside it.
            let q = ss.p();
            let nn = cross(p1 - p0, p2 - p0).normalize();
            assert!(dot(q - p0, nn).abs() < 1e-5);
            let a = cross(p1 - q, p2 - q).length()
                + cross(p2 - q, p0 - q).length()
                + cross(p0 - q, p1 - q).length();
            assert!((0.5 * a - tri.area()).abs() < 1e-4 * (1.0 + tri.area()));
            assert!((ss.n.length() - 1.0).abs() < 1e-5);
            assert!((Vector3f::from(ss.n) - tri.normal_bounds().w).length() < 1e-5);
        }
        assert!((inv / n as f64 - tri.area() as f64).abs() < 1e-4 * tri.area() as f64);
    }
}

/// An emitter's copy samples exactly as the mesh triangle: the same
/// points, errors, normals, uvs and densities, bit for bit, for meshes
/// with and without vertex normals and uvs, reversed or not, from
/// contexts near and far (spherical and area sampling), with and without
/// a shading normal. Triangles whose orientation is not uniform have no
/// copy.
#[test]
fn sampled_triangle_matches_mesh_triangle() {
    let mut r = Rng::with_sequence(21);
    let (mut compared, mut none) = (0, 0);
    for case in 0..200 {
        let p = vec![rp(&mut r, 1.0), rp(&mut r, 1.0), rp(&mut r, 1.0)];
        let nf = cross(p[1] - p[0], p[2] - p[0]).normalize();
        let normals = match case % 4 {
            0 => vec![],
            1 => vec![Normal3f::from(nf + Vector3f::new(0.1, -0.2, 0.05)); 3],
            2 => vec![Normal3f::from(-nf); 3],
            _ => (0..3)
                .map(|_| Normal3f::from(Vector3f::from(rp(&mut r, 1.0))))
                .collect(),
        };
        let uv = if case % 3 == 0 {
            vec![]
        } else {
            (0..3).map(|_| ru(&mut r)).collect()
        };
        let Ok((m, _)) = TriangleMesh::new(
            &Transform::default(),
            case % 5 == 0,
            vec![0, 1, 2],
            p,
            vec![],
            normals,
            uv,
            vec![],
        ) else {
            continue;
        };
        let tri = Triangle::new(m, 0);
        let Some(copy) = SampledTriangle::new(&tri) else {
            none += 1;
            continue;
        };
        for ctx in contexts(&mut r, &tri) {
            for _ in 0..8 {
                let u = ru(&mut r);
                let (a, b) = (tri.sample(&ctx, u), copy.sample(&ctx, u));
                let bits = |s: &ShapeSample| {
                    let (p, e) = (s.p(), s.pi.error());
                    [
                        p.x, p.y, p.z, e.x, e.y, e.z, s.n.x, s.n.y, s.n.z, s.uv.x, s.uv.y, s.pdf,
                    ]
                    .map(Float::to_bits)
                };
                assert_eq!(a.as_ref().map(bits), b.as_ref().map(bits), "case {case}");
                compared += 1;
            }
        }
    }
    assert!(compared > 5000 && none > 10, "{compared} {none}");
}

/// A quad of two triangles in the z = 0 plane with normals along −z (the
/// side opposite the winding's): one normal non-finite and one zero are
/// recomputed from the triangles around them, turned to −z like the good
/// ones; a NaN tangent is dropped and a NaN uv set to (0, 0), each kind
/// with one warning giving the count.
#[test]
fn flawed_vertex_data_is_mended_with_warnings() {
    let id = Transform::identity();
    let p = vec![
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 0.0, 0.0),
        Point3f::new(1.0, 1.0, 0.0),
        Point3f::new(0.0, 1.0, 0.0),
    ];
    let down = Normal3f::new(0.0, 0.0, -1.0);
    let n = vec![
        down,
        Normal3f::new(Float::NAN, 0.0, 0.0),
        Normal3f::new(0.0, 0.0, 0.0),
        down,
    ];
    let s = vec![
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(Float::INFINITY, 0.0, 0.0),
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(1.0, 0.0, 0.0),
    ];
    let uv = vec![
        Point2f::new(0.0, 0.0),
        Point2f::new(1.0, 0.0),
        Point2f::new(Float::NAN, 1.0),
        Point2f::new(0.0, 1.0),
    ];
    let (m, w) = TriangleMesh::new(&id, false, vec![0, 1, 2, 0, 2, 3], p, s, n, uv, vec![])
        .expect("flawed data renders");
    let ns = m.n.as_ref().expect("normals kept");
    for (i, v) in ns.iter().enumerate() {
        assert!(
            (v.z + 1.0).abs() < 1e-6 && v.x.abs() < 1e-6,
            "normal {i}: {v:?}"
        );
    }
    let ss = m.s.as_ref().expect("tangents kept");
    assert_eq!(ss[1], Vector3f::default());
    assert_eq!(ss[0], Vector3f::new(1.0, 0.0, 0.0));
    let uvs = m.uv.as_ref().expect("uvs kept");
    assert_eq!(uvs[2], Point2f::new(0.0, 0.0));
    assert_eq!(w.len(), 3, "{w:?}");
    assert!(w[0].contains("2 of 4 normals"), "{w:?}");
    assert!(w[1].contains("1 of 4 tangents"), "{w:?}");
    assert!(w[2].contains("1 of 4 texture coordinates"), "{w:?}");
    // The mended mesh shades like the intact one.
    let tri = Triangle::new(m.clone(), 1);
    let ray = Ray::new(Point3f::new(0.6, 0.7, 1.0), Vector3f::new(0.0, 0.0, -1.0));
    let hit = tri.intersect(&ray, Float::INFINITY).expect("hit");
    let sn = hit.intr.shading.n;
    assert!((sn.z + 1.0).abs() < 1e-5, "shading normal {sn:?}");
}

/// The batched solid-angle sampling of many triangles gives, at every SIMD
/// width, the samples `SampledTriangle::sample` gives one at a time, bit
/// for bit (reference points near and far, with and without a normal,
/// including ones that fall back to sampling by area).
#[test]
fn batched_solid_angle_samples_match_single_ones() {
    let mut r = Rng::with_sequence(33);
    let mut tris = Vec::new();
    while tris.len() < 40 {
        let p = vec![rp(&mut r, 1.0), rp(&mut r, 1.0), rp(&mut r, 1.0)];
        let Ok((m, _)) = TriangleMesh::new(
            &Transform::default(),
            false,
            vec![0, 1, 2],
            p,
            vec![],
            vec![],
            vec![],
            vec![],
        ) else {
            continue;
        };
        if let Some(t) = SampledTriangle::new(&Triangle::new(m, 0)) {
            tris.push(t);
        }
    }
    let mut cases = Vec::new();
    for k in 0..tris.len() {
        for j in 0..50 {
            let scale = [0.5, 2.0, 30.0, 0.05][j % 4];
            let p = Point3f::from(Vector3f::from(rp(&mut r, 1.0)) * scale);
            let ns = if j % 5 == 0 {
                Normal3f::default()
            } else {
                Normal3f::from(Vector3f::from(rp(&mut r, 1.0)).normalize())
            };
            let ctx = ShapeSampleContext {
                pi: Point3fi::from(p),
                n: ns,
                ns,
                time: 0.0,
            };
            cases.push((k, ctx, ru(&mut r)));
        }
    }
    let queries: Vec<_> = cases
        .iter()
        .map(|(k, ctx, u)| tris[*k].solid_angle_query(ctx, *u))
        .collect();
    let bits = |s: &Option<ShapeSample>| {
        s.map(|s| [s.p().x, s.p().y, s.p().z, s.pdf, s.uv.x, s.uv.y].map(f32::to_bits))
    };
    let (mut by_area, mut sampled, mut toward) = (0, 0, 0);
    for level in crate::simd::SimdLevel::available() {
        let mut points = Vec::new();
        sample_solid_angle_points(level, &queries, &mut points);
        assert_eq!(points.len(), cases.len());
        for ((k, ctx, u), point) in cases.iter().zip(&points) {
            let single = tris[*k].sample(ctx, *u);
            let batched = tris[*k].finish_sample(ctx, *u, point.core);
            assert_eq!(bits(&single), bits(&batched), "{level:?}: {ctx:?} {u:?}");
            by_area += point.core.by_area as usize;
            sampled += single.is_some() as usize;
            // The point and the direction to it, as a light's sample
            // finds them.
            let Some(ss) = single.filter(|_| point.core.ok && !point.core.by_area) else {
                continue;
            };
            let interval =
                |i: rpbrt_geometry::interval::Interval| [i.low, i.high].map(f32::to_bits);
            for (a, b) in [
                (ss.pi.x, point.pi.x),
                (ss.pi.y, point.pi.y),
                (ss.pi.z, point.pi.z),
            ] {
                assert_eq!(interval(a), interval(b), "{level:?}: {ctx:?} {u:?}");
            }
            let d = ss.p() - ctx.p();
            let expect_toward = !(ss.pdf == 0.0 || d.length_squared() == 0.0);
            assert_eq!(point.toward, expect_toward);
            if expect_toward {
                let wi = d.normalize();
                assert_eq!(
                    [wi.x, wi.y, wi.z].map(f32::to_bits),
                    [point.wi.x, point.wi.y, point.wi.z].map(f32::to_bits)
                );
                toward += 1;
            }
        }
    }
    assert!(toward > 0, "{toward}");
    assert!(by_area > 0 && sampled > by_area, "{by_area} {sampled}");
}
