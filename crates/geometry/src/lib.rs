//! rpbrt's geometry: the types of *Physically Based Rendering*, chapter 3
//! (points, vectors, normals, rays, bounds, transformations, interactions)
//! and the floating-point error analysis of section 6.8.
#![forbid(unsafe_code)]
#![deny(missing_docs)]
