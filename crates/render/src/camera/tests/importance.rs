//! The perspective camera's importance (pbrt-v4 `We`, `PDF_We`,
//! `SampleWi`): normalised over the film and the lens, densities that
//! match it, and lens sampling that finds the raster position
//! `generate_ray` starts from.

use rpbrt_geometry::{
    dot, AnimatedTransform, Float, Point2f, Point3f, Ray, Transform, Vector2f, Vector3f, PI,
};

use super::{make, sample, CameraTransform, P};
use crate::camera::{Camera, CameraSample, FilmGeometry};
use crate::rng::Rng;
use crate::sampling::{sample_uniform_disk_concentric, sample_uniform_sphere};
use crate::spectrum::SampledWavelengths;

/// A camera placed away from the render-space origin and turned.
fn placed() -> CameraTransform {
    CameraTransform {
        render_from_camera: AnimatedTransform::fixed(
            Transform::translate(Vector3f::new(0.5, -1.0, 2.0))
                * Transform::rotate(35.0, Vector3f::new(0.2, 1.0, 0.3).normalize()),
        ),
        ..CameraTransform::default()
    }
}

/// A camera moving and turning over the shutter interval [0, 1].
fn moving() -> CameraTransform {
    CameraTransform {
        render_from_camera: AnimatedTransform::new(
            Transform::translate(Vector3f::new(0.0, 0.0, -1.0)),
            0.0,
            Transform::translate(Vector3f::new(1.0, 0.5, 0.0)) * Transform::rotate_y(20.0),
            1.0,
        ),
        ..CameraTransform::default()
    }
}

fn perspective(params: &[P], ct: CameraTransform) -> Camera {
    let e = super::entity_with("perspective", params, ct);
    match super::create_camera(&e, &FilmGeometry::new(64, 48)) {
        Ok(c) => c,
        Err(e) => panic!("{e:?}"),
    }
}

fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_visible(0.5)
}

/// Where the camera is and looks at `time`, in render space.
fn pose(c: &Camera, time: Float) -> (Point3f, Vector3f) {
    let xf = c
        .base()
        .camera_transform
        .render_from_camera
        .interpolate(time);
    (
        xf.apply_point(Point3f::new(0.0, 0.0, 0.0)),
        xf.apply_vector(Vector3f::new(0.0, 0.0, 1.0)).normalize(),
    )
}

fn parts(c: &Camera) -> (Float, Float, Float) {
    let Camera::Perspective(p) = c else { panic!() };
    (p.image_plane_area, p.lens_radius, p.focal_distance)
}

/// ∫∫ We(p, ω) cos θ dω dA over the lens and all directions, by jittered
/// stratified directions (k × k) and, with a lens, uniformly sampled lens
/// points.
fn integrate_importance(c: &Camera, k: usize, seed: u64) -> Float {
    let (_, lens_radius, _) = parts(c);
    let xf = c
        .base()
        .camera_transform
        .render_from_camera
        .start_transform();
    let view = xf.apply_vector(Vector3f::new(0.0, 0.0, 1.0)).normalize();
    let lens_area = if lens_radius > 0.0 {
        PI * lens_radius * lens_radius
    } else {
        1.0
    };
    let mut rng = Rng::with_sequence(seed);
    let mut sum = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let u = Point2f::new(
                (i as Float + rng.uniform_float()) / k as Float,
                (j as Float + rng.uniform_float()) / k as Float,
            );
            let w = sample_uniform_sphere(u);
            let pl = sample_uniform_disk_concentric(Point2f::new(
                rng.uniform_float(),
                rng.uniform_float(),
            ));
            let o = xf.apply_point(Point3f::new(lens_radius * pl.x, lens_radius * pl.y, 0.0));
            let (we, _) = c.we(&Ray::with_time(o, w, 0.0, None), &lambda());
            let cos = dot(w, view);
            sum += (we[0] * cos * 4.0 * PI * lens_area) as f64;
        }
    }
    (sum / (k * k) as f64) as Float
}

#[test]
fn importance_is_normalised_over_the_film() {
    let mut c = perspective(&[P::F("fov", &[50.0])], placed());
    let int = integrate_importance(&c, 1000, 1);
    assert!((int - 1.0).abs() < 2e-3, "pinhole: ∫We cos = {int}");
    // A wider filter grows the sample bounds by r − 1/2 on every side.
    c.set_filter_radius(Vector2f::new(2.0, 1.5));
    let int = integrate_importance(&c, 1000, 2);
    let grown = (64.0 + 3.0) * (48.0 + 2.0) / (64.0 * 48.0);
    assert!(
        (int - grown).abs() < 2e-3 * grown,
        "∫We cos = {int}, want {grown}"
    );
    // With a thin lens, over the lens area too (a little is lost near
    // the corners, where pbrt-v4's pinhole cone cuts lens rays off).
    let c = perspective(
        &[
            P::F("fov", &[40.0]),
            P::F("lensradius", &[0.2]),
            P::F("focaldistance", &[3.0]),
        ],
        placed(),
    );
    let int = integrate_importance(&c, 1000, 3);
    assert!((int - 1.0).abs() < 1e-2, "thin lens: ∫∫We cos = {int}");
}

