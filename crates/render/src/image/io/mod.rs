//! Reading and writing image files by extension (pbrt-v4 `Image::Read`, `Image::Write`;
//! book appendix B.5). EXR via the `exr` crate, PNG via `png`; PFM, TGA, Radiance HDR and
//! QOI are implemented here. Readers work on in-memory bytes and never panic on
//! malformed input: every failure is an [`ImageError`] naming the file.

mod exr_io;
mod hdr;
mod pfm;
mod png_io;
mod qoi;
mod tga;

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use rpbrt_geometry::{Bounds2i, Point2i};
use rpbrt_parser::MemoryBudget;

use super::{ColorEncoding, Image};

/// Why an image could not be read or written.
#[derive(Debug)]
pub enum ImageError {
    /// The file could not be opened, read or written.
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file's contents are malformed or use an unsupported feature.
    Format {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// An invalid request independent of any file (bad sizes, missing channels).
    Invalid(String),
}

impl fmt::Display for ImageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImageError::Io { path, source } => write!(f, "{path}: {source}"),
            ImageError::Format { path, message } => write!(f, "{path}: {message}"),
            ImageError::Invalid(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for ImageError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ImageError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Information stored alongside pixels, mostly in EXR headers (pbrt-v4 `ImageMetadata`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageMetadata {
    /// Render time ("renderTimeSeconds").
    pub render_time_seconds: Option<f32>,
    /// Camera-from-world matrix, row major ("worldToCamera").
    pub camera_from_world: Option<[[f32; 4]; 4]>,
    /// NDC-from-world matrix, row major ("worldToNDC").
    pub ndc_from_world: Option<[[f32; 4]; 4]>,
    /// Pixel bounds of the stored data within the full image (EXR data window).
    pub pixel_bounds: Option<Bounds2i>,
    /// Resolution of the full image (EXR display window).
    pub full_resolution: Option<Point2i>,
    /// Samples per pixel ("samplesPerPixel").
    pub samples_per_pixel: Option<i32>,
    /// Estimated variance ("estimatedVariance").
    pub estimated_variance: Option<f32>,
    /// Mean squared error against a reference ("MSE").
    pub mse: Option<f32>,
    /// RGB colour space name as pbrt-v4 names them ("srgb", "rec2020", "aces2065-1",
    /// "dci-p3"); `None` when the file says nothing.
    pub color_space: Option<String>,
    /// String-vector attributes.
    pub strings: BTreeMap<String, Vec<String>>,
}

impl ImageMetadata {
    /// The colour space name, defaulting to "srgb" as pbrt-v4 does.
    pub fn color_space_name(&self) -> &str {
        self.color_space.as_deref().unwrap_or("srgb")
    }
}

/// An image with its metadata.
#[derive(Clone, Debug)]
pub struct ImageAndMetadata {
    /// The pixels.
    pub image: Image,
    /// What the file said about them.
    pub metadata: ImageMetadata,
}

/// Writes `bytes` to `path` through a temporary file in the same directory
/// (same file system) that is renamed over `path` once complete.
///
/// The temporary file is created exclusively (`O_CREAT|O_EXCL`, which also
/// refuses to follow a symlink planted at its name) under an unpredictable
/// name, so another user of a shared directory can neither guess it in
/// advance nor redirect the write elsewhere. When `path` itself is a symlink
/// the write goes through it: the file it names is replaced and the link
/// stays a link, as a plain `open(O_TRUNC)` would have done. A replaced file
/// keeps its permission bits; a new one gets the default (umask) mode.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let target = resolve_symlinks(path)?;
    let existing_mode = existing_permissions(&target);
    let (tmp, mut f) = create_temp_beside(&target, existing_mode.as_ref())?;
    let result = (|| {
        if let Some(perm) = existing_mode {
            // The creation mode went through the umask; set the exact bits.
            f.set_permissions(perm)?;
        }
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, &target)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Checks, before any work is spent on it, that a file could be written at
/// `path` the way [`write_atomically`] writes it: creates and removes an
/// exclusive temporary file in the directory the write would reach
/// (through symlinks), and refuses a `path` that is a directory. A render
/// can thus fail in a moment rather than after hours.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    let target = resolve_symlinks(path)?;
    if std::fs::metadata(&target).is_ok_and(|m| m.is_dir()) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is a directory",
        ));
    }
    let (tmp, f) = create_temp_beside(&target, None)?;
    drop(f);
    std::fs::remove_file(&tmp)
}

/// Follows `path` through any chain of symlinks (relative links resolve
/// against the link's own directory) to the file a write through it would
/// reach, which need not exist yet. Gives up after as many hops as Linux
/// allows (40) so that a link loop is an error rather than a hang.
fn resolve_symlinks(path: &Path) -> std::io::Result<std::path::PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&current) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&current)?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        "too many levels of symbolic links",
    ))
}

