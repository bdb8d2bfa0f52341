//! The byte stream under the PLY body decoder: a [`BufRead`] (a slice in
//! memory, a file, a gzip stream) read window by window, with values that
//! straddle two windows gathered in a small scratch buffer; and the two
//! value sources on top of it, binary and ASCII.
//!
//! Nothing here holds more than one window of the body, whatever the header
//! says: counts are only trusted as the data they describe arrives.

use std::io::{self, BufRead};

use super::header::{lossy, Element, Scalar};

/// Why a value could not be read; turned into a [`PlyErrorKind`](super::PlyErrorKind) by the
/// element loop, which knows the element and record.
pub(super) enum ReadErr {
    /// The data ended.
    Eof,
    /// A malformed value.
    Bad(String),
    /// A vertex index out of range.
    Index(i64),
    /// The underlying reader failed (for gzip: corrupt or truncated data).
    Io(io::Error),
    /// The mesh grew past the memory budget.
    Budget(crate::budget::OverBudget),
}

#[inline(always)]
pub(super) fn array_at<const N: usize>(b: &[u8], off: usize) -> [u8; N] {
    let mut a = [0u8; N];
    a.copy_from_slice(&b[off..off + N]);
    a
}

macro_rules! decode_num {
    ($t:ty, $n:literal, $be:expr, $b:expr, $off:expr) => {{
        let a = $crate::ply::stream::array_at::<$n>($b, $off);
        if $be {
            <$t>::from_be_bytes(a)
        } else {
            <$t>::from_le_bytes(a)
        }
    }};
}
pub(super) use decode_num;

/// Decodes a scalar at `off` (which the caller has bounds-checked) as `f32`.
#[inline(always)]
pub(super) fn decode_f32<const BE: bool>(ty: Scalar, b: &[u8], off: usize) -> f32 {
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

pub(super) fn float_to_int(f: f64) -> Result<i64, ReadErr> {
    if f.is_finite() && f.fract() == 0.0 && f.abs() < 9.0e15 {
        Ok(f as i64)
    } else {
        Err(ReadErr::Bad(format!("expected an integer, found {f}")))
    }
}

/// Decodes a scalar at `off` (which the caller has bounds-checked) as an integer.
#[inline(always)]
pub(super) fn decode_int<const BE: bool>(ty: Scalar, b: &[u8], off: usize) -> Result<i64, ReadErr> {
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

// ---------------------------------------------------------------------------
// The stream

/// The rest of a PLY body, read window by window.
pub(super) struct Input<R> {
    r: R,
    /// Bytes consumed so far.
    consumed: u64,
    /// Size of the body in bytes, when known or guessed without reading it;
    /// sizes reservations.
    total: Option<u64>,
    /// `total` is the body's exact size (data in memory, plain files), not a
    /// guess (a gzip trailer's).
    exact: bool,
    /// A value or token that straddles two windows.
    scratch: Vec<u8>,
}

/// The reader's current window, empty at the end of the data.
#[inline]
fn fill<R: BufRead>(r: &mut R) -> Result<&[u8], ReadErr> {
    loop {
        match r.fill_buf() {
            Ok(_) => break,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(ReadErr::Io(e)),
        }
    }
    // A second call returns the same window without reading.
    r.fill_buf().map_err(ReadErr::Io)
}

impl<R: BufRead> Input<R> {
    /// Wraps `r`, positioned at the first body byte; `total` is the size of
    /// the body when known (`exact`) or guessed.
    pub(super) fn new(r: R, total: Option<u64>, exact: bool) -> Self {
        Input {
            r,
            consumed: 0,
            total,
            exact,
            scratch: Vec::new(),
        }
    }

    /// The bytes available now without reading further; empty only at the
    /// end of the data.
    #[inline]
    pub(super) fn window(&mut self) -> Result<&[u8], ReadErr> {
        fill(&mut self.r)
    }

    /// Marks `n` bytes of the window as used.
    #[inline]
    pub(super) fn consume(&mut self, n: usize) {
        self.r.consume(n);
        self.consumed += n as u64;
    }

    /// How many records of at least `size` bytes the rest of the body can
    /// (probably) hold, capped at `count`, for sizing reservations; `None`
    /// when the body's size is unknown.
    pub(super) fn fits(&self, count: u64, size: usize) -> Option<usize> {
        let left = self.total?.saturating_sub(self.consumed);
        usize::try_from(count.min(left / size.max(1) as u64)).ok()
    }

    /// [`fits`](Self::fits) when the body's size is known exactly, so that a
    /// short body can be reported before it is read.
    pub(super) fn fits_exactly(&self, count: u64, size: usize) -> Option<usize> {
        self.fits(count, size).filter(|_| self.exact)
    }

    /// Passes the next `n` bytes to `f`, straight from the window when they
    /// are all there, gathered into the scratch buffer when they straddle
    /// the window's end.
    #[inline]
    pub(super) fn with_bytes<T>(
        &mut self,
        n: usize,
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, ReadErr> {
        let buf = fill(&mut self.r)?;
        if buf.len() >= n {
            let v = f(&buf[..n]);
            self.consume(n);
            return Ok(v);
        }
        self.scratch.clear();
        while self.scratch.len() < n {
            let buf = fill(&mut self.r)?;
            if buf.is_empty() {
                return Err(ReadErr::Eof);
            }
            let k = (n - self.scratch.len()).min(buf.len());
            self.scratch.extend_from_slice(&buf[..k]);
            self.r.consume(k);
            self.consumed += k as u64;
        }
        Ok(f(&self.scratch))
    }

    /// Skips up to `n` bytes; returns how many there were.
    pub(super) fn skip(&mut self, n: u64) -> Result<u64, ReadErr> {
        let mut done = 0;
        while done < n {
            let avail = fill(&mut self.r)?.len();
            if avail == 0 {
                break;
            }
            let k = usize::try_from(n - done).map_or(avail, |left| left.min(avail));
            self.consume(k);
            done += k as u64;
        }
        Ok(done)
    }

    /// Reads to the end of the data (which checks a gzip stream's trailer);
    /// returns the number of bytes that were left.
    pub(super) fn drain(&mut self) -> Result<u64, ReadErr> {
        self.skip(u64::MAX)
    }

    /// Passes the next whitespace-separated token to `f`; `None` at the end
    /// of the data.
    pub(super) fn token<T>(&mut self, f: impl FnOnce(&[u8]) -> T) -> Result<Option<T>, ReadErr> {
        loop {
            let buf = fill(&mut self.r)?;
            if buf.is_empty() {
                return Ok(None);
            }
            match buf.iter().position(|b| !b.is_ascii_whitespace()) {
                Some(i) => {
                    self.consume(i);
                    break;
                }
                None => {
                    let n = buf.len();
                    self.consume(n);
                }
            }
        }
        let buf = fill(&mut self.r)?;
        if let Some(end) = buf.iter().position(|b| b.is_ascii_whitespace()) {
            let v = f(&buf[..end]);
            self.consume(end);
            return Ok(Some(v));
        }
        // The token runs to the end of the window: gather it.
        self.scratch.clear();
        loop {
            let buf = fill(&mut self.r)?;
            if buf.is_empty() {
                break;
            }
            let (k, done) = match buf.iter().position(|b| b.is_ascii_whitespace()) {
                Some(end) => (end, true),
                None => (buf.len(), false),
            };
            self.scratch.extend_from_slice(&buf[..k]);
            self.r.consume(k);
            self.consumed += k as u64;
            if done {
                break;
            }
        }
        Ok(Some(f(&self.scratch)))
    }
}

// ---------------------------------------------------------------------------
// Value sources

/// A stream of property values: binary records or ASCII tokens.
pub(super) trait Source {
    /// How many records of `el` the rest of the body can hold, capped at its
    /// count; `None` when the body's size is unknown.
    fn plausible_records(&self, el: &Element) -> Option<usize>;
    /// The next value, of type `ty`, as a float.
    fn read_f32(&mut self, ty: Scalar) -> Result<f32, ReadErr>;
    /// The next value, of type `ty`, as an integer.
    fn read_int(&mut self, ty: Scalar) -> Result<i64, ReadErr>;
    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), ReadErr>;
}

/// Binary values, big-endian when `BE`.
pub(super) struct BinarySource<'a, R, const BE: bool>(pub(super) &'a mut Input<R>);

impl<R: BufRead, const BE: bool> Source for BinarySource<'_, R, BE> {
    fn plausible_records(&self, el: &Element) -> Option<usize> {
        self.0.fits(el.count, el.min_binary_size())
    }

    #[inline]
    fn read_f32(&mut self, ty: Scalar) -> Result<f32, ReadErr> {
        self.0.with_bytes(ty.size(), |b| decode_f32::<BE>(ty, b, 0))
    }

    #[inline]
    fn read_int(&mut self, ty: Scalar) -> Result<i64, ReadErr> {
        self.0
            .with_bytes(ty.size(), |b| decode_int::<BE>(ty, b, 0))?
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), ReadErr> {
        let bytes = n.checked_mul(ty.size() as u64).ok_or(ReadErr::Eof)?;
        if self.0.skip(bytes)? < bytes {
            return Err(ReadErr::Eof);
        }
        Ok(())
    }
}

