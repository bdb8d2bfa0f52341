//! SIMD lanes and the run-time choice of instruction set: the one module
//! that holds `std::arch` intrinsics (STYLE.md's boundary, as glam keeps
//! its backends apart).
//!
//! A kernel is written once, generic over [`F32Lanes`] (a few `f32` lanes
//! and their operations, with [`U32Lanes`] of the same width beside them
//! for bit work), and [`dispatch`] runs it at a width the processor
//! offers: AVX-512 (16 lanes), AVX2 with FMA (8 lanes), SSE4.1 (4 lanes)
//! or plain scalar code (1 lane), chosen once per process from
//! `is_x86_feature_detected!` ([`SimdLevel::preferred`]: the widest,
//! except AVX2 on Intel's AVX-512 processors), or forced with
//! `RPBRT_SIMD=scalar|sse4|avx2|avx512` (for tests and benchmarks; a level
//! the processor lacks falls back to the best it has). Every lane
//! operation is the IEEE operation the scalar code performs (`min`/`max`
//! with the scalar code's NaN order), so a kernel gives the same values at
//! every width.

mod ints;
mod lanes;
pub mod math;

pub use ints::{U32Lanes, U32x1};
#[cfg(target_arch = "x86_64")]
pub use ints::{U32x16, U32x4, U32x8};
pub use lanes::{F32Lanes, Scalar1};
#[cfg(target_arch = "x86_64")]
pub use lanes::{F32x16, F32x4, F32x8};

use std::sync::OnceLock;

/// The most lanes any width has (arrays that hold one value per lane are
/// this long).
pub const MAX_LANES: usize = 16;

/// An instruction-set level kernels can run at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SimdLevel {
    /// One lane, no vector instructions.
    Scalar,
    /// SSE4.1: 4 lanes.
    Sse4,
    /// AVX2 with FMA: 8 lanes.
    Avx2,
    /// AVX-512 (F, BW, DQ and VL, beside AVX2 and FMA): 16 lanes.
    Avx512,
}

impl SimdLevel {
    /// Lanes of `f32` per vector at this level.
    pub fn lanes(self) -> usize {
        match self {
            SimdLevel::Scalar => 1,
            SimdLevel::Sse4 => 4,
            SimdLevel::Avx2 => 8,
            SimdLevel::Avx512 => 16,
        }
    }

    /// The name `RPBRT_SIMD` takes and statistics print.
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Scalar => "scalar",
            SimdLevel::Sse4 => "sse4",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
        }
    }

    /// The level named `s` (as `RPBRT_SIMD` spells it).
    pub fn parse(s: &str) -> Option<SimdLevel> {
        match s.trim().to_ascii_lowercase().as_str() {
            "scalar" => Some(SimdLevel::Scalar),
            "sse4" | "sse4.1" | "sse41" => Some(SimdLevel::Sse4),
            "avx2" => Some(SimdLevel::Avx2),
            "avx512" | "avx-512" => Some(SimdLevel::Avx512),
            _ => None,
        }
    }

    /// Every level this processor runs, lowest first.
    pub fn available() -> Vec<SimdLevel> {
        [
            SimdLevel::Scalar,
            SimdLevel::Sse4,
            SimdLevel::Avx2,
            SimdLevel::Avx512,
        ]
        .into_iter()
        .filter(|&l| l <= SimdLevel::detected())
        .collect()
    }

    /// The best level this processor runs (found once per process:
    /// [`dispatch`] asks on every call).
    #[inline]
    pub fn detected() -> SimdLevel {
        static DETECTED: OnceLock<SimdLevel> = OnceLock::new();
        *DETECTED.get_or_init(SimdLevel::detect)
    }

    /// The level kernels run at unless told otherwise: the best this
    /// processor runs, but AVX2 rather than AVX-512 on Intel processors.
    /// Intel's cores lower their clock while they run 512-bit arithmetic,
    /// for everything they run (LLVM's and GCC's tuning for them prefers
    /// 256-bit vectors for the same reason), and on the development
    /// machines' AVX-512 Xeon that cost more than the wider lanes gained:
    /// the Cornell box rendered 7% slower at 16 lanes than at 8, the
    /// water caustic 3%, the killeroo crop the same (its coated BSDFs'
    /// walk was 7% faster, every other stage 5–10% slower).
    pub fn preferred() -> SimdLevel {
        let best = SimdLevel::detected();
        if best == SimdLevel::Avx512 && is_intel() {
            SimdLevel::Avx2
        } else {
            best
        }
    }

    /// Asks the processor which level it runs.
    fn detect() -> SimdLevel {
        #[cfg(target_arch = "x86_64")]
        {
            let avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
            if avx2
                && is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512bw")
                && is_x86_feature_detected!("avx512dq")
                && is_x86_feature_detected!("avx512vl")
            {
                return SimdLevel::Avx512;
            }
            if avx2 {
                return SimdLevel::Avx2;
            }
            if is_x86_feature_detected!("sse4.1") {
                return SimdLevel::Sse4;
            }
        }
        SimdLevel::Scalar
    }
}

