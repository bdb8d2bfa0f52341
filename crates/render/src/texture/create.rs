//! Textures from `Texture` directives, and the texture-or-constant
//! parameter lookups materials and lights use (pbrt-v4
//! `FloatTexture::Create`, `SpectrumTexture::Create`, the `Create` methods
//! in `textures.cpp`, `BasicScene::CreateTextures` and
//! `TextureParameterDictionary` in `paramdict.cpp`).
//!
//! Float textures are created first, then spectrum textures, each in
//! definition order, so a texture may use any float texture and any
//! earlier texture of its kind. Every spectrum texture is created three
//! times, once per [`SpectrumType`], because RGB values turn into different
//! spectra for reflectances, unbounded quantities and emission.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use super::imagemap::{FloatImageTexture, ImageTextureBase, SpectrumImageTexture};
use super::mapping::{TextureMapping2D, TextureMapping3D};
use super::procedural::*;
use super::ptex::{load_ptex, FloatPtexTexture, PtexTextureBase, SpectrumPtexTexture};
use super::{FloatTexture, FloatTextureRef, SpectrumTexture, SpectrumTextureRef};
use crate::image::{ColorEncoding, FilterFunction, MIPMapCache, MIPMapFilterOptions, WrapMode};
use crate::scene::entities::{TextureKind, TextureSceneEntity};
use crate::spectrum::{spectrum_from_param, RgbColorSpace, Spectrum, SpectrumType};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary};

/// Settings that affect texture creation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextureOptions {
    /// Point-sample image textures instead of filtering them (pbrt-v4's
    /// `--disable-texture-filtering`).
    pub disable_texture_filtering: bool,
}

/// The named textures of a scene, by name; each spectrum texture is in all
/// three spectrum maps, created for that spectrum type.
#[derive(Clone, Debug, Default)]
pub struct NamedTextures {
    /// Float textures.
    pub float: HashMap<String, FloatTextureRef>,
    /// Spectrum textures created for reflectances.
    pub albedo: HashMap<String, SpectrumTextureRef>,
    /// Spectrum textures created for unbounded quantities.
    pub unbounded: HashMap<String, SpectrumTextureRef>,
    /// Spectrum textures created for emission.
    pub illuminant: HashMap<String, SpectrumTextureRef>,
}

impl NamedTextures {
    /// The spectrum textures created for `ty`.
    pub fn spectrum(&self, ty: SpectrumType) -> &HashMap<String, SpectrumTextureRef> {
        match ty {
            SpectrumType::Albedo => &self.albedo,
            SpectrumType::Unbounded => &self.unbounded,
            SpectrumType::Illuminant => &self.illuminant,
        }
    }

    fn spectrum_mut(&mut self, ty: SpectrumType) -> &mut HashMap<String, SpectrumTextureRef> {
        match ty {
            SpectrumType::Albedo => &mut self.albedo,
            SpectrumType::Unbounded => &mut self.unbounded,
            SpectrumType::Illuminant => &mut self.illuminant,
        }
    }
}

/// The textures visible to a lookup, plus the names of spectrum textures
/// not created yet (so that a float parameter naming one gets the
/// wrong-kind message rather than "undefined").
#[derive(Clone, Copy)]
struct Scope<'a> {
    named: &'a NamedTextures,
    later_spectrum: Option<&'a HashSet<String>>,
}

impl<'a> Scope<'a> {
    fn of(named: &'a NamedTextures) -> Self {
        Scope {
            named,
            later_spectrum: None,
        }
    }

    fn is_spectrum(&self, name: &str) -> bool {
        self.named.albedo.contains_key(name)
            || self.later_spectrum.is_some_and(|s| s.contains(name))
    }
}

/// Where parameter `name` was written, or `fallback`.
fn param_loc(params: &ParameterDictionary, name: &str, fallback: Option<&FileLoc>) -> FileLoc {
    params
        .loc(name)
        .or(fallback)
        .cloned()
        .unwrap_or_else(crate::scene::entities::default_loc)
}

