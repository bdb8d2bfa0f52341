//! Decoding a PLY body into a [`PlyMesh`]: a fast path for the fixed-size
//! binary records exporters write, and a general property-by-property decoder
//! for everything else (ASCII, lists, unusual types).

use std::io::Read;

use super::header::{lossy, parse_header, Element, Format, Header, PropKind, Scalar};
use super::{PlyErrorKind, PlyMesh};

// ---------------------------------------------------------------------------
// What to extract from the vertex and face elements

const SLOT_COUNT: usize = 8;

struct VertexLayout {
    /// For each property, which of x y z nx ny nz u v it feeds, if any.
    slots: Vec<Option<usize>>,
    normals: bool,
    uvs: bool,
}

pub(super) const UV_NAMES: [(&str, &str); 4] = [
    ("u", "v"),
    ("s", "t"),
    ("texture_u", "texture_v"),
    ("texture_s", "texture_t"),
];

fn vertex_layout(el: &Element) -> Result<VertexLayout, PlyErrorKind> {
    let scalar = |name: &str| {
        el.find(name)
            .filter(|&i| matches!(el.props[i].kind, PropKind::Scalar(_)))
    };
    let mut slots = vec![None; el.props.len()];
    for (slot, name) in ["x", "y", "z"].into_iter().enumerate() {
        let Some(i) = el.find(name) else {
            return Err(PlyErrorKind::MissingProperty {
                element: "vertex",
                property: name,
            });
        };
        if scalar(name).is_none() {
            return Err(PlyErrorKind::UnsupportedProperty {
                element: el.name.clone(),
                property: name.into(),
                reason: "is a list, not a scalar",
            });
        }
        slots[i] = Some(slot);
    }
    let normals = match (scalar("nx"), scalar("ny"), scalar("nz")) {
        (Some(a), Some(b), Some(c)) => {
            slots[a] = Some(3);
            slots[b] = Some(4);
            slots[c] = Some(5);
            true
        }
        _ => false,
    };
    let mut uvs = false;
    for (un, vn) in UV_NAMES {
        if let (Some(a), Some(b)) = (scalar(un), scalar(vn)) {
            slots[a] = Some(6);
            slots[b] = Some(7);
            uvs = true;
            break;
        }
    }
    Ok(VertexLayout {
        slots,
        normals,
        uvs,
    })
}

struct FaceLayout {
    indices: usize,
    face_index: Option<usize>,
}

fn face_layout(el: &Element) -> Result<FaceLayout, PlyErrorKind> {
    let Some(indices) = el
        .find("vertex_indices")
        .or_else(|| el.find("vertex_index"))
    else {
        return Err(PlyErrorKind::MissingProperty {
            element: "face",
            property: "vertex_indices",
        });
    };
    if !matches!(el.props[indices].kind, PropKind::List { .. }) {
        return Err(PlyErrorKind::UnsupportedProperty {
            element: el.name.clone(),
            property: el.props[indices].name.clone(),
            reason: "is a scalar, not a list",
        });
    }
    let face_index = el.find("face_indices");
    if let Some(i) = face_index {
        if !matches!(el.props[i].kind, PropKind::Scalar(_)) {
            return Err(PlyErrorKind::UnsupportedProperty {
                element: el.name.clone(),
                property: "face_indices".into(),
                reason: "is a list, not a scalar",
            });
        }
    }
    Ok(FaceLayout {
        indices,
        face_index,
    })
}

// ---------------------------------------------------------------------------
// Decoding values

/// Why a value could not be read; turned into a [`PlyErrorKind`] by the
/// element loop, which knows the element and record.
enum ReadErr {
    Eof,
    Bad(String),
    Index(i64),
}

#[inline(always)]
fn array_at<const N: usize>(b: &[u8], off: usize) -> [u8; N] {
    let mut a = [0u8; N];
    a.copy_from_slice(&b[off..off + N]);
    a
}

macro_rules! decode_num {
    ($t:ty, $n:literal, $be:expr, $b:expr, $off:expr) => {{
        let a = array_at::<$n>($b, $off);
        if $be {
            <$t>::from_be_bytes(a)
        } else {
            <$t>::from_le_bytes(a)
        }
    }};
}

