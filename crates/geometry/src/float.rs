//! Floating-point utilities (pbrt-v4 `util/float.h`, `util/math.h`; book
//! section 6.8): error bounds, ulp stepping and error-free transformations.

/// The floating-point type used throughout rpbrt.
pub type Float = f32;

/// Half of the distance between 1 and the next representable float: the
/// relative error bound of one correctly rounded operation.
pub const MACHINE_EPSILON: Float = f32::EPSILON * 0.5;
/// π.
pub const PI: Float = std::f32::consts::PI;
/// 1/π.
pub const INV_PI: Float = std::f32::consts::FRAC_1_PI;
/// 1/(2π).
pub const INV_2PI: Float = 0.159_154_94;
/// 1/(4π).
pub const INV_4PI: Float = 0.079_577_47;
/// π/2.
pub const PI_OVER_2: Float = std::f32::consts::FRAC_PI_2;
/// π/4.
pub const PI_OVER_4: Float = std::f32::consts::FRAC_PI_4;
/// √2.
pub const SQRT2: Float = std::f32::consts::SQRT_2;
/// The largest float strictly below one.
pub const ONE_MINUS_EPSILON: Float = 0.999_999_94;

/// γ(n) = nε/(1 − nε): the bound on the relative error of n rounded operations.
#[inline]
pub fn gamma(n: i32) -> Float {
    let ne = n as Float * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// The smallest float strictly greater than `v` (infinity stays infinity).
///
/// The step's direction depends on the sign, which is as good as random
/// for error bounds around points: it is selected, not branched on.
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v == f32::INFINITY {
        return v;
    }
    // −0 becomes +0 (and every other value stays as it is).
    let v = if v == 0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits =
        std::hint::select_unpredictable(v >= 0.0, bits.wrapping_add(1), bits.wrapping_sub(1));
    f32::from_bits(bits)
}

/// The largest float strictly less than `v` (negative infinity stays).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v == f32::NEG_INFINITY {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = std::hint::select_unpredictable(v > 0.0, bits.wrapping_sub(1), bits.wrapping_add(1));
    f32::from_bits(bits)
}

/// The smallest f64 strictly greater than `v`.
#[inline]
pub fn next_double_up(v: f64) -> f64 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    f64::from_bits(if v >= 0.0 { bits + 1 } else { bits - 1 })
}

/// The largest f64 strictly less than `v`.
#[inline]
pub fn next_double_down(v: f64) -> f64 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    f64::from_bits(if v > 0.0 { bits - 1 } else { bits + 1 })
}

/// Rounded addition toward +∞ (an upper bound on the exact sum).
#[inline]
pub fn add_round_up(a: Float, b: Float) -> Float {
    next_float_up(a + b)
}
/// Rounded addition toward −∞.
#[inline]
pub fn add_round_down(a: Float, b: Float) -> Float {
    next_float_down(a + b)
}
/// Rounded subtraction toward +∞.
#[inline]
pub fn sub_round_up(a: Float, b: Float) -> Float {
    add_round_up(a, -b)
}
/// Rounded subtraction toward −∞.
#[inline]
pub fn sub_round_down(a: Float, b: Float) -> Float {
    add_round_down(a, -b)
}
/// Rounded multiplication toward +∞.
#[inline]
pub fn mul_round_up(a: Float, b: Float) -> Float {
    next_float_up(a * b)
}
/// Rounded multiplication toward −∞.
#[inline]
pub fn mul_round_down(a: Float, b: Float) -> Float {
    next_float_down(a * b)
}
/// Rounded division toward +∞.
#[inline]
pub fn div_round_up(a: Float, b: Float) -> Float {
    next_float_up(a / b)
}
/// Rounded division toward −∞.
#[inline]
pub fn div_round_down(a: Float, b: Float) -> Float {
    next_float_down(a / b)
}
/// Rounded square root toward +∞.
#[inline]
pub fn sqrt_round_up(a: Float) -> Float {
    next_float_up(a.sqrt())
}
/// Rounded square root toward −∞ (never below zero).
#[inline]
pub fn sqrt_round_down(a: Float) -> Float {
    next_float_down(a.sqrt()).max(0.0)
}

/// a·b − c·d, accurate even when the two products nearly cancel.
///
/// pbrt-v4 uses Kahan's algorithm with fused multiply-adds. Without a
/// hardware FMA (the x86-64 baseline has none) `mul_add` becomes a slow
/// software routine, so the products are formed in double precision
/// instead: a product of two floats is exact in a double, and the one
/// rounding of the difference is at least as accurate as Kahan's result.
#[inline]
pub fn difference_of_products(a: Float, b: Float, c: Float, d: Float) -> Float {
    (a as f64 * b as f64 - c as f64 * d as f64) as Float
}

