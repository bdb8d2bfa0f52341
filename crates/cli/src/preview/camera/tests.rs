use super::*;
use rpbrt_render::camera::CameraSample;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};

const WORLD: &str = r#"
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 24 ] "string filename" "x.exr"
Camera "perspective" "float fov" [ 45 ]
WorldBegin
Shape "trianglemesh" "point3 P" [ -10 -10 4  10 -10 4  10 10 4  -10 10 4 ]
    "integer indices" [ 0 1 2 0 2 3 ]
"#;

/// The control of the camera `placement` (scene text before `Camera`)
/// puts in `WORLD`, and the scene's camera, in `space`.
fn control(placement: &str, space: &str) -> (CameraControl, Camera) {
    let text = format!("Option \"string rendercoordsys\" \"{space}\"\n{placement}\n{WORLD}");
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default()).unwrap();
    let created = create_scene(&desc, &CreateOptions::default()).unwrap();
    let s = created.scene;
    let directive = CameraDirective::of(&desc.camera.base);
    let c = CameraControl::new(
        s.camera.clone(),
        directive,
        Arc::clone(&s.aggregate),
        (0, 0),
        (32, 24),
    );
    (c, s.camera)
}

fn rays(c: &Camera) -> Vec<[u32; 6]> {
    (0..12)
        .map(|i| {
            let s = CameraSample {
                p_film: Point2f::new(2.7 * i as Float, 1.9 * i as Float),
                ..CameraSample::default()
            };
            let r = c.generate_ray(&s).unwrap().ray;
            [r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z].map(f32::to_bits)
        })
        .collect()
}

