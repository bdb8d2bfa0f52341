//! Elementary functions and 3-vectors over lanes, written once for every
//! width: each is a fixed sequence of IEEE lane operations, so it gives
//! the same bits at every width, and the scalar code that must agree
//! with a vector kernel calls it at width one ([`super::Scalar1`]).
//!
//! The polynomials are the classic single-precision minimax fits of the
//! Cephes library (Moshier): sine and cosine on [−π/4, π/4] after a
//! three-part Cody–Waite reduction by π/4, and arctangent on
//! [0, tan π/8] after the reduction atan a = π/4 + atan((a − 1)/(a + 1)).
//! Both are within about two ulps of the correctly rounded result on the
//! arguments rpbrt gives them (tested against `f64`).

use super::{F32Lanes, U32Lanes};

/// 4/π.
const FOUR_OVER_PI: f32 = 1.273_239_5;
/// π/4 in three parts whose products with small integers are exact.
const PI4_A: f32 = 0.785_156_25;
const PI4_B: f32 = 2.418_756_5e-4;
const PI4_C: f32 = 3.774_895e-8;
/// sin r ≈ r + r³ (S1 + r² (S2 + r² S3)) on [−π/4, π/4].
const S1: f32 = -1.666_665_5e-1;
const S2: f32 = 8.332_161e-3;
const S3: f32 = -1.951_529_6e-4;
/// cos r ≈ 1 − r²/2 + r⁴ (C1 + r² (C2 + r² C3)) on [−π/4, π/4].
const C1: f32 = 4.166_664_6e-2;
const C2: f32 = -1.388_731_6e-3;
const C3: f32 = 2.443_315_7e-5;
/// atan t ≈ t + t³ (A1 + t² (A2 + t² (A3 + t² A4))) on [0, tan π/8].
const A1: f32 = -3.333_295e-1;
const A2: f32 = 1.997_771_1e-1;
const A3: f32 = -1.387_768_6e-1;
const A4: f32 = 8.053_744_5e-2;
/// tan π/8.
const TAN_PI_8: f32 = 0.414_213_57;

/// Lane-wise `(sin x, cos x)`, for finite `|x|` up to about 8192 (beyond,
/// the reduction loses accuracy; rpbrt's arguments are angles of at most
/// a few turns).
#[inline(always)]
pub fn sin_cos<L: F32Lanes>(x: L) -> (L, L) {
    let s = L::splat;
    let ax = x.abs();
    // The multiple j of π/4 nearest below |x|, rounded up to even, and
    // its octant j mod 8 (all small integers, exact in f32).
    let j = ax.mul(s(FOUR_OVER_PI)).floor();
    let odd = j.sub(j.mul(s(0.5)).floor().mul(s(2.0)));
    let j = j.add(odd);
    let octant = j.sub(j.mul(s(0.125)).floor().mul(s(8.0)));
    let r = ax
        .sub(j.mul(s(PI4_A)))
        .sub(j.mul(s(PI4_B)))
        .sub(j.mul(s(PI4_C)));
    let z = r.mul(r);
    let sin_r = s(S3)
        .mul(z)
        .add(s(S2))
        .mul(z)
        .add(s(S1))
        .mul(z)
        .mul(r)
        .add(r);
    let cos_r = s(C3)
        .mul(z)
        .add(s(C2))
        .mul(z)
        .add(s(C1))
        .mul(z)
        .mul(z)
        .sub(s(0.5).mul(z))
        .add(s(1.0));
    // Octants 2 and 6 swap the two; sin is negative in octants 4 and 6
    // (and for negative x), cos in octants 2 and 4.
    let o2 = octant.eq(s(2.0));
    let o4 = octant.eq(s(4.0));
    let o6 = octant.eq(s(6.0));
    let swap = L::or(o2, o6);
    let sin_v = L::select(swap, cos_r, sin_r);
    let cos_v = L::select(swap, sin_r, cos_r);
    let sin_neg = L::or(o4, o6);
    let sin_v = L::select(sin_neg, sin_v.neg(), sin_v);
    let sin_v = L::select(x.lt(s(0.0)), sin_v.neg(), sin_v);
    let cos_v = L::select(L::or(o2, o4), cos_v.neg(), cos_v);
    (sin_v, cos_v)
}

