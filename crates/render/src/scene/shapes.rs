//! Turning the shape entities of a scene description into primitives
//! (pbrt-v4 `BasicScene::CreateAggregate`'s shape half): every `Shape`
//! directive with its material, alpha mask and area lights, with located
//! errors and warnings.

use std::collections::HashMap;
use std::sync::Arc;

use rpbrt_parser::{Diagnostic, MemoryBudget};

use super::assemble::Problems;
use super::entities::{
    AnimatedShapeSceneEntity, MaterialRef, OptionValue, SceneDescription, SceneEntity,
    ShapeSceneEntity,
};
use crate::light::{create_area_light, Light};
use crate::material::MaterialSet;
use crate::params::ParamReader;
use crate::primitive::{Alpha, GeometricPrimitive, MediumInterface, MeshPrimitive, Primitive};
use crate::shape::create::{create_shape_set, create_shapes, Displacement};
use crate::shape::Shape;
use crate::texture::{FloatTexture, NamedTextures, TextureEvalContext, TextureParams};
use rpbrt_geometry::animated::AnimatedTransform;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::{Point2f, Point3f};

/// What shapes are turned into primitives with.
pub(super) struct ShapeContext<'a> {
    /// The scene (for its area lights).
    pub desc: &'a SceneDescription,
    /// The named textures (for alpha masks).
    pub textures: &'a NamedTextures,
    /// Named materials' indices.
    pub named_material_ids: &'a HashMap<String, u32>,
    /// The materials (to recognise interfaces).
    pub materials: &'a MaterialSet,
    /// Named media's indices.
    pub medium_ids: &'a HashMap<String, u32>,
}

/// What one primitive adds to the accelerator, in bytes: its build
/// reference and its share of the nodes (about what a 10M-triangle mesh's
/// 4-wide BVH takes, build buffers included).
const ACCEL_BYTES_PER_PRIMITIVE: usize = 64;

/// What a shape other than a mesh triangle takes, in bytes: its box
/// (quadrics keep a transformation and their parameters) and the enum
/// that holds it.
const SHAPE_BYTES: usize = 320;

/// A shape entity's reader (shapes have no colours of their own),
/// charging to `budget`.
fn reader<'a>(e: &'a SceneEntity, budget: &MemoryBudget) -> ParamReader<'a> {
    ParamReader::plain(&e.params, &e.loc).with_budget(budget)
}

/// pbrt-v4's alpha: a float texture or constant; 1 (the default) is opaque.
fn alpha_of(tp: &TextureParams) -> Result<Alpha, Diagnostic> {
    match tp.float_texture_opt("alpha")? {
        None => Ok(Alpha::Opaque),
        Some(t) => match &*t {
            FloatTexture::Constant(a) if *a >= 1.0 => Ok(Alpha::Opaque),
            FloatTexture::Constant(a) => Ok(Alpha::Constant(*a)),
            _ => Ok(Alpha::Texture(t)),
        },
    }
}

/// The fixed-transformation view of an animated shape, and its motion:
/// its shapes are made in its own space and moved by an animated
/// primitive.
pub(super) fn at_origin(s: AnimatedShapeSceneEntity) -> (ShapeSceneEntity, AnimatedTransform) {
    let shape = ShapeSceneEntity {
        base: s.base,
        render_from_object: Transform::identity(),
        object_from_render: Transform::identity(),
        attributes: s.attributes,
    };
    (shape, s.render_from_object)
}

/// The scene's `displacementedgescale` option (pbrt-v4's
/// `--displacement-edge-scale`; default 1).
fn displacement_edge_scale(desc: &SceneDescription) -> Float {
    match desc.option("displacementedgescale") {
        Some(OptionValue::Float(v)) if *v > 0.0 => *v,
        _ => 1.0,
    }
}

