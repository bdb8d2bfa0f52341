//! Located diagnostics: errors and warnings with a `file:line:col` prefix,
//! rendered with the offending source line and a caret (pbrt-v4
//! `util/error.cpp`, presented like rustc/clang).

use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;

use crate::input;
use crate::loc::FileLoc;
use crate::tokenizer::SourceText;

/// How serious a [`Diagnostic`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Severity {
    /// Something suspicious that does not stop the scene from being used.
    Warning,
    /// The scene is invalid.
    Error,
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Severity::Warning => "warning",
            Severity::Error => "error",
        })
    }
}

/// One message about the scene, optionally located.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// Where it happened, when known.
    pub loc: Option<FileLoc>,
    /// The message, without location or severity prefix.
    pub message: String,
}

impl Diagnostic {
    /// A located error.
    pub fn error(loc: FileLoc, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            loc: Some(loc),
            message: message.into(),
        }
    }

    /// A located warning.
    pub fn warning(loc: FileLoc, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            loc: Some(loc),
            message: message.into(),
        }
    }

    /// An error without a location (e.g. a file that cannot be opened).
    pub fn unlocated_error(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            loc: None,
            message: message.into(),
        }
    }

    /// True for [`Severity::Error`].
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Renders the message followed, when `source` (the whole text of the
    /// file named in the location) is given, by the offending line and a
    /// caret under the column.
    pub fn render(&self, source: Option<&[u8]>) -> String {
        let mut out = self.to_string();
        if let (Some(loc), Some(src)) = (&self.loc, source) {
            if let Some(line) = source_line(src, loc.line) {
                let raw = String::from_utf8_lossy(line);
                let raw = raw.trim_end_matches(['\r', '\n']);
                // Tabs keep their width so the caret lines up in a terminal;
                // other control characters are shown escaped (a scene must
                // not drive the terminal), and the caret skips their escape.
                let mut caret = String::new();
                for (i, ch) in raw.chars().enumerate() {
                    if i + 1 >= loc.column as usize {
                        break;
                    }
                    match ch {
                        '\t' => caret.push('\t'),
                        c if is_unsafe_control(c) => {
                            caret.push_str(&" ".repeat(c.escape_unicode().count()))
                        }
                        _ => caret.push(' '),
                    }
                }
                let text = escape_controls(raw, "\t");
                // Columns count bytes; clamp for lines with multibyte characters.
                let gutter = loc.line.to_string();
                let pad = " ".repeat(gutter.len());
                out.push('\n');
                out.push_str(&format!("{pad} |\n{gutter} | {text}\n{pad} | {caret}^"));
            }
        }
        out
    }
}

/// True for characters a terminal may act on rather than show: the C0
/// and C1 controls and DEL.
fn is_unsafe_control(c: char) -> bool {
    c.is_control()
}

/// `s` with its control characters other than those in `keep` written as
/// `\u{1b}`-style escapes, so that text from a scene or an image file (an
/// OSC sequence setting the window title, a bell, a cursor move) is shown
/// rather than obeyed when printed to a terminal.
pub fn escape_controls<'a>(s: &'a str, keep: &str) -> std::borrow::Cow<'a, str> {
    if !s.chars().any(|c| is_unsafe_control(c) && !keep.contains(c)) {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 16);
    for c in s.chars() {
        if is_unsafe_control(c) && !keep.contains(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Returns line `line` (1-based) of `src`, without its terminator.
fn source_line(src: &[u8], line: u32) -> Option<&[u8]> {
    if line == 0 {
        return None;
    }
    let mut l = 1u32;
    let mut start = 0usize;
    if line > 1 {
        for (i, &b) in src.iter().enumerate() {
            if b == b'\n' {
                l += 1;
                if l == line {
                    start = i + 1;
                    break;
                }
            }
        }
        if l != line {
            return None;
        }
    }
    let rest = &src[start..];
    let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    Some(&rest[..end])
}

impl fmt::Display for Diagnostic {
    /// Control characters in the file name or message (often quoting the
    /// scene) are escaped; newlines and tabs are kept.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match &self.loc {
            Some(loc) => format!("{}: {}: {}", loc, self.severity, self.message),
            None => format!("{}: {}", self.severity, self.message),
        };
        f.write_str(&escape_controls(&text, "\n\t"))
    }
}

impl std::error::Error for Diagnostic {}

/// The text of the files diagnostics refer to, so that they can be rendered
/// with their source line after parsing has finished.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: HashMap<Arc<str>, SourceText>,
}

impl SourceMap {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records the contents of `file`.
    pub fn insert(&mut self, file: Arc<str>, contents: SourceText) {
        self.files.insert(file, contents);
    }

    /// The contents of `file`, if recorded.
    pub fn get(&self, file: &str) -> Option<&[u8]> {
        self.files.get(file).map(|c| &c[..])
    }

    /// Number of files recorded.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// True when no file is recorded.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// The recorded files and their contents.
    pub fn into_files(self) -> impl Iterator<Item = (Arc<str>, SourceText)> {
        self.files.into_iter()
    }
}

