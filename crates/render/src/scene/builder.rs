//! The scene builder: a [`ParserTarget`] that follows pbrt-v4's
//! `BasicSceneBuilder` (`scene.h`/`scene.cpp`, book section C.2.3). It keeps
//! the graphics state (current transformation for the start and end of the
//! shutter interval, material, area light, media, color space, `Attribute`
//! defaults) on an explicit stack and turns every directive into a plain
//! entity of a [`SceneDescription`].
//!
//! pbrt-v3 input is read directly: each typed directive first goes through
//! the parser crate's `upgrade_*` mappings, whose warnings are reported at
//! the directive. A directive the mapping leaves alone produces no message.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use rpbrt_geometry::{
    AnimatedTransform, Point3f, SquareMatrix4, Transform, TransformError, Vector3f,
};
use rpbrt_parser::budget::{heap, vec_element};
use rpbrt_parser::upgrade::legacy::{Given, LegacyTransport, Target, Transport};
use rpbrt_parser::upgrade::{self, Reference, Upgraded};
use rpbrt_parser::{Diagnostic, MemoryBudget};
use rpbrt_parser::{
    DirectiveResult, FileLoc, ParamList, ParameterDictionary, ParsedParameter, ParserTarget,
};

use super::entities::*;
use super::entity_list::EntityList;
use super::names::*;
use super::state::*;
use crate::bxdf::LAFORTUNE_MATERIALS;
use crate::camera::{CameraTransform, RenderingCoordinateSystem};
use crate::params::unknown_type;
use crate::spectrum::RgbColorSpace;

/// What one entry of the `AttributeBegin`/`TransformBegin`/`ObjectBegin`
/// stack is charged: the graphics state it saves.
const PUSHED_BYTES: usize =
    2 * std::mem::size_of::<Pushed>() + std::mem::size_of::<GraphicsState>();

/// A pbrt-v3 → pbrt-v4 mapping of the parser crate.
type UpgradeFn = fn(&str, Vec<ParsedParameter>, &FileLoc) -> Upgraded;

/// Builds a [`SceneDescription`] from parser callbacks (pbrt-v4
/// `BasicSceneBuilder`).
#[derive(Debug)]
pub struct SceneBuilder {
    scene: SceneDescription,
    block: Block,
    state: GraphicsState,
    pushed: Vec<Pushed>,
    /// Boxes of states popped by `AttributeEnd`, reused by the next
    /// `AttributeBegin` (a scene of many small attribute blocks would
    /// otherwise allocate and free one for each). Boxed: the boxes
    /// themselves move into and out of `pushed`.
    #[allow(clippy::vec_box)]
    spare_states: Vec<Box<GraphicsState>>,
    named_coordinate_systems: HashMap<String, TransformSet>,
    render_from_world: Transform,
    camera_defined: bool,
    active_definition: Option<InstanceDefinitionSceneEntity>,
    instance_names: HashSet<Arc<str>>,
    named_material_names: HashSet<String>,
    medium_names: HashSet<String>,
    float_texture_names: HashSet<String>,
    spectrum_texture_names: HashSet<String>,
    /// `NamedMaterial` directives, checked once all files are read.
    named_material_uses: Vec<(String, FileLoc)>,
    /// Media named by `MediumInterface`, checked once all files are read.
    medium_uses: Vec<(String, FileLoc)>,
    /// Messages waiting for [`ParserTarget::take_diagnostics`].
    pending: Vec<Diagnostic>,
    /// pbrt-v3's redefined textures and named materials (see
    /// [`SceneBuilder::redefine`]).
    renames: [Renames; 2],
    /// Redefinitions met before anything marked the files as pbrt-v3:
    /// pbrt-v4's error and pbrt-v3's warning, one of which the end of the
    /// files gives.
    undecided_redefinitions: Vec<(Diagnostic, Diagnostic)>,
    /// A pbrt-v1/v2 file's `Renderer`, `SurfaceIntegrator` and
    /// `VolumeIntegrator`, made into one integrator once all files are read.
    legacy: LegacyTransport,
    /// A `LookAt` came before `WorldBegin`.
    options_look_at: bool,
    /// The `Camera`'s world-from-camera transformations and times, and
    /// whether a `LookAt` came before it (pbrt-v1's mirrors the view).
    camera_placement: Option<([Transform; 2], [f32; 2], bool)>,
}

/// The names of one kind that a pbrt-v3 file defined more than once, each
/// with the name its latest definition is stored under, and how many were
/// renamed.
#[derive(Clone, Debug, Default)]
struct Renames {
    current: HashMap<String, String>,
    count: usize,
}

/// Whether `e` is a default the file did not set.
fn unset_entity(e: &SceneEntity) -> bool {
    e.loc == default_loc()
}

/// An integer parameter standing for a default.
fn default_int(name: &str, v: i32) -> ParsedParameter {
    let mut p = ParsedParameter::new("integer", name, default_loc());
    p.ints = vec![v];
    p
}

/// At most this many popped states' boxes are kept for reuse (the depth
/// of nesting that gains from it).
const MAX_SPARE_STATES: usize = 16;

/// An entity standing for a default.
fn default_entity(name: &'static str, params: Vec<ParsedParameter>) -> SceneEntity {
    SceneEntity::new(
        name,
        ParameterDictionary::new(params),
        default_loc(),
        "srgb",
    )
}

impl Default for SceneBuilder {
    fn default() -> Self {
        SceneBuilder::new(RenderingCoordinateSystem::default())
    }
}

impl SceneBuilder {
    /// A builder rendering in `render_coord_sys` unless the scene's
    /// `Option "rendercoordsys"` says otherwise.
    pub fn new(render_coord_sys: RenderingCoordinateSystem) -> Self {
        let scene = SceneDescription {
            render_coord_sys,
            ..SceneDescription::default()
        };
        SceneBuilder {
            scene,
            block: Block::Options,
            state: GraphicsState::default(),
            pushed: Vec::new(),
            spare_states: Vec::new(),
            named_coordinate_systems: HashMap::new(),
            render_from_world: Transform::identity(),
            camera_defined: false,
            active_definition: None,
            instance_names: HashSet::new(),
            named_material_names: HashSet::new(),
            medium_names: HashSet::new(),
            float_texture_names: HashSet::new(),
            spectrum_texture_names: HashSet::new(),
            named_material_uses: Vec::new(),
            medium_uses: Vec::new(),
            pending: Vec::new(),
            undecided_redefinitions: Vec::new(),
            renames: Default::default(),
            legacy: LegacyTransport::default(),
            options_look_at: false,
            camera_placement: None,
        }
    }

