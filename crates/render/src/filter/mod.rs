//! Image reconstruction filters (book section 8.8; pbrt-v4 `filters.h`,
//! `filters.cpp`): box, Gaussian, Mitchell–Netravali, Lanczos-windowed
//! sinc and triangle, each with its value, radius, integral and a sampling
//! routine that draws filter offsets with density ∝ |f| and weight f/pdf.
//!
//! Box and triangle are sampled analytically (weight 1); the others through
//! a [`FilterSampler`]: the filter tabulated at 32 cells per unit radius and
//! sampled as a [`PiecewiseConstant2D`].

mod create;
#[cfg(test)]
mod tests;

pub use create::{create_filter, FILTER_NAMES};

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds2f;

use crate::sampling::sample_linear;
use crate::sampling::tabulated::PiecewiseConstant2D;

/// An offset drawn from a filter and the weight to apply to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// Offset from the pixel centre, within the filter radius.
    pub p: Point2f,
    /// f(p) / pdf(p): constant in magnitude, negative where f is.
    pub weight: Float,
}

/// Tabulated sampling of an arbitrary filter (pbrt-v4's `FilterSampler`).
#[derive(Clone, Debug)]
pub struct FilterSampler {
    f: Vec<Float>,
    nx: usize,
    distrib: PiecewiseConstant2D,
}

impl FilterSampler {
    /// Tabulates `eval` over [−radius, radius] at 32 cells per unit radius.
    pub fn new(radius: Vector2f, eval: impl Fn(Point2f) -> Float) -> Self {
        let domain = Bounds2f::new(
            Point2f::new(-radius.x, -radius.y),
            Point2f::new(radius.x, radius.y),
        );
        let nx = ((32.0 * radius.x) as usize).max(1);
        let ny = ((32.0 * radius.y) as usize).max(1);
        let mut f = Vec::with_capacity(nx * ny);
        for y in 0..ny {
            for x in 0..nx {
                let p = domain.lerp(Point2f::new(
                    (x as Float + 0.5) / nx as Float,
                    (y as Float + 0.5) / ny as Float,
                ));
                f.push(eval(p));
            }
        }
        let distrib = PiecewiseConstant2D::new(&f, nx, ny, domain);
        FilterSampler { f, nx, distrib }
    }

    /// Draws an offset with density ∝ |tabulated f|.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        let (p, pdf, cell) = self.distrib.sample(u);
        let fv = self.f[cell.y as usize * self.nx + cell.x as usize];
        let weight = if pdf > 0.0 { fv / pdf } else { 0.0 };
        FilterSample { p, weight }
    }

    /// [`sample`](Self::sample) of every value of `us`, appended to `out`
    /// (the table searches of a batch interleaved:
    /// [`PiecewiseConstant2D::sample_many`]).
    pub fn sample_many(&self, us: &[Point2f], out: &mut Vec<FilterSample>) {
        const BATCH: usize = 64;
        let mut found = [(Point2f::new(0.0, 0.0), 0.0, Point2i::new(0, 0)); BATCH];
        for us in us.chunks(BATCH) {
            let found = &mut found[..us.len()];
            self.distrib.sample_many(us, found);
            out.extend(found.iter().map(|&(p, pdf, cell)| {
                let fv = self.f[cell.y as usize * self.nx + cell.x as usize];
                let weight = if pdf > 0.0 { fv / pdf } else { 0.0 };
                FilterSample { p, weight }
            }));
        }
    }
}

/// The box filter.
#[derive(Clone, Copy, Debug)]
pub struct BoxFilter {
    radius: Vector2f,
}

