//! BxDFs over lanes: the models the vectorised path tracer evaluates for
//! many paths at once (the diffuse, conductor and dielectric BxDFs, the
//! Trowbridge–Reitz distribution, and the coated models' random walk),
//! written once over [`F32Lanes`] as `shape/triangle.rs` writes the
//! spherical-triangle sample.
//!
//! Each lane computes exactly the operations of pbrt-v4's scalar code for
//! its model, branches turned into masks, so every width gives the same
//! bits; the scalar [`super::BxDFMethods`] of these models call the same
//! code at width one ([`Scalar1`]), so the scalar integrators and the
//! wavefront ones give the same images. Work only some lanes need (the
//! refracted branch, the bottom interface) is skipped when no lane needs
//! it, so width one still branches as scalar code does.

mod interfaces;
mod layered;
mod microfacet;
#[cfg(test)]
mod tests;

pub(crate) use interfaces::{ConductorLanes, DielectricLanes, DiffuseLanes};
pub(crate) use layered::LayeredLanes;
pub(crate) use microfacet::TrLanes;

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::{Point2f, Vector3f};

use super::{BSDFSample, BxDFFlags, BxDFReflTransFlags, TransportMode};
use crate::simd::math::V3;
use crate::simd::{F32Lanes, Scalar1};
use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

// The lane code is spelled out without closures (`array::from_fn`,
// `map`): a closure is a function of its own, compiled without the
// dispatching function's instruction set, so the intrinsics in it could
// not be inlined.
const _: () = assert!(N_SPECTRUM_SAMPLES == 4);

pub(crate) use crate::simd::MAX_LANES;

/// Lane `i` of `x`.
#[inline(always)]
pub(crate) fn lane<L: F32Lanes>(x: L, i: usize) -> f32 {
    let mut a = [0.0f32; MAX_LANES];
    x.store(&mut a);
    a[i]
}

/// True when lane `i` of `m` is set.
#[inline(always)]
pub(crate) fn bit<L: F32Lanes>(m: L::Mask, i: usize) -> bool {
    (L::bits(m) >> i) & 1 != 0
}

/// True when any lane of `m` is set.
#[inline(always)]
pub(crate) fn any<L: F32Lanes>(m: L::Mask) -> bool {
    L::bits(m) != 0
}

/// The mask with every lane `b`.
#[inline(always)]
pub(crate) fn splat_mask<L: F32Lanes>(b: bool) -> L::Mask {
    L::from_bits(if b { u32::MAX } else { 0 })
}

/// `a & !b`.
#[inline(always)]
pub(crate) fn and_not<L: F32Lanes>(a: L::Mask, b: L::Mask) -> L::Mask {
    L::and(a, L::not(b))
}

/// A sampled spectrum per lane: one lane vector per wavelength.
#[derive(Clone, Copy, Debug)]
pub(crate) struct S4<L>(pub [L; N_SPECTRUM_SAMPLES]);

impl<L: F32Lanes> S4<L> {
    /// Every lane and wavelength `c`.
    #[inline(always)]
    pub fn splat(c: f32) -> Self {
        S4([L::splat(c); N_SPECTRUM_SAMPLES])
    }
    /// Every wavelength of lane `i` the value of `v` at lane `i`.
    #[inline(always)]
    pub fn uniform(v: L) -> Self {
        S4([v; N_SPECTRUM_SAMPLES])
    }
    /// Lane `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> SampledSpectrum {
        let mut a = [[0.0f32; MAX_LANES]; N_SPECTRUM_SAMPLES];
        for (v, a) in self.0.iter().zip(a.iter_mut()) {
            v.store(a);
        }
        SampledSpectrum::from_array([a[0][i], a[1][i], a[2][i], a[3][i]])
    }
    /// Wavelength-wise `self * o`.
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        let (a, b) = (self.0, o.0);
        S4([
            a[0].mul(b[0]),
            a[1].mul(b[1]),
            a[2].mul(b[2]),
            a[3].mul(b[3]),
        ])
    }
    /// Wavelength-wise `self + o`.
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        let (a, b) = (self.0, o.0);
        S4([
            a[0].add(b[0]),
            a[1].add(b[1]),
            a[2].add(b[2]),
            a[3].add(b[3]),
        ])
    }
    /// Every wavelength times `s`.
    #[inline(always)]
    pub fn scale(self, s: L) -> Self {
        let a = self.0;
        S4([a[0].mul(s), a[1].mul(s), a[2].mul(s), a[3].mul(s)])
    }
    /// Every wavelength over `s`.
    #[inline(always)]
    pub fn div(self, s: L) -> Self {
        let a = self.0;
        S4([a[0].div(s), a[1].div(s), a[2].div(s), a[3].div(s)])
    }
    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: L::Mask, a: Self, b: Self) -> Self {
        let (a, b) = (a.0, b.0);
        S4([
            L::select(m, a[0], b[0]),
            L::select(m, a[1], b[1]),
            L::select(m, a[2], b[2]),
            L::select(m, a[3], b[3]),
        ])
    }
    /// Lanes whose every wavelength is zero ([`SampledSpectrum::is_black`]).
    #[inline(always)]
    pub fn is_black(&self) -> L::Mask {
        let z = L::splat(0.0);
        let mut m = self.0[0].eq(z);
        for v in &self.0[1..] {
            m = L::and(m, v.eq(z));
        }
        m
    }
    /// The largest wavelength of each lane, folded as
    /// [`SampledSpectrum::max_component_value`] folds (`f32::max`: NaN
    /// values are passed over).
    #[inline(always)]
    pub fn max_component(&self) -> L {
        let mut m = self.0[0];
        for &v in &self.0 {
            m = fmax(m, v);
        }
        m
    }
}

