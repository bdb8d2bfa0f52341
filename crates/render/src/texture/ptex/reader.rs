//! Reading Ptex files (the open Ptex format by Walt Disney Animation
//! Studios; pbrt-v4 reads them through the Ptex library, book section
//! 10.4.3 mentions it only in passing).
//!
//! Layout, all little endian: a 64-byte header (magic "Ptex", version 1,
//! mesh type, data type, alpha channel, channel/level/face counts and the
//! sizes of the blocks that follow), an extended header, then zlib
//! streams for the face infos (20 bytes per face), the per-face constant
//! (average) pixels and, after an uncompressed level-info table, the level
//! data: per level a zlib-compressed table of face data headers (block
//! size and encoding), then the face blocks. A face block is a constant
//! pixel, a zlib stream of channel planes (for `uint8`/`uint16` optionally
//! difference encoded as one running sum over all planes), or a tiled face
//! (tile resolution, a compressed tile header, then tiles encoded the same
//! way). Edits appended after the metadata replace faces.
//!
//! Triangle and quad files share this layout (a triangle face's texels
//! are a square array, see [`super::triangle`]). Only level 0 is read:
//! reductions are computed from it on demand by the filters (box averages
//! on quads, Ptex's four-triangle averages on triangles). Adjacency that
//! names faces or edges the file lacks is read as a border and counted. Every size is checked against the file; damaged
//! files are errors naming the file, and decompressed sizes are bounded by
//! what the file can hold.

use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicI64, AtomicU64};
use std::sync::OnceLock;

use half::f16;

/// How faces are meshed (the Ptex header's mesh type).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PtexMeshType {
    /// Triangles (texels packed in a triangular layout).
    Triangle,
    /// Quads.
    Quad,
}

/// The type of each channel value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PtexDataType {
    /// 8-bit unsigned, normalized by 255.
    U8,
    /// 16-bit unsigned, normalized by 65535.
    U16,
    /// IEEE half.
    Half,
    /// IEEE single.
    Float,
}

impl PtexDataType {
    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            PtexDataType::U8 => 1,
            PtexDataType::U16 | PtexDataType::Half => 2,
            PtexDataType::Float => 4,
        }
    }
}

/// What a lookup outside the face's [0, 1]² does where the face has no
/// neighbour (the extended header's border modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PtexBorderMode {
    /// Repeat the edge texels.
    Clamp,
    /// Zero.
    Black,
    /// Wrap around within the face.
    Periodic,
}

/// Face flag: every texel has the same value.
pub const FLAG_CONSTANT: u8 = 1;
/// Face flag: the face was replaced by an edit.
pub const FLAG_HAS_EDITS: u8 = 2;
/// Face flag: the face and all its neighbours are constant with one value.
pub const FLAG_NEIGHBORHOOD_CONSTANT: u8 = 4;
/// Face flag: the face is a subface of a non-quad.
pub const FLAG_SUBFACE: u8 = 8;

/// One face: its resolution, adjacency and texels.
#[derive(Debug)]
pub struct PtexFace {
    /// log2 of the u resolution.
    pub ulog2: u8,
    /// log2 of the v resolution.
    pub vlog2: u8,
    /// Adjacent edge ids, 2 bits per edge (bottom, right, top, left).
    pub adj_edges: u8,
    /// `FLAG_*` bits.
    pub flags: u8,
    /// Adjacent faces (−1: none), bottom, right, top, left.
    pub adj_faces: [i32; 4],
    /// The face's average (constant-data block), one value per channel.
    pub constant: Vec<f32>,
    /// Level-0 texels, channels interleaved, rows of u texels from v = 0;
    /// `None` when the face is constant.
    pub texels: Option<Box<[f32]>>,
    /// Summed-area table of the texels (built on the first minified
    /// lookup), (ures + 1) × (vres + 1) × channels.
    pub(super) sat: OnceLock<Box<[f64]>>,
    /// Reduced resolutions of a triangle face's texels (built on the
    /// first lookup that needs one), halving from level 0 down to 1 × 1.
    pub(super) reductions: OnceLock<Box<[Box<[f32]>]>>,
}

