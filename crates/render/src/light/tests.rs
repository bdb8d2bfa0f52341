//! Light tests in the style of pbrt-v4's `lights_test.cpp`: sampling
//! densities against `pdf_li`, radiance against `l`/`le`, emitted power
//! against numerical integrals and the `power`/`illuminance` targets.

use std::sync::Arc;

use rpbrt_geometry::{
    equal_area_square_to_sphere, AnimatedTransform, Float, Normal3f, Point2f, Point2i, Point3f,
    Ray, Transform, Vector3f, PI,
};
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary, ParsedParameter};

use super::*;
use crate::camera::CameraTransform;

mod envmap;
mod le;
use crate::image::Image;
use crate::params::ParamReader;
use crate::rng::Rng;
use crate::sampling::sample_uniform_sphere;
use crate::shape::{Disk, Shape, ShapeMethods};
use crate::spectrum::{spectrum_to_photometric, RgbColorSpace, SampledWavelengths};

/// Where the light directive is.
fn loc() -> FileLoc {
    FileLoc::new(Arc::from("test.pbrt"), 1, 1)
}

thread_local! {
    static NEXT_LINE: std::cell::Cell<u32> = const { std::cell::Cell::new(10) };
}

/// A fresh location for a parameter: each parameter of a test is on a
/// line of its own, so that error locations are checked for real.
fn ploc() -> FileLoc {
    let line = NEXT_LINE.with(|n| {
        let l = n.get();
        n.set(l + 1);
        l
    });
    FileLoc::new(Arc::from("test.pbrt"), line, 3)
}

/// The line an error or warning points at.
fn line_of(d: &Diagnostic) -> Option<u32> {
    d.loc.as_ref().map(|l| l.line)
}

/// A `LightSource` directive's parts.
pub(crate) struct LightEntity {
    pub name: String,
    pub params: ParameterDictionary,
    pub render_from_object: AnimatedTransform,
    pub pbrt_v3: bool,
}

/// A light and its warnings, unused parameters included.
pub(crate) fn create_light(
    e: &LightEntity,
    medium: Option<rpbrt_geometry::MediumId>,
    ct: &CameraTransform,
) -> Result<(Light, Vec<Diagnostic>), Diagnostic> {
    let at = FileLoc::new(Arc::from("test.pbrt"), 1, 1);
    let r = ParamReader::plain(&e.params, &at);
    let dialect = LightDialect {
        v3_mapname: e.pbrt_v3,
        v3_file: e.pbrt_v3,
    };
    let light = super::create_light(&e.name, &r, &e.render_from_object, medium, ct, dialect)?;
    Ok((light, r.finish()))
}

fn floats(name: &str, v: &[f32]) -> ParsedParameter {
    let ty = match v.len() {
        3 if name == "from" || name == "to" => "point3",
        3 => "rgb",
        _ => "float",
    };
    ParsedParameter::with_floats(ty, name, ploc(), v.to_vec())
}

fn entity(name: &str, params: Vec<ParsedParameter>) -> LightEntity {
    LightEntity {
        name: name.to_string(),
        params: ParameterDictionary::new(params),
        render_from_object: AnimatedTransform::fixed(Transform::identity()),
        pbrt_v3: false,
    }
}

fn make(name: &str, params: Vec<ParsedParameter>) -> Light {
    match create_light(&entity(name, params), None, &CameraTransform::default()) {
        Ok((l, w)) => {
            assert!(w.is_empty(), "unexpected warnings {w:?}");
            l
        }
        Err(e) => panic!("{e:?}"),
    }
}

fn rel_eq(a: Float, b: Float, eps: Float) -> bool {
    (a - b).abs() <= eps * a.abs().max(b.abs()).max(1e-6)
}

fn lambda(rng: &mut Rng) -> SampledWavelengths {
    SampledWavelengths::sample_visible(rng.uniform_float())
}

/// ∫ I(ω) dω over the sphere, by stratified sampling, through `sample_li`
/// from points on the unit sphere around the light's origin.
fn integrate_intensity(light: &Light, origin: Point3f, lambda: &SampledWavelengths) -> [Float; 4] {
    let n = 256;
    let mut sum = [0.0f64; 4];
    for i in 0..n {
        for j in 0..n {
            let u = Point2f::new(
                (i as Float + 0.5) / n as Float,
                (j as Float + 0.5) / n as Float,
            );
            let w = sample_uniform_sphere(u);
            let ctx = LightSampleContext::from_point(origin + w * 2.0);
            if let Some(ls) = light.sample_li(&ctx, Point2f::new(0.5, 0.5), lambda, false) {
                assert_eq!(ls.pdf, 1.0);
                for (k, s) in sum.iter_mut().enumerate() {
                    *s += (ls.l[k] * 4.0) as f64;
                }
            }
        }
    }
    sum.map(|s| (s * 4.0 * PI as f64 / (n * n) as f64) as Float)
}

