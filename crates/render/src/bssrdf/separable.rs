//! Separable BSSRDFs (pbrt-v3 `SeparableBSSRDF`, pbrt-v4 `TabulatedBSSRDF`'s
//! sampling): S(po, ωo, pi, ωi) ≈ (1 − Fr(cos θo)) · Sp(|po − pi|) · Sw(ωi),
//! with Sp a radial profile. Whatever the profile, light is found where it
//! enters by probe rays: an axis of the shading frame at po, a radius drawn
//! from the profile and a segment through the sphere of the profile's
//! extent along that axis. [`SeparableBssrdf`] holds that shared part; a
//! profile supplies Sr, its sampling and its density.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{Frame, Point3fi, SurfaceInteraction};

use crate::bxdf::{BxDF, NormalizedFresnelBxDF, BSDF};
use crate::spectrum::SampledSpectrum;

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

/// Probabilities of projecting along the local x, y and z axes.
const AXIS_PROB: [Float; 3] = [0.25, 0.25, 0.5];

/// Where light leaves a BSSRDF: the point, its shading normal and the
/// boundary's relative index of refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BssrdfOrigin {
    /// The point light leaves from.
    pub po: Point3f,
    /// The shading normal there.
    pub ns: Normal3f,
    /// Relative index of refraction of the boundary.
    pub eta: Float,
}

/// A BSSRDF whose spatial term depends on distance alone. Implementors give
/// where light leaves and the radial profile (in world units, as an area
/// density); sampling the probe segment, its density and the sample at a
/// probe hit follow from those.
pub trait SeparableBssrdf {
    /// Where light leaves.
    fn origin(&self) -> &BssrdfOrigin;
    /// The radial profile Sr(r) at world-space distance `r`.
    fn sr(&self, r: Float) -> SampledSpectrum;
    /// Samples a radius with the first wavelength's profile; `None` when
    /// that wavelength has none.
    fn sample_sr(&self, u: Float) -> Option<Float>;
    /// The density (per unit area) with which [`Self::sample_sr`], using
    /// each wavelength's own profile, picks the point at radius `r`.
    fn pdf_sr(&self, r: Float) -> SampledSpectrum;

    /// The spatial term Sp between the origin and `pi`.
    #[inline]
    fn sp(&self, pi: Point3f) -> SampledSpectrum {
        self.sr(distance(self.origin().po, pi))
    }

    /// Samples a probe segment: a projection axis of the shading frame
    /// (x: `u1` < ¼, y: < ½, else the normal), a radius from
    /// [`Self::sample_sr`] (`u2[0]`) and an angle (`u2[1]`); the segment runs
    /// along the axis through the sphere of radius r_max = `sample_sr(0.999)`.
    fn sample_sp(&self, u1: Float, u2: Point2f) -> Option<BssrdfProbeSegment> {
        let o = self.origin();
        let n = Vector3f::from(o.ns);
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
        if !(r >= 0.0) || r >= r_max {
            return None;
        }
        let l = 2.0 * (r_max * r_max - r * r).sqrt();
        let p_start = o.po + r * (f.x * phi.cos() + f.y * phi.sin()) - f.z * (l / 2.0);
        Some(BssrdfProbeSegment {
            p0: p_start,
            p1: p_start + f.z * l,
        })
    }

    /// The density (per unit area) of [`Self::sample_sp`] finding `pi` with
    /// surface normal `ni`, combined over the three projection axes.
    fn pdf_sp(&self, pi: Point3f, ni: Normal3f) -> SampledSpectrum {
        let o = self.origin();
        let f = Frame::from_z(Vector3f::from(o.ns));
        let d = f.to_local(pi - o.po);
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
    fn probe_intersection_to_sample(&self, si: &SubsurfaceInteraction) -> BssrdfSample {
        let bxdf = BxDF::NormalizedFresnel(NormalizedFresnelBxDF::new(self.origin().eta));
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