/// A list of diagnostics plus the sources needed to render them.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    /// The diagnostics, in the order they were reported.
    pub items: Vec<Diagnostic>,
    /// Source text of the files the diagnostics point into (may be partial:
    /// files without diagnostics are not kept).
    pub sources: SourceMap,
}

impl Diagnostics {
    /// An empty list.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends one diagnostic.
    pub fn push(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    /// Number of errors (not warnings).
    pub fn error_count(&self) -> usize {
        self.items.iter().filter(|d| d.is_error()).count()
    }

    /// True when at least one error is present.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(Diagnostic::is_error)
    }

    /// Number of diagnostics.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when there are no diagnostics at all.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Iterates over the diagnostics.
    pub fn iter(&self) -> std::slice::Iter<'_, Diagnostic> {
        self.items.iter()
    }

    /// Renders every diagnostic with its source line and caret, one after
    /// the other, separated by newlines. Sources not kept in memory are
    /// read again from disk when possible.
    pub fn render(&self) -> String {
        let mut out = String::new();
        let mut reread: HashMap<Arc<str>, Option<Vec<u8>>> = HashMap::new();
        for d in &self.items {
            let src: Option<&[u8]> = match &d.loc {
                None => None,
                Some(loc) => match self.sources.get(&loc.file) {
                    Some(s) => Some(s),
                    None => reread
                        .entry(loc.file.clone())
                        .or_insert_with(|| {
                            input::read_file_limited(
                                &*loc.file,
                                input::DEFAULT_MAX_SCENE_FILE_BYTES,
                            )
                            .ok()
                        })
                        .as_deref(),
                },
            };
            out.push_str(&d.render(src));
            out.push('\n');
        }
        out
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.items.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Diagnostics {
            items: vec![d],
            sources: SourceMap::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn loc(line: u32, col: u32) -> FileLoc {
        FileLoc::new(Arc::from("a.pbrt"), line, col)
    }

    #[test]
    fn display_has_location_and_severity() {
        let d = Diagnostic::error(loc(3, 5), "bad thing");
        assert_eq!(d.to_string(), "a.pbrt:3:5: error: bad thing");
        let w = Diagnostic::warning(loc(1, 1), "hmm");
        assert_eq!(w.to_string(), "a.pbrt:1:1: warning: hmm");
        assert_eq!(Diagnostic::unlocated_error("x").to_string(), "error: x");
    }

    #[test]
    fn diagnostic_escapes_terminal_control_characters() {
        // An OSC sequence setting the terminal's title, quoted by a message
        // and present in the source line.
        let src = "Shape \"\x1b]0;title\x07\" 1\n";
        let d = Diagnostic::error(loc(1, 20), "unknown shape \"\x1b]0;title\x07\"");
        let r = d.render(Some(src.as_bytes()));
        assert!(!r.contains('\x1b') && !r.contains('\x07'), "{r:?}");
        let lines: Vec<&str> = r.lines().collect();
        assert_eq!(
            lines[0],
            "a.pbrt:1:20: error: unknown shape \"\\u{1b}]0;title\\u{7}\""
        );
        assert_eq!(lines[2], "1 | Shape \"\\u{1b}]0;title\\u{7}\" 1");
        // The caret stays under the `1` after the escapes.
        let col = lines[2].find(" 1").unwrap() + 1;
        assert_eq!(lines[3].find('^'), Some(col), "{r}");
        // Newlines in messages and tabs in source stay as they are.
        let m = Diagnostic::unlocated_error("a\n\tb").to_string();
        assert_eq!(m, "error: a\n\tb");
    }

    #[test]
    fn render_shows_line_and_caret() {
        let src = b"Shape \"sphere\"\nFoo 1 2\n";
        let d = Diagnostic::error(loc(2, 5), "unexpected");
        let r = d.render(Some(src));
        let lines: Vec<&str> = r.lines().collect();
        assert_eq!(lines[0], "a.pbrt:2:5: error: unexpected");
        assert_eq!(lines[2], "2 | Foo 1 2");
        assert_eq!(lines[3], "  |     ^");
    }

    #[test]
    fn render_tolerates_out_of_range_lines() {
        let d = Diagnostic::error(loc(99, 5), "x");
        assert_eq!(d.render(Some(b"one line")), "a.pbrt:99:5: error: x");
        assert_eq!(source_line(b"a\nb", 2), Some(&b"b"[..]));
        assert_eq!(source_line(b"a\nb", 0), None);
    }

    #[test]
    fn diagnostics_counts_and_renders_from_sources() {
        let mut ds = Diagnostics::new();
        ds.sources
            .insert(Arc::from("a.pbrt"), Arc::new(b"Foo\n".to_vec()));
        ds.push(Diagnostic::warning(loc(1, 1), "w"));
        assert!(!ds.has_errors());
        ds.push(Diagnostic::error(loc(1, 2), "e"));
        assert_eq!(ds.error_count(), 1);
        let r = ds.render();
        assert!(r.contains("1 | Foo"), "{r}");
        assert!(r.contains("|  ^"), "{r}");
    }
}
