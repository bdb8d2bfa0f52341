//! Reading NanoVDB (`.nvdb`) files: the float grids behind pbrt-v4's `nanovdb` medium
//! (`NanoVDBMedium` in pbrt-v4 `media.h`, which reads a required "density" grid and an
//! optional "temperature" grid from one file).
//!
//! This is our own reader of the on-disk layout; no NanoVDB or OpenVDB library is used.
//!
//! # The file
//!
//! A file is a sequence of *segments* (`io::Segment` in NanoVDB's `IO.h`): a 16-byte header
//! (magic `"NanoVDB0"`, or `"NanoVDB2"` from NanoVDB 32.6 on; the version; the grid count; the
//! codec), then for every grid a 176-byte metadata record followed by the grid's name, then
//! the grids' buffers one after another. NanoVDB 32.6 and later may also write a file that is
//! just raw grid buffers back to back (each starting with the grid magic `"NanoVDB1"`); those
//! are read too. Buffers are stored as is (codec NONE) or ZIP (zlib) compressed, both
//! supported; BLOSC-compressed grids give [`NanoVdbError::UnsupportedCodec`].
//!
//! # The grid
//!
//! A grid buffer is the in-memory NanoVDB grid: `GridData` (672 bytes: name, the index/world
//! map, world bounding box, class, value type), `TreeData` (64 bytes), the root node with its
//! table of tiles, and the upper (32³ children), lower (16³) and leaf (8³)
//! nodes, all addressed by byte offsets relative to their parent. Only grids of value type
//! `float` are accepted; quantised (Fp4/Fp8/Fp16/FpN), half, double and other grids give
//! [`NanoVdbError::NotFloatGrid`].
//!
//! Supported versions: major version 32 (NanoVDB 32.x, OpenVDB 8.1 to 12), whose major number
//! NanoVDB itself bumps on any change of the binary layout. The layouts used here (file and
//! grid headers, root/internal/leaf nodes of float grids) are identical across 32.3 to 32.8.
//!
//! # Loading
//!
//! [`read_float_grid`] reads the file's headers, then only the wanted grid's bytes, and decodes
//! the tree once into flat arrays ([`FloatGrid`]): every child offset is checked to lie inside
//! the grid buffer, aligned, and not to overlap another node of its level, so a corrupt or
//! truncated file gives an error rather than a panic or an outsized allocation, and lookups
//! afterwards need no checks beyond Rust's own. Reading the density and the temperature grid
//! of one file is two calls; each reads just the headers and its own grid.

mod file;
mod tree;

#[cfg(test)]
mod tests;

use std::fmt;
use std::path::Path;

pub use tree::{FloatGrid, GridClass};

/// The largest file accepted (8 GiB); anything longer is refused before reading.
pub const MAX_FILE_BYTES: u64 = 8 << 30;

/// What went wrong reading a .nvdb file. The message ([`fmt::Display`]) is one line without
/// the file name; the caller adds the location.
#[derive(Debug)]
pub enum NanoVdbError {
    /// The file could not be opened or read.
    Io(std::io::Error),
    /// The file is longer than [`MAX_FILE_BYTES`].
    TooLarge {
        /// The file's length in bytes.
        len: u64,
    },
    /// The file does not start with a NanoVDB magic number.
    NotNanoVdb,
    /// The file ends inside a header or a grid.
    Truncated {
        /// The part that is cut off (e.g. "grid metadata").
        what: &'static str,
        /// Byte offset of that part in the file.
        offset: u64,
        /// Bytes the part needs.
        needed: u64,
        /// Bytes left in the file from `offset` on.
        available: u64,
    },
    /// A major version other than 32 (the layout this reader knows).
    UnsupportedVersion {
        /// Major version number.
        major: u32,
        /// Minor version number.
        minor: u32,
        /// Patch version number.
        patch: u32,
    },
    /// The grid is stored with a compression codec this reader does not implement.
    UnsupportedCodec {
        /// The codec's name ("BLOSC", or "codec N" for an unknown number).
        codec: String,
    },
    /// The grid holds values of another type than 32-bit float.
    NotFloatGrid {
        /// The grid's name.
        name: String,
        /// NanoVDB's name of the value type found (e.g. "Float16", "double").
        found_type: String,
    },
    /// No grid of the requested name (returned by [`require_float_grid`]; [`read_float_grid`]
    /// gives `Ok(None)` instead).
    GridNotFound {
        /// The requested name.
        name: String,
        /// The names of the grids the file has.
        available: Vec<String>,
    },
    /// Inconsistent content: offsets out of range, sizes that disagree, bad grid magic, ...
    Corrupt(String),
}

