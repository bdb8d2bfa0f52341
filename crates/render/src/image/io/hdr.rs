//! Radiance HDR (RGBE) files: a text header, a "-Y height +X width" resolution line, and
//! scanlines either flat or in the adaptive run-length encoding. Decoding matches
//! stb_image, which pbrt-v4 uses: value = byte * 2^(exponent - 136), zero when the
//! exponent byte is zero.

use super::{check_resolution, ByteReader, Claim, FmtResult, ImageAndMetadata, ImageMetadata};
use crate::image::Image;

fn line<'a>(r: &mut ByteReader<'a>) -> FmtResult<&'a [u8]> {
    let start = r.pos;
    while r.u8()? != b'\n' {
        if r.pos - start > 1024 {
            return Err("malformed HDR header".into());
        }
    }
    Ok(&r.data[start..r.pos - 1])
}

#[inline]
fn rgbe_to_float(p: &[u8], out: &mut Vec<f32>) {
    if p[3] == 0 {
        out.extend_from_slice(&[0.0; 3]);
    } else {
        let f = 2f32.powi(p[3] as i32 - 136);
        out.extend_from_slice(&[p[0] as f32 * f, p[1] as f32 * f, p[2] as f32 * f]);
    }
}

pub(super) fn read(data: &[u8], claim: &mut Claim) -> FmtResult<ImageAndMetadata> {
    let mut r = ByteReader::new(data);
    let magic = line(&mut r)?;
    if magic != b"#?RADIANCE" && magic != b"#?RGBE" {
        return Err("not a Radiance HDR file".into());
    }
    let mut format_ok = false;
    loop {
        let l = line(&mut r)?;
        if l.is_empty() {
            break;
        }
        if l == b"FORMAT=32-bit_rle_rgbe" {
            format_ok = true;
        } else if l.starts_with(b"FORMAT=") {
            return Err("unsupported HDR format (only 32-bit_rle_rgbe)".into());
        }
    }
    if !format_ok {
        return Err("HDR file lacks FORMAT=32-bit_rle_rgbe".into());
    }
    let res_line = std::str::from_utf8(line(&mut r)?).map_err(|_| "malformed HDR resolution")?;
    let f: Vec<&str> = res_line.split_whitespace().collect();
    if f.len() != 4 || f[0] != "-Y" || f[2] != "+X" {
        return Err("unsupported HDR orientation (only \"-Y height +X width\")".into());
    }
    let h: i64 = f[1].parse().map_err(|_| "malformed HDR height")?;
    let w: i64 = f[3].parse().map_err(|_| "malformed HDR width")?;
    let res = check_resolution(w, h)?;
    let (wu, hu) = (res.x as usize, res.y as usize);
    // Run-length data holds at least two bytes per 128 values of each of four components.
    let min_row = if (8..0x8000).contains(&wu) {
        4 + 8 * wu.div_ceil(128)
    } else {
        4 * wu
    };
    if hu.saturating_mul(min_row) > r.remaining() {
        return Err("premature end of file in HDR data".into());
    }
    claim.image(12 * (wu * hu) as u64, 4 * wu as u64)?;
    let mut px = Vec::with_capacity(wu * hu * 3);
    let mut flat = !(8..0x8000).contains(&wu);
    let mut scan = vec![0u8; 4 * wu];
    let mut y = 0;
    while y < hu {
        if flat {
            let b = r.bytes(4 * wu * (hu - y))?;
            for p in b.chunks_exact(4) {
                rgbe_to_float(p, &mut px);
            }
            break;
        }
        let head = r.bytes(4)?;
        if head[0] != 2 || head[1] != 2 || head[2] & 0x80 != 0 {
            // Not run-length encoded: the rest of the file is flat pixels.
            r.pos -= 4;
            flat = true;
            continue;
        }
        if ((head[2] as usize) << 8 | head[3] as usize) != wu {
            return Err("invalid HDR scanline width".into());
        }
        for c in 0..4 {
            let mut i = 0;
            while i < wu {
                let count = r.u8()? as usize;
                if count > 128 {
                    let n = count - 128;
                    let v = r.u8()?;
                    if i + n > wu {
                        return Err("corrupt HDR run length".into());
                    }
                    for k in 0..n {
                        scan[4 * (i + k) + c] = v;
                    }
                    i += n;
                } else {
                    if count == 0 || i + count > wu {
                        return Err("corrupt HDR run length".into());
                    }
                    let b = r.bytes(count)?;
                    for (k, &v) in b.iter().enumerate() {
                        scan[4 * (i + k) + c] = v;
                    }
                    i += count;
                }
            }
        }
        for p in scan.chunks_exact(4) {
            rgbe_to_float(p, &mut px);
        }
        y += 1;
    }
    let image = Image::from_f32(px, res, &["R", "G", "B"]).map_err(|e| e.to_string())?;
    Ok(ImageAndMetadata {
        image,
        metadata: ImageMetadata::default(),
    })
}
