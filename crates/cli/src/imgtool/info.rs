//! `imgtool info`: resolution, metadata and channel statistics of images
//! (pbrt-v4's `info`).

use super::{emit, load_md};
use rpbrt_parser::diag::escape_controls;
use rpbrt_parser::MemoryBudget;
use rpbrt_render::image::ops::info;
use rpbrt_render::image::ImageMetadata;

/// `s` with every control character escaped, newlines and tabs included:
/// file names, attribute keys and values and channel names come from the
/// image file, and a terminal would obey an escape sequence in them (or a
/// newline would forge a line of the report).
fn shown(s: &str) -> String {
    escape_controls(s, "").into_owned()
}

/// Usage of `imgtool info`.
pub const USAGE: &str = "\
usage: rpbrt imgtool info <filenames...>
    For each image: resolution, pixel format, colour space, the metadata
    stored with it (full resolution and pixel bounds of a crop, render
    time, camera matrices, samples per pixel, MSE, string attributes) and
    each channel's min, max, average and NaN and Inf counts.
";

fn matrix(m: &[[f32; 4]; 4]) -> String {
    let rows: Vec<String> = m
        .iter()
        .map(|r| format!("[ {} {} {} {} ]", r[0], r[1], r[2], r[3]))
        .collect();
    format!("[ {} ]", rows.join(" "))
}

/// The metadata lines pbrt-v4's `info` prints, each tab-indented.
fn metadata_lines(md: &ImageMetadata) -> Vec<String> {
    let mut l = Vec::new();
    let cs = match md.color_space.as_deref() {
        None => "(unspecified)".to_string(),
        Some("srgb") => "sRGB".into(),
        Some("dci-p3") => "DCI-P3".into(),
        Some("rec2020") => "rec2020".into(),
        Some("aces2065-1") => "ACES".into(),
        Some(o) => shown(o),
    };
    l.push(format!("color space: {cs}"));
    if let Some(f) = md.full_resolution {
        l.push(format!("full resolution ({}, {})", f.x, f.y));
    }
    if let Some(b) = md.pixel_bounds {
        l.push(format!(
            "pixel bounds ({}, {}) - ({}, {})",
            b.p_min.x, b.p_min.y, b.p_max.x, b.p_max.y
        ));
    }
    if let Some(t) = md.render_time_seconds {
        let total = t;
        let h = (t / 3600.0).floor();
        let m = ((t - h * 3600.0) / 60.0).floor();
        let s = t - h * 3600.0 - m * 60.0;
        l.push(format!(
            "render time: {h}h {m}m {s:.2}s (total {total:.2}s)"
        ));
    }
    if let Some(m) = &md.camera_from_world {
        l.push(format!("camera from world: {}", matrix(m)));
    }
    if let Some(m) = &md.ndc_from_world {
        l.push(format!("NDC from world: {}", matrix(m)));
    }
    if let Some(s) = md.samples_per_pixel {
        l.push(format!("samples per pixel: {s}"));
    }
    if let Some(v) = md.estimated_variance {
        l.push(format!("estimated variance: {v}"));
    }
    if let Some(m) = md.mse {
        l.push(format!("MSE vs. reference image: {m}"));
    }
    for (k, v) in &md.strings {
        let vals: Vec<String> = v.iter().map(|s| format!("\"{}\"", shown(s))).collect();
        l.push(format!("\"{}\": [ {} ]", shown(k), vals.join(" ")));
    }
    l
}

/// Runs `imgtool info`.
pub fn run(args: &[String], budget: &MemoryBudget) -> Result<(), String> {
    if args.is_empty() {
        return Err("info: needs at least one image".into());
    }
    if let Some(f) = args.iter().find(|a| a.starts_with('-')) {
        return Err(format!("info: {f}: unknown option (info takes no options)"));
    }
    for f in args {
        let im = load_md(f, budget)?;
        let mut s = format!("{}:\n", shown(f));
        for l in metadata_lines(&im.metadata) {
            s += &format!("  {l}\n");
        }
        let mut stats = info(&im.image);
        for c in &mut stats.channels {
            c.name = shown(&c.name);
        }
        s += &stats.to_string();
        // Each image is done with before the next is read.
        budget.release(im.image.bytes_used() as u64);
        emit(&s)?;
    }
    Ok(())
}
