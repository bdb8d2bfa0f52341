//! Metropolis light transport in primary sample space over bdpt (pbrt-v4
//! `MLTIntegrator`, `cpu/integrators.cpp`; book section 16.4 of the third
//! edition). Bootstrap paths of every length estimate the image's total
//! brightness `b` and seed the chains; each chain mutates its path's
//! primary samples (large and small steps) and splats both the current and
//! the proposed path, weighted by the acceptance probability.
//!
//! Determinism: bootstrap paths and chains are keyed by their indices
//! only, chains run in parallel and their splats are applied in chain
//! order ([`OrderedSplats`]), so the image does not depend on the thread
//! count.

mod sampler;

use super::bdpt::{
    connect_bdpt, generate_camera_subpath, generate_light_subpath, Vertex, WalkOptions,
};
use super::render::{
    snapshot, thread_pool, with_progress, write_film, ProgressFn, RenderError, RenderOptions,
    RenderStats,
};
use super::Scene;
use crate::camera::CameraSample;
use crate::film::OrderedSplats;
use crate::image::ImageMetadata;
use crate::rng::{mix_bits, Rng};
use crate::sampler::SampleSource;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use sampler::MltSampler;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// pbrt-v4's `mlt` integrator.
#[derive(Clone, Debug)]
pub struct MltIntegrator {
    /// Maximum number of scattering events of a path.
    pub max_depth: i32,
    /// Bootstrap paths per path length.
    pub bootstrap_samples: i32,
    /// Markov chains.
    pub chains: i32,
    /// Mutations per pixel (the sampler's pixel samples override it when
    /// given on the command line, as pbrt-v4's `--spp`).
    pub mutations_per_pixel: i32,
    /// Probability of a large step.
    pub large_step_probability: Float,
    /// Standard deviation of small steps.
    pub sigma: Float,
    /// Roughen near-specular BSDFs after the first non-specular bounce.
    pub regularize: bool,
    /// The seed (`--seed`).
    pub seed: u64,
}

/// The three primary-sample streams (pbrt-v4's camera, light and
/// connection streams).
const CAMERA_STREAM: usize = 0;
const LIGHT_STREAM: usize = 1;
const CONNECTION_STREAM: usize = 2;
const N_STREAMS: usize = 3;

/// The scalar contribution the chains are distributed by (pbrt-v4 `c`).
#[inline]
fn contribution(l: &SampledSpectrum, lambda: &SampledWavelengths) -> Float {
    let c = l.y(lambda);
    if c.is_finite() {
        c.max(0.0)
    } else {
        0.0
    }
}

impl MltIntegrator {
    /// The path of length `depth` the primary samples describe: its
    /// strategy, wavelengths, radiance (times the strategy count) and
    /// raster position (pbrt-v4 `MLTIntegrator::L`).
    fn l(
        &self,
        scene: &Scene,
        sampler: &mut MltSampler,
        depth: usize,
        paths: &mut (Vec<Vertex>, Vec<Vertex>),
    ) -> (SampledSpectrum, Point2f, SampledWavelengths) {
        let zero = SampledSpectrum::new(0.0);
        sampler.start_stream(CAMERA_STREAM);
        let (s, t, n_strategies) = if depth == 0 {
            (0, 2, 1)
        } else {
            let n = depth + 2;
            let s = ((sampler.get_1d() * n as Float) as usize).min(n - 1);
            (s, n - s, n)
        };
        let mut lambda = scene.film.sample_wavelengths(sampler.get_1d());
        let sample_bounds = scene.film.sample_bounds();
        let u = sampler.get_2d();
        let p_raster = sample_bounds.lerp(u);
        let cs = CameraSample {
            p_film: p_raster,
            p_lens: Point2f::default(),
            time: sampler.get_1d(),
            filter_weight: 1.0,
        };
        let cs = CameraSample {
            p_lens: sampler.get_2d(),
            ..cs
        };
        if scene.lights.is_empty() {
            return (zero, p_raster, lambda);
        }
        let Some(mut crd) = scene.camera.generate_ray_differential(&cs) else {
            return (zero, p_raster, lambda);
        };
        if crd.weight == 0.0 {
            return (zero, p_raster, lambda);
        }
        let scale = (1.0 / (self.mutations_per_pixel.max(1) as Float).sqrt()).max(0.125);
        crd.ray.scale_differentials(scale);
        let opts = WalkOptions {
            regularize: self.regularize,
        };
        let (camera, light) = paths;
        if generate_camera_subpath(scene, crd.ray, &mut lambda, sampler, t, opts, camera) != t {
            return (zero, p_raster, lambda);
        }
        sampler.start_stream(LIGHT_STREAM);
        let time = camera[0].time;
        if generate_light_subpath(scene, &mut lambda, sampler, s, time, opts, light) != s {
            return (zero, p_raster, lambda);
        }
        sampler.start_stream(CONNECTION_STREAM);
        let c = connect_bdpt(scene, &lambda, light, camera, s, t, sampler);
        let p = c.p_raster.unwrap_or(p_raster);
        (c.l * n_strategies as Float, p, lambda)
    }
}

