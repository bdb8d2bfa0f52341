//! End-to-end tests of the `rpbrt` binary: exit codes and located messages.

use std::path::PathBuf;
use std::process::Command;

/// `rpbrt imgtool`'s commands, each against hand-computed results.
mod imgtool;

fn rpbrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rpbrt"))
}

fn temp_scene(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn help_lists_flags() {
    let out = rpbrt().arg("--help").output().unwrap();
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    for flag in [
        "--outfile",
        "--spp",
        "--nthreads",
        "--format",
        "--upgrade",
        "--toply",
        "--preview",
        "--display-server",
        "imgtool",
    ] {
        assert!(s.contains(flag), "{flag} missing from --help");
    }
}

#[test]
fn errors_are_located_with_a_caret_and_exit_1() {
    let p = temp_scene(
        "bad.pbrt",
        "WorldBegin\nShape \"sphere\" \"float radius\" \"big\"\n",
    );
    let out = rpbrt().arg("--format").arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("bad.pbrt:2:31: error:"), "{e}");
    assert!(e.contains('^'), "{e}");
}

#[test]
fn unknown_shape_type_lists_known_ones() {
    let p = temp_scene("unknown.pbrt", "WorldBegin\nShape \"sphear\"\n");
    let out = rpbrt().arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("unknown.pbrt:2:") && e.contains("sphere"), "{e}");
}

#[test]
fn degenerate_shape_is_a_located_error() {
    let p = temp_scene(
        "degenerate.pbrt",
        "WorldBegin\nAttributeBegin\nShape \"sphere\" \"float radius\" -2\nAttributeEnd\n",
    );
    let out = rpbrt().arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("degenerate.pbrt:3:") && e.contains("error"),
        "{e}"
    );
}

