//! `plymesh` displacement end to end (pbrt-v4's `displacement` texture and
//! `edgelength`): a flat square displaced by d = u/2 renders as the
//! explicitly tilted square does, and not as the flat one; an undefined
//! texture and a non-positive edge length are located errors.

use rpbrt_parser::ply::{write_ply, PlyMesh};
use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use std::path::{Path, PathBuf};

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-displacement-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The unit square in z = 0 as one quad, uv = (x, y).
fn square_ply(dir: &Path) -> PathBuf {
    let path = dir.join("square.ply");
    let mesh = PlyMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        quad_indices: vec![0, 1, 3, 2],
        ..PlyMesh::default()
    };
    write_ply(&path, &mesh).unwrap();
    path
}

/// The square seen from above, lit by a distant light, direct lighting.
fn scene(out: &Path, shape: &str) -> String {
    format!(
        "LookAt 0.5 0.5 5  0.5 0.5 0  0 1 0\n\
         Camera \"orthographic\" \"float screenwindow\" [ -0.4 0.4 -0.4 0.4 ]\n\
         Sampler \"independent\" \"integer pixelsamples\" 4\n\
         Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Integrator \"path\" \"integer maxdepth\" 1\nWorldBegin\n\
         LightSource \"distant\" \"point3 from\" [ 0.6 0.2 1 ] \"point3 to\" [ 0 0 0 ] \"float scale\" 3\n\
         Texture \"d\" \"float\" \"bilerp\" \"float v00\" 0 \"float v10\" 0.5 \"float v01\" 0 \"float v11\" 0.5\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n{shape}\n",
        out.display()
    )
}

/// Renders scene text, or returns the creation errors.
fn render(text: &str) -> Result<Vec<f32>, Vec<rpbrt_parser::Diagnostic>> {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let created = create_scene(&desc, &CreateOptions::default())?;
    let mut scene = created.scene;
    let mut md = ImageMetadata::default();
    created
        .integrator
        .render(&mut scene, &RenderOptions::default(), &mut md, &|_| {})
        .unwrap();
    let path = scene.film.filename().to_string();
    Ok(Image::read(Path::new(&path), None)
        .unwrap()
        .image
        .to_f32_vec())
}

fn max_rel_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x - y).abs() / x.abs().max(y.abs()).max(1e-3))
        .fold(0.0, f32::max)
}

#[test]
fn displaced_plane_renders_as_the_explicitly_displaced_one() {
    let dir = temp_dir("render");
    let ply = square_ply(&dir);
    let displaced = format!(
        "Shape \"plymesh\" \"string filename\" \"{}\" \"texture displacement\" \"d\" \"float edgelength\" 0.1",
        ply.display()
    );
    // d = u/2 along the normal +z: the plane z = x/2.
    let explicit = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0.5  1 1 0.5  0 1 0 ] \
                    \"integer indices\" [ 0 1 2  0 2 3 ] \"point2 uv\" [ 0 0  1 0  1 1  0 1 ]";
    let flat = format!(
        "Shape \"plymesh\" \"string filename\" \"{}\"",
        ply.display()
    );
    let a = render(&scene(&dir.join("a.exr"), &displaced)).unwrap();
    let b = render(&scene(&dir.join("b.exr"), explicit)).unwrap();
    let c = render(&scene(&dir.join("c.exr"), &flat)).unwrap();
    assert!(a.iter().all(|&v| v > 0.01), "the square fills the frame");
    let same = max_rel_diff(&a, &b);
    assert!(same < 1e-3, "displaced vs explicit: {same}");
    let differ = max_rel_diff(&a, &c);
    assert!(differ > 0.05, "displaced vs flat: {differ}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn displacement_errors_are_located() {
    let dir = temp_dir("errors");
    let ply = square_ply(&dir);
    // An undefined texture: an error at the parameter (line 10, the shape).
    let shape = format!(
        "Shape \"plymesh\" \"string filename\" \"{}\" \"texture displacement\" \"nosuch\"",
        ply.display()
    );
    let errors = render(&scene(&dir.join("o.exr"), &shape)).unwrap_err();
    let e = &errors[0];
    assert!(e.message.contains("nosuch"), "{}", e.message);
    assert_eq!(e.loc.as_ref().map(|l| l.line), Some(10), "{e:?}");
    // A non-positive edge length, at its parameter.
    for bad in ["0", "-2"] {
        let shape = format!(
            "Shape \"plymesh\" \"string filename\" \"{}\" \"texture displacement\" \"d\"\n  \"float edgelength\" {bad}",
            ply.display()
        );
        let errors = render(&scene(&dir.join("o.exr"), &shape)).unwrap_err();
        let e = &errors[0];
        assert!(e.message.contains("edgelength"), "{}", e.message);
        assert_eq!(
            e.loc.as_ref().map(|l| (l.line, l.column)),
            Some((11, 3)),
            "{e:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
