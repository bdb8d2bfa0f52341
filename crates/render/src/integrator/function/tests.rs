//! The `function` integrator end to end: scene text in, error file out.

use super::*;
use crate::integrator::Integrator;
use crate::scene::assemble::{create_scene, CreateOptions, CreatedScene};
use crate::scene::{build_scene_from_str, BuildOptions};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

fn out_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-function-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A scene for the function integrator: `res`² pixels, the sampler with
/// its extra parameters, the integrator's extra parameters (on line 4).
fn scene_text(sampler: &str, spp: i32, res: i32, function: &str, tag: &str, extra: &str) -> String {
    format!(
        "Sampler {sampler} \"integer pixelsamples\" {spp}\n\
         Film \"rgb\" \"integer xresolution\" {res} \"integer yresolution\" {res} \"string filename\" \"{}\"\n\
         Camera \"perspective\"\n\
         Integrator \"function\" \"string function\" \"{function}\" \"string filename\" \"{}\" {extra}\n\
         WorldBegin\n",
        out_path(&format!("{tag}.exr")).display(),
        out_path(&format!("{tag}-mse.txt")).display(),
    )
}

fn create(text: &str, opts: &CreateOptions) -> Result<CreatedScene, Vec<rpbrt_parser::Diagnostic>> {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    create_scene(&desc, opts)
}

/// Renders and returns the statistics and the error file's (N, mse) lines.
fn run_with(text: &str, opts: &RenderOptions) -> (RenderStats, Vec<(i32, f64)>) {
    let c = create(text, &CreateOptions::default())
        .unwrap_or_else(|e| panic!("{:?}", e.iter().map(|d| &d.message).collect::<Vec<_>>()));
    let Integrator::Function(f) = &c.integrator else {
        panic!("not the function integrator");
    };
    let filename = f.filename.clone();
    let stats = render(f, &c.scene, opts, &|_| {}).unwrap();
    let text = std::fs::read_to_string(&filename).unwrap();
    let lines = text
        .lines()
        .map(|l| {
            let (n, mse) = l.split_once(' ').unwrap();
            // pbrt-v4's "%f": six decimals.
            assert_eq!(mse.split_once('.').unwrap().1.len(), 6, "{l}");
            (n.parse().unwrap(), mse.parse().unwrap())
        })
        .collect();
    (stats, lines)
}

fn run(text: &str, threads: usize) -> (RenderStats, Vec<(i32, f64)>) {
    let opts = RenderOptions {
        nthreads: threads,
        ..Default::default()
    };
    run_with(text, &opts)
}

/// The error at sample count `n`.
fn mse_at(lines: &[(i32, f64)], n: i32) -> f64 {
    lines.iter().find(|l| l.0 == n).unwrap().1
}

/// Each test function integrates to 1 (midpoint rule on a fine grid).
#[test]
fn test_functions_integrate_to_one() {
    const N: usize = 2000;
    for name in TestFunction::NAMES {
        let f = TestFunction::from_name(name).unwrap();
        assert_eq!(f.name(), name);
        let mut sum = 0.0f64;
        for y in 0..N {
            for x in 0..N {
                let p = Point2f::new(
                    (x as Float + 0.5) / N as Float,
                    (y as Float + 0.5) / N as Float,
                );
                sum += f.eval(p) as f64;
            }
        }
        let integral = sum / (N * N) as f64;
        assert!((integral - 1.0).abs() < 2e-3, "{name}: {integral}");
    }
    assert_eq!(TestFunction::from_name("stepp"), None);
}

/// One line per sample count that pbrt-v4's `skipbad` keeps, for each of
/// the sampler kinds it knows; every count without `skipbad`.
#[test]
fn function_writes_one_line_per_good_sample_count() {
    let cases: &[(&str, i32, &str, &[i32])] = &[
        ("\"independent\"", 6, "", &[1, 2, 3, 4, 5, 6]),
        ("\"zsobol\"", 4, "", &[1, 2, 3, 4]),
        (
            "\"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 8",
            16,
            "",
            &[1, 4, 9, 16],
        ),
        ("\"paddedsobol\"", 16, "", &[1, 2, 4, 8, 16]),
        ("\"halton\"", 40, "", &[1, 6, 36]),
        (
            "\"stratified\" \"integer xsamples\" 5 \"integer ysamples\" 1",
            5,
            "\"bool skipbad\" false",
            &[1, 2, 3, 4, 5],
        ),
        ("\"halton\"", 3, "\"bool skipbad\" false", &[1, 2, 3]),
    ];
    for (i, (sampler, spp, extra, counts)) in cases.iter().enumerate() {
        let text = scene_text(sampler, *spp, 8, "step", &format!("lines-{i}"), extra);
        let (stats, lines) = run(&text, 0);
        let ns: Vec<i32> = lines.iter().map(|l| l.0).collect();
        assert_eq!(&ns, counts, "{sampler} {extra}");
        assert!(!stats.interrupted);
        assert_eq!(stats.mse_per_wave.len(), counts.len());
    }
}

