//! Sobol'-based samplers (book section 8.7; pbrt-v4 `SobolSampler`,
//! `PaddedSobolSampler`, `ZSobolSampler`).
//!
//! * [`SobolSampler`]: one Sobol' sequence over the whole image; the
//!   first two dimensions choose the pixel, so sample `i` of a pixel is the
//!   `i`-th sequence point that lands in it.
//! * [`PaddedSobolSampler`]: per pixel, the first `spp` Sobol' points,
//!   reordered per dimension by a random permutation and scrambled.
//! * [`ZSobolSampler`] (pbrt-v4's default): pixels are visited in Morton
//!   order with randomly permuted base-4 digits, which spreads one 2-D
//!   Sobol' sequence over the image with blue-noise-like error.

use rpbrt_geometry::float::{Float, ONE_MINUS_EPSILON};
use rpbrt_geometry::tuple::{Point2f, Point2i};

use super::lowdiscrepancy::{
    encode_morton2, fast_owen_01, fast_owen_01_batch, mix_bits, permutation_element,
    sobol_matrices, sobol_reversed_01, sobol_sample, sobol_sample_fast_owen_01, BinaryScrambler,
    RandomizeStrategy, N_SOBOL_DIMENSIONS, PERMUTATIONS_4, SOBOL_MATRIX_SIZE,
};
use crate::simd::SimdLevel;

/// Largest supported log2 of the Sobol' sampler's pixel scale (so that
/// `2 * log2_scale + log2(spp)` fits the 52 generator-matrix columns).
pub const MAX_SOBOL_LOG2_SCALE: u32 = 20;

/// The global Sobol' sampler.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    samples_per_pixel: i32,
    scale: i32,
    log2_scale: u32,
    seed: i32,
    randomize: RandomizeStrategy,
    /// Inverse of the GF(2) system for the unknown index bits, one column
    /// per bit of the pixel's y coordinate.
    inv_columns: [u32; MAX_SOBOL_LOG2_SCALE as usize],
    pixel: Point2i,
    dimension: i32,
    sobol_index: u64,
}

impl SobolSampler {
    /// A Sobol' sampler over an image of `full_resolution`, whose larger
    /// side must be at most 2^[`MAX_SOBOL_LOG2_SCALE`]. `seed` randomises
    /// the scrambling (pbrt-v4 takes it from the `--seed` option).
    pub fn new(
        samples_per_pixel: i32,
        full_resolution: Point2i,
        randomize: RandomizeStrategy,
        seed: i32,
    ) -> Self {
        let scale = (full_resolution.x.max(full_resolution.y).max(1) as u32).next_power_of_two();
        let log2_scale = scale.trailing_zeros().min(MAX_SOBOL_LOG2_SCALE);
        let scale = 1i32 << log2_scale;
        SobolSampler {
            samples_per_pixel,
            scale,
            log2_scale,
            seed,
            randomize,
            inv_columns: solve_pixel_system(log2_scale),
            pixel: Point2i::new(0, 0),
            dimension: 0,
            sobol_index: 0,
        }
    }

    /// Samples per pixel.
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        self.samples_per_pixel
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        super::SamplerCursor {
            a: self.sobol_index,
            pixel: self.pixel,
            dimension: self.dimension,
            ..Default::default()
        }
    }

    /// Goes back to where [`SobolSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.sobol_index = c.a;
        self.pixel = c.pixel;
        self.dimension = c.dimension;
    }

    /// Finds the sequence index of sample `sample_index` in pixel `p`.
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, sample_index: i32, dim: i32) {
        self.pixel = p;
        self.dimension = dim.max(2);
        self.sobol_index = self.interval_to_index(sample_index as u64, p);
    }

    /// The index of the `frame`-th Sobol' point whose first two dimensions,
    /// scaled by `scale`, fall in pixel `p` (pbrt-v4's
    /// `SobolIntervalToIndex`, solved here directly over GF(2)).
    ///
    /// Indices `frame·4^m + low` (`low` < 4^m) form a (0,2m,2)-net, so each
    /// pixel holds exactly one. Dimension 0 is van der Corput: its top `m`
    /// bits are the low `m` index bits reversed, which fixes them from
    /// `p.x`. Dimension 1's top `m` bits are linear in the index; the
    /// unknown bits `m..2m` follow from `p.y` by the precomputed inverse.
    pub fn interval_to_index(&self, frame: u64, p: Point2i) -> u64 {
        let m = self.log2_scale;
        if m == 0 {
            return frame;
        }
        let mask = (1u32 << m) - 1;
        let px = (p.x as u32) & mask;
        let py = (p.y as u32) & mask;
        let low = (px.reverse_bits() >> (32 - m)) as u64;
        let mut index = (frame << (2 * m)) | low;
        // y's top m bits from the known index bits.
        let c1 = &sobol_matrices()[SOBOL_MATRIX_SIZE..2 * SOBOL_MATRIX_SIZE];
        let mut known = 0u32;
        let mut bits = index;
        let mut j = 0;
        while bits != 0 {
            if bits & 1 != 0 {
                known ^= c1[j] >> (32 - m);
            }
            bits >>= 1;
            j += 1;
        }
        let target = py ^ known;
        let mut unknown = 0u32;
        for (b, col) in self.inv_columns.iter().enumerate().take(m as usize) {
            if target >> b & 1 != 0 {
                unknown ^= col;
            }
        }
        index |= (unknown as u64) << m;
        index
    }

    #[inline]
    fn sample_dimension(&self, dimension: usize) -> Float {
        let scrambler = if self.randomize == RandomizeStrategy::None {
            BinaryScrambler::None
        } else {
            let hash = mix_bits(((dimension as u64) << 32) ^ self.seed as i64 as u64) as u32;
            BinaryScrambler::new(self.randomize, hash)
        };
        sobol_sample(self.sobol_index, dimension, scrambler)
    }

    /// The next 1-D value (dimensions wrap to 2 after 1024).
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        if self.dimension as usize >= N_SOBOL_DIMENSIONS {
            self.dimension = 2;
        }
        let d = self.dimension as usize;
        self.dimension += 1;
        self.sample_dimension(d)
    }

    /// The next 2-D value.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        if self.dimension as usize + 1 >= N_SOBOL_DIMENSIONS {
            self.dimension = 2;
        }
        let d = self.dimension as usize;
        self.dimension += 2;
        Point2f::new(self.sample_dimension(d), self.sample_dimension(d + 1))
    }

    /// The position within the pixel: the first two dimensions, scaled
    /// and offset to the pixel.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        let u = [
            sobol_sample(self.sobol_index, 0, BinaryScrambler::None),
            sobol_sample(self.sobol_index, 1, BinaryScrambler::None),
        ];
        let p = [
            self.pixel.x & (self.scale - 1),
            self.pixel.y & (self.scale - 1),
        ];
        let f =
            |i: usize| (u[i] * self.scale as Float - p[i] as Float).clamp(0.0, ONE_MINUS_EPSILON);
        Point2f::new(f(0), f(1))
    }
}

