//! Wide BVHs, 4 and 8 children per node (pbrt-v4 section 7.3 builds the
//! binary tree; the wide layout follows Wald et al., "Getting Rid of
//! Packets", 2008, and Embree's BVH4 and BVH8): the SAH binary tree of
//! [`Bvh`] collapsed so that every node holds up to `W` children whose
//! boxes are tested together.
//!
//! A node stores its children's boxes structure-of-arrays (one `[f32; W]`
//! per box plane), so the slab test of all its children is a handful of
//! lane operations ([`crate::simd::F32Lanes`]): the traversals run inside
//! [`crate::simd::dispatch`], and test a node's boxes a whole vector at a
//! time (the 8-wide tree's eight with one AVX2 instruction per step, or two
//! SSE ones; the 4-wide tree's four with one SSE instruction). Left to the
//! compiler, the same loops came out as a mix of scalar and partial vector
//! code with a long shuffle chain for the mask. Per ray, the near and far
//! plane of each axis are chosen
//! once by the direction's sign, so the slab test needs no per-axis min/max.
//! Leaf children are intersected as soon as their box is hit; interior
//! children are pushed far to near with their entry distance, and popped
//! entries that lie beyond the closest hit found so far are dropped.
//!
//! Collapsing is sequential, cheap, and a pure function of the binary tree,
//! which is itself independent of the build thread count, so the wide tree
//! is deterministic too.

use super::bvh::{Bvh, BvhNode, STACK_SIZE};
use super::params::BvhParams;
use super::{far_pad, Aggregate};
use crate::simd::{F32Lanes, Kernel};
use rpbrt_geometry::{next_float_down, next_float_up, Bounds3f, Float, Ray};
use std::mem::MaybeUninit;

/// One node of a `W`-wide BVH: `W` child boxes in structure-of-arrays form
/// and their references; 128 bytes (two cache lines, aligned) for `W = 4`,
/// 256 for `W = 8`.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode<const W: usize> {
    /// Child box planes: `[min_x, min_y, min_z, max_x, max_y, max_z]`, each
    /// with one lane per child. Unused lanes hold an inverted box
    /// (`min = +∞`, `max = −∞`) that no ray can hit.
    pub bounds: [[Float; W]; 6],
    /// Interior child: its node index. Leaf child: its first entry in the
    /// primitive index array.
    pub child: [u32; W],
    /// Leaf child: its primitive count; 0 for interior children and unused
    /// lanes.
    pub count: [u16; W],
    /// Bit `i` set when lane `i` is a leaf child (nonzero count).
    pub leaf_lanes: u32,
    /// Padding (the alignment rounds the size up to whole cache lines).
    pub pad: u32,
}

/// A node of the 4-wide BVH.
pub type Bvh4Node = WideNode<4>;
/// A node of the 8-wide BVH.
pub type Bvh8Node = WideNode<8>;

impl<const W: usize> WideNode<W> {
    /// A node with every lane unused.
    pub(super) fn empty() -> WideNode<W> {
        let inf = Float::INFINITY;
        WideNode {
            bounds: [
                [inf; W], [inf; W], [inf; W], [-inf; W], [-inf; W], [-inf; W],
            ],
            child: [0; W],
            count: [0; W],
            leaf_lanes: 0,
            pad: 0,
        }
    }

    fn set_bounds(&mut self, lane: usize, b: &BvhNode) {
        for a in 0..3 {
            self.bounds[a][lane] = b.bounds_min[a];
            self.bounds[3 + a][lane] = b.bounds_max[a];
        }
    }

    /// The box of child `lane` (inverted for unused lanes).
    pub fn child_bounds(&self, lane: usize) -> Bounds3f {
        let b = &self.bounds;
        Bounds3f {
            p_min: rpbrt_geometry::Point3f::new(b[0][lane], b[1][lane], b[2][lane]),
            p_max: rpbrt_geometry::Point3f::new(b[3][lane], b[4][lane], b[5][lane]),
        }
    }
}

