//! Creating a [`Camera`] from the scene's `Camera` directive (pbrt-v4
//! `Camera::Create` and the cameras' `Create` functions): parameter names
//! and defaults as pbrt-v4, with located errors for values it cannot use.

use std::path::Path;

use rpbrt_geometry::{Bounds2f, Float, MediumId, Point2f};
use rpbrt_parser::Diagnostic;

use super::realistic::EXIT_PUPIL_RINGS;
use super::CameraTransform;
use super::{
    ApertureImage, Camera, CameraBase, FilmGeometry, OrthographicCamera, PerspectiveCamera,
    RealisticCamera, SphericalCamera, SphericalMapping,
};
use crate::params::{unknown_type, ParamReader};

/// Rays traced per ring when bounding the exit pupil (pbrt-v4: 1024²);
/// smaller in unit tests, which build many lens systems on few cores.
const EXIT_PUPIL_SAMPLES: usize = if cfg!(test) { 128 * 128 } else { 1024 * 1024 };

/// The camera types `Camera` accepts, sorted.
pub const CAMERA_NAMES: &[&str] = &["orthographic", "perspective", "realistic", "spherical"];

/// Creates the camera of type `name` placed by `camera_transform`, for
/// `film`, in `medium` (pbrt-v4 `Camera::Create`); warnings go to `cp`.
pub fn create_camera(
    name: &str,
    cp: &ParamReader,
    camera_transform: &CameraTransform,
    film: &FilmGeometry,
    medium: Option<MediumId>,
) -> Result<Camera, Diagnostic> {
    let loc = cp.loc();

    let res = film.full_resolution;
    if res.x <= 0 || res.y <= 0 {
        return Err(Diagnostic::error(
            loc.clone(),
            format!("film resolution {}x{} is not positive", res.x, res.y),
        ));
    }
    if !CAMERA_NAMES.contains(&name) {
        return Err(unknown_type("camera", name, CAMERA_NAMES, loc));
    }

    let shutter_open = cp.float("shutteropen", 0.0)?;
    let shutter_close = cp.float("shutterclose", 1.0)?;
    if !(shutter_open.is_finite() && shutter_close.is_finite()) {
        return Err(Diagnostic::error(
            cp.param_loc("shutteropen"),
            "shutter times must be finite",
        ));
    }
    if shutter_close < shutter_open {
        cp.warn_at(
            "shutterclose",
            format!(
                "shutter close time {shutter_close} < shutter open {shutter_open}; swapping them"
            ),
        );
    }
    let ct = camera_transform.clone();
    let rfc = &ct.render_from_camera;
    if rfc.start_transform().has_scale(1e-3) || rfc.end_transform().has_scale(1e-3) {
        cp.warn(
            "scaling detected in the camera-from-render transformation; the renderer \
             assumes it has none, so the image may be wrong",
        );
    }
    let base = CameraBase::new(ct, shutter_open, shutter_close, *film, medium);

    let camera = match name {
        "perspective" | "orthographic" | "spherical" => {
            let lens_radius = cp.float("lensradius", 0.0)?;
            let default_focal = if name == "spherical" { 1e30 } else { 1e6 };
            let focal_distance = cp.float("focaldistance", default_focal)?;
            let screen = screen_window(cp, film)?;
            if !(lens_radius >= 0.0 && lens_radius.is_finite()) {
                return Err(Diagnostic::error(
                    cp.param_loc("lensradius"),
                    format!("lens radius {lens_radius} must be finite and non-negative"),
                ));
            }
            if lens_radius > 0.0 && !(focal_distance > 0.0 && focal_distance.is_finite()) {
                return Err(Diagnostic::error(
                    cp.param_loc("focaldistance"),
                    format!("focal distance {focal_distance} must be positive"),
                ));
            }
            match name {
                "perspective" => {
                    let fov = cp.float("fov", 90.0)?;
                    if !(fov > 0.0 && fov < 180.0) {
                        return Err(Diagnostic::error(
                            cp.param_loc("fov"),
                            format!("field of view {fov} must be between 0 and 180 degrees"),
                        ));
                    }
                    let c = PerspectiveCamera::new(base, fov, screen, lens_radius, focal_distance)
                        .map_err(|e| Diagnostic::error(loc.clone(), format!("{e}")))?;
                    Camera::Perspective(c)
                }
                "orthographic" => {
                    let c = OrthographicCamera::new(base, screen, lens_radius, focal_distance)
                        .map_err(|e| Diagnostic::error(loc.clone(), format!("{e}")))?;
                    Camera::Orthographic(c)
                }
                _ => {
                    let m = cp.string("mapping", "equalarea")?;
                    let mapping = match m.as_str() {
                        "equalarea" => SphericalMapping::EqualArea,
                        "equirectangular" => SphericalMapping::EquiRectangular,
                        _ => {
                            return Err(Diagnostic::error(
                                cp.param_loc("mapping"),
                                format!(
                                    "\"{m}\": unknown mapping for spherical camera (must be \
                                     \"equalarea\" or \"equirectangular\")"
                                ),
                            ))
                        }
                    };
                    if mapping == SphericalMapping::EqualArea && res.x != res.y {
                        return Err(Diagnostic::error(
                            cp.param_loc("mapping"),
                            format!(
                                "the equal-area spherical mapping needs a square film; \
                                 the resolution is {}x{}",
                                res.x, res.y
                            ),
                        ));
                    }
                    Camera::Spherical(SphericalCamera::new(base, mapping))
                }
            }
        }
        _ => create_realistic(cp, base)?,
    };
    Ok(camera)
}

