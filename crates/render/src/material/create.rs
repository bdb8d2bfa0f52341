//! Materials from `Material` and `MakeNamedMaterial` directives (pbrt-v4
//! `Material::Create` and the `Create` methods in `materials.cpp`,
//! `BasicScene::CreateMaterials` in `scene.cpp`).
//!
//! Anonymous materials keep their indices `0..n` (the scene description's
//! `MaterialRef::Index`); named ones follow in definition order. As in
//! pbrt-v4, named materials are created in definition order, so a named
//! `mix` may only use named materials defined before it; anonymous ones
//! may use any.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use rpbrt_geometry::float::Float;
use rpbrt_parser::params::canonical_type;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary};

use super::coated::LayerSettings;
use super::*;
use crate::bxdf::MeasuredBxDFData;
use crate::image::Image;
use crate::scene::entities::SceneEntity;
use crate::scene::names::EntityKind;
use crate::spectrum::{
    named_spectrum, spectrum_from_param, RgbColorSpace, RgbUnboundedSpectrum, Spectrum,
    SpectrumType, RGB,
};
use crate::texture::{
    get_float_texture, get_float_texture_opt, get_spectrum_texture, FloatTexture, NamedTextures,
    SpectrumTexture, SpectrumTextureRef,
};

/// Creates every material of a scene: `materials` (anonymous, indices
/// `0..materials.len()`) and `named_materials` (indices following, in
/// order). Returns the set, the index of each named material and the
/// warnings (unused parameters...), or every error and warning.
#[allow(clippy::type_complexity)]
pub fn create_materials(
    materials: &[SceneEntity],
    named_materials: &[(String, SceneEntity)],
    textures: &NamedTextures,
) -> Result<(MaterialSet, HashMap<String, u32>, Vec<Diagnostic>), Vec<Diagnostic>> {
    let n_anon = materials.len();
    let mut diags = Vec::new();
    let mut normal_maps: HashMap<PathBuf, Arc<Image>> = HashMap::new();
    let mut out: Vec<Option<Material>> = vec![None; n_anon + named_materials.len()];
    // Every named material's index, and how many were defined before each.
    let all_named: HashMap<&str, (usize, u32)> = named_materials
        .iter()
        .enumerate()
        .map(|(j, (name, _))| (name.as_str(), (j, (n_anon + j) as u32)))
        .collect();
    let mut failed = false;

    let mut create = |e: &SceneEntity,
                      ty: &str,
                      visible: &dyn Fn(&str) -> Result<u32, String>,
                      diags: &mut Vec<Diagnostic>|
     -> Option<Material> {
        let mut cx = match Ctx::new(e, textures, diags) {
            Ok(cx) => cx,
            Err(d) => {
                diags.push(d);
                return None;
            }
        };
        let r = create_material(ty, &mut cx, visible, &mut normal_maps);
        match r {
            Ok(m) => {
                diags.extend(e.params.report_unused());
                Some(m)
            }
            Err(d) => {
                diags.push(d);
                None
            }
        }
    };

    for (j, (name, e)) in named_materials.iter().enumerate() {
        let ty = match e.params.get_one_string("type", "") {
            Ok(t) if !t.is_empty() => t,
            Ok(_) => e.name.clone(),
            Err(err) => {
                diags.push(err.into());
                failed = true;
                continue;
            }
        };
        let visible = |m: &str| match all_named.get(m) {
            Some(&(k, index)) if k < j => Ok(index),
            Some(_) => Err(format!(
                "named material \"{m}\" is used by \"{name}\" before it is defined"
            )),
            None => Err(format!("\"{m}\": named material not defined")),
        };
        match create(e, &ty, &visible, &mut diags) {
            Some(m) => out[n_anon + j] = Some(m),
            None => failed = true,
        }
    }
    for (i, e) in materials.iter().enumerate() {
        let visible = |m: &str| match all_named.get(m) {
            Some(&(_, index)) => Ok(index),
            None => Err(format!("\"{m}\": named material not defined")),
        };
        match create(e, &e.name, &visible, &mut diags) {
            Some(m) => out[i] = Some(m),
            None => failed = true,
        }
    }
    if failed {
        return Err(diags);
    }
    let set: Vec<Material> = out.into_iter().flatten().collect();
    debug_assert_eq!(set.len(), n_anon + named_materials.len());
    let named = all_named
        .into_iter()
        .map(|(k, (_, index))| (k.to_string(), index))
        .collect();
    let locs = materials
        .iter()
        .chain(named_materials.iter().map(|(_, e)| e))
        .map(|e| e.loc.clone())
        .collect();
    Ok((MaterialSet::new(set).with_locs(locs), named, diags))
}

