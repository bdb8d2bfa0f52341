//! Error metrics of an image against a reference (pbrt-v4 `Image::MSE`,
//! `Image::MRSE` and the mean absolute error `imgtool diff --metric`
//! offers) and the estimate behind `imgtool error`: the mean error of a
//! set of independent renders with a confidence interval from their
//! spread, and the per-pixel variance image.

use crate::image::ColorEncoding;
use crate::image::{Image, ImageError, PixelFormat};

/// An error metric of `imgtool diff` and `imgtool error`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Mean squared error, (v - r)^2.
    Mse,
    /// Mean absolute error, |v - r|.
    Mae,
    /// Mean relative squared error, (v - r)^2 / (r + 0.01)^2.
    Mrse,
}

impl Metric {
    /// The metric by pbrt-v4's name (`MSE`, `MAE`, `MRSE`), any case.
    pub fn parse(name: &str) -> Option<Metric> {
        match name.to_ascii_uppercase().as_str() {
            "MSE" => Some(Metric::Mse),
            "MAE" => Some(Metric::Mae),
            "MRSE" => Some(Metric::Mrse),
            _ => None,
        }
    }

    /// pbrt-v4's name of the metric.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mse => "MSE",
            Metric::Mae => "MAE",
            Metric::Mrse => "MRSE",
        }
    }

    /// The per-value error term, computed in single precision as pbrt-v4
    /// does (so an overflowing term is infinite and left out of sums).
    #[inline]
    pub fn term(self, v: f32, r: f32) -> f32 {
        let d = v - r;
        match self {
            Metric::Mse => d * d,
            Metric::Mae => d.abs(),
            Metric::Mrse => d * d / ((r + 0.01) * (r + 0.01)),
        }
    }
}

/// The error of an image against a reference, per channel, with the
/// image of the per-value terms.
#[derive(Clone, Debug)]
pub struct MetricError {
    /// The channels compared, in the image's order.
    pub channels: Vec<String>,
    /// The mean error of each channel over all pixels.
    pub per_channel: Vec<f64>,
    /// The error term of every pixel and channel (float, the image's
    /// channel names; 0 where the term was infinite).
    pub image: Image,
}

impl MetricError {
    /// The mean of the per-channel errors (pbrt-v4's
    /// `ImageChannelValues::Average`).
    pub fn average(&self) -> f64 {
        if self.per_channel.is_empty() {
            return 0.0;
        }
        self.per_channel.iter().sum::<f64>() / self.per_channel.len() as f64
    }

