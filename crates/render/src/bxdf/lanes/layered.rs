//! The coated models' random walk over lanes (pbrt-v4 `LayeredBxDF` with
//! a dielectric top, two-sided, and no medium between the interfaces: what
//! `coateddiffuse` and `coatedconductor` are unless given an albedo; the
//! scalar walk in `../layered.rs` keeps the case with a medium).
//!
//! Each lane walks with its own random stream, seeded as the scalar walk
//! seeds it, and draws from it only while its walk goes on, so a lane's
//! numbers are the scalar walk's. `break` and `continue` become masks: a
//! lane whose walk ended stays in the loop without effect.

use super::interfaces::same_hemisphere;
use super::{
    and_not, any, bit, power_heuristic, sel_mask, BxDFLanes, DielectricLanes, SampleLanes,
    MAX_LANES, S4,
};
use crate::bxdf::layered::hash_floats;
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::rng::Rng;
use crate::simd::math::{self, lerp, V3};
use crate::simd::F32Lanes;
use rpbrt_geometry::float::{ONE_MINUS_EPSILON, PI};

/// A dielectric coating over `B`, per lane; the depth, sample count and
/// seed are the same for every lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LayeredLanes<L, B> {
    pub top: DielectricLanes<L>,
    pub bottom: B,
    pub thickness: L,
    pub max_depth: u32,
    pub n_samples: u32,
    pub seed: i32,
}

#[inline(always)]
fn neg<L: F32Lanes>(v: V3<L>) -> V3<L> {
    V3 {
        x: v.x.neg(),
        y: v.y.neg(),
        z: v.z.neg(),
    }
}

/// One random stream per lane.
struct Streams {
    rng: [Rng; MAX_LANES],
}

impl Streams {
    /// Streams seeded as the scalar walk seeds them: from the global seed
    /// and `a`, and from `b`, for the lanes of `m`.
    #[inline(always)]
    fn new<L: F32Lanes>(m: L::Mask, seed: i32, a: [L; 3], b: [L; 3]) -> Streams {
        let mut av = [[0.0f32; MAX_LANES]; 3];
        let mut bv = [[0.0f32; MAX_LANES]; 3];
        for k in 0..3 {
            a[k].store(&mut av[k]);
            b[k].store(&mut bv[k]);
        }
        let mut rng: [Rng; MAX_LANES] = std::array::from_fn(|_| Rng::from_raw((0, 1)));
        for (i, r) in rng.iter_mut().enumerate().take(L::N) {
            if bit::<L>(m, i) {
                let ai = [av[0][i], av[1][i], av[2][i]];
                let bi = [bv[0][i], bv[1][i], bv[2][i]];
                *r = Rng::new(hash_floats(Some(seed), &ai), hash_floats(None, &bi));
            }
        }
        Streams { rng }
    }

    /// The next number of each lane of `m` (the others: 0).
    #[inline(always)]
    fn draw<L: F32Lanes>(&mut self, m: L::Mask) -> L {
        let mut v = [0.0f32; MAX_LANES];
        for (i, (x, r)) in v.iter_mut().zip(self.rng.iter_mut()).enumerate().take(L::N) {
            if bit::<L>(m, i) {
                *x = r.uniform_float().min(ONE_MINUS_EPSILON);
            }
        }
        L::load(&v)
    }

    /// `uc`, then `u`.
    #[inline(always)]
    fn draw3<L: F32Lanes>(&mut self, m: L::Mask) -> (L, [L; 2]) {
        let uc = self.draw::<L>(m);
        let ux = self.draw::<L>(m);
        let uy = self.draw::<L>(m);
        (uc, [ux, uy])
    }
}

/// Lanes holding a sample with a value and a positive (or NaN) density,
/// as the scalar pdf estimate checks them.
#[inline(always)]
fn valid<L: F32Lanes>(s: &SampleLanes<L>) -> L::Mask {
    let zero = L::splat(0.0);
    L::and(L::and(s.ok, L::not(s.f.is_black())), L::not(s.pdf.le(zero)))
}

