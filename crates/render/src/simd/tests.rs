use super::math;
use super::*;
use crate::rng::Rng;

/// Values that lane code gets wrong most easily: zeros of both signs,
/// infinities, NaN, subnormals, the largest float.
const AWKWARD: [f32; 12] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    1e-40,
    -1e-40,
    f32::MAX,
    3.5,
    -2.25,
];

/// Applies every lane operation to `a` and `b` at width `L` and returns
/// the results lane by lane, to compare with the scalar code's.
struct AllOps<'a> {
    a: &'a [f32],
    b: &'a [f32],
}

impl Kernel for AllOps<'_> {
    type Output = Vec<[u32; 9]>;
    // Lane i of six result arrays and three masks: indexing reads best.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> Vec<[u32; 9]> {
        let mut out = Vec::new();
        for (ca, cb) in self.a.chunks_exact(L::N).zip(self.b.chunks_exact(L::N)) {
            let (a, b) = (L::load(ca), L::load(cb));
            let mut vals = [[0.0f32; 16]; 6];
            a.add(b).store(&mut vals[0]);
            a.sub(b).store(&mut vals[1]);
            a.mul(b).store(&mut vals[2]);
            a.min(b).store(&mut vals[3]);
            a.max(b).store(&mut vals[4]);
            L::select(a.lt(b), a, b).store(&mut vals[5]);
            let lt = L::bits(a.lt(b));
            let le = L::bits(a.le(b));
            let both = L::bits(L::and(a.lt(b), L::from_bits(0b1010_1010_1010_1010)));
            for i in 0..L::N {
                out.push([
                    vals[0][i].to_bits(),
                    vals[1][i].to_bits(),
                    vals[2][i].to_bits(),
                    vals[3][i].to_bits(),
                    vals[4][i].to_bits(),
                    vals[5][i].to_bits(),
                    (lt >> i) & 1,
                    (le >> i) & 1,
                    (both >> i) & 1,
                ]);
            }
        }
        out
    }
}

/// Every width gives the scalar results bit for bit, on random values and
/// on the awkward ones (zeros of both signs, infinities, NaN, subnormals).
#[test]
fn every_width_computes_what_scalar_code_computes() {
    let special = AWKWARD;
    let mut rng = Rng::with_sequence(5);
    let mut a = Vec::new();
    let mut b = Vec::new();
    for &x in &special {
        for &y in &special {
            a.push(x);
            b.push(y);
        }
    }
    for _ in 0..4000 {
        a.push((rng.uniform_float() - 0.5) * 1e3);
        b.push((rng.uniform_float() - 0.5) * 1e3);
    }
    // A multiple of 16 values, for every width.
    while a.len() % 16 != 0 {
        a.push(1.0);
        b.push(2.0);
    }
    let reference = dispatch(SimdLevel::Scalar, AllOps { a: &a, b: &b });
    // The scalar lanes are the scalar expressions themselves.
    for (i, r) in reference.iter().enumerate() {
        let (x, y) = (a[i], b[i]);
        assert_eq!(r[0], (x + y).to_bits());
        assert_eq!(r[3], (if x < y { x } else { y }).to_bits());
        assert_eq!(r[4], (if x > y { x } else { y }).to_bits());
        assert_eq!(r[6], (x < y) as u32);
        assert_eq!(r[7], (x <= y) as u32);
    }
    let levels = SimdLevel::available();
    assert!(levels.contains(&SimdLevel::Scalar));
    for level in levels {
        let got = dispatch(level, AllOps { a: &a, b: &b });
        assert_eq!(got.len(), reference.len());
        for (i, (g, r)) in got.iter().zip(&reference).enumerate() {
            // The mask test ANDs with every other lane of a 16-lane
            // pattern: lane i of an N-wide chunk is bit i % N.
            let mut r = *r;
            let lanes = level.lanes();
            let bit = if lanes == 1 {
                0
            } else {
                (0b1010_1010_1010_1010u32 >> (i % lanes)) & 1
            };
            r[8] = r[6] & bit;
            assert_eq!(*g, r, "{level:?}: values {} and {}", a[i], b[i]);
        }
    }
}

