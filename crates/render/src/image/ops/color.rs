//! Per-pixel colour operations: white balancing an image's R, G, B in its
//! colour space (pbrt-v4 `imgtool whitebalance`, von Kries adaptation in
//! Bradford LMS) and rescaling the slopes of a normal map (pbrt-v4
//! `imgtool scalenormalmap`).

use std::sync::Arc;

use crate::film::{daylight_illuminant, white_balance};
use crate::image::{Image, ImageError, ImageMetadata};
use crate::spectrum::{named_spectrum, spectrum_to_xyz, RgbColorSpace, Spectrum};

/// The chromaticity (xy) of pbrt-v4's standard illuminant `name` (the
/// suffix of a `stdillum-` spectrum: D65, D50, A, F1, ..., F12).
pub fn illuminant_white(name: &str) -> Option<[f32; 2]> {
    let s = named_spectrum(&format!("stdillum-{name}"))?;
    Some(spectrum_to_xyz(&s).xy())
}

/// The chromaticity of CIE daylight (a blackbody below 4000 K) at
/// `kelvin` (pbrt-v4's `Spectra::D`).
pub fn temperature_white(kelvin: f32) -> [f32; 2] {
    let s = Spectrum::DenselySampled(Arc::new(daylight_illuminant(kelvin)));
    spectrum_to_xyz(&s).xy()
}

/// `image` with its R, G, B white balanced from the white `src_white`
/// (xy) to its colour space's white (pbrt-v4 `whitebalance`): RGB to XYZ,
/// Bradford von Kries adaptation, back to RGB. Other channels are kept.
pub fn white_balance_image(
    image: &Image,
    metadata: &ImageMetadata,
    src_white: [f32; 2],
) -> Result<Image, ImageError> {
    let rgb = image
        .get_channel_desc(&["R", "G", "B"])
        .ok_or_else(|| ImageError::Invalid("image doesn't have R, G, B channels".into()))?;
    if src_white[1].is_nan() || src_white[1] <= 0.0 || !src_white[0].is_finite() {
        return Err(ImageError::Invalid(format!(
            "white point ({}, {}) is not a valid chromaticity",
            src_white[0], src_white[1]
        )));
    }
    let cs = RgbColorSpace::get(metadata.color_space_name()).unwrap_or(RgbColorSpace::srgb());
    let m = cs
        .rgb_from_xyz
        .mul(&white_balance(src_white, cs.w))
        .mul(&cs.xyz_from_rgb);
    let nc = image.n_channels();
    let mut out = image.clone();
    for (p, px) in image.to_f32_vec().chunks_exact(nc).enumerate() {
        let v = m.apply([px[rgb.offset[0]], px[rgb.offset[1]], px[rgb.offset[2]]]);
        for (&o, vk) in rgb.offset.iter().zip(v) {
            out.set_value_at(p * nc + o, vk);
        }
    }
    Ok(out)
}

/// A normal map (R, G, B encoding n = 2 v - 1) with the normals' x and y
/// scaled by `scale` and z recomputed as sqrt(max(0, 1 - x² - y²))
/// (pbrt-v4 `scalenormalmap`).
pub fn scale_normal_map(image: &Image, scale: f32) -> Result<Image, ImageError> {
    let rgb = image
        .get_channel_desc(&["R", "G", "B"])
        .ok_or_else(|| ImageError::Invalid("image doesn't have R, G, B channels".into()))?;
    let nc = image.n_channels();
    let mut out = image.clone();
    for (p, px) in image.to_f32_vec().chunks_exact(nc).enumerate() {
        let x = (2.0 * px[rgb.offset[0]] - 1.0) * scale;
        let y = (2.0 * px[rgb.offset[1]] - 1.0) * scale;
        let z = (1.0 - x * x - y * y).max(0.0).sqrt();
        for (k, n) in [x, y, z].into_iter().enumerate() {
            out.set_value_at(p * nc + rgb.offset[k], (n + 1.0) / 2.0);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_geometry::Point2i;

    #[test]
    fn balancing_from_the_spaces_own_white_changes_nothing() {
        let im =
            Image::from_f32(vec![0.2, 0.5, 0.9], Point2i::new(1, 1), &["R", "G", "B"]).unwrap();
        let w = RgbColorSpace::srgb().w;
        let o = white_balance_image(&im, &ImageMetadata::default(), w)
            .unwrap()
            .to_f32_vec();
        for (a, b) in o.iter().zip([0.2, 0.5, 0.9]) {
            assert!((a - b).abs() < 1e-4, "{o:?}");
        }
    }

    #[test]
    fn balancing_maps_the_source_white_to_white() {
        // An RGB whose chromaticity is illuminant A's becomes neutral.
        let a = illuminant_white("A").unwrap();
        // Illuminant A: x = 0.44757, y = 0.40745.
        assert!(
            (a[0] - 0.44757).abs() < 2e-3 && (a[1] - 0.40745).abs() < 2e-3,
            "{a:?}"
        );
        let cs = RgbColorSpace::srgb();
        let xyz = crate::spectrum::XYZ::from_xyy(a, 1.0);
        let rgb = cs.to_rgb(xyz);
        let im = Image::from_f32(
            vec![rgb.r, rgb.g, rgb.b],
            Point2i::new(1, 1),
            &["R", "G", "B"],
        )
        .unwrap();
        let o = white_balance_image(&im, &ImageMetadata::default(), a)
            .unwrap()
            .to_f32_vec();
        assert!(
            (o[0] - o[1]).abs() < 1e-3 && (o[1] - o[2]).abs() < 1e-3,
            "{o:?}"
        );
        assert!(illuminant_white("nope").is_none());
    }

    #[test]
    fn daylight_6504k_is_d65() {
        let w = temperature_white(6504.0);
        assert!(
            (w[0] - 0.3127).abs() < 2e-3 && (w[1] - 0.3290).abs() < 2e-3,
            "{w:?}"
        );
    }

    #[test]
    fn normal_map_slopes_scale() {
        // Normal (0.6, 0, 0.8) encoded (0.8, 0.5, 0.9); scale 0.5 gives
        // x = 0.3, z = sqrt(1 - 0.09) = 0.953939.
        let im =
            Image::from_f32(vec![0.8, 0.5, 0.9], Point2i::new(1, 1), &["R", "G", "B"]).unwrap();
        let o = scale_normal_map(&im, 0.5).unwrap().to_f32_vec();
        assert!((o[0] - 0.65).abs() < 1e-6);
        assert!((o[1] - 0.5).abs() < 1e-6);
        assert!((o[2] - (1.0 + 0.91f32.sqrt()) / 2.0).abs() < 1e-6);
        let y = Image::from_f32(vec![0.5], Point2i::new(1, 1), &["Y"]).unwrap();
        assert!(scale_normal_map(&y, 1.0).is_err());
    }
}
