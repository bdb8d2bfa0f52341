//! MIP maps and texture filtering: point, bilinear, trilinear and EWA lookups (pbrt-v4
//! `util/mipmap.h`, `util/mipmap.cpp`; book section 10.4.3 "MIP Maps" and 10.4.4
//! "Elliptically Weighted Averaging"), plus a cache so each texture file is read once.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use rpbrt_geometry::{Point2f, Point2i, Vector2f};

use super::tiled::{pyramid_file_name, write_pyramid, TileCache, TiledPyramid};
use super::{
    bilerp4, remap_pixel_coords, ColorEncoding, Image, ImageError, PixelFormat, WrapMode,
    WrapMode2D,
};
use rpbrt_parser::MemoryBudget;

/// How MIP-map lookups filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterFunction {
    /// Nearest texel at the chosen level.
    Point,
    /// Bilinear interpolation at the chosen level.
    Bilinear,
    /// Interpolation between bilinear lookups at two levels.
    Trilinear,
    /// Elliptically weighted average with a Gaussian.
    EWA,
}

impl FilterFunction {
    /// Parses pbrt-v4's names: "point", "bilinear", "trilinear", "ewa" / "EWA".
    pub fn parse(s: &str) -> Option<FilterFunction> {
        match s {
            "point" => Some(FilterFunction::Point),
            "bilinear" => Some(FilterFunction::Bilinear),
            "trilinear" => Some(FilterFunction::Trilinear),
            "ewa" | "EWA" => Some(FilterFunction::EWA),
            _ => None,
        }
    }
}

/// Filter choice and the anisotropy limit for EWA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MIPMapFilterOptions {
    /// The filter.
    pub filter: FilterFunction,
    /// Largest ratio of the ellipse axes; longer ellipses are widened.
    pub max_anisotropy: f32,
}

impl Default for MIPMapFilterOptions {
    fn default() -> Self {
        MIPMapFilterOptions {
            filter: FilterFunction::EWA,
            max_anisotropy: 8.0,
        }
    }
}

/// Gaussian weights exp(-2 r^2) - exp(-2) sampled at r^2 = i / 127 (pbrt-v4's
/// `MIPFilterLUT`), computed once.
fn ewa_weights() -> &'static [f32; 128] {
    static LUT: std::sync::OnceLock<[f32; 128]> = std::sync::OnceLock::new();
    LUT.get_or_init(|| {
        let mut t = [0.0f32; 128];
        for (i, w) in t.iter_mut().enumerate() {
            let r2 = i as f64 / 127.0;
            *w = ((-2.0 * r2).exp() - (-2.0f64).exp()) as f32;
        }
        t
    })
}

/// Values a MIP map can return: a float or an RGB triple.
trait MipValue: Copy {
    fn zero() -> Self;
    fn add(self, o: Self) -> Self;
    fn scale(self, s: f32) -> Self;
    fn texel(m: &MIPMap, level: usize, st: Point2i) -> Self;
    fn bilerp(m: &MIPMap, level: usize, st: Point2f) -> Self;
}