/// Decodes a scalar at `off` (which the caller has bounds-checked) as `f32`.
#[inline(always)]
fn decode_f32<const BE: bool>(ty: Scalar, b: &[u8], off: usize) -> f32 {
    match ty {
        Scalar::I8 => f32::from(b[off] as i8),
        Scalar::U8 => f32::from(b[off]),
        Scalar::I16 => f32::from(decode_num!(i16, 2, BE, b, off)),
        Scalar::U16 => f32::from(decode_num!(u16, 2, BE, b, off)),
        Scalar::I32 => decode_num!(i32, 4, BE, b, off) as f32,
        Scalar::U32 => decode_num!(u32, 4, BE, b, off) as f32,
        Scalar::F32 => decode_num!(f32, 4, BE, b, off),
        Scalar::F64 => decode_num!(f64, 8, BE, b, off) as f32,
    }
}

fn float_to_int(f: f64) -> Result<i64, ReadErr> {
    if f.is_finite() && f.fract() == 0.0 && f.abs() < 9.0e15 {
        Ok(f as i64)
    } else {
        Err(ReadErr::Bad(format!("expected an integer, found {f}")))
    }
}

/// Decodes a scalar at `off` (which the caller has bounds-checked) as an integer.
#[inline(always)]
fn decode_int<const BE: bool>(ty: Scalar, b: &[u8], off: usize) -> Result<i64, ReadErr> {
    Ok(match ty {
        Scalar::I8 => i64::from(b[off] as i8),
        Scalar::U8 => i64::from(b[off]),
        Scalar::I16 => i64::from(decode_num!(i16, 2, BE, b, off)),
        Scalar::U16 => i64::from(decode_num!(u16, 2, BE, b, off)),
        Scalar::I32 => i64::from(decode_num!(i32, 4, BE, b, off)),
        Scalar::U32 => i64::from(decode_num!(u32, 4, BE, b, off)),
        Scalar::F32 => return float_to_int(f64::from(decode_num!(f32, 4, BE, b, off))),
        Scalar::F64 => return float_to_int(decode_num!(f64, 8, BE, b, off)),
    })
}

/// A stream of property values: a binary slice or ASCII tokens.
trait Source {
    fn remaining(&self) -> usize;
    /// A lower bound on the bytes one record of `el` occupies.
    fn min_record_size(&self, el: &Element) -> usize;
    fn read_f32(&mut self, ty: Scalar) -> Result<f32, ReadErr>;
    fn read_int(&mut self, ty: Scalar) -> Result<i64, ReadErr>;
    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), ReadErr>;
}

struct BinarySource<'a, const BE: bool> {
    data: &'a [u8],
    pos: usize,
}

impl<'a, const BE: bool> BinarySource<'a, BE> {
    #[inline(always)]
    fn take(&mut self, n: usize) -> Result<&'a [u8], ReadErr> {
        let end = self.pos.checked_add(n).ok_or(ReadErr::Eof)?;
        let s = self.data.get(self.pos..end).ok_or(ReadErr::Eof)?;
        self.pos = end;
        Ok(s)
    }
}

impl<const BE: bool> Source for BinarySource<'_, BE> {
    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn min_record_size(&self, el: &Element) -> usize {
        el.min_binary_size()
    }

    fn read_f32(&mut self, ty: Scalar) -> Result<f32, ReadErr> {
        let b = self.take(ty.size())?;
        Ok(decode_f32::<BE>(ty, b, 0))
    }

    fn read_int(&mut self, ty: Scalar) -> Result<i64, ReadErr> {
        let b = self.take(ty.size())?;
        decode_int::<BE>(ty, b, 0)
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), ReadErr> {
        let bytes = n
            .checked_mul(ty.size() as u64)
            .and_then(|b| usize::try_from(b).ok())
            .ok_or(ReadErr::Eof)?;
        self.take(bytes).map(|_| ())
    }
}

