//! Integrator creation (pbrt-v4 `Integrator::Create` in
//! `cpu/integrators.cpp`): an `Integrator` directive's name and parameters
//! turned into an [`Integrator`].

use super::{
    AmbientOcclusionIntegrator, Integrator, PathIntegrator, RandomWalkIntegrator,
    SimplePathIntegrator, SimpleVolPathIntegrator, SppmIntegrator, VolPathIntegrator,
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
/// it needs is created by the caller (it needs the lights). `options_seed`
/// is the command line's `--seed` (0 without it), the default of `sppm`'s
/// `seed` as pbrt-v4's `Options->seed`.
pub fn create_integrator(
    name: &str,
    ip: &ParamReader,
    options_seed: i32,
) -> Result<Integrator, Diagnostic> {
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
        "sppm" => {
            let photons_per_iteration = ip.int("photonsperiteration", -1)?;
            if photons_per_iteration == 0 || photons_per_iteration < -1 {
                return Err(ip.error_at(
                    "photonsperiteration",
                    format!("\"photonsperiteration\" must be positive (or -1 for one photon per pixel), got {photons_per_iteration}"),
                ));
            }
            let radius = ip.float("radius", 1.0)?;
            if radius.is_nan() || radius <= 0.0 || radius.is_infinite() {
                return Err(ip.error_at(
                    "radius",
                    format!("\"radius\" must be positive, got {radius}"),
                ));
            }
            Ok(Integrator::Sppm(SppmIntegrator {
                max_depth,
                photons_per_iteration,
                initial_radius: radius,
                seed: ip.int("seed", options_seed)?,
                color_space: ip.color_space().name.clone(),
            }))
        }
        "bdpt" | "lightpath" | "mlt" => Err(Diagnostic::error(
            loc.clone(),
            format!("the \"{name}\" integrator is not supported yet; rpbrt renders with \"path\", \"volpath\", \"simplevolpath\", \"simplepath\", \"ambientocclusion\", \"randomwalk\" and \"sppm\""),
        )),
        _ => Err(unknown_type("integrator", name, INTEGRATOR_NAMES, loc)),
    }
}
