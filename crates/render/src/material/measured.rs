//! Measured materials (pbrt-v4 book section 9.8; pbrt-v4 `MeasuredMaterial`):
//! a BRDF tabulated in an RGL `.bsdf` file.

use crate::bxdf::{BxDF, MeasuredBxDF, MeasuredBxDFData};
use crate::spectrum::SampledWavelengths;

use super::{MaterialEvalContext, ShadingPerturbation};

/// `measured`: reflectance from a Dupuy–Jakob tensor file.
#[derive(Clone, Debug)]
pub struct MeasuredMaterial {
    /// The file's tables, shared by every material naming the same file
    /// and kept for the whole run.
    pub data: &'static MeasuredBxDFData,
    /// Normal or bump mapping.
    pub perturbation: ShadingPerturbation,
}

impl MeasuredMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Measured(MeasuredBxDF::new(self.data, lambda))
    }
}
