//! Spectral distributions (pbrt-v4 book section 4.5.1, `Spectrum` and its
//! implementations in `util/spectrum.h`).

use std::sync::Arc;

use rpbrt_geometry::Float;

use super::color::{RgbSigmoidPolynomial, RGB};
use super::colorspace::RgbColorSpace;
use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::{cie, LAMBDA_MAX, LAMBDA_MIN, N_SPECTRUM_SAMPLES};

/// A spectral distribution: a value for every wavelength. Cheap to clone
/// (tabulated data sits behind an `Arc`).
#[derive(Clone, Debug)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(Float),
    /// Values tabulated at 1 nm steps.
    DenselySampled(Arc<DenselySampledSpectrum>),
    /// Linear interpolation between samples; zero outside them.
    PiecewiseLinear(Arc<PiecewiseLinearSpectrum>),
    /// Planck's law, scaled so its peak is 1.
    Blackbody(BlackbodySpectrum),
    /// A reflectance from an RGB colour with components in `[0, 1]`.
    RgbAlbedo(RgbAlbedoSpectrum),
    /// A positive spectrum from an RGB colour of any magnitude.
    RgbUnbounded(RgbUnboundedSpectrum),
    /// An emission spectrum: an RGB colour times its colour space's
    /// illuminant.
    RgbIlluminant(RgbIlluminantSpectrum),
}

impl Spectrum {
    /// The value at wavelength `lambda` (nm).
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::DenselySampled(s) => s.evaluate(lambda),
            Spectrum::PiecewiseLinear(s) => s.evaluate(lambda),
            Spectrum::Blackbody(s) => s.evaluate(lambda),
            Spectrum::RgbAlbedo(s) => s.evaluate(lambda),
            Spectrum::RgbUnbounded(s) => s.evaluate(lambda),
            Spectrum::RgbIlluminant(s) => s.evaluate(lambda),
        }
    }

    /// The values at the wavelengths `lambda`.
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Spectrum::Constant(c) => SampledSpectrum::new(*c),
            Spectrum::DenselySampled(s) => s.sample(lambda),
            Spectrum::PiecewiseLinear(s) => sample_with(lambda, |l| s.evaluate(l)),
            Spectrum::Blackbody(s) => sample_with(lambda, |l| s.evaluate(l)),
            Spectrum::RgbAlbedo(s) => SampledSpectrum::from_array(s.rsp.evaluate_n(&lambda.lambda)),
            Spectrum::RgbUnbounded(s) => {
                SampledSpectrum::from_array(s.rsp.evaluate_n(&lambda.lambda)) * s.scale
            }
            Spectrum::RgbIlluminant(s) => s.sample(lambda),
        }
    }

    /// An upper bound on the value over all wavelengths.
    pub fn max_value(&self) -> Float {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::DenselySampled(s) => s.max_value(),
            Spectrum::PiecewiseLinear(s) => s.max_value(),
            Spectrum::Blackbody(_) => 1.0,
            Spectrum::RgbAlbedo(s) => s.rsp.max_value(),
            Spectrum::RgbUnbounded(s) => s.max_value(),
            Spectrum::RgbIlluminant(s) => s.max_value(),
        }
    }

    /// A constant spectrum.
    #[inline]
    pub fn constant(c: Float) -> Spectrum {
        Spectrum::Constant(c)
    }

    /// A normalised blackbody emitter at temperature `t` Kelvin.
    pub fn blackbody(t: Float) -> Spectrum {
        Spectrum::Blackbody(BlackbodySpectrum::new(t))
    }
}

#[inline]
fn sample_with(lambda: &SampledWavelengths, f: impl Fn(Float) -> Float) -> SampledSpectrum {
    SampledSpectrum::from_array(lambda.lambda.map(f))
}

/// A spectrum tabulated at every integer wavelength of
/// `[lambda_min, lambda_max]`; zero outside. Evaluation rounds to the
/// nearest nm, as pbrt-v4 does.
#[derive(Clone, Debug, PartialEq)]
pub struct DenselySampledSpectrum {
    lambda_min: i32,
    values: Vec<Float>,
}

impl DenselySampledSpectrum {
    /// Tabulates `s` over `[LAMBDA_MIN, LAMBDA_MAX]`.
    pub fn new(s: &Spectrum) -> Self {
        Self::from_fn(LAMBDA_MIN as i32, LAMBDA_MAX as i32, |l| s.evaluate(l))
    }

    /// Tabulates `f` at every integer wavelength of `[lambda_min, lambda_max]`.
    pub fn from_fn(lambda_min: i32, lambda_max: i32, f: impl Fn(Float) -> Float) -> Self {
        let values = (lambda_min..=lambda_max).map(|l| f(l as Float)).collect();
        DenselySampledSpectrum { lambda_min, values }
    }

