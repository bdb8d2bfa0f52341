//! The Hosek–Wilkie sky model (L. Hosek and A. Wilkie, "An Analytic Model
//! for Full Spectral Sky-Dome Radiance", SIGGRAPH 2012, and "Adding a Solar
//! Radiance Function to the Hosek Skylight Model", IEEE CG&A 2013; their
//! spectral reference implementation, version 1.4a) and pbrt-v4's
//! `imgtool makesky`, which bakes it into an equal-area environment map.
//!
//! The model's state holds, per 40 nm band, nine sky-dome parameters and a
//! mean radiance, each a quintic Bézier in the cube root of the normalised
//! solar elevation, blended linearly in turbidity and ground albedo
//! (`data.rs` holds the fitted control points). Sky radiance at a view
//! direction of zenith angle θ and angle γ from the sun follows the
//! extended Perez formula; the solar disc adds a per-band polynomial in the
//! view elevation times a limb-darkening polynomial, zero outside the disc
//! (pbrt's copy of the reference code returns zero there; the original
//! returns the disc's rim value everywhere).

mod data;

use std::fmt;
use std::sync::Arc;

use rayon::prelude::*;
use rpbrt_geometry::{equal_area_square_to_sphere, spherical_theta, Float, Point2f, Point2i};

use super::{Image, ImageMetadata};
use crate::spectrum::{spectrum_to_xyz, PiecewiseLinearSpectrum, RgbColorSpace, Spectrum};

use std::f64::consts::PI;

/// Half the sun's apparent diameter, 0.51°, in radians.
const SOLAR_RADIUS: f64 = 0.51 * PI / 180.0 / 2.0;
/// Elevation segments of the solar radiance polynomials.
const SOLAR_SEGMENTS: usize = 45;

/// The spectral sky model for one sun elevation, turbidity and albedo
/// (the reference code's `ArHosekSkyModelState`).
#[derive(Clone, Debug)]
pub struct SkyModel {
    configs: [[f64; 9]; 11],
    radiances: [f64; 11],
    turbidity: f64,
}

/// A quintic Bézier of the six control points `p` at `t`.
fn quintic(p: impl Fn(usize) -> f64, t: f64) -> f64 {
    let s = 1.0 - t;
    s.powi(5) * p(0)
        + 5.0 * s.powi(4) * t * p(1)
        + 10.0 * s.powi(3) * t * t * p(2)
        + 10.0 * s * s * t.powi(3) * p(3)
        + 5.0 * s * t.powi(4) * p(4)
        + t.powi(5) * p(5)
}

/// The (albedo, turbidity index, weight) corners the reference code blends:
/// turbidity is read between its integer neighbours, albedo between 0 and
/// 1 (`ArHosekSkyModel_CookConfiguration`).
fn blend_corners(turbidity: f64, albedo: f64) -> Vec<(usize, usize, f64)> {
    let t_int = turbidity as usize;
    let t_rem = turbidity - t_int as f64;
    let mut corners = vec![
        (0, t_int - 1, (1.0 - albedo) * (1.0 - t_rem)),
        (1, t_int - 1, albedo * (1.0 - t_rem)),
    ];
    if t_int < 10 {
        corners.push((0, t_int, (1.0 - albedo) * t_rem));
        corners.push((1, t_int, albedo * t_rem));
    }
    corners
}

impl SkyModel {
    /// The model for a sun `solar_elevation` radians above the horizon,
    /// `turbidity` in [1, 10] and ground `albedo` in [0, 1]
    /// (`arhosekskymodelstate_alloc_init`).
    pub fn new(solar_elevation: f64, turbidity: f64, albedo: f64) -> Self {
        let turbidity = turbidity.clamp(1.0, 10.0);
        let albedo = albedo.clamp(0.0, 1.0);
        let t = (solar_elevation.max(0.0) / (PI / 2.0)).powf(1.0 / 3.0);
        let corners = blend_corners(turbidity, albedo);
        let mut configs = [[0.0; 9]; 11];
        let mut radiances = [0.0; 11];
        for band in 0..11 {
            for &(a, ti, w) in &corners {
                let params = &data::SKY_PARAMS[band][a][ti];
                for (k, c) in configs[band].iter_mut().enumerate() {
                    *c += w * quintic(|i| params[i][k], t);
                }
                let rad = &data::SKY_RADIANCE[band][a][ti];
                radiances[band] += w * quintic(|i| rad[i], t);
            }
        }
        SkyModel {
            configs,
            radiances,
            turbidity,
        }
    }

    /// The extended Perez formula of one band (`ArHosekSkyModel_GetRadianceInternal`).
    fn perez(c: &[f64; 9], theta: f64, gamma: f64) -> f64 {
        let cos_gamma = gamma.cos();
        let exp_m = (c[4] * gamma).exp();
        let ray_m = cos_gamma * cos_gamma;
        let mie_m =
            (1.0 + cos_gamma * cos_gamma) / (1.0 + c[8] * c[8] - 2.0 * c[8] * cos_gamma).powf(1.5);
        let zenith = theta.cos().sqrt();
        (1.0 + c[0] * (c[1] / (theta.cos() + 0.01)).exp())
            * (c[2] + c[3] * exp_m + c[5] * ray_m + c[6] * mie_m + c[7] * zenith)
    }

