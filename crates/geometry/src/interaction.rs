//! Surface interactions (book section 4.1.4 / pbrt-v4 `interaction.h`):
//! the local differential geometry at a ray–surface hit, with error bounds
//! on the point, the shading frame, screen-space differentials and robust
//! ray spawning.

use crate::float::*;
use crate::ray::{offset_ray_origin, Ray, RayDifferential};
use crate::transform::Transform;
use crate::tuple::*;

/// The shading geometry, possibly perturbed by interpolated normals, bump
/// or normal maps. Always on the same side as the geometric normal unless
/// the shading normal is declared authoritative.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadingGeometry {
    /// Shading normal.
    pub n: Normal3f,
    /// Shading ∂p/∂u.
    pub dpdu: Vector3f,
    /// Shading ∂p/∂v.
    pub dpdv: Vector3f,
    /// Shading ∂n/∂u.
    pub dndu: Normal3f,
    /// Shading ∂n/∂v.
    pub dndv: Normal3f,
}

/// The geometry of a ray's hit on a surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceInteraction {
    /// The hit point with its rounding-error intervals.
    pub pi: Point3fi,
    /// Time of the hit.
    pub time: Float,
    /// Direction toward the ray's origin (negated ray direction, normalized).
    pub wo: Vector3f,
    /// Geometric normal.
    pub n: Normal3f,
    /// Surface parameterization coordinates.
    pub uv: Point2f,
    /// ∂p/∂u.
    pub dpdu: Vector3f,
    /// ∂p/∂v.
    pub dpdv: Vector3f,
    /// ∂n/∂u.
    pub dndu: Normal3f,
    /// ∂n/∂v.
    pub dndv: Normal3f,
    /// Shading geometry.
    pub shading: ShadingGeometry,
    /// Face index of the hit primitive (for ptex), 0 by default.
    pub face_index: i32,
    /// Screen-space change of p per pixel in x.
    pub dpdx: Vector3f,
    /// Screen-space change of p per pixel in y.
    pub dpdy: Vector3f,
    /// ∂u/∂x.
    pub dudx: Float,
    /// ∂v/∂x.
    pub dvdx: Float,
    /// ∂u/∂y.
    pub dudy: Float,
    /// ∂v/∂y.
    pub dvdy: Float,
}

/// What a camera knows to approximate screen-space differentials at points
/// reached by rays without differentials (pbrt-v4's
/// `CameraBase::Approximate_dp_dxy`): the smallest change of camera-ray
/// origin and direction per pixel over the image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraDifferentials {
    /// Camera-from-render transformation.
    pub camera_from_render: Transform,
    /// Minimum per-pixel origin change in x (camera space).
    pub min_pos_differential_x: Vector3f,
    /// Minimum per-pixel origin change in y (camera space).
    pub min_pos_differential_y: Vector3f,
    /// Minimum per-pixel direction change in x (camera space).
    pub min_dir_differential_x: Vector3f,
    /// Minimum per-pixel direction change in y (camera space).
    pub min_dir_differential_y: Vector3f,
}

impl CameraDifferentials {
    /// Approximates (∂p/∂x, ∂p/∂y) at `p` with normal `n` as if a camera ray
    /// with the minimum differentials had hit the tangent plane there;
    /// `spp_scale` shrinks them with the sample count.
    pub fn approximate_dp_dxy(
        &self,
        p: Point3f,
        n: Normal3f,
        spp_scale: Float,
    ) -> (Vector3f, Vector3f) {
        let p_camera = self.camera_from_render.apply_point(p);
        let dir = match Vector3f::from(p_camera).try_normalize() {
            Some(d) => d,
            None => return (Vector3f::default(), Vector3f::default()),
        };
        let down_z = Transform::rotate_from_to(dir, Vector3f::new(0.0, 0.0, 1.0));
        let p_down_z = down_z.apply_point(p_camera);
        let n_down_z = down_z.apply_normal(self.camera_from_render.apply_normal(n));
        let d = n_down_z.z * p_down_z.z;
        let hit = |o: Vector3f, dd: Vector3f| -> Point3f {
            let dir = Vector3f::new(0.0, 0.0, 1.0) + dd;
            let t = -(dot(n_down_z, o) - d) / dot(n_down_z, dir);
            Point3f::from(o) + dir * t
        };
        let px = hit(self.min_pos_differential_x, self.min_dir_differential_x);
        let py = hit(self.min_pos_differential_y, self.min_dir_differential_y);
        let render_from_camera = self.camera_from_render.inverse();
        let dpdx =
            render_from_camera.apply_vector(down_z.apply_inverse_vector(px - p_down_z)) * spp_scale;
        let dpdy =
            render_from_camera.apply_vector(down_z.apply_inverse_vector(py - p_down_z)) * spp_scale;
        let fin = |v: Vector3f| {
            if v.is_finite() {
                v
            } else {
                Vector3f::default()
            }
        };
        (fin(dpdx), fin(dpdy))
    }
}