/// `f32::max` lane-wise (a NaN operand gives the other).
#[inline(always)]
pub(crate) fn fmax<L: F32Lanes>(a: L, b: L) -> L {
    let m = a.max(b);
    L::select(a.is_nan(), b, L::select(b.is_nan(), a, m))
}

/// `power_heuristic(1, f, 1, g)` lane-wise.
#[inline(always)]
pub(crate) fn power_heuristic<L: F32Lanes>(f: L, g: L) -> L {
    let z = L::splat(0.0);
    let r = f.mul(f).div(f.mul(f).add(g.mul(g)));
    let r = L::select(L::and(f.eq(z), g.eq(z)), z, r);
    L::select(f.eq(L::splat(f32::INFINITY)), L::splat(1.0), r)
}

/// One BSDF sample per lane: the lanes of `ok` hold one, with the flags
/// as masks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SampleLanes<L: F32Lanes> {
    pub f: S4<L>,
    pub wi: V3<L>,
    pub pdf: L,
    pub eta: L,
    /// Lanes that sampled something (`Some` in the scalar code).
    pub ok: L::Mask,
    /// Reflection (else transmission).
    pub reflection: L::Mask,
    /// A specular lobe.
    pub specular: L::Mask,
    /// A diffuse lobe (when not specular; neither: glossy).
    pub diffuse: L::Mask,
    /// The density is only proportional to the true one (layered models).
    pub proportional: L::Mask,
}

impl<L: F32Lanes> SampleLanes<L> {
    /// No sample in any lane.
    #[inline(always)]
    pub fn none() -> Self {
        let f = splat_mask::<L>(false);
        SampleLanes {
            f: S4::splat(0.0),
            wi: V3 {
                x: L::splat(0.0),
                y: L::splat(0.0),
                z: L::splat(1.0),
            },
            pdf: L::splat(0.0),
            eta: L::splat(1.0),
            ok: f,
            reflection: f,
            specular: f,
            diffuse: f,
            proportional: f,
        }
    }

    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: L::Mask, a: &Self, b: &Self) -> Self {
        SampleLanes {
            f: S4::select(m, a.f, b.f),
            wi: V3::select(m, a.wi, b.wi),
            pdf: L::select(m, a.pdf, b.pdf),
            eta: L::select(m, a.eta, b.eta),
            ok: sel_mask::<L>(m, a.ok, b.ok),
            reflection: sel_mask::<L>(m, a.reflection, b.reflection),
            specular: sel_mask::<L>(m, a.specular, b.specular),
            diffuse: sel_mask::<L>(m, a.diffuse, b.diffuse),
            proportional: sel_mask::<L>(m, a.proportional, b.proportional),
        }
    }

    /// Lanes whose sample a layered walk can continue with (pbrt-v4's
    /// check in `LayeredBxDF`: a value, a density and a direction off the
    /// plane).
    #[inline(always)]
    pub fn usable(&self) -> L::Mask {
        let z = L::splat(0.0);
        L::and(
            L::and(self.ok, L::not(self.f.is_black())),
            L::and(L::not(self.pdf.eq(z)), L::not(self.wi.z.eq(z))),
        )
    }

    /// Lane `i` as the scalar code's sample.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Option<BSDFSample> {
        if !bit::<L>(self.ok, i) {
            return None;
        }
        let mut flags = if bit::<L>(self.reflection, i) {
            BxDFFlags::REFLECTION
        } else {
            BxDFFlags::TRANSMISSION
        };
        flags |= if bit::<L>(self.specular, i) {
            BxDFFlags::SPECULAR
        } else if bit::<L>(self.diffuse, i) {
            BxDFFlags::DIFFUSE
        } else {
            BxDFFlags::GLOSSY
        };
        Some(BSDFSample {
            f: self.f.get(i),
            wi: Vector3f::new(lane(self.wi.x, i), lane(self.wi.y, i), lane(self.wi.z, i)),
            pdf: lane(self.pdf, i),
            flags,
            eta: lane(self.eta, i),
            pdf_is_proportional: bit::<L>(self.proportional, i),
        })
    }
}

