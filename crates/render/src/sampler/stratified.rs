//! The stratified sampler (book section 8.5; pbrt-v4 `StratifiedSampler`):
//! each dimension (pair) is split into `xsamples × ysamples` strata, the
//! pixel's samples are assigned to strata by a per-dimension random
//! permutation, and jittered within them.

use rpbrt_geometry::float::{Float, ONE_MINUS_EPSILON};
use rpbrt_geometry::tuple::{Point2f, Point2i};

use super::independent::start_stream;
use super::lowdiscrepancy::{mix_bits, permutation_element};
use crate::rng::Rng;

/// Jittered stratified samples.
#[derive(Clone, Debug)]
pub struct StratifiedSampler {
    x_pixel_samples: i32,
    y_pixel_samples: i32,
    seed: i32,
    jitter: bool,
    rng: Rng,
    pixel: Point2i,
    sample_index: i32,
    dimension: i32,
}

impl StratifiedSampler {
    /// `x_pixel_samples × y_pixel_samples` strata (both > 0), jittered or
    /// centred.
    pub fn new(x_pixel_samples: i32, y_pixel_samples: i32, jitter: bool, seed: i32) -> Self {
        debug_assert!(x_pixel_samples > 0 && y_pixel_samples > 0);
        StratifiedSampler {
            x_pixel_samples,
            y_pixel_samples,
            seed,
            jitter,
            rng: Rng::default(),
            pixel: Point2i::new(0, 0),
            sample_index: 0,
            dimension: 0,
        }
    }

    /// Samples per pixel (`xsamples * ysamples`).
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        self.x_pixel_samples * self.y_pixel_samples
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        let (a, b) = self.rng.raw();
        super::SamplerCursor {
            a,
            b,
            pixel: self.pixel,
            index: self.sample_index,
            dimension: self.dimension,
        }
    }

    /// Goes back to where [`StratifiedSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.rng = Rng::from_raw((c.a, c.b));
        self.pixel = c.pixel;
        self.sample_index = c.index;
        self.dimension = c.dimension;
    }

    /// Starts sample `index` of pixel `p` at `dimension`.
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, index: i32, dimension: i32) {
        self.pixel = p;
        self.sample_index = index;
        self.dimension = dimension;
        start_stream(&mut self.rng, p, self.seed, index, dimension);
    }

    #[inline]
    fn stratum(&self) -> u32 {
        let hash = mix_bits(
            ((self.pixel.x as u64) << 48)
                ^ ((self.pixel.y as u64) << 32)
                ^ ((self.dimension as u64) << 16)
                ^ self.seed as u64,
        );
        permutation_element(
            self.sample_index as u32,
            self.samples_per_pixel() as u32,
            hash as u32,
        )
    }

    #[inline]
    fn delta(&mut self) -> Float {
        if self.jitter {
            self.rng.uniform_float()
        } else {
            0.5
        }
    }

    /// The next 1-D value.
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        let stratum = self.stratum();
        self.dimension += 1;
        let d = self.delta();
        ((stratum as Float + d) / self.samples_per_pixel() as Float).min(ONE_MINUS_EPSILON)
    }

    /// The next 2-D value.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        let stratum = self.stratum() as i32;
        self.dimension += 2;
        let x = stratum % self.x_pixel_samples;
        let y = stratum / self.x_pixel_samples;
        let dx = self.delta();
        let dy = self.delta();
        Point2f::new(
            ((x as Float + dx) / self.x_pixel_samples as Float).min(ONE_MINUS_EPSILON),
            ((y as Float + dy) / self.y_pixel_samples as Float).min(ONE_MINUS_EPSILON),
        )
    }

    /// The 2-D value for the position within the pixel.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        self.get_2d()
    }
}
