//! Lights at a point (book section 12.2; pbrt-v4 `PointLight`,
//! `SpotLight`, `GoniometricLight`, `ProjectionLight`).

use rpbrt_geometry::{
    distance_squared, equal_area_sphere_to_square, equal_area_square_to_sphere, safe_sqrt,
    spherical_direction, Bounds2f, Float, MediumId, Normal3f, Point2f, Point2i, Point3f, Point3fi,
    Ray, Transform, Vector3f, PI,
};

use super::{
    acos_c, rgb_illuminant, smooth_step, LightBounds, LightLeSample, LightLiSample,
    LightSampleContext,
};
use crate::bssrdf::spline::newton_bisection;
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::sampling::tabulated::PiecewiseConstant2D;
use crate::sampling::{
    sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf, UNIFORM_SPHERE_PDF,
};
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths, Spectrum};

/// The sample every point-like light returns: direction and distance
/// falloff toward its origin.
fn delta_sample(
    ctx: &LightSampleContext,
    p: Point3f,
    intensity: SampledSpectrum,
) -> Option<LightLiSample> {
    let d2 = distance_squared(p, ctx.p());
    let wi = (p - ctx.p()).try_normalize()?;
    let l = intensity / d2;
    if l.is_black() {
        return None;
    }
    Some(LightLiSample {
        l,
        wi,
        pdf: 1.0,
        p_light: Point3fi::from(p),
        n_light: Normal3f::default(),
    })
}

/// The ray leaving a point-like light at light-space origin along
/// light-space direction `w_light`, in render space with a unit direction
/// (pbrt-v4 transforms the light-space ray by `renderFromLight`).
fn delta_position_le(
    render_from_light: &Transform,
    w_light: Vector3f,
    l: SampledSpectrum,
    pdf_dir: Float,
    time: Float,
    medium: Option<MediumId>,
) -> Option<LightLeSample> {
    let o = render_from_light.apply_point(Point3f::new(0.0, 0.0, 0.0));
    let d = render_from_light.apply_vector(w_light).try_normalize()?;
    Some(LightLeSample {
        l,
        ray: Ray::with_time(o, d, time, medium),
        surface: None,
        pdf_pos: 1.0,
        pdf_dir,
    })
}

/// A render-space direction taken to light space, unit length.
fn light_dir(render_from_light: &Transform, w: Vector3f) -> Option<Vector3f> {
    render_from_light.apply_inverse_vector(w).try_normalize()
}

/// pbrt-v4's `SmoothStepPDF`: the density ∝ smoothstep on [a, b].
#[inline]
fn smooth_step_pdf(x: Float, a: Float, b: Float) -> Float {
    if x < a || x > b {
        return 0.0;
    }
    (2.0 / (b - a)) * smooth_step(x, a, b)
}

/// pbrt-v4's `SampleSmoothStep`: inverts the CDF 2t³ − t⁴ by Newton
/// steps safeguarded with bisection.
fn sample_smooth_step(u: Float, a: Float, b: Float) -> Float {
    let cdf_minus_u = |x: Float| {
        let t = (x - a) / (b - a);
        (
            2.0 * t * t * t - t * t * t * t - u,
            smooth_step_pdf(x, a, b),
        )
    };
    newton_bisection(a, b, cdf_minus_u, 1e-6, 1e-6)
}

/// An isotropic point light (pbrt-v4 `PointLight`).
#[derive(Clone, Debug)]
pub struct PointLight {
    /// Light space to render space; the light sits at the light-space origin.
    pub render_from_light: Transform,
    /// Radiant intensity spectrum.
    pub i: Spectrum,
    /// Scale (photometric normalisation and power target included).
    pub scale: Float,
    /// The medium around the light.
    pub medium: Option<MediumId>,
}

