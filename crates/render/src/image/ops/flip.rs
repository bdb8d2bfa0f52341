//! The FLIP image difference of `imgtool diff --metric FLIP`: NVIDIA's LDR
//! FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating
//! Images", HPG 2020) in the form pbrt-v4 vendors (`src/ext/flip/flip.cpp`,
//! from the paper's 2020 reference code).
//!
//! Per pixel, FLIP combines a colour difference (both images filtered by
//! contrast sensitivity functions in YCxCz, taken to Hunt-adjusted L*a*b*,
//! HyAB distance, compressed and remapped to [0, 1]) with a feature
//! difference (edge and point detectors on the achromatic channel) as
//! `colour^(1 - feature)`. Everything runs in single precision in the
//! order of the reference code, so the numbers are pbrt-v4's.
//!
//! As pbrt-v4 does, the input values are taken to be sRGB-encoded values in
//! [0, 1] even though `imgtool` hands over linear values (it clamps them to
//! [0, 1] and passes them straight in). NVIDIA's later releases (the
//! `flip-evaluator` package, FLIP 1.x) compute the same LDR metric with
//! restructured filtering; their means agree with these to about 1e-4
//! relative (see the tests). pbrt-v4's variant is the one kept here.

use rayon::prelude::*;

use crate::image::{Image, ImageError};

/// FLIP's colour-difference compression exponent (q_c).
const QC: f32 = 0.7;
/// Fraction of the largest colour difference that maps to `PT` (p_c).
const PC: f32 = 0.4;
/// Error value at the colour-difference knee (p_t).
const PT: f32 = 0.95;
/// Feature detectors' width in degrees of visual angle (w).
const W: f32 = 0.082;
/// Feature-difference exponent (q_f).
const QF: f32 = 0.5;

/// The D65 white point in XYZ used by the colour conversions (the
/// reference code's literals, rounded to `f32` as its compiler does).
#[allow(clippy::excessive_precision)]
const D65: [f32; 3] = [0.950428545377181, 1.0, 1.088900370798128];

/// The viewing conditions: FLIP measures what a viewer resolves, which
/// depends on how many pixels fall in one degree of visual angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipOptions {
    /// Pixels per degree of visual angle.
    pub ppd: f32,
}

impl Default for FlipOptions {
    /// FLIP's default viewer (and pbrt-v4's): a 0.7 m wide, 3840-pixel
    /// monitor seen from 0.7 m, about 67 pixels per degree.
    fn default() -> Self {
        FlipOptions {
            ppd: pixels_per_degree(0.7, 3840.0, 0.7),
        }
    }
}

/// Pixels per degree for a monitor `monitor_width` metres wide with
/// `resolution_x` pixels across, seen from `distance` metres.
pub fn pixels_per_degree(distance: f32, resolution_x: f32, monitor_width: f32) -> f32 {
    distance * (resolution_x / monitor_width) * (std::f32::consts::PI / 180.0)
}

/// FLIP of an image against a reference: the per-pixel error image and
/// its mean as pbrt-v4's `imgtool diff` reports it.
#[derive(Clone, Debug)]
pub struct FlipError {
    /// The FLIP value of every pixel, in [0, 1]: a float image with one
    /// channel named `Error` (what pbrt-v4 writes with `--outfile`).
    pub image: Image,
    /// The mean over all pixels, summed in single precision in scanline
    /// order as pbrt-v4 does.
    pub mean: f64,
}

