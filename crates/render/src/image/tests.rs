//! Tests of the image layer: encodings, wrap modes, file formats, MIP maps, diff.

use std::path::Path;

use half::f16;
use rpbrt_geometry::{Bounds2i, Point2f, Point2i, Vector2f};

use super::ops::{diff, info, rel_mse_trimmed, trimmed_mean};
use super::*;
use crate::rng::Rng;

fn p(x: i32, y: i32) -> Point2i {
    Point2i { x, y }
}

fn random_float_image(w: i32, h: i32, names: &[&str], seed: u64) -> Image {
    let mut rng = Rng::new(seed, 0);
    let n = (w * h) as usize * names.len();
    let v = (0..n).map(|_| rng.uniform_float() * 4.0 - 0.5).collect();
    Image::from_f32(v, p(w, h), names).unwrap()
}

fn random_u8_image(w: i32, h: i32, names: &[&str], seed: u64) -> Image {
    let mut rng = Rng::new(seed, 0);
    let n = (w * h) as usize * names.len();
    // Mix runs, small deltas and random values so every QOI operation occurs.
    let mut v = Vec::with_capacity(n);
    let mut last = 0u8;
    for i in 0..n {
        let r = rng.uniform_float();
        last = if r < 0.3 && i > 0 {
            last
        } else if r < 0.6 {
            last.wrapping_add((rng.uniform_float() * 5.0) as u8)
        } else {
            (rng.uniform_float() * 256.0) as u8
        };
        v.push(last);
    }
    Image::from_u8(v, p(w, h), names, ColorEncoding::SRGB).unwrap()
}

#[test]
fn encodings_round_trip_all_8bit_values() {
    for enc in [
        ColorEncoding::SRGB,
        ColorEncoding::Linear,
        ColorEncoding::Gamma(2.2),
    ] {
        for i in 0..=255u8 {
            assert_eq!(enc.from_linear(enc.to_linear(i)), i, "{enc:?} {i}");
        }
    }
    assert_eq!(srgb8_to_linear(0), 0.0);
    assert_eq!(srgb8_to_linear(255), 1.0);
    assert!((srgb8_to_linear(128) - 0.215_860_5).abs() < 1e-6);
    for i in 0..=1000 {
        let v = i as f32 / 1000.0;
        assert!((srgb_to_linear(linear_to_srgb(v)) - v).abs() < 1e-5);
    }
    assert_eq!(linear_to_srgb8(-1.0), 0);
    assert_eq!(linear_to_srgb8(f32::NAN), 0);
    assert_eq!(linear_to_srgb8(7.0), 255);
    assert_eq!(
        ColorEncoding::parse("gamma 2.2"),
        Some(ColorEncoding::Gamma(2.2))
    );
    assert_eq!(ColorEncoding::parse("sRGB"), Some(ColorEncoding::SRGB));
    assert_eq!(ColorEncoding::parse("bogus"), None);
}

#[test]
fn wrap_modes() {
    let res = p(4, 3);
    let w = |m: WrapMode| WrapMode2D::from(m);
    assert_eq!(
        remap_pixel_coords(p(-1, 5), res, w(WrapMode::Repeat)),
        Some(p(3, 2))
    );
    assert_eq!(
        remap_pixel_coords(p(9, -7), res, w(WrapMode::Repeat)),
        Some(p(1, 2))
    );
    assert_eq!(
        remap_pixel_coords(p(-1, 5), res, w(WrapMode::Clamp)),
        Some(p(0, 2))
    );
    assert_eq!(remap_pixel_coords(p(-1, 1), res, w(WrapMode::Black)), None);
    assert_eq!(
        remap_pixel_coords(p(2, 1), res, w(WrapMode::Black)),
        Some(p(2, 1))
    );
    let mixed = WrapMode2D::new(WrapMode::Repeat, WrapMode::Clamp);
    assert_eq!(remap_pixel_coords(p(5, 9), res, mixed), Some(p(1, 2)));
    // Octahedral: crossing u = 0 mirrors u and flips v about its centre; likewise for v.
    let o = w(WrapMode::OctahedralSphere);
    let r = p(4, 4);
    assert_eq!(remap_pixel_coords(p(-1, 0), r, o), Some(p(1, 3)));
    assert_eq!(remap_pixel_coords(p(4, 1), r, o), Some(p(3, 2)));
    assert_eq!(remap_pixel_coords(p(1, -1), r, o), Some(p(2, 1)));
    assert_eq!(remap_pixel_coords(p(1, 4), r, o), Some(p(2, 3)));
    assert_eq!(remap_pixel_coords(p(-1, -1), r, o), Some(p(2, 3)));
    assert_eq!(remap_pixel_coords(p(2, 2), r, o), Some(p(2, 2)));
    // Black gives zero through the lookups too.
    let img = Image::from_f32(vec![1.0; 12], res, &["Y"]).unwrap();
    assert_eq!(img.get_channel(p(-1, 0), 0, w(WrapMode::Black)), 0.0);
    assert_eq!(img.get_channel(p(-1, 0), 0, w(WrapMode::Clamp)), 1.0);
    // Octahedral continuity: the texel across the seam equals the mirrored one.
    let img = random_float_image(8, 8, &["Y"], 3);
    for y in 0..8 {
        assert_eq!(
            img.get_channel(p(-1, y), 0, o),
            img.get_channel(p(1, 7 - y), 0, o)
        );
    }
}

/// All channels at once give each channel's own bilinear value, for every
/// storage format (8-bit sRGB, half, float) and wrap mode, inside and
/// outside the image.
#[test]
fn bilerp_channels_into_matches_each_channel() {
    let float = random_float_image(7, 5, &["R", "G", "B"], 3);
    let half = float.convert_to_format(PixelFormat::Half, ColorEncoding::Linear);
    let u8_srgb = random_u8_image(7, 5, &["R", "G", "B"], 4);
    let mut rng = Rng::new(11, 0);
    for (img, wrap) in [&float, &half, &u8_srgb].into_iter().flat_map(|img| {
        [
            WrapMode::Clamp,
            WrapMode::Repeat,
            WrapMode::Black,
            WrapMode::OctahedralSphere,
        ]
        .map(|w| (img, w))
    }) {
        let wrap = match wrap {
            WrapMode::OctahedralSphere => WrapMode2D::new(wrap, wrap),
            w => WrapMode2D::new(w, WrapMode::Clamp),
        };
        for _ in 0..500 {
            let q = Point2f::new(
                rng.uniform_float() * 1.6 - 0.3,
                rng.uniform_float() * 1.6 - 0.3,
            );
            let mut all = [0.0f32; 3];
            img.bilerp_channels_into(q, wrap, &mut all);
            for (c, v) in all.iter().enumerate() {
                let want = img.bilerp_channel(q, c, wrap);
                assert_eq!(v.to_bits(), want.to_bits(), "{wrap:?} {q:?} {c}");
            }
        }
    }
}

