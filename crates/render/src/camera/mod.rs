//! Cameras (book chapter 5; pbrt-v4 `base/camera.h`, `cameras.h`,
//! `cameras.cpp`): the mapping from a film sample to a ray leaving the
//! camera into the scene.
//!
//! [`Camera`] is a closed enum over the four pbrt-v4 cameras
//! ([`PerspectiveCamera`], [`OrthographicCamera`], [`SphericalCamera`] and
//! [`RealisticCamera`]); each method is a one-line delegation. Every camera
//! carries a [`CameraBase`] with what they share: placement over time,
//! shutter interval, film geometry, medium and the minimum ray
//! differentials used to approximate texture footprints for rays that have
//! no differentials of their own (book section 10.1.2).
//!
//! Conventions are pbrt-v4's: camera space is left-handed, looking down +z
//! with +y up; raster coordinates are in pixels with y going down, so
//! raster x increasing is camera +x and raster y increasing is camera −y.

mod create;
mod lanes;
mod place;
mod projective;
mod realistic;
mod spherical;
mod transform;

#[cfg(test)]
mod tests;

use rpbrt_geometry::interaction::CameraDifferentials;
use rpbrt_geometry::{
    lerp, Bounds2f, Bounds2i, Float, Frame, MediumId, Normal3f, Point2f, Point2i, Point3f, Ray,
    RayDifferential, Transform, Vector2f, Vector3f,
};

use crate::spectrum::{SampledSpectrum, SampledWavelengths};

pub use create::{create_camera, read_lens_file, CAMERA_NAMES};
pub use lanes::{OffsetRays, PinholeRays};
pub use place::{LensChange, LensSettings};
pub use projective::{OrthographicCamera, PerspectiveCamera, ProjectiveTransforms};
pub use realistic::{ApertureImage, LensElementInterface, RealisticCamera};
pub use spherical::{SphericalCamera, SphericalMapping};
pub use transform::{CameraTransform, RenderingCoordinateSystem};

/// Where on the film and lens, and when, a camera ray starts (pbrt-v4
/// `CameraSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSample {
    /// The film position in raster coordinates (pixels, y down).
    pub p_film: Point2f,
    /// A point in [0,1)² choosing the position on the lens.
    pub p_lens: Point2f,
    /// A value in [0,1) choosing the time within the shutter interval.
    pub time: Float,
    /// The reconstruction filter's weight for this sample.
    pub filter_weight: Float,
}

impl Default for CameraSample {
    fn default() -> Self {
        CameraSample {
            p_film: Point2f::new(0.0, 0.0),
            p_lens: Point2f::new(0.5, 0.5),
            time: 0.0,
            filter_weight: 1.0,
        }
    }
}

/// A camera ray in render space and the weight of the radiance it carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRay {
    /// The ray, in render space.
    pub ray: Ray,
    /// The factor scaling the radiance arriving along it (1 except for the
    /// realistic camera).
    pub weight: Float,
}

/// A camera ray with its one-pixel-offset neighbours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRayDifferential {
    /// The ray and its differentials, in render space.
    pub ray: RayDifferential,
    /// The factor scaling the radiance arriving along it.
    pub weight: Float,
}

/// Importance arriving at a reference point from a point sampled on the
/// camera's lens (pbrt-v4 `CameraWiSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraWiSample {
    /// The importance `We` of the ray from the lens point toward the
    /// reference point (pbrt-v4 `Wi`).
    pub wi_importance: SampledSpectrum,
    /// Unit direction from the reference point toward the lens point.
    pub wi: Vector3f,
    /// Density of `wi` per unit solid angle at the reference point.
    pub pdf: Float,
    /// Where on the film (raster coordinates) the reference point lands.
    pub p_raster: Point2f,
    /// The lens point, in render space.
    pub p_lens: Point3f,
    /// The lens's normal: the camera's viewing direction in render space.
    pub n_lens: Normal3f,
}

/// What a camera needs to know about the film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmGeometry {
    /// The image's full resolution in pixels.
    pub full_resolution: Point2i,
    /// The pixels actually rendered (the crop window).
    pub pixel_bounds: Bounds2i,
    /// The physical diagonal of the sensor in metres (film parameter
    /// `"diagonal"`, given in millimetres, divided by 1000).
    pub diagonal_m: Float,
}

