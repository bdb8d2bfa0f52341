//! End-to-end tests of `rpbrt imgtool`: every command's usage, results on
//! small images made here (values worked out by hand), and clear errors
//! with status 1, never a panic, on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rpbrt_render::geometry::Point2i;
use rpbrt_render::image::{Image, ImageMetadata};

const COMMANDS: [&str; 12] = [
    "average",
    "bloom",
    "cat",
    "convert",
    "diff",
    "error",
    "falsecolor",
    "info",
    "makeemitters",
    "scalenormalmap",
    "splitn",
    "whitebalance",
];

fn imgtool(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rpbrt"))
        .arg("imgtool")
        .args(args)
        .output()
        .unwrap()
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rpbrt-imgtool-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(path: &Path, vals: &[f32], w: i32, h: i32, names: &[&str]) -> String {
    Image::from_f32(vals.to_vec(), Point2i::new(w, h), names)
        .unwrap()
        .write(path, &ImageMetadata::default())
        .unwrap();
    path.to_string_lossy().into_owned()
}

/// Reads an image, R, G, B first when it has them (EXR stores channels
/// sorted by name).
fn read(path: &Path) -> Image {
    let im = Image::read(path, None).unwrap().image;
    match im.get_channel_desc(&["R", "G", "B"]) {
        Some(d) => im.select_channels(&d),
        None => im,
    }
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Status 1, a message containing `want`, no panic.
fn fails_with(o: &Output, want: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "stderr: {e}");
    assert!(e.contains(want), "expected \"{want}\" in: {e}");
    assert!(!e.contains("panicked"), "{e}");
}

fn close(a: &[f32], b: &[f32]) {
    assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() < 1e-5, "{a:?} vs {b:?}");
    }
}

#[test]
fn every_command_has_usage_by_help_and_flag() {
    let o = imgtool(&["help"]);
    assert_eq!(o.status.code(), Some(0));
    for c in COMMANDS {
        assert!(stdout(&o).contains(c), "{c} missing from help");
        for args in [vec!["help", c], vec![c, "--help"]] {
            let o = imgtool(&args);
            assert_eq!(o.status.code(), Some(0), "{args:?}");
            assert!(
                stdout(&o).starts_with(&format!("usage: rpbrt imgtool {c}")),
                "{args:?}: {}",
                stdout(&o)
            );
        }
    }
    fails_with(&imgtool(&["help", "frob"]), "unknown imgtool command");
}

#[test]
fn missing_files_and_unknown_options_are_clear_errors() {
    let d = dir("missing");
    let out = d.join("o.exr");
    let out = out.to_str().unwrap();
    for args in [
        vec![
            "bloom",
            "--level",
            "1",
            "--outfile",
            out,
            "/nonexistent.exr",
        ],
        vec!["cat", "/nonexistent.exr"],
        vec!["convert", "/nonexistent.exr", out],
        vec!["diff", "/nonexistent.exr", "/nonexistent2.exr"],
        vec![
            "error",
            "--reference",
            "/nonexistent.exr",
            "/nonexistent/r-",
        ],
        vec!["falsecolor", "--outfile", out, "/nonexistent.exr"],
        vec!["info", "/nonexistent.exr"],
        vec!["makeemitters", "/nonexistent.exr"],
        vec!["scalenormalmap", "--outfile", out, "/nonexistent.exr"],
        vec!["splitn", "--outfile", out, "/nonexistent.exr"],
        vec![
            "whitebalance",
            "--temperature",
            "3000",
            "--outfile",
            out,
            "/nonexistent.exr",
        ],
    ] {
        fails_with(&imgtool(&args), "nonexistent");
    }
    for c in COMMANDS {
        fails_with(&imgtool(&[c, "--frobnicate", "x"]), "frobnicate");
    }
    fails_with(
        &imgtool(&["convert", "--scale", "x", "a.exr"]),
        "not a number",
    );
    fails_with(
        &imgtool(&["convert", "--crop", "1,2", "a.exr"]),
        "4 comma-separated",
    );
    fails_with(&imgtool(&["convert", "a.exr"]), "--outfile");
    fails_with(&imgtool(&["bloom", "a.exr"]), "--outfile");
    fails_with(&imgtool(&["diff", "a.exr"]), "--reference");
    fails_with(&imgtool(&["error", "a-"]), "--reference");
    fails_with(
        &imgtool(&["diff", "--metric", "PSNR", "a", "b"]),
        "--metric",
    );
}