/// `tr(dz, w)`: the transmittance `e^−|dz / w.z|` (1 for no distance).
#[inline(always)]
fn tr<L: F32Lanes>(dz: L, w: V3<L>) -> L {
    let v = math::exp(dz.div(w.z).abs().neg());
    L::select(dz.abs().le(L::splat(f32::MIN_POSITIVE)), L::splat(1.0), v)
}

impl<L: F32Lanes, B: BxDFLanes<L>> LayeredLanes<L, B> {
    /// The top interface's sample for lanes not in `bottom`, the bottom's
    /// for lanes in it (each computed only where some lane needs it).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sample_at(
        &self,
        bottom: L::Mask,
        wo: V3<L>,
        uc: L,
        u: [L; 2],
        mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> SampleLanes<L> {
        let on_top = and_not::<L>(active, bottom);
        let on_bottom = L::and(active, bottom);
        let mut s = SampleLanes::none();
        if any::<L>(on_top) {
            s = self.top.sample_f(wo, uc, u, mode, flags, on_top);
        }
        if any::<L>(on_bottom) {
            let b = self.bottom.sample_f(wo, uc, u, mode, flags, on_bottom);
            s = SampleLanes::select(bottom, &b, &s);
        }
        s
    }

    /// f of the top or bottom interface, as [`Self::sample_at`] chooses.
    #[inline(always)]
    fn f_at(
        &self,
        bottom: L::Mask,
        wo: V3<L>,
        wi: V3<L>,
        mode: TransportMode,
        active: L::Mask,
    ) -> S4<L> {
        let on_top = and_not::<L>(active, bottom);
        let on_bottom = L::and(active, bottom);
        let mut f = S4::splat(0.0);
        if any::<L>(on_top) {
            f = self.top.f(wo, wi, mode, on_top);
        }
        if any::<L>(on_bottom) {
            f = S4::select(bottom, self.bottom.f(wo, wi, mode, on_bottom), f);
        }
        f
    }

    /// The pdf of the top or bottom interface, as [`Self::sample_at`]
    /// chooses.
    #[inline(always)]
    fn pdf_at(
        &self,
        bottom: L::Mask,
        wo: V3<L>,
        wi: V3<L>,
        mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> L {
        let on_top = and_not::<L>(active, bottom);
        let on_bottom = L::and(active, bottom);
        let mut p = L::splat(0.0);
        if any::<L>(on_top) {
            p = self.top.pdf(wo, wi, mode, flags, on_top);
        }
        if any::<L>(on_bottom) {
            p = L::select(bottom, self.bottom.pdf(wo, wi, mode, flags, on_bottom), p);
        }
        p
    }

    /// `wo` and `wi` mirrored for lanes where `wo` is below the surface
    /// (the model is two-sided).
    #[inline(always)]
    fn upper(wo: V3<L>, wi: V3<L>) -> (V3<L>, V3<L>) {
        let flip = wo.z.lt(L::splat(0.0));
        (V3::select(flip, neg(wo), wo), V3::select(flip, neg(wi), wi))
    }
}

impl<L: F32Lanes, B: BxDFLanes<L>> BxDFLanes<L> for LayeredLanes<L, B> {
    #[inline(always)]
    fn f(&self, wo: V3<L>, wi: V3<L>, mode: TransportMode, active: L::Mask) -> S4<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let th = self.thickness;
        let (wo, wi) = Self::upper(wo, wi);
        let same = same_hemisphere(wo, wi);
        // Entered at the top; leaves through the bottom when ωi is below.
        let exits_bottom = L::not(same);
        let exit_z = L::select(exits_bottom, zero, th);
        let ns = self.n_samples as f32;
        let mut f = S4::splat(0.0);
        if any::<L>(L::and(active, same)) {
            f = S4::select(
                same,
                self.top
                    .f(wo, wi, mode, L::and(active, same))
                    .scale(L::splat(ns)),
                f,
            );
        }
        let mut rng = Streams::new::<L>(active, self.seed, [wo.x, wo.y, wo.z], [wi.x, wi.y, wi.z]);
        let (top_spec, bottom_spec) = (self.top.flags_specular(), self.bottom.flags_specular());
        let exit_spec = sel_mask::<L>(exits_bottom, bottom_spec, top_spec);
        let non_exit_spec = sel_mask::<L>(exits_bottom, top_spec, bottom_spec);
        let non_exit_bottom = L::not(exits_bottom);
        let trans = BxDFReflTransFlags::TRANSMISSION;
        let refl = BxDFReflTransFlags::REFLECTION;
        let all = BxDFReflTransFlags::ALL;

