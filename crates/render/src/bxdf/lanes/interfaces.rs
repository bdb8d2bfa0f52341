//! The diffuse, conductor and dielectric BxDFs over lanes (pbrt-v4
//! `DiffuseBxDF`, `ConductorBxDF`, `DielectricBxDF`; the scalar models in
//! `../diffuse.rs`, `../conductor.rs` and `../dielectric.rs` call these at
//! width one).

use super::{and_not, any, sel_mask, splat_mask, BxDFLanes, SampleLanes, TrLanes, S4};
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::simd::math::{self, clamp, safe_sqrt, sign_bit, V3};
use crate::simd::F32Lanes;
use rpbrt_geometry::float::{INV_PI, PI_OVER_4};

#[inline(always)]
fn sqr<L: F32Lanes>(x: L) -> L {
    x.mul(x)
}

#[inline(always)]
fn neg<L: F32Lanes>(v: V3<L>) -> V3<L> {
    V3 {
        x: v.x.neg(),
        y: v.y.neg(),
        z: v.z.neg(),
    }
}

/// Lanes where `a` and `b` lie on the same side of the plane.
#[inline(always)]
pub(crate) fn same_hemisphere<L: F32Lanes>(a: V3<L>, b: V3<L>) -> L::Mask {
    a.z.mul(b.z).gt(L::splat(0.0))
}

/// `v.face_forward(+z)`: `v` flipped when `v · (0, 0, 1) < 0`.
#[inline(always)]
fn face_forward_z<L: F32Lanes>(v: V3<L>) -> V3<L> {
    let (z, o) = (L::splat(0.0), L::splat(1.0));
    let d = v.dot(V3 { x: z, y: z, z: o });
    V3::select(d.lt(z), neg(v), v)
}

/// `reflect(wo, n)`: `−wo + n (2 wo·n)`.
#[inline(always)]
fn reflect<L: F32Lanes>(wo: V3<L>, n: V3<L>) -> V3<L> {
    neg(wo).add(n.scale(L::splat(2.0).mul(wo.dot(n))))
}

/// `refract(wi, n, eta)`: the transmitted direction, the relative index
/// used, and the lanes without total internal reflection.
#[inline(always)]
fn refract<L: F32Lanes>(wi: V3<L>, n: V3<L>, eta: L) -> (V3<L>, L, L::Mask) {
    let zero = L::splat(0.0);
    let c = n.dot(wi);
    let inside = c.lt(zero);
    let eta = L::select(inside, L::splat(1.0).div(eta), eta);
    let c = L::select(inside, c.neg(), c);
    let n = V3::select(inside, neg(n), n);
    let sin2_i = L::splat(1.0).sub(sqr(c)).max(zero);
    let sin2_t = sin2_i.div(sqr(eta));
    let ok = L::not(sin2_t.ge(L::splat(1.0)));
    let cos_t = safe_sqrt(L::splat(1.0).sub(sin2_t));
    let wt = neg(wi).div(eta).add(n.scale(c.div(eta).sub(cos_t)));
    (wt, eta, ok)
}

/// `fr_dielectric(cos θi, eta)`.
#[inline(always)]
pub(crate) fn fr_dielectric<L: F32Lanes>(cos_i: L, eta: L) -> L {
    let zero = L::splat(0.0);
    let c = clamp(cos_i, -1.0, 1.0);
    let inside = c.lt(zero);
    let eta = L::select(inside, L::splat(1.0).div(eta), eta);
    let c = L::select(inside, c.neg(), c);
    let sin2_i = L::splat(1.0).sub(sqr(c));
    let sin2_t = sin2_i.div(sqr(eta));
    let tir = sin2_t.ge(L::splat(1.0));
    let cos_t = safe_sqrt(L::splat(1.0).sub(sin2_t));
    let r_parl = eta.mul(c).sub(cos_t).div(eta.mul(c).add(cos_t));
    let r_perp = c.sub(eta.mul(cos_t)).div(c.add(eta.mul(cos_t)));
    let r = sqr(r_parl).add(sqr(r_perp)).div(L::splat(2.0));
    L::select(tir, L::splat(1.0), r)
}

