//! pbrt-v3 → pbrt-v4 mappings (pbrt-v4 `--upgrade`, `parser.cpp`'s
//! formatting target and `upgrade.cpp`; book appendix C).
//!
//! Pure functions over a directive's type name and parameter list that
//! return the pbrt-v4 name, the rewritten parameters and located
//! diagnostics (warnings where the mapping is approximate, errors where it
//! cannot be done). The formatter uses them for `--upgrade`; the scene
//! builder can use them to read pbrt-v3 files directly.

use crate::diag::Diagnostic;
use crate::loc::FileLoc;
use crate::params::{canonical_type, ParsedParameter};

/// The result of upgrading one directive.
#[derive(Clone, Debug, PartialEq)]
pub struct Upgraded {
    /// The pbrt-v4 type name (e.g. `diffuse` for `matte`).
    pub name: String,
    /// The rewritten parameters.
    pub params: Vec<ParsedParameter>,
    /// Warnings (approximations) and errors (things that need manual work).
    pub diagnostics: Vec<Diagnostic>,
}

/// Renames pbrt-v3 parameter types to pbrt-v4 ones in place
/// (`point`→`point3`, `vector`→`vector3`, `color`→`rgb`, `normal3`→`normal`).
pub fn upgrade_param_types(params: &mut [ParsedParameter]) {
    for p in params {
        if let Some(ct) = canonical_type(&p.ty) {
            if ct != p.ty {
                p.ty = std::borrow::Cow::Borrowed(ct);
            }
        }
    }
}

/// A small editing helper over a parameter list.
struct Edit {
    name: String,
    params: Vec<ParsedParameter>,
    diags: Vec<Diagnostic>,
    loc: FileLoc,
    /// Parameters to put first, in order (pbrt-v4 prints them first).
    front: Vec<ParsedParameter>,
}

const SPECTRUM_TYPES: [&str; 3] = ["rgb", "spectrum", "blackbody"];

impl Edit {
    fn new(name: &str, mut params: Vec<ParsedParameter>, loc: &FileLoc) -> Self {
        upgrade_param_types(&mut params);
        Edit {
            name: name.to_string(),
            params,
            diags: Vec::new(),
            loc: loc.clone(),
            front: Vec::new(),
        }
    }

    fn finish(self) -> Upgraded {
        let mut params = self.params;
        if !self.front.is_empty() {
            params.splice(0..0, self.front);
        }
        // Kept with the scene's entity: a directive of one parameter would
        // otherwise hold room for four (a Vec's smallest growth), 500 bytes
        // more per shape in a scene of many small shapes.
        params.shrink_to_fit();
        Upgraded {
            name: self.name,
            params,
            diagnostics: self.diags,
        }
    }

    fn index(&self, name: &str, types: &[&str]) -> Option<usize> {
        self.params
            .iter()
            .rposition(|p| p.name == name && types.contains(&p.canonical_type()))
    }

    fn get(&self, name: &str, types: &[&str]) -> Option<&ParsedParameter> {
        self.index(name, types).map(|i| &self.params[i])
    }

    fn remove(&mut self, name: &str, types: &[&str]) -> Option<ParsedParameter> {
        let i = self.index(name, types)?;
        Some(self.params.remove(i))
    }

    fn remove_all(&mut self, name: &str, types: &[&str]) {
        self.params
            .retain(|p| !(p.name == name && types.contains(&p.canonical_type())));
    }

    fn rename(&mut self, from: &str, to: &str) {
        for p in &mut self.params {
            if p.name == from {
                p.name = to.to_string();
            }
        }
    }

    fn add_front(&mut self, p: ParsedParameter) {
        self.front.push(p);
    }

    fn float(&self, name: &str, v: &[f32]) -> ParsedParameter {
        ParsedParameter::with_floats("float", name, self.loc.clone(), v.to_vec())
    }

    fn string(&self, ty: &str, name: &str, v: &[&str]) -> ParsedParameter {
        ParsedParameter::with_strings(
            ty,
            name,
            self.loc.clone(),
            v.iter().map(|s| s.to_string()).collect(),
        )
    }

    fn warn(&mut self, loc: Option<&FileLoc>, msg: String) {
        self.diags
            .push(Diagnostic::warning(loc.unwrap_or(&self.loc).clone(), msg));
    }

    fn error(&mut self, loc: Option<&FileLoc>, msg: String) {
        self.diags
            .push(Diagnostic::error(loc.unwrap_or(&self.loc).clone(), msg));
    }

    /// The single value of `name` if it is an RGB with three equal components.
    fn uniform_rgb(&self, name: &str) -> Option<f32> {
        let p = self.get(name, &["rgb"])?;
        match p.floats[..] {
            [r, g, b] if r == g && g == b => Some(r),
            _ => None,
        }
    }

    /// Drops spectrum or texture `name`; silent if it was the uniform RGB
    /// `value` (pbrt-v4's implied value), a warning otherwise. Returns
    /// whether it matched.
    fn drop_if_constant(&mut self, name: &str, value: f32) -> bool {
        let matches = self.uniform_rgb(name) == Some(value);
        if !matches {
            if let Some(p) = self
                .get(name, &SPECTRUM_TYPES)
                .or_else(|| self.get(name, &["texture"]))
            {
                let loc = p.loc.clone();
                let msg = format!(
                    "parameter \"{} {}\" is removed when converting to the \"{}\" material",
                    p.ty, p.name, self.name
                );
                self.warn(Some(&loc), msg);
            }
        }
        self.remove_all(name, &SPECTRUM_TYPES);
        self.remove_all(name, &["texture"]);
        matches
    }

