//! Creating lights from `LightSource` and `AreaLightSource` directives
//! (pbrt-v4 `Light::Create` and the lights' `Create` functions): pbrt-v4's
//! parameter names and defaults, its photometric normalisation
//! (`scale /= SpectrumToPhotometric(spectrum)`) and its `power` /
//! `illuminance` targets, with located errors.

use rpbrt_geometry::{
    equal_area_square_to_sphere, AnimatedTransform, Float, Frame, MediumId, Point2f, Point2i,
    Point3f, SquareMatrix4, Transform, Vector3f, PI,
};
use rpbrt_parser::{Diagnostic, FileLoc};

use super::area::AreaEmission;
use super::{
    dense, luminance_vector, DiffuseAreaLight, DistantLight, GoniometricLight, ImageInfiniteLight,
    Light, PointLight, PortalImageInfiniteLight, ProjectionLight, SceneSphere, SpotLight,
    UniformInfiniteLight,
};
use crate::camera::CameraTransform;
use crate::image::equiarea::{env_map_layout, equirect_to_equal_area, EnvMapLayout};
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::params::{unknown_type, ParamReader};
use crate::shape::{Shape, ShapeMethods};
use crate::spectrum::{spectrum_to_photometric, RgbColorSpace, Spectrum, SpectrumType};
use crate::texture::FloatTextureRef;

/// The light types `LightSource` accepts, sorted.
pub const LIGHT_NAMES: &[&str] = &[
    "distant",
    "goniometric",
    "infinite",
    "point",
    "projection",
    "spot",
];

/// An illuminant spectrum parameter, or `None` when absent.
fn spectrum_param(lp: &ParamReader, name: &str) -> Result<Option<Spectrum>, Diagnostic> {
    lp.spectrum(name, SpectrumType::Illuminant)
}

/// `scale`, which must not be negative.
fn scale_param(lp: &ParamReader) -> Result<Float, Diagnostic> {
    let s = lp.float("scale", 1.0)?;
    if s.is_nan() || s < 0.0 || !s.is_finite() {
        return Err(lp.error_at(
            "scale",
            format!("\"scale\" {s} must be finite and non-negative"),
        ));
    }
    Ok(s)
}

/// `scale / SpectrumToPhotometric(s)`, guarding a spectrum with no
/// luminance.
fn normalize_scale(
    scale: Float,
    s: &Spectrum,
    what: &str,
    loc: &FileLoc,
) -> Result<Float, Diagnostic> {
    let y = spectrum_to_photometric(s);
    if y.is_nan() || y <= 0.0 {
        return Err(Diagnostic::error(
            loc.clone(),
            format!("{what} spectrum has no visible emission (zero luminance)"),
        ));
    }
    Ok(scale / y)
}

fn point3(lp: &ParamReader, name: &str, def: [f32; 3]) -> Result<Point3f, Diagnostic> {
    let p = lp.point3(name, def)?;
    Ok(Point3f::new(p[0], p[1], p[2]))
}

