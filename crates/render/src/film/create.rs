//! Creating a film from the scene's `Film` directive (pbrt-v4
//! `Film::Create`, `FilmBaseParameters`, `PixelSensor::Create`): parameter
//! names and defaults as pbrt-v4, with located errors for values it cannot
//! use.

use std::path::Path;

use rpbrt_geometry::{AnimatedTransform, Bounds2i, Float, Point2i};
use rpbrt_parser::{Diagnostic, FileLoc};

use super::pixels::KindConfig;
use super::sensor::{sensor_names, PixelSensor};
use super::{Film, FilmCore, FilmParams, GBufferFilm, RgbFilm, SpectralFilm};
use crate::camera::CameraTransform;
use crate::filter::Filter;
use crate::params::{unknown_type, ParamReader};
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN};

/// The film types `Film` accepts, sorted.
pub const FILM_NAMES: &[&str] = &["gbuffer", "rgb", "spectral"];

/// Largest accepted `xresolution`/`yresolution` (2^15).
pub const MAX_RESOLUTION: i32 = 1 << 15;
/// Largest accepted number of rendered pixels (2^28).
const MAX_PIXELS: i64 = 1 << 28;
/// Image file extensions the image module writes.
pub const IMAGE_EXTENSIONS: [&str; 4] = ["exr", "pfm", "png", "qoi"];

/// Command-line settings that override the scene's film (pbrt-v4
/// `--outfile`, `--cropwindow`, `--pixelbounds`, `--quick`).
#[derive(Clone, Debug, Default)]
pub struct FilmOverrides {
    /// Output file name.
    pub outfile: Option<String>,
    /// Crop window `x0 x1 y0 y1` in [0, 1].
    pub crop_window: Option<[Float; 4]>,
    /// Pixel bounds `x0 x1 y0 y1`.
    pub pixel_bounds: Option<[i32; 4]>,
    /// Quarter the resolution.
    pub quick: bool,
    /// `--tile K/N`: render only tile K of N of the pixel bounds
    /// ([`super::tile_bounds`]).
    pub tile: Option<(u32, u32)>,
    /// `--denoise`, `--gbuffer`: an `rgb` film is made a `gbuffer` film with the same
    /// parameters (the same R, G, B, plus the first visible surface's
    /// albedo and normal, in camera space, for the denoiser).
    pub aovs: bool,
}

fn extension(name: &str) -> String {
    Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default()
}

/// Pixel bounds of crop window `c` (`x0 x1 y0 y1`), rounding the scaled
/// corners up as pbrt-v4 does.
pub fn crop_to_pixel_bounds(res: Point2i, c: [Float; 4]) -> Bounds2i {
    let (x0, x1) = (c[0].min(c[1]), c[0].max(c[1]));
    let (y0, y1) = (c[2].min(c[3]), c[2].max(c[3]));
    Bounds2i::new(
        Point2i::new(
            (res.x as Float * x0).ceil() as i32,
            (res.y as Float * y0).ceil() as i32,
        ),
        Point2i::new(
            (res.x as Float * x1).ceil() as i32,
            (res.y as Float * y1).ceil() as i32,
        ),
    )
}

fn check_crop(c: &[Float], loc: FileLoc) -> Result<[Float; 4], Diagnostic> {
    if c.len() != 4 {
        return Err(Diagnostic::error(
            loc,
            format!("{} values supplied for \"cropwindow\"; expected 4", c.len()),
        ));
    }
    if c.iter().any(|v| !(0.0..=1.0).contains(v)) {
        return Err(Diagnostic::error(
            loc,
            format!(
                "crop window [{} {} {} {}] is not in the [0,1] range; did you mean \"pixelbounds\"?",
                c[0], c[1], c[2], c[3]
            ),
        ));
    }
    Ok([c[0], c[1], c[2], c[3]])
}

fn check_pixel_bounds(pb: &[i32], full: Bounds2i, loc: FileLoc) -> Result<Bounds2i, Diagnostic> {
    if pb.len() != 4 {
        return Err(Diagnostic::error(
            loc,
            format!(
                "{} values supplied for \"pixelbounds\"; expected 4",
                pb.len()
            ),
        ));
    }
    let b = Bounds2i::new(Point2i::new(pb[0], pb[2]), Point2i::new(pb[1], pb[3]));
    if b.intersect(&full) != b || pb[0] > pb[1] || pb[2] > pb[3] {
        return Err(Diagnostic::error(
            loc,
            format!(
                "pixel bounds [{} {} {} {}] extend beyond the {}x{} image",
                pb[0], pb[1], pb[2], pb[3], full.p_max.x, full.p_max.y
            ),
        ));
    }
    Ok(b)
}