impl PointLight {
    fn position(&self) -> Point3f {
        self.render_from_light
            .apply_point(Point3f::new(0.0, 0.0, 0.0))
    }
    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        delta_sample(ctx, self.position(), self.i.sample(lambda) * self.scale)
    }
    /// Always zero: a delta distribution.
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vector3f, _a: bool) -> Float {
        0.0
    }
    /// A ray in a uniformly sampled direction (`u1`; `u2` unused).
    pub fn sample_le(
        &self,
        u1: Point2f,
        _u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        Some(LightLeSample {
            l: self.i.sample(lambda) * self.scale,
            ray: Ray::with_time(
                self.position(),
                sample_uniform_sphere(u1),
                time,
                self.medium,
            ),
            surface: None,
            pdf_pos: 1.0,
            pdf_dir: UNIFORM_SPHERE_PDF,
        })
    }
    /// `(0, 1/4π)`: pbrt-v4 reports no positional density for a delta.
    pub fn pdf_le(&self, _ray: &Ray) -> (Float, Float) {
        (0.0, UNIFORM_SPHERE_PDF)
    }
    /// 4π · scale · I.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.i.sample(lambda) * (4.0 * PI * self.scale)
    }
    /// A point emitting in every direction.
    pub fn bounds(&self) -> Option<LightBounds> {
        let p = self.position();
        Some(LightBounds::new(
            rpbrt_geometry::Bounds3f::from_point(p),
            Vector3f::new(0.0, 0.0, 1.0),
            4.0 * PI * self.scale * self.i.max_value(),
            -1.0,
            0.0,
            false,
        ))
    }
    /// The light's medium.
    pub fn medium(&self) -> Option<MediumId> {
        self.medium
    }
}

/// A spotlight along light-space +z with a smoothstep falloff between
/// `cos_falloff_start` and `cos_falloff_end` (pbrt-v4 `SpotLight`).
#[derive(Clone, Debug)]
pub struct SpotLight {
    /// Light space to render space.
    pub render_from_light: Transform,
    /// Radiant intensity spectrum on the axis.
    pub i: Spectrum,
    /// Scale (photometric normalisation and power target included).
    pub scale: Float,
    /// Cosine of the angle where the falloff starts (full intensity inside).
    pub cos_falloff_start: Float,
    /// Cosine of the cone's total angle (zero intensity outside).
    pub cos_falloff_end: Float,
    /// The medium around the light.
    pub medium: Option<MediumId>,
}

impl SpotLight {
    fn position(&self) -> Point3f {
        self.render_from_light
            .apply_point(Point3f::new(0.0, 0.0, 0.0))
    }
    /// Intensity toward light-space unit direction `w`.
    pub fn intensity(&self, w: Vector3f, lambda: &SampledWavelengths) -> SampledSpectrum {
        let falloff = smooth_step(w.z, self.cos_falloff_end, self.cos_falloff_start);
        self.i.sample(lambda) * (falloff * self.scale)
    }
    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let p = self.position();
        let wi = (p - ctx.p()).try_normalize()?;
        let wl = self
            .render_from_light
            .apply_inverse_vector(-wi)
            .try_normalize()?;
        delta_sample(ctx, p, self.intensity(wl, lambda))
    }
    /// Always zero: a delta distribution.
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vector3f, _a: bool) -> Float {
        0.0
    }
    /// The weights of the full-intensity cone and the falloff band in
    /// pbrt-v4's choice between them: their integrals over cos θ.
    fn section_weights(&self) -> [Float; 2] {
        [
            1.0 - self.cos_falloff_start,
            (self.cos_falloff_start - self.cos_falloff_end) / 2.0,
        ]
    }
    /// A ray sampled as pbrt-v4 does: `u2[0]` chooses the full-intensity
    /// cone or the falloff band by their power, `u1` the direction in it
    /// (uniform in the cone; cos θ ∝ smoothstep in the band).
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let p = self.section_weights();
        let sum = p[0] + p[1];
        if sum <= 0.0 {
            return None;
        }
        // pbrt-v4's `SampleDiscrete` over the two weights.
        let mut up = u2.x * sum;
        if up == sum {
            up = rpbrt_geometry::next_float_down(up);
        }
        let section = if p[0] > up { 0 } else { 1 };
        let section_pdf = p[section] / sum;
        let (w_light, pdf_dir) = if section == 0 {
            let w = sample_uniform_cone(u1, self.cos_falloff_start);
            (w, uniform_cone_pdf(self.cos_falloff_start) * section_pdf)
        } else {
            let cos_theta = sample_smooth_step(u1.x, self.cos_falloff_end, self.cos_falloff_start);
            let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
            let phi = u1.y * 2.0 * PI;
            let w = spherical_direction(sin_theta, cos_theta, phi);
            let pdf = smooth_step_pdf(cos_theta, self.cos_falloff_end, self.cos_falloff_start)
                * section_pdf
                / (2.0 * PI);
            (w, pdf)
        };
        delta_position_le(
            &self.render_from_light,
            w_light,
            self.intensity(w_light, lambda),
            pdf_dir,
            time,
            self.medium,
        )
    }
    /// `(0, pdf_dir)` of [`sample_le`](Self::sample_le) for the ray's
    /// direction.
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        let p = self.section_weights();
        let Some(w) = light_dir(&self.render_from_light, ray.d) else {
            return (0.0, 0.0);
        };
        if p[0] + p[1] <= 0.0 {
            return (0.0, 0.0);
        }
        let cos_theta = w.z;
        let pdf_dir = if cos_theta >= self.cos_falloff_start {
            uniform_cone_pdf(self.cos_falloff_start) * p[0] / (p[0] + p[1])
        } else {
            smooth_step_pdf(cos_theta, self.cos_falloff_end, self.cos_falloff_start) * p[1]
                / ((p[0] + p[1]) * (2.0 * PI))
        };
        (0.0, pdf_dir)
    }
    /// The integral of the falloff over the sphere times scale · I:
    /// 2π((1 − cos start) + (cos start − cos end)/2).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.i.sample(lambda)
            * (self.scale
                * 2.0
                * PI
                * ((1.0 - self.cos_falloff_start)
                    + (self.cos_falloff_start - self.cos_falloff_end) / 2.0))
    }
    /// Bounded as pbrt-v4 does: power as an isotropic point light, the
    /// full-intensity cone as θ_o and the falloff band as θ_e.
    pub fn bounds(&self) -> Option<LightBounds> {
        let p = self.position();
        let w = self
            .render_from_light
            .apply_vector(Vector3f::new(0.0, 0.0, 1.0));
        let phi = self.scale * self.i.max_value() * 4.0 * PI;
        let cos_theta_e = (acos_c(self.cos_falloff_end) - acos_c(self.cos_falloff_start)).cos();
        Some(LightBounds::new(
            rpbrt_geometry::Bounds3f::from_point(p),
            w,
            phi,
            self.cos_falloff_start,
            cos_theta_e,
            false,
        ))
    }
    /// The light's medium.
    pub fn medium(&self) -> Option<MediumId> {
        self.medium
    }
}

