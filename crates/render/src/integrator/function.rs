//! pbrt-v4's `function` integrator (`FunctionIntegrator`,
//! `cpu/integrators.cpp`): no light transport, but a bench for the
//! samplers of book chapter 8. Every pixel integrates a 2-D test function
//! over [0,1)² with the scene's sampler, one sample per pixel per sample
//! count, and after each count the mean squared error of the per-pixel
//! estimates against the true integral (1) is recorded. The result is a
//! text file of `N mse` lines, the error as a function of the sample
//! count, whose slope says how fast a sampler converges on that kind of
//! integrand (a step, an edge, a disk, ...).
//!
//! As in pbrt-v4, the samplers whose pixel points are built from a
//! sequence shared by all pixels are not driven through their
//! `start_pixel_sample` (which would place each pixel's points in a
//! different part of the sequence): `halton` takes the radical inverses of
//! the sample index with per-pixel digit permutations or Owen scrambling,
//! `paddedsobol` takes the Sobol' points of the sample index with
//! per-pixel scramblers, and `stratified` takes a fresh jittered `nx × ny`
//! grid at each count. Every other sampler gives its `get_pixel_2d`.
//!
//! Determinism: each pixel's running sum depends on its own samples only
//! (per-pixel randomisation is drawn in pixel order before sampling), and
//! the error is summed in pixel order, so the file is the same for any
//! thread count.

use super::render::{
    thread_pool, with_progress, ProgressFn, RenderError, RenderOptions, RenderStats,
};
use super::Scene;
use crate::filter::erf;
use crate::image::{Image, ImageMetadata};
use crate::rng::{mix_bits, Rng};
use crate::sampler::lowdiscrepancy::{
    owen_scrambled_radical_inverse, radical_inverse, scrambled_radical_inverse, sobol_sample,
    BinaryScrambler, DigitPermutation, RandomizeStrategy,
};
use crate::sampler::Sampler;
use rayon::prelude::*;
use rpbrt_geometry::float::{Float, PI};
use rpbrt_geometry::tuple::*;
use std::sync::atomic::Ordering;
use std::sync::OnceLock;
use std::time::Instant;

/// The test functions of pbrt-v4's `function` integrator; each integrates
/// to 1 over [0,1)².
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestFunction {
    /// 2 for x < ½, else 0: one axis-aligned edge.
    Step,
    /// 2 below the diagonal x + y = 1, else 0.
    Diagonal,
    /// 1/(π/4) inside the disk of radius ½ at the centre, else 0.
    Disk,
    /// A 10×10 checkerboard of 2s and 0s.
    Checkerboard,
    /// The checkerboard rotated by 45°, normalised by its measured mean.
    RotatedCheckerboard,
    /// A separable Gaussian (μ = ½, σ = ¼), normalised over the square.
    Gaussian,
}

impl TestFunction {
    /// The scene-file names, as `"string function"` takes them.
    pub const NAMES: [&'static str; 6] = [
        "step",
        "diagonal",
        "disk",
        "checkerboard",
        "rotatedcheckerboard",
        "gaussian",
    ];

    /// The function of a scene-file name.
    pub fn from_name(name: &str) -> Option<TestFunction> {
        Some(match name {
            "step" => TestFunction::Step,
            "diagonal" => TestFunction::Diagonal,
            "disk" => TestFunction::Disk,
            "checkerboard" => TestFunction::Checkerboard,
            "rotatedcheckerboard" => TestFunction::RotatedCheckerboard,
            "gaussian" => TestFunction::Gaussian,
            _ => return None,
        })
    }

