//! Bounding volume hierarchies (pbrt-v4 section 7.3): a binary BVH built by
//! binned SAH, HLBVH, middle or equal-count splits, flattened into 32-byte
//! nodes laid out depth first (the first child follows its parent), and
//! traversed front to back by the ray direction's signs.
//!
//! Construction is parallel with `std::thread::scope` on the top levels (no
//! extra dependency) and deterministic: subtrees are built into their own
//! node vectors and spliced in a fixed order, so the node array does not
//! depend on the thread count (pbrt-v4's leaf order does).

use super::params::{BvhParams, SplitMethod};
use super::{centroid, surface_area_f64, usable_bounds, Aggregate, RayPrecomp};
use rpbrt_geometry::{encode_morton3, Bounds3f, Float, Point3f, Ray};

/// One node of the flattened BVH (pbrt-v4 `LinearBVHNode`), 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    /// Minimum corner of the node's bounds.
    pub bounds_min: [Float; 3],
    /// Maximum corner of the node's bounds.
    pub bounds_max: [Float; 3],
    /// Leaf: first entry in the primitive index array; interior: index of
    /// the second child (the first child is the next node).
    pub offset: u32,
    /// Primitives in a leaf; 0 marks an interior node.
    pub count: u16,
    /// Interior: the split axis (0, 1, 2).
    pub axis: u8,
    /// Padding to 32 bytes.
    pub pad: u8,
}

impl BvhNode {
    fn leaf(b: &Bounds3f, offset: u32, count: u16) -> BvhNode {
        BvhNode {
            bounds_min: [b.p_min.x, b.p_min.y, b.p_min.z],
            bounds_max: [b.p_max.x, b.p_max.y, b.p_max.z],
            offset,
            count,
            axis: 0,
            pad: 0,
        }
    }
    /// The node's bounds.
    pub fn bounds(&self) -> Bounds3f {
        Bounds3f {
            p_min: Point3f::new(self.bounds_min[0], self.bounds_min[1], self.bounds_min[2]),
            p_max: Point3f::new(self.bounds_max[0], self.bounds_max[1], self.bounds_max[2]),
        }
    }
    /// True for leaves.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Largest leaf a node can describe (`count` is a `u16`); degenerate
/// clusters bigger than this are split by count instead.
pub(super) const LEAF_MAX: usize = u16::MAX as usize;
/// Traversal stack size; the builders keep every leaf at most this deep.
pub(crate) const STACK_SIZE: usize = 64;
/// SAH bucket count (pbrt-v4).
const N_BUCKETS: usize = 12;
/// Below this many primitives a subtree is not worth a thread.
pub(super) const PAR_MIN_PRIMS: usize = 4096;

/// A binary BVH over primitive bounds.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    prim_indices: Vec<u32>,
    n_input: usize,
    n_skipped: usize,
}

/// A primitive during the build: its bounds and its caller index, 28
/// bytes (the centroid is computed where it is needed: storing it would
/// cost 12 bytes per primitive and as much memory traffic per pass).
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRef {
    pub bounds: Bounds3f,
    pub index: u32,
}

/// Anything binned by the SAH: primitives, or HLBVH treelets.
pub(super) trait Binnable {
    fn bounds(&self) -> &Bounds3f;
    fn centroid(&self) -> Point3f;
}

impl Binnable for PrimRef {
    #[inline(always)]
    fn bounds(&self) -> &Bounds3f {
        &self.bounds
    }
    #[inline(always)]
    fn centroid(&self) -> Point3f {
        centroid(&self.bounds)
    }
}

fn bounds_and_centroids<T: Binnable>(items: &[T]) -> (Bounds3f, Bounds3f) {
    let mut b = Bounds3f::empty();
    let mut c = Bounds3f::empty();
    for it in items {
        b = b.union(it.bounds());
        c = c.union_point(it.centroid());
    }
    (b, c)
}

/// In-place partition: items satisfying `pred` first; returns their count.
fn partition<T>(items: &mut [T], mut pred: impl FnMut(&T) -> bool) -> usize {
    let mut first = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(first, i);
            first += 1;
        }
    }
    first
}

