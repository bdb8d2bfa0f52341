//! The tabulated radial BSSRDF (pbrt-v4 `TabulatedBSSRDF`, pbrt-v3 book
//! sections 11.4 and 15.4): evaluation, importance sampling of the probe
//! segment and its density.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{Frame, Point3fi, SurfaceInteraction};

use crate::bxdf::{BxDF, NormalizedFresnelBxDF, BSDF};
use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

use super::spline::{catmull_rom_weights, invert_catmull_rom, sample_catmull_rom_2d};
use super::table::BssrdfTable;

/// The geometry of a probe-ray hit that a BSSRDF sample needs (pbrt-v4
/// `SubsurfaceInteraction`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubsurfaceInteraction {
    /// Position with error bounds.
    pub pi: Point3fi,
    /// Geometric normal.
    pub n: Normal3f,
    /// Shading normal.
    pub ns: Normal3f,
    /// ∂p/∂u.
    pub dpdu: Vector3f,
    /// ∂p/∂v.
    pub dpdv: Vector3f,
    /// Shading ∂p/∂u.
    pub dpdus: Vector3f,
    /// Shading ∂p/∂v.
    pub dpdvs: Vector3f,
}

impl SubsurfaceInteraction {
    /// The point (midpoint of its error bounds).
    #[inline]
    pub fn p(&self) -> Point3f {
        self.pi.midpoint()
    }
}

impl From<&SurfaceInteraction> for SubsurfaceInteraction {
    fn from(si: &SurfaceInteraction) -> Self {
        SubsurfaceInteraction {
            pi: si.pi,
            n: si.n,
            ns: si.shading.n,
            dpdu: si.dpdu,
            dpdv: si.dpdv,
            dpdus: si.shading.dpdu,
            dpdvs: si.shading.dpdv,
        }
    }
}

/// The segment a probe ray is traced along to find where light sampled by
/// the BSSRDF enters the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BssrdfProbeSegment {
    /// Start of the segment.
    pub p0: Point3f,
    /// End of the segment.
    pub p1: Point3f,
}

/// The BSSRDF's value at a probe hit, with its density and the BSDF that
/// light enters through there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BssrdfSample {
    /// Spatial profile value Sp(pi).
    pub sp: SampledSpectrum,
    /// Density of having sampled pi (per unit area), per wavelength.
    pub pdf: SampledSpectrum,
    /// The entry point's directional term: a normalized Fresnel lobe.
    pub sw: BSDF,
    /// The outgoing direction to evaluate `sw` with (the shading normal).
    pub wo: Vector3f,
}

/// A radially symmetric BSSRDF interpolated from a [`BssrdfTable`]:
/// S(po, pi) ≈ Sp(|po − pi|) · Sw(wi), with per-wavelength σt and albedo.
#[derive(Clone, Copy, Debug)]
pub struct TabulatedBssrdf<'a> {
    po: Point3f,
    wo: Vector3f,
    ns: Normal3f,
    eta: Float,
    sigma_t: SampledSpectrum,
    rho: SampledSpectrum,
    table: &'a BssrdfTable,
}

/// Probabilities of projecting along the local x, y and z axes.
const AXIS_PROB: [Float; 3] = [0.25, 0.25, 0.5];

impl<'a> TabulatedBssrdf<'a> {
    /// The BSSRDF leaving at `po` (shading normal `ns`, direction `wo`)
    /// through a boundary of relative index `eta`, for a medium with
    /// absorption `sigma_a` and scattering `sigma_s` (per unit length).
    pub fn new(
        po: Point3f,
        ns: Normal3f,
        wo: Vector3f,
        eta: Float,
        sigma_a: SampledSpectrum,
        sigma_s: SampledSpectrum,
        table: &'a BssrdfTable,
    ) -> Self {
        let sigma_t = sigma_a + sigma_s;
        TabulatedBssrdf {
            po,
            wo,
            ns,
            eta,
            sigma_t,
            rho: SampledSpectrum::safe_div(sigma_s, sigma_t),
            table,
        }
    }

    /// Extinction coefficient per wavelength.
    pub fn sigma_t(&self) -> SampledSpectrum {
        self.sigma_t
    }

    /// Single-scattering albedo per wavelength.
    pub fn rho(&self) -> SampledSpectrum {
        self.rho
    }

    /// The outgoing direction the BSSRDF was created for.
    pub fn wo(&self) -> Vector3f {
        self.wo
    }

    /// The spatial term Sp between `po` and `pi`.
    #[inline]
    pub fn sp(&self, pi: Point3f) -> SampledSpectrum {
        self.sr(distance(self.po, pi))
    }

    /// Interpolates the table at wavelength `i` and world radius `r`:
    /// `(radial profile value Sr in optical units, interpolated ρ_eff)`, or
    /// `None` outside the table.
    fn lookup(&self, i: usize, r: Float) -> Option<(Float, Float)> {
        let t = self.table;
        let r_optical = r * self.sigma_t[i];
        let (rho_off, rho_w) = catmull_rom_weights(&t.rho_samples, self.rho[i])?;
        let (rad_off, rad_w) = catmull_rom_weights(&t.radius_samples, r_optical)?;
        let (mut sr, mut rho_eff) = (0.0, 0.0);
        for (j, &wj) in rho_w.iter().enumerate() {
            if wj == 0.0 {
                continue;
            }
            let rj = (rho_off + j as isize) as usize;
            rho_eff += t.rho_eff[rj] * wj;
            for (k, &wk) in rad_w.iter().enumerate() {
                if wk != 0.0 {
                    sr += wj * wk * t.eval_profile(rj, (rad_off + k as isize) as usize);
                }
            }
        }
        // The table holds the radial marginal 2π r Sr; undo that factor.
        if r_optical != 0.0 {
            sr /= 2.0 * PI * r_optical;
        }
        Some((sr, rho_eff))
    }

