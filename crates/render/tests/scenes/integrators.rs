//! pbrt-v4's analytic integrator scenes (`cpu/integrators_test.cpp`),
//! written as scene files and rendered end to end: the mean radiance must
//! match the closed form within 2.5%, for every integrator, sampler and
//! camera. Plus determinism across thread counts.

use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use std::path::PathBuf;

use crate::common;
use crate::common::{assert_same_pixels, render_scene, render_with};
use rpbrt_render::simd::SimdLevel;

fn out_path(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-integrators-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{tag}.exr"))
}

fn mean_rgb(im: &Image) -> f64 {
    let v = im.to_f32_vec();
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

fn camera(kind: &str) -> &'static str {
    match kind {
        "perspective" => "Camera \"perspective\" \"float fov\" 45",
        _ => "Camera \"orthographic\" \"float screenwindow\" [ -0.3 0.3 -0.3 0.3 ]",
    }
}

fn header(tag: &str, cam: &str, sampler: &str, integrator: &str, spp: i32) -> String {
    format!(
        "LookAt 0 0 0  0 0 1  0 1 0\n{}\nSampler \"{sampler}\" \"integer pixelsamples\" {spp}\nFilm \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\nIntegrator \"{integrator}\" \"integer maxdepth\" 64\n",
        camera(cam),
        out_path(tag).display()
    )
}

/// A closed sphere of reflectance 0.5 that emits 0.5: L = 0.5 / (1 − 0.5) = 1.
fn emitting_sphere(tag: &str, cam: &str, sampler: &str, integrator: &str, spp: i32) -> String {
    header(tag, cam, sampler, integrator, spp)
        + "WorldBegin\nAttributeBegin\nReverseOrientation\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 0.5 0.5 0.5 ]\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"
}

/// A closed sphere of reflectance 0.5 with a point light of intensity π at
/// its centre: direct 0.5 per bounce, L = 1.
fn point_lit_sphere(tag: &str, cam: &str, sampler: &str, integrator: &str, spp: i32) -> String {
    header(tag, cam, sampler, integrator, spp)
        + "WorldBegin\nLightSource \"point\" \"rgb I\" [ 3.14159265 3.14159265 3.14159265 ]\nAttributeBegin\nReverseOrientation\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n"
}

fn check(name: &str, im: &Image, expected: f64, tol: f64) {
    let m = mean_rgb(im);
    assert!(
        (m - expected).abs() <= tol,
        "{name}: mean {m}, expected {expected}"
    );
}

const SAMPLERS: &[&str] = &[
    "independent",
    "stratified",
    "halton",
    "sobol",
    "paddedsobol",
    "zsobol",
    "pmj02bn",
];

#[test]
fn furnace_every_sampler_and_camera() {
    for cam in ["perspective", "orthographic"] {
        for s in SAMPLERS {
            let tag = format!("furnace-{cam}-{s}");
            let im = render_scene(&emitting_sphere(&tag, cam, s, "path", 16), 0);
            check(&tag, &im, 1.0, 0.025);
        }
    }
}

#[test]
fn furnace_every_integrator() {
    for i in ["path", "volpath", "simplepath", "randomwalk"] {
        let spp = if i == "randomwalk" { 256 } else { 32 };
        let tag = format!("furnace-int-{i}");
        let im = render_scene(&emitting_sphere(&tag, "perspective", "zsobol", i, spp), 0);
        check(&tag, &im, 1.0, 0.025);
    }
}

#[test]
fn point_light_in_sphere() {
    for i in ["path", "volpath", "simplepath"] {
        for cam in ["perspective", "orthographic"] {
            let tag = format!("point-{i}-{cam}");
            let im = render_scene(&point_lit_sphere(&tag, cam, "zsobol", i, 32), 0);
            check(&tag, &im, 1.0, 0.025);
        }
    }
}

