//! `imgtool assemble`: join crops (tiles) of one image into the whole.

use super::args::{Arg, Args};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::assemble::assemble;
use rpbrt_render::image::{Image, ImageMetadata};
use std::path::Path;

/// Usage of `imgtool assemble`.
pub const USAGE: &str = "\
usage: rpbrt imgtool assemble --outfile <file> <images...>
    Join crops of one image (rendered with --tile, --cropwindow or --pixelbounds)
    into the full image, placing each by its EXR data window. The crops must
    cover every pixel exactly once, with the same full resolution and channels;
    overlaps, gaps and mismatches are errors (pbrt-v4's assemble).
";

/// Reads an image with its metadata.
pub(crate) fn load_with_metadata(
    path: &str,
    budget: &MemoryBudget,
) -> Result<(Image, ImageMetadata), String> {
    Image::read_within(Path::new(path), None, budget)
        .map(|im| (im.image, im.metadata))
        .map_err(|e| e.to_string())
}

/// The `--outfile` value and the input files of `assemble` / `merge`.
pub(crate) fn outfile_and_files(
    cmd: &'static str,
    args: &[String],
) -> Result<(String, Vec<String>), String> {
    let mut a = Args::new(cmd, args);
    let mut outfile = None;
    let mut files = Vec::new();
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) if f == "outfile" => outfile = Some(a.value(&f)?),
            Arg::Flag(f) => return Err(a.unknown(&f)),
            Arg::Positional(p) => files.push(p),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("must provide --outfile."))?;
    if files.is_empty() {
        return Err(a.err("no input images."));
    }
    Ok((outfile, files))
}

/// Runs `imgtool assemble`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let (outfile, files) = outfile_and_files("assemble", args)?;
    let loaded = files
        .iter()
        .map(|f| load_with_metadata(f, budget))
        .collect::<Result<Vec<_>, _>>()?;
    let parts: Vec<_> = files
        .iter()
        .zip(&loaded)
        .map(|(f, (im, md))| (f.as_str(), im, md))
        .collect();
    let (image, md) = assemble(&parts).map_err(|e| e.to_string())?;
    image
        .write(Path::new(&outfile), &md)
        .map_err(|e| e.to_string())
}