    /// Sky-dome radiance in W/(m² sr nm) at zenith angle `theta`, angle
    /// `gamma` from the sun, `wavelength` nm (`arhosekskymodel_radiance`;
    /// zero outside 320–760 nm, fading past 720 nm as the reference does).
    pub fn sky_radiance(&self, theta: f64, gamma: f64, wavelength: f64) -> f64 {
        let x = (wavelength - 320.0) / 40.0;
        if x < 0.0 {
            return 0.0;
        }
        let low = x as usize;
        if low >= 11 {
            return 0.0;
        }
        let interp = x % 1.0;
        let band = |b: usize| Self::perez(&self.configs[b], theta, gamma) * self.radiances[b];
        let val_low = band(low);
        if interp < 1e-6 {
            return val_low;
        }
        let mut result = (1.0 - interp) * val_low;
        if low + 1 < 11 {
            result += interp * band(low + 1);
        }
        result
    }

    /// One band's solar radiance polynomial at view `elevation` radians
    /// for turbidity index `ti` (`arhosekskymodel_sr_internal`).
    fn solar_polynomial(ti: usize, band: usize, elevation: f64) -> f64 {
        let e = elevation.max(0.0);
        let pos = ((2.0 * e / PI).powf(1.0 / 3.0) * SOLAR_SEGMENTS as f64) as usize;
        let pos = pos.min(SOLAR_SEGMENTS - 1);
        let break_x = (pos as f64 / SOLAR_SEGMENTS as f64).powi(3) * (PI * 0.5);
        let x = elevation - break_x;
        let coefs = &data::SOLAR[band][ti][pos];
        coefs[0] + x * (coefs[1] + x * (coefs[2] + x * coefs[3]))
    }

    /// Radiance of the solar disc (limb darkened) at view `elevation`
    /// radians, angle `gamma` from the sun's centre; zero off the disc
    /// (`arhosekskymodel_solar_radiance_internal2` as pbrt compiles it).
    pub fn solar_disc_radiance(&self, wavelength: f64, elevation: f64, gamma: f64) -> f64 {
        let sol_rad_sin = SOLAR_RADIUS.sin();
        let ar2 = 1.0 / (sol_rad_sin * sol_rad_sin);
        let sin_gamma = gamma.sin();
        let sample_cosine = (1.0 - ar2 * sin_gamma * sin_gamma).max(0.0).sqrt();
        if sample_cosine == 0.0 || !(320.0..=720.0).contains(&wavelength) {
            return 0.0;
        }
        let (mut t_low, mut t_frac) = (
            self.turbidity as usize - 1,
            self.turbidity - self.turbidity.trunc(),
        );
        if t_low == 9 {
            t_low = 8;
            t_frac = 1.0;
        }
        let (mut wl_low, mut wl_frac) = (
            ((wavelength - 320.0) / 40.0) as usize,
            (wavelength % 40.0) / 40.0,
        );
        if wl_low == 10 {
            wl_low = 9;
            wl_frac = 1.0;
        }
        let sr = |t: usize| {
            (1.0 - wl_frac) * Self::solar_polynomial(t, wl_low, elevation)
                + wl_frac * Self::solar_polynomial(t, wl_low + 1, elevation)
        };
        let direct = (1.0 - t_frac) * sr(t_low) + t_frac * sr(t_low + 1);
        let (ld0, ld1) = (
            &data::LIMB_DARKENING[wl_low],
            &data::LIMB_DARKENING[wl_low + 1],
        );
        let darkening: f64 = (0..6)
            .map(|i| ((1.0 - wl_frac) * ld0[i] + wl_frac * ld1[i]) * sample_cosine.powi(i as i32))
            .sum();
        direct * darkening
    }

    /// Sky plus solar disc radiance at zenith angle `theta`, angle `gamma`
    /// from the sun (`arhosekskymodel_solar_radiance`).
    pub fn radiance(&self, theta: f64, gamma: f64, wavelength: f64) -> f64 {
        self.solar_disc_radiance(wavelength, PI / 2.0 - theta, gamma)
            + self.sky_radiance(theta, gamma, wavelength)
    }
}

/// `makesky`'s parameters out of range.
#[derive(Clone, Debug, PartialEq)]
pub enum SkyError {
    /// Albedo outside [0, 1].
    Albedo(Float),
    /// Turbidity outside [1.7, 10].
    Turbidity(Float),
    /// Elevation outside [0, 90] degrees.
    Elevation(Float),
    /// Resolution below 1.
    Resolution(i32),
}

