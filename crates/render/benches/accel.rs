//! Acceleration-structure throughput (plain harness:
//! `cargo bench -p rpbrt-render --bench accel`).
//!
//! Meshes: the killeroo (Loop-subdivided to ≥ 100k triangles), each
//! water-caustic PLY mesh (both from `../shared/scenes`, skipped with a
//! message when absent), and a generated ~1M-triangle terrain. Rays: 1M
//! coherent pinhole-camera rays (1000×1000) framing the mesh, and 1M
//! incoherent rays: cosine-distributed bounces from the camera rays' first
//! hits (seeded). Each structure is timed on `intersect` for both sets and on
//! `intersect_p` for the incoherent set, with 1 and 2 threads (rays split in
//! contiguous chunks across `std::thread::scope` threads), plus its build
//! rate with that many build threads.
//!
//! Every structure, obvhs' CWBVH included, calls the same hit closure:
//! `intersect_prepared_triangle` on a triangle array (with the per-ray
//! `TriangleRay`, as the renderer does), so only traversal and the
//! triangles' memory order differ: rpbrt's structures read the triangles
//! in their slot order (the 4-wide BVH's leaf order), as the renderer's
//! `PrimitiveAggregate` does, obvhs the caller's order. Output: one `RESULT` line per mesh, structure and thread count.
//!
//! Every mesh is then benchmarked again as `<mesh>-closed`: inside a closed,
//! tessellated cube around it with the camera inside, so that (nearly) all
//! bounce rays hit something, as in an interior scene; in the open sets
//! most bounce rays escape.
//!
//! With `--features embree` (needs the system's Embree 3, Debian's
//! `libembree-dev`), Embree is benchmarked on the same triangles and rays
//! as `accel=embree`: `rtcIntersect1` on both sets, `rtcOccluded1` for
//! shadow rays, and `rtcIntersect8` / `rtcIntersect16` on the camera rays in
//! 4×2 / 4×4 pixel tiles (`packet8_coherent_mrays_s`,
//! `packet16_coherent_mrays_s`). Embree uses its own (SIMD) triangle tests.
//! `accel=rpbrt-embree` is rpbrt's `Accelerator "embree"` over the same
//! triangles: Embree's traversal and triangle test, then rpbrt's triangle
//! test on each candidate in Embree's intersection filter (the renderer's
//! path; Embree's `tfar` padded as there).
//!
//! `RPBRT_ACCEL_BENCH_RES=500` shrinks the camera (and so every ray set) and
//! `RPBRT_ACCEL_BENCH_THREADS=1` limits the thread counts, for short runs.
//!
//! The kd-tree and grid trace a subset of the rays (`SLOW_RAYS`, every k-th
//! ray of each set) to keep the run short; their Mrays/s are computed from
//! the rays actually traced. `RPBRT_ACCEL_BENCH_ONLY=bvh4,obvhs` restricts
//! the structures (`embree` included), `RPBRT_ACCEL_BENCH_MESH=terrain` the meshes
//! (prefixes: `killeroo-closed` only the closed killeroo).

#[cfg(feature = "embree")]
#[path = "accel/embree.rs"]
mod embree_bench;

use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::BvhBuildParams;
use rpbrt_geometry::{
    cross, dot, Bounds3f, Float, Frame, Normal3f, Point2f, Point3f, Ray, Vector3f,
};
use rpbrt_render::accel::{AccelKind, AccelParams, Accelerator, Aggregate, ParamValue, WideBvh};
use rpbrt_render::rng::Rng;
use rpbrt_render::sampling::sample_cosine_hemisphere;
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use rpbrt_render::shape::loopsubdiv::loop_subdivide;
use rpbrt_render::shape::triangle::{
    intersect_prepared_triangle, triangle_is_nondegenerate, TriangleRay,
};
use std::path::Path;
use std::time::Instant;

type Tri = [Point3f; 3];

