//! Tests of the spline tools, the beam-diffusion table and the tabulated
//! BSSRDF.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use super::*;
use crate::rng::Rng;
use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

fn table() -> &'static BssrdfTable {
    beam_diffusion_table(0.0, 1.33)
}

#[test]
fn catmull_rom_weights_reproduce_evaluation() {
    let nodes = [0.0, 0.3, 0.5, 1.2, 2.0, 2.1];
    let values = [1.0, -0.5, 2.0, 0.7, 3.0, 0.1];
    let mut rng = Rng::new(7, 0);
    for _ in 0..200 {
        let x = 2.1 * rng.uniform_float();
        let (off, w) = catmull_rom_weights(&nodes, x).unwrap();
        let mut v = 0.0;
        for (j, &wj) in w.iter().enumerate() {
            if wj != 0.0 {
                v += wj * values[(off + j as isize) as usize];
            }
        }
        let e = catmull_rom(&nodes, &values, x);
        assert!((v - e).abs() < 1e-4, "x={x}: {v} vs {e}");
    }
    // Interpolating at the nodes themselves.
    for (i, &x) in nodes.iter().enumerate() {
        assert!((catmull_rom(&nodes, &values, x) - values[i]).abs() < 1e-5);
    }
    assert!(catmull_rom_weights(&nodes, -0.01).is_none());
    assert!(catmull_rom_weights(&nodes, 2.11).is_none());
    assert!(catmull_rom_weights(&nodes, Float::NAN).is_none());
}

#[test]
fn integrate_matches_quadrature_and_invert_inverts_it() {
    // A smooth positive function on non-uniform nodes.
    let f = |x: Float| 1.0 + x.sin() + 0.3 * x * x;
    let nodes: Vec<Float> = (0..40).map(|i| 3.0 * sqr(i as Float / 39.0)).collect();
    let values: Vec<Float> = nodes.iter().map(|&x| f(x)).collect();
    let mut cdf = vec![0.0; nodes.len()];
    let total = integrate_catmull_rom(&nodes, &values, &mut cdf);
    let exact = 3.0 + (1.0 - (3.0 as Float).cos()) + 0.1 * 27.0;
    assert!((total - exact).abs() < 2e-3 * exact, "{total} vs {exact}");
    assert_eq!(cdf[0], 0.0);
    assert_eq!(*cdf.last().unwrap(), total);
    assert!(cdf.windows(2).all(|w| w[1] > w[0]));
    // The spline through the running integral, inverted, gives back x.
    let mut rng = Rng::new(3, 0);
    for _ in 0..200 {
        let x = 3.0 * rng.uniform_float();
        let y = catmull_rom(&nodes, &cdf, x);
        let xi = invert_catmull_rom(&nodes, &cdf, y);
        assert!((xi - x).abs() < 1e-3, "x={x} y={y} inverted to {xi}");
    }
    // Out-of-range values clamp to the ends.
    assert_eq!(invert_catmull_rom(&nodes, &cdf, -1.0), 0.0);
    assert_eq!(invert_catmull_rom(&nodes, &cdf, total + 1.0), 3.0);
}

#[test]
fn sample_catmull_rom_2d_pdf_matches_and_histograms() {
    let nodes1 = [0.0, 0.5, 1.0];
    let nodes2: Vec<Float> = (0..20).map(|i| i as Float / 19.0).collect();
    let g = |a: Float, x: Float| (1.0 + a) * (-3.0 * a * x).exp() + 0.2 * x;
    let mut values = Vec::new();
    for &a in &nodes1 {
        values.extend(nodes2.iter().map(|&x| g(a, x)));
    }
    let mut cdf = vec![0.0; values.len()];
    for (row, c) in values.chunks(20).zip(cdf.chunks_mut(20)) {
        integrate_catmull_rom(&nodes2, row, c);
    }
    let alpha = 0.7;
    let mut rng = Rng::new(11, 0);
    const BINS: usize = 10;
    let mut hist = [0usize; BINS];
    let n = 100_000;
    for _ in 0..n {
        let s = sample_catmull_rom_2d(&nodes1, &nodes2, &values, &cdf, alpha, rng.uniform_float())
            .unwrap();
        assert!((0.0..=1.0).contains(&s.x));
        hist[((s.x * BINS as Float) as usize).min(BINS - 1)] += 1;
        // The reported pdf is the interpolated function over its integral.
        assert!(s.pdf > 0.0 && s.fval > 0.0);
    }
    // The density each bin should hold, by integrating g(alpha, ·) (the
    // row interpolation is near-exact for this smooth family).
    let total: Float = (0..1000)
        .map(|i| g(alpha, (i as Float + 0.5) / 1000.0))
        .sum();
    for (b, &h) in hist.iter().enumerate() {
        let want: Float = (0..100)
            .map(|i| {
                g(
                    alpha,
                    (b as Float + (i as Float + 0.5) / 100.0) / BINS as Float,
                )
            })
            .sum::<Float>()
            / total;
        let got = h as Float / n as Float;
        assert!((got - want).abs() < 0.01, "bin {b}: {got} vs {want}");
    }
    assert!(sample_catmull_rom_2d(&nodes1, &nodes2, &values, &cdf, 1.5, 0.5).is_none());
}

