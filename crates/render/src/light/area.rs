//! Diffuse area lights (book section 12.3; pbrt-v4 `DiffuseAreaLight`).

use rpbrt_geometry::{
    dot, offset_ray_origin, Float, Frame, MediumId, Normal3f, Point2f, Point2i, Point3f, Ray,
    Vector3f, ONE_MINUS_EPSILON, PI,
};

use super::{
    rgb_illuminant, LightBounds, LightLeSample, LightLiSample, LightSampleContext,
    LightSurfacePoint,
};
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::rng::mix_bits;
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::shape::{
    SampledTriangle, Shape, ShapeMethods, ShapeSample, ShapeSampleContext, SolidAngleCore,
    SolidAnglePoint, SolidAngleQuery,
};
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths, Spectrum};
use crate::texture::{FloatTextureRef, TextureEvalContext};

/// Where a diffuse area light's radiance comes from.
#[derive(Clone, Debug)]
pub enum AreaEmission {
    /// A spectrum, the same everywhere.
    Spectrum(Spectrum),
    /// An RGB image looked up at the surface's (u, v), with its colour
    /// space.
    Image(Image, &'static RgbColorSpace),
}

/// Radiance `scale · L` leaving a shape's surface uniformly in direction
/// (pbrt-v4 `DiffuseAreaLight`).
#[derive(Clone, Debug)]
pub struct DiffuseAreaLight {
    /// The emitting shape (in render space).
    pub shape: Shape,
    /// Cached surface area of `shape`.
    pub area: Float,
    /// Emitted radiance.
    pub emission: AreaEmission,
    /// Scale (photometric normalisation and power target included).
    pub scale: Float,
    /// Emits from both sides of the surface.
    pub two_sided: bool,
    /// Optional alpha texture: points with alpha 0 emit nothing.
    pub alpha: Option<FloatTextureRef>,
    /// Medium inside the shape.
    pub medium_inside: Option<MediumId>,
    /// Medium outside the shape.
    pub medium_outside: Option<MediumId>,
    /// For a triangle with a uniform oriented normal, its sampling data
    /// (see [`SampledTriangle`]); built by [`DiffuseAreaLight::with_cache`].
    pub sampled_triangle: Option<SampledTriangle>,
}

/// A deterministic hash of a point to [0, 1) (pbrt-v4 `HashFloat`'s role
/// in stochastic alpha).
fn hash_point(p: Point3f) -> Float {
    let bits =
        ((p.x.to_bits() as u64) << 32) ^ ((p.y.to_bits() as u64) << 16) ^ p.z.to_bits() as u64;
    let h = mix_bits(bits ^ mix_bits(p.z.to_bits() as u64 + 0x9e37_79b9));
    (h >> 40) as Float / (1u64 << 24) as Float
}

impl DiffuseAreaLight {
    /// True when the alpha texture masks the point out (pbrt-v4
    /// `AlphaMasked`: alpha ≤ 0 masks, alpha ≥ 1 never does, in between a
    /// hash of the point decides).
    fn alpha_masked(&self, p: Point3f, uv: Point2f) -> bool {
        let Some(alpha) = &self.alpha else {
            return false;
        };
        let ctx = TextureEvalContext {
            p,
            uv,
            ..Default::default()
        };
        let a = alpha.evaluate(&ctx);
        if a >= 1.0 {
            return false;
        }
        if a <= 0.0 {
            return true;
        }
        hash_point(p) > a
    }

    /// Emitted radiance at `p` (normal `n`, surface coordinates `uv`)
    /// toward `w`.
    pub fn l(
        &self,
        p: Point3f,
        n: Normal3f,
        uv: Point2f,
        w: Vector3f,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if !self.two_sided && dot(n, w) < 0.0 {
            return SampledSpectrum::new(0.0);
        }
        if self.alpha_masked(p, uv) {
            return SampledSpectrum::new(0.0);
        }
        match &self.emission {
            AreaEmission::Spectrum(s) => s.sample(lambda) * self.scale,
            AreaEmission::Image(image, cs) => {
                // Image rows run top to bottom while v runs bottom to top.
                let st = Point2f::new(uv.x, 1.0 - uv.y);
                let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
                let rgb = [0, 1, 2].map(|c| image.bilerp_channel(st, c, clamp));
                rgb_illuminant(cs, rgb, lambda) * self.scale
            }
        }
    }

