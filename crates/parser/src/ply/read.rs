//! Decoding a PLY body into a [`PlyMesh`]: a fast path for the fixed-size
//! binary records exporters write, and a general property-by-property decoder
//! for everything else (ASCII, lists, unusual types).

use std::io::{BufRead, BufReader};

use super::header::{parse_header, Element, Format, Header, PropKind, Scalar};
use super::stream::{decode_f32, decode_num, AsciiSource, BinarySource, Input, ReadErr, Source};
use super::types::{PlyErrorKind, PlyMesh};
use crate::budget::MemoryBudget;

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
// Assembling the mesh

/// Bytes of decompressed data decoded at a time when reading a gzip stream.
const WINDOW: usize = 256 * 1024;

/// The first reservation, in elements, for an array whose final size is not
/// yet backed by data (a gzip body, whose size is unknown until read).
const FIRST_RESERVE: usize = 4096;

/// Makes room for `n` more elements in `v`, growing geometrically (from
/// [`FIRST_RESERVE`]) but never past `total` elements in all unless `n`
/// itself needs it. Callers pass the records actually present in the data as
/// `n` and the header's count as `total`, so a lying count never drives an
/// allocation, and a truthful one ends with no excess capacity.
#[inline]
fn reserve_upto<T>(v: &mut Vec<T>, n: usize, total: usize) {
    if v.capacity() - v.len() >= n {
        return;
    }
    let grow = v.capacity().max(FIRST_RESERVE);
    let room = total.saturating_sub(v.len());
    v.reserve_exact(grow.min(room).max(n));
}

struct Builder {
    /// What the arrays are charged to.
    budget: MemoryBudget,
    /// Bytes charged for the arrays so far.
    charged: u64,
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
    /// Bytes the mesh's arrays hold (their capacity).
    fn held_bytes(&self) -> u64 {
        let f32x3 = std::mem::size_of::<[f32; 3]>();
        let f32x2 = std::mem::size_of::<[f32; 2]>();
        let n = (self.positions.capacity() + self.normals.capacity()) * f32x3
            + self.uvs.capacity() * f32x2
            + (self.tris.capacity() + self.quads.capacity()) * 4
            + (self.tri_faces.capacity() + self.quad_faces.capacity()) * 4;
        n as u64
    }

    /// Charges what the arrays grew by since the last call: a mesh that
    /// inflates past the budget stops here, with the error.
    fn account(&mut self) -> Result<(), ReadErr> {
        let held = self.held_bytes();
        if held > self.charged {
            self.charge(held - self.charged, held)?;
        }
        Ok(())
    }

    /// Charges `bytes` more, the arrays then holding `held`; on failure,
    /// gives back everything the mesh had charged.
    fn charge(&mut self, bytes: u64, held: u64) -> Result<(), ReadErr> {
        if self.budget.charge(bytes, "this mesh").is_err() {
            self.budget.release(self.charged);
            self.charged = 0;
            return Err(ReadErr::Budget(self.budget.exceeded(held, "this mesh")));
        }
        self.charged += bytes;
        Ok(())
    }

    /// Makes room for the face in `self.poly` (its triangles or quad and
    /// their face indices), charging any growth before it is allocated:
    /// polygons are what can make a mesh outgrow its header's counts.
    fn reserve_face(&mut self, with_face_index: bool) -> Result<(), ReadErr> {
        let (tris, quads) = match self.poly.len() {
            0..=2 => return Ok(()),
            3 => (1, 0),
            4 => (0, 1),
            n => (n - 2, 0),
        };
        let fi = usize::from(with_face_index);
        // New capacities: doubled (from FIRST_RESERVE) when full.
        let grown = |len: usize, cap: usize, extra: usize| {
            if cap - len >= extra {
                cap
            } else {
                (cap * 2).max(len + extra).max(FIRST_RESERVE)
            }
        };
        let caps = [
            grown(self.tris.len(), self.tris.capacity(), 3 * tris),
            grown(self.quads.len(), self.quads.capacity(), 4 * quads),
            grown(self.tri_faces.len(), self.tri_faces.capacity(), fi * tris),
            grown(
                self.quad_faces.len(),
                self.quad_faces.capacity(),
                fi * quads,
            ),
        ];
        let now = [
            self.tris.capacity(),
            self.quads.capacity(),
            self.tri_faces.capacity(),
            self.quad_faces.capacity(),
        ];
        let extra: usize = caps.iter().zip(now).map(|(c, n)| c - n).sum();
        if extra == 0 {
            return Ok(());
        }
        let bytes = 4 * extra as u64;
        self.charge(bytes, self.held_bytes() + bytes)?;
        let len = [
            self.tris.len(),
            self.quads.len(),
            self.tri_faces.len(),
            self.quad_faces.len(),
        ];
        self.tris.reserve_exact(caps[0] - len[0]);
        self.quads.reserve_exact(caps[1] - len[1]);
        self.tri_faces.reserve_exact(caps[2] - len[2]);
        self.quad_faces.reserve_exact(caps[3] - len[3]);
        Ok(())
    }

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

