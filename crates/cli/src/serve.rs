//! `rpbrt --serve-parts scene.pbrt`: parse and build the scene once, then
//! render the parts of it that stdin asks for, one request a line, so a
//! render-farm worker pays for parsing and the BVH once, not once a tile.
//!
//! A request is the part's flags, `--outfile` last (the rest of the line
//! is the file name):
//!
//!     --tile 3/64 --outfile /tmp/part-3.exr
//!     --spp-range 16..32 --outfile /tmp/range.exr
//!     --tile 3/64 --spp-range 0..8 --outfile /tmp/both.exr
//!
//! Each is answered by one line on stdout: `ok` or `error: <message>`.
//! An empty line or the end of stdin ends the process. A part rendered
//! this way has exactly the pixels `rpbrt --tile`/`--spp-range` gives.

use rpbrt_render::film::{tile_bounds, SampleRange};
use rpbrt_render::image::ImageMetadata;
use rpbrt_render::integrator::{Integrator, RenderOptions, Scene};
use std::io::{BufRead, Write};
use std::process::ExitCode;

/// One request: the tile, the sample range, the output file.
#[derive(Debug, PartialEq)]
struct Request {
    tile: Option<(u32, u32)>,
    range: Option<(i32, i32)>,
    outfile: String,
}

fn parse_request(line: &str) -> Result<Request, String> {
    let (flags, outfile) = line
        .split_once("--outfile ")
        .ok_or("a request needs --outfile <file> last")?;
    let outfile = outfile.trim().to_string();
    if outfile.is_empty() {
        return Err("--outfile needs a file".into());
    }
    let args: Vec<String> = flags.split_whitespace().map(str::to_string).collect();
    let o = crate::args::parse_args(&args).map_err(|e| e.to_string())?;
    let only_parts = o.files.is_empty()
        && crate::args::Options {
            tile: None,
            spp_range: None,
            ..o.clone()
        } == crate::args::Options::default();
    if !only_parts {
        return Err(format!(
            "\"{}\": a request takes only --tile, --spp-range and --outfile",
            flags.trim()
        ));
    }
    Ok(Request {
        tile: o.tile,
        range: o.spp_range,
        outfile,
    })
}

/// Renders one request into its file.
fn render_part(
    integrator: &Integrator,
    scene: &mut Scene,
    base: &RenderOptions,
    req: &Request,
) -> Result<(), String> {
    let bounds = match req.tile {
        Some((k, n)) => {
            let all = scene.film.pixel_bounds();
            tile_bounds(all, k, n).ok_or_else(|| {
                format!(
                    "--tile {k}/{n}: the film's {} pixels cannot be split into {n} tiles",
                    all.area()
                )
            })?
        }
        None => scene.film.pixel_bounds(),
    };
    if let Some((start, end)) = req.range {
        SampleRange { start, end }
            .check(scene.sampler.samples_per_pixel())
            .map_err(|e| e.to_string())?;
    }
    scene.film.reset();
    if !scene.film.set_active_bounds(bounds) {
        return Err("the tile lies outside the film".into());
    }
    crate::check_output("--outfile", &req.outfile)?;
    scene.film.set_filename(req.outfile.clone());
    let opts = RenderOptions {
        sample_range: req.range.map(|(start, end)| SampleRange { start, end }),
        ..base.clone()
    };
    let mut metadata = ImageMetadata::default();
    integrator
        .render(scene, &opts, &mut metadata, &|_| {})
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Serves part requests from stdin until it ends.
pub fn run(integrator: &Integrator, scene: &mut Scene, base: RenderOptions) -> ExitCode {
    if !integrator.renders_pixel_samples() {
        diagln!(
            "rpbrt: error: --serve-parts: the \"{}\" integrator does not render pixel by pixel, so it cannot render parts",
            integrator.name()
        );
        return ExitCode::FAILURE;
    }
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for line in stdin.lock().lines() {
        let Ok(line) = line else { break };
        if line.trim().is_empty() {
            break;
        }
        let reply = parse_request(&line)
            .and_then(|req| render_part(integrator, scene, &base, &req))
            .map(|()| "ok".to_string())
            .unwrap_or_else(|e| format!("error: {}", e.replace('\n', " | ")));
        if writeln!(out, "{reply}").and_then(|()| out.flush()).is_err() {
            break;
        }
    }
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_parse() {
        assert_eq!(
            parse_request("--tile 3/64 --outfile /tmp/a b.exr"),
            Ok(Request {
                tile: Some((3, 64)),
                range: None,
                outfile: "/tmp/a b.exr".into()
            })
        );
        assert_eq!(
            parse_request("--spp-range 0..8 --tile 1/2 --outfile x.exr"),
            Ok(Request {
                tile: Some((1, 2)),
                range: Some((0, 8)),
                outfile: "x.exr".into()
            })
        );
        assert!(parse_request("--tile 3/64").is_err());
        assert!(parse_request("--tile 3/64 --outfile ").is_err());
        assert!(parse_request("--spp 4 --outfile x.exr").is_err());
        assert!(parse_request("scene.pbrt --outfile x.exr").is_err());
        assert!(parse_request("--tile 9/4 --outfile x.exr").is_err());
    }
}