/// The directory file names in `loc`'s file resolve against.
fn dir_of(loc: &FileLoc) -> &Path {
    Path::new(&*loc.file)
        .parent()
        .unwrap_or_else(|| Path::new("."))
}

fn float_tex_opt(
    params: &ParameterDictionary,
    name: &str,
    scope: Scope,
) -> Result<Option<FloatTextureRef>, Diagnostic> {
    if let Some(tex) = params.get_texture(name)? {
        if let Some(t) = scope.named.float.get(&tex) {
            return Ok(Some(t.clone()));
        }
        let loc = param_loc(params, name, None);
        let msg = if scope.is_spectrum(&tex) {
            format!(
                "\"{tex}\" is a spectrum texture, but parameter \"{name}\" needs a float texture"
            )
        } else {
            format!("couldn't find float texture named \"{tex}\" for parameter \"{name}\"")
        };
        return Err(Diagnostic::error(loc, msg));
    }
    if params.param_type(name).is_some() {
        // A float constant; any other type is reported by the lookup.
        let v = params.get_one_float(name, 0.0)?;
        return Ok(Some(Arc::new(FloatTexture::Constant(v))));
    }
    Ok(None)
}

fn float_tex(
    params: &ParameterDictionary,
    name: &str,
    default: Float,
    scope: Scope,
) -> Result<FloatTextureRef, Diagnostic> {
    Ok(float_tex_opt(params, name, scope)?
        .unwrap_or_else(|| Arc::new(FloatTexture::Constant(default))))
}

/// A spectrum given as a constant parameter (rgb, blackbody, spectrum),
/// converted for `ty`; file names resolve next to the scene file.
fn spectrum_param(
    params: &ParameterDictionary,
    name: &str,
    ty: SpectrumType,
    cs: &RgbColorSpace,
) -> Result<Option<Spectrum>, Diagnostic> {
    let Some(v) = params.get_one_spectrum(name)? else {
        return Ok(None);
    };
    let loc = param_loc(params, name, None);
    spectrum_from_param(&v, ty, cs, dir_of(&loc))
        .map(Some)
        .map_err(|m| Diagnostic::error(loc, format!("parameter \"{name}\": {m}")))
}

fn spectrum_tex_opt(
    params: &ParameterDictionary,
    name: &str,
    ty: SpectrumType,
    cs: &RgbColorSpace,
    scope: Scope,
) -> Result<Option<SpectrumTextureRef>, Diagnostic> {
    if let Some(tex) = params.get_texture(name)? {
        if let Some(t) = scope.named.spectrum(ty).get(&tex) {
            return Ok(Some(t.clone()));
        }
        let loc = param_loc(params, name, None);
        let msg = if scope.named.float.contains_key(&tex) {
            format!(
                "\"{tex}\" is a float texture, but parameter \"{name}\" needs a spectrum texture"
            )
        } else {
            format!("couldn't find spectrum texture named \"{tex}\" for parameter \"{name}\"")
        };
        return Err(Diagnostic::error(loc, msg));
    }
    Ok(spectrum_param(params, name, ty, cs)?.map(|s| Arc::new(SpectrumTexture::Constant(s))))
}

fn spectrum_tex(
    params: &ParameterDictionary,
    name: &str,
    default: Float,
    ty: SpectrumType,
    cs: &RgbColorSpace,
    scope: Scope,
) -> Result<SpectrumTextureRef, Diagnostic> {
    Ok(spectrum_tex_opt(params, name, ty, cs, scope)?
        .unwrap_or_else(|| Arc::new(SpectrumTexture::Constant(Spectrum::constant(default)))))
}

/// The float texture bound to parameter `name`: a `"texture"` parameter
/// naming a float texture, a `"float"` constant, or else `default` (pbrt-v4
/// `TextureParameterDictionary::GetFloatTexture`).
pub fn get_float_texture(
    params: &ParameterDictionary,
    name: &str,
    default: Float,
    named: &NamedTextures,
) -> Result<FloatTextureRef, Diagnostic> {
    float_tex(params, name, default, Scope::of(named))
}