/// Camera resolution (rays per set: its square); `RPBRT_ACCEL_BENCH_RES`
/// overrides it (a multiple of 4, for the packet tiles).
fn res() -> usize {
    std::env::var("RPBRT_ACCEL_BENCH_RES")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
        .map_or(1000, |r| r.max(4) / 4 * 4)
}

/// Build and trace thread counts: `RPBRT_ACCEL_BENCH_THREADS=1` (a comma
/// list) overrides the default 1 and 2.
fn thread_counts() -> Vec<usize> {
    std::env::var("RPBRT_ACCEL_BENCH_THREADS")
        .ok()
        .map(|s| {
            s.split(',')
                .filter_map(|t| t.parse().ok())
                .collect::<Vec<usize>>()
        })
        .filter(|v| !v.is_empty())
        .unwrap_or(vec![1, 2])
}
/// Rays per set for the slow structures (kd-tree, grid).
const SLOW_RAYS: usize = 100_000;

struct Mesh {
    name: String,
    tris: Vec<Tri>,
    /// The bounds the camera frames (the inner mesh's for a closed
    /// variant, so that the camera sits inside the enclosure); `None`: all
    /// triangles.
    view: Option<Bounds3f>,
}

/// The triangles of an indexed mesh, less degenerate ones (which the
/// renderer leaves out of its triangle fast path too).
fn tris_from_indexed(p: &[Point3f], idx: &[u32]) -> Vec<Tri> {
    idx.chunks_exact(3)
        .map(|c| [p[c[0] as usize], p[c[1] as usize], p[c[2] as usize]])
        .filter(|t| triangle_is_nondegenerate(t[0], t[1], t[2]))
        .collect()
}

/// The killeroo's `loopsubdiv` control mesh, subdivided to ≥ 100k triangles.
fn killeroo(shared: &Path) -> Result<Mesh, String> {
    let path = shared.join("scenes/killeroos/geometry/killeroo.pbrt");
    let path = path.canonicalize().map_err(|e| format!("{path:?}: {e}"))?;
    let text = format!("WorldBegin\nInclude \"{}\"\n", path.display());
    let (scene, _) = build_scene_from_str(&text, &BuildOptions::default())
        .map_err(|d| format!("killeroo: {} diagnostics", d.items.len()))?;
    let shape = scene
        .shapes
        .iter()
        .find(|s| s.base.name == "loopsubdiv" || s.base.name == "trianglemesh")
        .ok_or("killeroo: no mesh shape")?;
    let params = &shape.base.params;
    let p: Vec<Point3f> = params
        .get_point3_array("P")
        .map_err(|e| format!("{e:?}"))?
        .iter()
        .map(|v| Point3f::new(v[0], v[1], v[2]))
        .collect();
    let idx: Vec<u32> = params
        .get_int_array("indices")
        .map_err(|e| format!("{e:?}"))?
        .iter()
        .map(|&i| i as u32)
        .collect();
    let mut levels = 0;
    while (idx.len() / 3) << (2 * levels) < 100_000 {
        levels += 1;
    }
    let sub = loop_subdivide(levels, &idx, &p).map_err(|e| e.0)?;
    Ok(Mesh {
        name: "killeroo".into(),
        tris: tris_from_indexed(&sub.p, &sub.indices),
        view: None,
    })
}

fn ply_mesh(path: &Path) -> Result<Mesh, String> {
    let m = rpbrt_parser::ply::read_ply(path).map_err(|e| format!("{path:?}: {e}"))?;
    let p: Vec<Point3f> = m
        .positions
        .iter()
        .map(|v| Point3f::new(v[0], v[1], v[2]))
        .collect();
    let mut idx = m.tri_indices.clone();
    for q in m.quad_indices.chunks_exact(4) {
        // Bilinear-patch order v0 v1 v3 v2: two triangles.
        idx.extend_from_slice(&[q[0], q[1], q[3], q[0], q[3], q[2]]);
    }
    let stem = path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    Ok(Mesh {
        name: format!("water-{stem}"),
        tris: tris_from_indexed(&p, &idx),
        view: None,
    })
}