    /// Folds a uniform RGB `name` into `scale`; false if it is not uniform.
    fn rgb_into_scale(&mut self, name: &str, scale: &mut f32) -> bool {
        if self.get(name, &SPECTRUM_TYPES).is_none() {
            return true;
        }
        match self.uniform_rgb(name) {
            Some(v) => {
                *scale *= v;
                self.remove_all(name, &SPECTRUM_TYPES);
                true
            }
            None => false,
        }
    }

    /// pbrt-v3's colour light `"scale"` (a spectrum there, multiplied into
    /// the emission): folded channel by channel into the RGB emission
    /// `emission`, or made the emission where the light gives none
    /// (pbrt-v3's default emission is 1). False, changing nothing, when the
    /// scale is not an RGB or the emission is a spectrum or blackbody,
    /// which take no per-channel factor.
    fn rgb_scale_into_emission(&mut self, emission: &str) -> bool {
        let Some(s) = self
            .get("scale", &["rgb"])
            .and_then(|p| <[f32; 3]>::try_from(&p.floats[..]).ok())
        else {
            return false;
        };
        let Some(i) = self.index(emission, &SPECTRUM_TYPES) else {
            let loc = self
                .get("scale", &["rgb"])
                .map_or(self.loc.clone(), |p| p.loc.clone());
            self.remove_all("scale", &SPECTRUM_TYPES);
            self.add_front(ParsedParameter::with_floats(
                "rgb",
                emission,
                loc,
                s.to_vec(),
            ));
            return true;
        };
        let p = &mut self.params[i];
        if p.canonical_type() != "rgb" || p.floats.len() != 3 {
            return false;
        }
        for (v, f) in p.floats.iter_mut().zip(s) {
            *v *= f;
        }
        self.remove_all("scale", &SPECTRUM_TYPES);
        true
    }

    /// pbrt-v3 `blackbody [T scale]`: keep T and fold the scale.
    fn upgrade_blackbody(&mut self, name: &str, scale: &mut f32) {
        let mut errs = Vec::new();
        for p in &mut self.params {
            if p.name == name && p.canonical_type() == "blackbody" {
                match p.floats.len() {
                    1 => {}
                    2 => {
                        *scale *= p.floats[1];
                        p.floats.truncate(1);
                    }
                    _ => errs.push(p.loc.clone()),
                }
            }
        }
        for l in errs {
            self.error(
                Some(&l),
                "expected one (pbrt-v4) or two (pbrt-v3) values for \"blackbody\"".into(),
            );
        }
    }
}

/// Warns where pbrt-v4's replacement of a pbrt-v3 material renders
/// differently from pbrt-v3's model (the mapping is pbrt-v4's `--upgrade`'s
/// either way): a different reflection model, pbrt-v3's roughness remapping
/// (a polynomial in log roughness, where pbrt-v4 takes the square root), or
/// a dropped parameter such as `matte`'s Oren–Nayar `sigma`.
fn approximation_warning(e: &mut Edit, name: &str) {
    let nonzero = |e: &Edit, n: &str| {
        e.get(n, &["texture"]).is_some()
            || e.get(n, &["float"])
                .is_some_and(|p| p.floats.iter().any(|&v| v != 0.0))
    };
    let rough = ["roughness", "uroughness", "vroughness"]
        .iter()
        .any(|n| nonzero(e, n));
    let what = match name {
        "plastic" | "substrate" | "uber" => Some("its reflection model differs"),
        "translucent" => Some("its glossy reflection and transmission are dropped"),
        "kdsubsurface" => Some("its specular interface differs"),
        // pbrt-v3's metal defaults to roughness 0.01, remapped.
        "metal" => Some("its roughness is remapped differently"),
        "mirror" => Some("its reflectance varies with angle in pbrt-v4"),
        "glass" if rough => Some("its roughness is remapped differently"),
        "matte" if nonzero(e, "sigma") => Some("pbrt-v4 has no Oren–Nayar \"sigma\""),
        _ => None,
    };
    // Uber and plastic without a specular part become "diffuse", exactly.
    let plain = matches!(name, "uber" | "plastic") && e.uniform_rgb("Ks") == Some(0.0);
    if let (Some(what), false) = (what, plain) {
        e.warn(
            None,
            format!("pbrt-v3's \"{name}\" material is approximated as pbrt-v4's --upgrade does: {what}, so the image differs from pbrt-v3's"),
        );
    }
}