impl MipValue for f32 {
    fn zero() -> Self {
        0.0
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn scale(self, s: f32) -> Self {
        self * s
    }
    fn texel(m: &MIPMap, level: usize, st: Point2i) -> Self {
        if let Some(t) = &m.tiled {
            let mut v = [0.0; 4];
            m.tiled_texel(t, level, st, &mut v[..1]);
            return v[0];
        }
        m.pyramid[level].get_channel(st, 0, m.wrap2d())
    }
    fn bilerp(m: &MIPMap, level: usize, st: Point2f) -> Self {
        if let Some(t) = &m.tiled {
            let v = m.tiled_bilerp(t, level, st);
            return match t.n_channels() {
                3 => v[..3].iter().sum::<f32>() / 3.0,
                4 => v[3],
                _ => v[0],
            };
        }
        let im = &m.pyramid[level];
        let w = m.wrap2d();
        match im.n_channels() {
            3 => {
                // The three channels' texels found once (the same values
                // as three `bilerp_channel` calls).
                let mut v = [0.0; 3];
                im.bilerp_channels_into(st, w, &mut v);
                v.iter().sum::<f32>() / 3.0
            }
            4 => im.bilerp_channel(st, 3, w),
            _ => im.bilerp_channel(st, 0, w),
        }
    }
}

impl MipValue for [f32; 3] {
    fn zero() -> Self {
        [0.0; 3]
    }
    fn add(self, o: Self) -> Self {
        [self[0] + o[0], self[1] + o[1], self[2] + o[2]]
    }
    fn scale(self, s: f32) -> Self {
        [self[0] * s, self[1] * s, self[2] * s]
    }
    fn texel(m: &MIPMap, level: usize, st: Point2i) -> Self {
        if let Some(t) = &m.tiled {
            let mut v = [0.0; 4];
            let n = t.n_channels().min(3);
            m.tiled_texel(t, level, st, &mut v[..n]);
            return if n >= 3 {
                [v[0], v[1], v[2]]
            } else {
                [v[0]; 3]
            };
        }
        let im = &m.pyramid[level];
        let w = m.wrap2d();
        if im.n_channels() >= 3 {
            [
                im.get_channel(st, 0, w),
                im.get_channel(st, 1, w),
                im.get_channel(st, 2, w),
            ]
        } else {
            let v = im.get_channel(st, 0, w);
            [v; 3]
        }
    }
    fn bilerp(m: &MIPMap, level: usize, st: Point2f) -> Self {
        if let Some(t) = &m.tiled {
            let v = m.tiled_bilerp(t, level, st);
            return if t.n_channels() >= 3 {
                [v[0], v[1], v[2]]
            } else {
                [v[0]; 3]
            };
        }
        let im = &m.pyramid[level];
        let w = m.wrap2d();
        if im.n_channels() >= 3 {
            // The four texels found once for the three channels (the same
            // values as three `bilerp_channel` calls).
            let mut v = [0.0; 3];
            im.bilerp_channels_into(st, w, &mut v);
            v
        } else {
            let v = im.bilerp_channel(st, 0, w);
            [v; 3]
        }
    }
}

#[inline]
fn lerp_v<T: MipValue>(t: f32, a: T, b: T) -> T {
    a.scale(1.0 - t).add(b.scale(t))
}

/// An image pyramid with filtered lookups.
#[derive(Clone, Debug)]
pub struct MIPMap {
    /// The levels, in memory (empty when they are tiled).
    pyramid: Vec<Image>,
    /// The levels, tiled on disk behind the texture cache.
    tiled: Option<Arc<TiledPyramid>>,
    color_space: String,
    wrap_mode: WrapMode,
    options: MIPMapFilterOptions,
}

impl MIPMap {
    /// Builds the pyramid of `image` (see [`Image::generate_pyramid`]).
    pub fn new(
        image: Image,
        color_space: &str,
        wrap_mode: WrapMode,
        options: MIPMapFilterOptions,
    ) -> MIPMap {
        MIPMap {
            pyramid: image.into_pyramid(wrap_mode.into()),
            tiled: None,
            color_space: color_space.to_string(),
            wrap_mode,
            options,
        }
    }

    /// The memory the pyramid of an image of resolution `res` with `nc`
    /// channels in `format` takes, and what building it needs for a
    /// moment besides (the finest level in floats), in bytes.
    pub fn memory_bytes(res: Point2i, nc: usize, format: PixelFormat) -> (u64, u64) {
        let up = |v: i32| (v.max(1) as u32).next_power_of_two() as u64;
        let samples = (up(res.x) * up(res.y)).saturating_mul(nc as u64);
        let size = match format {
            PixelFormat::U256 => 1,
            PixelFormat::Half => 2,
            PixelFormat::Float => 4,
        };
        // The levels below the finest add a third.
        let pyramid = samples.saturating_mul(size) / 3 * 4;
        (pyramid, samples.saturating_mul(4))
    }

