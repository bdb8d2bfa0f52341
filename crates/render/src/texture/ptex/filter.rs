//! Ptex lookups: the separable cubic B-spline filter that pbrt-v4 asks the
//! Ptex library for (`PtexFilter::f_bspline`, Ptex's `PtexWidth4Filter`
//! with B = 1, C = 0), evaluated within one face.
//!
//! As in Ptex, the footprint (|∂u/∂x| + |∂u/∂y|, |∂v/∂x| + |∂v/∂y|) is
//! clamped to at least one texel and picks a power-of-two resolution per
//! axis at which the kernel covers 4 to 8 texels; footprints of a quarter
//! face or more switch to Ptex's wide smoothstep kernels on 4, 2 or 1
//! texels. Reduced resolutions are box averages of level 0 (what Ptex's
//! stored and on-the-fly reductions hold, up to their integer rounding).
//!
//! Difference from Ptex: kernel weights that fall outside the face are
//! not carried across the edge into the adjacent face (Ptex rotates them
//! into the neighbour, with special cases at irregular corners); they are
//! folded onto the edge texels as Ptex does at a border of the clamp
//! mode. At real borders (no neighbour) the file's border mode applies
//! (clamp, black or periodic), as in Ptex.

use std::sync::atomic::Ordering;

use super::reader::{
    PtexBorderMode, PtexFace, PtexFile, PtexMeshType, FLAG_NEIGHBORHOOD_CONSTANT, FLAG_SUBFACE,
};

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

    /// Doubles the resolution, giving each texel's weight to both halves
    /// (Ptex `upresU`, for subfaces).
    fn upres(&mut self) {
        let mut w = [0.0; KMAX];
        let len = (self.len * 2).min(KMAX);
        for (i, x) in w.iter_mut().enumerate().take(len) {
            *x = self.w[i / 2];
        }
        self.w = w;
        self.len = len;
        self.start *= 2;
        self.log2 += 1;
    }

    /// The in-face texels and weights: out-of-face taps are folded onto the
    /// edge (`fold`), wrapped (periodic) or dropped (black).
    fn resolve(&self, low: PtexBorderMode, high: PtexBorderMode) -> ([(usize, f32); KMAX], usize) {
        let res = 1i32 << self.log2;
        let mut out = [(0usize, 0.0f32); KMAX];
        let mut n = 0;
        for i in 0..self.len {
            let w = self.w[i];
            if w == 0.0 {
                continue;
            }
            let t = self.start + i as i32;
            let mode = if t < 0 {
                low
            } else if t >= res {
                high
            } else {
                PtexBorderMode::Clamp
            };
            let idx = match mode {
                PtexBorderMode::Clamp => t.clamp(0, res - 1),
                PtexBorderMode::Periodic => t.rem_euclid(res),
                PtexBorderMode::Black => continue,
            } as usize;
            if let Some(e) = out[..n].iter_mut().find(|e| e.0 == idx) {
                e.1 += w;
            } else {
                out[n] = (idx, w);
                n += 1;
            }
        }
        (out, n)
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

impl PtexFile {
    /// The filtered value of face `face` at (u, v) with the given
    /// derivatives, channels written to `out` (which must hold
    /// `nchannels` values). A face index out of range gives zeros.
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
        if self.mesh_type == PtexMeshType::Triangle {
            self.eval_triangle(out, face as usize, u, v, dudx, dvdx, dudy, dvdy);
            return;
        }
        if f.flags & FLAG_NEIGHBORHOOD_CONSTANT != 0 || f.is_constant() {
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
        let wrap = |x: f32, m: PtexBorderMode| match m {
            PtexBorderMode::Clamp => x.clamp(0.0, 1.0),
            PtexBorderMode::Periodic => x - x.floor(),
            PtexBorderMode::Black => x,
        };
        let (u, v) = (wrap(u, self.border[0]), wrap(v, self.border[1]));
        if !u.is_finite() || !v.is_finite() {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        let (mut ku, mut kv) = if f.flags & FLAG_SUBFACE != 0 {
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
            (ku, kv)
        } else {
            (
                build_axis(u, uw, f.ulog2 as i32),
                build_axis(v, vw, f.vlog2 as i32),
            )
        };
        let total = ku.weight() * kv.weight();
        if total.is_nan() || total <= 0.0 {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        while ku.log2 > f.ulog2 as i32 {
            ku.downres();
        }
        while kv.log2 > f.vlog2 as i32 {
            kv.downres();
        }
        // Sides: bottom (v low), right (u high), top (v high), left (u low).
        let side = |edge: usize, axis: usize| {
            if f.adj_faces[edge] >= 0 {
                PtexBorderMode::Clamp
            } else {
                self.border[axis]
            }
        };
        let (tu, nu) = ku.resolve(side(3, 0), side(1, 0));
        let (tv, nv) = kv.resolve(side(0, 1), side(2, 1));
        let mut acc = [0.0f64; 4];
        let mut big;
        let acc: &mut [f64] = if nc <= 4 {
            &mut acc[..nc]
        } else {
            big = vec![0.0f64; nc];
            &mut big
        };
        for &(iv, wv) in &tv[..nv] {
            for &(iu, wu) in &tu[..nu] {
                f.accumulate(nc, ku.log2, kv.log2, iu, iv, wu * wv, acc);
            }
        }
        let inv = 1.0 / total as f64;
        for c in 0..nc {
            out[c] = (acc[c] * inv) as f32;
        }
    }
}
