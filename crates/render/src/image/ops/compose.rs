//! Images made from other images' pixels: pbrt-v4's `splitn` (slanted
//! strips of several renders side by side, with optional enlarged crops),
//! `makeemitters` (a quad light per pixel) and the pixel listing behind
//! `cat`.

use rpbrt_geometry::{Bounds2i, Point2i};

use crate::image::{ColorEncoding, Image, ImageError, ImageMetadata, PixelFormat};

/// The border colours of `splitn`'s crops, in order.
pub const SPLITN_EDGES: [[f32; 3]; 3] = [[0.8, 0.15, 0.15], [0.15, 0.8, 0.15], [0.15, 0.15, 0.8]];

/// Border width of `splitn`'s crop boxes.
const BORDER: i32 = 5;
/// Gap between strips and between crops.
const PAD: i32 = 6;
/// Slant of the strip boundaries: they move by ±width/15 over the height.
const SLANT: f32 = 15.0;

/// The result of [`splitn`].
#[derive(Clone, Debug)]
pub struct SplitN {
    /// The composite: a slanted strip of each image, separated by black.
    pub image: Image,
    /// The crops (one row per crop, one column per image, each boxed in
    /// its crop's colour), when crops were asked for.
    pub crops: Option<Image>,
}

fn fill_box(image: &mut Image, b: Bounds2i, rgb: [f32; 3]) {
    let Some(desc) = image.get_channel_desc(&["R", "G", "B"]) else {
        return;
    };
    let res = image.resolution();
    let nc = image.n_channels();
    for y in b.p_min.y.max(0)..b.p_max.y.min(res.y) {
        for x in b.p_min.x.max(0)..b.p_max.x.min(res.x) {
            let i = (y as usize * res.x as usize + x as usize) * nc;
            for (&o, &c) in desc.offset.iter().zip(&rgb) {
                image.set_value_at(i + o, c);
            }
        }
    }
}

/// Draws a `BORDER`-pixel frame of colour `rgb` around `b` (parts outside
/// the image are dropped).
fn draw_frame(image: &mut Image, b: Bounds2i, rgb: [f32; 3]) {
    let bw = BORDER;
    let r = |x0, y0, x1, y1| Bounds2i {
        p_min: Point2i::new(x0, y0),
        p_max: Point2i::new(x1, y1),
    };
    let (p0, p1) = (b.p_min, b.p_max);
    fill_box(image, r(p0.x - bw, p0.y - bw, p1.x + bw, p0.y), rgb);
    fill_box(image, r(p0.x - bw, p1.y, p1.x + bw, p1.y + bw), rgb);
    fill_box(image, r(p0.x - bw, p0.y, p0.x, p1.y), rgb);
    fill_box(image, r(p1.x, p0.y, p1.x + bw, p1.y), rgb);
}

