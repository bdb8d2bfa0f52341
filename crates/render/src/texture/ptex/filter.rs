//! Ptex lookups on quad meshes: the separable cubic B-spline filter that
//! pbrt-v4 asks the Ptex library for (`PtexFilter::f_bspline`, Ptex's
//! `PtexWidth4Filter` with B = 1, C = 0, run by `PtexSeparableFilter`).
//!
//! As in Ptex, the footprint (|∂u/∂x| + |∂u/∂y|, |∂v/∂x| + |∂v/∂y|) is
//! clamped to at least one texel and picks a power-of-two resolution per
//! axis at which the kernel covers 4 to 8 texels; footprints of a quarter
//! face or more switch to Ptex's wide smoothstep kernels on 4, 2 or 1
//! texels. Reduced resolutions are box averages of level 0 (what Ptex's
//! stored and on-the-fly reductions hold, up to their integer rounding).
//!
//! Kernel taps beyond an edge are split off and carried into the
//! neighbour the file names (rotated by the edges' orientation, taken to
//! the neighbour's resolution, through the half-resolution subfaces of
//! non-quads); taps beyond a corner go to the diagonal face of a regular
//! (valence 4) vertex, are made symmetric and shared among the faces of a
//! vertex of valence 5 or more, and are dropped (the total renormalized)
//! at valence 3. At an edge without a neighbour they are folded onto the
//! edge texels (every border mode; Ptex wraps periodic textures through
//! their adjacency, not here), or dropped under the "black" border mode.

use std::sync::atomic::Ordering;

use super::reader::{
    PtexBorderMode, PtexFace, PtexFile, PtexMeshType, FLAG_NEIGHBORHOOD_CONSTANT, FLAG_SUBFACE,
};

/// Writes a filter's result, `acc / weight` per channel, to `out`; where
/// the weights came to nothing usable, the face's `constant` value.
pub(super) fn resolve_filtered(acc: &[f64], weight: f64, constant: &[f32], out: &mut [f32]) {
    let nc = acc.len();
    if weight.is_nan() || weight <= 0.0 || weight.is_infinite() {
        out[..nc].copy_from_slice(constant);
        return;
    }
    for (o, a) in out.iter_mut().zip(acc) {
        *o = (a / weight) as f32;
    }
}

/// The most taps along one axis (4 filter widths of 1 to 2 texels, plus
/// rounding to even pairs).
const KMAX: usize = 12;

/// One axis of a separable kernel: weights for texels `start..start+len`
/// at resolution 2^log2.
#[derive(Clone, Copy, Debug)]
struct Axis {
    log2: i32,
    start: i32,
    len: usize,
    w: [f32; KMAX],
}

/// Cubic B-spline (Mitchell–Netravali with B = 1, C = 0), support ±2.
#[inline]
fn bspline(x: f32) -> f32 {
    let x = x.abs();
    if x < 1.0 {
        (0.5 * x - 1.0) * x * x + 2.0 / 3.0
    } else if x < 2.0 {
        ((-x / 6.0 + 1.0) * x - 2.0) * x + 4.0 / 3.0
    } else {
        0.0
    }
}

/// Ptex's two-unit cubic Hermite ("blur") kernel.
#[inline]
fn smoothstep_kernel(x: f32) -> f32 {
    let x = x.abs();
    if x < 1.0 {
        (2.0 * x - 3.0) * x * x + 1.0
    } else {
        0.0
    }
}

/// The resolution (log2) whose texel is no larger than `w`: 127 minus
/// the float's biased exponent, as Ptex computes it.
#[inline]
fn res_from_width(w: f32) -> i32 {
    127 - ((w.to_bits() >> 23) & 0xff) as i32
}