/// One material's parameters and what reading them needs.
struct Ctx<'a> {
    params: &'a ParameterDictionary,
    loc: &'a FileLoc,
    cs: &'static RgbColorSpace,
    textures: &'a NamedTextures,
    warnings: &'a mut Vec<Diagnostic>,
}

/// The directory file names in `loc`'s file resolve against.
fn dir_of(loc: &FileLoc) -> &Path {
    Path::new(&*loc.file)
        .parent()
        .unwrap_or_else(|| Path::new("."))
}

impl<'a> Ctx<'a> {
    fn new(
        e: &'a SceneEntity,
        textures: &'a NamedTextures,
        warnings: &'a mut Vec<Diagnostic>,
    ) -> Result<Self, Diagnostic> {
        let Some(cs) = RgbColorSpace::get(&e.color_space) else {
            return Err(Diagnostic::error(
                e.loc.clone(),
                format!("\"{}\": unknown color space", e.color_space),
            ));
        };
        Ok(Ctx {
            params: &e.params,
            loc: &e.loc,
            cs,
            textures,
            warnings,
        })
    }

    /// Where parameter `name` was written, or the directive.
    fn ploc(&self, name: &str) -> FileLoc {
        self.params.loc(name).unwrap_or(self.loc).clone()
    }

    fn err(&self, name: &str, msg: impl Into<String>) -> Diagnostic {
        Diagnostic::error(
            self.ploc(name),
            format!("parameter \"{name}\": {}", msg.into()),
        )
    }

    fn ftex(&self, name: &str, default: Float) -> Result<FloatTextureRef, Diagnostic> {
        get_float_texture(self.params, name, default, self.textures)
    }

    fn ftex_opt(&self, name: &str) -> Result<Option<FloatTextureRef>, Diagnostic> {
        get_float_texture_opt(self.params, name, self.textures)
    }

    /// A float texture whose constant value must satisfy `ok`.
    fn checked_ftex(
        &self,
        name: &str,
        default: Float,
        ok: fn(Float) -> bool,
        what: &str,
    ) -> Result<FloatTextureRef, Diagnostic> {
        let t = self.ftex(name, default)?;
        self.check_constant(name, &t, ok, what)?;
        Ok(t)
    }

    fn check_constant(
        &self,
        name: &str,
        t: &FloatTexture,
        ok: fn(Float) -> bool,
        what: &str,
    ) -> Result<(), Diagnostic> {
        match t {
            FloatTexture::Constant(v) if !ok(*v) => {
                Err(self.err(name, format!("{what} (got {v})")))
            }
            _ => Ok(()),
        }
    }

    fn stex_opt(
        &self,
        name: &str,
        ty: SpectrumType,
    ) -> Result<Option<SpectrumTextureRef>, Diagnostic> {
        get_spectrum_texture(self.params, name, None, ty, self.cs, self.textures)
    }

    fn stex(
        &self,
        name: &str,
        default: Spectrum,
        ty: SpectrumType,
    ) -> Result<SpectrumTextureRef, Diagnostic> {
        let t = get_spectrum_texture(self.params, name, Some(default), ty, self.cs, self.textures)?;
        // With a default the lookup always gives a texture.
        Ok(t.unwrap_or_else(|| Arc::new(SpectrumTexture::Constant(Spectrum::constant(0.0)))))
    }

    fn one_float(&self, name: &str, default: Float) -> Result<Float, Diagnostic> {
        Ok(self.params.get_one_float(name, default)?)
    }

    fn one_int(&self, name: &str, default: i32) -> Result<i32, Diagnostic> {
        Ok(self.params.get_one_int(name, default)?)
    }

