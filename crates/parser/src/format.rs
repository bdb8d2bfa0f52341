//! A [`ParserTarget`] that prints the scene back as canonical pbrt-v4 text
//! (pbrt-v4 `FormattingParserTarget`, `pbrt --format` / `--upgrade`).
//!
//! One directive per line, parameters on the following lines indented one
//! step further, blocks (`AttributeBegin`, `ObjectBegin`) indented, numbers
//! in the shortest form that reads back to the same `f32`. Formatting is a
//! pure function of the directive stream, so formatting formatted output
//! gives the same bytes. `Include`/`Import` are printed, not followed.
//!
//! With `upgrade`, a texture, named material or object defined again
//! (legal in pbrt-v3, where the later definition wins; an error in
//! pbrt-v4) is renamed `<name>-renamed-<n>` with pbrt-v4's warning, `n`
//! counting from 0 per kind. References are renamed to the most recent
//! definition: texture parameters (of materials, textures and shapes),
//! `NamedMaterial`, a `mix` material's materials and `ObjectInstance`.
//! pbrt-v4 renames only the texture parameters of materials and textures
//! and `ObjectInstance`, so its `NamedMaterial "m"` after a redefinition
//! would pick the first definition; and it registers a texture's new name
//! before renaming the texture's own parameters, so a pbrt-v3 texture that
//! builds on the one it replaces would refer to itself. Both are fixed
//! here so that the upgraded file renders as the pbrt-v3 one did.
//!
//! Comments are kept, as pbrt-v4's `--format` keeps them: each on a line
//! of its own at the current indentation. pbrt-v4 prints a comment when
//! its tokenizer reaches it, which puts a comment that follows a directive
//! with parameters before that directive (the parser has read past it
//! looking for more parameters); here every comment stays after the
//! directive it follows and before the next one.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::diag::Diagnostic;
use crate::loc::FileLoc;
use crate::params::{canonical_type, ParsedParameter};
use crate::target::{DirectiveResult, IncludeKind, ParamList, ParserTarget};
use crate::tokenizer::escape_string;
use crate::upgrade::legacy::{Given, LegacyTransport, Target, Transport};
use crate::upgrade::{self, Upgraded};

/// Prints directives as canonical pbrt-v4 text into a string.
#[derive(Clone, Debug, Default)]
pub struct FormattingTarget {
    out: String,
    depth: usize,
    upgrade: bool,
    diags: Vec<Diagnostic>,
    toply: Option<ToPly>,
    /// `--upgrade`'s current name of each texture, named material and
    /// object instance.
    renames: [Renames; 3],
    /// `--upgrade`: a pbrt-v1/v2 file's `Renderer`, `SurfaceIntegrator`
    /// and `VolumeIntegrator`, written as one `Integrator` at `WorldBegin`.
    legacy: LegacyTransport,
}

/// Which kind of named thing a [`Renames`] table holds.
#[derive(Clone, Copy)]
enum Kind {
    Texture = 0,
    Material = 1,
    Object = 2,
}

impl Kind {
    /// pbrt-v4's word for the kind in the renaming warning.
    fn what(self) -> &'static str {
        match self {
            Kind::Texture => "texture",
            Kind::Material => "named material",
            Kind::Object => "object instance",
        }
    }
}

/// The names defined so far of one kind, each with the name it is printed
/// under, and how many were renamed.
#[derive(Clone, Debug, Default)]
struct Renames {
    current: HashMap<String, String>,
    count: usize,
}

/// Where `--toply` writes meshes, and how many it has written.
#[derive(Clone, Debug, Default)]
struct ToPly {
    dir: std::path::PathBuf,
    prefix: String,
    count: usize,
}

/// Meshes with fewer vertex indices than this stay inline under `--toply`
/// (as in pbrt-v4).
pub const TOPLY_MIN_INDICES: usize = 500;

