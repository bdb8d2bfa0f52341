//! The PMJ02BN sampler (book section 8.5.4 and pbrt-v4 `PMJ02BNSampler`):
//! progressive multi-jittered (0,2) sequences with blue-noise point
//! selection (Christensen, Kensler and Kilpatrick 2018).
//!
//! pbrt-v4 ships precomputed tables (`util/pmj02tables.cpp`, five sets of
//! 65536 points). Here the sets are generated on first use, deterministic
//! per set index, and cached. Construction, point by point: at level `K`
//! (growing the sequence to 2^K points) a new point must fall into an empty
//! cell of every elementary-interval shape 2^j × 2^(K−j), j = 0..=K. For a
//! candidate x stratum the admissible y strata are found by a depth-first
//! search over y bits (each bit decides one more shape). Among a few
//! admissible jittered candidates the one farthest from the existing points
//! (toroidal distance) is kept (Mitchell's best-candidate rule, after
//! Christensen et al.). Measured: under the (0,2) constraints this barely
//! changes the spacing (mean nearest-neighbour distance 0.649 vs 0.651 ×
//! 1/sqrt(N) for 1024 points, 16 vs 1 candidates; uniform random ≈ 0.5),
//! so the sets are pmj02 with only a nominal blue-noise step; a real
//! blue-noise optimisation is not done. If a level cannot be completed (rare), it is
//! restarted with fresh random choices. Every prefix of 2^K points is thus
//! a (0,K,2)-net.
//!
//! pbrt-v4 offsets the non-pixel dimensions by per-pixel values from 48
//! precomputed 128×128 blue-noise textures; those textures are not
//! reproduced — the offsets use pbrt-v4's procedural
//! `BlueNoiseSample` (Morton-permuted) instead.

use std::sync::{Arc, OnceLock};

use rpbrt_geometry::float::{Float, ONE_MINUS_EPSILON};
use rpbrt_geometry::tuple::{Point2f, Point2i};

use super::lowdiscrepancy::{blue_noise_sample, mix_bits, permutation_element};
use crate::rng::Rng;

/// Number of distinct generated point sets (pbrt-v4's `nPMJ02bnSets`).
pub const N_PMJ02BN_SETS: usize = 5;
/// log2 of the points per set.
pub const LOG2_PMJ02BN_SAMPLES: u32 = 16;
/// Points per set (pbrt-v4's `nPMJ02bnSamples`): the most samples per pixel.
pub const N_PMJ02BN_SAMPLES: usize = 1 << LOG2_PMJ02BN_SAMPLES;

/// Best-candidate tries per point for the cached sets.
const N_CANDIDATES: usize = 4;

/// Point set `set` (mod [`N_PMJ02BN_SETS`]), generated on first use.
pub fn pmj02bn_set(set: usize) -> &'static [Point2f] {
    static SETS: [OnceLock<Vec<Point2f>>; N_PMJ02BN_SETS] = [
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
        OnceLock::new(),
    ];
    let set = set % N_PMJ02BN_SETS;
    SETS[set].get_or_init(|| {
        generate_pmj02bn(LOG2_PMJ02BN_SAMPLES, set as u64, N_CANDIDATES)
            .into_iter()
            .map(|(x, y)| Point2f::new(truncate_f32(x), truncate_f32(y)))
            .collect()
    })
}

/// The largest f32 not above `v` (so points never cross a stratum
/// boundary when narrowed), capped below one.
fn truncate_f32(v: f64) -> Float {
    let mut f = v as f32;
    if f as f64 > v {
        f = rpbrt_geometry::float::next_float_down(f);
    }
    f.min(ONE_MINUS_EPSILON)
}

/// Sample `index` of point set `set` (pbrt-v4's `GetPMJ02BNSample`).
#[inline]
pub fn pmj02bn_sample(set: usize, index: usize) -> Point2f {
    pmj02bn_set(set)[index % N_PMJ02BN_SAMPLES]
}

/// Uniform grid over the torus for nearest-neighbour queries.
struct PointGrid {
    res: usize,
    cells: Vec<Vec<u32>>,
}

