//! The tokenizer (pbrt-v4 `parser.cpp`, `Tokenizer`; book appendix C).
//!
//! Splits a scene file held in memory into words, quoted strings and
//! brackets, skipping whitespace and `#` comments (kept aside on request,
//! for `--format`). Tokens are byte ranges
//! into the shared buffer, so nothing is allocated per token; escaped
//! strings are decoded only when their value is asked for. Numbers are
//! parsed with a fast exact path and fall back to the standard library.

use std::borrow::Cow;
use std::sync::Arc;

use crate::diag::Diagnostic;
use crate::loc::FileLoc;

/// What a [`Token`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokenKind {
    /// A bare word: a directive name, a number, `true`/`false`, ...
    Word,
    /// A quoted string; the token's range excludes the quotes.
    /// `escaped` tells whether it contains backslash escapes.
    Str {
        /// The string contains at least one `\` escape.
        escaped: bool,
    },
    /// `[`
    LBracket,
    /// `]`
    RBracket,
}

/// One token: its kind, its byte range in the tokenizer's buffer and where
/// it starts (1-based line and byte column). `Copy`, no allocation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token {
    /// Kind of token.
    pub kind: TokenKind,
    /// Byte offset of the first byte (after the opening quote for strings).
    pub start: usize,
    /// Byte offset one past the last byte (before the closing quote).
    pub end: usize,
    /// 1-based line of the token's first character.
    pub line: u32,
    /// 1-based byte column of the token's first character (the quote for strings).
    pub column: u32,
}

impl Token {
    /// True for a quoted string.
    #[inline]
    pub fn is_string(&self) -> bool {
        matches!(self.kind, TokenKind::Str { .. })
    }
}

/// A scene file's text, shared by its tokenizer and the diagnostics that
/// point into it. A `Vec` behind the `Arc` (not an `Arc<[u8]>`), so that a
/// file read into a vector is shared as it is, without a copy.
pub type SourceText = Arc<Vec<u8>>;

/// Tokenizer over one file's contents.
#[derive(Clone, Debug)]
pub struct Tokenizer {
    name: Arc<str>,
    data: SourceText,
    pos: usize,
    line: u32,
    line_start: usize,
    /// Record comments in `comments` instead of only skipping them.
    keep_comments: bool,
    /// Comments met since the last [`Tokenizer::take_comments`]: line,
    /// column and byte range (from the `#` to the end of the line).
    comments: Vec<(u32, u32, usize, usize)>,
}

/// Bytes that end a bare word, as a table so the hot scan is one load.
static ENDS_WORD: [bool; 256] = {
    let mut t = [false; 256];
    t[b' ' as usize] = true;
    t[b'\n' as usize] = true;
    t[b'\t' as usize] = true;
    t[b'\r' as usize] = true;
    t[b'"' as usize] = true;
    t[b'[' as usize] = true;
    t[b']' as usize] = true;
    t
};

#[inline]
fn ends_word(b: u8) -> bool {
    ENDS_WORD[b as usize]
}

fn saturating_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

impl Tokenizer {
    /// Creates a tokenizer over `data`, reported as file `name`. A UTF-8
    /// byte-order mark is skipped.
    pub fn new(name: Arc<str>, data: SourceText) -> Self {
        let pos = if data.starts_with(&[0xef, 0xbb, 0xbf]) {
            3
        } else {
            0
        };
        Tokenizer {
            name,
            data,
            pos,
            line: 1,
            line_start: 0,
            keep_comments: false,
            comments: Vec::new(),
        }
    }

    /// Makes the tokenizer record the `#` comments it skips, for
    /// [`Tokenizer::take_comments`].
    pub fn set_keep_comments(&mut self, keep: bool) {
        self.keep_comments = keep;
    }

    /// The comments skipped since the last call (when recording them), in
    /// file order: where each starts and its text from the `#` to the end
    /// of the line, trailing whitespace removed.
    pub fn take_comments(&mut self) -> Vec<(FileLoc, String)> {
        let data = &self.data;
        let name = &self.name;
        self.comments
            .drain(..)
            .map(|(line, column, start, end)| {
                let text = String::from_utf8_lossy(&data[start..end]);
                (
                    FileLoc::new(name.clone(), line, column),
                    text.trim_end().to_string(),
                )
            })
            .collect()
    }

