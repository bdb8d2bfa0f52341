//! Participating media (pbrt-v4 `media.h/.cpp`, `base/medium.h`; book
//! chapter 11): the closed [`Medium`] enum, the properties a medium has at a
//! point, majorants along rays, the Henyey–Greenstein phase function, and
//! [`sample_t_maj`], the delta-tracking loop every volumetric integrator
//! builds on.
//!
//! The files: `phase`, the phase function; `majorant`, majorant segments,
//! the majorant grid and its DDA walk; `sampled_grid`, trilinearly
//! interpolated sample grids; one file per medium type (`homogeneous`,
//! `grid`, `rgbgrid`, `cloud`), each with its creation; `create`,
//! creation from `MakeNamedMedium` and the parameter checks the media
//! share.

mod cloud;
mod create;
mod grid;
mod homogeneous;
mod majorant;
mod phase;
mod rgbgrid;
mod sampled_grid;
#[cfg(test)]
mod grid_tests;
#[cfg(test)]
mod tests;

pub use cloud::{CloudMedium, CloudMediumParts};
pub use create::{create_medium, MAX_GRID_SAMPLES, MEDIUM_NAMES};
pub use grid::{GridMedium, GridMediumParts, GRID_MAJORANT_RES};
pub use homogeneous::HomogeneousMedium;
pub use rgbgrid::{RgbEmissionGrid, RgbGridMedium, RgbGridMediumParts, RGB_GRID_MAJORANT_RES};
pub use sampled_grid::{GridValue, Interpolant, SampledGrid};
pub use majorant::{DdaMajorantIterator, HomogeneousMajorantIterator, MajorantGrid, RayMajorantSegment};
pub use phase::{henyey_greenstein, sample_henyey_greenstein, HGPhaseFunction, PhaseFunctionSample};

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
    fn sample_ray<'a>(&'a self, ray: &Ray, t_max: Float, lambda: &SampledWavelengths)
        -> Self::Majorants<'a>;
}

/// The closed set of participating media (pbrt-v4 `Medium`). The grid
/// media are boxed to keep the enum small.
#[derive(Clone, Debug)]
pub enum Medium {
    /// `homogeneous`.
    Homogeneous(HomogeneousMedium),
    /// `uniformgrid` (and pbrt-v3's `heterogeneous`).
    UniformGrid(Box<GridMedium>),
    /// `rgbgrid`.
    RgbGrid(Box<RgbGridMedium>),
    /// `cloud`.
    Cloud(Box<CloudMedium>),
}

impl Medium {
    /// Whether the medium emits light anywhere.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        match self {
            Medium::Homogeneous(m) => m.is_emissive(),
            Medium::UniformGrid(m) => m.is_emissive(),
            Medium::RgbGrid(m) => m.is_emissive(),
            Medium::Cloud(_) => false,
        }
    }

    /// The medium's properties at a rendering-space point.
    #[inline]
    pub fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        match self {
            Medium::Homogeneous(m) => m.sample_point(p, lambda),
            Medium::UniformGrid(m) => m.sample_point(p, lambda),
            Medium::RgbGrid(m) => m.sample_point(p, lambda),
            Medium::Cloud(m) => m.sample_point(p, lambda),
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
            Medium::UniformGrid(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::RgbGrid(m) => m.sample_ray(&ray, t_max, lambda).collect(),
            Medium::Cloud(m) => m.sample_ray(&ray, t_max, lambda).collect(),
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
        Medium::UniformGrid(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::RgbGrid(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
        Medium::Cloud(m) => sample_t_maj_in(&**m, ray, t_max, u, rng, lambda, callback),
    }
}

/// [`sample_t_maj`] for one medium type.
#[inline(always)]
fn sample_t_maj_in<M: ConcreteMedium>(
    medium: &M,
    ray: &Ray,
    t_max: Float,
    mut u: Float,
    rng: &mut Rng,
    lambda: &SampledWavelengths,
    mut callback: impl FnMut(Point3f, &MediumProperties, SampledSpectrum, SampledSpectrum, &mut Rng) -> bool,
) -> SampledSpectrum {
    let (ray, t_max) = normalized(ray, t_max);
    let mut t_maj = SampledSpectrum::new(1.0);
    for seg in medium.sample_ray(&ray, t_max, lambda) {
        if seg.sigma_maj[0] == 0.0 {
            // Nothing to collide with: the majorant transmittance of the
            // whole segment (unbounded segments kept finite).
            let dt = finite(seg.t_max - seg.t_min);
            t_maj *= (-dt * seg.sigma_maj).exp();
            continue;
        }
        let mut t_min = seg.t_min;
        loop {
            let t = t_min + sample_exponential(u, seg.sigma_maj[0]);
            u = rng.uniform_float();
            if t < seg.t_max {
                t_maj *= (-(t - t_min) * seg.sigma_maj).exp();
                let p = ray.at(t);
                let mp = medium.sample_point(p, lambda);
                if !callback(p, &mp, seg.sigma_maj, t_maj, rng) {
                    return SampledSpectrum::new(1.0);
                }
                t_maj = SampledSpectrum::new(1.0);
                t_min = t;
            } else {
                let dt = finite(seg.t_max - t_min);
                t_maj *= (-dt * seg.sigma_maj).exp();
                break;
            }
        }
    }
    t_maj
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
