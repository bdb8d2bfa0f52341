//! The Henyey–Greenstein phase function (pbrt-v4 `HGPhaseFunction`; book
//! section 11.3.1): scattering in media, forward for `g > 0` and backward
//! for `g < 0`, sampled exactly.

use rpbrt_geometry::float::{Float, INV_4PI, PI};
use rpbrt_geometry::frame::Frame;
use rpbrt_geometry::spherical::spherical_direction;
use rpbrt_geometry::tuple::*;

/// A direction sampled from a phase function (pbrt-v4 `PhaseFunctionSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseFunctionSample {
    /// The phase function's value for the sampled direction.
    pub p: Float,
    /// The sampled incident direction.
    pub wi: Vector3f,
    /// Its density (equal to `p`: the sampling is exact).
    pub pdf: Float,
}

/// The Henyey–Greenstein distribution of scattered directions with
/// asymmetry `g` in (−1, 1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HGPhaseFunction {
    /// The mean cosine of the scattering angle.
    pub g: Float,
}

/// pbrt-v4 `HenyeyGreenstein`: the density for the cosine between the
/// outgoing and incident directions (both pointing away from the point, so
/// forward scattering is `cos_theta = −1`). `g` is kept inside
/// [−0.99, 0.99], where the sampling below stays accurate.
#[inline]
pub fn henyey_greenstein(cos_theta: Float, g: Float) -> Float {
    let g = g.clamp(-0.99, 0.99);
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    INV_4PI * (1.0 - g * g) / (denom * denom.max(0.0).sqrt())
}

/// pbrt-v4 `SampleHenyeyGreenstein`: a direction `wi` around `wo` and its
/// density.
#[inline]
pub fn sample_henyey_greenstein(wo: Vector3f, g: Float, u: Point2f) -> (Vector3f, Float) {
    let g = g.clamp(-0.99, 0.99);
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u[0]
    } else {
        -1.0 / (2.0 * g) * (1.0 + g * g - sqr((1.0 - g * g) / (1.0 + g - 2.0 * g * u[0])))
    };
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    let frame = Frame::from_z(wo);
    let wi = frame.from_local(spherical_direction(sin_theta, cos_theta, phi));
    (wi, henyey_greenstein(cos_theta, g))
}

#[inline]
fn sqr(x: Float) -> Float {
    x * x
}

impl HGPhaseFunction {
    /// A phase function with asymmetry `g`.
    #[inline]
    pub fn new(g: Float) -> Self {
        HGPhaseFunction { g }
    }

    /// The phase function's value for the pair of directions.
    #[inline]
    pub fn p(&self, wo: Vector3f, wi: Vector3f) -> Float {
        henyey_greenstein(dot(wo, wi), self.g)
    }

    /// Samples an incident direction for `wo`.
    #[inline]
    pub fn sample_p(&self, wo: Vector3f, u: Point2f) -> Option<PhaseFunctionSample> {
        let (wi, pdf) = sample_henyey_greenstein(wo, self.g, u);
        Some(PhaseFunctionSample { p: pdf, wi, pdf })
    }

    /// The density of sampling `wi` for `wo`.
    #[inline]
    pub fn pdf(&self, wo: Vector3f, wi: Vector3f) -> Float {
        self.p(wo, wi)
    }
}
