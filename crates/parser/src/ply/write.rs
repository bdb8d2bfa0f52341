//! Writing a [`PlyMesh`] as a `binary_little_endian` PLY file (what
//! `rpbrt --toply` and pbrt-v4's `--toply` produce).

use std::io::Write;
use std::path::Path;

use super::types::{PlyError, PlyErrorKind, PlyMesh};
use crate::input::has_gz_extension;

// ---------------------------------------------------------------------------
// Writing

// `is_multiple_of` is newer than the workspace's rust-version (1.80).
#[allow(clippy::manual_is_multiple_of)]
fn check_mesh(mesh: &PlyMesh) -> Result<(), String> {
    let nv = mesh.positions.len();
    if !mesh.normals.is_empty() && mesh.normals.len() != nv {
        return Err(format!("{} normals for {nv} vertices", mesh.normals.len()));
    }
    if !mesh.uvs.is_empty() && mesh.uvs.len() != nv {
        return Err(format!("{} uvs for {nv} vertices", mesh.uvs.len()));
    }
    if mesh.tri_indices.len() % 3 != 0 {
        return Err(format!(
            "{} triangle indices is not a multiple of 3",
            mesh.tri_indices.len()
        ));
    }
    if mesh.quad_indices.len() % 4 != 0 {
        return Err(format!(
            "{} quad indices is not a multiple of 4",
            mesh.quad_indices.len()
        ));
    }
    let faces = mesh.triangle_count() + mesh.quad_count();
    if !mesh.face_indices.is_empty() && mesh.face_indices.len() != faces {
        return Err(format!(
            "{} face indices for {faces} faces",
            mesh.face_indices.len()
        ));
    }
    let bad = mesh
        .tri_indices
        .iter()
        .chain(&mesh.quad_indices)
        .find(|&&i| i as usize >= nv);
    if let Some(i) = bad {
        return Err(format!("vertex index {i} out of range [0, {nv})"));
    }
    Ok(())
}

/// Encodes `mesh` as a `binary_little_endian` PLY file in memory: the bytes
/// [`write_ply`] writes (before any compression).
///
/// Quads are written in PLY polygon order (undoing the bilinear-patch order
/// of [`PlyMesh::quad_indices`]), so [`parse_ply`](super::parse_ply) reads back an identical mesh.
pub fn encode_ply(mesh: &PlyMesh) -> Result<Vec<u8>, PlyError> {
    check_mesh(mesh).map_err(|m| PlyError::new(None, PlyErrorKind::InvalidMesh(m)))?;
    let nv = mesh.positions.len();
    let (nt, nq) = (mesh.triangle_count(), mesh.quad_count());
    let has_n = !mesh.normals.is_empty();
    let has_uv = !mesh.uvs.is_empty();
    let has_fi = !mesh.face_indices.is_empty();
    let index_type = if nv <= i32::MAX as usize {
        "int"
    } else {
        "uint"
    };

    let mut header =
        String::from("ply\nformat binary_little_endian 1.0\ncomment written by rpbrt\n");
    header +=
        &format!("element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n");
    if has_n {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if has_uv {
        header += "property float u\nproperty float v\n";
    }
    header += &format!(
        "element face {}\nproperty list uchar {index_type} vertex_indices\n",
        nt + nq
    );
    if has_fi {
        header += "property int face_indices\n";
    }
    header += "end_header\n";

    let stride = 12 + if has_n { 12 } else { 0 } + if has_uv { 8 } else { 0 };
    let fi = if has_fi { 4 } else { 0 };
    let mut out = Vec::with_capacity(header.len() + nv * stride + nt * (13 + fi) + nq * (17 + fi));
    out.extend_from_slice(header.as_bytes());
    for i in 0..nv {
        for c in mesh.positions[i] {
            out.extend_from_slice(&c.to_le_bytes());
        }
        if has_n {
            for c in mesh.normals[i] {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        if has_uv {
            for c in mesh.uvs[i] {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    let mut face = 0;
    for t in mesh.tri_indices.chunks_exact(3) {
        out.push(3);
        for &i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
        if has_fi {
            out.extend_from_slice(&mesh.face_indices[face].to_le_bytes());
        }
        face += 1;
    }
    for q in mesh.quad_indices.chunks_exact(4) {
        out.push(4);
        for i in [q[0], q[1], q[3], q[2]] {
            out.extend_from_slice(&i.to_le_bytes());
        }
        if has_fi {
            out.extend_from_slice(&mesh.face_indices[face].to_le_bytes());
        }
        face += 1;
    }
    Ok(out)
}

/// Writes `mesh` as a `binary_little_endian` PLY file (gzip-compressed when
/// `path` ends in `.gz`) that [`read_ply`](super::read_ply) reads back identically.
pub fn write_ply(path: &Path, mesh: &PlyMesh) -> Result<(), PlyError> {
    let err = |kind| PlyError::new(Some(path), kind);
    let bytes = encode_ply(mesh).map_err(|e| err(e.kind))?;
    let bytes = if has_gz_extension(path) {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(&bytes)
            .and_then(|()| enc.finish())
            .map_err(|e| err(PlyErrorKind::Io(e)))?
    } else {
        bytes
    };
    std::fs::write(path, bytes).map_err(|e| err(PlyErrorKind::Io(e)))
}
