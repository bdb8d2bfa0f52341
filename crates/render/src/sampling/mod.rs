//! Sampling routines (book chapters 2 and A.5; pbrt-v4 `util/sampling.h`):
//! warps of uniform samples to the distributions rendering needs, with
//! their densities and, where pbrt has them, their inverses.

pub mod spherical;
pub mod tabulated;

use crate::select::select_f32;
use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

/// Uniform point on the unit disk by the concentric mapping (Shirley–Chiu).
#[inline]
pub fn sample_uniform_disk_concentric(u: Point2f) -> Point2f {
    let uo = Point2f::new(2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
    if uo.x == 0.0 && uo.y == 0.0 {
        return Point2f::new(0.0, 0.0);
    }
    // Both wedges computed and one selected: which one is a coin flip, so a
    // branch would mispredict half the time.
    let x_major = uo.x.abs() > uo.y.abs();
    let r = select_f32(x_major, uo.x, uo.y);
    // θ = φ in the x-major wedges and π/2 − φ in the others, with φ in
    // [−π/4, π/4]: the sine and cosine of φ are taken either way and
    // swapped for the second case (cos(π/2 − φ) = sin φ), so that the
    // library's sin/cos, which branches on whether its argument exceeds
    // π/4, always takes the same path.
    let phi = PI_OVER_4 * select_f32(x_major, uo.y / uo.x, uo.x / uo.y);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let cos_theta = select_f32(x_major, cos_phi, sin_phi);
    let sin_theta = select_f32(x_major, sin_phi, cos_phi);
    Point2f::new(r * cos_theta, r * sin_theta)
}

/// Uniform point on the unit disk by the polar mapping.
#[inline]
pub fn sample_uniform_disk_polar(u: Point2f) -> Point2f {
    let r = u.x.sqrt();
    let theta = 2.0 * PI * u.y;
    Point2f::new(r * theta.cos(), r * theta.sin())
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u: Point2f) -> Vector3f {
    let z = 1.0 - 2.0 * u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = 2.0 * PI * u.y;
    Vector3f::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`] (per steradian).
pub const UNIFORM_SPHERE_PDF: Float = INV_4PI;

/// Uniform direction on the hemisphere z ≥ 0.
#[inline]
pub fn sample_uniform_hemisphere(u: Point2f) -> Vector3f {
    let z = u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = 2.0 * PI * u.y;
    Vector3f::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_hemisphere`].
pub const UNIFORM_HEMISPHERE_PDF: Float = INV_2PI;

/// Cosine-weighted direction on the hemisphere z ≥ 0 (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u: Point2f) -> Vector3f {
    let d = sample_uniform_disk_concentric(u);
    let z = safe_sqrt(1.0 - d.x * d.x - d.y * d.y);
    Vector3f::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`] for a direction with the given
/// cos θ.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: Float) -> Float {
    cos_theta * INV_PI
}

/// Uniform direction in the cone about +z with half-angle cosine
/// `cos_theta_max`.
#[inline]
pub fn sample_uniform_cone(u: Point2f, cos_theta_max: Float) -> Vector3f {
    let cos_theta = (1.0 - u.x) + u.x * cos_theta_max;
    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
    let phi = u.y * 2.0 * PI;
    rpbrt_geometry::spherical::spherical_direction(sin_theta, cos_theta, phi)
}

/// Density of [`sample_uniform_cone`].
#[inline]
pub fn uniform_cone_pdf(cos_theta_max: Float) -> Float {
    1.0 / (2.0 * PI * (1.0 - cos_theta_max))
}

/// Uniform barycentric coordinates (b0, b1, b2) on a triangle
/// (pbrt-v4's area-preserving warp).
#[inline]
pub fn sample_uniform_triangle(u: Point2f) -> [Float; 3] {
    let (b0, b1);
    if u.x < u.y {
        b0 = u.x / 2.0;
        b1 = u.y - b0;
    } else {
        b1 = u.y / 2.0;
        b0 = u.x - b1;
    }
    [b0, b1, 1.0 - b0 - b1]
}

/// Samples x ∈ [0,1] with density proportional to `lerp(x, a, b)`.
#[inline]
pub fn sample_linear(u: Float, a: Float, b: Float) -> Float {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + lerp(u, a * a, b * b).sqrt());
    x.min(ONE_MINUS_EPSILON)
}

/// Density of [`sample_linear`].
#[inline]
pub fn linear_pdf(x: Float, a: Float, b: Float) -> Float {
    if !(0.0..=1.0).contains(&x) {
        return 0.0;
    }
    2.0 * lerp(x, a, b) / (a + b)
}

/// Inverse of [`sample_linear`].
#[inline]
pub fn invert_linear_sample(x: Float, a: Float, b: Float) -> Float {
    x * (a * (2.0 - x) + b * x) / (a + b)
}

/// Samples [0,1]² with density proportional to the bilinear interpolation
/// of the corner weights `w` = [w(0,0), w(1,0), w(0,1), w(1,1)].
#[inline]
pub fn sample_bilinear(u: Point2f, w: [Float; 4]) -> Point2f {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, lerp(y, w[0], w[2]), lerp(y, w[1], w[3]));
    Point2f::new(x, y)
}

/// Density of [`sample_bilinear`].
#[inline]
pub fn bilinear_pdf(p: Point2f, w: [Float; 4]) -> Float {
    if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
        return 0.0;
    }
    if w[0] + w[1] + w[2] + w[3] == 0.0 {
        return 1.0;
    }
    4.0 * ((1.0 - p.x) * (1.0 - p.y) * w[0]
        + p.x * (1.0 - p.y) * w[1]
        + (1.0 - p.x) * p.y * w[2]
        + p.x * p.y * w[3])
        / (w[0] + w[1] + w[2] + w[3])
}

/// Inverse of [`sample_bilinear`].
#[inline]
pub fn invert_bilinear_sample(p: Point2f, w: [Float; 4]) -> Point2f {
    Point2f::new(
        invert_linear_sample(p.x, lerp(p.y, w[0], w[2]), lerp(p.y, w[1], w[3])),
        invert_linear_sample(p.y, w[0] + w[1], w[2] + w[3]),
    )
}

/// The power heuristic (β = 2) for multiple importance sampling.
#[inline]
pub fn power_heuristic(nf: Float, f_pdf: Float, ng: Float, g_pdf: Float) -> Float {
    let f = nf * f_pdf;
    let g = ng * g_pdf;
    if f.is_infinite() && f > 0.0 {
        return 1.0;
    }
    if f == 0.0 && g == 0.0 {
        return 0.0;
    }
    (f * f) / (f * f + g * g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn disk_samples_inside() {
        let mut r = Rng::new(0, 0);
        for _ in 0..10000 {
            let u = Point2f::new(r.uniform_float(), r.uniform_float());
            let p = sample_uniform_disk_concentric(u);
            assert!(p.x * p.x + p.y * p.y <= 1.0 + 1e-5);
            let v = sample_cosine_hemisphere(u);
            assert!(v.z >= 0.0 && (v.length() - 1.0).abs() < 1e-4);
            let s = sample_uniform_sphere(u);
            assert!((s.length() - 1.0).abs() < 1e-4);
            let c = sample_uniform_cone(u, 0.9);
            assert!(c.z >= 0.9 - 1e-5);
            let b = sample_uniform_triangle(u);
            assert!(b.iter().all(|&x| x >= -1e-6) && (b[0] + b[1] + b[2] - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn linear_and_bilinear_invert() {
        let mut r = Rng::new(3, 0);
        let w = [0.2, 1.5, 0.7, 3.0];
        let mut integral = 0.0f64;
        let n = 100000;
        for _ in 0..n {
            let u = Point2f::new(r.uniform_float(), r.uniform_float());
            let p = sample_bilinear(u, w);
            let back = invert_bilinear_sample(p, w);
            assert!((back - u).length() < 1e-3, "{u:?} {back:?}");
            // E[1/pdf] over samples = area = 1.
            integral += 1.0 / bilinear_pdf(p, w) as f64;
        }
        assert!((integral / n as f64 - 1.0).abs() < 0.02);
        assert!((linear_pdf(0.5, 1.0, 1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn power_heuristic_limits() {
        assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
        assert_eq!(power_heuristic(1.0, Float::INFINITY, 1.0, 1.0), 1.0);
        assert!((power_heuristic(1.0, 1.0, 1.0, 1.0) - 0.5).abs() < 1e-6);
    }
}
