//! pbrt-v3's Disney BSDF (pbrt-v3 `materials/disney.cpp`, after Burley's
//! 2012 and 2015 course notes), which pbrt-v4 dropped.
//!
//! pbrt-v3 builds it as a `BSDF` holding up to eight separate BxDFs: a
//! Fresnel-modified diffuse lobe, the "fake subsurface" lobe that thin
//! surfaces blend in by `flatness`, retro-reflection, sheen, a
//! Trowbridge–Reitz specular lobe with the Disney Fresnel blend, the GTR1
//! clearcoat, microfacet transmission and (thin surfaces) Lambertian
//! transmission. [`DisneyBxDF`] keeps the evaluated parameters and
//! reproduces that composite: `f` sums the lobes on the side of the
//! surface the directions ask for, `sample_f` picks one lobe uniformly
//! and averages the lobes' densities, as pbrt-v3's `BSDF::Sample_f` does.
//!
//! Two departures, both in sampling only (so the expected image is the
//! model's): the specular lobe carries no `color` factor (pbrt-v3 issue
//! #224, fixed in pbrt-v3's last version), and the clearcoat lobe samples
//! and evaluates the same GTR1 density (pbrt-v3 drew half-vectors with
//! α = 0.25 but divided by the density of the gloss-dependent α, without
//! the cos θh factor, which biased it). The transmission lobe also
//! rejects back-facing microfacets, as pbrt-v4's rough dielectric does
//! (pbrt-v3 evaluated it there too, for pairs its sampling never makes).

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta, same_hemisphere, spherical_direction};

use super::scattering::{fr_dielectric, reflect, refract};
use super::TrowbridgeReitzDistribution;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::SampledSpectrum;

/// The lobes, as bits of [`DisneyBxDF::lobes`], in pbrt-v3's order.
const DIFFUSE: u16 = 1;
const FAKE_SS: u16 = 2;
/// Solid surfaces with a BSSRDF: perfect specular transmission into it,
/// in place of the diffuse lobe.
const ENTRY: u16 = 4;
const RETRO: u16 = 8;
const SHEEN: u16 = 16;
const SPECULAR: u16 = 32;
const CLEARCOAT: u16 = 64;
const SPEC_TRANS: u16 = 128;
const DIFF_TRANS: u16 = 256;
const ALL_LOBES: [u16; 9] = [
    DIFFUSE, FAKE_SS, ENTRY, RETRO, SHEEN, SPECULAR, CLEARCOAT, SPEC_TRANS, DIFF_TRANS,
];

/// The material's parameters evaluated at a point (pbrt-v3
/// `DisneyMaterial`'s textures), the input of [`DisneyBxDF::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyParams {
    /// Base colour (clamped to be non-negative).
    pub color: SampledSpectrum,
    /// Luminance of `color` (for the tint colour `color / luminance`).
    pub luminance: Float,
    /// Metallic blend.
    pub metallic: Float,
    /// Index of refraction.
    pub eta: Float,
    /// Roughness.
    pub roughness: Float,
    /// Tint of the dielectric specular reflectance towards the base colour.
    pub specular_tint: Float,
    /// Anisotropy.
    pub anisotropic: Float,
    /// Sheen weight.
    pub sheen: Float,
    /// Tint of the sheen towards the base colour.
    pub sheen_tint: Float,
    /// Clearcoat weight.
    pub clearcoat: Float,
    /// Clearcoat gloss.
    pub clearcoat_gloss: Float,
    /// Specular transmission weight.
    pub spec_trans: Float,
    /// Thin-surface model (no interior).
    pub thin: bool,
    /// Thin surfaces: blend of the diffuse and fake-subsurface lobes.
    pub flatness: Float,
    /// Thin surfaces: diffuse transmission (0 to 2; half transmits).
    pub diff_trans: Float,
    /// Solid surfaces: light the diffuse lobe would scatter enters a
    /// BSSRDF instead (a non-black `scatterdistance`).
    pub subsurface: bool,
}