/// Equal-count split: the median by centroid along `dim`.
fn split_equal<T: Binnable>(items: &mut [T], dim: usize) -> usize {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centroid()[dim].total_cmp(&b.centroid()[dim]));
    mid
}

/// Midpoint split of the centroid bounds, by count if that fails.
fn split_middle<T: Binnable>(items: &mut [T], cb: &Bounds3f, dim: usize) -> usize {
    let pmid = 0.5 * cb.p_min[dim] + 0.5 * cb.p_max[dim];
    let m = partition(items, |p| p.centroid()[dim] < pmid);
    if m == 0 || m == items.len() {
        split_equal(items, dim)
    } else {
        m
    }
}

fn bucket_of(c: Float, cmin: f64, cext: f64) -> usize {
    let b = (N_BUCKETS as f64 * ((c as f64 - cmin) / cext)) as usize;
    b.min(N_BUCKETS - 1)
}

/// The bounds of a set of primitives and of their centroids.
#[derive(Clone, Copy, Debug)]
pub(super) struct SetBounds {
    /// The union of the primitives' bounds.
    pub bounds: Bounds3f,
    /// The bounds of their centroids.
    pub centroids: Bounds3f,
}

impl SetBounds {
    /// The bounds of `items`, in one pass.
    pub(super) fn of<T: Binnable>(items: &[T]) -> SetBounds {
        let (bounds, centroids) = bounds_and_centroids(items);
        SetBounds { bounds, centroids }
    }

    pub(super) fn empty() -> SetBounds {
        SetBounds {
            bounds: Bounds3f::empty(),
            centroids: Bounds3f::empty(),
        }
    }

    fn union(&self, o: &SetBounds) -> SetBounds {
        SetBounds {
            bounds: self.bounds.union(&o.bounds),
            centroids: self.centroids.union(&o.centroids),
        }
    }
}

/// A binned SAH split: where it falls and, from the buckets, the bounds of
/// both sides (min and max are exact, so they are the bounds a pass over
/// each side would give).
type SahSplit = (usize, Option<(SetBounds, SetBounds)>);

/// Binned SAH (pbrt-v4 `buildRecursive`). Returns the split position, or
/// `None` when a leaf is cheaper and allowed (`leaf_max` prims or fewer).
/// `buckets` is scratch space: each item's bucket is computed once, for
/// the binning, and read back by the partition.
fn split_sah<T: Binnable>(
    items: &mut [T],
    bounds: &Bounds3f,
    cb: &Bounds3f,
    dim: usize,
    leaf_max: Option<usize>,
    buckets: &mut Vec<u8>,
) -> Option<SahSplit> {
    let n = items.len();
    if n <= 2 {
        return Some((split_equal(items, dim), None));
    }
    let cmin = cb.p_min[dim] as f64;
    let cext = cb.p_max[dim] as f64 - cmin;
    let mut counts = [0usize; N_BUCKETS];
    let mut bb = [SetBounds::empty(); N_BUCKETS];
    if buckets.len() < n {
        buckets.resize(n, 0);
    }
    for (it, slot) in items.iter().zip(buckets.iter_mut()) {
        let c = it.centroid();
        let b = bucket_of(c[dim], cmin, cext);
        *slot = b as u8;
        counts[b] += 1;
        bb[b].bounds = bb[b].bounds.union(it.bounds());
        bb[b].centroids = bb[b].centroids.union_point(c);
    }
    // Cost of splitting after bucket i, from a forward and a backward sweep.
    let mut costs = [0.0f64; N_BUCKETS - 1];
    let mut below = Bounds3f::empty();
    let mut n_below = 0;
    for i in 0..N_BUCKETS - 1 {
        below = below.union(&bb[i].bounds);
        n_below += counts[i];
        costs[i] = n_below as f64 * surface_area_f64(&below);
    }
    let mut above = Bounds3f::empty();
    let mut n_above = 0;
    for i in (1..N_BUCKETS).rev() {
        above = above.union(&bb[i].bounds);
        n_above += counts[i];
        costs[i - 1] += n_above as f64 * surface_area_f64(&above);
    }
    let mut best = None;
    let mut best_cost = f64::INFINITY;
    let mut n_below = 0;
    for (i, &c) in costs.iter().enumerate() {
        n_below += counts[i];
        if n_below == 0 || n_below == n {
            continue;
        }
        if c < best_cost {
            best_cost = c;
            best = Some(i);
        }
    }
    let best = best?;
    if let Some(leaf_max) = leaf_max {
        let area = surface_area_f64(bounds);
        let split_cost = 0.5 + best_cost / area;
        if n <= leaf_max && split_cost >= n as f64 {
            return None;
        }
    }
    // `partition` tests the items in their original order (each before
    // any swap moves it), so the k-th test is of the item binned k-th.
    let mut k = 0;
    let mid = partition(items, |_| {
        let below = buckets[k] as usize <= best;
        k += 1;
        below
    });
    if mid == 0 || mid == n {
        Some((split_equal(items, dim), None))
    } else {
        let side =
            |r: std::ops::Range<usize>| bb[r].iter().fold(SetBounds::empty(), |a, b| a.union(b));
        Some((mid, Some((side(0..best + 1), side(best + 1..N_BUCKETS)))))
    }
}