/// Independent samples of the step (variance 1 per sample): the error
/// falls as 1/N.
#[test]
fn function_mse_falls_as_one_over_n_for_independent_samples() {
    let text = scene_text("\"independent\"", 256, 32, "step", "step-independent", "");
    let (_, lines) = run(&text, 0);
    let (e16, e256) = (mse_at(&lines, 16), mse_at(&lines, 256));
    // Expected 1/16 and 1/256, each from 1024 pixels (±10% or so).
    assert!((e16 * 16.0 - 1.0).abs() < 0.25, "mse(16) = {e16}");
    assert!((e256 * 256.0 - 1.0).abs() < 0.25, "mse(256) = {e256}");
    let ratio = e16 / e256;
    assert!((11.0..23.0).contains(&ratio), "mse(16)/mse(256) = {ratio}");
}

/// At 256 samples of the disk, stratified, halton and padded Sobol' points
/// (each randomisation) do better than independent ones; all but the
/// padded Sobol' points with random XOR (a digital shift, which moves the
/// points of an elementary interval together) far better.
#[test]
fn function_low_discrepancy_beats_independent_on_the_disk() {
    let text = scene_text("\"independent\"", 256, 16, "disk", "disk-independent", "");
    let independent = mse_at(&run(&text, 0).1, 256);
    // Independent: the disk's variance (4/π − 1) over 256.
    assert!((independent * 256.0 / (4.0 / std::f64::consts::PI - 1.0) - 1.0).abs() < 0.3);
    let others = [
        (
            "\"stratified\" \"integer xsamples\" 16 \"integer ysamples\" 16",
            4.0,
        ),
        ("\"halton\"", 4.0),
        ("\"halton\" \"string randomization\" \"owen\"", 4.0),
        ("\"halton\" \"string randomization\" \"none\"", 4.0),
        ("\"paddedsobol\"", 4.0),
        ("\"paddedsobol\" \"string randomization\" \"owen\"", 4.0),
        (
            "\"paddedsobol\" \"string randomization\" \"permutedigits\"",
            1.2,
        ),
        ("\"paddedsobol\" \"string randomization\" \"none\"", 4.0),
        ("\"zsobol\"", 4.0),
        ("\"pmj02bn\"", 4.0),
    ];
    for (i, (sampler, factor)) in others.iter().enumerate() {
        let text = scene_text(
            sampler,
            256,
            16,
            "disk",
            &format!("disk-{i}"),
            "\"bool skipbad\" false",
        );
        let mse = mse_at(&run(&text, 0).1, 256);
        assert!(
            mse * factor < independent,
            "{sampler}: {mse} vs independent {independent}"
        );
    }
}

/// The average estimate's check: a 1-sample render is far from 1 and
/// warns; a stratified grid aligned with the step is exact and does not.
#[test]
fn function_warns_when_the_average_is_far_from_one() {
    let text = scene_text("\"independent\"", 1, 8, "step", "warn-1", "");
    let (stats, _) = run(&text, 0);
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(
        stats.warnings[0].contains("suspiciously far from 1"),
        "{:?}",
        stats.warnings
    );
    let text = scene_text("\"stratified\"", 16, 8, "step", "warn-none", ""); // 4×4 by default
    let (stats, lines) = run(&text, 0);
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    // Two columns of strata, split by the step exactly: no error at all.
    assert_eq!(mse_at(&lines, 4), 0.0);
    assert_eq!(mse_at(&lines, 16), 0.0);
}

/// pbrt-v4's errors, located: an unknown function at its parameter, the
/// `sobol` sampler at the `Integrator` directive; and an image file name
/// that cannot be written.
#[test]
fn function_errors_are_located() {
    let errors = |text: &str| match create(text, &CreateOptions::default()) {
        Ok(_) => panic!("must fail: {text}"),
        Err(e) => e,
    };
    let e = errors(&scene_text("\"independent\"", 4, 8, "stepp", "err-1", ""));
    assert!(
        e.iter().any(|d| d
            .message
            .contains("\"stepp\": function for the \"function\" integrator unknown")
            && d.loc.as_ref().is_some_and(|l| l.line == 4 && l.column > 20)),
        "{e:?}"
    );
    let e = errors(&scene_text("\"sobol\"", 4, 8, "step", "err-2", ""));
    assert!(
        e.iter().any(|d| d.message
            == "\"sobol\" sampler should be replaced with \"paddedsobol\" for the \"function\" integrator."
            && d.loc.as_ref().is_some_and(|l| l.line == 4 && l.column == 1)),
        "{e:?}"
    );
    let e = errors(&scene_text(
        "\"independent\"",
        4,
        8,
        "step",
        "err-3",
        "\"string imagefilename\" \"f.txt\"",
    ));
    assert!(
        e.iter()
            .any(|d| d.message.contains("imagefilename") || d.message.contains("f.txt")),
        "{e:?}"
    );
}