/// Like [`get_float_texture`] without a default: `None` when the parameter
/// is absent (pbrt-v4 `GetFloatTextureOrNull`).
pub fn get_float_texture_opt(
    params: &ParameterDictionary,
    name: &str,
    named: &NamedTextures,
) -> Result<Option<FloatTextureRef>, Diagnostic> {
    float_tex_opt(params, name, Scope::of(named))
}

/// The spectrum texture bound to parameter `name`: a `"texture"` parameter
/// naming a spectrum texture (the version created for `spectrum_type`), an
/// `rgb`/`spectrum`/`blackbody` constant converted for `spectrum_type` in
/// colour space `cs`, or else a constant texture of `default` (`None` when
/// there is no default either); pbrt-v4 `GetSpectrumTexture` /
/// `GetSpectrumTextureOrNull`.
pub fn get_spectrum_texture(
    params: &ParameterDictionary,
    name: &str,
    default: Option<Spectrum>,
    spectrum_type: SpectrumType,
    cs: &RgbColorSpace,
    named: &NamedTextures,
) -> Result<Option<SpectrumTextureRef>, Diagnostic> {
    let found = spectrum_tex_opt(params, name, spectrum_type, cs, Scope::of(named))?;
    Ok(found.or_else(|| default.map(|s| Arc::new(SpectrumTexture::Constant(s)))))
}

fn octaves(params: &ParameterDictionary, loc: &FileLoc) -> Result<i32, Diagnostic> {
    let n = params.get_one_int("octaves", 8)?;
    if n < 0 {
        return Err(Diagnostic::error(
            param_loc(params, "octaves", Some(loc)),
            format!("\"octaves\" must not be negative (got {n})"),
        ));
    }
    Ok(n)
}

/// Names `FilterFunction::parse` accepts.
const FILTER_NAMES: &str = "point, bilinear, trilinear, ewa";
/// Names `WrapMode::parse` accepts.
const WRAP_NAMES: &str = "repeat, black, clamp, octahedralsphere";