#[test]
fn lambertian_plane_under_distant_light() {
    // The plane z = 1 seen head-on; light arriving at 60° from the normal
    // with unit irradiance at normal incidence: L = 0.5/π · cos 60°.
    for i in ["path", "simplepath"] {
        let tag = format!("distant-{i}");
        let text = header(&tag, "orthographic", "zsobol", i, 16)
            + "WorldBegin\nLightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0.8660254 0.5 ] \"rgb L\" [ 1 1 1 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 1  10 -10 1  10 10 1  -10 10 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
        let im = render_scene(&text, 0);
        let expected = 0.5 / std::f64::consts::PI * 0.5;
        check(&tag, &im, expected, 0.025 * expected);
    }
}

#[test]
fn point_light_over_plane() {
    // A point light of intensity 2 at height 1 over the plane, seen in a
    // narrow orthographic window around the foot point: L = 0.5/π · 2.
    let tag = "point-plane";
    let text = format!(
        "LookAt 0 0 -1  0 0 1  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [ -0.01 0.01 -0.01 0.01 ]\nSampler \"zsobol\" \"integer pixelsamples\" 16\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"{}\"\nIntegrator \"path\" \"integer maxdepth\" 5\nWorldBegin\nLightSource \"point\" \"point3 from\" [ 0 0 0 ] \"rgb I\" [ 2 2 2 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 1  10 -10 1  10 10 1  -10 10 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n",
        out_path(tag).display()
    );
    let im = render_scene(&text, 0);
    let expected = 0.5 / std::f64::consts::PI * 2.0;
    check(tag, &im, expected, 0.01 * expected);
}

#[test]
fn one_and_two_threads_give_identical_pixels() {
    let a = render_scene(
        &emitting_sphere("det-1", "perspective", "zsobol", "path", 8),
        1,
    );
    let b = render_scene(
        &emitting_sphere("det-2", "perspective", "zsobol", "path", 8),
        2,
    );
    assert_eq!(a.to_f32_vec(), b.to_f32_vec());
}

/// The G-buffer film against an analytic scene: a plane of reflectance
/// 0.3 at z = 4 facing the camera (which looks down +z): albedo 0.3, normals
/// facing the camera, camera-space depth 4.
#[test]
fn gbuffer_channels_match_an_analytic_scene() {
    let text = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"orthographic\"\nSampler \"zsobol\" \"integer pixelsamples\" 4\nFilm \"gbuffer\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"{}\"\nWorldBegin\nLightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ] \"rgb L\" [ 1 1 1 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.3 0.3 0.3 ]\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 4  10 -10 4  10 10 4  -10 10 4 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n",
        out_path("gbuffer").display()
    );
    let im = render_scene(&text, 0);
    let mean = |name: &str| -> f64 {
        let c = im
            .channel_names()
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no channel {name}: {:?}", im.channel_names()));
        let nc = im.n_channels();
        let v = im.to_f32_vec();
        let vals: Vec<f64> = v.chunks_exact(nc).map(|px| px[c] as f64).collect();
        vals.iter().sum::<f64>() / vals.len() as f64
    };
    for c in ["Albedo.R", "Albedo.G", "Albedo.B"] {
        assert!((mean(c) - 0.3).abs() < 0.01, "{c} = {}", mean(c));
    }
    assert!((mean("N.Z") + 1.0).abs() < 1e-3, "N.Z = {}", mean("N.Z"));
    assert!((mean("Ns.Z") + 1.0).abs() < 1e-3, "Ns.Z = {}", mean("Ns.Z"));
    assert!((mean("P.Z") - 4.0).abs() < 1e-3, "P.Z = {}", mean("P.Z"));
    // Radiance: L = 0.3/π under unit irradiance at normal incidence.
    let r = mean("R");
    assert!((r - 0.3 / std::f64::consts::PI).abs() < 0.01 * r, "R = {r}");
}