/// pbrt-v4's `splitn`: each row of the result takes consecutive slanted
/// strips from the images in order (boundary i at x = (i+1)/n · width −
/// (2y/height − 1) · width/15, with 6 black pixels between strips). With
/// `crops` (upper-left corners, at most three, each `crop_size` square and
/// inside the images), each crop is framed in its colour on the result and
/// copied, framed, from every image into a second, white image. All
/// images need the same resolution, channels and colour space.
pub fn splitn(
    images: &[(Image, ImageMetadata)],
    crops: &[Point2i],
    crop_size: i32,
) -> Result<SplitN, ImageError> {
    let invalid = |m: String| Err(ImageError::Invalid(m));
    let Some((first, first_md)) = images.first() else {
        return invalid("no images to split".into());
    };
    for (k, (im, md)) in images.iter().enumerate().skip(1) {
        if im.resolution() != first.resolution() {
            return invalid(format!(
                "image {k}: resolution {}x{} doesn't match the first image's {}x{}",
                im.resolution().x,
                im.resolution().y,
                first.resolution().x,
                first.resolution().y
            ));
        }
        if im.channel_names() != first.channel_names() {
            return invalid(format!(
                "image {k}: channels {} don't match the first image's {}",
                im.channel_names().join(","),
                first.channel_names().join(",")
            ));
        }
        if md.color_space_name() != first_md.color_space_name() {
            return invalid(format!(
                "image {k}: color space {} doesn't match the first image's {}",
                md.color_space_name(),
                first_md.color_space_name()
            ));
        }
    }
    if crops.len() > SPLITN_EDGES.len() {
        return invalid(format!(
            "at most {} crops are supported",
            SPLITN_EDGES.len()
        ));
    }
    let res = first.resolution();
    if !crops.is_empty() {
        if crop_size < 1 {
            return invalid(format!("crop size {crop_size} must be at least 1"));
        }
        if first.get_channel_desc(&["R", "G", "B"]).is_none() {
            return invalid("crops need R, G, B channels".into());
        }
        for c in crops {
            if c.x < 0 || c.y < 0 || c.x + crop_size > res.x || c.y + crop_size > res.y {
                return invalid(format!(
                    "crop at ({}, {}) of size {crop_size} is outside the {}x{} image",
                    c.x, c.y, res.x, res.y
                ));
            }
        }
    }
    let n = images.len();
    let nc = first.n_channels();
    let vals: Vec<Vec<f32>> = images.iter().map(|(im, _)| im.to_f32_vec()).collect();
    let mut result = Image::new(first.format(), res, first.channel_names(), first.encoding());
    let w = res.x as usize;
    let copy = |result: &mut Image, k: usize, x: i32, y: i32| {
        let i = (y as usize * w + x as usize) * nc;
        for c in 0..nc {
            result.set_value_at(i + c, vals[k][i + c]);
        }
    };
    for y in 0..res.y {
        let mut x = 0;
        for k in 0..n {
            if k == n - 1 {
                while x < res.x {
                    copy(&mut result, k, x, y);
                    x += 1;
                }
            } else {
                let x1 = ((k + 1) as f32 / n as f32 * res.x as f32
                    + (2.0 * (y as f32 / res.y as f32) - 1.0) * res.x as f32 / -SLANT)
                    as i32;
                while x < (x1 - PAD / 2).min(res.x) {
                    copy(&mut result, k, x, y);
                    x += 1;
                }
                // The black gap: the result starts zeroed.
                x = x.max((x1 + PAD / 2).min(res.x));
            }
        }
    }
    if crops.is_empty() {
        return Ok(SplitN {
            image: result,
            crops: None,
        });
    }
    let cell = crop_size + 2 * BORDER;
    let xres = (cell * n as i32 + PAD * (n as i32 - 1)).max(1);
    let yres = (cell * crops.len() as i32 + PAD * (crops.len() as i32 - 1)).max(1);
    let mut crops_image = Image::new(
        PixelFormat::Float,
        Point2i::new(xres, yres),
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    let all = Bounds2i {
        p_min: Point2i::new(0, 0),
        p_max: Point2i::new(xres, yres),
    };
    fill_box(&mut crops_image, all, [1.0; 3]);
    for (ci, c) in crops.iter().enumerate() {
        let crop = Bounds2i {
            p_min: *c,
            p_max: Point2i::new(c.x + crop_size, c.y + crop_size),
        };
        draw_frame(&mut result, crop, SPLITN_EDGES[ci]);
        for (k, (im, _)) in images.iter().enumerate() {
            let y0 = ci as i32 * (cell + PAD);
            let x0 = k as i32 * (cell + PAD);
            let inner = Point2i::new(x0 + BORDER, y0 + BORDER);
            draw_frame(
                &mut crops_image,
                Bounds2i {
                    p_min: inner,
                    p_max: Point2i::new(inner.x + crop_size, inner.y + crop_size),
                },
                SPLITN_EDGES[ci],
            );
            let desc = im
                .get_channel_desc(&["R", "G", "B"])
                .ok_or_else(|| ImageError::Invalid("crops need R, G, B channels".into()))?;
            for dy in 0..crop_size {
                for dx in 0..crop_size {
                    let src = ((c.y + dy) as usize * w + (c.x + dx) as usize) * nc;
                    let dst =
                        ((inner.y + dy) as usize * xres as usize + (inner.x + dx) as usize) * 3;
                    for kk in 0..3 {
                        crops_image.set_value_at(dst + kk, vals[k][src + desc.offset[kk]]);
                    }
                }
            }
        }
    }
    Ok(SplitN {
        image: result,
        crops: Some(crops_image),
    })
}

/// One quadrilateral emitter of [`make_emitters`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEmitter {
    /// Its emitted radiance: the mean R, G, B of its pixels.
    pub rgb: [f32; 3],
    /// Its corners (x, y; z is 0) in bilinear-patch order: (x0, y0),
    /// (x1, y0), (x0, y1), (x1, y1).
    pub corners: [[f32; 2]; 4],
}

