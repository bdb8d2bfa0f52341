//! Partial renders that join into exactly the image one run makes: tiles
//! of the image (`--tile K/N`, pbrt-v4's pixel bounds chosen for the
//! user) and ranges of pixel samples (`--spp-range A..B`).
//!
//! A tile is an ordinary crop: every pixel's samples depend only on the
//! pixel and the sample index, so a tile's pixels equal the full render's.
//! A sample range is different: its pixels are averages over fewer
//! samples, and averaging averages is not exact. A range's EXR therefore
//! carries, beside its own viewable R, G, B, the film's per-pixel sums
//! (weighted sensor RGB, filter weight and splats) as raw `f64` bits, and
//! the constants that turn sums into output RGB. [`merge_sample_ranges`]
//! adds the sums and resolves them with the film's own code.
//!
//! How exact is "exact": one run adds a pixel's samples as (sample 0) +
//! (samples 1..n), while merged ranges add them as (range sums) in range
//! order. Floating-point addition is not associative, so the two `f64`
//! sums can differ in their last bit; that reaches the written `f32` or
//! `f16` value only when it straddles a rounding boundary of the output
//! format, about one value in 10^8.

use rpbrt_geometry::{Bounds2i, Float, Point2i};

use super::{Film, FilmCore, KindConfig};
use crate::image::{ColorEncoding, Image, ImageMetadata, PixelFormat};
use crate::spectrum::{ColorMatrix, RGB};

/// Metadata key of a sample-range partial: `[start, end, samples per pixel]`.
pub const SAMPLE_RANGE_KEY: &str = "rpbrt.sampleRange";
const MATRIX_KEY: &str = "rpbrt.outputRGBFromSensorRGB";
const FILTER_INTEGRAL_KEY: &str = "rpbrt.filterIntegral";
const FP16_KEY: &str = "rpbrt.savefp16";

/// The per-pixel sums a sample-range partial carries, in order.
const SUMS: [&str; 7] = ["SumR", "SumG", "SumB", "SumW", "SplatR", "SplatG", "SplatB"];

/// Channels per stored `f64`: 22 + 21 + 21 bits, each an integer that
/// any `f32` channel holds exactly.
const PIECES: usize = 3;

/// A mistake in a partial render's request or files.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialError(pub String);

impl std::fmt::Display for PartialError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PartialError {}

fn err<T>(msg: impl Into<String>) -> Result<T, PartialError> {
    Err(PartialError(msg.into()))
}

/// Samples `[start, end)` of every pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleRange {
    /// First sample index.
    pub start: i32,
    /// One past the last sample index.
    pub end: i32,
}

impl SampleRange {
    /// Checks the range against the sampler's samples per pixel.
    pub fn check(self, spp: i32) -> Result<SampleRange, PartialError> {
        if self.start < 0 || self.start >= self.end {
            return err(format!(
                "--spp-range {}..{}: need 0 <= A < B",
                self.start, self.end
            ));
        }
        if self.end > spp {
            return err(format!(
                "--spp-range {}..{}: the render takes {spp} samples per pixel, so B must be at most {spp}",
                self.start, self.end
            ));
        }
        Ok(self)
    }
}

/// The names of the sum channels: `rpbrt.SumR.0` ... `rpbrt.SplatB.2`.
pub fn sum_channel_names() -> Vec<String> {
    SUMS.iter()
        .flat_map(|s| (0..PIECES).map(move |k| format!("rpbrt.{s}.{k}")))
        .collect()
}

/// `x`'s bits as three integers below 2^22, stored as `f32`.
pub fn encode_f64(x: f64) -> [f32; 3] {
    let b = x.to_bits();
    [
        (b >> 42) as f32,
        ((b >> 21) & 0x1F_FFFF) as f32,
        (b & 0x1F_FFFF) as f32,
    ]
}

/// The `f64` [`encode_f64`] stored, or `None` when the values are not
/// such integers.
pub fn decode_f64(v: [f32; 3]) -> Option<f64> {
    let mut b = 0u64;
    for (k, (x, bits)) in v.iter().zip([22, 21, 21]).enumerate() {
        if !(x.fract() == 0.0 && *x >= 0.0 && (*x as u64) < (1 << bits)) {
            return None;
        }
        b |= (*x as u64) << [42, 21, 0][k];
    }
    Some(f64::from_bits(b))
}