/// a·b + c·d with the same exact-product evaluation.
#[inline]
pub fn sum_of_products(a: Float, b: Float, c: Float, d: Float) -> Float {
    (a as f64 * b as f64 + c as f64 * d as f64) as Float
}

/// An unevaluated sum `v + err` holding more precision than one float.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensatedFloat {
    /// The rounded value.
    pub v: Float,
    /// The rounding error: the exact value is `v + err`.
    pub err: Float,
}

impl CompensatedFloat {
    /// The best single-float approximation of the compensated value.
    #[inline]
    pub fn value(self) -> Float {
        self.v + self.err
    }
}

/// Error-free product: `a·b` exactly as `v + err`.
///
/// The error is pbrt-v4's `FMA(a, b, -ab)`, found in double precision (as
/// [`difference_of_products`] explains): the double product is exact, so is
/// its difference from the nearby `ab` (Sterbenz), and the one rounding to
/// a float is the fused multiply-add's. The bits are the same.
#[inline]
pub fn two_prod(a: Float, b: Float) -> CompensatedFloat {
    let ab = a * b;
    CompensatedFloat {
        v: ab,
        err: (a as f64 * b as f64 - ab as f64) as Float,
    }
}

/// Error-free sum (Knuth's TwoSum): `a + b` exactly as `v + err`.
#[inline]
pub fn two_sum(a: Float, b: Float) -> CompensatedFloat {
    let s = a + b;
    let delta = s - a;
    CompensatedFloat {
        v: s,
        err: (a - (s - delta)) + (b - delta),
    }
}

/// Inner product of two equal-length slices with compensated summation.
pub fn inner_product(a: &[Float], b: &[Float]) -> Float {
    debug_assert_eq!(a.len(), b.len());
    let mut sum = CompensatedFloat { v: 0.0, err: 0.0 };
    for (&x, &y) in a.iter().zip(b) {
        let p = two_prod(x, y);
        let s = two_sum(sum.v, p.v);
        sum = CompensatedFloat {
            v: s.v,
            err: sum.err + p.err + s.err,
        };
    }
    sum.value()
}

/// A fixed-seed xorshift64 step, for tests that need many reproducible
/// bit patterns: advances `state` and returns it.
#[cfg(test)]
pub(crate) fn xorshift64(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// A fixed-seed value for tests (advancing `state`): of either sign, a
/// 24-bit fraction below ½ times `2^e` for an `e` from `lowest` to
/// `lowest + octaves − 1`, so magnitudes over many orders.
#[cfg(test)]
pub(crate) fn spread_value(state: &mut u64, octaves: u64, lowest: i32) -> Float {
    let r = xorshift64(state);
    let m = (r >> 40) as Float / (1u64 << 24) as Float - 0.5;
    m * (2.0 as Float).powi((r % octaves) as i32 + lowest)
}

/// Linear interpolation `(1 − t)·a + t·b`.
#[inline]
pub fn lerp(t: Float, a: Float, b: Float) -> Float {
    (1.0 - t) * a + t * b
}

/// Clamps `v` to `[lo, hi]`; NaN maps to `lo`.
#[inline]
pub fn clamp(v: Float, lo: Float, hi: Float) -> Float {
    if v < lo || v.is_nan() {
        lo
    } else if v > hi {
        hi
    } else {
        v
    }
}

/// Square root that treats small negative inputs (rounding error) as zero.
#[inline]
pub fn safe_sqrt(x: Float) -> Float {
    x.max(0.0).sqrt()
}

/// asin with its argument clamped to [−1, 1].
#[inline]
pub fn safe_asin(x: Float) -> Float {
    clamp(x, -1.0, 1.0).asin()
}

/// acos with its argument clamped to [−1, 1].
#[inline]
pub fn safe_acos(x: Float) -> Float {
    clamp(x, -1.0, 1.0).acos()
}

/// x².
#[inline]
pub fn sqr(x: Float) -> Float {
    x * x
}

/// Degrees to radians.
#[inline]
pub fn radians(deg: Float) -> Float {
    (PI / 180.0) * deg
}

/// Radians to degrees.
#[inline]
pub fn degrees(rad: Float) -> Float {
    (180.0 / PI) * rad
}

/// Evaluates a polynomial with coefficients in increasing degree (Horner).
#[inline]
pub fn evaluate_polynomial(t: Float, coeffs: &[Float]) -> Float {
    let mut r: Float = 0.0;
    for &c in coeffs.iter().rev() {
        r = r * t + c;
    }
    r
}

/// The real roots `t0 ≤ t1` of `a t² + b t + c`, computed stably in double
/// precision; `None` when there are none.
pub fn quadratic(a: Float, b: Float, c: Float) -> Option<(Float, Float)> {
    let (a, b, c) = (a as f64, b as f64, c as f64);
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = (-c / b) as Float;
        return Some((t, t));
    }
    let discrim = b * b - 4.0 * a * c;
    if discrim < 0.0 {
        return None;
    }
    let root = discrim.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let mut t0 = q / a;
    let mut t1 = if q != 0.0 { c / q } else { t0 };
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    Some((t0 as Float, t1 as Float))
}