impl PointGrid {
    fn new(res: usize) -> Self {
        PointGrid {
            res,
            cells: vec![Vec::new(); res * res],
        }
    }
    fn cell(&self, v: f64) -> usize {
        ((v * self.res as f64) as usize).min(self.res - 1)
    }
    fn insert(&mut self, p: (f64, f64), i: u32) {
        let c = self.cell(p.1) * self.res + self.cell(p.0);
        self.cells[c].push(i);
    }
    /// Squared toroidal distance from `p` to its nearest point.
    fn nearest_sq(&self, p: (f64, f64), pts: &[(f64, f64)]) -> f64 {
        let (cx, cy) = (self.cell(p.0) as i64, self.cell(p.1) as i64);
        let res = self.res as i64;
        let mut best = f64::INFINITY;
        for r in 0..=(res / 2) {
            // Any point in ring r is at least (r-1)/res away.
            let ring_min = (r - 1).max(0) as f64 / res as f64;
            if ring_min * ring_min > best {
                break;
            }
            for dy in -r..=r {
                for dx in -r..=r {
                    if dx.abs() != r && dy.abs() != r {
                        continue;
                    }
                    let c = (cy + dy).rem_euclid(res) * res + (cx + dx).rem_euclid(res);
                    for &i in &self.cells[c as usize] {
                        let q = pts[i as usize];
                        let mut ddx = (p.0 - q.0).abs();
                        let mut ddy = (p.1 - q.1).abs();
                        ddx = ddx.min(1.0 - ddx);
                        ddy = ddy.min(1.0 - ddy);
                        best = best.min(ddx * ddx + ddy * ddy);
                    }
                }
            }
        }
        best
    }
}

/// Occupancy of every elementary-interval shape at one level.
struct Occupancy {
    k: u32,
    /// `occ[j]`: shape with 2^j x strata and 2^(k−j) y strata.
    occ: Vec<Vec<bool>>,
}

impl Occupancy {
    fn new(k: u32, pts: &[(f64, f64)]) -> Self {
        let mut o = Occupancy {
            k,
            occ: vec![vec![false; 1 << k]; k as usize + 1],
        };
        for &p in pts {
            let (x, y) = o.cells(p);
            o.mark(x, y);
        }
        o
    }
    fn cells(&self, p: (f64, f64)) -> (u32, u32) {
        let n = (1u64 << self.k) as f64;
        let max = (1u32 << self.k) - 1;
        (((p.0 * n) as u32).min(max), ((p.1 * n) as u32).min(max))
    }
    #[inline]
    fn index(&self, j: u32, x: u32, y: u32) -> usize {
        (((x >> (self.k - j)) << (self.k - j)) | (y >> j)) as usize
    }
    fn mark(&mut self, x: u32, y: u32) {
        for j in 0..=self.k {
            let i = self.index(j, x, y);
            debug_assert!(!self.occ[j as usize][i]);
            self.occ[j as usize][i] = true;
        }
    }
    /// A y stratum (finest level) admissible with x stratum `x`, found by
    /// randomised depth-first search over y's bits, top first.
    fn find_y(&self, x: u32, rng: &mut Rng) -> Option<u32> {
        self.dfs(x, 0, 0, rng)
    }
    fn dfs(&self, x: u32, depth: u32, top: u32, rng: &mut Rng) -> Option<u32> {
        if depth == self.k {
            return Some(top);
        }
        let d = depth + 1;
        let j = self.k - d;
        let first = rng.uniform_u32() & 1;
        for b in [first, first ^ 1] {
            let t = (top << 1) | b;
            // Shape j: x's top j bits and y's top d bits.
            let i = (((x >> d) << d) | t) as usize;
            if !self.occ[j as usize][i] {
                if let Some(y) = self.dfs(x, d, t, rng) {
                    return Some(y);
                }
            }
        }
        None
    }
}

