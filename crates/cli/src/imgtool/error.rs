//! `imgtool error`: the mean error of a set of renders against a
//! reference, with a 95% confidence interval (pbrt-v4's `error`, which
//! prints the estimate only).

use super::args::{crop, fmt_g, Arg, Args};
use super::average::matching_filenames;
use super::{emit, load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::metrics::{estimate_error, Metric};
use rpbrt_render::image::ImageMetadata;
use std::path::Path;

/// Usage of `imgtool error`.
pub const USAGE: &str = "\
usage: rpbrt imgtool error [options] <filename prefix>
    The mean error, against a reference, of the images whose file names
    start with the prefix (independent renders, same samples per pixel),
    with a 95% confidence interval for the expected error from the spread
    of the images' errors (Student's t), and its standard error.
options:
    --crop <x0,x1,y0,y1> Crop all images first (a negative x1 or y1 is a size).
    --errorfile <name>   Write the per-pixel variance across the images
                         (of v/(r+0.01) for MRSE), averaged over channels.
    --metric <name>      MSE, MAE or MRSE. Default: MSE
    --reference <name>   The reference image (required).
";

/// Runs `imgtool error`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("error", argv);
    let (mut reference, mut errorfile, mut window, mut base) = (None, None, None, None);
    let mut metric = Metric::Mse;
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "reference" => reference = Some(a.value(&f)?),
                "errorfile" => errorfile = Some(a.value(&f)?),
                "crop" => window = crop(&mut a, &f)?,
                "metric" => {
                    let v = a.value(&f)?;
                    metric = Metric::parse(&v).ok_or_else(|| {
                        a.err(format!(
                            "{v}: --metric must be \"MAE\", \"MSE\", or \"MRSE\""
                        ))
                    })?;
                }
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if base.is_none() => base = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: unknown argument"))),
        }
    }
    let base = base.ok_or_else(|| a.err("must provide base filename"))?;
    let reference = reference.ok_or_else(|| a.err("must provide --reference file"))?;
    let mut refim = load_md(&reference, budget)?.image;
    if let Some(w) = window {
        refim = refim
            .crop(w)
            .map_err(|e| a.err(format!("{reference}: {e}")))?;
    }
    let skip: Vec<&Path> = [Some(reference.as_str()), errorfile.as_deref()]
        .into_iter()
        .flatten()
        .map(Path::new)
        .collect();
    let files: Vec<_> = matching_filenames(&base)?
        .into_iter()
        .filter(|f| !skip.contains(&f.as_path()))
        .collect();
    if files.is_empty() {
        return Err(a.err(format!("{base}: no matching filenames!")));
    }
    let mut images = Vec::with_capacity(files.len());
    let mut spp: Option<(i32, String)> = None;
    for f in &files {
        let name = f.to_string_lossy().into_owned();
        let im = load_md(&name, budget)?;
        if let Some(s) = im.metadata.samples_per_pixel {
            match &spp {
                Some((s0, f0)) if *s0 != s => {
                    return Err(a.err(format!("{name}: spp {s} mismatch. {f0} has {s0}.")))
                }
                None => spp = Some((s, name.clone())),
                _ => {}
            }
        }
        let mut image = im.image;
        if let Some(w) = window {
            image = image.crop(w).map_err(|e| a.err(format!("{name}: {e}")))?;
        }
        images.push(image);
    }
    let e = estimate_error(&images, &refim, metric).map_err(|e| {
        let m = e.to_string();
        let idx = m
            .strip_prefix("image ")
            .and_then(|r| r.split(':').next())
            .and_then(|k| k.parse::<usize>().ok());
        match idx.and_then(|k| files.get(k)) {
            Some(f) => a.err(format!("{}{}", f.display(), &m[m.find(':').unwrap_or(0)..])),
            None => a.err(m),
        }
    })?;
    let mut out = format!("{} estimate = {}\n", metric.name(), fmt_g(e.mean, 9));
    if images.len() > 1 {
        out += &format!(
            "95% confidence interval: [{}, {}] (standard error {}, {} images)\n",
            fmt_g(e.ci95.0, 6),
            fmt_g(e.ci95.1, 6),
            fmt_g(e.std_error, 6),
            images.len()
        );
    } else {
        out += "95% confidence interval: needs at least two images (1 image)\n";
    }
    if let Some(f) = errorfile {
        save(&e.variance_image, &f, &ImageMetadata::default())?;
    }
    emit(&out)
}
