//! What every render loop shares (pbrt-v4 `Integrator::Render`'s contract,
//! `cpu/integrators.h`): the options a render runs under, the statistics it
//! returns, its typed errors, and progress reported to a caller-supplied
//! callback. The library never writes to the terminal: the command line
//! draws the progress bar from [`Progress`] reports.

use crate::image::ImageError;
use rpbrt_geometry::float::Float;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How the render loop runs (the command line's part).
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Worker threads (0: all cores).
    pub nthreads: usize,
    /// Write the image after every wave of samples.
    pub write_partial_images: bool,
    /// Sample pixel centres only.
    pub disable_pixel_jitter: bool,
    /// Always use the same wavelengths.
    pub disable_wavelength_jitter: bool,
    /// Set (e.g. by a Ctrl-C handler) to stop after the current wave; the
    /// image rendered so far is written.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// `--mse-reference-image`: after every wave of samples, the image's
    /// MSE against this reference is recorded.
    pub mse_reference: Option<crate::image::Image>,
    /// `--spp-range`: render only these samples of every pixel (with the
    /// sampler indices a full render uses) and write a partial image that
    /// carries the film's sums ([`crate::film::merge_sample_ranges`]).
    /// Integrators that do not render pixel samples refuse it.
    pub sample_range: Option<crate::film::SampleRange>,
    /// Someone watching the image as it refines (`--preview`,
    /// `--display-server`). `None` costs nothing; otherwise the loops ask
    /// [`RenderObserver::wants_image`] after each unit of work and hand
    /// over a [`Snapshot`] when it says yes, and always at the end.
    pub observer: Option<Arc<dyn RenderObserver>>,
    /// `--wavefront`: render with the wavefront path tracer (many paths
    /// per thread at once; the same image) where the integrator has one
    /// ([`crate::integrator::Integrator::has_wavefront`]).
    pub wavefront: bool,
    /// The SIMD level the wavefront's kernels run at; `None`: the
    /// process's ([`crate::simd::level`]). Tests set it to compare widths
    /// within one process.
    pub simd: Option<crate::simd::SimdLevel>,
    /// Where the wavefront loop adds its time per stage (`--stats`);
    /// `None`: it reads no clock.
    pub stage_times: Option<Arc<super::StageTimes>>,
}

/// The image of a render in progress, as the film would write its R, G
/// and B channels now.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Width in pixels (the film's active bounds: its pixel bounds, or
    /// the part of them `--tile` renders).
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `3 × width × height` output-RGB values, rows from the top.
    pub rgb: Vec<f32>,
    /// Samples per pixel (SPPM: iterations) that every pixel has; pixels
    /// of tiles finished in the running wave have more.
    pub spp: i32,
    /// True for the final image, the one written to the file (in an
    /// interactive render: the image with all its samples for a camera).
    pub done: bool,
    /// The camera it was rendered from: 0, the scene's; in an interactive
    /// render, the number of the [`CameraChange`] since.
    pub camera: u64,
}

/// A camera an interactive render goes on with ([`RenderObserver::take_camera`]).
#[derive(Clone, Debug)]
pub struct CameraChange {
    /// Its number, which the snapshots rendered from it carry (greater than
    /// those before it; 0 is the scene's own camera).
    pub number: u64,
    /// The camera: the scene's, placed elsewhere
    /// ([`crate::camera::Camera::placed`]), or the scene's own again.
    pub camera: crate::camera::Camera,
}

/// Watches a render as it runs (the command line's live view and tev
/// client). Called from worker threads: both methods must be quick, and
/// [`RenderObserver::image`] should hand the snapshot on rather than work
/// on it.
pub trait RenderObserver: Send + Sync {
    /// Whether a new snapshot is wanted now. Asked after every tile (MLT
    /// chain, SPPM iteration); `wave_end` is true when a wave of samples
    /// has just completed.
    fn wants_image(&self, wave_end: bool) -> bool;
    /// A new snapshot.
    fn image(&self, snapshot: Snapshot);
    /// Whether the render is interactive (`--interactive`): it goes on
    /// until interrupted, starts again from the first sample whenever
    /// [`RenderObserver::take_camera`] has a camera, and waits for one once
    /// the image has all its samples. Default: no.
    fn interactive(&self) -> bool {
        false
    }
    /// Whether a camera waits to be taken (asked every few milliseconds
    /// while an interactive render runs: keep it cheap).
    fn camera_pending(&self) -> bool {
        false
    }
    /// The latest camera asked for since the last one taken, waiting at
    /// most `timeout` for one.
    fn take_camera(&self, timeout: Duration) -> Option<CameraChange> {
        let _ = timeout;
        None
    }
}

impl std::fmt::Debug for dyn RenderObserver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("RenderObserver")
    }
}

impl RenderOptions {
    /// True once the interrupt flag is set.
    #[inline]
    pub(crate) fn interrupted(&self) -> bool {
        self.interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// The observer, when there is one and it wants a snapshot now.
    #[inline]
    pub(crate) fn observer_wanting(&self, wave_end: bool) -> Option<&dyn RenderObserver> {
        self.observer.as_deref().filter(|o| o.wants_image(wave_end))
    }

    /// Hands the final image to the observer, if any.
    pub(crate) fn observe_final(&self, film: &crate::film::Film, spp: i32, splat_scale: Float) {
        if let Some(o) = &self.observer {
            o.image(snapshot(film, std::iter::empty(), spp, splat_scale, true));
        }
    }
}

/// A snapshot of `film` with `tiles` (finished, not yet merged) added.
pub(crate) fn snapshot<'t>(
    film: &crate::film::Film,
    tiles: impl IntoIterator<Item = &'t crate::film::FilmTile>,
    spp: i32,
    splat_scale: Float,
    done: bool,
) -> Snapshot {
    let d = film.active_bounds().diagonal();
    Snapshot {
        width: d.x.max(0) as usize,
        height: d.y.max(0) as usize,
        rgb: film.rgb_snapshot(tiles, splat_scale),
        spp,
        done,
        camera: 0,
    }
}