fn check_phi_against_integral(light: &Light, origin: Point3f, eps: Float) {
    let mut rng = Rng::with_sequence(7);
    let lambda = lambda(&mut rng);
    let integral = integrate_intensity(light, origin, &lambda);
    let phi = light.phi(&lambda);
    for k in 0..4 {
        assert!(
            rel_eq(integral[k], phi[k], eps),
            "∫I = {:?} vs phi {:?}",
            integral,
            phi
        );
    }
}

#[test]
fn point_light_power_and_falloff() {
    let l = make(
        "point",
        vec![floats("power", &[100.0]), floats("from", &[1.0, 2.0, 3.0])],
    );
    let Light::Point(p) = &l else { panic!() };
    // Luminous power exactly as requested.
    assert!(rel_eq(
        p.scale * 4.0 * PI * spectrum_to_photometric(&p.i),
        100.0,
        1e-4
    ));
    check_phi_against_integral(&l, Point3f::new(1.0, 2.0, 3.0), 1e-3);
    let lambda = SampledWavelengths::sample_visible(0.3);
    let a = l
        .sample_li(
            &LightSampleContext::from_point(Point3f::new(1.0, 2.0, 5.0)),
            Point2f::new(0.5, 0.5),
            &lambda,
            false,
        )
        .unwrap();
    let b = l
        .sample_li(
            &LightSampleContext::from_point(Point3f::new(1.0, 2.0, 7.0)),
            Point2f::new(0.5, 0.5),
            &lambda,
            false,
        )
        .unwrap();
    assert!(rel_eq(a.l[0], 4.0 * b.l[0], 1e-4));
    assert!((a.wi - Vector3f::new(0.0, 0.0, -1.0)).length() < 1e-5);
    assert_eq!(l.light_type(), LightType::DeltaPosition);
}

#[test]
fn spot_light_power_falloff_and_integral() {
    let l = make(
        "spot",
        vec![
            floats("power", &[50.0]),
            floats("coneangle", &[40.0]),
            floats("conedeltaangle", &[10.0]),
            floats("from", &[0.0, 0.0, 0.0]),
            floats("to", &[1.0, 0.0, 0.0]),
        ],
    );
    let Light::Spot(s) = &l else { panic!() };
    let cs = s.cos_falloff_start;
    let ce = s.cos_falloff_end;
    let k_e = 2.0 * PI * ((1.0 - cs) + (cs - ce) / 2.0);
    assert!(rel_eq(
        s.scale * k_e * spectrum_to_photometric(&s.i),
        50.0,
        1e-4
    ));
    check_phi_against_integral(&l, Point3f::new(0.0, 0.0, 0.0), 5e-3);
    let lambda = SampledWavelengths::sample_visible(0.5);
    let at_angle = |deg: Float| {
        let t = deg.to_radians();
        // The light points along +x; the context sits at angle t off axis.
        let p = Point3f::new(t.cos(), t.sin(), 0.0);
        l.sample_li(
            &LightSampleContext::from_point(p),
            Point2f::new(0.5, 0.5),
            &lambda,
            false,
        )
        .map(|s| s.l[0])
        .unwrap_or(0.0)
    };
    let full = at_angle(0.0);
    assert!(full > 0.0);
    assert!(rel_eq(at_angle(29.9), full, 1e-3));
    assert!(at_angle(40.1) == 0.0);
    let mid = at_angle(35.0);
    assert!(mid > 0.0 && mid < full);
    // Smoothstep is symmetric about the middle of the falloff band in cosine.
    let cmid = ((cs + ce) / 2.0).acos().to_degrees();
    assert!(rel_eq(at_angle(cmid), full / 2.0, 1e-2));
}

#[test]
fn distant_light_illuminance() {
    let l = make(
        "distant",
        vec![
            floats("illuminance", &[5.0]),
            floats("from", &[0.0, 1.0, 0.0]),
            floats("to", &[0.0, 0.0, 0.0]),
        ],
    );
    let Light::Distant(d) = &l else { panic!() };
    // Luminance of the radiance times cos 0 on a perpendicular surface.
    assert!(rel_eq(
        d.scale * spectrum_to_photometric(&d.l_emit),
        5.0,
        1e-4
    ));
    let mut l = l;
    l.preprocess(&rpbrt_geometry::Bounds3f::new(
        Point3f::new(-1.0, -1.0, -1.0),
        Point3f::new(1.0, 1.0, 1.0),
    ));
    let lambda = SampledWavelengths::sample_visible(0.5);
    let s = l
        .sample_li(
            &LightSampleContext::from_point(Point3f::new(0.0, 0.0, 0.0)),
            Point2f::new(0.5, 0.5),
            &lambda,
            false,
        )
        .unwrap();
    assert!((s.wi - Vector3f::new(0.0, 1.0, 0.0)).length() < 1e-5);
    assert!(s.p_light.midpoint().y > 3.0);
    let r2 = 3.0;
    assert!(rel_eq(l.phi(&lambda)[0], s.l[0] * PI * r2, 1e-4));
}