/// Upgrades a `Material` (or the `"string type"` of a `MakeNamedMaterial`).
pub fn upgrade_material(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    // "index" became "eta" for glass and uber.
    if name == "glass" || name == "uber" {
        if let Some(mut p) = e.remove("index", &["float", "texture"]) {
            if e.get("eta", &["float", "texture", "spectrum"]).is_some() {
                let l = p.loc.clone();
                e.error(
                    Some(&l),
                    format!("material \"{name}\" has both \"index\" and \"eta\""),
                );
            } else {
                p.name = "eta".into();
                e.add_front(p);
            }
        }
    }
    e.rename("bumpmap", "displacement");
    approximation_warning(&mut e, name);
    match name {
        "uber" => {
            e.name = "coateddiffuse".into();
            if e.drop_if_constant("Ks", 0.0) {
                e.name = "diffuse".into();
                e.remove_all("eta", &["float", "texture"]);
                e.remove_all("roughness", &["float", "texture"]);
            }
            e.drop_if_constant("Kr", 0.0);
            e.drop_if_constant("Kt", 0.0);
            e.rename("Kd", "reflectance");
            if let Some(p) = e.get("opacity", &["texture"]) {
                let l = p.loc.clone();
                e.error(Some(&l), "an \"opacity\" texture on \"uber\" is not supported by pbrt-v4; edit the file manually".into());
            } else if e.get("opacity", &SPECTRUM_TYPES).is_some() {
                if e.uniform_rgb("opacity") == Some(1.0) {
                    e.remove_all("opacity", &SPECTRUM_TYPES);
                } else {
                    let l = e.get("opacity", &SPECTRUM_TYPES).map(|p| p.loc.clone());
                    e.error(l.as_ref(), "a non-opaque \"opacity\" on \"uber\" is not supported by pbrt-v4; edit the file manually".into());
                }
            }
        }
        // A pbrt-v4 mix (it names its materials with "materials") is left
        // as it is; only the pbrt-v3 form is rewritten.
        "mix" if e.get("materials", &["string"]).is_some() => {}
        "mix" => {
            if let Some(p) = e.get("amount", &["rgb"]) {
                let (l, f) = (p.loc.clone(), p.floats.clone());
                if let [r, g, b] = f[..] {
                    let v = if r == g && g == b {
                        r
                    } else {
                        let avg = (r + g + b) / 3.0;
                        e.warn(
                            Some(&l),
                            format!("RGB \"amount\" ({r}, {g}, {b}) becomes its average {avg}"),
                        );
                        avg
                    };
                    let p = e.float("amount", &[v]);
                    e.add_front(p);
                }
            } else if let Some(p) = e.get("amount", &["spectrum", "blackbody"]) {
                let l = p.loc.clone();
                e.error(
                    Some(&l),
                    "cannot convert a non-RGB spectrum \"amount\" to a scalar".into(),
                );
            }
            e.remove_all("amount", &SPECTRUM_TYPES);
            let m1 = e
                .remove("namedmaterial1", &["string"])
                .and_then(|p| p.strings.first().cloned());
            let m2 = e
                .remove("namedmaterial2", &["string"])
                .and_then(|p| p.strings.first().cloned());
            match (m1, m2) {
                (Some(m1), Some(m2)) => {
                    // pbrt-v4 blends the other way round: amount weights the second.
                    let p = e.string("string", "materials", &[&m2, &m1]);
                    e.add_front(p);
                }
                _ => e.error(
                    None,
                    "\"mix\" material needs \"namedmaterial1\" and \"namedmaterial2\"".into(),
                ),
            }
        }
        "substrate" => {
            e.name = "coateddiffuse".into();
            e.drop_if_constant("Ks", 1.0);
            e.rename("Kd", "reflectance");
        }
        "glass" => {
            e.name = "dielectric".into();
            e.drop_if_constant("Kr", 1.0);
            e.drop_if_constant("Kt", 1.0);
        }
        "plastic" => {
            e.name = "coateddiffuse".into();
            if e.drop_if_constant("Ks", 0.0) {
                e.name = "diffuse".into();
                e.remove_all("roughness", &["float", "texture"]);
                e.remove_all("eta", &["float", "texture"]);
            }
            e.rename("Kd", "reflectance");
        }
        // pbrt-v1/v2: a glossy Blinn lobe over a mirror, each with a
        // Fresnel term made from a colour; the nearest pbrt-v4 model is a
        // rough conductor of the glossy lobe's colour.
        "shinymetal" => {
            e.name = "conductor".into();
            e.rename("Ks", "reflectance");
            e.remove_all("Kr", &SPECTRUM_TYPES);
            e.remove_all("Kr", &["texture"]);
            e.warn(
                None,
                "pbrt-v2's \"shinymetal\" is approximated by a rough \"conductor\" of its \"Ks\" colour: its mirror lobe (\"Kr\") and Blinn distribution are lost".into(),
            );
        }
        "bluepaint" | "brushedmetal" | "clay" | "felt" | "primer" | "skin" => e.error(
            None,
            format!("pbrt-v1's measured \"{name}\" material has no pbrt-v4 equivalent: --upgrade cannot write it (rpbrt renders it)"),
        ),
        "fourier" => e.warn(
            None,
            "the \"fourier\" material is not supported by pbrt-v4 (see \"measured\")".into(),
        ),
        "kdsubsurface" => {
            e.name = "subsurface".into();
            e.rename("Kd", "reflectance");
        }
        "matte" => {
            e.name = "diffuse".into();
            e.rename("Kd", "reflectance");
        }
        "metal" => {
            e.name = "conductor".into();
            e.drop_if_constant("Kr", 1.0);
        }
        "translucent" => {
            e.name = "diffusetransmission".into();
            e.rename("Kd", "transmittance");
            e.drop_if_constant("reflect", 0.0);
            e.drop_if_constant("transmit", 1.0);
            e.drop_if_constant("Ks", 0.0);
            e.remove_all("roughness", &["float", "texture"]);
        }
        "mirror" => {
            // A perfect conductor tinted by pbrt-v3's Kr (default 0.9).
            e.name = "conductor".into();
            let p = e.float("roughness", &[0.0]);
            e.add_front(p);
            if e.get("Kr", &["rgb", "spectrum", "blackbody", "texture"])
                .is_some()
            {
                e.rename("Kr", "reflectance");
            } else {
                let p =
                    ParsedParameter::with_floats("rgb", "reflectance", e.loc.clone(), vec![0.9; 3]);
                e.add_front(p);
            }
        }
        "disney" => {
            e.name = "diffuse".into();
            e.rename("color", "reflectance");
            e.warn(
                None,
                "the \"disney\" material is approximated by \"diffuse\"".into(),
            );
        }
        "" | "none" => e.name = "interface".into(),
        _ => {}
    }
    e.finish()
}

