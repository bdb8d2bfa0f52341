//! The processing pipeline of `imgtool convert` (pbrt-v4's `convert`):
//! channel selection, cropping (kept consistent with the EXR data and
//! display windows), clamping, colour-space conversion, black and white,
//! despiking, scaling, gamma, Reinhard tone mapping, colour-preserving
//! normalisation, the ACES filmic curve, pixel repetition and flipping,
//! in pbrt-v4's order.

use rpbrt_geometry::{Bounds2i, Point2i};

use super::filter::despike;
use crate::image::{ColorEncoding, Image, ImageError, ImageMetadata, PixelFormat};
use crate::spectrum::{convert_rgb_color_space, RgbColorSpace};

/// What `convert` does; the default changes nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvertOptions {
    /// Apply the ACES filmic curve (Narkowicz's fit) to map values to [0, 1].
    pub aces_filmic: bool,
    /// Replace every channel by the pixel's channel average.
    pub bw: bool,
    /// Keep only these channels, in this order.
    pub channels: Option<Vec<String>>,
    /// Rescale pixels whose largest channel exceeds this to have it as
    /// their largest (infinite: no clamping).
    pub clamp: f32,
    /// Keep only this window of the full image (in full-image pixel
    /// coordinates when the file has a data window).
    pub crop: Option<Bounds2i>,
    /// Convert R, G, B to this colour space (pbrt-v4's names, any case).
    pub color_space: Option<String>,
    /// Pixels whose channel average is at least this are replaced by their
    /// 3×3 neighbourhood's median (infinite: disabled).
    pub despike: f32,
    /// Mirror the image top to bottom.
    pub flip_y: bool,
    /// Raise max(0, v) to this power (1: none).
    pub gamma: f32,
    /// The luminance Reinhard tone mapping maps to white.
    pub max_luminance: f32,
    /// Divide pixels whose largest channel exceeds 1 by it.
    pub preserve_colors: bool,
    /// Repeat each pixel this many times in x and y.
    pub repeat: i32,
    /// Multiply every value by this.
    pub scale: f32,
    /// Apply Reinhard et al.'s photographic tone mapping.
    pub tonemap: bool,
    /// Store the result as 16-bit half floats (rpbrt's addition).
    pub fp16: bool,
}

impl Default for ConvertOptions {
    fn default() -> Self {
        ConvertOptions {
            aces_filmic: false,
            bw: false,
            channels: None,
            clamp: f32::INFINITY,
            crop: None,
            color_space: None,
            despike: f32::INFINITY,
            flip_y: false,
            gamma: 1.0,
            max_luminance: 1.0,
            preserve_colors: false,
            repeat: 1,
            scale: 1.0,
            tonemap: false,
            fp16: false,
        }
    }
}

/// The result of [`convert`].
#[derive(Clone, Debug)]
pub struct Converted {
    /// The processed image.
    pub image: Image,
    /// The metadata to write with it (colour space, camera matrices and
    /// windows carried over and adjusted).
    pub metadata: ImageMetadata,
    /// Pixels the despike step replaced.
    pub despiked: usize,
    /// Notes for the user (such as channels dropped for the output format).
    pub warnings: Vec<String>,
}

/// pbrt-v4's crop window from `--crop x0,x1,y0,y1`: a negative x1 or y1
/// is a size (x1 = x0 - x1); a negative x0 or y0 means no crop.
pub fn crop_window(c: [i32; 4]) -> Option<Bounds2i> {
    let mut c = c;
    if c[1] < 0 {
        c[1] = c[0] - c[1];
    }
    if c[3] < 0 {
        c[3] = c[2] - c[3];
    }
    (c[0] >= 0 && c[2] >= 0).then(|| Bounds2i {
        p_min: Point2i::new(c[0], c[2]),
        p_max: Point2i::new(c[1], c[3]),
    })
}

/// Whether `a` lies within `b`.
fn inside(a: &Bounds2i, b: &Bounds2i) -> bool {
    a.p_min.x >= b.p_min.x
        && a.p_min.y >= b.p_min.y
        && a.p_max.x <= b.p_max.x
        && a.p_max.y <= b.p_max.y
}