#[test]
fn uniform_infinite_illuminance_and_pdf() {
    let mut l = make(
        "infinite",
        vec![floats("illuminance", &[3.0]), floats("L", &[0.2, 0.5, 0.9])],
    );
    let Light::UniformInfinite(u) = &l else {
        panic!()
    };
    // pbrt-v4 normalises by the illuminant, not the RGB multiplier.
    let illum = RgbColorSpace::srgb().illuminant_spectrum();
    assert!(rel_eq(
        u.scale * spectrum_to_photometric(&illum) * PI,
        3.0,
        1e-4
    ));
    l.preprocess(&rpbrt_geometry::Bounds3f::new(
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 1.0, 1.0),
    ));
    let mut rng = Rng::with_sequence(3);
    let ctx = LightSampleContext::from_point(Point3f::new(0.5, 0.5, 0.5));
    for _ in 0..100 {
        let lambda = lambda(&mut rng);
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let s = l.sample_li(&ctx, u, &lambda, false).unwrap();
        assert!(rel_eq(s.pdf, l.pdf_li(&ctx, s.wi, false), 1e-5));
        let le = l.le(&Ray::new(ctx.p(), s.wi), &lambda);
        assert_eq!(le, s.l);
        assert!(l.sample_li(&ctx, u, &lambda, true).is_none());
        assert_eq!(l.pdf_li(&ctx, s.wi, true), 0.0);
    }
}

fn disk_light(two_sided: bool, power: Option<f32>, render_from_object: Transform) -> Light {
    let disk = Disk::new(render_from_object, false, 0.0, 1.5, 0.0, 360.0).unwrap();
    let shape = Shape::Disk(Box::new(disk));
    let mut params = vec![floats("L", &[0.7, 0.4, 0.2])];
    if two_sided {
        params.push(ParsedParameter {
            bools: vec![true],
            ..ParsedParameter::new("bool", "twosided", ploc())
        });
    }
    if let Some(p) = power {
        params.push(floats("power", &[p]));
    }
    let params = ParameterDictionary::new(params);
    let at = loc();
    let r = ParamReader::plain(&params, &at);
    let l =
        create_area_light("diffuse", &r, &render_from_object, &shape, None, None, None).unwrap();
    assert!(r.finish().is_empty());
    l
}

#[test]
fn area_light_sampling_power_and_radiance() {
    let xf = Transform::translate(Vector3f::new(0.0, 0.0, 1.0)) * Transform::rotate_x(20.0);
    for two_sided in [false, true] {
        let l = disk_light(two_sided, None, xf);
        let Light::DiffuseArea(a) = &l else { panic!() };
        let mut rng = Rng::with_sequence(11);
        // pdf consistency and radiance from sample_li against l().
        let mut n_ok = 0;
        for _ in 0..400 {
            let p = Point3f::new(
                rng.uniform_float() * 4.0 - 2.0,
                rng.uniform_float() * 4.0 - 2.0,
                rng.uniform_float() * 4.0 - 2.0,
            );
            let ctx = LightSampleContext::from_point(p);
            let lambda = lambda(&mut rng);
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            if let Some(s) = l.sample_li(&ctx, u, &lambda, false) {
                n_ok += 1;
                let pdf = l.pdf_li(&ctx, s.wi, false);
                assert!(rel_eq(s.pdf, pdf, 2e-2), "{} vs {}", s.pdf, pdf);
                let lv = l.l(
                    s.p_light.midpoint(),
                    s.n_light,
                    Point2f::new(0.5, 0.5),
                    -s.wi,
                    &lambda,
                );
                assert_eq!(lv, s.l);
            }
        }
        assert!(n_ok > 50, "{n_ok}");
        // Power against ∫∫ L cos over area and directions.
        let lambda = SampledWavelengths::sample_visible(0.4);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let ss = a
                .shape
                .sample_area(Point2f::new(rng.uniform_float(), rng.uniform_float()))
                .unwrap();
            let w = sample_uniform_sphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            let le = l.l(ss.p(), ss.n, ss.uv, w, &lambda);
            let cos = rpbrt_geometry::dot(ss.n, w).abs();
            sum += (le[0] * cos / (ss.pdf * (1.0 / (4.0 * PI)))) as f64;
        }
        let integral = (sum / n as f64) as Float;
        let phi = l.phi(&lambda)[0];
        assert!(
            rel_eq(integral, phi, 2e-2),
            "two_sided {two_sided}: {integral} vs {phi}"
        );
    }
    // `power` gives exactly the requested luminous power.
    for two_sided in [false, true] {
        let l = disk_light(two_sided, Some(20.0), xf);
        let Light::DiffuseArea(a) = &l else { panic!() };
        let AreaEmission::Spectrum(s) = &a.emission else {
            panic!()
        };
        let cs = RgbColorSpace::srgb();
        let k = if two_sided { 2.0 } else { 1.0 };
        let lum_rgb =
            spectrum_to_photometric(s) / spectrum_to_photometric(&cs.illuminant_spectrum());
        // pbrt-v4 normalises the illuminant, not the RGB multiplier: the
        // power is 20 × the spectrum's luminance relative to the illuminant.
        let phi_v = a.scale * k * a.area * PI * spectrum_to_photometric(&cs.illuminant_spectrum());
        assert!(
            rel_eq(phi_v, 20.0, 1e-4),
            "{phi_v} (rgb luminance {lum_rgb})"
        );
    }
}