/// A complex number per lane, with the scalar `Complex`'s operations.
#[derive(Clone, Copy)]
struct C<L> {
    re: L,
    im: L,
}

impl<L: F32Lanes> C<L> {
    #[inline(always)]
    fn real(re: L) -> Self {
        C {
            re,
            im: L::splat(0.0),
        }
    }
    #[inline(always)]
    fn norm(self) -> L {
        sqr(self.re).add(sqr(self.im))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        C {
            re: self.re.add(o.re),
            im: self.im.add(o.im),
        }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        C {
            re: self.re.sub(o.re),
            im: self.im.sub(o.im),
        }
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        C {
            re: self.re.mul(o.re).sub(self.im.mul(o.im)),
            im: self.re.mul(o.im).add(self.im.mul(o.re)),
        }
    }
    #[inline(always)]
    fn scale(self, s: L) -> Self {
        C {
            re: self.re.mul(s),
            im: self.im.mul(s),
        }
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let scale = L::splat(1.0).div(o.norm());
        C {
            re: scale.mul(self.re.mul(o.re).add(self.im.mul(o.im))),
            im: scale.mul(self.im.mul(o.re).sub(self.re.mul(o.im))),
        }
    }
    /// `s + c` for real `s`.
    #[inline(always)]
    fn radd(s: L, c: Self) -> Self {
        C {
            re: s.add(c.re),
            im: c.im,
        }
    }
    /// `s − c` for real `s`.
    #[inline(always)]
    fn rsub(s: L, c: Self) -> Self {
        C {
            re: s.sub(c.re),
            im: c.im.neg(),
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let zero = L::splat(0.0);
        let n = self.norm().sqrt();
        let t1 = L::splat(0.5).mul(n.add(self.re.abs())).sqrt();
        let t2 = L::splat(0.5).mul(self.im).div(t1);
        let pos = self.re.ge(zero);
        let t1s = L::select(sign_bit(self.im), t1.neg(), t1);
        let root = C {
            re: L::select(pos, t1, t2.abs()),
            im: L::select(pos, t2, t1s),
        };
        let z = n.eq(zero);
        C {
            re: L::select(z, zero, root.re),
            im: L::select(z, zero, root.im),
        }
    }
}

/// `fr_complex(cos θi, eta + i k)`.
#[inline(always)]
fn fr_complex<L: F32Lanes>(cos_i: L, eta: L, k: L) -> L {
    let c = clamp(cos_i, 0.0, 1.0);
    let e = C { re: eta, im: k };
    let sin2_i = L::splat(1.0).sub(sqr(c));
    let sin2_t = C::real(sin2_i).div(e.mul(e));
    let cos_t = C::rsub(L::splat(1.0), sin2_t).sqrt();
    let ec = e.scale(c);
    let r_parl = ec.sub(cos_t).div(ec.add(cos_t));
    let ect = e.mul(cos_t);
    let r_perp = C::rsub(c, ect).div(C::radd(c, ect));
    r_parl.norm().add(r_perp.norm()).div(L::splat(2.0))
}

/// `fr_complex_spectrum`: [`fr_complex`] at each wavelength.
#[inline(always)]
fn fr_complex_spectrum<L: F32Lanes>(cos_i: L, eta: &S4<L>, k: &S4<L>) -> S4<L> {
    let (e, k) = (eta.0, k.0);
    S4([
        fr_complex(cos_i, e[0], k[0]),
        fr_complex(cos_i, e[1], k[1]),
        fr_complex(cos_i, e[2], k[2]),
        fr_complex(cos_i, e[3], k[3]),
    ])
}

/// Lambertian reflection per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DiffuseLanes<L> {
    pub r: S4<L>,
}

