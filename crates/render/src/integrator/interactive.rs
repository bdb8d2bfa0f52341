//! Interactive rendering (`--interactive`, pbrt-v4's flag; its window is
//! the command line's business, here a browser page): the tile loop run
//! pass after pass, one pass per camera. A pass renders every sample of
//! every pixel; a new camera from the observer
//! ([`RenderObserver::take_camera`]) stops it within a sample, clears the
//! film and starts the next. The scene is built once: only the camera and
//! the film change.
//!
//! What a pass shows, and why:
//! - first a **coarse image**: sample 0 of one pixel in each block of
//!   `block × block`, spread over its block. The block side is chosen so
//!   that this takes about [`COARSE_BUDGET`] (from the last coarse image's
//!   time per pixel, or the last full sample's; before any, from the pixel
//!   count): a full pixel sample of a 400×400 path-traced image takes
//!   about 0.4 s on two cores, too long to wait for after each key press.
//!   Its samples are thrown away.
//! - then **waves** of 1, 1, 2, 4 and then at most [`MAX_WAVE`] samples
//!   per pixel, each shown when it completes: the whole image refines
//!   together rather than tile by tile.
//!
//! The film gets sample 0 of every pixel in one wave (merged into the
//! cleared film, as the ordinary loop's first wave is) and the other
//! samples in tiles kept across the waves, each pixel's samples added in
//! order and merged once at the end, as the ordinary loop's one tile per
//! wave does. So a pass's image is bit for bit the ordinary loop's for
//! the same camera.

use super::render::{
    snapshot, thread_pool, with_progress, write_film, CameraChange, ProgressFn, RenderError,
    RenderObserver, RenderOptions, RenderStats, Snapshot,
};
use super::tile::{tiles, TileIntegrator};
use super::Scene;
use crate::camera::{Camera, CameraSample};
use crate::film::{splat_scale, FilmTile, SplatBuffer};
use crate::image::ImageMetadata;
use crate::primitive::PrimitiveAggregate;
use rpbrt_geometry::bounds::Bounds2i;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// About how long a pass's coarse image should take.
const COARSE_BUDGET: Duration = Duration::from_millis(30);
/// Most samples per pixel one wave takes after the first few.
const MAX_WAVE: i32 = 8;
/// How often a running pass checks for a new camera and for Ctrl-C.
const POLL: Duration = Duration::from_millis(2);
/// How long the loop waits for a camera at a time once a pass is done
/// (it checks for Ctrl-C in between).
const IDLE_WAIT: Duration = Duration::from_millis(100);
/// Pixels the first coarse image takes at most (before any timing).
const FIRST_COARSE_PIXELS: u64 = 16 * 1024;

/// A point picked on the film: the first surface seen through it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pick {
    /// The surface point, in world space.
    pub p_world: Point3f,
    /// Its depth along the camera's viewing axis (camera-space z): the
    /// focal distance that puts it in focus.
    pub depth: Float,
}

/// The first surface `camera`'s ray through film point `p_film` (raster
/// coordinates; lens centre, middle of the shutter) meets in `aggregate`.
pub fn pick(aggregate: &PrimitiveAggregate, camera: &Camera, p_film: Point2f) -> Option<Pick> {
    let base = camera.base();
    let sample = CameraSample {
        p_film,
        p_lens: Point2f::new(0.5, 0.5),
        time: 0.5,
        filter_weight: 1.0,
    };
    let ray = camera.generate_ray(&sample)?.ray;
    let hit = aggregate.intersect(&ray, Float::INFINITY)?;
    let p = ray.at(hit.t_hit);
    let depth = base.camera_from_render(ray.time).apply_point(p).z;
    let p_world = base.camera_transform.world_from_render.apply_point(p);
    Some(Pick { p_world, depth })
}

/// How a pass ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PassEnd {
    /// Every sample taken.
    Complete,
    /// Stopped (a camera or Ctrl-C) with the waves before `spp` whole.
    Stopped { spp: i32 },
}

/// What a pass needs besides the scene.
struct Pass<'a, I> {
    integrator: &'a I,
    opts: &'a RenderOptions,
    pool: &'a rayon::ThreadPool,
    tile_list: &'a [Bounds2i],
    differentials: bool,
    observer: &'a dyn RenderObserver,
    camera: u64,
    done: &'a AtomicU64,
}

