//! Splats in a fixed order: what makes light-tracing integrators
//! deterministic. pbrt-v4's `Film::AddSplat` adds into atomic doubles from
//! whichever thread gets there first, so the image depends on the thread
//! count and on timing. Here a unit of work (an image tile, an MLT chain)
//! records its splats in a [`SplatBuffer`]; [`OrderedSplats`] applies the
//! buffers to the film in the units' index order, whatever order they
//! finish in, so the sums are the same float additions in the same order
//! on every run.

use std::collections::BTreeMap;
use std::sync::Mutex;

use rpbrt_geometry::Point2f;

use super::Film;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// One recorded splat: `Film::add_splat`'s arguments.
#[derive(Clone, Copy, Debug)]
struct Splat {
    /// Which film: 0 the render's, k ≥ 1 the k-th extra film (bdpt's
    /// strategy images).
    film: u32,
    p: Point2f,
    l: SampledSpectrum,
    lambda: SampledWavelengths,
}

/// The splats of one unit of work, in the order it made them.
#[derive(Clone, Debug, Default)]
pub struct SplatBuffer {
    splats: Vec<Splat>,
}

impl SplatBuffer {
    /// An empty buffer.
    pub fn new() -> Self {
        SplatBuffer::default()
    }

    /// Records a splat of radiance `l` at continuous raster position `p`.
    #[inline]
    pub fn add(&mut self, p: Point2f, l: SampledSpectrum, lambda: &SampledWavelengths) {
        self.add_to(0, p, l, lambda);
    }

    /// Records a splat for film `film` (0: the render's film; k ≥ 1: the
    /// k-th extra film of the render loop).
    #[inline]
    pub fn add_to(
        &mut self,
        film: usize,
        p: Point2f,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
    ) {
        self.splats.push(Splat {
            film: film as u32,
            p,
            l,
            lambda: *lambda,
        });
    }

    /// The number of splats recorded.
    pub fn len(&self) -> usize {
        self.splats.len()
    }

    /// Forgets the splats, keeping the memory.
    pub fn clear(&mut self) {
        self.splats.clear();
    }

    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.splats.is_empty()
    }

    /// Adds the splats to their films (`films[k]` for film index k) in
    /// the order they were recorded.
    pub fn apply(&self, films: &[&Film]) {
        for s in &self.splats {
            if let Some(f) = films.get(s.film as usize) {
                f.add_splat(s.p, s.l, &s.lambda);
            }
        }
    }
}

/// Buffers waiting for their turn, and whether a thread is applying.
#[derive(Default)]
struct Pending {
    /// The index of the next buffer to apply.
    next: usize,
    /// Finished buffers with higher indices.
    waiting: BTreeMap<usize, SplatBuffer>,
    /// A thread is applying buffers (outside the lock).
    applying: bool,
    /// Applied buffers, emptied, for [`OrderedSplats::buffer`] to hand
    /// out again (their memory stays allocated).
    free: Vec<SplatBuffer>,
}

/// Emptied buffers kept for reuse.
const FREE_BUFFERS: usize = 64;

/// Applies numbered [`SplatBuffer`]s to a film in index order (0, 1, 2, …)
/// as they are submitted from any thread. A buffer submitted early waits
/// until all lower indices have been applied; the thread that submits the
/// next-needed buffer applies it and every waiting successor, while other
/// threads only queue theirs. Hand out the indices in order (a shared
/// counter) so that few buffers wait at any time.
#[derive(Default)]
pub struct OrderedSplats {
    pending: Mutex<Pending>,
}

impl OrderedSplats {
    /// Nothing applied yet: the first buffer expected is number 0.
    pub fn new() -> Self {
        OrderedSplats::default()
    }

    /// An empty buffer, reusing the memory of one already applied.
    pub fn buffer(&self) -> SplatBuffer {
        self.pending
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .free
            .pop()
            .unwrap_or_default()
    }

    /// Submits buffer `index`; applies what has become applicable.
    pub fn submit(&self, films: &[&Film], index: usize, buffer: SplatBuffer) {
        let lock = || self.pending.lock().unwrap_or_else(|e| e.into_inner());
        let mut p = lock();
        p.waiting.insert(index, buffer);
        if p.applying {
            // The applying thread picks it up when its turn comes.
            return;
        }
        p.applying = true;
        loop {
            let next = p.next;
            let Some(buf) = p.waiting.remove(&next) else {
                p.applying = false;
                return;
            };
            drop(p);
            let mut buf = buf;
            buf.apply(films);
            buf.clear();
            p = lock();
            p.next += 1;
            if p.free.len() < FREE_BUFFERS {
                p.free.push(buf);
            }
        }
    }

    /// The number of buffers applied so far.
    pub fn applied(&self) -> usize {
        self.pending.lock().unwrap_or_else(|e| e.into_inner()).next
    }
}