/// `sample_uniform_disk_concentric` then the lift to the hemisphere.
#[inline(always)]
fn cosine_hemisphere<L: F32Lanes>(u: [L; 2]) -> V3<L> {
    let (zero, one, two) = (L::splat(0.0), L::splat(1.0), L::splat(2.0));
    let ox = two.mul(u[0]).sub(one);
    let oy = two.mul(u[1]).sub(one);
    let center = L::and(ox.eq(zero), oy.eq(zero));
    let x_major = ox.abs().gt(oy.abs());
    let r = L::select(x_major, ox, oy);
    let phi = L::splat(PI_OVER_4).mul(L::select(x_major, oy.div(ox), ox.div(oy)));
    let (sin_phi, cos_phi) = math::sin_cos(phi);
    let cos_t = L::select(x_major, cos_phi, sin_phi);
    let sin_t = L::select(x_major, sin_phi, cos_phi);
    let dx = L::select(center, zero, r.mul(cos_t));
    let dy = L::select(center, zero, r.mul(sin_t));
    let z = safe_sqrt(one.sub(dx.mul(dx)).sub(dy.mul(dy)));
    V3 { x: dx, y: dy, z }
}

impl<L: F32Lanes> BxDFLanes<L> for DiffuseLanes<L> {
    #[inline(always)]
    fn f(&self, wo: V3<L>, wi: V3<L>, _mode: TransportMode, _active: L::Mask) -> S4<L> {
        let v = self.r.scale(L::splat(INV_PI));
        S4::select(same_hemisphere(wo, wi), v, S4::splat(0.0))
    }

    #[inline(always)]
    fn sample_f(
        &self,
        wo: V3<L>,
        _uc: L,
        u: [L; 2],
        _mode: TransportMode,
        flags: BxDFReflTransFlags,
        _active: L::Mask,
    ) -> SampleLanes<L> {
        if !flags.contains(BxDFReflTransFlags::REFLECTION) {
            return SampleLanes::none();
        }
        let mut wi = cosine_hemisphere(u);
        wi.z = L::select(wo.z.lt(L::splat(0.0)), wi.z.neg(), wi.z);
        let t = splat_mask::<L>(true);
        SampleLanes {
            f: self.r.scale(L::splat(INV_PI)),
            wi,
            pdf: wi.z.abs().mul(L::splat(INV_PI)),
            eta: L::splat(1.0),
            ok: t,
            reflection: t,
            specular: splat_mask::<L>(false),
            diffuse: t,
            proportional: splat_mask::<L>(false),
        }
    }

    #[inline(always)]
    fn pdf(
        &self,
        wo: V3<L>,
        wi: V3<L>,
        _mode: TransportMode,
        flags: BxDFReflTransFlags,
        _active: L::Mask,
    ) -> L {
        if !flags.contains(BxDFReflTransFlags::REFLECTION) {
            return L::splat(0.0);
        }
        let v = wi.z.abs().mul(L::splat(INV_PI));
        L::select(same_hemisphere(wo, wi), v, L::splat(0.0))
    }

    #[inline(always)]
    fn flags_specular(&self) -> L::Mask {
        splat_mask::<L>(false)
    }

    #[inline(always)]
    fn flags_non_specular(&self) -> L::Mask {
        L::not(self.r.is_black())
    }
}

/// A smooth or rough conductor per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ConductorLanes<L> {
    pub d: TrLanes<L>,
    pub eta: S4<L>,
    pub k: S4<L>,
}

impl<L: F32Lanes> ConductorLanes<L> {
    #[inline(always)]
    fn torrance_sparrow(&self, wo: V3<L>, wi: V3<L>, wm: V3<L>) -> S4<L> {
        let f = fr_complex_spectrum(wo.dot(wm).abs(), &self.eta, &self.k);
        let s = self
            .d
            .d(wm)
            .mul(self.d.g(wo, wi))
            .div(L::splat(4.0).mul(wi.z.abs()).mul(wo.z.abs()));
        f.scale(s)
    }
}

impl<L: F32Lanes> BxDFLanes<L> for ConductorLanes<L> {
    #[inline(always)]
    fn f(&self, wo: V3<L>, wi: V3<L>, _mode: TransportMode, _active: L::Mask) -> S4<L> {
        let zero = L::splat(0.0);
        let wm = wi.add(wo);
        let bad = L::or(
            L::or(L::not(same_hemisphere(wo, wi)), self.d.smooth()),
            L::or(
                L::or(wi.z.abs().eq(zero), wo.z.abs().eq(zero)),
                wm.dot(wm).eq(zero),
            ),
        );
        let v = self.torrance_sparrow(wo, wi, wm.normalize());
        S4::select(bad, S4::splat(0.0), v)
    }

