//! Acceleration structures: the ray–primitive culling of *Physically Based
//! Rendering* chapter 7 (pbrt-v4 section 7.3, bounding volume hierarchies),
//! pbrt-v3 section 4.4 (the SAH kd-tree) and pbrt-v1/v2 section 4.3 (the
//! uniform grid).
//!
//! Every structure here sees only primitive bounding boxes at build time and
//! a *hit closure* at query time (the obvhs style), so none of them knows
//! what a shape is. The closure receives the caller's primitive index, the
//! ray and the current nearest distance `t_max`; for [`Aggregate::intersect`]
//! it returns `Some(t)` with `t < t_max` when the primitive is hit closer, for
//! [`Aggregate::intersect_p`] it returns whether the primitive blocks the ray
//! before `t_max`. The traversal functions are generic over the closure, so
//! the primitive test inlines into the traversal loop; [`Accelerator`] is the
//! closed enum that the scene stores, each method a one-line `match`.
//!
//! Primitives whose bounds contain NaN or an infinity, or are empty, are left
//! out of every structure (they could never be hit reliably) and counted by
//! [`Aggregate::skipped_primitives`]. Coordinates must stay below ~1e38 in
//! magnitude so that box extents are finite in `f32`.

pub mod bvh;
#[cfg(feature = "embree")]
pub mod embree;
pub mod grid;
pub mod kdtree;
pub(crate) mod packet;
mod params;
#[cfg(test)]
mod tests;
mod wide;
pub mod widebvh;

pub use bvh::{Bvh, BvhNode};
#[cfg(feature = "embree")]
pub use embree::{AccelError, EmbreeAccel};
pub use grid::Grid;
pub use kdtree::{KdNode, KdTree};
pub use params::{
    AccelKind, AccelParams, BvhParams, GridParams, KdTreeParams, ParamValue, SplitMethod,
    LARGE_BVH_ENTRIES,
};
pub use widebvh::{Bvh4, Bvh4Node, Bvh8, Bvh8Node, WideBvh, WideNode};

use rpbrt_geometry::{gamma, next_float_down, next_float_up, Bounds3f, Float, Point3f, Ray};

/// The interface shared by every acceleration structure.
///
/// The query methods are generic over the hit closure, so this trait is not
/// object safe on purpose: dispatch goes through [`Accelerator`].
pub trait Aggregate {
    /// The bounds of all the (usable) primitives; empty when there are none.
    fn bounds(&self) -> Bounds3f;

    /// The nearest hit along `ray` in `(0, t_max)`: the primitive index and
    /// its `t`, as reported by `hit`. `hit(prim, ray, t)` must return
    /// `Some(t_hit)` only for `t_hit < t` (it is called with the distance of
    /// the closest hit found so far).
    fn intersect<F>(&self, ray: &Ray, t_max: Float, hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>;

    /// True if any primitive blocks `ray` before `t_max`; stops at the first
    /// primitive for which `hit(prim, ray, t_max)` returns true.
    fn intersect_p<F>(&self, ray: &Ray, t_max: Float, hit: F) -> bool
    where
        F: FnMut(u32, &Ray, Float) -> bool;

    /// [`Aggregate::intersect`], also handing `hit` the entry's slot: where
    /// the structure keeps its entries (see [`Aggregate::slot_entries`]), so
    /// that a caller can store per-entry data in traversal order.
    #[inline(always)]
    fn intersect_slots<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
    {
        self.intersect(ray, t_max, |p, r, t| hit(p, p, r, t))
    }

    /// [`Aggregate::intersect_p`] with slots, as
    /// [`Aggregate::intersect_slots`].
    #[inline(always)]
    fn intersect_p_slots<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> bool
    where
        F: FnMut(u32, u32, &Ray, Float) -> bool,
    {
        self.intersect_p(ray, t_max, |p, r, t| hit(p, p, r, t))
    }

    /// The entry held in each slot, when slots are not the entry indices
    /// themselves (`None`: slot = entry index).
    fn slot_entries(&self) -> Option<&[u32]> {
        None
    }

    /// Heap and inline bytes used by the structure (for `--stats`).
    fn memory_bytes(&self) -> usize;

    /// The number of primitive bounds given at build time.
    fn primitive_count(&self) -> usize;

    /// The number of primitives left out because their bounds were NaN,
    /// infinite or empty.
    fn skipped_primitives(&self) -> usize;
}

/// The closed set of acceleration structures, built from primitive bounds
/// according to [`AccelParams`].
#[derive(Clone, Debug)]
pub enum Accelerator {
    /// A binary bounding volume hierarchy (pbrt-v4 `BVHAggregate`;
    /// `Accelerator "bvh" "integer width" 2`).
    Bvh(Bvh),
    /// The same SAH tree collapsed to 4-wide nodes
    /// (`Accelerator "bvh" "integer width" 4`, and the default for larger
    /// aggregates: see [`BvhParams::width_for`]).
    Bvh4(Bvh4),
    /// The same SAH tree collapsed to 8-wide nodes (`Accelerator "bvh"`,
    /// the default below [`params::LARGE_BVH_ENTRIES`] entries: the fastest
    /// in `benches/accel.rs`).
    Bvh8(Bvh8),
    /// An SAH kd-tree (pbrt-v3 `KdTreeAccel`).
    KdTree(KdTree),
    /// A uniform grid with mailboxing (pbrt-v2 `GridAccel`).
    Grid(Grid),
    /// Embree 3's BVH (`Accelerator "embree"`, cargo feature `embree`):
    /// Embree culls, the hit closure decides.
    #[cfg(feature = "embree")]
    Embree(EmbreeAccel),
}

impl Accelerator {
    /// Builds the structure selected by `params` over `prim_bounds`
    /// (primitive `i` has bounds `prim_bounds[i]`; closures get `i` back).
    pub fn build(prim_bounds: &[Bounds3f], params: &AccelParams) -> Accelerator {
        Accelerator::build_with_threads(prim_bounds, params, default_threads())
    }

