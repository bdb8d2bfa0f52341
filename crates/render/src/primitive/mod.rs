//! Primitives (pbrt-v4 `primitive.h/.cpp`; book section 7.1): shapes bound
//! to their material, area light, media and alpha mask; object instances
//! placed by a fixed or animated transformation; and aggregates that put an
//! acceleration structure over a set of primitives.

use crate::accel::packet::MAX_PACKET;
use crate::accel::{AccelParams, Accelerator, Aggregate, WideBvh};
use crate::shape::triangle::{
    intersect_prepared_triangle, intersect_triangle, triangle_is_nondegenerate, TriangleFrame,
    TriangleOf, TriangleRay,
};
use crate::shape::{Shape, ShapeMethods, TriangleMesh};
use crate::simd::SimdLevel;
use crate::texture::{FloatTextureRef, TextureEvalContext};
use rpbrt_geometry::animated::AnimatedTransform;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::{MediumId, Ray};
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::transform_list::TransformList;
use rpbrt_geometry::tuple::{Normal3f, Point2f, Point3f, Vector3f};
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

/// Keeps a hit or lets the ray pass according to the alpha mask.
#[inline]
fn alpha_passes(alpha: &Alpha, ray: &Ray, si: &SurfaceInteraction) -> bool {
    let a = match alpha {
        Alpha::Opaque => return true,
        Alpha::Constant(a) => *a,
        Alpha::Texture(t) => t.evaluate(&TextureEvalContext::from_si(si)),
    };
    a >= 1.0 || (a > 0.0 && hash_float_ray(ray) <= a)
}

impl GeometricPrimitive {
    /// The closest hit in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let isect = self.shape.intersect(ray, t_max)?;
        if !alpha_passes(&self.alpha, ray, &isect.intr) {
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

/// The triangles of one mesh with a common material, media and alpha and
/// no area light: the primitive of a whole `trianglemesh` or `plymesh`.
/// An aggregate gives each of its triangles an entry of its own in the
/// acceleration structure, reached through the mesh and the triangle's
/// index, so that no per-triangle primitive is stored.
#[derive(Clone, Debug)]
pub struct MeshPrimitive {
    /// The mesh; its degenerate triangles (see
    /// [`TriangleMesh::is_valid_triangle`]) are left out.
    pub mesh: Arc<TriangleMesh>,
    /// Material index (`None`: interface).
    pub material: Option<u32>,
    /// Media on either side.
    pub medium_interface: Option<MediumInterface>,
    /// Alpha mask.
    pub alpha: Alpha,
}

impl MeshPrimitive {
    /// Triangle `i` of the mesh.
    #[inline(always)]
    fn triangle(&self, i: u32) -> TriangleOf<&TriangleMesh> {
        TriangleOf {
            mesh: &*self.mesh,
            tri_index: i,
        }
    }

    /// The bounds of triangle `i`; empty for a degenerate triangle, so that
    /// acceleration structures leave it out.
    fn triangle_bounds(&self, i: u32) -> Bounds3f {
        if self.mesh.is_valid_triangle(i as usize) {
            let [p0, p1, p2] = self.mesh.vertices(i as usize);
            Bounds3f::new(p0, p1).union_point(p2)
        } else {
            Bounds3f::empty()
        }
    }

    /// The hit of triangle `i` in (0, t_max), alpha mask applied: what a
    /// [`GeometricPrimitive`] holding that triangle returns.
    fn intersect_triangle(&self, i: u32, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let tri = self.triangle(i);
        let [p0, p1, p2] = tri.vertex_positions();
        let (b0, b1, b2, t_hit) = intersect_triangle(ray, t_max, p0, p1, p2)?;
        let si = tri.interaction_at_hit(b0, b1, b2, ray);
        if !alpha_passes(&self.alpha, ray, &si) {
            return None;
        }
        Some(PrimitiveIntersection {
            si,
            t_hit,
            material: self.material,
            area_light: None,
            medium_interface: self.medium_interface,
        })
    }

    /// Whether triangle `i` blocks the ray in (0, t_max).
    fn intersect_p_triangle(&self, i: u32, ray: &Ray, t_max: Float) -> bool {
        match self.alpha {
            Alpha::Opaque => {
                let [p0, p1, p2] = self.mesh.vertices(i as usize);
                intersect_triangle(ray, t_max, p0, p1, p2).is_some()
            }
            _ => self.intersect_triangle(i, ray, t_max).is_some(),
        }
    }

    /// The triangles that are not degenerate.
    fn valid_triangles(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.mesh.n_triangles() as u32).filter(|&i| self.mesh.is_valid_triangle(i as usize))
    }
}

/// The closest of the hits `hit` finds on each of `entries`, each asked
/// within (0, the closest so far).
fn closest_of(
    entries: impl Iterator<Item = u32>,
    mut t_max: Float,
    mut hit: impl FnMut(u32, Float) -> Option<PrimitiveIntersection>,
) -> Option<PrimitiveIntersection> {
    let mut closest = None;
    for i in entries {
        if let Some(pi) = hit(i, t_max) {
            t_max = pi.t_hit;
            closest = Some(pi);
        }
    }
    closest
}

/// Object instances: shared aggregates (object definitions), each placed
/// by a fixed transformation. An aggregate gives each instance an entry
/// of its own, as it gives a mesh's triangles, so a run of instances is
/// one primitive: per instance a transformation and the index of its
/// object in flat arrays (52 bytes for an affine transformation, kept as
/// its inverse: see [`TransformList`]), where
/// a primitive of its own took a 72-byte enum and a boxed 136-byte
/// transformation and object.
#[derive(Clone, Debug, Default)]
pub struct InstanceSet {
    /// The instanced aggregates, each in its own space.
    objects: Vec<Arc<PrimitiveAggregate>>,
    /// Per instance: the index of its object in `objects`.
    object_of: Vec<u32>,
    /// Per instance: from its object's space to rendering space.
    render_from_object: TransformList,
}

impl InstanceSet {
    /// No instances.
    pub fn new() -> InstanceSet {
        InstanceSet::default()
    }

