//! Image comparison, statistics and processing behind `rpbrt imgtool`
//! (pbrt-v4 `cmd/imgtool.cpp`; `Image::MSE`, `Image::Average`). Functions
//! return data; formatting for the terminal belongs to the CLI. This file
//! holds `diff`, `average` and `info`; the other commands' work lives in
//! one submodule per topic.

pub mod color;
pub mod compose;
pub mod convert;
pub mod falsecolor;
pub mod filter;
pub mod flip;
pub mod metrics;
mod viridis;

use std::fmt;

use rpbrt_geometry::Point2i;

use super::{ColorEncoding, Image, ImageError, PixelFormat};

/// Splits a comma-separated channel list (pbrt-v4's `--channels`) into
/// names, keeping the commas inside channel names that have them (the
/// spectral film's "S0.418,750nm"): at each piece the longest run of
/// comma-joined pieces naming one of `available` is taken, otherwise the
/// piece alone (an unknown name the caller reports).
pub fn split_channel_list(spec: &str, available: &[String]) -> Vec<String> {
    let pieces: Vec<&str> = spec.split(',').map(str::trim).collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < pieces.len() {
        let take = (i + 1..=pieces.len())
            .rev()
            .find(|&j| available.iter().any(|a| *a == pieces[i..j].join(",")))
            .unwrap_or(i + 1);
        out.push(pieces[i..take].join(","));
        i = take;
    }
    out
}

/// Differences between two images of the same resolution and channels.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffStats {
    /// Channels compared (those of the first image).
    pub channels: Vec<String>,
    /// Mean over pixels and channels of (a - b)^2.
    pub mse: f64,
    /// Mean over pixels and channels of (a - b)^2 / (b^2 + 0.01).
    pub rel_mse: f64,
    /// The relative MSE per pixel (averaged over channels), with the worst 0.1% of
    /// pixels dropped before averaging.
    pub rel_mse_trimmed: f64,
    /// Mean of all channel values of `a`.
    pub mean_a: f64,
    /// Mean of all channel values of `b`.
    pub mean_b: f64,
    /// Largest |a - b| over pixels and channels.
    pub max_abs_diff: f64,
    /// Pixels where any channel differs.
    pub differing_pixels: usize,
    /// Channel values where a term was NaN or infinite (left out of the sums).
    pub non_finite: usize,
    /// The reference's value at [`CLAMP_PERCENTILE`], where both images
    /// are clamped for the means below.
    pub clamp_value: f64,
    /// Mean of the image with every value clamped at `clamp_value`.
    pub clamped_mean_a: f64,
    /// Mean of the reference clamped the same way.
    pub clamped_mean_b: f64,
    /// The median over pixels of each pixel's brightness (the mean of its
    /// compared channels): insensitive to fireflies and to a few dark
    /// pixels alike.
    pub median_a: f64,
    /// The reference's median pixel brightness.
    pub median_b: f64,
}

/// Fraction of pixels dropped by the trimmed relative MSE.
pub const TRIM_FRACTION: f64 = 0.001;

/// Both images' values over `a`'s channels, after checking they match.
type Paired = (Vec<String>, Vec<f32>, Vec<f32>);

fn paired(a: &Image, b: &Image) -> Result<Paired, ImageError> {
    if a.resolution() != b.resolution() {
        let (ra, rb) = (a.resolution(), b.resolution());
        return Err(ImageError::Invalid(format!(
            "image resolutions differ: {}x{} vs {}x{}",
            ra.x, ra.y, rb.x, rb.y
        )));
    }
    let names = a.channel_names().to_vec();
    let bdesc = b.get_channel_desc(&names).ok_or_else(|| {
        ImageError::Invalid(format!(
            "second image lacks some of the channels {:?} (it has {:?})",
            names,
            b.channel_names()
        ))
    })?;
    let bsel = if bdesc.is_identity() && b.n_channels() == names.len() {
        b.clone()
    } else {
        b.select_channels(&bdesc)
    };
    Ok((names, a.to_f32_vec(), bsel.to_f32_vec()))
}