/// `--force-diffuse` turns a mirror into a diffuse surface of its albedo.
#[test]
fn force_diffuse_replaces_materials() {
    let text = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"orthographic\"\nSampler \"zsobol\" \"integer pixelsamples\" 16\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"{}\"\nOption \"bool forcediffuse\" true\nWorldBegin\nLightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ] \"rgb L\" [ 1 1 1 ]\nMaterial \"conductor\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 4  10 -10 4  10 10 4  -10 10 4 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n",
        out_path("forcediffuse").display()
    );
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let opts = CreateOptions {
        force_diffuse: true,
        ..Default::default()
    };
    let created = create_scene(&desc, &opts).unwrap_or_else(|e| {
        panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        )
    });
    let mut scene = created.scene;
    let mut md = ImageMetadata::default();
    created
        .integrator
        .render(&mut scene, &RenderOptions::default(), &mut md, &|_| {})
        .unwrap();
    let im = Image::read(std::path::Path::new(scene.film.filename()), None)
        .unwrap()
        .image;
    // A mirror would reflect nothing toward an orthographic camera looking
    // along the light; the diffuse stand-in reflects ≈ 0.5/π.
    let m = mean_rgb(&im);
    assert!(
        (m - 0.5 / std::f64::consts::PI).abs() < 0.03 * m,
        "mean {m}"
    );
}

/// Creates the scene of `text` (a tiny emitting sphere).
fn created(text: &str) -> rpbrt_render::scene::assemble::CreatedScene {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    create_scene(&desc, &CreateOptions::default()).unwrap_or_else(|e| {
        panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        )
    })
}

/// `Integrator::render` reports progress to its callback, last with every
/// sample done, for each integrator.
#[test]
fn render_reports_progress_to_the_callback() {
    for integrator in ["path", "simplepath", "ambientocclusion", "randomwalk"] {
        let tag = format!("progress-{integrator}");
        let c = created(&emitting_sphere(
            &tag,
            "orthographic",
            "independent",
            integrator,
            4,
        ));
        let mut scene = c.scene;
        let reports = std::sync::Mutex::new(Vec::new());
        let stats = c
            .integrator
            .render(
                &mut scene,
                &RenderOptions::default(),
                &mut ImageMetadata::default(),
                &|p| reports.lock().unwrap().push(p),
            )
            .unwrap();
        let reports = reports.into_inner().unwrap();
        let last = reports.last().expect("no progress reported");
        // A 16×16 film at 4 samples per pixel.
        assert_eq!(last.total, 16 * 16 * 4, "{integrator}");
        assert_eq!(last.done, last.total, "{integrator}");
        assert_eq!(stats.samples, last.total, "{integrator}");
        // Reports never go backwards.
        assert!(
            reports
                .windows(2)
                .all(|w| w[0].done <= w[1].done && w[0].elapsed <= w[1].elapsed),
            "{integrator}: {reports:?}"
        );
    }
}

/// A render fails with a typed error: an MSE reference image of another
/// resolution, and an image file that cannot be written.
#[test]
fn render_errors_are_typed() {
    use rpbrt_render::integrator::RenderError;
    let c = created(&emitting_sphere(
        "mse-mismatch",
        "orthographic",
        "independent",
        "path",
        1,
    ));
    let mut scene = c.scene;
    let reference = Image::new(
        rpbrt_render::image::PixelFormat::Float,
        rpbrt_geometry::Point2i::new(3, 5),
        &["R", "G", "B"],
        rpbrt_render::image::ColorEncoding::Linear,
    );
    let opts = RenderOptions {
        mse_reference: Some(reference),
        ..Default::default()
    };
    let err = c
        .integrator
        .render(&mut scene, &opts, &mut ImageMetadata::default(), &|_| {})
        .unwrap_err();
    assert!(matches!(err, RenderError::MseReference(_)), "{err:?}");
    assert!(std::error::Error::source(&err).is_some());

    let text = emitting_sphere("unwritable", "orthographic", "independent", "path", 1).replace(
        &out_path("unwritable").display().to_string(),
        "/nonexistent-rpbrt-dir/x.exr",
    );
    let c = created(&text);
    let mut scene = c.scene;
    let err = c
        .integrator
        .render(
            &mut scene,
            &RenderOptions::default(),
            &mut ImageMetadata::default(),
            &|_| {},
        )
        .unwrap_err();
    match &err {
        RenderError::WriteImage { path, .. } => assert_eq!(path, "/nonexistent-rpbrt-dir/x.exr"),
        e => panic!("{e:?}"),
    }
    assert!(
        err.to_string().contains("/nonexistent-rpbrt-dir/x.exr"),
        "{err}"
    );
}

