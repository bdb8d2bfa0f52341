//! The independent sampler (book section 8.3; pbrt-v4 `IndependentSampler`):
//! uniform random values from a PCG32 stream chosen by pixel and seed.

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::{Point2f, Point2i};

use super::lowdiscrepancy::hash_values;
use crate::rng::{mix_bits, Rng};

/// Independent uniform samples.
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    samples_per_pixel: i32,
    seed: i32,
    rng: Rng,
}

impl IndependentSampler {
    /// A sampler taking `samples_per_pixel` samples, randomised by `seed`.
    pub fn new(samples_per_pixel: i32, seed: i32) -> Self {
        IndependentSampler {
            samples_per_pixel,
            seed,
            rng: Rng::default(),
        }
    }

    /// Samples per pixel.
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        self.samples_per_pixel
    }

    /// Positions the stream at sample `sample_index` of pixel `p`, dimension
    /// `dimension` (each sample owns 65536 values of the stream).
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, sample_index: i32, dimension: i32) {
        start_stream(&mut self.rng, p, self.seed, sample_index, dimension);
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        let (a, b) = self.rng.raw();
        super::SamplerCursor {
            a,
            b,
            ..Default::default()
        }
    }

    /// Goes back to where [`IndependentSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.rng = Rng::from_raw((c.a, c.b));
    }

    /// The next 1-D value.
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        self.rng.uniform_float()
    }

    /// The next 2-D value.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        let x = self.rng.uniform_float();
        Point2f::new(x, self.rng.uniform_float())
    }

    /// The 2-D value for the position within the pixel.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        self.get_2d()
    }
}

/// Restarts `rng` on the stream of pixel `p` and `seed`, advanced to
/// `sample_index * 65536 + dimension`.
#[inline]
pub(crate) fn start_stream(
    rng: &mut Rng,
    p: Point2i,
    seed: i32,
    sample_index: i32,
    dimension: i32,
) {
    let seq = hash_values(&[&p, &seed]);
    rng.set_sequence(seq, mix_bits(seq));
    rng.advance(sample_index as i64 * 65536 + dimension as i64);
}
