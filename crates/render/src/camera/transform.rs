//! Where the camera is, and the space rendering happens in (pbrt-v4
//! `CameraTransform` in `cameras.h/.cpp`, `RenderingCoordinateSystem` in
//! `options.h`; book section 5.1.1).

use rpbrt_geometry::{AnimatedTransform, Float, Point3f, Transform, Vector3f};

/// The space in which rendering computations happen (pbrt-v4
/// `RenderingCoordinateSystem`, `options.h`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RenderingCoordinateSystem {
    /// Camera space: the camera sits at the origin looking down +z.
    Camera,
    /// World space translated so that the camera is at the origin, with the
    /// world's orientation (pbrt-v4's default).
    #[default]
    CameraWorld,
    /// World space.
    World,
}

impl RenderingCoordinateSystem {
    /// Parses `camera`, `cameraworld` or `world`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "camera" => Some(Self::Camera),
            "cameraworld" => Some(Self::CameraWorld),
            "world" => Some(Self::World),
            _ => None,
        }
    }

    /// The name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Camera => "camera",
            Self::CameraWorld => "cameraworld",
            Self::World => "world",
        }
    }
}

/// The camera's placement (pbrt-v4 `CameraTransform`): where render space
/// is with respect to the world, and the camera with respect to it.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraTransform {
    /// From camera space to render space, over the shutter interval.
    pub render_from_camera: AnimatedTransform,
    /// From render space to world space.
    pub world_from_render: Transform,
}

impl Default for CameraTransform {
    fn default() -> Self {
        CameraTransform {
            render_from_camera: AnimatedTransform::fixed(Transform::identity()),
            world_from_render: Transform::identity(),
        }
    }
}

impl CameraTransform {
    /// Chooses render space for a camera placed by `world_from_camera`.
    /// The camera and camera-world choices use the camera's placement at
    /// the middle of the transformation times.
    pub fn new(world_from_camera: &AnimatedTransform, space: RenderingCoordinateSystem) -> Self {
        let t_mid = (world_from_camera.start_time + world_from_camera.end_time) / 2.0;
        let world_from_render = match space {
            RenderingCoordinateSystem::Camera => world_from_camera.interpolate(t_mid),
            RenderingCoordinateSystem::CameraWorld => {
                let p = world_from_camera.apply_point(Point3f::new(0.0, 0.0, 0.0), t_mid);
                Transform::translate(Vector3f::from(p))
            }
            RenderingCoordinateSystem::World => Transform::identity(),
        };
        let render_from_world = world_from_render.inverse();
        let render_from_camera = AnimatedTransform::new(
            render_from_world * world_from_camera.start_transform(),
            world_from_camera.start_time,
            render_from_world * world_from_camera.end_transform(),
            world_from_camera.end_time,
        );
        CameraTransform {
            render_from_camera,
            world_from_render,
        }
    }

    /// From world space to render space.
    pub fn render_from_world(&self) -> Transform {
        self.world_from_render.inverse()
    }

    /// From render space to camera space at `time`.
    pub fn camera_from_render(&self, time: Float) -> Transform {
        self.render_from_camera.interpolate(time).inverse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_world_render_space_is_translated_world() {
        let world_from_camera = Transform::translate(Vector3f::new(1.0, 2.0, 3.0))
            * Transform::rotate(30.0, Vector3f::new(0.0, 1.0, 0.0));
        let a = AnimatedTransform::fixed(world_from_camera);
        let ct = CameraTransform::new(&a, RenderingCoordinateSystem::CameraWorld);
        let p = ct
            .world_from_render
            .apply_point(Point3f::new(0.0, 0.0, 0.0));
        assert!((Vector3f::from(p) - Vector3f::new(1.0, 2.0, 3.0)).length() < 1e-5);
        let ct = CameraTransform::new(&a, RenderingCoordinateSystem::Camera);
        assert!(
            ct.render_from_camera.start_transform().is_identity()
                || ct
                    .render_from_camera
                    .start_transform()
                    .matrix()
                    .m
                    .iter()
                    .flatten()
                    .zip(Transform::identity().matrix().m.iter().flatten())
                    .all(|(a, b)| (a - b).abs() < 1e-5)
        );
        let ct = CameraTransform::new(&a, RenderingCoordinateSystem::World);
        assert!(ct.world_from_render.is_identity());
    }
}
