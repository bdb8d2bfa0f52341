//! `imgtool bloom`: pbrt-v4's bloom around pixels above a threshold.

use super::args::{Arg, Args};
use super::{load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::filter::bloom;

/// Usage of `imgtool bloom`.
pub const USAGE: &str = "\
usage: rpbrt imgtool bloom [options] <filename>
    Blur the pixels brighter than a threshold and add the blur back, so
    bright pixels glow (pbrt-v4's bloom).
options:
    --iterations <n>   Blur passes whose results are summed. Default: 5
    --level <v>        A pixel contributes when any channel exceeds <v>.
                       Default: infinity (no pixel does: an error)
    --outfile <name>   Output image filename (required).
    --scale <s>        Weight of the summed blurs. Default: 0.3
    --width <w>        Gaussian width in pixels (made odd). Default: 15
";

/// Runs `imgtool bloom`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("bloom", argv);
    let (mut level, mut width, mut iterations, mut scale) = (f32::INFINITY, 15, 5, 0.3f32);
    let (mut infile, mut outfile) = (None, None);
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "level" => level = a.f32(&f)?,
                "width" => width = a.i32(&f)?,
                "iterations" => iterations = a.i32(&f)?,
                "scale" => scale = a.f32(&f)?,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: excess argument"))),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("--outfile must be specified"))?;
    let infile = infile.ok_or_else(|| a.err("input filename must be specified"))?;
    let im = load_md(&infile, budget)?;
    let b = bloom(&im.image, level, width, iterations, scale)
        .map_err(|e| a.err(format!("{infile}: {e}")))?;
    if b.width != width {
        diagln!(
            "rpbrt imgtool bloom: warning: bloom width must be odd; using {}",
            b.width
        );
    }
    save(&b.image, &outfile, &im.metadata)
}
