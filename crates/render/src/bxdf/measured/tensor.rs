//! The RGL tensor file format of Dupuy and Jakob's measured materials
//! (pbrt-v4 `bxdfs.cpp`, class `Tensor`).
//!
//! Layout, little-endian: the 12 bytes `"tensor_file\0"`, a version of two
//! bytes (1, 0), a `u32` field count, then per field a `u16` name length,
//! the name, a `u16` rank, a `u8` type code, a `u64` absolute data offset
//! and `rank` `u64` extents. Each field's data lies at its offset, the last
//! extent contiguous.
//!
//! The reader checks every length against the file before it allocates
//! or slices, so truncated or corrupted files give errors, never panics.

use std::collections::HashMap;
use std::path::Path;

/// The magic bytes a tensor file starts with.
pub const TENSOR_MAGIC: &[u8; 12] = b"tensor_file\0";

/// Element types of tensor fields, with pbrt-v4's type codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TensorType {
    /// Code 1.
    UInt8,
    /// Code 2.
    Int8,
    /// Code 3.
    UInt16,
    /// Code 4.
    Int16,
    /// Code 5.
    UInt32,
    /// Code 6.
    Int32,
    /// Code 7.
    UInt64,
    /// Code 8.
    Int64,
    /// Code 9 (IEEE half).
    Float16,
    /// Code 10.
    Float32,
    /// Code 11.
    Float64,
}

impl TensorType {
    /// The type with file code `c`, if any (0 is "invalid").
    pub fn from_code(c: u8) -> Option<Self> {
        use TensorType::*;
        Some(match c {
            1 => UInt8,
            2 => Int8,
            3 => UInt16,
            4 => Int16,
            5 => UInt32,
            6 => Int32,
            7 => UInt64,
            8 => Int64,
            9 => Float16,
            10 => Float32,
            11 => Float64,
            _ => return None,
        })
    }

    /// The file code of the type.
    pub fn code(self) -> u8 {
        self as u8 + 1
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        use TensorType::*;
        match self {
            UInt8 | Int8 => 1,
            UInt16 | Int16 | Float16 => 2,
            UInt32 | Int32 | Float32 => 4,
            UInt64 | Int64 | Float64 => 8,
        }
    }
}

/// One named field of a tensor file.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorField {
    /// The element type.
    pub dtype: TensorType,
    /// The extents, outermost first.
    pub shape: Vec<usize>,
    /// The raw little-endian bytes (`shape` product × element size).
    pub data: Vec<u8>,
}

impl TensorField {
    /// The number of elements.
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// True when the field holds no element.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The elements of a `Float32` field, or `None` for other types.
    pub fn as_f32(&self) -> Option<Vec<f32>> {
        if self.dtype != TensorType::Float32 {
            return None;
        }
        Some(
            self.data
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        )
    }
}

/// The fields of a tensor file by name.
pub type Tensors = HashMap<String, TensorField>;

/// A cursor over the file's bytes that fails instead of reading past the end.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| format!("truncated tensor file: cannot read {what}"))?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }
    fn u16(&mut self, what: &str) -> Result<u16, String> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let b = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
}

/// Parses tensor-file bytes.
pub fn parse_tensor_bytes(bytes: &[u8]) -> Result<Tensors, String> {
    if bytes.len() < 12 + 2 + 4 {
        return Err("invalid tensor file: too small, truncated?".into());
    }
    let mut r = Reader { bytes, pos: 0 };
    if r.take(12, "the header")? != TENSOR_MAGIC {
        return Err("invalid tensor file: invalid header".into());
    }
    let version = r.take(2, "the version")?;
    if version != [1, 0] {
        return Err(format!(
            "invalid tensor file: unknown file version {}.{}",
            version[0], version[1]
        ));
    }
    let n_fields = r.u32("the field count")?;
    let mut fields = Tensors::new();
    for i in 0..n_fields {
        let what = format!("field {i}");
        let name_len = r.u16(&what)? as usize;
        let name = String::from_utf8_lossy(r.take(name_len, &what)?).into_owned();
        let what = format!("field \"{name}\"");
        let ndim = r.u16(&what)? as usize;
        let code = r.u8(&what)?;
        let offset = r.u64(&what)?;
        let dtype = TensorType::from_code(code)
            .ok_or_else(|| format!("invalid tensor file: {what} has unknown type {code}"))?;
        let mut shape = Vec::with_capacity(ndim.min(64));
        let mut total = dtype.size() as u64;
        for _ in 0..ndim {
            let extent = r.u64(&what)?;
            total = total
                .checked_mul(extent)
                .ok_or_else(|| format!("invalid tensor file: {what} is too large"))?;
            shape.push(
                usize::try_from(extent)
                    .map_err(|_| format!("invalid tensor file: {what} is too large"))?,
            );
        }
        let end = offset
            .checked_add(total)
            .filter(|&e| e <= bytes.len() as u64)
            .ok_or_else(|| {
                format!(
                    "truncated tensor file: {what} needs bytes {offset}..{} but the file has {}",
                    offset.saturating_add(total),
                    bytes.len()
                )
            })?;
        let data = bytes[offset as usize..end as usize].to_vec();
        fields.insert(name, TensorField { dtype, shape, data });
    }
    Ok(fields)
}

/// Reads a tensor file (pbrt-v4's `Tensor` constructor), with errors naming
/// the file.
pub fn read_tensor_file(path: &Path) -> Result<Tensors, String> {
    let bytes =
        std::fs::read(path).map_err(|e| format!("{}: unable to open file: {e}", path.display()))?;
    parse_tensor_bytes(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Encodes fields as a tensor file (the inverse of [`parse_tensor_bytes`];
/// fields are written in the given order, data after the headers).
pub fn write_tensor_bytes(fields: &[(&str, &TensorField)]) -> Vec<u8> {
    let mut header_len = 12 + 2 + 4;
    for (name, f) in fields {
        header_len += 2 + name.len() + 2 + 1 + 8 + 8 * f.shape.len();
    }
    let mut out = Vec::with_capacity(header_len);
    out.extend_from_slice(TENSOR_MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    let mut offset = header_len as u64;
    for (name, f) in fields {
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&(f.shape.len() as u16).to_le_bytes());
        out.push(f.dtype.code());
        out.extend_from_slice(&offset.to_le_bytes());
        for &s in &f.shape {
            out.extend_from_slice(&(s as u64).to_le_bytes());
        }
        offset += f.data.len() as u64;
    }
    debug_assert_eq!(out.len(), header_len);
    for (_, f) in fields {
        out.extend_from_slice(&f.data);
    }
    out
}
