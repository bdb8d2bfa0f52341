//! Neighbourhood filters behind `imgtool bloom` and `convert --despike`:
//! pbrt-v4's separable Gaussian blur (`Image::GaussianFilter`), its bloom
//! (thresholded, repeatedly blurred and added back) and the 3×3 median
//! despiking of bright pixels.

use crate::image::{Image, ImageChannelDesc, ImageError, PixelFormat};
use rpbrt_geometry::Point2i;

/// The normal density with mean `mu` and standard deviation `sigma`.
fn gaussian(x: f32, mu: f32, sigma: f32) -> f32 {
    let s2 = sigma * sigma;
    (1.0 / (2.0 * std::f32::consts::PI * s2).sqrt()) * (-(x - mu) * (x - mu) / (2.0 * s2)).exp()
}

/// A float image of the channels `desc` selects, blurred by a separable
/// Gaussian of standard deviation `sigma` over 2 `half_width` + 1 pixels
/// (weights normalised; pixels beyond the edge repeat the edge, pbrt-v4's
/// clamp wrapping).
pub fn gaussian_filter(
    image: &Image,
    desc: &ImageChannelDesc,
    half_width: i32,
    sigma: f32,
) -> Image {
    let hw = half_width.max(0);
    let mut wts: Vec<f32> = (0..2 * hw + 1)
        .map(|d| gaussian((d - hw) as f32, 0.0, sigma))
        .collect();
    let sum: f32 = wts.iter().sum();
    if sum > 0.0 {
        wts.iter_mut().for_each(|w| *w /= sum);
    }
    let res = image.resolution();
    let (w, h) = (res.x.max(0) as usize, res.y.max(0) as usize);
    let nc_in = image.n_channels();
    let nc = desc.len();
    let vals = image.to_f32_vec();
    let at = |x: i32, y: i32, c: usize, v: &[f32], n: usize| -> f32 {
        let x = x.clamp(0, res.x - 1) as usize;
        let y = y.clamp(0, res.y - 1) as usize;
        v[(y * w + x) * n + c]
    };
    let mut blurx = vec![0.0f32; w * h * nc];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            for (ci, &c) in desc.offset.iter().enumerate() {
                let mut s = 0.0;
                for r in -hw..=hw {
                    s += wts[(r + hw) as usize] * at(x + r, y, c, &vals, nc_in);
                }
                blurx[(y as usize * w + x as usize) * nc + ci] = s;
            }
        }
    }
    let mut out = vec![0.0f32; w * h * nc];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            for c in 0..nc {
                let mut s = 0.0;
                for r in -hw..=hw {
                    s += wts[(r + hw) as usize] * at(x, y + r, c, &blurx, nc);
                }
                out[(y as usize * w + x as usize) * nc + c] = s;
            }
        }
    }
    let names = image.channel_names_of(desc);
    let mut result = Image::new(PixelFormat::Float, res, &names, image.encoding());
    for (i, v) in out.into_iter().enumerate() {
        result.set_value_at(i, v);
    }
    result
}

/// The result of [`bloom`].
#[derive(Clone, Debug)]
pub struct Bloom {
    /// The image with the bloom added.
    pub image: Image,
    /// Pixels above the threshold.
    pub survivors: usize,
    /// The filter width used (an even width is rounded up to odd).
    pub width: i32,
}

/// pbrt-v4's bloom: the pixels with any channel above `level` are kept
/// (the rest zeroed), blurred `iterations` times in succession by a
/// Gaussian of `width` pixels (radius width/2, sigma radius/2), and the
/// sum of the blurred images times `scale / iterations` is added to the
/// image. No pixel above the threshold is an error, as is a width or
/// iteration count below 1.
pub fn bloom(
    image: &Image,
    level: f32,
    width: i32,
    iterations: i32,
    scale: f32,
) -> Result<Bloom, ImageError> {
    if width < 1 || iterations < 1 {
        return Err(ImageError::Invalid(format!(
            "bloom width ({width}) and iterations ({iterations}) must be at least 1"
        )));
    }
    let nc = image.n_channels();
    let vals = image.to_f32_vec();
    let mut survivors = 0;
    let mut thresholded = vals.clone();
    for px in thresholded.chunks_exact_mut(nc.max(1)) {
        if px.iter().any(|&v| v > level) {
            survivors += 1;
        } else {
            px.iter_mut().for_each(|v| *v = 0.0);
        }
    }
    if survivors == 0 {
        return Err(ImageError::Invalid(format!(
            "no pixels were above the bloom threshold {level}"
        )));
    }
    let width = if width % 2 == 0 { width + 1 } else { width };
    let radius = width / 2;
    let sigma = radius as f32 / 2.0;
    let all = image.all_channels_desc();
    let mut current = Image::from_f32(thresholded, image.resolution(), image.channel_names())?;
    let mut sum = vec![0.0f32; vals.len()];
    for _ in 0..iterations {
        current = gaussian_filter(&current, &all, radius, sigma);
        for (s, v) in sum.iter_mut().zip(current.to_f32_vec()) {
            *s += v;
        }
    }
    let k = scale / iterations as f32;
    let mut out = image.convert_to_format(PixelFormat::Float, image.encoding());
    for (i, (v, s)) in vals.iter().zip(sum).enumerate() {
        out.set_value_at(i, v + k * s);
    }
    Ok(Bloom {
        image: out,
        survivors,
        width,
    })
}