/// Per-pixel relative squared error, averaged over channels: (a-b)^2 / (b^2 + 0.01).
fn per_pixel_rel(va: &[f32], vb: &[f32], nc: usize) -> Vec<f64> {
    va.chunks_exact(nc)
        .zip(vb.chunks_exact(nc))
        .map(|(pa, pb)| {
            let s: f64 = pa
                .iter()
                .zip(pb)
                .map(|(&x, &y)| {
                    let (x, y) = (x as f64, y as f64);
                    (x - y) * (x - y) / (y * y + 0.01)
                })
                .sum();
            s / nc as f64
        })
        .collect()
}

/// Mean of per-pixel values after dropping the largest `fraction` of them (non-finite
/// values count as largest).
pub fn trimmed_mean(mut v: Vec<f64>, fraction: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let key = |x: &f64| if x.is_finite() { *x } else { f64::INFINITY };
    v.sort_by(|x, y| key(x).total_cmp(&key(y)));
    let drop = ((v.len() as f64) * fraction).floor() as usize;
    let keep = &v[..v.len() - drop.min(v.len() - 1)];
    keep.iter().sum::<f64>() / keep.len() as f64
}

/// Relative MSE of `a` against reference `b` with the worst `fraction` of pixels dropped.
pub fn rel_mse_trimmed(a: &Image, b: &Image, fraction: f64) -> Result<f64, ImageError> {
    let (names, va, vb) = paired(a, b)?;
    Ok(trimmed_mean(
        per_pixel_rel(&va, &vb, names.len().max(1)),
        fraction,
    ))
}

/// The percentile of the reference's values at which [`diff`] clamps
/// both images for its firefly-insensitive means.
pub const CLAMP_PERCENTILE: f64 = 99.9;

/// The `p`-th percentile (0–100) of the finite values of `v`, by the
/// nearest rank (0 for no finite value).
pub fn percentile(v: &[f32], p: f64) -> f64 {
    let mut f: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.is_empty() {
        return 0.0;
    }
    f.sort_by(f32::total_cmp);
    let rank = ((p / 100.0) * f.len() as f64).ceil() as usize;
    f[rank.clamp(1, f.len()) - 1] as f64
}

/// The median of the pixels' brightnesses, each the mean of the pixel's
/// `nc` channel values.
fn median_brightness(v: &[f32], nc: usize) -> f64 {
    let brightness: Vec<f32> = v
        .chunks_exact(nc)
        .map(|px| (px.iter().map(|&x| x as f64).sum::<f64>() / nc as f64) as f32)
        .collect();
    percentile(&brightness, 50.0)
}

/// Compares `a` with the reference `b` over `a`'s channels.
pub fn diff(a: &Image, b: &Image) -> Result<DiffStats, ImageError> {
    let (names, va, vb) = paired(a, b)?;
    let nc = names.len().max(1);
    let (mut se, mut rse, mut sa, mut sb, mut maxd) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut non_finite = 0;
    let mut differing = 0;
    for (pa, pb) in va.chunks_exact(nc).zip(vb.chunks_exact(nc)) {
        if pa != pb {
            differing += 1;
        }
        for (&x, &y) in pa.iter().zip(pb) {
            let (x, y) = (x as f64, y as f64);
            let d = x - y;
            let e = d * d;
            let re = e / (y * y + 0.01);
            if !e.is_finite() || !re.is_finite() {
                non_finite += 1;
                continue;
            }
            se += e;
            rse += re;
            sa += x;
            sb += y;
            maxd = maxd.max(d.abs());
        }
    }
    let n = va.len().max(1) as f64;
    let clamp = percentile(&vb, CLAMP_PERCENTILE);
    let clamped_mean = |v: &[f32]| {
        v.iter()
            .filter(|x| x.is_finite())
            .map(|&x| (x as f64).min(clamp))
            .sum::<f64>()
            / n
    };
    Ok(DiffStats {
        clamp_value: clamp,
        clamped_mean_a: clamped_mean(&va),
        clamped_mean_b: clamped_mean(&vb),
        median_a: median_brightness(&va, nc),
        median_b: median_brightness(&vb, nc),
        rel_mse_trimmed: trimmed_mean(per_pixel_rel(&va, &vb, nc), TRIM_FRACTION),
        channels: names,
        mse: se / n,
        rel_mse: rse / n,
        mean_a: sa / n,
        mean_b: sb / n,
        max_abs_diff: maxd,
        differing_pixels: differing,
        non_finite,
    })
}

