//! Bidirectional path tracing (pbrt-v4 `BDPTIntegrator`, `cpu/integrators.cpp`;
//! book chapter 16 of the third edition): a camera subpath and a light
//! subpath per pixel sample, joined in every (s, t) way, each strategy
//! weighted by the balance heuristic. Strategies with one camera vertex
//! (t = 1) land anywhere on the film and are splatted.
//!
//! The files: `vertex`, path vertices and their densities; `walk`,
//! subpath generation through surfaces and media; `connect`, the
//! strategies and their MIS weights. MLT ([`super::mlt`]) reuses all three.

mod connect;
pub(crate) mod vertex;
pub(crate) mod walk;

#[cfg(test)]
mod tests;

pub(crate) use connect::{connect_bdpt, transmittance, Connection};
pub(crate) use vertex::Vertex;
pub(crate) use walk::{generate_camera_subpath, generate_light_subpath, WalkOptions};

use super::camera_samples::CameraRaySample;
use super::render::{write_film, ProgressFn, RenderError, RenderOptions, RenderStats};
use super::tile::{self, TileIntegrator};
use super::Scene;
use crate::film::{
    Film, FilmCore, FilmParams, FilmTile, KindConfig, PixelSensor, RgbFilm, SplatBuffer,
};
use crate::filter::{BoxFilter, Filter};
use crate::image::ImageMetadata;
use crate::sampler::Sampler;
use crate::spectrum::RgbColorSpace;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::bounds::Bounds2i;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;
use std::cell::RefCell;

/// pbrt-v4's `bdpt` integrator.
#[derive(Clone, Debug)]
pub struct BdptIntegrator {
    /// Maximum number of scattering events of a path.
    pub max_depth: i32,
    /// Roughen near-specular BSDFs after the first non-specular bounce.
    pub regularize: bool,
    /// Write each strategy's unweighted contribution to its own image.
    pub visualize_strategies: bool,
    /// Write each strategy's weighted contribution to its own image.
    pub visualize_weights: bool,
}

thread_local! {
    /// This thread's subpath buffers (camera, light), reused across
    /// samples.
    static SUBPATHS: RefCell<(Vec<Vertex>, Vec<Vertex>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// The index of strategy (s, t) among the visualisation films (pbrt-v4
/// `BufferIndex`).
pub(crate) fn buffer_index(s: usize, t: usize) -> usize {
    let above = s + t - 2;
    s + above * (5 + above) / 2
}

impl BdptIntegrator {
    /// The radiance of one camera ray: the strategies with t ≥ 2, while
    /// t = 1 strategies go to `splats` (pbrt-v4 `BDPTIntegrator::Li`).
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        p_film: Point2f,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        let max_depth = self.max_depth.max(0) as usize;
        let opts = WalkOptions {
            regularize: self.regularize,
        };
        let visualize = self.visualize_strategies || self.visualize_weights;
        SUBPATHS.with(|cell| {
            let mut paths = cell.borrow_mut();
            let (camera, light) = &mut *paths;
            let n_camera =
                generate_camera_subpath(scene, ray, lambda, sampler, max_depth + 2, opts, camera);
            let time = camera[0].time;
            let n_light =
                generate_light_subpath(scene, lambda, sampler, max_depth + 1, time, opts, light);
            let mut l = SampledSpectrum::new(0.0);
            for t in 1..=n_camera {
                for s in 0..=n_light {
                    let depth = (t + s) as i64 - 2;
                    if (s == 1 && t == 1) || depth < 0 || depth > max_depth as i64 {
                        continue;
                    }
                    let c: Connection = connect_bdpt(scene, lambda, light, camera, s, t, sampler);
                    if visualize {
                        // pbrt-v4 records only t = 1 strategies (the others
                        // have no raster position there); as pbrt-v3, the
                        // others go to the camera sample's film position.
                        if let Some(p) = c.p_raster.or((t != 1).then_some(p_film)) {
                            let value = if self.visualize_weights {
                                c.l
                            } else if c.mis_weight == 0.0 {
                                SampledSpectrum::new(0.0)
                            } else {
                                c.l / c.mis_weight
                            };
                            if !value.is_black() {
                                splats.add_to(buffer_index(s, t) + 1, p, value, lambda);
                            }
                        }
                    }
                    if t != 1 {
                        l += c.l;
                    } else if !c.l.is_black() {
                        if let Some(p) = c.p_raster {
                            splats.add(p, c.l, lambda);
                        }
                    }
                }
            }
            l
        })
    }
}

/// A bdpt render: the integrator and, when strategies are visualised,
/// one film per (s, t) strategy (pbrt-v4's `weightFilms`; `None` for the
/// indices of strategies that do not exist).
struct BdptRun<'a> {
    integrator: &'a BdptIntegrator,
    films: Vec<Film>,
}

