//! `imgtool diff`: compare an image with a reference. By default rpbrt's
//! report (which CI scripts parse); `--metric` or `--difftol` switch to
//! pbrt-v4's behaviour: silent and status 0 when the images are equal,
//! otherwise a summary and status 1.

use super::args::{crop, Arg, Args};
use super::{emit, load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::flip::{flip, FlipOptions};
use rpbrt_render::image::ops::metrics::{metric_error, zero_infinities, Metric};
use rpbrt_render::image::ops::{diff, split_channel_list, worst_block, BLOCK_SIZE};
use rpbrt_render::image::{Image, ImageAndMetadata};
use std::fmt::Write as _;

/// Usage of `imgtool diff`.
pub const USAGE: &str = "\
usage: rpbrt imgtool diff [options] <image> [<reference>]
    Compare an image with a reference. Without --metric or --difftol,
    print rpbrt's report: MSE, relative MSE ((a-b)^2/(b^2+0.01)), relative
    MSE with the worst 0.1% of pixels dropped, means (also with both images
    clamped at the reference's 99.9th-percentile value), the median pixel
    brightness, the worst 16x16 block's z-score, and NaN/Inf counts.
    With them, as pbrt-v4: infinite values are zeroed, nothing is printed
    and the status is 0 when the images are equal, otherwise the averages,
    their difference in percent and the error are printed, status 1.
options:
    --channels <names> Comma-separated channels to compare. Default: the
                       image's channels.
    --crop <x0,x1,y0,y1> Crop both images first (a negative x1 or y1 is a size).
    --difftol <v>      Report a difference only when the averages differ by
                       more than <v> percent (0: any difference). Default: 0
    --metric <name>    MSE, MAE, MRSE ((a-b)^2/(b+0.01)^2) or FLIP (NVIDIA's
                       LDR FLIP as pbrt-v4 computes it: 3-channel images,
                       values clamped to [0,1] and taken as sRGB-encoded,
                       67 pixels per degree; the mean over pixels).
                       Default: MSE
    --outfile <name>   Write the image of per-pixel error terms (FLIP: one
                       channel named Error).
    --reference <name> The reference image (or give it second).
";

fn select(im: &ImageAndMetadata, file: &str, chans: &[String]) -> Result<Image, String> {
    let desc = im.image.get_channel_desc(chans).ok_or_else(|| {
        format!(
            "diff: {file}: image does not have \"{}\" channels (it has {})",
            chans.join(","),
            im.image.channel_names().join(",")
        )
    })?;
    Ok(im.image.select_channels(&desc))
}

/// Runs `imgtool diff`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("diff", argv);
    let (mut reference, mut outfile, mut channels, mut window) = (None, None, None, None);
    let (mut metric, mut difftol) = (None, None);
    let mut files = Vec::new();
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "reference" => reference = Some(a.value(&f)?),
                "outfile" => outfile = Some(a.value(&f)?),
                "channels" => channels = Some(a.value(&f)?),
                "crop" => window = crop(&mut a, &f)?,
                "metric" => {
                    let v = a.value(&f)?;
                    metric = Some(if v.eq_ignore_ascii_case("FLIP") {
                        DiffMetric::Flip
                    } else {
                        DiffMetric::Pixel(Metric::parse(&v).ok_or_else(|| {
                            a.err(format!(
                                "{v}: --metric must be \"MAE\", \"MSE\", \"MRSE\", or \"FLIP\""
                            ))
                        })?)
                    });
                }
                "difftol" => difftol = Some(a.f32(&f)?),
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) => files.push(p),
        }
    }
    let (image_file, ref_file) = match (files.as_slice(), reference) {
        ([i], Some(r)) => (i.clone(), r),
        ([i, r], None) => (i.clone(), r.clone()),
        ([], _) => return Err(a.err("must specify the image to compare")),
        ([_], None) => return Err(a.err("must specify --reference image")),
        _ => return Err(a.err(format!("{}: excess argument", files[files.len() - 1]))),
    };
    let im = load_md(&image_file, budget)?;
    let rf = load_md(&ref_file, budget)?;
    let chans = match channels {
        Some(spec) => split_channel_list(&spec, im.image.channel_names()),
        None => im.image.channel_names().to_vec(),
    };
    let mut image = select(&im, &image_file, &chans)?;
    let mut refim = select(&rf, &ref_file, &chans)?;
    if let Some(w) = window {
        image = image
            .crop(w)
            .map_err(|e| a.err(format!("{image_file}: {e}")))?;
        refim = refim
            .crop(w)
            .map_err(|e| a.err(format!("{ref_file}: {e}")))?;
    }
    let (ra, rb) = (image.resolution(), refim.resolution());
    if ra != rb {
        return Err(a.err(format!(
            "{image_file}: image resolution ({}, {}) doesn't match \"{ref_file}\" ({}, {})",
            ra.x, ra.y, rb.x, rb.y
        )));
    }
    if im.metadata.color_space_name() != rf.metadata.color_space_name() {
        return Err(a.err(format!(
            "{image_file}: color space {} does not match \"{ref_file}\" ({})",
            im.metadata.color_space_name(),
            rf.metadata.color_space_name()
        )));
    }
    if metric.is_none() && difftol.is_none() {
        report(&image, &refim)?;
        if let Some(out) = outfile {
            let e = metric_error(&image, &refim, Metric::Mse).map_err(|e| a.err(e))?;
            save(&e.image, &out, &im.metadata)?;
        }
        return Ok(());
    }
    let metric = metric.unwrap_or(DiffMetric::Pixel(Metric::Mse));
    let tol = difftol.unwrap_or(0.0);
    let n = zero_infinities(&mut image);
    if n > 0 {
        diagln!("rpbrt imgtool diff: warning: {image_file}: clamped {n} infinite pixel values.");
    }
    let n = zero_infinities(&mut refim);
    if n > 0 {
        diagln!("rpbrt imgtool diff: warning: {ref_file}: clamped {n} infinite pixel values.");
    }
    let avg = |im: &Image| {
        let v = im.to_f32_vec();
        v.iter().map(|&x| x as f64).sum::<f64>() / v.len().max(1) as f64
    };
    let (ia, ra) = (avg(&image), avg(&refim));
    let (error_image, error, max_error, name) = match metric {
        DiffMetric::Pixel(m) => {
            let e = metric_error(&image, &refim, m).map_err(|e| a.err(e))?;
            let (avg, max) = (e.average(), e.max());
            (e.image, avg, max, m.name())
        }
        DiffMetric::Flip => {
            let e = flip(&image, &refim, FlipOptions::default())
                .map_err(|e| a.err(format!("{ref_file}: {e}")))?;
            (e.image, e.mean, e.mean, "FLIP")
        }
    };
    if let Some(out) = &outfile {
        save(&error_image, out, &im.metadata)?;
    }
    if max_error == 0.0 {
        return Ok(());
    }
    let delta = 100.0 * (ia - ra) / ra;
    if tol > 0.0 && delta.abs() <= tol as f64 {
        return Ok(());
    }
    emit(&format!(
        "Images differ:\n\t{image_file} {ref_file}\n\tavg = {ia:.6} / {ra:.6} ({delta:.6}% delta), {name} = {error:.6}\n"
    ))?;
    Err(String::new())
}

