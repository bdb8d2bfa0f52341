//! Interval arithmetic (pbrt-v4 `util/float.h` `Interval`; book section
//! 6.8.2): conservative bounds on the exact result of float computations.

use crate::float::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A closed interval `[low, high]` that is guaranteed to contain the exact
/// value of the computation that produced it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Interval {
    /// Lower bound.
    pub low: Float,
    /// Upper bound.
    pub high: Float,
}

impl Interval {
    /// The degenerate interval holding exactly `v`.
    #[inline]
    pub const fn new(v: Float) -> Self {
        Interval { low: v, high: v }
    }

    /// The interval spanning `a` and `b`, in either order.
    #[inline]
    pub fn from_bounds(a: Float, b: Float) -> Self {
        Interval {
            low: a.min(b),
            high: a.max(b),
        }
    }

    /// `v ± err`, rounded outward.
    #[inline]
    pub fn from_value_and_error(v: Float, err: Float) -> Self {
        if err == 0.0 {
            Interval::new(v)
        } else {
            Interval {
                low: sub_round_down(v, err),
                high: add_round_up(v, err),
            }
        }
    }

    /// The midpoint, used as the best single-float estimate.
    #[inline]
    pub fn midpoint(self) -> Float {
        (self.low + self.high) / 2.0
    }

    /// Half the width: the error bound around the midpoint.
    #[inline]
    pub fn width(self) -> Float {
        self.high - self.low
    }

    /// True when `v` lies in the interval.
    #[inline]
    pub fn contains(self, v: Float) -> bool {
        v >= self.low && v <= self.high
    }

    /// True when the interval holds exactly one value.
    #[inline]
    pub fn is_exact(self) -> bool {
        self.low == self.high
    }

    /// The square of the interval (tighter than `self * self` when it
    /// straddles zero).
    #[inline]
    pub fn sqr(self) -> Interval {
        let alow = self.low.abs();
        let ahigh = self.high.abs();
        let (lo, hi) = if alow > ahigh {
            (ahigh, alow)
        } else {
            (alow, ahigh)
        };
        if self.contains(0.0) {
            Interval {
                low: 0.0,
                high: mul_round_up(hi, hi),
            }
        } else {
            Interval {
                low: mul_round_down(lo, lo),
                high: mul_round_up(hi, hi),
            }
        }
    }

    /// The square root of the interval.
    #[inline]
    pub fn sqrt(self) -> Interval {
        Interval {
            low: sqrt_round_down(self.low.max(0.0)),
            high: sqrt_round_up(self.high),
        }
    }
}

impl From<Float> for Interval {
    #[inline]
    fn from(v: Float) -> Self {
        Interval::new(v)
    }
}

impl Add for Interval {
    type Output = Interval;
    #[inline]
    fn add(self, o: Interval) -> Interval {
        Interval {
            low: add_round_down(self.low, o.low),
            high: add_round_up(self.high, o.high),
        }
    }
}

impl Sub for Interval {
    type Output = Interval;
    #[inline]
    fn sub(self, o: Interval) -> Interval {
        Interval {
            low: sub_round_down(self.low, o.high),
            high: sub_round_up(self.high, o.low),
        }
    }
}

impl Neg for Interval {
    type Output = Interval;
    #[inline]
    fn neg(self) -> Interval {
        Interval {
            low: -self.high,
            high: -self.low,
        }
    }
}

