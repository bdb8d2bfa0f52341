//! Integer lanes: `N` `u32` lanes beside each width's `f32` lanes, for
//! kernels that compute with bits (hashes, scrambles, sequence indices).
//! Every operation is the wrapping `u32` operation the scalar code
//! performs, so a kernel gives the same bits at every width.

/// `N` lanes of `u32` (the same `N` as the [`super::F32Lanes`] type whose
/// `U32` they are).
pub trait U32Lanes: Copy {
    /// The lane count.
    const N: usize;
    /// Every lane `x`.
    fn splat(x: u32) -> Self;
    /// Lanes from the first `N` values of `s`.
    fn load(s: &[u32]) -> Self;
    /// Writes the lanes to the first `N` values of `s`.
    fn store(self, s: &mut [u32]);
    /// Lane-wise `self.wrapping_add(o)`.
    fn add(self, o: Self) -> Self;
    /// Lane-wise `self.wrapping_mul(o)` (the low 32 bits of the product).
    fn mul(self, o: Self) -> Self;
    /// Lane-wise `self ^ o`.
    fn xor(self, o: Self) -> Self;
    /// Lane-wise `self | o`.
    fn or(self, o: Self) -> Self;
    /// Lane-wise `self & o`.
    fn and(self, o: Self) -> Self;
    /// Lane-wise `self >> K` (logical).
    fn shr<const K: i32>(self) -> Self;
    /// Lane-wise `self.reverse_bits()`.
    fn reverse_bits(self) -> Self;
}

/// One `u32` lane: the scalar code itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct U32x1(pub u32);

