//! A grid medium with RGB coefficients (pbrt-v4 `RGBGridMedium`, the
//! `"rgbgrid"` medium; book section 11.4.3): absorption, scattering and
//! emission each given per sample as an RGB colour, turned into spectra in
//! the directive's colour space, and interpolated after being sampled at
//! the path's wavelengths.
//!
//! Each sample is stored as the scale and sigmoid polynomial of its RGB
//! spectrum (16 bytes). Emission samples are `RGBIlluminantSpectrum`s in
//! pbrt-v4: the same scale and polynomial times the colour space's
//! illuminant, which is common to all samples and so is applied once after
//! interpolation instead of at every lattice point.

use super::create::{grid_bounds, grid_resolution, non_negative, phase_asymmetry};
use super::majorant::{DdaMajorantIterator, MajorantGrid};
use super::sampled_grid::SampledGrid;
use super::{ConcreteMedium, HGPhaseFunction, MediumProperties};
use crate::params::ParamReader;
use crate::spectrum::{
    DenselySampledSpectrum, RgbColorSpace, RgbUnboundedSpectrum, SampledSpectrum,
    SampledWavelengths, RGB,
};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::Point3f;
use rpbrt_geometry::Bounds3f;
use rpbrt_parser::Diagnostic;
use std::sync::Arc;

/// The majorant grid's resolution on each axis (pbrt-v4's 16³).
pub const RGB_GRID_MAJORANT_RES: i32 = 16;

/// RGB emission samples and the illuminant they multiply.
#[derive(Clone, Debug)]
pub struct RgbEmissionGrid {
    /// Scale and polynomial of each sample's colour.
    pub grid: SampledGrid<RgbUnboundedSpectrum>,
    /// The colour space's standard illuminant.
    pub illuminant: Arc<DenselySampledSpectrum>,
}

/// The parts of an [`RgbGridMedium`].
#[derive(Clone, Debug)]
pub struct RgbGridMediumParts {
    /// The medium's box, in medium space.
    pub bounds: Bounds3f,
    /// From medium space to rendering space.
    pub render_from_medium: Transform,
    /// Henyey–Greenstein asymmetry.
    pub g: Float,
    /// Absorption samples (absent: 1 everywhere).
    pub sigma_a: Option<SampledGrid<RgbUnboundedSpectrum>>,
    /// Scattering samples (absent: 1 everywhere).
    pub sigma_s: Option<SampledGrid<RgbUnboundedSpectrum>>,
    /// Multiplies both coefficients.
    pub sigma_scale: Float,
    /// Emission samples, if the medium glows.
    pub le: Option<RgbEmissionGrid>,
    /// Multiplies the emission.
    pub le_scale: Float,
}

/// pbrt-v4's `rgbgrid` medium.
#[derive(Clone, Debug)]
pub struct RgbGridMedium {
    bounds: Bounds3f,
    medium_from_render: Transform,
    phase: HGPhaseFunction,
    sigma_a: Option<SampledGrid<RgbUnboundedSpectrum>>,
    sigma_s: Option<SampledGrid<RgbUnboundedSpectrum>>,
    sigma_scale: Float,
    le: Option<RgbEmissionGrid>,
    le_scale: Float,
    majorant: MajorantGrid,
}

/// The values of an RGB sample at the path's wavelengths.
#[inline(always)]
fn sample_rgb(s: RgbUnboundedSpectrum, lambda: &SampledWavelengths) -> SampledSpectrum {
    SampledSpectrum::from_array(s.rsp.evaluate_n(&lambda.lambda)) * s.scale
}

impl RgbGridMedium {
    /// The medium of `parts`; its bounds must have positive extent on
    /// every axis.
    pub fn new(parts: RgbGridMediumParts) -> Self {
        let mut majorant = MajorantGrid::new(parts.bounds, [RGB_GRID_MAJORANT_RES; 3]);
        let max = |grid: &Option<SampledGrid<RgbUnboundedSpectrum>>, b: &Bounds3f| match grid {
            Some(g) => g.max_value_with(b, |s| s.max_value()),
            None => 1.0,
        };
        majorant.fill(|b| parts.sigma_scale * (max(&parts.sigma_a, b) + max(&parts.sigma_s, b)));
        RgbGridMedium {
            bounds: parts.bounds,
            medium_from_render: parts.render_from_medium.inverse(),
            phase: HGPhaseFunction::new(parts.g),
            sigma_a: parts.sigma_a,
            sigma_s: parts.sigma_s,
            sigma_scale: parts.sigma_scale,
            le: parts.le,
            le_scale: parts.le_scale,
            majorant,
        }
    }