    /// The builder charging the description to `budget` (by default, to
    /// [`MemoryBudget::default`]); the description keeps it for creation.
    pub fn with_budget(mut self, budget: MemoryBudget) -> Self {
        self.scene.budget = budget;
        self
    }

    /// The description built so far (complete after `end_of_files`).
    pub fn scene(&self) -> &SceneDescription {
        &self.scene
    }

    /// Hands over the description.
    pub fn finish(self) -> SceneDescription {
        self.scene
    }

    /// Depth of the `AttributeBegin`/`ObjectBegin`/`TransformBegin` stack.
    pub fn nesting_depth(&self) -> usize {
        self.pushed.len()
    }

    // ---- the memory budget ------------------------------------------------

    /// Charges `bytes`, what the directive `what` at `loc` adds to the
    /// description, to the memory budget: a scene of millions of
    /// directives ends in a located error when the budget runs out, not in
    /// an allocation failure.
    fn charge(&self, bytes: usize, what: &str, loc: &FileLoc) -> DirectiveResult {
        self.scene
            .budget
            .charge_lazily(bytes as u64, || format!("this {what}"))
            .map_err(|e| Diagnostic::error(loc.clone(), e.to_string()))
    }

    /// [`charge`](Self::charge) for an entity of type `T` whose heap part is `e`'s.
    fn charge_entity<T>(&self, e: &SceneEntity, what: &str) -> DirectiveResult {
        self.charge(vec_element::<T>() + e.heap_bytes(), what, &e.loc)
    }

    // ---- state checks ---------------------------------------------------

    fn verify_options(&self, directive: &str, loc: &FileLoc) -> DirectiveResult {
        if self.block == Block::World {
            return Err(Diagnostic::error(
                loc.clone(),
                format!("{directive} not allowed after WorldBegin"),
            ));
        }
        Ok(())
    }

    fn verify_world(&self, directive: &str, loc: &FileLoc) -> DirectiveResult {
        if self.block == Block::Options {
            return Err(Diagnostic::error(
                loc.clone(),
                format!("{directive} not allowed before WorldBegin"),
            ));
        }
        Ok(())
    }

    // ---- transformations --------------------------------------------------

    fn render_from_object_at(&self, i: usize) -> Transform {
        self.render_from_world * self.state.ctm[i]
    }

    fn render_from_object(&self) -> AnimatedTransform {
        AnimatedTransform::new(
            self.render_from_object_at(0),
            self.state.start_time,
            self.render_from_object_at(1),
            self.state.end_time,
        )
    }

    fn ctm_is_animated(&self) -> bool {
        self.state.ctm[0] != self.state.ctm[1]
    }

    fn transform_error(e: TransformError, loc: FileLoc, directive: &str) -> Diagnostic {
        Diagnostic::error(
            loc,
            format!("{directive}: {e}; the current transformation is unchanged"),
        )
    }

