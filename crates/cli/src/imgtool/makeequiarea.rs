//! `imgtool makeequiarea`: pbrt-v4's conversion of a latitude–longitude
//! (pbrt-v3) environment map to the equal-area square pbrt-v4 reads; the
//! resampling is `rpbrt_render::image::equiarea`'s, the one the infinite
//! light uses on pbrt-v3 maps.

use super::charge_output;
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::equiarea::equirect_to_equal_area;
use rpbrt_render::image::{Image, ImageMetadata};
use std::path::Path;

/// Usage of `imgtool makeequiarea`.
pub const USAGE: &str = "\
usage: rpbrt imgtool makeequiarea [options] <filename> [<outfile>]
    Convert an equirectangular (latitude-longitude) environment map, as
    pbrt-v3 used, to the equal-area parameterization pbrt-v4 uses, with
    pbrt-v3's orientation. Every channel is resampled (36 filtered lookups
    per output pixel); the output is float.
options:
    --outfile <name>   Output image filename (or give it after the input).
    --resolution <n>   Resolution of the square output image.
                       Default: the width of the input image.
";

/// Runs `imgtool makeequiarea`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut outfile: Option<String> = None;
    let mut infile: Option<String> = None;
    let mut resolution: Option<i32> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--outfile" | "-outfile" => {
                let v = args
                    .get(i + 1)
                    .ok_or("makeequiarea: --outfile needs a file")?;
                outfile = Some(v.clone());
                i += 2;
            }
            "--resolution" | "-resolution" => {
                let v = args
                    .get(i + 1)
                    .ok_or("makeequiarea: --resolution needs a number")?;
                let n: i32 = v
                    .parse()
                    .map_err(|_| format!("makeequiarea: --resolution \"{v}\" is not an integer"))?;
                if n < 1 {
                    return Err(format!("makeequiarea: --resolution {n} must be at least 1"));
                }
                resolution = Some(n);
                i += 2;
            }
            a if a.starts_with('-') && a.len() > 1 => {
                return Err(format!("makeequiarea: {a}: unknown command flag"))
            }
            a => {
                if infile.is_none() {
                    infile = Some(a.to_string());
                } else if outfile.is_none() {
                    outfile = Some(a.to_string());
                } else {
                    return Err(format!("makeequiarea: {a}: excess argument"));
                }
                i += 1;
            }
        }
    }
    let infile = infile.ok_or("makeequiarea: input image filename must be provided.")?;
    let outfile = outfile.ok_or("makeequiarea: output image filename must be provided.")?;
    let read = Image::read_within(Path::new(&infile), None, budget).map_err(|e| e.to_string())?;
    let res = read.image.resolution();
    if res.x != 2 * res.y {
        diagln!(
            "rpbrt imgtool: warning: {infile}: resolution ({}, {}) doesn't have a 2:1 aspect \
             ratio; it is doubtful that this is a latitude-longitude environment map",
            res.x,
            res.y
        );
    }
    let n = resolution.unwrap_or(res.x);
    let what = format!("the {n}x{n} output image");
    charge_output(budget, n.into(), n.into(), read.image.n_channels(), &what)
        .map_err(|e| format!("makeequiarea: {e}"))?;
    let out = equirect_to_equal_area(&read.image, n).map_err(|e| format!("{infile}: {e}"))?;
    let metadata = ImageMetadata {
        camera_from_world: read.metadata.camera_from_world,
        color_space: read.metadata.color_space.clone(),
        strings: read.metadata.strings.clone(),
        ..ImageMetadata::default()
    };
    out.write(Path::new(&outfile), &metadata)
        .map_err(|e| e.to_string())
}