/// A transform whose columns are the given axes (light-space x, y, z to
/// the axes).
fn from_axes(x: Vector3f, y: Vector3f, z: Vector3f) -> Transform {
    let m = SquareMatrix4::new([
        [x.x, y.x, z.x, 0.0],
        [x.y, y.y, z.y, 0.0],
        [x.z, y.z, z.z, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    // Orthonormal axes: always invertible.
    Transform::from_matrix(m).unwrap_or_default()
}

/// Reads an image, with located errors.
fn read_image(
    lp: &ParamReader,
    filename: &str,
) -> Result<(Image, &'static RgbColorSpace), Diagnostic> {
    let path = lp.resolve("filename", filename);
    let im = Image::read_within(&path, None, lp.budget())
        .map_err(|e| lp.error_at("filename", format!("{e}")))?;
    let cs_name = im.metadata.color_space_name();
    let cs = RgbColorSpace::get(cs_name)
        .ok_or_else(|| lp.error_at("filename", format!("\"{cs_name}\": unknown colour space")))?;
    Ok((im.image, cs))
}

/// The R, G, B channels of `image` alone.
fn rgb_image(
    image: &Image,
    filename: &str,
    what: &str,
    loc: &FileLoc,
) -> Result<Image, Diagnostic> {
    let desc = image.get_channel_desc(&["R", "G", "B"]).ok_or_else(|| {
        Diagnostic::error(
            loc.clone(),
            format!(
                "{filename}: image provided to \"{what}\" light must have R, G, and B channels"
            ),
        )
    })?;
    Ok(image.select_channels(&desc))
}

/// pbrt-v3's goniometric map, a latitude–longitude image of any size
/// (`(φ/2π, θ/π)` of the light-space direction with y and z swapped, the
/// swap pbrt-v4 also makes), resampled to the equal-area square pbrt-v4's
/// light reads: `2h` texels a side for a `2h × h` map (as an environment
/// map converts), else about twice the map's texel count. pbrt-v4 averages
/// R, G and B where pbrt-v3 kept the colour: a coloured map warns.
fn v3_goniometric_map(
    lp: &ParamReader,
    im: &Image,
    filename: &str,
    loc: &FileLoc,
) -> Result<Image, Diagnostic> {
    let res = im.resolution();
    let n = if res.x == 2 * res.y {
        res.x
    } else {
        ((2.0 * res.x as f64 * res.y as f64).sqrt().ceil() as i32).max(1)
    };
    let bytes = n as u64 * n as u64 * im.n_channels() as u64 * 4;
    lp.charge(bytes, "goniometric map")?;
    if let Some(desc) = im.get_channel_desc(&["R", "G", "B"]) {
        let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
        let coloured = (0..res.y).any(|y| {
            (0..res.x).any(|x| {
                let v = im.get_channels_desc(Point2i::new(x, y), &desc, clamp);
                v[0] != v[1] || v[1] != v[2]
            })
        });
        if coloured {
            lp.warn_located(
                loc.clone(),
                format!(
                    "{filename}: pbrt-v4's goniometric light uses the average of R, G and B; \
                     pbrt-v3 kept this map's colour"
                ),
            );
        }
    }
    equirect_to_equal_area(im, n)
        .map_err(|e| Diagnostic::error(loc.clone(), format!("{filename}: {e}")))
}

/// A float copy of the RGB `image` with its channels multiplied by `f`.
fn scaled_rgb(image: &Image, f: [Float; 3], loc: &FileLoc) -> Result<Image, Diagnostic> {
    let res = image.resolution();
    let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
    let mut data = Vec::with_capacity(res.x as usize * res.y as usize * 3);
    for y in 0..res.y {
        for x in 0..res.x {
            for (c, k) in f.iter().enumerate() {
                data.push(image.get_channel(Point2i::new(x, y), c, clamp) * k);
            }
        }
    }
    Image::from_f32(data, res, &["R", "G", "B"])
        .map_err(|e| Diagnostic::error(loc.clone(), e.to_string()))
}

/// Which of pbrt-v3's meanings a `LightSource` directive takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightDialect {
    /// The directive named its image `mapname`: an `infinite` light's
    /// image is then pbrt-v3's latitude–longitude map.
    pub v3_mapname: bool,
    /// The scene is a pbrt-v3 file: a `goniometric` light without an image
    /// is pbrt-v3's uniform point light and a `projection` light without
    /// one projects `I` over its frustum (pbrt-v4 requires the image), and
    /// a `projection` light's `fov` defaults to pbrt-v3's 45 degrees.
    pub v3_file: bool,
}

/// Creates the light of a `LightSource` directive in `medium`, with
/// unused-parameter warnings. `camera_transform` takes infinite-light
/// portals, given in world space, into render space; `dialect` says which
/// pbrt-v3 meanings apply.
pub fn create_light(
    name: &str,
    lp: &ParamReader,
    render_from_light: &AnimatedTransform,
    medium: Option<MediumId>,
    camera_transform: &CameraTransform,
    dialect: LightDialect,
) -> Result<Light, Diagnostic> {
    let cs = lp.color_space();
    let loc = lp.loc();
    if render_from_light.is_animated() {
        lp.warn("animated lights aren't supported; using the start transform");
    }
    let render_from_light = render_from_light.start_transform();

    let light = match name {
        "point" => {
            let i = spectrum_param(lp, "I")?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(lp)?, &i, "\"I\"", loc)?;
            let power = lp.float("power", -1.0)?;
            if power > 0.0 {
                scale *= power / (4.0 * PI);
            }
            let from = point3(lp, "from", [0.0; 3])?;
            Light::Point(PointLight {
                render_from_light: render_from_light * Transform::translate(Vector3f::from(from)),
                i: dense(&i),
                scale,
                medium,
            })
        }
        "spot" => {
            let i = spectrum_param(lp, "I")?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(lp)?, &i, "\"I\"", loc)?;
            let coneangle = lp.float("coneangle", 30.0)?;
            let conedelta = lp.float("conedeltaangle", 5.0)?;
            let from = point3(lp, "from", [0.0; 3])?;
            let to = point3(lp, "to", [0.0, 0.0, 1.0])?;
            let dir = (to - from).try_normalize().ok_or_else(|| {
                Diagnostic::error(
                    lp.param_loc("to"),
                    "spot light \"from\" and \"to\" coincide",
                )
            })?;
            let f = Frame::from_z(dir);
            let light_from_spot =
                Transform::translate(Vector3f::from(from)) * from_axes(f.x, f.y, f.z);
            let cos_falloff_end = coneangle.to_radians().cos();
            let cos_falloff_start = (coneangle - conedelta).to_radians().cos();
            let power = lp.float("power", -1.0)?;
            if power > 0.0 {
                let k_e = 2.0
                    * PI
                    * ((1.0 - cos_falloff_start) + (cos_falloff_start - cos_falloff_end) / 2.0);
                scale *= power / k_e;
            }
            Light::Spot(SpotLight {
                render_from_light: render_from_light * light_from_spot,
                i: dense(&i),
                scale,
                cos_falloff_start,
                cos_falloff_end,
                medium,
            })
        }
        "goniometric" => {
            let i = spectrum_param(lp, "I")?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(lp)?, &i, "\"I\"", loc)?;
            let filename = lp.string("filename", "")?;
            let power = lp.float("power", -1.0)?;
            if filename.is_empty() && dialect.v3_file {
                // pbrt-v3 (`lights/goniometric.cpp`): without a map the
                // distribution is 1 everywhere, a point light.
                if power > 0.0 {
                    scale *= power / (4.0 * PI);
                }
                return Ok(Light::Point(PointLight {
                    render_from_light,
                    i: dense(&i),
                    scale,
                    medium,
                }));
            }
            if filename.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "must provide \"filename\" to \"goniometric\" light source",
                ));
            }
            let floc = lp.param_loc("filename");
            let (im, _) = read_image(lp, &filename)?;
            let im = if dialect.v3_file {
                v3_goniometric_map(lp, &im, &filename, &floc)?
            } else {
                im
            };
            let image = goniometric_image(&im, &filename, &floc)?;
            if power > 0.0 {
                let res = image.resolution();
                let wrap = WrapMode2D::new(WrapMode::OctahedralSphere, WrapMode::OctahedralSphere);
                let mut sum = 0.0f64;
                for y in 0..res.y {
                    for x in 0..res.x {
                        sum += image.get_channel(Point2i::new(x, y), 0, wrap) as f64;
                    }
                }
                let k_e = 4.0 * PI * sum as Float / (res.x as Float * res.y as Float);
                if k_e > 0.0 {
                    scale *= power / k_e;
                }
            }
            // pbrt-v4 swaps y and z so that goniometric diagrams have +y up.
            let swap_yz = from_axes(
                Vector3f::new(1.0, 0.0, 0.0),
                Vector3f::new(0.0, 0.0, 1.0),
                Vector3f::new(0.0, 1.0, 0.0),
            );
            Light::Goniometric(Box::new(GoniometricLight::new(
                render_from_light * swap_yz,
                dense(&i),
                scale,
                image,
                medium,
            )))
        }
        "projection" => {
            let scale = scale_param(lp)?;
            let power = lp.float("power", -1.0)?;
            // pbrt-v3's default field of view is 45 degrees, pbrt-v4's 90.
            let fov = lp.float("fov", if dialect.v3_file { 45.0 } else { 90.0 })?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(Diagnostic::error(
                    lp.param_loc("fov"),
                    format!("\"fov\" {fov} must be in (0, 180) degrees"),
                ));
            }
            let filename = lp.string("filename", "")?;
            let flip = Transform::scale(1.0, -1.0, 1.0);
            let mut light = if filename.is_empty() && dialect.v3_file {
                // pbrt-v3 (`lights/projection.cpp`): without a map, `I`
                // over the square frustum (aspect 1), nothing outside it.
                let i = spectrum_param(lp, "I")?.unwrap_or_else(|| cs.illuminant_spectrum());
                let scale = normalize_scale(scale, &i, "\"I\"", loc)?;
                let white = Image::from_f32(vec![1.0; 3], Point2i::new(1, 1), &["R", "G", "B"])
                    .map_err(|e| Diagnostic::error(loc.clone(), e.to_string()))?;
                let mut l =
                    ProjectionLight::new(render_from_light * flip, white, cs, scale, fov, medium);
                l.constant_i = Some(dense(&i));
                l
            } else {
                if filename.is_empty() {
                    return Err(Diagnostic::error(
                        loc.clone(),
                        "must provide \"filename\" to \"projection\" light source",
                    ));
                }
                let floc = lp.param_loc("filename");
                let (im, ics) = read_image(lp, &filename)?;
                let mut image = rgb_image(&im, &filename, "projection", &floc)?;
                let res = image.resolution();
                if res.x <= 0 || res.y <= 0 {
                    return Err(Diagnostic::error(floc, format!("{filename}: empty image")));
                }
                // pbrt-v3 multiplies its map by `I` (an RGB here: the
                // upgrade folds a uniform one into `scale`).
                if dialect.v3_file && lp.param_type("I") == Some("rgb") {
                    if let Some(&[r, g, b]) = lp.rgbs("I")?.first() {
                        image = scaled_rgb(&image, [r, g, b], &floc)?;
                    }
                }
                let scale =
                    normalize_scale(scale, &ics.illuminant_spectrum(), "image colour space", loc)?;
                ProjectionLight::new(render_from_light * flip, image, ics, scale, fov, medium)
            };
            let res = light.image.resolution();
            let ics = light.color_space;
            if power > 0.0 && light.constant_i.is_some() {
                // The spectrum has unit luminance after normalization.
                light.scale *= power / light.solid_angle();
            } else if power > 0.0 {
                let lum = luminance_vector(ics);
                let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
                let mut sum = 0.0f64;
                for y in 0..res.y {
                    for x in 0..res.x {
                        let dwda = light.dwda(light.pixel_screen(x, y));
                        for (c, l) in lum.iter().enumerate() {
                            sum += (light.image.get_channel(Point2i::new(x, y), c, clamp)
                                * l
                                * dwda) as f64;
                        }
                    }
                }
                let k_e = light.a * sum as Float / (res.x as Float * res.y as Float);
                if k_e > 0.0 {
                    light.scale *= power / k_e;
                }
            }
            Light::Projection(Box::new(light))
        }
        "distant" => {
            let l = spectrum_param(lp, "L")?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(lp)?, &l, "\"L\"", loc)?;
            let from = point3(lp, "from", [0.0; 3])?;
            let to = point3(lp, "to", [0.0, 0.0, 1.0])?;
            let w = (from - to).try_normalize().ok_or_else(|| {
                Diagnostic::error(
                    lp.param_loc("to"),
                    "distant light \"from\" and \"to\" coincide",
                )
            })?;
            let (v1, v2) = w.coordinate_system();
            // Illuminance is measured on a surface facing the light.
            let e_v = lp.float("illuminance", -1.0)?;
            if e_v > 0.0 {
                scale *= e_v;
            }
            Light::Distant(DistantLight {
                render_from_light: render_from_light * from_axes(v1, v2, w),
                l_emit: dense(&l),
                scale,
                scene: SceneSphere::default(),
            })
        }
        "infinite" => create_infinite(lp, render_from_light, camera_transform, dialect.v3_mapname)?,
        other => return Err(unknown_type("light", other, LIGHT_NAMES, loc)),
    };
    Ok(light)
}