/// `screenwindow`, or the default from `frameaspectratio` (itself
/// defaulting to the film's aspect): the shorter axis spans [−1, 1].
fn screen_window(cp: &ParamReader, film: &FilmGeometry) -> Result<Bounds2f, Diagnostic> {
    let res = film.full_resolution;
    let frame = cp.float("frameaspectratio", res.x as Float / res.y as Float)?;
    if !(frame > 0.0 && frame.is_finite()) {
        return Err(Diagnostic::error(
            cp.param_loc("frameaspectratio"),
            format!("frame aspect ratio {frame} must be positive"),
        ));
    }
    let mut screen = if frame > 1.0 {
        Bounds2f::new(Point2f::new(-frame, -1.0), Point2f::new(frame, 1.0))
    } else {
        Bounds2f::new(
            Point2f::new(-1.0, -1.0 / frame),
            Point2f::new(1.0, 1.0 / frame),
        )
    };
    let sw = cp.floats("screenwindow")?;
    if !sw.is_empty() {
        if sw.len() != 4 {
            return Err(Diagnostic::error(
                cp.param_loc("screenwindow"),
                format!(
                    "\"screenwindow\" should have four values; it has {}",
                    sw.len()
                ),
            ));
        }
        if !(sw.iter().all(|v| v.is_finite()) && sw[0] != sw[1] && sw[2] != sw[3]) {
            return Err(Diagnostic::error(
                cp.param_loc("screenwindow"),
                "\"screenwindow\" must be finite with a nonzero extent in x and y",
            ));
        }
        // Kept as written (not sorted): a reversed window mirrors the image.
        screen.p_min = Point2f::new(sw[0], sw[2]);
        screen.p_max = Point2f::new(sw[1], sw[3]);
    }
    Ok(screen)
}

/// Reads an aperture image file (pbrt-v4: RGB images are averaged to one
/// channel; the image is flipped and normalised by `ApertureImage`).
fn read_aperture_image(
    path: &Path,
    budget: &rpbrt_parser::MemoryBudget,
) -> Result<ApertureImage, String> {
    let encoding = Some(crate::image::ColorEncoding::Linear);
    let image = crate::image::Image::read_within(path, encoding, budget)
        .map_err(|e| e.to_string())?
        .image;
    let res = image.resolution();
    let nc = image.n_channels();
    let values = image.to_f32_vec();
    let names = image.channel_names();
    let rgb: Option<Vec<usize>> = ["R", "G", "B"]
        .iter()
        .map(|c| names.iter().position(|n| n == c))
        .collect();
    let mono: Vec<Float> = match (nc, rgb) {
        (1, _) => values,
        (_, Some(idx)) => values
            .chunks_exact(nc)
            .map(|px| idx.iter().map(|&i| px[i]).sum::<Float>() / 3.0)
            .collect(),
        _ => {
            return Err(format!(
                "{}: aperture images need one channel or R, G and B",
                path.display()
            ))
        }
    };
    ApertureImage::from_pixels(res.x.max(0) as usize, res.y.max(0) as usize, mono)
        .ok_or_else(|| format!("{}: the aperture image is empty or black", path.display()))
}

