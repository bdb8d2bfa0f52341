//! The Halton sampler (book section 8.6; pbrt-v4 `HaltonSampler`): radical
//! inverses in successive prime bases, with the first two dimensions
//! scaled so that a run of consecutive indices covers each pixel of a
//! (at most 128×128) tile, and digit-permutation or Owen randomisation.

use std::sync::Arc;

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::{Point2f, Point2i};

use super::lowdiscrepancy::{
    compute_radical_inverse_permutations, inverse_radical_inverse, mix_bits,
    owen_scrambled_radical_inverse, radical_inverse, scrambled_radical_inverse,
    scrambled_radical_inverses, DigitPermutation, RandomizeStrategy, PRIME_TABLE_SIZE,
};

/// Largest pixel tile the first two Halton dimensions are scaled over.
const MAX_HALTON_RESOLUTION: i32 = 128;

/// The Halton sampler.
#[derive(Clone, Debug)]
pub struct HaltonSampler {
    samples_per_pixel: i32,
    randomize: RandomizeStrategy,
    digit_permutations: Option<Arc<Vec<DigitPermutation>>>,
    base_scales: [i64; 2],
    base_exponents: [u32; 2],
    mult_inverse: [i64; 2],
    halton_index: u64,
    dimension: i32,
}

impl HaltonSampler {
    /// A Halton sampler for an image of `full_resolution`. `randomize` must
    /// be `None`, `PermuteDigits` or `Owen` (FastOwen is treated as Owen;
    /// creation from scene files rejects it as pbrt-v4 does).
    pub fn new(
        samples_per_pixel: i32,
        full_resolution: Point2i,
        randomize: RandomizeStrategy,
        seed: i32,
    ) -> Self {
        let randomize = if randomize == RandomizeStrategy::FastOwen {
            RandomizeStrategy::Owen
        } else {
            randomize
        };
        let digit_permutations = (randomize == RandomizeStrategy::PermuteDigits)
            .then(|| Arc::new(compute_radical_inverse_permutations(seed as u32)));
        let mut base_scales = [1i64; 2];
        let mut base_exponents = [0u32; 2];
        for i in 0..2 {
            let base = if i == 0 { 2 } else { 3 };
            let res = if i == 0 {
                full_resolution.x
            } else {
                full_resolution.y
            };
            let (mut scale, mut exp) = (1i64, 0u32);
            while scale < res.min(MAX_HALTON_RESOLUTION) as i64 {
                scale *= base;
                exp += 1;
            }
            base_scales[i] = scale;
            base_exponents[i] = exp;
        }
        let mult_inverse = [
            multiplicative_inverse(base_scales[1], base_scales[0]),
            multiplicative_inverse(base_scales[0], base_scales[1]),
        ];
        HaltonSampler {
            samples_per_pixel,
            randomize,
            digit_permutations,
            base_scales,
            base_exponents,
            mult_inverse,
            halton_index: 0,
            dimension: 0,
        }
    }

