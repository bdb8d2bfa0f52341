//! Cross-model tests in the style of pbrt-v4's `bsdfs_test.cpp`: energy
//! conservation, reciprocity, agreement of `sample_f` with `f` and `pdf`,
//! and χ² tests that samples follow the density `pdf` describes.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, same_hemisphere, sin_theta, spherical_direction};

use super::*;
use crate::rng::Rng;
use crate::sampling::{sample_uniform_sphere, UNIFORM_SPHERE_PDF};
use crate::spectrum::SampledSpectrum;

pub(super) fn u2(rng: &mut Rng) -> Point2f {
    Point2f::new(rng.uniform_float(), rng.uniform_float())
}

pub(super) fn rand_dir(rng: &mut Rng) -> Vector3f {
    sample_uniform_sphere(u2(rng))
}

fn tr(ax: Float, ay: Float) -> TrowbridgeReitzDistribution {
    TrowbridgeReitzDistribution::new(ax, ay)
}

fn white() -> SampledSpectrum {
    SampledSpectrum::new(1.0)
}

fn gold() -> (SampledSpectrum, SampledSpectrum) {
    (
        SampledSpectrum::from_array([0.2, 0.4, 0.9, 1.4]),
        SampledSpectrum::from_array([3.9, 3.0, 2.2, 1.8]),
    )
}

/// Models whose `sample_f` and `pdf` are exact (not layered).
fn exact_models() -> Vec<(String, BxDF)> {
    let (eta, k) = gold();
    let mut v = vec![
        (
            "diffuse".to_string(),
            BxDF::Diffuse(DiffuseBxDF::new(SampledSpectrum::new(0.7))),
        ),
        (
            "diffuse transmission".into(),
            BxDF::DiffuseTransmission(DiffuseTransmissionBxDF::new(
                SampledSpectrum::new(0.3),
                SampledSpectrum::new(0.6),
            )),
        ),
        (
            "normalized fresnel".into(),
            BxDF::NormalizedFresnel(NormalizedFresnelBxDF::new(1.33)),
        ),
    ];
    for (ax, ay) in [(0.1, 0.1), (0.3, 0.3), (0.5, 0.15), (0.9, 0.9)] {
        v.push((
            format!("conductor {ax} {ay}"),
            BxDF::Conductor(ConductorBxDF::new(tr(ax, ay), eta, k)),
        ));
        for e in [1.5, 0.7] {
            v.push((
                format!("dielectric eta {e} alpha {ax} {ay}"),
                BxDF::Dielectric(DielectricBxDF::new(e, tr(ax, ay))),
            ));
        }
    }
    for (bm, bn, alpha) in [(0.3, 0.3, 2.0), (0.6, 0.2, 0.0), (0.2, 0.7, 3.0)] {
        v.push((
            format!("hair {bm} {bn} {alpha}"),
            BxDF::Hair(HairBxDF::new(
                0.3,
                1.55,
                SampledSpectrum::new(0.4),
                bm,
                bn,
                alpha,
            )),
        ));
    }
    v
}

pub(super) fn approx(a: Float, b: Float, rel: Float) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-3)
}

/// Draws 5000 samples of `b` from random directions; for each sample that
/// `keep` accepts (it may assert model-specific properties), checks that
/// the sampled value and density equal `f` and `pdf` to `rel`. Returns how
/// many samples were checked.
pub(super) fn check_sample_f_against_f_and_pdf(
    name: &str,
    b: &BxDF,
    rng: &mut Rng,
    rel: Float,
    keep: impl Fn(Vector3f, &BSDFSample) -> bool,
) -> usize {
    let mut checked = 0;
    for _ in 0..5000 {
        let wo = rand_dir(rng);
        let uc = rng.uniform_float();
        let Some(bs) = b.sample_f(
            wo,
            uc,
            u2(rng),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        ) else {
            continue;
        };
        if !keep(wo, &bs) {
            continue;
        }
        let pdf = b.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
        let f = b.f(wo, bs.wi, TransportMode::Radiance);
        assert!(
            approx(bs.pdf, pdf, rel),
            "{name}: pdf {} vs {pdf}, wo {wo:?} wi {:?}",
            bs.pdf,
            bs.wi
        );
        for i in 0..4 {
            assert!(approx(bs.f[i], f[i], rel), "{name}: f {:?} vs {f:?}", bs.f);
        }
        checked += 1;
    }
    checked
}

