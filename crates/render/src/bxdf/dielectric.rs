//! Dielectric interfaces (pbrt-v4 book sections 9.5 and 9.7; pbrt-v4
//! `bxdfs.h`, `bxdfs.cpp`): specular or rough (generalized half vector)
//! reflection and transmission, with radiance scaled by 1/η² on
//! transmission, and the thin dielectric slab with its interreflections.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta, same_hemisphere};

use super::microfacet::TrowbridgeReitzDistribution;
use super::scattering::{fr_dielectric, reflect, refract};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::SampledSpectrum;

/// Probabilities of choosing reflection (`r`) or transmission (`t`) under
/// the sampling flags.
#[inline]
fn choice(r: Float, t: Float, sample_flags: BxDFReflTransFlags) -> (Float, Float) {
    let pr = if sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
        r
    } else {
        0.0
    };
    let pt = if sample_flags.contains(BxDFReflTransFlags::TRANSMISSION) {
        t
    } else {
        0.0
    };
    (pr, pt)
}

/// A dielectric boundary with relative index `eta` (inside over outside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricBxDF {
    eta: Float,
    mf_distrib: TrowbridgeReitzDistribution,
}

impl DielectricBxDF {
    /// A dielectric interface.
    pub fn new(eta: Float, mf_distrib: TrowbridgeReitzDistribution) -> Self {
        DielectricBxDF { eta, mf_distrib }
    }

    /// The relative index of refraction.
    pub fn eta(&self) -> Float {
        self.eta
    }

    /// True when scattering is a pair of delta lobes.
    #[inline]
    fn is_specular(&self) -> bool {
        self.eta == 1.0 || self.mf_distrib.effectively_smooth()
    }

    /// The generalized half vector for the pair, facing +z, with the
    /// relative index for transmission (1 for reflection); `None` for
    /// degenerate configurations and back-facing microfacets.
    #[inline]
    fn half_vector(&self, wo: Vector3f, wi: Vector3f) -> Option<(Vector3f, Float, bool)> {
        let cos_o = cos_theta(wo);
        let cos_i = cos_theta(wi);
        let reflect = cos_i * cos_o > 0.0;
        let etap = if reflect {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let wm = wi * etap + wo;
        if cos_i == 0.0 || cos_o == 0.0 || wm.length_squared() == 0.0 {
            return None;
        }
        let wm = wm.normalize().face_forward(Vector3f::new(0.0, 0.0, 1.0));
        if dot(wm, wi) * cos_i < 0.0 || dot(wm, wo) * cos_o < 0.0 {
            return None;
        }
        Some((wm, etap, reflect))
    }
}

impl BxDFMethods for DielectricBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        if self.is_specular() {
            return SampledSpectrum::new(0.0);
        }
        let Some((wm, etap, is_reflection)) = self.half_vector(wo, wi) else {
            return SampledSpectrum::new(0.0);
        };
        let fr = fr_dielectric(dot(wo, wm), self.eta);
        let d = &self.mf_distrib;
        if is_reflection {
            SampledSpectrum::new(
                d.d(wm) * d.g(wo, wi) * fr / (4.0 * cos_theta(wi) * cos_theta(wo)).abs(),
            )
        } else {
            let denom = sqr(dot(wi, wm) + dot(wo, wm) / etap) * cos_theta(wi) * cos_theta(wo);
            let mut ft =
                d.d(wm) * (1.0 - fr) * d.g(wo, wi) * (dot(wi, wm) * dot(wo, wm) / denom).abs();
            if mode == TransportMode::Radiance {
                ft /= sqr(etap);
            }
            SampledSpectrum::new(ft)
        }
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        if self.is_specular() {
            let r = fr_dielectric(cos_theta(wo), self.eta);
            let (pr, pt) = choice(r, 1.0 - r, sample_flags);
            if pr == 0.0 && pt == 0.0 {
                return None;
            }
            if uc < pr / (pr + pt) {
                let wi = Vector3f::new(-wo.x, -wo.y, wo.z);
                let fr = SampledSpectrum::new(r / abs_cos_theta(wi));
                return Some(BSDFSample::new(
                    fr,
                    wi,
                    pr / (pr + pt),
                    BxDFFlags::SPECULAR_REFLECTION,
                ));
            }
            let (wi, etap) = refract(wo, Normal3f::new(0.0, 0.0, 1.0), self.eta)?;
            let mut ft = SampledSpectrum::new((1.0 - r) / abs_cos_theta(wi));
            if mode == TransportMode::Radiance {
                ft /= sqr(etap);
            }
            return Some(BSDFSample::with_eta(
                ft,
                wi,
                pt / (pr + pt),
                BxDFFlags::SPECULAR_TRANSMISSION,
                etap,
            ));
        }