struct AsciiSource<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> AsciiSource<'a> {
    fn token(&mut self) -> Option<&'a [u8]> {
        let rest = self.data.get(self.pos..)?;
        let start = rest.iter().position(|b| !b.is_ascii_whitespace())?;
        let rest = &rest[start..];
        let len = rest
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(rest.len());
        self.pos += start + len;
        Some(&rest[..len])
    }

    fn text(&mut self) -> Result<&'a str, ReadErr> {
        let tok = self.token().ok_or(ReadErr::Eof)?;
        std::str::from_utf8(tok)
            .map_err(|_| ReadErr::Bad(format!("invalid number '{}'", lossy(tok))))
    }
}

impl Source for AsciiSource<'_> {
    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn min_record_size(&self, el: &Element) -> usize {
        // Every value is at least one character plus a separator.
        el.props.len()
    }

    fn read_f32(&mut self, _ty: Scalar) -> Result<f32, ReadErr> {
        let s = self.text()?;
        s.parse::<f32>()
            .map_err(|_| ReadErr::Bad(format!("invalid number '{}'", lossy(s.as_bytes()))))
    }

    fn read_int(&mut self, _ty: Scalar) -> Result<i64, ReadErr> {
        let s = self.text()?;
        match s.parse::<i64>() {
            Ok(i) => Ok(i),
            Err(_) => match s.parse::<f64>() {
                Ok(f) => float_to_int(f),
                Err(_) => Err(ReadErr::Bad(format!(
                    "invalid integer '{}'",
                    lossy(s.as_bytes())
                ))),
            },
        }
    }

    fn skip(&mut self, _ty: Scalar, n: u64) -> Result<(), ReadErr> {
        for _ in 0..n {
            self.token().ok_or(ReadErr::Eof)?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Assembling the mesh

struct Builder {
    vertex_count: u64,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    tris: Vec<u32>,
    quads: Vec<u32>,
    tri_faces: Vec<i32>,
    quad_faces: Vec<i32>,
    /// Scratch space for the indices of one face.
    poly: Vec<u32>,
    fans: u64,
    ignored: u64,
}

impl Builder {
    #[inline]
    fn push_vertex(&mut self, v: &[f32; SLOT_COUNT], normals: bool, uvs: bool) {
        self.positions.push([v[0], v[1], v[2]]);
        if normals {
            self.normals.push([v[3], v[4], v[5]]);
        }
        if uvs {
            self.uvs.push([v[6], v[7]]);
        }
    }

    fn reserve_vertices(&mut self, n: usize, layout: &VertexLayout) {
        self.positions.reserve(n);
        if layout.normals {
            self.normals.reserve(n);
        }
        if layout.uvs {
            self.uvs.reserve(n);
        }
    }

    /// Emits the face in `self.poly`.
    fn emit_face(&mut self, face_index: Option<i32>) {
        let p = &self.poly;
        match p.len() {
            0..=2 => self.ignored += 1,
            3 => {
                self.tris.extend_from_slice(p);
                self.tri_faces.extend(face_index);
            }
            4 => {
                self.quads.extend_from_slice(&[p[0], p[1], p[3], p[2]]);
                self.quad_faces.extend(face_index);
            }
            n => {
                for i in 1..n - 1 {
                    self.tris.extend_from_slice(&[p[0], p[i], p[i + 1]]);
                    self.tri_faces.extend(face_index);
                }
                self.fans += 1;
            }
        }
    }

    #[inline]
    fn check_index(&self, i: i64) -> Result<u32, ReadErr> {
        match u32::try_from(i) {
            Ok(u) if u64::from(u) < self.vertex_count => Ok(u),
            _ => Err(ReadErr::Index(i)),
        }
    }
}

fn map_err(e: ReadErr, el: &Element, record: u64, vertex_count: u64) -> PlyErrorKind {
    match e {
        ReadErr::Eof => PlyErrorKind::Truncated {
            element: el.name.clone(),
            expected: el.count,
            read: record,
        },
        ReadErr::Bad(message) => PlyErrorKind::BadValue {
            element: el.name.clone(),
            record,
            message,
        },
        ReadErr::Index(index) => PlyErrorKind::IndexOutOfRange {
            face: record,
            index,
            vertex_count,
        },
    }
}

/// How many records of `el` can possibly fit in what `src` has left: caps
/// reservations so that a lying count never drives an allocation.
fn plausible_records<S: Source>(src: &S, el: &Element) -> usize {
    let cap = src.remaining() / src.min_record_size(el).max(1);
    usize::try_from(el.count).unwrap_or(usize::MAX).min(cap)
}

fn skip_property<S: Source>(src: &mut S, kind: PropKind) -> Result<(), ReadErr> {
    match kind {
        PropKind::Scalar(t) => src.skip(t, 1),
        PropKind::List { count, item } => {
            let n = src.read_int(count)?;
            let n =
                u64::try_from(n).map_err(|_| ReadErr::Bad(format!("negative list count {n}")))?;
            src.skip(item, n)
        }
    }
}

fn skip_element<S: Source>(src: &mut S, el: &Element) -> Result<(), PlyErrorKind> {
    if el.props.is_empty() {
        return Ok(());
    }
    // Each record consumes at least one byte, so this loop is bounded by the
    // data actually present, whatever the header claims.
    for rec in 0..el.count {
        for p in &el.props {
            skip_property(src, p.kind).map_err(|e| map_err(e, el, rec, 0))?;
        }
    }
    Ok(())
}

fn read_vertices_general<S: Source>(
    src: &mut S,
    el: &Element,
    layout: &VertexLayout,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    b.reserve_vertices(plausible_records(src, el), layout);
    for rec in 0..el.count {
        let mut v = [0.0f32; SLOT_COUNT];
        for (p, slot) in el.props.iter().zip(&layout.slots) {
            let r = match (p.kind, slot) {
                (PropKind::Scalar(t), Some(s)) => src.read_f32(t).map(|x| v[*s] = x),
                (kind, _) => skip_property(src, kind),
            };
            r.map_err(|e| map_err(e, el, rec, 0))?;
        }
        b.push_vertex(&v, layout.normals, layout.uvs);
    }
    Ok(())
}

fn read_face_record<S: Source>(
    src: &mut S,
    el: &Element,
    layout: &FaceLayout,
    b: &mut Builder,
) -> Result<(), ReadErr> {
    b.poly.clear();
    let mut face_index = None;
    for (i, p) in el.props.iter().enumerate() {
        match p.kind {
            PropKind::List { count, item } if i == layout.indices => {
                let n = src.read_int(count)?;
                let n = u64::try_from(n)
                    .map_err(|_| ReadErr::Bad(format!("negative vertex count {n}")))?;
                // Reading stops at the end of the data, so `n` needs no check.
                for _ in 0..n {
                    let idx = src.read_int(item)?;
                    let idx = b.check_index(idx)?;
                    b.poly.push(idx);
                }
            }
            PropKind::Scalar(t) if Some(i) == layout.face_index => {
                let v = src.read_int(t)?;
                let v = i32::try_from(v)
                    .map_err(|_| ReadErr::Bad(format!("face index {v} does not fit in 32 bits")))?;
                face_index = Some(v);
            }
            kind => skip_property(src, kind)?,
        }
    }
    b.emit_face(face_index);
    Ok(())
}

fn read_faces_general<S: Source>(
    src: &mut S,
    el: &Element,
    layout: &FaceLayout,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    b.tris.reserve(plausible_records(src, el).saturating_mul(3));
    for rec in 0..el.count {
        read_face_record(src, el, layout, b).map_err(|e| map_err(e, el, rec, b.vertex_count))?;
    }
    Ok(())
}

/// Fixed-size binary vertex records: decode each field at its offset.
fn read_vertices_fixed<const BE: bool>(
    data: &[u8],
    pos: &mut usize,
    el: &Element,
    layout: &VertexLayout,
    record_size: usize,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    let remaining = data.len().saturating_sub(*pos);
    let truncated = || PlyErrorKind::Truncated {
        element: el.name.clone(),
        expected: el.count,
        read: (remaining / record_size.max(1)) as u64,
    };
    let bytes = usize::try_from(el.count)
        .ok()
        .and_then(|n| n.checked_mul(record_size))
        .filter(|&n| n <= remaining)
        .ok_or_else(truncated)?;
    let count = bytes / record_size.max(1);
    let body = &data[*pos..*pos + bytes];
    *pos += bytes;
    b.reserve_vertices(count, layout);
    if record_size == 0 {
        return Ok(());
    }

    // (offset, type) of each slot; unused slots read field 0 harmlessly.
    let mut fields = [(0usize, Scalar::U8); SLOT_COUNT];
    let mut offset = 0;
    for (p, slot) in el.props.iter().zip(&layout.slots) {
        if let PropKind::Scalar(t) = p.kind {
            if let Some(s) = slot {
                fields[*s] = (offset, t);
            }
            offset += t.size();
        }
    }
    let mut needed = vec![0, 1, 2];
    if layout.normals {
        needed.extend([3, 4, 5]);
    }
    if layout.uvs {
        needed.extend([6, 7]);
    }
    let all_f32 = needed.iter().all(|&s| fields[s].1 == Scalar::F32);

    let (normals, uvs) = (layout.normals, layout.uvs);
    if all_f32 {
        let f = |rec: &[u8], s: usize| decode_num!(f32, 4, BE, rec, fields[s].0);
        for rec in body.chunks_exact(record_size) {
            b.positions.push([f(rec, 0), f(rec, 1), f(rec, 2)]);
            if normals {
                b.normals.push([f(rec, 3), f(rec, 4), f(rec, 5)]);
            }
            if uvs {
                b.uvs.push([f(rec, 6), f(rec, 7)]);
            }
        }
    } else {
        let f = |rec: &[u8], s: usize| decode_f32::<BE>(fields[s].1, rec, fields[s].0);
        for rec in body.chunks_exact(record_size) {
            b.positions.push([f(rec, 0), f(rec, 1), f(rec, 2)]);
            if normals {
                b.normals.push([f(rec, 3), f(rec, 4), f(rec, 5)]);
            }
            if uvs {
                b.uvs.push([f(rec, 6), f(rec, 7)]);
            }
        }
    }
    Ok(())
}

/// The face layout nearly every exporter writes: `list uchar int|uint
/// vertex_indices`, optionally followed by a 32-bit `face_indices`.
fn fast_face_layout(el: &Element, layout: &FaceLayout) -> Option<(bool, bool)> {
    let signed = match el.props[layout.indices].kind {
        PropKind::List {
            count: Scalar::U8,
            item: Scalar::I32,
        } => true,
        PropKind::List {
            count: Scalar::U8,
            item: Scalar::U32,
        } => false,
        _ => return None,
    };
    match (layout.indices, layout.face_index, el.props.len()) {
        (0, None, 1) => Some((signed, false)),
        (0, Some(1), 2)
            if matches!(
                el.props[1].kind,
                PropKind::Scalar(Scalar::I32) | PropKind::Scalar(Scalar::U32)
            ) =>
        {
            Some((signed, true))
        }
        _ => None,
    }
}

fn read_faces_fast<const BE: bool>(
    data: &[u8],
    pos: &mut usize,
    el: &Element,
    layout: &FaceLayout,
    signed: bool,
    with_face_index: bool,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    let fi_len = if with_face_index { 4 } else { 0 };
    let tri_len = 13 + fi_len;
    let quad_len = 17 + fi_len;
    let plausible = usize::try_from(el.count)
        .unwrap_or(usize::MAX)
        .min(data.len().saturating_sub(*pos) / tri_len);
    b.tris.reserve(plausible.saturating_mul(3));
    if with_face_index {
        b.tri_faces.reserve(plausible);
    }
    // Valid indices are below `limit`; a negative `int` read as `u32` is at
    // least 2^31 and so fails the same comparison.
    let limit = if signed {
        b.vertex_count.min(1 << 31)
    } else {
        b.vertex_count.min(1 << 32)
    };
    let index_err = |raw: u32| {
        let index = if signed {
            i64::from(raw as i32)
        } else {
            i64::from(raw)
        };
        ReadErr::Index(index)
    };
    let face_index = |rec: &[u8], off: usize| -> Result<i32, ReadErr> {
        let raw = decode_num!(u32, 4, BE, rec, off);
        if signed_face_index(el) {
            Ok(raw as i32)
        } else {
            i32::try_from(raw)
                .map_err(|_| ReadErr::Bad(format!("face index {raw} does not fit in 32 bits")))
        }
    };
    let mut rec = 0u64;
    while rec < el.count {
        let rest = &data[*pos..];
        let r: Result<(), ReadErr> = match rest.first() {
            Some(3) if rest.len() >= tri_len => {
                let i = [
                    decode_num!(u32, 4, BE, rest, 1),
                    decode_num!(u32, 4, BE, rest, 5),
                    decode_num!(u32, 4, BE, rest, 9),
                ];
                match i.iter().find(|&&v| u64::from(v) >= limit) {
                    Some(&bad) => Err(index_err(bad)),
                    None => {
                        b.tris.extend_from_slice(&i);
                        if with_face_index {
                            face_index(rest, 13).map(|f| b.tri_faces.push(f))
                        } else {
                            Ok(())
                        }
                    }
                }
                .map(|()| *pos += tri_len)
            }
            Some(4) if rest.len() >= quad_len => {
                let i = [
                    decode_num!(u32, 4, BE, rest, 1),
                    decode_num!(u32, 4, BE, rest, 5),
                    decode_num!(u32, 4, BE, rest, 9),
                    decode_num!(u32, 4, BE, rest, 13),
                ];
                match i.iter().find(|&&v| u64::from(v) >= limit) {
                    Some(&bad) => Err(index_err(bad)),
                    None => {
                        b.quads.extend_from_slice(&[i[0], i[1], i[3], i[2]]);
                        if with_face_index {
                            face_index(rest, 17).map(|f| b.quad_faces.push(f))
                        } else {
                            Ok(())
                        }
                    }
                }
                .map(|()| *pos += quad_len)
            }
            _ => {
                let mut src = BinarySource::<BE> { data, pos: *pos };
                let r = read_face_record(&mut src, el, layout, b);
                *pos = src.pos;
                r
            }
        };
        r.map_err(|e| map_err(e, el, rec, b.vertex_count))?;
        rec += 1;
    }
    Ok(())
}

fn signed_face_index(el: &Element) -> bool {
    matches!(
        el.props.get(1).map(|p| p.kind),
        Some(PropKind::Scalar(Scalar::I32))
    )
}

struct Plan {
    vertex: usize,
    vertex_layout: VertexLayout,
    face: usize,
    face_layout: FaceLayout,
}

fn plan(header: &Header) -> Result<Plan, PlyErrorKind> {
    let find = |name| header.elements.iter().position(|e| e.name == name);
    let vertex = find("vertex").ok_or(PlyErrorKind::MissingElement("vertex"))?;
    let face = find("face").ok_or(PlyErrorKind::MissingElement("face"))?;
    Ok(Plan {
        vertex,
        vertex_layout: vertex_layout(&header.elements[vertex])?,
        face,
        face_layout: face_layout(&header.elements[face])?,
    })
}

fn read_binary<const BE: bool>(
    data: &[u8],
    header: &Header,
    plan: &Plan,
    b: &mut Builder,
) -> Result<usize, PlyErrorKind> {
    let mut pos = 0;
    for (i, el) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            if let Some(size) = el.fixed_size() {
                read_vertices_fixed::<BE>(data, &mut pos, el, &plan.vertex_layout, size, b)?;
                continue;
            }
        } else if i == plan.face {
            if let Some((signed, fi)) = fast_face_layout(el, &plan.face_layout) {
                read_faces_fast::<BE>(data, &mut pos, el, &plan.face_layout, signed, fi, b)?;
                continue;
            }
        } else if let Some(size) = el.fixed_size() {
            let skip = usize::try_from(el.count)
                .ok()
                .and_then(|n| n.checked_mul(size))
                .filter(|&n| n <= data.len() - pos)
                .ok_or_else(|| PlyErrorKind::Truncated {
                    element: el.name.clone(),
                    expected: el.count,
                    read: ((data.len() - pos) / size.max(1)) as u64,
                })?;
            pos += skip;
            continue;
        }
        let mut src = BinarySource::<BE> { data, pos };
        if i == plan.vertex {
            read_vertices_general(&mut src, el, &plan.vertex_layout, b)?;
        } else if i == plan.face {
            read_faces_general(&mut src, el, &plan.face_layout, b)?;
        } else {
            skip_element(&mut src, el)?;
        }
        pos = src.pos;
    }
    Ok(data.len() - pos)
}

