//! An environment map seen through a rectangular portal (book section
//! 12.5.3; pbrt-v4 `PortalImageInfiniteLight`).
//!
//! The equal-area environment map is resampled once into a *rectified*
//! image: direction `w` with local coordinates (x, y, z) in the portal's
//! frame (z > 0 through the portal) maps to
//! `u = (atan2(x, z) + π/2) / π`, `v = (atan2(y, z) + π/2) / π`. Under this
//! mapping the portal, seen from any point, covers an axis-aligned
//! rectangle spanned by the images of two opposite corners, so sampling
//! from a point restricts a [`WindowedPiecewiseConstant2D`] to that
//! rectangle. The change of variables is
//! `dω/d(u,v) = π² (1 − x²)(1 − y²) / z` for unit `w` (pbrt-v4 names this
//! factor `dw_duv`; it is solid angle per unit image area, so densities
//! convert as `p(ω) = p(u,v) / (dω/d(u,v))`).

use rpbrt_geometry::{
    dot, equal_area_sphere_to_square, Bounds2f, Bounds3f, Float, Frame, MediumId, Normal3f,
    Point2f, Point2i, Point3f, Point3fi, Ray, Transform, Vector3f, PI,
};

use super::{
    rgb_illuminant, LightBounds, LightLeSample, LightLiSample, LightSampleContext, SceneSphere,
};
use crate::image::{Image, WrapMode, WrapMode2D};
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths};

#[cfg(test)]
mod tests;
mod windowed;

pub use windowed::{SummedAreaTable, WindowedPiecewiseConstant2D};

const OCTA_WRAP: WrapMode2D = WrapMode2D {
    wrap: [WrapMode::OctahedralSphere, WrapMode::OctahedralSphere],
};
const CLAMP_WRAP: WrapMode2D = WrapMode2D {
    wrap: [WrapMode::Clamp, WrapMode::Clamp],
};

/// The tolerance pbrt-v4 allows on the cosines that check a portal is a
/// rectangle.
const RECT_TOLERANCE: Float = 1e-3;

/// An image infinite light restricted to the directions through a
/// rectangular portal (pbrt-v4 `PortalImageInfiniteLight`). Radiance
/// arriving from outside the portal is zero.
#[derive(Clone, Debug)]
pub struct PortalImageInfiniteLight {
    /// The portal's corners in render space, in order around the
    /// rectangle.
    pub portal: [Point3f; 4],
    /// x along corner 0 → 3, y along corner 0 → 1, z = x × y: the side
    /// the environment lies on.
    pub portal_frame: Frame,
    /// The environment map resampled into the portal's rectified layout
    /// (RGB, float).
    pub image: Image,
    /// The image's colour space.
    pub color_space: &'static RgbColorSpace,
    /// Scale (photometric normalisation and illuminance target included).
    pub scale: Float,
    /// The scene's bounding sphere, set by `preprocess`.
    pub scene: SceneSphere,
    distribution: WindowedPiecewiseConstant2D,
}

/// dω/d(u,v) for the unit portal-frame direction `w`: pbrt-v4's
/// π² (1 − x²)(1 − y²) / z, with 1 − x² written as y² + z² and 1 − y² as
/// x² + z² (equal for a unit vector) so that grazing directions, where
/// x or y is nearly ±1, do not lose their digits to cancellation.
#[inline]
fn dw_duv(w: Vector3f) -> Float {
    PI * PI * (w.y * w.y + w.z * w.z) * (w.x * w.x + w.z * w.z) / w.z
}

/// Checks that `portal` is a rectangle as pbrt-v4 does (opposite edges
/// parallel, adjacent edges perpendicular, within a cosine of 10⁻³) and
/// returns the portal frame.
pub fn portal_frame(portal: &[Point3f; 4]) -> Result<Frame, String> {
    let edge = |a: usize, b: usize| {
        (portal[b] - portal[a])
            .try_normalize()
            .ok_or_else(|| format!("portal corners {a} and {b} coincide"))
    };
    let p01 = edge(0, 1)?;
    let p12 = edge(1, 2)?;
    let p32 = edge(3, 2)?;
    let p03 = edge(0, 3)?;
    let parallel = (dot(p01, p32) - 1.0).abs() <= RECT_TOLERANCE
        && (dot(p12, p03) - 1.0).abs() <= RECT_TOLERANCE;
    let perpendicular = dot(p01, p12).abs() <= RECT_TOLERANCE
        && dot(p12, p32).abs() <= RECT_TOLERANCE
        && dot(p32, p03).abs() <= RECT_TOLERANCE
        && dot(p03, p01).abs() <= RECT_TOLERANCE;
    if !parallel || !perpendicular {
        return Err(
            "infinite light portal isn't a planar rectangle (its four corners must \
                    be given in order around a rectangle)"
                .into(),
        );
    }
    Ok(Frame::from_xy(p03, p01))
}

