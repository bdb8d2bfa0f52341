//! Camera samples (pbrt-v4 `GetCameraSample` and the ray generation that
//! follows): a pixel sample's wavelengths, film position and camera ray,
//! one at a time for the per-ray loops, or a batch at a time for the
//! wavefront ([`CameraBatch`]), whose filter table searches are
//! interleaved and whose pinhole rays are generated lane-parallel, with
//! the same values.

use super::render::RenderOptions;
use super::tile::add_estimate;
use super::Scene;
use crate::camera::{CameraSample, OffsetRays, PinholeRays};
use crate::film::{FilmTile, VisibleSurface};
use crate::filter::FilterSample;
use crate::sampler::Sampler;
use crate::simd::SimdLevel;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// A camera sample's draws, in pbrt-v4's order: the wavelengths' 1-D,
/// the film position's 2-D, the time's 1-D and the lens's 2-D.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraDraws {
    pub lu: Float,
    pub u_pixel: Point2f,
    pub time: Float,
    pub p_lens: Point2f,
}

impl CameraDraws {
    /// Takes the draws from `sampler`.
    #[inline]
    pub(crate) fn take(sampler: &mut Sampler) -> Self {
        Self::from_four(sampler.get_camera_samples())
    }

    /// The draws from [`Sampler::get_camera_samples`]' four values (or
    /// the same values computed ahead).
    #[inline]
    pub(crate) fn from_four((lu, u_pixel, time, p_lens): (Float, Point2f, Float, Point2f)) -> Self {
        CameraDraws {
            lu,
            u_pixel,
            time,
            p_lens,
        }
    }
}

/// How far camera ray differentials reach at `spp` samples per pixel
/// (pbrt-v4: 1/√spp, at least 1/8).
#[inline]
pub(crate) fn differential_scale(spp: i32) -> Float {
    (1.0 / (spp as Float).sqrt()).max(0.125)
}

/// The wavelengths for the draw `lu` (the middle of the film's range when
/// wavelength jitter is off).
#[inline]
fn sample_wavelengths(scene: &Scene, opts: &RenderOptions, lu: Float) -> SampledWavelengths {
    scene.film.sample_wavelengths(wavelength_draw(opts, lu))
}

/// The draw the wavelengths take: `lu`, or 0.5 when wavelength jitter is
/// off.
#[inline]
fn wavelength_draw(opts: &RenderOptions, lu: Float) -> Float {
    if opts.disable_wavelength_jitter {
        0.5
    } else {
        lu
    }
}

/// The camera sample in pixel `p_pixel` at filter offset `fs` (the pixel
/// centre, weight 1, when pixel jitter is off).
#[inline]
fn camera_sample(
    opts: &RenderOptions,
    p_pixel: Point2i,
    mut fs: FilterSample,
    time: Float,
    p_lens: Point2f,
) -> CameraSample {
    if opts.disable_pixel_jitter {
        fs.p = Point2f::new(0.0, 0.0);
        fs.weight = 1.0;
    }
    CameraSample {
        p_film: Point2f::new(
            p_pixel.x as Float + fs.p.x + 0.5,
            p_pixel.y as Float + fs.p.y + 0.5,
        ),
        p_lens,
        time,
        filter_weight: fs.weight,
    }
}

/// The film position of a camera sample in pixel `p_pixel` (the filter
/// sampled with `u_pixel`) and the camera ray through it, with
/// differentials scaled by `diff_scale` when `differentials` asks for
/// them (pbrt-v4 `GetCameraSample` and the ray generation that follows).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn camera_ray(
    scene: &Scene,
    opts: &RenderOptions,
    p_pixel: Point2i,
    u_pixel: Point2f,
    time: Float,
    p_lens: Point2f,
    differentials: bool,
    diff_scale: Float,
) -> (CameraSample, Option<(RayDifferential, Float)>) {
    let cs = camera_sample(opts, p_pixel, scene.filter.sample(u_pixel), time, p_lens);
    (cs, ray_for(scene, opts, &cs, differentials, diff_scale))
}

/// The camera ray for `cs` and its weight, with differentials when
/// `differentials` asks for them.
#[inline]
fn ray_for(
    scene: &Scene,
    opts: &RenderOptions,
    cs: &CameraSample,
    differentials: bool,
    diff_scale: Float,
) -> Option<(RayDifferential, Float)> {
    if differentials {
        scene.camera.generate_ray_differential(cs).map(|mut cr| {
            if !opts.disable_pixel_jitter {
                cr.ray.scale_differentials(diff_scale);
            }
            (cr.ray, cr.weight)
        })
    } else {
        // Nothing reads them: the same main ray without its offset rays.
        scene
            .camera
            .generate_ray(cs)
            .map(|cr| (RayDifferential::new(cr.ray), cr.weight))
    }
}

/// One camera sample through one pixel: its wavelengths, film position
/// and camera ray (pbrt-v4 `RayIntegrator::EvaluatePixelSample`'s first
/// half).
pub(crate) struct CameraRaySample {
    /// The pixel.
    pub p_pixel: Point2i,
    /// The sampled wavelengths.
    pub lambda: SampledWavelengths,
    /// The film position, time, lens sample and filter weight.
    pub cs: CameraSample,
    /// The camera ray and its weight (`None` when the camera makes none).
    pub ray: Option<(RayDifferential, Float)>,
}