/// Whether the processor is Intel's (its CPUID vendor string).
fn is_intel() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: CPUID leaf 0 exists on every x86-64 processor.
        #[allow(unused_unsafe)]
        let r = unsafe { std::arch::x86_64::__cpuid(0) };
        let vendor = [r.ebx, r.edx, r.ecx].map(u32::to_le_bytes).concat();
        vendor == b"GenuineIntel"
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The level kernels run at: [`SimdLevel::preferred`], or `RPBRT_SIMD`
/// when it names a level the processor has (a higher one is capped at the
/// best the processor runs). Read once per process.
pub fn level() -> SimdLevel {
    static LEVEL: OnceLock<SimdLevel> = OnceLock::new();
    *LEVEL.get_or_init(|| {
        match std::env::var("RPBRT_SIMD")
            .ok()
            .as_deref()
            .and_then(SimdLevel::parse)
        {
            Some(forced) => forced.min(SimdLevel::detected()),
            None => SimdLevel::preferred(),
        }
    })
}

/// The warning for an `RPBRT_SIMD` value that names no level, or a level
/// this processor lacks (for the command line to print); `None` when the
/// variable is unset or usable.
pub fn env_warning() -> Option<String> {
    let v = std::env::var("RPBRT_SIMD").ok()?;
    match SimdLevel::parse(&v) {
        None => Some(format!(
            "RPBRT_SIMD=\"{v}\" is not one of scalar, sse4, avx2, avx512; using {}",
            level().name()
        )),
        Some(l) if l > SimdLevel::detected() => Some(format!(
            "RPBRT_SIMD={v}: this processor lacks it; using {}",
            level().name()
        )),
        Some(_) => None,
    }
}

/// Asks the processor to start loading the cache lines of `v` (at most
/// four: 256 bytes from its start), which the caller will read soon: a
/// hint with no effect on results (none where the architecture has no
/// such hint).
#[inline(always)]
pub fn prefetch<T>(v: &T) {
    prefetch_ptr(v as *const T);
}

/// [`prefetch`] of the value at `v`, which need not be a valid address: a
/// prefetch never faults (callers skip the bounds check a reference would
/// need).
#[inline(always)]
pub fn prefetch_ptr<T>(v: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        let p = v as *const i8;
        let lines = std::mem::size_of::<T>().div_ceil(64).min(4);
        // SAFETY: prefetching is a hint that never faults, whatever the
        // address; SSE is part of the x86-64 baseline.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            for i in 0..lines {
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * i));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// A computation written once over [`F32Lanes`], run by [`dispatch`] at
/// one width.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// Runs the kernel with lanes `L`. Must be `#[inline(always)]`-friendly
    /// (generic code, no function pointers) so that it compiles inside
    /// [`dispatch`]'s target-feature functions.
    fn run<L: F32Lanes>(self) -> Self::Output;
}

/// Runs `k` at `level` (normally [`level()`]; a level above what the
/// processor runs is lowered to it, so any value is safe).
#[inline]
pub fn dispatch<K: Kernel>(level: SimdLevel, k: K) -> K::Output {
    let level = level.min(SimdLevel::detected());
    match level {
        #[cfg(target_arch = "x86_64")]
        SimdLevel::Avx512 => {
            // SAFETY: the processor has AVX-512 F, BW, DQ and VL, AVX2 and
            // FMA (`level` is at most `detected()`).
            unsafe { run_avx512(k) }
        }
        #[cfg(target_arch = "x86_64")]
        SimdLevel::Avx2 => {
            // SAFETY: the processor has AVX2 and FMA (`level` is at most
            // `detected()`).
            unsafe { run_avx2(k) }
        }
        #[cfg(target_arch = "x86_64")]
        SimdLevel::Sse4 => {
            // SAFETY: the processor has SSE4.1 (as above).
            unsafe { run_sse4(k) }
        }
        _ => k.run::<Scalar1>(),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx2,fma")]
unsafe fn run_avx512<K: Kernel>(k: K) -> K::Output {
    k.run::<F32x16>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<K: Kernel>(k: K) -> K::Output {
    k.run::<F32x8>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
unsafe fn run_sse4<K: Kernel>(k: K) -> K::Output {
    k.run::<F32x4>()
}

#[cfg(test)]
mod tests;
