//! Quad lookups across face edges and corners, against weights worked out
//! by hand from the cubic B-spline: at a texel centre the taps weigh 1/6,
//! 2/3, 1/6; on an edge between texels, 1/48, 23/48, 23/48, 1/48.

use super::super::reader::*;
use super::super::tests::{write_ptex_mesh, Store, TestFace};
use crate::rng::Rng;

const B: usize = 0;
const R: usize = 1;
const T: usize = 2;
const L: usize = 3;

fn quad(value: impl Fn(usize, usize) -> f32, adj: [i32; 4]) -> TestFace {
    TestFace {
        ulog2: 2,
        vlog2: 2,
        texels: (0..16).map(|i| value(i % 4, i / 4)).collect(),
        store: Store::Zipped,
        adj,
    }
}

fn edges(e: [usize; 4]) -> u8 {
    (e[0] | (e[1] << 2) | (e[2] << 4) | (e[3] << 6)) as u8
}

fn file(faces: &[TestFace], e: &[u8]) -> PtexFile {
    let bytes = write_ptex_mesh(faces, PtexDataType::Float, 1, [0, 0], false, e);
    PtexFile::parse(&bytes, "q.ptx").unwrap()
}

fn lookup(f: &PtexFile, face: i32, u: f32, v: f32) -> f32 {
    let mut out = [0.0f32; 3];
    f.eval(&mut out, face, u, v, 0.0, 0.0, 0.0, 0.0);
    out[0]
}

#[test]
fn neighbours_across_an_edge_blend() {
    let (a, b) = (0.2f32, 0.9f32);
    let f = file(
        &[
            quad(|_, _| a, [-1, 1, -1, -1]),
            quad(|_, _| b, [-1, -1, -1, 0]),
        ],
        &[edges([0, L, 0, 0]), edges([0, 0, 0, R])],
    );
    // On the shared edge: half of each face.
    let e = (a + b) / 2.0;
    assert!((lookup(&f, 0, 1.0, 0.5) - e).abs() < 1e-6);
    assert!((lookup(&f, 1, 0.0, 0.5) - e).abs() < 1e-6);
    // At the last texel's centre: one tap of 1/6 in the neighbour.
    let e = a * 5.0 / 6.0 + b / 6.0;
    assert!((lookup(&f, 0, 0.875, 0.3) - e).abs() < 1e-6);
    // Inside, the neighbour is out of reach.
    assert!((lookup(&f, 0, 0.5, 0.5) - a).abs() < 1e-6);
}

#[test]
fn rotated_neighbours_are_read_in_their_own_orientation() {
    // Face 0's right edge is face 1's bottom edge: face 0's (1 + d, v) is
    // face 1's (1 − v, d). Face 1's texel (i, j) holds i + 10 j.
    let a = 0.5f32;
    let f = file(
        &[
            quad(|_, _| a, [-1, 1, -1, -1]),
            quad(|i, j| (i + 10 * j) as f32, [0, -1, -1, -1]),
        ],
        &[edges([0, B, 0, 0]), edges([R, 0, 0, 0])],
    );
    // Texel (3, 1) of face 0: the taps beyond its right edge are face 1's
    // row 0, columns 3, 2, 1 (for face 0's rows 0, 1, 2), weighted 1/6 ×
    // (1/6, 2/3, 1/6).
    let e = a * 5.0 / 6.0 + (3.0 / 6.0 + 2.0 * 2.0 / 3.0 + 1.0 / 6.0) / 6.0;
    let got = lookup(&f, 0, 0.875, 0.375);
    assert!((got - e).abs() < 1e-5, "{got} vs {e}");
}

