//! The tabulated radial BSSRDF (pbrt-v4 `TabulatedBSSRDF`, pbrt-v3 book
//! sections 11.4 and 15.4): the radial profile interpolated from a
//! photon-beam-diffusion table, its sampling and density.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

use super::separable::{BssrdfOrigin, SeparableBssrdf};
use super::spline::{catmull_rom_weights, invert_catmull_rom, sample_catmull_rom_2d};
use super::table::BssrdfTable;

/// A radially symmetric BSSRDF interpolated from a [`BssrdfTable`]:
/// S(po, pi) ≈ Sp(|po − pi|) · Sw(wi), with per-wavelength σt and albedo.
#[derive(Clone, Copy, Debug)]
pub struct TabulatedBssrdf<'a> {
    origin: BssrdfOrigin,
    wo: Vector3f,
    sigma_t: SampledSpectrum,
    rho: SampledSpectrum,
    table: &'a BssrdfTable,
}

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
            origin: BssrdfOrigin { po, ns, eta },
            wo,
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
}

impl SeparableBssrdf for TabulatedBssrdf<'_> {
    fn origin(&self) -> &BssrdfOrigin {
        &self.origin
    }

    fn sr(&self, r: Float) -> SampledSpectrum {
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

    fn sample_sr(&self, u: Float) -> Option<Float> {
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

    fn pdf_sr(&self, r: Float) -> SampledSpectrum {
        let mut pdf = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            if let Some((sr, rho_eff)) = self.lookup(i, r) {
                pdf[i] = sr * sqr(self.sigma_t[i]) / rho_eff;
            }
        }
        pdf.clamp_zero()
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
