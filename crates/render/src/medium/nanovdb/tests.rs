//! Tests of the NanoVDB reader against files written by OpenVDB's `vdb_tool` and values
//! NanoVDB itself returns for them (see `testdata/README.md`), and against corrupt input.

use std::io::Read;
use std::path::{Path, PathBuf};

use super::*;

fn testdata_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src/medium/nanovdb/testdata")
        .join(name)
}

/// A test file's bytes, inflated if gzipped.
fn testdata(name: &str) -> Vec<u8> {
    let raw = std::fs::read(testdata_path(name)).expect("test file");
    if name.ends_with(".gz") {
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(&raw[..])
            .read_to_end(&mut out)
            .expect("gzip");
        out
    } else {
        raw
    }
}

fn grid(bytes: &[u8], name: &str) -> FloatGrid {
    read_float_grid_from_bytes(bytes, name)
        .expect("readable")
        .expect("grid present")
}

/// What `dump_reference.cpp` wrote: NanoVDB's own answers for one grid.
#[derive(Default)]
struct Reference {
    name: String,
    class: u32,
    bbox: ([i32; 3], [i32; 3]),
    wbbox: ([u64; 3], [u64; 3]),
    min_max: (u32, u32),
    background: u32,
    values: Vec<([i32; 3], u32)>,
    samples: Vec<([f32; 3], u32)>,
    world_to_index: Vec<([f32; 3], [f32; 3])>,
}

fn reference(name: &str) -> Reference {
    let text = String::from_utf8(testdata(name)).expect("utf-8");
    let mut r = Reference::default();
    let hex32 = |s: &str| u32::from_str_radix(s, 16).expect("hex");
    let f = |s: &str| f32::from_bits(hex32(s));
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let int = |i: usize| w[i].parse::<i32>().expect("int");
        match w[0] {
            "name" => r.name = w[1].to_string(),
            "class" => r.class = w[1].parse().expect("class"),
            "bbox" => r.bbox = ([int(1), int(2), int(3)], [int(4), int(5), int(6)]),
            "wbbox" => {
                let d = |i: usize| u64::from_str_radix(w[i], 16).expect("hex");
                r.wbbox = ([d(1), d(2), d(3)], [d(4), d(5), d(6)]);
            }
            "minmax" => r.min_max = (hex32(w[1]), hex32(w[2])),
            "background" => r.background = hex32(w[1]),
            "v" => r.values.push(([int(1), int(2), int(3)], hex32(w[4]))),
            "s" => r.samples.push(([f(w[1]), f(w[2]), f(w[3])], hex32(w[4]))),
            "w" => r
                .world_to_index
                .push(([f(w[1]), f(w[2]), f(w[3])], [f(w[4]), f(w[5]), f(w[6])])),
            other => panic!("unknown reference line {other}"),
        }
    }
    r
}

/// Every value, sample, box and extremum equals NanoVDB's, bit for bit; worldToIndexF to
/// within rounding (NanoVDB uses fused multiply-adds).
fn check_against_reference(g: &FloatGrid, r: &Reference) {
    assert_eq!(g.name(), r.name);
    let class = match g.grid_class() {
        GridClass::Unknown => 0,
        GridClass::LevelSet => 1,
        GridClass::FogVolume => 2,
        GridClass::Other(c) => c,
    };
    assert_eq!(class, r.class);
    assert_eq!(g.index_bbox(), r.bbox);
    let (lo, hi) = g.world_bbox();
    assert_eq!((lo.map(f64::to_bits), hi.map(f64::to_bits)), r.wbbox);
    let (min, max) = g.min_max();
    assert_eq!((min.to_bits(), max.to_bits()), r.min_max);
    assert_eq!(g.background().to_bits(), r.background);
    assert!(!r.values.is_empty());
    for &(ijk, v) in &r.values {
        assert_eq!(g.value(ijk).to_bits(), v, "value at {ijk:?}");
    }
    assert_eq!(r.samples.len(), 200);
    for &(p, v) in &r.samples {
        assert_eq!(g.sample_trilinear(p).to_bits(), v, "sample at {p:?}");
    }
    assert_eq!(r.world_to_index.len(), 100);
    for &(p, q) in &r.world_to_index {
        let got = g.world_to_index(p);
        for a in 0..3 {
            let tol = 1e-5 * (1.0 + q[a].abs());
            assert!((got[a] - q[a]).abs() <= tol, "{p:?}: {got:?} vs {q:?}");
        }
    }
}