/// pbrt-v3's Disney BSDF at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyBxDF {
    c: SampledSpectrum,
    /// Normal-incidence reflectance of the Schlick part of the Fresnel blend.
    cspec0: SampledSpectrum,
    /// Sheen reflectance (already weighted).
    sheen: SampledSpectrum,
    diffuse_weight: Float,
    flat: Float,
    /// Half of `difftrans`.
    dt: Float,
    roughness: Float,
    metallic: Float,
    eta: Float,
    clearcoat: Float,
    clearcoat_gloss: Float,
    spec_trans: Float,
    /// The distribution of the specular lobe (and of transmission on
    /// solid surfaces), with separable masking.
    spec: TrowbridgeReitzDistribution,
    /// The transmission distribution of thin surfaces (roughness scaled
    /// by the index of refraction), with height-correlated masking.
    thin_trans: TrowbridgeReitzDistribution,
    lobes: u16,
}

#[inline]
fn schlick_weight(cos_theta: Float) -> Float {
    let m = clamp(1.0 - cos_theta, 0.0, 1.0);
    (m * m) * (m * m) * m
}

#[inline]
fn schlick_r0_from_eta(eta: Float) -> Float {
    sqr(eta - 1.0) / sqr(eta + 1.0)
}

/// The GTR1 distribution of the clearcoat (normalized so that
/// ∫ D cos θh dω = 1).
#[inline]
fn gtr1(cos_theta: Float, alpha: Float) -> Float {
    let a2 = alpha * alpha;
    (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * cos_theta * cos_theta))
}

/// Smith masking for GGX divided by 2 cos θ (the clearcoat's form).
#[inline]
fn smith_g_ggx(cos_theta: Float, alpha: Float) -> Float {
    let a2 = alpha * alpha;
    let c2 = cos_theta * cos_theta;
    1.0 / (cos_theta + (a2 + c2 - a2 * c2).sqrt())
}

/// The normalized half vector of a reflection pair, if any.
#[inline]
fn half_vector(wo: Vector3f, wi: Vector3f) -> Option<Vector3f> {
    let wh = wi + wo;
    if wh.x == 0.0 && wh.y == 0.0 && wh.z == 0.0 {
        return None;
    }
    Some(wh.normalize())
}

/// A visible microfacet normal on `wo`'s side (pbrt-v3 flips `wo` up,
/// samples, and flips the normal back).
#[inline]
fn sample_wh(d: &TrowbridgeReitzDistribution, wo: Vector3f, u: Point2f) -> Vector3f {
    if wo.z < 0.0 {
        -d.sample_wm(-wo, u)
    } else {
        d.sample_wm(wo, u)
    }
}

/// True when microfacet `wh` (facing up) can refract `wo` into `wi`: the
/// directions lie on opposite sides of it, each on the side of the
/// microfacet that faces its own hemisphere. pbrt-v3 tested only the
/// first; pbrt-v4's test of back-facing microfacets is added so that the
/// lobe is reciprocal and its density describes what sampling produces.
#[inline]
fn refraction_pair(wo: Vector3f, wi: Vector3f, wh: Vector3f) -> bool {
    dot(wo, wh) * dot(wi, wh) < 0.0 && dot(wh, wi) * wi.z > 0.0 && dot(wh, wo) * wo.z > 0.0
}

/// The side of the surface a lobe scatters to.
#[inline]
fn is_transmission_lobe(lobe: u16) -> bool {
    lobe == SPEC_TRANS || lobe == DIFF_TRANS || lobe == ENTRY
}

