//! pbrt-v1 and pbrt-v2 scenes, written as those editions wrote them
//! (`SurfaceIntegrator`, `Renderer`, `VolumeIntegrator`, `Volume`,
//! `color`/`point` parameters, `WorldEnd`), rendered end to end against
//! closed forms: a closed emitting `matte` sphere seen from inside through
//! each light-transport choice, and an emitter seen through `Volume`
//! regions of each type.
//!
//! The README's pbrt-v1/v2 table lists these cases.

use std::path::PathBuf;

use crate::common::render_scene;
use rpbrt_render::image::Image;

fn out(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rpbrt-v2-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(format!("{tag}.exr"))
}

fn mean(im: &Image) -> f64 {
    let v = im.to_f32_vec();
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

fn assert_close(tag: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got / want - 1.0).abs() <= tol,
        "{tag}: mean {got}, expected {want} (±{:.1}%)",
        100.0 * tol
    );
}

/// A closed `matte` sphere of reflectance 0.5 emitting 0.5 on its inside,
/// seen from its centre, with the options block `opts`.
fn emitting_sphere(tag: &str, opts: &str) -> String {
    format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         {opts}\nWorldBegin\nAttributeBegin\nReverseOrientation\n\
         Material \"matte\" \"color Kd\" [ 0.5 0.5 0.5 ]\n\
         AreaLightSource \"diffuse\" \"color L\" [ 0.5 0.5 0.5 ]\n\
         Shape \"sphere\" \"float radius\" 1\nAttributeEnd\nWorldEnd\n",
        out(tag).display()
    )
}

/// Radiance inside the sphere when light is followed over at most
/// `bounces` reflections: 0.5 · Σ 0.5^k (1 as `bounces` grows).
fn truncated(bounces: i32) -> f64 {
    (0..=bounces).map(|k| 0.5 * 0.5f64.powi(k)).sum()
}

#[test]
fn closed_sphere_through_each_transport() {
    let spp = "Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 64";
    let cases: [(&str, String, f64); 6] = [
        // pbrt-v2's default surface integrator: direct lighting (one
        // bounce), specular chains to depth 5.
        (
            "default",
            format!("{spp}\nVolumeIntegrator \"emission\""),
            truncated(1),
        ),
        (
            "path",
            format!("{spp}\nSurfaceIntegrator \"path\" \"integer maxdepth\" 60"),
            truncated(60),
        ),
        (
            "whitted",
            format!("{spp}\nRenderer \"sampler\"\nSurfaceIntegrator \"whitted\""),
            truncated(1),
        ),
        // Substituted by path at the integrator's depth (default 5).
        (
            "photonmap",
            format!("{spp}\nSurfaceIntegrator \"photonmap\" \"integer causticphotons\" 1000"),
            truncated(5),
        ),
        (
            "igi",
            format!("{spp}\nSurfaceIntegrator \"igi\" \"integer maxdepth\" 60"),
            truncated(60),
        ),
        // mlt with pbrt-v2's default depth, 7.
        (
            "metropolis",
            "Renderer \"metropolis\" \"integer samplesperpixel\" 256 \"integer bootstrapsamples\" 20000"
                .to_string(),
            truncated(7),
        ),
    ];
    for (tag, opts, want) in cases {
        let im = render_scene(&emitting_sphere(tag, &opts), 2);
        assert_close(tag, mean(&im), want, 0.02);
    }
}

/// An emitter of radiance 1 filling the view above a camera looking up
/// (+z) through the world block's `regions`, with the options block
/// `opts`.
fn through_regions(tag: &str, opts: &str, regions: &str) -> String {
    format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 2\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 64\n{opts}\nWorldBegin\n{regions}\n\
         AttributeBegin\nTranslate 0 0 5\nReverseOrientation\n\
         AreaLightSource \"diffuse\" \"color L\" [ 1 1 1 ]\n\
         Shape \"disk\" \"float radius\" 100\nAttributeEnd\nWorldEnd\n",
        out(tag).display()
    )
}

