//! Piecewise-bilinear 2-D distributions with optional parameters (pbrt-v4
//! `util/sampling.h` `PiecewiseLinear2D`, after Dupuy and Jakob 2018 and
//! Mitsuba 2's `Marginal2D`).
//!
//! A density on the unit square is given by values on a regular grid and
//! interpolated bilinearly; sampling draws the row from a marginal CDF and
//! the column from the row's conditional CDF, both integrating the bilinear
//! patches exactly (so each step inverts a quadratic). With `N` parameters
//! the input holds one grid per combination of parameter values, and every
//! lookup interpolates linearly between the 2^N neighbouring grids.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

/// A warped point and the density there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PLSample {
    /// The point in the unit square.
    pub p: Point2f,
    /// The density at `p` (with respect to area on the unit square).
    pub pdf: Float,
}

/// The largest `i` in `[0, size - 2]` with `pred(i)` (for a predicate that
/// is true then false along the indices), or 0 (pbrt-v4 `FindInterval`).
#[inline]
pub fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    let mut first = 1usize;
    let mut len = size.saturating_sub(2);
    while len > 0 {
        let half = len >> 1;
        let middle = first + half;
        if pred(middle) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    (first - 1).min(size.saturating_sub(2))
}

/// A piecewise-bilinear distribution on the unit square depending on `N`
/// parameters (pbrt-v4 `PiecewiseLinear2D<N>`).
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear2D<const N: usize> {
    /// Grid resolution (x, y).
    nx: usize,
    ny: usize,
    /// Patch size in the unit square, and its inverse (`n − 1`).
    patch: [Float; 2],
    inv_patch: [Float; 2],
    /// Number of values of each parameter.
    param_size: [usize; N],
    /// Stride of each parameter in units of whole grids (0 for parameters
    /// with a single value).
    param_strides: [usize; N],
    /// Where each parameter was discretized.
    param_values: [Vec<f32>; N],
    /// The (normalized, when requested) grid values, slice after slice.
    data: Vec<f32>,
    /// Per slice: `ny` marginal CDF values over rows.
    marginal_cdf: Vec<f32>,
    /// Per slice: `nx · ny` conditional CDF values along each row.
    conditional_cdf: Vec<f32>,
}