    /// The function's scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            TestFunction::Step => "step",
            TestFunction::Diagonal => "diagonal",
            TestFunction::Disk => "disk",
            TestFunction::Checkerboard => "checkerboard",
            TestFunction::RotatedCheckerboard => "rotatedcheckerboard",
            TestFunction::Gaussian => "gaussian",
        }
    }

    /// The function's value at `p`. pbrt-v4 computes the values in double
    /// precision and hands them on through a `Float` function, so they
    /// are rounded to `Float` here too.
    #[inline]
    pub fn eval(self, p: Point2f) -> Float {
        match self {
            TestFunction::Step => {
                if p.x < 0.5 {
                    2.0
                } else {
                    0.0
                }
            }
            TestFunction::Diagonal => {
                if p.x + p.y < 1.0 {
                    2.0
                } else {
                    0.0
                }
            }
            TestFunction::Disk => {
                let (dx, dy) = (p.x - 0.5, p.y - 0.5);
                if (dx * dx + dy * dy).sqrt() < 0.5 {
                    (1.0 / (PI as f64 * 0.25)) as Float
                } else {
                    0.0
                }
            }
            TestFunction::Checkerboard => checkerboard(p.x, p.y) as Float,
            TestFunction::RotatedCheckerboard => {
                // pbrt-v4's 45° goes through `Radians` in `Float`; the
                // normalisation is the rotated board's mean over the square.
                const NORM: f64 = 1.000_068_664_550_781_3;
                let angle = ((PI / 180.0) * 45.0) as f64;
                let (sa, ca) = angle.sin_cos();
                let (x, y) = (p.x as f64, p.y as f64);
                let q = (
                    (10.0 + x * ca - y * sa) as Float,
                    (10.0 + x * sa + y * ca) as Float,
                );
                (checkerboard(q.0, q.1) / NORM) as Float
            }
            TestFunction::Gaussian => {
                let g = |x: f64| {
                    let (mu, sigma) = (0.5, 0.25);
                    1.0 / ((2.0 * PI) as f64 * sigma * sigma).sqrt()
                        * (-(x - mu) * (x - mu) / (2.0 * sigma * sigma)).exp()
                };
                (g(p.x as f64) * g(p.y as f64) / gaussian_norm()) as Float
            }
        }
    }
}

/// The 10×10 checkerboard: 2 where the cell's coordinates differ in
/// parity (cells by truncation, as pbrt-v4's `Point2i` conversion).
#[inline]
fn checkerboard(x: Float, y: Float) -> f64 {
    let (ix, iy) = ((x * 10.0) as i32, (y * 10.0) as i32);
    if (ix & 1) ^ (iy & 1) != 0 {
        2.0
    } else {
        0.0
    }
}

/// The square of the Gaussian's integral over [0,1] (μ = ½, σ = ¼).
fn gaussian_norm() -> f64 {
    static NORM: OnceLock<f64> = OnceLock::new();
    *NORM.get_or_init(|| {
        let (mu, sigma) = (0.5f64, 0.25f64);
        let s = sigma * std::f64::consts::SQRT_2;
        let integral = 0.5 * (erf((mu - 0.0) / s) - erf((mu - 1.0) / s));
        integral * integral
    })
}

/// pbrt-v4's `function` integrator.
#[derive(Clone, Debug)]
pub struct FunctionIntegrator {
    /// The function integrated in every pixel.
    pub function: TestFunction,
    /// The file the `N mse` lines are written to.
    pub filename: String,
    /// Skip (or leave out of the file) the sample counts the sampler is
    /// not designed for: non-square counts for `stratified`, counts other
    /// than powers of two for `paddedsobol`, other than 2^k·3^k for
    /// `halton`.
    pub skip_bad: bool,
    /// Where to write an image of the function (256 random samples per
    /// pixel over the film's resolution), if anywhere.
    pub image_filename: Option<String>,
}

/// How each sample count's points are made (pbrt-v4's special cases).
enum PixelPoints {
    /// A fresh jittered grid per count.
    Stratified,
    /// Radical inverses of the sample index, randomised per pixel.
    Halton {
        strategy: RandomizeStrategy,
        /// Per pixel, bases 2 and 3 (built for digit permutation only).
        permutations: [Vec<DigitPermutation>; 2],
        /// Per pixel, the Owen-scrambling seeds of the two dimensions.
        hashes: [Vec<u64>; 2],
    },
    /// Sobol' points of the sample index, scrambled per pixel.
    PaddedSobol {
        strategy: RandomizeStrategy,
        hashes: [Vec<u64>; 2],
    },
    /// The sampler's own pixel samples.
    Sampler,
}

