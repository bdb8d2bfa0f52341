//! Textures (book chapter 10; pbrt-v4 `textures.h/.cpp`, `base/texture.h`):
//! functions over surface points that materials and lights read, with the
//! screen-space footprint for filtering.
//!
//! [`FloatTexture`] and [`SpectrumTexture`] are closed enums; each method is
//! a one-line delegation. Textures are shared with `Arc`, so named textures
//! are built once and referenced by every material that uses them.
//!
//! Submodules: [`mapping`] (texture coordinates, 10.2), [`noise`] (Perlin
//! noise, FBm, turbulence, 10.6), [`procedural`] (the basic and procedural
//! textures, 10.3 and 10.5), [`imagemap`] (10.4), [`ptex`] (per-face Ptex
//! textures, with our own Ptex reader), [`create`] (textures from their
//! directives' parameters) and [`params`] (texture-or-value parameter
//! lookups for materials, lights and textures).

pub mod create;
pub mod imagemap;
pub mod mapping;
pub mod noise;
pub mod params;
pub mod procedural;
pub mod ptex;
#[cfg(test)]
mod tests;

pub use create::{
    create_float_texture, create_spectrum_texture, ImageRequest, NamedTextures, TextureDef,
    TextureOptions, FLOAT_TEXTURE_NAMES, SPECTRUM_TEXTURE_NAMES, TEXTURE_NAMES,
};
pub use imagemap::{FloatImageTexture, ImageTextureBase, SpectrumImageTexture};
pub use mapping::{TexCoord2D, TexCoord3D, TextureMapping2D, TextureMapping3D};
pub use params::TextureParams;
pub use procedural::*;
pub use ptex::{FloatPtexTexture, PtexTextureBase, SpectrumPtexTexture};

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
    /// `tex * scale`.
    Scaled(FloatScaledTexture),
    /// A blend of two textures by a third.
    Mix(FloatMixTexture),
    /// A blend of two textures by the normal's alignment with a direction.
    DirectionMix(FloatDirectionMixTexture),
    /// Bilinear interpolation of four values.
    Bilerp(FloatBilerpTexture),
    /// Checks of two textures, 2-D or 3-D.
    Checkerboard(FloatCheckerboardTexture),
    /// Random polka dots.
    Dots(FloatDotsTexture),
    /// Fractional Brownian motion.
    FBm(FBmTexture),
    /// Turbulence.
    Wrinkled(WrinkledTexture),
    /// Wind-blown waves.
    Windy(WindyTexture),
    /// An image.
    Image(FloatImageTexture),
    /// A Ptex file.
    Ptex(FloatPtexTexture),
}

impl FloatTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        match self {
            FloatTexture::Constant(v) => *v,
            FloatTexture::Scaled(t) => t.evaluate(ctx),
            FloatTexture::Mix(t) => t.evaluate(ctx),
            FloatTexture::DirectionMix(t) => t.evaluate(ctx),
            FloatTexture::Bilerp(t) => t.evaluate(ctx),
            FloatTexture::Checkerboard(t) => t.evaluate(ctx),
            FloatTexture::Dots(t) => t.evaluate(ctx),
            FloatTexture::FBm(t) => t.evaluate(ctx),
            FloatTexture::Wrinkled(t) => t.evaluate(ctx),
            FloatTexture::Windy(t) => t.evaluate(ctx),
            FloatTexture::Image(t) => t.evaluate(ctx),
            FloatTexture::Ptex(t) => t.evaluate(ctx),
        }
    }

    /// Starts loading the image texels that [`FloatTexture::evaluate`]
    /// at `ctx` reads, through scales and blends, for an evaluation soon
    /// after: a hint with no effect on results.
    pub fn prefetch(&self, ctx: &TextureEvalContext) {
        match self {
            FloatTexture::Image(t) => t.base.prefetch(ctx),
            FloatTexture::Scaled(t) => {
                t.tex.prefetch(ctx);
                t.scale.prefetch(ctx);
            }
            FloatTexture::Mix(t) => {
                t.tex1.prefetch(ctx);
                t.tex2.prefetch(ctx);
                t.amount.prefetch(ctx);
            }
            FloatTexture::DirectionMix(t) => {
                t.tex1.prefetch(ctx);
                t.tex2.prefetch(ctx);
            }
            _ => {}
        }
    }

    /// The value if the texture is a constant.
    #[inline]
    pub fn constant_value(&self) -> Option<Float> {
        match self {
            FloatTexture::Constant(v) => Some(*v),
            _ => None,
        }
    }
}

/// A texture returning a spectrum.
#[derive(Clone, Debug)]
pub enum SpectrumTexture {
    /// A constant spectrum.
    Constant(Spectrum),
    /// `tex * scale`.
    Scaled(SpectrumScaledTexture),
    /// `tex * tex2` (pbrt-v3's scale of two textures).
    Product(SpectrumProductTexture),
    /// A blend of two textures by a float texture.
    Mix(SpectrumMixTexture),
    /// A blend of two textures by the normal's alignment with a direction.
    DirectionMix(SpectrumDirectionMixTexture),
    /// Bilinear interpolation of four spectra.
    Bilerp(SpectrumBilerpTexture),
    /// Checks of two textures, 2-D or 3-D.
    Checkerboard(SpectrumCheckerboardTexture),
    /// Random polka dots.
    Dots(SpectrumDotsTexture),
    /// Marble.
    Marble(MarbleTexture),
    /// An RGB image.
    Image(SpectrumImageTexture),
    /// A Ptex file.
    Ptex(SpectrumPtexTexture),
    /// pbrt-v3's `uv` texture.
    Uv(UvTexture),
    /// A float texture as a grey spectrum (pbrt-v3's spectrum `fbm`,
    /// `wrinkled` and `windy`, which return the float value in every
    /// channel).
    Grey(FloatTextureRef),
}

impl SpectrumTexture {
    /// The value at a point for the sampled wavelengths.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            SpectrumTexture::Constant(s) => s.sample(lambda),
            SpectrumTexture::Scaled(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Product(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Mix(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::DirectionMix(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Bilerp(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Checkerboard(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Dots(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Marble(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Image(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Ptex(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Uv(t) => t.evaluate(ctx, lambda),
            SpectrumTexture::Grey(t) => SampledSpectrum::new(t.evaluate(ctx)),
        }
    }

    /// Starts loading the image texels that [`SpectrumTexture::evaluate`]
    /// at `ctx` reads, through scales, products and blends, for an
    /// evaluation soon after: a hint with no effect on results.
    pub fn prefetch(&self, ctx: &TextureEvalContext) {
        match self {
            SpectrumTexture::Image(t) => t.base.prefetch(ctx),
            SpectrumTexture::Scaled(t) => {
                t.tex.prefetch(ctx);
                t.scale.prefetch(ctx);
            }
            SpectrumTexture::Product(t) => {
                t.tex.prefetch(ctx);
                t.tex2.prefetch(ctx);
            }
            SpectrumTexture::Mix(t) => {
                t.tex1.prefetch(ctx);
                t.tex2.prefetch(ctx);
                t.amount.prefetch(ctx);
            }
            SpectrumTexture::DirectionMix(t) => {
                t.tex1.prefetch(ctx);
                t.tex2.prefetch(ctx);
            }
            SpectrumTexture::Grey(t) => t.prefetch(ctx),
            _ => {}
        }
    }
}

/// A shared float texture.
pub type FloatTextureRef = Arc<FloatTexture>;
/// A shared spectrum texture.
pub type SpectrumTextureRef = Arc<SpectrumTexture>;
