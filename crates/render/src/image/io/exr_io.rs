//! OpenEXR through the `exr` crate: any channels, half or float, with pbrt-v4's
//! metadata attributes (pbrt-v4 `ReadEXR`, `WriteEXR`). Of a multi-part file, every part
//! of the first part's size is read, a named part's channels as "<part>.<channel>";
//! channels of mixed sample types are read as float.

use std::collections::HashMap;
use std::io::Cursor;

use exr::math::Vec2;
use exr::meta::attribute::{AttributeValue, Chromaticities, IntegerBounds, Text};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Layer, LayerAttributes, ReadChannels,
    ReadLayers, SmallVec, WritableImage,
};
use half::f16;
use rpbrt_geometry::{Bounds2i, Point2i};

use super::{Claim, FmtResult, ImageAndMetadata, ImageMetadata};
use crate::image::{Image, PixelFormat};

/// Primaries and white point (x, y) of the colour spaces pbrt-v4 knows by name.
const COLOR_SPACES: [(&str, [[f32; 2]; 4]); 4] = [
    (
        "srgb",
        [[0.64, 0.33], [0.3, 0.6], [0.15, 0.06], [0.3127, 0.329]],
    ),
    (
        "dci-p3",
        [[0.68, 0.32], [0.265, 0.69], [0.15, 0.06], [0.3127, 0.329]],
    ),
    (
        "rec2020",
        [
            [0.708, 0.292],
            [0.17, 0.797],
            [0.131, 0.046],
            [0.3127, 0.329],
        ],
    ),
    (
        "aces2065-1",
        [
            [0.7347, 0.2653],
            [0.0, 1.0],
            [0.0001, -0.077],
            [0.32168, 0.33767],
        ],
    ),
];

fn lookup_color_space(c: &Chromaticities) -> &'static str {
    let got = [c.red, c.green, c.blue, c.white];
    for (name, prim) in COLOR_SPACES {
        let close = got
            .iter()
            .zip(prim)
            .all(|(g, p)| (g.0 - p[0]).abs() < 1e-3 && (g.1 - p[1]).abs() < 1e-3);
        if close {
            return name;
        }
    }
    // pbrt-v4 falls back to sRGB (with a warning) for unknown chromaticities.
    "srgb"
}

fn to_matrix(m: &[f32; 16]) -> [[f32; 4]; 4] {
    let mut r = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            r[i][j] = m[4 * i + j];
        }
    }
    r
}

fn from_matrix(m: &[[f32; 4]; 4]) -> [f32; 16] {
    let mut r = [0.0; 16];
    for i in 0..4 {
        for j in 0..4 {
            r[4 * i + j] = m[i][j];
        }
    }
    r
}

/// The most bytes of raw samples one byte of a chunk's stored data can
/// stand for under `compression`: a bound on what a file of a given size
/// can honestly hold. Deflate (ZIP, and PXR24 after its 32-to-24-bit
/// rounding) stops near 1032:1; PIZ's run-length Huffman code needs at
/// least 9 bits for a run of 255 half values; RLE stores a run of at most
/// 128 bytes in 2; B44A packs a flat 4×4 block of halves (32 bytes) in 3.
fn max_expansion(compression: exr::compression::Compression) -> u64 {
    use exr::compression::Compression as C;
    match compression {
        C::Uncompressed => 1,
        C::RLE => 64,
        C::B44 | C::B44A => 11,
        C::ZIP1 | C::ZIP16 | C::PIZ => 1100,
        // PXR24 and anything the decoder may add later.
        _ => 1400,
    }
}