#[test]
fn bilerp_and_channels() {
    let img = Image::from_f32(
        vec![0.0, 10.0, 1.0, 11.0, 2.0, 12.0, 3.0, 13.0],
        p(2, 2),
        &["R", "G"],
    )
    .unwrap();
    let c = WrapMode::Clamp.into();
    // At the image centre all four texels weigh equally.
    assert!((img.bilerp_channel(Point2f { x: 0.5, y: 0.5 }, 0, c) - 1.5).abs() < 1e-6);
    // At a texel centre the texel itself.
    assert_eq!(img.bilerp_channel(Point2f { x: 0.75, y: 0.25 }, 1, c), 11.0);
    let d = img.get_channel_desc(&["G", "R"]).unwrap();
    assert_eq!(&*img.get_channels_desc(p(1, 1), &d, c), &[13.0, 3.0]);
    assert!(img.get_channel_desc(&["B"]).is_none());
    let g = img.select_channels(&img.get_channel_desc(&["G"]).unwrap());
    assert_eq!(g.as_f32().unwrap(), &[10.0, 11.0, 12.0, 13.0]);
    let mut f = img.clone();
    f.flip_y();
    assert_eq!(&*f.get_channels(p(0, 0), c), &[2.0, 12.0]);
    let cr = img.crop(Bounds2i::new(p(1, 0), p(2, 2))).unwrap();
    assert_eq!(cr.as_f32().unwrap(), &[1.0, 11.0, 3.0, 13.0]);
    assert!(img.crop(Bounds2i::new(p(1, 0), p(3, 2))).is_err());
    // NaN is stored as zero; U256 conversion quantises.
    let mut h = img.convert_to_format(PixelFormat::Half, ColorEncoding::Linear);
    h.set_channel(p(0, 0), 0, f32::NAN);
    assert_eq!(h.get_channel(p(0, 0), 0, c), 0.0);
    let u = random_float_image(3, 3, &["Y"], 1)
        .convert_to_format(PixelFormat::U256, ColorEncoding::SRGB);
    assert_eq!(u.format(), PixelFormat::U256);
    let many = ImageChannelValues::new(6, 2.0);
    assert_eq!(many.len(), 6);
    assert_eq!(many.average(), 2.0);
}

fn round_trip(img: &Image, name: &str, md: &ImageMetadata) -> ImageAndMetadata {
    let bytes = img.encode(name, md).unwrap();
    Image::read_from_bytes(&bytes, name, None).unwrap()
}

fn assert_close(a: &Image, b: &Image, tol: f32) {
    assert_eq!(a.resolution(), b.resolution());
    assert_eq!(a.channel_names(), b.channel_names());
    for (x, y) in a.to_f32_vec().iter().zip(b.to_f32_vec()) {
        assert!((x - y).abs() <= tol * (1.0 + y.abs()), "{x} vs {y}");
    }
}

#[test]
fn exr_round_trips_with_metadata() {
    let img = random_float_image(13, 7, &["R", "G", "B", "A"], 5);
    let md = ImageMetadata {
        render_time_seconds: Some(12.5),
        camera_from_world: Some([
            [1.0, 2.0, 3.0, 4.0],
            [5.0, 6.0, 7.0, 8.0],
            [9.0, 10.0, 11.0, 12.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
        ndc_from_world: Some([
            [0.5, 0.0, 0.0, 0.0],
            [0.0, 0.5, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ]),
        pixel_bounds: Some(Bounds2i::new(p(3, 4), p(16, 11))),
        full_resolution: Some(p(20, 12)),
        samples_per_pixel: Some(64),
        estimated_variance: Some(0.25),
        mse: Some(0.125),
        color_space: Some("rec2020".into()),
        strings: [("note".to_string(), vec!["a".to_string(), "b c".to_string()])]
            .into_iter()
            .collect(),
    };
    let r = round_trip(&img, "x.exr", &md);
    assert_eq!(r.image.format(), PixelFormat::Float);
    // EXR sorts channels by name; compare through names.
    let d = r.image.get_channel_desc(&["R", "G", "B", "A"]).unwrap();
    assert_close(&r.image.select_channels(&d), &img, 0.0);
    assert_eq!(r.metadata, md);

    // Half images stay half, bit for bit; arbitrary channel names survive.
    let h = random_float_image(5, 9, &["Y", "depth.Z"], 9)
        .convert_to_format(PixelFormat::Half, ColorEncoding::Linear);
    let r = round_trip(&h, "h.EXR", &ImageMetadata::default());
    assert_eq!(r.image.format(), PixelFormat::Half);
    let d = r.image.get_channel_desc(&["Y", "depth.Z"]).unwrap();
    assert_eq!(r.image.select_channels(&d), h);
    assert_eq!(
        r.metadata.pixel_bounds,
        Some(Bounds2i::new(p(0, 0), p(5, 9)))
    );
    assert_eq!(r.metadata.full_resolution, Some(p(5, 9)));
    assert_eq!(r.metadata.color_space, None);
    // 8-bit images are written as half.
    let u = random_u8_image(4, 4, &["R", "G", "B"], 2);
    let r = round_trip(&u, "u.exr", &ImageMetadata::default());
    assert_eq!(r.image.format(), PixelFormat::Half);
    let d = r.image.get_channel_desc(&["R", "G", "B"]).unwrap();
    assert_close(&r.image.select_channels(&d), &u, 1e-3);
}

#[test]
fn pfm_round_trip_and_row_order() {
    let img = random_float_image(6, 4, &["R", "G", "B"], 7);
    let bytes = img.encode("a.pfm", &ImageMetadata::default()).unwrap();
    let header = b"PF\n6 4\n-1.000000\n";
    assert_eq!(&bytes[..header.len()], header);
    // The first stored row is the bottom one.
    let first = f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap());
    assert_eq!(first, img.get_channel(p(0, 3), 0, WrapMode::Clamp.into()));
    let r = Image::read_from_bytes(&bytes, "a.pfm", None).unwrap();
    assert_close(&r.image, &img, 0.0);
    // Grey, big endian, with a scale factor.
    let mut be = b"Pf\n2 2\n2.0\n".to_vec();
    for v in [1.0f32, 2.0, 3.0, 4.0] {
        be.extend_from_slice(&v.to_be_bytes());
    }
    let r = Image::read_from_bytes(&be, "b.pfm", None).unwrap().image;
    assert_eq!(r.channel_names(), &["Y"]);
    assert_eq!(r.as_f32().unwrap(), &[6.0, 8.0, 2.0, 4.0]);
    let g = random_float_image(3, 5, &["Y"], 8);
    assert_close(
        &round_trip(&g, "g.pfm", &ImageMetadata::default()).image,
        &g,
        0.0,
    );
    // RGBA drops alpha; RGB are reordered by name.
    let bgr = random_float_image(2, 2, &["B", "G", "R"], 4);
    let r = round_trip(&bgr, "c.pfm", &ImageMetadata::default()).image;
    let d = bgr.get_channel_desc(&["R", "G", "B"]).unwrap();
    assert_close(&r, &bgr.select_channels(&d), 0.0);
}

#[test]
fn png_round_trips() {
    for names in [&["Y"][..], &["R", "G", "B"], &["R", "G", "B", "A"]] {
        let u = random_u8_image(9, 5, names, 11);
        let r = round_trip(&u, "u.png", &ImageMetadata::default());
        assert_eq!(r.image, u);
    }
    // Float data is sRGB-encoded with clamping.
    let f = random_float_image(8, 8, &["R", "G", "B"], 12);
    let r = round_trip(&f, "f.png", &ImageMetadata::default()).image;
    assert_eq!(r.format(), PixelFormat::U256);
    for (x, y) in f.to_f32_vec().iter().zip(r.to_f32_vec()) {
        let want = ColorEncoding::SRGB.to_linear(linear_to_srgb8(*x));
        assert_eq!(want, y);
    }
    // The caller's encoding applies.
    let bytes = random_u8_image(2, 2, &["Y"], 3)
        .encode("l.png", &ImageMetadata::default())
        .unwrap();
    let lin = Image::read_from_bytes(&bytes, "l.png", Some(ColorEncoding::Linear))
        .unwrap()
        .image;
    assert_eq!(lin.encoding(), ColorEncoding::Linear);
    // 16-bit grey-alpha is read as linearised half floats.
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, 2, 1);
        enc.set_color(png::ColorType::GrayscaleAlpha);
        enc.set_depth(png::BitDepth::Sixteen);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[0xff, 0xff, 0x80, 0x00, 0x00, 0x00, 0xff, 0xff])
            .unwrap();
    }
    let r = Image::read_from_bytes(&out, "s.png", None).unwrap().image;
    assert_eq!(r.format(), PixelFormat::Half);
    assert_eq!(r.channel_names(), &["Y", "A"]);
    let v = r.to_f32_vec();
    assert_eq!(v[0], 1.0);
    assert!((v[1] - srgb_to_linear(32768.0 / 65535.0)).abs() < 1e-3);
    assert_eq!(v[2], 0.0);
    // Palette images expand to RGB.
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, 2, 1);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(vec![10, 20, 30, 200, 100, 0]);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[1, 0]).unwrap();
    }
    let r = Image::read_from_bytes(&out, "p.png", None).unwrap().image;
    assert_eq!(r.as_u8().unwrap(), &[200, 100, 0, 10, 20, 30]);
}

