//! Truevision TGA: uncompressed and run-length-encoded true-colour, grey and
//! colour-mapped images (types 1, 2, 3, 9, 10, 11). As pbrt-v4 (through stb_image)
//! does, alpha is dropped: the result is "Y" or "R", "G", "B" with the caller's encoding.

use super::{
    check_resolution, png_io, ByteReader, Claim, FmtResult, ImageAndMetadata, ImageMetadata,
};
use crate::image::ColorEncoding;

/// Expands a 5-bit value to 8 bits.
fn expand5(v: u16) -> u8 {
    ((v as u32 & 31) * 255 / 31) as u8
}

/// Decodes one pixel of `bytes_pp` bytes (BGR(A) order, or 16-bit 5:5:5) into RGB or grey.
fn decode_pixel(p: &[u8], grey: bool, out: &mut Vec<u8>) {
    if grey {
        out.push(p[0]);
        return;
    }
    match p.len() {
        2 => {
            let v = u16::from_le_bytes([p[0], p[1]]);
            out.extend_from_slice(&[expand5(v >> 10), expand5(v >> 5), expand5(v)]);
        }
        _ => out.extend_from_slice(&[p[2], p[1], p[0]]),
    }
}

pub(super) fn read(
    data: &[u8],
    encoding: ColorEncoding,
    claim: &mut Claim,
) -> FmtResult<ImageAndMetadata> {
    let mut r = ByteReader::new(data);
    let id_len = r.u8()? as usize;
    let cmap_type = r.u8()?;
    let image_type = r.u8()?;
    let cmap_first = r.u16_le()? as usize;
    let cmap_len = r.u16_le()? as usize;
    let cmap_bits = r.u8()?;
    let _x0 = r.u16_le()?;
    let _y0 = r.u16_le()?;
    let w = r.u16_le()?;
    let h = r.u16_le()?;
    let bits = r.u8()?;
    let desc = r.u8()?;
    let rle = image_type >= 9;
    let base_type = if rle { image_type - 8 } else { image_type };
    if !(1..=3).contains(&base_type) || cmap_type > 1 {
        return Err(format!("unsupported TGA image type {image_type}"));
    }
    let mapped = base_type == 1;
    if mapped && (cmap_type != 1 || bits != 8) {
        return Err("unsupported colour-mapped TGA layout".into());
    }
    let grey = base_type == 3;
    if grey && bits != 8 {
        return Err(format!("unsupported {bits}-bit grey TGA"));
    }
    if base_type == 2 && ![15, 16, 24, 32].contains(&bits) {
        return Err(format!("unsupported {bits}-bit TGA"));
    }
    let res = check_resolution(w as i64, h as i64)?;
    r.bytes(id_len)?;
    // Colour map, decoded to RGB triples.
    let mut palette = Vec::new();
    if cmap_type == 1 {
        let entry = match cmap_bits {
            15 | 16 => 2,
            24 => 3,
            32 => 4,
            b => return Err(format!("unsupported TGA colour map entry size {b}")),
        };
        let bytes = r.bytes(entry * cmap_len)?;
        for e in bytes.chunks_exact(entry) {
            decode_pixel(e, false, &mut palette);
        }
    }
    let bpp = (bits as usize).div_ceil(8);
    let npix = res.x as usize * res.y as usize;
    if (!rle && r.remaining() / bpp < npix) || (rle && npix > 128 * r.remaining()) {
        return Err("premature end of file in TGA data".into());
    }
    let nc = if grey { 1 } else { 3 };
    claim.image((npix * nc) as u64, 0)?;
    let mut px = Vec::with_capacity(npix * nc);
    let put = |p: &[u8], px: &mut Vec<u8>| -> FmtResult<()> {
        if mapped {
            let i = (p[0] as usize)
                .checked_sub(cmap_first)
                .filter(|i| 3 * i + 3 <= palette.len())
                .ok_or("TGA colour-map index out of range")?;
            px.extend_from_slice(&palette[3 * i..3 * i + 3]);
        } else {
            decode_pixel(p, grey, px);
        }
        Ok(())
    };
    let mut count = 0;
    while count < npix {
        if rle {
            let head = r.u8()?;
            let n = (head & 0x7f) as usize + 1;
            if head & 0x80 != 0 {
                let p = r.bytes(bpp)?;
                for _ in 0..n.min(npix - count) {
                    put(p, &mut px)?;
                }
            } else {
                for _ in 0..n {
                    let p = r.bytes(bpp)?;
                    if px.len() / nc < npix {
                        put(p, &mut px)?;
                    }
                }
            }
            count = px.len() / nc;
        } else {
            let p = r.bytes(bpp)?;
            put(p, &mut px)?;
            count += 1;
        }
    }
    px.truncate(npix * nc);
    // Bit 5 of the descriptor set: rows stored top to bottom; otherwise bottom to top.
    let names: &[&str] = if grey { &["Y"] } else { &["R", "G", "B"] };
    let mut image = png_io::image_from_8bit(px, res, names, encoding)?;
    if desc & 0x20 == 0 {
        image.flip_y();
    }
    Ok(ImageAndMetadata {
        image,
        metadata: ImageMetadata::default(),
    })
}
