//! Ptex lookups on triangle meshes: the elliptical Gaussian that the Ptex
//! library uses for every filter type but "point" on triangle files
//! (`PtexTriangleFilter`, `PtexTriangleKernel`), so it is what pbrt-v4's
//! `f_bspline` request gets there.
//!
//! A triangle face of resolution 2^L is split into 4^L small triangles,
//! stored in a 2^L × 2^L array: the "even" triangle of grid cell (i, j)
//! (corners (i, j), (i+1, j), (i, j+1) in texels) at array position
//! (i, j), and the "odd" one (corners (i+1, j+1), (i, j+1), (i+1, j)) at
//! (2^L−1−j, 2^L−1−i). (u, v) are barycentric weights of vertices 1 and 2;
//! w = 1 − u − v weighs vertex 0. Edge 0 runs from vertex 0 to 1 (v = 0),
//! edge 1 from 1 to 2 (w = 0), edge 2 from 2 to 0 (u = 0).
//!
//! The footprint (the derivatives as two vectors) becomes an ellipse
//! Q(u, v) = A u² + B u v + C v² < 1, widened so it covers at least a
//! texel and is at most 15:1 eccentric, scaled by the kernel width 3.5;
//! texels weigh exp(−3.5²·Q/2). The resolution is the one whose texels
//! match the ellipse's minor diameter. Parts of the ellipse beyond an edge
//! with a neighbour are carried into the neighbour (re-expressed in its
//! coordinates, recursively); at an edge without one they are dropped and
//! the rest is renormalized. Reduced resolutions average each 2×2 block of
//! small triangles (three even, one odd), as Ptex's reductions do.

use super::reader::{PtexFace, PtexFile, FLAG_NEIGHBORHOOD_CONSTANT};

/// Kernel extent as a multiple of the footprint (Ptex's
/// `PtexTriangleKernelWidth`).
const KERNEL_WIDTH: f32 = 3.5;
/// Largest eccentricity of the filter ellipse.
const MAX_ECCENTRICITY: f32 = 15.0;
/// Bound on edge crossings from one lookup: far more than any kernel of
/// extent at most one face needs on a valid mesh; it stops cycles in
/// damaged adjacency data.
const MAX_DEPTH: u32 = 32;

/// A kernel in a face's barycentric coordinates.
#[derive(Clone, Copy, Debug)]
struct TriKernel {
    /// Resolution (log2) the kernel is applied at.
    res: i32,
    u: f32,
    v: f32,
    /// Lower and upper bounds of u, v and w.
    u1: f32,
    v1: f32,
    w1: f32,
    u2: f32,
    v2: f32,
    w2: f32,
    /// Ellipse coefficients.
    a: f32,
    b: f32,
    c: f32,
}

/// The Gaussian of the squared ellipse distance.
#[inline]
fn gaussian(q: f32) -> f32 {
    (-0.5 * KERNEL_WIDTH * KERNEL_WIDTH * q).exp()
}

/// `PtexUtils::calcResFromWidth`: the log2 resolution whose texel is no
/// larger than `w`.
#[inline]
fn res_from_width(w: f32) -> i32 {
    127 - ((w.to_bits() >> 23) & 0xff) as i32
}