/// Lane-wise `if m { a } else { b }` of masks.
#[inline(always)]
pub(crate) fn sel_mask<L: F32Lanes>(m: L::Mask, a: L::Mask, b: L::Mask) -> L::Mask {
    L::or(L::and(m, a), and_not::<L>(b, m))
}

/// What the lane models answer: the scalar BxDF interface over lanes.
/// `active` lanes are the ones whose results are used; the others may
/// compute anything (but never draw random numbers).
pub(crate) trait BxDFLanes<L: F32Lanes> {
    /// f(ωo, ωi).
    fn f(&self, wo: V3<L>, wi: V3<L>, mode: TransportMode, active: L::Mask) -> S4<L>;
    /// A sample of ωi.
    fn sample_f(
        &self,
        wo: V3<L>,
        uc: L,
        u: [L; 2],
        mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> SampleLanes<L>;
    /// The density of `sample_f`.
    fn pdf(
        &self,
        wo: V3<L>,
        wi: V3<L>,
        mode: TransportMode,
        flags: BxDFReflTransFlags,
        active: L::Mask,
    ) -> L;
    /// Lanes whose flags say specular.
    fn flags_specular(&self) -> L::Mask;
    /// Lanes whose flags say diffuse or glossy.
    fn flags_non_specular(&self) -> L::Mask;
}

/// One lane's vector as lanes (for the scalar entry points).
#[inline(always)]
pub(crate) fn v1(v: Vector3f) -> V3<Scalar1> {
    V3 {
        x: Scalar1(v.x),
        y: Scalar1(v.y),
        z: Scalar1(v.z),
    }
}

/// The scalar entry points of a model: its lane code at width one.
#[inline(always)]
pub(crate) fn f1<B: BxDFLanes<Scalar1>>(
    b: &B,
    wo: Vector3f,
    wi: Vector3f,
    mode: TransportMode,
) -> SampledSpectrum {
    b.f(v1(wo), v1(wi), mode, true).get(0)
}

/// See [`f1`].
#[inline(always)]
pub(crate) fn sample_f1<B: BxDFLanes<Scalar1>>(
    b: &B,
    wo: Vector3f,
    uc: Float,
    u: Point2f,
    mode: TransportMode,
    flags: BxDFReflTransFlags,
) -> Option<BSDFSample> {
    b.sample_f(
        v1(wo),
        Scalar1(uc),
        [Scalar1(u.x), Scalar1(u.y)],
        mode,
        flags,
        true,
    )
    .get(0)
}

/// See [`f1`].
#[inline(always)]
pub(crate) fn pdf1<B: BxDFLanes<Scalar1>>(
    b: &B,
    wo: Vector3f,
    wi: Vector3f,
    mode: TransportMode,
    flags: BxDFReflTransFlags,
) -> Float {
    b.pdf(v1(wo), v1(wi), mode, flags, true).0
}

/// Models with a lane form: their parameters gathered from one model per
/// lane.
pub(crate) trait ToLanes: Sized {
    /// The lane form.
    type Lanes<L: F32Lanes>: BxDFLanes<L>;
    /// Lanes from `items[..L::N]` (when fewer, the first fills the rest).
    fn gather<L: F32Lanes>(items: &[&Self]) -> Self::Lanes<L>;
    /// The model at width one, for its scalar methods.
    #[inline(always)]
    fn one(&self) -> Self::Lanes<Scalar1> {
        Self::gather::<Scalar1>(&[self])
    }
}

/// Which item fills lane `i` of a gather from `n` items.
#[inline(always)]
pub(crate) fn source(i: usize, n: usize) -> usize {
    if i < n {
        i
    } else {
        0
    }
}

/// Lanes of `f(item)` for `n` items.
#[inline(always)]
pub(crate) fn gather_f<L: F32Lanes>(n: usize, f: impl Fn(usize) -> f32) -> L {
    let mut a = [0.0f32; MAX_LANES];
    for (i, x) in a.iter_mut().enumerate().take(L::N) {
        *x = f(source(i, n));
    }
    L::load(&a)
}

/// Spectrum lanes of `f(item)` for `n` items.
#[inline(always)]
pub(crate) fn gather_s<L: F32Lanes>(n: usize, f: impl Fn(usize) -> SampledSpectrum) -> S4<L> {
    let mut c = [[0.0f32; MAX_LANES]; N_SPECTRUM_SAMPLES];
    for i in 0..L::N {
        let s = f(source(i, n));
        for (w, col) in c.iter_mut().enumerate() {
            col[i] = s[w];
        }
    }
    S4([
        L::load(&c[0]),
        L::load(&c[1]),
        L::load(&c[2]),
        L::load(&c[3]),
    ])
}
