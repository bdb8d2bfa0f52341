//! The plain scene description the builder produces: one entity per
//! directive, with its type name, parameters, location and transformation
//! (pbrt-v4 `scene.h`: `SceneEntity`, `TransformedSceneEntity`,
//! `CameraSceneEntity`, `ShapeSceneEntity`, `AnimatedShapeSceneEntity`,
//! `LightSceneEntity`, `InstanceDefinitionSceneEntity`,
//! `InstanceSceneEntity`, whose list rpbrt keeps compactly: see
//! [`InstanceList`](super::instances::InstanceList)).
//!
//! Nothing here is a render object yet: parameters are kept as written (after
//! the pbrt-v3 upgrade) and are read when the renderer creates the objects.

use std::borrow::Cow;
use std::fmt::Write as _;
use std::sync::Arc;

use rpbrt_geometry::{AnimatedTransform, Float, Transform};
use rpbrt_parser::{Diagnostic, FileLoc, MemoryBudget, ParameterDictionary, ParsedParameter};

use super::entity_list::EntityList;
use super::instances::InstanceList;
use crate::camera::{CameraTransform, RenderingCoordinateSystem};

/// The location given to entities that stand for a default (no directive).
pub fn default_loc() -> FileLoc {
    FileLoc::new(Arc::from("<default>"), 0, 0)
}

/// A directive's type name, parameters and location.
#[derive(Clone, Debug)]
pub struct SceneEntity {
    /// The entity's type, e.g. `"sphere"` or `"diffuse"` (one of the
    /// known names, held without a copy, where the builder checked it).
    pub name: Cow<'static, str>,
    /// Its parameters (with the `Attribute` defaults in effect, if any).
    pub params: ParameterDictionary,
    /// Where the directive was.
    pub loc: FileLoc,
    /// The RGB color space in effect (`ColorSpace`), by name (one of the
    /// named spaces, held without a copy: one per shape adds up).
    pub color_space: &'static str,
}

impl SceneEntity {
    /// An entity with the given parts.
    pub fn new(
        name: impl Into<Cow<'static, str>>,
        params: ParameterDictionary,
        loc: FileLoc,
        color_space: &'static str,
    ) -> Self {
        SceneEntity {
            name: name.into(),
            params,
            loc,
            color_space,
        }
    }

    /// The memory the entity holds beyond its own size (name, colour
    /// space, parameters), in bytes, for the memory budget.
    pub fn heap_bytes(&self) -> usize {
        use rpbrt_parser::budget::heap;
        let name = match &self.name {
            Cow::Owned(s) => heap(s.capacity()),
            Cow::Borrowed(_) => 0,
        };
        name + self.params.memory_bytes()
    }

    /// A default entity of type `name` without parameters, in sRGB.
    pub fn default_named(name: &str) -> Self {
        SceneEntity::new(
            name.to_string(),
            ParameterDictionary::default(),
            default_loc(),
            "srgb",
        )
    }
}

/// An entity placed in the scene by a (possibly animated) transformation.
#[derive(Clone, Debug)]
pub struct TransformedSceneEntity {
    /// Type, parameters and location.
    pub base: SceneEntity,
    /// From the entity's own space to render space.
    pub render_from_object: AnimatedTransform,
}

/// The `Camera` directive.
#[derive(Clone, Debug)]
pub struct CameraSceneEntity {
    /// Type (`perspective`...), parameters and location.
    pub base: SceneEntity,
    /// Where the camera and render space are.
    pub camera_transform: CameraTransform,
    /// The medium the camera is in (the outside medium when `Camera` was
    /// given; empty for none).
    pub medium: String,
}

/// Which material a shape uses.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum MaterialRef {
    /// An index into [`SceneDescription::materials`] (set by `Material`).
    Index(usize),
    /// A named material (set by `NamedMaterial`).
    Named(String),
}

