//! Measured reflectance (pbrt-v4 book section 9.8; pbrt-v4 `bxdfs.h`,
//! `bxdfs.cpp` `MeasuredBxDF`, `MeasuredBRDF`): Dupuy and Jakob's (2018)
//! adaptive parameterization of isotropic and anisotropic BRDFs, read from
//! RGL `.bsdf` tensor files.
//!
//! The data hold, over the unit square of microfacet normals (θ through
//! `theta2u`, φ through `phi2u`): the NDF `ndf`, the projected area `sigma`,
//! for each incident direction (φi, θi) the visible-normal distribution
//! `vndf` and, on the VNDF's sample space, the `luminance` used for
//! importance sampling and the reflectance `spectra` at the `wavelengths`.

use super::{cached_file, FileCache};
use std::fmt;
use std::path::Path;

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, same_hemisphere, spherical_direction, spherical_theta};

use super::scattering::reflect;
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, N_SPECTRUM_SAMPLES};

mod tensor;
#[cfg(test)]
mod tests;
mod warp;

pub use tensor::{
    parse_tensor_bytes, read_tensor_file, write_tensor_bytes, TensorField, TensorType, Tensors,
    TENSOR_MAGIC,
};
pub use warp::{find_interval, PLSample, PiecewiseLinear2D};

/// θ ∈ [0, π/2] to the unit interval (square-root spacing).
#[inline]
pub fn theta2u(theta: Float) -> Float {
    (theta * (2.0 / PI)).sqrt()
}
/// φ ∈ [−π, π] to the unit interval.
#[inline]
pub fn phi2u(phi: Float) -> Float {
    phi * (1.0 / (2.0 * PI)) + 0.5
}
/// The inverse of [`theta2u`].
#[inline]
pub fn u2theta(u: Float) -> Float {
    u * u * (PI / 2.0)
}
/// The inverse of [`phi2u`].
#[inline]
pub fn u2phi(u: Float) -> Float {
    (2.0 * u - 1.0) * PI
}

/// A measured BRDF's tables (pbrt-v4 `MeasuredBRDF`).
#[derive(Clone, PartialEq)]
pub struct MeasuredBxDFData {
    /// The normal distribution over the unit square (raw values).
    pub ndf: PiecewiseLinear2D<0>,
    /// The projected microfacet area over incident directions (raw values).
    pub sigma: PiecewiseLinear2D<0>,
    /// Visible normals per incident (φi, θi).
    pub vndf: PiecewiseLinear2D<2>,
    /// Luminance on the VNDF's sample space per incident (φi, θi).
    pub luminance: PiecewiseLinear2D<2>,
    /// Reflectance per (φi, θi, λ), raw values.
    pub spectra: PiecewiseLinear2D<3>,
    /// Where the spectra were measured, in nm.
    pub wavelengths: Vec<f32>,
    /// True when the data do not depend on φi (one or two φi values).
    pub isotropic: bool,
    /// The file's `jacobian` flag (read, unused, as in pbrt-v4).
    pub jacobian: bool,
    /// The file the data came from.
    pub filename: String,
}

impl fmt::Debug for MeasuredBxDFData {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "MeasuredBxDFData {{ filename: {:?}, isotropic: {}, wavelengths: {} }}",
            self.filename,
            self.isotropic,
            self.wavelengths.len()
        )
    }
}

/// A `Float32` field of rank `ndim`, or an error naming what is wrong.
fn f32_field<'a>(t: &'a Tensors, name: &str, ndim: usize) -> Result<&'a TensorField, String> {
    let f = t
        .get(name)
        .ok_or_else(|| format!("invalid BRDF file structure: no \"{name}\" field"))?;
    if f.dtype != TensorType::Float32 || f.shape.len() != ndim {
        return Err(format!(
            "invalid BRDF file structure: \"{name}\" should be float32 of rank {ndim}, is {:?} of shape {:?}",
            f.dtype, f.shape
        ));
    }
    Ok(f)
}

fn structure(msg: impl fmt::Display) -> String {
    format!("invalid BRDF file structure: {msg}")
}

