//! Bidirectional scattering-surface reflectance distribution functions
//! (pbrt-v4 `bssrdf.h`; pbrt-v3 book sections 11.4 and 15.4–15.5). Both
//! kinds are separable ([`SeparableBssrdf`]: a radial profile, probe rays
//! and a normalized-Fresnel exit lobe): the tabulated photon-beam-diffusion
//! BSSRDF of the `subsurface` material, built on the Catmull–Rom spline
//! tools here, and pbrt-v3's Disney BSSRDF of the `disney` material with a
//! `scatterdistance`. The `volpath` integrator traces them.

pub mod disney;
pub mod separable;
pub mod spline;
pub mod table;
pub mod tabulated;

pub use disney::DisneyBssrdf;
pub use separable::{
    BssrdfOrigin, BssrdfProbeSegment, BssrdfSample, SeparableBssrdf, SubsurfaceInteraction,
};
pub use spline::{
    catmull_rom, catmull_rom_weights, integrate_catmull_rom, invert_catmull_rom, newton_bisection,
    sample_catmull_rom_2d, SplineSample,
};
pub use table::{
    beam_diffusion_ms, beam_diffusion_ss, beam_diffusion_table, compute_beam_diffusion_bssrdf,
    BssrdfTable, N_RADIUS_SAMPLES, N_RHO_SAMPLES,
};
pub use tabulated::{subsurface_from_diffuse, TabulatedBssrdf};

use rpbrt_geometry::float::Float;

use crate::spectrum::SampledSpectrum;

/// The BSSRDF a material gives at a point.
#[derive(Clone, Copy, Debug)]
pub enum Bssrdf<'a> {
    /// The `subsurface` material's.
    Tabulated(TabulatedBssrdf<'a>),
    /// The `disney` material's, with a `scatterdistance`.
    Disney(DisneyBssrdf),
}

macro_rules! dispatch {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            Bssrdf::Tabulated($b) => $e,
            Bssrdf::Disney($b) => $e,
        }
    };
}

impl SeparableBssrdf for Bssrdf<'_> {
    fn origin(&self) -> &BssrdfOrigin {
        dispatch!(self, b => b.origin())
    }

    fn sr(&self, r: Float) -> SampledSpectrum {
        dispatch!(self, b => b.sr(r))
    }

    fn sample_sr(&self, u: Float) -> Option<Float> {
        dispatch!(self, b => b.sample_sr(u))
    }

    fn pdf_sr(&self, r: Float) -> SampledSpectrum {
        dispatch!(self, b => b.pdf_sr(r))
    }
}

#[cfg(test)]
mod tests;