/// The side of the pixel blocks [`worst_block`] compares.
pub const BLOCK_SIZE: i32 = 16;

/// How one block of an image differs from the same block of a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockDifference {
    /// The block's first pixel.
    pub at: Point2i,
    /// The block's mean over the reference's.
    pub ratio: f64,
    /// The mean difference in units of its standard error (the spread of
    /// the sub-blocks' differences over the square root of their count):
    /// beyond 4 or so, the block differs by more than noise.
    pub z: f64,
}

/// The block of `a` that differs most from the same block of the
/// reference `b`, measured against the noise within it: blocks of
/// `size`×`size` pixels (partial ones at the edges), differences averaged
/// over channels (non-finite ones left out) and over each of the block's
/// 4×4 sub-blocks. A difference image
/// with structure (a missing caustic, a shifted highlight) shows here as a
/// large |z| even when the overall means agree. `None` for an empty image.
pub fn worst_block(a: &Image, b: &Image, size: i32) -> Result<Option<BlockDifference>, ImageError> {
    let (names, va, vb) = paired(a, b)?;
    let nc = names.len().max(1);
    let res = a.resolution();
    let size = size.max(1);
    let mut worst: Option<BlockDifference> = None;
    let mut by = 0;
    while by < res.y {
        let mut bx = 0;
        while bx < res.x {
            // The differences are taken over 4×4 sub-blocks, whose means
            // are nearly independent even when a reconstruction filter
            // spreads each sample over neighbouring pixels.
            let (mut sa, mut sb) = (0.0f64, 0.0f64);
            let (mut sd, mut sd2, mut n) = (0.0f64, 0.0f64, 0usize);
            let sub = (size / 4).max(1);
            let (ey, ex) = ((by + size).min(res.y), (bx + size).min(res.x));
            let mut sy = by;
            while sy < ey {
                let mut sx = bx;
                while sx < ex {
                    let (mut ta, mut tb, mut m) = (0.0f64, 0.0f64, 0usize);
                    for y in sy..(sy + sub).min(ey) {
                        for x in sx..(sx + sub).min(ex) {
                            let i = (y as usize * res.x as usize + x as usize) * nc;
                            let (pa, pb) = (&va[i..i + nc], &vb[i..i + nc]);
                            if pa.iter().chain(pb).all(|v| v.is_finite()) {
                                ta += pa.iter().map(|&v| v as f64).sum::<f64>() / nc as f64;
                                tb += pb.iter().map(|&v| v as f64).sum::<f64>() / nc as f64;
                                m += 1;
                            }
                        }
                    }
                    if m > 0 {
                        sa += ta;
                        sb += tb;
                        let d = (ta - tb) / m as f64;
                        sd += d;
                        sd2 += d * d;
                        n += 1;
                    }
                    sx += sub;
                }
                sy += sub;
            }
            if n > 1 {
                let nf = n as f64;
                let mean = sd / nf;
                let var = ((sd2 - sd * sd / nf) / (nf - 1.0)).max(0.0);
                let se = (var / nf).sqrt();
                let z = if se > 0.0 {
                    mean / se
                } else if mean == 0.0 {
                    0.0
                } else {
                    f64::INFINITY
                };
                let ratio = if sb > 0.0 { sa / sb } else { f64::NAN };
                if worst.is_none_or(|w| z.abs() > w.z.abs()) {
                    worst = Some(BlockDifference {
                        at: Point2i::new(bx, by),
                        ratio,
                        z,
                    });
                }
            }
            bx += size;
        }
        by += size;
    }
    Ok(worst)
}