/// A quad emitter per block of `downsample`×`downsample` pixels (pbrt-v4
/// `makeemitters`): the image spans y in [0, 1] (top row at 1) and x over
/// the aspect ratio, centred and mirrored (the first column at +aspect/2,
/// so the image reads correctly seen from +z towards the origin with y up
/// in a left-handed frame). Each block's radiance is the mean of its
/// pixels inside the image.
pub fn make_emitters(image: &Image, downsample: i32) -> Result<Vec<PixelEmitter>, ImageError> {
    if downsample < 1 {
        return Err(ImageError::Invalid(format!(
            "--downsample ({downsample}) must be at least 1"
        )));
    }
    let rgb = image
        .get_channel_desc(&["R", "G", "B"])
        .ok_or_else(|| ImageError::Invalid("didn't find R, G, and B channels".into()))?;
    let res = image.resolution();
    let nc = image.n_channels();
    let vals = image.to_f32_vec();
    let aspect = res.x as f32 / res.y as f32;
    let mut out = Vec::new();
    let d = downsample;
    for y in (0..res.y).step_by(d as usize) {
        for x in (0..res.x).step_by(d as usize) {
            let mut sum = [0.0f32; 3];
            let mut count = 0;
            for py in y..(y + d).min(res.y) {
                for px in x..(x + d).min(res.x) {
                    let i = (py as usize * res.x as usize + px as usize) * nc;
                    for k in 0..3 {
                        sum[k] += vals[i + rgb.offset[k]];
                    }
                    count += 1;
                }
            }
            let rgb_mean = sum.map(|s| s / count as f32);
            let fx = |x: i32| aspect * (1.0 - x as f32 / res.x as f32) - aspect / 2.0;
            let fy = |y: i32| 1.0 - y as f32 / res.y as f32;
            let (x0, x1) = (fx(x), fx((x + d).min(res.x)));
            let (y0, y1) = (fy(y), fy((y + d).min(res.y)));
            out.push(PixelEmitter {
                rgb: rgb_mean,
                corners: [[x0, y0], [x1, y0], [x0, y1], [x1, y1]],
            });
        }
    }
    Ok(out)
}

