//! `rpbrt imgtool`: image utilities like pbrt-v4's `imgtool`. One file per
//! command, each with its `USAGE` and `run`; the numbers come from
//! `rpbrt_render::image::ops`, these modules only parse arguments and print.

use rpbrt_parser::budget::{default_limit, parse_size};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::{Image, ImageAndMetadata, ImageMetadata};
use std::path::Path;
use std::process::ExitCode;

mod args;
mod assemble;
mod average;
mod bloom;
mod cat;
mod convert;
pub(crate) mod denoise;
mod diff;
mod error;
mod falsecolor;
mod info;
mod makeemitters;
mod makeequiarea;
mod makesky;
mod merge;
mod scalenormalmap;
mod splitn;
mod whitebalance;

/// A command: its name, one-line summary, usage text and entry point.
struct Command {
    name: &'static str,
    summary: &'static str,
    usage: &'static str,
    run: fn(&[String], &MemoryBudget) -> Result<(), String>,
}

/// Every command, in the order `help` lists them.
const COMMANDS: &[Command] = &[
    Command {
        name: "assemble",
        summary: "join tiles (crops) of an image into the whole",
        usage: assemble::USAGE,
        run: assemble::run,
    },
    Command {
        name: "average",
        summary: "average images sharing a filename base",
        usage: average::USAGE,
        run: average::run,
    },
    Command {
        name: "bloom",
        summary: "add a bloom around bright pixels",
        usage: bloom::USAGE,
        run: bloom::run,
    },
    Command {
        name: "cat",
        summary: "print pixel values",
        usage: cat::USAGE,
        run: cat::run,
    },
    Command {
        name: "convert",
        summary: "convert format; scale, tone map, crop, recolour",
        usage: convert::USAGE,
        run: convert::run,
    },
    Command {
        name: "denoise",
        summary: "denoise with Intel Open Image Denoise (CPU; colour, albedo, normal)",
        usage: denoise::USAGE,
        run: denoise::run,
    },
    Command {
        name: "diff",
        summary: "compare an image with a reference",
        usage: diff::USAGE,
        run: diff::run,
    },
    Command {
        name: "error",
        summary: "mean error of renders against a reference, with a 95% interval",
        usage: error::USAGE,
        run: error::run,
    },
    Command {
        name: "falsecolor",
        summary: "false-colour image of pixel magnitudes",
        usage: falsecolor::USAGE,
        run: falsecolor::run,
    },
    Command {
        name: "info",
        summary: "print resolution, metadata and channel statistics",
        usage: info::USAGE,
        run: info::run,
    },
    Command {
        name: "makeemitters",
        summary: "scene text: a quad emitter per pixel",
        usage: makeemitters::USAGE,
        run: makeemitters::run,
    },
    Command {
        name: "makeequiarea",
        summary: "convert a lat-long environment map to pbrt-v4's equal-area square",
        usage: makeequiarea::USAGE,
        run: makeequiarea::run,
    },
    Command {
        name: "makesky",
        summary: "make a Hosek-Wilkie sky environment map (equal-area)",
        usage: makesky::USAGE,
        run: makesky::run,
    },
    Command {
        name: "merge",
        summary: "join sample ranges (--spp-range) of the same pixels",
        usage: merge::USAGE,
        run: merge::run,
    },
    Command {
        name: "scalenormalmap",
        summary: "scale a normal map's slopes",
        usage: scalenormalmap::USAGE,
        run: scalenormalmap::run,
    },
    Command {
        name: "splitn",
        summary: "composite of slanted strips of images, with crops",
        usage: splitn::USAGE,
        run: splitn::run,
    },
    Command {
        name: "whitebalance",
        summary: "white balance for an illuminant, white point or temperature",
        usage: whitebalance::USAGE,
        run: whitebalance::run,
    },
];

/// The overview printed by `rpbrt imgtool help`.
fn overview() -> String {
    let mut s = String::from("usage: rpbrt imgtool <command> [options] <files...>\n\ncommands:\n");
    for c in COMMANDS {
        s += &format!("  {:<16}{}\n", c.name, c.summary);
    }
    s += "\nrpbrt imgtool help <command> (or <command> --help) prints a command's usage.\n";
    s += "Every command takes --max-memory <size> (e.g. 4G): the most memory its images\n";
    s += "may take (default: 3/4 of the machine's memory).\n";
    s
}

