//! `imgtool makeemitters`: scene text with a quad emitter per pixel
//! (pbrt-v4's `makeemitters`).

use super::args::{Arg, Args};
use super::{emit, load};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::compose::make_emitters;

/// Usage of `imgtool makeemitters`.
pub const USAGE: &str = "\
usage: rpbrt imgtool makeemitters [options] <filename>
    Print scene text with a small quadrilateral diffuse emitter for every
    pixel (the image spans y in [0,1] and x over its aspect ratio, at z = 0).
options:
    --downsample <n>   One emitter per n x n pixels, their mean. Default: 1
";

/// Runs `imgtool makeemitters`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("makeemitters", argv);
    let (mut infile, mut rate) = (None, 1);
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "downsample" => rate = a.i32(&f)?,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(_) => return Err(a.err("multiple input filenames provided")),
        }
    }
    let infile = infile.ok_or_else(|| a.err("missing image filename"))?;
    let image = load(&infile, budget)?;
    let emitters = make_emitters(&image, rate).map_err(|e| a.err(format!("{infile}: {e}")))?;
    let mut out =
        String::from("AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n");
    for e in emitters {
        out += &format!(
            "AreaLightSource \"diffuse\" \"rgb L\" [ {:.6} {:.6} {:.6} ]\n",
            e.rgb[0], e.rgb[1], e.rgb[2]
        );
        let c = e.corners;
        out += &format!(
            "Shape \"bilinearmesh\" \"point3 P\" [ {:.6} {:.6} 0 {:.6} {:.6} 0 {:.6} {:.6} 0 {:.6} {:.6} 0 ]\n",
            c[0][0], c[0][1], c[1][0], c[1][1], c[2][0], c[2][1], c[3][0], c[3][1]
        );
    }
    out += "AttributeEnd\n";
    emit(&out)
}