impl U32Lanes for U32x1 {
    const N: usize = 1;
    #[inline(always)]
    fn splat(x: u32) -> Self {
        U32x1(x)
    }
    #[inline(always)]
    fn load(s: &[u32]) -> Self {
        U32x1(s[0])
    }
    #[inline(always)]
    fn store(self, s: &mut [u32]) {
        s[0] = self.0;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        U32x1(self.0.wrapping_add(o.0))
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        U32x1(self.0.wrapping_mul(o.0))
    }
    #[inline(always)]
    fn xor(self, o: Self) -> Self {
        U32x1(self.0 ^ o.0)
    }
    #[inline(always)]
    fn or(self, o: Self) -> Self {
        U32x1(self.0 | o.0)
    }
    #[inline(always)]
    fn and(self, o: Self) -> Self {
        U32x1(self.0 & o.0)
    }
    #[inline(always)]
    fn shr<const K: i32>(self) -> Self {
        U32x1(self.0 >> K)
    }
    #[inline(always)]
    fn reverse_bits(self) -> Self {
        U32x1(self.0.reverse_bits())
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{U32x16, U32x4, U32x8};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::U32Lanes;
    use std::arch::x86_64::*;

    /// Eight `u32` lanes in an AVX register (AVX2 and AVX-512 kernels).
    #[derive(Clone, Copy, Debug)]
    pub struct U32x8(pub(in crate::simd) __m256i);

    /// Sixteen `u32` lanes in an AVX-512 register (AVX-512 kernels only).
    #[derive(Clone, Copy, Debug)]
    pub struct U32x16(pub(in crate::simd) __m512i);

    /// Four `u32` lanes in an SSE register (SSE4.1, AVX2 and AVX-512
    /// kernels).
    #[derive(Clone, Copy, Debug)]
    pub struct U32x4(pub(in crate::simd) __m128i);

    /// The bits of each nibble value reversed (`0b0001` → `0b1000`), and
    /// the same shifted into the byte's high nibble: the two tables a
    /// byte-shuffle bit reversal looks up, repeated per 128-bit half.
    const REV_NIBBLE: [i8; 16] = [0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15];
    const REV_NIBBLE_HIGH: [i8; 16] = [
        0,
        0x80u8 as i8,
        0x40,
        0xc0u8 as i8,
        0x20,
        0xa0u8 as i8,
        0x60,
        0xe0u8 as i8,
        0x10,
        0x90u8 as i8,
        0x50,
        0xd0u8 as i8,
        0x30,
        0xb0u8 as i8,
        0x70,
        0xf0u8 as i8,
    ];
    /// Reverses the bytes of each 32-bit lane.
    const BYTE_SWAP: [i8; 16] = [3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12];

    #[inline(always)]
    unsafe fn table128(t: &[i8; 16]) -> __m128i {
        _mm_loadu_si128(t.as_ptr() as *const __m128i)
    }

    // SAFETY (every `unsafe` block below): these types are only used by
    // kernels that `dispatch` runs after checking that the processor has
    // the instructions (AVX-512 F and BW for U32x16, AVX2 for U32x8,
    // SSE4.1 for U32x4); slices are length-checked before unaligned loads
    // and stores.
    impl U32Lanes for U32x16 {
        const N: usize = 16;
        #[inline(always)]
        fn splat(x: u32) -> Self {
            unsafe { U32x16(_mm512_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        fn load(s: &[u32]) -> Self {
            let s = &s[..16];
            unsafe { U32x16(_mm512_loadu_epi32(s.as_ptr() as *const i32)) }
        }
        #[inline(always)]
        fn store(self, s: &mut [u32]) {
            let s = &mut s[..16];
            unsafe { _mm512_storeu_epi32(s.as_mut_ptr() as *mut i32, self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { U32x16(_mm512_add_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { U32x16(_mm512_mullo_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn xor(self, o: Self) -> Self {
            unsafe { U32x16(_mm512_xor_si512(self.0, o.0)) }
        }
        #[inline(always)]
        fn or(self, o: Self) -> Self {
            unsafe { U32x16(_mm512_or_si512(self.0, o.0)) }
        }
        #[inline(always)]
        fn and(self, o: Self) -> Self {
            unsafe { U32x16(_mm512_and_si512(self.0, o.0)) }
        }
        #[inline(always)]
        fn shr<const K: i32>(self) -> Self {
            // The shift count in a register (the immediate form takes a
            // `u32` constant); folded to the immediate form when inlined.
            unsafe { U32x16(_mm512_srl_epi32(self.0, _mm_cvtsi32_si128(K))) }
        }
        #[inline(always)]
        fn reverse_bits(self) -> Self {
            // As U32x8's, the tables repeated in each 128-bit quarter.
            unsafe {
                let swap = _mm512_broadcast_i32x4(table128(&BYTE_SWAP));
                let rev = _mm512_broadcast_i32x4(table128(&REV_NIBBLE));
                let rev_high = _mm512_broadcast_i32x4(table128(&REV_NIBBLE_HIGH));
                let v = _mm512_shuffle_epi8(self.0, swap);
                let low = _mm512_set1_epi8(0x0f);
                let lo = _mm512_and_si512(v, low);
                let hi = _mm512_and_si512(_mm512_srli_epi16::<4>(v), low);
                U32x16(_mm512_or_si512(
                    _mm512_shuffle_epi8(rev_high, lo),
                    _mm512_shuffle_epi8(rev, hi),
                ))
            }
        }
    }

    impl U32Lanes for U32x8 {
        const N: usize = 8;
        #[inline(always)]
        fn splat(x: u32) -> Self {
            unsafe { U32x8(_mm256_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        fn load(s: &[u32]) -> Self {
            let s = &s[..8];
            unsafe { U32x8(_mm256_loadu_si256(s.as_ptr() as *const __m256i)) }
        }
        #[inline(always)]
        fn store(self, s: &mut [u32]) {
            let s = &mut s[..8];
            unsafe { _mm256_storeu_si256(s.as_mut_ptr() as *mut __m256i, self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { U32x8(_mm256_add_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { U32x8(_mm256_mullo_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn xor(self, o: Self) -> Self {
            unsafe { U32x8(_mm256_xor_si256(self.0, o.0)) }
        }
        #[inline(always)]
        fn or(self, o: Self) -> Self {
            unsafe { U32x8(_mm256_or_si256(self.0, o.0)) }
        }
        #[inline(always)]
        fn and(self, o: Self) -> Self {
            unsafe { U32x8(_mm256_and_si256(self.0, o.0)) }
        }
        #[inline(always)]
        fn shr<const K: i32>(self) -> Self {
            unsafe { U32x8(_mm256_srli_epi32::<K>(self.0)) }
        }
        #[inline(always)]
        fn reverse_bits(self) -> Self {
            unsafe {
                let both = |t: &[i8; 16]| {
                    let h = table128(t);
                    _mm256_set_m128i(h, h)
                };
                let v = _mm256_shuffle_epi8(self.0, both(&BYTE_SWAP));
                let low = _mm256_set1_epi8(0x0f);
                let lo = _mm256_and_si256(v, low);
                let hi = _mm256_and_si256(_mm256_srli_epi16::<4>(v), low);
                U32x8(_mm256_or_si256(
                    _mm256_shuffle_epi8(both(&REV_NIBBLE_HIGH), lo),
                    _mm256_shuffle_epi8(both(&REV_NIBBLE), hi),
                ))
            }
        }
    }

    impl U32Lanes for U32x4 {
        const N: usize = 4;
        #[inline(always)]
        fn splat(x: u32) -> Self {
            unsafe { U32x4(_mm_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        fn load(s: &[u32]) -> Self {
            let s = &s[..4];
            unsafe { U32x4(_mm_loadu_si128(s.as_ptr() as *const __m128i)) }
        }
        #[inline(always)]
        fn store(self, s: &mut [u32]) {
            let s = &mut s[..4];
            unsafe { _mm_storeu_si128(s.as_mut_ptr() as *mut __m128i, self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { U32x4(_mm_add_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { U32x4(_mm_mullo_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn xor(self, o: Self) -> Self {
            unsafe { U32x4(_mm_xor_si128(self.0, o.0)) }
        }
        #[inline(always)]
        fn or(self, o: Self) -> Self {
            unsafe { U32x4(_mm_or_si128(self.0, o.0)) }
        }
        #[inline(always)]
        fn and(self, o: Self) -> Self {
            unsafe { U32x4(_mm_and_si128(self.0, o.0)) }
        }
        #[inline(always)]
        fn shr<const K: i32>(self) -> Self {
            unsafe { U32x4(_mm_srli_epi32::<K>(self.0)) }
        }
        #[inline(always)]
        fn reverse_bits(self) -> Self {
            unsafe {
                let v = _mm_shuffle_epi8(self.0, table128(&BYTE_SWAP));
                let low = _mm_set1_epi8(0x0f);
                let lo = _mm_and_si128(v, low);
                let hi = _mm_and_si128(_mm_srli_epi16::<4>(v), low);
                U32x4(_mm_or_si128(
                    _mm_shuffle_epi8(table128(&REV_NIBBLE_HIGH), lo),
                    _mm_shuffle_epi8(table128(&REV_NIBBLE), hi),
                ))
            }
        }
    }
}