    fn shape_ctx(ctx: &LightSampleContext) -> ShapeSampleContext {
        ShapeSampleContext {
            pi: ctx.pi,
            n: ctx.n,
            ns: ctx.ns,
            time: 0.0,
        }
    }

    /// The light with its sampling cache filled in.
    pub fn with_cache(mut self) -> Self {
        self.sampled_triangle = match &self.shape {
            Shape::Triangle(t) => SampledTriangle::new(t),
            _ => None,
        };
        self
    }

    /// Samples a point on the shape by solid angle from `ctx`.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let sctx = Self::shape_ctx(ctx);
        let ss = match &self.sampled_triangle {
            Some(t) => t.sample(&sctx, u),
            None => self.shape.sample(&sctx, u),
        }?;
        self.li_sample_from(ctx, ss, lambda)
    }

    /// For a triangle light, the lane-parallel part of
    /// [`DiffuseAreaLight::sample_li`] as a query for
    /// [`crate::shape::sample_solid_angle_points`]; `None` for other shapes.
    #[inline]
    pub(crate) fn triangle_query(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
    ) -> Option<SolidAngleQuery> {
        let t = self.sampled_triangle.as_ref()?;
        Some(t.solid_angle_query(&Self::shape_ctx(ctx), u))
    }

    /// [`DiffuseAreaLight::sample_li`] of a triangle light given the core
    /// of its [`DiffuseAreaLight::triangle_query`]: the same value.
    #[inline]
    pub(crate) fn sample_li_from_core(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        core: SolidAngleCore,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let t = self.sampled_triangle.as_ref()?;
        let ss = t.finish_sample(&Self::shape_ctx(ctx), u, core)?;
        self.li_sample_from(ctx, ss, lambda)
    }

    /// [`DiffuseAreaLight::sample_li`] of a triangle light given its
    /// query's sampled point (the lane-parallel part): the same value.
    #[inline]
    pub(crate) fn sample_li_from_point(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        s: &SolidAnglePoint,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let t = self.sampled_triangle.as_ref()?;
        let spectrum = match &self.emission {
            AreaEmission::Spectrum(spectrum) if !s.core.by_area && self.alpha.is_none() => spectrum,
            // A sample by area, or an emission that needs the point's uv.
            _ => return self.sample_li_from_core(ctx, u, s.core, lambda),
        };
        if !s.core.ok || !s.toward {
            return None;
        }
        // `l` toward −ωi, without an alpha texture.
        let n = t.normal();
        if !self.two_sided && dot(n, -s.wi) < 0.0 {
            return None;
        }
        let le = spectrum.sample(lambda) * self.scale;
        if le.is_black() {
            return None;
        }
        Some(LightLiSample {
            l: le,
            wi: s.wi,
            pdf: s.core.pdf,
            p_light: s.pi,
            n_light: n,
        })
    }

    /// The light sample of the shape sample `ss`.
    #[inline(always)]
    fn li_sample_from(
        &self,
        ctx: &LightSampleContext,
        ss: ShapeSample,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        if ss.pdf == 0.0 || (ss.p() - ctx.p()).length_squared() == 0.0 {
            return None;
        }
        let wi = (ss.p() - ctx.p()).normalize();
        let le = self.l(ss.p(), ss.n, ss.uv, -wi, lambda);
        if le.is_black() {
            return None;
        }
        Some(LightLiSample {
            l: le,
            wi,
            pdf: ss.pdf,
            p_light: ss.pi,
            n_light: ss.n,
        })
    }

