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
//! clone too. `RPBRT_FUZZ_ITERS` sets the mutations per file (default 60);
//! `RPBRT_FUZZ_SECONDS`, if set, keeps going over fresh seeds until that
//! much time has passed and prints the count.

use rpbrt_geometry::Point2i;
use rpbrt_parser::ply::parse_ply;
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

/// Hands mutated bytes to the reader for `ext`; the result is ignored,
/// only panics matter.
fn read(ext: &str, bytes: &[u8], scratch: &Path) {
    match ext {
        "ply" => {
            let _ = parse_ply(bytes);
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
            let _ = Image::read_from_bytes(bytes, &format!("x.{ext}"), None);
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
    let loaded: Vec<(String, Vec<u8>)> = files
        .iter()
        .filter_map(|p| {
            let ext = p.extension()?.to_str()?.to_string();
            Some((ext, std::fs::read(p).ok()?))
        })
        .collect();
    assert!(loaded.len() >= 6, "the built-in files were not written");
    let iters: u32 = std::env::var("RPBRT_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    let budget = std::env::var("RPBRT_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .map(Duration::from_secs);
    let start = Instant::now();
    let mut round = 0u64;
    let mut total = 0u64;
    loop {
        for (k, (ext, bytes)) in loaded.iter().enumerate() {
            let mut rng = Rng::new(0xda7a + k as u64, round);
            for _ in 0..iters {
                read(ext, &mutate(bytes, &mut rng), &scratch);
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
            "data fuzz: {total} mutated files over {} inputs in {:.0} s",
            loaded.len(),
            start.elapsed().as_secs_f64()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
