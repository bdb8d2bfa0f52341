//! Creating lights from `LightSource` and `AreaLightSource` directives
//! (pbrt-v4 `Light::Create` and the lights' `Create` functions): pbrt-v4's
//! parameter names and defaults, its photometric normalisation
//! (`scale /= SpectrumToPhotometric(spectrum)`) and its `power` /
//! `illuminance` targets, with located errors.

use std::path::{Path, PathBuf};

use rpbrt_geometry::{
    equal_area_square_to_sphere, Float, Frame, MediumId, Point2f, Point2i, Point3f, SquareMatrix4,
    Transform, Vector3f, PI,
};
use rpbrt_parser::{Diagnostic, FileLoc, ParamError, ParameterDictionary};

use super::area::AreaEmission;
use super::{
    dense, luminance_vector, DiffuseAreaLight, DistantLight, GoniometricLight, ImageInfiniteLight,
    Light, PointLight, PortalImageInfiniteLight, ProjectionLight, SceneSphere, SpotLight,
    UniformInfiniteLight,
};
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::scene::entities::{CameraTransform, LightSceneEntity, SceneEntity};
use crate::shape::{Shape, ShapeMethods};
use crate::spectrum::{
    spectrum_from_param, spectrum_to_photometric, RgbColorSpace, Spectrum, SpectrumType,
};
use crate::texture::FloatTextureRef;

/// The light types `LightSource` accepts.
pub const LIGHT_NAMES: &[&str] = &[
    "point",
    "spot",
    "goniometric",
    "projection",
    "distant",
    "infinite",
];

fn perr(e: ParamError) -> Diagnostic {
    Diagnostic::from(e)
}

/// The location of parameter `name`, or the directive's.
fn at(params: &ParameterDictionary, name: &str, loc: &FileLoc) -> FileLoc {
    params.loc(name).cloned().unwrap_or_else(|| loc.clone())
}

/// Resolves a file name against the scene file's directory (pbrt-v4
/// `ResolveFilename`).
fn resolve(loc: &FileLoc, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    let dir = Path::new(&*loc.file)
        .parent()
        .unwrap_or_else(|| Path::new("."));
    let joined = dir.join(p);
    if joined.exists() {
        joined
    } else {
        p.to_path_buf()
    }
}

fn base_dir(loc: &FileLoc) -> PathBuf {
    Path::new(&*loc.file)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn color_space(name: &str, loc: &FileLoc) -> Result<&'static RgbColorSpace, Diagnostic> {
    RgbColorSpace::get(name)
        .ok_or_else(|| Diagnostic::error(loc.clone(), format!("\"{name}\": unknown colour space")))
}

/// An illuminant spectrum parameter, or `None` when absent.
fn spectrum_param(
    params: &ParameterDictionary,
    name: &str,
    cs: &RgbColorSpace,
    loc: &FileLoc,
) -> Result<Option<Spectrum>, Diagnostic> {
    let Some(v) = params.get_one_spectrum(name).map_err(perr)? else {
        return Ok(None);
    };
    let ploc = at(params, name, loc);
    spectrum_from_param(&v, SpectrumType::Illuminant, cs, &base_dir(&ploc))
        .map(Some)
        .map_err(|e| Diagnostic::error(ploc, format!("\"{name}\": {e}")))
}