    /// The matrix of `Transform`/`ConcatTransform`: the 16 values are the
    /// matrix's columns, one after the other (pbrt transposes them).
    fn matrix_from_values(
        m: &[f32; 16],
        loc: &FileLoc,
        directive: &str,
    ) -> Result<Transform, Diagnostic> {
        let mut rows = [[0.0; 4]; 4];
        for (i, row) in rows.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = m[j * 4 + i];
            }
        }
        Transform::from_matrix(SquareMatrix4::new(rows))
            .map_err(|e| Self::transform_error(e, loc.clone(), directive))
    }

    /// In a scene marked pbrt-v3, the rendering options the file left out
    /// take pbrt-v3's defaults (pbrt-v3 `core/api.cpp`'s `RenderOptions`
    /// and the creators' parameter defaults): a box filter of radius 0.5,
    /// the `halton` sampler with 16 samples and the `path` integrator with
    /// depth 5, where pbrt-v4's are `gaussian`, `zsobol` and `volpath`.
    /// (Both default to a 1280 × 720 film, a `bvh` and a perspective
    /// camera with a 90° field of view.)
    fn use_pbrt_v3_defaults(&mut self) {
        let (unset, int, entity) = (unset_entity, default_int, default_entity);
        if unset(&self.scene.filter) {
            self.scene.filter = entity("box", Vec::new());
        }
        if unset(&self.scene.sampler) {
            self.scene.sampler = entity("halton", vec![int("pixelsamples", 16)]);
        }
        if unset(&self.scene.integrator) {
            self.scene.integrator = entity("path", vec![int("maxdepth", 5)]);
        }
    }

    /// In a pbrt-v1/v2 scene, the rendering options the file left out take
    /// pbrt-v2's defaults (pbrt-v2 `core/api.cpp`'s `RenderOptions` and
    /// the creators' parameter defaults): a 640 × 480 film, a box filter
    /// of radius 0.5 and the `lowdiscrepancy` sampler (→ `paddedsobol`)
    /// with 4 samples; its `Renderer`, `SurfaceIntegrator` (default
    /// `directlighting`) and `VolumeIntegrator` become the integrator
    /// unless the file also gave an `Integrator`.
    fn use_pbrt_v2_defaults(&mut self, v2: &FileLoc) {
        let (unset, int, entity) = (unset_entity, default_int, default_entity);
        // pbrt-v2's creators' defaults, where the directive was given
        // without them.
        let missing =
            |e: &SceneEntity, name: &str| !e.params.params().iter().any(|p| p.name == name);
        let mut film_extra = Vec::new();
        for (name, v) in [("xresolution", 640), ("yresolution", 480)] {
            if missing(&self.scene.film, name) {
                film_extra.push(int(name, v));
            }
        }
        let mut sampler_extra = Vec::new();
        if self.scene.sampler.name == "stratified" {
            for name in ["xsamples", "ysamples"] {
                if missing(&self.scene.sampler, name) {
                    sampler_extra.push(int(name, 2));
                }
            }
        } else if missing(&self.scene.sampler, "pixelsamples") {
            sampler_extra.push(int("pixelsamples", 4));
        }
        for (e, extra) in [
            (&mut self.scene.film, film_extra),
            (&mut self.scene.sampler, sampler_extra),
        ] {
            if !extra.is_empty() {
                let mut params = std::mem::take(&mut e.params).into_params();
                params.extend(extra);
                e.params = ParameterDictionary::new(params);
            }
        }
        // (pbrt-v1's own defaults are already in place.)
        let not_v1 = self.scene.pbrt_v1.is_none();
        if not_v1 && unset(&self.scene.filter) {
            self.scene.filter = entity("box", Vec::new());
        }
        if not_v1 && unset(&self.scene.sampler) {
            self.scene.sampler.name = "paddedsobol".into();
        }
        let legacy = std::mem::take(&mut self.legacy);
        if !unset(&self.scene.integrator) {
            if let Some(g) = [&legacy.renderer, &legacy.surface, &legacy.volume]
                .into_iter()
                .flatten()
                .next()
            {
                self.pending.push(Diagnostic::warning(
                    g.loc.clone(),
                    format!(
                        "ignored: the \"Integrator\" at {} chooses the light transport",
                        self.scene.integrator.loc
                    ),
                ));
            }
            return;
        }
        // pbrt-v2's default volume integrator, `emission`, ignores
        // scattering.
        self.scene.regions_scatter = legacy.volume.as_ref().is_some_and(|v| v.name != "emission");
        let volumes = !self.scene.volume_regions.is_empty();
        let u = legacy.integrator(volumes, Target::Render, v2);
        let failed = u.diagnostics.iter().any(Diagnostic::is_error);
        self.pending.extend(u.diagnostics);
        if failed {
            return;
        }
        let loc = [&legacy.renderer, &legacy.surface]
            .into_iter()
            .flatten()
            .next()
            .map_or_else(default_loc, |g| g.loc.clone());
        self.scene.integrator = self.entity(u.name, u.params, loc);
    }

    /// pbrt-v2 put a point light at `from` added to where the
    /// transformation takes the origin (its light-to-world was
    /// `Translate(from) · CTM`); pbrt-v3 and pbrt-v4 transform `from`
    /// itself. `from` is replaced by the point the transformation takes
    /// to pbrt-v2's position.
    fn v2_point_from(&self, params: &mut ParamList) {
        let ctm = self.state.ctm[0];
        if let Some(p) = params
            .iter_mut()
            .rev()
            .find(|p| p.name == "from" && p.ty == "point3" && p.floats.len() == 3)
        {
            let from = Vector3f::new(p.floats[0], p.floats[1], p.floats[2]);
            let world = ctm.apply_point(Point3f::new(0.0, 0.0, 0.0)) + from;
            let q = ctm.inverse().apply_point(world);
            p.floats = vec![q.x, q.y, q.z];
        }
    }

    /// Notes a material type only pbrt-v1/v2 had, and gives a pbrt-v1
    /// file's materials pbrt-v1's defaults where they differ from
    /// pbrt-v2's (`Kd` 1 for `matte`, `plastic` and `uber`, `Ks` 1 for
    /// `plastic` and `uber`, `Kr` 1 for `mirror`).
    fn v1_v2_material(&mut self, ty: &str, params: &mut ParamList, loc: &FileLoc) {
        if ty == "shinymetal" {
            self.note_pbrt_v2(loc);
        } else if LAFORTUNE_MATERIALS.contains(&ty) {
            self.note_pbrt_v1(loc);
        }
        if self.scene.pbrt_v1.is_none() {
            return;
        }
        let ones: &[&str] = match ty {
            "matte" => &["Kd"],
            "plastic" | "uber" => &["Kd", "Ks"],
            "mirror" => &["Kr"],
            _ => &[],
        };
        for &name in ones {
            if !params.iter().any(|p| p.name == name) {
                params.push(ParsedParameter::with_floats(
                    "rgb",
                    name,
                    loc.clone(),
                    vec![1.0; 3],
                ));
            }
        }
    }

    /// `Renderer`, `SurfaceIntegrator` or `VolumeIntegrator`: kept for
    /// the one integrator made once all files are read.
    fn legacy_transport(
        &mut self,
        which: Transport,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.verify_options(which.directive(), &loc)?;
        self.note_pbrt_v2(&loc);
        self.note_pbrt_v3_params(&params);
        self.legacy.set(which, Given::new(name, params, loc));
        Ok(())
    }

    /// Remembers `loc` if it is the scene's first pbrt-v1-only construct
    /// (which also makes the scene a pbrt-v2 one).
    fn note_pbrt_v1(&mut self, loc: &FileLoc) {
        if self.scene.pbrt_v1.is_none() {
            self.scene.pbrt_v1 = Some(loc.clone());
        }
        self.note_pbrt_v2(loc);
    }

    /// pbrt-v1's defaults where pbrt-v2's differ: a `mitchell` filter, the
    /// `bestcandidate` sampler (→ `pmj02bn`, 4 samples), the `kdtree` and
    /// a `matte` default material of reflectance 1; and its `LookAt`,
    /// whose camera frame was mirrored in x (pbrt-v2's README: add
    /// `Scale -1 1 1` before it to get pbrt-v1's view).
    fn use_pbrt_v1_defaults(&mut self) {
        let unset = unset_entity;
        if unset(&self.scene.filter) {
            self.scene.filter.name = "mitchell".into();
        }
        if unset(&self.scene.sampler) {
            self.scene.sampler.name = "pmj02bn".into();
        }
        if unset(&self.scene.accelerator) {
            self.scene.accelerator.name = "kdtree".into();
        }
        if let Some(m) = self.scene.materials.first_mut() {
            if unset(m) && m.params.params().is_empty() {
                let p =
                    ParsedParameter::with_floats("rgb", "reflectance", default_loc(), vec![1.0; 3]);
                m.params = ParameterDictionary::new(vec![p]);
            }
        }
        let Some(([start, end], [t0, t1], true)) = self.camera_placement else {
            return;
        };
        let mirror = Transform::scale(-1.0, 1.0, 1.0);
        if self.scene.render_coord_sys == RenderingCoordinateSystem::Camera {
            // Render space is camera space there: every shape is already
            // placed in the unmirrored one.
            self.pending.push(Diagnostic::warning(
                self.scene.camera.base.loc.clone(),
                "pbrt-v1's LookAt mirrored the view in x; not reproduced with --render-coord-sys camera",
            ));
            return;
        }
        let animated = AnimatedTransform::new(start * mirror, t0, end * mirror, t1);
        self.scene.camera.camera_transform =
            CameraTransform::new(&animated, self.scene.render_coord_sys);
    }

    /// Remembers `loc` if it is the scene's first pbrt-v1/v2-only
    /// construct (which also makes the scene a pbrt-v3 one).
    fn note_pbrt_v2(&mut self, loc: &FileLoc) {
        if self.scene.pbrt_v2.is_none() {
            self.scene.pbrt_v2 = Some(loc.clone());
        }
        self.note_pbrt_v3(loc);
    }

    // ---- entities ---------------------------------------------------------

    /// Runs a pbrt-v3 → pbrt-v4 mapping and queues its messages; a mapping
    /// that changed nothing reports only errors.
    fn upgraded(
        &mut self,
        f: UpgradeFn,
        name: &str,
        params: ParamList,
        loc: &FileLoc,
    ) -> (String, ParamList) {
        self.note_pbrt_v3_params(&params);
        let before = fingerprint(&params);
        let u = f(name, params, loc);
        self.keep_upgrade_messages(
            name == u.name && before == fingerprint(&u.params),
            u.diagnostics,
        );
        (u.name, u.params)
    }

    /// Remembers `loc` if it is the scene's first pbrt-v3-only construct.
    fn note_pbrt_v3(&mut self, loc: &FileLoc) {
        if self.scene.pbrt_v3.is_none() {
            self.scene.pbrt_v3 = Some(loc.clone());
        }
    }

    /// Notes a parameter only pbrt-v3 accepts: the type names pbrt-v4
    /// renamed (it reads them only when upgrading) or a `mapname`.
    fn note_pbrt_v3_params(&mut self, params: &[ParsedParameter]) {
        let v3 = params.iter().find(|p| {
            matches!(&*p.ty, "color" | "point" | "vector")
                || (p.name == "mapname" && p.ty == "string")
        });
        if let Some(p) = v3 {
            let loc = p.loc.clone();
            self.note_pbrt_v3(&loc);
        }
    }

    fn keep_upgrade_messages(&mut self, unchanged: bool, diags: Vec<Diagnostic>) {
        self.pending
            .extend(diags.into_iter().filter(|d| !unchanged || d.is_error()));
    }

    /// A name defined again (`defined`: the name is taken). pbrt-v4 refuses
    /// it; pbrt-v3 warns and the later definition wins for what follows,
    /// while what was defined before keeps the earlier one. So the
    /// definition is stored as `<name>-renamed-<n>` (the name `--upgrade`
    /// gives it) and later references to `name` are renamed to it
    /// ([`SceneBuilder::renamed_refs`]); at the end of the files, pbrt-v4's
    /// error `refusal` stands unless something marked them as pbrt-v3
    /// (before or after this directive). Returns the name to store the
    /// definition under.
    fn redefine(
        &mut self,
        kind: Reference,
        name: &str,
        defined: bool,
        loc: &FileLoc,
        refusal: String,
    ) -> String {
        if !defined {
            return name.to_string();
        }
        let r = &mut self.renames[kind as usize];
        let stored = format!("{name}-renamed-{}", r.count);
        r.count += 1;
        let what = match kind {
            Reference::Texture => "texture",
            Reference::NamedMaterial => "named material",
        };
        let warning = Diagnostic::warning(
            loc.clone(),
            format!(
                "\"{name}\": {what} defined again; as in pbrt-v3, this definition is used from \
                 here on (stored as \"{stored}\")"
            ),
        );
        if self.scene.pbrt_v3.is_some() {
            self.pending.push(warning);
        } else {
            // A pbrt-v3 construct later in the files makes this pbrt-v3's
            // redefinition; without one it is pbrt-v4's error.
            self.undecided_redefinitions
                .push((Diagnostic::error(loc.clone(), refusal), warning));
        }
        stored
    }

    /// Records that `name`'s latest definition is stored as `stored`.
    fn note_definition(&mut self, kind: Reference, name: &str, stored: &str) {
        if name != stored {
            self.renames[kind as usize]
                .current
                .insert(name.to_string(), stored.to_string());
        }
    }

    /// The name a reference to `name` resolves to: its latest definition's.
    fn resolve(&self, kind: Reference, name: &str) -> String {
        self.renames[kind as usize]
            .current
            .get(name)
            .cloned()
            .unwrap_or_else(|| name.to_string())
    }

    /// `params` with their texture references (and a `mix` material's
    /// material names) renamed to the latest definitions of pbrt-v3's
    /// redefined names. Textures share one namespace here, as under
    /// `--upgrade`.
    fn renamed_refs(&self, mut params: ParamList) -> ParamList {
        if self.renames.iter().all(|r| r.current.is_empty()) {
            return params;
        }
        for p in params.iter_mut() {
            let Some(kind) = upgrade::reference_of(p) else {
                continue;
            };
            for s in p.strings.iter_mut() {
                *s = self.resolve(kind, s);
            }
        }
        params
    }

    fn entity(&self, name: String, params: ParamList, loc: FileLoc) -> SceneEntity {
        let params = self.renamed_refs(params);
        SceneEntity::new(
            name,
            ParameterDictionary::new(params),
            loc,
            self.state.color_space,
        )
    }

    fn entity_with(
        &self,
        kind: EntityKind,
        name: String,
        params: ParamList,
        inherited: &Arc<Vec<ParsedParameter>>,
        loc: FileLoc,
    ) -> SceneEntity {
        let params = self.renamed_refs(params);
        let dict = ParameterDictionary::with_inherited(params, inherited.as_ref().clone());
        SceneEntity::new(kind.interned(name), dict, loc, self.state.color_space)
    }

    /// Film, Sampler, PixelFilter, Integrator and Accelerator.
    fn option_entity(
        &mut self,
        directive: &str,
        kind: EntityKind,
        f: Option<UpgradeFn>,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> Result<SceneEntity, Diagnostic> {
        self.verify_options(directive, &loc)?;
        let (name, params) = match f {
            Some(f) => self.upgraded(f, name, params, &loc),
            None => {
                let mut params = params;
                self.note_pbrt_v3_params(&params);
                upgrade::upgrade_param_types(&mut params);
                (name.to_string(), params)
            }
        };
        kind.check(&name, &loc)?;
        Ok(self.entity(name, params, loc))
    }

    /// Removes the last `"string type"` parameter and returns its value and
    /// location.
    fn take_type_param(params: &mut ParamList) -> Option<(String, FileLoc)> {
        let i = params
            .iter()
            .rposition(|p| p.name == "type" && p.ty == "string")?;
        let p = params.remove(i);
        let value = p.strings.first().cloned().unwrap_or_default();
        Some((value, p.loc))
    }

    fn shape_attributes(&self, light_index: Option<usize>) -> ShapeAttributes {
        ShapeAttributes {
            reverse_orientation: self.state.reverse_orientation,
            material: self.state.material.clone(),
            light_index,
            inside_medium: self.state.inside_medium.clone(),
            outside_medium: self.state.outside_medium.clone(),
        }
    }

    // ---- the push stack ---------------------------------------------------

    /// Pops one entry for the directive `closing`, which expects an entry
    /// made by `opening`; a mismatch is an error, but the entry is popped
    /// and restored anyway (as pbrt-v4 does).
    fn pop(&mut self, closing: &str, opening: &str, loc: &FileLoc) -> DirectiveResult {
        let Some(top) = self.pushed.pop() else {
            return Err(Diagnostic::error(
                loc.clone(),
                format!("unmatched {closing} encountered; ignoring it"),
            ));
        };
        let mismatch = (top.describe() != opening).then(|| {
            Diagnostic::error(
                loc.clone(),
                format!(
                    "mismatched nesting: open {} from {} at {closing}",
                    top.describe(),
                    top.loc()
                ),
            )
        });
        self.scene.budget.release(PUSHED_BYTES as u64);
        match top {
            Pushed::Attribute(mut state, _) => {
                std::mem::swap(&mut self.state, &mut state);
                if self.spare_states.len() < MAX_SPARE_STATES {
                    self.spare_states.push(state);
                }
            }
            Pushed::Transform(ctm, active, _) => {
                self.state.ctm = *ctm;
                self.state.active = active;
            }
            Pushed::Object { state, opened, .. } => {
                self.state = *state;
                if opened {
                    if let Some(def) = self.active_definition.take() {
                        self.scene.instance_definitions.push(def);
                    }
                }
            }
        }
        match mismatch {
            Some(d) => Err(d),
            None => Ok(()),
        }
    }
}