fn key(k: &str, fast: bool) -> Op {
    parse_op(format!(r#"{{"op":"key","key":"{k}","fast":{fast}}}"#).as_bytes()).unwrap()
}

#[test]
fn the_text_reproduces_the_file_camera_and_each_move() {
    let (mut c, file) = control("LookAt 0 1 -5  0 1 0  0 1 0", "world");
    assert_eq!(
        c.text(),
        "LookAt 0 1 -5  0 1 -4  0 1 0\nCamera \"perspective\"\n    \"float fov\" [ 45 ]\n"
    );
    // The derived LookAt is the file's camera (not bit for bit: it was
    // derived from the matrix).
    // A step is 1% of the scene's diagonal (the 20 × 20 quad).
    let step = c.step;
    assert!((step - 0.01 * 800.0f32.sqrt()).abs() < 1e-4, "{step}");
    let before = c.text();
    let change = c.apply(key("w", false)).unwrap();
    assert_eq!(change.number, 1);
    let l = c.view.looks[0];
    assert_eq!((l.eye.x, l.eye.y), (0.0, 1.0));
    assert!((l.eye.z - (-5.0 + step)).abs() < 1e-5, "{l:?}");
    assert_ne!(c.text(), before);
    // Shift: five steps.
    c.apply(key("s", true)).unwrap();
    assert!((c.view.looks[0].eye.z - (-5.0 - 4.0 * step)).abs() < 1e-4);
    // D goes to the image's right: +x for this camera (left-handed, +y up).
    c.apply(key("d", false)).unwrap();
    assert!(c.view.looks[0].eye.x > 0.0);
    c.apply(key("e", false)).unwrap();
    assert!(c.view.looks[0].eye.y > 1.0);
    // Turning right looks toward +x; turning up toward +y.
    c.apply(key("right", false)).unwrap();
    let d = c.view.looks[0].dir();
    assert!(d.x > 0.0 && d.z > 0.0, "{d:?}");
    c.apply(key("up", true)).unwrap();
    assert!(c.view.looks[0].dir().y > 0.0);
    // Pasting the text gives the camera rendered, bit for bit (world
    // render space, where the camera does not move the scene).
    let text = c.text();
    let (placement, rest) = text.split_at(text.find("Camera").unwrap());
    let scene = WORLD.replacen("Camera \"perspective\" \"float fov\" [ 45 ]\n", rest, 1);
    let full = format!("Option \"string rendercoordsys\" \"world\"\n{placement}{scene}");
    let (desc, _) = build_scene_from_str(&full, &BuildOptions::default()).unwrap();
    let fresh = create_scene(&desc, &CreateOptions::default())
        .unwrap()
        .scene
        .camera;
    assert_eq!(rays(&fresh), rays(&change_camera(&c)));
    // Reset: the file's camera, bit for bit.
    let back = c.apply(Op::Reset).unwrap();
    assert_eq!(rays(&back.camera), rays(&file));
    assert_eq!(back.number, 7);
}

fn change_camera(c: &CameraControl) -> Camera {
    c.camera.clone()
}

#[test]
fn a_mirrored_camera_keeps_its_scale_and_lens_changes_are_checked() {
    let (mut c, _) = control("Scale -1 1 1\nLookAt 1 2 -5  1 2 0  0 1 0", "cameraworld");
    assert!(
        c.text()
            .starts_with("Scale -1 1 1\nLookAt 1 2 -5  1 2 -4  0 1 0\n"),
        "{}",
        c.text()
    );
    // D still moves to the image's right, which is world -x here.
    c.apply(key("d", false)).unwrap();
    assert!(c.view.looks[0].eye.x < 1.0);
    fn lens(c: &mut CameraControl, body: &str) -> Result<CameraChange, String> {
        parse_op(body.as_bytes()).and_then(|op| c.apply(op))
    }
    let n = c.number;
    assert!(lens(&mut c, r#"{"op":"lens","fov":200}"#).is_err());
    assert!(lens(&mut c, r#"{"op":"lens","lensradius":-1}"#).is_err());
    assert_eq!(c.number, n, "a refused change changes nothing");
    lens(
        &mut c,
        r#"{"op":"lens","fov":30,"lensradius":0.1,"focaldistance":5}"#,
    )
    .unwrap();
    let t = c.text();
    assert!(
        t.contains("\"float fov\" [ 30 ]") && t.contains("\"float lensradius\" [ 0.1 ]"),
        "{t}"
    );
    assert!(t.contains("\"float focaldistance\" [ 5 ]"), "{t}");
    // Click to focus: the plane at z = 4 seen from z = -5.
    c.apply(Op::Focus(16.0, 12.0)).unwrap();
    assert!((c.view.lens.focal_distance.unwrap() - 9.0).abs() < 1e-3);
    // Nothing there: refused.
    c.apply(key("up", true)).unwrap();
    for _ in 0..20 {
        let _ = c.apply(key("up", true));
    }
    assert!(c.apply(Op::Focus(16.0, 0.0)).is_err() || c.view.lens.focal_distance.is_some());
}

#[test]
fn orbit_and_dolly_turn_about_and_move_toward_the_point_under_the_cursor() {
    let (mut c, _) = control("LookAt 0 0 -5  0 0 0  0 1 0", "world");
    // The centre pixel sees (0, 0, 4): orbit about it.
    let op = parse_op(br#"{"op":"orbit","start":[16,12],"dx":8,"dy":0}"#).unwrap();
    c.apply(op).unwrap();
    let l = c.view.looks[0];
    let r = (l.eye - Point3f::new(0.0, 0.0, 4.0)).length();
    assert!((r - 9.0).abs() < 1e-3, "{l:?}");
    // Dragged right: the camera went left (−x), still facing the pivot.
    assert!(l.eye.x < 0.0);
    let to_pivot = (Point3f::new(0.0, 0.0, 4.0) - l.eye).normalize();
    assert!(dot(to_pivot, l.dir()) > 0.9999);
    let op = parse_op(br#"{"op":"dolly","amount":1,"at":[16,12]}"#).unwrap();
    let before = (Point3f::new(0.0, 0.0, 4.0) - c.view.looks[0].eye).length();
    c.apply(op).unwrap();
    let after = (Point3f::new(0.0, 0.0, 4.0) - c.view.looks[0].eye).length();
    assert!((before - after - 0.9).abs() < 0.05, "{before} {after}");
}

#[test]
fn malformed_requests_are_refused() {
    for bad in [
        &b"not json"[..],
        br#"[1,2]"#,
        br#"{"key":"w"}"#,
        br#"{"op":"fly"}"#,
        br#"{"op":"key","key":"x"}"#,
        br#"{"op":"key","key":"w","speed":3}"#,
        br#"{"op":"key","key":"w","steps":0}"#,
        br#"{"op":"key","key":"w","steps":100000}"#,
        br#"{"op":"key","key":"w","fast":"yes"}"#,
        br#"{"op":"orbit","dx":1e300,"dy":0}"#,
        br#"{"op":"orbit","dx":1}"#,
        br#"{"op":"dolly","amount":1,"at":[1]}"#,
        br#"{"op":"lens"}"#,
        br#"{"op":"lens","fov":"wide"}"#,
        br#"{"op":"focus","at":[1e300,0]}"#,
        br#"{"op":"reset","x":1}"#,
    ] {
        assert!(parse_op(bad).is_err(), "{}", String::from_utf8_lossy(bad));
    }
    assert_eq!(parse_op(br#"{"op":"reset"}"#), Ok(Op::Reset));
}
