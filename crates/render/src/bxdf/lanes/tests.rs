//! The lane models give the same bits at every width, and the coated
//! models' lane walk agrees with the scalar walk it replaced.

use super::*;
use crate::bxdf::layered::FORCE_SCALAR_WALK;
use crate::bxdf::{
    BxDFMethods, CoatedConductorBxDF, CoatedDiffuseBxDF, ConductorBxDF, DielectricBxDF,
    DiffuseBxDF, TrowbridgeReitzDistribution,
};
use crate::rng::Rng;
use crate::sampling::sample_uniform_sphere;
use crate::simd::{dispatch, Kernel, SimdLevel};

fn u2(rng: &mut Rng) -> Point2f {
    Point2f::new(rng.uniform_float(), rng.uniform_float())
}

fn spectrum(rng: &mut Rng, lo: Float, hi: Float) -> SampledSpectrum {
    SampledSpectrum::from_array(std::array::from_fn(|_| {
        lo + (hi - lo) * rng.uniform_float()
    }))
}

/// Roughness: smooth, nearly smooth and rough lanes mixed.
fn alpha(rng: &mut Rng) -> TrowbridgeReitzDistribution {
    let pick = |r: &mut Rng| match (r.uniform_float() * 4.0) as u32 {
        0 => 0.0,
        1 => 2e-3,
        _ => r.uniform_float(),
    };
    let a = pick(rng);
    let b = if rng.uniform_float() < 0.5 {
        a
    } else {
        pick(rng)
    };
    TrowbridgeReitzDistribution::new(a, b)
}

fn dielectric(rng: &mut Rng) -> DielectricBxDF {
    let eta = match (rng.uniform_float() * 5.0) as u32 {
        0 => 1.0,
        1 => 0.7,
        _ => 1.1 + rng.uniform_float(),
    };
    DielectricBxDF::new(eta, alpha(rng))
}

fn conductor(rng: &mut Rng) -> ConductorBxDF {
    ConductorBxDF::new(alpha(rng), spectrum(rng, 0.1, 2.0), spectrum(rng, 0.5, 5.0))
}

fn diffuse(rng: &mut Rng) -> DiffuseBxDF {
    DiffuseBxDF::new(spectrum(rng, 0.0, 1.0))
}

/// One query: directions, sample values, and the two modes.
#[derive(Clone, Copy)]
struct Query {
    wo: Vector3f,
    wi: Vector3f,
    uc: Float,
    u: Point2f,
    mode: TransportMode,
    flags: BxDFReflTransFlags,
}

fn queries(n: usize, rng: &mut Rng) -> Vec<Query> {
    (0..n)
        .map(|k| Query {
            wo: sample_uniform_sphere(u2(rng)),
            wi: sample_uniform_sphere(u2(rng)),
            uc: rng.uniform_float(),
            u: u2(rng),
            mode: if k % 3 == 0 {
                TransportMode::Importance
            } else {
                TransportMode::Radiance
            },
            flags: [
                BxDFReflTransFlags::ALL,
                BxDFReflTransFlags::ALL,
                BxDFReflTransFlags::REFLECTION,
                BxDFReflTransFlags::TRANSMISSION,
            ][k % 4],
        })
        .collect()
}

/// One result per query, as bits: f, the sample, pdf.
type Bits = (
    Vec<u32>,
    Option<(Vec<u32>, [u32; 3], u32, u8, u32, bool)>,
    u32,
);

fn bits_of(f: SampledSpectrum, s: Option<BSDFSample>, pdf: Float) -> Bits {
    (
        f.values.iter().map(|v| v.to_bits()).collect(),
        s.map(|s| {
            (
                s.f.values.iter().map(|v| v.to_bits()).collect(),
                [s.wi.x.to_bits(), s.wi.y.to_bits(), s.wi.z.to_bits()],
                s.pdf.to_bits(),
                s.flags.bits(),
                s.eta.to_bits(),
                s.pdf_is_proportional,
            )
        }),
        pdf.to_bits(),
    )
}

/// Runs `models[k]` on `queries[k]`, `L::N` lanes at a time, all lanes of
/// a call with the same mode and flags (as the wavefront batches them).
struct Run<'a, M> {
    models: &'a [M],
    queries: &'a [Query],
}