#[test]
fn one_sided_area_light_dark_behind() {
    let l = disk_light(false, None, Transform::identity());
    let lambda = SampledWavelengths::sample_visible(0.5);
    let n = Normal3f::new(0.0, 0.0, 1.0);
    let front = l.l(
        Point3f::new(0.0, 0.0, 0.0),
        n,
        Point2f::new(0.5, 0.5),
        Vector3f::new(0.0, 0.0, 1.0),
        &lambda,
    );
    let back = l.l(
        Point3f::new(0.0, 0.0, 0.0),
        n,
        Point2f::new(0.5, 0.5),
        Vector3f::new(0.0, 0.0, -1.0),
        &lambda,
    );
    assert!(!front.is_black());
    assert!(back.is_black());
}

fn test_envmap(res: i32, bright: Point2i) -> Image {
    let mut data = Vec::new();
    for y in 0..res {
        for x in 0..res {
            let v = if Point2i::new(x, y) == bright {
                50.0
            } else {
                0.1 + 0.05 * ((x * 7 + y * 3) % 5) as f32
            };
            data.extend_from_slice(&[v, v * 0.8, v * 0.6]);
        }
    }
    Image::from_f32(data, Point2i::new(res, res), &["R", "G", "B"]).unwrap()
}

#[test]
fn image_infinite_light_sampling() {
    let res = 16;
    let bright = Point2i::new(3, 11);
    let xf = Transform::rotate_z(30.0);
    let mut l = Light::ImageInfinite(Box::new(ImageInfiniteLight::new(
        xf,
        test_envmap(res, bright),
        RgbColorSpace::srgb(),
        1.0,
    )));
    l.preprocess(&rpbrt_geometry::Bounds3f::new(
        Point3f::new(0.0, 0.0, 0.0),
        Point3f::new(1.0, 1.0, 1.0),
    ));
    let ctx = LightSampleContext::from_point(Point3f::new(0.2, 0.3, 0.4));
    let mut rng = Rng::with_sequence(5);
    // pdf integrates to one over the sphere (both distributions).
    for allow in [false, true] {
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let w = sample_uniform_sphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            sum += (l.pdf_li(&ctx, w, allow) * 4.0 * PI) as f64;
        }
        let mean = sum / n as f64;
        assert!((mean - 1.0).abs() < 0.03, "allow {allow}: ∫pdf = {mean}");
    }
    // sample_li agrees with pdf_li and le; histogram matches the image.
    let mut counts = vec![0usize; (res * res) as usize];
    let n = 200_000;
    let lambda = SampledWavelengths::sample_visible(0.5);
    for i in 0..n {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let s = l.sample_li(&ctx, u, &lambda, false).unwrap();
        if i < 2000 {
            assert!(rel_eq(s.pdf, l.pdf_li(&ctx, s.wi, false), 1e-3));
            assert_eq!(s.l, l.le(&Ray::new(ctx.p(), s.wi), &lambda));
            let sc = l.sample_li(&ctx, u, &lambda, true).unwrap();
            assert!(rel_eq(sc.pdf, l.pdf_li(&ctx, sc.wi, true), 1e-3));
        }
        let wl = xf.apply_inverse_vector(s.wi);
        let uv = rpbrt_geometry::equal_area_sphere_to_square(wl);
        let px = ((uv.x * res as Float) as i32).min(res - 1);
        let py = ((uv.y * res as Float) as i32).min(res - 1);
        counts[(py * res + px) as usize] += 1;
    }
    let Light::ImageInfinite(img) = &l else {
        panic!()
    };
    let mut total = 0.0;
    let mut w = vec![0.0; (res * res) as usize];
    for y in 0..res {
        for x in 0..res {
            let v: Float = (0..3)
                .map(|c| {
                    img.image.get_channel(
                        Point2i::new(x, y),
                        c,
                        crate::image::WrapMode2D::new(
                            crate::image::WrapMode::Clamp,
                            crate::image::WrapMode::Clamp,
                        ),
                    )
                })
                .sum::<Float>();
            w[(y * res + x) as usize] = v;
            total += v;
        }
    }
    for i in 0..(res * res) as usize {
        let expected = w[i] / total * n as Float;
        let got = counts[i] as Float;
        assert!(
            (got - expected).abs() <= 5.0 * expected.sqrt() + 3.0,
            "pixel {i}: {got} vs {expected}"
        );
    }
    // Orientation: the bright pixel's centre direction (light space,
    // rotated into render space) sees the bright radiance.
    let uv = Point2f::new(
        (bright.x as Float + 0.5) / res as Float,
        (bright.y as Float + 0.5) / res as Float,
    );
    let dir = xf.apply_vector(equal_area_square_to_sphere(uv));
    let le = l.le(&Ray::new(ctx.p(), dir), &lambda);
    let le_other = l.le(&Ray::new(ctx.p(), -dir), &lambda);
    assert!(le[0] > 50.0 * le_other[0]);
    // Power: 4π · π r² · mean radiance.
    let phi = l.phi(&lambda)[0];
    assert!(phi > 0.0);
}

