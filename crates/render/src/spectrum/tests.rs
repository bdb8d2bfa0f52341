//! Tests for the spectral machinery.

use std::path::Path;
use std::sync::Arc;

use rpbrt_geometry::Float;
use rpbrt_parser::SpectrumValue;

use super::*;
use crate::rng::Rng;

fn close(a: Float, b: Float, tol: Float) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// The XYZ of `s` reflecting the colour space's illuminant, normalised so
/// the illuminant's Y is 1 (what the RGB to spectrum fit targets).
fn reflected_rgb(cs: &RgbColorSpace, s: &Spectrum) -> RGB {
    let illum = cs.illuminant_spectrum();
    let mut xyz = [0.0f64; 3];
    let mut y_illum = 0.0f64;
    for l in 360..=830 {
        let lf = l as Float;
        let m = cie::xyz_matching(lf);
        let e = illum.evaluate(lf) as f64;
        let v = s.evaluate(lf) as f64;
        for c in 0..3 {
            xyz[c] += m[c] as f64 * e * v;
        }
        y_illum += m[1] as f64 * e;
    }
    let xyz = XYZ::new(
        (xyz[0] / y_illum) as Float,
        (xyz[1] / y_illum) as Float,
        (xyz[2] / y_illum) as Float,
    );
    cs.to_rgb(xyz)
}

#[test]
fn sampled_spectrum_arithmetic() {
    let a = SampledSpectrum::from_array([1.0, 2.0, 3.0, 4.0]);
    let b = SampledSpectrum::new(2.0);
    assert_eq!((a + b).values, [3.0, 4.0, 5.0, 6.0]);
    assert_eq!((a - b).values, [-1.0, 0.0, 1.0, 2.0]);
    assert_eq!((a * b).values, [2.0, 4.0, 6.0, 8.0]);
    assert_eq!((a / 2.0).values, [0.5, 1.0, 1.5, 2.0]);
    let mut c = a;
    c *= 2.0;
    c += b;
    assert_eq!(c.values, [4.0, 6.0, 8.0, 10.0]);
    assert_eq!(a.max_component_value(), 4.0);
    assert_eq!(a.min_component_value(), 1.0);
    assert_eq!(a.average(), 2.5);
    let z = SampledSpectrum::from_array([1.0, 0.0, 2.0, 0.0]);
    assert_eq!(SampledSpectrum::safe_div(a, z).values, [1.0, 0.0, 1.5, 0.0]);
    assert!(SampledSpectrum::new(0.0).is_black());
    assert!(!a.is_black());
    assert!(SampledSpectrum::from_array([0.0, Float::NAN, 0.0, 0.0]).has_nan());
    assert_eq!(
        SampledSpectrum::from_array([-1.0, 1.0, -2.0, 4.0])
            .clamp_zero()
            .values,
        [0.0, 1.0, 0.0, 4.0]
    );
    assert_eq!(
        SampledSpectrum::lerp(0.5, a, b).values,
        [1.5, 2.0, 2.5, 3.0]
    );
    assert_eq!(a[3], 4.0);
}

#[test]
fn uniform_wavelengths_are_stratified() {
    let l = SampledWavelengths::sample_uniform(0.9, 360.0, 830.0);
    let delta = 470.0 / 4.0;
    assert!(close(l[0], 360.0 + 0.9 * 470.0, 1e-6));
    for i in 1..4 {
        let mut expect = l[i - 1] + delta;
        if expect > 830.0 {
            expect -= 470.0;
        }
        assert!(close(l[i], expect, 1e-5));
        assert!((360.0..=830.0).contains(&l[i]));
    }
    assert!(l.pdf().values.iter().all(|&p| close(p, 1.0 / 470.0, 1e-6)));
}

#[test]
fn terminate_secondary_keeps_estimate_unbiased() {
    let mut l = SampledWavelengths::sample_visible(0.3);
    let p0 = l.pdf[0];
    assert!(!l.secondary_terminated());
    l.terminate_secondary();
    assert!(l.secondary_terminated());
    assert!(close(l.pdf[0], p0 / 4.0, 1e-6));
    l.terminate_secondary();
    assert!(close(l.pdf[0], p0 / 4.0, 1e-6));
}