/// For the top `m` bits of Sobol' dimension 1 as a function of index bits
/// `m..2m`, the inverse map: column `b` is the bit pattern of those index
/// bits that produces a 1 in bit `b` only.
fn solve_pixel_system(m: u32) -> [u32; MAX_SOBOL_LOG2_SCALE as usize] {
    let mut out = [0u32; MAX_SOBOL_LOG2_SCALE as usize];
    if m == 0 {
        return out;
    }
    let c1 = &sobol_matrices()[SOBOL_MATRIX_SIZE..2 * SOBOL_MATRIX_SIZE];
    // Rows: equation per unknown k: image (m bits) | identity (which unknown).
    let mut rows: Vec<(u32, u32)> = (0..m)
        .map(|k| (c1[(m + k) as usize] >> (32 - m), 1u32 << k))
        .collect();
    // Gaussian elimination over GF(2) on the image bits: afterwards row b
    // has image exactly bit b.
    for b in 0..m as usize {
        let bit = 1u32 << b;
        let pivot = (b..rows.len()).find(|&r| rows[r].0 & bit != 0);
        let Some(pivot) = pivot else {
            debug_assert!(false, "Sobol' dimensions 0/1 are not a (0,2)-sequence");
            continue;
        };
        rows.swap(b, pivot);
        for r in 0..rows.len() {
            if r != b && rows[r].0 & bit != 0 {
                rows[r].0 ^= rows[b].0;
                rows[r].1 ^= rows[b].1;
            }
        }
    }
    for (b, row) in rows.iter().enumerate() {
        out[b] = row.1;
    }
    out
}

/// Scrambler for sample values from a 32-bit hash.
#[inline]
fn scrambler(randomize: RandomizeStrategy, hash: u32) -> BinaryScrambler {
    BinaryScrambler::new(randomize, hash)
}

/// The padded Sobol' sampler.
#[derive(Clone, Debug)]
pub struct PaddedSobolSampler {
    samples_per_pixel: i32,
    seed: i32,
    randomize: RandomizeStrategy,
    pixel: Point2i,
    sample_index: i32,
    dimension: i32,
}

impl PaddedSobolSampler {
    /// A padded Sobol' sampler (best with power-of-two `samples_per_pixel`).
    pub fn new(samples_per_pixel: i32, randomize: RandomizeStrategy, seed: i32) -> Self {
        PaddedSobolSampler {
            samples_per_pixel,
            seed,
            randomize,
            pixel: Point2i::new(0, 0),
            sample_index: 0,
            dimension: 0,
        }
    }

    /// Samples per pixel.
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        self.samples_per_pixel
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        super::SamplerCursor {
            pixel: self.pixel,
            index: self.sample_index,
            dimension: self.dimension,
            ..Default::default()
        }
    }

    /// Goes back to where [`PaddedSobolSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
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
    }

    /// The randomisation in use.
    pub fn randomize(&self) -> RandomizeStrategy {
        self.randomize
    }

    #[inline]
    fn hash_and_index(&self) -> (u64, u64) {
        let hash = mix_bits(
            ((self.pixel.x as u64) << 48)
                ^ ((self.pixel.y as u64) << 32)
                ^ ((self.dimension as u64) << 16)
                ^ self.seed as i64 as u64,
        );
        let index = permutation_element(
            self.sample_index as u32,
            self.samples_per_pixel as u32,
            hash as u32,
        );
        (hash, index as u64)
    }

    /// The next 1-D value: a permuted, scrambled van der Corput point.
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        let (hash, index) = self.hash_and_index();
        self.dimension += 1;
        sobol_sample(index, 0, scrambler(self.randomize, (hash >> 32) as u32))
    }

    /// The next 2-D value: a permuted, scrambled 2-D Sobol' point.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        let (hash, index) = self.hash_and_index();
        self.dimension += 2;
        Point2f::new(
            sobol_sample(index, 0, scrambler(self.randomize, hash as u32)),
            sobol_sample(index, 1, scrambler(self.randomize, (hash >> 32) as u32)),
        )
    }

    /// The position within the pixel.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        self.get_2d()
    }
}

/// Dimensions whose pixel-only index digits [`ZSobolSampler`] caches.
const ZSOBOL_CACHED_DIMENSIONS: usize = 64;

/// Base-4 index digits whose permutations [`ZSobolSampler`] caches:
/// enough for 2^12 × 2^12 pixels at 2^16 samples per pixel (or any
/// trade between the two); larger indices are computed uncached.
const ZSOBOL_CACHED_DIGITS: usize = 20;