#[test]
fn goniometric_and_projection_power_integrals() {
    let res = 16;
    let mut data = Vec::new();
    for y in 0..res {
        for x in 0..res {
            data.push(0.2 + ((x + 2 * y) % 7) as f32 * 0.1);
        }
    }
    let image = Image::from_f32(data, Point2i::new(res, res), &["Y"]).unwrap();
    let cs = RgbColorSpace::srgb();
    let g = Light::Goniometric(Box::new(GoniometricLight::new(
        Transform::translate(Vector3f::new(1.0, 0.0, 0.0)),
        dense(&cs.illuminant_spectrum()),
        0.01,
        image,
        None,
    )));
    check_phi_against_integral(&g, Point3f::new(1.0, 0.0, 0.0), 1e-2);

    let mut data = Vec::new();
    for y in 0..8 {
        for x in 0..12 {
            let v = 0.1 + ((x * y) % 5) as f32 * 0.2;
            data.extend_from_slice(&[v, 0.5 * v, 0.2]);
        }
    }
    let image = Image::from_f32(data, Point2i::new(12, 8), &["R", "G", "B"]).unwrap();
    let p = Light::Projection(Box::new(ProjectionLight::new(
        Transform::identity(),
        image,
        cs,
        0.01,
        60.0,
        None,
    )));
    check_phi_against_integral(&p, Point3f::new(0.0, 0.0, 0.0), 2e-2);
}

#[test]
fn creation_errors_are_located() {
    let bad = |name: &str, params: Vec<ParsedParameter>| {
        create_light(&entity(name, params), None, &CameraTransform::default()).unwrap_err()
    };
    // Unknown types and missing parameters point at the directive.
    let e = bad("nosuch", vec![]);
    assert!(e.message.contains("\"point\""), "{}", e.message);
    assert_eq!(line_of(&e), Some(1));
    let e = bad("goniometric", vec![]);
    assert!(e.message.contains("filename"), "{}", e.message);
    assert_eq!(line_of(&e), Some(1));
    // Bad values point at their parameter.
    let scale = floats("scale", &[-1.0]);
    let e = bad(
        "point",
        vec![floats("from", &[0.0, 0.0, 0.0]), scale.clone()],
    );
    assert!(e.message.contains("scale"), "{}", e.message);
    assert_eq!(e.loc.as_ref(), Some(&scale.loc));
    let to = floats("to", &[1.0, 2.0, 3.0]);
    let e = bad("spot", vec![floats("from", &[1.0, 2.0, 3.0]), to.clone()]);
    assert!(e.message.contains("coincide"), "{}", e.message);
    assert_eq!(e.loc.as_ref(), Some(&to.loc));
    let fov = floats("fov", &[200.0]);
    let e = bad("projection", vec![floats("scale", &[1.0]), fov.clone()]);
    assert_eq!(e.loc.as_ref(), Some(&fov.loc), "{e:?}");
    let file = ParsedParameter::with_strings(
        "string",
        "filename",
        ploc(),
        vec!["/nonexistent/env.exr".into()],
    );
    let e = bad("infinite", vec![floats("scale", &[1.0]), file.clone()]);
    assert!(e.message.contains("env.exr"), "{}", e.message);
    assert_eq!(e.loc.as_ref(), Some(&file.loc));
    let portal = ParsedParameter::with_floats("point3", "portal", ploc(), vec![0.0; 12]);
    let e = bad(
        "infinite",
        vec![floats("L", &[1.0, 1.0, 1.0]), portal.clone()],
    );
    assert!(
        e.message.contains("portals are not supported"),
        "{}",
        e.message
    );
    assert_eq!(e.loc.as_ref(), Some(&portal.loc));
    // Unused parameters are warned about, at the parameter.
    let bogus = floats("bogus", &[1.0]);
    let (_, w) = create_light(
        &entity("point", vec![bogus.clone()]),
        None,
        &CameraTransform::default(),
    )
    .unwrap();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].loc.as_ref(), Some(&bogus.loc));
}

