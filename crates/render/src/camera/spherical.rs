//! The spherical camera (book section 5.3; pbrt-v4 `SphericalCamera`):
//! rays in every direction from the camera's position, laid out on the
//! film by an equirectangular or an equal-area octahedral mapping.

use rpbrt_geometry::{equal_area_square_to_sphere, Float, Point2f, Point3f, Ray, Vector3f, PI};

use super::{differential_by_offset, CameraBase, CameraRay, CameraRayDifferential, CameraSample};

/// How film positions map to directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SphericalMapping {
    /// Longitude along x (φ = 2π u), colatitude along y (θ = π v).
    EquiRectangular,
    /// Clarberg's equal-area octahedral mapping; needs a square film.
    EqualArea,
}

/// A camera seeing the whole sphere of directions.
#[derive(Clone, Debug)]
pub struct SphericalCamera {
    /// Shared camera state.
    pub base: CameraBase,
    /// The film layout.
    pub mapping: SphericalMapping,
}

/// Folds a point outside [0,1]² back into the equal-area square the way
/// the octahedral layout continues across its edges.
#[inline]
fn wrap_equal_area_square(mut uv: Point2f) -> Point2f {
    if uv.x < 0.0 {
        uv.x = -uv.x;
        uv.y = 1.0 - uv.y;
    } else if uv.x > 1.0 {
        uv.x = 2.0 - uv.x;
        uv.y = 1.0 - uv.y;
    }
    if uv.y < 0.0 {
        uv.x = 1.0 - uv.x;
        uv.y = -uv.y;
    } else if uv.y > 1.0 {
        uv.x = 1.0 - uv.x;
        uv.y = 2.0 - uv.y;
    }
    uv
}

impl SphericalCamera {
    /// A spherical camera with the given film mapping.
    pub fn new(base: CameraBase, mapping: SphericalMapping) -> Self {
        let mut cam = SphericalCamera {
            base: base.clone(),
            mapping,
        };
        let mut base = base;
        base.find_minimum_differentials(|b, s| {
            differential_by_offset(s, |s| cam.ray_with_base(b, s))
        });
        cam.base = base;
        cam
    }

    /// The camera-space direction for film position `uv` in \[0,1\]²
    /// (y of the mapping swapped with z, so +y is up and the equator is
    /// the xz plane).
    pub fn direction(&self, uv: Point2f) -> Vector3f {
        let dir = match self.mapping {
            SphericalMapping::EquiRectangular => {
                let theta = PI * uv.y;
                let phi = 2.0 * PI * uv.x;
                let st = theta.sin();
                Vector3f::new(st * phi.cos(), st * phi.sin(), theta.cos())
            }
            SphericalMapping::EqualArea => equal_area_square_to_sphere(wrap_equal_area_square(uv)),
        };
        Vector3f::new(dir.x, dir.z, dir.y)
    }

    fn ray_with_base(&self, base: &CameraBase, sample: &CameraSample) -> Option<CameraRay> {
        let res = base.film.full_resolution;
        let uv = Point2f::new(
            sample.p_film.x / res.x as Float,
            sample.p_film.y / res.y as Float,
        );
        let ray = Ray::with_time(
            Point3f::new(0.0, 0.0, 0.0),
            self.direction(uv),
            base.sample_time(sample.time),
            base.medium,
        );
        Some(CameraRay {
            ray: base.render_from_camera_ray(&ray),
            weight: 1.0,
        })
    }

    /// The ray through a film sample.
    #[inline]
    pub fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        self.ray_with_base(&self.base, sample)
    }

    /// The ray with its neighbours, found by offsetting the film sample.
    pub fn generate_ray_differential(
        &self,
        sample: &CameraSample,
    ) -> Option<CameraRayDifferential> {
        differential_by_offset(sample, |s| self.generate_ray(s))
    }
}
