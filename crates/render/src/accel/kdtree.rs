//! The SAH kd-tree of pbrt-v3 section 4.4 (`KdTreeAccel`): split planes
//! chosen among primitive bound edges by a cost model with an empty-space
//! bonus, 8-byte nodes, and front-to-back traversal with a todo stack.

use super::params::KdTreeParams;
use super::{far_pad, usable_bounds, Aggregate, RayPrecomp};
use rpbrt_geometry::{Bounds3f, Float, Ray};

/// An 8-byte kd-tree node (pbrt-v3 `KdAccelNode`).
///
/// The low two bits of `flags` are the split axis (0–2) or 3 for a leaf; the
/// upper 30 bits are the index of the above child (interior; the below
/// child is the next node) or the primitive count (leaf). `data` is the
/// split position's bits (interior), the primitive itself (leaf of one) or
/// an offset into the primitive index array (larger leaf).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KdNode {
    /// Split position bits, the single primitive, or a primitive offset.
    pub data: u32,
    /// Axis or leaf tag in the low two bits; child index or count above.
    pub flags: u32,
}

impl KdNode {
    fn leaf(data: u32, count: u32) -> KdNode {
        KdNode {
            data,
            flags: 3 | (count << 2),
        }
    }
    /// True for leaves.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.flags & 3 == 3
    }
    /// Interior: the split axis.
    #[inline]
    pub fn axis(&self) -> usize {
        (self.flags & 3) as usize
    }
    /// Interior: the split position.
    #[inline]
    pub fn split(&self) -> Float {
        Float::from_bits(self.data)
    }
    /// Interior: the above child's index; leaf: the primitive count.
    #[inline]
    pub fn upper(&self) -> u32 {
        self.flags >> 2
    }
}

/// An SAH kd-tree over primitive bounds.
#[derive(Clone, Debug)]
pub struct KdTree {
    nodes: Vec<KdNode>,
    prim_indices: Vec<u32>,
    bounds: Bounds3f,
    n_input: usize,
    n_skipped: usize,
}

#[derive(Clone, Copy, Debug)]
struct Edge {
    t: Float,
    prim: u32,
    is_end: bool,
}

/// Traversal stack size; the depth is capped to it.
const STACK_SIZE: usize = 64;

struct KdBuilder<'a> {
    params: &'a KdTreeParams,
    prim_bounds: &'a [Bounds3f],
    nodes: Vec<KdNode>,
    prim_indices: Vec<u32>,
    edges: Vec<Edge>,
}

