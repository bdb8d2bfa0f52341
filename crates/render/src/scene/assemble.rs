//! From a scene description to a render-ready [`Scene`] (pbrt-v4
//! `BasicScene`'s `Create*` phase): film, camera, sampler, filter,
//! textures, materials, lights, primitives, the aggregate and the
//! integrator. Each entity's parameters are read through one
//! [`ParamReader`] by its module's `create`; every problem is reported at
//! its directive, and parameters nothing read are warned about.

use std::collections::HashMap;
use std::sync::Arc;

use rpbrt_geometry::Transform;
use rpbrt_parser::{Diagnostic, MemoryBudget};

use super::entities::*;
use super::entity_list::EntityList;
use super::instances::InstanceList;
use super::materials::{create_materials, create_textures};
use super::shapes::{at_origin, create_primitives, ShapeContext};
use crate::accel::{AccelParams, ParamValue};
use crate::camera::create_camera;
use crate::film::{create_film, FilmOverrides};
use crate::filter::create_filter;
use crate::image::MIPMapCache;
use crate::integrator::{
    create_integrator, Integrator, IntegratorOptions, RayCounters, Scene, VolPathIntegrator,
};
use crate::light::{create_light, Light, LightCull, LightDialect, LightType};
use crate::lightsampler::create_light_sampler;
use crate::material::MaterialSet;
use crate::medium::{create_medium, create_region, Medium, RegionMedium};
use crate::params::{unknown_type, ParamReader};
use crate::primitive::{AnimatedPrimitive, InstanceSet, Moving, Primitive, PrimitiveAggregate};
use crate::sampler::{create_sampler, Sampler};
use crate::texture::TextureOptions;

/// What an object instance adds when the scene is created, in bytes: its
/// transformation and object in an [`InstanceSet`], and its accelerator
/// entry.
const INSTANCE_BYTES: u64 = 256;

/// Command-line settings that change how the scene is created.
#[derive(Clone, Debug, Default)]
pub struct CreateOptions {
    /// `--spp`.
    pub spp: Option<i32>,
    /// `--seed`.
    pub seed: Option<i32>,
    /// Film overrides (`--outfile`, `--cropwindow`, `--pixelbounds`, `--quick`).
    pub film: FilmOverrides,
    /// `--disable-texture-filtering`.
    pub disable_texture_filtering: bool,
    /// `--force-diffuse`.
    pub force_diffuse: bool,
    /// `--texture-cache-mb`: image textures tiled on disk behind this
    /// cache (`None`: held in memory).
    pub texture_cache: Option<std::sync::Arc<crate::image::tiled::TileCache>>,
}

/// The result of [`create_scene`].
pub struct CreatedScene {
    /// Everything the integrator needs.
    pub scene: Scene,
    /// The integrator.
    pub integrator: Integrator,
    /// Warnings raised while creating.
    pub warnings: Vec<Diagnostic>,
}

/// The errors and warnings of scene creation: the one place creators'
/// diagnostics go.
#[derive(Debug, Default)]
pub(super) struct Problems {
    /// Errors: the scene is not rendered.
    pub errors: Vec<Diagnostic>,
    /// Warnings, including unused parameters.
    pub warnings: Vec<Diagnostic>,
}

impl Problems {
    /// The value, or `None` with the error kept.
    pub fn take<T>(&mut self, r: Result<T, Diagnostic>) -> Option<T> {
        r.map_err(|e| self.errors.push(e)).ok()
    }

    /// The value of a creator that read `reader`: its warnings are kept,
    /// with the unused-parameter ones when it succeeded.
    pub fn finish<T>(&mut self, reader: ParamReader, r: Result<T, Diagnostic>) -> Option<T> {
        match r {
            Ok(v) => {
                self.warnings.extend(reader.finish());
                Some(v)
            }
            Err(e) => {
                self.errors.push(e);
                self.warnings.extend(reader.take_warnings());
                None
            }
        }
    }

    /// A step of a creator that goes on reading `reader`: on an error, the
    /// error and the warnings so far are kept.
    pub fn keep_going<T>(&mut self, reader: &ParamReader, r: Result<T, Diagnostic>) -> Option<T> {
        r.map_err(|e| {
            self.errors.push(e);
            self.warnings.extend(reader.take_warnings());
        })
        .ok()
    }
}

