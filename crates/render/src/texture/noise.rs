//! Perlin noise and the sums of octaves built on it (book section 10.6.1
//! "Perlin Noise" and 10.6.2 "Random Polka Dots"/10.6.3 "Noise Idioms";
//! pbrt-v4 `util/noise.h/.cpp`).
//!
//! The permutation table and the gradient choice are pbrt's (Perlin's
//! improved-noise table), so patterns match pbrt-v4 point for point.

use rpbrt_geometry::float::{clamp, lerp, Float};
use rpbrt_geometry::tuple::*;

const PERM_SIZE: usize = 256;

/// Perlin's permutation of 0..=255, stored twice so that sums of two
/// entries index without wrapping.
static PERM: [u8; 2 * PERM_SIZE] = {
    const BASE: [u8; PERM_SIZE] = [
        151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30,
        69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94,
        252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171,
        168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60,
        211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1,
        216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86,
        164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118,
        126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170,
        213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39,
        253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34,
        242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49,
        192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254,
        138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180,
    ];
    let mut out = [0u8; 2 * PERM_SIZE];
    let mut i = 0;
    while i < 2 * PERM_SIZE {
        out[i] = BASE[i % PERM_SIZE];
        i += 1;
    }
    out
};

/// Dot product of the lattice point's pseudo-random gradient (one of 12
/// cube-edge directions, 4 repeated) with the offset `(dx, dy, dz)`.
#[inline]
fn grad(x: usize, y: usize, z: usize, dx: Float, dy: Float, dz: Float) -> Float {
    let h = PERM[PERM[PERM[x] as usize + y] as usize + z] & 15;
    let u = if h < 8 || h == 12 || h == 13 { dx } else { dy };
    let v = if h < 4 || h == 12 || h == 13 { dy } else { dz };
    (if h & 1 != 0 { -u } else { u }) + (if h & 2 != 0 { -v } else { v })
}

/// The quintic fade 6t⁵ − 15t⁴ + 10t³ (C² continuous at the lattice).
#[inline]
fn noise_weight(t: Float) -> Float {
    let t3 = t * t * t;
    let t4 = t3 * t;
    6.0 * t4 * t - 15.0 * t4 + 10.0 * t3
}

/// Perlin noise at `(x, y, z)`, in about [-1, 1], zero at lattice points.
pub fn noise(x: Float, y: Float, z: Float) -> Float {
    // Keep the cell indices inside i32 for huge coordinates.
    const BIG: Float = (1u32 << 30) as Float;
    let (x, y, z) = (x % BIG, y % BIG, z % BIG);
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (dx, dy, dz) = (x - fx, y - fy, z - fz);
    let mask = (PERM_SIZE - 1) as i32;
    let ix = ((fx as i32) & mask) as usize;
    let iy = ((fy as i32) & mask) as usize;
    let iz = ((fz as i32) & mask) as usize;
    let w000 = grad(ix, iy, iz, dx, dy, dz);
    let w100 = grad(ix + 1, iy, iz, dx - 1.0, dy, dz);
    let w010 = grad(ix, iy + 1, iz, dx, dy - 1.0, dz);
    let w110 = grad(ix + 1, iy + 1, iz, dx - 1.0, dy - 1.0, dz);
    let w001 = grad(ix, iy, iz + 1, dx, dy, dz - 1.0);
    let w101 = grad(ix + 1, iy, iz + 1, dx - 1.0, dy, dz - 1.0);
    let w011 = grad(ix, iy + 1, iz + 1, dx, dy - 1.0, dz - 1.0);
    let w111 = grad(ix + 1, iy + 1, iz + 1, dx - 1.0, dy - 1.0, dz - 1.0);
    let (wx, wy, wz) = (noise_weight(dx), noise_weight(dy), noise_weight(dz));
    let x00 = lerp(wx, w000, w100);
    let x10 = lerp(wx, w010, w110);
    let x01 = lerp(wx, w001, w101);
    let x11 = lerp(wx, w011, w111);
    let y0 = lerp(wy, x00, x10);
    let y1 = lerp(wy, x01, x11);
    lerp(wz, y0, y1)
}

/// Perlin noise at a point.
#[inline]
pub fn noise_p(p: Point3f) -> Float {
    noise(p.x, p.y, p.z)
}

/// Finite-difference gradient of the noise (step 0.01), as pbrt-v4's
/// `DNoise`.
pub fn dnoise(p: Point3f) -> Vector3f {
    let delta = 0.01;
    let n = noise_p(p);
    Vector3f::new(
        noise_p(p + Vector3f::new(delta, 0.0, 0.0)) - n,
        noise_p(p + Vector3f::new(0.0, delta, 0.0)) - n,
        noise_p(p + Vector3f::new(0.0, 0.0, delta)) - n,
    ) / delta
}

/// Hermite smooth step of `x` between `a` and `b`.
#[inline]
pub fn smooth_step(x: Float, a: Float, b: Float) -> Float {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = clamp((x - a) / (b - a), 0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// How many octaves the footprint allows: octaves whose frequency exceeds
/// the sampling rate implied by the larger of `dpdx`, `dpdy` are dropped
/// (pbrt-v4's clamp of −1 − log2(len²)/2 to [0, max_octaves]).
#[inline]
pub fn octave_count(dpdx: Vector3f, dpdy: Vector3f, max_octaves: i32) -> Float {
    let len2 = dpdx.length_squared().max(dpdy.length_squared());
    let n = -1.0 - len2.log2() / 2.0;
    // NaN (a degenerate footprint) behaves like no footprint at all.
    if n.is_nan() {
        return max_octaves.max(0) as Float;
    }
    clamp(n, 0.0, max_octaves.max(0) as Float)
}

/// Fractional Brownian motion: octaves of noise at frequencies growing by
/// 1.99 and amplitudes shrinking by `omega`, band-limited to the footprint.
pub fn fbm(p: Point3f, dpdx: Vector3f, dpdy: Vector3f, omega: Float, max_octaves: i32) -> Float {
    let n = octave_count(dpdx, dpdy, max_octaves);
    let n_int = n.floor() as i32;
    let (mut sum, mut lambda, mut o) = (0.0, 1.0, 1.0);
    for _ in 0..n_int {
        sum += o * noise_p(p * lambda);
        lambda *= 1.99;
        o *= omega;
    }
    let partial = n - n_int as Float;
    sum + o * smooth_step(partial, 0.3, 0.7) * noise_p(p * lambda)
}

/// Turbulence: like [`fbm`] with |noise|; clamped octaves contribute their
/// average value 0.2 so the mean stays put as the footprint grows.
pub fn turbulence(
    p: Point3f,
    dpdx: Vector3f,
    dpdy: Vector3f,
    omega: Float,
    max_octaves: i32,
) -> Float {
    let n = octave_count(dpdx, dpdy, max_octaves);
    let n_int = n.floor() as i32;
    let (mut sum, mut lambda, mut o) = (0.0, 1.0, 1.0);
    for _ in 0..n_int {
        sum += o * noise_p(p * lambda).abs();
        lambda *= 1.99;
        o *= omega;
    }
    let partial = n - n_int as Float;
    sum += o * lerp(
        smooth_step(partial, 0.3, 0.7),
        0.2,
        noise_p(p * lambda).abs(),
    );
    // pbrt-v4 adds the remaining octaves' averages without first advancing
    // the amplitude past the partial octave; kept for identical results.
    for _ in n_int..max_octaves {
        sum += o * 0.2;
        o *= omega;
    }
    sum
}