    /// Reads an image file and builds its MIP map. Multi-channel images are reduced to
    /// R, G, B (and A unless alpha is 1 everywhere), as pbrt-v4 does. The
    /// image and the map are held against the default memory budget.
    pub fn from_file(
        path: impl AsRef<Path>,
        options: MIPMapFilterOptions,
        wrap_mode: WrapMode,
        encoding: ColorEncoding,
    ) -> Result<MIPMap, ImageError> {
        Self::from_file_within(path, options, wrap_mode, encoding, &MemoryBudget::default())
    }

    /// [`from_file`](Self::from_file), charging the image and then its
    /// pyramid (which replaces it) to `budget`.
    pub fn from_file_within(
        path: impl AsRef<Path>,
        options: MIPMapFilterOptions,
        wrap_mode: WrapMode,
        encoding: ColorEncoding,
        budget: &MemoryBudget,
    ) -> Result<MIPMap, ImageError> {
        let path = path.as_ref();
        let read = Image::read_within(path, Some(encoding), budget)?;
        let read_bytes = read.image.bytes_used() as u64;
        let result = Self::from_read(path, read, options, wrap_mode, budget);
        budget.release(read_bytes);
        result
    }

    fn from_read(
        path: &Path,
        read: super::ImageAndMetadata,
        options: MIPMapFilterOptions,
        wrap_mode: WrapMode,
        budget: &MemoryBudget,
    ) -> Result<MIPMap, ImageError> {
        let image = texture_channels(path, read.image)?;
        Self::check_room(path, &image, budget, true)?;
        Ok(MIPMap::new(
            image,
            read.metadata.color_space_name(),
            wrap_mode,
            options,
        ))
    }

    /// Checks that `budget` has room for `image`'s pyramid and the scratch
    /// building it takes, and charges it for the pyramid if `charge`.
    fn check_room(
        path: &Path,
        image: &Image,
        budget: &MemoryBudget,
        charge: bool,
    ) -> Result<(), ImageError> {
        let (pyramid, scratch) =
            Self::memory_bytes(image.resolution(), image.n_channels(), image.format());
        let what = "this texture's MIP map";
        budget
            .check(pyramid.saturating_add(scratch), what)
            .and_then(|()| {
                if charge {
                    budget.charge(pyramid, what)
                } else {
                    Ok(())
                }
            })
            .map_err(|e| ImageError::Format {
                path: path.display().to_string(),
                message: e.to_string(),
            })
    }