impl FilmGeometry {
    /// A film of `x` × `y` pixels, all rendered, with pbrt-v4's default
    /// 35 mm diagonal.
    pub fn new(x: i32, y: i32) -> Self {
        FilmGeometry {
            full_resolution: Point2i::new(x, y),
            pixel_bounds: Bounds2i::new(Point2i::new(0, 0), Point2i::new(x, y)),
            diagonal_m: 0.035,
        }
    }
}

/// What every camera shares (pbrt-v4 `CameraBase`).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraBase {
    /// Where the camera is in render space, over time.
    pub camera_transform: CameraTransform,
    /// Shutter opening time.
    pub shutter_open: Float,
    /// Shutter closing time.
    pub shutter_close: Float,
    /// The film's resolution and size.
    pub film: FilmGeometry,
    /// The medium the camera sits in.
    pub medium: Option<MediumId>,
    /// Smallest change of ray origin per pixel in x, in camera space.
    pub min_pos_differential_x: Vector3f,
    /// Smallest change of ray origin per pixel in y, in camera space.
    pub min_pos_differential_y: Vector3f,
    /// Smallest change of (normalised, local-frame) ray direction per pixel
    /// in x.
    pub min_dir_differential_x: Vector3f,
    /// Smallest change of ray direction per pixel in y.
    pub min_dir_differential_y: Vector3f,
    /// The radius of the film's reconstruction filter (pbrt-v4 asks the
    /// film for it): it decides the film's sample bounds and how far off
    /// axis the perspective camera's importance reaches. (0.5, 0.5), a box
    /// filter's, until [`Camera::set_filter_radius`] sets it.
    pub filter_radius: Vector2f,
}

impl CameraBase {
    /// A base with the given placement, shutter (swapped when reversed),
    /// film and medium; the minimum differentials start at zero and are set
    /// by the concrete camera.
    pub fn new(
        camera_transform: CameraTransform,
        shutter_open: Float,
        shutter_close: Float,
        film: FilmGeometry,
        medium: Option<MediumId>,
    ) -> Self {
        let (shutter_open, shutter_close) = if shutter_close < shutter_open {
            (shutter_close, shutter_open)
        } else {
            (shutter_open, shutter_close)
        };
        CameraBase {
            camera_transform,
            shutter_open,
            shutter_close,
            film,
            medium,
            min_pos_differential_x: Vector3f::default(),
            min_pos_differential_y: Vector3f::default(),
            min_dir_differential_x: Vector3f::default(),
            min_dir_differential_y: Vector3f::default(),
            filter_radius: Vector2f::new(0.5, 0.5),
        }
    }

    /// The film area that receives samples: the pixel bounds grown by the
    /// filter radius less half a pixel (pbrt-v4 `Film::SampleBounds`).
    pub fn film_sample_bounds(&self) -> Bounds2f {
        let b = self.film.pixel_bounds;
        let r = self.filter_radius;
        Bounds2f::new(
            Point2f::new(
                b.p_min.x as Float - r.x + 0.5,
                b.p_min.y as Float - r.y + 0.5,
            ),
            Point2f::new(
                b.p_max.x as Float + r.x - 0.5,
                b.p_max.y as Float + r.y - 0.5,
            ),
        )
    }

    /// The time for the sample value `u` in [0,1): a lerp across the shutter
    /// interval.
    #[inline]
    pub fn sample_time(&self, u: Float) -> Float {
        lerp(u, self.shutter_open, self.shutter_close)
    }

    /// A camera-space ray taken to render space at its own time.
    #[inline]
    pub fn render_from_camera_ray(&self, r: &Ray) -> Ray {
        self.camera_transform
            .render_from_camera
            .apply_ray(r, Float::INFINITY)
            .0
    }

    /// A camera-space ray differential taken to render space at its time.
    #[inline]
    pub fn render_from_camera_ray_differential(&self, r: &RayDifferential) -> RayDifferential {
        let rfc = &self.camera_transform.render_from_camera;
        let xf = if rfc.is_animated() {
            rfc.interpolate(r.ray.time)
        } else {
            rfc.start_transform()
        };
        xf.apply_ray_differential(r, Float::INFINITY).0
    }

    /// From render space to camera space at `time`.
    pub fn camera_from_render(&self, time: Float) -> Transform {
        self.camera_transform.camera_from_render(time)
    }

