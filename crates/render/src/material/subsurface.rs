//! Subsurface scattering materials (pbrt-v4 book section 14.4; pbrt-v4
//! `SubsurfaceMaterial`). Only the BSDF part (a dielectric boundary) is
//! evaluated here; [`SubsurfaceMaterial::get_bssrdf`] builds the tabulated
//! BSSRDF from the scattering parameters.

use rpbrt_geometry::float::*;

use crate::bssrdf::{beam_diffusion_table, subsurface_from_diffuse, TabulatedBssrdf};
use crate::bxdf::{BxDF, DielectricBxDF};
use crate::spectrum::SampledWavelengths;
use crate::texture::SpectrumTextureRef;

use super::{MaterialEvalContext, Roughness, ShadingPerturbation};

/// How the volume under the surface is described (pbrt-v4's four
/// mutually exclusive ways collapse to these two).
#[derive(Clone, Debug)]
pub enum SubsurfaceCoefficients {
    /// Absorption and scattering coefficients (given directly, from a named
    /// measured medium, or pbrt-v4's default whole milk), in mm⁻¹ before
    /// `scale`.
    Coefficients {
        /// σa.
        sigma_a: SpectrumTextureRef,
        /// σs.
        sigma_s: SpectrumTextureRef,
    },
    /// A diffuse reflectance and a mean free path, to be inverted into
    /// coefficients.
    Reflectance {
        /// Multiple-scattering albedo.
        reflectance: SpectrumTextureRef,
        /// Mean free path.
        mfp: SpectrumTextureRef,
    },
}

/// `subsurface`: a dielectric boundary over a homogeneous scattering
/// volume.
#[derive(Clone, Debug)]
pub struct SubsurfaceMaterial {
    /// Scale applied to the coefficients.
    pub scale: Float,
    /// The volume's coefficients.
    pub coefficients: SubsurfaceCoefficients,
    /// Henyey–Greenstein asymmetry (0 for named media, whose scattering
    /// coefficients are already reduced).
    pub g: Float,
    /// Index of refraction of the boundary.
    pub eta: Float,
    /// Roughness of the boundary.
    pub roughness: Roughness,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl SubsurfaceMaterial {
    /// The boundary's BxDF at a point.
    pub fn get_bxdf(&self, ctx: &MaterialEvalContext, _lambda: &mut SampledWavelengths) -> BxDF {
        let distrib = self.roughness.distribution(&ctx.tex);
        BxDF::Dielectric(DielectricBxDF::new(self.eta, distrib))
    }

    /// The BSSRDF leaving the point (pbrt-v4 `SubsurfaceMaterial::GetBSSRDF`):
    /// σa and σs scaled by `scale` (clamped to be non-negative), or found
    /// from the reflectance and the scaled mean free path by inverting the
    /// beam-diffusion table's effective albedo; the table for this
    /// material's (g, eta) is computed on first use and then shared.
    pub fn get_bssrdf(
        &self,
        ctx: &MaterialEvalContext,
        lambda: &SampledWavelengths,
    ) -> TabulatedBssrdf<'static> {
        let table = beam_diffusion_table(self.g, self.eta);
        let (sigma_a, sigma_s) = match &self.coefficients {
            SubsurfaceCoefficients::Coefficients { sigma_a, sigma_s } => (
                (sigma_a.evaluate(&ctx.tex, lambda) * self.scale).clamp_zero(),
                (sigma_s.evaluate(&ctx.tex, lambda) * self.scale).clamp_zero(),
            ),
            SubsurfaceCoefficients::Reflectance { reflectance, mfp } => {
                let mfree = (mfp.evaluate(&ctx.tex, lambda) * self.scale).clamp_zero();
                let r = reflectance.evaluate(&ctx.tex, lambda).clamp(0.0, 1.0);
                subsurface_from_diffuse(table, r, mfree)
            }
        };
        TabulatedBssrdf::new(ctx.tex.p, ctx.ns, ctx.wo, self.eta, sigma_a, sigma_s, table)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use rpbrt_geometry::interaction::SurfaceInteraction;
    use rpbrt_geometry::tuple::*;

    use super::*;
    use crate::bssrdf::{catmull_rom, SeparableBssrdf};
    use crate::spectrum::Spectrum;
    use crate::texture::{FloatTexture, SpectrumTexture};

    fn stex(v: Float) -> SpectrumTextureRef {
        Arc::new(SpectrumTexture::Constant(Spectrum::constant(v)))
    }

    fn material(coefficients: SubsurfaceCoefficients, scale: Float) -> SubsurfaceMaterial {
        let zero = Arc::new(FloatTexture::Constant(0.0));
        SubsurfaceMaterial {
            scale,
            coefficients,
            g: 0.0,
            eta: 1.33,
            roughness: Roughness {
                u: zero.clone(),
                v: zero,
                remap: true,
            },
            perturbation: ShadingPerturbation::default(),
        }
    }

    fn ctx() -> MaterialEvalContext {
        let si = SurfaceInteraction::new(
            Point3fi::from(Point3f::new(1.0, 2.0, 0.0)),
            Point2f::new(0.5, 0.5),
            Vector3f::new(0.0, 0.0, 1.0),
            Vector3f::new(1.0, 0.0, 0.0),
            Vector3f::new(0.0, 1.0, 0.0),
            Normal3f::default(),
            Normal3f::default(),
            0.0,
            false,
        );
        MaterialEvalContext::from_si(&si)
    }

    #[test]
    fn bssrdf_from_coefficients_is_scaled() {
        let m = material(
            SubsurfaceCoefficients::Coefficients {
                sigma_a: stex(0.25),
                sigma_s: stex(-1.0),
            },
            2.0,
        );
        let lambda = SampledWavelengths::sample_visible(0.3);
        let b = m.get_bssrdf(&ctx(), &lambda);
        // Negative coefficients clamp to zero; the scale multiplies.
        assert_eq!(b.sigma_t(), crate::spectrum::SampledSpectrum::new(0.5));
        assert_eq!(b.rho(), crate::spectrum::SampledSpectrum::new(0.0));
        assert_eq!(b.wo(), Vector3f::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn bssrdf_from_reflectance_reproduces_it() {
        let m = material(
            SubsurfaceCoefficients::Reflectance {
                reflectance: stex(0.4),
                mfp: stex(0.5),
            },
            2.0,
        );
        let lambda = SampledWavelengths::sample_visible(0.6);
        let b = m.get_bssrdf(&ctx(), &lambda);
        let t = crate::bssrdf::beam_diffusion_table(0.0, 1.33);
        for i in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
            // σt = 1 / (scale · mfp); the albedo maps back to 0.4.
            assert!((b.sigma_t()[i] - 1.0).abs() < 1e-5);
            let eff = catmull_rom(&t.rho_samples, &t.rho_eff, b.rho()[i]);
            assert!((eff - 0.4).abs() < 1e-3, "{eff}");
        }
        // The profile is centred on the shading point.
        let near = b.sp(Point3f::new(1.0, 2.01, 0.0));
        let far = b.sp(Point3f::new(1.0, 3.0, 0.0));
        assert!(near[0] > far[0] && far[0] > 0.0);
    }
}