impl fmt::Display for SkyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SkyError::Albedo(a) => write!(f, "--albedo {a} must be between 0 and 1"),
            SkyError::Turbidity(t) => write!(f, "--turbidity {t} must be between 1.7 and 10."),
            SkyError::Elevation(e) => write!(f, "--elevation {e} must be between 0. and 90."),
            SkyError::Resolution(r) => write!(f, "--resolution {r} must be >= 1"),
        }
    }
}

impl std::error::Error for SkyError {}

/// The wavelengths `makesky` samples: 13 from 320 to 720 nm.
pub fn makesky_wavelengths() -> Vec<f64> {
    let n = 1 + (720 - 320) / 32;
    (0..n)
        .map(|i| 320.0 + (720.0 - 320.0) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The sky's ACES2065-1 RGB radiance in light-space direction `v` (z up)
/// for the sun in direction `sun`: the model sampled at
/// [`makesky_wavelengths`], read as a piecewise-linear spectrum and
/// converted through CIE XYZ, as pbrt-v4's `makesky` does per pixel.
pub fn sky_rgb(model: &SkyModel, v: [f64; 3], sun: [f64; 3]) -> [Float; 3] {
    let lambdas = makesky_wavelengths();
    let theta = spherical_theta(rpbrt_geometry::Vector3f::new(
        v[0] as Float,
        v[1] as Float,
        v[2] as Float,
    )) as f64;
    let cos_gamma = (v[0] * sun[0] + v[1] * sun[1] + v[2] * sun[2]).clamp(-1.0, 1.0);
    let gamma = cos_gamma.acos();
    let values: Vec<Float> = lambdas
        .iter()
        .map(|&l| model.radiance(theta, gamma, l) as Float)
        .collect();
    let lambdas: Vec<Float> = lambdas.iter().map(|&l| l as Float).collect();
    let Ok(spec) = PiecewiseLinearSpectrum::new(lambdas, values) else {
        return [0.0; 3];
    };
    let xyz = spectrum_to_xyz(&Spectrum::PiecewiseLinear(Arc::new(spec)));
    match RgbColorSpace::get("aces2065-1") {
        Some(cs) => cs.to_rgb(xyz).to_array(),
        None => [0.0; 3],
    }
}

/// pbrt-v4's `imgtool makesky`: a `resolution`² equal-area RGB map of the
/// Hosek–Wilkie sky (sun and sky) for the sun `elevation_degrees` above the
/// horizon toward +y, `turbidity` and ground `albedo`, with +z up and the
/// lower hemisphere black; ACES2065-1 RGB, and the parameters in the
/// metadata as pbrt-v4 writes them (its elevation in radians).
pub fn make_sky(
    albedo: Float,
    elevation_degrees: Float,
    turbidity: Float,
    resolution: i32,
) -> Result<(Image, ImageMetadata), SkyError> {
    if !(0.0..=1.0).contains(&albedo) {
        return Err(SkyError::Albedo(albedo));
    }
    if !(1.7..=10.0).contains(&turbidity) {
        return Err(SkyError::Turbidity(turbidity));
    }
    if !(0.0..=90.0).contains(&elevation_degrees) {
        return Err(SkyError::Elevation(elevation_degrees));
    }
    if resolution < 1 {
        return Err(SkyError::Resolution(resolution));
    }
    let elevation = (elevation_degrees as f64).to_radians();
    let model = SkyModel::new(elevation, turbidity as f64, albedo as f64);
    // Elevation is measured from the horizon; the sun lies toward +y.
    let sun = [0.0, elevation.cos(), elevation.sin()];
    let n = resolution as usize;
    let mut pixels = vec![0.0 as Float; n * n * 3];
    pixels
        .par_chunks_mut(n * 3)
        .enumerate()
        .for_each(|(iy, row)| {
            let y = (iy as Float + 0.5) / resolution as Float;
            for ix in 0..n {
                let x = (ix as Float + 0.5) / resolution as Float;
                let v = equal_area_square_to_sphere(Point2f::new(x, y));
                if v.z <= 0.0 {
                    continue;
                }
                let rgb = sky_rgb(&model, [v.x as f64, v.y as f64, v.z as f64], sun);
                row[ix * 3..ix * 3 + 3].copy_from_slice(&rgb);
            }
        });
    let image = Image::from_f32(
        pixels,
        Point2i::new(resolution, resolution),
        &["R", "G", "B"],
    )
    .map_err(|_| SkyError::Resolution(resolution))?;
    let mut metadata = ImageMetadata {
        color_space: Some("aces2065-1".into()),
        ..ImageMetadata::default()
    };
    // pbrt-v4 formats them with std::to_string (six decimals).
    for (k, v) in [
        ("makesky.albedo", albedo as f64),
        ("makesky.elevation", elevation),
        ("makesky.turbidity", turbidity as f64),
    ] {
        metadata.strings.insert(k.into(), vec![format!("{v:.6}")]);
    }
    Ok((image, metadata))
}

#[cfg(test)]
mod tests;