/// Lane-wise `atan2(y, x)` in [−π, π].
#[inline(always)]
pub fn atan2<L: F32Lanes>(y: L, x: L) -> L {
    let s = L::splat;
    let (ax, ay) = (x.abs(), y.abs());
    let big = ax.max(ay);
    let small = ax.min(ay);
    // a = small/big in [0, 1]; 0 when both are zero.
    let a = L::select(big.eq(s(0.0)), s(0.0), small.div(big));
    let reduce = a.gt(s(TAN_PI_8));
    let t = L::select(reduce, a.sub(s(1.0)).div(a.add(s(1.0))), a);
    let base = L::select(reduce, s(std::f32::consts::FRAC_PI_4), s(0.0));
    let z = t.mul(t);
    let poly = s(A4)
        .mul(z)
        .add(s(A3))
        .mul(z)
        .add(s(A2))
        .mul(z)
        .add(s(A1))
        .mul(z)
        .mul(t)
        .add(t);
    let r = base.add(poly);
    // Back to the octant and quadrant of (x, y), zeros by their signs
    // (as `f32::atan2`: atan2(±0, −0) = ±π).
    let r = L::select(ay.gt(ax), s(std::f32::consts::FRAC_PI_2).sub(r), r);
    let r = L::select(sign_bit(x), s(std::f32::consts::PI).sub(r), r);
    L::select(sign_bit(y), r.neg(), r)
}

/// Lane-wise: the sign bit is set (negative numbers and −0).
#[inline(always)]
pub fn sign_bit<L: F32Lanes>(x: L) -> L::Mask {
    let zero = L::splat(0.0);
    L::or(
        x.lt(zero),
        L::and(x.eq(zero), L::splat(1.0).div(x).lt(zero)),
    )
}

/// log₂ e.
const LOG2_E: f32 = std::f32::consts::LOG2_E;
/// ln 2 in two parts (the first exact in few bits), for the reduction.
const LN2_HI: f32 = 0.693_359_4;
const LN2_LO: f32 = -2.121_944_4e-4;
/// eʳ ≈ 1 + r + r² (E0 + r (E1 + r (E2 + r (E3 + r (E4 + r E5))))) on
/// [−ln 2/2, ln 2/2] (reversed: E5 is the constant term's neighbour).
const EXP_P: [f32; 6] = [
    1.987_569_1e-4,
    1.398_2e-3,
    8.333_452e-3,
    4.166_579_6e-2,
    1.666_666_5e-1,
    5.000_000_1e-1,
];

/// Lane-wise `eˣ` (the Cephes single-precision method: x = n ln 2 + r,
/// a degree-7 polynomial for eʳ, then the exact scaling by 2ⁿ). Below
/// −87.3 it gives 0 (the true value is below 2⁻¹²⁶), above 88 +∞, NaN
/// stays NaN.
#[inline(always)]
pub fn exp<L: F32Lanes>(x: L) -> L {
    let (lo, hi) = (-87.3f32, 88.0f32);
    let xc = L::select(x.lt(L::splat(lo)), L::splat(lo), x);
    let xc = L::select(xc.gt(L::splat(hi)), L::splat(hi), xc);
    let xc = L::select(x.is_nan(), L::splat(0.0), xc);
    let n = xc.mul(L::splat(LOG2_E)).add(L::splat(0.5)).floor();
    let r = xc.sub(n.mul(L::splat(LN2_HI))).sub(n.mul(L::splat(LN2_LO)));
    let mut y = L::splat(EXP_P[0]);
    for &c in &EXP_P[1..] {
        y = y.mul(r).add(L::splat(c));
    }
    let y = y.mul(r.mul(r)).add(r).add(L::splat(1.0));
    let v = y.mul(L::pow2i(n));
    let v = L::select(x.lt(L::splat(lo)), L::splat(0.0), v);
    let v = L::select(x.gt(L::splat(hi)), L::splat(f32::INFINITY), v);
    L::select(x.is_nan(), x, v)
}

/// √½, where the logarithm's reduction moves the mantissa from
/// [½, √½) to [1, √2).
const SQRT_HALF: f32 = std::f32::consts::FRAC_1_SQRT_2;
/// ln(1 + r) ≈ r − r²/2 + r³ (L0 r⁸ … + L8) on [√½ − 1, √2 − 1]
/// (highest power first).
const LN_P: [f32; 9] = [
    7.037_683_6e-2,
    -1.151_461e-1,
    1.167_699_9e-1,
    -1.242_014_1e-1,
    1.424_932_3e-1,
    -1.666_805_8e-1,
    2.000_071_4e-1,
    -2.499_999_4e-1,
    3.333_333e-1,
];

