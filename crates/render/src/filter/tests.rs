//! Filter tests: integrals against numerical integration, unbiased
//! importance sampling, analytic samplers inside the radius.

use super::*;
use crate::params::ParamReader;
use crate::rng::Rng;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::Vector2f;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary};

fn create_filter(
    name: &str,
    params: &ParameterDictionary,
    loc: &FileLoc,
) -> Result<Filter, Diagnostic> {
    super::create_filter(name, &ParamReader::plain(params, loc))
}

fn name(f: &Filter) -> &'static str {
    match f {
        Filter::Box(_) => "box",
        Filter::Gaussian(_) => "gaussian",
        Filter::Mitchell(_) => "mitchell",
        Filter::LanczosSinc(_) => "sinc",
        Filter::Triangle(_) => "triangle",
    }
}
use rpbrt_parser::ParsedParameter;

fn all_filters() -> Vec<Filter> {
    let d = ParameterDictionary::new(vec![]);
    let loc = FileLoc::new("test.pbrt".into(), 1, 1);
    ["box", "gaussian", "mitchell", "sinc", "triangle"]
        .iter()
        .map(|n| create_filter(n, &d, &loc).unwrap())
        .chain([
            Filter::Gaussian(GaussianFilter::new(Vector2f::new(2.0, 1.0), 0.7)),
            Filter::Mitchell(MitchellFilter::new(Vector2f::new(1.5, 2.5), 0.0, 0.5)),
            Filter::Triangle(TriangleFilter::new(Vector2f::new(0.75, 1.25))),
            Filter::Box(BoxFilter::new(Vector2f::new(1.0, 0.25))),
        ])
        .collect()
}

/// Midpoint-rule integral of `g` over the filter's support.
fn numeric(f: &Filter, g: impl Fn(Point2f) -> f64) -> f64 {
    let r = f.radius();
    let n = 1000;
    let (dx, dy) = (2.0 * r.x as f64 / n as f64, 2.0 * r.y as f64 / n as f64);
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let p = Point2f::new(
                (-r.x as f64 + (i as f64 + 0.5) * dx) as Float,
                (-r.y as f64 + (j as f64 + 0.5) * dy) as Float,
            );
            sum += g(p);
        }
    }
    sum * dx * dy
}

#[test]
fn integrals_match_numerical_integration() {
    for f in all_filters() {
        let num = numeric(&f, |p| f.evaluate(p) as f64);
        let int = f.integral() as f64;
        let tol = if matches!(f, Filter::LanczosSinc(_)) {
            5e-3
        } else {
            1e-3
        };
        assert!(
            (int - num).abs() < tol * num.abs().max(1.0),
            "{}: {int} vs {num}",
            name(&f)
        );
    }
}

