//! The lane types: `N` `f32` lanes with the operations kernels use, each
//! lane computing exactly what the scalar expression computes.

/// `N` lanes of `f32` and a mask of `N` lanes.
///
/// Implementations are `#[inline(always)]` throughout: kernels instantiated
/// by [`super::dispatch`] compile them inside functions built for the
/// level's instruction set. `min` and `max` keep the scalar code's order
/// (`a < b ? a : b`, `a > b ? a : b`), which is also what x86's
/// `minps`/`maxps` do with NaN.
pub trait F32Lanes: Copy {
    /// The lane count.
    const N: usize;
    /// A lane mask (one boolean per lane).
    type Mask: Copy;
    /// `u32` lanes of the same width.
    type U32: super::U32Lanes;
    /// Lanes of the same instruction set at most four wide (this type
    /// where it has four lanes or fewer): for data four wide, such as the
    /// 4-wide BVH's nodes.
    type Four: F32Lanes;
    /// Lanes of the same instruction set at most eight wide, as `Four`:
    /// for the 8-wide BVH's nodes.
    type Eight: F32Lanes;
    /// Lane-wise `u as f32` (rounded to nearest, ties to even).
    fn from_u32(u: Self::U32) -> Self;
    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// Lanes from the first `N` values of `s`.
    fn load(s: &[f32]) -> Self;
    /// Writes the lanes to the first `N` values of `s`.
    fn store(self, s: &mut [f32]);
    /// Lane-wise `self + o`.
    fn add(self, o: Self) -> Self;
    /// Lane-wise `self - o`.
    fn sub(self, o: Self) -> Self;
    /// Lane-wise `self * o`.
    fn mul(self, o: Self) -> Self;
    /// Lane-wise `if self < o { self } else { o }`.
    fn min(self, o: Self) -> Self;
    /// Lane-wise `if self > o { self } else { o }`.
    fn max(self, o: Self) -> Self;
    /// Lane-wise `self < o`.
    fn lt(self, o: Self) -> Self::Mask;
    /// Lane-wise `self <= o`.
    fn le(self, o: Self) -> Self::Mask;
    /// Lane-wise `if m { a } else { b }`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Lane-wise `a && b`.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// The mask as bits, lane `i` at bit `i`.
    fn bits(m: Self::Mask) -> u32;
    /// The mask whose lane `i` is bit `i` of `bits`.
    fn from_bits(bits: u32) -> Self::Mask;
    /// Lane-wise `self / o`.
    fn div(self, o: Self) -> Self;
    /// Lane-wise square root.
    fn sqrt(self) -> Self;
    /// Lane-wise absolute value (the sign bit cleared).
    fn abs(self) -> Self;
    /// Lane-wise negation (the sign bit flipped).
    fn neg(self) -> Self;
    /// Lane-wise largest integer not above the value.
    fn floor(self) -> Self;
    /// Lane-wise `self == o` (false where either is NaN).
    fn eq(self, o: Self) -> Self::Mask;
    /// Lane-wise: `self` is NaN.
    fn is_nan(self) -> Self::Mask;
    /// Lane-wise `a || b`.
    fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Lane-wise `!a`.
    fn not(a: Self::Mask) -> Self::Mask;
    /// Lane-wise `a·b − c·d` with the products exact (in `f64`), rounded
    /// once to `f64` and once to `f32`, as
    /// [`rpbrt_geometry::float::difference_of_products`].
    fn difference_of_products(a: Self, b: Self, c: Self, d: Self) -> Self;
    /// Lane-wise `a·b + c·d`, as [`rpbrt_geometry::float::sum_of_products`].
    fn sum_of_products(a: Self, b: Self, c: Self, d: Self) -> Self;
    /// Lane-wise 2ⁿ for lanes holding an integer `n` in [−126, 127] (built
    /// from its exponent bits: exact).
    fn pow2i(n: Self) -> Self;
    /// Lane-wise the float whose bit pattern is one more than `self`'s
    /// where `up`, one less elsewhere (wrapping), as `f32::from_bits` of
    /// `to_bits() ± 1`: the step of [`rpbrt_geometry::float::next_float_up`]
    /// and `next_float_down`.
    fn step_bits(self, up: Self::Mask) -> Self;
    /// Lane-wise bit pattern (`f32::to_bits`).
    fn to_u32_bits(self) -> Self::U32;
    /// Lane-wise float of a bit pattern (`f32::from_bits`).
    fn from_u32_bits(u: Self::U32) -> Self;
    /// Lane-wise `self > o`.
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        o.lt(self)
    }
    /// Lane-wise `self >= o`.
    #[inline(always)]
    fn ge(self, o: Self) -> Self::Mask {
        o.le(self)
    }
}

