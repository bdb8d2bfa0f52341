//! Shapes (book chapter 6; pbrt-v4 `base/shape.h`, `shapes.h`): geometric
//! surfaces that rays can hit and lights can sample.
//!
//! Every concrete shape implements [`ShapeMethods`]; [`Shape`] is the closed
//! set of them, each method a one-line delegation (the Rust form of
//! pbrt-v4's tagged pointer). Shapes live in rendering space: quadrics keep
//! their render-from-object transformation, meshes store rendering-space
//! vertices.

use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::{offset_ray_origin, Ray};
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use std::fmt;

pub use bilinear::{BilinearPatch, BilinearPatchMesh};
pub use cone::Cone;
pub use curve::Curve;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use hyperboloid::Hyperboloid;
pub use paraboloid::Paraboloid;
pub use sphere::Sphere;
pub(crate) use triangle::{
    sample_solid_angle_points, SolidAngleCore, SolidAnglePoint, SolidAngleQuery,
};
pub use triangle::{SampledTriangle, Triangle, TriangleMesh};

pub mod bilinear;
pub mod cone;
pub mod create;
pub mod curve;
pub mod cylinder;
pub mod disk;
pub mod displace;
pub mod hyperboloid;
pub mod loopsubdiv;
pub mod paraboloid;
pub mod sphere;
pub mod triangle;
pub mod triangle_lanes;

/// A ray's hit on a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeIntersection {
    /// The surface geometry at the hit.
    pub intr: SurfaceInteraction,
    /// The ray parameter of the hit.
    pub t_hit: Float,
}

/// A point sampled on a shape's surface and its density: per unit area for
/// [`ShapeMethods::sample_area`], per unit solid angle from the reference
/// point for [`ShapeMethods::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    /// The sampled point with its error bounds.
    pub pi: Point3fi,
    /// The surface normal there (flipped like intersection normals).
    pub n: Normal3f,
    /// Surface (u, v) of the point.
    pub uv: Point2f,
    /// Time of the sample.
    pub time: Float,
    /// The sample's density.
    pub pdf: Float,
}

impl ShapeSample {
    /// The sampled point.
    #[inline]
    pub fn p(&self) -> Point3f {
        self.pi.midpoint()
    }
}

/// The reference point from which a shape is sampled by solid angle
/// (pbrt-v4's `ShapeSampleContext`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeSampleContext {
    /// The reference point with error bounds.
    pub pi: Point3fi,
    /// Geometric normal at the reference point (zero in a medium).
    pub n: Normal3f,
    /// Shading normal at the reference point (zero in a medium).
    pub ns: Normal3f,
    /// Time.
    pub time: Float,
}

impl ShapeSampleContext {
    /// A context at a point in space (no surface).
    pub fn from_point(p: Point3f, time: Float) -> Self {
        ShapeSampleContext {
            pi: Point3fi::from(p),
            n: Normal3f::default(),
            ns: Normal3f::default(),
            time,
        }
    }
    /// The reference point.
    #[inline]
    pub fn p(&self) -> Point3f {
        self.pi.midpoint()
    }
    /// The origin of a ray leaving toward `w`, offset off the surface.
    #[inline]
    pub fn offset_ray_origin(&self, w: Vector3f) -> Point3f {
        offset_ray_origin(self.p(), self.pi.error(), self.n, w)
    }
    /// A ray leaving the reference point toward `w`.
    #[inline]
    pub fn spawn_ray(&self, w: Vector3f) -> Ray {
        Ray::with_time(self.offset_ray_origin(w), w, self.time, None)
    }
}

/// Why a shape could not be built from its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeError(pub String);

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShapeError {}

/// The interface every shape provides.
pub trait ShapeMethods {
    /// Bounds in rendering space.
    fn bounds(&self) -> Bounds3f;
    /// A cone bounding the surface normals (for the light BVH).
    fn normal_bounds(&self) -> DirectionCone;
    /// The closest hit with `t` in (0, `t_max`), with full geometry.
    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection>;
    /// Whether any hit with `t` in (0, `t_max`) exists (shadow rays).
    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool;
    /// Surface area in rendering space.
    fn area(&self) -> Float;
    /// A point sampled on the surface with density per unit area.
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample>;
    /// Density per unit area of [`ShapeMethods::sample_area`] (1/area for
    /// uniform sampling).
    fn pdf_area(&self) -> Float {
        1.0 / self.area()
    }
    /// Density per unit area with which [`ShapeMethods::sample_area`]
    /// produces the surface point `p` (pbrt-v4 `Shape::PDF(Interaction)`):
    /// [`ShapeMethods::pdf_area`] for shapes sampled uniformly by area.
    fn pdf_area_at_point(&self, _p: Point3f) -> Float {
        self.pdf_area()
    }
    /// A point sampled as seen from `ctx`, density per unit solid angle.
    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample>;
    /// Density per unit solid angle of sampling direction `wi` from `ctx`.
    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float;
}

