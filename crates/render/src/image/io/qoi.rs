//! The "Quite OK Image" format (QOI specification 1.0): a 14-byte header, then a stream
//! of RGB, RGBA, index, diff, luma and run operations, ended by seven zero bytes and a one.

use super::{check_resolution, png_io, Claim, FmtResult, ImageAndMetadata, ImageMetadata};
use crate::image::Image;

const OP_INDEX: u8 = 0x00;
const OP_DIFF: u8 = 0x40;
const OP_LUMA: u8 = 0x80;
const OP_RUN: u8 = 0xc0;
const OP_RGB: u8 = 0xfe;
const OP_RGBA: u8 = 0xff;
const END: [u8; 8] = [0, 0, 0, 0, 0, 0, 0, 1];

#[inline]
fn hash(p: [u8; 4]) -> usize {
    (p[0] as usize * 3 + p[1] as usize * 5 + p[2] as usize * 7 + p[3] as usize * 11) % 64
}

pub(super) fn read(
    data: &[u8],
    encoding: crate::image::ColorEncoding,
    claim: &mut Claim,
) -> FmtResult<ImageAndMetadata> {
    if data.len() < 14 + END.len() || &data[0..4] != b"qoif" {
        return Err("not a QOI file".into());
    }
    let w = u32::from_be_bytes([data[4], data[5], data[6], data[7]]);
    let h = u32::from_be_bytes([data[8], data[9], data[10], data[11]]);
    let channels = data[12] as usize;
    if channels != 3 && channels != 4 {
        return Err(format!("invalid QOI channel count {channels}"));
    }
    let res = check_resolution(w as i64, h as i64)?;
    let npix = res.x as usize * res.y as usize;
    let chunks = &data[14..data.len() - END.len()];
    // Every byte yields at most 62 pixels, so a short file cannot claim a huge image.
    if npix > 62 * chunks.len().max(1) {
        return Err("premature end of file in QOI data".into());
    }
    claim.image((npix * channels) as u64, 0)?;
    let mut out = Vec::with_capacity(npix * channels);
    let mut index = [[0u8; 4]; 64];
    let mut px = [0u8, 0, 0, 255];
    let mut run = 0usize;
    let mut p = 0usize;
    let next = |p: &mut usize| -> FmtResult<u8> {
        let b = *chunks.get(*p).ok_or("premature end of file in QOI data")?;
        *p += 1;
        Ok(b)
    };
    for _ in 0..npix {
        if run > 0 {
            run -= 1;
        } else {
            let b1 = next(&mut p)?;
            if b1 == OP_RGB {
                px[0] = next(&mut p)?;
                px[1] = next(&mut p)?;
                px[2] = next(&mut p)?;
            } else if b1 == OP_RGBA {
                for c in &mut px {
                    *c = next(&mut p)?;
                }
            } else {
                match b1 & 0xc0 {
                    OP_INDEX => px = index[b1 as usize],
                    OP_DIFF => {
                        px[0] = px[0].wrapping_add(((b1 >> 4) & 3).wrapping_sub(2));
                        px[1] = px[1].wrapping_add(((b1 >> 2) & 3).wrapping_sub(2));
                        px[2] = px[2].wrapping_add((b1 & 3).wrapping_sub(2));
                    }
                    OP_LUMA => {
                        let b2 = next(&mut p)?;
                        let vg = (b1 & 0x3f).wrapping_sub(32);
                        px[0] =
                            px[0].wrapping_add(vg.wrapping_sub(8).wrapping_add((b2 >> 4) & 0x0f));
                        px[1] = px[1].wrapping_add(vg);
                        px[2] = px[2].wrapping_add(vg.wrapping_sub(8).wrapping_add(b2 & 0x0f));
                    }
                    _ => run = (b1 & 0x3f) as usize,
                }
            }
            index[hash(px)] = px;
        }
        out.extend_from_slice(&px[..channels]);
    }
    let names: &[&str] = if channels == 3 {
        &["R", "G", "B"]
    } else {
        &["R", "G", "B", "A"]
    };
    let image = png_io::image_from_8bit(out, res, names, encoding)?;
    let metadata = ImageMetadata {
        color_space: Some("srgb".into()),
        ..Default::default()
    };
    Ok(ImageAndMetadata { image, metadata })
}

/// Encodes 8-bit sRGB QOI (grey images are written as RGB).
pub(super) fn write(image: &Image) -> FmtResult<Vec<u8>> {
    let nc = image.n_channels();
    let src = png_io::encode_8bit(image);
    let (channels, pixels): (usize, Vec<[u8; 4]>) = match nc {
        1 => (3, src.iter().map(|&v| [v, v, v, 255]).collect()),
        3 => (
            3,
            src.chunks_exact(3)
                .map(|c| [c[0], c[1], c[2], 255])
                .collect(),
        ),
        4 => (
            4,
            src.chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
        ),
        _ => return Err(format!("QOI needs 1, 3 or 4 channels, not {nc}")),
    };
    let res = image.resolution();
    let mut out = Vec::with_capacity(14 + pixels.len() * (channels + 1) + 8);
    out.extend_from_slice(b"qoif");
    out.extend_from_slice(&(res.x as u32).to_be_bytes());
    out.extend_from_slice(&(res.y as u32).to_be_bytes());
    out.push(channels as u8);
    out.push(0); // colour space byte: sRGB
    let mut index = [[0u8; 4]; 64];
    let mut prev = [0u8, 0, 0, 255];
    let mut run = 0u8;
    let n = pixels.len();
    for (i, &px) in pixels.iter().enumerate() {
        if px == prev {
            run += 1;
            if run == 62 || i + 1 == n {
                out.push(OP_RUN | (run - 1));
                run = 0;
            }
            continue;
        }
        if run > 0 {
            out.push(OP_RUN | (run - 1));
            run = 0;
        }
        let h = hash(px);
        if index[h] == px {
            out.push(OP_INDEX | h as u8);
        } else {
            index[h] = px;
            if px[3] == prev[3] {
                let vr = px[0].wrapping_sub(prev[0]) as i8;
                let vg = px[1].wrapping_sub(prev[1]) as i8;
                let vb = px[2].wrapping_sub(prev[2]) as i8;
                let vg_r = vr.wrapping_sub(vg);
                let vg_b = vb.wrapping_sub(vg);
                if (-2..2).contains(&vr) && (-2..2).contains(&vg) && (-2..2).contains(&vb) {
                    out.push(
                        OP_DIFF
                            | (((vr + 2) as u8) << 4)
                            | (((vg + 2) as u8) << 2)
                            | (vb + 2) as u8,
                    );
                } else if (-8..8).contains(&vg_r)
                    && (-32..32).contains(&vg)
                    && (-8..8).contains(&vg_b)
                {
                    out.push(OP_LUMA | (vg + 32) as u8);
                    out.push((((vg_r + 8) as u8) << 4) | (vg_b + 8) as u8);
                } else {
                    out.extend_from_slice(&[OP_RGB, px[0], px[1], px[2]]);
                }
            } else {
                out.extend_from_slice(&[OP_RGBA, px[0], px[1], px[2], px[3]]);
            }
        }
        prev = px;
    }
    out.extend_from_slice(&END);
    Ok(out)
}
