//! Creating samplers from scene-file parameters (pbrt-v4
//! `Sampler::Create` and each sampler's `Create`): parameter names,
//! defaults and overrides as pbrt-v4, with located errors for bad values.

use rpbrt_geometry::tuple::Point2i;
use rpbrt_parser::Diagnostic;

use super::*;
use crate::params::{unknown_type, ParamReader};

/// The sampler types `Sampler` accepts, sorted.
pub const SAMPLER_NAMES: &[&str] = &[
    "halton",
    "independent",
    "paddedsobol",
    "pmj02bn",
    "sobol",
    "stratified",
    "zsobol",
];

/// Reads `pixelsamples` (default `default`), applying the command-line
/// override; counts ≤ 0 are errors.
fn pixel_samples(
    sp: &ParamReader,
    default: i32,
    spp_override: Option<i32>,
) -> Result<i32, Diagnostic> {
    let mut n = sp.int("pixelsamples", default)?;
    if n <= 0 {
        return Err(Diagnostic::error(
            sp.param_loc("pixelsamples"),
            format!("\"pixelsamples\" must be positive, not {n}"),
        ));
    }
    if let Some(o) = spp_override {
        if o <= 0 {
            return Err(sp.error(format!(
                "samples-per-pixel override must be positive, not {o}"
            )));
        }
        n = o;
    }
    Ok(n)
}

fn randomization(
    sp: &ParamReader,
    default: &str,
    sampler: &str,
) -> Result<RandomizeStrategy, Diagnostic> {
    let s = sp.string("randomization", default)?;
    let err = |msg: String| sp.error_at("randomization", msg);
    match s.as_str() {
        "none" => Ok(RandomizeStrategy::None),
        "permutedigits" => Ok(RandomizeStrategy::PermuteDigits),
        "fastowen" if sampler == "halton" => Err(err(
            "\"fastowen\" randomization is not supported by the halton sampler".into(),
        )),
        "fastowen" => Ok(RandomizeStrategy::FastOwen),
        "owen" => Ok(RandomizeStrategy::Owen),
        _ => Err(err(format!(
            "\"{s}\": unknown randomization strategy given to {sampler} sampler \
             (expected none, permutedigits, fastowen or owen)"
        ))),
    }
}

fn warn_not_pow2(n: i32, name: &str, sp: &ParamReader) {
    if n & (n - 1) != 0 {
        sp.warn(format!(
            "{name}: non power-of-two sample counts ({n}) are sub-optimal"
        ));
    }
}

