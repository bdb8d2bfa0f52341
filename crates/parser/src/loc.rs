//! Source locations (pbrt-v4 `FileLoc`, book section B.3 / `util/error.h`).
//!
//! Every token, parameter and directive carries one so that messages can
//! point at the exact place in the scene file.

use std::fmt;
use std::sync::Arc;

/// A position in a scene file: file name, 1-based line and 1-based column
/// (counted in bytes, as pbrt-v4 does).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct FileLoc {
    /// Name of the file as it was opened (or `<string>` for in-memory input).
    pub file: Arc<str>,
    /// 1-based line number.
    pub line: u32,
    /// 1-based column number, in bytes.
    pub column: u32,
}

impl FileLoc {
    /// Creates a location.
    pub fn new(file: Arc<str>, line: u32, column: u32) -> Self {
        FileLoc { file, line, column }
    }
}

impl fmt::Display for FileLoc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_is_file_line_col() {
        let l = FileLoc::new(Arc::from("scene.pbrt"), 12, 7);
        assert_eq!(l.to_string(), "scene.pbrt:12:7");
    }
}
