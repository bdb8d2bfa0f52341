//! Integrator creation (pbrt-v4 `Integrator::Create` in
//! `cpu/integrators.cpp`): an `Integrator` directive's name and parameters
//! turned into an [`Integrator`].

use super::{
    AmbientOcclusionIntegrator, Integrator, PathIntegrator, RandomWalkIntegrator,
    SimplePathIntegrator,
};
use rpbrt_geometry::float::Float;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary};

/// Integrator names rpbrt knows, and those it renders.
pub const INTEGRATOR_NAMES: &[&str] = &[
    "ambientocclusion",
    "bdpt",
    "lightpath",
    "mlt",
    "path",
    "randomwalk",
    "simplepath",
    "simplevolpath",
    "sppm",
    "volpath",
];

/// Creates the integrator of an `Integrator` directive. The light sampler
/// it needs is created by the caller (it needs the lights).
pub fn create_integrator(
    name: &str,
    params: &ParameterDictionary,
    loc: &FileLoc,
    scene_has_media: bool,
) -> Result<Integrator, Diagnostic> {
    let perr = Diagnostic::from;
    let max_depth = params.get_one_int("maxdepth", 5).map_err(perr)?;
    if max_depth < 0 {
        return Err(Diagnostic::error(
            params
                .loc("maxdepth")
                .cloned()
                .unwrap_or_else(|| loc.clone()),
            format!("\"maxdepth\" must not be negative, got {max_depth}"),
        ));
    }
    match name {
        "path" | "volpath" => {
            if name == "volpath" && scene_has_media {
                return Err(Diagnostic::error(loc.clone(), "participating media are not supported yet: the \"volpath\" integrator renders only scenes without media"));
            }
            Ok(Integrator::Path(PathIntegrator {
                max_depth,
                light_sampler_name: params.get_one_string("lightsampler", "bvh").map_err(perr)?,
                regularize: params.get_one_bool("regularize", false).map_err(perr)?,
            }))
        }
        "simplepath" => Ok(Integrator::SimplePath(SimplePathIntegrator {
            max_depth,
            sample_lights: params.get_one_bool("samplelights", true).map_err(perr)?,
            sample_bsdf: params.get_one_bool("samplebsdf", true).map_err(perr)?,
        })),
        "ambientocclusion" => {
            let max_distance = params.get_one_float("maxdistance", Float::INFINITY).map_err(perr)?;
            if !(max_distance > 0.0) {
                return Err(Diagnostic::error(params.loc("maxdistance").cloned().unwrap_or_else(|| loc.clone()), "\"maxdistance\" must be positive"));
            }
            Ok(Integrator::AmbientOcclusion(AmbientOcclusionIntegrator { cos_sample: params.get_one_bool("cossample", true).map_err(perr)?, max_distance }))
        }
        "randomwalk" => Ok(Integrator::RandomWalk(RandomWalkIntegrator { max_depth })),
        "bdpt" | "lightpath" | "mlt" | "simplevolpath" | "sppm" => Err(Diagnostic::error(
            loc.clone(),
            format!("the \"{name}\" integrator is not supported yet; rpbrt renders with \"path\", \"volpath\" (without media), \"simplepath\", \"ambientocclusion\" and \"randomwalk\""),
        )),
        _ => Err(Diagnostic::error(loc.clone(), format!("unknown integrator \"{name}\"; known integrators: {}", INTEGRATOR_NAMES.join(", ")))),
    }
}
