//! Sampling a piecewise-constant 2-D function restricted to a rectangle
//! chosen at sampling time (book section A.5.6; pbrt-v4
//! `SummedAreaTable` and `WindowedPiecewiseConstant2D` in
//! `util/sampling.h`).
//!
//! The portal light needs this: from every reference point the portal
//! covers a different axis-aligned window of its rectified image.

use rpbrt_geometry::{Bounds2f, Float, Point2f};

/// Integrals of a piecewise-constant function on [0,1]² over arbitrary
/// axis-aligned boxes, from a table of prefix sums (pbrt-v4
/// `SummedAreaTable`). Sums are kept in `f64` because differences of large
/// prefix sums cancel badly in single precision.
#[derive(Clone, Debug)]
pub struct SummedAreaTable {
    nx: usize,
    ny: usize,
    /// `sum[y * nx + x]`: the integral over [0, (x+1)/nx] × [0, (y+1)/ny].
    sum: Vec<f64>,
}

impl SummedAreaTable {
    /// The table of `f` (`nx` × `ny` values, row by row, y major).
    pub fn new(f: &[Float], nx: usize, ny: usize) -> Self {
        debug_assert_eq!(f.len(), nx * ny);
        let cell = 1.0 / (nx as f64 * ny as f64);
        let mut sum = vec![0.0f64; nx * ny];
        for y in 0..ny {
            let mut row = 0.0f64;
            for x in 0..nx {
                row += f[y * nx + x] as f64 * cell;
                let below = if y > 0 { sum[(y - 1) * nx + x] } else { 0.0 };
                sum[y * nx + x] = row + below;
            }
        }
        SummedAreaTable { nx, ny, sum }
    }

    /// The integral over [0, x/nx] × [0, y/ny] for integer corners; zero on
    /// the lower edges, clamped at the upper ones.
    #[inline]
    fn corner(&self, x: i64, y: i64) -> f64 {
        if x <= 0 || y <= 0 {
            return 0.0;
        }
        let xi = ((x - 1) as usize).min(self.nx - 1);
        let yi = ((y - 1) as usize).min(self.ny - 1);
        self.sum[yi * self.nx + xi]
    }

    /// The integral over [0, x] × [0, y]: bilinear between the integer
    /// corners, which is exact for a piecewise-constant function.
    fn lookup(&self, x: Float, y: Float) -> f64 {
        let x = x as f64 * self.nx as f64;
        let y = y as f64 * self.ny as f64;
        let (x0, y0) = (x.floor(), y.floor());
        let (dx, dy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let v00 = self.corner(x0, y0);
        let v10 = self.corner(x0 + 1, y0);
        let v01 = self.corner(x0, y0 + 1);
        let v11 = self.corner(x0 + 1, y0 + 1);
        (1.0 - dx) * (1.0 - dy) * v00
            + dx * (1.0 - dy) * v10
            + (1.0 - dx) * dy * v01
            + dx * dy * v11
    }

    /// The integral of the function over `b` (never negative).
    pub fn sum(&self, b: &Bounds2f) -> Float {
        let s = (self.lookup(b.p_max.x, b.p_max.y) - self.lookup(b.p_min.x, b.p_max.y))
            + (self.lookup(b.p_min.x, b.p_min.y) - self.lookup(b.p_max.x, b.p_min.y));
        s.max(0.0) as Float
    }
}

/// A piecewise-constant function on [0,1]² that can be sampled, and whose
/// density can be evaluated, restricted to any axis-aligned window (pbrt-v4
/// `WindowedPiecewiseConstant2D`).
#[derive(Clone, Debug)]
pub struct WindowedPiecewiseConstant2D {
    sat: SummedAreaTable,
    func: Vec<Float>,
    nx: usize,
    ny: usize,
}

impl WindowedPiecewiseConstant2D {
    /// The distribution of `f` (`nx` × `ny` non-negative values, y major).
    pub fn new(f: &[Float], nx: usize, ny: usize) -> Self {
        debug_assert!(nx > 0 && ny > 0 && f.len() == nx * ny);
        WindowedPiecewiseConstant2D {
            sat: SummedAreaTable::new(f, nx, ny),
            func: f.to_vec(),
            nx,
            ny,
        }
    }

    /// The function's value at `p`.
    #[inline]
    fn eval(&self, p: Point2f) -> Float {
        let x = ((p.x * self.nx as Float).max(0.0) as usize).min(self.nx - 1);
        let y = ((p.y * self.ny as Float).max(0.0) as usize).min(self.ny - 1);
        self.func[y * self.nx + x]
    }

    /// Inverts the monotone cumulative function `cdf` on [min, max] at `u`:
    /// bisection until one cell of `n` brackets `u`, then linear
    /// interpolation, exact inside a cell.
    fn invert_cdf(
        cdf: impl Fn(Float) -> Float,
        u: Float,
        mut min: Float,
        mut max: Float,
        n: usize,
    ) -> Float {
        let n = n as Float;
        // Halving stops once min and max share a cell; the cap only guards
        // against a non-terminating loop on pathological rounding.
        let mut steps = 0;
        while (n * max).ceil() - (n * min).floor() > 1.0 && steps < 64 {
            let mid = 0.5 * (min + max);
            if cdf(mid) > u {
                max = mid;
            } else {
                min = mid;
            }
            steps += 1;
        }
        let (c0, c1) = (cdf(min), cdf(max));
        let t = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.0 };
        ((1.0 - t) * min + t * max).clamp(min, max)
    }