/// What a parameter names when it refers to a definition that pbrt-v3
/// lets a file make again (and `--upgrade` or the renderer renames).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// A texture (a `texture` parameter).
    Texture = 0,
    /// A named material (a `mix` material's `namedmaterial1`,
    /// `namedmaterial2` or `materials`).
    NamedMaterial = 1,
}

/// The kind of definition whose names `p`'s values are, if any.
pub fn reference_of(p: &ParsedParameter) -> Option<Reference> {
    if p.ty == "texture" {
        Some(Reference::Texture)
    } else if p.ty == "string"
        && matches!(
            p.name.as_str(),
            "namedmaterial1" | "namedmaterial2" | "materials"
        )
    {
        Some(Reference::NamedMaterial)
    } else {
        None
    }
}

/// The pbrt-v3 materials pbrt-v4 dropped that a renderer reading pbrt-v3
/// files directly can still build (rpbrt does): `--upgrade` must map them
/// to something pbrt-v4 reads, rendering need not.
pub const NATIVE_V3_MATERIALS: &[&str] = &[
    "bluepaint",
    "brushedmetal",
    "clay",
    "disney",
    "felt",
    "fourier",
    "primer",
    "shinymetal",
    "skin",
];

/// [`upgrade_material`] for a renderer that implements
/// [`NATIVE_V3_MATERIALS`]: those keep their name and parameters (only the
/// parameter types and pbrt-v3's `bumpmap` are renamed); every other
/// material is upgraded as `--upgrade` does.
pub fn upgrade_material_for_render(
    name: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
) -> Upgraded {
    if NATIVE_V3_MATERIALS.contains(&name) {
        let mut e = Edit::new(name, params, loc);
        e.rename("bumpmap", "displacement");
        return e.finish();
    }
    upgrade_material(name, params, loc)
}

/// Upgrades a `LightSource`.
pub fn upgrade_light(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    upgrade_light_with(name, params, loc, false)
}

/// [`upgrade_light`] for rpbrt's renderer, which also renders what pbrt-v4
/// cannot express: a pbrt-v3 `projection` light's non-uniform RGB `I` with
/// its `mapname` stays `"rgb I"`, and an `infinite` light's non-uniform
/// RGB `L` (or colour `scale`) with its `mapname` stays (or becomes)
/// `"rgb L"`, which rpbrt multiplies into the map.
pub fn upgrade_light_for_render(
    name: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
) -> Upgraded {
    upgrade_light_with(name, params, loc, true)
}

fn upgrade_light_with(
    name: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
    render: bool,
) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    let mut scale = 1.0f32;
    // A colour scale multiplies the emission, where that is an RGB (or
    // absent) and no image is scaled with it.
    let emission = match name {
        "point" | "spot" | "goniometric" => Some("I"),
        "distant" => Some("L"),
        // With a map, only a renderer that multiplies the map by an RGB
        // `L` (pbrt-v3's meaning; pbrt-v4 has no such parameter) takes it.
        "infinite" | "exinfinite" | "infinitesample"
            if render || e.get("mapname", &["string"]).is_none() =>
        {
            Some("L")
        }
        _ => None,
    };
    if !e.rgb_into_scale("scale", &mut scale)
        && !emission.is_some_and(|em| e.rgb_scale_into_emission(em))
    {
        let l = e.get("scale", &SPECTRUM_TYPES).map(|p| p.loc.clone());
        e.error(l.as_ref(), "in pbrt-v4 a light's \"scale\" is a \"float\"; a non-uniform spectrum cannot be converted".into());
        return e.finish();
    }
    // pbrt-v3's light sample counts ("samples", or "nsamples" on infinite
    // and area lights) only set how many shadow rays its "directlighting"
    // integrator traces per light: the noise, never the expected image.
    for n in ["samples", "nsamples"] {
        e.remove_all(n, &["integer", "float"]);
    }
    // pbrt-v3 accepted "exinfinite" as another name of "infinite", and
    // pbrt-v1 had "infinitesample" (the same light, sampled by its map).
    if name == "exinfinite" || name == "infinitesample" {
        e.name = "infinite".into();
    }
    let has_map = e.get("mapname", &["string"]).is_some();
    if has_map
        && e.name == "infinite"
        && !e.rgb_into_scale("L", &mut scale)
        && !(render && e.get("L", &["rgb"]).is_some_and(|p| p.floats.len() == 3))
    {
        let l = e.get("L", &SPECTRUM_TYPES).map(|p| p.loc.clone());
        e.error(l.as_ref(), "a non-uniform \"L\" with \"mapname\" on an \"infinite\" light is not supported by pbrt-v4".into());
        return e.finish();
    }
    if has_map
        && name == "projection"
        && !e.rgb_into_scale("I", &mut scale)
        && !(render && e.get("I", &["rgb"]).is_some_and(|p| p.floats.len() == 3))
    {
        let l = e.get("I", &SPECTRUM_TYPES).map(|p| p.loc.clone());
        e.error(
            l.as_ref(),
            "\"I\" with \"mapname\" on a \"projection\" light is not supported by pbrt-v4".into(),
        );
        return e.finish();
    }
    e.upgrade_blackbody("I", &mut scale);
    e.upgrade_blackbody("L", &mut scale);
    if let Some(mut p) = e.remove("mapname", &["string"]) {
        p.name = "filename".into();
        e.add_front(p);
    }
    if scale != 1.0 {
        let old = e
            .remove("scale", &["float"])
            .and_then(|p| p.floats.first().copied())
            .unwrap_or(1.0);
        let p = e.float("scale", &[scale * old]);
        e.front.insert(0, p);
    }
    warn_if_normalized(&mut e);
    e.finish()
}

