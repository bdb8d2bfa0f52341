//! Tests of the pbrt-v3 models pbrt-v4 dropped (the Disney BSDF and the
//! Fourier BSDF), with the cross-model checks of `tests.rs`: `sample_f`
//! against `f` and `pdf`, reciprocity, energy bounds and χ² tests of the
//! sampled directions.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, cos_theta, same_hemisphere, sin_theta};

use super::tests::{albedo, approx, check_sample_f_against_f_and_pdf, chi2_test, rand_dir};
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
        subsurface: false,
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
        let checked = check_sample_f_against_f_and_pdf(name, &b, &mut rng, 2e-3, |wo, bs| {
            assert!(
                !bs.is_specular(),
                "{name}: the Disney BSDF has no delta lobe without a BSSRDF"
            );
            assert_eq!(bs.is_transmission(), !same_hemisphere(wo, bs.wi));
            true
        });
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
fn disney_subsurface_enters_through_specular_transmission() {
    // Zero roughness: no retro-reflection and a near-mirror specular lobe,
    // so away from the mirror direction nothing but the diffuse lobe
    // reflects, and a BSSRDF surface has none.
    let up = Vector3f::new(0.0, 0.0, 1.0);
    let wi = Vector3f::new(0.6, 0.0, 0.8);
    let b = disney(|p| {
        p.roughness = 0.0;
        p.subsurface = true;
    });
    assert!(b.f(up, wi, TransportMode::Radiance)[0] < 1e-6);
    assert!(b.f(up, -wi, TransportMode::Radiance).is_black());
    assert!(b.flags().is_specular() && b.flags().is_transmissive());
    let plain = disney(|p| p.roughness = 0.0);
    assert!(plain.f(up, wi, TransportMode::Radiance)[0] > 0.1);
    // Thin surfaces keep their diffuse lobes.
    let thin = disney(|p| {
        p.thin = true;
        p.subsurface = true;
    });
    assert!(!thin.flags().is_specular());

    // Lobes: entry, retro, specular. The entry is chosen a third of the
    // time, refracts by Snell's law and carries (1 − Fr)/η² in radiance.
    let b = disney(|p| p.subsurface = true);
    let mut rng = Rng::new(320, 0);
    let (mut entries, n) = (0, 30_000);
    for _ in 0..n {
        let wo = rand_dir(&mut rng);
        let Some(bs) = b.sample_f(
            wo,
            rng.uniform_float(),
            Point2f::new(rng.uniform_float(), rng.uniform_float()),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        ) else {
            continue;
        };
        if !bs.is_specular() {
            continue;
        }
        entries += 1;
        assert!(bs.is_transmission() && !same_hemisphere(wo, bs.wi));
        assert!((bs.pdf - 1.0 / 3.0).abs() < 1e-6);
        let (sin_o, sin_i) = (sin_theta(wo), sin_theta(bs.wi));
        let eta = if wo.z > 0.0 { 1.5 } else { 1.0 / 1.5 };
        assert!(
            (sin_o - eta * sin_i).abs() < 1e-4,
            "{sin_o} vs {eta}·{sin_i}"
        );
        assert!((bs.eta - eta).abs() < 1e-6);
        let ft = (1.0 - fr_dielectric(cos_theta(wo), 1.5)) / (eta * eta);
        let got = bs.f[0] * abs_cos_theta(bs.wi);
        assert!((got - ft).abs() < 1e-4 * ft.max(1e-3), "{got} vs {ft}");
        assert!(b.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL) == 0.0);
    }
    // A third of the draws, less those from below beyond the critical
    // angle (total internal reflection): cos θ > √(1 − 1/η²) passes.
    let share = entries as Float / n as Float;
    let below = (1.0 - 1.0 / (1.5 as Float * 1.5)).sqrt();
    let want = (0.5 + 0.5 * (1.0 - below)) / 3.0;
    assert!((share - want).abs() < 0.01, "{share} vs {want}");
    // Sampling reflection only leaves the entry out.
    for _ in 0..2000 {
        let wo = rand_dir(&mut rng);
        if let Some(bs) = b.sample_f(
            wo,
            rng.uniform_float(),
            Point2f::new(rng.uniform_float(), rng.uniform_float()),
            TransportMode::Radiance,
            BxDFReflTransFlags::REFLECTION,
        ) {
            assert!(!bs.is_specular() && same_hemisphere(wo, bs.wi));
        }
    }
}

#[test]
fn chi2_disney() {
    for (i, (name, b)) in disney_models().into_iter().enumerate() {
        chi2_test(name, &b, 310 + i as u64);
    }
}

// ---------------------------------------------------------------------------
// Fourier BSDF: synthetic `.bsdf` files.

use super::fourier::{FOURIER_HEADER_LEN, FOURIER_MAGIC};
use crate::bssrdf::spline::integrate_catmull_rom;