/// A `W`-wide BVH over primitive bounds.
#[derive(Clone, Debug, Default)]
pub struct WideBvh<const W: usize> {
    nodes: Vec<WideNode<W>>,
    prim_indices: Vec<u32>,
    bounds: Bounds3f,
    n_input: usize,
    n_skipped: usize,
}

/// The 4-wide BVH (the default where the processor lacks AVX2).
pub type Bvh4 = WideBvh<4>;
/// The 8-wide BVH.
pub type Bvh8 = WideBvh<8>;

/// Surface area of a binary node (for choosing which child to open).
fn node_area(n: &BvhNode) -> f64 {
    super::surface_area_f64(&n.bounds())
}

/// Appends the wide node for binary interior node `bin` and, depth first,
/// its descendants; returns its index.
fn collapse<const W: usize>(bin: &[BvhNode], root: usize, out: &mut Vec<WideNode<W>>) -> u32 {
    // Open the largest interior child until there are `W` children.
    let mut kids: Vec<usize> = vec![root + 1, bin[root].offset as usize];
    while kids.len() < W {
        let mut best: Option<(usize, f64)> = None;
        for (i, &k) in kids.iter().enumerate() {
            if !bin[k].is_leaf() {
                let a = node_area(&bin[k]);
                if best.is_none_or(|(_, ba)| a > ba) {
                    best = Some((i, a));
                }
            }
        }
        let Some((i, _)) = best else { break };
        let k = kids[i];
        // Keep the binary order (near child first along the split axis).
        kids.splice(i..=i, [k + 1, bin[k].offset as usize]);
    }
    let me = out.len();
    out.push(WideNode::empty());
    for (lane, &k) in kids.iter().enumerate() {
        let n = &bin[k];
        out[me].set_bounds(lane, n);
        if n.is_leaf() {
            out[me].child[lane] = n.offset;
            out[me].count[lane] = n.count;
            if n.count > 0 {
                out[me].leaf_lanes |= 1 << lane;
            }
        } else {
            let c = collapse(bin, k, out);
            out[me].child[lane] = c;
        }
    }
    me as u32
}

/// Per-ray state for the wide slab test: the near and far plane rows of
/// each axis (chosen by the direction's sign) and the matching origins.
struct WideRay {
    near: [usize; 3],
    far: [usize; 3],
    o_near: [Float; 3],
    o_far: [Float; 3],
    inv: [Float; 3],
    /// `inv` times [`far_pad`]: the far distances' padding folded into
    /// their factor (one rounding more, which the pad's `2γ₃` covers, so
    /// the test stays conservative).
    inv_far: [Float; 3],
}

impl WideRay {
    #[inline(always)]
    fn new(ray: &Ray) -> WideRay {
        let o = [ray.o.x, ray.o.y, ray.o.z];
        let d = [ray.d.x, ray.d.y, ray.d.z];
        let mut w = WideRay {
            near: [0, 1, 2],
            far: [3, 4, 5],
            o_near: o,
            o_far: o,
            inv: [0.0; 3],
            inv_far: [0.0; 3],
        };
        for a in 0..3 {
            let inv = 1.0 / d[a];
            w.inv[a] = inv;
            w.inv_far[a] = inv * far_pad();
            // A negative direction (−0 included) enters through the max
            // plane. Selected, not branched on: the signs of a ray's
            // direction are as good as random. (Only integers: a select
            // between floats becomes a branch on x86-64.)
            let neg = inv < 0.0;
            let sel = std::hint::select_unpredictable;
            w.near[a] = sel(neg, 3 + a, a);
            w.far[a] = sel(neg, a, 3 + a);
            if d[a] == 0.0 {
                // Zero components (rare, so this branch predicts well):
                // the nudged origins of `RayPrecomp` (lo planes against an
                // origin one ulp up, hi planes one ulp down) so that a ray
                // lying in a face counts as inside. Elsewhere both planes
                // use the origin itself.
                let (o_lo, o_hi) = (next_float_up(o[a]), next_float_down(o[a]));
                w.o_near[a] = if neg { o_hi } else { o_lo };
                w.o_far[a] = if neg { o_lo } else { o_hi };
            }
        }
        w
    }
}

