//! Scene construction: from parser directives to a plain description of the
//! scene (book section C.2; pbrt-v4 `scene.h`/`scene.cpp`,
//! `BasicSceneBuilder` and the `*SceneEntity` structures).
//!
//! [`SceneBuilder`] implements the parser's `ParserTarget`; [`build_scene`]
//! and [`build_scene_from_str`] run the parser with one and return the
//! resulting [`SceneDescription`] with every warning, or every error and
//! warning when the scene is invalid.

pub mod assemble;
pub mod builder;
pub mod entities;
mod materials;
pub mod names;
pub mod options;
pub mod shapes;
mod state;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use rpbrt_parser::{Diagnostics, ParseOptions, Parser};

use crate::camera::RenderingCoordinateSystem;

pub use builder::SceneBuilder;
pub use entities::*;
pub use names::EntityKind;

/// Settings for [`build_scene`].
#[derive(Clone, Debug, Default)]
pub struct BuildOptions {
    /// The rendering coordinate system, unless the scene sets
    /// `Option "rendercoordsys"` (pbrt-v4's `--render-coord-sys`).
    pub render_coord_sys: RenderingCoordinateSystem,
    /// Parser limits.
    pub parse: ParseOptions,
}

fn finish(
    builder: SceneBuilder,
    result: Result<Diagnostics, Diagnostics>,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    match result {
        Ok(diags) => {
            let mut scene = builder.finish();
            scene.diagnostics = diags.items.clone();
            Ok((scene, diags))
        }
        Err(diags) => Err(diags),
    }
}

/// Parses the scene files in order and builds their description.
///
/// `Ok` carries the description and the warnings; `Err` carries every
/// error and warning when at least one error was reported.
pub fn build_scene(
    paths: &[PathBuf],
    options: &BuildOptions,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    let mut builder = SceneBuilder::new(options.render_coord_sys);
    let result = Parser::new(options.parse.clone()).parse_files(paths, &mut builder);
    finish(builder, result)
}

/// Builds the description of scene text held in memory, reported as file
/// `<string>`; `Include` paths are resolved against the current directory.
pub fn build_scene_from_str(
    text: &str,
    options: &BuildOptions,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    let mut builder = SceneBuilder::new(options.render_coord_sys);
    let result = Parser::new(options.parse.clone()).parse_bytes(
        "<string>",
        Arc::from(text.as_bytes()),
        Path::new("."),
        &mut builder,
    );
    finish(builder, result)
}

/// Builds the description of scene bytes held in memory as if they were
/// the file `name` in directory `dir` (against which `Include`, `Import`
/// and file parameters resolve).
pub fn build_scene_from_bytes(
    name: &str,
    bytes: &[u8],
    dir: &Path,
    options: &BuildOptions,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    let mut builder = SceneBuilder::new(options.render_coord_sys);
    let result =
        Parser::new(options.parse.clone()).parse_bytes(name, Arc::from(bytes), dir, &mut builder);
    finish(builder, result)
}
