//! Medium creation (pbrt-v4 `Medium::Create` and each medium's `Create` in
//! `media.cpp`): a `MakeNamedMedium` directive's type and parameters turned
//! into a [`Medium`], with located errors for values no medium can have.
//! The grid media's own creation lives with them; the parameter checks
//! they share are here.

use super::measured::get_medium_scattering_properties;
use super::nanovdb::{
    grid_bytes, read_float_grid, require_float_grid, FloatGrid, GridClass, NanoVdbError,
};
use super::{
    CloudMedium, GridMedium, HomogeneousMedium, Medium, NanoVdbMedium, NanoVdbTemperature,
    RgbGridMedium,
};
use crate::params::{unknown_type, ParamReader};
use crate::spectrum::{spectrum_to_photometric, DenselySampledSpectrum, Spectrum, SpectrumType};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::Point3f;
use rpbrt_geometry::Bounds3f;
use rpbrt_parser::Diagnostic;

/// The medium types `MakeNamedMedium` accepts, sorted.
pub const MEDIUM_NAMES: &[&str] = &["cloud", "homogeneous", "nanovdb", "rgbgrid", "uniformgrid"];

/// The most samples a grid may have (so that indices stay in `i32`).
pub const MAX_GRID_SAMPLES: u64 = i32::MAX as u64;