#[test]
fn qoi_round_trips() {
    for names in [&["R", "G", "B"][..], &["R", "G", "B", "A"]] {
        for (w, h, seed) in [(1, 1, 1), (17, 13, 2), (64, 3, 3)] {
            let u = random_u8_image(w, h, names, seed);
            let bytes = u.encode("q.qoi", &ImageMetadata::default()).unwrap();
            assert_eq!(&bytes[..4], b"qoif");
            assert_eq!(
                Image::read_from_bytes(&bytes, "q.qoi", None).unwrap().image,
                u
            );
        }
    }
    // A constant image compresses into runs.
    let c = Image::from_u8(
        vec![7; 3 * 100 * 100],
        p(100, 100),
        &["R", "G", "B"],
        ColorEncoding::SRGB,
    )
    .unwrap();
    let bytes = c.encode("c.qoi", &ImageMetadata::default()).unwrap();
    assert!(bytes.len() < 14 + 8 + 4 + 10_000 / 62 + 2);
    assert_eq!(
        Image::read_from_bytes(&bytes, "c.qoi", None).unwrap().image,
        c
    );
    // Grey float images become RGB.
    let g = random_float_image(4, 4, &["Y"], 5);
    let r = round_trip(&g, "g.qoi", &ImageMetadata::default()).image;
    assert_eq!(r.n_channels(), 3);
    let y = g.to_f32_vec();
    for (i, v) in r.to_f32_vec().chunks(3).enumerate() {
        assert_eq!(v[0], srgb8_to_linear(linear_to_srgb8(y[i])));
    }
}

fn tga_header(
    image_type: u8,
    cmap: Option<(u16, u8)>,
    w: u16,
    h: u16,
    bits: u8,
    desc: u8,
) -> Vec<u8> {
    let mut v = vec![0u8, cmap.is_some() as u8, image_type];
    let (len, size) = cmap.unwrap_or((0, 0));
    v.extend_from_slice(&0u16.to_le_bytes());
    v.extend_from_slice(&len.to_le_bytes());
    v.push(size);
    v.extend_from_slice(&[0, 0, 0, 0]);
    v.extend_from_slice(&w.to_le_bytes());
    v.extend_from_slice(&h.to_le_bytes());
    v.push(bits);
    v.push(desc);
    v
}

#[test]
fn tga_variants() {
    // Uncompressed BGR, bottom-up.
    let mut f = tga_header(2, None, 2, 2, 24, 0);
    f.extend_from_slice(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]);
    let r = Image::read_from_bytes(&f, "a.tga", None).unwrap().image;
    assert_eq!(r.as_u8().unwrap(), &[9, 8, 7, 12, 11, 10, 3, 2, 1, 6, 5, 4]);
    // RLE BGRA, top-down, a run crossing the row boundary; alpha dropped.
    let mut f = tga_header(10, None, 2, 2, 32, 0x28);
    f.extend_from_slice(&[0x82, 1, 2, 3, 255, 0x00, 4, 5, 6, 0]);
    let r = Image::read_from_bytes(&f, "b.tga", None).unwrap().image;
    assert_eq!(r.channel_names(), &["R", "G", "B"]);
    assert_eq!(r.as_u8().unwrap(), &[3, 2, 1, 3, 2, 1, 3, 2, 1, 6, 5, 4]);
    // Colour-mapped, 24-bit palette, RLE, top-down.
    let mut f = tga_header(9, Some((2, 24)), 3, 1, 8, 0x20);
    f.extend_from_slice(&[10, 20, 30, 40, 50, 60]);
    f.extend_from_slice(&[0x81, 1, 0x00, 0]);
    let r = Image::read_from_bytes(&f, "c.tga", None).unwrap().image;
    assert_eq!(r.as_u8().unwrap(), &[60, 50, 40, 60, 50, 40, 30, 20, 10]);
    // Grey and 16-bit 5:5:5.
    let mut f = tga_header(3, None, 1, 1, 8, 0);
    f.push(77);
    assert_eq!(
        Image::read_from_bytes(&f, "d.tga", None)
            .unwrap()
            .image
            .as_u8()
            .unwrap(),
        &[77]
    );
    let mut f = tga_header(2, None, 1, 1, 16, 0);
    f.extend_from_slice(&(31u16 << 10).to_le_bytes());
    assert_eq!(
        Image::read_from_bytes(&f, "e.tga", None)
            .unwrap()
            .image
            .as_u8()
            .unwrap(),
        &[255, 0, 0]
    );
    // A colour-map index outside the palette is an error.
    let mut f = tga_header(1, Some((1, 24)), 1, 1, 8, 0);
    f.extend_from_slice(&[1, 2, 3, 5]);
    assert!(Image::read_from_bytes(&f, "f.tga", None).is_err());
}

#[test]
fn hdr_flat_and_rle() {
    // RLE scanlines of width 8: each component is one run.
    let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n".to_vec();
    for row in 0..2u8 {
        f.extend_from_slice(&[2, 2, 0, 8]);
        for c in 0..4u8 {
            let v = if c == 3 { 129 + row } else { 64 * (c + 1) };
            f.extend_from_slice(&[128 + 8, v]);
        }
    }
    let r = Image::read_from_bytes(&f, "a.hdr", None).unwrap().image;
    assert_eq!(r.resolution(), p(8, 2));
    let v = r.to_f32_vec();
    // byte * 2^(e - 136): 64 * 2^-7 = 0.5 in row 0, 1.0 in row 1.
    assert_eq!(&v[..3], &[0.5, 1.0, 1.5]);
    assert_eq!(&v[24..27], &[1.0, 2.0, 3.0]);
    // Literal runs too: width 8 as one literal of 8 bytes per component.
    let mut f = b"#?RGBE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n".to_vec();
    f.extend_from_slice(&[2, 2, 0, 8]);
    for c in 0..4u8 {
        f.push(8);
        f.extend((0..8u8).map(|i| if c == 3 { 128 + 8 } else { i * (c + 1) }));
    }
    let v = Image::read_from_bytes(&f, "b.hdr", None)
        .unwrap()
        .image
        .to_f32_vec();
    assert_eq!(&v[3 * 5..3 * 6], &[5.0, 10.0, 15.0]);
    // Narrow images are flat; a zero exponent gives zero.
    let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
    f.extend_from_slice(&[128, 64, 32, 129, 9, 9, 9, 0]);
    let v = Image::read_from_bytes(&f, "c.hdr", None)
        .unwrap()
        .image
        .to_f32_vec();
    assert_eq!(v, vec![1.0, 0.5, 0.25, 0.0, 0.0, 0.0]);
}

