//! Materials from the parameters of `Material` and `MakeNamedMaterial`
//! directives (pbrt-v4 `Material::Create` and the `Create` methods in
//! `materials.cpp`). The scene decides which named materials a `mix` may
//! use (pbrt-v4 `BasicScene::CreateMaterials`).

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use rpbrt_geometry::float::Float;
use rpbrt_parser::Diagnostic;

use super::coated::LayerSettings;
use super::*;
use crate::bxdf::{FourierBSDFTable, IrregularBrdf, MeasuredBxDFData, MerlTable, LAFORTUNE_FITS};
use crate::image::Image;
use crate::params::unknown_type;
use crate::spectrum::{
    named_spectrum, RgbColorSpace, RgbUnboundedSpectrum, Spectrum, SpectrumType, RGB,
};
use crate::texture::{FloatTexture, SpectrumTexture, SpectrumTextureRef, TextureParams};

/// The material types `Material` and `MakeNamedMaterial` accept, sorted
/// (`""` and `"none"` also mean `interface`, as in pbrt-v4).
pub const MATERIAL_NAMES: &[&str] = &[
    "bluepaint",
    "brushedmetal",
    "clay",
    "coatedconductor",
    "coateddiffuse",
    "conductor",
    "dielectric",
    "diffuse",
    "diffusetransmission",
    "disney",
    "felt",
    "fourier",
    "hair",
    "interface",
    "measured",
    "mix",
    "primer",
    "shinymetal",
    "skin",
    "subsurface",
    "thindielectric",
];

/// Whether the file at `path` starts like a MERL table.
fn is_merl_file(path: &std::path::Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 12];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && MerlTable::looks_like(&head)
}

/// Image files already read as normal maps, by path (one load per file).
pub type NormalMapCache = HashMap<PathBuf, Arc<Image>>;

/// `{prefix}uroughness` / `{prefix}vroughness`, each defaulting to
/// `{prefix}roughness` (0), and `remaproughness`.
fn roughness(tp: &TextureParams, prefix: &str) -> Result<Roughness, Diagnostic> {
    let nonneg: fn(Float) -> bool = |v| v >= 0.0;
    let what = "roughness must not be negative";
    let get = |axis: &str| -> Result<FloatTextureRef, Diagnostic> {
        let name = format!("{prefix}{axis}roughness");
        match tp.float_texture_opt(&name)? {
            Some(t) => {
                tp.check_constant(&name, &t, nonneg, what)?;
                Ok(t)
            }
            None => tp.checked_float_texture(&format!("{prefix}roughness"), 0.0, nonneg, what),
        }
    };
    let u = get("u")?;
    let v = get("v")?;
    let remap = tp.bool("remaproughness", true)?;
    Ok(Roughness { u, v, remap })
}

/// An index of refraction given as `float` (first value) or as a
/// spectrum; `default` when absent. Constant values must be positive.
fn eta_spectrum(tp: &TextureParams, name: &str, default: Float) -> Result<Spectrum, Diagnostic> {
    let ty = tp.param_type(name);
    let s = match ty {
        Some("float") => {
            let v = tp.floats(name)?;
            Spectrum::constant(v.first().copied().unwrap_or(default))
        }
        Some("rgb") | Some("spectrum") | Some("blackbody") => {
            match tp.spectrum(name, SpectrumType::Unbounded)? {
                Some(s) => s,
                None => return Ok(Spectrum::constant(default)),
            }
        }
        // Textures are not accepted for eta here (as in pbrt-v4); the
        // parameter stays unused and is reported.
        _ => Spectrum::constant(default),
    };
    if let Spectrum::Constant(c) = s {
        if c.is_nan() || c <= 0.0 {
            return Err(tp.invalid(
                name,
                format!("index of refraction must be positive (got {c})"),
            ));
        }
    }
    Ok(s)
}

