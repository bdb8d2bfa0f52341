//! Point-sampled spectra and the wavelengths they are sampled at (pbrt-v4
//! book section 4.5.4, `SampledSpectrum` and `SampledWavelengths`).

use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

use rpbrt_geometry::Float;

use super::{LAMBDA_MAX, LAMBDA_MIN, N_SPECTRUM_SAMPLES};
use crate::simd::math::ln;
use crate::simd::{dispatch, F32Lanes, Kernel, Scalar1, SimdLevel};

/// A spectral distribution point-sampled at the `N_SPECTRUM_SAMPLES`
/// wavelengths of a [`SampledWavelengths`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampledSpectrum {
    /// The value at each sampled wavelength.
    pub values: [Float; N_SPECTRUM_SAMPLES],
}

impl SampledSpectrum {
    /// A spectrum with the value `c` at every wavelength.
    #[inline]
    pub const fn new(c: Float) -> Self {
        SampledSpectrum {
            values: [c; N_SPECTRUM_SAMPLES],
        }
    }

    /// A spectrum with the given per-wavelength values.
    #[inline]
    pub const fn from_array(values: [Float; N_SPECTRUM_SAMPLES]) -> Self {
        SampledSpectrum { values }
    }

    /// True when every value is zero.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.values.iter().all(|&v| v == 0.0)
    }

    /// True when any value is NaN.
    #[inline]
    pub fn has_nan(&self) -> bool {
        self.values.iter().any(|v| v.is_nan())
    }

    /// The largest value.
    #[inline]
    pub fn max_component_value(&self) -> Float {
        self.values.iter().copied().fold(self.values[0], Float::max)
    }

    /// The smallest value.
    #[inline]
    pub fn min_component_value(&self) -> Float {
        self.values.iter().copied().fold(self.values[0], Float::min)
    }

    /// The mean of the values.
    #[inline]
    pub fn average(&self) -> Float {
        self.values.iter().sum::<Float>() / N_SPECTRUM_SAMPLES as Float
    }

    /// Applies `f` to every value.
    #[inline]
    pub fn map(self, f: impl Fn(Float) -> Float) -> Self {
        SampledSpectrum {
            values: self.values.map(f),
        }
    }

    /// Component-wise `a / b`, with zero where `b` is zero.
    #[inline]
    pub fn safe_div(a: SampledSpectrum, b: SampledSpectrum) -> SampledSpectrum {
        let mut r = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            r.values[i] = if b.values[i] != 0.0 {
                a.values[i] / b.values[i]
            } else {
                0.0
            };
        }
        r
    }

    /// Component-wise square root.
    #[inline]
    pub fn sqrt(self) -> Self {
        self.map(Float::sqrt)
    }

    /// Component-wise exponential.
    #[inline]
    pub fn exp(self) -> Self {
        self.map(Float::exp)
    }

    /// Component-wise power.
    #[inline]
    pub fn powf(self, e: Float) -> Self {
        self.map(|v| v.powf(e))
    }

    /// Negative values replaced by zero.
    #[inline]
    pub fn clamp_zero(self) -> Self {
        self.map(|v| v.max(0.0))
    }

    /// Values clamped to `[lo, hi]`.
    #[inline]
    pub fn clamp(self, lo: Float, hi: Float) -> Self {
        self.map(|v| v.clamp(lo, hi))
    }

    /// Linear interpolation `(1 - t) a + t b`.
    #[inline]
    pub fn lerp(t: Float, a: SampledSpectrum, b: SampledSpectrum) -> SampledSpectrum {
        a * (1.0 - t) + b * t
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = Float;
    #[inline]
    fn index(&self, i: usize) -> &Float {
        &self.values[i]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut Float {
        &mut self.values[i]
    }
}

impl Neg for SampledSpectrum {
    type Output = SampledSpectrum;
    #[inline]
    fn neg(self) -> Self {
        self.map(|v| -v)
    }
}

macro_rules! spectrum_binop {
    ($tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt) => {
        impl $tr for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $f(mut self, o: SampledSpectrum) -> SampledSpectrum {
                for i in 0..N_SPECTRUM_SAMPLES {
                    self.values[i] = self.values[i] $op o.values[i];
                }
                self
            }
        }
        impl $tr<Float> for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $f(mut self, s: Float) -> SampledSpectrum {
                for v in &mut self.values {
                    *v = *v $op s;
                }
                self
            }
        }
        impl $atr for SampledSpectrum {
            #[inline]
            fn $af(&mut self, o: SampledSpectrum) {
                *self = *self $op o;
            }
        }
        impl $atr<Float> for SampledSpectrum {
            #[inline]
            fn $af(&mut self, s: Float) {
                *self = *self $op s;
            }
        }
    };
}