#[test]
fn pdf_we_inside_outside_and_behind() {
    for lens in [0.0, 0.15] {
        let mut c = perspective(
            &[
                P::F("fov", &[60.0]),
                P::F("lensradius", &[lens]),
                P::F("focaldistance", &[2.5]),
            ],
            placed(),
        );
        let (a, _, _) = parts(&c);
        let lens_area = if lens > 0.0 { PI * lens * lens } else { 1.0 };
        let (_, view) = pose(&c, 0.0);
        let lambda = lambda();
        let corners: &[(Float, Float)] = if lens == 0.0 {
            &[(0.2, 0.3), (63.9, 47.5)]
        } else {
            &[]
        };
        for &(x, y) in [(32.0, 24.0), (10.0, 40.0), (55.0, 6.0)]
            .iter()
            .chain(corners)
        {
            let mut s = sample(x, y);
            s.p_lens = Point2f::new(0.8, 0.3);
            let ray = c.generate_ray(&s).unwrap().ray;
            let cos = dot(ray.d, view);
            let (pdf_pos, pdf_dir) = c.pdf_we(&ray);
            assert!((pdf_pos - 1.0 / lens_area).abs() < 1e-4 / lens_area);
            let want = 1.0 / (a * cos * cos * cos);
            assert!((pdf_dir - want).abs() < 1e-4 * want, "{pdf_dir} vs {want}");
            let (we, p_raster) = c.we(&ray, &lambda);
            let want = 1.0 / (a * lens_area * cos * cos * cos * cos);
            assert!((we[0] - want).abs() < 1e-4 * want);
            assert!(
                (p_raster - Point2f::new(x, y)).length() < 2e-3,
                "{p_raster:?}"
            );
        }
        if lens > 0.0 {
            // As in pbrt-v4, the cone of directions with importance is the
            // pinhole's (through the film's corners grown by the filter
            // radius), so a lens ray reaching a corner from the far side
            // of the lens has none.
            let mut s = sample(0.2, 0.3);
            s.p_lens = Point2f::new(0.8, 0.3);
            let ray = c.generate_ray(&s).unwrap().ray;
            assert_eq!(c.pdf_we(&ray), (0.0, 0.0));
        }
        // Rays landing outside the film, and rays behind the camera.
        for (x, y) in [(-0.6, 10.0), (64.7, 10.0), (20.0, -1.0), (20.0, 48.9)] {
            let ray = c.generate_ray(&sample(x, y)).unwrap().ray;
            assert_eq!(c.pdf_we(&ray), (0.0, 0.0), "({x}, {y})");
            let (we, p_raster) = c.we(&ray, &lambda);
            assert!(we.is_black());
            // The raster position is still reported.
            assert!((p_raster - Point2f::new(x, y)).length() < 2e-3);
        }
        let (o, _) = pose(&c, 0.0);
        let back = Ray::with_time(o, -view, 0.0, None);
        assert_eq!(c.pdf_we(&back), (0.0, 0.0));
        assert!(c.we(&back, &lambda).0.is_black());
        // A wider filter: half a pixel beyond the film is now inside.
        c.set_filter_radius(Vector2f::new(1.5, 1.5));
        let ray = c.generate_ray(&sample(-0.6, 10.0)).unwrap().ray;
        assert!(c.pdf_we(&ray).1 > 0.0);
        let ray = c.generate_ray(&sample(-1.2, 10.0)).unwrap().ray;
        assert_eq!(c.pdf_we(&ray), (0.0, 0.0));
    }
}