/// Encodes a Fourier table: `coeffs(mu_i, mu_o)` gives a cell's
/// coefficients, channel after channel (all channels the same length).
fn encode_fourier(
    mu: &[Float],
    channels: usize,
    eta: Float,
    coeffs: impl Fn(Float, Float) -> Vec<Float>,
) -> Vec<u8> {
    let n = mu.len();
    let mut a = Vec::new();
    let mut pairs = Vec::new();
    let mut a0 = vec![0.0; n * n];
    let mut m_max = 0;
    for (o, &mu_o) in mu.iter().enumerate() {
        for (i, &mu_i) in mu.iter().enumerate() {
            let c = coeffs(mu_i, mu_o);
            let m = c.len() / channels;
            m_max = m_max.max(m);
            pairs.push((a.len() as i32, m as i32));
            a0[o * n + i] = if m > 0 { c[0] } else { 0.0 };
            a.extend(c);
        }
    }
    let mut cdf = vec![0.0; n * n];
    for o in 0..n {
        integrate_catmull_rom(mu, &a0[o * n..(o + 1) * n], &mut cdf[o * n..(o + 1) * n]);
    }
    let mut out = Vec::new();
    out.extend_from_slice(FOURIER_MAGIC);
    for v in [
        1,
        n as i32,
        a.len() as i32,
        m_max as i32,
        channels as i32,
        1,
        0,
        0,
        0,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&eta.to_le_bytes());
    out.extend_from_slice(&[0u8; 16]);
    assert_eq!(out.len(), FOURIER_HEADER_LEN);
    for v in mu.iter().chain(&cdf) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for (off, len) in pairs {
        out.extend_from_slice(&off.to_le_bytes());
        out.extend_from_slice(&len.to_le_bytes());
    }
    for v in &a {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

fn nodes(n: usize) -> Vec<Float> {
    (0..n)
        .map(|i| -1.0 + 2.0 * i as Float / (n - 1) as Float)
        .collect()
}

/// f = c |μi| |μo| (1 + ½ cos φ) on both sides, so that the stored
/// f |μi| is smooth; ρ(ωo) = (4π/3) c |μo|. Colour tables scale red by
/// 1.2 and blue by 0.8.
fn smooth_table(channels: usize, eta: Float, albedo: Float) -> &'static FourierBSDFTable {
    let c = albedo * 3.0 / (4.0 * PI);
    let bytes = encode_fourier(&nodes(41), channels, eta, |mi, mo| {
        let y = c * mi * mi * mo.abs();
        let mut v = vec![y, 0.5 * y];
        if channels == 3 {
            v.extend([1.2 * y, 0.6 * y, 0.8 * y, 0.4 * y]);
        }
        v
    });
    Box::leak(Box::new(
        FourierBSDFTable::from_bytes(&bytes).expect("valid table"),
    ))
}

/// Away from the grid's ends and from μ = 0, where the splines of
/// `smooth_table` (quadratic in μi, |μo| in μo) are exact.
fn interior(w: Vector3f) -> bool {
    (0.06..0.94).contains(&w.z.abs())
}

fn fourier_bxdf(table: &'static FourierBSDFTable) -> BxDF {
    let lambda = crate::spectrum::SampledWavelengths::sample_visible(0.37);
    BxDF::Fourier(FourierBxDF::new(table, &lambda))
}

#[test]
fn fourier_series_and_sampling() {
    // 1 + ½ cos φ: the sampled φ follow it (mean of cos φ is ¼).
    let ak = [1.0, 0.5];
    let recip = [0.0, 1.0];
    assert!((super::fourier::fourier(&ak, 2, 0.5) - 1.25).abs() < 1e-6);
    let n = 20_000;
    let mut mean = 0.0;
    for i in 0..n {
        let u = (i as Float + 0.5) / n as Float;
        let (f, pdf, phi) = super::fourier::sample_fourier(&ak, &recip, 2, u);
        assert!((f - (1.0 + 0.5 * phi.cos())).abs() < 1e-4);
        assert!((pdf - f / (2.0 * PI)).abs() < 1e-4);
        mean += phi.cos() / n as Float;
    }
    assert!((mean - 0.25).abs() < 2e-3, "{mean}");
}

#[test]
fn fourier_matches_its_function() {
    let b = fourier_bxdf(smooth_table(1, 1.0, 0.9));
    let c = 0.9 * 3.0 / (4.0 * PI);
    let mut rng = Rng::new(320, 0);
    let mut n = 0;
    while n < 2000 {
        let (wo, wi) = (rand_dir(&mut rng), rand_dir(&mut rng));
        if !(interior(wo) && interior(wi)) {
            continue;
        }
        n += 1;
        let cos_phi = rpbrt_geometry::cos_d_phi(-wi, wo);
        let expect = c * wi.z.abs() * wo.z.abs() * (1.0 + 0.5 * cos_phi);
        let f = b.f(wo, wi, TransportMode::Importance)[0];
        assert!(
            (f - expect).abs() < 2e-3 * c + 1e-3 * expect,
            "{f} vs {expect}"
        );
    }
}

#[test]
fn fourier_sample_f_agrees_with_f_and_pdf() {
    let mut rng = Rng::new(321, 0);
    for (name, b) in [
        ("grey", fourier_bxdf(smooth_table(1, 1.5, 0.8))),
        ("colour", fourier_bxdf(smooth_table(3, 1.33, 0.6))),
    ] {
        let checked = check_sample_f_against_f_and_pdf(name, &b, &mut rng, 1e-4, |wo, bs| {
            assert!((bs.wi.length() - 1.0).abs() < 1e-4);
            assert_eq!(bs.is_transmission(), !same_hemisphere(wo, bs.wi));
            true
        });
        assert!(checked > 4000, "{name}: {checked}");
    }
}

#[test]
fn fourier_reciprocity_and_energy() {
    let mut rng = Rng::new(322, 0);
    let b = fourier_bxdf(smooth_table(3, 1.0, 0.9));
    let mut n = 0;
    while n < 3000 {
        let (wo, wi) = (rand_dir(&mut rng), rand_dir(&mut rng));
        if !(interior(wo) && interior(wi)) {
            continue;
        }
        n += 1;
        let (x, y) = (
            b.f(wo, wi, TransportMode::Radiance),
            b.f(wi, wo, TransportMode::Radiance),
        );
        for i in 0..4 {
            assert!(approx(x[i], y[i], 1e-3), "{x:?} vs {y:?}");
        }
    }
    // White furnace: ρ(ωo) = 0.9 |cos θo| ≤ 1, by importance sampling.
    let grey = fourier_bxdf(smooth_table(1, 1.5, 0.9));
    for cos in [0.2 as Float, 0.6, 1.0, -0.7] {
        let wo = Vector3f::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let rho = albedo(&grey, wo, TransportMode::Importance, 50_000, &mut rng)[0];
        assert!((rho - 0.9 * cos.abs()).abs() < 0.01, "cos {cos}: {rho}");
        assert!(rho <= 1.0);
    }
}

#[test]
fn chi2_fourier() {
    chi2_test(
        "fourier grey",
        &fourier_bxdf(smooth_table(1, 1.5, 0.8)),
        330,
    );
    chi2_test(
        "fourier colour",
        &fourier_bxdf(smooth_table(3, 1.0, 0.5)),
        331,
    );
}

#[test]
fn bad_fourier_files_are_errors() {
    let good = encode_fourier(&nodes(5), 1, 1.5, |mi, mo| vec![mi * mi * mo.abs(), 0.1]);
    assert!(FourierBSDFTable::from_bytes(&good).is_ok());
    // Every truncation is an error, never a panic.
    for len in 0..good.len() {
        let e = FourierBSDFTable::from_bytes(&good[..len]).expect_err("truncated");
        assert!(
            matches!(e, FourierError::Truncated { .. }),
            "length {len}: {e}"
        );
    }
    let set = |at: usize, v: i32| {
        let mut b = good.clone();
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        FourierBSDFTable::from_bytes(&b)
    };
    // Absurd sizes: a claim of 2³⁰ nodes in a small file is "truncated"
    // (nothing is allocated from it), as are huge coefficient counts.
    assert!(matches!(
        set(12, 1 << 30),
        Err(FourierError::Truncated { .. })
    ));
    assert!(matches!(
        set(16, i32::MAX),
        Err(FourierError::Truncated { .. })
    ));
    assert!(matches!(set(12, -3), Err(FourierError::Corrupt(_))));
    assert!(matches!(set(12, 1), Err(FourierError::Corrupt(_))));
    assert!(matches!(set(20, -1), Err(FourierError::Corrupt(_))));
    // A maximum order below the cells' lengths.
    assert!(matches!(set(20, 1), Err(FourierError::Corrupt(_))));
    assert!(matches!(set(8, 0), Err(FourierError::Unsupported(_))));
    assert!(matches!(set(24, 2), Err(FourierError::Unsupported(_))));
    assert!(matches!(set(28, 3), Err(FourierError::Unsupported(_))));
    // Offsets past the coefficients and negative lengths.
    let pairs = FOURIER_HEADER_LEN + 4 * (5 + 25);
    assert!(matches!(
        set(pairs + 8, 10_000),
        Err(FourierError::Corrupt(_))
    ));
    assert!(matches!(set(pairs + 12, -2), Err(FourierError::Corrupt(_))));
    // Zenith nodes out of order.
    let mut b = good.clone();
    b[FOURIER_HEADER_LEN..FOURIER_HEADER_LEN + 4].copy_from_slice(&(0.5f32).to_le_bytes());
    assert!(matches!(
        FourierBSDFTable::from_bytes(&b),
        Err(FourierError::Corrupt(_))
    ));
    // Wrong magic, and an RGL tensor file named where a Fourier file belongs.
    let mut b = good.clone();
    b[0] = b'X';
    assert_eq!(
        FourierBSDFTable::from_bytes(&b),
        Err(FourierError::WrongMagic { tensor_file: false })
    );
    let mut t = super::measured::TENSOR_MAGIC.to_vec();
    t.extend_from_slice(&[0u8; 100]);
    let e = FourierBSDFTable::from_bytes(&t).expect_err("tensor file");
    assert_eq!(e, FourierError::WrongMagic { tensor_file: true });
    assert!(e.to_string().contains("measured"));
}
