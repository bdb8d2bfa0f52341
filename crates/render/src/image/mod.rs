//! Images: pixel storage in 8-bit, half or float formats, wrap modes, lookups, format
//! conversion, resampling and MIP pyramids (pbrt-v4 `util/image.h`, `util/image.cpp`;
//! book section 10.4.1 "Image Texture Memory Management" and appendix B.5 "Images").
//!
//! Reading and writing files lives in [`io`]; MIP-mapped filtering in [`mipmap`]; the
//! comparisons and statistics behind `imgtool` in [`ops`]; pbrt-v3 latitude–longitude
//! environment maps to pbrt-v4's equal-area square in [`equiarea`]; the Hosek–Wilkie sky
//! model behind `imgtool makesky` in [`sky`].

pub mod assemble;
mod encoding;
pub mod equiarea;
pub mod io;
pub mod mipmap;
pub mod ops;
mod resample;
pub mod sky;
#[cfg(test)]
mod tests;
pub mod tiled;

use std::fmt;
use std::ops::{Deref, DerefMut};

use half::f16;
use rpbrt_geometry::{Bounds2i, Point2f, Point2i};

pub use encoding::{
    linear_to_srgb, linear_to_srgb8, linear_to_srgb8_exact, srgb8_to_linear, srgb_to_linear,
    ColorEncoding,
};
pub use io::{ImageAndMetadata, ImageError, ImageMetadata};
pub use mipmap::{FilterFunction, MIPMap, MIPMapCache, MIPMapFilterOptions};

/// Storage format of pixel values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PixelFormat {
    /// 8 bits per channel, interpreted through a [`ColorEncoding`].
    U256,
    /// 16-bit IEEE half floats, linear.
    Half,
    /// 32-bit floats, linear.
    Float,
}

impl PixelFormat {
    /// Bytes per channel value.
    pub fn texel_bytes(self) -> usize {
        match self {
            PixelFormat::U256 => 1,
            PixelFormat::Half => 2,
            PixelFormat::Float => 4,
        }
    }
}

impl fmt::Display for PixelFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PixelFormat::U256 => "U256",
            PixelFormat::Half => "Half",
            PixelFormat::Float => "Float",
        })
    }
}

/// What a lookup outside the image returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WrapMode {
    /// Tile the image.
    Repeat,
    /// Zero outside.
    Black,
    /// Extend the edge texels.
    Clamp,
    /// Equal-area octahedral sphere parameterisation: mirror across the edges.
    OctahedralSphere,
}

impl WrapMode {
    /// Parses pbrt-v4's names: "repeat", "black", "clamp", "octahedralsphere".
    pub fn parse(s: &str) -> Option<WrapMode> {
        match s {
            "repeat" => Some(WrapMode::Repeat),
            "black" => Some(WrapMode::Black),
            "clamp" => Some(WrapMode::Clamp),
            "octahedralsphere" => Some(WrapMode::OctahedralSphere),
            _ => None,
        }
    }

    /// The pbrt-v4 name.
    pub fn name(self) -> &'static str {
        match self {
            WrapMode::Repeat => "repeat",
            WrapMode::Black => "black",
            WrapMode::Clamp => "clamp",
            WrapMode::OctahedralSphere => "octahedralsphere",
        }
    }
}

/// A wrap mode per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WrapMode2D {
    /// Modes for x and y.
    pub wrap: [WrapMode; 2],
}

impl WrapMode2D {
    /// Separate modes for x and y.
    pub fn new(x: WrapMode, y: WrapMode) -> Self {
        WrapMode2D { wrap: [x, y] }
    }
}

impl From<WrapMode> for WrapMode2D {
    fn from(w: WrapMode) -> Self {
        WrapMode2D { wrap: [w, w] }
    }
}