    /// The shape's solid-angle density for `wi` from `ctx`.
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vector3f, _a: bool) -> Float {
        self.shape.pdf(&Self::shape_ctx(ctx), wi)
    }

    /// A ray leaving a point sampled uniformly by area on the shape (`u1`)
    /// in a cosine-distributed direction (`u2`) about the surface normal;
    /// a two-sided light first picks the side with `u2[0]` (then reused,
    /// stretched, for the direction) and halves the density, as pbrt-v4.
    /// `None` where the alpha texture masks the point out.
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let ss = self.shape.sample_area(u1)?;
        if self.alpha_masked(ss.p(), ss.uv) {
            return None;
        }
        let (w_local, pdf_dir) = if self.two_sided {
            let (u, flip) = if u2.x < 0.5 {
                ((u2.x * 2.0).min(ONE_MINUS_EPSILON), false)
            } else {
                (((u2.x - 0.5) * 2.0).min(ONE_MINUS_EPSILON), true)
            };
            let mut w = sample_cosine_hemisphere(Point2f::new(u, u2.y));
            if flip {
                w.z = -w.z;
            }
            (w, cosine_hemisphere_pdf(w.z.abs()) / 2.0)
        } else {
            let w = sample_cosine_hemisphere(u2);
            (w, cosine_hemisphere_pdf(w.z))
        };
        if pdf_dir == 0.0 {
            return None;
        }
        let w = Frame::from_normal(ss.n).from_local(w_local);
        let l = self.l(ss.p(), ss.n, ss.uv, w, lambda);
        // pbrt-v4's `Interaction::SpawnRay`: offset off the surface, in the
        // medium on the side the ray leaves by.
        let medium = if dot(w, ss.n) > 0.0 {
            self.medium_outside
        } else {
            self.medium_inside
        };
        let o = offset_ray_origin(ss.p(), ss.pi.error(), ss.n, w);
        Some(LightLeSample {
            l,
            ray: Ray::with_time(o, w, time, medium),
            surface: Some(LightSurfacePoint {
                pi: ss.pi,
                n: ss.n,
                uv: ss.uv,
            }),
            pdf_pos: ss.pdf,
            pdf_dir,
        })
    }

    /// The densities with which [`sample_le`](Self::sample_le) leaves
    /// surface point `p` (normal `n`) toward `w`: the shape's area density
    /// at `p` and the cosine density (halved when two-sided). pbrt-v4's
    /// one-sided density goes negative behind the surface; it is zero
    /// here.
    pub fn pdf_le_surface(&self, p: Point3f, n: Normal3f, w: Vector3f) -> (Float, Float) {
        let Some(w) = w.try_normalize() else {
            return (0.0, 0.0);
        };
        let pdf_pos = self.shape.pdf_area_at_point(p);
        let cos = dot(n, w);
        let pdf_dir = if self.two_sided {
            cosine_hemisphere_pdf(cos.abs()) / 2.0
        } else {
            cosine_hemisphere_pdf(cos.max(0.0))
        };
        (pdf_pos, pdf_dir)
    }

    /// Mean emission · scale · area · π, doubled when two-sided.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let l = match &self.emission {
            AreaEmission::Spectrum(s) => s.sample(lambda),
            AreaEmission::Image(image, cs) => {
                let res = image.resolution();
                let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
                let mut sum = SampledSpectrum::new(0.0);
                for y in 0..res.y {
                    for x in 0..res.x {
                        let rgb =
                            [0, 1, 2].map(|c| image.get_channel(Point2i::new(x, y), c, clamp));
                        sum += rgb_illuminant(cs, rgb, lambda);
                    }
                }
                sum / (res.x as Float * res.y as Float)
            }
        };
        l * (if self.two_sided { 2.0 } else { 1.0 } * self.scale * self.area * PI)
    }

    /// The shape's bounds and normal cone, emission over a hemisphere.
    pub fn bounds(&self) -> Option<LightBounds> {
        let mut phi = match &self.emission {
            AreaEmission::Spectrum(s) => s.max_value(),
            AreaEmission::Image(image, _) => {
                let res = image.resolution();
                let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
                let mut sum = 0.0f64;
                for y in 0..res.y {
                    for x in 0..res.x {
                        for c in 0..3 {
                            sum += image.get_channel(Point2i::new(x, y), c, clamp) as f64;
                        }
                    }
                }
                (sum / (3.0 * res.x as f64 * res.y as f64)) as Float
            }
        };
        phi *= if self.two_sided { 2.0 } else { 1.0 } * self.scale * self.area * PI;
        let nb = self.shape.normal_bounds();
        Some(LightBounds::new(
            self.shape.bounds(),
            nb.w,
            phi,
            nb.cos_theta,
            0.0,
            self.two_sided,
        ))
    }

    /// The medium outside the shape.
    pub fn medium(&self) -> Option<MediumId> {
        self.medium_outside
    }
}
