//! rpbrt's renderer: shapes, accelerators, scene building and integrators.
#![deny(missing_docs)]

pub mod accel;
pub mod bxdf;
pub mod rng;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod spectrum;

pub use rpbrt_geometry as geometry;
