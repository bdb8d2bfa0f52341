//! The Trowbridge–Reitz (GGX) microfacet distribution with Smith masking
//! and visible-normal sampling (pbrt-v4 book section 9.6; pbrt-v4
//! `util/scattering.h`).

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos2_theta, cos_phi, sin_phi, tan2_theta};

use crate::sampling::sample_uniform_disk_polar;

/// An anisotropic Trowbridge–Reitz distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitzDistribution {
    alpha_x: Float,
    alpha_y: Float,
}

impl TrowbridgeReitzDistribution {
    /// A distribution with roughness `alpha_x` along x and `alpha_y` along y.
    /// Unless the surface is effectively smooth, both are raised to at least
    /// 1e-4 so that one nearly-zero direction does not blow up [`Self::d`].
    pub fn new(alpha_x: Float, alpha_y: Float) -> Self {
        let mut d = TrowbridgeReitzDistribution { alpha_x, alpha_y };
        if !d.effectively_smooth() {
            d.alpha_x = d.alpha_x.max(1e-4);
            d.alpha_y = d.alpha_y.max(1e-4);
        }
        d
    }

    /// Roughness along x.
    #[inline]
    pub fn alpha_x(&self) -> Float {
        self.alpha_x
    }

    /// Roughness along y.
    #[inline]
    pub fn alpha_y(&self) -> Float {
        self.alpha_y
    }

    /// pbrt-v4's mapping from the user-facing roughness to α: `sqrt(r)`.
    #[inline]
    pub fn roughness_to_alpha(roughness: Float) -> Float {
        roughness.sqrt()
    }

    /// The microfacet normal density D(ωm).
    #[inline]
    pub fn d(&self, wm: Vector3f) -> Float {
        let tan2 = tan2_theta(wm);
        if tan2.is_infinite() || tan2.is_nan() {
            return 0.0;
        }
        let cos4 = sqr(cos2_theta(wm));
        if cos4 < 1e-16 {
            return 0.0;
        }
        let e = tan2 * (sqr(cos_phi(wm) / self.alpha_x) + sqr(sin_phi(wm) / self.alpha_y));
        1.0 / (PI * self.alpha_x * self.alpha_y * cos4 * sqr(1.0 + e))
    }