impl PtexFace {
    /// Texels along u.
    #[inline]
    pub fn ures(&self) -> usize {
        1 << self.ulog2
    }
    /// Texels along v.
    #[inline]
    pub fn vres(&self) -> usize {
        1 << self.vlog2
    }
    /// The id of the neighbour's edge across edge `eid`.
    #[inline]
    pub fn adj_edge(&self, eid: usize) -> usize {
        ((self.adj_edges >> (2 * (eid & 3))) & 3) as usize
    }
    /// Whether the face is stored as one value.
    #[inline]
    pub fn is_constant(&self) -> bool {
        self.texels.is_none()
    }
}

/// A whole Ptex file, decoded to floats.
#[derive(Debug)]
pub struct PtexFile {
    /// The file (for messages).
    pub filename: String,
    /// Triangles or quads.
    pub mesh_type: PtexMeshType,
    /// Stored value type.
    pub data_type: PtexDataType,
    /// Channels per texel.
    pub nchannels: usize,
    /// The alpha channel, if any.
    pub alpha_channel: Option<usize>,
    /// Border modes along u and v.
    pub border: [PtexBorderMode; 2],
    /// The faces, by face id.
    pub faces: Vec<PtexFace>,
    /// Adjacency entries that named a face outside the file (or, on a
    /// triangle mesh, an edge id other than 0, 1, 2); each was read as a
    /// border.
    pub bad_adjacency: usize,
    /// Lookups with a face index outside the file, since the last report.
    pub bad_lookups: AtomicU64,
    /// The last such face index.
    pub bad_face: AtomicI64,
}

const MAGIC: u32 = u32::from_le_bytes(*b"Ptex");
const HEADER_SIZE: usize = 64;
const EXT_HEADER_SIZE: usize = 40;
const FACE_INFO_SIZE: usize = 20;
const LEVEL_INFO_SIZE: usize = 16;
/// Bound on decoded floats per stored byte (constant tiles legitimately
/// stand for up to 64 KiB of texels).
const MAX_EXPANSION: u64 = 65536;
/// Largest face resolution (log2) accepted.
const MAX_RES_LOG2: u8 = 15;

/// Little-endian field reads from a byte slice that fail instead of
/// panicking.
struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        let end = end.ok_or_else(|| "unexpected end of data".to_string())?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u16(&mut self) -> Result<u16, String> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let lo = self.u32()? as u64;
        let hi = self.u32()? as u64;
        Ok(lo | (hi << 32))
    }
}

/// The byte range [pos, pos + len) of `file`, or an error naming `what`.
fn slice<'a>(file: &'a [u8], pos: u64, len: u64, what: &str) -> Result<&'a [u8], String> {
    let end = pos.checked_add(len).filter(|&e| e <= file.len() as u64);
    match end {
        Some(end) => Ok(&file[pos as usize..end as usize]),
        None => Err(format!(
            "{what} ({len} bytes at offset {pos}) extends past the end of the file ({} bytes)",
            file.len()
        )),
    }
}

/// Inflates a zlib stream that must decode to exactly `size` bytes. The
/// output grows only as data really decompresses, so a lying size cannot
/// cause a huge allocation.
fn unzip(data: &[u8], size: u64, what: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(size.min(1 << 20) as usize);
    let mut dec = flate2::read::ZlibDecoder::new(data).take(size.saturating_add(1));
    dec.read_to_end(&mut out)
        .map_err(|e| format!("{what}: corrupt compressed data ({e})"))?;
    if out.len() as u64 != size {
        return Err(format!(
            "{what}: compressed data holds {} bytes, {size} expected",
            if out.len() as u64 > size {
                "more than".to_string()
            } else {
                out.len().to_string()
            }
        ));
    }
    Ok(out)
}

/// A face data header: block size and encoding.
#[derive(Clone, Copy, Debug)]
struct Fdh {
    size: u32,
    encoding: u32,
}