/// `text` with the integrator's maximum depth set to `depth` and `extra`
/// parameters added to the `Integrator` directive.
fn with_integrator_params(text: String, depth: i32, extra: &str) -> String {
    text.replace(
        "\"integer maxdepth\" 64",
        &format!("\"integer maxdepth\" {depth} {extra}"),
    )
}

/// Parameters that keep MLT's bootstrap and chains small for 16×16 tests.
const MLT_PARAMS: &str = "\"integer bootstrapsamples\" 4000 \"integer chains\" 64";

/// The bidirectional integrators on pbrt-v4's closed-sphere scenes (its
/// `integrators_test` runs them on the same): an emitting sphere and a
/// point light at the centre, both of radiance 1 everywhere, with several
/// samplers. Paths of 12 bounces lose 0.5^13 of the answer.
#[test]
fn closed_spheres_with_the_bidirectional_integrators() {
    let cases: &[(&str, &str, &[&str], i32)] = &[
        ("bdpt", "", &["independent", "halton", "zsobol"], 16),
        ("lightpath", "", &["independent", "zsobol"], 32),
        ("mlt", MLT_PARAMS, &["independent"], 64),
    ];
    for &(integrator, extra, samplers, spp) in cases {
        for &s in samplers {
            let tag = format!("bidir-area-{integrator}-{s}");
            let text = emitting_sphere(&tag, "perspective", s, integrator, spp);
            let im = render_scene(&with_integrator_params(text, 12, extra), 0);
            check(&tag, &im, 1.0, 0.03);
            let tag = format!("bidir-point-{integrator}-{s}");
            let text = point_lit_sphere(&tag, "perspective", s, integrator, spp);
            let im = render_scene(&with_integrator_params(text, 12, extra), 0);
            check(&tag, &im, 1.0, 0.03);
        }
    }
}

/// Splats are applied in a fixed order: light tracing, bdpt and MLT give
/// the same pixels on one and on two threads.
#[test]
fn bidirectional_integrators_are_deterministic_across_thread_counts() {
    for (integrator, extra) in [("bdpt", ""), ("lightpath", ""), ("mlt", MLT_PARAMS)] {
        let render = |threads: usize| {
            let tag = format!("bidir-det-{integrator}-{threads}");
            let text = emitting_sphere(&tag, "perspective", "zsobol", integrator, 4);
            render_scene(&with_integrator_params(text, 5, extra), threads).to_f32_vec()
        };
        assert_eq!(render(1), render(2), "{integrator}");
    }
}

/// bdpt, lightpath and mlt need the camera's importance: other cameras
/// are pbrt-v4's located error, and bad MLT parameters are refused.
#[test]
fn bidirectional_integrators_refuse_what_they_cannot_render() {
    for integrator in ["bdpt", "lightpath", "mlt"] {
        let text = emitting_sphere("bidir-ortho", "orthographic", "zsobol", integrator, 1);
        let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
        let Err(errors) = create_scene(&desc, &CreateOptions::default()) else {
            panic!("{integrator} with an orthographic camera must fail");
        };
        assert!(
            errors
                .iter()
                .any(|e| e.message.contains("Only the \"perspective\" camera")
                    && e.loc.as_ref().is_some_and(|l| l.line == 5)),
            "{integrator}: {:?}",
            errors.iter().map(|e| &e.message).collect::<Vec<_>>()
        );
    }
    for (param, value) in [
        ("integer chains", "0"),
        ("float largestepprobability", "1.5"),
        ("float largestepprobability", "-0.1"),
        ("integer bootstrapsamples", "-3"),
        ("integer mutationsperpixel", "0"),
        ("float sigma", "0"),
    ] {
        let text = emitting_sphere("bidir-bad", "perspective", "zsobol", "mlt", 1);
        let text = with_integrator_params(text, 5, &format!("\"{param}\" {value}"));
        let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
        let Err(errors) = create_scene(&desc, &CreateOptions::default()) else {
            panic!("mlt with {param} {value} must fail");
        };
        let name = param.split(' ').nth(1).unwrap_or_default();
        assert!(
            errors.iter().any(|e| e.message.contains(name)),
            "{param}: {:?}",
            errors.iter().map(|e| &e.message).collect::<Vec<_>>()
        );
    }
}