/// A seeded noisy terrain of 2·710² ≈ 1.01M triangles: a sum of random
/// sinusoids plus per-vertex jitter.
// 6.28, not τ: the terrain (and so the figures) stays the same as in
// earlier sessions.
#[allow(clippy::approx_constant)]
fn terrain() -> Mesh {
    const N: usize = 710;
    let mut rng = Rng::with_sequence(42);
    let waves: Vec<[Float; 4]> = (0..8)
        .map(|k| {
            let f = 2.0 + 3.0 * k as Float;
            [
                f * (rng.uniform_float() - 0.5),
                f * (rng.uniform_float() - 0.5),
                6.28 * rng.uniform_float(),
                0.3 / (1.0 + k as Float),
            ]
        })
        .collect();
    let mut p = Vec::with_capacity((N + 1) * (N + 1));
    for j in 0..=N {
        for i in 0..=N {
            let x = i as Float / N as Float;
            let y = j as Float / N as Float;
            let mut h = 0.0;
            for w in &waves {
                h += w[3] * (w[0] * x * 6.28 + w[1] * y * 6.28 + w[2]).sin();
            }
            h += 0.002 * (rng.uniform_float() - 0.5);
            p.push(Point3f::new(x, y, h));
        }
    }
    let mut idx = Vec::with_capacity(N * N * 6);
    for j in 0..N {
        for i in 0..N {
            let a = (j * (N + 1) + i) as u32;
            let b = a + 1;
            let c = a + (N + 1) as u32;
            let d = c + 1;
            idx.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    Mesh {
        name: "terrain".into(),
        tris: tris_from_indexed(&p, &idx),
        view: None,
    }
}

/// `mesh` inside a closed cube (each face a 32×32 grid of quads, two
/// triangles each) centred on its bounds, with half-side twice the radius
/// of its bounding sphere: the benchmark camera (at 1.7 radii) sits
/// inside, so camera rays that miss the mesh hit a wall and bounce rays
/// (almost) always hit something, as in a closed room.
fn enclosed(mesh: &Mesh) -> Mesh {
    let mut b = Bounds3f::empty();
    for t in &mesh.tris {
        b = b.union(&tri_bounds(t));
    }
    let c = b.p_min + (b.p_max - b.p_min) * 0.5;
    let h = (b.p_max - b.p_min).length();
    const N: usize = 32;
    let mut tris = mesh.tris.clone();
    for axis in 0..3 {
        for side in [-1.0 as Float, 1.0] {
            // The face at `c[axis] + side·h`, spanned by the other axes.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |i: usize, j: usize| {
                let mut p = [c.x, c.y, c.z];
                p[axis] += side * h;
                p[u] += h * (2.0 * i as Float / N as Float - 1.0);
                p[v] += h * (2.0 * j as Float / N as Float - 1.0);
                Point3f::new(p[0], p[1], p[2])
            };
            for i in 0..N {
                for j in 0..N {
                    let (p00, p10) = (corner(i, j), corner(i + 1, j));
                    let (p01, p11) = (corner(i, j + 1), corner(i + 1, j + 1));
                    tris.push([p00, p10, p11]);
                    tris.push([p00, p11, p01]);
                }
            }
        }
    }
    Mesh {
        name: format!("{}-closed", mesh.name),
        tris,
        view: Some(b),
    }
}

fn tri_bounds(t: &Tri) -> Bounds3f {
    Bounds3f::new(t[0], t[1]).union_point(t[2])
}

/// The shared primitive test, as the renderer's `PrimitiveAggregate` runs
/// it: the watertight test with the ray's permutation and shear computed
/// once per ray (`tr`). `Some(t)` for a hit strictly before `t_max`.
/// (Degenerate triangles were dropped when the mesh was made.)
#[inline(always)]
fn hit_tri(tris: &[Tri], tr: &TriangleRay, p: u32, t_max: Float) -> Option<Float> {
    let t = &tris[p as usize];
    match intersect_prepared_triangle(tr, t_max, t[0], t[1], t[2]) {
        // (The hit's `t` is the last of the four values; the first is a
        // barycentric, which an earlier version returned by mistake.)
        Some((.., th)) if th < t_max => Some(th),
        _ => None,
    }
}

/// Pinhole camera rays framing the mesh's bounding sphere, from above and
/// to the side.
fn camera_rays(b: &Bounds3f) -> Vec<Ray> {
    let c = b.p_min + (b.p_max - b.p_min) * 0.5;
    let r = (b.p_max - b.p_min).length() * 0.5;
    let view = Vector3f::new(0.55, -0.45, 0.7).normalize();
    let eye = c + view * (1.7 * r);
    let fwd = -view;
    let frame = Frame::from_z(fwd);
    let tan_half = (0.5 as Float).tan() * 0.8; // ~46° field of view
    let res = res();
    let mut rays = Vec::with_capacity(res * res);
    for y in 0..res {
        for x in 0..res {
            let sx = (2.0 * (x as Float + 0.5) / res as Float - 1.0) * tan_half;
            let sy = (1.0 - 2.0 * (y as Float + 0.5) / res as Float) * tan_half;
            let d = frame.from_local(Vector3f::new(sx, sy, 1.0)).normalize();
            rays.push(Ray::new(eye, d));
        }
    }
    rays
}

/// Cosine-distributed bounces from the first hits of `cam` (cycling over
/// the hits so there are as many rays as camera rays).
fn bounce_rays(tris: &[Tri], accel: &Accelerator, cam: &[Ray]) -> Vec<Ray> {
    let mut hits = Vec::new();
    for r in cam {
        let tr = TriangleRay::new(r);
        if let Some((p, t)) =
            accel.intersect(r, Float::INFINITY, |p, _, t| hit_tri(tris, &tr, p, t))
        {
            let tri = &tris[p as usize];
            let mut n = cross(tri[1] - tri[0], tri[2] - tri[0]).normalize();
            if dot(n, r.d) > 0.0 {
                n = -n;
            }
            hits.push((r.o + r.d * t, n));
        }
    }
    eprintln!("  {} of {} camera rays hit", hits.len(), cam.len());
    let mut rng = Rng::with_sequence(7);
    if hits.is_empty() {
        return cam.to_vec();
    }
    (0..cam.len())
        .map(|i| {
            let (p, n) = hits[i % hits.len()];
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let d = Frame::from_normal(Normal3f::from(n)).from_local(sample_cosine_hemisphere(u));
            let ext = 1e-4 * (1.0 + p.x.abs().max(p.y.abs()).max(p.z.abs()));
            Ray::new(p + n * ext, d)
        })
        .collect()
}

/// Runs `f` over `rays` split into `threads` contiguous chunks; returns
/// Mrays/s and the number of hits (to keep the work observable).
fn run<F>(rays: &[Ray], threads: usize, f: F) -> (f64, usize)
where
    F: Fn(&Ray) -> bool + Sync,
{
    let t0 = Instant::now();
    let chunk = rays.len().div_ceil(threads);
    let hits: usize = std::thread::scope(|s| {
        let hs: Vec<_> = rays
            .chunks(chunk)
            .map(|c| {
                let f = &f;
                s.spawn(move || c.iter().filter(|r| f(r)).count())
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap_or(0)).sum()
    });
    (rays.len() as f64 / t0.elapsed().as_secs_f64() / 1e6, hits)
}

fn subset(rays: &[Ray], n: usize) -> Vec<Ray> {
    let step = rays.len().div_ceil(n).max(1);
    rays.iter().step_by(step).copied().collect()
}

fn to_vec3a(p: Point3f) -> glam::Vec3A {
    glam::Vec3A::new(p.x, p.y, p.z)
}

struct BoxPrim(Aabb);
impl obvhs::Boundable for BoxPrim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

fn build_obvhs(bounds: &[Bounds3f], threads: usize) -> (CwBvh, f64) {
    let prims: Vec<BoxPrim> = bounds
        .iter()
        .map(|b| BoxPrim(Aabb::new(to_vec3a(b.p_min), to_vec3a(b.p_max))))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| panic!("rayon pool: {e}"));
    let t0 = Instant::now();
    let bvh = pool.install(|| {
        let mut d = std::time::Duration::default();
        obvhs::cwbvh::builder::build_cwbvh(&prims, BvhBuildParams::medium_build(), &mut d)
    });
    (bvh, t0.elapsed().as_secs_f64())
}

fn obvhs_ray(r: &Ray, t_max: Float) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new(
        to_vec3a(r.o),
        glam::Vec3A::new(r.d.x, r.d.y, r.d.z),
        0.0,
        t_max,
    )
}