/// Builds one kernel axis for coordinate `u`, filter width `uw`, on a face
/// of 2^`face_log2` texels (Ptex `PtexWidth4Filter::buildKernelAxis`,
/// without lerping between resolutions).
fn build_axis(u: f32, uw: f32, face_log2: i32) -> Axis {
    let mut a = Axis {
        log2: 0,
        start: 0,
        len: 0,
        w: [0.0; KMAX],
    };
    let uw = uw.max(1.0 / (1u32 << face_log2) as f32);
    if uw >= 0.25 {
        if uw < 0.5 {
            a.log2 = 2;
            let upix = u * 4.0 - 0.5;
            let u1 = ((upix - 2.0).ceil() as i32) & !1;
            let u2 = ((upix + 2.0).ceil() as i32 + 1) & !1;
            a.start = u1;
            a.len = (u2 - u1).clamp(0, KMAX as i32) as usize;
            let x1 = u1 as f32 - upix;
            for i in 0..a.len {
                a.w[i] = bspline(x1 + i as f32);
            }
        } else if uw < 1.0 {
            a.log2 = 1;
            let upix = u * 2.0 - 0.5;
            a.start = (u - 0.5).floor() as i32 * 2;
            a.len = 4;
            let x1 = a.start as f32 - upix;
            let s = 1.0 / (uw * 1.5 + 0.5);
            for i in 0..a.len {
                a.w[i] = smoothstep_kernel((x1 + i as f32) * s);
            }
        } else {
            a.log2 = 0;
            let upix = u - 0.5;
            let ui = upix.floor();
            a.start = ui as i32;
            a.len = 2;
            a.w[0] = smoothstep_kernel(upix - ui);
            a.w[1] = 1.0 - a.w[0];
        }
        return a;
    }
    a.log2 = res_from_width(uw);
    let res = (1u32 << a.log2) as f32;
    let upix = u * res - 0.5;
    let uwpix = uw * res;
    let d = 2.0 * uwpix;
    let u1 = (upix - d).ceil() as i32;
    let u2 = (upix + d).ceil() as i32;
    a.start = u1;
    a.len = (u2 - u1).clamp(0, KMAX as i32) as usize;
    let step = 1.0 / uwpix;
    let x1 = (u1 as f32 - upix) * step;
    for i in 0..a.len {
        a.w[i] = bspline(x1 + i as f32 * step);
    }
    a
}

impl Axis {
    fn weight(&self) -> f32 {
        self.w[..self.len].iter().sum()
    }

    /// Texels at the current resolution.
    #[inline]
    fn res(&self) -> i32 {
        1i32 << self.log2.clamp(0, 30)
    }

    /// Drops zero weights at both ends (Ptex `stripZeros`).
    fn strip_zeros(&mut self) {
        let first = self.w[..self.len].iter().position(|&x| x != 0.0);
        let Some(first) = first else {
            self.len = 0;
            return;
        };
        let last = self.w[..self.len]
            .iter()
            .rposition(|&x| x != 0.0)
            .unwrap_or(first);
        self.w.copy_within(first..=last, 0);
        self.start += first as i32;
        self.len = last + 1 - first;
    }

    /// Removes the first `n` taps.
    fn drop_front(&mut self, n: usize) {
        let n = n.min(self.len);
        self.w.copy_within(n..self.len, 0);
        self.len -= n;
        self.start += n as i32;
    }

    /// Taps below texel 0 folded onto texel 0 (dropped when `black`).
    fn merge_low(&mut self, black: bool) {
        let n = ((-self.start).max(0) as usize).min(self.len);
        if n == 0 {
            return;
        }
        let s: f32 = self.w[..n].iter().sum();
        self.drop_front(n);
        if !black && self.len > 0 {
            self.w[0] += s;
        }
    }

    /// Taps at or above the resolution folded onto the last texel.
    fn merge_high(&mut self, black: bool) {
        let n = (self.start + self.len as i32 - self.res()).clamp(0, self.len as i32) as usize;
        if n == 0 {
            return;
        }
        let keep = self.len - n;
        let s: f32 = self.w[keep..self.len].iter().sum();
        self.len = keep;
        if !black && keep > 0 {
            self.w[keep - 1] += s;
        }
    }

    /// Splits off the taps below texel 0, positioned at the far side of
    /// the neighbour (Ptex `splitL`/`splitB`).
    fn split_low(&mut self) -> Axis {
        let n = (-self.start).max(0) as usize;
        let mut piece = *self;
        if n < self.len {
            piece.len = n;
            piece.start = self.res() - n as i32;
            self.drop_front(n);
        } else {
            piece.start += self.res();
            self.start = 0;
            self.len = 0;
        }
        piece
    }