/// Generates 2^`log2_n` pmj02bn points (in [0,1)², as f64) for `seed`,
/// keeping the best of `candidates` admissible points each time (1 gives
/// plain pmj02 without blue-noise selection).
pub fn generate_pmj02bn(log2_n: u32, seed: u64, candidates: usize) -> Vec<(f64, f64)> {
    let n = 1usize << log2_n;
    let mut rng = Rng::new(mix_bits(seed ^ 0x706d_6a30_3262_6e00), seed);
    let mut pts: Vec<(f64, f64)> = Vec::with_capacity(n);
    pts.push((rng.uniform_float() as f64, rng.uniform_float() as f64));
    let grid_res = 1usize << log2_n.div_ceil(2);
    let mut grid = PointGrid::new(grid_res);
    grid.insert(pts[0], 0);
    for k in 1..=log2_n {
        let start = pts.len();
        let end = 1usize << k;
        let cell = 1.0 / (1u64 << k) as f64;
        'attempt: loop {
            let mut occ = Occupancy::new(k, &pts);
            let mut free_x: Vec<u32> = (0..1u32 << k)
                .filter(|&x| !occ.occ[k as usize][x as usize])
                .collect();
            while pts.len() < end {
                // Random order of the free x strata; take the first few
                // admissible candidates.
                let mut best: Option<((f64, f64), f64, usize)> = None;
                let mut found = 0;
                let mut remaining = free_x.len();
                while remaining > 0 && found < candidates.max(1) {
                    let r = rng.uniform_bounded(remaining as u32) as usize;
                    free_x.swap(r, remaining - 1);
                    remaining -= 1;
                    let x = free_x[remaining];
                    if let Some(y) = occ.find_y(x, &mut rng) {
                        found += 1;
                        let p = (
                            (x as f64 + rng.uniform_float() as f64) * cell,
                            (y as f64 + rng.uniform_float() as f64) * cell,
                        );
                        let p = (p.0.min(1.0 - f64::EPSILON), p.1.min(1.0 - f64::EPSILON));
                        // Jitter must stay in the cell at f64 precision.
                        let (cx, cy) = occ.cells(p);
                        if cx != x || cy != y {
                            continue;
                        }
                        let d = grid.nearest_sq(p, &pts);
                        if best.map_or(true, |b| d > b.1) {
                            best = Some((p, d, remaining));
                        }
                    }
                }
                let Some((p, _, slot)) = best else {
                    // Dead end: restart this level.
                    pts.truncate(start);
                    grid = PointGrid::new(grid_res);
                    for (i, &q) in pts.iter().enumerate() {
                        grid.insert(q, i as u32);
                    }
                    continue 'attempt;
                };
                let (cx, cy) = occ.cells(p);
                occ.mark(cx, cy);
                free_x.swap_remove(slot);
                grid.insert(p, pts.len() as u32);
                pts.push(p);
            }
            break;
        }
    }
    pts
}

/// The PMJ02BN sampler.
#[derive(Clone, Debug)]
pub struct Pmj02bnSampler {
    samples_per_pixel: i32,
    seed: i32,
    pixel_tile_size: i32,
    pixel_samples: Arc<Vec<Point2f>>,
    pixel: Point2i,
    sample_index: i32,
    dimension: i32,
    blue_noise: BlueNoiseCache,
}

/// Slots of [`BlueNoiseCache`] (a power of two).
const BLUE_NOISE_SLOTS: usize = 1024;

/// The blue-noise offsets taken lately, by pixel (mod 256) and dimension:
/// every sample of a pixel takes the same ones, and each costs eight
/// hashes ([`blue_noise_sample`]). Direct-mapped, 8 KB a sampler (one
/// per thread); a pixel's dimensions and the few pixels a thread has in
/// flight fit.
#[derive(Clone, Debug)]
struct BlueNoiseCache {
    /// Per slot, its key (`u32::MAX`: empty) and value.
    slots: Box<[(u32, Float)]>,
}

impl Default for BlueNoiseCache {
    fn default() -> Self {
        BlueNoiseCache {
            slots: vec![(u32::MAX, 0.0); BLUE_NOISE_SLOTS].into_boxed_slice(),
        }
    }
}

impl BlueNoiseCache {
    /// [`blue_noise_sample`] of `p` and `dimension`.
    #[inline]
    fn get(&mut self, p: Point2i, dimension: i32) -> Float {
        // The key: the pixel mod 256 and the dimension below 2^15 (others
        // are computed every time; `u32::MAX` marks an empty slot).
        if !(0..1 << 15).contains(&dimension) {
            return blue_noise_sample(p, dimension);
        }
        let key = (((p.x & 255) as u32) << 23) | (((p.y & 255) as u32) << 15) | dimension as u32;
        let slot = (key.wrapping_mul(0x9e37_79b1) >> 22) as usize & (BLUE_NOISE_SLOTS - 1);
        let entry = &mut self.slots[slot];
        if entry.0 != key {
            *entry = (key, blue_noise_sample(p, dimension));
        }
        entry.1
    }
}

