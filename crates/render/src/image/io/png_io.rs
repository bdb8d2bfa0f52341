//! PNG through the `png` crate. Reading follows pbrt-v4's `ReadPNG`: 8-bit data stays
//! 8-bit with the caller's encoding, 16-bit data is linearised into half floats.
//! Palettes and low bit depths are expanded; alpha is kept as an "A" channel that, as in
//! pbrt-v4, shares the colour encoding. Writing produces 8-bit sRGB with clamping (no
//! dither).

use std::io::Cursor;

use half::f16;

use super::{Claim, FmtResult, ImageAndMetadata, ImageMetadata};
use crate::image::{linear_to_srgb8, ColorEncoding, Image};

pub(super) fn read(
    data: &[u8],
    encoding: ColorEncoding,
    claim: &mut Claim,
) -> FmtResult<ImageAndMetadata> {
    let mut decoder =
        png::Decoder::new_with_limits(Cursor::new(data), png::Limits { bytes: 1 << 32 });
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let size = reader
        .output_buffer_size()
        .ok_or("PNG image is too large")?;
    let (w, h) = {
        let info = reader.info();
        (info.width, info.height)
    };
    let res = super::check_resolution(w as i64, h as i64)?;
    // The image takes about as many bytes as the decoder's rows.
    claim.image(size as u64, size as u64)?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    let names: &[&str] = match info.color_type {
        png::ColorType::Grayscale => &["Y"],
        png::ColorType::GrayscaleAlpha => &["Y", "A"],
        png::ColorType::Rgb => &["R", "G", "B"],
        png::ColorType::Rgba => &["R", "G", "B", "A"],
        png::ColorType::Indexed => return Err("unexpanded palette PNG".into()),
    };
    let nc = names.len();
    let (wu, hu) = (res.x as usize, res.y as usize);
    let sixteen = info.bit_depth == png::BitDepth::Sixteen;
    let bpc = if sixteen { 2 } else { 1 };
    if info.line_size < wu * nc * bpc || buf.len() < info.line_size * hu {
        return Err("unexpected PNG layout".into());
    }
    let sample = |y: usize, i: usize| -> f32 {
        let row = &buf[y * info.line_size..];
        if sixteen {
            u16::from_be_bytes([row[2 * i], row[2 * i + 1]]) as f32 / 65535.0
        } else {
            row[i] as f32 / 255.0
        }
    };
    let image = if !sixteen {
        let mut px = Vec::with_capacity(wu * hu * nc);
        for y in 0..hu {
            px.extend_from_slice(&buf[y * info.line_size..y * info.line_size + wu * nc]);
        }
        return Ok(ImageAndMetadata {
            image: image_from_8bit(px, res, names, encoding)?,
            metadata: ImageMetadata {
                color_space: (nc >= 3).then(|| "srgb".to_string()),
                ..Default::default()
            },
        });
    } else {
        let mut px = Vec::with_capacity(wu * hu * nc);
        for y in 0..hu {
            for i in 0..wu * nc {
                px.push(f16::from_f32(encoding.to_float_linear(sample(y, i))));
            }
        }
        Image::from_f16(px, res, names)
    }
    .map_err(|e| e.to_string())?;
    let metadata = ImageMetadata {
        color_space: (nc >= 3).then(|| "srgb".to_string()),
        ..Default::default()
    };
    Ok(ImageAndMetadata { image, metadata })
}

/// An image from interleaved 8-bit values; as in pbrt-v4, every channel (alpha
/// included) shares the encoding.
pub(super) fn image_from_8bit(
    px: Vec<u8>,
    res: rpbrt_geometry::Point2i,
    names: &[&str],
    encoding: ColorEncoding,
) -> FmtResult<Image> {
    Image::from_u8(px, res, names, encoding).map_err(|e| e.to_string())
}

/// 8-bit PNG: grey, RGB or RGBA. 8-bit images are written as stored; others are
/// sRGB-encoded with clamping to [0, 1].
pub(super) fn write(image: &Image) -> FmtResult<Vec<u8>> {
    let nc = image.n_channels();
    let color = match nc {
        1 => png::ColorType::Grayscale,
        3 => png::ColorType::Rgb,
        4 => png::ColorType::Rgba,
        _ => return Err(format!("PNG needs 1, 3 or 4 channels, not {nc}")),
    };
    let pixels = encode_8bit(image);
    let res = image.resolution();
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, res.x as u32, res.y as u32);
        enc.set_color(color);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(&pixels)
            .map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// Interleaved 8-bit values for writing: raw for `U256`, otherwise sRGB-encoded with
/// clamping (alpha too, matching how the readers decode it).
pub(super) fn encode_8bit(image: &Image) -> Vec<u8> {
    if let Some(v) = image.as_u8() {
        return v.to_vec();
    }
    image
        .to_f32_vec()
        .iter()
        .map(|&v| linear_to_srgb8(v))
        .collect()
}
