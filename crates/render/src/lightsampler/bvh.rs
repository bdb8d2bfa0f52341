//! pbrt-v4's `BVHLightSampler` (book section 12.6.3): infinite lights are
//! chosen with probability `pInfinite`, the others by descending a BVH
//! over their [`LightBounds`], choosing each child in proportion to its
//! importance at the reference point. Each light's path from the root is
//! stored as a bit trail so that [`BvhLightSampler::pmf`] retraces exactly
//! the choices [`BvhLightSampler::sample`] makes.

use rpbrt_geometry::{safe_acos, Bounds3f, Float, Normal3f, Point3f, PI};

use super::{SampledLight, ONE_MINUS_EPSILON};
use crate::light::{
    importance2, importance_lanes, importance_lanes_uniform, Light, LightBounds,
    LightSampleContext, PreparedLightBounds,
};
use crate::select::select_f32;
use crate::simd::{F32Lanes, Kernel, SimdLevel, MAX_LANES};

/// Number of buckets per axis for the split heuristic.
const N_BUCKETS: usize = 12;
/// Beyond this depth splits are forced to the median, so bit trails fit.
const MAX_SAH_DEPTH: u32 = 40;

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: PreparedLightBounds,
    /// Second child for interior nodes (the first follows the node);
    /// the light's index for leaves.
    child_or_light: u32,
    is_leaf: bool,
}

/// Where a light sits for the sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// Sampled with the infinite lights.
    Infinite,
    /// A BVH leaf reached by this bit trail (bit d: child taken at depth d).
    Bvh(u64),
    /// Bounded with zero power: never sampled.
    Never,
}

/// The BVH light sampler.
#[derive(Clone, Debug)]
pub struct BvhLightSampler {
    n_lights: usize,
    infinite_lights: Vec<u32>,
    nodes: Vec<Node>,
    slots: Vec<Slot>,
}

/// pbrt-v4's `EvaluateCost`: power × the M_Ω measure of the direction
/// cone × surface area, scaled by the box's aspect along `dim`. Empty
/// bounds (zero power) make the split invalid.
fn evaluate_cost(b: &LightBounds, bounds: &Bounds3f, dim: usize) -> Float {
    if b.phi == 0.0 {
        return Float::INFINITY;
    }
    let theta_o = safe_acos(b.cos_theta_o);
    let theta_e = safe_acos(b.cos_theta_e);
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_theta_o = (1.0 - b.cos_theta_o * b.cos_theta_o).max(0.0).sqrt();
    let m_omega = 2.0 * PI * (1.0 - b.cos_theta_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_theta_o
                - (theta_o - 2.0 * theta_w).cos()
                - 2.0 * theta_o * sin_theta_o
                + b.cos_theta_o);
    let d = bounds.diagonal();
    let kr = d.x.max(d.y).max(d.z) / d[dim];
    b.phi * m_omega * kr * b.bounds.surface_area()
}

fn bucket_of(centroid_bounds: &Bounds3f, p: Point3f, dim: usize) -> usize {
    let o = centroid_bounds.offset(p)[dim];
    ((N_BUCKETS as Float * o) as usize).min(N_BUCKETS - 1)
}