#[test]
fn fog_sphere_matches_nanovdb() {
    let bytes = testdata("fog.nvdb.gz");
    let g = grid(&bytes, "density");
    check_against_reference(&g, &reference("fog.density.ref.gz"));
    // As `vdb_tool -read fog.nvdb -print` and `nanovdb_print -l` report it.
    assert_eq!(g.index_bbox(), ([-4, -4, -4], [4, 4, 4]));
    assert_eq!(g.grid_class(), GridClass::FogVolume);
    assert_eq!(g.node_counts(), [8, 8, 8]);
    for (a, b) in g.voxel_size().iter().zip([0.2; 3]) {
        assert!((a - b).abs() < 1e-6);
    }
    let (lo, hi) = g.world_bbox();
    for a in 0..3 {
        assert!((lo[a] + 0.8).abs() < 1e-6 && (hi[a] - 1.0).abs() < 1e-6);
    }
}

#[test]
fn level_set_sphere_matches_nanovdb() {
    let bytes = testdata("ls.nvdb.gz");
    let g = grid(&bytes, "ls");
    check_against_reference(&g, &reference("ls.ls.ref.gz"));
    assert_eq!(g.grid_class(), GridClass::LevelSet);
    // Outside the narrow band: +background outside, -background deep inside (inactive
    // values of the leaves or tiles).
    let bg = g.background();
    assert!((bg - 0.6).abs() < 1e-6);
    assert_eq!(g.value([0, 0, 0]), -bg);
    assert_eq!(g.value([100, 0, 0]), bg);
    assert_eq!(g.value([-9, 3, 2]), bg);
}

#[test]
fn two_grid_file() {
    let bytes = testdata("two.nvdb.gz");
    assert_eq!(
        grid_names_from_bytes(&bytes).unwrap(),
        ["temperature", "density"]
    );
    let t = grid(&bytes, "temperature");
    check_against_reference(&t, &reference("two.temperature.ref.gz"));
    // The density grid is the same sphere as fog.nvdb's.
    let d = grid(&bytes, "density");
    check_against_reference(&d, &reference("fog.density.ref.gz"));
}

#[test]
fn fog_values_are_densities() {
    let g = grid(&testdata("fog.nvdb.gz"), "density");
    let (lo, hi) = g.index_bbox();
    for i in lo[0] - 2..=hi[0] + 2 {
        for j in lo[1] - 2..=hi[1] + 2 {
            for k in lo[2] - 2..=hi[2] + 2 {
                let v = g.value([i, j, k]);
                assert!((0.0..=1.0).contains(&v), "{v} at {i} {j} {k}");
            }
        }
    }
    // Deep inside (radius 5 voxels) the fog is 1; far away and outside the bbox it is 0.
    assert_eq!(g.value([0, 0, 0]), 1.0);
    assert_eq!(g.sample_trilinear([0.25, -0.5, 0.75]), 1.0);
    for ijk in [
        [5, 0, 0],
        [0, -5, 0],
        [1000, 2000, -3000],
        [i32::MIN, 0, i32::MAX],
    ] {
        assert_eq!(g.value(ijk), 0.0, "{ijk:?}");
    }
    assert_eq!(g.sample_trilinear([1e9, -1e9, 3.5]), 0.0);
    let (min, max) = g.min_max();
    assert!(min > 0.0 && min < 0.1 && max == 1.0);
}