/// Reads the shared image-texture parameters and loads the MIP map.
fn image_base(
    entity: &TextureSceneEntity,
    render_from_texture: &Transform,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<ImageTextureBase, Diagnostic> {
    let params = &entity.base.params;
    let loc = &entity.base.loc;
    let mapping = TextureMapping2D::create(params, render_from_texture, loc)?;
    let max_anisotropy = params.get_one_float("maxanisotropy", 8.0)?;
    let filter_name = params.get_one_string("filter", "bilinear")?;
    let Some(mut filter) = FilterFunction::parse(&filter_name) else {
        return Err(Diagnostic::error(
            param_loc(params, "filter", Some(loc)),
            format!("\"{filter_name}\": filter function unknown (known: {FILTER_NAMES})"),
        ));
    };
    if options.disable_texture_filtering {
        filter = FilterFunction::Point;
    }
    let wrap_name = params.get_one_string("wrap", "repeat")?;
    let Some(wrap) = WrapMode::parse(&wrap_name) else {
        return Err(Diagnostic::error(
            param_loc(params, "wrap", Some(loc)),
            format!("\"{wrap_name}\": wrap mode unknown (known: {WRAP_NAMES})"),
        ));
    };
    let scale = params.get_one_float("scale", 1.0)?;
    let invert = params.get_one_bool("invert", false)?;
    let filename = params.get_one_string("filename", "")?;
    if filename.is_empty() {
        return Err(Diagnostic::error(
            loc.clone(),
            format!(
                "{} texture \"{}\": no \"filename\" given",
                entity.base.name, entity.name
            ),
        ));
    }
    let path = dir_of(loc).join(&filename);
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let encoding_name =
        params.get_one_string("encoding", if is_png { "sRGB" } else { "linear" })?;
    let Some(encoding) = ColorEncoding::parse(&encoding_name) else {
        return Err(Diagnostic::error(
            param_loc(params, "encoding", Some(loc)),
            format!(
                "\"{encoding_name}\": color encoding unknown (known: linear, sRGB, gamma <value>)"
            ),
        ));
    };
    let filter_options = MIPMapFilterOptions {
        filter,
        max_anisotropy,
    };
    let mipmap = cache
        .get_or_load(&path, filter_options, wrap, encoding)
        .map_err(|e| {
            Diagnostic::error(
                param_loc(params, "filename", Some(loc)),
                format!(
                    "{} texture \"{}\": unable to read image \"{}\": {e}",
                    entity.base.name,
                    entity.name,
                    path.display()
                ),
            )
        })?;
    Ok(ImageTextureBase {
        mapping,
        filename: path.display().to_string(),
        scale,
        invert,
        mipmap,
    })
}

fn checkerboard_mapping(
    params: &ParameterDictionary,
    render_from_texture: &Transform,
    loc: &FileLoc,
    dim: i32,
) -> Result<CheckerboardMapping, Diagnostic> {
    Ok(if dim == 2 {
        CheckerboardMapping::Planar(TextureMapping2D::create(params, render_from_texture, loc)?)
    } else {
        CheckerboardMapping::Solid(TextureMapping3D::new(render_from_texture))
    })
}

fn checkerboard_dimension(params: &ParameterDictionary, loc: &FileLoc) -> Result<i32, Diagnostic> {
    let dim = params.get_one_int("dimension", 2)?;
    if dim != 2 && dim != 3 {
        return Err(Diagnostic::error(
            param_loc(params, "dimension", Some(loc)),
            format!("{dim} dimensional checkerboard texture not supported (use 2 or 3)"),
        ));
    }
    Ok(dim)
}

/// The file, encoding and scale of a ptex texture (pbrt-v4
/// `FloatPtexTexture::Create`: "filename", "encoding" (default
/// "gamma 2.2"), "scale").
fn ptex_base(entity: &TextureSceneEntity) -> Result<PtexTextureBase, Diagnostic> {
    let params = &entity.base.params;
    let loc = &entity.base.loc;
    let filename = params.get_one_string("filename", "")?;
    if filename.is_empty() {
        return Err(Diagnostic::error(
            loc.clone(),
            format!("ptex texture \"{}\": no \"filename\" given", entity.name),
        ));
    }
    let encoding_name = params.get_one_string("encoding", "gamma 2.2")?;
    let Some(encoding) = ColorEncoding::parse(&encoding_name) else {
        return Err(Diagnostic::error(
            param_loc(params, "encoding", Some(loc)),
            format!(
                "\"{encoding_name}\": color encoding unknown (known: linear, sRGB, gamma <value>)"
            ),
        ));
    };
    let scale = params.get_one_float("scale", 1.0)?;
    let path = dir_of(loc).join(&filename);
    let file = load_ptex(&path).map_err(|e| {
        Diagnostic::error(
            param_loc(params, "filename", Some(loc)),
            format!(
                "ptex texture \"{}\": unable to read ptex file: {e}",
                entity.name
            ),
        )
    })?;
    Ok(PtexTextureBase {
        filename: path.display().to_string(),
        file,
        encoding,
        scale,
    })
}

/// The float texture classes [`create_float_texture`] knows.
pub const FLOAT_TEXTURE_NAMES: &str =
    "constant, scale, mix, directionmix, bilerp, imagemap, checkerboard, dots, fbm, wrinkled, windy, ptex";
/// The spectrum texture classes [`create_spectrum_texture`] knows.
pub const SPECTRUM_TEXTURE_NAMES: &str =
    "constant, scale, mix, directionmix, bilerp, imagemap, checkerboard, dots, marble, ptex";

fn create_float_in(
    entity: &TextureSceneEntity,
    scope: Scope,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<FloatTextureRef, Diagnostic> {
    let params = &entity.base.params;
    let loc = &entity.base.loc;
    let rft = entity.render_from_object.start_transform;
    let tex = match entity.base.name.as_str() {
        "constant" => FloatTexture::Constant(params.get_one_float("value", 1.0)?),
        "scale" => {
            let mut tex = float_tex(params, "tex", 1.0, scope)?;
            let mut scale = float_tex(params, "scale", 1.0, scope)?;
            // Fold constant scales as pbrt-v4 does: a scale of 1 is the
            // texture itself, and an image texture takes the factor.
            for _ in 0..2 {
                if let Some(cs) = scale.constant_value() {
                    if cs == 1.0 {
                        return Ok(tex);
                    }
                    if let FloatTexture::Image(image) = &*tex {
                        let mut copy = image.clone();
                        copy.base.scale *= cs;
                        return Ok(Arc::new(FloatTexture::Image(copy)));
                    }
                }
                std::mem::swap(&mut tex, &mut scale);
            }
            FloatTexture::Scaled(FloatScaledTexture { tex, scale })
        }
        "mix" => FloatTexture::Mix(FloatMixTexture {
            tex1: float_tex(params, "tex1", 0.0, scope)?,
            tex2: float_tex(params, "tex2", 1.0, scope)?,
            amount: float_tex(params, "amount", 0.5, scope)?,
        }),
        "directionmix" => {
            let d = params.get_one_vector3("dir", [0.0, 1.0, 0.0])?;
            let dir = direction(params, &rft, d, loc)?;
            FloatTexture::DirectionMix(FloatDirectionMixTexture {
                tex1: float_tex(params, "tex1", 0.0, scope)?,
                tex2: float_tex(params, "tex2", 1.0, scope)?,
                dir,
            })
        }
        "bilerp" => FloatTexture::Bilerp(FloatBilerpTexture {
            mapping: TextureMapping2D::create(params, &rft, loc)?,
            v00: params.get_one_float("v00", 0.0)?,
            v01: params.get_one_float("v01", 1.0)?,
            v10: params.get_one_float("v10", 0.0)?,
            v11: params.get_one_float("v11", 1.0)?,
        }),
        "imagemap" => FloatTexture::Image(FloatImageTexture {
            base: image_base(entity, &rft, cache, options)?,
        }),
        "checkerboard" => {
            let dim = checkerboard_dimension(params, loc)?;
            let tex1 = float_tex(params, "tex1", 1.0, scope)?;
            let tex2 = float_tex(params, "tex2", 0.0, scope)?;
            FloatTexture::Checkerboard(FloatCheckerboardTexture {
                mapping: checkerboard_mapping(params, &rft, loc, dim)?,
                tex1,
                tex2,
            })
        }
        "dots" => FloatTexture::Dots(FloatDotsTexture {
            mapping: TextureMapping2D::create(params, &rft, loc)?,
            inside: float_tex(params, "inside", 1.0, scope)?,
            outside: float_tex(params, "outside", 0.0, scope)?,
        }),
        "fbm" => FloatTexture::FBm(FBmTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(params, loc)?,
            omega: params.get_one_float("roughness", 0.5)?,
        }),
        "wrinkled" => FloatTexture::Wrinkled(WrinkledTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(params, loc)?,
            omega: params.get_one_float("roughness", 0.5)?,
        }),
        "windy" => FloatTexture::Windy(WindyTexture {
            mapping: TextureMapping3D::new(&rft),
        }),
        "ptex" => FloatTexture::Ptex(FloatPtexTexture {
            base: ptex_base(entity)?,
        }),
        other => {
            return Err(Diagnostic::error(
                loc.clone(),
                format!("\"{other}\": float texture type unknown (known: {FLOAT_TEXTURE_NAMES})"),
            ))
        }
    };
    Ok(Arc::new(tex))
}