impl BvhLightSampler {
    /// Builds the BVH over the bounded lights of `lights`.
    pub fn new(lights: &[Light]) -> Self {
        let mut s = BvhLightSampler {
            n_lights: lights.len(),
            infinite_lights: Vec::new(),
            nodes: Vec::new(),
            slots: vec![Slot::Never; lights.len()],
        };
        let mut bvh_lights: Vec<(u32, LightBounds)> = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            match l.bounds() {
                None => {
                    s.infinite_lights.push(i as u32);
                    s.slots[i] = Slot::Infinite;
                }
                Some(lb) if lb.phi > 0.0 => bvh_lights.push((i as u32, lb)),
                Some(_) => {}
            }
        }
        if !bvh_lights.is_empty() {
            s.build(&mut bvh_lights, 0, 0);
        }
        s
    }

    /// Builds the subtree for `lights`, returning its bounds.
    fn build(
        &mut self,
        lights: &mut [(u32, LightBounds)],
        bit_trail: u64,
        depth: u32,
    ) -> LightBounds {
        debug_assert!(!lights.is_empty());
        if lights.len() == 1 {
            let (li, lb) = lights[0];
            self.nodes.push(Node {
                bounds: PreparedLightBounds::new(&lb),
                child_or_light: li,
                is_leaf: true,
            });
            self.slots[li as usize] = Slot::Bvh(bit_trail);
            return lb;
        }
        let mut bounds = lights[0].1.bounds;
        let mut centroid_bounds = Bounds3f::from_point(lights[0].1.centroid());
        for (_, lb) in lights.iter() {
            bounds = bounds.union(&lb.bounds);
            centroid_bounds = centroid_bounds.union_point(lb.centroid());
        }

        let mut min_cost = Float::INFINITY;
        let mut split: Option<(usize, usize)> = None;
        if depth < MAX_SAH_DEPTH {
            for dim in 0..3 {
                if centroid_bounds.p_max[dim] == centroid_bounds.p_min[dim] {
                    continue;
                }
                let mut buckets = [LightBounds::default(); N_BUCKETS];
                for (_, lb) in lights.iter() {
                    let b = bucket_of(&centroid_bounds, lb.centroid(), dim);
                    buckets[b] = LightBounds::union(&buckets[b], lb);
                }
                for i in 1..N_BUCKETS - 1 {
                    let b0 = buckets[..=i]
                        .iter()
                        .fold(LightBounds::default(), |a, b| LightBounds::union(&a, b));
                    let b1 = buckets[i + 1..]
                        .iter()
                        .fold(LightBounds::default(), |a, b| LightBounds::union(&a, b));
                    let cost = evaluate_cost(&b0, &bounds, dim) + evaluate_cost(&b1, &bounds, dim);
                    if cost > 0.0 && cost < min_cost {
                        min_cost = cost;
                        split = Some((dim, i));
                    }
                }
            }
        }
        let n = lights.len();
        let mut mid = n / 2;
        if let Some((dim, bucket)) = split {
            let (lo, hi): (Vec<_>, Vec<_>) = lights
                .iter()
                .partition(|(_, lb)| bucket_of(&centroid_bounds, lb.centroid(), dim) <= bucket);
            let m = lo.len();
            if m > 0 && m < n {
                for (dst, src) in lights.iter_mut().zip(lo.into_iter().chain(hi)) {
                    *dst = src;
                }
                mid = m;
            }
        }

        let node_index = self.nodes.len();
        self.nodes.push(Node {
            bounds: PreparedLightBounds::default(),
            child_or_light: 0,
            is_leaf: false,
        });
        let (left, right) = lights.split_at_mut(mid);
        let b0 = self.build(left, bit_trail, depth + 1);
        let child1 = self.nodes.len() as u32;
        let b1 = self.build(right, bit_trail | (1u64 << depth), depth + 1);
        let lb = LightBounds::union(&b0, &b1);
        self.nodes[node_index] = Node {
            bounds: PreparedLightBounds::new(&lb),
            child_or_light: child1,
            is_leaf: false,
        };
        lb
    }

    fn p_infinite(&self) -> Float {
        let ni = self.infinite_lights.len() as Float;
        ni / (ni + if self.nodes.is_empty() { 0.0 } else { 1.0 })
    }

    /// Chooses a light for `ctx` with `u` in [0, 1).
    pub fn sample(&self, ctx: &LightSampleContext, u: Float) -> Option<SampledLight> {
        self.sample_at(ctx.p(), ctx.ns, u)
    }

    /// [`sample`](Self::sample) at point `p` with shading normal `n`.
    #[inline]
    fn sample_at(&self, p: Point3f, n: Normal3f, u: Float) -> Option<SampledLight> {
        let p_inf = self.p_infinite();
        if u < p_inf {
            let n = self.infinite_lights.len();
            let u = (u / p_inf).min(ONE_MINUS_EPSILON);
            let index = ((u * n as Float) as usize).min(n - 1);
            return Some(SampledLight {
                light: self.infinite_lights[index],
                p: p_inf / n as Float,
            });
        }
        if self.nodes.is_empty() {
            return None;
        }
        let mut u = ((u - p_inf) / (1.0 - p_inf)).min(ONE_MINUS_EPSILON);
        let mut node_index = 0usize;
        let mut pmf = 1.0 - p_inf;
        loop {
            let node = &self.nodes[node_index];
            if node.is_leaf {
                if node_index > 0 || node.bounds.importance(p, n) > 0.0 {
                    return Some(SampledLight {
                        light: node.child_or_light,
                        p: pmf,
                    });
                }
                return None;
            }
            let c1 = node.child_or_light as usize;
            let [ci0, ci1] = importance2(
                &self.nodes[node_index + 1].bounds,
                &self.nodes[c1].bounds,
                p,
                n,
            );
            if ci0 == 0.0 && ci1 == 0.0 {
                return None;
            }
            let p0 = ci0 / (ci0 + ci1);
            // Both outcomes computed and one selected: which child is taken
            // is as random as `u`, so a branch would often mispredict.
            let first = u < p0;
            let p1 = 1.0 - p0;
            pmf *= select_f32(first, p0, ci1 / (ci0 + ci1));
            u = select_f32(first, u / p0, (u - p0) / p1).min(ONE_MINUS_EPSILON);
            node_index = std::hint::select_unpredictable(first, node_index + 1, c1);
        }
    }

    /// [`sample`](Self::sample) of every query in `queries` (its point,
    /// shading normal and sample), into `out` (cleared first), bit for
    /// bit: the descent through the tree's interior nodes runs at
    /// `level`'s width, each lane at its own node, the importance of both
    /// children of every lane's node evaluated together
    /// ([`importance_lanes`]). (One sample's descent is a chain of square
    /// roots and divisions, each waiting on the last: lanes run the chains
    /// of many side by side.)
    pub fn sample_batch(
        &self,
        level: SimdLevel,
        queries: &[LightChoice],
        out: &mut Vec<Option<SampledLight>>,
    ) {
        out.clear();
        out.resize(queries.len(), None);
        crate::simd::dispatch(
            level,
            SampleBatch {
                sampler: self,
                queries,
                out,
            },
        );
    }

    /// The probability that [`sample`](Self::sample) chooses `light` at
    /// `ctx`, retracing its bit trail.
    pub fn pmf(&self, ctx: &LightSampleContext, light: u32) -> Float {
        let Some(slot) = self.slots.get(light as usize) else {
            return 0.0;
        };
        let mut bit_trail = match *slot {
            Slot::Never => return 0.0,
            Slot::Infinite => {
                return 1.0
                    / (self.infinite_lights.len() as Float
                        + if self.nodes.is_empty() { 0.0 } else { 1.0 })
            }
            Slot::Bvh(b) => b,
        };
        let p = ctx.p();
        let n = ctx.ns;
        let mut pmf = 1.0 - self.p_infinite();
        let mut node_index = 0usize;
        loop {
            let node = &self.nodes[node_index];
            if node.is_leaf {
                if node_index == 0 && node.bounds.importance(p, n) <= 0.0 {
                    return 0.0;
                }
                return pmf;
            }
            let c1 = node.child_or_light as usize;
            let [ci0, ci1] = importance2(
                &self.nodes[node_index + 1].bounds,
                &self.nodes[c1].bounds,
                p,
                n,
            );
            let sum = ci0 + ci1;
            if sum == 0.0 {
                return 0.0;
            }
            let take_second = bit_trail & 1 == 1;
            pmf *= if take_second { ci1 } else { ci0 } / sum;
            if pmf == 0.0 {
                return 0.0;
            }
            node_index = if take_second { c1 } else { node_index + 1 };
            bit_trail >>= 1;
        }
    }

    /// Uniform choice over all lights (pbrt-v4's context-free sampling).
    pub fn sample_no_ctx(&self, u: Float) -> Option<SampledLight> {
        if self.n_lights == 0 {
            return None;
        }
        let i = ((u * self.n_lights as Float) as usize).min(self.n_lights - 1);
        Some(SampledLight {
            light: i as u32,
            p: 1.0 / self.n_lights as Float,
        })
    }

    /// The probability of [`sample_no_ctx`](Self::sample_no_ctx) choosing
    /// `light`.
    pub fn pmf_no_ctx(&self, light: u32) -> Float {
        if (light as usize) < self.n_lights {
            1.0 / self.n_lights as Float
        } else {
            0.0
        }
    }

    /// Number of BVH nodes (for tests and statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

