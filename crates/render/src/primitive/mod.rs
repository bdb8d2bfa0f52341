//! Primitives (pbrt-v4 `primitive.h/.cpp`; book section 7.1): shapes bound
//! to their material, area light, media and alpha mask; object instances
//! placed by a fixed or animated transformation; and aggregates that put an
//! acceleration structure over a set of primitives.

use crate::accel::{AccelParams, Accelerator, Aggregate};
use crate::shape::triangle::{
    intersect_prepared_triangle, triangle_is_nondegenerate, TriangleFrame, TriangleRay,
};
use crate::shape::{Shape, ShapeMethods};
use crate::texture::{FloatTextureRef, TextureEvalContext};
use rpbrt_geometry::animated::AnimatedTransform;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::{MediumId, Ray};
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::Point3f;
use rpbrt_geometry::Bounds3f;
use std::sync::Arc;

/// The media on the two sides of a surface (pbrt-v4 `MediumInterface`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumInterface {
    /// The medium on the side the normal points away from.
    pub inside: Option<MediumId>,
    /// The medium on the side the normal points to.
    pub outside: Option<MediumId>,
}

impl MediumInterface {
    /// True when the two sides have different media: crossing the surface
    /// changes the medium a ray travels in (pbrt-v4 `IsMediumTransition`).
    #[inline]
    pub fn is_transition(&self) -> bool {
        self.inside != self.outside
    }
}

/// How a primitive's alpha mask cuts it out. pbrt-v4 tests alpha
/// stochastically: a hit with alpha `a` is kept with probability `a`,
/// decided by a hash of the ray so that the result is deterministic.
#[derive(Clone, Debug)]
pub enum Alpha {
    /// Fully opaque.
    Opaque,
    /// A constant alpha in (0, 1); zero alpha primitives are never built.
    Constant(Float),
    /// An alpha texture, evaluated at the hit point.
    Texture(FloatTextureRef),
}

/// What a ray hit: the surface geometry plus the primitive's properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimitiveIntersection {
    /// The surface interaction, in rendering space.
    pub si: SurfaceInteraction,
    /// The ray parameter of the hit.
    pub t_hit: Float,
    /// The material index (`None`: an interface between media, no surface).
    pub material: Option<u32>,
    /// The area light index, if the surface emits.
    pub area_light: Option<u32>,
    /// The media on both sides, when the primitive separates media; `None`
    /// means the ray's medium continues on both sides.
    pub medium_interface: Option<MediumInterface>,
}

/// A shape with its material, area light, media and alpha.
#[derive(Clone, Debug)]
pub struct GeometricPrimitive {
    /// The shape.
    pub shape: Shape,
    /// Material index (`None`: interface).
    pub material: Option<u32>,
    /// Area light index.
    pub area_light: Option<u32>,
    /// Media on either side.
    pub medium_interface: Option<MediumInterface>,
    /// Alpha mask.
    pub alpha: Alpha,
}

/// A deterministic uniform value in [0, 1) from a ray, for the stochastic
/// alpha test (pbrt-v4 hashes the ray's origin and direction).
#[inline]
fn hash_float_ray(r: &Ray) -> Float {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in [r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z] {
        h ^= v.to_bits() as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    let h = crate::rng::mix_bits(h);
    ((h >> 40) as Float) / (1u64 << 24) as Float
}

impl GeometricPrimitive {
    /// Keeps a hit or lets the ray pass according to the alpha mask.
    #[inline]
    fn alpha_passes(&self, ray: &Ray, si: &SurfaceInteraction) -> bool {
        let a = match &self.alpha {
            Alpha::Opaque => return true,
            Alpha::Constant(a) => *a,
            Alpha::Texture(t) => t.evaluate(&TextureEvalContext::from_si(si)),
        };
        a >= 1.0 || (a > 0.0 && hash_float_ray(ray) <= a)
    }

    /// The closest hit in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let isect = self.shape.intersect(ray, t_max)?;
        if !self.alpha_passes(ray, &isect.intr) {
            return None;
        }
        Some(PrimitiveIntersection {
            si: isect.intr,
            t_hit: isect.t_hit,
            material: self.material,
            area_light: self.area_light,
            medium_interface: self.medium_interface,
        })
    }

    /// Whether anything is hit in (0, t_max).
    #[inline]
    pub fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        match self.alpha {
            Alpha::Opaque => self.shape.intersect_p(ray, t_max),
            _ => self.intersect(ray, t_max).is_some(),
        }
    }
}