#[test]
fn sample_f_agrees_with_f_and_pdf() {
    let mut rng = Rng::new(100, 0);
    for (name, b) in exact_models() {
        let checked = check_sample_f_against_f_and_pdf(&name, &b, &mut rng, 2e-3, |_, bs| {
            if bs.is_specular() || bs.pdf == 0.0 || bs.wi.z == 0.0 {
                return false;
            }
            assert!(!bs.pdf_is_proportional);
            true
        });
        assert!(checked > 1000, "{name}: only {checked} usable samples");
    }
}

#[test]
fn reflection_is_reciprocal() {
    let mut rng = Rng::new(101, 0);
    let (eta, k) = gold();
    let models = [
        BxDF::Diffuse(DiffuseBxDF::new(SampledSpectrum::new(0.5))),
        BxDF::Conductor(ConductorBxDF::new(tr(0.3, 0.3), eta, k)),
        BxDF::Conductor(ConductorBxDF::new(tr(0.6, 0.2), eta, k)),
        BxDF::Dielectric(DielectricBxDF::new(1.5, tr(0.3, 0.3))),
        BxDF::Dielectric(DielectricBxDF::new(1.5, tr(0.2, 0.5))),
    ];
    for b in models {
        for _ in 0..5000 {
            let wo = rand_dir(&mut rng);
            let mut wi = rand_dir(&mut rng);
            if !same_hemisphere(wo, wi) {
                wi = -wi;
            }
            let a = b.f(wo, wi, TransportMode::Radiance);
            let c = b.f(wi, wo, TransportMode::Radiance);
            for i in 0..4 {
                assert!(approx(a[i], c[i], 1e-3), "{}: {a:?} vs {c:?}", b.name());
            }
        }
    }
}

#[test]
fn rough_dielectric_transmission_is_adjoint() {
    // Radiance-mode BTDF equals the importance-mode BTDF with the
    // directions swapped (the 1/η² scaling is exactly the asymmetry).
    let mut rng = Rng::new(102, 0);
    for eta in [1.5, 1.33, 0.8] {
        let b = DielectricBxDF::new(eta, tr(0.4, 0.4));
        let mut nonzero = 0;
        for _ in 0..5000 {
            let wo = rand_dir(&mut rng);
            let mut wi = rand_dir(&mut rng);
            if same_hemisphere(wo, wi) {
                wi = -wi;
            }
            let a = b.f(wo, wi, TransportMode::Radiance)[0];
            let c = b.f(wi, wo, TransportMode::Importance)[0];
            assert!(approx(a, c, 2e-3), "eta {eta}: {a} vs {c}");
            if a > 0.0 {
                nonzero += 1;
            }
        }
        assert!(
            nonzero > 300,
            "eta {eta}: only {nonzero} pairs with transmission"
        );
    }
}

/// ∫ f |cos θi| dωi estimated with `sample_f`, in the given mode.
pub(super) fn albedo(
    b: &BxDF,
    wo: Vector3f,
    mode: TransportMode,
    n: usize,
    rng: &mut Rng,
) -> SampledSpectrum {
    let mut sum = SampledSpectrum::new(0.0);
    for _ in 0..n {
        let uc = rng.uniform_float();
        if let Some(bs) = b.sample_f(wo, uc, u2(rng), mode, BxDFReflTransFlags::ALL) {
            if bs.pdf > 0.0 {
                sum += bs.f * abs_cos_theta(bs.wi) / bs.pdf;
            }
        }
    }
    sum / n as Float
}