/// A directive's parameter reader in its colour space.
pub(super) fn reader<'a>(
    e: &'a SceneEntity,
    budget: &MemoryBudget,
) -> Result<ParamReader<'a>, Diagnostic> {
    ParamReader::new(&e.params, &e.loc, e.color_space).map(|r| r.with_budget(budget))
}

/// Reads an `Accelerator` directive's parameters.
fn accel_params(name: &str, ap: &ParamReader) -> Result<AccelParams, Diagnostic> {
    if name == "embree" {
        if let Err(why) = embree_available() {
            ap.warn(format!("\"embree\": {why}; using \"bvh\""));
            // Its parameters (it has none) are not worth a second warning.
            for param in ap.dict().params() {
                param.mark_used();
            }
            return Ok(AccelParams::default());
        }
    }
    let mut p = AccelParams::new(name)
        .map_err(|_| unknown_type("accelerator", name, AccelParams::NAMES, ap.loc()))?;
    for param in ap.dict().params() {
        let v = match param.canonical_type() {
            "integer" if param.ints.len() == 1 => ParamValue::Int(param.ints[0]),
            "float" if param.floats.len() == 1 => ParamValue::Float(param.floats[0]),
            "string" if param.strings.len() == 1 => ParamValue::Str(param.strings[0].as_str()),
            _ => {
                return Err(Diagnostic::error(
                    param.loc.clone(),
                    format!(
                        "\"{}\": expected a single integer, float or string value",
                        param.name
                    ),
                ))
            }
        };
        p.set(&param.name, v)
            .map_err(|m| Diagnostic::error(param.loc.clone(), m))?;
        param.mark_used();
    }
    Ok(p)
}

/// Whether `Accelerator "embree"` can be honoured: the cargo feature
/// `embree` is on and Embree's device could be made.
#[cfg(feature = "embree")]
fn embree_available() -> Result<(), String> {
    crate::accel::embree::available().map_err(|e| e.to_string())
}

/// Whether `Accelerator "embree"` can be honoured: not in this build.
#[cfg(not(feature = "embree"))]
fn embree_available() -> Result<(), String> {
    Err(crate::accel::params_no_embree().to_string())
}

/// Creates the named media (pbrt-v4 `BasicScene::CreateMedia`), each
/// under the transformation in effect at its `MakeNamedMedium` (the start
/// of an animated one, with a warning as in pbrt-v4), and their ids by name.
fn create_media(desc: &SceneDescription, p: &mut Problems) -> (Vec<Medium>, HashMap<String, u32>) {
    let mut media = Vec::new();
    let mut ids = HashMap::new();
    for m in &desc.media {
        let Some(r) = p.take(reader(&m.base, &desc.budget)) else {
            continue;
        };
        if m.render_from_object.is_animated() {
            r.warn(
                "animated transformation provided for medium; only the start transform will be used",
            );
        }
        // The builder keeps the type among the parameters as its
        // `"string type"`; reading it here marks it used (it is the
        // entity's name), so it is not reported as an unused parameter.
        // Grids written in the scene copy their parameters' values.
        let medium = r
            .charge(m.base.params.memory_bytes() as u64, "this medium's data")
            .and_then(|()| r.string("type", &m.base.name))
            .and_then(|ty| create_medium(&ty, &r, &m.render_from_object.start_transform()));
        if let Some(medium) = p.finish(r, medium) {
            ids.insert(m.name.clone(), media.len() as u32);
            media.push(medium);
        }
    }
    (media, ids)
}

/// Creates a pbrt-v1/v2 scene's `Volume` regions as one medium, appended
/// to `media`; returns its id (`None` without regions).
fn create_regions(
    desc: &SceneDescription,
    p: &mut Problems,
    media: &mut Vec<Medium>,
) -> Option<u32> {
    let mut regions = Vec::new();
    for v in &desc.volume_regions {
        let Some(r) = p.take(reader(&v.base, &desc.budget)) else {
            continue;
        };
        let region = r
            .charge(v.base.params.memory_bytes() as u64, "this region's data")
            .and_then(|()| {
                create_region(
                    &v.base.name,
                    &r,
                    &v.render_from_region,
                    desc.regions_scatter,
                )
            });
        if let Some(region) = p.finish(r, region) {
            regions.push(region);
        }
    }
    if regions.is_empty() {
        return None;
    }
    media.push(Medium::Region(Box::new(RegionMedium::new(regions))));
    Some(media.len() as u32 - 1)
}

