//! pbrt-v3's tabulated Fourier BSDF (pbrt-v3 book section 8.6; pbrt-v3
//! `core/reflection.h/.cpp` `FourierBSDFTable`, `FourierBSDF`,
//! `core/interpolation.cpp` `Fourier`, `SampleFourier`), which pbrt-v4
//! dropped: isotropic scattering, reflection and transmission, stored as
//! Fourier series in the azimuth difference φ over a grid of zenith
//! cosines μi × μo, read from the binary `.bsdf` files of Mitsuba's layer
//! laboratory (header `SCATFUN` version 1).
//!
//! Each (μi, μo) cell holds `m` coefficients per channel (luminance, then
//! red and blue for colour files) of f(μi, μo, φ) |μi|; values between grid
//! nodes come from Catmull–Rom weights in both cosines. Sampling picks μi
//! from the spline of the order-0 term and φ by inverting the luminance
//! series.
//!
//! Reading checks every size and offset against the file's actual length
//! before anything is allocated, so a truncated or corrupt file is a
//! [`FourierError`], never a panic or an allocation sized by the header.

use super::{cached_file, FileCache};
use std::fmt;
use std::path::Path;

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{cos_d_phi, cos_theta, sin2_theta};

use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::bssrdf::spline::{catmull_rom_weights, sample_catmull_rom_2d};
use crate::spectrum::{
    RgbColorSpace, RgbUnboundedSpectrum, SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES,
    RGB,
};

/// The first eight bytes of a Fourier BSDF file.
pub const FOURIER_MAGIC: &[u8; 8] = b"SCATFUN\x01";

/// The header's size in bytes: the magic, nine 32-bit integers, η and
/// four unused 32-bit words.
pub const FOURIER_HEADER_LEN: usize = 64;

/// What is wrong with a Fourier BSDF file.
#[derive(Clone, Debug, PartialEq)]
pub enum FourierError {
    /// The file could not be read.
    Io(String),
    /// The file ends before the data its header describes.
    Truncated {
        /// Bytes the header implies (at least).
        expected: u64,
        /// Bytes the file has.
        actual: u64,
    },
    /// The file does not start with `SCATFUN\x01`.
    WrongMagic {
        /// True when it starts like an RGL tensor file (the `.bsdf` files
        /// of the `measured` material).
        tensor_file: bool,
    },
    /// The header describes something pbrt-v3 cannot use.
    Unsupported(String),
    /// Sizes, offsets or values that do not fit together.
    Corrupt(String),
}

impl fmt::Display for FourierError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FourierError::Io(e) => write!(f, "unable to read file: {e}"),
            FourierError::Truncated { expected, actual } => write!(
                f,
                "truncated Fourier BSDF file: its header describes at least {expected} bytes, the file has {actual}"
            ),
            FourierError::WrongMagic { tensor_file: true } => write!(
                f,
                "not a Fourier BSDF file (\"SCATFUN\" header): this is an RGL tensor file, which the \"measured\" material reads"
            ),
            FourierError::WrongMagic { tensor_file: false } => write!(
                f,
                "not a Fourier BSDF file: expected the header \"SCATFUN\" version 1"
            ),
            FourierError::Unsupported(m) => write!(f, "unsupported Fourier BSDF file: {m}"),
            FourierError::Corrupt(m) => write!(f, "corrupt Fourier BSDF file: {m}"),
        }
    }
}

impl std::error::Error for FourierError {}

/// A Fourier BSDF file's tables (pbrt-v3 `FourierBSDFTable`).
#[derive(Clone, Debug, PartialEq)]
pub struct FourierBSDFTable {
    /// Relative index of refraction of the interface (inside over outside).
    pub eta: Float,
    /// The largest number of coefficients of any cell.
    pub m_max: usize,
    /// 1 (luminance) or 3 (luminance, red, blue).
    pub n_channels: usize,
    /// Zenith-angle cosines of the grid, increasing, in [−1, 1].
    pub mu: Vec<Float>,
    /// Per μo row, the running integral over μi of the order-0 term.
    pub cdf: Vec<Float>,
    /// The order-0 luminance coefficient of every cell.
    pub a0: Vec<Float>,
    /// Where each cell's coefficients start in `a`.
    pub a_offset: Vec<usize>,
    /// Each cell's number of coefficients per channel.
    pub m: Vec<usize>,
    /// All coefficients.
    pub a: Vec<Float>,
    /// 1/k for k < `m_max` (the integrals of the series' sines).
    pub recip: Vec<Float>,
}

