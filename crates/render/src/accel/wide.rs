//! Building the wide BVHs straight from the primitives (pbrt-v4 section
//! 7.3.2's top-down build, collapsed as `widebvh.rs` collapses it), without
//! the binary tree in between.
//!
//! [`WideBvh::from_binary`] turns a binary node into a wide one by opening,
//! while there are fewer than `W` children, the interior child of largest
//! surface area, in place. Here the same children are found top down: a
//! binary node is decided (leaf, or split and partitioned) when it becomes
//! a child, and opening it decides its two sides. Every binary node is
//! decided once, on its own primitives, exactly as the binary builder
//! decides it (the same [`Builder::decide`]), so the wide tree, its node
//! order (depth first, children in lane order) and the primitive order are
//! those of `WideBvh::from_binary(Bvh::build(..))`, for every thread count.
//!
//! Memory: the binary tree of 10 million triangles is about 500 MB, as
//! much as the wide one; it is never made. The root's subtrees each get
//! their own copy of their build references, cut from the end of the
//! array one at a time, so that each subtree's references are freed as
//! soon as it is built.

use super::bvh::{prim_refs, Builder, Decision, PrimRef, SetBounds, PAR_MIN_PRIMS};
use super::params::BvhParams;
use super::surface_area_f64;
use super::widebvh::{WideBvh, WideNode};
use rpbrt_geometry::Bounds3f;

/// Below this many primitives the two sides of a split are decided on one
/// thread.
const PAR_DECIDE_MIN: usize = 1 << 16;

/// A binary node while a wide node is being cut: its primitives (a range
/// of the wide node's), binary depth, bounds and decision.
#[derive(Clone, Copy, Debug)]
struct Kid {
    start: usize,
    end: usize,
    depth: usize,
    set: SetBounds,
    decision: Decision,
}

/// The children of one wide node, in lane order.
struct Kids<const W: usize> {
    items: [Kid; W],
    len: usize,
}

impl<const W: usize> Kids<W> {
    fn as_slice(&self) -> &[Kid] {
        &self.items[..self.len]
    }
}

/// Builds the 4-wide BVH over the `n` primitives whose bounds `bounds`
/// gives (see the module documentation).
pub(super) fn build<const W: usize, F>(
    n: usize,
    bounds: F,
    params: &BvhParams,
    threads: usize,
) -> WideBvh<W>
where
    F: Fn(u32) -> Bounds3f + Sync,
{
    let mut prims = prim_refs(n, bounds, threads);
    let n_skipped = n - prims.len();
    if prims.is_empty() {
        return WideBvh::from_parts(Vec::new(), Vec::new(), Bounds3f::empty(), n, n_skipped);
    }
    let builder = Builder::new(params, threads);
    let set = SetBounds::of(&prims);
    let mut idx = vec![0u32; prims.len()];
    let mut buckets = Vec::new();
    let mut nodes = Vec::new();
    match builder.decide(&mut prims, &set, 0, &mut buckets) {
        Decision::Leaf => {
            let root = Kid {
                start: 0,
                end: prims.len(),
                depth: 0,
                set,
                decision: Decision::Leaf,
            };
            let mut node = WideNode::<W>::empty();
            set_lane(&mut node, 0, &root, 0);
            nodes.push(node);
            write_indices(&prims, &mut idx);
        }
        Decision::Split { mid, sides, .. } => {
            let par = builder.par_depth > 0 && prims.len() >= PAR_MIN_PRIMS;
            let kids = builder.wide_kids(&mut prims, 0, mid, sides, &mut buckets, par);
            drop(buckets);
            nodes = builder.build_root(prims, &mut idx, &kids, par);
        }
    }
    // No `shrink_to_fit`: the nodes are 64-byte aligned, so shrinking
    // would allocate and copy the whole tree (the system allocator only
    // reallocates in place up to 16-byte alignment), while the reserved
    // tail was never written and holds no memory.
    WideBvh::from_parts(nodes, idx, set.bounds, n, n_skipped)
}