#[test]
fn energy_conservation() {
    let mut rng = Rng::new(103, 0);
    let mut models: Vec<BxDF> = vec![
        BxDF::Diffuse(DiffuseBxDF::new(white())),
        BxDF::DiffuseTransmission(DiffuseTransmissionBxDF::new(
            SampledSpectrum::new(0.5),
            SampledSpectrum::new(0.5),
        )),
        BxDF::ThinDielectric(ThinDielectricBxDF::new(1.5)),
    ];
    for a in [0.0, 0.05, 0.2, 0.5, 1.0] {
        // Fresnel ≈ 1: a perfect mirror conductor.
        models.push(BxDF::Conductor(ConductorBxDF::new(
            tr(a, a),
            SampledSpectrum::new(0.0),
            SampledSpectrum::new(1e4),
        )));
        for e in [1.01, 1.5, 2.4, 0.66] {
            models.push(BxDF::Dielectric(DielectricBxDF::new(e, tr(a, a))));
        }
        models.push(BxDF::CoatedDiffuse(CoatedDiffuseBxDF::new(
            DielectricBxDF::new(1.5, tr(a, a)),
            DiffuseBxDF::new(white()),
            0.01,
            SampledSpectrum::new(0.0),
            0.0,
            10,
            1,
        )));
        models.push(BxDF::CoatedConductor(CoatedConductorBxDF::new(
            DielectricBxDF::new(1.5, tr(a, a)),
            ConductorBxDF::new(
                tr(0.3, 0.3),
                SampledSpectrum::new(0.0),
                SampledSpectrum::new(1e4),
            ),
            0.01,
            SampledSpectrum::new(0.0),
            0.0,
            10,
            1,
        )));
    }
    for b in &models {
        for _ in 0..8 {
            let wo = rand_dir(&mut rng);
            // Importance mode: no 1/η² radiance scaling, so ρ ≤ 1 exactly.
            let rho = albedo(b, wo, TransportMode::Importance, 20_000, &mut rng);
            assert!(
                rho.max_component_value() <= 1.02,
                "{} {b:?}: rho {rho:?} for wo {wo:?}",
                b.name()
            );
        }
    }
}

#[test]
fn normalized_fresnel_is_normalized() {
    // ∫ f |cos| = 1 in importance mode and η² in radiance mode.
    let mut rng = Rng::new(107, 0);
    for eta in [1.0, 1.33, 1.5] {
        let b = BxDF::NormalizedFresnel(NormalizedFresnelBxDF::new(eta));
        let wo = Vector3f::new(0.1, 0.2, 0.9).normalize();
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let wi = rand_dir(&mut rng);
            sum += (b.f(wo, wi, TransportMode::Importance)[0] * abs_cos_theta(wi)
                / UNIFORM_SPHERE_PDF) as f64;
        }
        let v = sum / n as f64;
        assert!((v - 1.0).abs() < 0.02, "eta {eta}: {v}");
        let r = albedo(&b, wo, TransportMode::Radiance, 10_000, &mut rng)[0];
        assert!((r - eta * eta).abs() < 0.05 * eta * eta, "eta {eta}: {r}");
    }
}

#[test]
fn white_furnace_diffuse_and_mirror_limits() {
    let mut rng = Rng::new(104, 0);
    // Lambertian: ρ = R exactly (every sample weighs R).
    for r in [0.2, 0.5, 1.0] {
        let b = BxDF::Diffuse(DiffuseBxDF::new(SampledSpectrum::new(r)));
        let uc: Vec<Float> = (0..1000).map(|_| rng.uniform_float()).collect();
        let us: Vec<Point2f> = (0..1000).map(|_| u2(&mut rng)).collect();
        let rho = b.rho_hd(Vector3f::new(0.3, 0.2, 0.9).normalize(), &uc, &us);
        assert!((rho[0] - r).abs() < 1e-4, "{rho:?}");
        let u1: Vec<Point2f> = (0..1000).map(|_| u2(&mut rng)).collect();
        let rho = b.rho_hh(&u1, &uc, &us);
        assert!((rho[0] - r).abs() < 0.03, "{rho:?}");
    }
    // Rough mirror (Fresnel = 1): close to 1 for low roughness at moderate
    // angles; single scattering loses more as roughness grows.
    let mut prev = 1.01;
    for a in [0.05, 0.1, 0.3, 0.6, 1.0] {
        let b = BxDF::Conductor(ConductorBxDF::new(
            tr(a, a),
            SampledSpectrum::new(0.0),
            SampledSpectrum::new(1e4),
        ));
        let wo = spherical_direction((0.5 as Float).sin(), (0.5 as Float).cos(), 0.3);
        let rho = albedo(&b, wo, TransportMode::Radiance, 100_000, &mut rng)[0];
        // Single-scattering GGX loses energy to masking as α grows (about
        // 0.99, 0.86, 0.60, 0.33 at α = 0.1, 0.3, 0.6, 1 for this wo).
        if a <= 0.1 {
            assert!(rho > 0.97, "alpha {a}: {rho}");
        }
        assert!(
            rho <= prev + 0.01 && rho > 0.3,
            "alpha {a}: {rho} (previous {prev})"
        );
        prev = rho;
    }
    // Specular conductor: sample weight is exactly the Fresnel term.
    let (eta, k) = gold();
    let b = BxDF::Conductor(ConductorBxDF::new(tr(0.0, 0.0), eta, k));
    let wo = Vector3f::new(0.0, 0.6, 0.8);
    let bs = b
        .sample_f(
            wo,
            0.5,
            Point2f::new(0.5, 0.5),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        )
        .expect("mirror sample");
    let w = bs.f * abs_cos_theta(bs.wi) / bs.pdf;
    let fr = fr_complex_spectrum(0.8, eta, k);
    assert!((w[2] - fr[2]).abs() < 1e-5);
    assert_eq!(b.flags(), BxDFFlags::SPECULAR_REFLECTION);
}