/// Little-endian 32-bit values of a file's bytes, by byte position
/// (callers check the positions against the length first).
struct Words<'a> {
    bytes: &'a [u8],
}

impl Words<'_> {
    #[inline]
    fn u32_at(&self, byte: usize) -> u32 {
        let b = &self.bytes[byte..byte + 4];
        u32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
    #[inline]
    fn i32_at(&self, byte: usize) -> i32 {
        self.u32_at(byte) as i32
    }
    #[inline]
    fn f32_at(&self, byte: usize) -> Float {
        f32::from_bits(self.u32_at(byte))
    }
    fn floats(&self, byte: usize, n: usize) -> Vec<Float> {
        (0..n).map(|i| self.f32_at(byte + 4 * i)).collect()
    }
}

impl FourierBSDFTable {
    /// Parses the bytes of a `.bsdf` file (pbrt-v3
    /// `FourierBSDFTable::Read`, with every size checked first).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, FourierError> {
        let actual = bytes.len() as u64;
        if bytes.len() < 8 || &bytes[..8] != FOURIER_MAGIC {
            let tensor_file = bytes.len() >= 12 && bytes[..12] == super::measured::TENSOR_MAGIC[..];
            if bytes.len() >= 8 || tensor_file {
                return Err(FourierError::WrongMagic { tensor_file });
            }
            return Err(FourierError::Truncated {
                expected: FOURIER_HEADER_LEN as u64,
                actual,
            });
        }
        if bytes.len() < FOURIER_HEADER_LEN {
            return Err(FourierError::Truncated {
                expected: FOURIER_HEADER_LEN as u64,
                actual,
            });
        }
        let w = Words { bytes };
        let flags = w.i32_at(8);
        let n_mu = w.i32_at(12);
        let n_coeffs = w.i32_at(16);
        let m_max = w.i32_at(20);
        let n_channels = w.i32_at(24);
        let n_bases = w.i32_at(28);
        let eta = w.f32_at(44);
        if flags != 1 {
            return Err(FourierError::Unsupported(format!(
                "flags {flags} (pbrt-v3 reads only bidirectional tables, flags 1)"
            )));
        }
        if n_channels != 1 && n_channels != 3 {
            return Err(FourierError::Unsupported(format!(
                "{n_channels} channels (1 or 3 expected)"
            )));
        }
        if n_bases != 1 {
            return Err(FourierError::Unsupported(format!(
                "{n_bases} basis functions (pbrt-v3 reads only 1)"
            )));
        }
        for (what, v) in [
            ("zenith nodes", n_mu),
            ("coefficients", n_coeffs),
            ("maximum order", m_max),
        ] {
            if v < 0 {
                return Err(FourierError::Corrupt(format!(
                    "negative number of {what} ({v})"
                )));
            }
        }
        if n_mu < 2 {
            return Err(FourierError::Corrupt(format!(
                "{n_mu} zenith nodes (at least 2 needed)"
            )));
        }
        if !(eta.is_finite() && eta > 0.0) {
            return Err(FourierError::Corrupt(format!("index of refraction {eta}")));
        }
        let (n_mu, n_coeffs, m_max, n_channels) = (
            n_mu as u64,
            n_coeffs as u64,
            m_max as u64,
            n_channels as u64,
        );
        // mu, cdf, (offset, length) pairs and the coefficients, 4 bytes
        // each (in 128 bits: header counts up to 2³¹ cannot overflow it).
        let cells = n_mu * n_mu;
        let words = n_mu as u128 + 3 * cells as u128 + n_coeffs as u128;
        let expected = FOURIER_HEADER_LEN as u128 + 4 * words;
        if (actual as u128) < expected {
            return Err(FourierError::Truncated {
                expected: u64::try_from(expected).unwrap_or(u64::MAX),
                actual,
            });
        }
        // From here on every count fits in the file, hence in memory.
        let (n_mu, cells, n_coeffs, n_channels) = (
            n_mu as usize,
            cells as usize,
            n_coeffs as usize,
            n_channels as usize,
        );
        let mut at = FOURIER_HEADER_LEN;
        let mu = w.floats(at, n_mu);
        at += 4 * n_mu;
        let cdf = w.floats(at, cells);
        at += 4 * cells;
        let pairs_at = at;
        at += 8 * cells;
        let a = w.floats(at, n_coeffs);
        if mu.iter().any(|m| !m.is_finite() || m.abs() > 1.0 + 1e-4)
            || mu.windows(2).any(|p| p[0] >= p[1])
        {
            return Err(FourierError::Corrupt(
                "zenith cosines are not increasing values in [-1, 1]".into(),
            ));
        }
        if cdf.iter().chain(&a).any(|v| !v.is_finite()) {
            return Err(FourierError::Corrupt("non-finite table values".into()));
        }
        let mut a_offset = Vec::with_capacity(cells);
        let mut m = Vec::with_capacity(cells);
        let mut a0 = Vec::with_capacity(cells);
        let mut longest = 0usize;
        for i in 0..cells {
            let offset = w.i32_at(pairs_at + 8 * i);
            let length = w.i32_at(pairs_at + 8 * i + 4);
            let fits = offset >= 0
                && length >= 0
                && (offset as u64) + (length as u64) * (n_channels as u64) <= n_coeffs as u64;
            if !fits {
                return Err(FourierError::Corrupt(format!(
                    "cell {i}: {length} coefficients at offset {offset} do not fit in the {n_coeffs} stored"
                )));
            }
            let (offset, length) = (offset as usize, length as usize);
            if length as u64 > m_max {
                return Err(FourierError::Corrupt(format!(
                    "cell {i} has {length} coefficients, more than the maximum order {m_max}"
                )));
            }
            longest = longest.max(length);
            a_offset.push(offset);
            m.push(length);
            a0.push(if length > 0 { a[offset] } else { 0.0 });
        }
        // Sized by the longest cell actually stored, not by the header.
        let recip = (0..longest)
            .map(|k| if k == 0 { 0.0 } else { 1.0 / k as Float })
            .collect();
        Ok(FourierBSDFTable {
            eta,
            m_max: longest,
            n_channels,
            mu,
            cdf,
            a0,
            a_offset,
            m,
            a,
            recip,
        })
    }

    /// Reads a `.bsdf` file.
    pub fn read(path: &Path) -> Result<Self, FourierError> {
        let bytes = std::fs::read(path).map_err(|e| FourierError::Io(e.to_string()))?;
        Self::from_bytes(&bytes)
    }

    /// The table of `path`, read once per file for the whole run.
    pub fn cached(path: &Path) -> Result<&'static FourierBSDFTable, FourierError> {
        static CACHE: FileCache<FourierBSDFTable> = FileCache::new();
        cached_file(&CACHE, path, Self::read)
    }

    /// Catmull–Rom offset and weights of a zenith cosine.
    #[inline]
    fn weights(&self, mu: Float) -> Option<(isize, [Float; 4])> {
        catmull_rom_weights(&self.mu, mu)
    }

    /// Sums the weighted coefficients of the (up to) 16 cells around
    /// (μi, μo) into `ak` (`channels` × `m_max`); returns the order used.
    fn accumulate(
        &self,
        (oi, wi): (isize, [Float; 4]),
        (oo, wo): (isize, [Float; 4]),
        channels: usize,
        ak: &mut [Float],
    ) -> usize {
        let n = self.mu.len();
        let mut order = 0;
        for (b, &wb) in wo.iter().enumerate() {
            for (a, &wa) in wi.iter().enumerate() {
                let weight = wa * wb;
                if weight == 0.0 {
                    continue;
                }
                // Cells with non-zero weight lie inside the grid.
                let cell = (oo + b as isize) as usize * n + (oi + a as isize) as usize;
                let (off, m) = (self.a_offset[cell], self.m[cell]);
                order = order.max(m);
                for c in 0..channels {
                    let src = &self.a[off + c * m..off + (c + 1) * m];
                    for (k, v) in src.iter().enumerate() {
                        ak[c * self.m_max + k] += weight * v;
                    }
                }
            }
        }
        order
    }
}