/// Lane-wise natural logarithm (the Cephes single-precision method:
/// x = m·2ᵉ with m in [√½, √2), ln x = e ln 2 + ln m by a degree-9
/// polynomial in m − 1, ln 2 in two parts). Within 2 ulps of the
/// correctly rounded value for positive normal and subnormal `x` (in the
/// tests); 0 gives −∞, +∞ gives +∞, negative numbers and NaN give NaN.
#[inline(always)]
pub fn ln<L: F32Lanes>(x: L) -> L {
    type U<L> = <L as F32Lanes>::U32;
    // Subnormals scaled into the normal range first (by 2²⁵).
    let subnormal = x.lt(L::splat(f32::MIN_POSITIVE));
    let xs = L::select(subnormal, x.mul(L::splat(33_554_432.0)), x);
    let bias = L::select(subnormal, L::splat(126.0 + 25.0), L::splat(126.0));
    // x = m·2ᵉ with m in [½, 1), from the bits.
    let bits = xs.to_u32_bits();
    let biased = <U<L> as U32Lanes>::and(bits.shr::<23>(), U::<L>::splat(0xff));
    let m = L::from_u32_bits(<U<L> as U32Lanes>::or(
        <U<L> as U32Lanes>::and(bits, U::<L>::splat(0x807f_ffff)),
        U::<L>::splat(0x3f00_0000),
    ));
    let e = L::from_u32(biased).sub(bias);
    // Below √½, m doubles and e drops by one.
    let low = m.lt(L::splat(SQRT_HALF));
    let e = L::select(low, e.sub(L::splat(1.0)), e);
    let r = L::select(low, m.add(m), m).sub(L::splat(1.0));
    let z = r.mul(r);
    let mut y = L::splat(LN_P[0]);
    for &c in &LN_P[1..] {
        y = y.mul(r).add(L::splat(c));
    }
    let y = y.mul(r).mul(z);
    let y = y.add(e.mul(L::splat(LN2_LO)));
    let y = y.add(z.mul(L::splat(-0.5)));
    let v = r.add(y).add(e.mul(L::splat(LN2_HI)));
    let zero = L::splat(0.0);
    let v = L::select(x.eq(zero), L::splat(f32::NEG_INFINITY), v);
    let v = L::select(x.eq(L::splat(f32::INFINITY)), x, v);
    L::select(L::or(x.lt(zero), x.is_nan()), L::splat(f32::NAN), v)
}

/// `clamp(v, lo, hi)` as [`rpbrt_geometry::float::clamp`] computes it
/// (NaN maps to `lo`).
#[inline(always)]
pub fn clamp<L: F32Lanes>(v: L, lo: f32, hi: f32) -> L {
    let (lo, hi) = (L::splat(lo), L::splat(hi));
    let r = L::select(v.gt(hi), hi, v);
    L::select(L::or(v.lt(lo), v.is_nan()), lo, r)
}

/// `safe_sqrt(x)`: the square root of `max(x, 0)` (NaN gives 0, as
/// `f32::max` does).
#[inline(always)]
pub fn safe_sqrt<L: F32Lanes>(x: L) -> L {
    x.max(L::splat(0.0)).sqrt()
}

/// [`rpbrt_geometry::float::next_float_up`] of each lane: the smallest
/// float above it (+∞ stays, −0 is 0 first).
#[inline(always)]
pub fn next_float_up<L: F32Lanes>(v: L) -> L {
    let zero = L::splat(0.0);
    let w = L::select(v.eq(zero), zero, v);
    let r = w.step_bits(w.ge(zero));
    L::select(v.eq(L::splat(f32::INFINITY)), v, r)
}

/// [`rpbrt_geometry::float::next_float_down`] of each lane: the largest
/// float below it (−∞ stays, 0 is −0 first).
#[inline(always)]
pub fn next_float_down<L: F32Lanes>(v: L) -> L {
    let zero = L::splat(0.0);
    let w = L::select(v.eq(zero), L::splat(-0.0), v);
    let r = w.step_bits(L::not(w.gt(zero)));
    L::select(v.eq(L::splat(f32::NEG_INFINITY)), v, r)
}