/// η and k (Cu by default) or a `reflectance`, not both.
fn conductor_spectra(
    tp: &TextureParams,
    eta_name: &str,
    k_name: &str,
) -> Result<ConductorSpectra, Diagnostic> {
    let eta = tp.spectrum_texture_opt(eta_name, SpectrumType::Unbounded)?;
    let k = tp.spectrum_texture_opt(k_name, SpectrumType::Unbounded)?;
    let reflectance = tp.spectrum_texture_opt("reflectance", SpectrumType::Albedo)?;
    if let Some(r) = reflectance {
        if eta.is_some() || k.is_some() {
            let which = if eta.is_some() { eta_name } else { k_name };
            return Err(Diagnostic::error(
                tp.param_loc("reflectance"),
                format!(
                    "\"reflectance\" and \"{which}\" can't both be given: either the \
                         complex index of refraction or a reflectance describes the metal"
                ),
            ));
        }
        return Ok(ConductorSpectra::Reflectance(r));
    }
    let cu = |n: &str| -> Result<SpectrumTextureRef, Diagnostic> {
        let s = named_spectrum(n).ok_or_else(|| {
            Diagnostic::error(tp.loc().clone(), format!("missing named spectrum \"{n}\""))
        })?;
        Ok(Arc::new(SpectrumTexture::Constant(s)))
    };
    Ok(ConductorSpectra::EtaK {
        eta: match eta {
            Some(t) => t,
            None => cu("metal-Cu-eta")?,
        },
        k: match k {
            Some(t) => t,
            None => cu("metal-Cu-k")?,
        },
    })
}

fn layer(tp: &TextureParams) -> Result<LayerSettings, Diagnostic> {
    let thickness = tp.checked_float_texture(
        "thickness",
        0.01,
        |v| v >= 0.0,
        "thickness must not be negative",
    )?;
    let max_depth = tp.int("maxdepth", 10)?;
    if max_depth < 0 {
        return Err(tp.invalid(
            "maxdepth",
            format!("must not be negative (got {max_depth})"),
        ));
    }
    let n_samples = tp.int("nsamples", 1)?;
    if n_samples < 1 {
        return Err(tp.invalid("nsamples", format!("must be at least 1 (got {n_samples})")));
    }
    let g = tp.float_texture("g", 0.0)?;
    let albedo = tp.spectrum_texture("albedo", Spectrum::constant(0.0), SpectrumType::Albedo)?;
    Ok(LayerSettings {
        thickness,
        albedo,
        g,
        max_depth: max_depth as u32,
        n_samples: n_samples as u32,
    })
}

/// `displacement` and `normalmap` (an image file relative to the scene
/// file, loaded once per path).
fn perturbation(
    tp: &TextureParams,
    cache: &mut NormalMapCache,
) -> Result<ShadingPerturbation, Diagnostic> {
    let displacement = tp.float_texture_opt("displacement")?;
    let file = tp.string("normalmap", "")?;
    let normal_map = if file.is_empty() {
        None
    } else {
        let loc = tp.param_loc("normalmap");
        let path = tp.resolve("normalmap", &file);
        if let Some(im) = cache.get(&path) {
            Some(im.clone())
        } else {
            let im = Arc::new(
                read_normal_map(&path, tp.budget())
                    .map_err(|m| Diagnostic::error(loc.clone(), m))?,
            );
            cache.insert(path, im.clone());
            Some(im)
        }
    };
    Ok(ShadingPerturbation {
        displacement,
        normal_map,
    })
}

/// Reads `normalmap` for materials that ignore it, with a warning.
fn ignore_normal_map(tp: &TextureParams, ty: &str) -> Result<(), Diagnostic> {
    if !tp.string("normalmap", "")?.is_empty() {
        tp.warn_at(
            "normalmap",
            format!("\"{ty}\" materials ignore \"normalmap\""),
        );
    }
    Ok(())
}

