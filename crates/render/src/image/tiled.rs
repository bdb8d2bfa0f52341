//! The texture cache (`--texture-cache-mb`; the idea of OpenImageIO's
//! `TextureSystem`): image textures' MIP pyramids kept on disk in tiles
//! and read tile by tile as lookups need them, through a cache of bounded
//! size, so that a scene's textures may be larger than memory.
//!
//! Each image file is converted once into a tiled pyramid file (the levels
//! [`Image::into_pyramid`] builds, each cut into [`TILE`]×[`TILE`]-texel
//! tiles stored as the levels store them: 8-bit texels stay 8-bit) in the
//! cache folder, named by a hash of the image file's bytes and the settings
//! the pyramid depends on. Later runs, and the farm's workers sharing the
//! folder, reuse it; an image whose bytes changed gets a new name, so it
//! is never served stale. A pyramid file is checked (header, size and a
//! hash of its tiles) when it is opened and rebuilt when it is not whole.
//!
//! Lookups read the same stored values as the in-memory levels, so the
//! filtered values, and the images, are identical. The cache holds tiles
//! in shards under a clock (second-chance) eviction; a tile larger than a
//! shard's share is read and used without being kept. At most
//! [`OPEN_FILES`] pyramid files are open at once, whatever the number of
//! textures.

use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::hash::Hasher;
use std::io::{BufReader, BufWriter, Read, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use half::f16;
use rpbrt_geometry::Point2i;

use super::{ColorEncoding, Image, PixelData, PixelFormat};

/// Texels along a tile's side.
pub const TILE: usize = 64;
/// Independently locked parts of the cache.
const SHARDS: usize = 16;
/// Pyramid files held open at once (each map's file is opened again when
/// it is needed after others pushed it out), well under the usual limit of
/// 1024 open files per process however many textures a scene has.
const OPEN_FILES: usize = 64;
/// The pyramid files' first bytes (the layout's version is the last).
const MAGIC: &[u8; 8] = b"RPBRTTX1";

/// The cache of tiles, shared by every texture of a scene.
#[derive(Debug)]
pub struct TileCache {
    /// Bytes of tiles kept, at most (over all shards).
    capacity: u64,
    /// Where the pyramid files go.
    dir: PathBuf,
    shards: Vec<Mutex<Shard>>,
    /// The pyramid files open now, by number, oldest first.
    open: Mutex<VecDeque<(u32, Arc<File>)>>,
    next_file: AtomicU32,
    hits: AtomicU64,
    misses: AtomicU64,
    converted: AtomicU64,
    reused: AtomicU64,
    /// The fallback warning, given once.
    warned: AtomicBool,
    warnings: Mutex<Vec<String>>,
}

/// Which tile: the pyramid file's number, the level, the tile's index.
type TileKey = (u32, u32, u32);

#[derive(Debug, Default)]
struct Shard {
    tiles: HashMap<TileKey, (Arc<[u8]>, bool)>,
    /// Keys in insertion order, for the clock.
    order: VecDeque<TileKey>,
    bytes: u64,
}

/// What the cache did, for `--stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TileCacheStats {
    /// The cache's size.
    pub capacity_bytes: u64,
    /// Tile reads the cache answered.
    pub hits: u64,
    /// Tile reads from the pyramid files.
    pub misses: u64,
    /// Image files converted into pyramid files in this run.
    pub converted: u64,
    /// Pyramid files found from an earlier run.
    pub reused: u64,
}

impl TileCache {
    /// A cache of `capacity` bytes whose pyramid files go in `dir`.
    pub fn new(capacity: u64, dir: PathBuf) -> TileCache {
        TileCache {
            capacity,
            dir,
            shards: (0..SHARDS).map(|_| Mutex::default()).collect(),
            open: Mutex::default(),
            next_file: AtomicU32::new(0),
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
            converted: AtomicU64::new(0),
            reused: AtomicU64::new(0),
            warned: AtomicBool::new(false),
            warnings: Mutex::default(),
        }
    }