/// What a render measured (for `--stats`).
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    /// Wall-clock rendering time.
    pub render_time: Duration,
    /// Samples taken in total.
    pub samples: u64,
    /// True when the render was interrupted (Ctrl-C).
    pub interrupted: bool,
    /// (samples per pixel, MSE against the reference) after each wave, when
    /// a reference image was given (the `function` integrator: against
    /// the true integral, after each reported sample count).
    pub mse_per_wave: Vec<(i32, f64)>,
    /// Warnings about the result, for the caller to show (the library
    /// never prints).
    pub warnings: Vec<String>,
}

/// How far a render has come, reported to the caller's progress callback.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Units of work done (camera samples, for the per-ray integrators).
    pub done: u64,
    /// Units of work in the whole render.
    pub total: u64,
    /// Time since the render started.
    pub elapsed: Duration,
}

/// Why a render failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum RenderError {
    /// The worker thread pool could not be started.
    ThreadPool(rayon::ThreadPoolBuildError),
    /// The image could not be compared with the MSE reference image (a
    /// different resolution or channels).
    MseReference(ImageError),
    /// The (partial or final) image could not be written.
    WriteImage {
        /// The file.
        path: String,
        /// Why.
        source: ImageError,
    },
    /// A text output file (the `function` integrator's errors) could not
    /// be written.
    WriteFile {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A partial render (`--spp-range`) cannot be made as asked.
    Partial(crate::film::PartialError),
    /// The integrator cannot render this way (interactively).
    Unsupported(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::ThreadPool(e) => write!(f, "cannot start worker threads: {e}"),
            RenderError::MseReference(e) => write!(f, "--mse-reference-image: {e}"),
            // The image errors that name a file name this one.
            RenderError::WriteImage { path, source } => match source {
                ImageError::Io { .. } | ImageError::Format { .. } => write!(f, "{source}"),
                ImageError::Invalid(m) => write!(f, "{path}: {m}"),
            },
            RenderError::WriteFile { path, source } => write!(f, "{path}: {source}"),
            RenderError::Partial(e) => write!(f, "{e}"),
            RenderError::Unsupported(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::ThreadPool(e) => Some(e),
            RenderError::MseReference(e) => Some(e),
            RenderError::WriteImage { source, .. } => Some(source),
            RenderError::WriteFile { source, .. } => Some(source),
            RenderError::Partial(e) => Some(e),
            RenderError::Unsupported(_) => None,
        }
    }
}

/// The worker pool a render runs on (`opts.nthreads` threads; 0: all
/// cores).
pub(crate) fn thread_pool(opts: &RenderOptions) -> Result<rayon::ThreadPool, RenderError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(opts.nthreads)
        .build()
        .map_err(RenderError::ThreadPool)
}

/// The progress callback's type: called from a reporting thread, so `Sync`.
pub type ProgressFn<'a> = &'a (dyn Fn(Progress) + Sync);

/// How often the reporting thread calls the progress callback.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(250);

/// Runs `work` while a thread reports its progress to `progress` every
/// [`PROGRESS_INTERVAL`] (from the start) and once more after it returns.
/// `work` counts the units it finishes in the counter it is given, out of
/// `total`; the last report has the count it reached (`total` unless it
/// stopped early). Any render loop can use it: the tile loop counts camera
/// samples, a loop of its own counts its own units.
pub(crate) fn with_progress<R>(
    total: u64,
    start: Instant,
    progress: ProgressFn,
    work: impl FnOnce(&AtomicU64) -> R,
) -> R {
    let done = AtomicU64::new(0);
    let running = AtomicBool::new(true);
    let report = |done: &AtomicU64| {
        progress(Progress {
            done: done.load(Ordering::Relaxed),
            total,
            elapsed: start.elapsed(),
        })
    };
    let result = std::thread::scope(|threads| {
        let reporter = threads.spawn(|| {
            while running.load(Ordering::Relaxed) {
                report(&done);
                // Woken early when the work ends.
                std::thread::park_timeout(PROGRESS_INTERVAL);
            }
        });
        let result = work(&done);
        running.store(false, Ordering::Relaxed);
        reporter.thread().unpark();
        result
    });
    // After the reporter has ended: this report is the last.
    report(&done);
    result
}

/// Writes the film's image to its file, splats weighted by `splat_scale`
/// (pbrt-v4 `Film::WriteImage`).
/// Writes a sample-range partial image (its own RGB and the film's sums)
/// to the film's file.
pub(crate) fn write_partial(
    film: &crate::film::Film,
    metadata: &crate::image::ImageMetadata,
    range: crate::film::SampleRange,
    spp: i32,
) -> Result<(), RenderError> {
    let mut md = metadata.clone();
    let image = film
        .partial_image(&mut md, range, spp)
        .map_err(RenderError::Partial)?;
    image
        .write(film.filename(), &md)
        .map_err(|source| RenderError::WriteImage {
            path: film.filename().to_string(),
            source,
        })
}

pub(crate) fn write_film(
    film: &crate::film::Film,
    metadata: &crate::image::ImageMetadata,
    splat_scale: Float,
) -> Result<(), RenderError> {
    film.write_image(metadata, splat_scale)
        .map_err(|source| RenderError::WriteImage {
            path: film.filename().to_string(),
            source,
        })
}