/// Appends `sub` (a subtree built with offsets relative to its own start)
/// to `out`, shifting interior child offsets.
fn append_relocated(out: &mut Vec<BvhNode>, sub: &[BvhNode]) {
    let base = out.len() as u32;
    out.extend(sub.iter().map(|n| {
        let mut n = *n;
        if n.count == 0 {
            n.offset += base;
        }
        n
    }));
}

pub(super) fn ceil_log2(n: usize) -> usize {
    (usize::BITS - n.saturating_sub(1).leading_zeros()) as usize
}

/// What the builder makes of a node.
#[derive(Clone, Copy, Debug)]
pub(super) enum Decision {
    /// A leaf of all the node's primitives.
    Leaf,
    /// An interior node: the primitives before `mid` (after the
    /// partition) go to the first child, with the bounds of both sides.
    Split {
        mid: usize,
        dim: usize,
        sides: (SetBounds, SetBounds),
    },
}

/// The top-down builder (SAH, middle and equal-count splits) shared by the
/// binary BVH and the 4-wide one (`wide.rs`), which make the same
/// decisions node for node.
pub(super) struct Builder {
    pub method: SplitMethod,
    pub max_prims: usize,
    pub par_depth: usize,
}

impl Builder {
    /// The builder for `params` with about `threads` threads (HLBVH, which
    /// has a builder of its own, falls back to the SAH here).
    pub(super) fn new(params: &BvhParams, threads: usize) -> Builder {
        Builder {
            method: match params.split_method {
                SplitMethod::Hlbvh => SplitMethod::Sah,
                m => m,
            },
            max_prims: params.max_prims_in_node.clamp(1, 255) as usize,
            par_depth: if threads > 1 {
                ceil_log2(threads) + 1
            } else {
                0
            },
        }
    }

    /// Decides the node over `prims` (bounds `set`, at binary depth
    /// `depth`): a leaf, or a split, partitioning `prims`. `buckets` is
    /// scratch space for the SAH.
    pub(super) fn decide(
        &self,
        prims: &mut [PrimRef],
        set: &SetBounds,
        depth: usize,
        buckets: &mut Vec<u8>,
    ) -> Decision {
        let n = prims.len();
        let (bounds, cb) = (&set.bounds, &set.centroids);
        let dim = cb.max_dimension();
        // Coincident centroids cannot be separated: leaf them (pbrt-v4).
        let degenerate = cb.p_max[dim] == cb.p_min[dim];
        if n <= LEAF_MAX
            && (n == 1 || degenerate || (self.method != SplitMethod::Sah && n <= self.max_prims))
        {
            return Decision::Leaf;
        }
        // Past this depth a split by count keeps every leaf within the
        // traversal stack, whatever the SAH would do.
        let guard = depth + ceil_log2(n) + 1 >= STACK_SIZE;
        // A node of zero area (all boxes on one line) has no SAH cost to
        // compare; pbrt makes it one leaf, a midpoint split does better.
        let flat = surface_area_f64(bounds) == 0.0;
        let (mid, sides) = if degenerate || guard {
            (split_equal(prims, dim), None)
        } else {
            match self.method {
                SplitMethod::Middle => (split_middle(prims, cb, dim), None),
                SplitMethod::Sah | SplitMethod::Hlbvh if flat => {
                    (split_middle(prims, cb, dim), None)
                }
                SplitMethod::Sah | SplitMethod::Hlbvh => {
                    match split_sah(prims, bounds, cb, dim, Some(self.max_prims), buckets) {
                        Some(s) => s,
                        None => return Decision::Leaf,
                    }
                }
                SplitMethod::EqualCounts => (split_equal(prims, dim), None),
            }
        };
        let sides =
            sides.unwrap_or_else(|| (SetBounds::of(&prims[..mid]), SetBounds::of(&prims[mid..])));
        Decision::Split { mid, dim, sides }
    }