    /// The default folder: `$XDG_CACHE_HOME/rpbrt/textures`, or
    /// `~/.cache/rpbrt/textures`, or the temporary folder's.
    pub fn default_dir() -> PathBuf {
        let base = std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("HOME")
                    .filter(|v| !v.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache"))
            })
            .unwrap_or_else(std::env::temp_dir);
        base.join("rpbrt").join("textures")
    }

    /// The folder of the pyramid files.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    pub(crate) fn count_converted(&self) {
        self.converted.fetch_add(1, Ordering::Relaxed);
    }

    pub(crate) fn count_reused(&self) {
        self.reused.fetch_add(1, Ordering::Relaxed);
    }

    /// The statistics so far.
    pub fn stats(&self) -> TileCacheStats {
        TileCacheStats {
            capacity_bytes: self.capacity,
            hits: self.hits.load(Ordering::Relaxed),
            misses: self.misses.load(Ordering::Relaxed),
            converted: self.converted.load(Ordering::Relaxed),
            reused: self.reused.load(Ordering::Relaxed),
        }
    }

    /// The warnings raised (at most one: the first fallback to memory).
    pub fn take_warnings(&self) -> Vec<String> {
        std::mem::take(&mut *self.warnings.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// Records that the pyramid of `image` could not be kept on disk
    /// (`why`); only the first such warning is kept.
    pub(crate) fn fall_back(&self, image: &Path, why: &str) {
        if !self.warned.swap(true, Ordering::Relaxed) {
            self.warnings
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(format!(
                    "texture cache folder \"{}\" cannot be used ({why}, for \"{}\"); \
                     image textures are held in memory instead",
                    self.dir.display(),
                    image.display()
                ));
        }
    }

    /// Pyramid file `id` (at `path`), from the open ones or opened now.
    fn file(&self, id: u32, path: &Path) -> std::io::Result<Arc<File>> {
        let mut open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, f)) = open.iter().find(|(i, _)| *i == id) {
            return Ok(f.clone());
        }
        let f = Arc::new(File::open(path)?);
        if open.len() == OPEN_FILES {
            open.pop_front();
        }
        open.push_back((id, f.clone()));
        Ok(f)
    }

    /// How many pyramid files are open now.
    pub fn open_files(&self) -> usize {
        self.open.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    /// The tile `key` of the pyramid file at `path`, `len` bytes at
    /// `offset`, from the cache or read now.
    fn tile(
        &self,
        path: &Path,
        key: TileKey,
        offset: u64,
        len: usize,
    ) -> std::io::Result<Arc<[u8]>> {
        let shard_of = (key.0 as usize)
            .wrapping_mul(31)
            .wrapping_add(key.1 as usize * 7)
            .wrapping_add(key.2 as usize)
            % SHARDS;
        let shard = &self.shards[shard_of];
        {
            let mut s = shard.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((t, referenced)) = s.tiles.get_mut(&key) {
                *referenced = true;
                self.hits.fetch_add(1, Ordering::Relaxed);
                return Ok(t.clone());
            }
        }
        self.misses.fetch_add(1, Ordering::Relaxed);
        let mut buf = vec![0u8; len];
        self.file(key.0, path)?.read_exact_at(&mut buf, offset)?;
        let tile: Arc<[u8]> = buf.into();
        let share = self.capacity / SHARDS as u64;
        if len as u64 <= share {
            let mut s = shard.lock().unwrap_or_else(|e| e.into_inner());
            if !s.tiles.contains_key(&key) {
                while s.bytes + len as u64 > share {
                    let Some(k) = s.order.pop_front() else { break };
                    match s.tiles.get_mut(&k) {
                        Some((_, referenced)) if *referenced => {
                            *referenced = false;
                            s.order.push_back(k);
                        }
                        Some(_) => {
                            if let Some((t, _)) = s.tiles.remove(&k) {
                                s.bytes -= t.len() as u64;
                            }
                        }
                        None => {}
                    }
                }
                s.tiles.insert(key, (tile.clone(), false));
                s.order.push_back(key);
                s.bytes += len as u64;
            }
        }
        Ok(tile)
    }
}

/// The pyramid file's name for an image file with `bytes`, decoded with
/// `encoding` and resampled (when not a power of two) with `wrap_key`.
pub(crate) fn pyramid_file_name(bytes: &[u8], encoding: ColorEncoding, wrap_key: u8) -> String {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    h.write(MAGIC);
    h.write_u64(bytes.len() as u64);
    h.write(bytes);
    let (kind, gamma) = encoding.key();
    h.write_u8(kind);
    h.write_u32(gamma);
    h.write_u8(wrap_key);
    format!("{:016x}.rptx", h.finish())
}

/// One level of a tiled pyramid.
#[derive(Clone, Copy, Debug)]
struct TiledLevel {
    res: Point2i,
    tiles_x: usize,
    /// Where its first tile starts in the file.
    offset: u64,
}

/// A pyramid file opened for lookups.
#[derive(Debug)]
pub struct TiledPyramid {
    id: u32,
    /// The pyramid file (opened through the cache's open files).
    path: PathBuf,
    levels: Vec<TiledLevel>,
    nc: usize,
    format: PixelFormat,
    encoding: ColorEncoding,
    cache: Arc<TileCache>,
    /// The colour space of the image's RGB values.
    pub(crate) color_space: String,
}

