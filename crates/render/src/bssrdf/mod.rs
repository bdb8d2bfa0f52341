//! Bidirectional scattering-surface reflectance distribution functions
//! (pbrt-v4 `bssrdf.h`; pbrt-v3 book sections 11.4 and 15.4–15.5): the
//! tabulated photon-beam-diffusion BSSRDF used by the `subsurface`
//! material, with the Catmull–Rom spline tools it is built on.
//!
//! No integrator traces probe rays yet, so nothing renders with these.

pub mod spline;
pub mod table;
pub mod tabulated;

pub use spline::{
    catmull_rom, catmull_rom_weights, integrate_catmull_rom, invert_catmull_rom, newton_bisection,
    sample_catmull_rom_2d, SplineSample,
};
pub use table::{
    beam_diffusion_ms, beam_diffusion_ss, beam_diffusion_table, compute_beam_diffusion_bssrdf,
    BssrdfTable, N_RADIUS_SAMPLES, N_RHO_SAMPLES,
};
pub use tabulated::{
    subsurface_from_diffuse, BssrdfProbeSegment, BssrdfSample, SubsurfaceInteraction,
    TabulatedBssrdf,
};

#[cfg(test)]
mod tests;