impl PixelPoints {
    /// The points for `sampler`, with per-pixel randomisation drawn from
    /// pbrt-v4's default-seeded generator in pixel order: the halton
    /// digit-permutation seeds of both dimensions, then the scrambling
    /// seeds (the permutation seeds are drawn whatever the strategy, so
    /// the scrambling seeds are pbrt-v4's).
    fn new(sampler: &Sampler, n_pixels: usize) -> PixelPoints {
        let mut rng = Rng::default();
        let hashes = |rng: &mut Rng| {
            let mut h = || (0..n_pixels).map(|_| rng.uniform_u64()).collect::<Vec<_>>();
            [h(), h()]
        };
        match sampler {
            Sampler::Stratified(_) => PixelPoints::Stratified,
            Sampler::Halton(s) => {
                let strategy = s.randomize();
                let permutations = [2, 3].map(|base| {
                    let seeds = (0..n_pixels).map(|_| rng.uniform_u32()).collect::<Vec<_>>();
                    if strategy == RandomizeStrategy::PermuteDigits {
                        seeds
                            .into_iter()
                            .map(|seed| DigitPermutation::new(base, seed))
                            .collect()
                    } else {
                        Vec::new()
                    }
                });
                PixelPoints::Halton {
                    strategy,
                    permutations,
                    hashes: hashes(&mut rng),
                }
            }
            Sampler::PaddedSobol(s) => PixelPoints::PaddedSobol {
                strategy: s.randomize(),
                hashes: hashes(&mut rng),
            },
            _ => PixelPoints::Sampler,
        }
    }

    /// What pbrt-v4's `skipbad` does with the sample count `n`.
    fn count_use(&self, n: i32) -> CountUse {
        match self {
            PixelPoints::Stratified => {
                let r = (n as f64).sqrt() as i32;
                if r * r == n {
                    CountUse::Report
                } else {
                    CountUse::Skip
                }
            }
            PixelPoints::PaddedSobol { .. } if n & (n - 1) != 0 => CountUse::Silent,
            PixelPoints::Halton { .. } => {
                let (mut m, mut n2, mut n3) = (n, 0, 0);
                loop {
                    if m % 2 == 0 {
                        m /= 2;
                        n2 += 1;
                    } else if m % 3 == 0 {
                        m /= 3;
                        n3 += 1;
                    } else {
                        break;
                    }
                }
                if m == 1 && n2 == n3 {
                    CountUse::Report
                } else {
                    CountUse::Silent
                }
            }
            _ => CountUse::Report,
        }
    }

    /// Sample `index` of pixel `pixel` (row-major within the film's pixel
    /// bounds) for the halton and paddedsobol cases.
    #[inline]
    fn sequence_point(&self, pixel: usize, index: i32) -> Point2f {
        let a = index as u64;
        match self {
            PixelPoints::Halton {
                strategy,
                permutations,
                hashes,
            } => match strategy {
                RandomizeStrategy::None => {
                    Point2f::new(radical_inverse(0, a), radical_inverse(1, a))
                }
                RandomizeStrategy::PermuteDigits => Point2f::new(
                    scrambled_radical_inverse(0, a, &permutations[0][pixel]),
                    scrambled_radical_inverse(1, a, &permutations[1][pixel]),
                ),
                // The halton sampler runs FastOwen as Owen.
                _ => Point2f::new(
                    owen_scrambled_radical_inverse(0, a, hashes[0][pixel] as u32),
                    owen_scrambled_radical_inverse(1, a, hashes[1][pixel] as u32),
                ),
            },
            PixelPoints::PaddedSobol { strategy, hashes } => Point2f::new(
                sobol_sample(
                    a,
                    0,
                    BinaryScrambler::new(*strategy, hashes[0][pixel] as u32),
                ),
                sobol_sample(
                    a,
                    1,
                    BinaryScrambler::new(*strategy, hashes[1][pixel] as u32),
                ),
            ),
            _ => {
                debug_assert!(false, "not a sequence sampler");
                Point2f::new(0.5, 0.5)
            }
        }
    }
}

