//! Opening input files: the one place that reads scene text, PLY meshes and
//! (later) images from disk, decompressing gzip transparently (pbrt-v4
//! `util/file.cpp` `ReadFileContents` / `ReadDecompressedFileContents`).
//!
//! Gzip is recognised by its magic bytes (`0x1f 0x8b`), whatever the file is
//! called. [`FileReader`] streams the (decompressed) contents, so a caller that
//! parses as it reads never holds the whole file in memory;
//! [`read_file_limited`] reads everything into one buffer, refusing files
//! larger than a given limit.
//!
//! This module depends on nothing else in the crate, so every other module
//! (the driver, diagnostics, the PLY reader) can use it.

use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::Path;

/// The two bytes every gzip member starts with (RFC 1952, section 2.3.1).
pub const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// The default largest image file (after decompression) that is read into
/// memory: 64 GiB. Scene text has its own, lower limit
/// ([`DEFAULT_MAX_SCENE_FILE_BYTES`]).
pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 36;

/// The default largest scene file (after decompression) the parser reads
/// into memory: 1 GiB of text per file. Scene text is held whole while it
/// is parsed, so this is a bound on memory, not only on disk reads: an
/// `Include "/dev/urandom"` or a small `.pbrt.gz` inflating without end
/// stops here with an error. Real scenes keep bulk geometry in PLY files
/// and stay far below it. `ParseOptions::max_file_bytes` changes it.
pub const DEFAULT_MAX_SCENE_FILE_BYTES: u64 = 1 << 30;

/// Size of the buffer between the file and its consumer.
const BUFFER_SIZE: usize = 64 * 1024;

/// True when `bytes` starts with the gzip magic bytes.
pub fn is_gzip(bytes: &[u8]) -> bool {
    bytes.starts_with(&GZIP_MAGIC)
}

/// True when `path` ends in `.gz` (any case): a name that promises gzip
/// data, for callers that open such files with [`FileReader::open_gzip`] or
/// compress what they write.
pub fn has_gz_extension(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
}

/// The first bytes of a file, read to sniff its format, followed by the rest.
type Raw = io::Chain<io::Cursor<Vec<u8>>, File>;

enum Inner {
    Plain(BufReader<Raw>),
    Gzip(Box<flate2::read::MultiGzDecoder<BufReader<Raw>>>),
}

/// A streaming reader over a file's contents, decompressed when the file is
/// gzip-compressed.
///
/// Plain files are read through a [`BufReader`]; gzip files through a
/// [`flate2::read::MultiGzDecoder`] (so concatenated gzip members read as one
/// stream). Errors from a gzip stream (corrupt or truncated data) surface as
/// [`io::Error`]s from [`Read::read`].
pub struct FileReader {
    inner: Inner,
    file_len: Option<u64>,
    gzip_hint: Option<u64>,
}

/// The most a gzip trailer's size is believed, as a multiple of the
/// compressed size.
const MAX_HINT_RATIO: u64 = 16;

/// The uncompressed size a gzip file's trailer records (ISIZE: the size of its
/// last member, modulo 2^32), capped at [`MAX_HINT_RATIO`] times the file
/// size. Only a hint: it may be forged, wrap, or miss earlier members.
fn file_gzip_size_hint(file: &mut File, file_len: u64) -> Option<u64> {
    use std::io::{Seek, SeekFrom};
    // A gzip member has at least a 10-byte header and an 8-byte trailer.
    if file_len < 18 {
        return None;
    }
    let mut isize = [0u8; 4];
    file.seek(SeekFrom::Start(file_len - 4)).ok()?;
    file.read_exact(&mut isize).ok()?;
    Some(u64::from(u32::from_le_bytes(isize)).min(file_len.saturating_mul(MAX_HINT_RATIO)))
}

impl FileReader {
    /// Opens `path`, inflating it when it starts with the gzip magic bytes.
    pub fn open(path: impl AsRef<Path>) -> io::Result<FileReader> {
        Self::open_impl(path.as_ref(), false)
    }

    /// Opens `path` as a gzip stream whatever its first bytes are (for files
    /// whose name says they are compressed); data that is not gzip fails on
    /// the first read.
    pub fn open_gzip(path: impl AsRef<Path>) -> io::Result<FileReader> {
        Self::open_impl(path.as_ref(), true)
    }