    /// Reserves room for `n` vertices, a number the data has been checked to
    /// hold.
    fn reserve_vertices(&mut self, n: usize, layout: &VertexLayout) {
        self.positions.reserve(n);
        if layout.normals {
            self.normals.reserve(n);
        }
        if layout.uvs {
            self.uvs.reserve(n);
        }
    }

    /// Makes room for `n` more vertices (see [`reserve_upto`]).
    #[inline]
    fn grow_vertices(&mut self, n: usize, total: usize, layout: &VertexLayout) {
        reserve_upto(&mut self.positions, n, total);
        if layout.normals {
            reserve_upto(&mut self.normals, n, total);
        }
        if layout.uvs {
            reserve_upto(&mut self.uvs, n, total);
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
        ReadErr::Io(e) => PlyErrorKind::Io(e),
        ReadErr::Budget(e) => PlyErrorKind::OverBudget(e),
    }
}

/// The header's count of `el` as a `usize` (saturating), for capping
/// reservations.
fn count_usize(el: &Element) -> usize {
    usize::try_from(el.count).unwrap_or(usize::MAX)
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
    if let Some(n) = src.plausible_records(el) {
        b.reserve_vertices(n, layout);
    }
    let total = count_usize(el);
    for rec in 0..el.count {
        let mut v = [0.0f32; SLOT_COUNT];
        for (p, slot) in el.props.iter().zip(&layout.slots) {
            let r = match (p.kind, slot) {
                (PropKind::Scalar(t), Some(s)) => src.read_f32(t).map(|x| v[*s] = x),
                (kind, _) => skip_property(src, kind),
            };
            r.map_err(|e| map_err(e, el, rec, 0))?;
        }
        b.grow_vertices(1, total, layout);
        b.push_vertex(&v, layout.normals, layout.uvs);
        b.account().map_err(|e| map_err(e, el, rec, 0))?;
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
    b.reserve_face(face_index.is_some())?;
    b.emit_face(face_index);
    b.account()
}

fn read_faces_general<S: Source>(
    src: &mut S,
    el: &Element,
    layout: &FaceLayout,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    if let Some(n) = src.plausible_records(el) {
        b.tris.reserve(n.saturating_mul(3));
    }
    let total = count_usize(el).saturating_mul(3);
    for rec in 0..el.count {
        reserve_upto(&mut b.tris, 3, total);
        read_face_record(src, el, layout, b).map_err(|e| map_err(e, el, rec, b.vertex_count))?;
    }
    Ok(())
}

/// Where the fixed-size vertex fast path finds each of x y z nx ny nz u v.
struct VertexFields {
    /// (offset, type) of each slot; unused slots read field 0 harmlessly.
    fields: [(usize, Scalar); SLOT_COUNT],
    /// Every needed field is an `f32`.
    all_f32: bool,
    normals: bool,
    uvs: bool,
}

impl VertexFields {
    fn new(el: &Element, layout: &VertexLayout) -> VertexFields {
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
        VertexFields {
            fields,
            all_f32,
            normals: layout.normals,
            uvs: layout.uvs,
        }
    }

    /// Decodes the whole records in `body` (a multiple of `record_size`).
    #[inline]
    fn decode<const BE: bool>(&self, body: &[u8], record_size: usize, b: &mut Builder) {
        let (fields, normals, uvs) = (&self.fields, self.normals, self.uvs);
        if self.all_f32 {
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
    }
}

/// Fixed-size binary vertex records: decode each field at its offset, a
/// window of records at a time.
fn read_vertices_fixed<R: BufRead, const BE: bool>(
    input: &mut Input<R>,
    el: &Element,
    layout: &VertexLayout,
    record_size: usize,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    let truncated = |read: u64| PlyErrorKind::Truncated {
        element: el.name.clone(),
        expected: el.count,
        read,
    };
    if let Some(n) = input.fits_exactly(el.count, record_size) {
        // The body's size is known: a short one fails before decoding.
        if (n as u64) < el.count {
            return Err(truncated(n as u64));
        }
    }
    if let Some(n) = input.fits(el.count, record_size) {
        b.reserve_vertices(n, layout);
    }
    if record_size == 0 {
        return Ok(());
    }
    let fields = VertexFields::new(el, layout);
    let total = count_usize(el);
    let mut read = 0u64;
    while read < el.count {
        let buf = input.window().map_err(|e| map_err(e, el, read, 0))?;
        let left = usize::try_from(el.count - read).unwrap_or(usize::MAX);
        let n = (buf.len() / record_size).min(left);
        if n > 0 {
            b.grow_vertices(n, total, layout);
            b.account().map_err(|e| map_err(e, el, read, 0))?;
            fields.decode::<BE>(&buf[..n * record_size], record_size, b);
            input.consume(n * record_size);
            read += n as u64;
        } else {
            // One record straddles the end of the window (or the data ends).
            b.grow_vertices(1, total, layout);
            b.account().map_err(|e| map_err(e, el, read, 0))?;
            input
                .with_bytes(record_size, |rec| fields.decode::<BE>(rec, record_size, b))
                .map_err(|e| map_err(e, el, read, 0))?;
            read += 1;
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

/// Faces in the layout of [`fast_face_layout`]: triangles and quads decoded
/// straight from the window; anything else (other vertex counts, a record
/// that straddles two windows) goes through [`read_face_record`].
fn read_faces_fast<R: BufRead, const BE: bool>(
    input: &mut Input<R>,
    el: &Element,
    layout: &FaceLayout,
    signed: bool,
    with_face_index: bool,
    b: &mut Builder,
) -> Result<(), PlyErrorKind> {
    let fi_len = if with_face_index { 4 } else { 0 };
    let tri_len = 13 + fi_len;
    let quad_len = 17 + fi_len;
    if let Some(plausible) = input.fits(el.count, tri_len) {
        b.tris.reserve(plausible.saturating_mul(3));
        if with_face_index {
            b.tri_faces.reserve(plausible);
        }
    }
    let total = count_usize(el);
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
    let signed_fi = signed_face_index(el);
    let face_index = |rec: &[u8], off: usize| -> Result<i32, ReadErr> {
        let raw = decode_num!(u32, 4, BE, rec, off);
        if signed_fi {
            Ok(raw as i32)
        } else {
            i32::try_from(raw)
                .map_err(|_| ReadErr::Bad(format!("face index {raw} does not fit in 32 bits")))
        }
    };
    let mut rec = 0u64;
    while rec < el.count {
        let buf = input
            .window()
            .map_err(|e| map_err(e, el, rec, b.vertex_count))?;
        // At most this many triangles start in the window.
        let in_window = (buf.len() / tri_len).min(total);
        reserve_upto(
            &mut b.tris,
            in_window.saturating_mul(3),
            total.saturating_mul(3),
        );
        if with_face_index {
            reserve_upto(&mut b.tri_faces, in_window, total);
        }
        b.account()
            .map_err(|e| map_err(e, el, rec, b.vertex_count))?;
        let mut pos = 0;
        while rec < el.count {
            let rest = &buf[pos..];
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
                    .map(|()| pos += tri_len)
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
                    .map(|()| pos += quad_len)
                }
                _ => break,
            };
            r.map_err(|e| map_err(e, el, rec, b.vertex_count))?;
            rec += 1;
        }
        input.consume(pos);
        if rec < el.count && pos == 0 {
            // Not a triangle or quad, or one that straddles the window's end.
            let r = read_face_record(&mut BinarySource::<R, BE>(input), el, layout, b);
            r.map_err(|e| map_err(e, el, rec, b.vertex_count))?;
            rec += 1;
        }
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

/// The warning naming the properties and elements the mesh does not use
/// (colours, confidences, materials ...), which are skipped.
fn unused_properties(header: &Header, plan: &Plan) -> Option<String> {
    let mut unused = Vec::new();
    for (e, el) in header.elements.iter().enumerate() {
        if e == plan.vertex {
            let layout = &plan.vertex_layout;
            for (p, prop) in el.props.iter().enumerate() {
                if layout.slots[p].is_none() {
                    unused.push(format!("{}.{}", el.name, prop.name));
                }
            }
        } else if e == plan.face {
            let layout = &plan.face_layout;
            for (p, prop) in el.props.iter().enumerate() {
                if p != layout.indices && Some(p) != layout.face_index {
                    unused.push(format!("{}.{}", el.name, prop.name));
                }
            }
        } else {
            unused.push(format!("element \"{}\"", el.name));
        }
    }
    (!unused.is_empty()).then(|| format!("ignored unused PLY data: {}", unused.join(", ")))
}

/// Reads a binary body; returns the number of bytes after the last element.
fn read_binary<R: BufRead, const BE: bool>(
    input: &mut Input<R>,
    header: &Header,
    plan: &Plan,
    b: &mut Builder,
) -> Result<u64, PlyErrorKind> {
    for (i, el) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            if let Some(size) = el.fixed_size() {
                read_vertices_fixed::<R, BE>(input, el, &plan.vertex_layout, size, b)?;
                continue;
            }
        } else if i == plan.face {
            if let Some((signed, fi)) = fast_face_layout(el, &plan.face_layout) {
                read_faces_fast::<R, BE>(input, el, &plan.face_layout, signed, fi, b)?;
                continue;
            }
        } else if let Some(size) = el.fixed_size() {
            let bytes = el.count.saturating_mul(size as u64);
            let skipped = input.skip(bytes).map_err(|e| map_err(e, el, 0, 0))?;
            if skipped < bytes {
                return Err(PlyErrorKind::Truncated {
                    element: el.name.clone(),
                    expected: el.count,
                    read: skipped / size.max(1) as u64,
                });
            }
            continue;
        }
        let mut src = BinarySource::<R, BE>(input);
        if i == plan.vertex {
            read_vertices_general(&mut src, el, &plan.vertex_layout, b)?;
        } else if i == plan.face {
            read_faces_general(&mut src, el, &plan.face_layout, b)?;
        } else {
            skip_element(&mut src, el)?;
        }
    }
    input.drain().map_err(io_kind)
}

/// Reads an ASCII body; returns whether anything follows the last element.
fn read_ascii<R: BufRead>(
    input: &mut Input<R>,
    header: &Header,
    plan: &Plan,
    b: &mut Builder,
) -> Result<bool, PlyErrorKind> {
    let mut src = AsciiSource(input);
    for (i, el) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            read_vertices_general(&mut src, el, &plan.vertex_layout, b)?;
        } else if i == plan.face {
            read_faces_general(&mut src, el, &plan.face_layout, b)?;
        } else {
            skip_element(&mut src, el)?;
        }
    }
    let trailing = input.token(|_| ()).map_err(io_kind)?.is_some();
    input.drain().map_err(io_kind)?;
    Ok(trailing)
}

/// A stream error outside any element (only [`ReadErr::Io`] can occur).
fn io_kind(e: ReadErr) -> PlyErrorKind {
    match e {
        ReadErr::Io(e) => PlyErrorKind::Io(e),
        ReadErr::Eof => PlyErrorKind::Io(std::io::ErrorKind::UnexpectedEof.into()),
        ReadErr::Bad(m) => PlyErrorKind::Io(std::io::Error::other(m)),
        ReadErr::Index(i) => PlyErrorKind::Io(std::io::Error::other(format!("index {i}"))),
        ReadErr::Budget(e) => PlyErrorKind::OverBudget(e),
    }
}

/// Parses a whole PLY file from `r`, decoding the body as it is read.
/// `total` is the size of the data when known (`exact`) or guessed without
/// reading it; it sizes reservations, and an exact one lets a short body be
/// reported before it is read. Errors from `r` come back as
/// [`PlyErrorKind::Io`].
///
/// The mesh's arrays are charged to `budget`: after the header, what its
/// counts need is checked against it (counts that a body of known size
/// cannot hold are left to the truncation checks), and as the arrays grow
/// they are charged. On an error the charges are given back.
pub(super) fn parse_reader<R: BufRead>(
    mut r: R,
    total: Option<u64>,
    exact: bool,
    budget: &MemoryBudget,
) -> Result<PlyMesh, PlyErrorKind> {
    let header = parse_header(&mut r)?;
    let plan = plan(&header)?;
    let body = total.map(|t| t.saturating_sub(header.data_start as u64));
    check_claim(&header, &plan, body.filter(|_| exact), budget)?;
    let mut input = Input::new(r, body, exact);
    let mut b = Builder {
        budget: budget.clone(),
        charged: 0,
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
    let result = read_body(&mut input, &header, &plan, &mut b);
    if result.is_err() {
        budget.release(b.charged);
    }
    result
}

/// Holds what the header's element counts need against the budget, before
/// any of the body is read. With `body`, the exact size of the body, a
/// count is believed only as far as the body can hold its records.
fn check_claim(
    header: &Header,
    plan: &Plan,
    body: Option<u64>,
    budget: &MemoryBudget,
) -> Result<(), PlyErrorKind> {
    let believed = |el: &Element| -> u64 {
        let min_size = match header.format {
            Format::Ascii => el.props.len(),
            _ => el.min_binary_size(),
        };
        match body {
            Some(b) => el.count.min(b / min_size.max(1) as u64),
            None => el.count,
        }
    };
    let (vertices, faces) = (&header.elements[plan.vertex], &header.elements[plan.face]);
    let layout = &plan.vertex_layout;
    let per_vertex = 12 + 12 * u64::from(layout.normals) + 8 * u64::from(layout.uvs);
    // A face is at least a triangle (12 bytes) and a quad takes 16.
    let per_face = 12 + 4 * u64::from(plan.face_layout.face_index.is_some());
    let (nv, nf) = (believed(vertices), believed(faces));
    let bytes = nv
        .saturating_mul(per_vertex)
        .saturating_add(nf.saturating_mul(per_face));
    let what = format!(
        "this mesh ({} vertices, {} faces)",
        vertices.count, faces.count
    );
    budget.check(bytes, &what).map_err(PlyErrorKind::OverBudget)
}

/// Decodes the body into `b` and assembles the mesh.
fn read_body<R: BufRead>(
    input: &mut Input<R>,
    header: &Header,
    plan: &Plan,
    b: &mut Builder,
) -> Result<PlyMesh, PlyErrorKind> {
    let mut warnings = Vec::new();
    match header.format {
        Format::Ascii => {
            if read_ascii(input, header, plan, b)? {
                warnings.push("ignored trailing data after the last element".to_string());
            }
        }
        Format::BinaryLittleEndian | Format::BinaryBigEndian => {
            let trailing = if header.format == Format::BinaryBigEndian {
                read_binary::<R, true>(input, header, plan, b)?
            } else {
                read_binary::<R, false>(input, header, plan, b)?
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
    if let Some(w) = unused_properties(header, plan) {
        warnings.push(w);
    }
    let mut face_indices = Vec::new();
    if plan.face_layout.face_index.is_some() {
        face_indices = std::mem::take(&mut b.tri_faces);
        face_indices.extend_from_slice(&b.quad_faces);
        b.account()
            .map_err(|e| map_err(e, &header.elements[plan.face], 0, b.vertex_count))?;
    }
    Ok(PlyMesh {
        positions: std::mem::take(&mut b.positions),
        normals: std::mem::take(&mut b.normals),
        uvs: std::mem::take(&mut b.uvs),
        tri_indices: std::mem::take(&mut b.tris),
        quad_indices: std::mem::take(&mut b.quads),
        face_indices,
        warnings,
    })
}

/// Parses a gzip-compressed PLY file held in memory, inflating it as it is
/// decoded. Errors from the decompressor come back as [`PlyErrorKind::Gzip`].
pub(super) fn parse_gzip(bytes: &[u8], budget: &MemoryBudget) -> Result<PlyMesh, PlyErrorKind> {
    let hint = crate::input::gzip_size_hint(bytes);
    let r = BufReader::with_capacity(WINDOW, flate2::read::MultiGzDecoder::new(bytes));
    parse_reader(r, hint, false, budget).map_err(gzip_kind)
}

/// Parses a PLY stream from a file (see [`crate::input::FileReader`]).
pub(super) fn parse_file(
    reader: crate::input::FileReader,
    budget: &MemoryBudget,
) -> Result<PlyMesh, PlyErrorKind> {
    let gzip = reader.is_gzip();
    let total = reader.size_hint();
    let r = BufReader::with_capacity(WINDOW, reader);
    let mesh = parse_reader(r, total, !gzip, budget);
    if gzip {
        mesh.map_err(gzip_kind)
    } else {
        mesh
    }
}

/// Read errors on a gzip stream are decompression errors.
fn gzip_kind(kind: PlyErrorKind) -> PlyErrorKind {
    match kind {
        PlyErrorKind::Io(e) => PlyErrorKind::Gzip(e),
        k => k,
    }
}
