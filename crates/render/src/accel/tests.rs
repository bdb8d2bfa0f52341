//! Cross-checks of every structure against brute force (obvhs
//! `tests/mod.rs` style), degenerate inputs, determinism, and a throughput
//! figure (`cargo test --release -- --ignored accel_throughput --nocapture`).

use super::*;
use crate::rng::Rng;
use rpbrt_geometry::{cross, dot, Point3f, Vector3f};

type Tri = [Point3f; 3];

fn pt(r: &mut Rng, lo: Float, hi: Float) -> Point3f {
    let mut u = || lo + (hi - lo) * r.uniform_float();
    Point3f::new(u(), u(), u())
}

/// Möller–Trumbore; hits strictly inside `(0, t_max)`.
fn tri_hit(tri: &Tri, ray: &Ray, t_max: Float) -> Option<Float> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = cross(ray.d, e2);
    let det = dot(e1, p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.o - tri[0];
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(ray.d, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, q) * inv;
    (t > 0.0 && t < t_max).then_some(t)
}

fn tri_bounds(t: &Tri) -> Bounds3f {
    Bounds3f::new(t[0], t[1]).union_point(t[2])
}

/// A box primitive: hit at its entry distance (0 when the origin is inside).
fn box_hit(b: &Bounds3f, ray: &Ray, t_max: Float) -> Option<Float> {
    let (t0, _) = b.intersect_p(ray.o, ray.d, t_max)?;
    (t0 < t_max).then_some(t0)
}

fn random_tris(seed: u64, n: usize, size: Float) -> Vec<Tri> {
    let mut r = Rng::with_sequence(seed);
    (0..n)
        .map(|_| {
            let c = pt(&mut r, 0.0, 1.0);
            let s = size * (0.2 + r.uniform_float());
            let mut off = || {
                Vector3f::new(
                    r.uniform_float() - 0.5,
                    r.uniform_float() - 0.5,
                    r.uniform_float() - 0.5,
                ) * s
            };
            [c + off(), c + off(), c + off()]
        })
        .collect()
}

/// Rays with origins around `[0, 1]³`: random directions, axis-parallel
/// ones, some with t_max of 0 or finite, most infinite.
fn random_rays(seed: u64, n: usize) -> Vec<(Ray, Float)> {
    let mut r = Rng::with_sequence(seed);
    (0..n)
        .map(|i| {
            let o = pt(&mut r, -0.5, 1.5);
            let mut d = pt(&mut r, -1.0, 1.0) - Point3f::new(0.0, 0.0, 0.0);
            if i % 7 == 0 {
                let a = (i / 7) % 3;
                let s = if i % 2 == 0 { 1.0 } else { -1.0 };
                d = Vector3f::new(0.0, 0.0, 0.0);
                d[a] = s;
            } else if i % 11 == 0 {
                d[(i / 11) % 3] = 0.0;
            } else if i % 5 == 0 {
                // Aim at the scene so that most rays hit something.
                d = pt(&mut r, 0.2, 0.8) - o;
            }
            let t_max = match i % 13 {
                0 => 0.0,
                1 => 0.5 * r.uniform_float(),
                _ => Float::INFINITY,
            };
            (Ray::new(o, d), t_max)
        })
        .collect()
}

/// Every structure and parameter set under test.
fn all_accels(bounds: &[Bounds3f]) -> Vec<(String, Accelerator)> {
    let mut v = Vec::new();
    for method in ["sah", "hlbvh", "middle", "equal"] {
        for (maxp, width) in [(1, 4), (4, 4), (1, 8), (4, 8), (1, 2), (4, 2)] {
            let p = AccelParams::parse(
                "bvh",
                [
                    ("splitmethod", ParamValue::Str(method)),
                    ("maxnodeprims", ParamValue::Int(maxp)),
                    ("width", ParamValue::Int(width)),
                ],
            )
            .unwrap();
            v.push((
                format!("bvh{width} {method} {maxp}"),
                Accelerator::build(bounds, &p),
            ));
        }
    }
    v.push((
        "kdtree".into(),
        Accelerator::build(bounds, &AccelParams::new("kdtree").unwrap()),
    ));
    let p = AccelParams::parse(
        "kdtree",
        [
            ("maxprims", ParamValue::Int(4)),
            ("emptybonus", ParamValue::Float(0.0)),
        ],
    )
    .unwrap();
    v.push(("kdtree maxprims 4".into(), Accelerator::build(bounds, &p)));
    v.push((
        "grid".into(),
        Accelerator::build(bounds, &AccelParams::new("grid").unwrap()),
    ));
    let p = AccelParams::parse("grid", [("maxvoxels", ParamValue::Int(4))]).unwrap();
    v.push(("grid coarse".into(), Accelerator::build(bounds, &p)));
    // Embree over user geometry only (its triangles: see
    // `embree_triangles_match_brute_force`).
    #[cfg(feature = "embree")]
    v.push((
        "embree".into(),
        Accelerator::build(bounds, &AccelParams::new("embree").unwrap()),
    ));
    v
}