impl DisneyBxDF {
    /// The BSDF pbrt-v3's `DisneyMaterial::ComputeScatteringFunctions`
    /// builds from `p`.
    pub fn new(p: &DisneyParams) -> Self {
        let c = p.color.clamp_zero();
        let diffuse_weight = (1.0 - p.metallic) * (1.0 - p.spec_trans);
        let dt = p.diff_trans / 2.0;
        let ctint = if p.luminance > 0.0 {
            c / p.luminance
        } else {
            SampledSpectrum::new(1.0)
        };
        let sheen = if p.sheen > 0.0 {
            SampledSpectrum::lerp(p.sheen_tint, SampledSpectrum::new(1.0), ctint)
                * (diffuse_weight * p.sheen)
        } else {
            SampledSpectrum::new(0.0)
        };
        let mut lobes = SPECULAR;
        if diffuse_weight > 0.0 {
            lobes |= RETRO;
            lobes |= if p.subsurface && !p.thin {
                ENTRY
            } else {
                DIFFUSE
            };
            if p.thin {
                lobes |= FAKE_SS;
            }
            if p.sheen > 0.0 {
                lobes |= SHEEN;
            }
        }
        if p.clearcoat > 0.0 {
            lobes |= CLEARCOAT;
        }
        if p.spec_trans > 0.0 {
            lobes |= SPEC_TRANS;
        }
        if p.thin {
            lobes |= DIFF_TRANS;
        }
        let aspect = (1.0 - p.anisotropic * 0.9).max(0.0).sqrt();
        let alphas = |r: Float| {
            let ax = (sqr(r) / aspect).max(0.001);
            let ay = (sqr(r) * aspect).max(0.001);
            TrowbridgeReitzDistribution::new(ax, ay)
        };
        let cspec0 = SampledSpectrum::lerp(
            p.metallic,
            SampledSpectrum::lerp(p.specular_tint, SampledSpectrum::new(1.0), ctint)
                * schlick_r0_from_eta(p.eta),
            c,
        );
        DisneyBxDF {
            c,
            cspec0,
            sheen,
            diffuse_weight,
            flat: p.flatness,
            dt,
            roughness: p.roughness,
            metallic: p.metallic,
            eta: p.eta,
            clearcoat: p.clearcoat,
            clearcoat_gloss: p.clearcoat_gloss,
            spec_trans: p.spec_trans,
            spec: alphas(p.roughness),
            thin_trans: alphas((0.65 * p.eta - 0.35) * p.roughness),
            lobes,
        }
    }

    #[inline]
    fn thin(&self) -> bool {
        self.lobes & DIFF_TRANS != 0
    }

