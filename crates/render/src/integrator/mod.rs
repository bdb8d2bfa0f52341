//! Integrators (book chapters 13–14; pbrt-v4 `cpu/integrators.h/.cpp`):
//! the light-transport algorithms and how each renders a [`Scene`].
//!
//! [`Integrator::render`] is the one entry point: each integrator owns its
//! render loop. Most integrators here are pbrt-v4 `RayIntegrator`s
//! ([`RayIntegrator`]): each estimates the radiance along one camera ray,
//! and the shared tile loop ([`tile`]) drives it over image tiles in
//! parallel. Light tracers that splat onto the film (bdpt, lightpath) use
//! the same loop through [`TileIntegrator`], one pixel sample at a time.
//! An integrator that needs a loop of its own (MLT, SPPM, the function
//! bench) gets a match arm in [`Integrator::render`] calling its own
//! function, which reports progress through the same callback
//! ([`Progress`]) and fails with the same [`RenderError`].
//!
//! Results never depend on the thread count: each pixel's samples come
//! from a sampler seeded by the pixel and sample index, each pixel belongs
//! to exactly one tile, and splats are applied in tile (or MLT chain)
//! order ([`crate::film::OrderedSplats`]).
//!
//! The files: [`scene`], the render-ready scene and its ray queries;
//! `create`, creation from the scene description; `direct`, direct
//! lighting; [`render`], what render loops share (options, statistics,
//! errors, progress); [`tile`], the tile loop; `path` and `simple`, the
//! integrators; `volume`, what the volumetric ones share; `volpath` and
//! `simplevolpath`, pbrt-v4's volumetric path tracers; `bdpt`, the
//! bidirectional path tracer and the vertices, random walks and
//! connections that `mlt` (primary-sample-space Metropolis) and
//! `lightpath` (the light tracer) share; `sppm`, stochastic progressive
//! photon mapping; `function`, pbrt-v4's sampler bench; `whitted`,
//! pbrt-v3's Whitted ray tracer.

pub(crate) mod bdpt;
mod bsdf_stage;
mod camera_samples;
mod create;
mod diffuse_lanes;
mod direct;
mod function;
mod interactive;
mod lightpath;
mod mlt;
mod path;
pub mod render;
pub mod scene;
mod simple;
mod simplevolpath;
mod sppm;
mod stages;
pub mod tile;
mod vertex;
mod volpath;
mod volume;
mod wavefront;
mod whitted;

pub use bdpt::BdptIntegrator;
pub use create::{create_integrator, IntegratorOptions, INTEGRATOR_NAMES};
pub use function::{FunctionIntegrator, TestFunction};
pub use interactive::{pick, Pick};
pub use lightpath::LightPathIntegrator;
pub use mlt::MltIntegrator;
pub use path::PathIntegrator;
pub use render::{
    CameraChange, Progress, ProgressFn, RenderError, RenderObserver, RenderOptions, RenderStats,
    Snapshot,
};
pub use scene::{RayCounters, Scene};
pub use simple::{AmbientOcclusionIntegrator, RandomWalkIntegrator, SimplePathIntegrator};
pub use simplevolpath::SimpleVolPathIntegrator;
pub use sppm::SppmIntegrator;
pub use stages::StageTimes;
pub use tile::{RayIntegrator, TileIntegrator};
pub use volpath::VolPathIntegrator;
pub use whitted::WhittedIntegrator;

pub(crate) use direct::{sample_ld, VertexOrigins};
pub(crate) use scene::skip_intersection;

use crate::image::ImageMetadata;