    /// One instance of `object`.
    pub fn one(object: Arc<PrimitiveAggregate>, render_from_object: Transform) -> InstanceSet {
        let mut set = InstanceSet::new();
        let k = set.add_object(object);
        set.push(k, render_from_object);
        set
    }

    /// Instances of `objects`: instance `i` places `objects[object_of[i]]`
    /// by `render_from_object.get(i)` (the lists moved in, not copied).
    /// Panics unless the lists are as long and every index is in range.
    pub fn from_parts(
        objects: Vec<Arc<PrimitiveAggregate>>,
        object_of: Vec<u32>,
        render_from_object: TransformList,
    ) -> InstanceSet {
        assert_eq!(object_of.len(), render_from_object.len());
        assert!(
            object_of.iter().all(|&k| (k as usize) < objects.len()),
            "an instance of no object"
        );
        InstanceSet {
            objects,
            object_of,
            render_from_object,
        }
    }

    /// Adds an object that instances may place; returns its index for
    /// [`InstanceSet::push`].
    pub fn add_object(&mut self, object: Arc<PrimitiveAggregate>) -> u32 {
        self.objects.push(object);
        (self.objects.len() - 1) as u32
    }

    /// Adds an instance of the object `object` (an index that
    /// [`InstanceSet::add_object`] returned).
    pub fn push(&mut self, object: u32, render_from_object: Transform) {
        // A bad index would otherwise panic at the first ray to meet it.
        assert!((object as usize) < self.objects.len(), "no object {object}");
        self.object_of.push(object);
        self.render_from_object.push(render_from_object);
        debug_assert_eq!(self.object_of.len(), self.render_from_object.len());
    }

    /// Room for `n` more instances.
    pub fn reserve_exact(&mut self, n: usize) {
        self.object_of.reserve_exact(n);
        self.render_from_object.reserve_exact(n);
    }

    /// The number of instances.
    pub fn len(&self) -> usize {
        self.object_of.len()
    }

    /// True when there are no instances.
    pub fn is_empty(&self) -> bool {
        self.object_of.is_empty()
    }

    /// Instance `i`: its object and transformation.
    #[inline]
    fn get(&self, i: u32) -> (&PrimitiveAggregate, Transform) {
        let i = i as usize;
        (
            &self.objects[self.object_of[i] as usize],
            self.render_from_object.get(i),
        )
    }

    /// The bounds of instance `i` in rendering space.
    fn bounds_of(&self, i: u32) -> Bounds3f {
        let (object, xf) = self.get(i);
        xf.apply_bounds(&object.bounds())
    }

    /// Instance `i`'s object and `ray` (with `t_max`) taken into its
    /// space, by the inverse transformation alone (the forward one of an
    /// affine instance is recomputed, so only a hit asks for it).
    #[inline]
    fn ray_into(&self, i: u32, ray: &Ray, t_max: Float) -> (&PrimitiveAggregate, Ray, Float) {
        let object = &self.objects[self.object_of[i as usize] as usize];
        let object_from_render = self.render_from_object.inverse_matrix(i as usize);
        let (r, t) = object_from_render.apply_ray(ray, t_max);
        (object, r, t)
    }

    /// The closest hit on instance `i` in (0, t_max).
    fn intersect_one(&self, i: u32, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let (object, r, t) = self.ray_into(i, ray, t_max);
        let pi = object.intersect(&r, t)?;
        Some(transform_hit(pi, &self.render_from_object.get(i as usize)))
    }

    /// Whether instance `i` blocks the ray in (0, t_max).
    fn intersect_p_one(&self, i: u32, ray: &Ray, t_max: Float) -> bool {
        let (object, r, t) = self.ray_into(i, ray, t_max);
        object.intersect_p(&r, t)
    }

    /// Reverses the order of the instances.
    pub fn reverse(&mut self) {
        self.object_of.reverse();
        self.render_from_object.reverse();
    }

    /// Gives back the room reserved beyond the instances.
    pub fn shrink_to_fit(&mut self) {
        self.object_of.shrink_to_fit();
        self.render_from_object.shrink_to_fit();
    }

    /// The instances' indices.
    fn indices(&self) -> impl Iterator<Item = u32> {
        0..self.len() as u32
    }
}

/// Primitives whose transformation changes over the shutter interval.
#[derive(Clone, Debug)]
pub struct AnimatedPrimitive {
    /// What moves, in its own space.
    pub primitive: Moving,
    /// From the primitive's space to rendering space, over time.
    pub render_from_primitive: AnimatedTransform,
    /// The primitive's bounds in its own space.
    bounds: Bounds3f,
    /// The largest coordinate of those bounds, in magnitude.
    bounds_magnitude: Float,
}

impl AnimatedPrimitive {
    /// `primitive` moved by `render_from_primitive`.
    pub fn new(primitive: Moving, render_from_primitive: AnimatedTransform) -> Self {
        let bounds = primitive.bounds();
        let bounds_magnitude = [bounds.p_min, bounds.p_max]
            .iter()
            .flat_map(|p| [p.x.abs(), p.y.abs(), p.z.abs()])
            .fold(0.0, Float::max);
        AnimatedPrimitive {
            primitive,
            render_from_primitive,
            bounds,
            bounds_magnitude,
        }
    }