/// Tile `k` of `n` over `bounds`, or `None` when `k >= n` or there are
/// more tiles than pixels.
///
/// The tiles form rows of near-square tiles covering every pixel once;
/// `k` walks them with a stride coprime to `n` near `n / φ`, so any run
/// of consecutive `k` (or every m-th `k`) spreads over the image and
/// machines handed tiles in order or round-robin get similar mixes of
/// cheap and costly regions.
pub fn tile_bounds(bounds: Bounds2i, k: u32, n: u32) -> Option<Bounds2i> {
    let d = bounds.diagonal();
    if n == 0 || k >= n || (n as i64) > (d.x as i64) * (d.y as i64) {
        return None;
    }
    let (w, h) = (d.x as f64, d.y as f64);
    let rows = ((n as f64 * h / w).sqrt().round() as u32).clamp(1, n.min(d.y as u32));
    let cell = spread_order(n)[k as usize];
    // Row r holds tiles [start(r), start(r + 1)).
    let start = |r: u32| (r as u64 * n as u64 / rows as u64) as u32;
    let row = (0..rows).find(|&r| cell < start(r + 1))?;
    let (c0, cols) = (start(row), start(row + 1) - start(row));
    if cols as i64 > d.x as i64 {
        return None;
    }
    let col = cell - c0;
    let y = |r: u32| bounds.p_min.y + (r as i64 * d.y as i64 / rows as i64) as i32;
    let x = |c: u32| bounds.p_min.x + (c as i64 * d.x as i64 / cols as i64) as i32;
    Some(Bounds2i::new(
        Point2i::new(x(col), y(row)),
        Point2i::new(x(col + 1), y(row + 1)),
    ))
}

/// The order tiles are numbered in: `k -> (k * stride) mod n`.
fn spread_order(n: u32) -> Vec<u32> {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let target = (n as f64 / 1.618_034).round().max(1.0) as u32;
    let stride = (0..n)
        .flat_map(|d| [target + d, target.saturating_sub(d)])
        .find(|&s| s >= 1 && gcd(s, n) == 1)
        .unwrap_or(1);
    (0..n)
        .map(|k| ((k as u64 * stride as u64) % n as u64) as u32)
        .collect()
}

/// The splat weight after `spp` samples per pixel (pbrt-v4 writes
/// `1 / waveStart`).
pub fn splat_scale(spp: i32) -> Float {
    1.0 / spp.max(1) as Float
}

/// A pixel's output RGB from its sums: weighted sensor RGB over the weight,
/// plus scaled splats, then sensor to output colour space. The film and
/// the merge of sample ranges both come here, so they agree to the bit.
pub(crate) fn resolve_rgb(
    sums: [f64; 4],
    splat: [f64; 3],
    splat_scale: Float,
    filter_integral: Float,
    output_from_sensor: &ColorMatrix,
) -> RGB {
    let mut v = [sums[0], sums[1], sums[2]];
    if sums[3] != 0.0 {
        v = v.map(|c| c / sums[3]);
    }
    for (vc, s) in v.iter_mut().zip(splat) {
        *vc += splat_scale as f64 * s / filter_integral as f64;
    }
    RGB::from_array(output_from_sensor.apply(v.map(|c| c as Float)))
}

/// An output image of `res` with `channels`, half or float.
pub(crate) fn output_image(fp16: bool, res: Point2i, channels: &[String]) -> Image {
    let format = if fp16 {
        PixelFormat::Half
    } else {
        PixelFormat::Float
    };
    Image::new(format, res, channels, ColorEncoding::Linear)
}

/// Clamps to the largest half when writing half floats.
pub(crate) fn clamp16(fp16: bool, v: Float) -> Float {
    if fp16 && v > 65504.0 {
        65504.0
    } else {
        v
    }
}

