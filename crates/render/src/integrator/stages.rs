//! Where the wavefront loop's time goes, stage by stage (`--stats`): each
//! worker thread times the stages of its pool passes with the monotonic
//! clock (two clock reads per stage per pass of a few hundred paths, so
//! the cost is far below the timings' own noise) and adds its totals to a
//! shared [`StageTimes`] when its tile is done. The totals are thread
//! time: with two threads they add up to about twice the wall time.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A stage of the wavefront loop's pass over its pool of paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stage {
    /// New paths: their pixel samples, camera draws and camera rays.
    Camera,
    /// The closest hits of every path's ray.
    Trace,
    /// The vertices' sampler draws, taken together.
    VertexDraws,
    /// The diffuse and specular vertices' surfaces, in lanes.
    Surfaces,
    /// The first half of every vertex.
    Begin,
    /// The light samples.
    Lights,
    /// The other BSDFs' queries, in lanes.
    Bsdfs,
    /// The diffuse vertices' BSDF values and samples, in lanes.
    Scatters,
    /// The second half of every vertex.
    Finish,
    /// The shadow rays.
    Shadow,
    /// Finished paths added to the image.
    Retire,
}

impl Stage {
    /// Every stage, in the pass's order.
    const ALL: [Stage; 11] = [
        Stage::Camera,
        Stage::Trace,
        Stage::VertexDraws,
        Stage::Surfaces,
        Stage::Begin,
        Stage::Lights,
        Stage::Bsdfs,
        Stage::Scatters,
        Stage::Finish,
        Stage::Shadow,
        Stage::Retire,
    ];

    /// The name `--stats` prints.
    fn name(self) -> &'static str {
        match self {
            Stage::Camera => "camera samples and rays",
            Stage::Trace => "closest hits",
            Stage::VertexDraws => "vertex sampler draws",
            Stage::Surfaces => "surfaces (lanes)",
            Stage::Begin => "vertex first halves",
            Stage::Lights => "light samples",
            Stage::Bsdfs => "other BSDFs (lanes)",
            Stage::Scatters => "diffuse BSDFs (lanes)",
            Stage::Finish => "vertex second halves",
            Stage::Shadow => "shadow rays",
            Stage::Retire => "finished samples to film",
        }
    }
}

/// The wavefront loop's time per stage, summed over threads and tiles.
#[derive(Debug, Default)]
pub struct StageTimes {
    nanos: [AtomicU64; Stage::ALL.len()],
}

impl StageTimes {
    /// No time yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Each stage's name and thread time, in the pass's order.
    pub fn totals(&self) -> Vec<(&'static str, Duration)> {
        Stage::ALL
            .iter()
            .zip(&self.nanos)
            .map(|(s, n)| (s.name(), Duration::from_nanos(n.load(Ordering::Relaxed))))
            .collect()
    }
}

/// One thread's clock over the stages of its passes: does nothing without
/// a [`StageTimes`] to report to.
pub(crate) struct StageClock<'a> {
    sink: Option<&'a StageTimes>,
    /// The stage being timed and when it began.
    current: Option<(Stage, Instant)>,
    nanos: [u64; Stage::ALL.len()],
}

impl<'a> StageClock<'a> {
    /// A clock reporting to `sink` when dropped.
    pub(crate) fn new(sink: Option<&'a StageTimes>) -> Self {
        StageClock {
            sink,
            current: None,
            nanos: [0; Stage::ALL.len()],
        }
    }

    /// Ends the current stage and begins `stage`.
    #[inline]
    pub(crate) fn enter(&mut self, stage: Stage) {
        if self.sink.is_none() {
            return;
        }
        let now = Instant::now();
        self.end_at(now);
        self.current = Some((stage, now));
    }

    fn end_at(&mut self, now: Instant) {
        if let Some((s, since)) = self.current.take() {
            self.nanos[s as usize] += now.saturating_duration_since(since).as_nanos() as u64;
        }
    }
}

impl Drop for StageClock<'_> {
    fn drop(&mut self) {
        let Some(sink) = self.sink else { return };
        self.end_at(Instant::now());
        for (total, &n) in sink.nanos.iter().zip(&self.nanos) {
            total.fetch_add(n, Ordering::Relaxed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clock_adds_its_stages_to_the_totals_and_nothing_without_a_sink() {
        let times = StageTimes::new();
        {
            let mut c = StageClock::new(Some(&times));
            c.enter(Stage::Trace);
            std::thread::sleep(Duration::from_millis(20));
            c.enter(Stage::Shadow);
            std::thread::sleep(Duration::from_millis(5));
        }
        let t = times.totals();
        assert_eq!(t.len(), Stage::ALL.len());
        let get = |name: &str| t.iter().find(|(n, _)| *n == name).map(|x| x.1).unwrap();
        assert!(get("closest hits") >= Duration::from_millis(20));
        assert!(get("shadow rays") >= Duration::from_millis(5));
        assert_eq!(get("light samples"), Duration::ZERO);
        let mut idle = StageClock::new(None);
        idle.enter(Stage::Trace);
        assert!(idle.current.is_none());
    }
}