/// Finds the largest index `i` in `[0, size − 2]` with `pred(i)` true,
/// assuming `pred` is true then false (pbrt's `FindInterval`).
///
/// The same answer as pbrt's binary search, found without data-dependent
/// branches (the range halves by a conditional move, which
/// `select_unpredictable` asks for), since the outcome of each probe is a
/// coin flip for random lookups such as sampling.
#[inline]
pub fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    if size < 2 {
        return 0;
    }
    // The first index in [1, size − 1] where `pred` is false (size − 1 if
    // none) lies in [base, base + len].
    let mut base = 1usize;
    let mut len = size - 2;
    while len > 1 {
        let half = len / 2;
        base = std::hint::select_unpredictable(pred(base + half - 1), base + half, base);
        len -= half;
    }
    if len == 1 && pred(base) {
        base += 1;
    }
    (base - 1).min(size - 2)
}

/// [`find_interval`] for many searches at once, interleaved: `out[k]`
/// becomes `find_interval(size, |i| pred(k, i))` for every `k`.
///
/// Every search over a `size`-entry table takes the same number of
/// halving steps whatever its outcome, so the searches advance in step,
/// one probe of each per round: their loads are independent, and the
/// processor overlaps them instead of waiting on each chain of dependent
/// loads in turn (the gain of lane-parallel sampling without gathers).
#[inline]
pub fn find_intervals(size: usize, out: &mut [usize], pred: impl Fn(usize, usize) -> bool) {
    if size < 2 {
        out.fill(0);
        return;
    }
    out.fill(1);
    let mut len = size - 2;
    while len > 1 {
        let half = len / 2;
        for (k, base) in out.iter_mut().enumerate() {
            *base = std::hint::select_unpredictable(pred(k, *base + half - 1), *base + half, *base);
        }
        len -= half;
    }
    for (k, base) in out.iter_mut().enumerate() {
        if len == 1 && pred(k, *base) {
            *base += 1;
        }
        *base = (*base - 1).min(size - 2);
    }
}

/// sin(x)/x, well-behaved at zero.
#[inline]
pub fn sin_x_over_x(x: Float) -> Float {
    if 1.0 - x * x == 1.0 {
        1.0
    } else {
        x.sin() / x
    }
}

/// Smallest power of two ≥ v (v > 0).
#[inline]
pub fn round_up_pow2(v: u32) -> u32 {
    v.max(1).next_power_of_two()
}