#[test]
fn dielectric_with_eta_one_transmits_everything() {
    let mut rng = Rng::new(105, 0);
    for a in [0.0, 0.3] {
        let b = BxDF::Dielectric(DielectricBxDF::new(1.0, tr(a, a)));
        // pbrt-v4 reports a rough index-matched interface as glossy even
        // though it samples it as a delta transmission.
        let expect = if a == 0.0 {
            BxDFFlags::SPECULAR_TRANSMISSION
        } else {
            BxDFFlags::GLOSSY_TRANSMISSION
        };
        assert_eq!(b.flags(), expect);
        for _ in 0..1000 {
            let wo = rand_dir(&mut rng);
            let uc = rng.uniform_float();
            let bs = b
                .sample_f(
                    wo,
                    uc,
                    u2(&mut rng),
                    TransportMode::Radiance,
                    BxDFReflTransFlags::ALL,
                )
                .expect("always transmits");
            assert!(bs.is_transmission() && bs.is_specular());
            assert!((bs.wi + wo).length() < 1e-3);
            let w = bs.f[0] * abs_cos_theta(bs.wi) / bs.pdf;
            assert!((w - 1.0).abs() < 1e-5);
            assert_eq!(bs.eta, 1.0);
        }
    }
}

#[test]
fn smooth_dielectric_splits_by_fresnel() {
    let mut rng = Rng::new(106, 0);
    let eta = 1.5;
    let b = BxDF::Dielectric(DielectricBxDF::new(eta, tr(0.0, 0.0)));
    let wo = Vector3f::new(0.0, 0.6, 0.8);
    let n = 100_000;
    let mut refl = 0;
    for _ in 0..n {
        let uc = rng.uniform_float();
        let bs = b
            .sample_f(
                wo,
                uc,
                u2(&mut rng),
                TransportMode::Radiance,
                BxDFReflTransFlags::ALL,
            )
            .expect("sample");
        if bs.is_reflection() {
            refl += 1;
            assert_eq!(bs.eta, 1.0);
        } else {
            // Radiance is compressed by 1/η² entering the denser medium.
            let w = bs.f[0] * abs_cos_theta(bs.wi) / bs.pdf;
            assert!((w - 1.0 / (eta * eta)).abs() < 1e-4, "{w}");
            assert_eq!(bs.eta, eta);
            assert!((sin_theta(wo) - eta * sin_theta(bs.wi)).abs() < 1e-4);
        }
    }
    let frac = refl as Float / n as Float;
    assert!((frac - fr_dielectric(0.8, eta)).abs() < 0.005, "{frac}");
    // Only-transmission sampling never reflects.
    let bs = b
        .sample_f(
            wo,
            0.0,
            Point2f::new(0.5, 0.5),
            TransportMode::Radiance,
            BxDFReflTransFlags::TRANSMISSION,
        )
        .expect("transmission");
    assert!(bs.is_transmission() && bs.pdf == 1.0);
}

