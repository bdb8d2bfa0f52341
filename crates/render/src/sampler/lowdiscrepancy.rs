//! Low-discrepancy building blocks (book sections 8.6–8.7; pbrt-v4
//! `util/lowdiscrepancy.h`, `util/primes.h`, `util/hash.h`, the
//! permutation function of `util/math.h`): primes, radical inverses with
//! digit permutations and Owen scrambling, Sobol' generator matrices from
//! Joe–Kuo direction numbers, binary scramblers, hashing.

use std::sync::OnceLock;

use crate::simd::{dispatch, F32Lanes, Kernel, SimdLevel, U32Lanes};
use rpbrt_geometry::float::{Float, ONE_MINUS_EPSILON};
use rpbrt_geometry::tuple::Point2i;

pub use crate::rng::mix_bits;

use super::data::joe_kuo::{JOE_KUO_D6, MAX_DEGREE};

/// Number of tabulated primes (pbrt-v4's `PrimeTableSize`): Halton
/// dimensions available before wrapping.
pub const PRIME_TABLE_SIZE: usize = 1000;

const fn compute_primes() -> [u32; PRIME_TABLE_SIZE] {
    let mut out = [0u32; PRIME_TABLE_SIZE];
    let mut n = 0;
    let mut candidate = 2u32;
    while n < PRIME_TABLE_SIZE {
        let mut is_prime = true;
        let mut d = 2u32;
        while d * d <= candidate {
            if candidate % d == 0 {
                is_prime = false;
                break;
            }
            d += 1;
        }
        if is_prime {
            out[n] = candidate;
            n += 1;
        }
        candidate += 1;
    }
    out
}

/// The first [`PRIME_TABLE_SIZE`] primes (2, 3, 5, ..., 7919).
pub static PRIMES: [u32; PRIME_TABLE_SIZE] = compute_primes();

/// `⌈2^64 / p⌉` for every prime `p` of [`PRIMES`]: the high 64 bits of its
/// product with an integer below 2^32 are that integer divided by `p`,
/// exactly (Lemire, Kaser and Kurz 2019, "Faster remainder by direct
/// computation"), for a fraction of a division's cost.
static DIV_MAGIC: [u64; PRIME_TABLE_SIZE] = {
    let primes = compute_primes();
    let mut out = [0u64; PRIME_TABLE_SIZE];
    let mut i = 0;
    while i < PRIME_TABLE_SIZE {
        out[i] = u64::MAX / primes[i] as u64 + 1;
        i += 1;
    }
    out
};

/// Exact division by one prime of the table.
trait DivideByPrime: Copy {
    fn base(self) -> u64;
    fn div(self, x: u64) -> u64;
}

/// By multiplication with [`DIV_MAGIC`]: only for dividends below 2^32.
#[derive(Clone, Copy)]
struct MagicDivision(u64, u64);

impl DivideByPrime for MagicDivision {
    #[inline(always)]
    fn base(self) -> u64 {
        self.0
    }
    #[inline(always)]
    fn div(self, x: u64) -> u64 {
        ((self.1 as u128 * x as u128) >> 64) as u64
    }
}

/// By the division instruction.
#[derive(Clone, Copy)]
struct PlainDivision(u64);

impl DivideByPrime for PlainDivision {
    #[inline(always)]
    fn base(self) -> u64 {
        self.0
    }
    #[inline(always)]
    fn div(self, x: u64) -> u64 {
        x / self.0
    }
}

/// Calls `$f` with the fastest exact division of `$a` (and of its
/// quotients, which are smaller) by `PRIMES[$base_index]`.
macro_rules! with_division {
    ($base_index:expr, $a:expr, $f:expr) => {{
        let (base_index, a) = ($base_index, $a);
        let base = PRIMES[base_index] as u64;
        if a <= u32::MAX as u64 {
            $f(MagicDivision(base, DIV_MAGIC[base_index]), a)
        } else {
            $f(PlainDivision(base), a)
        }
    }};
}

/// Number of Sobol' dimensions (pbrt-v4's `NSobolDimensions`).
pub const N_SOBOL_DIMENSIONS: usize = 1024;
/// Columns per Sobol' generator matrix (pbrt-v4's `SobolMatrixSize`):
/// sample indices below 2^52.
pub const SOBOL_MATRIX_SIZE: usize = 52;