/// Nodes to reserve for the wide tree over `prims` primitives: an upper
/// bound (every wide node is a distinct interior node of the binary tree,
/// which has fewer than `prims`), capped at 2²⁶ nodes (8 GiB). Reserving it
/// costs address space, not memory: pages are only made resident as nodes
/// are written, the vector never reallocates (a doubling would hold the old
/// and the new copy at once), and the final `shrink_to_fit` returns the
/// rest.
fn node_capacity(prims: usize) -> usize {
    prims.min(1 << 26)
}

/// Copies the caller indices of `prims` into `idx` (the same length).
fn write_indices(prims: &[PrimRef], idx: &mut [u32]) {
    for (slot, p) in idx.iter_mut().zip(prims) {
        *slot = p.index;
    }
}

/// Fills lane `lane` of `node` for `kid`, whose first primitive sits at
/// `first` in the final order: its box, and for a leaf its primitives.
fn set_lane<const W: usize>(node: &mut WideNode<W>, lane: usize, kid: &Kid, first: u32) {
    let b = &kid.set.bounds;
    for a in 0..3 {
        node.bounds[a][lane] = b.p_min[a];
        node.bounds[3 + a][lane] = b.p_max[a];
    }
    if let Decision::Leaf = kid.decision {
        // Leaves never hold more than `LEAF_MAX` (a `u16`) primitives.
        node.child[lane] = first + kid.start as u32;
        node.count[lane] = (kid.end - kid.start) as u16;
        node.leaf_lanes |= 1 << lane;
    }
}

/// Appends `sub` (a subtree built with child indices relative to its own
/// start) to `out`, shifting its interior children's indices; returns the
/// index of its root.
fn append_relocated<const W: usize>(out: &mut Vec<WideNode<W>>, sub: &[WideNode<W>]) -> u32 {
    let base = out.len() as u32;
    out.extend(sub.iter().map(|n| {
        let mut n = *n;
        for lane in 0..W {
            // Interior children point forward, so never at the root (0);
            // unused lanes hold 0.
            if n.count[lane] == 0 && n.child[lane] != 0 {
                n.child[lane] += base;
            }
        }
        n
    }));
    base
}

impl Builder {
    /// Decides the two sides of a node over `prims` split at `mid`, at
    /// binary depth `depth`; their ranges are offset by `start`.
    #[allow(clippy::too_many_arguments)]
    fn decide_pair(
        &self,
        prims: &mut [PrimRef],
        start: usize,
        mid: usize,
        sides: (SetBounds, SetBounds),
        depth: usize,
        buckets: &mut Vec<u8>,
        par: bool,
    ) -> (Kid, Kid) {
        let n = prims.len();
        let (left, right) = prims.split_at_mut(mid);
        let (dl, dr) = if par && n >= PAR_DECIDE_MIN {
            std::thread::scope(|s| {
                let handle = s.spawn(|| self.decide(right, &sides.1, depth, &mut Vec::new()));
                let dl = self.decide(left, &sides.0, depth, buckets);
                match handle.join() {
                    Ok(dr) => (dl, dr),
                    Err(e) => std::panic::resume_unwind(e),
                }
            })
        } else {
            let dl = self.decide(left, &sides.0, depth, buckets);
            (dl, self.decide(right, &sides.1, depth, buckets))
        };
        (
            Kid {
                start,
                end: start + mid,
                depth,
                set: sides.0,
                decision: dl,
            },
            Kid {
                start: start + mid,
                end: start + n,
                depth,
                set: sides.1,
                decision: dr,
            },
        )
    }