    fn open_impl(path: &Path, force_gzip: bool) -> io::Result<FileReader> {
        let mut file = File::open(path)?;
        // Only a regular file's size says how much there is to read (a pipe
        // reports 0).
        let file_len = file
            .metadata()
            .ok()
            .filter(|m| m.is_file())
            .map(|m| m.len());
        // Read the magic bytes without seeking, so pipes work too.
        let mut head = Vec::with_capacity(GZIP_MAGIC.len());
        (&mut file)
            .take(GZIP_MAGIC.len() as u64)
            .read_to_end(&mut head)?;
        let gzip = force_gzip || is_gzip(&head);
        let gzip_hint = match (gzip, file_len) {
            (true, Some(len)) => File::open(path)
                .ok()
                .and_then(|mut f| file_gzip_size_hint(&mut f, len)),
            _ => None,
        };
        let raw = BufReader::with_capacity(BUFFER_SIZE, io::Cursor::new(head).chain(file));
        let inner = if gzip {
            Inner::Gzip(Box::new(flate2::read::MultiGzDecoder::new(raw)))
        } else {
            Inner::Plain(raw)
        };
        Ok(FileReader {
            inner,
            file_len,
            gzip_hint,
        })
    }

    /// True when the contents are being decompressed.
    pub fn is_gzip(&self) -> bool {
        matches!(self.inner, Inner::Gzip(_))
    }

    /// Size of the file on disk (compressed size for gzip files), when it is
    /// a regular file.
    pub fn file_len(&self) -> Option<u64> {
        self.file_len
    }

    /// The number of bytes [`Read`] will yield, when known without reading:
    /// the file size for plain files, `None` for gzip files.
    pub fn content_len(&self) -> Option<u64> {
        match self.inner {
            Inner::Plain(_) => self.file_len,
            Inner::Gzip(_) => None,
        }
    }

    /// A guess at the number of bytes [`Read`] will yield, for sizing
    /// buffers: [`content_len`](Self::content_len) for plain files; for gzip
    /// files the size the gzip trailer records, believed up to 16 times the
    /// compressed size. Not a bound: the data may be shorter or longer.
    pub fn size_hint(&self) -> Option<u64> {
        match self.inner {
            Inner::Plain(_) => self.file_len,
            Inner::Gzip(_) => self.gzip_hint,
        }
    }
}

impl Read for FileReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match &mut self.inner {
            Inner::Plain(r) => r.read(buf),
            Inner::Gzip(r) => r.read(buf),
        }
    }
}

/// The uncompressed size that gzip data held in memory records in its
/// trailer, believed up to 16 times the compressed size (see
/// [`FileReader::size_hint`]); `None` when `bytes` is too short to be gzip.
pub fn gzip_size_hint(bytes: &[u8]) -> Option<u64> {
    let len = bytes.len() as u64;
    let tail = bytes.len().checked_sub(4).filter(|_| len >= 18)?;
    let isize = u32::from_le_bytes(bytes[tail..].try_into().ok()?);
    Some(u64::from(isize).min(len.saturating_mul(MAX_HINT_RATIO)))
}

/// The error inside the [`io::Error`] of a read that passed its limit
/// (see [`is_too_large`]).
#[derive(Debug)]
pub struct TooLarge {
    /// What was measured ("file size", "decompressed size").
    pub what: String,
    /// The limit, in bytes.
    pub limit: u64,
}

impl std::fmt::Display for TooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} exceeds the limit of {} bytes", self.what, self.limit)
    }
}

impl std::error::Error for TooLarge {}

fn too_large(what: &str, limit: u64) -> io::Error {
    io::Error::other(TooLarge {
        what: what.to_string(),
        limit,
    })
}

/// True when `e` says a read passed its size limit (rather than failing).
pub fn is_too_large(e: &io::Error) -> bool {
    e.get_ref().is_some_and(|inner| inner.is::<TooLarge>())
}

