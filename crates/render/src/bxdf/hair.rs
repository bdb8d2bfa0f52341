//! Hair scattering (pbrt-v4 book section 9.9, after Chiang et al. 2016;
//! pbrt-v4 `bxdfs.h`, `bxdfs.cpp`): a dielectric cylinder with absorbing
//! interior, tilted cuticle scales, longitudinal lobes M_p, attenuation
//! A_p and azimuthal trimmed-logistic lobes N_p for p = 0 (R), 1 (TT),
//! 2 (TRT) plus a lumped remainder.
//!
//! Local frame: x runs along the hair (so `wo.x` is sin θo), and the
//! azimuth is measured in the y–z plane.

use rpbrt_geometry::abs_cos_theta;
use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use super::scattering::fr_dielectric;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES, RGB};

/// Scattering orders modelled explicitly.
const P_MAX: usize = 3;

/// Modified Bessel function of the first kind, order 0 (series).
fn i0(x: Float) -> Float {
    let mut val = 0.0;
    let mut x2i = 1.0;
    let mut ifact: i64 = 1;
    let mut i4: i64 = 1;
    for i in 0..10 {
        if i > 1 {
            ifact *= i;
        }
        val += x2i / (i4 as Float * sqr(ifact as Float));
        x2i *= x * x;
        i4 *= 4;
    }
    val
}

/// log I0(x), with the asymptotic expansion for large x.
fn log_i0(x: Float) -> Float {
    if x > 12.0 {
        x + 0.5 * (-(2.0 * PI).ln() + (1.0 / x).ln() + 1.0 / (8.0 * x))
    } else {
        i0(x).ln()
    }
}

/// The logistic density with scale `s`.
#[inline]
fn logistic(x: Float, s: Float) -> Float {
    let x = x.abs();
    (-x / s).exp() / (s * sqr(1.0 + (-x / s).exp()))
}

/// The logistic cumulative distribution.
#[inline]
fn logistic_cdf(x: Float, s: Float) -> Float {
    1.0 / (1.0 + (-x / s).exp())
}

/// The logistic density renormalized to [a, b].
#[inline]
fn trimmed_logistic(x: Float, s: Float, a: Float, b: Float) -> Float {
    logistic(x, s) / (logistic_cdf(b, s) - logistic_cdf(a, s))
}

/// Samples [`trimmed_logistic`] by inverting its CDF.
#[inline]
fn sample_trimmed_logistic(u: Float, s: Float, a: Float, b: Float) -> Float {
    let u = lerp(u, logistic_cdf(a, s), logistic_cdf(b, s));
    let x = -s * (1.0 / u - 1.0).ln();
    clamp(x, a, b)
}

/// Chooses an index with probability proportional to `weights`; returns it
/// and `u` remapped to [0, 1).
fn sample_discrete(weights: &[Float], u: Float) -> (usize, Float) {
    let sum: Float = weights.iter().sum();
    let mut up = u * sum;
    if up == sum {
        up = next_float_down(up);
    }
    let mut i = 0;
    let mut acc = 0.0;
    while i + 1 < weights.len() && acc + weights[i] <= up {
        acc += weights[i];
        i += 1;
    }
    let remapped = if weights[i] > 0.0 {
        ((up - acc) / weights[i]).min(ONE_MINUS_EPSILON)
    } else {
        0.0
    };
    (i, remapped)
}

/// The hair BSDF of Chiang et al.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairBxDF {
    h: Float,
    eta: Float,
    sigma_a: SampledSpectrum,
    beta_m: Float,
    beta_n: Float,
    v: [Float; P_MAX + 1],
    s: Float,
    sin_2k_alpha: [Float; P_MAX],
    cos_2k_alpha: [Float; P_MAX],
}

