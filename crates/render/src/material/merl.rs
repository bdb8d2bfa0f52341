//! pbrt-v2's `measured` material over a MERL table (see [`MerlBxDF`]) or
//! irregular `.brdf` measurements (see [`IrregularBxDF`]).

use crate::bxdf::{BxDF, IrregularBrdf, IrregularBxDF, MerlBxDF, MerlTable};
use crate::spectrum::{RgbColorSpace, SampledWavelengths};

use super::{MaterialEvalContext, ShadingPerturbation};

/// `measured` with a MERL `.binary` file (pbrt-v2).
#[derive(Clone, Debug)]
pub struct MerlMaterial {
    /// The table, shared by every material naming the same file.
    pub table: &'static MerlTable,
    /// The colour space its RGB values are read in.
    pub color_space: &'static RgbColorSpace,
    /// pbrt-v2's `bumpmap` (read as `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl MerlMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Merl(MerlBxDF::new(self.table, self.color_space, lambda))
    }
}

/// `measured` with an irregular `.brdf` file (pbrt-v2).
#[derive(Clone, Debug)]
pub struct IrregularMaterial {
    /// The measurements, shared by every material naming the same file.
    pub data: &'static IrregularBrdf,
    /// pbrt-v2's `bumpmap` (read as `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl IrregularMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Irregular(IrregularBxDF::new(self.data, lambda))
    }
}