    /// False only when the ray surely misses the primitive: a test of the
    /// primitive's own box where it is at the ray's time, made before the
    /// ray is taken into the primitive's space (a transformation, and for
    /// a sphere an interval test, per primitive met). The box in rendering
    /// space is the whole motion's, and a ray that meets it mostly misses
    /// the primitive: 200,000 moving spheres spend most of their render
    /// in those tests.
    ///
    /// Only for keyframes that are both translations, where the primitive
    /// at the ray's time is its box moved by an offset. The box is padded
    /// by 10⁻⁴ of the largest coordinate in play, hundreds of times the
    /// rounding of this test and of the exact one after it (the ray's
    /// transformation, the shape's test and its error bounds), so a ray
    /// the exact test finds a hit on is never turned away; a `NaN` keeps
    /// the exact test.
    #[inline]
    fn may_hit(&self, ray: &Ray, t_max: Float) -> bool {
        let Some(off) = self.render_from_primitive.translation_at(ray.time) else {
            return true;
        };
        let o = [ray.o.x - off.x, ray.o.y - off.y, ray.o.z - off.z];
        let d = [ray.d.x, ray.d.y, ray.d.z];
        let magnitude = [ray.o.x, ray.o.y, ray.o.z, off.x, off.y, off.z]
            .iter()
            .fold(self.bounds_magnitude, |m, v| m.max(v.abs()));
        let pad = 1e-4 * magnitude;
        let b = &self.bounds;
        let (lo, hi) = (
            [b.p_min.x, b.p_min.y, b.p_min.z],
            [b.p_max.x, b.p_max.y, b.p_max.z],
        );
        let (mut t_near, mut t_far) = (0.0, t_max);
        for i in 0..3 {
            let (near, far) = (lo[i] - pad - o[i], hi[i] + pad - o[i]);
            if d[i] == 0.0 {
                if near > 0.0 || far < 0.0 {
                    return false;
                }
                continue;
            }
            let (t0, t1) = (near / d[i], far / d[i]);
            let (t0, t1) = if t0 > t1 { (t1, t0) } else { (t0, t1) };
            if t0 > t_near {
                t_near = t0;
            }
            if t1 < t_far {
                t_far = t1;
            }
            if t_near > t_far {
                return false;
            }
        }
        true
    }
}

/// What an [`AnimatedPrimitive`] moves: one shape (as pbrt-v4 wraps a
/// single shape's primitive directly), or an aggregate over several (a
/// mesh's triangles, an object definition's shapes).
#[derive(Clone, Debug)]
pub enum Moving {
    /// A single shape: no aggregate of its own (a scene of many moving
    /// spheres would otherwise hold a tree per sphere).
    One(Primitive),
    /// Several primitives, or a mesh, under their own aggregate.
    Many(Arc<PrimitiveAggregate>),
}

impl Moving {
    /// `prims` as one moving primitive, under `accel` when they need an
    /// aggregate; `None` when there are none. Takes them all, leaving
    /// `prims` empty (and, for a single shape, its room kept for the next
    /// one: a scene of many moving shapes makes them one after another).
    pub fn of(prims: &mut Vec<Primitive>, accel: &AccelParams) -> Option<Moving> {
        match prims.len() {
            0 => None,
            1 if matches!(prims[0], Primitive::Geometric(_)) => prims.pop().map(Moving::One),
            _ => Some(Moving::Many(Arc::new(PrimitiveAggregate::new(
                std::mem::take(prims),
                accel,
            )))),
        }
    }

    /// Bounds in the primitive's own space.
    fn bounds(&self) -> Bounds3f {
        match self {
            Moving::One(p) => p.bounds(),
            Moving::Many(a) => a.bounds(),
        }
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        match self {
            Moving::One(p) => p.intersect(ray, t_max),
            Moving::Many(a) => a.intersect(ray, t_max),
        }
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        match self {
            Moving::One(p) => p.intersect_p(ray, t_max),
            Moving::Many(a) => a.intersect_p(ray, t_max),
        }
    }

    fn for_each_material(&self, f: &mut impl FnMut(u32)) {
        match self {
            Moving::One(p) => p.for_each_material(f),
            Moving::Many(a) => a.prims.iter().for_each(|q| q.for_each_material(f)),
        }
    }
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
    /// The triangles of a mesh with common properties (an aggregate gives
    /// each triangle an entry).
    Mesh(MeshPrimitive),
    /// Object instances under fixed transformations (an aggregate gives
    /// each an entry; boxed: three vectors would make every primitive
    /// larger).
    Instances(Box<InstanceSet>),
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
            Primitive::Mesh(p) => {
                if let Some(m) = p.material {
                    f(m)
                }
            }
            Primitive::Instances(set) => {
                for &k in &set.object_of {
                    for q in &set.objects[k as usize].prims {
                        q.for_each_material(f);
                    }
                }
            }
            Primitive::Animated(p) => p.primitive.for_each_material(f),
        }
    }

    /// Bounds in rendering space (over the whole shutter for animated ones).
    pub fn bounds(&self) -> Bounds3f {
        match self {
            Primitive::Geometric(p) => p.shape.bounds(),
            Primitive::Mesh(p) => p
                .valid_triangles()
                .fold(Bounds3f::empty(), |b, i| b.union(&p.triangle_bounds(i))),
            Primitive::Instances(set) => set
                .indices()
                .fold(Bounds3f::empty(), |b, i| b.union(&set.bounds_of(i))),
            Primitive::Animated(p) => p.render_from_primitive.motion_bounds(&p.bounds),
        }
    }

    /// The closest hit in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        match self {
            Primitive::Geometric(p) => p.intersect(ray, t_max),
            // (Aggregates test a mesh's triangles, and a set's instances,
            // as entries of their own; these are for one met on its own.)
            Primitive::Mesh(p) => closest_of(p.valid_triangles(), t_max, |i, t| {
                p.intersect_triangle(i, ray, t)
            }),
            Primitive::Instances(set) => {
                closest_of(set.indices(), t_max, |i, t| set.intersect_one(i, ray, t))
            }
            Primitive::Animated(p) => {
                if !p.may_hit(ray, t_max) {
                    return None;
                }
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
            Primitive::Mesh(p) => p
                .valid_triangles()
                .any(|i| p.intersect_p_triangle(i, ray, t_max)),
            Primitive::Instances(set) => set.indices().any(|i| set.intersect_p_one(i, ray, t_max)),
            Primitive::Animated(p) => {
                if !p.may_hit(ray, t_max) {
                    return false;
                }
                let (r, t) = p
                    .render_from_primitive
                    .interpolate(ray.time)
                    .apply_inverse_ray(ray, t_max);
                p.primitive.intersect_p(&r, t)
            }
        }
    }
}

