//! Textures (book chapter 10; pbrt-v4 `textures.h/.cpp`, `base/texture.h`):
//! functions over surface points that materials and lights read, with the
//! screen-space footprint for filtering.
//!
//! [`FloatTexture`] and [`SpectrumTexture`] are closed enums; each method is
//! a one-line delegation. Textures are shared with `Arc`, so named textures
//! are built once and referenced by every material that uses them.

use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::tuple::*;
use std::sync::Arc;

/// What a texture sees of the point being shaded (pbrt-v4
/// `TextureEvalContext`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureEvalContext {
    /// The point, in rendering space.
    pub p: Point3f,
    /// Change of p per pixel in x.
    pub dpdx: Vector3f,
    /// Change of p per pixel in y.
    pub dpdy: Vector3f,
    /// Surface normal.
    pub n: Normal3f,
    /// Surface (u, v).
    pub uv: Point2f,
    /// ∂u/∂x.
    pub dudx: Float,
    /// ∂u/∂y.
    pub dudy: Float,
    /// ∂v/∂x.
    pub dvdx: Float,
    /// ∂v/∂y.
    pub dvdy: Float,
    /// Face index (ptex).
    pub face_index: i32,
}

impl TextureEvalContext {
    /// The context of a surface interaction (after its differentials were
    /// computed).
    pub fn from_si(si: &SurfaceInteraction) -> Self {
        TextureEvalContext {
            p: si.p(),
            dpdx: si.dpdx,
            dpdy: si.dpdy,
            n: si.n,
            uv: si.uv,
            dudx: si.dudx,
            dudy: si.dudy,
            dvdx: si.dvdx,
            dvdy: si.dvdy,
            face_index: si.face_index,
        }
    }
}

/// A texture returning a float.
#[derive(Clone, Debug)]
pub enum FloatTexture {
    /// A constant value.
    Constant(Float),
}

impl FloatTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        match self {
            FloatTexture::Constant(v) => {
                let _ = ctx;
                *v
            }
        }
    }
}

/// A texture returning a spectrum.
#[derive(Clone, Debug)]
pub enum SpectrumTexture {
    /// A constant spectrum.
    Constant(Spectrum),
}

impl SpectrumTexture {
    /// The value at a point for the sampled wavelengths.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            SpectrumTexture::Constant(s) => {
                let _ = ctx;
                s.sample(lambda)
            }
        }
    }
}

/// A shared float texture.
pub type FloatTextureRef = Arc<FloatTexture>;
/// A shared spectrum texture.
pub type SpectrumTextureRef = Arc<SpectrumTexture>;
