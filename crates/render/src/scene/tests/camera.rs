//! The camera as the scene places it.

use rpbrt_geometry::{Float, Point2f, Point3f, Ray};

use crate::camera::{create_camera, Camera, CameraSample, FilmGeometry, RenderingCoordinateSystem};
use crate::params::ParamReader;
use crate::scene::{build_scene_from_str, BuildOptions};

#[test]
fn look_at_centre_ray_hits_the_origin_in_cameraworld_space() {
    let text = "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
                Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30\n\
                WorldBegin\n";
    let opts = BuildOptions {
        render_coord_sys: RenderingCoordinateSystem::CameraWorld,
        ..Default::default()
    };
    let (scene, _) = build_scene_from_str(text, &opts).expect("scene");
    let base = &scene.camera.base;
    let r = ParamReader::plain(&base.params, &base.loc);
    let c = create_camera(
        &base.name,
        &r,
        &scene.camera.camera_transform,
        &FilmGeometry::new(40, 30),
        None,
    )
    .expect("camera");
    let r = ray(&c, 20.0, 15.0);
    let target = scene
        .camera
        .camera_transform
        .render_from_world()
        .apply_point(Point3f::new(0.0, 0.0, 0.0));
    // In camera-world space the camera sits at the render-space origin.
    assert!(closep(r.o, Point3f::new(0.0, 0.0, 0.0), 1e-5), "{:?}", r.o);
    assert!(
        closep(target, Point3f::new(0.0, 0.0, 5.0), 1e-5),
        "{target:?}"
    );
    let t = (target - r.o).length();
    assert!(closep(r.at(t), target, 1e-4), "{:?}", r.at(t));
    // Up is still +y: the top of the image looks up.
    assert!(ray(&c, 20.0, 0.0).d.y > 0.0);
}

fn ray(c: &Camera, x: Float, y: Float) -> Ray {
    let s = CameraSample {
        p_film: Point2f::new(x, y),
        ..Default::default()
    };
    c.generate_ray(&s).expect("a ray").ray
}

fn closep(a: Point3f, b: Point3f, eps: Float) -> bool {
    (a - b).length() <= eps
}

#[test]
fn the_scene_gives_the_camera_its_filter_radius() {
    use crate::scene::assemble::{create_scene, CreateOptions};
    use rpbrt_geometry::Vector2f;
    let text = "Camera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 20 \
                \"integer yresolution\" 10\nPixelFilter \"gaussian\" \"float xradius\" 2 \
                \"float yradius\" 1\nWorldBegin\n";
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default()).expect("scene");
    let Ok(created) = create_scene(&desc, &CreateOptions::default()) else {
        panic!("scene creation failed")
    };
    let camera = &created.scene.camera;
    assert_eq!(camera.base().filter_radius, Vector2f::new(2.0, 1.0));
    assert_eq!(
        camera.base().film_sample_bounds(),
        created.scene.film.sample_bounds()
    );
}
