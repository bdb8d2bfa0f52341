//! Resampling up to power-of-two resolutions and building MIP pyramids (pbrt-v4
//! `Image::FloatResizeUp`, `Image::GeneratePyramid`; book section 10.4.3 "MIP Maps").

use rpbrt_geometry::{Point2i, PI};

use super::{Image, PixelFormat, WrapMode2D};

/// sin(pi x) / (pi x), exactly 1 where the power series rounds to 1.
fn sinc(x: f32) -> f32 {
    let px = PI * x;
    if 1.0 + px * px == 1.0 {
        1.0
    } else {
        px.sin() / px
    }
}

/// Lanczos-windowed sinc of the given radius and window width `tau`.
pub(crate) fn windowed_sinc(x: f32, radius: f32, tau: f32) -> f32 {
    if x.abs() > radius {
        0.0
    } else {
        sinc(x) * sinc(x / tau)
    }
}

/// First source texel and four normalised weights for one output texel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ResampleWeight {
    pub first_texel: i32,
    pub weight: [f32; 4],
}

/// Weights for resampling `old_res` texels up to `new_res` with a windowed sinc of
/// radius 2.
pub(crate) fn resample_weights(old_res: i32, new_res: i32) -> Vec<ResampleWeight> {
    debug_assert!(new_res >= old_res);
    let filter_width = 2.0f32;
    (0..new_res)
        .map(|i| {
            let center = (i as f32 + 0.5) * old_res as f32 / new_res as f32;
            let first_texel = ((center - filter_width) + 0.5).floor() as i32;
            let mut weight = [0.0f32; 4];
            for (j, w) in weight.iter_mut().enumerate() {
                let pos = first_texel as f32 + j as f32 + 0.5;
                *w = windowed_sinc(pos - center, filter_width, 2.0);
            }
            let inv = 1.0 / (weight[0] + weight[1] + weight[2] + weight[3]);
            for w in &mut weight {
                *w *= inv;
            }
            ResampleWeight {
                first_texel,
                weight,
            }
        })
        .collect()
}

/// Smallest power of two >= v (v >= 1).
pub(crate) fn round_up_pow2(v: i32) -> i32 {
    (v.max(1) as u32).next_power_of_two() as i32
}

impl Image {
    /// Resamples to a resolution at least as large in each dimension, as floats, with
    /// a separable windowed-sinc filter; results are clamped to be non-negative.
    /// Source texels outside the image come from `wrap` (`Black` gives zeros).
    pub fn float_resize_up(&self, new_res: Point2i, wrap: WrapMode2D) -> Image {
        let res = self.resolution;
        debug_assert!(new_res.x >= res.x && new_res.y >= res.y);
        let nc = self.n_channels();
        let xw = resample_weights(res.x, new_res.x);
        let yw = resample_weights(res.y, new_res.y);
        let mut out = Image::new(
            PixelFormat::Float,
            new_res,
            &self.channel_names,
            self.encoding,
        );
        if xw.is_empty() || yw.is_empty() {
            return out;
        }
        let y0 = yw[0].first_texel;
        let y1 = yw[yw.len() - 1].first_texel + 4;
        let nxo = new_res.x as usize;
        // Zoom in x for every source row the y pass needs.
        let mut xbuf = vec![0.0f32; (y1 - y0) as usize * nxo * nc];
        for y in y0..y1 {
            let row = (y - y0) as usize * nxo * nc;
            for (xo, w) in xw.iter().enumerate() {
                for c in 0..nc {
                    let v = |j: i32| {
                        self.get_channel(
                            Point2i {
                                x: w.first_texel + j,
                                y,
                            },
                            c,
                            wrap,
                        )
                    };
                    xbuf[row + xo * nc + c] = w.weight[0] * v(0)
                        + w.weight[1] * v(1)
                        + w.weight[2] * v(2)
                        + w.weight[3] * v(3);
                }
            }
        }
        // Zoom in y.
        let step = nxo * nc;
        if let super::PixelData::Float(dst) = &mut out.data {
            for (yo, w) in yw.iter().enumerate() {
                let base = (w.first_texel - y0) as usize * step;
                for i in 0..step {
                    let b = base + i;
                    let v = w.weight[0] * xbuf[b]
                        + w.weight[1] * xbuf[b + step]
                        + w.weight[2] * xbuf[b + 2 * step]
                        + w.weight[3] * xbuf[b + 3 * step];
                    dst[yo * step + i] = v.max(0.0);
                }
            }
        }
        out
    }

