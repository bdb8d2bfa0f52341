//! SPPM's grid of visible points (pbrt-v4 `SPPMIntegrator::Render`'s
//! hashed grid and `ToGrid`, `cpu/integrators.cpp`; pbrt-v3 book section
//! 16.2.5): a uniform grid over the visible points' bounds, with cells about
//! the size of the largest search radius, hashed into a table with as many
//! buckets as the image has pixels. Each visible point is entered in every
//! cell its search sphere overlaps, so a photon looks at one cell only.
//!
//! pbrt-v4 pushes points onto per-bucket lists with atomics, in thread
//! order. Here the buckets are one flat array sorted by bucket (a counting
//! sort), each bucket holding its points in pixel order: an order that does
//! not depend on the thread count. One deliberate difference: pbrt-v4
//! enters a point once per cell, so a point two of whose cells hash to the
//! same bucket is listed there twice and takes the photons of those cells
//! twice; here it is listed once. With a bucket per pixel the collisions
//! are rare on real images (about one point in two thousand at 256×256),
//! but on tiny ones they brighten the image by percents.

use rayon::prelude::*;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

use crate::sampler::lowdiscrepancy::murmur_hash64a;

/// A visible point as the grid holds it: what a photon needs to decide
/// whether it lands within the point's search radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct GridEntry {
    /// The visible point.
    pub p: Point3f,
    /// Its pixel's squared search radius.
    pub r2: Float,
    /// Its pixel's index in the render's pixel array.
    pub pixel: u32,
}

/// The hashed grid of one iteration's visible points.
pub(super) struct VisiblePointGrid {
    /// The visible points' bounds, grown by their radii.
    bounds: Bounds3f,
    /// Cells along each axis.
    res: [i32; 3],
    /// Bucket `h` holds `entries[starts[h]..starts[h + 1]]`.
    starts: Vec<u32>,
    /// The entries of all buckets, bucket by bucket.
    entries: Vec<GridEntry>,
}

/// Visible points per unit of parallel work while the grid is built.
const BUILD_CHUNK: usize = 4096;

impl VisiblePointGrid {
    /// Builds the grid of `points` (each a visible point, its search
    /// radius and its pixel index) with `hash_size` buckets. `None` when
    /// there is no point (or the radii leave no usable grid): no photon
    /// can then land anywhere.
    pub fn new(points: &[(Point3f, Float, u32)], hash_size: usize) -> Option<Self> {
        // Bounds and largest radius, as pbrt-v4 computes them.
        let mut bounds = Bounds3f::empty();
        let mut max_radius: Float = 0.0;
        for &(p, r, _) in points {
            bounds = bounds.union(&Bounds3f::from_point(p).expand(r));
            max_radius = max_radius.max(r);
        }
        if points.is_empty() || max_radius.is_nan() || max_radius <= 0.0 || hash_size == 0 {
            return None;
        }
        let diag = bounds.diagonal();
        let max_diag = diag.max_component_value();
        // Float-to-int casts saturate (pbrt-v4's C casts would not, for
        // radii absurdly small against the scene).
        let base_res = (max_diag / max_radius) as i32;
        let mut res = [1; 3];
        for (i, r) in res.iter_mut().enumerate() {
            *r = ((base_res as Float * diag[i] / max_diag) as i32).max(1);
        }
        let mut grid = VisiblePointGrid {
            bounds,
            res,
            starts: Vec::new(),
            entries: Vec::new(),
        };

        // Each point's (bucket, entry) pairs, computed in parallel in
        // chunks whose results are kept in point order.
        let pairs: Vec<Vec<(u32, GridEntry)>> = points
            .par_chunks(BUILD_CHUNK)
            .map(|chunk| {
                let mut out = Vec::with_capacity(chunk.len() * 8);
                let mut buckets: Vec<u32> = Vec::new();
                for &(p, r, pixel) in chunk {
                    let rv = Vector3f::new(r, r, r);
                    let (p_min, _) = grid.to_grid(p - rv);
                    let (p_max, _) = grid.to_grid(p + rv);
                    let entry = GridEntry {
                        p,
                        r2: r * r,
                        pixel,
                    };
                    buckets.clear();
                    for z in p_min[2]..=p_max[2] {
                        for y in p_min[1]..=p_max[1] {
                            for x in p_min[0]..=p_max[0] {
                                buckets.push(hash_cell([x, y, z], hash_size) as u32);
                            }
                        }
                    }
                    // Cells that share a bucket list the point once.
                    buckets.sort_unstable();
                    buckets.dedup();
                    out.extend(buckets.iter().map(|&h| (h, entry)));
                }
                out
            })
            .collect();

        // Counting sort by bucket, stable: each bucket's entries stay in
        // point (pixel) order.
        let mut starts = vec![0u32; hash_size + 1];
        for chunk in &pairs {
            for &(h, _) in chunk {
                starts[h as usize + 1] += 1;
            }
        }
        for h in 0..hash_size {
            starts[h + 1] += starts[h];
        }
        let total = starts[hash_size] as usize;
        let mut next: Vec<u32> = starts[..hash_size].to_vec();
        let placeholder = GridEntry {
            p: Point3f::new(0.0, 0.0, 0.0),
            r2: 0.0,
            pixel: 0,
        };
        let mut entries = vec![placeholder; total];
        for chunk in &pairs {
            for &(h, e) in chunk {
                let slot = &mut next[h as usize];
                entries[*slot as usize] = e;
                *slot += 1;
            }
        }
        grid.starts = starts;
        grid.entries = entries;
        Some(grid)
    }