        for _ in 0..self.n_samples {
            // Enter through the top along ωo; presample the exit toward ωi.
            let mut act = active;
            let (uc, u) = rng.draw3::<L>(act);
            let wos = self.top.sample_f(wo, uc, u, mode, trans, act);
            act = L::and(act, wos.usable());
            let (uc, u) = rng.draw3::<L>(act);
            let wis = self.sample_at(exits_bottom, wi, uc, u, !mode, trans, act);
            act = L::and(act, wis.usable());
            if !any::<L>(act) {
                continue;
            }
            let mut beta = wos.f.scale(wos.wi.z.abs()).div(wos.pdf);
            let mut z = th;
            let mut w = wos.wi;

            for depth in 0..self.max_depth {
                if !any::<L>(act) {
                    break;
                }
                if depth > 3 {
                    let m = beta.max_component();
                    let low = L::and(act, m.lt(L::splat(0.25)));
                    if any::<L>(low) {
                        let q = one.sub(m).max(zero);
                        let r = rng.draw::<L>(low);
                        let stop = L::and(low, r.lt(q));
                        act = and_not::<L>(act, stop);
                        let go = and_not::<L>(low, stop);
                        beta = S4::select(go, beta.div(one.sub(q)), beta);
                    }
                }
                // No medium: straight to the other interface.
                z = L::select(z.eq(th), zero, th);
                beta = beta.scale(tr(th, w));
                let at_exit = z.eq(exit_z);
                let ex = L::and(act, at_exit);
                let nx = and_not::<L>(act, at_exit);
                if any::<L>(ex) {
                    // Reflect off the exit interface back into the slab.
                    let (uc, u) = rng.draw3::<L>(ex);
                    let bs = self.sample_at(exits_bottom, neg(w), uc, u, mode, refl, ex);
                    let ok = bs.usable();
                    act = and_not::<L>(act, and_not::<L>(ex, ok));
                    let upd = L::and(ex, ok);
                    let t = bs.f.scale(bs.wi.z.abs()).div(bs.pdf);
                    beta = S4::select(upd, beta.mul(t), beta);
                    w = V3::select(upd, bs.wi, w);
                }
                if any::<L>(nx) {
                    // Next-event estimate through the exit along ωis.
                    let ne = and_not::<L>(nx, non_exit_spec);
                    if any::<L>(ne) {
                        let wt = if any::<L>(and_not::<L>(ne, exit_spec)) {
                            let p =
                                self.pdf_at(non_exit_bottom, neg(w), neg(wis.wi), mode, all, ne);
                            L::select(exit_spec, one, power_heuristic(wis.pdf, p))
                        } else {
                            one
                        };
                        let fne = self.f_at(non_exit_bottom, neg(w), neg(wis.wi), mode, ne);
                        let s = wis.wi.z.abs().mul(wt).mul(tr(th, wis.wi));
                        let add = beta.mul(fne).scale(s).mul(wis.f).div(wis.pdf);
                        f = S4::select(ne, f.add(add), f);
                    }
                    let (uc, u) = rng.draw3::<L>(nx);
                    let bs = self.sample_at(non_exit_bottom, neg(w), uc, u, mode, refl, nx);
                    let ok = bs.usable();
                    act = and_not::<L>(act, and_not::<L>(nx, ok));
                    let upd = L::and(nx, ok);
                    let t = bs.f.scale(bs.wi.z.abs()).div(bs.pdf);
                    beta = S4::select(upd, beta.mul(t), beta);
                    w = V3::select(upd, bs.wi, w);
                    // The sample may leave through the exit toward ωi.
                    let ce = and_not::<L>(upd, exit_spec);
                    if any::<L>(ce) {
                        let f_exit = self.f_at(exits_bottom, neg(w), wi, mode, ce);
                        let nz = and_not::<L>(ce, f_exit.is_black());
                        if any::<L>(nz) {
                            let wt = if any::<L>(and_not::<L>(nz, non_exit_spec)) {
                                let p = self.pdf_at(exits_bottom, neg(w), wi, mode, trans, nz);
                                L::select(non_exit_spec, one, power_heuristic(bs.pdf, p))
                            } else {
                                one
                            };
                            let add = beta.scale(tr(th, bs.wi)).mul(f_exit).scale(wt);
                            f = S4::select(nz, f.add(add), f);
                        }
                    }
                }
            }
        }
        f.div(L::splat(ns))
    }

