//! pbrt-v3's colour `scale` on a light whose emission is a spectrum or a
//! blackbody. pbrt-v3 rendered in RGB: it turned the emission into RGB when
//! it read it (the spectrum's XYZ, then sRGB), and multiplied the scale's
//! RGB into that. pbrt-v4's `scale` is a float, and multiplying a spectrum
//! by an RGB has no spectral meaning, so the emission is given as pbrt-v3's
//! RGB, which the upgrade then multiplies by the scale: the light has
//! pbrt-v3's colour and brightness (an RGB emission keeps its brightness in
//! pbrt-v4, where a spectrum is normalised to unit luminance).

use std::path::Path;

use rpbrt_parser::{Diagnostic, FileLoc, ParsedParameter, SpectrumValue};

use crate::spectrum::{
    spectrum_from_param, spectrum_to_xyz, BlackbodySpectrum, PiecewiseLinearSpectrum,
    RgbColorSpace, Spectrum, SpectrumType,
};

/// The emission parameter a colour `scale` multiplies on light `name`.
fn emission_of(name: &str) -> Option<&'static str> {
    match name {
        "point" | "spot" | "goniometric" | "projection" => Some("I"),
        "distant" | "area" | "diffuse" | "infinite" | "exinfinite" | "infinitesample" => Some("L"),
        _ => None,
    }
}

/// Replaces the spectral or blackbody emission of a pbrt-v3 light with a
/// non-uniform colour `scale`, or of an `infinite` light with a `mapname`,
/// by the RGB pbrt-v3 made of it (see the module's note). Other lights are
/// left as they are.
pub(super) fn spectral_emission_as_rgb(
    name: &str,
    params: &mut [ParsedParameter],
    loc: &FileLoc,
) -> Result<(), Diagnostic> {
    let non_uniform_scale = params.iter().any(|p| {
        p.name == "scale"
            && matches!(&*p.ty, "rgb" | "color")
            && p.floats.len() == 3
            && !(p.floats[0] == p.floats[1] && p.floats[1] == p.floats[2])
    });
    // pbrt-v3 also multiplies an environment map by its `L`, which
    // rpbrt's renderer takes as an RGB.
    let map = matches!(name, "infinite" | "exinfinite" | "infinitesample")
        && params.iter().any(|p| p.name == "mapname");
    let Some(emission) = emission_of(name).filter(|_| non_uniform_scale || map) else {
        return Ok(());
    };
    let Some(p) = params
        .iter_mut()
        .rev()
        .find(|p| p.name == emission && matches!(&*p.ty, "spectrum" | "blackbody"))
    else {
        return Ok(());
    };
    let error = |message: String| Diagnostic::error(p.loc.clone(), message);
    let (spectrum, factor) = if p.ty == "blackbody" {
        // pbrt-v3's [T scale]: its blackbody peaks at 1, as pbrt-v4's does.
        match p.floats[..] {
            [t] | [t, _] if t > 0.0 => (
                Spectrum::Blackbody(BlackbodySpectrum::new(t)),
                p.floats.get(1).copied().unwrap_or(1.0),
            ),
            _ => {
                return Err(error(
                    "expected \"blackbody\" [ T ] or [ T scale ] with T > 0".into(),
                ))
            }
        }
    } else if p.strings.is_empty() {
        // Samples, extended with the end values as pbrt-v3 interpolates them.
        let s = PiecewiseLinearSpectrum::from_interleaved(&p.floats, false).map_err(error)?;
        (Spectrum::PiecewiseLinear(std::sync::Arc::new(s)), 1.0)
    } else {
        let dir = Path::new(&*loc.file).parent().unwrap_or(Path::new("."));
        let value = SpectrumValue::NameOrFile(p.strings[0].clone());
        let s = spectrum_from_param(&value, SpectrumType::Illuminant, RgbColorSpace::srgb(), dir)
            .map_err(error)?;
        (s, 1.0)
    };
    let rgb = RgbColorSpace::srgb().to_rgb(spectrum_to_xyz(&spectrum));
    // Colours outside sRGB's gamut lose their negative parts.
    let c = [rgb.r, rgb.g, rgb.b].map(|v| (v * factor).max(0.0));
    *p = ParsedParameter::with_floats("rgb", emission, p.loc.clone(), c.to_vec());
    Ok(())
}