    /// [`MIPMap::from_file_within`] behind the texture cache `tiles`: the
    /// pyramid file of the image's bytes from the cache folder, converted
    /// and written there first when it is missing or not whole. Where the
    /// folder cannot be written, the levels stay in memory (the cache warns
    /// once).
    pub fn from_file_tiled(
        path: &Path,
        options: MIPMapFilterOptions,
        wrap_mode: WrapMode,
        encoding: ColorEncoding,
        budget: &MemoryBudget,
        tiles: &Arc<TileCache>,
    ) -> Result<MIPMap, ImageError> {
        let bytes = Image::file_bytes_within(path, budget)?;
        let file_len = bytes.len() as u64;
        let name = pyramid_file_name(&bytes, encoding, wrap_mode as u8);
        let cached = tiles.dir().join(name);
        let tiled = |t: TiledPyramid| MIPMap {
            pyramid: Vec::new(),
            color_space: t.color_space.clone(),
            tiled: Some(Arc::new(t)),
            wrap_mode,
            options,
        };
        if let Ok(Some(t)) = TiledPyramid::open(&cached, encoding, tiles) {
            budget.release(file_len);
            tiles.count_reused();
            return Ok(tiled(t));
        }
        let read = Image::read_from_bytes_within(
            &bytes,
            &Image::format_name(path),
            Some(encoding),
            budget,
        );
        drop(bytes);
        budget.release(file_len);
        let read = read?;
        let read_bytes = read.image.bytes_used() as u64;
        let color_space = read.metadata.color_space_name().to_string();
        let image = texture_channels(path, read.image)?;
        let room = Self::check_room(path, &image, budget, false);
        budget.release(read_bytes);
        room?;
        let levels = image.into_pyramid(wrap_mode.into());
        let written = std::fs::create_dir_all(tiles.dir())
            .and_then(|()| write_pyramid(&cached, &levels, &color_space))
            .and_then(|()| {
                TiledPyramid::open(&cached, encoding, tiles)?.ok_or_else(|| {
                    std::io::Error::other("the file written does not read back whole")
                })
            });
        match written {
            Ok(t) => {
                tiles.count_converted();
                Ok(tiled(t))
            }
            Err(e) => {
                tiles.fall_back(path, &e.to_string());
                let bytes: u64 = levels.iter().map(|l| l.bytes_used() as u64).sum();
                budget
                    .charge(bytes, "this texture's MIP map")
                    .map_err(|e| ImageError::Format {
                        path: path.display().to_string(),
                        message: e.to_string(),
                    })?;
                Ok(MIPMap {
                    pyramid: levels,
                    tiled: None,
                    color_space,
                    wrap_mode,
                    options,
                })
            }
        }
    }

    fn wrap2d(&self) -> WrapMode2D {
        self.wrap_mode.into()
    }
    /// Number of levels (finest is 0).
    pub fn levels(&self) -> usize {
        match &self.tiled {
            Some(t) => t.levels(),
            None => self.pyramid.len(),
        }
    }
    /// Resolution of a level.
    pub fn level_resolution(&self, level: usize) -> Point2i {
        match &self.tiled {
            Some(t) => t.level_resolution(level),
            None => self.pyramid[level].resolution(),
        }
    }
    /// The image of a level, when the levels are in memory (not behind the
    /// texture cache).
    pub fn level(&self, level: usize) -> Option<&Image> {
        self.pyramid.get(level)
    }
    /// Whether the levels are tiled behind the texture cache.
    pub fn is_tiled(&self) -> bool {
        self.tiled.is_some()
    }

    /// Texel `st` of a tiled level, remapped by the wrap mode (zero outside
    /// with `Black`), as `Image::get_channel` reads it for each channel.
    fn tiled_texel(&self, t: &TiledPyramid, level: usize, st: Point2i, out: &mut [f32]) {
        match remap_pixel_coords(st, t.level_resolution(level), self.wrap2d()) {
            Some(p) => t.texel_into(level, p, out),
            None => out.fill(0.0),
        }
    }