#[test]
fn thin_dielectric_interreflection() {
    let b = ThinDielectricBxDF::new(1.5);
    let (r, t) = b.reflectance_transmittance(1.0);
    let r0: Float = 0.04;
    let expect = r0 + sqr(1.0 - r0) * r0 / (1.0 - sqr(r0));
    assert!((r - expect).abs() < 1e-5 && (r + t - 1.0).abs() < 1e-6);
    // Transmission goes straight through.
    let wo = Vector3f::new(0.3, 0.4, 0.866).normalize();
    let bs = b
        .sample_f(
            wo,
            0.99,
            Point2f::new(0.5, 0.5),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        )
        .expect("sample");
    assert!(bs.is_transmission() && (bs.wi + wo).length() < 1e-6);
}

// ---------------------------------------------------------------------------
// χ² test (pbrt-v4 bsdfs_test.cpp): histogram of sampled directions over a
// (θ, φ) grid against the integral of `pdf` over each cell.

const THETA_RES: usize = 10;
const PHI_RES: usize = 2 * THETA_RES;

/// Regularized upper incomplete gamma Q(a, x).
fn gamma_q(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        // Lanczos approximation (g = 7, n = 9).
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let x = x - 1.0;
        let mut s = C[0];
        for (i, c) in C.iter().enumerate().skip(1) {
            s += c / (x + i as f64);
        }
        let t = x + 7.5;
        0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
    }
    if x <= 0.0 {
        return 1.0;
    }
    let lg = ln_gamma(a);
    if x < a + 1.0 {
        // Series for P.
        let mut sum = 1.0 / a;
        let mut del = sum;
        let mut ap = a;
        for _ in 0..1000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-14 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - lg).exp()
    } else {
        // Continued fraction for Q (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-14 {
                break;
            }
        }
        (-x + a * x.ln() - lg).exp() * h
    }
}