/// SPPM on pbrt-v4's two analytic spheres (area-lit and point-lit), with
/// two samplers: the mean radiance is 1 within pbrt-v4's tolerance. The
/// part of a unit sphere within distance r of one of its points has area
/// exactly πr², but a visible point's BSDF turns away photons that arrive
/// below its own tangent plane, which at the default radius (1) costs a
/// few percent: hence a radius of 0.2.
#[test]
fn sppm_matches_the_analytic_spheres() {
    type SceneFn = fn(&str, &str, &str, &str, i32) -> String;
    let scenes: [(&str, SceneFn); 2] = [("emit", emitting_sphere), ("point", point_lit_sphere)];
    for sampler in ["zsobol", "halton"] {
        for (name, scene) in scenes {
            let tag = format!("sppm-{name}-{sampler}");
            let text = scene(&tag, "perspective", sampler, "sppm", 64).replace(
                "Integrator \"sppm\"",
                "Integrator \"sppm\" \"float radius\" 0.2",
            );
            let im = render_scene(&text, 0);
            check(&tag, &im, 1.0, 0.025);
        }
    }
}

/// SPPM's pixels do not depend on the thread count, photon contributions
/// included (several photon chunks, one of them partial).
#[test]
fn sppm_is_identical_on_one_and_three_threads() {
    let text = |tag: &str| {
        point_lit_sphere(tag, "perspective", "zsobol", "sppm", 4).replace(
            "Integrator \"sppm\"",
            "Integrator \"sppm\" \"integer photonsperiteration\" 2500 \"float radius\" 0.3",
        )
    };
    let a = render_scene(&text("sppm-det-1"), 1);
    let b = render_scene(&text("sppm-det-3"), 3);
    assert_eq!(a.to_f32_vec(), b.to_f32_vec());
    assert!(mean_rgb(&a) > 0.5);
}

/// SPPM reports its progress (camera paths and photons) up to its total,
/// and counts one sample per pixel and iteration.
#[test]
fn sppm_reports_progress() {
    let c = created(&emitting_sphere(
        "sppm-progress",
        "orthographic",
        "independent",
        "sppm",
        4,
    ));
    let mut scene = c.scene;
    let reports = std::sync::Mutex::new(Vec::new());
    let mut md = ImageMetadata::default();
    let stats = c
        .integrator
        .render(&mut scene, &RenderOptions::default(), &mut md, &|p| {
            reports.lock().unwrap().push(p)
        })
        .unwrap();
    let reports = reports.into_inner().unwrap();
    let last = reports.last().expect("no progress reported");
    // 4 iterations of 256 camera paths and 256 photons.
    assert_eq!(last.total, 4 * (256 + 256));
    assert_eq!(last.done, last.total);
    assert_eq!(stats.samples, 16 * 16 * 4);
    assert_eq!(md.samples_per_pixel, Some(4));
}