/// Converts an area-density sample into a solid-angle density sample from
/// `ctx` (the generic `Shape::Sample(ctx, u)` of pbrt-v4); `None` when the
/// density is infinite.
pub fn area_sample_to_solid_angle(
    ctx: &ShapeSampleContext,
    mut ss: ShapeSample,
) -> Option<ShapeSample> {
    let wi = ss.p() - ctx.p();
    let d2 = wi.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let wi = wi / d2.sqrt();
    ss.pdf /= abs_dot(ss.n, -wi) / d2;
    if ss.pdf.is_infinite() || ss.pdf.is_nan() {
        return None;
    }
    Some(ss)
}

/// The generic solid-angle pdf of pbrt-v4: intersect the ray from `ctx`
/// toward `wi` with the shape and convert 1/area to solid angle.
pub fn pdf_by_intersection<S: ShapeMethods + ?Sized>(
    shape: &S,
    ctx: &ShapeSampleContext,
    wi: Vector3f,
) -> Float {
    let ray = ctx.spawn_ray(wi);
    let isect = match shape.intersect(&ray, Float::INFINITY) {
        Some(i) => i,
        None => return 0.0,
    };
    let pdf = (1.0 / shape.area())
        / (abs_dot(isect.intr.n, -wi) / ctx.p().distance_squared(isect.intr.p()));
    if pdf.is_infinite() {
        0.0
    } else {
        pdf
    }
}

/// Every shape rpbrt renders: a closed set, each method a one-line
/// delegation. The quadrics carry two transformations and are boxed so that
/// the common variants (triangles, patches, curve pieces) keep the enum
/// small.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A sphere, possibly partial.
    Sphere(Box<Sphere>),
    /// A cylinder, possibly partial.
    Cylinder(Box<Cylinder>),
    /// A disk or annulus, possibly partial.
    Disk(Box<Disk>),
    /// A cone (pbrt-v3).
    Cone(Box<Cone>),
    /// A paraboloid (pbrt-v3).
    Paraboloid(Box<Paraboloid>),
    /// A hyperboloid (pbrt-v3).
    Hyperboloid(Box<Hyperboloid>),
    /// One triangle of a mesh.
    Triangle(Triangle),
    /// One bilinear patch of a mesh.
    BilinearPatch(BilinearPatch),
    /// One piece of a curve.
    Curve(Curve),
}

macro_rules! delegate {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            Shape::Sphere($s) => $e,
            Shape::Cylinder($s) => $e,
            Shape::Disk($s) => $e,
            Shape::Cone($s) => $e,
            Shape::Paraboloid($s) => $e,
            Shape::Hyperboloid($s) => $e,
            Shape::Triangle($s) => $e,
            Shape::BilinearPatch($s) => $e,
            Shape::Curve($s) => $e,
        }
    };
}

impl ShapeMethods for Shape {
    #[inline]
    fn bounds(&self) -> Bounds3f {
        delegate!(self, s => s.bounds())
    }
    #[inline]
    fn normal_bounds(&self) -> DirectionCone {
        delegate!(self, s => s.normal_bounds())
    }
    #[inline]
    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        delegate!(self, s => s.intersect(ray, t_max))
    }
    #[inline]
    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        delegate!(self, s => s.intersect_p(ray, t_max))
    }
    #[inline]
    fn area(&self) -> Float {
        delegate!(self, s => s.area())
    }
    #[inline]
    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        delegate!(self, s => s.sample_area(u))
    }
    #[inline]
    fn pdf_area(&self) -> Float {
        delegate!(self, s => s.pdf_area())
    }
    #[inline]
    fn pdf_area_at_point(&self, p: Point3f) -> Float {
        delegate!(self, s => s.pdf_area_at_point(p))
    }
    #[inline]
    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        delegate!(self, s => s.sample(ctx, u))
    }
    #[inline]
    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        delegate!(self, s => s.pdf(ctx, wi))
    }
}

#[cfg(test)]
mod enum_tests {
    use super::*;

    #[test]
    fn shape_enum_stays_small() {
        // Triangles dominate real scenes: keep the enum at two words plus
        // the tag.
        assert!(
            std::mem::size_of::<Shape>() <= 24,
            "Shape is {} bytes",
            std::mem::size_of::<Shape>()
        );
    }
}