/// `scale`, which must not be negative.
fn scale_param(params: &ParameterDictionary, loc: &FileLoc) -> Result<Float, Diagnostic> {
    let s = params.get_one_float("scale", 1.0).map_err(perr)?;
    if s.is_nan() || s < 0.0 || !s.is_finite() {
        return Err(Diagnostic::error(
            at(params, "scale", loc),
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

fn point3(params: &ParameterDictionary, name: &str, def: [f32; 3]) -> Result<Point3f, Diagnostic> {
    let p = params.get_one_point3(name, def).map_err(perr)?;
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
    params: &ParameterDictionary,
    filename: &str,
    loc: &FileLoc,
) -> Result<(Image, &'static RgbColorSpace), Diagnostic> {
    let floc = at(params, "filename", loc);
    let path = resolve(&floc, filename);
    let im =
        Image::read(&path, None).map_err(|e| Diagnostic::error(floc.clone(), format!("{e}")))?;
    let cs_name = im.metadata.color_space_name().to_string();
    let cs = color_space(&cs_name, &floc)?;
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

/// Creates the light of a `LightSource` directive in `medium`, with
/// unused-parameter warnings. `camera_transform` takes infinite-light
/// portals, given in world space, into render space.
pub fn create_light(
    entity: &LightSceneEntity,
    medium: Option<MediumId>,
    camera_transform: &CameraTransform,
) -> Result<(Light, Vec<Diagnostic>), Diagnostic> {
    let base = &entity.base;
    let params = &base.params;
    let loc = &base.loc;
    let cs = color_space(&base.color_space, loc)?;
    let mut warnings = Vec::new();
    if entity.render_from_object.is_animated() {
        warnings.push(Diagnostic::warning(
            loc.clone(),
            "animated lights aren't supported; using the start transform",
        ));
    }
    let render_from_light = entity.render_from_object.start_transform;

    let light = match base.name.as_str() {
        "point" => {
            let i =
                spectrum_param(params, "I", cs, loc)?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(params, loc)?, &i, "\"I\"", loc)?;
            let power = params.get_one_float("power", -1.0).map_err(perr)?;
            if power > 0.0 {
                scale *= power / (4.0 * PI);
            }
            let from = point3(params, "from", [0.0; 3])?;
            Light::Point(PointLight {
                render_from_light: render_from_light * Transform::translate(Vector3f::from(from)),
                i: dense(&i),
                scale,
                medium,
            })
        }
        "spot" => {
            let i =
                spectrum_param(params, "I", cs, loc)?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(params, loc)?, &i, "\"I\"", loc)?;
            let coneangle = params.get_one_float("coneangle", 30.0).map_err(perr)?;
            let conedelta = params.get_one_float("conedelta", 5.0).map_err(perr)?;
            let from = point3(params, "from", [0.0; 3])?;
            let to = point3(params, "to", [0.0, 0.0, 1.0])?;
            let dir = (to - from).try_normalize().ok_or_else(|| {
                Diagnostic::error(
                    at(params, "to", loc),
                    "spot light \"from\" and \"to\" coincide",
                )
            })?;
            let f = Frame::from_z(dir);
            let light_from_spot =
                Transform::translate(Vector3f::from(from)) * from_axes(f.x, f.y, f.z);
            let cos_falloff_end = coneangle.to_radians().cos();
            let cos_falloff_start = (coneangle - conedelta).to_radians().cos();
            let power = params.get_one_float("power", -1.0).map_err(perr)?;
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
            let i =
                spectrum_param(params, "I", cs, loc)?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(params, loc)?, &i, "\"I\"", loc)?;
            let filename = params.get_one_string("filename", "").map_err(perr)?;
            if filename.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "must provide \"filename\" to \"goniometric\" light source",
                ));
            }
            let floc = at(params, "filename", loc);
            let (im, _) = read_image(params, &filename, loc)?;
            let image = goniometric_image(&im, &filename, &floc)?;
            let power = params.get_one_float("power", -1.0).map_err(perr)?;
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
            Light::Goniometric(Box::new(GoniometricLight {
                render_from_light: render_from_light * swap_yz,
                i: dense(&i),
                scale,
                image,
                medium,
            }))
        }
        "projection" => {
            let scale = scale_param(params, loc)?;
            let power = params.get_one_float("power", -1.0).map_err(perr)?;
            let fov = params.get_one_float("fov", 90.0).map_err(perr)?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(Diagnostic::error(
                    at(params, "fov", loc),
                    format!("\"fov\" {fov} must be in (0, 180) degrees"),
                ));
            }
            let filename = params.get_one_string("filename", "").map_err(perr)?;
            if filename.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "must provide \"filename\" to \"projection\" light source",
                ));
            }
            let floc = at(params, "filename", loc);
            let (im, ics) = read_image(params, &filename, loc)?;
            let image = rgb_image(&im, &filename, "projection", &floc)?;
            let res = image.resolution();
            if res.x <= 0 || res.y <= 0 {
                return Err(Diagnostic::error(floc, format!("{filename}: empty image")));
            }
            let flip = Transform::scale(1.0, -1.0, 1.0);
            let scale =
                normalize_scale(scale, &ics.illuminant_spectrum(), "image colour space", loc)?;
            let mut light =
                ProjectionLight::new(render_from_light * flip, image, ics, scale, fov, medium);
            if power > 0.0 {
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
            let l =
                spectrum_param(params, "L", cs, loc)?.unwrap_or_else(|| cs.illuminant_spectrum());
            let mut scale = normalize_scale(scale_param(params, loc)?, &l, "\"L\"", loc)?;
            let from = point3(params, "from", [0.0; 3])?;
            let to = point3(params, "to", [0.0, 0.0, 1.0])?;
            let w = (from - to).try_normalize().ok_or_else(|| {
                Diagnostic::error(
                    at(params, "to", loc),
                    "distant light \"from\" and \"to\" coincide",
                )
            })?;
            let (v1, v2) = w.coordinate_system();
            // Illuminance is measured on a surface facing the light.
            let e_v = params.get_one_float("illuminance", -1.0).map_err(perr)?;
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
        "infinite" => create_infinite(params, loc, cs, render_from_light, camera_transform)?,
        other => {
            return Err(Diagnostic::error(
                loc.clone(),
                format!(
                    "\"{other}\": light type unknown (known: {})",
                    LIGHT_NAMES.join(", ")
                ),
            ))
        }
    };
    warnings.extend(params.report_unused());
    Ok((light, warnings))
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