/// Creates the sampler `name` ("zsobol", "sobol", "paddedsobol", "halton",
/// "pmj02bn", "independent", "stratified") for an image of
/// `full_resolution` from its parameters. `spp_override` and
/// `seed_override` are the command-line `--spp` and `--seed` (the seed
/// default for the `seed` parameter; pbrt's default 0). Warnings (such as
/// a non-power-of-two count for a Sobol' sampler) go to `sp`.
pub fn create_sampler(
    name: &str,
    sp: &ParamReader,
    full_resolution: Point2i,
    spp_override: Option<i32>,
    seed_override: Option<i32>,
) -> Result<Sampler, Diagnostic> {
    let loc = sp.loc();
    let options_seed = seed_override.unwrap_or(0);
    let sampler = match name {
        "zsobol" => {
            let n = pixel_samples(sp, 16, spp_override)?;
            let seed = sp.int("seed", options_seed)?;
            let r = randomization(sp, "fastowen", name)?;
            if n & (n - 1) != 0 {
                let used = 1 << (31 - (n as u32).leading_zeros());
                sp.warn(format!(
                    "zsobol: non power-of-two sample counts are sub-optimal; \
                     using {used} samples per pixel instead of {n}"
                ));
            }
            Sampler::ZSobol(ZSobolSampler::new(n, full_resolution, r, seed))
        }
        "sobol" => {
            let n = pixel_samples(sp, 16, spp_override)?;
            let r = randomization(sp, "fastowen", name)?;
            warn_not_pow2(n, name, sp);
            let res = full_resolution.x.max(full_resolution.y).max(1) as u64;
            let log2_scale = res.next_power_of_two().trailing_zeros();
            let log2_spp = (n as u64).next_power_of_two().trailing_zeros();
            if log2_scale > sobol::MAX_SOBOL_LOG2_SCALE
                || 2 * log2_scale + log2_spp > lowdiscrepancy::SOBOL_MATRIX_SIZE as u32
            {
                return Err(Diagnostic::error(
                    loc.clone(),
                    format!(
                        "sobol: image resolution {}x{} with {n} samples per pixel exceeds \
                         the Sobol' sequence's 2^52 samples",
                        full_resolution.x, full_resolution.y
                    ),
                ));
            }
            // pbrt-v4 randomises the global Sobol' sampler with the
            // command-line seed only.
            Sampler::Sobol(SobolSampler::new(n, full_resolution, r, options_seed))
        }
        "paddedsobol" => {
            let n = pixel_samples(sp, 16, spp_override)?;
            let seed = sp.int("seed", options_seed)?;
            let r = randomization(sp, "fastowen", name)?;
            warn_not_pow2(n, name, sp);
            Sampler::PaddedSobol(PaddedSobolSampler::new(n, r, seed))
        }
        "halton" => {
            let n = pixel_samples(sp, 16, spp_override)?;
            let seed = sp.int("seed", options_seed)?;
            let r = randomization(sp, "permutedigits", name)?;
            Sampler::Halton(HaltonSampler::new(n, full_resolution, r, seed))
        }
        "pmj02bn" => {
            let n = pixel_samples(sp, 16, spp_override)?;
            let seed = sp.int("seed", options_seed)?;
            let log2 = 31 - (n as u32).leading_zeros();
            if n & (n - 1) != 0 || log2 % 2 != 0 {
                sp.warn(
                    "pmj02bn: results are best with power-of-4 samples per pixel (1, 4, 16, 64, ...)",
                );
            }
            let s = Pmj02bnSampler::new(n, seed).map_err(|e| sp.error_at("pixelsamples", e))?;
            Sampler::Pmj02bn(s)
        }
        "independent" => {
            let n = pixel_samples(sp, 4, spp_override)?;
            let seed = sp.int("seed", options_seed)?;
            Sampler::Independent(IndependentSampler::new(n, seed))
        }
        "stratified" => {
            let jitter = sp.bool("jitter", true)?;
            let mut xs = sp.int("xsamples", 4)?;
            let mut ys = sp.int("ysamples", 4)?;
            for (v, pname) in [(xs, "xsamples"), (ys, "ysamples")] {
                if v <= 0 {
                    return Err(Diagnostic::error(
                        sp.param_loc(pname),
                        format!("\"{pname}\" must be positive, not {v}"),
                    ));
                }
            }
            if let Some(n) = spp_override {
                if n <= 0 {
                    return Err(Diagnostic::error(
                        loc.clone(),
                        format!("samples-per-pixel override must be positive, not {n}"),
                    ));
                }
                // The most square factorisation, as pbrt-v4.
                let mut div = (n as f64).sqrt() as i32;
                while n % div != 0 {
                    div -= 1;
                }
                xs = n / div;
                ys = n / xs;
            }
            // Samples per pixel are counted in an i32: a larger product
            // would wrap (65536² to 0 samples, an endless pixel loop;
            // 46341² to 1).
            let spp = i64::from(xs) * i64::from(ys);
            if spp > i64::from(i32::MAX) {
                return Err(sp.error_at(
                    "xsamples",
                    format!(
                        "stratified: \"xsamples\" × \"ysamples\" ({xs} × {ys} = {spp}) \
                         exceeds the {} samples per pixel a pixel can take",
                        i32::MAX
                    ),
                ));
            }
            let seed = sp.int("seed", options_seed)?;
            Sampler::Stratified(StratifiedSampler::new(xs, ys, jitter, seed))
        }
        _ => return Err(unknown_type("sampler", name, SAMPLER_NAMES, loc)),
    };
    Ok(sampler)
}
