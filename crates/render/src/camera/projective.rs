//! Projective cameras (book sections 5.2.1–5.2.3; pbrt-v4
//! `ProjectiveCamera`, `OrthographicCamera`, `PerspectiveCamera`): a
//! projection from camera to screen space, a screen window mapped to the
//! raster, and an optional thin lens.

use rpbrt_geometry::{
    abs_dot, dot, Bounds2f, Float, Normal3f, Point2f, Point3f, Ray, RayDifferential, Transform,
    TransformError, Vector2f, Vector3f, PI,
};

use super::{CameraBase, CameraRay, CameraRayDifferential, CameraSample, CameraWiSample};
use crate::sampling::sample_uniform_disk_concentric;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// The transformations between camera, screen and raster space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectiveTransforms {
    /// The camera's projection.
    pub screen_from_camera: Transform,
    /// Raster (pixels, y down) to camera space.
    pub camera_from_raster: Transform,
    /// Screen to raster space.
    pub raster_from_screen: Transform,
    /// Raster to screen space.
    pub screen_from_raster: Transform,
}

impl ProjectiveTransforms {
    /// The transformations for a projection, screen window and film
    /// resolution: the window's upper-left corner goes to raster (0, 0) and
    /// its lower-right to the resolution.
    pub fn new(
        screen_from_camera: Transform,
        screen_window: Bounds2f,
        base: &CameraBase,
    ) -> ProjectiveTransforms {
        let res = base.film.full_resolution;
        let ndc_from_screen = Transform::scale(
            1.0 / (screen_window.p_max.x - screen_window.p_min.x),
            1.0 / (screen_window.p_max.y - screen_window.p_min.y),
            1.0,
        ) * Transform::translate(Vector3f::new(
            -screen_window.p_min.x,
            -screen_window.p_max.y,
            0.0,
        ));
        let raster_from_ndc = Transform::scale(res.x as Float, -(res.y as Float), 1.0);
        let raster_from_screen = raster_from_ndc * ndc_from_screen;
        let screen_from_raster = raster_from_screen.inverse();
        let camera_from_raster = screen_from_camera.inverse() * screen_from_raster;
        ProjectiveTransforms {
            screen_from_camera,
            camera_from_raster,
            raster_from_screen,
            screen_from_raster,
        }
    }
}

/// Moves a camera-space ray's origin to a point on the thin lens and aims
/// it at where the original ray meets the plane of focus.
#[inline]
fn apply_thin_lens(ray: &mut Ray, lens_radius: Float, focal_distance: Float, u: Point2f) {
    let p_lens = sample_uniform_disk_concentric(u);
    let ft = focal_distance / ray.d.z;
    let p_focus = ray.at(ft);
    ray.o = Point3f::new(lens_radius * p_lens.x, lens_radius * p_lens.y, 0.0);
    ray.d = (p_focus - ray.o).normalize();
}

/// Parallel projection along +z (pbrt-v4 `OrthographicCamera`).
#[derive(Clone, Debug)]
pub struct OrthographicCamera {
    /// Shared camera state.
    pub base: CameraBase,
    /// Camera, screen and raster transformations.
    pub xf: ProjectiveTransforms,
    /// Radius of the thin lens (0: pinhole).
    pub lens_radius: Float,
    /// Distance to the plane in focus.
    pub focal_distance: Float,
    /// The screen window the raster maps to (kept to build the camera
    /// again elsewhere: [`super::Camera::placed`]).
    pub screen_window: Bounds2f,
    dx_camera: Vector3f,
    dy_camera: Vector3f,
}

impl OrthographicCamera {
    /// An orthographic camera looking through `screen_window`.
    pub fn new(
        mut base: CameraBase,
        screen_window: Bounds2f,
        lens_radius: Float,
        focal_distance: Float,
    ) -> Result<Self, TransformError> {
        let xf =
            ProjectiveTransforms::new(Transform::orthographic(0.0, 1.0)?, screen_window, &base);
        let dx_camera = xf
            .camera_from_raster
            .apply_vector(Vector3f::new(1.0, 0.0, 0.0));
        let dy_camera = xf
            .camera_from_raster
            .apply_vector(Vector3f::new(0.0, 1.0, 0.0));
        base.min_dir_differential_x = Vector3f::default();
        base.min_dir_differential_y = Vector3f::default();
        base.min_pos_differential_x = dx_camera;
        base.min_pos_differential_y = dy_camera;
        Ok(OrthographicCamera {
            base,
            xf,
            lens_radius,
            focal_distance,
            screen_window,
            dx_camera,
            dy_camera,
        })
    }

