//! Tabulated distributions (book section A.5.2 and A.5.3; pbrt-v4
//! `util/sampling.h`, `PiecewiseConstant1D`/`PiecewiseConstant2D`):
//! sampling proportionally to a piecewise-constant function given by
//! values over equal-width cells of an interval or a rectangle.
//!
//! As in pbrt-v4, the absolute value of the function is used, and a
//! function that is zero everywhere is sampled uniformly (with a reported
//! density of zero, so callers can tell).

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds2f;

/// A piecewise-constant 1-D distribution over `[min, max]`.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant1D {
    func: Vec<Float>,
    cdf: Vec<Float>,
    min: Float,
    max: Float,
    func_int: Float,
}

impl PiecewiseConstant1D {
    /// The distribution of `|f|` over `[0, 1]`.
    pub fn new(f: &[Float]) -> Self {
        Self::with_range(f, 0.0, 1.0)
    }

    /// The distribution of `|f|` over `[min, max]`; `f` holds the values of
    /// equal-width cells. An empty `f` is treated as a single zero cell.
    pub fn with_range(f: &[Float], min: Float, max: Float) -> Self {
        let func: Vec<Float> = if f.is_empty() {
            vec![0.0]
        } else {
            f.iter().map(|v| v.abs()).collect()
        };
        let n = func.len();
        // Accumulate in f64 so long tables keep a monotone, accurate CDF.
        let width = (max - min) as f64 / n as f64;
        let mut acc = vec![0.0f64; n + 1];
        for i in 1..=n {
            acc[i] = acc[i - 1] + func[i - 1] as f64 * width;
        }
        let total = acc[n];
        let cdf: Vec<Float> = if total == 0.0 {
            (0..=n).map(|i| i as Float / n as Float).collect()
        } else {
            acc.iter().map(|c| (c / total) as Float).collect()
        };
        PiecewiseConstant1D {
            func,
            cdf,
            min,
            max,
            func_int: total as Float,
        }
    }

    /// The integral of `|f|` over `[min, max]`.
    #[inline]
    pub fn integral(&self) -> Float {
        self.func_int
    }

    /// Number of cells.
    #[inline]
    pub fn size(&self) -> usize {
        self.func.len()
    }

    /// The (absolute) function values.
    #[inline]
    pub fn func(&self) -> &[Float] {
        &self.func
    }

    /// Lower end of the domain.
    #[inline]
    pub fn min(&self) -> Float {
        self.min
    }

    /// Upper end of the domain.
    #[inline]
    pub fn max(&self) -> Float {
        self.max
    }

    /// Samples `x` with density ∝ |f| for `u` ∈ [0,1); returns `(x, pdf,
    /// cell offset)`. The pdf is with respect to `x` (zero if `f` ≡ 0).
    #[inline]
    pub fn sample(&self, u: Float) -> (Float, Float, usize) {
        let o = find_interval(self.cdf.len(), |i| self.cdf[i] <= u);
        self.sample_in(o, u)
    }

    /// [`sample`](Self::sample) once the interval `o` holding `u` is found.
    #[inline(always)]
    fn sample_in(&self, o: usize, u: Float) -> (Float, Float, usize) {
        let mut du = u - self.cdf[o];
        let width = self.cdf[o + 1] - self.cdf[o];
        if width > 0.0 {
            du /= width;
        }
        let pdf = if self.func_int > 0.0 {
            self.func[o] / self.func_int
        } else {
            0.0
        };
        let x = lerp((o as Float + du) / self.size() as Float, self.min, self.max);
        (x, pdf, o)
    }

    /// The density at `x` (zero outside the domain or if `f` ≡ 0).
    pub fn pdf(&self, x: Float) -> Float {
        if !(self.min..=self.max).contains(&x) || self.func_int == 0.0 {
            return 0.0;
        }
        let c = (x - self.min) / (self.max - self.min) * self.size() as Float;
        let o = (c as usize).min(self.size() - 1);
        self.func[o] / self.func_int
    }

    /// The sample `u` that [`sample`](Self::sample) maps to `x`, or `None`
    /// if `x` is outside the domain.
    pub fn invert(&self, x: Float) -> Option<Float> {
        if !(x >= self.min && x <= self.max) {
            return None;
        }
        let c = (x - self.min) / (self.max - self.min) * self.size() as Float;
        let offset = (c.max(0.0) as usize).min(self.size() - 1);
        let delta = c - offset as Float;
        Some(lerp(delta, self.cdf[offset], self.cdf[offset + 1]))
    }
}

