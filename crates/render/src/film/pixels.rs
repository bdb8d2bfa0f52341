//! Per-pixel accumulation shared by the film and its tiles: weighted
//! sensor-RGB sums, G-buffer sums and spectral buckets, plus lock-free
//! splat storage (pbrt-v4 `RGBFilm::Pixel`, `GBufferFilm::Pixel`,
//! `SpectralFilm::Pixel`).

use std::sync::atomic::{AtomicU64, Ordering};

use rpbrt_geometry::{AnimatedTransform, Bounds2i, Float, Point2i};

use super::sensor::PixelSensor;
use super::VisibleSurface;
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths, CIE_Y_INTEGRAL};

/// Welford's running mean and variance (pbrt-v4 `VarianceEstimator`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VarianceEstimator {
    mean: f64,
    s: f64,
    n: i64,
}

impl VarianceEstimator {
    /// Adds one value.
    pub fn add(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.s += d * (x - self.mean);
    }
    /// The sample variance (zero for fewer than two values).
    pub fn variance(&self) -> f64 {
        if self.n > 1 {
            self.s / (self.n - 1) as f64
        } else {
            0.0
        }
    }
    /// Variance over mean (zero when undefined).
    pub fn relative_variance(&self) -> f64 {
        if self.n < 1 || self.mean == 0.0 {
            0.0
        } else {
            self.variance() / self.mean
        }
    }
    /// Combines another estimator's values into this one (Chan et al.).
    pub fn merge(&mut self, o: &VarianceEstimator) {
        if o.n == 0 {
            return;
        }
        let (n, m) = (self.n as f64, o.n as f64);
        self.s = self.s + o.s + (o.mean - self.mean).powi(2) * n * m / (n + m);
        self.mean = (n * self.mean + m * o.mean) / (n + m);
        self.n += o.n;
    }
}

/// What a film accumulates beyond RGB, and the constants every sample
/// needs; shared (immutably) between a film and its tiles.
#[derive(Debug)]
pub struct SampleConfig {
    /// The sensor turning radiance into sensor RGB.
    pub sensor: PixelSensor,
    /// Largest sensor RGB component a sample may have (`maxcomponentvalue`).
    pub max_component_value: Float,
    /// The film kind's extra state.
    pub kind: KindConfig,
}

/// Film-kind specific constants.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // one per film, never in a hot array
pub enum KindConfig {
    /// RGB only.
    Rgb,
    /// G-buffer: where positions and normals are expressed.
    GBuffer {
        /// Output space from render space.
        output_from_render: AnimatedTransform,
        /// Whether `output_from_render` is applied inverted (camera space).
        apply_inverse: bool,
        /// The colour space albedo is converted to.
        color_space: &'static RgbColorSpace,
    },
    /// Spectral buckets over `[lambda_min, lambda_max]`.
    Spectral {
        /// Shortest wavelength.
        lambda_min: Float,
        /// Longest wavelength.
        lambda_max: Float,
        /// Number of buckets.
        n_buckets: usize,
    },
}

impl KindConfig {
    /// The bucket of wavelength `lambda` (spectral films only).
    pub fn bucket(lambda: Float, min: Float, max: Float, n: usize) -> usize {
        let b = (n as Float * (lambda - min) / (max - min)) as i64;
        b.clamp(0, n as i64 - 1) as usize
    }
}

/// G-buffer sums of one pixel.
#[derive(Clone, Copy, Debug, Default)]
pub struct GBufferPixel {
    pub(crate) weight_sum: f64,
    pub(crate) p_sum: [f64; 3],
    pub(crate) dzdx_sum: f64,
    pub(crate) dzdy_sum: f64,
    pub(crate) n_sum: [f64; 3],
    pub(crate) ns_sum: [f64; 3],
    pub(crate) uv_sum: [f64; 2],
    pub(crate) albedo_sum: [f64; 3],
    pub(crate) variance: [VarianceEstimator; 3],
}