/// Checks `accel` against a loop over all primitives: the same nearest `t`
/// (a different primitive only at the same `t`) and the same occlusion.
fn check_against_brute<H>(
    name: &str,
    accel: &Accelerator,
    n: usize,
    rays: &[(Ray, Float)],
    hit: H,
) -> usize
where
    H: Fn(u32, &Ray, Float) -> Option<Float>,
{
    let mut n_hits = 0;
    let mut singles = Vec::with_capacity(rays.len());
    for (k, (ray, t_max)) in rays.iter().enumerate() {
        let mut brute: Option<(u32, Float)> = None;
        for p in 0..n as u32 {
            let cur = brute.map_or(*t_max, |b| b.1);
            if let Some(t) = hit(p, ray, cur) {
                brute = Some((p, t));
            }
        }
        let mut calls = 0usize;
        let got = accel.intersect(ray, *t_max, |p, r, t| {
            calls += 1;
            hit(p, r, t)
        });
        match (brute, got) {
            (None, None) => {}
            (Some((bp, bt)), Some((gp, gt))) => {
                assert_eq!(
                    bt, gt,
                    "{name}: ray {k} {ray:?}: t differs (brute prim {bp}, got {gp})"
                );
                n_hits += 1;
            }
            _ => panic!("{name}: ray {k} {ray:?} t_max {t_max}: brute {brute:?}, got {got:?}"),
        }
        let any = accel.intersect_p(ray, *t_max, |p, r, t| hit(p, r, t).is_some());
        assert_eq!(any, brute.is_some(), "{name}: ray {k} {ray:?}: intersect_p");
        // The slot variants find the same, and each slot names its entry.
        let entry_of = |slot: u32| match accel.slot_entries() {
            Some(order) => order[slot as usize],
            None => slot,
        };
        let by_slot = accel.intersect_slots(ray, *t_max, |s, p, r, t| {
            assert_eq!(entry_of(s), p, "{name}: slot {s}");
            hit(p, r, t)
        });
        assert_eq!(by_slot, got, "{name}: ray {k}: intersect_slots");
        let any_slot = accel.intersect_p_slots(ray, *t_max, |s, p, r, t| {
            assert_eq!(entry_of(s), p, "{name}: slot {s}");
            hit(p, r, t).is_some()
        });
        assert_eq!(any_slot, any, "{name}: ray {k}: intersect_p_slots");
        singles.push(got);
    }
    match accel {
        Accelerator::Bvh4(bvh) => {
            check_packets(name, bvh, rays, &singles, &hit);
            check_levels(name, bvh, rays, &singles, &hit);
        }
        Accelerator::Bvh8(bvh) => {
            check_packets(name, bvh, rays, &singles, &hit);
            check_levels(name, bvh, rays, &singles, &hit);
        }
        _ => {}
    }
    n_hits
}