/// The render-space unit direction of a direction-mix texture.
fn direction(
    params: &ParameterDictionary,
    render_from_texture: &Transform,
    d: [Float; 3],
    loc: &FileLoc,
) -> Result<Vector3f, Diagnostic> {
    render_from_texture
        .apply_vector(Vector3f::new(d[0], d[1], d[2]))
        .try_normalize()
        .ok_or_else(|| {
            Diagnostic::error(
                param_loc(params, "dir", Some(loc)),
                "\"dir\" must not be the zero vector",
            )
        })
}

fn create_spectrum_in(
    entity: &TextureSceneEntity,
    ty: SpectrumType,
    scope: Scope,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<SpectrumTextureRef, Diagnostic> {
    let params = &entity.base.params;
    let loc = &entity.base.loc;
    let rft = entity.render_from_object.start_transform;
    let cs = RgbColorSpace::get(&entity.base.color_space).ok_or_else(|| {
        Diagnostic::error(
            loc.clone(),
            format!("unknown color space \"{}\"", entity.base.color_space),
        )
    })?;
    let constant = |name: &str, default: Float| -> Result<Spectrum, Diagnostic> {
        Ok(spectrum_param(params, name, ty, cs)?.unwrap_or(Spectrum::constant(default)))
    };
    let tex = match entity.base.name.as_str() {
        "constant" => SpectrumTexture::Constant(constant("value", 1.0)?),
        "scale" => {
            let tex = spectrum_tex(params, "tex", 1.0, ty, cs, scope)?;
            let scale = float_tex(params, "scale", 1.0, scope)?;
            if let Some(c) = scale.constant_value() {
                if c == 1.0 {
                    return Ok(tex);
                }
                if let SpectrumTexture::Image(image) = &*tex {
                    let mut copy = image.clone();
                    copy.base.scale *= c;
                    return Ok(Arc::new(SpectrumTexture::Image(copy)));
                }
            }
            SpectrumTexture::Scaled(SpectrumScaledTexture { tex, scale })
        }
        "mix" => SpectrumTexture::Mix(SpectrumMixTexture {
            tex1: spectrum_tex(params, "tex1", 0.0, ty, cs, scope)?,
            tex2: spectrum_tex(params, "tex2", 1.0, ty, cs, scope)?,
            amount: float_tex(params, "amount", 0.5, scope)?,
        }),
        "directionmix" => {
            let d = params.get_one_vector3("dir", [0.0, 1.0, 0.0])?;
            let dir = direction(params, &rft, d, loc)?;
            SpectrumTexture::DirectionMix(SpectrumDirectionMixTexture {
                tex1: spectrum_tex(params, "tex1", 0.0, ty, cs, scope)?,
                tex2: spectrum_tex(params, "tex2", 1.0, ty, cs, scope)?,
                dir,
            })
        }
        "bilerp" => {
            let mapping = TextureMapping2D::create(params, &rft, loc)?;
            SpectrumTexture::Bilerp(SpectrumBilerpTexture {
                mapping,
                v: Box::new([
                    constant("v00", 0.0)?,
                    constant("v01", 1.0)?,
                    constant("v10", 0.0)?,
                    constant("v11", 1.0)?,
                ]),
            })
        }
        "imagemap" => {
            let base = image_base(entity, &rft, cache, options)?;
            // The RGB values are in the image's colour space (pbrt-v4 takes
            // it from the file's metadata, sRGB by default).
            let color_space = RgbColorSpace::get(base.mipmap.color_space()).unwrap_or(cs);
            SpectrumTexture::Image(SpectrumImageTexture {
                base,
                spectrum_type: ty,
                color_space,
            })
        }
        "checkerboard" => {
            let dim = checkerboard_dimension(params, loc)?;
            let tex1 = spectrum_tex(params, "tex1", 1.0, ty, cs, scope)?;
            let tex2 = spectrum_tex(params, "tex2", 0.0, ty, cs, scope)?;
            SpectrumTexture::Checkerboard(SpectrumCheckerboardTexture {
                mapping: checkerboard_mapping(params, &rft, loc, dim)?,
                tex1,
                tex2,
            })
        }
        "dots" => SpectrumTexture::Dots(SpectrumDotsTexture {
            mapping: TextureMapping2D::create(params, &rft, loc)?,
            inside: spectrum_tex(params, "inside", 1.0, ty, cs, scope)?,
            outside: spectrum_tex(params, "outside", 0.0, ty, cs, scope)?,
        }),
        "marble" => SpectrumTexture::Marble(MarbleTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(params, loc)?,
            omega: params.get_one_float("roughness", 0.5)?,
            scale: params.get_one_float("scale", 1.0)?,
            variation: params.get_one_float("variation", 0.2)?,
        }),
        "ptex" => SpectrumTexture::Ptex(SpectrumPtexTexture {
            base: ptex_base(entity)?,
            spectrum_type: ty,
        }),
        other => {
            return Err(Diagnostic::error(
                loc.clone(),
                format!(
                    "\"{other}\": spectrum texture type unknown (known: {SPECTRUM_TEXTURE_NAMES})"
                ),
            ))
        }
    };
    Ok(Arc::new(tex))
}

