//! pbrt-v1/v2's `shinymetal` material (pbrt-v2 `materials/shinymetal.cpp`),
//! which pbrt-v3 dropped: see [`ShinyMetalBxDF`].

use crate::bxdf::{BxDF, ShinyMetalBxDF};
use crate::spectrum::SampledWavelengths;
use crate::texture::{FloatTextureRef, SpectrumTextureRef};

use super::{MaterialEvalContext, ShadingPerturbation};

/// `shinymetal`: `Ks` (the glossy lobe's colour, default 1), `Kr` (the
/// mirror's, default 1) and `roughness` (0.1).
#[derive(Clone, Debug)]
pub struct ShinyMetalMaterial {
    /// The glossy lobe's reflectance at normal incidence.
    pub ks: SpectrumTextureRef,
    /// The mirror's reflectance at normal incidence.
    pub kr: SpectrumTextureRef,
    /// Blinn's roughness (the exponent is its reciprocal).
    pub roughness: FloatTextureRef,
    /// pbrt-v2's `bumpmap` (read as `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl ShinyMetalMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let ks = self.ks.evaluate(&ctx.tex, lambda);
        let kr = self.kr.evaluate(&ctx.tex, lambda);
        let roughness = self.roughness.evaluate(&ctx.tex);
        BxDF::ShinyMetal(ShinyMetalBxDF::new(ks, kr, roughness))
    }
}