/// The wide BVH's packet traversal, at every width this processor runs:
/// 16 rays a call (two packets of 8, four of 4, or sixteen single lanes),
/// each ray's hit at the single ray's distance.
fn check_packets<const W: usize, H>(
    name: &str,
    bvh: &WideBvh<W>,
    rays: &[(Ray, Float)],
    singles: &[Option<(u32, Float)>],
    hit: &H,
) where
    H: Fn(u32, &Ray, Float) -> Option<Float>,
{
    for level in crate::simd::SimdLevel::available() {
        for (g, group) in rays.chunks(16).enumerate() {
            let rs: Vec<Ray> = group.iter().map(|(r, _)| *r).collect();
            let mut t_max: Vec<Float> = group.iter().map(|(_, t)| *t).collect();
            let mut best = vec![None; rs.len()];
            bvh.intersect_packet(level, &rs, &mut t_max, &mut best, |lane, s, p, r, t| {
                assert_eq!(bvh.prim_indices()[s as usize], p, "{name}: packet slot {s}");
                assert_eq!(*r, rs[lane]);
                hit(p, r, t)
            });
            for (lane, b) in best.iter().enumerate() {
                let k = 16 * g + lane;
                assert_eq!(
                    b.map(|b| b.1),
                    singles[k].map(|s| s.1),
                    "{name}: {level:?} packet: ray {k} {:?}",
                    rays[k]
                );
            }
        }
    }
}

/// The wide BVH's single-ray traversals compiled for every level this
/// processor runs: the same hits (primitive and distance) and occlusion.
fn check_levels<const W: usize, H>(
    name: &str,
    bvh: &WideBvh<W>,
    rays: &[(Ray, Float)],
    singles: &[Option<(u32, Float)>],
    hit: &H,
) where
    H: Fn(u32, &Ray, Float) -> Option<Float>,
{
    for level in crate::simd::SimdLevel::available() {
        for (k, (ray, t_max)) in rays.iter().enumerate() {
            let got = bvh.intersect_slots_at(level, ray, *t_max, |s, p, r, t| {
                assert_eq!(bvh.prim_indices()[s as usize], p, "{name}: slot {s}");
                hit(p, r, t)
            });
            assert_eq!(got, singles[k], "{name}: {level:?}: ray {k} {ray:?}");
            let any =
                bvh.intersect_p_slots_at(level, ray, *t_max, |_, p, r, t| hit(p, r, t).is_some());
            assert_eq!(any, got.is_some(), "{name}: {level:?}: ray {k}: occlusion");
        }
        // The interleaved search of a batch: the same occlusion, each
        // candidate handed with its own ray's index (batches of several
        // lengths, so that tracks are refilled mid-batch or left idle).
        for chunk in [1, 5, 8, 13, rays.len().max(1)] {
            for (c, batch) in rays.chunks(chunk).enumerate() {
                let mut out = vec![true; batch.len()];
                let mut tested = 0;
                bvh.intersect_ps_stream_at(
                    level,
                    batch,
                    &mut out,
                    |k, s, p, r, t| {
                        assert_eq!(bvh.prim_indices()[s as usize], p, "{name}: slot {s}");
                        assert_eq!((*r, t), batch[k], "{name}: ray {k} of the batch");
                        tested += 1;
                        hit(p, r, t).is_some()
                    },
                    |_, _| {},
                );
                for (j, &blocked) in out.iter().enumerate() {
                    let k = c * chunk + j;
                    let want = singles[k].is_some();
                    assert_eq!(
                        blocked, want,
                        "{name}: {level:?}: batch of {chunk}: ray {k}"
                    );
                }
                assert!(tested > 0 || out.iter().all(|b| !b), "{name}");
            }
        }
    }
}

fn check_all<H>(bounds: &[Bounds3f], rays: &[(Ray, Float)], hit: H, min_hits: usize)
where
    H: Fn(u32, &Ray, Float) -> Option<Float> + Copy,
{
    for (name, accel) in all_accels(bounds) {
        assert_eq!(accel.primitive_count(), bounds.len(), "{name}");
        let hits = check_against_brute(&name, &accel, bounds.len(), rays, hit);
        assert!(hits >= min_hits, "{name}: only {hits} hits, test too weak");
    }
}

#[test]
fn node_sizes() {
    assert_eq!(std::mem::size_of::<BvhNode>(), 32);
    assert_eq!(std::mem::size_of::<Bvh4Node>(), 128);
    assert_eq!(std::mem::size_of::<Bvh8Node>(), 256);
    assert_eq!(std::mem::size_of::<KdNode>(), 8);
}

#[test]
fn random_triangles_match_brute_force() {
    let tris = random_tris(1, 2000, 0.12);
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let rays = random_rays(2, 2500);
    check_all(
        &bounds,
        &rays,
        |p, r, t| tri_hit(&tris[p as usize], r, t),
        250,
    );
}