impl fmt::Display for NanoVdbError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NanoVdbError::Io(e) => write!(f, "cannot read the NanoVDB file: {e}"),
            NanoVdbError::TooLarge { len } => write!(
                f,
                "NanoVDB file of {len} bytes is larger than the {MAX_FILE_BYTES}-byte limit"
            ),
            NanoVdbError::NotNanoVdb => {
                write!(
                    f,
                    "not a NanoVDB file (no \"NanoVDB\" magic number at its start)"
                )
            }
            NanoVdbError::Truncated {
                what,
                offset,
                needed,
                available,
            } => write!(
                f,
                "truncated NanoVDB file: the {what} at byte {offset} needs {needed} bytes, \
                 only {available} remain"
            ),
            NanoVdbError::UnsupportedVersion {
                major,
                minor,
                patch,
            } => write!(
                f,
                "NanoVDB version {major}.{minor}.{patch} is not supported (only major version 32)"
            ),
            NanoVdbError::UnsupportedCodec { codec } => write!(
                f,
                "the grid is {codec}-compressed, which is not supported; \
                 rewrite the file uncompressed or with ZIP (e.g. vdb_tool ... -write codec=none)"
            ),
            NanoVdbError::NotFloatGrid { name, found_type } => write!(
                f,
                "grid \"{name}\" holds {found_type} values; only 32-bit float grids are supported"
            ),
            NanoVdbError::GridNotFound { name, available } => {
                write!(f, "no grid named \"{name}\"; the file has ")?;
                if available.is_empty() {
                    write!(f, "no grids")
                } else {
                    let list: Vec<String> = available.iter().map(|n| format!("\"{n}\"")).collect();
                    write!(f, "{}", list.join(", "))
                }
            }
            NanoVdbError::Corrupt(msg) => write!(f, "corrupt NanoVDB file: {msg}"),
        }
    }
}

impl std::error::Error for NanoVdbError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            NanoVdbError::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for NanoVdbError {
    fn from(e: std::io::Error) -> Self {
        NanoVdbError::Io(e)
    }
}

/// Reads the float grid called `name` from a .nvdb file. `Ok(None)` when the file is a valid
/// NanoVDB file without a grid of that name ([`grid_names`] lists the names; use
/// [`require_float_grid`] for an error that lists them). With several grids of one name, the
/// first is read (as NanoVDB's `readGrid` does).
pub fn read_float_grid(path: &Path, name: &str) -> Result<Option<FloatGrid>, NanoVdbError> {
    let mut src = file::FileSource::open(path)?;
    read_from(&mut src, name)
}

/// Like [`read_float_grid`], but a missing grid is [`NanoVdbError::GridNotFound`], whose
/// message lists the grids the file has.
pub fn require_float_grid(path: &Path, name: &str) -> Result<FloatGrid, NanoVdbError> {
    let mut src = file::FileSource::open(path)?;
    require_from(&mut src, name)
}

/// The uncompressed size the file records for the grid called `name` (the
/// first of that name), in bytes; `Ok(None)` when there is none. Read from
/// the file's headers alone, so that the grid can be held against a memory
/// budget before it is inflated.
pub fn grid_bytes(path: &Path, name: &str) -> Result<Option<u64>, NanoVdbError> {
    let mut src = file::FileSource::open(path)?;
    let entries = file::scan(&mut src)?;
    Ok(entries.iter().find(|e| e.name == name).map(|e| e.grid_size))
}

/// The names of all grids in a .nvdb file (of any value type), in file order.
pub fn grid_names(path: &Path) -> Result<Vec<String>, NanoVdbError> {
    let mut src = file::FileSource::open(path)?;
    Ok(file::scan(&mut src)?.into_iter().map(|e| e.name).collect())
}

/// [`read_float_grid`] on the bytes of a .nvdb file held in memory.
pub fn read_float_grid_from_bytes(
    bytes: &[u8],
    name: &str,
) -> Result<Option<FloatGrid>, NanoVdbError> {
    let mut src = file::SliceSource(bytes);
    read_from(&mut src, name)
}

/// [`require_float_grid`] on the bytes of a .nvdb file held in memory.
pub fn require_float_grid_from_bytes(bytes: &[u8], name: &str) -> Result<FloatGrid, NanoVdbError> {
    let mut src = file::SliceSource(bytes);
    require_from(&mut src, name)
}

/// [`grid_names`] on the bytes of a .nvdb file held in memory.
pub fn grid_names_from_bytes(bytes: &[u8]) -> Result<Vec<String>, NanoVdbError> {
    let mut src = file::SliceSource(bytes);
    Ok(file::scan(&mut src)?.into_iter().map(|e| e.name).collect())
}

fn read_from<S: file::Source>(src: &mut S, name: &str) -> Result<Option<FloatGrid>, NanoVdbError> {
    let entries = file::scan(src)?;
    let Some(entry) = entries.iter().find(|e| e.name == name) else {
        return Ok(None);
    };
    load_entry(src, entry).map(Some)
}

fn require_from<S: file::Source>(src: &mut S, name: &str) -> Result<FloatGrid, NanoVdbError> {
    let entries = file::scan(src)?;
    match entries.iter().find(|e| e.name == name) {
        Some(entry) => load_entry(src, entry),
        None => Err(NanoVdbError::GridNotFound {
            name: name.to_string(),
            available: entries.into_iter().map(|e| e.name).collect(),
        }),
    }
}

fn load_entry<S: file::Source>(
    src: &mut S,
    entry: &file::GridEntry,
) -> Result<FloatGrid, NanoVdbError> {
    if entry.grid_type != tree::GRID_TYPE_FLOAT {
        return Err(NanoVdbError::NotFloatGrid {
            name: entry.name.clone(),
            found_type: tree::grid_type_name(entry.grid_type),
        });
    }
    let bytes = file::load_grid_bytes(src, entry)?;
    tree::decode(&bytes, &entry.name)
}