/// Renders interactively (see the module docs) until `opts` is
/// interrupted; the image of each completed pass is written to the film's
/// file, and so is the image so far when interrupted mid-pass (the stats
/// say interrupted then).
pub(crate) fn render<I: TileIntegrator>(
    integrator: &I,
    scene: &mut Scene,
    opts: &RenderOptions,
    metadata: &mut ImageMetadata,
    progress: ProgressFn,
    observer: &dyn RenderObserver,
) -> Result<RenderStats, RenderError> {
    if opts.sample_range.is_some()
        || opts.write_partial_images
        || opts.mse_reference.is_some()
        || scene.film.active_bounds() != scene.film.pixel_bounds()
    {
        return Err(RenderError::Unsupported(
            "an interactive render takes the whole image: no sample ranges, tiles, partial images or MSE references".into(),
        ));
    }
    let start = Instant::now();
    let pool = thread_pool(opts)?;
    let spp = scene.sampler.samples_per_pixel().max(1);
    let bounds = scene.film.active_bounds();
    let tile_list = tiles(bounds);
    let pixels = bounds.area().max(0) as u64;
    let differentials =
        scene.film.uses_visible_surface() || scene.materials.any_needs_differentials();
    let mut block = first_block(pixels);
    let mut camera = 0;
    let mut samples = 0;
    // Whether the image last written has all its samples.
    let mut complete = false;
    loop {
        scene.film.reset();
        let stop = Arc::new(AtomicBool::new(false));
        let pass_opts = RenderOptions {
            interrupt: Some(Arc::clone(&stop)),
            observer: None,
            mse_reference: None,
            ..opts.clone()
        };
        let pass_start = Instant::now();
        let over = AtomicBool::new(false);
        let (end, wave0) = std::thread::scope(|threads| {
            threads.spawn(|| {
                while !over.load(Ordering::Relaxed) {
                    if opts.interrupted() || observer.camera_pending() {
                        stop.store(true, Ordering::Relaxed);
                        break;
                    }
                    std::thread::sleep(POLL);
                }
            });
            let total = pixels * spp as u64;
            let r = with_progress(total, pass_start, progress, |done| {
                let pass = Pass {
                    integrator,
                    opts: &pass_opts,
                    pool: &pool,
                    tile_list: &tile_list,
                    differentials,
                    observer,
                    camera,
                    done,
                };
                let r = pass.run(scene, spp, block);
                samples += done.load(Ordering::Relaxed);
                r
            });
            over.store(true, Ordering::Relaxed);
            r
        });
        if let Some(t) = wave0 {
            block = block_for(pixels, t);
        }
        let write = |scene: &Scene, metadata: &mut ImageMetadata, spp: i32| {
            metadata.render_time_seconds = Some(pass_start.elapsed().as_secs_f32());
            metadata.samples_per_pixel = Some(spp);
            write_film(&scene.film, metadata, splat_scale(spp))
        };
        let next = match end {
            PassEnd::Complete => {
                write(scene, metadata, spp)?;
                complete = true;
                let mut s = snapshot(&scene.film, std::iter::empty(), spp, splat_scale(spp), true);
                s.camera = camera;
                observer.image(s);
                wait_for_camera(opts, observer)
            }
            PassEnd::Stopped { spp } if opts.interrupted() => {
                write(scene, metadata, spp)?;
                complete = false;
                // The image written is the last one: a watching page gets it.
                let mut s = snapshot(&scene.film, std::iter::empty(), spp, splat_scale(spp), true);
                s.camera = camera;
                observer.image(s);
                None
            }
            PassEnd::Stopped { .. } => observer.take_camera(Duration::ZERO),
        };
        let Some(change) = next else {
            if opts.interrupted() {
                break;
            }
            // Stopped for a camera that was taken back meanwhile: go on.
            continue;
        };
        scene.set_camera(change.camera);
        camera = change.number;
    }
    Ok(RenderStats {
        render_time: start.elapsed(),
        samples,
        // Ended by Ctrl-C, as interactive renders are; interrupted when the
        // image written lacks samples.
        interrupted: !complete,
        mse_per_wave: Vec::new(),
        warnings: Vec::new(),
    })
}

