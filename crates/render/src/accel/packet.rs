//! Packet traversal of the wide BVHs: up to [`MAX_PACKET`] rays walk the
//! tree together, each node's boxes tested against all of them at once,
//! one ray per SIMD lane (Wald, Slusallek and Benthin 2001, "Interactive
//! rendering with coherent ray tracing"; Embree's `rtcIntersect8/16`).
//! Written once over [`F32Lanes`] and run at the processor's width by
//! [`crate::simd::dispatch`]; the scalar one-lane form is the reference.
//!
//! Each ray's box tests compute exactly what [`WideBvh`]'s single-ray test
//! computes (the same planes, nudged origins and far-plane padding), so a
//! ray enters the same boxes either way; its leaves are tested with the
//! caller's closure as the single-ray traversal tests them. Only the order
//! in which a ray meets its leaves can differ, which matters for no hit
//! but an exact tie in distance between two primitives. Packets pay when
//! their rays are coherent (camera rays through nearby pixels); a node is
//! visited when any active ray enters it, and popped entries are culled
//! per lane against each ray's closest hit so far.
//!
//! Where the caller gives the slots' triangles
//! ([`WideBvh::intersect_packet_triangles`]), a leaf's triangles are
//! tested against all the rays entering it at once
//! ([`TriangleRayLanes`], the scalar watertight test in lanes: the same
//! hits), in the leaf's order, so each ray meets them in the order the
//! single-ray traversal does; other primitives take the closure per ray.

use super::far_pad;
use super::widebvh::{closest_in_leaf, WideBvh};
use crate::shape::triangle::TriangleRay;
use crate::shape::triangle_lanes::TriangleRayLanes;
use crate::simd::{F32Lanes, Kernel, MAX_LANES};
use rpbrt_geometry::{next_float_down, next_float_up, Float, Point3f, Ray};
use std::mem::MaybeUninit;

/// The most rays a packet holds (the widest lane count).
pub const MAX_PACKET: usize = 16;

/// Entries the packet stack holds: as the single-ray traversal's.
const PACKET_STACK: usize = 7 * super::bvh::STACK_SIZE + 1;

/// The closest hits of a packet of rays, as [`super::Aggregate::intersect_slots`]
/// finds them for each ray alone: `hit(lane, slot, entry, ray, t_max)`
/// tests entry `entry` (at slot `slot`) against ray `lane`; `t_max[lane]`
/// starts as the ray's bound and ends as its closest hit's distance, and
/// `best[lane]` receives the hit entry and distance.
pub(crate) struct PacketClosest<'a, const W: usize, F> {
    pub bvh: &'a WideBvh<W>,
    pub rays: &'a [Ray],
    pub t_max: &'a mut [Float],
    pub best: &'a mut [Option<(u32, Float)>],
    /// The vertices of the triangle at each slot (`None` for other
    /// primitives; empty when the caller gives none): these are tested
    /// in lanes, without the closure.
    pub tris: &'a [Option<[Point3f; 3]>],
    /// Per ray: the barycentrics of its closest hit where that hit is one
    /// of `tris`, `None` where the closure found it (or there is none).
    pub bary: &'a mut [Option<[Float; 3]>],
    pub hit: F,
}

impl<const W: usize, F> Kernel for PacketClosest<'_, W, F>
where
    F: FnMut(usize, u32, u32, &Ray, Float) -> Option<Float>,
{
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(mut self) {
        let n = self.rays.len();
        assert!(
            n <= MAX_PACKET
                && self.t_max.len() >= n
                && self.best.len() >= n
                && self.bary.len() >= n
        );
        // Rays beyond the lane count go in further packets.
        let mut first = 0;
        while first < n {
            let end = (first + L::N).min(n);
            packet_closest::<W, L, F>(
                self.bvh,
                &self.rays[first..end],
                &mut self.t_max[first..end],
                &mut self.best[first..end],
                self.tris,
                &mut self.bary[first..end],
                first,
                &mut self.hit,
            );
            first = end;
        }
    }
}

/// The per-lane ray values of the slab test, as `WideRay` computes them
/// for one ray: origins nudged for zero direction components (min planes
/// against the origin one ulp up, max planes one ulp down) and the
/// reciprocal direction.
struct PacketRays<L: F32Lanes> {
    o_lo: [L; 3],
    o_hi: [L; 3],
    inv: [L; 3],
    neg: [L::Mask; 3],
}