    /// The minimum differentials with the camera placement at the middle of
    /// the shutter interval, for `SurfaceInteraction::compute_differentials`
    /// (pbrt-v4 `CameraBase::Approximate_dp_dxy`).
    pub fn camera_differentials(&self) -> CameraDifferentials {
        let t_mid = 0.5 * (self.shutter_open + self.shutter_close);
        CameraDifferentials {
            camera_from_render: self.camera_from_render(t_mid),
            min_pos_differential_x: self.min_pos_differential_x,
            min_pos_differential_y: self.min_pos_differential_y,
            min_dir_differential_x: self.min_dir_differential_x,
            min_dir_differential_y: self.min_dir_differential_y,
        }
    }

    /// Sets the minimum differentials by generating ray differentials at
    /// 512 points along the film's diagonal and keeping the shortest
    /// changes (pbrt-v4 `FindMinimumDifferentials`).
    fn find_minimum_differentials(
        &mut self,
        generate: impl Fn(&CameraBase, &CameraSample) -> Option<CameraRayDifferential>,
    ) {
        let inf = Vector3f::new(Float::INFINITY, Float::INFINITY, Float::INFINITY);
        let (mut pos_x, mut pos_y, mut dir_x, mut dir_y) = (inf, inf, inf, inf);
        let n = 512;
        let res = self.film.full_resolution;
        for i in 0..n {
            let f = i as Float / (n - 1) as Float;
            let sample = CameraSample {
                p_film: Point2f::new(f * res.x as Float, f * res.y as Float),
                p_lens: Point2f::new(0.5, 0.5),
                time: 0.5,
                filter_weight: 1.0,
            };
            let Some(crd) = generate(self, &sample) else {
                continue;
            };
            let ray = crd.ray;
            let cfr = self.camera_from_render(ray.ray.time);
            let dox = cfr.apply_vector(ray.rx_origin - ray.ray.o);
            if dox.length() < pos_x.length() {
                pos_x = dox;
            }
            let doy = cfr.apply_vector(ray.ry_origin - ray.ray.o);
            if doy.length() < pos_y.length() {
                pos_y = doy;
            }
            let (Some(d), Some(dx), Some(dy)) = (
                ray.ray.d.try_normalize(),
                ray.rx_direction.try_normalize(),
                ray.ry_direction.try_normalize(),
            ) else {
                continue;
            };
            let frame = Frame::from_z(d);
            let df = frame.to_local(d);
            let dxf = frame.to_local(dx).normalize();
            let dyf = frame.to_local(dy).normalize();
            if (dxf - df).length() < dir_x.length() {
                dir_x = dxf - df;
            }
            if (dyf - df).length() < dir_y.length() {
                dir_y = dyf - df;
            }
        }
        self.min_pos_differential_x = pos_x;
        self.min_pos_differential_y = pos_y;
        self.min_dir_differential_x = dir_x;
        self.min_dir_differential_y = dir_y;
    }
}

/// Ray differentials for cameras without a closed form: the rays for film
/// positions shifted by ±0.05 pixel, scaled up to one pixel (pbrt-v4
/// `CameraBase::GenerateRayDifferential`).
fn differential_by_offset(
    sample: &CameraSample,
    generate: impl Fn(&CameraSample) -> Option<CameraRay>,
) -> Option<CameraRayDifferential> {
    let cr = generate(sample)?;
    let mut rd = RayDifferential::new(cr.ray);
    let mut got_x = false;
    for eps in [0.05, -0.05] {
        let mut s = *sample;
        s.p_film.x += eps;
        if let Some(rx) = generate(&s) {
            rd.rx_origin = rd.ray.o + (rx.ray.o - rd.ray.o) / eps;
            rd.rx_direction = rd.ray.d + (rx.ray.d - rd.ray.d) / eps;
            got_x = true;
            break;
        }
    }
    let mut got_y = false;
    for eps in [0.05, -0.05] {
        let mut s = *sample;
        s.p_film.y += eps;
        if let Some(ry) = generate(&s) {
            rd.ry_origin = rd.ray.o + (ry.ray.o - rd.ray.o) / eps;
            rd.ry_direction = rd.ray.d + (ry.ray.d - rd.ray.d) / eps;
            got_y = true;
            break;
        }
    }
    rd.has_differentials = got_x && got_y;
    Some(CameraRayDifferential {
        ray: rd,
        weight: cr.weight,
    })
}