/// pbrt-v3's `path` integrator traced BSSRDFs, which pbrt-v4's leaves to
/// `volpath`: in a pbrt-v3 scene with subsurface scattering, `path` is
/// rendered by `volpath` with the same parameters (the same image in
/// expectation, the BSSRDF included).
fn v3_path_with_subsurface(
    desc: &SceneDescription,
    materials: &MaterialSet,
    integrator: Integrator,
) -> Integrator {
    match integrator {
        Integrator::Path(p) if desc.pbrt_v3.is_some() && materials.any_subsurface() => {
            Integrator::VolPath(VolPathIntegrator {
                max_depth: p.max_depth,
                light_sampler_name: p.light_sampler_name,
                regularize: p.regularize,
            })
        }
        i => i,
    }
}

/// What [`check_integrator_support`] looks at.
struct Support<'a> {
    media: &'a [Medium],
    materials: &'a MaterialSet,
    /// Per material, whether some shape uses it.
    used: &'a [bool],
    lights: &'a [Light],
}

/// What pbrt-v4 says when an integrator cannot render part of a scene:
/// warnings for media and subsurface scattering that the integrator
/// ignores, and errors for what `simplevolpath` refuses (delta lights,
/// surfaces that scatter).
fn check_integrator_support(
    desc: &SceneDescription,
    integrator: &Integrator,
    support: &Support,
    p: &mut Problems,
) {
    let Support {
        media,
        materials,
        used,
        lights,
    } = *support;
    let name = &*desc.integrator.name;
    let loc = &desc.integrator.loc;
    // pbrt-v4's list: the integrators that trace through media.
    let volumetric = matches!(
        integrator,
        Integrator::VolPath(_)
            | Integrator::SimpleVolPath(_)
            | Integrator::Bdpt(_)
            | Integrator::Mlt(_)
    );
    if !media.is_empty() && !volumetric {
        p.warnings.push(Diagnostic::warning(
            loc.clone(),
            format!("scene has scattering media but the \"{name}\" integrator doesn't support volume scattering; consider using \"volpath\" or \"simplevolpath\""),
        ));
    }
    if materials.any_subsurface() && !matches!(integrator, Integrator::VolPath(_)) {
        p.warnings.push(Diagnostic::warning(
            loc.clone(),
            format!("some objects in the scene have subsurface scattering, which is not supported by the \"{name}\" integrator; use the \"volpath\" integrator to render them correctly"),
        ));
    }
    if let Integrator::SimpleVolPath(_) = integrator {
        for (l, e) in lights.iter().zip(&desc.lights) {
            if l.light_type().is_delta() {
                p.errors.push(Diagnostic::error(
                    e.base.loc.clone(),
                    "the \"simplevolpath\" integrator only supports area and infinite light sources",
                ));
            }
        }
        if let Some(loc) = materials.first_scattering(|m| used.get(m as usize) == Some(&true)) {
            p.errors.push(Diagnostic::error(
                loc.cloned().unwrap_or_else(|| loc_of(desc)),
                "the \"simplevolpath\" integrator doesn't support surface scattering (only \"interface\" and black \"diffuse\" emitter surfaces)",
            ));
        }
    }
}

fn loc_of(desc: &SceneDescription) -> rpbrt_parser::FileLoc {
    desc.integrator.loc.clone()
}

/// Builds the render-ready scene.
pub fn create_scene(
    desc: &SceneDescription,
    opts: &CreateOptions,
) -> Result<CreatedScene, Vec<Diagnostic>> {
    create(desc, Taken::default(), opts)
}

/// [`create_scene`], taking the description's object instances and
/// animated shapes (left empty): the instances' transformations become
/// the scene's instance set as they are, and the animated shapes are
/// freed as they become render primitives, instead of being held whole
/// beside them.
pub fn create_scene_taking_entities(
    desc: &mut SceneDescription,
    opts: &CreateOptions,
) -> Result<CreatedScene, Vec<Diagnostic>> {
    let taken = Taken {
        instances: Some(std::mem::take(&mut desc.instances)),
        animated_shapes: Some(std::mem::take(&mut desc.animated_shapes)),
    };
    create(desc, taken, opts)
}