    #[inline(always)]
    fn sample_f(
        &self,
        wo: V3<L>,
        uc: L,
        u: [L; 2],
        mode: TransportMode,
        _flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> SampleLanes<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let th = self.thickness;
        let all = BxDFReflTransFlags::ALL;
        let flip = wo.z.lt(zero);
        let wo = V3::select(flip, neg(wo), wo);
        let first = self.top.sample_f(wo, uc, u, mode, all, active);
        let ok = L::and(active, first.usable());
        let mut out = first;
        out.ok = ok;
        out.wi = V3::select(flip, neg(first.wi), first.wi);
        out.proportional = ok;
        let mut go = and_not::<L>(ok, first.reflection);
        if !any::<L>(go) {
            return out;
        }
        // Lanes that entered the slab: walk until they leave it.
        out.ok = and_not::<L>(out.ok, go);
        let mut rng = Streams::new::<L>(go, self.seed, [wo.x, wo.y, wo.z], [uc, u[0], u[1]]);
        let mut w = first.wi;
        let mut specular = first.specular;
        let mut f = first.f.scale(first.wi.z.abs());
        let mut pdf = first.pdf;
        let mut z = th;
        for depth in 0..self.max_depth {
            if !any::<L>(go) {
                break;
            }
            let rr_beta = f.max_component().div(pdf);
            if depth > 3 {
                let low = L::and(go, rr_beta.lt(L::splat(0.25)));
                if any::<L>(low) {
                    let q = one.sub(rr_beta).max(zero);
                    let r = rng.draw::<L>(low);
                    let stop = L::and(low, r.lt(q));
                    go = and_not::<L>(go, stop);
                    pdf = L::select(and_not::<L>(low, stop), pdf.mul(one.sub(q)), pdf);
                }
            }
            go = and_not::<L>(go, w.z.eq(zero));
            z = L::select(z.eq(th), zero, th);
            f = f.scale(tr(th, w));
            let (uc2, u2) = rng.draw3::<L>(go);
            let bs = self.sample_at(z.eq(zero), neg(w), uc2, u2, mode, all, go);
            go = L::and(go, bs.usable());
            f = S4::select(go, f.mul(bs.f), f);
            pdf = L::select(go, pdf.mul(bs.pdf), pdf);
            specular = sel_mask::<L>(go, L::and(specular, bs.specular), specular);
            w = V3::select(go, bs.wi, w);
            let left = and_not::<L>(go, bs.reflection);
            if any::<L>(left) {
                // The walk left the slab.
                let done = SampleLanes {
                    f,
                    wi: V3::select(flip, neg(w), w),
                    pdf,
                    eta: one,
                    ok: left,
                    reflection: same_hemisphere(wo, w),
                    specular,
                    diffuse: L::from_bits(0),
                    proportional: left,
                };
                out = SampleLanes::select(left, &done, &out);
                go = and_not::<L>(go, left);
            }
            f = S4::select(go, f.scale(bs.wi.z.abs()), f);
        }
        out
    }