impl CameraRaySample {
    /// Draws the camera sample's dimensions from `sampler` in pbrt-v4's
    /// order and generates the ray.
    #[inline]
    pub(crate) fn take(
        scene: &Scene,
        opts: &RenderOptions,
        p_pixel: Point2i,
        sampler: &mut Sampler,
        differentials: bool,
    ) -> Self {
        let d = CameraDraws::take(sampler);
        let lambda = sample_wavelengths(scene, opts, d.lu);
        let scale = differential_scale(sampler.samples_per_pixel());
        let (cs, ray) = camera_ray(
            scene,
            opts,
            p_pixel,
            d.u_pixel,
            d.time,
            d.p_lens,
            differentials,
            scale,
        );
        CameraRaySample {
            p_pixel,
            lambda,
            cs,
            ray,
        }
    }

    /// Estimates the radiance along the ray with `li` and adds it to the
    /// tile (zero when there is no ray; NaN and infinite estimates are
    /// dropped, as pbrt-v4 does).
    #[inline]
    pub(crate) fn finish(
        mut self,
        scene: &Scene,
        tile: &mut FilmTile,
        li: impl FnOnce(
            RayDifferential,
            &mut SampledWavelengths,
            Option<&mut VisibleSurface>,
        ) -> SampledSpectrum,
    ) {
        let mut l = SampledSpectrum::new(0.0);
        // Only G-buffer films record the first visible surface.
        let mut visible: Option<VisibleSurface> = if scene.film.uses_visible_surface() {
            Some(VisibleSurface::default())
        } else {
            None
        };
        if let Some((ray, weight)) = self.ray {
            l = li(ray, &mut self.lambda, visible.as_mut()) * weight;
        }
        add_estimate(
            tile,
            self.p_pixel,
            l,
            &self.lambda,
            visible.as_ref(),
            self.cs.filter_weight,
        );
    }
}

/// The camera samples of many pixel samples at once: what
/// [`CameraRaySample::take`] gives for each, bit for bit, with the filter
/// table's searches interleaved ([`crate::filter::Filter::sample_many`])
/// and, for a pinhole camera, the rays (with their differentials where
/// asked) generated lane-parallel ([`PinholeRays`]). Holds the buffers
/// between batches.
pub(crate) struct CameraBatch {
    pinhole: Option<PinholeRays>,
    u_pixel: Vec<Point2f>,
    filter: Vec<FilterSample>,
    p_film: Vec<Point2f>,
    times: Vec<Float>,
    rays: Vec<RayDifferential>,
    lu: Vec<Float>,
    lambda_scratch: Vec<Float>,
    lambdas: Vec<SampledWavelengths>,
}

impl CameraBatch {
    /// Buffers for `scene`'s camera.
    pub(crate) fn new(scene: &Scene) -> Self {
        CameraBatch {
            pinhole: scene.camera.pinhole_rays(),
            u_pixel: Vec::new(),
            filter: Vec::new(),
            p_film: Vec::new(),
            times: Vec::new(),
            rays: Vec::new(),
            lu: Vec::new(),
            lambda_scratch: Vec::new(),
            lambdas: Vec::new(),
        }
    }

    /// The camera samples of `samples` (each a pixel and its draws), in
    /// order, into `out`; `diff_scale` is [`differential_scale`] of the
    /// sampler's count.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn take(
        &mut self,
        scene: &Scene,
        opts: &RenderOptions,
        level: SimdLevel,
        samples: &[(Point2i, CameraDraws)],
        differentials: bool,
        diff_scale: Float,
        out: &mut Vec<CameraRaySample>,
    ) {
        out.clear();
        self.u_pixel.clear();
        self.u_pixel.extend(samples.iter().map(|(_, d)| d.u_pixel));
        self.filter.clear();
        scene.filter.sample_many(&self.u_pixel, &mut self.filter);
        self.lu.clear();
        self.lu
            .extend(samples.iter().map(|(_, d)| wavelength_draw(opts, d.lu)));
        scene.film.sample_wavelengths_many(
            level,
            &self.lu,
            &mut self.lambda_scratch,
            &mut self.lambdas,
        );
        out.extend(samples.iter().zip(&self.filter).zip(&self.lambdas).map(
            |((&(p_pixel, d), &fs), &lambda)| CameraRaySample {
                p_pixel,
                lambda,
                cs: camera_sample(opts, p_pixel, fs, d.time, d.p_lens),
                ray: None,
            },
        ));
        match self.pinhole.as_ref() {
            Some(pinhole) => {
                self.p_film.clear();
                self.p_film.extend(out.iter().map(|s| s.cs.p_film));
                self.times.clear();
                self.times
                    .extend(out.iter().map(|s| scene.camera.sample_time(s.cs.time)));
                // `ray_for`'s offset rays.
                let offsets = match (differentials, opts.disable_pixel_jitter) {
                    (false, _) => OffsetRays::None,
                    (true, true) => OffsetRays::Unscaled,
                    (true, false) => OffsetRays::Scaled(diff_scale),
                };
                self.rays.clear();
                pinhole.rays(level, &self.p_film, &self.times, offsets, &mut self.rays);
                for (s, &r) in out.iter_mut().zip(&self.rays) {
                    s.ray = Some((r, 1.0));
                }
            }
            None => {
                for s in out.iter_mut() {
                    s.ray = ray_for(scene, opts, &s.cs, differentials, diff_scale);
                }
            }
        }
    }
}