#[test]
fn importance_sampling_is_unbiased() {
    // Weights are f/pdf up to a constant (pbrt-v4 gives the analytic
    // samplers weight 1 and the tabulated ones ∫|f|), so check the ratio
    // estimator: Σ w g / Σ w → ∫ f g / ∫ f.
    let g = |p: Point2f| {
        1.0 + 0.5 * (p.x as f64 * 1.3).cos() + 0.3 * p.y as f64 + 0.2 * (p.x * p.y) as f64
    };
    for f in all_filters() {
        let want =
            numeric(&f, |p| f.evaluate(p) as f64 * g(p)) / numeric(&f, |p| f.evaluate(p) as f64);
        let mut rng = Rng::new(11, 0);
        let n = 200_000;
        let (mut swg, mut sw) = (0.0, 0.0);
        let r = f.radius();
        for _ in 0..n {
            let s = f.sample(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            assert!(
                s.p.x.abs() <= r.x + 1e-5 && s.p.y.abs() <= r.y + 1e-5,
                "{} {s:?}",
                name(&f)
            );
            swg += s.weight as f64 * g(s.p);
            sw += s.weight as f64;
        }
        let est = swg / sw;
        assert!(
            (est - want).abs() < 0.01 * want.abs(),
            "{}: {est} vs {want}",
            name(&f)
        );
        if matches!(
            f,
            Filter::Gaussian(_) | Filter::Mitchell(_) | Filter::LanczosSinc(_)
        ) {
            // Tabulated: |weight| is the table's integral of |f|.
            let s = f.sample(Point2f::new(0.5, 0.5));
            assert!(s.weight > 0.0);
        }
    }
}

#[test]
fn analytic_samplers_stay_inside_and_have_unit_weight() {
    let mut rng = Rng::new(5, 0);
    for f in [
        Filter::Box(BoxFilter::new(Vector2f::new(0.5, 0.5))),
        Filter::Triangle(TriangleFilter::new(Vector2f::new(2.0, 2.0))),
    ] {
        for _ in 0..10000 {
            let s = f.sample(Point2f::new(rng.uniform_float(), rng.uniform_float()));
            assert_eq!(s.weight, 1.0);
            assert!(s.p.x.abs() <= f.radius().x && s.p.y.abs() <= f.radius().y);
        }
        for u in [0.0, ONE_MINUS_EPSILON] {
            let s = f.sample(Point2f::new(u, u));
            assert!(s.p.x.abs() <= f.radius().x && s.p.y.abs() <= f.radius().y);
        }
    }
}

#[test]
fn batched_samples_match_single_ones() {
    let mut rng = Rng::new(6, 0);
    for f in all_filters() {
        let us: Vec<Point2f> = (0..300)
            .map(|_| Point2f::new(rng.uniform_float(), rng.uniform_float()))
            .collect();
        let mut out = vec![FilterSample {
            p: Point2f::new(9.0, 9.0),
            weight: 9.0,
        }];
        f.sample_many(&us, &mut out);
        assert_eq!(out.len(), us.len() + 1, "{}", name(&f));
        for (u, s) in us.iter().zip(&out[1..]) {
            let e = f.sample(*u);
            assert_eq!(
                (s.p.x.to_bits(), s.p.y.to_bits(), s.weight.to_bits()),
                (e.p.x.to_bits(), e.p.y.to_bits(), e.weight.to_bits()),
                "{} at {u:?}",
                name(&f)
            );
        }
    }
}

#[test]
fn erf_values() {
    assert!((erf(0.0)).abs() < 1e-15);
    assert!((erf(0.3) - 0.328_626_759_459_127_4).abs() < 1e-12);
    assert!((erf(1.0) - 0.842_700_792_949_714_9).abs() < 1e-12);
    assert!((erf(-2.5) + 0.999_593_047_982_555).abs() < 1e-12);
}

#[test]
fn defaults_and_bad_parameters() {
    let loc = FileLoc::new("test.pbrt".into(), 1, 1);
    let d = ParameterDictionary::new(vec![]);
    assert_eq!(
        create_filter("gaussian", &d, &loc).unwrap().radius(),
        Vector2f::new(1.5, 1.5)
    );
    assert_eq!(
        create_filter("mitchell", &d, &loc).unwrap().radius(),
        Vector2f::new(2.0, 2.0)
    );
    assert_eq!(
        create_filter("sinc", &d, &loc).unwrap().radius(),
        Vector2f::new(4.0, 4.0)
    );
    assert_eq!(
        create_filter("triangle", &d, &loc).unwrap().radius(),
        Vector2f::new(2.0, 2.0)
    );
    assert_eq!(
        create_filter("box", &d, &loc).unwrap().radius(),
        Vector2f::new(0.5, 0.5)
    );
    assert!(create_filter("lanczos", &d, &loc)
        .unwrap_err()
        .message
        .contains("unknown"));
    let bad = ParameterDictionary::new(vec![ParsedParameter::with_floats(
        "float",
        "xradius",
        FileLoc::new("test.pbrt".into(), 1, 1),
        vec![-1.0],
    )]);
    assert!(create_filter("box", &bad, &loc).is_err());
    let p = ParameterDictionary::new(vec![ParsedParameter::with_floats(
        "float",
        "sigma",
        FileLoc::new("test.pbrt".into(), 1, 1),
        vec![0.25],
    )]);
    let g = create_filter("gaussian", &p, &loc).unwrap();
    assert!(
        (g.evaluate(Point2f::new(0.0, 0.0))
            - sqr(gaussian(0.0, 0.0, 0.25) - gaussian(1.5, 0.0, 0.25)))
        .abs()
            < 1e-5
    );
}