/// Creates the medium of a `MakeNamedMedium` directive of type `name`;
/// `render_from_medium` is the transformation in effect there.
pub fn create_medium(
    name: &str,
    mp: &ParamReader,
    render_from_medium: &Transform,
) -> Result<Medium, Diagnostic> {
    match name {
        "homogeneous" => create_homogeneous(mp).map(Medium::Homogeneous),
        "nanovdb" => create_nanovdb(mp, render_from_medium).map(|m| Medium::NanoVdb(Box::new(m))),
        "uniformgrid" => {
            GridMedium::create(mp, render_from_medium).map(|m| Medium::UniformGrid(Box::new(m)))
        }
        "rgbgrid" => {
            RgbGridMedium::create(mp, render_from_medium).map(|m| Medium::RgbGrid(Box::new(m)))
        }
        "cloud" => CloudMedium::create(mp, render_from_medium).map(|m| Medium::Cloud(Box::new(m))),
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
    Ok(HomogeneousMedium::new(
        &sig_a, &sig_s, scale, &le, le_scale, g,
    ))
}

/// An absorption or scattering spectrum (default 1), checked to be finite
/// and non-negative at every wavelength.
pub(super) fn coefficient(mp: &ParamReader, name: &str) -> Result<Spectrum, Diagnostic> {
    let Some(s) = mp.spectrum(name, SpectrumType::Unbounded)? else {
        return Ok(Spectrum::constant(1.0));
    };
    let dense = DenselySampledSpectrum::new(&s);
    if let Some(v) = dense
        .values()
        .iter()
        .find(|v| !(v.is_finite() && **v >= 0.0))
    {
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
    let le = le_spectrum(mp)?;
    let scale = mp.float("Lescale", 1.0)?;
    if !scale.is_finite() {
        return Err(mp.error_at("Lescale", "\"Lescale\" must be finite"));
    }
    Ok(match le {
        Some((le, norm)) => (le, scale * norm),
        None => (Spectrum::constant(0.0), scale),
    })
}

/// `"Le"` when given: the spectrum (zero when black) and the factor that
/// normalises it, one over its photometric value (one for black).
pub(super) fn le_spectrum(mp: &ParamReader) -> Result<Option<(Spectrum, Float)>, Diagnostic> {
    let Some(le) = mp.spectrum("Le", SpectrumType::Illuminant)? else {
        return Ok(None);
    };
    let dense = DenselySampledSpectrum::new(&le);
    if dense.values().iter().any(|v| !v.is_finite()) {
        return Err(mp.error_at("Le", "\"Le\" must be finite"));
    }
    if le.max_value() == 0.0 {
        return Ok(Some((Spectrum::constant(0.0), 1.0)));
    }
    let norm = 1.0 / spectrum_to_photometric(&le);
    if !norm.is_finite() {
        return Err(mp.error_at("Le", "\"Le\" has no visible emission to normalise it by"));
    }
    Ok(Some((le, norm)))
}

/// `"nx"`, `"ny"`, `"nz"` (default 1 each) and their product, checked to
/// be positive and at most [`MAX_GRID_SAMPLES`] before anything is
/// allocated for the grid.
pub(super) fn grid_resolution(mp: &ParamReader) -> Result<(i32, i32, i32, u64), Diagnostic> {
    let mut n = [0i32; 3];
    for (i, name) in ["nx", "ny", "nz"].into_iter().enumerate() {
        let v = mp.int(name, 1)?;
        if v <= 0 {
            return Err(mp.error_at(name, format!("\"{name}\" must be positive, got {v}")));
        }
        n[i] = v;
    }
    let total = n.iter().fold(1u64, |acc, &v| acc.saturating_mul(v as u64));
    if total > MAX_GRID_SAMPLES {
        let at = if mp.has("nz") {
            "nz"
        } else if mp.has("ny") {
            "ny"
        } else {
            "nx"
        };
        return Err(mp.error_at(
            at,
            format!(
                "grid resolution {} x {} x {} is too large (more than {MAX_GRID_SAMPLES} samples)",
                n[0], n[1], n[2]
            ),
        ));
    }
    Ok((n[0], n[1], n[2], total))
}

/// Checks that every value of float array `name` is finite and
/// non-negative.
pub(super) fn check_values(
    mp: &ParamReader,
    name: &str,
    values: &[Float],
) -> Result<(), Diagnostic> {
    if let Some((i, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
    {
        return Err(mp.error_at(
            name,
            format!("\"{name}\" values must be finite and non-negative; value {i} is {v}"),
        ));
    }
    Ok(())
}

/// `"p0"` and `"p1"` (default the unit cube): the medium's box, checked to
/// be finite, with `p0` below `p1` on every axis.
pub(super) fn grid_bounds(mp: &ParamReader) -> Result<Bounds3f, Diagnostic> {
    let p0 = mp.point3("p0", [0.0; 3])?;
    let p1 = mp.point3("p1", [1.0; 3])?;
    for (name, p) in [("p0", p0), ("p1", p1)] {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(mp.error_at(
                name,
                format!(
                    "\"{name}\" must be finite, got ({}, {}, {})",
                    p[0], p[1], p[2]
                ),
            ));
        }
    }
    let at = if mp.has("p1") { "p1" } else { "p0" };
    if (0..3).any(|i| p0[i] == p1[i]) {
        return Err(mp.error_at(
            at,
            format!(
                "grid with zero-size bounds: p0 = ({}, {}, {}), p1 = ({}, {}, {})",
                p0[0], p0[1], p0[2], p1[0], p1[1], p1[2]
            ),
        ));
    }
    if (0..3).any(|i| p0[i] > p1[i]) {
        return Err(mp.error_at(
            at,
            format!(
                "grid with inverted bounds: p0 = ({}, {}, {}) must be below p1 = ({}, {}, {}) on every axis",
                p0[0], p0[1], p0[2], p1[0], p1[1], p1[2]
            ),
        ));
    }
    Ok(Bounds3f::new(
        Point3f::new(p0[0], p0[1], p0[2]),
        Point3f::new(p1[0], p1[1], p1[2]),
    ))
}

/// A float parameter that must be finite and non-negative.
pub(super) fn non_negative(
    mp: &ParamReader,
    name: &str,
    default: Float,
) -> Result<Float, Diagnostic> {
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
        mp.warn_at(
            "g",
            format!(
                "\"g\" = {g} is outside [-1, 1]; using {}",
                g.clamp(-0.99, 0.99)
            ),
        );
    }
    Ok(g)
}

/// pbrt-v4 `NanoVDBMedium::Create`: the density grid (`"gridname"`,
/// default "density") and optional temperature grid (`"temperaturename"`)
/// of a `.nvdb` file, with their emission and scattering parameters.
fn create_nanovdb(
    mp: &ParamReader,
    render_from_medium: &Transform,
) -> Result<NanoVdbMedium, Diagnostic> {
    let Some(path) = mp.path("filename")? else {
        return Err(mp.error("must supply \"filename\" to the \"nanovdb\" medium"));
    };
    let file_error = |e: NanoVdbError| mp.error_at("filename", format!("{}: {e}", path.display()));
    let grid_name = mp.string("gridname", "density")?;
    let temperature_name = mp.string("temperaturename", "temperature")?;
    // The grids as the file stores them, and the tables made of them, before
    // they are inflated.
    for name in [&grid_name, &temperature_name] {
        if let Some(bytes) = grid_bytes(&path, name).map_err(file_error)? {
            mp.charge(bytes.saturating_mul(2), &format!("the grid \"{name}\""))?;
        }
    }
    let density = require_float_grid(&path, &grid_name).map_err(file_error)?;
    check_vdb_grid(mp, &path, &density)?;
    let temperature_grid = read_float_grid(&path, &temperature_name).map_err(file_error)?;
    let le_scale = mp.float("Lescale", 1.0)?;
    let cutoff = mp.float("temperaturecutoff", 0.0)?;
    let offset = mp.float("temperatureoffset", cutoff)?;
    let scale_t = mp.float("temperaturescale", 1.0)?;
    for (name, v) in [
        ("Lescale", le_scale),
        ("temperatureoffset", offset),
        ("temperaturescale", scale_t),
    ] {
        if !v.is_finite() {
            return Err(mp.error_at(name, format!("\"{name}\" must be finite")));
        }
    }
    let temperature = match temperature_grid {
        Some(grid) => {
            check_vdb_grid(mp, &path, &grid)?;
            Some(NanoVdbTemperature {
                grid,
                offset,
                scale: scale_t,
                le_scale,
            })
        }
        None => None,
    };
    let g = phase_asymmetry(mp)?;
    let sigma_a = coefficient(mp, "sigma_a")?;
    let sigma_s = coefficient(mp, "sigma_s")?;
    let scale = non_negative(mp, "scale", 1.0)?;
    Ok(NanoVdbMedium::new(
        *render_from_medium,
        &sigma_a,
        &sigma_s,
        scale,
        g,
        density,
        temperature,
    ))
}

/// Refuses grids a medium cannot use: level sets and other non-fog
/// classes (as pbrt-v4), negative or non-finite values, empty bounds.
fn check_vdb_grid(
    mp: &ParamReader,
    path: &std::path::Path,
    grid: &FloatGrid,
) -> Result<(), Diagnostic> {
    let err = |m: String| {
        Err(mp.error_at(
            "filename",
            format!("{}: grid \"{}\" {m}", path.display(), grid.name()),
        ))
    };
    match grid.grid_class() {
        GridClass::FogVolume | GridClass::Unknown => {}
        c => return err(format!("isn't a FogVolume grid (its class is {c:?})")),
    }
    let (lo, hi) = grid.min_max();
    if !(lo.is_finite() && hi.is_finite()) || lo < 0.0 {
        return err(format!(
            "has values in [{lo}, {hi}]; a medium needs finite, non-negative ones"
        ));
    }
    let (wlo, whi) = grid.world_bbox();
    if (0..3).any(|a| !(whi[a] > wlo[a]) || !wlo[a].is_finite() || !whi[a].is_finite()) {
        return err(format!("has zero-size bounds ({wlo:?} to {whi:?})"));
    }
    Ok(())
}