/// A [`WideRay`]'s values splatted over lanes `L`, for the slab test of
/// `L::N` children at a time.
struct LaneRay<L: F32Lanes> {
    near: [usize; 3],
    far: [usize; 3],
    o_near: [L; 3],
    o_far: [L; 3],
    inv: [L; 3],
    inv_far: [L; 3],
}

impl<L: F32Lanes> LaneRay<L> {
    #[inline(always)]
    fn new(w: &WideRay) -> LaneRay<L> {
        LaneRay {
            near: w.near,
            far: w.far,
            o_near: w.o_near.map(L::splat),
            o_far: w.o_far.map(L::splat),
            inv: w.inv.map(L::splat),
            inv_far: w.inv_far.map(L::splat),
        }
    }

    /// Entry distances of the node's children and the mask of those the
    /// ray overlaps within `[0, t_max]`, `L::N` children per instruction
    /// (`W` is a multiple of `L::N`). Each lane computes what the scalar
    /// slab test computes, in the same order (`max` and `min` keep the
    /// scalar operand order, so NaNs resolve the same way): the masks and
    /// distances are bit-identical at every width.
    #[inline(always)]
    fn test<const W: usize>(&self, node: &WideNode<W>, t_max: Float) -> ([Float; W], u32) {
        debug_assert_eq!(W % L::N, 0);
        let b = &node.bounds;
        let mut t0 = [0.0 as Float; W];
        let mut mask = 0u32;
        let tm = L::splat(t_max);
        let mut k = 0;
        while k < W {
            let mut near = L::splat(0.0);
            let mut far = tm;
            for a in 0..3 {
                let n = L::load(&b[self.near[a]][k..]);
                let f = L::load(&b[self.far[a]][k..]);
                near = near.max(n.sub(self.o_near[a]).mul(self.inv[a]));
                far = far.min(f.sub(self.o_far[a]).mul(self.inv_far[a]));
            }
            near.store(&mut t0[k..]);
            mask |= L::bits(near.le(far)) << k;
            k += L::N;
        }
        (t0, mask)
    }
}

/// Enough for any tree of up to 8 children: at most seven entries are
/// pushed per level and the binary tree (hence the wide one) is at most
/// `STACK_SIZE` deep.
const WIDE_STACK: usize = 7 * STACK_SIZE + 1;

/// A traversal stack that is not zero-filled per ray.
struct Stack<T: Copy> {
    items: [MaybeUninit<T>; WIDE_STACK],
    len: usize,
}

impl<T: Copy> Stack<T> {
    #[inline(always)]
    fn new() -> Self {
        Stack {
            items: [const { MaybeUninit::uninit() }; WIDE_STACK],
            len: 0,
        }
    }
    #[inline(always)]
    fn push(&mut self, v: T) {
        // Bounds-checked: a malformed tree panics instead of corrupting.
        self.items[self.len] = MaybeUninit::new(v);
        self.len += 1;
    }
    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every slot below `len` was written by `push` (slots are
        // only ever written in order 0, 1, ... and `len` counts them).
        Some(unsafe { self.items[self.len].assume_init() })
    }
}

impl<const W: usize> WideBvh<W> {
    /// Starts loading the nodes of the interior children in `mask`: their
    /// loads overlap the leaf tests and box tests before they are visited
    /// (large trees do not fit in cache).
    #[inline(always)]
    pub(super) fn prefetch_children(&self, node: &WideNode<W>, mask: u32) {
        let mut inner = mask & !node.leaf_lanes;
        let base = self.nodes.as_ptr();
        while inner != 0 {
            let i = inner.trailing_zeros() as usize;
            inner &= inner - 1;
            // An address, not a reference: a prefetch never faults, so the
            // index needs no bounds check (the visit that follows has one).
            crate::simd::prefetch_ptr(base.wrapping_add(node.child[i] as usize));
        }
    }

