//! Hair (pbrt-v4 book section 9.9; pbrt-v4 `HairMaterial`).

use rpbrt_geometry::float::*;

use crate::bxdf::{BxDF, HairBxDF};
use crate::spectrum::{
    RgbColorSpace, RgbUnboundedSpectrum, SampledSpectrum, SampledWavelengths, Spectrum,
};
use crate::texture::{FloatTextureRef, SpectrumTextureRef};

use super::MaterialEvalContext;

/// How a hair's absorption is given.
#[derive(Clone, Debug)]
pub enum HairAbsorption {
    /// The absorption coefficient σa directly.
    SigmaA(SpectrumTextureRef),
    /// A reflectance (colour) the fiber should approximately have.
    Reflectance(SpectrumTextureRef),
    /// Eumelanin and pheomelanin concentrations.
    Melanin {
        /// Eumelanin (dark brown) concentration.
        eumelanin: FloatTextureRef,
        /// Pheomelanin (red) concentration.
        pheomelanin: FloatTextureRef,
    },
}

/// `hair`: Chiang et al.'s fiber scattering model.
#[derive(Clone, Debug)]
pub struct HairMaterial {
    /// The fiber's absorption.
    pub absorption: HairAbsorption,
    /// Index of refraction of the fiber.
    pub eta: FloatTextureRef,
    /// Longitudinal roughness.
    pub beta_m: FloatTextureRef,
    /// Azimuthal roughness.
    pub beta_n: FloatTextureRef,
    /// Scale tilt in degrees.
    pub alpha: FloatTextureRef,
}

impl HairMaterial {
    /// The BxDF at a point; v across the curve gives the offset h.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let t = &ctx.tex;
        let bm = self.beta_m.evaluate(t).max(1e-2);
        let bn = self.beta_n.evaluate(t).max(1e-2);
        let a = self.alpha.evaluate(t);
        let e = self.eta.evaluate(t);
        let sigma_a: SampledSpectrum = match &self.absorption {
            HairAbsorption::SigmaA(s) => s.evaluate(t, lambda).clamp_zero(),
            HairAbsorption::Reflectance(c) => {
                let c = c.evaluate(t, lambda).clamp(0.0, 1.0);
                HairBxDF::sigma_a_from_reflectance(c, bn)
            }
            HairAbsorption::Melanin {
                eumelanin,
                pheomelanin,
            } => {
                let ce = eumelanin.evaluate(t).max(0.0);
                let cp = pheomelanin.evaluate(t).max(0.0);
                let rgb = HairBxDF::sigma_a_from_concentration(ce, cp);
                Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(RgbColorSpace::srgb(), rgb))
                    .sample(lambda)
            }
        };
        let h = clamp(-1.0 + 2.0 * t.uv.y, -1.0, 1.0);
        BxDF::Hair(HairBxDF::new(h, e, sigma_a, bm, bn, a))
    }
}