/// The slab planes of a packet whose rays all share their direction
/// signs: per axis, the row of the near and far plane and the origins
/// they are tested against.
struct Octant<L: F32Lanes> {
    near: [usize; 3],
    far: [usize; 3],
    o_near: [L; 3],
    o_far: [L; 3],
}

#[inline(always)]
fn packet_rays<L: F32Lanes>(rays: &[Ray]) -> PacketRays<L> {
    let mut o_lo = [[0.0 as Float; MAX_PACKET]; 3];
    let mut o_hi = [[0.0 as Float; MAX_PACKET]; 3];
    // Unused lanes: a NaN reciprocal enters no box.
    let mut inv = [[Float::NAN; MAX_PACKET]; 3];
    for (i, r) in rays.iter().enumerate() {
        let o = [r.o.x, r.o.y, r.o.z];
        let d = [r.d.x, r.d.y, r.d.z];
        for a in 0..3 {
            inv[a][i] = 1.0 / d[a];
            if d[a] == 0.0 {
                o_lo[a][i] = next_float_up(o[a]);
                o_hi[a][i] = next_float_down(o[a]);
            } else {
                o_lo[a][i] = o[a];
                o_hi[a][i] = o[a];
            }
        }
    }
    let zero = L::splat(0.0);
    let load = |v: &[Float; MAX_PACKET]| L::load(v);
    let inv = [load(&inv[0]), load(&inv[1]), load(&inv[2])];
    PacketRays {
        o_lo: [load(&o_lo[0]), load(&o_lo[1]), load(&o_lo[2])],
        o_hi: [load(&o_hi[0]), load(&o_hi[1]), load(&o_hi[2])],
        neg: [inv[0].lt(zero), inv[1].lt(zero), inv[2].lt(zero)],
        inv,
    }
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn packet_closest<const W: usize, L: F32Lanes, F>(
    bvh: &WideBvh<W>,
    rays: &[Ray],
    t_max: &mut [Float],
    best: &mut [Option<(u32, Float)>],
    tris: &[Option<[Point3f; 3]>],
    bary: &mut [Option<[Float; 3]>],
    lane_offset: usize,
    hit: &mut F,
) where
    F: FnMut(usize, u32, u32, &Ray, Float) -> Option<Float>,
{
    let nodes = bvh.nodes();
    if nodes.is_empty() || rays.is_empty() {
        return;
    }
    let prims = bvh.prim_indices();
    let pr = packet_rays::<L>(rays);
    let mut trs = [TriangleRay::new(&rays[0]); MAX_PACKET];
    for (t, r) in trs.iter_mut().zip(rays) {
        *t = TriangleRay::new(r);
    }
    let tri_lanes = TriangleRayLanes::<L>::new(&trs[..rays.len()]);
    let mut t_max_lanes = [Float::NEG_INFINITY; MAX_PACKET];
    t_max_lanes[..rays.len()].copy_from_slice(t_max);
    let mut t_max_v = L::load(&t_max_lanes);
    let pad = L::splat(far_pad());
    let zero = L::splat(0.0);
    let inf = L::splat(Float::INFINITY);
    let all = (1u32 << rays.len()) - 1;
    let mut active = L::from_bits(all);
    // Packets whose rays share their direction signs (camera rays through
    // nearby pixels) take the near and far planes without a per-lane
    // select.
    let octant = {
        let signs = [0, 1, 2].map(|a| L::bits(pr.neg[a]) & all);
        if signs.iter().all(|&s| s == 0 || s == all) {
            let neg = signs.map(|s| s != 0);
            Some(Octant::<L> {
                near: [0, 1, 2].map(|a| if neg[a] { 3 + a } else { a }),
                far: [0, 1, 2].map(|a| if neg[a] { a } else { 3 + a }),
                o_near: [0, 1, 2].map(|a| if neg[a] { pr.o_hi[a] } else { pr.o_lo[a] }),
                o_far: [0, 1, 2].map(|a| if neg[a] { pr.o_lo[a] } else { pr.o_hi[a] }),
            })
        } else {
            None
        }
    };
    let mut stack: [MaybeUninit<(u32, L)>; PACKET_STACK] =
        [const { MaybeUninit::uninit() }; PACKET_STACK];
    let mut sp = 0usize;
    let mut cur = 0u32;
    loop {
        let node = &nodes[cur as usize];
        let b = &node.bounds;
        let mut t_near = [zero; W];
        let mut hit_bits = [0u32; W];
        for c in 0..W {
            let mut t0 = zero;
            let mut t1 = t_max_v;
            if let Some(oct) = &octant {
                // Every ray enters each slab by the same plane: the
                // single-ray test's planes, chosen once per packet.
                for a in 0..3 {
                    let near = L::splat(b[oct.near[a]][c])
                        .sub(oct.o_near[a])
                        .mul(pr.inv[a]);
                    let far = L::splat(b[oct.far[a]][c]).sub(oct.o_far[a]).mul(pr.inv[a]);
                    t0 = t0.max(near);
                    t1 = t1.min(far.mul(pad));
                }
            } else {
                for a in 0..3 {
                    let t_lo = L::splat(b[a][c]).sub(pr.o_lo[a]).mul(pr.inv[a]);
                    let t_hi = L::splat(b[3 + a][c]).sub(pr.o_hi[a]).mul(pr.inv[a]);
                    let near = L::select(pr.neg[a], t_hi, t_lo);
                    let far = L::select(pr.neg[a], t_lo, t_hi).mul(pad);
                    t0 = t0.max(near);
                    t1 = t1.min(far);
                }
            }
            let m = L::and(t0.le(t1), active);
            hit_bits[c] = L::bits(m);
            t_near[c] = L::select(m, t0, inf);
        }
        let entered = (0..W).fold(0, |m, c| m | (((hit_bits[c] != 0) as u32) << c));
        bvh.prefetch_children(node, entered);
        // Leaf children, in lane order, each against the rays that enter it.
        let mut leaves = node.leaf_lanes;
        let mut leaf_hit = false;
        while leaves != 0 {
            let c = leaves.trailing_zeros() as usize;
            leaves &= leaves - 1;
            let mut lanes = hit_bits[c];
            if lanes == 0 {
                continue;
            }
            leaf_hit = true;
            let start = node.child[c] as usize;
            let count = node.count[c] as usize;
            if !tris.is_empty() {
                leaf_lanes(
                    &tri_lanes,
                    &prims[start..start + count],
                    start,
                    lanes,
                    rays,
                    t_max,
                    best,
                    tris,
                    bary,
                    lane_offset,
                    hit,
                );
                continue;
            }
            while lanes != 0 {
                let i = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                closest_in_leaf(
                    &prims[start..start + count],
                    start as u32,
                    &rays[i],
                    &mut t_max[i],
                    &mut best[i],
                    &mut |slot, entry, ray: &Ray, t| hit(lane_offset + i, slot, entry, ray, t),
                );
            }
        }
        if leaf_hit {
            t_max_lanes[..rays.len()].copy_from_slice(t_max);
            t_max_v = L::load(&t_max_lanes);
        }
        // Interior children entered by some ray: ordered by their entry
        // distance for the first such ray, nearest visited next.
        let mut inner = [(0u32, 0.0 as Float, zero); W];
        let mut n_inner = 0;
        for c in 0..W {
            let bits = hit_bits[c];
            if bits == 0 || node.leaf_lanes & (1 << c) != 0 {
                continue;
            }
            let mut lanes = [0.0 as Float; MAX_PACKET];
            t_near[c].store(&mut lanes);
            let key = lanes[bits.trailing_zeros() as usize];
            let mut j = n_inner;
            while j > 0 && inner[j - 1].1 < key {
                inner[j] = inner[j - 1];
                j -= 1;
            }
            inner[j] = (node.child[c], key, t_near[c]);
            n_inner += 1;
        }
        // Pushed far to near (sorted far first above); then pop the next
        // entry some ray may still need.
        for &(child, _, tn) in &inner[..n_inner] {
            stack[sp] = MaybeUninit::new((child, tn));
            sp += 1;
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: slots below `sp` were written by the pushes above
            // (written in order, `sp` counts them).
            let (child, tn) = unsafe { stack[sp].assume_init() };
            let m = tn.le(t_max_v);
            if L::bits(m) != 0 {
                active = m;
                cur = child;
                break;
            }
        }
    }
}

/// One leaf (its entries `leaf`, the first at slot `start`) against the
/// rays in `lanes`: each triangle of `tris` against all of them at once,
/// other entries with the closure ray by ray, in the leaf's order.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn leaf_lanes<L: F32Lanes, F>(
    tri_lanes: &TriangleRayLanes<L>,
    leaf: &[u32],
    start: usize,
    lanes: u32,
    rays: &[Ray],
    t_max: &mut [Float],
    best: &mut [Option<(u32, Float)>],
    tris: &[Option<[Point3f; 3]>],
    bary: &mut [Option<[Float; 3]>],
    lane_offset: usize,
    hit: &mut F,
) where
    F: FnMut(usize, u32, u32, &Ray, Float) -> Option<Float>,
{
    let mut t_lanes = [Float::INFINITY; MAX_LANES];
    t_lanes[..rays.len()].copy_from_slice(t_max);
    let mut t_v = L::load(&t_lanes);
    let active = L::from_bits(lanes);
    for (k, &entry) in leaf.iter().enumerate() {
        let slot = start + k;
        if let Some(Some([p0, p1, p2])) = tris.get(slot) {
            let h = tri_lanes.intersect(active, t_v, *p0, *p1, *p2);
            let mut bits = L::bits(h.mask);
            if bits == 0 {
                continue;
            }
            t_v = L::select(h.mask, h.t, t_v);
            let mut t = [0.0 as Float; MAX_LANES];
            let mut b = [[0.0 as Float; MAX_LANES]; 3];
            h.t.store(&mut t);
            for (row, v) in b.iter_mut().zip(h.b) {
                v.store(row);
            }
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                t_max[i] = t[i];
                best[i] = Some((entry, t[i]));
                bary[i] = Some([b[0][i], b[1][i], b[2][i]]);
            }
        } else {
            let mut bits = lanes;
            let mut any = false;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if let Some(t) = hit(lane_offset + i, slot as u32, entry, &rays[i], t_max[i]) {
                    t_max[i] = t;
                    best[i] = Some((entry, t));
                    bary[i] = None;
                    any = true;
                }
            }
            if any {
                t_lanes[..rays.len()].copy_from_slice(t_max);
                t_v = L::load(&t_lanes);
            }
        }
    }
}