/// Creates the material of type `ty` (pbrt-v4 `Material::Create`) from
/// its parameters. `visible` gives the index of a named material a `mix`
/// may use, or why it may not; normal maps are read once per file through
/// `cache`.
pub fn create_material(
    ty: &str,
    tp: &TextureParams,
    visible: &dyn Fn(&str) -> Result<u32, String>,
    cache: &mut NormalMapCache,
) -> Result<Material, Diagnostic> {
    let albedo = SpectrumType::Albedo;
    Ok(match ty {
        "" | "none" | "interface" => Material::Interface,
        "diffuse" => Material::Diffuse(DiffuseMaterial {
            reflectance: tp.spectrum_texture("reflectance", Spectrum::constant(0.5), albedo)?,
            perturbation: perturbation(tp, cache)?,
        }),
        "diffusetransmission" => Material::DiffuseTransmission(DiffuseTransmissionMaterial {
            reflectance: tp.spectrum_texture("reflectance", Spectrum::constant(0.25), albedo)?,
            transmittance: tp.spectrum_texture(
                "transmittance",
                Spectrum::constant(0.25),
                albedo,
            )?,
            scale: tp.float("scale", 1.0)?,
            perturbation: perturbation(tp, cache)?,
        }),
        "conductor" => Material::Conductor(ConductorMaterial {
            spectra: conductor_spectra(tp, "eta", "k")?,
            roughness: roughness(tp, "")?,
            perturbation: perturbation(tp, cache)?,
        }),
        "dielectric" => Material::Dielectric(DielectricMaterial {
            eta: eta_spectrum(tp, "eta", 1.5)?,
            roughness: roughness(tp, "")?,
            perturbation: perturbation(tp, cache)?,
        }),
        "thindielectric" => Material::ThinDielectric(ThinDielectricMaterial {
            eta: eta_spectrum(tp, "eta", 1.5)?,
            perturbation: perturbation(tp, cache)?,
        }),
        "coateddiffuse" => Material::CoatedDiffuse(Box::new(CoatedDiffuseMaterial {
            reflectance: tp.spectrum_texture("reflectance", Spectrum::constant(0.5), albedo)?,
            roughness: roughness(tp, "")?,
            eta: eta_spectrum(tp, "eta", 1.5)?,
            layer: layer(tp)?,
            perturbation: perturbation(tp, cache)?,
        })),
        "coatedconductor" => Material::CoatedConductor(Box::new(CoatedConductorMaterial {
            interface_roughness: roughness(tp, "interface.")?,
            interface_eta: eta_spectrum(tp, "interface.eta", 1.5)?,
            conductor: conductor_spectra(tp, "conductor.eta", "conductor.k")?,
            conductor_roughness: roughness(tp, "conductor.")?,
            layer: layer(tp)?,
            perturbation: perturbation(tp, cache)?,
        })),
        "hair" => create_hair(tp)?,
        "disney" => create_disney(tp, cache)?,
        "fourier" => {
            let file = tp.string("bsdffile", "")?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    tp.loc().clone(),
                    "\"fourier\" material: \"bsdffile\" must be provided",
                ));
            }
            let loc = tp.param_loc("bsdffile");
            let path = tp.resolve("bsdffile", &file);
            let table = FourierBSDFTable::cached(&path)
                .map_err(|e| Diagnostic::error(loc.clone(), format!("{}: {e}", path.display())))?;
            Material::Fourier(Box::new(FourierMaterial {
                table,
                perturbation: perturbation(tp, cache)?,
            }))
        }
        "mix" => create_mix(tp, visible)?,
        "bluepaint" | "brushedmetal" | "clay" | "felt" | "primer" | "skin" => {
            let Some(fit) = LAFORTUNE_FITS.iter().find(|f| f.name == ty) else {
                return Err(unknown_type("material", ty, MATERIAL_NAMES, tp.loc()));
            };
            Material::Lafortune(Box::new(LafortuneMaterial {
                fit,
                color_space: tp.color_space(),
                perturbation: perturbation(tp, cache)?,
            }))
        }
        "shinymetal" => Material::ShinyMetal(Box::new(ShinyMetalMaterial {
            ks: tp.spectrum_texture("Ks", Spectrum::constant(1.0), albedo)?,
            kr: tp.spectrum_texture("Kr", Spectrum::constant(1.0), albedo)?,
            roughness: tp.float_texture("roughness", 0.1)?,
            perturbation: perturbation(tp, cache)?,
        })),
        "subsurface" => create_subsurface(tp, cache)?,
        "measured" => {
            let file = tp.string("filename", "")?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    tp.loc().clone(),
                    "\"measured\" material: \"filename\" must be provided",
                ));
            }
            let loc = tp.param_loc("filename");
            let path = tp.resolve("filename", &file);
            // pbrt-v2 read MERL tables (any suffix but .brdf) and its own
            // irregular .brdf samples; pbrt-v4 reads RGL .bsdf files.
            let ext = path
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            if ext.as_deref() == Some("brdf") {
                let data = IrregularBrdf::cached(&path).map_err(|m| {
                    Diagnostic::error(loc.clone(), format!("{}: {m}", path.display()))
                })?;
                return Ok(Material::Irregular(Box::new(IrregularMaterial {
                    data,
                    perturbation: perturbation(tp, cache)?,
                })));
            }
            if ext.as_deref() != Some("bsdf") && is_merl_file(&path) {
                let table = MerlTable::cached(&path).map_err(|m| {
                    Diagnostic::error(loc.clone(), format!("{}: {m}", path.display()))
                })?;
                return Ok(Material::Merl(Box::new(MerlMaterial {
                    table,
                    color_space: tp.color_space(),
                    perturbation: perturbation(tp, cache)?,
                })));
            }
            let data =
                MeasuredBxDFData::cached(&path).map_err(|m| Diagnostic::error(loc.clone(), m))?;
            Material::Measured(Box::new(MeasuredMaterial {
                data,
                perturbation: perturbation(tp, cache)?,
            }))
        }
        _ => return Err(unknown_type("material", ty, MATERIAL_NAMES, tp.loc())),
    })
}