impl TriKernel {
    /// Builds the kernel at (u, v) for the footprint vectors (uw1, vw1)
    /// and (uw2, vw2) on a face of resolution 2^`face_log2`.
    fn new(u: f32, v: f32, uw1: f32, vw1: f32, uw2: f32, vw2: f32, face_log2: i32) -> Self {
        let sqrt3 = 3.0f32.sqrt();
        // Ellipse A u² + B u v + C v² = AC − B²/4 (filter width 1).
        let a = (vw1 * vw1 + vw2 * vw2) * 0.25;
        let b = (uw1 * vw1 + uw2 * vw2) * -0.5;
        let c = (uw1 * uw1 + uw2 * uw2) * 0.25;
        // To a Cartesian (equilateral) frame.
        let mut ac = 0.75 * a;
        let bc = sqrt3 / 2.0 * (b - a);
        let mut cc = 0.25 * a - 0.5 * b + c;
        // Blur: bounded eccentricity, no smaller than a texel.
        let ecc_ratio = (MAX_ECCENTRICITY * MAX_ECCENTRICITY + 1.0)
            / (MAX_ECCENTRICITY * MAX_ECCENTRICITY - 1.0);
        let x = ((ac - cc) * (ac - cc) + bc * bc).sqrt();
        let b_e = 0.5 * (ecc_ratio * x - (ac + cc));
        let texel = 0.5 / (1u32 << face_log2) as f32;
        let blur = b_e.max(texel * texel);
        ac += blur;
        cc += blur;
        // Minor radius picks the resolution.
        let m = (2.0 * (ac * cc - 0.25 * bc * bc) / (ac + cc + x)).sqrt();
        let res = res_from_width(2.0 * m).max(0);
        // Back to the triangle's frame, scaled by the kernel width.
        let a = 4.0 / 3.0 * ac;
        let b = 2.0 / sqrt3 * bc + a;
        let c = -0.25 * a + 0.5 * b + cc;
        let s = KERNEL_WIDTH * KERNEL_WIDTH;
        let (a, b, c) = (a * s, b * s, c * s);
        let uw = c.sqrt().min(1.0);
        let vw = a.sqrt().min(1.0);
        let ww = (a - b + c).sqrt().min(1.0);
        let w = 1.0 - u - v;
        TriKernel {
            res,
            u,
            v,
            u1: u - uw,
            v1: v - vw,
            w1: w - ww,
            u2: u + uw,
            v2: v + vw,
            w2: w + ww,
            a,
            b,
            c,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn set(&mut self, u: f32, v: f32, u1: f32, v1: f32, w1: f32, u2: f32, v2: f32, w2: f32) {
        self.u = u;
        self.v = v;
        self.u1 = u1;
        self.v1 = v1;
        self.w1 = w1;
        self.u2 = u2;
        self.v2 = v2;
        self.w2 = w2;
    }

    /// The ellipse in coordinates u' = w, v' = u, w' = v.
    fn rotate1(&mut self) {
        let (a, b, c) = (self.a, self.b, self.c);
        (self.a, self.b, self.c) = (c, 2.0 * c - b, a + c - b);
    }

    /// The ellipse in coordinates u' = v, v' = w, w' = u.
    fn rotate2(&mut self) {
        let (a, b, c) = (self.a, self.b, self.c);
        (self.a, self.b, self.c) = (a + c - b, 2.0 * a - b, a);
    }

    /// Re-expresses the kernel, which lies beyond edge `eid` of its face,
    /// in the coordinates of the neighbour across it, whose edge `aeid`
    /// is the shared one.
    fn reorient(&mut self, eid: usize, aeid: usize) {
        let (u, v) = (self.u, self.v);
        let w = 1.0 - u - v;
        let (u1, v1, w1, u2, v2, w2) = (self.u1, self.v1, self.w1, self.u2, self.v2, self.w2);
        match (eid, aeid) {
            (0, 0) => self.set(
                1.0 - u,
                -v,
                1.0 - u2,
                -v2,
                1.0 - w2,
                1.0 - u1,
                -v1,
                1.0 - w1,
            ),
            (0, 1) => {
                self.set(
                    1.0 - w,
                    1.0 - u,
                    1.0 - w2,
                    1.0 - u2,
                    -v2,
                    1.0 - w1,
                    1.0 - u1,
                    -v1,
                );
                self.rotate1();
            }
            (0, _) => {
                self.set(
                    -v,
                    1.0 - w,
                    -v2,
                    1.0 - w2,
                    1.0 - u2,
                    -v1,
                    1.0 - w1,
                    1.0 - u1,
                );
                self.rotate2();
            }
            (1, 0) => {
                self.set(
                    1.0 - v,
                    -w,
                    1.0 - v2,
                    -w2,
                    1.0 - u2,
                    1.0 - v1,
                    -w1,
                    1.0 - u1,
                );
                self.rotate2();
            }
            (1, 1) => self.set(
                1.0 - u,
                1.0 - v,
                1.0 - u2,
                1.0 - v2,
                -w2,
                1.0 - u1,
                1.0 - v1,
                -w1,
            ),
            (1, _) => {
                self.set(
                    -w,
                    1.0 - u,
                    -w2,
                    1.0 - u2,
                    1.0 - v2,
                    -w1,
                    1.0 - u1,
                    1.0 - v1,
                );
                self.rotate1();
            }
            (_, 0) => {
                self.set(
                    1.0 - w,
                    -u,
                    1.0 - w2,
                    -u2,
                    1.0 - v2,
                    1.0 - w1,
                    -u1,
                    1.0 - v1,
                );
                self.rotate1();
            }
            (_, 1) => {
                self.set(
                    1.0 - v,
                    1.0 - w,
                    1.0 - v2,
                    1.0 - w2,
                    -u2,
                    1.0 - v1,
                    1.0 - w1,
                    -u1,
                );
                self.rotate2();
            }
            (_, _) => self.set(
                -u,
                1.0 - v,
                -u2,
                1.0 - v2,
                1.0 - w2,
                -u1,
                1.0 - v1,
                1.0 - w1,
            ),
        }
    }
}

/// A kernel over one half (even or odd triangles) of a face's texel
/// array, in texel units.
struct TriIter {
    rowlen: i32,
    u: f32,
    v: f32,
    u1: i32,
    v1: i32,
    w1: i32,
    u2: i32,
    v2: i32,
    w2: i32,
    a: f32,
    b: f32,
    c: f32,
    wscale: f32,
}

/// `ceil(x)` as an index, kept in [lo, hi] (non-finite values go to `lo`).
#[inline]
fn ceil_index(x: f32, lo: i32, hi: i32) -> i32 {
    if x.is_nan() {
        return lo;
    }
    (x.ceil().clamp(lo as f32, hi as f32)) as i32
}

impl TriIter {
    fn valid(&self) -> bool {
        self.u2 > self.u1 && self.v2 > self.v1 && self.w2 > self.w1
    }

    /// Adds the weighted texels of `data` (`nc` channels, `rowlen`² texels,
    /// or one constant pixel) to `acc`; returns the weight applied.
    fn apply(&self, data: Option<&[f32]>, constant: &[f32], nc: usize, acc: &mut [f64]) -> f64 {
        let ddq = 2.0 * self.a;
        let mut total = 0.0f64;
        for vi in self.v1..self.v2 {
            let xw = self.rowlen - vi;
            let x1 = self.u1.max(xw - self.w2).max(0);
            let x2 = self.u2.min(xw - self.w1).min(self.rowlen);
            let uu = x1 as f32 - self.u;
            let vv = vi as f32 - self.v;
            let mut dq = self.a * (2.0 * uu + 1.0) + self.b * vv;
            let mut q = self.a * uu * uu + (self.b * uu + self.c * vv) * vv;
            for x in x1..x2 {
                if q < 1.0 {
                    let w = gaussian(q) * self.wscale;
                    total += w as f64;
                    if let Some(t) = data {
                        let o = (vi * self.rowlen + x) as usize * nc;
                        for c in 0..nc {
                            acc[c] += (w * t[o + c]) as f64;
                        }
                    }
                }
                q += dq;
                dq += ddq;
            }
        }
        if data.is_none() {
            for (a, c) in acc.iter_mut().zip(constant) {
                *a += total * *c as f64;
            }
        }
        total
    }
}

impl PtexFace {
    /// The face's texels at resolution 2^`log2` (at most its own) for a
    /// triangle face: level 0 or a cached reduction; `None` when the face
    /// is constant.
    fn triangle_texels(&self, nc: usize, log2: u8) -> Option<&[f32]> {
        let t = self.texels.as_deref()?;
        let depth = self.ulog2.saturating_sub(log2) as usize;
        if depth == 0 {
            return Some(t);
        }
        let levels = self.reductions.get_or_init(|| {
            let mut levels: Vec<Box<[f32]>> = Vec::new();
            let mut w = self.ures();
            while w > 1 {
                let src: &[f32] = levels.last().map_or(t, |l| l);
                levels.push(reduce_triangle(src, w, nc));
                w /= 2;
            }
            levels.into_boxed_slice()
        });
        levels.get(depth - 1).map(|l| &l[..])
    }
}

/// Halves a triangle face's resolution: each small triangle of the result
/// is the mean of the four it covers (Ptex `reduceTri`).
fn reduce_triangle(src: &[f32], w: usize, nc: usize) -> Box<[f32]> {
    let h = w / 2;
    let mut out = vec![0.0f32; h * h * nc];
    let px = |x: usize, y: usize, c: usize| src[(y * w + x) * nc + c];
    for j in 0..h {
        for i in 0..h {
            for c in 0..nc {
                out[(j * h + i) * nc + c] = 0.25
                    * (px(2 * i, 2 * j, c)
                        + px(2 * i + 1, 2 * j, c)
                        + px(2 * i, 2 * j + 1, c)
                        + px(w - 1 - 2 * j, w - 1 - 2 * i, c));
            }
        }
    }
    out.into_boxed_slice()
}

/// Accumulated sums of one triangle lookup.
struct Accum<'a> {
    file: &'a PtexFile,
    acc: &'a mut [f64],
    weight: f64,
}

impl Accum<'_> {
    fn split_and_apply(&mut self, mut k: TriKernel, faceid: usize, depth: u32) {
        let f = &self.file.faces[faceid];
        // Edges: 2 where u < 0, 0 where v < 0, 1 where w < 0.
        if depth < MAX_DEPTH {
            if k.u1 < 0.0 && f.adj_faces[2] >= 0 {
                let mut ka = k;
                k.u1 = 0.0;
                ka.u2 = 0.0;
                self.across_edge(ka, f, 2, depth);
            }
            if k.v1 < 0.0 && f.adj_faces[0] >= 0 {
                let mut ka = k;
                k.v1 = 0.0;
                ka.v2 = 0.0;
                self.across_edge(ka, f, 0, depth);
            }
            if k.w1 < 0.0 && f.adj_faces[1] >= 0 {
                let mut ka = k;
                k.w1 = 0.0;
                ka.w2 = 0.0;
                self.across_edge(ka, f, 1, depth);
            }
        }
        self.apply(k, f);
    }

