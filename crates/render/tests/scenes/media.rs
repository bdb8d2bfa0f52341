//! Participating media end to end: analytic scenes in the style of
//! pbrt-v4's `cpu/integrators_test.cpp` (the mean radiance must match the
//! closed form), `volpath` against `simplevolpath`, determinism across
//! thread counts, and located errors for bad media.

use rpbrt_render::image::Image;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use std::path::PathBuf;

use crate::common::render_scene;

fn out_path(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-media-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{tag}.exr"))
}

fn mean_rgb(im: &Image) -> f64 {
    let v = im.to_f32_vec();
    assert!(v.iter().all(|x| x.is_finite()), "non-finite pixel");
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

fn check(name: &str, im: &Image, expected: f64, rel_tol: f64) {
    let m = mean_rgb(im);
    assert!(
        (m - expected).abs() <= rel_tol * expected,
        "{name}: mean {m}, expected {expected}"
    );
}

/// Camera at the origin looking down +z; `camera_medium` is the medium
/// the camera sits in (empty for none).
fn header(tag: &str, integrator: &str, spp: i32, ortho: bool, camera_medium: &str) -> String {
    let cam = if ortho {
        "Camera \"orthographic\" \"float screenwindow\" [ -0.3 0.3 -0.3 0.3 ]"
    } else {
        "Camera \"perspective\" \"float fov\" 60"
    };
    format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nMediumInterface \"\" \"{camera_medium}\"\n{cam}\nSampler \"zsobol\" \"integer pixelsamples\" {spp}\nFilm \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\nIntegrator \"{integrator}\" \"integer maxdepth\" 100\n",
        out_path(tag).display()
    )
}

/// A two-sided emitting plane at z = 3 (L = 1) behind a slab of absorbing
/// medium between z = 1 and z = 2 bounded by two `interface` planes whose
/// normals point out of the slab.
fn slab_scene(tag: &str, integrator: &str, medium: &str) -> String {
    header(tag, integrator, 16, true, "")
        + "WorldBegin\n"
        + medium
        + "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"bool twosided\" true\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 3  10 -10 3  10 10 3  -10 10 3 ] \"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n\
AttributeBegin\nMediumInterface \"slab\" \"\"\nMaterial \"interface\"\n\
Shape \"trianglemesh\" \"point3 P\" [ -10 -10 1  10 -10 1  10 10 1  -10 10 1 ] \"normal N\" [ 0 0 -1  0 0 -1  0 0 -1  0 0 -1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -10 -10 2  10 -10 2  10 10 2  -10 10 2 ] \"normal N\" [ 0 0 1  0 0 1  0 0 1  0 0 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
AttributeEnd\n"
}

#[test]
fn emitter_through_an_absorbing_slab() {
    let medium = "MakeNamedMedium \"slab\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 0 0 0 ]\n";
    for i in ["volpath", "simplevolpath"] {
        let tag = format!("slab-{i}");
        let im = render_scene(&slab_scene(&tag, i, medium), 0);
        check(&tag, &im, (-0.5f64).exp(), 0.01);
    }
    // The same slab as a constant `uniformgrid`: a grid's density falls off
    // within half a cell of its bounds, so they reach past the slab.
    let grid = "MakeNamedMedium \"slab\" \"string type\" \"uniformgrid\" \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 0 0 0 ] \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 4 \"float density\" [ 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 ] \"point3 p0\" [ -20 -20 0 ] \"point3 p1\" [ 20 20 3 ]\n";
    for i in ["volpath", "simplevolpath"] {
        let tag = format!("slab-grid-{i}");
        let im = render_scene(&slab_scene(&tag, i, grid), 0);
        check(&tag, &im, (-0.5f64).exp(), 0.01);
    }
    // Without the medium the interfaces are invisible.
    let im = render_scene(&slab_scene("slab-none", "volpath", "MakeNamedMedium \"slab\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] \"rgb sigma_s\" [ 0 0 0 ]\n"), 0);
    check("slab-none", &im, 1.0, 0.005);
}

#[test]
fn camera_inside_an_absorbing_medium() {
    // Every camera ray crosses 3 units of fog before the emitter.
    let text = header("camera-fog", "volpath", 16, true, "fog")
        + "WorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.2 0.2 0.2 ] \"rgb sigma_s\" [ 0 0 0 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"bool twosided\" true\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 3  10 -10 3  10 10 3  -10 10 3 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
    let im = render_scene(&text, 0);
    check("camera-fog", &im, (-0.6f64).exp(), 0.01);
}