impl<const N: usize> PiecewiseLinear2D<N> {
    /// A distribution from `data` (`N0 × … × N(n−1) × y_size × x_size`,
    /// x contiguous) with the parameter grids `param_values` (one slice per
    /// parameter, `Ni` values each, ascending).
    ///
    /// `normalize` rescales each slice to integrate to 1 (otherwise
    /// [`evaluate`](Self::evaluate) interpolates the raw values);
    /// `build_cdf` prepares [`sample`](Self::sample) and
    /// [`invert`](Self::invert) and requires `normalize`.
    pub fn new(
        data: &[f32],
        x_size: usize,
        y_size: usize,
        param_values: [&[f32]; N],
        normalize: bool,
        build_cdf: bool,
    ) -> Result<Self, String> {
        if build_cdf && !normalize {
            return Err("PiecewiseLinear2D: building the CDF requires normalization".into());
        }
        if x_size < 2 || y_size < 2 {
            return Err(format!(
                "PiecewiseLinear2D: resolution {x_size}×{y_size} is below 2×2"
            ));
        }
        let mut param_size = [0usize; N];
        let mut param_strides = [0usize; N];
        let mut slices = 1usize;
        for i in (0..N).rev() {
            let n = param_values[i].len();
            if n < 1 {
                return Err("PiecewiseLinear2D: a parameter has no values".into());
            }
            param_size[i] = n;
            param_strides[i] = if n > 1 { slices } else { 0 };
            slices = slices
                .checked_mul(n)
                .ok_or("PiecewiseLinear2D: too many parameter values")?;
        }
        let n_values = x_size
            .checked_mul(y_size)
            .ok_or("PiecewiseLinear2D: resolution too large")?;
        if slices.checked_mul(n_values) != Some(data.len()) {
            return Err(format!(
                "PiecewiseLinear2D: {} values given, {slices} slices of {x_size}×{y_size} expected",
                data.len()
            ));
        }
        let inv_patch = [(x_size - 1) as Float, (y_size - 1) as Float];
        let mut w = PiecewiseLinear2D {
            nx: x_size,
            ny: y_size,
            patch: [1.0 / inv_patch[0], 1.0 / inv_patch[1]],
            inv_patch,
            param_size,
            param_strides,
            param_values: std::array::from_fn(|i| param_values[i].to_vec()),
            data: vec![0.0; data.len()],
            marginal_cdf: Vec::new(),
            conditional_cdf: Vec::new(),
        };
        if build_cdf {
            w.marginal_cdf = vec![0.0; slices * y_size];
            w.conditional_cdf = vec![0.0; data.len()];
            for s in 0..slices {
                let src = &data[s * n_values..(s + 1) * n_values];
                let cond = &mut w.conditional_cdf[s * n_values..(s + 1) * n_values];
                for y in 0..y_size {
                    let row = y * x_size;
                    let mut sum = 0.0f64;
                    cond[row] = 0.0;
                    for x in 0..x_size - 1 {
                        sum += 0.5 * (src[row + x] as f64 + src[row + x + 1] as f64);
                        cond[row + x + 1] = sum as f32;
                    }
                }
                let marg = &mut w.marginal_cdf[s * y_size..(s + 1) * y_size];
                marg[0] = 0.0;
                let mut sum = 0.0f64;
                for y in 0..y_size - 1 {
                    sum += 0.5
                        * (cond[(y + 1) * x_size - 1] as f64 + cond[(y + 2) * x_size - 1] as f64);
                    marg[y + 1] = sum as f32;
                }
                // A slice without mass (pbrt-v4 divides by zero here) stays
                // zero, so it yields no samples rather than NaNs.
                let total = marg[y_size - 1];
                let norm = if total > 0.0 && total.is_finite() {
                    1.0 / total
                } else {
                    0.0
                };
                cond.iter_mut().for_each(|c| *c *= norm);
                marg.iter_mut().for_each(|m| *m *= norm);
                for (o, &v) in w.data[s * n_values..(s + 1) * n_values].iter_mut().zip(src) {
                    *o = v * norm;
                }
            }
        } else {
            for s in 0..slices {
                let src = &data[s * n_values..(s + 1) * n_values];
                let mut norm = 1.0 / (inv_patch[0] * inv_patch[1]);
                if normalize {
                    let mut sum = 0.0f64;
                    for y in 0..y_size - 1 {
                        for x in 0..x_size - 1 {
                            let i = y * x_size + x;
                            let avg = 0.25
                                * (src[i] + src[i + 1] + src[i + x_size] + src[i + 1 + x_size]);
                            sum += avg as f64;
                        }
                    }
                    norm = if sum > 0.0 && sum.is_finite() {
                        (1.0 / sum) as f32
                    } else {
                        0.0
                    };
                }
                for (o, &v) in w.data[s * n_values..(s + 1) * n_values].iter_mut().zip(src) {
                    *o = v * norm;
                }
            }
        }
        Ok(w)
    }

    /// True when the distribution can be sampled and inverted.
    pub fn has_cdf(&self) -> bool {
        !self.conditional_cdf.is_empty()
    }

    /// The interpolation weights of each parameter and the offset (in whole
    /// grids) of the first grid they blend.
    #[inline]
    fn param_weights(&self, param: &[Float; N]) -> ([[Float; 2]; N], usize) {
        let mut w = [[1.0, 0.0]; N];
        let mut slice_offset = 0;
        for dim in 0..N {
            if self.param_size[dim] == 1 {
                continue;
            }
            let values = &self.param_values[dim];
            let p = param[dim];
            let idx = find_interval(self.param_size[dim], |i| values[i] <= p);
            let (p0, p1) = (values[idx], values[idx + 1]);
            let t = (p - p0) / (p1 - p0);
            let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
            w[dim] = [1.0 - t, t];
            slice_offset += self.param_strides[dim] * idx;
        }
        (w, slice_offset)
    }

