//! `imgtool whitebalance`: white balance an image (pbrt-v4's
//! `whitebalance`).

use super::args::{Arg, Args};
use super::{load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::color::{illuminant_white, temperature_white, white_balance_image};

/// Usage of `imgtool whitebalance`.
pub const USAGE: &str = "\
usage: rpbrt imgtool whitebalance [options] <filename>
    Adapt the image's R, G, B from a given white to its colour space's
    white (von Kries in Bradford LMS). Give exactly one of the white's
    sources.
options:
    --illuminant <n>   A standard illuminant's white (D65, D50, A, F1..F12, ...).
    --outfile <name>   Output image filename (required).
    --primaries <x,y>  The white's chromaticity x,y.
    --temperature <T>  CIE daylight (blackbody below 4000 K) of T kelvin.
";

/// Runs `imgtool whitebalance`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("whitebalance", argv);
    let (mut infile, mut outfile, mut illuminant) = (None, None, None::<String>);
    let (mut temperature, mut xy) = (0.0f32, None::<[f32; 2]>);
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "illuminant" => illuminant = Some(a.value(&f)?),
                "temperature" => temperature = a.f32(&f)?,
                "primaries" => {
                    let v = a.floats(&f, 2)?;
                    xy = Some([v[0], v[1]]);
                }
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: excess argument"))),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("--outfile must be specified"))?;
    let infile = infile.ok_or_else(|| a.err("input filename must be specified"))?;
    let given = illuminant.is_some() as u8 + (temperature > 0.0) as u8 + xy.is_some() as u8;
    if given > 1 {
        return Err(a.err("can only provide one of --illuminant, --primaries, --temperature"));
    }
    let src = if let Some(name) = &illuminant {
        illuminant_white(name)
            .ok_or_else(|| a.err(format!("stdillum-{name}: illuminant unknown")))?
    } else if temperature > 0.0 {
        temperature_white(temperature)
    } else if let Some(xy) = xy {
        xy
    } else {
        return Err(a.err("must provide one of --illuminant, --primaries, or --temperature"));
    };
    let im = load_md(&infile, budget)?;
    let out = white_balance_image(&im.image, &im.metadata, src)
        .map_err(|e| a.err(format!("{infile}: {e}")))?;
    save(&out, &outfile, &im.metadata)
}