impl BoxFilter {
    /// A box of half-widths `radius`.
    pub fn new(radius: Vector2f) -> Self {
        BoxFilter { radius }
    }
    /// Radius.
    pub fn radius(&self) -> Vector2f {
        self.radius
    }
    /// 1 inside the box, 0 outside.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        if p.x.abs() <= self.radius.x && p.y.abs() <= self.radius.y {
            1.0
        } else {
            0.0
        }
    }
    /// Uniform offset in the box, weight 1.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        FilterSample {
            p: Point2f::new(
                lerp(u.x, -self.radius.x, self.radius.x),
                lerp(u.y, -self.radius.y, self.radius.y),
            ),
            weight: 1.0,
        }
    }
    /// Area of the box.
    pub fn integral(&self) -> Float {
        2.0 * self.radius.x * 2.0 * self.radius.y
    }
}

/// The normal density with mean `mu` and deviation `sigma` at `x`.
#[inline]
pub fn gaussian(x: Float, mu: Float, sigma: Float) -> Float {
    1.0 / (2.0 * PI * sigma * sigma).sqrt() * (-sqr(x - mu) / (2.0 * sigma * sigma)).exp()
}

/// ∫ from `x0` to `x1` of [`gaussian`].
pub fn gaussian_integral(x0: Float, x1: Float, mu: Float, sigma: Float) -> Float {
    let s = sigma as f64 * std::f64::consts::SQRT_2;
    (0.5 * (erf((mu as f64 - x0 as f64) / s) - erf((mu as f64 - x1 as f64) / s))) as Float
}

/// The error function: Maclaurin series for |x| < 0.5, otherwise
/// 1 − erfc by its continued fraction (double precision; Rust's std has
/// no `erf`).
pub fn erf(x: f64) -> f64 {
    if x.abs() < 0.5 {
        // Maclaurin series converges fast here.
        let x2 = x * x;
        let mut term = x;
        let mut sum = x;
        for n in 1..20 {
            term *= -x2 / n as f64;
            sum += term / (2 * n + 1) as f64;
        }
        return sum * 2.0 / std::f64::consts::PI.sqrt();
    }
    // Complementary error function by continued fraction (Lentz) for
    // |x| ≥ 0.5, accurate to double precision.
    let ax = x.abs();
    let erfc = {
        let tiny = 1e-300;
        // erfc(x) = exp(-x²)/sqrt(pi) * 1/(x + 1/2/(x + 1/(x + 3/2/(x + ...))))
        let mut f = ax;
        if f == 0.0 {
            f = tiny;
        }
        let mut c = f;
        let mut d = 0.0;
        for i in 1..200 {
            let a = i as f64 / 2.0;
            d = ax + a * d;
            if d == 0.0 {
                d = tiny;
            }
            c = ax + a / c;
            if c == 0.0 {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = c * d;
            f *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-ax * ax).exp() / std::f64::consts::PI.sqrt() / f
    };
    (1.0 - erfc).copysign(x)
}

/// The Gaussian filter, shifted down so it reaches zero at the radius.
#[derive(Clone, Debug)]
pub struct GaussianFilter {
    radius: Vector2f,
    sigma: Float,
    exp_x: Float,
    exp_y: Float,
    sampler: FilterSampler,
}

impl GaussianFilter {
    /// A Gaussian of deviation `sigma` truncated at `radius`.
    pub fn new(radius: Vector2f, sigma: Float) -> Self {
        let exp_x = gaussian(radius.x, 0.0, sigma);
        let exp_y = gaussian(radius.y, 0.0, sigma);
        let eval = |p: Point2f| {
            (gaussian(p.x, 0.0, sigma) - exp_x).max(0.0)
                * (gaussian(p.y, 0.0, sigma) - exp_y).max(0.0)
        };
        let sampler = FilterSampler::new(radius, eval);
        GaussianFilter {
            radius,
            sigma,
            exp_x,
            exp_y,
            sampler,
        }
    }
    /// Radius.
    pub fn radius(&self) -> Vector2f {
        self.radius
    }
    /// Filter value.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        (gaussian(p.x, 0.0, self.sigma) - self.exp_x).max(0.0)
            * (gaussian(p.y, 0.0, self.sigma) - self.exp_y).max(0.0)
    }
    /// Tabulated sample.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        self.sampler.sample(u)
    }
    /// Closed-form integral.
    pub fn integral(&self) -> Float {
        (gaussian_integral(-self.radius.x, self.radius.x, 0.0, self.sigma)
            - 2.0 * self.radius.x * self.exp_x)
            * (gaussian_integral(-self.radius.y, self.radius.y, 0.0, self.sigma)
                - 2.0 * self.radius.y * self.exp_y)
    }
}