/// Creates the float texture of a `Texture "name" "float" "class" ...`
/// directive; references resolve in `named`. Unused parameters are not
/// reported here (see [`create_textures`]).
pub fn create_float_texture(
    entity: &TextureSceneEntity,
    named: &NamedTextures,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<FloatTextureRef, Diagnostic> {
    create_float_in(entity, Scope::of(named), cache, options)
}

/// Creates a spectrum texture for the consumers that need `spectrum_type`
/// (pbrt-v4 `SpectrumTexture::Create`); references resolve in `named`.
pub fn create_spectrum_texture(
    entity: &TextureSceneEntity,
    spectrum_type: SpectrumType,
    named: &NamedTextures,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<SpectrumTextureRef, Diagnostic> {
    create_spectrum_in(entity, spectrum_type, Scope::of(named), cache, options)
}

/// Creates every named texture: float textures first, then spectrum
/// textures (each for all three spectrum types), in definition order.
/// `Ok` carries the textures and the unused-parameter warnings; `Err` every
/// error (a texture that failed is left out, and later references to it
/// fail too) together with the warnings.
pub fn create_textures(
    float_entities: &[TextureSceneEntity],
    spectrum_entities: &[TextureSceneEntity],
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<(NamedTextures, Vec<Diagnostic>), Vec<Diagnostic>> {
    let mut named = NamedTextures::default();
    let mut diags = Vec::new();
    let spectrum_names: HashSet<String> =
        spectrum_entities.iter().map(|e| e.name.clone()).collect();
    for e in float_entities {
        debug_assert_eq!(e.kind, TextureKind::Float);
        let scope = Scope {
            named: &named,
            later_spectrum: Some(&spectrum_names),
        };
        match create_float_in(e, scope, cache, options) {
            Ok(t) => {
                named.float.insert(e.name.clone(), t);
                diags.extend(e.base.params.report_unused());
            }
            Err(d) => diags.push(d),
        }
    }
    for e in spectrum_entities {
        debug_assert_eq!(e.kind, TextureKind::Spectrum);
        let types = [
            SpectrumType::Albedo,
            SpectrumType::Unbounded,
            SpectrumType::Illuminant,
        ];
        let mut made = Vec::with_capacity(3);
        for ty in types {
            match create_spectrum_in(e, ty, Scope::of(&named), cache, options) {
                Ok(t) => made.push((ty, t)),
                Err(d) => {
                    diags.push(d);
                    break;
                }
            }
        }
        if made.len() == types.len() {
            for (ty, t) in made {
                named.spectrum_mut(ty).insert(e.name.clone(), t);
            }
            diags.extend(e.base.params.report_unused());
        }
    }
    if diags.iter().any(|d| d.is_error()) {
        Err(diags)
    } else {
        Ok((named, diags))
    }
}
