//! The wavefront's BSDF stage: the BSDF queries of every path's vertex
//! (its value and density toward the light sample, the sample that
//! continues the path and its density for MIS), answered together before
//! the vertices finish, lane-parallel for the models that have a lane form
//! (`bxdf/lanes`), grouped by model.
//!
//! Each answer is what the scalar [`BSDF`] methods return for the same
//! query, bit for bit: the directions are taken to and from the shading
//! frame by the same scalar code, and the lane models compute at every
//! width what the scalar models compute (they are the same code at width
//! one). A vertex whose model has no lane form gets no answers and
//! evaluates its BSDF itself in [`super::vertex::VertexIntegrator::finish`].
//!
//! Batched today: the conductor and dielectric models, and the coated
//! models (`coateddiffuse`, `coatedconductor`) without a medium between
//! their interfaces, whose stochastic walk is most of the shading time of
//! scenes that use them. (The diffuse model's few operations cost less
//! than gathering them into lanes.)

use crate::bxdf::lanes::{gather_f, lane, BxDFLanes, ToLanes, MAX_LANES};
use crate::bxdf::{BSDFSample, BxDF, BxDFReflTransFlags, TransportMode, BSDF};
use crate::simd::math::V3;
use crate::simd::{dispatch, F32Lanes, Kernel, SimdLevel};
use crate::spectrum::SampledSpectrum;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::{Point2f, Vector3f};

/// The BSDF queries a vertex's second half will make.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BsdfQuery<'a> {
    pub bsdf: &'a BSDF,
    /// ωo for the light sample's evaluation.
    pub wo_light: Vector3f,
    /// The light sample's direction, if there is one to evaluate.
    pub wi_light: Option<Vector3f>,
    /// ωo and the sample values for the BSDF sample.
    pub wo: Vector3f,
    pub u: Float,
    pub u2: Point2f,
}

/// Answers to a vertex's [`BsdfQuery`], as the scalar methods give them.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BsdfAnswers {
    /// `bsdf.f(wo_light, wi_light)` and `bsdf.pdf(wo_light, wi_light)`.
    pub light: Option<(SampledSpectrum, Float)>,
    /// `bsdf.sample_f(wo, u, u2)` and the density MIS uses for it
    /// (`bsdf.pdf(wo, wi)` when the sample's is only proportional).
    pub sample: Option<(Option<BSDFSample>, Float)>,
}

impl BsdfAnswers {
    /// `bsdf.f(wo, wi)` toward the light sample (answered, or evaluated
    /// now).
    #[inline]
    pub fn light_f(&self, bsdf: &BSDF, wo: Vector3f, wi: Vector3f) -> SampledSpectrum {
        match self.light {
            Some((f, _)) => f,
            None => bsdf.f(wo, wi, TransportMode::Radiance),
        }
    }

    /// `bsdf.pdf(wo, wi)` toward the light sample (answered, or evaluated
    /// now).
    #[inline]
    pub fn light_pdf(&self, bsdf: &BSDF, wo: Vector3f, wi: Vector3f) -> Float {
        match self.light {
            Some((_, p)) => p,
            None => bsdf.pdf(wo, wi, TransportMode::Radiance, BxDFReflTransFlags::ALL),
        }
    }

    /// The BSDF sample from `wo` and its MIS density (answered, or
    /// computed now).
    #[inline]
    pub fn sample(
        &self,
        bsdf: &BSDF,
        wo: Vector3f,
        u: Float,
        u2: Point2f,
    ) -> Option<(BSDFSample, Float)> {
        if let Some((bs, p)) = self.sample {
            return bs.map(|bs| (bs, p));
        }
        let bs = bsdf.sample_f(wo, u, u2, TransportMode::Radiance, BxDFReflTransFlags::ALL)?;
        let p = if bs.pdf_is_proportional {
            bsdf.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
        } else {
            bs.pdf
        };
        Some((bs, p))
    }
}

/// The groups a batch is sorted into: one per lane model and walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Group {
    Conductor,
    Dielectric,
    CoatedDiffuse(u32, u32, i32),
    CoatedConductor(u32, u32, i32),
}

/// The lane group of a vertex's model, if it has one.
#[inline]
fn group_of(bxdf: &BxDF) -> Option<Group> {
    match bxdf {
        BxDF::Conductor(_) => Some(Group::Conductor),
        BxDF::Dielectric(_) => Some(Group::Dielectric),
        BxDF::CoatedDiffuse(m) if m.has_lane_walk() => {
            let (d, n, s) = m.walk_key();
            Some(Group::CoatedDiffuse(d, n, s))
        }
        BxDF::CoatedConductor(m) if m.has_lane_walk() => {
            let (d, n, s) = m.walk_key();
            Some(Group::CoatedConductor(d, n, s))
        }
        _ => None,
    }
}