const ENC_CONSTANT: u32 = 0;
const ENC_ZIPPED: u32 = 1;
const ENC_DIFFZIPPED: u32 = 2;
const ENC_TILED: u32 = 3;

fn read_fdhs(data: &[u8], n: usize, what: &str) -> Result<Vec<Fdh>, String> {
    let mut b = Bytes::new(data);
    (0..n)
        .map(|_| {
            let v = b.u32().map_err(|e| format!("{what}: {e}"))?;
            Ok(Fdh {
                size: v & 0x3fff_ffff,
                encoding: v >> 30,
            })
        })
        .collect()
}

/// Decodes `n` values of `dt` to normalized floats.
fn to_floats(bytes: &[u8], dt: PtexDataType, out: &mut Vec<f32>) {
    match dt {
        PtexDataType::U8 => out.extend(bytes.iter().map(|&b| b as f32 / 255.0)),
        PtexDataType::U16 => out.extend(
            bytes
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]) as f32 / 65535.0),
        ),
        PtexDataType::Half => out.extend(
            bytes
                .chunks_exact(2)
                .map(|c| f16::from_bits(u16::from_le_bytes([c[0], c[1]])).to_f32()),
        ),
        PtexDataType::Float => out.extend(
            bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        ),
    }
}

/// Undoes the running-difference encoding (one sum over the whole
/// buffer, wrapping, as the Ptex writer encodes it).
fn undo_difference(buf: &mut [u8], dt: PtexDataType) {
    match dt {
        PtexDataType::U8 => {
            let mut prev = 0u8;
            for b in buf.iter_mut() {
                *b = b.wrapping_add(prev);
                prev = *b;
            }
        }
        PtexDataType::U16 => {
            let mut prev = 0u16;
            for c in buf.chunks_exact_mut(2) {
                let v = u16::from_le_bytes([c[0], c[1]]).wrapping_add(prev);
                c.copy_from_slice(&v.to_le_bytes());
                prev = v;
            }
        }
        PtexDataType::Half | PtexDataType::Float => {}
    }
}

struct Ctx<'a> {
    file: &'a [u8],
    dt: PtexDataType,
    nc: usize,
    /// Floats decoded so far, against `budget`.
    decoded: u64,
    budget: u64,
}