spectrum_binop!(Add, add, AddAssign, add_assign, +);
spectrum_binop!(Sub, sub, SubAssign, sub_assign, -);
spectrum_binop!(Mul, mul, MulAssign, mul_assign, *);
spectrum_binop!(Div, div, DivAssign, div_assign, /);

impl Mul<SampledSpectrum> for Float {
    type Output = SampledSpectrum;
    #[inline]
    fn mul(self, s: SampledSpectrum) -> SampledSpectrum {
        s * self
    }
}

impl Add<SampledSpectrum> for Float {
    type Output = SampledSpectrum;
    #[inline]
    fn add(self, s: SampledSpectrum) -> SampledSpectrum {
        s + self
    }
}

impl Sub<SampledSpectrum> for Float {
    type Output = SampledSpectrum;
    #[inline]
    fn sub(self, s: SampledSpectrum) -> SampledSpectrum {
        SampledSpectrum::new(self) - s
    }
}

impl Div<SampledSpectrum> for Float {
    type Output = SampledSpectrum;
    #[inline]
    fn div(self, s: SampledSpectrum) -> SampledSpectrum {
        SampledSpectrum::new(self) / s
    }
}

/// The wavelengths (in nm) a path carries, with the probability density each
/// was sampled with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    /// The wavelengths, in nm.
    pub lambda: [Float; N_SPECTRUM_SAMPLES],
    /// The density each wavelength was sampled with; zero once terminated.
    pub pdf: [Float; N_SPECTRUM_SAMPLES],
}

impl SampledWavelengths {
    /// Wavelengths spread evenly over `[lambda_min, lambda_max]`: the first
    /// at `u`, the others at equal steps after it, wrapping around (pbrt-v4
    /// `SampleUniform`).
    pub fn sample_uniform(u: Float, lambda_min: Float, lambda_max: Float) -> Self {
        let mut lambda = [0.0; N_SPECTRUM_SAMPLES];
        lambda[0] = (1.0 - u) * lambda_min + u * lambda_max;
        let delta = (lambda_max - lambda_min) / N_SPECTRUM_SAMPLES as Float;
        for i in 1..N_SPECTRUM_SAMPLES {
            lambda[i] = lambda[i - 1] + delta;
            if lambda[i] > lambda_max {
                lambda[i] = lambda_min + (lambda[i] - lambda_max);
            }
        }
        SampledWavelengths {
            lambda,
            pdf: [1.0 / (lambda_max - lambda_min); N_SPECTRUM_SAMPLES],
        }
    }

    /// Wavelengths uniformly over the full range `[LAMBDA_MIN, LAMBDA_MAX]`.
    pub fn sample_uniform_full(u: Float) -> Self {
        Self::sample_uniform(u, LAMBDA_MIN, LAMBDA_MAX)
    }

    /// Wavelengths importance-sampled over the visible range, stratified:
    /// the `i`th uses `u + i / N` wrapped to `[0, 1)` (pbrt-v4 `SampleVisible`).
    pub fn sample_visible(u: Float) -> Self {
        let mut lambda = [0.0; N_SPECTRUM_SAMPLES];
        let mut pdf = [0.0; N_SPECTRUM_SAMPLES];
        for (i, (l, p)) in lambda.iter_mut().zip(&mut pdf).enumerate() {
            let (vl, vp) = visible_lanes(Scalar1(stratum(u, i)));
            (*l, *p) = (vl.0, vp.0);
        }
        SampledWavelengths { lambda, pdf }
    }

    /// [`SampledWavelengths::sample_visible`] of each of `us`, into `out`
    /// (cleared first): the same values, computed lane-parallel at
    /// `level`. `scratch` holds the draws and values between calls.
    pub fn sample_visible_many(
        level: SimdLevel,
        us: &[Float],
        scratch: &mut Vec<Float>,
        out: &mut Vec<Self>,
    ) {
        const N: usize = N_SPECTRUM_SAMPLES;
        let n = N * us.len();
        scratch.clear();
        scratch.extend(us.iter().flat_map(|&u| (0..N).map(move |i| stratum(u, i))));
        scratch.resize(3 * n, 0.0);
        let (strata, values) = scratch.split_at_mut(n);
        let (lambda, pdf) = values.split_at_mut(n);
        dispatch(
            level,
            VisibleBatch {
                us: strata,
                lambda,
                pdf,
            },
        );
        out.clear();
        out.extend(
            lambda
                .chunks_exact(N)
                .zip(pdf.chunks_exact(N))
                .map(|(l, p)| SampledWavelengths {
                    lambda: std::array::from_fn(|i| l[i]),
                    pdf: std::array::from_fn(|i| p[i]),
                }),
        );
    }