/// Writes `s` to standard output; a closed pipe (`| head`) is not an error.
pub(crate) fn emit(s: &str) -> Result<(), String> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(s.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("writing to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// Reads an image, with the file name in any error; the image is charged
/// to `budget`.
pub(crate) fn load(path: &str, budget: &MemoryBudget) -> Result<Image, String> {
    load_md(path, budget).map(|im| im.image)
}

/// Reads an image and its metadata, with the file name in any error; the
/// image is charged to `budget`.
pub(crate) fn load_md(path: &str, budget: &MemoryBudget) -> Result<ImageAndMetadata, String> {
    Image::read_within(Path::new(path), None, budget).map_err(|e| e.to_string())
}

/// Charges an output image of `w` × `h` pixels with `channels` channels,
/// which a command is about to make, to `budget`: its float pixels and the
/// encoded file. A size past what an image may have is an error too.
pub(crate) fn charge_output(
    budget: &MemoryBudget,
    w: i64,
    h: i64,
    channels: usize,
    what: &str,
) -> Result<(), String> {
    if w > i64::from(i32::MAX) || h > i64::from(i32::MAX) {
        return Err(format!(
            "{what} is larger than an image may be (at most {} pixels a side)",
            i32::MAX
        ));
    }
    let pixels = (w.max(0) as u64).saturating_mul(h.max(0) as u64);
    let bytes = pixels.saturating_mul(channels as u64 * 4 * 2);
    budget.charge(bytes, what).map_err(|e| e.to_string())
}

/// Takes `--max-memory <size>` (or `=<size>`, any spelling of the flag's
/// dashes) out of `args`: the budget every command's images are charged to.
fn take_max_memory(args: &[String]) -> Result<(Vec<String>, MemoryBudget), String> {
    let mut rest = Vec::with_capacity(args.len());
    let mut limit = None;
    let mut i = 0;
    while i < args.len() {
        let a = &args[i];
        i += 1;
        let body = a.trim_start_matches('-');
        let (name, inline) = match body.split_once('=') {
            Some((n, v)) => (n, Some(v.to_string())),
            None => (body, None),
        };
        let is_flag = a.starts_with('-')
            && name
                .replace(['-', '_'], "")
                .eq_ignore_ascii_case("maxmemory");
        if !is_flag {
            rest.push(a.clone());
            continue;
        }
        let value = match inline {
            Some(v) => v,
            None => {
                let v = args.get(i).ok_or("--max-memory needs a size (e.g. 4G)")?;
                i += 1;
                v.clone()
            }
        };
        limit = Some(parse_max_memory(&value)?);
    }
    let limit = limit.unwrap_or_else(default_limit);
    Ok((rest, MemoryBudget::labelled(limit, "--max-memory")))
}

/// A `--max-memory` value: a positive size.
pub(crate) fn parse_max_memory(value: &str) -> Result<u64, String> {
    match parse_size(value) {
        Ok(0) => Err("--max-memory must be more than 0".to_string()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("--max-memory: {e}")),
    }
}

/// Writes an image (format by extension), with the file name in any error.
pub(crate) fn save(image: &Image, path: &str, metadata: &ImageMetadata) -> Result<(), String> {
    image
        .write(Path::new(path), metadata)
        .map_err(|e| e.to_string())
}

fn find(name: &str) -> Option<&'static Command> {
    COMMANDS.iter().find(|c| c.name == name)
}

/// Runs `rpbrt imgtool <args>`.
pub fn run(args: &[String]) -> ExitCode {
    let Some(cmd) = args.first() else {
        diag!("{}", overview());
        return ExitCode::FAILURE;
    };
    let (rest, budget) = match take_max_memory(&args[1..]) {
        Ok(r) => r,
        Err(e) => {
            diagln!("rpbrt imgtool: error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let rest = &rest[..];
    let result = match cmd.as_str() {
        "help" | "--help" | "-h" => match rest.first() {
            None => emit(&overview()),
            Some(name) => match find(name) {
                Some(c) => emit(c.usage),
                None => Err(format!(
                    "unknown imgtool command \"{name}\"\n\n{}",
                    overview()
                )),
            },
        },
        name => match find(name) {
            Some(c) if rest.iter().any(|a| a == "--help" || a == "-h") => emit(c.usage),
            Some(c) => (c.run)(rest, &budget),
            None => Err(format!(
                "unknown imgtool command \"{name}\"\n\n{}",
                overview()
            )),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A command that printed its own verdict (pbrt-v4's diff).
        Err(e) if e.is_empty() => ExitCode::FAILURE,
        Err(e) => {
            diagln!("rpbrt imgtool: error: {e}");
            ExitCode::FAILURE
        }
    }
}