    /// Samples a point of window `b` with density proportional to the
    /// function; `None` where the function is zero over the window.
    /// Returns the point and its density over [0,1]².
    pub fn sample(&self, u: Point2f, b: &Bounds2f) -> Option<(Point2f, Float)> {
        let sum_b = self.sat.sum(b);
        if sum_b == 0.0 {
            return None;
        }
        // Marginal in x over the window.
        let px = |x: Float| {
            let mut bx = *b;
            bx.p_max.x = x;
            self.sat.sum(&bx) / sum_b
        };
        let x = Self::invert_cdf(px, u.x, b.p_min.x, b.p_max.x, self.nx);
        // Conditional in y within the column that holds x.
        let nx = self.nx as Float;
        let mut by = *b;
        by.p_min.x = (x * nx).floor() / nx;
        by.p_max.x = (x * nx).ceil() / nx;
        if by.p_min.x == by.p_max.x {
            by.p_max.x += 1.0 / nx;
        }
        let sum_by = self.sat.sum(&by);
        if sum_by == 0.0 {
            // A window narrower than rounding can resolve.
            return None;
        }
        let py = |y: Float| {
            let mut byy = by;
            byy.p_max.y = y;
            self.sat.sum(&byy) / sum_by
        };
        let y = Self::invert_cdf(py, u.y, b.p_min.y, b.p_max.y, self.ny);
        let p = Point2f::new(x, y);
        Some((p, self.pdf(p, b)))
    }

    /// The density over [0,1]² with which [`sample`](Self::sample) picks
    /// `p` from window `b`: zero outside the window (pbrt-v4 evaluates the
    /// function there regardless; callers never weight such points).
    pub fn pdf(&self, p: Point2f, b: &Bounds2f) -> Float {
        if !b.inside(p) {
            return 0.0;
        }
        let sum_b = self.sat.sum(b);
        if sum_b == 0.0 {
            return 0.0;
        }
        self.eval(p) / sum_b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn func(nx: usize, ny: usize) -> Vec<Float> {
        (0..nx * ny)
            .map(|i| ((i * 7 + 3) % 11) as Float * if i % 5 == 0 { 0.0 } else { 1.0 })
            .collect()
    }

    #[test]
    fn sat_matches_brute_force_sums() {
        let (nx, ny) = (7, 5);
        let f = func(nx, ny);
        let sat = SummedAreaTable::new(&f, nx, ny);
        let mut rng = Rng::with_sequence(3);
        for _ in 0..200 {
            let a = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let c = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let b = Bounds2f::new(a, c);
            // Integrate by midpoint rule on a fine grid.
            let m = 700;
            let mut s = 0.0f64;
            for j in 0..m {
                for i in 0..m {
                    let p = Point2f::new(
                        b.p_min.x + (i as Float + 0.5) / m as Float * (b.p_max.x - b.p_min.x),
                        b.p_min.y + (j as Float + 0.5) / m as Float * (b.p_max.y - b.p_min.y),
                    );
                    let xi = ((p.x * nx as Float) as usize).min(nx - 1);
                    let yi = ((p.y * ny as Float) as usize).min(ny - 1);
                    s += f[yi * nx + xi] as f64;
                }
            }
            let expect = s / (m * m) as f64 * b.area() as f64;
            assert!(
                (sat.sum(&b) as f64 - expect).abs() < 2e-3 * (1.0 + expect),
                "{b:?}: {} vs {expect}",
                sat.sum(&b)
            );
        }
    }

    #[test]
    fn windowed_samples_stay_inside_and_match_pdf() {
        let (nx, ny) = (8, 6);
        let f = func(nx, ny);
        let d = WindowedPiecewiseConstant2D::new(&f, nx, ny);
        let b = Bounds2f::new(Point2f::new(0.13, 0.21), Point2f::new(0.77, 0.9));
        let mut rng = Rng::with_sequence(9);
        let n = 200_000;
        let mut hist = vec![0usize; nx * ny];
        for _ in 0..n {
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let (p, pdf) = d.sample(u, &b).unwrap();
            assert!(b.inside(p), "{p:?}");
            assert!(pdf > 0.0);
            assert_eq!(pdf, d.pdf(p, &b));
            let xi = ((p.x * nx as Float) as usize).min(nx - 1);
            let yi = ((p.y * ny as Float) as usize).min(ny - 1);
            hist[yi * nx + xi] += 1;
        }
        // Expected share of each cell: f times the cell's overlap with b.
        let total = d.sat.sum(&b) as f64;
        for y in 0..ny {
            for x in 0..nx {
                let cell = Bounds2f::new(
                    Point2f::new(x as Float / nx as Float, y as Float / ny as Float),
                    Point2f::new(
                        (x + 1) as Float / nx as Float,
                        (y + 1) as Float / ny as Float,
                    ),
                )
                .intersect(&b);
                let area = if cell.is_empty() { 0.0 } else { cell.area() };
                let expect = f[y * nx + x] as f64 * area as f64 / total * n as f64;
                let got = hist[y * nx + x] as f64;
                assert!(
                    (got - expect).abs() <= 5.0 * expect.sqrt() + 2.0,
                    "cell ({x},{y}): {got} vs {expect}"
                );
            }
        }
        assert_eq!(d.pdf(Point2f::new(0.05, 0.5), &b), 0.0);
        let empty = Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(0.1, 0.1));
        // Cell (0,0) holds f = 0 (index 0 is zeroed).
        assert!(d.sample(Point2f::new(0.5, 0.5), &empty).is_none());
    }
}
