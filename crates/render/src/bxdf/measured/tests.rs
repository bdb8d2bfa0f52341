//! Tests of the tensor reader, the 2-D warps and the measured BRDF on
//! synthetic data (no RGL measurement is available offline).

use std::path::PathBuf;

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, spherical_direction};

use super::*;
use crate::bxdf::{BxDF, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::rng::Rng;
use crate::sampling::{sample_uniform_hemisphere, UNIFORM_HEMISPHERE_PDF};

fn f32_field(shape: &[usize], v: &[f32]) -> TensorField {
    assert_eq!(shape.iter().product::<usize>(), v.len());
    TensorField {
        dtype: TensorType::Float32,
        shape: shape.to_vec(),
        data: v.iter().flat_map(|x| x.to_le_bytes()).collect(),
    }
}

fn u8_field(v: &[u8]) -> TensorField {
    TensorField {
        dtype: TensorType::UInt8,
        shape: vec![v.len()],
        data: v.to_vec(),
    }
}

fn temp_path(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-measured-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{tag}.bsdf"))
}

/// Reflectance of the synthetic material, linear in λ so that interpolation
/// over the three tabulated wavelengths is exact.
fn albedo(lambda: Float) -> Float {
    0.2 + 0.6 * (lambda - 360.0) / 470.0
}

/// A tabulated Lambertian BRDF with reflectance [`albedo`], in the
/// Dupuy–Jakob representation: a uniform NDF D = 1/π (so σ(ω) =
/// (1 + cos θ)/2), its visible normals, a non-uniform luminance (to exercise
/// the composed warps) and spectra R = 4 σ(θo) cos θi ρ(λ) / (π D), which
/// make f = ρ/π. `n_phi` φo values (1: isotropic).
fn lambertian_fields(n_phi: usize) -> Vec<(&'static str, TensorField)> {
    let n = 25; // grid resolution of every 2-D table
    let nt = 7; // θo values
    let theta_i: Vec<f32> = (0..nt)
        .map(|k| u2theta(k as Float / (nt - 1) as Float))
        .collect();
    let phi_i: Vec<f32> = if n_phi == 1 {
        vec![0.0]
    } else {
        (0..n_phi)
            .map(|k| -PI + 2.0 * PI * k as Float / (n_phi - 1) as Float)
            .collect()
    };
    let wavelengths = [360.0f32, 560.0, 830.0];
    let grid = |i: usize| i as Float / (n - 1) as Float;
    let d = 1.0 / PI;
    let sigma_of = |theta: Float| 0.5 * (1.0 + theta.cos());

    let mut ndf = Vec::new();
    let mut sigma = Vec::new();
    for _y in 0..n {
        for x in 0..n {
            ndf.push(d);
            sigma.push(sigma_of(u2theta(grid(x))));
        }
    }
    let mut vndf = Vec::new();
    let mut luminance = Vec::new();
    for &phi_o in &phi_i {
        for &theta_o in &theta_i {
            let wo = spherical_direction(theta_o.sin(), theta_o.cos(), phi_o);
            for y in 0..n {
                for x in 0..n {
                    let (ut, up) = (grid(x), grid(y));
                    let theta_m = u2theta(ut);
                    let mut phi_m = u2phi(up);
                    if n_phi == 1 {
                        phi_m += phi_o;
                    }
                    let wm = spherical_direction(theta_m.sin(), theta_m.cos(), phi_m);
                    let jac = 2.0 * PI * PI * ut * theta_m.sin();
                    vndf.push(d * dot(wo, wm).max(0.0) * jac);
                    luminance.push(1.0 + 0.5 * grid(x) + 0.25 * grid(y));
                }
            }
        }
    }
    // The spectra need the VNDF warp: R at a sample-space node depends on
    // the ωi its microfacet normal reflects ωo to.
    let vndf_warp =
        PiecewiseLinear2D::<2>::new(&vndf, n, n, [&phi_i, &theta_i], true, true).unwrap();
    let mut spectra = Vec::new();
    for &phi_o in &phi_i {
        for &theta_o in &theta_i {
            let wo = spherical_direction(theta_o.sin(), theta_o.cos(), phi_o);
            for &lambda in &wavelengths {
                for y in 0..n {
                    for x in 0..n {
                        let s = Point2f::new(grid(x), grid(y));
                        let u_wm = vndf_warp.sample(s, &[phi_o, theta_o]).p;
                        let theta_m = u2theta(u_wm.x);
                        let mut phi_m = u2phi(u_wm.y);
                        if n_phi == 1 {
                            phi_m += phi_o;
                        }
                        let wm = spherical_direction(theta_m.sin(), theta_m.cos(), phi_m);
                        let wi = reflect(wo, wm);
                        let r = 4.0 * sigma_of(theta_o) * wi.z.max(0.0) * albedo(lambda) / (PI * d);
                        spectra.push(r);
                    }
                }
            }
        }
    }
    let (np, nt, nw) = (phi_i.len(), theta_i.len(), wavelengths.len());
    vec![
        ("description", u8_field(b"synthetic Lambertian")),
        ("jacobian", u8_field(&[1])),
        ("theta_i", f32_field(&[nt], &theta_i)),
        ("phi_i", f32_field(&[np], &phi_i)),
        ("wavelengths", f32_field(&[nw], &wavelengths)),
        ("ndf", f32_field(&[n, n], &ndf)),
        ("sigma", f32_field(&[n, n], &sigma)),
        ("vndf", f32_field(&[np, nt, n, n], &vndf)),
        ("luminance", f32_field(&[np, nt, n, n], &luminance)),
        ("spectra", f32_field(&[np, nt, nw, n, n], &spectra)),
    ]
}

fn encode(fields: &[(&'static str, TensorField)]) -> Vec<u8> {
    let refs: Vec<(&str, &TensorField)> = fields.iter().map(|(n, f)| (*n, f)).collect();
    write_tensor_bytes(&refs)
}

/// Writes a synthetic file and loads it through the process-wide cache.
fn lambertian(n_phi: usize) -> &'static MeasuredBxDFData {
    let path = temp_path(&format!("lambert-{n_phi}"));
    std::fs::write(&path, encode(&lambertian_fields(n_phi))).unwrap();
    MeasuredBxDFData::cached(&path).unwrap()
}

fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_uniform(0.3, 360.0, 830.0)
}

#[test]
fn tensor_file_round_trips() {
    let fields = lambertian_fields(1);
    let path = temp_path("roundtrip");
    std::fs::write(&path, encode(&fields)).unwrap();
    let t = read_tensor_file(&path).unwrap();
    assert_eq!(t.len(), fields.len());
    for (name, f) in &fields {
        assert_eq!(t.get(*name), Some(f), "{name}");
    }
    let th = t["theta_i"].as_f32().unwrap();
    assert_eq!(th.len(), 7);
    assert!((th[6] - PI / 2.0).abs() < 1e-6);
    assert_eq!(t["description"].as_f32(), None);
}

#[test]
fn truncated_and_corrupted_files_are_errors() {
    let good = encode(&lambertian_fields(1));
    assert!(parse_tensor_bytes(&good).is_ok());
    // Every proper prefix is an error (the data come last), never a panic.
    for len in (0..good.len()).step_by(7).chain(good.len() - 3..good.len()) {
        assert!(parse_tensor_bytes(&good[..len]).is_err(), "prefix {len}");
    }
    let mut bad = good.clone();
    bad[0] = b'T';
    assert!(parse_tensor_bytes(&bad).unwrap_err().contains("header"));
    let mut bad = good.clone();
    bad[12] = 2;
    assert!(parse_tensor_bytes(&bad).unwrap_err().contains("version"));
    // First field: name length at 18, name "description" (11), rank, type.
    let type_at = 18 + 2 + 11 + 2;
    assert_eq!(good[type_at], TensorType::UInt8.code());
    for code in [0u8, 12, 255] {
        let mut bad = good.clone();
        bad[type_at] = code;
        assert!(parse_tensor_bytes(&bad).unwrap_err().contains("type"));
    }
    // Absurd extents and offsets fail before any allocation.
    let shape_at = type_at + 1 + 8;
    for extent in [u64::MAX, 1 << 40, u64::MAX / 2] {
        let mut bad = good.clone();
        bad[shape_at..shape_at + 8].copy_from_slice(&extent.to_le_bytes());
        assert!(parse_tensor_bytes(&bad).is_err());
    }
    let mut bad = good.clone();
    bad[type_at + 1..type_at + 9].copy_from_slice(&(u64::MAX - 3).to_le_bytes());
    assert!(parse_tensor_bytes(&bad).is_err());
    // A huge field count with nothing behind it.
    let mut bad = good.clone();
    bad[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(parse_tensor_bytes(&bad).is_err());
    // Seeded garbage never panics.
    let mut rng = Rng::with_sequence(7);
    for _ in 0..200 {
        let mut g = good.clone();
        for _ in 0..4 {
            let i = (rng.uniform_float() * g.len() as Float) as usize % g.len();
            g[i] = (rng.uniform_float() * 256.0) as u8;
        }
        if let Ok(t) = parse_tensor_bytes(&g) {
            let _ = MeasuredBxDFData::from_tensors(&t, "garbage");
        }
    }
    let missing = temp_path("does-not-exist-x");
    let e = MeasuredBxDFData::read(&missing).unwrap_err();
    assert!(e.contains("unable to open"), "{e}");
}

#[test]
fn inconsistent_structure_is_an_error() {
    let fields = lambertian_fields(1);
    let without = |name: &str| -> Tensors {
        fields
            .iter()
            .filter(|(n, _)| *n != name)
            .map(|(n, f)| (n.to_string(), f.clone()))
            .collect()
    };
    for name in ["vndf", "spectra", "jacobian", "description", "theta_i"] {
        let e = MeasuredBxDFData::from_tensors(&without(name), "x").unwrap_err();
        assert!(e.contains(name), "{e}");
    }
    let mut t = without("");
    t.insert("wavelengths".into(), f32_field(&[2], &[400.0, 700.0]));
    let e = MeasuredBxDFData::from_tensors(&t, "x").unwrap_err();
    assert!(e.contains("spectra"), "{e}");
    let mut t = without("");
    t.insert("ndf".into(), f32_field(&[1, 3], &[1.0, 1.0, 1.0]));
    assert!(MeasuredBxDFData::from_tensors(&t, "x").is_err());
    let mut t = without("");
    t.insert(
        "sigma".into(),
        f32_field(&[2, 2], &[1.0, f32::NAN, 1.0, 1.0]),
    );
    assert!(MeasuredBxDFData::from_tensors(&t, "x").is_err());
    // Anisotropic data must cover the full φ range.
    let mut t: Tensors = lambertian_fields(3)
        .into_iter()
        .map(|(n, f)| (n.to_string(), f))
        .collect();
    t.insert("phi_i".into(), f32_field(&[3], &[0.0, 0.5, 1.0]));
    let e = MeasuredBxDFData::from_tensors(&t, "x").unwrap_err();
    assert!(e.contains("reduction"), "{e}");
}

/// A positive table of `slices` grids, seeded.
fn random_table(rng: &mut Rng, nx: usize, ny: usize, slices: usize) -> Vec<f32> {
    (0..nx * ny * slices)
        .map(|_| 0.05 + rng.uniform_float())
        .collect()
}

/// The integral of `w.evaluate` over the unit square (midpoint rule).
fn integral<const N: usize>(w: &PiecewiseLinear2D<N>, param: &[Float; N]) -> f64 {
    let m = 200;
    let mut sum = 0.0f64;
    for j in 0..m {
        for i in 0..m {
            let p = Point2f::new(
                (i as Float + 0.5) / m as Float,
                (j as Float + 0.5) / m as Float,
            );
            sum += w.evaluate(p, param) as f64;
        }
    }
    sum / (m * m) as f64
}

#[test]
fn piecewise_linear_2d_samples_inverts_and_normalizes() {
    let mut rng = Rng::with_sequence(3);
    let (nx, ny) = (6, 4);
    let w0 =
        PiecewiseLinear2D::<0>::new(&random_table(&mut rng, nx, ny, 1), nx, ny, [], true, true)
            .unwrap();
    let pa = [0.0f32, 1.0, 3.0];
    let pb = [-1.0f32, 2.0];
    let w2 = PiecewiseLinear2D::<2>::new(
        &random_table(&mut rng, nx, ny, 6),
        nx,
        ny,
        [&pa, &pb],
        true,
        true,
    )
    .unwrap();
    assert!((integral(&w0, &[]) - 1.0).abs() < 1e-3);
    for param in [[0.0, -1.0], [0.4, 1.3], [2.9, 2.0], [3.5, -4.0]] {
        assert!((integral(&w2, &param) - 1.0).abs() < 1e-3, "{param:?}");
    }
    for i in 0..2000 {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let param = [3.0 * rng.uniform_float(), -1.0 + 3.0 * rng.uniform_float()];
        let s0 = w0.sample(u, &[]);
        let s2 = w2.sample(u, &param);
        for (s, inv, ev) in [
            (s0, w0.invert(s0.p, &[]), w0.evaluate(s0.p, &[])),
            (s2, w2.invert(s2.p, &param), w2.evaluate(s2.p, &param)),
        ] {
            assert!((0.0..=1.0).contains(&s.p.x) && (0.0..=1.0).contains(&s.p.y));
            assert!(
                (inv.p.x - u.x).abs() < 2e-3 && (inv.p.y - u.y).abs() < 2e-3,
                "{i}: {u:?} {inv:?}"
            );
            assert!((inv.pdf - s.pdf).abs() < 1e-3 * s.pdf.max(1.0), "{i}");
            assert!((ev - s.pdf).abs() < 1e-3 * s.pdf.max(1.0), "{i}");
        }
    }
    // Sampling follows the density: a χ²-like check on a 4×4 histogram.
    let mut hist = [0u32; 16];
    let n = 40000;
    for _ in 0..n {
        let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let p = w2.sample(u, &[1.5, 0.5]).p;
        let (i, j) = (((p.x * 4.0) as usize).min(3), ((p.y * 4.0) as usize).min(3));
        hist[j * 4 + i] += 1;
    }
    for j in 0..4 {
        for i in 0..4 {
            let mut expected = 0.0;
            for b in 0..20 {
                for a in 0..20 {
                    let p = Point2f::new(
                        (i as Float + (a as Float + 0.5) / 20.0) / 4.0,
                        (j as Float + (b as Float + 0.5) / 20.0) / 4.0,
                    );
                    expected += w2.evaluate(p, &[1.5, 0.5]) / (16.0 * 400.0);
                }
            }
            let got = hist[j * 4 + i] as Float / n as Float;
            assert!(
                (got - expected).abs() < 0.01,
                "bin {i},{j}: {got} vs {expected}"
            );
        }
    }
    // Raw (unnormalized) tables interpolate their values.
    let raw = PiecewiseLinear2D::<0>::new(&[1.0, 3.0, 5.0, 7.0], 2, 2, [], false, false).unwrap();
    assert!((raw.evaluate(Point2f::new(0.5, 0.5), &[]) - 4.0).abs() < 1e-6);
    assert!((raw.evaluate(Point2f::new(1.0, 0.0), &[]) - 3.0).abs() < 1e-6);
    assert!(!raw.has_cdf());
    // Bad shapes are errors.
    assert!(PiecewiseLinear2D::<0>::new(&[1.0; 3], 2, 2, [], true, true).is_err());
    assert!(PiecewiseLinear2D::<0>::new(&[1.0; 2], 1, 2, [], true, true).is_err());
    assert!(PiecewiseLinear2D::<0>::new(&[1.0; 4], 2, 2, [], false, true).is_err());
    let empty: [f32; 0] = [];
    assert!(PiecewiseLinear2D::<1>::new(&[1.0; 4], 2, 2, [&empty], true, true).is_err());
}

#[test]
fn lambertian_table_gives_albedo_over_pi() {
    for n_phi in [1, 9] {
        let data = lambertian(n_phi);
        assert_eq!(data.isotropic, n_phi == 1);
        let l = lambda();
        let b = MeasuredBxDF::new(data, &l);
        let mut rng = Rng::with_sequence(11);
        let (mut worst, mut sum, mut count): (Float, Float, usize) = (0.0, 0.0, 0);
        for _ in 0..300 {
            let wo =
                sample_uniform_hemisphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            let wi =
                sample_uniform_hemisphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            if wo.z < 0.5 || wi.z < 0.5 {
                continue;
            }
            let f = b.f(wo, wi, TransportMode::Radiance);
            for i in 0..N_SPECTRUM_SAMPLES {
                let expected = albedo(l[i]) * INV_PI;
                let e = (f[i] - expected).abs() / expected;
                worst = worst.max(e);
                sum += e;
                count += 1;
            }
            // Both sides of the surface behave alike; no transmission.
            let fb = b.f(-wo, -wi, TransportMode::Radiance);
            assert!((fb[0] - f[0]).abs() <= 1e-6 * f[0]);
            assert!(b.f(wo, -wi, TransportMode::Radiance).is_black());
        }
        // The table is exact at its nodes; between them, bilinear
        // interpolation on the sample space is coarse where the half vector
        // nears the normal (the VNDF table vanishes like u³ there), hence
        // the looser bound on the worst case. A swapped cosine or a missing
        // π would be off by far more on average.
        let mean = sum / count as Float;
        assert!(mean < 0.03, "n_phi {n_phi}: mean relative error {mean}");
        assert!(worst < 0.25, "n_phi {n_phi}: worst relative error {worst}");
    }
}

#[test]
fn sample_f_matches_f_and_pdf() {
    for n_phi in [1, 9] {
        let b = MeasuredBxDF::new(lambertian(n_phi), &lambda());
        assert_eq!(b.flags(), BxDFFlags::GLOSSY_REFLECTION);
        let mut rng = Rng::with_sequence(5);
        let mut n_ok = 0;
        for _ in 0..2000 {
            let mut wo =
                sample_uniform_hemisphere(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            if rng.uniform_float() < 0.3 {
                wo = -wo;
            }
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let Some(bs) = b.sample_f(wo, 0.5, u, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            else {
                continue;
            };
            n_ok += 1;
            assert!(!bs.pdf_is_proportional);
            assert_eq!(bs.flags, BxDFFlags::GLOSSY_REFLECTION);
            assert!(bs.wi.z * wo.z > 0.0);
            let pdf = b.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL);
            let f = b.f(wo, bs.wi, TransportMode::Radiance);
            assert!(
                (pdf - bs.pdf).abs() <= 2e-3 * bs.pdf + 1e-5,
                "pdf {pdf} vs {}",
                bs.pdf
            );
            for i in 0..N_SPECTRUM_SAMPLES {
                assert!(
                    (f[i] - bs.f[i]).abs() <= 2e-3 * bs.f[i] + 1e-6,
                    "{f:?} vs {:?}",
                    bs.f
                );
            }
        }
        // Half vectors beyond 45° from ωo's mirror are rejected (wi.z ≤ 0).
        assert!(n_ok > 1000, "{n_ok}");
        let wo = Vector3f::new(0.3, 0.2, 0.9).normalize();
        let u = Point2f::new(0.3, 0.6);
        let refl_only = BxDFReflTransFlags::TRANSMISSION;
        assert!(b
            .sample_f(wo, 0.5, u, TransportMode::Radiance, refl_only)
            .is_none());
        assert_eq!(b.pdf(wo, wo, TransportMode::Radiance, refl_only), 0.0);
    }
}

#[test]
fn energy_is_conserved_and_pdf_integrates_to_at_most_one() {
    let b = BxDF::Measured(MeasuredBxDF::new(lambertian(1), &lambda()));
    let mut rng = Rng::with_sequence(9);
    let n = 20000;
    let uc: Vec<Float> = (0..n).map(|_| rng.uniform_float()).collect();
    let u2: Vec<Point2f> = (0..n)
        .map(|_| Point2f::new(rng.uniform_float(), rng.uniform_float()))
        .collect();
    let l = lambda();
    for cos_o in [1.0f32, 0.8, 0.5] {
        let wo = spherical_direction(safe_sqrt(1.0 - cos_o * cos_o), cos_o, 0.7);
        let r = b.rho_hd(wo, &uc, &u2);
        for i in 0..N_SPECTRUM_SAMPLES {
            assert!(r[i] <= 1.0, "{r:?}");
            assert!((r[i] - albedo(l[i])).abs() < 0.05, "cos {cos_o}: {r:?}");
        }
        // ∫ pdf dωi over the hemisphere: the fraction of samples kept.
        let mut integral = 0.0;
        for u in &u2 {
            let wi = sample_uniform_hemisphere(*u);
            integral += b.pdf(wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
                / UNIFORM_HEMISPHERE_PDF;
        }
        integral /= n as Float;
        // At normal incidence only normals within 45° of the normal reflect
        // into the hemisphere: P = sin²45° = 1/2 for this NDF.
        assert!(
            integral <= 1.02 && integral > 0.4,
            "cos {cos_o}: {integral}"
        );
    }
    // Estimates of f cos θ / pdf are bounded: importance sampling works.
    let wo = Vector3f::new(0.0, 0.0, 1.0);
    for u in u2.iter().take(2000) {
        if let Some(bs) = b.sample_f(
            wo,
            0.5,
            *u,
            TransportMode::Radiance,
            BxDFReflTransFlags::ALL,
        ) {
            let w = bs.f[0] * abs_cos_theta(bs.wi) / bs.pdf;
            assert!(w.is_finite() && w < 10.0, "{w}");
        }
    }
}

#[test]
fn data_are_cached_per_file_and_enum_stays_small() {
    let a = lambertian(1);
    let path = temp_path("lambert-1");
    let b = MeasuredBxDFData::cached(&path).unwrap();
    assert!(std::ptr::eq(a, b));
    assert!(std::mem::size_of::<MeasuredBxDF>() <= 48);
    let x = BxDF::Measured(MeasuredBxDF::new(a, &lambda()));
    assert_eq!(x.name(), "MeasuredBxDF");
    assert_eq!(x, x);
}