impl MeasuredBxDFData {
    /// Reads and checks a `.bsdf` file (pbrt-v4 `MeasuredBRDF::Create`).
    pub fn read(path: &Path) -> Result<Self, String> {
        let t = read_tensor_file(path)?;
        Self::from_tensors(&t, &path.display().to_string())
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The data of parsed tensor-file fields, with pbrt-v4's consistency
    /// checks (and the extra ones that keep lookups in bounds).
    pub fn from_tensors(t: &Tensors, filename: &str) -> Result<Self, String> {
        let description = t
            .get("description")
            .ok_or_else(|| structure("no \"description\" field"))?;
        if description.dtype != TensorType::UInt8 || description.shape.len() != 1 {
            return Err(structure("\"description\" should be a uint8 string"));
        }
        let jacobian = t
            .get("jacobian")
            .ok_or_else(|| structure("no \"jacobian\" field"))?;
        if jacobian.dtype != TensorType::UInt8 || jacobian.shape != [1] {
            return Err(structure("\"jacobian\" should be one uint8"));
        }
        let theta_i = f32_field(t, "theta_i", 1)?;
        let phi_i = f32_field(t, "phi_i", 1)?;
        let wavelengths = f32_field(t, "wavelengths", 1)?;
        let ndf = f32_field(t, "ndf", 2)?;
        let sigma = f32_field(t, "sigma", 2)?;
        let vndf = f32_field(t, "vndf", 4)?;
        let luminance = f32_field(t, "luminance", 4)?;
        let spectra = f32_field(t, "spectra", 5)?;
        let (np, nt, nw) = (phi_i.shape[0], theta_i.shape[0], wavelengths.shape[0]);
        let (vs, ls, ss) = (&vndf.shape, &luminance.shape, &spectra.shape);
        if np == 0 || nt == 0 || nw == 0 {
            return Err(structure(
                "\"phi_i\", \"theta_i\" and \"wavelengths\" must not be empty",
            ));
        }
        if vs[0] != np || vs[1] != nt {
            return Err(structure(format!(
                "\"vndf\" has shape {vs:?}, expected [{np}, {nt}, ..]"
            )));
        }
        if ls[0] != np || ls[1] != nt || ls[2] != ls[3] {
            return Err(structure(format!(
                "\"luminance\" has shape {ls:?}, expected [{np}, {nt}, n, n]"
            )));
        }
        if ss[0] != np || ss[1] != nt || ss[2] != nw || ss[3] != ss[4] {
            return Err(structure(format!(
                "\"spectra\" has shape {ss:?}, expected [{np}, {nt}, {nw}, n, n]"
            )));
        }
        if ls[2] != ss[3] || ls[3] != ss[4] {
            return Err(structure(
                "\"luminance\" and \"spectra\" have different resolutions",
            ));
        }
        let phi = phi_i.as_f32().unwrap_or_default();
        let theta = theta_i.as_f32().unwrap_or_default();
        let lambda = wavelengths.as_f32().unwrap_or_default();
        let isotropic = np <= 2;
        if !isotropic {
            let reduction = ((2.0 * PI) / (phi[np - 1] - phi[0])).round();
            if reduction != 1.0 {
                return Err(format!(
                    "reduction {reduction} (!= 1) of the φi range is not supported"
                ));
            }
        }
        let field = |f: &TensorField, what: &str| -> Result<Vec<f32>, String> {
            let v = f.as_f32().unwrap_or_default();
            if v.iter().any(|x| !x.is_finite()) {
                return Err(structure(format!("\"{what}\" holds non-finite values")));
            }
            Ok(v)
        };
        let ctx = |what: &'static str| move |e: String| structure(format!("\"{what}\": {e}"));
        let ndf_v = field(ndf, "ndf")?;
        let sigma_v = field(sigma, "sigma")?;
        Ok(MeasuredBxDFData {
            ndf: PiecewiseLinear2D::new(&ndf_v, ndf.shape[1], ndf.shape[0], [], false, false)
                .map_err(ctx("ndf"))?,
            sigma: PiecewiseLinear2D::new(
                &sigma_v,
                sigma.shape[1],
                sigma.shape[0],
                [],
                false,
                false,
            )
            .map_err(ctx("sigma"))?,
            vndf: PiecewiseLinear2D::new(
                &field(vndf, "vndf")?,
                vs[3],
                vs[2],
                [&phi, &theta],
                true,
                true,
            )
            .map_err(ctx("vndf"))?,
            luminance: PiecewiseLinear2D::new(
                &field(luminance, "luminance")?,
                ls[3],
                ls[2],
                [&phi, &theta],
                true,
                true,
            )
            .map_err(ctx("luminance"))?,
            spectra: PiecewiseLinear2D::new(
                &field(spectra, "spectra")?,
                ss[4],
                ss[3],
                [&phi, &theta, &lambda],
                false,
                false,
            )
            .map_err(ctx("spectra"))?,
            wavelengths: lambda,
            isotropic,
            jacobian: jacobian.data[0] != 0,
            filename: filename.to_string(),
        })
    }

    /// The data of `path`, read once per process and kept for its lifetime
    /// (pbrt-v4 `MeasuredBxDF::BRDFDataFromFile` keeps them in the scene's
    /// allocator). The data are leaked on purpose: BxDFs are `Copy` and
    /// hold a plain reference. Failed reads are not cached.
    pub fn cached(path: &Path) -> Result<&'static MeasuredBxDFData, String> {
        static CACHE: FileCache<MeasuredBxDFData> = FileCache::new();
        cached_file(&CACHE, path, Self::read)
    }
}

/// A measured BRDF at the sampled wavelengths (pbrt-v4 `MeasuredBxDF`).
#[derive(Clone, Copy, Debug)]
pub struct MeasuredBxDF {
    data: &'static MeasuredBxDFData,
    lambda: SampledWavelengths,
}

impl PartialEq for MeasuredBxDF {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self.data, o.data) && self.lambda == o.lambda
    }
}