#[test]
fn table_layout_and_values_are_sane() {
    let t = table();
    assert_eq!(t.rho_samples.len(), N_RHO_SAMPLES);
    assert_eq!(t.radius_samples.len(), N_RADIUS_SAMPLES);
    assert_eq!(t.rho_samples[0], 0.0);
    assert!((t.rho_samples[N_RHO_SAMPLES - 1] - 1.0).abs() < 1e-6);
    assert_eq!(t.radius_samples[0], 0.0);
    assert_eq!(t.radius_samples[1], 2.5e-3);
    assert!(t.radius_samples.windows(2).all(|w| w[1] > w[0]));
    assert!(t.rho_samples.windows(2).all(|w| w[1] > w[0]));
    assert!(t.profile.iter().all(|p| p.is_finite() && *p >= 0.0));
    assert!(t.profile_cdf.iter().all(|p| p.is_finite()));
    // ρ_eff grows with ρ, from 0 for a pure absorber, and stays below 1.
    assert_eq!(t.rho_eff[0], 0.0);
    assert!(t.rho_eff.windows(2).all(|w| w[1] > w[0]), "{:?}", t.rho_eff);
    let top = t.rho_eff[N_RHO_SAMPLES - 1];
    // A non-absorbing medium returns all light that enters it, so the
    // effective albedo at ρ = 1 should be close to one; photon beam
    // diffusion overshoots slightly (1.019 for g = 0, η = 1.33).
    assert!((top - 1.0).abs() < 0.03, "rho_eff(1) = {top}");
    // Half the albedo loses far more than half the light to absorption
    // along the long multiple-scattering paths.
    let half = crate::bssrdf::catmull_rom(&t.rho_samples, &t.rho_eff, 0.5);
    assert!(half < 0.25, "rho_eff(0.5) = {half}");
    // Each row's running integral ends at its ρ_eff.
    for i in 0..N_RHO_SAMPLES {
        assert_eq!(
            t.profile_cdf[i * N_RADIUS_SAMPLES + N_RADIUS_SAMPLES - 1],
            t.rho_eff[i]
        );
    }
    // Cached: the same table comes back.
    assert!(std::ptr::eq(t, beam_diffusion_table(0.0, 1.33)));
    assert!(!std::ptr::eq(t, beam_diffusion_table(0.5, 1.33)));
}

#[test]
fn profile_integral_matches_rho_eff() {
    // Integrate 2π r Sr(r) over the plane by midpoint quadrature in log
    // radius, independently of the table's own integration.
    let t = table();
    for &rho in &[0.3, 0.8, 0.99] {
        let b = TabulatedBssrdf::new(
            Point3f::new(0.0, 0.0, 0.0),
            Normal3f::new(0.0, 0.0, 1.0),
            Vector3f::new(0.0, 0.0, 1.0),
            1.33,
            SampledSpectrum::new(1.0 - rho),
            SampledSpectrum::new(rho),
            t,
        );
        let r_max = *t.radius_samples.last().unwrap();
        let n = 20_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let r0 = r_max * (i as Float) / n as Float;
            let r1 = r_max * (i as Float + 1.0) / n as Float;
            let r = 0.5 * (r0 + r1);
            sum += (2.0 * PI * r * b.sr(r)[0] * (r1 - r0)) as f64;
        }
        let (i, _) = t
            .rho_samples
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - rho).abs().partial_cmp(&(b.1 - rho).abs()).unwrap())
            .unwrap();
        let want = crate::bssrdf::catmull_rom(&t.rho_samples, &t.rho_eff, rho);
        assert!(
            (sum as Float - want).abs() < 0.02 * want,
            "rho {rho}: integral {sum} vs rho_eff {want} (node {i})"
        );
    }
}