/// Creates the primitives of one shape entity into `out`, with its area
/// lights appended to `lights`.
pub(super) fn create_primitives(
    cx: &ShapeContext,
    s: &ShapeSceneEntity,
    lights: &mut Vec<Light>,
    problems: &mut Problems,
    out: &mut Vec<Primitive>,
) {
    // Once the budget has run out, the error said where; shapes after it
    // would only repeat it.
    if cx.desc.budget.exhausted() {
        return;
    }
    let tp = TextureParams::new(reader(&s.base, &cx.desc.budget), cx.textures);
    // pbrt-v4 reads a displacement texture for `plymesh` alone.
    let displacement = if s.base.name == "plymesh" {
        match tp.float_texture_opt("displacement") {
            Ok(t) => t,
            Err(e) => {
                problems.errors.push(e);
                problems.warnings.extend(tp.take_warnings());
                return;
            }
        }
    } else {
        None
    };
    let eval = |p: Point3f, uv: Point2f| match &displacement {
        // pbrt-v4 evaluates it at the object-space vertex and its uv.
        Some(t) => t.evaluate(&TextureEvalContext {
            p,
            uv,
            ..TextureEvalContext::default()
        }),
        None => 0.0,
    };
    let displace = Displacement {
        eval: &eval,
        edge_scale: displacement_edge_scale(cx.desc),
    };
    // Meshes written in the scene copy their parameters' arrays.
    let copied = s.base.params.memory_bytes() as u64;
    if let Err(e) = tp.charge(copied, "this shape's data") {
        problems.errors.push(e);
        problems.warnings.extend(tp.take_warnings());
        return;
    }
    let shapes = create_shape_set(
        &s.base.name,
        &tp,
        &s.render_from_object,
        s.attributes.reverse_orientation,
        displacement.as_ref().map(|_| &displace),
    );
    let Some(shapes) = problems.keep_going(&tp, shapes) else {
        return;
    };
    let Some(alpha) = problems.keep_going(&tp, alpha_of(&tp)) else {
        return;
    };
    let material = match &s.attributes.material {
        MaterialRef::Named(n) if n.is_empty() || n == "none" || n == "interface" => None,
        MaterialRef::Index(i) => Some(*i as u32),
        MaterialRef::Named(n) => match cx.named_material_ids.get(n) {
            Some(&id) => Some(id),
            None => {
                problems.errors.push(Diagnostic::error(
                    s.base.loc.clone(),
                    format!("material {:?} is not defined", s.attributes.material),
                ));
                problems.warnings.extend(tp.take_warnings());
                return;
            }
        },
    };
    // An `interface` material, named or not, is no material: rays pass.
    let material = material.filter(|&m| {
        !cx.materials
            .materials()
            .get(m as usize)
            .is_some_and(|m| m.is_interface())
    });
    let Some(media) = medium_interface(cx, s, problems) else {
        problems.warnings.extend(tp.take_warnings());
        return;
    };
    let area_light = s.attributes.light_index.map(|li| &cx.desc.area_lights[li]);
    let area = match (area_light, material) {
        (Some(al), Some(_)) => match ParamReader::new(&al.params, &al.loc, al.color_space) {
            Ok(r) => Some((al, r)),
            Err(e) => {
                problems.errors.push(e);
                None
            }
        },
        (Some(al), None) => {
            problems.warnings.push(Diagnostic::warning(
                al.loc.clone(),
                "ignoring the area light of a shape with an interface material",
            ));
            None
        }
        _ => None,
    };
    // The primitives, before a mesh with an area light is cut into a shape
    // (with a light) per triangle and before the accelerator is built.
    let triangles = shapes.mesh.as_ref().map_or(0, |m| m.n_triangles());
    let light = if area.is_some() {
        std::mem::size_of::<Light>()
    } else {
        0
    };
    let per_triangle = ACCEL_BYTES_PER_PRIMITIVE
        + if area.is_some() {
            std::mem::size_of::<Shape>() + std::mem::size_of::<Primitive>() + light
        } else {
            0
        };
    let per_shape =
        ACCEL_BYTES_PER_PRIMITIVE + SHAPE_BYTES + std::mem::size_of::<Primitive>() + light;
    let bytes = (triangles as u64)
        .saturating_mul(per_triangle as u64)
        .saturating_add((shapes.shapes.len() as u64).saturating_mul(per_shape as u64));
    if let Err(e) = tp.charge(bytes, "this shape's primitives") {
        problems.errors.push(e);
        problems.warnings.extend(tp.take_warnings());
        return;
    }
    let alpha_tex = match &alpha {
        Alpha::Texture(t) => Some(t.clone()),
        Alpha::Constant(a) => Some(Arc::new(FloatTexture::Constant(*a))),
        Alpha::Opaque => None,
    };
    // A mesh without an area light is one primitive (the aggregate gives
    // its triangles entries); with one, each triangle is a primitive with
    // a light of its own.
    let medium_interface = media.is_transition().then_some(media);
    let shapes = match (shapes.mesh, &area) {
        (Some(mesh), None) => {
            out.push(Primitive::Mesh(MeshPrimitive {
                mesh,
                material,
                medium_interface,
                alpha: alpha.clone(),
            }));
            shapes.shapes
        }
        (mesh, _) => crate::shape::create::ShapeSet {
            mesh,
            shapes: shapes.shapes,
        }
        .into_shapes(),
    };
    for shape in shapes {
        let area_light = area.as_ref().and_then(|(al, r)| {
            let light = create_area_light(
                &al.name,
                r,
                &s.render_from_object,
                &shape,
                alpha_tex.clone(),
                media.inside,
                media.outside,
            );
            match light {
                Ok(light) => {
                    lights.push(light);
                    Some((lights.len() - 1) as u32)
                }
                Err(e) => {
                    problems.errors.push(e);
                    None
                }
            }
        });
        out.push(Primitive::Geometric(GeometricPrimitive {
            shape,
            material,
            area_light,
            // Kept only where it changes the medium (pbrt-v4
            // `SetIntersectionProperties`): elsewhere rays keep theirs.
            medium_interface,
            alpha: alpha.clone(),
        }));
    }
    // One `AreaLightSource` serves every shape of the entity: its unused
    // parameters are reported once.
    if let Some((_, r)) = area {
        problems.warnings.extend(r.finish());
    }
    problems.warnings.extend(tp.finish());
}