fn read_ascii(
    data: &[u8],
    header: &Header,
    plan: &Plan,
    b: &mut Builder,
) -> Result<bool, PlyErrorKind> {
    let mut src = AsciiSource { data, pos: 0 };
    for (i, el) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            read_vertices_general(&mut src, el, &plan.vertex_layout, b)?;
        } else if i == plan.face {
            read_faces_general(&mut src, el, &plan.face_layout, b)?;
        } else {
            skip_element(&mut src, el)?;
        }
    }
    Ok(src.token().is_some())
}

fn gunzip(bytes: &[u8]) -> Result<Vec<u8>, PlyErrorKind> {
    // The trailer's ISIZE (uncompressed size mod 2^32) is a capacity hint;
    // capped at a modest ratio so that a forged trailer cannot drive the
    // allocation.
    let hint = bytes
        .len()
        .checked_sub(4)
        .and_then(|i| bytes.get(i..))
        .map_or(0, |t| u32::from_le_bytes([t[0], t[1], t[2], t[3]]) as usize);
    let mut out = Vec::with_capacity(hint.min(bytes.len().saturating_mul(16)));
    flate2::read::MultiGzDecoder::new(bytes)
        .read_to_end(&mut out)
        .map_err(PlyErrorKind::Gzip)?;
    Ok(out)
}