impl<M: ToLanes> Kernel for Run<'_, M> {
    type Output = Vec<Bits>;
    fn run<L: F32Lanes>(self) -> Vec<Bits> {
        let mut out = Vec::new();
        for (ms, qs) in self.models.chunks(L::N).zip(self.queries.chunks(L::N)) {
            let refs: Vec<&M> = ms.iter().collect();
            let m = M::gather::<L>(&refs);
            let g = |f: &dyn Fn(&Query) -> Vector3f| {
                let v: Vec<[f32; 3]> = (0..L::N)
                    .map(|i| {
                        let v = f(&qs[source(i, qs.len())]);
                        [v.x, v.y, v.z]
                    })
                    .collect();
                V3::<L>::gather(&v)
            };
            let wo = g(&|q| q.wo);
            let wi = g(&|q| q.wi);
            let uc = gather_f::<L>(qs.len(), |i| qs[i].uc);
            let u = [
                gather_f::<L>(qs.len(), |i| qs[i].u.x),
                gather_f::<L>(qs.len(), |i| qs[i].u.y),
            ];
            let all = splat_mask::<L>(true);
            // The queries of a chunk share the first one's mode and flags.
            let (mode, flags) = (qs[0].mode, qs[0].flags);
            let f = m.f(wo, wi, mode, all);
            let s = m.sample_f(wo, uc, u, mode, flags, all);
            let p = m.pdf(wo, wi, mode, flags, all);
            for i in 0..qs.len() {
                out.push(bits_of(f.get(i), s.get(i), lane(p, i)));
            }
        }
        out
    }
}

/// The same queries one at a time through `one_query`, each with the mode
/// and flags of its chunk's first query (`width` queries a chunk).
fn one_by_one<M>(
    models: &[M],
    queries: &[Query],
    width: usize,
    one_query: impl Fn(&M, &Query, TransportMode, BxDFReflTransFlags) -> Bits,
) -> Vec<Bits> {
    models
        .iter()
        .zip(queries)
        .enumerate()
        .map(|(k, (m, q))| {
            let head = &queries[k - k % width];
            one_query(m, q, head.mode, head.flags)
        })
        .collect()
}

fn compare<M: ToLanes>(
    name: &str,
    models: &[M],
    queries: &[Query],
    one_query: impl Fn(&M, &Query, TransportMode, BxDFReflTransFlags) -> Bits + Copy,
) {
    for level in SimdLevel::available() {
        let got = dispatch(level, Run { models, queries });
        let want = one_by_one(models, queries, level.lanes(), one_query);
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{name}, {level:?}, query {k}");
        }
    }
}

/// Every width against the model's scalar methods (which run the lane
/// form at width one).
fn check<M: ToLanes + BxDFMethods>(name: &str, models: &[M], queries: &[Query]) {
    compare(name, models, queries, |m, q, mode, flags| {
        bits_of(
            m.f(q.wo, q.wi, mode),
            m.sample_f(q.wo, q.uc, q.u, mode, flags),
            m.pdf(q.wo, q.wi, mode, flags),
        )
    });
}

/// Every width against the lane form at width one (for a model whose
/// scalar methods are plain scalar code).
fn check_width_one<M: ToLanes>(name: &str, models: &[M], queries: &[Query]) {
    compare(name, models, queries, |m, q, mode, flags| {
        let one = m.one();
        bits_of(
            f1(&one, q.wo, q.wi, mode),
            sample_f1(&one, q.wo, q.uc, q.u, mode, flags),
            pdf1(&one, q.wo, q.wi, mode, flags),
        )
    });
}

/// The diffuse model's plain scalar methods and its lane form agree: the
/// same values, directions within the lane sine and cosine's rounding.
#[test]
fn diffuse_scalar_code_agrees_with_its_lane_form() {
    let mut rng = Rng::new(79, 0);
    let n = 4000;
    let q = queries(n, &mut rng);
    for q in &q {
        let m = diffuse(&mut rng);
        let one = m.one();
        assert_eq!(m.f(q.wo, q.wi, q.mode), f1(&one, q.wo, q.wi, q.mode));
        assert_eq!(
            m.pdf(q.wo, q.wi, q.mode, q.flags),
            pdf1(&one, q.wo, q.wi, q.mode, q.flags)
        );
        let a = m.sample_f(q.wo, q.uc, q.u, q.mode, q.flags);
        let b = sample_f1(&one, q.wo, q.uc, q.u, q.mode, q.flags);
        assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            assert_eq!(a.f, b.f);
            assert_eq!(a.flags, b.flags);
            assert!((a.wi - b.wi).length() < 1e-6, "{:?} {:?}", a.wi, b.wi);
            assert!((a.pdf - b.pdf).abs() <= 1e-6 * a.pdf.max(1.0));
        }
    }
}