    /// Builds a MIP pyramid: the image is resampled up to power-of-two resolution (or
    /// converted to float), then each level is the 2x2 box-filtered previous one. Levels
    /// are stored in the original pixel format and encoding, finest first.
    pub fn generate_pyramid(image: &Image, wrap: WrapMode2D) -> Vec<Image> {
        image.clone().into_pyramid(wrap)
    }

    /// [`Image::generate_pyramid`], taking the image: pbrt-v4's levels bit for bit,
    /// built without its float copy of the finest level. Rows flow down the
    /// levels as they are made (each level holds one float row waiting for its
    /// pair), so building takes a few rows of floats besides the levels
    /// themselves. Where converting to floats and back gives the stored values
    /// (8-bit images whose encoding round-trips every code, half and float images
    /// without NaNs) the image itself is the finest level.
    pub fn into_pyramid(self, wrap: WrapMode2D) -> Vec<Image> {
        let res = self.resolution;
        if res.x <= 0 || res.y <= 0 {
            return vec![self];
        }
        let pow2 = (res.x as u32).is_power_of_two() && (res.y as u32).is_power_of_two();
        if !pow2 {
            // pbrt-v4 resamples up to powers of two first.
            let up = self.float_resize_up(
                Point2i {
                    x: round_up_pow2(res.x),
                    y: round_up_pow2(res.y),
                },
                wrap,
            );
            let super::PixelData::Float(floats) = &up.data else {
                unreachable!("resampling makes floats")
            };
            let mut cascade = Cascade::new(&self, up.resolution, true);
            for row in floats.chunks_exact(up.resolution.x as usize * up.n_channels()) {
                cascade.push_row(0, row.to_vec());
            }
            return cascade.finish();
        }
        let keep = self.keeps_own_values();
        let mut cascade = Cascade::new(&self, res, !keep);
        let row_len = res.x as usize * self.n_channels();
        let enc = self.encoding;
        match &self.data {
            super::PixelData::U256(v) => {
                let lut: [f32; 256] = std::array::from_fn(|b| enc.to_linear(b as u8));
                for row in v.chunks_exact(row_len) {
                    cascade.push_row(0, row.iter().map(|&b| lut[b as usize]).collect());
                }
            }
            super::PixelData::Half(v) => {
                // Converting to floats stores NaN as zero.
                let value = |h: &half::f16| if h.is_nan() { 0.0 } else { h.to_f32() };
                for row in v.chunks_exact(row_len) {
                    cascade.push_row(0, row.iter().map(value).collect());
                }
            }
            super::PixelData::Float(v) => {
                for row in v.chunks_exact(row_len) {
                    cascade.push_row(0, row.to_vec());
                }
            }
        }
        let mut levels = cascade.finish();
        if keep {
            levels[0] = self;
        }
        levels
    }

    /// Whether converting the image to floats and back gives its own values
    /// (what lets [`Image::into_pyramid`] keep it as the finest level).
    fn keeps_own_values(&self) -> bool {
        match &self.data {
            super::PixelData::U256(_) => {
                (0..=255u8).all(|b| self.encoding.from_linear(self.encoding.to_linear(b)) == b)
            }
            // Storing turns NaN into zero.
            super::PixelData::Half(v) => !v.iter().any(|h| h.is_nan()),
            // Float to float is a copy.
            super::PixelData::Float(_) => true,
        }
    }

    /// An image of resolution `res` holding `values` stored as this image
    /// stores its values (what `convert_to_format` to its format gives).
    fn stored_like(&self, res: Point2i, values: &[f32]) -> Image {
        let mut out = Image {
            resolution: res,
            channel_names: self.channel_names.clone(),
            encoding: self.encoding,
            data: match &self.data {
                super::PixelData::U256(_) => super::PixelData::U256(Vec::new()),
                super::PixelData::Half(_) => super::PixelData::Half(Vec::new()),
                super::PixelData::Float(_) => super::PixelData::Float(Vec::new()),
            },
        };
        out.append_stored(values);
        out
    }