    /// The radial profile Sr(r) at world-space distance `r`.
    pub fn sr(&self, r: Float) -> SampledSpectrum {
        let mut out = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            if let Some((sr, _)) = self.lookup(i, r) {
                // Optical units to world units: a factor σt² for an area
                // density.
                out[i] = sr * sqr(self.sigma_t[i]);
            }
        }
        out.clamp_zero()
    }

    /// Samples a radius proportionally to the first wavelength's radial
    /// marginal 2π r Sr(r); `None` if that wavelength has no extinction or
    /// no scattering.
    pub fn sample_sr(&self, u: Float) -> Option<Float> {
        let st = self.sigma_t[0];
        if st == 0.0 {
            return None;
        }
        let t = self.table;
        let s = sample_catmull_rom_2d(
            &t.rho_samples,
            &t.radius_samples,
            &t.profile,
            &t.profile_cdf,
            self.rho[0],
            u,
        )?;
        Some(s.x / st)
    }

    /// The density (per unit area) with which [`Self::sample_sr`], using each
    /// wavelength's own coefficients, picks the point at radius `r`.
    pub fn pdf_sr(&self, r: Float) -> SampledSpectrum {
        let mut pdf = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            if let Some((sr, rho_eff)) = self.lookup(i, r) {
                pdf[i] = sr * sqr(self.sigma_t[i]) / rho_eff;
            }
        }
        pdf.clamp_zero()
    }

    /// Samples a probe segment: a projection axis of the shading frame
    /// (x: `u1` < ¼, y: < ½, else the normal), a radius from
    /// [`Self::sample_sr`] (`u2[0]`) and an angle (`u2[1]`); the segment runs
    /// along the axis through the sphere of radius r_max = `sample_sr(0.999)`.
    pub fn sample_sp(&self, u1: Float, u2: Point2f) -> Option<BssrdfProbeSegment> {
        let n = Vector3f::from(self.ns);
        let f = if u1 < 0.25 {
            Frame::from_x(n)
        } else if u1 < 0.5 {
            // pbrt-v4's Frame::FromY: the other two axes from the
            // coordinate system around y, taken as (z, x).
            let (z, x) = n.coordinate_system();
            Frame::new(x, n, z)
        } else {
            Frame::from_z(n)
        };
        let r = self.sample_sr(u2[0])?;
        let phi = 2.0 * PI * u2[1];
        let r_max = self.sample_sr(0.999)?;
        if r >= r_max {
            return None;
        }
        let l = 2.0 * (r_max * r_max - r * r).sqrt();
        let p_start = self.po + r * (f.x * phi.cos() + f.y * phi.sin()) - f.z * (l / 2.0);
        Some(BssrdfProbeSegment {
            p0: p_start,
            p1: p_start + f.z * l,
        })
    }

    /// The density (per unit area) of [`Self::sample_sp`] finding `pi` with
    /// surface normal `ni`, combined over the three projection axes.
    pub fn pdf_sp(&self, pi: Point3f, ni: Normal3f) -> SampledSpectrum {
        let f = Frame::from_z(Vector3f::from(self.ns));
        let d = f.to_local(pi - self.po);
        let n = f.to_local_normal(ni);
        let r_proj = [
            (d.y * d.y + d.z * d.z).sqrt(),
            (d.z * d.z + d.x * d.x).sqrt(),
            (d.x * d.x + d.y * d.y).sqrt(),
        ];
        let n_local = [n.x, n.y, n.z];
        let mut pdf = SampledSpectrum::new(0.0);
        for axis in 0..3 {
            pdf += self.pdf_sr(r_proj[axis]) * (n_local[axis].abs() * AXIS_PROB[axis]);
        }
        pdf
    }

    /// Turns a probe-ray hit into a BSSRDF sample: Sp, the sampling density
    /// and the normalized-Fresnel BSDF light enters through.
    pub fn probe_intersection_to_sample(&self, si: &SubsurfaceInteraction) -> BssrdfSample {
        let bxdf = BxDF::NormalizedFresnel(NormalizedFresnelBxDF::new(self.eta));
        let wo = Vector3f::from(si.ns);
        let p = si.p();
        BssrdfSample {
            sp: self.sp(p),
            pdf: self.pdf_sp(p, si.n),
            sw: BSDF::new(si.ns, si.dpdus, bxdf),
            wo,
        }
    }
}

/// Inverts the table's effective albedo: the (σa, σs) of a medium with mean
/// free path `mfp` (1/σt) whose multiple-scattering albedo is `rho_eff`,
/// per wavelength.
pub fn subsurface_from_diffuse(
    table: &BssrdfTable,
    rho_eff: SampledSpectrum,
    mfp: SampledSpectrum,
) -> (SampledSpectrum, SampledSpectrum) {
    let mut sigma_a = SampledSpectrum::new(0.0);
    let mut sigma_s = SampledSpectrum::new(0.0);
    for c in 0..N_SPECTRUM_SAMPLES {
        let rho = invert_catmull_rom(&table.rho_samples, &table.rho_eff, rho_eff[c]);
        sigma_s[c] = rho / mfp[c];
        sigma_a[c] = (1.0 - rho) / mfp[c];
    }
    (sigma_a, sigma_s)
}