/// Warns when a light's `L` or `I` is a `spectrum` or `blackbody`:
/// pbrt-v4 scales those to unit luminance where pbrt-v3 used them as they
/// are (its blackbody peaks at 1), so the light's brightness changes. An
/// RGB value keeps its brightness: pbrt-v4 divides by the luminance of the
/// colour space's illuminant only, which the RGB-to-spectrum conversion
/// multiplies in.
fn warn_if_normalized(e: &mut Edit) {
    let p = e
        .get("L", &["spectrum", "blackbody"])
        .or_else(|| e.get("I", &["spectrum", "blackbody"]));
    if let Some(p) = p {
        let (loc, ty, name) = (p.loc.clone(), p.ty.clone(), p.name.clone());
        e.warn(
            Some(&loc),
            format!("pbrt-v4 normalizes a light's \"{ty} {name}\" to unit luminance, pbrt-v3 did not: brightness differs from pbrt-v3 (adjust \"scale\" or use \"power\")"),
        );
    }
}

/// Upgrades an `AreaLightSource` (`area` → `diffuse`).
pub fn upgrade_area_light(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    let mut scale = 1.0f32;
    if !e.rgb_into_scale("scale", &mut scale) && !e.rgb_scale_into_emission("L") {
        let l = e.get("scale", &SPECTRUM_TYPES).map(|p| p.loc.clone());
        e.error(l.as_ref(), "in pbrt-v4 a light's \"scale\" is a \"float\"; a non-uniform spectrum cannot be converted".into());
        return e.finish();
    }
    e.upgrade_blackbody("L", &mut scale);
    if name == "area" {
        e.name = "diffuse".into();
    }
    warn_if_normalized(&mut e);
    for n in ["samples", "nsamples"] {
        e.remove_all(n, &["integer", "float"]);
    }
    if scale != 1.0 {
        let old = e
            .remove("scale", &["float"])
            .and_then(|p| p.floats.first().copied())
            .unwrap_or(1.0);
        let p = e.float("scale", &[scale * old]);
        e.front.insert(0, p);
    }
    e.finish()
}

/// Upgrades a `Film` (`image` → `rgb`, `maxsampleluminance`, `scale` → `iso`).
pub fn upgrade_film(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    if let Some(mut p) = e.remove("maxsampleluminance", &["float"]) {
        p.name = "maxcomponentvalue".into();
        e.add_front(p);
    }
    if let Some(p) = e.remove("scale", &["float"]) {
        if let Some(&s) = p.floats.first() {
            let iso = e.float("iso", &[100.0 * s]);
            e.add_front(iso);
            e.warn(
                Some(&p.loc),
                "film \"scale\" is approximated by \"iso\" = 100 × scale".into(),
            );
        }
    }
    if name == "image" {
        e.name = "rgb".into();
        // pbrt-v1/v2's on-screen display, alpha premultiplication and
        // partial writes: none changes the image.
        e.remove_all("display", &["bool"]);
        e.remove_all("premultiplyalpha", &["bool"]);
        e.remove_all("writefrequency", &["integer"]);
    }
    e.finish()
}

/// Upgrades a `Sampler` (`lowdiscrepancy`/`02sequence` → `paddedsobol`,
/// `maxmindist` → `pmj02bn`, `random` → `independent`, as pbrt-v4's
/// `--upgrade`).
pub fn upgrade_sampler(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    match name {
        "lowdiscrepancy" | "02sequence" => e.name = "paddedsobol".into(),
        "maxmindist" => e.name = "pmj02bn".into(),
        "random" => {
            e.name = "independent".into();
            // pbrt-v1's random sampler took a grid's `xsamples` and
            // `ysamples` (2 each) per pixel.
            let x = e.remove("xsamples", &["integer"]);
            let y = e.remove("ysamples", &["integer"]);
            if x.is_some() || y.is_some() {
                let n = |p: Option<ParsedParameter>| {
                    p.and_then(|p| p.ints.first().copied()).unwrap_or(2)
                };
                let mut p = ParsedParameter::new("integer", "pixelsamples", e.loc.clone());
                p.ints = vec![n(x).saturating_mul(n(y))];
                e.remove_all("pixelsamples", &["integer"]);
                e.add_front(p);
            }
        }
        // pbrt-v1/v2's best-candidate patterns were blue noise, as
        // pbrt-v4's pmj02bn's are.
        "bestcandidate" => e.name = "pmj02bn".into(),
        // pbrt-v2's adaptive sampler took between `minsamples` and
        // `maxsamples` per pixel, more where the first ones disagreed:
        // every pixel takes `maxsamples` (same image, less noise).
        "adaptive" => {
            e.name = "paddedsobol".into();
            let max = e
                .remove("maxsamples", &["integer"])
                .and_then(|p| p.ints.first().copied())
                .unwrap_or(32);
            e.remove_all("minsamples", &["integer"]);
            e.remove_all("method", &["string"]);
            e.remove_all("pixelsamples", &["integer"]);
            let mut p = ParsedParameter::new("integer", "pixelsamples", e.loc.clone());
            p.ints = vec![max];
            e.add_front(p);
        }
        _ => {}
    }
    e.finish()
}