/// The description's entities [`create`] was given to free as it goes
/// (`None`: read from the description).
#[derive(Default)]
struct Taken {
    instances: Option<InstanceList>,
    animated_shapes: Option<EntityList<AnimatedShapeSceneEntity>>,
}

/// Appends the primitives of the description's object instances to
/// `prims`, in order (`taken`: the instances taken from it, whose lists
/// are moved into the primitives instead of copied). Instances of an
/// undefined object are errors (at its first instance); those of an empty
/// one are left out.
fn place_instances(
    desc: &SceneDescription,
    taken: Option<InstanceList>,
    definitions: &HashMap<&str, Arc<PrimitiveAggregate>>,
    prims: &mut Vec<Primitive>,
    p: &mut Problems,
) {
    let list = taken.as_ref().unwrap_or(&desc.instances);
    // Per name: its object, where defined and not empty.
    let objects: Vec<Option<&Arc<PrimitiveAggregate>>> = list
        .names
        .iter()
        .map(|(name, loc)| match definitions.get(&**name) {
            None => {
                p.errors.push(Diagnostic::error(
                    loc.clone(),
                    format!("object \"{name}\" is not defined"),
                ));
                None
            }
            Some(def) => (!def.primitives().is_empty()).then_some(def),
        })
        .collect();
    let placed = list
        .name_of
        .iter()
        .filter(|&&k| objects[k as usize].is_some())
        .count();
    // The instances' primitives and accelerator entries, charged at the
    // first instance.
    if let Some((_, loc)) = list.names.first() {
        let bytes = INSTANCE_BYTES.saturating_mul(placed as u64);
        if let Err(e) = desc.budget.charge(bytes, "these object instances") {
            p.errors.push(Diagnostic::error(loc.clone(), e.to_string()));
            return;
        }
    }
    if placed == 0 {
        return;
    }
    if !list.animated.is_empty() {
        place_runs(list, &objects, prims);
        return;
    }
    // No instance moves: all of them are one set, its lists the
    // description's (copied only when it is borrowed), each name's index
    // turned into its object's.
    let mut set_objects = Vec::new();
    let index: Vec<u32> = objects
        .iter()
        .map(|o| match o {
            Some(def) => {
                set_objects.push(Arc::clone(def));
                set_objects.len() as u32 - 1
            }
            None => u32::MAX,
        })
        .collect();
    let (mut object_of, mut fixed) = match taken {
        Some(list) => (list.name_of, list.fixed),
        None => (list.name_of.clone(), list.fixed.clone()),
    };
    if placed < object_of.len() {
        fixed.retain_indices(|i| index[object_of[i] as usize] != u32::MAX);
        object_of.retain(|&k| index[k as usize] != u32::MAX);
    }
    for k in &mut object_of {
        *k = index[*k as usize];
    }
    object_of.shrink_to_fit();
    fixed.shrink_to_fit();
    prims.push(Primitive::Instances(Box::new(InstanceSet::from_parts(
        set_objects,
        object_of,
        fixed,
    ))));
}

/// [`place_instances`] where some instances move: each run of fixed ones
/// is a set, each moving one a primitive of its own, in order.
fn place_runs(
    list: &InstanceList,
    objects: &[Option<&Arc<PrimitiveAggregate>>],
    prims: &mut Vec<Primitive>,
) {
    let mut runs = InstanceRuns::default();
    let mut moving = list.animated.iter().peekable();
    for (i, &k) in list.name_of.iter().enumerate() {
        let animated = moving.next_if(|(j, _)| *j as usize == i).map(|(_, a)| &**a);
        let Some(def) = objects[k as usize] else {
            continue;
        };
        match animated {
            Some(a) => {
                runs.close(prims);
                prims.push(Primitive::Animated(Box::new(AnimatedPrimitive::new(
                    Moving::Many(def.clone()),
                    a.clone(),
                ))));
            }
            None => runs.add(def, list.fixed.get(i)),
        }
    }
    runs.close(prims);
}

/// Consecutive instances under fixed transformations, gathered into one
/// [`InstanceSet`] each run (an entry per instance in the aggregate, in
/// order).
#[derive(Default)]
struct InstanceRuns {
    set: InstanceSet,
    /// The set's objects, by their aggregate's address.
    objects: HashMap<usize, u32>,
}