    /// The sampling densities as a spectrum.
    #[inline]
    pub fn pdf(&self) -> SampledSpectrum {
        SampledSpectrum::from_array(self.pdf)
    }

    /// The `i`th wavelength.
    #[inline]
    pub fn get(&self, i: usize) -> Float {
        self.lambda[i]
    }

    /// Keeps only the first wavelength (after wavelength-dependent
    /// refraction, say): the others get a zero density, and the first's
    /// density is divided by the count so estimates stay unbiased.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        self.pdf[0] /= N_SPECTRUM_SAMPLES as Float;
    }

    /// True once [`terminate_secondary`](Self::terminate_secondary) ran.
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

impl Index<usize> for SampledWavelengths {
    type Output = Float;
    #[inline]
    fn index(&self, i: usize) -> &Float {
        &self.lambda[i]
    }
}

/// Maps `u` in `[0, 1)` to a wavelength in `[360, 830]` nm with density
/// [`visible_wavelengths_pdf`], a fit concentrating samples where the eye is
/// sensitive (pbrt-v4 `SampleVisibleWavelengths`).
#[inline]
pub fn sample_visible_wavelengths(u: Float) -> Float {
    visible_lanes(Scalar1(u)).0 .0
}

/// The `i`th of [`SampledWavelengths::sample_visible`]'s stratified
/// draws: `u + i / N`, wrapped to `[0, 1)`.
#[inline(always)]
fn stratum(u: Float, i: usize) -> Float {
    let up = u + i as Float / N_SPECTRUM_SAMPLES as Float;
    if up > 1.0 {
        up - 1.0
    } else {
        up
    }
}

/// [`sample_visible_wavelengths`] of each lane and its density. With
/// y = 0.8569106 − 1.827502·u, λ = 538 − 138.888889·atanh(y) and the
/// density 0.0039398042 / cosh²(0.0072·(λ − 538)); as 0.0072 · 138.888889
/// = 1, that is 0.0039398042 · (1 − y²), with no cosh to evaluate. atanh
/// is ½ ln((1 + y) / (1 − y)) (one logarithm; the wavelengths need no
/// more than f32 accuracy around y = 0), by the lanes' [`ln`], so that
/// the scalar and lane-parallel forms agree bit for bit.
#[inline(always)]
fn visible_lanes<L: F32Lanes>(u: L) -> (L, L) {
    let one = L::splat(1.0);
    let y = L::splat(0.856_910_6).sub(L::splat(1.827_502).mul(u));
    let atanh = L::splat(0.5).mul(ln(one.add(y).div(one.sub(y))));
    let lambda = L::splat(538.0).sub(L::splat(138.888_89).mul(atanh));
    let inside = L::and(lambda.ge(L::splat(360.0)), lambda.le(L::splat(830.0)));
    let pdf = L::splat(0.003_939_804_2).mul(one.sub(y.mul(y)));
    (lambda, L::select(inside, pdf, L::splat(0.0)))
}

/// [`SampledWavelengths::sample_visible_many`]'s kernel: `lambda` and
/// `pdf` (as long as `us`) of each draw in `us`.
struct VisibleBatch<'a> {
    us: &'a [Float],
    lambda: &'a mut [Float],
    pdf: &'a mut [Float],
}

impl Kernel for VisibleBatch<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let n = self.us.len().min(self.lambda.len()).min(self.pdf.len());
        let mut i = 0;
        while i + L::N <= n {
            let (l, p) = visible_lanes(L::load(&self.us[i..]));
            l.store(&mut self.lambda[i..]);
            p.store(&mut self.pdf[i..]);
            i += L::N;
        }
        for j in i..n {
            let (l, p) = visible_lanes(Scalar1(self.us[j]));
            (self.lambda[j], self.pdf[j]) = (l.0, p.0);
        }
    }
}

/// The density of [`sample_visible_wavelengths`]; zero outside `[360, 830]`.
#[inline]
pub fn visible_wavelengths_pdf(lambda: Float) -> Float {
    if !(360.0..=830.0).contains(&lambda) {
        return 0.0;
    }
    let c = (0.0072 * (lambda - 538.0)).cosh();
    0.003_939_804_2 / (c * c)
}
