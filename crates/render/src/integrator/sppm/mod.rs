//! Stochastic progressive photon mapping (pbrt-v4 `SPPMIntegrator`,
//! `cpu/integrators.cpp`; pbrt-v3 book section 16.2): each iteration
//! traces one camera path per pixel to a visible point, gathering direct
//! lighting along the way, then traces photons from the lights and adds
//! every photon's flux to the visible points it lands near; each pixel's
//! search radius shrinks as photons accumulate (γ = 2/3).
//!
//! The iterations are the sampler's samples per pixel. Every pass runs in
//! parallel, and nothing depends on the thread count: a pixel's camera
//! path uses the scene's sampler at (pixel, iteration), a photon's path the
//! scrambled Halton sequence at its index, and photon contributions are
//! summed in photon order (see [`photon`]). Like pbrt-v4, SPPM ignores
//! participating media (scene creation warns) and writes the image itself,
//! as output RGB, after iterations 1, 2, 4, …, 64 and every 64th after.
//!
//! The files: this one, the passes and the render loop; [`grid`], the
//! hashed grid of visible points; [`photon`], the photon paths.

mod grid;
mod photon;

use super::camera_samples::camera_ray;
use super::render::{with_progress, ProgressFn, RenderError, RenderOptions, RenderStats, Snapshot};
use super::{sample_ld, skip_intersection, RayCounters, Scene, VertexOrigins};
use crate::bxdf::{BxDFReflTransFlags, TransportMode, BSDF};
use crate::image::{ColorEncoding, Image, ImageMetadata, PixelFormat};
use crate::light::LightSampleContext;
use crate::lightsampler::PowerLightSampler;
use crate::sampler::lowdiscrepancy::{radical_inverse, DigitPermutation, PRIMES, PRIME_TABLE_SIZE};
use crate::sampler::{IndependentSampler, Sampler};
use crate::sampling::power_heuristic;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, RGB};
use grid::{next_prime, VisiblePointGrid};
use photon::{photon_dimensions, Deposit, PhotonPass};
use rayon::prelude::*;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// pbrt-v4's `sppm` integrator.
#[derive(Clone, Debug)]
pub struct SppmIntegrator {
    /// Maximum number of vertices of camera and photon paths.
    pub max_depth: i32,
    /// Photons traced per iteration (the pixel count when not positive).
    pub photons_per_iteration: i32,
    /// The search radius every pixel starts with.
    pub initial_radius: Float,
    /// Seed of the photons' Halton digit permutations.
    pub seed: i32,
    /// Name of the colour space recorded in the image's metadata (the one
    /// in effect at the `Integrator` directive, as pbrt-v4).
    pub color_space: String,
}

/// Where a pixel's camera path stopped to gather photons (pbrt-v4
/// `SPPMPixel::VisiblePoint`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct VisiblePoint {
    /// The surface point.
    p: Point3f,
    /// The direction back along the camera path.
    wo: Vector3f,
    /// The BSDF there.
    bsdf: BSDF,
    /// The camera path's throughput up to the point.
    beta: SampledSpectrum,
    /// Whether the camera path kept only its first wavelength.
    secondary_terminated: bool,
}

/// A pixel's SPPM state (pbrt-v4 `SPPMPixel`).
#[derive(Clone, Debug)]
pub(crate) struct SppmPixel {
    /// The photon search radius.
    radius: Float,
    /// Light gathered along the camera paths (emission and direct
    /// lighting), summed over iterations, in output RGB.
    ld: RGB,
    /// This iteration's visible point, if its camera path made one.
    vp: Option<VisiblePoint>,
    /// The accumulated photon count (pbrt-v4's `N`).
    n: Float,
    /// The accumulated flux, scaled with the radius (pbrt-v4's `tau`).
    tau: RGB,
}

/// Photons traced as one unit of parallel work.
const PHOTON_CHUNK: u64 = 1024;
/// Chunks whose contributions are held in memory at once before they are
/// added to the pixels, in chunk order.
const CHUNKS_PER_BATCH: u64 = 256;