    /// The children of the wide node whose binary root (at `depth`) over
    /// `prims` splits at `mid` into `sides`: the root's two sides, then,
    /// while there are fewer than `W`, the interior child of largest
    /// surface area (the first of equals) opened in place.
    fn wide_kids<const W: usize>(
        &self,
        prims: &mut [PrimRef],
        depth: usize,
        mid: usize,
        sides: (SetBounds, SetBounds),
        buckets: &mut Vec<u8>,
        par: bool,
    ) -> Kids<W> {
        let (l, r) = self.decide_pair(prims, 0, mid, sides, depth + 1, buckets, par);
        let mut items = [l; W];
        items[1] = r;
        let mut kids = Kids { items, len: 2 };
        while kids.len < W {
            let mut best: Option<(usize, f64)> = None;
            for (i, k) in kids.as_slice().iter().enumerate() {
                if let Decision::Split { .. } = k.decision {
                    let a = surface_area_f64(&k.set.bounds);
                    if best.is_none_or(|(_, ba)| a > ba) {
                        best = Some((i, a));
                    }
                }
            }
            let Some((i, _)) = best else { break };
            let k = kids.items[i];
            let Decision::Split { mid, sides, .. } = k.decision else {
                break;
            };
            let range = &mut prims[k.start..k.end];
            let (a, b) = self.decide_pair(range, k.start, mid, sides, k.depth + 1, buckets, par);
            // Keep the binary order (first side first).
            kids.items.copy_within(i + 1..kids.len, i + 2);
            kids.items[i] = a;
            kids.items[i + 1] = b;
            kids.len += 1;
        }
        kids
    }