impl FilmCore {
    fn partial_image(
        &self,
        metadata: &mut ImageMetadata,
        range: SampleRange,
        spp: i32,
    ) -> Result<Image, PartialError> {
        if !matches!(self.config.kind, KindConfig::Rgb) {
            return err(
                "--spp-range needs the \"rgb\" film: the sums of \"gbuffer\" and \"spectral\" films are not stored in partial images",
            );
        }
        let mut names: Vec<String> = ["R", "G", "B"].iter().map(|s| s.to_string()).collect();
        names.extend(sum_channel_names());
        let d = self.active.diagonal();
        let mut image = output_image(false, Point2i::new(d.x, d.y), &names);
        let own_scale = splat_scale(range.end - range.start);
        let pmin = self.active.p_min;
        let mut vals = Vec::with_capacity(names.len());
        for p in self.active.iter() {
            let i = self.pixels.index(p);
            let sums = self.pixels.rgb[i];
            let splat = [0, 1, 2].map(|c| self.splat_rgb.get(3 * i + c));
            let rgb = resolve_rgb(
                sums,
                splat,
                own_scale,
                self.filter_integral,
                &self.output_rgb_from_sensor_rgb,
            );
            vals.clear();
            vals.extend([rgb.r, rgb.g, rgb.b]);
            for v in sums.iter().chain(splat.iter()) {
                vals.extend(encode_f64(*v));
            }
            image.set_channels(Point2i::new(p.x - pmin.x, p.y - pmin.y), &vals);
        }
        metadata.pixel_bounds = Some(self.active);
        metadata.full_resolution = Some(self.full_resolution);
        metadata.color_space = Some(self.color_space.name.clone());
        metadata.samples_per_pixel = Some(range.end - range.start);
        let s = &mut metadata.strings;
        s.insert(
            SAMPLE_RANGE_KEY.into(),
            vec![
                range.start.to_string(),
                range.end.to_string(),
                spp.to_string(),
            ],
        );
        s.insert(
            MATRIX_KEY.into(),
            self.output_rgb_from_sensor_rgb
                .m
                .iter()
                .flatten()
                .map(|v| format!("{v:?}"))
                .collect(),
        );
        s.insert(
            FILTER_INTEGRAL_KEY.into(),
            vec![format!("{:?}", self.filter_integral)],
        );
        s.insert(FP16_KEY.into(), vec![self.write_fp16.to_string()]);
        Ok(image)
    }
}

impl Film {
    /// The image of a sample-range render: its own R, G, B (splats scaled
    /// by its sample count) plus the sums [`merge_sample_ranges`] needs.
    /// Always float. Only the `rgb` film stores its sums.
    pub fn partial_image(
        &self,
        metadata: &mut ImageMetadata,
        range: SampleRange,
        spp: i32,
    ) -> Result<Image, PartialError> {
        self.core().partial_image(metadata, range, spp)
    }
}

/// What one partial file says about itself.
struct Part<'a> {
    name: &'a str,
    image: &'a Image,
    md: &'a ImageMetadata,
    start: i32,
    end: i32,
    spp: i32,
}

fn strings<'a>(md: &'a ImageMetadata, key: &str, name: &str) -> Result<&'a [String], PartialError> {
    md.strings.get(key).map(Vec::as_slice).ok_or_else(|| {
        PartialError(format!(
            "{name}: not a sample-range partial of rpbrt (no \"{key}\" attribute); render it with --spp-range"
        ))
    })
}

fn parse<T: std::str::FromStr>(s: &str, key: &str, name: &str) -> Result<T, PartialError> {
    s.parse()
        .map_err(|_| PartialError(format!("{name}: bad \"{key}\" value \"{s}\"")))
}

