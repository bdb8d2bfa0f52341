//! Ptex tests: files written by a small test-only writer, read back,
//! looked up, damaged; textures created from scene text.

use super::reader::*;
use super::*;
use crate::rng::Rng;
use crate::texture::{FloatTexture, SpectrumTexture, TextureEvalContext};
use half::f16;
use rpbrt_geometry::tuple::*;
use std::io::Write;

/// How the writer stores a face.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Store {
    Zipped,
    DiffZipped,
    /// Tiled with 2^n × 2^n tiles; tile 0 is stored constant-encoded when
    /// its texels are all equal.
    Tiled(u8),
    /// Flagged constant (only in the constant-data block).
    ConstantFlag,
}

pub(super) struct TestFace {
    pub(super) ulog2: u8,
    pub(super) vlog2: u8,
    /// Interleaved texels.
    pub(super) texels: Vec<f32>,
    pub(super) store: Store,
    pub(super) adj: [i32; 4],
}

fn zip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn encode(v: f32, dt: PtexDataType, out: &mut Vec<u8>) {
    match dt {
        PtexDataType::U8 => out.push((v * 255.0).round().clamp(0.0, 255.0) as u8),
        PtexDataType::U16 => out.extend(((v * 65535.0).round() as u16).to_le_bytes()),
        PtexDataType::Half => out.extend(f16::from_f32(v).to_bits().to_le_bytes()),
        PtexDataType::Float => out.extend(v.to_le_bytes()),
    }
}

/// The value `v` stored as `dt` and read back.
fn quantize(v: f32, dt: PtexDataType) -> f32 {
    match dt {
        PtexDataType::U8 => (v * 255.0).round().clamp(0.0, 255.0) / 255.0,
        PtexDataType::U16 => (v * 65535.0).round() / 65535.0,
        PtexDataType::Half => f16::from_f32(v).to_f32(),
        PtexDataType::Float => v,
    }
}

/// Planar, optionally differenced, zipped block of `w` × `h` texels taken
/// from `t` (row stride `stride`, origin (u0, v0)).
#[allow(clippy::too_many_arguments)]
fn block(
    t: &[f32],
    nc: usize,
    stride: usize,
    u0: usize,
    v0: usize,
    w: usize,
    h: usize,
    dt: PtexDataType,
    diff: bool,
) -> Vec<u8> {
    let mut raw = Vec::new();
    for c in 0..nc {
        for v in 0..h {
            for u in 0..w {
                encode(t[((v0 + v) * stride + u0 + u) * nc + c], dt, &mut raw);
            }
        }
    }
    if diff {
        match dt {
            PtexDataType::U8 => {
                let mut prev = 0u8;
                for b in raw.iter_mut() {
                    let cur = *b;
                    *b = cur.wrapping_sub(prev);
                    prev = cur;
                }
            }
            PtexDataType::U16 => {
                let mut prev = 0u16;
                for c in raw.chunks_exact_mut(2) {
                    let cur = u16::from_le_bytes([c[0], c[1]]);
                    c.copy_from_slice(&cur.wrapping_sub(prev).to_le_bytes());
                    prev = cur;
                }
            }
            _ => {}
        }
    }
    zip(&raw)
}

fn fdh(size: usize, enc: u32) -> [u8; 4] {
    ((size as u32 & 0x3fff_ffff) | (enc << 30)).to_le_bytes()
}

/// Writes a one-level quad Ptex file.
fn write_ptex(faces: &[TestFace], dt: PtexDataType, nc: usize, border: [u32; 2]) -> Vec<u8> {
    write_ptex_mesh(faces, dt, nc, border, false, &[])
}

