//! A medium whose density is sampled on a regular grid (pbrt-v4
//! `GridMedium`, the `"uniformgrid"` medium; book section 11.4.2 "Grid
//! Medium"): constant absorption and scattering spectra scaled by a
//! trilinearly interpolated density, optional emission from either a
//! temperature grid (blackbody) or a spectrum times a scale grid, and a
//! 16³ majorant grid walked with the DDA.

use super::create::{
    check_values, coefficient, grid_bounds, grid_resolution, le_spectrum, non_negative,
    phase_asymmetry,
};
use super::majorant::{DdaMajorantIterator, MajorantGrid};
use super::sampled_grid::SampledGrid;
use super::{ConcreteMedium, HGPhaseFunction, MediumProperties};
use crate::params::ParamReader;
use crate::spectrum::{
    BlackbodySpectrum, DenselySampledSpectrum, SampledSpectrum, SampledWavelengths, Spectrum,
};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::Point3f;
use rpbrt_geometry::Bounds3f;
use rpbrt_parser::Diagnostic;

/// The majorant grid's resolution on each axis (pbrt-v4's 16³).
pub const GRID_MAJORANT_RES: i32 = 16;

/// Below this temperature (Kelvin) a temperature grid emits nothing.
const MIN_EMITTING_TEMPERATURE: Float = 100.0;

/// The parts of a [`GridMedium`], as `MakeNamedMedium` gives them.
#[derive(Clone, Debug)]
pub struct GridMediumParts {
    /// The medium's box, in medium space.
    pub bounds: Bounds3f,
    /// From medium space to rendering space.
    pub render_from_medium: Transform,
    /// Absorption at unit density.
    pub sigma_a: Spectrum,
    /// Scattering at unit density.
    pub sigma_s: Spectrum,
    /// Multiplies `sigma_a` and `sigma_s`.
    pub sigma_scale: Float,
    /// Henyey–Greenstein asymmetry.
    pub g: Float,
    /// The density samples.
    pub density: SampledGrid<Float>,
    /// Temperature samples (Kelvin before offset and scale), when the
    /// medium glows as a blackbody.
    pub temperature: Option<SampledGrid<Float>>,
    /// Multiplies the temperature after the offset.
    pub temperature_scale: Float,
    /// Subtracted from the temperature.
    pub temperature_offset: Float,
    /// The emitted spectrum without a temperature grid (zero for none).
    pub le: Spectrum,
    /// Emission scale samples (with the photometric normalisation of
    /// `le` folded in).
    pub le_scale: SampledGrid<Float>,
}

/// pbrt-v4's `uniformgrid` medium.
#[derive(Clone, Debug)]
pub struct GridMedium {
    bounds: Bounds3f,
    medium_from_render: Transform,
    sigma_a: DenselySampledSpectrum,
    sigma_s: DenselySampledSpectrum,
    density: SampledGrid<Float>,
    phase: HGPhaseFunction,
    temperature: Option<SampledGrid<Float>>,
    temperature_scale: Float,
    temperature_offset: Float,
    le: DenselySampledSpectrum,
    le_scale: SampledGrid<Float>,
    emissive: bool,
    majorant: MajorantGrid,
}

impl GridMedium {
    /// The medium of `parts`; its bounds must have positive extent on
    /// every axis.
    pub fn new(parts: GridMediumParts) -> Self {
        let mut sigma_a = DenselySampledSpectrum::new(&parts.sigma_a);
        let mut sigma_s = DenselySampledSpectrum::new(&parts.sigma_s);
        sigma_a.scale(parts.sigma_scale);
        sigma_s.scale(parts.sigma_scale);
        let le = DenselySampledSpectrum::new(&parts.le);
        let emissive = parts.temperature.is_some() || le.max_value() > 0.0;
        let res = [GRID_MAJORANT_RES; 3];
        let mut majorant = MajorantGrid::new(parts.bounds, res);
        majorant.fill(|b| parts.density.max_value(b));
        GridMedium {
            bounds: parts.bounds,
            medium_from_render: parts.render_from_medium.inverse(),
            sigma_a,
            sigma_s,
            density: parts.density,
            phase: HGPhaseFunction::new(parts.g),
            temperature: parts.temperature,
            temperature_scale: parts.temperature_scale,
            temperature_offset: parts.temperature_offset,
            le,
            le_scale: parts.le_scale,
            emissive,
            majorant,
        }
    }

