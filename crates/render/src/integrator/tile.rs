//! The tile loop of the per-ray integrators (pbrt-v4 `ImageTileIntegrator::Render`
//! and `RayIntegrator::EvaluatePixelSample`, `cpu/integrators.cpp`; book
//! section 1.3.4): image tiles rendered in parallel, samples taken in waves:
//! pbrt-v4's doubling waves when partial images or per-wave MSE are asked
//! for, otherwise one sample per pixel and then the rest. Ctrl-C is checked
//! at every pixel; progress is counted per tile. An observer
//! ([`RenderOptions::observer`]) may take snapshots after any tile: the
//! film of the completed waves with the running wave's finished tiles.
//!
//! The loop is generic over the [`TileIntegrator`]: each integrator gets
//! its own copy, with its per-sample work called directly.

use super::camera_samples::CameraRaySample;
use super::render::{
    snapshot, thread_pool, with_progress, write_film, write_partial, ProgressFn, RenderError,
    RenderOptions, RenderStats,
};
use super::Scene;
use crate::film::{
    splat_scale, FilmTile, OrderedSplats, PartialError, SplatBuffer, VisibleSurface,
};
use crate::image::ImageMetadata;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::bounds::Bounds2i;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;
use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// An integrator that estimates the radiance along one camera ray at a
/// time (pbrt-v4 `RayIntegrator`), rendered by [`render_tiles`].
pub trait RayIntegrator: Sync {
    /// The radiance arriving along `ray` for the sampled wavelengths
    /// (pbrt-v4 `RayIntegrator::Li`). `visible`, when given, receives the
    /// first visible surface (for G-buffer films); integrators that do not
    /// record it leave it unset.
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum;
}

/// Side of the square tiles the image is split into.
const TILE_SIZE: i32 = 16;

pub(crate) fn tiles(bounds: Bounds2i) -> Vec<Bounds2i> {
    let mut out = Vec::new();
    let mut y = bounds.p_min.y;
    while y < bounds.p_max.y {
        let mut x = bounds.p_min.x;
        while x < bounds.p_max.x {
            out.push(Bounds2i::new(
                Point2i::new(x, y),
                Point2i::new(
                    (x + TILE_SIZE).min(bounds.p_max.x),
                    (y + TILE_SIZE).min(bounds.p_max.y),
                ),
            ));
            x += TILE_SIZE;
        }
        y += TILE_SIZE;
    }
    out
}

/// An integrator driven by the tile loop, one pixel sample at a time
/// (pbrt-v4 `ImageTileIntegrator::EvaluatePixelSample`). Per-ray
/// integrators get this through [`RayTiles`]; integrators that splat
/// (light tracing, bdpt) implement it themselves and record their splats
/// in the tile's [`SplatBuffer`], which the loop applies to the film in
/// tile order.
pub trait TileIntegrator: Sync {
    /// What a worker thread keeps from one [`TileIntegrator::render_tile`]
    /// to the next (the wavefront's pool of paths and its columns, whose
    /// allocation per tile cost page faults and zero-filling).
    type Buffers: Default;

    /// Takes sample `sampler` (already started for this pixel and sample
    /// index) of pixel `p_pixel`: adds to `tile` and/or records splats.
    /// `differentials`: whether camera rays need their differentials.
    #[allow(clippy::too_many_arguments)]
    fn evaluate_pixel_sample(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        p_pixel: Point2i,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        splats: &mut SplatBuffer,
        differentials: bool,
    );

    /// Films besides the render's that splats may go to (film index k ≥ 1
    /// of [`SplatBuffer::add_to`] is `extra_films()[k - 1]`).
    fn extra_films(&self) -> &[crate::film::Film] {
        &[]
    }

    /// Takes samples `samples` of every pixel of `bounds`, pixel by pixel
    /// in `bounds.iter()` order and each pixel's samples in order, adding
    /// them to `tile` (splats to `splats`); returns the camera samples
    /// taken. Stops early, between samples, once `opts` is interrupted:
    /// every sample taken is whole. The default takes one sample at a time
    /// ([`TileIntegrator::evaluate_pixel_sample`]); the wavefront path
    /// tracer takes many at once, adding them to the tile in the same
    /// order.
    #[allow(clippy::too_many_arguments)]
    fn render_tile(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        bounds: Bounds2i,
        samples: Range<i32>,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        splats: &mut SplatBuffer,
        differentials: bool,
        buffers: &mut Self::Buffers,
    ) -> u64 {
        let _ = buffers;
        let mut taken = 0;
        for p in bounds.iter() {
            for s in samples.clone() {
                // Checked per sample: one pixel's samples can take minutes.
                if opts.interrupted() {
                    return taken;
                }
                sampler.start_pixel_sample(p, s, 0);
                self.evaluate_pixel_sample(scene, opts, p, sampler, tile, splats, differentials);
                taken += 1;
            }
        }
        taken
    }
}

/// A [`RayIntegrator`] as a [`TileIntegrator`].
pub(crate) struct RayTiles<'a, I>(pub &'a I);

