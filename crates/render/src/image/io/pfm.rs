//! Portable float maps (PFM): "PF" (RGB) or "Pf" (grey), width, height, and a scale whose
//! sign gives the byte order (negative: little endian); rows stored bottom to top.

use super::{check_resolution, Claim, FmtResult, ImageAndMetadata, ImageMetadata};
use crate::image::Image;

fn is_space(b: u8) -> bool {
    b == b' ' || b == b'\n' || b == b'\t' || b == b'\r'
}

/// Next whitespace-delimited header word; consumes exactly one delimiter after it.
fn word<'a>(data: &'a [u8], pos: &mut usize) -> FmtResult<&'a str> {
    while *pos < data.len() && is_space(data[*pos]) {
        *pos += 1;
    }
    let start = *pos;
    while *pos < data.len() && !is_space(data[*pos]) {
        *pos += 1;
        if *pos - start > 80 {
            return Err("malformed PFM header".into());
        }
    }
    if *pos >= data.len() {
        return Err("premature end of file in PFM header".into());
    }
    let w = std::str::from_utf8(&data[start..*pos]).map_err(|_| "malformed PFM header")?;
    *pos += 1;
    Ok(w)
}

pub(super) fn read(data: &[u8], claim: &mut Claim) -> FmtResult<ImageAndMetadata> {
    let mut pos = 0;
    let nc = match word(data, &mut pos)? {
        "Pf" => 1usize,
        "PF" => 3,
        t => {
            return Err(format!(
                "unable to decode PFM file type \"{}\"",
                t.escape_default()
            ))
        }
    };
    let w: i64 = word(data, &mut pos)?
        .parse()
        .map_err(|_| "unable to decode PFM width")?;
    let h: i64 = word(data, &mut pos)?
        .parse()
        .map_err(|_| "unable to decode PFM height")?;
    let scale: f32 = word(data, &mut pos)?
        .parse()
        .map_err(|_| "unable to decode PFM scale")?;
    if !scale.is_finite() || scale == 0.0 {
        return Err("invalid PFM scale".into());
    }
    let res = check_resolution(w, h)?;
    let (wu, hu) = (res.x as usize, res.y as usize);
    let n = nc * wu * hu;
    if (data.len() - pos) / 4 < n {
        return Err("premature end of file in PFM data".into());
    }
    claim.image(4 * n as u64, 0)?;
    let little = scale < 0.0;
    let s = scale.abs();
    let mut px = vec![0.0f32; n];
    let row = nc * wu;
    for (i, chunk) in data[pos..pos + 4 * n].chunks_exact(4).enumerate() {
        let b = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let mut v = if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        if s != 1.0 {
            v *= s;
        }
        // File rows run bottom to top.
        let (fy, x) = (i / row, i % row);
        px[(hu - 1 - fy) * row + x] = v;
    }
    let names: &[&str] = if nc == 1 { &["Y"] } else { &["R", "G", "B"] };
    let image = Image::from_f32(px, res, names).map_err(|e| e.to_string())?;
    let metadata = ImageMetadata {
        color_space: Some("srgb".into()),
        ..Default::default()
    };
    Ok(ImageAndMetadata { image, metadata })
}

/// Writes little-endian PFM: grey images as "Pf", others (RGB) as "PF".
pub(super) fn write(image: &Image) -> FmtResult<Vec<u8>> {
    let nc = image.n_channels();
    if nc != 1 && nc != 3 {
        return Err(format!("PFM needs 1 or 3 channels, not {nc}"));
    }
    let res = image.resolution();
    let mut out = format!(
        "{}\n{} {}\n-1.000000\n",
        if nc == 1 { "Pf" } else { "PF" },
        res.x,
        res.y
    )
    .into_bytes();
    let vals = image.to_f32_vec();
    let row = nc * res.x as usize;
    out.reserve(4 * vals.len());
    for y in (0..res.y as usize).rev() {
        for v in &vals[y * row..(y + 1) * row] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(out)
}