#[test]
fn every_width_gives_the_scalar_bits() {
    let mut rng = Rng::new(77, 0);
    let n = 4000;
    let q = queries(n, &mut rng);
    let d: Vec<_> = (0..n).map(|_| dielectric(&mut rng)).collect();
    check("dielectric", &d, &q);
    let c: Vec<_> = (0..n).map(|_| conductor(&mut rng)).collect();
    check("conductor", &c, &q);
    let r: Vec<_> = (0..n).map(|_| diffuse(&mut rng)).collect();
    check_width_one("diffuse", &r, &q);
    // Coated models: layered sampling is always unrestricted.
    let q: Vec<Query> = q
        .into_iter()
        .map(|q| Query {
            flags: BxDFReflTransFlags::ALL,
            ..q
        })
        .collect();
    let n = 1500;
    let cd: Vec<_> = (0..n).map(|_| coated_diffuse(&mut rng, 10, 1)).collect();
    check("coated diffuse", &cd, &q[..n]);
    let cc: Vec<_> = (0..n).map(|_| coated_conductor(&mut rng, 10, 2)).collect();
    check("coated conductor", &cc, &q[..n]);
}

fn coated_diffuse(rng: &mut Rng, depth: u32, samples: u32) -> CoatedDiffuseBxDF {
    CoatedDiffuseBxDF::new(
        dielectric(rng),
        diffuse(rng),
        0.001 + rng.uniform_float() * 0.1,
        SampledSpectrum::new(0.0),
        0.0,
        depth,
        samples,
    )
}

fn coated_conductor(rng: &mut Rng, depth: u32, samples: u32) -> CoatedConductorBxDF {
    CoatedConductorBxDF::new(
        dielectric(rng),
        conductor(rng),
        0.001 + rng.uniform_float() * 0.1,
        SampledSpectrum::new(0.0),
        0.0,
        depth,
        samples,
    )
}

/// The lane walk computes what the scalar walk computed: the same values
/// except where a last-bit difference (the lane sine, cosine and
/// exponential) flips one of the walk's random decisions, which is rare.
#[test]
fn lane_walk_agrees_with_the_scalar_walk() {
    let mut rng = Rng::new(78, 0);
    let n = 3000;
    let q: Vec<Query> = queries(n, &mut rng)
        .into_iter()
        .map(|q| Query {
            flags: BxDFReflTransFlags::ALL,
            ..q
        })
        .collect();
    let models: Vec<(CoatedDiffuseBxDF, CoatedConductorBxDF)> = (0..n)
        .map(|_| {
            (
                coated_diffuse(&mut rng, 10, 1),
                coated_conductor(&mut rng, 8, 2),
            )
        })
        .collect();
    let eval = |scalar_walk: bool| {
        FORCE_SCALAR_WALK.with(|c| c.set(scalar_walk));
        let v: Vec<[f64; 4]> = models
            .iter()
            .zip(&q)
            .flat_map(|((d, c), q)| {
                let m: [&dyn BxDFMethods; 2] = [d, c];
                m.map(|m| {
                    let s = m.sample_f(q.wo, q.uc, q.u, q.mode, q.flags);
                    [
                        m.f(q.wo, q.wi, q.mode).average() as f64,
                        m.pdf(q.wo, q.wi, q.mode, q.flags) as f64,
                        s.map_or(0.0, |s| s.f.average() as f64),
                        s.map_or(0.0, |s| s.pdf as f64),
                    ]
                })
            })
            .collect();
        FORCE_SCALAR_WALK.with(|c| c.set(false));
        v
    };
    let (lanes, scalar) = (eval(false), eval(true));
    let mut far = [0usize; 4];
    let mut sums = [[0.0f64; 2]; 4];
    for (a, b) in lanes.iter().zip(&scalar) {
        for j in 0..4 {
            let close = (a[j] - b[j]).abs() <= 1e-3 * a[j].abs().max(b[j].abs()) + 1e-6;
            far[j] += usize::from(!close);
            sums[j][0] += a[j];
            sums[j][1] += b[j];
        }
    }
    for j in 0..4 {
        assert!(
            far[j] * 100 <= lanes.len(),
            "quantity {j}: {} of {} differ",
            far[j],
            lanes.len()
        );
        let rel = (sums[j][0] - sums[j][1]).abs() / sums[j][1].abs().max(1e-9);
        assert!(rel < 0.01, "quantity {j}: sums {:?}", sums[j]);
    }
}
