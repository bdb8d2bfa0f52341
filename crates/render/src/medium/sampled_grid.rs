//! Point samples on a regular 3-D lattice, reconstructed by trilinear
//! interpolation (pbrt-v4 `SampledGrid` in `util/containers.h`; book
//! section B.4.5 "3D Sampled Data"): the density, temperature and emission
//! grids of the grid media.
//!
//! Sample `(x, y, z)` of an `nx × ny × nz` grid sits at the centre of its
//! cell, `((x + ½)/nx, (y + ½)/ny, (z + ½)/nz)` in the `[0, 1]³`
//! parametrisation of the medium's bounds. Lattice points outside the grid
//! count as zero (as in pbrt-v4), so values fall off linearly over the half
//! cell next to each face of the bounds.

use crate::spectrum::{RgbSigmoidPolynomial, RgbUnboundedSpectrum};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use std::ops::{Add, Mul};

/// A value a [`SampledGrid`] can hold: copyable, with the zero that
/// lattice points outside the grid take (pbrt-v4's `T{}`).
pub trait GridValue: Copy {
    /// The value outside the grid.
    const ZERO: Self;
}

impl GridValue for Float {
    const ZERO: Self = 0.0;
}

impl GridValue for RgbUnboundedSpectrum {
    /// A zero scale: the spectrum that is zero everywhere.
    const ZERO: Self = RgbUnboundedSpectrum {
        scale: 0.0,
        rsp: RgbSigmoidPolynomial::new(0.0, 0.0, 0.0),
    };
}

/// What trilinear interpolation produces: anything that can be scaled and
/// summed (a float, a sampled spectrum).
pub trait Interpolant: Copy + Add<Output = Self> + Mul<Float, Output = Self> {}

impl<T: Copy + Add<Output = T> + Mul<Float, Output = T>> Interpolant for T {}

#[inline(always)]
fn lerp<R: Interpolant>(t: Float, a: R, b: R) -> R {
    a * (1.0 - t) + b * t
}

/// An `nx × ny × nz` lattice of samples, x varying fastest.
#[derive(Clone, Debug)]
pub struct SampledGrid<T> {
    values: Vec<T>,
    nx: i32,
    ny: i32,
    nz: i32,
}

impl<T: GridValue> SampledGrid<T> {
    /// The grid of `values` at resolution `nx × ny × nz`; `None` unless
    /// every resolution is positive and there are exactly `nx · ny · nz`
    /// values.
    pub fn new(values: Vec<T>, nx: i32, ny: i32, nz: i32) -> Option<Self> {
        if nx <= 0 || ny <= 0 || nz <= 0 {
            return None;
        }
        let n = (nx as u64).checked_mul(ny as u64)?.checked_mul(nz as u64)?;
        if n != values.len() as u64 {
            return None;
        }
        Some(SampledGrid { values, nx, ny, nz })
    }

    /// The resolution `[nx, ny, nz]`.
    pub fn resolution(&self) -> [i32; 3] {
        [self.nx, self.ny, self.nz]
    }

    /// Sample `(x, y, z)`, or zero outside the grid.
    #[inline(always)]
    pub fn sample(&self, x: i32, y: i32, z: i32) -> T {
        if x < 0 || y < 0 || z < 0 || x >= self.nx || y >= self.ny || z >= self.nz {
            return T::ZERO;
        }
        self.values[((z * self.ny + y) * self.nx + x) as usize]
    }

    /// The continuous lattice coordinate of `p` (in `[0, 1]³` over the
    /// bounds) along an axis of resolution `n`: kept within `[−1, n]`,
    /// where the result no longer changes (the samples there are all
    /// zero), so that far-away or non-finite points stay in integer range
    /// (NaN maps to −1 and so to zero).
    #[inline(always)]
    fn lattice(p: Float, n: i32) -> Float {
        (p * n as Float - 0.5).max(-1.0).min(n as Float)
    }

    /// The trilinear interpolation at `p` (`[0, 1]³` over the bounds) of
    /// the samples mapped through `convert` (pbrt-v4's `Lookup(p,
    /// convert)`): spectra are interpolated after conversion.
    #[inline]
    pub fn lookup_with<R: Interpolant>(&self, p: Point3f, convert: impl Fn(T) -> R) -> R {
        let ps = [
            Self::lattice(p.x, self.nx),
            Self::lattice(p.y, self.ny),
            Self::lattice(p.z, self.nz),
        ];
        let f = ps.map(|v| v.floor());
        let (x, y, z) = (f[0] as i32, f[1] as i32, f[2] as i32);
        let (dx, dy, dz) = (ps[0] - f[0], ps[1] - f[1], ps[2] - f[2]);
        let at = |i: i32, j: i32, k: i32| convert(self.sample(x + i, y + j, z + k));
        let d00 = lerp(dx, at(0, 0, 0), at(1, 0, 0));
        let d10 = lerp(dx, at(0, 1, 0), at(1, 1, 0));
        let d01 = lerp(dx, at(0, 0, 1), at(1, 0, 1));
        let d11 = lerp(dx, at(0, 1, 1), at(1, 1, 1));
        lerp(dz, lerp(dy, d00, d10), lerp(dy, d01, d11))
    }

    /// The largest `convert(sample)` over the samples that can influence
    /// a lookup inside `bounds` (in `[0, 1]³`; pbrt-v4 `MaxValue(bounds,
    /// convert)`): an upper bound of the interpolated values there as
    /// long as the converted samples are non-negative.
    pub fn max_value_with(&self, bounds: &Bounds3f, convert: impl Fn(T) -> Float) -> Float {
        let n = [self.nx, self.ny, self.nz];
        let lo = [0, 1, 2].map(|a| (Self::lattice(bounds.p_min[a], n[a]).floor() as i32).max(0));
        let hi = [0, 1, 2]
            .map(|a| (Self::lattice(bounds.p_max[a], n[a]).floor() as i32 + 1).min(n[a] - 1));
        let mut max = convert(self.sample(lo[0], lo[1], lo[2]));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    max = max.max(convert(self.sample(x, y, z)));
                }
            }
        }
        max
    }

    /// Every sample, x fastest.
    pub fn values(&self) -> &[T] {
        &self.values
    }
}

impl SampledGrid<Float> {
    /// The interpolated value at `p` (`[0, 1]³` over the bounds).
    #[inline]
    pub fn lookup(&self, p: Point3f) -> Float {
        self.lookup_with(p, |v| v)
    }

    /// The largest sample that can influence a lookup inside `bounds`.
    pub fn max_value(&self, bounds: &Bounds3f) -> Float {
        self.max_value_with(bounds, |v| v)
    }
}