/// A piecewise-constant 2-D distribution over a rectangle, sampled as a
/// marginal in y and conditionals in x.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant2D {
    domain: Bounds2f,
    conditional: Vec<PiecewiseConstant1D>,
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// The distribution of `|f|` over `domain`, with `f` given row by row:
    /// `nu` values in x for each of `nv` rows in y (`f.len() == nu * nv`;
    /// missing values count as zero).
    pub fn new(f: &[Float], nu: usize, nv: usize, domain: Bounds2f) -> Self {
        let nu = nu.max(1);
        let nv = nv.max(1);
        let conditional: Vec<PiecewiseConstant1D> = (0..nv)
            .map(|v| {
                let row: Vec<Float> = (0..nu)
                    .map(|u| f.get(v * nu + u).copied().unwrap_or(0.0))
                    .collect();
                PiecewiseConstant1D::with_range(&row, domain.p_min.x, domain.p_max.x)
            })
            .collect();
        let marginal_func: Vec<Float> = conditional.iter().map(|c| c.integral()).collect();
        let marginal =
            PiecewiseConstant1D::with_range(&marginal_func, domain.p_min.y, domain.p_max.y);
        PiecewiseConstant2D {
            domain,
            conditional,
            marginal,
        }
    }

    /// The distribution of `|f|` over [0,1]².
    pub fn unit(f: &[Float], nu: usize, nv: usize) -> Self {
        Self::new(
            f,
            nu,
            nv,
            Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(1.0, 1.0)),
        )
    }

    /// The integral of `|f|` over the domain.
    #[inline]
    pub fn integral(&self) -> Float {
        self.marginal.integral()
    }

    /// The domain.
    #[inline]
    pub fn domain(&self) -> Bounds2f {
        self.domain
    }

    /// Table resolution (nu, nv).
    #[inline]
    pub fn resolution(&self) -> (usize, usize) {
        (self.conditional[0].size(), self.marginal.size())
    }

    /// Samples a point with density ∝ |f|; returns `(p, pdf, cell)`, the
    /// pdf with respect to area in the domain.
    #[inline]
    pub fn sample(&self, u: Point2f) -> (Point2f, Float, Point2i) {
        let (d1, pdf1, v) = self.marginal.sample(u.y);
        let (d0, pdf0, uo) = self.conditional[v].sample(u.x);
        (
            Point2f::new(d0, d1),
            pdf0 * pdf1,
            Point2i::new(uo as i32, v as i32),
        )
    }

    /// [`sample`](Self::sample) of every value of `us`, into `out` (as
    /// long): the same samples, found a batch at a time with interleaved
    /// searches ([`find_intervals`]), the marginal's first and then each
    /// sample's conditional.
    pub fn sample_many(&self, us: &[Point2f], out: &mut [(Point2f, Float, Point2i)]) {
        const BATCH: usize = 16;
        let mut rows = [0usize; BATCH];
        let mut cols = [0usize; BATCH];
        for (us, out) in us.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
            let n = us.len();
            let cdf = &self.marginal.cdf;
            find_intervals(cdf.len(), &mut rows[..n], |k, i| cdf[i] <= us[k].y);
            // Every conditional has the same size; each search's table is
            // looked up once, not at every probe.
            let size = self.conditional[0].cdf.len();
            let mut cdfs: [&[Float]; BATCH] = [&[]; BATCH];
            for (c, &row) in cdfs.iter_mut().zip(&rows[..n]) {
                *c = &self.conditional[row].cdf;
            }
            find_intervals(size, &mut cols[..n], |k, i| cdfs[k][i] <= us[k].x);
            for k in 0..n {
                let (d1, pdf1, v) = self.marginal.sample_in(rows[k], us[k].y);
                let (d0, pdf0, uo) = self.conditional[v].sample_in(cols[k], us[k].x);
                out[k] = (
                    Point2f::new(d0, d1),
                    pdf0 * pdf1,
                    Point2i::new(uo as i32, v as i32),
                );
            }
        }
    }

    /// The density at `p` (area measure).
    pub fn pdf(&self, p: Point2f) -> Float {
        let o = self.domain.offset(p);
        let (nu, nv) = self.resolution();
        let iu = ((o.x * nu as Float) as i64).clamp(0, nu as i64 - 1) as usize;
        let iv = ((o.y * nv as Float) as i64).clamp(0, nv as i64 - 1) as usize;
        let int = self.marginal.integral();
        if int == 0.0 {
            return 0.0;
        }
        self.conditional[iv].func()[iu] / int
    }

    /// The sample `u` that [`sample`](Self::sample) maps to `p`, or `None`
    /// outside the domain.
    pub fn invert(&self, p: Point2f) -> Option<Point2f> {
        let m = self.marginal.invert(p.y)?;
        let t = (p.y - self.domain.p_min.y) / (self.domain.p_max.y - self.domain.p_min.y);
        if !(0.0..=1.0).contains(&t) {
            return None;
        }
        let nv = self.conditional.len();
        let offset = ((t * nv as Float) as usize).min(nv - 1);
        let c = self.conditional[offset].invert(p.x)?;
        Some(Point2f::new(c, m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn one_d_sample_pdf_invert() {
        let f = [0.0, 1.0, -3.0, 2.0, 0.5];
        let d = PiecewiseConstant1D::with_range(&f, -1.0, 4.0);
        // |f| summed times width 1.
        assert!((d.integral() - 6.5).abs() < 1e-5);
        let mut r = Rng::new(1, 0);
        let mut hist = [0usize; 5];
        let n = 200_000;
        for _ in 0..n {
            let u = r.uniform_float();
            let (x, pdf, o) = d.sample(u);
            assert!((-1.0..=4.0).contains(&x));
            assert_eq!(o, ((x + 1.0) as usize).min(4));
            assert!((pdf - d.pdf(x)).abs() < 1e-6, "{x} {pdf}");
            assert!(pdf > 0.0);
            let back = d.invert(x).unwrap();
            assert!((back - u).abs() < 1e-4, "{u} {back}");
            hist[o] += 1;
        }
        for (i, &h) in hist.iter().enumerate() {
            let expect = f[i].abs() / 6.5;
            assert!((h as f64 / n as f64 - expect as f64).abs() < 0.005);
        }
        assert!(d.invert(4.5).is_none());
    }

    #[test]
    fn zero_function_is_uniform() {
        let d = PiecewiseConstant1D::new(&[0.0, 0.0, 0.0, 0.0]);
        assert_eq!(d.integral(), 0.0);
        let (x, pdf, o) = d.sample(0.6);
        assert!((x - 0.6).abs() < 1e-6);
        assert_eq!(pdf, 0.0);
        assert_eq!(o, 2);
        let d2 = PiecewiseConstant2D::unit(&[0.0; 6], 3, 2);
        let (p, pdf, _) = d2.sample(Point2f::new(0.25, 0.75));
        assert!((p.x - 0.25).abs() < 1e-6 && (p.y - 0.75).abs() < 1e-6);
        assert_eq!(pdf, 0.0);
    }

    #[test]
    fn two_d_sample_pdf_invert() {
        let (nu, nv) = (7, 5);
        let f: Vec<Float> = (0..nu * nv)
            .map(|i| ((i * 37 % 11) as Float - 3.0) * if i % 4 == 0 { 0.0 } else { 1.0 })
            .collect();
        let domain = Bounds2f::new(Point2f::new(-2.0, 1.0), Point2f::new(1.5, 3.0));
        let d = PiecewiseConstant2D::new(&f, nu, nv, domain);
        let cell_area = domain.area() / (nu * nv) as Float;
        let expect_int: Float = f.iter().map(|v| v.abs()).sum::<Float>() * cell_area;
        assert!((d.integral() - expect_int).abs() < 1e-4 * expect_int);
        let mut r = Rng::new(2, 0);
        let mut est = 0.0f64;
        let n = 100_000;
        for _ in 0..n {
            let u = Point2f::new(r.uniform_float(), r.uniform_float());
            let (p, pdf, cell) = d.sample(u);
            assert!(pdf > 0.0);
            assert!((pdf - d.pdf(p)).abs() < 1e-5 * pdf.max(1.0), "{p:?}");
            let fc = f[cell.y as usize * nu + cell.x as usize].abs() / d.integral();
            assert!((fc - pdf).abs() < 1e-5 * pdf);
            let back = d.invert(p).unwrap();
            assert!((back - u).length() < 1e-3, "{u:?} {back:?}");
            // E[1/pdf] over the support = area of the support.
            est += 1.0 / pdf as f64;
        }
        let support = f.iter().filter(|v| **v != 0.0).count() as f64 * cell_area as f64;
        assert!((est / n as f64 - support).abs() < 0.02 * support);
    }

    #[test]
    fn two_d_batched_samples_match_single_ones() {
        // Tables with zero rows and cells, of sizes that make the
        // interleaved searches take every number of rounds, and batches
        // longer and shorter than the searches' chunk.
        for (nu, nv) in [(1, 1), (7, 5), (48, 48), (3, 33)] {
            let f: Vec<Float> = (0..nu * nv)
                .map(|i| ((i * 37 % 11) as Float) * if i % 5 == 0 { 0.0 } else { 1.0 })
                .collect();
            let domain = Bounds2f::new(Point2f::new(-1.5, -1.5), Point2f::new(1.5, 1.5));
            let d = PiecewiseConstant2D::new(&f, nu, nv, domain);
            let mut r = Rng::new(9, 0);
            for n in [0, 1, 5, 16, 17, 100] {
                let mut us: Vec<Point2f> = (0..n)
                    .map(|_| Point2f::new(r.uniform_float(), r.uniform_float()))
                    .collect();
                if n > 2 {
                    us[0] = Point2f::new(0.0, 0.0);
                    us[1] = Point2f::new(ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
                }
                let mut out = vec![(Point2f::new(0.0, 0.0), -1.0, Point2i::new(-1, -1)); n];
                d.sample_many(&us, &mut out);
                for (u, o) in us.iter().zip(&out) {
                    let e = d.sample(*u);
                    assert_eq!(
                        (o.0.x.to_bits(), o.0.y.to_bits(), o.1.to_bits(), o.2),
                        (e.0.x.to_bits(), e.0.y.to_bits(), e.1.to_bits(), e.2),
                        "{nu}x{nv}, u {u:?}"
                    );
                }
            }
        }
    }
}