    /// Builds the subtree over `prims` (bounds `set`; they sit at `first..`
    /// in the final primitive order) at `depth`, appending nodes to `out`
    /// with child offsets relative to `out`'s start.
    fn build(
        &self,
        prims: &mut [PrimRef],
        set: &SetBounds,
        first: u32,
        depth: usize,
        out: &mut Vec<BvhNode>,
        buckets: &mut Vec<u8>,
    ) {
        let n = prims.len();
        let node = out.len();
        out.push(BvhNode::leaf(&set.bounds, first, n.min(LEAF_MAX) as u16));
        let Decision::Split { mid, dim, sides } = self.decide(prims, set, depth, buckets) else {
            return;
        };
        out[node].count = 0;
        out[node].axis = dim as u8;
        let (left, right) = prims.split_at_mut(mid);
        let right_first = first + mid as u32;
        if depth < self.par_depth && n >= PAR_MIN_PRIMS {
            let mut right_nodes = Vec::new();
            std::thread::scope(|s| {
                let handle = s.spawn(|| {
                    let mut v = Vec::with_capacity(2 * right.len() / self.max_prims.max(1));
                    let mut buckets = Vec::new();
                    self.build(
                        right,
                        &sides.1,
                        right_first,
                        depth + 1,
                        &mut v,
                        &mut buckets,
                    );
                    v
                });
                self.build(left, &sides.0, first, depth + 1, out, buckets);
                match handle.join() {
                    Ok(v) => right_nodes = v,
                    Err(e) => std::panic::resume_unwind(e),
                }
            });
            out[node].offset = out.len() as u32;
            append_relocated(out, &right_nodes);
        } else {
            self.build(left, &sides.0, first, depth + 1, out, buckets);
            out[node].offset = out.len() as u32;
            self.build(right, &sides.1, right_first, depth + 1, out, buckets);
        }
    }
}

/// An HLBVH treelet: a subtree over primitives sharing their top 12 Morton
/// bits, built on its own.
struct Treelet {
    bounds: Bounds3f,
    centroid: Point3f,
    nodes: Vec<BvhNode>,
}

impl Binnable for Treelet {
    fn bounds(&self) -> &Bounds3f {
        &self.bounds
    }
    fn centroid(&self) -> Point3f {
        self.centroid
    }
}

/// Stable LSD radix sort of `(morton code, position)` pairs on 30 bits.
fn radix_sort(v: &mut Vec<(u32, u32)>) {
    const BITS: u32 = 10;
    let mut tmp = vec![(0u32, 0u32); v.len()];
    for pass in 0..3 {
        let shift = pass * BITS;
        let mut count = vec![0usize; 1 << BITS];
        for &(c, _) in v.iter() {
            count[((c >> shift) & ((1 << BITS) - 1)) as usize] += 1;
        }
        let mut sum = 0;
        for c in count.iter_mut() {
            let k = *c;
            *c = sum;
            sum += k;
        }
        for &e in v.iter() {
            let b = ((e.0 >> shift) & ((1 << BITS) - 1)) as usize;
            tmp[count[b]] = e;
            count[b] += 1;
        }
        std::mem::swap(v, &mut tmp);
    }
}

