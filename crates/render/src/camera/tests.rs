use std::sync::Arc;

use rpbrt_geometry::{AnimatedTransform, Float, Point2f, Point3f, Ray, Transform, Vector3f};
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary, ParsedParameter};

use super::*;
use crate::params::ParamReader;
use crate::rng::Rng;
use rpbrt_geometry::MediumId;

mod importance;

fn loc(line: u32) -> FileLoc {
    FileLoc::new(Arc::from("cams.pbrt"), line, 5)
}

/// A parameter list: `("float fov", [..])` floats or `("string x", "y")`.
enum P<'a> {
    F(&'a str, &'a [Float]),
    S(&'a str, &'a str),
}

/// A `Camera` directive's parts.
struct CamEntity {
    name: String,
    params: ParameterDictionary,
    ct: CameraTransform,
}

/// A camera and the warnings its creation raised.
struct Made {
    camera: Camera,
    warnings: Vec<Diagnostic>,
}

fn create_camera_with(
    e: &CamEntity,
    film: &FilmGeometry,
    medium: Option<MediumId>,
) -> Result<Made, Diagnostic> {
    let at = loc(1);
    let r = ParamReader::plain(&e.params, &at);
    let camera = super::create_camera(&e.name, &r, &e.ct, film, medium)?;
    Ok(Made {
        camera,
        warnings: r.finish(),
    })
}

fn create_camera(e: &CamEntity, film: &FilmGeometry) -> Result<Camera, Diagnostic> {
    create_camera_with(e, film, None).map(|m| m.camera)
}

fn entity_with(name: &str, params: &[P], ct: CameraTransform) -> CamEntity {
    let list = params
        .iter()
        .enumerate()
        .map(|(i, p)| match p {
            P::F(n, v) => ParsedParameter::with_floats("float", n, loc(10 + i as u32), v.to_vec()),
            P::S(n, v) => {
                ParsedParameter::with_strings("string", n, loc(10 + i as u32), vec![v.to_string()])
            }
        })
        .collect();
    CamEntity {
        name: name.to_string(),
        params: ParameterDictionary::new(list),
        ct,
    }
}

fn entity(name: &str, params: &[P]) -> CamEntity {
    entity_with(name, params, CameraTransform::default())
}

fn make(name: &str, params: &[P], film: FilmGeometry) -> Camera {
    match create_camera(&entity(name, params), &film) {
        Ok(c) => c,
        Err(e) => panic!("camera creation failed: {e:?}"),
    }
}

