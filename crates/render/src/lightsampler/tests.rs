//! Light sampler tests: pmfs sum to one, sampling frequencies match the
//! pmfs, and the BVH sampler gives zero only to lights that cannot
//! contribute.

use std::sync::Arc;

use rpbrt_geometry::{Float, Normal3f, Point3f, Transform, Vector3f};
use rpbrt_parser::{FileLoc, ParameterDictionary, ParsedParameter};

use super::*;
use crate::light::{
    create_area_light, Light, LightSampleContext, PointLight, UniformInfiniteLight,
};
use crate::params::ParamReader;
use crate::rng::Rng;
use crate::shape::{Disk, Shape};
use crate::spectrum::{RgbColorSpace, Spectrum};

fn disk(at: Vector3f, rot_x: Float, radius: Float) -> Light {
    let xf = Transform::translate(at) * Transform::rotate_x(rot_x);
    let shape = Shape::Disk(Box::new(
        Disk::new(xf, false, 0.0, radius, 0.0, 360.0).unwrap(),
    ));
    let loc = FileLoc::new(Arc::from("t.pbrt"), 1, 1);
    let params = ParameterDictionary::new(vec![ParsedParameter::with_floats(
        "float",
        "scale",
        loc.clone(),
        vec![radius],
    )]);
    let r = ParamReader::plain(&params, &loc);
    create_area_light("diffuse", &r, &xf, &shape, None, None, None).unwrap()
}

fn point(p: Point3f, scale: Float) -> Light {
    Light::Point(PointLight {
        render_from_light: Transform::translate(Vector3f::from(p)),
        i: Spectrum::Constant(1.0),
        scale,
        medium: None,
    })
}

fn scene(rng: &mut Rng, n: usize, infinite: usize) -> Vec<Light> {
    let mut lights = Vec::new();
    for i in 0..n {
        let p = Vector3f::new(
            rng.uniform_float() * 10.0 - 5.0,
            rng.uniform_float() * 10.0 - 5.0,
            rng.uniform_float() * 10.0 - 5.0,
        );
        if i % 2 == 0 {
            lights.push(disk(
                p,
                rng.uniform_float() * 360.0,
                0.2 + rng.uniform_float(),
            ));
        } else {
            lights.push(point(Point3f::from(p), 0.5 + rng.uniform_float() * 3.0));
        }
    }
    for _ in 0..infinite {
        lights.push(Light::UniformInfinite(UniformInfiniteLight {
            l_emit: Spectrum::Constant(1.0),
            scale: 1.0,
            scene: Default::default(),
        }));
    }
    lights
}

fn random_ctx(rng: &mut Rng) -> LightSampleContext {
    let p = Point3f::new(
        rng.uniform_float() * 12.0 - 6.0,
        rng.uniform_float() * 12.0 - 6.0,
        rng.uniform_float() * 12.0 - 6.0,
    );
    let mut ctx = LightSampleContext::from_point(p);
    if rng.uniform_float() < 0.5 {
        let n = Normal3f::from(
            Vector3f::new(
                rng.uniform_float() - 0.5,
                rng.uniform_float() - 0.5,
                rng.uniform_float() - 0.5,
            )
            .normalize(),
        );
        ctx.n = n;
        ctx.ns = n;
    }
    ctx
}

fn check_sampler(
    sampler: &LightSampler,
    n_lights: usize,
    rng: &mut Rng,
    contexts: usize,
    samples: usize,
) {
    for _ in 0..contexts {
        let ctx = random_ctx(rng);
        let pmf: Vec<Float> = (0..n_lights as u32).map(|l| sampler.pmf(&ctx, l)).collect();
        let sum: Float = pmf.iter().sum();
        let mut counts = vec![0usize; n_lights];
        let mut none = 0;
        for _ in 0..samples {
            match sampler.sample(&ctx, rng.uniform_float()) {
                Some(s) => {
                    let p = pmf[s.light as usize];
                    assert!(
                        (s.p - p).abs() <= 1e-4 * p.max(1e-3),
                        "sample p {} vs pmf {}",
                        s.p,
                        p
                    );
                    counts[s.light as usize] += 1;
                }
                None => none += 1,
            }
        }
        if none == samples {
            assert!(sum.abs() < 1e-5, "nothing sampled but pmf sums to {sum}");
            continue;
        }
        // The BVH sampler may reach a node whose children both have zero
        // importance (pbrt-v4 then returns no light); the pmfs of the lights
        // below it are zero too, so the pmfs sum to one minus that mass.
        let p_none = none as Float / samples as Float;
        assert!(
            (sum + p_none - 1.0).abs() < 5e-3 + 5.0 * (p_none / samples as Float).sqrt(),
            "pmf sums to {sum}, no light {p_none}"
        );
        if !matches!(sampler, LightSampler::Bvh(_)) {
            assert_eq!(none, 0);
            assert!((sum - 1.0).abs() < 1e-4);
        }
        for l in 0..n_lights {
            let expected = pmf[l] * samples as Float;
            let got = counts[l] as Float;
            assert!(
                (got - expected).abs() <= 5.0 * expected.sqrt() + 2.0,
                "light {l}: {got} vs {expected}"
            );
            if pmf[l] == 0.0 {
                assert_eq!(counts[l], 0);
            }
        }
        // Context-free sampling.
        let s: Float = (0..n_lights as u32).map(|l| sampler.pmf_no_ctx(l)).sum();
        assert!((s - 1.0).abs() < 1e-4);
    }
}