#[test]
fn emitter_through_volume_regions() {
    let slab = "\"point p0\" [ -50 -50 1 ] \"point p1\" [ 50 50 2 ]";
    let e = std::f64::consts::E;
    let cases = [
        // The default volume integrator, emission: absorption and
        // scattering both only attenuate.
        (
            "homogeneous",
            "",
            format!("Volume \"homogeneous\" \"color sigma_a\" [ 0.25 0.25 0.25 ] \"color sigma_s\" [ 0.75 0.75 0.75 ] {slab}"),
            1.0 / e,
        ),
        // Optical depth ∫ a·exp(−b h) dh over the unit height: a(1 − e^−b)/b.
        (
            "exponential",
            "",
            format!("Volume \"exponential\" \"color sigma_a\" [ 1 1 1 ] \"float a\" 1 \"float b\" 2 \"vector updir\" [ 0 0 1 ] {slab}"),
            (-(1.0 - (-2.0f64).exp()) / 2.0).exp(),
        ),
        // Two samples along z, clamped at the ends: density 0 over the
        // first quarter, 0 → 1 over the middle half, 1 over the last
        // quarter: optical depth 0.5 (reading zero past the grid, as
        // pbrt-v4's grids do, would give 0.25 + 1/12).
        (
            "volumegrid",
            "",
            format!("Volume \"volumegrid\" \"color sigma_a\" [ 1 1 1 ] \"integer nz\" 2 \"float density\" [ 0 1 ] {slab}"),
            (-0.5f64).exp(),
        ),
        // Overlapping regions add up: 0.5 over z ∈ [1, 2] and 0.5 over
        // [1.5, 2.5], each one unit thick.
        (
            "aggregate",
            "VolumeIntegrator \"emission\"",
            "Volume \"homogeneous\" \"color sigma_a\" [ 0.5 0.5 0.5 ] \"point p0\" [ -50 -50 1 ] \"point p1\" [ 50 50 2 ]\n\
             Volume \"homogeneous\" \"color sigma_a\" [ 0.5 0.5 0.5 ] \"point p0\" [ -50 -50 1.5 ] \"point p1\" [ 50 50 2.5 ]"
                .to_string(),
            1.0 / e,
        ),
        // A region's transformation moves its box: this one is pushed
        // out of the view, so nothing attenuates.
        (
            "transformed",
            "",
            format!("AttributeBegin\nTranslate 200 0 0\nVolume \"homogeneous\" \"color sigma_a\" [ 5 5 5 ] {slab}\nAttributeEnd"),
            1.0,
        ),
    ];
    for (tag, opts, regions, want) in cases {
        let im = render_scene(&through_regions(tag, opts, &regions), 2);
        assert_close(tag, mean(&im), want, 0.015);
    }
}

#[test]
fn emitting_region_adds_its_emission_per_unit_length() {
    // No emitter behind: a unit-thick region absorbing σa = 2 and emitting
    // Lve = 1 per unit length gives ∫₀¹ e^−2t dt = (1 − e^−2)/2 (taking
    // `Le` as pbrt-v4's, emission σa·Le, would give twice that).
    let text = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 2\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 64\nWorldBegin\n\
         Volume \"homogeneous\" \"color sigma_a\" [ 2 2 2 ] \"color Le\" [ 1 1 1 ] \"point p0\" [ -50 -50 1 ] \"point p1\" [ 50 50 2 ]\n\
         WorldEnd\n",
        out("emitting").display()
    );
    let im = render_scene(&text, 2);
    assert_close("emitting", mean(&im), (1.0 - (-2.0f64).exp()) / 2.0, 0.015);
}

#[test]
fn shinymetal_mirror_reflects_its_kr_at_normal_incidence() {
    // A camera facing a shinymetal plane head-on, an emitter of radiance
    // 1 behind the camera. Kr = 0.5 makes the mirror's Fresnel term 0.5
    // at normal incidence; Ks = 0 makes the glossy lobe's zero there (its
    // sharp Blinn lobe sees only near-normal half vectors). pbrt-v2's
    // default surface integrator (direct lighting with specular
    // reflection) then sees 0.5.
    let text = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 5\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 16\nWorldBegin\n\
         AttributeBegin\nTranslate 0 0 5\n\
         Material \"shinymetal\" \"color Kr\" [ 0.5 0.5 0.5 ] \"color Ks\" [ 0 0 0 ] \"float roughness\" 0.001\n\
         Shape \"disk\" \"float radius\" 100\nAttributeEnd\n\
         AttributeBegin\nTranslate 0 0 -1\n\
         AreaLightSource \"diffuse\" \"color L\" [ 1 1 1 ]\n\
         Shape \"disk\" \"float radius\" 100\nAttributeEnd\nWorldEnd\n",
        out("shinymetal").display()
    );
    let im = render_scene(&text, 2);
    assert_close("shinymetal", mean(&im), 0.5, 0.02);
}