    /// `{prefix}uroughness` / `{prefix}vroughness`, each defaulting to
    /// `{prefix}roughness` (0), and `remaproughness`.
    fn roughness(&self, prefix: &str) -> Result<Roughness, Diagnostic> {
        let nonneg: fn(Float) -> bool = |v| v >= 0.0;
        let what = "roughness must not be negative";
        let get = |axis: &str| -> Result<FloatTextureRef, Diagnostic> {
            let name = format!("{prefix}{axis}roughness");
            match self.ftex_opt(&name)? {
                Some(t) => {
                    self.check_constant(&name, &t, nonneg, what)?;
                    Ok(t)
                }
                None => self.checked_ftex(&format!("{prefix}roughness"), 0.0, nonneg, what),
            }
        };
        let u = get("u")?;
        let v = get("v")?;
        let remap = self.params.get_one_bool("remaproughness", true)?;
        Ok(Roughness { u, v, remap })
    }

    /// An index of refraction given as `float` (first value) or as a
    /// spectrum; `default` when absent. Constant values must be positive.
    fn eta_spectrum(&self, name: &str, default: Float) -> Result<Spectrum, Diagnostic> {
        let ty = self
            .params
            .param_type(name)
            .map(|t| canonical_type(t).unwrap_or(t));
        let s = match ty {
            Some("float") => {
                let v = self.params.get_float_array(name)?;
                Spectrum::constant(v.first().copied().unwrap_or(default))
            }
            Some("rgb") | Some("spectrum") | Some("blackbody") => {
                let Some(v) = self.params.get_one_spectrum(name)? else {
                    return Ok(Spectrum::constant(default));
                };
                let loc = self.ploc(name);
                spectrum_from_param(&v, SpectrumType::Unbounded, self.cs, dir_of(&loc))
                    .map_err(|m| self.err(name, m))?
            }
            // Textures are not accepted for eta here (as in pbrt-v4); the
            // parameter stays unused and is reported.
            _ => Spectrum::constant(default),
        };
        if let Spectrum::Constant(c) = s {
            if c.is_nan() || c <= 0.0 {
                return Err(self.err(
                    name,
                    format!("index of refraction must be positive (got {c})"),
                ));
            }
        }
        Ok(s)
    }

