//! Catmull–Rom spline evaluation, integration, inversion and sampling over
//! non-uniform nodes (pbrt-v4 `util/math.h`, book section 8.4.2 / pbrt-v3
//! appendix A.3): the machinery behind the tabulated BSSRDF profile.

use rpbrt_geometry::float::{evaluate_polynomial, find_interval, Float};

/// Finite-difference end-point derivatives of the spline segment `[i, i+1]`
/// of `values` over `nodes`, scaled to the segment's unit parameter.
#[inline]
fn segment_derivatives(
    nodes: &[Float],
    i: usize,
    value: impl Fn(usize) -> Float,
) -> (Float, Float) {
    let (x0, x1) = (nodes[i], nodes[i + 1]);
    let (f0, f1) = (value(i), value(i + 1));
    let width = x1 - x0;
    // One-sided differences at the ends of the node range.
    let d0 = if i > 0 {
        width * (f1 - value(i - 1)) / (x1 - nodes[i - 1])
    } else {
        f1 - f0
    };
    let d1 = if i + 2 < nodes.len() {
        width * (value(i + 2) - f0) / (nodes[i + 2] - x0)
    } else {
        f1 - f0
    };
    (d0, d1)
}

/// The Catmull–Rom interpolant of `values` at `nodes`, evaluated at `x`;
/// zero outside `[nodes[0], nodes[last]]`.
pub fn catmull_rom(nodes: &[Float], values: &[Float], x: Float) -> Float {
    debug_assert_eq!(nodes.len(), values.len());
    if nodes.len() < 2 || !(x >= nodes[0] && x <= nodes[nodes.len() - 1]) {
        return 0.0;
    }
    let i = find_interval(nodes.len(), |k| nodes[k] <= x);
    let (d0, d1) = segment_derivatives(nodes, i, |k| values[k]);
    let (f0, f1) = (values[i], values[i + 1]);
    let t = (x - nodes[i]) / (nodes[i + 1] - nodes[i]);
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * f0
        + (-2.0 * t3 + 3.0 * t2) * f1
        + (t3 - 2.0 * t2 + t) * d0
        + (t3 - t2) * d1
}

/// The weights of the (up to) four nodes that the spline through `nodes`
/// combines at `x`: `Some((offset, w))` means the value is
/// `Σ w[j] · f[offset + j]`. `offset` may be −1 (then `w[0]` is zero);
/// entries with zero weight must not be read. `None` when `x` lies outside
/// the node range.
pub fn catmull_rom_weights(nodes: &[Float], x: Float) -> Option<(isize, [Float; 4])> {
    if nodes.len() < 2 || !(x >= nodes[0] && x <= nodes[nodes.len() - 1]) {
        return None;
    }
    let idx = find_interval(nodes.len(), |k| nodes[k] <= x);
    let (x0, x1) = (nodes[idx], nodes[idx + 1]);
    let t = (x - x0) / (x1 - x0);
    let (t2, t3) = (t * t, t * t * t);
    let mut w = [0.0; 4];
    w[1] = 2.0 * t3 - 3.0 * t2 + 1.0;
    w[2] = -2.0 * t3 + 3.0 * t2;
    // The derivative terms spread over the neighbouring nodes (or fold back
    // onto the segment's own nodes at the ends of the range).
    let h0 = t3 - 2.0 * t2 + t;
    if idx > 0 {
        let w0 = h0 * (x1 - x0) / (x1 - nodes[idx - 1]);
        w[0] = -w0;
        w[2] += w0;
    } else {
        w[0] = 0.0;
        w[1] -= h0;
        w[2] += h0;
    }
    let h1 = t3 - t2;
    if idx + 2 < nodes.len() {
        let w3 = h1 * (x1 - x0) / (nodes[idx + 2] - x0);
        w[1] -= w3;
        w[3] = w3;
    } else {
        w[1] -= h1;
        w[2] += h1;
        w[3] = 0.0;
    }
    Some((idx as isize - 1, w))
}

/// Integrates the spline through (`x`, `values`) segment by segment,
/// writing the running integral at each node into `cdf` (`cdf[0] = 0`) and
/// returning the total.
pub fn integrate_catmull_rom(x: &[Float], values: &[Float], cdf: &mut [Float]) -> Float {
    debug_assert!(x.len() == values.len() && cdf.len() == x.len());
    let mut sum = 0.0;
    if let Some(c) = cdf.first_mut() {
        *c = 0.0;
    }
    for i in 0..x.len().saturating_sub(1) {
        let (d0, d1) = segment_derivatives(x, i, |k| values[k]);
        let width = x[i + 1] - x[i];
        // Exact integral of the cubic Hermite segment.
        sum += ((d0 - d1) * (1.0 / 12.0) + (values[i] + values[i + 1]) * 0.5) * width;
        cdf[i + 1] = sum;
    }
    sum
}

