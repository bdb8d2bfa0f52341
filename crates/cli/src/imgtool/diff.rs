//! `imgtool diff`: compare an image with a reference.

use super::load;
use rpbrt_render::image::ops::{diff, worst_block, BLOCK_SIZE};

/// Usage of `imgtool diff`.
pub const USAGE: &str = "\
usage: rpbrt imgtool diff [--reference <ref>] <image> [<ref>]
    Compare an image with a reference: MSE, relative MSE ((a-b)^2/(b^2+0.01)),
    relative MSE with the worst 0.1% of pixels dropped, means (also with both images
    clamped at the reference's 99.9th-percentile value), the median pixel brightness,
    the worst 16x16 block's z-score, and NaN/Inf counts.
";

/// Runs `imgtool diff`.
pub fn run(args: &[String]) -> Result<(), String> {
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