    #[inline]
    fn camera_ray(&self, sample: &CameraSample) -> (Ray, Point3f) {
        let p_camera = self.xf.camera_from_raster.apply_point(Point3f::new(
            sample.p_film.x,
            sample.p_film.y,
            0.0,
        ));
        let mut ray = Ray::with_time(
            p_camera,
            Vector3f::new(0.0, 0.0, 1.0),
            self.base.sample_time(sample.time),
            self.base.medium,
        );
        if self.lens_radius > 0.0 {
            apply_thin_lens(
                &mut ray,
                self.lens_radius,
                self.focal_distance,
                sample.p_lens,
            );
        }
        (ray, p_camera)
    }

    /// The ray through a film sample.
    #[inline]
    pub fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let (ray, _) = self.camera_ray(sample);
        Some(CameraRay {
            ray: self.base.render_from_camera_ray(&ray),
            weight: 1.0,
        })
    }

    /// The ray through a film sample with its one-pixel neighbours.
    pub fn generate_ray_differential(
        &self,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        let (ray, p_camera) = self.camera_ray(sample);
        let mut rd = RayDifferential::new(ray);
        if self.lens_radius > 0.0 {
            let p_lens = sample_uniform_disk_concentric(sample.p_lens);
            let o = Point3f::new(
                self.lens_radius * p_lens.x,
                self.lens_radius * p_lens.y,
                0.0,
            );
            let ft = self.focal_distance; // the unperturbed direction is +z
            let z = Vector3f::new(0.0, 0.0, ft);
            rd.rx_origin = o;
            rd.rx_direction = (p_camera + self.dx_camera + z - o).normalize();
            rd.ry_origin = o;
            rd.ry_direction = (p_camera + self.dy_camera + z - o).normalize();
        } else {
            rd.rx_origin = ray.o + self.dx_camera;
            rd.ry_origin = ray.o + self.dy_camera;
            rd.rx_direction = ray.d;
            rd.ry_direction = ray.d;
        }
        rd.has_differentials = true;
        Some(CameraRayDifferential {
            ray: self.base.render_from_camera_ray_differential(&rd),
            weight: 1.0,
        })
    }
}

/// Perspective projection from a pinhole or thin lens (pbrt-v4
/// `PerspectiveCamera`).
#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    /// Shared camera state.
    pub base: CameraBase,
    /// Camera, screen and raster transformations.
    pub xf: ProjectiveTransforms,
    /// Radius of the thin lens (0: pinhole).
    pub lens_radius: Float,
    /// Distance to the plane in focus.
    pub focal_distance: Float,
    /// The field of view in degrees across the screen window's [−1, 1]
    /// extent, and the window (kept to build the camera again elsewhere:
    /// [`super::Camera::placed`]).
    pub fov: Float,
    /// The screen window the raster maps to.
    pub screen_window: Bounds2f,
    /// Area of the image rectangle on the plane z = 1 (for importance).
    pub image_plane_area: Float,
    /// Cosine of the angle between the viewing direction and the film's
    /// corner grown by the filter radius: directions further off axis
    /// carry no importance (pbrt-v4 `cosTotalWidth`).
    pub cos_total_width: Float,
    /// The camera-space offsets of one raster pixel along x and y (the
    /// ray differentials' film offsets).
    pub(crate) dx_camera: Vector3f,
    pub(crate) dy_camera: Vector3f,
}