/// Writes a one-level Ptex file of triangles or quads; `edges[i]` is face
/// i's packed adjacent-edge byte (0 where missing).
pub(super) fn write_ptex_mesh(
    faces: &[TestFace],
    dt: PtexDataType,
    nc: usize,
    border: [u32; 2],
    triangles: bool,
    edges: &[u8],
) -> Vec<u8> {
    let mut infos = Vec::new();
    let mut consts = Vec::new();
    let mut hdrs = Vec::new();
    let mut blocks = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        let (w, h) = (1usize << f.ulog2, 1usize << f.vlog2);
        let constant = f.store == Store::ConstantFlag;
        let e = edges.get(i).copied().unwrap_or(0);
        infos.extend([f.ulog2, f.vlog2, e, if constant { 1 } else { 0 }]);
        for a in f.adj {
            infos.extend(a.to_le_bytes());
        }
        for c in 0..nc {
            let mean = (0..w * h).map(|i| f.texels[i * nc + c]).sum::<f32>() / (w * h) as f32;
            encode(mean, dt, &mut consts);
        }
        let diff = matches!(dt, PtexDataType::U8 | PtexDataType::U16);
        let data = match f.store {
            Store::ConstantFlag => {
                hdrs.extend(fdh(0, 0));
                continue;
            }
            Store::Zipped => (block(&f.texels, nc, w, 0, 0, w, h, dt, false), 1),
            Store::DiffZipped => (
                block(&f.texels, nc, w, 0, 0, w, h, dt, diff),
                if diff { 2 } else { 1 },
            ),
            Store::Tiled(tl) => {
                let ts = 1usize << tl;
                let (ntu, ntv) = (w / ts, h / ts);
                let mut th = Vec::new();
                let mut tdata = Vec::new();
                for t in 0..ntu * ntv {
                    let (u0, v0) = ((t % ntu) * ts, (t / ntu) * ts);
                    let first = &f.texels[(v0 * w + u0) * nc..(v0 * w + u0) * nc + nc];
                    let uniform = (0..ts).all(|v| {
                        (0..ts).all(|u| &f.texels[((v0 + v) * w + u0 + u) * nc..][..nc] == first)
                    });
                    if t == 0 && uniform {
                        let mut px = Vec::new();
                        for &x in first {
                            encode(x, dt, &mut px);
                        }
                        th.extend(fdh(px.len(), 0));
                        tdata.extend(px);
                    } else {
                        let b = block(&f.texels, nc, w, u0, v0, ts, ts, dt, diff);
                        th.extend(fdh(b.len(), if diff { 2 } else { 1 }));
                        tdata.extend(b);
                    }
                }
                let zth = zip(&th);
                let mut out = vec![tl, tl];
                out.extend((zth.len() as u32).to_le_bytes());
                out.extend(zth);
                out.extend(tdata);
                (out, 3)
            }
        };
        hdrs.extend(fdh(data.0.len(), data.1));
        blocks.extend(data.0);
    }
    let zinfos = zip(&infos);
    let zconsts = zip(&consts);
    let zhdrs = zip(&hdrs);
    let level_size = zhdrs.len() + blocks.len();
    let mut levelinfo = Vec::new();
    levelinfo.extend((level_size as u64).to_le_bytes());
    levelinfo.extend((zhdrs.len() as u32).to_le_bytes());
    levelinfo.extend((faces.len() as u32).to_le_bytes());
    let mut ext = Vec::new();
    ext.extend(border[0].to_le_bytes());
    ext.extend(border[1].to_le_bytes());
    ext.resize(40, 0);

    let mut out = Vec::new();
    out.extend(b"Ptex");
    out.extend(1u32.to_le_bytes());
    out.extend(u32::from(!triangles).to_le_bytes()); // 0: triangles, 1: quads
    let dtv: u32 = match dt {
        PtexDataType::U8 => 0,
        PtexDataType::U16 => 1,
        PtexDataType::Half => 2,
        PtexDataType::Float => 3,
    };
    out.extend(dtv.to_le_bytes());
    out.extend((-1i32).to_le_bytes());
    out.extend((nc as u16).to_le_bytes());
    out.extend(1u16.to_le_bytes());
    out.extend((faces.len() as u32).to_le_bytes());
    out.extend((ext.len() as u32).to_le_bytes());
    out.extend((zinfos.len() as u32).to_le_bytes());
    out.extend((zconsts.len() as u32).to_le_bytes());
    out.extend((levelinfo.len() as u32).to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.extend((level_size as u64).to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    assert_eq!(out.len(), 64);
    out.extend(ext);
    out.extend(zinfos);
    out.extend(zconsts);
    out.extend(levelinfo);
    out.extend(zhdrs);
    out.extend(blocks);
    out
}

/// Texels with a pattern that varies by face, texel and channel.
fn pattern(face: usize, ulog2: u8, vlog2: u8, nc: usize) -> Vec<f32> {
    let (w, h) = (1usize << ulog2, 1usize << vlog2);
    let mut t = Vec::new();
    for v in 0..h {
        for u in 0..w {
            for c in 0..nc {
                t.push(((face * 7 + u * 3 + v * 5 + c * 11) % 17) as f32 / 16.0);
            }
        }
    }
    t
}

fn test_faces(nc: usize) -> Vec<TestFace> {
    let mut tiled = pattern(2, 3, 3, nc);
    // Tile 0 (4x4 at the origin) uniform so it is stored constant-encoded.
    for v in 0..4 {
        for u in 0..4 {
            for c in 0..nc {
                tiled[(v * 8 + u) * nc + c] = 0.25 + 0.25 * c as f32;
            }
        }
    }
    vec![
        TestFace {
            ulog2: 2,
            vlog2: 1,
            texels: pattern(0, 2, 1, nc),
            store: Store::Zipped,
            adj: [-1; 4],
        },
        TestFace {
            ulog2: 1,
            vlog2: 1,
            texels: vec![0.5; 4 * nc],
            store: Store::ConstantFlag,
            adj: [-1; 4],
        },
        TestFace {
            ulog2: 3,
            vlog2: 3,
            texels: tiled,
            store: Store::Tiled(2),
            adj: [-1; 4],
        },
        TestFace {
            ulog2: 0,
            vlog2: 0,
            texels: vec![0.75; nc],
            store: Store::Zipped,
            adj: [-1; 4],
        },
        TestFace {
            ulog2: 1,
            vlog2: 3,
            texels: pattern(4, 1, 3, nc),
            store: Store::DiffZipped,
            adj: [-1; 4],
        },
    ]
}

const TYPES: [PtexDataType; 4] = [
    PtexDataType::U8,
    PtexDataType::U16,
    PtexDataType::Half,
    PtexDataType::Float,
];

fn tol(dt: PtexDataType) -> f32 {
    match dt {
        PtexDataType::Half => 1e-3,
        _ => 1e-6,
    }
}

#[test]
fn texels_round_trip() {
    for dt in TYPES {
        for nc in [1, 3] {
            let faces = test_faces(nc);
            let bytes = write_ptex(&faces, dt, nc, [0, 0]);
            let file = PtexFile::parse(&bytes, "t.ptx").unwrap();
            assert_eq!(file.faces.len(), faces.len());
            assert_eq!(file.nchannels, nc);
            assert_eq!(file.data_type, dt);
            for (i, (f, tf)) in file.faces.iter().zip(&faces).enumerate() {
                assert_eq!((f.ulog2, f.vlog2), (tf.ulog2, tf.vlog2));
                let constant = tf.store == Store::ConstantFlag || tf.texels.len() == nc;
                assert_eq!(f.is_constant(), constant, "face {i}");
                match &f.texels {
                    Some(t) => {
                        assert_eq!(t.len(), tf.texels.len());
                        for (a, b) in t.iter().zip(&tf.texels) {
                            assert!(
                                (a - quantize(*b, dt)).abs() <= tol(dt),
                                "{dt:?} {nc} face {i}: {a} vs {b}"
                            );
                        }
                    }
                    None => {
                        for (c, v) in f.constant.iter().enumerate() {
                            assert!(
                                (v - quantize(tf.texels[c], dt)).abs() <= tol(dt),
                                "face {i}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// The lookup at a texel centre with zero derivatives, computed
/// independently: per axis, B-spline weights 1/6, 2/3, 1/6 on faces of 4
/// or more texels, Ptex's smoothstep kernel (stretched by 1/0.8) on faces
/// of 2; edges clamped.
fn centre_reference(
    t: &[f32],
    w: usize,
    h: usize,
    nc: usize,
    iu: usize,
    iv: usize,
    c: usize,
) -> f32 {
    let axis = |n: usize| -> [(i32, f32); 3] {
        if n >= 4 {
            [(-1, 1.0 / 6.0), (0, 2.0 / 3.0), (1, 1.0 / 6.0)]
        } else {
            let x: f32 = 0.8;
            let e = (2.0 * x - 3.0) * x * x + 1.0;
            let sum = 1.0 + 2.0 * e;
            [(-1, e / sum), (0, 1.0 / sum), (1, e / sum)]
        }
    };
    let mut s = 0.0;
    for (dv, wv) in axis(h) {
        for (du, wu) in axis(w) {
            let u = (iu as i32 + du).clamp(0, w as i32 - 1) as usize;
            let v = (iv as i32 + dv).clamp(0, h as i32 - 1) as usize;
            s += wu * wv * t[(v * w + u) * nc + c];
        }
    }
    s
}

#[test]
#[allow(clippy::needless_range_loop)]
fn lookups_at_texel_centres() {
    for dt in TYPES {
        for nc in [1, 3] {
            let faces = test_faces(nc);
            let file = PtexFile::parse(&write_ptex(&faces, dt, nc, [0, 0]), "t.ptx").unwrap();
            let mut out = [0.0f32; 3];
            for (i, tf) in faces.iter().enumerate() {
                let (w, h) = (1usize << tf.ulog2, 1usize << tf.vlog2);
                let q: Vec<f32> = tf.texels.iter().map(|&x| quantize(x, dt)).collect();
                for iv in 0..h {
                    for iu in 0..w {
                        let (u, v) = ((iu as f32 + 0.5) / w as f32, (iv as f32 + 0.5) / h as f32);
                        file.eval(&mut out, i as i32, u, v, 0.0, 0.0, 0.0, 0.0);
                        for c in 0..nc {
                            let e = if tf.store == Store::ConstantFlag {
                                file.faces[i].constant[c]
                            } else {
                                centre_reference(&q, w, h, nc, iu, iv, c)
                            };
                            assert!(
                                (out[c] - e).abs() < 1e-4,
                                "{dt:?} face {i} ({iu},{iv}) c{c}: {} vs {e}",
                                out[c]
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn linear_ramps_are_reproduced_and_footprints_average() {
    // 16x16 face with value u-index / 15: a B-spline reproduces it
    // exactly away from the edges.
    let (l, n) = (4u8, 16usize);
    let texels: Vec<f32> = (0..n * n).map(|i| (i % n) as f32 / 15.0).collect();
    let faces = [TestFace {
        ulog2: l,
        vlog2: l,
        texels,
        store: Store::Zipped,
        adj: [-1; 4],
    }];
    let file =
        PtexFile::parse(&write_ptex(&faces, PtexDataType::Float, 1, [0, 0]), "r.ptx").unwrap();
    let mut out = [0.0f32; 3];
    for x in [0.3f32, 0.41, 0.5, 0.66] {
        file.eval(&mut out, 0, x, 0.5, 0.0, 0.0, 0.0, 0.0);
        let e = (x * n as f32 - 0.5) / 15.0;
        assert!((out[0] - e).abs() < 1e-5, "{x}: {} vs {e}", out[0]);
        // A wider footprint (4 texels: resolution 4) still reproduces
        // the ramp in the middle, from box-averaged texels.
        file.eval(&mut out, 0, 0.5, 0.5, 0.2, 0.0, 0.0, 0.2);
        assert!((out[0] - 0.5).abs() < 1e-4, "{}", out[0]);
    }
    // A footprint of the whole face gives the face's mean.
    file.eval(&mut out, 0, 0.5, 0.5, 2.0, 0.0, 0.0, 2.0);
    assert!((out[0] - 0.5).abs() < 1e-5, "{}", out[0]);
}

#[test]
fn black_border_darkens_and_periodic_wraps() {
    let texels = vec![1.0f32; 16];
    let faces = [TestFace {
        ulog2: 2,
        vlog2: 2,
        texels,
        store: Store::Zipped,
        adj: [-1; 4],
    }];
    let mut out = [0.0f32; 3];
    let black =
        PtexFile::parse(&write_ptex(&faces, PtexDataType::Float, 1, [1, 1]), "b.ptx").unwrap();
    black.eval(&mut out, 0, 0.5 / 4.0, 0.5, 0.0, 0.0, 0.0, 0.0);
    assert!((out[0] - 5.0 / 6.0).abs() < 1e-5, "{}", out[0]);
    // With a neighbour on the left, the edge is treated as clamp.
    let faces2 = [
        TestFace {
            ulog2: 2,
            vlog2: 2,
            texels: vec![1.0; 16],
            store: Store::Zipped,
            adj: [-1, -1, -1, 1],
        },
        TestFace {
            ulog2: 2,
            vlog2: 2,
            texels: vec![1.0; 16],
            store: Store::Zipped,
            adj: [-1, 0, -1, -1],
        },
    ];
    let f2 = PtexFile::parse(
        &write_ptex(&faces2, PtexDataType::Float, 1, [1, 1]),
        "n.ptx",
    )
    .unwrap();
    f2.eval(&mut out, 0, 0.5 / 4.0, 0.5, 0.0, 0.0, 0.0, 0.0);
    assert!((out[0] - 1.0).abs() < 1e-5, "{}", out[0]);
    let t: Vec<f32> = (0..16).map(|i| (i % 4) as f32).collect();
    let faces = [TestFace {
        ulog2: 2,
        vlog2: 2,
        texels: t,
        store: Store::Zipped,
        adj: [-1; 4],
    }];
    let per =
        PtexFile::parse(&write_ptex(&faces, PtexDataType::Float, 1, [2, 2]), "p.ptx").unwrap();
    // Periodic wraps the lookup coordinate; as in Ptex, taps past a
    // border without a neighbour fold onto the edge texel (a periodic
    // file wraps its filter through its adjacency).
    per.eval(&mut out, 0, 0.5 / 4.0, 0.5, 0.0, 0.0, 0.0, 0.0);
    assert!((out[0] - 1.0 / 6.0).abs() < 1e-5, "{}", out[0]);
    let mut wrapped = [0.0f32; 3];
    per.eval(&mut wrapped, 0, 1.0 + 0.5 / 4.0, 0.5, 0.0, 0.0, 0.0, 0.0);
    assert!((wrapped[0] - out[0]).abs() < 1e-6, "{}", wrapped[0]);
    // Black: a lookup a face or more outside is black.
    black.eval(&mut out, 0, 2.5, 0.5, 0.0, 0.0, 0.0, 0.0);
    assert_eq!(out[0], 0.0);
}

#[test]
fn face_index_out_of_range_is_zero() {
    let faces = test_faces(3);
    let file = PtexFile::parse(&write_ptex(&faces, PtexDataType::U8, 3, [0, 0]), "t.ptx").unwrap();
    let mut out = [9.0f32; 3];
    for face in [-1, 5, 1000, i32::MAX, i32::MIN] {
        out = [9.0; 3];
        file.eval(&mut out, face, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(out, [0.0; 3]);
    }
    // Non-finite coordinates and derivatives do not panic.
    file.eval(
        &mut out,
        0,
        f32::NAN,
        0.5,
        f32::INFINITY,
        0.0,
        0.0,
        f32::NAN,
    );
    file.eval(&mut out, 2, 1e30, -1e30, 1e30, 0.0, 0.0, 0.0);
}

#[test]
fn damaged_files_are_errors() {
    let faces = test_faces(3);
    let bytes = write_ptex(&faces, PtexDataType::U16, 3, [0, 0]);
    assert!(PtexFile::parse(&bytes, "t.ptx").is_ok());
    for len in 0..bytes.len() {
        assert!(
            PtexFile::parse(&bytes[..len], "t.ptx").is_err(),
            "prefix {len} accepted"
        );
    }
    let mut bad = bytes.clone();
    bad[0] = b'Q';
    assert!(PtexFile::parse(&bad, "t.ptx")
        .unwrap_err()
        .contains("not a Ptex file"));
    // Huge counts in the header fail without allocating for them.
    let mut bad = bytes.clone();
    bad[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(PtexFile::parse(&bad, "t.ptx").is_err());
    // Random corruption: errors or values, never panics.
    let mut rng = Rng::new(7, 0);
    for _ in 0..2000 {
        let mut b = bytes.clone();
        for _ in 0..1 + rng.uniform_bounded(4) {
            let i = rng.uniform_bounded(b.len() as u32) as usize;
            b[i] = rng.uniform_u32() as u8;
        }
        if let Ok(f) = PtexFile::parse(&b, "t.ptx") {
            let mut out = vec![0.0f32; f.nchannels.max(3)];
            for face in 0..f.faces.len() as i32 {
                f.eval(&mut out, face, 0.3, 0.7, 0.01, 0.0, 0.0, 0.3);
            }
        }
    }
    // Read errors name the file.
    let e = PtexFile::read(std::path::Path::new("/nonexistent/q.ptx")).unwrap_err();
    assert!(e.contains("q.ptx"), "{e}");
}

#[test]
fn textures_from_scene() {
    let dir = std::env::temp_dir().join(format!("rpbrt-ptex-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let faces = test_faces(3);
    let path = dir.join("c.ptx");
    std::fs::write(&path, write_ptex(&faces, PtexDataType::U8, 3, [0, 0])).unwrap();
    // What `Texture "f" "float" "ptex" "string filename" ... "float scale" 2`
    // and `Texture "s" "spectrum" "ptex" ... "string encoding" "linear"`
    // give.
    let l = rpbrt_parser::FileLoc::new(Arc::from("t.pbrt"), 1, 1);
    let file = || {
        rpbrt_parser::ParsedParameter::with_strings(
            "string",
            "filename",
            l.clone(),
            vec![path.display().to_string()],
        )
    };
    let fparams = rpbrt_parser::ParameterDictionary::new(vec![
        file(),
        rpbrt_parser::ParsedParameter::with_floats("float", "scale", l.clone(), vec![2.0]),
    ]);
    let sparams = rpbrt_parser::ParameterDictionary::new(vec![
        file(),
        rpbrt_parser::ParsedParameter::with_strings(
            "string",
            "encoding",
            l.clone(),
            vec!["linear".into()],
        ),
    ]);
    let cache = crate::image::MIPMapCache::new();
    let options = crate::texture::TextureOptions::default();
    let mut named = crate::texture::NamedTextures::default();
    let def = |name| crate::texture::TextureDef {
        name,
        class: "ptex",
        render_from_texture: rpbrt_geometry::transform::Transform::identity(),
    };
    let tp =
        crate::texture::TextureParams::new(crate::params::ParamReader::plain(&fparams, &l), &named);
    let f = crate::texture::create_float_texture(&def("f"), &tp, &cache, &options).unwrap();
    assert!(tp.finish().is_empty());
    let mut spectra = Vec::new();
    let tp =
        crate::texture::TextureParams::new(crate::params::ParamReader::plain(&sparams, &l), &named);
    for ty in [
        SpectrumType::Albedo,
        SpectrumType::Unbounded,
        SpectrumType::Illuminant,
    ] {
        let s = crate::texture::create_spectrum_texture(&def("s"), ty, &tp, &cache, &options);
        spectra.push((ty, s.unwrap()));
    }
    assert!(tp.finish().is_empty());
    named.float.insert("f".into(), f);
    for (ty, s) in spectra {
        named.spectrum_mut(ty).insert("s".into(), s);
    }
    let ctx = TextureEvalContext {
        uv: Point2f::new(0.5, 0.5),
        face_index: 1,
        ..Default::default()
    };
    // Face 1 is constant 0.5 (stored as 128/255): gamma 2.2 then scale 2.
    let FloatTexture::Ptex(ft) = &*named.float["f"] else {
        panic!("not a ptex texture")
    };
    let e = 2.0 * (128.0f32 / 255.0).powf(2.2);
    assert!((ft.evaluate(&ctx) - e).abs() < 1e-5);
    for ty in [
        SpectrumType::Albedo,
        SpectrumType::Unbounded,
        SpectrumType::Illuminant,
    ] {
        let SpectrumTexture::Ptex(st) = &*named.spectrum(ty)["s"] else {
            panic!("not a ptex texture")
        };
        assert_eq!(st.spectrum_type, ty);
        // One file, shared.
        assert!(Arc::ptr_eq(&st.base.file, &ft.base.file));
    }
    let SpectrumTexture::Ptex(st) = &*named.albedo["s"] else {
        unreachable!()
    };
    let mut r = [0.0; 3];
    assert_eq!(st.base.sample(&ctx, &mut r), 3);
    for v in r {
        assert!((v - 128.0 / 255.0).abs() < 1e-6, "{r:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