/// Formats `v` in the shortest decimal form that parses back to `v`.
pub fn format_float(v: f32) -> String {
    let s = format!("{v:?}");
    match s.strip_suffix(".0") {
        Some(t) => t.to_string(),
        None => s,
    }
}

impl FormattingTarget {
    /// A formatter; with `upgrade` it also maps pbrt-v3 constructs to pbrt-v4.
    pub fn new(upgrade: bool) -> Self {
        FormattingTarget {
            upgrade,
            ..Self::default()
        }
    }

    /// Makes the formatter write every `trianglemesh` with at least
    /// [`TOPLY_MIN_INDICES`] indices to `dir/<prefix>_NNNNN.ply` (object
    /// space, binary) and print a `plymesh` shape referring to it instead
    /// (`pbrt --toply`).
    pub fn with_toply(
        mut self,
        dir: impl Into<std::path::PathBuf>,
        prefix: impl Into<String>,
    ) -> Self {
        self.toply = Some(ToPly {
            dir: dir.into(),
            prefix: prefix.into(),
            count: 0,
        });
        self
    }

    /// Writes an inline triangle mesh to a PLY file; returns the file name
    /// to reference, or `None` when the mesh is small enough to stay inline.
    fn mesh_to_ply(
        &mut self,
        params: &mut ParamList,
        loc: &FileLoc,
    ) -> Result<Option<String>, Diagnostic> {
        if self.toply.is_none() {
            return Ok(None);
        }
        let dict = crate::params::ParameterDictionary::new(params.clone());
        let idx = dict.get_int_array("indices").map_err(Diagnostic::from)?;
        if idx.len() < TOPLY_MIN_INDICES {
            return Ok(None);
        }
        let positions = dict.get_point3_array("P").map_err(Diagnostic::from)?;
        let normals = dict.get_normal3_array("N").map_err(Diagnostic::from)?;
        let uvs = dict.get_point2_array("uv").map_err(Diagnostic::from)?;
        let face_indices = dict
            .get_int_array("faceIndices")
            .map_err(Diagnostic::from)?;
        if !dict
            .get_vector3_array("S")
            .map_err(Diagnostic::from)?
            .is_empty()
        {
            self.diags.push(Diagnostic::warning(
                loc.clone(),
                "--toply: per-vertex tangents \"S\" cannot be stored in PLY and are dropped",
            ));
        }
        let mut tri_indices = Vec::with_capacity(idx.len());
        for &i in &idx {
            if i < 0 || i as usize >= positions.len() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    format!(
                        "--toply: vertex index {i} is out of range (the mesh has {} vertices)",
                        positions.len()
                    ),
                ));
            }
            tri_indices.push(i as u32);
        }
        if tri_indices.len() % 3 != 0 {
            return Err(Diagnostic::error(
                loc.clone(),
                "--toply: the number of indices is not a multiple of 3",
            ));
        }
        let Some(tp) = self.toply.as_mut() else {
            return Ok(None);
        };
        tp.count += 1;
        let file = format!("{}_{:05}.ply", tp.prefix, tp.count);
        let mesh = crate::ply::PlyMesh {
            positions,
            normals,
            uvs,
            tri_indices,
            quad_indices: Vec::new(),
            face_indices,
            warnings: Vec::new(),
        };
        crate::ply::write_ply(&tp.dir.join(&file), &mesh)
            .map_err(|e| Diagnostic::error(loc.clone(), format!("--toply: {e}")))?;
        params.retain(|p| {
            !matches!(
                p.name.as_str(),
                "indices" | "P" | "N" | "S" | "uv" | "faceIndices"
            )
        });
        Ok(Some(file))
    }

    /// The text printed so far.
    pub fn output(&self) -> &str {
        &self.out
    }

    /// The printed text.
    pub fn into_output(self) -> String {
        self.out
    }

    fn indent(&mut self, extra: usize) {
        for _ in 0..(self.depth + extra) {
            self.out.push_str("    ");
        }
    }

    fn line(&mut self, text: &str) {
        self.indent(0);
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn quoted(s: &str) -> String {
        format!("\"{}\"", escape_string(s))
    }

    fn named(&mut self, directive: &str, name: &str, params: &[ParsedParameter]) {
        self.line(&format!("{directive} {}", Self::quoted(name)));
        self.params(params);
    }

    fn params(&mut self, params: &[ParsedParameter]) {
        for p in params {
            self.param(p);
        }
    }

    fn param(&mut self, p: &ParsedParameter) {
        let ty = if self.upgrade {
            canonical_type(&p.ty).unwrap_or(&p.ty)
        } else {
            &p.ty
        };
        let mut vals: Vec<String> = Vec::with_capacity(p.value_count());
        vals.extend(p.floats.iter().map(|&f| format_float(f)));
        vals.extend(p.ints.iter().map(|i| i.to_string()));
        vals.extend(p.strings.iter().map(|s| Self::quoted(s)));
        vals.extend(
            p.bools
                .iter()
                .map(|&b| if b { "true" } else { "false" }.to_string()),
        );
        let per_line = match canonical_type(ty) {
            Some("point2" | "vector2") => 12,
            Some("string" | "texture") => 4,
            _ if !p.strings.is_empty() => 4,
            _ => 12,
        };
        self.indent(1);
        let _ = write!(self.out, "{} [", Self::quoted(&format!("{ty} {}", p.name)));
        if vals.len() <= per_line {
            for v in &vals {
                self.out.push(' ');
                self.out.push_str(v);
            }
            self.out.push_str(" ]\n");
        } else {
            self.out.push('\n');
            for chunk in vals.chunks(per_line) {
                self.indent(2);
                self.out.push_str(&chunk.join(" "));
                self.out.push('\n');
            }
            self.indent(1);
            self.out.push_str("]\n");
        }
    }

    /// Registers a definition of `name` (under `--upgrade`) and returns the
    /// name to print: `name`, or a fresh `<name>-renamed-<n>` with a warning
    /// when it was defined before.
    fn define(&mut self, kind: Kind, name: &str, loc: &FileLoc) -> String {
        if !self.upgrade {
            return name.to_string();
        }
        let r = &mut self.renames[kind as usize];
        let printed = if r.current.contains_key(name) {
            let new = format!("{name}-renamed-{}", r.count);
            r.count += 1;
            self.diags.push(Diagnostic::warning(
                loc.clone(),
                format!("{name}: renaming multiply-defined {}", kind.what()),
            ));
            new
        } else {
            name.to_string()
        };
        r.current.insert(name.to_string(), printed.clone());
        printed
    }

    /// The name a reference to `name` is printed as: its most recent
    /// definition's (under `--upgrade`), else `name`.
    fn reference(&self, kind: Kind, name: &str) -> String {
        if !self.upgrade {
            return name.to_string();
        }
        self.renames[kind as usize]
            .current
            .get(name)
            .cloned()
            .unwrap_or_else(|| name.to_string())
    }

    /// Renames the texture references among `params` (and, with
    /// `materials`, a `mix` material's material names) to their most
    /// recent definitions.
    fn rename_references(&self, params: &mut ParamList, materials: bool) {
        if !self.upgrade {
            return;
        }
        for p in params.iter_mut() {
            let kind = match upgrade::reference_of(p) {
                Some(upgrade::Reference::Texture) => Kind::Texture,
                Some(upgrade::Reference::NamedMaterial) if materials => Kind::Material,
                _ => continue,
            };
            for s in p.strings.iter_mut() {
                *s = self.reference(kind, s);
            }
        }
    }

    fn take(&mut self, u: Upgraded) -> (String, ParamList) {
        self.diags.extend(u.diagnostics);
        (u.name, u.params)
    }

    fn nums(v: &[f32]) -> String {
        v.iter()
            .map(|&f| format_float(f))
            .collect::<Vec<_>>()
            .join(" ")
    }

    fn simple(
        &mut self,
        directive: &str,
        name: &str,
        params: ParamList,
        loc: &FileLoc,
        f: fn(&str, ParamList, &FileLoc) -> Upgraded,
    ) -> DirectiveResult {
        if self.upgrade {
            let u = f(name, params, loc);
            let (n, p) = self.take(u);
            self.named(directive, &n, &p);
        } else {
            self.named(directive, name, &params);
        }
        Ok(())
    }
}

