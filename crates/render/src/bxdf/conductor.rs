//! Conductors (pbrt-v4 book sections 9.4 and 9.6.3; pbrt-v4 `bxdfs.h`):
//! perfect specular reflection when the microfacet distribution is
//! effectively smooth, Torrance–Sparrow reflection otherwise, both with the
//! complex Fresnel equations.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use super::lanes::{self, gather_f, gather_s, ConductorLanes, ToLanes, TrLanes, S4};
use super::microfacet::TrowbridgeReitzDistribution;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::simd::{F32Lanes, Scalar1};
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
}

impl ToLanes for ConductorBxDF {
    type Lanes<L: F32Lanes> = ConductorLanes<L>;
    #[inline(always)]
    fn gather<L: F32Lanes>(items: &[&Self]) -> ConductorLanes<L> {
        let n = items.len();
        ConductorLanes {
            d: TrLanes {
                ax: gather_f(n, |i| items[i].mf_distrib.alpha_x()),
                ay: gather_f(n, |i| items[i].mf_distrib.alpha_y()),
            },
            eta: gather_s(n, |i| items[i].eta),
            k: gather_s(n, |i| items[i].k),
        }
    }
    #[inline(always)]
    fn one(&self) -> ConductorLanes<Scalar1> {
        ConductorLanes {
            d: TrLanes {
                ax: Scalar1(self.mf_distrib.alpha_x()),
                ay: Scalar1(self.mf_distrib.alpha_y()),
            },
            eta: S4(self.eta.values.map(Scalar1)),
            k: S4(self.k.values.map(Scalar1)),
        }
    }
}

impl BxDFMethods for ConductorBxDF {
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