/// The Fourier series `a` (`m` terms) at cos φ (pbrt-v3 `Fourier`), with
/// the Chebyshev recurrence for cos kφ.
pub fn fourier(a: &[Float], m: usize, cos_phi: f64) -> Float {
    let mut value = 0.0f64;
    let (mut cos_prev, mut cos_k) = (cos_phi, 1.0f64);
    for &ak in &a[..m] {
        value += ak as f64 * cos_k;
        let next = 2.0 * cos_phi * cos_k - cos_prev;
        cos_prev = cos_k;
        cos_k = next;
    }
    value as Float
}

/// Samples φ ∈ [0, 2π) proportionally to the series `ak` (pbrt-v3
/// `SampleFourier`: Newton–bisection on [0, π], mirrored for u ≥ ½).
/// Returns (the series' value at φ, the density of φ, φ).
pub fn sample_fourier(ak: &[Float], recip: &[Float], m: usize, u: Float) -> (Float, Float, Float) {
    let flip = u >= 0.5;
    let u = if flip { 1.0 - 2.0 * (u - 0.5) } else { u * 2.0 } as f64;
    let (mut a, mut b, mut phi) = (0.0f64, std::f64::consts::PI, 0.5 * std::f64::consts::PI);
    let a0 = ak[0] as f64;
    let mut f;
    let mut iterations = 0;
    loop {
        let cos_phi = phi.cos();
        let sin_phi = (1.0 - cos_phi * cos_phi).max(0.0).sqrt();
        let (mut cos_prev, mut cos_cur) = (cos_phi, 1.0f64);
        let (mut sin_prev, mut sin_cur) = (-sin_phi, 0.0f64);
        let mut big_f = a0 * phi;
        f = a0;
        for k in 1..m {
            let sin_next = 2.0 * cos_phi * sin_cur - sin_prev;
            let cos_next = 2.0 * cos_phi * cos_cur - cos_prev;
            sin_prev = sin_cur;
            sin_cur = sin_next;
            cos_prev = cos_cur;
            cos_cur = cos_next;
            big_f += ak[k] as f64 * recip[k] as f64 * sin_next;
            f += ak[k] as f64 * cos_next;
        }
        big_f -= u * a0 * std::f64::consts::PI;
        if big_f > 0.0 {
            b = phi;
        } else {
            a = phi;
        }
        iterations += 1;
        if big_f.abs() < 1e-6 || b - a < 1e-6 || iterations > 100 {
            break;
        }
        phi -= big_f / f;
        if !(phi > a && phi < b) {
            phi = 0.5 * (a + b);
        }
    }
    if flip {
        phi = 2.0 * std::f64::consts::PI - phi;
    }
    let pdf = (f / (2.0 * std::f64::consts::PI * a0)) as Float;
    (f as Float, pdf, phi as Float)
}

