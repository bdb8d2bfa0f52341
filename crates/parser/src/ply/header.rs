//! The PLY header: the `format` line and the `element` / `property`
//! declarations that describe the body (the PLY format of Turk's "The PLY
//! Polygon File Format", as read by pbrt-v4's `plymesh` via rply).

use std::io::{self, BufRead, Read};

use super::types::PlyErrorKind;

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    pub(super) fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PropKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: PropKind,
}

#[derive(Clone, Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
}

impl Element {
    /// Size in bytes of one binary record, if every property is a scalar.
    pub(super) fn fixed_size(&self) -> Option<usize> {
        self.props
            .iter()
            .map(|p| match p.kind {
                PropKind::Scalar(t) => Some(t.size()),
                PropKind::List { .. } => None,
            })
            .sum()
    }

    /// A lower bound on the bytes one record occupies in a binary body.
    pub(super) fn min_binary_size(&self) -> usize {
        self.props
            .iter()
            .map(|p| match p.kind {
                PropKind::Scalar(t) => t.size(),
                PropKind::List { count, .. } => count.size(),
            })
            .sum()
    }

    pub(super) fn find(&self, name: &str) -> Option<usize> {
        self.props.iter().position(|p| p.name == name)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) format: Format,
    pub(super) elements: Vec<Element>,
    /// Size of the header in bytes: the offset of the first body byte.
    pub(super) data_start: usize,
}

/// The longest header line accepted, in bytes (the body is read as a stream,
/// so a file without line breaks must not be read whole into one line).
pub(super) const MAX_LINE: usize = 1 << 20;

/// One header line.
enum Line {
    /// The line, without its `\n` or `\r\n`.
    Text,
    /// Longer than [`MAX_LINE`].
    TooLong,
    /// The data ended.
    End,
}

/// Reads the next `\n`-terminated line into `buf` (without `\r\n`), adding
/// the bytes consumed to `pos`.
fn next_line<R: BufRead>(r: &mut R, buf: &mut Vec<u8>, pos: &mut usize) -> io::Result<Line> {
    buf.clear();
    let n = r
        .by_ref()
        .take(MAX_LINE as u64 + 1)
        .read_until(b'\n', buf)?;
    *pos += n;
    if n == 0 {
        return Ok(Line::End);
    }
    if buf.last() == Some(&b'\n') {
        buf.pop();
    } else if buf.len() > MAX_LINE {
        return Ok(Line::TooLong);
    }
    if buf.last() == Some(&b'\r') {
        buf.pop();
    }
    Ok(Line::Text)
}

pub(super) fn lossy(bytes: &[u8]) -> String {
    const MAX: usize = 40;
    let s = String::from_utf8_lossy(&bytes[..bytes.len().min(MAX)]).into_owned();
    if bytes.len() > MAX {
        s + "..."
    } else {
        s
    }
}

/// Reads the header from the start of `r`, leaving `r` at the first body byte.
pub(super) fn parse_header<R: BufRead>(r: &mut R) -> Result<Header, PlyErrorKind> {
    let mut pos = 0;
    let mut buf = Vec::new();
    match next_line(r, &mut buf, &mut pos).map_err(PlyErrorKind::Io)? {
        Line::Text if buf.trim_ascii() == b"ply" => {}
        _ => return Err(PlyErrorKind::BadMagic),
    }
    let mut line_no = 1;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        match next_line(r, &mut buf, &mut pos).map_err(PlyErrorKind::Io)? {
            Line::Text => {}
            Line::TooLong => {
                return Err(PlyErrorKind::Header {
                    line: line_no + 1,
                    message: format!("line longer than {MAX_LINE} bytes"),
                })
            }
            Line::End => {
                return Err(PlyErrorKind::Header {
                    line: line_no,
                    message: "missing 'end_header'".into(),
                })
            }
        }
        let line = &buf[..];
        line_no += 1;
        let err = |message: String| PlyErrorKind::Header {
            line: line_no,
            message,
        };
        let tokens: Vec<&[u8]> = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
            .collect();
        let Some(&keyword) = tokens.first() else {
            continue;
        };
        match keyword {
            b"comment" | b"obj_info" => {}
            b"end_header" => break,
            b"format" => {
                if format.is_some() {
                    return Err(err("duplicate 'format' line".into()));
                }
                let [_, name, version] = tokens[..] else {
                    return Err(err("expected 'format <type> 1.0'".into()));
                };
                format = Some(match name {
                    b"ascii" => Format::Ascii,
                    b"binary_little_endian" => Format::BinaryLittleEndian,
                    b"binary_big_endian" => Format::BinaryBigEndian,
                    other => return Err(err(format!("unknown format '{}'", lossy(other)))),
                });
                if version != b"1.0" && version != b"1" {
                    return Err(err(format!("unsupported version '{}'", lossy(version))));
                }
            }
            b"element" => {
                let [_, name, count] = tokens[..] else {
                    return Err(err("expected 'element <name> <count>'".into()));
                };
                let count = std::str::from_utf8(count)
                    .ok()
                    .and_then(|s| s.parse::<u64>().ok())
                    .ok_or_else(|| err(format!("invalid element count '{}'", lossy(count))))?;
                let name = String::from_utf8_lossy(name).into_owned();
                if (name == "vertex" || name == "face") && elements.iter().any(|e| e.name == name) {
                    return Err(err(format!("duplicate '{name}' element")));
                }
                elements.push(Element {
                    name,
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(err("'property' before any 'element'".into()));
                };
                let ty = |name: &[u8]| {
                    Scalar::from_name(name)
                        .ok_or_else(|| err(format!("unknown property type '{}'", lossy(name))))
                };
                let (kind, name) = match tokens[..] {
                    [_, b"list", count, item, name] => {
                        let count = ty(count)?;
                        if !count.is_integer() {
                            return Err(err("list count type must be an integer type".into()));
                        }
                        (
                            PropKind::List {
                                count,
                                item: ty(item)?,
                            },
                            name,
                        )
                    }
                    [_, t, name] if t != b"list" => (PropKind::Scalar(ty(t)?), name),
                    _ => {
                        return Err(err("expected 'property <type> <name>' or \
                             'property list <count type> <item type> <name>'"
                            .into()))
                    }
                };
                element.props.push(Property {
                    name: String::from_utf8_lossy(name).into_owned(),
                    kind,
                });
            }
            other => return Err(err(format!("unknown keyword '{}'", lossy(other)))),
        }
    }
    let format = format.ok_or(PlyErrorKind::Header {
        line: line_no,
        message: "no 'format' line".into(),
    })?;
    Ok(Header {
        format,
        elements,
        data_start: pos,
    })
}