    fn across_edge(&mut self, mut k: TriKernel, f: &PtexFace, eid: usize, depth: u32) {
        let afid = f.adj_faces[eid] as usize;
        let aeid = f.adj_edge(eid);
        k.reorient(eid, aeid);
        self.split_and_apply(k, afid, depth + 1);
    }

    fn apply(&mut self, mut k: TriKernel, f: &PtexFace) {
        k.res = k.res.min(f.ulog2 as i32);
        k.u1 = k.u1.max(0.0);
        k.v1 = k.v1.max(0.0);
        k.w1 = k.w1.max(0.0);
        k.u2 = k.u2.min(1.0 - (k.v1 + k.w1));
        k.v2 = k.v2.min(1.0 - (k.w1 + k.u1));
        k.w2 = k.w2.min(1.0 - (k.u1 + k.v1));
        let n = 1i32 << k.res;
        let scale = n as f32;
        let finv = 1.0 / (scale * scale * (k.a * k.c - 0.25 * k.b * k.b));
        let (ak, bk, ck) = (k.a * finv, k.b * finv, k.c * finv);
        let off = 1.0 / 3.0;
        let idx = |x: f32| ceil_index(x * scale - off, -n - 1, n + 1);
        let even = TriIter {
            rowlen: n,
            u: k.u * scale - off,
            v: k.v * scale - off,
            u1: idx(k.u1).max(0),
            v1: idx(k.v1).max(0),
            w1: idx(k.w1),
            u2: idx(k.u2).min(n),
            v2: idx(k.v2).min(n),
            w2: idx(k.w2),
            a: ak,
            b: bk,
            c: ck,
            wscale: 1.0 / (scale * scale),
        };
        // The odd triangles, flipped across the diagonal: u = 1 − v,
        // v = 1 − u, w = −w.
        let odd = TriIter {
            rowlen: n,
            u: (1.0 - k.v) * scale - off,
            v: (1.0 - k.u) * scale - off,
            u1: idx(1.0 - k.v2).max(0),
            v1: idx(1.0 - k.u2).max(0),
            w1: idx(-k.w2),
            u2: idx(1.0 - k.v1).min(n),
            v2: idx(1.0 - k.u1).min(n),
            w2: idx(-k.w1),
            a: ck,
            b: bk,
            c: ak,
            wscale: even.wscale,
        };
        let nc = self.file.nchannels;
        let data = f.triangle_texels(nc, k.res as u8);
        if f.texels.is_some() && data.is_none() {
            return;
        }
        for it in [even, odd] {
            if it.valid() {
                self.weight += it.apply(data, &f.constant, nc, self.acc);
            }
        }
    }
}

