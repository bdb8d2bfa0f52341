//! Layered materials (pbrt-v4 book section 14.3; pbrt-v4
//! `CoatedDiffuseMaterial`, `CoatedConductorMaterial`).

use rpbrt_geometry::float::*;

use crate::bxdf::{
    BxDF, CoatedConductorBxDF, CoatedDiffuseBxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF,
};
use crate::spectrum::{SampledWavelengths, Spectrum};
use crate::texture::{FloatTextureRef, SpectrumTextureRef};

use super::{sample_eta, ConductorSpectra, MaterialEvalContext, Roughness, ShadingPerturbation};

/// The medium between the layers and the random walk's settings.
#[derive(Clone, Debug)]
pub struct LayerSettings {
    /// Thickness of the slab.
    pub thickness: FloatTextureRef,
    /// Single-scattering albedo of the medium inside (0: none).
    pub albedo: SpectrumTextureRef,
    /// Henyey–Greenstein asymmetry of the medium.
    pub g: FloatTextureRef,
    /// Bound on the random walk's scattering events.
    pub max_depth: u32,
    /// Walks averaged per evaluation.
    pub n_samples: u32,
}

/// `coateddiffuse`: a dielectric coating over a Lambertian base.
#[derive(Clone, Debug)]
pub struct CoatedDiffuseMaterial {
    /// The base's reflectance.
    pub reflectance: SpectrumTextureRef,
    /// The coating's roughness.
    pub roughness: Roughness,
    /// The coating's index of refraction.
    pub eta: Spectrum,
    /// The slab between coating and base.
    pub layer: LayerSettings,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl CoatedDiffuseMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &mut SampledWavelengths,
        seed: i32,
    ) -> BxDF {
        let t = &ctx.tex;
        let r = self.reflectance.evaluate(t, lambda).clamp(0.0, 1.0);
        let distrib = self.roughness.distribution(t);
        let thickness = self.layer.thickness.evaluate(t);
        let eta = sample_eta(&self.eta, lambda);
        let albedo = self.layer.albedo.evaluate(t, lambda).clamp(0.0, 1.0);
        let g = clamp(self.layer.g.evaluate(t), -1.0, 1.0);
        BxDF::CoatedDiffuse(
            CoatedDiffuseBxDF::new(
                DielectricBxDF::new(eta, distrib),
                DiffuseBxDF::new(r),
                thickness,
                albedo,
                g,
                self.layer.max_depth,
                self.layer.n_samples,
            )
            .with_seed(seed),
        )
    }
}

/// `coatedconductor`: a dielectric coating over a metal.
#[derive(Clone, Debug)]
pub struct CoatedConductorMaterial {
    /// The coating's roughness.
    pub interface_roughness: Roughness,
    /// The coating's index of refraction.
    pub interface_eta: Spectrum,
    /// The metal's complex index of refraction.
    pub conductor: ConductorSpectra,
    /// The metal's roughness.
    pub conductor_roughness: Roughness,
    /// The slab between coating and metal.
    pub layer: LayerSettings,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl CoatedConductorMaterial {
    /// The BxDF at a point. The metal's index is taken relative to the
    /// coating's.
    pub fn get_bxdf(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &mut SampledWavelengths,
        seed: i32,
    ) -> BxDF {
        let t = &ctx.tex;
        let interface_distrib = self.interface_roughness.distribution(t);
        let ieta = sample_eta(&self.interface_eta, lambda);
        let (ce, ck) = self.conductor.evaluate(t, lambda);
        let (ce, ck) = (ce / ieta, ck / ieta);
        let conductor_distrib = self.conductor_roughness.distribution(t);
        let thickness = self.layer.thickness.evaluate(t);
        let albedo = self.layer.albedo.evaluate(t, lambda).clamp(0.0, 1.0);
        let g = clamp(self.layer.g.evaluate(t), -1.0, 1.0);
        BxDF::CoatedConductor(
            CoatedConductorBxDF::new(
                DielectricBxDF::new(ieta, interface_distrib),
                ConductorBxDF::new(conductor_distrib, ce, ck),
                thickness,
                albedo,
                g,
                self.layer.max_depth,
                self.layer.n_samples,
            )
            .with_seed(seed),
        )
    }
}