#[test]
fn visible_pdf_integrates_to_one_and_matches_sampling() {
    let mut sum = 0.0f64;
    let n = 47000;
    for i in 0..n {
        let l = 360.0 + (i as f64 + 0.5) * 470.0 / n as f64;
        sum += visible_wavelengths_pdf(l as Float) as f64 * 470.0 / n as f64;
    }
    assert!((sum - 1.0).abs() < 1e-3, "integral {sum}");
    // The inverse CDF is monotone and stays in range.
    let mut prev = 0.0;
    for i in 0..=1000 {
        let l = sample_visible_wavelengths(i as Float / 1000.0);
        assert!((359.9..=830.1).contains(&l), "{l}");
        assert!(l >= prev);
        prev = l;
    }
    // The density is the derivative of the sampling map.
    for u in [0.1, 0.4, 0.7, 0.95] {
        let h = 1e-3;
        let dl =
            (sample_visible_wavelengths(u + h) - sample_visible_wavelengths(u - h)) / (2.0 * h);
        let l = sample_visible_wavelengths(u);
        assert!(close(1.0 / dl, visible_wavelengths_pdf(l), 2e-2));
    }
    // `sample_visible` computes the densities from the sample (no cosh):
    // they agree with the density of the wavelengths it returns.
    for i in 0..1000 {
        let lw = SampledWavelengths::sample_visible(i as Float / 1000.0);
        for j in 0..N_SPECTRUM_SAMPLES {
            let (l, p) = (lw.get(j), lw.pdf()[j]);
            let q = visible_wavelengths_pdf(l);
            assert!((p - q).abs() <= 1e-5 * q, "{l}: {p} vs {q}");
        }
    }
}

/// The camera batch's wavelengths are `sample_visible`'s, bit for bit, at
/// every SIMD level and for a batch that does not fill the last vector.
#[test]
fn batched_visible_wavelengths_match_single_ones() {
    let mut rng = Rng::with_sequence(5);
    let mut us: Vec<Float> = (0..203).map(|_| rng.uniform_float()).collect();
    us.extend([0.0, 0.5, 0.75, 1.0 - Float::EPSILON / 2.0]);
    let expect: Vec<SampledWavelengths> = us
        .iter()
        .map(|&u| SampledWavelengths::sample_visible(u))
        .collect();
    let (mut scratch, mut got) = (Vec::new(), Vec::new());
    for level in crate::simd::SimdLevel::available() {
        SampledWavelengths::sample_visible_many(level, &us, &mut scratch, &mut got);
        assert_eq!(got.len(), us.len());
        for (g, e) in got.iter().zip(&expect) {
            for j in 0..N_SPECTRUM_SAMPLES {
                assert_eq!(g.get(j).to_bits(), e.get(j).to_bits(), "{level:?}");
                assert_eq!(g.pdf()[j].to_bits(), e.pdf()[j].to_bits(), "{level:?}");
            }
        }
    }
}

#[test]
fn luminance_estimate_of_constant_is_one() {
    let mut rng = Rng::with_sequence(7);
    let s = SampledSpectrum::new(1.0);
    let (mut vis, mut uni) = (0.0f64, 0.0f64);
    let n = 200_000;
    for _ in 0..n {
        let u = rng.uniform_float();
        vis += s.y(&SampledWavelengths::sample_visible(u)) as f64;
        uni += s.y(&SampledWavelengths::sample_uniform(
            u, LAMBDA_MIN, LAMBDA_MAX,
        )) as f64;
    }
    assert!(
        (vis / n as f64 - 1.0).abs() < 3e-3,
        "visible {}",
        vis / n as f64
    );
    assert!(
        (uni / n as f64 - 1.0).abs() < 3e-3,
        "uniform {}",
        uni / n as f64
    );
    // to_xyz agrees with y.
    let l = SampledWavelengths::sample_visible(0.37);
    assert!(close(s.to_xyz(&l).y, s.y(&l), 1e-5));
}

#[test]
fn cie_y_integral_matches_table() {
    let sum: f64 = cie::CIE_Y.iter().map(|&v| v as f64).sum();
    assert!((sum as Float - CIE_Y_INTEGRAL).abs() < 1e-3);
    let xyz = spectrum_to_xyz(&Spectrum::Constant(1.0));
    assert!(close(xyz.y, 1.0, 1e-5));
}