impl PerspectiveCamera {
    /// A perspective camera with field of view `fov` degrees across the
    /// screen window's [−1, 1] extent (pbrt's near 1e-2, far 1000).
    pub fn new(
        mut base: CameraBase,
        fov: Float,
        screen_window: Bounds2f,
        lens_radius: Float,
        focal_distance: Float,
    ) -> Result<Self, TransformError> {
        let xf = ProjectiveTransforms::new(
            Transform::perspective(fov, 1e-2, 1000.0)?,
            screen_window,
            &base,
        );
        let c = &xf.camera_from_raster;
        let origin = c.apply_point(Point3f::new(0.0, 0.0, 0.0));
        let dx_camera = c.apply_point(Point3f::new(1.0, 0.0, 0.0)) - origin;
        let dy_camera = c.apply_point(Point3f::new(0.0, 1.0, 0.0)) - origin;
        let res = base.film.full_resolution;
        let p_min = origin / origin.z;
        let p_max = c.apply_point(Point3f::new(res.x as Float, res.y as Float, 0.0));
        let p_max = p_max / p_max.z;
        let image_plane_area = ((p_max.x - p_min.x) * (p_max.y - p_min.y)).abs();
        let mut cam = PerspectiveCamera {
            base: base.clone(),
            xf,
            lens_radius,
            focal_distance,
            fov,
            screen_window,
            image_plane_area,
            cos_total_width: 0.0,
            dx_camera,
            dy_camera,
        };
        base.find_minimum_differentials(|b, s| cam.differential_with_base(b, s));
        cam.base = base;
        cam.set_filter_radius(cam.base.filter_radius);
        Ok(cam)
    }

    /// Records the film filter's radius and the importance cone it
    /// implies: the direction through raster (−r.x, −r.y), one corner of
    /// the film grown by the radius, as pbrt-v4 computes it.
    pub fn set_filter_radius(&mut self, radius: Vector2f) {
        self.base.filter_radius = radius;
        let corner = self
            .xf
            .camera_from_raster
            .apply_point(Point3f::new(-radius.x, -radius.y, 0.0));
        self.cos_total_width = Vector3f::from(corner).try_normalize().map_or(1.0, |w| w.z);
    }