fn err(name: &str, params: &[P], film: FilmGeometry) -> Diagnostic {
    match create_camera(&entity(name, params), &film) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

fn sample(x: Float, y: Float) -> CameraSample {
    CameraSample {
        p_film: Point2f::new(x, y),
        p_lens: Point2f::new(0.5, 0.5),
        time: 0.5,
        filter_weight: 1.0,
    }
}

fn ray(c: &Camera, x: Float, y: Float) -> Ray {
    c.generate_ray(&sample(x, y)).expect("ray").ray
}

fn close(a: Vector3f, b: Vector3f, eps: Float) -> bool {
    (a - b).length() <= eps
}

fn closep(a: Point3f, b: Point3f, eps: Float) -> bool {
    (a - b).length() <= eps
}

#[test]
fn camera_enum_stays_small() {
    // One per scene, never in an array; the projective transforms and the
    // animated camera placement dominate its size.
    assert!(
        std::mem::size_of::<Camera>() <= 1280,
        "{}",
        std::mem::size_of::<Camera>()
    );
}

#[test]
fn perspective_centre_and_corners() {
    let c = make(
        "perspective",
        &[P::F("fov", &[90.0])],
        FilmGeometry::new(64, 64),
    );
    let r = ray(&c, 32.0, 32.0);
    assert!(close(r.d, Vector3f::new(0.0, 0.0, 1.0), 1e-5), "{:?}", r.d);
    assert!(closep(r.o, Point3f::new(0.0, 0.0, 0.0), 1e-6));
    // Raster (0,0) is the upper left: camera −x, +y. x grows to the right.
    let d = ray(&c, 0.0, 0.0).d;
    assert!(
        close(d, Vector3f::new(-1.0, 1.0, 1.0).normalize(), 1e-5),
        "{d:?}"
    );
    let d = ray(&c, 64.0, 0.0).d;
    assert!(
        close(d, Vector3f::new(1.0, 1.0, 1.0).normalize(), 1e-5),
        "{d:?}"
    );
    let d = ray(&c, 64.0, 64.0).d;
    assert!(
        close(d, Vector3f::new(1.0, -1.0, 1.0).normalize(), 1e-5),
        "{d:?}"
    );
    assert!((d.length() - 1.0).abs() < 1e-5);
    let r = c.generate_ray(&sample(3.0, 7.0)).unwrap();
    assert_eq!(r.weight, 1.0);
}

#[test]
fn fov_applies_to_the_shorter_axis() {
    let half = (30.0 as Float).to_radians();
    // Landscape: the vertical extent spans the field of view.
    let c = make(
        "perspective",
        &[P::F("fov", &[60.0])],
        FilmGeometry::new(200, 100),
    );
    let d = ray(&c, 100.0, 0.0).d;
    assert!((d.y / d.z - half.tan()).abs() < 1e-4, "{d:?}");
    let d = ray(&c, 0.0, 50.0).d;
    assert!((-d.x / d.z - 2.0 * half.tan()).abs() < 1e-4, "{d:?}");
    // Portrait: the horizontal extent does.
    let c = make(
        "perspective",
        &[P::F("fov", &[60.0])],
        FilmGeometry::new(100, 200),
    );
    let d = ray(&c, 0.0, 100.0).d;
    assert!((-d.x / d.z - half.tan()).abs() < 1e-4, "{d:?}");
    let d = ray(&c, 50.0, 200.0).d;
    assert!((-d.y / d.z - 2.0 * half.tan()).abs() < 1e-4, "{d:?}");
    // frameaspectratio overrides the film's aspect.
    let c = make(
        "perspective",
        &[P::F("fov", &[60.0]), P::F("frameaspectratio", &[0.5])],
        FilmGeometry::new(200, 100),
    );
    let d = ray(&c, 0.0, 50.0).d;
    assert!((-d.x / d.z - half.tan()).abs() < 1e-4, "{d:?}");
    // An explicit screen window.
    let c = make(
        "perspective",
        &[
            P::F("fov", &[90.0]),
            P::F("screenwindow", &[0.0, 1.0, 0.0, 1.0]),
        ],
        FilmGeometry::new(10, 10),
    );
    let d = ray(&c, 0.0, 10.0).d;
    assert!(close(d, Vector3f::new(0.0, 0.0, 1.0), 1e-5), "{d:?}");
}

#[test]
fn thin_lens_rays_converge_on_the_plane_of_focus() {
    let fd = 7.0;
    let c = make(
        "perspective",
        &[
            P::F("fov", &[50.0]),
            P::F("lensradius", &[0.3]),
            P::F("focaldistance", &[fd]),
        ],
        FilmGeometry::new(50, 50),
    );
    let pinhole = make(
        "perspective",
        &[P::F("fov", &[50.0])],
        FilmGeometry::new(50, 50),
    );
    let mut rng = Rng::with_sequence(3);
    for &(x, y) in &[(25.0, 25.0), (3.5, 41.0), (49.0, 0.5)] {
        let p = ray(&pinhole, x, y);
        let focus = p.at(fd / p.d.z);
        let mut spread = 0.0 as Float;
        for _ in 0..32 {
            let mut s = sample(x, y);
            s.p_lens = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let r = c.generate_ray(&s).unwrap().ray;
            assert!(r.o.z.abs() < 1e-6 && (r.o.x * r.o.x + r.o.y * r.o.y).sqrt() <= 0.3 + 1e-5);
            spread = spread.max(r.o.x.abs().max(r.o.y.abs()));
            let q = r.at((fd - r.o.z) / r.d.z);
            assert!(closep(q, focus, 1e-4), "{q:?} vs {focus:?}");
        }
        assert!(spread > 0.05, "lens samples should spread over the lens");
    }
    // Orthographic with a lens focuses too.
    let c = make(
        "orthographic",
        &[P::F("lensradius", &[0.2]), P::F("focaldistance", &[3.0])],
        FilmGeometry::new(20, 20),
    );
    let focus = ray(
        &make("orthographic", &[], FilmGeometry::new(20, 20)),
        5.0,
        5.0,
    )
    .at(3.0);
    for i in 0..8 {
        let mut s = sample(5.0, 5.0);
        s.p_lens = Point2f::new(i as Float / 8.0 + 0.03, 0.9 - i as Float / 10.0);
        let r = c.generate_ray(&s).unwrap().ray;
        assert!(closep(r.at((3.0 - r.o.z) / r.d.z), focus, 1e-4));
    }
}

#[test]
fn orthographic_rays_are_parallel_and_span_the_screen_window() {
    let c = make("orthographic", &[], FilmGeometry::new(40, 20));
    for &(x, y) in &[(0.0, 0.0), (40.0, 20.0), (13.0, 7.0)] {
        assert!(close(ray(&c, x, y).d, Vector3f::new(0.0, 0.0, 1.0), 1e-6));
    }
    // Aspect 2: x in [−2, 2], y in [−1, 1]; raster y down.
    assert!(closep(
        ray(&c, 0.0, 0.0).o,
        Point3f::new(-2.0, 1.0, 0.0),
        1e-5
    ));
    assert!(closep(
        ray(&c, 40.0, 20.0).o,
        Point3f::new(2.0, -1.0, 0.0),
        1e-5
    ));
    assert!(closep(
        ray(&c, 20.0, 10.0).o,
        Point3f::new(0.0, 0.0, 0.0),
        1e-5
    ));
    let c = make(
        "orthographic",
        &[P::F("screenwindow", &[-5.0, 5.0, -3.0, 3.0])],
        FilmGeometry::new(40, 20),
    );
    assert!(closep(
        ray(&c, 0.0, 0.0).o,
        Point3f::new(-5.0, 3.0, 0.0),
        1e-5
    ));
    let b = c.base();
    assert!(close(
        b.min_pos_differential_x,
        Vector3f::new(0.25, 0.0, 0.0),
        1e-6
    ));
    assert!(close(
        b.min_pos_differential_y,
        Vector3f::new(0.0, -0.3, 0.0),
        1e-6
    ));
    assert_eq!(b.min_dir_differential_x, Vector3f::default());
}

/// The differentials must match the rays generated one pixel over.
fn check_differentials(c: &Camera, s: &CameraSample, eps_o: Float, eps_d: Float) {
    let rd = c.generate_ray_differential(s).expect("ray differential");
    assert!(rd.ray.has_differentials);
    let main = c.generate_ray(s).unwrap();
    assert!(closep(rd.ray.ray.o, main.ray.o, 1e-6));
    assert!(close(rd.ray.ray.d, main.ray.d, 1e-6));
    assert_eq!(rd.weight, main.weight);
    let mut sx = *s;
    sx.p_film.x += 1.0;
    let rx = c.generate_ray(&sx).unwrap().ray;
    assert!(
        closep(rd.ray.rx_origin, rx.o, eps_o),
        "{:?} {:?}",
        rd.ray.rx_origin,
        rx.o
    );
    assert!(
        close(rd.ray.rx_direction, rx.d, eps_d),
        "{:?} {:?}",
        rd.ray.rx_direction,
        rx.d
    );
    let mut sy = *s;
    sy.p_film.y += 1.0;
    let ry = c.generate_ray(&sy).unwrap().ray;
    assert!(
        closep(rd.ray.ry_origin, ry.o, eps_o),
        "{:?} {:?}",
        rd.ray.ry_origin,
        ry.o
    );
    assert!(
        close(rd.ray.ry_direction, ry.d, eps_d),
        "{:?} {:?}",
        rd.ray.ry_direction,
        ry.d
    );
}

#[test]
fn ray_differentials_match_rays_one_pixel_over() {
    let film = FilmGeometry::new(64, 48);
    let mut s = sample(17.3, 30.8);
    s.p_lens = Point2f::new(0.2, 0.7);
    let xf = Transform::translate(Vector3f::new(1.0, 2.0, 3.0)) * Transform::rotate_y(30.0);
    let ct = CameraTransform {
        render_from_camera: AnimatedTransform::fixed(xf),
        world_from_render: Transform::identity(),
    };
    for params in [
        vec![P::F("fov", &[70.0])],
        vec![
            P::F("fov", &[70.0]),
            P::F("lensradius", &[0.1]),
            P::F("focaldistance", &[4.0]),
        ],
    ] {
        let c = create_camera(&entity_with("perspective", &params, ct.clone()), &film).unwrap();
        check_differentials(&c, &s, 1e-5, 1e-5);
    }
    for params in [
        vec![],
        vec![P::F("lensradius", &[0.1]), P::F("focaldistance", &[4.0])],
    ] {
        let c = create_camera(&entity_with("orthographic", &params, ct.clone()), &film).unwrap();
        check_differentials(&c, &s, 1e-5, 1e-5);
    }
    // Offset-based differentials are linearisations: close, not exact.
    let c = create_camera(
        &entity_with("spherical", &[P::S("mapping", "equirectangular")], ct),
        &film,
    )
    .unwrap();
    check_differentials(&c, &s, 1e-5, 1e-2);
}

#[test]
fn camera_differentials_are_positive_and_plausible() {
    let c = make(
        "perspective",
        &[P::F("fov", &[90.0])],
        FilmGeometry::new(64, 64),
    );
    let b = c.base();
    assert_eq!(b.min_pos_differential_x.length(), 0.0);
    // One pixel is 2/64 of tan(45°) at the centre, less toward the corners.
    let dx = b.min_dir_differential_x.length();
    let dy = b.min_dir_differential_y.length();
    for d in [dx, dy] {
        assert!(d > 0.3 * 2.0 / 64.0 && d <= 2.0 / 64.0 + 1e-4, "{d}");
    }
    let cd = c.camera_differentials();
    assert_eq!(cd.min_dir_differential_x, b.min_dir_differential_x);
    assert_eq!(cd.camera_from_render, Transform::identity());

    let c = make(
        "spherical",
        &[P::S("mapping", "equirectangular")],
        FilmGeometry::new(64, 32),
    );
    // As in pbrt-v4, the sweep starts at raster (0, 0), the pole, where
    // moving along x does not change the direction: the x minimum is zero.
    assert_eq!(c.base().min_dir_differential_x.length(), 0.0);
    let d = c.base().min_dir_differential_y.length();
    assert!(d > 0.0 && d <= PI / 32.0 * 1.01, "{d}");
    assert_eq!(c.base().min_pos_differential_y.length(), 0.0);
}

use rpbrt_geometry::PI;

#[test]
fn time_sampling_lerps_the_shutter() {
    let c = make(
        "perspective",
        &[P::F("shutteropen", &[0.2]), P::F("shutterclose", &[0.6])],
        FilmGeometry::new(8, 8),
    );
    assert!((c.sample_time(0.5) - 0.4).abs() < 1e-6);
    assert!((c.sample_time(0.0) - 0.2).abs() < 1e-6);
    let mut s = sample(4.0, 4.0);
    s.time = 0.25;
    assert!((c.generate_ray(&s).unwrap().ray.time - 0.3).abs() < 1e-6);
    // Reversed: swapped with a warning located at "shutterclose".
    let e = entity(
        "orthographic",
        &[P::F("shutteropen", &[0.9]), P::F("shutterclose", &[0.1])],
    );
    let made = create_camera_with(&e, &FilmGeometry::new(8, 8), Some(3)).unwrap();
    assert_eq!(made.camera.base().shutter_open, 0.1);
    assert_eq!(made.camera.base().shutter_close, 0.9);
    assert_eq!(made.camera.base().medium, Some(3));
    assert_eq!(made.camera.generate_ray(&s).unwrap().ray.medium, Some(3));
    assert!(made
        .warnings
        .iter()
        .any(|w| w.loc.as_ref().map(|l| l.line) == Some(11)));
}

/// A camera transform that moves 2 units along x over the shutter [0, 1].
fn moving_transform() -> CameraTransform {
    CameraTransform {
        render_from_camera: AnimatedTransform::new(
            Transform::identity(),
            0.0,
            Transform::translate(Vector3f::new(2.0, 0.0, 0.0)),
            1.0,
        ),
        world_from_render: Transform::identity(),
    }
}

#[test]
fn animated_camera_moves_rays_with_time() {
    let ct = moving_transform();
    let c = create_camera(
        &entity_with("perspective", &[], ct),
        &FilmGeometry::new(8, 8),
    )
    .unwrap();
    for t in [0.0, 0.25, 1.0] {
        let mut s = sample(4.0, 4.0);
        s.time = t;
        let r = c.generate_ray(&s).unwrap().ray;
        assert!(
            closep(r.o, Point3f::new(2.0 * t, 0.0, 0.0), 1e-5),
            "{:?}",
            r.o
        );
        let rd = c.generate_ray_differential(&s).unwrap().ray;
        assert!(closep(rd.rx_origin, Point3f::new(2.0 * t, 0.0, 0.0), 1e-5));
    }
}

#[test]
fn spherical_mappings_follow_pbrt() {
    let c = make(
        "spherical",
        &[P::S("mapping", "equirectangular")],
        FilmGeometry::new(80, 40),
    );
    // u = 0.5 is φ = π: the image centre looks down −x.
    assert!(close(
        ray(&c, 40.0, 20.0).d,
        Vector3f::new(-1.0, 0.0, 0.0),
        1e-5
    ));
    // The top row is θ = 0, swapped to +y (up); the bottom −y.
    assert!(close(
        ray(&c, 13.0, 0.0).d,
        Vector3f::new(0.0, 1.0, 0.0),
        1e-5
    ));
    assert!(close(
        ray(&c, 13.0, 40.0).d,
        Vector3f::new(0.0, -1.0, 0.0),
        1e-5
    ));
    assert!(close(
        ray(&c, 20.0, 20.0).d,
        Vector3f::new(0.0, 0.0, 1.0),
        1e-5
    ));
    assert!(close(
        ray(&c, 0.0, 20.0).d,
        Vector3f::new(1.0, 0.0, 0.0),
        1e-5
    ));

    let c = make("spherical", &[], FilmGeometry::new(32, 32));
    assert!(close(
        ray(&c, 16.0, 16.0).d,
        Vector3f::new(0.0, 1.0, 0.0),
        1e-5
    ));
    let mut rng = Rng::with_sequence(9);
    for _ in 0..200 {
        let (x, y) = (32.0 * rng.uniform_float(), 32.0 * rng.uniform_float());
        assert!((ray(&c, x, y).d.length() - 1.0).abs() < 1e-4);
    }
    // Points off the square wrap to the mirrored side.
    let a = ray(&c, -1.0, 10.0).d;
    let b = ray(&c, 1.0, 22.0).d;
    assert!(close(a, b, 1e-4), "{a:?} {b:?}");

    let e = err(
        "spherical",
        &[P::S("mapping", "equalarea")],
        FilmGeometry::new(64, 32),
    );
    assert!(e.message.contains("square"), "{}", e.message);
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let e = err("spherical", &[], FilmGeometry::new(64, 32));
    assert_eq!(e.loc.as_ref().unwrap().line, 1);
    let e = err(
        "spherical",
        &[P::S("mapping", "cubemap")],
        FilmGeometry::new(8, 8),
    );
    assert!(e.message.contains("cubemap"));
}

/// pbrt-v4-scenes `lenses/dgauss.50mm.dat` (D-GAUSS F/2, scaled to 50 mm).
const DGAUSS: &str = "# D-GAUSS F/2 22deg HFOV\n# radius axpos N aperture\n\
29.475 3.76 1.67 25.2\n84.83 0.12 1 25.2\n19.275 4.025 1.67 23\n40.77 3.275 1.699 23\n\
12.75 5.705 1 18\n0 4.5 0 17.1\n-14.495 1.18 1.603 17\n40.77 6.065 1.658 20\n\
-20.385 0.19 1 20\n437.065 3.22 1.717 20\n-39.73 0 1 20\n";

fn write_temp(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("rpbrt-camera-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

fn realistic(params: &[P], film: FilmGeometry) -> RealisticCamera {
    match make("realistic", params, film) {
        Camera::Realistic(c) => *c,
        _ => unreachable!(),
    }
}

#[test]
fn realistic_camera_focuses_a_point() {
    let lens = write_temp("dgauss.dat", DGAUSS);
    let fd = 2.0;
    let film = FilmGeometry::new(64, 48);
    let cam = realistic(
        &[
            P::S("lensfile", &lens),
            P::F("aperturediameter", &[8.0]),
            P::F("focusdistance", &[fd]),
        ],
        film,
    );
    // A 50 mm lens focused at 2 m sits a bit over 50 mm from the film.
    let rear = cam.lens_rear_z();
    assert!(rear > 0.03 && rear < 0.08, "{rear}");
    let c = Camera::Realistic(Box::new(cam.clone()));
    let mut rng = Rng::with_sequence(1);
    for &(x, y) in &[(32.0, 24.0), (45.0, 30.0), (10.0, 5.0)] {
        let mut pts = Vec::new();
        for _ in 0..400 {
            let mut s = sample(x, y);
            s.p_lens = Point2f::new(rng.uniform_float(), rng.uniform_float());
            if let Some(r) = c.generate_ray(&s) {
                assert!(r.weight > 0.0 && r.weight.is_finite());
                assert!((r.ray.d.length() - 1.0).abs() < 1e-4 && r.ray.d.z > 0.0);
                // The focus plane is `fd` from the film.
                pts.push(r.ray.at((fd - r.ray.o.z) / r.ray.d.z));
            }
        }
        assert!(pts.len() > 50, "too few rays got through: {}", pts.len());
        let n = pts.len() as Float;
        let mean = pts
            .iter()
            .fold(Vector3f::default(), |a, p| a + Vector3f::from(*p))
            / n;
        let spread = pts
            .iter()
            .map(|p| (Vector3f::from(*p) - mean).length())
            .fold(0.0 as Float, Float::max);
        // Rays leave an aperture millimetres wide and meet within a fraction
        // of a millimetre at the focus plane.
        assert!(spread < 1.5e-3, "spread {spread} at ({x}, {y})");
        // The image is inverted back: raster x right is +x, raster y down −y.
        if x > 32.0 {
            assert!(mean.x > 0.0 && mean.y < 0.0, "{mean:?}");
        }
    }
    // Out of focus: at half the distance the same rays spread far more.
    let mut far = Vec::new();
    for i in 0..100 {
        let mut s = sample(32.0, 24.0);
        s.p_lens = Point2f::new(
            (i % 10) as Float / 10.0 + 0.05,
            (i / 10) as Float / 10.0 + 0.05,
        );
        if let Some(r) = c.generate_ray(&s) {
            far.push(r.ray.at((fd / 2.0 - r.ray.o.z) / r.ray.d.z));
        }
    }
    let w = far.iter().map(|p| p.x).fold(Float::MIN, Float::max)
        - far.iter().map(|p| p.x).fold(Float::MAX, Float::min);
    assert!(w > 2e-3, "{w}");
    check_differentials(&c, &sample(20.0, 20.0), 1e-3, 2e-3);
    let cd = c.camera_differentials();
    assert!(cd.min_dir_differential_x.length() > 0.0);
}

#[test]
fn exit_pupil_bounds_contain_every_ray_that_gets_through() {
    let lens = write_temp("dgauss-pupil.dat", DGAUSS);
    let cam = realistic(
        &[P::S("lensfile", &lens), P::F("aperturediameter", &[30.0])],
        FilmGeometry::new(64, 64),
    );
    assert_eq!(cam.exit_pupil_bounds.len(), 64);
    let half = cam.base.film.diagonal_m / 2.0;
    let rear = cam.rear_element_radius();
    let mut rng = Rng::with_sequence(5);
    let (mut through, mut tried) = (0, 0);
    for _ in 0..20000 {
        let r = rng.uniform_float() * half;
        let pd = crate::sampling::sample_uniform_disk_concentric(Point2f::new(
            rng.uniform_float(),
            rng.uniform_float(),
        ));
        let p_film = Point3f::new(r, 0.0, 0.0);
        let p_rear = Point3f::new(rear * pd.x, rear * pd.y, cam.lens_rear_z());
        tried += 1;
        if cam
            .trace_lenses_from_film(&Ray::new(p_film, p_rear - p_film))
            .0
            == 0.0
        {
            continue;
        }
        through += 1;
        let i = ((r / half * 64.0) as usize).min(63);
        let b = cam.exit_pupil_bounds[i];
        assert!(
            b.inside(Point2f::new(p_rear.x, p_rear.y)),
            "ring {i}: {p_rear:?} outside {b:?}"
        );
    }
    assert!(through > tried / 10, "{through} of {tried}");
    // Vignetting: the pupil is smaller at the film's edge than at its centre.
    let a0 = cam.exit_pupil_bounds[0].area();
    let a63 = cam.exit_pupil_bounds[63].area();
    assert!(a0 > 0.0 && a63 < a0, "{a0} {a63}");
}

#[test]
fn aperture_shapes() {
    for name in ["gaussian", "square", "pentagon", "star"] {
        let img = ApertureImage::builtin(name).expect(name);
        // Normalised to the mean a circular aperture has over its square.
        let mean: f64 = (0..256 * 256)
            .map(|i| {
                img.bilerp(Point2f::new(
                    (i % 256) as Float / 256.0 + 1.0 / 512.0,
                    (i / 256) as Float / 256.0 + 1.0 / 512.0,
                )) as f64
            })
            .sum::<f64>()
            / 65536.0;
        assert!(
            (mean - std::f64::consts::PI / 4.0).abs() < 1e-3,
            "{name}: {mean}"
        );
        assert_eq!(img.bilerp(Point2f::new(-0.5, 0.5)), 0.0);
    }
    let sq = ApertureImage::builtin("square").unwrap();
    assert!(sq.bilerp(Point2f::new(0.5, 0.5)) > 0.0);
    assert_eq!(sq.bilerp(Point2f::new(0.1, 0.5)), 0.0);
    // The pentagon's point is at +y before the flip, so near uv.y = 0 after.
    let pent = ApertureImage::builtin("pentagon").unwrap();
    assert!(pent.bilerp(Point2f::new(0.5, 0.15)) > 0.0);
    assert_eq!(pent.bilerp(Point2f::new(0.5, 0.85)), 0.0);
    assert!(ApertureImage::builtin("hexagon").is_none());

    let lens = write_temp("dgauss-star.dat", DGAUSS);
    let c = make(
        "realistic",
        &[P::S("lensfile", &lens), P::S("aperture", "star")],
        FilmGeometry::new(16, 16),
    );
    let mut got = 0;
    for i in 0..64 {
        let mut s = sample(8.0, 8.0);
        s.p_lens = Point2f::new((i % 8) as Float / 8.0 + 0.06, (i / 8) as Float / 8.0 + 0.06);
        got += c.generate_ray(&s).is_some() as i32;
    }
    assert!(got > 0);
}

#[test]
fn bad_parameters_are_located_errors() {
    let film = FilmGeometry::new(16, 16);
    for fov in [0.0, 180.0, -3.0, 200.0] {
        let e = err(
            "perspective",
            &[P::F("lensradius", &[0.0]), P::F("fov", &[fov])],
            film,
        );
        assert_eq!(e.loc.as_ref().unwrap().line, 11, "{}", e.message);
        assert!(e.message.contains("field of view"));
    }
    let e = err("perspective", &[P::F("lensradius", &[-1.0])], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let e = err("orthographic", &[P::F("lensradius", &[-0.5])], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let e = err(
        "perspective",
        &[P::F("screenwindow", &[0.0, 1.0, 2.0])],
        film,
    );
    assert!(e.message.contains("four"));
    let e = err("perspective", &[P::F("frameaspectratio", &[0.0])], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let e = err("fisheye", &[], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 1);
    assert!(e.message.contains("fisheye"));

    // Realistic: missing, unreadable and malformed lens files.
    let e = err("realistic", &[], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 1);
    assert!(e.message.contains("lens"));
    let e = err(
        "realistic",
        &[P::S("lensfile", "/nonexistent/lens.dat")],
        film,
    );
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let five = write_temp("five.dat", "1 2 3 4\n5\n");
    let e = err("realistic", &[P::S("lensfile", &five)], film);
    assert!(e.message.contains("multiple-of-four"), "{}", e.message);
    assert_eq!(e.loc.as_ref().unwrap().line, 10);
    let junk = write_temp("junk.dat", "# comment\n1 2 3 4\n1 2 x 4\n");
    let e = err("realistic", &[P::S("lensfile", &junk)], film);
    assert!(e.message.contains(":3:"), "{}", e.message);
    let empty = write_temp("empty.dat", "# nothing\n");
    let e = err("realistic", &[P::S("lensfile", &empty)], film);
    assert!(e.message.contains("no values"));
    // A "lens" that cannot focus: a flat slab does not bend rays.
    let slab = write_temp("slab.dat", "0 5 0 10\n");
    let e = err("realistic", &[P::S("lensfile", &slab)], film);
    assert_eq!(e.loc.as_ref().unwrap().line, 10, "{}", e.message);
    let lens = write_temp("dgauss-bad.dat", DGAUSS);
    let e = err(
        "realistic",
        &[P::S("lensfile", &lens), P::F("focusdistance", &[-1.0])],
        film,
    );
    assert_eq!(e.loc.as_ref().unwrap().line, 11);
    let e = err(
        "realistic",
        &[P::S("lensfile", &lens), P::S("aperture", "bokeh.png")],
        film,
    );
    assert_eq!(e.loc.as_ref().unwrap().line, 11);
    // Too close to focus.
    let e = err(
        "realistic",
        &[P::S("lensfile", &lens), P::F("focusdistance", &[0.01])],
        film,
    );
    assert!(e.message.contains("focus"), "{}", e.message);
}

#[test]
fn warnings_for_unused_parameters_and_clamped_apertures() {
    let film = FilmGeometry::new(16, 16);
    let e = entity(
        "perspective",
        &[P::F("fov", &[40.0]), P::F("halffov", &[20.0])],
    );
    let made = create_camera_with(&e, &film, None).unwrap();
    assert_eq!(made.warnings.len(), 1);
    assert!(made.warnings[0].message.contains("halffov"));
    // Spherical reads (and ignores) the projective parameters, as pbrt-v4.
    let e = entity(
        "spherical",
        &[
            P::F("lensradius", &[0.1]),
            P::F("screenwindow", &[-1.0, 1.0, -1.0, 1.0]),
        ],
    );
    assert!(create_camera_with(&e, &film, None)
        .unwrap()
        .warnings
        .is_empty());
    let lens = write_temp("dgauss-clamp.dat", DGAUSS);
    let e = entity(
        "realistic",
        &[P::S("lensfile", &lens), P::F("aperturediameter", &[100.0])],
    );
    let made = create_camera_with(&e, &film, None).unwrap();
    assert!(made.warnings.iter().any(|w| w.message.contains("clamping")));
    let Camera::Realistic(c) = &made.camera else {
        unreachable!()
    };
    let stop = c
        .elements
        .iter()
        .find(|e| e.curvature_radius == 0.0)
        .unwrap();
    assert!((stop.aperture_radius - 0.0171 / 2.0).abs() < 1e-6);
}

/// Times the exit-pupil precomputation at pbrt-v4's sample count:
/// `cargo test --release -p rpbrt-render --lib camera::tests::time_full -- --ignored --nocapture`.
#[test]
#[ignore]
fn time_full_exit_pupil_precomputation() {
    let lens = super::read_lens_file(std::path::Path::new(&write_temp("dgauss-time.dat", DGAUSS)))
        .unwrap();
    let base = CameraBase::new(
        CameraTransform::default(),
        0.0,
        1.0,
        FilmGeometry::new(64, 64),
        None,
    );
    let t0 = std::time::Instant::now();
    let (cam, _) = RealisticCamera::new(base, &lens, 10.0, 1.0, None, 1024 * 1024).unwrap();
    eprintln!(
        "dgauss exit pupil, 64 rings x 1024^2 samples: {:.2} s; centre bounds {:?}",
        t0.elapsed().as_secs_f64(),
        cam.exit_pupil_bounds[0]
    );
}

#[test]
fn aperture_image_from_a_file() {
    // A 16x16 single-channel image: an open square in the middle.
    let mut values = vec![0.0f32; 16 * 16];
    for y in 4..12 {
        for x in 4..12 {
            values[y * 16 + x] = 1.0;
        }
    }
    let dir = std::env::temp_dir().join(format!("rpbrt-camera-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("aperture.pfm");
    crate::image::Image::from_f32(values, rpbrt_geometry::Point2i::new(16, 16), &["Y"])
        .unwrap()
        .write(&path, &Default::default())
        .unwrap();
    let lens = write_temp("dgauss-file-aperture.dat", DGAUSS);
    let c = make(
        "realistic",
        &[
            P::S("lensfile", &lens),
            P::S("aperture", &path.to_string_lossy()),
        ],
        FilmGeometry::new(16, 16),
    );
    let mut got = 0;
    for i in 0..256 {
        let mut s = sample(8.0, 8.0);
        s.p_lens = Point2f::new(
            (i % 16) as Float / 16.0 + 0.03,
            (i / 16) as Float / 16.0 + 0.03,
        );
        got += c.generate_ray(&s).is_some() as i32;
    }
    // Only lens samples inside the open square (a quarter of the image)
    // can pass; some of those are vignetted.
    assert!(got > 0 && got <= 64 + 16, "{got}");
}

#[test]
fn pinhole_lanes_match_single_rays() {
    use crate::simd::SimdLevel;
    use rpbrt_geometry::ray::RayDifferential;
    let moved = Transform::translate(Vector3f::new(3.0, -1.5, 250.0))
        * Transform::rotate(37.0, Vector3f::new(0.3, 1.0, -0.2))
        * Transform::scale(1.0, 1.0, -1.0);
    let ct = CameraTransform {
        render_from_camera: AnimatedTransform::fixed(moved),
        world_from_render: Transform::identity(),
    };
    let cases = [
        (
            vec![P::F("fov", &[39.0])],
            ct.clone(),
            FilmGeometry::new(37, 23),
        ),
        (
            vec![
                P::F("fov", &[90.0]),
                P::F("screenwindow", &[-0.5, 1.5, -1.0, 0.25]),
            ],
            ct,
            FilmGeometry::new(16, 64),
        ),
        (
            vec![],
            CameraTransform::default(),
            FilmGeometry::new(256, 256),
        ),
    ];
    let mut rng = Rng::new(11, 0);
    for (params, ct, film) in cases {
        let c = create_camera_with(&entity_with("perspective", &params, ct), &film, Some(2))
            .unwrap()
            .camera;
        let lanes = c.pinhole_rays().expect("a pinhole camera has a lane form");
        // Points over the film and its filter margin, a few off it.
        let (w, h) = (
            film.full_resolution.x as Float,
            film.full_resolution.y as Float,
        );
        let mut p_film: Vec<Point2f> = (0..203)
            .map(|_| {
                Point2f::new(
                    -2.0 + (w + 4.0) * rng.uniform_float(),
                    -2.0 + (h + 4.0) * rng.uniform_float(),
                )
            })
            .collect();
        p_film.extend([
            Point2f::new(0.0, 0.0),
            Point2f::new(w, h),
            Point2f::new(w / 2.0, h / 2.0),
        ]);
        let times: Vec<Float> = p_film.iter().map(|_| rng.uniform_float()).collect();
        let bits = |r: &RayDifferential| {
            let (o, d) = (r.ray.o, r.ray.d);
            let (ox, oy, dx, dy) = (r.rx_origin, r.ry_origin, r.rx_direction, r.ry_direction);
            [
                o.x, o.y, o.z, d.x, d.y, d.z, r.ray.time, ox.x, ox.y, ox.z, oy.x, oy.y, oy.z, dx.x,
                dx.y, dx.z, dy.x, dy.y, dy.z,
            ]
            .map(Float::to_bits)
        };
        for level in SimdLevel::available() {
            for offsets in [
                OffsetRays::None,
                OffsetRays::Unscaled,
                OffsetRays::Scaled(0.125),
            ] {
                let mut out = vec![];
                lanes.rays(level, &p_film, &times, offsets, &mut out);
                assert_eq!(out.len(), p_film.len());
                for ((p, &t), r) in p_film.iter().zip(&times).zip(&out) {
                    let mut s = sample(p.x, p.y);
                    s.time = t;
                    let mut e = match offsets {
                        OffsetRays::None => RayDifferential::new(c.generate_ray(&s).unwrap().ray),
                        _ => c.generate_ray_differential(&s).unwrap().ray,
                    };
                    if let OffsetRays::Scaled(f) = offsets {
                        e.scale_differentials(f);
                    }
                    e.ray.time = t;
                    assert_eq!(r.has_differentials, offsets != OffsetRays::None);
                    assert_eq!(bits(r), bits(&e), "{level:?} {offsets:?} at {p:?}");
                    assert_eq!(r.ray.medium, Some(2));
                }
            }
        }
    }
    // Thin lenses, moving cameras and other projections have none.
    let lens = make(
        "perspective",
        &[P::F("lensradius", &[0.1]), P::F("focaldistance", &[3.0])],
        FilmGeometry::new(8, 8),
    );
    assert!(lens.pinhole_rays().is_none());
    assert!(make("orthographic", &[], FilmGeometry::new(8, 8))
        .pinhole_rays()
        .is_none());
    let moving = moving_transform();
    let c = create_camera(
        &entity_with("perspective", &[], moving),
        &FilmGeometry::new(8, 8),
    );
    assert!(c.unwrap().pinhole_rays().is_none());
}