/// A unit sphere around the camera, its inside filled with `medium`
/// ("fog"), with walls of the given reflectance emitting `le`.
fn filled_sphere(
    tag: &str,
    integrator: &str,
    spp: i32,
    medium: &str,
    reflectance: f64,
    le: f64,
) -> String {
    header(tag, integrator, spp, false, "fog")
        + "WorldBegin\n"
        + medium
        + &format!("AttributeBegin\nReverseOrientation\nMediumInterface \"\" \"fog\"\nMaterial \"diffuse\" \"rgb reflectance\" [ {reflectance} {reflectance} {reflectance} ]\n")
        + &if le > 0.0 { format!("AreaLightSource \"diffuse\" \"rgb L\" [ {le} {le} {le} ]\n") } else { String::new() }
        + "Shape \"sphere\" \"float radius\" 1\nAttributeEnd\n"
}

#[test]
fn scattering_medium_in_a_furnace_keeps_radiance_one() {
    let medium = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] \"rgb sigma_s\" [ 1.5 1.5 1.5 ] \"float g\" 0.4\n";
    // Walls of albedo 0.5 emitting 0.5: L = 1 without the medium, and a
    // conservative medium keeps the uniform radiance.
    let im = render_scene(
        &filled_sphere("furnace-volpath", "volpath", 64, medium, 0.5, 0.5),
        0,
    );
    check("furnace-volpath", &im, 1.0, 0.03);
    // bdpt connects through the medium (pbrt-v4's RandomWalk and Tr).
    let text = filled_sphere("furnace-bdpt", "bdpt", 16, medium, 0.5, 0.5)
        .replace("\"integer maxdepth\" 100", "\"integer maxdepth\" 24");
    let im = render_scene(&text, 0);
    check("furnace-bdpt", &im, 1.0, 0.03);
    // simplevolpath takes black walls emitting 1.
    let im = render_scene(
        &filled_sphere("furnace-simple", "simplevolpath", 64, medium, 0.0, 1.0),
        0,
    );
    check("furnace-simple", &im, 1.0, 0.03);
}

#[test]
fn emitting_absorbing_medium_seen_from_the_centre() {
    // Le (1 − e^{−σa r}) with σa = 0.7, r = 1 and Le = 2 (an RGB emission
    // is normalised like a light's, so it renders at its RGB value).
    let medium = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.7 0.7 0.7 ] \"rgb sigma_s\" [ 0 0 0 ] \"rgb Le\" [ 2 2 2 ]\n";
    let expected = 2.0 * (1.0 - (-0.7f64).exp());
    for i in ["volpath", "simplevolpath"] {
        let tag = format!("emissive-{i}");
        let spp = if i == "simplevolpath" { 256 } else { 64 };
        let im = render_scene(&filled_sphere(&tag, i, spp, medium, 0.0, 0.0), 0);
        check(&tag, &im, expected, 0.03);
    }
}

#[test]
fn chromatic_scattering_medium_converges_like_simplevolpath() {
    // A chromatic medium (spectral MIS in volpath) around the camera in a
    // furnace of black walls emitting 1, with some absorption: volpath and
    // the hero-wavelength reference agree.
    let medium = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.05 0.3 0.6 ] \"rgb sigma_s\" [ 2 0.8 0.2 ] \"float g\" -0.3\n";
    let a = mean_rgb(&render_scene(
        &filled_sphere("chroma-volpath", "volpath", 128, medium, 0.0, 1.0),
        0,
    ));
    let b = mean_rgb(&render_scene(
        &filled_sphere("chroma-simple", "simplevolpath", 512, medium, 0.0, 1.0),
        0,
    ));
    assert!((a - b).abs() < 0.03 * b, "volpath {a} vs simplevolpath {b}");

    assert!(
        a < 0.95 && a > 0.3,
        "absorption must darken the furnace: {a}"
    );
}