/// Permission bits of an existing regular file at `path`, which the new file
/// should keep (a private 0600 image must not become world-readable).
fn existing_permissions(path: &Path) -> Option<std::fs::Permissions> {
    std::fs::metadata(path)
        .ok()
        .filter(|m| m.is_file())
        .map(|m| m.permissions())
}

/// Creates a fresh file named `.<name>.<unique>.tmp` in `target`'s directory,
/// retrying a bounded number of times when the name is taken.
fn create_temp_beside(
    target: &Path,
    mode: Option<&std::fs::Permissions>,
) -> std::io::Result<(std::path::PathBuf, std::fs::File)> {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let file_name = target
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    let mut last_err = None;
    for _ in 0..64 {
        let count = COUNTER.fetch_add(1, Ordering::Relaxed);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(0);
        // `RandomState` is seeded from the OS's random source: the hash is
        // what makes the name unguessable, the rest what makes it unique.
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(count);
        h.write_u64(nanos);
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(file_name);
        tmp_name.push(format!(
            ".{}-{count}-{:016x}.tmp",
            std::process::id(),
            h.finish()
        ));
        let tmp = target.with_file_name(tmp_name);
        let mut options = std::fs::OpenOptions::new();
        options.write(true).create_new(true);
        #[cfg(unix)]
        if let Some(perm) = mode {
            use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
            options.mode(perm.mode() & 0o7777);
        }
        #[cfg(not(unix))]
        let _ = mode;
        match options.open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last_err = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_err.unwrap_or_else(|| {
        std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary name")
    }))
}

/// Result type of the format modules: a message without the file name.
type FmtResult<T> = Result<T, String>;

/// Lower-case extension of a file name, without the dot.
fn extension(name: &str) -> String {
    Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default()
}

impl Image {
    /// Reads an image file chosen by extension: exr, png, pfm, hdr, tga, qoi.
    /// `encoding` applies to 8- and 16-bit PNG, TGA and QOI (default sRGB).
    /// The image is held against the default memory budget
    /// ([`MemoryBudget::default`]).
    pub fn read(
        path: impl AsRef<Path>,
        encoding: Option<ColorEncoding>,
    ) -> Result<ImageAndMetadata, ImageError> {
        Self::read_within(path, encoding, &MemoryBudget::default())
    }

    /// [`read`](Self::read), charging the decoded image to `budget`: the
    /// file is read no further than the budget has room for, and a header
    /// whose size needs more than that is an error before any pixel is
    /// decoded.
    pub fn read_within(
        path: impl AsRef<Path>,
        encoding: Option<ColorEncoding>,
        budget: &MemoryBudget,
    ) -> Result<ImageAndMetadata, ImageError> {
        let path = path.as_ref();
        let bytes = Self::file_bytes_within(path, budget)?;
        let image =
            Self::read_from_bytes_within(&bytes, &Self::format_name(path), encoding, budget);
        budget.release(bytes.len() as u64);
        image
    }

    /// The name whose extension says how `path`'s bytes are decoded (a
    /// `.gz` suffix is not the image's extension).
    pub(crate) fn format_name(path: &Path) -> String {
        let name = path.display().to_string();
        name.strip_suffix(".gz").unwrap_or(&name).to_string()
    }

    /// The bytes of the image file at `path` (inflated when gzip-compressed),
    /// charged to `budget`: the caller releases `len()` bytes when done.
    pub(crate) fn file_bytes_within(
        path: &Path,
        budget: &MemoryBudget,
    ) -> Result<Vec<u8>, ImageError> {
        let name = path.display().to_string();
        // The project's one file reader (gzip-compressed images are
        // inflated as they are read). The file's bytes are held while the
        // image is decoded.
        let room = budget.available();
        let limit = rpbrt_parser::input::DEFAULT_MAX_FILE_BYTES.min(room);
        let bytes = rpbrt_parser::input::read_file_limited(path, limit).map_err(|source| {
            if rpbrt_parser::input::is_too_large(&source) && limit == room {
                ImageError::Format {
                    path: name.clone(),
                    message: budget.exceeded(room, "this image file").to_string(),
                }
            } else {
                ImageError::Io {
                    path: name.clone(),
                    source,
                }
            }
        })?;
        budget
            .charge(bytes.len() as u64, "this image file")
            .map_err(|e| ImageError::Format {
                path: name.clone(),
                message: e.to_string(),
            })?;
        Ok(bytes)
    }

    /// Decodes an in-memory file; `name` supplies the extension and the
    /// error messages. The image is held against the default memory
    /// budget.
    pub fn read_from_bytes(
        bytes: &[u8],
        name: &str,
        encoding: Option<ColorEncoding>,
    ) -> Result<ImageAndMetadata, ImageError> {
        Self::read_from_bytes_within(bytes, name, encoding, &MemoryBudget::default())
    }