    /// Creates a tokenizer over a string (handy for tests and `parse_string`).
    pub fn from_str(name: &str, text: &str) -> Self {
        Self::new(Arc::from(name), Arc::new(text.as_bytes().to_vec()))
    }

    /// An error if the file is UTF-16 encoded (which pbrt does not support).
    pub fn check_encoding(&self) -> Option<Diagnostic> {
        let d = &self.data;
        if d.len() >= 2 && ((d[0] == 0xfe && d[1] == 0xff) || (d[0] == 0xff && d[1] == 0xfe)) {
            Some(Diagnostic::error(
                FileLoc::new(self.name.clone(), 1, 1),
                "file is encoded as UTF-16, which is not supported; convert it to UTF-8",
            ))
        } else {
            None
        }
    }

    /// Name of the file being tokenized.
    pub fn file_name(&self) -> &Arc<str> {
        &self.name
    }

    /// The whole buffer.
    pub fn data(&self) -> &SourceText {
        &self.data
    }

    /// The location of `tok`.
    #[inline]
    pub fn loc(&self, tok: &Token) -> FileLoc {
        FileLoc::new(self.name.clone(), tok.line, tok.column)
    }

    /// The location of the current position (end of file after the last token).
    pub fn here(&self) -> FileLoc {
        FileLoc::new(
            self.name.clone(),
            self.line,
            saturating_u32(self.pos - self.line_start + 1),
        )
    }

    /// The raw bytes of `tok` (without quotes, escapes not decoded).
    #[inline]
    pub fn raw(&self, tok: &Token) -> &[u8] {
        self.data.get(tok.start..tok.end).unwrap_or(&[])
    }

    /// The token's text for messages, lossily decoded.
    pub fn display(&self, tok: &Token) -> String {
        let raw = String::from_utf8_lossy(self.raw(tok));
        match tok.kind {
            TokenKind::Str { .. } => format!("\"{raw}\""),
            _ => raw.into_owned(),
        }
    }

