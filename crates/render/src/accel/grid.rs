//! The uniform grid of pbrt-v1/v2 (section 4.3, `GridAccel`): voxels
//! sized from the primitive count, each listing the primitives whose bounds
//! overlap it, traversed by a 3-D DDA that stops once the nearest hit lies
//! before the next voxel boundary.
//!
//! **Mailboxing.** pbrt-v2 kept a ray id in every primitive, which is not
//! thread safe. Here each query carries a small open-addressing hash set on
//! the stack (64 slots, 256 bytes, no allocation, nothing shared between
//! threads) holding the primitives already tested by this ray. Only
//! primitives that span more than one voxel can repeat, and the grid flags
//! those entries at build time, so single-voxel primitives never touch the
//! set. When the set is three-quarters full it is cleared: a primitive may
//! then be tested twice, which costs time but never changes the answer.

use super::params::GridParams;
use super::{far_pad, usable_bounds, Aggregate, RayPrecomp};
use rpbrt_geometry::{Bounds3f, Float, Ray};

/// Marks voxel entries whose primitive spans several voxels.
const MULTI: u32 = 1 << 31;
/// Primitives are inserted into every voxel within this fraction of a voxel
/// of their bounds, so that DDA rounding near voxel faces cannot skip one.
const PAD: Float = 1e-4;

/// A uniform grid over primitive bounds.
#[derive(Clone, Debug)]
pub struct Grid {
    bounds: Bounds3f,
    n_voxels: [u32; 3],
    width: [Float; 3],
    inv_width: [Float; 3],
    /// Voxel `v` lists `voxel_prims[voxel_start[v]..voxel_start[v + 1]]`.
    voxel_start: Vec<u32>,
    voxel_prims: Vec<u32>,
    n_input: usize,
    n_skipped: usize,
}

const MAILBOX_SLOTS: usize = 64;
const EMPTY: u32 = u32::MAX;

/// The per-query set of primitives already tested.
struct Mailbox {
    slots: [u32; MAILBOX_SLOTS],
    len: usize,
}

impl Mailbox {
    #[inline(always)]
    fn new() -> Mailbox {
        Mailbox {
            slots: [EMPTY; MAILBOX_SLOTS],
            len: 0,
        }
    }
    /// True if `id` was not yet in the set (and adds it).
    #[inline]
    fn insert(&mut self, id: u32) -> bool {
        if self.len >= MAILBOX_SLOTS * 3 / 4 {
            self.slots = [EMPTY; MAILBOX_SLOTS];
            self.len = 0;
        }
        let mut h = (id.wrapping_mul(0x9e37_79b9) >> 26) as usize;
        loop {
            let s = self.slots[h];
            if s == id {
                return false;
            }
            if s == EMPTY {
                self.slots[h] = id;
                self.len += 1;
                return true;
            }
            h = (h + 1) % MAILBOX_SLOTS;
        }
    }
}

impl Grid {
    /// Builds a grid over `prim_bounds`. Primitive indices must be below
    /// 2³¹ (higher ones are skipped).
    pub fn build(prim_bounds: &[Bounds3f], params: &GridParams) -> Grid {
        let prims: Vec<u32> = (0..prim_bounds.len().min(MULTI as usize) as u32)
            .filter(|&i| usable_bounds(&prim_bounds[i as usize]))
            .collect();
        let bounds = prims
            .iter()
            .fold(Bounds3f::empty(), |b, &i| b.union(&prim_bounds[i as usize]));
        let mut grid = Grid {
            bounds,
            n_voxels: [0; 3],
            width: [0.0; 3],
            inv_width: [0.0; 3],
            voxel_start: Vec::new(),
            voxel_prims: Vec::new(),
            n_input: prim_bounds.len(),
            n_skipped: prim_bounds.len() - prims.len(),
        };
        if prims.is_empty() {
            return grid;
        }
        // Resolution (pbrt-v2): 3·∛N voxels along the longest axis, the
        // same voxel size elsewhere, at most `max_voxels_per_axis` each.
        let delta = [
            bounds.p_max.x as f64 - bounds.p_min.x as f64,
            bounds.p_max.y as f64 - bounds.p_min.y as f64,
            bounds.p_max.z as f64 - bounds.p_min.z as f64,
        ];
        let max_width = delta[0].max(delta[1]).max(delta[2]);
        let per_unit = if max_width > 0.0 {
            3.0 * (prims.len() as f64).cbrt() / max_width
        } else {
            0.0
        };
        let max_v = params.max_voxels_per_axis.max(1) as f64;
        for (a, &da) in delta.iter().enumerate() {
            let nv = (da * per_unit).round().clamp(1.0, max_v);
            grid.n_voxels[a] = nv as u32;
            let w = da / nv;
            grid.width[a] = w as Float;
            grid.inv_width[a] = if w > 0.0 { (1.0 / w) as Float } else { 0.0 };
        }
        let n_vox = grid.n_voxels.iter().map(|&n| n as usize).product::<usize>();
        // Two passes (count, then fill) give a compact, ordered table.
        let ranges: Vec<[[u32; 2]; 3]> = prims
            .iter()
            .map(|&p| grid.voxel_range(&prim_bounds[p as usize]))
            .collect();
        let mut count = vec![0u32; n_vox + 1];
        for r in &ranges {
            grid.for_each_voxel(r, |v| count[v] += 1);
        }
        let mut sum = 0u32;
        for c in count.iter_mut() {
            let k = *c;
            *c = sum;
            sum += k;
        }
        let mut fill = count.clone();
        let mut entries = vec![0u32; sum as usize];
        for (r, &p) in ranges.iter().zip(&prims) {
            let multi = r.iter().any(|[lo, hi]| lo != hi);
            let e = if multi { p | MULTI } else { p };
            grid.for_each_voxel(r, |v| {
                entries[fill[v] as usize] = e;
                fill[v] += 1;
            });
        }
        grid.voxel_start = count;
        grid.voxel_prims = entries;
        grid
    }