/// A point light whose intensity is modulated by a single-channel image
/// over the sphere of directions in pbrt-v4's equal-area octahedral layout
/// (pbrt-v4 `GoniometricLight`).
#[derive(Clone, Debug)]
pub struct GoniometricLight {
    /// Light space to render space (includes pbrt-v4's y/z swap).
    pub render_from_light: Transform,
    /// Intensity spectrum.
    pub i: Spectrum,
    /// Scale (photometric normalisation and power target included).
    pub scale: Float,
    /// Square single-channel image.
    pub image: Image,
    /// The medium around the light.
    pub medium: Option<MediumId>,
    /// Directions are sampled by image value over the equal-area square.
    distribution: PiecewiseConstant2D,
}

const OCTA_WRAP: WrapMode2D = WrapMode2D {
    wrap: [WrapMode::OctahedralSphere, WrapMode::OctahedralSphere],
};

/// Sum of channel 0 over all pixels.
fn channel_sum(image: &Image, c: usize) -> Float {
    let res = image.resolution();
    let mut sum = 0.0f64;
    for y in 0..res.y {
        for x in 0..res.x {
            sum += image.get_channel(Point2i::new(x, y), c, OCTA_WRAP) as f64;
        }
    }
    sum as Float
}

/// pbrt-v4's `Image::GetSamplingDistribution`: the average of the
/// channels of each pixel times `dxda` at the pixel's centre mapped into
/// `domain`, row by row.
fn sampling_distribution(
    image: &Image,
    domain: Bounds2f,
    dxda: impl Fn(Point2f) -> Float,
) -> PiecewiseConstant2D {
    let res = image.resolution();
    let (nx, ny) = (res.x.max(1) as usize, res.y.max(1) as usize);
    let nc = image.n_channels().max(1);
    let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
    let mut d = Vec::with_capacity(nx * ny);
    for y in 0..res.y {
        for x in 0..res.x {
            let avg = (0..nc)
                .map(|c| image.get_channel(Point2i::new(x, y), c, clamp))
                .sum::<Float>()
                / nc as Float;
            let p = domain.lerp(Point2f::new(
                (x as Float + 0.5) / res.x as Float,
                (y as Float + 0.5) / res.y as Float,
            ));
            d.push(avg * dxda(p));
        }
    }
    PiecewiseConstant2D::new(&d, nx, ny, domain)
}