    /// Builds over `prim_bounds` with all available cores.
    pub fn build(prim_bounds: &[Bounds3f], params: &BvhParams) -> WideBvh<W> {
        WideBvh::build_with_threads(prim_bounds, params, super::default_threads())
    }

    /// Builds with at most about `threads` threads; the result is the same
    /// for every thread count.
    pub fn build_with_threads(
        prim_bounds: &[Bounds3f],
        params: &BvhParams,
        threads: usize,
    ) -> WideBvh<W> {
        WideBvh::build_from(
            prim_bounds.len(),
            |i| prim_bounds[i as usize],
            params,
            threads,
        )
    }

    /// [`WideBvh::build_with_threads`] over `n` primitives whose bounds
    /// `bounds` gives, called once per primitive. The tree is the one
    /// [`WideBvh::from_binary`] makes of the binary BVH, built without the
    /// binary tree in between (`wide.rs`), except for HLBVH.
    pub fn build_from<F>(n: usize, bounds: F, params: &BvhParams, threads: usize) -> WideBvh<W>
    where
        F: Fn(u32) -> Bounds3f + Sync,
    {
        if params.split_method == super::SplitMethod::Hlbvh {
            WideBvh::from_binary(Bvh::build_from(n, bounds, params, threads))
        } else {
            super::wide::build(n, bounds, params, threads)
        }
    }

    /// A tree from its parts (for the direct builder).
    pub(super) fn from_parts(
        nodes: Vec<WideNode<W>>,
        prim_indices: Vec<u32>,
        bounds: Bounds3f,
        n_input: usize,
        n_skipped: usize,
    ) -> WideBvh<W> {
        WideBvh {
            nodes,
            prim_indices,
            bounds,
            n_input,
            n_skipped,
        }
    }

    /// Collapses a binary BVH into a `W`-wide one (same leaves, same
    /// primitive order).
    pub fn from_binary(bin: Bvh) -> WideBvh<W> {
        let bounds = bin.bounds();
        let n_input = bin.primitive_count();
        let n_skipped = bin.skipped_primitives();
        let (bnodes, prim_indices) = bin.into_parts();
        let mut nodes = Vec::with_capacity(bnodes.len() / 2 + 1);
        if let Some(root) = bnodes.first() {
            if root.is_leaf() {
                let mut n = WideNode::empty();
                n.set_bounds(0, root);
                n.child[0] = root.offset;
                n.count[0] = root.count;
                n.leaf_lanes = u32::from(root.count > 0);
                nodes.push(n);
            } else {
                collapse(&bnodes, 0, &mut nodes);
            }
        }
        nodes.shrink_to_fit();
        WideBvh {
            nodes,
            prim_indices,
            bounds,
            n_input,
            n_skipped,
        }
    }

    /// The nodes (root first; empty when there are no primitives).
    pub fn nodes(&self) -> &[WideNode<W>] {
        &self.nodes
    }

    /// Caller primitive indices in leaf order: a leaf child covers
    /// `prim_indices()[child..child + count]`.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }
}

impl<const W: usize> WideBvh<W> {
    /// [`Aggregate::intersect_slots`] compiled for `level` (the 8-wide
    /// tree's single-ray traversal, whose eight box tests a node become
    /// 8-lane instructions at AVX2; the wide tree's hits are the same at
    /// every level).
    #[inline]
    pub fn intersect_slots_at<F>(
        &self,
        level: crate::simd::SimdLevel,
        ray: &Ray,
        t_max: Float,
        hit: F,
    ) -> Option<(u32, Float)>
    where
        F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
    {
        let k = Closest {
            bvh: self,
            ray,
            t_max,
            hit,
        };
        crate::simd::dispatch(level, k)
    }

    /// [`Aggregate::intersect_p_slots`] compiled for `level` (as
    /// [`WideBvh::intersect_slots_at`]).
    #[inline]
    pub fn intersect_p_slots_at<F>(
        &self,
        level: crate::simd::SimdLevel,
        ray: &Ray,
        t_max: Float,
        hit: F,
    ) -> bool
    where
        F: FnMut(u32, u32, &Ray, Float) -> bool,
    {
        let k = Any {
            bvh: self,
            ray,
            t_max,
            hit,
        };
        crate::simd::dispatch(level, k)
    }

