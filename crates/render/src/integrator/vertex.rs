//! Path tracers written one vertex at a time: the form both execution
//! designs share. The scalar loop ([`li_by_vertices`]) traces each ray as
//! soon as it is made; the wavefront loop (`wavefront.rs`) traces a batch
//! of paths' rays together and answers their light samples together. Both
//! call the same [`VertexIntegrator::begin`] and
//! [`VertexIntegrator::finish`] in the same sampler order, so they give
//! the same pixels.

use super::bsdf_stage::{BsdfAnswers, BsdfQuery};
use super::diffuse_lanes::{LaneShade, LaneVertices, SurfaceOut};
use super::direct::{answer_light, LightAnswer, LightRequest, ShadowQuery};
use super::Scene;
use crate::bxdf::{DielectricBxDF, BSDF};
use crate::film::VisibleSurface;
use crate::primitive::HitRecord;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::Point2f;

/// What a path vertex leaves to the caller: a shadow ray whose
/// contribution counts if nothing blocks it, and whether the path ends
/// (after that contribution).
pub(crate) struct VertexStep {
    /// The light sample's shadow query, its contribution already
    /// multiplied by the path throughput.
    pub shadow: Option<ShadowQuery>,
    /// The path ends here.
    pub done: bool,
}

impl VertexStep {
    /// The path goes on, with no shadow ray.
    pub(crate) const NEXT: VertexStep = VertexStep {
        shadow: None,
        done: false,
    };
    /// The path ends, with no shadow ray.
    pub(crate) const DONE: VertexStep = VertexStep {
        shadow: None,
        done: true,
    };
}

/// The first half of a vertex: either the whole step, or a light sample
/// to take before the second half ([`VertexIntegrator::finish`]).
pub(crate) enum Begin {
    /// The vertex is done.
    Step(VertexStep),
    /// The vertex needs this light sample answered ([`answer_light`]).
    Light(LightRequest),
}

/// A path tracer as a function from a path's state and its ray's closest
/// hit to the next state, in two halves around the vertex's light sample
/// (so that the wavefront loop can answer many paths' light samples
/// together).
pub(crate) trait VertexIntegrator: Sync {
    /// A path in flight: its ray, radiance so far and throughput.
    type State: Send;

    /// What a vertex keeps between its halves (its hit and BSDF).
    type Scratch: Default;

    /// The state of a path starting with a camera ray.
    fn start(&self, ray: RayDifferential) -> Self::State;

    /// The ray whose closest hit the next vertex needs, with its
    /// differentials.
    fn ray(s: &Self::State) -> &RayDifferential;

    /// The radiance the path has gathered.
    fn radiance(s: &mut Self::State) -> &mut SampledSpectrum;

