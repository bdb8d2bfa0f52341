//! pbrt-v1's measured Lafortune materials: see [`LafortuneBxDF`].

use crate::bxdf::{BxDF, LafortuneBxDF, LafortuneFit};
use crate::spectrum::{RgbColorSpace, SampledWavelengths};

use super::{MaterialEvalContext, ShadingPerturbation};

/// `bluepaint`, `brushedmetal`, `clay`, `felt`, `primer` or `skin`.
#[derive(Clone, Debug)]
pub struct LafortuneMaterial {
    /// The fit.
    pub fit: &'static LafortuneFit,
    /// The colour space its RGB coefficients are read in.
    pub color_space: &'static RgbColorSpace,
    /// pbrt-v1's `bumpmap` (read as `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl LafortuneMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Lafortune(LafortuneBxDF::new(self.fit, self.color_space, lambda))
    }
}