/// Bytes of one stored value.
fn value_bytes(format: PixelFormat) -> usize {
    match format {
        PixelFormat::U256 => 1,
        PixelFormat::Half => 2,
        PixelFormat::Float => 4,
    }
}

/// The levels' places in a file whose tiles start at `start`, and where the
/// tiles end.
fn layout(resolutions: &[Point2i], tile_bytes: u64, start: u64) -> (Vec<TiledLevel>, u64) {
    let mut offset = start;
    let levels = resolutions
        .iter()
        .map(|&res| {
            let tiles_x = (res.x as usize).div_ceil(TILE);
            let tiles_y = (res.y as usize).div_ceil(TILE);
            let level = TiledLevel {
                res,
                tiles_x,
                offset,
            };
            offset += (tiles_x * tiles_y) as u64 * tile_bytes;
            level
        })
        .collect();
    (levels, offset)
}

fn format_code(f: PixelFormat) -> u8 {
    match f {
        PixelFormat::U256 => 0,
        PixelFormat::Half => 1,
        PixelFormat::Float => 2,
    }
}

/// The header: magic, format, encoding, channels, colour space, levels'
/// resolutions (little-endian).
fn header(pyramid: &[Image], color_space: &str) -> Vec<u8> {
    let first = &pyramid[0];
    let mut h = MAGIC.to_vec();
    h.push(format_code(first.format()));
    let (kind, gamma) = first.encoding().key();
    h.push(kind);
    h.extend(gamma.to_le_bytes());
    h.extend((first.n_channels() as u32).to_le_bytes());
    h.extend((color_space.len() as u32).to_le_bytes());
    h.extend(color_space.as_bytes());
    h.extend((pyramid.len() as u32).to_le_bytes());
    for level in pyramid {
        h.extend(level.resolution().x.to_le_bytes());
        h.extend(level.resolution().y.to_le_bytes());
    }
    h
}