/// pbrt-v3's `CreateDisneyMaterial`: every parameter a texture, with
/// pbrt-v3's defaults.
fn create_disney(tp: &TextureParams, cache: &mut NormalMapCache) -> Result<Material, Diagnostic> {
    let f = |name: &str, default: Float| tp.float_texture(name, default);
    let eta = tp.checked_float_texture(
        "eta",
        1.5,
        |v| v > 0.0,
        "index of refraction must be positive",
    )?;
    // pbrt-v3 replaces the diffuse lobe of a solid surface with its Disney
    // BSSRDF where "scatterdistance" is not black; a constant black one is
    // the same as none.
    let thin = tp.bool("thin", false)?;
    let scatter_distance = tp
        .spectrum_texture_opt("scatterdistance", SpectrumType::Unbounded)?
        .filter(|sd| {
            !thin && !matches!(&**sd, SpectrumTexture::Constant(s) if s.max_value() <= 0.0)
        });
    Ok(Material::Disney(Box::new(DisneyMaterial {
        color: tp.spectrum_texture("color", Spectrum::constant(0.5), SpectrumType::Albedo)?,
        metallic: f("metallic", 0.0)?,
        eta,
        roughness: f("roughness", 0.5)?,
        specular_tint: f("speculartint", 0.0)?,
        anisotropic: f("anisotropic", 0.0)?,
        sheen: f("sheen", 0.0)?,
        sheen_tint: f("sheentint", 0.5)?,
        clearcoat: f("clearcoat", 0.0)?,
        clearcoat_gloss: f("clearcoatgloss", 1.0)?,
        spec_trans: f("spectrans", 0.0)?,
        thin,
        flatness: f("flatness", 0.0)?,
        diff_trans: f("difftrans", 1.0)?,
        scatter_distance,
        perturbation: perturbation(tp, cache)?,
    })))
}

fn create_hair(tp: &TextureParams) -> Result<Material, Diagnostic> {
    let sigma_a = tp.spectrum_texture_opt("sigma_a", SpectrumType::Unbounded)?;
    let reflectance = tp.spectrum_texture_opt("reflectance", SpectrumType::Albedo)?;
    let eumelanin = tp.float_texture_opt("eumelanin")?;
    let pheomelanin = tp.float_texture_opt("pheomelanin")?;
    let absorption = if let Some(s) = sigma_a {
        for (given, name) in [
            (reflectance.is_some(), "reflectance"),
            (eumelanin.is_some(), "eumelanin"),
            (pheomelanin.is_some(), "pheomelanin"),
        ] {
            if given {
                tp.warn(format!(
                    "ignoring \"{name}\" parameter since \"sigma_a\" was provided"
                ));
            }
        }
        HairAbsorption::SigmaA(s)
    } else if let Some(r) = reflectance {
        if eumelanin.is_some() || pheomelanin.is_some() {
            tp.warn("ignoring \"eumelanin\"/\"pheomelanin\" since \"reflectance\" was provided");
        }
        HairAbsorption::Reflectance(r)
    } else if eumelanin.is_some() || pheomelanin.is_some() {
        let zero = || Arc::new(FloatTexture::Constant(0.0));
        HairAbsorption::Melanin {
            eumelanin: eumelanin.unwrap_or_else(zero),
            pheomelanin: pheomelanin.unwrap_or_else(zero),
        }
    } else {
        // pbrt-v4's default: brown hair (eumelanin 1.3) as an sRGB σa.
        let rgb: RGB = crate::bxdf::HairBxDF::sigma_a_from_concentration(1.3, 0.0);
        let s = Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(RgbColorSpace::srgb(), rgb));
        HairAbsorption::SigmaA(Arc::new(SpectrumTexture::Constant(s)))
    };
    let eta = tp.checked_float_texture(
        "eta",
        1.55,
        |v| v > 0.0,
        "index of refraction must be positive",
    )?;
    let beta_m = tp.float_texture("beta_m", 0.3)?;
    let beta_n = tp.float_texture("beta_n", 0.3)?;
    let alpha = tp.float_texture("alpha", 2.0)?;
    ignore_normal_map(tp, "hair")?;
    Ok(Material::Hair(HairMaterial {
        absorption,
        eta,
        beta_m,
        beta_n,
        alpha,
    }))
}