#[test]
fn blackbody_peak_and_wien() {
    for t in [1500.0, 2700.0, 5000.0, 6500.0] {
        let s = BlackbodySpectrum::new(t);
        let peak = 2.897_772_1e-3 / t * 1e9;
        assert!(close(s.evaluate(peak), 1.0, 1e-4));
        // The maximum over a fine grid sits at Wien's wavelength.
        let mut best = (0.0, 0.0);
        let mut l = 200.0;
        while l < 3000.0 {
            let v = s.evaluate(l);
            if v > best.1 {
                best = (l, v);
            }
            l += 0.25;
        }
        assert!((best.0 - peak).abs() < 0.5, "t {t}: {best:?} vs {peak}");
        assert!(best.1 <= 1.0 + 1e-4);
    }
    assert_eq!(blackbody(500.0, 0.0), 0.0);
    // Planck at 500 nm, 5000 K: 2hc²/λ⁵ / (exp(hc/λkT) - 1).
    assert!(close(blackbody(500.0, 5000.0), 1.2107e13, 1e-3));
}

#[test]
fn densely_sampled_matches_piecewise_linear() {
    let pl =
        PiecewiseLinearSpectrum::from_interleaved(&[400.0, 1.0, 500.0, 3.0, 700.0, 2.0], false)
            .unwrap();
    let s = Spectrum::PiecewiseLinear(Arc::new(pl));
    let d = Spectrum::DenselySampled(Arc::new(DenselySampledSpectrum::new(&s)));
    for l in 360..=830 {
        assert!(close(d.evaluate(l as Float), s.evaluate(l as Float), 1e-6));
    }
    // Extended with the end values to cover the visible range.
    assert_eq!(s.evaluate(360.0), 1.0);
    assert_eq!(s.evaluate(830.0), 2.0);
    assert!(close(s.evaluate(450.0), 2.0, 1e-6));
    assert_eq!(s.max_value(), 3.0);
    assert_eq!(d.evaluate(900.0), 0.0);
    let l = SampledWavelengths::sample_uniform(0.2, 400.0, 700.0);
    let a = s.sample(&l);
    let b = d.sample(&l);
    for i in 0..4 {
        assert!((a[i] - b[i]).abs() < 0.02);
    }
}

/// The interpolation by bisection that the lookup table replaces.
fn piecewise_by_bisection(s: &PiecewiseLinearSpectrum, lambda: Float) -> Float {
    let (ls, vs) = (s.lambdas(), s.values());
    if !(lambda >= ls[0] && lambda <= ls[ls.len() - 1]) {
        return 0.0;
    }
    if ls.len() == 1 {
        return vs[0];
    }
    let i = ls
        .partition_point(|&l| l <= lambda)
        .saturating_sub(1)
        .min(ls.len() - 2);
    let t = (lambda - ls[i]) / (ls[i + 1] - ls[i]);
    (1.0 - t) * vs[i] + t * vs[i + 1]
}