impl FormattingTarget {
    /// `Renderer`, `SurfaceIntegrator` or `VolumeIntegrator`: printed as
    /// they are, or under `--upgrade` kept for the one `Integrator`
    /// [`FormattingTarget::world_begin`] writes.
    fn legacy_transport(
        &mut self,
        which: Transport,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        if self.upgrade {
            self.legacy.set(which, Given::new(name, params, loc));
        } else {
            self.named(which.directive(), name, &params);
        }
        Ok(())
    }
}

fn identity(name: &str, mut params: ParamList, _: &FileLoc) -> Upgraded {
    upgrade::upgrade_param_types(&mut params);
    Upgraded {
        name: name.to_string(),
        params,
        diagnostics: Vec::new(),
    }
}

impl ParserTarget for FormattingTarget {
    fn identity(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("Identity");
        Ok(())
    }
    fn translate(&mut self, d: [f32; 3], _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("Translate {}", Self::nums(&d)));
        Ok(())
    }
    fn scale(&mut self, s: [f32; 3], _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("Scale {}", Self::nums(&s)));
        Ok(())
    }
    fn rotate(&mut self, angle: f32, axis: [f32; 3], _loc: FileLoc) -> DirectiveResult {
        self.line(&format!(
            "Rotate {} {}",
            format_float(angle),
            Self::nums(&axis)
        ));
        Ok(())
    }
    fn look_at(
        &mut self,
        eye: [f32; 3],
        look: [f32; 3],
        up: [f32; 3],
        _loc: FileLoc,
    ) -> DirectiveResult {
        self.line(&format!("LookAt {}", Self::nums(&eye)));
        self.line(&format!("       {}", Self::nums(&look)));
        self.line(&format!("       {}", Self::nums(&up)));
        Ok(())
    }
    fn concat_transform(&mut self, m: [f32; 16], _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("ConcatTransform [ {} ]", Self::nums(&m)));
        Ok(())
    }
    fn transform(&mut self, m: [f32; 16], _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("Transform [ {} ]", Self::nums(&m)));
        Ok(())
    }
    fn coordinate_system(&mut self, name: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("CoordinateSystem {}", Self::quoted(name)));
        Ok(())
    }
    fn coord_sys_transform(&mut self, name: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("CoordSysTransform {}", Self::quoted(name)));
        Ok(())
    }
    fn search_path(&mut self, path: &str, _loc: FileLoc) -> DirectiveResult {
        // Only pbrt-v1's plugin lookup read it: dropped by --upgrade.
        if !self.upgrade {
            self.line(&format!("SearchPath {}", Self::quoted(path)));
        }
        Ok(())
    }
    fn active_transform_all(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("ActiveTransform All");
        Ok(())
    }
    fn active_transform_end_time(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("ActiveTransform EndTime");
        Ok(())
    }
    fn active_transform_start_time(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("ActiveTransform StartTime");
        Ok(())
    }
    fn transform_times(&mut self, start: f32, end: f32, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!(
            "TransformTimes {} {}",
            format_float(start),
            format_float(end)
        ));
        Ok(())
    }
    fn reverse_orientation(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("ReverseOrientation");
        Ok(())
    }
    fn color_space(&mut self, name: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("ColorSpace {}", Self::quoted(name)));
        Ok(())
    }
    fn pixel_filter(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple(
            "PixelFilter",
            name,
            params,
            &loc,
            upgrade::upgrade_pixel_filter,
        )
    }
    fn film(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple("Film", name, params, &loc, upgrade::upgrade_film)
    }
    fn sampler(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple("Sampler", name, params, &loc, upgrade::upgrade_sampler)
    }
    fn accelerator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple(
            "Accelerator",
            name,
            params,
            &loc,
            upgrade::upgrade_accelerator,
        )
    }
    fn renderer(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.legacy_transport(Transport::Renderer, name, params, loc)
    }
    fn surface_integrator(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.legacy_transport(Transport::Surface, name, params, loc)
    }
    fn volume_integrator(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.legacy_transport(Transport::Volume, name, params, loc)
    }
    fn volume(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        if self.upgrade {
            self.diags.push(Diagnostic::error(
                loc,
                format!("pbrt-v4 has no \"Volume\" regions: --upgrade cannot write this \"{name}\" region (give it a bounding shape with a MediumInterface)"),
            ));
        } else {
            self.named("Volume", name, &params);
        }
        Ok(())
    }
    fn integrator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple(
            "Integrator",
            name,
            params,
            &loc,
            upgrade::upgrade_integrator,
        )
    }
    fn camera(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple("Camera", name, params, &loc, upgrade::upgrade_camera)
    }
    fn make_named_medium(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        // The medium's kind is its "string type" parameter.
        if !self.upgrade {
            self.named("MakeNamedMedium", name, &params);
            return Ok(());
        }
        let mut params = params;
        let at = params
            .iter()
            .rposition(|p| p.name == "type" && p.ty == "string" && p.strings.len() == 1);
        let Some(at) = at else {
            // No usable type: only the parameter types are upgraded.
            upgrade::upgrade_param_types(&mut params);
            self.named("MakeNamedMedium", name, &params);
            return Ok(());
        };
        let ty = params.remove(at);
        let u = upgrade::upgrade_medium(&ty.strings[0], params, &loc);
        let (new, mut p) = self.take(u);
        p.insert(
            0,
            ParsedParameter::with_strings("string", "type", ty.loc, vec![new]),
        );
        self.named("MakeNamedMedium", name, &p);
        Ok(())
    }
    fn medium_interface(&mut self, inside: &str, outside: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!(
            "MediumInterface {} {}",
            Self::quoted(inside),
            Self::quoted(outside)
        ));
        Ok(())
    }
    fn option(&mut self, name: &str, value: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(&format!("Option {} {value}", Self::quoted(name)));
        Ok(())
    }
    fn world_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        if !self.legacy.is_empty() {
            let u = std::mem::take(&mut self.legacy).integrator(false, Target::PbrtV4, &loc);
            let (n, p) = self.take(u);
            self.named("Integrator", &n, &p);
        }
        self.out.push('\n');
        self.line("WorldBegin");
        self.out.push('\n');
        Ok(())
    }
    fn world_end(&mut self, _loc: FileLoc) -> DirectiveResult {
        Ok(()) // pbrt-v3 only: dropped, as pbrt-v4 does.
    }
    fn attribute_begin(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line("AttributeBegin");
        self.depth += 1;
        Ok(())
    }
    fn attribute_end(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.depth = self.depth.saturating_sub(1);
        self.line("AttributeEnd");
        Ok(())
    }
    fn attribute(&mut self, target: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple("Attribute", target, params, &loc, identity)
    }
    fn transform_begin(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.line(if self.upgrade {
            "AttributeBegin"
        } else {
            "TransformBegin"
        });
        self.depth += 1;
        Ok(())
    }
    fn transform_end(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.depth = self.depth.saturating_sub(1);
        self.line(if self.upgrade {
            "AttributeEnd"
        } else {
            "TransformEnd"
        });
        Ok(())
    }
    fn texture(
        &mut self,
        name: &str,
        ty: &str,
        texname: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        let mut params = params;
        self.rename_references(&mut params, false);
        let name = self.define(Kind::Texture, name, &loc);
        let (ty, class, params) = if self.upgrade {
            let (ty, u) = upgrade::upgrade_texture(ty, texname, params, &loc);
            let (class, p) = self.take(u);
            (ty, class, p)
        } else {
            (ty.to_string(), texname.to_string(), params)
        };
        self.line(&format!(
            "Texture {} {} {}",
            Self::quoted(&name),
            Self::quoted(&ty),
            Self::quoted(&class)
        ));
        self.params(&params);
        Ok(())
    }
    fn material(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let mut params = params;
        self.rename_references(&mut params, true);
        self.simple("Material", name, params, &loc, upgrade::upgrade_material)
    }
    fn make_named_material(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        if !self.upgrade {
            self.named("MakeNamedMaterial", name, &params);
            return Ok(());
        }
        let mut params = params;
        self.rename_references(&mut params, true);
        let name = self.define(Kind::Material, name, &loc);
        let ty = params
            .iter()
            .rposition(|p| p.name == "type" && p.ty == "string")
            .map(|i| params.remove(i));
        let old = ty
            .as_ref()
            .and_then(|p| p.strings.first().cloned())
            .unwrap_or_default();
        let u = upgrade::upgrade_material(&old, params, &loc);
        let (new, mut p) = self.take(u);
        let tloc = ty.map_or(loc, |t| t.loc);
        p.insert(
            0,
            ParsedParameter::with_strings("string", "type", tloc, vec![new]),
        );
        self.named("MakeNamedMaterial", &name, &p);
        Ok(())
    }
    fn named_material(&mut self, name: &str, _loc: FileLoc) -> DirectiveResult {
        let name = self.reference(Kind::Material, name);
        self.line(&format!("NamedMaterial {}", Self::quoted(&name)));
        Ok(())
    }
    fn light_source(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.simple("LightSource", name, params, &loc, upgrade::upgrade_light)
    }
    fn area_light_source(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.simple(
            "AreaLightSource",
            name,
            params,
            &loc,
            upgrade::upgrade_area_light,
        )
    }
    fn shape(&mut self, name: &str, mut params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.rename_references(&mut params, false);
        if name == "trianglemesh" {
            if let Some(file) = self.mesh_to_ply(&mut params, &loc)? {
                let mut all = vec![ParsedParameter::with_strings(
                    "string",
                    "filename",
                    loc.clone(),
                    vec![file],
                )];
                all.extend(params);
                return self.simple("Shape", "plymesh", all, &loc, upgrade::upgrade_shape);
            }
        }
        self.simple("Shape", name, params, &loc, upgrade::upgrade_shape)
    }
    fn object_begin(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        let name = self.define(Kind::Object, name, &loc);
        self.line(&format!("ObjectBegin {}", Self::quoted(&name)));
        self.depth += 1;
        Ok(())
    }
    fn object_end(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.depth = self.depth.saturating_sub(1);
        self.line("ObjectEnd");
        Ok(())
    }
    fn object_instance(&mut self, name: &str, _loc: FileLoc) -> DirectiveResult {
        let name = self.reference(Kind::Object, name);
        self.line(&format!("ObjectInstance {}", Self::quoted(&name)));
        Ok(())
    }
    fn end_of_files(&mut self) -> DirectiveResult {
        Ok(())
    }
    fn wants_comments(&self) -> bool {
        true
    }
    fn comment(&mut self, text: &str, _loc: FileLoc) -> DirectiveResult {
        self.line(text);
        Ok(())
    }
    fn include(
        &mut self,
        filename: &str,
        kind: IncludeKind,
        _loc: FileLoc,
    ) -> Result<bool, Diagnostic> {
        let d = match kind {
            IncludeKind::Include => "Include",
            IncludeKind::Import => "Import",
        };
        self.line(&format!("{d} {}", Self::quoted(filename)));
        Ok(false)
    }
    fn take_diagnostics(&mut self) -> Vec<Diagnostic> {
        std::mem::take(&mut self.diags)
    }
}

#[cfg(test)]
mod tests;
