//! Light samplers (book section 12.6; pbrt-v4 `lightsamplers.h/.cpp`,
//! `base/lightsampler.h`): choosing one light to sample per lookup.
//!
//! [`LightSampler`] is a closed enum over the uniform, power and BVH
//! samplers. Lights are named by their index in the scene's light list.

use rpbrt_geometry::Float;
use rpbrt_parser::Diagnostic;

use crate::light::{Light, LightSampleContext};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

mod bvh;
#[cfg(test)]
mod tests;

pub use bvh::{BvhLightSampler, LightChoice};

/// The largest float below 1.
pub(crate) const ONE_MINUS_EPSILON: Float = 1.0 - Float::EPSILON / 2.0;

/// A light chosen by a sampler and the probability of choosing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledLight {
    /// Index of the light in the scene's light list.
    pub light: u32,
    /// Probability of the choice.
    pub p: Float,
}

/// Every light with the same probability (pbrt-v4 `UniformLightSampler`).
#[derive(Clone, Debug)]
pub struct UniformLightSampler {
    n: usize,
}

impl UniformLightSampler {
    /// A sampler over `n_lights` lights.
    pub fn new(n_lights: usize) -> Self {
        UniformLightSampler { n: n_lights }
    }
    /// Picks a light with `u` in [0, 1).
    pub fn sample_no_ctx(&self, u: Float) -> Option<SampledLight> {
        if self.n == 0 {
            return None;
        }
        let i = ((u * self.n as Float) as usize).min(self.n - 1);
        Some(SampledLight {
            light: i as u32,
            p: 1.0 / self.n as Float,
        })
    }
    /// The probability of any light.
    pub fn pmf_no_ctx(&self, light: u32) -> Float {
        if (light as usize) < self.n {
            1.0 / self.n as Float
        } else {
            0.0
        }
    }
}

/// Lights chosen in proportion to their emitted power (pbrt-v4
/// `PowerLightSampler`): `phi / pdf` at the wavelengths of visible sample
/// 0.5, averaged; all-zero powers fall back to uniform.
#[derive(Clone, Debug)]
pub struct PowerLightSampler {
    pmf: Vec<Float>,
    cdf: Vec<Float>,
}

impl PowerLightSampler {
    /// Builds the distribution for `lights`.
    pub fn new(lights: &[Light]) -> Self {
        let lambda = SampledWavelengths::sample_visible(0.5);
        let mut power: Vec<f64> = lights
            .iter()
            .map(|l| {
                let phi = SampledSpectrum::safe_div(l.phi(&lambda), lambda.pdf());
                (phi.average() as f64).max(0.0)
            })
            .collect();
        let total: f64 = power.iter().sum();
        if total.is_nan() || total <= 0.0 || !total.is_finite() {
            power.iter_mut().for_each(|p| *p = 1.0);
        }
        let total: f64 = power.iter().sum();
        let pmf: Vec<Float> = power.iter().map(|&p| (p / total) as Float).collect();
        let mut cdf = Vec::with_capacity(power.len());
        let mut acc = 0.0f64;
        for &p in &power {
            acc += p / total;
            cdf.push(acc as Float);
        }
        PowerLightSampler { pmf, cdf }
    }
    /// Picks a light with `u` in [0, 1).
    pub fn sample_no_ctx(&self, u: Float) -> Option<SampledLight> {
        if self.pmf.is_empty() {
            return None;
        }
        // First light whose cumulative probability exceeds u, skipping
        // zero-probability lights.
        let mut i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.pmf.len() - 1);
        while self.pmf[i] == 0.0 && i > 0 {
            i -= 1;
        }
        Some(SampledLight {
            light: i as u32,
            p: self.pmf[i],
        })
    }
    /// The probability of choosing `light`.
    pub fn pmf_no_ctx(&self, light: u32) -> Float {
        self.pmf.get(light as usize).copied().unwrap_or(0.0)
    }
}

/// A strategy for choosing which light to sample (pbrt-v4 `LightSampler`).
#[derive(Clone, Debug)]
pub enum LightSampler {
    /// Uniform over lights.
    Uniform(UniformLightSampler),
    /// By emitted power.
    Power(PowerLightSampler),
    /// By importance from a BVH over the lights' bounds.
    Bvh(BvhLightSampler),
}

/// The names [`create_light_sampler`] accepts.
pub const LIGHT_SAMPLER_NAMES: &[&str] = &["uniform", "power", "bvh"];

/// Creates the light sampler called `name` for `lights`.
pub fn create_light_sampler(name: &str, lights: &[Light]) -> Result<LightSampler, Diagnostic> {
    match name {
        "uniform" => Ok(LightSampler::Uniform(UniformLightSampler::new(
            lights.len(),
        ))),
        "power" => Ok(LightSampler::Power(PowerLightSampler::new(lights))),
        "bvh" => Ok(LightSampler::Bvh(BvhLightSampler::new(lights))),
        _ => Err(Diagnostic::unlocated_error(format!(
            "\"{name}\": light sampler unknown (known: {})",
            LIGHT_SAMPLER_NAMES.join(", ")
        ))),
    }
}

impl LightSampler {
    /// Chooses a light for shading at `ctx` with `u` in [0, 1).
    #[inline]
    pub fn sample(&self, ctx: &LightSampleContext, u: Float) -> Option<SampledLight> {
        match self {
            LightSampler::Uniform(s) => s.sample_no_ctx(u),
            LightSampler::Power(s) => s.sample_no_ctx(u),
            LightSampler::Bvh(s) => s.sample(ctx, u),
        }
    }
    /// The probability that [`sample`](Self::sample) chooses `light` at `ctx`.
    #[inline]
    pub fn pmf(&self, ctx: &LightSampleContext, light: u32) -> Float {
        match self {
            LightSampler::Uniform(s) => s.pmf_no_ctx(light),
            LightSampler::Power(s) => s.pmf_no_ctx(light),
            LightSampler::Bvh(s) => s.pmf(ctx, light),
        }
    }
    /// Chooses a light without a reference point.
    #[inline]
    pub fn sample_no_ctx(&self, u: Float) -> Option<SampledLight> {
        match self {
            LightSampler::Uniform(s) => s.sample_no_ctx(u),
            LightSampler::Power(s) => s.sample_no_ctx(u),
            LightSampler::Bvh(s) => s.sample_no_ctx(u),
        }
    }
    /// The probability that [`sample_no_ctx`](Self::sample_no_ctx) chooses
    /// `light`.
    #[inline]
    pub fn pmf_no_ctx(&self, light: u32) -> Float {
        match self {
            LightSampler::Uniform(s) => s.pmf_no_ctx(light),
            LightSampler::Power(s) => s.pmf_no_ctx(light),
            LightSampler::Bvh(s) => s.pmf_no_ctx(light),
        }
    }
}