/// The media inside and outside a shape entity, by their names (an
/// error for a name no `MakeNamedMedium` defined).
fn medium_interface(
    cx: &ShapeContext,
    s: &ShapeSceneEntity,
    problems: &mut Problems,
) -> Option<MediumInterface> {
    let find = |name: &str| -> Result<Option<u32>, Diagnostic> {
        if name.is_empty() {
            return Ok(None);
        }
        cx.medium_ids.get(name).copied().map(Some).ok_or_else(|| {
            Diagnostic::error(
                s.base.loc.clone(),
                format!("\"{name}\": medium not defined"),
            )
        })
    };
    match (
        find(&s.attributes.inside_medium),
        find(&s.attributes.outside_medium),
    ) {
        (Ok(inside), Ok(outside)) => Some(MediumInterface { inside, outside }),
        (Err(e), _) | (_, Err(e)) => {
            problems.errors.push(e);
            None
        }
    }
}

/// Every shape of a scene, in directive order (instance definitions last),
/// and the diagnostics raised creating them: errors for shapes that could
/// not be built, warnings for skipped pieces and unused parameters.
#[derive(Debug, Default)]
pub struct SceneShapes {
    /// The shapes.
    pub shapes: Vec<Shape>,
    /// Errors and warnings, located at the directives.
    pub diagnostics: Vec<Diagnostic>,
}

/// Creates every shape in `desc` without materials or lights (for tools
/// and tests that look at geometry alone). Animated shapes are created at
/// their start transformation.
pub fn create_scene_shapes(desc: &SceneDescription) -> SceneShapes {
    let mut out = SceneShapes::default();
    let mut add = |base: &SceneEntity, xf: &Transform, ro: bool| {
        let r = reader(base, &desc.budget);
        match create_shapes(&base.name, &r, xf, ro, None) {
            Ok(shapes) => out.shapes.extend(shapes),
            Err(e) => out.diagnostics.push(e),
        }
        out.diagnostics.extend(r.take_warnings());
    };
    let fixed = desc
        .shapes
        .iter()
        .chain(desc.instance_definitions.iter().flat_map(|d| &d.shapes));
    let animated = desc.animated_shapes.iter().chain(
        desc.instance_definitions
            .iter()
            .flat_map(|d| &d.animated_shapes),
    );
    for s in fixed {
        add(
            &s.base,
            &s.render_from_object,
            s.attributes.reverse_orientation,
        );
    }
    for s in animated {
        add(
            &s.base,
            &s.render_from_object.start_transform(),
            s.attributes.reverse_orientation,
        );
    }
    out
}