/// Bad SPPM parameters are errors located at the parameter.
#[test]
fn sppm_bad_parameters_are_located_errors() {
    let cases = [
        ("\"float radius\" 0", "radius"),
        ("\"float radius\" -0.5", "radius"),
        ("\"integer photonsperiteration\" 0", "photonsperiteration"),
        ("\"integer photonsperiteration\" -2", "photonsperiteration"),
    ];
    for (param, needle) in cases {
        let text = format!(
            "Film \"rgb\" \"string filename\" \"/dev/null.exr\"\nIntegrator \"sppm\" {param}\nWorldBegin\nShape \"sphere\"\n"
        );
        let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
        let errs = match create_scene(&desc, &CreateOptions::default()) {
            Ok(_) => panic!("no error for {param}"),
            Err(e) => e,
        };
        assert!(
            errs.iter().any(|d| {
                d.loc
                    .as_ref()
                    .is_some_and(|l| l.line == 2 && l.column == 19)
                    && d.message.contains(needle)
            }),
            "{param}: {:?}",
            errs.iter()
                .map(|d| (d.loc.clone(), d.message.clone()))
                .collect::<Vec<_>>()
        );
    }
}

/// pbrt-v3's `whitted`: direct light from every light at the first hit
/// (a point light over a diffuse plane, L = 0.5/π · 2, as above) and, seen
/// in a perfect mirror, the same plane: the mirror's reflectance times it.
#[test]
fn whitted_direct_light_and_a_mirror() {
    let scene = |tag: &str, mirror: bool| {
        let header = format!(
            "LookAt 0 0 -1  0 0 1  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [ -0.01 0.01 -0.01 0.01 ]\nSampler \"zsobol\" \"integer pixelsamples\" 16\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"{}\"\nIntegrator \"whitted\" \"integer maxdepth\" 5\nWorldBegin\nLightSource \"point\" \"point3 from\" [ 0 0 0 ] \"rgb I\" [ 2 2 2 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 1  10 -10 1  10 10 1  -10 10 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n",
            out_path(tag).display()
        );
        if mirror {
            // A mirror at z = -0.5 facing +z, seen from behind by a camera
            // at z = -0.4 looking down −z: it shows the plane's foot point
            // lit at distance 1 (the light sits at the origin).
            header.replace("LookAt 0 0 -1  0 0 1  0 1 0", "LookAt 0 0 -0.4  0 0 -1  0 1 0")
                + "Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\" \"float roughness\" 0\nShape \"trianglemesh\" \"point3 P\" [ -10 -10 -0.5  10 -10 -0.5  10 10 -0.5  -10 10 -0.5 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
        } else {
            header
        }
    };
    let expected = 0.5 / std::f64::consts::PI * 2.0;
    let im = render_scene(&scene("whitted-plane", false), 0);
    check("whitted-plane", &im, expected, 0.01 * expected);
    // Silver reflects about 95% at normal incidence; whitted follows the
    // mirror and agrees with path limited to the same two bounces (mirror,
    // then light at the plane: no diffuse interreflection, which Whitted
    // leaves out).
    let w = mean_rgb(&render_scene(&scene("whitted-mirror", true), 0));
    let p = mean_rgb(&render_scene(
        &scene("whitted-mirror-path", true).replace(
            "\"whitted\" \"integer maxdepth\" 5",
            "\"path\" \"integer maxdepth\" 2",
        ),
        0,
    ));
    assert!(w > 0.9 * expected && w < expected, "mirror: whitted {w}");
    assert!((w - p).abs() < 0.01 * p, "whitted {w} vs path {p}");
}

