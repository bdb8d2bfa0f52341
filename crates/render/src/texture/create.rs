//! Textures from `Texture` directives (pbrt-v4 `FloatTexture::Create`,
//! `SpectrumTexture::Create` and the `Create` methods in `textures.cpp`).
//!
//! The scene creates float textures first, then spectrum textures, each in
//! definition order, so a texture may use any float texture and any
//! earlier texture of its kind. Every spectrum texture is created three
//! times, once per [`SpectrumType`], because RGB values turn into different
//! spectra for reflectances, unbounded quantities and emission.

use std::collections::HashMap;
use std::sync::Arc;

use super::imagemap::{FloatImageTexture, ImageTextureBase, SpectrumImageTexture};
use super::mapping::{TextureMapping2D, TextureMapping3D};
use super::params::TextureParams;
use super::procedural::*;
use super::ptex::{load_ptex, FloatPtexTexture, PtexTextureBase, SpectrumPtexTexture};
use super::{FloatTexture, FloatTextureRef, SpectrumTexture, SpectrumTextureRef};
use crate::image::{
    ColorEncoding, FilterFunction, MIPMap, MIPMapCache, MIPMapFilterOptions, WrapMode,
};
use crate::params::{unknown_type, ParamReader};
use crate::spectrum::{RgbColorSpace, Spectrum, SpectrumType};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::Diagnostic;

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

    /// The spectrum textures created for `ty`, to add to.
    pub fn spectrum_mut(&mut self, ty: SpectrumType) -> &mut HashMap<String, SpectrumTextureRef> {
        match ty {
            SpectrumType::Albedo => &mut self.albedo,
            SpectrumType::Unbounded => &mut self.unbounded,
            SpectrumType::Illuminant => &mut self.illuminant,
        }
    }
}

fn octaves(tp: &ParamReader) -> Result<i32, Diagnostic> {
    let n = tp.int("octaves", 8)?;
    if n < 0 {
        return Err(tp.error_at(
            "octaves",
            format!("\"octaves\" must not be negative (got {n})"),
        ));
    }
    Ok(n)
}

/// Names `FilterFunction::parse` accepts.
const FILTER_NAMES: &str = "point, bilinear, trilinear, ewa";
/// Names `WrapMode::parse` accepts.
const WRAP_NAMES: &str = "repeat, black, clamp, octahedralsphere";

/// The MIP map an image texture's parameters ask for (its file and how it
/// is filtered, wrapped and decoded), before it is loaded.
#[derive(Clone, Debug)]
pub struct ImageRequest {
    path: std::path::PathBuf,
    filter_options: MIPMapFilterOptions,
    wrap: WrapMode,
    encoding: ColorEncoding,
}

impl ImageRequest {
    /// Reads the request from an image texture's parameters (`filter`,
    /// `maxanisotropy`, `wrap`, `filename`, `encoding`; pbrt-v4's defaults).
    pub fn read(
        def: &TextureDef,
        tp: &ParamReader,
        options: &TextureOptions,
    ) -> Result<ImageRequest, Diagnostic> {
        let max_anisotropy = tp.float("maxanisotropy", 8.0)?;
        let filter_name = tp.string("filter", "bilinear")?;
        let Some(mut filter) = FilterFunction::parse(&filter_name) else {
            return Err(Diagnostic::error(
                tp.param_loc("filter"),
                format!("\"{filter_name}\": filter function unknown (known: {FILTER_NAMES})"),
            ));
        };
        if options.disable_texture_filtering {
            filter = FilterFunction::Point;
        }
        let wrap_name = tp.string("wrap", "repeat")?;
        let Some(wrap) = WrapMode::parse(&wrap_name) else {
            return Err(Diagnostic::error(
                tp.param_loc("wrap"),
                format!("\"{wrap_name}\": wrap mode unknown (known: {WRAP_NAMES})"),
            ));
        };
        let filename = tp.string("filename", "")?;
        if filename.is_empty() {
            return Err(tp.error(format!(
                "{} texture \"{}\": no \"filename\" given",
                def.class, def.name
            )));
        }
        let path = tp.resolve("filename", &filename);
        let is_png = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let encoding_name = tp.string("encoding", if is_png { "sRGB" } else { "linear" })?;
        let Some(encoding) = ColorEncoding::parse(&encoding_name) else {
            return Err(Diagnostic::error(
                tp.param_loc("encoding"),
                format!(
                    "\"{encoding_name}\": color encoding unknown (known: linear, sRGB, gamma <value>)"
                ),
            ));
        };
        Ok(ImageRequest {
            path,
            filter_options: MIPMapFilterOptions {
                filter,
                max_anisotropy,
            },
            wrap,
            encoding,
        })
    }

