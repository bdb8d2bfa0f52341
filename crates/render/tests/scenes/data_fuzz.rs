//! A seeded mutation fuzzer over the binary and data files scenes refer to:
//! PLY meshes, NanoVDB grids, images (EXR, PNG, PFM, HDR, TGA, QOI) and
//! spectrum files. Each file is mutated at the byte level (flipped bits,
//! extreme integers written over header fields and counts, truncation,
//! spliced and deleted chunks) and handed to its reader; the only
//! requirement is that every outcome is a value or a typed error: no
//! panic, no hang, no allocation sized by a corrupted count.
//!
//! The files are every such file under `../shared/scenes` (when present)
//! plus small ones written here, so the test means something on a fresh
//! clone too. EXR files also get header damage aimed at their attributes
//! (sizes, windows, channel lists, compression, chunk counts) and offset
//! tables. Resource claims: small files whose valid headers claim images
//! and meshes far larger than the memory budget they are read with (a
//! zero-filled PNG, EXR and QOI, a gzip PLY of many-sided polygons), so
//! that the budget checks after headers and while inflating are fuzzed
//! too; every read is held against a budget, and running past it is an
//! error like any other.
//!
//! `RPBRT_FUZZ_ITERS` sets the mutations per file (default 60);
//! `RPBRT_FUZZ_SECONDS`, if set, keeps going over fresh seeds until that
//! much time has passed and prints the count; rounds of seeds start at
//! `RPBRT_FUZZ_FIRST_ROUND` (default 0), so that runs in chunks need not
//! repeat each other.

use rpbrt_geometry::Point2i;
use rpbrt_parser::ply::parse_ply_within;
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::{ColorEncoding, Image, ImageMetadata, PixelFormat};
use rpbrt_render::medium::nanovdb::read_float_grid_from_bytes;
use rpbrt_render::rng::Rng;
use rpbrt_render::spectrum::read_spectrum_file;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Values that break careless readers when written over a field.
const EXTREMES: [u32; 7] = [
    0,
    1,
    0xFFFF_FFFF,
    0x7FFF_FFFF,
    0x8000_0000,
    0x0001_0000,
    0x4000_0000,
];

fn mutate(src: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut v = src.to_vec();
    let n = 1 + rng.uniform_bounded(4);
    for _ in 0..n {
        if v.is_empty() {
            v.push(0);
        }
        // Headers hold the counts and offsets: aim half the mutations at
        // the first 512 bytes.
        let span = if rng.uniform_bounded(2) == 0 {
            v.len().min(512)
        } else {
            v.len()
        };
        let pos = rng.uniform_bounded(span as u32) as usize;
        match rng.uniform_bounded(7) {
            0 => v[pos] ^= 1 << rng.uniform_bounded(8),
            1 => v[pos] = rng.uniform_u32() as u8,
            2 => {
                let x = EXTREMES[rng.uniform_bounded(EXTREMES.len() as u32) as usize];
                let at = pos & !3;
                for (k, b) in x.to_le_bytes().iter().enumerate() {
                    if let Some(slot) = v.get_mut(at + k) {
                        *slot = *b;
                    }
                }
            }
            3 => v.truncate(pos),
            4 => {
                let end = (pos + 1 + rng.uniform_bounded(64) as usize).min(v.len());
                let chunk = v[pos..end].to_vec();
                let at = rng.uniform_bounded(v.len() as u32) as usize;
                v.splice(at..at, chunk);
            }
            5 => {
                let end = (pos + 1 + rng.uniform_bounded(64) as usize).min(v.len());
                v.drain(pos..end);
            }
            _ => {
                // Text formats (PLY headers, PFM, spectra): a digit
                // becomes a large number.
                if v[pos].is_ascii_digit() {
                    v.splice(pos..pos + 1, b"99999999999".iter().copied());
                }
            }
        }
    }
    v
}

/// One attribute of an EXR header: where its size field and value lie.
struct ExrAttribute {
    name: String,
    size_at: usize,
    value: std::ops::Range<usize>,
}

/// The attributes of the first header of an EXR file, and where the
/// header ends (the offset table follows for single-part files).
fn exr_attributes(b: &[u8]) -> (Vec<ExrAttribute>, usize) {
    let mut out = Vec::new();
    let mut pos = 8;
    let cstr = |pos: &mut usize| -> Option<String> {
        let end = *pos + b.get(*pos..)?.iter().position(|&c| c == 0)?;
        let s = String::from_utf8_lossy(&b[*pos..end]).into_owned();
        *pos = end + 1;
        Some(s)
    };
    while let Some(name) = cstr(&mut pos) {
        if name.is_empty() {
            break;
        }
        let Some(_ty) = cstr(&mut pos) else { break };
        let Some(size) = b.get(pos..pos + 4) else {
            break;
        };
        let size = u32::from_le_bytes([size[0], size[1], size[2], size[3]]) as usize;
        let value = pos + 4..(pos + 4 + size).min(b.len());
        out.push(ExrAttribute {
            name,
            size_at: pos,
            value: value.clone(),
        });
        pos = value.end;
    }
    (out, pos)
}