#[test]
fn diff_flip_prints_pbrt_v4_summary_and_writes_the_error_channel() {
    let d = dir("flip");
    let (w, h) = (12, 10);
    let grey = vec![0.5f32; 3 * w * h];
    let mut dot = grey.clone();
    let centre = 3 * (5 * w + 6);
    dot[centre..centre + 3].copy_from_slice(&[1.0, 1.0, 1.0]);
    let a = write(
        &d.join("a.exr"),
        &grey,
        w as i32,
        h as i32,
        &["R", "G", "B"],
    );
    let b = write(&d.join("b.exr"), &dot, w as i32, h as i32, &["R", "G", "B"]);
    // Equal: silent, status 0.
    let o = imgtool(&["diff", "--metric", "flip", &a, &a]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stdout(&o).is_empty());
    // Different: pbrt-v4's summary with the mean FLIP, and the per-pixel
    // FLIP in one "Error" channel, largest at the changed pixel.
    let err = d.join("flip.exr");
    let o = imgtool(&[
        "diff",
        "--metric",
        "FLIP",
        "--outfile",
        err.to_str().unwrap(),
        &b,
        &a,
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = Image::read(&err, None).unwrap().image;
    assert_eq!(e.channel_names(), ["Error"]);
    let v = e.to_f32_vec();
    let max = v.iter().copied().fold(0.0f32, f32::max);
    assert_eq!(v[5 * w + 6], max);
    assert!(max > 0.0 && max <= 1.0);
    let mean = v.iter().sum::<f32>() / v.len() as f32;
    let s = stdout(&o);
    assert!(s.contains(&format!("FLIP = {mean:.6}")), "{s}");
    assert!(
        s.contains("avg = 0.504167 / 0.500000 (0.833333% delta)"),
        "{s}"
    );
    // FLIP takes three channels only.
    let rg = write(&d.join("rg.exr"), &[0.1, 0.2], 1, 1, &["R", "G"]);
    fails_with(
        &imgtool(&["diff", "--metric", "FLIP", &rg, &rg]),
        "only 3 channel",
    );
}

#[test]
fn diff_reports_by_default_and_follows_pbrt_v4_with_a_metric() {
    let d = dir("diff");
    let a = write(&d.join("a.exr"), &[1.0, 2.0, 3.0, 4.0], 2, 1, &["R", "G"]);
    let b = write(&d.join("b.exr"), &[1.0, 2.0, 1.0, 2.0], 2, 1, &["R", "G"]);
    let o = imgtool(&["diff", &a, &b]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let s = stdout(&o);
    // Terms 0, 0, 4, 4 over 4 values: MSE 2.
    assert!(s.contains("MSE: 2.000000e0"), "{s}");
    for line in [
        "relative MSE (worst 0.1% dropped):",
        "mean clamped",
        "median pixel brightness:",
        "differing pixels: 1",
        "non-finite terms: 0",
    ] {
        assert!(s.contains(line), "{line} missing: {s}");
    }
    // pbrt-v4's behaviour: equal images are silent, status 0.
    let o = imgtool(&["diff", "--metric", "MSE", "--reference", &a, &a]);
    assert_eq!(o.status.code(), Some(0));
    assert!(stdout(&o).is_empty());
    // Different: averages 2.5 and 1.5 (66.67% delta), MAE (0+0+2+2)/2
    // per channel = 1 each, status 1; the error image holds the terms.
    let err = d.join("err.exr");
    let o = imgtool(&[
        "diff",
        "--metric",
        "MAE",
        "--outfile",
        err.to_str().unwrap(),
        "--reference",
        &b,
        &a,
    ]);
    assert_eq!(o.status.code(), Some(1));
    let s = stdout(&o);
    assert!(s.contains("Images differ"), "{s}");
    assert!(
        s.contains("avg = 2.500000 / 1.500000 (66.666667% delta), MAE = 1.000000"),
        "{s}"
    );
    close(&read(&err).to_f32_vec(), &[0.0, 0.0, 2.0, 2.0]);
    // Within the tolerance: not reported.
    let o = imgtool(&["diff", "--difftol", "70", "--reference", &b, &a]);
    assert_eq!(o.status.code(), Some(0));
    // Channels and crop: only G of the second pixel differs by 2.
    let o = imgtool(&[
        "diff",
        "--channels",
        "G",
        "--crop",
        "1,2,0,1",
        "--metric",
        "MSE",
        &a,
        &b,
    ]);
    assert!(stdout(&o).contains("MSE = 4.000000"), "{}", stdout(&o));
    fails_with(
        &imgtool(&["diff", "--channels", "B", &a, &b]),
        "does not have \"B\"",
    );
    let c = write(&d.join("c.exr"), &[1.0, 2.0], 1, 1, &["R", "G"]);
    fails_with(&imgtool(&["diff", &a, &c]), "doesn't match");
    fails_with(&imgtool(&["diff", "--crop", "0,5,0,1", &a, &b]), "outside");
}

#[test]
fn convert_applies_pbrt_v4_options() {
    let d = dir("convert");
    let i = write(
        &d.join("i.exr"),
        &[4.0, 2.0, 1.0, 0.5, 0.25, 0.0],
        2,
        1,
        &["R", "G", "B"],
    );
    let out = d.join("o.exr");
    let o = imgtool(&[
        "convert",
        "--clamp",
        "2",
        "--scale",
        "2",
        "--outfile",
        out.to_str().unwrap(),
        &i,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    close(&read(&out).to_f32_vec(), &[4.0, 2.0, 1.0, 1.0, 0.5, 0.0]);
    // --exposure 1 is --scale 2; the output may follow the input; crop
    // keeps the second pixel; flip of one row changes nothing.
    let out2 = d.join("o2.pfm");
    let o = imgtool(&[
        "convert",
        "--exposure",
        "1",
        "--crop",
        "1,2,0,1",
        "--flipy",
        &i,
        out2.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    close(&read(&out2).to_f32_vec(), &[1.0, 0.5, 0.0]);
    // Reinhard with max luminance 2: pixel 2's lum is 0.25, its scale
    // (1 + 0.25/4) / 1.25 = 0.85.
    let o = imgtool(&[
        "convert",
        "--tonemap",
        "--maxluminance",
        "2",
        "--channels",
        "R,G,B",
        &i,
        out2.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0));
    let v = read(&out2).to_f32_vec();
    close(&v[3..], &[0.425, 0.2125, 0.0]);
    fails_with(
        &imgtool(&["convert", "--channels", "Q", &i, out2.to_str().unwrap()]),
        "doesn't have channels \"Q\"",
    );
    fails_with(
        &imgtool(&[
            "convert",
            "--colorspace",
            "nope",
            &i,
            out2.to_str().unwrap(),
        ]),
        "color space unknown",
    );
    fails_with(
        &imgtool(&["convert", "--repeatpix", "0", &i, out2.to_str().unwrap()]),
        "--repeatpix",
    );
}

#[test]
fn error_estimates_mean_error_with_an_interval() {
    let d = dir("error");
    let r = write(&d.join("ref.exr"), &[0.0, 0.0], 2, 1, &["Y"]);
    // Errors: (1 + 1)/2 = 1, (4 + 0)/2 = 2, (9 + 9)/2 = 9 → mean 4.
    write(&d.join("r-1.exr"), &[1.0, -1.0], 2, 1, &["Y"]);
    write(&d.join("r-2.exr"), &[2.0, 0.0], 2, 1, &["Y"]);
    write(&d.join("r-3.exr"), &[3.0, 3.0], 2, 1, &["Y"]);
    let ef = d.join("var.exr");
    let base = d.join("r-");
    let o = imgtool(&[
        "error",
        "--reference",
        &r,
        "--errorfile",
        ef.to_str().unwrap(),
        base.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("MSE estimate = 4\n"), "{s}");
    // Sample sd of 1, 2, 9: sqrt(19) = 4.3589; se = 2.51661; t(2) = 4.3027.
    assert!(s.contains("standard error 2.51661, 3 images"), "{s}");
    // 4 - 4.3027 * 2.51661 = -6.8281.
    assert!(s.contains("[-6.828"), "{s}");
    // Per-pixel variances: of 1, 2, 3: 1; of -1, 0, 3: 13/3.
    close(&read(&ef).to_f32_vec(), &[1.0, 13.0 / 3.0]);
    fails_with(
        &imgtool(&["error", "--reference", &r, d.join("zz").to_str().unwrap()]),
        "no matching filenames",
    );
    write(&d.join("r-4.exr"), &[1.0], 1, 1, &["Y"]);
    fails_with(
        &imgtool(&["error", "--reference", &r, base.to_str().unwrap()]),
        "r-4.exr",
    );
}

#[test]
fn cat_info_and_falsecolor() {
    let d = dir("cat");
    let i = write(&d.join("i.exr"), &[3.0, 1.0, 2.0], 3, 1, &["Y"]);
    let o = imgtool(&["cat", &i]);
    assert_eq!(
        stdout(&o),
        "(0, 0): 3.000000\n(1, 0): 1.000000\n(2, 0): 2.000000\n"
    );
    let o = imgtool(&["cat", "--sort", &i]);
    assert_eq!(
        stdout(&o),
        "(1, 0): 1.000000\n(2, 0): 2.000000\n(0, 0): 3.000000\n"
    );
    let o = imgtool(&["cat", "--csv", &i]);
    assert_eq!(stdout(&o), "3.000000\n1.000000\n2.000000\n");
    let o = imgtool(&["cat", "--list", &i]);
    assert_eq!(stdout(&o), "3.000000 1.000000 2.000000 \n");
    fails_with(
        &imgtool(&["cat", "--sort", "--csv", &i]),
        "don't make sense",
    );

    let o = imgtool(&["info", &i]);
    let s = stdout(&o);
    assert!(s.contains("resolution 3x1"), "{s}");
    assert!(s.contains("color space: (unspecified)"), "{s}");
    assert!(s.contains("pixel bounds (0, 0) - (3, 1)"), "{s}");
    assert!(s.contains("Y: min 1 max 3 avg 2 (0 NaN, 0 Inf)"), "{s}");

    let f = d.join("f.exr");
    let o = imgtool(&["falsecolor", "--outfile", f.to_str().unwrap(), &i]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = read(&f).to_f32_vec();
    // Pixel 0 is the maximum: viridis' last entry (0.993248, 0.906157,
    // 0.143936) sRGB-decoded: 0.98471, 0.79965, 0.01824 (half floats).
    assert!(
        (v[0] - 0.98471).abs() < 1e-3 && (v[1] - 0.79965).abs() < 1e-3,
        "{v:?}"
    );
    let o = imgtool(&["falsecolor", "--ramp", "--outfile", f.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(read(&f).resolution(), Point2i::new(10, 300));
}

#[test]
fn bloom_normal_maps_white_balance_splitn_and_emitters() {
    let d = dir("misc");
    let i = write(&d.join("i.exr"), &[0.5, 4.0, 0.5], 3, 1, &["Y"]);
    let out = d.join("o.exr");
    let os = out.to_str().unwrap();
    let o = imgtool(&[
        "bloom",
        "--level",
        "1",
        "--width",
        "3",
        "--iterations",
        "1",
        "--scale",
        "0.5",
        "--outfile",
        os,
        &i,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Radius 1, sigma 0.5: side weight e^-2 / (1 + 2 e^-2).
    let e = (-2.0f32).exp();
    let w1 = e / (1.0 + 2.0 * e);
    close(&read(&out).to_f32_vec()[..1], &[0.5 + 0.5 * 4.0 * w1]);
    fails_with(&imgtool(&["bloom", "--outfile", os, &i]), "threshold");

    let n = write(&d.join("n.exr"), &[0.8, 0.5, 0.9], 1, 1, &["R", "G", "B"]);
    let o = imgtool(&["scalenormalmap", "--scale", "0.5", "--outfile", os, &n]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    close(
        &read(&out).to_f32_vec(),
        &[0.65, 0.5, (1.0 + 0.91f32.sqrt()) / 2.0],
    );
    fails_with(
        &imgtool(&["scalenormalmap", "--outfile", os, &i]),
        "R, G, B",
    );

    // Balancing for D65 in sRGB (whose white is D65) changes little.
    let o = imgtool(&[
        "whitebalance",
        "--primaries",
        "0.3127,0.329",
        "--outfile",
        os,
        &n,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = read(&out).to_f32_vec();
    assert!(
        (v[0] - 0.8).abs() < 1e-3 && (v[2] - 0.9).abs() < 1e-3,
        "{v:?}"
    );
    fails_with(
        &imgtool(&[
            "whitebalance",
            "--illuminant",
            "D65",
            "--temperature",
            "5000",
            "--outfile",
            os,
            &n,
        ]),
        "only provide one",
    );
    fails_with(
        &imgtool(&["whitebalance", "--illuminant", "Q9", "--outfile", os, &n]),
        "illuminant unknown",
    );
    fails_with(
        &imgtool(&["whitebalance", "--outfile", os, &n]),
        "must provide one",
    );

    let a = write(
        &d.join("a.exr"),
        &[1.0; 30 * 20 * 3],
        30,
        20,
        &["R", "G", "B"],
    );
    let b = write(
        &d.join("b.exr"),
        &[2.0; 30 * 20 * 3],
        30,
        20,
        &["R", "G", "B"],
    );
    let s = d.join("s.exr");
    let o = imgtool(&[
        "splitn",
        "--cropsize",
        "4",
        "--crop",
        "5,5",
        "--outfile",
        s.to_str().unwrap(),
        &a,
        &b,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(d.join("crops-s.exr").exists());
    let v = read(&s).to_f32_vec();
    // Row 19: x1 = 15 + (2*19/20 - 1)(30/-15) = 13.2 → 13: a up to x 10.
    let at = |x: usize, y: usize| v[(y * 30 + x) * 3];
    assert_eq!((at(9, 19), at(10, 19), at(16, 19)), (1.0, 0.0, 2.0));
    let c = write(&d.join("c.exr"), &[1.0; 3], 1, 1, &["R", "G", "B"]);
    fails_with(
        &imgtool(&["splitn", "--outfile", s.to_str().unwrap(), &a, &c]),
        "c.exr",
    );

    let e = write(
        &d.join("e.exr"),
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
        2,
        1,
        &["R", "G", "B"],
    );
    let o = imgtool(&["makeemitters", &e]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(
        s.contains("AreaLightSource \"diffuse\" \"rgb L\" [ 1.000000 2.000000 3.000000 ]"),
        "{s}"
    );
    assert!(
        s.contains("\"point3 P\" [ 1.000000 1.000000 0 0.000000 1.000000 0 1.000000 0.000000 0 0.000000 0.000000 0 ]"),
        "{s}"
    );
    fails_with(&imgtool(&["makeemitters", &i]), "R, G, and B");
}

#[test]
fn spectral_channel_names_with_commas_can_be_selected() {
    let d = dir("spectral");
    let i = write(
        &d.join("s.exr"),
        &[1.0, 2.0, 3.0, 0.5, 0.25],
        1,
        1,
        &["R", "G", "B", "S0.418,750nm", "S0.431,250nm"],
    );
    let out = d.join("o.exr");
    let o = imgtool(&[
        "convert",
        "--channels",
        "S0.431,250nm,R",
        &i,
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let im = read(&out);
    let desc = im.get_channel_desc(&["S0.431,250nm", "R"]).unwrap();
    assert_eq!(im.select_channels(&desc).to_f32_vec(), vec![0.25, 1.0]);
    let o = imgtool(&[
        "diff",
        "--channels",
        "S0.418,750nm",
        "--metric",
        "MSE",
        &i,
        &i,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn a_closed_output_pipe_is_not_a_panic() {
    use std::process::Stdio;
    let d = dir("pipe");
    let i = write(&d.join("big.exr"), &vec![0.5; 200 * 200], 200, 200, &["Y"]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_rpbrt"))
        .args(["imgtool", "cat", &i])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"));
}

/// An EXR's string attributes, its channel names and the file name are
/// printed by `info` with their control characters escaped: an ESC
/// sequence in them would otherwise act on the terminal, and a newline
/// would forge a line of the report.
#[test]
fn info_escapes_control_characters_of_exr_attributes() {
    let d = dir("info-escape");
    let path = d.join("e\u{1b}[2J.exr");
    let md = ImageMetadata {
        strings: [(
            "note\u{1b}]0;owned\u{7}".to_string(),
            vec!["a\u{1b}[31mred".to_string(), "two\nlines".to_string()],
        )]
        .into_iter()
        .collect(),
        ..Default::default()
    };
    Image::from_f32(vec![1.0], Point2i::new(1, 1), &["Y\u{1b}"])
        .unwrap()
        .write(&path, &md)
        .unwrap();
    let o = imgtool(&["info", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(!s.contains('\u{1b}') && !s.contains('\u{7}'), "{s:?}");
    assert!(
        s.contains(r#""note\u{1b}]0;owned\u{7}": [ "a\u{1b}[31mred" "two\u{a}lines" ]"#),
        "{s}"
    );
    assert!(s.contains(r"e\u{1b}[2J.exr:"), "{s}");
    assert!(s.contains(r"  Y\u{1b}: min 1 max 1"), "{s}");
}

/// A fixed-seed uniform value in [0, 1) (an LCG: enough noise for tests).
fn noise(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

#[test]
fn denoise_bad_inputs_are_clear_errors() {
    let d = dir("denoise-bad");
    let p = |n: &str| d.join(n).to_string_lossy().into_owned();
    let out = p("out.exr");
    let color = write(&d.join("c.exr"), &[0.5; 4 * 4 * 3], 4, 4, &["R", "G", "B"]);
    let gray = write(&d.join("y.exr"), &[0.5; 4 * 4], 4, 4, &["Y"]);
    fails_with(
        &imgtool(&["denoise", &gray, "--outfile", &out]),
        "no R, G, B channels to denoise",
    );
    let small = write(&d.join("a2.exr"), &[0.5; 2 * 2 * 3], 2, 2, &["R", "G", "B"]);
    fails_with(
        &imgtool(&["denoise", &color, "--albedo", &small, "--outfile", &out]),
        "2x2 albedo image for a 4x4 colour image",
    );
    fails_with(
        &imgtool(&["denoise", &color, "--normal", &color, "--outfile", &out]),
        "needs an albedo image too",
    );
    let mut nan = vec![0.5; 4 * 4 * 3];
    nan[7] = f32::NAN;
    let bad_albedo = write(&d.join("an.exr"), &nan, 4, 4, &["R", "G", "B"]);
    fails_with(
        &imgtool(&[
            "denoise",
            &color,
            "--albedo",
            &bad_albedo,
            "--outfile",
            &out,
        ]),
        "1 pixel(s) with a non-finite albedo",
    );
    fails_with(
        &imgtool(&["denoise", &color, "--quality", "best", "--outfile", &out]),
        "must be fast, balanced or high",
    );
    fails_with(
        &imgtool(&[
            "denoise",
            &color,
            "--color-only",
            "--albedo",
            &color,
            "--outfile",
            &out,
        ]),
        "--color-only takes no --albedo or --normal",
    );
    fails_with(
        &imgtool(&[
            "denoise",
            &color,
            "--color-only",
            "--noisy-aux",
            "--outfile",
            &out,
        ]),
        "--color-only uses none",
    );
    fails_with(
        &imgtool(&["denoise", &color]),
        "--outfile must be specified",
    );
    // A corrupt library where OIDN_DIR points: an error naming it.
    let lib_dir = d.join("oidn");
    std::fs::create_dir_all(&lib_dir).unwrap();
    std::fs::write(lib_dir.join("libOpenImageDenoise.so.2"), b"not a library").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_rpbrt"))
        .args(["imgtool", "denoise", &color, "--outfile", &out])
        .env("OIDN_DIR", &lib_dir)
        .output()
        .unwrap();
    fails_with(
        &o,
        "libOpenImageDenoise.so.2: cannot load Open Image Denoise",
    );
}

/// A noisy gradient with a NaN pixel, denoised from its colour alone and
/// with a `gbuffer` film's albedo and normal channels (prefiltered, and as
/// they are): each comes much closer to the clean image, the NaN is
/// reported and zeroed, and the metadata is kept. Skipped, with a message,
/// where there is no OIDN.
#[test]
fn denoise_removes_noise_with_and_without_auxiliary_images() {
    let d = dir("denoise");
    let (w, h) = (64usize, 64usize);
    let mut seed = 7u64;
    let mut clean = Vec::new();
    let mut vals = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let c = [
                0.2 + 0.6 * x as f32 / w as f32,
                0.5,
                0.3 + 0.4 * y as f32 / h as f32,
            ];
            let albedo = [0.8, 0.6, 0.4];
            for k in 0..3 {
                clean.push(c[k]);
                // Uniform in [0, 2c]: mean c, as a Monte Carlo estimate.
                vals.push(2.0 * c[k] * noise(&mut seed));
            }
            vals.extend(albedo);
            vals.extend([0.0, 0.0, 1.0]);
        }
    }
    vals[0] = f32::NAN;
    let names = [
        "R", "G", "B", "Albedo.R", "Albedo.G", "Albedo.B", "Ns.X", "Ns.Y", "Ns.Z",
    ];
    let input = d.join("noisy.exr");
    let md = ImageMetadata {
        samples_per_pixel: Some(4),
        ..Default::default()
    };
    Image::from_f32(vals.clone(), Point2i::new(w as i32, h as i32), &names)
        .unwrap()
        .write(&input, &md)
        .unwrap();
    let input = input.to_string_lossy().into_owned();
    let mse = |im: &[f32]| -> f64 {
        let rgb: Vec<f32> = if im.len() == clean.len() {
            im.to_vec()
        } else {
            im.chunks_exact(9).flat_map(|p| p[..3].to_vec()).collect()
        };
        rgb.iter()
            .zip(&clean)
            .skip(3)
            .map(|(a, b)| f64::from(a - b).powi(2))
            .sum::<f64>()
            / (rgb.len() - 3) as f64
    };
    let noisy_mse = mse(&vals);
    for (name, extra) in [
        ("aux", None),
        ("noisy-aux", Some("--noisy-aux")),
        ("color", Some("--color-only")),
    ] {
        let out = d.join(format!("{name}.exr"));
        let out_s = out.to_string_lossy().into_owned();
        let mut args = vec!["denoise", &input, "--outfile", &out_s, "--quality", "fast"];
        args.extend(extra);
        let o = imgtool(&args);
        let e = stderr(&o);
        if e.contains("not found: install it with `pip install pyoidn`") {
            eprintln!("skipping the denoise test: no Open Image Denoise here ({e})");
            return;
        }
        assert_eq!(o.status.code(), Some(0), "{e}");
        assert!(
            e.contains("1 pixel(s) with non-finite colour set to zero"),
            "{e}"
        );
        let im = Image::read(&out, None).unwrap();
        assert_eq!(im.metadata.samples_per_pixel, Some(4));
        let rgb = read(&out).to_f32_vec();
        assert!(
            rgb.iter().all(|v| v.is_finite()),
            "{name}: non-finite output"
        );
        let m = mse(&rgb);
        assert!(
            m * 5.0 < noisy_mse,
            "{name}: denoised MSE {m} against the noisy image's {noisy_mse}"
        );
    }
}
