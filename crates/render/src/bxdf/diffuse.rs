//! Lambertian models (pbrt-v4 book sections 9.2 and 14.3.3; pbrt-v4
//! `bxdfs.h`): diffuse reflection, diffuse reflection plus transmission,
//! and the normalized Fresnel lobe used where subsurface light exits.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta, same_hemisphere};

use super::lanes::{gather_s, DiffuseLanes, ToLanes, S4};
use super::scattering::{fr_dielectric, fresnel_moment1};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::simd::{F32Lanes, Scalar1};
use crate::spectrum::SampledSpectrum;

/// Cosine-weighted direction in the hemisphere of `wo`.
#[inline]
fn cosine_in_hemisphere_of(wo: Vector3f, u: Point2f) -> Vector3f {
    let mut wi = sample_cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    wi
}

/// Lambertian reflection with reflectance `R`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseBxDF {
    r: SampledSpectrum,
}

impl DiffuseBxDF {
    /// A Lambertian reflector with reflectance `r`.
    pub fn new(r: SampledSpectrum) -> Self {
        DiffuseBxDF { r }
    }
}

// The scalar methods stay plain scalar code: the wavefront does not batch
// this model on its own (its few operations cost less than gathering
// them into lanes), only as the base of `coateddiffuse`, whose walk runs
// the lane form below at every width.
impl ToLanes for DiffuseBxDF {
    type Lanes<L: F32Lanes> = DiffuseLanes<L>;
    #[inline(always)]
    fn gather<L: F32Lanes>(items: &[&Self]) -> DiffuseLanes<L> {
        DiffuseLanes {
            r: gather_s(items.len(), |i| items[i].r),
        }
    }
    #[inline(always)]
    fn one(&self) -> DiffuseLanes<Scalar1> {
        DiffuseLanes {
            r: S4(self.r.values.map(Scalar1)),
        }
    }
}

impl BxDFMethods for DiffuseBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        self.r * INV_PI
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        _uc: Float,
        u: Point2f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
            return None;
        }
        let wi = cosine_in_hemisphere_of(wo, u);
        let pdf = cosine_hemisphere_pdf(abs_cos_theta(wi));
        Some(BSDFSample::new(
            self.r * INV_PI,
            wi,
            pdf,
            BxDFFlags::DIFFUSE_REFLECTION,
        ))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        cosine_hemisphere_pdf(abs_cos_theta(wi))
    }

    fn flags(&self) -> BxDFFlags {
        if self.r.is_black() {
            BxDFFlags::UNSET
        } else {
            BxDFFlags::DIFFUSE_REFLECTION
        }
    }

    fn regularize(&mut self) {}
}

/// Lambertian reflection `R` and Lambertian transmission `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseTransmissionBxDF {
    r: SampledSpectrum,
    t: SampledSpectrum,
}

impl DiffuseTransmissionBxDF {
    /// A diffuse reflector-transmitter.
    pub fn new(r: SampledSpectrum, t: SampledSpectrum) -> Self {
        DiffuseTransmissionBxDF { r, t }
    }

    /// Probabilities of sampling reflection and transmission.
    #[inline]
    fn probabilities(&self, sample_flags: BxDFReflTransFlags) -> (Float, Float) {
        let mut pr = self.r.max_component_value();
        let mut pt = self.t.max_component_value();
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
            pr = 0.0;
        }
        if !sample_flags.contains(BxDFReflTransFlags::TRANSMISSION) {
            pt = 0.0;
        }
        (pr, pt)
    }
}

impl BxDFMethods for DiffuseTransmissionBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if same_hemisphere(wo, wi) {
            self.r * INV_PI
        } else {
            self.t * INV_PI
        }
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let (pr, pt) = self.probabilities(sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let mut wi = cosine_in_hemisphere_of(wo, u);
        if uc < pr / (pr + pt) {
            let pdf = cosine_hemisphere_pdf(abs_cos_theta(wi)) * pr / (pr + pt);
            Some(BSDFSample::new(
                self.f(wo, wi, mode),
                wi,
                pdf,
                BxDFFlags::DIFFUSE_REFLECTION,
            ))
        } else {
            wi.z = -wi.z;
            let pdf = cosine_hemisphere_pdf(abs_cos_theta(wi)) * pt / (pr + pt);
            Some(BSDFSample::new(
                self.f(wo, wi, mode),
                wi,
                pdf,
                BxDFFlags::DIFFUSE_TRANSMISSION,
            ))
        }
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        let (pr, pt) = self.probabilities(sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        let p = if same_hemisphere(wo, wi) { pr } else { pt };
        p / (pr + pt) * cosine_hemisphere_pdf(abs_cos_theta(wi))
    }

    fn flags(&self) -> BxDFFlags {
        let mut f = BxDFFlags::UNSET;
        if !self.r.is_black() {
            f |= BxDFFlags::DIFFUSE_REFLECTION;
        }
        if !self.t.is_black() {
            f |= BxDFFlags::DIFFUSE_TRANSMISSION;
        }
        f
    }

    fn regularize(&mut self) {}
}

/// The diffuse lobe of light leaving a subsurface-scattering medium through
/// a dielectric boundary: (1 − Fr(cos θi)) / (c π), normalized by the first
/// Fresnel moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalizedFresnelBxDF {
    eta: Float,
}

impl NormalizedFresnelBxDF {
    /// The lobe for relative index `eta`.
    pub fn new(eta: Float) -> Self {
        NormalizedFresnelBxDF { eta }
    }
}

impl BxDFMethods for NormalizedFresnelBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        let c = 1.0 - 2.0 * fresnel_moment1(1.0 / self.eta);
        let mut f = (1.0 - fr_dielectric(cos_theta(wi), self.eta)) / (c * PI);
        // Adjoint transport does not carry the eta² radiance scaling.
        if mode == TransportMode::Radiance {
            f *= sqr(self.eta);
        }
        SampledSpectrum::new(f)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        _uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
            return None;
        }
        let wi = cosine_in_hemisphere_of(wo, u);
        Some(BSDFSample::new(
            self.f(wo, wi, mode),
            wi,
            self.pdf(wo, wi, mode, sample_flags),
            BxDFFlags::DIFFUSE_REFLECTION,
        ))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        abs_cos_theta(wi) * INV_PI
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::DIFFUSE_REFLECTION
    }

    fn regularize(&mut self) {}
}

/// A cosine-weighted direction on `wo`'s side, with `f` toward it: pbrt's
/// default `BxDF::Sample_f` (up to pbrt-v3), which the old measured
/// models keep.
pub(crate) fn sample_cosine_reflection(
    wo: Vector3f,
    u: Point2f,
    sample_flags: BxDFReflTransFlags,
    flags: BxDFFlags,
    f: impl Fn(Vector3f) -> SampledSpectrum,
) -> Option<BSDFSample> {
    if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
        return None;
    }
    let mut wi = sample_cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    let pdf = cosine_hemisphere_pdf(abs_cos_theta(wi));
    if pdf == 0.0 {
        return None;
    }
    Some(BSDFSample::new(f(wi), wi, pdf, flags))
}

/// The density of [`sample_cosine_reflection`].
pub(crate) fn cosine_reflection_pdf(
    wo: Vector3f,
    wi: Vector3f,
    sample_flags: BxDFReflTransFlags,
) -> Float {
    if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) || !same_hemisphere(wo, wi) {
        return 0.0;
    }
    cosine_hemisphere_pdf(abs_cos_theta(wi))
}