    #[inline(always)]
    fn sample_f(
        &self,
        wo: V3<L>,
        _uc: L,
        u: [L; 2],
        _mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> SampleLanes<L> {
        if !flags.contains(BxDFReflTransFlags::REFLECTION) {
            return SampleLanes::none();
        }
        let zero = L::splat(0.0);
        let smooth = self.d.smooth();
        let t = splat_mask::<L>(true);
        let mut out = SampleLanes::none();
        if any::<L>(L::and(active, smooth)) {
            let wi = V3 {
                x: wo.x.neg(),
                y: wo.y.neg(),
                z: wo.z,
            };
            let c = wi.z.abs();
            out = SampleLanes {
                f: fr_complex_spectrum(c, &self.eta, &self.k).div(c),
                wi,
                pdf: L::splat(1.0),
                eta: L::splat(1.0),
                ok: t,
                reflection: t,
                specular: t,
                diffuse: splat_mask::<L>(false),
                proportional: splat_mask::<L>(false),
            };
        }
        let rough = and_not::<L>(active, smooth);
        if any::<L>(rough) {
            let wm = self.d.sample_wm(wo, u);
            let wi = reflect(wo, wm);
            let pdf = self.d.pdf(wo, wm).div(L::splat(4.0).mul(wo.dot(wm).abs()));
            let ok = L::and(
                L::and(L::not(wo.z.eq(zero)), same_hemisphere(wo, wi)),
                L::and(L::not(wi.z.abs().eq(zero)), L::not(wo.z.abs().eq(zero))),
            );
            let r = SampleLanes {
                f: self.torrance_sparrow(wo, wi, wm),
                wi,
                pdf,
                eta: L::splat(1.0),
                ok,
                reflection: t,
                specular: splat_mask::<L>(false),
                diffuse: splat_mask::<L>(false),
                proportional: splat_mask::<L>(false),
            };
            out = SampleLanes::select(smooth, &out, &r);
        }
        out
    }

    #[inline(always)]
    fn pdf(
        &self,
        wo: V3<L>,
        wi: V3<L>,
        _mode: TransportMode,
        flags: BxDFReflTransFlags,
        _active: L::Mask,
    ) -> L {
        let zero = L::splat(0.0);
        if !flags.contains(BxDFReflTransFlags::REFLECTION) {
            return zero;
        }
        let wm = wo.add(wi);
        let bad = L::or(
            L::or(L::not(same_hemisphere(wo, wi)), self.d.smooth()),
            wm.dot(wm).eq(zero),
        );
        let wm = face_forward_z(wm.normalize());
        let v = self.d.pdf(wo, wm).div(L::splat(4.0).mul(wo.dot(wm).abs()));
        L::select(bad, zero, v)
    }

    #[inline(always)]
    fn flags_specular(&self) -> L::Mask {
        self.d.smooth()
    }

    #[inline(always)]
    fn flags_non_specular(&self) -> L::Mask {
        L::not(self.d.smooth())
    }
}

/// A smooth or rough dielectric interface per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DielectricLanes<L> {
    pub eta: L,
    pub d: TrLanes<L>,
}

/// The probabilities of reflection and transmission that `flags` allow.
#[inline(always)]
fn choice<L: F32Lanes>(r: L, flags: BxDFReflTransFlags) -> (L, L) {
    let zero = L::splat(0.0);
    let pr = if flags.contains(BxDFReflTransFlags::REFLECTION) {
        r
    } else {
        zero
    };
    let pt = if flags.contains(BxDFReflTransFlags::TRANSMISSION) {
        L::splat(1.0).sub(r)
    } else {
        zero
    };
    (pr, pt)
}

impl<L: F32Lanes> DielectricLanes<L> {
    /// Lanes that behave specularly (an index of 1 or a smooth surface).
    #[inline(always)]
    fn specular(&self) -> L::Mask {
        L::or(self.eta.eq(L::splat(1.0)), self.d.smooth())
    }