    /// The BSDF queries the second half of a vertex that asked for
    /// `light` will make (`None`: it makes none), for the wavefront's
    /// batched BSDF stage.
    fn bsdf_query<'a>(
        s: &Self::State,
        scratch: &'a Self::Scratch,
        light: Option<&LightAnswer>,
    ) -> Option<BsdfQuery<'a>>;

    /// Where the BSDF stage leaves its answers for the second half (which
    /// takes them, evaluating what is not answered).
    fn bsdf_answers(scratch: &mut Self::Scratch) -> &mut BsdfAnswers;

    /// A vertex's first half: `record` is the closest hit of
    /// [`VertexIntegrator::ray`] with no bound on the ray parameter
    /// (`None`: the ray escaped).
    #[allow(clippy::too_many_arguments)]
    fn begin(
        &self,
        scene: &Scene,
        s: &mut Self::State,
        record: Option<HitRecord>,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        visible: Option<&mut VisibleSurface>,
        scratch: &mut Self::Scratch,
    ) -> Begin;

    /// A vertex's second half, after [`Begin::Light`], given the answer
    /// to its request; the sampler continues where `begin` left it.
    fn finish(
        &self,
        scene: &Scene,
        s: &mut Self::State,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Self::Scratch,
        light: Option<&LightAnswer>,
    ) -> VertexStep;

    /// The lane forms of a vertex (`diffuse_lanes.rs`), for the
    /// wavefront: for a hit `record` of the path in state `s` that a lane
    /// form covers, what it shades with, the surface kernel's input
    /// taking the next slot of `out`; `None` (the default) where the
    /// scalar vertex runs. `gbuffer`: the film records the first visible
    /// surface.
    fn lane_hit(
        &self,
        _scene: &Scene,
        _s: &Self::State,
        _record: &HitRecord,
        _lambda: &SampledWavelengths,
        _gbuffer: bool,
        _out: &mut LaneVertices,
    ) -> Option<LaneShade> {
        None
    }

    /// The whole vertex that [`VertexIntegrator::lane_hit`] took as
    /// [`LaneShade::Specular`], given its surface and BxDF (a specular
    /// vertex asks for no light sample).
    fn specular_step(
        &self,
        _s: &mut Self::State,
        _scratch: &mut Self::Scratch,
        _surface: &SurfaceOut,
        _bxdf: DielectricBxDF,
        _sampler: &mut Sampler,
    ) -> VertexStep {
        unreachable!("specular_step without lane_hit")
    }

    /// The diffuse vertex's BSDF sample leaves from ωo (true) or from the
    /// negated ray direction (false), as the scalar vertex samples it.
    const DIFFUSE_SAMPLE_FROM_WO: bool = false;

    /// The first half of a vertex that [`VertexIntegrator::lane_hit`]
    /// took as [`LaneShade::Diffuse`], at slot `k` of `lanes` after the
    /// surface kernel, given its reflectance and its four sampler draws
    /// ([`Sampler::get_vertex_samples`]): its light request.
    fn diffuse_begin(
        &self,
        _s: &mut Self::State,
        _scratch: &mut Self::Scratch,
        _lanes: &mut LaneVertices,
        _k: usize,
        _r: SampledSpectrum,
        _draws: (Float, Point2f, Float, Point2f),
    ) -> LightRequest {
        unreachable!("diffuse_begin without lane_hit")
    }

    /// The second half of such a vertex, after the scatter kernel, given
    /// the answer to its light request; `draw` gives its next 1-D sampler
    /// draw, called where the vertex draws (Russian roulette).
    fn diffuse_finish(
        &self,
        _scene: &Scene,
        _s: &mut Self::State,
        _lanes: &LaneVertices,
        _k: usize,
        _light: Option<&LightAnswer>,
        _draw: impl FnOnce() -> Float,
    ) -> VertexStep {
        unreachable!("diffuse_finish without lane_hit")
    }

    /// The first half of a vertex that [`VertexIntegrator::lane_hit`]
    /// took as [`LaneShade::Staged`], at slot `k` of `lanes` after the
    /// surface kernel, given its BSDF (non-specular, in the kernel's
    /// frame: [`LaneVertices::bsdf`]) and its four sampler draws: its
    /// light request. The BSDF stage then answers its queries
    /// ([`VertexIntegrator::bsdf_query`]).
    fn staged_begin(
        &self,
        _s: &mut Self::State,
        _scratch: &mut Self::Scratch,
        _lanes: &LaneVertices,
        _k: usize,
        _bsdf: BSDF,
        _draws: (Float, Point2f, Float, Point2f),
    ) -> LightRequest {
        unreachable!("staged_begin without lane_hit")
    }

    /// The second half of such a vertex, given the answer to its light
    /// request and the BSDF stage's answers in `scratch`; `draw` as for
    /// [`VertexIntegrator::diffuse_finish`].
    #[allow(clippy::too_many_arguments)]
    fn staged_finish(
        &self,
        _scene: &Scene,
        _s: &mut Self::State,
        _scratch: &mut Self::Scratch,
        _lanes: &LaneVertices,
        _k: usize,
        _light: Option<&LightAnswer>,
        _draw: impl FnOnce() -> Float,
    ) -> VertexStep {
        unreachable!("staged_finish without lane_hit")
    }
}

/// The scalar loop: the radiance along `ray`, each vertex's rays traced
/// as soon as they are made (the `li` of the integrators that have a
/// vertex form).
pub(crate) fn li_by_vertices<I: VertexIntegrator>(
    integrator: &I,
    scene: &Scene,
    ray: RayDifferential,
    lambda: &mut SampledWavelengths,
    sampler: &mut Sampler,
    mut visible: Option<&mut VisibleSurface>,
) -> SampledSpectrum {
    let mut s = integrator.start(ray);
    let mut scratch = I::Scratch::default();
    loop {
        let record = scene.intersect_record(&I::ray(&s).ray, Float::INFINITY);
        let step = match integrator.begin(
            scene,
            &mut s,
            record,
            lambda,
            sampler,
            visible.as_deref_mut(),
            &mut scratch,
        ) {
            Begin::Step(step) => step,
            Begin::Light(req) => {
                let answer = answer_light(scene, &scene.light_sampler, &req, lambda);
                integrator.finish(
                    scene,
                    &mut s,
                    lambda,
                    sampler,
                    &mut scratch,
                    answer.as_ref(),
                )
            }
        };
        if let Some(q) = step.shadow {
            if !scene.intersect_p(&q.ray, q.t_max) {
                *I::radiance(&mut s) += q.ld;
            }
        }
        if step.done {
            return *I::radiance(&mut s);
        }
    }
}