/// One lane: the scalar code itself, for processors without vector units
/// (and as the reference the vector widths are tested against).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scalar1(pub f32);

impl F32Lanes for Scalar1 {
    const N: usize = 1;
    type Mask = bool;
    type U32 = super::U32x1;
    type Four = Scalar1;
    type Eight = Scalar1;
    #[inline(always)]
    fn from_u32(u: super::U32x1) -> Self {
        Scalar1(u.0 as f32)
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Scalar1(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        Scalar1(s[0])
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        s[0] = self.0;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Scalar1(self.0 + o.0)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Scalar1(self.0 - o.0)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Scalar1(self.0 * o.0)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        if self.0 < o.0 {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        if self.0 > o.0 {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self.0 < o.0
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self.0 <= o.0
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a && b
    }
    #[inline(always)]
    fn bits(m: bool) -> u32 {
        m as u32
    }
    #[inline(always)]
    fn from_bits(bits: u32) -> bool {
        bits & 1 != 0
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Scalar1(self.0 / o.0)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Scalar1(self.0.sqrt())
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Scalar1(self.0.abs())
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Scalar1(-self.0)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        Scalar1(self.0.floor())
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self.0 == o.0
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        self.0.is_nan()
    }
    #[inline(always)]
    fn or(a: bool, b: bool) -> bool {
        a || b
    }
    #[inline(always)]
    fn not(a: bool) -> bool {
        !a
    }
    #[inline(always)]
    fn difference_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
        Scalar1(rpbrt_geometry::float::difference_of_products(
            a.0, b.0, c.0, d.0,
        ))
    }
    #[inline(always)]
    fn sum_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
        Scalar1(rpbrt_geometry::float::sum_of_products(a.0, b.0, c.0, d.0))
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        Scalar1(f32::from_bits(((n.0 as i32 + 127) as u32) << 23))
    }
    #[inline(always)]
    fn to_u32_bits(self) -> super::U32x1 {
        super::U32x1(self.0.to_bits())
    }
    #[inline(always)]
    fn from_u32_bits(u: super::U32x1) -> Self {
        Scalar1(f32::from_bits(u.0))
    }
    #[inline(always)]
    fn step_bits(self, up: bool) -> Self {
        let b = self.0.to_bits();
        Scalar1(f32::from_bits(if up {
            b.wrapping_add(1)
        } else {
            b.wrapping_sub(1)
        }))
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{F32x16, F32x4, F32x8};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::F32Lanes;
    use crate::simd::{U32x16, U32x4, U32x8};
    use std::arch::x86_64::*;

    /// Eight lanes in an AVX register. Only [`crate::simd::dispatch`]'s
    /// AVX2 and AVX-512 paths run code that uses it (the processor has
    /// AVX2 there).
    #[derive(Clone, Copy, Debug)]
    pub struct F32x8(__m256);

    /// Sixteen lanes in an AVX-512 register, with a 16-bit mask register
    /// for masks. Only [`crate::simd::dispatch`]'s AVX-512 path runs code
    /// that uses it.
    #[derive(Clone, Copy, Debug)]
    pub struct F32x16(__m512);

    /// Four lanes in an SSE register. Only [`crate::simd::dispatch`]'s
    /// SSE4.1, AVX2 and AVX-512 paths run code that uses it.
    #[derive(Clone, Copy, Debug)]
    pub struct F32x4(__m128);

    // SAFETY (every `unsafe` block below): these types are only used by
    // kernels that `dispatch` runs after checking that the processor has
    // the instructions (AVX-512 F, BW, DQ and VL for F32x16, AVX for
    // F32x8, SSE4.1 for F32x4); slices are length-checked before unaligned
    // loads and stores.
    impl F32Lanes for F32x16 {
        const N: usize = 16;
        type Mask = __mmask16;
        type U32 = U32x16;
        type Four = F32x4;
        type Eight = F32x8;
        #[inline(always)]
        fn from_u32(u: U32x16) -> Self {
            // One rounding to nearest, as `u as f32`.
            unsafe { F32x16(_mm512_cvtepu32_ps(u.0)) }
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { F32x16(_mm512_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..16];
            unsafe { F32x16(_mm512_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn store(self, s: &mut [f32]) {
            let s = &mut s[..16];
            unsafe { _mm512_storeu_ps(s.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { F32x16(_mm512_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { F32x16(_mm512_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { F32x16(_mm512_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // vminps(a, b) = a < b ? a : b, as minps.
            unsafe { F32x16(_mm512_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { F32x16(_mm512_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn select(m: __mmask16, a: Self, b: Self) -> Self {
            // The blend takes its second operand where the mask is set.
            unsafe { F32x16(_mm512_mask_blend_ps(m, b.0, a.0)) }
        }
        #[inline(always)]
        fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & b
        }
        #[inline(always)]
        fn bits(m: __mmask16) -> u32 {
            m as u32
        }
        #[inline(always)]
        fn from_bits(bits: u32) -> __mmask16 {
            bits as __mmask16
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { F32x16(_mm512_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            unsafe { F32x16(_mm512_sqrt_ps(self.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe {
                let b = _mm512_castps_si512(self.0);
                F32x16(_mm512_castsi512_ps(_mm512_and_si512(
                    b,
                    _mm512_set1_epi32(i32::MAX),
                )))
            }
        }
        #[inline(always)]
        fn neg(self) -> Self {
            unsafe {
                let b = _mm512_castps_si512(self.0);
                F32x16(_mm512_castsi512_ps(_mm512_xor_si512(
                    b,
                    _mm512_set1_epi32(i32::MIN),
                )))
            }
        }
        #[inline(always)]
        fn floor(self) -> Self {
            // Round toward −∞, no precision exception: `floor`.
            unsafe {
                F32x16(_mm512_roundscale_ps::<
                    { _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC },
                >(self.0))
            }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn is_nan(self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(self.0, self.0) }
        }
        #[inline(always)]
        fn or(a: __mmask16, b: __mmask16) -> __mmask16 {
            a | b
        }
        #[inline(always)]
        fn not(a: __mmask16) -> __mmask16 {
            !a
        }
        #[inline(always)]
        fn difference_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (lo, hi) = products_pd16(a.0, b.0, c.0, d.0);
                let l = _mm512_cvtpd_ps(_mm512_sub_pd(lo.0, lo.1));
                let h = _mm512_cvtpd_ps(_mm512_sub_pd(hi.0, hi.1));
                F32x16(_mm512_insertf32x8::<1>(_mm512_castps256_ps512(l), h))
            }
        }
        #[inline(always)]
        fn sum_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (lo, hi) = products_pd16(a.0, b.0, c.0, d.0);
                let l = _mm512_cvtpd_ps(_mm512_add_pd(lo.0, lo.1));
                let h = _mm512_cvtpd_ps(_mm512_add_pd(hi.0, hi.1));
                F32x16(_mm512_insertf32x8::<1>(_mm512_castps256_ps512(l), h))
            }
        }
        #[inline(always)]
        fn pow2i(n: Self) -> Self {
            unsafe {
                let e = _mm512_add_epi32(_mm512_cvttps_epi32(n.0), _mm512_set1_epi32(127));
                F32x16(_mm512_castsi512_ps(_mm512_slli_epi32::<23>(e)))
            }
        }
        #[inline(always)]
        fn to_u32_bits(self) -> U32x16 {
            unsafe { U32x16(_mm512_castps_si512(self.0)) }
        }
        #[inline(always)]
        fn from_u32_bits(u: U32x16) -> Self {
            unsafe { F32x16(_mm512_castsi512_ps(u.0)) }
        }
        #[inline(always)]
        fn step_bits(self, up: __mmask16) -> Self {
            unsafe {
                let b = _mm512_castps_si512(self.0);
                let one = _mm512_set1_epi32(1);
                let plus = _mm512_add_epi32(b, one);
                let minus = _mm512_sub_epi32(b, one);
                F32x16(_mm512_castsi512_ps(_mm512_mask_blend_epi32(
                    up, minus, plus,
                )))
            }
        }
    }

    /// The exact products `a·b` and `c·d` in `f64`, of the low eight lanes
    /// and of the high eight.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    unsafe fn products_pd16(
        a: __m512,
        b: __m512,
        c: __m512,
        d: __m512,
    ) -> ((__m512d, __m512d), (__m512d, __m512d)) {
        (
            (
                _mm512_mul_pd(pd_lo(a), pd_lo(b)),
                _mm512_mul_pd(pd_lo(c), pd_lo(d)),
            ),
            (
                _mm512_mul_pd(pd_hi(a), pd_hi(b)),
                _mm512_mul_pd(pd_hi(c), pd_hi(d)),
            ),
        )
    }

    /// The low eight lanes of `x` as `f64` (exact).
    #[inline(always)]
    unsafe fn pd_lo(x: __m512) -> __m512d {
        _mm512_cvtps_pd(_mm512_castps512_ps256(x))
    }

    /// The high eight lanes of `x` as `f64` (exact).
    #[inline(always)]
    unsafe fn pd_hi(x: __m512) -> __m512d {
        _mm512_cvtps_pd(_mm512_extractf32x8_ps::<1>(x))
    }

    impl F32Lanes for F32x8 {
        const N: usize = 8;
        type Mask = __m256;
        type U32 = U32x8;
        type Four = F32x4;
        type Eight = F32x8;
        #[inline(always)]
        fn from_u32(u: U32x8) -> Self {
            // The high and low halves convert exactly (as signed values
            // below 2^16); their sum, rounded once, is `u as f32`.
            unsafe {
                let hi = _mm256_cvtepi32_ps(_mm256_srli_epi32::<16>(u.0));
                let lo = _mm256_cvtepi32_ps(_mm256_and_si256(u.0, _mm256_set1_epi32(0xffff)));
                F32x8(_mm256_add_ps(
                    _mm256_mul_ps(hi, _mm256_set1_ps(65536.0)),
                    lo,
                ))
            }
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { F32x8(_mm256_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..8];
            unsafe { F32x8(_mm256_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn store(self, s: &mut [f32]) {
            let s = &mut s[..8];
            unsafe { _mm256_storeu_ps(s.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { F32x8(_mm256_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { F32x8(_mm256_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { F32x8(_mm256_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // minps(a, b) = a < b ? a : b.
            unsafe { F32x8(_mm256_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { F32x8(_mm256_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn select(m: __m256, a: Self, b: Self) -> Self {
            unsafe { F32x8(_mm256_blendv_ps(b.0, a.0, m)) }
        }
        #[inline(always)]
        fn and(a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_and_ps(a, b) }
        }
        #[inline(always)]
        fn bits(m: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(m) as u32 }
        }
        #[inline(always)]
        fn from_bits(bits: u32) -> __m256 {
            unsafe {
                let lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let b = _mm256_set1_epi32(bits as i32);
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(b, lane), lane))
            }
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { F32x8(_mm256_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            unsafe { F32x8(_mm256_sqrt_ps(self.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { F32x8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn neg(self) -> Self {
            unsafe { F32x8(_mm256_xor_ps(_mm256_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn floor(self) -> Self {
            unsafe { F32x8(_mm256_floor_ps(self.0)) }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0) }
        }
        #[inline(always)]
        fn is_nan(self) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_UNORD_Q>(self.0, self.0) }
        }
        #[inline(always)]
        fn or(a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_or_ps(a, b) }
        }
        #[inline(always)]
        fn not(a: __m256) -> __m256 {
            unsafe { _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) }
        }
        #[inline(always)]
        fn difference_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (lo, hi) = products_pd(a.0, b.0, c.0, d.0);
                let l = _mm256_cvtpd_ps(_mm256_sub_pd(lo.0, lo.1));
                let h = _mm256_cvtpd_ps(_mm256_sub_pd(hi.0, hi.1));
                F32x8(_mm256_set_m128(h, l))
            }
        }
        #[inline(always)]
        fn sum_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (lo, hi) = products_pd(a.0, b.0, c.0, d.0);
                let l = _mm256_cvtpd_ps(_mm256_add_pd(lo.0, lo.1));
                let h = _mm256_cvtpd_ps(_mm256_add_pd(hi.0, hi.1));
                F32x8(_mm256_set_m128(h, l))
            }
        }
        #[inline(always)]
        fn pow2i(n: Self) -> Self {
            unsafe {
                let e = _mm256_add_epi32(_mm256_cvttps_epi32(n.0), _mm256_set1_epi32(127));
                F32x8(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(e)))
            }
        }
        #[inline(always)]
        fn to_u32_bits(self) -> U32x8 {
            unsafe { U32x8(_mm256_castps_si256(self.0)) }
        }
        #[inline(always)]
        fn from_u32_bits(u: U32x8) -> Self {
            unsafe { F32x8(_mm256_castsi256_ps(u.0)) }
        }
        #[inline(always)]
        fn step_bits(self, up: __m256) -> Self {
            unsafe {
                // +1 where up (the mask's lanes are −1: subtract them),
                // −1 elsewhere.
                let b = _mm256_castps_si256(self.0);
                let m = _mm256_castps_si256(up);
                let plus = _mm256_sub_epi32(b, m);
                let minus = _mm256_sub_epi32(b, _mm256_set1_epi32(1));
                F32x8(_mm256_blendv_ps(
                    _mm256_castsi256_ps(minus),
                    _mm256_castsi256_ps(plus),
                    up,
                ))
            }
        }
    }

    /// The exact products `a·b` and `c·d` in `f64`, of the low four lanes
    /// and of the high four.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    unsafe fn products_pd(
        a: __m256,
        b: __m256,
        c: __m256,
        d: __m256,
    ) -> ((__m256d, __m256d), (__m256d, __m256d)) {
        let (al, bl) = (_mm256_castps256_ps128(a), _mm256_castps256_ps128(b));
        let (cl, dl) = (_mm256_castps256_ps128(c), _mm256_castps256_ps128(d));
        let (ah, bh) = (_mm256_extractf128_ps::<1>(a), _mm256_extractf128_ps::<1>(b));
        let (ch, dh) = (_mm256_extractf128_ps::<1>(c), _mm256_extractf128_ps::<1>(d));
        (
            (
                _mm256_mul_pd(_mm256_cvtps_pd(al), _mm256_cvtps_pd(bl)),
                _mm256_mul_pd(_mm256_cvtps_pd(cl), _mm256_cvtps_pd(dl)),
            ),
            (
                _mm256_mul_pd(_mm256_cvtps_pd(ah), _mm256_cvtps_pd(bh)),
                _mm256_mul_pd(_mm256_cvtps_pd(ch), _mm256_cvtps_pd(dh)),
            ),
        )
    }

    impl F32Lanes for F32x4 {
        const N: usize = 4;
        type Mask = __m128;
        type U32 = U32x4;
        type Four = F32x4;
        type Eight = F32x4;
        #[inline(always)]
        fn from_u32(u: U32x4) -> Self {
            // As F32x8's.
            unsafe {
                let hi = _mm_cvtepi32_ps(_mm_srli_epi32::<16>(u.0));
                let lo = _mm_cvtepi32_ps(_mm_and_si128(u.0, _mm_set1_epi32(0xffff)));
                F32x4(_mm_add_ps(_mm_mul_ps(hi, _mm_set1_ps(65536.0)), lo))
            }
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { F32x4(_mm_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..4];
            unsafe { F32x4(_mm_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn store(self, s: &mut [f32]) {
            let s = &mut s[..4];
            unsafe { _mm_storeu_ps(s.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { F32x4(_mm_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { F32x4(_mm_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { F32x4(_mm_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { F32x4(_mm_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { F32x4(_mm_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> __m128 {
            unsafe { _mm_cmplt_ps(self.0, o.0) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> __m128 {
            unsafe { _mm_cmple_ps(self.0, o.0) }
        }
        #[inline(always)]
        fn select(m: __m128, a: Self, b: Self) -> Self {
            unsafe { F32x4(_mm_blendv_ps(b.0, a.0, m)) }
        }
        #[inline(always)]
        fn and(a: __m128, b: __m128) -> __m128 {
            unsafe { _mm_and_ps(a, b) }
        }
        #[inline(always)]
        fn bits(m: __m128) -> u32 {
            unsafe { _mm_movemask_ps(m) as u32 }
        }
        #[inline(always)]
        fn from_bits(bits: u32) -> __m128 {
            unsafe {
                let lane = _mm_setr_epi32(1, 2, 4, 8);
                let b = _mm_set1_epi32(bits as i32);
                _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, lane), lane))
            }
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { F32x4(_mm_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            unsafe { F32x4(_mm_sqrt_ps(self.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { F32x4(_mm_andnot_ps(_mm_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn neg(self) -> Self {
            unsafe { F32x4(_mm_xor_ps(_mm_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn floor(self) -> Self {
            unsafe { F32x4(_mm_floor_ps(self.0)) }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> __m128 {
            unsafe { _mm_cmpeq_ps(self.0, o.0) }
        }
        #[inline(always)]
        fn is_nan(self) -> __m128 {
            unsafe { _mm_cmpunord_ps(self.0, self.0) }
        }
        #[inline(always)]
        fn or(a: __m128, b: __m128) -> __m128 {
            unsafe { _mm_or_ps(a, b) }
        }
        #[inline(always)]
        fn not(a: __m128) -> __m128 {
            unsafe { _mm_xor_ps(a, _mm_castsi128_ps(_mm_set1_epi32(-1))) }
        }
        #[inline(always)]
        fn difference_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (a, b, c, d) = (a.0, b.0, c.0, d.0);
                let l = _mm_sub_pd(
                    _mm_mul_pd(_mm_cvtps_pd(a), _mm_cvtps_pd(b)),
                    _mm_mul_pd(_mm_cvtps_pd(c), _mm_cvtps_pd(d)),
                );
                let (a, b, c, d) = (
                    _mm_movehl_ps(a, a),
                    _mm_movehl_ps(b, b),
                    _mm_movehl_ps(c, c),
                    _mm_movehl_ps(d, d),
                );
                let h = _mm_sub_pd(
                    _mm_mul_pd(_mm_cvtps_pd(a), _mm_cvtps_pd(b)),
                    _mm_mul_pd(_mm_cvtps_pd(c), _mm_cvtps_pd(d)),
                );
                F32x4(_mm_movelh_ps(_mm_cvtpd_ps(l), _mm_cvtpd_ps(h)))
            }
        }
        #[inline(always)]
        fn sum_of_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            unsafe {
                let (a, b, c, d) = (a.0, b.0, c.0, d.0);
                let l = _mm_add_pd(
                    _mm_mul_pd(_mm_cvtps_pd(a), _mm_cvtps_pd(b)),
                    _mm_mul_pd(_mm_cvtps_pd(c), _mm_cvtps_pd(d)),
                );
                let (a, b, c, d) = (
                    _mm_movehl_ps(a, a),
                    _mm_movehl_ps(b, b),
                    _mm_movehl_ps(c, c),
                    _mm_movehl_ps(d, d),
                );
                let h = _mm_add_pd(
                    _mm_mul_pd(_mm_cvtps_pd(a), _mm_cvtps_pd(b)),
                    _mm_mul_pd(_mm_cvtps_pd(c), _mm_cvtps_pd(d)),
                );
                F32x4(_mm_movelh_ps(_mm_cvtpd_ps(l), _mm_cvtpd_ps(h)))
            }
        }
        #[inline(always)]
        fn pow2i(n: Self) -> Self {
            unsafe {
                let e = _mm_add_epi32(_mm_cvttps_epi32(n.0), _mm_set1_epi32(127));
                F32x4(_mm_castsi128_ps(_mm_slli_epi32::<23>(e)))
            }
        }
        #[inline(always)]
        fn to_u32_bits(self) -> U32x4 {
            unsafe { U32x4(_mm_castps_si128(self.0)) }
        }
        #[inline(always)]
        fn from_u32_bits(u: U32x4) -> Self {
            unsafe { F32x4(_mm_castsi128_ps(u.0)) }
        }
        #[inline(always)]
        fn step_bits(self, up: __m128) -> Self {
            unsafe {
                // As F32x8's.
                let b = _mm_castps_si128(self.0);
                let m = _mm_castps_si128(up);
                let plus = _mm_sub_epi32(b, m);
                let minus = _mm_sub_epi32(b, _mm_set1_epi32(1));
                F32x4(_mm_blendv_ps(
                    _mm_castsi128_ps(minus),
                    _mm_castsi128_ps(plus),
                    up,
                ))
            }
        }
    }
}