/// What a shape carries besides its transformation.
#[derive(Clone, Debug)]
pub struct ShapeAttributes {
    /// `ReverseOrientation` was in effect (an odd number of times).
    pub reverse_orientation: bool,
    /// The current material.
    pub material: MaterialRef,
    /// Index into [`SceneDescription::area_lights`] when an
    /// `AreaLightSource` was active.
    pub light_index: Option<usize>,
    /// The medium inside the shape (empty for none).
    pub inside_medium: String,
    /// The medium outside the shape (empty for none).
    pub outside_medium: String,
}

/// A `Shape` under a fixed transformation.
#[derive(Clone, Debug)]
pub struct ShapeSceneEntity {
    /// Type (`sphere`...), parameters and location.
    pub base: SceneEntity,
    /// From object space to render space.
    pub render_from_object: Transform,
    /// The inverse of `render_from_object`.
    pub object_from_render: Transform,
    /// Orientation, material, area light and media.
    pub attributes: ShapeAttributes,
}

/// A `Shape` whose transformation changes over time.
#[derive(Clone, Debug)]
pub struct AnimatedShapeSceneEntity {
    /// Type, parameters and location.
    pub base: SceneEntity,
    /// From object space to render space, over time.
    pub render_from_object: AnimatedTransform,
    /// Orientation, material, area light and media.
    pub attributes: ShapeAttributes,
}

/// A `LightSource`.
#[derive(Clone, Debug)]
pub struct LightSceneEntity {
    /// Type (`point`...), parameters and location.
    pub base: SceneEntity,
    /// From light space to render space.
    pub render_from_object: AnimatedTransform,
    /// The medium the light is in (the current outside medium).
    pub medium: String,
    /// Written in pbrt-v3's form: an `infinite` light's `mapname` (now
    /// `filename`) names a latitude–longitude map.
    pub pbrt_v3: bool,
}

/// Whether a texture gives numbers or spectra.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureKind {
    /// `Texture "name" "float" ...`
    Float,
    /// `Texture "name" "spectrum" ...` (pbrt-v3 `"color"`).
    Spectrum,
}

/// A `Texture`.
#[derive(Clone, Debug)]
pub struct TextureSceneEntity {
    /// The texture's name, by which materials refer to it.
    pub name: String,
    /// Float or spectrum.
    pub kind: TextureKind,
    /// Class (`imagemap`...), parameters and location.
    pub base: SceneEntity,
    /// From texture space to render space.
    pub render_from_object: AnimatedTransform,
}

/// A `MakeNamedMedium`.
#[derive(Clone, Debug)]
pub struct MediumSceneEntity {
    /// The medium's name, by which `MediumInterface` refers to it.
    pub name: String,
    /// Type (from `"string type"`), parameters and location.
    pub base: SceneEntity,
    /// From medium space to render space.
    pub render_from_object: AnimatedTransform,
}

/// A pbrt-v1/v2 `Volume` directive: a density region seen by every ray.
#[derive(Clone, Debug)]
pub struct VolumeRegionEntity {
    /// Type, parameters and location.
    pub base: SceneEntity,
    /// From region space to render space.
    pub render_from_region: Transform,
}

/// An `ObjectBegin`/`ObjectEnd` block: shapes to be instanced.
#[derive(Clone, Debug)]
pub struct InstanceDefinitionSceneEntity {
    /// The object's name.
    pub name: String,
    /// Where `ObjectBegin` was.
    pub loc: FileLoc,
    /// Its shapes with fixed transformations.
    pub shapes: EntityList<ShapeSceneEntity>,
    /// Its shapes with animated transformations.
    pub animated_shapes: EntityList<AnimatedShapeSceneEntity>,
}

/// How an instance is placed.
#[derive(Clone, Debug, PartialEq)]
pub enum InstanceTransform {
    /// A fixed transformation.
    Fixed(Transform),
    /// A transformation that changes over time (boxed: it is large).
    Animated(Box<AnimatedTransform>),
}

/// The value of an `Option` setting.
#[derive(Clone, Debug, PartialEq)]
pub enum OptionValue {
    /// A boolean option.
    Bool(bool),
    /// An integer option.
    Int(i32),
    /// A floating-point option.
    Float(Float),
    /// A string option (without quotes).
    String(String),
}

