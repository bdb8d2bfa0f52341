//! The photon beam diffusion profile (pbrt-v3 book section 15.5, pbrt-v4
//! `bssrdf.cpp`): single and multiple scattering from a beam entering a
//! semi-infinite homogeneous medium, tabulated over albedo and optical
//! radius.

use std::cell::Cell;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use rpbrt_geometry::float::*;

use crate::bxdf::{fr_dielectric, fresnel_moment1, fresnel_moment2, henyey_greenstein};

use super::spline::integrate_catmull_rom;

/// Number of albedo samples in the beam-diffusion table (as pbrt-v4).
pub const N_RHO_SAMPLES: usize = 100;
/// Number of optical-radius samples in the beam-diffusion table (as
/// pbrt-v4).
pub const N_RADIUS_SAMPLES: usize = 64;

/// Depth samples used by each beam-diffusion quadrature.
const N_DEPTH_SAMPLES: usize = 100;

/// Multiple-scattering radial exitance at distance `r` from where a beam
/// enters the medium: the PBD integral of classical dipoles (with Grosjean's
/// diffusion coefficient) over exponentially distributed depths.
pub fn beam_diffusion_ms(sigma_s: Float, sigma_a: Float, g: Float, eta: Float, r: Float) -> Float {
    // Reduced (similarity-theory) coefficients.
    let sigmap_s = sigma_s * (1.0 - g);
    let sigmap_t = sigma_a + sigmap_s;
    let rhop = sigmap_s / sigmap_t;
    let d_g = (2.0 * sigma_a + sigmap_s) / (3.0 * sigmap_t * sigmap_t);
    let sigma_tr = safe_sqrt(sigma_a / d_g);
    let fm1 = fresnel_moment1(eta);
    let fm2 = fresnel_moment2(eta);
    // Extrapolation distance of the partial-current boundary condition.
    let ze = -2.0 * d_g * (1.0 + 3.0 * fm2) / (1.0 - 2.0 * fm1);
    let c_phi = 0.25 * (1.0 - 2.0 * fm1);
    let c_e = 0.5 * (1.0 - 3.0 * fm2);
    let mut ed = 0.0;
    for i in 0..N_DEPTH_SAMPLES {
        let zr = -(1.0 - (i as Float + 0.5) / N_DEPTH_SAMPLES as Float).ln() / sigmap_t;
        let zv = -zr + 2.0 * ze;
        let dr = (r * r + zr * zr).sqrt();
        let dv = (r * r + zv * zv).sqrt();
        let er = (-sigma_tr * dr).exp();
        let ev = (-sigma_tr * dv).exp();
        // Fluence and normal vector irradiance of the dipole.
        let phi_d = INV_4PI / d_g * (er / dr - ev / dv);
        let ed_n = INV_4PI
            * (zr * (1.0 + sigma_tr * dr) * er / (dr * dr * dr)
                - zv * (1.0 + sigma_tr * dv) * ev / (dv * dv * dv));
        let e = phi_d * c_phi + ed_n * c_e;
        // Correction that removes the dipole's contribution close to the
        // entry point, where single scattering dominates.
        let kappa = 1.0 - (-2.0 * sigmap_t * (dr + zr)).exp();
        ed += kappa * rhop * rhop * e;
    }
    ed / N_DEPTH_SAMPLES as Float
}

/// Single-scattering radial exitance at distance `r` from where a beam
/// enters the medium, integrated along the refracted beam (only depths
/// below the critical angle can leave).
pub fn beam_diffusion_ss(sigma_s: Float, sigma_a: Float, g: Float, eta: Float, r: Float) -> Float {
    let sigma_t = sigma_a + sigma_s;
    let rho = sigma_s / sigma_t;
    let t_crit = r * safe_sqrt(eta * eta - 1.0);
    let mut ess = 0.0;
    for i in 0..N_DEPTH_SAMPLES {
        let ti = t_crit - (1.0 - (i as Float + 0.5) / N_DEPTH_SAMPLES as Float).ln() / sigma_t;
        let d = (r * r + ti * ti).sqrt();
        let cos_theta_o = ti / d;
        ess += rho * (-sigma_t * (d + t_crit)).exp() / (d * d)
            * henyey_greenstein(cos_theta_o, g)
            * (1.0 - fr_dielectric(-cos_theta_o, eta))
            * cos_theta_o.abs();
    }
    ess / N_DEPTH_SAMPLES as Float
}

