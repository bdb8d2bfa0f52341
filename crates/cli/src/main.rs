//! The `rpbrt` command-line renderer: a thin layer that parses flags and
//! calls into the parser and renderer crates, printing located diagnostics
//! (`file:line:col: error: ...`) and exiting non-zero on errors.

/// `eprint!` that ignores write errors. Diagnostics and progress are
/// best effort: std's `eprint!` panics when the write fails (stderr on a
/// full disk or `/dev/full`), which would abort a render and lose its image.
/// Messages often quote scene text or file names, so control characters
/// other than newline and tab are escaped rather than sent to the terminal.
macro_rules! diag {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = format!($($arg)*);
        let text = rpbrt_parser::diag::escape_controls(&text, "\n\t");
        let _ = std::io::stderr().write_all(text.as_bytes());
    }};
}

/// `eprintln!` that ignores write errors (see [`diag!`]).
macro_rules! diagln {
    () => {
        diag!("\n")
    };
    ($($arg:tt)*) => {
        diag!("{}\n", format_args!($($arg)*))
    };
}

mod args;
mod imgtool;
mod oidn;
mod preview;
mod serve;
mod tev;
mod watch;

use rpbrt_parser::{FormattingTarget, MemoryBudget, ParseOptions, Parser};
use rpbrt_render::accel::Aggregate;
use rpbrt_render::camera::RenderingCoordinateSystem;
use rpbrt_render::film::{FilmOverrides, SampleRange};
use rpbrt_render::image::tiled::TileCache;
use rpbrt_render::image::ImageMetadata;
use rpbrt_render::integrator::{Progress, RenderOptions};
use rpbrt_render::scene::assemble::{create_scene_taking_entities, CreateOptions};
use rpbrt_render::scene::{build_scene, BuildOptions, OptionValue, SceneDescription};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Where `--denoise` writes the raw render of output `out`: beside it,
/// `<stem>-noisy.exr` (EXR, which keeps the albedo and normal).
fn noisy_name(out: &str) -> String {
    let p = std::path::Path::new(out);
    let stem = p
        .file_stem()
        .map_or_else(|| "pbrt".into(), |s| s.to_string_lossy());
    p.with_file_name(format!("{stem}-noisy.exr"))
        .to_string_lossy()
        .into_owned()
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    if argv.first().map(String::as_str) == Some("imgtool") {
        return imgtool::run(&argv[1..]);
    }
    let opts = match args::parse_args(&argv) {
        Ok(o) => o,
        Err(e) => {
            diagln!("rpbrt: error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if opts.help {
        return print_product(args::USAGE);
    }
    if opts.version {
        return print_product(&format!("rpbrt {}\n", env!("CARGO_PKG_VERSION")));
    }
    if opts.files.is_empty() {
        diagln!("rpbrt: error: no scene file given\n\n{}", args::USAGE);
        return ExitCode::FAILURE;
    }
    if opts.format || opts.upgrade {
        return format_scene(&opts);
    }
    if opts.toply {
        diagln!("rpbrt: error: --toply is used together with --format or --upgrade");
        return ExitCode::FAILURE;
    }
    render_command(&opts)
}

/// `--format` / `--upgrade`: print the scene back as pbrt-v4 text.
fn format_scene(opts: &args::Options) -> ExitCode {
    let mut target = FormattingTarget::new(opts.upgrade);
    if opts.toply {
        // As pbrt-v4: PLY files go to the current directory, named
        // $PLY_PREFIX_NNNNN.ply ("mesh" by default).
        let prefix = std::env::var("PLY_PREFIX").unwrap_or_else(|_| "mesh".to_string());
        target = target.with_toply(".", prefix);
    }
    let parse = ParseOptions {
        budget: memory_budget(opts),
        ..ParseOptions::default()
    };
    let result = Parser::new(parse).parse_files(&opts.files, &mut target);
    let (diags, ok) = match result {
        Ok(d) => (d, true),
        Err(d) => (d, false),
    };
    if !diags.is_empty() {
        diag!("{}", diags.render());
    }
    if !ok {
        return ExitCode::FAILURE;
    }
    print_product(&target.into_output())
}

/// Writes output that is the command's product (usage, version, formatted
/// scene) to stdout: a failed write is an error exit with a message, not
/// a panic; a closed pipe (`| head`) is not an error.
fn print_product(s: &str) -> ExitCode {
    match imgtool::emit(s) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            diagln!("rpbrt: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The memory budget of `--max-memory` (or its default, from the
/// machine's memory) that the scene text, the description and the render
/// objects are charged to.
fn memory_budget(opts: &args::Options) -> MemoryBudget {
    let limit = opts
        .max_memory
        .unwrap_or_else(rpbrt_parser::budget::default_limit);
    MemoryBudget::labelled(limit, "--max-memory")
}

/// Peak resident memory in bytes (Linux), for `--stats`.
fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Renders the scene: parse and build it, create the render objects, render
/// in parallel and write the image. Every mistake in the file is reported
/// with its location, and the exit status is 1 on any error.
fn render_command(opts: &args::Options) -> ExitCode {
    let t0 = Instant::now();
    // `--interactive` implies `--preview` (a free loopback port by default).
    let preview_addr = opts.preview.or_else(|| {
        opts.interactive
            .then(|| std::net::SocketAddr::from(([127, 0, 0, 1], 0)))
    });
    if opts.interactive {
        let clash = [
            (opts.serve_parts, "--serve-parts"),
            (opts.spp_range.is_some(), "--spp-range"),
            (opts.tile.is_some(), "--tile"),
            (opts.denoise, "--denoise"),
            (opts.write_partial_images, "--write-partial-images"),
            (opts.mse_reference_image.is_some(), "--mse-reference-image"),
        ];
        if let Some((_, flag)) = clash.iter().find(|(on, _)| *on) {
            diagln!("rpbrt: error: --interactive renders the whole image until stopped; it does not go with {flag}");
            return ExitCode::FAILURE;
        }
    }
    let watching = preview_addr.is_some() || opts.display_server.is_some();
    if watching && opts.serve_parts {
        diagln!("rpbrt: error: --preview and --display-server watch one render, not --serve-parts");
        return ExitCode::FAILURE;
    }
    // Watching: the server binds before the scene loads, so that a port
    // in use fails at once.
    let watch = watching.then(|| Arc::new(watch::Watch::new()));
    let server = match (preview_addr, &watch) {
        (Some(addr), Some(w)) => match preview::Preview::start(addr, Arc::clone(w)) {
            Ok(p) => {
                let everywhere = if p.addr().ip().is_unspecified() {
                    " (all interfaces)"
                } else {
                    ""
                };
                diagln!("rpbrt: preview at {}{everywhere}", p.url());
                Some(p)
            }
            Err(e) => {
                diagln!("rpbrt: error: {e}");
                return ExitCode::FAILURE;
            }
        },
        _ => None,
    };
    let budget = memory_budget(opts);
    let mut build = BuildOptions::default();
    build.parse.budget = budget.clone();
    if let Some(r) = opts
        .render_coord_sys
        .as_deref()
        .and_then(RenderingCoordinateSystem::from_name)
    {
        build.render_coord_sys = r;
    }
    let paths: Vec<PathBuf> = opts.files.iter().map(PathBuf::from).collect();
    let (mut desc, diags) = match build_scene(&paths, &build) {
        Ok(r) => r,
        Err(d) => {
            diag!("{}", d.render());
            return ExitCode::FAILURE;
        }
    };
    let t_parse = t0.elapsed();
    let texture_cache = opts.texture_cache_mb.map(|mb| {
        let dir = opts
            .texture_cache_dir
            .as_ref()
            .map(PathBuf::from)
            .unwrap_or_else(TileCache::default_dir);
        Arc::new(TileCache::new((mb * 1e6) as u64, dir))
    });
    let create_opts = CreateOptions {
        spp: opts.spp,
        seed: opts.seed.or_else(|| {
            desc.option("seed").and_then(|o| match *o {
                OptionValue::Int(i) => Some(i),
                _ => None,
            })
        }),
        film: FilmOverrides {
            outfile: opts.outfile.clone(),
            crop_window: opts.crop_window,
            pixel_bounds: opts.pixel_bounds,
            quick: opts.quick,
            tile: opts.tile,
            aovs: opts.denoise || opts.gbuffer,
        },
        disable_texture_filtering: opts.disable_texture_filtering
            || desc_flag(&desc, "disabletexturefiltering"),
        force_diffuse: opts.force_diffuse || desc_flag(&desc, "forcediffuse"),
        texture_cache: texture_cache.clone(),
    };
    let mut all = diags;
    let created = match create_scene_taking_entities(&mut desc, &create_opts) {
        Ok(c) => c,
        Err(errors) => {
            all.items.extend(errors);
            diag!("{}", all.render());
            return ExitCode::FAILURE;
        }
    };
    all.items.extend(created.warnings);
    if !opts.quiet && !all.is_empty() {
        diag!("{}", all.render());
    }
    let mut scene = created.scene;
    let integrator = created.integrator;
    let t_create = t0.elapsed() - t_parse;
    if opts.interactive {
        if !integrator.renders_interactively() {
            diagln!(
                "rpbrt: error: --interactive: the \"{}\" integrator cannot render interactively (path, volpath, simplepath, simplevolpath, ambientocclusion, randomwalk and whitted can)",
                integrator.name()
            );
            return ExitCode::FAILURE;
        }
        if let Some(p) = &server {
            let b = scene.film.pixel_bounds();
            let d = b.diagonal();
            p.set_camera_control(preview::CameraControl::new(
                scene.camera.clone(),
                preview::CameraDirective::of(&desc.camera.base),
                Arc::clone(&scene.aggregate),
                (b.p_min.x, b.p_min.y),
                (d.x, d.y),
            ));
            if !opts.quiet {
                diagln!(
                    "rpbrt: interactive: move the camera at {}; Ctrl-C writes the image and ends",
                    p.url()
                );
            }
        }
    }
    if let Some((start, end)) = opts.spp_range {
        if !integrator.renders_pixel_samples() {
            diagln!(
                "rpbrt: error: --spp-range: the \"{}\" integrator does not take samples pixel by pixel, so its samples cannot be split into ranges",
                integrator.name()
            );
            return ExitCode::FAILURE;
        }
        if let Err(e) = (SampleRange { start, end }).check(scene.sampler.samples_per_pixel()) {
            diagln!("rpbrt: error: {e}");
            return ExitCode::FAILURE;
        }
    }
    if opts.tile.is_some() && !opts.quiet {
        let name = integrator.name();
        if matches!(name, "bdpt" | "lightpath" | "mlt" | "sppm") {
            diagln!(
                "rpbrt: warning: --tile: the tiles of a \"{name}\" render do not join into its full image (light paths splat across tile edges{}){}",
                if name == "sppm" { " and the photon count follows the pixel count" } else { "" },
                if integrator.renders_pixel_samples() { "; split it with --spp-range instead" } else { "" }
            );
        }
    }

    // `--denoise`: the render is written beside the output name, which
    // the denoised image takes.
    let denoise_to = if opts.denoise {
        if opts.tile.is_some() || opts.spp_range.is_some() || opts.serve_parts {
            diagln!(
                "rpbrt: error: --denoise: a tile or sample range is a part of an image; render the parts with --gbuffer and denoise the joined image (rpbrt imgtool denoise; rpbrt-farm --denoise does both)"
            );
            return ExitCode::FAILURE;
        }
        if !scene.film.uses_visible_surface() && !opts.quiet {
            diagln!(
                "rpbrt: warning: --denoise: a spectral film records no albedo or normal; denoising from the colour alone"
            );
        }
        let out = scene.film.filename().to_string();
        scene.film.set_filename(noisy_name(&out));
        Some(out)
    } else {
        None
    };

    // The outputs' directories are checked now, not after the render.
    if !opts.serve_parts {
        let outputs = std::iter::once(("output image", scene.film.filename())).chain(
            opts.mse_reference_out
                .as_deref()
                .map(|p| ("--mse-reference-out", p)),
        );
        for (what, path) in outputs {
            if let Err(e) = check_output(what, path) {
                diagln!("rpbrt: error: {e}");
                return ExitCode::FAILURE;
            }
        }
    }

    if let Some(w) = rpbrt_render::simd::env_warning() {
        if !opts.quiet {
            diagln!("rpbrt: warning: {w}");
        }
    }
    // The command line's choice, else the scene file's `Option "bool
    // wavefront"`, else the integrator's default for this scene.
    let asked = opts.wavefront.or(match desc.option("wavefront") {
        Some(OptionValue::Bool(b)) => Some(*b),
        _ => None,
    });
    let wavefront = asked.unwrap_or_else(|| integrator.wavefront_by_default(&scene));
    if asked == Some(true) && !integrator.has_wavefront() && !opts.quiet {
        diagln!(
            "rpbrt: warning: --wavefront: the \"{}\" integrator has no wavefront form yet; rendering it with the scalar loop",
            integrator.name(),
        );
    }

    let interrupt = Arc::new(AtomicBool::new(false));
    // A second Ctrl-C ends the process at once; the first one stops the
    // render after the current wave and writes the image so far.
    let _ = signal_hook::flag::register_conditional_shutdown(
        signal_hook::consts::SIGINT,
        130,
        Arc::clone(&interrupt),
    );
    let _ = signal_hook::flag::register(signal_hook::consts::SIGINT, Arc::clone(&interrupt));
    let mse_reference = match &opts.mse_reference_image {
        Some(path) => {
            match rpbrt_render::image::Image::read_within(std::path::Path::new(path), None, &budget)
            {
                Ok(im) => Some(im.image),
                Err(e) => {
                    diagln!("rpbrt: error: --mse-reference-image: {e}");
                    return ExitCode::FAILURE;
                }
            }
        }
        None => None,
    };
    if opts.mse_reference_out.is_some() && mse_reference.is_none() {
        diagln!("rpbrt: error: --mse-reference-out needs --mse-reference-image");
        return ExitCode::FAILURE;
    }
    let render_opts = RenderOptions {
        nthreads: opts.nthreads.unwrap_or(0),
        write_partial_images: opts.write_partial_images,
        disable_pixel_jitter: opts.disable_pixel_jitter || desc_flag(&desc, "disablepixeljitter"),
        disable_wavelength_jitter: opts.disable_wavelength_jitter
            || desc_flag(&desc, "disablewavelengthjitter"),
        interrupt: Some(Arc::clone(&interrupt)),
        mse_reference,
        sample_range: opts
            .spp_range
            .map(|(start, end)| SampleRange { start, end }),
        observer: watch
            .as_ref()
            .map(|w| Arc::clone(w) as Arc<dyn rpbrt_render::integrator::RenderObserver>),
        wavefront,
        simd: None,
        stage_times: (opts.stats && wavefront)
            .then(|| Arc::new(rpbrt_render::integrator::StageTimes::new())),
    };
    let tev = match (&watch, &opts.display_server) {
        (Some(w), Some(address)) => {
            w.set_title(scene.film.filename());
            let title = format!("{} ({})", scene.film.filename(), std::process::id());
            Some(tev::spawn(address, &title, Arc::clone(w)))
        }
        (Some(w), None) => {
            w.set_title(scene.film.filename());
            None
        }
        _ => None,
    };
    if opts.serve_parts {
        return serve::run(&integrator, &mut scene, render_opts);
    }
    let mut metadata = ImageMetadata::default();
    // The progress bar, redrawn in place on each report.
    let show_progress = !opts.quiet && std::io::stderr().is_terminal();
    let draw_progress = |p: Progress| {
        if let Some(w) = &watch {
            w.progress(p);
        }
        if show_progress {
            // Written as is: the bar's `\r` is ours, not scene text.
            let mut err = std::io::stderr().lock();
            let _ = err.write_all(progress_line(p).as_bytes());
            let _ = err.flush();
        }
    };
    let result = integrator.render(&mut scene, &render_opts, &mut metadata, &draw_progress);
    if show_progress {
        // Below the bar's last state.
        diagln!();
    }
    if let Some(w) = &watch {
        w.finish();
    }
    if let Some(t) = tev {
        let _ = t.join();
    }
    if let Some(p) = &server {
        // A page watching gets the final image before the process ends.
        p.linger();
    }
    let stats = match result {
        Ok(s) => s,
        Err(e) => {
            diagln!("rpbrt: error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if !opts.quiet {
        for w in &stats.warnings {
            diagln!("rpbrt: warning: {w}");
        }
    }
    if let Some(out) = &denoise_to {
        let job = imgtool::denoise::Job {
            infile: scene.film.filename(),
            outfile: out,
            albedo_file: None,
            normal_file: None,
            color_only: false,
            noisy_aux: false,
            quality: oidn::Quality::High,
        };
        if let Err(e) = imgtool::denoise::denoise_file(&job, &budget) {
            diagln!("rpbrt: error: --denoise: {e}");
            return ExitCode::FAILURE;
        }
    }
    if let Some(path) = &opts.mse_reference_out {
        let text: String = stats
            .mse_per_wave
            .iter()
            .map(|(spp, mse)| format!("{spp} {mse:e}\n"))
            .collect();
        if let Err(e) = std::fs::write(path, text) {
            diagln!("rpbrt: error: --mse-reference-out {path}: {e}");
            return ExitCode::FAILURE;
        }
    }
    if opts.stats {
        let c = &scene.counters;
        let secs = stats.render_time.as_secs_f64().max(1e-9);
        diagln!("Statistics:");
        diagln!(
            "  Parse and build scene      {:>10.3} s",
            t_parse.as_secs_f64()
        );
        diagln!(
            "  Create render objects      {:>10.3} s",
            t_create.as_secs_f64()
        );
        diagln!("  Render                     {:>10.3} s", secs);
        diagln!(
            "  Design                     {:>10}  (SIMD {})",
            if render_opts.wavefront && integrator.has_wavefront() {
                "wavefront"
            } else {
                "scalar"
            },
            rpbrt_render::simd::level().name()
        );
        if let Some(times) = render_opts
            .stage_times
            .as_ref()
            .filter(|_| integrator.has_wavefront())
        {
            let totals = times.totals();
            let sum: f64 = totals.iter().map(|(_, t)| t.as_secs_f64()).sum();
            diagln!("  Wavefront stages (thread time, all threads)");
            for (name, t) in totals {
                diagln!(
                    "    {:<26} {:>8.3} s {:>5.1}%",
                    name,
                    t.as_secs_f64(),
                    100.0 * t.as_secs_f64() / sum.max(1e-9)
                );
            }
        }
        diagln!(
            "  Samples                    {:>10}  ({:.3} M/s)",
            stats.samples,
            stats.samples as f64 / secs / 1e6
        );
        diagln!(
            "  Camera rays                {:>10}",
            c.camera_rays.load(Ordering::Relaxed)
        );
        diagln!(
            "  Intersection rays          {:>10}",
            c.intersection_rays.load(Ordering::Relaxed)
        );
        diagln!(
            "  Shadow rays                {:>10}",
            c.shadow_rays.load(Ordering::Relaxed)
        );
        let prims = scene.aggregate.primitive_count().max(1);
        diagln!(
            "  Primitives                 {:>10}",
            scene.aggregate.primitive_count()
        );
        diagln!(
            "  Accelerator memory         {:>10} bytes ({:.1} bytes/primitive)",
            scene.aggregate.accelerator().memory_bytes(),
            scene.aggregate.accelerator().memory_bytes() as f64 / prims as f64
        );
        diagln!(
            "  Memory budget              {:>10.1} MiB of {:.1} MiB (--max-memory)",
            budget.used() as f64 / (1024.0 * 1024.0),
            budget.limit() as f64 / (1024.0 * 1024.0)
        );
        if let Some(t) = &texture_cache {
            let st = t.stats();
            let reads = (st.hits + st.misses).max(1);
            diagln!(
                "  Texture cache              {:>10.1} MB, {} tile reads, {:.1}% hits; {} maps converted, {} reused ({})",
                st.capacity_bytes as f64 / 1e6,
                st.hits + st.misses,
                100.0 * st.hits as f64 / reads as f64,
                st.converted,
                st.reused,
                t.dir().display()
            );
        }
        if let Some(m) = peak_memory_bytes() {
            diagln!(
                "  Peak memory                {:>10.1} MiB",
                m as f64 / (1024.0 * 1024.0)
            );
        }
    }
    // The process ends with this function: the scene's memory goes back
    // with it, not freed part by part (a million object instances take a
    // tenth of a second to free), as pbrt-v4 leaves its scene at exit.
    std::mem::forget(scene);
    if stats.interrupted {
        diagln!("rpbrt: interrupted; wrote the image rendered so far");
        return ExitCode::from(130);
    }
    ExitCode::SUCCESS
}

/// Fails fast when `path` could not be written once the render is done:
/// a missing or read-only directory is found before hours of rendering.
pub(crate) fn check_output(what: &str, path: &str) -> Result<(), String> {
    let p = std::path::Path::new(path);
    rpbrt_render::image::io::check_writable(p).map_err(|e| {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        format!(
            "{what} \"{path}\" cannot be written in directory \"{}\": {e}",
            dir.display()
        )
    })
}

/// The progress bar line for a progress report.
fn progress_line(p: Progress) -> String {
    let elapsed = p.elapsed.as_secs_f64();
    let frac = p.done as f64 / p.total.max(1) as f64;
    let eta = if frac > 0.0 {
        elapsed / frac - elapsed
    } else {
        0.0
    };
    let width = 40;
    let filled = ((frac * width as f64) as usize).min(width);
    format!(
        "\r[{}{}] {:5.1}% {:.1}s elapsed, ETA {:.1}s ",
        "+".repeat(filled),
        " ".repeat(width - filled),
        frac * 100.0,
        elapsed,
        eta
    )
}

/// A boolean `Option` from the scene file.
fn desc_flag(desc: &SceneDescription, name: &str) -> bool {
    matches!(desc.option(name), Some(OptionValue::Bool(true)))
}

#[cfg(test)]
mod tests {
    use super::progress_line;
    use rpbrt_render::integrator::Progress;
    use std::time::Duration;

    #[test]
    fn progress_line_draws_the_fraction_done() {
        let line = progress_line(Progress {
            done: 50,
            total: 200,
            elapsed: Duration::from_secs(2),
        });
        assert!(line.starts_with('\r'), "{line:?}");
        assert!(line.contains(&format!("[{}{}]", "+".repeat(10), " ".repeat(30))));
        assert!(line.contains(" 25.0% 2.0s elapsed, ETA 6.0s"), "{line:?}");
        let done = progress_line(Progress {
            done: 7,
            total: 7,
            elapsed: Duration::from_millis(500),
        });
        assert!(done.contains(&format!("[{}]", "+".repeat(40))) && done.contains("100.0%"));
    }
}
