//! The Trowbridge–Reitz distribution over lanes (pbrt-v4
//! `TrowbridgeReitzDistribution`, as `../microfacet.rs` documents it).

use crate::simd::math::{self, clamp, lerp, V3};
use crate::simd::F32Lanes;
use rpbrt_geometry::float::PI;

/// One distribution per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TrLanes<L> {
    pub ax: L,
    pub ay: L,
}

/// tan²θ, cos φ and sin φ of `w` and cos²θ, as the geometry crate's
/// spherical functions compute them.
#[inline(always)]
fn angles<L: F32Lanes>(w: V3<L>) -> (L, L, L, L) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let cos2 = w.z.mul(w.z);
    let sin2 = one.sub(cos2).max(zero);
    let tan2 = sin2.div(cos2);
    let st = sin2.sqrt();
    let pole = st.eq(zero);
    let cos_phi = L::select(pole, one, clamp(w.x.div(st), -1.0, 1.0));
    let sin_phi = L::select(pole, zero, clamp(w.y.div(st), -1.0, 1.0));
    (tan2, cos_phi, sin_phi, cos2)
}

/// Lanes where tan²θ is infinite or NaN.
#[inline(always)]
fn unbounded<L: F32Lanes>(tan2: L) -> L::Mask {
    L::or(tan2.is_nan(), tan2.abs().eq(L::splat(f32::INFINITY)))
}

#[inline(always)]
fn sqr<L: F32Lanes>(x: L) -> L {
    x.mul(x)
}

impl<L: F32Lanes> TrLanes<L> {
    /// Lanes so smooth they are treated as specular.
    #[inline(always)]
    pub fn smooth(&self) -> L::Mask {
        self.ax.max(self.ay).lt(L::splat(1e-3))
    }

    /// D(ωm).
    #[inline(always)]
    pub fn d(&self, wm: V3<L>) -> L {
        let (tan2, cp, sp, cos2) = angles(wm);
        let cos4 = sqr(cos2);
        let e = tan2.mul(sqr(cp.div(self.ax)).add(sqr(sp.div(self.ay))));
        let v = L::splat(1.0).div(
            L::splat(PI)
                .mul(self.ax)
                .mul(self.ay)
                .mul(cos4)
                .mul(sqr(L::splat(1.0).add(e))),
        );
        let zero = L::or(unbounded(tan2), cos4.lt(L::splat(1e-16)));
        L::select(zero, L::splat(0.0), v)
    }

    /// Λ(ω).
    #[inline(always)]
    pub fn lambda(&self, w: V3<L>) -> L {
        let (tan2, cp, sp, _) = angles(w);
        let alpha2 = sqr(cp.mul(self.ax)).add(sqr(sp.mul(self.ay)));
        let v = L::splat(1.0)
            .add(alpha2.mul(tan2))
            .sqrt()
            .sub(L::splat(1.0))
            .div(L::splat(2.0));
        L::select(unbounded(tan2), L::splat(0.0), v)
    }

    /// G(ωo, ωi), height-correlated.
    #[inline(always)]
    pub fn g(&self, wo: V3<L>, wi: V3<L>) -> L {
        L::splat(1.0).div(L::splat(1.0).add(self.lambda(wo)).add(self.lambda(wi)))
    }

    /// D_ω(ωm), the density of [`Self::sample_wm`].
    #[inline(always)]
    pub fn pdf(&self, w: V3<L>, wm: V3<L>) -> L {
        let g1 = L::splat(1.0).div(L::splat(1.0).add(self.lambda(w)));
        g1.div(w.z.abs()).mul(self.d(wm)).mul(w.dot(wm).abs())
    }

    /// A microfacet normal visible from `w` (the scalar `sample_wm`).
    #[inline(always)]
    pub fn sample_wm(&self, w: V3<L>, u: [L; 2]) -> V3<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let wh = V3 {
            x: self.ax.mul(w.x),
            y: self.ay.mul(w.y),
            z: w.z,
        }
        .normalize();
        let wh = V3::select(
            wh.z.lt(zero),
            V3 {
                x: wh.x.neg(),
                y: wh.y.neg(),
                z: wh.z.neg(),
            },
            wh,
        );
        let up = V3 {
            x: zero,
            y: zero,
            z: one,
        };
        let t1 = V3::select(
            wh.z.lt(L::splat(0.99999)),
            up.cross(wh).normalize(),
            V3 {
                x: one,
                y: zero,
                z: zero,
            },
        );
        let t2 = wh.cross(t1);
        // The polar disk sample.
        let r = u[0].sqrt();
        let theta = L::splat(2.0 * PI).mul(u[1]);
        let (s, c) = math::sin_cos(theta);
        let px = r.mul(c);
        let py = r.mul(s);
        let h = one.sub(sqr(px)).sqrt();
        let py = lerp(one.add(wh.z).div(L::splat(2.0)), h, py);
        let pz = one.sub(sqr(px)).sub(sqr(py)).max(zero).sqrt();
        let nh = t1.scale(px).add(t2.scale(py)).add(wh.scale(pz));
        V3 {
            x: self.ax.mul(nh.x),
            y: self.ay.mul(nh.y),
            z: nh.z.max(L::splat(1e-6)),
        }
        .normalize()
    }
}