/// Each pixel's sum depends on its own samples only: the file is the same
/// for one and two threads, for every sampler and randomisation.
#[test]
fn function_is_deterministic_across_thread_counts() {
    for (i, sampler) in [
        "\"independent\"",
        "\"stratified\"",
        "\"halton\"",
        "\"halton\" \"string randomization\" \"owen\"",
        "\"paddedsobol\"",
        "\"paddedsobol\" \"string randomization\" \"owen\"",
        "\"zsobol\"",
        "\"pmj02bn\"",
    ]
    .iter()
    .enumerate()
    {
        let text = scene_text(
            sampler,
            16,
            13,
            "rotatedcheckerboard",
            &format!("det-{i}"),
            "\"bool skipbad\" false",
        );
        let (_, one) = run(&text, 1);
        let (_, two) = run(&text, 2);
        assert_eq!(one, two, "{sampler}");
        assert_eq!(one.len(), 16);
    }
}

/// `--outfile` names the error file (the film, never written, keeps its
/// own name), and `imagefilename` writes the function's image.
#[test]
fn function_outfile_and_image() {
    let outfile = out_path("outfile-mse.txt");
    let _ = std::fs::remove_file(&outfile);
    let image = out_path("gaussian.pfm");
    let text = format!(
        "Sampler \"independent\" \"integer pixelsamples\" 2\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
         Camera \"perspective\"\n\
         Integrator \"function\" \"string function\" \"gaussian\" \"string imagefilename\" \"{}\"\n\
         WorldBegin\n",
        image.display()
    );
    let opts = CreateOptions {
        film: crate::film::FilmOverrides {
            outfile: Some(outfile.display().to_string()),
            ..Default::default()
        },
        ..Default::default()
    };
    let c = create(&text, &opts).unwrap_or_else(|e| panic!("{e:?}"));
    let Integrator::Function(f) = &c.integrator else {
        panic!("not the function integrator");
    };
    assert_eq!(PathBuf::from(&f.filename), outfile);
    assert_eq!(f.function, TestFunction::Gaussian);
    render(f, &c.scene, &RenderOptions::default(), &|_| {}).unwrap();
    let text = std::fs::read_to_string(&outfile).unwrap();
    assert_eq!(text.lines().count(), 2, "{text}");
    let im = Image::read(&image, None).unwrap().image;
    assert_eq!(im.resolution(), Point2i::new(8, 8));
    let v = im.to_f32_vec();
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    assert!((mean - 1.0).abs() < 0.02, "image mean {mean}");
    // The Gaussian peaks in the middle.
    assert!(v[4 * 8 + 4] > v[0] * 4.0);
}

/// The default file name is "<function>-mse.txt".
#[test]
fn function_default_file_name() {
    let text = "Sampler \"independent\"\nCamera \"perspective\"\nIntegrator \"function\" \"string function\" \"diagonal\"\nWorldBegin\n";
    let c = create(text, &CreateOptions::default()).unwrap_or_else(|e| panic!("{e:?}"));
    let Integrator::Function(f) = &c.integrator else {
        panic!("not the function integrator");
    };
    assert_eq!(f.filename, "diagonal-mse.txt");
    assert!(f.skip_bad);
    assert!(f.image_filename.is_none());
    assert!(c.integrator.light_sampler_name().is_none());
}

/// Ctrl-C before the first count: nothing sampled, an empty file, the
/// render marked interrupted; progress counts sample counts.
#[test]
fn function_interrupt_and_progress() {
    let text = scene_text("\"independent\"", 8, 8, "step", "interrupt", "");
    let opts = RenderOptions {
        interrupt: Some(Arc::new(AtomicBool::new(true))),
        ..Default::default()
    };
    let (stats, lines) = run_with(&text, &opts);
    assert!(stats.interrupted);
    assert!(lines.is_empty());
    assert!(stats.warnings.is_empty());

    let c = create(&text, &CreateOptions::default()).unwrap();
    let reports = std::sync::Mutex::new(Vec::new());
    let stats = c
        .integrator
        .render(
            &mut { c.scene },
            &RenderOptions::default(),
            &mut ImageMetadata::default(),
            &|p| reports.lock().unwrap().push(p),
        )
        .unwrap();
    let reports = reports.into_inner().unwrap();
    let last = reports.last().unwrap();
    assert_eq!((last.done, last.total), (8, 8));
    assert_eq!(stats.samples, 8 * 8 * 8);
}