#[test]
fn mixed_sizes_match_brute_force() {
    // Small triangles plus a few spanning the scene: many grid voxels and
    // kd-tree leaves share the big ones (mailboxing, straddling).
    let mut tris = random_tris(3, 800, 0.03);
    tris.extend(random_tris(4, 25, 1.5));
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let rays = random_rays(5, 2000);
    check_all(
        &bounds,
        &rays,
        |p, r, t| tri_hit(&tris[p as usize], r, t),
        500,
    );
}

#[test]
fn random_boxes_rays_starting_inside() {
    let mut r = Rng::with_sequence(6);
    let boxes: Vec<Bounds3f> = (0..600)
        .map(|_| {
            let c = pt(&mut r, 0.0, 1.0);
            Bounds3f::new(c, c + Vector3f::new(0.1, 0.05, 0.2) * r.uniform_float())
        })
        .collect();
    let mut rays = random_rays(7, 1500);
    // Origins inside boxes.
    for (i, (ray, _)) in rays.iter_mut().enumerate().take(300) {
        ray.o = boxes[i].lerp(Point3f::new(0.3, 0.6, 0.5));
    }
    check_all(
        &boxes,
        &rays,
        |p, r, t| box_hit(&boxes[p as usize], r, t),
        300,
    );
}

#[test]
fn no_primitives() {
    let rays = random_rays(8, 50);
    for (name, a) in all_accels(&[]) {
        assert!(a.bounds().is_empty(), "{name}");
        for (ray, t) in &rays {
            assert!(a.intersect(ray, *t, |_, _, _| panic!("no prims")).is_none());
            assert!(!a.intersect_p(ray, *t, |_, _, _| panic!("no prims")));
        }
    }
}

#[test]
fn one_primitive() {
    let tris = [[
        Point3f::new(0.0, 0.0, 0.5),
        Point3f::new(1.0, 0.0, 0.5),
        Point3f::new(0.0, 1.0, 0.5),
    ]];
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let rays = random_rays(9, 1000);
    check_all(
        &bounds,
        &rays,
        |p, r, t| tri_hit(&tris[p as usize], r, t),
        20,
    );
}

#[test]
fn identical_boxes() {
    let b = Bounds3f::new(Point3f::new(0.2, 0.3, 0.4), Point3f::new(0.6, 0.5, 0.9));
    let boxes = vec![b; 2000];
    let rays = random_rays(10, 300);
    check_all(
        &boxes,
        &rays,
        |p, r, t| box_hit(&boxes[p as usize], r, t),
        10,
    );
}

#[test]
fn flat_and_point_boxes() {
    let mut r = Rng::with_sequence(11);
    let mut boxes = Vec::new();
    for i in 0..400 {
        let c = pt(&mut r, 0.0, 1.0);
        let e = Vector3f::new(0.1, 0.1, 0.1) * r.uniform_float();
        let mut hi = c + e;
        match i % 4 {
            0 => hi.z = c.z,
            1 => hi.x = c.x,
            2 => hi = c,
            _ => {
                // Coplanar flat boxes in z = 0.5.
                boxes.push(Bounds3f::new(
                    Point3f::new(c.x, c.y, 0.5),
                    Point3f::new(hi.x, hi.y, 0.5),
                ));
                continue;
            }
        }
        boxes.push(Bounds3f::new(c, hi));
    }
    let mut rays = random_rays(12, 1500);
    // Rays aimed exactly at the point boxes.
    for (i, (ray, _)) in rays.iter_mut().enumerate().take(200) {
        let target = boxes[(i * 4 + 2) % boxes.len()].p_min;
        ray.d = target - ray.o;
    }
    check_all(
        &boxes,
        &rays,
        |p, r, t| box_hit(&boxes[p as usize], r, t),
        150,
    );
    // Every primitive on one line: zero-area nodes.
    let line: Vec<Bounds3f> = (0..300)
        .map(|i| Bounds3f::from_point(Point3f::new(i as Float * 0.01, 0.25, 0.75)))
        .collect();
    let rays: Vec<(Ray, Float)> = (0..300)
        .map(|i| {
            let target = line[i].p_min;
            let o = Point3f::new(0.5, -1.0, 0.3 + 0.001 * i as Float);
            (Ray::new(o, target - o), Float::INFINITY)
        })
        .collect();
    check_all(&line, &rays, |p, r, t| box_hit(&line[p as usize], r, t), 0);
}

