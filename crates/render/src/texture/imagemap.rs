//! Image textures (book section 10.4 "Image Texture"; pbrt-v4
//! `ImageTextureBase`, `FloatImageTexture`, `SpectrumImageTexture`).
//!
//! Lookups go through a shared [`MIPMap`]; the texture flips t because
//! texture space has (0, 0) at the bottom left while images start at the
//! top row.

use std::sync::Arc;

use super::mapping::{TexCoord2D, TextureMapping2D};
use super::TextureEvalContext;
use crate::image::MIPMap;
use crate::spectrum::{
    RgbAlbedoSpectrum, RgbColorSpace, RgbIlluminantSpectrum, RgbUnboundedSpectrum, SampledSpectrum,
    SampledWavelengths, Spectrum, SpectrumType, RGB,
};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;

/// What float and spectrum image textures share.
#[derive(Clone, Debug)]
pub struct ImageTextureBase {
    /// The (s, t) mapping.
    pub mapping: TextureMapping2D,
    /// The file, as resolved (for messages).
    pub filename: String,
    /// Multiplies the looked-up value.
    pub scale: Float,
    /// Return max(0, 1 − value) instead.
    pub invert: bool,
    /// The image pyramid (shared through the cache).
    pub mipmap: Arc<MIPMap>,
}

impl ImageTextureBase {
    /// Image-space coordinates (t flipped) and the footprint axes.
    #[inline]
    fn lookup_coords(&self, ctx: &TextureEvalContext) -> (Point2f, Vector2f, Vector2f) {
        let c: TexCoord2D = self.mapping.map(ctx);
        (
            Point2f::new(c.st.x, 1.0 - c.st.y),
            Vector2f::new(c.dsdx, c.dtdx),
            Vector2f::new(c.dsdy, c.dtdy),
        )
    }

    /// Starts loading the texels a lookup at `ctx` reads
    /// ([`MIPMap::prefetch`]).
    #[inline]
    pub fn prefetch(&self, ctx: &TextureEvalContext) {
        let (st, d0, d1) = self.lookup_coords(ctx);
        self.mipmap.prefetch(st, d0, d1);
    }
}

/// A float texture read from an image (pbrt-v4 `FloatImageTexture`).
#[derive(Clone, Debug)]
pub struct FloatImageTexture {
    /// Mapping, file, scale and inversion.
    pub base: ImageTextureBase,
}

impl FloatImageTexture {
    /// The filtered value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let (st, d0, d1) = self.base.lookup_coords(ctx);
        let v = self.base.scale * self.base.mipmap.filter_float(st, d0, d1);
        if self.base.invert {
            (1.0 - v).max(0.0)
        } else {
            v
        }
    }
}

/// A spectrum texture read from an RGB image (pbrt-v4
/// `SpectrumImageTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumImageTexture {
    /// Mapping, file, scale and inversion.
    pub base: ImageTextureBase,
    /// How filtered RGB values become spectra.
    pub spectrum_type: SpectrumType,
    /// The colour space of the image's RGB values (from the file, sRGB when
    /// it says nothing).
    pub color_space: &'static RgbColorSpace,
}

impl SpectrumImageTexture {
    /// The filtered, scaled (and possibly inverted) RGB at a point, clamped
    /// to be non-negative.
    #[inline]
    pub fn rgb(&self, ctx: &TextureEvalContext) -> RGB {
        let (st, d0, d1) = self.base.lookup_coords(ctx);
        let v = self.base.mipmap.filter_rgb(st, d0, d1);
        let s = self.base.scale;
        let mut rgb = [s * v[0], s * v[1], s * v[2]];
        if self.base.invert {
            rgb = [1.0 - rgb[0], 1.0 - rgb[1], 1.0 - rgb[2]];
        }
        RGB::new(rgb[0].max(0.0), rgb[1].max(0.0), rgb[2].max(0.0))
    }

    /// The spectrum at a point, as the consumer's spectrum type wants it:
    /// albedos are clamped to [0, 1].
    pub fn spectrum(&self, ctx: &TextureEvalContext) -> Spectrum {
        let rgb = self.rgb(ctx);
        let cs = self.color_space;
        match self.spectrum_type {
            SpectrumType::Unbounded => Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, rgb)),
            SpectrumType::Albedo => {
                let c = RGB::new(rgb.r.min(1.0), rgb.g.min(1.0), rgb.b.min(1.0));
                Spectrum::RgbAlbedo(RgbAlbedoSpectrum::new(cs, c))
            }
            SpectrumType::Illuminant => {
                Spectrum::RgbIlluminant(RgbIlluminantSpectrum::new(cs, rgb))
            }
        }
    }

    /// The value at a point for the sampled wavelengths.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.spectrum(ctx).sample(lambda)
    }
}
