//! Participating media (pbrt-v4 `media.h/.cpp`, `base/medium.h`; book
//! chapter 11): the closed [`Medium`] enum, the properties a medium has at a
//! point, majorants along rays, the Henyey–Greenstein phase function, and
//! [`sample_t_maj`], the delta-tracking loop every volumetric integrator
//! builds on.
//!
//! The files: `phase`, the phase function; `majorant`, majorant segments,
//! the majorant grid and its DDA walk; `sampled_grid`, trilinearly
//! interpolated sample grids; one file per medium type (`homogeneous`,
//! `grid`, `rgbgrid`, `cloud`, and pbrt-v1/v2's `Volume` regions in
//! `region`), each with its creation; `create`,
//! creation from `MakeNamedMedium` and the parameter checks the media
//! share.

mod cloud;
mod create;
mod grid;
#[cfg(test)]
mod grid_tests;
mod homogeneous;
mod majorant;
pub mod measured;
pub mod nanovdb;
mod nanovdb_medium;
mod phase;
mod region;
mod rgbgrid;
mod sampled_grid;
#[cfg(test)]
mod tests;

pub use cloud::{CloudMedium, CloudMediumParts};
pub use create::{create_medium, MAX_GRID_SAMPLES, MEDIUM_NAMES};
pub use grid::{GridMedium, GridMediumParts, GRID_MAJORANT_RES};
pub use homogeneous::HomogeneousMedium;
pub use majorant::{
    DdaMajorantIterator, HomogeneousMajorantIterator, MajorantGrid, RayMajorantSegment,
};
pub use nanovdb_medium::{NanoVdbMedium, NanoVdbTemperature};
pub use phase::{
    henyey_greenstein, sample_henyey_greenstein, HGPhaseFunction, PhaseFunctionSample,
};
pub use region::{create_region, RegionMedium, VolumeRegion, REGION_NAMES};
pub use rgbgrid::{RgbEmissionGrid, RgbGridMedium, RgbGridMediumParts, RGB_GRID_MAJORANT_RES};
pub use sampled_grid::{GridValue, Interpolant, SampledGrid};

use crate::rng::Rng;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::tuple::*;

/// What a medium is like at a point (pbrt-v4 `MediumProperties`).
#[derive(Clone, Copy, Debug)]
pub struct MediumProperties {
    /// Absorption coefficient.
    pub sigma_a: SampledSpectrum,
    /// Scattering coefficient.
    pub sigma_s: SampledSpectrum,
    /// How light scatters there.
    pub phase: HGPhaseFunction,
    /// Emitted radiance.
    pub le: SampledSpectrum,
}

/// What each medium type provides to delta tracking (pbrt-v4's `Medium`
/// interface: `SamplePoint` and `SampleRay`); [`sample_t_maj`] is generic
/// over it so that each medium gets a loop of its own.
pub(crate) trait ConcreteMedium {
    /// The iterator over majorant segments along a ray.
    type Majorants<'a>: Iterator<Item = RayMajorantSegment>
    where
        Self: 'a;
    /// The medium's properties at a rendering-space point.
    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties;
    /// The majorant segments along `ray` (rendering space, unit direction)
    /// over `[0, t_max]`.
    fn sample_ray<'a>(
        &'a self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> Self::Majorants<'a>;
}

/// The closed set of participating media (pbrt-v4 `Medium`). The grid
/// media are boxed to keep the enum small.
#[derive(Clone, Debug)]
pub enum Medium {
    /// `homogeneous`.
    Homogeneous(HomogeneousMedium),
    /// `nanovdb` (boxed: its grids and majorants make it large).
    NanoVdb(Box<NanoVdbMedium>),
    /// `uniformgrid` (and pbrt-v3's `heterogeneous`).
    UniformGrid(Box<GridMedium>),
    /// `rgbgrid`.
    RgbGrid(Box<RgbGridMedium>),
    /// `cloud`.
    Cloud(Box<CloudMedium>),
    /// pbrt-v1/v2's `Volume` regions, all of a scene's together.
    Region(Box<RegionMedium>),
}

