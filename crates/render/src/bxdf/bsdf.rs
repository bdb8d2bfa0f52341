//! The BSDF: a BxDF placed in the shading frame of a surface point (pbrt-v4
//! book section 9.1.5; pbrt-v4 `bsdf.h`).

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Frame;

use super::{
    rho_hd, rho_hh, BSDFSample, BxDF, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode,
};
use crate::spectrum::SampledSpectrum;

/// A BxDF with the local frame it lives in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BSDF {
    /// The reflection model, in local coordinates.
    pub bxdf: BxDF,
    /// x = normalized shading ∂p/∂u, z = shading normal.
    pub shading_frame: Frame,
}

impl BSDF {
    /// A BSDF at a point with shading normal `ns` and shading ∂p/∂u `dpdus`
    /// (expected perpendicular to `ns`, as shapes and normal/bump mapping
    /// provide it).
    pub fn new(ns: Normal3f, dpdus: Vector3f, bxdf: BxDF) -> Self {
        BSDF {
            bxdf,
            shading_frame: Frame::from_xz(dpdus.normalize(), Vector3f::from(ns)),
        }
    }

    /// The kinds of scattering present.
    #[inline]
    pub fn flags(&self) -> BxDFFlags {
        self.bxdf.flags()
    }

    /// A rendering-space direction in the local shading frame.
    #[inline]
    pub fn render_to_local(&self, v: Vector3f) -> Vector3f {
        self.shading_frame.to_local(v)
    }

    /// A local direction in rendering space.
    #[inline]
    pub fn local_to_render(&self, v: Vector3f) -> Vector3f {
        self.shading_frame.from_local(v)
    }

    /// The BSDF value for rendering-space directions.
    #[inline]
    pub fn f(
        &self,
        wo_render: Vector3f,
        wi_render: Vector3f,
        mode: TransportMode,
    ) -> SampledSpectrum {
        let wi = self.render_to_local(wi_render);
        let wo = self.render_to_local(wo_render);
        if wo.z == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        self.bxdf.f(wo, wi, mode)
    }

    /// Samples an incident direction (in rendering space). Samples with zero
    /// value or density, or tangent to the surface, are rejected.
    #[inline]
    pub fn sample_f(
        &self,
        wo_render: Vector3f,
        u: Float,
        u2: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let wo = self.render_to_local(wo_render);
        if wo.z == 0.0 || !self.bxdf.flags().allows(sample_flags) {
            return None;
        }
        let mut bs = self.bxdf.sample_f(wo, u, u2, mode, sample_flags)?;
        if bs.f.is_black() || bs.pdf == 0.0 || bs.wi.z == 0.0 {
            return None;
        }
        debug_assert!(bs.pdf >= 0.0);
        bs.wi = self.local_to_render(bs.wi);
        Some(bs)
    }

    /// The density of sampling `wi_render` (rendering space).
    #[inline]
    pub fn pdf(
        &self,
        wo_render: Vector3f,
        wi_render: Vector3f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        let wo = self.render_to_local(wo_render);
        let wi = self.render_to_local(wi_render);
        if wo.z == 0.0 {
            return 0.0;
        }
        self.bxdf.pdf(wo, wi, mode, sample_flags)
    }

    /// Hemispherical-directional reflectance for rendering-space `wo`.
    pub fn rho_hd(&self, wo_render: Vector3f, uc: &[Float], u2: &[Point2f]) -> SampledSpectrum {
        rho_hd(&self.bxdf, self.render_to_local(wo_render), uc, u2)
    }

    /// Hemispherical-hemispherical reflectance.
    pub fn rho_hh(&self, u1: &[Point2f], uc: &[Float], u2: &[Point2f]) -> SampledSpectrum {
        rho_hh(&self.bxdf, u1, uc, u2)
    }

    /// Widens near-specular lobes (path regularization).
    #[inline]
    pub fn regularize(&mut self) {
        self.bxdf.regularize();
    }
}