/// Reusable buffers of the stage.
#[derive(Default)]
pub(crate) struct BsdfBatch {
    groups: Vec<(Group, Vec<usize>)>,
}

/// Answers `queries[k]` into `out[k]` (left default for models without
/// a lane form), at `level`'s width.
pub(crate) fn answer_bsdfs(
    level: SimdLevel,
    queries: &[Option<BsdfQuery>],
    batch: &mut BsdfBatch,
    out: &mut Vec<BsdfAnswers>,
) {
    out.clear();
    out.resize(queries.len(), BsdfAnswers::default());
    for (_, v) in batch.groups.iter_mut() {
        v.clear();
    }
    for (k, q) in queries.iter().enumerate() {
        let Some(g) = q.and_then(|q| group_of(&q.bsdf.bxdf)) else {
            continue;
        };
        match batch.groups.iter_mut().find(|(h, _)| *h == g) {
            Some((_, v)) => v.push(k),
            None => batch.groups.push((g, vec![k])),
        }
    }
    let width = level.lanes().max(1);
    for (g, members) in &batch.groups {
        for chunk in members.chunks(width) {
            match g {
                Group::Conductor => run_chunk(level, queries, chunk, out, |b| match b {
                    BxDF::Conductor(m) => Some(m),
                    _ => None,
                }),
                Group::Dielectric => run_chunk(level, queries, chunk, out, |b| match b {
                    BxDF::Dielectric(m) => Some(m),
                    _ => None,
                }),
                Group::CoatedDiffuse(..) => run_chunk(level, queries, chunk, out, |b| match b {
                    BxDF::CoatedDiffuse(m) => Some(m),
                    _ => None,
                }),
                Group::CoatedConductor(..) => run_chunk(level, queries, chunk, out, |b| match b {
                    BxDF::CoatedConductor(m) => Some(m),
                    _ => None,
                }),
            }
        }
    }
}

/// Answers one chunk of a group (at most the width's lanes) of models `M`,
/// which `pick` finds in each member's BxDF.
fn run_chunk<'a, M: ToLanes + 'a>(
    level: SimdLevel,
    queries: &'a [Option<BsdfQuery>],
    chunk: &[usize],
    out: &mut [BsdfAnswers],
    pick: impl Fn(&'a BxDF) -> Option<&'a M>,
) {
    let models = models_of(queries, chunk, pick);
    let k = Chunk::<M> {
        models: &models[..chunk.len()],
        queries,
        members: chunk,
    };
    dispatch(level, k).write(chunk, out);
}

/// The models of a chunk's members (every member is of the group's kind;
/// unused entries repeat the first).
fn models_of<'a, M>(
    queries: &'a [Option<BsdfQuery>],
    chunk: &[usize],
    pick: impl Fn(&'a BxDF) -> Option<&'a M>,
) -> [&'a M; MAX_LANES] {
    let get = |k: usize| {
        queries[k]
            .and_then(|q| pick(&q.bsdf.bxdf))
            .expect("a group holds only its own model")
    };
    let first = get(chunk[0]);
    let mut out = [first; MAX_LANES];
    for (o, &k) in out.iter_mut().zip(chunk) {
        *o = get(k);
    }
    out
}

/// One chunk of a group, run at one width.
struct Chunk<'a, 'q, M> {
    models: &'a [&'a M],
    queries: &'a [Option<BsdfQuery<'q>>],
    members: &'a [usize],
}

/// A chunk's answers, one per member.
struct ChunkAnswers {
    answers: [BsdfAnswers; MAX_LANES],
}

impl ChunkAnswers {
    fn write(&self, members: &[usize], out: &mut [BsdfAnswers]) {
        for (a, &k) in self.answers.iter().zip(members) {
            out[k] = *a;
        }
    }
}

/// Lanes of one vector per member (the first fills the rest).
#[inline(always)]
fn gather_v<L: F32Lanes>(n: usize, f: impl Fn(usize) -> Vector3f) -> V3<L> {
    let mut c = [[0.0f32; 3]; MAX_LANES];
    for (i, x) in c.iter_mut().enumerate().take(L::N) {
        let v = f(if i < n { i } else { 0 });
        *x = [v.x, v.y, v.z];
    }
    V3::gather(&c)
}

