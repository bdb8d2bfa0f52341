//! Samplers (book chapter 8; pbrt-v4 `samplers.h`, `samplers.cpp`): the
//! sources of the sample values that drive rendering, from independent
//! random numbers to stratified and low-discrepancy sequences.
//!
//! Each sampler is deterministic per (pixel, sample index, dimension,
//! seed): `start_pixel_sample` sets all of its state, so results never
//! depend on which thread renders which pixel or in what order. Clone one
//! sampler per thread.

mod create;
mod data;
pub mod halton;
pub mod independent;
pub mod lowdiscrepancy;
pub mod pmj02bn;
pub mod sobol;
pub mod stratified;
#[cfg(test)]
mod tests;

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::{Point2f, Point2i};

pub use create::{create_sampler, SAMPLER_NAMES};
pub use halton::HaltonSampler;
pub use independent::IndependentSampler;
pub use lowdiscrepancy::RandomizeStrategy;
pub use pmj02bn::Pmj02bnSampler;
pub use sobol::{FourDrawBatch, PaddedSobolSampler, SobolSampler, ZSobolSampler};
pub use stratified::StratifiedSampler;

/// Where sample values come from, for code that runs under both the
/// pixel samplers ([`Sampler`]) and MLT's primary-sample-space sampler
/// (pbrt-v4 puts `MLTSampler` in its `Sampler` union; here the path code
/// that MLT shares is generic over this trait instead).
pub trait SampleSource {
    /// The next sample dimension, in [0,1).
    fn get_1d(&mut self) -> Float;
    /// The next two sample dimensions, in [0,1)².
    fn get_2d(&mut self) -> Point2f;
}

impl SampleSource for Sampler {
    #[inline]
    fn get_1d(&mut self) -> Float {
        Sampler::get_1d(self)
    }
    #[inline]
    fn get_2d(&mut self) -> Point2f {
        Sampler::get_2d(self)
    }
}

/// Where a sampler stands within one pixel sample: everything
/// [`Sampler::start_pixel_sample`] and the draws since have set, without
/// the sampler's tables and caches. Many paths in flight at once (the
/// wavefront integrator's lanes) share one sampler and keep a cursor each:
/// [`Sampler::set_cursor`] then continues a path's sample exactly where
/// [`Sampler::cursor`] left it. Each sampler uses the fields it needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SamplerCursor {
    /// A sampler's 64-bit position (a sequence index, a generator state).
    pub(crate) a: u64,
    /// A second 64-bit word (a generator's increment).
    pub(crate) b: u64,
    /// The pixel.
    pub(crate) pixel: Point2i,
    /// The sample index within the pixel.
    pub(crate) index: i32,
    /// The next sample dimension.
    pub(crate) dimension: i32,
}

impl SamplerCursor {
    /// Takes draws [`Sampler::four_draws_batch`] computed at this cursor
    /// (its `out`), without the sampler: the values and the cursor after
    /// them are those of [`Sampler::get_vertex_samples`] at this cursor
    /// with the draws offered ([`Sampler::offer_four_draws`]). (Only
    /// Z-Sobol' computes draws ahead; its four draws span six
    /// dimensions.)
    #[inline(always)]
    pub(crate) fn take_four_draws(&mut self, d: [Float; 6]) -> (Float, Point2f, Float, Point2f) {
        self.dimension += 6;
        (
            d[0],
            Point2f::new(d[1], d[2]),
            d[3],
            Point2f::new(d[4], d[5]),
        )
    }

    /// Takes the 1-D draw [`Sampler::four_draws_batch`] computed at this
    /// cursor (its `next`), without the sampler: as
    /// [`Sampler::get_1d`] with the draw offered ([`Sampler::offer_1d`]).
    #[inline(always)]
    pub(crate) fn take_1d(&mut self, v: Float) -> Float {
        self.dimension += 1;
        v
    }
}

/// A sampler: a closed set of variants with one-line delegation (the
/// Rust form of pbrt-v4's tagged `Sampler`).
#[derive(Clone, Debug)]
pub enum Sampler {
    /// Independent uniform random samples.
    Independent(IndependentSampler),
    /// Jittered stratified samples.
    Stratified(StratifiedSampler),
    /// The Halton sequence.
    Halton(HaltonSampler),
    /// One Sobol' sequence over the whole image.
    Sobol(SobolSampler),
    /// Per-pixel padded Sobol' points.
    PaddedSobol(PaddedSobolSampler),
    /// Morton-ordered Sobol' (pbrt-v4's default).
    ZSobol(ZSobolSampler),
    /// Progressive multi-jittered (0,2) points with blue-noise selection.
    Pmj02bn(Pmj02bnSampler),
}

macro_rules! dispatch {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Sampler::Independent($s) => $e,
            Sampler::Stratified($s) => $e,
            Sampler::Halton($s) => $e,
            Sampler::Sobol($s) => $e,
            Sampler::PaddedSobol($s) => $e,
            Sampler::ZSobol($s) => $e,
            Sampler::Pmj02bn($s) => $e,
        }
    };
}

impl Sampler {
    /// Samples taken in each pixel.
    #[inline]
    pub fn samples_per_pixel(&self) -> i32 {
        dispatch!(self, s => s.samples_per_pixel())
    }

