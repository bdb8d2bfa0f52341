//! Reading and writing PLY polygon meshes, the files behind pbrt-v4's `plymesh`
//! shape (Physically Based Rendering, 4th ed., Section 6.5 "Triangle Meshes"
//! and the bilinear patches of Section 6.6).
//!
//! The reader accepts `ascii 1.0`, `binary_little_endian 1.0` and
//! `binary_big_endian 1.0` bodies, optionally gzip-compressed. Binary files with
//! the layouts that exporters (and `rpbrt --toply`) actually write take a fast
//! path that decodes fixed-size records straight from the read buffer;
//! anything else goes through a general property-by-property decoder. Files
//! are decoded as they are read (and inflated), never held whole in memory.
//!
//! Robustness: no count read from the file drives an allocation before the
//! data it describes has been seen (or, when the size of the data is known,
//! checked to fit in it), so a corrupt header cannot make the reader reserve
//! gigabytes, and no input makes it panic.
//!
//! The module is split by stage: the mesh and error types in `types.rs`,
//! header parsing in `header.rs`, the windowed byte stream and value sources
//! in `stream.rs`, body decoding in `read.rs`, writing in `write.rs`; the
//! reading entry points are here. No file imports one above it, so the
//! files' import graph has no cycle.

use std::path::Path;

use crate::budget::MemoryBudget;
use crate::input::{has_gz_extension, FileReader};

mod header;
mod read;
mod stream;
mod types;
mod write;

pub use types::{PlyError, PlyErrorKind, PlyMesh};
pub use write::{encode_ply, write_ply};

/// Parses a PLY file held in memory; gzip-compressed data (recognised by its
/// magic bytes) is inflated as it is decoded. The mesh is held against the
/// default memory budget ([`MemoryBudget::default`]).
pub fn parse_ply(bytes: &[u8]) -> Result<PlyMesh, PlyError> {
    parse_ply_within(bytes, &MemoryBudget::default())
}

/// [`parse_ply`], with the mesh's arrays charged to `budget`.
pub fn parse_ply_within(bytes: &[u8], budget: &MemoryBudget) -> Result<PlyMesh, PlyError> {
    let mesh = if crate::input::is_gzip(bytes) {
        read::parse_gzip(bytes, budget)
    } else {
        read::parse_reader(bytes, Some(bytes.len() as u64), true, budget)
    };
    mesh.map_err(|kind| PlyError::new(None, kind))
}

/// Reads a PLY file; files named `*.gz` or starting with the gzip magic bytes
/// are decompressed transparently.
///
/// The body is decoded as it is read (and inflated), so memory use is the
/// mesh's arrays plus a small window of the file, never the whole file.
/// The mesh is held against the default memory budget
/// ([`MemoryBudget::default`]).
pub fn read_ply(path: &Path) -> Result<PlyMesh, PlyError> {
    read_ply_within(path, &MemoryBudget::default())
}

/// [`read_ply`], with the mesh's arrays charged to `budget`: a header whose
/// counts need more than the budget has left, or a body that inflates past
/// it, is a [`PlyErrorKind::OverBudget`] error.
pub fn read_ply_within(path: &Path, budget: &MemoryBudget) -> Result<PlyMesh, PlyError> {
    let err = |kind| PlyError::new(Some(path), kind);
    let reader = if has_gz_extension(path) {
        FileReader::open_gzip(path)
    } else {
        FileReader::open(path)
    };
    read::parse_file(reader.map_err(|e| err(PlyErrorKind::Io(e)))?, budget).map_err(err)
}

#[cfg(test)]
mod tests;
