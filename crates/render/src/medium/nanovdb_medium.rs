//! A medium whose density (and optionally temperature) comes from a
//! NanoVDB file (pbrt-v4 `NanoVDBMedium`): trilinear lookups in the float
//! grids read by [`super::nanovdb`], a 64³ majorant grid over the grids'
//! world bounds, and blackbody emission from the temperature grid.

use super::majorant::{DdaMajorantIterator, MajorantGrid};
use super::nanovdb::FloatGrid;
use super::{scaled_spectrum, ConcreteMedium, HGPhaseFunction, MediumProperties};
use crate::spectrum::{DenselySampledSpectrum, SampledSpectrum, SampledWavelengths, Spectrum};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

/// Resolution of the majorant grid per axis (as pbrt-v4).
const MAJORANT_RES: i32 = 64;

/// The temperature grid and how its values become blackbody emission.
#[derive(Clone, Debug)]
pub struct NanoVdbTemperature {
    /// The grid, in the same file as the density.
    pub grid: FloatGrid,
    /// Subtracted from the grid's values before scaling.
    pub offset: Float,
    /// Multiplies the offset values, giving Kelvin.
    pub scale: Float,
    /// Scale of the emitted (normalised) blackbody radiance.
    pub le_scale: Float,
}

/// pbrt-v4's `nanovdb` medium.
#[derive(Clone, Debug)]
pub struct NanoVdbMedium {
    medium_from_render: Transform,
    sigma_a: DenselySampledSpectrum,
    sigma_s: DenselySampledSpectrum,
    phase: HGPhaseFunction,
    majorants: MajorantGrid,
    density: FloatGrid,
    temperature: Option<NanoVdbTemperature>,
}

fn bbox_of(g: &FloatGrid) -> Bounds3f {
    let (lo, hi) = g.world_bbox();
    Bounds3f::new(
        Point3f::new(lo[0] as Float, lo[1] as Float, lo[2] as Float),
        Point3f::new(hi[0] as Float, hi[1] as Float, hi[2] as Float),
    )
}

impl NanoVdbMedium {
    /// A medium of density grid `density` (values multiply `sigma_a` and
    /// `sigma_s`, both scaled by `sigma_scale`) placed by
    /// `render_from_medium`, emitting from `temperature` if given.
    pub fn new(
        render_from_medium: Transform,
        sigma_a: &Spectrum,
        sigma_s: &Spectrum,
        sigma_scale: Float,
        g: Float,
        density: FloatGrid,
        temperature: Option<NanoVdbTemperature>,
    ) -> Self {
        let mut bounds = bbox_of(&density);
        if let Some(t) = &temperature {
            bounds = bounds.union(&bbox_of(&t.grid));
        }
        let mut majorants = MajorantGrid::new(bounds, [MAJORANT_RES; 3]);
        let (ilo, ihi) = density.index_bbox();
        majorants.fill(|vb| {
            // The voxel's medium-space box, its corners in index space,
            // widened by one voxel for the trilinear filter's reach.
            let wb = Bounds3f::new(bounds.lerp(vb.p_min), bounds.lerp(vb.p_max));
            let mut lo = [Float::INFINITY; 3];
            let mut hi = [-Float::INFINITY; 3];
            for c in 0..8 {
                let p = [
                    if c & 1 == 0 { wb.p_min.x } else { wb.p_max.x },
                    if c & 2 == 0 { wb.p_min.y } else { wb.p_max.y },
                    if c & 4 == 0 { wb.p_min.z } else { wb.p_max.z },
                ];
                let q = density.world_to_index(p);
                for a in 0..3 {
                    lo[a] = lo[a].min(q[a]);
                    hi[a] = hi[a].max(q[a]);
                }
            }
            let range = |a: usize| {
                let l = ((lo[a] - 1.0).floor().max(ilo[a] as Float)) as i32;
                let h = ((hi[a] + 1.0).ceil().min(ihi[a] as Float)) as i32;
                l..=h
            };
            let mut m: Float = 0.0;
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        m = m.max(density.value([x, y, z]));
                    }
                }
            }
            m
        });
        NanoVdbMedium {
            medium_from_render: render_from_medium.inverse(),
            sigma_a: scaled_spectrum(sigma_a, sigma_scale),
            sigma_s: scaled_spectrum(sigma_s, sigma_scale),
            phase: HGPhaseFunction::new(g),
            majorants,
            density,
            temperature,
        }
    }

    /// Whether the medium emits (a temperature grid with a positive scale).
    pub fn is_emissive(&self) -> bool {
        self.temperature.as_ref().is_some_and(|t| t.le_scale > 0.0)
    }

    /// Blackbody emission at a medium-space point.
    #[inline]
    fn le(&self, p: [Float; 3], lambda: &SampledWavelengths) -> SampledSpectrum {
        let Some(t) = &self.temperature else {
            return SampledSpectrum::new(0.0);
        };
        let temp = (t.grid.sample_trilinear(t.grid.world_to_index(p)) - t.offset) * t.scale;
        if temp <= 100.0 {
            return SampledSpectrum::new(0.0);
        }
        Spectrum::blackbody(temp).sample(lambda) * t.le_scale
    }
}

impl ConcreteMedium for NanoVdbMedium {
    type Majorants<'a> = DdaMajorantIterator<'a>;

    #[inline]
    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        let p = self.medium_from_render.apply_point(p);
        let p = [p.x, p.y, p.z];
        let d = self
            .density
            .sample_trilinear(self.density.world_to_index(p));
        MediumProperties {
            sigma_a: self.sigma_a.sample(lambda) * d,
            sigma_s: self.sigma_s.sample(lambda) * d,
            phase: self.phase,
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
            &self.majorants,
            sigma_t,
        )
    }
}