#[test]
fn axis_aligned_rays_on_box_faces() {
    // Unit boxes on an integer lattice; rays along the axes through lattice
    // coordinates lie exactly in box faces and in split planes.
    let mut boxes = Vec::new();
    for x in 0..6 {
        for y in 0..6 {
            for z in 0..3 {
                if (x + 2 * y + z) % 3 != 0 {
                    let p = Point3f::new(x as Float, y as Float, z as Float);
                    boxes.push(Bounds3f::new(p, p + Vector3f::new(1.0, 1.0, 1.0)));
                }
            }
        }
    }
    let mut rays = Vec::new();
    for a in 0..3 {
        for i in 0..7 {
            for j in 0..7 {
                for s in [-1.0, 1.0] {
                    let mut o = Point3f::new(i as Float, j as Float, 1.0 + 0.5 * (i % 2) as Float);
                    o[a] = if s > 0.0 { -2.0 } else { 9.0 };
                    let mut d = Vector3f::new(0.0, 0.0, 0.0);
                    d[a] = s;
                    rays.push((Ray::new(o, d), Float::INFINITY));
                }
            }
        }
    }
    check_all(
        &boxes,
        &rays,
        |p, r, t| box_hit(&boxes[p as usize], r, t),
        50,
    );
}

#[test]
fn huge_coordinates() {
    // Triangles at 1e9 (Möller–Trumbore's triple products stay finite),
    // boxes at 1e30.
    for (scale, boxes) in [(1e9, false), (1e30, true)] {
        let s = |p: Point3f| Point3f::new(p.x * scale, p.y * scale, p.z * scale);
        let tris: Vec<Tri> = random_tris(13, 500, 0.1)
            .into_iter()
            .map(|t| t.map(s))
            .collect();
        let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
        let rays: Vec<(Ray, Float)> = random_rays(14, 1500)
            .into_iter()
            .map(|(r, t)| (Ray::new(s(r.o), r.d), t * scale))
            .collect();
        if boxes {
            check_all(
                &bounds,
                &rays,
                |p, r, t| box_hit(&bounds[p as usize], r, t),
                150,
            );
        } else {
            check_all(
                &bounds,
                &rays,
                |p, r, t| tri_hit(&tris[p as usize], r, t),
                40,
            );
        }
    }
}

#[test]
fn unusable_bounds_are_skipped() {
    let mut tris = random_tris(15, 300, 0.3);
    let mut bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let nan = Float::NAN;
    bounds[3] = Bounds3f {
        p_min: Point3f::new(nan, 0.0, 0.0),
        p_max: Point3f::new(1.0, 1.0, 1.0),
    };
    bounds[7].p_max.y = Float::INFINITY;
    bounds[11] = Bounds3f::empty();
    for i in [3, 7, 11] {
        // Move those triangles away so brute force cannot hit them either.
        tris[i] = [Point3f::new(1e6, 1e6, 1e6); 3];
    }
    for (name, a) in all_accels(&bounds) {
        assert_eq!(a.skipped_primitives(), 3, "{name}");
        assert!(a.memory_bytes() > 0);
    }
    let rays = random_rays(16, 1000);
    check_all(
        &bounds,
        &rays,
        |p, r, t| tri_hit(&tris[p as usize], r, t),
        40,
    );
}

#[test]
fn bvh_depth_is_bounded() {
    // Exponentially spaced boxes: each SAH split peels off few primitives.
    let boxes: Vec<Bounds3f> = (0..3000)
        .map(|i| {
            let x = (1.02 as Float).powi(i);
            Bounds3f::new(Point3f::new(x, 0.0, 0.0), Point3f::new(x * 1.001, 1.0, 1.0))
        })
        .collect();
    for method in [SplitMethod::Sah, SplitMethod::Hlbvh, SplitMethod::Middle] {
        let bvh = Bvh::build(
            &boxes,
            &BvhParams {
                split_method: method,
                max_prims_in_node: 1,
                ..Default::default()
            },
        );
        assert!(
            bvh.depth() <= bvh::STACK_SIZE,
            "{method:?}: depth {}",
            bvh.depth()
        );
    }
    let rays: Vec<(Ray, Float)> = (0..200)
        .map(|i| {
            let x = (1.02 as Float).powi(i * 15) * 1.0005;
            (
                Ray::new(Point3f::new(x, 0.5, -1.0), Vector3f::new(0.0, 0.0, 1.0)),
                Float::INFINITY,
            )
        })
        .collect();
    check_all(
        &boxes,
        &rays,
        |p, r, t| box_hit(&boxes[p as usize], r, t),
        150,
    );
}