/// `evaluate` through the whole-nanometre lookup table gives what bisection
/// gives, bit for bit: at random wavelengths, at every sample wavelength
/// and its neighbouring floats, at whole nanometres and their neighbours,
/// for samples closer than a nanometre, wider apart, off the whole
/// numbers, one sample only, a span too wide for the table, and a named
/// metal.
#[test]
fn piecewise_linear_lookup_matches_bisection() {
    let mut rng = Rng::with_sequence(11);
    let mut spectra = Vec::new();
    let dense: Vec<Float> = (0..1500).map(|i| 380.0 + 0.3 * i as Float).collect();
    let dense_v: Vec<Float> = (0..1500).map(|i| ((i * 7919) % 101) as Float).collect();
    spectra.push(PiecewiseLinearSpectrum::new(dense, dense_v).unwrap());
    spectra.push(
        PiecewiseLinearSpectrum::new(
            vec![360.5, 400.25, 555.0, 830.75],
            vec![1.0, 4.0, -2.0, 8.0],
        )
        .unwrap(),
    );
    spectra.push(PiecewiseLinearSpectrum::new(vec![500.0], vec![3.0]).unwrap());
    spectra.push(
        PiecewiseLinearSpectrum::new(vec![-10.0, 2.0, 9000.0, 1e6], vec![1.0, 2.0, 3.0, 4.0])
            .unwrap(),
    );
    spectra.push(
        PiecewiseLinearSpectrum::new(vec![1e9, 1e9 + 256.0, 1e9 + 2048.0], vec![1.0, 2.0, 3.0])
            .unwrap(),
    );
    match named_spectrum("metal-Au-eta") {
        Some(Spectrum::PiecewiseLinear(p)) => spectra.push((*p).clone()),
        other => panic!("metal-Au-eta: {other:?}"),
    }
    for s in &spectra {
        let ls = s.lambdas();
        let (lo, hi) = (ls[0], ls[ls.len() - 1]);
        let mut probes: Vec<Float> = Vec::new();
        for &l in ls {
            probes.extend([l, l.next_down(), l.next_up()]);
        }
        let mut w = lo.floor() - 2.0;
        while w <= hi.floor() + 2.0 && probes.len() < 200_000 {
            probes.extend([w, w.next_down(), w.next_up()]);
            w += 1.0;
        }
        for _ in 0..20_000 {
            let u = rng.uniform_float();
            probes.push(lo - 1.0 + u * (hi - lo + 2.0));
        }
        probes.extend([Float::NAN, Float::INFINITY, Float::NEG_INFINITY]);
        for &l in &probes {
            let (got, want) = (s.evaluate(l), piecewise_by_bisection(s, l));
            assert_eq!(
                got.to_bits(),
                want.to_bits(),
                "{l} in {lo}..{hi}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn piecewise_linear_rejects_bad_input() {
    assert!(PiecewiseLinearSpectrum::new(vec![400.0, 400.0], vec![1.0, 2.0]).is_err());
    assert!(PiecewiseLinearSpectrum::new(vec![400.0], vec![1.0, 2.0]).is_err());
    assert!(PiecewiseLinearSpectrum::from_interleaved(&[400.0, 1.0, 500.0], false).is_err());
}

#[test]
fn named_illuminants_are_normalised() {
    for name in named_spectrum_names().filter(|n| n.contains("illum")) {
        let s = named_spectrum(name).unwrap_or_else(|| panic!("{name} missing"));
        let y = inner_product(cie::y(), &s);
        assert!(close(y, CIE_Y_INTEGRAL, 1e-4), "{name}: {y}");
        assert!(close(spectrum_to_xyz(&s).y, 1.0, 1e-4));
    }
    assert!(named_spectrum("no-such-spectrum").is_none());
}

#[test]
fn srgb_white_is_d65() {
    let cs = RgbColorSpace::srgb();
    let xyz = cs.to_xyz(RGB::new(1.0, 1.0, 1.0));
    let xy = xyz.xy();
    assert!(
        (xy[0] - 0.3127).abs() < 1e-3 && (xy[1] - 0.3290).abs() < 1e-3,
        "{xy:?}"
    );
    assert!(close(xyz.y, 1.0, 1e-4));
    let d65 = spectrum_to_xyz(&named_spectrum("stdillum-D65").unwrap()).xy();
    assert!((d65[0] - 0.3127).abs() < 1e-3 && (d65[1] - 0.3290).abs() < 1e-3);
}

#[test]
fn colour_space_matrices_invert() {
    for name in ["srgb", "rec2020", "aces2065-1", "dci-p3"] {
        let cs = RgbColorSpace::get(name).unwrap();
        let id = cs.rgb_from_xyz.mul(&cs.xyz_from_rgb);
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((id.m[i][j] - e).abs() < 1e-5, "{name}");
            }
        }
        // Primaries map to their chromaticities.
        let r = cs.to_xyz(RGB::new(1.0, 0.0, 0.0)).xy();
        assert!(
            (r[0] - cs.r[0]).abs() < 1e-4 && (r[1] - cs.r[1]).abs() < 1e-4,
            "{name}"
        );
        let m = convert_rgb_color_space(RgbColorSpace::srgb(), cs);
        let back = convert_rgb_color_space(cs, RgbColorSpace::srgb()).mul(&m);
        for i in 0..3 {
            assert!((back.m[i][i] - 1.0).abs() < 1e-4);
        }
    }
    assert!(RgbColorSpace::get("nope").is_none());
    let aces = RgbColorSpace::get("aces2065-1").unwrap();
    assert!(
        (aces.w[0] - 0.32168).abs() < 2e-3 && (aces.w[1] - 0.33767).abs() < 2e-3,
        "{:?}",
        aces.w
    );
}

#[test]
fn table_reproduces_white_black_and_primaries() {
    let cs = RgbColorSpace::srgb();
    let white = cs.rgb_to_spectrum_coeffs(RGB::new(1.0, 1.0, 1.0));
    let black = cs.rgb_to_spectrum_coeffs(RGB::new(0.0, 0.0, 0.0));
    for l in [360.0, 500.0, 830.0] {
        assert_eq!(white.evaluate(l), 1.0);
        assert_eq!(black.evaluate(l), 0.0);
    }
    let grey = cs.rgb_to_spectrum_coeffs(RGB::new(0.3, 0.3, 0.3));
    assert!(close(grey.evaluate(600.0), 0.3, 1e-5));
    for c in [
        RGB::new(1.0, 0.0, 0.0),
        RGB::new(0.0, 1.0, 0.0),
        RGB::new(0.0, 0.0, 1.0),
    ] {
        let s = Spectrum::RgbAlbedo(RgbAlbedoSpectrum::new(cs, c));
        let rgb = reflected_rgb(cs, &s);
        // Pure primaries lie on the edge of what reflectances can reach;
        // the fit gets within a few percent.
        for i in 0..3 {
            assert!((rgb[i] - c[i]).abs() < 0.06, "{c:?} -> {rgb:?}");
        }
    }
}

#[test]
fn rgb_albedo_round_trips() {
    let mut rng = Rng::with_sequence(3);
    for name in ["srgb", "rec2020", "dci-p3", "aces2065-1"] {
        let cs = RgbColorSpace::get(name).unwrap();
        let mut worst: Float = 0.0;
        for _ in 0..300 {
            // Stay a little inside the gamut: the extreme corners are not
            // reachable by reflectances.
            let c = RGB::new(
                0.05 + 0.9 * rng.uniform_float(),
                0.05 + 0.9 * rng.uniform_float(),
                0.05 + 0.9 * rng.uniform_float(),
            );
            // Wide gamuts hold saturated colours no reflectance reaches:
            // pull them halfway to grey there.
            let c = if name == "srgb" {
                c
            } else {
                (c + RGB::new(1.0, 1.0, 1.0) * c.average()) * 0.5
            };
            let s = Spectrum::RgbAlbedo(RgbAlbedoSpectrum::new(cs, c));
            let rgb = reflected_rgb(cs, &s);
            for i in 0..3 {
                worst = worst.max((rgb[i] - c[i]).abs());
            }
            assert!(s.max_value() <= 1.0);
        }
        let limit = if name == "srgb" { 1e-3 } else { 5e-3 };
        eprintln!("{name}: worst {worst}");
        assert!(worst < limit, "{name}: worst round-trip error {worst}");
    }
}

#[test]
fn unbounded_and_illuminant_rgb() {
    let cs = RgbColorSpace::srgb();
    let c = RGB::new(2.0, 0.5, 1.0);
    let s = Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, c));
    let rgb = reflected_rgb(cs, &s);
    for i in 0..3 {
        assert!((rgb[i] - c[i]).abs() < 4e-3, "{rgb:?}");
    }
    // RGB (1,1,1) emission is the illuminant itself.
    let e = Spectrum::RgbIlluminant(RgbIlluminantSpectrum::new(cs, RGB::new(1.0, 1.0, 1.0)));
    let d65 = cs.illuminant_spectrum();
    for l in [400.0, 550.0, 700.0] {
        assert!(close(e.evaluate(l), d65.evaluate(l), 1e-5));
    }
    let lam = SampledWavelengths::sample_visible(0.5);
    let a = e.sample(&lam);
    for i in 0..4 {
        assert!(close(a[i], e.evaluate(lam[i]), 1e-5));
    }
    assert!(close(
        spectrum_to_photometric(&e),
        inner_product(cie::y(), &d65),
        1e-6
    ));
    assert!(e.max_value() >= d65.max_value() * 0.99);
}