    /// The value of a string token with escapes decoded, or the text of a
    /// word. Errors (located) on invalid UTF-8.
    pub fn string_value(&self, tok: &Token) -> Result<Cow<'_, str>, Diagnostic> {
        let raw = self.raw(tok);
        let decoded: Cow<'_, [u8]> = match tok.kind {
            TokenKind::Str { escaped: true } => {
                let mut out = Vec::with_capacity(raw.len());
                let mut i = 0;
                while i < raw.len() {
                    let c = raw[i];
                    if c == b'\\' && i + 1 < raw.len() {
                        // Escapes were validated while tokenizing.
                        out.push(unescape(raw[i + 1]).unwrap_or(raw[i + 1]));
                        i += 2;
                    } else {
                        out.push(c);
                        i += 1;
                    }
                }
                Cow::Owned(out)
            }
            _ => Cow::Borrowed(raw),
        };
        match decoded {
            Cow::Borrowed(b) => std::str::from_utf8(b)
                .map(Cow::Borrowed)
                .map_err(|_| Diagnostic::error(self.loc(tok), "string is not valid UTF-8")),
            Cow::Owned(v) => String::from_utf8(v)
                .map(Cow::Owned)
                .map_err(|_| Diagnostic::error(self.loc(tok), "string is not valid UTF-8")),
        }
    }

    /// Parses `tok` as a 32-bit float. Quoted strings, malformed numbers
    /// and values out of `f32` range are located errors.
    #[inline]
    pub fn parse_float(&self, tok: &Token) -> Result<f32, Diagnostic> {
        if tok.kind == TokenKind::Word {
            if let Some(v) = parse_f32(self.raw(tok)) {
                if v.is_finite() {
                    return Ok(v);
                }
                return Err(Diagnostic::error(
                    self.loc(tok),
                    format!(
                        "{}: number out of range for a 32-bit float",
                        self.display(tok)
                    ),
                ));
            }
        }
        Err(Diagnostic::error(
            self.loc(tok),
            format!("{}: expected a number", self.display(tok)),
        ))
    }

    /// Parses `tok` as a 32-bit signed integer.
    #[inline]
    pub fn parse_int(&self, tok: &Token) -> Result<i32, Diagnostic> {
        if tok.kind == TokenKind::Word {
            match parse_i32(self.raw(tok)) {
                Ok(v) => return Ok(v),
                Err(IntError::OutOfRange) => {
                    return Err(Diagnostic::error(
                        self.loc(tok),
                        format!(
                            "{}: value too large for a 32-bit integer",
                            self.display(tok)
                        ),
                    ))
                }
                Err(IntError::Invalid) => {}
            }
        }
        Err(Diagnostic::error(
            self.loc(tok),
            format!("{}: expected an integer", self.display(tok)),
        ))
    }

    /// Returns the next token, `Ok(None)` at end of file, or a located
    /// error for a malformed string (after which tokenizing can continue).
    #[inline]
    pub fn next_token(&mut self) -> Result<Option<Token>, Diagnostic> {
        let data = self.data.as_slice();
        let len = data.len();
        let mut pos = self.pos;
        // Skip whitespace and comments.
        loop {
            match data.get(pos) {
                None => {
                    self.pos = pos;
                    return Ok(None);
                }
                Some(b'\n') => {
                    pos += 1;
                    self.line = self.line.saturating_add(1);
                    self.line_start = pos;
                }
                Some(b' ' | b'\t' | b'\r') => pos += 1,
                Some(b'#') => {
                    let start = pos;
                    while pos < len && data[pos] != b'\n' {
                        pos += 1;
                    }
                    if self.keep_comments {
                        let column = saturating_u32(start - self.line_start + 1);
                        self.comments.push((self.line, column, start, pos));
                    }
                }
                Some(_) => break,
            }
        }
        let line = self.line;
        let column = saturating_u32(pos - self.line_start + 1);
        let b = data[pos];
        let tok = match b {
            b'[' | b']' => {
                self.pos = pos + 1;
                Token {
                    kind: if b == b'[' {
                        TokenKind::LBracket
                    } else {
                        TokenKind::RBracket
                    },
                    start: pos,
                    end: pos + 1,
                    line,
                    column,
                }
            }
            b'"' => return self.scan_string(pos, line, column),
            _ => {
                let mut i = pos + 1;
                while i < len && !ends_word(data[i]) {
                    i += 1;
                }
                self.pos = i;
                Token {
                    kind: TokenKind::Word,
                    start: pos,
                    end: i,
                    line,
                    column,
                }
            }
        };
        Ok(Some(tok))
    }

    fn scan_string(
        &mut self,
        quote: usize,
        line: u32,
        column: u32,
    ) -> Result<Option<Token>, Diagnostic> {
        let data = self.data.as_slice();
        let len = data.len();
        let start_loc = || FileLoc::new(self.name.clone(), line, column);
        let mut i = quote + 1;
        let mut escaped = false;
        let mut bad_escape: Option<Diagnostic> = None;
        loop {
            if i >= len {
                self.pos = len;
                return Err(Diagnostic::error(
                    start_loc(),
                    "unterminated string: end of file before the closing '\"'",
                ));
            }
            match data[i] {
                b'"' => break,
                b'\n' => {
                    // Leave the newline so line counting stays right.
                    self.pos = i;
                    return Err(Diagnostic::error(
                        start_loc(),
                        "unterminated string: newline before the closing '\"'",
                    ));
                }
                b'\\' => {
                    escaped = true;
                    let Some(&c) = data.get(i + 1) else {
                        self.pos = len;
                        return Err(Diagnostic::error(
                            start_loc(),
                            "unterminated string: end of file after '\\'",
                        ));
                    };
                    if unescape(c).is_none() && bad_escape.is_none() {
                        let col = saturating_u32(i - self.line_start + 1);
                        let shown = if c.is_ascii_graphic() {
                            (c as char).to_string()
                        } else {
                            format!("\\x{c:02x}")
                        };
                        bad_escape = Some(Diagnostic::error(
                            FileLoc::new(self.name.clone(), line, col),
                            format!("unexpected escaped character '{shown}' in string"),
                        ));
                    }
                    if c == b'\n' {
                        self.pos = i + 1;
                        return Err(Diagnostic::error(
                            start_loc(),
                            "unterminated string: newline before the closing '\"'",
                        ));
                    }
                    i += 2;
                }
                _ => i += 1,
            }
        }
        self.pos = i + 1;
        if let Some(e) = bad_escape {
            return Err(e);
        }
        Ok(Some(Token {
            kind: TokenKind::Str { escaped },
            start: quote + 1,
            end: i,
            line,
            column,
        }))
    }
}