#[test]
fn corners_regular_and_valence_three() {
    let vals = [0.1f32, 0.3, 0.5, 0.9];
    // A 2 × 2 grid: 0 bottom left, 1 bottom right, 2 top left, 3 top right.
    let grid = file(
        &[
            quad(|_, _| vals[0], [-1, 1, 2, -1]),
            quad(|_, _| vals[1], [-1, -1, 3, 0]),
            quad(|_, _| vals[2], [0, 3, -1, -1]),
            quad(|_, _| vals[3], [1, -1, -1, 2]),
        ],
        &[
            edges([0, L, B, 0]),
            edges([0, 0, B, R]),
            edges([T, L, 0, 0]),
            edges([T, 0, 0, R]),
        ],
    );
    let mean = vals.iter().sum::<f32>() / 4.0;
    for (face, u, v) in [(0, 1.0, 1.0), (1, 0.0, 1.0), (2, 1.0, 0.0), (3, 0.0, 0.0)] {
        let got = lookup(&grid, face, u, v);
        assert!((got - mean).abs() < 1e-6, "face {face}: {got}");
    }
    let e = vals[0] * 25.0 / 36.0 + (vals[1] + vals[2]) * 5.0 / 36.0 + vals[3] / 36.0;
    assert!((lookup(&grid, 0, 0.875, 0.875) - e).abs() < 1e-6);

    // A cube corner: face 0's top-right vertex is shared by three faces;
    // the corner part of the kernel is left out and the rest renormalized.
    let cube = file(
        &[
            quad(|_, _| vals[0], [-1, 1, 2, -1]),
            quad(|_, _| vals[1], [-1, -1, 2, 0]),
            quad(|_, _| vals[2], [0, 1, -1, -1]),
        ],
        &[
            edges([0, L, B, 0]),
            edges([0, 0, R, R]),
            edges([T, T, 0, 0]),
        ],
    );
    let e = (vals[0] + vals[1] + vals[2]) / 3.0;
    let got = lookup(&cube, 0, 1.0, 1.0);
    assert!((got - e).abs() < 1e-6, "{got} vs {e}");
}

#[test]
fn constant_grid_stays_constant_and_damage_never_panics() {
    // A 3 × 3 torus of constant faces (every vertex regular) at mixed
    // resolutions: constant everywhere, for every footprint.
    let id = |i: usize, j: usize| ((j % 3) * 3 + i % 3) as i32;
    let mut faces = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let l = ((i + j) % 3) as u8 + 1;
            faces.push(TestFace {
                ulog2: l,
                vlog2: 4 - l,
                texels: vec![0.625; 16],
                store: Store::Zipped,
                adj: [id(i, j + 2), id(i + 1, j), id(i, j + 1), id(i + 2, j)],
            });
        }
    }
    let e = vec![edges([T, L, B, R]); 9];
    let mut torus = file(&faces, &e);
    let mut rng = Rng::new(9, 0);
    let mut out = [0.0f32; 3];
    for _ in 0..2000 {
        let face = rng.uniform_bounded(9) as i32;
        let (u, v) = (rng.uniform_float(), rng.uniform_float());
        let d = [0.0, 0.01, 0.1, 0.3, 2.0][rng.uniform_bounded(5) as usize];
        let (a, b) = (d * rng.uniform_float(), d * rng.uniform_float());
        torus.eval(&mut out, face, u, v, a, b, -b, a);
        assert!(
            (out[0] - 0.625).abs() < 1e-5,
            "face {face} ({u}, {v}) {d}: {}",
            out[0]
        );
    }
    // Random adjacency, edges and subface flags: never panics.
    for _ in 0..3000 {
        for f in torus.faces.iter_mut() {
            for a in f.adj_faces.iter_mut() {
                *a = rng.uniform_bounded(11) as i32 - 1;
            }
            f.adj_edges = rng.uniform_u32() as u8;
            f.flags = (rng.uniform_u32() as u8) & FLAG_SUBFACE;
        }
        let face = rng.uniform_bounded(9) as i32;
        let (u, v) = (rng.uniform_float(), rng.uniform_float());
        let d = [0.0, 0.1, 0.6][rng.uniform_bounded(3) as usize];
        torus.eval(&mut out, face, u, v, d, 0.0, 0.0, d);
        assert!(out[0].is_finite());
    }
}