impl KdBuilder<'_> {
    fn make_leaf(&mut self, prims: &[u32]) {
        let node = match prims.len() {
            0 => KdNode::leaf(0, 0),
            1 => KdNode::leaf(prims[0], 1),
            n => {
                let off = self.prim_indices.len() as u32;
                self.prim_indices.extend_from_slice(prims);
                KdNode::leaf(off, n as u32)
            }
        };
        self.nodes.push(node);
    }

    fn fill_edges(&mut self, prims: &[u32], axis: usize) {
        self.edges.clear();
        for &p in prims {
            let b = &self.prim_bounds[p as usize];
            self.edges.push(Edge {
                t: b.p_min[axis],
                prim: p,
                is_end: false,
            });
            self.edges.push(Edge {
                t: b.p_max[axis],
                prim: p,
                is_end: true,
            });
        }
        // Starts before ends at equal t (pbrt), then by primitive so the
        // order is fully determined.
        self.edges.sort_unstable_by(|a, b| {
            a.t.total_cmp(&b.t)
                .then(a.is_end.cmp(&b.is_end))
                .then(a.prim.cmp(&b.prim))
        });
    }

    fn build(&mut self, node_bounds: &Bounds3f, prims: &[u32], depth: u32, mut bad_refines: u32) {
        let n = prims.len();
        if n <= self.params.max_prims as usize || depth == 0 {
            self.make_leaf(prims);
            return;
        }
        // Choose the split with the lowest cost (pbrt-v3 4.4.2), in f64 so
        // that huge scenes do not overflow the areas.
        let isect = self.params.isect_cost as f64;
        let trav = self.params.traversal_cost as f64;
        let bonus = self.params.empty_bonus as f64;
        let old_cost = isect * n as f64;
        let lo = [
            node_bounds.p_min.x as f64,
            node_bounds.p_min.y as f64,
            node_bounds.p_min.z as f64,
        ];
        let hi = [
            node_bounds.p_max.x as f64,
            node_bounds.p_max.y as f64,
            node_bounds.p_max.z as f64,
        ];
        let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let total_sa = 2.0 * (d[0] * d[1] + d[0] * d[2] + d[1] * d[2]);
        let inv_total_sa = 1.0 / total_sa;
        let mut axis = node_bounds.max_dimension();
        let mut best: Option<(usize, usize)> = None; // (axis, edge index)
        let mut best_cost = f64::INFINITY;
        for _retry in 0..3 {
            self.fill_edges(prims, axis);
            let (o0, o1) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut n_below = 0usize;
            let mut n_above = n;
            for (i, e) in self.edges.iter().enumerate() {
                if e.is_end {
                    n_above -= 1;
                }
                let t = e.t as f64;
                if t > lo[axis] && t < hi[axis] {
                    let below_sa = 2.0 * (d[o0] * d[o1] + (t - lo[axis]) * (d[o0] + d[o1]));
                    let above_sa = 2.0 * (d[o0] * d[o1] + (hi[axis] - t) * (d[o0] + d[o1]));
                    let p_below = below_sa * inv_total_sa;
                    let p_above = above_sa * inv_total_sa;
                    let eb = if n_above == 0 || n_below == 0 {
                        bonus
                    } else {
                        0.0
                    };
                    let cost = trav
                        + isect
                            * (1.0 - eb)
                            * (p_below * n_below as f64 + p_above * n_above as f64);
                    if cost < best_cost {
                        best_cost = cost;
                        best = Some((axis, i));
                    }
                }
                if !e.is_end {
                    n_below += 1;
                }
            }
            if best.is_some() {
                break;
            }
            axis = (axis + 1) % 3;
        }
        if best_cost > old_cost {
            bad_refines += 1;
        }
        let Some((axis, best_offset)) = best else {
            self.make_leaf(prims);
            return;
        };
        if (best_cost > 4.0 * old_cost && n < 16) || bad_refines == 3 {
            self.make_leaf(prims);
            return;
        }
        // Classify by the chosen edge (pbrt-v3): the sort is deterministic,
        // so refilling reproduces the sweep's order. A primitive is below if
        // it starts before the split edge, above if it ends after it.
        self.fill_edges(prims, axis);
        let t_split = self.edges[best_offset].t;
        let mut below = Vec::new();
        let mut above = Vec::new();
        for (i, e) in self.edges.iter().enumerate() {
            if i < best_offset && !e.is_end {
                below.push(e.prim);
            } else if i > best_offset && e.is_end {
                above.push(e.prim);
            }
        }
        let mut b0 = *node_bounds;
        let mut b1 = *node_bounds;
        b0.p_max[axis] = t_split;
        b1.p_min[axis] = t_split;
        let node = self.nodes.len();
        self.nodes.push(KdNode { data: 0, flags: 0 });
        self.build(&b0, &below, depth - 1, bad_refines);
        let above_idx = self.nodes.len() as u32;
        self.nodes[node] = KdNode {
            data: t_split.to_bits(),
            flags: axis as u32 | (above_idx << 2),
        };
        self.build(&b1, &above, depth - 1, bad_refines);
    }
}

impl KdTree {
    /// Builds a kd-tree over `prim_bounds`.
    pub fn build(prim_bounds: &[Bounds3f], params: &KdTreeParams) -> KdTree {
        let prims: Vec<u32> = (0..prim_bounds.len() as u32)
            .filter(|&i| usable_bounds(&prim_bounds[i as usize]))
            .collect();
        let bounds = prims
            .iter()
            .fold(Bounds3f::empty(), |b, &i| b.union(&prim_bounds[i as usize]));
        let mut tree = KdTree {
            nodes: Vec::new(),
            prim_indices: Vec::new(),
            bounds,
            n_input: prim_bounds.len(),
            n_skipped: prim_bounds.len() - prims.len(),
        };
        if prims.is_empty() {
            return tree;
        }
        let max_depth = params
            .max_depth
            .unwrap_or_else(|| (8.0 + 1.3 * (prims.len() as f64).log2().floor()).round() as u32)
            .min(STACK_SIZE as u32);
        let mut b = KdBuilder {
            params,
            prim_bounds,
            nodes: Vec::new(),
            prim_indices: Vec::new(),
            edges: Vec::with_capacity(2 * prims.len()),
        };
        b.build(&bounds, &prims, max_depth, 0);
        b.nodes.shrink_to_fit();
        b.prim_indices.shrink_to_fit();
        tree.nodes = b.nodes;
        tree.prim_indices = b.prim_indices;
        tree
    }