    /// [`Accelerator::build`] over `n` primitives whose bounds `bounds`
    /// gives (called once per primitive by the BVH, which never holds the
    /// bounds apart from its build references).
    pub fn build_from<F>(n: usize, bounds: F, params: &AccelParams) -> Accelerator
    where
        F: Fn(u32) -> Bounds3f + Sync,
    {
        Accelerator::build_from_triangles(n, bounds, |_| None, params)
    }

    /// [`Accelerator::build_from`], also told which entries are opaque
    /// triangles that the hit closure tests exactly (`triangle(e)` gives
    /// their vertices): Embree intersects those with its own triangles and
    /// lets the closure refine each candidate; every other structure
    /// ignores `triangle`. If Embree fails to build its scene, the default
    /// BVH is built instead (the scene checks [`embree::available`] first
    /// and warns there).
    pub fn build_from_triangles<F, T>(
        n: usize,
        bounds: F,
        triangle: T,
        params: &AccelParams,
    ) -> Accelerator
    where
        F: Fn(u32) -> Bounds3f + Sync,
        T: Fn(u32) -> Option<[Point3f; 3]>,
    {
        let threads = default_threads();
        #[cfg(feature = "embree")]
        if params.kind == AccelKind::Embree {
            match EmbreeAccel::build(n, &bounds, triangle) {
                Ok(a) => return Accelerator::Embree(a),
                // The default BVH, its width chosen by size as always.
                Err(_) => return Accelerator::build_from(n, bounds, &AccelParams::default()),
            }
        }
        #[cfg(not(feature = "embree"))]
        let _ = triangle;
        let width = params.bvh.width_for(n);
        match params.kind {
            AccelKind::Bvh if width == 2 => {
                Accelerator::Bvh(Bvh::build_from(n, bounds, &params.bvh, threads))
            }
            AccelKind::Bvh if width == 4 => {
                Accelerator::Bvh4(Bvh4::build_from(n, bounds, &params.bvh, threads))
            }
            AccelKind::Bvh => Accelerator::Bvh8(Bvh8::build_from(n, bounds, &params.bvh, threads)),
            _ => {
                let b: Vec<Bounds3f> = (0..n as u32).map(bounds).collect();
                Accelerator::build_with_threads(&b, params, threads)
            }
        }
    }

