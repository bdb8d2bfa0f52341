//! `rpbrt imgtool`: image utilities like pbrt-v4's `imgtool`. One file per
//! command, each with its `USAGE` and `run`; the numbers come from
//! `rpbrt_render::image::ops`, these modules only parse arguments and print.

use rpbrt_render::image::Image;
use std::path::Path;
use std::process::ExitCode;

mod assemble;
mod average;
mod convert;
mod diff;
mod info;
mod makeequiarea;
mod makesky;
mod merge;

/// A command: its name, one-line summary, usage text and entry point.
struct Command {
    name: &'static str,
    summary: &'static str,
    usage: &'static str,
    run: fn(&[String]) -> Result<(), String>,
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
        name: "convert",
        summary: "convert an image's format, exposure, orientation",
        usage: convert::USAGE,
        run: convert::run,
    },
    Command {
        name: "diff",
        summary: "compare an image with a reference",
        usage: diff::USAGE,
        run: diff::run,
    },
    Command {
        name: "info",
        summary: "print resolution, channels and statistics",
        usage: info::USAGE,
        run: info::run,
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
];

/// The overview printed by `rpbrt imgtool help`.
fn overview() -> String {
    let mut s = String::from("usage: rpbrt imgtool <command> [options] <files...>\n\ncommands:\n");
    for c in COMMANDS {
        s += &format!("  {:<16}{}\n", c.name, c.summary);
    }
    s += "\nrpbrt imgtool help <command> (or <command> --help) prints a command's usage.\n";
    s
}

/// Reads an image, with the file name in any error.
pub(crate) fn load(path: &str) -> Result<Image, String> {
    Image::read(Path::new(path), None)
        .map(|im| im.image)
        .map_err(|e| e.to_string())
}

fn find(name: &str) -> Option<&'static Command> {
    COMMANDS.iter().find(|c| c.name == name)
}

/// Runs `rpbrt imgtool <args>`.
pub fn run(args: &[String]) -> ExitCode {
    let Some(cmd) = args.first() else {
        eprint!("{}", overview());
        return ExitCode::FAILURE;
    };
    let rest = &args[1..];
    let result = match cmd.as_str() {
        "help" | "--help" | "-h" => match rest.first() {
            None => {
                print!("{}", overview());
                Ok(())
            }
            Some(name) => match find(name) {
                Some(c) => {
                    print!("{}", c.usage);
                    Ok(())
                }
                None => Err(format!(
                    "unknown imgtool command \"{name}\"\n\n{}",
                    overview()
                )),
            },
        },
        name => match find(name) {
            Some(c) if rest.iter().any(|a| a == "--help" || a == "-h") => {
                print!("{}", c.usage);
                Ok(())
            }
            Some(c) => (c.run)(rest),
            None => Err(format!(
                "unknown imgtool command \"{name}\"\n\n{}",
                overview()
            )),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rpbrt imgtool: error: {e}");
            ExitCode::FAILURE
        }
    }
}