impl PtexFile {
    /// The filtered value of triangle face `face` at barycentrics (u, v)
    /// (`out` holds `nchannels` values), for the footprint vectors
    /// (uw1, vw1) and (uw2, vw2); zeros for a face out of range.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn eval_triangle(
        &self,
        out: &mut [f32],
        face: usize,
        u: f32,
        v: f32,
        uw1: f32,
        vw1: f32,
        uw2: f32,
        vw2: f32,
    ) {
        let nc = self.nchannels;
        out[..nc].fill(0.0);
        let Some(f) = self.faces.get(face) else {
            return;
        };
        if f.flags & FLAG_NEIGHBORHOOD_CONSTANT != 0 || !u.is_finite() || !v.is_finite() {
            out[..nc].copy_from_slice(&f.constant);
            return;
        }
        let d = |x: f32| if x.is_finite() { x } else { 1.0 };
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let k = TriKernel::new(u, v, d(uw1), d(vw1), d(uw2), d(vw2), f.ulog2 as i32);
        let mut acc = vec![0.0f64; nc];
        let mut a = Accum {
            file: self,
            acc: &mut acc,
            weight: 0.0,
        };
        a.split_and_apply(k, face, 0);
        let weight = a.weight;
        super::filter::resolve_filtered(&acc, weight, &f.constant, out);
    }
}

#[cfg(test)]
mod tests;