/// Reads all of `reader` into memory, failing when it yields more than `limit`
/// bytes. `what` names the size in the error ("file size", "decompressed
/// size"). `capacity` is an initial reservation (clamped to the limit).
pub fn read_to_end_limited(
    reader: impl Read,
    limit: u64,
    capacity: u64,
    what: &str,
) -> io::Result<Vec<u8>> {
    let capacity = usize::try_from(capacity.min(limit)).unwrap_or(0);
    let mut out = Vec::with_capacity(capacity);
    reader.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    if out.len() as u64 > limit {
        return Err(too_large(what, limit));
    }
    Ok(out)
}

/// Reads a whole file into memory, decompressing it when it starts with the
/// gzip magic bytes, and fails when its (decompressed) size exceeds `limit`
/// bytes.
///
/// Plain files are checked against the limit before anything is read. Gzip
/// files are inflated straight into the result as the compressed bytes are
/// read, so the compressed data is never held in memory as a whole.
pub fn read_file_limited(path: impl AsRef<Path>, limit: u64) -> io::Result<Vec<u8>> {
    let path = path.as_ref();
    let reader = FileReader::open(path)?;
    match reader.content_len() {
        Some(len) => {
            if len > limit {
                return Err(too_large("file size", limit));
            }
            if len >= PARALLEL_READ_MIN {
                let parts = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
                if let Some(bytes) = read_plain_in_parts(path, len, parts)? {
                    return Ok(bytes);
                }
            }
            // The file may still grow while it is read: keep the limit.
            read_to_end_limited(reader, limit, len, "file size")
        }
        None => {
            // One more byte than expected, so that a correct hint needs no
            // reallocation to find the end.
            let hint = reader.size_hint().unwrap_or(0).saturating_add(1);
            read_to_end_limited(reader, limit, hint, "decompressed size")
        }
    }
}

/// Plain files at least this large are read in parts by as many threads
/// as there are cores (up to four), each part's pages faulted in and
/// copied by its own thread: a 40 MB scene's read took a tenth of its parse
/// on one thread, most of it the kernel filling fresh pages.
const PARALLEL_READ_MIN: u64 = 8 << 20;

/// The `len` bytes of the plain file at `path`, read in `parts` pieces at
/// once; `None` (the caller then reads it in order) when the file is not
/// what was found when it was opened: another length, gzip data now, or a
/// part that ends early.
#[cfg(unix)]
fn read_plain_in_parts(path: &Path, len: u64, parts: usize) -> io::Result<Option<Vec<u8>>> {
    use std::os::unix::fs::FileExt;
    let Ok(n) = usize::try_from(len) else {
        return Ok(None);
    };
    let file = File::open(path)?;
    if parts < 2 || file.metadata()?.len() != len {
        return Ok(None);
    }
    // Zeroed by the allocator (fresh pages for a buffer this large), so
    // nothing writes it before the reads do.
    let mut buf = vec![0u8; n];
    let part = n.div_ceil(parts).next_multiple_of(1 << 16).max(1);
    let read_part = |offset: usize, chunk: &mut [u8]| -> io::Result<bool> {
        let mut done = 0;
        while done < chunk.len() {
            match file.read_at(&mut chunk[done..], (offset + done) as u64) {
                Ok(0) => return Ok(false),
                Ok(k) => done += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        Ok(true)
    };
    let complete = std::thread::scope(|s| {
        let mut chunks = buf.chunks_mut(part).enumerate();
        let first = chunks.next();
        let others: Vec<_> = chunks
            .map(|(i, chunk)| s.spawn(move || read_part(i * part, chunk)))
            .collect();
        let mut complete = match first {
            Some((_, chunk)) => read_part(0, chunk)?,
            None => true,
        };
        for h in others {
            complete &= h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))?;
        }
        io::Result::Ok(complete)
    })?;
    // A file that grew while it was read has more to give: read in order.
    let grew = file.read_at(&mut [0u8], len)? > 0;
    Ok((complete && !grew && !is_gzip(&buf)).then_some(buf))
}

/// Elsewhere files are read in order.
#[cfg(not(unix))]
fn read_plain_in_parts(_: &Path, _: u64, _: usize) -> io::Result<Option<Vec<u8>>> {
    Ok(None)
}