/// Damages an EXR header where readers trust it: an attribute's size, a
/// 32-bit field of its value (window corners, channel types and
/// samplings, chunk counts), the compression byte, or an offset-table
/// entry, each set to an extreme or random value.
fn damage_exr_header(src: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut v = src.to_vec();
    let (attrs, end) = exr_attributes(&v);
    let put = |v: &mut Vec<u8>, at: usize, x: u32| {
        for (k, byte) in x.to_le_bytes().iter().enumerate() {
            if let Some(slot) = v.get_mut(at + k) {
                *slot = *byte;
            }
        }
    };
    let extreme = |rng: &mut Rng| match rng.uniform_bounded(3) {
        0 => rng.uniform_u32(),
        _ => EXTREMES[rng.uniform_bounded(EXTREMES.len() as u32) as usize],
    };
    let n = 1 + rng.uniform_bounded(3);
    for _ in 0..n {
        if attrs.is_empty() || rng.uniform_bounded(5) == 0 {
            // An offset-table entry (8 bytes each after the header).
            let entries = (v.len().saturating_sub(end) / 8).max(1) as u32;
            let at = end + 8 * rng.uniform_bounded(entries.min(64)) as usize;
            let x = extreme(rng);
            put(&mut v, at + 4 * rng.uniform_bounded(2) as usize, x);
            continue;
        }
        let a = &attrs[rng.uniform_bounded(attrs.len() as u32) as usize];
        match rng.uniform_bounded(4) {
            0 => {
                let x = extreme(rng);
                put(&mut v, a.size_at, x);
            }
            1 if a.name == "compression" && !a.value.is_empty() => {
                v[a.value.start] = rng.uniform_bounded(12) as u8;
            }
            _ if a.value.len() >= 4 => {
                let slots = (a.value.len() / 4) as u32;
                let at = a.value.start + 4 * rng.uniform_bounded(slots) as usize;
                let x = extreme(rng);
                put(&mut v, at, x);
            }
            _ => {
                if let Some(b) = v.get_mut(a.value.start) {
                    *b = rng.uniform_u32() as u8;
                }
            }
        }
    }
    v
}

/// Hands mutated bytes to the reader for `ext`, against a memory budget
/// of `budget` bytes; the result is ignored, only panics matter.
fn read(ext: &str, bytes: &[u8], scratch: &Path, budget: u64) {
    let budget = MemoryBudget::new(budget);
    match ext {
        "ply" => {
            let _ = parse_ply_within(bytes, &budget);
        }
        "nvdb" => {
            let _ = read_float_grid_from_bytes(bytes, "density");
        }
        "spd" => {
            if std::fs::write(scratch, bytes).is_ok() {
                let _ = read_spectrum_file(scratch);
            }
        }
        _ => {
            let _ = Image::read_from_bytes_within(bytes, &format!("x.{ext}"), None, &budget);
        }
    }
}

const EXTENSIONS: [&str; 9] = [
    "ply", "nvdb", "exr", "png", "pfm", "hdr", "tga", "qoi", "spd",
];

/// Small files of every kind, written by rpbrt's own writers.
fn builtin_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut im = Image::new(
        PixelFormat::Float,
        Point2i::new(5, 3),
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    for y in 0..3 {
        for x in 0..5 {
            im.set_channels(Point2i::new(x, y), &[x as f32, y as f32, 0.5]);
        }
    }
    for ext in ["exr", "png", "pfm", "qoi"] {
        let p = dir.join(format!("builtin.{ext}"));
        if im.write(&p, &ImageMetadata::default()).is_ok() {
            out.push(p);
        }
    }
    let ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut bytes = ply.to_vec();
    for v in [
        [0.0f32, 0.0, 0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0, 0.0, 1.0],
    ] {
        for c in v {
            bytes.extend(c.to_le_bytes());
        }
    }
    bytes.push(3);
    for i in [0i32, 1, 2] {
        bytes.extend(i.to_le_bytes());
    }
    let p = dir.join("builtin.ply");
    if std::fs::write(&p, bytes).is_ok() {
        out.push(p);
    }
    let p = dir.join("builtin.spd");
    if std::fs::write(&p, "400 0.5\n500 0.7\n600 0.2\n").is_ok() {
        out.push(p);
    }
    out
}

/// The memory budget the built-in and shared files are read with.
const BUDGET: u64 = 256 << 20;

/// The budget the resource-claim files are read with: far below what they
/// claim.
const CLAIM_BUDGET: u64 = 4 << 20;

/// A PNG chunk: length, type, data and CRC.
fn png_chunk(out: &mut Vec<u8>, ty: &[u8; 4], data: &[u8]) {
    out.extend((data.len() as u32).to_be_bytes());
    let mut crc = flate2::Crc::new();
    crc.update(ty);
    crc.update(data);
    out.extend(ty);
    out.extend(data);
    out.extend(crc.sum().to_be_bytes());
}