    /// `table[i0]` blended over the parameters: the grids `size` apart
    /// (times each parameter's stride) weighted by `w`.
    #[inline]
    fn lookup(&self, table: &[f32], i0: usize, size: usize, w: &[[Float; 2]; N]) -> Float {
        self.lookup_dim(table, i0, size, w, N)
    }

    fn lookup_dim(
        &self,
        table: &[f32],
        i0: usize,
        size: usize,
        w: &[[Float; 2]; N],
        dim: usize,
    ) -> Float {
        if dim == 0 {
            return table[i0];
        }
        let i1 = i0 + self.param_strides[dim - 1] * size;
        let v0 = self.lookup_dim(table, i0, size, w, dim - 1);
        let v1 = self.lookup_dim(table, i1, size, w, dim - 1);
        v0 * w[dim - 1][0] + v1 * w[dim - 1][1]
    }

    /// The patch holding `pos` (scaled to grid units) and the position
    /// inside it; points outside the square extrapolate the border patch.
    #[inline]
    fn patch_of(&self, pos: Point2f) -> (usize, usize, Float, Float) {
        let px = pos.x * self.inv_patch[0];
        let py = pos.y * self.inv_patch[1];
        let ix = (px.max(0.0) as usize).min(self.nx - 2);
        let iy = (py.max(0.0) as usize).min(self.ny - 2);
        (ix, iy, px - ix as Float, py - iy as Float)
    }

