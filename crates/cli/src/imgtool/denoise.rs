//! `imgtool denoise`: Intel Open Image Denoise on the CPU (pbrt-v4 has
//! only `denoise-optix`, on NVIDIA GPUs), with the albedo and normal of
//! pbrt-v4's `gbuffer` film as its auxiliary images.

use super::args::{Arg, Args};
use super::{charge_output, load_md, save};
use crate::oidn::{Inputs, Oidn, Quality};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::Image;

/// Usage of `imgtool denoise`.
pub const USAGE: &str = "\
usage: rpbrt imgtool denoise [options] <filename>
    Denoise a rendered image with Intel Open Image Denoise on the CPU
    (its generic ray-tracing filter, HDR colour). The colour is the
    image's R, G, B channels. A `gbuffer` film's image also holds the
    first visible surface's albedo (Albedo.R/G/B) and shading normal
    (Ns.X/Y/Z): they are used as auxiliary images, prefiltered first
    (OIDN's recommended workflow; albedos clamped to [0, 1]), unless
    --color-only or --noisy-aux is given.
    Non-finite colour pixels are counted, reported and set to zero.
    The library is loaded at run time: `pip install pyoidn` provides it
    (or set OIDN_DIR to a folder holding libOpenImageDenoise.so.2).
options:
    --albedo <file>    Albedo image (its Albedo.R/G/B channels, else R, G, B),
                       in place of the input's own.
    --color-only       Denoise from the colour alone.
    --noisy-aux        Pass the albedo and normal as they are, not
                       prefiltered (OIDN's mode for noisy auxiliary images:
                       one filter run instead of three).
    --normal <file>    Normal image (its Ns.X/Y/Z or N.X/Y/Z channels, else
                       R, G, B), in place of the input's own; needs an albedo.
    --outfile <name>   Output image filename (required): R, G, B, with the
                       input's metadata.
    --quality <q>      fast, balanced or high. Default: high
";

/// Runs `imgtool denoise`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("denoise", argv);
    let (mut infile, mut outfile, mut albedo_file, mut normal_file) = (None, None, None, None);
    let (mut color_only, mut noisy_aux) = (false, false);
    let mut quality = Quality::High;
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "albedo" => albedo_file = Some(a.value(&f)?),
                "normal" => normal_file = Some(a.value(&f)?),
                "color-only" | "coloronly" => color_only = a.bool(&f)?,
                "noisy-aux" | "noisyaux" => noisy_aux = a.bool(&f)?,
                "quality" => {
                    let q = a.value(&f)?;
                    quality = Quality::parse(&q).ok_or_else(|| {
                        a.err(format!("--quality \"{q}\": must be fast, balanced or high"))
                    })?;
                }
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) if infile.is_none() => infile = Some(p),
            Arg::Positional(p) => return Err(a.err(format!("{p}: excess argument"))),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("--outfile must be specified"))?;
    let infile = infile.ok_or_else(|| a.err("input filename must be specified"))?;
    if color_only && (albedo_file.is_some() || normal_file.is_some()) {
        return Err(a.err("--color-only takes no --albedo or --normal"));
    }
    if color_only && noisy_aux {
        return Err(
            a.err("--noisy-aux is how the auxiliary images are passed; --color-only uses none")
        );
    }
    let job = Job {
        infile: &infile,
        outfile: &outfile,
        albedo_file: albedo_file.as_deref(),
        normal_file: normal_file.as_deref(),
        color_only,
        noisy_aux,
        quality,
    };
    denoise_file(&job, budget).map_err(|e| a.err(e))
}

/// One denoise: the files and options of `imgtool denoise` (and of
/// `rpbrt --denoise`, on the render it wrote).
pub(crate) struct Job<'a> {
    pub infile: &'a str,
    pub outfile: &'a str,
    pub albedo_file: Option<&'a str>,
    pub normal_file: Option<&'a str>,
    pub color_only: bool,
    /// The auxiliary images passed as they are (`--noisy-aux`).
    pub noisy_aux: bool,
    pub quality: Quality,
}

