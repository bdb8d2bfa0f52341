//! Spectra from scene-file parameters and `.spd` files, following pbrt-v4's
//! `ParameterDictionary::GetOneSpectrum` and `PiecewiseLinearSpectrum::Read`.

use std::path::Path;
use std::sync::Arc;

use rpbrt_geometry::Float;
use rpbrt_parser::SpectrumValue;

use super::color::RGB;
use super::colorspace::RgbColorSpace;
use super::named::named_spectrum;
use super::spectra::{
    BlackbodySpectrum, PiecewiseLinearSpectrum, RgbAlbedoSpectrum, RgbIlluminantSpectrum,
    RgbUnboundedSpectrum, Spectrum,
};

/// What a spectrum parameter describes, which decides how RGB values turn
/// into spectra.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumType {
    /// A reflectance in `[0, 1]` (RGB components above 1 are an error).
    Albedo,
    /// Any non-negative quantity (scattering coefficients, IOR, ...).
    Unbounded,
    /// Emission: RGB is multiplied by the colour space's illuminant.
    Illuminant,
}

/// Parses `.spd` text: whitespace-separated `wavelength value` pairs with
/// `#` comments; wavelengths must strictly increase.
pub fn parse_spectrum_text(text: &str) -> Result<Spectrum, String> {
    let mut vals: Vec<Float> = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for tok in line.split(|c: char| c.is_whitespace() || c == ',') {
            if tok.is_empty() {
                continue;
            }
            let v: Float = tok
                .parse()
                .map_err(|_| format!("line {}: \"{}\" is not a number", line_no + 1, tok))?;
            vals.push(v);
        }
    }
    if vals.is_empty() {
        return Err("no values found".into());
    }
    if vals.len() % 2 != 0 {
        return Err(format!(
            "odd number of values ({}): expected wavelength/value pairs",
            vals.len()
        ));
    }
    let (lambda, v): (Vec<Float>, Vec<Float>) = vals.chunks_exact(2).map(|c| (c[0], c[1])).unzip();
    let s = PiecewiseLinearSpectrum::new(lambda, v)?;
    Ok(Spectrum::PiecewiseLinear(Arc::new(s)))
}

/// Reads a `.spd` spectrum file (see [`parse_spectrum_text`]).
pub fn read_spectrum_file(path: &Path) -> Result<Spectrum, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: unable to read spectrum file: {e}", path.display()))?;
    parse_spectrum_text(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The spectrum a parameter value describes: RGB through `cs` according to
/// `kind`, a normalised blackbody, inline samples, a named spectrum, or a
/// file relative to `base_dir`.
pub fn spectrum_from_param(
    value: &SpectrumValue,
    kind: SpectrumType,
    cs: &RgbColorSpace,
    base_dir: &Path,
) -> Result<Spectrum, String> {
    match value {
        SpectrumValue::Rgb(c) => {
            let rgb = RGB::new(c[0], c[1], c[2]);
            if rgb.min_component_value() < 0.0 {
                return Err(format!(
                    "RGB ({}, {}, {}) has a negative component",
                    c[0], c[1], c[2]
                ));
            }
            Ok(match kind {
                SpectrumType::Albedo => {
                    if rgb.max_component_value() > 1.0 {
                        return Err(format!(
                            "RGB albedo value ({}, {}, {}) has a component > 1",
                            c[0], c[1], c[2]
                        ));
                    }
                    Spectrum::RgbAlbedo(RgbAlbedoSpectrum::new(cs, rgb))
                }
                SpectrumType::Unbounded => {
                    Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, rgb))
                }
                SpectrumType::Illuminant => {
                    Spectrum::RgbIlluminant(RgbIlluminantSpectrum::new(cs, rgb))
                }
            })
        }
        SpectrumValue::Blackbody(t) => {
            if !(*t > 0.0) {
                return Err(format!("blackbody temperature {t} is not positive"));
            }
            Ok(Spectrum::Blackbody(BlackbodySpectrum::new(*t)))
        }
        SpectrumValue::Sampled(pairs) => {
            let (lambda, v): (Vec<Float>, Vec<Float>) = pairs.iter().copied().unzip();
            let s = PiecewiseLinearSpectrum::new(lambda, v)
                .map_err(|e| format!("spectrum description invalid: {e}"))?;
            Ok(Spectrum::PiecewiseLinear(Arc::new(s)))
        }
        SpectrumValue::NameOrFile(name) => {
            if let Some(s) = named_spectrum(name) {
                return Ok(s);
            }
            let path = base_dir.join(name);
            if !path.exists() {
                return Err(format!(
                    "\"{name}\" is not a named spectrum and {} does not exist",
                    path.display()
                ));
            }
            read_spectrum_file(&path)
        }
    }
}
