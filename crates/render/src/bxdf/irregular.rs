//! pbrt-v2's `measured` material with irregularly sampled isotropic data
//! (a `.brdf` file; pbrt-v2 `IrregIsotropicBRDF` in `core/reflection.cpp`
//! and its reader in `materials/measured.cpp`), which pbrt-v3 and pbrt-v4
//! dropped.
//!
//! The file is numbers (and `#` comments): the count of wavelengths, the
//! wavelengths in nm, then one record per measurement: θi, φi, θo, φo in
//! radians and a value at each wavelength. Each record becomes a point
//! `(sin θi sin θo, Δφ/π, cos θi cos θo)` (Δφ folded into [0, π]); a
//! lookup averages the values of the points within a radius, weighted by
//! `exp(−100 d²)`, doubling the squared radius from 0.001 until more than
//! two are found (or it passes 1.5). Spectra are interpolated linearly at
//! the path's wavelengths, held constant past the measured ones (pbrt-v2
//! turned them into RGB; rpbrt renders them spectrally). Sampling is
//! cosine-weighted.

use super::{cached_file, FileCache};
use std::path::Path;

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{same_hemisphere, spherical_direction, spherical_phi};

use super::diffuse::{cosine_reflection_pdf, sample_cosine_reflection};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Cells per axis of the lookup grid over the unit cube of points.
const GRID: usize = 8;

/// The measurements of one `.brdf` file.
#[derive(Debug)]
pub struct IrregularBrdf {
    /// The wavelengths, ascending.
    lambdas: Vec<Float>,
    /// Each measurement's point.
    points: Vec<[Float; 3]>,
    /// Each measurement's values, `lambdas.len()` per point.
    values: Vec<Float>,
    /// The points in each grid cell, by index.
    cells: Vec<Vec<u32>>,
}

/// pbrt-v2's `BRDFRemap`: the point of a pair of directions.
fn remap(wo: Vector3f, wi: Vector3f) -> [Float; 3] {
    let sin = |w: Vector3f| (1.0 - w.z * w.z).max(0.0).sqrt();
    let mut dphi = spherical_phi(wi) - spherical_phi(wo);
    if dphi < 0.0 {
        dphi += 2.0 * PI;
    }
    if dphi > 2.0 * PI {
        dphi -= 2.0 * PI;
    }
    if dphi > PI {
        dphi = 2.0 * PI - dphi;
    }
    [sin(wi) * sin(wo), dphi / PI, wi.z * wo.z]
}

fn cell_of(v: Float) -> usize {
    ((v * GRID as Float).max(0.0) as usize).min(GRID - 1)
}

impl IrregularBrdf {
    /// The measurements in a `.brdf` file's text.
    pub fn parse(text: &str) -> Result<IrregularBrdf, String> {
        let mut numbers = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            for tok in line.split_whitespace() {
                let v: Float = tok
                    .parse()
                    .map_err(|_| format!("line {}: \"{tok}\" is not a number", n + 1))?;
                numbers.push(v);
            }
        }
        let Some(&n_wl) = numbers.first() else {
            return Err("empty file".into());
        };
        if !(n_wl >= 1.0 && n_wl.fract() == 0.0 && (n_wl as usize) < numbers.len()) {
            return Err(format!("bad wavelength count {n_wl}"));
        }
        let n_wl = n_wl as usize;
        let lambdas = numbers[1..=n_wl].to_vec();
        if lambdas.windows(2).any(|w| !(w[0] < w[1])) || lambdas.iter().any(|l| !l.is_finite()) {
            return Err("the wavelengths must be finite and ascending".into());
        }
        let rest = &numbers[1 + n_wl..];
        let stride = 4 + n_wl;
        if rest.is_empty() || rest.len() % stride != 0 {
            return Err(format!(
                "{} numbers after the wavelengths: not a whole number of records of {stride} (four angles and {n_wl} values)",
                rest.len()
            ));
        }
        let mut points = Vec::with_capacity(rest.len() / stride);
        let mut values = Vec::with_capacity(rest.len() / stride * n_wl);
        let mut cells = vec![Vec::new(); GRID * GRID * GRID];
        for r in rest.chunks(stride) {
            let dir = |theta: Float, phi: Float| spherical_direction(theta.sin(), theta.cos(), phi);
            let p = remap(dir(r[2], r[3]), dir(r[0], r[1]));
            if p.iter().any(|v| !v.is_finite()) || r[4..].iter().any(|v| !v.is_finite()) {
                return Err("a record has a value that is not finite".into());
            }
            let c = cell_of(p[0]) + GRID * (cell_of(p[1]) + GRID * cell_of(p[2]));
            cells[c].push(points.len() as u32);
            points.push(p);
            values.extend_from_slice(&r[4..]);
        }
        Ok(IrregularBrdf {
            lambdas,
            points,
            values,
            cells,
        })
    }

    /// The measurements of the file at `path`, read once per run.
    pub fn cached(path: &Path) -> Result<&'static IrregularBrdf, String> {
        static CACHE: FileCache<IrregularBrdf> = FileCache::new();
        cached_file(&CACHE, path, |p| {
            Self::parse(&std::fs::read_to_string(p).map_err(|e| e.to_string())?)
        })
    }

    /// Point `i`'s value at wavelength `lambda`.
    fn value(&self, i: usize, lambda: Float) -> Float {
        let n = self.lambdas.len();
        let v = &self.values[i * n..(i + 1) * n];
        let k = self.lambdas.partition_point(|&l| l <= lambda);
        if k == 0 {
            return v[0];
        }
        if k == n {
            return v[n - 1];
        }
        let t = (lambda - self.lambdas[k - 1]) / (self.lambdas[k] - self.lambdas[k - 1]);
        (1.0 - t) * v[k - 1] + t * v[k]
    }

    /// pbrt-v2's `IrregIsotropicBRDF::f` at the wavelengths.
    pub fn lookup(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let m = remap(wo, wi);
        let mut r2: Float = 0.001;
        loop {
            let r = r2.sqrt();
            let lo = m.map(|v| cell_of(v - r));
            let hi = m.map(|v| cell_of(v + r));
            let (mut sum, mut weights, mut found) = (SampledSpectrum::new(0.0), 0.0, 0);
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        for &i in &self.cells[x + GRID * (y + GRID * z)] {
                            let p = self.points[i as usize];
                            let d2: Float = (0..3).map(|a| (p[a] - m[a]) * (p[a] - m[a])).sum();
                            if d2 < r2 {
                                let w = (-100.0 * d2).exp();
                                let mut v = SampledSpectrum::new(0.0);
                                for (k, vk) in v.values.iter_mut().enumerate() {
                                    *vk = self.value(i as usize, lambda.get(k));
                                }
                                sum += v * w;
                                weights += w;
                                found += 1;
                            }
                        }
                    }
                }
            }
            if found > 2 || r2 > 1.5 {
                return if weights > 0.0 {
                    (sum / weights).clamp_zero()
                } else {
                    SampledSpectrum::new(0.0)
                };
            }
            r2 *= 2.0;
        }
    }
}