/// A single-channel image from an RGB (channel average) or Y image, which
/// must be square (the equal-area layout).
fn goniometric_image(im: &Image, filename: &str, loc: &FileLoc) -> Result<Image, Diagnostic> {
    let res = im.resolution();
    if res.x != res.y || res.x <= 0 {
        return Err(Diagnostic::error(
            loc.clone(),
            format!(
                "{filename}: image resolution ({}, {}) is non-square; it is unlikely to be an \
                 equal-area environment map",
                res.x, res.y
            ),
        ));
    }
    let rgb = im.get_channel_desc(&["R", "G", "B"]);
    let y = im.get_channel_desc(&["Y"]);
    let wrap = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
    match (rgb, y) {
        (Some(_), Some(_)) => Err(Diagnostic::error(
            loc.clone(),
            format!("{filename}: has both \"R\", \"G\", \"B\" and \"Y\" channels"),
        )),
        (Some(desc), None) => {
            let mut data = Vec::with_capacity((res.x * res.y) as usize);
            for yy in 0..res.y {
                for x in 0..res.x {
                    data.push(
                        im.get_channels_desc(Point2i::new(x, yy), &desc, wrap)
                            .average(),
                    );
                }
            }
            Image::from_f32(data, res, &["Y"])
                .map_err(|e| Diagnostic::error(loc.clone(), format!("{e}")))
        }
        (None, Some(desc)) => Ok(im.select_channels(&desc)),
        (None, None) => Err(Diagnostic::error(
            loc.clone(),
            format!("{filename}: has neither \"R\", \"G\", \"B\" nor \"Y\" channels"),
        )),
    }
}