fn print_result(mesh: &str, accel: &str, threads: usize, v: [f64; 4], extra: &str) {
    println!(
        "RESULT mesh={mesh} accel={accel} threads={threads} build_mprims_s={:.2} coherent_mrays_s={:.2} incoherent_mrays_s={:.2} shadow_mrays_s={:.2}{extra}",
        v[0], v[1], v[2], v[3],
    );
}

/// The camera rays regrouped into `tw`×`th` pixel tiles (tile after tile,
/// row-major inside each), the order packet tracers take them in.
fn tiled(cam: &[Ray], tw: usize, th: usize) -> Vec<Ray> {
    let res = (cam.len() as f64).sqrt().round() as usize;
    let mut out = Vec::with_capacity(cam.len());
    for ty in (0..res).step_by(th) {
        for tx in (0..res).step_by(tw) {
            for y in ty..(ty + th).min(res) {
                for x in tx..(tx + tw).min(res) {
                    out.push(cam[y * res + x]);
                }
            }
        }
    }
    out
}

/// Runs `f` over consecutive groups of `n` rays split across `threads`;
/// returns Mrays/s and the hits `f` reports.
fn run_groups<F>(rays: &[Ray], n: usize, threads: usize, f: F) -> (f64, usize)
where
    F: Fn(&[Ray]) -> usize + Sync,
{
    let t0 = Instant::now();
    let chunk = rays.len().div_ceil(threads).div_ceil(n) * n;
    let hits: usize = std::thread::scope(|s| {
        let hs: Vec<_> = rays
            .chunks(chunk.max(n))
            .map(|c| {
                let f = &f;
                s.spawn(move || c.chunks(n).map(f).sum::<usize>())
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap_or(0)).sum()
    });
    (rays.len() as f64 / t0.elapsed().as_secs_f64() / 1e6, hits)
}

/// The packet figures of a wide BVH (see `bench_mesh`): the SIMD level and
/// the camera and incoherent rays' Mrays/s in packets of its width.
fn packet_figures<const W: usize>(
    bvh: &WideBvh<W>,
    slot_tris: &[Tri],
    cam_set: &[Ray],
    bounce_set: &[Ray],
    threads: usize,
) -> String {
    let level = rpbrt_render::simd::level();
    let w = level.lanes();
    if w == 1 {
        return String::new();
    }
    // Every slot a triangle: all tested in lanes, one triangle against
    // the packet's rays at a time.
    let tris: Vec<Option<Tri>> = slot_tris.iter().map(|t| Some(*t)).collect();
    let packet = |g: &[Ray]| {
        let mut t_max = [Float::INFINITY; 16];
        let mut best = [None; 16];
        let mut bary = [None; 16];
        bvh.intersect_packet_triangles(
            level,
            g,
            &mut t_max[..g.len()],
            &mut best[..g.len()],
            &tris,
            &mut bary[..g.len()],
            |_, _, _, _, _| None,
        );
        best[..g.len()].iter().filter(|b| b.is_some()).count()
    };
    let (tw, th) = match w {
        16 => (4, 4),
        8 => (4, 2),
        _ => (2, 2),
    };
    let (pc, _) = run_groups(&tiled(cam_set, tw, th), w, threads, packet);
    let (pi, _) = run_groups(bounce_set, w, threads, packet);
    format!(
        " simd={} packet{w}_coherent_mrays_s={pc:.2} packet{w}_incoherent_mrays_s={pi:.2}",
        level.name()
    )
}

/// The rpbrt structures benchmarked: (name, parameters).
///
/// `bvh` is the default BVH, `bvh2` the binary one (`"integer width" 2`),
/// `bvh4` and `bvh8` the 4- and 8-wide ones.
fn rpbrt_structures() -> Vec<(&'static str, AccelParams)> {
    let mut v = Vec::new();
    for name in AccelParams::NAMES {
        // Benchmarked below as `rpbrt-embree`, with its triangles.
        if *name == "embree" {
            continue;
        }
        if let Ok(p) = AccelParams::new(name) {
            v.push((*name, p));
        }
        if *name == "bvh" {
            for (w, wname) in [(2, "bvh2"), (4, "bvh4"), (8, "bvh8")] {
                if let Ok(p) = AccelParams::parse(name, [("width", ParamValue::Int(w))]) {
                    v.push((wname, p));
                }
            }
        }
    }
    v
}

fn bench_mesh(mesh: &Mesh, only: &Option<Vec<String>>) {
    let tris = &mesh.tris;
    let bounds: Vec<Bounds3f> = tris.iter().map(tri_bounds).collect();
    let n = tris.len() as f64;
    let mut total = Bounds3f::empty();
    for b in &bounds {
        total = total.union(b);
    }
    let cam = camera_rays(&mesh.view.unwrap_or(total));
    let reference = Accelerator::build(&bounds, &AccelParams::default());
    let bounce = bounce_rays(tris, &reference, &cam);
    drop(reference);
    eprintln!("mesh {}: {} triangles", mesh.name, tris.len());
    let wanted = |name: &str| only.as_ref().is_none_or(|o| o.iter().any(|s| s == name));
    let default_params = AccelParams::default();

    for (name, params) in rpbrt_structures() {
        if !wanted(name) {
            continue;
        }
        let slow = matches!(params.kind, AccelKind::KdTree | AccelKind::Grid);
        let (cam_set, bounce_set) = if slow {
            (subset(&cam, SLOW_RAYS), subset(&bounce, SLOW_RAYS))
        } else {
            (cam.clone(), bounce.clone())
        };
        for &threads in &thread_counts() {
            let t0 = Instant::now();
            let a = Accelerator::build_with_threads(&bounds, &params, threads);
            let build = n / t0.elapsed().as_secs_f64() / 1e6;
            // The triangles in the structure's slot order (leaf order for
            // the 4-wide BVH), as `PrimitiveAggregate` keeps them.
            let slot_tris: Vec<Tri> = match a.slot_entries() {
                Some(order) => order.iter().map(|&e| tris[e as usize]).collect(),
                None => tris.clone(),
            };
            let slot_tris = &slot_tris;
            let closest = |r: &Ray| {
                let tr = TriangleRay::new(r);
                a.intersect_slots(r, Float::INFINITY, |s, _, _, t| {
                    hit_tri(slot_tris, &tr, s, t)
                })
                .is_some()
            };
            let any = |r: &Ray| {
                let tr = TriangleRay::new(r);
                a.intersect_p_slots(r, Float::INFINITY, |s, _, _, t| {
                    hit_tri(slot_tris, &tr, s, t).is_some()
                })
            };
            let (c, _) = run(&cam_set, threads, closest);
            let (i, ih) = run(&bounce_set, threads, closest);
            let (s, _) = run(&bounce_set, threads, any);
            if threads == 1 {
                // Primitive tests per ray: a quality figure, on stderr.
                let tests = |rays: &[Ray]| {
                    let mut k = 0usize;
                    let sample = subset(rays, 20_000);
                    for r in &sample {
                        let tr = TriangleRay::new(r);
                        a.intersect_slots(r, Float::INFINITY, |s, _, _, t| {
                            k += 1;
                            hit_tri(slot_tris, &tr, s, t)
                        });
                    }
                    k as f64 / sample.len() as f64
                };
                eprintln!(
                    "  {name}: {:.2} / {:.2} triangle tests per coherent / incoherent ray, {:.0}% of incoherent rays hit",
                    tests(&cam_set),
                    tests(&bounce_set),
                    100.0 * ih as f64 / bounce_set.len() as f64
                );
            }
            let default = if params == default_params {
                " default=yes"
            } else {
                ""
            };
            // The wide BVHs' packet traversal at the processor's SIMD
            // width: camera rays in 4×4 (16 lanes), 4×2 (8) or 2×2 (4) pixel
            // tiles, and the incoherent rays in groups of the same size.
            let extra = match &a {
                Accelerator::Bvh4(bvh) => {
                    packet_figures(bvh, slot_tris, &cam_set, &bounce_set, threads)
                }
                Accelerator::Bvh8(bvh) => {
                    packet_figures(bvh, slot_tris, &cam_set, &bounce_set, threads)
                }
                _ => String::new(),
            };
            print_result(
                &mesh.name,
                name,
                threads,
                [build, c, i, s],
                &(default.to_string() + &extra),
            );
        }
    }

    if wanted("obvhs") {
        for &threads in &thread_counts() {
            let (bvh, secs) = build_obvhs(&bounds, threads);
            let build = n / secs / 1e6;
            let closest = |r: &Ray| {
                let tr = TriangleRay::new(r);
                let mut hit = obvhs::ray::RayHit::none();
                bvh.ray_traverse(obvhs_ray(r, Float::INFINITY), &mut hit, |ray, id| {
                    let p = bvh.primitive_indices[id];
                    hit_tri(tris, &tr, p, ray.tmax).unwrap_or(Float::INFINITY)
                })
            };
            let any = |r: &Ray| {
                let tr = TriangleRay::new(r);
                !bvh.ray_traverse_miss(obvhs_ray(r, Float::INFINITY), |ray, id| {
                    let p = bvh.primitive_indices[id];
                    hit_tri(tris, &tr, p, ray.tmax).unwrap_or(Float::INFINITY)
                })
            };
            let (c, _) = run(&cam, threads, closest);
            let (i, _) = run(&bounce, threads, closest);
            let (s, _) = run(&bounce, threads, any);
            print_result(&mesh.name, "obvhs", threads, [build, c, i, s], "");
        }
    }

    #[cfg(feature = "embree")]
    if wanted("embree") {
        for &threads in &thread_counts() {
            let (scene, secs) = match embree_bench::EmbreeScene::build(tris, threads) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("skipping embree: {e}");
                    break;
                }
            };
            let build = n / secs / 1e6;
            let closest = |r: &Ray| scene.intersect1(r).is_some();
            let (c, _) = run(&cam, threads, closest);
            let (i, ih) = run(&bounce, threads, closest);
            let (s, _) = run(&bounce, threads, |r| scene.occluded1(r));
            let (p8, _) = run_groups(&tiled(&cam, 4, 2), 8, threads, |g| scene.intersect8(g));
            let (p16, h16) = run_groups(&tiled(&cam, 4, 4), 16, threads, |g| scene.intersect16(g));
            if threads == 1 {
                eprintln!(
                    "  embree: {:.0}% of incoherent rays hit, {:.0}% of camera rays",
                    100.0 * ih as f64 / bounce.len() as f64,
                    100.0 * h16 as f64 / cam.len() as f64
                );
            }
            let extra =
                format!(" packet8_coherent_mrays_s={p8:.2} packet16_coherent_mrays_s={p16:.2}");
            print_result(&mesh.name, "embree", threads, [build, c, i, s], &extra);
        }
    }

    // rpbrt's `Accelerator "embree"`: Embree's triangles with rpbrt's
    // triangle test refining every candidate in the intersection filter,
    // through the same hit closure as the structures above.
    #[cfg(feature = "embree")]
    if wanted("rpbrt-embree") {
        let Ok(params) = AccelParams::new("embree") else {
            return;
        };
        for &threads in &thread_counts() {
            let t0 = Instant::now();
            // (Embree builds with its own thread pool, whatever `threads`.)
            let a = Accelerator::build_from_triangles(
                tris.len(),
                |e| bounds[e as usize],
                |e| Some(tris[e as usize]),
                &params,
            );
            let build = n / t0.elapsed().as_secs_f64() / 1e6;
            let closest = |r: &Ray| {
                let tr = TriangleRay::new(r);
                a.intersect(r, Float::INFINITY, |p, _, t| hit_tri(tris, &tr, p, t))
                    .is_some()
            };
            let any = |r: &Ray| {
                let tr = TriangleRay::new(r);
                a.intersect_p(r, Float::INFINITY, |p, _, t| {
                    hit_tri(tris, &tr, p, t).is_some()
                })
            };
            let (c, _) = run(&cam, threads, closest);
            let (i, ih) = run(&bounce, threads, closest);
            let (s, _) = run(&bounce, threads, any);
            if threads == 1 {
                eprintln!(
                    "  rpbrt-embree: {:.0}% of incoherent rays hit",
                    100.0 * ih as f64 / bounce.len() as f64
                );
            }
            print_result(&mesh.name, "rpbrt-embree", threads, [build, c, i, s], "");
        }
    }
}