#[test]
fn importance_follows_the_camera_motion() {
    let lambda = lambda();
    for lens in [0.0, 0.1] {
        let c = perspective(
            &[
                P::F("fov", &[45.0]),
                P::F("lensradius", &[lens]),
                P::F("focaldistance", &[4.0]),
            ],
            moving(),
        );
        for (x, y, t) in [(20.0, 30.0, 0.1), (50.0, 5.0, 0.6), (33.0, 21.0, 0.95)] {
            let s = CameraSample {
                p_film: Point2f::new(x, y),
                p_lens: Point2f::new(0.3, 0.7),
                time: t,
                filter_weight: 1.0,
            };
            let ray = c.generate_ray(&s).unwrap().ray;
            let (we, p_raster) = c.we(&ray, &lambda);
            assert!(!we.is_black());
            assert!(
                (p_raster - Point2f::new(x, y)).length() < 5e-3,
                "{p_raster:?}"
            );
            // The same ray at another time meets a camera elsewhere.
            let other = Ray::with_time(ray.o, ray.d, 1.0 - t, ray.medium);
            let (_, p_other) = c.we(&other, &lambda);
            assert!((p_other - Point2f::new(x, y)).length() > 0.5, "{p_other:?}");
        }
    }
}

#[test]
fn sample_wi_finds_the_raster_position() {
    let lambda = lambda();
    let mut rng = Rng::with_sequence(9);
    for (lens, ct) in [
        (0.0, placed()),
        (0.25, placed()),
        (0.0, moving()),
        (0.1, moving()),
    ] {
        let focal = 3.0;
        let c = perspective(
            &[
                P::F("fov", &[55.0]),
                P::F("lensradius", &[lens]),
                P::F("focaldistance", &[focal]),
            ],
            ct,
        );
        let (a, _, _) = parts(&c);
        let lens_area = if lens > 0.0 { PI * lens * lens } else { 1.0 };
        for _ in 0..200 {
            // Away from the film's corners, which a lens ray may reach
            // from outside the importance cone (see the test above).
            let (x, y) = (
                8.0 + rng.uniform_float() * 48.0,
                8.0 + rng.uniform_float() * 32.0,
            );
            let time = rng.uniform_float();
            let s = CameraSample {
                p_film: Point2f::new(x, y),
                p_lens: Point2f::new(rng.uniform_float(), rng.uniform_float()),
                time,
                filter_weight: 1.0,
            };
            let ray = c.generate_ray(&s).unwrap().ray;
            let (o, view) = pose(&c, ray.time);
            // A point on the plane of focus (any point along a pinhole's
            // ray) is seen at (x, y) from every point on the lens.
            let t = if lens > 0.0 {
                focal / dot(ray.d, view)
            } else {
                2.7
            };
            let p_ref = ray.at(t);
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let ws = c.sample_wi(p_ref, ray.time, u, &lambda).expect("visible");
            assert!(
                (ws.p_raster - Point2f::new(x, y)).length() < 1e-2,
                "lens {lens}: {:?} vs ({x}, {y})",
                ws.p_raster
            );
            assert!((Vector3f::from(ws.n_lens) - view).length() < 1e-5);
            assert!((ws.p_lens - o).length() <= lens + 1e-4);
            let d = ws.p_lens - p_ref;
            assert!((ws.wi - d.normalize()).length() < 1e-5);
            let cos = dot(ws.wi, view).abs();
            let want = d.length_squared() / (cos * lens_area);
            assert!((ws.pdf - want).abs() < 1e-4 * want, "{} vs {want}", ws.pdf);
            let want_we = 1.0 / (a * lens_area * cos * cos * cos * cos);
            assert!((ws.wi_importance[0] - want_we).abs() < 1e-3 * want_we);
            if lens == 0.0 {
                assert!((ws.wi + ray.d).length() < 1e-4);
            }
        }
        // Points behind the camera or outside its view are not seen.
        let (o, view) = pose(&c, 0.5);
        let u = Point2f::new(0.5, 0.5);
        assert!(c.sample_wi(o - view * 2.0, 0.5, u, &lambda).is_none());
        let side = Vector3f::new(view.y, -view.x, 0.0).normalize();
        assert!(c
            .sample_wi(o + side * 5.0 + view * 0.5, 0.5, u, &lambda)
            .is_none());
    }
}

#[test]
fn only_the_perspective_camera_has_importance() {
    let lambda = lambda();
    let p = make("perspective", &[], FilmGeometry::new(16, 16));
    assert!(p.supports_importance());
    for name in ["orthographic", "spherical"] {
        let c = make(name, &[], FilmGeometry::new(16, 16));
        assert!(!c.supports_importance());
        let ray = c.generate_ray(&sample(8.0, 8.0)).unwrap().ray;
        assert!(c.we(&ray, &lambda).0.is_black());
        assert_eq!(c.pdf_we(&ray), (0.0, 0.0));
        let target = ray.at(3.0);
        assert!(c
            .sample_wi(target, 0.0, Point2f::new(0.5, 0.5), &lambda)
            .is_none());
    }
}