/// Aggregates with at most this many entries keep the vertices of their
/// triangles beside the entries for the traversal.
const MAX_CACHED_TRIANGLE_PRIMITIVES: usize = 1 << 22;

/// Aggregates with at most this many entries also keep each triangle's
/// [`TriangleFrame`] (at most 60 MiB).
const MAX_TRIANGLE_FRAME_PRIMITIVES: usize = 1 << 20;

/// Aggregates with more entries than this have their hits' mesh data
/// prefetched in batches ([`PrimitiveAggregate::prefetch_pays`]): about
/// the entries whose indices, vertices and normals fill a core's 512 KiB
/// second-level cache.
const PREFETCH_MIN_ENTRIES: usize = 1 << 13;

/// Up to this many primitives, an entry's primitive is found by a binary
/// search over their first entries; beyond it, by a table with one `u32`
/// per entry.
const MAX_SEARCHED_PRIMITIVES: usize = 16;

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
    /// The entry hit: an index below [`PrimitiveAggregate::entry_count`]
    /// (a primitive, or one triangle of a [`MeshPrimitive`]).
    pub primitive: u32,
    /// The ray parameter of the hit.
    pub t_hit: Float,
    /// What builds the interaction.
    kind: HitKind,
}

/// A hit on a triangle, before its interaction is built
/// ([`PrimitiveAggregate::triangle_hit`]).
#[derive(Debug)]
pub(crate) struct TriangleHit<'a> {
    /// The triangle.
    pub tri: TriangleOf<&'a TriangleMesh>,
    /// Its cached frame (what does not depend on the point hit), if the
    /// aggregate keeps frames ([`TriangleHit::frame_parts`]).
    pub frame: Option<&'a TriangleFrame>,
    /// The barycentrics of the hit.
    pub b: [Float; 3],
    /// The primitive's material (`None`: interface).
    pub material: Option<u32>,
    /// The primitive's area light.
    pub area_light: Option<u32>,
}

impl TriangleHit<'_> {
    /// Writes the triangle's geometric normal and ∂p/∂u to `ng` and
    /// `dpdu`: read in place from the cached frame (a hit holding copies,
    /// or a frame copied whole, goes through the stack and stalls on
    /// store forwarding), or from a frame computed now.
    #[inline(always)]
    pub(crate) fn frame_parts(&self, ng: &mut Normal3f, dpdu: &mut Vector3f) {
        match self.frame {
            Some(f) => {
                *ng = f.n;
                *dpdu = f.dpdu;
            }
            None => {
                let f = self.tri.frame();
                *ng = f.n;
                *dpdu = f.dpdu;
            }
        }
    }

    /// What texture lookups read of the hit besides the point and its
    /// normal, as the interaction holds it.
    #[inline(always)]
    pub(crate) fn texture_parts(&self) -> TextureParts {
        let [b0, b1, b2] = self.b;
        let (dpdu, dpdv) = match self.frame {
            Some(f) => (f.dpdu, f.dpdv),
            None => {
                let f = self.tri.frame();
                (f.dpdu, f.dpdv)
            }
        };
        TextureParts {
            uv: self.tri.uv_at(b0, b1, b2),
            dpdu,
            dpdv,
            face_index: self.tri.face_index(),
        }
    }
}

/// A triangle hit's surface parameterization at the point hit
/// ([`TriangleHit::texture_parts`]): (u, v), the geometric ∂p/∂u and
/// ∂p/∂v, and the face index.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TextureParts {
    pub uv: Point2f,
    pub dpdu: Vector3f,
    pub dpdv: Vector3f,
    pub face_index: i32,
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

/// Where the entries of an aggregate's primitives lie in the acceleration
/// structure: one entry per primitive, except a [`MeshPrimitive`], which
/// has one per triangle (degenerate ones included, with empty bounds), and
/// an [`InstanceSet`], which has one per instance. Entries keep the
/// primitives' order.
#[derive(Clone, Debug, Default)]
struct EntryMap {
    /// The first entry of each primitive, then the number of entries;
    /// empty when every primitive has one entry (entry `i` is primitive
    /// `i`).
    starts: Vec<u32>,
    /// The primitive of each entry, kept when there are too many
    /// primitives to search `starts`.
    owner: Vec<u32>,
    /// The number of entries.
    len: usize,
}

