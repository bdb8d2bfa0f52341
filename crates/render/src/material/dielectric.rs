//! Dielectrics (pbrt-v4 book sections 9.3 and 9.5; pbrt-v4
//! `DielectricMaterial`, `ThinDielectricMaterial`).

use crate::bxdf::{BxDF, DielectricBxDF, ThinDielectricBxDF};
use crate::spectrum::{SampledWavelengths, Spectrum};

use super::{sample_eta, MaterialEvalContext, Roughness, ShadingPerturbation};

/// `dielectric`: a smooth or rough interface between two dielectrics.
#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    /// The relative index of refraction; a non-constant spectrum makes the
    /// material dispersive.
    pub eta: Spectrum,
    /// Microfacet roughness.
    pub roughness: Roughness,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl DielectricMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let eta = sample_eta(&self.eta, lambda);
        let distrib = self.roughness.distribution(&ctx.tex);
        BxDF::Dielectric(DielectricBxDF::new(eta, distrib))
    }
}

/// `thindielectric`: a thin slab with two parallel smooth interfaces.
#[derive(Clone, Debug)]
pub struct ThinDielectricMaterial {
    /// The slab's index of refraction.
    pub eta: Spectrum,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl ThinDielectricMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::ThinDielectric(ThinDielectricBxDF::new(sample_eta(&self.eta, lambda)))
    }
}