/// The 32-bit Sobol' generator matrices, `SOBOL_MATRIX_SIZE` columns per
/// dimension; dimension 0 is van der Corput, dimensions 1.. follow the
/// Joe–Kuo direction numbers. Computed once on first use.
pub fn sobol_matrices() -> &'static [u32] {
    static M: OnceLock<Vec<u32>> = OnceLock::new();
    M.get_or_init(build_sobol_matrices)
}

/// For dimensions 0 and 1: the XOR of the matrix columns selected by each
/// possible value of each byte of the (52-bit) index.
fn sobol_byte_tables() -> &'static [[[u32; 256]; 7]; 2] {
    static T: OnceLock<Box<[[[u32; 256]; 7]; 2]>> = OnceLock::new();
    T.get_or_init(|| {
        let m = sobol_matrices();
        let mut t = Box::new([[[0u32; 256]; 7]; 2]);
        for (dim, tables) in t.iter_mut().enumerate() {
            for (byte, table) in tables.iter_mut().enumerate() {
                for (value, out) in table.iter_mut().enumerate() {
                    let mut v = 0u32;
                    for bit in 0..8 {
                        if value & (1 << bit) != 0 && byte * 8 + bit < SOBOL_MATRIX_SIZE {
                            v ^= m[dim * SOBOL_MATRIX_SIZE + byte * 8 + bit];
                        }
                    }
                    *out = v;
                }
            }
        }
        t
    })
}

fn build_sobol_matrices() -> Vec<u32> {
    let mut out = vec![0u32; N_SOBOL_DIMENSIONS * SOBOL_MATRIX_SIZE];
    let mut m = [0u64; SOBOL_MATRIX_SIZE];
    for dim in 0..N_SOBOL_DIMENSIONS {
        if dim == 0 {
            m = [1; SOBOL_MATRIX_SIZE];
        } else {
            let (s, a, init) = JOE_KUO_D6[dim - 1];
            let s = s as usize;
            debug_assert!(s <= MAX_DEGREE);
            for k in 0..s {
                m[k] = init[k] as u64;
            }
            // m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}
            for k in s..SOBOL_MATRIX_SIZE {
                let mut v = m[k - s] ^ (m[k - s] << s);
                for j in 1..s {
                    if (a >> (s - 1 - j)) & 1 != 0 {
                        v ^= m[k - j] << j;
                    }
                }
                m[k] = v;
            }
        }
        // Column k is m_k / 2^(k+1), kept to 32 fractional bits.
        for (k, &mk) in m.iter().enumerate() {
            let c = if k <= 31 {
                mk << (31 - k)
            } else {
                mk >> (k - 31)
            };
            out[dim * SOBOL_MATRIX_SIZE + k] = c as u32;
        }
    }
    out
}

/// How a low-discrepancy sequence is randomised (pbrt-v4's
/// `RandomizeStrategy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RandomizeStrategy {
    /// No randomisation.
    None,
    /// Random digit permutations (binary XOR for Sobol').
    PermuteDigits,
    /// Hash-based Owen scrambling (Laine–Karras style; Sobol' only).
    FastOwen,
    /// Full Owen scrambling.
    Owen,
}

impl RandomizeStrategy {
    /// pbrt's scene-file name for the strategy.
    pub fn name(self) -> &'static str {
        match self {
            RandomizeStrategy::None => "none",
            RandomizeStrategy::PermuteDigits => "permutedigits",
            RandomizeStrategy::FastOwen => "fastowen",
            RandomizeStrategy::Owen => "owen",
        }
    }
}

/// Element `i` of a pseudo-random permutation of `0..n` chosen by `seed`
/// (Kensler's cycle-walking hash, pbrt-v4's `PermutationElement`).
#[inline]
pub fn permutation_element(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(n > 0 && i < n);
    let p = seed;
    let mut w = n.wrapping_sub(1);
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | (p >> 27));
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    (i.wrapping_add(p)) % n
}

