//! `imgtool scalenormalmap`: scale a normal map's slopes (pbrt-v4's
//! `scalenormalmap`).

use super::args::{Arg, Args};
use super::{load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::color::scale_normal_map;

/// Usage of `imgtool scalenormalmap`.
pub const USAGE: &str = "\
usage: rpbrt imgtool scalenormalmap [options] <filename>
    Scale the x and y of each normal in a normal map (R, G, B = (n + 1) / 2)
    and renormalise z.
options:
    --outfile <name>   Output image filename (required).
    --scale <s>        Scale factor. Default: 1
";

/// Runs `imgtool scalenormalmap`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("scalenormalmap", argv);
    let (mut infile, mut outfile, mut scale) = (None, None, 1.0f32);
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "scale" => scale = a.f32(&f)?,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: excess argument"))),
        }
    }
    let infile = infile.ok_or_else(|| a.err("must provide an input filename"))?;
    let outfile = outfile.ok_or_else(|| a.err("must provide --outfile"))?;
    let im = load_md(&infile, budget)?;
    let out = scale_normal_map(&im.image, scale).map_err(|e| a.err(format!("{infile}: {e}")))?;
    save(&out, &outfile, &im.metadata)
}