    #[inline(always)]
    fn pdf(
        &self,
        wo: V3<L>,
        wi: V3<L>,
        mode: TransportMode,
        _flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> L {
        let zero = L::splat(0.0);
        let (wo, wi) = Self::upper(wo, wi);
        let mut rng = Streams::new::<L>(active, self.seed, [wi.x, wi.y, wi.z], [wo.x, wo.y, wo.z]);
        let ns = L::splat(self.n_samples as f32);
        let all = BxDFReflTransFlags::ALL;
        let trans = BxDFReflTransFlags::TRANSMISSION;
        let same = same_hemisphere(wo, wi);
        let mut sum = zero;
        if any::<L>(L::and(active, same)) {
            let p = self
                .top
                .pdf(wo, wi, mode, BxDFReflTransFlags::REFLECTION, active);
            sum = L::select(same, ns.mul(p), zero);
        }
        let top_ns = self.top.flags_non_specular();
        let bottom_ns = self.bottom.flags_non_specular();
        let (top_spec, bottom_spec) = (self.top.flags_specular(), self.bottom.flags_specular());
        for _ in 0..self.n_samples {
            let trt = L::and(active, same);
            if any::<L>(trt) {
                // Transmission, reflection inside, transmission.
                let (uc, u) = rng.draw3::<L>(trt);
                let wos = self.top.sample_f(wo, uc, u, mode, trans, trt);
                let (uc, u) = rng.draw3::<L>(trt);
                let wis = self.top.sample_f(wi, uc, u, !mode, trans, trt);
                let ok = L::and(trt, L::and(valid(&wos), valid(&wis)));
                let a = and_not::<L>(ok, top_ns);
                if any::<L>(a) {
                    let p = self.bottom.pdf(neg(wos.wi), neg(wis.wi), mode, all, a);
                    sum = L::select(a, sum.add(p), sum);
                }
                let b = L::and(ok, top_ns);
                if any::<L>(b) {
                    let (uc, u) = rng.draw3::<L>(b);
                    let rs = self.bottom.sample_f(neg(wos.wi), uc, u, mode, all, b);
                    let okr = L::and(b, valid(&rs));
                    let c = and_not::<L>(okr, bottom_ns);
                    if any::<L>(c) {
                        let p = self.top.pdf(neg(rs.wi), wi, mode, all, c);
                        sum = L::select(c, sum.add(p), sum);
                    }
                    let d = L::and(okr, bottom_ns);
                    if any::<L>(d) {
                        let r_pdf = self.bottom.pdf(neg(wos.wi), neg(wis.wi), mode, all, d);
                        let s1 = sum.add(power_heuristic(wis.pdf, r_pdf).mul(r_pdf));
                        let t_pdf = self.top.pdf(neg(rs.wi), wi, mode, all, d);
                        let s2 = s1.add(power_heuristic(rs.pdf, t_pdf).mul(t_pdf));
                        sum = L::select(d, s2, sum);
                    }
                }
            }
            let tt = and_not::<L>(active, same);
            if any::<L>(tt) {
                // Transmission through both interfaces.
                let (uc, u) = rng.draw3::<L>(tt);
                let wos = self.top.sample_f(wo, uc, u, mode, all, tt);
                let ok1 = and_not::<L>(L::and(tt, wos.usable()), wos.reflection);
                let (uc, u) = rng.draw3::<L>(ok1);
                let wis = self.bottom.sample_f(wi, uc, u, !mode, all, ok1);
                let ok2 = and_not::<L>(L::and(ok1, wis.usable()), wis.reflection);
                if any::<L>(ok2) {
                    let e1 = L::and(ok2, top_spec);
                    let rest = and_not::<L>(ok2, top_spec);
                    let e2 = L::and(rest, bottom_spec);
                    let e3 = and_not::<L>(rest, bottom_spec);
                    let pb = self.bottom.pdf(neg(wos.wi), wi, mode, all, L::or(e1, e3));
                    let pt = self.top.pdf(wo, neg(wis.wi), mode, all, L::or(e2, e3));
                    let v = L::select(e1, pb, L::select(e2, pt, pt.add(pb).div(L::splat(2.0))));
                    sum = L::select(ok2, sum.add(v), sum);
                }
            }
        }
        lerp(L::splat(0.9), L::splat(1.0 / (4.0 * PI)), sum.div(ns))
    }

    #[inline(always)]
    fn flags_specular(&self) -> L::Mask {
        self.top.flags_specular()
    }

    #[inline(always)]
    fn flags_non_specular(&self) -> L::Mask {
        L::or(
            self.top.flags_non_specular(),
            self.bottom.flags_non_specular(),
        )
    }
}
