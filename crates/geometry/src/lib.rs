//! rpbrt's geometry: the types of *Physically Based Rendering*, chapter 3
//! (points, vectors, normals, rays, bounds, transformations, interactions)
//! and the floating-point error analysis of section 6.8.
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod animated;
pub mod bilinear;
pub mod bounds;
pub mod float;
pub mod frame;
pub mod interaction;
pub mod interval;
pub mod pointfi;
pub mod quaternion;
pub mod ray;
pub mod spherical;
pub mod transform;
pub mod transform_list;
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
pub use transform_list::TransformList;
pub use tuple::*;

/// A uniform-sphere warp, exposed only for the crate's integration tests
/// (the renderer's sampling module has the real one).
#[doc(hidden)]
pub mod sampling_for_tests {
    use crate::float::*;
    use crate::tuple::*;
    /// Uniform direction on the unit sphere.
    pub fn uniform_sphere(u: Point2f) -> Vector3f {
        let z = 1.0 - 2.0 * u.x;
        let r = safe_sqrt(1.0 - z * z);
        let phi = 2.0 * PI * u.y;
        Vector3f::new(r * phi.cos(), r * phi.sin(), z)
    }
}
