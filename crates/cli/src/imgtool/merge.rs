//! `imgtool merge`: join sample ranges of the same pixels into one image.

use super::assemble::{load_with_metadata, outfile_and_files};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::film::merge_sample_ranges;
use std::path::Path;

/// Usage of `imgtool merge`.
pub const USAGE: &str = "\
usage: rpbrt imgtool merge --outfile <file> <images...>
    Join renders of sample ranges of the same pixels (rpbrt --spp-range A..B) into
    the image one render of all their samples writes: their per-pixel sums are
    added and divided as the film does, so ranges covering 0..spp give the full
    render's pixels. Overlapping ranges, different pixels or films are errors;
    ranges with gaps merge into the image of the samples present (with a warning).
";

/// Runs `imgtool merge`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let (outfile, files) = outfile_and_files("merge", args)?;
    let loaded = files
        .iter()
        .map(|f| load_with_metadata(f, budget))
        .collect::<Result<Vec<_>, _>>()?;
    let parts: Vec<_> = files
        .iter()
        .zip(&loaded)
        .map(|(f, (im, md))| (f.as_str(), im, md))
        .collect();
    let (image, md, covered) = merge_sample_ranges(&parts).map_err(|e| e.to_string())?;
    let total = loaded
        .first()
        .and_then(|(_, md)| md.strings.get(rpbrt_render::film::SAMPLE_RANGE_KEY))
        .and_then(|v| v.get(2))
        .and_then(|s| s.parse::<i32>().ok());
    if let Some(total) = total.filter(|t| *t != covered) {
        diagln!(
            "rpbrt imgtool: warning: merge: the ranges hold {covered} of the render's {total} samples per pixel"
        );
    }
    image
        .write(Path::new(&outfile), &md)
        .map_err(|e| e.to_string())
}