/// Checks the headers' claims before the decoder allocates for them: a
/// corrupted size or channel count must be an error, not an allocation
/// that aborts the process. Beyond fixed limits, the claims are held
/// against the bytes actually in the file: each chunk needs an 8-byte
/// offset-table entry, and the samples must fit the stored data at the
/// compression's best ratio ([`max_expansion`]). What passes is charged
/// to the memory budget: the image, with the decoder's samples beside it.
fn check_headers(data: &[u8], claim: &mut Claim) -> FmtResult<()> {
    let mut cursor = Cursor::new(data);
    let meta = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        exr::meta::MetaData::read_from_buffered(&mut cursor, false)
    }))
    .map_err(|_| "EXR header decoder failed on malformed data".to_string())?
    .map_err(|e| e.to_string())?;
    let after_headers = data.len() as u64 - cursor.position().min(data.len() as u64);
    let mut total: u64 = 0;
    let mut chunks: u64 = 0;
    let mut expandable: u64 = 0;
    // The decoder's samples, and the image made of them (floats, or
    // halves when every channel is half).
    let mut decoded: u64 = 0;
    let mut all_half = true;
    for h in &meta.headers {
        let (w, hgt) = (h.layer_size.0 as u64, h.layer_size.1 as u64);
        super::check_resolution(
            w.min(i64::MAX as u64) as i64,
            hgt.min(i64::MAX as u64) as i64,
        )?;
        let channels = h.channels.list.len() as u64;
        total = total.saturating_add((w * hgt).saturating_mul(channels.max(1)));
        chunks = chunks.saturating_add(h.chunk_count as u64);
        let bytes_per_pixel: u64 = h
            .channels
            .list
            .iter()
            .map(|c| c.sample_type.bytes_per_sample() as u64)
            .sum();
        let raw = (w * hgt).saturating_mul(bytes_per_pixel);
        decoded = decoded.saturating_add(raw);
        all_half &= bytes_per_pixel == 2 * channels;
        // Samples per byte of stored data, scaled so headers of different
        // compressions add up: raw / ratio, rounded up.
        expandable = expandable.saturating_add(raw.div_ceil(max_expansion(h.compression)));
    }
    // Every sample is decoded to at most four bytes.
    if total > super::MAX_PIXELS * 4 {
        return Err(format!(
            "EXR file claims {total} samples, more than the supported {}",
            super::MAX_PIXELS * 4
        ));
    }
    if chunks.saturating_mul(8) > after_headers {
        return Err(format!(
            "EXR header claims {chunks} chunks, but the file has only {after_headers} bytes \
             after its header (truncated file or damaged header)"
        ));
    }
    let stored = after_headers - chunks * 8;
    if !meta.headers.iter().any(|h| h.deep) && expandable > stored {
        return Err(format!(
            "EXR header claims more pixel data than {stored} stored bytes can hold \
             (truncated file or damaged header)"
        ));
    }
    let image = if all_half {
        decoded
    } else {
        total.saturating_mul(4)
    };
    claim.image(image, decoded)
}

