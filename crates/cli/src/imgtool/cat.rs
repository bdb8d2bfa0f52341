//! `imgtool cat`: print an image's pixel values (pbrt-v4's `cat`).

use super::args::{Arg, Args};
use super::{emit, load_md};
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::compose::pixel_listing;

/// Usage of `imgtool cat`.
pub const USAGE: &str = "\
usage: rpbrt imgtool cat [options] <filenames...>
    Print each pixel's coordinates (in the full image) and values. An
    option applies to the files after it; giving it again turns it off.
options:
    --csv              Print only the values, comma-separated.
    --list             Print a one-channel image as rows of values
                       (Mathematica-style).
    --sort             Print pixels by increasing channel average.
";

/// Runs `imgtool cat`.
pub fn run(argv: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("cat", argv);
    if argv.is_empty() {
        return Err(a.err("no filenames provided"));
    }
    let (mut sort, mut csv, mut list) = (false, false, false);
    let mut out = String::new();
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) => match f.as_str() {
                "sort" => sort = !sort,
                "csv" => csv = !csv,
                "list" => list = !list,
                _ => return Err(a.unknown(&f)),
            },
            Arg::Positional(file) => {
                if sort && csv {
                    return Err(a.err("--sort and --csv don't make sense together"));
                }
                if sort && list {
                    return Err(a.err("--sort and --list don't make sense together"));
                }
                let im = load_md(&file, budget)?;
                if list {
                    if im.image.n_channels() != 1 {
                        return Err(a.err(format!(
                            "{file}: --list needs a one-channel image (it has {})",
                            im.image.n_channels()
                        )));
                    }
                    let w = im.image.resolution().x.max(1) as usize;
                    for row in im.image.to_f32_vec().chunks(w) {
                        for v in row {
                            out += &format!("{v:.6} ");
                        }
                        out.push('\n');
                    }
                } else {
                    for (p, v) in pixel_listing(&im.image, &im.metadata, sort) {
                        if !csv {
                            out += &format!("({}, {}): ", p.x, p.y);
                        }
                        let vals: Vec<String> = v.iter().map(|x| format!("{x:.6}")).collect();
                        out += &vals.join(",");
                        out.push('\n');
                    }
                }
            }
        }
    }
    emit(&out)
}