/// Checks a histogram of `b.sample_sr` radii (up to `sample_sr(0.999)`)
/// against 2π r `pdf_sr(r)` integrated over each bin; returns that radius.
fn check_sample_sr_histogram(b: &impl SeparableBssrdf, seed: u64) -> Float {
    // Histogram of sampled radii against 2π r pdf_sr(r) integrated per bin.
    let r_max = b.sample_sr(0.999).unwrap();
    const BINS: usize = 16;
    let mut hist = [0usize; BINS];
    let mut rng = Rng::new(seed, 0);
    let n = 200_000;
    for _ in 0..n {
        let r = b.sample_sr(rng.uniform_float()).unwrap();
        assert!(r >= 0.0 && r.is_finite());
        if r < r_max {
            hist[((r / r_max * BINS as Float) as usize).min(BINS - 1)] += 1;
        }
    }
    for (k, &h) in hist.iter().enumerate() {
        let mut want = 0.0;
        let m = 400;
        for j in 0..m {
            let r = r_max * (k as Float + (j as Float + 0.5) / m as Float) / BINS as Float;
            want += 2.0 * PI * r * b.pdf_sr(r)[0] * r_max / (BINS * m) as Float;
        }
        let got = h as Float / n as Float;
        assert!((got - want).abs() < 0.006, "bin {k}: {got} vs {want}");
    }
    r_max
}

#[test]
fn sample_sr_matches_pdf_sr_and_profile() {
    let t = table();
    let sigma_a = SampledSpectrum::from_array([0.05, 0.2, 0.5, 1.0]);
    let sigma_s = SampledSpectrum::from_array([2.0, 1.0, 0.5, 3.0]);
    let b = TabulatedBssrdf::new(
        Point3f::new(0.0, 0.0, 0.0),
        Normal3f::new(0.0, 0.0, 1.0),
        Vector3f::new(0.0, 0.0, 1.0),
        1.33,
        sigma_a,
        sigma_s,
        t,
    );
    let st = b.sigma_t()[0];
    let rho = b.rho()[0];
    let rho_eff = crate::bssrdf::catmull_rom(&t.rho_samples, &t.rho_eff, rho);
    // pdf_sr is Sr / ρ_eff per unit area (for every wavelength).
    for &r in &[0.01, 0.1, 0.5, 2.0] {
        let sr = b.sr(r);
        let pdf = b.pdf_sr(r);
        assert!((pdf[0] - sr[0] / rho_eff).abs() < 1e-3 * pdf[0].max(1e-3));
        for i in 0..N_SPECTRUM_SAMPLES {
            assert!(pdf[i].is_finite() && pdf[i] >= 0.0);
        }
    }
    let r_max = check_sample_sr_histogram(&b, 5);
    // Radii scale with the mean free path.
    assert!(r_max > 0.0 && r_max * st < *t.radius_samples.last().unwrap());
}

#[test]
fn probe_segments_and_pdf_sp() {
    let t = table();
    let ns = Normal3f::new(0.0, 0.0, 1.0);
    let po = Point3f::new(1.0, 2.0, 3.0);
    let b = TabulatedBssrdf::new(
        po,
        ns,
        Vector3f::new(0.0, 0.0, 1.0),
        1.33,
        SampledSpectrum::new(0.1),
        SampledSpectrum::new(1.0),
        t,
    );
    check_probes(&b);
}