/// Upgrades an `Accelerator`: pbrt-v1/v2's uniform `grid` (pbrt-v4 has
/// none; the accelerator changes only the speed) becomes a `bvh`.
pub fn upgrade_accelerator(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    if name == "grid" {
        e.name = "bvh".into();
        e.remove_all("refineimmediately", &["bool"]);
    }
    e.finish()
}

/// Upgrades an `Integrator` (`directlighting` → `path` with depth 1, SPPM
/// and light-sampling parameters).
pub fn upgrade_integrator(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    e.remove_all("rrthreshold", &["float"]);
    if name == "sppm" {
        e.remove_all("imagewritefrequency", &["integer"]);
        if let Some(p) = e.remove("numiterations", &["integer"]) {
            e.warn(
                Some(&p.loc),
                "the SPPM integrator no longer takes \"numiterations\"; the sampler's pixel sample count sets it".into(),
            );
        }
    }
    if e.get("lightsamplestrategy", &["string"])
        .is_some_and(|p| p.strings == ["spatial"])
    {
        e.remove_all("lightsamplestrategy", &["string"]);
        let p = e.string("string", "lightsamplestrategy", &["bvh"]);
        e.add_front(p);
    }
    if name == "directlighting" {
        e.name = "path".into();
        let mut p = ParsedParameter::new("integer", "maxdepth", loc.clone());
        p.ints = vec![1];
        e.remove_all("maxdepth", &["integer"]);
        e.add_front(p);
        e.warn(
            None,
            "\"directlighting\" is approximated by \"path\" with \"maxdepth\" 1".into(),
        );
    }
    e.finish()
}

/// [`upgrade_integrator`] for rpbrt's renderer, which also has pbrt-v3's
/// `whitted`: `directlighting` (direct lighting at each hit, specular
/// chains to `maxdepth`) is the same light transport as `whitted` and
/// renders as it, where `--upgrade` can only approximate it with `path`.
pub fn upgrade_integrator_for_render(
    name: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
) -> Upgraded {
    if name == "directlighting" {
        let mut e = legacy::surface_integrator(
            &legacy::Given::new(name, params, loc.clone()),
            legacy::Target::Render,
        );
        e.remove_all("rrthreshold", &["float"]);
        return e.finish();
    }
    upgrade_integrator(name, params, loc)
}

/// Upgrades a `Camera` (`environment` → `spherical`, equirectangular).
pub fn upgrade_camera(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    if name == "environment" {
        e.name = "spherical".into();
        let p = e.string("string", "mapping", &["equirectangular"]);
        e.add_front(p);
    }
    if name == "realistic" {
        e.remove_all("simpleweighting", &["bool"]);
    }
    // pbrt-v2's half field of view, used where no "fov" is given.
    if let Some(p) = e.remove("halffov", &["float"]) {
        match p.floats[..] {
            [h] if h > 0.0 && e.get("fov", &["float"]).is_none() => {
                let fov = e.float("fov", &[2.0 * h]);
                e.add_front(fov);
            }
            _ => {}
        }
    }
    // pbrt-v1's clipping planes (default 1e-3 and 1e30): pbrt-v4 clips
    // nothing, which changes the image only where they cut the scene.
    for (plane, default) in [("hither", 1e-3), ("yon", 1e30)] {
        if let Some(p) = e.remove(plane, &["float"]) {
            if p.floats.first().is_some_and(|&v| v != default) {
                let l = p.loc.clone();
                e.warn(
                    Some(&l),
                    format!("pbrt-v1's clipping plane \"{plane}\" is ignored: pbrt-v4 cameras clip nothing"),
                );
            }
        }
    }
    e.finish()
}

/// Upgrades a `PixelFilter` (widths → radii, gaussian `alpha` → `sigma`).
pub fn upgrade_pixel_filter(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    for (from, to) in [("xwidth", "xradius"), ("ywidth", "yradius")] {
        if e.get(from, &["float"]).is_some_and(|p| p.floats.len() == 1) {
            if let Some(mut p) = e.remove(from, &["float"]) {
                p.name = to.into();
                e.add_front(p);
            }
        }
    }
    if name == "gaussian" {
        if let Some(p) = e.remove("alpha", &["float"]) {
            if let [a] = p.floats[..] {
                if a > 0.0 {
                    let s = e.float("sigma", &[1.0 / (2.0 * a).sqrt()]);
                    e.add_front(s);
                } else {
                    e.error(Some(&p.loc), "gaussian \"alpha\" must be positive".into());
                }
            }
        }
    }
    e.finish()
}

