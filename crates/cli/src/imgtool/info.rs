//! `imgtool info`: resolution, channels and statistics of images.

use super::load;
use rpbrt_render::image::ops::info;

/// Usage of `imgtool info`.
pub const USAGE: &str = "\
usage: rpbrt imgtool info <images...>
    Resolution, channels, per-channel min/max/average, NaN and Inf counts.
";

/// Runs `imgtool info`.
pub fn run(args: &[String]) -> Result<(), String> {
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