impl InstanceRuns {
    /// Adds an instance of `def` placed by `t` to the open run.
    fn add(&mut self, def: &Arc<PrimitiveAggregate>, t: Transform) {
        let set = &mut self.set;
        let k = *self
            .objects
            .entry(Arc::as_ptr(def) as usize)
            .or_insert_with(|| set.add_object(def.clone()));
        set.push(k, t);
    }

    /// Ends the open run, appending its set to `prims`.
    fn close(&mut self, prims: &mut Vec<Primitive>) {
        if !self.set.is_empty() {
            let mut set = std::mem::take(&mut self.set);
            set.shrink_to_fit();
            prims.push(Primitive::Instances(Box::new(set)));
        }
        self.objects.clear();
    }
}

fn create(
    desc: &SceneDescription,
    taken: Taken,
    opts: &CreateOptions,
) -> Result<CreatedScene, Vec<Diagnostic>> {
    let mut problems = Problems::default();
    let p = &mut problems;

    // Participating media, by name.
    let (mut media, medium_ids) = create_media(desc, p);
    // pbrt-v1/v2's regions are seen wherever a ray is (surfaces do not
    // change a ray's medium without a MediumInterface).
    let regions = create_regions(desc, p, &mut media);
    let medium_of = |name: &str| medium_ids.get(name).copied().or(regions);

    // Filter, film, camera, sampler.
    let filter = p.take(reader(&desc.filter, &desc.budget)).and_then(|r| {
        let f = create_filter(&desc.filter.name, &r);
        p.finish(r, f)
    });
    let camera_entity = &desc.camera;
    let Some(camera_reader) = p.take(reader(&camera_entity.base, &desc.budget)) else {
        return Err(problems.errors);
    };
    let exposure = camera_reader.float("shutterclose", 1.0).unwrap_or(1.0)
        - camera_reader.float("shutteropen", 0.0).unwrap_or(0.0);
    let camera_transform = &camera_entity.camera_transform;
    // The `function` integrator takes `--outfile` for its text file and
    // never writes the film (pbrt-v4's `Options->imageFile`).
    let film_overrides = FilmOverrides {
        outfile: opts
            .film
            .outfile
            .clone()
            .filter(|_| desc.integrator.name != "function"),
        ..opts.film.clone()
    };
    let film = filter.as_ref().and_then(|filter| {
        let r = p.take(reader(&desc.film, &desc.budget))?;
        let f = create_film(
            &desc.film.name,
            &r,
            filter,
            exposure,
            camera_transform,
            &film_overrides,
        );
        p.finish(r, f)
    });
    let Some((filter, film)) = filter.zip(film) else {
        return Err(problems.errors);
    };
    let geometry = film.geometry();
    let camera = create_camera(
        &camera_entity.base.name,
        &camera_reader,
        camera_transform,
        &geometry,
        medium_of(&camera_entity.medium),
    );
    let Some(mut camera) = p.finish(camera_reader, camera) else {
        return Err(problems.errors);
    };
    // Importance (pbrt-v4 `We`) depends on the film's filter.
    camera.set_filter_radius(filter.radius());
    let sampler = p.take(reader(&desc.sampler, &desc.budget)).and_then(|r| {
        let s = create_sampler(
            &desc.sampler.name,
            &r,
            geometry.full_resolution,
            opts.spp,
            opts.seed,
        );
        p.finish(r, s)
    });

    // Textures and materials.
    let mut cache = MIPMapCache::with_budget(&desc.budget);
    if let Some(tiles) = &opts.texture_cache {
        cache = cache.with_tiles(tiles.clone());
    }
    let texture_options = TextureOptions {
        disable_texture_filtering: opts.disable_texture_filtering,
    };
    let Some(textures) = create_textures(
        &desc.float_textures,
        &desc.spectrum_textures,
        &cache,
        &texture_options,
        &desc.budget,
        p,
    ) else {
        return Err(problems.errors);
    };
    if let Some(tiles) = &opts.texture_cache {
        // About the cache folder (a command-line setting), not a directive.
        p.warnings
            .extend(tiles.take_warnings().into_iter().map(|message| Diagnostic {
                severity: rpbrt_parser::Severity::Warning,
                loc: None,
                message,
            }));
    }
    let Some((materials, named_material_ids)) = create_materials(
        &desc.materials,
        &desc.named_materials,
        &textures,
        &desc.budget,
        p,
    ) else {
        return Err(problems.errors);
    };
    // Lights.
    let mut lights: Vec<Light> = Vec::new();
    for l in &desc.lights {
        let Some(r) = p.take(reader(&l.base, &desc.budget)) else {
            continue;
        };
        let light = create_light(
            &l.base.name,
            &r,
            &l.render_from_object,
            medium_of(&l.medium),
            camera_transform,
            LightDialect {
                v3_mapname: l.pbrt_v3,
                v3_file: desc.pbrt_v3.is_some(),
            },
        );
        if let Some(light) = p.finish(r, light) {
            lights.push(light);
        }
    }

    // Primitives, with area lights per shape.
    let cx = ShapeContext {
        desc,
        textures: &textures,
        named_material_ids: &named_material_ids,
        materials: &materials,
        medium_ids: &medium_ids,
    };
    // Object definitions and animated shapes get an aggregate of their
    // own: under Embree, an Embree scene each (reached through the user
    // geometry of the instance or animated primitive); otherwise the
    // default BVH, whatever the scene's accelerator.
    let default_accel = match AccelParams::new(&desc.accelerator.name) {
        Ok(a) if desc.accelerator.name == "embree" && embree_available().is_ok() => a,
        _ => AccelParams::default(),
    };
    let mut prims: Vec<Primitive> = Vec::new();
    for s in &desc.shapes {
        create_primitives(&cx, s, &mut lights, p, &mut prims);
    }
    // One primitive for each animated shape (they carry no lights).
    let mut inner = Vec::new();
    let mut animated = |s: AnimatedShapeSceneEntity,
                        lights: &mut Vec<Light>,
                        p: &mut Problems,
                        prims: &mut Vec<Primitive>| {
        if s.attributes.light_index.is_some() {
            p.errors.push(Diagnostic::error(
                s.base.loc.clone(),
                "area lights on animated shapes are not supported (as in pbrt-v4)",
            ));
            return;
        }
        let (shape, render_from_primitive) = at_origin(s);
        create_primitives(&cx, &shape, lights, p, &mut inner);
        if let Some(moving) = Moving::of(&mut inner, &default_accel) {
            prims.push(Primitive::Animated(Box::new(AnimatedPrimitive::new(
                moving,
                render_from_primitive,
            ))));
        }
    };
    match taken.animated_shapes {
        None => {
            for s in &desc.animated_shapes {
                animated(s.clone(), &mut lights, p, &mut prims);
            }
        }
        Some(list) => {
            // Taken from the description: made from the last, each chunk
            // of the list freed as it empties (its memory reused for the
            // primitives), each shape's problems kept apart and reported
            // in the files' order.
            let (base, n_lights) = (prims.len(), lights.len());
            let mut reported = Vec::new();
            let mut list = list;
            while let Some(s) = list.pop() {
                let mut own = Problems::default();
                animated(s, &mut lights, &mut own, &mut prims);
                if !own.errors.is_empty() || !own.warnings.is_empty() {
                    reported.push(own);
                }
            }
            debug_assert_eq!(lights.len(), n_lights);
            prims[base..].reverse();
            for own in reported.into_iter().rev() {
                p.errors.extend(own.errors);
                p.warnings.extend(own.warnings);
            }
        }
    }
    // Object definitions, built once and shared by their instances.
    let mut definitions: HashMap<&str, Arc<PrimitiveAggregate>> = HashMap::new();
    for def in &desc.instance_definitions {
        let mut inner = Vec::new();
        for s in &def.shapes {
            if s.attributes.light_index.is_some() {
                p.errors.push(Diagnostic::error(
                    s.base.loc.clone(),
                    "area lights inside object definitions are not supported (as in pbrt-v4)",
                ));
                continue;
            }
            create_primitives(&cx, s, &mut lights, p, &mut inner);
        }
        for s in &def.animated_shapes {
            let mut shapes = Vec::new();
            let (shape, render_from_primitive) = at_origin(s.clone());
            create_primitives(&cx, &shape, &mut lights, p, &mut shapes);
            if let Some(moving) = Moving::of(&mut shapes, &default_accel) {
                inner.push(Primitive::Animated(Box::new(AnimatedPrimitive::new(
                    moving,
                    render_from_primitive,
                ))));
            }
        }
        definitions.insert(
            def.name.as_str(),
            Arc::new(PrimitiveAggregate::new(inner, &default_accel)),
        );
    }
    place_instances(desc, taken.instances, &definitions, &mut prims, p);

    let accel = p
        .take(reader(&desc.accelerator, &desc.budget))
        .and_then(|r| {
            let a = accel_params(&desc.accelerator.name, &r);
            p.finish(r, a)
        })
        .unwrap_or_default();
    let integrator = p
        .take(reader(&desc.integrator, &desc.budget))
        .and_then(|r| {
            let iopts = IntegratorOptions {
                spp: opts.spp,
                seed: opts.seed,
                outfile: opts.film.outfile.clone(),
            };
            let i = create_integrator(&desc.integrator.name, &r, &iopts)
                .map(|i| v3_path_with_subsurface(desc, &materials, i));
            p.finish(r, i)
        });
    if let Some(i) = &integrator {
        let mut used = vec![false; materials.materials().len()];
        for prim in &prims {
            prim.for_each_material(&mut |m| {
                if let Some(u) = used.get_mut(m as usize) {
                    *u = true;
                }
            });
        }
        let support = Support {
            media: &media,
            materials: &materials,
            used: &used,
            lights: &lights,
        };
        check_integrator_support(desc, i, &support, p);
        // Light tracing connects to the camera through its importance,
        // which only the perspective camera has (pbrt-v4's error).
        if i.needs_camera_importance() && !camera.supports_importance() {
            p.errors.push(Diagnostic::error(
                desc.integrator.loc.clone(),
                format!(
                    "Only the \"perspective\" camera is currently supported with the \"{}\" integrator.",
                    desc.integrator.name
                ),
            ));
        }
        // pbrt-v4's check: the global Sobol' sequence spreads a pixel's
        // points over the image.
        if matches!(i, Integrator::Function(_)) && matches!(sampler, Some(Sampler::Sobol(_))) {
            p.errors.push(Diagnostic::error(
                desc.integrator.loc.clone(),
                "\"sobol\" sampler should be replaced with \"paddedsobol\" for the \"function\" integrator.",
            ));
        }
    }
    if let Some(i) = &integrator {
        let pixels = film.pixel_bounds().area().max(0) as u64;
        if let Err(e) = desc.budget.charge(
            i.memory_bytes(pixels),
            &format!("the \"{}\" integrator", i.name()),
        ) {
            p.errors.push(Diagnostic::error(
                desc.integrator.loc.clone(),
                e.to_string(),
            ));
        }
    }
    if !problems.errors.is_empty() {
        return Err(problems.errors);
    }
    let (Some(sampler), Some(integrator)) = (sampler, integrator) else {
        return Err(problems.errors);
    };
    let aggregate = PrimitiveAggregate::new(prims, &accel);
    let bounds = aggregate.bounds();
    for l in &mut lights {
        l.preprocess(&bounds);
    }
    let infinite_lights: Vec<u32> = lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.light_type() == LightType::Infinite)
        .map(|(i, _)| i as u32)
        .collect();
    let ls_name = integrator.light_sampler_name().unwrap_or("bvh").to_string();
    let light_sampler = match create_light_sampler(&ls_name, &lights) {
        Ok(s) => s,
        Err(e) => return Err(vec![e]),
    };
    let spp = sampler.samples_per_pixel();
    let camera_differentials = camera.camera_differentials();
    let scene = Scene {
        camera,
        film,
        sampler,
        filter,
        aggregate: std::sync::Arc::new(aggregate),
        light_cull: lights.iter().map(LightCull::for_light).collect(),
        lights,
        infinite_lights,
        light_sampler,
        has_volumes: !media.is_empty() || materials.any_interface(),
        media,
        materials,
        camera_differentials,
        samples_per_pixel: spp,
        disable_texture_filtering: opts.disable_texture_filtering,
        force_diffuse: opts.force_diffuse,
        counters: RayCounters::default(),
    };
    Ok(CreatedScene {
        scene,
        integrator,
        warnings: problems.warnings,
    })
}
