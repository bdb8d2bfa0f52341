//! pbrt-v1/v2's volume regions (the `Volume` directive; pbrt-v2
//! `core/volume.h` and `volumes/*.cpp`): participating media with no
//! bounding surface, each a box in the coordinate system in effect at its
//! directive, seen by every ray that crosses it. Overlapping regions add
//! up, as pbrt-v2's `AggregateVolume` added them.
//!
//! Each region scales its absorption, scattering and emission by a
//! density: 1 in the box (`homogeneous`), `a·exp(−b·h)` with `h` the
//! height above the box's lower corner along `updir` (`exponential`), or
//! a grid of samples interpolated trilinearly over the box with clamped
//! indices (`volumegrid`; pbrt-v4's grids read zero past their edges
//! instead). Delta tracking needs a majorant along each ray: a region
//! contributes its largest density along the part of the ray inside its
//! box (exact for the first two; the grid's largest sample for the
//! third), and the segments where regions overlap carry their sum.
//!
//! pbrt-v2 added a region's emission `Lve` per unit length travelled;
//! pbrt-v4's radiative transfer (which volpath solves) emits `σa·Le`, so
//! a point's `Le` is the regions' summed `Lve` over their summed `σa`.

use super::create::{check_values, coefficient, emission, grid_bounds, grid_resolution};
use super::{
    scaled_spectrum, ConcreteMedium, HGPhaseFunction, MediumProperties, RayMajorantSegment,
};
use crate::params::{unknown_type, ParamReader};
use crate::spectrum::{DenselySampledSpectrum, SampledSpectrum, SampledWavelengths, Spectrum};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use rpbrt_parser::Diagnostic;

/// The region types `Volume` accepts, sorted.
pub const REGION_NAMES: &[&str] = &["exponential", "homogeneous", "volumegrid"];

/// How a region's density varies over its box (region space).
#[derive(Clone, Debug)]
enum Density {
    /// 1 everywhere in the box.
    Constant,
    /// `a·exp(−b·h)`, `h = (p − p0)·up` with `up` of unit length.
    Exponential { a: Float, b: Float, up: Vector3f },
    /// Samples at the centres of `n[0] × n[1] × n[2]` cells of the box,
    /// x fastest, and the largest of them.
    Grid {
        values: Vec<Float>,
        n: [i32; 3],
        max: Float,
    },
}

/// One `Volume` directive's region.
#[derive(Clone, Debug)]
pub struct VolumeRegion {
    /// Rendering space to the region's own.
    region_from_render: Transform,
    /// The box, in region space.
    bounds: Bounds3f,
    density: Density,
    sigma_a: DenselySampledSpectrum,
    sigma_s: DenselySampledSpectrum,
    le: DenselySampledSpectrum,
    g: Float,
    emissive: bool,
    /// False: the scattering counts as absorption (see
    /// [`RegionMedium::create`]).
    scatter: bool,
}

/// Every `Volume` region of a scene, as one medium.
#[derive(Clone, Debug)]
pub struct RegionMedium {
    regions: Vec<VolumeRegion>,
}

impl Density {
    /// The density at region-space point `p` of a box `b` that holds it.
    fn at(&self, b: &Bounds3f, p: Point3f) -> Float {
        match self {
            Density::Constant => 1.0,
            Density::Exponential { a, b: falloff, up } => {
                let h = (p - b.p_min).dot(*up);
                a * (-falloff * h).exp()
            }
            Density::Grid { values, n, .. } => {
                let o = b.offset(p);
                let o = [o.x, o.y, o.z];
                let lattice = [0, 1, 2].map(|a| o[a] * n[a] as Float - 0.5);
                let i = [0, 1, 2].map(|a| lattice[a].floor());
                let d = [0, 1, 2].map(|a| lattice[a] - i[a]);
                let at = |dx: i32, dy: i32, dz: i32| {
                    let c = |a: usize, di: i32| (i[a] as i32 + di).clamp(0, n[a] - 1);
                    let (x, y, z) = (c(0, dx), c(1, dy), c(2, dz));
                    values[((z * n[1] + y) * n[0] + x) as usize]
                };
                let lerp = |t: Float, a: Float, b: Float| (1.0 - t) * a + t * b;
                let d00 = lerp(d[0], at(0, 0, 0), at(1, 0, 0));
                let d10 = lerp(d[0], at(0, 1, 0), at(1, 1, 0));
                let d01 = lerp(d[0], at(0, 0, 1), at(1, 0, 1));
                let d11 = lerp(d[0], at(0, 1, 1), at(1, 1, 1));
                lerp(d[2], lerp(d[1], d00, d10), lerp(d[1], d01, d11))
            }
        }
    }