/// MurmurHash64A of a byte string (Austin Appleby's 64-bit Murmur2).
pub fn murmur_hash64a(key: &[u8], seed: u64) -> u64 {
    const M: u64 = 0xc6a4_a793_5bd1_e995;
    const R: u32 = 47;
    let mut h = seed ^ (key.len() as u64).wrapping_mul(M);
    let mut chunks = key.chunks_exact(8);
    for c in &mut chunks {
        let mut k = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        k = k.wrapping_mul(M);
        k ^= k >> R;
        k = k.wrapping_mul(M);
        h ^= k;
        h = h.wrapping_mul(M);
    }
    let rest = chunks.remainder();
    if !rest.is_empty() {
        for (i, &b) in rest.iter().enumerate() {
            h ^= (b as u64) << (8 * i);
        }
        h = h.wrapping_mul(M);
    }
    h ^= h >> R;
    h = h.wrapping_mul(M);
    h ^= h >> R;
    h
}

/// Values whose little-endian byte representation is hashed by
/// [`hash_values`] (pbrt-v4's variadic `Hash(...)`).
pub trait HashBytes {
    /// Appends the value's bytes.
    fn put(&self, out: &mut Vec<u8>);
}

macro_rules! hash_bytes_int {
    ($($t:ty),*) => {$(
        impl HashBytes for $t {
            #[inline]
            fn put(&self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}
hash_bytes_int!(i32, u32, i64, u64, f32);

impl HashBytes for Point2i {
    #[inline]
    fn put(&self, out: &mut Vec<u8>) {
        self.x.put(out);
        self.y.put(out);
    }
}

/// A 64-bit hash of the concatenated byte representations of `values`
/// (MurmurHash64A with seed 0, as pbrt-v4's `Hash`).
pub fn hash_values(values: &[&dyn HashBytes]) -> u64 {
    let mut buf = Vec::with_capacity(32);
    for v in values {
        v.put(&mut buf);
    }
    murmur_hash64a(&buf, 0)
}

/// Random permutations of the digits of every prime base, one per digit
/// position (pbrt-v4's `DigitPermutation`).
#[derive(Clone, Debug)]
pub struct DigitPermutation {
    base: u32,
    n_digits: usize,
    /// `1/base` to the power `n_digits`, as the digit loop computes it.
    inv_base_n: Float,
    permutations: Vec<u16>,
}

impl DigitPermutation {
    /// Permutations for `base` (< 65536) chosen by `seed`.
    pub fn new(base: u32, seed: u32) -> Self {
        debug_assert!(base >= 2 && base < 65536);
        let (n_digits, inv_base_n) = digits_for_base(base);
        let mut permutations = Vec::with_capacity(n_digits * base as usize);
        for digit_index in 0..n_digits {
            let dseed = hash_values(&[&(base as i32), &(digit_index as i32), &seed]);
            for digit_value in 0..base {
                permutations.push(permutation_element(digit_value, base, dseed as u32) as u16);
            }
        }
        DigitPermutation {
            base,
            n_digits,
            inv_base_n,
            permutations,
        }
    }

    /// The permuted value of `digit_value` at position `digit_index`.
    #[inline]
    pub fn permute(&self, digit_index: usize, digit_value: u32) -> u32 {
        debug_assert!(digit_index < self.n_digits && digit_value < self.base);
        self.permutations[digit_index * self.base as usize + digit_value as usize] as u32
    }
}

/// Number of base-`base` digits that matter at `Float` precision (the
/// iterations of pbrt-v4's `ScrambledRadicalInverse` loop), and `1/base`
/// to that power as that loop computes it.
fn digits_for_base(base: u32) -> (usize, Float) {
    let inv_base = 1.0 / base as Float;
    let mut inv_base_m: Float = 1.0;
    let mut n = 0;
    while 1.0 - (base - 1) as Float * inv_base_m < 1.0 {
        n += 1;
        inv_base_m *= inv_base;
    }
    (n, inv_base_m)
}

/// Digit permutations for every prime base of the table (pbrt-v4's
/// `ComputeRadicalInversePermutations`).
pub fn compute_radical_inverse_permutations(seed: u32) -> Vec<DigitPermutation> {
    // About 3.7 million table entries: built in parallel (each base's
    // table depends on the base and seed alone, so the result is the same).
    use rayon::prelude::*;
    PRIMES
        .par_iter()
        .map(|&b| DigitPermutation::new(b, seed))
        .collect()
}

/// The radical inverse of `a` in the base `PRIMES[base_index]`.
#[inline]
pub fn radical_inverse(base_index: usize, a: u64) -> Float {
    with_division!(base_index, a, radical_inverse_by)
}

#[inline(always)]
fn radical_inverse_by(d: impl DivideByPrime, mut a: u64) -> Float {
    let base = d.base();
    let inv_base = 1.0 / base as Float;
    let mut inv_base_n: Float = 1.0;
    let mut reversed: u64 = 0;
    while a != 0 {
        let next = d.div(a);
        let digit = a - next * base;
        reversed = reversed * base + digit;
        inv_base_n *= inv_base;
        a = next;
    }
    (reversed as Float * inv_base_n).min(ONE_MINUS_EPSILON)
}

/// The index whose first `n_digits` base-`base` digits, reversed, give
/// `inverse` (pbrt-v4's `InverseRadicalInverse`).
#[inline]
pub fn inverse_radical_inverse(mut inverse: u64, base: u64, n_digits: u32) -> u64 {
    let mut index = 0;
    for _ in 0..n_digits {
        let digit = inverse % base;
        inverse /= base;
        index = index * base + digit;
    }
    index
}

/// The radical inverse with each digit position's digits permuted:
/// pbrt-v4's loop, with what it recomputes on every call taken from `perm`:
/// the number of digits and the final power of `1/base` (the loop's own
/// floating-point condition and product, computed once); and, for indices
/// that fit in 32 bits, the division by the base as a multiplication
/// (`DIV_MAGIC`).
/// Every step is exact, so the values are pbrt-v4's.
#[inline]
pub fn scrambled_radical_inverse(base_index: usize, a: u64, perm: &DigitPermutation) -> Float {
    debug_assert_eq!(perm.base, PRIMES[base_index]);
    let reversed = with_division!(base_index, a, |d, a| scrambled_digits(d, a, perm));
    (perm.inv_base_n * reversed as Float).min(ONE_MINUS_EPSILON)
}

/// [`scrambled_radical_inverse`] of one index `a` (below 2^32) in the `N`
/// consecutive bases from `PRIMES[first]` (`first + N` at most
/// [`PRIME_TABLE_SIZE`]), each with its permutation from `perms` (indexed
/// by base index), computed together: the `N` digit loops are
/// interleaved, so that their chains of dependent multiplications overlap
/// in the processor instead of running one after another (a path vertex
/// draws six dimensions at once). The same operations as `N` single
/// calls, so the same values.
#[inline]
pub fn scrambled_radical_inverses<const N: usize>(
    first: usize,
    a: u64,
    perms: &[DigitPermutation],
) -> [Float; N] {
    debug_assert!(a <= u32::MAX as u64 && first + N <= PRIME_TABLE_SIZE);
    let perm: [&DigitPermutation; N] = std::array::from_fn(|j| &perms[first + j]);
    let base: [u64; N] = std::array::from_fn(|j| perm[j].base as u64);
    let magic: [u64; N] = std::array::from_fn(|j| DIV_MAGIC[first + j]);
    let n_max = perm.iter().map(|p| p.n_digits).max().unwrap_or(0);
    let mut a = [a; N];
    let mut reversed = [0u64; N];
    for i in 0..n_max {
        for j in 0..N {
            if i < perm[j].n_digits {
                let next = MagicDivision(base[j], magic[j]).div(a[j]);
                let digit = (a[j] - next * base[j]) as usize;
                let row = i * base[j] as usize;
                reversed[j] = reversed[j] * base[j] + perm[j].permutations[row + digit] as u64;
                a[j] = next;
            }
        }
    }
    std::array::from_fn(|j| (perm[j].inv_base_n * reversed[j] as Float).min(ONE_MINUS_EPSILON))
}

/// The permuted digits of `a`, reversed, as an integer.
#[inline(always)]
fn scrambled_digits(d: impl DivideByPrime, mut a: u64, perm: &DigitPermutation) -> u64 {
    let base = d.base();
    let mut reversed: u64 = 0;
    for row in perm.permutations.chunks_exact(perm.base as usize) {
        let next = d.div(a);
        let digit = (a - next * base) as usize;
        reversed = reversed * base + row[digit] as u64;
        a = next;
    }
    reversed
}

/// pbrt-v4's `ScrambledRadicalInverse` as written there: the reference
/// [`scrambled_radical_inverse`] is tested against.
#[cfg(test)]
pub(crate) fn scrambled_radical_inverse_reference(
    base_index: usize,
    mut a: u64,
    perm: &DigitPermutation,
) -> Float {
    let base = PRIMES[base_index] as u64;
    let inv_base = 1.0 / base as Float;
    let mut inv_base_m: Float = 1.0;
    let mut reversed: u64 = 0;
    let mut digit_index = 0;
    while 1.0 - (base - 1) as Float * inv_base_m < 1.0 {
        let next = a / base;
        let digit = (a - next * base) as u32;
        reversed = reversed * base + perm.permute(digit_index, digit) as u64;
        inv_base_m *= inv_base;
        digit_index += 1;
        a = next;
    }
    (inv_base_m * reversed as Float).min(ONE_MINUS_EPSILON)
}

/// The radical inverse with Owen scrambling: each digit is permuted by a
/// permutation chosen from the hash of the digits before it.
#[inline]
pub fn owen_scrambled_radical_inverse(base_index: usize, mut a: u64, hash: u32) -> Float {
    let base = PRIMES[base_index] as u64;
    let inv_base = 1.0 / base as Float;
    let mut inv_base_m: Float = 1.0;
    let mut reversed: u64 = 0;
    while 1.0 - inv_base_m < 1.0 {
        let next = a / base;
        let digit = (a - next * base) as u32;
        let digit_hash = mix_bits(hash as u64 ^ reversed) as u32;
        let digit = permutation_element(digit, base as u32, digit_hash);
        reversed = reversed * base + digit as u64;
        inv_base_m *= inv_base;
        a = next;
    }
    (inv_base_m * reversed as Float).min(ONE_MINUS_EPSILON)
}

/// A bijection on 32-bit Sobol' sample values that keeps their
/// stratification (pbrt-v4's randomizer functors).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryScrambler {
    /// Identity.
    None,
    /// XOR with a random bit pattern.
    Permute(u32),
    /// Laine–Karras-style hash approximating Owen scrambling.
    FastOwen(u32),
    /// Owen scrambling: each bit flipped by a hash of the bits above it.
    Owen(u32),
}

impl BinaryScrambler {
    /// The scrambler for `strategy` seeded with `seed`.
    #[inline]
    pub fn new(strategy: RandomizeStrategy, seed: u32) -> Self {
        match strategy {
            RandomizeStrategy::None => BinaryScrambler::None,
            RandomizeStrategy::PermuteDigits => BinaryScrambler::Permute(seed),
            RandomizeStrategy::FastOwen => BinaryScrambler::FastOwen(seed),
            RandomizeStrategy::Owen => BinaryScrambler::Owen(seed),
        }
    }

    /// Scrambles `v` (bit 31 is the most significant fraction bit).
    #[inline]
    pub fn apply(self, v: u32) -> u32 {
        match self {
            BinaryScrambler::None => v,
            BinaryScrambler::Permute(p) => v ^ p,
            BinaryScrambler::FastOwen(seed) => fast_owen_reversed(v.reverse_bits(), seed),
            BinaryScrambler::Owen(seed) => {
                let mut v = v;
                if seed & 1 != 0 {
                    v ^= 1 << 31;
                }
                for b in 1..32 {
                    let mask = (!0u32) << (32 - b);
                    if (mix_bits(((v & mask) ^ seed) as u64) as u32) & (1u32 << b) != 0 {
                        v ^= 1 << (31 - b);
                    }
                }
                v
            }
        }
    }
}

/// The Sobol' sample of index `a` in `dimension`, scrambled, as a float
/// in [0,1).
#[inline(always)]
pub fn sobol_sample(a: u64, dimension: usize, scrambler: BinaryScrambler) -> Float {
    debug_assert!(dimension < N_SOBOL_DIMENSIONS && a < (1u64 << SOBOL_MATRIX_SIZE));
    let v = if dimension < 2 {
        // The first two dimensions are used for every camera sample and by
        // the Z-Sobol sampler for everything: look them up a byte at a time.
        let t = &sobol_byte_tables()[dimension];
        let mut v = t[0][(a & 0xff) as usize]
            ^ t[1][((a >> 8) & 0xff) as usize]
            ^ t[2][((a >> 16) & 0xff) as usize]
            ^ t[3][((a >> 24) & 0xff) as usize];
        if a >> 32 != 0 {
            v ^= t[4][((a >> 32) & 0xff) as usize]
                ^ t[5][((a >> 40) & 0xff) as usize]
                ^ t[6][((a >> 48) & 0xff) as usize];
        }
        v
    } else {
        let m =
            &sobol_matrices()[dimension * SOBOL_MATRIX_SIZE..(dimension + 1) * SOBOL_MATRIX_SIZE];
        // One XOR per set bit of the index, found with trailing-zero
        // counts (no branch on each bit, whose values are random).
        let mut v = 0u32;
        let mut a = a;
        while a != 0 {
            v ^= m.get(a.trailing_zeros() as usize).copied().unwrap_or(0);
            a &= a - 1;
        }
        v
    };
    let v = scrambler.apply(v);
    (v as Float * f32::from_bits(0x2f80_0000)).min(ONE_MINUS_EPSILON)
}

/// [`sobol_byte_tables`] with every entry bit-reversed.
fn sobol_reversed_byte_tables() -> &'static [[[u32; 256]; 7]; 2] {
    static T: OnceLock<Box<[[[u32; 256]; 7]; 2]>> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = Box::new(*sobol_byte_tables());
        for v in t.iter_mut().flatten().flatten() {
            *v = v.reverse_bits();
        }
        t
    })
}

