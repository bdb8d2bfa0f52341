//! False-colour visualisation (pbrt-v4 `imgtool falsecolor`): each pixel's
//! channel average, relative to a maximum, mapped through the viridis
//! colour map, or to green (positive) and red (negative).

use rpbrt_geometry::Point2i;

use super::viridis::VIRIDIS;
use crate::image::encoding::srgb_to_linear;
use crate::image::ColorEncoding;
use crate::image::{Image, PixelFormat};

/// The image pbrt-v4's `--ramp` shows: 10×300 pixels, one channel "Y",
/// running from 1 at the top row to 0 at the bottom.
pub fn ramp_image() -> Image {
    let (w, h) = (10, 300);
    let mut v = Vec::with_capacity(w * h);
    for y in 0..h {
        let t = (h - 1 - y) as f32 / (h - 1) as f32;
        v.extend(std::iter::repeat_n(t, w));
    }
    let mut im = Image::new(
        PixelFormat::Float,
        Point2i::new(w as i32, h as i32),
        &["Y"],
        ColorEncoding::Linear,
    );
    for (i, t) in v.into_iter().enumerate() {
        im.set_value_at(i, t);
    }
    im
}

/// The largest |channel average| over the pixels (pbrt-v4's default
/// `--maxvalue`).
pub fn max_abs_average(image: &Image) -> f32 {
    let nc = image.n_channels().max(1);
    image
        .to_f32_vec()
        .chunks_exact(nc)
        .map(|px| (px.iter().sum::<f32>() / nc as f32).abs())
        .fold(f32::NEG_INFINITY, f32::max)
}

/// The viridis colour (linear RGB) of `t` in [0, 1] (clamped): entry
/// floor(t × 256), the last for t = 1.
pub fn viridis(t: f32) -> [f32; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let i = ((t * VIRIDIS.len() as f32) as usize).min(VIRIDIS.len() - 1);
    VIRIDIS[i].map(srgb_to_linear)
}

/// A half-float R, G, B image colouring each pixel of `image` by its
/// channel average over `max_value` (default: [`max_abs_average`]):
/// viridis, or with `plus_minus` green for positive and red for
/// negative values (their magnitude, sRGB-decoded).
pub fn false_color(image: &Image, max_value: Option<f32>, plus_minus: bool) -> Image {
    let max_value = max_value.unwrap_or_else(|| max_abs_average(image));
    let nc = image.n_channels().max(1);
    let res = image.resolution();
    let mut out = Image::new(
        PixelFormat::Half,
        res,
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    for (p, px) in image.to_f32_vec().chunks_exact(nc).enumerate() {
        let rel = px.iter().sum::<f32>() / nc as f32 / max_value;
        let rgb = if plus_minus {
            let c = |v: f32| srgb_to_linear(v);
            if rel > 0.0 {
                [0.0, c(rel), 0.0]
            } else {
                [c(rel.abs()), 0.0, 0.0]
            }
        } else {
            viridis(rel)
        };
        for (c, v) in rgb.into_iter().enumerate() {
            out.set_value_at(p * 3 + c, v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_map_to_viridis_entries() {
        // Pixels 0, 0.5 and 1 of max 1: entries 0, 128 and 255.
        let im = Image::from_f32(vec![0.0, 0.5, 1.0], Point2i::new(3, 1), &["Y"]).unwrap();
        let o = false_color(&im, None, false).to_f32_vec();
        let want = |i: usize| VIRIDIS[i].map(srgb_to_linear);
        for (k, i) in [0usize, 128, 255].into_iter().enumerate() {
            for c in 0..3 {
                // Half precision.
                assert!((o[k * 3 + c] - want(i)[c]).abs() < 1e-3, "{k} {c}");
            }
        }
        // sRGB 0.267004 decodes to 0.057951.
        assert!((o[0] - 0.057951).abs() < 1e-4);
    }

    #[test]
    fn plus_minus_colours_sign() {
        let im =
            Image::from_f32(vec![2.0, -1.0, 0.0, -4.0], Point2i::new(2, 1), &["A", "B"]).unwrap();
        // Averages 0.5 and -2; max |avg| is 2: 0.25 → green, -1 → red.
        let o = false_color(&im, None, true).to_f32_vec();
        assert_eq!(o[0], 0.0);
        // sRGB 0.25 decodes to 0.050876.
        assert!((o[1] - 0.050876).abs() < 1e-4);
        assert_eq!(&o[3..6], &[1.0, 0.0, 0.0]);
    }

    #[test]
    fn ramp_runs_top_to_bottom() {
        let r = ramp_image();
        assert_eq!(r.resolution(), Point2i::new(10, 300));
        let v = r.to_f32_vec();
        assert_eq!(v[0], 1.0);
        assert_eq!(v[v.len() - 1], 0.0);
    }
}
