//! `imgtool convert`: change an image's format, exposure and orientation.

use super::load;
use rpbrt_render::image::ImageMetadata;
use std::path::Path;

/// Usage of `imgtool convert`.
pub const USAGE: &str = "\
usage: rpbrt imgtool convert [--exposure <stops>] [--clamp <max>] [--flipy] <input> <output>
    Convert between formats (by extension: exr, pfm, png, qoi; reads also tga, hdr).
";

/// Runs `imgtool convert`.
pub fn run(args: &[String]) -> Result<(), String> {
    let mut exposure = 0.0f32;
    let mut clamp: Option<f32> = None;
    let mut flip = false;
    let mut files = Vec::new();
    let mut i = 0;
    let num = |v: Option<&String>, flag: &str| -> Result<f32, String> {
        v.ok_or(format!("{flag} needs a value"))?
            .parse::<f32>()
            .map_err(|_| format!("{flag}: not a number"))
    };
    while i < args.len() {
        match args[i].as_str() {
            "--exposure" => {
                exposure = num(args.get(i + 1), "--exposure")?;
                i += 2;
            }
            "--clamp" => {
                clamp = Some(num(args.get(i + 1), "--clamp")?);
                i += 2;
            }
            "--flipy" => {
                flip = true;
                i += 1;
            }
            f => {
                files.push(f.to_string());
                i += 1;
            }
        }
    }
    let [input, output] = files.as_slice() else {
        return Err("convert needs an input and an output file".into());
    };
    let mut im = load(input)?;
    if exposure != 0.0 {
        im = im.apply_exposure(exposure);
    }
    if let Some(c) = clamp {
        im = im.clamp_values(0.0, c);
    }
    if flip {
        im.flip_y();
    }
    im.write(Path::new(output), &ImageMetadata::default())
        .map_err(|e| e.to_string())
}