/// Maps a pixel coordinate that may lie outside the image to one inside it, or `None`
/// when the wrap mode says the lookup is black (pbrt-v4 `RemapPixelCoords`).
/// Octahedral wrapping applies when the x mode is `OctahedralSphere`.
#[inline]
pub fn remap_pixel_coords(p: Point2i, res: Point2i, wrap: WrapMode2D) -> Option<Point2i> {
    let (mut x, mut y) = (p.x, p.y);
    if wrap.wrap[0] == WrapMode::OctahedralSphere {
        debug_assert!(wrap.wrap[1] == WrapMode::OctahedralSphere);
        if x < 0 {
            x = -x;
            y = res.y - 1 - y;
        } else if x >= res.x {
            x = 2 * res.x - 1 - x;
            y = res.y - 1 - y;
        }
        if y < 0 {
            x = res.x - 1 - x;
            y = -y;
        } else if y >= res.y {
            x = res.x - 1 - x;
            y = 2 * res.y - 1 - y;
        }
        if res.x == 1 {
            x = 0;
        }
        if res.y == 1 {
            y = 0;
        }
        // Far outside (more than one image away) the mirroring does not land inside;
        // clamp so that lookups stay in bounds.
        return Some(Point2i {
            x: x.clamp(0, res.x - 1),
            y: y.clamp(0, res.y - 1),
        });
    }
    let mut c = [x, y];
    let r = [res.x, res.y];
    for i in 0..2 {
        if c[i] >= 0 && c[i] < r[i] {
            continue;
        }
        match wrap.wrap[i] {
            WrapMode::Repeat => c[i] = c[i].rem_euclid(r[i]),
            WrapMode::Clamp | WrapMode::OctahedralSphere => c[i] = c[i].clamp(0, r[i] - 1),
            WrapMode::Black => return None,
        }
    }
    Some(Point2i { x: c[0], y: c[1] })
}

/// Indices of a subset of an image's channels, in a chosen order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ImageChannelDesc {
    /// Channel index in the image for each requested channel.
    pub offset: Vec<usize>,
}

impl ImageChannelDesc {
    /// Number of channels described.
    pub fn len(&self) -> usize {
        self.offset.len()
    }
    /// Whether no channel is described.
    pub fn is_empty(&self) -> bool {
        self.offset.is_empty()
    }
    /// Whether the channels are 0, 1, 2, ... in order.
    pub fn is_identity(&self) -> bool {
        self.offset.iter().enumerate().all(|(i, &o)| i == o)
    }
}

/// Channel values of one pixel; up to four stay inline (pbrt-v4 `ImageChannelValues`).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageChannelValues {
    inline: [f32; 4],
    heap: Vec<f32>,
    len: usize,
}

impl ImageChannelValues {
    /// `n` values, all `v`.
    pub fn new(n: usize, v: f32) -> Self {
        if n <= 4 {
            ImageChannelValues {
                inline: [v; 4],
                heap: Vec::new(),
                len: n,
            }
        } else {
            ImageChannelValues {
                inline: [0.0; 4],
                heap: vec![v; n],
                len: n,
            }
        }
    }
    /// From a slice.
    pub fn from_slice(v: &[f32]) -> Self {
        let mut r = Self::new(v.len(), 0.0);
        r.copy_from_slice(v);
        r
    }
    /// Largest value.
    pub fn max_value(&self) -> f32 {
        self.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }
    /// Mean of the values.
    pub fn average(&self) -> f32 {
        if self.len == 0 {
            return 0.0;
        }
        self.iter().sum::<f32>() / self.len as f32
    }
}

impl Deref for ImageChannelValues {
    type Target = [f32];
    fn deref(&self) -> &[f32] {
        if self.len <= 4 {
            &self.inline[..self.len]
        } else {
            &self.heap
        }
    }
}

