//! Scattering utilities (pbrt-v4 book sections 9.3–9.5 and 11.3.1; pbrt-v4
//! `util/scattering.h`): mirror reflection, Snell refraction, the Fresnel
//! equations for dielectrics and conductors, the Henyey–Greenstein phase
//! function, and the Fresnel moments used by subsurface scattering.

use std::ops::{Add, Div, Mul, Neg, Sub};

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{spherical_direction, Frame};

use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

/// Mirror reflection of `wo` about the unit vector `n`.
#[inline]
pub fn reflect(wo: Vector3f, n: Vector3f) -> Vector3f {
    -wo + n * (2.0 * dot(wo, n))
}

/// Refraction of `wi` through an interface with normal `n` and relative
/// index of refraction `eta` (inside over outside).
///
/// When `wi` lies below the surface (opposite `n`), the interface is seen from
/// the other side: `eta` is inverted and `n` flipped. Returns the transmitted
/// direction and the relative index actually used, or `None` under total
/// internal reflection.
#[inline]
pub fn refract(wi: Vector3f, n: Normal3f, eta: Float) -> Option<(Vector3f, Float)> {
    let mut n = Vector3f::from(n);
    let mut eta = eta;
    let mut cos_theta_i = dot(n, wi);
    if cos_theta_i < 0.0 {
        eta = 1.0 / eta;
        cos_theta_i = -cos_theta_i;
        n = -n;
    }
    let sin2_theta_i = (1.0 - sqr(cos_theta_i)).max(0.0);
    let sin2_theta_t = sin2_theta_i / sqr(eta);
    if sin2_theta_t >= 1.0 {
        return None;
    }
    let cos_theta_t = safe_sqrt(1.0 - sin2_theta_t);
    let wt = -wi / eta + n * (cos_theta_i / eta - cos_theta_t);
    Some((wt, eta))
}

/// Unpolarized Fresnel reflectance of a dielectric interface with relative
/// index `eta` for incident cosine `cos_theta_i` (negative: from inside).
#[inline]
pub fn fr_dielectric(cos_theta_i: Float, eta: Float) -> Float {
    let mut cos_theta_i = clamp(cos_theta_i, -1.0, 1.0);
    let mut eta = eta;
    if cos_theta_i < 0.0 {
        eta = 1.0 / eta;
        cos_theta_i = -cos_theta_i;
    }
    let sin2_theta_i = 1.0 - sqr(cos_theta_i);
    let sin2_theta_t = sin2_theta_i / sqr(eta);
    if sin2_theta_t >= 1.0 {
        return 1.0;
    }
    let cos_theta_t = safe_sqrt(1.0 - sin2_theta_t);
    let r_parl = (eta * cos_theta_i - cos_theta_t) / (eta * cos_theta_i + cos_theta_t);
    let r_perp = (cos_theta_i - eta * cos_theta_t) / (cos_theta_i + eta * cos_theta_t);
    (sqr(r_parl) + sqr(r_perp)) / 2.0
}

/// A complex number, as the Fresnel equations for conductors need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Complex {
    /// Real part.
    pub re: Float,
    /// Imaginary part.
    pub im: Float,
}

impl Complex {
    /// `re + i im`.
    #[inline]
    pub const fn new(re: Float, im: Float) -> Self {
        Complex { re, im }
    }
    /// A real number.
    #[inline]
    pub const fn real(re: Float) -> Self {
        Complex { re, im: 0.0 }
    }
    /// The squared magnitude `re² + im²`.
    #[inline]
    pub fn norm(self) -> Float {
        sqr(self.re) + sqr(self.im)
    }
    /// The magnitude, `√(re² + im²)` as pbrt-v4's `pstd::abs` computes it
    /// (not `hypot`: the Fresnel terms never come near overflow, and
    /// libm's `hypotf` alone took over 1% of a coated conductor's render).
    #[inline]
    pub fn abs(self) -> Float {
        self.norm().sqrt()
    }
    /// The principal square root (non-negative real part). Both branches
    /// are computed and one selected, so that [`fr_complex_spectrum`]'s
    /// loop over wavelengths compiles to vector instructions.
    #[inline]
    pub fn sqrt(self) -> Complex {
        let n = self.abs();
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        let root = if self.re >= 0.0 {
            Complex::new(t1, t2)
        } else {
            Complex::new(t2.abs(), t1.copysign(self.im))
        };
        if n == 0.0 {
            Complex::real(0.0)
        } else {
            root
        }
    }
}