    /// Warps a uniform sample `u` to the distribution (for parameters
    /// `param`), with the density there (pbrt-v4 `Sample`). Requires the CDF.
    pub fn sample(&self, u: Point2f, param: &[Float; N]) -> PLSample {
        debug_assert!(self.has_cdf());
        if !self.has_cdf() {
            return PLSample {
                p: Point2f::new(0.0, 0.0),
                pdf: 0.0,
            };
        }
        let (nx, ny) = (self.nx, self.ny);
        let mut sx = u.x.clamp(1.0 - ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
        let mut sy = u.y.clamp(1.0 - ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
        let (w, slice_offset) = self.param_weights(param);
        let (cond, marg) = (&self.conditional_cdf, &self.marginal_cdf);

        // The row.
        let moff = slice_offset * ny;
        let fetch_marginal = |i: usize| self.lookup(marg, moff + i, ny, &w);
        let row = find_interval(ny, |i| fetch_marginal(i) < sy);
        sy -= fetch_marginal(row);
        let slice_size = nx * ny;
        let mut offset = row * nx + slice_offset * slice_size;
        let r0 = self.lookup(cond, offset + nx - 1, slice_size, &w);
        let r1 = self.lookup(cond, offset + 2 * nx - 1, slice_size, &w);
        let is_const = (r0 - r1).abs() < 1e-4 * (r0 + r1);
        sy = if is_const {
            2.0 * sy / (r0 + r1)
        } else {
            (r0 - safe_sqrt(r0 * r0 - 2.0 * sy * (r0 - r1))) / (r0 - r1)
        };

        // The column.
        sx *= (1.0 - sy) * r0 + sy * r1;
        let fetch_conditional = |i: usize| {
            let v0 = self.lookup(cond, offset + i, slice_size, &w);
            let v1 = self.lookup(cond, offset + i + nx, slice_size, &w);
            (1.0 - sy) * v0 + sy * v1
        };
        let col = find_interval(nx, |i| fetch_conditional(i) < sx);
        sx -= fetch_conditional(col);
        offset += col;

        let v00 = self.lookup(&self.data, offset, slice_size, &w);
        let v10 = self.lookup(&self.data, offset + 1, slice_size, &w);
        let v01 = self.lookup(&self.data, offset + nx, slice_size, &w);
        let v11 = self.lookup(&self.data, offset + nx + 1, slice_size, &w);
        let c0 = (1.0 - sy) * v00 + sy * v01;
        let c1 = (1.0 - sy) * v10 + sy * v11;
        let is_const = (c0 - c1).abs() < 1e-4 * (c0 + c1);
        sx = if is_const {
            2.0 * sx / (c0 + c1)
        } else {
            (c0 - safe_sqrt(c0 * c0 - 2.0 * sx * (c0 - c1))) / (c0 - c1)
        };
        PLSample {
            p: Point2f::new(
                (col as Float + sx) * self.patch[0],
                (row as Float + sy) * self.patch[1],
            ),
            pdf: ((1.0 - sx) * c0 + sx * c1) * self.inv_patch[0] * self.inv_patch[1],
        }
    }

    /// The inverse of [`sample`](Self::sample): the uniform sample that
    /// maps to `p`, with the density at `p` (pbrt-v4 `Invert`). Requires
    /// the CDF.
    pub fn invert(&self, p: Point2f, param: &[Float; N]) -> PLSample {
        debug_assert!(self.has_cdf());
        if !self.has_cdf() {
            return PLSample {
                p: Point2f::new(0.0, 0.0),
                pdf: 0.0,
            };
        }
        let (nx, ny) = (self.nx, self.ny);
        let (w, slice_offset) = self.param_weights(param);
        let (cond, marg) = (&self.conditional_cdf, &self.marginal_cdf);
        let (ix, iy, mut sx, mut sy) = self.patch_of(p);
        let slice_size = nx * ny;
        let offset = ix + iy * nx + slice_offset * slice_size;

        // x.
        let v00 = self.lookup(&self.data, offset, slice_size, &w);
        let v10 = self.lookup(&self.data, offset + 1, slice_size, &w);
        let v01 = self.lookup(&self.data, offset + nx, slice_size, &w);
        let v11 = self.lookup(&self.data, offset + nx + 1, slice_size, &w);
        let c0 = (1.0 - sy) * v00 + sy * v01;
        let c1 = (1.0 - sy) * v10 + sy * v11;
        let pdf = (1.0 - sx) * c0 + sx * c1;
        sx *= c0 + 0.5 * sx * (c1 - c0);
        let v0 = self.lookup(cond, offset, slice_size, &w);
        let v1 = self.lookup(cond, offset + nx, slice_size, &w);
        sx += (1.0 - sy) * v0 + sy * v1;
        let roff = iy * nx + slice_offset * slice_size;
        let r0 = self.lookup(cond, roff + nx - 1, slice_size, &w);
        let r1 = self.lookup(cond, roff + 2 * nx - 1, slice_size, &w);
        sx /= (1.0 - sy) * r0 + sy * r1;

        // y.
        sy *= r0 + 0.5 * sy * (r1 - r0);
        sy += self.lookup(marg, iy + slice_offset * ny, ny, &w);
        PLSample {
            p: Point2f::new(sx, sy),
            pdf: pdf * self.inv_patch[0] * self.inv_patch[1],
        }
    }

    /// The density (or, without normalization, the interpolated value) at
    /// `p` for parameters `param` (pbrt-v4 `Evaluate`).
    pub fn evaluate(&self, p: Point2f, param: &[Float; N]) -> Float {
        let (w, slice_offset) = self.param_weights(param);
        let (ix, iy, w1x, w1y) = self.patch_of(p);
        let (w0x, w0y) = (1.0 - w1x, 1.0 - w1y);
        let size = self.nx * self.ny;
        let index = ix + iy * self.nx + slice_offset * size;
        let v00 = self.lookup(&self.data, index, size, &w);
        let v10 = self.lookup(&self.data, index + 1, size, &w);
        let v01 = self.lookup(&self.data, index + self.nx, size, &w);
        let v11 = self.lookup(&self.data, index + self.nx + 1, size, &w);
        (w0y * (w0x * v00 + w1x * v10) + w1y * (w0x * v01 + w1x * v11))
            * self.inv_patch[0]
            * self.inv_patch[1]
    }

    /// Bytes held by the tables.
    pub fn bytes_used(&self) -> usize {
        4 * (self.data.len()
            + self.marginal_cdf.len()
            + self.conditional_cdf.len()
            + self.param_values.iter().map(Vec::len).sum::<usize>())
    }
}