    /// The generalized half vector of `wo` and `wi`, its relative index,
    /// whether the pair is a reflection, and the lanes where it exists.
    #[inline(always)]
    fn half_vector(&self, wo: V3<L>, wi: V3<L>) -> (V3<L>, L, L::Mask, L::Mask) {
        let zero = L::splat(0.0);
        let (cos_o, cos_i) = (wo.z, wi.z);
        let refl = cos_i.mul(cos_o).gt(zero);
        let etap = L::select(
            refl,
            L::splat(1.0),
            L::select(cos_o.gt(zero), self.eta, L::splat(1.0).div(self.eta)),
        );
        let wm = wi.scale(etap).add(wo);
        let bad = L::or(L::or(cos_i.eq(zero), cos_o.eq(zero)), wm.dot(wm).eq(zero));
        let wm = face_forward_z(wm.normalize());
        let bad = L::or(
            bad,
            L::or(
                wm.dot(wi).mul(cos_i).lt(zero),
                wm.dot(wo).mul(cos_o).lt(zero),
            ),
        );
        (wm, etap, refl, L::not(bad))
    }
}

impl<L: F32Lanes> BxDFLanes<L> for DielectricLanes<L> {
    #[inline(always)]
    fn f(&self, wo: V3<L>, wi: V3<L>, mode: TransportMode, _active: L::Mask) -> S4<L> {
        let (wm, etap, refl, ok) = self.half_vector(wo, wi);
        let ok = and_not::<L>(ok, self.specular());
        if !any::<L>(ok) {
            return S4::splat(0.0);
        }
        let fr = fr_dielectric(wo.dot(wm), self.eta);
        let d = &self.d;
        let dm = d.d(wm);
        let g = d.g(wo, wi);
        let four = L::splat(4.0);
        let vr = dm.mul(g).mul(fr).div(four.mul(wi.z).mul(wo.z).abs());
        let ft = if any::<L>(and_not::<L>(ok, refl)) {
            let denom = sqr(wi.dot(wm).add(wo.dot(wm).div(etap)))
                .mul(wi.z)
                .mul(wo.z);
            let ft = dm
                .mul(L::splat(1.0).sub(fr))
                .mul(g)
                .mul(wi.dot(wm).mul(wo.dot(wm)).div(denom).abs());
            if mode == TransportMode::Radiance {
                ft.div(sqr(etap))
            } else {
                ft
            }
        } else {
            vr
        };
        let v = L::select(refl, vr, ft);
        S4::uniform(L::select(ok, v, L::splat(0.0)))
    }

