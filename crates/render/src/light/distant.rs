//! A directional light infinitely far away (book section 12.4; pbrt-v4
//! `DistantLight`).

use rpbrt_geometry::{
    Bounds3f, Float, MediumId, Normal3f, Point2f, Point3fi, Ray, Transform, Vector3f, PI,
};

use super::{LightBounds, LightLeSample, LightLiSample, LightSampleContext, SceneSphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

/// Radiance `scale · L` arriving along light-space +z (pbrt-v4
/// `DistantLight`).
#[derive(Clone, Debug)]
pub struct DistantLight {
    /// Light space to render space; light arrives from light-space +z.
    pub render_from_light: Transform,
    /// Emitted radiance spectrum.
    pub l_emit: Spectrum,
    /// Scale (photometric normalisation and illuminance target included).
    pub scale: Float,
    /// The scene's bounding sphere, set by `preprocess`.
    pub scene: SceneSphere,
}

impl DistantLight {
    /// Unit render-space direction toward the light.
    pub fn direction(&self) -> Vector3f {
        self.render_from_light
            .apply_vector(Vector3f::new(0.0, 0.0, 1.0))
            .normalize()
    }
    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let wi = self.direction();
        let p_outside = ctx.p() + wi * (2.0 * self.scene.radius);
        Some(LightLiSample {
            l: self.l_emit.sample(lambda) * self.scale,
            wi,
            pdf: 1.0,
            p_light: Point3fi::from(p_outside),
            n_light: Normal3f::default(),
        })
    }
    /// Always zero: a delta distribution.
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vector3f, _a: bool) -> Float {
        0.0
    }
    /// A ray along the light's direction through a point sampled by `u1`
    /// on the scene's bounding disk facing the light, starting outside
    /// the scene (`u2` unused). The ray is in no medium, as pbrt-v4's.
    pub fn sample_le(
        &self,
        u1: Point2f,
        _u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let (ray, pdf_pos) = self
            .scene
            .sample_ray_through_disk(-self.direction(), u1, time);
        Some(LightLeSample {
            l: self.l_emit.sample(lambda) * self.scale,
            ray,
            surface: None,
            pdf_pos,
            pdf_dir: 1.0,
        })
    }
    /// `(1/(π r²), 0)`: pbrt-v4 reports no directional density for a
    /// delta.
    pub fn pdf_le(&self, _ray: &Ray) -> (Float, Float) {
        (self.scene.disk_pdf(), 0.0)
    }
    /// Power through the scene's disk: scale · L · π r².
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.l_emit.sample(lambda) * (self.scale * PI * self.scene.radius * self.scene.radius)
    }
    /// Records the scene's bounding sphere.
    pub fn preprocess(&mut self, scene_bounds: &Bounds3f) {
        self.scene = SceneSphere::from_bounds(scene_bounds);
    }
    /// None: the light is at infinity.
    pub fn bounds(&self) -> Option<LightBounds> {
        None
    }
    /// Distant lights are in no medium.
    pub fn medium(&self) -> Option<MediumId> {
        None
    }
}