impl MeasuredBxDF {
    /// The BRDF of `data` at wavelengths `lambda`.
    pub fn new(data: &'static MeasuredBxDFData, lambda: &SampledWavelengths) -> Self {
        MeasuredBxDF {
            data,
            lambda: *lambda,
        }
    }

    /// The tables.
    pub fn data(&self) -> &'static MeasuredBxDFData {
        self.data
    }

    /// The reflectance at VNDF sample `sample` for outgoing (φ, θ) at each
    /// wavelength, clamped to be non-negative.
    #[inline]
    fn spectra(&self, sample: Point2f, phi: Float, theta: Float) -> SampledSpectrum {
        let mut fr = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            let v = self
                .data
                .spectra
                .evaluate(sample, &[phi, theta, self.lambda[i]]);
            fr[i] = v.max(0.0);
        }
        fr
    }

    /// The half vector of a reflected pair (both with z ≥ 0) in the unit
    /// square of microfacet normals, relative to φo for isotropic data.
    #[inline]
    fn u_wm(&self, wm: Vector3f, phi_o: Float) -> Point2f {
        let theta_m = spherical_theta(wm);
        let phi_m = wm.y.atan2(wm.x);
        let y = phi2u(if self.data.isotropic {
            phi_m - phi_o
        } else {
            phi_m
        });
        Point2f::new(theta2u(theta_m), y - y.floor())
    }
}

impl BxDFMethods for MeasuredBxDF {
    fn f(&self, mut wo: Vector3f, mut wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        if wo.z < 0.0 {
            wo = -wo;
            wi = -wi;
        }
        let wm = wi + wo;
        if wm.length_squared() == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        let wm = wm.normalize();
        // The tables are indexed by ωo, as in `sample_f` (pbrt-v4 after its
        // pull request #215, which made `f` and `PDF` agree with `Sample_f`).
        let theta_o = spherical_theta(wo);
        let phi_o = wo.y.atan2(wo.x);
        let u_wo = Point2f::new(theta2u(theta_o), phi2u(phi_o));
        let u_wm = self.u_wm(wm, phi_o);
        let params = [phi_o, theta_o];
        let sample = self.data.vndf.invert(u_wm, &params).p;
        let fr = self.spectra(sample, phi_o, theta_o);
        fr * self.data.ndf.evaluate(u_wm, &[])
            / (4.0 * self.data.sigma.evaluate(u_wo, &[]) * abs_cos_theta(wi))
    }

    fn sample_f(
        &self,
        mut wo: Vector3f,
        _uc: Float,
        u: Point2f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) {
            return None;
        }
        let flip = wo.z <= 0.0;
        if flip {
            wo = -wo;
        }
        let theta_o = spherical_theta(wo);
        let phi_o = wo.y.atan2(wo.x);
        let params = [phi_o, theta_o];
        let s = self.data.luminance.sample(Point2f::new(u.y, u.x), &params);
        let (sample, lum_pdf) = (s.p, s.pdf);
        let s = self.data.vndf.sample(sample, &params);
        let (u_wm, ndf_pdf) = (s.p, s.pdf);

        let mut phi_m = u2phi(u_wm.y);
        let theta_m = u2theta(u_wm.x);
        if self.data.isotropic {
            phi_m += phi_o;
        }
        let (sin_m, cos_m) = (theta_m.sin(), theta_m.cos());
        let wm = spherical_direction(sin_m, cos_m, phi_m);
        let wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let mut fr = self.spectra(sample, phi_o, theta_o);
        let u_wo = Point2f::new(theta2u(theta_o), phi2u(phi_o));
        fr *= self.data.ndf.evaluate(u_wm, &[])
            / (4.0 * self.data.sigma.evaluate(u_wo, &[]) * abs_cos_theta(wi));
        let jacobian = 4.0 * dot(wo, wm) * (2.0 * PI * PI * u_wm.x * sin_m).max(1e-6);
        let pdf = ndf_pdf * lum_pdf / jacobian;
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let wi = if flip { -wi } else { wi };
        Some(BSDFSample::new(fr, wi, pdf, BxDFFlags::GLOSSY_REFLECTION))
    }

    fn pdf(
        &self,
        mut wo: Vector3f,
        mut wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        if !sample_flags.contains(BxDFReflTransFlags::REFLECTION) || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        if wo.z < 0.0 {
            wo = -wo;
            wi = -wi;
        }
        let wm = wi + wo;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        let theta_o = spherical_theta(wo);
        let phi_o = wo.y.atan2(wo.x);
        let u_wm = self.u_wm(wm, phi_o);
        let params = [phi_o, theta_o];
        let ui = self.data.vndf.invert(u_wm, &params);
        let lum = self.data.luminance.evaluate(ui.p, &params);
        let sin_m = (wm.x * wm.x + wm.y * wm.y).sqrt();
        let jacobian = 4.0 * dot(wo, wm) * (2.0 * PI * PI * u_wm.x * sin_m).max(1e-6);
        ui.pdf * lum / jacobian
    }

    fn flags(&self) -> BxDFFlags {
        BxDFFlags::GLOSSY_REFLECTION
    }

    fn regularize(&mut self) {}
}
