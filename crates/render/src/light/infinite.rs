//! Lights at infinity (book section 12.5; pbrt-v4 `UniformInfiniteLight`,
//! `ImageInfiniteLight`).

use rpbrt_geometry::{
    equal_area_sphere_to_square, equal_area_square_to_sphere, Bounds3f, Float, MediumId, Normal3f,
    Point2f, Point2i, Point3fi, Ray, Transform, Vector3f, PI,
};

use super::{
    rgb_illuminant, LightBounds, LightLeSample, LightLiSample, LightSampleContext, SceneSphere,
};
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::sampling::sample_uniform_sphere;
use crate::sampling::tabulated::PiecewiseConstant2D;
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths, Spectrum};

const INV_4PI: Float = 1.0 / (4.0 * PI);

fn infinite_sample(
    ctx: &LightSampleContext,
    scene: &SceneSphere,
    l: SampledSpectrum,
    wi: Vector3f,
    pdf: Float,
) -> LightLiSample {
    LightLiSample {
        l,
        wi,
        pdf,
        p_light: Point3fi::from(ctx.p() + wi * (2.0 * scene.radius)),
        n_light: Normal3f::default(),
    }
}

/// The same radiance from every direction (pbrt-v4
/// `UniformInfiniteLight`).
#[derive(Clone, Debug)]
pub struct UniformInfiniteLight {
    /// Emitted radiance spectrum.
    pub l_emit: Spectrum,
    /// Scale (photometric normalisation and illuminance target included).
    pub scale: Float,
    /// The scene's bounding sphere, set by `preprocess`.
    pub scene: SceneSphere,
}

impl UniformInfiniteLight {
    /// See [`super::Light::sample_li`]. With `allow_incomplete_pdf` the
    /// light leaves all directions to BSDF sampling, as pbrt-v4 does.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        lambda: &SampledWavelengths,
        allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        if allow_incomplete_pdf {
            return None;
        }
        let wi = sample_uniform_sphere(u);
        Some(infinite_sample(
            ctx,
            &self.scene,
            self.l_emit.sample(lambda) * self.scale,
            wi,
            INV_4PI,
        ))
    }
    /// Uniform over the sphere (zero with `allow_incomplete_pdf`).
    pub fn pdf_li(
        &self,
        _ctx: &LightSampleContext,
        _wi: Vector3f,
        allow_incomplete_pdf: bool,
    ) -> Float {
        if allow_incomplete_pdf {
            0.0
        } else {
            INV_4PI
        }
    }
    /// Radiance along any escaping ray.
    pub fn le(&self, _ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.l_emit.sample(lambda) * self.scale
    }
    /// A ray from a uniformly sampled direction (`u1`) through a point on
    /// the scene's bounding disk (`u2`), starting outside the scene.
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let w = sample_uniform_sphere(u1);
        let (ray, pdf_pos) = self.scene.sample_ray_through_disk(w, u2, time);
        Some(LightLeSample {
            l: self.l_emit.sample(lambda) * self.scale,
            ray,
            surface: None,
            pdf_pos,
            pdf_dir: INV_4PI,
        })
    }
    /// `(1/(π r²), 1/4π)` for every ray.
    pub fn pdf_le(&self, _ray: &Ray) -> (Float, Float) {
        (self.scene.disk_pdf(), INV_4PI)
    }
    /// 4π · π r² · scale · L.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let r = self.scene.radius;
        self.l_emit.sample(lambda) * (4.0 * PI * PI * r * r * self.scale)
    }
    /// Records the scene's bounding sphere.
    pub fn preprocess(&mut self, scene_bounds: &Bounds3f) {
        self.scene = SceneSphere::from_bounds(scene_bounds);
    }
    /// None: the light is at infinity.
    pub fn bounds(&self) -> Option<LightBounds> {
        None
    }
    /// Infinite lights are in no medium.
    pub fn medium(&self) -> Option<MediumId> {
        None
    }
}

/// An environment map in pbrt-v4's equal-area octahedral layout,
/// importance sampled by pixel brightness (pbrt-v4 `ImageInfiniteLight`).
#[derive(Clone, Debug)]
pub struct ImageInfiniteLight {
    /// Light space to render space.
    pub render_from_light: Transform,
    /// Square RGB image.
    pub image: Image,
    /// The image's colour space.
    pub color_space: &'static RgbColorSpace,
    /// Scale (photometric normalisation and illuminance target included).
    pub scale: Float,
    /// The scene's bounding sphere, set by `preprocess`.
    pub scene: SceneSphere,
    distribution: PiecewiseConstant2D,
    compensated_distribution: PiecewiseConstant2D,
}

const OCTA_WRAP: WrapMode2D = WrapMode2D {
    wrap: [WrapMode::OctahedralSphere, WrapMode::OctahedralSphere],
};