/// An object instance: a shared aggregate placed by a fixed transformation.
#[derive(Clone, Debug)]
pub struct TransformedPrimitive {
    /// The instanced aggregate, in its own space.
    pub primitive: Arc<PrimitiveAggregate>,
    /// From the instance's space to rendering space.
    pub render_from_primitive: Transform,
}

/// Primitives whose transformation changes over the shutter interval.
#[derive(Clone, Debug)]
pub struct AnimatedPrimitive {
    /// The animated aggregate, in its own space.
    pub primitive: Arc<PrimitiveAggregate>,
    /// From the primitive's space to rendering space, over time.
    pub render_from_primitive: AnimatedTransform,
}

fn transform_hit(
    mut pi: PrimitiveIntersection,
    render_from_primitive: &Transform,
) -> PrimitiveIntersection {
    pi.si = pi.si.transform(render_from_primitive);
    pi
}

/// The closed set of primitives.
#[derive(Clone, Debug)]
pub enum Primitive {
    /// A shape with its properties.
    Geometric(GeometricPrimitive),
    /// An object instance (boxed: two matrices would make every
    /// primitive large).
    Transformed(Box<TransformedPrimitive>),
    /// Motion-blurred primitives (boxed: an animated transform is large).
    Animated(Box<AnimatedPrimitive>),
}

impl Primitive {
    /// Calls `f` with the material of every shape under this primitive
    /// (instances included; once per use).
    pub fn for_each_material(&self, f: &mut impl FnMut(u32)) {
        match self {
            Primitive::Geometric(p) => {
                if let Some(m) = p.material {
                    f(m)
                }
            }
            Primitive::Transformed(p) => p
                .primitive
                .prims
                .iter()
                .for_each(|q| q.for_each_material(f)),
            Primitive::Animated(p) => p
                .primitive
                .prims
                .iter()
                .for_each(|q| q.for_each_material(f)),
        }
    }

    /// Bounds in rendering space (over the whole shutter for animated ones).
    pub fn bounds(&self) -> Bounds3f {
        match self {
            Primitive::Geometric(p) => p.shape.bounds(),
            Primitive::Transformed(p) => {
                p.render_from_primitive.apply_bounds(&p.primitive.bounds())
            }
            Primitive::Animated(p) => p.render_from_primitive.motion_bounds(&p.primitive.bounds()),
        }
    }

    /// The closest hit in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        match self {
            Primitive::Geometric(p) => p.intersect(ray, t_max),
            Primitive::Transformed(p) => {
                let (r, t) = p.render_from_primitive.apply_inverse_ray(ray, t_max);
                let pi = p.primitive.intersect(&r, t)?;
                Some(transform_hit(pi, &p.render_from_primitive))
            }
            Primitive::Animated(p) => {
                let xf = p.render_from_primitive.interpolate(ray.time);
                let (r, t) = xf.apply_inverse_ray(ray, t_max);
                let pi = p.primitive.intersect(&r, t)?;
                Some(transform_hit(pi, &xf))
            }
        }
    }

    /// Whether anything is hit in (0, t_max).
    #[inline]
    pub fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        match self {
            Primitive::Geometric(p) => p.intersect_p(ray, t_max),
            Primitive::Transformed(p) => {
                let (r, t) = p.render_from_primitive.apply_inverse_ray(ray, t_max);
                p.primitive.intersect_p(&r, t)
            }
            Primitive::Animated(p) => {
                let (r, t) = p
                    .render_from_primitive
                    .interpolate(ray.time)
                    .apply_inverse_ray(ray, t_max);
                p.primitive.intersect_p(&r, t)
            }
        }
    }
}

/// Aggregates with at most this many primitives keep the vertices of their
/// triangles beside the primitives for the traversal.
const MAX_CACHED_TRIANGLE_PRIMITIVES: usize = 1 << 22;

/// Aggregates with at most this many primitives also keep each triangle's
/// [`TriangleFrame`] (at most 60 MiB).
const MAX_TRIANGLE_FRAME_PRIMITIVES: usize = 1 << 20;

/// The closest hit found so far by [`PrimitiveAggregate::intersect`]: an
/// opaque triangle's barycentrics (its interaction is built once, for the
/// closest), or another primitive's full intersection (kept inline:
/// boxing it would allocate per hit).
#[allow(clippy::large_enum_variant)]
enum Closest {
    None,
    Full(PrimitiveIntersection),
    Triangle {
        prim: u32,
        b: (Float, Float, Float),
        t_hit: Float,
    },
}

