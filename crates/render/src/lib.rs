//! rpbrt's renderer: shapes, accelerators, scene building and integrators.
#![deny(missing_docs)]

pub mod accel;
pub mod bssrdf;
pub mod bxdf;
pub mod camera;
pub mod film;
pub mod filter;
pub mod image;
pub mod integrator;
pub mod light;
pub mod lightsampler;
pub mod material;
pub mod medium;
pub mod params;
pub mod primitive;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod select;
pub mod shape;
pub mod simd;
pub mod spectrum;
pub mod texture;

pub use rpbrt_geometry as geometry;
