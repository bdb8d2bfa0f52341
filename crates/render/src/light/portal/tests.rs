//! Portal light tests: sampling densities against `pdf_li`, radiance
//! against `le`, the density's normalisation over the portal's solid
//! angle, irradiance through the portal by light and by uniform sampling,
//! and creation errors.

use std::sync::Arc;

use rpbrt_geometry::{
    dot, AnimatedTransform, Bounds3f, Float, Point2f, Point2i, Point3f, Ray, Transform, Vector3f,
    PI,
};
use rpbrt_parser::{FileLoc, ParameterDictionary, ParsedParameter};

use super::super::{ImageInfiniteLight, Light, LightSampleContext, PortalImageInfiniteLight};
use crate::camera::CameraTransform;
use crate::image::Image;
use crate::light::tests::{create_light, LightEntity};
use crate::rng::Rng;
use crate::sampling::sample_uniform_sphere;
use crate::spectrum::{RgbColorSpace, SampledWavelengths};

/// A tilted 2a × 2b rectangle centred at `c`, with the environment on the
/// side of `tilt · +z`.
fn portal_corners(a: Float, b: Float, c: Point3f, tilt: &Transform) -> [Point3f; 4] {
    let x = tilt.apply_vector(Vector3f::new(1.0, 0.0, 0.0));
    let y = tilt.apply_vector(Vector3f::new(0.0, 1.0, 0.0));
    let p0 = c - x * a - y * b;
    [
        p0,
        p0 + y * (2.0 * b),
        p0 + x * (2.0 * a) + y * (2.0 * b),
        p0 + x * (2.0 * a),
    ]
}

fn tilt() -> Transform {
    Transform::rotate(25.0, Vector3f::new(1.0, 2.0, 0.5).normalize())
}

/// An equal-area map with smooth structure and one bright pixel.
fn envmap(res: i32) -> Image {
    let mut data = Vec::new();
    for y in 0..res {
        for x in 0..res {
            let v = if (x, y) == (res / 3, res / 2) {
                40.0
            } else {
                0.2 + 0.1 * ((x * 5 + y * 3) % 7) as f32
            };
            data.extend_from_slice(&[v, 0.7 * v, 0.4 * v]);
        }
    }
    Image::from_f32(data, Point2i::new(res, res), &["R", "G", "B"]).unwrap()
}

fn constant_map(res: i32, v: f32) -> Image {
    Image::from_f32(
        vec![v; (res * res * 3) as usize],
        Point2i::new(res, res),
        &["R", "G", "B"],
    )
    .unwrap()
}

fn scene_bounds() -> Bounds3f {
    Bounds3f::new(Point3f::new(-3.0, -3.0, -3.0), Point3f::new(3.0, 3.0, 3.0))
}

fn light_with(image: &Image, render_from_light: Transform) -> PortalImageInfiniteLight {
    let t = tilt();
    let corners = portal_corners(0.8, 0.5, t.apply_point(Point3f::new(0.0, 0.0, 2.0)), &t);
    let mut l = PortalImageInfiniteLight::new(
        render_from_light,
        image,
        RgbColorSpace::srgb(),
        1.3,
        corners,
    )
    .unwrap();
    l.preprocess(&scene_bounds());
    l
}

fn rel_eq(a: Float, b: Float, eps: Float) -> bool {
    (a - b).abs() <= eps * a.abs().max(b.abs()).max(1e-6)
}

/// The reference point: below the portal, off its axis.
fn ref_point() -> Point3f {
    tilt().apply_point(Point3f::new(0.3, -0.2, 0.1))
}