    /// Creates the medium from `MakeNamedMedium "uniformgrid"` parameters
    /// (pbrt-v4 `GridMedium::Create`).
    pub fn create(mp: &ParamReader, render_from_medium: &Transform) -> Result<Self, Diagnostic> {
        let density = mp.floats("density")?;
        if density.is_empty() {
            return Err(mp.error("no \"density\" values provided for grid medium"));
        }
        let temperature = mp.floats("temperature")?;
        if !temperature.is_empty() && temperature.len() != density.len() {
            return Err(mp.error_at(
                "temperature",
                format!(
                    "different number of samples ({} vs {}) provided for \"density\" and \"temperature\"",
                    density.len(),
                    temperature.len()
                ),
            ));
        }
        let (nx, ny, nz, n) = grid_resolution(mp)?;
        if density.len() as u64 != n {
            return Err(mp.error_at(
                "density",
                format!(
                    "grid medium has {} density values; expected nx*ny*nz = {nx}*{ny}*{nz} = {n}",
                    density.len()
                ),
            ));
        }
        check_values(mp, "density", &density)?;
        check_values(mp, "temperature", &temperature)?;

        let le = le_spectrum(mp)?;
        if le.is_some() && !temperature.is_empty() {
            return Err(mp.error_at("Le", "both \"Le\" and \"temperature\" values were provided"));
        }
        let (le, le_norm) = match le {
            Some((le, norm)) => (le, norm),
            None => (Spectrum::constant(0.0), 1.0),
        };
        let mut le_scale = mp.floats("Lescale")?;
        if le_scale.iter().any(|v| !v.is_finite()) {
            return Err(mp.error_at("Lescale", "\"Lescale\" values must be finite"));
        }
        let (lx, ly, lz) = match le_scale.len() as u64 {
            // No values: pbrt-v4's default, a 1×1×1 grid.
            0 => {
                le_scale.push(1.0);
                (1, 1, 1)
            }
            // One value: a 1×1×1 grid too (pbrt-v4 accepts one value only
            // when the density grid is 1×1×1).
            1 => (1, 1, 1),
            len if len == n => (nx, ny, nz),
            len => {
                return Err(mp.error_at(
                    "Lescale",
                    format!("expected 1 or nx*ny*nz = {n} values for \"Lescale\", got {len}"),
                ))
            }
        };
        for v in &mut le_scale {
            *v *= le_norm;
        }

        let bounds = grid_bounds(mp)?;
        let g = phase_asymmetry(mp)?;
        let sigma_a = coefficient(mp, "sigma_a")?;
        let sigma_s = coefficient(mp, "sigma_s")?;
        let sigma_scale = non_negative(mp, "scale", 1.0)?;
        // "temperaturecutoff" is the older name of "temperatureoffset".
        let cutoff = finite_float(mp, "temperaturecutoff", 0.0)?;
        let temperature_offset = finite_float(mp, "temperatureoffset", cutoff)?;
        let temperature_scale = finite_float(mp, "temperaturescale", 1.0)?;

        let grid = |values: Vec<Float>, x: i32, y: i32, z: i32, name: &str| {
            SampledGrid::new(values, x, y, z)
                .ok_or_else(|| mp.error_at(name, format!("\"{name}\" does not fit the grid")))
        };
        let density = grid(density, nx, ny, nz, "density")?;
        let temperature = if temperature.is_empty() {
            None
        } else {
            Some(grid(temperature, nx, ny, nz, "temperature")?)
        };
        let le_scale = grid(le_scale, lx, ly, lz, "Lescale")?;
        Ok(GridMedium::new(GridMediumParts {
            bounds,
            render_from_medium: *render_from_medium,
            sigma_a,
            sigma_s,
            sigma_scale,
            g,
            density,
            temperature,
            temperature_scale,
            temperature_offset,
            le,
            le_scale,
        }))
    }

    /// Whether the medium emits light somewhere.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        self.emissive
    }

    /// The medium's box, in medium space.
    pub fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    /// The per-voxel maximum densities the DDA walks.
    pub fn majorant_grid(&self) -> &MajorantGrid {
        &self.majorant
    }

    /// The interpolated density at a point in the `[0, 1]³`
    /// parametrisation of the bounds.
    #[inline]
    pub fn density(&self, p: Point3f) -> Float {
        self.density.lookup(p)
    }

    /// The emitted radiance at `p` (`[0, 1]³` over the bounds).
    #[inline]
    fn le(&self, p: Point3f, lambda: &SampledWavelengths) -> SampledSpectrum {
        if !self.emissive {
            return SampledSpectrum::new(0.0);
        }
        let scale = self.le_scale.lookup(p);
        if scale.is_nan() || scale <= 0.0 {
            return SampledSpectrum::new(0.0);
        }
        match &self.temperature {
            Some(grid) => {
                let temp = (grid.lookup(p) - self.temperature_offset) * self.temperature_scale;
                if temp > MIN_EMITTING_TEMPERATURE {
                    let bb = BlackbodySpectrum::new(temp);
                    SampledSpectrum::from_array(lambda.lambda.map(|l| bb.evaluate(l))) * scale
                } else {
                    SampledSpectrum::new(0.0)
                }
            }
            None => self.le.sample(lambda) * scale,
        }
    }
}

/// A float parameter that must be finite.
fn finite_float(mp: &ParamReader, name: &str, default: Float) -> Result<Float, Diagnostic> {
    let v = mp.float(name, default)?;
    if !v.is_finite() {
        return Err(mp.error_at(name, format!("\"{name}\" must be finite, got {v}")));
    }
    Ok(v)
}

impl ConcreteMedium for GridMedium {
    type Majorants<'a> = DdaMajorantIterator<'a>;

    #[inline]
    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        let p = Point3f::from(self.bounds.offset(self.medium_from_render.apply_point(p)));
        let d = self.density.lookup(p);
        MediumProperties {
            sigma_a: self.sigma_a.sample(lambda) * d,
            sigma_s: self.sigma_s.sample(lambda) * d,
            phase: self.phase,
            // pbrt-v4 evaluates the emission wherever the point is, even
            // where the density is zero.
            le: self.le(p, lambda),
        }
    }

    #[inline]
    fn sample_ray<'a>(
        &'a self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> DdaMajorantIterator<'a> {
        let sigma_t = self.sigma_a.sample(lambda) + self.sigma_s.sample(lambda);
        DdaMajorantIterator::through_grid(
            ray,
            t_max,
            &self.medium_from_render,
            &self.majorant,
            sigma_t,
        )
    }
}
