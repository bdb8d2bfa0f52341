//! Conductors (pbrt-v4 book sections 9.4 and 9.6.3; pbrt-v4 `bxdfs.h`):
//! perfect specular reflection when the microfacet distribution is
//! effectively smooth, Torrance–Sparrow reflection otherwise, both with the
//! complex Fresnel equations.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, same_hemisphere};

use super::microfacet::TrowbridgeReitzDistribution;
use super::scattering::{fr_complex_spectrum, reflect};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::SampledSpectrum;

/// A smooth or rough metal with complex index `eta + i k` per wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorBxDF {
    mf_distrib: TrowbridgeReitzDistribution,
    eta: SampledSpectrum,
    k: SampledSpectrum,
}

impl ConductorBxDF {
    /// A conductor with microfacet distribution `mf_distrib`.
    pub fn new(
        mf_distrib: TrowbridgeReitzDistribution,
        eta: SampledSpectrum,
        k: SampledSpectrum,
    ) -> Self {
        ConductorBxDF { mf_distrib, eta, k }
    }

    /// The microfacet distribution.
    pub fn distribution(&self) -> &TrowbridgeReitzDistribution {
        &self.mf_distrib
    }

    /// Torrance–Sparrow value for a reflected pair with half vector `wm`.
    #[inline]
    fn torrance_sparrow(&self, wo: Vector3f, wi: Vector3f, wm: Vector3f) -> SampledSpectrum {
        let f = fr_complex_spectrum(abs_dot(wo, wm), self.eta, self.k);
        f * (self.mf_distrib.d(wm) * self.mf_distrib.g(wo, wi)
            / (4.0 * abs_cos_theta(wi) * abs_cos_theta(wo)))
    }
}

impl BxDFMethods for ConductorBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) || self.mf_distrib.effectively_smooth() {
            return SampledSpectrum::new(0.0);
        }
        if abs_cos_theta(wi) == 0.0 || abs_cos_theta(wo) == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        let wm = wi + wo;
        if wm.length_squared() == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        self.torrance_sparrow(wo, wi, wm.normalize())
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
        if self.mf_distrib.effectively_smooth() {
            let wi = Vector3f::new(-wo.x, -wo.y, wo.z);
            let c = abs_cos_theta(wi);
            let f = fr_complex_spectrum(c, self.eta, self.k) / c;
            return Some(BSDFSample::new(f, wi, 1.0, BxDFFlags::SPECULAR_REFLECTION));
        }
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.mf_distrib.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let pdf = self.mf_distrib.pdf(wo, wm) / (4.0 * abs_dot(wo, wm));
        if abs_cos_theta(wi) == 0.0 || abs_cos_theta(wo) == 0.0 {
            return None;
        }
        let f = self.torrance_sparrow(wo, wi, wm);
        Some(BSDFSample::new(f, wi, pdf, BxDFFlags::GLOSSY_REFLECTION))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION)
            || !same_hemisphere(wo, wi)
            || self.mf_distrib.effectively_smooth()
        {
            return 0.0;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize().face_forward(Vector3f::new(0.0, 0.0, 1.0));
        self.mf_distrib.pdf(wo, wm) / (4.0 * abs_dot(wo, wm))
    }

    fn flags(&self) -> BxDFFlags {
        if self.mf_distrib.effectively_smooth() {
            BxDFFlags::SPECULAR_REFLECTION
        } else {
            BxDFFlags::GLOSSY_REFLECTION
        }
    }

    fn regularize(&mut self) {
        self.mf_distrib.regularize();
    }
}
