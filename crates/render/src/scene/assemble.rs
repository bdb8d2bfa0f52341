//! From a scene description to a render-ready [`Scene`] (pbrt-v4
//! `BasicScene`'s `Create*` phase): film, camera, sampler, filter,
//! textures, materials, lights, primitives, the aggregate and the
//! integrator, with every problem reported at its directive.

use super::entities::*;
use super::shapes::create_entity_shapes;
use crate::accel::{AccelParams, ParamValue};
use crate::camera::create_camera_with;
use crate::film::{create_film, FilmOverrides};
use crate::filter::create_filter;
use crate::image::MIPMapCache;
use crate::integrator::{create_integrator, Integrator, RayCounters, Scene};
use crate::light::{create_area_light, create_light, Light, LightCull, LightType};
use crate::lightsampler::create_light_sampler;
use crate::material::create_materials;
use crate::primitive::{
    Alpha, AnimatedPrimitive, GeometricPrimitive, Primitive, PrimitiveAggregate,
    TransformedPrimitive,
};
use crate::sampler::create_sampler;
use crate::texture::{create_textures, get_float_texture_opt, NamedTextures, TextureOptions};
use rpbrt_geometry::transform::Transform;
use rpbrt_parser::{Diagnostic, ParameterDictionary};
use std::collections::HashMap;
use std::sync::Arc;

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

/// Reads an `Accelerator` directive's parameters.
fn accel_params(e: &SceneEntity) -> Result<AccelParams, Diagnostic> {
    let mut p = AccelParams::new(&e.name).map_err(|m| Diagnostic::error(e.loc.clone(), m))?;
    for param in e.params.params() {
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

fn alpha_of(params: &ParameterDictionary, textures: &NamedTextures) -> Result<Alpha, Diagnostic> {
    match get_float_texture_opt(params, "alpha", textures)? {
        None => Ok(Alpha::Opaque),
        Some(t) => match &*t {
            crate::texture::FloatTexture::Constant(a) if *a >= 1.0 => Ok(Alpha::Opaque),
            crate::texture::FloatTexture::Constant(a) => Ok(Alpha::Constant(*a)),
            _ => Ok(Alpha::Texture(t)),
        },
    }
}

fn one<T>(r: Result<T, Diagnostic>, errors: &mut Vec<Diagnostic>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            errors.push(e);
            None
        }
    }
}

