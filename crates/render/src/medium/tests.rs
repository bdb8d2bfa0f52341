//! Tests of the media: the phase function, majorants and delta tracking.

use super::*;
use crate::spectrum::Spectrum;
use rpbrt_geometry::float::PI;
use rpbrt_geometry::Bounds3f;

fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_visible(0.37)
}

#[test]
fn hg_is_normalised_and_sampling_matches_its_pdf() {
    for &g in &[-0.9, -0.3, 0.0, 0.0005, 0.5, 0.95] {
        let phase = HGPhaseFunction::new(g);
        let wo = Vector3f::new(0.3, -0.5, 0.8).normalize();
        // ∫ p dω over the sphere by stratified uniform sampling.
        let n = 256;
        let mut integral = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = Point2f::new(
                    (i as Float + 0.5) / n as Float,
                    (j as Float + 0.5) / n as Float,
                );
                let w = crate::sampling::sample_uniform_sphere(u);
                integral += phase.p(wo, w) as f64 * 4.0 * PI as f64;
            }
        }
        integral /= (n * n) as f64;
        assert!((integral - 1.0).abs() < 0.02, "g={g}: ∫p = {integral}");
        // Sampled directions: pdf equals p, and the mean cosine is −g
        // (wo points back along the incoming light).
        let mut rng = Rng::new(7, 0);
        let mut mean_cos = 0.0f64;
        let m = 20000;
        for _ in 0..m {
            let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
            let s = phase.sample_p(wo, u).unwrap();
            assert!((s.wi.length() - 1.0).abs() < 1e-3);
            let p = phase.p(wo, s.wi);
            assert!(
                (s.pdf - p).abs() <= 1e-3 * p.max(1.0),
                "g={g}: pdf {} vs p {p}",
                s.pdf
            );
            assert_eq!(s.p, s.pdf);
            mean_cos += dot(wo, s.wi) as f64;
        }
        mean_cos /= m as f64;
        assert!(
            (mean_cos + g as f64).abs() < 0.02,
            "g={g}: mean cos {mean_cos}"
        );
    }
}

#[test]
fn homogeneous_transmittance_estimators_are_unbiased() {
    // Ratio tracking through a medium whose majorant equals its extinction
    // is exact; with delta tracking the fraction of rays that reach the end
    // estimates exp(−σt d).
    let sa = Spectrum::constant(0.3);
    let ss = Spectrum::constant(0.9);
    let m = Medium::Homogeneous(HomogeneousMedium::new(
        &sa,
        &ss,
        1.0,
        &Spectrum::constant(0.0),
        1.0,
        0.0,
    ));
    let lambda = lambda();
    let ray = Ray::new(Point3f::new(0.0, 0.0, 0.0), Vector3f::new(0.0, 0.0, 2.0));
    // t_max 1 along a direction of length 2: a distance of 2.
    let expected = (-1.2f64 * 2.0).exp();
    let mut rng = Rng::new(3, 0);
    let n = 40000;
    let mut escaped = 0;
    for _ in 0..n {
        let u = rng.uniform_float();
        let mut collided = false;
        let t = sample_t_maj(&m, &ray, 1.0, u, &mut rng, &lambda, |_, _, _, _, _| {
            collided = true;
            false
        });
        if !collided {
            escaped += 1;
            assert!((t[0] as f64 - expected).abs() < 1e-4);
        }
    }
    let frac = escaped as f64 / n as f64;
    assert!(
        (frac - expected).abs() < 0.01,
        "escaped {frac}, expected {expected}"
    );
    let segs = m.majorant_segments(&ray, 1.0, &lambda);
    assert_eq!(segs.len(), 1);
    assert!((segs[0].t_max - 2.0).abs() < 1e-6);
    assert!((segs[0].sigma_maj[0] - 1.2).abs() < 1e-6);
}

#[test]
fn dda_visits_voxels_in_order_and_covers_the_ray() {
    let bounds = Bounds3f::new(Point3f::new(-1.0, -1.0, -1.0), Point3f::new(1.0, 1.0, 1.0));
    let mut grid = MajorantGrid::new(bounds, [4, 4, 4]);
    grid.fill(|b| b.p_min.x + 2.0 * b.p_min.y + 4.0 * b.p_min.z);
    let mut rng = Rng::new(11, 0);
    for _ in 0..500 {
        let o = Point3f::new(
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
            rng.uniform_float() * 4.0 - 2.0,
        );
        let d = crate::sampling::sample_uniform_sphere(Point2f::new(
            rng.uniform_float(),
            rng.uniform_float(),
        ));
        let ray = Ray::new(o, d);
        let Some((t0, t1)) = bounds.intersect_p(o, d, 10.0) else {
            continue;
        };
        let segs: Vec<_> =
            DdaMajorantIterator::new(&ray, t0, t1, &grid, SampledSpectrum::new(1.0)).collect();
        assert!(!segs.is_empty());
        assert!((segs[0].t_min - t0).abs() < 1e-5);
        assert!(
            (segs.last().unwrap().t_max - t1).abs() < 1e-4,
            "{segs:?} t1={t1}"
        );
        for w in segs.windows(2) {
            assert_eq!(w[0].t_max, w[1].t_min);
        }
        for s in &segs {
            assert!(s.t_max >= s.t_min);
            // The voxel holding the segment's midpoint has this majorant.
            let mid = ray.at(0.5 * (s.t_min + s.t_max));
            let off = bounds.offset(mid);
            let v = [0, 1, 2].map(|a| ((off[a] * 4.0) as i32).clamp(0, 3));
            if s.t_max - s.t_min > 1e-4 {
                assert_eq!(s.sigma_maj[0], grid.lookup(v[0], v[1], v[2]));
            }
        }
    }
}

#[test]
fn fast_exp_is_close_to_exp() {
    let mut x = -87.0f32;
    while x < 80.0 {
        let (a, b) = (fast_exp(x), x.exp());
        assert!((a - b).abs() <= 3e-4 * b, "{x}: {a} vs {b}");
        x += 0.0137;
    }
    assert_eq!(fast_exp(-200.0), 0.0);
    assert_eq!(fast_exp(-Float::MAX), 0.0);
    assert_eq!(fast_exp(200.0), Float::INFINITY);
    assert_eq!(fast_exp(0.0), 1.0);
    assert!(fast_exp(Float::NAN).is_nan());
}