fn create_infinite(
    params: &ParameterDictionary,
    loc: &FileLoc,
    cs: &'static RgbColorSpace,
    render_from_light: Transform,
    camera_transform: &CameraTransform,
) -> Result<Light, Diagnostic> {
    let l = spectrum_param(params, "L", cs, loc)?;
    let scale = scale_param(params, loc)?;
    let portal = params.get_point3_array("portal").map_err(perr)?;
    let filename = params.get_one_string("filename", "").map_err(perr)?;
    let e_v = params.get_one_float("illuminance", -1.0).map_err(perr)?;
    if l.is_some() && !portal.is_empty() {
        return Err(Diagnostic::error(
            at(params, "portal", loc),
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
    let floc = at(params, "filename", loc);
    let (im, ics) = read_image(params, &filename, loc)?;
    let image = rgb_image(&im, &filename, "infinite", &floc)?;
    let res = image.resolution();
    if res.x != res.y || res.x <= 0 {
        return Err(Diagnostic::error(
            floc,
            format!(
                "{filename}: image resolution ({}, {}) is non-square; it is unlikely to be an \
                 equal-area environment map",
                res.x, res.y
            ),
        ));
    }
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
        let ploc = at(params, "portal", loc);
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

/// Creates the `diffuse` area light of an `AreaLightSource` directive for
/// one shape (already in render space; `render_from_object` is the
/// shape's placement, kept for pbrt-v4 parity). `alpha` masks emission.
/// Unused parameters are not reported here, since one directive serves
/// many shapes: call `entity.params.report_unused()` once afterwards.
pub fn create_area_light(
    entity: &SceneEntity,
    render_from_object: &Transform,
    shape: &Shape,
    alpha: Option<FloatTextureRef>,
    medium_inside: Option<MediumId>,
    medium_outside: Option<MediumId>,
) -> Result<Light, Diagnostic> {
    let _ = render_from_object;
    let params = &entity.params;
    let loc = &entity.loc;
    if entity.name != "diffuse" {
        return Err(Diagnostic::error(
            loc.clone(),
            format!(
                "\"{}\": area light type unknown (known: diffuse)",
                entity.name
            ),
        ));
    }
    let cs = color_space(&entity.color_space, loc)?;
    let l = spectrum_param(params, "L", cs, loc)?;
    let scale = scale_param(params, loc)?;
    let two_sided = params.get_one_bool("twosided", false).map_err(perr)?;
    let filename = params.get_one_string("filename", "").map_err(perr)?;
    let power = params.get_one_float("power", -1.0).map_err(perr)?;
    let area = shape.area();

    let (emission, norm_spectrum, image_cs) = if !filename.is_empty() {
        if l.is_some() {
            return Err(Diagnostic::error(
                loc.clone(),
                "both \"L\" and \"filename\" specified for diffuse area light",
            ));
        }
        let floc = at(params, "filename", loc);
        let (im, ics) = read_image(params, &filename, loc)?;
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