#[test]
fn sample_li_matches_pdf_li_and_le() {
    let l = light_with(&envmap(32), Transform::rotate_z(40.0));
    let ctx = LightSampleContext::from_point(ref_point());
    let lambda = SampledWavelengths::sample_visible(0.4);
    let mut rng = Rng::with_sequence(11);
    let n = 20_000;
    let (mut pdf_mismatch, mut l_mismatch) = (0, 0);
    for _ in 0..n {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let s = l.sample_li(&ctx, u, &lambda, false).unwrap();
        assert!(s.pdf > 0.0 && s.pdf.is_finite());
        assert!((s.wi.length() - 1.0).abs() < 1e-4);
        // The direction passes through the portal: it meets the portal's
        // plane inside the rectangle.
        let n = l.portal_frame.z;
        let t = dot(l.portal[0] - ctx.p(), n) / dot(s.wi, n);
        assert!(t > 0.0);
        let hit = ctx.p() + s.wi * t;
        let lx = dot(hit - l.portal[0], l.portal_frame.x);
        let ly = dot(hit - l.portal[0], l.portal_frame.y);
        assert!(
            lx > -1e-3 && lx < 1.6 + 1e-3 && ly > -1e-3 && ly < 1.0 + 1e-3,
            "{lx} {ly}"
        );
        // Re-deriving the pixel from the direction may land across a pixel
        // edge or the window's boundary by rounding; that must stay rare.
        if !rel_eq(s.pdf, l.pdf_li(&ctx, s.wi, false), 1e-3) {
            pdf_mismatch += 1;
        }
        if s.l != l.le(&Ray::new(ctx.p(), s.wi), &lambda) {
            l_mismatch += 1;
        }
        assert_eq!(l.pdf_li(&ctx, s.wi, true), l.pdf_li(&ctx, s.wi, false));
    }
    assert!(pdf_mismatch * 200 < n, "{pdf_mismatch} pdf mismatches");
    assert!(l_mismatch * 200 < n, "{l_mismatch} radiance mismatches");
    // The enum delegates.
    let light = Light::PortalImageInfinite(Box::new(l.clone()));
    assert!(light.bounds().is_none());
    assert_eq!(light.light_type(), super::super::LightType::Infinite);
    let s = light
        .sample_li(&ctx, Point2f::new(0.3, 0.6), &lambda, false)
        .unwrap();
    assert_eq!(light.pdf_li(&ctx, s.wi, false), l.pdf_li(&ctx, s.wi, false));
}

#[test]
fn directions_outside_the_portal_get_nothing() {
    let l = light_with(&envmap(16), Transform::identity());
    let ctx = LightSampleContext::from_point(ref_point());
    let lambda = SampledWavelengths::sample_visible(0.6);
    let mut rng = Rng::with_sequence(4);
    let n_axis = l.portal_frame.z;
    let (mut inside, mut outside, mut rim) = (0, 0, 0);
    for _ in 0..20_000 {
        let w = sample_uniform_sphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
        let denom = dot(w, n_axis);
        let through = denom > 0.0 && {
            let t = dot(l.portal[0] - ctx.p(), n_axis) / denom;
            let hit = ctx.p() + w * t;
            let lx = dot(hit - l.portal[0], l.portal_frame.x);
            let ly = dot(hit - l.portal[0], l.portal_frame.y);
            lx > 0.0 && lx < 1.6 && ly > 0.0 && ly < 1.0
        };
        let pdf = l.pdf_li(&ctx, w, false);
        let le = l.le(&Ray::new(ctx.p(), w), &lambda);
        if through {
            inside += 1;
            // The map is positive everywhere: so are density and radiance
            // (except by rounding at the rim).
            if pdf == 0.0 || le.is_black() {
                rim += 1;
            }
        } else {
            // Allow rounding right at the rim: re-test with a margin.
            let t = if denom > 0.0 {
                dot(l.portal[0] - ctx.p(), n_axis) / denom
            } else {
                -1.0
            };
            let hit = ctx.p() + w * t;
            let lx = dot(hit - l.portal[0], l.portal_frame.x);
            let ly = dot(hit - l.portal[0], l.portal_frame.y);
            let near_rim = t > 0.0 && lx > -1e-3 && lx < 1.601 && ly > -1e-3 && ly < 1.001;
            if !near_rim {
                outside += 1;
                assert_eq!(pdf, 0.0, "{w:?}");
                assert!(le.is_black(), "{w:?}");
            }
        }
    }
    assert!(inside > 500 && outside > 10_000, "{inside} {outside}");
    assert!(
        rim * 100 < inside,
        "{rim} of {inside} through the portal got nothing"
    );
    // From behind the portal's plane (on the environment side) nothing is
    // sampled.
    let behind = LightSampleContext::from_point(tilt().apply_point(Point3f::new(0.0, 0.0, 3.0)));
    assert!(l
        .sample_li(&behind, Point2f::new(0.5, 0.5), &lambda, false)
        .is_none());
    assert_eq!(l.pdf_li(&behind, l.portal_frame.z, false), 0.0);
}

#[test]
fn pdf_integrates_to_one_over_the_portal() {
    let l = light_with(&envmap(32), Transform::rotate_x(70.0));
    for p in [
        ref_point(),
        tilt().apply_point(Point3f::new(-1.5, 0.9, 1.2)),
    ] {
        let ctx = LightSampleContext::from_point(p);
        let mut rng = Rng::with_sequence(21);
        // Uniform points on the portal: dω = cos θ / r² dA.
        let area = l.area();
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let (u, v) = (rng.uniform_float(), rng.uniform_float());
            let q = l.portal[0] + (l.portal[1] - l.portal[0]) * u + (l.portal[3] - l.portal[0]) * v;
            let d = q - p;
            let r2 = d.length_squared();
            let w = d.normalize();
            let cos = dot(w, l.portal_frame.z).abs();
            sum += (l.pdf_li(&ctx, w, false) * cos / r2 * area) as f64;
        }
        let mean = sum / n as f64;
        assert!((mean - 1.0).abs() < 0.01, "{p:?}: ∫pdf dω = {mean}");
    }
}

