//! Reflection models (pbrt-v4 book chapters 9, 10.1 and 14.3; pbrt-v4
//! `base/bxdf.h`, `bxdfs.h`, `bxdfs.cpp`, `bsdf.h`, `util/scattering.h`).
//!
//! Every BxDF works in the local shading frame, where z is the shading
//! normal; [`BSDF`] converts from and to rendering space. [`BxDF`] is the
//! closed set of models, each method a one-line delegation.

use std::ops::{BitAnd, BitOr, BitOrAssign, Not};

use rpbrt_geometry::abs_cos_theta;
use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use crate::sampling::{sample_uniform_hemisphere, UNIFORM_HEMISPHERE_PDF};
use crate::spectrum::SampledSpectrum;

mod bsdf;
mod conductor;
mod dielectric;
mod diffuse;
mod disney;
pub mod fourier;
mod hair;
mod irregular;
mod lafortune;
pub(crate) mod lanes;
mod layered;
pub mod measured;
mod merl;
mod microfacet;
mod scattering;
mod shinymetal;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_v3;

/// A per-process cache of data read from files (measured BRDFs, Fourier
/// tables), keyed by canonical path: each model's `cached` holds one as a
/// `static` and reads through [`cached_file`].
pub(crate) type FileCache<T> = std::sync::OnceLock<
    std::sync::Mutex<std::collections::HashMap<std::path::PathBuf, &'static T>>,
>;

/// The data of the file at `path` from `cache`, made by `load` on first
/// use and kept for the rest of the run. The data are leaked on purpose:
/// BxDFs are `Copy` and hold a plain reference (pbrt-v4 keeps such data in
/// the scene's allocator). Failed loads are not cached; two threads that
/// load the same file at once keep the first.
pub(crate) fn cached_file<T: Sync, E>(
    cache: &'static FileCache<T>,
    path: &std::path::Path,
    load: impl FnOnce(&std::path::Path) -> Result<T, E>,
) -> Result<&'static T, E> {
    let key = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    let map = cache.get_or_init(Default::default);
    if let Some(d) = map.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Ok(d);
    }
    let data: &'static T = Box::leak(Box::new(load(path)?));
    let mut m = map.lock().unwrap_or_else(|e| e.into_inner());
    Ok(*m.entry(key).or_insert(data))
}

pub use bsdf::BSDF;
pub use conductor::ConductorBxDF;
pub use dielectric::{DielectricBxDF, ThinDielectricBxDF};
pub use diffuse::{DiffuseBxDF, DiffuseTransmissionBxDF, NormalizedFresnelBxDF};
pub use disney::{DisneyBxDF, DisneyParams};
pub use fourier::{FourierBSDFTable, FourierBxDF, FourierError};
pub use hair::HairBxDF;
pub use irregular::{IrregularBrdf, IrregularBxDF};
pub use lafortune::{
    LafortuneBxDF, LafortuneFit, LafortuneLobe, LAFORTUNE_FITS, LAFORTUNE_MATERIALS,
};
pub use layered::{CoatedConductorBxDF, CoatedDiffuseBxDF, LayeredBxDF};
pub use measured::{MeasuredBxDF, MeasuredBxDFData};
pub use merl::{MerlBxDF, MerlTable};
pub use microfacet::TrowbridgeReitzDistribution;
pub use scattering::{
    fr_complex, fr_complex_spectrum, fr_dielectric, fresnel_moment1, fresnel_moment2,
    henyey_greenstein, reflect, refract, sample_henyey_greenstein, Complex,
};
pub use shinymetal::ShinyMetalBxDF;

/// Whether light (radiance) or importance is being transported; BxDFs that
/// refract scale differently in the two cases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Paths traced from the camera carry radiance.
    Radiance,
    /// Paths traced from lights carry importance.
    Importance,
}

impl Not for TransportMode {
    type Output = TransportMode;
    /// The adjoint mode.
    #[inline]
    fn not(self) -> TransportMode {
        match self {
            TransportMode::Radiance => TransportMode::Importance,
            TransportMode::Importance => TransportMode::Radiance,
        }
    }
}

/// Which hemispheres a sampling routine may choose from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BxDFReflTransFlags(u8);

impl BxDFReflTransFlags {
    /// Neither.
    pub const UNSET: Self = BxDFReflTransFlags(0);
    /// Reflection only.
    pub const REFLECTION: Self = BxDFReflTransFlags(1);
    /// Transmission only.
    pub const TRANSMISSION: Self = BxDFReflTransFlags(2);
    /// Both.
    pub const ALL: Self = BxDFReflTransFlags(3);

