//! The file level of a .nvdb file: segment headers, per-grid metadata and names, and getting
//! one grid's buffer out (stored as is or ZIP-compressed), or a file of raw grid buffers.
//!
//! Every size a header claims is checked against the bytes the file actually has before
//! anything is allocated for it.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::{NanoVdbError, MAX_FILE_BYTES};

/// "NanoVDB0": segment headers of files up to 32.5, and grid buffers up to 32.5.
pub(super) const MAGIC_NUMB: u64 = 0x3042_4456_6f6e_614e;
/// "NanoVDB1": grid buffers from 32.6 on.
pub(super) const MAGIC_GRID: u64 = 0x3142_4456_6f6e_614e;
/// "NanoVDB2": segment headers from 32.6 on.
const MAGIC_FILE: u64 = 0x3242_4456_6f6e_614e;

/// The one major version whose layout this reader knows.
pub(super) const SUPPORTED_MAJOR: u32 = 32;

/// `io::FileHeader`: magic u64, version u32, grid count u16, codec u16.
const FILE_HEADER_BYTES: u64 = 16;
/// `io::FileMetaData`, followed by the name (`nameSize` bytes, NUL included).
const FILE_META_BYTES: u64 = 176;
/// `GridData`; a grid buffer also holds at least `TreeData` (64) and the root (64).
pub(super) const GRID_DATA_BYTES: u64 = 672;
const MIN_GRID_BYTES: u64 = GRID_DATA_BYTES + 64 + 64;

/// The packed version number: major << 21 | minor << 10 | patch.
pub(super) fn version_error(v: u32) -> NanoVdbError {
    NanoVdbError::UnsupportedVersion {
        major: v >> 21,
        minor: (v >> 10) & 0x7ff,
        patch: v & 0x3ff,
    }
}

pub(super) fn is_supported_version(v: u32) -> bool {
    v >> 21 == SUPPORTED_MAJOR
}

/// Random access to the file's bytes (a file on disk, or bytes in memory for tests).
pub(super) trait Source {
    /// Length in bytes.
    fn len(&self) -> u64;
    /// Fills `buf` from `offset`; callers have checked the range lies within `len()`.
    fn read_at(&mut self, offset: u64, buf: &mut [u8]) -> Result<(), NanoVdbError>;
}

/// A file on disk.
pub(super) struct FileSource {
    file: File,
    len: u64,
}

impl FileSource {
    pub(super) fn open(path: &Path) -> Result<Self, NanoVdbError> {
        let file = File::open(path)?;
        let len = file.metadata()?.len();
        if len > MAX_FILE_BYTES {
            return Err(NanoVdbError::TooLarge { len });
        }
        Ok(FileSource { file, len })
    }
}

impl Source for FileSource {
    fn len(&self) -> u64 {
        self.len
    }
    fn read_at(&mut self, offset: u64, buf: &mut [u8]) -> Result<(), NanoVdbError> {
        self.file.seek(SeekFrom::Start(offset))?;
        self.file.read_exact(buf)?;
        Ok(())
    }
}

/// Bytes in memory.
pub(super) struct SliceSource<'a>(pub(super) &'a [u8]);

impl Source for SliceSource<'_> {
    fn len(&self) -> u64 {
        self.0.len() as u64
    }
    fn read_at(&mut self, offset: u64, buf: &mut [u8]) -> Result<(), NanoVdbError> {
        let start = usize::try_from(offset).ok();
        let part = start
            .and_then(|s| Some(s..s.checked_add(buf.len())?))
            .and_then(|r| self.0.get(r));
        match part {
            Some(part) => {
                buf.copy_from_slice(part);
                Ok(())
            }
            None => Err(NanoVdbError::Corrupt(format!(
                "read of {} bytes at byte {offset} is outside the data",
                buf.len()
            ))),
        }
    }
}

/// Reads `n` bytes at `offset`, or says the file is truncated there.
fn read_exact_at<S: Source>(
    src: &mut S,
    offset: u64,
    n: u64,
    what: &'static str,
) -> Result<Vec<u8>, NanoVdbError> {
    let available = src.len().saturating_sub(offset);
    if n > available {
        return Err(NanoVdbError::Truncated {
            what,
            offset,
            needed: n,
            available,
        });
    }
    // n <= file length <= MAX_FILE_BYTES, so this fits in memory's address space on 64-bit.
    let n = usize::try_from(n)
        .map_err(|_| NanoVdbError::Corrupt(format!("{what} of {n} bytes is too large")))?;
    let mut buf = vec![0u8; n];
    src.read_at(offset, &mut buf)?;
    Ok(buf)
}

pub(super) fn le_u16(b: &[u8], at: usize) -> u16 {
    let mut a = [0u8; 2];
    a.copy_from_slice(&b[at..at + 2]);
    u16::from_le_bytes(a)
}

pub(super) fn le_u32(b: &[u8], at: usize) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[at..at + 4]);
    u32::from_le_bytes(a)
}