    /// [`Aggregate::intersect_slots`], compiled for the caller's
    /// instruction set, testing boxes `L::N` at a time.
    #[inline(always)]
    fn closest_slots<L: F32Lanes, F>(
        &self,
        ray: &Ray,
        t_max: Float,
        mut hit: F,
    ) -> Option<(u32, Float)>
    where
        F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
    {
        if self.nodes.is_empty() {
            return None;
        }
        let w = LaneRay::<L>::new(&WideRay::new(ray));
        let mut t_max = t_max;
        let mut best = None;
        let mut stack: Stack<(u32, Float)> = Stack::new();
        let mut cur = 0u32;
        loop {
            let node = &self.nodes[cur as usize];
            let (t0, mask) = w.test(node, t_max);
            self.prefetch_children(node, mask);
            // Leaf children first, in lane order: each tests its primitives
            // against the shrinking `t_max`, so their order does not change
            // which are tested, and not sorting them saves branches on
            // which children a ray happens to hit.
            let mut leaves = mask & node.leaf_lanes;
            while leaves != 0 {
                let i = leaves.trailing_zeros() as usize;
                leaves &= leaves - 1;
                let start = node.child[i] as usize;
                let c = node.count[i] as usize;
                closest_in_leaf(
                    &self.prim_indices[start..start + c],
                    start as u32,
                    ray,
                    &mut t_max,
                    &mut best,
                    &mut hit,
                );
            }
            let next = nearest_child(node, mask & !node.leaf_lanes, &t0, t_max, &mut stack);
            match next {
                Some((c, _)) => cur = c,
                None => loop {
                    match stack.pop() {
                        None => return best,
                        Some((c, tn)) if tn <= t_max => {
                            cur = c;
                            break;
                        }
                        Some(_) => {}
                    }
                },
            }
        }
    }

    /// [`Aggregate::intersect_p_slots`], compiled for the caller's
    /// instruction set, testing boxes `L::N` at a time.
    #[inline(always)]
    fn any_slots<L: F32Lanes, F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> bool
    where
        F: FnMut(u32, u32, &Ray, Float) -> bool,
    {
        if self.nodes.is_empty() {
            return false;
        }
        let w = LaneRay::<L>::new(&WideRay::new(ray));
        let mut stack: Stack<u32> = Stack::new();
        let mut cur = 0u32;
        loop {
            let node = &self.nodes[cur as usize];
            let (_, mut mask) = w.test(node, t_max);
            self.prefetch_children(node, mask);
            let mut next: Option<u32> = None;
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = node.count[i];
                if c > 0 {
                    let start = node.child[i] as usize;
                    for (k, &p) in self.prim_indices[start..start + c as usize]
                        .iter()
                        .enumerate()
                    {
                        if hit((start + k) as u32, p, ray, t_max) {
                            return true;
                        }
                    }
                } else {
                    if let Some(prev) = next {
                        stack.push(prev);
                    }
                    next = Some(node.child[i]);
                }
            }
            match next.or_else(|| stack.pop()) {
                Some(c) => cur = c,
                None => return false,
            }
        }
    }
}

/// No node.
const NO_NODE: u32 = u32::MAX;

/// Rays in flight at once in [`WideBvh::intersect_ps_stream_at`].
/// (4 and 16 were slower on the water caustic's shadow rays; one ray at
/// a time through this loop was 48% slower than the single-ray search.)
const STREAM: usize = 8;

/// One ray in flight of an interleaved any-hit search.
struct AnyTrack<L: F32Lanes> {
    /// Its index in the batch; `usize::MAX` when the track is free.
    ray: usize,
    w: LaneRay<L>,
    /// The node to visit on its next turn (prefetched); `NO_NODE` when
    /// none is left.
    cur: u32,
    /// Leaf children of node `leaf_node` whose primitives its next turn
    /// tests first (their data prefetched).
    leaves: u32,
    leaf_node: u32,
    stack: Stack<u32>,
}