/// Files whose valid headers claim far more memory than [`CLAIM_BUDGET`],
/// in few bytes: a 4000² grey PNG and a 2048² EXR of zeros, a 4000² QOI of
/// one colour, and a gzip PLY whose 40000 faces of 255 vertices become ten
/// million triangles (its header's counts fit the budget; its triangles do
/// not).
fn claim_files() -> Vec<(String, Vec<u8>)> {
    use std::io::Write;
    let mut out = Vec::new();
    // PNG: 4000 x 4000, 8-bit grey, every row filter 0 and zeros.
    let n = 4000u32;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let row = vec![0u8; n as usize + 1];
    for _ in 0..n {
        z.write_all(&row).expect("in memory");
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend(n.to_be_bytes());
    ihdr.extend(n.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    png_chunk(&mut png, b"IHDR", &ihdr);
    png_chunk(&mut png, b"IDAT", &z.finish().expect("in memory"));
    png_chunk(&mut png, b"IEND", &[]);
    out.push(("png".to_string(), png));
    // EXR: 2048 x 2048 half zeros, compressed by rpbrt's writer.
    let im = Image::new(
        PixelFormat::Half,
        Point2i::new(2048, 2048),
        &["Y"],
        ColorEncoding::Linear,
    );
    if let Ok(b) = im.encode("claim.exr", &ImageMetadata::default()) {
        out.push(("exr".to_string(), b));
    }
    // QOI: 4000 x 4000 RGB, runs of 62 pixels of the start colour.
    let mut qoi = b"qoif".to_vec();
    qoi.extend(n.to_be_bytes());
    qoi.extend(n.to_be_bytes());
    qoi.extend([3, 0]);
    let pixels = (n * n) as usize;
    qoi.resize(qoi.len() + pixels / 62, 0xc0 | 61);
    qoi.resize(qoi.len() + pixels % 62, 0xc0);
    qoi.extend([0, 0, 0, 0, 0, 0, 0, 1]);
    out.push(("qoi".to_string(), qoi));
    // PLY: 256 vertices, 40000 faces of 255 vertices each, gzip.
    let faces = 40_000;
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 256\n\
         property float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    for i in 0..256u32 {
        for c in [i as f32, (i * 7 % 13) as f32, 0.0] {
            ply.extend(c.to_le_bytes());
        }
    }
    let mut face = vec![255u8];
    for i in 0..255i32 {
        face.extend(i.to_le_bytes());
    }
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&ply).expect("in memory");
    for _ in 0..faces {
        gz.write_all(&face).expect("in memory");
    }
    out.push(("ply".to_string(), gz.finish().expect("in memory")));
    out
}

fn shared_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let mut out = Vec::new();
    let mut stack = vec![root];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| EXTENSIONS.contains(&e))
                && std::fs::metadata(&p).is_ok_and(|m| m.len() <= 8 << 20)
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn mutated_data_files_never_panic() {
    let dir = std::env::temp_dir().join(format!("rpbrt-data-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let scratch = dir.join("mutated.spd");
    let mut files = builtin_files(&dir);
    files.extend(shared_files());
    let mut loaded: Vec<(String, Vec<u8>, u64)> = files
        .iter()
        .filter_map(|p| {
            let ext = p.extension()?.to_str()?.to_string();
            Some((ext, std::fs::read(p).ok()?, BUDGET))
        })
        .collect();
    assert!(loaded.len() >= 6, "the built-in files were not written");
    let claims = claim_files();
    assert_eq!(claims.len(), 4, "the resource-claim files were not made");
    // Unmutated, each claim is refused by the budget, not decoded.
    for (ext, bytes) in &claims {
        let budget = MemoryBudget::new(CLAIM_BUDGET);
        let refused = if ext == "ply" {
            parse_ply_within(bytes, &budget).is_err()
        } else {
            Image::read_from_bytes_within(bytes, &format!("x.{ext}"), None, &budget).is_err()
        };
        assert!(refused && budget.exhausted(), "{ext} claim was not refused");
    }
    loaded.extend(claims.into_iter().map(|(e, b)| (e, b, CLAIM_BUDGET)));
    let iters: u32 = std::env::var("RPBRT_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    let budget = std::env::var("RPBRT_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .map(Duration::from_secs);
    let start = Instant::now();
    // Rounds of fresh seeds start here: runs in chunks continue where the
    // last one stopped.
    let first_round: u64 = std::env::var("RPBRT_FUZZ_FIRST_ROUND")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let mut round = first_round;
    let mut total = 0u64;
    loop {
        for (k, (ext, bytes, budget)) in loaded.iter().enumerate() {
            let mut rng = Rng::new(0xda7a + k as u64, round);
            for i in 0..iters {
                // EXR files: every other mutation aims at the header's
                // attributes and offset table.
                let m = if ext == "exr" && i % 2 == 1 {
                    damage_exr_header(bytes, &mut rng)
                } else {
                    mutate(bytes, &mut rng)
                };
                read(ext, &m, &scratch, *budget);
                total += 1;
            }
        }
        round += 1;
        match budget {
            Some(b) if start.elapsed() < b => continue,
            _ => break,
        }
    }
    if budget.is_some() {
        println!(
            "data fuzz: {total} mutated files over {} inputs in {:.0} s (rounds {first_round} to {})",
            loaded.len(),
            start.elapsed().as_secs_f64(),
            round - 1
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
