//! Medium creation (pbrt-v4 `Medium::Create` and each medium's `Create` in
//! `media.cpp`): a `MakeNamedMedium` directive's type and parameters turned
//! into a [`Medium`], with located errors for values no medium can have.

use super::{HomogeneousMedium, Medium};
use crate::material::data::get_medium_scattering_properties;
use crate::params::{unknown_type, ParamReader};
use crate::spectrum::{spectrum_to_photometric, DenselySampledSpectrum, Spectrum, SpectrumType};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_parser::Diagnostic;

/// The medium types `MakeNamedMedium` accepts, sorted.
pub const MEDIUM_NAMES: &[&str] = &["cloud", "homogeneous", "nanovdb", "rgbgrid", "uniformgrid"];

/// Creates the medium of a `MakeNamedMedium` directive of type `name`;
/// `render_from_medium` is the transformation in effect there.
pub fn create_medium(
    name: &str,
    mp: &ParamReader,
    render_from_medium: &Transform,
) -> Result<Medium, Diagnostic> {
    let _ = render_from_medium;
    match name {
        "homogeneous" => create_homogeneous(mp).map(Medium::Homogeneous),
        "uniformgrid" | "rgbgrid" | "cloud" | "nanovdb" => Err(Diagnostic::error(
            mp.loc().clone(),
            format!("the \"{name}\" medium is not supported yet"),
        )),
        _ => Err(unknown_type("medium", name, MEDIUM_NAMES, mp.loc())),
    }
}

/// pbrt-v4 `HomogeneousMedium::Create`.
fn create_homogeneous(mp: &ParamReader) -> Result<HomogeneousMedium, Diagnostic> {
    let mut sig_a = None;
    let mut sig_s = None;
    if let Some(preset) = mp.string_opt("preset")? {
        if !preset.is_empty() {
            match get_medium_scattering_properties(&preset) {
                Some((a, s)) => {
                    sig_a = Some(a);
                    sig_s = Some(s);
                }
                None => mp.warn_at("preset", format!("material preset \"{preset}\" not found")),
            }
        }
    }
    let sig_a = match sig_a {
        Some(s) => s,
        None => coefficient(mp, "sigma_a")?,
    };
    let sig_s = match sig_s {
        Some(s) => s,
        None => coefficient(mp, "sigma_s")?,
    };
    let (le, le_scale) = emission(mp)?;
    let scale = non_negative(mp, "scale", 1.0)?;
    let g = phase_asymmetry(mp)?;
    Ok(HomogeneousMedium::new(&sig_a, &sig_s, scale, &le, le_scale, g))
}

/// An absorption or scattering spectrum (default 1), checked to be finite
/// and non-negative at every wavelength.
pub(super) fn coefficient(mp: &ParamReader, name: &str) -> Result<Spectrum, Diagnostic> {
    let Some(s) = mp.spectrum(name, SpectrumType::Unbounded)? else {
        return Ok(Spectrum::constant(1.0));
    };
    let dense = DenselySampledSpectrum::new(&s);
    if let Some(v) = dense.values().iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(mp.error_at(
            name,
            format!("\"{name}\" must be finite and non-negative, got a value of {v}"),
        ));
    }
    Ok(s)
}

/// `"Le"` and `"Lescale"`: the emitted spectrum (zero when absent or
/// black) and its scale, divided by the spectrum's photometric value as
/// pbrt-v4 does for media.
pub(super) fn emission(mp: &ParamReader) -> Result<(Spectrum, Float), Diagnostic> {
    let le = mp.spectrum("Le", SpectrumType::Illuminant)?;
    let mut scale = mp.float("Lescale", 1.0)?;
    if !scale.is_finite() {
        return Err(mp.error_at("Lescale", "\"Lescale\" must be finite"));
    }
    match le {
        Some(le) if le.max_value() != 0.0 => {
            let dense = DenselySampledSpectrum::new(&le);
            if dense.values().iter().any(|v| !v.is_finite()) {
                return Err(mp.error_at("Le", "\"Le\" must be finite"));
            }
            scale /= spectrum_to_photometric(&le);
            Ok((le, scale))
        }
        _ => Ok((Spectrum::constant(0.0), scale)),
    }
}

/// A float parameter that must be finite and non-negative.
pub(super) fn non_negative(mp: &ParamReader, name: &str, default: Float) -> Result<Float, Diagnostic> {
    let v = mp.float(name, default)?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(mp.error_at(
            name,
            format!("\"{name}\" must be finite and non-negative, got {v}"),
        ));
    }
    Ok(v)
}

/// `"g"`, the Henyey–Greenstein asymmetry: finite (values beyond ±0.99
/// are clamped when used, as in pbrt-v4).
pub(super) fn phase_asymmetry(mp: &ParamReader) -> Result<Float, Diagnostic> {
    let g = mp.float("g", 0.0)?;
    if !g.is_finite() {
        return Err(mp.error_at("g", "\"g\" must be finite"));
    }
    if !(-1.0..=1.0).contains(&g) {
        mp.warn_at("g", format!("\"g\" = {g} is outside [-1, 1]; using {}", g.clamp(-0.99, 0.99)));
    }
    Ok(g)
}
