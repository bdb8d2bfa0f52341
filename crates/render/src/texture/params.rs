//! Texture-or-value parameter lookups (pbrt-v4
//! `TextureParameterDictionary` in `paramdict.cpp`): a [`ParamReader`]
//! plus the scene's named textures, so that a material or texture
//! parameter may be a constant or name a texture.

use std::collections::HashSet;
use std::ops::Deref;
use std::sync::Arc;

use rpbrt_geometry::float::Float;
use rpbrt_parser::Diagnostic;

use super::create::NamedTextures;
use super::{FloatTexture, FloatTextureRef, SpectrumTexture, SpectrumTextureRef};
use crate::params::ParamReader;
use crate::spectrum::{Spectrum, SpectrumType};

/// A [`ParamReader`] that also resolves texture references.
pub struct TextureParams<'a> {
    reader: ParamReader<'a>,
    named: &'a NamedTextures,
    /// Names of spectrum textures not created yet, so that a float
    /// parameter naming one gets the wrong-kind message, not "undefined".
    later_spectrum: Option<&'a HashSet<String>>,
}

impl<'a> Deref for TextureParams<'a> {
    type Target = ParamReader<'a>;

    fn deref(&self) -> &ParamReader<'a> {
        &self.reader
    }
}

impl<'a> TextureParams<'a> {
    /// Lookups in `reader` whose texture references resolve in `named`.
    pub fn new(reader: ParamReader<'a>, named: &'a NamedTextures) -> Self {
        TextureParams {
            reader,
            named,
            later_spectrum: None,
        }
    }

    /// [`TextureParams::new`], knowing the names of the spectrum textures
    /// that will be created after `named` (while float textures are made).
    pub fn with_later_spectrum(
        reader: ParamReader<'a>,
        named: &'a NamedTextures,
        later_spectrum: &'a HashSet<String>,
    ) -> Self {
        TextureParams {
            reader,
            named,
            later_spectrum: Some(later_spectrum),
        }
    }

    /// The plain reader back.
    pub fn into_reader(self) -> ParamReader<'a> {
        self.reader
    }

    /// The warnings, then one for every parameter nothing read.
    pub fn finish(self) -> Vec<Diagnostic> {
        self.reader.finish()
    }

    fn is_spectrum(&self, name: &str) -> bool {
        self.named.albedo.contains_key(name)
            || self.later_spectrum.is_some_and(|s| s.contains(name))
    }

    /// The float texture bound to parameter `name`: a `"texture"`
    /// parameter naming a float texture, or a `"float"` constant; `None`
    /// when absent (pbrt-v4 `GetFloatTextureOrNull`).
    pub fn float_texture_opt(&self, name: &str) -> Result<Option<FloatTextureRef>, Diagnostic> {
        if let Some(tex) = self.texture_name(name)? {
            if let Some(t) = self.named.float.get(&tex) {
                return Ok(Some(t.clone()));
            }
            let msg = if self.is_spectrum(&tex) {
                format!(
                    "\"{tex}\" is a spectrum texture, but parameter \"{name}\" needs a float texture"
                )
            } else {
                format!("couldn't find float texture named \"{tex}\" for parameter \"{name}\"")
            };
            return Err(self.error_at(name, msg));
        }
        if self.has(name) {
            // A float constant; any other type is reported by the lookup.
            let v = self.float(name, 0.0)?;
            return Ok(Some(Arc::new(FloatTexture::Constant(v))));
        }
        Ok(None)
    }

    /// [`TextureParams::float_texture_opt`], or a constant `default`
    /// (pbrt-v4 `GetFloatTexture`).
    pub fn float_texture(&self, name: &str, default: Float) -> Result<FloatTextureRef, Diagnostic> {
        Ok(self
            .float_texture_opt(name)?
            .unwrap_or_else(|| Arc::new(FloatTexture::Constant(default))))
    }

    /// A float texture whose constant value must satisfy `ok`; `what` says
    /// what is wrong otherwise.
    pub fn checked_float_texture(
        &self,
        name: &str,
        default: Float,
        ok: fn(Float) -> bool,
        what: &str,
    ) -> Result<FloatTextureRef, Diagnostic> {
        let t = self.float_texture(name, default)?;
        self.check_constant(name, &t, ok, what)?;
        Ok(t)
    }

    /// An error when `t` is a constant that fails `ok`.
    pub fn check_constant(
        &self,
        name: &str,
        t: &FloatTexture,
        ok: fn(Float) -> bool,
        what: &str,
    ) -> Result<(), Diagnostic> {
        match t {
            FloatTexture::Constant(v) if !ok(*v) => {
                Err(self.invalid(name, format!("{what} (got {v})")))
            }
            _ => Ok(()),
        }
    }

    /// The spectrum texture bound to parameter `name`: a `"texture"`
    /// parameter naming a spectrum texture (the version created for `ty`),
    /// or an `rgb` / `spectrum` / `blackbody` constant converted for `ty`;
    /// `None` when absent (pbrt-v4 `GetSpectrumTextureOrNull`).
    pub fn spectrum_texture_opt(
        &self,
        name: &str,
        ty: SpectrumType,
    ) -> Result<Option<SpectrumTextureRef>, Diagnostic> {
        if let Some(tex) = self.texture_name(name)? {
            if let Some(t) = self.named.spectrum(ty).get(&tex) {
                return Ok(Some(t.clone()));
            }
            let msg = if self.named.float.contains_key(&tex) {
                format!(
                    "\"{tex}\" is a float texture, but parameter \"{name}\" needs a spectrum texture"
                )
            } else {
                format!("couldn't find spectrum texture named \"{tex}\" for parameter \"{name}\"")
            };
            return Err(self.error_at(name, msg));
        }
        Ok(self
            .spectrum(name, ty)?
            .map(|s| Arc::new(SpectrumTexture::Constant(s))))
    }

    /// [`TextureParams::spectrum_texture_opt`], or a constant `default`
    /// (pbrt-v4 `GetSpectrumTexture`).
    pub fn spectrum_texture(
        &self,
        name: &str,
        default: Spectrum,
        ty: SpectrumType,
    ) -> Result<SpectrumTextureRef, Diagnostic> {
        Ok(self
            .spectrum_texture_opt(name, ty)?
            .unwrap_or_else(|| Arc::new(SpectrumTexture::Constant(default))))
    }
}