/// An infinite light's map in pbrt-v4's equal-area layout. A pbrt-v3 map
/// (`pbrt_v3`) or a 2:1 one is a latitude–longitude map: it is resampled
/// (at pbrt-v4 `makeequiarea`'s default resolution, the map's width) with a
/// located warning. A square map of a pbrt-v4 file is used as it is; any
/// other shape is a located error.
fn equal_area_env_map(
    lp: &ParamReader,
    image: Image,
    filename: &str,
    floc: &FileLoc,
    pbrt_v3: bool,
) -> Result<Image, Diagnostic> {
    let res = image.resolution();
    match env_map_layout(res) {
        None => Err(Diagnostic::error(
            floc.clone(),
            format!(
                "{filename}: environment map resolution ({}, {}) is neither square (pbrt-v4's \
                 equal-area layout) nor 2:1 (a latitude-longitude map)",
                res.x, res.y
            ),
        )),
        Some(EnvMapLayout::EqualArea) if !pbrt_v3 => Ok(image),
        Some(_) => {
            let n = res.x;
            let why = if pbrt_v3 {
                "a pbrt-v3 \"mapname\""
            } else {
                "2:1"
            };
            lp.warn_located(
                floc.clone(),
                format!(
                    "{filename}: {}x{} latitude-longitude environment map ({why}) resampled to the \
                     {n}x{n} equal-area map pbrt-v4 needs, with pbrt-v3's orientation; convert it \
                     once with \"rpbrt imgtool makeequiarea\" to skip this",
                    res.x, res.y
                ),
            );
            equirect_to_equal_area(&image, n)
                .map_err(|e| Diagnostic::error(floc.clone(), format!("{filename}: {e}")))
        }
    }
}

