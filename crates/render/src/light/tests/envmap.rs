//! pbrt-v3 latitude–longitude environment maps on pbrt-v4's image infinite
//! light: resampled on load with a located warning, and lit from where
//! pbrt-v3's `InfiniteAreaLight` puts each texel: θ = π v, φ = 2π u in
//! light space, then the light's transform.

use rpbrt_geometry::{
    angle_between, AnimatedTransform, Point2f, Point2i, Point3f, Ray, Transform, Vector3f,
};
use rpbrt_parser::ParsedParameter;

use super::{create_light, entity, line_of, ploc};
use crate::camera::CameraTransform;
use crate::image::equiarea::equirect_to_direction;
use crate::image::Image;
use crate::light::{Light, LightSampleContext};
use crate::rng::Rng;
use crate::spectrum::SampledWavelengths;

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-envmap-light-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A `w` × `h` RGB map of 0.01 with one texel of 1000 at `sun`.
fn sun_map(w: i32, h: i32, sun: Point2i) -> Image {
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let v = if Point2i::new(x, y) == sun {
                1000.0
            } else {
                0.01
            };
            data.extend_from_slice(&[v, v, v]);
        }
    }
    Image::from_f32(data, Point2i::new(w, h), &["R", "G", "B"]).unwrap()
}

fn file_param(path: &std::path::Path) -> ParsedParameter {
    ParsedParameter::with_strings(
        "string",
        "filename",
        ploc(),
        vec![path.display().to_string()],
    )
}

/// Creates an infinite light from `path` under `xf`, returning it and its
/// warnings.
fn light_from(
    path: &std::path::Path,
    xf: Transform,
    pbrt_v3: bool,
) -> (Light, Vec<rpbrt_parser::Diagnostic>, u32) {
    let p = file_param(path);
    let line = p.loc.line;
    let mut e = entity("infinite", vec![p]);
    e.render_from_object = AnimatedTransform::fixed(xf);
    e.pbrt_v3 = pbrt_v3;
    let (l, w) = create_light(&e, None, &CameraTransform::default()).unwrap();
    (l, w, line)
}

fn equal_area_image(l: &Light) -> &Image {
    match l {
        Light::ImageInfinite(img) => &img.image,
        _ => panic!("not an image infinite light"),
    }
}

#[test]
fn pbrt_v3_sun_lands_where_pbrt_v3_puts_it() {
    let dir = temp_dir("sun");
    let (w, h) = (64, 32);
    let sun = Point2i::new(45, 10);
    let path = dir.join("sun.pfm");
    sun_map(w, h, sun)
        .write(&path, &Default::default())
        .unwrap();
    let xf = Transform::rotate(30.0, Vector3f::new(1.0, 1.0, 0.0)) * Transform::rotate_z(-70.0);
    let (light, warnings, line) = light_from(&path, xf, true);

    // One warning, at the file name, saying what happened.
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].message.contains("latitude-longitude"),
        "{}",
        warnings[0].message
    );
    assert_eq!(line_of(&warnings[0]), Some(line));
    assert_eq!(equal_area_image(&light).resolution(), Point2i::new(64, 64));

    // pbrt-v3: θ = π (y + ½) / h, φ = 2π (x + ½) / w, then light to world.
    let want = xf
        .apply_vector(equirect_to_direction(Point2f::new(
            (sun.x as f32 + 0.5) / w as f32,
            (sun.y as f32 + 0.5) / h as f32,
        )))
        .normalize();

    // Sampling: the brightest sampled direction is the sun's, and nearly
    // all samples go there (it holds ~98% of the map's power).
    let ctx = LightSampleContext::from_point(Point3f::new(0.0, 0.0, 0.0));
    let lambda = SampledWavelengths::sample_visible(0.5);
    let mut rng = Rng::with_sequence(3);
    let (mut best, mut best_l) = (Vector3f::new(0.0, 0.0, 0.0), -1.0);
    let (mut near, n) = (0, 4000);
    for _ in 0..n {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let Some(s) = light.sample_li(&ctx, u, &lambda, false) else {
            continue;
        };
        let l = s.l.average();
        if l > best_l {
            (best, best_l) = (s.wi, l);
        }
        if angle_between(s.wi, want) < 0.15 {
            near += 1;
        }
    }
    let angle = angle_between(best, want);
    // An equal-area texel of a 64² map spans ~0.055 rad; the resampling
    // filter reaches 1.5 texels.
    assert!(
        angle < 0.08,
        "brightest sample {best:?} is {angle} rad from {want:?}"
    );
    assert!(
        near as f64 > 0.9 * n as f64,
        "{near} of {n} samples near the sun"
    );

    // Radiance along rays: bright toward the sun, background elsewhere.
    let toward = light.le(&Ray::new(Point3f::new(0.0, 0.0, 0.0), want), &lambda);
    let away = light.le(&Ray::new(Point3f::new(0.0, 0.0, 0.0), -want), &lambda);
    assert!(
        toward.average() > 1000.0 * away.average(),
        "{toward:?} vs {away:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn wide_pbrt_v4_map_is_read_as_latitude_longitude() {
    let dir = temp_dir("wide");
    let path = dir.join("wide.pfm");
    sun_map(32, 16, Point2i::new(5, 12))
        .write(&path, &Default::default())
        .unwrap();
    let (v4, w4, line) = light_from(&path, Transform::identity(), false);
    assert_eq!(w4.len(), 1, "{w4:?}");
    assert!(w4[0].message.contains("2:1"), "{}", w4[0].message);
    assert_eq!(line_of(&w4[0]), Some(line));
    let (v3, w3, _) = light_from(&path, Transform::identity(), true);
    assert!(w3[0].message.contains("pbrt-v3"), "{}", w3[0].message);
    // Same map, same resampling.
    assert_eq!(equal_area_image(&v4), equal_area_image(&v3));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn square_maps_equal_area_in_pbrt_v4_lat_long_in_pbrt_v3() {
    let dir = temp_dir("square");
    let path = dir.join("square.pfm");
    let map = sun_map(16, 16, Point2i::new(3, 4));
    map.write(&path, &Default::default()).unwrap();
    let (v4, w4, _) = light_from(&path, Transform::identity(), false);
    assert!(w4.is_empty(), "{w4:?}");
    assert_eq!(equal_area_image(&v4), &map);
    let (v3, w3, _) = light_from(&path, Transform::identity(), true);
    assert_eq!(w3.len(), 1, "{w3:?}");
    assert_ne!(equal_area_image(&v3), &map);
    let _ = std::fs::remove_dir_all(&dir);
}