impl GoniometricLight {
    /// The light with its direction-sampling distribution (the image's
    /// values over the equal-area square).
    pub fn new(
        render_from_light: Transform,
        i: Spectrum,
        scale: Float,
        image: Image,
        medium: Option<MediumId>,
    ) -> Self {
        let unit = Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(1.0, 1.0));
        let distribution = sampling_distribution(&image, unit, |_| 1.0);
        GoniometricLight {
            render_from_light,
            i,
            scale,
            image,
            medium,
            distribution,
        }
    }

    fn position(&self) -> Point3f {
        self.render_from_light
            .apply_point(Point3f::new(0.0, 0.0, 0.0))
    }
    /// Intensity toward light-space unit direction `w`.
    pub fn intensity(&self, w: Vector3f, lambda: &SampledWavelengths) -> SampledSpectrum {
        let uv = equal_area_sphere_to_square(w);
        let v = self.image.lookup_nearest_channel(uv, 0, OCTA_WRAP);
        self.i.sample(lambda) * (self.scale * v)
    }
    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let p = self.position();
        let wi = (p - ctx.p()).try_normalize()?;
        let wl = self
            .render_from_light
            .apply_inverse_vector(-wi)
            .try_normalize()?;
        delta_sample(ctx, p, self.intensity(wl, lambda))
    }
    /// Always zero: a delta distribution.
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vector3f, _a: bool) -> Float {
        0.0
    }
    /// A ray in a direction sampled by the image's values (`u1`; `u2`
    /// unused).
    pub fn sample_le(
        &self,
        u1: Point2f,
        _u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let (uv, pdf, _) = self.distribution.sample(u1);
        if pdf == 0.0 {
            return None;
        }
        let w_light = equal_area_square_to_sphere(uv);
        delta_position_le(
            &self.render_from_light,
            w_light,
            self.intensity(w_light, lambda),
            pdf / (4.0 * PI),
            time,
            self.medium,
        )
    }
    /// `(0, pdf_dir)` of [`sample_le`](Self::sample_le) for the ray's
    /// direction.
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        let Some(w) = light_dir(&self.render_from_light, ray.d) else {
            return (0.0, 0.0);
        };
        let uv = equal_area_sphere_to_square(w);
        (0.0, self.distribution.pdf(uv) / (4.0 * PI))
    }
    /// Mean image value times 4π · scale · I (each equal-area pixel
    /// subtends the same solid angle).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let res = self.image.resolution();
        let n = (res.x as Float * res.y as Float).max(1.0);
        self.i.sample(lambda) * (self.scale * 4.0 * PI * channel_sum(&self.image, 0) / n)
    }
    /// Bounded as an isotropic point light of the same power.
    pub fn bounds(&self) -> Option<LightBounds> {
        let res = self.image.resolution();
        let n = (res.x as Float * res.y as Float).max(1.0);
        let phi = self.scale * self.i.max_value() * 4.0 * PI * channel_sum(&self.image, 0) / n;
        Some(LightBounds::new(
            rpbrt_geometry::Bounds3f::from_point(self.position()),
            Vector3f::new(0.0, 0.0, 1.0),
            phi,
            -1.0,
            0.0,
            false,
        ))
    }
    /// The light's medium.
    pub fn medium(&self) -> Option<MediumId> {
        self.medium
    }
}

/// A point light projecting an RGB image through a perspective frustum
/// along light-space +z (pbrt-v4 `ProjectionLight`).
#[derive(Clone, Debug)]
pub struct ProjectionLight {
    /// Light space to render space (includes pbrt-v4's y flip).
    pub render_from_light: Transform,
    /// RGB image.
    pub image: Image,
    /// The image's colour space.
    pub color_space: &'static RgbColorSpace,
    /// Scale (photometric normalisation and power target included).
    pub scale: Float,
    /// Screen-space extent of the image (aspect-ratio dependent).
    pub screen_bounds: Bounds2f,
    /// tan(fov / 2).
    pub tan_half_fov: Float,
    /// Area of the image on the z = 1 plane.
    pub a: Float,
    /// Cosine of the angle to the image corner.
    pub cos_total_width: Float,
    /// The medium around the light.
    pub medium: Option<MediumId>,
    /// pbrt-v3's projection light without an image: this intensity over
    /// the whole frustum (`image` is then a white pixel, giving the
    /// frustum's shape and sampling).
    pub constant_i: Option<Spectrum>,
    /// Screen points are sampled by pixel value times cos³θ over the
    /// screen bounds.
    distribution: PiecewiseConstant2D,
}