#[test]
fn trilinear_interpolates_voxel_values() {
    let g = grid(&testdata("ls.nvdb.gz"), "ls");
    let lerp = |a: f32, b: f32, w: f32| a + w * (b - a);
    // Stencils inside one leaf, across leaf and node boundaries (-8, -1, 0, 7).
    for base in [
        [0, 0, 0],
        [-1, -1, -1],
        [3, -2, 5],
        [7, 7, 7],
        [-8, 0, 6],
        [2, 7, -1],
    ] {
        // At integer points a sample is the voxel's value.
        assert_eq!(
            g.sample_trilinear(base.map(|c| c as f32)),
            g.value(base),
            "{base:?}"
        );
        // Along one axis it is the linear blend of two neighbours.
        for axis in 0..3 {
            let mut p = base.map(|c| c as f32);
            p[axis] += 0.25;
            let mut next = base;
            next[axis] += 1;
            let want = lerp(g.value(base), g.value(next), 0.25);
            assert!(
                (g.sample_trilinear(p) - want).abs() < 1e-6,
                "{base:?} {axis}"
            );
        }
        // Anywhere in the cell it is the trilinear blend of the eight corners.
        let w = [0.3f32, 0.6, 0.9];
        let v = |d: [i32; 3]| g.value([base[0] + d[0], base[1] + d[1], base[2] + d[2]]);
        let x0 = lerp(
            lerp(v([0, 0, 0]), v([0, 0, 1]), w[2]),
            lerp(v([0, 1, 0]), v([0, 1, 1]), w[2]),
            w[1],
        );
        let x1 = lerp(
            lerp(v([1, 0, 0]), v([1, 0, 1]), w[2]),
            lerp(v([1, 1, 0]), v([1, 1, 1]), w[2]),
            w[1],
        );
        let p = [0, 1, 2].map(|a| base[a] as f32 + w[a]);
        let got = g.sample_trilinear(p);
        assert!((got - lerp(x0, x1, w[0])).abs() < 1e-6, "{base:?}: {got}");
    }
}

#[test]
fn world_and_index_maps_invert_each_other() {
    let bytes = testdata("two.nvdb.gz");
    for name in ["density", "temperature"] {
        let g = grid(&bytes, name);
        let dx = g.voxel_size()[0] as f32;
        let o = g.index_to_world([0.0; 3]);
        let e = g.index_to_world([1.0, 0.0, 0.0]);
        assert!((e[0] - o[0] - dx).abs() < 1e-6 && e[1] == o[1] && e[2] == o[2]);
        for p in [[0.0f32, 0.0, 0.0], [1.5, -2.25, 3.0], [-40.0, 17.5, 0.125]] {
            let q = g.world_to_index(g.index_to_world(p));
            for a in 0..3 {
                assert!(
                    (q[a] - p[a]).abs() < 1e-4 * (1.0 + p[a].abs()),
                    "{p:?} {q:?}"
                );
            }
            let w = g.index_to_world(g.world_to_index(p));
            for a in 0..3 {
                assert!(
                    (w[a] - p[a]).abs() < 1e-4 * (1.0 + p[a].abs()),
                    "{p:?} {w:?}"
                );
            }
        }
        // The world bbox's corner is the index bbox's corner mapped to world.
        let (wlo, _) = g.world_bbox();
        let ilo = g.index_bbox().0.map(|c| c as f32);
        let m = g.index_to_world(ilo);
        for a in 0..3 {
            assert!((f64::from(m[a]) - wlo[a]).abs() < 1e-5);
        }
    }
}

#[test]
fn zip_codec_reads_the_same_grid() {
    let z = grid(&testdata("zip.nvdb"), "density");
    check_against_reference(&z, &reference("fog.density.ref.gz"));
}

#[test]
fn blosc_codec_is_reported() {
    let bytes = testdata("blosc.nvdb");
    assert_eq!(grid_names_from_bytes(&bytes).unwrap(), ["empty"]);
    let e = read_float_grid_from_bytes(&bytes, "empty").unwrap_err();
    assert!(matches!(&e, NanoVdbError::UnsupportedCodec { codec } if codec == "BLOSC"));
    assert!(e.to_string().contains("BLOSC-compressed"), "{e}");
}

