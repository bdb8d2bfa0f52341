//! `imgtool convert`: pbrt-v4's `convert`, plus rpbrt's `--exposure`,
//! `--fp16` and an output file given as a second name.

use super::args::{crop, Arg, Args};
use super::{charge_output, load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::convert::{convert, ConvertOptions};
use rpbrt_render::image::ops::split_channel_list;
use std::path::Path;

/// Usage of `imgtool convert`.
pub const USAGE: &str = "\
usage: rpbrt imgtool convert [options] <input> [<output>]
    Convert an image, possibly between formats (by extension: exr, pfm,
    png, qoi; reads also tga, hdr), processing it on the way in this order:
    channels, crop, clamp, colorspace, bw, despike, scale/exposure, gamma,
    tonemap, preservecolors, acesfilmic, repeatpix, flipy, fp16.
options:
    --acesfilmic       Map values to [0,1] with the ACES filmic curve.
    --bw               Set every channel to the pixel's channel average.
    --channels <names> Keep these comma-separated channels. Default: all
                       (only R,G,B when writing a format without AOVs).
    --clamp <v>        Rescale pixels whose largest channel exceeds <v>.
    --colorspace <n>   Convert R,G,B to ACES2065-1, Rec2020, DCI-P3 or sRGB.
    --crop <x0,x1,y0,y1> Keep [x0,x1) x [y0,y1) (full-image coordinates;
                       a negative x1 or y1 is a size).
    --despike <v>      Replace pixels whose channel average is at least <v>
                       by their 3x3 neighbourhood's median (alias --despeckle).
    --exposure <stops> Scale by 2^stops (with --scale).
    --flipy            Flip the image top to bottom.
    --fp16             Store half floats (EXR).
    --gamma <v>        Raise values to the power <v>. Default: 1
    --maxluminance <n> Luminance --tonemap maps to white. Default: 1
    --outfile <name>   Output image filename (or give it after the input).
    --preservecolors   Divide pixels with a channel above 1 by their largest.
    --repeatpix <n>    Repeat each pixel n times in x and y.
    --scale <s>        Scale values by <s>.
    --tonemap          Reinhard et al.'s photographic tone mapping.
";

/// Runs `imgtool convert`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("convert", argv);
    let mut o = ConvertOptions::default();
    let mut exposure = 0.0f32;
    let (mut outfile, mut channels) = (None, None);
    let mut files = Vec::new();
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.to_ascii_lowercase().as_str() {
                "acesfilmic" | "aces-filmic" => o.aces_filmic = a.bool(&f)?,
                "bw" => o.bw = a.bool(&f)?,
                "channels" => channels = Some(a.value(&f)?),
                "clamp" => o.clamp = a.f32(&f)?,
                "colorspace" => o.color_space = Some(a.value(&f)?),
                "crop" => o.crop = crop(&mut a, &f)?,
                "despike" | "despeckle" => o.despike = a.f32(&f)?,
                "exposure" => exposure = a.f32(&f)?,
                "flipy" => o.flip_y = a.bool(&f)?,
                "fp16" => o.fp16 = a.bool(&f)?,
                "gamma" => o.gamma = a.f32(&f)?,
                "maxluminance" => o.max_luminance = a.f32(&f)?,
                "outfile" => outfile = Some(a.value(&f)?),
                "preservecolors" => o.preserve_colors = a.bool(&f)?,
                "repeatpix" => o.repeat = a.i32(&f)?,
                "scale" => o.scale = a.f32(&f)?,
                "tonemap" => o.tonemap = a.bool(&f)?,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) => files.push(p),
        }
    }
    let (input, output) = match (files.as_slice(), outfile) {
        ([i], Some(o)) => (i.clone(), o),
        ([i, o], None) => (i.clone(), o.clone()),
        ([], _) => return Err(a.err("input filename not specified")),
        ([_], None) => return Err(a.err("--outfile filename must be specified")),
        _ => return Err(a.err(format!("{}: excess argument", files[files.len() - 1]))),
    };
    if !exposure.is_finite() {
        return Err(a.err("--exposure must be finite"));
    }
    o.scale *= exposure.exp2();
    let im = load_md(&input, budget)?;
    if o.repeat > 1 {
        // The output's size before it is made (crops come first and only
        // shrink it, so the input's size bounds it).
        let res = im.image.resolution();
        let (w, h) = (i64::from(res.x), i64::from(res.y));
        let r = i64::from(o.repeat);
        let what = format!(
            "--repeatpix {}: the {}x{} output image",
            o.repeat,
            w * r,
            h * r
        );
        charge_output(budget, w * r, h * r, im.image.n_channels(), &what).map_err(|e| a.err(e))?;
    }
    if let Some(spec) = channels {
        o.channels = Some(split_channel_list(&spec, im.image.channel_names()));
    }
    let to_exr = Path::new(&output)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let c =
        convert(&im.image, &im.metadata, &o, to_exr).map_err(|e| a.err(format!("{input}: {e}")))?;
    for w in &c.warnings {
        diagln!("rpbrt imgtool convert: warning: {input}: {w}");
    }
    if o.despike < f32::INFINITY {
        diagln!("{input}: despiked {} pixels", c.despiked);
    }
    save(&c.image, &output, &c.metadata)
}