impl<const W: usize> WideBvh<W> {
    /// [`WideBvh::intersect_p_slots_at`] of each ray `(ray, t_max)` of
    /// `rays`, into `out` (as long): the same answers. A few rays are
    /// searched at once, taking turns: each turn visits one node of one
    /// ray (and tests the leaves its previous node found), having
    /// prefetched that node and those leaves' data (`prefetch(first
    /// slot, count)`) on the ray's previous turn, so that other rays'
    /// work hides the memory latency of each (the tree of a large scene
    /// does not fit in a core's cache). `hit(ray index, slot, primitive,
    /// ray, t_max)` decides each candidate.
    pub fn intersect_ps_stream_at<F, P>(
        &self,
        level: crate::simd::SimdLevel,
        rays: &[(Ray, Float)],
        out: &mut [bool],
        hit: F,
        prefetch: P,
    ) where
        F: FnMut(usize, u32, u32, &Ray, Float) -> bool,
        P: Fn(u32, u32),
    {
        let k = AnyStream {
            bvh: self,
            rays,
            out,
            hit,
            prefetch,
        };
        crate::simd::dispatch(level, k)
    }

    #[inline(always)]
    fn any_stream<L: F32Lanes, F, P>(
        &self,
        rays: &[(Ray, Float)],
        out: &mut [bool],
        mut hit: F,
        prefetch: P,
    ) where
        F: FnMut(usize, u32, u32, &Ray, Float) -> bool,
        P: Fn(u32, u32),
    {
        debug_assert_eq!(rays.len(), out.len());
        out.fill(false);
        if self.nodes.is_empty() {
            return;
        }
        let blank = WideRay::new(&Ray::default());
        let mut tracks: [AnyTrack<L>; STREAM] = std::array::from_fn(|_| AnyTrack {
            ray: usize::MAX,
            w: LaneRay::new(&blank),
            cur: NO_NODE,
            leaves: 0,
            leaf_node: 0,
            stack: Stack::new(),
        });
        let mut next_ray = 0;
        loop {
            let mut busy = false;
            for t in tracks.iter_mut() {
                if t.ray == usize::MAX {
                    if next_ray == rays.len() {
                        continue;
                    }
                    t.ray = next_ray;
                    next_ray += 1;
                    t.w = LaneRay::new(&WideRay::new(&rays[t.ray].0));
                    t.cur = 0;
                    t.leaves = 0;
                    t.stack.len = 0;
                }
                busy = true;
                if let Some(blocked) = self.any_turn(t, rays, &mut hit, &prefetch) {
                    out[t.ray] = blocked;
                    t.ray = usize::MAX;
                }
            }
            if !busy {
                return;
            }
        }
    }

    /// One turn of track `t`: its pending leaves, then its node. The
    /// answer once the ray's search is over.
    #[inline(always)]
    fn any_turn<L: F32Lanes, F, P>(
        &self,
        t: &mut AnyTrack<L>,
        rays: &[(Ray, Float)],
        hit: &mut F,
        prefetch: &P,
    ) -> Option<bool>
    where
        F: FnMut(usize, u32, u32, &Ray, Float) -> bool,
        P: Fn(u32, u32),
    {
        let (ray, t_max) = (&rays[t.ray].0, rays[t.ray].1);
        if t.leaves != 0 {
            let node = &self.nodes[t.leaf_node as usize];
            let mut leaves = t.leaves;
            t.leaves = 0;
            while leaves != 0 {
                let i = leaves.trailing_zeros() as usize;
                leaves &= leaves - 1;
                let start = node.child[i] as usize;
                let c = node.count[i] as usize;
                for (k, &p) in self.prim_indices[start..start + c].iter().enumerate() {
                    if hit(t.ray, (start + k) as u32, p, ray, t_max) {
                        return Some(true);
                    }
                }
            }
        }
        if t.cur == NO_NODE {
            return Some(false);
        }
        let node = &self.nodes[t.cur as usize];
        let (_, mask) = t.w.test(node, t_max);
        let leaves = mask & node.leaf_lanes;
        if leaves != 0 {
            t.leaves = leaves;
            t.leaf_node = t.cur;
            let mut l = leaves;
            while l != 0 {
                let i = l.trailing_zeros() as usize;
                l &= l - 1;
                let start = node.child[i];
                crate::simd::prefetch_ptr(self.prim_indices.as_ptr().wrapping_add(start as usize));
                prefetch(start, node.count[i] as u32);
            }
        }
        let mut inner = mask & !node.leaf_lanes;
        let mut next = NO_NODE;
        while inner != 0 {
            let i = inner.trailing_zeros() as usize;
            inner &= inner - 1;
            if next != NO_NODE {
                t.stack.push(next);
            }
            next = node.child[i];
        }
        t.cur = if next != NO_NODE {
            next
        } else {
            t.stack.pop().unwrap_or(NO_NODE)
        };
        if t.cur != NO_NODE {
            crate::simd::prefetch_ptr(self.nodes.as_ptr().wrapping_add(t.cur as usize));
        } else if t.leaves == 0 {
            return Some(false);
        }
        None
    }
}