#[test]
fn garbage_and_truncated_files_are_errors() {
    let mut rng = Rng::new(99, 0);
    let mut files: Vec<(&str, Vec<u8>)> = Vec::new();
    let md = ImageMetadata::default();
    let f = random_float_image(9, 7, &["R", "G", "B"], 1);
    let u = random_u8_image(9, 7, &["R", "G", "B"], 2);
    files.push(("t.exr", f.encode("t.exr", &md).unwrap()));
    files.push(("t.pfm", f.encode("t.pfm", &md).unwrap()));
    files.push(("t.png", u.encode("t.png", &md).unwrap()));
    files.push(("t.qoi", u.encode("t.qoi", &md).unwrap()));
    let mut tga = tga_header(2, None, 9, 7, 24, 0);
    tga.extend(std::iter::repeat_n(5, 9 * 7 * 3));
    files.push(("t.tga", tga));
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n".to_vec();
    for _ in 0..2 {
        hdr.extend_from_slice(&[2, 2, 0, 8]);
        for _ in 0..4 {
            hdr.extend_from_slice(&[136, 130]);
        }
    }
    files.push(("t.hdr", hdr));
    for (name, bytes) in &files {
        assert!(Image::read_from_bytes(bytes, name, None).is_ok(), "{name}");
        for cut in [
            0,
            1,
            3,
            10,
            bytes.len() / 3,
            bytes.len() / 2,
            bytes.len() - 13,
        ] {
            let r = Image::read_from_bytes(&bytes[..cut], name, None);
            let e = r.expect_err(&format!("{name} truncated to {cut} should fail"));
            assert!(e.to_string().starts_with(name), "{e}");
        }
        for _ in 0..50 {
            let len = (rng.uniform_float() * 300.0) as usize;
            let mut g: Vec<u8> = (0..len)
                .map(|_| (rng.uniform_float() * 256.0) as u8)
                .collect();
            let _ = Image::read_from_bytes(&g, name, None);
            // Corrupt a valid file in a few places.
            g = bytes.clone();
            for _ in 0..4 {
                let i = (rng.uniform_float() * g.len() as f32) as usize % g.len();
                g[i] = (rng.uniform_float() * 256.0) as u8;
            }
            let _ = Image::read_from_bytes(&g, name, None);
        }
    }
    assert!(Image::read_from_bytes(b"abc", "x.jpg", None).is_err());
    let e = Image::read("/nonexistent/dir/x.png", None).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/dir/x.png"));
    // Writing formats that cannot hold the channels fails cleanly.
    let two = random_float_image(2, 2, &["U", "V"], 1);
    assert!(two.encode("x.png", &md).is_err());
    assert!(two.encode("x.pfm", &md).is_err());
    assert!(two.encode("x.exr", &md).is_ok());
    assert!(f.encode("x.bmp", &md).is_err());
}

fn constant_image(w: i32, h: i32, v: [f32; 3]) -> Image {
    let data = (0..w * h).flat_map(|_| v).collect();
    Image::from_f32(data, p(w, h), &["R", "G", "B"]).unwrap()
}