/// Upgrades a `MakeNamedMedium` (`heterogeneous` → `uniformgrid`).
///
/// pbrt-v3's grid medium takes the same `density`, `nx`/`ny`/`nz`,
/// `p0`/`p1`, `sigma_a`, `sigma_s`, `scale` and `g` as pbrt-v4's
/// `uniformgrid` (and samples the grid the same way), but its default
/// coefficients were those of whole milk, (.0011, .0024, .014) and
/// (2.55, 3.21, 3.77), where pbrt-v4's are 1: an absent `sigma_a` or
/// `sigma_s` is written out with the pbrt-v3 value so that the medium
/// looks as it did. pbrt-v4's `uniformgrid` has no `"preset"`, so a preset
/// is dropped with a warning. (pbrt-v4's own `--upgrade` compares the
/// medium's name instead of its type with `"heterogeneous"`, so it never
/// converts one.)
pub fn upgrade_medium(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    if name == "heterogeneous" {
        e.name = "uniformgrid".into();
        if let Some(p) = e.remove("preset", &["string"]) {
            e.warn(
                Some(&p.loc),
                "pbrt-v4's \"uniformgrid\" medium has no \"preset\"; give \"sigma_a\" and \"sigma_s\" instead (using pbrt-v3's defaults where absent)".into(),
            );
            e.remove_all("preset", &["string"]);
        }
        const V3_DEFAULTS: [(&str, [f32; 3]); 2] = [
            ("sigma_a", [0.0011, 0.0024, 0.014]),
            ("sigma_s", [2.55, 3.21, 3.77]),
        ];
        for (param, rgb) in V3_DEFAULTS {
            if e.get(param, &SPECTRUM_TYPES).is_none() {
                let p = ParsedParameter::with_floats("rgb", param, e.loc.clone(), rgb.to_vec());
                e.add_front(p);
            }
        }
    }
    e.finish()
}

/// Upgrades a `Texture`; returns the pbrt-v4 texture type (`color` →
/// `spectrum`) and the upgraded class and parameters.
pub fn upgrade_texture(
    ty: &str,
    class: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
) -> (String, Upgraded) {
    upgrade_texture_with(ty, class, params, loc, false)
}

/// [`upgrade_texture`] for rpbrt's renderer, which also renders what
/// pbrt-v4 cannot express: a pbrt-v3 `"scale"` spectrum texture of two
/// textures (or of a texture and a non-uniform colour) keeps the first as
/// `"tex"` and the second as `"tex2"`, rpbrt's spectrum factor of the
/// `"scale"` texture, so the product renders as pbrt-v3 drew it.
pub fn upgrade_texture_for_render(
    ty: &str,
    class: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
) -> (String, Upgraded) {
    upgrade_texture_with(ty, class, params, loc, true)
}

fn upgrade_texture_with(
    ty: &str,
    class: &str,
    params: Vec<ParsedParameter>,
    loc: &FileLoc,
    render: bool,
) -> (String, Upgraded) {
    let mut e = Edit::new(class, params, loc);
    let ty = if ty == "color" { "spectrum" } else { ty }.to_string();
    let uniform_rgb = |p: &ParsedParameter| {
        p.canonical_type() == "rgb" && matches!(p.floats[..], [r, g, b] if r == g && g == b)
    };
    let is_factor = |p: &ParsedParameter| p.name == "tex1" || p.name == "tex2";
    if class == "scale"
        && ty != "float"
        && render
        && !e.params.iter().any(|p| is_factor(p) && uniform_rgb(p))
    {
        // No factor becomes a float scale: the first is the texture, the
        // second (if any) rpbrt's spectrum factor.
        let mut first = true;
        for p in e.params.iter_mut().filter(|p| is_factor(p)) {
            p.name = if first { "tex" } else { "tex2" }.into();
            first = false;
        }
    } else if class == "scale" {
        if ty == "float" {
            e.rename("tex1", "tex");
            e.rename("tex2", "scale");
        } else {
            // One of tex1/tex2 must be a constant to become the float "scale".
            let (mut found_rgb, mut found_tex) = (false, false);
            let mut errs = Vec::new();
            for p in &mut e.params {
                if p.name != "tex1" && p.name != "tex2" {
                    continue;
                }
                if p.canonical_type() == "rgb" {
                    let uniform = matches!(p.floats[..], [r, g, b] if r == g && g == b);
                    if found_rgb || !uniform {
                        errs.push((p.loc.clone(), format!("cannot convert \"{}\" of a \"scale\" texture to a float scale; edit the file manually", p.name)));
                        continue;
                    }
                    found_rgb = true;
                    p.ty = "float".into();
                    p.name = "scale".into();
                    p.floats.truncate(1);
                } else {
                    if found_tex {
                        errs.push((
                            p.loc.clone(),
                            "two textures in a \"scale\" texture; edit the file manually".into(),
                        ));
                        continue;
                    }
                    found_tex = true;
                    p.name = "tex".into();
                }
            }
            for (l, m) in errs {
                e.error(Some(&l), m);
            }
        }
    }
    if class == "imagemap" {
        if let Some(p) = e.remove("trilinear", &["bool"]) {
            if let [t] = p.bools[..] {
                let s = e.string(
                    "string",
                    "filter",
                    &[if t { "trilinear" } else { "bilinear" }],
                );
                e.add_front(s);
            }
        }
    }
    if class == "imagemap" || class == "ptex" {
        if let Some(p) = e.remove("gamma", &["float"]) {
            if let [g] = p.floats[..] {
                let s = e.string("string", "encoding", &[&format!("gamma {g}")]);
                e.add_front(s);
            }
        } else if let Some(p) = e.remove("gamma", &["bool"]) {
            if let [g] = p.bools[..] {
                let s = e.string("string", "encoding", &[if g { "sRGB" } else { "linear" }]);
                e.add_front(s);
            }
        }
    }
    (ty, e.finish())
}