    /// The cell holding `p` (clamped into the grid) and whether `p` lies
    /// inside it (pbrt-v4 `ToGrid`: the truncation toward zero counts
    /// points less than a cell below the bounds as inside, as there).
    #[inline]
    fn to_grid(&self, p: Point3f) -> ([i32; 3], bool) {
        let pg = self.bounds.offset(p);
        let mut in_bounds = true;
        let mut cell = [0; 3];
        for (i, c) in cell.iter_mut().enumerate() {
            let v = (self.res[i] as Float * pg[i]) as i32;
            in_bounds &= v >= 0 && v < self.res[i];
            *c = v.clamp(0, self.res[i] - 1);
        }
        (cell, in_bounds)
    }

    /// The visible points that may lie within their search radius of `p`:
    /// those of `p`'s cell's bucket (empty when `p` is outside the grid).
    #[inline]
    pub fn candidates(&self, p: Point3f) -> &[GridEntry] {
        let (cell, in_bounds) = self.to_grid(p);
        if !in_bounds {
            return &[];
        }
        let h = hash_cell(cell, self.starts.len() - 1);
        &self.entries[self.starts[h] as usize..self.starts[h + 1] as usize]
    }

    /// Grid entries in all (visible points times cells overlapped).
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.entries.len()
    }
}

/// The bucket of a grid cell: pbrt-v4's `Hash(Point3i)` (MurmurHash64A of
/// the three coordinates' bytes, seed 0) modulo the table size.
#[inline]
fn hash_cell(c: [i32; 3], hash_size: usize) -> usize {
    let mut bytes = [0u8; 12];
    for (i, v) in c.iter().enumerate() {
        bytes[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    (murmur_hash64a(&bytes, 0) % hash_size as u64) as usize
}

/// The smallest prime at least `x` (pbrt-v4 `NextPrime`; 3 for `x` < 3
/// other than 2).
// `is_multiple_of` is newer than the workspace's rust-version (1.80).
#[allow(clippy::manual_is_multiple_of)]
pub(super) fn next_prime(x: u64) -> u64 {
    if x == 2 {
        return 2;
    }
    let mut x = if x % 2 == 0 { x + 1 } else { x };
    while !is_prime(x) {
        x += 2;
    }
    x
}

#[allow(clippy::manual_is_multiple_of)]
fn is_prime(n: u64) -> bool {
    if n <= 1 {
        return false;
    }
    if n <= 3 {
        return true;
    }
    if n % 2 == 0 || n % 3 == 0 {
        return false;
    }
    let mut i = 5;
    while i * i <= n {
        if n % i == 0 || n % (i + 2) == 0 {
            return false;
        }
        i += 6;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_prime_matches_pbrt_v4() {
        assert_eq!(next_prime(0), 3);
        assert_eq!(next_prime(1), 3);
        assert_eq!(next_prime(2), 2);
        assert_eq!(next_prime(3), 3);
        assert_eq!(next_prime(4), 5);
        assert_eq!(next_prime(100), 101);
        assert_eq!(next_prime(65536), 65537);
        assert_eq!(next_prime(65538), 65539);
    }

    /// Every point within its radius of a query point is among the
    /// query's candidates (checked against brute force).
    #[test]
    fn candidates_hold_every_point_in_reach() {
        let mut rng = crate::rng::Rng::with_sequence(7);
        let mut points = Vec::new();
        for i in 0..500u32 {
            let p = Point3f::new(
                rng.uniform_float(),
                rng.uniform_float(),
                rng.uniform_float(),
            );
            let r = 0.02 + 0.1 * rng.uniform_float();
            points.push((p, r, i));
        }
        let grid = VisiblePointGrid::new(&points, next_prime(points.len() as u64) as usize)
            .expect("a grid");
        assert!(grid.len() >= points.len());
        for _ in 0..2000 {
            let q = Point3f::new(
                1.2 * rng.uniform_float() - 0.1,
                1.2 * rng.uniform_float() - 0.1,
                1.2 * rng.uniform_float() - 0.1,
            );
            let cands = grid.candidates(q);
            for &(p, r, i) in &points {
                if p.distance_squared(q) <= r * r {
                    assert!(
                        cands.iter().any(|e| e.pixel == i),
                        "point {i} within reach of {q:?} missing"
                    );
                }
            }
            // Buckets keep pixel order and list a point once.
            assert!(cands.windows(2).all(|w| w[0].pixel < w[1].pixel));
        }
    }

    #[test]
    fn no_points_no_grid() {
        assert!(VisiblePointGrid::new(&[], 3).is_none());
        let p = Point3f::new(0.0, 0.0, 0.0);
        assert!(VisiblePointGrid::new(&[(p, 0.0, 0)], 3).is_none());
    }
}