/// The mean of the left and right halves of a 16-pixel-wide image.
fn halves(im: &Image) -> (f64, f64) {
    let v = im.to_f32_vec();
    let ch = v.len() / (16 * 16);
    let (mut l, mut r) = (0.0, 0.0);
    for (i, px) in v.chunks(ch).enumerate() {
        let s: f64 = px.iter().map(|&x| x as f64).sum();
        if i % 16 < 8 {
            l += s;
        } else {
            r += s;
        }
    }
    (l, r)
}

#[test]
fn pbrt_v1_files_render_mirrored_with_their_materials() {
    // An emitter at world +x: pbrt-v2 (and v3, v4) show it on the right,
    // pbrt-v1's LookAt on the left. `SearchPath` and the measured `clay`
    // each mark a pbrt-v1 file.
    let scene = |tag: &str, first: &str, material: &str| {
        format!(
            "{first}\nLookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 60\n\
             Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
             Sampler \"bestcandidate\" \"integer pixelsamples\" 4\nWorldBegin\n\
             AttributeBegin\nTranslate 2 0 5\nReverseOrientation\n\
             AreaLightSource \"diffuse\" \"color L\" [ 1 1 1 ]\nShape \"disk\" \"float radius\" 1\nAttributeEnd\n\
             AttributeBegin\nTranslate -2 0 5\nMaterial \"{material}\"\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n\
             WorldEnd\n",
            out(tag).display()
        )
    };
    let (l1, r1) = halves(&render_scene(
        &scene("v1-path", "SearchPath \"&\"", "matte"),
        1,
    ));
    let (l2, r2) = halves(&render_scene(&scene("v1-clay", "", "clay"), 1));
    let (l3, r3) = halves(&render_scene(
        &scene("v2", "Renderer \"sampler\"", "matte"),
        1,
    ));
    assert!(l1 > 4.0 * r1 && l2 > 4.0 * r2, "v1 {l1} {r1}, {l2} {r2}");
    assert!(r3 > 4.0 * l3, "v2 {l3} {r3}");
}

#[test]
fn merl_table_of_a_lambertian_reflects_its_albedo() {
    // A MERL table whose every entry is ρ/π once pbrt-v2's per-channel
    // scales (1, 1.15, 1.66)/1500 are applied: a Lambertian of albedo ρ =
    // 0.5. A sphere of it under a uniform environment of radiance 1
    // reflects 0.5 everywhere.
    let path = out("lambertian").with_extension("binary");
    let mut b = Vec::with_capacity(12 + 24 * 90 * 90 * 180);
    for d in [90i32, 90, 180] {
        b.extend_from_slice(&d.to_le_bytes());
    }
    for scale in [1.0, 1.15, 1.66] {
        let v: f64 = 0.5 / std::f64::consts::PI * 1500.0 / scale;
        for _ in 0..90 * 90 * 180 {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(&path, b).unwrap();
    let text = format!(
        "LookAt 0 0 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 16\nSurfaceIntegrator \"path\"\nWorldBegin\n\
         LightSource \"infinite\" \"color L\" [ 1 1 1 ]\n\
         Material \"measured\" \"string filename\" \"{}\"\nShape \"sphere\"\nWorldEnd\n",
        out("merl").display(),
        path.display()
    );
    let im = render_scene(&text, 2);
    assert_close("merl", mean(&im), 0.5, 0.01);
}

#[test]
fn irregular_measurements_of_a_lambertian_reflect_its_albedo() {
    // pbrt-v2's irregular .brdf format: measurements of ρ/π (ρ = 0.5) at
    // two wavelengths over a grid of angles, every lookup averages them
    // to ρ/π: a sphere of it in a white furnace reflects 0.5.
    let path = out("lambertian").with_extension("brdf");
    let v = 0.5 / std::f64::consts::PI;
    let mut text = String::from("2 400 700\n");
    for i in 0..8 {
        for o in 0..8 {
            for p in 0..8 {
                let (ti, to) = (0.1 + 0.2 * i as f64, 0.1 + 0.2 * o as f64);
                text += &format!("{ti} {} {to} 0 {v} {v}\n", p as f64 * 0.45);
            }
        }
    }
    std::fs::write(&path, text).unwrap();
    let scene = format!(
        "LookAt 0 0 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
         Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 16\nSurfaceIntegrator \"path\"\nWorldBegin\n\
         LightSource \"infinite\" \"color L\" [ 1 1 1 ]\n\
         Material \"measured\" \"string filename\" \"{}\"\nShape \"sphere\"\nWorldEnd\n",
        out("irregular").display(),
        path.display()
    );
    let im = render_scene(&scene, 2);
    assert_close("irregular", mean(&im), 0.5, 0.01);
}