pub(super) fn le_u64(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// A NUL-terminated name (lossily decoded as UTF-8).
pub(super) fn c_string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}

/// How a grid's buffer is stored in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Codec {
    /// As is.
    None,
    /// A u64 byte count, then that many bytes of zlib data.
    Zip,
    /// Anything else (2 is BLOSC).
    Other(u16),
}

impl Codec {
    fn from_raw(c: u16) -> Self {
        match c {
            0 => Codec::None,
            1 => Codec::Zip,
            c => Codec::Other(c),
        }
    }
}

/// One grid found in the file.
#[derive(Clone, Debug)]
pub(super) struct GridEntry {
    /// The grid's name.
    pub(super) name: String,
    /// NanoVDB's `GridType` number (1 is float).
    pub(super) grid_type: u32,
    codec: Codec,
    /// Where its stored bytes start.
    data_offset: u64,
    /// How many bytes it occupies in the file.
    file_size: u64,
    /// The size of the (uncompressed) grid buffer.
    pub(super) grid_size: u64,
}

/// Lists the grids of the file, checking every header and that every grid's bytes are present.
pub(super) fn scan<S: Source>(src: &mut S) -> Result<Vec<GridEntry>, NanoVdbError> {
    let len = src.len();
    if len > MAX_FILE_BYTES {
        return Err(NanoVdbError::TooLarge { len });
    }
    if len < 8 {
        // Too short for a magic number: truncated if what is there starts like one.
        let head = read_exact_at(src, 0, len, "file header")?;
        let is_prefix = [MAGIC_NUMB, MAGIC_GRID, MAGIC_FILE]
            .iter()
            .any(|m| m.to_le_bytes().starts_with(&head));
        return Err(if is_prefix && len > 0 {
            NanoVdbError::Truncated {
                what: "file header",
                offset: 0,
                needed: FILE_HEADER_BYTES,
                available: len,
            }
        } else {
            NanoVdbError::NotNanoVdb
        });
    }
    let magic = le_u64(&read_exact_at(src, 0, 8, "file header")?, 0);
    match magic {
        MAGIC_GRID => scan_raw_grids(src),
        MAGIC_NUMB if len >= 20 => {
            // Up to 32.5 raw grid buffers and segment headers share this magic: a segment
            // has the version at byte 8, a grid buffer at byte 16 (after its checksum).
            let head = read_exact_at(src, 0, 20, "file header")?;
            if !is_supported_version(le_u32(&head, 8)) && is_supported_version(le_u32(&head, 16)) {
                scan_raw_grids(src)
            } else {
                scan_segments(src)
            }
        }
        MAGIC_NUMB | MAGIC_FILE => scan_segments(src),
        m if [MAGIC_NUMB, MAGIC_GRID, MAGIC_FILE].contains(&m.swap_bytes()) => Err(
            NanoVdbError::Corrupt("byte-swapped (big-endian) NanoVDB file".to_string()),
        ),
        _ => Err(NanoVdbError::NotNanoVdb),
    }
}

/// Segments: header, metadata and name of each grid, then the grids' bytes; repeated to the
/// end of the file.
fn scan_segments<S: Source>(src: &mut S) -> Result<Vec<GridEntry>, NanoVdbError> {
    let len = src.len();
    let mut entries = Vec::new();
    let mut offset = 0u64;
    while offset < len {
        let header = read_exact_at(src, offset, FILE_HEADER_BYTES, "segment header")?;
        let magic = le_u64(&header, 0);
        if magic != MAGIC_NUMB && magic != MAGIC_FILE {
            return Err(if offset == 0 {
                NanoVdbError::NotNanoVdb
            } else {
                NanoVdbError::Corrupt(format!(
                    "no segment header at byte {offset} (bad magic number)"
                ))
            });
        }
        let version = le_u32(&header, 8);
        if !is_supported_version(version) {
            return Err(version_error(version));
        }
        let grid_count = le_u16(&header, 12);
        let codec = Codec::from_raw(le_u16(&header, 14));
        let mut pos = offset + FILE_HEADER_BYTES;
        // (name, type, file size, grid size) of each grid of this segment.
        let mut metas = Vec::with_capacity(usize::from(grid_count));
        for _ in 0..grid_count {
            let m = read_exact_at(src, pos, FILE_META_BYTES, "grid metadata")?;
            let grid_size = le_u64(&m, 0);
            let file_size = le_u64(&m, 8);
            let grid_type = le_u32(&m, 32);
            let name_size = u64::from(le_u32(&m, 136));
            pos += FILE_META_BYTES;
            let name = c_string(&read_exact_at(src, pos, name_size, "grid name")?);
            pos += name_size;
            metas.push((name, grid_type, file_size, grid_size));
        }
        for (name, grid_type, file_size, grid_size) in metas {
            let available = len - pos;
            if file_size > available {
                return Err(NanoVdbError::Truncated {
                    what: "grid data",
                    offset: pos,
                    needed: file_size,
                    available,
                });
            }
            entries.push(GridEntry {
                name,
                grid_type,
                codec,
                data_offset: pos,
                file_size,
                grid_size,
            });
            pos += file_size;
        }
        offset = pos;
    }
    Ok(entries)
}