/// ASCII values, one whitespace-separated token each.
pub(super) struct AsciiSource<'a, R>(pub(super) &'a mut Input<R>);

impl<R: BufRead> AsciiSource<'_, R> {
    fn parse<T>(&mut self, f: impl FnOnce(&str) -> Result<T, ReadErr>) -> Result<T, ReadErr> {
        let r = self.0.token(|tok| match std::str::from_utf8(tok) {
            Ok(s) => f(s),
            Err(_) => Err(ReadErr::Bad(format!("invalid number '{}'", lossy(tok)))),
        })?;
        r.unwrap_or(Err(ReadErr::Eof))
    }
}

impl<R: BufRead> Source for AsciiSource<'_, R> {
    fn plausible_records(&self, el: &Element) -> Option<usize> {
        // Every value is at least one character plus a separator.
        self.0.fits(el.count, el.props.len())
    }

    fn read_f32(&mut self, _ty: Scalar) -> Result<f32, ReadErr> {
        self.parse(|s| {
            s.parse::<f32>()
                .map_err(|_| ReadErr::Bad(format!("invalid number '{}'", lossy(s.as_bytes()))))
        })
    }

    fn read_int(&mut self, _ty: Scalar) -> Result<i64, ReadErr> {
        self.parse(|s| match s.parse::<i64>() {
            Ok(i) => Ok(i),
            Err(_) => match s.parse::<f64>() {
                Ok(f) => float_to_int(f),
                Err(_) => Err(ReadErr::Bad(format!(
                    "invalid integer '{}'",
                    lossy(s.as_bytes())
                ))),
            },
        })
    }

    fn skip(&mut self, _ty: Scalar, n: u64) -> Result<(), ReadErr> {
        for _ in 0..n {
            self.0.token(|_| ())?.ok_or(ReadErr::Eof)?;
        }
        Ok(())
    }
}