        // Rough interface: sample a visible microfacet normal first.
        let d = &self.mf_distrib;
        let wm = d.sample_wm(wo, u);
        let r = fr_dielectric(dot(wo, wm), self.eta);
        let (pr, pt) = choice(r, 1.0 - r, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        // D(ωm) and Λ(ωo) once for the density and the value (the same
        // operations as `d.pdf` and `d.d`·`d.g`).
        let dm = d.d(wm);
        let lambda_o = d.lambda(wo);
        let d_visible = (1.0 / (1.0 + lambda_o)) / abs_cos_theta(wo) * dm * abs_dot(wo, wm);
        if uc < pr / (pr + pt) {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            let pdf = d_visible / (4.0 * abs_dot(wo, wm)) * pr / (pr + pt);
            let f = SampledSpectrum::new(
                dm * (1.0 / (1.0 + lambda_o + d.lambda(wi))) * r
                    / (4.0 * cos_theta(wi) * cos_theta(wo)),
            );
            Some(BSDFSample::new(f, wi, pdf, BxDFFlags::GLOSSY_REFLECTION))
        } else {
            let (wi, etap) = refract(wo, Normal3f::from(wm), self.eta)?;
            if same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            let denom = sqr(dot(wi, wm) + dot(wo, wm) / etap);
            let dwm_dwi = abs_dot(wi, wm) / denom;
            let pdf = d_visible * dwm_dwi * pt / (pr + pt);
            let mut ft = (1.0 - r)
                * dm
                * (1.0 / (1.0 + lambda_o + d.lambda(wi)))
                * (dot(wi, wm) * dot(wo, wm) / (cos_theta(wi) * cos_theta(wo) * denom)).abs();
            if mode == TransportMode::Radiance {
                ft /= sqr(etap);
            }
            Some(BSDFSample::with_eta(
                SampledSpectrum::new(ft),
                wi,
                pdf,
                BxDFFlags::GLOSSY_TRANSMISSION,
                etap,
            ))
        }
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if self.is_specular() {
            return 0.0;
        }
        let Some((wm, etap, is_reflection)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = fr_dielectric(dot(wo, wm), self.eta);
        let (pr, pt) = choice(r, 1.0 - r, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        let d = &self.mf_distrib;
        if is_reflection {
            d.pdf(wo, wm) / (4.0 * abs_dot(wo, wm)) * pr / (pr + pt)
        } else {
            let denom = sqr(dot(wi, wm) + dot(wo, wm) / etap);
            let dwm_dwi = abs_dot(wi, wm) / denom;
            d.pdf(wo, wm) * dwm_dwi * pt / (pr + pt)
        }
    }

    fn flags(&self) -> BxDFFlags {
        let lobes = if self.eta == 1.0 {
            BxDFFlags::TRANSMISSION
        } else {
            BxDFFlags::REFLECTION | BxDFFlags::TRANSMISSION
        };
        lobes
            | if self.mf_distrib.effectively_smooth() {
                BxDFFlags::SPECULAR
            } else {
                BxDFFlags::GLOSSY
            }
    }

    fn regularize(&mut self) {
        self.mf_distrib.regularize();
    }
}

/// A thin dielectric slab: specular reflection and straight-through
/// transmission, summing the light bounced between its two faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectricBxDF {
    eta: Float,
}

impl ThinDielectricBxDF {
    /// A slab of relative index `eta`.
    pub fn new(eta: Float) -> Self {
        ThinDielectricBxDF { eta }
    }

    /// Total reflectance and transmittance of the slab at `cos_theta`:
    /// R' = R + T²R / (1 − R²), T' = 1 − R'.
    pub fn reflectance_transmittance(&self, cos_theta: Float) -> (Float, Float) {
        let mut r = fr_dielectric(cos_theta.abs(), self.eta);
        let mut t = 1.0 - r;
        if r < 1.0 {
            r += sqr(t) * r / (1.0 - sqr(r));
            t = 1.0 - r;
        }
        (r, t)
    }
}

impl BxDFMethods for ThinDielectricBxDF {
    fn f(&self, _wo: Vector3f, _wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        SampledSpectrum::new(0.0)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        _u: Point2f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let (r, t) = self.reflectance_transmittance(cos_theta(wo));
        let (pr, pt) = choice(r, t, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        if uc < pr / (pr + pt) {
            let wi = Vector3f::new(-wo.x, -wo.y, wo.z);
            let f = SampledSpectrum::new(r / abs_cos_theta(wi));
            Some(BSDFSample::new(
                f,
                wi,
                pr / (pr + pt),
                BxDFFlags::SPECULAR_REFLECTION,
            ))
        } else {
            let wi = -wo;
            let f = SampledSpectrum::new(t / abs_cos_theta(wi));
            Some(BSDFSample::new(
                f,
                wi,
                pt / (pr + pt),
                BxDFFlags::SPECULAR_TRANSMISSION,
            ))
        }
    }

    fn pdf(
        &self,
        _wo: Vector3f,
        _wi: Vector3f,
        _mode: TransportMode,
        _sample_flags: BxDFReflTransFlags,
    ) -> Float {
        0.0
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::REFLECTION | BxDFFlags::TRANSMISSION | BxDFFlags::SPECULAR
    }

    /// pbrt-v4 leaves the thin dielectric unregularized.
    fn regularize(&mut self) {}
}