    /// Wraps values tabulated from `lambda_min` at 1 nm steps.
    pub fn from_values(lambda_min: i32, values: Vec<Float>) -> Self {
        DenselySampledSpectrum { lambda_min, values }
    }

    /// The wavelength (nm) of the first tabulated value.
    pub fn lambda_min(&self) -> i32 {
        self.lambda_min
    }

    /// The tabulated values.
    pub fn values(&self) -> &[Float] {
        &self.values
    }

    /// The value at `lambda` (nm), zero outside the table.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        let offset = super::round_nm(lambda) - self.lambda_min as i64;
        if offset < 0 || offset as usize >= self.values.len() {
            return 0.0;
        }
        self.values[offset as usize]
    }

    /// The values at the sampled wavelengths.
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let mut s = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            s[i] = self.evaluate(lambda[i]);
        }
        s
    }

    /// The largest tabulated value.
    pub fn max_value(&self) -> Float {
        self.values.iter().copied().fold(Float::MIN, Float::max)
    }

    /// Multiplies every value by `s`.
    pub fn scale(&mut self, s: Float) {
        for v in &mut self.values {
            *v *= s;
        }
    }
}

/// Linear interpolation between `(lambda, value)` samples with increasing
/// wavelengths; zero outside the first and last sample.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinearSpectrum {
    lambdas: Vec<Float>,
    values: Vec<Float>,
    /// Where [`PiecewiseLinearSpectrum::evaluate`]'s search starts: entry
    /// `k` counts the wavelengths at or below `index_base + k` nm, for
    /// every whole nanometre from the first wavelength's floor to the
    /// last's (empty when that span exceeds [`INDEX_MAX_NM`]).
    index: Vec<u32>,
    index_base: Float,
}

/// The widest span of wavelengths (nm) [`PiecewiseLinearSpectrum`] keeps a
/// lookup table for (4 bytes a nanometre); wider ones are searched by
/// bisection.
const INDEX_MAX_NM: Float = 4096.0;