impl<const W: usize> WideBvh<W> {
    /// The closest hits of up to [`MAX_PACKET`] rays traced as packets of
    /// `level`'s width (see the module documentation):
    /// `hit(lane, slot, entry, ray, t_max)` as for
    /// [`super::Aggregate::intersect_slots`], with the ray's index in
    /// `rays`. `t_max` holds each ray's bound and receives its closest
    /// hit's distance; `best` receives each ray's hit entry and distance.
    pub fn intersect_packet<F>(
        &self,
        level: crate::simd::SimdLevel,
        rays: &[Ray],
        t_max: &mut [Float],
        best: &mut [Option<(u32, Float)>],
        hit: F,
    ) where
        F: FnMut(usize, u32, u32, &Ray, Float) -> Option<Float>,
    {
        let mut bary = [None; MAX_PACKET];
        let n = rays.len().min(MAX_PACKET);
        self.intersect_packet_triangles(level, rays, t_max, best, &[], &mut bary[..n], hit);
    }

    /// [`WideBvh::intersect_packet`] where `tris` gives the vertices of
    /// the triangle at each slot (`None` for other primitives): those are
    /// tested in lanes, the closure is called for the others only, and
    /// `bary` receives each ray's barycentrics where its closest hit is
    /// one of `tris`.
    #[allow(clippy::too_many_arguments)]
    pub fn intersect_packet_triangles<F>(
        &self,
        level: crate::simd::SimdLevel,
        rays: &[Ray],
        t_max: &mut [Float],
        best: &mut [Option<(u32, Float)>],
        tris: &[Option<[Point3f; 3]>],
        bary: &mut [Option<[Float; 3]>],
        hit: F,
    ) where
        F: FnMut(usize, u32, u32, &Ray, Float) -> Option<Float>,
    {
        crate::simd::dispatch(
            level,
            PacketClosest {
                bvh: self,
                rays,
                t_max,
                best,
                tris,
                bary,
                hit,
            },
        );
    }
}