fn create_mix(
    tp: &TextureParams,
    visible: &dyn Fn(&str) -> Result<u32, String>,
) -> Result<Material, Diagnostic> {
    let names = tp.strings("materials")?;
    if names.len() != 2 {
        return Err(Diagnostic::error(
            tp.param_loc("materials"),
            format!(
                "mix material needs exactly two names in \"string materials\" (got {})",
                names.len()
            ),
        ));
    }
    let mut materials = [0u32; 2];
    for (slot, name) in materials.iter_mut().zip(&names) {
        *slot = visible(name).map_err(|m| Diagnostic::error(tp.param_loc("materials"), m))?;
    }
    let amount = tp.float_texture("amount", 0.5)?;
    ignore_normal_map(tp, "mix")?;
    Ok(Material::Mix(MixMaterial { materials, amount }))
}

fn create_subsurface(
    tp: &TextureParams,
    cache: &mut NormalMapCache,
) -> Result<Material, Diagnostic> {
    let mut g = tp.float("g", 0.0)?;
    let name = tp.string("name", "")?;
    let constant = |s: Spectrum| -> SpectrumTextureRef { Arc::new(SpectrumTexture::Constant(s)) };
    let coefficients = if !name.is_empty() {
        let Some((sa, ss)) = get_medium_scattering_properties(&name) else {
            let known: Vec<&str> = crate::medium::measured::measured_medium_names().collect();
            return Err(Diagnostic::error(
                tp.param_loc("name"),
                format!(
                    "\"{name}\": named medium not found (known: {})",
                    known.join(", ")
                ),
            ));
        };
        if g != 0.0 {
            tp.warn("non-zero \"g\" ignored with named scattering coefficients");
        }
        // The table gives reduced scattering coefficients.
        g = 0.0;
        SubsurfaceCoefficients::Coefficients {
            sigma_a: constant(sa),
            sigma_s: constant(ss),
        }
    } else {
        let sigma_a = tp.spectrum_texture_opt("sigma_a", SpectrumType::Unbounded)?;
        let sigma_s = tp.spectrum_texture_opt("sigma_s", SpectrumType::Unbounded)?;
        match (sigma_a, sigma_s) {
            (Some(sigma_a), Some(sigma_s)) => {
                SubsurfaceCoefficients::Coefficients { sigma_a, sigma_s }
            }
            (Some(_), None) => {
                return Err(Diagnostic::error(
                    tp.param_loc("sigma_a"),
                    "\"sigma_a\" given without \"sigma_s\"",
                ))
            }
            (None, Some(_)) => {
                return Err(Diagnostic::error(
                    tp.param_loc("sigma_s"),
                    "\"sigma_s\" given without \"sigma_a\"",
                ))
            }
            (None, None) => {
                if let Some(reflectance) =
                    tp.spectrum_texture_opt("reflectance", SpectrumType::Albedo)?
                {
                    let mfp = tp.spectrum_texture(
                        "mfp",
                        Spectrum::constant(1.0),
                        SpectrumType::Unbounded,
                    )?;
                    SubsurfaceCoefficients::Reflectance { reflectance, mfp }
                } else {
                    // pbrt-v4's default: whole milk, in sRGB.
                    let srgb = RgbColorSpace::srgb();
                    let rgb = |r, g, b| {
                        constant(Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(
                            srgb,
                            RGB::new(r, g, b),
                        )))
                    };
                    SubsurfaceCoefficients::Coefficients {
                        sigma_a: rgb(0.0011, 0.0024, 0.014),
                        sigma_s: rgb(2.55, 3.21, 3.77),
                    }
                }
            }
        }
    };
    let scale = tp.float("scale", 1.0)?;
    let eta = tp.float("eta", 1.33)?;
    if eta.is_nan() || eta <= 0.0 {
        return Err(tp.invalid(
            "eta",
            format!("index of refraction must be positive (got {eta})"),
        ));
    }
    Ok(Material::Subsurface(Box::new(SubsurfaceMaterial {
        scale,
        coefficients,
        g,
        eta,
        roughness: roughness(tp, "")?,
        perturbation: perturbation(tp, cache)?,
    })))
}