    /// Starts sample `sample_index` of pixel `p`, at sample dimension
    /// `dimension` (0 for a camera sample from scratch).
    #[inline]
    pub fn start_pixel_sample(&mut self, p: Point2i, sample_index: i32, dimension: i32) {
        dispatch!(self, s => s.start_pixel_sample(p, sample_index, dimension))
    }

    /// Where the sampler stands in its current pixel sample.
    #[inline]
    pub fn cursor(&self) -> SamplerCursor {
        dispatch!(self, s => s.cursor())
    }

    /// Continues the pixel sample that [`Sampler::cursor`] described (of
    /// this sampler or a clone of it), as if no other sample had been
    /// started since.
    #[inline]
    pub fn set_cursor(&mut self, c: &SamplerCursor) {
        dispatch!(self, s => s.set_cursor(c))
    }

    /// The next sample dimension, in [0,1).
    #[inline]
    pub fn get_1d(&mut self) -> Float {
        dispatch!(self, s => s.get_1d())
    }

    /// The next two sample dimensions, in [0,1)².
    #[inline]
    pub fn get_2d(&mut self) -> Point2f {
        dispatch!(self, s => s.get_2d())
    }

    /// Four draws in a row, as the path tracer takes them at a vertex with
    /// next-event estimation: light choice (1-D), point on the light
    /// (2-D), BSDF component (1-D), BSDF direction (2-D). The same values
    /// as four separate calls; drawn together, their independent
    /// computations overlap in the processor instead of each stalling the
    /// path in turn.
    #[inline]
    pub fn get_vertex_samples(&mut self) -> (Float, Point2f, Float, Point2f) {
        match self {
            Sampler::ZSobol(s) => return s.get_1d_2d_1d_2d(),
            Sampler::Halton(s) => return s.get_1d_2d_1d_2d(),
            _ => {}
        }
        dispatch!(self, s => {
            let u_light = s.get_1d();
            let u_light_2d = s.get_2d();
            let u_bsdf = s.get_1d();
            let u_bsdf_2d = s.get_2d();
            (u_light, u_light_2d, u_bsdf, u_bsdf_2d)
        })
    }

    /// The draws that start a camera sample, in pbrt-v4's order and taken
    /// together (see [`Sampler::get_vertex_samples`]): wavelengths (1-D),
    /// position in the pixel, time (1-D), lens position (2-D).
    #[inline]
    pub fn get_camera_samples(&mut self) -> (Float, Point2f, Float, Point2f) {
        match self {
            Sampler::ZSobol(s) => return s.get_1d_2d_1d_2d(),
            Sampler::Halton(s) => return s.get_camera_samples(),
            _ => {}
        }
        dispatch!(self, s => {
            let u_lambda = s.get_1d();
            let u_pixel = s.get_pixel_2d();
            let u_time = s.get_1d();
            let u_lens = s.get_2d();
            (u_lambda, u_pixel, u_time, u_lens)
        })
    }

    /// The four draws [`Sampler::get_vertex_samples`] (or
    /// [`Sampler::get_camera_samples`]) would take at each of `cursors`,
    /// computed together, lane-parallel at `level`, into `out`: `None`
    /// where this sampler has no batched form for them (today: all but
    /// Z-Sobol' with fast Owen scrambling and at least 4 spp). Offer one
    /// to the draw with [`Sampler::offer_four_draws`].
    pub fn four_draws_batch(
        &mut self,
        level: crate::simd::SimdLevel,
        cursors: &[SamplerCursor],
        batch: &mut FourDrawBatch,
        out: &mut Vec<Option<[Float; 6]>>,
        next: Option<&mut Vec<Option<Float>>>,
    ) {
        if let Sampler::ZSobol(s) = self {
            return s.four_draws_batch(level, cursors, batch, out, next);
        }
        out.clear();
        out.resize(cursors.len(), None);
        if let Some(next) = next {
            next.clear();
            next.resize(cursors.len(), None);
        }
    }

    /// Offers four draws from [`Sampler::four_draws_batch`], computed at
    /// the current cursor, to the next four-draw call at that cursor
    /// ([`Sampler::set_cursor`] withdraws them).
    #[inline]
    pub fn offer_four_draws(&mut self, draws: Option<[Float; 6]>) {
        if let Sampler::ZSobol(s) = self {
            s.offer_four_draws(draws);
        }
    }

    /// Offers a 1-D draw from [`Sampler::four_draws_batch`]'s `next`,
    /// computed at the current cursor, to the next [`Sampler::get_1d`] at
    /// that cursor ([`Sampler::set_cursor`] withdraws it).
    #[inline]
    pub fn offer_1d(&mut self, draw: Option<Float>) {
        if let Sampler::ZSobol(s) = self {
            s.offer_1d(draw);
        }
    }

    /// The sample's position within its pixel, in [0,1)².
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Point2f {
        dispatch!(self, s => s.get_pixel_2d())
    }

    /// pbrt's scene-file name of the sampler type.
    pub fn name(&self) -> &'static str {
        match self {
            Sampler::Independent(_) => "independent",
            Sampler::Stratified(_) => "stratified",
            Sampler::Halton(_) => "halton",
            Sampler::Sobol(_) => "sobol",
            Sampler::PaddedSobol(_) => "paddedsobol",
            Sampler::ZSobol(_) => "zsobol",
            Sampler::Pmj02bn(_) => "pmj02bn",
        }
    }
}
