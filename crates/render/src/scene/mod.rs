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
mod entity_list;
pub mod files;
pub mod instances;
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
pub use entity_list::EntityList;
pub use instances::InstanceList;
pub use names::EntityKind;

/// Settings for [`build_scene`]. The memory budget is the parser's
/// (`parse.budget`): the scene text, the description and, when the scene is
/// created, the render objects are all charged to it.
#[derive(Clone, Debug, Default)]
pub struct BuildOptions {
    /// The rendering coordinate system, unless the scene sets
    /// `Option "rendercoordsys"` (pbrt-v4's `--render-coord-sys`).
    pub render_coord_sys: RenderingCoordinateSystem,
    /// Parser limits.
    pub parse: ParseOptions,
    /// Leave out the check that every input file the scene names exists
    /// ([`files::missing_files`]); creation then reports a missing file
    /// when it opens it.
    pub skip_file_check: bool,
}

fn finish(
    builder: SceneBuilder,
    result: Result<Diagnostics, Diagnostics>,
    options: &BuildOptions,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    // Every missing input file is reported in this one run, beside any
    // errors of the parse (a missing Include among them).
    match result {
        Ok(mut diags) => {
            let mut scene = builder.finish();
            let missing = if options.skip_file_check {
                Vec::new()
            } else {
                files::missing_files(&scene)
            };
            if !missing.is_empty() {
                diags.items.extend(missing);
                return Err(diags);
            }
            scene.diagnostics = diags.items.clone();
            Ok((scene, diags))
        }
        Err(mut diags) => {
            if !options.skip_file_check {
                diags.items.extend(files::missing_files(&builder.finish()));
            }
            Err(diags)
        }
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
    let mut builder =
        SceneBuilder::new(options.render_coord_sys).with_budget(options.parse.budget.clone());
    let result = Parser::new(options.parse.clone()).parse_files(paths, &mut builder);
    finish(builder, result, options)
}

/// Builds the description of scene text held in memory, reported as file
/// `<string>`; `Include` paths are resolved against the current directory.
pub fn build_scene_from_str(
    text: &str,
    options: &BuildOptions,
) -> Result<(SceneDescription, Diagnostics), Diagnostics> {
    let mut builder =
        SceneBuilder::new(options.render_coord_sys).with_budget(options.parse.budget.clone());
    let result = Parser::new(options.parse.clone()).parse_bytes(
        "<string>",
        Arc::new(text.as_bytes().to_vec()),
        Path::new("."),
        &mut builder,
    );
    finish(builder, result, options)
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
    let mut builder =
        SceneBuilder::new(options.render_coord_sys).with_budget(options.parse.budget.clone());
    let result = Parser::new(options.parse.clone()).parse_bytes(
        name,
        Arc::new(bytes.to_vec()),
        dir,
        &mut builder,
    );
    finish(builder, result, options)
}
