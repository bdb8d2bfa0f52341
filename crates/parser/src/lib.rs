//! Tokenizer and parser for pbrt-v4 and pbrt-v3 scene files (book appendix C,
//! pbrt-v4 `parser.h/.cpp`, `paramdict.h/.cpp`, `upgrade.cpp`).
//!
//! - [`Tokenizer`]: zero-copy tokens over an in-memory buffer, each with its
//!   [`FileLoc`].
//! - [`ParsedParameter`] / [`ParameterDictionary`]: parameter lists and typed,
//!   usage-tracking access to them.
//! - [`ParserTarget`]: one method per directive; [`parse_files`] and
//!   [`parse_string`] drive it, following `Include`/`Import`.
//! - [`Diagnostic`] / [`Diagnostics`]: located errors and warnings, rendered
//!   with the source line and a caret.
//! - [`input`]: opening files, with transparent gzip decompression, as a
//!   stream ([`input::FileReader`]) or whole ([`input::read_file_limited`]).
//! - [`MemoryBudget`]: the limit on the memory input may claim, shared by
//!   the parser, the scene builder and the renderer ([`budget`]).
//! - [`FormattingTarget`]: prints a scene back as canonical pbrt-v4 text,
//!   optionally upgrading pbrt-v3 constructs with the mappings in [`upgrade`].
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod budget;
pub mod diag;
pub mod driver;
pub mod format;
pub mod input;
pub mod loc;
pub mod params;
pub mod ply;
pub mod target;
pub mod tokenizer;
pub mod upgrade;

pub use budget::{MemoryBudget, OverBudget};
pub use diag::{Diagnostic, Diagnostics, Severity, SourceMap};
pub use driver::{parse_files, parse_string, read_scene_file, ParseOptions, Parser};
pub use format::FormattingTarget;
pub use loc::FileLoc;
pub use params::{ParamError, ParameterDictionary, ParsedParameter, SpectrumValue, ValueKind};
pub use target::{DirectiveResult, IncludeKind, ParamList, ParserTarget};
pub use tokenizer::{SourceText, Token, TokenKind, Tokenizer};
