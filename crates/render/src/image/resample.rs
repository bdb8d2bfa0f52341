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
        let orig_format = image.format();
        let orig_encoding = image.encoding;
        let nc = image.n_channels();
        let res = image.resolution;
        if res.x <= 0 || res.y <= 0 {
            return vec![image.clone()];
        }
        let mut img = if !(res.x as u32).is_power_of_two() || !(res.y as u32).is_power_of_two() {
            image.float_resize_up(
                Point2i {
                    x: round_up_pow2(res.x),
                    y: round_up_pow2(res.y),
                },
                wrap,
            )
        } else {
            image.convert_to_format(PixelFormat::Float, orig_encoding)
        };
        let n_levels = 1 + (img.resolution.x.max(img.resolution.y) as u32).ilog2() as usize;
        let mut pyramid = Vec::with_capacity(n_levels);
        let mut level_res = img.resolution;
        for _ in 0..n_levels - 1 {
            pyramid.push(img.convert_to_format(orig_format, orig_encoding));
            let next_res = Point2i {
                x: (level_res.x / 2).max(1),
                y: (level_res.y / 2).max(1),
            };
            let mut next = Image::new(
                PixelFormat::Float,
                next_res,
                &img.channel_names,
                orig_encoding,
            );
            let rx = level_res.x as usize;
            let mut deltas = [0, nc, nc * rx, nc * rx + nc];
            if level_res.x == 1 {
                deltas[1] = 0;
                deltas[3] -= nc;
            }
            if level_res.y == 1 {
                deltas[2] = 0;
                deltas[3] -= nc * rx;
            }
            if let (super::PixelData::Float(src), super::PixelData::Float(dst)) =
                (&img.data, &mut next.data)
            {
                for y in 0..next_res.y as usize {
                    let mut so = 2 * y * rx * nc;
                    let mut no = y * next_res.x as usize * nc;
                    for _ in 0..next_res.x {
                        for _ in 0..nc {
                            dst[no] = 0.25
                                * (src[so]
                                    + src[so + deltas[1]]
                                    + src[so + deltas[2]]
                                    + src[so + deltas[3]]);
                            so += 1;
                            no += 1;
                        }
                        so += nc;
                    }
                }
            }
            img = next;
            level_res = next_res;
        }
        pyramid.push(img.convert_to_format(orig_format, orig_encoding));
        pyramid
    }
}