/// Solid angle of a 2a × 2b rectangle seen from distance d on its axis.
fn rect_solid_angle(a: f64, b: f64, d: f64) -> f64 {
    4.0 * (a * b / ((a * a + d * d) * (b * b + d * d)).sqrt()).asin()
}

#[test]
fn constant_map_through_portal_gives_uniform_radiance_times_solid_angle() {
    let image = constant_map(64, 0.75);
    let l = light_with(&image, Transform::rotate_y(15.0));
    let full =
        ImageInfiniteLight::new(Transform::rotate_y(15.0), image, RgbColorSpace::srgb(), 1.3);
    // On the portal's axis, distance 1.9 below it.
    let p = tilt().apply_point(Point3f::new(0.0, 0.0, 0.1));
    let ctx = LightSampleContext::from_point(p);
    let lambda = SampledWavelengths::sample_visible(0.3);
    let l_uniform = full.le(&Ray::new(p, Vector3f::new(0.0, 0.0, 1.0)), &lambda)[0];
    let omega = rect_solid_angle(0.8, 0.5, 1.9);
    let expect = l_uniform as f64 * omega;
    // Irradiance-like integrals with normal along the portal axis.
    let nz = l.portal_frame.z;
    let expect_e = {
        // ∫ cos dω over the rectangle, numerically on a fine grid.
        let m = 600;
        let mut s = 0.0f64;
        for j in 0..m {
            for i in 0..m {
                let x = -0.8 + 1.6 * (i as f64 + 0.5) / m as f64;
                let y = -0.5 + 1.0 * (j as f64 + 0.5) / m as f64;
                let r2 = x * x + y * y + 1.9 * 1.9;
                s += 1.9 * 1.9 / (r2 * r2) * (1.6 * 1.0 / (m * m) as f64);
            }
        }
        s * l_uniform as f64
    };
    let mut rng = Rng::with_sequence(8);
    let n = 200_000;
    let (mut li_sum, mut li_e) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let s = l.sample_li(&ctx, u, &lambda, false).unwrap();
        // Radiance through the portal is the uniform radiance.
        assert!(rel_eq(s.l[0], l_uniform, 1e-5), "{} vs {l_uniform}", s.l[0]);
        li_sum += (s.l[0] / s.pdf) as f64;
        li_e += (s.l[0] * dot(s.wi, nz) / s.pdf) as f64;
    }
    // Uniform directions: only about 3% pass through the portal.
    let n_mc = 1_000_000;
    let (mut mc_sum, mut mc_e) = (0.0f64, 0.0f64);
    for _ in 0..n_mc {
        let w = sample_uniform_sphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
        let le = l.le(&Ray::new(p, w), &lambda)[0];
        mc_sum += (le * 4.0 * PI) as f64;
        mc_e += (le * dot(w, nz).max(0.0) * 4.0 * PI) as f64;
    }
    let (li, mc) = (li_sum / n as f64, mc_sum / n_mc as f64);
    let (li_e, mc_e) = (li_e / n as f64, mc_e / n_mc as f64);
    assert!(
        (li - expect).abs() < 0.01 * expect,
        "light sampling {li} vs {expect}"
    );
    assert!(
        (mc - expect).abs() < 0.03 * expect,
        "uniform sampling {mc} vs {expect}"
    );
    assert!(
        (li_e - expect_e).abs() < 0.01 * expect_e,
        "E by light {li_e} vs {expect_e}"
    );
    assert!(
        (mc_e - expect_e).abs() < 0.03 * expect_e,
        "E by MC {mc_e} vs {expect_e}"
    );
    // Power is positive, finite and linear in the radiance.
    let phi = l.phi(&lambda)[0];
    let l2 = light_with(&constant_map(64, 1.5), Transform::rotate_y(15.0));
    let phi2 = l2.phi(&lambda)[0];
    assert!(phi > 0.0 && phi.is_finite());
    assert!(rel_eq(phi2, 2.0 * phi, 1e-4), "{phi2} vs 2 × {phi}");
}