#[test]
fn pyramid_shapes_and_resampling() {
    let img = constant_image(5, 3, [0.25, 0.5, 1.0]);
    let pyr = Image::generate_pyramid(&img, WrapMode::Clamp.into());
    let res: Vec<Point2i> = pyr.iter().map(|i| i.resolution()).collect();
    assert_eq!(res, vec![p(8, 4), p(4, 2), p(2, 1), p(1, 1)]);
    for level in &pyr {
        for px in level.to_f32_vec().chunks(3) {
            for (a, b) in px.iter().zip([0.25, 0.5, 1.0]) {
                assert!((a - b).abs() < 1e-5, "{a} {b}");
            }
        }
    }
    // Levels keep the original format.
    let u = random_u8_image(4, 4, &["R", "G", "B"], 4);
    assert!(Image::generate_pyramid(&u, WrapMode::Repeat.into())
        .iter()
        .all(|l| l.format() == PixelFormat::U256));
    // The top of a power-of-two pyramid is the mean.
    let f = random_float_image(8, 8, &["Y"], 6);
    let pyr = Image::generate_pyramid(&f, WrapMode::Repeat.into());
    let mean = f.average(&f.all_channels_desc())[0];
    assert!((pyr[3].to_f32_vec()[0] - mean).abs() < 1e-5);
    // Windowed-sinc weights are normalised.
    for w in super::resample::resample_weights(5, 8) {
        assert!((w.weight.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }
}

const FILTERS: [FilterFunction; 4] = [
    FilterFunction::Point,
    FilterFunction::Bilinear,
    FilterFunction::Trilinear,
    FilterFunction::EWA,
];

#[test]
fn mipmap_constant_filters_to_constant() {
    let c = [0.3, 0.6, 0.9];
    let img = constant_image(16, 8, c);
    let grey = Image::from_f32(vec![0.6; 16 * 8], p(16, 8), &["Y"]).unwrap();
    let mut rng = Rng::new(5, 0);
    for filter in FILTERS {
        for wrap in [
            WrapMode::Repeat,
            WrapMode::Clamp,
            WrapMode::OctahedralSphere,
        ] {
            let opts = MIPMapFilterOptions {
                filter,
                max_anisotropy: 8.0,
            };
            let m = MIPMap::new(img.clone(), "srgb", wrap, opts);
            let mg = MIPMap::new(grey.clone(), "srgb", wrap, opts);
            for level in 0..m.levels() {
                let r = m.level_resolution(level);
                assert_eq!(m.texel_rgb(level, p(r.x - 1, 0)), c);
            }
            for i in 0..200 {
                let st = Point2f {
                    x: rng.uniform_float(),
                    y: rng.uniform_float(),
                };
                // Footprints from tiny to wider than the image, isotropic and anisotropic.
                let scale = 10f32.powf(-4.0 + 5.0 * (i as f32 / 200.0));
                let d0 = Vector2f {
                    x: scale * rng.uniform_float(),
                    y: scale * (rng.uniform_float() - 0.5),
                };
                let d1 = Vector2f {
                    x: -scale * rng.uniform_float() * 0.1,
                    y: scale * rng.uniform_float(),
                };
                let v = m.filter_rgb(st, d0, d1);
                for k in 0..3 {
                    assert!((v[k] - c[k]).abs() < 1e-5, "{filter:?} {wrap:?} {v:?}");
                }
                let f = mg.filter_float(st, d0, d1);
                assert!((f - 0.6).abs() < 1e-5, "{filter:?} {f}");
            }
            assert_eq!(
                m.filter_rgb(
                    Point2f { x: 0.5, y: 0.5 },
                    Vector2f::default(),
                    Vector2f::default()
                ),
                c
            );
        }
    }
}

#[test]
fn mipmap_checkerboard_averages_at_coarse_levels() {
    let n = 64;
    let data = (0..n * n)
        .map(|i| (((i % n) + (i / n)) % 2) as f32)
        .collect();
    let img = Image::from_f32(data, p(n, n), &["Y"]).unwrap();
    for filter in [
        FilterFunction::Trilinear,
        FilterFunction::Bilinear,
        FilterFunction::EWA,
    ] {
        let m = MIPMap::new(
            img.clone(),
            "srgb",
            WrapMode::Repeat,
            MIPMapFilterOptions {
                filter,
                max_anisotropy: 8.0,
            },
        );
        let mut rng = Rng::new(8, 0);
        for _ in 0..100 {
            let st = Point2f {
                x: rng.uniform_float(),
                y: rng.uniform_float(),
            };
            // A footprint of 4 to 16 texels lands on level 2 or coarser.
            let w = (4.0 + 12.0 * rng.uniform_float()) / n as f32;
            let v = m.filter_float(st, Vector2f { x: w, y: 0.0 }, Vector2f { x: 0.0, y: w });
            assert!((v - 0.5).abs() < 1e-5, "{filter:?} {v}");
        }
        // At the finest level a texel centre returns the texel itself.
        let bil = MIPMap::new(
            img.clone(),
            "srgb",
            WrapMode::Repeat,
            MIPMapFilterOptions {
                filter: FilterFunction::Bilinear,
                max_anisotropy: 8.0,
            },
        );
        let st = Point2f {
            x: 1.5 / n as f32,
            y: 0.5 / n as f32,
        };
        assert_eq!(
            bil.filter_float(
                st,
                Vector2f { x: 1e-4, y: 0.0 },
                Vector2f { x: 0.0, y: 1e-4 }
            ),
            1.0
        );
    }
    // Point sampling at level 0 picks the nearest texel.
    let m = MIPMap::new(
        img.clone(),
        "srgb",
        WrapMode::Repeat,
        MIPMapFilterOptions {
            filter: FilterFunction::Point,
            max_anisotropy: 8.0,
        },
    );
    let v = m.filter_float(
        Point2f {
            x: 2.4 / n as f32,
            y: 0.6 / n as f32,
        },
        Vector2f { x: 1e-5, y: 0.0 },
        Vector2f::default(),
    );
    assert_eq!(v, 0.0);
}

#[test]
fn ewa_matches_direct_gaussian_weighting() {
    // EWA of a linear ramp in s, symmetric footprint: the weighted mean is the ramp value.
    let n = 32;
    let data = (0..n * n).map(|i| (i % n) as f32).collect();
    let img = Image::from_f32(data, p(n, n), &["Y"]).unwrap();
    let m = MIPMap::new(
        img.clone(),
        "srgb",
        WrapMode::Clamp,
        MIPMapFilterOptions::default(),
    );
    let st = Point2f {
        x: 16.0 / n as f32,
        y: 0.5,
    };
    let v = m.filter_float(
        st,
        Vector2f {
            x: 0.5 / n as f32,
            y: 0.0,
        },
        Vector2f {
            x: 0.0,
            y: 0.5 / n as f32,
        },
    );
    assert!((v - 15.5).abs() < 1e-3, "{v}");
}

#[test]
fn mipmap_cache_reads_each_file_once() {
    let dir = std::env::temp_dir().join(format!("rpbrt-image-cache-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tex.png");
    random_u8_image(8, 8, &["R", "G", "B", "A"], 3)
        .write(&path, &ImageMetadata::default())
        .unwrap();
    let cache = std::sync::Arc::new(MIPMapCache::new());
    let opts = MIPMapFilterOptions::default();
    let threads: Vec<_> = (0..4)
        .map(|_| {
            let cache = cache.clone();
            let path = path.clone();
            std::thread::spawn(move || {
                cache
                    .get_or_load(&path, opts, WrapMode::Repeat, ColorEncoding::SRGB)
                    .unwrap()
            })
        })
        .collect();
    let maps: Vec<_> = threads.into_iter().map(|t| t.join().unwrap()).collect();
    assert!(maps.iter().all(|m| std::sync::Arc::ptr_eq(m, &maps[0])));
    assert_eq!(cache.files_read(), 1);
    assert_eq!(maps[0].level(0).map(|l| l.n_channels()), Some(4));
    cache
        .get_or_load(&path, opts, WrapMode::Clamp, ColorEncoding::SRGB)
        .unwrap();
    cache
        .get_or_load(&path, opts, WrapMode::Repeat, ColorEncoding::Linear)
        .unwrap();
    assert_eq!(cache.files_read(), 3);
    assert!(cache
        .get_or_load(
            dir.join("missing.png"),
            opts,
            WrapMode::Repeat,
            ColorEncoding::SRGB
        )
        .is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn diff_stats_on_known_images() {
    let a = Image::from_f32(vec![1.0, 2.0, 3.0, 4.0], p(2, 2), &["Y"]).unwrap();
    let b = Image::from_f32(vec![1.0, 2.0, 3.0, 2.0], p(2, 2), &["Y"]).unwrap();
    let d = diff(&a, &b).unwrap();
    assert_eq!(d.mse, 1.0);
    assert!((d.rel_mse - 4.0 / 4.01 / 4.0).abs() < 1e-12);
    assert_eq!(d.mean_a, 2.5);
    assert_eq!(d.mean_b, 2.0);
    assert_eq!(d.max_abs_diff, 2.0);
    assert_eq!(d.differing_pixels, 1);
    // Nearest-rank medians: the 2nd of 4 values.
    assert_eq!(d.median_a, 2.0);
    assert_eq!(d.median_b, 2.0);
    assert_eq!(diff(&a, &a).unwrap().mse, 0.0);
    // Dropping 0.1% of 1000 pixels removes exactly the one outlier.
    let n = 1000;
    let mut va = vec![1.0f32; n];
    va[17] = 100.0;
    let big_a = Image::from_f32(va, p(100, 10), &["Y"]).unwrap();
    let big_b = Image::from_f32(vec![1.0; n], p(100, 10), &["Y"]).unwrap();
    assert!(diff(&big_a, &big_b).unwrap().rel_mse > 9.0);
    assert_eq!(rel_mse_trimmed(&big_a, &big_b, 0.001).unwrap(), 0.0);
    assert_eq!(diff(&big_a, &big_b).unwrap().rel_mse_trimmed, 0.0);
    assert_eq!(trimmed_mean(vec![1.0, f64::NAN, 3.0], 0.34), 2.0);
    // Channels are matched by name.
    let rgb = random_float_image(3, 3, &["R", "G", "B"], 1);
    let bgr = rgb.select_channels(&rgb.get_channel_desc(&["B", "G", "R"]).unwrap());
    assert_eq!(diff(&rgb, &bgr).unwrap().mse, 0.0);
    // A pixel's brightness is the mean of its channels.
    let two = Image::from_f32(
        vec![0.0, 3.0, 6.0, 1.0, 1.0, 1.0],
        p(2, 1),
        &["R", "G", "B"],
    )
    .unwrap();
    assert_eq!(diff(&two, &two).unwrap().median_a, 1.0);
    assert!(diff(&rgb, &a).is_err());
    let y = Image::from_f32(vec![0.0; 9], p(3, 3), &["Y"]).unwrap();
    assert!(diff(&y, &rgb).is_err());
}

#[test]
fn info_and_edits() {
    let img = Image::from_f32(
        vec![1.0, f32::NAN, -2.0, f32::INFINITY, 3.0, 0.5],
        p(3, 1),
        &["A", "B"],
    )
    .unwrap();
    let i = info(&img);
    assert_eq!(i.channels[0].min, -2.0);
    assert_eq!(i.channels[0].max, 3.0);
    assert!((i.channels[0].average - 2.0 / 3.0).abs() < 1e-9);
    assert_eq!(i.channels[1].nan_count, 1);
    assert_eq!(i.channels[1].inf_count, 1);
    assert_eq!(i.channels[1].average, 0.5);
    assert!(i.to_string().contains("3x1"));
    let e = img.apply_exposure(1.0);
    assert_eq!(e.as_f32().unwrap()[4], 6.0);
    let c = img.clamp_values(0.0, 1.0);
    assert_eq!(c.as_f32().unwrap(), &[1.0, 0.0, 0.0, 1.0, 1.0, 0.5]);
}

fn shared(path: &str) -> Option<std::path::PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared")
        .join(path);
    let alt = Path::new("/work/shared").join(path);
    [p, alt].into_iter().find(|p| p.exists())
}

#[test]
fn reads_shared_scene_images() {
    for name in [
        "scenes/cornell-box/TungstenRender.exr",
        "scenes/cornell-box/ref-256-pbrtv4-1024spp.exr",
    ] {
        let Some(path) = shared(name) else { continue };
        let r = Image::read(&path, None).unwrap();
        let img = &r.image;
        assert!(img.resolution().x > 0 && img.resolution().y > 0);
        let d = img
            .get_channel_desc(&["R", "G", "B"])
            .expect("RGB channels");
        let avg = img.average(&d);
        assert!(
            avg.iter().all(|v| v.is_finite() && *v > 0.0),
            "{name}: {avg:?}"
        );
        // Write and reread the same data bit for bit.
        let bytes = img.encode("x.exr", &r.metadata).unwrap();
        let back = Image::read_from_bytes(&bytes, "x.exr", None).unwrap();
        assert_eq!(back.image, r.image);
        assert_eq!(back.metadata, r.metadata);
    }
    if let Some(dir) = shared("scenes/hair-curl/textures") {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) == Some("pfm") {
                let img = Image::read(&path, None).unwrap().image;
                assert_eq!(img.format(), PixelFormat::Float);
                let i = info(&img);
                assert!(
                    i.channels.iter().all(|c| c.nan_count == 0),
                    "{}",
                    path.display()
                );
                let m = MIPMap::new(
                    img.clone(),
                    "srgb",
                    WrapMode::OctahedralSphere,
                    MIPMapFilterOptions::default(),
                );
                let v = m.filter_rgb(
                    Point2f { x: 0.3, y: 0.7 },
                    Vector2f { x: 0.01, y: 0.0 },
                    Vector2f { x: 0.0, y: 0.01 },
                );
                assert!(v.iter().all(|x| x.is_finite()));
            }
        }
    }
    let _ = f16::ONE;
}

#[test]
fn writes_replace_the_file_whole_and_leave_no_temporary_files() {
    let dir = std::env::temp_dir().join(format!("rpbrt-atomic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.pfm");
    let image = |v: f32| Image::from_f32(vec![v; 2 * 2 * 3], Point2i::new(2, 2), &["R", "G", "B"]);
    image(1.0)
        .unwrap()
        .write(&path, &Default::default())
        .unwrap();
    image(2.0)
        .unwrap()
        .write(&path, &Default::default())
        .unwrap();
    let back = Image::read(&path, None).unwrap().image;
    assert_eq!(back.to_f32_vec(), vec![2.0; 12]);
    // A target that cannot be replaced (a directory) is an error that
    // leaves no temporary file behind.
    let sub = dir.join("sub.pfm");
    std::fs::create_dir_all(&sub).unwrap();
    assert!(image(3.0)
        .unwrap()
        .write(&sub, &Default::default())
        .is_err());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["out.pfm", "sub.pfm"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn average_of_images_counts_infinities_as_zero_and_refuses_mismatches() {
    use crate::image::ops::average;
    let res = Point2i::new(2, 1);
    let a = Image::from_f32(vec![1.0, 2.0, f32::INFINITY, 4.0], res, &["R", "G"]).unwrap();
    let b = Image::from_f32(vec![3.0, 4.0, 1.0, 0.0], res, &["R", "G"]).unwrap();
    let avg = average(&[a.clone(), b.clone()]).unwrap();
    assert_eq!(avg.to_f32_vec(), vec![2.0, 3.0, 0.5, 2.0]);
    assert_eq!(avg.channel_names(), ["R", "G"]);
    let nan = Image::from_f32(vec![0.0, f32::NAN, 0.0, 0.0], res, &["R", "G"]).unwrap();
    let e = average(&[a.clone(), nan]).unwrap_err().to_string();
    assert!(
        e.contains("image 1") && e.contains("NaN at pixel (0, 0)"),
        "{e}"
    );
    let other = Image::from_f32(vec![0.0; 4], Point2i::new(1, 2), &["R", "G"]).unwrap();
    assert!(average(&[a.clone(), other])
        .unwrap_err()
        .to_string()
        .contains("resolution"));
    let chans = Image::from_f32(vec![0.0; 4], res, &["R", "B"]).unwrap();
    assert!(average(&[a, chans])
        .unwrap_err()
        .to_string()
        .contains("channels"));
    assert!(average(&[]).is_err());
}

/// Found by the data-file fuzzer: an EXR whose data window claims a vast
/// image made the decoder allocate hundreds of terabytes and abort the
/// process. The header is now checked first.
#[test]
fn exr_with_a_vast_data_window_is_an_error() {
    let im = Image::new(
        PixelFormat::Float,
        Point2i::new(4, 2),
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    let path = std::env::temp_dir().join(format!("rpbrt-vast-{}.exr", std::process::id()));
    im.write(&path, &ImageMetadata::default()).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let key = b"dataWindow\0box2i\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("a data window")
        + key.len()
        + 4;
    // xMax and yMax of the box.
    bytes[at + 8..at + 12].copy_from_slice(&0x3FFF_FFFFi32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&0x3FFF_FFFFi32.to_le_bytes());
    let e = Image::read_from_bytes(&bytes, "vast.exr", None).expect_err("vast");
    assert!(
        e.to_string().contains("too large") || e.to_string().contains("invalid"),
        "{e}"
    );
}

/// A data window that passes the fixed pixel limit but is far more than
/// the file holds (30000² RGB float, 10.8 GB, from a file of a few hundred
/// bytes) made `imgtool info` allocate gigabytes: it is held against the
/// file's size now.
#[test]
fn exr_header_size_claims_are_checked_against_the_file() {
    let im = Image::new(
        PixelFormat::Float,
        Point2i::new(4, 2),
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    let good = im.encode("a.exr", &ImageMetadata::default()).unwrap();
    // The undamaged file still reads.
    let r = Image::read_from_bytes(&good, "a.exr", None).unwrap();
    assert_eq!(r.image.resolution, Point2i::new(4, 2));
    let key = b"dataWindow\0box2i\0";
    let at = good
        .windows(key.len())
        .position(|w| w == key)
        .expect("a data window")
        + key.len()
        + 4;
    let t = std::time::Instant::now();
    // Tall (many chunks) and wide (one chunk of vast lines).
    for (x_max, y_max) in [(29_999i32, 29_999i32), ((1 << 29) - 1, 0), (3, 1 << 20)] {
        let mut bytes = good.clone();
        bytes[at + 8..at + 12].copy_from_slice(&x_max.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&y_max.to_le_bytes());
        let e = Image::read_from_bytes(&bytes, "damaged.exr", None)
            .expect_err("a damaged header was decoded");
        assert!(
            e.to_string().contains("damaged header"),
            "{x_max}x{y_max}: {e}"
        );
    }
    // A file cut short after its header is refused by the same check.
    let header_end = good.len() - 40;
    assert!(Image::read_from_bytes(&good[..header_end], "cut.exr", None).is_err());
    assert!(t.elapsed() < std::time::Duration::from_secs(5));
}

#[test]
fn channel_lists_keep_commas_of_spectral_names() {
    use crate::image::ops::split_channel_list;
    let avail: Vec<String> = ["R", "G", "S0.418,750nm", "S0.431,250nm"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(
        split_channel_list("R,S0.418,750nm,G", &avail),
        ["R", "S0.418,750nm", "G"]
    );
    assert_eq!(split_channel_list("Q,R", &avail), ["Q", "R"]);
    assert_eq!(split_channel_list("S0.418", &avail), ["S0.418"]);
}

/// pbrt-v4's `GeneratePyramid` for a power-of-two image, written out: the
/// image in floats, each level the 2x2 mean of the one above, every level
/// stored converted back to the image's format.
fn reference_pyramid(img: &Image) -> Vec<Image> {
    let (format, enc, nc) = (img.format(), img.encoding(), img.n_channels());
    let names: Vec<&str> = img.channel_names().iter().map(|s| s.as_str()).collect();
    let mut f = img.convert_to_format(PixelFormat::Float, enc);
    let mut out = Vec::new();
    loop {
        let fl = Image::from_f32(f.to_f32_vec(), f.resolution(), &names).unwrap();
        out.push(fl.convert_to_format(format, enc));
        let r = f.resolution();
        if r.x == 1 && r.y == 1 {
            return out;
        }
        let v = f.to_f32_vec();
        let (nx, ny) = ((r.x / 2).max(1), (r.y / 2).max(1));
        let at = |x: i32, y: i32, c: usize| {
            v[((y.min(r.y - 1) * r.x + x.min(r.x - 1)) as usize) * nc + c]
        };
        let mut next = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                for c in 0..nc {
                    next.push(
                        0.25 * (at(2 * x, 2 * y, c)
                            + at(2 * x + 1, 2 * y, c)
                            + at(2 * x, 2 * y + 1, c)
                            + at(2 * x + 1, 2 * y + 1, c)),
                    );
                }
            }
        }
        f = Image::from_f32(next, p(nx, ny), &names).unwrap();
    }
}

/// The stored bits of every value of `img`, with its format and encoding.
fn stored_bits(img: &Image) -> (PixelFormat, ColorEncoding, Point2i, Vec<u32>) {
    let bits = match img.format() {
        PixelFormat::U256 => img.as_u8().unwrap().iter().map(|&b| u32::from(b)).collect(),
        _ => img.to_f32_vec().iter().map(|v| v.to_bits()).collect(),
    };
    (img.format(), img.encoding(), img.resolution(), bits)
}

#[test]
fn pyramids_are_pbrt_v4s_bit_for_bit() {
    let mut images = Vec::new();
    for (w, h) in [(1, 1), (1, 8), (8, 1), (16, 4), (32, 32)] {
        for (k, enc) in [
            ColorEncoding::SRGB,
            ColorEncoding::Linear,
            ColorEncoding::Gamma(2.2),
        ]
        .into_iter()
        .enumerate()
        {
            let u = random_u8_image(w, h, &["R", "G", "B"], 10 + k as u64);
            let data = u.as_u8().unwrap().to_vec();
            images.push(Image::from_u8(data, p(w, h), &["R", "G", "B"], enc).unwrap());
        }
        let mut f = random_float_image(w, h, &["R", "G", "B", "A"], 20).to_f32_vec();
        let halves: Vec<half::f16> = f.iter().map(|&v| half::f16::from_f32(v)).collect();
        images.push(Image::from_f16(halves.clone(), p(w, h), &["R", "G", "B", "A"]).unwrap());
        f[1] = f32::NAN;
        let mut nan_halves = halves;
        nan_halves[2] = half::f16::NAN;
        images.push(Image::from_f32(f, p(w, h), &["R", "G", "B", "A"]).unwrap());
        images.push(Image::from_f16(nan_halves, p(w, h), &["R", "G", "B", "A"]).unwrap());
    }
    for img in &images {
        let want: Vec<_> = reference_pyramid(img).iter().map(stored_bits).collect();
        let got: Vec<_> = img.clone().into_pyramid(WrapMode::Repeat.into());
        let got: Vec<_> = got.iter().map(stored_bits).collect();
        assert_eq!(got, want, "{:?} {:?}", img.format(), img.encoding());
    }
}

#[test]
fn fast_srgb8_encoding_is_the_formulas() {
    // Around every code's threshold, and a sweep of the whole range.
    let mut checked = 0;
    let mut at = |v: f32| {
        assert_eq!(linear_to_srgb8(v), linear_to_srgb8_exact(v), "{v:e}");
        checked += 1;
    };
    for code in 0..=255u8 {
        let mid = if code == 0 {
            0.0
        } else {
            srgb8_to_linear(code)
        };
        let lo = srgb8_to_linear(code.saturating_sub(1));
        // Bisect down to the threshold between lo and mid, then test the
        // floats on either side of it.
        let (mut a, mut b) = (lo.to_bits(), mid.to_bits());
        while b > a + 1 {
            let m = a + (b - a) / 2;
            if linear_to_srgb8_exact(f32::from_bits(m)) >= code {
                b = m;
            } else {
                a = m;
            }
        }
        for bits in b.saturating_sub(300)..b + 300 {
            at(f32::from_bits(bits));
        }
    }
    for i in 0..=1_000_000u32 {
        at(i as f32 / 1_000_000.0);
    }
    for v in [
        -0.0,
        1e-45,
        1e-38,
        0.003_130_8,
        0.999_999_94,
        1.0,
        f32::INFINITY,
    ] {
        at(v);
    }
    assert!(checked > 1_000_000);
}

/// Every kind of lookup of `a` and `b` at fixed-seed random places and
/// footprints, compared bit for bit.
fn assert_same_lookups(a: &MIPMap, b: &MIPMap, seed: u64) {
    assert_n_same_lookups(a, b, seed, 2000);
}

/// [`assert_same_lookups`] with `n` places.
fn assert_n_same_lookups(a: &MIPMap, b: &MIPMap, seed: u64, n: usize) {
    assert_eq!(a.levels(), b.levels());
    let mut rng = Rng::new(seed, 0);
    for _ in 0..n {
        let st = Point2f {
            x: rng.uniform_float() * 3.0 - 1.0,
            y: rng.uniform_float() * 3.0 - 1.0,
        };
        let d = |rng: &mut Rng| Vector2f {
            x: (rng.uniform_float() - 0.5) * 0.2,
            y: (rng.uniform_float() - 0.5) * 0.2,
        };
        let (d0, d1) = (d(&mut rng), d(&mut rng));
        let level = (rng.uniform_float() * a.levels() as f32) as usize;
        let sti = Point2i {
            x: (st.x * 40.0) as i32,
            y: (st.y * 40.0) as i32,
        };
        let bits = |v: [f32; 3]| v.map(f32::to_bits);
        assert_eq!(
            bits(a.filter_rgb(st, d0, d1)),
            bits(b.filter_rgb(st, d0, d1))
        );
        assert_eq!(
            a.filter_float(st, d0, d1).to_bits(),
            b.filter_float(st, d0, d1).to_bits()
        );
        assert_eq!(bits(a.bilerp_rgb(level, st)), bits(b.bilerp_rgb(level, st)));
        assert_eq!(
            a.bilerp_float(level, st).to_bits(),
            b.bilerp_float(level, st).to_bits()
        );
        assert_eq!(bits(a.texel_rgb(level, sti)), bits(b.texel_rgb(level, sti)));
        assert_eq!(
            a.texel_float(level, sti).to_bits(),
            b.texel_float(level, sti).to_bits()
        );
    }
}

/// A fresh folder under the temporary one for a texture cache test.
fn cache_test_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-tiles-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn tiled_maps_look_up_what_maps_in_memory_do() {
    use super::tiled::TileCache;
    use std::sync::Arc;
    let dir = cache_test_dir("same");
    // 8-bit RGB, RGBA and grey; half and float; a power of two and not;
    // a tile and a half wide.
    let files = [
        ("rgb.png", random_u8_image(96, 64, &["R", "G", "B"], 1)),
        (
            "rgba.png",
            random_u8_image(32, 32, &["R", "G", "B", "A"], 2),
        ),
        ("grey.png", random_u8_image(70, 33, &["Y"], 3)),
        ("half.exr", {
            let f = random_float_image(128, 16, &["R", "G", "B"], 4).to_f32_vec();
            let h = f.iter().map(|&v| half::f16::from_f32(v)).collect();
            Image::from_f16(h, p(128, 16), &["R", "G", "B"]).unwrap()
        }),
        ("float.pfm", random_float_image(50, 20, &["R", "G", "B"], 5)),
    ];
    for (name, img) in &files {
        img.write(dir.join(name), &ImageMetadata::default())
            .unwrap();
    }
    // Big enough for every tile; smaller than one tile (nothing kept).
    for capacity in [1 << 24, 1000] {
        let tiles = Arc::new(TileCache::new(capacity, dir.join("cache")));
        let tiled = MIPMapCache::new().with_tiles(tiles.clone());
        let memory = MIPMapCache::new();
        let mut maps = Vec::new();
        for (k, (name, _)) in files.iter().enumerate() {
            for wrap in [WrapMode::Repeat, WrapMode::Black, WrapMode::Clamp] {
                // More maps than files are kept open: the first are
                // opened again when looked up at the end.
                for (filter, max_anisotropy) in FILTERS.iter().flat_map(|&f| [(f, 8.0), (f, 2.0)]) {
                    let opts = MIPMapFilterOptions {
                        filter,
                        max_anisotropy,
                    };
                    let enc = if name.ends_with(".png") {
                        ColorEncoding::SRGB
                    } else {
                        ColorEncoding::Linear
                    };
                    let path = dir.join(name);
                    let a = tiled.get_or_load(&path, opts, wrap, enc).unwrap();
                    let b = memory.get_or_load(&path, opts, wrap, enc).unwrap();
                    assert!(a.is_tiled() && !b.is_tiled());
                    assert_eq!(a.color_space(), b.color_space());
                    assert_same_lookups(&a, &b, k as u64);
                    maps.push((a, b));
                }
            }
        }
        assert_eq!(maps.len(), 120);
        assert!(tiles.open_files() <= 64);
        for (k, (a, b)) in maps.iter().enumerate() {
            assert_n_same_lookups(a, b, 100 + k as u64, 50);
        }
        let st = tiles.stats();
        assert!(st.misses > 0);
        if capacity == 1000 {
            assert_eq!(st.hits, 0, "a cache smaller than a tile keeps none");
        } else {
            assert!(st.hits > st.misses);
        }
        assert!(tiles.take_warnings().is_empty());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn tiled_maps_are_never_stale_and_mend_corrupt_files() {
    use super::tiled::TileCache;
    use std::sync::Arc;
    let dir = cache_test_dir("stale");
    let path = dir.join("t.png");
    let opts = MIPMapFilterOptions::default();
    let load = |tiles: &Arc<TileCache>| {
        MIPMapCache::new()
            .with_tiles(tiles.clone())
            .get_or_load(&path, opts, WrapMode::Repeat, ColorEncoding::SRGB)
            .unwrap()
    };
    let in_memory = || {
        MIPMapCache::new()
            .get_or_load(&path, opts, WrapMode::Repeat, ColorEncoding::SRGB)
            .unwrap()
    };
    let cache_dir = dir.join("cache");
    let run = || Arc::new(TileCache::new(1 << 20, cache_dir.clone()));
    random_u8_image(64, 64, &["R", "G", "B"], 7)
        .write(&path, &ImageMetadata::default())
        .unwrap();
    let first = run();
    assert_same_lookups(&load(&first), &in_memory(), 1);
    assert_eq!((first.stats().converted, first.stats().reused), (1, 0));
    // A later run reuses the file.
    let second = run();
    assert_same_lookups(&load(&second), &in_memory(), 2);
    assert_eq!((second.stats().converted, second.stats().reused), (0, 1));
    // The image changes (same name, same size): converted again, and the
    // lookups are the new image's.
    random_u8_image(64, 64, &["R", "G", "B"], 8)
        .write(&path, &ImageMetadata::default())
        .unwrap();
    let third = run();
    assert_same_lookups(&load(&third), &in_memory(), 3);
    assert_eq!((third.stats().converted, third.stats().reused), (1, 0));
    // A byte of a pyramid file flipped, and one cut short: both rebuilt.
    let pyramid = std::fs::read_dir(&cache_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .max_by_key(|p| std::fs::metadata(p).unwrap().modified().unwrap())
        .unwrap();
    let mut bytes = std::fs::read(&pyramid).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&pyramid, &bytes).unwrap();
    let fourth = run();
    assert_same_lookups(&load(&fourth), &in_memory(), 4);
    assert_eq!((fourth.stats().converted, fourth.stats().reused), (1, 0));
    let whole = std::fs::read(&pyramid).unwrap();
    std::fs::write(&pyramid, &whole[..whole.len() - 100]).unwrap();
    let fifth = run();
    assert_same_lookups(&load(&fifth), &in_memory(), 5);
    assert_eq!((fifth.stats().converted, fifth.stats().reused), (1, 0));
    assert_eq!(std::fs::read(&pyramid).unwrap(), whole);
    // A folder that cannot be made (under a file): in memory, one warning.
    let blocked = Arc::new(TileCache::new(1 << 20, path.join("cache")));
    let m = load(&blocked);
    assert!(!m.is_tiled());
    assert_same_lookups(&m, &in_memory(), 6);
    MIPMapCache::new()
        .with_tiles(blocked.clone())
        .get_or_load(&path, opts, WrapMode::Clamp, ColorEncoding::SRGB)
        .unwrap();
    let warnings = blocked.take_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("cannot be used"), "{}", warnings[0]);
    std::fs::remove_dir_all(&dir).ok();
}