    #[inline(always)]
    fn sample_f(
        &self,
        wo: V3<L>,
        uc: L,
        u: [L; 2],
        mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> SampleLanes<L> {
        let zero = L::splat(0.0);
        let t = splat_mask::<L>(true);
        let f = splat_mask::<L>(false);
        let specular = self.specular();
        let mut out = SampleLanes::none();
        if any::<L>(L::and(active, specular)) {
            let r = fr_dielectric(wo.z, self.eta);
            let (pr, pt) = choice(r, flags);
            let some = L::not(L::and(pr.eq(zero), pt.eq(zero)));
            let p_refl = pr.div(pr.add(pt));
            let is_r = uc.lt(p_refl);
            let wr = V3 {
                x: wo.x.neg(),
                y: wo.y.neg(),
                z: wo.z,
            };
            let up = V3 {
                x: zero,
                y: zero,
                z: L::splat(1.0),
            };
            let (wt, etap, no_tir) = refract(wo, up, self.eta);
            let wi = V3::select(is_r, wr, wt);
            let mut ft = L::splat(1.0).sub(r).div(wt.z.abs());
            if mode == TransportMode::Radiance {
                ft = ft.div(sqr(etap));
            }
            let fv = L::select(is_r, r.div(wr.z.abs()), ft);
            out = SampleLanes {
                f: S4::uniform(fv),
                wi,
                pdf: L::select(is_r, p_refl, pt.div(pr.add(pt))),
                eta: L::select(is_r, L::splat(1.0), etap),
                ok: L::and(some, L::or(is_r, no_tir)),
                reflection: is_r,
                specular: t,
                diffuse: f,
                proportional: f,
            };
        }
        let rough = and_not::<L>(active, specular);
        if any::<L>(rough) {
            let d = &self.d;
            let wm = d.sample_wm(wo, u);
            let r = fr_dielectric(wo.dot(wm), self.eta);
            let (pr, pt) = choice(r, flags);
            let some = L::not(L::and(pr.eq(zero), pt.eq(zero)));
            let dm = d.d(wm);
            let lambda_o = d.lambda(wo);
            let one = L::splat(1.0);
            let d_visible = one
                .div(one.add(lambda_o))
                .div(wo.z.abs())
                .mul(dm)
                .mul(wo.dot(wm).abs());
            let is_r = uc.lt(pr.div(pr.add(pt)));
            let wr = reflect(wo, wm);
            // The refracted branch only where some lane takes it.
            let any_t = any::<L>(and_not::<L>(rough, is_r));
            let (wt, etap, no_tir) = if any_t {
                refract(wo, wm, self.eta)
            } else {
                (wr, one, f)
            };
            let wi = V3::select(is_r, wr, wt);
            let g = one.div(one.add(lambda_o).add(d.lambda(wi)));
            // Reflection.
            let pdf_r = d_visible
                .div(L::splat(4.0).mul(wo.dot(wm).abs()))
                .mul(pr)
                .div(pr.add(pt));
            let f_r = dm.mul(g).mul(r).div(L::splat(4.0).mul(wi.z).mul(wo.z));
            let ok_r = same_hemisphere(wo, wr);
            // Transmission.
            let (pdf_t, f_t, ok_t) = if any_t {
                let denom = sqr(wt.dot(wm).add(wo.dot(wm).div(etap)));
                let dwm_dwi = wt.dot(wm).abs().div(denom);
                let pdf_t = d_visible.mul(dwm_dwi).mul(pt).div(pr.add(pt));
                let mut f_t = one.sub(r).mul(dm).mul(g).mul(
                    wt.dot(wm)
                        .mul(wo.dot(wm))
                        .div(wt.z.mul(wo.z).mul(denom))
                        .abs(),
                );
                if mode == TransportMode::Radiance {
                    f_t = f_t.div(sqr(etap));
                }
                let ok_t = L::and(
                    no_tir,
                    L::and(L::not(same_hemisphere(wo, wt)), L::not(wt.z.eq(zero))),
                );
                (pdf_t, f_t, ok_t)
            } else {
                (zero, zero, f)
            };
            let rs = SampleLanes {
                f: S4::uniform(L::select(is_r, f_r, f_t)),
                wi,
                pdf: L::select(is_r, pdf_r, pdf_t),
                eta: L::select(is_r, one, etap),
                ok: L::and(some, sel_mask::<L>(is_r, ok_r, ok_t)),
                reflection: is_r,
                specular: f,
                diffuse: f,
                proportional: f,
            };
            out = SampleLanes::select(specular, &out, &rs);
        }
        out
    }

    #[inline(always)]
    fn pdf(
        &self,
        wo: V3<L>,
        wi: V3<L>,
        _mode: TransportMode,
        flags: BxDFReflTransFlags,
        _active: L::Mask,
    ) -> L {
        let zero = L::splat(0.0);
        let (wm, etap, refl, ok) = self.half_vector(wo, wi);
        let ok = and_not::<L>(ok, self.specular());
        if !any::<L>(ok) {
            return zero;
        }
        let r = fr_dielectric(wo.dot(wm), self.eta);
        let (pr, pt) = choice(r, flags);
        let ok = L::and(ok, L::not(L::and(pr.eq(zero), pt.eq(zero))));
        let dp = self.d.pdf(wo, wm);
        let vr = dp
            .div(L::splat(4.0).mul(wo.dot(wm).abs()))
            .mul(pr)
            .div(pr.add(pt));
        let denom = sqr(wi.dot(wm).add(wo.dot(wm).div(etap)));
        let dwm_dwi = wi.dot(wm).abs().div(denom);
        let vt = dp.mul(dwm_dwi).mul(pt).div(pr.add(pt));
        L::select(ok, L::select(refl, vr, vt), zero)
    }

    #[inline(always)]
    fn flags_specular(&self) -> L::Mask {
        self.d.smooth()
    }

    #[inline(always)]
    fn flags_non_specular(&self) -> L::Mask {
        L::not(self.d.smooth())
    }
}
