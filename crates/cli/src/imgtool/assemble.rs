//! `imgtool assemble`: join crops (tiles) of one image into the whole.

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
pub(crate) fn load_with_metadata(path: &str) -> Result<(Image, ImageMetadata), String> {
    Image::read(Path::new(path), None)
        .map(|im| (im.image, im.metadata))
        .map_err(|e| e.to_string())
}

/// The `--outfile` value and the other arguments.
pub(crate) fn outfile_and_files(
    cmd: &str,
    args: &[String],
) -> Result<(String, Vec<String>), String> {
    let mut outfile = None;
    let mut files = Vec::new();
    let mut i = 0;
    while i < args.len() {
        let a = args[i].as_str();
        if let Some(v) = a
            .strip_prefix("--outfile=")
            .or_else(|| a.strip_prefix("-outfile="))
        {
            outfile = Some(v.to_string());
            i += 1;
        } else if a == "--outfile" || a == "-outfile" {
            outfile = Some(args.get(i + 1).ok_or("--outfile needs a file")?.clone());
            i += 2;
        } else if a.starts_with('-') {
            return Err(format!("{cmd}: {a}: unknown argument"));
        } else {
            files.push(a.to_string());
            i += 1;
        }
    }
    let outfile = outfile.ok_or(format!("{cmd}: must provide --outfile."))?;
    if files.is_empty() {
        return Err(format!("{cmd}: no input images."));
    }
    Ok((outfile, files))
}

/// Runs `imgtool assemble`.
pub fn run(args: &[String]) -> Result<(), String> {
    let (outfile, files) = outfile_and_files("assemble", args)?;
    let loaded = files
        .iter()
        .map(|f| load_with_metadata(f))
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