impl<I: RayIntegrator> TileIntegrator for RayTiles<'_, I> {
    type Buffers = ();

    #[inline]
    fn evaluate_pixel_sample(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        p_pixel: Point2i,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        _splats: &mut SplatBuffer,
        differentials: bool,
    ) {
        let cs = CameraRaySample::take(scene, opts, p_pixel, sampler, differentials);
        cs.finish(scene, tile, |ray, lambda, visible| {
            self.0.li(scene, ray, lambda, sampler, visible)
        });
    }
}

/// Adds a camera sample's radiance estimate `l` (already multiplied by
/// the camera ray's weight) to `tile`: NaN and infinite estimates are
/// dropped, as pbrt-v4 does (and logs them), and `visible` counts only
/// when something set it.
#[inline]
pub(crate) fn add_estimate(
    tile: &mut FilmTile,
    p_pixel: Point2i,
    mut l: SampledSpectrum,
    lambda: &SampledWavelengths,
    visible: Option<&VisibleSurface>,
    filter_weight: Float,
) {
    if l.has_nan() || !l.y(lambda).is_finite() {
        l = SampledSpectrum::new(0.0);
    }
    tile.add_sample(p_pixel, l, lambda, visible.filter(|v| v.set), filter_weight);
}

/// The samples of the wave after `[start, end)`: pbrt-v4's schedule,
/// doubling waves of at most 64 samples, when something happens between
/// waves (partial images, MSE against a reference); otherwise everything
/// left in one wave. A wave revisits every pixel, and the Z-Sobol sampler's
/// caches start over on each pixel it moves to, so fewer waves are faster;
/// the first wave of one sample per pixel is kept either way, so that an
/// interrupted render has every pixel.
fn next_wave(end: i32, wave_size: i32, spp: i32, progressive: bool) -> (i32, i32) {
    if progressive {
        ((end + wave_size).min(spp), (2 * wave_size).min(64))
    } else {
        (spp, wave_size)
    }
}