    /// The MIP map, from `cache` or read now.
    pub fn load(&self, cache: &MIPMapCache) -> Result<Arc<MIPMap>, crate::image::ImageError> {
        cache.get_or_load(&self.path, self.filter_options, self.wrap, self.encoding)
    }
}

/// Reads the shared image-texture parameters and loads the MIP map.
fn image_base(
    def: &TextureDef,
    tp: &ParamReader,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<ImageTextureBase, Diagnostic> {
    let mapping = TextureMapping2D::create(tp, &def.render_from_texture)?;
    let request = ImageRequest::read(def, tp, options)?;
    let scale = tp.float("scale", 1.0)?;
    let invert = tp.bool("invert", false)?;
    let path = &request.path;
    let mipmap = request.load(cache).map_err(|e| {
        tp.error_at(
            "filename",
            format!(
                "{} texture \"{}\": unable to read image \"{}\": {e}",
                def.class,
                def.name,
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
    tp: &ParamReader,
    render_from_texture: &Transform,
    dim: i32,
) -> Result<CheckerboardMapping, Diagnostic> {
    Ok(if dim == 2 {
        CheckerboardMapping::Planar(TextureMapping2D::create(tp, render_from_texture)?)
    } else {
        CheckerboardMapping::Solid(TextureMapping3D::new(render_from_texture))
    })
}

fn checkerboard_dimension(tp: &ParamReader) -> Result<i32, Diagnostic> {
    let dim = tp.int("dimension", 2)?;
    if dim != 2 && dim != 3 {
        return Err(Diagnostic::error(
            tp.param_loc("dimension"),
            format!("{dim} dimensional checkerboard texture not supported (use 2 or 3)"),
        ));
    }
    Ok(dim)
}

/// The file, encoding and scale of a ptex texture (pbrt-v4
/// `FloatPtexTexture::Create`: "filename", "encoding" (default
/// "gamma 2.2"), "scale").
fn ptex_base(def: &TextureDef, tp: &ParamReader) -> Result<PtexTextureBase, Diagnostic> {
    let filename = tp.string("filename", "")?;
    if filename.is_empty() {
        return Err(tp.error(format!(
            "ptex texture \"{}\": no \"filename\" given",
            def.name
        )));
    }
    let encoding_name = tp.string("encoding", "gamma 2.2")?;
    let Some(encoding) = ColorEncoding::parse(&encoding_name) else {
        return Err(Diagnostic::error(
            tp.param_loc("encoding"),
            format!(
                "\"{encoding_name}\": color encoding unknown (known: linear, sRGB, gamma <value>)"
            ),
        ));
    };
    let scale = tp.float("scale", 1.0)?;
    let path = tp.resolve("filename", &filename);
    let (file, fresh) = load_ptex(&path).map_err(|e| {
        tp.error_at(
            "filename",
            format!(
                "ptex texture \"{}\": unable to read ptex file: {e}",
                def.name
            ),
        )
    })?;
    if fresh && file.bad_adjacency > 0 {
        tp.warn_at(
            "filename",
            format!(
                "\"{}\": {} face adjacency entries name faces or edges the file does not have; those edges are filtered as borders",
                path.display(),
                file.bad_adjacency
            ),
        );
    }
    Ok(PtexTextureBase {
        filename: path.display().to_string(),
        file,
        encoding,
        scale,
    })
}

/// The float texture classes [`create_float_texture`] knows, sorted.
pub const FLOAT_TEXTURE_NAMES: &[&str] = &[
    "bilerp",
    "checkerboard",
    "constant",
    "directionmix",
    "dots",
    "fbm",
    "imagemap",
    "mix",
    "ptex",
    "scale",
    "windy",
    "wrinkled",
];
/// The spectrum texture classes [`create_spectrum_texture`] knows, sorted
/// (`fbm`, `uv`, `windy` and `wrinkled` are pbrt-v3's).
pub const SPECTRUM_TEXTURE_NAMES: &[&str] = &[
    "bilerp",
    "checkerboard",
    "constant",
    "directionmix",
    "dots",
    "fbm",
    "imagemap",
    "marble",
    "mix",
    "ptex",
    "scale",
    "uv",
    "windy",
    "wrinkled",
];

/// Every texture class, float or spectrum, sorted (what the `Texture`
/// directive accepts before its kind is checked).
pub const TEXTURE_NAMES: &[&str] = &[
    "bilerp",
    "checkerboard",
    "constant",
    "directionmix",
    "dots",
    "fbm",
    "imagemap",
    "marble",
    "mix",
    "ptex",
    "scale",
    "uv",
    "windy",
    "wrinkled",
];

/// What a `Texture` directive makes, besides its parameters.
#[derive(Clone, Copy, Debug)]
pub struct TextureDef<'a> {
    /// The texture's name, by which materials refer to it (for messages).
    pub name: &'a str,
    /// Its class (`imagemap`, `checkerboard`...).
    pub class: &'a str,
    /// From texture space to render space.
    pub render_from_texture: Transform,
}

/// Creates the float texture of a `Texture "name" "float" "class" ...`
/// directive (pbrt-v4 `FloatTexture::Create`); references to other
/// textures resolve through `tp`.
pub fn create_float_texture(
    def: &TextureDef,
    tp: &TextureParams,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<FloatTextureRef, Diagnostic> {
    let rft = def.render_from_texture;
    let tex = match def.class {
        "constant" => FloatTexture::Constant(tp.float("value", 1.0)?),
        "scale" => {
            let mut tex = tp.float_texture("tex", 1.0)?;
            let mut scale = tp.float_texture("scale", 1.0)?;
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
            tex1: tp.float_texture("tex1", 0.0)?,
            tex2: tp.float_texture("tex2", 1.0)?,
            amount: tp.float_texture("amount", 0.5)?,
        }),
        "directionmix" => {
            let d = tp.vector3("dir", [0.0, 1.0, 0.0])?;
            let dir = direction(tp, &rft, d)?;
            FloatTexture::DirectionMix(FloatDirectionMixTexture {
                tex1: tp.float_texture("tex1", 0.0)?,
                tex2: tp.float_texture("tex2", 1.0)?,
                dir,
            })
        }
        "bilerp" => FloatTexture::Bilerp(FloatBilerpTexture {
            mapping: TextureMapping2D::create(tp, &rft)?,
            v00: tp.float("v00", 0.0)?,
            v01: tp.float("v01", 1.0)?,
            v10: tp.float("v10", 0.0)?,
            v11: tp.float("v11", 1.0)?,
        }),
        "imagemap" => FloatTexture::Image(FloatImageTexture {
            base: image_base(def, tp, cache, options)?,
        }),
        "checkerboard" => {
            let dim = checkerboard_dimension(tp)?;
            let tex1 = tp.float_texture("tex1", 1.0)?;
            let tex2 = tp.float_texture("tex2", 0.0)?;
            FloatTexture::Checkerboard(FloatCheckerboardTexture {
                mapping: checkerboard_mapping(tp, &rft, dim)?,
                tex1,
                tex2,
            })
        }
        "dots" => FloatTexture::Dots(FloatDotsTexture {
            mapping: TextureMapping2D::create(tp, &rft)?,
            inside: tp.float_texture("inside", 1.0)?,
            outside: tp.float_texture("outside", 0.0)?,
        }),
        "fbm" => FloatTexture::FBm(FBmTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(tp)?,
            omega: tp.float("roughness", 0.5)?,
        }),
        "wrinkled" => FloatTexture::Wrinkled(WrinkledTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(tp)?,
            omega: tp.float("roughness", 0.5)?,
        }),
        "windy" => FloatTexture::Windy(WindyTexture {
            mapping: TextureMapping3D::new(&rft),
        }),
        "ptex" => FloatTexture::Ptex(FloatPtexTexture {
            base: ptex_base(def, tp)?,
        }),
        other => {
            return Err(unknown_type(
                "float texture",
                other,
                FLOAT_TEXTURE_NAMES,
                tp.loc(),
            ))
        }
    };
    Ok(Arc::new(tex))
}

/// The render-space unit direction of a direction-mix texture.
fn direction(
    tp: &ParamReader,
    render_from_texture: &Transform,
    d: [Float; 3],
) -> Result<Vector3f, Diagnostic> {
    render_from_texture
        .apply_vector(Vector3f::new(d[0], d[1], d[2]))
        .try_normalize()
        .ok_or_else(|| tp.error_at("dir", "\"dir\" must not be the zero vector"))
}

/// Creates a spectrum texture for the consumers that need `ty` (pbrt-v4
/// `SpectrumTexture::Create`); references to other textures resolve
/// through `tp`.
pub fn create_spectrum_texture(
    def: &TextureDef,
    ty: SpectrumType,
    tp: &TextureParams,
    cache: &MIPMapCache,
    options: &TextureOptions,
) -> Result<SpectrumTextureRef, Diagnostic> {
    let rft = def.render_from_texture;
    let cs = tp.color_space();
    let constant = |name: &str, default: Float| -> Result<Spectrum, Diagnostic> {
        Ok(tp
            .spectrum(name, ty)?
            .unwrap_or(Spectrum::constant(default)))
    };
    let tex = match def.class {
        "constant" => SpectrumTexture::Constant(constant("value", 1.0)?),
        "scale" => {
            let mut tex = tp.spectrum_texture("tex", Spectrum::constant(1.0), ty)?;
            // rpbrt's spectrum factor (pbrt-v3's scale of two textures).
            if let Some(tex2) = tp.spectrum_texture_opt("tex2", ty)? {
                tex = Arc::new(SpectrumTexture::Product(SpectrumProductTexture {
                    tex,
                    tex2,
                }));
            }
            let scale = tp.float_texture("scale", 1.0)?;
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
            tex1: tp.spectrum_texture("tex1", Spectrum::constant(0.0), ty)?,
            tex2: tp.spectrum_texture("tex2", Spectrum::constant(1.0), ty)?,
            amount: tp.float_texture("amount", 0.5)?,
        }),
        "directionmix" => {
            let d = tp.vector3("dir", [0.0, 1.0, 0.0])?;
            let dir = direction(tp, &rft, d)?;
            SpectrumTexture::DirectionMix(SpectrumDirectionMixTexture {
                tex1: tp.spectrum_texture("tex1", Spectrum::constant(0.0), ty)?,
                tex2: tp.spectrum_texture("tex2", Spectrum::constant(1.0), ty)?,
                dir,
            })
        }
        "bilerp" => {
            let mapping = TextureMapping2D::create(tp, &rft)?;
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
            let base = image_base(def, tp, cache, options)?;
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
            let dim = checkerboard_dimension(tp)?;
            let tex1 = tp.spectrum_texture("tex1", Spectrum::constant(1.0), ty)?;
            let tex2 = tp.spectrum_texture("tex2", Spectrum::constant(0.0), ty)?;
            SpectrumTexture::Checkerboard(SpectrumCheckerboardTexture {
                mapping: checkerboard_mapping(tp, &rft, dim)?,
                tex1,
                tex2,
            })
        }
        "dots" => SpectrumTexture::Dots(SpectrumDotsTexture {
            mapping: TextureMapping2D::create(tp, &rft)?,
            inside: tp.spectrum_texture("inside", Spectrum::constant(1.0), ty)?,
            outside: tp.spectrum_texture("outside", Spectrum::constant(0.0), ty)?,
        }),
        "marble" => SpectrumTexture::Marble(MarbleTexture {
            mapping: TextureMapping3D::new(&rft),
            octaves: octaves(tp)?,
            omega: tp.float("roughness", 0.5)?,
            scale: tp.float("scale", 1.0)?,
            variation: tp.float("variation", 0.2)?,
        }),
        "ptex" => SpectrumTexture::Ptex(SpectrumPtexTexture {
            base: ptex_base(def, tp)?,
            spectrum_type: ty,
        }),
        // pbrt-v3's spectrum versions of the noise textures: the float
        // value in every channel.
        "fbm" | "wrinkled" | "windy" => {
            SpectrumTexture::Grey(create_float_texture(def, tp, cache, options)?)
        }
        "uv" => SpectrumTexture::Uv(UvTexture {
            mapping: TextureMapping2D::create(tp, &rft)?,
        }),
        other => {
            return Err(unknown_type(
                "spectrum texture",
                other,
                SPECTRUM_TEXTURE_NAMES,
                tp.loc(),
            ))
        }
    };
    Ok(Arc::new(tex))
}
