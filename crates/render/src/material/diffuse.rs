//! Lambertian materials (pbrt-v4 book section 9.2; pbrt-v4
//! `DiffuseMaterial`, `DiffuseTransmissionMaterial`).

use crate::bxdf::{BxDF, DiffuseBxDF, DiffuseTransmissionBxDF};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{SpectrumTextureRef, TextureEvalContext};
use rpbrt_geometry::float::Float;

use super::{MaterialEvalContext, ShadingPerturbation};

/// `diffuse`: Lambertian reflection.
#[derive(Clone, Debug)]
pub struct DiffuseMaterial {
    /// Reflectance (clamped to [0, 1] when evaluated).
    pub reflectance: SpectrumTextureRef,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl DiffuseMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Diffuse(DiffuseBxDF::new(self.reflectance_at(&ctx.tex, lambda)))
    }

    /// The reflectance at a point, clamped to [0, 1] (the BxDF's).
    #[inline]
    pub fn reflectance_at(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.reflectance.evaluate(ctx, lambda).clamp(0.0, 1.0)
    }
}

/// `diffusetransmission`: Lambertian reflection and transmission.
#[derive(Clone, Debug)]
pub struct DiffuseTransmissionMaterial {
    /// Reflectance.
    pub reflectance: SpectrumTextureRef,
    /// Transmittance.
    pub transmittance: SpectrumTextureRef,
    /// Scale applied to both before clamping to [0, 1].
    pub scale: Float,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl DiffuseTransmissionMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let r = (self.reflectance.evaluate(&ctx.tex, lambda) * self.scale).clamp(0.0, 1.0);
        let t = (self.transmittance.evaluate(&ctx.tex, lambda) * self.scale).clamp(0.0, 1.0);
        BxDF::DiffuseTransmission(DiffuseTransmissionBxDF::new(r, t))
    }
}