#[test]
fn quantised_grid_is_not_float() {
    let bytes = testdata("half.nvdb.gz");
    let e = read_float_grid_from_bytes(&bytes, "density").unwrap_err();
    match &e {
        NanoVdbError::NotFloatGrid { name, found_type } => {
            assert_eq!(name, "density");
            assert_eq!(found_type, "Float16");
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("Float16"));
}

#[test]
fn empty_grid_is_background_everywhere() {
    let g = grid(&testdata("empty.nvdb"), "empty");
    assert_eq!(g.node_counts(), [0, 0, 0]);
    let (lo, hi) = g.index_bbox();
    assert!(lo[0] > hi[0], "an empty grid's bbox is inverted");
    for ijk in [[0, 0, 0], [-5, 7, 100], [i32::MAX, i32::MIN, 0]] {
        assert_eq!(g.value(ijk), 0.0);
    }
    assert_eq!(g.sample_trilinear([0.5, 0.5, 0.5]), 0.0);
}

#[test]
fn missing_grid_lists_the_grids_there_are() {
    let bytes = testdata("ls.nvdb.gz");
    assert!(read_float_grid_from_bytes(&bytes, "density")
        .unwrap()
        .is_none());
    assert_eq!(grid_names_from_bytes(&bytes).unwrap(), ["ls"]);
    let e = require_float_grid_from_bytes(&bytes, "density").unwrap_err();
    assert!(matches!(&e, NanoVdbError::GridNotFound { available, .. } if available == &["ls"]));
    assert_eq!(
        e.to_string(),
        "no grid named \"density\"; the file has \"ls\""
    );
    let two = testdata("two.nvdb.gz");
    let e = require_float_grid_from_bytes(&two, "smoke").unwrap_err();
    assert!(
        e.to_string().ends_with("\"temperature\", \"density\""),
        "{e}"
    );
}

#[test]
fn reads_from_a_path() {
    let path = testdata_path("zip.nvdb");
    assert_eq!(grid_names(&path).unwrap(), ["density"]);
    assert!(read_float_grid(&path, "density").unwrap().is_some());
    assert!(read_float_grid(&path, "temperature").unwrap().is_none());
    assert!(require_float_grid(&path, "density").is_ok());
    let e = read_float_grid(&testdata_path("no-such-file.nvdb"), "density").unwrap_err();
    assert!(matches!(e, NanoVdbError::Io(_)));
}

/// The grid buffers of an uncompressed file (segments of: header, metadata and names, then
/// the grids).
fn grid_buffers(file: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < file.len() {
        let count = u16::from_le_bytes([file[pos + 12], file[pos + 13]]) as usize;
        pos += 16;
        let mut sizes = Vec::new();
        for _ in 0..count {
            let m = &file[pos..pos + 176];
            sizes.push(u64::from_le_bytes(m[8..16].try_into().unwrap()) as usize);
            pos += 176 + u32::from_le_bytes(m[136..140].try_into().unwrap()) as usize;
        }
        for s in sizes {
            out.push(file[pos..pos + s].to_vec());
            pos += s;
        }
    }
    out
}

#[test]
fn raw_grid_buffer_files() {
    // NanoVDB 32.6 and later can write a file that is just grid buffers, with the grid magic
    // "NanoVDB1"; older raw dumps start with "NanoVDB0" like a segment.
    let two = testdata("two.nvdb.gz");
    let buffers = grid_buffers(&two);
    let raw: Vec<u8> = buffers.concat();
    assert_eq!(
        grid_names_from_bytes(&raw).unwrap(),
        ["temperature", "density"]
    );
    let d = grid(&raw, "density");
    check_against_reference(&d, &reference("fog.density.ref.gz"));

    let mut new = buffers.clone();
    for b in &mut new {
        b[7] = b'1';
        // Version 32.6.0.
        b[16..20].copy_from_slice(&(32u32 << 21 | 6 << 10).to_le_bytes());
    }
    let raw_new = new.concat();
    let t = grid(&raw_new, "temperature");
    check_against_reference(&t, &reference("two.temperature.ref.gz"));
}

#[test]
fn newer_segment_magic_and_minor_versions_read() {
    // 32.6+ files start their segments with "NanoVDB2"; the minor version does not matter.
    let mut bytes = testdata("fog.nvdb.gz");
    bytes[7] = b'2';
    bytes[8..12].copy_from_slice(&(32u32 << 21 | 7 << 10 | 1).to_le_bytes());
    let g = grid(&bytes, "density");
    assert_eq!(g.value([0, 0, 0]), 1.0);
}

#[test]
fn bad_headers_are_errors() {
    let good = testdata("fog.nvdb.gz");
    let err = |b: &[u8]| read_float_grid_from_bytes(b, "density").unwrap_err();

    assert!(matches!(err(b""), NanoVdbError::NotNanoVdb));
    assert!(matches!(err(b"Nano"), NanoVdbError::Truncated { .. }));
    assert!(matches!(
        err(b"hello, world, this is text"),
        NanoVdbError::NotNanoVdb
    ));
    let mut b = good.clone();
    b[0] = b'M';
    assert!(matches!(err(&b), NanoVdbError::NotNanoVdb));
    assert!(err(&b).to_string().starts_with("not a NanoVDB file"));

    let mut swapped = good.clone();
    swapped[..8].reverse();
    assert!(matches!(err(&swapped), NanoVdbError::Corrupt(_)));

    let mut old = good.clone();
    old[8..12].copy_from_slice(&(31u32 << 21 | 2 << 10).to_le_bytes());
    let e = err(&old);
    assert!(matches!(
        e,
        NanoVdbError::UnsupportedVersion {
            major: 31,
            minor: 2,
            patch: 0
        }
    ));
    assert!(e.to_string().contains("31.2.0"), "{e}");

    // Sizes claimed far beyond the file are truncation, not allocation.
    for (at, value) in [
        (16usize, u64::MAX), // gridSize
        (24, u64::MAX),      // fileSize
        (24, 1 << 40),
    ] {
        let mut b = good.clone();
        b[at..at + 8].copy_from_slice(&value.to_le_bytes());
        assert!(read_float_grid_from_bytes(&b, "density").is_err(), "{at}");
    }
    let mut b = good.clone();
    b[16 + 136..16 + 140].copy_from_slice(&u32::MAX.to_le_bytes()); // nameSize
    assert!(matches!(
        err(&b),
        NanoVdbError::Truncated {
            what: "grid name",
            ..
        }
    ));
    let mut b = good.clone();
    b[12..14].copy_from_slice(&u16::MAX.to_le_bytes()); // grid count
    assert!(matches!(err(&b), NanoVdbError::Truncated { .. }));
    // Trailing bytes after the last grid that are not a segment.
    let mut b = good.clone();
    b.extend_from_slice(&[0u8; 40]);
    assert!(matches!(err(&b), NanoVdbError::Corrupt(_)));
    let mut b = good.clone();
    b.extend_from_slice(b"NanoVDB0");
    assert!(matches!(err(&b), NanoVdbError::Truncated { .. }));
}

/// Offset of the (first) grid buffer in a one-grid, one-segment file.
fn grid_start(file: &[u8]) -> usize {
    16 + 176 + u32::from_le_bytes(file[16 + 136..16 + 140].try_into().unwrap()) as usize
}

#[test]
fn bad_node_offsets_are_errors() {
    let good = testdata("fog.nvdb.gz");
    let g0 = grid_start(&good);
    let tree = g0 + 672;
    let root = tree + u64::from_le_bytes(good[tree + 24..tree + 32].try_into().unwrap()) as usize;
    let tile0_child = root + 64 + 8;
    let child0 = i64::from_le_bytes(good[tile0_child..tile0_child + 8].try_into().unwrap());
    assert_ne!(child0, 0, "the first root tile has a child");
    let patched = |at: usize, bytes: &[u8]| {
        let mut b = good.clone();
        b[at..at + bytes.len()].copy_from_slice(bytes);
        read_float_grid_from_bytes(&b, "density")
    };
    for bad in [
        i64::MAX,
        i64::MIN,
        -(root as i64) - 32,
        child0 + 4,
        (good.len() - root) as i64,
    ] {
        let r = patched(tile0_child, &bad.to_le_bytes());
        assert!(matches!(r, Err(NanoVdbError::Corrupt(_))), "{bad}: {r:?}");
    }
    // Offsets are relative to the root: a second tile may share the first one's node, but
    // not point 32 bytes into it.
    let r = patched(root + 64 + 32 + 8, &child0.to_le_bytes());
    assert!(
        r.is_ok(),
        "pointing a second tile at the same node is allowed"
    );
    let r = patched(root + 64 + 32 + 8, &(child0 + 32).to_le_bytes());
    assert!(
        matches!(&r, Err(NanoVdbError::Corrupt(m)) if m.contains("overlap")),
        "{r:?}"
    );
    // A tile table longer than the grid.
    let r = patched(root + 24, &u32::MAX.to_le_bytes());
    assert!(matches!(r, Err(NanoVdbError::Corrupt(_))));
    // The root outside the grid.
    let r = patched(tree + 24, &u64::MAX.to_le_bytes());
    assert!(matches!(r, Err(NanoVdbError::Corrupt(_))));
    // A grid type other than float inside the buffer.
    let r = patched(g0 + 636, &2u32.to_le_bytes());
    assert!(matches!(r, Err(NanoVdbError::NotFloatGrid { .. })));
}

#[test]
fn every_truncation_is_an_error() {
    for name in ["fog.nvdb.gz", "two.nvdb.gz", "zip.nvdb", "empty.nvdb"] {
        let good = testdata(name);
        let grids = grid_names_from_bytes(&good).unwrap();
        let mut cuts: Vec<usize> = (0..2000.min(good.len())).collect();
        cuts.extend((2000..good.len()).step_by(997));
        cuts.extend(good.len().saturating_sub(100)..good.len());
        for cut in cuts {
            let b = &good[..cut];
            for g in &grids {
                let r = read_float_grid_from_bytes(b, g);
                assert!(r.is_err(), "{name} cut at {cut} read {g}");
            }
            assert!(grid_names_from_bytes(b).is_err(), "{name} cut at {cut}");
        }
    }
}

/// A small deterministic generator (splitmix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// `RPBRT_FUZZ_ITERS` sets the rounds per file (default 300).
#[test]
fn byte_flips_never_panic() {
    let rounds = std::env::var("RPBRT_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let mut rng = Rng(7);
    for name in ["fog.nvdb.gz", "two.nvdb.gz", "zip.nvdb"] {
        let good = testdata(name);
        let grids = grid_names_from_bytes(&good).unwrap();
        // Flip where the data is: headers, masks, child offsets and values are the non-zero
        // bytes (and the zero bytes next to them); plus anywhere at all.
        let nonzero: Vec<usize> = (0..good.len()).filter(|&i| good[i] != 0).collect();
        let mut ok = 0;
        for round in 0..rounds {
            let mut b = good.clone();
            for _ in 0..1 + rng.below(4) {
                let at = match round % 3 {
                    0 => rng.below(good.len()),
                    1 => rng.below(1200.min(good.len())),
                    _ => (nonzero[rng.below(nonzero.len())] + rng.below(8)).min(good.len() - 1),
                };
                b[at] ^= 1 << rng.below(8);
            }
            for g in &grids {
                if let Ok(Some(grid)) = read_float_grid_from_bytes(&b, g) {
                    ok += 1;
                    // Lookups on whatever was accepted stay in bounds.
                    let (lo, hi) = grid.index_bbox();
                    for c in [lo, hi, [0, 0, 0], [-1, -1, -1], [4095, -4096, 127]] {
                        let _ = grid.value(c);
                        let _ = grid.sample_trilinear(c.map(|x| x as f32 + 0.5));
                    }
                }
            }
        }
        assert!(ok > 0, "{name}: some flips leave a readable grid");
    }
}

/// Needs the third-party scenes in `../shared/scenes` beside the project.
#[test]
#[ignore = "needs ../shared/scenes/nanovdb-sphere beside the project"]
fn shared_sphere_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/nanovdb-sphere/sphere.nvdb");
    assert!(path.exists(), "{} is missing", path.display());
    assert_eq!(grid_names(&path).unwrap(), ["density"]);
    let g = require_float_grid(&path, "density").unwrap();
    // As `nanovdb_print -l sphere.nvdb` reports it: FOG, bbox (-20,-20,-20) -> (20,20,20),
    // world bbox (-0.952,...) -> (1,1,1), voxel 1/21, 8 upper, 8 lower, 146 leaf nodes.
    assert_eq!(g.grid_class(), GridClass::FogVolume);
    assert_eq!(g.index_bbox(), ([-20; 3], [20; 3]));
    assert_eq!(g.node_counts(), [8, 8, 146]);
    let (lo, hi) = g.world_bbox();
    for a in 0..3 {
        assert!((lo[a] + 0.952).abs() < 1e-3 && (hi[a] - 1.0).abs() < 1e-6);
        assert!((g.voxel_size()[a] - 1.0 / 21.0).abs() < 1e-4);
    }
    let (min, max) = g.min_max();
    assert!(min >= 0.0 && max == 1.0);
    assert_eq!(g.value([0, 0, 0]), 1.0);
    let centre = g.world_to_index([0.0, 0.0, 0.0]);
    assert!((g.sample_trilinear(centre) - 1.0).abs() < 1e-6);
    assert_eq!(g.value([25, 0, 0]), 0.0);
    for i in -21..=21 {
        let v = g.value([i, i / 2, -i / 3]);
        assert!((0.0..=1.0).contains(&v));
    }
}