/// Writes `pyramid` as a tiled pyramid file at `path` (through a
/// temporary file renamed into place, so readers never see half a file).
pub(crate) fn write_pyramid(
    path: &Path,
    pyramid: &[Image],
    color_space: &str,
) -> std::io::Result<()> {
    let first = &pyramid[0];
    let nc = first.n_channels();
    let vb = value_bytes(first.format());
    let tile_bytes = TILE * TILE * nc * vb;
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    let result = (|| {
        let mut w = BufWriter::with_capacity(1 << 20, File::create(&tmp)?);
        w.write_all(&header(pyramid, color_space))?;
        let mut hash = std::collections::hash_map::DefaultHasher::new();
        let mut tile = vec![0u8; tile_bytes];
        for level in pyramid {
            let res = level.resolution();
            let (w_px, h_px) = (res.x as usize, res.y as usize);
            let row_bytes = w_px * nc * vb;
            let data: &[u8] = match &level.data {
                PixelData::U256(v) => v,
                PixelData::Half(v) => bytemuck_f16(v),
                PixelData::Float(v) => bytemuck_f32(v),
            };
            for ty in 0..h_px.div_ceil(TILE) {
                for tx in 0..w_px.div_ceil(TILE) {
                    tile.fill(0);
                    let x0 = tx * TILE;
                    let cols = TILE.min(w_px - x0);
                    for r in 0..TILE.min(h_px - ty * TILE) {
                        let y = ty * TILE + r;
                        let src = &data[y * row_bytes + x0 * nc * vb..][..cols * nc * vb];
                        tile[r * TILE * nc * vb..][..src.len()].copy_from_slice(src);
                    }
                    hash.write(&tile);
                    w.write_all(&tile)?;
                }
            }
        }
        w.write_all(&hash.finish().to_le_bytes())?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The values' bytes in the order `to_le_bytes` gives (little-endian hosts).
fn bytemuck_f16(v: &[f16]) -> &[u8] {
    // SAFETY: f16 is two plain bytes; u8 has no alignment needs.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

fn bytemuck_f32(v: &[f32]) -> &[u8] {
    // SAFETY: f32 is four plain bytes; u8 has no alignment needs.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Reads `n` bytes of the header.
fn take<'a>(h: &mut &'a [u8], n: usize) -> Option<&'a [u8]> {
    if h.len() < n {
        return None;
    }
    let (a, b) = h.split_at(n);
    *h = b;
    Some(a)
}

fn take_u32(h: &mut &[u8]) -> Option<u32> {
    take(h, 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

impl TiledPyramid {
    /// Opens the pyramid file at `path` if it is whole (its header reads,
    /// its size is the header's, its tiles hash to its last eight bytes)
    /// and was made with `encoding`; `Ok(None)` when it must be rebuilt.
    pub(crate) fn open(
        path: &Path,
        encoding: ColorEncoding,
        cache: &Arc<TileCache>,
    ) -> std::io::Result<Option<TiledPyramid>> {
        let mut file = match File::open(path) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(e),
        };
        let len = file.metadata()?.len();
        // The header is at most a few kilobytes (levels ≤ 32).
        let mut head = vec![0u8; (len as usize).min(4096)];
        file.read_exact(&mut head)?;
        let parsed = (|| {
            let mut h: &[u8] = &head;
            if take(&mut h, 8)? != MAGIC {
                return None;
            }
            let format = match take(&mut h, 1)?[0] {
                0 => PixelFormat::U256,
                1 => PixelFormat::Half,
                2 => PixelFormat::Float,
                _ => return None,
            };
            let kind = take(&mut h, 1)?[0];
            let gamma = take_u32(&mut h)?;
            if (kind, gamma) != encoding.key() {
                return None;
            }
            let nc = take_u32(&mut h)? as usize;
            let cs_len = take_u32(&mut h)? as usize;
            let cs = String::from_utf8(take(&mut h, cs_len)?.to_vec()).ok()?;
            let n = take_u32(&mut h)? as usize;
            if !(1..=32).contains(&n) || !(1..=4).contains(&nc) {
                return None;
            }
            let mut res = Vec::with_capacity(n);
            for _ in 0..n {
                let x = take_u32(&mut h)? as i32;
                let y = take_u32(&mut h)? as i32;
                if x <= 0 || y <= 0 || x > 1 << 20 || y > 1 << 20 {
                    return None;
                }
                res.push(Point2i { x, y });
            }
            Some((format, nc, cs, res, head.len() - h.len()))
        })();
        let Some((format, nc, color_space, resolutions, start)) = parsed else {
            return Ok(None);
        };
        let tile_bytes = (TILE * TILE * nc * value_bytes(format)) as u64;
        let (levels, end) = layout(&resolutions, tile_bytes, start as u64);
        if end + 8 != len {
            return Ok(None);
        }
        // The tiles' hash, read in the writer's units.
        let mut r = BufReader::with_capacity(1 << 20, &file);
        std::io::Seek::seek(&mut r, std::io::SeekFrom::Start(start as u64))?;
        let mut hash = std::collections::hash_map::DefaultHasher::new();
        let mut tile = vec![0u8; tile_bytes as usize];
        for _ in 0..(end - start as u64) / tile_bytes {
            r.read_exact(&mut tile)?;
            hash.write(&tile);
        }
        let mut stored = [0u8; 8];
        r.read_exact(&mut stored)?;
        if u64::from_le_bytes(stored) != hash.finish() {
            return Ok(None);
        }
        drop(r);
        Ok(Some(TiledPyramid {
            id: cache.next_file.fetch_add(1, Ordering::Relaxed),
            path: path.to_path_buf(),
            levels,
            nc,
            format,
            encoding,
            cache: cache.clone(),
            color_space,
        }))
    }

    /// Number of levels.
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// A level's resolution.
    pub fn level_resolution(&self, level: usize) -> Point2i {
        self.levels[level].res
    }

    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.nc
    }

    /// The first `out.len()` channels of texel `p` (inside the level) of
    /// `level`, as the in-memory level's `value_at` reads them. A tile that
    /// cannot be read (the file shrank under the render) reads as zero.
    pub fn texel_into(&self, level: usize, p: Point2i, out: &mut [f32]) {
        let l = &self.levels[level];
        let (x, y) = (p.x as usize, p.y as usize);
        let (tx, ty) = (x / TILE, y / TILE);
        let index = ty * l.tiles_x + tx;
        let vb = value_bytes(self.format);
        let tile_bytes = TILE * TILE * self.nc * vb;
        let key = (self.id, level as u32, index as u32);
        let Ok(tile) = self.cache.tile(
            &self.path,
            key,
            l.offset + (index * tile_bytes) as u64,
            tile_bytes,
        ) else {
            out.fill(0.0);
            return;
        };
        let at = ((y % TILE) * TILE + x % TILE) * self.nc * vb;
        for (c, o) in out.iter_mut().enumerate().take(self.nc) {
            let i = at + c * vb;
            *o = match self.format {
                PixelFormat::U256 => self.encoding.to_linear(tile[i]),
                PixelFormat::Half => f16::from_le_bytes([tile[i], tile[i + 1]]).to_f32(),
                PixelFormat::Float => {
                    f32::from_le_bytes([tile[i], tile[i + 1], tile[i + 2], tile[i + 3]])
                }
            };
        }
    }
}