/// The pixels of `image` with their coordinates in the full image (offset
/// by the metadata's data window), in scanline order or, with `sort`, by
/// increasing channel average (pbrt-v4 `cat`).
pub fn pixel_listing(
    image: &Image,
    metadata: &ImageMetadata,
    sort: bool,
) -> Vec<(Point2i, Vec<f32>)> {
    let res = image.resolution();
    let origin = metadata
        .pixel_bounds
        .map(|b| b.p_min)
        .unwrap_or(Point2i::new(0, 0));
    let nc = image.n_channels().max(1);
    let mut v: Vec<(Point2i, Vec<f32>)> = image
        .to_f32_vec()
        .chunks_exact(nc)
        .enumerate()
        .map(|(i, px)| {
            let (x, y) = (i as i32 % res.x, i as i32 / res.x);
            (Point2i::new(x + origin.x, y + origin.y), px.to_vec())
        })
        .collect();
    if sort {
        let avg = |p: &[f32]| p.iter().sum::<f32>() / p.len().max(1) as f32;
        v.sort_by(|a, b| avg(&a.1).total_cmp(&avg(&b.1)));
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(v: f32, w: i32, h: i32) -> (Image, ImageMetadata) {
        (
            Image::from_f32(
                vec![v; (w * h * 3) as usize],
                Point2i::new(w, h),
                &["R", "G", "B"],
            )
            .unwrap(),
            ImageMetadata::default(),
        )
    }

    #[test]
    fn splitn_takes_slanted_strips_with_black_gaps() {
        // Two 30x2 images of 1 and 2. Row 0: x1 = 15 + (-1)(30/-15) = 17;
        // image 1 for x < 14, black for 14..20, image 2 from 20. Row 1:
        // x1 = 15 + 0 = 15: image 1 for x < 12, black 12..18.
        let s = splitn(&[flat(1.0, 30, 2), flat(2.0, 30, 2)], &[], 96).unwrap();
        assert!(s.crops.is_none());
        let v = s.image.to_f32_vec();
        let at = |x: usize, y: usize| v[(y * 30 + x) * 3];
        assert_eq!(at(13, 0), 1.0);
        assert_eq!(at(14, 0), 0.0);
        assert_eq!(at(19, 0), 0.0);
        assert_eq!(at(20, 0), 2.0);
        assert_eq!(at(11, 1), 1.0);
        assert_eq!(at(12, 1), 0.0);
        assert_eq!(at(18, 1), 2.0);
    }

    #[test]
    fn splitn_crops_are_framed_copies() {
        let s = splitn(
            &[flat(1.0, 20, 20), flat(2.0, 20, 20)],
            &[Point2i::new(5, 5)],
            4,
        )
        .unwrap();
        let c = s.crops.unwrap();
        // Cells of 4 + 2*5 = 14 pixels, 6 apart: 14*2 + 6 wide, 14 high.
        assert_eq!(c.resolution(), Point2i::new(34, 14));
        let v = c.to_f32_vec();
        let at = |x: usize, y: usize| &v[(y * 34 + x) * 3..(y * 34 + x) * 3 + 3];
        assert_eq!(at(5, 5), &[1.0, 1.0, 1.0]);
        assert_eq!(at(20 + 5, 5), &[2.0, 2.0, 2.0]);
        assert_eq!(at(0, 0), &SPLITN_EDGES[0]);
        // Between cells: white.
        assert_eq!(at(16, 7), &[1.0, 1.0, 1.0]);
        // The frame on the composite, just above the crop.
        let r = s.image.to_f32_vec();
        assert_eq!(&r[(4 * 20 + 5) * 3..(4 * 20 + 5) * 3 + 3], &SPLITN_EDGES[0]);
        assert!(splitn(&[flat(1.0, 20, 20)], &[Point2i::new(18, 0)], 4).is_err());
        assert!(splitn(&[flat(1.0, 20, 20), flat(1.0, 10, 20)], &[], 4).is_err());
    }

    #[test]
    fn emitters_cover_the_image_mirrored() {
        // 2x1 image: aspect 2; pixel 0 spans x from 1 to 0, pixel 1 from 0
        // to -1; y from 1 to 0.
        let im = Image::from_f32(
            vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            Point2i::new(2, 1),
            &["R", "G", "B"],
        )
        .unwrap();
        let e = make_emitters(&im, 1).unwrap();
        assert_eq!(e.len(), 2);
        assert_eq!(e[0].rgb, [1.0, 2.0, 3.0]);
        assert_eq!(
            e[0].corners,
            [[1.0, 1.0], [0.0, 1.0], [1.0, 0.0], [0.0, 0.0]]
        );
        assert_eq!(e[1].corners[1], [-1.0, 1.0]);
        // Downsampled by 2: one emitter, the mean.
        let e = make_emitters(&im, 2).unwrap();
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].rgb, [2.5, 3.5, 4.5]);
        assert_eq!(e[0].corners[3], [-1.0, 0.0]);
        assert!(make_emitters(&im, 0).is_err());
    }

    #[test]
    fn listing_offsets_and_sorts() {
        let im = Image::from_f32(vec![3.0, 1.0, 2.0], Point2i::new(3, 1), &["Y"]).unwrap();
        let md = ImageMetadata {
            pixel_bounds: Some(Bounds2i {
                p_min: Point2i::new(10, 20),
                p_max: Point2i::new(13, 21),
            }),
            ..Default::default()
        };
        let l = pixel_listing(&im, &md, false);
        assert_eq!(l[1], (Point2i::new(11, 20), vec![1.0]));
        let l = pixel_listing(&im, &md, true);
        let order: Vec<i32> = l.iter().map(|(p, _)| p.x).collect();
        assert_eq!(order, vec![11, 12, 10]);
    }
}