/// A batch's interleaved any-hit searches as a [`Kernel`].
struct AnyStream<'a, const W: usize, F, P> {
    bvh: &'a WideBvh<W>,
    rays: &'a [(Ray, Float)],
    out: &'a mut [bool],
    hit: F,
    prefetch: P,
}

impl<const W: usize, F, P> Kernel for AnyStream<'_, W, F, P>
where
    F: FnMut(usize, u32, u32, &Ray, Float) -> bool,
    P: Fn(u32, u32),
{
    type Output = ();
    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let (b, r, o, h, p) = (self.bvh, self.rays, self.out, self.hit, self.prefetch);
        if W >= L::N {
            b.any_stream::<L, F, P>(r, o, h, p)
        } else if W >= <L::Eight as F32Lanes>::N {
            b.any_stream::<L::Eight, F, P>(r, o, h, p)
        } else {
            b.any_stream::<L::Four, F, P>(r, o, h, p)
        }
    }
}

/// Of the interior children in `inner` (lanes of `node` whose boxes the
/// ray entered at `t0`), those entered by `t_max`: the nearest is
/// returned, to be visited next, and the others pushed far to near.
#[inline(always)]
fn nearest_child<const W: usize>(
    node: &WideNode<W>,
    mut inner: u32,
    t0: &[Float; W],
    t_max: Float,
    stack: &mut Stack<(u32, Float)>,
) -> Option<(u32, Float)> {
    if inner == 0 {
        return None;
    }
    if inner & (inner - 1) == 0 {
        // One interior child hit (the common case): no ordering.
        let i = inner.trailing_zeros() as usize;
        return (t0[i] <= t_max).then(|| (node.child[i], t0[i]));
    }
    let i = inner.trailing_zeros() as usize;
    let rest = inner & (inner - 1);
    if rest & (rest - 1) == 0 {
        // Two (the next most common): the nearer (the lower lane on a
        // tie, as the sort below orders them) is visited next, the other
        // pushed.
        let j = rest.trailing_zeros() as usize;
        let (a, b) = if t0[j] < t0[i] { (j, i) } else { (i, j) };
        if t0[a] > t_max {
            return None;
        }
        if t0[b] <= t_max {
            stack.push((node.child[b], t0[b]));
        }
        return Some((node.child[a], t0[a]));
    }
    // Hit interior children sorted near to far (at most `W`: insertion
    // sort).
    let mut order = [(0usize, 0.0 as Float); W];
    let mut n = 0;
    while inner != 0 {
        let i = inner.trailing_zeros() as usize;
        inner &= inner - 1;
        let mut j = n;
        while j > 0 && order[j - 1].1 > t0[i] {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = (i, t0[i]);
        n += 1;
    }
    let mut next = None;
    for &(i, tn) in order[..n].iter().rev() {
        if tn <= t_max {
            if let Some(prev) = next {
                stack.push(prev);
            }
            next = Some((node.child[i], tn));
        }
    }
    next
}

impl<const W: usize> Aggregate for WideBvh<W> {
    fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    #[inline]
    fn intersect<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>,
    {
        self.intersect_slots(ray, t_max, |_, p, r, t| hit(p, r, t))
    }

    #[inline]
    fn intersect_p<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> bool
    where
        F: FnMut(u32, &Ray, Float) -> bool,
    {
        self.intersect_p_slots(ray, t_max, |_, p, r, t| hit(p, r, t))
    }

    /// Slots are positions in [`WideBvh::prim_indices`] (leaf order).
    fn slot_entries(&self) -> Option<&[u32]> {
        Some(&self.prim_indices)
    }

    #[inline]
    fn intersect_slots<F>(&self, ray: &Ray, t_max: Float, hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
    {
        self.intersect_slots_at(crate::simd::level(), ray, t_max, hit)
    }

    #[inline]
    fn intersect_p_slots<F>(&self, ray: &Ray, t_max: Float, hit: F) -> bool
    where
        F: FnMut(u32, u32, &Ray, Float) -> bool,
    {
        self.intersect_p_slots_at(crate::simd::level(), ray, t_max, hit)
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            // Nodes written (a directly built tree reserves more address
            // space than it uses; the untouched tail is not memory).
            + self.nodes.len() * std::mem::size_of::<WideNode<W>>()
            + self.prim_indices.capacity() * 4
    }

    fn primitive_count(&self) -> usize {
        self.n_input
    }

    fn skipped_primitives(&self) -> usize {
        self.n_skipped
    }
}

/// One ray's closest hit as a [`Kernel`] (run at the processor's level).
struct Closest<'a, const W: usize, F> {
    bvh: &'a WideBvh<W>,
    ray: &'a Ray,
    t_max: Float,
    hit: F,
}

impl<const W: usize, F> Kernel for Closest<'_, W, F>
where
    F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
{
    type Output = Option<(u32, Float)>;
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> Self::Output {
        // Boxes a whole vector at a time: the 8-wide tree at 16 lanes
        // takes the level's 8-lane vectors, the 4-wide tree at 8 or 16
        // its 4-lane ones.
        if W >= L::N {
            self.bvh
                .closest_slots::<L, F>(self.ray, self.t_max, self.hit)
        } else if W >= <L::Eight as F32Lanes>::N {
            self.bvh
                .closest_slots::<L::Eight, F>(self.ray, self.t_max, self.hit)
        } else {
            self.bvh
                .closest_slots::<L::Four, F>(self.ray, self.t_max, self.hit)
        }
    }
}

/// One ray's any-hit test as a [`Kernel`].
struct Any<'a, const W: usize, F> {
    bvh: &'a WideBvh<W>,
    ray: &'a Ray,
    t_max: Float,
    hit: F,
}