impl Mul for Interval {
    type Output = Interval;
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        // When the signs of both intervals are known, the extreme products
        // are known too: the same bounds as the minimum and maximum of all
        // four (rounding is monotonic), for two products instead of eight.
        let (a, b) = (self, o);
        if a.low >= 0.0 {
            if b.low >= 0.0 {
                return Interval::bounds(a.low, b.low, a.high, b.high);
            }
            if b.high <= 0.0 {
                return Interval::bounds(a.high, b.low, a.low, b.high);
            }
            return Interval::bounds(a.high, b.low, a.high, b.high);
        }
        if a.high <= 0.0 {
            if b.low >= 0.0 {
                return Interval::bounds(a.low, b.high, a.high, b.low);
            }
            if b.high <= 0.0 {
                return Interval::bounds(a.high, b.high, a.low, b.low);
            }
            return Interval::bounds(a.low, b.high, a.low, b.low);
        }
        if b.low >= 0.0 {
            return Interval::bounds(a.low, b.high, a.high, b.high);
        }
        if b.high <= 0.0 {
            return Interval::bounds(a.high, b.low, a.low, b.low);
        }
        let lp = [
            mul_round_down(self.low, o.low),
            mul_round_down(self.high, o.low),
            mul_round_down(self.low, o.high),
            mul_round_down(self.high, o.high),
        ];
        let hp = [
            mul_round_up(self.low, o.low),
            mul_round_up(self.high, o.low),
            mul_round_up(self.low, o.high),
            mul_round_up(self.high, o.high),
        ];
        Interval {
            low: lp[0].min(lp[1]).min(lp[2].min(lp[3])),
            high: hp[0].max(hp[1]).max(hp[2].max(hp[3])),
        }
    }
}

impl Interval {
    /// `[a·b rounded down, c·d rounded up]`.
    #[inline(always)]
    fn bounds(a: Float, b: Float, c: Float, d: Float) -> Interval {
        Interval {
            low: mul_round_down(a, b),
            high: mul_round_up(c, d),
        }
    }

    /// `[a/b rounded down, c/d rounded up]`.
    #[inline(always)]
    fn quotient_bounds(a: Float, b: Float, c: Float, d: Float) -> Interval {
        Interval {
            low: div_round_down(a, b),
            high: div_round_up(c, d),
        }
    }
}

impl Div for Interval {
    type Output = Interval;
    #[inline]
    fn div(self, o: Interval) -> Interval {
        if o.contains(0.0) {
            // Division by an interval containing zero is unbounded.
            return Interval {
                low: Float::NEG_INFINITY,
                high: Float::INFINITY,
            };
        }
        // A divisor of known sign (it excludes zero) and a dividend of
        // known sign or straddling zero: the extreme quotients are known.
        let a = self;
        if o.low > 0.0 {
            if a.low >= 0.0 {
                return Interval::quotient_bounds(a.low, o.high, a.high, o.low);
            }
            if a.high <= 0.0 {
                return Interval::quotient_bounds(a.low, o.low, a.high, o.high);
            }
            return Interval::quotient_bounds(a.low, o.low, a.high, o.low);
        }
        if o.high < 0.0 {
            if a.low >= 0.0 {
                return Interval::quotient_bounds(a.high, o.high, a.low, o.low);
            }
            if a.high <= 0.0 {
                return Interval::quotient_bounds(a.high, o.low, a.low, o.high);
            }
            return Interval::quotient_bounds(a.high, o.high, a.low, o.high);
        }
        let lq = [
            div_round_down(self.low, o.low),
            div_round_down(self.high, o.low),
            div_round_down(self.low, o.high),
            div_round_down(self.high, o.high),
        ];
        let hq = [
            div_round_up(self.low, o.low),
            div_round_up(self.high, o.low),
            div_round_up(self.low, o.high),
            div_round_up(self.high, o.high),
        ];
        Interval {
            low: lq[0].min(lq[1]).min(lq[2].min(lq[3])),
            high: hq[0].max(hq[1]).max(hq[2].max(hq[3])),
        }
    }
}