/// A ray's closest hit in an aggregate, before its interaction is built
/// (the first of the two steps of [`PrimitiveAggregate::intersect`]; the
/// second is [`PrimitiveAggregate::interaction`]): small and `Copy`, so
/// that a batch of rays can be intersected first and shaded later.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// The primitive hit, an index into [`PrimitiveAggregate::primitives`].
    pub primitive: u32,
    /// The ray parameter of the hit.
    pub t_hit: Float,
    /// What builds the interaction.
    kind: HitKind,
}

/// How [`PrimitiveAggregate::interaction`] builds a hit's interaction.
#[derive(Clone, Copy, Debug, PartialEq)]
enum HitKind {
    /// An opaque triangle's barycentrics.
    Triangle(Float, Float, Float),
    /// Another primitive, hit by its own test with this bound on the ray
    /// parameter: the test is deterministic, so testing again with the
    /// same bound gives the same interaction.
    Other {
        /// The bound the hit was found with.
        t_max: Float,
    },
}

/// Primitives under an acceleration structure (pbrt-v4's aggregates).
#[derive(Clone, Debug)]
pub struct PrimitiveAggregate {
    prims: Vec<Primitive>,
    accel: Accelerator,
    /// Per primitive: the vertices of an opaque, non-degenerate triangle,
    /// so that the traversal tests it without going through the primitive
    /// and its mesh (`None` for every other primitive).
    triangle_vertices: Vec<Option<[Point3f; 3]>>,
    /// Per primitive, for the same triangles: the parts of the surface
    /// interaction that are the same all over the triangle, so that a hit
    /// builds only the rest (empty for large aggregates, default for
    /// other primitives).
    triangle_frames: Vec<TriangleFrame>,
}

impl PrimitiveAggregate {
    /// Builds the structure chosen by `params` over `prims`.
    pub fn new(prims: Vec<Primitive>, params: &AccelParams) -> Self {
        let bounds: Vec<Bounds3f> = prims.iter().map(Primitive::bounds).collect();
        let accel = Accelerator::build(&bounds, params);
        // 40 bytes per primitive: bounded so that huge scenes do not pay
        // gigabytes for it (they fall back to going through the mesh).
        let cache_triangles = prims.len() <= MAX_CACHED_TRIANGLE_PRIMITIVES;
        let triangle_vertices: Vec<Option<[Point3f; 3]>> = prims
            .iter()
            .take(if cache_triangles { prims.len() } else { 0 })
            .map(|p| match p {
                Primitive::Geometric(GeometricPrimitive {
                    shape: Shape::Triangle(tri),
                    alpha: Alpha::Opaque,
                    ..
                }) => {
                    let [p0, p1, p2] = tri.vertex_positions();
                    triangle_is_nondegenerate(p0, p1, p2).then_some([p0, p1, p2])
                }
                _ => None,
            })
            .collect();
        // 60 bytes per primitive, read once per closest hit.
        let triangle_frames = if prims.len() <= MAX_TRIANGLE_FRAME_PRIMITIVES {
            prims
                .iter()
                .zip(&triangle_vertices)
                .map(|(p, cached)| match p {
                    Primitive::Geometric(GeometricPrimitive {
                        shape: Shape::Triangle(tri),
                        ..
                    }) if cached.is_some() => tri.frame(),
                    _ => TriangleFrame::default(),
                })
                .collect()
        } else {
            Vec::new()
        };
        PrimitiveAggregate {
            prims,
            accel,
            triangle_vertices,
            triangle_frames,
        }
    }

    /// The primitives.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// The acceleration structure.
    pub fn accelerator(&self) -> &Accelerator {
        &self.accel
    }

    /// Bounds of everything.
    pub fn bounds(&self) -> Bounds3f {
        self.accel.bounds()
    }