fn create_infinite(
    lp: &ParamReader,
    render_from_light: Transform,
    camera_transform: &CameraTransform,
    pbrt_v3: bool,
) -> Result<Light, Diagnostic> {
    let cs = lp.color_space();
    let loc = lp.loc();
    let filename = lp.string("filename", "")?;
    // pbrt-v3 multiplies its map by `L` (an RGB here: the upgrade folds a
    // uniform one into `scale`, and a colour `scale` into it).
    let v3_map_factor = if pbrt_v3 && !filename.is_empty() && lp.param_type("L") == Some("rgb") {
        lp.rgbs("L")?.first().copied()
    } else {
        None
    };
    let l = match v3_map_factor {
        Some(_) => None,
        None => spectrum_param(lp, "L")?,
    };
    let scale = scale_param(lp)?;
    let portal = lp.point3s("portal")?;
    let e_v = lp.float("illuminance", -1.0)?;
    if l.is_some() && !portal.is_empty() {
        return Err(Diagnostic::error(
            lp.param_loc("portal"),
            "portals are not supported for infinite lights without \"filename\"",
        ));
    }
    if l.is_some() && !filename.is_empty() {
        return Err(Diagnostic::error(
            loc.clone(),
            "can't specify both \"L\" and \"filename\" with an infinite light",
        ));
    }
    if filename.is_empty() {
        let l = l.unwrap_or_else(|| cs.illuminant_spectrum());
        let mut scale = normalize_scale(scale, &l, "\"L\"", loc)?;
        if e_v > 0.0 {
            // Uniform radiance 1 gives illuminance π on an upward patch.
            scale *= e_v / PI;
        }
        return Ok(Light::UniformInfinite(UniformInfiniteLight {
            l_emit: dense(&l),
            scale,
            scene: SceneSphere::default(),
        }));
    }
    let floc = lp.param_loc("filename");
    let (im, ics) = read_image(lp, &filename)?;
    let image = rgb_image(&im, &filename, "infinite", &floc)?;
    let mut image = equal_area_env_map(lp, image, &filename, &floc, pbrt_v3)?;
    if let Some([r, g, b]) = v3_map_factor {
        image = scaled_rgb(&image, [r, g, b], &floc)?;
    }
    let res = image.resolution();
    let mut scale = normalize_scale(scale, &ics.illuminant_spectrum(), "image colour space", loc)?;
    if e_v > 0.0 {
        // Illuminance on an upward-facing (light-space +z) patch: each
        // equal-area pixel subtends 4π / N steradians.
        let lum = luminance_vector(ics);
        let wrap = WrapMode2D::new(WrapMode::OctahedralSphere, WrapMode::OctahedralSphere);
        let mut k_e = 0.0f64;
        for y in 0..res.y {
            for x in 0..res.x {
                let uv = Point2f::new(
                    (x as Float + 0.5) / res.x as Float,
                    (y as Float + 0.5) / res.y as Float,
                );
                let w = equal_area_square_to_sphere(uv);
                if w.z <= 0.0 {
                    continue;
                }
                for (c, l) in lum.iter().enumerate() {
                    k_e += (image.get_channel(Point2i::new(x, y), c, wrap) * l * w.z) as f64;
                }
            }
        }
        // pbrt-v4 multiplies by 2π/N here (each equal-area pixel covers
        // 4π/N sr, so the map's true illuminance is twice this); rpbrt keeps
        // pbrt-v4's factor so that scenes using "illuminance" render at the
        // same brightness as in pbrt-v4.
        let k_e = k_e as Float * 2.0 * PI / (res.x as Float * res.y as Float);
        if k_e > 0.0 {
            scale *= e_v / k_e;
        }
    }
    if !portal.is_empty() {
        let ploc = lp.param_loc("portal");
        let corners: [Point3f; 4] = match portal.as_slice() {
            [a, b, c, d] => [*a, *b, *c, *d].map(|p| {
                camera_transform
                    .render_from_world()
                    .apply_point(Point3f::new(p[0], p[1], p[2]))
            }),
            _ => {
                return Err(Diagnostic::error(
                    ploc,
                    format!(
                        "expected 4 vertices for infinite light portal but given {}",
                        portal.len()
                    ),
                ))
            }
        };
        let light = PortalImageInfiniteLight::new(render_from_light, &image, ics, scale, corners)
            .map_err(|msg| Diagnostic::error(ploc, msg))?;
        return Ok(Light::PortalImageInfinite(Box::new(light)));
    }
    Ok(Light::ImageInfinite(Box::new(ImageInfiniteLight::new(
        render_from_light,
        image,
        ics,
        scale,
    ))))
}