impl ImageInfiniteLight {
    /// Builds the light from a square RGB `image` (checked by the caller)
    /// and its sampling distributions: one proportional to the mean
    /// channel value of each pixel and, for MIS, pbrt-v4's compensated one
    /// (the average subtracted, clamped at zero).
    pub fn new(
        render_from_light: Transform,
        image: Image,
        color_space: &'static RgbColorSpace,
        scale: Float,
    ) -> Self {
        let res = image.resolution();
        let (nu, nv) = (res.x.max(1) as usize, res.y.max(1) as usize);
        let mut d = Vec::with_capacity(nu * nv);
        for y in 0..res.y {
            for x in 0..res.x {
                let p = Point2i::new(x, y);
                let avg = (0..3)
                    .map(|c| image.get_channel(p, c, OCTA_WRAP))
                    .sum::<Float>()
                    / 3.0;
                d.push(avg);
            }
        }
        let distribution = PiecewiseConstant2D::unit(&d, nu, nv);
        let average = d.iter().map(|&v| v as f64).sum::<f64>() / d.len().max(1) as f64;
        let mut dc: Vec<Float> = d.iter().map(|&v| (v - average as Float).max(0.0)).collect();
        if dc.iter().all(|&v| v == 0.0) {
            dc.iter_mut().for_each(|v| *v = 1.0);
        }
        let compensated_distribution = PiecewiseConstant2D::unit(&dc, nu, nv);
        ImageInfiniteLight {
            render_from_light,
            image,
            color_space,
            scale,
            scene: SceneSphere::default(),
            distribution,
            compensated_distribution,
        }
    }

    /// Radiance at equal-area image coordinates `uv`.
    pub fn image_le(&self, uv: Point2f, lambda: &SampledWavelengths) -> SampledSpectrum {
        let rgb = [0, 1, 2].map(|c| self.image.lookup_nearest_channel(uv, c, OCTA_WRAP));
        rgb_illuminant(self.color_space, rgb, lambda) * self.scale
    }

    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        lambda: &SampledWavelengths,
        allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let dist = if allow_incomplete_pdf {
            &self.compensated_distribution
        } else {
            &self.distribution
        };
        let (uv, map_pdf, _) = dist.sample(u);
        if map_pdf == 0.0 {
            return None;
        }
        let wl = equal_area_square_to_sphere(uv);
        let wi = self.render_from_light.apply_vector(wl).normalize();
        Some(infinite_sample(
            ctx,
            &self.scene,
            self.image_le(uv, lambda),
            wi,
            map_pdf * INV_4PI,
        ))
    }

    /// The solid-angle density of `w` (the equal-area map has a constant
    /// Jacobian of 4π).
    pub fn pdf_li(
        &self,
        _ctx: &LightSampleContext,
        w: Vector3f,
        allow_incomplete_pdf: bool,
    ) -> Float {
        let Some(wl) = self
            .render_from_light
            .apply_inverse_vector(w)
            .try_normalize()
        else {
            return 0.0;
        };
        let uv = equal_area_sphere_to_square(wl);
        let pdf = if allow_incomplete_pdf {
            self.compensated_distribution.pdf(uv)
        } else {
            self.distribution.pdf(uv)
        };
        pdf * INV_4PI
    }

    /// Radiance along an escaping ray.
    pub fn le(&self, ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        let Some(wl) = self
            .render_from_light
            .apply_inverse_vector(ray.d)
            .try_normalize()
        else {
            return SampledSpectrum::new(0.0);
        };
        self.image_le(equal_area_sphere_to_square(wl), lambda)
    }

    /// A ray whose direction is sampled by the image's brightness (`u1`;
    /// the ray travels away from the sampled direction of arrival) through
    /// a point on the scene's bounding disk (`u2`).
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let (uv, map_pdf, _) = self.distribution.sample(u1);
        if map_pdf == 0.0 {
            return None;
        }
        let w_light = equal_area_square_to_sphere(uv);
        let w = -self
            .render_from_light
            .apply_vector(w_light)
            .try_normalize()?;
        let (ray, pdf_pos) = self.scene.sample_ray_through_disk(w, u2, time);
        Some(LightLeSample {
            l: self.image_le(uv, lambda),
            ray,
            surface: None,
            pdf_pos,
            pdf_dir: map_pdf * INV_4PI,
        })
    }
    /// The densities of [`sample_le`](Self::sample_le) for `ray` (by the
    /// full, not the compensated, distribution).
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        let Some(wl) = self
            .render_from_light
            .apply_inverse_vector(-ray.d)
            .try_normalize()
        else {
            return (0.0, 0.0);
        };
        let map_pdf = self.distribution.pdf(equal_area_sphere_to_square(wl));
        (self.scene.disk_pdf(), map_pdf * INV_4PI)
    }

    /// 4π · π r² · scale · mean pixel radiance.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let res = self.image.resolution();
        let mut sum = SampledSpectrum::new(0.0);
        for y in 0..res.y {
            for x in 0..res.x {
                let p = Point2i::new(x, y);
                let rgb = [0, 1, 2].map(|c| self.image.get_channel(p, c, OCTA_WRAP));
                sum += rgb_illuminant(self.color_space, rgb, lambda);
            }
        }
        let r = self.scene.radius;
        sum * (4.0 * PI * PI * r * r * self.scale / (res.x as Float * res.y as Float))
    }

    /// Records the scene's bounding sphere.
    pub fn preprocess(&mut self, scene_bounds: &Bounds3f) {
        self.scene = SceneSphere::from_bounds(scene_bounds);
    }
    /// None: the light is at infinity.
    pub fn bounds(&self) -> Option<LightBounds> {
        None
    }
    /// Infinite lights are in no medium.
    pub fn medium(&self) -> Option<MediumId> {
        None
    }
}