/// pbrt-v3's Fourier BSDF of one table at the sampled wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct FourierBxDF {
    table: &'static FourierBSDFTable,
    lambda: SampledWavelengths,
}

impl PartialEq for FourierBxDF {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self.table, o.table) && self.lambda == o.lambda
    }
}

impl FourierBxDF {
    /// The BSDF of `table` at wavelengths `lambda` (colour tables are sRGB).
    pub fn new(table: &'static FourierBSDFTable, lambda: &SampledWavelengths) -> Self {
        FourierBxDF {
            table,
            lambda: *lambda,
        }
    }

    /// f(ωo, ωi) from the series at cos φ, as pbrt-v3's `FourierBSDF::f`.
    fn value(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        let t = self.table;
        let (mu_i, mu_o) = (-cos_theta(wi), cos_theta(wo));
        let cos_phi = cos_d_phi(-wi, wo) as f64;
        let (Some(wts_i), Some(wts_o)) = (t.weights(mu_i), t.weights(mu_o)) else {
            return SampledSpectrum::new(0.0);
        };
        let mut ak = vec![0.0; t.m_max * t.n_channels];
        let order = t.accumulate(wts_i, wts_o, t.n_channels, &mut ak);
        let y = fourier(&ak, order, cos_phi).max(0.0);
        let mut scale = if mu_i != 0.0 { 1.0 / mu_i.abs() } else { 0.0 };
        if mode == TransportMode::Radiance && mu_i * mu_o > 0.0 {
            let eta = if mu_i > 0.0 { 1.0 / t.eta } else { t.eta };
            scale *= eta * eta;
        }
        if t.n_channels == 1 {
            return SampledSpectrum::new(y * scale);
        }
        let r = fourier(&ak[t.m_max..], order, cos_phi);
        let b = fourier(&ak[2 * t.m_max..], order, cos_phi);
        let g = 1.39829 * y - 0.100913 * b - 0.297375 * r;
        let rgb = RGB::new(
            (r * scale).max(0.0),
            (g * scale).max(0.0),
            (b * scale).max(0.0),
        );
        let spec = RgbUnboundedSpectrum::new(RgbColorSpace::srgb(), rgb);
        let mut out = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            out[i] = spec.evaluate(self.lambda[i]);
        }
        out
    }

    /// The density of `wi` under `sample_f` (pbrt-v3 `FourierBSDF::Pdf`).
    fn density(&self, wo: Vector3f, wi: Vector3f) -> Float {
        let t = self.table;
        let (mu_i, mu_o) = (-cos_theta(wi), cos_theta(wo));
        let cos_phi = cos_d_phi(-wi, wo) as f64;
        let (Some(wts_i), Some(wts_o)) = (t.weights(mu_i), t.weights(mu_o)) else {
            return 0.0;
        };
        let mut ak = vec![0.0; t.m_max];
        let order = t.accumulate(wts_i, wts_o, 1, &mut ak);
        let n = t.mu.len();
        let (oo, wo_w) = wts_o;
        let mut rho = 0.0;
        for (o, &w) in wo_w.iter().enumerate() {
            if w != 0.0 {
                let row = (oo + o as isize) as usize;
                rho += w * t.cdf[row * n + n - 1] * (2.0 * PI);
            }
        }
        let y = fourier(&ak, order, cos_phi);
        if rho > 0.0 && y > 0.0 {
            y / rho
        } else {
            0.0
        }
    }

    #[inline]
    fn side_allowed(wo: Vector3f, wi: Vector3f, sample_flags: BxDFReflTransFlags) -> bool {
        if wo.z * wi.z > 0.0 {
            sample_flags.contains(BxDFReflTransFlags::REFLECTION)
        } else {
            sample_flags.contains(BxDFReflTransFlags::TRANSMISSION)
        }
    }
}