/// `sobol_sample(a, dimension, BinaryScrambler::FastOwen(seed))` for
/// dimension 0 or 1, bit for bit: bit reversal commutes with XOR, so the
/// generator columns are looked up already reversed, saving the first
/// reversal of the fast Owen scramble.
#[inline(always)]
pub fn sobol_sample_fast_owen_01(a: u64, dimension: usize, seed: u32) -> Float {
    fast_owen_01(sobol_reversed_01(a, dimension), seed)
}

/// The Sobol' value of index `a` in dimension 0 or 1, bit-reversed: what
/// [`sobol_sample_fast_owen_01`] scrambles.
#[inline(always)]
pub(crate) fn sobol_reversed_01(a: u64, dimension: usize) -> u32 {
    debug_assert!(dimension < 2 && a < (1u64 << SOBOL_MATRIX_SIZE));
    if dimension == 0 {
        // Sobol' dimension 0 is the van der Corput sequence: its generator
        // matrix reverses the low 32 bits of the index (and ignores the
        // rest), so its bit-reversed value is the index itself.
        return a as u32;
    }
    let t = &sobol_reversed_byte_tables()[1];
    let mut v = t[0][(a & 0xff) as usize]
        ^ t[1][((a >> 8) & 0xff) as usize]
        ^ t[2][((a >> 16) & 0xff) as usize]
        ^ t[3][((a >> 24) & 0xff) as usize];
    if a >> 32 != 0 {
        v ^= t[4][((a >> 32) & 0xff) as usize]
            ^ t[5][((a >> 40) & 0xff) as usize]
            ^ t[6][((a >> 48) & 0xff) as usize];
    }
    v
}