/// The byte an escape `\c` stands for, as pbrt-v4 accepts them.
fn unescape(c: u8) -> Option<u8> {
    Some(match c {
        b'b' => 0x08,
        b'f' => 0x0c,
        b'n' => b'\n',
        b'r' => b'\r',
        b't' => b'\t',
        b'\\' => b'\\',
        b'\'' => b'\'',
        b'"' => b'"',
        _ => return None,
    })
}

/// Escapes `s` so that it reads back as the same string inside quotes.
pub fn escape_string(s: &str) -> Cow<'_, str> {
    if !s
        .bytes()
        .any(|b| matches!(b, b'"' | b'\\' | b'\n' | b'\r' | b'\t' | 0x08 | 0x0c))
    {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 4);
    for ch in s.chars() {
        match ch {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '\u{8}' => out.push_str("\\b"),
            '\u{c}' => out.push_str("\\f"),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// Why an integer did not parse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntError {
    /// Not a decimal integer.
    Invalid,
    /// Does not fit in an `i32`.
    OutOfRange,
}

/// Parses an optionally signed decimal integer into an `i32`.
pub fn parse_i32(s: &[u8]) -> Result<i32, IntError> {
    let (neg, digits) = match s.first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    if digits.is_empty() {
        return Err(IntError::Invalid);
    }
    let mut v: i64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return Err(IntError::Invalid);
        }
        v = v * 10 + i64::from(c - b'0');
        if v > 1 << 32 {
            // Keep scanning for invalid characters but stop growing.
            v = 1 << 32;
        }
    }
    let v = if neg { -v } else { v };
    i32::try_from(v).map_err(|_| IntError::OutOfRange)
}

const POW10_F32: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];