#[test]
fn builds_are_deterministic() {
    let tris = random_tris(17, 30000, 0.02);
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    for method in [
        SplitMethod::Sah,
        SplitMethod::Hlbvh,
        SplitMethod::Middle,
        SplitMethod::EqualCounts,
    ] {
        let p = BvhParams {
            split_method: method,
            max_prims_in_node: 4,
            ..Default::default()
        };
        let a = Bvh::build_with_threads(&bounds, &p, 1);
        let b = Bvh::build_with_threads(&bounds, &p, 4);
        let c = Bvh::build_with_threads(&bounds, &p, 3);
        assert!(
            a.nodes() == b.nodes() && a.nodes() == c.nodes(),
            "{method:?}"
        );
        assert!(a.prim_indices() == b.prim_indices() && a.prim_indices() == c.prim_indices());
        let w1 = Bvh4::build_with_threads(&bounds, &p, 1);
        let w3 = Bvh4::build_with_threads(&bounds, &p, 3);
        assert!(w1.nodes() == w3.nodes() && w1.prim_indices() == w3.prim_indices());
        let e1 = Bvh8::build_with_threads(&bounds, &p, 1);
        let e3 = Bvh8::build_with_threads(&bounds, &p, 3);
        assert!(e1.nodes() == e3.nodes() && e1.prim_indices() == w1.prim_indices());
        assert!(
            w1.prim_indices() == a.prim_indices(),
            "{method:?}: same leaves"
        );
    }
    let k1 = KdTree::build(&bounds[..5000], &KdTreeParams::default());
    let k2 = KdTree::build(&bounds[..5000], &KdTreeParams::default());
    assert_eq!(k1.nodes(), k2.nodes());
}

/// The 4-wide BVH built directly (`wide.rs`) is the binary BVH collapsed,
/// node for node and in the same order, for every split method, leaf size
/// and thread count, on random, clustered, flat and badly spread input.
#[test]
fn direct_wide_build_is_the_collapsed_binary_tree() {
    let tris = random_tris(19, 20000, 0.03);
    let mut inputs: Vec<(&str, Vec<Bounds3f>)> =
        vec![("random triangles", tris.iter().map(tri_bounds).collect())];
    // Clusters of identical boxes (coincident centroids) among others.
    let mut clustered: Vec<Bounds3f> = tris[..3000].iter().map(tri_bounds).collect();
    let cluster = Bounds3f::new(Point3f::new(0.4, 0.4, 0.4), Point3f::new(0.5, 0.5, 0.5));
    clustered.extend(std::iter::repeat_n(cluster, 6000));
    inputs.push(("clustered", clustered));
    // Zero-area boxes on a line, and exponentially spaced ones (the depth
    // guard's equal-count splits).
    inputs.push((
        "flat",
        (0..5000)
            .map(|i| {
                let p = Point3f::new(i as Float * 0.01, 0.0, 0.0);
                Bounds3f::new(p, p)
            })
            .collect(),
    ));
    inputs.push((
        "exponential",
        (0..3000)
            .map(|i| {
                let x = (1.02 as Float).powi(i);
                Bounds3f::new(Point3f::new(x, 0.0, 0.0), Point3f::new(x * 1.001, 1.0, 1.0))
            })
            .collect(),
    ));
    inputs.push(("one", vec![cluster]));
    inputs.push(("three", vec![cluster; 3]));
    for (name, bounds) in &inputs {
        for method in [
            SplitMethod::Sah,
            SplitMethod::Middle,
            SplitMethod::EqualCounts,
        ] {
            for max_prims in [1, 4, 255] {
                let p = BvhParams {
                    split_method: method,
                    max_prims_in_node: max_prims,
                    ..Default::default()
                };
                check_direct_build::<4>(name, bounds, &p);
                check_direct_build::<8>(name, bounds, &p);
            }
        }
    }
}

