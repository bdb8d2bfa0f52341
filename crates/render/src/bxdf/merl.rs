//! pbrt-v2's `measured` material with a MERL isotropic BRDF table
//! (Matusik et al. 2003; pbrt-v2 `materials/measured.cpp` and
//! `RegularHalfangleBRDF` in `core/reflection.cpp`), which pbrt-v3 and
//! pbrt-v4 dropped (pbrt-v4's `measured` reads RGL `.bsdf` files instead).
//!
//! The file holds three integers, the table's dimensions (90 θh × 90 θd ×
//! 180 φd), then every red value, every green and every blue as doubles,
//! `φd` fastest. pbrt-v2 scaled them by (1, 1.15, 1.66) / 1500 into RGB
//! reflectance and clamped MERL's negative markers of missing samples to
//! zero; a lookup takes the nearest entry (no interpolation), with θh
//! indexed by `√(θh / (π/2))`. Sampling is cosine-weighted, as pbrt-v2's
//! default BxDF sampling was.

use super::{cached_file, FileCache};
use std::path::Path;

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{same_hemisphere, spherical_phi, spherical_theta};

use super::diffuse::{cosine_reflection_pdf, sample_cosine_reflection};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::{
    RgbColorSpace, RgbUnboundedSpectrum, SampledSpectrum, SampledWavelengths, RGB,
};

/// θh, θd and φd entries of a MERL table.
const DIMS: [usize; 3] = [90, 90, 180];
/// Entries in a MERL table.
const ENTRIES: usize = 90 * 90 * 180;
/// pbrt-v2's factors from MERL's values to RGB reflectance.
const SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// A MERL table as RGB triples, entry by entry.
#[derive(Debug)]
pub struct MerlTable {
    rgb: Vec<[f32; 3]>,
}

impl MerlTable {
    /// Whether `bytes` start like a MERL table: three integers whose
    /// product is the table's size.
    pub fn looks_like(bytes: &[u8]) -> bool {
        bytes.len() >= 12 && header_entries(bytes) == Some(ENTRIES as u64)
    }

    /// The table in a MERL file's bytes.
    pub fn parse(bytes: &[u8]) -> Result<MerlTable, String> {
        if header_entries(bytes) != Some(ENTRIES as u64) {
            return Err(format!(
                "not a MERL BRDF table: its dimensions must multiply to {ENTRIES} (90 x 90 x 180)"
            ));
        }
        let want = 12 + 3 * ENTRIES * 8;
        if bytes.len() != want {
            return Err(format!(
                "a MERL BRDF table is {want} bytes; this file has {}",
                bytes.len()
            ));
        }
        let value = |i: usize| {
            let o = 12 + 8 * i;
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[o..o + 8]);
            f64::from_le_bytes(b)
        };
        let rgb = (0..ENTRIES)
            .map(|e| std::array::from_fn(|c| (value(c * ENTRIES + e) * SCALES[c]).max(0.0) as f32))
            .collect();
        Ok(MerlTable { rgb })
    }

    /// The table of the file at `path`, read once per run and shared.
    pub fn cached(path: &Path) -> Result<&'static MerlTable, String> {
        static CACHE: FileCache<MerlTable> = FileCache::new();
        cached_file(&CACHE, path, |p| {
            Self::parse(&std::fs::read(p).map_err(|e| e.to_string())?)
        })
    }

    /// pbrt-v2's `RegularHalfangleBRDF::f`: the RGB entry for the pair of
    /// directions (in the shading frame), by their half and difference
    /// angles.
    pub fn lookup(&self, wo: Vector3f, wi: Vector3f) -> [f32; 3] {
        let mut wi = wi;
        let mut wh = wo + wi;
        if wh.z < 0.0 {
            (wi, wh) = (-wi, -wh);
        }
        if wh.x == 0.0 && wh.y == 0.0 && wh.z == 0.0 {
            return [0.0; 3];
        }
        let wh = wh.normalize();
        let theta_h = wh.z.clamp(-1.0, 1.0).acos();
        let (sin_h, cos_h) = theta_h.sin_cos();
        let (cos_phi, sin_phi) = if sin_h == 0.0 {
            (1.0, 0.0)
        } else {
            (
                (wh.x / sin_h).clamp(-1.0, 1.0),
                (wh.y / sin_h).clamp(-1.0, 1.0),
            )
        };
        let whx = Vector3f::new(cos_phi * cos_h, sin_phi * cos_h, -sin_h);
        let why = Vector3f::new(-sin_phi, cos_phi, 0.0);
        let wd = Vector3f::new(wi.dot(whx), wi.dot(why), wi.dot(wh));
        let theta_d = spherical_theta(wd);
        let mut phi_d = spherical_phi(wd);
        if phi_d > PI {
            phi_d -= PI;
        }
        let remap = |v: Float, max: Float, n: usize| {
            ((v / max * n as Float) as i64).clamp(0, n as i64 - 1) as usize
        };
        let th = remap((theta_h / (PI / 2.0)).max(0.0).sqrt(), 1.0, DIMS[0]);
        let td = remap(theta_d, PI / 2.0, DIMS[1]);
        let pd = remap(phi_d, PI, DIMS[2]);
        self.rgb[pd + DIMS[2] * (td + DIMS[1] * th)]
    }
}