    /// Creates the medium from `MakeNamedMedium "rgbgrid"` parameters
    /// (pbrt-v4 `RGBGridMedium::Create`); RGB values are in the
    /// directive's colour space.
    pub fn create(mp: &ParamReader, render_from_medium: &Transform) -> Result<Self, Diagnostic> {
        let sigma_a = mp.rgbs("sigma_a")?;
        let sigma_s = mp.rgbs("sigma_s")?;
        let le = mp.rgbs("Le")?;
        if sigma_a.is_empty() && sigma_s.is_empty() {
            return Err(
                mp.error("RGB grid requires \"sigma_a\" and/or \"sigma_s\" parameter values")
            );
        }
        let n_density = if sigma_a.is_empty() {
            sigma_s.len()
        } else {
            sigma_a.len()
        };
        if !sigma_a.is_empty() && !sigma_s.is_empty() && sigma_a.len() != sigma_s.len() {
            return Err(mp.error_at(
                "sigma_s",
                format!(
                    "different number of samples ({} vs {}) provided for \"sigma_a\" and \"sigma_s\"",
                    sigma_a.len(),
                    sigma_s.len()
                ),
            ));
        }
        if !le.is_empty() && sigma_a.is_empty() {
            return Err(mp.error_at(
                "Le",
                "RGB grid requires \"sigma_a\" if \"Le\" value provided",
            ));
        }
        if !le.is_empty() && le.len() != n_density {
            return Err(mp.error_at(
                "Le",
                format!(
                    "expected {n_density} values for \"Le\" but were given {}",
                    le.len()
                ),
            ));
        }
        let (nx, ny, nz, n) = grid_resolution(mp)?;
        if n_density as u64 != n {
            let at = if sigma_a.is_empty() {
                "sigma_s"
            } else {
                "sigma_a"
            };
            return Err(mp.error_at(
                at,
                format!(
                    "RGB grid medium has {n_density} density values; expected nx*ny*nz = {nx}*{ny}*{nz} = {n}"
                ),
            ));
        }
        for (name, values) in [("sigma_a", &sigma_a), ("sigma_s", &sigma_s), ("Le", &le)] {
            if let Some((i, c)) = values
                .iter()
                .enumerate()
                .find(|(_, c)| c.iter().any(|v| !v.is_finite()))
            {
                return Err(mp.error_at(
                    name,
                    format!(
                        "\"{name}\" values must be finite; RGB {i} is ({}, {}, {})",
                        c[0], c[1], c[2]
                    ),
                ));
            }
        }

        let cs = mp.color_space();
        let grid = |values: &[[Float; 3]], name: &str| {
            if values.is_empty() {
                return Ok(None);
            }
            let spectra = values.iter().map(|c| to_spectrum(cs, *c)).collect();
            SampledGrid::new(spectra, nx, ny, nz)
                .map(Some)
                .ok_or_else(|| mp.error_at(name, format!("\"{name}\" does not fit the grid")))
        };
        let sigma_a = grid(&sigma_a, "sigma_a")?;
        let sigma_s = grid(&sigma_s, "sigma_s")?;
        let le = grid(&le, "Le")?.map(|grid| RgbEmissionGrid {
            grid,
            illuminant: cs.illuminant.clone(),
        });

        let bounds = grid_bounds(mp)?;
        let le_scale = mp.float("Lescale", 1.0)?;
        if !le_scale.is_finite() {
            return Err(mp.error_at("Lescale", "\"Lescale\" must be finite"));
        }
        let g = phase_asymmetry(mp)?;
        let sigma_scale = non_negative(mp, "scale", 1.0)?;
        Ok(RgbGridMedium::new(RgbGridMediumParts {
            bounds,
            render_from_medium: *render_from_medium,
            g,
            sigma_a,
            sigma_s,
            sigma_scale,
            le,
            le_scale,
        }))
    }

    /// Whether the medium emits light somewhere.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        self.le.is_some() && self.le_scale > 0.0
    }

    /// The medium's box, in medium space.
    pub fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    /// The per-voxel maximum extinctions the DDA walks.
    pub fn majorant_grid(&self) -> &MajorantGrid {
        &self.majorant
    }
}

/// The spectrum of a (non-negative) RGB sample.
fn to_spectrum(cs: &RgbColorSpace, c: [Float; 3]) -> RgbUnboundedSpectrum {
    RgbUnboundedSpectrum::new(cs, RGB::new(c[0], c[1], c[2]))
}

impl ConcreteMedium for RgbGridMedium {
    type Majorants<'a> = DdaMajorantIterator<'a>;

    #[inline]
    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        let p = Point3f::from(self.bounds.offset(self.medium_from_render.apply_point(p)));
        let convert = |s| sample_rgb(s, lambda);
        let coefficient = |grid: &Option<SampledGrid<RgbUnboundedSpectrum>>| match grid {
            Some(g) => g.lookup_with(p, convert) * self.sigma_scale,
            None => SampledSpectrum::new(self.sigma_scale),
        };
        let le = match &self.le {
            Some(e) if self.le_scale > 0.0 => {
                e.grid.lookup_with(p, convert) * e.illuminant.sample(lambda) * self.le_scale
            }
            _ => SampledSpectrum::new(0.0),
        };
        MediumProperties {
            sigma_a: coefficient(&self.sigma_a),
            sigma_s: coefficient(&self.sigma_s),
            phase: self.phase,
            le,
        }
    }

    #[inline]
    fn sample_ray<'a>(
        &'a self,
        ray: &Ray,
        t_max: Float,
        _lambda: &SampledWavelengths,
    ) -> DdaMajorantIterator<'a> {
        // The majorant grid holds extinctions already.
        let one = SampledSpectrum::new(1.0);
        DdaMajorantIterator::through_grid(ray, t_max, &self.medium_from_render, &self.majorant, one)
    }
}