    /// Bilinear lookup of every channel of a tiled level (what
    /// `Image::bilerp_channel` gives for each).
    fn tiled_bilerp(&self, t: &TiledPyramid, level: usize, st: Point2f) -> [f32; 4] {
        let res = t.level_resolution(level);
        let x = st.x * res.x as f32 - 0.5;
        let y = st.y * res.y as f32 - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (dx, dy) = (x - xf, y - yf);
        let (xi, yi) = (xf as i32, yf as i32);
        let nc = t.n_channels().min(4);
        let mut corners = [[0.0f32; 4]; 4];
        for (k, (ox, oy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
            let p = Point2i {
                x: xi + ox,
                y: yi + oy,
            };
            self.tiled_texel(t, level, p, &mut corners[k][..nc]);
        }
        std::array::from_fn(|c| {
            bilerp4(
                dx,
                dy,
                [corners[0][c], corners[1][c], corners[2][c], corners[3][c]],
            )
        })
    }
    /// Name of the RGB colour space of the texels.
    pub fn color_space(&self) -> &str {
        &self.color_space
    }
    /// The wrap mode.
    pub fn wrap_mode(&self) -> WrapMode {
        self.wrap_mode
    }
    /// The filter options.
    pub fn options(&self) -> MIPMapFilterOptions {
        self.options
    }
    /// Bytes of pixel storage over all levels in memory.
    pub fn total_bytes_used(&self) -> usize {
        self.pyramid.iter().map(|i| i.bytes_used()).sum()
    }

    /// Float texel (first channel).
    pub fn texel_float(&self, level: usize, st: Point2i) -> f32 {
        f32::texel(self, level, st)
    }
    /// RGB texel (grey images replicated).
    pub fn texel_rgb(&self, level: usize, st: Point2i) -> [f32; 3] {
        <[f32; 3]>::texel(self, level, st)
    }
    /// Bilinear float lookup: one channel as is, RGB averaged, RGBA gives alpha.
    pub fn bilerp_float(&self, level: usize, st: Point2f) -> f32 {
        f32::bilerp(self, level, st)
    }
    /// Bilinear RGB lookup.
    pub fn bilerp_rgb(&self, level: usize, st: Point2f) -> [f32; 3] {
        <[f32; 3]>::bilerp(self, level, st)
    }
    /// Filtered float lookup over the footprint spanned by `dst0` and `dst1`.
    pub fn filter_float(&self, st: Point2f, dst0: Vector2f, dst1: Vector2f) -> f32 {
        self.filter::<f32>(st, dst0, dst1)
    }
    /// Filtered RGB lookup over the footprint spanned by `dst0` and `dst1`.
    pub fn filter_rgb(&self, st: Point2f, dst0: Vector2f, dst1: Vector2f) -> [f32; 3] {
        self.filter::<[f32; 3]>(st, dst0, dst1)
    }

    /// The fractional level whose texel spacing matches the footprint
    /// spanned by `dst0` and `dst1`, for the filters other than EWA.
    #[inline]
    fn footprint_level(&self, dst0: Vector2f, dst1: Vector2f) -> f32 {
        let width = 2.0
            * dst0
                .x
                .abs()
                .max(dst0.y.abs())
                .max(dst1.x.abs())
                .max(dst1.y.abs());
        (self.levels() - 1) as f32 + width.max(1e-8).log2()
    }

    /// Starts loading the texels that a filtered lookup at `st` over the
    /// footprint spanned by `dst0` and `dst1` reads at its finer level,
    /// for a lookup soon after (bilinear and trilinear lookups of levels
    /// in memory; nothing otherwise): a hint with no effect on results.
    pub fn prefetch(&self, st: Point2f, dst0: Vector2f, dst1: Vector2f) {
        if self.tiled.is_some()
            || !matches!(
                self.options.filter,
                FilterFunction::Bilinear | FilterFunction::Trilinear
            )
        {
            return;
        }
        let level = self.footprint_level(dst0, dst1);
        if level < (self.levels() - 1) as f32 {
            let ilevel = level.floor().max(0.0) as usize;
            self.pyramid[ilevel].prefetch_bilerp(st, self.wrap2d());
        }
    }

    fn filter<T: MipValue>(&self, st: Point2f, mut dst0: Vector2f, mut dst1: Vector2f) -> T {
        let n_levels = self.levels();
        if self.options.filter != FilterFunction::EWA {
            // Level whose texel spacing matches the filter width; very wide filters use
            // the single top texel.
            let level = self.footprint_level(dst0, dst1);
            if level >= (n_levels - 1) as f32 {
                return T::texel(self, n_levels - 1, Point2i { x: 0, y: 0 });
            }
            let ilevel = level.floor().max(0.0) as usize;
            return match self.options.filter {
                FilterFunction::Point => {
                    let r = self.level_resolution(ilevel);
                    let sti = Point2i {
                        x: (st.x * r.x as f32 - 0.5).round() as i32,
                        y: (st.y * r.y as f32 - 0.5).round() as i32,
                    };
                    T::texel(self, ilevel, sti)
                }
                FilterFunction::Bilinear => T::bilerp(self, ilevel, st),
                _ => {
                    if ilevel == 0 {
                        T::bilerp(self, 0, st)
                    } else {
                        lerp_v(
                            level - ilevel as f32,
                            T::bilerp(self, ilevel, st),
                            T::bilerp(self, ilevel + 1, st),
                        )
                    }
                }
            };
        }
        // EWA: the longer axis first, then limit the eccentricity.
        let len2 = |v: Vector2f| v.x * v.x + v.y * v.y;
        if len2(dst0) < len2(dst1) {
            std::mem::swap(&mut dst0, &mut dst1);
        }
        let longer = len2(dst0).sqrt();
        let mut shorter = len2(dst1).sqrt();
        if shorter * self.options.max_anisotropy < longer && shorter > 0.0 {
            let scale = longer / (shorter * self.options.max_anisotropy);
            dst1 = Vector2f {
                x: dst1.x * scale,
                y: dst1.y * scale,
            };
            shorter *= scale;
        }
        if shorter == 0.0 {
            return T::bilerp(self, 0, st);
        }
        let lod = ((n_levels - 1) as f32 + shorter.log2()).max(0.0);
        let ilod = lod.floor();
        lerp_v(
            lod - ilod,
            self.ewa::<T>(ilod as usize, st, dst0, dst1),
            self.ewa::<T>(ilod as usize + 1, st, dst0, dst1),
        )
    }

    fn ewa<T: MipValue>(&self, level: usize, st: Point2f, dst0: Vector2f, dst1: Vector2f) -> T {
        if level >= self.levels() {
            return T::texel(self, self.levels() - 1, Point2i { x: 0, y: 0 });
        }
        let r = self.level_resolution(level);
        let (rx, ry) = (r.x as f32, r.y as f32);
        let s = st.x * rx - 0.5;
        let t = st.y * ry - 0.5;
        let (d0x, d0y, d1x, d1y) = (dst0.x * rx, dst0.y * ry, dst1.x * rx, dst1.y * ry);
        // Implicit ellipse A s^2 + B s t + C t^2 = 1, widened by one texel.
        let mut a = d0y * d0y + d1y * d1y + 1.0;
        let mut b = -2.0 * (d0x * d0y + d1x * d1y);
        let mut c = d0x * d0x + d1x * d1x + 1.0;
        let inv_f = 1.0 / (a * c - b * b * 0.25);
        a *= inv_f;
        b *= inv_f;
        c *= inv_f;
        let det = -b * b + 4.0 * a * c;
        let inv_det = 1.0 / det;
        let u_sqrt = (det * c).max(0.0).sqrt();
        let v_sqrt = (a * det).max(0.0).sqrt();
        let s0 = (s - 2.0 * inv_det * u_sqrt).ceil() as i32;
        let s1 = (s + 2.0 * inv_det * u_sqrt).floor() as i32;
        let t0 = (t - 2.0 * inv_det * v_sqrt).ceil() as i32;
        let t1 = (t + 2.0 * inv_det * v_sqrt).floor() as i32;
        let lut = ewa_weights();
        let mut sum = T::zero();
        let mut sum_w = 0.0f32;
        for it in t0..=t1 {
            let tt = it as f32 - t;
            for is in s0..=s1 {
                let ss = is as f32 - s;
                let r2 = a * ss * ss + b * ss * tt + c * tt * tt;
                if r2 < 1.0 {
                    let idx = ((r2 * 128.0) as usize).min(127);
                    let w = lut[idx];
                    sum = sum.add(T::texel(self, level, Point2i { x: is, y: it }).scale(w));
                    sum_w += w;
                }
            }
        }
        sum.scale(1.0 / sum_w)
    }
}

/// A texture's channels of `image` (read from `path`): R, G, B (and A
/// unless alpha is 1 everywhere) of a multi-channel image, as pbrt-v4
/// reduces them; a one-channel image as it is.
fn texture_channels(path: &Path, image: Image) -> Result<Image, ImageError> {
    if image.n_channels() == 1 {
        return Ok(image);
    }
    let rgba = image.get_channel_desc(&["R", "G", "B", "A"]);
    let rgb = image.get_channel_desc(&["R", "G", "B"]);
    Ok(match (rgba, rgb) {
        (Some(rgba), Some(rgb)) => {
            let nc = image.n_channels();
            let a = rgba.offset[3];
            let n = image.data_len();
            let all_one = (a..n).step_by(nc).all(|i| image.value_at(i) == 1.0);
            image.into_channels(if all_one { &rgb } else { &rgba })
        }
        (None, Some(rgb)) => image.into_channels(&rgb),
        _ => {
            return Err(ImageError::Format {
                path: path.display().to_string(),
                message: "image doesn't have R, G, and B channels".into(),
            })
        }
    })
}

/// Key of a cached MIP map: file, filter, anisotropy (bits), wrap mode, encoding.
type CacheKey = (PathBuf, FilterFunction, u32, WrapMode, (u8, u32));

/// One cache entry, locked while its file loads so concurrent users wait for it.
type CacheSlot = Arc<Mutex<Option<Arc<MIPMap>>>>;

/// MIP maps shared by all textures that use the same file with the same settings
/// (pbrt-v4's texture cache). Different files load in parallel; the same file once.
#[derive(Debug, Default)]
pub struct MIPMapCache {
    map: Mutex<HashMap<CacheKey, CacheSlot>>,
    files_read: AtomicUsize,
    /// What the maps are charged to (`None`: the default budget).
    budget: Option<MemoryBudget>,
    /// The texture cache, when the maps are tiled behind it.
    tiles: Option<Arc<TileCache>>,
}

impl MIPMapCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty cache whose maps are charged to `budget`.
    pub fn with_budget(budget: &MemoryBudget) -> Self {
        MIPMapCache {
            budget: Some(budget.clone()),
            ..Self::default()
        }
    }