    /// Splits off the taps at or above the resolution, positioned at the
    /// near side of the neighbour (Ptex `splitR`/`splitT`).
    fn split_high(&mut self) -> Axis {
        let n = (self.start + self.len as i32 - self.res()).max(0) as usize;
        let mut piece = *self;
        if n < self.len {
            let keep = self.len - n;
            piece.w = [0.0; KMAX];
            piece.w[..n].copy_from_slice(&self.w[keep..self.len]);
            piece.len = n;
            piece.start = 0;
            self.len = keep;
        } else {
            piece.start -= self.res();
            self.start = 0;
            self.len = 0;
        }
        piece
    }

    /// Mirrors the axis (texel i becomes res − 1 − i).
    fn flip(&mut self) {
        self.start = self.res() - self.start - self.len as i32;
        self.w[..self.len].reverse();
    }

    /// Halves the resolution, adding the weights of each texel pair.
    fn downres(&mut self) {
        let mut w = [0.0; KMAX];
        let start = self.start.div_euclid(2);
        let mut len = 0;
        for i in 0..self.len {
            let j = (self.start + i as i32).div_euclid(2) - start;
            w[j as usize] += self.w[i];
            len = len.max(j as usize + 1);
        }
        self.w = w;
        self.start = start;
        self.len = len;
        self.log2 -= 1;
    }

    /// Doubles the resolution, splitting each texel's weight between its
    /// halves (Ptex `upresU`).
    fn upres(&mut self) {
        let mut w = [0.0; KMAX];
        let len = (self.len * 2).min(KMAX);
        for (i, x) in w.iter_mut().enumerate().take(len) {
            *x = self.w[i / 2] * 0.5;
        }
        self.w = w;
        self.len = len;
        self.start *= 2;
        self.log2 += 1;
    }
}

/// A separable kernel placed on a face (Ptex `PtexSeparableKernel`).
#[derive(Clone, Copy, Debug)]
struct Kernel {
    ku: Axis,
    kv: Axis,
}

/// Edge ids: bottom (v = 0), right (u = 1), top (v = 1), left (u = 0).
const BOTTOM: usize = 0;
const RIGHT: usize = 1;
const TOP: usize = 2;
const LEFT: usize = 3;
/// Most faces visited around one vertex.
const MAX_VALENCE: usize = 10;
/// Bound on nested splits (subface crossings); stops cycles in damaged
/// adjacency data.
const MAX_DEPTH: u32 = 16;

impl Kernel {
    fn weight(&self) -> f32 {
        self.ku.weight() * self.kv.weight()
    }

    fn is_empty(&self) -> bool {
        self.ku.len == 0 || self.kv.len == 0
    }

    fn split_l(&mut self) -> Kernel {
        Kernel {
            ku: self.ku.split_low(),
            kv: self.kv,
        }
    }
    fn split_r(&mut self) -> Kernel {
        Kernel {
            ku: self.ku.split_high(),
            kv: self.kv,
        }
    }
    fn split_b(&mut self) -> Kernel {
        Kernel {
            ku: self.ku,
            kv: self.kv.split_low(),
        }
    }
    fn split_t(&mut self) -> Kernel {
        Kernel {
            ku: self.ku,
            kv: self.kv.split_high(),
        }
    }

    /// Rotates the kernel `r` quarter turns counter-clockwise.
    fn rotate(&mut self, r: i32) {
        match r & 3 {
            1 => {
                self.ku.flip();
                std::mem::swap(&mut self.ku, &mut self.kv);
            }
            2 => {
                self.ku.flip();
                self.kv.flip();
            }
            3 => {
                self.kv.flip();
                std::mem::swap(&mut self.ku, &mut self.kv);
            }
            _ => {}
        }
    }