impl DerefMut for ImageChannelValues {
    fn deref_mut(&mut self) -> &mut [f32] {
        if self.len <= 4 {
            &mut self.inline[..self.len]
        } else {
            &mut self.heap
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum PixelData {
    U256(Vec<u8>),
    Half(Vec<f16>),
    Float(Vec<f32>),
}

/// A 2-D image with named channels stored interleaved, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    resolution: Point2i,
    channel_names: Vec<String>,
    encoding: ColorEncoding,
    data: PixelData,
}

/// Channel `c` of `out`, for each `c`, interpolated between the texels
/// whose storage indices `at` holds (`None`: outside, black) with the
/// weights of `dx`, `dy`; `get` reads a stored value.
#[inline(always)]
fn bilerp_texels(
    at: [Option<usize>; 4],
    dx: f32,
    dy: f32,
    out: &mut [f32],
    get: impl Fn(usize) -> f32,
) {
    for (c, o) in out.iter_mut().enumerate() {
        let v = at.map(|a| a.map_or(0.0, |i| get(i + c)));
        *o = bilerp4(dx, dy, v);
    }
}

/// pbrt-v4's `Bilerp` of four corner values.
#[inline]
pub(crate) fn bilerp4(dx: f32, dy: f32, v: [f32; 4]) -> f32 {
    (1.0 - dx) * (1.0 - dy) * v[0]
        + dx * (1.0 - dy) * v[1]
        + (1.0 - dx) * dy * v[2]
        + dx * dy * v[3]
}

fn to_names<S: AsRef<str>>(names: &[S]) -> Vec<String> {
    names.iter().map(|s| s.as_ref().to_string()).collect()
}

impl Image {
    /// A zero-filled image. `encoding` matters only for `U256`.
    pub fn new<S: AsRef<str>>(
        format: PixelFormat,
        resolution: Point2i,
        channels: &[S],
        encoding: ColorEncoding,
    ) -> Image {
        let n = channels.len() * resolution.x.max(0) as usize * resolution.y.max(0) as usize;
        let data = match format {
            PixelFormat::U256 => PixelData::U256(vec![0; n]),
            PixelFormat::Half => PixelData::Half(vec![f16::ZERO; n]),
            PixelFormat::Float => PixelData::Float(vec![0.0; n]),
        };
        Image {
            resolution,
            channel_names: to_names(channels),
            encoding,
            data,
        }
    }

    fn check_len(len: usize, resolution: Point2i, nc: usize) -> Result<(), ImageError> {
        let expect = nc * resolution.x.max(0) as usize * resolution.y.max(0) as usize;
        if len != expect || resolution.x < 0 || resolution.y < 0 {
            return Err(ImageError::Invalid(format!(
                "{len} values do not fill a {}x{} image with {nc} channels",
                resolution.x, resolution.y
            )));
        }
        Ok(())
    }

    /// An 8-bit image from interleaved values.
    pub fn from_u8<S: AsRef<str>>(
        data: Vec<u8>,
        resolution: Point2i,
        channels: &[S],
        encoding: ColorEncoding,
    ) -> Result<Image, ImageError> {
        Self::check_len(data.len(), resolution, channels.len())?;
        Ok(Image {
            resolution,
            channel_names: to_names(channels),
            encoding,
            data: PixelData::U256(data),
        })
    }

    /// A half-float image from interleaved values.
    pub fn from_f16<S: AsRef<str>>(
        data: Vec<f16>,
        resolution: Point2i,
        channels: &[S],
    ) -> Result<Image, ImageError> {
        Self::check_len(data.len(), resolution, channels.len())?;
        Ok(Image {
            resolution,
            channel_names: to_names(channels),
            encoding: ColorEncoding::Linear,
            data: PixelData::Half(data),
        })
    }

    /// A float image from interleaved values.
    pub fn from_f32<S: AsRef<str>>(
        data: Vec<f32>,
        resolution: Point2i,
        channels: &[S],
    ) -> Result<Image, ImageError> {
        Self::check_len(data.len(), resolution, channels.len())?;
        Ok(Image {
            resolution,
            channel_names: to_names(channels),
            encoding: ColorEncoding::Linear,
            data: PixelData::Float(data),
        })
    }

    /// Storage format.
    pub fn format(&self) -> PixelFormat {
        match self.data {
            PixelData::U256(_) => PixelFormat::U256,
            PixelData::Half(_) => PixelFormat::Half,
            PixelData::Float(_) => PixelFormat::Float,
        }
    }
    /// Width and height in pixels.
    pub fn resolution(&self) -> Point2i {
        self.resolution
    }
    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.channel_names.len()
    }
    /// Channel names in storage order.
    pub fn channel_names(&self) -> &[String] {
        &self.channel_names
    }
    /// Names of the channels a description selects.
    pub fn channel_names_of(&self, desc: &ImageChannelDesc) -> Vec<String> {
        desc.offset
            .iter()
            .map(|&o| self.channel_names[o].clone())
            .collect()
    }
    /// Encoding of 8-bit values.
    pub fn encoding(&self) -> ColorEncoding {
        self.encoding
    }
    /// Whether the image has no pixels.
    pub fn is_empty(&self) -> bool {
        self.resolution.x <= 0 || self.resolution.y <= 0
    }
    /// Bytes of pixel storage.
    pub fn bytes_used(&self) -> usize {
        match &self.data {
            PixelData::U256(v) => v.len(),
            PixelData::Half(v) => 2 * v.len(),
            PixelData::Float(v) => 4 * v.len(),
        }
    }
    /// Raw 8-bit values, if the format is `U256`.
    pub fn as_u8(&self) -> Option<&[u8]> {
        match &self.data {
            PixelData::U256(v) => Some(v),
            _ => None,
        }
    }
    /// Raw half values, if the format is `Half`.
    pub fn as_f16(&self) -> Option<&[f16]> {
        match &self.data {
            PixelData::Half(v) => Some(v),
            _ => None,
        }
    }
    /// Raw float values, if the format is `Float`.
    pub fn as_f32(&self) -> Option<&[f32]> {
        match &self.data {
            PixelData::Float(v) => Some(v),
            _ => None,
        }
    }

    /// Index of the first channel of pixel `p` in the interleaved storage.
    #[inline]
    pub fn pixel_offset(&self, p: Point2i) -> usize {
        debug_assert!(p.x >= 0 && p.y >= 0 && p.x < self.resolution.x && p.y < self.resolution.y);
        self.n_channels() * (p.y as usize * self.resolution.x as usize + p.x as usize)
    }

    /// Linear value at storage index `i`.
    #[inline]
    fn value_at(&self, i: usize) -> f32 {
        match &self.data {
            PixelData::U256(v) => self.encoding.to_linear(v[i]),
            PixelData::Half(v) => v[i].to_f32(),
            PixelData::Float(v) => v[i],
        }
    }

    #[inline]
    fn set_value_at(&mut self, i: usize, value: f32) {
        // pbrt-v4 replaces NaN by zero when storing.
        let value = if value.is_nan() { 0.0 } else { value };
        match &mut self.data {
            PixelData::U256(v) => v[i] = self.encoding.from_linear(value),
            PixelData::Half(v) => v[i] = f16::from_f32(value),
            PixelData::Float(v) => v[i] = value,
        }
    }

    /// Channel `c` of pixel `p`, remapped by `wrap` (0 outside with `Black`).
    #[inline]
    pub fn get_channel(&self, p: Point2i, c: usize, wrap: WrapMode2D) -> f32 {
        match remap_pixel_coords(p, self.resolution, wrap) {
            Some(p) => self.value_at(self.pixel_offset(p) + c),
            None => 0.0,
        }
    }

    /// All channels of pixel `p`.
    pub fn get_channels(&self, p: Point2i, wrap: WrapMode2D) -> ImageChannelValues {
        let nc = self.n_channels();
        let mut cv = ImageChannelValues::new(nc, 0.0);
        if let Some(p) = remap_pixel_coords(p, self.resolution, wrap) {
            let o = self.pixel_offset(p);
            for (c, v) in cv.iter_mut().enumerate() {
                *v = self.value_at(o + c);
            }
        }
        cv
    }

    /// The channels `desc` selects of pixel `p`.
    pub fn get_channels_desc(
        &self,
        p: Point2i,
        desc: &ImageChannelDesc,
        wrap: WrapMode2D,
    ) -> ImageChannelValues {
        let mut cv = ImageChannelValues::new(desc.len(), 0.0);
        if let Some(p) = remap_pixel_coords(p, self.resolution, wrap) {
            let o = self.pixel_offset(p);
            for (v, &c) in cv.iter_mut().zip(&desc.offset) {
                *v = self.value_at(o + c);
            }
        }
        cv
    }

    /// Sets channel `c` of pixel `p` (inside the image); NaN is stored as 0.
    #[inline]
    pub fn set_channel(&mut self, p: Point2i, c: usize, value: f32) {
        let o = self.pixel_offset(p) + c;
        self.set_value_at(o, value);
    }

    /// Sets the first `values.len()` channels of pixel `p`.
    pub fn set_channels(&mut self, p: Point2i, values: &[f32]) {
        debug_assert!(values.len() <= self.n_channels());
        let o = self.pixel_offset(p);
        for (c, &v) in values.iter().enumerate() {
            self.set_value_at(o + c, v);
        }
    }

    /// Sets the channels `desc` selects of pixel `p`.
    pub fn set_channels_desc(&mut self, p: Point2i, desc: &ImageChannelDesc, values: &[f32]) {
        let o = self.pixel_offset(p);
        for (&c, &v) in desc.offset.iter().zip(values) {
            self.set_value_at(o + c, v);
        }
    }

    /// Description selecting the named channels in the given order, or `None` if one is
    /// missing.
    pub fn get_channel_desc<S: AsRef<str>>(&self, names: &[S]) -> Option<ImageChannelDesc> {
        let mut offset = Vec::with_capacity(names.len());
        for n in names {
            offset.push(self.channel_names.iter().position(|c| c == n.as_ref())?);
        }
        Some(ImageChannelDesc { offset })
    }

    /// Description of all channels in storage order.
    pub fn all_channels_desc(&self) -> ImageChannelDesc {
        ImageChannelDesc {
            offset: (0..self.n_channels()).collect(),
        }
    }

    /// [`Image::select_channels`], taking the image: itself when `desc`
    /// is all its channels in order.
    pub fn into_channels(self, desc: &ImageChannelDesc) -> Image {
        if desc.offset.iter().copied().eq(0..self.n_channels()) {
            self
        } else {
            self.select_channels(desc)
        }
    }

    /// Number of stored values (pixels times channels).
    fn data_len(&self) -> usize {
        match &self.data {
            PixelData::U256(v) => v.len(),
            PixelData::Half(v) => v.len(),
            PixelData::Float(v) => v.len(),
        }
    }

    /// A new image holding only the channels `desc` selects, same format.
    pub fn select_channels(&self, desc: &ImageChannelDesc) -> Image {
        let names = self.channel_names_of(desc);
        let npix = (self.resolution.x.max(0) * self.resolution.y.max(0)) as usize;
        let nc = self.n_channels();
        let data = match &self.data {
            PixelData::U256(v) => PixelData::U256(
                (0..npix)
                    .flat_map(|i| desc.offset.iter().map(move |&c| v[i * nc + c]))
                    .collect(),
            ),
            PixelData::Half(v) => PixelData::Half(
                (0..npix)
                    .flat_map(|i| desc.offset.iter().map(move |&c| v[i * nc + c]))
                    .collect(),
            ),
            PixelData::Float(v) => PixelData::Float(
                (0..npix)
                    .flat_map(|i| desc.offset.iter().map(move |&c| v[i * nc + c]))
                    .collect(),
            ),
        };
        Image {
            resolution: self.resolution,
            channel_names: names,
            encoding: self.encoding,
            data,
        }
    }

    /// The pixels inside `bounds`, which must lie within the image.
    pub fn crop(&self, bounds: Bounds2i) -> Result<Image, ImageError> {
        let r = self.resolution;
        if bounds.is_empty()
            || bounds.p_min.x < 0
            || bounds.p_min.y < 0
            || bounds.p_max.x > r.x
            || bounds.p_max.y > r.y
        {
            return Err(ImageError::Invalid(format!(
                "crop window [{}, {}) x [{}, {}) is empty or outside the {}x{} image",
                bounds.p_min.x, bounds.p_max.x, bounds.p_min.y, bounds.p_max.y, r.x, r.y
            )));
        }
        let nr = Point2i {
            x: bounds.p_max.x - bounds.p_min.x,
            y: bounds.p_max.y - bounds.p_min.y,
        };
        let nc = self.n_channels();
        let rows = |y: i32| {
            let start = self.pixel_offset(Point2i {
                x: bounds.p_min.x,
                y,
            });
            start..start + nr.x as usize * nc
        };
        let ys = bounds.p_min.y..bounds.p_max.y;
        let data = match &self.data {
            PixelData::U256(v) => {
                PixelData::U256(ys.flat_map(|y| v[rows(y)].iter().copied()).collect())
            }
            PixelData::Half(v) => {
                PixelData::Half(ys.flat_map(|y| v[rows(y)].iter().copied()).collect())
            }
            PixelData::Float(v) => {
                PixelData::Float(ys.flat_map(|y| v[rows(y)].iter().copied()).collect())
            }
        };
        Ok(Image {
            resolution: nr,
            channel_names: self.channel_names.clone(),
            encoding: self.encoding,
            data,
        })
    }

    /// Mirrors the image top to bottom in place.
    pub fn flip_y(&mut self) {
        let row = self.n_channels() * self.resolution.x.max(0) as usize;
        let h = self.resolution.y.max(0) as usize;
        fn flip<T>(v: &mut [T], row: usize, h: usize) {
            for y in 0..h / 2 {
                let (a, b) = v.split_at_mut((h - 1 - y) * row);
                a[y * row..(y + 1) * row].swap_with_slice(&mut b[..row]);
            }
        }
        match &mut self.data {
            PixelData::U256(v) => flip(v, row, h),
            PixelData::Half(v) => flip(v, row, h),
            PixelData::Float(v) => flip(v, row, h),
        }
    }

    /// The image converted to `format`; `encoding` applies when the target is `U256`.
    pub fn convert_to_format(&self, format: PixelFormat, encoding: ColorEncoding) -> Image {
        if format == self.format() && (format != PixelFormat::U256 || encoding == self.encoding) {
            return self.clone();
        }
        let n = match &self.data {
            PixelData::U256(v) => v.len(),
            PixelData::Half(v) => v.len(),
            PixelData::Float(v) => v.len(),
        };
        let mut out = Image::new(format, self.resolution, &self.channel_names, encoding);
        for i in 0..n {
            out.set_value_at(i, self.value_at(i));
        }
        out
    }

    /// All values as linear floats, interleaved.
    pub fn to_f32_vec(&self) -> Vec<f32> {
        match &self.data {
            PixelData::Float(v) => v.clone(),
            PixelData::Half(v) => v.iter().map(|h| h.to_f32()).collect(),
            PixelData::U256(v) => v.iter().map(|&b| self.encoding.to_linear(b)).collect(),
        }
    }

    /// Nearest-texel lookup of channel `c` at continuous coordinates `p` in [0,1]^2.
    #[inline]
    pub fn lookup_nearest_channel(&self, p: Point2f, c: usize, wrap: WrapMode2D) -> f32 {
        let pi = Point2i {
            x: (p.x * self.resolution.x as f32) as i32,
            y: (p.y * self.resolution.y as f32) as i32,
        };
        self.get_channel(pi, c, wrap)
    }

    /// Bilinear interpolation of channel `c` at `p` in [0,1]^2, texel centres at half-integers.
    #[inline]
    pub fn bilerp_channel(&self, p: Point2f, c: usize, wrap: WrapMode2D) -> f32 {
        let x = p.x * self.resolution.x as f32 - 0.5;
        let y = p.y * self.resolution.y as f32 - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (dx, dy) = (x - xf, y - yf);
        let (xi, yi) = (xf as i32, yf as i32);
        let v = [
            self.get_channel(Point2i { x: xi, y: yi }, c, wrap),
            self.get_channel(Point2i { x: xi + 1, y: yi }, c, wrap),
            self.get_channel(Point2i { x: xi, y: yi + 1 }, c, wrap),
            self.get_channel(
                Point2i {
                    x: xi + 1,
                    y: yi + 1,
                },
                c,
                wrap,
            ),
        ];
        bilerp4(dx, dy, v)
    }

    /// Bilinear interpolation of the first `out.len()` channels at `p`
    /// into `out`: each value as [`Image::bilerp_channel`] gives it, the
    /// four texels found once for all channels.
    #[inline]
    pub fn bilerp_channels_into(&self, p: Point2f, wrap: WrapMode2D, out: &mut [f32]) {
        let (at, dx, dy) = self.bilerp_corners(p, wrap);
        let n = self.n_channels().min(out.len());
        // The storage type matched once for all twelve-odd reads (each
        // read is `value_at`'s).
        let out = &mut out[..n];
        match &self.data {
            PixelData::U256(v) => bilerp_texels(at, dx, dy, out, |i| self.encoding.to_linear(v[i])),
            PixelData::Half(v) => bilerp_texels(at, dx, dy, out, |i| v[i].to_f32()),
            PixelData::Float(v) => bilerp_texels(at, dx, dy, out, |i| v[i]),
        }
    }

    /// The storage offsets of the four texels a bilinear lookup at `p`
    /// reads (`None` outside the image under `Black` wrapping), and the
    /// lookup's weights along x and y.
    #[inline(always)]
    fn bilerp_corners(&self, p: Point2f, wrap: WrapMode2D) -> ([Option<usize>; 4], f32, f32) {
        let x = p.x * self.resolution.x as f32 - 0.5;
        let y = p.y * self.resolution.y as f32 - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (dx, dy) = (x - xf, y - yf);
        let (xi, yi) = (xf as i32, yf as i32);
        let corner = |x: i32, y: i32| {
            remap_pixel_coords(Point2i { x, y }, self.resolution, wrap)
                .map(|q| self.pixel_offset(q))
        };
        let at = [
            corner(xi, yi),
            corner(xi + 1, yi),
            corner(xi, yi + 1),
            corner(xi + 1, yi + 1),
        ];
        (at, dx, dy)
    }

    /// Starts loading the texels a bilinear lookup at `p` reads
    /// ([`Image::bilerp_channels_into`]), for a lookup soon after: a hint
    /// with no effect on results.
    #[inline]
    pub fn prefetch_bilerp(&self, p: Point2f, wrap: WrapMode2D) {
        let (at, _, _) = self.bilerp_corners(p, wrap);
        let (base, size): (*const u8, usize) = match &self.data {
            PixelData::U256(v) => (v.as_ptr(), 1),
            PixelData::Half(v) => (v.as_ptr().cast(), 2),
            PixelData::Float(v) => (v.as_ptr().cast(), 4),
        };
        // Each cache line once: a row's two texels usually share one.
        let mut last = usize::MAX;
        for i in at.into_iter().flatten() {
            let p = base.wrapping_add(i * size);
            if p.addr() >> 6 != last {
                crate::simd::prefetch_ptr(p);
                last = p.addr() >> 6;
            }
        }
    }

    /// Bilinear interpolation of all channels.
    pub fn bilerp(&self, p: Point2f, wrap: WrapMode2D) -> ImageChannelValues {
        let mut cv = ImageChannelValues::new(self.n_channels(), 0.0);
        for (c, v) in cv.iter_mut().enumerate() {
            *v = self.bilerp_channel(p, c, wrap);
        }
        cv
    }

    /// Bilinear interpolation of the channels `desc` selects.
    pub fn bilerp_desc(
        &self,
        p: Point2f,
        desc: &ImageChannelDesc,
        wrap: WrapMode2D,
    ) -> ImageChannelValues {
        let mut cv = ImageChannelValues::new(desc.len(), 0.0);
        for (v, &c) in cv.iter_mut().zip(&desc.offset) {
            *v = self.bilerp_channel(p, c, wrap);
        }
        cv
    }

    /// Mean of each selected channel over all pixels.
    pub fn average(&self, desc: &ImageChannelDesc) -> ImageChannelValues {
        let mut sum = vec![0.0f64; desc.len()];
        let npix = (self.resolution.x.max(0) * self.resolution.y.max(0)) as usize;
        let nc = self.n_channels();
        for i in 0..npix {
            for (s, &c) in sum.iter_mut().zip(&desc.offset) {
                *s += self.value_at(i * nc + c) as f64;
            }
        }
        let mut cv = ImageChannelValues::new(desc.len(), 0.0);
        for (v, s) in cv.iter_mut().zip(sum) {
            *v = (s / npix.max(1) as f64) as f32;
        }
        cv
    }
}