fn main() {
    let only: Option<Vec<String>> = std::env::var("RPBRT_ACCEL_BENCH_ONLY")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    let only_mesh: Option<Vec<String>> = std::env::var("RPBRT_ACCEL_BENCH_MESH")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    let want_mesh = |name: &str| {
        only_mesh
            .as_ref()
            .is_none_or(|o| o.iter().any(|s| name.starts_with(s.as_str())))
    };
    // Loading: also the meshes whose closed variant is wanted.
    let want_load = |name: &str| {
        only_mesh.as_ref().is_none_or(|o| {
            o.iter()
                .any(|s| name.starts_with(s.as_str()) || s.starts_with(name))
        })
    };
    // The bench runs from the crate directory; `shared` sits beside the
    // workspace root.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let shared = [root.join("../shared"), root.join("shared")]
        .into_iter()
        .find(|p| p.join("scenes").is_dir());
    let mut meshes = Vec::new();
    match &shared {
        Some(shared) => {
            if want_load("killeroo") {
                match killeroo(shared) {
                    Ok(m) => meshes.push(m),
                    Err(e) => eprintln!("skipping killeroo: {e}"),
                }
            }
            if want_load("water") {
                let dir = shared.join("scenes/water-caustic/models");
                let mut plys: Vec<_> = std::fs::read_dir(&dir)
                    .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                    .unwrap_or_default();
                plys.retain(|p| p.extension().is_some_and(|e| e == "ply"));
                plys.sort();
                for p in plys {
                    match ply_mesh(&p) {
                        Ok(m) => meshes.push(m),
                        Err(e) => eprintln!("skipping {p:?}: {e}"),
                    }
                }
            }
        }
        None => {
            eprintln!("../shared/scenes not found: skipping the killeroo and water-caustic meshes")
        }
    }
    if want_load("terrain") {
        meshes.push(terrain());
    }
    // Each mesh again inside a closed box, where bounce rays hit.
    let closed: Vec<Mesh> = meshes.iter().map(enclosed).collect();
    for m in meshes.iter().chain(&closed) {
        if want_mesh(&m.name) {
            bench_mesh(m, &only);
        }
    }
}