impl Add<Float> for Interval {
    type Output = Interval;
    #[inline]
    fn add(self, f: Float) -> Interval {
        self + Interval::new(f)
    }
}
impl Sub<Float> for Interval {
    type Output = Interval;
    #[inline]
    fn sub(self, f: Float) -> Interval {
        self - Interval::new(f)
    }
}
impl Mul<Float> for Interval {
    type Output = Interval;
    #[inline]
    fn mul(self, f: Float) -> Interval {
        if f > 0.0 {
            Interval {
                low: mul_round_down(f, self.low),
                high: mul_round_up(f, self.high),
            }
        } else {
            Interval {
                low: mul_round_down(f, self.high),
                high: mul_round_up(f, self.low),
            }
        }
    }
}
impl Div<Float> for Interval {
    type Output = Interval;
    #[inline]
    fn div(self, f: Float) -> Interval {
        if f == 0.0 {
            Interval {
                low: Float::NEG_INFINITY,
                high: Float::INFINITY,
            }
        } else if f > 0.0 {
            Interval {
                low: div_round_down(self.low, f),
                high: div_round_up(self.high, f),
            }
        } else {
            Interval {
                low: div_round_down(self.high, f),
                high: div_round_up(self.low, f),
            }
        }
    }
}
impl Mul<Interval> for Float {
    type Output = Interval;
    #[inline]
    fn mul(self, i: Interval) -> Interval {
        i * self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds of all four rounded products or quotients: what the
    /// sign-case shortcuts of `mul` and `div` must reproduce bit for bit.
    fn all_four(
        a: Interval,
        b: Interval,
        down: fn(Float, Float) -> Float,
        up: fn(Float, Float) -> Float,
    ) -> Interval {
        let pairs = [
            (a.low, b.low),
            (a.high, b.low),
            (a.low, b.high),
            (a.high, b.high),
        ];
        Interval {
            low: pairs
                .iter()
                .map(|&(x, y)| down(x, y))
                .fold(Float::INFINITY, Float::min),
            high: pairs
                .iter()
                .map(|&(x, y)| up(x, y))
                .fold(Float::NEG_INFINITY, Float::max),
        }
    }

    #[test]
    fn sign_case_products_and_quotients_equal_all_four() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || crate::float::xorshift64(&mut state);
        let specials = [
            0.0, -0.0, 1.0, -1.0, 1e-30, -1e-30, 3.5e20, -3.5e20, 0.1, -7.25,
        ];
        let mut value = || -> Float {
            let r = next();
            if r % 4 == 0 {
                specials[(r >> 8) as usize % specials.len()]
            } else {
                let m = ((r >> 8) % 2_000_000) as Float / 1000.0 - 1000.0;
                m * [1.0, 1e-6, 1e6][(r >> 40) as usize % 3]
            }
        };
        for _ in 0..200_000 {
            let (x0, x1, y0, y1) = (value(), value(), value(), value());
            let a = Interval {
                low: x0.min(x1),
                high: x0.max(x1),
            };
            let b = Interval {
                low: y0.min(y1),
                high: y0.max(y1),
            };
            let p = a * b;
            let q = all_four(a, b, mul_round_down, mul_round_up);
            assert_eq!(
                (p.low.to_bits(), p.high.to_bits()),
                (q.low.to_bits(), q.high.to_bits()),
                "{a:?} * {b:?}"
            );
            if !b.contains(0.0) {
                let p = a / b;
                let q = all_four(a, b, div_round_down, div_round_up);
                assert_eq!(
                    (p.low.to_bits(), p.high.to_bits()),
                    (q.low.to_bits(), q.high.to_bits()),
                    "{a:?} / {b:?}"
                );
            }
        }
    }

    /// A simple deterministic generator for the tests.
    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn intervals_contain_exact_results() {
        let mut s = 0x1234_5678_9abc_def1u64;
        for _ in 0..10000 {
            let a = (rng(&mut s) * 200.0 - 100.0) as f32;
            let b = (rng(&mut s) * 200.0 - 100.0) as f32;
            let ea = (rng(&mut s) * 0.01) as f32;
            let eb = (rng(&mut s) * 0.01) as f32;
            let ia = Interval::from_value_and_error(a, ea);
            let ib = Interval::from_value_and_error(b, eb);
            let (ad, bd) = (a as f64, b as f64);
            let chk = |i: Interval, v: f64| {
                assert!(i.low as f64 <= v && v <= i.high as f64, "{i:?} {v}");
            };
            chk(ia + ib, ad + bd);
            chk(ia - ib, ad - bd);
            chk(ia * ib, ad * bd);
            if !ib.contains(0.0) {
                chk(ia / ib, ad / bd);
            }
            chk(ia.sqr(), ad * ad);
            chk(ia * 3.5, ad * 3.5);
            chk(ia * -2.0, ad * -2.0);
            if a >= 0.0 {
                chk(ia.sqrt(), ad.sqrt());
            }
        }
    }

    #[test]
    fn division_by_zero_interval_is_unbounded() {
        let r = Interval::new(1.0) / Interval::from_bounds(-1.0, 1.0);
        assert!(r.low.is_infinite() && r.high.is_infinite());
    }
}