    /// [`read_from_bytes`](Self::read_from_bytes), charging the decoded
    /// image to `budget` (the charge stays with the image; see
    /// [`Image::bytes_used`]).
    pub fn read_from_bytes_within(
        bytes: &[u8],
        name: &str,
        encoding: Option<ColorEncoding>,
        budget: &MemoryBudget,
    ) -> Result<ImageAndMetadata, ImageError> {
        let enc = encoding.unwrap_or(ColorEncoding::SRGB);
        let mut claim = Claim { budget, charged: 0 };
        let r = match extension(name).as_str() {
            "exr" => exr_io::read(bytes, &mut claim),
            "png" => png_io::read(bytes, enc, &mut claim),
            "pfm" => pfm::read(bytes, &mut claim),
            "hdr" => hdr::read(bytes, &mut claim),
            "tga" => tga::read(bytes, enc, &mut claim),
            "qoi" => qoi::read(bytes, enc, &mut claim),
            e => Err(format!(
                "no support for reading images with extension \"{e}\""
            )),
        };
        // What stays charged is what the image holds.
        let r = r.and_then(|im| claim.settle(im.image.bytes_used() as u64).map(|()| im));
        if r.is_err() {
            budget.release(claim.charged);
        }
        r.map_err(|message| ImageError::Format {
            path: name.to_string(),
            message,
        })
    }

    /// Writes the image to a file chosen by extension: exr, pfm, png, qoi.
    /// The file is written beside its target under a temporary name and
    /// renamed into place, so a failed or interrupted write leaves any
    /// earlier image of that name as it was.
    pub fn write(
        &self,
        path: impl AsRef<Path>,
        metadata: &ImageMetadata,
    ) -> Result<(), ImageError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let bytes = self.encode(&name, metadata)?;
        write_atomically(path, &bytes).map_err(|source| ImageError::Io { path: name, source })
    }

    /// Encodes the image in the format `name`'s extension names.
    pub fn encode(&self, name: &str, metadata: &ImageMetadata) -> Result<Vec<u8>, ImageError> {
        let fail = |message: String| ImageError::Format {
            path: name.to_string(),
            message,
        };
        if let Some(b) = metadata.pixel_bounds {
            if b.area() != self.resolution.x as i64 * self.resolution.y as i64 {
                return Err(fail(
                    "metadata pixel bounds do not match the image resolution".into(),
                ));
            }
        }
        let ext = extension(name);
        if ext == "exr" {
            return exr_io::write(self, metadata).map_err(fail);
        }
        let image = self.canonical_for_ldr(ext == "pfm").map_err(fail)?;
        match ext.as_str() {
            "pfm" => pfm::write(&image),
            "png" => png_io::write(&image),
            "qoi" => qoi::write(&image),
            e => Err(format!(
                "no support for writing images with extension \"{e}\""
            )),
        }
        .map_err(fail)
    }

    /// Channels reordered for formats without channel names: Y, RGB or RGBA (alpha
    /// dropped when `drop_alpha`).
    fn canonical_for_ldr(&self, drop_alpha: bool) -> FmtResult<Image> {
        let nc = self.n_channels();
        if nc == 1 {
            return Ok(self.clone());
        }
        if nc == 4 || nc == 3 {
            if nc == 4 && !drop_alpha {
                if let Some(d) = self.get_channel_desc(&["R", "G", "B", "A"]) {
                    return Ok(self.select_channels(&d));
                }
            }
            if let Some(d) = self.get_channel_desc(&["R", "G", "B"]) {
                return Ok(self.select_channels(&d));
            }
            if nc == 3 {
                // pbrt-v4 writes unnamed 3-channel images as they are.
                return Ok(self.clone());
            }
            return Err("unable to write a 4-channel image that is not RGBA".into());
        }
        Err(format!(
            "unable to write an image with {nc} channels in this format"
        ))
    }
}

/// Little helper: a reader over bytes that reports truncation as an error.
pub(crate) struct ByteReader<'a> {
    pub data: &'a [u8],
    pub pos: usize,
}