    /// [`Accelerator::build`] with at most about `threads` build threads
    /// (the BVH builds in parallel; its result does not depend on
    /// `threads`). Embree builds with its device's own thread pool, whatever
    /// `threads`, and holds every entry as user geometry here (see
    /// [`Accelerator::build_from_triangles`] for its triangles).
    pub fn build_with_threads(
        prim_bounds: &[Bounds3f],
        params: &AccelParams,
        threads: usize,
    ) -> Accelerator {
        let width = params.bvh.width_for(prim_bounds.len());
        match params.kind {
            AccelKind::Bvh if width == 2 => {
                Accelerator::Bvh(Bvh::build_with_threads(prim_bounds, &params.bvh, threads))
            }
            AccelKind::Bvh if width == 4 => {
                Accelerator::Bvh4(Bvh4::build_with_threads(prim_bounds, &params.bvh, threads))
            }
            AccelKind::Bvh => {
                Accelerator::Bvh8(Bvh8::build_with_threads(prim_bounds, &params.bvh, threads))
            }
            AccelKind::KdTree => Accelerator::KdTree(KdTree::build(prim_bounds, &params.kdtree)),
            AccelKind::Grid => Accelerator::Grid(Grid::build(prim_bounds, &params.grid)),
            #[cfg(feature = "embree")]
            AccelKind::Embree => {
                match EmbreeAccel::build(prim_bounds.len(), |e| prim_bounds[e as usize], |_| None) {
                    Ok(a) => Accelerator::Embree(a),
                    Err(_) => Accelerator::build_with_threads(
                        prim_bounds,
                        &AccelParams::default(),
                        threads,
                    ),
                }
            }
        }
    }
}

impl Aggregate for Accelerator {
    #[inline]
    fn bounds(&self) -> Bounds3f {
        match self {
            Accelerator::Bvh(a) => a.bounds(),
            Accelerator::Bvh4(a) => a.bounds(),
            Accelerator::Bvh8(a) => a.bounds(),
            Accelerator::KdTree(a) => a.bounds(),
            Accelerator::Grid(a) => a.bounds(),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => a.bounds(),
        }
    }
    #[inline]
    fn intersect<F>(&self, ray: &Ray, t_max: Float, hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>,
    {
        match self {
            Accelerator::Bvh(a) => a.intersect(ray, t_max, hit),
            Accelerator::Bvh4(a) => a.intersect(ray, t_max, hit),
            Accelerator::Bvh8(a) => a.intersect(ray, t_max, hit),
            Accelerator::KdTree(a) => a.intersect(ray, t_max, hit),
            Accelerator::Grid(a) => a.intersect(ray, t_max, hit),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => {
                let mut hit = hit;
                a.intersect(ray, t_max, &mut hit)
            }
        }
    }
    #[inline]
    fn intersect_p<F>(&self, ray: &Ray, t_max: Float, hit: F) -> bool
    where
        F: FnMut(u32, &Ray, Float) -> bool,
    {
        match self {
            Accelerator::Bvh(a) => a.intersect_p(ray, t_max, hit),
            Accelerator::Bvh4(a) => a.intersect_p(ray, t_max, hit),
            Accelerator::Bvh8(a) => a.intersect_p(ray, t_max, hit),
            Accelerator::KdTree(a) => a.intersect_p(ray, t_max, hit),
            Accelerator::Grid(a) => a.intersect_p(ray, t_max, hit),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => {
                let mut hit = hit;
                a.intersect_p(ray, t_max, &mut hit)
            }
        }
    }
    #[inline]
    fn intersect_slots<F>(&self, ray: &Ray, t_max: Float, hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
    {
        match self {
            Accelerator::Bvh(a) => a.intersect_slots(ray, t_max, hit),
            Accelerator::Bvh4(a) => a.intersect_slots(ray, t_max, hit),
            Accelerator::Bvh8(a) => a.intersect_slots(ray, t_max, hit),
            Accelerator::KdTree(a) => a.intersect_slots(ray, t_max, hit),
            Accelerator::Grid(a) => a.intersect_slots(ray, t_max, hit),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => {
                let mut hit = hit;
                a.intersect(ray, t_max, &mut |p, r, t| hit(p, p, r, t))
            }
        }
    }
    #[inline]
    fn intersect_p_slots<F>(&self, ray: &Ray, t_max: Float, hit: F) -> bool
    where
        F: FnMut(u32, u32, &Ray, Float) -> bool,
    {
        match self {
            Accelerator::Bvh(a) => a.intersect_p_slots(ray, t_max, hit),
            Accelerator::Bvh4(a) => a.intersect_p_slots(ray, t_max, hit),
            Accelerator::Bvh8(a) => a.intersect_p_slots(ray, t_max, hit),
            Accelerator::KdTree(a) => a.intersect_p_slots(ray, t_max, hit),
            Accelerator::Grid(a) => a.intersect_p_slots(ray, t_max, hit),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => {
                let mut hit = hit;
                a.intersect_p(ray, t_max, &mut |p, r, t| hit(p, p, r, t))
            }
        }
    }
    fn slot_entries(&self) -> Option<&[u32]> {
        match self {
            Accelerator::Bvh(a) => a.slot_entries(),
            Accelerator::Bvh4(a) => a.slot_entries(),
            Accelerator::Bvh8(a) => a.slot_entries(),
            Accelerator::KdTree(a) => a.slot_entries(),
            Accelerator::Grid(a) => a.slot_entries(),
            #[cfg(feature = "embree")]
            Accelerator::Embree(_) => None,
        }
    }
    fn memory_bytes(&self) -> usize {
        match self {
            Accelerator::Bvh(a) => a.memory_bytes(),
            Accelerator::Bvh4(a) => a.memory_bytes(),
            Accelerator::Bvh8(a) => a.memory_bytes(),
            Accelerator::KdTree(a) => a.memory_bytes(),
            Accelerator::Grid(a) => a.memory_bytes(),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => a.memory_bytes(),
        }
    }
    fn primitive_count(&self) -> usize {
        match self {
            Accelerator::Bvh(a) => a.primitive_count(),
            Accelerator::Bvh4(a) => a.primitive_count(),
            Accelerator::Bvh8(a) => a.primitive_count(),
            Accelerator::KdTree(a) => a.primitive_count(),
            Accelerator::Grid(a) => a.primitive_count(),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => a.primitive_count(),
        }
    }
    fn skipped_primitives(&self) -> usize {
        match self {
            Accelerator::Bvh(a) => a.skipped_primitives(),
            Accelerator::Bvh4(a) => a.skipped_primitives(),
            Accelerator::Bvh8(a) => a.skipped_primitives(),
            Accelerator::KdTree(a) => a.skipped_primitives(),
            Accelerator::Grid(a) => a.skipped_primitives(),
            #[cfg(feature = "embree")]
            Accelerator::Embree(a) => a.skipped_primitives(),
        }
    }
}

/// Why `Accelerator "embree"` falls back to the BVH in a build without the
/// cargo feature `embree`.
#[cfg(not(feature = "embree"))]
pub fn params_no_embree() -> &'static str {
    params::NO_EMBREE
}

/// True for bounds a structure can hold: finite and not empty (zero-size
/// boxes are fine).
#[inline]
pub(crate) fn usable_bounds(b: &Bounds3f) -> bool {
    b.p_min.is_finite() && b.p_max.is_finite() && !b.is_empty()
}

/// The midpoint of a box, computed so that it cannot overflow for huge
/// coordinates.
#[inline]
pub(crate) fn centroid(b: &Bounds3f) -> Point3f {
    Point3f::new(
        0.5 * b.p_min.x + 0.5 * b.p_max.x,
        0.5 * b.p_min.y + 0.5 * b.p_max.y,
        0.5 * b.p_min.z + 0.5 * b.p_max.z,
    )
}

/// Surface area in `f64`: SAH costs multiply extents, which overflow `f32`
/// for coordinates beyond ~1e19.
#[inline]
pub(crate) fn surface_area_f64(b: &Bounds3f) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let dx = b.p_max.x as f64 - b.p_min.x as f64;
    let dy = b.p_max.y as f64 - b.p_min.y as f64;
    let dz = b.p_max.z as f64 - b.p_min.z as f64;
    2.0 * (dx * dy + dx * dz + dy * dz)
}

/// `min` that compiles to one instruction (no NaN fix-up; where NaN can
/// occur it does not matter, see [`RayPrecomp`]).
#[inline(always)]
pub(crate) fn fmin(a: Float, b: Float) -> Float {
    if a < b {
        a
    } else {
        b
    }
}

/// `max` counterpart of [`fmin`].
#[inline(always)]
pub(crate) fn fmax(a: Float, b: Float) -> Float {
    if a > b {
        a
    } else {
        b
    }
}

/// Per-ray values reused by every box test of a traversal.
///
/// For a zero direction component the reciprocal is infinite and the slab
/// test must still say "inside" exactly when `lo ≤ o ≤ hi` (a ray lying in a
/// box face counts as inside, as in [`Bounds3f::intersect_p`]). `o − lo` and
/// `o − hi` may then be zero, giving `0 · ∞ = NaN`; so on such axes the
/// origin used against `lo` is nudged one ulp up and the one used against
/// `hi` one ulp down. A face containing the ray then yields ∓∞, never NaN;
/// NaN remains possible only for a box one ulp off the ray's line, which the
/// ray misses, so whether the test then accepts or rejects is harmless.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayPrecomp {
    pub o: [Float; 3],
    /// The origin compared against boxes' minimum corners.
    pub o_lo: [Float; 3],
    /// The origin compared against boxes' maximum corners.
    pub o_hi: [Float; 3],
    pub inv_dir: [Float; 3],
    /// 1 where the reciprocal direction is negative (−0 counts).
    pub dir_is_neg: [usize; 3],
}