    /// The largest density along the region-space segment from `p0` to
    /// `p1` inside box `b`.
    fn max_on(&self, b: &Bounds3f, p0: Point3f, p1: Point3f) -> Float {
        match self {
            Density::Constant => 1.0,
            // The height is linear along the segment, so the density is
            // largest at one of its ends.
            Density::Exponential { .. } => self.at(b, p0).max(self.at(b, p1)),
            Density::Grid { max, .. } => *max,
        }
    }
}

impl VolumeRegion {
    /// The part `[t0, t1]` of `ray` (rendering space) within `[0, t_max]`
    /// inside the box, and the majorant there.
    fn majorant(
        &self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> Option<RayMajorantSegment> {
        // An affine map keeps the ray's parametrisation.
        let o = self.region_from_render.apply_point(ray.o);
        let d = self.region_from_render.apply_vector(ray.d);
        let (t0, t1) = self.bounds.intersect_p(o, d, t_max)?;
        let density = self.density.max_on(&self.bounds, o + d * t0, o + d * t1);
        let sigma_t = self.sigma_a.sample(lambda) + self.sigma_s.sample(lambda);
        Some(RayMajorantSegment {
            t_min: t0,
            t_max: t1,
            sigma_maj: sigma_t * density,
        })
    }
}

impl RegionMedium {
    /// The medium of a scene's regions (at least one).
    pub fn new(regions: Vec<VolumeRegion>) -> Self {
        RegionMedium { regions }
    }

    /// Whether some region emits light.
    pub fn is_emissive(&self) -> bool {
        self.regions.iter().any(|r| r.emissive)
    }
}

/// One region: pbrt-v2's `sigma_a`, `sigma_s` (default 0), `Le` (0), `g`
/// (0) and box `p0`–`p1` (the unit cube) for every type; `a`, `b` (1) and
/// `updir` (0, 1, 0) for `exponential`; `nx`, `ny`, `nz` (1) and
/// `density` for `volumegrid`.
///
/// `scatter` is false under pbrt-v2's `emission` volume integrator, which
/// attenuated by absorption and scattering alike and added emission but
/// no scattered light: the scattering then counts as absorption.
pub fn create_region(
    name: &str,
    mp: &ParamReader,
    render_from_region: &Transform,
    scatter: bool,
) -> Result<VolumeRegion, Diagnostic> {
    let zero_default = |param: &str| -> Result<Spectrum, Diagnostic> {
        if mp.has(param) {
            coefficient(mp, param)
        } else {
            Ok(Spectrum::constant(0.0))
        }
    };
    let sigma_a = scaled_spectrum(&zero_default("sigma_a")?, 1.0);
    let sigma_s = scaled_spectrum(&zero_default("sigma_s")?, 1.0);
    let (le, le_scale) = emission(mp)?;
    let le = scaled_spectrum(&le, le_scale);
    let absorbs = sigma_a.max_value() > 0.0 || (!scatter && sigma_s.max_value() > 0.0);
    if le.max_value() > 0.0 && !absorbs {
        mp.warn_at(
            "Le",
            "this region emits but does not absorb: pbrt-v4's media emit in proportion to their absorption, so it renders dark",
        );
    }
    let g = mp.float("g", 0.0)?;
    if !(-1.0..=1.0).contains(&g) {
        return Err(mp.error_at("g", format!("\"g\" must be in [-1, 1], got {g}")));
    }
    let bounds = grid_bounds(mp)?;
    let density = match name {
        "homogeneous" => Density::Constant,
        "exponential" => {
            let a = mp.float("a", 1.0)?;
            let b = mp.float("b", 1.0)?;
            for (param, v) in [("a", a), ("b", b)] {
                if !v.is_finite() {
                    return Err(mp.error_at(param, format!("\"{param}\" must be finite, got {v}")));
                }
            }
            if a < 0.0 {
                return Err(mp.error_at("a", format!("\"a\" must not be negative, got {a}")));
            }
            let [x, y, z] = mp.vector3("updir", [0.0, 1.0, 0.0])?;
            let up = Vector3f::new(x, y, z);
            let len = up.length();
            if !(len > 0.0 && len.is_finite()) {
                return Err(mp.error_at(
                    "updir",
                    format!("\"updir\" must be a non-zero finite vector, got ({x}, {y}, {z})"),
                ));
            }
            Density::Exponential { a, b, up: up / len }
        }
        "volumegrid" => {
            let (nx, ny, nz, total) = grid_resolution(mp)?;
            let values = mp.floats("density")?;
            if values.len() as u64 != total {
                return Err(mp.error_at(
                    "density",
                    format!(
                        "\"density\" has {} values, but the grid is {nx} x {ny} x {nz} ({total})",
                        values.len()
                    ),
                ));
            }
            check_values(mp, "density", &values)?;
            let max = values.iter().copied().fold(0.0, Float::max);
            Density::Grid {
                values,
                n: [nx, ny, nz],
                max,
            }
        }
        _ => return Err(unknown_type("volume region", name, REGION_NAMES, mp.loc())),
    };
    Ok(VolumeRegion {
        region_from_render: render_from_region.inverse(),
        bounds,
        density,
        emissive: le.max_value() > 0.0,
        sigma_a,
        sigma_s,
        le,
        g,
        scatter,
    })
}

impl ConcreteMedium for RegionMedium {
    type Majorants<'a> = std::vec::IntoIter<RayMajorantSegment>;

