//! `imgtool splitn`: a composite of slanted strips of several images
//! (pbrt-v4's `splitn`).

use super::args::{Arg, Args};
use super::{load_md, save};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::geometry::Point2i;
use rpbrt_render::image::ops::compose::splitn;
use rpbrt_render::image::ImageMetadata;
use std::path::Path;

/// Usage of `imgtool splitn`.
pub const USAGE: &str = "\
usage: rpbrt imgtool splitn [options] <filenames...>
    Make an image of slanted strips, one from each image in order, with
    black gaps; optionally also an image of enlarged crops of every image.
options:
    --crop <x,y>       Upper-left corner of a crop (up to three; each is
                       framed in its colour). Applies the current --cropsize.
    --cropsize <n>     Width and height of the crops. Default: 96
    --outfile <name>   Output image filename (required); the crops go to
                       \"crops-<name>\" beside it.
";

/// Runs `imgtool splitn`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("splitn", argv);
    if argv.is_empty() {
        return Err(a.err("no filenames provided"));
    }
    let (mut outfile, mut crop_size) = (None, 96);
    let mut crops: Vec<(Point2i, i32)> = Vec::new();
    let mut infiles = Vec::new();
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "outfile" => outfile = Some(a.value(&f)?),
                "cropsize" => crop_size = a.i32(&f)?,
                "crop" => {
                    let c = a.ints(&f, 2)?;
                    crops.push((Point2i::new(c[0], c[1]), crop_size));
                }
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(p) => infiles.push(p),
        }
    }
    let outfile = outfile.ok_or_else(|| a.err("--outfile not provided"))?;
    if infiles.is_empty() {
        return Err(a.err("no input filenames provided"));
    }
    // pbrt-v4 sizes each crop with the --cropsize given before it, but
    // lays them out with the last one; crops must share one size.
    if crops.iter().any(|&(_, s)| s != crop_size) {
        return Err(a.err("give --cropsize once, before every --crop"));
    }
    let mut images = Vec::new();
    for f in &infiles {
        let im = load_md(f, budget)?;
        images.push((im.image, im.metadata));
    }
    let corners: Vec<Point2i> = crops.iter().map(|c| c.0).collect();
    let s = splitn(&images, &corners, crop_size).map_err(|e| {
        // Name the file the message's image index refers to.
        let m = e.to_string();
        let idx = m
            .strip_prefix("image ")
            .and_then(|r| r.split(':').next())
            .and_then(|k| k.parse::<usize>().ok());
        match idx.and_then(|k| infiles.get(k)) {
            Some(f) => a.err(format!("{f}{}", &m[m.find(':').unwrap_or(0)..])),
            None => a.err(m),
        }
    })?;
    let md = ImageMetadata {
        color_space: images[0].1.color_space.clone(),
        ..Default::default()
    };
    save(&s.image, &outfile, &md)?;
    if let Some(c) = s.crops {
        let p = Path::new(&outfile);
        let name = p
            .file_name()
            .map(|n| format!("crops-{}", n.to_string_lossy()))
            .unwrap_or_else(|| "crops".into());
        save(&c, &p.with_file_name(name).to_string_lossy(), &md)?;
    }
    Ok(())
}
