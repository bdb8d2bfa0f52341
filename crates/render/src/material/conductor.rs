//! Metals (pbrt-v4 book section 9.5; pbrt-v4 `ConductorMaterial`).

use crate::bxdf::{BxDF, ConductorBxDF};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{SpectrumTextureRef, TextureEvalContext};

use super::{MaterialEvalContext, Roughness, ShadingPerturbation};

/// How a conductor's complex index of refraction is given.
#[derive(Clone, Debug)]
pub enum ConductorSpectra {
    /// Real and imaginary parts η and k.
    EtaK {
        /// η.
        eta: SpectrumTextureRef,
        /// k.
        k: SpectrumTextureRef,
    },
    /// A normal-incidence reflectance r: η = 1 and k = 2√r / √(1 − r),
    /// which reflects exactly r at normal incidence.
    Reflectance(SpectrumTextureRef),
}

impl ConductorSpectra {
    /// η and k at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> (SampledSpectrum, SampledSpectrum) {
        match self {
            ConductorSpectra::EtaK { eta, k } => {
                (eta.evaluate(ctx, lambda), k.evaluate(ctx, lambda))
            }
            ConductorSpectra::Reflectance(r) => {
                let r = r.evaluate(ctx, lambda).clamp(0.0, 0.9999);
                let k = r.sqrt() * 2.0 / (SampledSpectrum::new(1.0) - r).clamp_zero().sqrt();
                (SampledSpectrum::new(1.0), k)
            }
        }
    }
}

/// `conductor`: a smooth or rough metal.
#[derive(Clone, Debug)]
pub struct ConductorMaterial {
    /// The complex index of refraction.
    pub spectra: ConductorSpectra,
    /// Microfacet roughness.
    pub roughness: Roughness,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl ConductorMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let distrib = self.roughness.distribution(&ctx.tex);
        let (eta, k) = self.spectra.evaluate(&ctx.tex, lambda);
        BxDF::Conductor(ConductorBxDF::new(distrib, eta, k))
    }
}