    /// The lens area, 1 for a pinhole (as pbrt-v4, so that importance and
    /// densities keep their units).
    #[inline]
    fn lens_area(&self) -> Float {
        if self.lens_radius != 0.0 {
            PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// For a ray leaving the lens: the cosine of its angle to the viewing
    /// direction and the raster point it comes from (through the plane of
    /// focus); `None` when outside the importance cone.
    fn raster_of(&self, ray: &Ray) -> Option<(Float, Point2f)> {
        let render_from_camera = self
            .base
            .camera_transform
            .render_from_camera
            .interpolate(ray.time);
        let view = render_from_camera
            .apply_vector(Vector3f::new(0.0, 0.0, 1.0))
            .try_normalize()?;
        let d = ray.d.try_normalize()?;
        let cos_theta = dot(d, view);
        if cos_theta <= self.cos_total_width {
            return None;
        }
        let dist = if self.lens_radius > 0.0 {
            self.focal_distance
        } else {
            1.0
        };
        let p_focus = ray.o + d * (dist / cos_theta);
        let p_camera = render_from_camera.apply_inverse_point(p_focus);
        let p_raster = self.xf.camera_from_raster.apply_inverse_point(p_camera);
        Some((cos_theta, Point2f::new(p_raster.x, p_raster.y)))
    }

    /// pbrt-v4 `We`: 1/(A · lens area · cos⁴θ) for rays that land inside
    /// the film's sample bounds, with the raster point they land on.
    pub fn we(&self, ray: &Ray, _lambda: &SampledWavelengths) -> (SampledSpectrum, Point2f) {
        let Some((cos_theta, p_raster)) = self.raster_of(ray) else {
            return (SampledSpectrum::new(0.0), Point2f::new(0.0, 0.0));
        };
        if !self.base.film_sample_bounds().inside(p_raster) {
            return (SampledSpectrum::new(0.0), p_raster);
        }
        let cos2 = cos_theta * cos_theta;
        let we = 1.0 / (self.image_plane_area * self.lens_area() * cos2 * cos2);
        (SampledSpectrum::new(we), p_raster)
    }

    /// pbrt-v4 `PDF_We`: (1/lens area, 1/(A cos³θ)) for rays that land
    /// inside the film's sample bounds, zeros otherwise.
    pub fn pdf_we(&self, ray: &Ray) -> (Float, Float) {
        let Some((cos_theta, p_raster)) = self.raster_of(ray) else {
            return (0.0, 0.0);
        };
        if !self.base.film_sample_bounds().inside(p_raster) {
            return (0.0, 0.0);
        }
        (
            1.0 / self.lens_area(),
            1.0 / (self.image_plane_area * cos_theta * cos_theta * cos_theta),
        )
    }

    /// pbrt-v4 `SampleWi`: a point sampled uniformly on the lens (the
    /// pinhole itself without one), the direction to it from `p_ref`, its
    /// solid-angle density there and the importance of the ray from the
    /// lens point back to `p_ref`.
    pub fn sample_wi(
        &self,
        p_ref: Point3f,
        time: Float,
        u: Point2f,
        lambda: &SampledWavelengths,
    ) -> Option<CameraWiSample> {
        let render_from_camera = self
            .base
            .camera_transform
            .render_from_camera
            .interpolate(time);
        let pl = sample_uniform_disk_concentric(u);
        let p_lens = render_from_camera.apply_point(Point3f::new(
            self.lens_radius * pl.x,
            self.lens_radius * pl.y,
            0.0,
        ));
        let n_lens = Normal3f::from(
            render_from_camera
                .apply_vector(Vector3f::new(0.0, 0.0, 1.0))
                .try_normalize()?,
        );
        let to_lens = p_lens - p_ref;
        let dist = to_lens.length();
        if dist == 0.0 || !dist.is_finite() {
            return None;
        }
        let wi = to_lens / dist;
        let pdf = dist * dist / (abs_dot(n_lens, wi) * self.lens_area());
        // The lens point has no rounding error: the ray leaves it exactly.
        let ray = Ray::with_time(p_lens, -wi, time, self.base.medium);
        let (wi_importance, p_raster) = self.we(&ray, lambda);
        if wi_importance.is_black() || !pdf.is_finite() {
            return None;
        }
        Some(CameraWiSample {
            wi_importance,
            wi,
            pdf,
            p_raster,
            p_lens,
            n_lens,
        })
    }

    #[inline]
    fn camera_ray(&self, base: &CameraBase, sample: &CameraSample) -> (Ray, Point3f) {
        let p_camera = self.xf.camera_from_raster.apply_point(Point3f::new(
            sample.p_film.x,
            sample.p_film.y,
            0.0,
        ));
        let mut ray = Ray::with_time(
            Point3f::new(0.0, 0.0, 0.0),
            Vector3f::from(p_camera).normalize(),
            base.sample_time(sample.time),
            base.medium,
        );
        if self.lens_radius > 0.0 {
            apply_thin_lens(
                &mut ray,
                self.lens_radius,
                self.focal_distance,
                sample.p_lens,
            );
        }
        (ray, p_camera)
    }

    /// The ray through a film sample.
    #[inline]
    pub fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let (ray, _) = self.camera_ray(&self.base, sample);
        Some(CameraRay {
            ray: self.base.render_from_camera_ray(&ray),
            weight: 1.0,
        })
    }

    /// The ray through a film sample with its one-pixel neighbours.
    #[inline]
    pub fn generate_ray_differential(
        &self,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        self.differential_with_base(&self.base, sample)
    }

    fn differential_with_base(
        &self,
        base: &CameraBase,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        let (ray, p_camera) = self.camera_ray(base, sample);
        let mut rd = RayDifferential::new(ray);
        let pc = Vector3f::from(p_camera);
        if self.lens_radius > 0.0 {
            let p_lens = sample_uniform_disk_concentric(sample.p_lens);
            let o = Point3f::new(
                self.lens_radius * p_lens.x,
                self.lens_radius * p_lens.y,
                0.0,
            );
            let focus = |d: Vector3f| {
                let d = d.normalize();
                Point3f::from(d * (self.focal_distance / d.z))
            };
            rd.rx_origin = o;
            rd.rx_direction = (focus(pc + self.dx_camera) - o).normalize();
            rd.ry_origin = o;
            rd.ry_direction = (focus(pc + self.dy_camera) - o).normalize();
        } else {
            rd.rx_origin = ray.o;
            rd.ry_origin = ray.o;
            rd.rx_direction = (pc + self.dx_camera).normalize();
            rd.ry_direction = (pc + self.dy_camera).normalize();
        }
        rd.has_differentials = true;
        Some(CameraRayDifferential {
            ray: base.render_from_camera_ray_differential(&rd),
            weight: 1.0,
        })
    }
}