#[test]
fn rectified_image_matches_the_environment() {
    // A smooth map: the portal's radiance in a direction is the full
    // light's, up to resampling error.
    let res = 128;
    let mut data = Vec::new();
    for y in 0..res {
        for x in 0..res {
            let w = rpbrt_geometry::equal_area_square_to_sphere(Point2f::new(
                (x as Float + 0.5) / res as Float,
                (y as Float + 0.5) / res as Float,
            ));
            let v = 1.0 + 0.8 * w.x + 0.3 * w.z;
            data.extend_from_slice(&[v, v, v]);
        }
    }
    let image = Image::from_f32(data, Point2i::new(res, res), &["R", "G", "B"]).unwrap();
    let xf = Transform::rotate_z(60.0);
    let l = light_with(&image, xf);
    let full = ImageInfiniteLight::new(xf, image, RgbColorSpace::srgb(), 1.3);
    let ctx = LightSampleContext::from_point(ref_point());
    let lambda = SampledWavelengths::sample_visible(0.5);
    let mut rng = Rng::with_sequence(2);
    for _ in 0..2000 {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let s = l.sample_li(&ctx, u, &lambda, false).unwrap();
        let want = full.le(&Ray::new(ctx.p(), s.wi), &lambda)[0];
        assert!(rel_eq(s.l[0], want, 0.05), "{} vs {want}", s.l[0]);
    }
}

fn loc_at(line: u32) -> FileLoc {
    FileLoc::new(Arc::from("portal.pbrt"), line, 3)
}

fn portal_param(pts: &[[Float; 3]]) -> ParsedParameter {
    ParsedParameter::with_floats(
        "point3",
        "portal",
        loc_at(7),
        pts.iter().flatten().copied().collect(),
    )
}

fn entity(params: Vec<ParsedParameter>) -> LightEntity {
    LightEntity {
        name: "infinite".to_string(),
        params: ParameterDictionary::new(params),
        render_from_object: AnimatedTransform::fixed(Transform::identity()),
        pbrt_v3: false,
    }
}

#[test]
fn creation_from_parameters_and_errors() {
    let dir = std::env::temp_dir().join(format!("rpbrt-portal-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("env.pfm");
    envmap(16).write(&path, &Default::default()).unwrap();
    let file = ParsedParameter::with_strings(
        "string",
        "filename",
        loc_at(5),
        vec![path.display().to_string()],
    );
    let square = [
        [-1.0, -1.0, 2.0],
        [-1.0, 1.0, 2.0],
        [1.0, 1.0, 2.0],
        [1.0, -1.0, 2.0],
    ];
    let (light, warnings) = create_light(
        &entity(vec![file.clone(), portal_param(&square)]),
        None,
        &CameraTransform::default(),
    )
    .unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let Light::PortalImageInfinite(p) = &light else {
        panic!("not a portal light")
    };
    assert!((p.area() - 4.0).abs() < 1e-5);
    // Corners 0 → 3 along +x, 0 → 1 along +y: the environment is at +z.
    assert!((p.portal_frame.z.z - 1.0).abs() < 1e-6);

    let check_err = |params: Vec<ParsedParameter>, what: &str| {
        let e = create_light(&entity(params), None, &CameraTransform::default()).unwrap_err();
        assert!(e.message.contains(what), "{}", e.message);
        assert_eq!(e.loc.as_ref().map(|l| l.line), Some(7), "{e:?}");
    };
    // A parallelogram: opposite sides parallel, corners not right angles.
    check_err(
        vec![
            file.clone(),
            portal_param(&[
                [-1.0, -1.0, 2.0],
                [-0.5, 1.0, 2.0],
                [1.5, 1.0, 2.0],
                [1.0, -1.0, 2.0],
            ]),
        ],
        "rectangle",
    );
    // Not planar: one corner lifted.
    check_err(
        vec![
            file.clone(),
            portal_param(&[
                [-1.0, -1.0, 2.0],
                [-1.0, 1.0, 2.0],
                [1.0, 1.0, 2.5],
                [1.0, -1.0, 2.0],
            ]),
        ],
        "rectangle",
    );
    // Corners out of order (a bow tie).
    check_err(
        vec![
            file.clone(),
            portal_param(&[square[0], square[2], square[1], square[3]]),
        ],
        "rectangle",
    );
    check_err(vec![file.clone(), portal_param(&square[..3])], "4 vertices");
    // Repeated corner.
    check_err(
        vec![
            file.clone(),
            portal_param(&[square[0], square[0], square[2], square[3]]),
        ],
        "coincide",
    );
    // A portal needs an image.
    check_err(
        vec![
            ParsedParameter::with_floats("rgb", "L", loc_at(4), vec![1.0, 1.0, 1.0]),
            portal_param(&square),
        ],
        "filename",
    );
    let _ = std::fs::remove_dir_all(&dir);
}