/// Renders `scene` with `integrator` tile by tile, writing the film's image
/// (and partial images when asked). `metadata` is completed with timing and
/// sample counts; `progress` hears of the camera samples taken.
///
/// Worker threads take tiles in index order from a shared counter; each
/// tile's splats are applied in tile order ([`OrderedSplats`]), so few wait
/// and the image does not depend on the thread count.
pub(crate) fn render_tiles<I: TileIntegrator>(
    integrator: &I,
    scene: &mut Scene,
    opts: &RenderOptions,
    metadata: &mut ImageMetadata,
    progress: ProgressFn,
) -> Result<RenderStats, RenderError> {
    if let Some(o) = opts.observer.as_deref().filter(|o| o.interactive()) {
        return super::interactive::render(integrator, scene, opts, metadata, progress, o);
    }
    let start = Instant::now();
    let pool = thread_pool(opts)?;
    let spp = scene.sampler.samples_per_pixel().max(1);
    // The samples of every pixel this render takes: all, or a range of
    // them (`--spp-range`) with the same sampler indices.
    let (first, last) = match opts.sample_range {
        Some(r) => {
            let r = r.check(spp).map_err(RenderError::Partial)?;
            (r.start, r.end)
        }
        None => (0, spp),
    };
    let pixel_bounds = scene.film.active_bounds();
    let tile_list = tiles(pixel_bounds);
    let pixels = pixel_bounds.area().max(0) as u64;
    let total = pixels * (last - first) as u64;
    // Camera rays carry differentials only when something reads them:
    // texture filtering or bump mapping, or a G-buffer film's depth slopes.
    let differentials =
        scene.film.uses_visible_surface() || scene.materials.any_needs_differentials();
    let progressive = opts.write_partial_images || opts.mse_reference.is_some();
    let mut wave_start = first;
    let mut wave_end = first + 1;
    let mut next_wave_size = 1;
    let mut interrupted = false;
    let mut mse_per_wave = Vec::new();
    // `samples_done`: samples taken so far, counted by the tiles as they
    // finish (the progress reporter reads it while a wave runs).
    let done = with_progress(total, start, progress, |samples_done| {
        while wave_start < last {
            let next_tile = AtomicUsize::new(0);
            let finished: Mutex<Vec<(usize, FilmTile)>> = Mutex::new(Vec::new());
            let splats = OrderedSplats::new();
            {
                let scene_ref: &Scene = scene;
                let mut targets = vec![&scene_ref.film];
                targets.extend(integrator.extra_films());
                let targets = &targets;
                let work = || {
                    let mut sampler = scene_ref.sampler.clone();
                    let mut buffers = I::Buffers::default();
                    loop {
                        let index = next_tile.fetch_add(1, Ordering::Relaxed);
                        let Some(&b) = tile_list.get(index) else {
                            break;
                        };
                        let mut tile = scene_ref.film.make_tile(b);
                        let mut tile_splats = splats.buffer();
                        super::RayCounters::reset_local();
                        let camera_rays = integrator.render_tile(
                            scene_ref,
                            opts,
                            b,
                            wave_start..wave_end,
                            &mut sampler,
                            &mut tile,
                            &mut tile_splats,
                            differentials,
                            &mut buffers,
                        );
                        scene_ref.counters.flush_local();
                        scene_ref
                            .counters
                            .camera_rays
                            .fetch_add(camera_rays, Ordering::Relaxed);
                        samples_done.fetch_add(camera_rays, Ordering::Relaxed);
                        splats.submit(targets, index, tile_splats);
                        finished
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .push((index, tile));
                        if let Some(o) = opts.observer_wanting(false) {
                            // Splats so far: those of the completed waves
                            // and of the tiles applied in this one.
                            let applied = splats.applied() as f64 / tile_list.len().max(1) as f64;
                            let spp_now = (wave_start - first) as f64
                                + (wave_end - wave_start) as f64 * applied;
                            let scale = if spp_now > 0.0 {
                                (1.0 / spp_now) as Float
                            } else {
                                1.0
                            };
                            let done = finished.lock().unwrap_or_else(|e| e.into_inner());
                            let tiles = done.iter().map(|(_, t)| t);
                            let spp = wave_start - first;
                            o.image(snapshot(&scene_ref.film, tiles, spp, scale, false));
                        }
                    }
                };
                pool.broadcast(|_| work());
            }
            let mut results = finished.into_inner().unwrap_or_else(|e| e.into_inner());
            results.sort_unstable_by_key(|(i, _)| *i);
            for (_, t) in &results {
                scene.film.merge_tile(t);
            }
            if opts.interrupted() {
                interrupted = true;
                break;
            }
            wave_start = wave_end;
            (wave_end, next_wave_size) = next_wave(wave_end, next_wave_size, last, progressive);
            if wave_start < last {
                if let Some(o) = opts.observer_wanting(true) {
                    let none = std::iter::empty();
                    let scale = splat_scale(wave_start - first);
                    o.image(snapshot(
                        &scene.film,
                        none,
                        wave_start - first,
                        scale,
                        false,
                    ));
                }
            }
            if let Some(reference) = &opts.mse_reference {
                let mut md = ImageMetadata::default();
                let image = scene
                    .film
                    .get_image(&mut md, splat_scale(wave_start - first));
                let d = crate::image::ops::diff(&image, reference)
                    .map_err(RenderError::MseReference)?;
                mse_per_wave.push((wave_start, d.mse));
            }
            if opts.write_partial_images && wave_start < last {
                metadata.render_time_seconds = Some(start.elapsed().as_secs_f32());
                metadata.samples_per_pixel = Some(wave_start - first);
                write_film(&scene.film, metadata, splat_scale(wave_start - first))?;
            }
        }
        Ok(samples_done.load(Ordering::Relaxed))
    })?;
    let render_time = start.elapsed();
    metadata.render_time_seconds = Some(render_time.as_secs_f32());
    // Every pixel has at least the samples of the completed waves.
    metadata.samples_per_pixel = Some(wave_start - first);
    if let Some(&(_, mse)) = mse_per_wave.last() {
        metadata.mse = Some(mse as f32);
    }
    opts.observe_final(
        &scene.film,
        wave_start - first,
        splat_scale(wave_start - first),
    );
    if let Some(range) = opts.sample_range {
        if interrupted {
            // The interrupted wave's samples are in the sums: they would
            // not merge exactly with any other range.
            return Err(RenderError::Partial(PartialError(format!(
                "interrupted: the partial image of samples {}..{} is incomplete and was not written",
                range.start, range.end
            ))));
        }
        write_partial(&scene.film, metadata, range, spp)?;
    } else {
        // An interrupted wave's splats are partial: the scale of the
        // completed waves keeps them at most slightly bright, as pbrt-v4's.
        write_film(&scene.film, metadata, splat_scale(wave_start - first))?;
    }
    Ok(RenderStats {
        render_time,
        samples: done,
        interrupted,
        mse_per_wave,
        warnings: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::next_wave;

    /// The waves as `[start, end)` ranges for `spp` samples per pixel.
    fn waves(spp: i32, progressive: bool) -> Vec<(i32, i32)> {
        let (mut start, mut end, mut size) = (0, 1, 1);
        let mut out = Vec::new();
        while start < spp {
            out.push((start, end));
            start = end;
            (end, size) = next_wave(end, size, spp, progressive);
        }
        out
    }

    #[test]
    fn progressive_waves_double_as_in_pbrt_v4() {
        assert_eq!(
            waves(64, true),
            [(0, 1), (1, 2), (2, 4), (4, 8), (8, 16), (16, 32), (32, 64)]
        );
        // At most 64 samples a wave.
        let w = waves(300, true);
        assert!(w.iter().all(|&(a, b)| b - a <= 64));
        assert_eq!(w.last(), Some(&(256, 300)));
        assert_eq!(waves(1, true), [(0, 1)]);
    }

    #[test]
    fn other_renders_take_one_sample_then_the_rest() {
        assert_eq!(waves(64, false), [(0, 1), (1, 64)]);
        assert_eq!(waves(1000, false), [(0, 1), (1, 1000)]);
        assert_eq!(waves(1, false), [(0, 1)]);
        assert_eq!(waves(2, false), [(0, 1), (1, 2)]);
    }
}