/// Finds the root of a function on `[x0, x1]` that changes sign there, by
/// Newton steps safeguarded with bisection. `f` returns the value and the
/// derivative.
pub fn newton_bisection(
    mut x0: Float,
    mut x1: Float,
    f: impl Fn(Float) -> (Float, Float),
    x_eps: Float,
    f_eps: Float,
) -> Float {
    let fx0 = f(x0).0;
    let fx1 = f(x1).0;
    if fx0.abs() < f_eps {
        return x0;
    }
    if fx1.abs() < f_eps {
        return x1;
    }
    let start_negative = fx0 < 0.0;
    // First guess: the root of the line through the end points.
    let mut x_mid = x0 + (x1 - x0) * -fx0 / (fx1 - fx0);
    // Bisection alone halves the bracket each step, so this bound is never
    // reached for sensible epsilons; it only guards against NaN inputs.
    for _ in 0..200 {
        if !(x0 < x_mid && x_mid < x1) {
            x_mid = 0.5 * (x0 + x1);
        }
        let (fx_mid, dfx_mid) = f(x_mid);
        if start_negative == (fx_mid < 0.0) {
            x0 = x_mid;
        } else {
            x1 = x_mid;
        }
        if x1 - x0 < x_eps || fx_mid.abs() < f_eps {
            return x_mid;
        }
        x_mid -= fx_mid / dfx_mid;
    }
    x_mid
}

/// The `x` at which the (assumed monotonically increasing) spline through
/// (`x`, `values`) takes the value `u`; clamped to the first or last node
/// when `u` is out of range.
pub fn invert_catmull_rom(x: &[Float], values: &[Float], u: Float) -> Float {
    debug_assert_eq!(x.len(), values.len());
    let (Some(&first), Some(&last)) = (values.first(), values.last()) else {
        return 0.0;
    };
    if u.is_nan() || u <= first {
        return x[0];
    } else if u >= last {
        return x[x.len() - 1];
    }
    let i = find_interval(values.len(), |k| values[k] <= u);
    let (x0, x1) = (x[i], x[i + 1]);
    let (f0, f1) = (values[i], values[i + 1]);
    let (d0, d1) = segment_derivatives(x, i, |k| values[k]);
    let eval = |t: Float| {
        let (t2, t3) = (t * t, t * t * t);
        let fhat_big = (2.0 * t3 - 3.0 * t2 + 1.0) * f0
            + (-2.0 * t3 + 3.0 * t2) * f1
            + (t3 - 2.0 * t2 + t) * d0
            + (t3 - t2) * d1;
        let fhat = (6.0 * t2 - 6.0 * t) * f0
            + (-6.0 * t2 + 6.0 * t) * f1
            + (3.0 * t2 - 4.0 * t + 1.0) * d0
            + (3.0 * t2 - 2.0 * t) * d1;
        (fhat_big - u, fhat)
    };
    let t = newton_bisection(0.0, 1.0, eval, 1e-6, 1e-6);
    x0 + t * (x1 - x0)
}

/// A sample drawn from a spline-interpolated 1-D distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplineSample {
    /// The sampled position.
    pub x: Float,
    /// The interpolated function's value there.
    pub fval: Float,
    /// The probability density of `x` (function value over its integral).
    pub pdf: Float,
}

/// Samples the second dimension of a 2-D tabulated function (rows over
/// `nodes1`, columns over `nodes2`, row-major `values`, with per-row running
/// integrals `cdf` from [`integrate_catmull_rom`]) with the first dimension
/// fixed to `alpha`, interpolating rows with Catmull–Rom weights. `None` when
/// `alpha` is outside `nodes1` or the interpolated row integrates to zero.
pub fn sample_catmull_rom_2d(
    nodes1: &[Float],
    nodes2: &[Float],
    values: &[Float],
    cdf: &[Float],
    alpha: Float,
    u: Float,
) -> Option<SplineSample> {
    let n2 = nodes2.len();
    debug_assert!(values.len() == nodes1.len() * n2 && cdf.len() == values.len());
    if n2 < 2 {
        return None;
    }
    let (offset, weights) = catmull_rom_weights(nodes1, alpha)?;
    let interpolate = |array: &[Float], idx: usize| -> Float {
        let mut v = 0.0;
        for (j, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                let row = (offset + j as isize) as usize;
                v += array[row * n2 + idx] * w;
            }
        }
        v
    };
    let maximum = interpolate(cdf, n2 - 1);
    if maximum.is_nan() || maximum <= 0.0 {
        return None;
    }
    let u = u * maximum;
    let idx = find_interval(n2, |i| interpolate(cdf, i) <= u);
    let (f0, f1) = (interpolate(values, idx), interpolate(values, idx + 1));
    let (x0, x1) = (nodes2[idx], nodes2[idx + 1]);
    let width = x1 - x0;
    let (d0, d1) = segment_derivatives(nodes2, idx, |k| interpolate(values, k));
    // The remaining integral inside the segment, in units of its parameter t.
    let u = (u - interpolate(cdf, idx)) / width;
    let big_f = |t: Float| {
        evaluate_polynomial(
            t,
            &[
                0.0,
                f0,
                0.5 * d0,
                (1.0 / 3.0) * (-2.0 * d0 - d1) + f1 - f0,
                0.25 * (d0 + d1) + 0.5 * (f0 - f1),
            ],
        )
    };
    let small_f = |t: Float| {
        evaluate_polynomial(
            t,
            &[
                f0,
                d0,
                -2.0 * d0 - d1 + 3.0 * (f1 - f0),
                d0 + d1 + 2.0 * (f0 - f1),
            ],
        )
    };
    let t = newton_bisection(0.0, 1.0, |t| (big_f(t) - u, small_f(t)), 1e-6, 1e-6);
    let fval = small_f(t);
    Some(SplineSample {
        x: x0 + width * t,
        fval,
        pdf: fval / maximum,
    })
}