/// A camera: one of pbrt-v4's four (closed set; each method delegates).
#[derive(Clone, Debug)]
pub enum Camera {
    /// Pinhole or thin-lens perspective projection.
    Perspective(PerspectiveCamera),
    /// Parallel projection, optionally with a thin lens.
    Orthographic(OrthographicCamera),
    /// Every direction around a point, mapped to the film.
    Spherical(SphericalCamera),
    /// A traced system of spherical lens elements. Boxed: it owns the lens
    /// description, exit-pupil table and aperture image.
    Realistic(Box<RealisticCamera>),
}

impl Camera {
    /// The ray for a film sample, or `None` when none leaves the camera
    /// (e.g. vignetted by the lens system).
    #[inline]
    pub fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        match self {
            Camera::Perspective(c) => c.generate_ray(sample),
            Camera::Orthographic(c) => c.generate_ray(sample),
            Camera::Spherical(c) => c.generate_ray(sample),
            Camera::Realistic(c) => c.generate_ray(sample),
        }
    }

    /// The ray for a film sample with the rays one pixel over in x and y.
    #[inline]
    pub fn generate_ray_differential(
        &self,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        match self {
            Camera::Perspective(c) => c.generate_ray_differential(sample),
            Camera::Orthographic(c) => c.generate_ray_differential(sample),
            Camera::Spherical(c) => c.generate_ray_differential(sample),
            Camera::Realistic(c) => c.generate_ray_differential(sample),
        }
    }

    /// What all cameras share.
    #[inline]
    pub fn base(&self) -> &CameraBase {
        match self {
            Camera::Perspective(c) => &c.base,
            Camera::Orthographic(c) => &c.base,
            Camera::Spherical(c) => &c.base,
            Camera::Realistic(c) => &c.base,
        }
    }

    /// The time for the sample value `u` (see [`CameraBase::sample_time`]).
    #[inline]
    pub fn sample_time(&self, u: Float) -> Float {
        self.base().sample_time(u)
    }

    /// The minimum differentials for approximate texture footprints.
    pub fn camera_differentials(&self) -> CameraDifferentials {
        self.base().camera_differentials()
    }

    /// Records the radius of the film's reconstruction filter, which
    /// [`we`](Self::we) and [`pdf_we`](Self::pdf_we) need (pbrt-v4 reads
    /// it from the film); the scene sets it when it creates the camera.
    pub fn set_filter_radius(&mut self, radius: Vector2f) {
        match self {
            Camera::Perspective(c) => c.set_filter_radius(radius),
            Camera::Orthographic(c) => c.base.filter_radius = radius,
            Camera::Spherical(c) => c.base.filter_radius = radius,
            Camera::Realistic(c) => c.base.filter_radius = radius,
        }
    }

    /// True for cameras with importance functions, which light-tracing
    /// methods can connect to (pbrt-v4: the perspective camera only).
    #[inline]
    pub fn supports_importance(&self) -> bool {
        matches!(self, Camera::Perspective(_))
    }

    /// The importance of `ray` leaving the lens and the raster position
    /// it reaches (pbrt-v4 `We`): zero outside the film's sample bounds,
    /// behind the camera, and for cameras without importance.
    #[inline]
    pub fn we(&self, ray: &Ray, lambda: &SampledWavelengths) -> (SampledSpectrum, Point2f) {
        match self {
            Camera::Perspective(c) => c.we(ray, lambda),
            _ => (SampledSpectrum::new(0.0), Point2f::new(0.0, 0.0)),
        }
    }

    /// The densities `(pdf_pos, pdf_dir)` of `ray` leaving the camera
    /// (pbrt-v4 `PDF_We`): per unit lens area and per unit solid angle;
    /// zero where [`we`](Self::we) is.
    #[inline]
    pub fn pdf_we(&self, ray: &Ray) -> (Float, Float) {
        match self {
            Camera::Perspective(c) => c.pdf_we(ray),
            _ => (0.0, 0.0),
        }
    }

    /// Samples a point on the lens (`u`) as seen from `p_ref` at `time`
    /// (pbrt-v4 `SampleWi`); `None` when the camera does not see `p_ref`
    /// or has no importance function.
    #[inline]
    pub fn sample_wi(
        &self,
        p_ref: Point3f,
        time: Float,
        u: Point2f,
        lambda: &SampledWavelengths,
    ) -> Option<CameraWiSample> {
        match self {
            Camera::Perspective(c) => c.sample_wi(p_ref, time, u, lambda),
            _ => None,
        }
    }
}
