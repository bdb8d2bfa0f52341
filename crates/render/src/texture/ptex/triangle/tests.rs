//! Triangle-mesh Ptex lookups against values worked out independently:
//! constants stay constant across edges, corners and resolutions, and
//! per-face constants blend across an edge with the Gaussian weights of
//! the unfolded pair of triangles.

use super::super::reader::*;
use super::super::tests::{write_ptex_mesh, Store, TestFace};
use super::reduce_triangle;
use crate::rng::Rng;

fn face(l: u8, value: f32, store: Store, adj: [i32; 3]) -> TestFace {
    let n = 1usize << (2 * l);
    TestFace {
        ulog2: l,
        vlog2: l,
        texels: vec![value; n],
        store,
        adj: [adj[0], adj[1], adj[2], -1],
    }
}

fn edges(e: [u8; 3]) -> u8 {
    e[0] | (e[1] << 2) | (e[2] << 4)
}

/// A tetrahedron: faces (0,1,2), (0,3,1), (1,3,2), (0,2,3) by vertex, edge
/// k of a face running from its vertex k to vertex k+1.
fn tetrahedron(levels: [u8; 4], value: f32) -> PtexFile {
    let adj = [[1, 2, 3], [3, 2, 0], [1, 3, 0], [0, 2, 1]];
    let e = [
        edges([2, 2, 0]),
        edges([2, 0, 0]),
        edges([1, 1, 1]),
        edges([2, 1, 0]),
    ];
    let faces: Vec<TestFace> = (0..4)
        .map(|i| face(levels[i], value, Store::Zipped, adj[i]))
        .collect();
    let bytes = write_ptex_mesh(&faces, PtexDataType::Float, 1, [0, 0], true, &e);
    PtexFile::parse(&bytes, "tet.ptx").unwrap()
}

#[test]
fn constant_texture_is_constant_everywhere() {
    let file = tetrahedron([0, 1, 3, 5], 0.375);
    assert_eq!(file.mesh_type, PtexMeshType::Triangle);
    assert_eq!(file.bad_adjacency, 0);
    let mut rng = Rng::new(3, 0);
    let mut out = [0.0f32; 3];
    let mut points = vec![
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.5, 0.5),
        (0.5, 0.0),
        (0.0, 0.5),
        (0.3, 0.3),
    ];
    for _ in 0..200 {
        let (u, v) = (rng.uniform_float(), rng.uniform_float());
        points.push(if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        });
    }
    for f in 0..4 {
        for &(u, v) in &points {
            for d in [0.0f32, 0.01, 0.1, 0.4, 3.0] {
                let (a, b) = (d * rng.uniform_float(), d * rng.uniform_float());
                file.eval(&mut out, f, u, v, a, -b, 0.5 * b, a);
                assert!(
                    (out[0] - 0.375).abs() < 1e-5,
                    "face {f} ({u}, {v}) width {d}: {}",
                    out[0]
                );
            }
        }
    }
}