    /// Appends `values` to the image's storage, converted as
    /// `convert_to_format` to its format converts them.
    fn append_stored(&mut self, values: &[f32]) {
        let enc = self.encoding;
        match &mut self.data {
            super::PixelData::U256(d) => d.extend(values.iter().map(|&v| enc.from_linear(v))),
            super::PixelData::Half(d) => d.extend(
                values
                    .iter()
                    .map(|&v| half::f16::from_f32(if v.is_nan() { 0.0 } else { v })),
            ),
            super::PixelData::Float(d) => d.extend_from_slice(values),
        }
    }
}

/// The levels of a pyramid being built a row at a time, finest first.
/// Level `l + 1`'s rows are the 2x2 means of level `l`'s pairs of rows, in
/// pbrt-v4's order of summing (a side of one texel is repeated).
struct Cascade {
    levels: Vec<Image>,
    /// Each level's float row waiting for its pair.
    pending: Vec<Option<Vec<f32>>>,
    /// Whether the finest level is stored (or given back by the caller).
    store_finest: bool,
}

impl Cascade {
    /// Empty levels stored like `like`, the finest of resolution `res`
    /// (left empty, for the caller to fill, unless `store_finest`).
    fn new(like: &Image, res: Point2i, store_finest: bool) -> Cascade {
        let n = 1 + (res.x.max(res.y) as u32).ilog2() as usize;
        let nc = like.n_channels();
        let mut levels = Vec::with_capacity(n);
        let mut r = res;
        for l in 0..n {
            let mut level = like.stored_like(r, &[]);
            let len = if l > 0 || store_finest {
                r.x as usize * r.y as usize * nc
            } else {
                0
            };
            match &mut level.data {
                super::PixelData::U256(d) => d.reserve_exact(len),
                super::PixelData::Half(d) => d.reserve_exact(len),
                super::PixelData::Float(d) => d.reserve_exact(len),
            }
            levels.push(level);
            r = half_res(r);
        }
        Cascade {
            pending: vec![None; n],
            levels,
            store_finest,
        }
    }

    /// Adds the next row of level `l`, in floats.
    fn push_row(&mut self, l: usize, row: Vec<f32>) {
        if l > 0 || self.store_finest {
            self.levels[l].append_stored(&row);
        }
        if l + 1 == self.levels.len() {
            return;
        }
        let res = self.levels[l].resolution;
        let nc = self.levels[l].n_channels();
        let below = if res.y == 1 {
            // A level one row high pairs the row with itself.
            halve_rows(&row, &row, res.x as usize, nc)
        } else {
            match self.pending[l].take() {
                None => {
                    self.pending[l] = Some(row);
                    return;
                }
                Some(first) => halve_rows(&first, &row, res.x as usize, nc),
            }
        };
        self.push_row(l + 1, below);
    }

    /// The levels, finest first (the finest empty when the caller keeps it).
    fn finish(self) -> Vec<Image> {
        self.levels
    }
}

/// The next coarser level's resolution.
fn half_res(res: Point2i) -> Point2i {
    Point2i {
        x: (res.x / 2).max(1),
        y: (res.y / 2).max(1),
    }
}

/// The row of 2x2 means of rows `a` and `b` (the same row where the level
/// is one row high) of a level `width` texels wide with `nc` channels.
#[inline]
fn halve_rows(a: &[f32], b: &[f32], width: usize, nc: usize) -> Vec<f32> {
    let next = (width / 2).max(1);
    // The second texel of a pair: the next one, or the same at width 1.
    let dx = if width == 1 { 0 } else { nc };
    let mut out = Vec::with_capacity(next * nc);
    for x in 0..next {
        let so = 2 * x * nc;
        for c in 0..nc {
            let i = so + c;
            out.push(0.25 * (a[i] + a[i + dx] + b[i] + b[i + dx]));
        }
    }
    out
}