/// pbrt-v4's near plane for projection lights: directions closer to the
/// light's plane than this are not lit.
const HITHER: Float = 1e-3;

impl ProjectionLight {
    /// Builds the frustum for `image` with full field of view `fov`
    /// degrees; `scale` must already include any normalisation.
    pub fn new(
        render_from_light: Transform,
        image: Image,
        color_space: &'static RgbColorSpace,
        scale: Float,
        fov: Float,
        medium: Option<MediumId>,
    ) -> Self {
        let res = image.resolution();
        let aspect = res.x as Float / res.y as Float;
        let screen_bounds = if aspect > 1.0 {
            Bounds2f::new(Point2f::new(-aspect, -1.0), Point2f::new(aspect, 1.0))
        } else {
            Bounds2f::new(
                Point2f::new(-1.0, -1.0 / aspect),
                Point2f::new(1.0, 1.0 / aspect),
            )
        };
        let tan_half_fov = (fov.to_radians() / 2.0).tan();
        let a =
            4.0 * tan_half_fov * tan_half_fov * if aspect > 1.0 { aspect } else { 1.0 / aspect };
        let mut l = ProjectionLight {
            render_from_light,
            image,
            color_space,
            scale,
            screen_bounds,
            tan_half_fov,
            a,
            cos_total_width: 0.0,
            medium,
            constant_i: None,
            distribution: PiecewiseConstant2D::unit(&[1.0], 1, 1),
        };
        l.cos_total_width = l.dir_from_screen(screen_bounds.p_max).z;
        l.distribution = sampling_distribution(&l.image, screen_bounds, |p| l.dwda(p));
        l
    }

    /// Light-space unit direction through screen point `ps`.
    fn dir_from_screen(&self, ps: Point2f) -> Vector3f {
        Vector3f::new(ps.x * self.tan_half_fov, ps.y * self.tan_half_fov, 1.0).normalize()
    }

    /// Solid angle per unit screen area at `ps` relative to the z = 1 plane
    /// (cos³θ).
    pub(crate) fn dwda(&self, ps: Point2f) -> Float {
        let z = self.dir_from_screen(ps).z;
        z * z * z
    }

    /// Screen point of pixel (x, y)'s centre.
    pub(crate) fn pixel_screen(&self, x: i32, y: i32) -> Point2f {
        let res = self.image.resolution();
        self.screen_bounds.lerp(Point2f::new(
            (x as Float + 0.5) / res.x as Float,
            (y as Float + 0.5) / res.y as Float,
        ))
    }

    fn position(&self) -> Point3f {
        self.render_from_light
            .apply_point(Point3f::new(0.0, 0.0, 0.0))
    }

    /// The unscaled emission of an image texel's `rgb`.
    fn emission(&self, rgb: [Float; 3], lambda: &SampledWavelengths) -> SampledSpectrum {
        match &self.constant_i {
            Some(i) => i.sample(lambda),
            None => rgb_illuminant(self.color_space, rgb, lambda),
        }
    }

    /// Intensity toward light-space direction `wl`.
    pub fn projection(&self, wl: Vector3f, lambda: &SampledWavelengths) -> SampledSpectrum {
        if wl.z < HITHER {
            return SampledSpectrum::new(0.0);
        }
        let ps = Point2f::new(
            wl.x / (wl.z * self.tan_half_fov),
            wl.y / (wl.z * self.tan_half_fov),
        );
        if !self.screen_bounds.inside(ps) {
            return SampledSpectrum::new(0.0);
        }
        let st = self.screen_bounds.offset(ps);
        let st = Point2f::new(st.x, st.y);
        let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
        let rgb = [0, 1, 2].map(|c| self.image.lookup_nearest_channel(st, c, clamp));
        self.emission(rgb, lambda) * self.scale
    }