/// Raw grid buffers back to back, each with its size in its `GridData`.
fn scan_raw_grids<S: Source>(src: &mut S) -> Result<Vec<GridEntry>, NanoVdbError> {
    let len = src.len();
    let mut entries = Vec::new();
    let mut offset = 0u64;
    while offset < len {
        let g = read_exact_at(src, offset, GRID_DATA_BYTES, "grid header")?;
        let magic = le_u64(&g, 0);
        if magic != MAGIC_NUMB && magic != MAGIC_GRID {
            return Err(NanoVdbError::Corrupt(format!(
                "no grid at byte {offset} (bad magic number)"
            )));
        }
        let version = le_u32(&g, 16);
        if !is_supported_version(version) {
            return Err(version_error(version));
        }
        let grid_size = le_u64(&g, 32);
        if grid_size < MIN_GRID_BYTES {
            return Err(NanoVdbError::Corrupt(format!(
                "grid at byte {offset} claims {grid_size} bytes, less than its headers"
            )));
        }
        let available = len - offset;
        if grid_size > available {
            return Err(NanoVdbError::Truncated {
                what: "grid",
                offset,
                needed: grid_size,
                available,
            });
        }
        entries.push(GridEntry {
            // GridData's own name field; a name over 255 bytes (which NanoVDB keeps in blind
            // data) comes out cut.
            name: c_string(&g[40..296]),
            grid_type: le_u32(&g, 636),
            codec: Codec::None,
            data_offset: offset,
            file_size: grid_size,
            grid_size,
        });
        offset += grid_size;
    }
    Ok(entries)
}

/// The grid's uncompressed buffer.
pub(super) fn load_grid_bytes<S: Source>(
    src: &mut S,
    e: &GridEntry,
) -> Result<Vec<u8>, NanoVdbError> {
    if e.grid_size < MIN_GRID_BYTES {
        return Err(NanoVdbError::Corrupt(format!(
            "grid \"{}\" claims {} bytes, less than its headers",
            e.name, e.grid_size
        )));
    }
    match e.codec {
        Codec::None => {
            if e.file_size != e.grid_size {
                return Err(NanoVdbError::Corrupt(format!(
                    "uncompressed grid \"{}\" takes {} bytes in the file but claims {}",
                    e.name, e.file_size, e.grid_size
                )));
            }
            read_exact_at(src, e.data_offset, e.grid_size, "grid data")
        }
        Codec::Zip => {
            if e.file_size < 8 {
                return Err(NanoVdbError::Corrupt(format!(
                    "ZIP-compressed grid \"{}\" takes only {} bytes",
                    e.name, e.file_size
                )));
            }
            let count = le_u64(&read_exact_at(src, e.data_offset, 8, "grid data")?, 0);
            if count > e.file_size - 8 {
                return Err(NanoVdbError::Corrupt(format!(
                    "ZIP-compressed grid \"{}\" claims {count} compressed bytes in a {}-byte record",
                    e.name, e.file_size
                )));
            }
            if e.grid_size > MAX_FILE_BYTES {
                return Err(NanoVdbError::TooLarge { len: e.grid_size });
            }
            let packed = read_exact_at(src, e.data_offset + 8, count, "compressed grid")?;
            inflate(&packed, e)
        }
        Codec::Other(2) => Err(NanoVdbError::UnsupportedCodec {
            codec: "BLOSC".to_string(),
        }),
        Codec::Other(c) => Err(NanoVdbError::UnsupportedCodec {
            codec: format!("codec {c}"),
        }),
    }
}

/// Inflates a zlib stream into exactly `e.grid_size` bytes. The output grows with what the
/// stream actually yields (never more than `grid_size + 1` bytes are asked for), so a false
/// size claim cannot make us allocate up front.
fn inflate(packed: &[u8], e: &GridEntry) -> Result<Vec<u8>, NanoVdbError> {
    let mut out = Vec::new();
    let mut reader = flate2::read::ZlibDecoder::new(packed).take(e.grid_size + 1);
    reader.read_to_end(&mut out).map_err(|err| {
        NanoVdbError::Corrupt(format!(
            "ZIP-compressed grid \"{}\" does not inflate: {err}",
            e.name
        ))
    })?;
    if out.len() as u64 > e.grid_size {
        return Err(NanoVdbError::Corrupt(format!(
            "ZIP-compressed grid \"{}\" inflates to more than its {} bytes",
            e.name, e.grid_size
        )));
    }
    if (out.len() as u64) < e.grid_size {
        return Err(NanoVdbError::Corrupt(format!(
            "ZIP-compressed grid \"{}\" inflates to {} bytes instead of {}",
            e.name,
            out.len(),
            e.grid_size
        )));
    }
    Ok(out)
}