    /// True when every bit of `o` is set.
    #[inline]
    pub fn contains(self, o: Self) -> bool {
        self.0 & o.0 == o.0
    }
    /// The raw bits.
    #[inline]
    pub fn bits(self) -> u8 {
        self.0
    }
}

impl BitOr for BxDFReflTransFlags {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        BxDFReflTransFlags(self.0 | o.0)
    }
}

/// The kinds of scattering a BxDF (or one sample of it) represents.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BxDFFlags(u8);

impl BxDFFlags {
    /// No scattering.
    pub const UNSET: Self = BxDFFlags(0);
    /// Scatters into the hemisphere of ωo.
    pub const REFLECTION: Self = BxDFFlags(1);
    /// Scatters into the opposite hemisphere.
    pub const TRANSMISSION: Self = BxDFFlags(2);
    /// A smooth, wide lobe.
    pub const DIFFUSE: Self = BxDFFlags(4);
    /// A concentrated but non-delta lobe.
    pub const GLOSSY: Self = BxDFFlags(8);
    /// A Dirac delta lobe.
    pub const SPECULAR: Self = BxDFFlags(16);
    /// Diffuse reflection.
    pub const DIFFUSE_REFLECTION: Self = BxDFFlags(1 | 4);
    /// Diffuse transmission.
    pub const DIFFUSE_TRANSMISSION: Self = BxDFFlags(2 | 4);
    /// Glossy reflection.
    pub const GLOSSY_REFLECTION: Self = BxDFFlags(1 | 8);
    /// Glossy transmission.
    pub const GLOSSY_TRANSMISSION: Self = BxDFFlags(2 | 8);
    /// Specular reflection.
    pub const SPECULAR_REFLECTION: Self = BxDFFlags(1 | 16);
    /// Specular transmission.
    pub const SPECULAR_TRANSMISSION: Self = BxDFFlags(2 | 16);
    /// Everything.
    pub const ALL: Self = BxDFFlags(31);

    /// The raw bits.
    #[inline]
    pub fn bits(self) -> u8 {
        self.0
    }
    /// True when no bit is set.
    #[inline]
    pub fn is_unset(self) -> bool {
        self.0 == 0
    }
    /// True when any bit of `o` is set.
    #[inline]
    pub fn intersects(self, o: Self) -> bool {
        self.0 & o.0 != 0
    }
    /// Has a reflection component.
    #[inline]
    pub fn is_reflective(self) -> bool {
        self.intersects(Self::REFLECTION)
    }
    /// Has a transmission component.
    #[inline]
    pub fn is_transmissive(self) -> bool {
        self.intersects(Self::TRANSMISSION)
    }
    /// Has a diffuse component.
    #[inline]
    pub fn is_diffuse(self) -> bool {
        self.intersects(Self::DIFFUSE)
    }
    /// Has a glossy component.
    #[inline]
    pub fn is_glossy(self) -> bool {
        self.intersects(Self::GLOSSY)
    }
    /// Has a specular component.
    #[inline]
    pub fn is_specular(self) -> bool {
        self.intersects(Self::SPECULAR)
    }
    /// Has a diffuse or glossy component.
    #[inline]
    pub fn is_non_specular(self) -> bool {
        self.intersects(BxDFFlags(4 | 8))
    }
    /// True when the flags share a hemisphere with the sampling flags
    /// (pbrt-v4's `bxdf.Flags() & sampleFlags`).
    #[inline]
    pub fn allows(self, s: BxDFReflTransFlags) -> bool {
        self.0 & s.bits() != 0
    }
}

impl BitOr for BxDFFlags {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        BxDFFlags(self.0 | o.0)
    }
}

impl BitOrAssign for BxDFFlags {
    #[inline]
    fn bitor_assign(&mut self, o: Self) {
        self.0 |= o.0;
    }
}

impl BitAnd for BxDFFlags {
    type Output = Self;
    #[inline]
    fn bitand(self, o: Self) -> Self {
        BxDFFlags(self.0 & o.0)
    }
}

/// One sample of a BSDF: value, direction, density and what was sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BSDFSample {
    /// The BSDF value f(ωo, ωi).
    pub f: SampledSpectrum,
    /// The sampled incident direction.
    pub wi: Vector3f,
    /// Its density (a discrete probability for specular samples).
    pub pdf: Float,
    /// What kind of scattering was sampled.
    pub flags: BxDFFlags,
    /// The relative index of refraction crossed (1 for reflection).
    pub eta: Float,
    /// True when `pdf` is only proportional to the true density (layered
    /// BxDFs), so MIS must use `BxDF::pdf` instead.
    pub pdf_is_proportional: bool,
}