    /// The closest hit in (0, t_max).
    ///
    /// Opaque triangles (nearly all primitives in practice) are tested
    /// without building their surface interaction; only the closest hit's
    /// is built, at the end. The result is the same as building every
    /// hit's, as pbrt-v4 does, and the same as the two steps
    /// [`PrimitiveAggregate::intersect_record`] and
    /// [`PrimitiveAggregate::interaction`] (fused here: a non-triangle's
    /// interaction is kept from its test rather than built again).
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let mut closest = Closest::None;
        let tr = TriangleRay::new(ray);
        self.accel.intersect(
            ray,
            t_max,
            #[inline(always)]
            |i, _, t| {
                if let Some(Some([p0, p1, p2])) = self.triangle_vertices.get(i as usize) {
                    let (p0, p1, p2) = (*p0, *p1, *p2);
                    let (b0, b1, b2, t_hit) = intersect_prepared_triangle(&tr, t, p0, p1, p2)?;
                    closest = Closest::Triangle {
                        prim: i,
                        b: (b0, b1, b2),
                        t_hit,
                    };
                    return Some(t_hit);
                }
                self.intersect_other(i, ray, t, &mut closest)
            },
        );
        match closest {
            Closest::None => None,
            Closest::Full(pi) => Some(pi),
            Closest::Triangle { prim, b, t_hit } => self.triangle_interaction(prim, b, t_hit, ray),
        }
    }

    /// The closest hit in (0, t_max) without its interaction (the first
    /// step of [`PrimitiveAggregate::intersect`]; the same primitives are
    /// tested in the same order, so the hit is the one it finds).
    pub fn intersect_record(&self, ray: &Ray, t_max: Float) -> Option<HitRecord> {
        let mut closest = None;
        let tr = TriangleRay::new(ray);
        self.accel.intersect(
            ray,
            t_max,
            #[inline(always)]
            |i, _, t| {
                if let Some(Some([p0, p1, p2])) = self.triangle_vertices.get(i as usize) {
                    let (p0, p1, p2) = (*p0, *p1, *p2);
                    let (b0, b1, b2, t_hit) = intersect_prepared_triangle(&tr, t, p0, p1, p2)?;
                    closest = Some(HitRecord {
                        primitive: i,
                        t_hit,
                        kind: HitKind::Triangle(b0, b1, b2),
                    });
                    return Some(t_hit);
                }
                let t_hit = self.prims[i as usize].intersect(ray, t)?.t_hit;
                closest = Some(HitRecord {
                    primitive: i,
                    t_hit,
                    kind: HitKind::Other { t_max: t },
                });
                Some(t_hit)
            },
        );
        closest
    }

    /// The interaction of a hit that [`PrimitiveAggregate::intersect_record`]
    /// found for the same ray (the second step of
    /// [`PrimitiveAggregate::intersect`]): bit for bit the one `intersect`
    /// returns. `None` only for a record of another aggregate.
    pub fn interaction(&self, ray: &Ray, hit: &HitRecord) -> Option<PrimitiveIntersection> {
        if hit.primitive as usize >= self.prims.len() {
            return None;
        }
        match hit.kind {
            HitKind::Triangle(b0, b1, b2) => {
                self.triangle_interaction(hit.primitive, (b0, b1, b2), hit.t_hit, ray)
            }
            HitKind::Other { t_max } => self.prims[hit.primitive as usize].intersect(ray, t_max),
        }
    }

    /// The interaction of a hit on the opaque triangle `prim` (one in
    /// `triangle_vertices`) at barycentrics `b`.
    #[inline(always)]
    fn triangle_interaction(
        &self,
        prim: u32,
        b: (Float, Float, Float),
        t_hit: Float,
        ray: &Ray,
    ) -> Option<PrimitiveIntersection> {
        match &self.prims[prim as usize] {
            Primitive::Geometric(g) => match &g.shape {
                Shape::Triangle(tri) => Some(PrimitiveIntersection {
                    // One construction path (not a `match` between two
                    // calls), so that the interaction is built in place
                    // instead of copied.
                    si: tri.interaction_at_hit_with_frame(
                        &self
                            .triangle_frames
                            .get(prim as usize)
                            .copied()
                            .unwrap_or_else(|| tri.frame()),
                        b.0,
                        b.1,
                        b.2,
                        ray,
                    ),
                    t_hit,
                    material: g.material,
                    area_light: g.area_light,
                    medium_interface: g.medium_interface,
                }),
                // `triangle_vertices` holds only triangles.
                _ => None,
            },
            _ => None,
        }
    }

    /// The test of a primitive that is not an opaque triangle, out of line
    /// so that the triangle test above inlines into the traversal.
    #[inline(never)]
    fn intersect_other(
        &self,
        i: u32,
        ray: &Ray,
        t_max: Float,
        closest: &mut Closest,
    ) -> Option<Float> {
        let pi = self.prims[i as usize].intersect(ray, t_max)?;
        let th = pi.t_hit;
        *closest = Closest::Full(pi);
        Some(th)
    }

    /// Whether anything is hit in (0, t_max).
    pub fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        let tr = TriangleRay::new(ray);
        self.accel.intersect_p(ray, t_max, |i, r, t| {
            match self.triangle_vertices.get(i as usize) {
                Some(Some([p0, p1, p2])) => {
                    intersect_prepared_triangle(&tr, t, *p0, *p1, *p2).is_some()
                }
                _ => self.prims[i as usize].intersect_p(r, t),
            }
        })
    }
}

#[cfg(test)]
mod tests;
