//! Environment maps end to end: a latitude–longitude (pbrt-v3) map,
//! resampled by the infinite light on load, and its `makeequiarea`
//! conversion at another resolution light a diffuse sphere alike (mean
//! within 1%, per pixel within the renders' own noise); a pbrt-v3 file's
//! `mapname` is read as latitude–longitude even when square; other map
//! shapes are located errors.

use rpbrt_render::geometry::{Float, Point2f, Point2i};
use rpbrt_render::image::equiarea::{equirect_to_direction, equirect_to_equal_area};
use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use std::path::{Path, PathBuf};

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-envmap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 128 × 64 latitude–longitude sky: a smooth gradient (brighter toward
/// +z, bluer toward +x) plus a small bright sun.
fn sky(path: &Path) {
    let (w, h): (i32, i32) = (128, 64);
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let uv = Point2f::new(
                (x as Float + 0.5) / w as Float,
                (y as Float + 0.5) / h as Float,
            );
            let d = equirect_to_direction(uv);
            let sun = if (x - 30).abs() <= 1 && (y - 20).abs() <= 1 {
                60.0
            } else {
                0.0
            };
            let base = 0.4 + 0.3 * d.z;
            data.extend_from_slice(&[base + sun, base + sun, base + 0.2 * d.x + sun]);
        }
    }
    Image::from_f32(data, Point2i::new(w, h), &["R", "G", "B"])
        .unwrap()
        .write(path, &ImageMetadata::default())
        .unwrap();
}

/// A diffuse sphere filling the frame, lit by the infinite light `light`
/// (every option given: a `mapname` makes the file pbrt-v3, whose
/// defaults differ).
fn scene(light: &str, out: &Path, seed: i32) -> String {
    format!(
        "LookAt 0 -3 0.5  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 20\n\
         Sampler \"independent\" \"integer pixelsamples\" 64 \"integer seed\" {seed}\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24 \"string filename\" \"{}\"\n\
         Integrator \"path\" \"integer maxdepth\" 5 PixelFilter \"gaussian\"\nWorldBegin\n\
         AttributeBegin\nRotate 20 1 0 0\n{light}\nAttributeEnd\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.7 ]\nShape \"sphere\" \"float radius\" 1\n",
        out.display()
    )
}

/// Renders scene text; returns the image and the creation warnings.
fn render(text: &str) -> (Vec<f32>, Vec<String>) {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let created = match create_scene(&desc, &CreateOptions::default()) {
        Ok(c) => c,
        Err(e) => panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        ),
    };
    let warnings = created.warnings.iter().map(|d| d.message.clone()).collect();
    let mut scene = created.scene;
    let mut md = ImageMetadata::default();
    created
        .integrator
        .render(&mut scene, &RenderOptions::default(), &mut md, &|_| {})
        .unwrap();
    let path = scene.film.filename().to_string();
    let im = Image::read(Path::new(&path), None).unwrap().image;
    (im.to_f32_vec(), warnings)
}

fn mean(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

fn rms_diff(a: &[f32], b: &[f32]) -> f64 {
    (a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64)
        .sqrt()
}

#[test]
fn lat_long_map_and_its_equal_area_conversion_light_a_sphere_alike() {
    let dir = temp_dir();
    let latlong = dir.join("sky.pfm");
    sky(&latlong);
    // makeequiarea's conversion, at a resolution other than the light's.
    let equal_area = dir.join("sky-equiarea.pfm");
    let ll = Image::read(&latlong, None).unwrap().image;
    equirect_to_equal_area(&ll, 96)
        .unwrap()
        .write(&equal_area, &ImageMetadata::default())
        .unwrap();

    let v3 = format!(
        "LightSource \"infinite\" \"string mapname\" \"{}\"",
        latlong.display()
    );
    let v4_wide = format!(
        "LightSource \"infinite\" \"string filename\" \"{}\"",
        latlong.display()
    );
    let v4 = format!(
        "LightSource \"infinite\" \"string filename\" \"{}\"",
        equal_area.display()
    );
    let (a, wa) = render(&scene(&v3, &dir.join("a.exr"), 1));
    let (a2, _) = render(&scene(&v4_wide, &dir.join("a2.exr"), 1));
    let (b, wb) = render(&scene(&v4, &dir.join("b.exr"), 1));
    let (b2, _) = render(&scene(&v4, &dir.join("b2.exr"), 2));

    assert!(
        wa.iter().any(|w| w.contains("latitude-longitude")),
        "{wa:?}"
    );
    assert!(
        !wb.iter().any(|w| w.contains("latitude-longitude")),
        "{wb:?}"
    );
    // The pbrt-v3 file and the 2:1 pbrt-v4 file load the same map.
    assert_eq!(a, a2);

    let (ma, mb) = (mean(&a), mean(&b));
    assert!(ma > 0.1, "{ma}");
    assert!((ma / mb - 1.0).abs() < 0.01, "means {ma} vs {mb}");
    // Per pixel: the two maps differ far less than two renders of the same
    // map with different seeds do (with the same seed the sample patterns
    // match, so what is left is the maps' own difference).
    let noise = rms_diff(&b, &b2);
    let diff = rms_diff(&a, &b);
    eprintln!("means {ma} {mb}; rms difference {diff}, noise {noise}");
    assert!(diff < 0.25 * noise, "rms difference {diff}, noise {noise}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn pbrt_v3_mapname_is_lat_long_even_when_square() {
    let dir = temp_dir().join("square");
    std::fs::create_dir_all(&dir).unwrap();
    let map = dir.join("square.pfm");
    Image::from_f32(vec![1.0; 8 * 8 * 3], Point2i::new(8, 8), &["R", "G", "B"])
        .unwrap()
        .write(&map, &ImageMetadata::default())
        .unwrap();
    let v3 = format!(
        "LightSource \"infinite\" \"string mapname\" \"{}\"",
        map.display()
    );
    let (desc, _) =
        build_scene_from_str(&scene(&v3, &dir.join("o.exr"), 1), &BuildOptions::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
    assert!(desc.lights[0].pbrt_v3);
    let created = create_scene(&desc, &CreateOptions::default()).ok().unwrap();
    assert!(
        created
            .warnings
            .iter()
            .any(|w| w.message.contains("pbrt-v3")),
        "{:?}",
        created.warnings
    );
    let v4 = format!(
        "LightSource \"infinite\" \"string filename\" \"{}\"",
        map.display()
    );
    let (desc, _) =
        build_scene_from_str(&scene(&v4, &dir.join("o.exr"), 1), &BuildOptions::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
    assert!(!desc.lights[0].pbrt_v3);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn env_map_neither_square_nor_two_to_one_is_a_located_error() {
    let dir = temp_dir().join("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let map = dir.join("bad.pfm");
    Image::from_f32(vec![1.0; 9 * 4 * 3], Point2i::new(9, 4), &["R", "G", "B"])
        .unwrap()
        .write(&map, &ImageMetadata::default())
        .unwrap();
    let light = format!(
        "LightSource \"infinite\" \"string mapname\" \"{}\"",
        map.display()
    );
    let text = scene(&light, &dir.join("o.exr"), 1);
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let errors = match create_scene(&desc, &CreateOptions::default()) {
        Ok(_) => panic!("a 9x4 environment map was accepted"),
        Err(e) => e,
    };
    let e = &errors[0];
    assert!(e.message.contains("neither square"), "{}", e.message);
    // The light is on line 9 of the scene text; its file name at column 24.
    assert_eq!(
        e.loc.as_ref().map(|l| (l.line, l.column)),
        Some((9, 24)),
        "{e:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