impl TileIntegrator for BdptRun<'_> {
    type Buffers = ();

    fn evaluate_pixel_sample(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        p_pixel: Point2i,
        sampler: &mut Sampler,
        tile: &mut FilmTile,
        splats: &mut SplatBuffer,
        differentials: bool,
    ) {
        let cs = CameraRaySample::take(scene, opts, p_pixel, sampler, differentials);
        let p_film = cs.cs.p_film;
        cs.finish(scene, tile, |ray, lambda, _| {
            self.integrator
                .li(scene, ray, lambda, sampler, p_film, splats)
        });
    }

    fn extra_films(&self) -> &[Film] {
        &self.films
    }
}

/// Renders with bdpt (pbrt-v4 `BDPTIntegrator::Render`): the tile loop,
/// then, when asked, the strategy images `bdpt_dDD_sSS_tTT.exr` (box
/// filter, default sensor, sRGB, the full resolution), scaled by one over
/// the samples per pixel.
pub(crate) fn render(
    integrator: &BdptIntegrator,
    scene: &mut Scene,
    opts: &RenderOptions,
    metadata: &mut ImageMetadata,
    progress: ProgressFn,
) -> Result<RenderStats, RenderError> {
    let mut films = Vec::new();
    let mut names = Vec::new();
    if integrator.visualize_strategies || integrator.visualize_weights {
        let max_depth = integrator.max_depth.max(0) as usize;
        let count = (1 + max_depth) * (6 + max_depth) / 2;
        let res = scene.film.full_resolution();
        let geometry = scene.film.geometry();
        let srgb = RgbColorSpace::srgb();
        names = vec![None; count];
        for depth in 0..=max_depth {
            for s in 0..=depth + 2 {
                let t = depth + 2 - s;
                if t == 0 || (s == 1 && t == 1) {
                    continue;
                }
                names[buffer_index(s, t)] = Some(format!("bdpt_d{depth:02}_s{s:02}_t{t:02}.exr"));
            }
        }
        for name in &names {
            let params = FilmParams {
                full_resolution: res,
                pixel_bounds: Bounds2i::new(Point2i::new(0, 0), res),
                diagonal_mm: geometry.diagonal_m * 1000.0,
                filename: name.clone().unwrap_or_default(),
                color_space: srgb,
                max_component_value: Float::INFINITY,
                write_fp16: false,
            };
            let filter = Filter::Box(BoxFilter::new(Vector2f::new(0.5, 0.5)));
            let sensor = PixelSensor::cie1931(srgb, 0.0, 1.0);
            films.push(Film::Rgb(RgbFilm {
                core: FilmCore::new(params, filter, sensor, KindConfig::Rgb),
            }));
        }
    }
    let run = BdptRun { integrator, films };
    let stats = tile::render_tiles(&run, scene, opts, metadata, progress)?;
    let spp = metadata.samples_per_pixel.unwrap_or(1).max(1);
    for (film, name) in run.films.iter().zip(&names) {
        if name.is_some() {
            write_film(film, &ImageMetadata::default(), 1.0 / spp as Float)?;
        }
    }
    Ok(stats)
}