impl PortalImageInfiniteLight {
    /// Builds the light from a square RGB equal-area `image` (checked by
    /// the caller) in light space and a `portal` in render space; errors
    /// when the portal is not a rectangle.
    pub fn new(
        render_from_light: Transform,
        equal_area_image: &Image,
        color_space: &'static RgbColorSpace,
        scale: Float,
        portal: [Point3f; 4],
    ) -> Result<Self, String> {
        let portal_frame = portal_frame(&portal)?;
        let res = equal_area_image.resolution();
        let (nx, ny) = (res.x.max(1) as usize, res.y.max(1) as usize);
        let mut light = PortalImageInfiniteLight {
            portal,
            portal_frame,
            image: Image::new(
                crate::image::PixelFormat::Float,
                Point2i::new(nx as i32, ny as i32),
                &["R", "G", "B"],
                equal_area_image.encoding(),
            ),
            color_space,
            scale,
            scene: SceneSphere::default(),
            distribution: WindowedPiecewiseConstant2D::new(&[0.0], 1, 1),
        };
        // Resample the environment map into the rectified layout, and
        // weight each pixel's mean by dω/d(u,v) at its centre so that the
        // density over directions follows the radiance.
        let mut d = Vec::with_capacity(nx * ny);
        for y in 0..ny {
            for x in 0..nx {
                let uv = Point2f::new(
                    (x as Float + 0.5) / nx as Float,
                    (y as Float + 0.5) / ny as Float,
                );
                let (w, dw_duv) = light.render_from_image(uv);
                let wl = render_from_light
                    .apply_inverse_vector(w)
                    .try_normalize()
                    .unwrap_or(Vector3f::new(0.0, 0.0, 1.0));
                let uv_equi = equal_area_sphere_to_square(wl);
                let p = Point2i::new(x as i32, y as i32);
                let mut sum = 0.0;
                for c in 0..3 {
                    let v = equal_area_image.bilerp_channel(uv_equi, c, OCTA_WRAP);
                    light.image.set_channel(p, c, v);
                    sum += v;
                }
                d.push(sum / 3.0 * dw_duv);
            }
        }
        light.distribution = WindowedPiecewiseConstant2D::new(&d, nx, ny);
        Ok(light)
    }

    /// Rectified image coordinates of render-space direction `w` and the
    /// Jacobian dω/d(u,v) there; `None` for directions not heading
    /// through the portal's plane toward the environment.
    pub fn image_from_render(&self, w: Vector3f) -> Option<(Point2f, Float)> {
        let w = self.portal_frame.to_local(w);
        if w.z <= 0.0 {
            return None;
        }
        let dw_duv = dw_duv(w);
        let alpha = w.x.atan2(w.z);
        let beta = w.y.atan2(w.z);
        let uv = Point2f::new(
            ((alpha + PI / 2.0) / PI).clamp(0.0, 1.0),
            ((beta + PI / 2.0) / PI).clamp(0.0, 1.0),
        );
        Some((uv, dw_duv))
    }

    /// The render-space direction of rectified coordinates `uv` and the
    /// Jacobian dω/d(u,v) there.
    pub fn render_from_image(&self, uv: Point2f) -> (Vector3f, Float) {
        let alpha = -PI / 2.0 + uv.x * PI;
        let beta = -PI / 2.0 + uv.y * PI;
        let w = Vector3f::new(alpha.tan(), beta.tan(), 1.0).normalize();
        let dw_duv = dw_duv(w);
        (self.portal_frame.from_local(w), dw_duv)
    }

    /// The rectangle of rectified coordinates through which the portal is
    /// seen from `p`; `None` from behind the portal's plane.
    pub fn image_bounds(&self, p: Point3f) -> Option<Bounds2f> {
        let (p0, _) = self.image_from_render((self.portal[0] - p).try_normalize()?)?;
        let (p1, _) = self.image_from_render((self.portal[2] - p).try_normalize()?)?;
        Some(Bounds2f::new(p0, p1))
    }

    /// The portal's area.
    pub fn area(&self) -> Float {
        (self.portal[1] - self.portal[0]).length() * (self.portal[3] - self.portal[0]).length()
    }

    /// Radiance stored at rectified coordinates `uv` (nearest pixel).
    pub fn image_lookup(&self, uv: Point2f, lambda: &SampledWavelengths) -> SampledSpectrum {
        let rgb = [0, 1, 2].map(|c| self.image.lookup_nearest_channel(uv, c, CLAMP_WRAP));
        rgb_illuminant(self.color_space, rgb, lambda) * self.scale
    }

