//! Joining crops of one image into the whole (pbrt-v4 `imgtool assemble`):
//! each part's EXR data window says where it lies in the full image (its
//! display window). The parts must cover every pixel exactly once.

use rpbrt_geometry::{Bounds2i, Point2i};

use super::{Image, ImageError, ImageMetadata, PixelFormat};

/// One part: a name for messages, the pixels and where they lie.
pub type Part<'a> = (&'a str, &'a Image, &'a ImageMetadata);

fn invalid<T>(msg: String) -> Result<T, ImageError> {
    Err(ImageError::Invalid(msg))
}

fn show(b: Bounds2i) -> String {
    format!(
        "[{}, {}) x [{}, {})",
        b.p_min.x, b.p_max.x, b.p_min.y, b.p_max.y
    )
}

/// The part's pixel bounds within the full image and the full resolution
/// (a part without them is the whole image).
fn placement(part: &Part) -> (Bounds2i, Point2i) {
    let (_, image, md) = part;
    let res = image.resolution();
    let bounds = md
        .pixel_bounds
        .unwrap_or(Bounds2i::new(Point2i::new(0, 0), res));
    (bounds, md.full_resolution.unwrap_or(res))
}

/// Joins `parts` into the full image, with the first part's metadata less
/// its placement. Refuses parts of different full resolutions or channels,
/// parts outside the full image, overlapping parts and missing pixels, each
/// with the files involved.
pub fn assemble(parts: &[Part]) -> Result<(Image, ImageMetadata), ImageError> {
    let Some(first) = parts.first() else {
        return invalid("no images to assemble".into());
    };
    let (_, full) = placement(first);
    let names = first.1.channel_names().to_vec();
    let mut area: i64 = 0;
    for part in parts {
        let (name, image, _) = part;
        let (b, f) = placement(part);
        if f != full {
            return invalid(format!(
                "{name}: full resolution {}x{} differs from {}'s {}x{}",
                f.x, f.y, first.0, full.x, full.y
            ));
        }
        if image.channel_names() != names.as_slice() {
            return invalid(format!(
                "{name}: channels {} differ from {}'s {}",
                image.channel_names().join(","),
                first.0,
                names.join(",")
            ));
        }
        let inside = b.p_min.x >= 0 && b.p_min.y >= 0 && b.p_max.x <= full.x && b.p_max.y <= full.y;
        if !inside {
            return invalid(format!(
                "{name}: pixels {} lie outside the full image {}x{}",
                show(b),
                full.x,
                full.y
            ));
        }
        area += b.area();
    }
    // Overlaps, before anything is allocated for the full image.
    for (i, a) in parts.iter().enumerate() {
        for b in &parts[i + 1..] {
            let o = placement(a).0.intersect(&placement(b).0);
            if !o.is_empty() {
                return invalid(format!(
                    "{} and {} overlap: both hold pixels {}",
                    a.0,
                    b.0,
                    show(o)
                ));
            }
        }
    }
    // Disjoint parts inside the image cover it exactly when their areas add
    // up; otherwise name the first missing pixel.
    let full_area = full.x as i64 * full.y as i64;
    if area != full_area {
        let missing = (0..full.y)
            .flat_map(|y| (0..full.x).map(move |x| Point2i::new(x, y)))
            .find(|p| {
                !parts
                    .iter()
                    .any(|part| placement(part).0.inside_exclusive(*p))
            });
        let at = missing
            .map(|p| format!(", the first at ({}, {})", p.x, p.y))
            .unwrap_or_default();
        return invalid(format!(
            "the images leave {} of the {}x{} pixels uncovered{at}: a tile is missing",
            full_area - area,
            full.x,
            full.y
        ));
    }
    let format = if parts.iter().all(|p| p.1.format() == PixelFormat::Half) {
        PixelFormat::Half
    } else {
        PixelFormat::Float
    };
    let mut out = Image::new(format, full, &names, first.1.encoding());
    let mut vals = Vec::with_capacity(names.len());
    for part in parts {
        let (b, _) = placement(part);
        let image = part.1;
        for p in b.iter() {
            let local = Point2i::new(p.x - b.p_min.x, p.y - b.p_min.y);
            vals.clear();
            vals.extend(
                (0..names.len())
                    .map(|c| image.get_channel(local, c, super::WrapMode::Clamp.into())),
            );
            out.set_channels(p, &vals);
        }
    }
    let mut md = first.2.clone();
    md.pixel_bounds = Some(Bounds2i::new(Point2i::new(0, 0), full));
    md.full_resolution = Some(full);
    md.render_time_seconds = parts
        .iter()
        .map(|p| p.2.render_time_seconds)
        .sum::<Option<f32>>();
    Ok((out, md))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::ColorEncoding;

    /// A part covering `b` of a `full` image whose pixel values are
    /// `x + 100 y` (channel 0) and `-(x + 100 y)` (channel 1).
    fn part(b: Bounds2i, full: Point2i) -> (Image, ImageMetadata) {
        let d = b.diagonal();
        let mut im = Image::new(
            PixelFormat::Float,
            Point2i::new(d.x, d.y),
            &["A", "B"],
            ColorEncoding::Linear,
        );
        for p in b.iter() {
            let v = (p.x + 100 * p.y) as f32;
            im.set_channels(Point2i::new(p.x - b.p_min.x, p.y - b.p_min.y), &[v, -v]);
        }
        let md = ImageMetadata {
            pixel_bounds: Some(b),
            full_resolution: Some(full),
            ..Default::default()
        };
        (im, md)
    }

    fn bounds(x0: i32, x1: i32, y0: i32, y1: i32) -> Bounds2i {
        Bounds2i::new(Point2i::new(x0, y0), Point2i::new(x1, y1))
    }

    fn run(list: &[(Image, ImageMetadata)]) -> Result<(Image, ImageMetadata), ImageError> {
        let names: Vec<String> = (0..list.len()).map(|i| format!("t{i}.exr")).collect();
        let parts: Vec<Part> = list
            .iter()
            .zip(&names)
            .map(|((im, md), n)| (n.as_str(), im, md))
            .collect();
        assemble(&parts)
    }

    #[test]
    fn tiles_join_into_the_full_image() {
        let full = Point2i::new(5, 3);
        let list = [
            part(bounds(0, 2, 0, 3), full),
            part(bounds(2, 5, 0, 1), full),
            part(bounds(2, 5, 1, 3), full),
        ];
        let (im, md) = run(&list).expect("assembles");
        assert_eq!(im.resolution(), full);
        assert_eq!(md.pixel_bounds, Some(bounds(0, 5, 0, 3)));
        for y in 0..3 {
            for x in 0..5 {
                let v = (x + 100 * y) as f32;
                let p = Point2i::new(x, y);
                let w = crate::image::WrapMode::Clamp.into();
                assert_eq!(im.get_channel(p, 0, w), v);
                assert_eq!(im.get_channel(p, 1, w), -v);
            }
        }
    }

    #[test]
    fn overlaps_gaps_and_mismatches_are_refused() {
        let full = Point2i::new(4, 4);
        let e = run(&[
            part(bounds(0, 3, 0, 4), full),
            part(bounds(2, 4, 0, 4), full),
        ])
        .expect_err("overlap");
        assert!(e.to_string().contains("t0.exr and t1.exr overlap"), "{e}");
        assert!(e.to_string().contains("[2, 3) x [0, 4)"), "{e}");

        let e = run(&[
            part(bounds(0, 2, 0, 4), full),
            part(bounds(2, 4, 0, 3), full),
        ])
        .expect_err("gap");
        assert!(
            e.to_string()
                .contains("leave 2 of the 4x4 pixels uncovered"),
            "{e}"
        );
        assert!(e.to_string().contains("(2, 3)"), "{e}");

        let e = run(&[
            part(bounds(0, 2, 0, 4), full),
            part(bounds(2, 4, 0, 4), Point2i::new(4, 5)),
        ])
        .expect_err("resolution");
        assert!(e.to_string().contains("t1.exr: full resolution 4x5"), "{e}");

        let e = run(&[
            part(bounds(0, 2, 0, 4), full),
            part(bounds(2, 5, 0, 4), full),
        ])
        .expect_err("outside");
        assert!(e.to_string().contains("outside the full image"), "{e}");

        let (mut other, md) = part(bounds(2, 4, 0, 4), full);
        other = other.select_channels(&other.get_channel_desc(&["A"]).expect("A"));
        let e = run(&[part(bounds(0, 2, 0, 4), full), (other, md)]).expect_err("channels");
        assert!(e.to_string().contains("channels A differ"), "{e}");

        assert!(run(&[]).is_err());
        // A huge claimed display window is refused without allocating it.
        let huge = Point2i::new(1 << 30, 1 << 30);
        let e = run(&[part(bounds(0, 2, 0, 2), huge)]).expect_err("huge");
        assert!(e.to_string().contains("uncovered"), "{e}");
    }
}
