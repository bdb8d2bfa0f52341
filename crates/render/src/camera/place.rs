//! Moving a camera that exists (interactive rendering): the same camera,
//! placed elsewhere in the render space the scene was built in, with its
//! thin lens or field of view changed. pbrt-v4's interactive mode moves
//! the camera by a transformation applied to its rays; here the camera is
//! built again by its own constructor, so a camera placed by a `LookAt`
//! is, bit for bit, the camera a scene file with that `LookAt` gives when
//! render space does not depend on the camera (`rendercoordsys "world"`).

use rpbrt_geometry::{AnimatedTransform, Float};

use super::{
    Camera, CameraBase, CameraTransform, OrthographicCamera, PerspectiveCamera, SphericalCamera,
};

/// Lens settings to change when placing a camera; `None` keeps the
/// camera's own. Only the cameras that have the setting take it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LensChange {
    /// Perspective field of view in degrees (pbrt-v4 `fov`).
    pub fov: Option<Float>,
    /// Thin-lens radius (`lensradius`; 0: pinhole).
    pub lens_radius: Option<Float>,
    /// Distance to the plane in focus (`focaldistance`).
    pub focal_distance: Option<Float>,
}

/// A camera's current lens settings, as its scene parameters name them
/// (`None` where the camera has no such setting).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LensSettings {
    /// `fov` (perspective cameras).
    pub fov: Option<Float>,
    /// `lensradius` (perspective and orthographic cameras).
    pub lens_radius: Option<Float>,
    /// `focaldistance` (perspective and orthographic cameras).
    pub focal_distance: Option<Float>,
}

