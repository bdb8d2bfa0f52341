//! Generated data tables for the samplers.

pub mod joe_kuo;