impl BxDFMethods for FourierBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        self.value(wo, wi, mode)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        _uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        let t = self.table;
        let mu_o = cos_theta(wo);
        let s = sample_catmull_rom_2d(&t.mu, &t.mu, &t.a0, &t.cdf, mu_o, u[1])?;
        let mu_i = s.x;
        let (wts_i, wts_o) = (t.weights(mu_i)?, t.weights(mu_o)?);
        let mut ak = vec![0.0; t.m_max];
        let order = t.accumulate(wts_i, wts_o, 1, &mut ak);
        if order == 0 || ak[0] <= 0.0 {
            return None;
        }
        let (_, _, phi) = sample_fourier(&ak, &t.recip, order, u[0]);
        let sin2_i = (1.0 - mu_i * mu_i).max(0.0);
        let mut norm = (sin2_i / sin2_theta(wo)).sqrt();
        if norm.is_infinite() {
            norm = 0.0;
        }
        let (sin_phi, cos_phi) = phi.sin_cos();
        let wi = -Vector3f::new(
            norm * (cos_phi * wo.x - sin_phi * wo.y),
            norm * (sin_phi * wo.x + cos_phi * wo.y),
            mu_i,
        );
        let wi = wi.try_normalize()?;
        if wi.z == 0.0 || !Self::side_allowed(wo, wi, sample_flags) {
            return None;
        }
        let pdf = self.density(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let f = self.value(wo, wi, mode);
        if wo.z * wi.z > 0.0 {
            Some(BSDFSample::new(f, wi, pdf, BxDFFlags::GLOSSY_REFLECTION))
        } else {
            let eta = if wo.z > 0.0 { t.eta } else { 1.0 / t.eta };
            Some(BSDFSample::with_eta(
                f,
                wi,
                pdf,
                BxDFFlags::GLOSSY_TRANSMISSION,
                eta,
            ))
        }
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !Self::side_allowed(wo, wi, sample_flags) {
            return 0.0;
        }
        self.density(wo, wi)
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::GLOSSY_REFLECTION | BxDFFlags::GLOSSY_TRANSMISSION
    }

    fn regularize(&mut self) {}
}