impl Medium {
    /// Whether the medium emits light anywhere.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        match self {
            Medium::Homogeneous(m) => m.is_emissive(),
            Medium::NanoVdb(m) => m.is_emissive(),
            Medium::UniformGrid(m) => m.is_emissive(),
            Medium::RgbGrid(m) => m.is_emissive(),
            Medium::Cloud(_) => false,
            Medium::Region(m) => m.is_emissive(),
        }
    }

    /// The medium's properties at a rendering-space point.
    #[inline]
    pub fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        match self {
            Medium::Homogeneous(m) => m.sample_point(p, lambda),
            Medium::NanoVdb(m) => m.sample_point(p, lambda),
            Medium::UniformGrid(m) => m.sample_point(p, lambda),
            Medium::RgbGrid(m) => m.sample_point(p, lambda),
            Medium::Cloud(m) => m.sample_point(p, lambda),
            Medium::Region(m) => m.sample_point(p, lambda),
        }
    }

    /// The majorant segments along `ray` over `[0, t_max]` (for tests and
    /// tools; integrators use [`sample_t_maj`]).
    pub fn majorant_segments(
        &self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> Vec<RayMajorantSegment> {
        let (ray, t_max) = normalized(ray, t_max);
        match self {
            Medium::Homogeneous(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::NanoVdb(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::UniformGrid(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::RgbGrid(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::Cloud(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::Region(m) => m.sample_ray(&ray, t_max, lambda).collect(),
        }
    }
}

/// The ray with a unit direction and `t_max` rescaled to match.
#[inline]
fn normalized(ray: &Ray, t_max: Float) -> (Ray, Float) {
    let len = ray.d.length();
    let mut r = *ray;
    r.d = ray.d / len;
    (r, t_max * len)
}

/// `s` tabulated at every nanometre and multiplied by `k` (pbrt-v4's
/// `DenselySampledSpectrum` followed by `Scale`).
pub(crate) fn scaled_spectrum(
    s: &crate::spectrum::Spectrum,
    k: Float,
) -> crate::spectrum::DenselySampledSpectrum {
    let mut d = crate::spectrum::DenselySampledSpectrum::new(s);
    d.scale(k);
    d
}

/// `−ln(1 − u) / a`: a sample of the exponential distribution with rate `a`.
#[inline]
pub fn sample_exponential(u: Float, a: Float) -> Float {
    -(1.0 - u).ln() / a
}

/// Delta tracking along `ray` through `medium` up to `t_max` (pbrt-v4
/// `SampleT_maj`; book section 11.4.4): samples tentative collisions
/// against the majorant and calls `callback(p, properties, sigma_maj,
/// T_maj, rng)` at each, with `T_maj` the majorant transmittance since the
/// previous collision. The callback returns whether to go on. Returns the
/// majorant transmittance from the last collision to the end of the ray
/// (one when the callback stopped the walk). `u` is the first collision's
/// sample; later ones come from `rng`, which the callback may also use.
#[inline]
pub fn sample_t_maj(
    medium: &Medium,
    ray: &Ray,
    t_max: Float,
    u: Float,
    rng: &mut Rng,
    lambda: &SampledWavelengths,
    callback: impl FnMut(Point3f, &MediumProperties, SampledSpectrum, SampledSpectrum, &mut Rng) -> bool,
) -> SampledSpectrum {
    match medium {
        Medium::Homogeneous(m) => sample_t_maj_in(m, ray, t_max, u, rng, lambda, callback),
        Medium::NanoVdb(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::UniformGrid(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::RgbGrid(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::Cloud(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::Region(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
    }
}

/// The most tentative collisions one [`sample_t_maj`] walk takes. Real
/// media stop far earlier (a real collision ends the walk of a path, and
/// Russian roulette that of a shadow ray); only majorants many orders of
/// magnitude above the density they bound get here.
pub const MAX_COLLISIONS: u32 = 1 << 22;

/// [`sample_t_maj`] for one medium type.
#[inline(always)]
fn sample_t_maj_in<M: ConcreteMedium>(
    medium: &M,
    ray: &Ray,
    t_max: Float,
    u: Float,
    rng: &mut Rng,
    lambda: &SampledWavelengths,
    mut callback: impl FnMut(
        Point3f,
        &MediumProperties,
        SampledSpectrum,
        SampledSpectrum,
        &mut Rng,
    ) -> bool,
) -> SampledSpectrum {
    let (ray, t_max) = normalized(ray, t_max);
    // The collision distance is sampled as an optical depth in the hero
    // wavelength's majorant and spent segment by segment: the same
    // exponential distribution as pbrt-v4's fresh sample per segment (the
    // process is memoryless), without a logarithm, an exponential and a
    // random number for every majorant-grid voxel the ray crosses. The
    // majorant optical depth of every wavelength since the last collision
    // is summed and exponentiated once per collision.
    let mut tau = sample_exponential(u, 1.0);
    let mut depth = SampledSpectrum::new(0.0);
    let mut collisions = 0u32;
    for seg in medium.sample_ray(&ray, t_max, lambda) {
        let sigma = seg.sigma_maj[0];
        let mut t_min = seg.t_min;
        loop {
            if sigma > 0.0 {
                let t = t_min + (tau / sigma).max(0.0);
                if t < seg.t_max {
                    collisions += 1;
                    if collisions > MAX_COLLISIONS {
                        // A guard against majorants absurdly above the
                        // density (a file's claims): the walk ends as if
                        // the ray were absorbed, rather than hanging.
                        return SampledSpectrum::new(0.0);
                    }
                    depth += (t - t_min) * seg.sigma_maj;
                    let t_maj = fast_exp_spectrum(-depth);
                    let p = ray.at(t);
                    let mp = medium.sample_point(p, lambda);
                    if !callback(p, &mp, seg.sigma_maj, t_maj, rng) {
                        return SampledSpectrum::new(1.0);
                    }
                    depth = SampledSpectrum::new(0.0);
                    tau = sample_exponential(rng.uniform_float(), 1.0);
                    t_min = t;
                    continue;
                }
            }
            // No collision in the rest of the segment (unbounded segments
            // kept finite so that a zero majorant gives zero depth).
            let dt = finite(seg.t_max - t_min);
            tau -= sigma * dt;
            depth += dt * seg.sigma_maj;
            break;
        }
    }
    fast_exp_spectrum(-depth)
}

/// pbrt-v4's `FastExp`: eˣ as 2^(x·log₂e), with 2^f on [0, 1) from a
/// cubic polynomial (relative error below 2·10⁻⁴) and the integer part put
/// in the exponent bits; 0 below the normal range, +∞ above it. Majorant
/// transmittances need no more accuracy, and this keeps them off `libm`.
#[inline(always)]
pub fn fast_exp(x: Float) -> Float {
    let xp = x * std::f32::consts::LOG2_E;
    // ⌊xp⌋ by truncation (saturating for huge values and NaN, which the
    // range checks below turn into 0, ∞ or NaN): `floor` is a libm call
    // on baseline x86-64.
    let mut i = xp as i32;
    if (i as Float) > xp {
        i = i.saturating_sub(1);
    }
    let f = xp - i as Float;
    let two_to_f = 1.0 + f * (0.695_556_86 + f * (0.226_173_57 + f * 0.078_145_574));
    if x.is_nan() {
        return x;
    }
    let exponent = ((two_to_f.to_bits() >> 23) & 0xff) as i32 - 127 + i.clamp(-1000, 1000);
    if exponent < -126 || !(f < 2.0) {
        // Below the normal range (or a saturated cast of −∞).
        return if xp > 0.0 { Float::INFINITY } else { 0.0 };
    }
    if exponent > 127 {
        return Float::INFINITY;
    }
    let bits = (two_to_f.to_bits() & 0x807f_ffff) | (((exponent + 127) as u32) << 23);
    Float::from_bits(bits)
}

/// [`fast_exp`] of every wavelength's value.
#[inline(always)]
pub fn fast_exp_spectrum(s: SampledSpectrum) -> SampledSpectrum {
    let mut out = s;
    for i in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
        out[i] = fast_exp(s[i]);
    }
    out
}

/// `x`, with +∞ replaced by the largest float (so that `0 × x` stays 0).
#[inline]
fn finite(x: Float) -> Float {
    if x.is_infinite() {
        Float::MAX
    } else {
        x
    }
}