    /// From a main face across edge `eid` to the subface beyond it: half
    /// the resolution, offset into the subface; true when the kernel lands
    /// on the primary subface (the one the main face names).
    fn main_to_subface(&mut self, eid: usize) -> bool {
        if self.ku.log2 == 0 {
            self.ku.upres();
        }
        if self.kv.log2 == 0 {
            self.kv.upres();
        }
        if self.ku.log2 > 0 {
            self.ku.log2 -= 1;
        }
        if self.kv.log2 > 0 {
            self.kv.log2 -= 1;
        }
        let (ru, rv) = (self.ku.res(), self.kv.res());
        let (u, v) = (&mut self.ku.start, &mut self.kv.start);
        match eid & 3 {
            BOTTOM => {
                let primary = *u < ru;
                *v -= rv;
                if !primary {
                    *u -= ru;
                }
                primary
            }
            RIGHT => {
                let primary = *v < rv;
                if !primary {
                    *v -= rv;
                }
                primary
            }
            TOP => {
                let primary = *u >= ru;
                if primary {
                    *u -= ru;
                }
                primary
            }
            _ => {
                let primary = *v >= rv;
                *u -= ru;
                if primary {
                    *v -= rv;
                }
                primary
            }
        }
    }

    /// From a subface across edge `eid` to the main face beyond it.
    fn subface_to_main(&mut self, eid: usize) {
        let (ru, rv) = (self.ku.res(), self.kv.res());
        match eid & 3 {
            BOTTOM => self.kv.start += rv,
            RIGHT => {}
            TOP => self.ku.start += ru,
            _ => {
                self.ku.start += ru;
                self.kv.start += rv;
            }
        }
        self.ku.log2 += 1;
        self.kv.log2 += 1;
    }

    /// Makes the kernel the same along u and v (for sharing among the
    /// faces around an extraordinary vertex), keeping `initial` as its
    /// weight where it can; returns the new weight (Ptex `makeSymmetric`).
    fn make_symmetric(&mut self, initial: f32) -> f32 {
        while self.ku.log2 > self.kv.log2 {
            self.ku.downres();
        }
        while self.kv.log2 > self.ku.log2 {
            self.kv.downres();
        }
        let n = self.ku.len.min(self.kv.len);
        self.ku.len = n;
        self.kv.len = n;
        let mut sum = 0.0;
        for i in 0..n {
            let s = self.ku.w[i] + self.kv.w[i];
            self.ku.w[i] = s;
            self.kv.w[i] = s;
            sum += s;
        }
        let new_weight = sum * sum;
        let scale = if new_weight == 0.0 {
            1.0
        } else {
            initial / new_weight
        };
        if scale >= 1.0 {
            new_weight
        } else {
            // (The B-spline's weights are positive, so the scale is in
            // (0, 1): the weight goes back to `initial`.)
            for x in &mut self.ku.w[..n] {
                *x *= scale;
            }
            initial
        }
    }
}

impl PtexFace {
    /// The summed-area table of the texels (built once).
    fn sat(&self, nc: usize) -> Option<&[f64]> {
        let t = self.texels.as_ref()?;
        Some(self.sat.get_or_init(|| {
            let (w, h) = (self.ures(), self.vres());
            let mut s = vec![0.0f64; (w + 1) * (h + 1) * nc];
            for v in 0..h {
                let mut row = vec![0.0f64; nc];
                for u in 0..w {
                    for c in 0..nc {
                        row[c] += t[(v * w + u) * nc + c] as f64;
                        s[((v + 1) * (w + 1) + u + 1) * nc + c] =
                            s[(v * (w + 1) + u + 1) * nc + c] + row[c];
                    }
                }
            }
            s.into_boxed_slice()
        }))
    }

    /// Adds `weight` × texel (iu, iv) at resolution 2^ulog2 × 2^vlog2 (at
    /// most the face's) to `acc`.
    #[allow(clippy::too_many_arguments)]
    fn accumulate(
        &self,
        nc: usize,
        ulog2: i32,
        vlog2: i32,
        iu: usize,
        iv: usize,
        weight: f32,
        acc: &mut [f64],
    ) {
        let Some(t) = &self.texels else {
            for (a, c) in acc.iter_mut().zip(&self.constant) {
                *a += (weight * c) as f64;
            }
            return;
        };
        let du = self.ulog2 as i32 - ulog2;
        let dv = self.vlog2 as i32 - vlog2;
        if du == 0 && dv == 0 {
            let o = (iv * self.ures() + iu) * nc;
            for c in 0..nc {
                acc[c] += (weight * t[o + c]) as f64;
            }
            return;
        }
        let Some(s) = self.sat(nc) else { return };
        let w1 = self.ures() + 1;
        let (u0, u1) = (iu << du, (iu + 1) << du);
        let (v0, v1) = (iv << dv, (iv + 1) << dv);
        let scale = weight as f64 / ((u1 - u0) * (v1 - v0)) as f64;
        for c in 0..nc {
            let sum = s[(v1 * w1 + u1) * nc + c]
                - s[(v0 * w1 + u1) * nc + c]
                - s[(v1 * w1 + u0) * nc + c]
                + s[(v0 * w1 + u0) * nc + c];
            acc[c] += sum * scale;
        }
    }
}