/// The mask of the lanes `i < n` for which `f(i)` holds.
#[inline(always)]
fn mask_of<L: F32Lanes>(n: usize, f: impl Fn(usize) -> bool) -> L::Mask {
    let mut bits = 0u32;
    for i in 0..n.min(L::N) {
        if f(i) {
            bits |= 1 << i;
        }
    }
    L::from_bits(bits)
}

impl<M: ToLanes> Kernel for Chunk<'_, '_, M> {
    type Output = ChunkAnswers;

    #[inline(always)]
    fn run<L: F32Lanes>(self) -> ChunkAnswers {
        let n = self.members.len();
        let q = |i: usize| -> BsdfQuery {
            self.queries[self.members[i]].expect("members have queries")
        };
        let m = M::gather::<L>(self.models);
        let mode = TransportMode::Radiance;
        let all = BxDFReflTransFlags::ALL;
        let mut answers = [BsdfAnswers::default(); MAX_LANES];

        // Toward the light: BSDF::f and BSDF::pdf in the shading frame.
        let local = |i: usize, v: Vector3f| q(i).bsdf.render_to_local(v);
        let wo_l = gather_v::<L>(n, |i| local(i, q(i).wo_light));
        let wi_l = gather_v::<L>(n, |i| {
            q(i).wi_light
                .map_or(Vector3f::new(0.0, 0.0, 1.0), |w| local(i, w))
        });
        let lit = mask_of::<L>(n, |i| {
            q(i).wi_light.is_some() && local(i, q(i).wo_light).z != 0.0
        });
        if L::bits(lit) != 0 {
            let f = m.f(wo_l, wi_l, mode, lit);
            let p = m.pdf(wo_l, wi_l, mode, all, lit);
            for (i, a) in answers.iter_mut().enumerate().take(n) {
                if q(i).wi_light.is_none() {
                    continue;
                }
                a.light = Some(if (L::bits(lit) >> i) & 1 != 0 {
                    (f.get(i), lane(p, i))
                } else {
                    // BSDF::f and BSDF::pdf of a grazing ωo.
                    (SampledSpectrum::new(0.0), 0.0)
                });
            }
        } else {
            for (i, a) in answers.iter_mut().enumerate().take(n) {
                if q(i).wi_light.is_some() {
                    a.light = Some((SampledSpectrum::new(0.0), 0.0));
                }
            }
        }

        // The sample: BSDF::sample_f, then the density of its direction
        // taken back to the shading frame from render space.
        let wo_s = gather_v::<L>(n, |i| local(i, q(i).wo));
        let can = mask_of::<L>(n, |i| {
            let qi = q(i);
            local(i, qi.wo).z != 0.0 && qi.bsdf.flags().allows(all)
        });
        let uc = gather_f::<L>(n, |i| q(i).u);
        let u = [
            gather_f::<L>(n, |i| q(i).u2.x),
            gather_f::<L>(n, |i| q(i).u2.y),
        ];
        let s = m.sample_f(wo_s, uc, u, mode, all, can);
        let mut samples: [Option<BSDFSample>; MAX_LANES] = [None; MAX_LANES];
        for (i, slot) in samples.iter_mut().enumerate().take(n) {
            if (L::bits(can) >> i) & 1 == 0 {
                continue;
            }
            let Some(mut bs) = s.get(i) else {
                continue;
            };
            if bs.f.is_black() || bs.pdf == 0.0 || bs.wi.z == 0.0 {
                continue;
            }
            bs.wi = q(i).bsdf.local_to_render(bs.wi);
            *slot = Some(bs);
        }
        let proportional = mask_of::<L>(n, |i| samples[i].is_some_and(|bs| bs.pdf_is_proportional));
        let mut mis = [0.0f32; MAX_LANES];
        if L::bits(proportional) != 0 {
            let wi_back = gather_v::<L>(n, |i| {
                samples[i].map_or(Vector3f::new(0.0, 0.0, 1.0), |bs| local(i, bs.wi))
            });
            let p = m.pdf(wo_s, wi_back, mode, all, proportional);
            for (i, x) in mis.iter_mut().enumerate().take(n) {
                *x = lane(p, i);
            }
        }
        for (i, a) in answers.iter_mut().enumerate().take(n) {
            let p = match samples[i] {
                Some(bs) if bs.pdf_is_proportional => mis[i],
                Some(bs) => bs.pdf,
                None => 0.0,
            };
            a.sample = Some((samples[i], p));
        }
        ChunkAnswers { answers }
    }
}