    /// Appends the wide subtree of `kid` (over all of `prims`, which sit
    /// at `first..` in the final order; `idx` receives their caller
    /// indices) to `out`, child indices relative to `out`'s start; returns
    /// its root's index, or `None` for a leaf, which has no node of its
    /// own. `wide_depth` is the wide node's depth (subtrees near the root
    /// are built in parallel).
    #[allow(clippy::too_many_arguments)]
    fn build_wide<const W: usize>(
        &self,
        prims: &mut [PrimRef],
        idx: &mut [u32],
        first: u32,
        kid: &Kid,
        out: &mut Vec<WideNode<W>>,
        buckets: &mut Vec<u8>,
        wide_depth: usize,
    ) -> Option<u32> {
        let Decision::Split { mid, sides, .. } = kid.decision else {
            return None;
        };
        let par = wide_depth < self.wide_par_depth() && prims.len() >= PAR_MIN_PRIMS;
        let kids: Kids<W> = self.wide_kids(prims, kid.depth, mid, sides, buckets, par);
        let me = out.len();
        let mut node = WideNode::<W>::empty();
        for (lane, k) in kids.as_slice().iter().enumerate() {
            set_lane(&mut node, lane, k, first);
            if let Decision::Leaf = k.decision {
                write_indices(&prims[k.start..k.end], &mut idx[k.start..k.end]);
            }
        }
        out.push(node);
        if !par {
            for (lane, k) in kids.as_slice().iter().enumerate() {
                let c = self.build_wide(
                    &mut prims[k.start..k.end],
                    &mut idx[k.start..k.end],
                    first + k.start as u32,
                    k,
                    out,
                    buckets,
                    wide_depth + 1,
                );
                if let Some(c) = c {
                    out[me].child[lane] = c;
                }
            }
            return Some(me as u32);
        }
        // The interior children's primitives, as disjoint slices.
        let mut parts = Vec::new();
        let (mut rest, mut rest_idx, mut at) = (prims, idx, 0);
        for (lane, k) in kids.as_slice().iter().enumerate() {
            let (_, tail) = rest.split_at_mut(k.start - at);
            let (_, tail_idx) = rest_idx.split_at_mut(k.start - at);
            let (mine, tail) = tail.split_at_mut(k.end - k.start);
            let (mine_idx, tail_idx) = tail_idx.split_at_mut(k.end - k.start);
            if let Decision::Split { .. } = k.decision {
                parts.push((lane, k, mine, mine_idx));
            }
            (rest, rest_idx, at) = (tail, tail_idx, k.end);
        }
        let subs = std::thread::scope(|s| {
            let handles: Vec<_> = parts
                .into_iter()
                .map(|(lane, k, p, i)| {
                    s.spawn(move || {
                        let mut sub = Vec::with_capacity(node_capacity(p.len()));
                        let mut buckets = Vec::new();
                        let f = first + k.start as u32;
                        self.build_wide(p, i, f, k, &mut sub, &mut buckets, wide_depth + 1);
                        (lane, sub)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| match h.join() {
                    Ok(v) => v,
                    Err(e) => std::panic::resume_unwind(e),
                })
                .collect::<Vec<_>>()
        });
        for (lane, sub) in subs {
            out[me].child[lane] = append_relocated(out, &sub);
        }
        Some(me as u32)
    }

    /// How many levels of wide nodes build their subtrees in parallel:
    /// about as many tasks as threads (`W` per level).
    fn wide_par_depth(&self) -> usize {
        self.par_depth.div_ceil(2)
    }

    /// The nodes of the whole tree, given the root's children `kids` over
    /// `prims`: each interior child's references are moved into a vector
    /// of their own (taken from the end of `prims`, which shrinks), built
    /// (in parallel when the builder has threads) and freed, and its nodes
    /// are appended in lane order.
    fn build_root<const W: usize>(
        &self,
        mut prims: Vec<PrimRef>,
        idx: &mut [u32],
        kids: &Kids<W>,
        par: bool,
    ) -> Vec<WideNode<W>> {
        let idx_len = idx.len();
        let mut root = WideNode::<W>::empty();
        for (lane, k) in kids.as_slice().iter().enumerate() {
            set_lane(&mut root, lane, k, 0);
            if let Decision::Leaf = k.decision {
                write_indices(&prims[k.start..k.end], &mut idx[k.start..k.end]);
            }
        }
        // Own references per interior child, cut from the back.
        let mut owned: Vec<(usize, Kid, Vec<PrimRef>)> = Vec::new();
        for (lane, k) in kids.as_slice().iter().enumerate().rev() {
            if let Decision::Split { .. } = k.decision {
                let refs = if k.start == 0 {
                    prims.truncate(k.end);
                    std::mem::take(&mut prims)
                } else {
                    let refs = prims[k.start..k.end].to_vec();
                    prims.truncate(k.start);
                    prims.shrink_to_fit();
                    refs
                };
                owned.push((lane, *k, refs));
            }
        }
        drop(prims);
        owned.reverse();
        // The index slices, in lane order.
        let mut parts = Vec::new();
        let (mut rest, mut at) = (idx, 0);
        for (lane, k, refs) in owned {
            let (_, tail) = rest.split_at_mut(k.start - at);
            let (mine, tail) = tail.split_at_mut(k.end - k.start);
            parts.push((lane, k, refs, mine));
            (rest, at) = (tail, k.end);
        }
        let build = |k: Kid, mut refs: Vec<PrimRef>, idx: &mut [u32]| {
            let mut sub = Vec::with_capacity(node_capacity(refs.len()));
            let mut buckets = Vec::new();
            self.build_wide(
                &mut refs,
                idx,
                k.start as u32,
                &k,
                &mut sub,
                &mut buckets,
                1,
            );
            sub
        };
        let mut nodes = Vec::with_capacity(node_capacity(idx_len));
        nodes.push(root);
        if !par {
            // Each subtree straight into the tree, its references freed
            // as soon as it is built.
            let mut buckets = Vec::new();
            for (lane, k, mut refs, idx) in parts {
                let c = self.build_wide(
                    &mut refs,
                    idx,
                    k.start as u32,
                    &k,
                    &mut nodes,
                    &mut buckets,
                    1,
                );
                if let Some(c) = c {
                    nodes[0].child[lane] = c;
                }
            }
            return nodes;
        }
        // As many subtrees in flight as the builder has threads at this
        // level: a finished subtree's nodes wait (held twice once copied)
        // only for those before it, and the later subtrees' references
        // are not yet joined by nodes of their own.
        let window = (1usize << self.par_depth.saturating_sub(1)).clamp(1, W);
        std::thread::scope(|s| {
            let mut pending = parts.into_iter();
            let mut running = std::collections::VecDeque::new();
            let mut start_next = |running: &mut std::collections::VecDeque<_>| {
                if let Some((lane, k, refs, idx)) = pending.next() {
                    running.push_back((lane, s.spawn(move || build(k, refs, idx))));
                }
            };
            for _ in 0..window {
                start_next(&mut running);
            }
            // Appended in lane order as each finishes.
            while let Some((lane, h)) = running.pop_front() {
                match h.join() {
                    Ok(sub) => nodes[0].child[lane] = append_relocated(&mut nodes, &sub),
                    Err(e) => std::panic::resume_unwind(e),
                }
                start_next(&mut running);
            }
        });
        nodes
    }
}