impl HairBxDF {
    /// A hair fiber hit at offset `h` ∈ [−1, 1] across its width, with index
    /// `eta`, absorption `sigma_a`, longitudinal and azimuthal roughness
    /// `beta_m`, `beta_n` ∈ [0, 1] and scale tilt `alpha` in degrees.
    /// Out-of-range `h`, `beta_m` and `beta_n` are clamped.
    pub fn new(
        h: Float,
        eta: Float,
        sigma_a: SampledSpectrum,
        beta_m: Float,
        beta_n: Float,
        alpha: Float,
    ) -> Self {
        debug_assert!((-1.0..=1.0).contains(&h));
        let h = clamp(h, -1.0, 1.0);
        let beta_m = clamp(beta_m, 0.0, 1.0);
        let beta_n = clamp(beta_n, 0.0, 1.0);
        let v0 = sqr(0.726 * beta_m + 0.812 * sqr(beta_m) + 3.7 * beta_m.powi(20));
        let v = [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0];
        const SQRT_PI_OVER_8: Float = 0.626_657_07;
        let s = SQRT_PI_OVER_8 * (0.265 * beta_n + 1.194 * sqr(beta_n) + 5.372 * beta_n.powi(22));
        let mut sin_2k_alpha = [0.0; P_MAX];
        let mut cos_2k_alpha = [0.0; P_MAX];
        sin_2k_alpha[0] = radians(alpha).sin();
        cos_2k_alpha[0] = safe_sqrt(1.0 - sqr(sin_2k_alpha[0]));
        for i in 1..P_MAX {
            sin_2k_alpha[i] = 2.0 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
            cos_2k_alpha[i] = sqr(cos_2k_alpha[i - 1]) - sqr(sin_2k_alpha[i - 1]);
        }
        HairBxDF {
            h,
            eta,
            sigma_a,
            beta_m,
            beta_n,
            v,
            s,
            sin_2k_alpha,
            cos_2k_alpha,
        }
    }

    /// Longitudinal variances v[p].
    pub fn longitudinal_variances(&self) -> [Float; P_MAX + 1] {
        self.v
    }

    /// Azimuthal logistic scale s.
    pub fn azimuthal_scale(&self) -> Float {
        self.s
    }

    /// The longitudinal roughness β_m.
    pub fn beta_m(&self) -> Float {
        self.beta_m
    }

    /// The azimuthal roughness β_n.
    pub fn beta_n(&self) -> Float {
        self.beta_n
    }

    /// Absorption coefficients (in sRGB) for eumelanin and pheomelanin
    /// concentrations `ce`, `cp`; the caller turns them into an unbounded
    /// RGB spectrum as pbrt-v4 does.
    pub fn sigma_a_from_concentration(ce: Float, cp: Float) -> RGB {
        let eu = [0.419, 0.697, 1.37];
        let pheo = [0.187, 0.4, 1.05];
        RGB::new(
            ce * eu[0] + cp * pheo[0],
            ce * eu[1] + cp * pheo[1],
            ce * eu[2] + cp * pheo[2],
        )
    }

