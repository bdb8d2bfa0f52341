//! pbrt-v3's `fourier` material (pbrt-v3 `materials/fourier.cpp`): a
//! tabulated BSDF read from a `"string bsdffile"` in Mitsuba's Fourier
//! format, which pbrt-v4 dropped.

use crate::bxdf::{BxDF, FourierBSDFTable, FourierBxDF};
use crate::spectrum::SampledWavelengths;

use super::{MaterialEvalContext, ShadingPerturbation};

/// `fourier`: the tables of one `.bsdf` file.
#[derive(Clone, Debug)]
pub struct FourierMaterial {
    /// The file's tables, shared by every material naming the same file
    /// and kept for the whole run.
    pub table: &'static FourierBSDFTable,
    /// pbrt-v3's `bumpmap` (read as `displacement`).
    pub perturbation: ShadingPerturbation,
}

impl FourierMaterial {
    /// The BxDF at a point.
    pub fn get_bxdf(&self, _ctx: &MaterialEvalContext, lambda: &mut SampledWavelengths) -> BxDF {
        BxDF::Fourier(FourierBxDF::new(self.table, lambda))
    }
}