/// The closed set of integrators.
pub enum Integrator {
    /// `path` (and `volpath` on scenes without participating media).
    Path(PathIntegrator),
    /// `simplepath`.
    SimplePath(SimplePathIntegrator),
    /// `ambientocclusion`.
    AmbientOcclusion(AmbientOcclusionIntegrator),
    /// `randomwalk`.
    RandomWalk(RandomWalkIntegrator),
    /// `volpath`.
    VolPath(VolPathIntegrator),
    /// `simplevolpath`.
    SimpleVolPath(SimpleVolPathIntegrator),
    /// `bdpt`.
    Bdpt(BdptIntegrator),
    /// `lightpath`.
    LightPath(LightPathIntegrator),
    /// `mlt`.
    Mlt(MltIntegrator),
    /// `sppm`.
    Sppm(SppmIntegrator),
    /// pbrt-v3's `whitted`.
    Whitted(WhittedIntegrator),
    /// `function`: a sampler bench, no light transport.
    Function(FunctionIntegrator),
}

impl Integrator {
    /// Renders `scene` and writes the film's image (and partial images
    /// when `opts` asks for them), pbrt-v4 `Integrator::Render`.
    /// `metadata` is completed with timing and sample counts; `progress`
    /// is called from a reporting thread about every 250 ms while the
    /// render runs and once at its end.
    pub fn render(
        &self,
        scene: &mut Scene,
        opts: &RenderOptions,
        metadata: &mut ImageMetadata,
        progress: ProgressFn,
    ) -> Result<RenderStats, RenderError> {
        let partial =
            opts.sample_range.is_some() || scene.film.active_bounds() != scene.film.pixel_bounds();
        if partial && !self.renders_pixel_samples() {
            return Err(RenderError::Partial(crate::film::PartialError(format!(
                "the \"{}\" integrator does not take samples pixel by pixel, so it cannot render sample ranges or parts of its film",
                self.name()
            ))));
        }
        if opts.observer.as_ref().is_some_and(|o| o.interactive()) && !self.renders_interactively()
        {
            return Err(RenderError::Unsupported(format!(
                "the \"{}\" integrator cannot render interactively (path, volpath, simplepath, simplevolpath, ambientocclusion, randomwalk and whitted can)",
                self.name()
            )));
        }
        // One match per render: each arm runs a loop built for its
        // integrator (no dispatch per ray).
        let mut result = match self {
            Integrator::Path(i) if opts.wavefront => {
                tile::render_tiles(&wavefront::Wavefront(i), scene, opts, metadata, progress)
            }
            Integrator::VolPath(i) if opts.wavefront => {
                tile::render_tiles(&wavefront::Wavefront(i), scene, opts, metadata, progress)
            }
            Integrator::Path(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::SimplePath(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::AmbientOcclusion(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::RandomWalk(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::VolPath(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::SimpleVolPath(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::Bdpt(i) => bdpt::render(i, scene, opts, metadata, progress),
            Integrator::LightPath(i) => tile::render_tiles(i, scene, opts, metadata, progress),
            Integrator::Mlt(i) => mlt::render(i, scene, opts, metadata, progress),
            Integrator::Sppm(i) => sppm::render(i, scene, opts, metadata, progress),
            Integrator::Whitted(i) => {
                tile::render_tiles(&tile::RayTiles(i), scene, opts, metadata, progress)
            }
            Integrator::Function(i) => function::render(i, scene, opts, progress),
        };
        if let Ok(stats) = &mut result {
            stats
                .warnings
                .extend(crate::texture::ptex::take_lookup_warnings());
        }
        result
    }

    /// True when `--wavefront` ([`RenderOptions::wavefront`]) renders this
    /// integrator with the wavefront path tracer (`path` and `volpath`);
    /// the others keep their scalar loops.
    pub fn has_wavefront(&self) -> bool {
        matches!(self, Integrator::Path(_) | Integrator::VolPath(_))
    }

    /// True when the wavefront path tracer is the better choice for this
    /// integrator in `scene`, which the command line makes its default
    /// (`--no-wavefront` selects the scalar loop; the two give the same
    /// pixels). Measured on the shared scenes (2 threads, AVX2): `path`
    /// scenes render 1.1–1.5× faster, and so do `volpath` scenes without
    /// media or interfaces (whose surface vertices take the same lanes);
    /// with media, where each lane tracks its medium with the scalar code,
    /// the wavefront is no faster (nanovdb-sphere 0.98×), so `volpath`
    /// keeps the scalar loop there.
    pub fn wavefront_by_default(&self, scene: &Scene) -> bool {
        match self {
            Integrator::Path(_) => true,
            Integrator::VolPath(_) => !scene.has_volumes,
            _ => false,
        }
    }

    /// The memory the integrator's own buffers take over a film of
    /// `pixels` pixels, in bytes, where its parameters or the film size
    /// them (for the memory budget; per-thread scratch is not counted).
    pub fn memory_bytes(&self, pixels: u64) -> u64 {
        match self {
            // Per pixel: the pixel's state, this iteration's flux and
            // photon count, and the visible points' hash grid.
            Integrator::Sppm(_) => {
                let per_pixel = std::mem::size_of::<sppm::SppmPixel>() + 12 + 4 + 8 + 16;
                pixels.saturating_mul(per_pixel as u64)
            }
            // The bootstrap weights and their distribution, and the
            // chains' states.
            Integrator::Mlt(m) => {
                let depths = m.max_depth.max(0) as u64 + 1;
                let bootstrap = (m.bootstrap_samples.max(1) as u64).saturating_mul(depths);
                bootstrap
                    .saturating_mul(12)
                    .saturating_add((m.chains.max(1) as u64).saturating_mul(512))
            }
            // One RGB film per strategy when they are visualised.
            Integrator::Bdpt(b) if b.visualize_strategies || b.visualize_weights => {
                let d = b.max_depth.max(0) as u64;
                let films = (1 + d).saturating_mul(6 + d) / 2;
                films.saturating_mul(pixels).saturating_mul(80)
            }
            _ => 0,
        }
    }

    /// The integrator's name in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Path(_) => "path",
            Integrator::SimplePath(_) => "simplepath",
            Integrator::AmbientOcclusion(_) => "ambientocclusion",
            Integrator::RandomWalk(_) => "randomwalk",
            Integrator::VolPath(_) => "volpath",
            Integrator::SimpleVolPath(_) => "simplevolpath",
            Integrator::Bdpt(_) => "bdpt",
            Integrator::LightPath(_) => "lightpath",
            Integrator::Mlt(_) => "mlt",
            Integrator::Sppm(_) => "sppm",
            Integrator::Whitted(_) => "whitted",
            Integrator::Function(_) => "function",
        }
    }

    /// True for integrators that take each pixel's samples by index, so
    /// that tiles and sample ranges (`--spp-range`) of a render can be made
    /// separately; mlt's chains, sppm's photon passes and the function
    /// bench cannot.
    pub fn renders_pixel_samples(&self) -> bool {
        !matches!(
            self,
            Integrator::Mlt(_) | Integrator::Sppm(_) | Integrator::Function(_)
        )
    }

    /// True for integrators that can render interactively (`--interactive`):
    /// those that estimate each camera ray's radiance alone, so that a
    /// moved camera needs only a cleared film.
    pub fn renders_interactively(&self) -> bool {
        matches!(
            self,
            Integrator::Path(_)
                | Integrator::VolPath(_)
                | Integrator::SimplePath(_)
                | Integrator::SimpleVolPath(_)
                | Integrator::AmbientOcclusion(_)
                | Integrator::RandomWalk(_)
                | Integrator::Whitted(_)
        )
    }

    /// True for integrators that connect paths to the camera's lens (they
    /// need [`crate::camera::Camera::we`] and its kin).
    pub fn needs_camera_importance(&self) -> bool {
        matches!(
            self,
            Integrator::Bdpt(_) | Integrator::LightPath(_) | Integrator::Mlt(_)
        )
    }

    /// The light sampler, if the integrator samples lights.
    pub fn light_sampler_name(&self) -> Option<&str> {
        match self {
            Integrator::Path(i) => Some(&i.light_sampler_name),
            Integrator::VolPath(i) => Some(&i.light_sampler_name),
            // pbrt-v4's bidirectional integrators choose lights by power.
            Integrator::Bdpt(_) | Integrator::LightPath(_) | Integrator::Mlt(_) => Some("power"),
            _ => None,
        }
    }
}