    /// The nodes (root first; empty when there are no primitives).
    pub fn nodes(&self) -> &[KdNode] {
        &self.nodes
    }

    #[inline(always)]
    fn leaf_prims<'s>(&'s self, node: &'s KdNode) -> &'s [u32] {
        match node.upper() {
            0 => &[],
            1 => std::slice::from_ref(&node.data),
            n => &self.prim_indices[node.data as usize..(node.data + n) as usize],
        }
    }

    /// The shared traversal: calls `leaf(prims, t_best)` for each leaf in
    /// front-to-back order; `leaf` returns the new best distance, or `None`
    /// to stop at once.
    #[inline(always)]
    fn traverse(
        &self,
        ray: &Ray,
        t_max: Float,
        mut leaf: impl FnMut(&[u32], Float) -> Option<Float>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let pre = RayPrecomp::new(ray);
        let lo = [
            self.bounds.p_min.x,
            self.bounds.p_min.y,
            self.bounds.p_min.z,
        ];
        let hi = [
            self.bounds.p_max.x,
            self.bounds.p_max.y,
            self.bounds.p_max.z,
        ];
        let Some((mut t_min, mut t_far)) = pre.slab(&lo, &hi, t_max) else {
            return;
        };
        let d = [ray.d.x, ray.d.y, ray.d.z];
        let pad = far_pad();
        let mut t_best = t_max;
        let mut stack = [(0u32, 0.0 as Float, 0.0 as Float); STACK_SIZE];
        let mut sp = 0;
        let mut idx = 0usize;
        loop {
            // A hit before this node's range is final for the node. Stack
            // entries usually have decreasing entry distances (pbrt stops
            // here), but a ray lying in a split plane pushes its far side
            // with the near side's range, so keep popping instead.
            let skip = t_best * pad < t_min;
            let node = &self.nodes[idx];
            if !skip && !node.is_leaf() {
                let axis = node.axis();
                let split = node.split();
                let o = pre.o[axis];
                let below_first = o < split || (o == split && d[axis] <= 0.0);
                let (first, second) = if below_first {
                    (idx as u32 + 1, node.upper())
                } else {
                    (node.upper(), idx as u32 + 1)
                };
                if o == split && d[axis] == 0.0 {
                    // The ray lies in the plane: both sides, same range.
                    stack[sp] = (second, t_min, t_far);
                    sp += 1;
                    idx = first as usize;
                    continue;
                }
                let t_plane = (split - o) * pre.inv_dir[axis];
                // The comparisons are padded like the slab test: near a
                // plane both sides are visited, as rounding could put a hit
                // on either.
                if t_plane > t_far * pad || t_plane <= 0.0 {
                    idx = first as usize;
                } else if t_plane * pad < t_min {
                    idx = second as usize;
                } else {
                    stack[sp] = (second, t_plane, t_far);
                    sp += 1;
                    idx = first as usize;
                    t_far = t_plane;
                }
                continue;
            } else if !skip {
                match leaf(self.leaf_prims(node), t_best) {
                    Some(t) => t_best = t,
                    None => return,
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (i, a, b) = stack[sp];
            idx = i as usize;
            t_min = a;
            t_far = b;
        }
    }
}

impl Aggregate for KdTree {
    fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    #[inline]
    fn intersect<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>,
    {
        let mut best = None;
        self.traverse(ray, t_max, |prims, mut t_best| {
            for &p in prims {
                if let Some(t) = hit(p, ray, t_best) {
                    t_best = t;
                    best = Some((p, t));
                }
            }
            Some(t_best)
        });
        best
    }

    #[inline]
    fn intersect_p<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> bool
    where
        F: FnMut(u32, &Ray, Float) -> bool,
    {
        let mut found = false;
        self.traverse(ray, t_max, |prims, t_best| {
            for &p in prims {
                if hit(p, ray, t_max) {
                    found = true;
                    return None;
                }
            }
            Some(t_best)
        });
        found
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.nodes.capacity() * std::mem::size_of::<KdNode>()
            + self.prim_indices.capacity() * 4
    }

    fn primitive_count(&self) -> usize {
        self.n_input
    }

    fn skipped_primitives(&self) -> usize {
        self.n_skipped
    }
}