/// Creates the film of a `Film` directive. `exposure_time` is the camera's
/// `shutterclose - shutteropen`; `camera_transform` places G-buffer output.
/// Warnings (overridden settings) go to `fp`.
pub fn create_film(
    name: &str,
    fp: &ParamReader,
    filter: &Filter,
    exposure_time: Float,
    camera_transform: &CameraTransform,
    overrides: &FilmOverrides,
) -> Result<Film, Diagnostic> {
    let loc = fp.loc();
    let name = if overrides.aovs && name == "rgb" {
        "gbuffer"
    } else {
        name
    };
    if !FILM_NAMES.contains(&name) {
        return Err(unknown_type("film", name, FILM_NAMES, loc));
    }
    let color_space = fp.color_space();

    // Sensor.
    let iso = fp.float("iso", 100.0)?;
    let mut wb = fp.float("whitebalance", 0.0)?;
    let sensor_name = fp.string("sensor", "cie1931")?;
    if sensor_name != "cie1931" && wb == 0.0 {
        wb = 6500.0;
    }
    let imaging_ratio = exposure_time * iso / 100.0;
    let sensor = if sensor_name == "cie1931" {
        PixelSensor::cie1931(color_space, wb, imaging_ratio)
    } else {
        match PixelSensor::camera(&sensor_name, color_space, wb, imaging_ratio) {
            Some(Ok(s)) => s,
            Some(Err(m)) => return Err(Diagnostic::error(fp.param_loc("sensor"), m)),
            None => {
                let known: Vec<&str> = sensor_names().collect();
                return Err(Diagnostic::error(
                    fp.param_loc("sensor"),
                    format!(
                        "\"{sensor_name}\": unknown sensor type (known: {})",
                        known.join(", ")
                    ),
                ));
            }
        }
    };

    // File name.
    let scene_filename = fp.string("filename", "")?;
    let filename = match &overrides.outfile {
        Some(f) => {
            if !scene_filename.is_empty() {
                fp.warn_at(
                    "filename",
                    format!("output filename \"{f}\" from the command line overrides \"{scene_filename}\" from the scene"),
                );
            }
            f.clone()
        }
        None if scene_filename.is_empty() => "pbrt.exr".to_string(),
        None => scene_filename,
    };
    let ext = extension(&filename);
    let floc = fp.param_loc("filename");
    if !IMAGE_EXTENSIONS.contains(&ext.as_str()) {
        return Err(Diagnostic::error(
            floc,
            format!("\"{filename}\": cannot write images with extension \"{ext}\" (supported: exr, pfm, png, qoi)"),
        ));
    }
    if name != "rgb" && ext != "exr" {
        return Err(Diagnostic::error(
            floc,
            format!("\"{filename}\": EXR is the only format supported by the {name} film"),
        ));
    }

    // Resolution.
    let xres = fp.int("xresolution", 1280)?;
    let yres = fp.int("yresolution", 720)?;
    for (n, v) in [("xresolution", xres), ("yresolution", yres)] {
        if v <= 0 {
            return Err(Diagnostic::error(
                fp.param_loc(n),
                format!("\"{n}\" must be positive (got {v})"),
            ));
        }
        if v > MAX_RESOLUTION {
            return Err(Diagnostic::error(
                fp.param_loc(n),
                format!("\"{n}\" {v} is larger than the supported maximum {MAX_RESOLUTION}"),
            ));
        }
    }
    let mut full = Point2i::new(xres, yres);
    if overrides.quick {
        full = Point2i::new((full.x / 4).max(1), (full.y / 4).max(1));
    }
    let full_bounds = Bounds2i::new(Point2i::new(0, 0), full);

    // Pixel bounds and crop window, with pbrt-v4's precedence.
    let mut pixel_bounds = full_bounds;
    let pb = fp.ints("pixelbounds")?;
    if let Some(cli) = overrides.pixel_bounds {
        pixel_bounds = check_pixel_bounds(&cli, full_bounds, loc.clone())?;
    } else if !pb.is_empty() {
        pixel_bounds = check_pixel_bounds(&pb, full_bounds, fp.param_loc("pixelbounds"))?;
    }
    let cr = fp.floats("cropwindow")?;
    if let Some(c) = overrides.crop_window {
        let c = check_crop(&c, loc.clone())?;
        pixel_bounds = crop_to_pixel_bounds(full, c);
        if !cr.is_empty() {
            fp.warn_at(
                "cropwindow",
                "crop window from the command line overrides the film's \"cropwindow\"",
            );
        }
    } else if !cr.is_empty() {
        let c = check_crop(&cr, fp.param_loc("cropwindow"))?;
        if overrides.pixel_bounds.is_some() {
            fp.warn_at(
                "cropwindow",
                "ignoring \"cropwindow\" since pixel bounds were given on the command line",
            );
        } else {
            if !pb.is_empty() {
                fp.warn_at(
                    "cropwindow",
                    "both pixel bounds and crop window were given; using the crop window",
                );
            }
            pixel_bounds = crop_to_pixel_bounds(full, c);
        }
    }
    if let Some((k, n)) = overrides.tile {
        let area = pixel_bounds.area();
        pixel_bounds = super::tile_bounds(pixel_bounds, k, n).ok_or_else(|| {
            Diagnostic::error(
                loc.clone(),
                format!("--tile {k}/{n}: the film's {area} pixels cannot be split into {n} tiles of at least one pixel (need K < N <= pixels)"),
            )
        })?;
    }
    if pixel_bounds.is_empty() {
        return Err(Diagnostic::error(
            loc.clone(),
            format!(
                "degenerate pixel bounds [{} {} {} {}] for the film",
                pixel_bounds.p_min.x,
                pixel_bounds.p_max.x,
                pixel_bounds.p_min.y,
                pixel_bounds.p_max.y
            ),
        ));
    }
    if pixel_bounds.area() > MAX_PIXELS {
        return Err(Diagnostic::error(
            loc.clone(),
            format!(
                "film of {} pixels is larger than the supported maximum {MAX_PIXELS}",
                pixel_bounds.area()
            ),
        ));
    }

    let diagonal = fp.float("diagonal", 35.0)?;
    let max_component_value = fp.float("maxcomponentvalue", Float::INFINITY)?;
    let write_fp16 = fp.bool("savefp16", true)?;

    let kind = match name {
        "gbuffer" => {
            let cs = fp.string("coordinatesystem", "camera")?;
            let (output_from_render, apply_inverse) = match cs.as_str() {
                "camera" => (camera_transform.render_from_camera.clone(), true),
                "world" => (AnimatedTransform::fixed(camera_transform.world_from_render), false),
                _ => {
                    return Err(Diagnostic::error(
                        fp.param_loc("coordinatesystem"),
                        format!("\"{cs}\": unknown coordinate system for the gbuffer film (expected \"camera\" or \"world\")"),
                    ))
                }
            };
            KindConfig::GBuffer {
                output_from_render,
                apply_inverse,
                color_space,
            }
        }
        "spectral" => {
            let nb = fp.int("nbuckets", 16)?;
            let lmin = fp.float("lambdamin", LAMBDA_MIN)?;
            let lmax = fp.float("lambdamax", LAMBDA_MAX)?;
            if !(1..=1024).contains(&nb) {
                return Err(Diagnostic::error(
                    fp.param_loc("nbuckets"),
                    format!("\"nbuckets\" must be in [1, 1024] (got {nb})"),
                ));
            }
            if lmin < LAMBDA_MIN
                || lmax > LAMBDA_MAX
                || lmin >= lmax
                || lmin.is_nan()
                || lmax.is_nan()
            {
                return Err(Diagnostic::error(
                    fp.param_loc("lambdamin"),
                    format!("wavelength range [{lmin}, {lmax}] must be increasing and within [{LAMBDA_MIN}, {LAMBDA_MAX}] nm"),
                ));
            }
            KindConfig::Spectral {
                lambda_min: lmin,
                lambda_max: lmax,
                n_buckets: nb as usize,
            }
        }
        _ => KindConfig::Rgb,
    };
    fp.charge(FilmCore::memory_bytes(pixel_bounds, &kind), "this film")?;
    let core = FilmCore::new(
        FilmParams {
            full_resolution: full,
            pixel_bounds,
            diagonal_mm: diagonal,
            filename,
            color_space,
            max_component_value,
            write_fp16,
        },
        filter.clone(),
        sensor,
        kind,
    );
    let film = match name {
        "gbuffer" => Film::GBuffer(GBufferFilm { core }),
        "spectral" => Film::Spectral(SpectralFilm { core }),
        _ => Film::Rgb(RgbFilm { core }),
    };
    Ok(film)
}