impl EntryMap {
    fn new(prims: &[Primitive]) -> EntryMap {
        let entries = |p: &Primitive| match p {
            Primitive::Mesh(m) => m.mesh.n_triangles(),
            Primitive::Instances(set) => set.len(),
            _ => 1,
        };
        let len: usize = prims.iter().map(entries).sum();
        // The accelerators number entries with `u32`s; a mesh of 2^32
        // triangles would need hundreds of gigabytes to get here.
        debug_assert!(len <= u32::MAX as usize);
        if len == prims.len() && prims.iter().all(|p| entries(p) == 1) {
            return EntryMap {
                len,
                ..EntryMap::default()
            };
        }
        let mut starts = Vec::with_capacity(prims.len() + 1);
        let mut next = 0u32;
        for p in prims {
            starts.push(next);
            next = next.wrapping_add(entries(p) as u32);
        }
        starts.push(next);
        let mut owner = Vec::new();
        if prims.len() > MAX_SEARCHED_PRIMITIVES {
            owner.reserve_exact(len);
            for (k, p) in prims.iter().enumerate() {
                owner.extend(std::iter::repeat_n(k as u32, entries(p)));
            }
        }
        EntryMap { starts, owner, len }
    }

    /// The primitive holding entry `e`, and which of its entries it is
    /// (the triangle, for a mesh).
    #[inline(always)]
    fn locate(&self, e: u32) -> (usize, u32) {
        if self.starts.is_empty() {
            return (e as usize, 0);
        }
        let p = match self.owner.get(e as usize) {
            Some(&p) => p as usize,
            None => self.starts.partition_point(|&s| s <= e).saturating_sub(1),
        };
        (p, e - self.starts[p])
    }
}

/// Primitives under an acceleration structure (pbrt-v4's aggregates).
#[derive(Clone, Debug)]
pub struct PrimitiveAggregate {
    prims: Vec<Primitive>,
    entries: EntryMap,
    accel: Accelerator,
    /// Per slot of the acceleration structure (its leaf order for the
    /// wide BVHs, so that a leaf's triangles are read from consecutive
    /// memory): the vertices of an opaque, non-degenerate triangle, so that
    /// the traversal tests it without going through the primitive and its
    /// mesh (`None` for every other entry; empty for large aggregates).
    triangle_vertices: Vec<Option<[Point3f; 3]>>,
    /// Per entry, for the same triangles: the parts of the surface
    /// interaction that are the same all over the triangle, so that a hit
    /// builds only the rest (empty for large aggregates, default for
    /// other entries).
    triangle_frames: Vec<TriangleFrame>,
}

impl PrimitiveAggregate {
    /// Builds the structure chosen by `params` over `prims` (over each
    /// triangle of their meshes).
    pub fn new(prims: Vec<Primitive>, params: &AccelParams) -> Self {
        Self::with_cache_limits(
            prims,
            params,
            MAX_CACHED_TRIANGLE_PRIMITIVES,
            MAX_TRIANGLE_FRAME_PRIMITIVES,
        )
    }