impl Add for Complex {
    type Output = Complex;
    #[inline]
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
}
impl Sub for Complex {
    type Output = Complex;
    #[inline]
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
}
impl Mul for Complex {
    type Output = Complex;
    #[inline]
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}
impl Div for Complex {
    type Output = Complex;
    #[inline]
    fn div(self, o: Complex) -> Complex {
        let scale = 1.0 / o.norm();
        Complex::new(
            scale * (self.re * o.re + self.im * o.im),
            scale * (self.im * o.re - self.re * o.im),
        )
    }
}
impl Neg for Complex {
    type Output = Complex;
    #[inline]
    fn neg(self) -> Complex {
        Complex::new(-self.re, -self.im)
    }
}
impl Mul<Float> for Complex {
    type Output = Complex;
    #[inline]
    fn mul(self, s: Float) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }
}
impl Mul<Complex> for Float {
    type Output = Complex;
    #[inline]
    fn mul(self, c: Complex) -> Complex {
        c * self
    }
}
impl Add<Complex> for Float {
    type Output = Complex;
    #[inline]
    fn add(self, c: Complex) -> Complex {
        Complex::new(self + c.re, c.im)
    }
}
impl Sub<Complex> for Float {
    type Output = Complex;
    #[inline]
    fn sub(self, c: Complex) -> Complex {
        Complex::new(self - c.re, -c.im)
    }
}
impl Div<Complex> for Float {
    type Output = Complex;
    #[inline]
    fn div(self, c: Complex) -> Complex {
        Complex::real(self) / c
    }
}

/// Fresnel reflectance of a conductor with complex relative index
/// `eta = η + i k`; the cosine is clamped to [0, 1].
#[inline]
pub fn fr_complex(cos_theta_i: Float, eta: Complex) -> Float {
    let cos_theta_i = clamp(cos_theta_i, 0.0, 1.0);
    let sin2_theta_i = 1.0 - sqr(cos_theta_i);
    let sin2_theta_t = sin2_theta_i / (eta * eta);
    let cos_theta_t = (1.0 - sin2_theta_t).sqrt();
    let r_parl = (eta * cos_theta_i - cos_theta_t) / (eta * cos_theta_i + cos_theta_t);
    let r_perp = (cos_theta_i - eta * cos_theta_t) / (cos_theta_i + eta * cos_theta_t);
    (r_parl.norm() + r_perp.norm()) / 2.0
}

/// [`fr_complex`] at each sampled wavelength, with `eta` and `k` the real
/// and imaginary parts of the conductor's index.
#[inline]
pub fn fr_complex_spectrum(
    cos_theta_i: Float,
    eta: SampledSpectrum,
    k: SampledSpectrum,
) -> SampledSpectrum {
    let mut r = SampledSpectrum::new(0.0);
    for i in 0..N_SPECTRUM_SAMPLES {
        r[i] = fr_complex(cos_theta_i, Complex::new(eta[i], k[i]));
    }
    r
}

/// The Henyey–Greenstein phase function for the cosine between the two
/// directions (both pointing away), with asymmetry `g`; `g > 0` scatters
/// forward, i.e. peaks at cosine −1.
#[inline]
pub fn henyey_greenstein(cos_theta: Float, g: Float) -> Float {
    let denom = 1.0 + sqr(g) + 2.0 * g * cos_theta;
    INV_4PI * (1.0 - sqr(g)) / (denom * safe_sqrt(denom))
}

/// Samples the Henyey–Greenstein phase function for outgoing direction
/// `wo`; returns the incident direction and its density (which equals the
/// phase function's value).
#[inline]
pub fn sample_henyey_greenstein(wo: Vector3f, g: Float, u: Point2f) -> (Vector3f, Float) {
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u.x
    } else {
        -1.0 / (2.0 * g) * (1.0 + sqr(g) - sqr((1.0 - sqr(g)) / (1.0 + g - 2.0 * g * u.x)))
    };
    let sin_theta = safe_sqrt(1.0 - sqr(cos_theta));
    let phi = 2.0 * PI * u.y;
    let frame = Frame::from_z(wo);
    let wi = frame.from_local(spherical_direction(sin_theta, cos_theta, phi));
    (wi, henyey_greenstein(cos_theta, g))
}