/// pbrt-v4 `emitLBVH`: splits Morton-sorted primitives at the first bit
/// (from `bit` down) where the codes differ.
fn emit_lbvh(
    prims: &[PrimRef],
    codes: &[u32],
    first: u32,
    bit: i32,
    max_prims: usize,
    out: &mut Vec<BvhNode>,
) {
    let n = prims.len();
    if bit < 0 || n <= max_prims {
        if n <= LEAF_MAX {
            let (b, _) = bounds_and_centroids(prims);
            out.push(BvhNode::leaf(&b, first, n as u16));
            return;
        }
        // Too many identical codes for one leaf: halve by count.
        let mid = n / 2;
        emit_interior(prims, codes, first, mid, -1, 0, max_prims, out);
        return;
    }
    let mask = 1u32 << bit;
    if codes[0] & mask == codes[n - 1] & mask {
        return emit_lbvh(prims, codes, first, bit - 1, max_prims, out);
    }
    // Codes are sorted, so within this range `bit` goes from 0 to 1 once.
    let mid = codes.partition_point(|c| c & mask == 0);
    emit_interior(
        prims,
        codes,
        first,
        mid,
        bit - 1,
        (bit % 3) as u8,
        max_prims,
        out,
    );
}

#[allow(clippy::too_many_arguments)]
fn emit_interior(
    prims: &[PrimRef],
    codes: &[u32],
    first: u32,
    mid: usize,
    bit: i32,
    axis: u8,
    max_prims: usize,
    out: &mut Vec<BvhNode>,
) {
    let node = out.len();
    out.push(BvhNode::leaf(&Bounds3f::empty(), 0, 0));
    emit_lbvh(&prims[..mid], &codes[..mid], first, bit, max_prims, out);
    let second = out.len();
    emit_lbvh(
        &prims[mid..],
        &codes[mid..],
        first + mid as u32,
        bit,
        max_prims,
        out,
    );
    let b = out[node + 1].bounds().union(&out[second].bounds());
    let mut n = BvhNode::leaf(&b, second as u32, 0);
    n.axis = axis;
    out[node] = n;
}

/// SAH over treelet roots (pbrt-v4 `buildUpperSAH`): always splits, down
/// to single treelets, which are spliced in.
fn build_upper(treelets: &mut [Treelet], depth: usize, out: &mut Vec<BvhNode>) {
    if treelets.len() == 1 {
        append_relocated(out, &treelets[0].nodes);
        return;
    }
    let (bounds, cb) = bounds_and_centroids(treelets);
    let dim = cb.max_dimension();
    let mid = if cb.p_max[dim] == cb.p_min[dim] || depth + ceil_log2(treelets.len()) + 1 >= 32 {
        split_equal(treelets, dim)
    } else {
        split_sah(treelets, &bounds, &cb, dim, None, &mut Vec::new())
            .map_or(treelets.len() / 2, |(mid, _)| mid)
    };
    let node = out.len();
    let mut interior = BvhNode::leaf(&bounds, 0, 0);
    interior.axis = dim as u8;
    out.push(interior);
    let (l, r) = treelets.split_at_mut(mid);
    build_upper(l, depth + 1, out);
    out[node].offset = out.len() as u32;
    build_upper(r, depth + 1, out);
}