    /// See [`super::Light::sample_li`].
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let p = self.position();
        let wi = (p - ctx.p()).try_normalize()?;
        let wl = self.render_from_light.apply_inverse_vector(-wi);
        delta_sample(ctx, p, self.projection(wl, lambda))
    }
    /// Always zero: a delta distribution.
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vector3f, _a: bool) -> Float {
        0.0
    }
    /// A ray through a screen point sampled by pixel value times cos³θ
    /// (`u1`; `u2` unused), as pbrt-v4.
    pub fn sample_le(
        &self,
        u1: Point2f,
        _u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let (ps, pdf, _) = self.distribution.sample(u1);
        if pdf == 0.0 {
            return None;
        }
        let w = self.dir_from_screen(ps);
        let cos_theta = w.z;
        let pdf_dir =
            pdf * self.screen_bounds.area() / (self.a * cos_theta * cos_theta * cos_theta);
        // pbrt-v4 looks the image up at the sampled screen point directly
        // (no near-plane or bounds test: the point is inside by
        // construction).
        let st = self.screen_bounds.offset(ps);
        let st = Point2f::new(st.x, st.y);
        let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
        let rgb = [0, 1, 2].map(|c| self.image.lookup_nearest_channel(st, c, clamp));
        let l = self.emission(rgb, lambda) * self.scale;
        delta_position_le(&self.render_from_light, w, l, pdf_dir, time, self.medium)
    }
    /// `(0, pdf_dir)` of [`sample_le`](Self::sample_le) for the ray's
    /// direction: zero outside the frustum.
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        let Some(w) = light_dir(&self.render_from_light, ray.d) else {
            return (0.0, 0.0);
        };
        if w.z < HITHER {
            return (0.0, 0.0);
        }
        let ps = Point2f::new(
            w.x / (w.z * self.tan_half_fov),
            w.y / (w.z * self.tan_half_fov),
        );
        if !self.screen_bounds.inside(ps) {
            return (0.0, 0.0);
        }
        let pdf_dir =
            self.distribution.pdf(ps) * self.screen_bounds.area() / (self.a * w.z * w.z * w.z);
        (0.0, pdf_dir)
    }
    /// The frustum's solid angle, 4 asin(sin α sin β) for the half-angles
    /// α, β of its sides.
    pub fn solid_angle(&self) -> Float {
        let half = |t: Float| (t * self.tan_half_fov).atan();
        let (a, b) = (
            half(self.screen_bounds.p_max.x),
            half(self.screen_bounds.p_max.y),
        );
        4.0 * (a.sin() * b.sin()).asin()
    }

    /// Sum over pixels of their emission times their solid angle (the
    /// intensity times the frustum's solid angle for a constant one).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        if let Some(i) = &self.constant_i {
            return i.sample(lambda) * (self.scale * self.solid_angle());
        }
        let res = self.image.resolution();
        let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
        let mut sum = SampledSpectrum::new(0.0);
        for y in 0..res.y {
            for x in 0..res.x {
                let dwda = self.dwda(self.pixel_screen(x, y));
                let rgb = [0, 1, 2].map(|c| self.image.get_channel(Point2i::new(x, y), c, clamp));
                sum += self.emission(rgb, lambda) * dwda;
            }
        }
        sum * (self.scale * self.a / (res.x as Float * res.y as Float))
    }
    /// pbrt-v4's bound: mean of the per-pixel maximum channel times scale,
    /// the frustum's axis and half-angle.
    pub fn bounds(&self) -> Option<LightBounds> {
        let res = self.image.resolution();
        let clamp = WrapMode2D::new(WrapMode::Clamp, WrapMode::Clamp);
        let mut sum = 0.0f64;
        for y in 0..res.y {
            for x in 0..res.x {
                let m = (0..3)
                    .map(|c| self.image.get_channel(Point2i::new(x, y), c, clamp))
                    .fold(Float::MIN, Float::max);
                sum += m as f64;
            }
        }
        let peak = self.constant_i.as_ref().map_or(1.0, |i| i.max_value());
        let phi = peak * self.scale * sum as Float / (res.x as Float * res.y as Float);
        let w = self
            .render_from_light
            .apply_vector(Vector3f::new(0.0, 0.0, 1.0));
        Some(LightBounds::new(
            rpbrt_geometry::Bounds3f::from_point(self.position()),
            w,
            phi,
            1.0,
            self.cos_total_width,
            false,
        ))
    }
    /// The light's medium.
    pub fn medium(&self) -> Option<MediumId> {
        self.medium
    }
}