/// bdpt through a chromatic medium converges to volpath's image. Its
/// random walks weight the other wavelengths by ratios to the hero's
/// (pbrt-v4's `RandomWalk`, without volpath's spectral MIS), whose
/// variance grows fast with the medium's chromaticity: the medium here is
/// mildly chromatic, with walls that reflect and emit.
#[test]
fn bdpt_through_a_chromatic_medium_matches_volpath() {
    let medium = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"rgb sigma_s\" [ 1 0.8 0.6 ] \"float g\" 0.3\n";
    let depth = |t: String| t.replace("\"integer maxdepth\" 100", "\"integer maxdepth\" 20");
    let v = render_scene(
        &depth(filled_sphere(
            "cbdpt-volpath",
            "volpath",
            256,
            medium,
            0.3,
            1.0,
        )),
        0,
    );
    let b = render_scene(
        &depth(filled_sphere("cbdpt-bdpt", "bdpt", 64, medium, 0.3, 1.0)),
        0,
    );
    // Channel by channel.
    let means = |im: &Image| {
        let v = im.to_f32_vec();
        let mut m = [0.0f64; 3];
        for p in v.chunks_exact(3) {
            for c in 0..3 {
                m[c] += p[c] as f64;
            }
        }
        m.map(|x| x / (v.len() / 3) as f64)
    };
    let (mv, mb) = (means(&v), means(&b));
    for c in 0..3 {
        assert!(
            (mv[c] - mb[c]).abs() < 0.03 * mv[c],
            "channel {c}: volpath {mv:?} vs bdpt {mb:?}"
        );
    }
}

#[test]
fn media_render_identically_on_one_and_two_threads() {
    let medium = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"rgb sigma_s\" [ 1 0.8 0.5 ]\n";
    let a = render_scene(&filled_sphere("det-1", "volpath", 8, medium, 0.5, 0.5), 1);
    let b = render_scene(&filled_sphere("det-2", "volpath", 8, medium, 0.5, 0.5), 2);
    assert_eq!(a.to_f32_vec(), b.to_f32_vec());
}

/// The errors `create_scene` reports for a scene, as "line: message".
fn creation_errors(text: &str) -> Vec<String> {
    let (desc, _) = match build_scene_from_str(text, &BuildOptions::default()) {
        Ok(d) => d,
        Err(d) => {
            return d
                .iter()
                .map(|d| format!("{}: {}", d.loc.as_ref().map_or(0, |l| l.line), d.message))
                .collect()
        }
    };
    match create_scene(&desc, &CreateOptions::default()) {
        Ok(_) => Vec::new(),
        Err(e) => e
            .iter()
            .map(|d| format!("{}: {}", d.loc.as_ref().map_or(0, |l| l.line), d.message))
            .collect(),
    }
}

#[test]
fn bad_media_are_located_errors() {
    let base =
        "Film \"rgb\" \"string filename\" \"/dev/null.exr\"\nIntegrator \"volpath\"\nWorldBegin\n";
    let cases = [
        (
            "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ -1 0 0 ]\n",
            "sigma_a",
        ),
        (
            "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float scale\" -2\n",
            "scale",
        ),
        (
            "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" nan\n",
            "",
        ),
        ("MakeNamedMedium \"m\" \"string type\" \"smoke\"\n", "smoke"),
        (
            "MediumInterface \"nothere\" \"\"\nShape \"sphere\"\n",
            "nothere",
        ),
    ];
    for (text, needle) in cases {
        let errs = creation_errors(&format!("{base}{text}"));
        assert!(!errs.is_empty(), "no error for {text:?}");
        assert!(
            errs.iter()
                .any(|e| e.starts_with("4: ") || e.starts_with("5: ")),
            "{errs:?}"
        );
        assert!(
            errs.iter().any(|e| e.contains(needle)),
            "{errs:?} lacks {needle:?}"
        );
    }
}

#[test]
fn simplevolpath_refuses_delta_lights_and_scattering_surfaces() {
    let base = "Film \"rgb\" \"string filename\" \"/dev/null.exr\"\nIntegrator \"simplevolpath\"\nWorldBegin\n";
    let errs = creation_errors(&format!("{base}LightSource \"point\"\n"));
    assert!(
        errs.iter()
            .any(|e| e.starts_with("4: ") && e.contains("area and infinite")),
        "{errs:?}"
    );
    let errs = creation_errors(&format!("{base}Material \"conductor\"\nShape \"sphere\"\n"));
    assert!(
        errs.iter().any(|e| e.contains("surface scattering")),
        "{errs:?}"
    );
}