/// FLIP of `image` against `reference`, both three-channel images of the
/// same resolution (pbrt-v4 refuses other channel counts). Values are
/// clamped to [0, 1] first; NaN counts as 0 (pbrt-v4 would pass it through
/// and print a NaN mean).
pub fn flip(image: &Image, reference: &Image, opts: FlipOptions) -> Result<FlipError, ImageError> {
    if image.n_channels() != 3 || reference.n_channels() != 3 {
        return Err(ImageError::Invalid(format!(
            "only 3 channel images are supported for FLIP (the image has {}, the reference {})",
            image.n_channels(),
            reference.n_channels()
        )));
    }
    if image.resolution() != reference.resolution() {
        let (a, b) = (image.resolution(), reference.resolution());
        return Err(ImageError::Invalid(format!(
            "image resolution {}x{} does not match the reference's {}x{}",
            a.x, a.y, b.x, b.y
        )));
    }
    let res = image.resolution();
    let (w, h) = (res.x.max(0) as usize, res.y.max(0) as usize);
    let pixels = |im: &Image| -> Vec<[f32; 3]> {
        let clamp = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        im.to_f32_vec()
            .chunks_exact(3)
            .map(|p| [clamp(p[0]), clamp(p[1]), clamp(p[2])])
            .collect()
    };
    let errors = flip_error(&pixels(image), &pixels(reference), w, h, opts.ppd);
    // pbrt-v4 adds the error into each of the three channels' `Float`
    // sums, divides by the pixel count and averages the three.
    let mut sum = 0.0f32;
    for &e in &errors {
        sum += e;
    }
    let mean = if errors.is_empty() {
        0.0
    } else {
        let m = sum / errors.len() as f32;
        ((m + m + m) / 3.0) as f64
    };
    Ok(FlipError {
        image: Image::from_f32(errors, res, &["Error"])?,
        mean,
    })
}

/// The per-pixel FLIP error of `test` against `reference`, both `width` x
/// `height` sRGB-encoded values in [0, 1], scanline order. The metric is
/// symmetric: swapping the two images gives the same values.
pub fn flip_error(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: usize,
    height: usize,
    ppd: f32,
) -> Vec<f32> {
    debug_assert_eq!(test.len(), width * height);
    debug_assert_eq!(reference.len(), width * height);
    let to_ycxcz = |p: &[f32; 3]| xyz_to_ycxcz(linear_rgb_to_xyz(p.map(srgb_to_linear)));
    let ref_y: Vec<[f32; 3]> = reference.iter().map(to_ycxcz).collect();
    let test_y: Vec<[f32; 3]> = test.iter().map(to_ycxcz).collect();

    // The colour pipeline.
    let csf = Kernel::spatial(ppd);
    let ref_lab = preprocess(&ref_y, width, height, &csf);
    let test_lab = preprocess(&test_y, width, height, &csf);
    let cmax = max_color_distance();
    let pccmax = PC * cmax;
    let color: Vec<f32> = ref_lab
        .iter()
        .zip(&test_lab)
        .map(|(r, t)| {
            let e = hyab(r, t).powf(QC);
            if e < pccmax {
                e * (PT / pccmax)
            } else {
                PT + ((e - pccmax) / (cmax - pccmax)) * (1.0 - PT)
            }
        })
        .collect();

    // The feature pipeline, on the achromatic channel normalised to [0, 1].
    let gray = |im: &[[f32; 3]]| -> Vec<[f32; 3]> {
        im.iter()
            .map(|p| {
                let c = (p[0] + 16.0) / 116.0;
                [c, c, 0.0]
            })
            .collect()
    };
    let (ref_g, test_g) = (gray(&ref_y), gray(&test_y));
    let edges = Kernel::detector(ppd, false);
    let points = Kernel::detector(ppd, true);
    let er = edges.convolve(&ref_g, width, height);
    let et = edges.convolve(&test_g, width, height);
    let pr = points.convolve(&ref_g, width, height);
    let pt = points.convolve(&test_g, width, height);
    let norm = 1.0 / 2.0f32.sqrt();
    let len = |p: &[f32; 3]| (p[0] * p[0] + p[1] * p[1]).sqrt();
    (0..width * height)
        .map(|i| {
            let edge = (len(&er[i]) - len(&et[i])).abs();
            let point = (len(&pr[i]) - len(&pt[i])).abs();
            let feature = (norm * edge.max(point)).powf(QF);
            color[i].powf(1.0 - feature)
        })
        .collect()
}

/// A square, odd-width kernel of per-channel weights.
struct Kernel {
    width: usize,
    weights: Vec<[f32; 3]>,
}