pub(super) fn read(data: &[u8], claim: &mut Claim) -> FmtResult<ImageAndMetadata> {
    check_headers(data, claim)?;
    // The exr crate is defensive, but a panic inside it must not escape to the caller.
    let decoded = std::panic::catch_unwind(|| {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .non_parallel()
            .from_buffered(Cursor::new(data))
    })
    .map_err(|_| "EXR decoder failed on malformed data".to_string())?
    .map_err(|e| e.to_string())?;

    let layer = decoded.layer_data.first().ok_or("EXR file has no layers")?;
    let (w, h) = (layer.size.0, layer.size.1);
    let res = super::check_resolution(w as i64, h as i64)?;
    // Every layer (part) of the first one's size contributes its channels;
    // a named layer's channels are called "<layer>.<channel>", OpenEXR's
    // multi-layer naming, unless they already carry that prefix.
    let mut channels: Vec<(String, &FlatSamples)> = Vec::new();
    for l in &decoded.layer_data {
        if l.size != layer.size || l.attributes.layer_position != layer.attributes.layer_position {
            continue;
        }
        let prefix = l.attributes.layer_name.as_ref().map(|n| n.to_string());
        for c in &l.channel_data.list {
            let name = c.name.to_string();
            let name = match &prefix {
                Some(p) if !p.is_empty() && !name.starts_with(&format!("{p}.")) => {
                    format!("{p}.{name}")
                }
                _ => name,
            };
            if channels.iter().any(|(n, _)| *n == name) {
                return Err(format!("EXR file has channel \"{name}\" twice"));
            }
            channels.push((name, &c.sample_data));
        }
    }
    if channels.is_empty() {
        return Err("EXR layer has no channels".into());
    }
    let names: Vec<String> = channels.iter().map(|(n, _)| n.clone()).collect();
    let nc = channels.len();
    let npix = w * h;
    let all_half = channels
        .iter()
        .all(|(_, c)| matches!(c, FlatSamples::F16(_)));
    for (_, c) in &channels {
        let len = match c {
            FlatSamples::F16(v) => v.len(),
            FlatSamples::F32(v) => v.len(),
            FlatSamples::U32(v) => v.len(),
        };
        if len != npix {
            return Err("EXR channel sizes do not match the data window".into());
        }
    }
    let image = if all_half {
        let mut px = vec![f16::ZERO; npix * nc];
        for (ci, (_, c)) in channels.iter().enumerate() {
            if let FlatSamples::F16(v) = c {
                for (i, &s) in v.iter().enumerate() {
                    px[i * nc + ci] = s;
                }
            }
        }
        Image::from_f16(px, res, &names)
    } else {
        let mut px = vec![0.0f32; npix * nc];
        for (ci, (_, c)) in channels.iter().enumerate() {
            for i in 0..npix {
                px[i * nc + ci] = match c {
                    FlatSamples::F16(v) => v[i].to_f32(),
                    FlatSamples::F32(v) => v[i],
                    FlatSamples::U32(v) => v[i] as f32,
                };
            }
        }
        Image::from_f32(px, res, &names)
    }
    .map_err(|e| e.to_string())?;

    let la = &layer.attributes;
    let ia = &decoded.attributes;
    let get = |name: &str| -> Option<&AttributeValue> {
        let key = Text::new_or_none(name)?;
        la.other.get(&key).or_else(|| ia.other.get(&key))
    };
    let f32_attr = |name: &str| match get(name) {
        Some(AttributeValue::F32(v)) => Some(*v),
        _ => None,
    };
    let mut metadata = ImageMetadata {
        render_time_seconds: f32_attr("renderTimeSeconds"),
        camera_from_world: la.world_to_camera.as_ref().map(to_matrix),
        ndc_from_world: la.world_to_normalized_device.as_ref().map(to_matrix),
        pixel_bounds: Some(Bounds2i::new(
            Point2i {
                x: la.layer_position.0,
                y: la.layer_position.1,
            },
            Point2i {
                x: la.layer_position.0 + res.x,
                y: la.layer_position.1 + res.y,
            },
        )),
        full_resolution: Some(Point2i {
            x: ia.display_window.size.0 as i32,
            y: ia.display_window.size.1 as i32,
        }),
        samples_per_pixel: match get("samplesPerPixel") {
            Some(AttributeValue::I32(v)) => Some(*v),
            _ => None,
        },
        estimated_variance: f32_attr("estimatedVariance"),
        mse: f32_attr("MSE"),
        color_space: ia
            .chromaticities
            .as_ref()
            .map(|c| lookup_color_space(c).to_string()),
        strings: Default::default(),
    };
    for (k, v) in la.other.iter().chain(ia.other.iter()) {
        if let AttributeValue::TextVector(list) = v {
            metadata
                .strings
                .insert(k.to_string(), list.iter().map(|t| t.to_string()).collect());
        }
    }
    Ok(ImageAndMetadata { image, metadata })
}

fn text(s: &str) -> FmtResult<Text> {
    Text::new_or_none(s).ok_or_else(|| format!("\"{s}\" cannot be stored as EXR text"))
}