    /// The maps from now on go behind the texture cache `tiles`.
    pub fn with_tiles(mut self, tiles: Arc<TileCache>) -> Self {
        self.tiles = Some(tiles);
        self
    }

    /// The MIP map for these settings, reading the file on first use. Failures are not
    /// cached.
    pub fn get_or_load(
        &self,
        path: impl AsRef<Path>,
        options: MIPMapFilterOptions,
        wrap_mode: WrapMode,
        encoding: ColorEncoding,
    ) -> Result<Arc<MIPMap>, ImageError> {
        let path = path.as_ref();
        let key = (
            path.to_path_buf(),
            options.filter,
            options.max_anisotropy.to_bits(),
            wrap_mode,
            encoding.key(),
        );
        let slot = {
            let mut map = self.map.lock().unwrap_or_else(|e| e.into_inner());
            map.entry(key).or_default().clone()
        };
        let mut slot = slot.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(m) = slot.as_ref() {
            return Ok(m.clone());
        }
        self.files_read.fetch_add(1, Ordering::Relaxed);
        let default_budget;
        let budget = match &self.budget {
            Some(b) => b,
            None => {
                default_budget = MemoryBudget::default();
                &default_budget
            }
        };
        let m = match &self.tiles {
            Some(t) => MIPMap::from_file_tiled(path, options, wrap_mode, encoding, budget, t)?,
            None => MIPMap::from_file_within(path, options, wrap_mode, encoding, budget)?,
        };
        let m = Arc::new(m);
        *slot = Some(m.clone());
        Ok(m)
    }

    /// How many times a file has been read (for tests and statistics).
    pub fn files_read(&self) -> usize {
        self.files_read.load(Ordering::Relaxed)
    }
}
