//! rpbrt's geometry: the types of *Physically Based Rendering*, chapter 3
//! (points, vectors, normals, rays, bounds, transformations, interactions)
//! and the floating-point error analysis of section 6.8.
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod animated;
pub mod bounds;
pub mod float;
pub mod frame;
pub mod interaction;
pub mod interval;
pub mod quaternion;
pub mod ray;
pub mod spherical;
pub mod transform;
pub mod tuple;

pub use animated::AnimatedTransform;
pub use bounds::{Bounds2f, Bounds2i, Bounds3f, Bounds3i};
pub use float::*;
pub use frame::Frame;
pub use interaction::SurfaceInteraction;
pub use interval::Interval;
pub use quaternion::Quaternion;
pub use ray::{offset_ray_origin, spawn_ray, spawn_ray_to, MediumId, Ray, RayDifferential};
pub use spherical::*;
pub use transform::{SquareMatrix4, Transform, TransformError};
pub use tuple::*;
