//! pbrt-v3's `disney` material (pbrt-v3 `materials/disney.cpp`), which
//! pbrt-v4 dropped: every parameter is a texture, evaluated at the point
//! and handed to [`DisneyBxDF`]; a solid surface with a non-black
//! `scatterdistance` there also has a [`DisneyBssrdf`].

use crate::bssrdf::DisneyBssrdf;
use crate::bxdf::{BxDF, DisneyBxDF, DisneyParams};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{FloatTextureRef, SpectrumTextureRef};

use super::{MaterialEvalContext, ShadingPerturbation};

/// `disney`: the parameters of pbrt-v3's Disney BSDF, with pbrt-v3's
/// defaults filled in by the creator.
#[derive(Clone, Debug)]
pub struct DisneyMaterial {
    /// `color` (0.5).
    pub color: SpectrumTextureRef,
    /// `metallic` (0).
    pub metallic: FloatTextureRef,
    /// `eta` (1.5).
    pub eta: FloatTextureRef,
    /// `roughness` (0.5).
    pub roughness: FloatTextureRef,
    /// `speculartint` (0).
    pub specular_tint: FloatTextureRef,
    /// `anisotropic` (0).
    pub anisotropic: FloatTextureRef,
    /// `sheen` (0).
    pub sheen: FloatTextureRef,
    /// `sheentint` (0.5).
    pub sheen_tint: FloatTextureRef,
    /// `clearcoat` (0).
    pub clearcoat: FloatTextureRef,
    /// `clearcoatgloss` (1).
    pub clearcoat_gloss: FloatTextureRef,
    /// `spectrans` (0).
    pub spec_trans: FloatTextureRef,
    /// `thin` (false).
    pub thin: bool,
    /// `flatness` (0).
    pub flatness: FloatTextureRef,
    /// `difftrans` (1).
    pub diff_trans: FloatTextureRef,
    /// `scatterdistance` (black: none), kept only for solid surfaces.
    pub scatter_distance: Option<SpectrumTextureRef>,
    /// `bumpmap` (pbrt-v3's name for `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl DisneyMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        let t = &ctx.tex;
        let color = self.color.evaluate(t, lambda).clamp_zero();
        let p = DisneyParams {
            luminance: color.y(lambda),
            color,
            metallic: self.metallic.evaluate(t),
            eta: self.eta.evaluate(t),
            roughness: self.roughness.evaluate(t),
            specular_tint: self.specular_tint.evaluate(t),
            anisotropic: self.anisotropic.evaluate(t),
            sheen: self.sheen.evaluate(t),
            sheen_tint: self.sheen_tint.evaluate(t),
            clearcoat: self.clearcoat.evaluate(t),
            clearcoat_gloss: self.clearcoat_gloss.evaluate(t),
            spec_trans: self.spec_trans.evaluate(t),
            thin: self.thin,
            flatness: self.flatness.evaluate(t),
            diff_trans: self.diff_trans.evaluate(t),
            subsurface: self.scatter_distance(ctx, lambda).is_some(),
        };
        BxDF::Disney(DisneyBxDF::new(&p))
    }

    /// The scatter distance at a point of a solid surface, unless black
    /// there (pbrt-v3 then keeps the diffuse lobe).
    fn scatter_distance(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &SampledWavelengths,
    ) -> Option<SampledSpectrum> {
        if self.thin {
            return None;
        }
        let d = self.scatter_distance.as_ref()?.evaluate(&ctx.tex, lambda);
        (!d.clamp_zero().is_black()).then_some(d)
    }

    /// True when the material can have a BSSRDF somewhere.
    pub fn has_subsurface_scattering(&self) -> bool {
        !self.thin && self.scatter_distance.is_some()
    }

    /// The BSSRDF at a point (pbrt-v3 creates it with the diffuse weight
    /// (1 − metallic)(1 − spectrans) times the colour as its albedo), or
    /// `None` where the surface has no diffuse part or no scatter distance.
    pub fn get_bssrdf(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &SampledWavelengths,
    ) -> Option<DisneyBssrdf> {
        let d = self.scatter_distance(ctx, lambda)?;
        let t = &ctx.tex;
        let diffuse_weight =
            (1.0 - self.metallic.evaluate(t)) * (1.0 - self.spec_trans.evaluate(t));
        if !(diffuse_weight > 0.0) {
            return None;
        }
        let color = self.color.evaluate(t, lambda).clamp_zero();
        Some(DisneyBssrdf::new(
            t.p,
            ctx.ns,
            self.eta.evaluate(t),
            color * diffuse_weight,
            d,
        ))
    }
}