/// Reads a lens description: whitespace-separated numbers, `#` comments to
/// the end of the line (pbrt-v4 `ReadFloatFile`). Errors name the line.
pub fn read_lens_file(path: &Path) -> Result<Vec<Float>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: unable to read lens file: {e}", path.display()))?;
    let mut values = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for tok in line.split_whitespace() {
            let v: Float = tok.parse().map_err(|_| {
                format!(
                    "{}:{}: \"{tok}\" is not a number in the lens file",
                    path.display(),
                    i + 1
                )
            })?;
            values.push(v);
        }
    }
    Ok(values)
}

fn create_realistic(cp: &ParamReader, base: CameraBase) -> Result<Camera, Diagnostic> {
    let loc = cp.loc();
    let lens_file = cp.string("lensfile", "")?;
    let aperture_diameter = cp.float("aperturediameter", 1.0)?;
    let focus_distance = cp.float("focusdistance", 10.0)?;
    let aperture = cp.string("aperture", "")?;

    if lens_file.is_empty() {
        return Err(Diagnostic::error(
            loc.clone(),
            "realistic camera: no lens description file supplied (\"string lensfile\")",
        ));
    }
    let lens_loc = cp.param_loc("lensfile");
    if !(aperture_diameter > 0.0 && aperture_diameter.is_finite()) {
        return Err(Diagnostic::error(
            cp.param_loc("aperturediameter"),
            format!("aperture diameter {aperture_diameter} must be positive"),
        ));
    }
    if !(focus_distance > 0.0 && focus_distance.is_finite()) {
        return Err(Diagnostic::error(
            cp.param_loc("focusdistance"),
            format!("focus distance {focus_distance} must be positive"),
        ));
    }
    let path = cp.resolve("lensfile", &lens_file);
    let lens = read_lens_file(&path).map_err(|m| Diagnostic::error(lens_loc.clone(), m))?;
    if lens.is_empty() {
        return Err(Diagnostic::error(
            lens_loc,
            format!("{}: the lens file holds no values", path.display()),
        ));
    }
    if !lens.chunks_exact(4).remainder().is_empty() {
        return Err(Diagnostic::error(
            lens_loc,
            format!(
                "{}: excess values in lens specification file; must be multiple-of-four \
                 values, read {}",
                path.display(),
                lens.len()
            ),
        ));
    }
    if !lens.chunks_exact(4).any(|r| r[0] == 0.0) {
        cp.warn_located(
            lens_loc.clone(),
            format!(
                "{}: the lens has no aperture stop (a row with curvature radius 0); \
                 \"aperturediameter\" has no effect",
                path.display()
            ),
        );
    }

    let aperture_image = if aperture.is_empty() {
        None
    } else {
        match ApertureImage::builtin(&aperture) {
            Some(img) => Some(img),
            None => Some(
                read_aperture_image(&cp.resolve("aperture", &aperture), cp.budget()).map_err(
                    |m| {
                        Diagnostic::error(
                            cp.param_loc("aperture"),
                            format!("aperture \"{aperture}\": {m}"),
                        )
                    },
                )?,
            ),
        }
    };

    let (cam, warns) = RealisticCamera::new(
        base,
        &lens,
        focus_distance,
        aperture_diameter,
        aperture_image,
        EXIT_PUPIL_SAMPLES,
    )
    .map_err(|m| Diagnostic::error(lens_loc.clone(), format!("{}: {m}", path.display())))?;
    debug_assert_eq!(cam.exit_pupil_bounds.len(), EXIT_PUPIL_RINGS);
    for m in warns {
        cp.warn_at("aperturediameter", m);
    }
    Ok(Camera::Realistic(Box::new(cam)))
}