/// Waits for a camera until one comes (`Some`) or `opts` is interrupted.
fn wait_for_camera(opts: &RenderOptions, observer: &dyn RenderObserver) -> Option<CameraChange> {
    while !opts.interrupted() {
        if let Some(c) = observer.take_camera(IDLE_WAIT) {
            return Some(c);
        }
    }
    None
}

/// The coarse image's block side before any pass was timed: a power of
/// two leaving at most [`FIRST_COARSE_PIXELS`] pixels (1: no coarse image).
fn first_block(pixels: u64) -> i32 {
    let mut b = 1;
    while pixels / (b * b) as u64 > FIRST_COARSE_PIXELS && b < 64 {
        b *= 2;
    }
    b
}

/// The block side (a power of two, at most 64) whose coarse image takes
/// about [`COARSE_BUDGET`] when a full pixel sample of `pixels` pixels
/// takes `wave0`; 1 when the full sample is itself that quick.
fn block_for(pixels: u64, wave0: Duration) -> i32 {
    let ratio = wave0.as_secs_f64() / COARSE_BUDGET.as_secs_f64();
    let mut b = 1;
    while ((b * b) as f64) < ratio && b < 64 && (4 * b * b) as u64 <= pixels {
        b *= 2;
    }
    b
}

impl<I: TileIntegrator> Pass<'_, I> {
    fn stopped(&self) -> bool {
        self.opts.interrupted()
    }

    /// Renders the pass into the cleared film; returns how it ended and an
    /// estimate of how long sample 0 of every pixel takes: from the coarse
    /// image's time per pixel when there was one (what the estimate sizes),
    /// else from the wave that took them all.
    fn run(&self, scene: &mut Scene, spp: i32, block: i32) -> (PassEnd, Option<Duration>) {
        let tc = Instant::now();
        // The time of the coarse image, over the pixels it stands for.
        let mut estimate = None;
        if block > 1 {
            let Some(rgb) = self.coarse(scene, block) else {
                return (PassEnd::Stopped { spp: 0 }, None);
            };
            estimate = Some(tc.elapsed() * (block * block) as u32);
            let d = scene.film.active_bounds().diagonal();
            self.observer.image(Snapshot {
                width: d.x.max(0) as usize,
                height: d.y.max(0) as usize,
                rgb,
                spp: 0,
                done: false,
                camera: self.camera,
            });
        }
        let t0 = Instant::now();
        let fresh = |scene: &Scene| {
            self.tile_list
                .iter()
                .map(|&b| Mutex::new(scene.film.make_tile(b)))
                .collect::<Vec<_>>()
        };
        let first = fresh(scene);
        self.wave(scene, 0..1, &first);
        for t in first {
            scene
                .film
                .merge_tile(&t.into_inner().unwrap_or_else(|e| e.into_inner()));
        }
        if self.stopped() {
            return (PassEnd::Stopped { spp: 0 }, estimate);
        }
        let wave0 = estimate.unwrap_or_else(|| t0.elapsed());
        self.show(scene, &[], 1, spp);
        // Samples 1.. of each pixel, in tiles kept across the waves.
        let rest = fresh(scene);
        let mut end = 1;
        let mut stopped = false;
        while end < spp && !stopped {
            let next = (end + end.min(MAX_WAVE)).min(spp);
            self.wave(scene, end..next, &rest);
            stopped = self.stopped();
            if !stopped {
                end = next;
                if end < spp {
                    self.show(scene, &rest, end, spp);
                }
            }
        }
        for t in rest {
            scene
                .film
                .merge_tile(&t.into_inner().unwrap_or_else(|e| e.into_inner()));
        }
        if stopped {
            (PassEnd::Stopped { spp: end }, Some(wave0))
        } else {
            (PassEnd::Complete, Some(wave0))
        }
    }

    /// Hands the observer the film with `tiles` added, `spp` samples per
    /// pixel (of `total`).
    fn show(&self, scene: &Scene, tiles: &[Mutex<FilmTile>], spp: i32, total: i32) {
        let guards: Vec<_> = tiles
            .iter()
            .map(|t| t.lock().unwrap_or_else(|e| e.into_inner()))
            .collect();
        let mut s = snapshot(
            &scene.film,
            guards.iter().map(|g| &**g),
            spp,
            splat_scale(spp),
            spp == total,
        );
        s.camera = self.camera;
        self.observer.image(s);
    }

    /// Takes samples `samples` of every tile into `tiles` (one per tile of
    /// the list) on the pool; stops early when the pass is stopped.
    fn wave(&self, scene: &Scene, samples: Range<i32>, tiles: &[Mutex<FilmTile>]) {
        let next = AtomicUsize::new(0);
        self.pool.broadcast(|_| {
            let mut sampler = scene.sampler.clone();
            let mut buffers = I::Buffers::default();
            let mut splats = SplatBuffer::new();
            while !self.stopped() {
                let index = next.fetch_add(1, Ordering::Relaxed);
                let (Some(&b), Some(tile)) = (self.tile_list.get(index), tiles.get(index)) else {
                    break;
                };
                let mut tile = tile.lock().unwrap_or_else(|e| e.into_inner());
                super::RayCounters::reset_local();
                let taken = self.integrator.render_tile(
                    scene,
                    self.opts,
                    b,
                    samples.clone(),
                    &mut sampler,
                    &mut tile,
                    &mut splats,
                    self.differentials,
                    &mut buffers,
                );
                scene.counters.flush_local();
                scene
                    .counters
                    .camera_rays
                    .fetch_add(taken, Ordering::Relaxed);
                self.done.fetch_add(taken, Ordering::Relaxed);
            }
        });
    }

    /// The coarse image: sample 0 of the top-left pixel of each
    /// `block × block` block, spread over the block; `None` when stopped.
    fn coarse(&self, scene: &Scene, block: i32) -> Option<Vec<f32>> {
        let bounds = scene.film.active_bounds();
        let (x0, y0) = (bounds.p_min.x, bounds.p_min.y);
        let (x1, y1) = (bounds.p_max.x, bounds.p_max.y);
        let rows: Vec<i32> = (y0..y1).step_by(block as usize).collect();
        let next = AtomicUsize::new(0);
        let finished: Mutex<Vec<FilmTile>> = Mutex::new(Vec::new());
        self.pool.broadcast(|_| {
            let mut sampler = scene.sampler.clone();
            let mut buffers = I::Buffers::default();
            let mut splats = SplatBuffer::new();
            while !self.stopped() {
                let Some(&y) = rows.get(next.fetch_add(1, Ordering::Relaxed)) else {
                    break;
                };
                let row = Bounds2i::new(Point2i::new(x0, y), Point2i::new(x1, y + 1));
                let mut tile = scene.film.make_tile(row);
                for x in (x0..x1).step_by(block as usize) {
                    let p = Bounds2i::new(Point2i::new(x, y), Point2i::new(x + 1, y + 1));
                    self.integrator.render_tile(
                        scene,
                        self.opts,
                        p,
                        0..1,
                        &mut sampler,
                        &mut tile,
                        &mut splats,
                        self.differentials,
                        &mut buffers,
                    );
                }
                finished
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(tile);
            }
        });
        if self.stopped() {
            return None;
        }
        let rows = finished.into_inner().unwrap_or_else(|e| e.into_inner());
        let mut rgb = scene.film.rgb_snapshot(rows.iter(), 1.0);
        let width = (x1 - x0) as usize;
        let b = block as usize;
        for y in 0..(y1 - y0) as usize {
            for x in 0..width {
                let from = 3 * ((y / b * b) * width + x / b * b);
                let to = 3 * (y * width + x);
                if from != to {
                    rgb.copy_within(from..from + 3, to);
                }
            }
        }
        Some(rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coarse_blocks_follow_the_pixel_count_then_the_timing() {
        assert_eq!(first_block(64 * 64), 1);
        assert_eq!(first_block(400 * 400), 4);
        assert_eq!(first_block(1920 * 1080), 16);
        // A full sample within the budget needs no coarse image; 16 times
        // the budget needs blocks of 4.
        assert_eq!(block_for(400 * 400, COARSE_BUDGET / 2), 1);
        assert_eq!(block_for(400 * 400, COARSE_BUDGET * 16), 4);
        assert_eq!(block_for(400 * 400, COARSE_BUDGET * 17), 8);
        assert_eq!(block_for(400 * 400, COARSE_BUDGET * 100_000), 64);
        // Never blocks bigger than the image.
        assert!(block_for(4, COARSE_BUDGET * 100) <= 2);
    }
}