/// [`fast_owen_01`] of each `(v_reversed, seed)` pair, lane-parallel at
/// `level`, into `out` (as long as the inputs): the same bits at every
/// level.
pub(crate) fn fast_owen_01_batch(level: SimdLevel, v: &[u32], seeds: &[u32], out: &mut [Float]) {
    dispatch(level, FastOwenBatch { v, seeds, out });
}

/// [`fast_owen_01_batch`]'s kernel.
struct FastOwenBatch<'a> {
    v: &'a [u32],
    seeds: &'a [u32],
    out: &'a mut [Float],
}

impl Kernel for FastOwenBatch<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let n = self.v.len().min(self.seeds.len()).min(self.out.len());
        let mut i = 0;
        while i + L::N <= n {
            let (v, seed) = (L::U32::load(&self.v[i..]), L::U32::load(&self.seeds[i..]));
            fast_owen_01_lanes::<L>(v, seed).store(&mut self.out[i..]);
            i += L::N;
        }
        for j in i..n {
            self.out[j] = fast_owen_01(self.v[j], self.seeds[j]);
        }
    }
}

/// [`fast_owen_01`] in lanes: the same operations, lane by lane.
#[inline(always)]
fn fast_owen_01_lanes<L: F32Lanes>(v: L::U32, seed: L::U32) -> L {
    let c = <L::U32 as U32Lanes>::splat;
    let mut v = v.xor(v.mul(c(0x3d20_adea)));
    v = v.add(seed);
    v = v.mul(seed.shr::<16>().or(c(1)));
    v = v.xor(v.mul(c(0x0552_6c56)));
    v = v.xor(v.mul(c(0x53a2_2864)));
    L::from_u32(v.reverse_bits())
        .mul(L::splat(f32::from_bits(0x2f80_0000)))
        .min(L::splat(ONE_MINUS_EPSILON))
}