fn build_hlbvh(prims: &mut Vec<PrimRef>, max_prims: usize, threads: usize) -> Vec<BvhNode> {
    let (_, cb) = bounds_and_centroids(prims);
    let mut keyed: Vec<(u32, u32)> = prims
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let o = cb.offset(p.centroid()) * 1024.0;
            (encode_morton3(o.x, o.y, o.z), i as u32)
        })
        .collect();
    radix_sort(&mut keyed);
    let sorted: Vec<PrimRef> = keyed.iter().map(|&(_, i)| prims[i as usize]).collect();
    *prims = sorted;
    let codes: Vec<u32> = keyed.iter().map(|&(c, _)| c).collect();

    // Treelets: runs of equal top 12 bits (of 30).
    const TREELET_MASK: u32 = 0b0011_1111_1111_1100_0000_0000_0000_0000;
    let mut ranges = Vec::new();
    let mut start = 0;
    for end in 1..=codes.len() {
        if end == codes.len() || (codes[start] & TREELET_MASK) != (codes[end] & TREELET_MASK) {
            ranges.push((start, end));
            start = end;
        }
    }
    // Contiguous groups of treelets, one per thread: the node arrays depend
    // only on the ranges, not on the grouping.
    let groups = threads.clamp(1, ranges.len().max(1));
    let per = ranges.len().div_ceil(groups);
    let ps: &[PrimRef] = prims;
    let build_range = |&(s, e): &(usize, usize)| {
        let mut nodes = Vec::new();
        emit_lbvh(
            &ps[s..e],
            &codes[s..e],
            s as u32,
            29 - 12,
            max_prims,
            &mut nodes,
        );
        let b = nodes[0].bounds();
        Treelet {
            bounds: b,
            centroid: centroid(&b),
            nodes,
        }
    };
    let mut treelets: Vec<Treelet> = if groups <= 1 || prims.len() < PAR_MIN_PRIMS {
        ranges.iter().map(&build_range).collect()
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = ranges
                .chunks(per)
                .map(|chunk| {
                    let f = &build_range;
                    s.spawn(move || chunk.iter().map(f).collect::<Vec<_>>())
                })
                .collect();
            let mut all = Vec::with_capacity(ranges.len());
            for h in handles {
                match h.join() {
                    Ok(v) => all.extend(v),
                    Err(e) => std::panic::resume_unwind(e),
                }
            }
            all
        })
    };
    let mut out = Vec::with_capacity(treelets.iter().map(|t| t.nodes.len()).sum::<usize>() * 2);
    build_upper(&mut treelets, 0, &mut out);
    out
}

/// The build references of the `n` primitives whose bounds `bounds` gives,
/// leaving out those with unusable bounds, in order. The bounds are found
/// on up to `threads` threads, each filling its own range of the result
/// (no second copy of the references is made).
pub(super) fn prim_refs<F>(n: usize, bounds: F, threads: usize) -> Vec<PrimRef>
where
    F: Fn(u32) -> Bounds3f + Sync,
{
    let mut prims = vec![
        PrimRef {
            bounds: Bounds3f::empty(),
            index: 0,
        };
        n
    ];
    let fill = |part: &mut [PrimRef], first: usize| {
        for (k, p) in part.iter_mut().enumerate() {
            let i = (first + k) as u32;
            *p = PrimRef {
                bounds: bounds(i),
                index: i,
            };
        }
    };
    if threads > 1 && n >= PAR_MIN_PRIMS {
        let chunk = n.div_ceil(threads);
        std::thread::scope(|s| {
            for (c, part) in prims.chunks_mut(chunk).enumerate() {
                let fill = &fill;
                s.spawn(move || fill(part, c * chunk));
            }
        });
    } else {
        fill(&mut prims, 0);
    }
    prims.retain(|p| usable_bounds(&p.bounds));
    prims
}

fn max_depth(nodes: &[BvhNode]) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        if !nodes[i].is_leaf() {
            stack.push((i + 1, d + 1));
            stack.push((nodes[i].offset as usize, d + 1));
        }
    }
    deepest
}

impl Bvh {
    /// Builds a BVH over `prim_bounds` using all available cores.
    pub fn build(prim_bounds: &[Bounds3f], params: &BvhParams) -> Bvh {
        Bvh::build_with_threads(prim_bounds, params, super::default_threads())
    }

    /// Builds with at most about `threads` threads; the result is the same
    /// for every thread count.
    pub fn build_with_threads(prim_bounds: &[Bounds3f], params: &BvhParams, threads: usize) -> Bvh {
        Bvh::build_from(
            prim_bounds.len(),
            |i| prim_bounds[i as usize],
            params,
            threads,
        )
    }