    /// The lobes `sample_flags` allows.
    #[inline]
    fn matching(&self, sample_flags: BxDFReflTransFlags) -> impl Iterator<Item = u16> + '_ {
        let refl = sample_flags.contains(BxDFReflTransFlags::REFLECTION);
        let trans = sample_flags.contains(BxDFReflTransFlags::TRANSMISSION);
        ALL_LOBES.into_iter().filter(move |&l| {
            self.lobes & l != 0 && if is_transmission_lobe(l) { trans } else { refl }
        })
    }

    /// The Fresnel blend of the specular lobe (pbrt-v3 `DisneyFresnel`).
    #[inline]
    fn disney_fresnel(&self, cos_i: Float) -> SampledSpectrum {
        let dielectric = fr_dielectric(cos_i, self.eta);
        let w = schlick_weight(cos_i);
        let schlick = SampledSpectrum::lerp(w, self.cspec0, SampledSpectrum::new(1.0));
        SampledSpectrum::lerp(self.metallic, SampledSpectrum::new(dielectric), schlick)
    }

    /// One lobe's value (no side test).
    fn lobe_f(
        &self,
        lobe: u16,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::new(0.0);
        let (fo, fi) = (
            schlick_weight(abs_cos_theta(wo)),
            schlick_weight(abs_cos_theta(wi)),
        );
        match lobe {
            DIFFUSE => {
                let r = if self.thin() {
                    self.c * (self.diffuse_weight * (1.0 - self.flat) * (1.0 - self.dt))
                } else {
                    self.c * self.diffuse_weight
                };
                r * (INV_PI * (1.0 - fo / 2.0) * (1.0 - fi / 2.0))
            }
            FAKE_SS => {
                let Some(wh) = half_vector(wo, wi) else {
                    return zero;
                };
                let cos_d = dot(wi, wh);
                let fss90 = cos_d * cos_d * self.roughness;
                let fss = lerp(fo, 1.0, fss90) * lerp(fi, 1.0, fss90);
                let ss = 1.25 * (fss * (1.0 / (abs_cos_theta(wo) + abs_cos_theta(wi)) - 0.5) + 0.5);
                self.c * (self.diffuse_weight * self.flat * (1.0 - self.dt) * INV_PI * ss)
            }
            RETRO => {
                let Some(wh) = half_vector(wo, wi) else {
                    return zero;
                };
                let cos_d = dot(wi, wh);
                let rr = 2.0 * self.roughness * cos_d * cos_d;
                self.c * (self.diffuse_weight * INV_PI * rr * (fo + fi + fo * fi * (rr - 1.0)))
            }
            SHEEN => {
                let Some(wh) = half_vector(wo, wi) else {
                    return zero;
                };
                self.sheen * schlick_weight(dot(wi, wh))
            }
            SPECULAR => {
                let (co, ci) = (abs_cos_theta(wo), abs_cos_theta(wi));
                if co == 0.0 || ci == 0.0 {
                    return zero;
                }
                let Some(wh) = half_vector(wo, wi) else {
                    return zero;
                };
                let whf = if wh.z < 0.0 { -wh } else { wh };
                let f = self.disney_fresnel(dot(wi, whf));
                let g = self.spec.g1(wo) * self.spec.g1(wi);
                f * (self.spec.d(wh) * g / (4.0 * ci * co))
            }
            CLEARCOAT => {
                let Some(wh) = half_vector(wo, wi) else {
                    return zero;
                };
                let dr = gtr1(abs_cos_theta(wh), self.clearcoat_alpha());
                let fr = lerp(schlick_weight(dot(wo, wh)), 0.04, 1.0);
                let gr =
                    smith_g_ggx(abs_cos_theta(wo), 0.25) * smith_g_ggx(abs_cos_theta(wi), 0.25);
                SampledSpectrum::new(0.25 * self.clearcoat * gr * fr * dr)
            }
            SPEC_TRANS => self.spec_trans_f(wo, wi, mode),
            DIFF_TRANS => self.c * (self.dt * INV_PI),
            _ => zero,
        }
    }

    #[inline]
    fn clearcoat_alpha(&self) -> Float {
        lerp(self.clearcoat_gloss, 0.1, 0.001)
    }

    /// The transmission distribution and its masking-shadowing term.
    #[inline]
    fn trans_distribution(&self) -> &TrowbridgeReitzDistribution {
        if self.thin() {
            &self.thin_trans
        } else {
            &self.spec
        }
    }

    #[inline]
    fn trans_g(&self, wo: Vector3f, wi: Vector3f) -> Float {
        if self.thin() {
            self.thin_trans.g(wo, wi)
        } else {
            self.spec.g1(wo) * self.spec.g1(wi)
        }
    }

    /// pbrt-v3's `MicrofacetTransmission::f` with T = spectrans·√color
    /// between indices 1 and η.
    fn spec_trans_f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        let zero = SampledSpectrum::new(0.0);
        if same_hemisphere(wo, wi) {
            return zero;
        }
        let (co, ci) = (cos_theta(wo), cos_theta(wi));
        if co == 0.0 || ci == 0.0 {
            return zero;
        }
        let eta = if co > 0.0 { self.eta } else { 1.0 / self.eta };
        let Some(mut wh) = (wo + wi * eta).try_normalize() else {
            return zero;
        };
        if wh.z < 0.0 {
            wh = -wh;
        }
        if !refraction_pair(wo, wi, wh) {
            return zero;
        }
        let f = fr_dielectric(dot(wo, wh), self.eta);
        let sqrt_denom = dot(wo, wh) + eta * dot(wi, wh);
        if sqrt_denom == 0.0 {
            return zero;
        }
        let factor = match mode {
            TransportMode::Radiance => 1.0 / eta,
            TransportMode::Importance => 1.0,
        };
        let d = self.trans_distribution();
        let v = d.d(wh)
            * self.trans_g(wo, wi)
            * eta
            * eta
            * abs_dot(wi, wh)
            * abs_dot(wo, wh)
            * factor
            * factor
            / (ci * co * sqrt_denom * sqrt_denom);
        self.c.sqrt() * ((1.0 - f) * self.spec_trans * v.abs())
    }

    /// One lobe's sampling density (each lobe checks its own side).
    fn lobe_pdf(&self, lobe: u16, wo: Vector3f, wi: Vector3f) -> Float {
        match lobe {
            DIFFUSE | FAKE_SS | RETRO | SHEEN if same_hemisphere(wo, wi) => {
                cosine_hemisphere_pdf(abs_cos_theta(wi))
            }
            SPECULAR => {
                if !same_hemisphere(wo, wi) {
                    return 0.0;
                }
                let Some(wh) = half_vector(wo, wi) else {
                    return 0.0;
                };
                let d = abs_dot(wo, wh);
                if d == 0.0 {
                    return 0.0;
                }
                self.spec.pdf(wo, wh) / (4.0 * d)
            }
            CLEARCOAT => {
                if !same_hemisphere(wo, wi) {
                    return 0.0;
                }
                let Some(wh) = half_vector(wo, wi) else {
                    return 0.0;
                };
                let d = abs_dot(wo, wh);
                if d == 0.0 {
                    return 0.0;
                }
                let cos_h = abs_cos_theta(wh);
                gtr1(cos_h, self.clearcoat_alpha()) * cos_h / (4.0 * d)
            }
            SPEC_TRANS => {
                if same_hemisphere(wo, wi) {
                    return 0.0;
                }
                let eta = if cos_theta(wo) > 0.0 {
                    self.eta
                } else {
                    1.0 / self.eta
                };
                let Some(mut wh) = (wo + wi * eta).try_normalize() else {
                    return 0.0;
                };
                if wh.z < 0.0 {
                    wh = -wh;
                }
                if !refraction_pair(wo, wi, wh) {
                    return 0.0;
                }
                let sqrt_denom = dot(wo, wh) + eta * dot(wi, wh);
                if sqrt_denom == 0.0 {
                    return 0.0;
                }
                let dwh_dwi = (eta * eta * dot(wi, wh) / (sqrt_denom * sqrt_denom)).abs();
                self.trans_distribution().pdf(wo, wh) * dwh_dwi
            }
            DIFF_TRANS if !same_hemisphere(wo, wi) => cosine_hemisphere_pdf(abs_cos_theta(wi)),
            _ => 0.0,
        }
    }

    /// Samples one lobe: the incident direction, or `None`.
    fn lobe_sample(&self, lobe: u16, wo: Vector3f, u: Point2f) -> Option<Vector3f> {
        match lobe {
            DIFFUSE | FAKE_SS | RETRO | SHEEN | DIFF_TRANS => {
                let mut wi = sample_cosine_hemisphere(u);
                let below = wo.z < 0.0;
                // Reflection lobes stay on ωo's side, transmission crosses.
                if below != (lobe == DIFF_TRANS) {
                    wi.z = -wi.z;
                }
                Some(wi)
            }
            SPECULAR => {
                if wo.z == 0.0 {
                    return None;
                }
                let wh = sample_wh(&self.spec, wo, u);
                if dot(wo, wh) < 0.0 {
                    return None;
                }
                let wi = reflect(wo, wh);
                same_hemisphere(wo, wi).then_some(wi)
            }
            CLEARCOAT => {
                if wo.z == 0.0 {
                    return None;
                }
                let a2 = sqr(self.clearcoat_alpha());
                let cos_t = ((1.0 - a2.powf(1.0 - u[0])) / (1.0 - a2)).max(0.0).sqrt();
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let mut wh = spherical_direction(sin_t, cos_t, 2.0 * PI * u[1]);
                if !same_hemisphere(wo, wh) {
                    wh = -wh;
                }
                let wi = reflect(wo, wh);
                same_hemisphere(wo, wi).then_some(wi)
            }
            SPEC_TRANS => {
                if wo.z == 0.0 {
                    return None;
                }
                let wh = sample_wh(self.trans_distribution(), wo, u);
                if dot(wo, wh) < 0.0 {
                    return None;
                }
                let etap = if cos_theta(wo) > 0.0 {
                    self.eta
                } else {
                    1.0 / self.eta
                };
                refract(wo, Normal3f::from(wh), etap).map(|(wi, _)| wi)
            }
            _ => None,
        }
    }

    /// Samples the specular transmission into the BSSRDF, chosen among
    /// `n` lobes (pbrt-v3's `SpecularTransmission` with T = 1: no other
    /// lobe adds to its value or density).
    fn sample_entry(&self, wo: Vector3f, n: usize, mode: TransportMode) -> Option<BSDFSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (wi, etap) = refract(wo, Normal3f::new(0.0, 0.0, 1.0), self.eta)?;
        let mut ft = 1.0 - fr_dielectric(cos_theta(wo), self.eta);
        if mode == TransportMode::Radiance {
            ft /= sqr(etap);
        }
        Some(BSDFSample::with_eta(
            SampledSpectrum::new(ft / abs_cos_theta(wi)),
            wi,
            1.0 / n as Float,
            BxDFFlags::SPECULAR_TRANSMISSION,
            etap,
        ))
    }

    /// The flags of one lobe.
    #[inline]
    fn lobe_flags(lobe: u16) -> BxDFFlags {
        match lobe {
            SPECULAR | CLEARCOAT => BxDFFlags::GLOSSY_REFLECTION,
            SPEC_TRANS => BxDFFlags::GLOSSY_TRANSMISSION,
            ENTRY => BxDFFlags::SPECULAR_TRANSMISSION,
            DIFF_TRANS => BxDFFlags::DIFFUSE_TRANSMISSION,
            _ => BxDFFlags::DIFFUSE_REFLECTION,
        }
    }
}