/// The fast Owen scramble of `v_reversed.reverse_bits()` as a float in
/// [0, 1).
#[inline(always)]
pub(crate) fn fast_owen_01(v_reversed: u32, seed: u32) -> Float {
    let v = fast_owen_reversed(v_reversed, seed);
    (v as Float * f32::from_bits(0x2f80_0000)).min(ONE_MINUS_EPSILON)
}

/// The fast Owen scramble of `v.reverse_bits()`, given the reversed value.
#[inline(always)]
fn fast_owen_reversed(mut v: u32, seed: u32) -> u32 {
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// Interleaves the low 32 bits of `x` with zeros.
#[inline]
pub fn left_shift2(x: u64) -> u64 {
    let mut x = x & 0xffff_ffff;
    x = (x ^ (x << 16)) & 0x0000_ffff_0000_ffff;
    x = (x ^ (x << 8)) & 0x00ff_00ff_00ff_00ff;
    x = (x ^ (x << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
    x = (x ^ (x << 2)) & 0x3333_3333_3333_3333;
    x = (x ^ (x << 1)) & 0x5555_5555_5555_5555;
    x
}

/// The 2-D Morton code of (x, y): x in the even bits, y in the odd ones.
#[inline]
pub fn encode_morton2(x: u32, y: u32) -> u64 {
    (left_shift2(y as u64) << 1) | left_shift2(x as u64)
}

/// The 24 permutations of four elements, for base-4 digit scrambling.
pub(crate) const PERMUTATIONS_4: [[u8; 4]; 24] = [
    [0, 1, 2, 3],
    [0, 1, 3, 2],
    [0, 2, 1, 3],
    [0, 2, 3, 1],
    [0, 3, 2, 1],
    [0, 3, 1, 2],
    [1, 0, 2, 3],
    [1, 0, 3, 2],
    [1, 2, 0, 3],
    [1, 2, 3, 0],
    [1, 3, 2, 0],
    [1, 3, 0, 2],
    [2, 1, 0, 3],
    [2, 1, 3, 0],
    [2, 0, 1, 3],
    [2, 0, 3, 1],
    [2, 3, 0, 1],
    [2, 3, 1, 0],
    [3, 1, 2, 0],
    [3, 1, 0, 2],
    [3, 2, 1, 0],
    [3, 2, 0, 1],
    [3, 0, 2, 1],
    [3, 0, 1, 2],
];

/// A per-pixel value in [0,1) with blue-noise-like spatial distribution:
/// the Morton index of the pixel (mod 256) with base-4 digits permuted
/// by hashes of the digits above them, bit-reversed (pbrt-v4's
/// `BlueNoiseSample`). Different `instance`s give decorrelated values.
pub fn blue_noise_sample(p: Point2i, instance: i32) -> Float {
    let morton = encode_morton2((p.x & 255) as u32, (p.y & 255) as u32);
    let mut index: u32 = 0;
    for i in (0..8).rev() {
        let shift = 2 * i;
        let digit = ((morton >> shift) & 3) as usize;
        let higher = morton >> (shift + 2);
        let perm = ((mix_bits(higher ^ 0x5555_5555u64.wrapping_mul(instance as i64 as u64)) >> 24)
            % 24) as usize;
        index |= (PERMUTATIONS_4[perm][digit] as u32) << shift;
    }
    (index.reverse_bits() as Float * f32::from_bits(0x2f80_0000)).min(ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_table() {
        assert_eq!(&PRIMES[..6], &[2, 3, 5, 7, 11, 13]);
        assert_eq!(PRIMES[999], 7919);
    }

    #[test]
    fn sobol_first_dimensions() {
        // Dimension 0 is van der Corput; dimension 1 the classic second
        // Sobol' dimension (m = 1, 3, 5, ...) in index order.
        let vdc: Vec<Float> = (0..4)
            .map(|i| sobol_sample(i, 0, BinaryScrambler::None))
            .collect();
        assert_eq!(vdc, vec![0.0, 0.5, 0.25, 0.75]);
        let d1: Vec<Float> = (0..8)
            .map(|i| sobol_sample(i, 1, BinaryScrambler::None))
            .collect();
        assert_eq!(d1, vec![0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
        // Dimension 2 (Joe–Kuo d=3: s=2, a=1, m=1,3): v = 1/2, 3/4, 3/8, ...
        let d2: Vec<Float> = (0..4)
            .map(|i| sobol_sample(i, 2, BinaryScrambler::None))
            .collect();
        assert_eq!(sobol_sample(4, 2, BinaryScrambler::None), 0.375);
        assert_eq!(d2, vec![0.0, 0.5, 0.75, 0.25]);
        // Every dimension is a (0,1)-sequence: the first 2^k values hit
        // each 1/2^k interval once.
        for dim in [3usize, 17, 500, 1023] {
            let k = 10;
            let mut seen = vec![false; 1 << k];
            for i in 0..(1u64 << k) {
                let v = sobol_sample(i, dim, BinaryScrambler::None);
                let cell = (v * (1 << k) as Float) as usize;
                assert!(!seen[cell], "dim {dim}");
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn fast_owen_01_matches_generic() {
        let mut rng = crate::rng::Rng::new(17, 0);
        for _ in 0..20_000 {
            let a = (rng.uniform_u32() as u64) << 20 ^ rng.uniform_u32() as u64;
            let a = a >> (rng.uniform_u32() % 52);
            let seed = rng.uniform_u32();
            for dim in 0..2 {
                let generic = sobol_sample(a, dim, BinaryScrambler::FastOwen(seed));
                assert_eq!(
                    sobol_sample_fast_owen_01(a, dim, seed).to_bits(),
                    generic.to_bits()
                );
            }
        }
    }

    #[test]
    fn scramblers_are_bijective_on_strata() {
        for s in [
            BinaryScrambler::Permute(0x1234_5678),
            BinaryScrambler::FastOwen(0x9abc_def1),
            BinaryScrambler::Owen(0x2468_ace1),
        ] {
            // The top 8 bits of scrambled values of all 8-bit prefixes are
            // a permutation: nested stratification survives.
            let mut seen = [false; 256];
            for i in 0..256u32 {
                let v = s.apply(i << 24 | 0x00ab_cdef) >> 24;
                assert!(!seen[v as usize], "{s:?}");
                seen[v as usize] = true;
            }
        }
    }

    #[test]
    fn radical_inverses() {
        assert_eq!(radical_inverse(0, 1), 0.5);
        assert_eq!(radical_inverse(0, 6), 0.375);
        assert!((radical_inverse(1, 5) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-6);
        assert_eq!(inverse_radical_inverse(5, 3, 2), 7);
        let perm = DigitPermutation::new(5, 7);
        let mut seen = [false; 125];
        for a in 0..125u64 {
            let v = scrambled_radical_inverse(2, a, &perm);
            let v2 = owen_scrambled_radical_inverse(2, a, 99);
            assert!((0.0..1.0).contains(&v) && (0.0..1.0).contains(&v2));
            let c = (v * 125.0) as usize;
            assert!(!seen[c]);
            seen[c] = true;
        }
        for i in 0..5 {
            let mut p: Vec<u32> = (0..5).map(|d| perm.permute(i, d)).collect();
            p.sort();
            assert_eq!(p, vec![0, 1, 2, 3, 4]);
        }
    }

    #[test]
    fn permutation_and_hash() {
        for n in [1u32, 2, 5, 16, 100] {
            let mut v: Vec<u32> = (0..n)
                .map(|i| permutation_element(i, n, 0xdead_beef))
                .collect();
            v.sort();
            assert_eq!(v, (0..n).collect::<Vec<_>>());
        }
        // Reference MurmurHash64A value for an empty key with seed 0 is 0;
        // distinct inputs hash apart and equal inputs agree.
        assert_eq!(murmur_hash64a(&[], 0), 0);
        let a = hash_values(&[&Point2i::new(3, 4), &7i32]);
        assert_eq!(a, hash_values(&[&Point2i::new(3, 4), &7i32]));
        assert_ne!(a, hash_values(&[&Point2i::new(4, 3), &7i32]));
        assert_eq!(encode_morton2(0b11, 0b01), 0b0111);
    }
}