/// Accumulated sums over a rectangle of pixels.
#[derive(Clone, Debug)]
pub struct Pixels {
    /// The pixels covered.
    pub bounds: Bounds2i,
    /// Weighted sensor-RGB sums and weight sum per pixel.
    pub(crate) rgb: Vec<[f64; 4]>,
    /// G-buffer sums (empty for other kinds).
    pub(crate) gbuffer: Vec<GBufferPixel>,
    /// Spectral sums: per pixel `n` bucket sums then `n` weight sums.
    pub(crate) buckets: Vec<f64>,
    n_buckets: usize,
}

impl Pixels {
    /// Zeroed sums over `bounds` for a film of kind `kind`.
    pub fn new(bounds: Bounds2i, kind: &KindConfig) -> Self {
        let n = bounds.area().max(0) as usize;
        let (gb, nb) = match kind {
            KindConfig::Rgb => (0, 0),
            KindConfig::GBuffer { .. } => (n, 0),
            KindConfig::Spectral { n_buckets, .. } => (0, *n_buckets),
        };
        Pixels {
            bounds,
            rgb: vec![[0.0; 4]; n],
            gbuffer: vec![GBufferPixel::default(); gb],
            buckets: vec![0.0; 2 * nb * n],
            n_buckets: nb,
        }
    }

    /// Index of pixel `p` (which must lie inside `bounds`).
    #[inline]
    pub fn index(&self, p: Point2i) -> usize {
        debug_assert!(self.bounds.inside_exclusive(p));
        let w = (self.bounds.p_max.x - self.bounds.p_min.x) as usize;
        (p.y - self.bounds.p_min.y) as usize * w + (p.x - self.bounds.p_min.x) as usize
    }

