//! `imgtool falsecolor`: colour pixels by magnitude (pbrt-v4's
//! `falsecolor`).

use super::args::{Arg, Args};
use super::{load, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::falsecolor::{false_color, ramp_image};
use rpbrt_render::image::ImageMetadata;

/// Usage of `imgtool falsecolor`.
pub const USAGE: &str = "\
usage: rpbrt imgtool falsecolor [options] <filename>
    Write an image colouring each pixel by its channel average through the
    viridis colour map (R, G, B, half float).
options:
    --maxvalue <v>     Value given the map's last colour. Default: the
                       largest |channel average| in the image.
    --outfile <name>   Output image filename (required).
    --plusminus        Show positive values green and negative ones red.
    --ramp             Colour a 10x300 ramp from 1 (top) to 0 instead of
                       an image.
";

/// Runs `imgtool falsecolor`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("falsecolor", argv);
    let (mut infile, mut outfile, mut max_value) = (None, None, None);
    let (mut plus_minus, mut ramp) = (false, false);
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.to_ascii_lowercase().as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "maxvalue" => max_value = Some(a.f32(&f)?),
                "plusminus" => plus_minus = a.bool(&f)?,
                "ramp" => ramp = a.bool(&f)?,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: excess argument"))),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("expecting --outfile filename"))?;
    let image = if ramp {
        ramp_image()
    } else {
        let infile = infile.ok_or_else(|| a.err("expecting input image filename"))?;
        load(&infile, budget)?
    };
    save(
        &false_color(&image, max_value, plus_minus),
        &outfile,
        &ImageMetadata::default(),
    )
}