/// A scene with a bit of everything the path tracer's vertex meets:
/// diffuse (a mesh with vertex normals, one of them turned away, among
/// them), conductor, dielectric and coated surfaces, a checkerboard
/// texture (filtered with ray differentials) and a bump map, sphere,
/// bilinear-patch and triangle emitters (the last sampled lane-parallel
/// under `--wavefront`), spot and uniform infinite lights, a G-buffer
/// film and a crop window.
fn varied_scene(tag: &str, sampler: &str, spp: i32, integrator: &str) -> String {
    format!(
        r#"LookAt 0 1 -5  0 0.5 0  0 1 0
Camera "perspective" "float fov" 50
Sampler "{sampler}" "integer pixelsamples" {spp}
Film "gbuffer" "integer xresolution" 24 "integer yresolution" 20
    "float cropwindow" [ 0.1 0.95 0 0.9 ] "string filename" "{}"
Integrator "{integrator}" "integer maxdepth" 6
WorldBegin
LightSource "infinite" "rgb L" [ 0.2 0.25 0.3 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 3 2 1 ]
  Material "diffuse"
  Shape "trianglemesh" "point3 P" [ 0.8 1.8 -0.8  1.6 1.8 -0.8  1.2 2.2 -0.4 ]
      "integer indices" [ 0 1 2 ]
AttributeEnd
LightSource "spot" "point3 from" [ 2 4 -2 ] "point3 to" [ 0 0 0 ] "rgb I" [ 20 18 15 ]
Texture "checks" "spectrum" "checkerboard" "float uscale" 8 "float vscale" 8
    "rgb tex1" [ 0.8 0.8 0.8 ] "rgb tex2" [ 0.1 0.2 0.1 ]
Texture "bumps" "float" "scale" "float tex" 0.02 "float scale" 1
Texture "scaled-checks" "spectrum" "scale" "texture tex" "checks" "float scale" 0.7
AttributeBegin
  Material "diffuse" "texture reflectance" "checks" "texture displacement" "bumps"
  Shape "trianglemesh" "point3 P" [ -4 0 -4  4 0 -4  4 0 4  -4 0 4 ]
      "point2 uv" [ 0 0 1 0 1 1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.3 0.6 0.5 ]
  Shape "trianglemesh" "point3 P" [ -3 0 2  -1 0 2.5  -2.2 1.4 2.2  -0.6 1.2 2 ]
      "normal N" [ -0.3 0.2 1  0.1 0.3 -1  -0.2 -0.4 -1  0.5 0 -1 ]
      "integer indices" [ 0 1 2  1 3 2 ]
AttributeEnd
AttributeBegin
  Translate -1.2 0.6 0
  Material "dielectric" "float eta" 1.5
  Shape "sphere" "float radius" 0.6
AttributeEnd
AttributeBegin
  # Smooth glass meshes, flat and with vertex normals: the wavefront's
  # lane-parallel specular vertex.
  Material "dielectric" "float eta" 1.5
  Translate 0.5 0.05 -2.4
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Translate -1.3 0 0.3
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "normal N" [ -0.5 -0.3 -0.6  0.6 -0.2 -0.5  0 1 0  0.1 -0.2 0.9 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
AttributeEnd
AttributeBegin
  # Glossy meshes of constant materials, flat and with vertex normals:
  # the wavefront's staged vertex (a smooth conductor's BSDF is specular
  # and falls back to the scalar vertex).
  Translate 1.6 0.05 -1.8
  Material "coatedconductor" "float interface.roughness" 0.1
      "float conductor.roughness" 0.2
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "normal N" [ -0.5 -0.3 -0.6  0.6 -0.2 -0.5  0 1 0  0.1 -0.2 0.9 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Translate -0.9 0 0.5
  Material "coateddiffuse" "rgb reflectance" [ 0.2 0.5 0.7 ] "float roughness" 0.1
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Translate -3.4 0 0.4
  Material "conductor" "float roughness" 0.25
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "normal N" [ -0.5 -0.3 -0.6  0.6 -0.2 -0.5  0 1 0  0.1 -0.2 0.9 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Translate 0 0 1.2
  Material "dielectric" "float eta" 1.4 "float roughness" 0.15
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Translate 4.2 0 0.6
  Material "conductor" "float roughness" 0
  Shape "trianglemesh" "point3 P" [ 0 0 0  0.7 0 0.1  0.3 0.8 0.3  0.35 0.1 0.7 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
AttributeEnd
AttributeBegin
  Translate 0.2 0.5 0.8
  Material "conductor" "float roughness" 0.1
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate 1.4 0.4 -0.3
  Material "coateddiffuse" "rgb reflectance" [ 0.7 0.2 0.1 ] "float roughness" 0.05
  Shape "sphere" "float radius" 0.4
AttributeEnd
AttributeBegin
  Translate -2.2 0.35 1.2
  Material "coatedconductor" "float interface.roughness" 0.15
      "float conductor.roughness" 0.3 "spectrum conductor.eta" "metal-Au-eta"
      "spectrum conductor.k" "metal-Au-k"
  Shape "sphere" "float radius" 0.35
AttributeEnd
AttributeBegin
  Translate 2.3 0.3 1.0
  Material "dielectric" "float eta" 1.33 "float roughness" 0.2
  Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
  Translate 0 2.5 1
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse"
  Shape "bilinearmesh" "point3 P" [ -0.5 0 -0.5  0.5 0 -0.5  -0.5 0 0.5  0.5 0 0.5 ]
      "integer indices" [ 0 1 2 3 ]
AttributeEnd
AttributeBegin
  Translate -0.3 0.15 -1.5
  AreaLightSource "diffuse" "rgb L" [ 2 1 0.5 ]
  Shape "sphere" "float radius" 0.15
AttributeEnd
"#,
        out_path(tag).display()
    )
}

/// `--wavefront` gives the scalar loop's pixels bit for bit on a varied
/// scene, for `path` and `volpath`, with samplers of each kind and sample
/// counts that are not powers of two, on one and on two threads, at
/// every SIMD width.
#[test]
fn wavefront_matches_scalar_bit_for_bit() {
    for (sampler, spp, integrator) in [
        ("zsobol", 8, "path"),
        // An even log2 spp: Z-Sobol's batched four draws.
        ("zsobol", 16, "path"),
        ("independent", 5, "path"),
        ("halton", 6, "path"),
        ("pmj02bn", 3, "path"),
        ("zsobol", 8, "volpath"),
        ("halton", 6, "volpath"),
    ] {
        let tag = format!("wavefront-varied-{sampler}-{integrator}");
        let varied = varied_scene(&tag, sampler, spp, integrator);
        let rgb = varied.replace("Film \"gbuffer\"", "Film \"rgb\"");
        let floor = "\"texture reflectance\" \"checks\" \"texture displacement\" \"bumps\"";
        // Without the G-buffer and the bump map: the textured diffuse
        // vertex, taken in lanes (on the floor, and on the mesh with
        // vertex normals and no uv, under a scaled texture), its texture
        // filtered with the camera ray's differentials and with the
        // camera's approximate ones.
        let textured = rgb
            .replace(floor, "\"texture reflectance\" \"checks\"")
            .replace(
                "\"rgb reflectance\" [ 0.3 0.6 0.5 ]",
                "\"texture reflectance\" \"scaled-checks\"",
            );
        // And without any texture that needs ray differentials: the
        // camera's pinhole rays generated lane-parallel.
        let plain = rgb.replace(floor, "\"rgb reflectance\" [ 0.4 0.5 0.3 ]");
        assert!(!textured.contains("\"texture displacement\""));
        assert!(textured.contains("\"texture reflectance\" \"scaled-checks\""));
        assert!(!plain.contains("gbuffer") && !plain.contains("texture reflectance"));
        for text in [varied, textured, plain] {
            check_wavefront_bits(&text);
        }
    }
}

/// [`wavefront_matches_scalar_bit_for_bit`] for one scene.
fn check_wavefront_bits(text: &str) {
    let (scalar, has) = render_with(text, 2, false);
    assert!(has);
    let (one, _) = render_with(text, 1, true);
    let (two, _) = render_with(text, 2, true);
    assert_same_pixels(&scalar, &one, text);
    assert_same_pixels(&scalar, &two, text);
    // At every SIMD width this processor runs (camera-ray packets of
    // 1, 4, 8 or 16 rays, pinhole rays as many lanes at a time).
    for level in SimdLevel::available() {
        let im = common::render_opts(text, 2, true, Some(level));
        assert_same_pixels(&scalar, &im, &format!("{level:?}\n{text}"));
    }
    // The scene is not black: the comparison compares something.
    assert!(
        mean_rgb(&scalar) > 0.01,
        "mean {}\n{text}",
        mean_rgb(&scalar)
    );
}