impl<'a> ByteReader<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        ByteReader { data, pos: 0 }
    }
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
    pub fn u8(&mut self) -> FmtResult<u8> {
        let b = *self.data.get(self.pos).ok_or("premature end of file")?;
        self.pos += 1;
        Ok(b)
    }
    pub fn bytes(&mut self, n: usize) -> FmtResult<&'a [u8]> {
        if self.remaining() < n {
            return Err("premature end of file".into());
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    pub fn u16_le(&mut self) -> FmtResult<u16> {
        let b = self.bytes(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
}

/// What a format reader charges the image it decodes to: once the header
/// is read, and before any pixel is, [`image`](Claim::image) holds the
/// size the header implies against the memory budget.
pub(crate) struct Claim<'a> {
    budget: &'a MemoryBudget,
    /// Bytes charged so far.
    charged: u64,
}

impl Claim<'_> {
    /// Charges a decoded image of `image` bytes, after checking that
    /// `scratch` bytes more (buffers the decoder drops before it returns)
    /// fit beside it.
    pub fn image(&mut self, image: u64, scratch: u64) -> FmtResult<()> {
        let what = "this image";
        self.budget
            .check(image.saturating_add(scratch), what)
            .map_err(|e| e.to_string())?;
        self.budget.charge(image, what).map_err(|e| e.to_string())?;
        self.charged += image;
        Ok(())
    }

    /// Makes the charge `held` bytes, what the decoded image holds.
    fn settle(&mut self, held: u64) -> FmtResult<()> {
        if held > self.charged {
            self.image(held - self.charged, 0)
        } else {
            self.budget.release(self.charged - held);
            self.charged = held;
            Ok(())
        }
    }
}

/// Largest pixel count a reader will accept (about 1.07 G pixels), so that a corrupt
/// header cannot request absurd allocations.
pub(crate) const MAX_PIXELS: u64 = 1 << 30;

/// Checks a resolution read from a file.
pub(crate) fn check_resolution(w: i64, h: i64) -> FmtResult<Point2i> {
    if w <= 0 || h <= 0 || w > i32::MAX as i64 || h > i32::MAX as i64 {
        return Err(format!("invalid resolution {w}x{h}"));
    }
    if (w as u64) * (h as u64) > MAX_PIXELS {
        return Err(format!("resolution {w}x{h} is too large"));
    }
    Ok(Point2i {
        x: w as i32,
        y: h as i32,
    })
}

#[cfg(test)]
mod tests {
    use super::write_atomically;
    use std::path::{Path, PathBuf};

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rpbrt-io-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Every directory entry's name, sorted.
    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[cfg(unix)]
    #[test]
    fn output_temp_file_does_not_follow_planted_symlink() {
        // The old scheme's temp name was `.<name>.<pid>.tmp`; a link planted
        // there must not redirect the write onto the victim.
        let d = temp_dir("planted");
        let victim = d.join("victim.txt");
        std::fs::write(&victim, b"precious").unwrap();
        let planted = d.join(format!(".x.exr.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_atomically(&d.join("x.exr"), b"image").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        assert_eq!(std::fs::read(d.join("x.exr")).unwrap(), b"image");
        assert!(std::fs::symlink_metadata(&planted)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(
            entries(&d),
            [
                planted.file_name().unwrap().to_str().unwrap(),
                "victim.txt",
                "x.exr"
            ]
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn output_through_symlink_keeps_the_link_and_updates_its_target() {
        let d = temp_dir("link");
        std::fs::create_dir(d.join("real")).unwrap();
        std::fs::write(d.join("real/out.exr"), b"old").unwrap();
        // A relative link, resolved against the link's own directory.
        std::os::unix::fs::symlink("real/out.exr", d.join("out.exr")).unwrap();
        write_atomically(&d.join("out.exr"), b"new").unwrap();
        assert!(std::fs::symlink_metadata(d.join("out.exr"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(d.join("real/out.exr")).unwrap(), b"new");
        assert_eq!(entries(&d), ["out.exr", "real"]);
        assert_eq!(entries(&d.join("real")), ["out.exr"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn output_replacing_a_private_file_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let d = temp_dir("mode");
        let p = d.join("private.exr");
        std::fs::write(&p, b"old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_atomically(&p, b"new").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert_eq!(entries(&d), ["private.exr"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn output_write_failure_leaves_no_temp_file() {
        let d = temp_dir("fail");
        // Renaming a file over a non-empty directory fails after the temp
        // file was written; it must be cleaned up.
        std::fs::create_dir_all(d.join("out.exr/inside")).unwrap();
        assert!(write_atomically(&d.join("out.exr"), b"x").is_err());
        assert_eq!(entries(&d), ["out.exr"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn output_check_writable_probes_the_directory() {
        let d = temp_dir("probe");
        assert!(super::check_writable(&d.join("out.exr")).is_ok());
        assert!(super::check_writable(&d.join("missing/out.exr")).is_err());
        assert!(super::check_writable(&d).is_err());
        // The probe leaves nothing behind.
        assert!(entries(&d).is_empty());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn output_symlink_loop_is_an_error() {
        let d = temp_dir("loop");
        std::os::unix::fs::symlink("b", d.join("a")).unwrap();
        std::os::unix::fs::symlink("a", d.join("b")).unwrap();
        assert!(write_atomically(&d.join("a"), b"x").is_err());
        assert_eq!(entries(&d), ["a", "b"]);
        let _ = std::fs::remove_dir_all(&d);
    }
}
