//! Creating the pixel filter from the `PixelFilter` directive's
//! parameters (pbrt-v4 `Filter::Create` and the filters' `Create`
//! functions), with pbrt-v4's defaults.

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::Vector2f;
use rpbrt_parser::Diagnostic;

use super::*;
use crate::params::{unknown_type, ParamReader};

/// The filter types `PixelFilter` accepts, sorted.
pub const FILTER_NAMES: &[&str] = &["box", "gaussian", "mitchell", "sinc", "triangle"];

fn positive(fp: &ParamReader, name: &str, default: Float) -> Result<Float, Diagnostic> {
    let v = fp.float(name, default)?;
    if !(v.is_finite() && v > 0.0) {
        return Err(fp.error_at(
            name,
            format!("\"{name}\" must be a positive number, not {v}"),
        ));
    }
    Ok(v)
}

fn finite(fp: &ParamReader, name: &str, default: Float) -> Result<Float, Diagnostic> {
    let v = fp.float(name, default)?;
    if !v.is_finite() {
        return Err(fp.error_at(name, format!("\"{name}\" must be finite")));
    }
    Ok(v)
}

/// Creates the filter `name` ("box", "gaussian", "mitchell", "sinc",
/// "triangle") from its parameters, with pbrt-v4's defaults.
pub fn create_filter(name: &str, fp: &ParamReader) -> Result<Filter, Diagnostic> {
    let radius = |d: Float| -> Result<Vector2f, Diagnostic> {
        Ok(Vector2f::new(
            positive(fp, "xradius", d)?,
            positive(fp, "yradius", d)?,
        ))
    };
    Ok(match name {
        "box" => Filter::Box(BoxFilter::new(radius(0.5)?)),
        "gaussian" => {
            let r = radius(1.5)?;
            Filter::Gaussian(GaussianFilter::new(r, positive(fp, "sigma", 0.5)?))
        }
        "mitchell" => {
            let r = radius(2.0)?;
            let b = finite(fp, "B", 1.0 / 3.0)?;
            let c = finite(fp, "C", 1.0 / 3.0)?;
            Filter::Mitchell(MitchellFilter::new(r, b, c))
        }
        "sinc" => {
            let r = radius(4.0)?;
            Filter::LanczosSinc(LanczosSincFilter::new(r, positive(fp, "tau", 3.0)?))
        }
        "triangle" => Filter::Triangle(TriangleFilter::new(radius(2.0)?)),
        _ => return Err(unknown_type("pixel filter", name, FILTER_NAMES, fp.loc())),
    })
}