/// Renders with MLT (pbrt-v4 `MLTIntegrator::Render`).
pub(crate) fn render(
    integrator: &MltIntegrator,
    scene: &mut Scene,
    opts: &RenderOptions,
    metadata: &mut ImageMetadata,
    progress: ProgressFn,
) -> Result<RenderStats, RenderError> {
    let start = Instant::now();
    let pool = thread_pool(opts)?;
    let it = integrator;
    let max_depth = it.max_depth.max(0) as usize;
    let n_bootstrap = it.bootstrap_samples.max(1) as usize;
    let n_chains = it.chains.max(1) as usize;
    let mutations_per_pixel = it.mutations_per_pixel.max(1) as u64;
    let n_bootstrap_samples = n_bootstrap * (max_depth + 1);
    let sample_area = scene.film.sample_bounds().area().max(0.0) as u64;
    let n_total_mutations = sample_area * mutations_per_pixel;
    let total = n_bootstrap_samples as u64 + n_total_mutations;
    let scene_ref: &Scene = scene;
    let result: Result<(u64, f64), RenderError> = with_progress(total, start, progress, |done| {
        // Bootstrap: every path length, in parallel, keyed by index.
        let weights: Vec<Float> = pool.install(|| {
            (0..n_bootstrap)
                .into_par_iter()
                .flat_map_iter(|i| {
                    let mut paths = (Vec::new(), Vec::new());
                    let w: Vec<Float> = (0..=max_depth)
                        .map(|depth| {
                            let index = i * (max_depth + 1) + depth;
                            let mut sampler = MltSampler::new(
                                index as u64,
                                it.seed,
                                it.sigma,
                                it.large_step_probability,
                                N_STREAMS,
                            );
                            let (l, _, lambda) = it.l(scene_ref, &mut sampler, depth, &mut paths);
                            contribution(&l, &lambda)
                        })
                        .collect();
                    done.fetch_add(w.len() as u64, Ordering::Relaxed);
                    w
                })
                .collect()
        });
        let sum: f64 = weights.iter().map(|&w| w as f64).sum();
        if sum == 0.0 {
            // Nothing to distribute: pbrt-v4 stops with "No light carrying
            // paths found"; a black image says the same without failing.
            return Ok((0u64, 0.0));
        }
        let b = (max_depth + 1) as f64 / weights.len() as f64 * sum;
        // The bootstrap paths' cumulative distribution.
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0f64;
        for &w in &weights {
            acc += w as f64;
            cdf.push(acc / sum);
        }
        let splats = OrderedSplats::new();
        let snapshot_lock = std::sync::Mutex::new(());
        let next_chain = AtomicUsize::new(0);
        let mutations_done = std::sync::atomic::AtomicU64::new(0);
        let films = [&scene_ref.film];
        pool.broadcast(|_| {
            let mut paths = (Vec::new(), Vec::new());
            loop {
                let i = next_chain.fetch_add(1, Ordering::Relaxed);
                if i >= n_chains || opts.interrupted() {
                    break;
                }
                let n = n_chains as u64;
                let i64_ = i as u64;
                let n_chain_mutations = ((i64_ + 1) * n_total_mutations / n).min(n_total_mutations)
                    - i64_ * n_total_mutations / n;
                let mut rng = Rng::new(i as u64, mix_bits(i as u64));
                let u = rng.uniform_float() as f64;
                let bootstrap_index = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
                let depth = bootstrap_index % (max_depth + 1);
                let mut sampler = MltSampler::new(
                    bootstrap_index as u64,
                    it.seed,
                    it.sigma,
                    it.large_step_probability,
                    N_STREAMS,
                );
                let mut buf = splats.buffer();
                let (mut l_cur, mut p_cur, mut lambda_cur) =
                    it.l(scene_ref, &mut sampler, depth, &mut paths);
                let mut c_cur = contribution(&l_cur, &lambda_cur);
                let mut taken = 0u64;
                for _ in 0..n_chain_mutations {
                    sampler.start_iteration();
                    let (l_prop, p_prop, lambda_prop) =
                        it.l(scene_ref, &mut sampler, depth, &mut paths);
                    let c_prop = contribution(&l_prop, &lambda_prop);
                    let accept = if c_cur > 0.0 {
                        (c_prop / c_cur).min(1.0)
                    } else {
                        1.0
                    };
                    if accept > 0.0 {
                        buf.add(p_prop, l_prop * (accept / c_prop), &lambda_prop);
                    }
                    if c_cur > 0.0 {
                        buf.add(p_cur, l_cur * ((1.0 - accept) / c_cur), &lambda_cur);
                    }
                    if rng.uniform_float() < accept {
                        p_cur = p_prop;
                        l_cur = l_prop;
                        lambda_cur = lambda_prop;
                        c_cur = c_prop;
                        sampler.accept();
                    } else {
                        sampler.reject();
                    }
                    taken += 1;
                    if taken.is_multiple_of(4096) {
                        done.fetch_add(4096, Ordering::Relaxed);
                    }
                }
                done.fetch_add(taken % 4096, Ordering::Relaxed);
                mutations_done.fetch_add(taken, Ordering::Relaxed);
                splats.submit(&films, i, buf);
                if let Some(o) = opts.observer_wanting(false) {
                    // One snapshot at a time, its chain count read inside
                    // the lock: snapshots reach the observer with their
                    // samples per pixel in order.
                    let _one = snapshot_lock.lock().unwrap_or_else(|e| e.into_inner());
                    // The chains applied so far (in order) made this many
                    // mutations: the sum of the per-chain counts above.
                    let applied = splats.applied() as u64;
                    let made = applied * n_total_mutations / n_chains as u64;
                    if made > 0 {
                        let scale = (b * sample_area as f64 / made as f64) as Float;
                        let spp = (made / sample_area.max(1)) as i32;
                        let none = std::iter::empty();
                        o.image(snapshot(&scene_ref.film, none, spp, scale, false));
                    }
                }
            }
        });
        Ok((mutations_done.load(Ordering::Relaxed), b))
    });
    let (taken, b) = result?;
    let interrupted = taken < n_total_mutations && opts.interrupted();
    let render_time = start.elapsed();
    metadata.render_time_seconds = Some(render_time.as_secs_f32());
    metadata.samples_per_pixel = Some(it.mutations_per_pixel);
    // pbrt-v4 writes the splats scaled by b over the mutations per pixel;
    // an interrupted render (whole chains only) by those it made.
    let scale = if taken == 0 {
        0.0
    } else {
        b * sample_area as f64 / taken as f64
    };
    opts.observe_final(&scene_ref.film, it.mutations_per_pixel, scale as Float);
    write_film(&scene_ref.film, metadata, scale as Float)?;
    Ok(RenderStats {
        render_time,
        samples: taken,
        interrupted,
        mse_per_wave: Vec::new(),
        warnings: Vec::new(),
    })
}