impl PiecewiseLinearSpectrum {
    /// A spectrum from matching wavelength and value lists; the wavelengths
    /// must strictly increase.
    pub fn new(lambdas: Vec<Float>, values: Vec<Float>) -> Result<Self, String> {
        if lambdas.len() != values.len() {
            return Err(format!(
                "{} wavelengths but {} values",
                lambdas.len(),
                values.len()
            ));
        }
        if lambdas.is_empty() {
            return Err("spectrum has no samples".into());
        }
        for (i, w) in lambdas.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(format!(
                    "at entry {}, wavelengths aren't increasing: {} >= {}",
                    i + 1,
                    w[0],
                    w[1]
                ));
            }
        }
        let (first, last) = (lambdas[0], lambdas[lambdas.len() - 1]);
        let index_base = first.floor();
        let index = if last - index_base <= INDEX_MAX_NM {
            // One pass over both: the counts only grow.
            let nm = (last.floor() - index_base) as usize + 1;
            let mut j = 0;
            (0..nm)
                .map(|k| {
                    let at = index_base + k as Float;
                    while j < lambdas.len() && lambdas[j] <= at {
                        j += 1;
                    }
                    j as u32
                })
                .collect()
        } else {
            Vec::new()
        };
        Ok(PiecewiseLinearSpectrum {
            lambdas,
            values,
            index,
            index_base,
        })
    }

    /// A spectrum from interleaved `lambda, value` pairs, extended with
    /// constant end values to cover `[LAMBDA_MIN, LAMBDA_MAX]`; when
    /// `normalize` is set, scaled so its luminance is 1 (that is
    /// `inner_product(Y, s) = CIE_Y_INTEGRAL`), as pbrt-v4 does for its named
    /// illuminants.
    pub fn from_interleaved(samples: &[Float], normalize: bool) -> Result<Self, String> {
        if samples.len() < 2 || samples.len() % 2 != 0 {
            return Err(format!(
                "expected an even, nonzero number of values, got {}",
                samples.len()
            ));
        }
        let mut lambdas = Vec::with_capacity(samples.len() / 2 + 2);
        let mut values = Vec::with_capacity(samples.len() / 2 + 2);
        if samples[0] > LAMBDA_MIN {
            lambdas.push(LAMBDA_MIN - 1.0);
            values.push(samples[1]);
        }
        for pair in samples.chunks_exact(2) {
            lambdas.push(pair[0]);
            values.push(pair[1]);
        }
        if let (Some(&last_l), Some(&last_v)) = (lambdas.last(), values.last()) {
            if last_l < LAMBDA_MAX {
                lambdas.push(LAMBDA_MAX + 1.0);
                values.push(last_v);
            }
        }
        let mut spec = Self::new(lambdas, values)?;
        if normalize {
            let y = inner_product(cie::y(), &Spectrum::PiecewiseLinear(Arc::new(spec.clone())));
            if y > 0.0 {
                spec.scale(cie::CIE_Y_INTEGRAL / y);
            }
        }
        Ok(spec)
    }

    /// The sample wavelengths.
    pub fn lambdas(&self) -> &[Float] {
        &self.lambdas
    }

    /// The sample values.
    pub fn values(&self) -> &[Float] {
        &self.values
    }

    /// Multiplies every value by `s`.
    pub fn scale(&mut self, s: Float) {
        for v in &mut self.values {
            *v *= s;
        }
    }

    /// The interpolated value at `lambda` (nm).
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        let (Some(&first), Some(&last)) = (self.lambdas.first(), self.lambdas.last()) else {
            return 0.0;
        };
        if !(lambda >= first && lambda <= last) {
            return 0.0;
        }
        // The last sample at or below lambda, kept one short of the end.
        let i = self
            .samples_at_or_below(lambda)
            .saturating_sub(1)
            .min(self.lambdas.len().saturating_sub(2));
        if self.lambdas.len() == 1 {
            return self.values[0];
        }
        let t = (lambda - self.lambdas[i]) / (self.lambdas[i + 1] - self.lambdas[i]);
        (1.0 - t) * self.values[i] + t * self.values[i + 1]
    }

    /// The largest sample value.
    pub fn max_value(&self) -> Float {
        self.values.iter().copied().fold(0.0, Float::max)
    }

    /// How many sample wavelengths are at or below `lambda` (which lies
    /// within them): `partition_point`'s answer, found from the lookup
    /// table's entry for `lambda`'s nanometre and a step or two, not by
    /// bisection (conductors evaluate two such spectra at four
    /// wavelengths every vertex).
    #[inline]
    fn samples_at_or_below(&self, lambda: Float) -> usize {
        let ls = &self.lambdas;
        if self.index.is_empty() {
            return ls.partition_point(|&l| l <= lambda);
        }
        // `lambda − index_base` may round up to the next whole number;
        // the steps below correct the count either way.
        let k = ((lambda - self.index_base) as usize).min(self.index.len() - 1);
        let mut j = self.index[k] as usize;
        while j > 0 && ls[j - 1] > lambda {
            j -= 1;
        }
        while j < ls.len() && ls[j] <= lambda {
            j += 1;
        }
        j
    }
}

/// Planck's law: the spectral radiance emitted at `lambda` nm by a
/// blackbody at `t` Kelvin, in W/(m² sr m); zero for `t <= 0`.
pub fn blackbody(lambda: Float, t: Float) -> Float {
    if t <= 0.0 {
        return 0.0;
    }
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_069_57e-34;
    const KB: f64 = 1.380_648_8e-23;
    let l = lambda as f64 * 1e-9;
    let le = (2.0 * H * C * C) / (l.powi(5) * (((H * C) / (l * KB * t as f64)).exp() - 1.0));
    le as Float
}

/// A blackbody emitter normalised so the peak of its spectrum (at the
/// wavelength given by Wien's displacement law) is 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlackbodySpectrum {
    /// Temperature in Kelvin.
    pub t: Float,
    /// One over the spectral radiance at the peak.
    pub normalization: Float,
}

impl BlackbodySpectrum {
    /// The normalised spectrum at temperature `t` Kelvin.
    pub fn new(t: Float) -> Self {
        let lambda_max = 2.897_772_1e-3 / t;
        BlackbodySpectrum {
            t,
            normalization: 1.0 / blackbody(lambda_max * 1e9, t),
        }
    }

    /// The normalised value at `lambda` nm.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        blackbody(lambda, self.t) * self.normalization
    }
}

/// A reflectance spectrum for an RGB colour with components in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbAlbedoSpectrum {
    /// The sigmoid polynomial from the colour space's table.
    pub rsp: RgbSigmoidPolynomial,
}

impl RgbAlbedoSpectrum {
    /// The spectrum for `rgb` in `cs`; components are clamped to `[0, 1]`.
    pub fn new(cs: &RgbColorSpace, rgb: RGB) -> Self {
        debug_assert!(rgb.max_component_value() <= 1.0 && rgb.min_component_value() >= 0.0);
        RgbAlbedoSpectrum {
            rsp: cs.rgb_to_spectrum_coeffs(rgb),
        }
    }