#[test]
fn light_bounds_importance_and_union() {
    let a = LightBounds::new(
        rpbrt_geometry::Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(1.0, 1.0, 0.0)),
        Vector3f::new(0.0, 0.0, 1.0),
        2.0,
        1.0,
        0.0,
        false,
    );
    // In front: positive; behind a one-sided emitter: zero.
    assert!(a.importance(Point3f::new(0.5, 0.5, 3.0), Normal3f::default()) > 0.0);
    assert_eq!(
        a.importance(Point3f::new(0.5, 0.5, -3.0), Normal3f::default()),
        0.0
    );
    let b = LightBounds {
        two_sided: true,
        ..a
    };
    assert!(b.importance(Point3f::new(0.5, 0.5, -3.0), Normal3f::default()) > 0.0);
    let u = LightBounds::union(
        &a,
        &LightBounds {
            w: Vector3f::new(1.0, 0.0, 0.0),
            ..a
        },
    );
    assert_eq!(u.phi, 4.0);
    assert!(u.cos_theta_o < 0.71 && u.cos_theta_o > 0.70);
    assert_eq!(LightBounds::union(&LightBounds::default(), &a), a);
}

/// The two-lane importance equals two calls of the scalar one, bit for
/// bit, over random bounds (one- and two-sided, narrow and wide cones),
/// points inside and outside them, and with and without a normal.
#[test]
fn importance2_matches_importance() {
    let mut rng = Rng::with_sequence(5);
    let mut r = |lo: Float, hi: Float| lo + (hi - lo) * rng.uniform_float();
    let mut nonzero = 0;
    for i in 0..20_000 {
        let mut bounds = || {
            let p0 = Point3f::new(r(-2.0, 2.0), r(-2.0, 2.0), r(-2.0, 2.0));
            let ext = if i % 7 == 0 { 0.0 } else { 1.0 };
            let p1 = p0 + Vector3f::new(r(0.0, ext), r(0.0, ext), r(0.0, ext));
            let w = Vector3f::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0));
            let lb = LightBounds::new(
                rpbrt_geometry::Bounds3f::new(p0, p1),
                w,
                r(0.0, 10.0),
                r(-1.0, 1.0),
                r(-1.0, 1.0).min(0.0),
                i % 3 == 0,
            );
            PreparedLightBounds::new(&lb)
        };
        let (a, b) = (bounds(), bounds());
        let p = Point3f::new(r(-4.0, 4.0), r(-4.0, 4.0), r(-4.0, 4.0));
        let n = if i % 5 == 0 {
            Normal3f::default()
        } else {
            Normal3f::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)).normalize()
        };
        let got = importance2(&a, &b, p, n);
        let want = [a.importance(p, n), b.importance(p, n)];
        assert_eq!(
            got.map(Float::to_bits),
            want.map(Float::to_bits),
            "case {i}"
        );
        nonzero += want.iter().filter(|&&v| v > 0.0).count();
    }
    assert!(nonzero > 10_000, "{nonzero}");
}

#[test]
fn light_enum_stays_small() {
    assert!(
        std::mem::size_of::<Light>() <= 200,
        "{}",
        std::mem::size_of::<Light>()
    );
}

