//! Ptex textures (pbrt-v4 `PtexTextureBase`, `FloatPtexTexture`,
//! `SpectrumPtexTexture` in `textures.h/.cpp`): per-face textures looked up
//! by the shape's face index and (u, v), read from Ptex files by our own
//! [`reader`] and filtered as the Ptex library filters for pbrt-v4's
//! request: the cubic B-spline on quad meshes ([`filter`]), the
//! elliptical Gaussian on triangle meshes ([`triangle`]), both carried
//! across face edges into the neighbours the file names.
//!
//! Lookups with a face index the file does not have give zero, as in
//! pbrt-v4 (where Ptex leaves the result unset); they are counted per file
//! and reported after the render by [`take_lookup_warnings`].
//!
//! As in pbrt-v4, the filtered value goes through the texture's colour
//! encoding by way of 8 bits when the encoding is not linear (default
//! "gamma 2.2", whatever the file's data type), then is multiplied by
//! `scale`. Files are read once and shared between textures.

pub mod filter;
pub mod reader;
#[cfg(test)]
mod tests;
pub mod triangle;

pub use reader::{PtexBorderMode, PtexDataType, PtexFace, PtexFile, PtexMeshType};

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, OnceLock, Weak};

use super::TextureEvalContext;
use crate::image::ColorEncoding;
use crate::spectrum::{
    RgbAlbedoSpectrum, RgbColorSpace, RgbIlluminantSpectrum, RgbUnboundedSpectrum, SampledSpectrum,
    SampledWavelengths, Spectrum, SpectrumType, RGB,
};
use rpbrt_geometry::float::Float;

/// The files in memory, by canonical path (weak: files stay while any
/// texture holds them).
fn cache() -> &'static Mutex<HashMap<PathBuf, Weak<PtexFile>>> {
    static CACHE: OnceLock<Mutex<HashMap<PathBuf, Weak<PtexFile>>>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// Loads a Ptex file, or returns the copy already in memory (files stay
/// shared while any texture holds them); the flag is true when the file
/// was read now (so its warnings are new). Channel counts other than 1
/// and 3 are errors, as pbrt-v4 only looks up those.
pub fn load_ptex(path: &Path) -> Result<(Arc<PtexFile>, bool), String> {
    let cache = cache();
    let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    if let Some(f) = cache
        .lock()
        .ok()
        .and_then(|m| m.get(&key).and_then(Weak::upgrade))
    {
        return Ok((f, false));
    }
    let file = PtexFile::read(path)?;
    let name = path.display();
    if file.nchannels != 1 && file.nchannels != 3 {
        return Err(format!(
            "\"{name}\": {} channels; only one and three channel ptex textures are supported",
            file.nchannels
        ));
    }
    let file = Arc::new(file);
    if let Ok(mut m) = cache.lock() {
        m.retain(|_, w| w.strong_count() > 0);
        m.insert(key, Arc::downgrade(&file));
    }
    Ok((file, true))
}

/// One warning per Ptex file in memory that was looked up with face
/// indices it does not have since the last call (the counts are reset).
pub fn take_lookup_warnings() -> Vec<String> {
    let Ok(m) = cache().lock() else {
        return Vec::new();
    };
    let mut files: Vec<Arc<PtexFile>> = m.values().filter_map(Weak::upgrade).collect();
    drop(m);
    files.sort_by(|a, b| a.filename.cmp(&b.filename));
    files
        .iter()
        .filter_map(|f| {
            let n = f.bad_lookups.swap(0, Ordering::Relaxed);
            let face = f.bad_face.swap(0, Ordering::Relaxed);
            (n > 0).then(|| {
                format!(
                    "\"{}\": {n} ptex lookups used face indices outside the file's {} faces (e.g. {face}) and gave zero; the mesh's \"faceIndices\" do not match the file",
                    f.filename,
                    f.faces.len()
                )
            })
        })
        .collect()
}

/// What float and spectrum Ptex textures share (pbrt-v4
/// `PtexTextureBase`).
#[derive(Clone, Debug)]
pub struct PtexTextureBase {
    /// The file, as resolved (for messages).
    pub filename: String,
    /// The decoded file, shared.
    pub file: Arc<PtexFile>,
    /// How filtered values are decoded (through 8 bits unless linear).
    pub encoding: ColorEncoding,
    /// Multiplies the result.
    pub scale: Float,
}

impl PtexTextureBase {
    /// The filtered, decoded and scaled channels at a point (1 or 3 of
    /// them); the count is returned.
    pub fn sample(&self, ctx: &TextureEvalContext, out: &mut [f32; 3]) -> usize {
        let nc = self.file.nchannels.min(3);
        self.file.eval(
            &mut out[..],
            ctx.face_index,
            ctx.uv.x,
            ctx.uv.y,
            ctx.dudx,
            ctx.dvdx,
            ctx.dudy,
            ctx.dvdy,
        );
        if self.encoding != ColorEncoding::Linear {
            for v in out[..nc].iter_mut() {
                let q = (*v * 255.0 + 0.5).clamp(0.0, 255.0) as u8;
                *v = self.encoding.to_linear(q);
            }
        }
        for v in out[..nc].iter_mut() {
            *v *= self.scale;
        }
        nc
    }
}

/// A float Ptex texture: the value, or the mean of three channels.
#[derive(Clone, Debug)]
pub struct FloatPtexTexture {
    /// File, encoding and scale.
    pub base: PtexTextureBase,
}

impl FloatPtexTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let mut r = [0.0; 3];
        match self.base.sample(ctx, &mut r) {
            1 => r[0],
            _ => (r[0] + r[1] + r[2]) / 3.0,
        }
    }
}

/// A spectrum Ptex texture: one channel is a constant spectrum, three are
/// sRGB turned into the consumer's spectrum type.
#[derive(Clone, Debug)]
pub struct SpectrumPtexTexture {
    /// File, encoding and scale.
    pub base: PtexTextureBase,
    /// How RGB values become spectra.
    pub spectrum_type: SpectrumType,
}

impl SpectrumPtexTexture {
    /// The spectrum at a point.
    pub fn spectrum(&self, ctx: &TextureEvalContext) -> Spectrum {
        let mut r = [0.0; 3];
        if self.base.sample(ctx, &mut r) == 1 {
            return Spectrum::constant(r[0]);
        }
        // Negative values (possible with float data read linearly) are
        // clamped so the spectra stay valid.
        let rgb = RGB::new(r[0].max(0.0), r[1].max(0.0), r[2].max(0.0));
        let cs = RgbColorSpace::srgb();
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
