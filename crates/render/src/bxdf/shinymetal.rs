//! pbrt-v1/v2's `shinymetal` (pbrt-v2 `materials/shinymetal.cpp`, the
//! same in pbrt-v1), which pbrt-v3 dropped: a glossy Torrance–Sparrow lobe
//! with Blinn's microfacet distribution over a perfect mirror, each with
//! the conductor Fresnel term of a metal whose index pbrt-v2 derived from
//! a reflectance colour (`FresnelApproxEta`, absorption 0).
//!
//! pbrt-v2's `BSDF` held the two as separate BxDFs; [`ShinyMetalBxDF`]
//! keeps its composite: `f` and `pdf` are the glossy lobe's (a mirror
//! contributes only along its delta direction), `sample_f` picks each lobe
//! with probability ½ and halves the densities, as pbrt-v2's
//! `BSDF::Sample_f` did over two matching components.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta, same_hemisphere, spherical_direction};

use super::scattering::reflect;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::SampledSpectrum;

/// The largest Blinn exponent pbrt-v2 used (a larger one, or NaN, from a
/// tiny roughness was clamped to it).
const MAX_EXPONENT: Float = 10_000.0;

/// pbrt-v2's `FresnelApproxEta`: the real index of a conductor without
/// absorption that reflects `r` at normal incidence.
pub fn fresnel_approx_eta(r: SampledSpectrum) -> SampledSpectrum {
    r.map(|r| {
        let s = r.clamp(0.0, 0.999).sqrt();
        (1.0 + s) / (1.0 - s)
    })
}

/// pbrt-v2's conductor Fresnel reflectance (`FrCond`, its approximation
/// for a complex index `η + i k`, here with `k = 0`) at `|cos θ|`.
pub fn fr_cond_v2(cos_i: Float, eta: SampledSpectrum) -> SampledSpectrum {
    let c = cos_i.abs();
    eta.map(|e| {
        let tmp = e * e * c * c;
        let r_parl2 = (tmp - 2.0 * e * c + 1.0) / (tmp + 2.0 * e * c + 1.0);
        let tmp_f = e * e;
        let r_perp2 = (tmp_f - 2.0 * e * c + c * c) / (tmp_f + 2.0 * e * c + c * c);
        0.5 * (r_parl2 + r_perp2)
    })
}

/// `shinymetal` at a point: the glossy lobe's reflectance `ks` and
/// Fresnel index `eta_s`, the mirror's `kr` and `eta_r`, and the Blinn
/// exponent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShinyMetalBxDF {
    eta_s: SampledSpectrum,
    eta_r: SampledSpectrum,
    exponent: Float,
}

impl ShinyMetalBxDF {
    /// pbrt-v2's construction: the glossy lobe's Fresnel index from `ks`,
    /// the mirror's from `kr` (each lobe scaled by 1), exponent
    /// `1 / roughness`.
    pub fn new(ks: SampledSpectrum, kr: SampledSpectrum, roughness: Float) -> Self {
        let e = 1.0 / roughness;
        ShinyMetalBxDF {
            eta_s: fresnel_approx_eta(ks),
            eta_r: fresnel_approx_eta(kr),
            exponent: if e > MAX_EXPONENT || e.is_nan() {
                MAX_EXPONENT
            } else {
                e
            },
        }
    }

    /// Blinn's distribution of microfacet normals `wh`.
    fn d(&self, wh: Vector3f) -> Float {
        (self.exponent + 2.0) * INV_2PI * abs_cos_theta(wh).powf(self.exponent)
    }

    /// pbrt-v2's Torrance–Sparrow shadowing–masking term.
    fn g(wo: Vector3f, wi: Vector3f, wh: Vector3f) -> Float {
        let n_dot_wh = abs_cos_theta(wh);
        let wo_dot_wh = wo.dot(wh).abs();
        (2.0 * n_dot_wh * abs_cos_theta(wo) / wo_dot_wh)
            .min(2.0 * n_dot_wh * abs_cos_theta(wi) / wo_dot_wh)
            .min(1.0)
    }

    /// The glossy lobe's value.
    fn glossy_f(&self, wo: Vector3f, wi: Vector3f) -> SampledSpectrum {
        let (cos_o, cos_i) = (abs_cos_theta(wo), abs_cos_theta(wi));
        if cos_i == 0.0 || cos_o == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        let wh = wi + wo;
        if wh.x == 0.0 && wh.y == 0.0 && wh.z == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        let wh = wh.normalize();
        let f = fr_cond_v2(wi.dot(wh), self.eta_s);
        f * (self.d(wh) * Self::g(wo, wi, wh) / (4.0 * cos_i * cos_o))
    }

    /// The glossy lobe's density (Blinn's half-vector density turned into
    /// one of `wi`).
    fn glossy_pdf(&self, wo: Vector3f, wi: Vector3f) -> Float {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let wh = (wo + wi).normalize();
        let cos_h = abs_cos_theta(wh);
        let wo_dot_wh = wo.dot(wh);
        if wo_dot_wh <= 0.0 {
            return 0.0;
        }
        (self.exponent + 1.0) * cos_h.powf(self.exponent) / (2.0 * PI * 4.0 * wo_dot_wh)
    }
}