#[test]
fn all_samplers_pmf_sum_and_frequency() {
    let mut rng = Rng::with_sequence(1);
    for (n, inf) in [(1, 0), (2, 1), (17, 0), (40, 2)] {
        let lights = scene(&mut rng, n, inf);
        for name in LIGHT_SAMPLER_NAMES {
            let s = create_light_sampler(name, &lights).unwrap();
            check_sampler(&s, lights.len(), &mut rng, 20, 20_000);
        }
    }
}

#[test]
fn power_sampler_follows_power() {
    let lights = vec![
        point(Point3f::new(0.0, 0.0, 0.0), 1.0),
        point(Point3f::new(1.0, 0.0, 0.0), 3.0),
    ];
    let s = create_light_sampler("power", &lights).unwrap();
    assert!((s.pmf_no_ctx(0) - 0.25).abs() < 1e-5);
    assert!((s.pmf_no_ctx(1) - 0.75).abs() < 1e-5);
}

#[test]
fn bvh_zero_only_behind_one_sided_emitters() {
    // A one-sided disk facing +z at the origin, and a point light.
    let lights = vec![
        disk(Vector3f::new(0.0, 0.0, 0.0), 0.0, 1.0),
        point(Point3f::new(5.0, 5.0, 5.0), 1.0),
    ];
    let s = create_light_sampler("bvh", &lights).unwrap();
    let behind = LightSampleContext::from_point(Point3f::new(0.0, 0.0, -3.0));
    let front = LightSampleContext::from_point(Point3f::new(0.0, 0.0, 3.0));
    assert_eq!(s.pmf(&behind, 0), 0.0);
    assert!((s.pmf(&behind, 1) - 1.0).abs() < 1e-5);
    assert!(s.pmf(&front, 0) > 0.0);
    assert!(s.pmf(&front, 1) > 0.0);
    let mut rng = Rng::with_sequence(9);
    check_sampler(&s, 2, &mut rng, 30, 10_000);
    // Every light that can contribute has a nonzero pmf.
    let lights = scene(&mut rng, 30, 0);
    let s = create_light_sampler("bvh", &lights).unwrap();
    for _ in 0..50 {
        let ctx = LightSampleContext::from_point(Point3f::new(
            rng.uniform_float() * 12.0 - 6.0,
            rng.uniform_float() * 12.0 - 6.0,
            rng.uniform_float() * 12.0 - 6.0,
        ));
        for (i, l) in lights.iter().enumerate() {
            if let Light::Point(_) = l {
                assert!(s.pmf(&ctx, i as u32) > 0.0, "point light {i} got zero pmf");
            }
        }
    }
}

#[test]
fn unknown_sampler_lists_known_ones() {
    let e = create_light_sampler("exhaustive-ish", &[]).unwrap_err();
    let msg = format!("{e:?}");
    assert!(msg.contains("uniform") && msg.contains("power") && msg.contains("bvh"));
    let _ = RgbColorSpace::srgb();
}

/// The batched choice equals the single one bit for bit at every width
/// the processor runs: random scenes (one light, a few, many, with and
/// without infinite lights, one-sided disks that some points are behind),
/// points with and without normals, batches of every length up to two
/// widths.
#[test]
fn batched_bvh_choices_match_single_ones() {
    use crate::simd::SimdLevel;
    let mut rng = Rng::with_sequence(21);
    let mut descended = 0;
    for (n, inf) in [(1, 0), (2, 0), (3, 1), (17, 0), (64, 2), (300, 0)] {
        let lights = scene(&mut rng, n, inf);
        let LightSampler::Bvh(s) = create_light_sampler("bvh", &lights).unwrap() else {
            panic!("not the BVH sampler");
        };
        for batch in 1..=33 {
            let ctxs: Vec<LightSampleContext> = (0..batch).map(|_| random_ctx(&mut rng)).collect();
            let queries: Vec<LightChoice> = ctxs
                .iter()
                .map(|c| LightChoice::new(c, rng.uniform_float()))
                .collect();
            let want: Vec<Option<SampledLight>> = ctxs
                .iter()
                .zip(&queries)
                .map(|(c, q)| s.sample(c, q.u))
                .collect();
            for level in SimdLevel::available() {
                let mut got = Vec::new();
                s.sample_batch(level, &queries, &mut got);
                let bits = |v: &[Option<SampledLight>]| -> Vec<Option<(u32, u32)>> {
                    v.iter()
                        .map(|o| o.map(|x| (x.light, x.p.to_bits())))
                        .collect()
                };
                assert_eq!(
                    bits(&got),
                    bits(&want),
                    "{n} lights, batch {batch}, {level:?}"
                );
            }
            descended += want.iter().filter(|w| w.is_some_and(|x| x.p < 1.0)).count();
        }
    }
    assert!(descended > 1500, "{descended}");
}