    /// Voxels per axis.
    pub fn resolution(&self) -> [u32; 3] {
        self.n_voxels
    }

    #[inline]
    fn voxel_coord(&self, p: Float, a: usize, pad: Float) -> u32 {
        let f = ((p - self.bounds.p_min[a]) * self.inv_width[a] + pad).floor();
        f.clamp(0.0, (self.n_voxels[a] - 1) as Float) as u32
    }

    fn voxel_range(&self, b: &Bounds3f) -> [[u32; 2]; 3] {
        let mut r = [[0u32; 2]; 3];
        for (a, ra) in r.iter_mut().enumerate() {
            *ra = [
                self.voxel_coord(b.p_min[a], a, -PAD),
                self.voxel_coord(b.p_max[a], a, PAD),
            ];
        }
        r
    }

    fn for_each_voxel(&self, r: &[[u32; 2]; 3], mut f: impl FnMut(usize)) {
        let [nx, ny, _] = self.n_voxels.map(|n| n as usize);
        for z in r[2][0]..=r[2][1] {
            for y in r[1][0]..=r[1][1] {
                for x in r[0][0]..=r[0][1] {
                    f((z as usize * ny + y as usize) * nx + x as usize);
                }
            }
        }
    }

    /// The 3-D DDA: calls `visit(entries, t_best)` for each voxel along the
    /// ray, front to back; `visit` returns the new best distance, or `None`
    /// to stop at once.
    #[inline(always)]
    fn traverse(
        &self,
        ray: &Ray,
        t_max: Float,
        mut visit: impl FnMut(&[u32], Float) -> Option<Float>,
    ) {
        if self.voxel_start.is_empty() {
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
        let Some((t0, _)) = pre.slab(&lo, &hi, t_max) else {
            return;
        };
        let p = ray.at(t0);
        let d = [ray.d.x, ray.d.y, ray.d.z];
        let mut pos = [0i32; 3];
        let mut next = [Float::INFINITY; 3];
        let mut delta = [0.0 as Float; 3];
        let mut step = [0i32; 3];
        let mut out = [0i32; 3];
        for a in 0..3 {
            pos[a] = self.voxel_coord(p[a], a, 0.0) as i32;
            // A direction so small that its reciprocal overflows never
            // crosses a voxel: treated as parallel (this also keeps NaN out).
            let finite = pre.inv_dir[a].is_finite();
            if finite && d[a] > 0.0 {
                let edge = self.bounds.p_min[a] + (pos[a] + 1) as Float * self.width[a];
                next[a] = t0 + (edge - p[a]) * pre.inv_dir[a];
                delta[a] = self.width[a] * pre.inv_dir[a];
                step[a] = 1;
                out[a] = self.n_voxels[a] as i32;
            } else if finite && d[a] < 0.0 {
                let edge = self.bounds.p_min[a] + pos[a] as Float * self.width[a];
                next[a] = t0 + (edge - p[a]) * pre.inv_dir[a];
                delta[a] = -self.width[a] * pre.inv_dir[a];
                step[a] = -1;
                out[a] = -1;
            } else {
                // Parallel to this axis' planes: never steps along it.
                out[a] = -2;
            }
        }
        let [nx, ny, _] = self.n_voxels.map(|n| n as usize);
        let pad = far_pad();
        let mut t_best = t_max;
        loop {
            let v = (pos[2] as usize * ny + pos[1] as usize) * nx + pos[0] as usize;
            let entries =
                &self.voxel_prims[self.voxel_start[v] as usize..self.voxel_start[v + 1] as usize];
            if !entries.is_empty() {
                match visit(entries, t_best) {
                    Some(t) => t_best = t,
                    None => return,
                }
            }
            let a = if next[0] < next[1] {
                if next[0] < next[2] {
                    0
                } else {
                    2
                }
            } else if next[1] < next[2] {
                1
            } else {
                2
            };
            // Every later voxel starts at or after next[a]: a hit before it
            // is final (padded against rounding, like the slab test). (This also ends rays that cannot step at all.)
            if t_best * pad < next[a] {
                return;
            }
            pos[a] += step[a];
            if pos[a] == out[a] || step[a] == 0 {
                return;
            }
            next[a] += delta[a];
        }
    }
}

impl Aggregate for Grid {
    fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    #[inline]
    fn intersect<F>(&self, ray: &Ray, t_max: Float, mut hit: F) -> Option<(u32, Float)>
    where
        F: FnMut(u32, &Ray, Float) -> Option<Float>,
    {
        let mut best = None;
        let mut mailbox = Mailbox::new();
        self.traverse(ray, t_max, |entries, mut t_best| {
            for &e in entries {
                let p = e & !MULTI;
                if e & MULTI != 0 && !mailbox.insert(p) {
                    continue;
                }
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
        let mut mailbox = Mailbox::new();
        self.traverse(ray, t_max, |entries, t_best| {
            for &e in entries {
                let p = e & !MULTI;
                if e & MULTI != 0 && !mailbox.insert(p) {
                    continue;
                }
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
            + (self.voxel_start.capacity() + self.voxel_prims.capacity()) * 4
    }

    fn primitive_count(&self) -> usize {
        self.n_input
    }

    fn skipped_primitives(&self) -> usize {
        self.n_skipped
    }
}