/// The Z-Sobol' index digits' permutations last used, per dimension, and
/// the permuted digits that depend on the pixel alone (not on the sample
/// index) for one pixel. A digit's permutation is chosen by a hash of the
/// digits above it, which change rarely from one call to the next: with a
/// pixel's samples taken in order, the lowest sample digit's every 4
/// samples, the next one's every 16; across the pixels of a tile, the
/// low pixel digits' every few pixels and the high ones' never. Each entry
/// is keyed by those higher digits, so results are identical to
/// recomputing them.
#[derive(Clone, Debug)]
struct PixelDigitCache {
    /// The permuted pixel digits of the index, per dimension.
    high: [u64; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension, the index bits above the sample digits (the pixel's
    /// Morton code, shifted) that `high` was computed for (`u64::MAX`:
    /// none).
    high_pixel: [u64; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension and digit, the index bits above the digit when its
    /// permutation was last chosen (`u64::MAX`: never).
    digit_keys: [[u64; ZSOBOL_CACHED_DIGITS]; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension and digit, that permutation (into `PERMUTATIONS_4`).
    digit_perms: [[u8; ZSOBOL_CACHED_DIGITS]; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension, the index bits above the lowest sample digit when
    /// `low_upper` and `low_perm` were computed (`u64::MAX`: never).
    low_key: [u64; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension, the permuted digits above the lowest sample digit.
    low_upper: [u64; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension, the lowest sample digit's permutation.
    low_perm: [u8; ZSOBOL_CACHED_DIMENSIONS],
    /// Per dimension, the key and flip of the last index bit (odd powers
    /// of two samples per pixel).
    last_bit: [(u64, u8); ZSOBOL_CACHED_DIMENSIONS],
    /// `mix_bits(d ^ seed)` for `d` in `0..ZSOBOL_CACHED_DIMENSIONS + 2`:
    /// the scrambling hashes, which depend on the dimension and seed alone.
    scramble_hash: [u64; ZSOBOL_CACHED_DIMENSIONS + 2],
}

impl PixelDigitCache {
    /// The permuted digits `split..n_digits` of `morton` (those of the
    /// pixel alone) for dimension `d`. Cached per dimension; when the pixel
    /// changes, only the digits up to the highest one that differs from
    /// the cached pixel's are recomputed (the ones above, and their
    /// permutations, are the same), which for the next pixel of a tile is
    /// one or two.
    #[inline(always)]
    fn pixel_digits(
        &mut self,
        morton: u64,
        d: usize,
        split: usize,
        n_digits: usize,
        odd: usize,
        dim_mix: u64,
    ) -> u64 {
        // Digit `split` starts at bit 2·split − odd, the lowest pixel bit.
        let pixel_shift = 2 * split - odd;
        let pixel = morton.checked_shr(pixel_shift as u32).unwrap_or(0);
        let old = self.high_pixel[d];
        if old == pixel {
            return self.high[d];
        }
        let (mut high, top) = if old == u64::MAX {
            (0, n_digits)
        } else {
            // Highest differing index bit, and the digit holding it.
            let b = 63 - (old ^ pixel).leading_zeros() as usize + pixel_shift;
            let top = ((b + odd) / 2 + 1).min(n_digits);
            let keep_from = 2 * top - odd;
            let keep = if keep_from >= 64 {
                0
            } else {
                u64::MAX << keep_from
            };
            (self.high[d] & keep, top)
        };
        for i in split..top {
            high |= self.digit(morton, d, i, odd, dim_mix);
        }
        self.high[d] = high;
        self.high_pixel[d] = pixel;
        high
    }

    /// Caches, for dimension `d`, everything the lowest sample digit
    /// (digit `odd`) takes from the index bits above it: the permuted
    /// digits above it and its own permutation, under those bits as the
    /// key. Needs `split > odd` (at least one sample digit above the last
    /// bit).
    #[inline(always)]
    fn refresh_low(
        &mut self,
        morton: u64,
        d: usize,
        split: usize,
        n_digits: usize,
        odd: usize,
        dim_mix: u64,
    ) {
        let key = morton >> (odd + 2);
        // A new key whenever the pixel changes, so `high` is checked here.
        let mut upper = self.pixel_digits(morton, d, split, n_digits, odd, dim_mix);
        for i in odd + 1..split {
            upper |= self.digit(morton, d, i, odd, dim_mix);
        }
        self.low_key[d] = key;
        self.low_upper[d] = upper;
        self.low_perm[d] = ZSobolSampler::digit_permutation(key, dim_mix) as u8;
    }

    /// The index bits of the lowest sample digit (at bit `odd`, its
    /// `digit`) and everything above it, for dimension `d`, from the
    /// entries [`PixelDigitCache::refresh_low`] keeps.
    #[inline(always)]
    fn low_index(&self, d: usize, digit: usize, odd: usize) -> u64 {
        self.low_upper[d] | (PERMUTATIONS_4[self.low_perm[d] as usize][digit] as u64) << odd
    }

    /// The permuted last bit of `morton` (odd log2 spp), for dimension `d`:
    /// its flip cached under the index bits above it.
    #[inline(always)]
    fn last_bit(&mut self, morton: u64, d: usize, dim_mix: u64) -> u64 {
        let higher = morton >> 1;
        let (key, flip) = &mut self.last_bit[d];
        if *key != higher {
            *key = higher;
            *flip = (mix_bits(higher ^ dim_mix) & 1) as u8;
        }
        (morton & 1) ^ *flip as u64
    }

    /// Permuted digit `i` of `morton` in place (at bit `2i - odd`), for
    /// dimension `d`, from the cache when the digits above it are the ones
    /// it was last chosen for.
    #[inline(always)]
    fn digit(&mut self, morton: u64, d: usize, i: usize, odd: usize, dim_mix: u64) -> u64 {
        let shift = 2 * i - odd;
        let digit = ((morton >> shift) & 3) as usize;
        let higher = morton >> (shift + 2);
        if self.digit_keys[d][i] != higher {
            self.digit_keys[d][i] = higher;
            self.digit_perms[d][i] = ZSobolSampler::digit_permutation(higher, dim_mix) as u8;
        }
        (PERMUTATIONS_4[self.digit_perms[d][i] as usize][digit] as u64) << shift
    }
}

/// Scratch space for [`ZSobolSampler::four_draws_batch`], kept between
/// calls so that a batch allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct FourDrawBatch {
    v: Vec<u32>,
    seeds: Vec<u32>,
    values: Vec<Float>,
    found: Vec<(bool, bool)>,
    order: Vec<u32>,
    counts: Vec<u32>,
}

/// The positions of `cursors` grouped by dimension into `order`, in their
/// own order within a dimension (a stable counting sort): the wavefront's
/// cursors come in its sample order, which keeps a pixel's samples
/// together and in order. A range of over 1024 dimensions falls back to a
/// comparison sort by dimension and index.
fn sort_by_dimension(
    cursors: &[super::SamplerCursor],
    counts: &mut Vec<u32>,
    order: &mut Vec<u32>,
) {
    order.clear();
    let (lo, hi) = cursors.iter().fold((i32::MAX, i32::MIN), |(lo, hi), c| {
        (lo.min(c.dimension), hi.max(c.dimension))
    });
    if cursors.is_empty() || hi as i64 - lo as i64 >= 1024 {
        order.extend(0..cursors.len() as u32);
        order.sort_unstable_by_key(|&k| {
            let c = &cursors[k as usize];
            (c.dimension, c.a)
        });
        return;
    }
    counts.clear();
    counts.resize((hi - lo) as usize + 2, 0);
    for c in cursors {
        counts[(c.dimension - lo) as usize + 1] += 1;
    }
    for i in 1..counts.len() {
        counts[i] += counts[i - 1];
    }
    order.resize(cursors.len(), 0);
    for (k, c) in cursors.iter().enumerate() {
        let slot = &mut counts[(c.dimension - lo) as usize];
        order[*slot as usize] = k as u32;
        *slot += 1;
    }
}

/// The Morton-ordered ("Z") Sobol' sampler, pbrt-v4's default.
#[derive(Clone, Debug)]
pub struct ZSobolSampler {
    randomize: RandomizeStrategy,
    seed: i32,
    log2_samples_per_pixel: u32,
    n_base4_digits: u32,
    morton_index: u64,
    dimension: i32,
    cache: Box<PixelDigitCache>,
    /// Four draws computed ahead ([`ZSobolSampler::four_draws_batch`]) for
    /// the Morton index and dimension they were drawn at, which the next
    /// [`ZSobolSampler::get_1d_2d_1d_2d`] at that position returns.
    offered: Option<(u64, i32, [Float; 6])>,
    /// A 1-D draw computed ahead (the one after four draws) for the Morton
    /// index and dimension it was drawn at, which the next
    /// [`ZSobolSampler::get_1d`] at that position returns.
    offered_1d: Option<(u64, i32, Float)>,
}

impl ZSobolSampler {
    /// A Z-Sobol' sampler; `samples_per_pixel` is rounded down to a power
    /// of two (the caller warns).
    pub fn new(
        samples_per_pixel: i32,
        full_resolution: Point2i,
        randomize: RandomizeStrategy,
        seed: i32,
    ) -> Self {
        let log2_spp = 31 - (samples_per_pixel.max(1) as u32).leading_zeros();
        let res = (full_resolution.x.max(full_resolution.y).max(1) as u32).next_power_of_two();
        let log4_spp = log2_spp.div_ceil(2);
        ZSobolSampler {
            randomize,
            seed,
            log2_samples_per_pixel: log2_spp,
            n_base4_digits: res.trailing_zeros() + log4_spp,
            morton_index: 0,
            dimension: 0,
            cache: Box::new(PixelDigitCache {
                high: [0; ZSOBOL_CACHED_DIMENSIONS],
                high_pixel: [u64::MAX; ZSOBOL_CACHED_DIMENSIONS],
                digit_keys: [[u64::MAX; ZSOBOL_CACHED_DIGITS]; ZSOBOL_CACHED_DIMENSIONS],
                digit_perms: [[0; ZSOBOL_CACHED_DIGITS]; ZSOBOL_CACHED_DIMENSIONS],
                last_bit: [(u64::MAX, 0); ZSOBOL_CACHED_DIMENSIONS],
                low_key: [u64::MAX; ZSOBOL_CACHED_DIMENSIONS],
                low_upper: [0; ZSOBOL_CACHED_DIMENSIONS],
                low_perm: [0; ZSOBOL_CACHED_DIMENSIONS],
                scramble_hash: std::array::from_fn(|d| mix_bits((d as i32 ^ seed) as i64 as u64)),
            }),
            offered: None,
            offered_1d: None,
        }
    }

    /// Samples per pixel (a power of two).
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        1 << self.log2_samples_per_pixel
    }

    /// Where this sampler stands in its pixel sample.
    #[inline]
    pub fn cursor(&self) -> super::SamplerCursor {
        super::SamplerCursor {
            a: self.morton_index,
            dimension: self.dimension,
            ..Default::default()
        }
    }

    /// Goes back to where [`ZSobolSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.morton_index = c.a;
        self.dimension = c.dimension;
        self.offered = None;
        self.offered_1d = None;
    }

    /// Offers `draws` (from [`ZSobolSampler::four_draws_batch`] at the
    /// current cursor) to the next [`ZSobolSampler::get_1d_2d_1d_2d`].
    #[inline]
    pub fn offer_four_draws(&mut self, draws: Option<[Float; 6]>) {
        self.offered = draws.map(|v| (self.morton_index, self.dimension, v));
    }

    /// Offers a 1-D draw from [`ZSobolSampler::four_draws_batch`]'s `next`,
    /// computed at the current cursor, to the next [`ZSobolSampler::get_1d`]
    /// at that cursor.
    #[inline]
    pub fn offer_1d(&mut self, draw: Option<Float>) {
        self.offered_1d = draw.map(|v| (self.morton_index, self.dimension, v));
    }

    /// Starts sample `index` of pixel `p` at `dimension`.
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, index: i32, dimension: i32) {
        self.dimension = dimension;
        let pixel = encode_morton2(p.x as u32, p.y as u32);
        self.morton_index = (pixel << self.log2_samples_per_pixel) | index as u64;
    }

    /// The permuted base-4 digits `lo..hi` of the index (digit `i` at bit
    /// `2i`, or `2i - 1` when the samples per pixel are an odd power of
    /// two), each permuted by a hash of the digits above it and
    /// `dim_mix`.
    #[inline]
    fn permuted_digits(&self, lo: i32, hi: i32, dim_mix: u64) -> u64 {
        let odd = (self.log2_samples_per_pixel & 1) as i32;
        let mut index = 0u64;
        for i in (lo..hi).rev() {
            let shift = 2 * i - odd;
            let digit = ((self.morton_index >> shift) & 3) as usize;
            let higher = self.morton_index >> (shift + 2);
            let p = Self::digit_permutation(higher, dim_mix);
            index |= (PERMUTATIONS_4[p][digit] as u64) << shift;
        }
        index
    }

    /// The hash input that makes digit permutations differ by dimension.
    #[inline(always)]
    fn dim_mix(dimension: usize) -> u64 {
        0x5555_5555u64.wrapping_mul(dimension as u64)
    }

    /// The first base-4 digit that lies in the pixel's Morton code
    /// (digits below it come from the sample index), at most `n_digits`.
    #[inline(always)]
    fn split(&self, n_digits: usize) -> usize {
        (self.log2_samples_per_pixel.div_ceil(2) as usize).min(n_digits)
    }

    /// Which of the 24 permutations of a base-4 digit the digits above it
    /// (`higher`) and the dimension select.
    #[inline(always)]
    fn digit_permutation(higher: u64, dim_mix: u64) -> usize {
        ((mix_bits(higher ^ dim_mix) >> 24) % 24) as usize
    }

    /// The last bit of the index when the samples per pixel are an odd
    /// power of two (0 otherwise).
    #[inline]
    fn permuted_last_bit(&self, dim_mix: u64) -> u64 {
        if self.log2_samples_per_pixel & 1 == 1 {
            let digit = self.morton_index & 1;
            digit ^ (mix_bits((self.morton_index >> 1) ^ dim_mix) & 1)
        } else {
            0
        }
    }

    /// The Sobol' index for the current pixel sample and dimension: the
    /// Morton index with each base-4 digit permuted by a hash of the
    /// digits above it and the dimension.
    pub fn sample_index(&self) -> u64 {
        let last_digit = (self.log2_samples_per_pixel & 1) as i32;
        let dim_mix = Self::dim_mix(self.dimension as usize);
        self.permuted_digits(last_digit, self.n_base4_digits as i32, dim_mix)
            | self.permuted_last_bit(dim_mix)
    }

    /// [`ZSobolSampler::sample_index`], with the digits that depend on the
    /// pixel alone cached per pixel and every digit's permutation cached
    /// under the digits above it. Digit `i` and everything above it lie in
    /// the pixel's Morton code exactly when `i ≥ ⌈log2(spp) / 2⌉`.
    #[inline(always)]
    fn cached_sample_index(&mut self) -> u64 {
        let d = self.dimension as usize;
        let n_digits = self.n_base4_digits as usize;
        if d >= ZSOBOL_CACHED_DIMENSIONS || n_digits > ZSOBOL_CACHED_DIGITS {
            return self.sample_index();
        }
        let split = self.split(n_digits);
        let odd = (self.log2_samples_per_pixel & 1) as usize;
        let dim_mix = Self::dim_mix(d);
        let morton = self.morton_index;
        let cache = &mut *self.cache;
        let mut index = if split > odd {
            // The lowest sample digit (digit 0, or 1 when digit 0 is the
            // last bit below): everything else it takes, the digits above
            // it and its own permutation, depends only on the index bits
            // above it, which change every fourth sample. Those are kept
            // under that key, so most draws cost one comparison.
            let shift = odd;
            let key = morton >> (shift + 2);
            if cache.low_key[d] != key {
                cache.refresh_low(morton, d, split, n_digits, odd, dim_mix);
            }
            cache.low_index(d, ((morton >> shift) & 3) as usize, shift)
        } else {
            cache.pixel_digits(morton, d, split, n_digits, odd, dim_mix)
        };
        if odd == 1 {
            index |= cache.last_bit(morton, d, dim_mix);
        }
        index
    }

    /// The scrambling hash `mix_bits(dimension ^ seed)` for the current
    /// dimension.
    #[inline(always)]
    fn scramble_hash(&self) -> u64 {
        let d = self.dimension as usize;
        if d < ZSOBOL_CACHED_DIMENSIONS + 2 {
            self.cache.scramble_hash[d]
        } else {
            mix_bits((self.dimension ^ self.seed) as i64 as u64)
        }
    }

    /// The next 1-D value.
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        if let Some((m, d, v)) = self.offered_1d.take() {
            if m == self.morton_index && d == self.dimension {
                self.dimension += 1;
                return v;
            }
        }
        self.draw_1d()
    }

    /// The next 2-D value.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        self.draw_2d()
    }

    /// A 1-D, a 2-D, a 1-D and a 2-D draw in one call, each inlined, so
    /// that a path vertex
    /// ([`Sampler::get_vertex_samples`](super::Sampler::get_vertex_samples))
    /// or a camera sample
    /// ([`Sampler::get_camera_samples`](super::Sampler::get_camera_samples))
    /// pays one call's overhead instead of four and the draws' work
    /// overlaps.
    #[inline(never)]
    pub fn get_1d_2d_1d_2d(&mut self) -> (Float, Point2f, Float, Point2f) {
        if let Some((m, d, v)) = self.offered.take() {
            if m == self.morton_index && d == self.dimension {
                self.dimension += 6;
                return (
                    v[0],
                    Point2f::new(v[1], v[2]),
                    v[3],
                    Point2f::new(v[4], v[5]),
                );
            }
        }
        if let Some(inputs) = self.four_draw_inputs() {
            self.dimension += 6;
            let f = |k: usize| fast_owen_01(inputs[k].0, inputs[k].1);
            return (
                f(0),
                Point2f::new(f(1), f(2)),
                f(3),
                Point2f::new(f(4), f(5)),
            );
        }
        let a = self.draw_1d();
        let b = self.draw_2d();
        let c = self.draw_1d();
        let d = self.draw_2d();
        (a, b, c, d)
    }

    /// [`ZSobolSampler::get_1d_2d_1d_2d`]'s values at each of `cursors`
    /// (its sampler's positions), into `out`: the bit-reversed Sobol'
    /// values are found per cursor, then scrambled and made floats
    /// together, lane-parallel at `level`. `None` where the four draws
    /// take the general route (2 spp, another randomization,
    /// uncached dimensions); the draw then computes them itself. With
    /// `next`, also the 1-D draw that follows the four (the path tracer's
    /// Russian roulette) into it, `None` where the six are or where its
    /// dimension is not cached. Leaves the sampler's position as it was.
    pub fn four_draws_batch(
        &mut self,
        level: SimdLevel,
        cursors: &[super::SamplerCursor],
        batch: &mut FourDrawBatch,
        out: &mut Vec<Option<[Float; 6]>>,
        next: Option<&mut Vec<Option<Float>>>,
    ) {
        const W: usize = 7;
        let with_next = next.is_some();
        let (morton, dimension) = (self.morton_index, self.dimension);
        let n = cursors.len();
        // Taken in order of dimension, then index, the draws meet their
        // cache entries as a pixel's samples taken in order do (the paths
        // in flight are at different depths, so in their own order each
        // dimension's entries would change at almost every draw).
        sort_by_dimension(cursors, &mut batch.counts, &mut batch.order);
        // Seven values a cursor (the seventh, the next draw, left zero
        // when not asked for).
        batch.v.clear();
        batch.v.resize(W * n, 0);
        batch.seeds.clear();
        batch.seeds.resize(W * n, 0);
        batch.found.clear();
        batch.found.resize(n, (false, false));
        for &k in &batch.order {
            let k = k as usize;
            let c = &cursors[k];
            self.morton_index = c.a;
            self.dimension = c.dimension;
            if let Some(inputs) = self.four_draw_inputs() {
                for (j, (v, seed)) in inputs.into_iter().enumerate() {
                    batch.v[W * k + j] = v;
                    batch.seeds[W * k + j] = seed;
                }
                let mut found_next = false;
                if with_next {
                    if let Some((v, seed)) = self.next_draw_input() {
                        batch.v[W * k + 6] = v;
                        batch.seeds[W * k + 6] = seed;
                        found_next = true;
                    }
                }
                batch.found[k] = (true, found_next);
            }
        }
        (self.morton_index, self.dimension) = (morton, dimension);
        batch.values.clear();
        batch.values.resize(W * n, 0.0);
        fast_owen_01_batch(level, &batch.v, &batch.seeds, &mut batch.values);
        out.clear();
        out.extend(
            batch
                .found
                .iter()
                .zip(batch.values.chunks_exact(W))
                .map(|(&(f, _), v)| f.then(|| std::array::from_fn(|j| v[j]))),
        );
        if let Some(next) = next {
            next.clear();
            next.extend(
                batch
                    .found
                    .iter()
                    .zip(batch.values.chunks_exact(W))
                    .map(|(&(_, f), v)| f.then_some(v[6])),
            );
        }
    }

    /// For the 1-D draw that follows [`ZSobolSampler::get_1d_2d_1d_2d`] at
    /// the current position, once [`ZSobolSampler::four_draw_inputs`] has
    /// found the six: its bit-reversed Sobol' value and scrambling seed
    /// (the value is [`fast_owen_01`] of the pair), through the single
    /// draw's cache; `None` where its dimension is not cached. Does not
    /// advance the dimension.
    #[inline(always)]
    fn next_draw_input(&mut self) -> Option<(u32, u32)> {
        let d = self.dimension as usize + 6;
        if d >= ZSOBOL_CACHED_DIMENSIONS {
            return None;
        }
        self.dimension += 6;
        let index = self.cached_sample_index();
        let hash = {
            self.dimension += 1;
            let h = self.scramble_hash() as u32;
            self.dimension -= 7;
            h
        };
        Some((sobol_reversed_01(index, 0), hash))
    }

    /// For [`ZSobolSampler::get_1d_2d_1d_2d`] at the current position,
    /// when the scrambling is fast Owen, the dimensions cached and the
    /// lowest sample digit has a digit above it (at least 4 samples per
    /// pixel, 8 for an odd log2): the six values' bit-reversed Sobol'
    /// values and scrambling seeds (each value is [`fast_owen_01`] of its
    /// pair). The four draws' cache entries are tested together (one
    /// branch instead of one each, since they miss together: every fourth
    /// sample and on a new pixel) and refreshed where stale, so the values
    /// are those of the four single draws. Does not advance the dimension.
    #[inline(always)]
    fn four_draw_inputs(&mut self) -> Option<[(u32, u32); 6]> {
        let d = self.dimension as usize;
        let n_digits = self.n_base4_digits as usize;
        if self.log2_samples_per_pixel == 0
            || self.randomize != RandomizeStrategy::FastOwen
            || d + 6 >= ZSOBOL_CACHED_DIMENSIONS
            || n_digits > ZSOBOL_CACHED_DIGITS
        {
            return None;
        }
        // The lowest sample digit is digit `odd` (at bit `odd`: below it,
        // for an odd log2 spp, the last bit); its key is everything above
        // it.
        let odd = (self.log2_samples_per_pixel & 1) as usize;
        let split = self.split(n_digits);
        if split <= odd {
            return None;
        }
        let morton = self.morton_index;
        let key = morton >> (odd + 2);
        let dims = [d, d + 1, d + 3, d + 4];
        let c = &mut *self.cache;
        let all_cached = (c.low_key[d] == key)
            & (c.low_key[d + 1] == key)
            & (c.low_key[d + 3] == key)
            & (c.low_key[d + 4] == key);
        if !all_cached {
            // Refreshed here, as the single draws would (the same cache
            // entries), without their per-draw checks.
            for dd in dims {
                if c.low_key[dd] != key {
                    c.refresh_low(morton, dd, split, n_digits, odd, Self::dim_mix(dd));
                }
            }
        }
        // The last bits (odd log2 spp), from the single draws' cache.
        let mut last = [0u64; 4];
        if odd == 1 {
            for (l, dd) in last.iter_mut().zip(dims) {
                *l = c.last_bit(morton, dd, Self::dim_mix(dd));
            }
        }
        let c = &*self.cache;
        let digit = ((morton >> odd) & 3) as usize;
        let index = |j: usize| c.low_index(dims[j], digit, odd) | last[j];
        let h = |dd: usize| c.scramble_hash[dd];
        let (i1, bits1) = (index(1), h(d + 3));
        let (i4, bits4) = (index(3), h(d + 6));
        Some([
            (sobol_reversed_01(index(0), 0), h(d + 1) as u32),
            (sobol_reversed_01(i1, 0), bits1 as u32),
            (sobol_reversed_01(i1, 1), (bits1 >> 32) as u32),
            (sobol_reversed_01(index(2), 0), h(d + 4) as u32),
            (sobol_reversed_01(i4, 0), bits4 as u32),
            (sobol_reversed_01(i4, 1), (bits4 >> 32) as u32),
        ])
    }

    #[inline(always)]
    fn draw_1d(&mut self) -> Float {
        let index = self.cached_sample_index();
        self.dimension += 1;
        let hash = self.scramble_hash() as u32;
        if self.randomize == RandomizeStrategy::FastOwen {
            return sobol_sample_fast_owen_01(index, 0, hash);
        }
        sobol_sample(index, 0, scrambler(self.randomize, hash))
    }

    #[inline(always)]
    fn draw_2d(&mut self) -> Point2f {
        let index = self.cached_sample_index();
        self.dimension += 2;
        let bits = self.scramble_hash();
        if self.randomize == RandomizeStrategy::FastOwen {
            return Point2f::new(
                sobol_sample_fast_owen_01(index, 0, bits as u32),
                sobol_sample_fast_owen_01(index, 1, (bits >> 32) as u32),
            );
        }
        Point2f::new(
            sobol_sample(index, 0, scrambler(self.randomize, bits as u32)),
            sobol_sample(index, 1, scrambler(self.randomize, (bits >> 32) as u32)),
        )
    }

    /// The position within the pixel.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        self.get_2d()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four-draw entry point (with its shared cache test) gives the
    /// values of four separate draws, in scanline and revisited pixel
    /// orders, for even and odd log2 spp, every randomization, starting
    /// dimensions inside and past the cache.
    #[test]
    fn four_draws_match_single_draws() {
        use RandomizeStrategy::*;
        for (spp, rand) in [
            (64, FastOwen),
            (16, FastOwen),
            (32, FastOwen),
            (8, FastOwen),
            (128, FastOwen),
            (64, Owen),
            (4, None),
        ] {
            let mut a = ZSobolSampler::new(spp, Point2i::new(40, 40), rand, 3);
            let mut b = a.clone();
            let mut checked = 0;
            for wave in [0..1, 1..2, 2..4, 4..spp] {
                for y in 0..6 {
                    for x in 0..6 {
                        for i in wave.clone() {
                            for d0 in [0, 6, 13, 55, 58, 70] {
                                a.start_pixel_sample(Point2i::new(x, y), i, d0);
                                b.start_pixel_sample(Point2i::new(x, y), i, d0);
                                let got = a.get_1d_2d_1d_2d();
                                let want = (b.get_1d(), b.get_2d(), b.get_1d(), b.get_2d());
                                assert_eq!(got, want, "spp {spp} {x},{y} sample {i} dim {d0}");
                                assert_eq!(a.dimension, b.dimension);
                                checked += 1;
                            }
                        }
                    }
                }
            }
            assert!(checked > 500, "{checked}");
        }
    }

    /// The cached index equals the uncached computation for the widest
    /// indices the cache covers, and the uncached fallback beyond them.
    /// The batched four draws, at cursors of interleaved pixels, samples
    /// and dimensions (the wavefront's order), are the single draws'
    /// values at every SIMD level; offered to the sampler they are what the
    /// four-draw call returns, and an offer at another cursor is ignored.
    #[test]
    fn batched_four_draws_match_single_draws() {
        use crate::sampler::SamplerCursor;
        use RandomizeStrategy::*;
        let mut rng = crate::rng::Rng::new(5, 9);
        for (spp, rand) in [
            (64, FastOwen),
            (16, FastOwen),
            (32, FastOwen),
            (8, FastOwen),
            (2, FastOwen),
            (64, Owen),
        ] {
            let mut reference = ZSobolSampler::new(spp, Point2i::new(300, 200), rand, 7);
            let mut cursors: Vec<SamplerCursor> = (0..333)
                .map(|_| {
                    let p = Point2i::new(
                        (rng.uniform_u32() % 300) as i32,
                        (rng.uniform_u32() % 200) as i32,
                    );
                    let i = (rng.uniform_u32() % spp as u32) as i32;
                    let d = [0, 6, 13, 52, 57, 60][(rng.uniform_u32() % 6) as usize];
                    reference.start_pixel_sample(p, i, d);
                    reference.cursor()
                })
                .collect();
            // One far dimension among the last few: the comparison sort's
            // batch (all but it within the counting sort's range).
            reference.start_pixel_sample(Point2i::new(3, 4), 1, 2000);
            cursors.insert(300, reference.cursor());
            // The four draws and the 1-D draw after them.
            let want: Vec<[Float; 7]> = cursors
                .iter()
                .map(|c| {
                    reference.set_cursor(c);
                    let (a, b, c, d) = (
                        reference.get_1d(),
                        reference.get_2d(),
                        reference.get_1d(),
                        reference.get_2d(),
                    );
                    [a, b.x, b.y, c, d.x, d.y, reference.get_1d()]
                })
                .collect();
            for level in SimdLevel::available() {
                let mut s = ZSobolSampler::new(spp, Point2i::new(300, 200), rand, 7);
                let mut batch = FourDrawBatch::default();
                let (mut out, mut next) = (Vec::new(), Vec::new());
                s.four_draws_batch(
                    level,
                    &cursors[300..],
                    &mut batch,
                    &mut out,
                    Some(&mut next),
                );
                let (far, far_next) = (out.clone(), next.clone());
                s.four_draws_batch(
                    level,
                    &cursors[..300],
                    &mut batch,
                    &mut out,
                    Some(&mut next),
                );
                out.extend(far);
                next.extend(far_next);
                assert_eq!(out.len(), cursors.len());
                assert_eq!(next.len(), cursors.len());
                // Without `next`, the same four draws.
                let mut alone = Vec::new();
                s.four_draws_batch(level, &cursors[..300], &mut batch, &mut alone, Option::None);
                assert_eq!(alone[..], out[..300]);
                for (((c, got), got_next), want) in cursors.iter().zip(&out).zip(&next).zip(&want) {
                    match got {
                        Some(v) => assert_eq!(v[..], want[..6], "{level:?} spp {spp} {c:?}"),
                        // Only the general route declines.
                        Option::None => assert!(rand != FastOwen || spp == 2 || c.dimension >= 57),
                    }
                    match got_next {
                        Some(v) => assert_eq!(*v, want[6], "{level:?} spp {spp} {c:?}"),
                        // Only with the four, here (the next draw's
                        // dimension is cached wherever theirs are).
                        Option::None => assert!(got.is_none()),
                    }
                    s.set_cursor(c);
                    s.offer_four_draws(*got);
                    let (a, b, cc, d) = s.get_1d_2d_1d_2d();
                    assert_eq!([a, b.x, b.y, cc, d.x, d.y], want[..6]);
                    assert_eq!(s.dimension, c.dimension + 6);
                    s.offer_1d(*got_next);
                    assert_eq!(s.get_1d(), want[6]);
                    assert_eq!(s.dimension, c.dimension + 7);
                    // Taken at the cursor without the sampler: the same
                    // values, and the cursor the sampler's draws leave.
                    if let (Some(v), Some(v_next)) = (got, got_next) {
                        let mut taken = *c;
                        let (a, b, cc, d) = taken.take_four_draws(*v);
                        assert_eq!([a, b.x, b.y, cc, d.x, d.y], want[..6]);
                        assert_eq!(taken.take_1d(*v_next), want[6]);
                        assert_eq!(taken, s.cursor());
                    }
                }
                // A 1-D offer is taken only at its own position: not by a
                // 2-D draw there, nor after the cursor moves.
                s.set_cursor(&cursors[2]);
                s.offer_1d(Some(0.5));
                reference.set_cursor(&cursors[2]);
                assert_eq!(s.get_2d(), reference.get_2d());
                assert_eq!(s.get_1d(), reference.get_1d());
                s.offer_1d(Some(0.5));
                s.set_cursor(&cursors[3]);
                reference.set_cursor(&cursors[3]);
                assert_eq!(s.get_1d(), reference.get_1d());
                // An offer is withdrawn when the cursor moves, and not
                // taken at another dimension.
                s.set_cursor(&cursors[0]);
                s.offer_four_draws(Some([0.5; 6]));
                s.set_cursor(&cursors[1]);
                let (a, ..) = s.get_1d_2d_1d_2d();
                assert_eq!(a, want[1][0]);
                s.set_cursor(&cursors[1]);
                s.offer_four_draws(Some([0.5; 6]));
                reference.set_cursor(&cursors[1]);
                assert_eq!(s.get_1d(), reference.get_1d());
                assert_eq!(s.get_1d_2d_1d_2d(), reference.get_1d_2d_1d_2d());
            }
        }
    }

    #[test]
    fn cached_sample_index_matches_uncached_for_large_indices() {
        // 2^10 × 2^10 pixels at 2^20 samples: 20 digits, the most cached;
        // 2^12 × 2^12 at 2^20: 22 digits, computed uncached.
        for res in [1 << 10, 1 << 12] {
            let spp = 1 << 20;
            let mut s =
                ZSobolSampler::new(spp, Point2i::new(res, res), RandomizeStrategy::FastOwen, 9);
            for (x, y) in [(0, 0), (res - 1, res - 1), (517, 3), (518, 3), (519, 3)] {
                for i in [0, 1, 5, 4097, spp - 1] {
                    for d in [0, 3, 40] {
                        s.start_pixel_sample(Point2i::new(x, y), i, d);
                        let uncached = s.sample_index();
                        assert_eq!(s.cached_sample_index(), uncached, "{res} {x} {y} {i} {d}");
                    }
                }
            }
        }
    }

    /// The cached index digits (pixel digits, per-digit permutations, the
    /// lowest sample digit's key, the last bit's flip, the scrambling
    /// hashes) equal the uncached computation.
    #[test]
    fn cached_sample_index_matches_uncached() {
        for spp in [1, 2, 4, 8, 16, 32, 64, 128] {
            let mut s =
                ZSobolSampler::new(spp, Point2i::new(37, 21), RandomizeStrategy::FastOwen, 3);
            // A few far-apart pixels, then a scanline sweep (the pixel
            // digits are updated from the previous pixel's).
            let sweep = (0..12).flat_map(|y| (0..9).map(move |x| Point2i::new(x + 3, y + 2)));
            let pixels = [
                Point2i::new(0, 0),
                Point2i::new(36, 20),
                Point2i::new(5, 17),
            ]
            .into_iter()
            .chain(sweep);
            for p in pixels {
                for i in 0..spp.min(8) {
                    for d in [0, 1, 2, 5, 17, 63, 64, 65, 66, 90] {
                        s.start_pixel_sample(p, i, d);
                        let uncached = s.sample_index();
                        assert_eq!(s.cached_sample_index(), uncached, "spp {spp} {p:?} {i} {d}");
                        s.dimension = d;
                        let expected = mix_bits((d ^ s.seed) as i64 as u64);
                        assert_eq!(s.scramble_hash(), expected);
                    }
                }
            }
        }
    }
}