impl Pmj02bnSampler {
    /// A sampler with `samples_per_pixel` in 1..=65536 (best with powers of
    /// four). Pixel positions come from set 0, distributed over a tile of
    /// pixels so that each pixel receives `samples_per_pixel` of them.
    pub fn new(samples_per_pixel: i32, seed: i32) -> Result<Self, String> {
        if samples_per_pixel < 1 || samples_per_pixel as usize > N_PMJ02BN_SAMPLES {
            return Err(format!(
                "pmj02bn sampler supports 1 to {N_PMJ02BN_SAMPLES} samples per pixel, not {samples_per_pixel}"
            ));
        }
        // Every set is generated now, together (a render takes all five,
        // one after another on first use they took 0.7 s of a process).
        std::thread::scope(|s| {
            for set in 1..N_PMJ02BN_SETS {
                s.spawn(move || pmj02bn_set(set).len());
            }
            pmj02bn_set(0);
        });
        let spp = samples_per_pixel as usize;
        let log4_n = LOG2_PMJ02BN_SAMPLES / 2;
        let log4_spp = (spp as u32)
            .next_power_of_two()
            .trailing_zeros()
            .div_ceil(2);
        let tile = 1usize << (log4_n - log4_spp);
        let mut samples = vec![Point2f::new(0.0, 0.0); tile * tile * spp];
        let mut stored = vec![0usize; tile * tile];
        for &p in pmj02bn_set(0) {
            let (sx, sy) = (p.x * tile as Float, p.y * tile as Float);
            let (ix, iy) = ((sx as usize).min(tile - 1), (sy as usize).min(tile - 1));
            let offset = ix + iy * tile;
            if stored[offset] == spp {
                continue;
            }
            samples[offset * spp + stored[offset]] = Point2f::new(
                (sx - ix as Float).clamp(0.0, ONE_MINUS_EPSILON),
                (sy - iy as Float).clamp(0.0, ONE_MINUS_EPSILON),
            );
            stored[offset] += 1;
        }
        if stored.iter().any(|&c| c != spp) {
            return Err("pmj02bn sampler: generated point set is not stratified".into());
        }
        Ok(Pmj02bnSampler {
            samples_per_pixel,
            seed,
            pixel_tile_size: tile as i32,
            pixel_samples: Arc::new(samples),
            pixel: Point2i::new(0, 0),
            sample_index: 0,
            dimension: 0,
            blue_noise: BlueNoiseCache::default(),
        })
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

    /// Goes back to where [`Pmj02bnSampler::cursor`] stood.
    #[inline]
    pub fn set_cursor(&mut self, c: &super::SamplerCursor) {
        self.pixel = c.pixel;
        self.sample_index = c.index;
        self.dimension = c.dimension;
    }

    /// Starts sample `index` of pixel `p` at `dimension` (at least 2).
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, index: i32, dimension: i32) {
        self.pixel = p;
        self.sample_index = index;
        self.dimension = dimension.max(2);
    }

    #[inline]
    fn permuted_index(&self) -> usize {
        let hash = mix_bits(
            ((self.pixel.x as u64) << 48)
                ^ ((self.pixel.y as u64) << 32)
                ^ ((self.dimension as u64) << 16)
                ^ self.seed as i64 as u64,
        );
        permutation_element(
            self.sample_index as u32,
            self.samples_per_pixel as u32,
            hash as u32,
        ) as usize
    }

    /// The next 1-D value: a permuted stratum, offset per pixel.
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        let index = self.permuted_index();
        let delta = self.blue_noise.get(self.pixel, self.dimension);
        self.dimension += 1;
        ((index as Float + delta) / self.samples_per_pixel as Float).min(ONE_MINUS_EPSILON)
    }

    /// The next 2-D value: a pmj02bn point, toroidally shifted per pixel.
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        let instance = (self.dimension / 2) as usize;
        let index = if instance >= N_PMJ02BN_SETS {
            self.permuted_index()
        } else {
            self.sample_index as usize
        };
        let mut u = pmj02bn_sample(instance, index);
        u.x += self.blue_noise.get(self.pixel, self.dimension);
        u.y += self.blue_noise.get(self.pixel, self.dimension + 1);
        if u.x >= 1.0 {
            u.x -= 1.0;
        }
        if u.y >= 1.0 {
            u.y -= 1.0;
        }
        self.dimension += 2;
        Point2f::new(u.x.min(ONE_MINUS_EPSILON), u.y.min(ONE_MINUS_EPSILON))
    }

    /// The position within the pixel, from the pixel's share of set 0.
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        let px = self.pixel.x.rem_euclid(self.pixel_tile_size);
        let py = self.pixel.y.rem_euclid(self.pixel_tile_size);
        let offset = ((px + py * self.pixel_tile_size) * self.samples_per_pixel) as usize;
        self.pixel_samples[offset + self.sample_index as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cache gives `blue_noise_sample`'s values whatever it holds:
    /// pixels and dimensions taken in an order that keeps evicting
    /// (fixed), past the cached dimensions and at negative pixels.
    #[test]
    fn blue_noise_cache_gives_the_samples() {
        let mut cache = BlueNoiseCache::default();
        for round in 0..3 {
            for y in (-40..300).step_by(7) {
                for x in (-20..600).step_by(13) {
                    for d in [0, 1, 2, 5, 37, 200, 32_767, 32_768, 1 << 20] {
                        let p = Point2i::new(x + round, y);
                        assert_eq!(
                            cache.get(p, d).to_bits(),
                            blue_noise_sample(p, d).to_bits(),
                            "{p:?}, {d}"
                        );
                    }
                }
            }
        }
    }
}