impl SurfaceInteraction {
    /// Builds an interaction from the parametric derivatives of the surface.
    /// The geometric normal is `dpdu × dpdv`, flipped when `flip_normal`
    /// (reverse orientation XOR a handedness-swapping transformation).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        pi: Point3fi,
        uv: Point2f,
        wo: Vector3f,
        dpdu: Vector3f,
        dpdv: Vector3f,
        dndu: Normal3f,
        dndv: Normal3f,
        time: Float,
        flip_normal: bool,
    ) -> Self {
        let mut n = Normal3f::from(cross(dpdu, dpdv).try_normalize().unwrap_or_default());
        if flip_normal {
            n = -n;
        }
        SurfaceInteraction {
            pi,
            time,
            wo,
            n,
            uv,
            dpdu,
            dpdv,
            dndu,
            dndv,
            shading: ShadingGeometry {
                n,
                dpdu,
                dpdv,
                dndu,
                dndv,
            },
            ..Default::default()
        }
    }

    /// The hit point (midpoint of its error intervals).
    #[inline]
    pub fn p(&self) -> Point3f {
        self.pi.midpoint()
    }

    /// The absolute error bound of the hit point.
    #[inline]
    pub fn p_error(&self) -> Vector3f {
        self.pi.error()
    }

    /// Sets the shading geometry. When `orientation_is_authoritative` the
    /// geometric normal is flipped to the shading normal's side; otherwise
    /// the shading normal follows the geometric one.
    pub fn set_shading_geometry(
        &mut self,
        ns: Normal3f,
        dpdus: Vector3f,
        dpdvs: Vector3f,
        dndus: Normal3f,
        dndvs: Normal3f,
        orientation_is_authoritative: bool,
    ) {
        self.shading.n = ns;
        if orientation_is_authoritative {
            self.n = self.n.face_forward(self.shading.n);
        } else {
            self.shading.n = self.shading.n.face_forward(self.n);
        }
        self.shading.dpdu = dpdus;
        self.shading.dpdv = dpdvs;
        self.shading.dndu = dndus;
        self.shading.dndv = dndvs;
        while self.shading.dpdu.length_squared() > 1e16 || self.shading.dpdv.length_squared() > 1e16
        {
            self.shading.dpdu /= 1e8;
            self.shading.dpdv /= 1e8;
        }
    }

    /// Estimates the screen-space derivatives of p, u and v, from the ray's
    /// differentials where it has them and otherwise from the camera's
    /// approximation. `disable` zeroes them (`--disable-texture-filtering`).
    pub fn compute_differentials(
        &mut self,
        ray: &RayDifferential,
        camera: Option<&CameraDifferentials>,
        spp_scale: Float,
        disable: bool,
    ) {
        if disable {
            self.dpdx = Vector3f::default();
            self.dpdy = Vector3f::default();
            self.dudx = 0.0;
            self.dvdx = 0.0;
            self.dudy = 0.0;
            self.dvdy = 0.0;
            return;
        }
        let n = self.n;
        let p = self.p();
        if ray.has_differentials
            && dot(n, ray.rx_direction) != 0.0
            && dot(n, ray.ry_direction) != 0.0
        {
            let d = -dot(n, Vector3f::from(p));
            let tx = (-dot(n, Vector3f::from(ray.rx_origin)) - d) / dot(n, ray.rx_direction);
            let px = ray.rx_origin + ray.rx_direction * tx;
            let ty = (-dot(n, Vector3f::from(ray.ry_origin)) - d) / dot(n, ray.ry_direction);
            let py = ray.ry_origin + ray.ry_direction * ty;
            self.dpdx = px - p;
            self.dpdy = py - p;
        } else if let Some(c) = camera {
            let (dx, dy) = c.approximate_dp_dxy(p, n, spp_scale);
            self.dpdx = dx;
            self.dpdy = dy;
        } else {
            self.dpdx = Vector3f::default();
            self.dpdy = Vector3f::default();
        }
        let fin = |v: Vector3f| {
            if v.is_finite() {
                v
            } else {
                Vector3f::default()
            }
        };
        self.dpdx = fin(self.dpdx);
        self.dpdy = fin(self.dpdy);
        // Least-squares solve of dp = dpdu du + dpdv dv.
        let ata00 = dot(self.dpdu, self.dpdu);
        let ata01 = dot(self.dpdu, self.dpdv);
        let ata11 = dot(self.dpdv, self.dpdv);
        let mut inv_det = 1.0 / difference_of_products(ata00, ata11, ata01, ata01);
        if !inv_det.is_finite() {
            inv_det = 0.0;
        }
        let atb0x = dot(self.dpdu, self.dpdx);
        let atb1x = dot(self.dpdv, self.dpdx);
        let atb0y = dot(self.dpdu, self.dpdy);
        let atb1y = dot(self.dpdv, self.dpdy);
        let clampf = |v: Float| {
            if v.is_finite() {
                clamp(v, -1e8, 1e8)
            } else {
                0.0
            }
        };
        self.dudx = clampf(difference_of_products(ata11, atb0x, ata01, atb1x) * inv_det);
        self.dvdx = clampf(difference_of_products(ata00, atb1x, ata01, atb0x) * inv_det);
        self.dudy = clampf(difference_of_products(ata11, atb0y, ata01, atb1y) * inv_det);
        self.dvdy = clampf(difference_of_products(ata00, atb1y, ata01, atb0y) * inv_det);
    }

    /// The origin for a ray leaving toward `w`, offset off the surface.
    #[inline]
    pub fn offset_ray_origin(&self, w: Vector3f) -> Point3f {
        offset_ray_origin(self.p(), self.p_error(), self.n, w)
    }

    /// A ray leaving the surface toward `d` that cannot hit it again.
    #[inline]
    pub fn spawn_ray(&self, d: Vector3f) -> Ray {
        Ray::with_time(self.offset_ray_origin(d), d, self.time, None)
    }

    /// A ray from the surface to `p`; `t = 1` reaches `p`.
    #[inline]
    pub fn spawn_ray_to(&self, p: Point3f) -> Ray {
        crate::ray::spawn_ray_to(self.p(), self.p_error(), self.n, self.time, p)
    }

    /// Transforms the interaction, carrying the point's error bounds and
    /// keeping the shading normal on the geometric normal's side.
    pub fn transform(&self, t: &Transform) -> SurfaceInteraction {
        let mut r = *self;
        r.pi = t.apply_point_fi(self.pi);
        r.n = t.apply_normal(self.n).try_normalize().unwrap_or(self.n);
        r.wo = t.apply_vector(self.wo).try_normalize().unwrap_or_default();
        r.dpdu = t.apply_vector(self.dpdu);
        r.dpdv = t.apply_vector(self.dpdv);
        r.dndu = t.apply_normal(self.dndu);
        r.dndv = t.apply_normal(self.dndv);
        r.shading.n = t
            .apply_normal(self.shading.n)
            .try_normalize()
            .unwrap_or(r.n)
            .face_forward(r.n);
        r.shading.dpdu = t.apply_vector(self.shading.dpdu);
        r.shading.dpdv = t.apply_vector(self.shading.dpdv);
        r.shading.dndu = t.apply_normal(self.shading.dndu);
        r.shading.dndv = t.apply_normal(self.shading.dndv);
        r.dpdx = t.apply_vector(self.dpdx);
        r.dpdy = t.apply_vector(self.dpdy);
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane_hit() -> SurfaceInteraction {
        // The plane z = 0 parameterized by (u, v) = (x, y).
        SurfaceInteraction::new(
            Point3fi::from(Point3f::new(0.5, 0.25, 0.0)),
            Point2f::new(0.5, 0.25),
            Vector3f::new(0.0, 0.0, 1.0),
            Vector3f::new(1.0, 0.0, 0.0),
            Vector3f::new(0.0, 1.0, 0.0),
            Normal3f::default(),
            Normal3f::default(),
            0.0,
            false,
        )
    }

    #[test]
    fn normal_from_partials() {
        let si = plane_hit();
        assert_eq!(si.n, Normal3f::new(0.0, 0.0, 1.0));
        let mut flipped = plane_hit();
        flipped = SurfaceInteraction::new(
            flipped.pi,
            flipped.uv,
            flipped.wo,
            flipped.dpdu,
            flipped.dpdv,
            flipped.dndu,
            flipped.dndv,
            0.0,
            true,
        );
        assert_eq!(flipped.n, Normal3f::new(0.0, 0.0, -1.0));
        assert_eq!(flipped.shading.n, flipped.n);
    }

    #[test]
    fn shading_normal_follows_geometry() {
        let mut si = plane_hit();
        si.set_shading_geometry(
            Normal3f::new(0.0, 0.0, -1.0),
            si.dpdu,
            si.dpdv,
            Normal3f::default(),
            Normal3f::default(),
            false,
        );
        assert_eq!(si.shading.n, Normal3f::new(0.0, 0.0, 1.0));
        let mut si = plane_hit();
        si.set_shading_geometry(
            Normal3f::new(0.0, 0.0, -1.0),
            si.dpdu,
            si.dpdv,
            Normal3f::default(),
            Normal3f::default(),
            true,
        );
        assert_eq!(si.n, Normal3f::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn differentials_from_ray() {
        let mut si = plane_hit();
        let mut rd = RayDifferential::new(Ray::new(
            Point3f::new(0.5, 0.25, 1.0),
            Vector3f::new(0.0, 0.0, -1.0),
        ));
        rd.has_differentials = true;
        rd.rx_origin = Point3f::new(0.6, 0.25, 1.0);
        rd.ry_origin = Point3f::new(0.5, 0.45, 1.0);
        rd.rx_direction = rd.ray.d;
        rd.ry_direction = rd.ray.d;
        si.compute_differentials(&rd, None, 1.0, false);
        assert!((si.dudx - 0.1).abs() < 1e-5 && si.dvdx.abs() < 1e-5);
        assert!((si.dvdy - 0.2).abs() < 1e-5 && si.dudy.abs() < 1e-5);
        si.compute_differentials(&rd, None, 1.0, true);
        assert_eq!(si.dudx, 0.0);
    }

    #[test]
    fn camera_approximation() {
        // A camera at z = 1 looking down -z toward the plane: per-pixel
        // origin offsets of 0.1 (orthographic-like) map to 0.1 in the plane.
        let camera_from_render = Transform::look_at(
            Point3f::new(0.5, 0.25, 1.0),
            Point3f::new(0.5, 0.25, 0.0),
            Vector3f::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        let cam = CameraDifferentials {
            camera_from_render,
            min_pos_differential_x: Vector3f::new(0.1, 0.0, 0.0),
            min_pos_differential_y: Vector3f::new(0.0, 0.1, 0.0),
            min_dir_differential_x: Vector3f::default(),
            min_dir_differential_y: Vector3f::default(),
        };
        let mut si = plane_hit();
        si.compute_differentials(&RayDifferential::default(), Some(&cam), 1.0, false);
        assert!((si.dpdx.length() - 0.1).abs() < 1e-4, "{:?}", si.dpdx);
        assert!((si.dpdy.length() - 0.1).abs() < 1e-4);
    }

    #[test]
    fn spawned_rays_leave_the_surface() {
        let mut si = plane_hit();
        si.pi = Point3fi::from_value_and_error(si.p(), Vector3f::new(1e-5, 1e-5, 1e-5));
        let r = si.spawn_ray(Vector3f::new(0.3, 0.0, 1.0));
        assert!(r.o.z > 0.0);
        let r = si.spawn_ray(Vector3f::new(0.3, 0.0, -1.0));
        assert!(r.o.z < 0.0);
        let r = si.spawn_ray_to(Point3f::new(0.0, 0.0, 5.0));
        assert!((r.at(1.0) - Point3f::new(0.0, 0.0, 5.0)).length() < 1e-5);
    }

    #[test]
    fn transform_keeps_shading_side() {
        let si = plane_hit();
        let t = Transform::scale(1.0, 1.0, -1.0);
        let ts = si.transform(&t);
        assert!(dot(ts.n, ts.shading.n) > 0.0);
        assert_eq!(ts.p(), Point3f::new(0.5, 0.25, 0.0));
    }
}