/// Joins sample-range partials of the same pixels (`(file name, image,
/// metadata)`) into the image one run over their samples writes: the
/// sums are added in range order and resolved as the film resolves them.
/// Overlapping ranges, different films or pixels, and files that are not
/// partials are errors; ranges that leave gaps give the image of the
/// samples present (the caller may warn). Returns the image, its metadata
/// and the samples per pixel covered.
pub fn merge_sample_ranges(
    parts: &[(&str, &Image, &ImageMetadata)],
) -> Result<(Image, ImageMetadata, i32), PartialError> {
    if parts.is_empty() {
        return err("no images to merge");
    }
    let mut list = Vec::with_capacity(parts.len());
    for &(name, image, md) in parts {
        let r = strings(md, SAMPLE_RANGE_KEY, name)?;
        let [a, b, n] = r else {
            return err(format!("{name}: \"{SAMPLE_RANGE_KEY}\" needs three values"));
        };
        list.push(Part {
            name,
            image,
            md,
            start: parse(a, SAMPLE_RANGE_KEY, name)?,
            end: parse(b, SAMPLE_RANGE_KEY, name)?,
            spp: parse(n, SAMPLE_RANGE_KEY, name)?,
        });
    }
    list.sort_by_key(|p| p.start);
    let first = &list[0];
    let names = sum_channel_names();
    let mut desc_names: Vec<&str> = vec!["R", "G", "B"];
    desc_names.extend(names.iter().map(String::as_str));
    for p in &list {
        if p.start < 0 || p.start >= p.end || p.end > p.spp {
            return err(format!(
                "{}: bad sample range {}..{} of {}",
                p.name, p.start, p.end, p.spp
            ));
        }
        if p.image.get_channel_desc(&desc_names).is_none() {
            return err(format!(
                "{}: missing the sum channels of a sample-range partial",
                p.name
            ));
        }
        let same = p.image.resolution() == first.image.resolution()
            && p.md.pixel_bounds == first.md.pixel_bounds
            && p.md.full_resolution == first.md.full_resolution;
        if !same {
            return err(format!(
                "{} and {} cover different pixels: sample ranges must be of the same pixels",
                first.name, p.name
            ));
        }
        for key in [MATRIX_KEY, FILTER_INTEGRAL_KEY, FP16_KEY] {
            if p.md.strings.get(key) != first.md.strings.get(key) {
                return err(format!(
                    "{} and {} come from different films (\"{key}\" differs)",
                    first.name, p.name
                ));
            }
        }
        if p.spp != first.spp {
            return err(format!(
                "{} and {} were rendered with different samples per pixel ({} and {})",
                first.name, p.name, first.spp, p.spp
            ));
        }
    }
    for w in list.windows(2) {
        if w[1].start < w[0].end {
            return err(format!(
                "{} (samples {}..{}) and {} (samples {}..{}) overlap",
                w[0].name, w[0].start, w[0].end, w[1].name, w[1].start, w[1].end
            ));
        }
    }
    let m = strings(first.md, MATRIX_KEY, first.name)?;
    if m.len() != 9 {
        return err(format!(
            "{}: \"{MATRIX_KEY}\" needs nine values",
            first.name
        ));
    }
    let mut matrix = ColorMatrix::IDENTITY;
    for (k, v) in m.iter().enumerate() {
        matrix.m[k / 3][k % 3] = parse(v, MATRIX_KEY, first.name)?;
    }
    let fi = strings(first.md, FILTER_INTEGRAL_KEY, first.name)?;
    let filter_integral: Float = parse(
        fi.first().map(String::as_str).unwrap_or(""),
        FILTER_INTEGRAL_KEY,
        first.name,
    )?;
    let fp = strings(first.md, FP16_KEY, first.name)?;
    let fp16: bool = parse(
        fp.first().map(String::as_str).unwrap_or(""),
        FP16_KEY,
        first.name,
    )?;
    let covered: i32 = list.iter().map(|p| p.end - p.start).sum();

    let res = first.image.resolution();
    let rgb_names: Vec<String> = ["R", "G", "B"].iter().map(|s| s.to_string()).collect();
    let mut out = output_image(fp16, res, &rgb_names);
    let descs: Vec<_> = list
        .iter()
        .map(|p| p.image.get_channel_desc(&names))
        .collect();
    let scale = splat_scale(covered);
    for y in 0..res.y {
        for x in 0..res.x {
            let pt = Point2i::new(x, y);
            let mut sums = [0.0f64; 7];
            for (p, desc) in list.iter().zip(&descs) {
                let Some(desc) = desc else { continue };
                let v = p
                    .image
                    .get_channels_desc(pt, desc, crate::image::WrapMode::Clamp.into());
                for (k, s) in sums.iter_mut().enumerate() {
                    let piece = [v[PIECES * k], v[PIECES * k + 1], v[PIECES * k + 2]];
                    let Some(d) = decode_f64(piece) else {
                        return err(format!(
                            "{}: pixel ({x}, {y}) holds no valid sums (the file was changed after rendering?)",
                            p.name
                        ));
                    };
                    *s += d;
                }
            }
            let rgb = resolve_rgb(
                [sums[0], sums[1], sums[2], sums[3]],
                [sums[4], sums[5], sums[6]],
                scale,
                filter_integral,
                &matrix,
            );
            out.set_channels(
                pt,
                &[
                    clamp16(fp16, rgb.r),
                    clamp16(fp16, rgb.g),
                    clamp16(fp16, rgb.b),
                ],
            );
        }
    }
    let mut md = ImageMetadata {
        pixel_bounds: first.md.pixel_bounds,
        full_resolution: first.md.full_resolution,
        color_space: first.md.color_space.clone(),
        samples_per_pixel: Some(covered),
        camera_from_world: first.md.camera_from_world,
        ndc_from_world: first.md.ndc_from_world,
        ..Default::default()
    };
    md.render_time_seconds = list
        .iter()
        .map(|p| p.md.render_time_seconds)
        .sum::<Option<f32>>();
    Ok((out, md, covered))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f64_bits_survive_f32_channels() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            -3.5e-310,
            1e300,
            f64::INFINITY,
            f64::MIN_POSITIVE,
            12345.678_901_234_5,
        ] {
            let e = encode_f64(x);
            assert!(e.iter().all(|v| v.fract() == 0.0 && *v < 4_194_304.0));
            assert_eq!(decode_f64(e).map(f64::to_bits), Some(x.to_bits()));
        }
        assert_eq!(decode_f64([0.5, 0.0, 0.0]), None);
        assert_eq!(decode_f64([4_194_304.0, 0.0, 0.0]), None);
        assert_eq!(decode_f64([0.0, 2_097_152.0, 0.0]), None);
        assert_eq!(decode_f64([-1.0, 0.0, 0.0]), None);
    }

    fn cover(bounds: Bounds2i, n: u32) -> Vec<Bounds2i> {
        (0..n)
            .map(|k| tile_bounds(bounds, k, n).expect("tile"))
            .collect()
    }

    #[test]
    fn tiles_cover_every_pixel_once() {
        let shapes = [
            Bounds2i::new(Point2i::new(0, 0), Point2i::new(400, 400)),
            Bounds2i::new(Point2i::new(3, 7), Point2i::new(130, 41)),
            Bounds2i::new(Point2i::new(0, 0), Point2i::new(5, 3)),
            Bounds2i::new(Point2i::new(0, 0), Point2i::new(1, 64)),
        ];
        for b in shapes {
            let max = (b.area() as u32).min(70);
            for n in 1..=max {
                let tiles = cover(b, n);
                let mut count = vec![0u8; b.area() as usize];
                for t in &tiles {
                    assert!(!t.is_empty(), "{b:?} n={n}: empty tile {t:?}");
                    for p in t.iter() {
                        assert!(b.inside_exclusive(p));
                        let w = b.diagonal().x;
                        count[((p.y - b.p_min.y) * w + p.x - b.p_min.x) as usize] += 1;
                    }
                }
                assert!(count.iter().all(|&c| c == 1), "{b:?} n={n}");
            }
        }
        let b = Bounds2i::new(Point2i::new(0, 0), Point2i::new(2, 2));
        assert_eq!(tile_bounds(b, 0, 5), None);
        assert_eq!(tile_bounds(b, 4, 4), None);
        assert_eq!(tile_bounds(b, 0, 0), None);
    }

    #[test]
    fn tiles_are_near_square_and_consecutive_ones_spread() {
        let b = Bounds2i::new(Point2i::new(0, 0), Point2i::new(400, 400));
        let tiles = cover(b, 16);
        for t in &tiles {
            assert_eq!(t.diagonal(), rpbrt_geometry::Vector2i::new(100, 100));
        }
        // The first four tiles are not all in one row or column.
        let rows: std::collections::BTreeSet<i32> = tiles[..4].iter().map(|t| t.p_min.y).collect();
        let cols: std::collections::BTreeSet<i32> = tiles[..4].iter().map(|t| t.p_min.x).collect();
        assert!(rows.len() >= 3 && cols.len() >= 3, "{:?}", &tiles[..4]);
    }

    #[test]
    fn sample_ranges_are_checked() {
        assert!(SampleRange { start: 0, end: 8 }.check(8).is_ok());
        assert!(SampleRange { start: 4, end: 4 }.check(8).is_err());
        assert!(SampleRange { start: -1, end: 4 }.check(8).is_err());
        assert!(SampleRange { start: 0, end: 9 }.check(8).is_err());
    }
}