pub(super) fn is_gzip(bytes: &[u8]) -> bool {
    bytes.starts_with(&[0x1f, 0x8b])
}

fn parse_uncompressed(bytes: &[u8]) -> Result<PlyMesh, PlyErrorKind> {
    let header = parse_header(bytes)?;
    let plan = plan(&header)?;
    let data = bytes.get(header.data_start..).unwrap_or(&[]);
    let mut b = Builder {
        vertex_count: header.elements[plan.vertex].count,
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
        tris: Vec::new(),
        quads: Vec::new(),
        tri_faces: Vec::new(),
        quad_faces: Vec::new(),
        poly: Vec::new(),
        fans: 0,
        ignored: 0,
    };
    let mut warnings = Vec::new();
    match header.format {
        Format::Ascii => {
            if read_ascii(data, &header, &plan, &mut b)? {
                warnings.push("ignored trailing data after the last element".to_string());
            }
        }
        Format::BinaryLittleEndian | Format::BinaryBigEndian => {
            let trailing = if header.format == Format::BinaryBigEndian {
                read_binary::<true>(data, &header, &plan, &mut b)?
            } else {
                read_binary::<false>(data, &header, &plan, &mut b)?
            };
            if trailing > 0 {
                warnings.push(format!(
                    "ignored {trailing} bytes of trailing data after the last element"
                ));
            }
        }
    }
    if b.fans > 0 {
        warnings.push(format!(
            "triangulated {} faces with more than 4 vertices as triangle fans",
            b.fans
        ));
    }
    if b.ignored > 0 {
        warnings.push(format!(
            "ignored {} faces with fewer than 3 vertices",
            b.ignored
        ));
    }
    let non_finite = b
        .positions
        .iter()
        .filter(|p| !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()))
        .count();
    if non_finite > 0 {
        warnings.push(format!(
            "{non_finite} vertices have non-finite (NaN or infinite) coordinates"
        ));
    }
    let mut face_indices = Vec::new();
    if plan.face_layout.face_index.is_some() {
        face_indices = b.tri_faces;
        face_indices.extend_from_slice(&b.quad_faces);
    }
    Ok(PlyMesh {
        positions: b.positions,
        normals: b.normals,
        uvs: b.uvs,
        tri_indices: b.tris,
        quad_indices: b.quads,
        face_indices,
        warnings,
    })
}

pub(super) fn parse_any(bytes: &[u8], gzip: bool) -> Result<PlyMesh, PlyErrorKind> {
    if gzip || is_gzip(bytes) {
        parse_uncompressed(&gunzip(bytes)?)
    } else {
        parse_uncompressed(bytes)
    }
}