    fn sample_point(&self, p: Point3f, lambda: &SampledWavelengths) -> MediumProperties {
        let mut sigma_a = SampledSpectrum::new(0.0);
        let mut sigma_s = SampledSpectrum::new(0.0);
        let mut lve = SampledSpectrum::new(0.0);
        // Overlapping regions scatter with their asymmetries averaged,
        // weighted by how much each scatters there.
        let (mut g_sum, mut weight) = (0.0, 0.0);
        for r in &self.regions {
            let pr = r.region_from_render.apply_point(p);
            if !r.bounds.inside(pr) {
                continue;
            }
            let d = r.density.at(&r.bounds, pr);
            let mut a = r.sigma_a.sample(lambda) * d;
            let mut s = r.sigma_s.sample(lambda) * d;
            if !r.scatter {
                a += s;
                s = SampledSpectrum::new(0.0);
            }
            sigma_a += a;
            sigma_s += s;
            if r.emissive {
                lve += r.le.sample(lambda) * d;
            }
            g_sum += r.g * s.average();
            weight += s.average();
        }
        let g = if weight > 0.0 { g_sum / weight } else { 0.0 };
        MediumProperties {
            // pbrt-v2 added `Lve` per unit length; pbrt-v4's media emit
            // `σa·Le`.
            le: SampledSpectrum::safe_div(lve, sigma_a),
            sigma_a,
            sigma_s,
            phase: HGPhaseFunction::new(g),
        }
    }

    fn sample_ray(
        &self,
        ray: &Ray,
        t_max: Float,
        lambda: &SampledWavelengths,
    ) -> std::vec::IntoIter<RayMajorantSegment> {
        let parts: Vec<RayMajorantSegment> = self
            .regions
            .iter()
            .filter_map(|r| r.majorant(ray, t_max, lambda))
            .collect();
        if parts.len() <= 1 {
            return parts.into_iter();
        }
        // Overlaps: cut at every region's ends and add the majorants of
        // the regions over each piece.
        let mut cuts: Vec<Float> = parts.iter().flat_map(|s| [s.t_min, s.t_max]).collect();
        cuts.sort_by(Float::total_cmp);
        cuts.dedup();
        let mut segments = Vec::with_capacity(cuts.len());
        for w in cuts.windows(2) {
            let (t0, t1) = (w[0], w[1]);
            let mid = 0.5 * (t0 + t1);
            let mut sigma_maj = SampledSpectrum::new(0.0);
            let mut any = false;
            for s in parts.iter().filter(|s| s.t_min <= mid && mid <= s.t_max) {
                sigma_maj += s.sigma_maj;
                any = true;
            }
            if any {
                segments.push(RayMajorantSegment {
                    t_min: t0,
                    t_max: t1,
                    sigma_maj,
                });
            }
        }
        segments.into_iter()
    }
}