/// Replaces each pixel whose channel average is at least `limit` by the
/// pixel of median average among its 3×3 neighbourhood (those inside
/// the image; pbrt-v4 `convert --despike`). Returns the filtered image
/// (same format) and how many pixels were replaced.
pub fn despike(image: &Image, limit: f32) -> (Image, usize) {
    let res = image.resolution();
    let nc = image.n_channels().max(1);
    let vals = image.to_f32_vec();
    let w = res.x.max(0) as usize;
    let avg = |x: i32, y: i32| -> f32 {
        let i = (y as usize * w + x as usize) * nc;
        vals[i..i + nc].iter().sum::<f32>() / nc as f32
    };
    let mut out = image.clone();
    let mut count = 0;
    for y in 0..res.y {
        for x in 0..res.x {
            if avg(x, y) < limit {
                continue;
            }
            count += 1;
            let mut neighbours: Vec<Point2i> = Vec::with_capacity(9);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx >= 0 && ny >= 0 && nx < res.x && ny < res.y {
                        neighbours.push(Point2i::new(nx, ny));
                    }
                }
            }
            // A stable sort by average: ties keep scan order.
            neighbours.sort_by(|a, b| avg(a.x, a.y).total_cmp(&avg(b.x, b.y)));
            let m = neighbours[neighbours.len() / 2];
            let src = (m.y as usize * w + m.x as usize) * nc;
            let dst = (y as usize * w + x as usize) * nc;
            for c in 0..nc {
                out.set_value_at(dst + c, vals[src + c]);
            }
        }
    }
    (out, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(vals: &[f32], w: i32, h: i32, names: &[&str]) -> Image {
        Image::from_f32(vals.to_vec(), Point2i::new(w, h), names).unwrap()
    }

    #[test]
    fn gaussian_filter_of_a_delta_is_the_outer_product_of_weights() {
        // 3x3 with a 1 in the middle; half width 1, sigma 1: weights
        // g(1), g(0), g(1) normalised: e^-0.5 / (1 + 2 e^-0.5) and 1 / (...).
        let mut v = vec![0.0; 9];
        v[4] = 1.0;
        let im = img(&v, 3, 3, &["Y"]);
        let out = gaussian_filter(&im, &im.all_channels_desc(), 1, 1.0);
        let e = (-0.5f32).exp();
        let (w0, w1) = (1.0 / (1.0 + 2.0 * e), e / (1.0 + 2.0 * e));
        let o = out.to_f32_vec();
        assert!((o[4] - w0 * w0).abs() < 1e-6);
        assert!((o[1] - w0 * w1).abs() < 1e-6);
        assert!((o[0] - w1 * w1).abs() < 1e-6);
        // The clamped edges repeat zeros here, so the mass stays 1.
        assert!((o.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn gaussian_filter_clamps_at_edges() {
        // A constant image stays constant.
        let im = img(&[2.0; 6], 3, 2, &["Y"]);
        let out = gaussian_filter(&im, &im.all_channels_desc(), 2, 1.0);
        assert!(out.to_f32_vec().iter().all(|&v| (v - 2.0).abs() < 1e-6));
    }

    #[test]
    fn bloom_adds_the_scaled_blur_of_bright_pixels() {
        // 3x1: only the middle pixel (4) exceeds level 1. Width 3: radius
        // 1, sigma 0.5; one iteration, scale 0.5.
        let im = img(&[0.5, 4.0, 0.5], 3, 1, &["Y"]);
        let b = bloom(&im, 1.0, 3, 1, 0.5).unwrap();
        assert_eq!(b.survivors, 1);
        let g1 = (-2.0f32).exp(); // exp(-1 / (2 * 0.25))
        let (w0, w1) = (1.0 / (1.0 + 2.0 * g1), g1 / (1.0 + 2.0 * g1));
        // Vertically the 1-row image clamps: weights sum to 1.
        let o = b.image.to_f32_vec();
        assert!((o[0] - (0.5 + 0.5 * 4.0 * w1)).abs() < 1e-5);
        assert!((o[1] - (4.0 + 0.5 * 4.0 * w0)).abs() < 1e-5);
        assert!(bloom(&im, 10.0, 3, 1, 0.5).is_err());
        assert_eq!(bloom(&im, 1.0, 4, 1, 0.5).unwrap().width, 5);
    }

    #[test]
    fn despike_replaces_bright_pixels_with_the_median_neighbour() {
        // 3x3, centre spike 100; neighbours 1..8 → median of 9 values
        // sorted (1..8, 100) is the 5th: 5.
        let v = [1.0, 2.0, 3.0, 4.0, 100.0, 5.0, 6.0, 7.0, 8.0];
        let im = img(&v, 3, 3, &["Y"]);
        let (out, n) = despike(&im, 50.0);
        assert_eq!(n, 1);
        let o = out.to_f32_vec();
        assert_eq!(o[4], 5.0);
        assert_eq!(o[0], 1.0);
        // A corner spike sees 4 pixels: (spike, 2, 4, 5 → sorted 2, 4, 5,
        // spike): index 2 → 5.
        let v = [100.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let (out, _) = despike(&img(&v, 3, 3, &["Y"]), 50.0);
        assert_eq!(out.to_f32_vec()[0], 5.0);
    }
}
