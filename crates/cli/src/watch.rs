//! Watching a render: the [`RenderObserver`] that `--preview` and
//! `--display-server` share. The render loops hand it snapshots of the
//! film; it keeps the latest one (numbered) with the latest progress
//! report, for the HTTP server and the tev client to read from their own
//! threads. Snapshots are taken only while someone is watching and at
//! most every [`SNAPSHOT_INTERVAL`] (oftener at the end of a wave), so
//! the render pays a film read now and then, never more. With
//! [`Watch::keep_wave_ends`] the ends of waves are kept even while nobody
//! watches, so that a page opened mid-render has an image at once rather
//! than when the next tile of a long wave finishes (minutes at high
//! sample counts).

use rpbrt_render::integrator::{CameraChange, Progress, RenderObserver, Snapshot};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Least time between two snapshots taken while a wave runs.
pub const SNAPSHOT_INTERVAL: Duration = Duration::from_millis(700);
/// Least time between two snapshots taken at the ends of waves.
const WAVE_END_INTERVAL: Duration = Duration::from_millis(100);
/// A browser that asked nothing for this long is taken to be gone.
pub const VIEWER_TIMEOUT: Duration = Duration::from_secs(5);

/// A numbered snapshot.
#[derive(Debug)]
pub struct Frame {
    /// 1, 2, 3, … in the order the snapshots came.
    pub version: u64,
    /// The image.
    pub snapshot: Snapshot,
}

/// What the watchers read.
#[derive(Debug, Default)]
pub struct State {
    /// The latest snapshot.
    pub frame: Option<Arc<Frame>>,
    /// The latest progress report.
    pub progress: Option<Progress>,
    /// Set when the render has ended (its final image is the frame).
    pub finished: bool,
    /// The image's name (the file it is written to).
    pub title: String,
}

/// The shared state of a watched render.
#[derive(Debug)]
pub struct Watch {
    state: Mutex<State>,
    changed: Condvar,
    start: Instant,
    /// Milliseconds from `start` of the last snapshot claimed (`u64::MAX`:
    /// none yet).
    last_snapshot_ms: AtomicU64,
    /// Milliseconds from `start` when a viewer last asked for something
    /// (`u64::MAX`: never).
    last_viewer_ms: AtomicU64,
    /// A consumer that always wants images (the tev client).
    always: AtomicBool,
    /// Snapshots at the ends of waves are wanted even with nobody watching.
    wave_ends: AtomicBool,
    /// `--interactive`: the render takes cameras from [`Watch::propose_camera`].
    interactive: AtomicBool,
    /// The camera proposed and not yet taken (the latest wins), and
    /// whether there is one (read by the render every few milliseconds).
    camera: Mutex<Option<CameraChange>>,
    camera_waiting: AtomicBool,
    camera_changed: Condvar,
}

impl Default for Watch {
    fn default() -> Self {
        Watch::new()
    }
}

impl Watch {
    /// Nothing seen yet, nobody watching.
    pub fn new() -> Self {
        Watch {
            state: Mutex::new(State::default()),
            changed: Condvar::new(),
            start: Instant::now(),
            last_snapshot_ms: AtomicU64::new(u64::MAX),
            last_viewer_ms: AtomicU64::new(u64::MAX),
            always: AtomicBool::new(false),
            wave_ends: AtomicBool::new(false),
            interactive: AtomicBool::new(false),
            camera: Mutex::new(None),
            camera_waiting: AtomicBool::new(false),
            camera_changed: Condvar::new(),
        }
    }

    fn now_ms(&self) -> u64 {
        self.start.elapsed().as_millis() as u64
    }