/// [`rpbrt_geometry::interval::Interval::from_value_and_error`] of each
/// lane: its low and high ends (`v` itself where the error is 0). (A NaN
/// end may differ from the scalar one in its sign and payload, which
/// Rust leaves unspecified.)
#[inline(always)]
pub fn interval_from_value_and_error<L: F32Lanes>(v: L, err: L) -> (L, L) {
    let exact = err.eq(L::splat(0.0));
    let lo = next_float_down(v.sub(err));
    let hi = next_float_up(v.add(err));
    (L::select(exact, v, lo), L::select(exact, v, hi))
}

/// `(1 − t)·a + t·b`, as [`rpbrt_geometry::float::lerp`].
#[inline(always)]
pub fn lerp<L: F32Lanes>(t: L, a: L, b: L) -> L {
    L::splat(1.0).sub(t).mul(a).add(t.mul(b))
}

/// A 3-vector (or point) per lane, with the geometry crate's operations
/// in the same order of evaluation.
#[derive(Clone, Copy, Debug)]
pub struct V3<L> {
    /// The x components.
    pub x: L,
    /// The y components.
    pub y: L,
    /// The z components.
    pub z: L,
}

// Named as the lane operations are (`F32Lanes::add`, …): a kernel reads
// the same with vectors and with lanes.
#[allow(clippy::should_implement_trait)]
impl<L: F32Lanes> V3<L> {
    /// Lanes from one `[x, y, z]` per lane (`v.len()` at least `L::N`).
    #[inline(always)]
    pub fn gather(v: &[[f32; 3]]) -> Self {
        let mut c = [[0.0f32; 16]; 3];
        for (i, p) in v.iter().take(L::N).enumerate() {
            c[0][i] = p[0];
            c[1][i] = p[1];
            c[2][i] = p[2];
        }
        V3 {
            x: L::load(&c[0]),
            y: L::load(&c[1]),
            z: L::load(&c[2]),
        }
    }
    /// `self + o`.
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        V3 {
            x: self.x.add(o.x),
            y: self.y.add(o.y),
            z: self.z.add(o.z),
        }
    }
    /// `self − o`.
    #[inline(always)]
    pub fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x.sub(o.x),
            y: self.y.sub(o.y),
            z: self.z.sub(o.z),
        }
    }
    /// `self * s`.
    #[inline(always)]
    pub fn scale(self, s: L) -> Self {
        V3 {
            x: self.x.mul(s),
            y: self.y.mul(s),
            z: self.z.mul(s),
        }
    }
    /// `self / s`, each component divided.
    #[inline(always)]
    pub fn div(self, s: L) -> Self {
        V3 {
            x: self.x.div(s),
            y: self.y.div(s),
            z: self.z.div(s),
        }
    }
    /// `self · o`, summed x, y, z in order.
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x.mul(o.x).add(self.y.mul(o.y)).add(self.z.mul(o.z))
    }
    /// The cross product with exact products, as the geometry crate's.
    #[inline(always)]
    pub fn cross(self, w: Self) -> Self {
        V3 {
            x: L::difference_of_products(self.y, w.z, self.z, w.y),
            y: L::difference_of_products(self.z, w.x, self.x, w.z),
            z: L::difference_of_products(self.x, w.y, self.y, w.x),
        }
    }
    /// `|self|`.
    #[inline(always)]
    pub fn length(self) -> L {
        self.dot(self).sqrt()
    }
    /// `self / |self|`.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self.div(self.length())
    }
    /// `self / |self|` and the mask of lanes where `try_normalize` would
    /// succeed (the length positive and finite).
    #[inline(always)]
    pub fn try_normalize(self) -> (Self, L::Mask) {
        let l = self.length();
        let ok = L::and(l.gt(L::splat(0.0)), l.lt(L::splat(f32::INFINITY)));
        (self.div(l), ok)
    }
    /// `self − w (self · w)`.
    #[inline(always)]
    pub fn gram_schmidt(self, w: Self) -> Self {
        self.sub(w.scale(self.dot(w)))
    }
    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: L::Mask, a: Self, b: Self) -> Self {
        V3 {
            x: L::select(m, a.x, b.x),
            y: L::select(m, a.y, b.y),
            z: L::select(m, a.z, b.z),
        }
    }
}