/// One `Option` directive.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneOption {
    /// Normalized name (lower case, no `-` or `_`).
    pub name: String,
    /// Typed value.
    pub value: OptionValue,
    /// Where the directive was.
    pub loc: FileLoc,
}

/// Everything a scene file describes, as plain entities.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// `Film` (default `rgb`).
    pub film: SceneEntity,
    /// `Sampler` (default `zsobol`).
    pub sampler: SceneEntity,
    /// `PixelFilter` (default `gaussian`).
    pub filter: SceneEntity,
    /// `Integrator` (default `volpath`).
    pub integrator: SceneEntity,
    /// `Accelerator` (default `bvh`).
    pub accelerator: SceneEntity,
    /// `Camera` (default `perspective` at the origin).
    pub camera: CameraSceneEntity,
    /// The rendering coordinate system used.
    pub render_coord_sys: RenderingCoordinateSystem,
    /// Shapes outside object definitions, fixed transformations.
    pub shapes: EntityList<ShapeSceneEntity>,
    /// Shapes outside object definitions, animated transformations.
    pub animated_shapes: EntityList<AnimatedShapeSceneEntity>,
    /// `LightSource`s.
    pub lights: Vec<LightSceneEntity>,
    /// One area light per shape created under an `AreaLightSource`.
    pub area_lights: Vec<SceneEntity>,
    /// Anonymous materials in order; index 0 is pbrt-v4's default `diffuse`.
    pub materials: Vec<SceneEntity>,
    /// Named materials in definition order; the entity's name is the type.
    pub named_materials: Vec<(String, SceneEntity)>,
    /// Float textures in definition order.
    pub float_textures: Vec<TextureSceneEntity>,
    /// Spectrum textures in definition order.
    pub spectrum_textures: Vec<TextureSceneEntity>,
    /// Named media in definition order.
    pub media: Vec<MediumSceneEntity>,
    /// pbrt-v1/v2 `Volume` regions in definition order: together one
    /// medium, the camera's and the lights' unless they name another.
    pub volume_regions: Vec<VolumeRegionEntity>,
    /// Whether the regions scatter light (false under pbrt-v2's default
    /// `emission` volume integrator: absorption and emission only).
    pub regions_scatter: bool,
    /// Object definitions in order.
    pub instance_definitions: Vec<InstanceDefinitionSceneEntity>,
    /// Object instances in order.
    pub instances: InstanceList,
    /// `Option` settings in order (a later one overrides an earlier one).
    pub options: Vec<SceneOption>,
    /// Warnings (and, for a failed build, errors) produced.
    pub diagnostics: Vec<Diagnostic>,
    /// Where the scene first used a construct only pbrt-v3 accepts (a
    /// `WorldEnd`, a `color`, `point` or `vector` parameter type, a
    /// `mapname` parameter; pbrt-v4 rejects them unless upgrading), or
    /// `None`. Where the same text means different things to pbrt-v3 and
    /// pbrt-v4 (a `goniometric` or `projection` light without an image),
    /// such a scene gets pbrt-v3's meaning.
    pub pbrt_v3: Option<FileLoc>,
    /// Where the scene first used a construct only pbrt-v1 or pbrt-v2
    /// accepts (`Renderer`, `SurfaceIntegrator`, `VolumeIntegrator`,
    /// `Volume`), or `None`. Such a scene is also marked [`pbrt_v3`]
    /// (pbrt-v3 reads everything else the way its predecessors did) and
    /// takes pbrt-v2's defaults.
    ///
    /// [`pbrt_v3`]: SceneDescription::pbrt_v3
    pub pbrt_v2: Option<FileLoc>,
    /// Where the scene first used a construct only pbrt-v1 accepts
    /// (`SearchPath`, its measured Lafortune materials, the
    /// `infinitesample` light), or `None`; such a scene is also marked
    /// [`pbrt_v2`](SceneDescription::pbrt_v2) and takes pbrt-v1's
    /// defaults and camera.
    pub pbrt_v1: Option<FileLoc>,
    /// The memory budget the description is charged to; creating the
    /// render objects charges the same one.
    pub budget: MemoryBudget,
}