/// A sample count under `skipbad`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CountUse {
    /// Not taken at all (stratified grids that are not square).
    Skip,
    /// Taken, but its error is not written.
    Silent,
    /// Taken and written.
    Report,
}

/// The jittered `nx × ny` grid of `spp` points pbrt-v4 takes in one pixel
/// for the stratified sampler: `nx` the largest divisor of `spp` up to
/// √spp. Returns the sum of the function over the grid.
fn stratified_sum(f: TestFunction, spp: i32, pixel: usize, sample_index: i32) -> (Float, i32) {
    let mut nx = ((spp as f64).sqrt() as i32).max(1);
    while spp % nx != 0 {
        nx -= 1;
    }
    let ny = spp / nx;
    let mut rng = Rng::new(pixel as u64, mix_bits(sample_index as u64 + 1));
    let mut v: Float = 0.0;
    for x in 0..nx {
        for y in 0..ny {
            let ux = (x as Float + rng.uniform_float()) / nx as Float;
            let uy = (y as Float + rng.uniform_float()) / ny as Float;
            v += f.eval(Point2f::new(ux, uy));
        }
    }
    (v, nx * ny)
}

/// The image of `f` over `res` pixels: the mean of 256 uniform random
/// samples per pixel from pbrt-v4's default-seeded generator, in scanline
/// order, as one `Y` channel.
fn function_image(f: TestFunction, res: Point2i) -> Result<Image, crate::image::ImageError> {
    const N: usize = 256;
    let mut rng = Rng::default();
    let mut data = Vec::with_capacity(res.x.max(0) as usize * res.y.max(0) as usize);
    for y in 0..res.y {
        for x in 0..res.x {
            let mut sum: Float = 0.0;
            for _ in 0..N {
                let ux = (x as Float + rng.uniform_float()) / res.x as Float;
                let uy = (y as Float + rng.uniform_float()) / res.y as Float;
                sum += f.eval(Point2f::new(ux, uy));
            }
            data.push(sum / N as Float);
        }
    }
    Image::from_f32(data, res, &["Y"])
}

/// What the sampling loop leaves.
struct Sampled {
    /// Per pixel, the running sum (for stratified: the last grid's mean
    /// times the counts taken, so that sum / taken is its estimate).
    sums: Vec<f64>,
    /// Sample counts taken.
    taken: u64,
    /// The file's text.
    text: String,
    /// The reported (count, error) pairs.
    errors: Vec<(i32, f64)>,
    /// Function evaluations.
    evaluations: u64,
    /// Stopped before the last count.
    interrupted: bool,
}