/// The per-pixel average of `images` (pbrt-v4 `imgtool average`): all of
/// the same resolution and channels (names and order) as the first;
/// infinite values count as zero, as pbrt-v4 does, and a NaN is an error
/// naming the image (by index) and pixel. Sums are taken in `f64` in the
/// order given, so the result does not depend on anything else.
pub fn average(images: &[Image]) -> Result<Image, ImageError> {
    let Some(first) = images.first() else {
        return Err(ImageError::Invalid("no images to average".into()));
    };
    let res = first.resolution();
    let names = first.channel_names().to_vec();
    let nc = names.len().max(1);
    let mut sum = vec![0.0f64; first.to_f32_vec().len()];
    let n = images.len() as f64;
    for (k, im) in images.iter().enumerate() {
        if im.resolution() != res {
            return Err(ImageError::Invalid(format!(
                "image {k}: resolution {}x{} differs from the first image's {}x{}",
                im.resolution().x,
                im.resolution().y,
                res.x,
                res.y
            )));
        }
        if im.channel_names() != names.as_slice() {
            return Err(ImageError::Invalid(format!(
                "image {k}: channels {:?} differ from the first image's {:?}",
                im.channel_names(),
                names
            )));
        }
        for (i, &v) in im.to_f32_vec().iter().enumerate() {
            if v.is_nan() {
                let px = i / nc;
                return Err(ImageError::Invalid(format!(
                    "image {k}: NaN at pixel ({}, {})",
                    px as i32 % res.x.max(1),
                    px as i32 / res.x.max(1)
                )));
            }
            if v.is_finite() {
                sum[i] += v as f64 / n;
            }
        }
    }
    Image::from_f32(sum.into_iter().map(|v| v as f32).collect(), res, &names)
}

/// Statistics of one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelStats {
    /// Channel name.
    pub name: String,
    /// Smallest finite value.
    pub min: f32,
    /// Largest finite value.
    pub max: f32,
    /// Mean of the finite values.
    pub average: f64,
    /// Count of NaN values.
    pub nan_count: usize,
    /// Count of infinite values.
    pub inf_count: usize,
}

/// Summary of an image for `imgtool info`.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageInfo {
    /// Resolution.
    pub resolution: Point2i,
    /// Storage format.
    pub format: PixelFormat,
    /// Encoding (meaningful for 8-bit images).
    pub encoding: ColorEncoding,
    /// Per-channel statistics.
    pub channels: Vec<ChannelStats>,
}

/// Resolution, format and per-channel min/max/average and NaN/Inf counts.
pub fn info(image: &Image) -> ImageInfo {
    let nc = image.n_channels();
    let vals = image.to_f32_vec();
    let channels = image
        .channel_names()
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let mut s = ChannelStats {
                name: name.clone(),
                min: f32::INFINITY,
                max: f32::NEG_INFINITY,
                average: 0.0,
                nan_count: 0,
                inf_count: 0,
            };
            let mut n = 0usize;
            for &v in vals.iter().skip(c).step_by(nc.max(1)) {
                if v.is_nan() {
                    s.nan_count += 1;
                } else if v.is_infinite() {
                    s.inf_count += 1;
                } else {
                    s.min = s.min.min(v);
                    s.max = s.max.max(v);
                    s.average += v as f64;
                    n += 1;
                }
            }
            s.average /= n.max(1) as f64;
            s
        })
        .collect();
    ImageInfo {
        resolution: image.resolution(),
        format: image.format(),
        encoding: image.encoding(),
        channels,
    }
}

impl fmt::Display for ImageInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "resolution {}x{}, format {}",
            self.resolution.x, self.resolution.y, self.format
        )?;
        if self.format == PixelFormat::U256 {
            write!(f, " (encoding {})", self.encoding.name())?;
        }
        writeln!(f)?;
        for c in &self.channels {
            writeln!(
                f,
                "  {}: min {} max {} avg {} ({} NaN, {} Inf)",
                c.name, c.min, c.max, c.average, c.nan_count, c.inf_count
            )?;
        }
        Ok(())
    }
}

impl Image {
    /// A copy with `f` applied to every linear value, in the same format.
    pub fn map_values(&self, f: impl Fn(f32) -> f32) -> Image {
        let vals: Vec<f32> = self.to_f32_vec().into_iter().map(f).collect();
        let mut out = Image::new(
            self.format(),
            self.resolution(),
            self.channel_names(),
            self.encoding(),
        );
        for (i, v) in vals.into_iter().enumerate() {
            out.set_value_at(i, v);
        }
        out
    }

    /// Values scaled by 2^stops.
    pub fn apply_exposure(&self, stops: f32) -> Image {
        let s = stops.exp2();
        self.map_values(|v| v * s)
    }

    /// Values clamped to [lo, hi] (NaN becomes `lo`).
    pub fn clamp_values(&self, lo: f32, hi: f32) -> Image {
        self.map_values(|v| if v.is_nan() { lo } else { v.clamp(lo, hi) })
    }
}