/// First Fresnel moment ∫₀¹ Fr(μ, 1/η) μ dμ, with `Fr` as
/// [`fr_dielectric`] computes it (polynomial fit of d'Eon and Irving, as
/// pbrt uses it: note the argument is the inverse of `fr_dielectric`'s).
pub fn fresnel_moment1(eta: Float) -> Float {
    let eta2 = eta * eta;
    let eta3 = eta2 * eta;
    let eta4 = eta3 * eta;
    let eta5 = eta4 * eta;
    if eta < 1.0 {
        0.45966 - 1.73965 * eta + 3.37668 * eta2 - 3.904945 * eta3 + 2.49277 * eta4 - 0.68441 * eta5
    } else {
        -4.61686 + 11.1136 * eta - 10.4646 * eta2 + 5.11455 * eta3 - 1.27198 * eta4 + 0.12746 * eta5
    }
}

/// Second Fresnel moment ∫₀¹ Fr(μ, 1/η) μ² dμ (polynomial fit, d'Eon and
/// Irving).
pub fn fresnel_moment2(eta: Float) -> Float {
    let eta2 = eta * eta;
    let eta3 = eta2 * eta;
    let eta4 = eta3 * eta;
    let eta5 = eta4 * eta;
    if eta < 1.0 {
        0.27614 - 0.87350 * eta + 1.12077 * eta2 - 0.65095 * eta3 + 0.07883 * eta4 + 0.04860 * eta5
    } else {
        let r_eta = 1.0 / eta;
        let r_eta2 = r_eta * r_eta;
        let r_eta3 = r_eta2 * r_eta;
        -547.033 + 45.3087 * r_eta3 - 218.725 * r_eta2 + 458.843 * r_eta + 404.557 * eta
            - 189.519 * eta2
            + 54.9327 * eta3
            - 9.00603 * eta4
            + 0.63942 * eta5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use rpbrt_geometry::sin_theta;

    fn rand_dir(rng: &mut Rng) -> Vector3f {
        crate::sampling::sample_uniform_sphere(Point2f::new(
            rng.uniform_float(),
            rng.uniform_float(),
        ))
    }

    #[test]
    fn complex_sqrt_is_the_principal_root() {
        assert_eq!(Complex::real(0.0).sqrt(), Complex::real(0.0));
        let mut rng = Rng::new(7, 0);
        for _ in 0..1000 {
            let z = Complex::new(
                20.0 * rng.uniform_float() - 10.0,
                20.0 * rng.uniform_float() - 10.0,
            );
            let r = z.sqrt();
            assert!(r.re >= 0.0, "{z:?} -> {r:?}");
            let back = r * r;
            let tol = 1e-5 * (1.0 + z.abs());
            assert!((back.re - z.re).abs() < tol && (back.im - z.im).abs() < tol);
        }
        // On the negative real axis the root is +i√|x| (the sign of +0).
        let r = Complex::new(-4.0, 0.0).sqrt();
        assert_eq!((r.re, r.im), (0.0, 2.0));
        assert_eq!(Complex::new(3.0, -4.0).abs(), 5.0);
    }

    #[test]
    fn fresnel_normal_incidence() {
        for eta in [1.0, 1.33, 1.5, 2.4] {
            let expect = sqr((eta - 1.0) / (eta + 1.0));
            assert!((fr_dielectric(1.0, eta) - expect).abs() < 1e-6);
            assert!((fr_dielectric(-1.0, eta) - expect).abs() < 1e-6);
            // A conductor with k = 0 is a dielectric.
            let c = fr_complex(1.0, Complex::real(eta));
            assert!((c - expect).abs() < 1e-6, "{c} vs {expect}");
        }
        // Grazing incidence reflects everything.
        assert!((fr_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn fresnel_total_internal_reflection() {
        let eta: Float = 1.5;
        let critical = (1.0 / eta).asin();
        // Inside the denser medium, beyond the critical angle.
        let cos_beyond = -(critical + 0.05).cos();
        assert_eq!(fr_dielectric(cos_beyond, eta), 1.0);
        let cos_before = -(critical - 0.05).cos();
        assert!(fr_dielectric(cos_before, eta) < 1.0);
        let w = Vector3f::new((critical + 0.05).sin(), 0.0, -(critical + 0.05).cos());
        assert!(refract(w, Normal3f::new(0.0, 0.0, 1.0), eta).is_none());
    }

    #[test]
    fn fresnel_dielectric_matches_complex_everywhere() {
        let mut rng = Rng::new(3, 0);
        for _ in 0..1000 {
            let c = rng.uniform_float();
            let eta = 1.0 + 2.0 * rng.uniform_float();
            let a = fr_dielectric(c, eta);
            let b = fr_complex(c, Complex::real(eta));
            assert!((a - b).abs() < 1e-4, "cos {c} eta {eta}: {a} vs {b}");
        }
        // Conductors reflect more than the lossless dielectric of the same η.
        assert!(fr_complex(0.7, Complex::new(1.5, 3.0)) > fr_dielectric(0.7, 1.5));
        // Gold-like values at normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
        let (n, k) = (0.2, 3.0);
        let expect = (sqr(n - 1.0) + sqr(k)) / (sqr(n + 1.0) + sqr(k));
        assert!((fr_complex(1.0, Complex::new(n, k)) - expect).abs() < 1e-5);
    }

    #[test]
    fn reflect_refract_identities() {
        let mut rng = Rng::new(4, 0);
        let n = Normal3f::new(0.0, 0.0, 1.0);
        for _ in 0..1000 {
            let w = rand_dir(&mut rng);
            let r = reflect(w, Vector3f::new(0.0, 0.0, 1.0));
            assert!((r - Vector3f::new(-w.x, -w.y, w.z)).length() < 1e-5);
            let eta = 1.0 + rng.uniform_float();
            if let Some((wt, etap)) = refract(w, n, eta) {
                assert!((wt.length() - 1.0).abs() < 1e-4);
                // Opposite hemisphere, Snell's law, coplanarity.
                assert!(wt.z * w.z <= 0.0);
                let sin_i = sin_theta(w);
                let sin_t = sin_theta(wt);
                assert!((sin_i - etap * sin_t).abs() < 1e-4);
                assert!(cross(w, wt).z.abs() < 1e-4 || (w.x * wt.y - w.y * wt.x).abs() < 1e-4);
                assert_eq!(etap, if w.z > 0.0 { eta } else { 1.0 / eta });
                // Refracting back returns the original direction.
                let (back, etab) = refract(wt, n, eta).expect("reverse path exists");
                assert!((back - w).length() < 2e-3, "{w:?} {back:?}");
                assert!((etab * etap - 1.0).abs() < 1e-5);
            } else {
                assert!(w.z < 0.0);
            }
        }
    }

    #[test]
    fn henyey_greenstein_normalized_and_sampled() {
        let mut rng = Rng::new(5, 0);
        for g in [-0.7, -0.2, 0.0, 0.3, 0.85] {
            // ∫ p dω = 1 by uniform sampling.
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let w = rand_dir(&mut rng);
                sum += (henyey_greenstein(w.z, g) / INV_4PI) as f64;
            }
            let integral = sum / n as f64;
            assert!((integral - 1.0).abs() < 0.03, "g {g}: {integral}");
            // Sampled directions: density matches, and mean cosine
            // between -wo and wi is g.
            let wo = Vector3f::new(0.3, -0.4, 0.866).normalize();
            let mut mean = 0.0f64;
            for _ in 0..n {
                let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
                let (wi, pdf) = sample_henyey_greenstein(wo, g, u);
                assert!((pdf - henyey_greenstein(dot(wo, wi), g)).abs() <= 1e-3 * pdf.max(1.0));
                mean += dot(-wo, wi) as f64;
            }
            let mean = mean / n as f64;
            assert!((mean - g as f64).abs() < 0.01, "g {g}: mean cos {mean}");
        }
    }

    #[test]
    fn fresnel_moments_match_integrals() {
        for eta in [0.7, 1.0, 1.33, 1.5, 2.0] {
            let n = 100_000;
            let (mut m1, mut m2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let c = (i as Float + 0.5) / n as Float;
                let f = fr_dielectric(c, 1.0 / eta) as f64;
                m1 += f * c as f64;
                m2 += f * (c * c) as f64;
            }
            let (m1, m2) = (m1 / n as f64, m2 / n as f64);
            assert!(
                (m1 - fresnel_moment1(eta) as f64).abs() < 3e-3,
                "eta {eta}: {m1}"
            );
            assert!(
                (m2 - fresnel_moment2(eta) as f64).abs() < 5e-3,
                "eta {eta}: {m2}"
            );
        }
    }

    #[test]
    fn complex_sqrt() {
        for (re, im) in [
            (4.0, 0.0),
            (-4.0, 0.0),
            (3.0, 4.0),
            (-3.0, -4.0),
            (0.0, 2.0),
        ] {
            let z = Complex::new(re, im);
            let s = z.sqrt();
            let back = s * s;
            assert!((back - z).abs() < 1e-5, "{z:?}");
            assert!(s.re >= 0.0);
        }
    }
}