/// Parses a decimal floating-point number (`[+-]digits[.digits][(e|E)[+-]digits]`).
/// Returns `None` for anything else (including `nan`, `inf`, hex); values
/// beyond `f32` range come back infinite. Correctly rounded.
#[inline]
pub fn parse_f32(s: &[u8]) -> Option<f32> {
    let n = s.len();
    let mut i = 0;
    let neg = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut mant: u64 = 0;
    let mut exp10: i64 = 0;
    let mut ndigits = 0usize;
    let mut truncated = false;
    while i < n && s[i].is_ascii_digit() {
        if mant < 100_000_000_000_000_000 {
            mant = mant * 10 + u64::from(s[i] - b'0');
        } else {
            exp10 += 1;
            truncated |= s[i] != b'0';
        }
        ndigits += 1;
        i += 1;
    }
    if i < n && s[i] == b'.' {
        i += 1;
        while i < n && s[i].is_ascii_digit() {
            if mant < 100_000_000_000_000_000 {
                mant = mant * 10 + u64::from(s[i] - b'0');
                exp10 -= 1;
            } else {
                truncated |= s[i] != b'0';
            }
            ndigits += 1;
            i += 1;
        }
    }
    if ndigits == 0 {
        return None;
    }
    if i < n && (s[i] == b'e' || s[i] == b'E') {
        i += 1;
        let eneg = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let estart = i;
        let mut e: i64 = 0;
        while i < n && s[i].is_ascii_digit() {
            if e < 1_000_000 {
                e = e * 10 + i64::from(s[i] - b'0');
            }
            i += 1;
        }
        if i == estart {
            return None;
        }
        exp10 += if eneg { -e } else { e };
    }
    if i != n {
        return None;
    }
    // Exact fast path: the mantissa and the power of ten are both exact in
    // f32, so one IEEE multiply or divide rounds correctly.
    if !truncated && mant <= 1 << 24 && (-10..=10).contains(&exp10) {
        let m = mant as f32;
        let v = if exp10 >= 0 {
            m * POW10_F32[exp10 as usize]
        } else {
            m / POW10_F32[(-exp10) as usize]
        };
        return Some(if neg { -v } else { v });
    }
    // The syntax is already validated, so the standard parser accepts it.
    std::str::from_utf8(s).ok()?.parse::<f32>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Vec<(TokenKind, String, u32, u32)> {
        let mut t = Tokenizer::from_str("t.pbrt", text);
        let mut out = Vec::new();
        while let Some(tok) = t.next_token().unwrap() {
            out.push((
                tok.kind,
                t.string_value(&tok).unwrap().into_owned(),
                tok.line,
                tok.column,
            ));
        }
        out
    }

    #[test]
    fn splits_words_strings_brackets_and_comments() {
        let toks = tokens("Shape \"sphere\" # a comment\n  \"float radius\" [2.5]\n#end");
        let w = TokenKind::Word;
        let s = TokenKind::Str { escaped: false };
        assert_eq!(
            toks,
            vec![
                (w, "Shape".into(), 1, 1),
                (s, "sphere".into(), 1, 7),
                (s, "float radius".into(), 2, 3),
                (TokenKind::LBracket, "[".into(), 2, 18),
                (w, "2.5".into(), 2, 19),
                (TokenKind::RBracket, "]".into(), 2, 22),
            ]
        );
    }

    #[test]
    fn words_stop_at_quotes_and_brackets() {
        let toks = tokens("a\"b\"[c]d\te\r\nf");
        let texts: Vec<&str> = toks.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(texts, ["a", "b", "[", "c", "]", "d", "e", "f"]);
        assert_eq!(toks[7].2, 2);
    }

    #[test]
    fn decodes_escapes() {
        let toks = tokens(r#""a\n\t\\\"\b\f\r\'z""#);
        assert_eq!(toks[0].0, TokenKind::Str { escaped: true });
        assert_eq!(toks[0].1, "a\n\t\\\"\u{8}\u{c}\r'z");
    }

    #[test]
    fn escape_round_trips() {
        let s = "we\"ird\\ \n\t\u{8}\u{c}\r name";
        let quoted = format!("\"{}\"", escape_string(s));
        assert_eq!(tokens(&quoted)[0].1, s);
        assert!(matches!(escape_string("plain"), Cow::Borrowed(_)));
    }

    #[test]
    fn unterminated_string_newline_is_located_and_recovers() {
        let mut t = Tokenizer::from_str("t.pbrt", "Shape\n  \"sphere\n Foo");
        assert!(t.next_token().unwrap().is_some());
        let e = t.next_token().unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.pbrt:2:3: error: unterminated string: newline before the closing '\"'"
        );
        let tok = t.next_token().unwrap().unwrap();
        assert_eq!((t.raw(&tok), tok.line, tok.column), (&b"Foo"[..], 3, 2));
    }

    #[test]
    fn unterminated_string_eof() {
        let mut t = Tokenizer::from_str("t.pbrt", "  \"abc");
        let e = t.next_token().unwrap_err();
        assert_eq!(e.loc.as_ref().map(|l| (l.line, l.column)), Some((1, 3)));
        assert!(t.next_token().unwrap().is_none());
        let mut t = Tokenizer::from_str("t.pbrt", "\"abc\\");
        assert!(t.next_token().is_err());
        assert!(t.next_token().unwrap().is_none());
    }

    #[test]
    fn bad_escape_is_located_at_backslash() {
        let mut t = Tokenizer::from_str("t.pbrt", "x \"ab\\qc\" y");
        t.next_token().unwrap();
        let e = t.next_token().unwrap_err();
        assert_eq!(e.loc.as_ref().map(|l| l.column), Some(6));
        assert!(e.message.contains("'q'"), "{}", e.message);
        let tok = t.next_token().unwrap().unwrap();
        assert_eq!(t.raw(&tok), b"y");
    }

    #[test]
    fn numbers_parse_exactly() {
        let cases = [
            "0",
            "1",
            "-1",
            "+2.5",
            ".5",
            "5.",
            "1e3",
            "1E-3",
            "-0.000123",
            "3.14159265358979",
            "123456789",
            "0.1",
            "16777217",
            "1e-45",
            "3.4028235e38",
            "7.006492e-46",
            "0.30000001192092896",
            "1.00000017881393432617187499",
            "00000000000000000000000001.5",
        ];
        for c in cases {
            let want: f32 = c.parse().unwrap();
            assert_eq!(
                parse_f32(c.as_bytes()).map(f32::to_bits),
                Some(want.to_bits()),
                "{c}"
            );
        }
        for bad in [
            "", "-", ".", "e5", "1e", "1e+", "nan", "-nan", "inf", "1.2.3", "0x10", "1,5", "--1",
        ] {
            assert_eq!(parse_f32(bad.as_bytes()), None, "{bad}");
        }
        assert_eq!(parse_f32(b"1e400"), Some(f32::INFINITY));
        assert_eq!(parse_f32(b"1e-400"), Some(0.0));
        assert_eq!(parse_f32(b"1e99999999999999"), Some(f32::INFINITY));
    }

    #[test]
    fn numbers_fast_path_matches_std_on_seeded_values() {
        let mut x: u64 = 0x9e3779b97f4a7c15;
        for _ in 0..20000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let digits = (x % 10_000_000) as i64;
            let e = ((x >> 32) % 21) as i32 - 10;
            let s = format!("{}e{}", digits, e);
            let want: f32 = s.parse().unwrap();
            assert_eq!(parse_f32(s.as_bytes()), Some(want), "{s}");
            let s = format!("-{}.{:06}", digits / 1000, (x >> 40) % 1_000_000);
            let want: f32 = s.parse().unwrap();
            assert_eq!(parse_f32(s.as_bytes()), Some(want), "{s}");
        }
    }

    #[test]
    fn float_and_int_errors_are_located() {
        let mut t =
            Tokenizer::from_str("t.pbrt", "1.5 abc 1e400 \"7\" 99999999999 -2147483648 3.0");
        let toks: Vec<Token> = std::iter::from_fn(|| t.next_token().unwrap()).collect();
        assert_eq!(t.parse_float(&toks[0]).unwrap(), 1.5);
        let e = t.parse_float(&toks[1]).unwrap_err();
        assert_eq!(e.to_string(), "t.pbrt:1:5: error: abc: expected a number");
        assert!(t
            .parse_float(&toks[2])
            .unwrap_err()
            .message
            .contains("out of range"));
        assert!(t.parse_float(&toks[3]).is_err());
        assert!(t
            .parse_int(&toks[4])
            .unwrap_err()
            .message
            .contains("too large"));
        assert_eq!(t.parse_int(&toks[5]).unwrap(), i32::MIN);
        assert!(t
            .parse_int(&toks[6])
            .unwrap_err()
            .message
            .contains("expected an integer"));
    }

    #[test]
    fn utf16_is_rejected_and_utf8_bom_skipped() {
        let t = Tokenizer::new(Arc::from("u"), Arc::new([0xff, 0xfe, b'a', 0].to_vec()));
        assert!(t.check_encoding().is_some());
        let mut t = Tokenizer::new(Arc::from("u"), Arc::new([0xef, 0xbb, 0xbf, b'A'].to_vec()));
        assert!(t.check_encoding().is_none());
        let tok = t.next_token().unwrap().unwrap();
        assert_eq!(t.raw(&tok), b"A");
    }

    #[test]
    fn invalid_utf8_string_is_an_error_not_a_panic() {
        let mut t = Tokenizer::new(Arc::from("u"), Arc::new(b"\"\xff\xfe\" \xc3".to_vec()));
        let tok = t.next_token().unwrap().unwrap();
        assert!(t.string_value(&tok).is_err());
        let tok = t.next_token().unwrap().unwrap();
        assert!(t.string_value(&tok).is_err());
        assert_eq!(t.display(&tok), "\u{fffd}");
    }
}
