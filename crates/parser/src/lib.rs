//! Tokenizer and parser for pbrt-v4 and pbrt-v3 scene files.
#![forbid(unsafe_code)]
#![deny(missing_docs)]
pub mod ply;
