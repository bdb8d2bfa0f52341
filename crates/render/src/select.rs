//! Branch-free selection between floats.
//!
//! x86-64 has no conditional move between float registers, so LLVM turns
//! `if c { a } else { b }` on floats, `std::hint::select_unpredictable`
//! included, into a branch (and folds integer bit-mask tricks back into
//! one). Where `c` is a coin flip (which wedge of the concentric disk
//! mapping, which child of the light BVH) that branch mispredicts half
//! the time. [`select_f32`] masks in an SSE register instead, which LLVM
//! keeps as masks.

/// `if c { a } else { b }`, without a branch on x86-64.
#[inline(always)]
pub fn select_f32(c: bool, a: f32, b: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE and SSE2 instructions, which every x86-64 CPU has
        // (they are part of the target's baseline); no memory is accessed.
        unsafe {
            let m = _mm_castsi128_ps(_mm_set1_epi32(-(c as i32)));
            _mm_cvtss_f32(_mm_or_ps(
                _mm_and_ps(m, _mm_set_ss(a)),
                _mm_andnot_ps(m, _mm_set_ss(b)),
            ))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        if c {
            a
        } else {
            b
        }
    }
}

#[cfg(test)]
mod tests {
    use super::select_f32;

    #[test]
    fn selects_exact_bits() {
        let values = [
            0.0f32,
            -0.0,
            1.5,
            -3.25,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE / 4.0,
            f32::MAX,
            f32::from_bits(0x7fc0_1234),
        ];
        for &a in &values {
            for &b in &values {
                assert_eq!(select_f32(true, a, b).to_bits(), a.to_bits());
                assert_eq!(select_f32(false, a, b).to_bits(), b.to_bits());
            }
        }
    }
}
