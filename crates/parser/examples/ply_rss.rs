//! Peak-memory check for the PLY reader:
//!
//! ```text
//! cargo run --release -p rpbrt-parser --example ply_rss -- write /tmp/x.ply.gz 1500
//! /usr/bin/time -v target/release/examples/ply_rss read /tmp/x.ply.gz
//! ```
//!
//! `write PATH N` writes an `N` x `N` vertex grid (positions, normals and uvs;
//! 2 (N-1)^2 triangles) with `write_ply` (gzip-compressed when `PATH` ends in
//! `.gz`); `read PATH` reads it back with `read_ply` and prints its size.

use std::path::Path;

use rpbrt_parser::ply::{read_ply, write_ply, PlyMesh};

fn grid(n: u32) -> PlyMesh {
    let mut mesh = PlyMesh::default();
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            let z = (u * 6.0).sin() * (v * 4.0).cos();
            mesh.positions.push([u * 10.0, v * 10.0, z]);
            mesh.normals.push([0.0, z.sin(), z.cos()]);
            mesh.uvs.push([u, v]);
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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let result = match args.get(1).map(String::as_str) {
        Some("write") if args.len() == 4 => match args[3].parse::<u32>() {
            Ok(n) if n >= 2 => write_ply(Path::new(&args[2]), &grid(n)).map_err(|e| e.to_string()),
            _ => Err(format!("bad grid size '{}'", args[3])),
        },
        Some("read") if args.len() == 3 => read_ply(Path::new(&args[2]))
            .map(|m| {
                println!(
                    "{} vertices, {} triangles, {} quads",
                    m.positions.len(),
                    m.triangle_count(),
                    m.quad_count()
                )
            })
            .map_err(|e| e.to_string()),
        _ => Err("usage: ply_rss write PATH N | ply_rss read PATH".to_string()),
    };
    if let Err(e) = result {
        eprintln!("{e}");
        std::process::exit(1);
    }
}