    /// [`PrimitiveAggregate::new`] keeping triangle vertices for at most
    /// `max_vertices` entries and frames for at most `max_frames` (tests
    /// use small limits to reach the paths of large aggregates).
    fn with_cache_limits(
        prims: Vec<Primitive>,
        params: &AccelParams,
        max_vertices: usize,
        max_frames: usize,
    ) -> Self {
        let entries = EntryMap::new(&prims);
        let n = entries.len;
        // The vertices of entry `e` when it is an opaque, non-degenerate
        // triangle.
        let opaque_triangle = |e: u32| -> Option<[Point3f; 3]> {
            let (p, i) = entries.locate(e);
            let [p0, p1, p2] = match &prims[p] {
                Primitive::Geometric(GeometricPrimitive {
                    shape: Shape::Triangle(tri),
                    alpha: Alpha::Opaque,
                    ..
                }) => tri.vertex_positions(),
                Primitive::Mesh(MeshPrimitive {
                    mesh,
                    alpha: Alpha::Opaque,
                    ..
                }) if mesh.is_valid_triangle(i as usize) => mesh.vertices(i as usize),
                _ => return None,
            };
            triangle_is_nondegenerate(p0, p1, p2).then_some([p0, p1, p2])
        };
        let accel = Accelerator::build_from_triangles(
            n,
            |e| {
                let (p, i) = entries.locate(e);
                match &prims[p] {
                    Primitive::Mesh(m) => m.triangle_bounds(i),
                    Primitive::Instances(set) => set.bounds_of(i),
                    prim => prim.bounds(),
                }
            },
            opaque_triangle,
            params,
        );
        // 40 bytes per entry: bounded so that huge scenes do not pay
        // gigabytes for it (they fall back to going through the mesh),
        // and kept only where at least half the entries are triangles (a
        // million object instances over a small mesh would pay 100 MB
        // for this and the frames below, and cache nothing).
        let triangle_entries: usize = prims
            .iter()
            .map(|p| match p {
                Primitive::Mesh(m) => m.mesh.n_triangles(),
                Primitive::Geometric(GeometricPrimitive {
                    shape: Shape::Triangle(_),
                    ..
                }) => 1,
                _ => 0,
            })
            .sum();
        let cached = n <= max_vertices && 2 * triangle_entries >= n;
        let triangle_vertices: Vec<Option<[Point3f; 3]>> = match accel.slot_entries() {
            _ if !cached => Vec::new(),
            Some(order) => order.iter().map(|&e| opaque_triangle(e)).collect(),
            None => (0..n as u32).map(opaque_triangle).collect(),
        };
        // 60 bytes per entry, read once per closest hit; only for the
        // triangles whose vertices are cached.
        let triangle_frames = if cached && n <= max_frames {
            (0..n as u32)
                .map(|e| {
                    if opaque_triangle(e).is_none() {
                        return TriangleFrame::default();
                    }
                    let (p, i) = entries.locate(e);
                    match &prims[p] {
                        Primitive::Geometric(GeometricPrimitive {
                            shape: Shape::Triangle(tri),
                            ..
                        }) => tri.frame(),
                        Primitive::Mesh(m) => m.triangle(i).frame(),
                        _ => TriangleFrame::default(),
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        PrimitiveAggregate {
            prims,
            entries,
            accel,
            triangle_vertices,
            triangle_frames,
        }
    }

    /// The primitives (a mesh primitive is one, whatever its triangles).
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// The number of entries in the acceleration structure: one per
    /// primitive, one per triangle of a [`MeshPrimitive`].
    pub fn entry_count(&self) -> usize {
        self.entries.len
    }

    /// The number of entries the acceleration structure holds: those whose
    /// bounds it can use (degenerate triangles and primitives with
    /// non-finite bounds are left out).
    pub fn primitive_count(&self) -> usize {
        self.accel.primitive_count() - self.accel.skipped_primitives()
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
        self.accel.intersect_slots(
            ray,
            t_max,
            #[inline(always)]
            |slot, i, _, t| {
                if let Some(Some([p0, p1, p2])) = self.triangle_vertices.get(slot as usize) {
                    let (p0, p1, p2) = (*p0, *p1, *p2);
                    let (b0, b1, b2, t_hit) = intersect_prepared_triangle(&tr, t, p0, p1, p2)?;
                    closest = Closest::Triangle {
                        prim: i,
                        b: (b0, b1, b2),
                        t_hit,
                    };
                    return Some(t_hit);
                }
                self.intersect_other(i, ray, &tr, t, &mut closest)
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
        self.accel.intersect_slots(
            ray,
            t_max,
            #[inline(always)]
            |slot, i, _, t| {
                if let Some(Some([p0, p1, p2])) = self.triangle_vertices.get(slot as usize) {
                    let (p0, p1, p2) = (*p0, *p1, *p2);
                    let (b0, b1, b2, t_hit) = intersect_prepared_triangle(&tr, t, p0, p1, p2)?;
                    closest = Some(HitRecord {
                        primitive: i,
                        t_hit,
                        kind: HitKind::Triangle(b0, b1, b2),
                    });
                    return Some(t_hit);
                }
                let record = self.record_other(i, ray, &tr, t)?;
                closest = Some(record);
                Some(record.t_hit)
            },
        );
        closest
    }

    /// [`PrimitiveAggregate::intersect_record`] of each of up to
    /// [`MAX_PACKET`] rays (no bound on the ray parameter), into the first
    /// `rays.len()` values of `out`. Under a wide BVH the rays walk the
    /// tree as one packet at `level`'s width ([`crate::accel::packet`]);
    /// otherwise, or at [`SimdLevel::Scalar`], one by one. The records are
    /// those of single rays, but where two primitives tie exactly in
    /// distance.
    pub fn intersect_records_packet(
        &self,
        rays: &[Ray],
        level: SimdLevel,
        out: &mut [Option<HitRecord>],
    ) {
        match &self.accel {
            Accelerator::Bvh4(bvh) => self.packet_records(bvh, rays, level, out),
            Accelerator::Bvh8(bvh) => self.packet_records(bvh, rays, level, out),
            _ => {
                for (o, r) in out.iter_mut().zip(rays) {
                    *o = self.intersect_record(r, Float::INFINITY);
                }
            }
        }
    }

    /// [`PrimitiveAggregate::intersect_records_packet`] under a wide BVH.
    fn packet_records<const W: usize>(
        &self,
        bvh: &WideBvh<W>,
        rays: &[Ray],
        level: SimdLevel,
        out: &mut [Option<HitRecord>],
    ) {
        let n = rays.len();
        if level == SimdLevel::Scalar || n > MAX_PACKET {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = self.intersect_record(r, Float::INFINITY);
            }
            return;
        }
        let mut trs = [TriangleRay::new(&rays[0]); MAX_PACKET];
        for (t, r) in trs.iter_mut().zip(rays) {
            *t = TriangleRay::new(r);
        }
        let mut t_max = [Float::INFINITY; MAX_PACKET];
        let mut best = [None; MAX_PACKET];
        let mut bary = [None; MAX_PACKET];
        let mut records = [None::<HitRecord>; MAX_PACKET];
        // Triangles are tested in lanes (their records built below from
        // the barycentrics); the closure sees the other primitives only.
        bvh.intersect_packet_triangles(
            level,
            rays,
            &mut t_max[..n],
            &mut best[..n],
            &self.triangle_vertices,
            &mut bary[..n],
            |lane: usize, _slot: u32, i: u32, ray: &Ray, t: Float| {
                let record = self.record_other(i, ray, &trs[lane], t)?;
                records[lane] = Some(record);
                Some(record.t_hit)
            },
        );
        for lane in 0..n {
            out[lane] = match (best[lane], bary[lane]) {
                (Some((i, t_hit)), Some([b0, b1, b2])) => Some(HitRecord {
                    primitive: i,
                    t_hit,
                    kind: HitKind::Triangle(b0, b1, b2),
                }),
                (Some(_), None) => records[lane],
                (None, _) => None,
            };
        }
    }

    /// The interaction of a hit that [`PrimitiveAggregate::intersect_record`]
    /// found for the same ray (the second step of
    /// [`PrimitiveAggregate::intersect`]): bit for bit the one `intersect`
    /// returns. `None` only for a record of another aggregate.
    pub fn interaction(&self, ray: &Ray, hit: &HitRecord) -> Option<PrimitiveIntersection> {
        if hit.primitive as usize >= self.entries.len {
            return None;
        }
        match hit.kind {
            HitKind::Triangle(b0, b1, b2) => {
                self.triangle_interaction(hit.primitive, (b0, b1, b2), hit.t_hit, ray)
            }
            HitKind::Other { t_max } => self.entry_intersect(hit.primitive, ray, t_max),
        }
    }

    /// What the interaction of a triangle hit is built from, for code that
    /// builds it itself (the wavefront's lane-parallel vertices): the mesh,
    /// the triangle, its frame, the barycentrics and the primitive's
    /// material and area light. `None` for hits on other shapes.
    #[inline]
    pub(crate) fn triangle_hit(&self, hit: &HitRecord) -> Option<TriangleHit<'_>> {
        let HitKind::Triangle(b0, b1, b2) = hit.kind else {
            return None;
        };
        let (p, i) = self.entries.locate(hit.primitive);
        let (tri, material, area_light) = match self.prims.get(p)? {
            Primitive::Geometric(g) => match &g.shape {
                Shape::Triangle(tri) => (
                    TriangleOf {
                        mesh: &*tri.mesh,
                        tri_index: tri.tri_index,
                    },
                    g.material,
                    g.area_light,
                ),
                _ => return None,
            },
            Primitive::Mesh(m) => (m.triangle(i), m.material, None),
            _ => return None,
        };
        Some(TriangleHit {
            frame: self.triangle_frames.get(hit.primitive as usize),
            tri,
            b: [b0, b1, b2],
            material,
            area_light,
        })
    }

    /// Whether [`PrimitiveAggregate::prefetch_triangle_hit`] pays: the
    /// aggregate has enough entries that their meshes are unlikely to
    /// stay in cache (below, the passes cost more than they save).
    pub(crate) fn prefetch_pays(&self) -> bool {
        self.entries.len > PREFETCH_MIN_ENTRIES
    }

    /// Starts loading what building the surface of the triangle hit `hit`
    /// reads from memory (for batches of hits, whose loads then overlap
    /// instead of each stalling in turn): with `vertices` false, the
    /// triangle's vertex indices and cached frame; with `vertices` true
    /// (a pass later, once the indices have arrived), its vertices, vertex
    /// normals and texture coordinates. Nothing for other hits.
    #[inline]
    pub(crate) fn prefetch_triangle_hit(&self, hit: &HitRecord, vertices: bool) {
        use crate::simd::prefetch_ptr;
        let HitKind::Triangle(..) = hit.kind else {
            return;
        };
        let (p, i) = self.entries.locate(hit.primitive);
        let (mesh, tri) = match self.prims.get(p) {
            Some(Primitive::Geometric(g)) => match &g.shape {
                Shape::Triangle(t) => (&*t.mesh, t.tri_index),
                _ => return,
            },
            Some(Primitive::Mesh(m)) => (&*m.mesh, i),
            _ => return,
        };
        let first = 3 * tri as usize;
        if !vertices {
            prefetch_ptr(mesh.indices.as_ptr().wrapping_add(first));
            prefetch_ptr(
                self.triangle_frames
                    .as_ptr()
                    .wrapping_add(hit.primitive as usize),
            );
            return;
        }
        let Some(v) = mesh.indices.get(first..first + 3) else {
            return;
        };
        for &k in v {
            prefetch_ptr(mesh.p.as_ptr().wrapping_add(k as usize));
            if let Some(n) = &mesh.n {
                prefetch_ptr(n.as_ptr().wrapping_add(k as usize));
            }
            // Read by the scalar vertex's interaction.
            if let Some(uv) = &mesh.uv {
                prefetch_ptr(uv.as_ptr().wrapping_add(k as usize));
            }
        }
    }

    /// The interaction of a hit on the opaque triangle at entry `prim` at
    /// barycentrics `b`.
    #[inline(always)]
    fn triangle_interaction(
        &self,
        prim: u32,
        b: (Float, Float, Float),
        t_hit: Float,
        ray: &Ray,
    ) -> Option<PrimitiveIntersection> {
        let frame = self.triangle_frames.get(prim as usize);
        let (p, i) = self.entries.locate(prim);
        match &self.prims[p] {
            Primitive::Geometric(g) => match &g.shape {
                Shape::Triangle(tri) => Some(PrimitiveIntersection {
                    // One construction path (not a `match` between two
                    // calls), so that the interaction is built in place
                    // instead of copied.
                    si: tri.interaction_at_hit_with_frame(
                        &frame.copied().unwrap_or_else(|| tri.frame()),
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
                // Only triangles are recorded with barycentrics.
                _ => None,
            },
            Primitive::Mesh(m) => {
                let tri = m.triangle(i);
                Some(PrimitiveIntersection {
                    si: tri.interaction_at_hit_with_frame(
                        &frame.copied().unwrap_or_else(|| tri.frame()),
                        b.0,
                        b.1,
                        b.2,
                        ray,
                    ),
                    t_hit,
                    material: m.material,
                    area_light: None,
                    medium_interface: m.medium_interface,
                })
            }
            _ => None,
        }
    }

    /// The hit of entry `e` in (0, t_max) with its interaction.
    fn entry_intersect(&self, e: u32, ray: &Ray, t_max: Float) -> Option<PrimitiveIntersection> {
        let (p, i) = self.entries.locate(e);
        match &self.prims[p] {
            Primitive::Mesh(m) => m.intersect_triangle(i, ray, t_max),
            Primitive::Instances(set) => set.intersect_one(i, ray, t_max),
            prim => prim.intersect(ray, t_max),
        }
    }

    /// The barycentrics and `t` of a hit on entry `e` when it is an opaque
    /// triangle of a mesh (an entry the vertex cache does not hold);
    /// `Err(())` for every other kind of entry.
    #[inline(always)]
    fn mesh_triangle_hit(
        &self,
        e: u32,
        tr: &TriangleRay,
        t_max: Float,
    ) -> Result<Option<(Float, Float, Float, Float)>, ()> {
        let (p, i) = self.entries.locate(e);
        match &self.prims[p] {
            Primitive::Mesh(MeshPrimitive {
                mesh,
                alpha: Alpha::Opaque,
                ..
            }) => {
                let [p0, p1, p2] = mesh.vertices(i as usize);
                if !triangle_is_nondegenerate(p0, p1, p2) {
                    return Ok(None);
                }
                Ok(intersect_prepared_triangle(tr, t_max, p0, p1, p2))
            }
            _ => Err(()),
        }
    }

    /// The test of an entry that is not in the vertex cache, out of line
    /// so that the cached triangle test above inlines into the traversal.
    #[inline(never)]
    fn intersect_other(
        &self,
        i: u32,
        ray: &Ray,
        tr: &TriangleRay,
        t_max: Float,
        closest: &mut Closest,
    ) -> Option<Float> {
        if let Ok(hit) = self.mesh_triangle_hit(i, tr, t_max) {
            let (b0, b1, b2, t_hit) = hit?;
            *closest = Closest::Triangle {
                prim: i,
                b: (b0, b1, b2),
                t_hit,
            };
            return Some(t_hit);
        }
        let pi = self.entry_intersect(i, ray, t_max)?;
        let th = pi.t_hit;
        *closest = Closest::Full(pi);
        Some(th)
    }

    /// [`PrimitiveAggregate::intersect_other`] for
    /// [`PrimitiveAggregate::intersect_record`].
    #[inline(never)]
    fn record_other(&self, i: u32, ray: &Ray, tr: &TriangleRay, t_max: Float) -> Option<HitRecord> {
        if let Ok(hit) = self.mesh_triangle_hit(i, tr, t_max) {
            let (b0, b1, b2, t_hit) = hit?;
            return Some(HitRecord {
                primitive: i,
                t_hit,
                kind: HitKind::Triangle(b0, b1, b2),
            });
        }
        let t_hit = self.entry_intersect(i, ray, t_max)?.t_hit;
        Some(HitRecord {
            primitive: i,
            t_hit,
            kind: HitKind::Other { t_max },
        })
    }

    /// Whether anything is hit in (0, t_max).
    pub fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        let tr = TriangleRay::new(ray);
        self.accel
            .intersect_p_slots(ray, t_max, |slot, i, r, t| self.blocks(slot, i, r, &tr, t))
    }

    /// [`PrimitiveAggregate::intersect_p`] of each of a batch of shadow
    /// rays `(ray, t_max)`, into `out`. With `interleave`, under a wide
    /// BVH too large for a core's cache
    /// ([`PrimitiveAggregate::prefetch_pays`]), the rays are searched a
    /// few at a time, taking turns ([`WideBvh::intersect_ps_stream_at`]):
    /// that pays where the rays end at blockers deep in the tree, whose
    /// nodes are rarely in cache (the water caustic's shadow rays from
    /// under the water: 20% faster), and costs where most rays are
    /// unblocked, seeing mostly the top of the tree, which stays in cache
    /// (the killeroo crop's, 93% unblocked: 20% slower). The answers are
    /// the same either way.
    pub fn intersect_ps(
        &self,
        rays: &[(Ray, Float)],
        level: SimdLevel,
        interleave: bool,
        out: &mut Vec<bool>,
    ) {
        out.clear();
        match &self.accel {
            Accelerator::Bvh4(bvh) if interleave && self.prefetch_pays() => {
                self.intersect_ps_stream(bvh, rays, level, out)
            }
            Accelerator::Bvh8(bvh) if interleave && self.prefetch_pays() => {
                self.intersect_ps_stream(bvh, rays, level, out)
            }
            _ => out.extend(rays.iter().map(|(r, t)| self.intersect_p(r, *t))),
        }
    }

    fn intersect_ps_stream<const W: usize>(
        &self,
        bvh: &WideBvh<W>,
        rays: &[(Ray, Float)],
        level: SimdLevel,
        out: &mut Vec<bool>,
    ) {
        let trs: Vec<TriangleRay> = rays.iter().map(|(r, _)| TriangleRay::new(r)).collect();
        out.resize(rays.len(), false);
        let vertices = &self.triangle_vertices;
        bvh.intersect_ps_stream_at(
            level,
            rays,
            out,
            |k, slot, i, r, t| self.blocks(slot, i, r, &trs[k], t),
            |first, count| {
                let base = vertices.as_ptr().wrapping_add(first as usize);
                for j in 0..count as usize {
                    crate::simd::prefetch_ptr(base.wrapping_add(j));
                }
            },
        );
    }

    /// Whether the entry `i` in slot `slot` blocks `ray` in (0, t_max).
    #[inline(always)]
    fn blocks(&self, slot: u32, i: u32, ray: &Ray, tr: &TriangleRay, t_max: Float) -> bool {
        match self.triangle_vertices.get(slot as usize) {
            Some(Some([p0, p1, p2])) => {
                intersect_prepared_triangle(tr, t_max, *p0, *p1, *p2).is_some()
            }
            _ => self.intersect_p_other(i, ray, tr, t_max),
        }
    }

    /// The shadow test of an entry that is not in the vertex cache.
    #[inline(never)]
    fn intersect_p_other(&self, i: u32, ray: &Ray, tr: &TriangleRay, t_max: Float) -> bool {
        if let Ok(hit) = self.mesh_triangle_hit(i, tr, t_max) {
            return hit.is_some();
        }
        let (p, e) = self.entries.locate(i);
        match &self.prims[p] {
            Primitive::Mesh(m) => m.intersect_p_triangle(e, ray, t_max),
            Primitive::Instances(set) => set.intersect_p_one(e, ray, t_max),
            prim => prim.intersect_p(ray, t_max),
        }
    }
}

#[cfg(test)]
mod tests;