/// Checks `b`'s probe segments (on the sphere of radius r_max, crossing
/// the tangent plane at the sampled radius), that `pdf_sp` integrates to
/// ½ over the tangent plane, and the sample at a hit. `b`'s shading normal
/// must be +z.
fn check_probes(b: &impl SeparableBssrdf) {
    let (po, ns) = (b.origin().po, b.origin().ns);
    let r_max = b.sample_sr(0.999).unwrap();
    let mut rng = Rng::new(9, 0);
    let mut hits = 0;
    for _ in 0..1000 {
        let u1 = rng.uniform_float();
        let u2 = Point2f::new(rng.uniform_float(), rng.uniform_float());
        let Some(seg) = b.sample_sp(u1, u2) else {
            continue;
        };
        // Both ends lie on the sphere of radius r_max around po.
        assert!((distance(seg.p0, po) - r_max).abs() < 1e-3 * r_max);
        assert!((distance(seg.p1, po) - r_max).abs() < 1e-3 * r_max);
        // With the z axis chosen, the probe crosses the tangent plane at the
        // sampled radius.
        if u1 >= 0.5 {
            let d = seg.p1 - seg.p0;
            assert!(d.x.abs() < 1e-4 && d.y.abs() < 1e-4);
            let tt = (po.z - seg.p0.z) / d.z;
            let hit = seg.p0 + d * tt;
            let pdf = b.pdf_sp(hit, ns);
            // Only the normal axis sees a flat surface hit.
            let r = distance(hit, po);
            assert!((pdf[0] - 0.5 * b.pdf_sr(r)[0]).abs() < 1e-3 * pdf[0].max(1e-3));
            hits += 1;
        }
    }
    assert!(hits > 300);
    // On a plane the probe density integrates to ½ (the z strategy's share)
    // times the fraction of the profile inside r_max (≈ 0.999).
    let n = 400;
    let mut sum = 0.0;
    let extent = r_max;
    for i in 0..n {
        for j in 0..n {
            let x = extent * (2.0 * (i as Float + 0.5) / n as Float - 1.0);
            let y = extent * (2.0 * (j as Float + 0.5) / n as Float - 1.0);
            if x * x + y * y < r_max * r_max {
                let p = po + Vector3f::new(x, y, 0.0);
                sum += b.pdf_sp(p, ns)[0] * sqr(2.0 * extent / n as Float);
            }
        }
    }
    assert!((sum - 0.5 * 0.999).abs() < 0.02, "{sum}");

    // The sample at a hit carries Sp, the pdf and a normalized Fresnel BSDF.
    let si = SubsurfaceInteraction {
        pi: rpbrt_geometry::Point3fi::from(po + Vector3f::new(0.1, 0.0, 0.0)),
        n: ns,
        ns,
        dpdu: Vector3f::new(1.0, 0.0, 0.0),
        dpdv: Vector3f::new(0.0, 1.0, 0.0),
        dpdus: Vector3f::new(1.0, 0.0, 0.0),
        dpdvs: Vector3f::new(0.0, 1.0, 0.0),
    };
    let s = b.probe_intersection_to_sample(&si);
    let sr = b.sr(0.1);
    assert!((s.sp[0] - sr[0]).abs() < 1e-5 * sr[0]);
    assert_eq!(s.pdf, b.pdf_sp(si.p(), ns));
    assert_eq!(s.sp, b.sp(si.p()));
    assert_eq!(s.wo, Vector3f::new(0.0, 0.0, 1.0));
    assert!(matches!(s.sw.bxdf, crate::bxdf::BxDF::NormalizedFresnel(_)));
}

#[test]
fn subsurface_from_diffuse_round_trips() {
    let t = table();
    let want = SampledSpectrum::from_array([0.05, 0.3, 0.6, 0.85]);
    let mfp = SampledSpectrum::from_array([0.5, 1.0, 2.0, 4.0]);
    let (sa, ss) = subsurface_from_diffuse(t, want, mfp);
    for c in 0..N_SPECTRUM_SAMPLES {
        // σt = 1 / mfp.
        assert!(((sa[c] + ss[c]) * mfp[c] - 1.0).abs() < 1e-5);
        let rho = ss[c] / (sa[c] + ss[c]);
        let got = crate::bssrdf::catmull_rom(&t.rho_samples, &t.rho_eff, rho);
        assert!((got - want[c]).abs() < 1e-3, "{c}: {got} vs {}", want[c]);
    }
}

#[test]
fn beam_diffusion_terms_are_physical() {
    // Both terms are positive and fall off with radius; more albedo, more
    // light.
    for &rho in &[0.2, 0.9] {
        let mut prev = (Float::INFINITY, Float::INFINITY);
        for &r in &[0.01, 0.1, 1.0, 5.0] {
            let ss = beam_diffusion_ss(rho, 1.0 - rho, 0.0, 1.33, r);
            let ms = beam_diffusion_ms(rho, 1.0 - rho, 0.0, 1.33, r);
            assert!(ss > 0.0 && ms > 0.0, "rho {rho} r {r}: {ss} {ms}");
            assert!(ss < prev.0 && ms < prev.1);
            prev = (ss, ms);
        }
    }
    assert!(
        beam_diffusion_ms(0.9, 0.1, 0.0, 1.33, 0.5) > beam_diffusion_ms(0.2, 0.8, 0.0, 1.33, 0.5)
    );
}