impl SppmIntegrator {
    /// Follows the camera path of pixel `p_pixel` in one iteration
    /// (pbrt-v4's "Follow camera ray path until a visible point is
    /// created"), adding the emission and direct lighting it finds to
    /// `pixel.ld` and leaving its visible point in `pixel.vp`.
    #[allow(clippy::too_many_arguments)]
    fn camera_path(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        sampler: &mut Sampler,
        p_pixel: Point2i,
        pass_lambda: &SampledWavelengths,
        inv_sqrt_spp: Float,
        differentials: bool,
        pixel: &mut SppmPixel,
    ) {
        let film = &scene.film;
        // pbrt-v4's GetCameraSample: no wavelength draw (the iteration's
        // wavelengths are fixed) and no use of the filter weight.
        let u_pixel = sampler.get_pixel_2d();
        let time = sampler.get_1d();
        let p_lens = sampler.get_2d();
        let (_, camera_ray) = camera_ray(
            scene,
            opts,
            p_pixel,
            u_pixel,
            time,
            p_lens,
            differentials,
            inv_sqrt_spp,
        );
        let Some((mut ray, weight)) = camera_ray else {
            return;
        };
        if weight == 0.0 {
            return;
        }
        let mut beta = SampledSpectrum::new(weight);
        let mut lambda = *pass_lambda;
        let light_sampler = &scene.light_sampler;
        let mut eta_scale: Float = 1.0;
        let mut bsdf_pdf: Float = 0.0;
        let mut specular_bounce = true;
        let mut have_visible_point = false;
        let mut prev_ctx = LightSampleContext::default();
        let mut depth = 0;
        loop {
            let mut closest = scene.intersect(&ray.ray, Float::INFINITY);
            let Some(hit) = closest.as_mut() else {
                // Escaped: infinite lights, MIS-weighted unless the last
                // bounce could not have been light-sampled.
                let mut l = SampledSpectrum::new(0.0);
                for &li in &scene.infinite_lights {
                    let light = &scene.lights[li as usize];
                    let le = light.le(&ray.ray, &lambda);
                    if depth == 0 || specular_bounce {
                        l += beta * le;
                    } else {
                        let light_pdf = light_sampler.pmf(&prev_ctx, li)
                            * light.pdf_li(&prev_ctx, ray.ray.d, true);
                        let w_b = power_heuristic(1.0, bsdf_pdf, 1.0, light_pdf);
                        l += beta * w_b * le;
                    }
                }
                if !l.is_black() {
                    pixel.ld = pixel.ld + film.to_output_rgb(l, &lambda);
                }
                break;
            };
            let bsdf_slot = scene.get_bsdf(hit, &ray, &mut lambda, sampler);
            let Some(bsdf) = bsdf_slot.as_ref() else {
                ray = skip_intersection(&ray, hit);
                continue;
            };
            // Emission of the surface hit.
            let wo = -ray.ray.d;
            let le = scene.le(hit, wo, &lambda);
            if !le.is_black() {
                let mut l = SampledSpectrum::new(0.0);
                if depth == 0 || specular_bounce {
                    l += beta * le;
                } else if let Some(al) = hit.area_light {
                    let light = &scene.lights[al as usize];
                    let light_pdf =
                        light_sampler.pmf(&prev_ctx, al) * light.pdf_li(&prev_ctx, ray.ray.d, true);
                    let w_l = power_heuristic(1.0, bsdf_pdf, 1.0, light_pdf);
                    l += beta * w_l * le;
                }
                pixel.ld = pixel.ld + film.to_output_rgb(l, &lambda);
            }
            // pbrt-v4's `depth++ == maxDepth`: the path goes one vertex past
            // its visible point, for the emission a BSDF sample finds there.
            if depth == self.max_depth || have_visible_point {
                break;
            }
            depth += 1;
            let si = &hit.si;
            let mut origins = VertexOrigins::new(si);
            // Direct lighting (the draws are taken for specular BSDFs too,
            // as pbrt-v4 does, though nothing can come of them).
            let u_light = sampler.get_1d();
            let u_light_2d = sampler.get_2d();
            if bsdf.flags().is_non_specular() {
                let ld = sample_ld(
                    scene,
                    light_sampler,
                    &mut origins,
                    bsdf,
                    &lambda,
                    u_light,
                    u_light_2d,
                );
                if !ld.is_black() {
                    pixel.ld = pixel.ld + film.to_output_rgb(beta * ld, &lambda);
                }
            }
            let flags = bsdf.flags();
            if flags.is_diffuse() || (flags.is_glossy() && depth == self.max_depth) {
                pixel.vp = Some(VisiblePoint {
                    p: si.p(),
                    wo,
                    bsdf: *bsdf,
                    beta,
                    secondary_terminated: lambda.secondary_terminated(),
                });
                have_visible_point = true;
            }
            let u = sampler.get_1d();
            let u2 = sampler.get_2d();
            let Some(bs) =
                bsdf.sample_f(wo, u, u2, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            else {
                break;
            };
            specular_bounce = bs.is_specular();
            if bs.is_transmission() {
                eta_scale *= bs.eta * bs.eta;
            }
            beta *= bs.f * abs_dot(bs.wi, si.shading.n) / bs.pdf;
            bsdf_pdf = if bs.pdf_is_proportional {
                bsdf.pdf(wo, bs.wi, TransportMode::Radiance, BxDFReflTransFlags::ALL)
            } else {
                bs.pdf
            };
            let rr_beta = beta * eta_scale;
            let m = rr_beta.max_component_value();
            if m < 1.0 {
                let q = (1.0 - m).max(0.05);
                if sampler.get_1d() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            ray = RayDifferential::new(origins.spawn_ray(bs.wi));
            prev_ctx = LightSampleContext::from_si(si);
        }
    }
}

/// The radius, count and flux update of one pixel after a photon pass
/// that brought it `m` photons of total flux `phi` (pbrt-v4's "Update
/// pixel values from this pass's photons"), and the reset of its visible
/// point and of `phi` and `m`.
fn update_pixel(p: &mut SppmPixel, phi: &mut RGB, m: &mut u32) {
    if *m > 0 {
        let gamma: Float = 2.0 / 3.0;
        let mf = *m as Float;
        let n_new = p.n + gamma * mf;
        let r_new = p.radius * (n_new / (p.n + mf)).sqrt();
        p.tau = (p.tau + *phi) * (r_new * r_new) / (p.radius * p.radius);
        p.n = n_new;
        p.radius = r_new;
        *m = 0;
        *phi = RGB::new(0.0, 0.0, 0.0);
    }
    p.vp = None;
}

/// pbrt-v4's image-writing schedule: after iterations 1, 2, 4, …, 64, every
/// 64th after that, and the last.
fn writes_after(iterations_done: i32, n_iterations: i32) -> bool {
    iterations_done == n_iterations
        || (iterations_done <= 64 && (iterations_done as u32).is_power_of_two())
        || iterations_done % 64 == 0
}

/// The image after `iterations_done` iterations of `photons_per_iteration`
/// photons: each pixel's `ld / iterations + tau / (photons · π r²)`.
fn sppm_image(
    pixels: &[SppmPixel],
    resolution: Point2i,
    iterations_done: i32,
    photons_per_iteration: u64,
) -> Image {
    let mut image = Image::new(
        PixelFormat::Float,
        resolution,
        &["R", "G", "B"],
        ColorEncoding::Linear,
    );
    let np = (iterations_done as u64 * photons_per_iteration) as Float;
    let width = resolution.x.max(1) as usize;
    for (i, p) in pixels.iter().enumerate() {
        let l = p.ld / iterations_done as Float
            + p.tau / (np * std::f32::consts::PI as Float * (p.radius * p.radius));
        let at = Point2i::new((i % width) as i32, (i / width) as i32);
        image.set_channels(at, &[l.r, l.g, l.b]);
    }
    image
}

/// Renders `scene` with SPPM, writing the image as pbrt-v4 does (see the
/// module documentation); `metadata` is completed with timing and the
/// iteration count, `progress` hears of camera paths and photons traced.
pub(crate) fn render(
    integrator: &SppmIntegrator,
    scene: &mut Scene,
    opts: &RenderOptions,
    metadata: &mut ImageMetadata,
    progress: ProgressFn,
) -> Result<RenderStats, RenderError> {
    let start = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.nthreads)
        .build()
        .map_err(RenderError::ThreadPool)?;
    let scene: &Scene = scene;
    let n_iterations = scene.sampler.samples_per_pixel().max(1);
    let inv_sqrt_spp = 1.0 / (n_iterations as Float).sqrt();
    let pixel_bounds = scene.film.pixel_bounds();
    let diag = pixel_bounds.diagonal();
    let resolution = Point2i::new(diag.x.max(0), diag.y.max(0));
    let width = resolution.x as usize;
    let n_pixels = width * resolution.y as usize;
    let photons_per_iteration = if integrator.photons_per_iteration > 0 {
        integrator.photons_per_iteration as u64
    } else {
        n_pixels as u64
    };
    let hash_size = next_prime(n_pixels as u64) as usize;
    let differentials = scene.materials.any_needs_differentials();
    let mut pixels = vec![
        SppmPixel {
            radius: integrator.initial_radius,
            ld: RGB::new(0.0, 0.0, 0.0),
            vp: None,
            n: 0.0,
            tau: RGB::new(0.0, 0.0, 0.0),
        };
        n_pixels
    ];
    // This iteration's photon flux and count per pixel (pbrt-v4's `Phi_i`
    // and `M`), kept apart from the pixels the photon pass reads.
    let mut phi = vec![RGB::new(0.0, 0.0, 0.0); n_pixels];
    let mut m = vec![0u32; n_pixels];
    let shoot = PowerLightSampler::new(&scene.lights);
    // The digit permutations of the dimensions photon paths can reach
    // (pbrt-v4 computes all of the prime table's).
    let n_dims = photon_dimensions(integrator.max_depth).min(PRIME_TABLE_SIZE);
    let seed = integrator.seed as u32;
    let permutations: Vec<DigitPermutation> = pool.install(|| {
        PRIMES[..n_dims]
            .par_iter()
            .map(|&b| DigitPermutation::new(b, seed))
            .collect()
    });

    let total = n_iterations as u64 * (n_pixels as u64 + photons_per_iteration);
    let mut iterations_done = 0;
    let mut interrupted = false;
    let mut mse_per_wave = Vec::new();
    let write = |image: Image,
                 iterations_done: i32,
                 metadata: &ImageMetadata,
                 mse_per_wave: &mut Vec<(i32, f64)>|
     -> Result<(), RenderError> {
        let mut md = metadata.clone();
        md.render_time_seconds = Some(start.elapsed().as_secs_f32());
        md.samples_per_pixel = Some(iterations_done);
        md.pixel_bounds = Some(pixel_bounds);
        md.full_resolution = Some(scene.film.full_resolution());
        md.color_space = Some(integrator.color_space.clone());
        if let Some(reference) = &opts.mse_reference {
            let d =
                crate::image::ops::diff(&image, reference).map_err(RenderError::MseReference)?;
            mse_per_wave.push((iterations_done, d.mse));
            md.mse = Some(d.mse as f32);
        }
        let path = scene.film.filename();
        image
            .write(path, &md)
            .map_err(|source| RenderError::WriteImage {
                path: path.to_string(),
                source,
            })
    };

    with_progress(total, start, progress, |done: &AtomicU64| {
        for iter in 0..n_iterations {
            // The iteration's wavelengths, shared by its camera paths and
            // photons.
            let u_lambda = if opts.disable_wavelength_jitter {
                0.5
            } else {
                radical_inverse(1, iter as u64)
            };
            let pass_lambda = scene.film.sample_wavelengths(u_lambda);

            // Camera pass: a visible point per pixel, row by row.
            pool.install(|| {
                pixels
                    .par_chunks_mut(width.max(1))
                    .enumerate()
                    .for_each(|(row, row_pixels)| {
                        let mut sampler = scene.sampler.clone();
                        RayCounters::reset_local();
                        let y = pixel_bounds.p_min.y + row as i32;
                        for (x, pixel) in row_pixels.iter_mut().enumerate() {
                            let p = Point2i::new(pixel_bounds.p_min.x + x as i32, y);
                            sampler.start_pixel_sample(p, iter, 0);
                            integrator.camera_path(
                                scene,
                                opts,
                                &mut sampler,
                                p,
                                &pass_lambda,
                                inv_sqrt_spp,
                                differentials,
                                pixel,
                            );
                        }
                        scene.counters.flush_local();
                        let n = row_pixels.len() as u64;
                        scene.counters.camera_rays.fetch_add(n, Ordering::Relaxed);
                        done.fetch_add(n, Ordering::Relaxed);
                    })
            });

            // The grid of visible points.
            let points: Vec<(Point3f, Float, u32)> = pixels
                .iter()
                .enumerate()
                .filter_map(|(i, p)| {
                    let vp = p.vp.as_ref()?;
                    (!vp.beta.is_black()).then_some((vp.p, p.radius, i as u32))
                })
                .collect();
            let grid = pool.install(|| VisiblePointGrid::new(&points, hash_size));
            drop(points);

            // Photon pass, in batches of chunks whose contributions are
            // added in photon order.
            if let Some(grid) = &grid {
                let pass = PhotonPass {
                    scene,
                    grid,
                    pixels: &pixels,
                    shoot: &shoot,
                    permutations: &permutations,
                    lambda: pass_lambda,
                    max_depth: integrator.max_depth,
                    first_index: iter as u64 * photons_per_iteration,
                };
                let n_chunks = photons_per_iteration.div_ceil(PHOTON_CHUNK);
                let mut batch_start = 0;
                while batch_start < n_chunks {
                    let batch_end = (batch_start + CHUNKS_PER_BATCH).min(n_chunks);
                    let batch: Vec<Vec<Deposit>> = pool.install(|| {
                        (batch_start..batch_end)
                            .into_par_iter()
                            .map(|chunk| {
                                let begin = chunk * PHOTON_CHUNK;
                                let end = (begin + PHOTON_CHUNK).min(photons_per_iteration);
                                let mut out = Vec::new();
                                let mut sampler = Sampler::Independent(IndependentSampler::new(
                                    1,
                                    integrator.seed,
                                ));
                                RayCounters::reset_local();
                                for i in begin..end {
                                    pass.trace(i, &mut sampler, &mut out);
                                }
                                scene.counters.flush_local();
                                done.fetch_add(end - begin, Ordering::Relaxed);
                                out
                            })
                            .collect()
                    });
                    for d in batch.iter().flatten() {
                        let i = d.pixel as usize;
                        phi[i] = phi[i] + d.phi;
                        m[i] += 1;
                    }
                    batch_start = batch_end;
                }
            } else {
                done.fetch_add(photons_per_iteration, Ordering::Relaxed);
            }
            drop(grid);

            pool.install(|| {
                pixels
                    .par_iter_mut()
                    .zip(phi.par_iter_mut())
                    .zip(m.par_iter_mut())
                    .for_each(|((p, phi), m)| update_pixel(p, phi, m))
            });
            iterations_done = iter + 1;
            let stop = opts.interrupted();
            // The last image always goes to the observer; others when it
            // asks.
            let last = stop || iterations_done == n_iterations;
            let observer = if last {
                opts.observer.as_deref()
            } else {
                opts.observer_wanting(true)
            };
            let writes = stop || writes_after(iterations_done, n_iterations);
            if writes || observer.is_some() {
                let image = sppm_image(&pixels, resolution, iterations_done, photons_per_iteration);
                if let Some(o) = observer {
                    o.image(Snapshot {
                        width: resolution.x.max(0) as usize,
                        height: resolution.y.max(0) as usize,
                        rgb: image.as_f32().map(<[f32]>::to_vec).unwrap_or_default(),
                        spp: iterations_done,
                        done: last,
                        camera: 0,
                    });
                }
                if writes {
                    write(image, iterations_done, metadata, &mut mse_per_wave)?;
                }
            }
            if stop {
                interrupted = iterations_done < n_iterations;
                break;
            }
        }
        Ok(())
    })?;

    let render_time = start.elapsed();
    metadata.render_time_seconds = Some(render_time.as_secs_f32());
    metadata.samples_per_pixel = Some(iterations_done);
    if let Some(&(_, mse)) = mse_per_wave.last() {
        metadata.mse = Some(mse as f32);
    }
    Ok(RenderStats {
        render_time,
        samples: iterations_done as u64 * n_pixels as u64,
        interrupted,
        mse_per_wave,
        warnings: Vec::new(),
    })
}