#[test]
fn bvh_leaves_cover_every_primitive_once() {
    let tris = random_tris(18, 5000, 0.05);
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    for method in [
        SplitMethod::Sah,
        SplitMethod::Hlbvh,
        SplitMethod::Middle,
        SplitMethod::EqualCounts,
    ] {
        let bvh = Bvh::build(
            &bounds,
            &BvhParams {
                split_method: method,
                max_prims_in_node: 4,
                ..Default::default()
            },
        );
        let mut seen = vec![0u32; bounds.len()];
        for n in bvh.nodes().iter().filter(|n| n.is_leaf()) {
            assert!(
                n.count as u32 <= 4 || method == SplitMethod::Hlbvh,
                "{method:?}: leaf of {}",
                n.count
            );
            for &p in &bvh.prim_indices()[n.offset as usize..(n.offset + n.count as u32) as usize] {
                seen[p as usize] += 1;
                let b = n.bounds();
                assert_eq!(b.union(&bounds[p as usize]), b, "{method:?}: leaf bounds");
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "{method:?}");
        // Interior bounds hold their children's.
        for (i, n) in bvh.nodes().iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let b = n.bounds();
            for c in [i + 1, n.offset as usize] {
                assert_eq!(b.union(&bvh.nodes()[c].bounds()), b);
            }
        }
    }
}

/// [`direct_wide_build_is_the_collapsed_binary_tree`] for one width.
fn check_direct_build<const W: usize>(name: &str, bounds: &[Bounds3f], p: &BvhParams) {
    let want = WideBvh::<W>::from_binary(Bvh::build_with_threads(bounds, p, 1));
    for threads in [1, 2, 3, 8] {
        let got = WideBvh::<W>::build_with_threads(bounds, p, threads);
        let what = format!(
            "{name}, {W} wide, {:?}, {} per leaf, {threads} threads",
            p.split_method, p.max_prims_in_node
        );
        assert!(got.nodes() == want.nodes(), "{what}: nodes differ");
        assert!(got.prim_indices() == want.prim_indices(), "{what}");
        assert_eq!(got.bounds(), want.bounds(), "{what}");
        // The direct build reserves one node per primitive and must never
        // outgrow it (growing would copy the tree).
        assert!(got.nodes().len() <= bounds.len().max(1), "{what}");
    }
}

#[test]
fn wide_collapse_keeps_leaves_and_bounds() {
    check_collapse::<4>();
    check_collapse::<8>();
}