/// Writes all channels as half (8-bit and half images) or float, ZIP-compressed
/// scanlines, with pbrt-v4's attributes.
pub(super) fn write(image: &Image, md: &ImageMetadata) -> FmtResult<Vec<u8>> {
    let res = image.resolution();
    if res.x <= 0 || res.y <= 0 || image.n_channels() == 0 {
        return Err("cannot write an empty image".into());
    }
    let nc = image.n_channels();
    let npix = res.x as usize * res.y as usize;
    let vals = image.to_f32_vec();
    let half = image.format() != PixelFormat::Float;
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (ci, name) in image.channel_names().iter().enumerate() {
        let samples = (0..npix).map(|i| vals[i * nc + ci]);
        let data = if half {
            FlatSamples::F16(samples.map(f16::from_f32).collect())
        } else {
            FlatSamples::F32(samples.collect())
        };
        list.push(AnyChannel::new(text(name)?, data));
    }
    let mut attrs = LayerAttributes::default();
    if let Some(b) = md.pixel_bounds {
        attrs.layer_position = Vec2(b.p_min.x, b.p_min.y);
    }
    attrs.world_to_camera = md.camera_from_world.as_ref().map(from_matrix);
    attrs.world_to_normalized_device = md.ndc_from_world.as_ref().map(from_matrix);
    let mut other: HashMap<Text, AttributeValue> = HashMap::new();
    if let Some(t) = md.render_time_seconds {
        other.insert(text("renderTimeSeconds")?, AttributeValue::F32(t));
    }
    if let Some(s) = md.samples_per_pixel {
        other.insert(text("samplesPerPixel")?, AttributeValue::I32(s));
    }
    if let Some(v) = md.estimated_variance {
        other.insert(text("estimatedVariance")?, AttributeValue::F32(v));
    }
    if let Some(v) = md.mse {
        other.insert(text("MSE")?, AttributeValue::F32(v));
    }
    for (k, v) in &md.strings {
        let list = v.iter().map(|s| text(s)).collect::<FmtResult<Vec<_>>>()?;
        other.insert(text(k)?, AttributeValue::TextVector(list));
    }
    attrs.other = other;
    let layer = Layer::new(
        Vec2(res.x as usize, res.y as usize),
        attrs,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let mut out = exr::image::Image::from_layer(layer);
    let full = md.full_resolution.unwrap_or(res);
    if full.x <= 0 || full.y <= 0 {
        return Err("invalid full resolution in metadata".into());
    }
    out.attributes.display_window =
        IntegerBounds::new(Vec2(0, 0), Vec2(full.x as usize, full.y as usize));
    // As pbrt-v4, chromaticities are written only for colour spaces other than sRGB.
    if let Some(name) = md.color_space.as_deref().filter(|n| *n != "srgb") {
        let (_, p) = COLOR_SPACES
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| format!("unknown colour space \"{name}\""))?;
        out.attributes.chromaticities = Some(Chromaticities {
            red: Vec2(p[0][0], p[0][1]),
            green: Vec2(p[1][0], p[1][1]),
            blue: Vec2(p[2][0], p[2][1]),
            white: Vec2(p[3][0], p[3][1]),
        });
    }
    let mut buf = Cursor::new(Vec::new());
    out.write()
        .non_parallel()
        .to_buffered(&mut buf)
        .map_err(|e| e.to_string())?;
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use exr::prelude::{ImageAttributes, WritableImage};

    fn layer(name: &str, chans: &[(&str, [f32; 2])]) -> Layer<AnyChannels<FlatSamples>> {
        let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = chans
            .iter()
            .map(|(n, v)| AnyChannel::new(Text::new_or_panic(*n), FlatSamples::F32(v.to_vec())))
            .collect();
        Layer::new(
            Vec2(2, 1),
            LayerAttributes::named(Text::new_or_panic(name)),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(list),
        )
    }

    #[test]
    fn multi_part_files_read_every_layer_with_prefixed_names() {
        let layers: SmallVec<[_; 2]> = [
            layer("diffuse", &[("R", [1.0, 2.0]), ("G", [3.0, 4.0])]),
            layer("specular", &[("specular.B", [5.0, 6.0])]),
        ]
        .into_iter()
        .collect();
        let im = exr::image::Image::from_layers(
            ImageAttributes::new(IntegerBounds::from_dimensions(Vec2(2, 1))),
            layers,
        );
        let mut buf = Cursor::new(Vec::new());
        im.write().non_parallel().to_buffered(&mut buf).unwrap();
        let r = super::super::Image::read_from_bytes(&buf.into_inner(), "x.exr", None).unwrap();
        assert_eq!(
            r.image.channel_names(),
            ["diffuse.G", "diffuse.R", "specular.B"]
        );
        assert_eq!(r.image.to_f32_vec(), vec![3.0, 1.0, 5.0, 4.0, 2.0, 6.0]);
    }

    #[test]
    fn spectral_channel_names_round_trip() {
        let names = ["R", "G", "B", "S0.418,750nm", "S0.431,250nm"];
        let vals: Vec<f32> = (0..10).map(|i| i as f32).collect();
        let im = Image::from_f32(vals, Point2i::new(2, 1), &names).unwrap();
        let bytes = write(&im, &ImageMetadata::default()).unwrap();
        let r = super::super::Image::read_from_bytes(&bytes, "x.exr", None).unwrap();
        let desc = r.image.get_channel_desc(&names).unwrap();
        let back = r.image.select_channels(&desc);
        assert_eq!(back.to_f32_vec(), im.to_f32_vec());
    }
}