/// Renders with the `function` integrator (pbrt-v4
/// `FunctionIntegrator::Render`): writes the image of the function if
/// asked, then the error file. A warning is returned in the statistics
/// when the average estimate is not within 0.1% of 1.
pub(crate) fn render(
    integrator: &FunctionIntegrator,
    scene: &Scene,
    opts: &RenderOptions,
    progress: ProgressFn,
) -> Result<RenderStats, RenderError> {
    let start = Instant::now();
    let pool = thread_pool(opts)?;
    let f = integrator.function;
    let bounds = scene.film.pixel_bounds();
    let width = (bounds.p_max.x - bounds.p_min.x).max(0) as usize;
    let height = (bounds.p_max.y - bounds.p_min.y).max(0) as usize;
    let n_pixels = width * height;
    let n_samples = scene.sampler.samples_per_pixel().max(0);

    if let Some(path) = &integrator.image_filename {
        let res = Point2i::new(width as i32, height as i32);
        function_image(f, res)
            .and_then(|im| im.write(path, &ImageMetadata::default()))
            .map_err(|source| RenderError::WriteImage {
                path: path.clone(),
                source,
            })?;
    }

    let points = PixelPoints::new(&scene.sampler, n_pixels);
    let sampled = with_progress(n_samples as u64, start, progress, |done| {
        let mut s = Sampled {
            sums: vec![0.0; n_pixels],
            taken: 0,
            text: String::new(),
            errors: Vec::new(),
            evaluations: 0,
            interrupted: false,
        };
        for sample_index in 0..n_samples {
            if opts.interrupted() {
                s.interrupted = true;
                break;
            }
            let spp = sample_index + 1;
            let count_use = if integrator.skip_bad {
                points.count_use(spp)
            } else {
                CountUse::Report
            };
            if count_use == CountUse::Skip {
                done.fetch_add(1, Ordering::Relaxed);
                continue;
            }
            s.taken += 1;
            let taken = s.taken;
            // Rows in parallel; each pixel's sum depends on its own
            // samples only.
            let rows = s.sums.par_chunks_mut(width.max(1)).enumerate();
            match &points {
                PixelPoints::Stratified => {
                    pool.install(|| {
                        rows.for_each(|(row, sums)| {
                            for (col, sum) in sums.iter_mut().enumerate() {
                                let (v, n) =
                                    stratified_sum(f, spp, row * width + col, sample_index);
                                // The grid's mean, scaled by the counts
                                // taken so that sum / taken is the estimate.
                                *sum = (v * taken as Float / n as Float) as f64;
                            }
                        })
                    });
                    s.evaluations += n_pixels as u64 * spp as u64;
                }
                PixelPoints::Halton { .. } | PixelPoints::PaddedSobol { .. } => {
                    pool.install(|| {
                        rows.for_each(|(row, sums)| {
                            for (col, sum) in sums.iter_mut().enumerate() {
                                let u = points.sequence_point(row * width + col, sample_index);
                                *sum += f.eval(u) as f64;
                            }
                        })
                    });
                    s.evaluations += n_pixels as u64;
                }
                PixelPoints::Sampler => {
                    pool.install(|| {
                        rows.for_each_init(
                            || scene.sampler.clone(),
                            |sampler, (row, sums)| {
                                let y = bounds.p_min.y + row as i32;
                                for (col, sum) in sums.iter_mut().enumerate() {
                                    let p = Point2i::new(bounds.p_min.x + col as i32, y);
                                    sampler.start_pixel_sample(p, sample_index, 0);
                                    *sum += f.eval(sampler.get_pixel_2d()) as f64;
                                }
                            },
                        )
                    });
                    s.evaluations += n_pixels as u64;
                }
            }
            if count_use == CountUse::Report {
                let se: f64 = s
                    .sums
                    .iter()
                    .map(|&v| {
                        let e = v / taken as f64 - 1.0;
                        e * e
                    })
                    .sum();
                // pbrt-v4 keeps the error as a Float and prints it "%f".
                let mse = (se / n_pixels as f64) as Float;
                s.text.push_str(&format!("{spp} {mse:.6}\n"));
                s.errors.push((spp, mse as f64));
            }
            done.fetch_add(1, Ordering::Relaxed);
        }
        s
    });

    let mut warnings = Vec::new();
    if sampled.taken > 0 && n_pixels > 0 {
        let sum: f64 = sampled.sums.iter().sum();
        let avg = sum / (n_pixels as f64 * sampled.taken as f64);
        if !(0.999..=1.001).contains(&avg) {
            warnings.push(format!(
                "Average estimate is {avg:.6}, which is suspiciously far from 1."
            ));
        }
    }
    std::fs::write(&integrator.filename, &sampled.text).map_err(|source| {
        RenderError::WriteFile {
            path: integrator.filename.clone(),
            source,
        }
    })?;
    Ok(RenderStats {
        render_time: start.elapsed(),
        samples: sampled.evaluations,
        interrupted: sampled.interrupted,
        mse_per_wave: sampled.errors,
        warnings,
    })
}

#[cfg(test)]
mod tests;