impl Kernel {
    /// The contrast sensitivity functions of the achromatic and the two
    /// chromatic channels as sums of Gaussians over visual angle, each
    /// normalised to unit sum.
    fn spatial(ppd: f32) -> Kernel {
        let dx = 1.0 / ppd;
        let pi = std::f32::consts::PI;
        let pi_sq = (std::f64::consts::PI * std::f64::consts::PI) as f32;
        let a1 = [1.0f32, 1.0, 34.1];
        let b1 = [0.0047f32, 0.0053, 0.04];
        let a2 = [0.0f32, 0.0, 13.5];
        let b2 = [1.0e-5f32, 1.0e-5, 0.025];
        let max_b = b1[0].max(b1[1]).max(b1[2].max(b2[0])).max(b2[1].max(b2[2]));
        let radius = (3.0 * (max_b / (2.0 * pi_sq)).sqrt() * ppd).ceil() as i64;
        let width = (2 * radius + 1) as usize;
        let gauss_sum = |x2: f32, c: usize| {
            a1[c] * (pi / b1[c]).sqrt() * (-pi_sq * x2 / b1[c]).exp()
                + a2[c] * (pi / b2[c]).sqrt() * (-pi_sq * x2 / b2[c]).exp()
        };
        let mut weights = Vec::with_capacity(width * width);
        let mut sum = [0.0f32; 3];
        for y in 0..width {
            let iy = (y as i64 - radius) as f32 * dx;
            for x in 0..width {
                let ix = (x as i64 - radius) as f32 * dx;
                let d2 = ix * ix + iy * iy;
                let v = [gauss_sum(d2, 0), gauss_sum(d2, 1), gauss_sum(d2, 2)];
                for c in 0..3 {
                    sum[c] += v[c];
                }
                weights.push(v);
            }
        }
        for v in &mut weights {
            for c in 0..3 {
                v[c] /= sum[c];
            }
        }
        Kernel { width, weights }
    }

    /// The edge (first derivative of a Gaussian) or point (second
    /// derivative) detectors, horizontal in channel 0 and vertical in
    /// channel 1, with positive weights summing to 1 and negative ones to
    /// -1.
    fn detector(ppd: f32, point: bool) -> Kernel {
        let sd = 0.5 * W * ppd;
        let radius = (3.0 * sd).ceil() as i64;
        let width = (2 * radius + 1) as usize;
        let mut weights = Vec::with_capacity(width * width);
        let (mut pos, mut neg) = ([0.0f32; 2], [0.0f32; 2]);
        for y in 0..width {
            let yy = (y as i64 - radius) as f32;
            for x in 0..width {
                let xx = (x as i64 - radius) as f32;
                let g = (-(xx * xx + yy * yy) / (2.0 * sd * sd)).exp();
                let (wx, wy) = if point {
                    (
                        (xx * xx / (sd * sd) - 1.0) * g,
                        (yy * yy / (sd * sd) - 1.0) * g,
                    )
                } else {
                    (-xx * g, -yy * g)
                };
                for (c, w) in [wx, wy].into_iter().enumerate() {
                    if w > 0.0 {
                        pos[c] += w;
                    } else {
                        neg[c] += -w;
                    }
                }
                weights.push([wx, wy, 0.0]);
            }
        }
        for v in &mut weights {
            for c in 0..2 {
                v[c] /= if v[c] > 0.0 { pos[c] } else { neg[c] };
            }
        }
        Kernel { width, weights }
    }