    /// Samples a direction through the portal as seen from `ctx`, by the
    /// rectified image's brightness times the Jacobian. The light ignores
    /// `allow_incomplete_pdf`, as pbrt-v4's does.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Point2f,
        lambda: &SampledWavelengths,
        _allow_incomplete_pdf: bool,
    ) -> Option<LightLiSample> {
        let b = self.image_bounds(ctx.p())?;
        let (uv, map_pdf) = self.distribution.sample(u, &b)?;
        if map_pdf == 0.0 {
            return None;
        }
        let (wi, dw_duv) = self.render_from_image(uv);
        if dw_duv == 0.0 {
            return None;
        }
        Some(LightLiSample {
            l: self.image_lookup(uv, lambda),
            wi,
            pdf: map_pdf / dw_duv,
            p_light: Point3fi::from(ctx.p() + wi * (2.0 * self.scene.radius)),
            n_light: Normal3f::default(),
        })
    }

    /// The solid-angle density of `w` from `ctx`: zero for directions that
    /// miss the portal.
    pub fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        w: Vector3f,
        _allow_incomplete_pdf: bool,
    ) -> Float {
        let Some((uv, dw_duv)) = w.try_normalize().and_then(|w| self.image_from_render(w)) else {
            return 0.0;
        };
        if dw_duv == 0.0 {
            return 0.0;
        }
        let Some(b) = self.image_bounds(ctx.p()) else {
            return 0.0;
        };
        self.distribution.pdf(uv, &b) / dw_duv
    }

    /// Radiance along an escaping ray: zero unless it leaves through the
    /// portal.
    pub fn le(&self, ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        let uv = ray
            .d
            .try_normalize()
            .and_then(|w| self.image_from_render(w));
        match (uv, self.image_bounds(ray.o)) {
            (Some((uv, _)), Some(b)) if b.inside(uv) => self.image_lookup(uv, lambda),
            _ => SampledSpectrum::new(0.0),
        }
    }

    /// A ray whose direction is sampled over the whole rectified image
    /// (every direction arriving through the portal's plane, not only
    /// through the portal) by `u1`, through a point on the scene's
    /// bounding disk chosen by `u2`, as pbrt-v4 does (its variant that
    /// samples points on the portal itself is disabled there, as it does
    /// not work with BDPT).
    pub fn sample_le(
        &self,
        u1: Point2f,
        u2: Point2f,
        lambda: &SampledWavelengths,
        time: Float,
    ) -> Option<LightLeSample> {
        let unit = Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(1.0, 1.0));
        let (uv, map_pdf) = self.distribution.sample(u1, &unit)?;
        let (w, dw_duv) = self.render_from_image(uv);
        if dw_duv == 0.0 || map_pdf == 0.0 {
            return None;
        }
        let (ray, pdf_pos) = self.scene.sample_ray_through_disk(-w, u2, time);
        Some(LightLeSample {
            l: self.image_lookup(uv, lambda),
            ray,
            surface: None,
            pdf_pos,
            pdf_dir: map_pdf / dw_duv,
        })
    }

    /// The densities of [`sample_le`](Self::sample_le) for `ray`: zero for
    /// rays that do not travel away from the environment's side of the
    /// portal's plane.
    pub fn pdf_le(&self, ray: &Ray) -> (Float, Float) {
        let Some((uv, dw_duv)) = (-ray.d)
            .try_normalize()
            .and_then(|w| self.image_from_render(w))
        else {
            return (0.0, 0.0);
        };
        if dw_duv == 0.0 {
            return (0.0, 0.0);
        }
        let unit = Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(1.0, 1.0));
        let pdf = self.distribution.pdf(uv, &unit);
        (self.scene.disk_pdf(), pdf / dw_duv)
    }

    /// pbrt-v4's power estimate, kept as it is: scale · portal area · the
    /// mean over pixels of radiance / (dω/d(u,v)).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let res = self.image.resolution();
        let mut sum = SampledSpectrum::new(0.0);
        for y in 0..res.y {
            for x in 0..res.x {
                let rgb =
                    [0, 1, 2].map(|c| self.image.get_channel(Point2i::new(x, y), c, CLAMP_WRAP));
                let st = Point2f::new(
                    (x as Float + 0.5) / res.x as Float,
                    (y as Float + 0.5) / res.y as Float,
                );
                let (_, dw_duv) = self.render_from_image(st);
                sum += rgb_illuminant(self.color_space, rgb, lambda) * (1.0 / dw_duv);
            }
        }
        sum * (self.scale * self.area() / (res.x as Float * res.y as Float))
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