/// `len` bytes of xorshift noise from `seed` (nonzero), for tests that
/// need bytes no two of which are alike for long.
#[cfg(test)]
pub(crate) fn noise_bytes(seed: u64, len: usize) -> Vec<u8> {
    let mut x = seed;
    (0..len)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;
    use std::path::PathBuf;

    fn temp(name: &str, bytes: &[u8]) -> PathBuf {
        let path = std::env::temp_dir().join(format!("rpbrt-input-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        path
    }

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(bytes).unwrap();
        enc.finish().unwrap()
    }

    #[test]
    fn plain_and_gzip_read_the_same() {
        let text = b"WorldBegin\nShape \"sphere\"\n".repeat(1000);
        let plain = temp("plain.pbrt", &text);
        let gz = temp("packed.pbrt", &gzip(&text));
        for (path, is_gz) in [(&plain, false), (&gz, true)] {
            let mut r = FileReader::open(path).unwrap();
            assert_eq!(r.is_gzip(), is_gz);
            assert_eq!(r.content_len().is_some(), !is_gz);
            let hint = r.size_hint().unwrap();
            assert!(hint > 0 && hint <= text.len() as u64, "{hint}");
            let mut out = Vec::new();
            r.read_to_end(&mut out).unwrap();
            assert_eq!(out, text);
            assert_eq!(read_file_limited(path, 1 << 20).unwrap(), text);
        }
        for path in [plain, gz] {
            std::fs::remove_file(path).unwrap();
        }
    }

    #[test]
    fn a_file_read_in_parts_is_the_file() {
        // Bytes that differ from part to part, in sizes around the parts'
        // 64 KiB alignment.
        let bytes = noise_bytes(0x9e37_79b9, (3 << 16) + 123);
        for len in [0, 1, 1 << 16, (1 << 16) + 1, (2 << 16) - 1, bytes.len()] {
            let path = temp(&format!("parts-{len}.bin"), &bytes[..len]);
            for parts in 1..=5 {
                let got = read_plain_in_parts(&path, len as u64, parts).unwrap();
                if parts == 1 || !cfg!(unix) {
                    assert_eq!(got, None);
                } else {
                    assert_eq!(
                        got.as_deref(),
                        Some(&bytes[..len]),
                        "{len} bytes, {parts} parts"
                    );
                }
            }
            // A length other than the file's: read in order instead.
            if len > 0 && cfg!(unix) {
                assert_eq!(read_plain_in_parts(&path, len as u64 - 1, 2).unwrap(), None);
                assert_eq!(read_plain_in_parts(&path, len as u64 + 1, 2).unwrap(), None);
            }
            std::fs::remove_file(path).unwrap();
        }
        // Gzip data is left to the reader that inflates it.
        let gz = temp("parts.gz", &gzip(&bytes));
        let n = std::fs::metadata(&gz).unwrap().len();
        assert_eq!(read_plain_in_parts(&gz, n, 2).unwrap(), None);
        std::fs::remove_file(gz).unwrap();
    }

    #[test]
    fn limits_and_short_files() {
        let text = b"0123456789";
        let plain = temp("limit.txt", text);
        let gz = temp("limit.gz", &gzip(text));
        let one = temp("one.txt", b"x");
        let empty = temp("empty.txt", b"");
        let e = read_file_limited(&plain, 9).unwrap_err();
        assert_eq!(e.to_string(), "file size exceeds the limit of 9 bytes");
        assert!(is_too_large(&e));
        assert!(!is_too_large(&io::Error::other("other")));
        let e = read_file_limited(&gz, 9).unwrap_err();
        assert_eq!(
            e.to_string(),
            "decompressed size exceeds the limit of 9 bytes"
        );
        assert_eq!(read_file_limited(&gz, 10).unwrap(), text);
        assert_eq!(read_file_limited(&one, 10).unwrap(), b"x");
        assert_eq!(read_file_limited(&empty, 10).unwrap(), b"");
        // A name that promises gzip does not make plain data decompress.
        let mut forced = FileReader::open_gzip(&plain).unwrap();
        assert!(forced.read_to_end(&mut Vec::new()).is_err());
        for path in [plain, gz, one, empty] {
            std::fs::remove_file(path).unwrap();
        }
        assert!(FileReader::open("/nonexistent/rpbrt-input-test").is_err());
    }
}