impl ParserTarget for SceneBuilder {
    fn identity(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.state.for_active(|_| Transform::identity());
        Ok(())
    }

    fn translate(&mut self, d: [f32; 3], _loc: FileLoc) -> DirectiveResult {
        let t = Transform::translate(Vector3f::new(d[0], d[1], d[2]));
        self.state.for_active(|c| *c * t);
        Ok(())
    }

    fn scale(&mut self, s: [f32; 3], _loc: FileLoc) -> DirectiveResult {
        let t = Transform::scale(s[0], s[1], s[2]);
        self.state.for_active(|c| *c * t);
        Ok(())
    }

    fn rotate(&mut self, angle: f32, axis: [f32; 3], loc: FileLoc) -> DirectiveResult {
        let t = Transform::try_rotate(angle, Vector3f::new(axis[0], axis[1], axis[2]))
            .map_err(|e| Self::transform_error(e, loc, "Rotate"))?;
        self.state.for_active(|c| *c * t);
        Ok(())
    }

    fn look_at(
        &mut self,
        eye: [f32; 3],
        look: [f32; 3],
        up: [f32; 3],
        loc: FileLoc,
    ) -> DirectiveResult {
        let t = Transform::look_at(
            Point3f::new(eye[0], eye[1], eye[2]),
            Point3f::new(look[0], look[1], look[2]),
            Vector3f::new(up[0], up[1], up[2]),
        )
        .map_err(|e| Self::transform_error(e, loc, "LookAt"))?;
        self.state.for_active(|c| *c * t);
        self.options_look_at |= self.block == Block::Options;
        Ok(())
    }