/// What `--metric` asks for.
#[derive(Clone, Copy)]
enum DiffMetric {
    /// A per-value metric (MSE, MAE, MRSE).
    Pixel(Metric),
    /// NVIDIA's FLIP.
    Flip,
}

/// Prints rpbrt's default report.
fn report(a: &Image, b: &Image) -> Result<(), String> {
    let mut o = String::new();
    let s = diff(a, b).map_err(|e| format!("diff: {e}"))?;
    let ratio = |x: f64, y: f64| if y != 0.0 { x / y } else { f64::NAN };
    let _ = writeln!(o, "channels: {}", s.channels.join(","));
    let _ = writeln!(o, "MSE: {:.6e}", s.mse);
    let _ = writeln!(o, "relative MSE: {:.6e}", s.rel_mse);
    let _ = writeln!(
        o,
        "relative MSE (worst 0.1% dropped): {:.6e}",
        s.rel_mse_trimmed
    );
    let _ = writeln!(
        o,
        "mean: {:.6} (reference {:.6}, ratio {:.4})",
        s.mean_a,
        s.mean_b,
        ratio(s.mean_a, s.mean_b)
    );
    let _ = writeln!(o,
        "mean clamped at the reference's 99.9th percentile ({:.6}): {:.6} (reference {:.6}, ratio {:.4})",
        s.clamp_value,
        s.clamped_mean_a,
        s.clamped_mean_b,
        ratio(s.clamped_mean_a, s.clamped_mean_b)
    );
    let _ = writeln!(
        o,
        "median pixel brightness: {:.6} (reference {:.6}, ratio {:.4})",
        s.median_a,
        s.median_b,
        ratio(s.median_a, s.median_b)
    );
    if let Some(w) = worst_block(a, b, BLOCK_SIZE).map_err(|e| format!("diff: {e}"))? {
        let _ =
            writeln!(o,
            "worst {BLOCK_SIZE}x{BLOCK_SIZE} block: z {:.2} (mean ratio {:.4}, block at {}, {})",
            w.z, w.ratio, w.at.x, w.at.y
        );
    }
    let _ = writeln!(o, "max |difference|: {:.6e}", s.max_abs_diff);
    let _ = writeln!(o, "differing pixels: {}", s.differing_pixels);
    let _ = writeln!(o, "non-finite terms: {}", s.non_finite);
    emit(&o)
}