    /// Absorption that yields approximately the diffuse colour `c` for
    /// azimuthal roughness `beta_n` (Chiang et al.'s fit).
    pub fn sigma_a_from_reflectance(c: SampledSpectrum, beta_n: Float) -> SampledSpectrum {
        let denom = 5.969 - 0.215 * beta_n + 2.532 * sqr(beta_n) - 10.73 * beta_n.powi(3)
            + 5.574 * beta_n.powi(4)
            + 0.245 * beta_n.powi(5);
        let mut s = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            s[i] = sqr(c[i].ln() / denom);
        }
        s
    }

    /// The longitudinal scattering function M_p.
    // pbrt-v4 uses the rounded constant 0.6931 (≈ ln 2) here; keep it.
    #[allow(clippy::approx_constant)]
    fn mp(cos_i: Float, cos_o: Float, sin_i: Float, sin_o: Float, v: Float) -> Float {
        let a = cos_i * cos_o / v;
        let b = sin_i * sin_o / v;
        if v <= 0.1 {
            (log_i0(a) - b - 1.0 / v + 0.6931 + (1.0 / (2.0 * v)).ln()).exp()
        } else {
            ((-b).exp() * i0(a)) / ((1.0 / v).sinh() * 2.0 * v)
        }
    }

    /// Attenuation A_p for each scattering order.
    fn ap(
        cos_theta_o: Float,
        eta: Float,
        h: Float,
        t: SampledSpectrum,
    ) -> [SampledSpectrum; P_MAX + 1] {
        let mut ap = [SampledSpectrum::new(0.0); P_MAX + 1];
        let cos_gamma_o = safe_sqrt(1.0 - sqr(h));
        let f = fr_dielectric(cos_theta_o * cos_gamma_o, eta);
        ap[0] = SampledSpectrum::new(f);
        ap[1] = t * sqr(1.0 - f);
        for p in 2..P_MAX {
            ap[p] = ap[p - 1] * t * f;
        }
        let denom = 1.0 - t * f;
        if !denom.is_black() {
            ap[P_MAX] = ap[P_MAX - 1] * t * f / denom;
        }
        ap
    }

    /// Net azimuthal deflection Φ for order `p`.
    #[inline]
    fn phi(p: usize, gamma_o: Float, gamma_t: Float) -> Float {
        let p = p as Float;
        2.0 * p * gamma_t - 2.0 * gamma_o + p * PI
    }

    /// The azimuthal scattering function N_p.
    #[inline]
    fn np(phi: Float, p: usize, s: Float, gamma_o: Float, gamma_t: Float) -> Float {
        let mut dphi = phi - Self::phi(p, gamma_o, gamma_t);
        while dphi > PI {
            dphi -= 2.0 * PI;
        }
        while dphi < -PI {
            dphi += 2.0 * PI;
        }
        trimmed_logistic(dphi, s, -PI, PI)
    }

    /// sin θo and cos θo rotated by the scale tilt for order `p`.
    #[inline]
    fn tilted(&self, p: usize, sin_o: Float, cos_o: Float) -> (Float, Float) {
        let (s, c) = match p {
            0 => (
                sin_o * self.cos_2k_alpha[1] - cos_o * self.sin_2k_alpha[1],
                cos_o * self.cos_2k_alpha[1] + sin_o * self.sin_2k_alpha[1],
            ),
            1 => (
                sin_o * self.cos_2k_alpha[0] + cos_o * self.sin_2k_alpha[0],
                cos_o * self.cos_2k_alpha[0] - sin_o * self.sin_2k_alpha[0],
            ),
            2 => (
                sin_o * self.cos_2k_alpha[2] + cos_o * self.sin_2k_alpha[2],
                cos_o * self.cos_2k_alpha[2] - sin_o * self.sin_2k_alpha[2],
            ),
            _ => (sin_o, cos_o),
        };
        (s, c.abs())
    }

    /// The refracted ray's γt and the single-pass transmittance for
    /// outgoing sin θo / cos θo.
    #[inline]
    fn refracted(&self, sin_o: Float, cos_o: Float) -> (Float, SampledSpectrum) {
        let sin_t = sin_o / self.eta;
        let cos_t = safe_sqrt(1.0 - sqr(sin_t));
        let etap = safe_sqrt(sqr(self.eta) - sqr(sin_o)) / cos_o;
        let sin_gamma_t = self.h / etap;
        let cos_gamma_t = safe_sqrt(1.0 - sqr(sin_gamma_t));
        let gamma_t = safe_asin(sin_gamma_t);
        let t = (-self.sigma_a * (2.0 * cos_gamma_t / cos_t)).exp();
        (gamma_t, t)
    }

    /// Probabilities of sampling each order, from the A_p's averages.
    fn ap_pdf(&self, cos_o: Float) -> [Float; P_MAX + 1] {
        let sin_o = safe_sqrt(1.0 - sqr(cos_o));
        let (_, t) = self.refracted(sin_o, cos_o);
        let ap = Self::ap(cos_o, self.eta, self.h, t);
        let sum: Float = ap.iter().map(|a| a.average()).sum();
        let mut pdf = [0.0; P_MAX + 1];
        for (p, a) in pdf.iter_mut().zip(ap.iter()) {
            *p = a.average() / sum;
        }
        pdf
    }

    /// Density of direction `wi` given the sampling probabilities.
    fn pdf_terms(&self, wo: Vector3f, wi: Vector3f) -> Float {
        let sin_o = wo.x;
        let cos_o = safe_sqrt(1.0 - sqr(sin_o));
        let phi_o = wo.z.atan2(wo.y);
        let gamma_o = safe_asin(self.h);
        let sin_i = wi.x;
        let cos_i = safe_sqrt(1.0 - sqr(sin_i));
        let phi_i = wi.z.atan2(wi.y);
        let (gamma_t, _) = self.refracted(sin_o, cos_o);
        let ap_pdf = self.ap_pdf(cos_o);
        let phi = phi_i - phi_o;
        let mut pdf = 0.0;
        for (p, &w) in ap_pdf.iter().enumerate().take(P_MAX) {
            let (sp, cp) = self.tilted(p, sin_o, cos_o);
            pdf += Self::mp(cos_i, cp, sin_i, sp, self.v[p])
                * w
                * Self::np(phi, p, self.s, gamma_o, gamma_t);
        }
        pdf += Self::mp(cos_i, cos_o, sin_i, sin_o, self.v[P_MAX])
            * ap_pdf[P_MAX]
            * (1.0 / (2.0 * PI));
        pdf
    }
}