/// The slab test's far distance is grown by this factor so that rounding
/// never culls a box the ray touches (pbrt-v4 section 6.8.7).
#[inline(always)]
pub(crate) fn far_pad() -> Float {
    1.0 + 2.0 * gamma(3)
}

impl RayPrecomp {
    #[inline]
    pub fn new(ray: &Ray) -> RayPrecomp {
        let o = [ray.o.x, ray.o.y, ray.o.z];
        let d = [ray.d.x, ray.d.y, ray.d.z];
        let inv_dir = d.map(|c| 1.0 / c);
        let mut o_lo = o;
        let mut o_hi = o;
        for a in 0..3 {
            if d[a] == 0.0 {
                o_lo[a] = next_float_up(o[a]);
                o_hi[a] = next_float_down(o[a]);
            }
        }
        RayPrecomp {
            o,
            o_lo,
            o_hi,
            inv_dir,
            dir_is_neg: inv_dir.map(|c| (c < 0.0) as usize),
        }
    }

    /// The parametric range `[t0, t1]` of the ray inside the box `lo..hi`,
    /// clipped to `[0, t_max]`, or `None`.
    #[inline(always)]
    pub fn slab(&self, lo: &[Float; 3], hi: &[Float; 3], t_max: Float) -> Option<(Float, Float)> {
        let mut t0: Float = 0.0;
        let mut t1 = t_max;
        let pad = far_pad();
        for a in 0..3 {
            let ta = (lo[a] - self.o_lo[a]) * self.inv_dir[a];
            let tb = (hi[a] - self.o_hi[a]) * self.inv_dir[a];
            t0 = fmax(t0, fmin(ta, tb));
            t1 = fmin(t1, fmax(ta, tb) * pad);
        }
        if t0 <= t1 {
            Some((t0, t1))
        } else {
            None
        }
    }