impl BxDFMethods for DisneyBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        let mut f = SampledSpectrum::new(0.0);
        let reflect = same_hemisphere(wo, wi);
        for lobe in ALL_LOBES {
            if self.lobes & lobe != 0 && is_transmission_lobe(lobe) != reflect {
                f += self.lobe_f(lobe, wo, wi, mode);
            }
        }
        f
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let n = self.matching(sample_flags).count();
        if n == 0 {
            return None;
        }
        let k = ((uc * n as Float) as usize).min(n - 1);
        let lobe = self.matching(sample_flags).nth(k)?;
        if lobe == ENTRY {
            return self.sample_entry(wo, n, mode);
        }
        let wi = self.lobe_sample(lobe, wo, u)?;
        if wi.z == 0.0 || self.lobe_pdf(lobe, wo, wi) == 0.0 {
            return None;
        }
        let pdf = self
            .matching(sample_flags)
            .map(|l| self.lobe_pdf(l, wo, wi))
            .sum::<Float>()
            / n as Float;
        let reflect = same_hemisphere(wo, wi);
        let mut f = SampledSpectrum::new(0.0);
        for l in self.matching(sample_flags) {
            if is_transmission_lobe(l) != reflect {
                f += self.lobe_f(l, wo, wi, mode);
            }
        }
        let eta = if lobe == SPEC_TRANS {
            if cos_theta(wo) > 0.0 {
                self.eta
            } else {
                1.0 / self.eta
            }
        } else {
            1.0
        };
        Some(BSDFSample::with_eta(
            f,
            wi,
            pdf,
            Self::lobe_flags(lobe),
            eta,
        ))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        let n = self.matching(sample_flags).count();
        if n == 0 {
            return 0.0;
        }
        self.matching(sample_flags)
            .map(|l| self.lobe_pdf(l, wo, wi))
            .sum::<Float>()
            / n as Float
    }

    fn flags(&self) -> BxDFFlags {
        let mut f = BxDFFlags::UNSET;
        for lobe in ALL_LOBES {
            if self.lobes & lobe != 0 {
                f |= Self::lobe_flags(lobe);
            }
        }
        f
    }

    fn regularize(&mut self) {
        self.spec.regularize();
        self.thin_trans.regularize();
    }
}