    /// Samples per pixel.
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        self.samples_per_pixel
    }

    /// The randomisation in use.
    pub fn randomize(&self) -> RandomizeStrategy {
        self.randomize
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        super::SamplerCursor {
            a: self.halton_index,
            dimension: self.dimension,
            ..Default::default()
        }
    }

    /// Goes back to where [`HaltonSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.halton_index = c.a;
        self.dimension = c.dimension;
    }

    /// Finds the Halton index of sample `sample_index` in pixel `p`: the
    /// index whose scaled first two dimensions fall in `p` (mod 128),
    /// found by the Chinese remainder theorem.
    pub fn start_pixel_sample(&mut self, p: Point2i, sample_index: i32, dim: i32) {
        self.halton_index = 0;
        let stride = self.base_scales[0] * self.base_scales[1];
        if stride > 1 {
            let pm = [
                p.x.rem_euclid(MAX_HALTON_RESOLUTION) as u64,
                p.y.rem_euclid(MAX_HALTON_RESOLUTION) as u64,
            ];
            let mut index: u64 = 0;
            for i in 0..2 {
                let base = if i == 0 { 2 } else { 3 };
                let dim_offset = inverse_radical_inverse(pm[i], base, self.base_exponents[i]);
                index = index.wrapping_add(
                    dim_offset
                        .wrapping_mul((stride / self.base_scales[i]) as u64)
                        .wrapping_mul(self.mult_inverse[i] as u64),
                );
            }
            self.halton_index = index % stride as u64;
        }
        self.halton_index += sample_index as u64 * stride as u64;
        self.dimension = dim.max(2);
    }

    #[inline]
    fn sample_dimension(&self, dimension: usize) -> Float {
        match self.randomize {
            RandomizeStrategy::None => radical_inverse(dimension, self.halton_index),
            RandomizeStrategy::PermuteDigits => match &self.digit_permutations {
                Some(perms) => {
                    scrambled_radical_inverse(dimension, self.halton_index, &perms[dimension])
                }
                None => radical_inverse(dimension, self.halton_index),
            },
            _ => owen_scrambled_radical_inverse(
                dimension,
                self.halton_index,
                mix_bits(1 + ((dimension as u64) << 4)) as u32,
            ),
        }
    }

    /// The next 1-D value (dimensions wrap to 2 after the prime table).
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        if self.dimension as usize >= PRIME_TABLE_SIZE {
            self.dimension = 2;
        }
        let d = self.dimension as usize;
        self.dimension += 1;
        self.sample_dimension(d)
    }

    /// The next 2-D value.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        if self.dimension as usize + 1 >= PRIME_TABLE_SIZE {
            self.dimension = 2;
        }
        let d = self.dimension as usize;
        self.dimension += 2;
        Point2f::new(self.sample_dimension(d), self.sample_dimension(d + 1))
    }

    /// `N` consecutive dimensions from the current one, drawn together
    /// ([`scrambled_radical_inverses`]) where that gives the values of
    /// single draws: digit permutations, no dimension wrapping past the
    /// prime table, an index below 2^32. Advances the dimension.
    #[inline(always)]
    fn draw_together<const N: usize>(&mut self) -> Option<[Float; N]> {
        let d = self.dimension as usize;
        if self.randomize != RandomizeStrategy::PermuteDigits
            || d + N > PRIME_TABLE_SIZE
            || self.halton_index > u32::MAX as u64
        {
            return None;
        }
        let perms = self.digit_permutations.as_ref()?;
        self.dimension += N as i32;
        Some(scrambled_radical_inverses::<N>(d, self.halton_index, perms))
    }

    /// A path vertex's draws: 1-D, 2-D, 1-D, 2-D (see
    /// [`Sampler::get_vertex_samples`](super::Sampler::get_vertex_samples)).
    #[inline]
    pub fn get_1d_2d_1d_2d(&mut self) -> (Float, Point2f, Float, Point2f) {
        if let Some(v) = self.draw_together::<6>() {
            return (
                v[0],
                Point2f::new(v[1], v[2]),
                v[3],
                Point2f::new(v[4], v[5]),
            );
        }
        let a = self.get_1d();
        let b = self.get_2d();
        let c = self.get_1d();
        let d = self.get_2d();
        (a, b, c, d)
    }

    /// A camera sample's draws: wavelengths (1-D), the position in the
    /// pixel, time (1-D), lens (2-D) (see
    /// [`Sampler::get_camera_samples`](super::Sampler::get_camera_samples)).
    #[inline]
    pub fn get_camera_samples(&mut self) -> (Float, Point2f, Float, Point2f) {
        if let Some(v) = self.draw_together::<4>() {
            return (v[0], self.get_pixel_2d(), v[1], Point2f::new(v[2], v[3]));
        }
        let a = self.get_1d();
        let b = self.get_pixel_2d();
        let c = self.get_1d();
        let d = self.get_2d();
        (a, b, c, d)
    }

    /// The position within the pixel: the first two (unrandomised)
    /// dimensions with the pixel's digits shifted out.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        Point2f::new(
            radical_inverse(0, self.halton_index >> self.base_exponents[0]),
            radical_inverse(1, self.halton_index / self.base_scales[1] as u64),
        )
    }
}

/// The inverse of `a` modulo `n` (a, n coprime).
fn multiplicative_inverse(a: i64, n: i64) -> i64 {
    let (x, _) = extended_gcd(a, n);
    x.rem_euclid(n)
}

fn extended_gcd(a: i64, b: i64) -> (i64, i64) {
    if b == 0 {
        return (1, 0);
    }
    let d = a / b;
    let (xp, yp) = extended_gcd(b, a % b);
    (yp, xp - d * yp)
}