impl BxDFMethods for ShinyMetalBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        // pbrt-v2 evaluated reflection lobes wherever the geometric normal
        // saw both directions on one side; with shading normals alone, as
        // here, that is the shading hemisphere.
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        self.glossy_f(wo, wi)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) || wo.z == 0.0 {
            return None;
        }
        if uc < 0.5 {
            // The mirror.
            let wi = Vector3f::new(-wo.x, -wo.y, wo.z);
            let f = fr_cond_v2(cos_theta(wi), self.eta_r) / abs_cos_theta(wi);
            return Some(BSDFSample::new(f, wi, 0.5, BxDFFlags::SPECULAR_REFLECTION));
        }
        // Blinn's half vector, on the side of wo.
        let cos_t = u[0].powf(1.0 / (self.exponent + 1.0));
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let mut wh = spherical_direction(sin_t, cos_t, 2.0 * PI * u[1]);
        if !same_hemisphere(wo, wh) {
            wh = -wh;
        }
        let wi = reflect(wo, wh);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let pdf = 0.5 * self.glossy_pdf(wo, wi);
        if pdf == 0.0 {
            return None;
        }
        Some(BSDFSample::new(
            self.glossy_f(wo, wi),
            wi,
            pdf,
            BxDFFlags::GLOSSY_REFLECTION,
        ))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
            return 0.0;
        }
        0.5 * self.glossy_pdf(wo, wi)
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::GLOSSY_REFLECTION | BxDFFlags::SPECULAR_REFLECTION
    }

    fn regularize(&mut self) {
        // pbrt-v4 doubles a near-specular lobe's roughness: the Blinn
        // exponent of the doubled roughness.
        self.exponent = (self.exponent * 0.5).max(1.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bxdf::rho_hd;

    fn spectrum(v: Float) -> SampledSpectrum {
        SampledSpectrum::new(v)
    }

    #[test]
    fn approx_eta_reflects_the_colour_at_normal_incidence() {
        for r in [0.05, 0.3, 0.8, 0.95] {
            let eta = fresnel_approx_eta(spectrum(r));
            let f = fr_cond_v2(1.0, eta);
            assert!((f.values[0] - r).abs() < 1e-5, "{r}: {}", f.values[0]);
        }
        // Grazing: a conductor reflects everything.
        let f = fr_cond_v2(0.0, fresnel_approx_eta(spectrum(0.3)));
        assert!((f.values[0] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sampling_matches_f_and_pdf_and_conserves_energy() {
        let b = ShinyMetalBxDF::new(spectrum(0.6), spectrum(0.4), 0.1);
        let wo = Vector3f::new(0.3, -0.2, 0.8).normalize();
        let n = 64;
        let mut uc = Vec::new();
        let mut u2 = Vec::new();
        for i in 0..n {
            for j in 0..n {
                uc.push(((i * n + j) as Float + 0.5) / (n * n) as Float);
                u2.push(Point2f::new(
                    (i as Float + 0.5) / n as Float,
                    (j as Float + 0.5) / n as Float,
                ));
            }
        }
        let rho = rho_hd(&b, wo, &uc, &u2).values[0];
        // The mirror reflects its Fresnel term exactly; the glossy lobe
        // about Ks (its Fresnel term near the mirror direction's half
        // vector, a little more toward grazing, less the shadowing).
        let mirror = fr_cond_v2(cos_theta(wo), fresnel_approx_eta(spectrum(0.4))).values[0];
        let glossy = rho - mirror;
        assert!(glossy > 0.5 && glossy < 0.75, "{rho} {mirror}");
        for (&c, &u) in uc.iter().zip(&u2).step_by(97) {
            let Some(s) = b.sample_f(wo, c, u, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            else {
                continue;
            };
            if s.flags == BxDFFlags::GLOSSY_REFLECTION {
                let f = b.f(wo, s.wi, TransportMode::Radiance);
                let pdf = b.pdf(wo, s.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
                assert!((f.values[0] - s.f.values[0]).abs() <= 1e-4 * f.values[0].max(1.0));
                assert!((pdf - s.pdf).abs() <= 1e-4 * pdf.max(1.0));
            }
        }
    }

    #[test]
    fn blinn_density_integrates_to_one() {
        // ∫ D(wh) cos θh dωh = 1 over the hemisphere (midpoint rule).
        let b = ShinyMetalBxDF::new(spectrum(0.5), spectrum(0.5), 0.05);
        let n = 400;
        let mut sum = 0.0f64;
        for i in 0..n {
            let cos_t = (i as Float + 0.5) / n as Float;
            let wh = Vector3f::new((1.0 - cos_t * cos_t).sqrt(), 0.0, cos_t);
            sum += (b.d(wh) * cos_t) as f64 * 2.0 * std::f64::consts::PI / n as f64;
        }
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    }
}