#[test]
fn bad_flags_are_errors() {
    let out = rpbrt().args(["--spp", "-3", "x.pbrt"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let out = rpbrt().arg("--frobnicate").output().unwrap();
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn format_round_trip_is_stable() {
    let scene = "LookAt 0 0 -5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\nAttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\nShape \"sphere\"\nAttributeEnd\n";
    let p = temp_scene("rt.pbrt", scene);
    let once = rpbrt().arg("--format").arg(&p).output().unwrap();
    assert!(once.status.success());
    let p2 = temp_scene("rt2.pbrt", &String::from_utf8_lossy(&once.stdout));
    let twice = rpbrt().arg("--format").arg(&p2).output().unwrap();
    assert_eq!(once.stdout, twice.stdout);
}

#[test]
fn upgrade_maps_v3_materials() {
    let p = temp_scene(
        "v3.pbrt",
        "WorldBegin\nMaterial \"matte\" \"color Kd\" [0.5 0.5 0.5]\nShape \"sphere\"\nWorldEnd\n",
    );
    let out = rpbrt().arg("--upgrade").arg(&p).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(
        s.contains("Material \"diffuse\"") && s.contains("\"rgb reflectance\""),
        "{s}"
    );
}

#[test]
fn imgtool_reports_bad_files() {
    let out = rpbrt()
        .args(["imgtool", "info", "/nonexistent.exr"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let out = rpbrt().args(["imgtool", "frob"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn renders_png_and_reports_mse_against_a_reference() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 45\nSampler \"zsobol\" \"integer pixelsamples\" 4\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\nAttributeBegin\nReverseOrientation\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 0.5 0.5 0.5 ]\nShape \"sphere\"\nAttributeEnd\n";
    let p = dir.join("furnace.pbrt");
    std::fs::write(&p, scene).unwrap();
    let exr = dir.join("ref.exr");
    let out = rpbrt()
        .arg("--quiet")
        .arg("--outfile")
        .arg(&exr)
        .arg(&p)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = dir.join("img.png");
    let mse = dir.join("mse.txt");
    let out = rpbrt()
        .args(["--quiet", "--spp", "4", "--outfile"])
        .arg(&png)
        .arg("--mse-reference-image")
        .arg(&exr)
        .arg("--mse-reference-out")
        .arg(&mse)
        .arg(&p)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
    let text = std::fs::read_to_string(&mse).unwrap();
    let last = text.lines().last().unwrap();
    let (spp, err) = last.split_once(' ').unwrap();
    assert_eq!(spp, "4");
    // The same deterministic render: its MSE against itself is tiny (the
    // reference is stored as half floats).
    assert!(err.parse::<f64>().unwrap() < 1e-4, "{text}");
    // A bad output extension is an error before rendering.
    let out = rpbrt()
        .arg("--outfile")
        .arg(dir.join("x.bmp"))
        .arg(&p)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn integrators_that_ignore_media_or_subsurface_warn_at_the_directive() {
    let cases = [
        ("ss.pbrt", "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nIntegrator \"path\"\nWorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\nMaterial \"subsurface\"\nShape \"sphere\"\n", "ss.pbrt:2:1", "subsurface"),
        ("medium.pbrt", "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nIntegrator \"path\"\nWorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nShape \"sphere\"\n", "medium.pbrt:2:1", "media"),
        ("sppm-medium.pbrt", "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nIntegrator \"sppm\"\nWorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nShape \"sphere\"\n", "sppm-medium.pbrt:2:1", "media"),
    ];
    for (name, text, loc, what) in cases {
        let p = temp_scene(name, text);
        let out = rpbrt()
            .args(["--spp", "1", "--outfile"])
            .arg(p.with_extension("exr"))
            .arg(&p)
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{name}: {e}");
        assert!(
            e.contains(loc) && e.contains(what) && e.contains("volpath"),
            "{name}: {e}"
        );
    }
}

#[test]
fn unsupported_features_are_located_errors_not_wrong_images() {
    let cases = [(
        "halton.pbrt",
        "Sampler \"halton\" \"string randomization\" \"fastowen\"
WorldBegin
Shape \"sphere\"
",
        "halton.pbrt:1:",
    )];
    for (name, text, loc) in cases {
        let p = temp_scene(name, text);
        let out = rpbrt().arg("--quiet").arg(&p).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{name}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(
            e.contains(loc) && e.contains("not supported"),
            "{name}: {e}"
        );
    }
}

#[test]
fn bidirectional_integrators_need_the_perspective_camera() {
    for integrator in ["bdpt", "lightpath", "mlt"] {
        let name = format!("{integrator}-ortho.pbrt");
        let text = format!(
            "Camera \"orthographic\"\nIntegrator \"{integrator}\"\nWorldBegin\nShape \"sphere\"\n"
        );
        let p = temp_scene(&name, &text);
        let out = rpbrt().arg("--quiet").arg(&p).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{name}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(
            e.contains(&format!("{name}:2:1")) && e.contains("Only the \"perspective\" camera"),
            "{name}: {e}"
        );
    }
}

/// bdpt's `visualizestrategies` writes one image per (s, t) strategy into
/// the working directory, named as pbrt-v4 names them.
#[test]
fn bdpt_writes_its_strategy_images() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-strategies-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 45\nSampler \"independent\" \"integer pixelsamples\" 4\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"main.exr\"\nIntegrator \"bdpt\" \"integer maxdepth\" 2 \"bool visualizestrategies\" true\nWorldBegin\nAttributeBegin\nReverseOrientation\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 0.5 0.5 0.5 ]\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n";
    std::fs::write(dir.join("s.pbrt"), text).unwrap();
    let out = rpbrt()
        .current_dir(&dir)
        .args(["--quiet", "s.pbrt"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Depth 0: (0,2); depth 1: (0,3), (1,2), (2,1); depth 2: s from 0 to 3.
    for name in [
        "bdpt_d00_s00_t02.exr",
        "bdpt_d01_s00_t03.exr",
        "bdpt_d01_s01_t02.exr",
        "bdpt_d01_s02_t01.exr",
        "bdpt_d02_s03_t01.exr",
    ] {
        assert!(dir.join(name).exists(), "{name} missing");
    }
    assert!(!dir.join("bdpt_d00_s01_t01.exr").exists());
    // The direct view of the emitter (0,2) carries its radiance 0.5 (a
    // little less on average: samples near the border land outside).
    let info = rpbrt()
        .args(["imgtool", "info"])
        .arg(dir.join("bdpt_d00_s00_t02.exr"))
        .output()
        .unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    let avgs: Vec<f64> = info
        .split("avg ")
        .skip(1)
        .filter_map(|t| t.split_whitespace().next()?.parse().ok())
        .collect();
    assert!(
        avgs.len() == 3 && avgs.iter().all(|a| (0.4..0.52).contains(a)),
        "{info}"
    );
}

/// `imgtool average` (pbrt-v4's): the images whose names start with a
/// base, averaged; a missing base or --outfile and no match are errors.
#[test]
fn imgtool_average_matches_a_filename_base() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-average-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Two renders of a tiny scene at different seeds.
    let scene = dir.join("s.pbrt");
    std::fs::write(&scene, "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\nShape \"sphere\"\n").unwrap();
    for seed in ["1", "2"] {
        let out = rpbrt()
            .args(["--quiet", "--spp", "2", "--seed", seed, "--outfile"])
            .arg(dir.join(format!("r-{seed}.exr")))
            .arg(&scene)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
    }
    let avg = dir.join("avg.exr");
    let out = rpbrt()
        .args(["imgtool", "average", "--outfile"])
        .arg(&avg)
        .arg(dir.join("r-"))
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(avg.exists());
    let out = rpbrt()
        .args(["imgtool", "average", "--outfile"])
        .arg(&avg)
        .arg(dir.join("nothing-"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no matching filenames"));
    let out = rpbrt()
        .args(["imgtool", "average"])
        .arg(dir.join("r-"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--outfile"));
}

/// A small lit scene for partial-render tests.
const PARTIAL_SCENE: &str = r#"
LookAt 0 1 -4  0 0.5 0  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" 37 "integer yresolution" 23 "string filename" "full.exr"
Sampler "zsobol" "integer pixelsamples" 8
Integrator "INTEGRATOR" "integer maxdepth" 4
WorldBegin
LightSource "infinite" "rgb L" [0.2 0.3 0.4]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [8 7 6]
  Translate 0 2.5 0
  Shape "sphere" "float radius" 0.4
AttributeEnd
Material "diffuse" "rgb reflectance" [0.6 0.5 0.4]
Shape "sphere" "float radius" 0.7
Shape "bilinearmesh" "point3 P" [-3 -0.7 -3  3 -0.7 -3  -3 -0.7 3  3 -0.7 3]
"#;

fn run_ok(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{cmd:?} failed: {err}");
    err + &String::from_utf8_lossy(&out.stdout)
}

/// `imgtool diff`'s count of differing pixels.
fn differing_pixels(a: &std::path::Path, b: &std::path::Path) -> String {
    let s = run_ok(rpbrt().args(["imgtool", "diff"]).arg(a).arg(b));
    s.lines()
        .find_map(|l| l.strip_prefix("differing pixels: "))
        .unwrap_or("?")
        .to_string()
}

#[test]
fn tiles_and_sample_ranges_join_into_the_full_render() {
    for integrator in ["path", "bdpt"] {
        let dir =
            std::env::temp_dir().join(format!("rpbrt-partial-{integrator}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("scene.pbrt");
        std::fs::write(&scene, PARTIAL_SCENE.replace("INTEGRATOR", integrator)).unwrap();
        let full = dir.join("full.exr");
        run_ok(
            rpbrt()
                .arg("--quiet")
                .arg("--outfile")
                .arg(&full)
                .arg(&scene),
        );

        // Three sample ranges, given out of order, with two threads each.
        let mut ranges = Vec::new();
        for r in ["3..8", "0..1", "1..3"] {
            let f = dir.join(format!("range-{r}.exr"));
            run_ok(
                rpbrt()
                    .args(["--quiet", "--nthreads", "2", "--spp-range", r, "--outfile"])
                    .arg(&f)
                    .arg(&scene),
            );
            ranges.push(f);
        }
        let merged = dir.join("merged.exr");
        run_ok(
            rpbrt()
                .args(["imgtool", "merge", "--outfile"])
                .arg(&merged)
                .args(&ranges),
        );
        assert_eq!(differing_pixels(&merged, &full), "0", "{integrator} ranges");

        if integrator == "path" {
            let mut tiles = Vec::new();
            for k in 0..7 {
                let f = dir.join(format!("tile-{k}.exr"));
                run_ok(
                    rpbrt()
                        .args(["--quiet", "--tile", &format!("{k}/7"), "--outfile"])
                        .arg(&f)
                        .arg(&scene),
                );
                tiles.push(f);
            }
            let joined = dir.join("joined.exr");
            run_ok(
                rpbrt()
                    .args(["imgtool", "assemble", "--outfile"])
                    .arg(&joined)
                    .args(&tiles),
            );
            assert_eq!(differing_pixels(&joined, &full), "0", "tiles");

            // The same parts from one --serve-parts process.
            use std::io::Write;
            let mut server = rpbrt()
                .args(["--quiet", "--serve-parts"])
                .arg(&scene)
                .stdin(std::process::Stdio::piped())
                .stdout(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            let served_tile = dir.join("served tile.exr");
            let served_range = dir.join("served-range.exr");
            let mut stdin = server.stdin.take().unwrap();
            writeln!(stdin, "--tile 4/7 --outfile {}", served_tile.display()).unwrap();
            writeln!(stdin, "--tile 9/7 --outfile x.exr").unwrap();
            writeln!(
                stdin,
                "--spp-range 3..8 --outfile {}",
                served_range.display()
            )
            .unwrap();
            drop(stdin);
            let out = server.wait_with_output().unwrap();
            assert!(out.status.success());
            let replies = String::from_utf8_lossy(&out.stdout);
            let lines: Vec<&str> = replies.lines().collect();
            assert_eq!(lines.len(), 3, "{replies}");
            assert_eq!(lines[0], "ok");
            assert!(lines[1].starts_with("error: --tile \"9/7\""), "{replies}");
            assert_eq!(lines[2], "ok");
            assert_eq!(
                differing_pixels(&served_tile, &tiles[4]),
                "0",
                "served tile"
            );
            assert_eq!(
                differing_pixels(&served_range, &ranges[0]),
                "0",
                "served range"
            );

            // A missing tile, a doubled tile: clear errors.
            let out = rpbrt()
                .args(["imgtool", "assemble", "--outfile"])
                .arg(dir.join("x.exr"))
                .args(&tiles[1..])
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(1));
            let e = String::from_utf8_lossy(&out.stderr);
            assert!(
                e.contains("uncovered") && e.contains("a tile is missing"),
                "{e}"
            );
            let out = rpbrt()
                .args(["imgtool", "assemble", "--outfile"])
                .arg(dir.join("x.exr"))
                .args(&tiles)
                .arg(&tiles[2])
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(1));
            assert!(String::from_utf8_lossy(&out.stderr).contains("overlap"));
            // Overlapping sample ranges.
            let out = rpbrt()
                .args(["imgtool", "merge", "--outfile"])
                .arg(dir.join("x.exr"))
                .args([&ranges[0], &ranges[0]])
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(1));
            assert!(String::from_utf8_lossy(&out.stderr).contains("overlap"));
            // A range past the sampler's samples, a tile that does not exist.
            let out = rpbrt()
                .args(["--spp-range", "4..9"])
                .arg(&scene)
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(1));
            assert!(String::from_utf8_lossy(&out.stderr).contains("at most 8"));
            let out = rpbrt()
                .args(["--tile", "0/5000"])
                .arg(&scene)
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(1));
            assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be split"));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn sample_ranges_are_refused_where_they_cannot_merge() {
    let scene = temp_scene(
        "sppm-range.pbrt",
        &PARTIAL_SCENE
            .replace("INTEGRATOR", "sppm")
            .replace("\"integer maxdepth\" 4", "\"integer iterations\" 2"),
    );
    let out = rpbrt()
        .args(["--spp-range", "0..1"])
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("\"sppm\" integrator does not take samples pixel by pixel"),
        "{e}"
    );
}

/// `imgtool makeequiarea` (pbrt-v4's): a latitude–longitude map to an
/// equal-area square, default resolution the input's width, `--resolution`
/// and a positional or `--outfile` output.
#[test]
fn imgtool_makeequiarea_converts_lat_long_maps() {
    use rpbrt_render::image::{Image, ImageMetadata};
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-equiarea-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("ll.pfm");
    let w = 16;
    let data: Vec<f32> = (0..w * w / 2 * 3).map(|i| 1.0 + (i % 7) as f32).collect();
    Image::from_f32(
        data,
        rpbrt_render::geometry::Point2i::new(w, w / 2),
        &["R", "G", "B"],
    )
    .unwrap()
    .write(&input, &ImageMetadata::default())
    .unwrap();
    let out1 = dir.join("ea1.pfm");
    let out = rpbrt()
        .args(["imgtool", "makeequiarea"])
        .arg(&input)
        .arg(&out1)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let im = Image::read(&out1, None).unwrap().image;
    assert_eq!(im.resolution(), rpbrt_render::geometry::Point2i::new(w, w));
    let out2 = dir.join("ea2.pfm");
    let out = rpbrt()
        .args(["imgtool", "makeequiarea", "--resolution", "9", "--outfile"])
        .arg(&out2)
        .arg(&input)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let im = Image::read(&out2, None).unwrap().image;
    assert_eq!(im.resolution(), rpbrt_render::geometry::Point2i::new(9, 9));
    // Bad input: no output file, a bad resolution, a missing file.
    let out = rpbrt()
        .args(["imgtool", "makeequiarea"])
        .arg(&input)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("output image filename"));
    let out = rpbrt()
        .args(["imgtool", "makeequiarea", "--resolution", "0"])
        .arg(&input)
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let out = rpbrt()
        .args(["imgtool", "makeequiarea", "/nonexistent/ll.exr", "x.exr"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/ll.exr"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `imgtool makesky` (pbrt-v4's): an equal-area Hosek–Wilkie sky with the
/// parameters in the metadata; out-of-range parameters are refused.
#[test]
fn imgtool_makesky_writes_an_equal_area_sky() {
    use rpbrt_render::image::Image;
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-makesky-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("sky.exr");
    let run = rpbrt()
        .args([
            "imgtool",
            "makesky",
            "--resolution",
            "16",
            "--elevation",
            "30",
        ])
        .args(["--turbidity", "4", "--albedo", "0.2", "--outfile"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let im = Image::read(&out, None).unwrap();
    assert_eq!(
        im.image.resolution(),
        rpbrt_render::geometry::Point2i::new(16, 16)
    );
    assert_eq!(im.metadata.color_space.as_deref(), Some("aces2065-1"));
    for (flag, value) in [
        ("--albedo", "1.5"),
        ("--turbidity", "1"),
        ("--elevation", "-5"),
        ("--resolution", "0"),
        ("--albedo", "x"),
    ] {
        let run = rpbrt()
            .args(["imgtool", "makesky", flag, value, "--outfile"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1), "{flag} {value}");
        assert!(
            String::from_utf8_lossy(&run.stderr).contains(flag),
            "{flag} {value}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    let run = rpbrt().args(["imgtool", "makesky"]).output().unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("--outfile"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A tiny emitter scene, 4×4 pixels at 1 sample, for tests about the
/// command rather than the image.
const TINY_SCENE: &str = "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 45\nSampler \"independent\" \"integer pixelsamples\" 1\nFilm \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 0.5 0.5 0.5 ]\nShape \"sphere\" \"float bogus\" 1\n";

fn dev_full() -> std::fs::File {
    std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap()
}

#[test]
fn failed_stderr_write_does_not_abort_the_render() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-devfull-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("tiny.pbrt");
    std::fs::write(&p, TINY_SCENE).unwrap();
    let exr = dir.join("tiny.exr");
    let _ = std::fs::remove_file(&exr);
    // The unused "bogus" parameter warns and --stats prints: both go to a
    // stderr that cannot be written.
    let status = rpbrt()
        .arg("--stats")
        .arg("--outfile")
        .arg(&exr)
        .arg(&p)
        .stderr(dev_full())
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(std::fs::metadata(&exr).unwrap().len() > 0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failed_stdout_write_is_an_error_exit_not_a_panic() {
    for args in [
        &["--help"][..],
        &["--version"][..],
        &["imgtool", "help"][..],
    ] {
        let out = rpbrt()
            .args(args)
            .stdout(dev_full())
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(
            e.contains("standard output") && !e.contains("panicked"),
            "{e}"
        );
    }
}

#[test]
fn missing_output_directory_fails_before_rendering() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-outdir-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // 64×64 pixels at a million samples each would render for hours.
    let heavy = TINY_SCENE
        .replace("pixelsamples\" 1", "pixelsamples\" 1000000")
        .replace("resolution\" 4", "resolution\" 64");
    assert!(heavy.contains("yresolution\" 64"));
    let p = dir.join("heavy.pbrt");
    std::fs::write(&p, &heavy).unwrap();
    let missing = dir.join("missing-dir");
    let t = std::time::Instant::now();
    let out = rpbrt()
        .arg("--outfile")
        .arg(missing.join("x.exr"))
        .arg(&p)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains(&*missing.to_string_lossy()), "{e}");
    // The scene's own file name is checked the same way.
    let in_scene = heavy.replace(
        "Film \"rgb\"",
        "Film \"rgb\" \"string filename\" \"no-such-dir/y.exr\"",
    );
    let p = dir.join("heavy-named.pbrt");
    std::fs::write(&p, in_scene).unwrap();
    let out = rpbrt().arg(&p).current_dir(&dir).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("no-such-dir"), "{e}");
    assert!(t.elapsed() < std::time::Duration::from_secs(10));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_control_characters_are_escaped_in_messages() {
    let p = temp_scene("osc.pbrt", "WorldBegin\nShape \"\x1b]0;pwned\x07\"\n");
    let out = rpbrt().arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!e.contains('\x1b') && !e.contains('\x07'), "{e:?}");
    assert!(e.contains("\\u{1b}]0;pwned\\u{7}"), "{e}");
}

#[test]
fn missing_scene_file_reports_only_that() {
    let out = rpbrt()
        .arg("/nonexistent-dir/missing-scene.pbrt")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("missing-scene.pbrt"), "{e}");
    assert!(!e.contains("WorldBegin"), "{e}");
    assert_eq!(e.lines().filter(|l| l.contains("error")).count(), 1, "{e}");
}

#[test]
fn degenerate_look_at_names_the_directive_once() {
    let p = temp_scene("lookat.pbrt", "LookAt 0 0 0  0 0 0  0 1 0\nWorldBegin\n");
    let out = rpbrt().arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("lookat.pbrt:1:1: error: LookAt: \"up\""), "{e}");
    assert!(!e.contains("LookAt: LookAt"), "{e}");
}

#[test]
fn named_medium_type_is_not_an_unused_parameter() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-medium-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = TINY_SCENE
        .replace(" \"float bogus\" 1", "")
        .replace(
            "WorldBegin\n",
            "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"float scale\" 0.1\nMediumInterface \"\" \"fog\"\nWorldBegin\n",
        );
    let p = dir.join("fog.pbrt");
    std::fs::write(&p, scene).unwrap();
    let out = rpbrt()
        .arg("--outfile")
        .arg(dir.join("fog.exr"))
        .arg(&p)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{e}");
    assert!(!e.contains("unused"), "{e}");
    // A parameter the medium does not take is still reported.
    let p2 = dir.join("fog2.pbrt");
    std::fs::write(
        &p2,
        std::fs::read_to_string(&p)
            .unwrap()
            .replace("\"float scale\" 0.1", "\"float scael\" 0.1"),
    )
    .unwrap();
    let out = rpbrt()
        .arg("--outfile")
        .arg(dir.join("fog2.exr"))
        .arg(&p2)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("scael") && !e.contains("\"type\""), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Ctrl-C is honoured within a second even when each pixel has billions
/// of samples (it was checked once per pixel, and the second wave takes
/// all of a pixel's remaining samples: SIGINT went unanswered for
/// minutes), in both designs, and the image so far is written.
#[test]
fn ctrl_c_is_honoured_between_samples_of_one_pixel() {
    for design in ["--no-wavefront", "--wavefront"] {
        let out = std::env::temp_dir().join(format!(
            "rpbrt-cli-{}-ctrlc{}.exr",
            std::process::id(),
            design
        ));
        let scene = temp_scene(
            "ctrlc.pbrt",
            "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\nSampler \"independent\" \"integer pixelsamples\" 2147483647\nFilm \"rgb\" \"integer xresolution\" 2 \"integer yresolution\" 2\nWorldBegin\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\nMaterial \"diffuse\"\nShape \"sphere\" \"float radius\" 1\n",
        );
        let mut cmd = rpbrt();
        cmd.args(["--quiet", "--nthreads", "2", "--outfile"])
            .arg(&out);
        cmd.arg(design);
        let mut child = cmd.arg(&scene).spawn().unwrap();
        // Into the second wave: each pixel's remaining 2^31 - 2 samples.
        std::thread::sleep(std::time::Duration::from_millis(1500));
        let sent = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let t0 = std::time::Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if t0.elapsed() > std::time::Duration::from_secs(10) {
                let _ = child.kill();
                panic!("{design:?}: still rendering 10 s after SIGINT");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert!(
            t0.elapsed() < std::time::Duration::from_secs(2),
            "{design:?}: took {:?} to stop",
            t0.elapsed()
        );
        assert_eq!(status.code(), Some(130), "{design:?}");
        assert!(out.exists(), "{design:?}: no image written");
    }
}

// ---- issue 34, finding 6: one memory budget, --max-memory ----------------

/// Runs `rpbrt` with `args`, expecting exit 1 and one located error: its
/// stderr.
fn one_located_error(args: &[&str], scene: &std::path::Path) -> String {
    let t = std::time::Instant::now();
    let out = rpbrt().args(args).arg(scene).output().unwrap();
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(e.matches("error:").count(), 1, "{e}");
    // Refused from the claims, not after allocating them.
    assert!(t.elapsed() < std::time::Duration::from_secs(20), "{e}");
    e
}

#[test]
fn oom_film_16384_squared_is_a_located_error() {
    let p = temp_scene(
        "oom-film.pbrt",
        "Film \"rgb\" \"integer xresolution\" [ 16384 ] \"integer yresolution\" [ 16384 ]\n\
         WorldBegin\nShape \"sphere\"\n",
    );
    let e = one_located_error(&["--max-memory", "6G"], &p);
    assert!(
        e.contains("oom-film.pbrt:1:1: error: this film needs 20.0 GiB; --max-memory is 6.0 GiB"),
        "{e}"
    );
    // The default budget comes from the machine's memory: a spectral film
    // of 2^28 pixels and 1024 buckets (8 TiB) is past it on any machine.
    let p = temp_scene(
        "oom-film-default.pbrt",
        "Film \"spectral\" \"integer xresolution\" [ 16384 ] \"integer yresolution\" [ 16384 ]\n\
         \"integer nbuckets\" 1024 \"string filename\" \"x.exr\"\nWorldBegin\nShape \"sphere\"\n",
    );
    let e = one_located_error(&[], &p);
    assert!(
        e.contains("oom-film-default.pbrt:1:1: error: this film needs 8.0 TiB; --max-memory is"),
        "{e}"
    );
}

#[test]
fn oom_sphere_directives_end_in_one_located_error() {
    let mut text = String::from(
        "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n",
    );
    text.push_str(&"Shape \"sphere\"\n".repeat(200_000));
    let p = temp_scene("oom-spheres.pbrt", &text);
    let e = one_located_error(&["--max-memory", "32M"], &p);
    assert!(
        e.contains("oom-spheres.pbrt:")
            && e.contains(":1: error: this Shape needs ")
            && e.contains("--max-memory is 32.0 MiB"),
        "{e}"
    );
}

#[test]
fn oom_png_imagemap_is_a_located_error() {
    use rpbrt_render::image::{ColorEncoding, Image, ImageMetadata, PixelFormat};
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-oom-png-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let im = Image::new(
        PixelFormat::U256,
        rpbrt_render::geometry::Point2i::new(2000, 2000),
        &["R", "G", "B"],
        ColorEncoding::SRGB,
    );
    im.write(dir.join("big.png"), &ImageMetadata::default())
        .unwrap();
    let p = dir.join("tex.pbrt");
    std::fs::write(
        &p,
        "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n\
         Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"big.png\"\n\
         Material \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"\n",
    )
    .unwrap();
    let e = one_located_error(&["--max-memory", "16M"], &p);
    assert!(
        e.contains("tex.pbrt:3:35: error: imagemap texture \"t\": unable to read image")
            && e.contains("this image needs 22.9 MiB; --max-memory is 16.0 MiB"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn oom_loopsubdiv_is_a_located_error_before_it_refines() {
    let p = temp_scene(
        "oom-loop.pbrt",
        "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n\
         Shape \"loopsubdiv\" \"integer levels\" 30 \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ]\n\
         \"integer indices\" [ 0 1 2 2 1 3 ]\n",
    );
    let e = one_located_error(&["--max-memory", "64M"], &p);
    assert!(
        e.contains(
            "oom-loop.pbrt:3:1: error: this subdivision (2097152 triangles after 10 levels) \
             needs 192.0 MiB; --max-memory is 64.0 MiB"
        ),
        "{e}"
    );
}

#[test]
fn oom_imgtool_outputs_are_refused_before_they_are_made() {
    let dir = std::env::temp_dir().join(format!("rpbrt-cli-oom-imgtool-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let small = dir.join("small.exr");
    let p = dir.join("tiny.pbrt");
    std::fs::write(&p, TINY_SCENE).unwrap();
    let run = rpbrt()
        .args(["--quiet", "--outfile"])
        .arg(&small)
        .arg(&p)
        .output()
        .unwrap();
    assert!(run.status.success());
    let check = |args: &[&str], expected: &str| {
        let t = std::time::Instant::now();
        let out = rpbrt().arg("imgtool").args(args).output().unwrap();
        let e = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {e}");
        assert!(e.contains(expected), "{args:?}: {e}");
        assert!(t.elapsed() < std::time::Duration::from_secs(20));
    };
    let s = small.to_str().unwrap();
    let out = dir.join("out.exr");
    let o = out.to_str().unwrap();
    check(
        &["convert", "--max-memory", "1G", "--repeatpix", "2000", s, o],
        "convert: --repeatpix 2000: the 8000x8000 output image needs 1.4 GiB; --max-memory is 1.0 GiB",
    );
    check(
        &["convert", "--repeatpix", "2000000000", s, o],
        "is larger than an image may be",
    );
    // Past any machine's default budget.
    check(
        &["makesky", "--resolution", "1000000", "--outfile", o],
        "makesky: the 1000000x1000000 sky map needs 21.8 TiB; --max-memory is",
    );
    check(
        &["makeequiarea", "--resolution", "1000000", s, o],
        "makeequiarea: the 1000000x1000000 output image needs 21.8 TiB; --max-memory is",
    );
    // Inputs are charged too, and the flag is checked.
    check(
        &["info", "--max-memory=100", s],
        "--max-memory is 100 bytes",
    );
    check(
        &["info", "--max-memory", "0", s],
        "--max-memory must be more than 0",
    );
    check(
        &["info", "--max-memory", "lots", s],
        "\"lots\" is not a size",
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn max_memory_flag_is_checked_and_listed() {
    for bad in ["0", "lots", "-1G", "6X"] {
        let out = rpbrt()
            .args(["--max-memory", bad, "x.pbrt"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{bad}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("--max-memory"),
            "{bad}"
        );
    }
    let out = rpbrt().arg("--help").output().unwrap();
    assert!(String::from_utf8_lossy(&out.stdout).contains("--max-memory <size>"));
    // --stats reports what was charged against it.
    let p = temp_scene("stats-budget.pbrt", TINY_SCENE);
    let out = rpbrt()
        .args(["--stats", "--quiet", "--max-memory", "512M", "--outfile"])
        .arg(std::env::temp_dir().join(format!("rpbrt-stats-{}.exr", std::process::id())))
        .arg(&p)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{e}");
    assert!(
        e.contains("Memory budget") && e.contains("MiB of 512.0 MiB (--max-memory)"),
        "{e}"
    );
}

/// The design each render gets (`--stats` names it): the wavefront path
/// tracer for `path` and for `volpath` without media, the scalar loop for
/// `volpath` with media; `--wavefront` and `--no-wavefront` choose, and so
/// does the scene's `Option "bool wavefront"`, which the command line
/// overrides.
#[test]
fn the_design_defaults_to_the_wavefront_except_through_media() {
    let head = "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nSampler \"independent\" \"integer pixelsamples\" 1\nFilm \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\n";
    let world = "WorldBegin\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\nMaterial \"diffuse\"\nShape \"sphere\" \"float radius\" 1\n";
    let fog = "AttributeBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"\"\nMaterial \"interface\"\nTranslate 3 0 0\nShape \"sphere\" \"float radius\" 1\nAttributeEnd\n";
    let cases: [(&str, &str, &str, &[&str], &str); 8] = [
        ("path", "Integrator \"path\"\n", "", &[], "wavefront"),
        (
            "path-scalar",
            "Integrator \"path\"\n",
            "",
            &["--no-wavefront"],
            "scalar",
        ),
        ("volpath", "", "", &[], "wavefront"),
        ("volpath-fog", "", fog, &[], "scalar"),
        (
            "volpath-fog-wavefront",
            "",
            fog,
            &["--wavefront"],
            "wavefront",
        ),
        (
            "option-false",
            "Option \"bool wavefront\" false\nIntegrator \"path\"\n",
            "",
            &[],
            "scalar",
        ),
        (
            "option-false-wavefront",
            "Option \"bool wavefront\" false\nIntegrator \"path\"\n",
            "",
            &["--wavefront"],
            "wavefront",
        ),
        ("bdpt", "Integrator \"bdpt\"\n", "", &[], "scalar"),
    ];
    for (name, integrator, media, flags, want) in cases {
        let scene = temp_scene(
            &format!("design-{name}.pbrt"),
            &format!("{integrator}{head}{world}{media}"),
        );
        let out = rpbrt()
            .args(["--quiet", "--stats", "--nthreads", "1", "--outfile"])
            .arg(std::env::temp_dir().join(format!(
                "rpbrt-cli-{}-design-{name}.exr",
                std::process::id()
            )))
            .args(flags)
            .arg(&scene)
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {e}");
        let design = e
            .lines()
            .find(|l| l.trim_start().starts_with("Design"))
            .and_then(|l| l.split_whitespace().nth(1))
            .unwrap_or("");
        assert_eq!(design, want, "{name}: {e}");
    }
}

/// `--denoise`: the raw render beside the output name has the plain
/// render's pixels (an `rgb` film recorded as `gbuffer`) plus albedo and
/// normal, the output is the denoised image; tiles are refused. Skipped,
/// with a message, where there is no Open Image Denoise.
#[test]
fn denoise_writes_the_raw_render_beside_the_denoised_one() {
    let scene = temp_scene(
        "denoise.pbrt",
        "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
         Sampler \"independent\" \"integer pixelsamples\" 4\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 16 \"string filename\" \"unused.exr\"\n\
         WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n\
         Material \"diffuse\" \"rgb reflectance\" [0.2 0.5 0.8]\nShape \"sphere\"\n",
    );
    let dir = scene.parent().unwrap().to_path_buf();
    let (plain, out) = (dir.join("plain.exr"), dir.join("den.exr"));
    let noisy = dir.join("den-noisy.exr");
    run_ok(
        rpbrt()
            .args(["--quiet", "--outfile"])
            .arg(&plain)
            .arg(&scene),
    );
    let o = rpbrt()
        .args(["--quiet", "--denoise", "--outfile"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if err.contains("not found: install it with `pip install pyoidn`") {
        eprintln!("skipping the --denoise test: no Open Image Denoise here ({err})");
        return;
    }
    assert!(o.status.success(), "{err}");
    assert_eq!(differing_pixels(&plain, &noisy), "0");
    let info = run_ok(rpbrt().args(["imgtool", "info"]).arg(&noisy));
    assert!(info.contains("Albedo.R") && info.contains("Ns.Z"), "{info}");
    let info = run_ok(rpbrt().args(["imgtool", "info"]).arg(&out));
    assert!(
        !info.contains("Albedo.R") && info.contains("resolution 24x16"),
        "{info}"
    );
    let o = rpbrt()
        .args(["--quiet", "--denoise", "--tile", "1/2", "--outfile"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("denoise the joined image"));
}