/// Accumulated sums of one quad lookup (Ptex `PtexSeparableFilter`'s
/// state).
struct Quad<'a> {
    file: &'a PtexFile,
    acc: &'a mut [f64],
    /// The total weight the sums are divided by.
    weight: f64,
}

impl<'a> Quad<'a> {
    fn face(&self, id: i32) -> Option<&'a PtexFace> {
        let file: &'a PtexFile = self.file;
        usize::try_from(id).ok().and_then(|i| file.faces.get(i))
    }

    fn split_and_apply(&mut self, mut k: Kernel, faceid: usize, depth: u32) {
        let Some(f) = self.face(faceid as i32) else {
            return;
        };
        let (ures, vres) = (k.ku.res(), k.kv.res());
        let split_r = k.ku.start + k.ku.len as i32 > ures;
        let split_l = k.ku.start < 0;
        let split_t = k.kv.start + k.kv.len as i32 > vres;
        let split_b = k.kv.start < 0;
        let black_u = self.file.border[0] == PtexBorderMode::Black;
        let black_v = self.file.border[1] == PtexBorderMode::Black;
        let has = |e: usize| depth < MAX_DEPTH && f.adj_faces[e] >= 0;
        if split_r {
            if has(RIGHT) {
                let mut ka = k.split_r();
                if split_t {
                    if has(TOP) {
                        let kc = ka.split_t();
                        self.apply_to_corner(kc, faceid, TOP, depth);
                    } else {
                        ka.kv.merge_high(black_v);
                    }
                }
                if split_b {
                    if has(BOTTOM) {
                        let kc = ka.split_b();
                        self.apply_to_corner(kc, faceid, RIGHT, depth);
                    } else {
                        ka.kv.merge_low(black_v);
                    }
                }
                self.apply_across_edge(ka, faceid, RIGHT, depth);
            } else {
                k.ku.merge_high(black_u);
            }
        }
        if split_l {
            if has(LEFT) {
                let mut ka = k.split_l();
                if split_t {
                    if has(TOP) {
                        let kc = ka.split_t();
                        self.apply_to_corner(kc, faceid, LEFT, depth);
                    } else {
                        ka.kv.merge_high(black_v);
                    }
                }
                if split_b {
                    if has(BOTTOM) {
                        let kc = ka.split_b();
                        self.apply_to_corner(kc, faceid, BOTTOM, depth);
                    } else {
                        ka.kv.merge_low(black_v);
                    }
                }
                self.apply_across_edge(ka, faceid, LEFT, depth);
            } else {
                k.ku.merge_low(black_u);
            }
        }
        if split_t {
            if has(TOP) {
                let ka = k.split_t();
                self.apply_across_edge(ka, faceid, TOP, depth);
            } else {
                k.kv.merge_high(black_v);
            }
        }
        if split_b {
            if has(BOTTOM) {
                let ka = k.split_b();
                self.apply_across_edge(ka, faceid, BOTTOM, depth);
            } else {
                k.kv.merge_low(black_v);
            }
        }
        self.apply(k, f);
    }

    fn apply_across_edge(&mut self, mut k: Kernel, faceid: usize, eid: usize, depth: u32) {
        let file: &'a PtexFile = self.file;
        let f = &file.faces[faceid];
        let mut afid = f.adj_faces[eid];
        let mut aeid = f.adj_edge(eid);
        let Some(mut af) = self.face(afid) else {
            return;
        };
        let mut rot = eid as i32 - aeid as i32 + 2;
        let (f_sub, af_sub) = (f.flags & FLAG_SUBFACE != 0, af.flags & FLAG_SUBFACE != 0);
        if f_sub != af_sub {
            if af_sub {
                if !k.main_to_subface(eid) {
                    // On to the secondary subface.
                    let neid = (aeid + 3) % 4;
                    afid = af.adj_faces[neid];
                    aeid = af.adj_edge(neid);
                    let Some(next) = self.face(afid) else {
                        return;
                    };
                    af = next;
                    rot += neid as i32 - aeid as i32 + 2;
                }
            } else {
                let primary = af.adj_faces[aeid] == faceid as i32;
                k.subface_to_main((eid + 4 - primary as usize) % 4);
            }
        }
        k.rotate(rot);
        if af.flags & FLAG_SUBFACE != 0 {
            self.split_and_apply(k, afid as usize, depth + 1);
        } else {
            self.apply(k, af);
        }
    }

    fn apply_to_corner(&mut self, mut k: Kernel, faceid: usize, eid: usize, depth: u32) {
        let file: &'a PtexFile = self.file;
        let f = &file.faces[faceid];
        let (mut afid, mut aeid) = (faceid as i32, eid);
        let mut af = f;
        let mut prev_sub = af.flags & FLAG_SUBFACE != 0;
        let mut corners = [(0usize, 0usize); MAX_VALENCE];
        let mut ncorners: i32 = 0;
        for (i, slot) in corners.iter_mut().enumerate() {
            let prev = afid;
            afid = af.adj_faces[aeid];
            aeid = (af.adj_edge(aeid) + 1) % 4;
            // A border, or back at the start (the edge id is checked too:
            // a periodic face can be all four corners).
            if afid < 0 || (afid == faceid as i32 && aeid == eid) {
                ncorners = i as i32 - 2;
                break;
            }
            let Some(next) = self.face(afid) else {
                ncorners = -1;
                break;
            };
            af = next;
            *slot = (afid as usize, aeid);
            let sub = af.flags & FLAG_SUBFACE != 0;
            if prev_sub && !sub && af.adj_faces[(aeid + 3) % 4] == prev {
                // A subface "tee": the corner is on the main face.
                let primary = i == 1;
                k.subface_to_main(eid + 2 * primary as usize);
                k.rotate(eid as i32 - aeid as i32 + 3 - primary as i32);
                self.split_and_apply(k, afid as usize, depth + 1);
                return;
            }
            prev_sub = sub;
        }
        if ncorners == 1 {
            let (cfid, ceid) = corners[1];
            self.apply_to_corner_face(k, f, eid, cfid, ceid, depth);
        } else if ncorners > 1 {
            // Valence 5 or more: a symmetric kernel, shared equally.
            k.rotate(eid as i32 + 2);
            let initial = k.weight();
            let new_weight = k.make_symmetric(initial);
            for &(cfid, ceid) in &corners[1..=ncorners as usize] {
                self.apply_to_corner_face(k, f, 2, cfid, ceid, depth);
            }
            self.weight += (new_weight * ncorners as f32 - initial) as f64;
        } else {
            // Valence 3 (or a border): the corner is left out.
            self.weight -= k.weight() as f64;
        }
    }

    fn apply_to_corner_face(
        &mut self,
        mut k: Kernel,
        f: &PtexFace,
        eid: usize,
        cfid: usize,
        ceid: usize,
        depth: u32,
    ) {
        let file: &'a PtexFile = self.file;
        let cf = &file.faces[cfid];
        let (f_sub, cf_sub) = (f.flags & FLAG_SUBFACE != 0, cf.flags & FLAG_SUBFACE != 0);
        if f_sub != cf_sub {
            if cf_sub {
                k.main_to_subface(eid + 3);
            } else {
                k.subface_to_main(eid + 3);
            }
        }
        k.rotate(eid as i32 - ceid as i32 + 2);
        if cf_sub {
            self.split_and_apply(k, cfid, depth + 1);
        } else {
            self.apply(k, cf);
        }
    }

    /// Adds the kernel's weighted texels of face `f` (taken down to the
    /// face's resolution first).
    fn apply(&mut self, mut k: Kernel, f: &PtexFace) {
        if k.is_empty() {
            return;
        }
        while k.ku.log2 > f.ulog2 as i32 {
            k.ku.downres();
        }
        while k.kv.log2 > f.vlog2 as i32 {
            k.kv.downres();
        }
        if k.ku.log2 < 0 || k.kv.log2 < 0 {
            return;
        }
        let nc = self.file.nchannels;
        let (ures, vres) = (k.ku.res(), k.kv.res());
        for j in 0..k.kv.len {
            let iv = k.kv.start + j as i32;
            if iv < 0 || iv >= vres {
                continue;
            }
            for i in 0..k.ku.len {
                let iu = k.ku.start + i as i32;
                if iu < 0 || iu >= ures {
                    continue;
                }
                let w = k.ku.w[i] * k.kv.w[j];
                f.accumulate(
                    nc,
                    k.ku.log2,
                    k.kv.log2,
                    iu as usize,
                    iv as usize,
                    w,
                    self.acc,
                );
            }
        }
    }
}

