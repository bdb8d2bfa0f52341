//! Turning the shape entities of a scene description into [`Shape`]s
//! (pbrt-v4 `BasicScene::CreateAggregate`'s shape half): every `Shape`
//! directive, inside object definitions too, with its located errors and
//! warnings.

use super::entities::{SceneDescription, SceneEntity};
use crate::shape::create::{create_shapes, CreatedShapes};
use crate::shape::Shape;
use rpbrt_geometry::transform::Transform;
use rpbrt_parser::Diagnostic;
use std::path::Path;

/// Shape parameters read by later stages (primitives and area lights), so
/// they are not reported as unused when the shapes are created.
pub const LATER_SHAPE_PARAMS: &[&str] = &["alpha", "emissionfilename"];

/// Creates the shapes of one entity; file names resolve against the
/// directory of the scene file the directive is in.
pub fn create_entity_shapes(
    base: &SceneEntity,
    render_from_object: &Transform,
    reverse_orientation: bool,
) -> Result<CreatedShapes, Diagnostic> {
    let dir = Path::new(&*base.loc.file)
        .parent()
        .unwrap_or_else(|| Path::new("."));
    create_shapes(
        &base.name,
        &base.params,
        render_from_object,
        reverse_orientation,
        dir,
        &base.loc,
    )
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

/// Creates every shape in `desc`. Animated shapes are created at their
/// start transformation (motion is the primitives' business).
pub fn create_scene_shapes(desc: &SceneDescription) -> SceneShapes {
    let mut out = SceneShapes::default();
    let mut add = |base: &SceneEntity, xf: &Transform, ro: bool| {
        match create_entity_shapes(base, xf, ro) {
            Ok(c) => {
                out.shapes.extend(c.shapes);
                out.diagnostics.extend(c.warnings);
            }
            Err(e) => out.diagnostics.push(e),
        }
        out.diagnostics
            .extend(base.params.report_unused().into_iter().filter(|d| {
                !LATER_SHAPE_PARAMS
                    .iter()
                    .any(|p| d.message.contains(&format!("\"{p}\"")))
            }));
    };
    for s in &desc.shapes {
        add(
            &s.base,
            &s.render_from_object,
            s.attributes.reverse_orientation,
        );
    }
    for s in &desc.animated_shapes {
        add(
            &s.base,
            &s.render_from_object.start_transform,
            s.attributes.reverse_orientation,
        );
    }
    for def in &desc.instance_definitions {
        for s in &def.shapes {
            add(
                &s.base,
                &s.render_from_object,
                s.attributes.reverse_orientation,
            );
        }
        for s in &def.animated_shapes {
            add(
                &s.base,
                &s.render_from_object.start_transform,
                s.attributes.reverse_orientation,
            );
        }
    }
    out
}