fn disney_bssrdf(r: SampledSpectrum, d: SampledSpectrum) -> DisneyBssrdf {
    DisneyBssrdf::new(
        Point3f::new(1.0, 2.0, 3.0),
        Normal3f::new(0.0, 0.0, 1.0),
        1.4,
        r,
        d,
    )
}

#[test]
fn disney_profile_integrates_to_the_albedo() {
    let r = SampledSpectrum::from_array([0.9, 0.5, 0.2, 1.0]);
    let d = SampledSpectrum::from_array([0.05, 0.5, 2.0, 1e-3]);
    let b = disney_bssrdf(r, d);
    for i in 0..N_SPECTRUM_SAMPLES {
        // ∫ 2π r Sr(r) dr over [0, 60 d] by the midpoint rule.
        let n = 50_000;
        let h = 60.0 * d[i] / n as Float;
        let mut sum = 0.0f64;
        let mut pdf_sum = 0.0f64;
        for k in 0..n {
            let x = (k as Float + 0.5) * h;
            sum += (2.0 * PI * x * b.sr(x)[i] * h) as f64;
            pdf_sum += (2.0 * PI * x * b.pdf_sr(x)[i] * h) as f64;
        }
        assert!(
            (sum as Float - r[i]).abs() < 1e-3 * r[i],
            "{i}: {sum} vs {}",
            r[i]
        );
        assert!(
            (pdf_sum - 1.0).abs() < 1e-3,
            "{i}: pdf integrates to {pdf_sum}"
        );
        // The density is the profile over the albedo, so Sr / pdf = R.
        for x in [1e-7, 0.01, 0.3, 4.0] {
            let (sr, pdf) = (b.sr(x)[i], b.pdf_sr(x)[i]);
            assert!(
                (sr - r[i] * pdf).abs() <= 1e-5 * sr + 1e-30,
                "{i} {x}: {sr} vs {pdf}"
            );
        }
    }
    // A wavelength without a scatter distance scatters nothing.
    let z = disney_bssrdf(r, SampledSpectrum::from_array([0.1, 0.0, 0.1, 0.1]));
    assert_eq!(z.sr(0.05)[1], 0.0);
    assert_eq!(z.pdf_sr(0.05)[1], 0.0);
    let none = disney_bssrdf(r, SampledSpectrum::from_array([0.0, 0.1, 0.1, 0.1]));
    assert!(none.sample_sr(0.5).is_none());
    assert!(none.sample_sp(0.7, Point2f::new(0.5, 0.5)).is_none());
}

#[test]
fn disney_sampling_follows_the_closed_form_cdf() {
    let d: Float = 0.2;
    let b = disney_bssrdf(SampledSpectrum::new(0.8), SampledSpectrum::new(d));
    // P(r < x) = 1 − e^(−x/d)/4 − ¾ e^(−x/3d), with stratified uniforms.
    let n = 100_000;
    let radii: Vec<Float> = (0..n)
        .map(|k| b.sample_sr((k as Float + 0.5) / n as Float).unwrap())
        .collect();
    for x in [0.01, 0.1, 0.3, 1.0, 3.0] {
        let got = radii.iter().filter(|&&r| r < x).count() as Float / n as Float;
        let want = 1.0 - (-x / d).exp() / 4.0 - 0.75 * (-x / (3.0 * d)).exp();
        assert!((got - want).abs() < 2e-3, "{x}: {got} vs {want}");
    }
    assert!(radii.iter().all(|r| r.is_finite() && *r >= 0.0));
    // u = 0.999 lands in the wide exponential: r_max = −3d ln(1 − 0.998667).
    let r_max = b.sample_sr(0.999).unwrap();
    assert!((r_max - 3.0 * d * (1.0 as Float / (1.0 - (0.999 - 0.25) / 0.75)).ln()).abs() < 1e-3);
    check_sample_sr_histogram(&b, 11);
}

#[test]
fn disney_probe_segments_and_pdf_sp() {
    let b = disney_bssrdf(
        SampledSpectrum::new(0.7),
        SampledSpectrum::from_array([0.3, 0.1, 0.6, 0.3]),
    );
    check_probes(&b);
    // Through the enum the same.
    let e = Bssrdf::Disney(b);
    let p = Point3f::new(1.2, 2.1, 3.0);
    assert_eq!(e.sp(p), b.sp(p));
    let ns = b.origin().ns;
    assert_eq!(e.pdf_sp(p, ns), b.pdf_sp(p, ns));
}