    /// The largest per-channel error.
    pub fn max(&self) -> f64 {
        self.per_channel
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Checks that `reference` has `image`'s resolution and channels and
/// returns the reference's values in the image's channel order.
pub(crate) fn reference_values(image: &Image, reference: &Image) -> Result<Vec<f32>, ImageError> {
    if image.resolution() != reference.resolution() {
        let (a, b) = (image.resolution(), reference.resolution());
        return Err(ImageError::Invalid(format!(
            "image resolution {}x{} does not match the reference's {}x{}",
            a.x, a.y, b.x, b.y
        )));
    }
    let desc = reference
        .get_channel_desc(image.channel_names())
        .ok_or_else(|| {
            ImageError::Invalid(format!(
                "the reference lacks some of the channels {} (it has {})",
                image.channel_names().join(","),
                reference.channel_names().join(",")
            ))
        })?;
    Ok(reference.select_channels(&desc).to_f32_vec())
}

/// The error of `image` against `reference` under `metric`, over all of
/// the image's channels (pbrt-v4 `Image::MSE` and kin): each channel's
/// terms are summed in double precision, infinite terms skipped, and
/// divided by the pixel count.
pub fn metric_error(
    image: &Image,
    reference: &Image,
    metric: Metric,
) -> Result<MetricError, ImageError> {
    let rv = reference_values(image, reference)?;
    let iv = image.to_f32_vec();
    let nc = image.n_channels();
    let names = image.channel_names().to_vec();
    let mut sums = vec![0.0f64; nc];
    let mut terms = vec![0.0f32; iv.len()];
    for (i, (&v, &r)) in iv.iter().zip(&rv).enumerate() {
        let t = metric.term(v, r);
        if t.is_infinite() {
            continue;
        }
        sums[i % nc.max(1)] += t as f64;
        terms[i] = t;
    }
    let res = image.resolution();
    let npix = (res.x.max(0) as usize * res.y.max(0) as usize).max(1) as f64;
    Ok(MetricError {
        per_channel: sums.into_iter().map(|s| s / npix).collect(),
        image: Image::from_f32(terms, res, &names)?,
        channels: names,
    })
}

/// Sets every infinite value of `image` to zero (as pbrt-v4's `diff` does
/// before comparing) and returns how many there were.
pub fn zero_infinities(image: &mut Image) -> usize {
    let vals = image.to_f32_vec();
    let mut n = 0;
    if vals.iter().any(|v| v.is_infinite()) {
        if image.format() != PixelFormat::Float {
            *image = image.convert_to_format(PixelFormat::Float, ColorEncoding::Linear);
        }
        for (i, v) in vals.into_iter().enumerate() {
            if v.is_infinite() {
                image.set_value_at(i, 0.0);
                n += 1;
            }
        }
    }
    n
}

/// The mean error of a set of renders against a reference, with its
/// uncertainty.
#[derive(Clone, Debug)]
pub struct ErrorEstimate {
    /// The metric used.
    pub metric: Metric,
    /// Each image's error (the average over channels).
    pub per_image: Vec<f64>,
    /// The mean of the images' errors: the estimate.
    pub mean: f64,
    /// The standard error of the mean (sample standard deviation over the
    /// square root of the count); NaN for a single image.
    pub std_error: f64,
    /// The 95% confidence interval for the expected error (Student's t with
    /// n - 1 degrees of freedom); NaN bounds for a single image.
    pub ci95: (f64, f64),
    /// Per pixel, the sample variance across the images of each channel's
    /// value (for MRSE, of v / (r + 0.01)), averaged over channels: one
    /// channel named after the metric (pbrt-v4's `--errorfile` image).
    pub variance_image: Image,
}

/// Student's t 97.5% quantiles for 1 to 30 degrees of freedom.
const T_975: [f64; 30] = [
    12.7062, 4.3027, 3.1824, 2.7764, 2.5706, 2.4469, 2.3646, 2.3060, 2.2622, 2.2281, 2.2010,
    2.1788, 2.1604, 2.1448, 2.1314, 2.1199, 2.1098, 2.1009, 2.0930, 2.0860, 2.0796, 2.0739, 2.0687,
    2.0639, 2.0595, 2.0555, 2.0518, 2.0484, 2.0452, 2.0423,
];

/// The 97.5% quantile of Student's t distribution with `dof` degrees of
/// freedom (the half-width factor of a two-sided 95% interval): tabulated
/// up to 30, beyond by the Cornish–Fisher expansion about the normal
/// quantile (error below 1e-4 there). NaN for no degrees of freedom.
pub fn student_t_975(dof: usize) -> f64 {
    if dof == 0 {
        return f64::NAN;
    }
    if dof <= T_975.len() {
        return T_975[dof - 1];
    }
    let z = 1.959_963_984_540_054f64;
    let v = dof as f64;
    let (z2, z3) = (z * z, z * z * z);
    let (z5, z7) = (z3 * z2, z3 * z2 * z2);
    z + (z3 + z) / (4.0 * v)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * v * v * v)
}

/// The error of each of `images` against `reference` under `metric`,
/// their mean and its 95% confidence interval, and the per-pixel
/// variance image (pbrt-v4 `imgtool error`). All images need the
/// reference's resolution and the image's channels in the reference.
pub fn estimate_error(
    images: &[Image],
    reference: &Image,
    metric: Metric,
) -> Result<ErrorEstimate, ImageError> {
    let Some(first) = images.first() else {
        return Err(ImageError::Invalid(
            "no images to estimate error from".into(),
        ));
    };
    let nc = first.n_channels();
    let res = reference.resolution();
    let nval = res.x.max(0) as usize * res.y.max(0) as usize * nc;
    // Welford's running mean and M2 per pixel and channel.
    let mut mean = vec![0.0f64; nval];
    let mut m2 = vec![0.0f64; nval];
    let mut per_image = Vec::with_capacity(images.len());
    for (k, im) in images.iter().enumerate() {
        if im.channel_names() != first.channel_names() {
            return Err(ImageError::Invalid(format!(
                "image {k}: channels {} differ from the first image's {}",
                im.channel_names().join(","),
                first.channel_names().join(",")
            )));
        }
        let err = metric_error(im, reference, metric)
            .map_err(|e| ImageError::Invalid(format!("image {k}: {e}")))?;
        per_image.push(err.average());
        let rv = reference_values(im, reference)?;
        let n = (k + 1) as f64;
        for (i, (&v, &r)) in im.to_f32_vec().iter().zip(&rv).enumerate() {
            let x = match metric {
                Metric::Mrse => v as f64 / (0.01 + r as f64),
                _ => v as f64,
            };
            let d = x - mean[i];
            mean[i] += d / n;
            m2[i] += d * (x - mean[i]);
        }
    }
    let n = images.len();
    let nf = n as f64;
    let est = per_image.iter().sum::<f64>() / nf;
    let (std_error, ci95) = if n > 1 {
        let var = per_image.iter().map(|e| (e - est) * (e - est)).sum::<f64>() / (nf - 1.0);
        let se = (var / nf).sqrt();
        let h = student_t_975(n - 1) * se;
        (se, (est - h, est + h))
    } else {
        (f64::NAN, (f64::NAN, f64::NAN))
    };
    let var_px: Vec<f32> = m2
        .chunks_exact(nc.max(1))
        .map(|px| {
            let s: f64 = px
                .iter()
                .map(|&m| if n > 1 { m / (nf - 1.0) } else { 0.0 })
                .sum();
            (s / nc.max(1) as f64) as f32
        })
        .collect();
    Ok(ErrorEstimate {
        metric,
        per_image,
        mean: est,
        std_error,
        ci95,
        variance_image: Image::from_f32(var_px, res, &[metric.name()])?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use rpbrt_geometry::Point2i;

    fn img(vals: &[f32], w: i32, h: i32, names: &[&str]) -> Image {
        Image::from_f32(vals.to_vec(), Point2i::new(w, h), names).unwrap()
    }

    #[test]
    fn metrics_match_hand_computed_values() {
        // 2x1 RGB image against a reference.
        let a = img(&[1.0, 0.5, 0.0, 2.0, 0.0, 0.25], 2, 1, &["R", "G", "B"]);
        let b = img(&[0.0, 0.5, 0.5, 1.0, 1.0, 0.25], 2, 1, &["R", "G", "B"]);
        let mse = metric_error(&a, &b, Metric::Mse).unwrap();
        // R: (1 + 1) / 2 = 1, G: (0 + 1) / 2 = 0.5, B: (0.25 + 0) / 2 = 0.125.
        assert_eq!(mse.per_channel, vec![1.0, 0.5, 0.125]);
        assert!((mse.average() - 1.625 / 3.0).abs() < 1e-12);
        let mae = metric_error(&a, &b, Metric::Mae).unwrap();
        assert_eq!(mae.per_channel, vec![1.0, 0.5, 0.25]);
        let mrse = metric_error(&a, &b, Metric::Mrse).unwrap();
        // R: 1/0.01^2 and 1/1.01^2, halved.
        let r = (1.0 / (0.01f64 * 0.01) + 1.0 / (1.01 * 1.01)) / 2.0;
        assert!((mrse.per_channel[0] - r).abs() / r < 1e-5);
        // The error image holds the terms.
        assert_eq!(mse.image.to_f32_vec(), vec![1.0, 0.0, 0.25, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn reference_channels_are_matched_by_name_and_mismatches_are_errors() {
        let a = img(&[1.0, 2.0], 1, 1, &["G", "R"]);
        let b = img(&[2.0, 1.0], 1, 1, &["R", "G"]);
        assert_eq!(metric_error(&a, &b, Metric::Mse).unwrap().max(), 0.0);
        let c = img(&[1.0], 1, 1, &["Y"]);
        assert!(metric_error(&a, &c, Metric::Mse).is_err());
        let d = img(&[1.0, 2.0, 1.0, 2.0], 2, 1, &["G", "R"]);
        assert!(metric_error(&a, &d, Metric::Mse)
            .unwrap_err()
            .to_string()
            .contains("resolution"));
    }

    #[test]
    fn infinite_terms_are_skipped_and_infinities_zeroed() {
        let a = img(&[f32::INFINITY, 1.0], 2, 1, &["Y"]);
        let b = img(&[0.0, 0.0], 2, 1, &["Y"]);
        // Only the finite term counts, over both pixels.
        assert_eq!(
            metric_error(&a, &b, Metric::Mse).unwrap().per_channel,
            vec![0.5]
        );
        let mut c = a.clone();
        assert_eq!(zero_infinities(&mut c), 1);
        assert_eq!(c.to_f32_vec(), vec![0.0, 1.0]);
    }

    #[test]
    fn t_quantiles_match_tables() {
        for (dof, t) in [
            (1, 12.706),
            (2, 4.303),
            (3, 3.182),
            (4, 2.776),
            (7, 2.365),
            (15, 2.131),
            (31, 2.040),
            (40, 2.021),
            (100, 1.984),
        ] {
            assert!((student_t_975(dof) - t).abs() < 2e-3, "{dof}");
        }
    }

    #[test]
    fn estimate_of_identical_images_is_their_error() {
        let a = img(&[1.0, 3.0], 2, 1, &["Y"]);
        let r = img(&[0.0, 1.0], 2, 1, &["Y"]);
        let e = estimate_error(&[a.clone(), a], &r, Metric::Mse).unwrap();
        // (1 + 4) / 2.
        assert_eq!(e.mean, 2.5);
        assert_eq!(e.std_error, 0.0);
        assert_eq!(e.ci95, (2.5, 2.5));
        assert_eq!(e.variance_image.to_f32_vec(), vec![0.0, 0.0]);
        assert_eq!(e.variance_image.channel_names(), ["MSE"]);
    }

    #[test]
    fn variance_image_is_the_per_pixel_sample_variance() {
        let r = img(&[0.0, 0.0], 1, 1, &["R", "G"]);
        let a = img(&[1.0, 2.0], 1, 1, &["R", "G"]);
        let b = img(&[3.0, 2.0], 1, 1, &["R", "G"]);
        let e = estimate_error(&[a, b], &r, Metric::Mse).unwrap();
        // R values 1, 3: variance 2; G: 0. Averaged: 1.
        assert_eq!(e.variance_image.to_f32_vec(), vec![1.0]);
        // Errors: (1 + 4)/2 = 2.5 and (9 + 4)/2 = 6.5.
        assert_eq!(e.per_image, vec![2.5, 6.5]);
        assert_eq!(e.mean, 4.5);
    }

    /// Seeded trials: each makes 8 renders = truth + Gaussian noise of
    /// standard deviation 0.1, whose expected MSE is 0.01; the 95%
    /// interval must cover 0.01 in about 95% of trials.
    #[test]
    fn confidence_interval_covers_the_true_mse() {
        let (w, h, n_images, trials) = (16, 16, 8, 200);
        let sigma = 0.1f64;
        let truth: Vec<f32> = (0..w * h).map(|i| (i % 7) as f32 * 0.1).collect();
        let reference = img(&truth, w, h, &["Y"]);
        let mut rng = Rng::with_sequence(42);
        let mut gauss = move || {
            // Box–Muller from two uniforms in (0, 1].
            let u1 = 1.0 - rng.uniform_float() as f64;
            let u2 = rng.uniform_float() as f64;
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        };
        let mut covered = 0;
        for _ in 0..trials {
            let images: Vec<Image> = (0..n_images)
                .map(|_| {
                    let v: Vec<f32> = truth
                        .iter()
                        .map(|&t| (t as f64 + sigma * gauss()) as f32)
                        .collect();
                    img(&v, w, h, &["Y"])
                })
                .collect();
            let e = estimate_error(&images, &reference, Metric::Mse).unwrap();
            if e.ci95.0 <= sigma * sigma && sigma * sigma <= e.ci95.1 {
                covered += 1;
            }
        }
        let rate = covered as f64 / trials as f64;
        assert!((0.88..=0.99).contains(&rate), "coverage {rate}");
    }
}
