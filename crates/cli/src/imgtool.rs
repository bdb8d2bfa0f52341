//! `rpbrt imgtool`: image utilities like pbrt-v4's `imgtool` (diff, info,
//! convert). The numbers come from `rpbrt_render::image::ops`; this module
//! only parses arguments and prints.

use rpbrt_render::image::ops::{diff, info, worst_block, BLOCK_SIZE};
use rpbrt_render::image::{Image, ImageMetadata};
use std::path::Path;
use std::process::ExitCode;

/// Usage text of `rpbrt imgtool`.
pub const USAGE: &str = "\
usage: rpbrt imgtool <command> [options] <files...>

commands:
  diff [--reference <ref>] <image> [<ref>]
      Compare an image with a reference: MSE, relative MSE ((a-b)^2/(b^2+0.01)),
      relative MSE with the worst 0.1% of pixels dropped, means (also with both images
      clamped at the reference's 99.9th-percentile value), and NaN/Inf counts.
  info <images...>
      Resolution, channels, per-channel min/max/average, NaN and Inf counts.
  convert [--exposure <stops>] [--clamp <max>] [--flipy] <input> <output>
      Convert between formats (by extension: exr, pfm, png, qoi; reads also tga, hdr).
";

fn load(path: &str) -> Result<Image, String> {
    Image::read(Path::new(path), None)
        .map(|im| im.image)
        .map_err(|e| e.to_string())
}

/// Runs `rpbrt imgtool <args>`.
pub fn run(args: &[String]) -> ExitCode {
    let Some(cmd) = args.first() else {
        eprint!("{USAGE}");
        return ExitCode::FAILURE;
    };
    let rest = &args[1..];
    let result = match cmd.as_str() {
        "diff" => cmd_diff(rest),
        "info" => cmd_info(rest),
        "convert" => cmd_convert(rest),
        "help" | "--help" | "-h" => {
            print!("{USAGE}");
            Ok(())
        }
        other => Err(format!("unknown imgtool command \"{other}\"\n\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rpbrt imgtool: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn cmd_diff(args: &[String]) -> Result<(), String> {
    let mut reference: Option<String> = None;
    let mut files = Vec::new();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--reference" | "-reference" => {
                reference = Some(args.get(i + 1).ok_or("--reference needs a file")?.clone());
                i += 2;
            }
            f => {
                files.push(f.to_string());
                i += 1;
            }
        }
    }
    let (image, reference) = match (files.as_slice(), reference) {
        ([a], Some(r)) => (a.clone(), r),
        ([a, r], None) => (a.clone(), r.clone()),
        _ => return Err("diff needs an image and a reference".into()),
    };
    let a = load(&image)?;
    let b = load(&reference)?;
    let s = diff(&a, &b).map_err(|e| e.to_string())?;
    println!("channels: {}", s.channels.join(","));
    println!("MSE: {:.6e}", s.mse);
    println!("relative MSE: {:.6e}", s.rel_mse);
    println!(
        "relative MSE (worst 0.1% dropped): {:.6e}",
        s.rel_mse_trimmed
    );
    println!(
        "mean: {:.6} (reference {:.6}, ratio {:.4})",
        s.mean_a,
        s.mean_b,
        if s.mean_b != 0.0 {
            s.mean_a / s.mean_b
        } else {
            f64::NAN
        }
    );
    println!(
        "mean clamped at the reference's 99.9th percentile ({:.6}): {:.6} (reference {:.6}, ratio {:.4})",
        s.clamp_value,
        s.clamped_mean_a,
        s.clamped_mean_b,
        if s.clamped_mean_b != 0.0 {
            s.clamped_mean_a / s.clamped_mean_b
        } else {
            f64::NAN
        }
    );
    println!(
        "median pixel brightness: {:.6} (reference {:.6}, ratio {:.4})",
        s.median_a,
        s.median_b,
        if s.median_b != 0.0 {
            s.median_a / s.median_b
        } else {
            f64::NAN
        }
    );
    if let Some(w) = worst_block(&a, &b, BLOCK_SIZE).map_err(|e| e.to_string())? {
        println!(
            "worst {BLOCK_SIZE}x{BLOCK_SIZE} block: z {:.2} (mean ratio {:.4}, block at {}, {})",
            w.z, w.ratio, w.at.x, w.at.y
        );
    }
    println!("max |difference|: {:.6e}", s.max_abs_diff);
    println!("differing pixels: {}", s.differing_pixels);
    println!("non-finite terms: {}", s.non_finite);
    Ok(())
}

fn cmd_info(args: &[String]) -> Result<(), String> {
    if args.is_empty() {
        return Err("info needs at least one image".into());
    }
    for f in args {
        let im = load(f)?;
        println!("{f}:");
        println!("{}", info(&im));
    }
    Ok(())
}

fn cmd_convert(args: &[String]) -> Result<(), String> {
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