impl Ctx<'_> {
    fn pixel_size(&self) -> usize {
        self.dt.size() * self.nc
    }

    fn charge(&mut self, floats: u64) -> Result<(), String> {
        self.decoded = self.decoded.saturating_add(floats);
        if self.decoded > self.budget {
            return Err(format!(
                "the faces decode to more texels ({}) than a file of {} bytes can hold",
                self.decoded / self.nc as u64,
                self.file.len()
            ));
        }
        Ok(())
    }

    /// Decodes an untiled block of `ures` × `vres` texels at `pos` into
    /// `dst` (row stride `stride` texels, starting at texel (u0, v0)).
    #[allow(clippy::too_many_arguments)]
    fn decode_block(
        &mut self,
        pos: u64,
        fdh: Fdh,
        ures: usize,
        vres: usize,
        dst: &mut [f32],
        stride: usize,
        u0: usize,
        v0: usize,
        what: &str,
    ) -> Result<(), String> {
        let nc = self.nc;
        let block = slice(self.file, pos, fdh.size as u64, what)?;
        match fdh.encoding {
            ENC_CONSTANT => {
                if block.len() < self.pixel_size() {
                    return Err(format!("{what}: constant block shorter than one pixel"));
                }
                let mut px = Vec::with_capacity(nc);
                to_floats(&block[..self.pixel_size()], self.dt, &mut px);
                for v in 0..vres {
                    for u in 0..ures {
                        let o = ((v0 + v) * stride + u0 + u) * nc;
                        dst[o..o + nc].copy_from_slice(&px);
                    }
                }
            }
            ENC_ZIPPED | ENC_DIFFZIPPED => {
                let ds = self.dt.size();
                let size = (ures * vres * self.pixel_size()) as u64;
                let mut raw = unzip(block, size, what)?;
                if fdh.encoding == ENC_DIFFZIPPED {
                    undo_difference(&mut raw, self.dt);
                }
                let mut vals = Vec::with_capacity(ures * vres * nc);
                to_floats(&raw, self.dt, &mut vals);
                debug_assert_eq!(raw.len(), vals.len() * ds);
                let plane = ures * vres;
                for c in 0..nc {
                    for v in 0..vres {
                        for u in 0..ures {
                            dst[((v0 + v) * stride + u0 + u) * nc + c] =
                                vals[c * plane + v * ures + u];
                        }
                    }
                }
            }
            _ => return Err(format!("{what}: tiles may not be tiled again")),
        }
        Ok(())
    }

    /// Decodes level-0 face data at `pos` for a face of 2^ulog2 × 2^vlog2.
    fn decode_face(
        &mut self,
        pos: u64,
        fdh: Fdh,
        ulog2: u8,
        vlog2: u8,
        what: &str,
    ) -> Result<Option<Box<[f32]>>, String> {
        let (ures, vres) = (1usize << ulog2, 1usize << vlog2);
        if fdh.encoding == ENC_CONSTANT {
            return Ok(None);
        }
        let n = ures * vres * self.nc;
        self.charge(n as u64)?;
        let mut dst = vec![0.0f32; n];
        if fdh.encoding != ENC_TILED {
            self.decode_block(pos, fdh, ures, vres, &mut dst, ures, 0, 0, what)?;
            return Ok(Some(dst.into_boxed_slice()));
        }
        let block = slice(self.file, pos, fdh.size as u64, what)?;
        let mut b = Bytes::new(block);
        let head = |e: String| format!("{what}: tile header: {e}");
        let tu = b.u8().map_err(head)?;
        let tv = b.u8().map_err(head)?;
        let tile_header_size = b.u32().map_err(head)? as u64;
        if tu > ulog2 || tv > vlog2 {
            return Err(format!(
                "{what}: tile resolution 2^{tu} x 2^{tv} exceeds the face's 2^{ulog2} x 2^{vlog2}"
            ));
        }
        let (tures, tvres) = (1usize << tu, 1usize << tv);
        let (ntu, ntv) = (ures / tures, vres / tvres);
        let ntiles = ntu * ntv;
        let header_pos = pos + 6;
        let zipped = slice(self.file, header_pos, tile_header_size, what)?;
        let hdr = unzip(zipped, ntiles as u64 * 4, &format!("{what}: tile header"))?;
        let fdhs = read_fdhs(&hdr, ntiles, what)?;
        let mut tpos = header_pos + tile_header_size;
        let end = pos + fdh.size as u64;
        for (t, tfdh) in fdhs.iter().enumerate() {
            if tfdh.encoding == ENC_TILED {
                return Err(format!("{what}: tile {t} is itself tiled"));
            }
            if tpos + tfdh.size as u64 > end {
                return Err(format!(
                    "{what}: tile {t} extends past the face's data block"
                ));
            }
            let tw = format!("{what}, tile {t}");
            let (iu, iv) = (t % ntu, t / ntu);
            self.decode_block(
                tpos,
                *tfdh,
                tures,
                tvres,
                &mut dst,
                ures,
                iu * tures,
                iv * tvres,
                &tw,
            )?;
            tpos += tfdh.size as u64;
        }
        Ok(Some(dst.into_boxed_slice()))
    }
}

/// A face-data edit found after the main data.
struct FaceEdit {
    faceid: usize,
    info: [u8; FACE_INFO_SIZE],
    constant: Vec<f32>,
    fdh: Fdh,
    pos: u64,
}

impl PtexFile {
    /// Reads and decodes a Ptex file; errors name the file.
    pub fn read(path: &Path) -> Result<PtexFile, String> {
        let name = path.display().to_string();
        let data = std::fs::read(path).map_err(|e| format!("\"{name}\": {e}"))?;
        PtexFile::parse(&data, &name).map_err(|e| format!("\"{name}\": {e}"))
    }