/// The area light types `AreaLightSource` accepts.
pub const AREA_LIGHT_NAMES: &[&str] = &["diffuse"];

/// Creates the `diffuse` area light of an `AreaLightSource` directive for
/// one shape (already in render space; `render_from_object` is the
/// shape's placement, kept for pbrt-v4 parity). `alpha` masks emission.
/// Unused parameters are not reported here, since one directive serves
/// many shapes: the caller reports them once, after its last shape.
pub fn create_area_light(
    name: &str,
    lp: &ParamReader,
    render_from_object: &Transform,
    shape: &Shape,
    alpha: Option<FloatTextureRef>,
    medium_inside: Option<MediumId>,
    medium_outside: Option<MediumId>,
) -> Result<Light, Diagnostic> {
    let _ = render_from_object;
    let loc = lp.loc();
    if name != "diffuse" {
        return Err(unknown_type("area light", name, AREA_LIGHT_NAMES, loc));
    }
    let cs = lp.color_space();
    let l = spectrum_param(lp, "L")?;
    let scale = scale_param(lp)?;
    let two_sided = lp.bool("twosided", false)?;
    let filename = lp.string("filename", "")?;
    let power = lp.float("power", -1.0)?;
    let area = shape.area();

    let (emission, norm_spectrum, image_cs) = if !filename.is_empty() {
        if l.is_some() {
            return Err(Diagnostic::error(
                loc.clone(),
                "both \"L\" and \"filename\" specified for diffuse area light",
            ));
        }
        let floc = lp.param_loc("filename");
        let (im, ics) = read_image(lp, &filename)?;
        let image = rgb_image(&im, &filename, "diffuse", &floc)?;
        if image.resolution().x <= 0 || image.resolution().y <= 0 {
            return Err(Diagnostic::error(floc, format!("{filename}: empty image")));
        }
        (
            AreaEmission::Image(image, ics),
            cs.illuminant_spectrum(),
            Some(ics),
        )
    } else {
        let l = l.unwrap_or_else(|| cs.illuminant_spectrum());
        (AreaEmission::Spectrum(dense(&l)), l, None)
    };
    let mut scale = normalize_scale(scale, &norm_spectrum, "\"L\"", loc)?;
    if power > 0.0 {
        let mut k_e: Float = 1.0;
        if let (AreaEmission::Image(image, _), Some(ics)) = (&emission, image_cs) {
            let lum = luminance_vector(ics);
            let res = image.resolution();
            let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
            let mut sum = 0.0f64;
            for y in 0..res.y {
                for x in 0..res.x {
                    for (c, lw) in lum.iter().enumerate() {
                        sum += (image.get_channel(Point2i::new(x, y), c, clamp) * lw) as f64;
                    }
                }
            }
            k_e = sum as Float / (res.x as Float * res.y as Float);
        }
        k_e *= if two_sided { 2.0 } else { 1.0 } * area * PI;
        if k_e > 0.0 {
            scale *= power / k_e;
        }
    }
    Ok(Light::DiffuseArea(Box::new(
        DiffuseAreaLight {
            shape: shape.clone(),
            area,
            emission,
            scale,
            two_sided,
            alpha,
            medium_inside,
            medium_outside,
            sampled_triangle: None,
        }
        .with_cache(),
    )))
}