impl PtexFile {
    /// The filtered value of face `face` at (u, v) with the given
    /// derivatives, channels written to `out` (which must hold
    /// `nchannels` values). A face index out of range gives zeros (and is
    /// counted for [`super::take_lookup_warnings`]).
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &self,
        out: &mut [f32],
        face: i32,
        u: f32,
        v: f32,
        dudx: f32,
        dvdx: f32,
        dudy: f32,
        dvdy: f32,
    ) {
        let nc = self.nchannels;
        out[..nc].fill(0.0);
        let Some(f) = usize::try_from(face).ok().and_then(|i| self.faces.get(i)) else {
            self.bad_lookups.fetch_add(1, Ordering::Relaxed);
            self.bad_face.store(face as i64, Ordering::Relaxed);
            return;
        };
        let faceid = face as usize;
        if self.mesh_type == PtexMeshType::Triangle {
            self.eval_triangle(out, faceid, u, v, dudx, dvdx, dudy, dvdy);
            return;
        }
        if f.flags & FLAG_NEIGHBORHOOD_CONSTANT != 0 {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        let mut uw = dudx.abs() + dudy.abs();
        let mut vw = dvdx.abs() + dvdy.abs();
        if !uw.is_finite() {
            uw = 1.0;
        }
        if !vw.is_finite() {
            vw = 1.0;
        }
        let mut black = false;
        let mut wrap = |x: f32, m: PtexBorderMode| match m {
            PtexBorderMode::Clamp => x.clamp(0.0, 1.0),
            PtexBorderMode::Periodic => x - x.floor(),
            PtexBorderMode::Black => {
                black |= x <= -1.0 || x >= 2.0;
                x
            }
        };
        let (u, v) = (wrap(u, self.border[0]), wrap(v, self.border[1]));
        if black {
            return;
        }
        if !u.is_finite() || !v.is_finite() {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        let mut k = if f.flags & FLAG_SUBFACE != 0 {
            // Built as if on the parent face, then taken down one level.
            let mut ku = build_axis(u * 0.5, uw * 0.5, f.ulog2 as i32 + 1);
            let mut kv = build_axis(v * 0.5, vw * 0.5, f.vlog2 as i32 + 1);
            if ku.log2 == 0 {
                ku.upres();
            }
            if kv.log2 == 0 {
                kv.upres();
            }
            ku.log2 -= 1;
            kv.log2 -= 1;
            Kernel { ku, kv }
        } else {
            Kernel {
                ku: build_axis(u, uw, f.ulog2 as i32),
                kv: build_axis(v, vw, f.vlog2 as i32),
            }
        };
        k.ku.strip_zeros();
        k.kv.strip_zeros();
        let total = k.weight();
        if total.is_nan() || total <= 0.0 {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        let mut acc = [0.0f64; 4];
        let mut big;
        let acc: &mut [f64] = if nc <= 4 {
            &mut acc[..nc]
        } else {
            big = vec![0.0f64; nc];
            &mut big
        };
        let mut q = Quad {
            file: self,
            acc,
            weight: total as f64,
        };
        q.split_and_apply(k, faceid, 0);
        let weight = q.weight;
        resolve_filtered(acc, weight, &f.constant, out);
    }
}

#[cfg(test)]
mod tests;