#[test]
fn levels_parse_and_order() {
    assert_eq!(SimdLevel::parse("AVX2"), Some(SimdLevel::Avx2));
    assert_eq!(SimdLevel::parse("sse4.1"), Some(SimdLevel::Sse4));
    assert_eq!(SimdLevel::parse("scalar"), Some(SimdLevel::Scalar));
    assert_eq!(SimdLevel::parse("AVX512"), Some(SimdLevel::Avx512));
    assert_eq!(SimdLevel::parse("avx9"), None);
    assert!(SimdLevel::Scalar < SimdLevel::Sse4 && SimdLevel::Sse4 < SimdLevel::Avx2);
    assert!(SimdLevel::Avx2 < SimdLevel::Avx512 && SimdLevel::Avx512.lanes() == 16);
    // Asking for more than the processor has runs what it has.
    assert!(level() <= SimdLevel::detected());
    // The default is the best level but for Intel's AVX-512, where it is
    // AVX2.
    let (preferred, best) = (SimdLevel::preferred(), SimdLevel::detected());
    assert!(
        preferred == best || (best == SimdLevel::Avx512 && preferred == SimdLevel::Avx2),
        "{preferred:?} of {best:?}"
    );
    let sum = dispatch(
        SimdLevel::Avx512,
        AllOps {
            a: &[1.0; 16],
            b: &[2.0; 16],
        },
    );
    assert!(sum.iter().all(|r| r[0] == 3.0f32.to_bits()));
}

/// Runs the elementary functions at width `L` over `x` (and `y`).
struct MathOps<'a> {
    x: &'a [f32],
    y: &'a [f32],
}

impl Kernel for MathOps<'_> {
    type Output = Vec<[u32; 4]>;
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> Vec<[u32; 4]> {
        let mut out = Vec::new();
        for (cx, cy) in self.x.chunks_exact(L::N).zip(self.y.chunks_exact(L::N)) {
            let (x, y) = (L::load(cx), L::load(cy));
            let (s, c) = math::sin_cos(x);
            let t = math::atan2(y, x);
            // e^(8y): arguments from −400 to 400 at the widest.
            let e = math::exp(y.mul(L::splat(8.0)));
            let mut v = [[0.0f32; 16]; 4];
            s.store(&mut v[0]);
            c.store(&mut v[1]);
            t.store(&mut v[2]);
            e.store(&mut v[3]);
            for i in 0..L::N {
                out.push([v[0][i], v[1][i], v[2][i], v[3][i]].map(f32::to_bits));
            }
        }
        out
    }
}

/// sin, cos, atan2 and exp are within a few ulps of the correctly rounded
/// values (on the arguments rpbrt gives them: angles of a few turns), and
/// every width gives the same bits.
#[test]
fn elementary_functions_are_accurate_and_the_same_at_every_width() {
    let mut rng = Rng::with_sequence(11);
    let mut x = vec![
        0.0f32,
        -0.0,
        1e-30,
        std::f32::consts::FRAC_PI_4,
        std::f32::consts::PI,
    ];
    let mut y = vec![0.0f32, 0.0, -1.0, 1.0, -0.0];
    for i in 0..20000 {
        let scale = [1.0, 8.0, 100.0, 1e-3][i % 4];
        x.push((rng.uniform_float() - 0.5) * 2.0 * scale);
        y.push((rng.uniform_float() - 0.5) * 2.0 * [1.0, 1e-3, 50.0, 1.0][i % 4]);
    }
    while x.len() % 16 != 0 {
        x.push(0.5);
        y.push(0.25);
    }
    let reference = dispatch(SimdLevel::Scalar, MathOps { x: &x, y: &y });
    // Error in units of the last place of the exact value (absolute near
    // zero, where the functions' results are tiny or cancel).
    let ulps = |got: f32, exact: f64| {
        let ulp = (exact.abs().max(1e-7) as f32).to_bits();
        let ulp = (f32::from_bits(ulp + 1) - f32::from_bits(ulp)) as f64;
        (got as f64 - exact).abs() / ulp
    };
    let mut worst = [0.0f64; 4];
    for (i, r) in reference.iter().enumerate() {
        let (xi, yi) = (x[i] as f64, y[i] as f64);
        let got = r.map(f32::from_bits);
        worst[0] = worst[0].max(ulps(got[0], xi.sin()));
        worst[1] = worst[1].max(ulps(got[1], xi.cos()));
        worst[2] = worst[2].max(ulps(got[2], yi.atan2(xi)));
        // exp: relative error where the result is a normal float, and the
        // flush to zero or infinity outside.
        let arg = (y[i] * 8.0) as f64;
        let exact = arg.exp();
        if (-87.3..=88.0).contains(&arg) {
            let ulp = f32::from_bits((exact as f32).to_bits() + 1) as f64 - (exact as f32) as f64;
            worst[3] = worst[3].max((got[3] as f64 - exact).abs() / ulp);
        } else if arg < -87.3 {
            assert_eq!(got[3], 0.0, "exp({arg})");
        } else {
            assert_eq!(got[3], f32::INFINITY, "exp({arg})");
        }
    }
    assert!(
        worst.iter().all(|&w| w <= 4.0),
        "worst errors (ulps) sin {} cos {} atan2 {} exp {}",
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    for level in SimdLevel::available() {
        let got = dispatch(level, MathOps { x: &x, y: &y });
        assert_eq!(got, reference, "{level:?}");
    }
}

/// Runs [`math::ln`] at width `L` over `x`.
struct LnOp<'a>(&'a [f32]);