fn check_collapse<const W: usize>() {
    let tris = random_tris(21, 5000, 0.05);
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    for maxp in [1, 4] {
        let p = BvhParams {
            max_prims_in_node: maxp,
            ..Default::default()
        };
        let w = WideBvh::<W>::build(&bounds, &p);
        let mut seen = vec![0u32; bounds.len()];
        let mut n_children = 0;
        // Walk from the root, checking that every child box holds what is
        // below it.
        let mut stack = vec![(0usize, w.bounds())];
        while let Some((i, outer)) = stack.pop() {
            let node = &w.nodes()[i];
            for lane in 0..W {
                let b = node.child_bounds(lane);
                if b.is_empty() {
                    continue;
                }
                n_children += 1;
                assert_eq!(outer.union(&b), outer, "child box outside its parent");
                let c = node.child[lane] as usize;
                let count = node.count[lane] as usize;
                if count > 0 {
                    for &p in &w.prim_indices()[c..c + count] {
                        seen[p as usize] += 1;
                        assert_eq!(b.union(&bounds[p as usize]), b, "leaf bounds");
                    }
                } else {
                    assert!(c > i, "children follow their parent");
                    stack.push((c, b));
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "every primitive once");
        // Collapsing fills nodes: far fewer than one per two children.
        assert!(
            w.nodes().len() * 3 < n_children,
            "{} nodes",
            w.nodes().len()
        );
    }
}

/// Throughput on a random-triangle scene (run in release, see module doc).
#[test]
#[ignore]
fn accel_throughput() {
    // RPBRT_BENCH_N sets the triangle count (default 200 000).
    let n = std::env::var("RPBRT_BENCH_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200_000);
    let tris = random_tris(19, n, 0.01);
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let rays = random_rays(20, 1_000_000);
    for (name, params) in [
        ("bvh sah", AccelParams::new("bvh").unwrap()),
        (
            "bvh hlbvh",
            AccelParams::parse("bvh", [("splitmethod", ParamValue::Str("hlbvh"))]).unwrap(),
        ),
        ("kdtree", AccelParams::new("kdtree").unwrap()),
        ("grid", AccelParams::new("grid").unwrap()),
    ] {
        let t0 = std::time::Instant::now();
        let a = Accelerator::build(&bounds, &params);
        let build = t0.elapsed().as_secs_f64();
        let t0 = std::time::Instant::now();
        let mut hits = 0usize;
        for (r, t) in &rays {
            hits += a
                .intersect(r, *t, |p, r, t| tri_hit(&tris[p as usize], r, t))
                .is_some() as usize;
        }
        let secs = t0.elapsed().as_secs_f64();
        let t0 = std::time::Instant::now();
        let mut occl = 0usize;
        for (r, t) in &rays {
            occl +=
                a.intersect_p(r, *t, |p, r, t| tri_hit(&tris[p as usize], r, t).is_some()) as usize;
        }
        let secs_p = t0.elapsed().as_secs_f64();
        let mut tests = 0usize;
        for (r, t) in rays.iter().take(10000) {
            a.intersect(r, *t, |p, r, t| {
                tests += 1;
                tri_hit(&tris[p as usize], r, t)
            });
        }
        println!(
            "{name:10} build {build:6.3} s  {:5.2} Mrays/s closest  {:5.2} Mrays/s any  {hits} hits {occl} occluded  {:.1} B/prim  {:.1} tests/ray",
            rays.len() as f64 / secs / 1e6,
            rays.len() as f64 / secs_p / 1e6,
            a.memory_bytes() as f64 / n as f64,
            tests as f64 / 10000.0
        );
    }
}

/// Embree's own triangles, each candidate refined by the closure: the
/// nearest hit must still be brute force's, on small, mixed, degenerate
/// and far-away triangles.
#[cfg(feature = "embree")]
#[test]
fn embree_triangles_match_brute_force() {
    let mut cases: Vec<(Vec<Tri>, Vec<(Ray, Float)>, usize)> = Vec::new();
    cases.push((random_tris(1, 2000, 0.12), random_rays(2, 2500), 250));
    let mut mixed = random_tris(3, 800, 0.03);
    mixed.extend(random_tris(4, 25, 1.5));
    // Degenerate: a repeated vertex, collinear, a needle.
    for (k, t) in mixed.iter_mut().enumerate().take(60) {
        match k % 3 {
            0 => t[2] = t[1],
            1 => t[2] = t[1] + (t[1] - t[0]),
            _ => t[2] = t[1] + (t[0] - t[1]) * 1e-6,
        }
    }
    cases.push((mixed, random_rays(5, 2000), 500));
    let scale: Float = 1e9;
    let s = |p: Point3f| Point3f::new(p.x * scale, p.y * scale, p.z * scale);
    let far: Vec<Tri> = random_tris(13, 500, 0.1)
        .into_iter()
        .map(|t| t.map(s))
        .collect();
    let far_rays = random_rays(14, 1500)
        .into_iter()
        .map(|(r, t)| (Ray::new(s(r.o), r.d), t * scale))
        .collect();
    cases.push((far, far_rays, 40));
    let params = AccelParams::new("embree").unwrap();
    for (k, (tris, rays, min_hits)) in cases.iter().enumerate() {
        let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
        let accel = Accelerator::build_from_triangles(
            tris.len(),
            |e| bounds[e as usize],
            |e| Some(tris[e as usize]),
            &params,
        );
        let Accelerator::Embree(e) = &accel else {
            panic!("case {k}: no Embree scene");
        };
        assert!(e.triangle_count() > 0, "case {k}");
        let hit = |p: u32, r: &Ray, t: Float| tri_hit(&tris[p as usize], r, t);
        let hits = check_against_brute(
            &format!("embree triangles {k}"),
            &accel,
            tris.len(),
            rays,
            hit,
        );
        assert!(hits >= *min_hits, "case {k}: only {hits} hits");
    }
}
