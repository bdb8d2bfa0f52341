//! Primary sample space for MLT (pbrt-v4 `MLTSampler`, `samplers.h/.cpp`;
//! Kelemen et al. 2002): a vector of uniform values that the path
//! generator reads as its random numbers, mutated by large steps (fresh
//! values) and small steps (normal perturbations, wrapped to [0, 1)),
//! with lazy updates and backups for rejected proposals.

use crate::rng::{mix_bits, Rng};
use crate::sampler::SampleSource;
use rpbrt_geometry::float::{Float, PI};
use rpbrt_geometry::tuple::Point2f;

/// One primary sample with what undoing a mutation needs.
#[derive(Clone, Copy, Debug, Default)]
struct PrimarySample {
    value: Float,
    last_modification_iteration: i64,
    value_backup: Float,
    modify_backup: i64,
}

impl PrimarySample {
    fn backup(&mut self) {
        self.value_backup = self.value;
        self.modify_backup = self.last_modification_iteration;
    }
    fn restore(&mut self) {
        self.value = self.value_backup;
        self.last_modification_iteration = self.modify_backup;
    }
}

/// The longest primary-sample vector a path may read (a guard: paths
/// read a few dozen values per vertex).
const MAX_SAMPLES: usize = 1 << 16;

/// pbrt-v4's `MLTSampler`.
#[derive(Clone, Debug)]
pub(crate) struct MltSampler {
    rng: Rng,
    sigma: Float,
    large_step_probability: Float,
    stream_count: usize,
    x: Vec<PrimarySample>,
    current_iteration: i64,
    large_step: bool,
    last_large_step_iteration: i64,
    stream_index: usize,
    sample_index: usize,
}

impl MltSampler {
    /// The sampler of bootstrap path `rng_sequence_index` (a chain
    /// continues from its bootstrap path's state).
    pub(crate) fn new(
        rng_sequence_index: u64,
        seed: u64,
        sigma: Float,
        large_step_probability: Float,
        stream_count: usize,
    ) -> Self {
        MltSampler {
            rng: Rng::with_sequence(mix_bits(rng_sequence_index) ^ mix_bits(seed)),
            sigma,
            large_step_probability,
            stream_count,
            x: Vec::new(),
            current_iteration: 0,
            large_step: true,
            last_large_step_iteration: 0,
            stream_index: 0,
            sample_index: 0,
        }
    }

    /// Starts a proposal: a large step with the configured probability.
    pub(crate) fn start_iteration(&mut self) {
        self.current_iteration += 1;
        self.large_step = self.rng.uniform_float() < self.large_step_probability;
    }

    /// The proposal was accepted.
    pub(crate) fn accept(&mut self) {
        if self.large_step {
            self.last_large_step_iteration = self.current_iteration;
        }
    }

    /// The proposal was rejected: the values it changed are restored.
    pub(crate) fn reject(&mut self) {
        let it = self.current_iteration;
        for xi in &mut self.x {
            if xi.last_modification_iteration == it {
                xi.restore();
            }
        }
        self.current_iteration -= 1;
    }

    /// Reads from stream `index` from its start (streams interleave in the
    /// vector so that each strategy's vertices keep their values).
    pub(crate) fn start_stream(&mut self, index: usize) {
        self.stream_index = index;
        self.sample_index = 0;
    }

    fn next_index(&mut self) -> usize {
        let i = self.stream_index + self.stream_count * self.sample_index;
        self.sample_index += 1;
        i
    }

    /// A standard normal variate (Box–Muller from two uniform values).
    fn normal(&mut self) -> Float {
        let u1 = 1.0 - self.rng.uniform_float();
        let u2 = self.rng.uniform_float();
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }

    /// Brings value `index` up to the current iteration (pbrt-v4
    /// `EnsureReady`).
    fn ensure_ready(&mut self, index: usize) -> Float {
        if index >= MAX_SAMPLES {
            // Beyond the guard: a fresh value, not tracked.
            return self.rng.uniform_float();
        }
        if index >= self.x.len() {
            self.x.resize(index + 1, PrimarySample::default());
        }
        let last_large = self.last_large_step_iteration;
        if self.x[index].last_modification_iteration < last_large {
            let v = self.rng.uniform_float();
            let xi = &mut self.x[index];
            xi.value = v;
            xi.last_modification_iteration = last_large;
        }
        self.x[index].backup();
        if self.large_step {
            let v = self.rng.uniform_float();
            self.x[index].value = v;
        } else {
            let n_small = self.current_iteration - self.x[index].last_modification_iteration;
            let eff_sigma = self.sigma * (n_small as Float).sqrt();
            let delta = eff_sigma * self.normal();
            let xi = &mut self.x[index];
            xi.value += delta;
            xi.value -= xi.value.floor();
            if xi.value >= 1.0 {
                // A tiny negative delta can round up to exactly 1.
                xi.value = 0.0;
            }
        }
        self.x[index].last_modification_iteration = self.current_iteration;
        self.x[index].value
    }
}

impl SampleSource for MltSampler {
    #[inline]
    fn get_1d(&mut self) -> Float {
        let i = self.next_index();
        self.ensure_ready(i)
    }
    #[inline]
    fn get_2d(&mut self) -> Point2f {
        let x = self.get_1d();
        let y = self.get_1d();
        Point2f::new(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejected_proposals_restore_the_values() {
        let mut s = MltSampler::new(7, 0, 0.01, 0.3, 3);
        s.start_stream(0);
        let a: Vec<Float> = (0..5).map(|_| s.get_1d()).collect();
        s.accept();
        for _ in 0..20 {
            s.start_iteration();
            s.start_stream(0);
            let b: Vec<Float> = (0..5).map(|_| s.get_1d()).collect();
            assert!(b.iter().all(|v| (0.0..1.0).contains(v)));
            s.reject();
        }
        // The next proposal starts again from the accepted state: a small
        // step stays close to it.
        loop {
            s.start_iteration();
            if !s.large_step {
                break;
            }
            s.reject();
        }
        s.start_stream(0);
        let c: Vec<Float> = (0..5).map(|_| s.get_1d()).collect();
        for (x, y) in a.iter().zip(&c) {
            let d = (x - y).abs().min(1.0 - (x - y).abs());
            assert!(d < 0.1, "{x} vs {y}");
        }
    }

    #[test]
    fn streams_interleave() {
        let mut s = MltSampler::new(1, 0, 0.01, 0.3, 3);
        s.start_stream(1);
        let _ = s.get_1d();
        let _ = s.get_1d();
        // Stream 1's second value is entry 1 + 3.
        assert_eq!(s.x.len(), 5);
    }
}