    /// η and k (Cu by default) or a `reflectance`, not both.
    fn conductor_spectra(
        &self,
        eta_name: &str,
        k_name: &str,
    ) -> Result<ConductorSpectra, Diagnostic> {
        let eta = self.stex_opt(eta_name, SpectrumType::Unbounded)?;
        let k = self.stex_opt(k_name, SpectrumType::Unbounded)?;
        let reflectance = self.stex_opt("reflectance", SpectrumType::Albedo)?;
        if let Some(r) = reflectance {
            if eta.is_some() || k.is_some() {
                let which = if eta.is_some() { eta_name } else { k_name };
                return Err(Diagnostic::error(
                    self.ploc("reflectance"),
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
                Diagnostic::error(self.loc.clone(), format!("missing named spectrum \"{n}\""))
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

    fn layer(&self) -> Result<LayerSettings, Diagnostic> {
        let thickness = self.checked_ftex(
            "thickness",
            0.01,
            |v| v >= 0.0,
            "thickness must not be negative",
        )?;
        let max_depth = self.one_int("maxdepth", 10)?;
        if max_depth < 0 {
            return Err(self.err(
                "maxdepth",
                format!("must not be negative (got {max_depth})"),
            ));
        }
        let n_samples = self.one_int("nsamples", 1)?;
        if n_samples < 1 {
            return Err(self.err("nsamples", format!("must be at least 1 (got {n_samples})")));
        }
        let g = self.ftex("g", 0.0)?;
        let albedo = self.stex("albedo", Spectrum::constant(0.0), SpectrumType::Albedo)?;
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
        &self,
        cache: &mut HashMap<PathBuf, Arc<Image>>,
    ) -> Result<ShadingPerturbation, Diagnostic> {
        let displacement = self.ftex_opt("displacement")?;
        let file = self.params.get_one_string("normalmap", "")?;
        let normal_map = if file.is_empty() {
            None
        } else {
            let loc = self.ploc("normalmap");
            let path = dir_of(&loc).join(&file);
            if let Some(im) = cache.get(&path) {
                Some(im.clone())
            } else {
                let im = Arc::new(
                    read_normal_map(&path).map_err(|m| Diagnostic::error(loc.clone(), m))?,
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
    fn ignore_normal_map(&mut self, ty: &str) -> Result<(), Diagnostic> {
        if !self.params.get_one_string("normalmap", "")?.is_empty() {
            let loc = self.ploc("normalmap");
            self.warnings.push(Diagnostic::warning(
                loc,
                format!("\"{ty}\" materials ignore \"normalmap\""),
            ));
        }
        Ok(())
    }

    fn warn(&mut self, msg: impl Into<String>) {
        self.warnings
            .push(Diagnostic::warning(self.loc.clone(), msg));
    }
}

fn create_material(
    ty: &str,
    cx: &mut Ctx,
    visible: &dyn Fn(&str) -> Result<u32, String>,
    cache: &mut HashMap<PathBuf, Arc<Image>>,
) -> Result<Material, Diagnostic> {
    EntityKind::Material.check(ty, cx.loc)?;
    let albedo = SpectrumType::Albedo;
    Ok(match ty {
        "" | "none" | "interface" => Material::Interface,
        "diffuse" => Material::Diffuse(DiffuseMaterial {
            reflectance: cx.stex("reflectance", Spectrum::constant(0.5), albedo)?,
            perturbation: cx.perturbation(cache)?,
        }),
        "diffusetransmission" => Material::DiffuseTransmission(DiffuseTransmissionMaterial {
            reflectance: cx.stex("reflectance", Spectrum::constant(0.25), albedo)?,
            transmittance: cx.stex("transmittance", Spectrum::constant(0.25), albedo)?,
            scale: cx.one_float("scale", 1.0)?,
            perturbation: cx.perturbation(cache)?,
        }),
        "conductor" => Material::Conductor(ConductorMaterial {
            spectra: cx.conductor_spectra("eta", "k")?,
            roughness: cx.roughness("")?,
            perturbation: cx.perturbation(cache)?,
        }),
        "dielectric" => Material::Dielectric(DielectricMaterial {
            eta: cx.eta_spectrum("eta", 1.5)?,
            roughness: cx.roughness("")?,
            perturbation: cx.perturbation(cache)?,
        }),
        "thindielectric" => Material::ThinDielectric(ThinDielectricMaterial {
            eta: cx.eta_spectrum("eta", 1.5)?,
            perturbation: cx.perturbation(cache)?,
        }),
        "coateddiffuse" => Material::CoatedDiffuse(Box::new(CoatedDiffuseMaterial {
            reflectance: cx.stex("reflectance", Spectrum::constant(0.5), albedo)?,
            roughness: cx.roughness("")?,
            eta: cx.eta_spectrum("eta", 1.5)?,
            layer: cx.layer()?,
            perturbation: cx.perturbation(cache)?,
        })),
        "coatedconductor" => Material::CoatedConductor(Box::new(CoatedConductorMaterial {
            interface_roughness: cx.roughness("interface.")?,
            interface_eta: cx.eta_spectrum("interface.eta", 1.5)?,
            conductor: cx.conductor_spectra("conductor.eta", "conductor.k")?,
            conductor_roughness: cx.roughness("conductor.")?,
            layer: cx.layer()?,
            perturbation: cx.perturbation(cache)?,
        })),
        "hair" => create_hair(cx)?,
        "mix" => create_mix(cx, visible)?,
        "subsurface" => create_subsurface(cx, cache)?,
        "measured" => {
            let file = cx.params.get_one_string("filename", "")?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    cx.loc.clone(),
                    "\"measured\" material: \"filename\" must be provided",
                ));
            }
            let loc = cx.ploc("filename");
            let path = dir_of(&loc).join(&file);
            let data =
                MeasuredBxDFData::cached(&path).map_err(|m| Diagnostic::error(loc.clone(), m))?;
            Material::Measured(Box::new(MeasuredMaterial {
                data,
                perturbation: cx.perturbation(cache)?,
            }))
        }
        _ => {
            return Err(Diagnostic::error(
                cx.loc.clone(),
                format!("\"{ty}\": material type not handled"),
            ))
        }
    })
}

fn create_hair(cx: &mut Ctx) -> Result<Material, Diagnostic> {
    let sigma_a = cx.stex_opt("sigma_a", SpectrumType::Unbounded)?;
    let reflectance = cx.stex_opt("reflectance", SpectrumType::Albedo)?;
    let eumelanin = cx.ftex_opt("eumelanin")?;
    let pheomelanin = cx.ftex_opt("pheomelanin")?;
    let absorption = if let Some(s) = sigma_a {
        for (given, name) in [
            (reflectance.is_some(), "reflectance"),
            (eumelanin.is_some(), "eumelanin"),
            (pheomelanin.is_some(), "pheomelanin"),
        ] {
            if given {
                cx.warn(format!(
                    "ignoring \"{name}\" parameter since \"sigma_a\" was provided"
                ));
            }
        }
        HairAbsorption::SigmaA(s)
    } else if let Some(r) = reflectance {
        if eumelanin.is_some() || pheomelanin.is_some() {
            cx.warn("ignoring \"eumelanin\"/\"pheomelanin\" since \"reflectance\" was provided");
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
    let eta = cx.checked_ftex(
        "eta",
        1.55,
        |v| v > 0.0,
        "index of refraction must be positive",
    )?;
    let beta_m = cx.ftex("beta_m", 0.3)?;
    let beta_n = cx.ftex("beta_n", 0.3)?;
    let alpha = cx.ftex("alpha", 2.0)?;
    cx.ignore_normal_map("hair")?;
    Ok(Material::Hair(HairMaterial {
        absorption,
        eta,
        beta_m,
        beta_n,
        alpha,
    }))
}

fn create_mix(
    cx: &mut Ctx,
    visible: &dyn Fn(&str) -> Result<u32, String>,
) -> Result<Material, Diagnostic> {
    let names = cx.params.get_string_array("materials")?;
    if names.len() != 2 {
        return Err(Diagnostic::error(
            cx.ploc("materials"),
            format!(
                "mix material needs exactly two names in \"string materials\" (got {})",
                names.len()
            ),
        ));
    }
    let mut materials = [0u32; 2];
    for (slot, name) in materials.iter_mut().zip(&names) {
        *slot = visible(name).map_err(|m| Diagnostic::error(cx.ploc("materials"), m))?;
    }
    let amount = cx.ftex("amount", 0.5)?;
    cx.ignore_normal_map("mix")?;
    Ok(Material::Mix(MixMaterial { materials, amount }))
}

fn create_subsurface(
    cx: &mut Ctx,
    cache: &mut HashMap<PathBuf, Arc<Image>>,
) -> Result<Material, Diagnostic> {
    let mut g = cx.one_float("g", 0.0)?;
    let name = cx.params.get_one_string("name", "")?;
    let constant = |s: Spectrum| -> SpectrumTextureRef { Arc::new(SpectrumTexture::Constant(s)) };
    let coefficients = if !name.is_empty() {
        let Some((sa, ss)) = get_medium_scattering_properties(&name) else {
            let known: Vec<&str> = data::measured_medium_names().collect();
            return Err(Diagnostic::error(
                cx.ploc("name"),
                format!(
                    "\"{name}\": named medium not found (known: {})",
                    known.join(", ")
                ),
            ));
        };
        if g != 0.0 {
            cx.warn("non-zero \"g\" ignored with named scattering coefficients");
        }
        // The table gives reduced scattering coefficients.
        g = 0.0;
        SubsurfaceCoefficients::Coefficients {
            sigma_a: constant(sa),
            sigma_s: constant(ss),
        }
    } else {
        let sigma_a = cx.stex_opt("sigma_a", SpectrumType::Unbounded)?;
        let sigma_s = cx.stex_opt("sigma_s", SpectrumType::Unbounded)?;
        match (sigma_a, sigma_s) {
            (Some(sigma_a), Some(sigma_s)) => {
                SubsurfaceCoefficients::Coefficients { sigma_a, sigma_s }
            }
            (Some(_), None) => {
                return Err(Diagnostic::error(
                    cx.ploc("sigma_a"),
                    "\"sigma_a\" given without \"sigma_s\"",
                ))
            }
            (None, Some(_)) => {
                return Err(Diagnostic::error(
                    cx.ploc("sigma_s"),
                    "\"sigma_s\" given without \"sigma_a\"",
                ))
            }
            (None, None) => {
                if let Some(reflectance) = cx.stex_opt("reflectance", SpectrumType::Albedo)? {
                    let mfp = cx.stex("mfp", Spectrum::constant(1.0), SpectrumType::Unbounded)?;
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
    let scale = cx.one_float("scale", 1.0)?;
    let eta = cx.one_float("eta", 1.33)?;
    if eta.is_nan() || eta <= 0.0 {
        return Err(cx.err(
            "eta",
            format!("index of refraction must be positive (got {eta})"),
        ));
    }
    Ok(Material::Subsurface(Box::new(SubsurfaceMaterial {
        scale,
        coefficients,
        g,
        eta,
        roughness: cx.roughness("")?,
        perturbation: cx.perturbation(cache)?,
    })))
}