    /// [`Bvh::build_with_threads`] over `n` primitives whose bounds
    /// `bounds` gives, called once per primitive: the bounds go straight
    /// into the build references, never into an array of their own.
    pub fn build_from<F>(n: usize, bounds: F, params: &BvhParams, threads: usize) -> Bvh
    where
        F: Fn(u32) -> Bounds3f + Sync,
    {
        let mut prims = prim_refs(n, bounds, threads);
        let mut bvh = Bvh {
            n_input: n,
            n_skipped: n - prims.len(),
            ..Default::default()
        };
        if prims.is_empty() {
            return bvh;
        }
        let builder = Builder::new(params, threads);
        let mut nodes = Vec::new();
        if params.split_method == SplitMethod::Hlbvh {
            nodes = build_hlbvh(&mut prims, builder.max_prims, threads);
        }
        if nodes.is_empty() || max_depth(&nodes) > STACK_SIZE {
            // (HLBVH cannot bound its depth while building; an SAH build
            // does, so it is the fallback.)
            nodes.clear();
            nodes.reserve(2 * prims.len() / builder.max_prims + 1);
            let set = SetBounds::of(&prims);
            builder.build(&mut prims, &set, 0, 0, &mut nodes, &mut Vec::new());
        }
        nodes.shrink_to_fit();
        bvh.nodes = nodes;
        bvh.prim_indices = prims.iter().map(|p| p.index).collect();
        bvh
    }

    /// The flattened nodes (root first; empty when there are no primitives).
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Caller primitive indices in leaf order: a leaf covers
    /// `prim_indices()[offset..offset + count]`.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Takes the nodes and the primitive index array apart (for
    /// [`Bvh4::from_binary`](super::Bvh4::from_binary)).
    pub fn into_parts(self) -> (Vec<BvhNode>, Vec<u32>) {
        (self.nodes, self.prim_indices)
    }

    /// The depth of the deepest leaf (the root has depth 0).
    pub fn depth(&self) -> usize {
        if self.nodes.is_empty() {
            0
        } else {
            max_depth(&self.nodes)
        }
    }
}

impl Aggregate for Bvh {
    fn bounds(&self) -> Bounds3f {
        self.nodes.first().map_or(Bounds3f::empty(), |n| n.bounds())
    }

    #[inline]
    fn intersect<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>,
    {
        if self.nodes.is_empty() {
            return None;
        }
        let pre = RayPrecomp::new(ray);
        let mut t_max = t_max;
        let mut best = None;
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if pre.hits(&node.bounds_min, &node.bounds_max, t_max) {
                if node.count > 0 {
                    let start = node.offset as usize;
                    for &p in &self.prim_indices[start..start + node.count as usize] {
                        if let Some(t) = hit(p, ray, t_max) {
                            debug_assert!(t <= t_max);
                            t_max = t;
                            best = Some((p, t));
                        }
                    }
                } else {
                    // Visit the child on the ray's near side first.
                    let (near, far) = if pre.dir_is_neg[node.axis as usize] != 0 {
                        (node.offset, idx as u32 + 1)
                    } else {
                        (idx as u32 + 1, node.offset)
                    };
                    stack[sp] = far;
                    sp += 1;
                    idx = near as usize;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
        best
    }

    #[inline]
    fn intersect_p<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> bool
    where
        F: FnMut(u32, &Ray, Float) -> bool,
    {
        if self.nodes.is_empty() {
            return false;
        }
        let pre = RayPrecomp::new(ray);
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if pre.hits(&node.bounds_min, &node.bounds_max, t_max) {
                if node.count > 0 {
                    let start = node.offset as usize;
                    for &p in &self.prim_indices[start..start + node.count as usize] {
                        if hit(p, ray, t_max) {
                            return true;
                        }
                    }
                } else {
                    let (near, far) = if pre.dir_is_neg[node.axis as usize] != 0 {
                        (node.offset, idx as u32 + 1)
                    } else {
                        (idx as u32 + 1, node.offset)
                    };
                    stack[sp] = far;
                    sp += 1;
                    idx = near as usize;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.nodes.capacity() * std::mem::size_of::<BvhNode>()
            + self.prim_indices.capacity() * 4
    }

    fn primitive_count(&self) -> usize {
        self.n_input
    }

    fn skipped_primitives(&self) -> usize {
        self.n_skipped
    }
}