impl<const W: usize, F> Kernel for Any<'_, W, F>
where
    F: FnMut(u32, u32, &Ray, Float) -> bool,
{
    type Output = bool;
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> bool {
        if W >= L::N {
            self.bvh.any_slots::<L, F>(self.ray, self.t_max, self.hit)
        } else if W >= <L::Eight as F32Lanes>::N {
            self.bvh
                .any_slots::<L::Eight, F>(self.ray, self.t_max, self.hit)
        } else {
            self.bvh
                .any_slots::<L::Four, F>(self.ray, self.t_max, self.hit)
        }
    }
}

/// Tests the primitives of one leaf (the first in slot `first`),
/// shrinking `t_max` on each closer hit.
#[inline(always)]
pub(super) fn closest_in_leaf<F>(
    prims: &[u32],
    first: u32,
    ray: &Ray,
    t_max: &mut Float,
    best: &mut Option<(u32, Float)>,
    hit: &mut F,
) where
    F: FnMut(u32, u32, &Ray, Float) -> Option<Float>,
{
    for (k, &p) in prims.iter().enumerate() {
        if let Some(t) = hit(first + k as u32, p, ray, *t_max) {
            debug_assert!(t <= *t_max);
            *t_max = t;
            *best = Some((p, t));
        }
    }
}