/// A radial scattering profile tabulated over single-scattering albedo ρ
/// and optical radius (radius × σt), for a unit extinction coefficient.
#[derive(Clone, Debug, PartialEq)]
pub struct BssrdfTable {
    /// Albedo nodes, increasing from 0 to 1.
    pub rho_samples: Vec<Float>,
    /// Optical-radius nodes, increasing from 0.
    pub radius_samples: Vec<Float>,
    /// Row-major `[rho][radius]` profile values 2π r Sr(r) (the radial
    /// marginal, ready for sampling).
    pub profile: Vec<Float>,
    /// Effective albedo (the profile's integral over radius) per albedo.
    pub rho_eff: Vec<Float>,
    /// Row-major running integrals of `profile` over radius.
    pub profile_cdf: Vec<Float>,
}

impl BssrdfTable {
    /// A zero-filled table of the given resolution.
    pub fn new(n_rho_samples: usize, n_radius_samples: usize) -> Self {
        BssrdfTable {
            rho_samples: vec![0.0; n_rho_samples],
            radius_samples: vec![0.0; n_radius_samples],
            profile: vec![0.0; n_rho_samples * n_radius_samples],
            rho_eff: vec![0.0; n_rho_samples],
            profile_cdf: vec![0.0; n_rho_samples * n_radius_samples],
        }
    }

    /// The tabulated profile at albedo node `rho_index` and radius node
    /// `radius_index`.
    #[inline]
    pub fn eval_profile(&self, rho_index: usize, radius_index: usize) -> Float {
        debug_assert!(rho_index < self.rho_samples.len());
        debug_assert!(radius_index < self.radius_samples.len());
        self.profile[rho_index * self.radius_samples.len() + radius_index]
    }
}

/// Tabulates the photon beam diffusion profile (single plus multiple
/// scattering) for asymmetry `g` and relative index `eta` at pbrt-v4's
/// resolution: radii 0, 2.5·10⁻³ growing by 1.2 per node; albedos
/// (1 − e^(−8i/(n−1))) / (1 − e^(−8)). Costly (tens of milliseconds): use
/// [`beam_diffusion_table`] for the cached copy.
pub fn compute_beam_diffusion_bssrdf(g: Float, eta: Float) -> BssrdfTable {
    let mut t = BssrdfTable::new(N_RHO_SAMPLES, N_RADIUS_SAMPLES);
    let n_r = t.radius_samples.len();
    t.radius_samples[1] = 2.5e-3;
    for i in 2..n_r {
        t.radius_samples[i] = t.radius_samples[i - 1] * 1.2;
    }
    let n_rho = t.rho_samples.len();
    for (i, rho) in t.rho_samples.iter_mut().enumerate() {
        *rho = (1.0 - (-8.0 * i as Float / (n_rho - 1) as Float).exp())
            / (1.0 - (-8.0 as Float).exp());
    }
    let BssrdfTable {
        rho_samples,
        radius_samples,
        profile,
        rho_eff,
        profile_cdf,
    } = &mut t;
    let rows = profile
        .chunks_mut(n_r)
        .zip(profile_cdf.chunks_mut(n_r))
        .zip(rho_eff.iter_mut())
        .zip(rho_samples.iter());
    for (((row, cdf_row), rho_eff), &rho) in rows {
        for (p, &r) in row.iter_mut().zip(radius_samples.iter()) {
            *p = 2.0
                * PI
                * r
                * (beam_diffusion_ss(rho, 1.0 - rho, g, eta, r)
                    + beam_diffusion_ms(rho, 1.0 - rho, g, eta, r));
        }
        *rho_eff = integrate_catmull_rom(radius_samples, row, cdf_row);
    }
    t
}

/// The beam-diffusion table for (`g`, `eta`), computed once per process
/// and kept for its lifetime (a scene has a handful of distinct pairs, so
/// the tables are leaked rather than reference counted, which lets
/// [`super::TabulatedBssrdf`] borrow them without atomic traffic).
pub fn beam_diffusion_table(g: Float, eta: Float) -> &'static BssrdfTable {
    type Key = (u32, u32);
    static TABLES: OnceLock<Mutex<HashMap<Key, &'static BssrdfTable>>> = OnceLock::new();
    thread_local! {
        // The last table this thread asked for: spares the shared lock on
        // every shading point.
        static LAST: Cell<Option<(Key, &'static BssrdfTable)>> = const { Cell::new(None) };
    }
    let key = (g.to_bits(), eta.to_bits());
    if let Some((k, t)) = LAST.with(|c| c.get()) {
        if k == key {
            return t;
        }
    }
    let map = TABLES.get_or_init(|| Mutex::new(HashMap::new()));
    // A poisoned lock only means another thread panicked mid-insert; the
    // map itself is still valid.
    let mut guard = map.lock().unwrap_or_else(|e| e.into_inner());
    let table = *guard
        .entry(key)
        .or_insert_with(|| Box::leak(Box::new(compute_beam_diffusion_bssrdf(g, eta))));
    drop(guard);
    LAST.with(|c| c.set(Some((key, table))));
    table
}