impl BxDFMethods for HairBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        let sin_o = wo.x;
        let cos_o = safe_sqrt(1.0 - sqr(sin_o));
        let phi_o = wo.z.atan2(wo.y);
        let gamma_o = safe_asin(self.h);
        let sin_i = wi.x;
        let cos_i = safe_sqrt(1.0 - sqr(sin_i));
        let phi_i = wi.z.atan2(wi.y);
        let (gamma_t, t) = self.refracted(sin_o, cos_o);
        let phi = phi_i - phi_o;
        let ap = Self::ap(cos_o, self.eta, self.h, t);
        let mut fsum = SampledSpectrum::new(0.0);
        for (p, a) in ap.iter().enumerate().take(P_MAX) {
            let (sp, cp) = self.tilted(p, sin_o, cos_o);
            fsum += *a
                * (Self::mp(cos_i, cp, sin_i, sp, self.v[p])
                    * Self::np(phi, p, self.s, gamma_o, gamma_t));
        }
        fsum += ap[P_MAX] * (Self::mp(cos_i, cos_o, sin_i, sin_o, self.v[P_MAX]) / (2.0 * PI));
        if abs_cos_theta(wi) > 0.0 {
            fsum /= abs_cos_theta(wi);
        }
        debug_assert!(!fsum.has_nan());
        fsum
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        _sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let sin_o = wo.x;
        let cos_o = safe_sqrt(1.0 - sqr(sin_o));
        let phi_o = wo.z.atan2(wo.y);
        let gamma_o = safe_asin(self.h);

        // Choose the scattering order, reusing uc for the azimuth.
        let ap_pdf = self.ap_pdf(cos_o);
        let (p, uc) = sample_discrete(&ap_pdf, uc);
        let (sp, cp) = self.tilted(p, sin_o, cos_o);

        // Longitudinal angle from M_p.
        let vp = self.v[p];
        let cos_theta = 1.0 + vp * (u.x.max(1e-5) + (1.0 - u.x) * (-2.0 / vp).exp()).ln();
        let sin_theta = safe_sqrt(1.0 - sqr(cos_theta));
        let cos_phi = (2.0 * PI * u.y).cos();
        let sin_i = -cos_theta * sp + sin_theta * cos_phi * cp;
        let cos_i = safe_sqrt(1.0 - sqr(sin_i));

        // Azimuthal offset from N_p.
        let (gamma_t, _) = self.refracted(sin_o, cos_o);
        let dphi = if p < P_MAX {
            Self::phi(p, gamma_o, gamma_t) + sample_trimmed_logistic(uc, self.s, -PI, PI)
        } else {
            2.0 * PI * uc
        };
        let phi_i = phi_o + dphi;
        let wi = Vector3f::new(sin_i, cos_i * phi_i.cos(), cos_i * phi_i.sin());

        let pdf = self.pdf_terms(wo, wi);
        Some(BSDFSample::new(self.f(wo, wi, mode), wi, pdf, self.flags()))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        _sample_flags: BxDFReflTransFlags,
    ) -> Float {
        self.pdf_terms(wo, wi)
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::GLOSSY_REFLECTION
    }

    fn regularize(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::{sample_uniform_sphere, UNIFORM_SPHERE_PDF};

    fn u2(rng: &mut Rng) -> Point2f {
        Point2f::new(rng.uniform_float(), rng.uniform_float())
    }

    #[test]
    fn special_functions() {
        // I0(0) = 1, I0(1) ≈ 1.2660659.
        assert!((i0(0.0) - 1.0).abs() < 1e-6);
        assert!((i0(1.0) - 1.266_066).abs() < 1e-5);
        // Reference values of ln I0 from a long double-precision series.
        assert!((log_i0(2.0) - 0.823_993_5).abs() < 1e-5);
        // pbrt-v4's large-argument expansion halves the 1/(8x) term, so it
        // is off by ~5e-3 at x = 13; we keep pbrt's formula.
        assert!((log_i0(13.0) - 10.808_606).abs() < 1e-2);
        // The trimmed logistic integrates to one over [-π, π].
        let n = 20_000;
        let mut s = 0.0;
        for i in 0..n {
            let x = -PI + 2.0 * PI * (i as Float + 0.5) / n as Float;
            s += trimmed_logistic(x, 0.3, -PI, PI);
        }
        assert!((s * 2.0 * PI / n as Float - 1.0).abs() < 1e-3);
        // Its sampling inverts the CDF: the median is 0.
        assert!(sample_trimmed_logistic(0.5, 0.3, -PI, PI).abs() < 1e-5);
        let (i, r) = sample_discrete(&[0.25, 0.25, 0.5], 0.6);
        assert_eq!(i, 2);
        assert!((r - 0.2).abs() < 1e-5);
    }

    #[test]
    fn white_furnace() {
        // With no absorption, ∫ f |cos θi| dωi = 1 for every wo (pbrt-v4
        // hair_test WhiteFurnace).
        let mut rng = Rng::new(21, 0);
        // As pbrt-v4's test, h is drawn afresh for every sample.
        let sigma_a = SampledSpectrum::new(0.0);
        let wo = sample_uniform_sphere(u2(&mut rng));
        let mut beta_m = 0.1;
        while beta_m < 1.0 {
            let mut beta_n = 0.1;
            while beta_n < 1.0 {
                let n = 300_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let h = -1.0 + 2.0 * rng.uniform_float();
                    let hair = HairBxDF::new(h, 1.55, sigma_a, beta_m, beta_n, 0.0);
                    let wi = sample_uniform_sphere(u2(&mut rng));
                    sum += (hair.f(wo, wi, TransportMode::Radiance)[0] * abs_cos_theta(wi)
                        / UNIFORM_SPHERE_PDF) as f64;
                }
                let avg = sum / n as f64;
                assert!(
                    (0.95..1.05).contains(&avg),
                    "beta_m {beta_m} beta_n {beta_n}: {avg}"
                );
                beta_n += 0.2;
            }
            beta_m += 0.2;
        }
    }

    #[test]
    fn white_furnace_sampled() {
        // With no absorption and no tilt, f cos / pdf ≡ 1 per sample.
        let mut rng = Rng::new(22, 0);
        let sigma_a = SampledSpectrum::new(0.0);
        for beta_m in [0.1, 0.3, 0.5, 0.7, 0.9] {
            for beta_n in [0.1, 0.3, 0.5, 0.7, 0.9] {
                let hair = HairBxDF::new(
                    -1.0 + 2.0 * rng.uniform_float(),
                    1.55,
                    sigma_a,
                    beta_m,
                    beta_n,
                    0.0,
                );
                for _ in 0..1000 {
                    let wo = sample_uniform_sphere(u2(&mut rng));
                    let uc = rng.uniform_float();
                    let bs = hair
                        .sample_f(
                            wo,
                            uc,
                            u2(&mut rng),
                            TransportMode::Radiance,
                            BxDFReflTransFlags::ALL,
                        )
                        .expect("hair always samples");
                    if bs.pdf > 0.0 {
                        let w = bs.f[0] * abs_cos_theta(bs.wi) / bs.pdf;
                        assert!(
                            (w - 1.0).abs() < 1e-3,
                            "beta_m {beta_m} beta_n {beta_n}: {w}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn pdf_integrates_to_one_and_sampling_is_consistent() {
        let mut rng = Rng::new(23, 0);
        let sigma_a = SampledSpectrum::new(0.25);
        for (beta_m, beta_n) in [(0.2, 0.3), (0.5, 0.5), (0.8, 0.2)] {
            let hair = HairBxDF::new(
                -1.0 + 2.0 * rng.uniform_float(),
                1.55,
                sigma_a,
                beta_m,
                beta_n,
                2.0,
            );
            let wo = sample_uniform_sphere(u2(&mut rng));
            let n = 100_000;
            let mut pdf_sum = 0.0f64;
            let mut f_uniform = 0.0f64;
            let mut f_importance = 0.0f64;
            for _ in 0..n {
                let wi = sample_uniform_sphere(u2(&mut rng));
                pdf_sum += (hair.pdf(wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
                    / UNIFORM_SPHERE_PDF) as f64;
                f_uniform += (hair.f(wo, wi, TransportMode::Radiance).average() * abs_cos_theta(wi)
                    / UNIFORM_SPHERE_PDF) as f64;
                let uc = rng.uniform_float();
                let bs = hair
                    .sample_f(
                        wo,
                        uc,
                        u2(&mut rng),
                        TransportMode::Radiance,
                        BxDFReflTransFlags::ALL,
                    )
                    .expect("hair always samples");
                if bs.pdf > 0.0 {
                    f_importance += (bs.f.average() * abs_cos_theta(bs.wi) / bs.pdf) as f64;
                }
            }
            let pdf_int = pdf_sum / n as f64;
            assert!((pdf_int - 1.0).abs() < 0.05, "pdf integral {pdf_int}");
            let (a, b) = (f_uniform / n as f64, f_importance / n as f64);
            assert!(
                (a - b).abs() < 0.05 * a.max(b),
                "uniform {a} importance {b}"
            );
        }
    }

    #[test]
    fn sigma_a_helpers() {
        let s = HairBxDF::sigma_a_from_concentration(1.3, 0.0);
        assert!((s.r - 1.3 * 0.419).abs() < 1e-6);
        // Whiter hair absorbs less.
        let dark = HairBxDF::sigma_a_from_reflectance(SampledSpectrum::new(0.2), 0.3);
        let light = HairBxDF::sigma_a_from_reflectance(SampledSpectrum::new(0.8), 0.3);
        assert!(dark[0] > light[0] && light[0] > 0.0);
    }
}