/// The lookup at (u, v) with zero derivatives on face 0 (the triangle
/// (0,0), (1,0), (0,1) of the plane, so barycentrics are positions) next
/// to face 1, which shares face 0's edge `eid` as its own edge `aeid` and
/// continues it to a parallelogram. Worked by hand from Ptex's kernel:
/// zero derivatives give A = B = C; after the one-texel blur and the
/// 3.5 scale, a texel whose centroid lies at (du, dv) texels from the
/// lookup weighs exp(−2 (du² + du dv + dv²)) where du² + du dv + dv² <
/// 3.5²/4, and nothing beyond.
fn blend_reference(l: u8, vals: [f32; 2], eid: usize, aeid: usize, u: f32, v: f32) -> f32 {
    let n = (1usize << l) as f64;
    let p = [[0.0f64, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let (a, b, c) = (p[eid], p[(eid + 1) % 3], p[(eid + 2) % 3]);
    let q = [a[0] + b[0] - c[0], a[1] + b[1] - c[1]];
    // Face 1's vertices: its edge aeid runs from b to a.
    let mut f1 = [[0.0f64; 2]; 3];
    f1[aeid] = b;
    f1[(aeid + 1) % 3] = a;
    f1[(aeid + 2) % 3] = q;
    let (mut sum, mut wsum) = (0.0f64, 0.0f64);
    for (fi, verts) in [p, f1].iter().enumerate() {
        for j in 0..1usize << l {
            for i in 0..1usize << l {
                let mut cents = vec![];
                if i + j < 1 << l {
                    cents.push(((i as f64 + 1.0 / 3.0) / n, (j as f64 + 1.0 / 3.0) / n));
                }
                if i + j + 2 <= 1 << l {
                    cents.push(((i as f64 + 2.0 / 3.0) / n, (j as f64 + 2.0 / 3.0) / n));
                }
                for (cu, cv) in cents {
                    let cw = 1.0 - cu - cv;
                    let x = cw * verts[0][0] + cu * verts[1][0] + cv * verts[2][0];
                    let y = cw * verts[0][1] + cu * verts[1][1] + cv * verts[2][1];
                    let (du, dv) = ((x - u as f64) * n, (y - v as f64) * n);
                    let r = du * du + du * dv + dv * dv;
                    if r < 3.5 * 3.5 / 4.0 {
                        let w = (-2.0 * r).exp();
                        sum += w * vals[fi] as f64;
                        wsum += w;
                    }
                }
            }
        }
    }
    (sum / wsum) as f32
}

#[test]
fn per_face_constants_blend_across_edges() {
    let vals = [0.2f32, 0.9];
    let l = 2;
    let mut out = [0.0f32; 3];
    for eid in 0..3 {
        for aeid in 0..3 {
            let mut adj0 = [-1; 3];
            adj0[eid] = 1;
            let mut adj1 = [-1; 3];
            adj1[aeid] = 0;
            let mut e0 = [0u8; 3];
            e0[eid] = aeid as u8;
            let mut e1 = [0u8; 3];
            e1[aeid] = eid as u8;
            let faces = [
                face(l, vals[0], Store::Zipped, adj0),
                face(l, vals[1], Store::DiffZipped, adj1),
            ];
            let bytes = write_ptex_mesh(
                &faces,
                PtexDataType::Float,
                1,
                [0, 0],
                true,
                &[edges(e0), edges(e1)],
            );
            let file = PtexFile::parse(&bytes, "pair.ptx").unwrap();
            // Points near and on the shared edge, and one far from it.
            let near: [(f32, f32); 3] = match eid {
                0 => [(0.45, 0.04), (0.3, 0.0), (0.6, 0.1)],
                1 => [(0.47, 0.49), (0.25, 0.75), (0.4, 0.5)],
                _ => [(0.02, 0.41), (0.0, 0.3), (0.08, 0.55)],
            };
            for (u, v) in near.into_iter().chain([(0.3f32, 0.3f32)]) {
                file.eval(&mut out, 0, u, v, 0.0, 0.0, 0.0, 0.0);
                let e = blend_reference(l, vals, eid, aeid, u, v);
                assert!(
                    (out[0] - e).abs() < 2e-5,
                    "edge {eid}/{aeid} at ({u}, {v}): {} vs {e}",
                    out[0]
                );
            }
            // Far from the shared edge the neighbour does not reach.
            let far = [(0.05, 0.9), (0.05, 0.05), (0.9, 0.05)][eid];
            file.eval(&mut out, 0, far.0, far.1, 0.0, 0.0, 0.0, 0.0);
            assert!((out[0] - 0.2).abs() < 1e-6, "{}", out[0]);
            // At the shared edge's midpoint the texels of both faces lie
            // point-symmetrically: the plain mean, from either face.
            let mids = [(0.5, 0.0), (0.5, 0.5), (0.0, 0.5)];
            for (f, (u, v)) in [(0, mids[eid]), (1, mids[aeid])] {
                file.eval(&mut out, f, u, v, 0.0, 0.0, 0.0, 0.0);
                assert!((out[0] - 0.55).abs() < 1e-5, "face {f}: {}", out[0]);
            }
        }
    }
}

#[test]
fn edges_without_neighbours_do_not_blend() {
    let faces = [
        face(2, 0.2, Store::Zipped, [-1; 3]),
        face(2, 0.9, Store::Zipped, [-1; 3]),
    ];
    let bytes = write_ptex_mesh(&faces, PtexDataType::Float, 1, [0, 0], true, &[]);
    let file = PtexFile::parse(&bytes, "apart.ptx").unwrap();
    let mut out = [0.0f32; 3];
    file.eval(&mut out, 0, 0.45, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert!((out[0] - 0.2).abs() < 1e-6);
}

#[test]
fn triangle_reduction_averages_the_four_covered_triangles() {
    // 4 × 4 array: value = array index, so each output names its sources.
    let src: Vec<f32> = (0..16).map(|i| i as f32).collect();
    let r = reduce_triangle(&src, 4, 1);
    // Even coarse triangle (0, 0): fine even (0,0), (1,0), (0,1) and the
    // odd one of cell (0, 0), stored at (3, 3).
    assert_eq!(r[0], (0.0 + 1.0 + 4.0 + 15.0) / 4.0);
    // Coarse odd triangle of cell (0, 0), stored at (1, 1): fine odd
    // triangles of cells (1,1), (1,0), (0,1) (stored at (2,2), (3,2),
    // (2,3)) and the even one of cell (1, 1) (at (1, 1)).
    assert_eq!(r[3], (10.0 + 11.0 + 14.0 + 5.0) / 4.0);
    // Every fine triangle is used exactly once.
    let mut rng = Rng::new(5, 0);
    for l in 1..5 {
        let n = 1usize << l;
        let src: Vec<f32> = (0..n * n * 3).map(|_| rng.uniform_float()).collect();
        let r = reduce_triangle(&src, n, 3);
        for c in 0..3 {
            let a: f64 = src.iter().skip(c).step_by(3).map(|&x| x as f64).sum();
            let b: f64 = r.iter().skip(c).step_by(3).map(|&x| x as f64).sum();
            assert!((a - 4.0 * b).abs() < 1e-4, "{a} {b}");
        }
    }
}

#[test]
fn bad_adjacency_and_damage_never_panic() {
    // Face 0 names face 7 of a two-face file and edge id 3.
    let faces = [
        face(2, 0.25, Store::Zipped, [7, 1, -1]),
        face(1, 0.5, Store::Zipped, [-1, 0, -1]),
    ];
    let bytes = write_ptex_mesh(
        &faces,
        PtexDataType::U16,
        1,
        [0, 0],
        true,
        &[edges([0, 3, 0]), edges([0, 1, 0])],
    );
    let file = PtexFile::parse(&bytes, "bad.ptx").unwrap();
    assert_eq!(file.bad_adjacency, 2);
    let mut out = [0.0f32; 3];
    file.eval(&mut out, 0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert!((out[0] - 0.25).abs() < 1e-4, "{}", out[0]);
    for face in [-1, 2, i32::MAX] {
        file.eval(&mut out, face, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(out[0], 0.0);
    }
    assert_eq!(
        file.bad_lookups.load(std::sync::atomic::Ordering::Relaxed),
        3
    );
    // A triangle face must be square.
    let faces = [TestFace {
        ulog2: 2,
        vlog2: 1,
        texels: vec![0.0; 8],
        store: Store::Zipped,
        adj: [-1; 4],
    }];
    let bytes = write_ptex_mesh(&faces, PtexDataType::U8, 1, [0, 0], true, &[]);
    let e = PtexFile::parse(&bytes, "r.ptx").unwrap_err();
    assert!(e.contains("face 0") && e.contains("2^n x 2^n"), "{e}");
    // Random damage to a tetrahedron: errors or values, never panics.
    let tet = {
        let adj = [[1, 2, 3], [3, 2, 0], [1, 3, 0], [0, 2, 1]];
        let e = [
            edges([2, 2, 0]),
            edges([2, 0, 0]),
            edges([1, 1, 1]),
            edges([2, 1, 0]),
        ];
        let faces: Vec<TestFace> = (0..4)
            .map(|i| {
                let mut f = face(i as u8, 0.5, Store::Zipped, adj[i]);
                for (k, t) in f.texels.iter_mut().enumerate() {
                    *t = (k % 5) as f32 / 4.0;
                }
                f
            })
            .collect();
        write_ptex_mesh(&faces, PtexDataType::U8, 1, [0, 0], true, &e)
    };
    let mut rng = Rng::new(11, 0);
    for _ in 0..1000 {
        let mut b = tet.clone();
        for _ in 0..1 + rng.uniform_bounded(4) {
            let i = rng.uniform_bounded(b.len() as u32) as usize;
            b[i] = rng.uniform_u32() as u8;
        }
        if let Ok(f) = PtexFile::parse(&b, "t.ptx") {
            let mut out = vec![0.0f32; f.nchannels.max(3)];
            for face in 0..f.faces.len() as i32 {
                for (u, v, d) in [(0.0, 0.0, 0.0), (0.5, 0.5, 0.3), (0.9, 0.05, 2.0)] {
                    f.eval(&mut out, face, u, v, d, 0.0, 0.0, d);
                }
                f.eval(
                    &mut out,
                    face,
                    f32::NAN,
                    0.2,
                    f32::INFINITY,
                    0.0,
                    0.0,
                    f32::NAN,
                );
            }
        }
    }
}

/// Renders `text` (whose film writes `out`); returns the pixels (RGB,
/// row-major from the top) and the render's warnings.
fn render(text: &str, out: &std::path::Path) -> (Vec<f32>, Vec<String>) {
    use crate::scene::assemble::{create_scene, CreateOptions};
    use crate::scene::{build_scene_from_str, BuildOptions};
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let created = create_scene(&desc, &CreateOptions::default()).unwrap_or_else(|e| {
        panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        )
    });
    assert!(created.warnings.is_empty(), "{:?}", created.warnings);
    let mut scene = created.scene;
    let mut md = crate::image::ImageMetadata::default();
    let stats = created
        .integrator
        .render(&mut scene, &Default::default(), &mut md, &|_| {})
        .unwrap();
    let im = crate::image::Image::read(out, None).unwrap().image;
    assert_eq!(im.n_channels(), 3);
    (im.to_f32_vec(), stats.warnings)
}

#[test]
fn renders_a_triangle_mesh_with_a_ptex_texture() {
    // A square of two triangles, each with its own vertices and the uvs
    // (0,0), (1,0), (0,1) at its corners, so uv is the Ptex barycentric;
    // their second edges are the shared diagonal. Face 0 (lower left)
    // reflects 0.2, face 1 (upper right) 0.8, under a uniform white sky:
    // the image is the reflectance.
    let dir = std::env::temp_dir().join(format!("rpbrt-ptextri-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = dir.join("square.ptx");
    let faces = [
        face(3, 0.2, Store::Zipped, [-1, 1, -1]),
        face(3, 0.8, Store::Zipped, [-1, 0, -1]),
    ];
    let e = [edges([0, 1, 0]), edges([0, 1, 0])];
    std::fs::write(
        &ptx,
        write_ptex_mesh(&faces, PtexDataType::Float, 1, [0, 0], true, &e),
    )
    .unwrap();
    let scene = |out: &std::path::Path, face_indices: &str| {
        format!(
            "LookAt 0 0 -1  0 0 0  0 1 0\n\
             Camera \"orthographic\" \"float screenwindow\" [ -1 1 -1 1 ]\n\
             Sampler \"zsobol\" \"integer pixelsamples\" 64\n\
             Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
             Integrator \"path\" \"integer maxdepth\" 1\n\
             WorldBegin\n\
             LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n\
             Texture \"r\" \"spectrum\" \"ptex\" \"string filename\" \"{}\" \"string encoding\" \"linear\"\n\
             Material \"diffuse\" \"texture reflectance\" \"r\"\n\
             Shape \"trianglemesh\" \"point3 P\" [ -2 -2 0  2 -2 0  -2 2 0   2 2 0  -2 2 0  2 -2 0 ]\n\
               \"point2 uv\" [ 0 0  1 0  0 1   0 0  1 0  0 1 ]\n\
               \"integer indices\" [ 0 1 2  3 4 5 ] \"integer faceIndices\" [ {face_indices} ]\n",
            out.display(),
            ptx.display()
        )
    };
    let out = dir.join("square.exr");
    let (px, warnings) = render(&scene(&out, "0 1"), &out);
    assert!(warnings.is_empty(), "{warnings:?}");
    // Looking down +z with +y up, +x is to the right (pbrt's camera space
    // is left-handed): the lower-left triangle (x + y < 0) is the image's
    // lower left.
    let at = |x: usize, y: usize, c: usize| px[(y * 16 + x) * 3 + c];
    for c in 0..3 {
        for (x, y, e) in [(1, 14, 0.2), (3, 12, 0.2), (14, 1, 0.8), (12, 2, 0.8)] {
            let v = at(x, y, c);
            assert!(
                (v - e).abs() < 0.04 * e,
                "pixel ({x}, {y}) channel {c}: {v} vs {e}"
            );
        }
    }
    let mean = px.iter().map(|&v| v as f64).sum::<f64>() / px.len() as f64;
    assert!((mean - 0.5).abs() < 0.02, "mean {mean}");

    // Face indices the file does not have: zero reflectance there, and one
    // warning after the render naming the file.
    let out2 = dir.join("bad.exr");
    let (px, warnings) = render(&scene(&out2, "0 7"), &out2);
    assert!(px[(2 * 16 + 13) * 3] < 1e-3, "{}", px[(2 * 16 + 13) * 3]);
    let ours: Vec<_> = warnings
        .iter()
        .filter(|w| w.contains("square.ptx"))
        .collect();
    assert_eq!(ours.len(), 1, "{warnings:?}");
    assert!(
        ours[0].contains("outside the file's 2 faces"),
        "{}",
        ours[0]
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_adjacency_is_a_located_warning() {
    use crate::scene::assemble::{create_scene, CreateOptions};
    use crate::scene::{build_scene_from_str, BuildOptions};
    let dir = std::env::temp_dir().join(format!("rpbrt-ptexadj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = dir.join("adj.ptx");
    let faces = [face(1, 0.5, Store::Zipped, [9, -1, -1])];
    let bytes = write_ptex_mesh(&faces, PtexDataType::U8, 1, [0, 0], true, &[]);
    std::fs::write(&ptx, bytes).unwrap();
    let text = format!(
        "Film \"rgb\" \"string filename\" \"{}\"\nWorldBegin\nTexture \"r\" \"float\" \"ptex\"\n  \"string filename\" \"{}\"\n",
        dir.join("x.exr").display(),
        ptx.display()
    );
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let created = create_scene(&desc, &CreateOptions::default()).unwrap_or_else(|e| {
        panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        )
    });
    let w: Vec<_> = created
        .warnings
        .iter()
        .filter(|d| d.message.contains("adj.ptx"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", created.warnings);
    assert!(
        w[0].message.contains("1 face adjacency entries"),
        "{}",
        w[0].message
    );
    // At the "filename" parameter: line 4.
    assert_eq!(w[0].loc.as_ref().map(|l| l.line), Some(4), "{:?}", w[0].loc);
    std::fs::remove_dir_all(&dir).ok();
}