impl BSDFSample {
    /// A sample with relative index 1 and an exact density.
    #[inline]
    pub fn new(f: SampledSpectrum, wi: Vector3f, pdf: Float, flags: BxDFFlags) -> Self {
        BSDFSample {
            f,
            wi,
            pdf,
            flags,
            eta: 1.0,
            pdf_is_proportional: false,
        }
    }
    /// A sample that crossed a relative index `eta`.
    #[inline]
    pub fn with_eta(
        f: SampledSpectrum,
        wi: Vector3f,
        pdf: Float,
        flags: BxDFFlags,
        eta: Float,
    ) -> Self {
        BSDFSample {
            eta,
            ..BSDFSample::new(f, wi, pdf, flags)
        }
    }
    /// Reflection was sampled.
    #[inline]
    pub fn is_reflection(&self) -> bool {
        self.flags.is_reflective()
    }
    /// Transmission was sampled.
    #[inline]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmissive()
    }
    /// A specular lobe was sampled.
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }
}

/// The operations every reflection model provides, in the local shading
/// frame. [`BxDF`] dispatches to them; [`LayeredBxDF`] is generic over them.
pub trait BxDFMethods {
    /// The BSDF value for the pair of directions.
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum;
    /// Samples an incident direction given `uc` (lobe choice) and `u`.
    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample>;
    /// The density with which `sample_f` returns `wi`.
    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float;
    /// The kinds of scattering present.
    fn flags(&self) -> BxDFFlags;
    /// Widens near-specular lobes to reduce variance (path regularization).
    fn regularize(&mut self);
}

/// The closed set of reflection models.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BxDF {
    /// Lambertian reflection.
    Diffuse(DiffuseBxDF),
    /// Lambertian reflection and transmission.
    DiffuseTransmission(DiffuseTransmissionBxDF),
    /// Smooth or rough conductor.
    Conductor(ConductorBxDF),
    /// Smooth or rough dielectric interface.
    Dielectric(DielectricBxDF),
    /// A thin dielectric slab.
    ThinDielectric(ThinDielectricBxDF),
    /// Dielectric coating over a diffuse base.
    CoatedDiffuse(CoatedDiffuseBxDF),
    /// Dielectric coating over a conductor.
    CoatedConductor(CoatedConductorBxDF),
    /// Chiang et al.'s hair scattering model.
    Hair(HairBxDF),
    /// The normalized Fresnel lobe at subsurface exits.
    NormalizedFresnel(NormalizedFresnelBxDF),
    /// Tabulated measured reflectance (RGL `.bsdf` data).
    Measured(MeasuredBxDF),
    /// pbrt-v3's Disney BSDF.
    Disney(DisneyBxDF),
    /// pbrt-v3's tabulated Fourier BSDF.
    Fourier(FourierBxDF),
    /// pbrt-v1/v2's `shinymetal`.
    ShinyMetal(ShinyMetalBxDF),
    /// pbrt-v1's measured Lafortune fits.
    Lafortune(LafortuneBxDF),
    /// pbrt-v2's MERL tables.
    Merl(MerlBxDF),
    /// pbrt-v2's irregular `.brdf` measurements.
    Irregular(IrregularBxDF),
}

macro_rules! dispatch {
    ($self:expr, $b:ident => $e:expr) => {
        match $self {
            BxDF::Diffuse($b) => $e,
            BxDF::DiffuseTransmission($b) => $e,
            BxDF::Conductor($b) => $e,
            BxDF::Dielectric($b) => $e,
            BxDF::ThinDielectric($b) => $e,
            BxDF::CoatedDiffuse($b) => $e,
            BxDF::CoatedConductor($b) => $e,
            BxDF::Hair($b) => $e,
            BxDF::NormalizedFresnel($b) => $e,
            BxDF::Measured($b) => $e,
            BxDF::Disney($b) => $e,
            BxDF::Fourier($b) => $e,
            BxDF::ShinyMetal($b) => $e,
            BxDF::Lafortune($b) => $e,
            BxDF::Merl($b) => $e,
            BxDF::Irregular($b) => $e,
        }
    };
}

impl BxDFMethods for BxDF {
    #[inline]
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        dispatch!(self, b => b.f(wo, wi, mode))
    }
    #[inline]
    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        dispatch!(self, b => b.sample_f(wo, uc, u, mode, sample_flags))
    }
    #[inline]
    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        dispatch!(self, b => b.pdf(wo, wi, mode, sample_flags))
    }
    #[inline(always)]
    fn flags(&self) -> BxDFFlags {
        dispatch!(self, b => b.flags())
    }
    #[inline]
    fn regularize(&mut self) {
        dispatch!(self, b => b.regularize())
    }
}

