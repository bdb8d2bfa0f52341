//! The `rpbrt` command-line renderer: a thin layer that parses flags and
//! calls into the parser and renderer crates, printing located diagnostics
//! (`file:line:col: error: ...`) and exiting non-zero on errors.

mod args;
mod imgtool;

use rpbrt_parser::{parse_files, FormattingTarget};
use rpbrt_render::scene::shapes::create_scene_shapes;
use rpbrt_render::scene::{build_scene, BuildOptions, RenderingCoordinateSystem};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    if argv.first().map(String::as_str) == Some("imgtool") {
        return imgtool::run(&argv[1..]);
    }
    let opts = match args::parse_args(&argv) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("rpbrt: error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if opts.help {
        print!("{}", args::USAGE);
        return ExitCode::SUCCESS;
    }
    if opts.version {
        println!("rpbrt {}", env!("CARGO_PKG_VERSION"));
        return ExitCode::SUCCESS;
    }
    if opts.files.is_empty() {
        eprintln!("rpbrt: error: no scene file given\n\n{}", args::USAGE);
        return ExitCode::FAILURE;
    }
    if opts.format || opts.upgrade {
        return format_scene(&opts);
    }
    if opts.toply {
        eprintln!("rpbrt: error: --toply is used together with --format or --upgrade");
        return ExitCode::FAILURE;
    }
    render(&opts)
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
    let result = parse_files(&opts.files, &mut target);
    let (diags, ok) = match result {
        Ok(d) => (d, true),
        Err(d) => (d, false),
    };
    if !diags.is_empty() {
        eprint!("{}", diags.render());
    }
    if !ok {
        return ExitCode::FAILURE;
    }
    let out = target.into_output();
    let mut stdout = std::io::stdout().lock();
    if stdout
        .write_all(out.as_bytes())
        .and_then(|_| stdout.flush())
        .is_err()
    {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

/// Renders the scene: parse and build it, create its shapes, then (not yet
/// built) render. Every mistake in the file is reported with its location
/// first; the missing renderer is then reported loudly rather than writing
/// a wrong image.
fn render(opts: &args::Options) -> ExitCode {
    let mut build = BuildOptions::default();
    if let Some(r) = opts
        .render_coord_sys
        .as_deref()
        .and_then(RenderingCoordinateSystem::from_name)
    {
        build.render_coord_sys = r;
    }
    let paths: Vec<PathBuf> = opts.files.iter().map(PathBuf::from).collect();
    let (desc, mut diags) = match build_scene(&paths, &build) {
        Ok(r) => r,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::FAILURE;
        }
    };
    let shapes = create_scene_shapes(&desc);
    diags.items.extend(shapes.diagnostics);
    if !opts.quiet || diags.has_errors() {
        eprint!("{}", diags.render());
    }
    if diags.has_errors() {
        return ExitCode::FAILURE;
    }
    eprintln!(
        "rpbrt: error: the scene is valid ({} shapes), but rendering is not implemented yet in this build",
        shapes.shapes.len()
    );
    ExitCode::FAILURE
}
