//! pbrt-v3's Disney BSSRDF (pbrt-v3 `materials/disney.cpp`, after Burley's
//! 2015 course notes and Christensen and Burley's "Approximate Reflectance
//! Profiles for Efficient Subsurface Scattering"), which pbrt-v4 dropped
//! with the `disney` material.
//!
//! Its radial profile is Burley's normalized diffusion,
//! Sr(r) = R (e^(−r/d) + e^(−r/3d)) / (8π d r), which integrates over the
//! plane to the albedo R; `d` is the material's `scatterdistance`. A
//! radius is drawn from one of the two exponentials (the first with
//! probability ¼, as it carries a quarter of the energy), so Sr over its
//! density is exactly R at the sampled wavelength.
//!
//! pbrt-v3 also gave this BSSRDF an `S` that fades the profile by the two
//! normals and a Schlick factor at each end, but its path tracer never
//! called it (`Sample_S` returns Sp alone and the exit point's BSDF carries
//! Sw), so the rendered model is the separable one built here.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

use crate::spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};

use super::separable::{BssrdfOrigin, SeparableBssrdf};

/// pbrt-v3 keeps radii this far from the profile's 1/r singularity.
const MIN_RADIUS: Float = 1e-6;

/// Burley's normalized-diffusion BSSRDF leaving one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyBssrdf {
    origin: BssrdfOrigin,
    /// Albedo: the profile's integral over the plane.
    r: SampledSpectrum,
    /// Scatter distance, per wavelength.
    d: SampledSpectrum,
}

impl DisneyBssrdf {
    /// The BSSRDF leaving `po` (shading normal `ns`) through a boundary of
    /// relative index `eta`, with albedo `r` and scatter distance `d`
    /// (both clamped to be non-negative; a wavelength whose distance is 0
    /// scatters nothing).
    pub fn new(
        po: Point3f,
        ns: Normal3f,
        eta: Float,
        r: SampledSpectrum,
        d: SampledSpectrum,
    ) -> Self {
        DisneyBssrdf {
            origin: BssrdfOrigin { po, ns, eta },
            r: r.clamp_zero(),
            d: d.clamp_zero(),
        }
    }

    /// Applies `f(d, r)` to each wavelength with a positive distance,
    /// leaving the others at zero.
    fn per_wavelength(&self, f: impl Fn(Float, usize) -> Float) -> SampledSpectrum {
        let mut out = SampledSpectrum::new(0.0);
        for i in 0..N_SPECTRUM_SAMPLES {
            if self.d[i] > 0.0 {
                out[i] = f(self.d[i], i);
            }
        }
        out
    }
}

impl SeparableBssrdf for DisneyBssrdf {
    fn origin(&self) -> &BssrdfOrigin {
        &self.origin
    }

    fn sr(&self, r: Float) -> SampledSpectrum {
        let r = r.max(MIN_RADIUS);
        self.per_wavelength(|d, i| {
            self.r[i] * ((-r / d).exp() + (-r / (3.0 * d)).exp()) / (8.0 * PI * d * r)
        })
    }

    fn sample_sr(&self, u: Float) -> Option<Float> {
        let d = self.d[0];
        if !(d > 0.0) {
            return None;
        }
        // The first exponential a quarter of the time, the second (three
        // times as wide) otherwise; each inverts its own CDF 1 − e^(−r/s).
        let (u, s) = if u < 0.25 {
            ((u * 4.0).min(ONE_MINUS_EPSILON), d)
        } else {
            (((u - 0.25) / 0.75).min(ONE_MINUS_EPSILON), 3.0 * d)
        };
        Some(-s * (1.0 - u).ln())
    }

    fn pdf_sr(&self, r: Float) -> SampledSpectrum {
        let r = r.max(MIN_RADIUS);
        self.per_wavelength(|d, _| {
            0.25 * (-r / d).exp() / (2.0 * PI * d * r)
                + 0.75 * (-r / (3.0 * d)).exp() / (6.0 * PI * d * r)
        })
    }
}