fn fmt_bounds(b: &Bounds2i) -> String {
    format!(
        "({},{})-({},{})",
        b.p_min.x, b.p_min.y, b.p_max.x, b.p_max.y
    )
}

/// Narkowicz's fit of the ACES filmic curve, clamped to [0, 1].
pub fn aces_filmic(x: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    let (a, b, c, d, e) = (2.51f32, 0.03f32, 2.43f32, 0.59f32, 0.14f32);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// Runs pbrt-v4's `convert` pipeline on `image` read with `metadata`;
/// `to_exr` says whether the output keeps arbitrary channels (otherwise
/// an image with channels beyond R, G, B, A is reduced to R, G, B).
pub fn convert(
    image: &Image,
    metadata: &ImageMetadata,
    opts: &ConvertOptions,
    to_exr: bool,
) -> Result<Converted, ImageError> {
    let invalid = |m: String| Err(ImageError::Invalid(m));
    if opts.max_luminance <= 0.0 {
        return invalid("--maxluminance value must be greater than zero".into());
    }
    if opts.repeat <= 0 {
        return invalid("--repeatpix value must be greater than zero".into());
    }
    let res = image.resolution();
    let r = opts.repeat;
    if res.x.checked_mul(r).is_none() || res.y.checked_mul(r).is_none() {
        return invalid(format!(
            "--repeatpix {r}: a {}x{} image repeated is larger than an image may be",
            res.x, res.y
        ));
    }
    if opts.scale == 0.0 {
        return invalid("--scale value must be non-zero".into());
    }
    let mut warnings = Vec::new();
    let mut md = ImageMetadata {
        color_space: metadata.color_space.clone(),
        camera_from_world: metadata.camera_from_world,
        ndc_from_world: metadata.ndc_from_world,
        pixel_bounds: metadata.pixel_bounds,
        full_resolution: metadata.full_resolution,
        ..Default::default()
    };
    let mut channels = opts.channels.clone();
    if channels.is_none()
        && !to_exr
        && image
            .channel_names()
            .iter()
            .any(|n| !matches!(n.as_str(), "R" | "G" | "B" | "A"))
    {
        warnings.push(
            "image has non-RGB channels but the output format can't store them; converting R,G,B only"
                .into(),
        );
        channels = Some(vec!["R".into(), "G".into(), "B".into()]);
    }
    let mut im = match &channels {
        Some(names) => {
            let desc = image.get_channel_desc(names).ok_or_else(|| {
                ImageError::Invalid(format!(
                    "image doesn't have channels \"{}\" (it has {})",
                    names.join(","),
                    image.channel_names().join(",")
                ))
            })?;
            image.select_channels(&desc)
        }
        None => image.clone(),
    };

    if let Some(crop) = opts.crop {
        let full = metadata.full_resolution.unwrap_or(im.resolution());
        if let Some(pb) = metadata.pixel_bounds.filter(|pb| !inside(&crop, pb)) {
            return invalid(format!(
                "crop window bounds {} are not inside the image's pixel bounds {}",
                fmt_bounds(&crop),
                fmt_bounds(&pb)
            ));
        }
        let full_bounds = Bounds2i {
            p_min: Point2i::new(0, 0),
            p_max: full,
        };
        if !inside(&crop, &full_bounds) {
            return invalid(format!(
                "crop window bounds {} are not inside the image's resolution ({},{})",
                fmt_bounds(&crop),
                full.x,
                full.y
            ));
        }
        md.full_resolution = Some(full);
        md.pixel_bounds = Some(crop);
        let origin = metadata
            .pixel_bounds
            .map(|b| b.p_min)
            .unwrap_or(Point2i::new(0, 0));
        let local = Bounds2i {
            p_min: Point2i::new(crop.p_min.x - origin.x, crop.p_min.y - origin.y),
            p_max: Point2i::new(crop.p_max.x - origin.x, crop.p_max.y - origin.y),
        };
        im = im.crop(local)?;
    }

    // Work in 32-bit floats.
    if im.format() != PixelFormat::Float {
        im = im.convert_to_format(PixelFormat::Float, ColorEncoding::Linear);
    }
    let nc = im.n_channels().max(1);
    let res = im.resolution();
    let mut v = im.to_f32_vec();

    if opts.clamp < f32::INFINITY {
        for px in v.chunks_exact_mut(nc) {
            let m = px.iter().copied().fold(0.0f32, f32::max);
            if m > opts.clamp {
                let s = opts.clamp / m;
                px.iter_mut().for_each(|x| *x *= s);
            }
        }
    }

    if let Some(name) = &opts.color_space {
        let dest = RgbColorSpace::get(&name.to_ascii_lowercase()).ok_or_else(|| {
            ImageError::Invalid(format!(
                "{name}: color space unknown (known: ACES2065-1, Rec2020, DCI-P3, sRGB)"
            ))
        })?;
        let rgb = im
            .get_channel_desc(&["R", "G", "B"])
            .ok_or_else(|| ImageError::Invalid("image doesn't have R, G, B channels".into()))?;
        let src = RgbColorSpace::get(metadata.color_space_name()).unwrap_or(RgbColorSpace::srgb());
        let m = convert_rgb_color_space(src, dest);
        for px in v.chunks_exact_mut(nc) {
            let c = [px[rgb.offset[0]], px[rgb.offset[1]], px[rgb.offset[2]]];
            let out = m.apply(c);
            for k in 0..3 {
                px[rgb.offset[k]] = out[k];
            }
        }
        md.color_space = Some(dest.name.clone());
    }

    if opts.bw {
        for px in v.chunks_exact_mut(nc) {
            let a = px.iter().sum::<f32>() / nc as f32;
            px.iter_mut().for_each(|x| *x = a);
        }
    }

    let mut despiked = 0;
    if opts.despike < f32::INFINITY {
        let cur = Image::from_f32(v, res, im.channel_names())?;
        let (out, n) = despike(&cur, opts.despike);
        despiked = n;
        v = out.to_f32_vec();
    }

    if opts.scale != 1.0 {
        v.iter_mut().for_each(|x| *x *= opts.scale);
    }
    if opts.gamma != 1.0 {
        v.iter_mut().for_each(|x| *x = x.max(0.0).powf(opts.gamma));
    }
    if opts.tonemap {
        let y2 = opts.max_luminance * opts.max_luminance;
        for px in v.chunks_exact_mut(nc) {
            let lum = px.iter().sum::<f32>() / nc as f32;
            let s = (1.0 + lum / y2) / (1.0 + lum);
            px.iter_mut().for_each(|x| *x *= s);
        }
    }
    if opts.preserve_colors {
        for px in v.chunks_exact_mut(nc) {
            let m = px.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            if m > 1.0 {
                px.iter_mut().for_each(|x| *x /= m);
            }
        }
    }
    if opts.aces_filmic {
        v.iter_mut().for_each(|x| *x = aces_filmic(*x));
    }

    let mut im = Image::from_f32(v, res, im.channel_names())?;
    let r = opts.repeat;
    if r > 1 {
        let (w, h) = (res.x as usize, res.y as usize);
        let vals = im.to_f32_vec();
        let rw = w * r as usize;
        let mut out = Vec::with_capacity(vals.len() * (r * r) as usize);
        for y in 0..h * r as usize {
            for x in 0..rw {
                let i = ((y / r as usize) * w + x / r as usize) * nc;
                out.extend_from_slice(&vals[i..i + nc]);
            }
        }
        im = Image::from_f32(out, Point2i::new(res.x * r, res.y * r), im.channel_names())?;
        if let Some(f) = md.full_resolution.as_mut() {
            *f = Point2i::new(f.x * r, f.y * r);
        }
        if let Some(b) = md.pixel_bounds.as_mut() {
            b.p_min = Point2i::new(b.p_min.x * r, b.p_min.y * r);
            b.p_max = Point2i::new(b.p_max.x * r, b.p_max.y * r);
        }
    }
    if opts.flip_y {
        im.flip_y();
        // The data window flips within the display window.
        if let (Some(b), Some(f)) = (md.pixel_bounds.as_mut(), md.full_resolution) {
            let (y0, y1) = (f.y - b.p_max.y, f.y - b.p_min.y);
            b.p_min.y = y0;
            b.p_max.y = y1;
        }
    }
    if opts.fp16 {
        im = im.convert_to_format(PixelFormat::Half, ColorEncoding::Linear);
    }
    Ok(Converted {
        image: im,
        metadata: md,
        despiked,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rgb(vals: &[f32], w: i32, h: i32) -> Image {
        Image::from_f32(vals.to_vec(), Point2i::new(w, h), &["R", "G", "B"]).unwrap()
    }

    fn run(im: &Image, opts: &ConvertOptions) -> Vec<f32> {
        convert(im, &ImageMetadata::default(), opts, true)
            .unwrap()
            .image
            .to_f32_vec()
    }

    #[test]
    fn crop_window_follows_pbrt_v4() {
        assert_eq!(crop_window([-1, 0, -1, 0]), None);
        let b = crop_window([1, 3, 2, -2]).unwrap();
        assert_eq!((b.p_min, b.p_max), (Point2i::new(1, 2), Point2i::new(3, 4)));
    }

    #[test]
    fn clamp_rescales_the_pixel_and_scale_multiplies() {
        let im = rgb(&[4.0, 2.0, 1.0, 0.5, 0.25, 0.0], 2, 1);
        let o = run(
            &im,
            &ConvertOptions {
                clamp: 2.0,
                scale: 2.0,
                ..Default::default()
            },
        );
        // First pixel: max 4 > 2 → halved (2, 1, 0.5), then doubled.
        assert_eq!(o, vec![4.0, 2.0, 1.0, 1.0, 0.5, 0.0]);
    }

    #[test]
    fn bw_gamma_tonemap_preserve_and_aces() {
        let im = rgb(&[3.0, 0.0, 0.0], 1, 1);
        let o = run(
            &im,
            &ConvertOptions {
                bw: true,
                ..Default::default()
            },
        );
        assert_eq!(o, vec![1.0; 3]);
        let o = run(
            &rgb(&[4.0, -1.0, 0.25], 1, 1),
            &ConvertOptions {
                gamma: 0.5,
                ..Default::default()
            },
        );
        assert_eq!(o, vec![2.0, 0.0, 0.5]);
        // Tonemap with max luminance 2: lum 1 → scale (1 + 1/4) / 2.
        let o = run(
            &rgb(&[1.0, 1.0, 1.0], 1, 1),
            &ConvertOptions {
                tonemap: true,
                max_luminance: 2.0,
                ..Default::default()
            },
        );
        assert_eq!(o, vec![0.625; 3]);
        let o = run(
            &rgb(&[4.0, 2.0, 1.0], 1, 1),
            &ConvertOptions {
                preserve_colors: true,
                ..Default::default()
            },
        );
        assert_eq!(o, vec![1.0, 0.5, 0.25]);
        // ACES at 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16.
        let o = run(
            &rgb(&[1.0, 0.0, 100.0], 1, 1),
            &ConvertOptions {
                aces_filmic: true,
                ..Default::default()
            },
        );
        assert!((o[0] - 2.54 / 3.16).abs() < 1e-6);
        assert_eq!(o[1], 0.0);
        assert_eq!(o[2], 1.0);
    }

    #[test]
    fn crop_repeat_and_flip_adjust_the_windows() {
        // 2x2 image, data window (0,0)-(2,2) in a 2x2 display window.
        let im = rgb(&(0..12).map(|i| i as f32).collect::<Vec<_>>(), 2, 2);
        let md = ImageMetadata {
            pixel_bounds: Some(Bounds2i {
                p_min: Point2i::new(0, 0),
                p_max: Point2i::new(2, 2),
            }),
            full_resolution: Some(Point2i::new(2, 2)),
            ..Default::default()
        };
        let opts = ConvertOptions {
            crop: crop_window([1, 2, 0, 2]),
            repeat: 2,
            flip_y: true,
            ..Default::default()
        };
        let c = convert(&im, &md, &opts, true).unwrap();
        // The right column (pixels 1 and 3: values 3..6, 9..12), each
        // repeated 2x2, then flipped: rows 9,9,3,3 order.
        let o = c.image.to_f32_vec();
        assert_eq!(c.image.resolution(), Point2i::new(2, 4));
        assert_eq!(&o[0..3], &[9.0, 10.0, 11.0]);
        assert_eq!(&o[12..15], &[3.0, 4.0, 5.0]);
        let pb = c.metadata.pixel_bounds.unwrap();
        assert_eq!(
            (pb.p_min, pb.p_max),
            (Point2i::new(2, 0), Point2i::new(4, 4))
        );
        assert_eq!(c.metadata.full_resolution, Some(Point2i::new(4, 4)));
        // Outside the data window is an error.
        let bad = ConvertOptions {
            crop: crop_window([1, 3, 0, 2]),
            ..Default::default()
        };
        assert!(convert(&im, &md, &bad, true).is_err());
    }

    #[test]
    fn channels_are_selected_and_aovs_dropped_for_ldr_output() {
        let im = Image::from_f32(
            vec![1.0, 2.0, 3.0, 4.0],
            Point2i::new(1, 1),
            &["R", "G", "B", "Pz"],
        )
        .unwrap();
        let c = convert(
            &im,
            &ImageMetadata::default(),
            &ConvertOptions::default(),
            false,
        )
        .unwrap();
        assert_eq!(c.image.channel_names(), ["R", "G", "B"]);
        assert_eq!(c.warnings.len(), 1);
        let c = convert(
            &im,
            &ImageMetadata::default(),
            &ConvertOptions::default(),
            true,
        )
        .unwrap();
        assert_eq!(c.image.n_channels(), 4);
        let opts = ConvertOptions {
            channels: Some(vec!["Pz".into(), "R".into()]),
            ..Default::default()
        };
        let c = convert(&im, &ImageMetadata::default(), &opts, true).unwrap();
        assert_eq!(c.image.to_f32_vec(), vec![4.0, 1.0]);
        let opts = ConvertOptions {
            channels: Some(vec!["Q".into()]),
            ..Default::default()
        };
        assert!(convert(&im, &ImageMetadata::default(), &opts, true).is_err());
    }

    #[test]
    fn colorspace_conversion_maps_white_to_white_and_records_the_space() {
        let im = rgb(&[1.0, 1.0, 1.0, 1.0, 0.0, 0.0], 2, 1);
        let opts = ConvertOptions {
            color_space: Some("Rec2020".into()),
            ..Default::default()
        };
        let c = convert(&im, &ImageMetadata::default(), &opts, true).unwrap();
        let o = c.image.to_f32_vec();
        // Both spaces have a D65 white: white stays white.
        for &x in &o[0..3] {
            assert!((x - 1.0).abs() < 1e-4, "{o:?}");
        }
        // sRGB red in Rec.2020 (BT.2087's matrix): 0.6274, 0.0691, 0.0164.
        assert!(
            (o[3] - 0.6274).abs() < 2e-3 && (o[4] - 0.0691).abs() < 2e-3,
            "{o:?}"
        );
        assert!((o[5] - 0.0164).abs() < 2e-3, "{o:?}");
        assert_eq!(c.metadata.color_space.as_deref(), Some("rec2020"));
        let bad = ConvertOptions {
            color_space: Some("nope".into()),
            ..Default::default()
        };
        assert!(convert(&im, &ImageMetadata::default(), &bad, true).is_err());
    }

    #[test]
    fn invalid_options_are_errors() {
        let im = rgb(&[1.0; 3], 1, 1);
        for opts in [
            ConvertOptions {
                scale: 0.0,
                ..Default::default()
            },
            ConvertOptions {
                repeat: 0,
                ..Default::default()
            },
            ConvertOptions {
                max_luminance: 0.0,
                ..Default::default()
            },
        ] {
            assert!(convert(&im, &ImageMetadata::default(), &opts, true).is_err());
        }
    }

    #[test]
    fn fp16_stores_half() {
        let im = rgb(&[1.0; 3], 1, 1);
        let opts = ConvertOptions {
            fp16: true,
            ..Default::default()
        };
        let c = convert(&im, &ImageMetadata::default(), &opts, true).unwrap();
        assert_eq!(c.image.format(), PixelFormat::Half);
    }
}
