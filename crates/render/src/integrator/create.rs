//! Integrator creation (pbrt-v4 `Integrator::Create` in
//! `cpu/integrators.cpp`): an `Integrator` directive's name and parameters
//! turned into an [`Integrator`].

use super::function::{FunctionIntegrator, TestFunction};
use super::{
    AmbientOcclusionIntegrator, BdptIntegrator, Integrator, LightPathIntegrator, MltIntegrator,
    PathIntegrator, RandomWalkIntegrator, SimplePathIntegrator, SimpleVolPathIntegrator,
    SppmIntegrator, VolPathIntegrator, WhittedIntegrator,
};
use crate::params::{unknown_type, ParamReader};
use rpbrt_geometry::float::Float;
use rpbrt_parser::Diagnostic;

/// Integrator names rpbrt knows, and those it renders.
pub const INTEGRATOR_NAMES: &[&str] = &[
    "ambientocclusion",
    "bdpt",
    "function",
    "lightpath",
    "mlt",
    "path",
    "randomwalk",
    "simplepath",
    "simplevolpath",
    "sppm",
    "volpath",
    "whitted",
];

/// The command line's say in integrator creation.
#[derive(Clone, Debug, Default)]
pub struct IntegratorOptions {
    /// `--spp`: MLT's mutations per pixel, as in pbrt-v4.
    pub spp: Option<i32>,
    /// `--seed`.
    pub seed: Option<i32>,
    /// `--outfile`: the `function` integrator's default output file, as
    /// pbrt-v4's `Options->imageFile`.
    pub outfile: Option<String>,
}

/// Creates the integrator of an `Integrator` directive. The light sampler
/// it needs is created by the caller (it needs the lights).
pub fn create_integrator(
    name: &str,
    ip: &ParamReader,
    opts: &IntegratorOptions,
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
        "simplevolpath" => Ok(Integrator::SimpleVolPath(SimpleVolPathIntegrator {
            max_depth,
        })),
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
            Ok(Integrator::AmbientOcclusion(AmbientOcclusionIntegrator {
                cos_sample: ip.bool("cossample", true)?,
                max_distance,
            }))
        }
        "randomwalk" => Ok(Integrator::RandomWalk(RandomWalkIntegrator { max_depth })),
        "bdpt" => {
            let visualize_strategies = ip.bool("visualizestrategies", false)?;
            let visualize_weights = ip.bool("visualizeweights", false)?;
            let mut max_depth = max_depth;
            if (visualize_strategies || visualize_weights) && max_depth > 5 {
                ip.warn_at(
                    "maxdepth",
                    "visualizestrategies/visualizeweights was enabled, limiting maxdepth to 5",
                );
                max_depth = 5;
            }
            Ok(Integrator::Bdpt(BdptIntegrator {
                max_depth,
                regularize: ip.bool("regularize", false)?,
                visualize_strategies,
                visualize_weights,
            }))
        }
        "lightpath" => Ok(Integrator::LightPath(LightPathIntegrator { max_depth })),
        "mlt" => {
            let bootstrap_samples = ip.int("bootstrapsamples", 100_000)?;
            if bootstrap_samples <= 0 {
                return Err(ip.error_at(
                    "bootstrapsamples",
                    format!("\"bootstrapsamples\" must be positive, got {bootstrap_samples}"),
                ));
            }
            let chains = ip.int("chains", 1000)?;
            if chains <= 0 {
                return Err(ip.error_at(
                    "chains",
                    format!("\"chains\" must be positive, got {chains}"),
                ));
            }
            let mut mutations_per_pixel = ip.int("mutationsperpixel", 100)?;
            if mutations_per_pixel <= 0 {
                return Err(ip.error_at(
                    "mutationsperpixel",
                    format!("\"mutationsperpixel\" must be positive, got {mutations_per_pixel}"),
                ));
            }
            if let Some(spp) = opts.spp {
                mutations_per_pixel = spp;
            }
            let large_step_probability = ip.float("largestepprobability", 0.3)?;
            if !(0.0..=1.0).contains(&large_step_probability) {
                return Err(ip.error_at(
                    "largestepprobability",
                    format!(
                        "\"largestepprobability\" must be in [0, 1], got {large_step_probability}"
                    ),
                ));
            }
            let sigma = ip.float("sigma", 0.01)?;
            if !(sigma > 0.0 && sigma.is_finite()) {
                return Err(
                    ip.error_at("sigma", format!("\"sigma\" must be positive, got {sigma}"))
                );
            }
            Ok(Integrator::Mlt(MltIntegrator {
                max_depth,
                bootstrap_samples,
                chains,
                mutations_per_pixel,
                large_step_probability,
                sigma,
                regularize: ip.bool("regularize", false)?,
                seed: opts.seed.unwrap_or(0) as u64,
            }))
        }
        "function" => create_function(ip, opts),
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
                seed: ip.int("seed", opts.seed.unwrap_or(0))?,
                color_space: ip.color_space().name.clone(),
            }))
        }
        "whitted" => Ok(Integrator::Whitted(WhittedIntegrator { max_depth })),
        _ => Err(unknown_type("integrator", name, INTEGRATOR_NAMES, loc)),
    }
}

/// The `function` integrator (pbrt-v4 `FunctionIntegrator::Create`). The
/// sampler check (no `"sobol"`) is made where the sampler is known.
fn create_function(ip: &ParamReader, opts: &IntegratorOptions) -> Result<Integrator, Diagnostic> {
    let name = ip.string("function", "step")?;
    let Some(function) = TestFunction::from_name(&name) else {
        let known = TestFunction::NAMES.map(|n| format!("\"{n}\"")).join(", ");
        return Err(ip.error_at(
            "function",
            format!("\"{name}\": function for the \"function\" integrator unknown; expected one of {known}"),
        ));
    };
    let default_filename = match &opts.outfile {
        Some(f) => f.clone(),
        None => format!("{name}-mse.txt"),
    };
    let filename = ip.string("filename", &default_filename)?;
    let skip_bad = ip.bool("skipbad", true)?;
    let image_filename = ip.string("imagefilename", "")?;
    if !image_filename.is_empty() {
        // Refused here rather than after the render has started.
        let ext = std::path::Path::new(&image_filename)
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .unwrap_or_default();
        if !crate::film::IMAGE_EXTENSIONS.contains(&ext.as_str()) {
            return Err(ip.error_at(
                "imagefilename",
                format!(
                    "\"{image_filename}\": cannot write images with extension \"{ext}\" (supported: {})",
                    crate::film::IMAGE_EXTENSIONS.join(", ")
                ),
            ));
        }
    }
    Ok(Integrator::Function(FunctionIntegrator {
        function,
        filename,
        skip_bad,
        image_filename: (!image_filename.is_empty()).then_some(image_filename),
    }))
}