/// p-value of the χ² statistic over the cells, pooling cells with small
/// expected counts as pbrt does.
fn chi2_p_value(observed: &[f64], expected: &[f64], min_exp: f64) -> (f64, usize) {
    let mut idx: Vec<usize> = (0..expected.len()).collect();
    idx.sort_by(|&a, &b| {
        expected[a]
            .partial_cmp(&expected[b])
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let (mut pooled_o, mut pooled_e, mut pooled_n) = (0.0, 0.0, 0);
    let mut chsq = 0.0;
    let mut dof = 0usize;
    for &i in &idx {
        if expected[i] == 0.0 {
            assert!(
                observed[i] <= 1e-9 * observed.iter().sum::<f64>() + 1.0,
                "samples in a cell of zero density: {} at {i}",
                observed[i]
            );
        } else if expected[i] < min_exp || (pooled_n > 0 && pooled_e < min_exp) {
            pooled_o += observed[i];
            pooled_e += expected[i];
            pooled_n += 1;
        } else {
            chsq += (observed[i] - expected[i]).powi(2) / expected[i];
            dof += 1;
        }
    }
    if pooled_n > 0 {
        chsq += (pooled_o - pooled_e).powi(2) / pooled_e;
        dof += 1;
    }
    let dof = dof.saturating_sub(1).max(1);
    (gamma_q(dof as f64 / 2.0, chsq / 2.0), dof)
}

/// Integral of the model's pdf over each (θ, φ) cell by the composite
/// midpoint rule. Unlike Simpson's rule it never evaluates on a cell edge,
/// where the pdf jumps at the horizon (θ = 90° is an edge) and an edge value
/// would leak the lower hemisphere's density into the upper cell.
fn integrate_pdf_cells(b: &BxDF, wo: Vector3f) -> Vec<f64> {
    // Transmission lobes can have sharp features in θ near the horizon.
    const SUB_T: usize = 128;
    const SUB_P: usize = 32;
    let mut out = vec![0.0; THETA_RES * PHI_RES];
    let dt = PI as f64 / THETA_RES as f64;
    let dp = 2.0 * PI as f64 / PHI_RES as f64;
    for ti in 0..THETA_RES {
        for pi in 0..PHI_RES {
            let (t0, p0) = (ti as f64 * dt, pi as f64 * dp);
            let (ht, hp) = (dt / SUB_T as f64, dp / SUB_P as f64);
            let mut s = 0.0;
            for a in 0..SUB_T {
                let theta = t0 + (a as f64 + 0.5) * ht;
                for c in 0..SUB_P {
                    let phi = p0 + (c as f64 + 0.5) * hp;
                    let wi = spherical_direction(
                        theta.sin() as Float,
                        theta.cos() as Float,
                        phi as Float,
                    );
                    let pdf =
                        b.pdf(wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL) as f64;
                    s += pdf * theta.sin();
                }
            }
            out[ti * PHI_RES + pi] = s * ht * hp;
        }
    }
    out
}

pub(super) fn chi2_test(name: &str, b: &BxDF, seed: u64) {
    const N: usize = 200_000;
    const RUNS: usize = 3;
    let significance = 1.0 - (1.0f64 - 0.01).powf(1.0 / RUNS as f64);
    let mut rng = Rng::new(seed, 0);
    for run in 0..RUNS {
        let wo = loop {
            let w = rand_dir(&mut rng);
            if w.z.abs() > 0.1 {
                break w;
            }
        };
        let mut hist = vec![0.0f64; THETA_RES * PHI_RES];
        for _ in 0..N {
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
            if bs.pdf == 0.0 || bs.f.is_black() {
                continue;
            }
            let wi = bs.wi.normalize();
            let theta = safe_acos(wi.z) as f64;
            let mut phi = (wi.y as f64).atan2(wi.x as f64);
            if phi < 0.0 {
                phi += 2.0 * std::f64::consts::PI;
            }
            let ti =
                ((theta / std::f64::consts::PI * THETA_RES as f64) as usize).min(THETA_RES - 1);
            let pi =
                ((phi / (2.0 * std::f64::consts::PI) * PHI_RES as f64) as usize).min(PHI_RES - 1);
            hist[ti * PHI_RES + pi] += 1.0;
        }
        let expected: Vec<f64> = integrate_pdf_cells(b, wo)
            .iter()
            .map(|p| p * N as f64)
            .collect();
        let (p, dof) = chi2_p_value(&hist, &expected, 5.0);
        eprintln!("chi2 {name} run {run}: p = {p:.3e}, dof {dof}");
        assert!(
            p > significance,
            "{name}, run {run}: χ² rejects (p = {p:.3e}, dof {dof}) for wo {wo:?}"
        );
    }
}

#[test]
fn chi2_diffuse_and_diffuse_transmission() {
    chi2_test(
        "diffuse",
        &BxDF::Diffuse(DiffuseBxDF::new(SampledSpectrum::new(0.5))),
        200,
    );
    chi2_test(
        "diffuse transmission",
        &BxDF::DiffuseTransmission(DiffuseTransmissionBxDF::new(
            SampledSpectrum::new(0.2),
            SampledSpectrum::new(0.7),
        )),
        201,
    );
}

#[test]
fn chi2_conductor() {
    let (eta, k) = gold();
    for (i, (ax, ay)) in [(0.1, 0.1), (0.3, 0.3), (0.6, 0.2), (1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        chi2_test(
            &format!("conductor {ax} {ay}"),
            &BxDF::Conductor(ConductorBxDF::new(tr(ax, ay), eta, k)),
            210 + i as u64,
        );
    }
}

#[test]
fn chi2_rough_dielectric() {
    for (i, (e, a)) in [(1.5, 0.2), (1.5, 0.5), (1.33, 0.8), (0.7, 0.4)]
        .into_iter()
        .enumerate()
    {
        chi2_test(
            &format!("dielectric {e} {a}"),
            &BxDF::Dielectric(DielectricBxDF::new(e, tr(a, a))),
            220 + i as u64,
        );
    }
}

#[test]
fn chi2_hair() {
    for (i, (bm, bn, alpha)) in [(0.3, 0.3, 2.0), (0.5, 0.6, 0.0), (0.8, 0.2, 3.0)]
        .into_iter()
        .enumerate()
    {
        chi2_test(
            &format!("hair {bm} {bn}"),
            &BxDF::Hair(HairBxDF::new(
                -0.4,
                1.55,
                SampledSpectrum::new(0.3),
                bm,
                bn,
                alpha,
            )),
            230 + i as u64,
        );
    }
}

// ---------------------------------------------------------------------------
// Layered models.

fn coated_diffuse(eta: Float, a: Float, albedo: Float, thickness: Float, r: Float) -> BxDF {
    BxDF::CoatedDiffuse(CoatedDiffuseBxDF::new(
        DielectricBxDF::new(eta, tr(a, a)),
        DiffuseBxDF::new(SampledSpectrum::new(r)),
        thickness,
        SampledSpectrum::new(albedo),
        0.0,
        10,
        1,
    ))
}

#[test]
fn coated_diffuse_with_invisible_coating_is_diffuse() {
    // eta 1, no medium, vanishing thickness: f = R/π.
    let mut rng = Rng::new(300, 0);
    let b = coated_diffuse(1.0, 0.0, 0.0, 1e-6, 1.0);
    for _ in 0..200 {
        let wo = rand_dir(&mut rng);
        let mut wi = rand_dir(&mut rng);
        if !same_hemisphere(wo, wi) {
            wi = -wi;
        }
        let f = b.f(wo, wi, TransportMode::Radiance)[0];
        assert!((f - INV_PI).abs() < 1e-3 * INV_PI, "{f}");
        // Deterministic per call.
        assert_eq!(f, b.f(wo, wi, TransportMode::Radiance)[0]);
    }
    let wo = Vector3f::new(0.2, 0.1, 0.97).normalize();
    let rho = albedo(&b, wo, TransportMode::Radiance, 20_000, &mut rng)[0];
    assert!((rho - 1.0).abs() < 0.02, "{rho}");
}

#[test]
fn layered_sampling_matches_evaluation() {
    // ∫ f |cos| estimated from `f` by uniform sampling must match the
    // estimate from `sample_f`'s weights (pbrt-v4's layered sample_f returns
    // a path throughput and a proportional pdf).
    let mut rng = Rng::new(301, 0);
    let (eta, k) = gold();
    let models = [
        coated_diffuse(1.5, 0.0, 0.0, 0.01, 0.8),
        coated_diffuse(1.5, 0.3, 0.0, 0.01, 0.5),
        coated_diffuse(1.5, 0.0, 0.8, 0.1, 0.5),
        BxDF::CoatedConductor(CoatedConductorBxDF::new(
            DielectricBxDF::new(1.5, tr(0.2, 0.2)),
            ConductorBxDF::new(tr(0.3, 0.3), eta, k),
            0.01,
            SampledSpectrum::new(0.0),
            0.0,
            10,
            1,
        )),
    ];
    for b in &models {
        let wo = Vector3f::new(0.3, -0.2, 0.8).normalize();
        let n = 60_000;
        let mut uniform = 0.0f64;
        for _ in 0..n {
            let wi = rand_dir(&mut rng);
            uniform += (b.f(wo, wi, TransportMode::Radiance).average() * abs_cos_theta(wi)
                / UNIFORM_SPHERE_PDF) as f64;
        }
        let uniform = uniform / n as f64;
        let sampled = albedo(b, wo, TransportMode::Radiance, n, &mut rng).average() as f64;
        // The specular coating's mirror lobe is invisible to `f`; remove it.
        let mirror = match b {
            BxDF::CoatedDiffuse(_) | BxDF::CoatedConductor(_) if b.flags().is_specular() => {
                fr_dielectric(wo.z, 1.5) as f64
            }
            _ => 0.0,
        };
        let sampled = sampled - mirror;
        // pbrt-v4 weights the exit-interface connection after a sampled
        // bounce with the exit's forward density pdf(-w, wi) rather than the
        // density of the presampled reverse direction; with a rough coating
        // over a rough or diffuse base the MIS weights then do not sum to one
        // and `f` runs about 7% high here (using the reverse density instead
        // makes the two estimates agree to 0.2%). We keep pbrt's estimator
        // so images match, and allow for it.
        let both_rough = !b.flags().is_specular();
        let tol = if both_rough { 0.1 } else { 0.03 };
        assert!(
            (uniform - sampled).abs() < tol * uniform.max(sampled) + 0.003,
            "{b:?}: uniform {uniform} sampled {sampled}"
        );
        // The layered pdf is positive where f is.
        let wi = Vector3f::new(-0.1, 0.4, 0.9).normalize();
        assert!(b.pdf(wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL) > 0.0);
    }
}

#[test]
fn layered_flags_and_two_sidedness() {
    let b = coated_diffuse(1.5, 0.0, 0.0, 0.01, 0.5);
    assert_eq!(
        b.flags(),
        BxDFFlags::REFLECTION | BxDFFlags::SPECULAR | BxDFFlags::DIFFUSE
    );
    let wo = Vector3f::new(0.3, -0.2, 0.8).normalize();
    let wi = Vector3f::new(-0.1, 0.4, 0.9).normalize();
    let a = b.f(wo, wi, TransportMode::Radiance);
    let c = b.f(-wo, -wi, TransportMode::Radiance);
    assert_eq!(a, c);
    let bs = b
        .sample_f(
            -wo,
            0.99,
            Point2f::new(0.3, 0.6),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        )
        .expect("sample");
    assert!(bs.wi.z < 0.0 && bs.pdf_is_proportional);
}

// ---------------------------------------------------------------------------
// BSDF and dispatch.

#[test]
fn bsdf_frame_conversion() {
    let mut rng = Rng::new(400, 0);
    let ns = Normal3f::new(0.2, 0.3, 0.9).normalize();
    let n = Vector3f::from(ns);
    let dpdu = Vector3f::new(1.0, 0.0, 0.0).gram_schmidt(n) * 3.0;
    let (eta, k) = gold();
    let bxdf = BxDF::Conductor(ConductorBxDF::new(tr(0.2, 0.2), eta, k));
    let bsdf = BSDF::new(ns, dpdu, bxdf);
    assert!((bsdf.local_to_render(Vector3f::new(0.0, 0.0, 1.0)) - n).length() < 1e-5);
    assert!(
        (bsdf.local_to_render(Vector3f::new(1.0, 0.0, 0.0)) - dpdu.normalize()).length() < 1e-5
    );
    for _ in 0..1000 {
        let wo = rand_dir(&mut rng);
        let wi = rand_dir(&mut rng);
        let f = bsdf.f(wo, wi, TransportMode::Radiance);
        let fl = bxdf.f(
            bsdf.render_to_local(wo),
            bsdf.render_to_local(wi),
            TransportMode::Radiance,
        );
        assert_eq!(f, fl);
        let uc = rng.uniform_float();
        if let Some(bs) = bsdf.sample_f(
            wo,
            uc,
            u2(&mut rng),
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        ) {
            assert!(bs.pdf > 0.0 && !bs.f.is_black());
            assert!(dot(bs.wi, n) * dot(wo, n) > 0.0);
            let p = bsdf.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
            assert!(approx(p, bs.pdf, 2e-3));
        }
        // A conductor cannot be sampled for transmission only.
        assert!(bsdf
            .sample_f(
                wo,
                uc,
                u2(&mut rng),
                TransportMode::Radiance,
                BxDFReflTransFlags::TRANSMISSION
            )
            .is_none());
    }
    // Tangent wo is rejected.
    let tangent = bsdf.local_to_render(Vector3f::new(1.0, 0.0, 0.0));
    let tangent_local = bsdf.render_to_local(tangent);
    if tangent_local.z == 0.0 {
        assert!(bsdf.f(tangent, n, TransportMode::Radiance).is_black());
    }
    let mut reg = bsdf;
    reg.regularize();
    assert_ne!(reg, bsdf);
}

#[test]
fn bxdf_enum_stays_small() {
    assert!(
        std::mem::size_of::<BxDF>() <= 128,
        "{}",
        std::mem::size_of::<BxDF>()
    );
}

#[test]
fn transport_mode_and_flags() {
    assert_eq!(!TransportMode::Radiance, TransportMode::Importance);
    let f = BxDFFlags::GLOSSY_REFLECTION | BxDFFlags::SPECULAR_TRANSMISSION;
    assert!(f.is_reflective() && f.is_transmissive() && f.is_glossy() && f.is_specular());
    assert!(!f.is_diffuse() && f.is_non_specular());
    assert!(BxDFFlags::DIFFUSE_REFLECTION.allows(BxDFReflTransFlags::REFLECTION));
    assert!(!BxDFFlags::DIFFUSE_REFLECTION.allows(BxDFReflTransFlags::TRANSMISSION));
    assert!(BxDFFlags::UNSET.is_unset());
}
