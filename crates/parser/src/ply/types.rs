//! The PLY reader's and writer's data types: the mesh ([`PlyMesh`]) and the
//! errors ([`PlyError`], [`PlyErrorKind`]). Re-exported from the `ply`
//! module; kept in a file of their own so that every part of the reader and
//! writer can use them without importing the module's entry points.

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

/// A polygon mesh as read from (or written to) a PLY file.
///
/// Per-vertex arrays are either empty or exactly as long as `positions`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyMesh {
    /// Vertex positions (`x`, `y`, `z`).
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex normals (`nx`, `ny`, `nz`); empty when the file has none.
    pub normals: Vec<[f32; 3]>,
    /// Per-vertex texture coordinates (`u`/`v`, `s`/`t`, `texture_u`/`texture_v`
    /// or `texture_s`/`texture_t`); empty when the file has none.
    pub uvs: Vec<[f32; 2]>,
    /// Triangle vertex indices, three per triangle. Faces with more than four
    /// vertices are triangulated as fans and end up here too.
    pub tri_indices: Vec<u32>,
    /// Quad vertex indices, four per quad, in pbrt-v4's bilinear-patch order:
    /// a PLY face `v0 v1 v2 v3` is stored as `v0 v1 v3 v2`.
    pub quad_indices: Vec<u32>,
    /// Per-primitive face indices (the `face_indices` property), empty when the
    /// file has none. When present it holds one entry per triangle followed by
    /// one entry per quad, i.e. `tri_indices.len() / 3 + quad_indices.len() / 4`
    /// entries; a fan-triangulated polygon repeats its index for each triangle.
    pub face_indices: Vec<i32>,
    /// Non-fatal problems found while reading (fan-triangulated or ignored faces,
    /// non-finite coordinates, trailing data). Not written by [`write_ply`](super::write_ply).
    pub warnings: Vec<String>,
}

impl PlyMesh {
    /// Number of triangles in `tri_indices`.
    pub fn triangle_count(&self) -> usize {
        self.tri_indices.len() / 3
    }

    /// Number of quads in `quad_indices`.
    pub fn quad_count(&self) -> usize {
        self.quad_indices.len() / 4
    }
}

/// An error reading or writing a PLY file, with the file it concerns.
#[derive(Debug)]
pub struct PlyError {
    /// The file, or `None` for [`parse_ply`](super::parse_ply) / [`encode_ply`](super::encode_ply) on memory.
    pub path: Option<PathBuf>,
    /// What went wrong.
    pub kind: PlyErrorKind,
}

/// What went wrong while reading or writing a PLY file.
#[derive(Debug)]
#[non_exhaustive]
pub enum PlyErrorKind {
    /// The file could not be opened, read or written.
    Io(io::Error),
    /// The file looked gzip-compressed but could not be decompressed.
    Gzip(io::Error),
    /// The file does not start with the `ply` magic line.
    BadMagic,
    /// The header is malformed.
    Header {
        /// 1-based header line.
        line: usize,
        /// What is wrong with it.
        message: String,
    },
    /// A required element (`vertex` or `face`) is not declared.
    MissingElement(&'static str),
    /// A required property (`x`, `y`, `z`, `vertex_indices`) is not declared.
    MissingProperty {
        /// The element that lacks it.
        element: &'static str,
        /// The missing property.
        property: &'static str,
    },
    /// A property the reader needs is declared with an unusable type.
    UnsupportedProperty {
        /// The element that declares it.
        element: String,
        /// The property.
        property: String,
        /// Why it cannot be used.
        reason: &'static str,
    },
    /// The body ends before all records the header declares.
    Truncated {
        /// The element being read.
        element: String,
        /// Records the header declares.
        expected: u64,
        /// Complete records present before the data ran out.
        read: u64,
    },
    /// A value in the body cannot be decoded (bad ASCII number, negative list
    /// count, non-integral index...).
    BadValue {
        /// The element being read.
        element: String,
        /// 0-based record within the element.
        record: u64,
        /// What is wrong.
        message: String,
    },
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange {
        /// 0-based face record.
        face: u64,
        /// The offending index.
        index: i64,
        /// Number of vertices in the file.
        vertex_count: u64,
    },
    /// The mesh given to the writer is inconsistent.
    InvalidMesh(String),
    /// The mesh needs more memory than the budget has left (see
    /// [`MemoryBudget`](crate::budget::MemoryBudget)).
    OverBudget(crate::budget::OverBudget),
}

impl PlyError {
    pub(super) fn new(path: Option<&Path>, kind: PlyErrorKind) -> PlyError {
        PlyError {
            path: path.map(Path::to_path_buf),
            kind,
        }
    }
}

fn element_noun(element: &str, n: u64) -> String {
    match (element, n == 1) {
        ("vertex", true) => "vertex".to_string(),
        ("vertex", false) => "vertices".to_string(),
        ("face", true) => "face".to_string(),
        ("face", false) => "faces".to_string(),
        (name, _) => format!("'{name}' records"),
    }
}

impl fmt::Display for PlyErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlyErrorKind::Io(e) => write!(f, "{e}"),
            PlyErrorKind::Gzip(e) => write!(f, "gzip decompression failed: {e}"),
            PlyErrorKind::BadMagic => write!(f, "not a PLY file (missing 'ply' magic line)"),
            PlyErrorKind::Header { line, message } => {
                write!(f, "malformed PLY header, line {line}: {message}")
            }
            PlyErrorKind::MissingElement(e) => write!(f, "no '{e}' element declared"),
            PlyErrorKind::MissingProperty { element, property } => {
                write!(f, "element '{element}' has no '{property}' property")
            }
            PlyErrorKind::UnsupportedProperty {
                element,
                property,
                reason,
            } => write!(f, "property '{property}' of element '{element}' {reason}"),
            PlyErrorKind::Truncated {
                element,
                expected,
                read,
            } => write!(
                f,
                "truncated data: expected {expected} {}, file ends after {read}",
                element_noun(element, *expected)
            ),
            PlyErrorKind::BadValue {
                element,
                record,
                message,
            } => write!(f, "element '{element}' record {record}: {message}"),
            PlyErrorKind::IndexOutOfRange {
                face,
                index,
                vertex_count,
            } => write!(
                f,
                "face {face}: vertex index {index} is out of range [0, {vertex_count})"
            ),
            PlyErrorKind::InvalidMesh(m) => write!(f, "invalid mesh: {m}"),
            PlyErrorKind::OverBudget(e) => write!(f, "{e}"),
        }
    }
}

impl fmt::Display for PlyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(p) => write!(f, "{}: {}", p.display(), self.kind),
            None => write!(f, "<memory>: {}", self.kind),
        }
    }
}

impl std::error::Error for PlyError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            PlyErrorKind::Io(e) | PlyErrorKind::Gzip(e) => Some(e),
            _ => None,
        }
    }
}