impl Camera {
    /// The scene-file name of the camera's type.
    pub fn type_name(&self) -> &'static str {
        match self {
            Camera::Perspective(_) => "perspective",
            Camera::Orthographic(_) => "orthographic",
            Camera::Spherical(_) => "spherical",
            Camera::Realistic(_) => "realistic",
        }
    }

    /// The lens settings a [`LensChange`] may change, as they are now.
    pub fn lens(&self) -> LensSettings {
        match self {
            Camera::Perspective(c) => LensSettings {
                fov: Some(c.fov),
                lens_radius: Some(c.lens_radius),
                focal_distance: Some(c.focal_distance),
            },
            Camera::Orthographic(c) => LensSettings {
                fov: None,
                lens_radius: Some(c.lens_radius),
                focal_distance: Some(c.focal_distance),
            },
            _ => LensSettings::default(),
        }
    }

    /// This camera placed by `world_from_camera` (over the same shutter)
    /// in the render space it was made for, with `lens` applied: built by
    /// the camera's constructor as a scene file would build it. Errors
    /// name a setting the camera does not have or cannot take.
    pub fn placed(
        &self,
        world_from_camera: &AnimatedTransform,
        lens: &LensChange,
    ) -> Result<Camera, String> {
        let old = self.base();
        let world_from_render = old.camera_transform.world_from_render;
        // As `CameraTransform::new` composes them.
        let render_from_world = world_from_render.inverse();
        let wfc = world_from_camera;
        let camera_transform = CameraTransform {
            render_from_camera: AnimatedTransform::new(
                render_from_world * wfc.start_transform(),
                wfc.start_time,
                render_from_world * wfc.end_transform(),
                wfc.end_time,
            ),
            world_from_render,
        };
        let base = CameraBase::new(
            camera_transform,
            old.shutter_open,
            old.shutter_close,
            old.film,
            old.medium,
        );
        let settings = self.lens();
        for (name, asked, has) in [
            ("fov", lens.fov, settings.fov),
            ("lensradius", lens.lens_radius, settings.lens_radius),
            (
                "focaldistance",
                lens.focal_distance,
                settings.focal_distance,
            ),
        ] {
            if asked.is_some() && has.is_none() {
                return Err(format!(
                    "the \"{}\" camera has no \"{name}\" setting",
                    self.type_name()
                ));
            }
        }
        if let Some(fov) = lens.fov {
            if !(fov > 0.0 && fov < 180.0) {
                return Err(format!(
                    "field of view {fov} must be between 0 and 180 degrees"
                ));
            }
        }
        if let Some(r) = lens.lens_radius {
            if !(r >= 0.0 && r.is_finite()) {
                return Err(format!("lens radius {r} must be finite and non-negative"));
            }
        }
        if let Some(d) = lens.focal_distance {
            if !(d > 0.0 && d.is_finite()) {
                return Err(format!("focal distance {d} must be positive"));
            }
        }
        let mut camera = match self {
            Camera::Perspective(c) => Camera::Perspective(
                PerspectiveCamera::new(
                    base,
                    lens.fov.unwrap_or(c.fov),
                    c.screen_window,
                    lens.lens_radius.unwrap_or(c.lens_radius),
                    lens.focal_distance.unwrap_or(c.focal_distance),
                )
                .map_err(|e| e.to_string())?,
            ),
            Camera::Orthographic(c) => Camera::Orthographic(
                OrthographicCamera::new(
                    base,
                    c.screen_window,
                    lens.lens_radius.unwrap_or(c.lens_radius),
                    lens.focal_distance.unwrap_or(c.focal_distance),
                )
                .map_err(|e| e.to_string())?,
            ),
            Camera::Spherical(c) => Camera::Spherical(SphericalCamera::new(base, c.mapping)),
            Camera::Realistic(c) => {
                // The lens system, focus and exit pupil are in camera space:
                // only the placement and what depends on it change.
                let mut cam = c.clone();
                cam.base = base;
                cam.refind_minimum_differentials();
                Camera::Realistic(cam)
            }
        };
        camera.set_filter_radius(old.filter_radius);
        Ok(camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{CameraSample, FilmGeometry, RenderingCoordinateSystem};
    use rpbrt_geometry::{Bounds2f, Point2f, Point3f, Transform, Vector3f};

    fn perspective(world_from_camera: Transform, space: RenderingCoordinateSystem) -> Camera {
        let ct = CameraTransform::new(&AnimatedTransform::fixed(world_from_camera), space);
        let base = CameraBase::new(ct, 0.0, 1.0, FilmGeometry::new(64, 48), None);
        let screen = Bounds2f::new(Point2f::new(-4.0 / 3.0, -1.0), Point2f::new(4.0 / 3.0, 1.0));
        Camera::Perspective(PerspectiveCamera::new(base, 45.0, screen, 0.0, 1e6).unwrap())
    }

    fn rays(c: &Camera) -> Vec<(Point3f, Vector3f)> {
        (0..20)
            .map(|i| {
                let s = CameraSample {
                    p_film: Point2f::new(3.1 * i as Float, 2.3 * i as Float),
                    ..CameraSample::default()
                };
                let r = c.generate_ray(&s).unwrap().ray;
                (r.o, r.d)
            })
            .collect()
    }

    fn look_at(eye: [Float; 3], look: [Float; 3]) -> Transform {
        Transform::look_at(
            Point3f::new(eye[0], eye[1], eye[2]),
            Point3f::new(look[0], look[1], look[2]),
            Vector3f::new(0.0, 1.0, 0.0),
        )
        .unwrap()
        .inverse()
    }

    #[test]
    fn placed_in_world_space_is_the_camera_a_scene_file_gives() {
        let world = RenderingCoordinateSystem::World;
        let a = look_at([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]);
        let b = look_at([-2.0, 0.5, 4.0], [1.0, 1.0, 0.0]);
        let moved = perspective(a, world)
            .placed(&AnimatedTransform::fixed(b), &LensChange::default())
            .unwrap();
        assert_eq!(rays(&moved), rays(&perspective(b, world)));
    }

    #[test]
    fn placed_keeps_render_space_and_changes_the_lens() {
        let cw = RenderingCoordinateSystem::CameraWorld;
        let a = look_at([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]);
        let b = look_at([-2.0, 0.5, 4.0], [1.0, 1.0, 0.0]);
        let c = perspective(a, cw);
        let moved = c
            .placed(
                &AnimatedTransform::fixed(b),
                &LensChange {
                    fov: Some(30.0),
                    ..LensChange::default()
                },
            )
            .unwrap();
        // Render space stays the first camera's: the new camera sits at its
        // world position minus the first one's.
        let o = moved.generate_ray(&CameraSample::default()).unwrap().ray.o;
        let want = Point3f::new(-3.0, -1.5, 1.0);
        assert!((o - want).length() < 1e-5, "{o:?}");
        assert_eq!(moved.lens().fov, Some(30.0));
        assert_eq!(
            moved.base().camera_transform.world_from_render,
            c.base().camera_transform.world_from_render
        );
        // Bad settings are refused.
        let bad = |l: LensChange| c.placed(&AnimatedTransform::fixed(b), &l).is_err();
        assert!(bad(LensChange {
            fov: Some(180.0),
            ..LensChange::default()
        }));
        assert!(bad(LensChange {
            lens_radius: Some(-1.0),
            ..LensChange::default()
        }));
        assert!(bad(LensChange {
            focal_distance: Some(Float::NAN),
            ..LensChange::default()
        }));
    }
}
