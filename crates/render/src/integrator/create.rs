//! Integrator creation (pbrt-v4 `Integrator::Create` in
//! `cpu/integrators.cpp`): an `Integrator` directive's name and parameters
//! turned into an [`Integrator`].

use super::{
    AmbientOcclusionIntegrator, Integrator, PathIntegrator, RandomWalkIntegrator,
    SimplePathIntegrator, SimpleVolPathIntegrator, VolPathIntegrator,
};
use crate::params::{unknown_type, ParamReader};
use rpbrt_geometry::float::Float;
use rpbrt_parser::Diagnostic;

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
pub fn create_integrator(name: &str, ip: &ParamReader) -> Result<Integrator, Diagnostic> {
    let loc = ip.loc();
    let max_depth = ip.int("maxdepth", 5)?;
    if max_depth < 0 {
        return Err(ip.error_at(
            "maxdepth",
            format!("\"maxdepth\" must not be negative, got {max_depth}"),
        ));
    }
    match name {
        "path" => Ok(Integrator::Path(PathIntegrator {
            max_depth,
            light_sampler_name: ip.string("lightsampler", "bvh")?,
            regularize: ip.bool("regularize", false)?,
        })),
        "volpath" => Ok(Integrator::VolPath(VolPathIntegrator {
            max_depth,
            light_sampler_name: ip.string("lightsampler", "bvh")?,
            regularize: ip.bool("regularize", false)?,
        })),
        "simplevolpath" => Ok(Integrator::SimpleVolPath(SimpleVolPathIntegrator { max_depth })),
        "simplepath" => Ok(Integrator::SimplePath(SimplePathIntegrator {
            max_depth,
            sample_lights: ip.bool("samplelights", true)?,
            sample_bsdf: ip.bool("samplebsdf", true)?,
        })),
        "ambientocclusion" => {
            let max_distance = ip.float("maxdistance", Float::INFINITY)?;
            if !(max_distance > 0.0) {
                return Err(ip.error_at("maxdistance", "\"maxdistance\" must be positive"));
            }
            Ok(Integrator::AmbientOcclusion(AmbientOcclusionIntegrator { cos_sample: ip.bool("cossample", true)?, max_distance }))
        }
        "randomwalk" => Ok(Integrator::RandomWalk(RandomWalkIntegrator { max_depth })),
        "bdpt" | "lightpath" | "mlt" | "sppm" => Err(Diagnostic::error(
            loc.clone(),
            format!("the \"{name}\" integrator is not supported yet; rpbrt renders with \"path\", \"volpath\", \"simplevolpath\", \"simplepath\", \"ambientocclusion\" and \"randomwalk\""),
        )),
        _ => Err(unknown_type("integrator", name, INTEGRATOR_NAMES, loc)),
    }
}