    /// Adds a radiance sample to pixel `p` as pbrt-v4's `AddSample`.
    pub fn add_sample(
        &mut self,
        cfg: &SampleConfig,
        p: Point2i,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        vs: Option<&VisibleSurface>,
        weight: Float,
    ) {
        if !self.bounds.inside_exclusive(p) {
            debug_assert!(false, "sample outside the pixel bounds");
            return;
        }
        let i = self.index(p);
        let mut rgb = cfg.sensor.to_sensor_rgb(l, lambda);
        let m = rgb.max_component_value();
        if m > cfg.max_component_value {
            rgb = rgb * (cfg.max_component_value / m);
        }
        let w = weight as f64;
        let px = &mut self.rgb[i];
        px[0] += w * rgb.r as f64;
        px[1] += w * rgb.g as f64;
        px[2] += w * rgb.b as f64;
        px[3] += w;
        match &cfg.kind {
            KindConfig::Rgb => {}
            KindConfig::GBuffer {
                output_from_render,
                apply_inverse,
                color_space,
            } => {
                let Some(vs) = vs.filter(|v| v.set) else {
                    return;
                };
                let g = &mut self.gbuffer[i];
                g.weight_sum += w;
                for c in 0..3 {
                    g.variance[c].add([rgb.r, rgb.g, rgb.b][c] as f64);
                }
                let t = output_from_render.interpolate(vs.time);
                let (pp, n, ns, dpdx, dpdy) = if *apply_inverse {
                    (
                        t.apply_inverse_point(vs.p),
                        t.apply_inverse_normal(vs.n),
                        t.apply_inverse_normal(vs.ns),
                        t.apply_inverse_vector(vs.dpdx),
                        t.apply_inverse_vector(vs.dpdy),
                    )
                } else {
                    (
                        t.apply_point(vs.p),
                        t.apply_normal(vs.n),
                        t.apply_normal(vs.ns),
                        t.apply_vector(vs.dpdx),
                        t.apply_vector(vs.dpdy),
                    )
                };
                for c in 0..3 {
                    g.p_sum[c] += w * [pp.x, pp.y, pp.z][c] as f64;
                    g.n_sum[c] += w * [n.x, n.y, n.z][c] as f64;
                    g.ns_sum[c] += w * [ns.x, ns.y, ns.z][c] as f64;
                }
                g.dzdx_sum += w * dpdx.z as f64;
                g.dzdy_sum += w * dpdy.z as f64;
                g.uv_sum[0] += w * vs.uv.x as f64;
                g.uv_sum[1] += w * vs.uv.y as f64;
                let albedo = vs.albedo * color_space.illuminant.sample(lambda);
                let a = color_space.to_rgb(albedo.to_xyz(lambda));
                g.albedo_sum[0] += w * a.r as f64;
                g.albedo_sum[1] += w * a.g as f64;
                g.albedo_sum[2] += w * a.b as f64;
            }
            KindConfig::Spectral {
                lambda_min,
                lambda_max,
                n_buckets,
            } => {
                let mut l = l;
                let lm = l.max_component_value();
                if lm > cfg.max_component_value {
                    l *= cfg.max_component_value / lm;
                }
                // Undo the lights' photometric normalisation; the uniform
                // wavelength density is left out, as pbrt-v4 does, so the
                // buckets hold average spectral radiance.
                let l = l * (weight * CIE_Y_INTEGRAL);
                let nb = *n_buckets;
                let base = 2 * nb * i;
                for k in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
                    let b = KindConfig::bucket(lambda[k], *lambda_min, *lambda_max, nb);
                    self.buckets[base + b] += l[k] as f64;
                    self.buckets[base + nb + b] += w;
                }
            }
        }
    }

    /// Adds `other`'s sums (a rectangle inside this one) into these.
    pub fn merge(&mut self, other: &Pixels) {
        let nb = self.n_buckets;
        for p in other.bounds.intersect(&self.bounds).iter() {
            let (i, j) = (self.index(p), other.index(p));
            for c in 0..4 {
                self.rgb[i][c] += other.rgb[j][c];
            }
            if !self.gbuffer.is_empty() && !other.gbuffer.is_empty() {
                let (a, b) = (&mut self.gbuffer[i], &other.gbuffer[j]);
                a.weight_sum += b.weight_sum;
                a.dzdx_sum += b.dzdx_sum;
                a.dzdy_sum += b.dzdy_sum;
                for c in 0..3 {
                    a.p_sum[c] += b.p_sum[c];
                    a.n_sum[c] += b.n_sum[c];
                    a.ns_sum[c] += b.ns_sum[c];
                    a.albedo_sum[c] += b.albedo_sum[c];
                    a.variance[c].merge(&b.variance[c]);
                }
                a.uv_sum[0] += b.uv_sum[0];
                a.uv_sum[1] += b.uv_sum[1];
            }
            if nb > 0 && other.n_buckets == nb {
                for k in 0..2 * nb {
                    self.buckets[2 * nb * i + k] += other.buckets[2 * nb * j + k];
                }
            }
        }
    }
}

/// Values added concurrently with atomic compare-and-swap on `f64` bits
/// (pbrt-v4 `AtomicDouble`). The order of additions from different
/// threads varies, so splatted sums are not bit-identical across runs or
/// thread counts (they agree to rounding).
#[derive(Debug)]
pub struct AtomicF64s(Vec<AtomicU64>);

impl AtomicF64s {
    /// `n` zeros.
    pub fn new(n: usize) -> Self {
        AtomicF64s((0..n).map(|_| AtomicU64::new(0f64.to_bits())).collect())
    }
    /// The number of entries.
    #[allow(clippy::len_without_is_empty)] // never asked of an empty film
    pub fn len(&self) -> usize {
        self.0.len()
    }
    /// Adds `v` to entry `i`.
    pub fn add(&self, i: usize, v: f64) {
        let a = &self.0[i];
        let mut cur = a.load(Ordering::Relaxed);
        loop {
            let new = (f64::from_bits(cur) + v).to_bits();
            match a.compare_exchange_weak(cur, new, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => return,
                Err(c) => cur = c,
            }
        }
    }
    /// Entry `i`.
    pub fn get(&self, i: usize) -> f64 {
        f64::from_bits(self.0[i].load(Ordering::Relaxed))
    }
}