/// Spreads the low 10 bits of `v` so that each is followed by two zeros
/// (for 3-D Morton codes).
#[inline]
pub fn left_shift3(mut x: u32) -> u32 {
    if x == 1 << 10 {
        x -= 1;
    }
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// The 3-D Morton code of a point with components in [0, 1024].
#[inline]
pub fn encode_morton3(x: Float, y: Float, z: Float) -> u32 {
    (left_shift3(z as u32) << 2) | (left_shift3(y as u32) << 1) | left_shift3(x as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_stepping() {
        assert!(next_float_up(1.0) > 1.0);
        assert!(next_float_down(1.0) < 1.0);
        assert_eq!(next_float_up(-0.0), next_float_up(0.0));
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(next_float_down(f32::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(next_float_up(f32::MAX), f32::INFINITY);
        assert_eq!(next_float_down(-1.0), -1.0 - f32::EPSILON);
        assert!(next_double_up(1.0) > 1.0 && next_double_down(1.0) < 1.0);
    }

    #[test]
    fn two_prod_error_is_the_fused_multiply_adds() {
        // Fixed seed; exponents across the float range, subnormal products
        // and overflowing ones included.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || xorshift64(&mut state);
        for _ in 0..200_000 {
            let r = next();
            // Half of them below 2 (tiny products), half anything
            // (overflows, infinities and NaNs too).
            let mask = if r & 1 == 0 { 0xbfff_ffff } else { u32::MAX };
            let a = f32::from_bits(r as u32 & mask);
            let b = f32::from_bits((r >> 32) as u32 & mask);
            let p = two_prod(a, b);
            let fma = a.mul_add(b, -(a * b));
            assert!(
                p.err.to_bits() == fma.to_bits() || (p.err.is_nan() && fma.is_nan()),
                "{a:e} * {b:e}: {:e} against {fma:e}",
                p.err
            );
        }
    }

    #[test]
    fn difference_of_products_is_accurate() {
        // Catastrophic cancellation in the naive form.
        let (a, b, c, d) = (33962.035f32, 41563.4f32, -24871.969f32, -56755.0f32);
        let exact = a as f64 * b as f64 - c as f64 * d as f64;
        let v = difference_of_products(a, b, c, d) as f64;
        assert!(((v - exact) / exact).abs() < 1e-6);
    }

    #[test]
    fn error_free_transforms() {
        let a = 1.0f32 + f32::EPSILON;
        let b = 1.0f32 - f32::EPSILON;
        let p = two_prod(a, b);
        assert_eq!(p.v as f64 + p.err as f64, a as f64 * b as f64);
        let s = two_sum(1e8, 1.0);
        assert_eq!(s.v as f64 + s.err as f64, 1e8 + 1.0);
        assert!((inner_product(&[1e8, 1.0, -1e8], &[1.0, 1.0, 1.0]) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn quadratic_roots() {
        let (t0, t1) = quadratic(1.0, -3.0, 2.0).unwrap();
        assert!((t0 - 1.0).abs() < 1e-6 && (t1 - 2.0).abs() < 1e-6);
        assert!(quadratic(1.0, 0.0, 1.0).is_none());
        assert!(quadratic(0.0, 0.0, 1.0).is_none());
        let (t0, _) = quadratic(0.0, 2.0, -4.0).unwrap();
        assert_eq!(t0, 2.0);
    }

    #[test]
    fn interval_search() {
        let v = [0.0f32, 1.0, 2.0, 3.0];
        assert_eq!(find_interval(4, |i| v[i] <= 1.5), 1);
        assert_eq!(find_interval(4, |i| v[i] <= -1.0), 0);
        assert_eq!(find_interval(4, |i| v[i] <= 10.0), 2);
        // Against pbrt's branching binary search on monotone tables with
        // repeated entries, for every size up to 70 and every threshold.
        fn reference(size: usize, pred: impl Fn(usize) -> bool) -> usize {
            if size < 2 {
                return 0;
            }
            let (mut first, mut sz) = (1usize, size - 2);
            while sz > 0 {
                let half = sz >> 1;
                let middle = first + half;
                if pred(middle) {
                    first = middle + 1;
                    sz -= half + 1;
                } else {
                    sz = half;
                }
            }
            (first - 1).min(size - 2)
        }
        for size in 0..70usize {
            let t: Vec<usize> = (0..size).map(|i| (i * 7 + i / 3) / 5).collect();
            for u in 0..(size * 2 + 2) {
                let pred = |i: usize| t[i] <= u / 2;
                assert_eq!(
                    find_interval(size, pred),
                    reference(size, pred),
                    "{size} {u}"
                );
            }
        }
    }

    #[test]
    fn interleaved_searches_match_single_ones() {
        // Every size up to 70, each search of a batch with its own
        // threshold (so the batch's searches end in different intervals).
        for size in 0..70usize {
            let t: Vec<usize> = (0..size).map(|i| (i * 7 + i / 3) / 5).collect();
            let us: Vec<usize> = (0..(size * 2 + 2)).collect();
            let mut out = vec![usize::MAX; us.len()];
            find_intervals(size, &mut out, |k, i| t[i] <= us[k] / 2);
            for (k, &o) in out.iter().enumerate() {
                assert_eq!(
                    o,
                    find_interval(size, |i| t[i] <= us[k] / 2),
                    "size {size}, k {k}"
                );
            }
        }
    }

    #[test]
    fn gamma_grows() {
        assert!(gamma(3) > gamma(2) && gamma(1) > MACHINE_EPSILON);
    }

    #[test]
    fn morton() {
        assert_eq!(encode_morton3(1.0, 0.0, 0.0), 1);
        assert_eq!(encode_morton3(0.0, 1.0, 0.0), 2);
        assert_eq!(encode_morton3(0.0, 0.0, 1.0), 4);
        assert_eq!(encode_morton3(3.0, 0.0, 0.0), 0b1001);
    }
}