impl Kernel for LnOp<'_> {
    type Output = Vec<u32>;
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> Vec<u32> {
        let mut out = Vec::new();
        for c in self.0.chunks_exact(L::N) {
            let mut v = [0.0f32; 16];
            math::ln(L::load(c)).store(&mut v);
            out.extend(v[..L::N].iter().map(|x| x.to_bits()));
        }
        out
    }
}

/// ln is within a few ulps of the correctly rounded value over the whole
/// positive range (subnormals included), gives the C library's special
/// values at 0, ∞, negative numbers and NaN, and the same bits at every
/// width.
#[test]
fn ln_is_accurate_and_the_same_at_every_width() {
    let mut rng = Rng::with_sequence(12);
    let mut x = vec![
        1.0f32,
        0.5,
        2.0,
        std::f32::consts::FRAC_1_SQRT_2,
        std::f32::consts::SQRT_2,
        f32::MIN_POSITIVE,
        1e-40,
        f32::from_bits(1),
        f32::MAX,
        0.0,
        -0.0,
        -1.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    for i in 0..20000 {
        // Near 1 (where ln cancels), over the wavelengths' range, and
        // across all exponents.
        let u = rng.uniform_float();
        x.push(match i % 3 {
            0 => 1.0 + (u - 0.5) * 1e-3,
            1 => 0.01 + u * 15.0,
            _ => f32::from_bits(1 + (u * (0x7f7f_ffff as f32)) as u32),
        });
    }
    while x.len() % 16 != 0 {
        x.push(3.0);
    }
    let reference = dispatch(SimdLevel::Scalar, LnOp(&x));
    let mut worst = 0.0f64;
    for (&xi, &r) in x.iter().zip(&reference) {
        let got = f32::from_bits(r);
        if xi.is_nan() || xi < 0.0 || xi == f32::NEG_INFINITY {
            assert!(got.is_nan(), "ln({xi}) = {got}");
        } else if xi == 0.0 {
            assert_eq!(got, f32::NEG_INFINITY, "ln({xi})");
        } else if xi == f32::INFINITY {
            assert_eq!(got, f32::INFINITY);
        } else {
            let exact = (xi as f64).ln();
            let e = exact as f32;
            let ulp = if e == 0.0 {
                f32::from_bits(1) as f64
            } else {
                (f32::from_bits(e.abs().to_bits() + 1) - e.abs()) as f64
            };
            worst = worst.max((got as f64 - exact).abs() / ulp);
        }
    }
    assert!(worst <= 2.0, "worst ln error {worst} ulps");
    for level in SimdLevel::available() {
        assert_eq!(dispatch(level, LnOp(&x)), reference, "{level:?}");
    }
}

/// Applies every integer lane operation (and the exact conversion to
/// `f32`) to `a` and `b` at width `L`, lane by lane.
struct IntOps<'a> {
    a: &'a [u32],
    b: &'a [u32],
}

impl Kernel for IntOps<'_> {
    type Output = Vec<[u32; 9]>;
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn run<L: F32Lanes>(self) -> Vec<[u32; 9]> {
        let mut out = Vec::new();
        for (ca, cb) in self.a.chunks_exact(L::N).zip(self.b.chunks_exact(L::N)) {
            let (a, b) = (L::U32::load(ca), L::U32::load(cb));
            let mut vals = [[0u32; 16]; 9];
            a.add(b).store(&mut vals[0]);
            a.mul(b).store(&mut vals[1]);
            a.xor(b).store(&mut vals[2]);
            a.or(b).store(&mut vals[3]);
            a.and(b).store(&mut vals[4]);
            a.shr::<16>().store(&mut vals[5]);
            a.shr::<3>().store(&mut vals[6]);
            a.reverse_bits().store(&mut vals[7]);
            let mut f = [0f32; 16];
            L::from_u32(a).store(&mut f);
            for (v, f) in vals[8].iter_mut().zip(f) {
                *v = f.to_bits();
            }
            for i in 0..L::N {
                out.push(std::array::from_fn(|k| vals[k][i]));
            }
        }
        out
    }
}