impl Default for SceneDescription {
    fn default() -> Self {
        SceneDescription {
            film: SceneEntity::default_named("rgb"),
            sampler: SceneEntity::default_named("zsobol"),
            filter: SceneEntity::default_named("gaussian"),
            integrator: SceneEntity::default_named("volpath"),
            accelerator: SceneEntity::default_named("bvh"),
            camera: CameraSceneEntity {
                base: SceneEntity::default_named("perspective"),
                camera_transform: CameraTransform::default(),
                medium: String::new(),
            },
            render_coord_sys: RenderingCoordinateSystem::default(),
            shapes: EntityList::new(),
            animated_shapes: EntityList::new(),
            lights: Vec::new(),
            area_lights: Vec::new(),
            materials: vec![SceneEntity::default_named("diffuse")],
            named_materials: Vec::new(),
            float_textures: Vec::new(),
            spectrum_textures: Vec::new(),
            media: Vec::new(),
            volume_regions: Vec::new(),
            regions_scatter: true,
            instance_definitions: Vec::new(),
            instances: InstanceList::new(),
            options: Vec::new(),
            diagnostics: Vec::new(),
            pbrt_v3: None,
            pbrt_v2: None,
            pbrt_v1: None,
            budget: MemoryBudget::default(),
        }
    }
}

impl SceneDescription {
    /// The named material `name`, if defined.
    pub fn named_material(&self, name: &str) -> Option<&SceneEntity> {
        self.named_materials
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, e)| e)
    }

    /// The float texture `name`, if defined.
    pub fn float_texture(&self, name: &str) -> Option<&TextureSceneEntity> {
        self.float_textures.iter().find(|t| t.name == name)
    }

    /// The spectrum texture `name`, if defined.
    pub fn spectrum_texture(&self, name: &str) -> Option<&TextureSceneEntity> {
        self.spectrum_textures.iter().find(|t| t.name == name)
    }

    /// The medium `name`, if defined.
    pub fn medium(&self, name: &str) -> Option<&MediumSceneEntity> {
        self.media.iter().find(|m| m.name == name)
    }

    /// The object definition `name`, if defined.
    pub fn instance_definition(&self, name: &str) -> Option<&InstanceDefinitionSceneEntity> {
        self.instance_definitions.iter().find(|d| d.name == name)
    }

    /// The last value given to option `name` (normalized), if any.
    pub fn option(&self, name: &str) -> Option<&OptionValue> {
        self.options
            .iter()
            .rev()
            .find(|o| o.name == name)
            .map(|o| &o.value)
    }

    /// A textual dump of the description without locations, with parameters
    /// sorted by name and numbers rounded, so that two descriptions of the
    /// same scene compare equal whatever their source text looked like.
    pub fn normalized_dump(&self) -> String {
        let mut d = Dump(String::new());
        d.entity("film", &self.film);
        d.entity("sampler", &self.sampler);
        d.entity("filter", &self.filter);
        d.entity("integrator", &self.integrator);
        d.entity("accelerator", &self.accelerator);
        d.entity("camera", &self.camera.base);
        d.animated(
            "camera.render_from_camera",
            &self.camera.camera_transform.render_from_camera,
        );
        d.transform(
            "camera.world_from_render",
            &self.camera.camera_transform.world_from_render,
        );
        d.line(&format!("camera.medium {:?}", self.camera.medium));
        d.line(&format!("rendercoordsys {}", self.render_coord_sys.name()));
        for s in &self.shapes {
            d.shape(s);
        }
        for s in &self.animated_shapes {
            d.animated_shape(s);
        }
        for l in &self.lights {
            d.entity("light", &l.base);
            d.animated("light.render_from_object", &l.render_from_object);
            d.line(&format!("light.medium {:?}", l.medium));
        }
        for a in &self.area_lights {
            d.entity("arealight", a);
        }
        for m in &self.materials {
            d.entity("material", m);
        }
        for (n, m) in &self.named_materials {
            d.entity(&format!("namedmaterial {n:?}"), m);
        }
        for t in self.float_textures.iter().chain(&self.spectrum_textures) {
            d.entity(&format!("texture {:?} {:?}", t.name, t.kind), &t.base);
            d.animated("texture.render_from_object", &t.render_from_object);
        }
        for m in &self.media {
            d.entity(&format!("medium {:?}", m.name), &m.base);
            d.animated("medium.render_from_object", &m.render_from_object);
        }
        for def in &self.instance_definitions {
            d.line(&format!("object {:?}", def.name));
            for s in &def.shapes {
                d.shape(s);
            }
            for s in &def.animated_shapes {
                d.animated_shape(s);
            }
            d.line("objectend");
        }
        for i in 0..self.instances.len() {
            match self.instances.get(i) {
                (name, InstanceTransform::Fixed(t)) => {
                    d.transform(&format!("instance {name:?}"), &t)
                }
                (name, InstanceTransform::Animated(a)) => {
                    d.animated(&format!("instance {name:?}"), &a)
                }
            }
        }
        for o in &self.options {
            d.line(&format!("option {} {:?}", o.name, o.value));
        }
        d.0
    }
}

