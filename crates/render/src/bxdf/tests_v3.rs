//! Tests of the pbrt-v3 models pbrt-v4 dropped (the Disney BSDF and the
//! Fourier BSDF), with the cross-model checks of `tests.rs`: `sample_f`
//! against `f` and `pdf`, reciprocity, energy bounds and χ² tests of the
//! sampled directions.

use rpbrt_geometry::float::*;
use rpbrt_geometry::same_hemisphere;
use rpbrt_geometry::tuple::*;

use super::tests::{albedo, approx, chi2_test, rand_dir, u2};
use super::*;
use crate::rng::Rng;
use crate::spectrum::SampledSpectrum;

fn disney(edit: impl Fn(&mut DisneyParams)) -> BxDF {
    let mut p = DisneyParams {
        color: SampledSpectrum::from_array([0.8, 0.5, 0.3, 0.6]),
        luminance: 0.55,
        metallic: 0.0,
        eta: 1.5,
        roughness: 0.5,
        specular_tint: 0.0,
        anisotropic: 0.0,
        sheen: 0.0,
        sheen_tint: 0.5,
        clearcoat: 0.0,
        clearcoat_gloss: 1.0,
        spec_trans: 0.0,
        thin: false,
        flatness: 0.0,
        diff_trans: 1.0,
    };
    edit(&mut p);
    BxDF::Disney(DisneyBxDF::new(&p))
}

/// Disney configurations covering every lobe, thin and solid.
fn disney_models() -> Vec<(&'static str, BxDF)> {
    vec![
        ("defaults", disney(|_| {})),
        (
            "metal aniso",
            disney(|p| {
                p.metallic = 0.8;
                p.anisotropic = 0.7;
                p.roughness = 0.3;
            }),
        ),
        (
            "sheen clearcoat",
            disney(|p| {
                p.sheen = 1.0;
                p.clearcoat = 1.0;
                p.clearcoat_gloss = 0.4;
                p.specular_tint = 0.5;
            }),
        ),
        (
            "glassy",
            disney(|p| {
                p.spec_trans = 0.9;
                p.roughness = 0.35;
            }),
        ),
        (
            "thin",
            disney(|p| {
                p.thin = true;
                p.flatness = 0.6;
                p.diff_trans = 0.8;
                p.spec_trans = 0.4;
                p.roughness = 0.6;
            }),
        ),
    ]
}

#[test]
fn disney_sample_f_agrees_with_f_and_pdf() {
    let mut rng = Rng::new(300, 0);
    for (name, b) in disney_models() {
        let mut checked = 0;
        for _ in 0..5000 {
            let wo = rand_dir(&mut rng);
            let uc = rng.uniform_float();
            let Some(bs) = b.sample_f(
                wo,
                uc,
                u2(&mut rng),
                TransportMode::Radiance,
                BxDFReflTransFlags::ALL,
            ) else {
                continue;
            };
            assert!(
                !bs.is_specular(),
                "{name}: the Disney BSDF has no delta lobe"
            );
            let pdf = b.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
            let f = b.f(wo, bs.wi, TransportMode::Radiance);
            assert!(approx(bs.pdf, pdf, 2e-3), "{name}: pdf {} vs {pdf}", bs.pdf);
            for i in 0..4 {
                assert!(approx(bs.f[i], f[i], 2e-3), "{name}: f {:?} vs {f:?}", bs.f);
            }
            assert_eq!(bs.is_transmission(), !same_hemisphere(wo, bs.wi));
            checked += 1;
        }
        assert!(checked > 3000, "{name}: only {checked} usable samples");
    }
}

#[test]
fn disney_reflection_is_reciprocal_and_transmission_adjoint() {
    let mut rng = Rng::new(301, 0);
    for (name, b) in disney_models() {
        for _ in 0..5000 {
            let wo = rand_dir(&mut rng);
            let wi = rand_dir(&mut rng);
            if same_hemisphere(wo, wi) {
                let (a, c) = (
                    b.f(wo, wi, TransportMode::Radiance),
                    b.f(wi, wo, TransportMode::Radiance),
                );
                for i in 0..4 {
                    assert!(approx(a[i], c[i], 1e-3), "{name}: {a:?} vs {c:?}");
                }
            } else {
                let a = b.f(wo, wi, TransportMode::Radiance);
                let c = b.f(wi, wo, TransportMode::Importance);
                for i in 0..4 {
                    assert!(approx(a[i], c[i], 2e-3), "{name}: {a:?} vs {c:?}");
                }
            }
        }
    }
}