    /// True when the surface is so smooth that it is treated as specular.
    #[inline]
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < 1e-3
    }

    /// Smith's auxiliary function Λ(ω).
    #[inline]
    pub fn lambda(&self, w: Vector3f) -> Float {
        let tan2 = tan2_theta(w);
        if tan2.is_infinite() || tan2.is_nan() {
            return 0.0;
        }
        let alpha2 = sqr(cos_phi(w) * self.alpha_x) + sqr(sin_phi(w) * self.alpha_y);
        ((1.0 + alpha2 * tan2).sqrt() - 1.0) / 2.0
    }

    /// Masking function G1(ω).
    #[inline]
    pub fn g1(&self, w: Vector3f) -> Float {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G(ωo, ωi).
    #[inline]
    pub fn g(&self, wo: Vector3f, wi: Vector3f) -> Float {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The distribution of normals visible from `w`, D_ω(ωm).
    #[inline]
    pub fn d_visible(&self, w: Vector3f, wm: Vector3f) -> Float {
        self.g1(w) / abs_cos_theta(w) * self.d(wm) * abs_dot(w, wm)
    }

    /// Density of [`Self::sample_wm`]: the visible-normal distribution.
    #[inline]
    pub fn pdf(&self, w: Vector3f, wm: Vector3f) -> Float {
        self.d_visible(w, wm)
    }

    /// Samples a microfacet normal visible from `w` (Heitz's method with the
    /// hemisphere projection of pbrt-v4); the result lies in `w`'s hemisphere
    /// when `w` is above the surface.
    pub fn sample_wm(&self, w: Vector3f, u: Point2f) -> Vector3f {
        // Stretch to the configuration of a hemisphere with unit roughness.
        let mut wh = Vector3f::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        let t1 = if wh.z < 0.99999 {
            cross(Vector3f::new(0.0, 0.0, 1.0), wh).normalize()
        } else {
            Vector3f::new(1.0, 0.0, 0.0)
        };
        let t2 = cross(wh, t1);
        // A uniform disk point, squeezed onto the projection of the
        // visible hemisphere.
        let mut p = sample_uniform_disk_polar(u);
        let h = (1.0 - sqr(p.x)).sqrt();
        p.y = lerp((1.0 + wh.z) / 2.0, h, p.y);
        let pz = (1.0 - sqr(p.x) - sqr(p.y)).max(0.0).sqrt();
        let nh = t1 * p.x + t2 * p.y + wh * pz;
        Vector3f::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }

    /// Widens near-specular lobes (path regularization): α below 0.3 is
    /// doubled and clamped to [0.1, 0.3].
    pub fn regularize(&mut self) {
        if self.alpha_x < 0.3 {
            self.alpha_x = clamp(2.0 * self.alpha_x, 0.1, 0.3);
        }
        if self.alpha_y < 0.3 {
            self.alpha_y = clamp(2.0 * self.alpha_y, 0.1, 0.3);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::sample_uniform_sphere;

    fn u2(rng: &mut Rng) -> Point2f {
        Point2f::new(rng.uniform_float(), rng.uniform_float())
    }

    #[test]
    fn normalization_of_projected_area() {
        // ∫ D(ωm) cos θm dωm = 1 over the hemisphere.
        let mut rng = Rng::new(11, 0);
        for (ax, ay) in [(0.1, 0.1), (0.3, 0.3), (0.5, 0.2), (0.8, 0.8)] {
            let d = TrowbridgeReitzDistribution::new(ax, ay);
            let n = 400_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let w = sample_uniform_sphere(u2(&mut rng));
                if w.z > 0.0 {
                    sum += (d.d(w) * w.z * 4.0 * PI) as f64;
                }
            }
            let v = sum / n as f64;
            assert!((v - 1.0).abs() < 0.05, "alpha {ax} {ay}: {v}");
        }
    }

    #[test]
    fn visible_normals_integrate_to_one_and_sampled_normals_are_visible() {
        let mut rng = Rng::new(12, 0);
        let d = TrowbridgeReitzDistribution::new(0.4, 0.25);
        let wo = Vector3f::new(0.5, 0.2, 0.6).normalize();
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let w = sample_uniform_sphere(u2(&mut rng));
            if w.z > 0.0 {
                sum += (d.pdf(wo, w) * 4.0 * PI) as f64;
            }
        }
        let v = sum / n as f64;
        assert!((v - 1.0).abs() < 0.03, "{v}");
        for _ in 0..10_000 {
            let wm = d.sample_wm(wo, u2(&mut rng));
            assert!(wm.z > 0.0 && dot(wm, wo) >= -1e-4);
            assert!((wm.length() - 1.0).abs() < 1e-4);
        }
    }

    #[test]
    fn smoothness_and_regularize() {
        let mut d = TrowbridgeReitzDistribution::new(0.0, 0.0);
        assert!(d.effectively_smooth());
        d.regularize();
        assert!(!d.effectively_smooth());
        assert_eq!(d.alpha_x(), 0.1);
        let mut d = TrowbridgeReitzDistribution::new(0.2, 0.5);
        d.regularize();
        assert_eq!((d.alpha_x(), d.alpha_y()), (0.3, 0.5));
        assert_eq!(TrowbridgeReitzDistribution::roughness_to_alpha(0.25), 0.5);
        // One rough direction keeps the other away from zero.
        let d = TrowbridgeReitzDistribution::new(0.0, 0.5);
        assert_eq!(d.alpha_x(), 1e-4);
    }
}