/// The Mitchell–Netravali cubic filter.
#[derive(Clone, Debug)]
pub struct MitchellFilter {
    radius: Vector2f,
    b: Float,
    c: Float,
    sampler: FilterSampler,
}

fn mitchell_1d(x: Float, b: Float, c: Float) -> Float {
    let x = x.abs();
    if x <= 1.0 {
        ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
            + (-18.0 + 12.0 * b + 6.0 * c) * x * x
            + (6.0 - 2.0 * b))
            * (1.0 / 6.0)
    } else if x <= 2.0 {
        ((-b - 6.0 * c) * x * x * x
            + (6.0 * b + 30.0 * c) * x * x
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c))
            * (1.0 / 6.0)
    } else {
        0.0
    }
}

impl MitchellFilter {
    /// A Mitchell filter with parameters `b`, `c`, stretched to `radius`.
    pub fn new(radius: Vector2f, b: Float, c: Float) -> Self {
        let sampler = FilterSampler::new(radius, |p| {
            mitchell_1d(2.0 * p.x / radius.x, b, c) * mitchell_1d(2.0 * p.y / radius.y, b, c)
        });
        MitchellFilter {
            radius,
            b,
            c,
            sampler,
        }
    }
    /// Radius.
    pub fn radius(&self) -> Vector2f {
        self.radius
    }
    /// Filter value.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        mitchell_1d(2.0 * p.x / self.radius.x, self.b, self.c)
            * mitchell_1d(2.0 * p.y / self.radius.y, self.b, self.c)
    }
    /// Tabulated sample.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        self.sampler.sample(u)
    }
    /// Closed-form integral (the 1-D cubic integrates to 1 over [−2, 2]
    /// for any B, C).
    pub fn integral(&self) -> Float {
        self.radius.x * self.radius.y / 4.0
    }
}

/// sinc(x) = sin(πx)/(πx).
#[inline]
pub fn sinc(x: Float) -> Float {
    sin_x_over_x(PI * x)
}

/// The sinc windowed by a Lanczos window of `tau` lobes, zero beyond
/// `radius`.
#[inline]
pub fn windowed_sinc(x: Float, radius: Float, tau: Float) -> Float {
    if x.abs() > radius {
        return 0.0;
    }
    sinc(x) * sinc(x / tau)
}

/// The Lanczos-windowed sinc filter.
#[derive(Clone, Debug)]
pub struct LanczosSincFilter {
    radius: Vector2f,
    tau: Float,
    sampler: FilterSampler,
}

impl LanczosSincFilter {
    /// A windowed sinc with `tau` lobes, truncated at `radius`.
    pub fn new(radius: Vector2f, tau: Float) -> Self {
        let sampler = FilterSampler::new(radius, |p| {
            windowed_sinc(p.x, radius.x, tau) * windowed_sinc(p.y, radius.y, tau)
        });
        LanczosSincFilter {
            radius,
            tau,
            sampler,
        }
    }
    /// Radius.
    pub fn radius(&self) -> Vector2f {
        self.radius
    }
    /// Filter value.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        windowed_sinc(p.x, self.radius.x, self.tau) * windowed_sinc(p.y, self.radius.y, self.tau)
    }
    /// Tabulated sample.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        self.sampler.sample(u)
    }
    /// The integral: the product of the two 1-D windowed-sinc integrals,
    /// each by a 4096-point midpoint rule (pbrt-v4 estimates it with 64×64
    /// stratified random samples, about 1% off for the defaults).
    pub fn integral(&self) -> Float {
        let int_1d = |r: Float| -> f64 {
            let n = 4096;
            let h = 2.0 * r as f64 / n as f64;
            (0..n)
                .map(|i| {
                    let x = -r as f64 + (i as f64 + 0.5) * h;
                    windowed_sinc(x as Float, r, self.tau) as f64
                })
                .sum::<f64>()
                * h
        };
        (int_1d(self.radius.x) * int_1d(self.radius.y)) as Float
    }
}