#[test]
fn disney_energy_is_bounded() {
    let mut rng = Rng::new(302, 0);
    let white = SampledSpectrum::new(1.0);
    let w = |edit: &dyn Fn(&mut DisneyParams)| {
        disney(|p| {
            p.color = white;
            p.luminance = 1.0;
            edit(p);
        })
    };
    // Analytic: with η = 1 the specular lobe vanishes and with zero
    // roughness so does retro-reflection, leaving Burley's diffuse, whose
    // albedo is (1 − F(θo)/2)(1 − 1/42) for a white base.
    let b = w(&|p| {
        p.eta = 1.0;
        p.roughness = 0.0;
    });
    for cos in [0.1 as Float, 0.5, 1.0] {
        let wo = Vector3f::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let rho = albedo(&b, wo, TransportMode::Importance, 100_000, &mut rng)[0];
        let fo = (1.0 - cos).powi(5);
        let expect = (1.0 - fo / 2.0) * (1.0 - 1.0 / 42.0);
        assert!((rho - expect).abs() < 0.01, "cos {cos}: {rho} vs {expect}");
    }
    // The lobes that conserve energy on their own: ρ ≤ 1 on both sides.
    let conserving = [
        w(&|p| {
            p.metallic = 1.0;
            p.roughness = 0.4;
            p.anisotropic = 0.5;
        }),
        w(&|p| {
            p.spec_trans = 1.0;
            p.roughness = 0.3;
        }),
        w(&|p| {
            p.spec_trans = 1.0;
            p.roughness = 0.7;
            p.anisotropic = 0.8;
        }),
    ];
    for b in &conserving {
        for _ in 0..6 {
            let wo = rand_dir(&mut rng);
            let rho = albedo(b, wo, TransportMode::Importance, 40_000, &mut rng);
            assert!(
                rho.max_component_value() <= 1.02,
                "{b:?}: {rho:?} for {wo:?}"
            );
            assert!(rho.min_component_value() > 0.2, "{b:?}: {rho:?} for {wo:?}");
        }
    }
    // The full model is not energy-conserving by design (nor are metallic
    // blends with transmission, whose reflection uses the Schlick blend
    // and transmission the dielectric Fresnel term): Burley's
    // retro-reflective diffuse and the sheen and clearcoat lobes are added
    // on top of the specular lobe without a (1 − F) weight. Seen from
    // above, a white base reflects at most about 1.7 (roughness 1, every
    // lobe on, grazing).
    let all = w(&|p| {
        p.roughness = 1.0;
        p.sheen = 1.0;
        p.clearcoat = 1.0;
    });
    for cos in [0.02 as Float, 0.3, 0.7, 1.0] {
        let wo = Vector3f::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let rho = albedo(&all, wo, TransportMode::Importance, 40_000, &mut rng)[0];
        assert!(rho > 1.0 && rho < 1.75, "cos {cos}: {rho}");
    }
}

#[test]
fn disney_lobes_follow_the_parameters() {
    // Zero roughness: no retro-reflection, α = 0.001 for the specular
    // lobe, so away from the mirror direction only Burley's diffuse is
    // left, R/π (1 − Fo/2)(1 − Fi/2).
    let up = Vector3f::new(0.0, 0.0, 1.0);
    let b = disney(|p| p.roughness = 0.0);
    let f = b.f(up, up, TransportMode::Radiance);
    let wi = Vector3f::new(0.6, 0.0, 0.8);
    let fd = b.f(up, wi, TransportMode::Radiance);
    let fo: Float = 0.0;
    let fi = (1.0 - 0.8 as Float).powi(5);
    let expect = 0.8 * INV_PI * (1.0 - fo / 2.0) * (1.0 - fi / 2.0);
    assert!((fd[0] - expect).abs() < 1e-4 * expect, "{fd:?} vs {expect}");
    assert!(f[0] > fd[0]);
    // A non-thin surface never transmits without spectrans.
    assert!(!b.flags().is_transmissive());
    assert!(b.f(up, -wi, TransportMode::Radiance).is_black());
    // A thin surface transmits diffusely: dt·c/π.
    let t = disney(|p| {
        p.thin = true;
        p.diff_trans = 1.0;
    });
    let ft = t.f(up, -wi, TransportMode::Radiance);
    assert!((ft[0] - 0.5 * 0.8 * INV_PI).abs() < 1e-5, "{ft:?}");
    assert!(t.flags().is_transmissive());
    // Fully metallic: no diffuse lobes, the flags say glossy only.
    let m = disney(|p| p.metallic = 1.0);
    assert_eq!(m.flags(), BxDFFlags::GLOSSY_REFLECTION);
}

#[test]
fn chi2_disney() {
    for (i, (name, b)) in disney_models().into_iter().enumerate() {
        chi2_test(name, &b, 310 + i as u64);
    }
}