    /// Decodes Ptex file contents (`filename` is only recorded).
    pub fn parse(file: &[u8], filename: &str) -> Result<PtexFile, String> {
        let mut h = Bytes::new(file);
        let short = |_| "file too short for a Ptex header".to_string();
        let magic = h.u32().map_err(short)?;
        if magic != MAGIC {
            return Err("not a Ptex file (bad magic number)".into());
        }
        let version = h.u32().map_err(short)?;
        if version != 1 {
            return Err(format!("unsupported Ptex version {version}"));
        }
        let mesh_type = match h.u32().map_err(short)? {
            0 => PtexMeshType::Triangle,
            1 => PtexMeshType::Quad,
            m => return Err(format!("unknown Ptex mesh type {m}")),
        };
        let dt = match h.u32().map_err(short)? {
            0 => PtexDataType::U8,
            1 => PtexDataType::U16,
            2 => PtexDataType::Half,
            3 => PtexDataType::Float,
            d => return Err(format!("unknown Ptex data type {d}")),
        };
        let alphachan = h.u32().map_err(short)? as i32;
        let nc = h.u16().map_err(short)? as usize;
        let nlevels = h.u16().map_err(short)? as usize;
        let nfaces = h.u32().map_err(short)? as usize;
        let ext_size = h.u32().map_err(short)? as u64;
        let faceinfo_size = h.u32().map_err(short)? as u64;
        let constdata_size = h.u32().map_err(short)? as u64;
        let levelinfo_size = h.u32().map_err(short)? as u64;
        let _minor_version = h.u32().map_err(short)?;
        let leveldata_size = h.u64().map_err(short)?;
        let metadata_zipsize = h.u32().map_err(short)? as u64;
        let _metadata_memsize = h.u32().map_err(short)?;
        debug_assert_eq!(h.pos, HEADER_SIZE);
        if nc == 0 {
            return Err("the file has no channels".into());
        }
        if nlevels == 0 && nfaces > 0 {
            return Err("the file has faces but no levels".into());
        }
        let alpha_channel = usize::try_from(alphachan).ok().filter(|&a| a < nc);

        // Extended header (only its start matters here).
        let ext = slice(file, HEADER_SIZE as u64, ext_size, "extended header")?;
        let mut ext_bytes = [0u8; EXT_HEADER_SIZE];
        let n = ext.len().min(EXT_HEADER_SIZE);
        ext_bytes[..n].copy_from_slice(&ext[..n]);
        let mut e = Bytes::new(&ext_bytes);
        let border_mode = |m: u32| match m {
            1 => PtexBorderMode::Black,
            2 => PtexBorderMode::Periodic,
            _ => PtexBorderMode::Clamp,
        };
        let ok = |r: Result<u32, String>| r.unwrap_or(0);
        let border = [border_mode(ok(e.u32())), border_mode(ok(e.u32()))];
        let lmd_header_zipsize = ok(e.u32()) as u64;
        let _lmd_header_memsize = ok(e.u32());
        let lmd_data_size = e.u64().unwrap_or(0);
        let edit_data_size = e.u64().unwrap_or(0);
        let edit_data_pos = e.u64().unwrap_or(0);

        // Block positions.
        let faceinfo_pos = HEADER_SIZE as u64 + ext_size;
        let constdata_pos = faceinfo_pos + faceinfo_size;
        let levelinfo_pos = constdata_pos + constdata_size;
        let leveldata_pos = levelinfo_pos + levelinfo_size;
        let metadata_pos = leveldata_pos.saturating_add(leveldata_size);

        let mut ctx = Ctx {
            file,
            dt,
            nc,
            decoded: 0,
            budget: (file.len() as u64).saturating_mul(MAX_EXPANSION),
        };
        let ps = ctx.pixel_size();

        // Face infos.
        let zipped = slice(file, faceinfo_pos, faceinfo_size, "face info block")?;
        let infos = unzip(zipped, (nfaces * FACE_INFO_SIZE) as u64, "face info block")?;
        let mut infos: Vec<[u8; FACE_INFO_SIZE]> = infos
            .chunks_exact(FACE_INFO_SIZE)
            .map(|c| {
                let mut a = [0u8; FACE_INFO_SIZE];
                a.copy_from_slice(c);
                a
            })
            .collect();

        // Constant data: one interleaved pixel per face.
        let zipped = slice(file, constdata_pos, constdata_size, "constant data block")?;
        let consts = unzip(zipped, (nfaces * ps) as u64, "constant data block")?;
        let mut constants: Vec<Vec<f32>> = consts
            .chunks_exact(ps)
            .map(|p| {
                let mut v = Vec::with_capacity(nc);
                to_floats(p, dt, &mut v);
                v
            })
            .collect();

        // Level info (uncompressed) and the level-0 face data headers.
        let mut level0 = Vec::new();
        if nlevels > 0 {
            let li = slice(
                file,
                levelinfo_pos,
                (nlevels * LEVEL_INFO_SIZE) as u64,
                "level info block",
            )?;
            let mut b = Bytes::new(li);
            let lerr = |e: String| format!("level info block: {e}");
            let _level_data_size = b.u64().map_err(lerr)?;
            let header_size = b.u32().map_err(lerr)? as u64;
            let level_faces = b.u32().map_err(lerr)? as usize;
            if level_faces != nfaces {
                return Err(format!(
                    "level 0 holds {level_faces} faces, the header says {nfaces}"
                ));
            }
            let zipped = slice(file, leveldata_pos, header_size, "level 0 header")?;
            let hdr = unzip(zipped, (nfaces * 4) as u64, "level 0 header")?;
            let fdhs = read_fdhs(&hdr, nfaces, "level 0 header")?;
            let mut pos = leveldata_pos + header_size;
            for f in fdhs {
                level0.push((f, pos));
                pos += f.size as u64;
            }
        }

        // Edits appended after the metadata (and large metadata).
        let mut edits_pos = metadata_pos
            .saturating_add(metadata_zipsize)
            .saturating_add(8)
            .saturating_add(lmd_header_zipsize)
            .saturating_add(lmd_data_size);
        edits_pos = edits_pos.max(edit_data_pos);
        let edits_end = if edit_data_pos > 0 {
            edits_pos
                .saturating_add(edit_data_size)
                .min(file.len() as u64)
        } else {
            file.len() as u64
        };
        for edit in read_edits(file, edits_pos, edits_end, nfaces, dt, nc)? {
            infos[edit.faceid] = edit.info;
            infos[edit.faceid][3] |= FLAG_HAS_EDITS;
            constants[edit.faceid] = edit.constant;
            if let Some(l) = level0.get_mut(edit.faceid) {
                *l = (edit.fdh, edit.pos);
            }
        }

        let mut faces = Vec::with_capacity(nfaces);
        let mut bad_adjacency = 0;
        for (id, info) in infos.iter().enumerate() {
            let what = format!("face {id}");
            let mut b = Bytes::new(info);
            let ulog2 = b.u8()?;
            let vlog2 = b.u8()?;
            let adj_edges = b.u8()?;
            let flags = b.u8()?;
            let mut adj_faces = [0i32; 4];
            let nedges = if mesh_type == PtexMeshType::Triangle {
                3
            } else {
                4
            };
            for (e, a) in adj_faces.iter_mut().enumerate() {
                *a = b.u32()? as i32;
                if e >= nedges {
                    *a = -1;
                    continue;
                }
                let bad_edge = nedges == 3 && (adj_edges >> (2 * e)) & 3 == 3;
                // -1 means no neighbour; anything else outside the file is
                // damage.
                if *a < -1 || *a >= nfaces as i32 || (*a >= 0 && bad_edge) {
                    *a = -1;
                    bad_adjacency += 1;
                }
            }
            if ulog2 > MAX_RES_LOG2 || vlog2 > MAX_RES_LOG2 {
                return Err(format!(
                    "{what}: resolution 2^{ulog2} x 2^{vlog2} is out of range (log2 at most {MAX_RES_LOG2})"
                ));
            }
            if mesh_type == PtexMeshType::Triangle && ulog2 != vlog2 {
                return Err(format!(
                    "{what}: triangle face with resolution 2^{ulog2} x 2^{vlog2} (triangle faces are 2^n x 2^n)"
                ));
            }
            let mut constant = std::mem::take(&mut constants[id]);
            let texels = if flags & FLAG_CONSTANT != 0 || (ulog2 == 0 && vlog2 == 0) {
                None
            } else {
                let Some(&(fdh, pos)) = level0.get(id) else {
                    return Err(format!("{what}: no level data"));
                };
                let mut t = ctx.decode_face(pos, fdh, ulog2, vlog2, &what)?;
                if t.is_none() {
                    // A constant-encoded level-0 block: its pixel is the
                    // face's value.
                    let px = slice(file, pos, ps as u64, &what)?;
                    constant.clear();
                    to_floats(px, dt, &mut constant);
                }
                if let (Some(t), Some(a)) = (t.as_mut(), alpha_channel) {
                    premultiply(t, nc, a);
                }
                t
            };
            if let Some(a) = alpha_channel {
                premultiply(&mut constant, nc, a);
            }
            faces.push(PtexFace {
                ulog2,
                vlog2,
                adj_edges,
                flags,
                adj_faces,
                constant,
                texels,
                sat: OnceLock::new(),
                reductions: OnceLock::new(),
            });
        }
        Ok(PtexFile {
            filename: filename.to_string(),
            mesh_type,
            data_type: dt,
            nchannels: nc,
            alpha_channel,
            border,
            faces,
            bad_adjacency,
            bad_lookups: AtomicU64::new(0),
            bad_face: AtomicI64::new(0),
        })
    }
}