/// Builds [`SceneDescription::normalized_dump`].
struct Dump(String);

impl Dump {
    fn line(&mut self, s: &str) {
        self.0.push_str(s);
        self.0.push('\n');
    }

    fn num(v: Float) -> String {
        // Five significant digits hide rounding differences between
        // equivalent spellings of the same value; -0 prints as 0.
        let r = format!("{:.5e}", v as f64);
        if r.starts_with("-0.00000e") {
            r[1..].to_string()
        } else {
            r
        }
    }

    fn param(p: &ParsedParameter) -> String {
        let mut s = format!("{} {} [", p.canonical_type(), p.name);
        for v in &p.floats {
            let _ = write!(s, " {}", Self::num(*v));
        }
        for v in &p.ints {
            let _ = write!(s, " {v}");
        }
        for v in &p.strings {
            let _ = write!(s, " {v:?}");
        }
        for v in &p.bools {
            let _ = write!(s, " {v}");
        }
        s.push_str(" ]");
        s
    }

    fn entity(&mut self, what: &str, e: &SceneEntity) {
        let mut params: Vec<String> = e.params.params().iter().map(Self::param).collect();
        params.sort();
        self.line(&format!(
            "{what} {:?} cs={} {{ {} }}",
            e.name,
            e.color_space,
            params.join(" ")
        ));
    }

    fn transform(&mut self, what: &str, t: &Transform) {
        let m = t.matrix();
        let nums: Vec<String> = m.m.iter().flatten().map(|&v| Self::num(v)).collect();
        self.line(&format!("{what} [{}]", nums.join(" ")));
    }

    fn animated(&mut self, what: &str, a: &AnimatedTransform) {
        self.transform(
            &format!("{what} t0={}", Self::num(a.start_time)),
            &a.start_transform(),
        );
        self.transform(
            &format!("{what} t1={}", Self::num(a.end_time)),
            &a.end_transform(),
        );
    }

    fn attributes(&mut self, a: &ShapeAttributes) {
        self.line(&format!(
            "  reverse={} material={:?} light={:?} media={:?}/{:?}",
            a.reverse_orientation, a.material, a.light_index, a.inside_medium, a.outside_medium
        ));
    }

    fn shape(&mut self, s: &ShapeSceneEntity) {
        self.entity("shape", &s.base);
        self.transform("  render_from_object", &s.render_from_object);
        self.attributes(&s.attributes);
    }

    fn animated_shape(&mut self, s: &AnimatedShapeSceneEntity) {
        self.entity("animatedshape", &s.base);
        self.animated("  render_from_object", &s.render_from_object);
        self.attributes(&s.attributes);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_follow_pbrt_v4() {
        let s = SceneDescription::default();
        assert_eq!(s.film.name, "rgb");
        assert_eq!(s.sampler.name, "zsobol");
        assert_eq!(s.filter.name, "gaussian");
        assert_eq!(s.integrator.name, "volpath");
        assert_eq!(s.accelerator.name, "bvh");
        assert_eq!(s.camera.base.name, "perspective");
        assert_eq!(s.materials[0].name, "diffuse");
        assert_eq!(s.film.color_space, "srgb");
    }
}