/// Irregular measurements at a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct IrregularBxDF {
    data: &'static IrregularBrdf,
    lambda: SampledWavelengths,
}

impl PartialEq for IrregularBxDF {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self.data, o.data) && self.lambda == o.lambda
    }
}

impl IrregularBxDF {
    /// `data`'s BRDF at `lambda`.
    pub fn new(data: &'static IrregularBrdf, lambda: &SampledWavelengths) -> Self {
        IrregularBxDF {
            data,
            lambda: *lambda,
        }
    }
}

impl BxDFMethods for IrregularBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        self.data.lookup(wo, wi, &self.lambda)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        _uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        sample_cosine_reflection(wo, u, sample_flags, self.flags(), |wi| self.f(wo, wi, mode))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        cosine_reflection_pdf(wo, wi, sample_flags)
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::GLOSSY_REFLECTION
    }

    fn regularize(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_average_the_nearby_measurements() {
        // Two wavelengths; a grid of measurements whose value is 1 where
        // Δφ < π/2 and 3 elsewhere (at 400 nm; twice that at 700 nm).
        let mut text = String::from("2  400 700\n# θi φi θo φo  v400 v700\n");
        for i in 0..10 {
            for o in 0..10 {
                for p in 0..12 {
                    let (ti, to) = (0.05 + 0.15 * i as Float, 0.05 + 0.15 * o as Float);
                    let phi = p as Float * PI / 6.0;
                    let folded = if phi > PI { 2.0 * PI - phi } else { phi };
                    let v = if folded < PI / 2.0 { 1.0 } else { 3.0 };
                    text += &format!("{ti} {phi} {to} 0 {v} {}\n", 2.0 * v);
                }
            }
        }
        let d = IrregularBrdf::parse(&text).unwrap();
        let lambda = SampledWavelengths::sample_visible(0.3);
        let at = |ti: Float, pi: Float, to: Float| {
            let s = d.lookup(
                spherical_direction(to.sin(), to.cos(), 0.0),
                spherical_direction(ti.sin(), ti.cos(), pi),
                &lambda,
            );
            (
                s,
                (0..4)
                    .map(|k| 1.0 + (lambda.get(k) - 400.0) / 300.0)
                    .collect::<Vec<_>>(),
            )
        };
        // Near Δφ = 0: about 1 (× the linear ramp over wavelength).
        let (s, ramp) = at(0.5, 0.1, 0.5);
        for k in 0..4 {
            assert!((s.values[k] / ramp[k] - 1.0).abs() < 0.05, "{:?}", s.values);
        }
        // Near Δφ = π: about 3.
        let (s, ramp) = at(0.5, 3.0, 0.5);
        for k in 0..4 {
            assert!((s.values[k] / ramp[k] - 3.0).abs() < 0.15, "{:?}", s.values);
        }
    }

    #[test]
    fn bad_files_are_errors() {
        assert!(IrregularBrdf::parse("").is_err());
        assert!(IrregularBrdf::parse("2 400 700 0 0 0 0 1")
            .unwrap_err()
            .contains("records"));
        assert!(IrregularBrdf::parse("2 700 400 0 0 0 0 1 1").is_err());
        assert!(IrregularBrdf::parse("1 500 0 0 x 0 1")
            .unwrap_err()
            .contains("\"x\""));
    }
}
