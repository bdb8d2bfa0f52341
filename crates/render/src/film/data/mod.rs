//! Measured tables for the film: camera sensor responses, ColorChecker
//! swatch reflectances and the CIE daylight basis.

pub mod cie_d;
pub mod sensors;
pub mod swatches;
