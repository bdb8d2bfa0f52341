//! Dielectric interfaces (pbrt-v4 book sections 9.5 and 9.7; pbrt-v4
//! `bxdfs.h`, `bxdfs.cpp`): specular or rough (generalized half vector)
//! reflection and transmission, with radiance scaled by 1/η² on
//! transmission, and the thin dielectric slab with its interreflections.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta};

use super::lanes::{self, gather_f, DielectricLanes, ToLanes, TrLanes};
use super::microfacet::TrowbridgeReitzDistribution;
use super::scattering::fr_dielectric;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::simd::{F32Lanes, Scalar1};
use crate::spectrum::SampledSpectrum;

/// Probabilities of choosing reflection (`r`) or transmission (`t`) under
/// the sampling flags.
#[inline]
fn choice(r: Float, t: Float, sample_flags: BxDFReflTransFlags) -> (Float, Float) {
    let pr = if sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
        r
    } else {
        0.0
    };
    let pt = if sample_flags.contains(BxDFReflTransFlags::TRANSMISSION) {
        t
    } else {
        0.0
    };
    (pr, pt)
}

/// A dielectric boundary with relative index `eta` (inside over outside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricBxDF {
    eta: Float,
    mf_distrib: TrowbridgeReitzDistribution,
}

impl DielectricBxDF {
    /// A dielectric interface.
    pub fn new(eta: Float, mf_distrib: TrowbridgeReitzDistribution) -> Self {
        DielectricBxDF { eta, mf_distrib }
    }

    /// The relative index of refraction.
    pub fn eta(&self) -> Float {
        self.eta
    }
}

impl ToLanes for DielectricBxDF {
    type Lanes<L: F32Lanes> = DielectricLanes<L>;
    #[inline(always)]
    fn gather<L: F32Lanes>(items: &[&Self]) -> DielectricLanes<L> {
        let n = items.len();
        DielectricLanes {
            eta: gather_f(n, |i| items[i].eta),
            d: TrLanes {
                ax: gather_f(n, |i| items[i].mf_distrib.alpha_x()),
                ay: gather_f(n, |i| items[i].mf_distrib.alpha_y()),
            },
        }
    }
    #[inline(always)]
    fn one(&self) -> DielectricLanes<Scalar1> {
        DielectricLanes {
            eta: Scalar1(self.eta),
            d: TrLanes {
                ax: Scalar1(self.mf_distrib.alpha_x()),
                ay: Scalar1(self.mf_distrib.alpha_y()),
            },
        }
    }
}

impl BxDFMethods for DielectricBxDF {
    #[inline]
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        lanes::f1(&self.one(), wo, wi, mode)
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
        lanes::sample_f1(&self.one(), wo, uc, u, mode, sample_flags)
    }

    #[inline]
    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        lanes::pdf1(&self.one(), wo, wi, mode, sample_flags)
    }

    fn flags(&self) -> BxDFFlags {
        let lobes = if self.eta == 1.0 {
            BxDFFlags::TRANSMISSION
        } else {
            BxDFFlags::REFLECTION | BxDFFlags::TRANSMISSION
        };
        lobes
            | if self.mf_distrib.effectively_smooth() {
                BxDFFlags::SPECULAR
            } else {
                BxDFFlags::GLOSSY
            }
    }

    fn regularize(&mut self) {
        self.mf_distrib.regularize();
    }
}

/// A thin dielectric slab: specular reflection and straight-through
/// transmission, summing the light bounced between its two faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectricBxDF {
    eta: Float,
}

impl ThinDielectricBxDF {
    /// A slab of relative index `eta`.
    pub fn new(eta: Float) -> Self {
        ThinDielectricBxDF { eta }
    }

    /// Total reflectance and transmittance of the slab at `cos_theta`:
    /// R' = R + T²R / (1 − R²), T' = 1 − R'.
    pub fn reflectance_transmittance(&self, cos_theta: Float) -> (Float, Float) {
        let mut r = fr_dielectric(cos_theta.abs(), self.eta);
        let mut t = 1.0 - r;
        if r < 1.0 {
            r += sqr(t) * r / (1.0 - sqr(r));
            t = 1.0 - r;
        }
        (r, t)
    }
}

impl BxDFMethods for ThinDielectricBxDF {
    fn f(&self, _wo: Vector3f, _wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        SampledSpectrum::new(0.0)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        _u: Point2f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let (r, t) = self.reflectance_transmittance(cos_theta(wo));
        let (pr, pt) = choice(r, t, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        if uc < pr / (pr + pt) {
            let wi = Vector3f::new(-wo.x, -wo.y, wo.z);
            let f = SampledSpectrum::new(r / abs_cos_theta(wi));
            Some(BSDFSample::new(
                f,
                wi,
                pr / (pr + pt),
                BxDFFlags::SPECULAR_REFLECTION,
            ))
        } else {
            let wi = -wo;
            let f = SampledSpectrum::new(t / abs_cos_theta(wi));
            Some(BSDFSample::new(
                f,
                wi,
                pt / (pr + pt),
                BxDFFlags::SPECULAR_TRANSMISSION,
            ))
        }
    }

    fn pdf(
        &self,
        _wo: Vector3f,
        _wi: Vector3f,
        _mode: TransportMode,
        _sample_flags: BxDFReflTransFlags,
    ) -> Float {
        0.0
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::REFLECTION | BxDFFlags::TRANSMISSION | BxDFFlags::SPECULAR
    }

    /// pbrt-v4 leaves the thin dielectric unregularized.
    fn regularize(&mut self) {}
}