/// Multiplies the colour channels by alpha (the Ptex cache pbrt-v4 opens
/// premultiplies).
fn premultiply(px: &mut [f32], nc: usize, alpha: usize) {
    for p in px.chunks_exact_mut(nc) {
        let a = p[alpha];
        for (c, v) in p.iter_mut().enumerate() {
            if c != alpha {
                *v *= a;
            }
        }
    }
}

/// Reads the face-data edits in [pos, end); metadata edits are skipped.
fn read_edits(
    file: &[u8],
    mut pos: u64,
    end: u64,
    nfaces: usize,
    dt: PtexDataType,
    nc: usize,
) -> Result<Vec<FaceEdit>, String> {
    let ps = dt.size() * nc;
    let mut edits = Vec::new();
    while pos.saturating_add(5) <= end {
        let Ok(h) = slice(file, pos, 5, "edit") else {
            break;
        };
        let kind = h[0];
        let size = u32::from_le_bytes([h[1], h[2], h[3], h[4]]) as u64;
        if size == 0 {
            break;
        }
        let body_pos = pos + 5;
        let body = slice(file, body_pos, size, "edit block")?;
        pos = body_pos + size;
        if kind != 0 {
            continue; // metadata edit
        }
        let mut b = Bytes::new(body);
        let err = |e: String| format!("face edit: {e}");
        let faceid = b.u32().map_err(err)? as usize;
        let mut info = [0u8; FACE_INFO_SIZE];
        info.copy_from_slice(b.take(FACE_INFO_SIZE).map_err(err)?);
        let v = b.u32().map_err(err)?;
        let fdh = Fdh {
            size: v & 0x3fff_ffff,
            encoding: v >> 30,
        };
        let mut constant = Vec::with_capacity(nc);
        to_floats(b.take(ps).map_err(err)?, dt, &mut constant);
        if faceid >= nfaces {
            continue;
        }
        edits.push(FaceEdit {
            faceid,
            info,
            constant,
            fdh,
            pos: body_pos + b.pos as u64,
        });
    }
    Ok(edits)
}