/// Samples the tent function of half-width `r` on [−r, r].
#[inline]
pub fn sample_tent(u: Float, r: Float) -> Float {
    if u < 0.5 {
        let u = (2.0 * u).min(ONE_MINUS_EPSILON);
        -r + r * sample_linear(u, 0.0, 1.0)
    } else {
        let u = ((u - 0.5) * 2.0).min(ONE_MINUS_EPSILON);
        r * sample_linear(u, 1.0, 0.0)
    }
}

/// The triangle (tent) filter.
#[derive(Clone, Copy, Debug)]
pub struct TriangleFilter {
    radius: Vector2f,
}

impl TriangleFilter {
    /// A tent of half-widths `radius`.
    pub fn new(radius: Vector2f) -> Self {
        TriangleFilter { radius }
    }
    /// Radius.
    pub fn radius(&self) -> Vector2f {
        self.radius
    }
    /// Filter value.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        (self.radius.x - p.x.abs()).max(0.0) * (self.radius.y - p.y.abs()).max(0.0)
    }
    /// Exact tent sample, weight 1.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        FilterSample {
            p: Point2f::new(
                sample_tent(u.x, self.radius.x),
                sample_tent(u.y, self.radius.y),
            ),
            weight: 1.0,
        }
    }
    /// Closed-form integral.
    pub fn integral(&self) -> Float {
        sqr(self.radius.x) * sqr(self.radius.y)
    }
}

/// A reconstruction filter: closed set of variants, one-line delegation.
#[derive(Clone, Debug)]
pub enum Filter {
    /// Box.
    Box(BoxFilter),
    /// Gaussian.
    Gaussian(GaussianFilter),
    /// Mitchell–Netravali.
    Mitchell(MitchellFilter),
    /// Lanczos-windowed sinc.
    LanczosSinc(LanczosSincFilter),
    /// Triangle.
    Triangle(TriangleFilter),
}

macro_rules! dispatch {
    ($self:expr, $f:ident => $e:expr) => {
        match $self {
            Filter::Box($f) => $e,
            Filter::Gaussian($f) => $e,
            Filter::Mitchell($f) => $e,
            Filter::LanczosSinc($f) => $e,
            Filter::Triangle($f) => $e,
        }
    };
}

impl Filter {
    /// The filter's value at offset `p` from the pixel centre.
    #[inline]
    pub fn evaluate(&self, p: Point2f) -> Float {
        dispatch!(self, f => f.evaluate(p))
    }
    /// Half-widths of the support.
    #[inline]
    pub fn radius(&self) -> Vector2f {
        dispatch!(self, f => f.radius())
    }
    /// ∫ f over the support.
    pub fn integral(&self) -> Float {
        dispatch!(self, f => f.integral())
    }
    /// An offset with density ∝ |f| and its weight f/pdf.
    #[inline]
    pub fn sample(&self, u: Point2f) -> FilterSample {
        dispatch!(self, f => f.sample(u))
    }
    /// [`sample`](Self::sample) of every value of `us`, appended to `out`:
    /// the same samples, the tabulated filters' searches interleaved.
    pub fn sample_many(&self, us: &[Point2f], out: &mut Vec<FilterSample>) {
        match self {
            Filter::Gaussian(f) => f.sampler.sample_many(us, out),
            Filter::Mitchell(f) => f.sampler.sample_many(us, out),
            Filter::LanczosSinc(f) => f.sampler.sample_many(us, out),
            _ => out.extend(us.iter().map(|&u| self.sample(u))),
        }
    }
}