    /// The state, for reading (a panicked holder leaves it usable).
    pub fn state(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Records that a viewer asked for something now: snapshots are
    /// taken while one has within [`VIEWER_TIMEOUT`].
    pub fn viewer_seen(&self) {
        self.last_viewer_ms.store(self.now_ms(), Ordering::Relaxed);
    }

    /// Whether a viewer asked for something within [`VIEWER_TIMEOUT`].
    pub fn viewer_recent(&self) -> bool {
        let seen = self.last_viewer_ms.load(Ordering::Relaxed);
        seen != u64::MAX && self.now_ms().saturating_sub(seen) < VIEWER_TIMEOUT.as_millis() as u64
    }

    /// Snapshots are wanted whether or not a browser watches (tev).
    pub fn always_want(&self) {
        self.always.store(true, Ordering::Relaxed);
    }

    /// Snapshots at the ends of waves are wanted whether or not a browser
    /// watches (`--preview`): a page that connects later is served the
    /// latest at once. A wave's end is rare and its snapshot a film read.
    pub fn keep_wave_ends(&self) {
        self.wave_ends.store(true, Ordering::Relaxed);
    }

    /// Makes the render interactive ([`RenderObserver::interactive`]).
    pub fn set_interactive(&self) {
        self.interactive.store(true, Ordering::Relaxed);
    }

    /// Whether the render is interactive.
    pub fn is_interactive(&self) -> bool {
        self.interactive.load(Ordering::Relaxed)
    }

    /// Asks the render to go on from `change`, replacing a camera proposed
    /// and not yet taken.
    pub fn propose_camera(&self, change: CameraChange) {
        let mut c = self.camera.lock().unwrap_or_else(|e| e.into_inner());
        *c = Some(change);
        self.camera_waiting.store(true, Ordering::Release);
        drop(c);
        self.camera_changed.notify_all();
    }

    /// Names the image (the file it is written to).
    pub fn set_title(&self, title: &str) {
        self.state().title = title.to_string();
    }

    /// Records a progress report.
    pub fn progress(&self, p: Progress) {
        self.state().progress = Some(p);
    }

    /// Marks the render ended and wakes everyone waiting.
    pub fn finish(&self) {
        self.state().finished = true;
        self.changed.notify_all();
    }

    /// Waits until the frame is newer than `version` or the render has
    /// finished, at most `timeout`; returns the state then.
    pub fn wait_newer(&self, version: u64, timeout: Duration) -> MutexGuard<'_, State> {
        let guard = self.state();
        let (guard, _) = self
            .changed
            .wait_timeout_while(guard, timeout, |s| {
                !s.finished && s.frame.as_ref().map_or(0, |f| f.version) <= version
            })
            .unwrap_or_else(|e| e.into_inner());
        guard
    }
}

impl RenderObserver for Watch {
    fn wants_image(&self, wave_end: bool) -> bool {
        let kept = wave_end && self.wave_ends.load(Ordering::Relaxed);
        if !kept && !self.always.load(Ordering::Relaxed) && !self.viewer_recent() {
            return false;
        }
        let interval = if wave_end {
            WAVE_END_INTERVAL
        } else {
            SNAPSHOT_INTERVAL
        };
        let now = self.now_ms();
        let last = self.last_snapshot_ms.load(Ordering::Relaxed);
        if last != u64::MAX && now.saturating_sub(last) < interval.as_millis() as u64 {
            return false;
        }
        // One thread of those asking at once gets it.
        self.last_snapshot_ms
            .compare_exchange(last, now, Ordering::Relaxed, Ordering::Relaxed)
            .is_ok()
    }

    fn image(&self, snapshot: Snapshot) {
        let mut s = self.state();
        let version = s.frame.as_ref().map_or(0, |f| f.version) + 1;
        s.frame = Some(Arc::new(Frame { version, snapshot }));
        drop(s);
        self.changed.notify_all();
    }

    fn interactive(&self) -> bool {
        self.is_interactive()
    }

    fn camera_pending(&self) -> bool {
        self.camera_waiting.load(Ordering::Acquire)
    }

    fn take_camera(&self, timeout: Duration) -> Option<CameraChange> {
        let guard = self.camera.lock().unwrap_or_else(|e| e.into_inner());
        let (mut guard, _) = self
            .camera_changed
            .wait_timeout_while(guard, timeout, |c| c.is_none())
            .unwrap_or_else(|e| e.into_inner());
        let taken = guard.take();
        self.camera_waiting.store(false, Ordering::Release);
        taken
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn snap(done: bool) -> Snapshot {
        Snapshot {
            width: 1,
            height: 1,
            rgb: vec![0.5; 3],
            spp: 1,
            done,
            camera: 0,
        }
    }

    #[test]
    fn snapshots_only_while_watched_and_not_too_often() {
        let w = Watch::new();
        assert!(!w.wants_image(false) && !w.wants_image(true));
        w.viewer_seen();
        assert!(w.wants_image(false));
        // Claimed: the next asker within the interval is refused.
        assert!(!w.wants_image(false));
        let w = Watch::new();
        w.always_want();
        assert!(w.wants_image(true));
        assert!(!w.wants_image(true));
        std::thread::sleep(WAVE_END_INTERVAL + Duration::from_millis(20));
        assert!(w.wants_image(true));
    }

    #[test]
    fn frames_are_numbered_and_waiters_wake() {
        let w = Arc::new(Watch::new());
        assert!(w.state().frame.is_none());
        let w2 = Arc::clone(&w);
        let t = std::thread::spawn(move || {
            w2.wait_newer(0, Duration::from_secs(20))
                .frame
                .as_ref()
                .map(|f| f.version)
        });
        w.image(snap(false));
        assert_eq!(t.join().unwrap(), Some(1));
        w.image(snap(true));
        let s = w.wait_newer(1, Duration::from_secs(1));
        assert_eq!(
            s.frame.as_ref().map(|f| (f.version, f.snapshot.done)),
            Some((2, true))
        );
        drop(s);
        // Nothing newer: returns at the timeout, or at once once finished.
        let t0 = Instant::now();
        drop(w.wait_newer(2, Duration::from_millis(50)));
        assert!(t0.elapsed() >= Duration::from_millis(50));
        w.finish();
        assert!(w.wait_newer(2, Duration::from_secs(20)).finished);
    }
}
