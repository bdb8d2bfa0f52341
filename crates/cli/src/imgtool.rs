//! `rpbrt imgtool`: image utilities like pbrt-v4's `imgtool` (diff, info,
//! convert). The numbers come from `rpbrt_render::image::ops`; this module
//! only parses arguments and prints.

use rpbrt_render::image::ops::{average, diff, info, worst_block, BLOCK_SIZE};
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
  average --outfile <file> <filename base>
      Average the images whose file names start with the base (in its folder,
      in name order): resolutions and channels must match; infinite values
      count as zero, a NaN is an error (pbrt-v4's average).
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
        "average" => cmd_average(rest),
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

/// The files whose names start with `base`'s file name, in its folder,
/// sorted by name (pbrt-v4's `MatchingFilenames`).
fn matching_filenames(base: &str) -> Result<Vec<std::path::PathBuf>, String> {
    let path = Path::new(base);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let prefix = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let entries = std::fs::read_dir(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut out: Vec<std::path::PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
        .map(|e| e.path())
        .collect();
    out.sort();
    Ok(out)
}

fn cmd_average(args: &[String]) -> Result<(), String> {
    let mut outfile: Option<String> = None;
    let mut base: Option<String> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--outfile" | "-outfile" => {
                outfile = Some(args.get(i + 1).ok_or("--outfile needs a file")?.clone());
                i += 2;
            }
            a if a.starts_with('-') => return Err(format!("average: {a}: unknown argument")),
            a => {
                if base.is_some() {
                    return Err(format!("average: {a}: excess argument"));
                }
                base = Some(a.to_string());
                i += 1;
            }
        }
    }
    let base = base.ok_or("average: must provide base filename.")?;
    let outfile = outfile.ok_or("average: must provide --outfile.")?;
    let out_path = Path::new(&outfile);
    let files: Vec<_> = matching_filenames(&base)?
        .into_iter()
        .filter(|f| f.as_path() != out_path)
        .collect();
    if files.is_empty() {
        return Err(format!("{base}: no matching filenames!"));
    }
    let mut images = Vec::with_capacity(files.len());
    for f in &files {
        images.push(load(&f.to_string_lossy())?);
    }
    let avg = average(&images).map_err(|e| match e {
        rpbrt_render::image::ImageError::Invalid(m) => {
            // Name the file the message's image index refers to.
            let idx = m
                .strip_prefix("image ")
                .and_then(|r| r.split(':').next())
                .and_then(|k| k.parse::<usize>().ok());
            match idx.and_then(|k| files.get(k)) {
                Some(f) => format!("{}{}", f.display(), &m[m.find(':').unwrap_or(0)..]),
                None => m,
            }
        }
        other => other.to_string(),
    })?;
    avg.write(out_path, &ImageMetadata::default())
        .map_err(|e| e.to_string())
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