/// Upgrades a `Shape` (implicit mesh indices, `loopsubdiv` levels, UVs,
/// dropped pbrt-v3 parameters).
pub fn upgrade_shape(name: &str, params: Vec<ParsedParameter>, loc: &FileLoc) -> Upgraded {
    let mut e = Edit::new(name, params, loc);
    let n_p = e.get("P", &["point3"]).map_or(0, |p| p.floats.len() / 3);
    let implicit = |ints: &[i32], n: usize| {
        ints.len() == n && ints.iter().enumerate().all(|(i, &v)| v as usize == i)
    };
    if name == "trianglemesh"
        && n_p == 3
        && e.get("indices", &["integer"])
            .is_some_and(|p| implicit(&p.ints, 3))
    {
        e.remove_all("indices", &["integer"]);
    }
    if name == "bilinearmesh"
        && n_p == 4
        && e.get("indices", &["integer"])
            .is_some_and(|p| implicit(&p.ints, 4))
    {
        e.remove_all("indices", &["integer"]);
    }
    if name == "loopsubdiv" {
        if let Some(mut p) = e.remove("nlevels", &["integer"]) {
            p.name = "levels".into();
            e.add_front(p);
        }
    }
    if name == "trianglemesh" || name == "plymesh" {
        e.remove_all("discarddegenerateUVs", &["bool"]);
        e.remove_all("shadowalpha", &["texture"]);
    }
    if name == "trianglemesh" {
        let uv = if let Some(mut p) = e.remove("st", &["point2"]) {
            p.name = "uv".into();
            Some(p)
        } else {
            let mut found = None;
            for n in ["uv", "st"] {
                if let Some(mut p) = e.remove(n, &["float"]) {
                    p.ty = "point2".into();
                    p.name = "uv".into();
                    if p.floats.len() % 2 != 0 {
                        let l = p.loc.clone();
                        e.error(Some(&l), format!("\"{n}\" has an odd number of values"));
                    }
                    found = Some(p);
                }
            }
            found
        };
        if let Some(p) = uv {
            e.add_front(p);
        }
    }
    if name == "heightfield" {
        upgrade_heightfield(&mut e);
    }
    if name == "nurbs" {
        nurbs::upgrade_nurbs(&mut e);
    }
    e.rename("Kd", "reflectance");
    e.finish()
}

/// pbrt-v3's `heightfield` (pbrt-v3 `shapes/heightfield.cpp`), which
/// pbrt-v4 dropped, as the triangle mesh pbrt-v3 built from it: `nu` × `nv`
/// heights `Pz` over the unit square (x fastest), the vertex (x, y) at
/// (x/(nu−1), y/(nv−1), Pz) with the same uv, two triangles per cell.
fn upgrade_heightfield(e: &mut Edit) {
    let one_int = |e: &Edit, n: &str| e.get(n, &["integer"]).and_then(|p| p.ints.first().copied());
    let (nu, nv) = (one_int(e, "nu"), one_int(e, "nv"));
    let z = e
        .get("Pz", &["float"])
        .map(|p| (p.floats.clone(), p.loc.clone()));
    let (Some(nu), Some(nv), Some((z, zloc))) = (nu, nv, z) else {
        e.error(
            None,
            "\"heightfield\" needs \"integer nu\", \"integer nv\" and \"float Pz\"".into(),
        );
        return;
    };
    if nu < 2 || nv < 2 {
        e.error(
            None,
            format!("\"heightfield\" needs at least 2 × 2 heights (nu {nu}, nv {nv})"),
        );
        return;
    }
    let (nu, nv) = (nu as usize, nv as usize);
    if nu.checked_mul(nv) != Some(z.len()) {
        e.error(
            Some(&zloc),
            format!(
                "\"heightfield\" has {} \"Pz\" values; nu × nv = {nu} × {nv} expected",
                z.len()
            ),
        );
        return;
    }
    for n in ["nu", "nv", "Pz"] {
        e.remove_all(n, &["integer", "float"]);
    }
    let mut p = Vec::with_capacity(3 * z.len());
    let mut uv = Vec::with_capacity(2 * z.len());
    for y in 0..nv {
        for x in 0..nu {
            let (s, t) = (x as f32 / (nu - 1) as f32, y as f32 / (nv - 1) as f32);
            p.extend([s, t, z[y * nu + x]]);
            uv.extend([s, t]);
        }
    }
    let vert = |x: usize, y: usize| (x + y * nu) as i32;
    let mut indices = Vec::with_capacity(6 * (nu - 1) * (nv - 1));
    for y in 0..nv - 1 {
        for x in 0..nu - 1 {
            indices.extend([vert(x, y), vert(x + 1, y), vert(x + 1, y + 1)]);
            indices.extend([vert(x, y), vert(x + 1, y + 1), vert(x, y + 1)]);
        }
    }
    e.name = "trianglemesh".into();
    let mut ip = ParsedParameter::new("integer", "indices", e.loc.clone());
    ip.ints = indices;
    e.add_front(ip);
    e.add_front(ParsedParameter::with_floats(
        "point3",
        "P",
        e.loc.clone(),
        p,
    ));
    e.add_front(ParsedParameter::with_floats(
        "point2",
        "uv",
        e.loc.clone(),
        uv,
    ));
}

pub mod legacy;
mod nurbs;

#[cfg(test)]
mod tests;