/// The number of entries three native (little-endian) integers at the
/// start of `bytes` claim, if they are positive.
fn header_entries(bytes: &[u8]) -> Option<u64> {
    let dims: Vec<i32> = bytes
        .get(..12)?
        .chunks(4)
        .map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    dims.iter().try_fold(1u64, |acc, &d| {
        (d > 0).then(|| acc.saturating_mul(d as u64))
    })
}

/// A MERL table at a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct MerlBxDF {
    table: &'static MerlTable,
    cs: &'static RgbColorSpace,
    lambda: SampledWavelengths,
}

impl PartialEq for MerlBxDF {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self.table, o.table) && std::ptr::eq(self.cs, o.cs) && self.lambda == o.lambda
    }
}

impl MerlBxDF {
    /// `table`'s BRDF, its RGB values read in `cs`, at `lambda`.
    pub fn new(
        table: &'static MerlTable,
        cs: &'static RgbColorSpace,
        lambda: &SampledWavelengths,
    ) -> Self {
        MerlBxDF {
            table,
            cs,
            lambda: *lambda,
        }
    }
}

impl BxDFMethods for MerlBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        let [r, g, b] = self.table.lookup(wo, wi);
        RgbUnboundedSpectrum::new(self.cs, RGB::new(r, g, b)).sample(&self.lambda)
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

/// The bytes of a MERL file whose every entry is `f(θh index, θd index,
/// φd index)` in each channel, before pbrt-v2's scale (for tests).
#[cfg(test)]
pub fn merl_bytes(f: impl Fn(usize, usize, usize, usize) -> f64) -> Vec<u8> {
    let mut b = Vec::with_capacity(12 + 24 * ENTRIES);
    for d in DIMS {
        b.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for c in 0..3 {
        for th in 0..DIMS[0] {
            for td in 0..DIMS[1] {
                for pd in 0..DIMS[2] {
                    b.extend_from_slice(&f(c, th, td, pd).to_le_bytes());
                }
            }
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_indexes_half_and_difference_angles() {
        // Each entry holds its θd index (red), θh index (green) and φd
        // index (blue), unscaled.
        let bytes = merl_bytes(|c, th, td, pd| [td, th, pd][c] as f64 / SCALES[c]);
        let t = MerlTable::parse(&bytes).unwrap();
        let idx = |v: [f32; 3]| v.map(|x| x.round() as usize);
        // Mirror pairs about the normal: θh = 0, θd the angle to it.
        for deg in [0.0f32, 7.3, 44.5, 80.3] {
            let a = deg.to_radians();
            let wo = Vector3f::new(a.sin(), 0.0, a.cos());
            let wi = Vector3f::new(-a.sin(), 0.0, a.cos());
            let [td, th, _] = idx(t.lookup(wo, wi));
            assert_eq!((th, td), (0, ((a / (PI / 2.0)) * 90.0) as usize), "{deg}");
        }
        // wo = wi at 60°: the half vector is wo, θh = 60° (index by the
        // square root), θd = 0.
        let a = 60.0f32.to_radians();
        let w = Vector3f::new(a.sin(), 0.0, a.cos());
        let [td, th, _] = idx(t.lookup(w, w));
        assert_eq!((th, td), (((2.0f32 / 3.0).sqrt() * 90.0) as usize, 0));
        // Swapping the directions folds φd by π: the same entry.
        let wo = Vector3f::new(0.3, 0.4, 0.866).normalize();
        let wi = Vector3f::new(-0.5, 0.1, 0.86).normalize();
        assert_eq!(t.lookup(wo, wi), t.lookup(wi, wo));
    }

    #[test]
    fn bad_files_are_errors() {
        assert!(MerlTable::parse(&[0u8; 8]).is_err());
        let mut b = merl_bytes(|_, _, _, _| 1.0);
        b.pop();
        assert!(MerlTable::parse(&b).unwrap_err().contains("bytes"));
        let mut b = vec![0u8; 12];
        b[..4].copy_from_slice(&(-90i32).to_le_bytes());
        assert!(!MerlTable::looks_like(&b));
        // Negative markers of missing samples read as zero.
        let t = MerlTable::parse(&merl_bytes(|_, _, _, _| -1.0)).unwrap();
        let n = Vector3f::new(0.0, 0.0, 1.0);
        assert_eq!(t.lookup(n, n), [0.0; 3]);
    }
}