/// Denoises `job.infile` into `job.outfile` (see [`USAGE`]); warnings go
/// to standard error, errors name the file.
pub(crate) fn denoise_file(job: &Job, budget: &MemoryBudget) -> Result<(), String> {
    let infile = job.infile;
    let input = load_md(infile, budget)?;
    let res = input.image.resolution();
    let mut color = channels(&input.image, &[&["R", "G", "B"]])
        .ok_or_else(|| format!("{infile}: no R, G, B channels to denoise"))?;
    let bad = zero_non_finite(&mut color);
    if bad > 0 {
        diagln!(
            "rpbrt: warning: denoise: {infile}: {bad} pixel(s) with non-finite colour set to zero before denoising"
        );
    }
    // The auxiliary images: from their own files, else from the input.
    let aux =
        |file: Option<&str>, sets: &[&[&str]], what: &str| -> Result<Option<Vec<f32>>, String> {
            if job.color_only {
                return Ok(None);
            }
            let Some(file) = file else {
                return Ok(channels(&input.image, &sets[..1]));
            };
            let im = load_md(file, budget)?.image;
            if im.resolution() != res {
                return Err(format!(
                    "{file}: {}x{} {what} image for a {}x{} colour image ({infile})",
                    im.resolution().x,
                    im.resolution().y,
                    res.x,
                    res.y
                ));
            }
            let v = channels(&im, sets)
                .ok_or_else(|| format!("{file}: no {what} channels ({})", names(sets)))?;
            Ok(Some(v))
        };
    let albedo_sets: &[&[&str]] = &[&["Albedo.R", "Albedo.G", "Albedo.B"], &["R", "G", "B"]];
    let normal_sets: &[&[&str]] = &[
        &["Ns.X", "Ns.Y", "Ns.Z"],
        &["N.X", "N.Y", "N.Z"],
        &["R", "G", "B"],
    ];
    let mut albedo = aux(job.albedo_file, albedo_sets, "albedo")?;
    let mut normal = aux(job.normal_file, normal_sets, "normal")?;
    if normal.is_some() && albedo.is_none() {
        return Err(
            "a normal image needs an albedo image too (Open Image Denoise's rule): give --albedo"
                .into(),
        );
    }
    for (v, what, file) in [
        (&albedo, "albedo", job.albedo_file),
        (&normal, "normal", job.normal_file),
    ] {
        let bad = v.as_ref().map_or(0, |v| {
            v.chunks_exact(3)
                .filter(|p| p.iter().any(|x| !x.is_finite()))
                .count()
        });
        if bad > 0 {
            return Err(format!(
                "{}: {bad} pixel(s) with a non-finite {what}",
                file.unwrap_or(infile)
            ));
        }
    }
    if let Some(a) = albedo.as_deref_mut() {
        clamp_albedo(a);
    }
    charge_output(budget, res.x.into(), res.y.into(), 3, "the denoised image")?;
    let oidn = Oidn::load()?;
    let out = oidn
        .denoise(Inputs {
            width: res.x.max(0) as usize,
            height: res.y.max(0) as usize,
            color: &color,
            albedo: albedo.as_deref_mut(),
            normal: normal.as_deref_mut(),
            quality: job.quality,
            prefilter: !job.noisy_aux,
        })
        .map_err(|e| format!("{infile}: {e}"))?;
    let image = Image::from_f32(out, res, &["R", "G", "B"]).map_err(|e| e.to_string())?;
    save(&image, job.outfile, &input.metadata)
}

/// Clamps albedo values to [0, 1], the range Open Image Denoise requires
/// of them ("must be always between 0 and 1"): pbrt-v4's `gbuffer` film
/// records a Monte Carlo estimate of each surface's reflectance, which
/// overshoots 1 a little at some pixels (1.01 on veach-mis at 16 spp).
/// Returns how many values were changed.
fn clamp_albedo(albedo: &mut [f32]) -> usize {
    let mut changed = 0;
    for x in albedo.iter_mut() {
        let c = x.clamp(0.0, 1.0);
        changed += usize::from(c != *x);
        *x = c;
    }
    changed
}

/// The first of `sets` of three channels that `image` has, as interleaved
/// floats.
fn channels(image: &Image, sets: &[&[&str]]) -> Option<Vec<f32>> {
    let desc = sets.iter().find_map(|s| image.get_channel_desc(s))?;
    Some(image.select_channels(&desc).to_f32_vec())
}

/// `sets` for a message: "Albedo.R,Albedo.G,Albedo.B or R,G,B".
fn names(sets: &[&[&str]]) -> String {
    sets.iter()
        .map(|s| s.join(","))
        .collect::<Vec<_>>()
        .join(" or ")
}

/// Sets every RGB triple of `v` that has a non-finite value to zero;
/// returns how many there were.
pub(crate) fn zero_non_finite(v: &mut [f32]) -> usize {
    let mut n = 0;
    for p in v.chunks_exact_mut(3) {
        if p.iter().any(|x| !x.is_finite()) {
            p.fill(0.0);
            n += 1;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_render::geometry::tuple::Point2i;

    #[test]
    fn non_finite_pixels_are_counted_and_zeroed() {
        let mut v = vec![1.0, 2.0, 3.0, f32::NAN, 0.5, 0.5, 0.1, f32::INFINITY, 0.2];
        assert_eq!(zero_non_finite(&mut v), 2);
        assert_eq!(v, vec![1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }

    /// Albedos outside [0, 1] are clamped, the rest kept bit for bit.
    #[test]
    fn albedo_is_clamped_to_the_unit_range() {
        let mut a = [
            0.0,
            0.5,
            1.0,
            1.0107,
            -0.25,
            0.999_999_9,
            f32::MIN_POSITIVE,
            7.0,
            -0.0,
        ];
        assert_eq!(clamp_albedo(&mut a), 3);
        let want = [
            0.0,
            0.5,
            1.0,
            1.0,
            0.0,
            0.999_999_9,
            f32::MIN_POSITIVE,
            1.0,
            -0.0,
        ];
        assert!(a.iter().zip(&want).all(|(x, y)| x.to_bits() == y.to_bits()));
    }

    #[test]
    fn channel_sets_are_tried_in_order() {
        let im = Image::from_f32(
            vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            Point2i::new(1, 1),
            &["R", "G", "B", "Ns.X", "Ns.Y", "Ns.Z"],
        )
        .expect("image");
        assert_eq!(
            channels(&im, &[&["N.X", "N.Y", "N.Z"], &["Ns.X", "Ns.Y", "Ns.Z"]]),
            Some(vec![4.0, 5.0, 6.0])
        );
        assert_eq!(
            channels(&im, &[&["Albedo.R", "Albedo.G", "Albedo.B"]]),
            None
        );
    }
}