#[test]
fn spd_parsing() {
    let s = parse_spectrum_text("# comment\n400 1.0\n500 2.0 # trailing\n600 0.5\n").unwrap();
    assert!(close(s.evaluate(450.0), 1.5, 1e-6));
    assert_eq!(s.evaluate(300.0), 0.0);
    assert!(parse_spectrum_text("400 1 500")
        .unwrap_err()
        .contains("odd"));
    assert!(parse_spectrum_text("500 1 400 2")
        .unwrap_err()
        .contains("increasing"));
    assert!(parse_spectrum_text("400 x")
        .unwrap_err()
        .contains("not a number"));
    assert!(parse_spectrum_text("# nothing\n").is_err());
    assert!(read_spectrum_file(Path::new("/nonexistent/file.spd")).is_err());
}

#[test]
fn spectrum_parameters() {
    let cs = RgbColorSpace::srgb();
    let dir = Path::new("/");
    let albedo = spectrum_from_param(
        &SpectrumValue::Rgb([0.5, 0.2, 0.1]),
        SpectrumType::Albedo,
        cs,
        dir,
    );
    assert!(matches!(albedo, Ok(Spectrum::RgbAlbedo(_))));
    let too_big = spectrum_from_param(
        &SpectrumValue::Rgb([1.5, 0.2, 0.1]),
        SpectrumType::Albedo,
        cs,
        dir,
    );
    assert!(too_big.unwrap_err().contains("> 1"));
    assert!(matches!(
        spectrum_from_param(
            &SpectrumValue::Rgb([1.5, 0.2, 0.1]),
            SpectrumType::Unbounded,
            cs,
            dir
        ),
        Ok(Spectrum::RgbUnbounded(_))
    ));
    assert!(matches!(
        spectrum_from_param(
            &SpectrumValue::Rgb([1.5, 0.2, 0.1]),
            SpectrumType::Illuminant,
            cs,
            dir
        ),
        Ok(Spectrum::RgbIlluminant(_))
    ));
    let bb = spectrum_from_param(
        &SpectrumValue::Blackbody(3000.0),
        SpectrumType::Illuminant,
        cs,
        dir,
    )
    .unwrap();
    assert!(close(bb.max_value(), 1.0, 1e-6));
    let sampled = spectrum_from_param(
        &SpectrumValue::Sampled(vec![(400.0, 1.0), (600.0, 3.0)]),
        SpectrumType::Unbounded,
        cs,
        dir,
    )
    .unwrap();
    assert!(close(sampled.evaluate(500.0), 2.0, 1e-6));
    assert!(spectrum_from_param(
        &SpectrumValue::Sampled(vec![(600.0, 1.0), (400.0, 3.0)]),
        SpectrumType::Unbounded,
        cs,
        dir
    )
    .is_err());
    let named = spectrum_from_param(
        &SpectrumValue::NameOrFile("stdillum-D65".into()),
        SpectrumType::Illuminant,
        cs,
        dir,
    );
    assert!(named.is_ok());
    let missing = spectrum_from_param(
        &SpectrumValue::NameOrFile("missing.spd".into()),
        SpectrumType::Unbounded,
        cs,
        Path::new("/nonexistent"),
    );
    assert!(missing.unwrap_err().contains("does not exist"));
    // A file next to the scene.
    let dir = std::env::temp_dir().join(format!("rpbrt-spd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("s.spd"), "400 0.25\n700 0.75\n").unwrap();
    let f = spectrum_from_param(
        &SpectrumValue::NameOrFile("s.spd".into()),
        SpectrumType::Unbounded,
        cs,
        &dir,
    )
    .unwrap();
    assert!(close(f.evaluate(550.0), 0.5, 1e-6));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn named_metals_and_glasses() {
    let au_k = named_spectrum("metal-Au-k").unwrap();
    assert!(
        (au_k.evaluate(600.0) - 3.0).abs() < 0.1,
        "{}",
        au_k.evaluate(600.0)
    );
    let cu_eta = named_spectrum("metal-Cu-eta").unwrap();
    assert!(cu_eta.evaluate(700.0) < 0.3 && cu_eta.evaluate(400.0) > 1.1);
    let bk7 = named_spectrum("glass-BK7").unwrap();
    assert!((bk7.evaluate(587.6) - 1.5168).abs() < 1e-3);
    // MgO data stop at 768 nm and are extended with the last value.
    assert!(close(
        named_spectrum("metal-MgO-eta").unwrap().evaluate(800.0),
        1.72872,
        1e-5
    ));
    for name in named_spectrum_names() {
        let s = named_spectrum(name).unwrap_or_else(|| panic!("{name} missing"));
        for l in [360.0, 550.0, 830.0] {
            let v = s.evaluate(l);
            assert!(v.is_finite() && v >= 0.0, "{name} at {l}: {v}");
        }
    }
    for name in [
        "glass-F5",
        "glass-F10",
        "glass-F11",
        "metal-Ag-k",
        "metal-Al-eta",
        "metal-TiO2-k",
    ] {
        assert!(named_spectrum(name).is_some(), "{name}");
    }
}

#[test]
fn named_brass_spectra() {
    let eta = named_spectrum("metal-CuZn-eta").expect("metal-CuZn-eta");
    let k = named_spectrum("metal-CuZn-k").expect("metal-CuZn-k");
    // pbrt-v4's table entries come back exactly at their wavelengths.
    for (l, e, kk) in [
        (290.0, 1.358, 1.688),
        (450.0, 1.094, 1.829),
        (600.0, 0.450, 3.253),
        (700.0, 0.446, 4.106),
        (890.0, 0.515, 5.575),
    ] {
        assert_eq!(eta.evaluate(l), e, "η at {l}");
        assert_eq!(k.evaluate(l), kk, "k at {l}");
    }
    // Linear between entries.
    assert!(close(eta.evaluate(595.0), 0.455, 1e-6));
    assert!(close(k.evaluate(455.0), 0.5 * (1.829 + 1.883), 1e-6));
    // Finite and positive across the visible range; k grows with
    // wavelength beyond 440 nm, as for copper alloys.
    let mut last_k = 0.0;
    for l in 360..=830 {
        let (e, kv) = (eta.evaluate(l as Float), k.evaluate(l as Float));
        assert!(
            e.is_finite() && e > 0.0 && kv.is_finite() && kv > 0.0,
            "{l}"
        );
        if l >= 440 {
            assert!(kv >= last_k, "k not increasing at {l}");
        }
        last_k = kv;
    }
    // Brass-like normal-incidence reflectance: yellow, brighter in the red
    // than in the blue.
    let r = |l: Float| {
        let (n, kv) = (eta.evaluate(l), k.evaluate(l));
        ((n - 1.0).powi(2) + kv * kv) / ((n + 1.0).powi(2) + kv * kv)
    };
    assert!(
        r(650.0) > 0.85 && r(450.0) < 0.6,
        "{} {}",
        r(650.0),
        r(450.0)
    );
}

#[test]
fn round_nm_matches_round() {
    let mut rng = Rng::with_sequence(11);
    let edges = [
        0.0,
        0.49999997,
        0.5,
        1.0,
        1.5,
        359.5,
        360.49997,
        829.5,
        8_388_607.5,
        1e9,
        -3.5,
    ];
    for &x in edges.iter() {
        assert_eq!(super::round_nm(x), (x as Float).round() as i64, "{x}");
    }
    for _ in 0..200_000 {
        let x = 1000.0 * rng.uniform_float();
        assert_eq!(super::round_nm(x), x.round() as i64, "{x}");
    }
}

#[test]
fn sigmoid_lanes_match_scalar_evaluation() {
    let mut rng = Rng::with_sequence(5);
    for _ in 0..10_000 {
        let c = [0, 1, 2].map(|_| (rng.uniform_float() - 0.5) * 200.0);
        let p = RgbSigmoidPolynomial::new(c[0] * 1e-4, c[1] * 1e-1, c[2]);
        let l = [0, 1, 2, 3].map(|_| 360.0 + 470.0 * rng.uniform_float());
        let v = p.evaluate_n(&l);
        for i in 0..4 {
            assert_eq!(v[i].to_bits(), p.evaluate(l[i]).to_bits());
        }
    }
    let inf = RgbSigmoidPolynomial::new(0.0, 0.0, Float::INFINITY);
    assert_eq!(inf.evaluate_n(&[500.0]), [1.0]);
    let ninf = RgbSigmoidPolynomial::new(0.0, 0.0, -Float::INFINITY);
    assert_eq!(ninf.evaluate_n(&[500.0]), [0.0]);
}
