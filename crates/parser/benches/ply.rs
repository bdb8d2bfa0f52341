//! PLY reading throughput: `cargo bench -p rpbrt-parser --bench ply`.
//!
//! Generates a binary little-endian grid mesh of about a million triangles in
//! memory (position + normal + uv, the layout exporters write), plus a
//! positions-only variant and a gzip-compressed copy, and times `parse_ply` on
//! each. Also times the water-caustic scene's PLY files when `../shared` is
//! present. Prints a `RESULT` line for the main case.

use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use rpbrt_parser::ply::{encode_ply, parse_ply, PlyMesh};

/// A `n` x `n` vertex grid on a gently curved surface: 2 (n-1)^2 triangles.
fn grid(n: u32, normals: bool, uvs: bool) -> PlyMesh {
    let mut mesh = PlyMesh::default();
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            mesh.positions
                .push([u * 10.0, v * 10.0, (u * 6.0).sin() * (v * 4.0).cos()]);
            if normals {
                mesh.normals.push([0.0, 0.0, 1.0]);
            }
            if uvs {
                mesh.uvs.push([u, v]);
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            mesh.tri_indices
                .extend_from_slice(&[a, a + 1, a + n + 1, a, a + n + 1, a + n]);
        }
    }
    mesh
}

/// Best wall time of `parse_ply(bytes)` over several runs (at least 5, and
/// at least about a second in all).
fn time_parse(bytes: &[u8]) -> (Duration, PlyMesh) {
    let mut best = Duration::MAX;
    let mut mesh = PlyMesh::default();
    let start = Instant::now();
    let mut runs = 0;
    while runs < 5 || (start.elapsed() < Duration::from_secs(1) && runs < 200) {
        let t = Instant::now();
        match parse_ply(black_box(bytes)) {
            Ok(m) => mesh = m,
            Err(e) => {
                eprintln!("benchmark input failed to parse: {e}");
                std::process::exit(1);
            }
        }
        best = best.min(t.elapsed());
        runs += 1;
    }
    (best, black_box(mesh))
}

fn report(label: &str, bytes: usize, t: Duration, mesh: &PlyMesh) -> (f64, f64) {
    let s = t.as_secs_f64();
    let mb_s = bytes as f64 / 1e6 / s;
    let prims = (mesh.triangle_count() + 2 * mesh.quad_count()) as f64;
    let mtris_s = prims / 1e6 / s;
    println!(
        "{label:<34} {:>8.2} MB  {:>8.2} ms  {mb_s:>8.1} MB/s  {mtris_s:>7.2} Mtris/s",
        bytes as f64 / 1e6,
        s * 1e3
    );
    (mb_s, mtris_s)
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    if let Err(e) = enc.write_all(bytes) {
        eprintln!("gzip failed: {e}");
        std::process::exit(1);
    }
    enc.finish().unwrap_or_else(|e| {
        eprintln!("gzip failed: {e}");
        std::process::exit(1)
    })
}

fn encode(mesh: &PlyMesh) -> Vec<u8> {
    encode_ply(mesh).unwrap_or_else(|e| {
        eprintln!("encoding failed: {e}");
        std::process::exit(1)
    })
}

/// The same mesh as an `ascii` PLY file (the general, token-by-token path).
fn encode_ascii(mesh: &PlyMesh) -> Vec<u8> {
    use std::fmt::Write as _;
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangle_count()
    );
    for p in &mesh.positions {
        let _ = writeln!(s, "{} {} {}", p[0], p[1], p[2]);
    }
    for t in mesh.tri_indices.chunks_exact(3) {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s.into_bytes()
}

fn main() {
    let full = grid(709, true, true);
    let full_bytes = encode(&full);
    let (t, mesh) = time_parse(&full_bytes);
    assert_eq!(mesh, full);
    let (mb_s, mtris_s) = report("binary LE xyz+n+uv", full_bytes.len(), t, &mesh);

    let plain = grid(709, false, false);
    let plain_bytes = encode(&plain);
    let (t, mesh) = time_parse(&plain_bytes);
    assert_eq!(mesh, plain);
    report("binary LE xyz", plain_bytes.len(), t, &mesh);

    let ascii = encode_ascii(&plain);
    let (t, mesh) = time_parse(&ascii);
    assert_eq!(mesh, plain);
    report("ascii xyz", ascii.len(), t, &mesh);

    let gz = gzip(&full_bytes);
    let (t, mesh) = time_parse(&gz);
    assert_eq!(mesh, full);
    report("gzip binary LE xyz+n+uv (gz bytes)", gz.len(), t, &mesh);
    report("  (uncompressed bytes)", full_bytes.len(), t, &mesh);

    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    for name in ["Mesh000.ply", "Mesh001.ply"] {
        let path = shared.join("water-caustic/models").join(name);
        if let Ok(bytes) = std::fs::read(&path) {
            let (t, mesh) = time_parse(&bytes);
            report(&format!("water-caustic/{name}"), bytes.len(), t, &mesh);
        }
    }

    println!("RESULT ply_binary_mb_s={mb_s:.1} ply_mtris_s={mtris_s:.2}");
}