/// Every integer lane operation gives the wrapping `u32` operation's
/// bits at every level, and `from_u32` is `as f32` (ties included).
#[test]
fn integer_lanes_match_scalar() {
    let mut rng = Rng::new(41, 3);
    let mut a: Vec<u32> = (0..4096).map(|_| rng.uniform_u32()).collect();
    let b: Vec<u32> = (0..4096).map(|_| rng.uniform_u32()).collect();
    // Values whose conversion to f32 is a tie or near one, and the ends.
    let specials = [
        0,
        1,
        u32::MAX,
        0x0100_0001,
        0x0100_0003,
        0xffff_ff80,
        0x8000_0080,
    ];
    a[..specials.len()].copy_from_slice(&specials);
    for (i, x) in a.iter_mut().enumerate().skip(specials.len()).take(512) {
        *x = (*x | 0x0100_0000) & !(0x7f << (i % 8));
    }
    let expect: Vec<[u32; 9]> = a
        .iter()
        .zip(&b)
        .map(|(&a, &b)| {
            [
                a.wrapping_add(b),
                a.wrapping_mul(b),
                a ^ b,
                a | b,
                a & b,
                a >> 16,
                a >> 3,
                a.reverse_bits(),
                (a as f32).to_bits(),
            ]
        })
        .collect();
    for level in SimdLevel::available() {
        let got = dispatch(level, IntOps { a: &a, b: &b });
        assert_eq!(got, expect, "{level:?}");
    }
}

/// The next floats up and down, and intervals from a value and an error,
/// at every width: the geometry crate's scalar functions bit for bit, on
/// random values and the awkward ones (zeros of both signs, infinities,
/// NaN, subnormals, the largest floats).
#[test]
fn next_floats_and_intervals_match_the_scalar_functions() {
    use rpbrt_geometry::float::{next_float_down, next_float_up};
    use rpbrt_geometry::interval::Interval;
    struct Steps<'a>(&'a [f32], &'a [f32]);
    impl Kernel for Steps<'_> {
        type Output = Vec<[u32; 4]>;
        #[inline(always)]
        fn run<L: F32Lanes>(self) -> Vec<[u32; 4]> {
            let mut out = Vec::new();
            for (cv, ce) in self.0.chunks_exact(L::N).zip(self.1.chunks_exact(L::N)) {
                let (v, e) = (L::load(cv), L::load(ce));
                let mut r = [[0.0f32; 16]; 4];
                math::next_float_up(v).store(&mut r[0]);
                math::next_float_down(v).store(&mut r[1]);
                let (lo, hi) = math::interval_from_value_and_error(v, e);
                lo.store(&mut r[2]);
                hi.store(&mut r[3]);
                for i in 0..L::N {
                    out.push([0, 1, 2, 3].map(|k| r[k][i].to_bits()));
                }
            }
            out
        }
    }
    let special: Vec<f32> = AWKWARD
        .into_iter()
        .chain([
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e-45,
            -1e-45,
            f32::MIN,
        ])
        .collect();
    let mut rng = Rng::with_sequence(48);
    let mut v = Vec::new();
    let mut e = Vec::new();
    for &a in &special {
        for &b in &special {
            v.push(a);
            e.push(b.abs());
        }
    }
    while v.len() % 16 != 0 || v.len() < 4096 {
        let x = (rng.uniform_float() - 0.5) * 10f32.powi((rng.uniform_u32() % 40) as i32 - 20);
        v.push(x);
        e.push(if rng.uniform_u32() % 4 == 0 {
            0.0
        } else {
            x.abs() * 1e-6
        });
    }
    let want: Vec<[u32; 4]> = v
        .iter()
        .zip(&e)
        .map(|(&x, &err)| {
            let i = Interval::from_value_and_error(x, err);
            [next_float_up(x), next_float_down(x), i.low, i.high].map(f32::to_bits)
        })
        .collect();
    for level in SimdLevel::available() {
        let got = dispatch(level, Steps(&v, &e));
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            // NaN results agree in being NaN (their sign and payload are
            // unspecified).
            let nan = |b: u32| f32::from_bits(b).is_nan();
            let same = g.iter().zip(w).all(|(&a, &b)| a == b || (nan(a) && nan(b)));
            assert!(
                same,
                "{level:?}: value {} error {}: {g:?} {w:?}",
                v[k], e[k]
            );
        }
    }
}