#[test]
fn image_infinite_from_file_illuminance_and_square_check() {
    let dir = std::env::temp_dir().join(format!("rpbrt-light-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let square = dir.join("env.pfm");
    test_envmap(8, Point2i::new(2, 2))
        .write(&square, &Default::default())
        .unwrap();
    let file = |p: &std::path::Path| {
        ParsedParameter::with_strings("string", "filename", ploc(), vec![p.display().to_string()])
    };
    let l = make(
        "infinite",
        vec![file(&square), floats("illuminance", &[2.0])],
    );
    let Light::ImageInfinite(img) = &l else {
        panic!()
    };
    // Recompute the upward illuminance the way pbrt-v4 measures it (its
    // factor is 2π/N, half of the true 4π/N solid angle per pixel, so the
    // true illuminance comes out at twice the target): with L = scale · rgb
    // · illuminant and Y(rgb · illuminant) = lum · rgb · photometric(illuminant).
    let cs = RgbColorSpace::srgb();
    let lum = luminance_vector(cs);
    let res = img.image.resolution();
    let wrap =
        crate::image::WrapMode2D::new(crate::image::WrapMode::Clamp, crate::image::WrapMode::Clamp);
    let mut e = 0.0;
    for y in 0..res.y {
        for x in 0..res.x {
            let w = equal_area_square_to_sphere(Point2f::new(
                (x as Float + 0.5) / res.x as Float,
                (y as Float + 0.5) / res.y as Float,
            ));
            if w.z > 0.0 {
                for c in 0..3 {
                    e += img.image.get_channel(Point2i::new(x, y), c, wrap) * lum[c] * w.z;
                }
            }
        }
    }
    e *= 2.0 * PI / (res.x * res.y) as Float
        * img.scale
        * spectrum_to_photometric(&cs.illuminant_spectrum());
    assert!(rel_eq(e, 2.0, 1e-3), "{e}");

    // Neither square nor 2:1: an error at the file name.
    let nonsquare = dir.join("wide.pfm");
    Image::from_f32(vec![1.0; 3 * 2 * 3], Point2i::new(3, 2), &["R", "G", "B"])
        .unwrap()
        .write(&nonsquare, &Default::default())
        .unwrap();
    let p = file(&nonsquare);
    let line = p.loc.line;
    let err = create_light(
        &entity("infinite", vec![p]),
        None,
        &CameraTransform::default(),
    )
    .unwrap_err();
    assert!(err.message.contains("neither square"), "{}", err.message);
    assert_eq!(line_of(&err), Some(line));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn pbrt_v3_goniometric_and_projection_lights_without_images() {
    let v3 = |name: &str, params: Vec<ParsedParameter>| {
        let mut e = entity(name, params);
        e.pbrt_v3 = true;
        create_light(&e, None, &CameraTransform::default())
    };
    let i = floats("I", &[2.0, 1.0, 0.5]);
    let point = make("point", vec![i.clone()]);
    let (gonio, w) = v3("goniometric", vec![i.clone()]).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let (proj, w) = v3("projection", vec![i.clone()]).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let mut rng = Rng::with_sequence(3);
    let l = lambda(&mut rng);
    let li = |light: &Light, p: Point3f| {
        let ctx = LightSampleContext::from_point(p);
        light
            .sample_li(&ctx, Point2f::new(0.5, 0.5), &l, false)
            .map_or(SampledSpectrum::new(0.0), |s| s.l)
    };
    // Directions (x/z, y/z) from the light at the origin, at distance 2.
    let at = |tx: Float, ty: Float| Vector3f::new(tx, ty, 1.0).normalize() * 2.0;
    for (tx, ty) in [
        (0.0, 0.0),
        (0.3, -0.2),
        (0.4, 0.4),
        (-0.41, 0.1),
        (1.0, 0.0),
        (0.0, -3.0),
    ] {
        let p = Point3f::new(0.0, 0.0, 0.0) + at(tx, ty);
        // Goniometric without a map: the point light, in every direction.
        let (g, q) = (li(&gonio, p), li(&point, p));
        for k in 0..4 {
            assert!(rel_eq(g[k], q[k], 1e-6), "{tx} {ty}: {} vs {}", g[k], q[k]);
        }
        assert!(li(&gonio, Point3f::new(0.0, 0.0, 0.0) - at(tx, ty))[0] > 0.0);
        // Projection without a map: I / r² inside pbrt-v3's default 45°
        // square frustum (tan 22.5° = 0.414), nothing outside or behind.
        let inside = tx.abs() < 0.414 && ty.abs() < 0.414;
        let e = li(&proj, p);
        for k in 0..4 {
            let want = if inside { q[k] } else { 0.0 };
            assert!(rel_eq(e[k], want, 1e-5), "{tx} {ty}: {} vs {want}", e[k]);
        }
        assert_eq!(li(&proj, Point3f::new(0.0, 0.0, 0.0) - at(tx, ty))[0], 0.0);
    }
    // Power: the point light's intensity over the frustum's solid angle,
    // 4 asin(sin² 22.5°).
    let omega = 4.0 * ((22.5 as Float).to_radians().sin().powi(2)).asin();
    let (pp, qp) = (proj.phi(&l), point.phi(&l));
    for k in 0..4 {
        assert!(rel_eq(pp[k], qp[k] * omega / (4.0 * PI), 1e-4));
    }
    // An explicit fov widens it; a pbrt-v4 file keeps pbrt-v4's error.
    let (wide, _) = v3("projection", vec![i.clone(), floats("fov", &[90.0])]).unwrap();
    assert!(li(&wide, Point3f::new(0.0, 0.0, 0.0) + at(0.9, 0.0))[0] > 0.0);
    for name in ["goniometric", "projection"] {
        let e = create_light(
            &entity(name, vec![i.clone()]),
            None,
            &CameraTransform::default(),
        )
        .unwrap_err();
        assert!(
            e.message.contains("must provide \"filename\""),
            "{}",
            e.message
        );
    }
}

/// `image` written to a fresh temporary folder: the folder, the file and
/// its `"string filename"` parameter.
fn temp_image(
    tag: &str,
    image: &Image,
) -> (std::path::PathBuf, std::path::PathBuf, ParsedParameter) {
    let dir = std::env::temp_dir().join(format!("rpbrt-light-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("map.pfm");
    image.write(&path, &Default::default()).unwrap();
    let file = ParsedParameter::with_strings(
        "string",
        "filename",
        ploc(),
        vec![path.display().to_string()],
    );
    (dir, path, file)
}

/// pbrt-v3 multiplies a `projection` light's map by its `I`: the RGB `I`
/// the render upgrade keeps is folded into the map, channel by channel.
#[test]
fn pbrt_v3_projection_map_is_multiplied_by_i() {
    let values: Vec<f32> = (0..12).map(|k| 0.25 + k as f32 * 0.1).collect();
    let slide = Image::from_f32(values, Point2i::new(2, 2), &["R", "G", "B"]).unwrap();
    let (dir, path, file) = temp_image("proj", &slide);
    let i = [2.0, 1.0, 0.5];
    let mut e = entity("projection", vec![file, floats("I", &i)]);
    e.pbrt_v3 = true;
    let (light, _) = create_light(&e, None, &CameraTransform::default()).expect("creates");
    let Light::Projection(p) = &light else {
        panic!("{light:?}")
    };
    let clamp =
        crate::image::WrapMode2D::new(crate::image::WrapMode::Clamp, crate::image::WrapMode::Clamp);
    let plain = Image::read(&path, None).expect("reads").image;
    for y in 0..2 {
        for x in 0..2 {
            for (c, k) in i.iter().enumerate() {
                let q = Point2i::new(x, y);
                assert_eq!(
                    p.image.get_channel(q, c, clamp),
                    plain.get_channel(q, c, clamp) * k,
                    "texel ({x}, {y}) channel {c}"
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// pbrt-v3 reads a goniometric map as a latitude–longitude image of any
/// size, θ down the rows of the light-space direction with y and z
/// swapped: a map lit only in its top rows shines along +y.
#[test]
fn pbrt_v3_goniometric_reads_any_latitude_longitude_map() {
    // 64 × 16 (not 2:1): the top rows (θ < π/4) are 1, the rest 0.
    let (w, h) = (64, 16);
    let values: Vec<f32> = (0..w * h)
        .map(|k| if k < w * h / 4 { 1.0 } else { 0.0 })
        .collect();
    let map = Image::from_f32(values, Point2i::new(w, h), &["Y"]).unwrap();
    let (dir, _, file) = temp_image("gonio", &map);
    let mut e = entity("goniometric", vec![file]);
    e.pbrt_v3 = true;
    let (light, warnings) = create_light(&e, None, &CameraTransform::default()).expect("creates");
    assert!(warnings.is_empty(), "{warnings:?}");
    let mut rng = Rng::with_sequence(5);
    let l = lambda(&mut rng);
    let li = |p: Point3f| {
        let ctx = LightSampleContext::from_point(p);
        light
            .sample_li(&ctx, Point2f::new(0.5, 0.5), &l, false)
            .map_or(0.0, |s| s.l.average())
    };
    let up = li(Point3f::new(0.0, 2.0, 0.0));
    // Without a map pbrt-v3's goniometric light is a point light of the
    // same intensity: the map's 1 along +y gives the same light.
    let mut bare = entity("goniometric", vec![]);
    bare.pbrt_v3 = true;
    let (point, _) = create_light(&bare, None, &CameraTransform::default()).expect("creates");
    let ctx = LightSampleContext::from_point(Point3f::new(0.0, 2.0, 0.0));
    let want = point
        .sample_li(&ctx, Point2f::new(0.5, 0.5), &l, false)
        .map_or(0.0, |s| s.l.average());
    assert!(
        (up / want - 1.0).abs() < 0.02,
        "{up} against the point light's {want}"
    );
    // (The resampling filter spreads a texel's worth of light at most.)
    for p in [
        Point3f::new(0.0, -2.0, 0.0),
        Point3f::new(2.0, -0.5, 0.0),
        Point3f::new(0.0, -0.5, 2.0),
    ] {
        assert!(li(p) < 1e-3 * up, "lit towards {p:?}: {} of {up}", li(p));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