    fn concat_transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        let t = Self::matrix_from_values(&m, &loc, "ConcatTransform")?;
        self.state.for_active(|c| *c * t);
        Ok(())
    }

    fn transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        let t = Self::matrix_from_values(&m, &loc, "Transform")?;
        self.state.for_active(|_| t);
        Ok(())
    }

    fn coordinate_system(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        if !self.named_coordinate_systems.contains_key(name) {
            // A map entry: the name, the transformations and the map's own
            // bookkeeping (about a word per entry).
            let bytes = name.len() + vec_element::<(String, TransformSet, u64)>();
            self.charge(bytes, "CoordinateSystem", &loc)?;
        }
        self.named_coordinate_systems
            .insert(name.to_string(), self.state.ctm);
        Ok(())
    }

    fn coord_sys_transform(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        match self.named_coordinate_systems.get(name) {
            Some(ctm) => {
                self.state.ctm = *ctm;
                Ok(())
            }
            None => Err(Diagnostic::warning(
                loc,
                format!("couldn't find named coordinate system \"{name}\""),
            )),
        }
    }

    fn active_transform_all(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.state.active = ALL_BITS;
        Ok(())
    }

    fn active_transform_end_time(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.state.active = END_BIT;
        Ok(())
    }

    fn active_transform_start_time(&mut self, _loc: FileLoc) -> DirectiveResult {
        self.state.active = START_BIT;
        Ok(())
    }

    fn transform_times(&mut self, start: f32, end: f32, loc: FileLoc) -> DirectiveResult {
        self.verify_options("TransformTimes", &loc)?;
        if !(start.is_finite() && end.is_finite() && start <= end) {
            return Err(Diagnostic::error(
                loc,
                format!("TransformTimes: start time {start} must not exceed end time {end}"),
            ));
        }
        self.state.start_time = start;
        self.state.end_time = end;
        Ok(())
    }

    fn reverse_orientation(&mut self, loc: FileLoc) -> DirectiveResult {
        self.verify_world("ReverseOrientation", &loc)?;
        self.state.reverse_orientation = !self.state.reverse_orientation;
        Ok(())
    }

    fn color_space(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        let lower = name.to_ascii_lowercase();
        match RgbColorSpace::NAMES.iter().find(|&&c| c == lower) {
            Some(c) => {
                self.state.color_space = c;
                Ok(())
            }
            None => Err(unknown_type(
                "color space",
                name,
                RgbColorSpace::NAMES,
                &loc,
            )),
        }
    }

    fn pixel_filter(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let f = upgrade::upgrade_pixel_filter;
        self.scene.filter = self.option_entity(
            "PixelFilter",
            EntityKind::Filter,
            Some(f),
            name,
            params,
            loc,
        )?;
        Ok(())
    }

    fn film(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let f = upgrade::upgrade_film;
        self.scene.film =
            self.option_entity("Film", EntityKind::Film, Some(f), name, params, loc)?;
        Ok(())
    }

    fn sampler(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let f = upgrade::upgrade_sampler;
        self.scene.sampler =
            self.option_entity("Sampler", EntityKind::Sampler, Some(f), name, params, loc)?;
        Ok(())
    }

    fn accelerator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.scene.accelerator = self.option_entity(
            "Accelerator",
            EntityKind::Accelerator,
            Some(upgrade::upgrade_accelerator),
            name,
            params,
            loc,
        )?;
        Ok(())
    }

    fn integrator(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let f = upgrade::upgrade_integrator_for_render;
        self.scene.integrator = self.option_entity(
            "Integrator",
            EntityKind::Integrator,
            Some(f),
            name,
            params,
            loc,
        )?;
        Ok(())
    }

    fn search_path(&mut self, _path: &str, loc: FileLoc) -> DirectiveResult {
        // Only pbrt-v1's plugin lookup read it; everything is built in.
        self.verify_options("SearchPath", &loc)?;
        self.note_pbrt_v1(&loc);
        Ok(())
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
        self.verify_world("Volume", &loc)?;
        self.note_pbrt_v2(&loc);
        self.note_pbrt_v3_params(&params);
        let mut params = params;
        upgrade::upgrade_param_types(&mut params);
        let bytes = vec_element::<VolumeRegionEntity>()
            + heap(name.len())
            + params
                .iter()
                .map(ParsedParameter::memory_bytes)
                .sum::<usize>();
        self.charge(bytes, "Volume", &loc)?;
        let base = self.entity(name.to_string(), params, loc);
        self.scene.volume_regions.push(VolumeRegionEntity {
            base,
            render_from_region: self.render_from_object_at(0),
        });
        Ok(())
    }

    fn camera(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        let f = upgrade::upgrade_camera;
        let base = self.option_entity("Camera", EntityKind::Camera, Some(f), name, params, loc)?;
        let camera_from_world = self.state.ctm;
        let world_from_camera = [
            camera_from_world[0].inverse(),
            camera_from_world[1].inverse(),
        ];
        self.named_coordinate_systems
            .insert("camera".to_string(), world_from_camera);
        let animated = AnimatedTransform::new(
            world_from_camera[0],
            self.state.start_time,
            world_from_camera[1],
            self.state.end_time,
        );
        let camera_transform = CameraTransform::new(&animated, self.scene.render_coord_sys);
        self.render_from_world = camera_transform.render_from_world();
        self.scene.camera = CameraSceneEntity {
            base,
            camera_transform,
            medium: self.state.outside_medium.clone(),
        };
        self.camera_defined = true;
        self.camera_placement = Some((
            world_from_camera,
            [self.state.start_time, self.state.end_time],
            self.options_look_at,
        ));
        Ok(())
    }

    fn make_named_medium(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        let mut params = params;
        let Some((ty, ty_loc)) = Self::take_type_param(&mut params) else {
            return Err(Diagnostic::error(
                loc,
                format!("no parameter \"string type\" found for medium \"{name}\""),
            ));
        };
        let (ty, mut params) = self.upgraded(upgrade::upgrade_medium, &ty, params, &loc);
        EntityKind::Medium.check(&ty, &ty_loc)?;
        if !self.medium_names.insert(name.to_string()) {
            return Err(Diagnostic::error(
                loc,
                format!("named medium \"{name}\" redefined"),
            ));
        }
        params.insert(
            0,
            ParsedParameter::with_strings("string", "type", ty_loc, vec![ty.clone()]),
        );
        let attrs = self.state.medium_attributes.clone();
        let base = self.entity_with(EntityKind::Medium, ty, params, &attrs, loc);
        self.charge_entity::<MediumSceneEntity>(&base, "MakeNamedMedium")?;
        let render_from_object = self.render_from_object();
        self.scene.media.push(MediumSceneEntity {
            name: name.to_string(),
            base,
            render_from_object,
        });
        Ok(())
    }

    fn medium_interface(&mut self, inside: &str, outside: &str, loc: FileLoc) -> DirectiveResult {
        for n in [inside, outside] {
            if !n.is_empty() {
                let bytes = vec_element::<(String, FileLoc)>() + heap(n.len());
                self.charge(bytes, "MediumInterface", &loc)?;
                self.medium_uses.push((n.to_string(), loc.clone()));
            }
        }
        self.state.inside_medium = inside.to_string();
        self.state.outside_medium = outside.to_string();
        Ok(())
    }

    fn option(&mut self, name: &str, value: &str, loc: FileLoc) -> DirectiveResult {
        let value = super::options::parse_option(name, value, &loc)?;
        if value.name == "rendercoordsys" {
            if self.camera_defined {
                return Err(Diagnostic::error(
                    loc,
                    "the \"rendercoordsys\" option must come before Camera",
                ));
            }
            if let OptionValue::String(s) = &value.value {
                if let Some(sys) = RenderingCoordinateSystem::from_name(s) {
                    self.scene.render_coord_sys = sys;
                }
            }
        }
        let text = match &value.value {
            OptionValue::String(s) => s.len(),
            _ => 0,
        };
        let bytes = vec_element::<SceneOption>() + heap(value.name.len()) + heap(text);
        self.charge(bytes, "Option", &loc)?;
        self.scene.options.push(value);
        Ok(())
    }

    fn world_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.verify_options("WorldBegin", &loc)?;
        self.block = Block::World;
        self.state.ctm = [Transform::identity(); 2];
        self.state.active = ALL_BITS;
        self.named_coordinate_systems
            .insert("world".to_string(), self.state.ctm);
        Ok(())
    }

    fn world_end(&mut self, loc: FileLoc) -> DirectiveResult {
        // pbrt-v4 accepts `WorldEnd` only when upgrading.
        self.note_pbrt_v3(&loc);
        Ok(())
    }

    fn attribute_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.verify_world("AttributeBegin", &loc)?;
        self.charge(PUSHED_BYTES, "AttributeBegin", &loc)?;
        let saved = match self.spare_states.pop() {
            Some(mut b) => {
                (*b).clone_from(&self.state);
                b
            }
            None => Box::new(self.state.clone()),
        };
        self.pushed.push(Pushed::Attribute(saved, loc));
        Ok(())
    }

    fn attribute_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.verify_world("AttributeEnd", &loc)?;
        self.pop("AttributeEnd", "AttributeBegin", &loc)
    }

    fn import_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        // pbrt-v4: an imported file starts from a copy of the graphics
        // state, and only inside the world block.
        if self.block == Block::Options {
            return Err(Diagnostic::error(
                loc,
                "Import statement only allowed inside world definition block",
            ));
        }
        self.attribute_begin(loc)
    }

    fn transform_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.charge(PUSHED_BYTES, "TransformBegin", &loc)?;
        self.pushed.push(Pushed::Transform(
            Box::new(self.state.ctm),
            self.state.active,
            loc,
        ));
        Ok(())
    }

    fn transform_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.pop("TransformEnd", "TransformBegin", &loc)
    }

    fn attribute(&mut self, target: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.note_pbrt_v3_params(&params);
        let attrs = match target {
            "shape" => &mut self.state.shape_attributes,
            "light" => &mut self.state.light_attributes,
            "material" => &mut self.state.material_attributes,
            "medium" => &mut self.state.medium_attributes,
            "texture" => &mut self.state.texture_attributes,
            _ => {
                return Err(Diagnostic::error(
                    loc,
                    format!(
                        "unknown attribute target \"{target}\"; must be \"shape\", \"light\", \"material\", \"medium\" or \"texture\""
                    ),
                ))
            }
        };
        let mut params = params;
        upgrade::upgrade_param_types(&mut params);
        let bytes: usize = params.iter().map(ParsedParameter::memory_bytes).sum();
        self.scene
            .budget
            .charge(bytes as u64, "this Attribute")
            .map_err(|e| Diagnostic::error(loc.clone(), e.to_string()))?;
        Arc::make_mut(attrs).extend(params);
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
        self.verify_world("Texture", &loc)?;
        self.note_pbrt_v3_params(&params);
        let before = fingerprint(&params);
        let (new_ty, u) = upgrade::upgrade_texture_for_render(ty, texname, params, &loc);
        let unchanged = new_ty == ty && u.name == texname && before == fingerprint(&u.params);
        self.keep_upgrade_messages(unchanged, u.diagnostics);
        let kind = match new_ty.as_str() {
            "float" => TextureKind::Float,
            "spectrum" => TextureKind::Spectrum,
            _ => {
                return Err(Diagnostic::error(
                    loc,
                    format!("\"{ty}\": texture type unknown; must be \"float\" or \"spectrum\""),
                ))
            }
        };
        EntityKind::Texture.check(&u.name, &loc)?;
        let defined = match kind {
            TextureKind::Float => self.float_texture_names.contains(name),
            TextureKind::Spectrum => self.spectrum_texture_names.contains(name),
        };
        let stored = self.redefine(
            Reference::Texture,
            name,
            defined,
            &loc,
            format!("redefining texture \"{name}\""),
        );
        let attrs = self.state.texture_attributes.clone();
        // Its own references still mean the earlier definitions.
        let base = self.entity_with(EntityKind::Texture, u.name, u.params, &attrs, loc);
        self.charge_entity::<TextureSceneEntity>(&base, "Texture")?;
        match kind {
            TextureKind::Float => self.float_texture_names.insert(stored.clone()),
            TextureKind::Spectrum => self.spectrum_texture_names.insert(stored.clone()),
        };
        self.note_definition(Reference::Texture, name, &stored);
        let entity = TextureSceneEntity {
            name: stored,
            kind,
            base,
            render_from_object: self.render_from_object(),
        };
        match kind {
            TextureKind::Float => self.scene.float_textures.push(entity),
            TextureKind::Spectrum => self.scene.spectrum_textures.push(entity),
        }
        Ok(())
    }

    fn material(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.verify_world("Material", &loc)?;
        let mut params = params;
        self.v1_v2_material(name, &mut params, &loc);
        let (name, params) =
            self.upgraded(upgrade::upgrade_material_for_render, name, params, &loc);
        EntityKind::Material.check(&name, &loc)?;
        let attrs = self.state.material_attributes.clone();
        let entity = self.entity_with(EntityKind::Material, name, params, &attrs, loc);
        self.charge_entity::<SceneEntity>(&entity, "Material")?;
        self.scene.materials.push(entity);
        self.state.material = MaterialRef::Index(self.scene.materials.len() - 1);
        Ok(())
    }

    fn make_named_material(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.verify_world("MakeNamedMaterial", &loc)?;
        let mut params = params;
        let Some((ty, ty_loc)) = Self::take_type_param(&mut params) else {
            return Err(Diagnostic::error(
                loc,
                format!("no parameter \"string type\" found for named material \"{name}\""),
            ));
        };
        self.v1_v2_material(&ty, &mut params, &ty_loc);
        let (ty, mut params) =
            self.upgraded(upgrade::upgrade_material_for_render, &ty, params, &loc);
        EntityKind::Material.check(&ty, &ty_loc)?;
        let stored = self.redefine(
            Reference::NamedMaterial,
            name,
            self.named_material_names.contains(name),
            &loc,
            format!("\"{name}\": named material redefined"),
        );
        params.insert(
            0,
            ParsedParameter::with_strings("string", "type", ty_loc, vec![ty.clone()]),
        );
        let attrs = self.state.material_attributes.clone();
        let entity = self.entity_with(EntityKind::Material, ty, params, &attrs, loc);
        self.charge_entity::<(String, SceneEntity)>(&entity, "MakeNamedMaterial")?;
        self.named_material_names.insert(stored.clone());
        self.note_definition(Reference::NamedMaterial, name, &stored);
        self.scene.named_materials.push((stored, entity));
        Ok(())
    }

    fn named_material(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.verify_world("NamedMaterial", &loc)?;
        let bytes = vec_element::<(String, FileLoc)>() + heap(name.len());
        self.charge(bytes, "NamedMaterial", &loc)?;
        let name = self.resolve(Reference::NamedMaterial, name);
        self.named_material_uses.push((name.clone(), loc));
        self.state.material = MaterialRef::Named(name);
        Ok(())
    }

    fn light_source(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.verify_world("LightSource", &loc)?;
        if name == "infinitesample" {
            self.note_pbrt_v1(&loc);
        }
        // Only pbrt-v3 names an infinite light's image "mapname".
        let pbrt_v3 = params
            .iter()
            .any(|p| p.name == "mapname" && p.ty == "string");
        let mut params = params;
        v3_emission::spectral_emission_as_rgb(name, &mut params, &loc)?;
        let (name, mut params) =
            self.upgraded(upgrade::upgrade_light_for_render, name, params, &loc);
        EntityKind::Light.check(&name, &loc)?;
        if name == "point" && self.scene.pbrt_v2.is_some() {
            self.v2_point_from(&mut params);
        }
        let attrs = self.state.light_attributes.clone();
        let base = self.entity_with(EntityKind::Light, name, params, &attrs, loc);
        self.charge_entity::<LightSceneEntity>(&base, "LightSource")?;
        let light = LightSceneEntity {
            base,
            render_from_object: self.render_from_object(),
            medium: self.state.outside_medium.clone(),
            pbrt_v3,
        };
        self.scene.lights.push(light);
        Ok(())
    }

    fn area_light_source(
        &mut self,
        name: &str,
        params: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.verify_world("AreaLightSource", &loc)?;
        let mut params = params;
        v3_emission::spectral_emission_as_rgb(name, &mut params, &loc)?;
        let (name, params) = self.upgraded(upgrade::upgrade_area_light, name, params, &loc);
        EntityKind::AreaLight.check(&name, &loc)?;
        let attrs = self.state.light_attributes.clone();
        let entity = self.entity_with(EntityKind::AreaLight, name, params, &attrs, loc);
        self.state.area_light = Some(Arc::new(entity));
        Ok(())
    }

    fn shape(&mut self, name: &str, params: ParamList, loc: FileLoc) -> DirectiveResult {
        self.verify_world("Shape", &loc)?;
        // pbrt-v3 meshes may spell out the implicit indices of a single
        // triangle or quad; the mapping drops them, but a pbrt-v4 file must
        // pass through unchanged, so they are kept.
        let indices = params
            .iter()
            .find(|p| p.name == "indices" && p.ty == "integer")
            .cloned();
        let (name, mut params) = self.upgraded(upgrade::upgrade_shape, name, params, &loc);
        if let Some(ix) = indices {
            if !params.iter().any(|p| p.name == "indices") {
                params.push(ix);
            }
        }
        EntityKind::Shape.check(&name, &loc)?;
        // The description's entity (with a copy of the area light's) is
        // charged here; the shapes made of it when the scene is created.
        let own = vec_element::<ShapeSceneEntity>()
            + params
                .iter()
                .map(ParsedParameter::memory_bytes)
                .sum::<usize>()
            + self
                .state
                .shape_attributes
                .iter()
                .map(ParsedParameter::memory_bytes)
                .sum::<usize>()
            + heap(name.capacity());
        let light = self
            .state
            .area_light
            .as_ref()
            .map_or(0, |al| vec_element::<SceneEntity>() + al.heap_bytes());
        self.charge(own + light, "Shape", &loc)?;
        let light_index = match &self.state.area_light {
            Some(al) => {
                if self.active_definition.is_some() {
                    self.pending.push(Diagnostic::warning(
                        loc.clone(),
                        "area lights not supported with object instancing",
                    ));
                }
                self.scene.area_lights.push(al.as_ref().clone());
                Some(self.scene.area_lights.len() - 1)
            }
            None => None,
        };
        let attrs = self.state.shape_attributes.clone();
        let base = self.entity_with(EntityKind::Shape, name, params, &attrs, loc);
        let attributes = self.shape_attributes(light_index);
        if self.ctm_is_animated() {
            let shape = AnimatedShapeSceneEntity {
                base,
                render_from_object: self.render_from_object(),
                attributes,
            };
            match &mut self.active_definition {
                Some(def) => def.animated_shapes.push(shape),
                None => self.scene.animated_shapes.push(shape),
            }
        } else {
            let render_from_object = self.render_from_object_at(0);
            let shape = ShapeSceneEntity {
                base,
                render_from_object,
                object_from_render: render_from_object.inverse(),
                attributes,
            };
            match &mut self.active_definition {
                Some(def) => def.shapes.push(shape),
                None => self.scene.shapes.push(shape),
            }
        }
        Ok(())
    }

    fn object_begin(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.verify_world("ObjectBegin", &loc)?;
        self.charge(PUSHED_BYTES + name.len(), "ObjectBegin", &loc)?;
        let state = Box::new(self.state.clone());
        let error = if self.active_definition.is_some() {
            Some(Diagnostic::error(
                loc.clone(),
                "ObjectBegin called inside of instance definition",
            ))
        } else if !self.instance_names.insert(Arc::from(name)) {
            Some(Diagnostic::error(
                loc.clone(),
                format!("\"{name}\": trying to redefine an object instance"),
            ))
        } else {
            None
        };
        let opened = error.is_none();
        if opened {
            self.active_definition = Some(InstanceDefinitionSceneEntity {
                name: name.to_string(),
                loc: loc.clone(),
                shapes: EntityList::new(),
                animated_shapes: EntityList::new(),
            });
        }
        self.pushed.push(Pushed::Object { state, loc, opened });
        match error {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn object_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.verify_world("ObjectEnd", &loc)?;
        let inside = self
            .pushed
            .iter()
            .any(|p| matches!(p, Pushed::Object { .. }));
        if !inside {
            return Err(Diagnostic::error(
                loc,
                "ObjectEnd called outside of instance definition",
            ));
        }
        self.pop("ObjectEnd", "ObjectBegin", &loc)
    }

    fn object_instance(&mut self, name: &str, loc: FileLoc) -> DirectiveResult {
        self.verify_world("ObjectInstance", &loc)?;
        if self.active_definition.is_some() {
            return Err(Diagnostic::error(
                loc,
                "ObjectInstance can't be called inside instance definition",
            ));
        }
        let world_from_render = self.render_from_world.inverse();
        let render_from_instance = if self.ctm_is_animated() {
            InstanceTransform::Animated(Box::new(AnimatedTransform::new(
                self.render_from_object_at(0) * world_from_render,
                self.state.start_time,
                self.render_from_object_at(1) * world_from_render,
                self.state.end_time,
            )))
        } else {
            InstanceTransform::Fixed(self.render_from_object_at(0) * world_from_render)
        };
        let bytes = self.scene.instances.push(name, &loc, render_from_instance);
        self.charge(bytes, "ObjectInstance", &loc)
    }

    fn end_of_files(&mut self) -> DirectiveResult {
        if self.scene.pbrt_v1.is_some() {
            self.use_pbrt_v1_defaults();
        }
        if let Some(v2) = self.scene.pbrt_v2.clone() {
            self.use_pbrt_v2_defaults(&v2);
        } else if self.scene.pbrt_v3.is_some() {
            self.use_pbrt_v3_defaults();
        }
        let v3 = self.scene.pbrt_v3.is_some();
        for (error, warning) in std::mem::take(&mut self.undecided_redefinitions) {
            self.pending.push(if v3 { warning } else { error });
        }
        if self.block != Block::World {
            self.pending.push(Diagnostic::unlocated_error(
                "end of files before \"WorldBegin\"",
            ));
        }
        if let Some(first) = self.pushed.first() {
            let n = self.pushed.len();
            let msg = if n == 1 {
                format!("missing end to {}", first.describe())
            } else {
                format!(
                    "missing end to {}; {n} blocks are still open, the outermost here",
                    first.describe()
                )
            };
            self.pending
                .push(Diagnostic::error(first.loc().clone(), msg));
            // Unwind so that an open object definition is kept.
            while let Some(p) = self.pushed.pop() {
                if let Pushed::Object { opened: true, .. } = p {
                    if let Some(def) = self.active_definition.take() {
                        self.scene.instance_definitions.push(def);
                    }
                }
            }
        }
        for (name, loc) in self.scene.instances.names() {
            if !self.instance_names.contains(name) {
                self.pending.push(Diagnostic::error(
                    loc.clone(),
                    format!("\"{name}\": object instance not defined"),
                ));
            }
        }
        for (name, loc) in &self.named_material_uses {
            if !self.named_material_names.contains(name) {
                self.pending.push(Diagnostic::error(
                    loc.clone(),
                    format!("\"{name}\": named material not defined"),
                ));
            }
        }
        let mut reported = HashSet::new();
        for (name, loc) in &self.medium_uses {
            if !self.medium_names.contains(name) && reported.insert((name, loc)) {
                self.pending.push(Diagnostic::error(
                    loc.clone(),
                    format!("\"{name}\": medium not defined"),
                ));
            }
        }
        Ok(())
    }

    fn take_diagnostics(&mut self) -> Vec<Diagnostic> {
        std::mem::take(&mut self.pending)
    }
}

#[cfg(test)]
mod tests;
mod v3_emission;
