//! The PCG32 random number generator (O'Neill), as pbrt-v4 uses it
//! (`util/rng.h`): small state, good statistics, and `advance` for
//! deterministic per-pixel streams.

use rpbrt_geometry::float::{Float, ONE_MINUS_EPSILON};

const PCG32_DEFAULT_STATE: u64 = 0x853c_49e6_748f_ea9b;
const PCG32_DEFAULT_STREAM: u64 = 0xda3e_39cb_94b9_5bdb;
const PCG32_MULT: u64 = 0x5851_f42d_4c95_7f2d;

/// A PCG32 generator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng {
    state: u64,
    inc: u64,
}

impl Default for Rng {
    fn default() -> Self {
        Rng {
            state: PCG32_DEFAULT_STATE,
            inc: PCG32_DEFAULT_STREAM,
        }
    }
}

impl Rng {
    /// A generator on stream `seq_index` starting from `offset`.
    pub fn new(seq_index: u64, offset: u64) -> Self {
        let mut r = Rng { state: 0, inc: 0 };
        r.set_sequence(seq_index, offset);
        r
    }
    /// A generator on stream `seq_index` with pbrt's default offset.
    pub fn with_sequence(seq_index: u64) -> Self {
        Rng::new(seq_index, mix_bits(seq_index))
    }
    /// Restarts on stream `seq_index` from `offset`.
    pub fn set_sequence(&mut self, seq_index: u64, offset: u64) {
        self.state = 0;
        self.inc = (seq_index << 1) | 1;
        self.uniform_u32();
        self.state = self.state.wrapping_add(offset);
        self.uniform_u32();
    }
    /// The generator's whole state (state, increment), to be handed back
    /// to [`Rng::from_raw`].
    #[inline]
    pub(crate) fn raw(&self) -> (u64, u64) {
        (self.state, self.inc)
    }
    /// The generator whose [`Rng::raw`] state was `raw`.
    #[inline]
    pub(crate) fn from_raw(raw: (u64, u64)) -> Self {
        Rng {
            state: raw.0,
            inc: raw.1,
        }
    }
    /// A uniformly distributed 32-bit value.
    #[inline]
    pub fn uniform_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG32_MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
    /// A uniformly distributed 64-bit value.
    #[inline]
    pub fn uniform_u64(&mut self) -> u64 {
        let a = self.uniform_u32() as u64;
        let b = self.uniform_u32() as u64;
        (a << 32) | b
    }
    /// A uniform float in [0, 1).
    #[inline]
    pub fn uniform_float(&mut self) -> Float {
        ((self.uniform_u32() as Float) * f32::from_bits(0x2f80_0000)).min(ONE_MINUS_EPSILON)
    }
    /// A uniform integer in [0, bound).
    pub fn uniform_bounded(&mut self, bound: u32) -> u32 {
        if bound == 0 {
            return 0;
        }
        let threshold = bound.wrapping_neg() % bound;
        loop {
            let r = self.uniform_u32();
            if r >= threshold {
                return r % bound;
            }
        }
    }
    /// Skips ahead (or back, for negative `delta`) by `delta` steps in
    /// O(log n) time.
    pub fn advance(&mut self, idelta: i64) {
        let mut cur_mult = PCG32_MULT;
        let mut cur_plus = self.inc;
        let mut acc_mult: u64 = 1;
        let mut acc_plus: u64 = 0;
        let mut delta = idelta as u64;
        while delta > 0 {
            if delta & 1 != 0 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            delta /= 2;
        }
        self.state = acc_mult.wrapping_mul(self.state).wrapping_add(acc_plus);
    }
}

/// A 64-bit bit mixer (pbrt-v4's `MixBits`).
#[inline]
pub fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_matches_stepping() {
        let mut a = Rng::with_sequence(7);
        let mut b = a.clone();
        for _ in 0..1000 {
            a.uniform_u32();
        }
        b.advance(1000);
        assert_eq!(a.uniform_u32(), b.uniform_u32());
        let mut c = Rng::with_sequence(7);
        let first = c.uniform_u32();
        c.advance(-1);
        assert_eq!(c.uniform_u32(), first);
    }

    #[test]
    fn floats_in_range() {
        let mut r = Rng::new(1, 2);
        let mut sum = 0.0f64;
        for _ in 0..100000 {
            let f = r.uniform_float();
            assert!((0.0..1.0).contains(&f));
            sum += f as f64;
        }
        assert!((sum / 100000.0 - 0.5).abs() < 0.01);
        assert!(r.uniform_bounded(10) < 10);
    }
}