    /// Convolves `image` with the kernel, replicating the border pixels,
    /// summing in the reference code's order (rows outer, columns inner).
    fn convolve(&self, image: &[[f32; 3]], width: usize, height: usize) -> Vec<[f32; 3]> {
        let half = (self.width / 2) as i64;
        let mut out = vec![[0.0f32; 3]; width * height];
        out.par_chunks_mut(width.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for (x, o) in row.iter_mut().enumerate() {
                    let mut s = [0.0f32; 3];
                    for iy in -half..=half {
                        let yy = (y as i64 + iy).clamp(0, height as i64 - 1) as usize;
                        let krow = &self.weights[(iy + half) as usize * self.width..];
                        for ix in -half..=half {
                            let xx = (x as i64 + ix).clamp(0, width as i64 - 1) as usize;
                            let w = krow[(ix + half) as usize];
                            let p = image[yy * width + xx];
                            s = [s[0] + w[0] * p[0], s[1] + w[1] * p[1], s[2] + w[2] * p[2]];
                        }
                    }
                    *o = s;
                }
            });
        out
    }
}

/// Filters a YCxCz image with the contrast sensitivity functions, clamps
/// it to the displayable (linear RGB in [0, 1]) range and returns it in
/// Hunt-adjusted L*a*b*.
fn preprocess(image: &[[f32; 3]], width: usize, height: usize, csf: &Kernel) -> Vec<[f32; 3]> {
    csf.convolve(image, width, height)
        .into_iter()
        .map(|p| {
            let rgb = xyz_to_linear_rgb(ycxcz_to_xyz(p)).map(|v| v.clamp(0.0, 1.0));
            hunt(xyz_to_lab(linear_rgb_to_xyz(rgb)))
        })
        .collect()
}

/// The largest Hunt-adjusted HyAB distance between displayable colours
/// (pure green against pure blue), compressed by `QC`.
fn max_color_distance() -> f32 {
    let green = hunt(xyz_to_lab(linear_rgb_to_xyz([0.0, 1.0, 0.0])));
    let blue = hunt(xyz_to_lab(linear_rgb_to_xyz([0.0, 0.0, 1.0])));
    hyab(&green, &blue).powf(QC)
}

/// Scales the chromatic channels by luminance (the Hunt effect).
fn hunt(lab: [f32; 3]) -> [f32; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// The HyAB distance: city-block in lightness, Euclidean in a*b*.
fn hyab(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    let (da, db) = (a[1] - b[1], a[2] - b[2]);
    (a[0] - b[0]).abs() + (da * da + db * db).sqrt()
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_rgb_to_xyz(v: [f32; 3]) -> [f32; 3] {
    let m = [
        [
            10135552.0f32 / 24577794.0,
            8788810.0f32 / 24577794.0,
            4435075.0f32 / 24577794.0,
        ],
        [
            2613072.0f32 / 12288897.0,
            8788810.0f32 / 12288897.0,
            887015.0f32 / 12288897.0,
        ],
        [
            1425312.0f32 / 73733382.0,
            8788810.0f32 / 73733382.0,
            70074185.0f32 / 73733382.0,
        ],
    ];
    m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2])
}

#[allow(clippy::excessive_precision)]
fn xyz_to_linear_rgb(v: [f32; 3]) -> [f32; 3] {
    let m: [[f32; 3]; 3] = [
        [3.241003232976358, -1.537398969488785, -0.498615881996363],
        [-0.969224252202516, 1.875929983695176, 0.041554226340085],
        [0.055639419851975, -0.204011206123910, 1.057148977187533],
    ];
    m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2])
}

fn xyz_to_ycxcz(v: [f32; 3]) -> [f32; 3] {
    let (x, y, z) = (v[0] / D65[0], v[1] / D65[1], v[2] / D65[2]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_xyz(v: [f32; 3]) -> [f32; 3] {
    let yy = (v[0] + 16.0) / 116.0;
    let (cx, cz) = (v[1] / 500.0, v[2] / 200.0);
    [(yy + cx) * D65[0], yy * D65[1], (yy - cz) * D65[2]]
}

fn xyz_to_lab(v: [f32; 3]) -> [f32; 3] {
    let f = |t: f32| {
        // The reference code compares against a double constant.
        if t as f64 > 0.008856 {
            t.powf(1.0 / 3.0)
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (x, y, z) = (
        f(v[0].abs() / D65[0]),
        f(v[1].abs() / D65[1]),
        f(v[2].abs() / D65[2]),
    );
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

#[cfg(test)]
mod tests;