    /// True when the ray overlaps the box `lo..hi` within `[0, t_max]`.
    #[inline(always)]
    pub fn hits(&self, lo: &[Float; 3], hi: &[Float; 3], t_max: Float) -> bool {
        let pad = far_pad();
        let tx0 = (lo[0] - self.o_lo[0]) * self.inv_dir[0];
        let tx1 = (hi[0] - self.o_hi[0]) * self.inv_dir[0];
        let ty0 = (lo[1] - self.o_lo[1]) * self.inv_dir[1];
        let ty1 = (hi[1] - self.o_hi[1]) * self.inv_dir[1];
        let tz0 = (lo[2] - self.o_lo[2]) * self.inv_dir[2];
        let tz1 = (hi[2] - self.o_hi[2]) * self.inv_dir[2];
        let near = fmax(
            fmax(fmin(tx0, tx1), fmin(ty0, ty1)),
            fmax(fmin(tz0, tz1), 0.0),
        );
        let far = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmax(tz0, tz1)) * pad;
        near <= fmin(far, t_max)
    }
}

/// The default number of build threads: the machine's parallelism, asked
/// once (on Linux the question reads cgroup files, and a scene of many
/// animated shapes or object definitions builds an aggregate for each).
pub(crate) fn default_threads() -> usize {
    static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *THREADS.get_or_init(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    })
}