impl BxDF {
    /// True when `f` is zero for every pair of directions on opposite
    /// sides of the shading plane: the models whose `f` starts with the
    /// same-hemisphere test (light culling relies on it).
    #[inline]
    pub fn zero_across_hemispheres(&self) -> bool {
        matches!(self, BxDF::Diffuse(_) | BxDF::Conductor(_))
    }

    /// The model's name, as pbrt-v4 prints it.
    pub fn name(&self) -> &'static str {
        match self {
            BxDF::Diffuse(_) => "DiffuseBxDF",
            BxDF::DiffuseTransmission(_) => "DiffuseTransmissionBxDF",
            BxDF::Conductor(_) => "ConductorBxDF",
            BxDF::Dielectric(_) => "DielectricBxDF",
            BxDF::ThinDielectric(_) => "ThinDielectricBxDF",
            BxDF::CoatedDiffuse(_) => "CoatedDiffuseBxDF",
            BxDF::CoatedConductor(_) => "CoatedConductorBxDF",
            BxDF::Hair(_) => "HairBxDF",
            BxDF::NormalizedFresnel(_) => "NormalizedFresnelBxDF",
            BxDF::Measured(_) => "MeasuredBxDF",
            BxDF::Disney(_) => "DisneyBxDF",
            BxDF::Fourier(_) => "FourierBSDF",
            BxDF::ShinyMetal(_) => "ShinyMetalBSDF",
            BxDF::Lafortune(_) => "LafortuneBSDF",
            BxDF::Merl(_) => "RegularHalfangleBRDF",
            BxDF::Irregular(_) => "IrregIsotropicBRDF",
        }
    }

    /// Hemispherical-directional reflectance ρ(ωo) estimated with the
    /// given samples (`uc[i]`, `u2[i]` pairs) of `sample_f` in radiance mode.
    pub fn rho_hd(&self, wo: Vector3f, uc: &[Float], u2: &[Point2f]) -> SampledSpectrum {
        rho_hd(self, wo, uc, u2)
    }

    /// Hemispherical-hemispherical reflectance ρ estimated with uniformly
    /// sampled outgoing directions `u1[i]` and `sample_f` samples.
    pub fn rho_hh(&self, u1: &[Point2f], uc: &[Float], u2: &[Point2f]) -> SampledSpectrum {
        rho_hh(self, u1, uc, u2)
    }
}

/// Monte Carlo hemispherical-directional reflectance of any model (pbrt-v4
/// `BxDF::rho(wo, uc, u2)`): the mean of f |cos θi| / pdf over samples.
pub fn rho_hd<B: BxDFMethods + ?Sized>(
    bxdf: &B,
    wo: Vector3f,
    uc: &[Float],
    u2: &[Point2f],
) -> SampledSpectrum {
    debug_assert_eq!(uc.len(), u2.len());
    if wo.z == 0.0 || uc.is_empty() {
        return SampledSpectrum::new(0.0);
    }
    let mut r = SampledSpectrum::new(0.0);
    for (&c, &u) in uc.iter().zip(u2) {
        if let Some(bs) = bxdf.sample_f(wo, c, u, TransportMode::Radiance, BxDFReflTransFlags::ALL)
        {
            if bs.pdf > 0.0 {
                r += bs.f * abs_cos_theta(bs.wi) / bs.pdf;
            }
        }
    }
    r / uc.len() as Float
}

/// Monte Carlo hemispherical-hemispherical reflectance of any model
/// (pbrt-v4 `BxDF::rho(u1, uc, u2)`).
pub fn rho_hh<B: BxDFMethods + ?Sized>(
    bxdf: &B,
    u1: &[Point2f],
    uc: &[Float],
    u2: &[Point2f],
) -> SampledSpectrum {
    debug_assert!(u1.len() == uc.len() && uc.len() == u2.len());
    if uc.is_empty() {
        return SampledSpectrum::new(0.0);
    }
    let mut r = SampledSpectrum::new(0.0);
    for i in 0..uc.len() {
        let wo = sample_uniform_hemisphere(u1[i]);
        if wo.z == 0.0 {
            continue;
        }
        if let Some(bs) = bxdf.sample_f(
            wo,
            uc[i],
            u2[i],
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        ) {
            if bs.pdf > 0.0 {
                r += bs.f * (abs_cos_theta(bs.wi) * abs_cos_theta(wo))
                    / (UNIFORM_HEMISPHERE_PDF * bs.pdf);
            }
        }
    }
    r / (PI * uc.len() as Float)
}