    /// The value at `lambda` nm.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        self.rsp.evaluate(lambda)
    }
}

/// A positive spectrum for an RGB colour of any magnitude: the colour
/// divided by twice its largest component, scaled back up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbUnboundedSpectrum {
    /// Twice the largest component.
    pub scale: Float,
    /// The sigmoid polynomial of the scaled-down colour.
    pub rsp: RgbSigmoidPolynomial,
}

impl RgbUnboundedSpectrum {
    /// The spectrum for non-negative `rgb` in `cs`.
    pub fn new(cs: &RgbColorSpace, rgb: RGB) -> Self {
        let (scale, rsp) = scaled_coeffs(cs, rgb);
        RgbUnboundedSpectrum { scale, rsp }
    }

    /// The value at `lambda` nm.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        self.scale * self.rsp.evaluate(lambda)
    }

    /// The values at the sampled wavelengths.
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let mut s = SampledSpectrum::new(0.0);
        for (i, v) in s.values.iter_mut().enumerate() {
            *v = self.evaluate(lambda.get(i));
        }
        s
    }

    /// The largest value.
    pub fn max_value(&self) -> Float {
        self.scale * self.rsp.max_value()
    }
}

fn scaled_coeffs(cs: &RgbColorSpace, rgb: RGB) -> (Float, RgbSigmoidPolynomial) {
    let m = rgb.max_component_value();
    let scale = 2.0 * m;
    let rsp = if scale > 0.0 {
        cs.rgb_to_spectrum_coeffs(rgb / scale)
    } else {
        cs.rgb_to_spectrum_coeffs(RGB::new(0.0, 0.0, 0.0))
    };
    (scale, rsp)
}

/// An emission spectrum: an unbounded RGB spectrum times the colour space's
/// standard illuminant, so `rgb = (1, 1, 1)` emits the illuminant itself.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbIlluminantSpectrum {
    /// Twice the largest component.
    pub scale: Float,
    /// The sigmoid polynomial of the scaled-down colour.
    pub rsp: RgbSigmoidPolynomial,
    /// The colour space's illuminant.
    pub illuminant: Arc<DenselySampledSpectrum>,
}

impl RgbIlluminantSpectrum {
    /// The spectrum for non-negative `rgb` in `cs`.
    pub fn new(cs: &RgbColorSpace, rgb: RGB) -> Self {
        let (scale, rsp) = scaled_coeffs(cs, rgb);
        RgbIlluminantSpectrum {
            scale,
            rsp,
            illuminant: cs.illuminant.clone(),
        }
    }

    /// The value at `lambda` nm.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        self.scale * self.rsp.evaluate(lambda) * self.illuminant.evaluate(lambda)
    }

    /// The values at the sampled wavelengths.
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let mut s = self.illuminant.sample(lambda);
        let r = self.rsp.evaluate_n(&lambda.lambda);
        for i in 0..N_SPECTRUM_SAMPLES {
            s[i] *= self.scale * r[i];
        }
        s
    }

    /// An upper bound on the value.
    pub fn max_value(&self) -> Float {
        self.scale * self.rsp.max_value() * self.illuminant.max_value()
    }

    /// The illuminant alone, as a spectrum.
    pub fn illuminant(&self) -> Spectrum {
        Spectrum::DenselySampled(self.illuminant.clone())
    }
}

/// `Σ f(λ) g(λ)` over the integer wavelengths of `[LAMBDA_MIN, LAMBDA_MAX]`.
pub fn inner_product(f: &Spectrum, g: &Spectrum) -> Float {
    let mut sum = 0.0f64;
    let mut lambda = LAMBDA_MIN;
    while lambda <= LAMBDA_MAX {
        sum += f.evaluate(lambda) as f64 * g.evaluate(lambda) as f64;
        lambda += 1.0;
    }
    sum as Float
}

/// The luminance-like quantity pbrt-v4 uses to normalise light power:
/// `inner_product(Y, s)`, with an RGB illuminant reduced to its illuminant
/// (its RGB scale is accounted for by the light itself).
pub fn spectrum_to_photometric(s: &Spectrum) -> Float {
    match s {
        Spectrum::RgbIlluminant(s) => inner_product(cie::y(), &s.illuminant()),
        _ => inner_product(cie::y(), s),
    }
}

/// The XYZ tristimulus value of `s`, normalised so a constant-1 spectrum has
/// `Y = 1`.
pub fn spectrum_to_xyz(s: &Spectrum) -> super::XYZ {
    super::XYZ::new(
        inner_product(cie::x(), s),
        inner_product(cie::y(), s),
        inner_product(cie::z(), s),
    ) / cie::CIE_Y_INTEGRAL
}
