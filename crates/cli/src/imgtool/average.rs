//! `imgtool average`: pbrt-v4's average of images sharing a filename base.

use super::args::{Arg, Args};
use super::load;
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::average;
use rpbrt_render::image::ImageMetadata;
use std::path::Path;

/// Usage of `imgtool average`.
pub const USAGE: &str = "\
usage: rpbrt imgtool average --outfile <file> <filename base>
    Average the images whose file names start with the base (in its folder,
    in name order): resolutions and channels must match; infinite values
    count as zero, a NaN is an error (pbrt-v4's average).
";

/// The files whose names start with `base`'s file name, in its folder,
/// sorted by name (pbrt-v4's `MatchingFilenames`).
pub(crate) fn matching_filenames(base: &str) -> Result<Vec<std::path::PathBuf>, String> {
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

/// Runs `imgtool average`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    let mut a = Args::new("average", args);
    let mut outfile: Option<String> = None;
    let mut base: Option<String> = None;
    while let Some(arg) = a.next_arg() {
        match arg {
            Arg::Flag(f) if f == "outfile" => outfile = Some(a.value(&f)?),
            Arg::Flag(f) => return Err(a.unknown(&f)),
            Arg::Positional(p) if base.is_some() => {
                return Err(a.err(format!("{p}: excess argument")))
            }
            Arg::Positional(p) => base = Some(p),
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
        images.push(load(&f.to_string_lossy(), budget)?);
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