/// One query of [`BvhLightSampler::sample_batch`]: a reference point, its
/// shading normal (zero in a medium) and the sample in [0, 1).
#[derive(Clone, Copy, Debug)]
pub struct LightChoice {
    /// The reference point ([`LightSampleContext::p`]).
    pub p: Point3f,
    /// Its shading normal ([`LightSampleContext::ns`]).
    pub n: Normal3f,
    /// The sample.
    pub u: Float,
}

impl LightChoice {
    /// The query of `ctx` with sample `u`.
    #[inline]
    pub fn new(ctx: &LightSampleContext, u: Float) -> Self {
        LightChoice {
            p: ctx.p(),
            n: ctx.ns,
            u,
        }
    }
}

/// [`BvhLightSampler::sample_batch`] at one width.
struct SampleBatch<'a> {
    sampler: &'a BvhLightSampler,
    queries: &'a [LightChoice],
    out: &'a mut [Option<SampledLight>],
}

impl Kernel for SampleBatch<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let s = self.sampler;
        let p_inf = s.p_infinite();
        for (queries, out) in self.queries.chunks(L::N).zip(self.out.chunks_mut(L::N)) {
            // Lanes descending the tree: their node, remapped sample and
            // probability so far. Infinite lights and a tree of one light
            // take the single sample's path.
            let mut node = [0usize; MAX_LANES];
            let mut u = [0.0 as Float; MAX_LANES];
            let mut pmf = [0.0 as Float; MAX_LANES];
            let mut active = 0u32;
            for (i, q) in queries.iter().enumerate() {
                if q.u < p_inf || s.nodes.first().is_none_or(|root| root.is_leaf) {
                    out[i] = s.sample_at(q.p, q.n, q.u);
                } else {
                    u[i] = ((q.u - p_inf) / (1.0 - p_inf)).min(ONE_MINUS_EPSILON);
                    pmf[i] = 1.0 - p_inf;
                    active |= 1 << i;
                }
            }
            if active == 0 {
                continue;
            }
            let mut rows = [[0.0 as Float; MAX_LANES]; 6];
            for (i, q) in queries.iter().enumerate() {
                for (row, x) in rows
                    .iter_mut()
                    .zip([q.p.x, q.p.y, q.p.z, q.n.x, q.n.y, q.n.z])
                {
                    row[i] = x;
                }
            }
            let p = [L::load(&rows[0]), L::load(&rows[1]), L::load(&rows[2])];
            let n = [L::load(&rows[3]), L::load(&rows[4]), L::load(&rows[5])];
            let empty = PreparedLightBounds::default();
            while active != 0 {
                // Every lane's node is interior: its two children.
                // Lanes at one node (all of them at the root, most of
                // them near it) read its children's bounds once.
                let first = node[active.trailing_zeros() as usize];
                let mut uniform = true;
                let mut bits = active;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    uniform &= node[i] == first;
                }
                let (ci0, ci1) = if uniform {
                    let c1 = s.nodes[first].child_or_light as usize;
                    (
                        importance_lanes_uniform::<L>(&s.nodes[first + 1].bounds, &p, &n),
                        importance_lanes_uniform::<L>(&s.nodes[c1].bounds, &p, &n),
                    )
                } else {
                    let mut b0 = [&empty; MAX_LANES];
                    let mut b1 = [&empty; MAX_LANES];
                    let mut bits = active;
                    while bits != 0 {
                        let i = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let c1 = s.nodes[node[i]].child_or_light as usize;
                        b0[i] = &s.nodes[node[i] + 1].bounds;
                        b1[i] = &s.nodes[c1].bounds;
                    }
                    (
                        importance_lanes::<L>(&b0[..L::N], &p, &n),
                        importance_lanes::<L>(&b1[..L::N], &p, &n),
                    )
                };
                // The single sample's arithmetic, lane-wise.
                let (uv, pmfv) = (L::load(&u), L::load(&pmf));
                let sum = ci0.add(ci1);
                let p0 = ci0.div(sum);
                let first = uv.lt(p0);
                let p1 = L::splat(1.0).sub(p0);
                let pmfv = pmfv.mul(L::select(first, p0, ci1.div(sum)));
                let uv = L::select(first, uv.div(p0), uv.sub(p0).div(p1))
                    .min(L::splat(ONE_MINUS_EPSILON));
                let zero = L::splat(0.0);
                let dead = L::bits(L::and(ci0.eq(zero), ci1.eq(zero)));
                let first = L::bits(first);
                uv.store(&mut u);
                pmfv.store(&mut pmf);
                let mut bits = active;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if dead & (1 << i) != 0 {
                        out[i] = None;
                        active &= !(1 << i);
                        continue;
                    }
                    let cur = &s.nodes[node[i]];
                    node[i] = if first & (1 << i) != 0 {
                        node[i] + 1
                    } else {
                        cur.child_or_light as usize
                    };
                    let next = &s.nodes[node[i]];
                    if next.is_leaf {
                        out[i] = Some(SampledLight {
                            light: next.child_or_light,
                            p: pmf[i],
                        });
                        active &= !(1 << i);
                    }
                }
            }
        }
    }
}