/// Builds the render-ready scene.
pub fn create_scene(
    desc: &SceneDescription,
    opts: &CreateOptions,
) -> Result<CreatedScene, Vec<Diagnostic>> {
    let mut warnings: Vec<Diagnostic> = Vec::new();
    let mut errors: Vec<Diagnostic> = Vec::new();

    // Participating media are not built yet: refuse scenes that use them.
    if let Some(m) = desc.media.first() {
        errors.push(Diagnostic::error(
            m.base.loc.clone(),
            "participating media are not supported yet",
        ));
    }

    // Filter, film, camera, sampler.
    let filter = one(
        create_filter(&desc.filter.name, &desc.filter.params, &desc.filter.loc),
        &mut errors,
    );
    let cam_params = &desc.camera.base.params;
    let exposure = cam_params.get_one_float("shutterclose", 1.0).unwrap_or(1.0)
        - cam_params.get_one_float("shutteropen", 0.0).unwrap_or(0.0);
    let film = filter.as_ref().and_then(|f| {
        one(
            create_film(
                &desc.film,
                f,
                exposure,
                &desc.camera.camera_transform,
                &opts.film,
            )
            .map(|(film, w)| {
                warnings.extend(w);
                film
            }),
            &mut errors,
        )
    });
    let Some((filter, film)) = filter.zip(film) else {
        return Err(errors);
    };
    let geometry = film.geometry();
    let camera = match create_camera_with(&desc.camera, &geometry, None) {
        Ok(c) => {
            warnings.extend(c.warnings);
            c.camera
        }
        Err(e) => {
            errors.push(e);
            return Err(errors);
        }
    };
    let mut sampler_warnings = Vec::new();
    let sampler = one(
        create_sampler(
            &desc.sampler.name,
            &desc.sampler.params,
            geometry.full_resolution,
            opts.spp,
            opts.seed,
            &desc.sampler.loc,
            &mut sampler_warnings,
        ),
        &mut errors,
    );
    warnings.extend(sampler_warnings);

    // Textures and materials.
    let cache = MIPMapCache::new();
    let textures = match create_textures(
        &desc.float_textures,
        &desc.spectrum_textures,
        &cache,
        &TextureOptions {
            disable_texture_filtering: opts.disable_texture_filtering,
        },
    ) {
        Ok((t, w)) => {
            warnings.extend(w);
            t
        }
        Err(e) => {
            errors.extend(e);
            return Err(errors);
        }
    };
    let (materials, named_material_ids) =
        match create_materials(&desc.materials, &desc.named_materials, &textures) {
            Ok((m, ids, w)) => {
                warnings.extend(w);
                (m, ids)
            }
            Err(e) => {
                errors.extend(e);
                return Err(errors);
            }
        };
    if let Some((_, loc)) = materials.first_subsurface() {
        let loc = loc.cloned().unwrap_or_else(|| desc.integrator.loc.clone());
        errors.push(Diagnostic::error(
            loc,
            "subsurface scattering is not supported yet: no rpbrt integrator renders BSSRDFs",
        ));
    }
    let material_id = |r: &MaterialRef| -> Option<u32> {
        match r {
            MaterialRef::Index(i) => Some(*i as u32),
            MaterialRef::Named(n) => named_material_ids.get(n).copied(),
        }
    };

    // Lights.
    let camera_transform = &desc.camera.camera_transform;
    let mut lights: Vec<Light> = Vec::new();
    for l in &desc.lights {
        match create_light(l, None, camera_transform) {
            Ok((light, w)) => {
                warnings.extend(w);
                lights.push(light);
            }
            Err(e) => errors.push(e),
        }
    }

    // Primitives, with area lights per shape.
    let mut prims: Vec<Primitive> = Vec::new();
    let make_prims = |s: &ShapeSceneEntity,
                      lights: &mut Vec<Light>,
                      errors: &mut Vec<Diagnostic>,
                      warnings: &mut Vec<Diagnostic>,
                      out: &mut Vec<Primitive>| {
        let created = match create_entity_shapes(
            &s.base,
            &s.render_from_object,
            s.attributes.reverse_orientation,
        ) {
            Ok(c) => c,
            Err(e) => {
                errors.push(e);
                return;
            }
        };
        warnings.extend(created.warnings);
        let alpha = match alpha_of(&s.base.params, &textures) {
            Ok(a) => a,
            Err(e) => {
                errors.push(e);
                return;
            }
        };
        let material = match &s.attributes.material {
            MaterialRef::Named(n) if n.is_empty() || n == "none" || n == "interface" => None,
            r => match material_id(r) {
                Some(id) => Some(id),
                None => {
                    errors.push(Diagnostic::error(
                        s.base.loc.clone(),
                        format!("material {r:?} is not defined"),
                    ));
                    return;
                }
            },
        };
        for shape in created.shapes {
            let area_light = match (s.attributes.light_index, material) {
                (Some(li), Some(_)) => {
                    let al = &desc.area_lights[li];
                    let alpha_tex = match &alpha {
                        Alpha::Texture(t) => Some(t.clone()),
                        Alpha::Constant(a) => {
                            Some(Arc::new(crate::texture::FloatTexture::Constant(*a)))
                        }
                        Alpha::Opaque => None,
                    };
                    match create_area_light(
                        al,
                        &s.render_from_object,
                        &shape,
                        alpha_tex,
                        None,
                        None,
                    ) {
                        Ok(light) => {
                            lights.push(light);
                            Some((lights.len() - 1) as u32)
                        }
                        Err(e) => {
                            errors.push(e);
                            None
                        }
                    }
                }
                (Some(li), None) => {
                    warnings.push(Diagnostic::warning(
                        desc.area_lights[li].loc.clone(),
                        "ignoring the area light of a shape with an interface material",
                    ));
                    None
                }
                _ => None,
            };
            out.push(Primitive::Geometric(GeometricPrimitive {
                shape,
                material,
                area_light,
                medium_interface: None,
                alpha: alpha.clone(),
            }));
        }
        for d in s.base.params.report_unused() {
            if !super::shapes::LATER_SHAPE_PARAMS
                .iter()
                .any(|p| d.message.contains(&format!("\"{p}\"")))
            {
                warnings.push(d);
            }
        }
    };
    for s in &desc.shapes {
        make_prims(s, &mut lights, &mut errors, &mut warnings, &mut prims);
    }
    let default_accel = AccelParams::default();
    for s in &desc.animated_shapes {
        if s.attributes.light_index.is_some() {
            errors.push(Diagnostic::error(
                s.base.loc.clone(),
                "area lights on animated shapes are not supported (as in pbrt-v4)",
            ));
            continue;
        }
        let fixed = ShapeSceneEntity {
            base: s.base.clone(),
            render_from_object: Transform::identity(),
            object_from_render: Transform::identity(),
            attributes: s.attributes.clone(),
        };
        let mut inner = Vec::new();
        make_prims(&fixed, &mut lights, &mut errors, &mut warnings, &mut inner);
        if !inner.is_empty() {
            prims.push(Primitive::Animated(Box::new(AnimatedPrimitive {
                primitive: Arc::new(PrimitiveAggregate::new(inner, &default_accel)),
                render_from_primitive: s.render_from_object,
            })));
        }
    }
    // Object definitions, built once and shared by their instances.
    let mut definitions: HashMap<&str, Arc<PrimitiveAggregate>> = HashMap::new();
    for def in &desc.instance_definitions {
        let mut inner = Vec::new();
        for s in &def.shapes {
            if s.attributes.light_index.is_some() {
                errors.push(Diagnostic::error(
                    s.base.loc.clone(),
                    "area lights inside object definitions are not supported (as in pbrt-v4)",
                ));
                continue;
            }
            make_prims(s, &mut lights, &mut errors, &mut warnings, &mut inner);
        }
        for s in &def.animated_shapes {
            let fixed = ShapeSceneEntity {
                base: s.base.clone(),
                render_from_object: Transform::identity(),
                object_from_render: Transform::identity(),
                attributes: s.attributes.clone(),
            };
            let mut shapes = Vec::new();
            make_prims(&fixed, &mut lights, &mut errors, &mut warnings, &mut shapes);
            if !shapes.is_empty() {
                inner.push(Primitive::Animated(Box::new(AnimatedPrimitive {
                    primitive: Arc::new(PrimitiveAggregate::new(shapes, &default_accel)),
                    render_from_primitive: s.render_from_object,
                })));
            }
        }
        definitions.insert(
            def.name.as_str(),
            Arc::new(PrimitiveAggregate::new(inner, &default_accel)),
        );
    }
    for inst in &desc.instances {
        let Some(def) = definitions.get(inst.name.as_str()) else {
            errors.push(Diagnostic::error(
                inst.loc.clone(),
                format!("object \"{}\" is not defined", inst.name),
            ));
            continue;
        };
        if def.primitives().is_empty() {
            continue;
        }
        prims.push(match &inst.render_from_instance {
            InstanceTransform::Fixed(t) => Primitive::Transformed(Box::new(TransformedPrimitive {
                primitive: def.clone(),
                render_from_primitive: *t,
            })),
            InstanceTransform::Animated(a) => Primitive::Animated(Box::new(AnimatedPrimitive {
                primitive: def.clone(),
                render_from_primitive: **a,
            })),
        });
    }

    let accel = match accel_params(&desc.accelerator) {
        Ok(a) => a,
        Err(e) => {
            errors.push(e);
            AccelParams::default()
        }
    };
    let integrator = one(
        create_integrator(
            &desc.integrator.name,
            &desc.integrator.params,
            &desc.integrator.loc,
            !desc.media.is_empty(),
        ),
        &mut errors,
    );
    for e in [
        &desc.film,
        &desc.sampler,
        &desc.filter,
        &desc.integrator,
        &desc.camera.base,
    ] {
        warnings.extend(e.params.report_unused());
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let (Some(sampler), Some(integrator)) = (sampler, integrator) else {
        return Err(errors);
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
        aggregate,
        light_cull: lights.iter().map(LightCull::for_light).collect(),
        lights,
        infinite_lights,
        light_sampler,
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
        warnings,
    })
}
