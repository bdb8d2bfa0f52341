//! `imgtool makesky`: pbrt-v4's Hosek–Wilkie sky environment map; the
//! model and the map are `rpbrt_render::image::sky`'s.

use super::charge_output;
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::sky::make_sky;
use std::path::Path;

/// Usage of `imgtool makesky`.
pub const USAGE: &str = "\
usage: rpbrt imgtool makesky [options] --outfile <filename>
    Generate an equal-area environment map (ACES2065-1 RGB, +z up, the sun
    toward +y) based on the Hosek-Wilkie sky model: sky and solar disc.
options:
    --albedo <a>       Albedo of ground-plane (range 0-1). Default: 0.5
    --elevation <e>    Elevation of the sun in degrees (range 0-90). Default: 10
    --outfile <name>   Filename to store environment map in.
    --turbidity <t>    Atmospheric turbidity (range 1.7-10). Default: 3
    --resolution <r>   Resolution of generated environment map. Default: 2048
";

fn number<T: std::str::FromStr>(args: &[String], i: usize, flag: &str) -> Result<T, String> {
    let v = args
        .get(i + 1)
        .ok_or_else(|| format!("makesky: {flag} needs a value"))?;
    v.parse()
        .map_err(|_| format!("makesky: {flag} \"{v}\" is not a number"))
}

/// Runs `imgtool makesky`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut outfile: Option<String> = None;
    let (mut albedo, mut turbidity, mut elevation) = (0.5f32, 3.0f32, 10.0f32);
    let mut resolution = 2048i32;
    let mut i = 0;
    while i < args.len() {
        let flag = args[i].trim_start_matches('-');
        match flag {
            "outfile" if args[i].starts_with('-') => {
                let v = args.get(i + 1).ok_or("makesky: --outfile needs a file")?;
                outfile = Some(v.clone());
            }
            "albedo" if args[i].starts_with('-') => albedo = number(args, i, "--albedo")?,
            "turbidity" if args[i].starts_with('-') => turbidity = number(args, i, "--turbidity")?,
            "elevation" if args[i].starts_with('-') => elevation = number(args, i, "--elevation")?,
            "resolution" if args[i].starts_with('-') => {
                resolution = number(args, i, "--resolution")?
            }
            _ if args[i].starts_with('-') => {
                return Err(format!("makesky: argument {} invalid", args[i]))
            }
            _ => {
                if outfile.is_some() {
                    return Err(format!("makesky: {}: excess argument", args[i]));
                }
                outfile = Some(args[i].clone());
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    let outfile = outfile.ok_or("makesky: --outfile must be specified")?;
    if resolution >= 1 {
        let what = format!("the {resolution}x{resolution} sky map");
        charge_output(budget, resolution.into(), resolution.into(), 3, &what)
            .map_err(|e| format!("makesky: {e}"))?;
    }
    let (image, metadata) =
        make_sky(albedo, elevation, turbidity, resolution).map_err(|e| format!("makesky: {e}"))?;
    image
        .write(Path::new(&outfile), &metadata)
        .map_err(|e| e.to_string())
}
