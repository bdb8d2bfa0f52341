//! Camera rays many at a time: the common camera (a pinhole perspective
//! camera whose transform does not move during the shutter) generating
//! the rays of a batch of film points lane-parallel, at the SIMD level's
//! width.
//!
//! Each lane performs the scalar code's operations in its order (no fused
//! multiply-adds: Rust does not contract them), so the rays are those of
//! [`PerspectiveCamera::generate_ray`](super::PerspectiveCamera::generate_ray)
//! bit for bit, at every width.

use super::Camera;
use crate::simd::{self, F32Lanes, Kernel, SimdLevel, MAX_LANES};
use rpbrt_geometry::pointfi::Point3fi;
use rpbrt_geometry::{Float, MediumId, Point2f, Point3f, Ray, Vector3f};

/// A pinhole perspective camera with a fixed render-from-camera
/// transform, in the form whose rays are generated lane-parallel.
#[derive(Clone, Debug)]
pub struct PinholeRays {
    /// Camera from raster (a projective matrix), by rows.
    raster: [[Float; 4]; 4],
    /// Render from camera, by rows (the linear part is what directions
    /// need).
    render: [[Float; 4]; 4],
    /// The camera-space origin taken to render space: its value and error
    /// bound, as [`Transform::apply_ray`](rpbrt_geometry::Transform::apply_ray)
    /// computes them (the same for every ray).
    origin: Point3f,
    origin_error: Vector3f,
    medium: Option<MediumId>,
}

impl Camera {
    /// The camera's lane-parallel form, when it has one: a pinhole
    /// perspective camera that does not move during the shutter.
    pub fn pinhole_rays(&self) -> Option<PinholeRays> {
        let Camera::Perspective(c) = self else {
            return None;
        };
        let rfc = &c.base.camera_transform.render_from_camera;
        if c.lens_radius > 0.0 || rfc.is_animated() {
            return None;
        }
        let render = &rfc.start_transform;
        let o = render.apply_point_fi(Point3fi::from(Point3f::new(0.0, 0.0, 0.0)));
        Some(PinholeRays {
            raster: c.xf.camera_from_raster.matrix().m,
            render: render.matrix().m,
            origin: o.midpoint(),
            origin_error: o.error(),
            medium: c.base.medium,
        })
    }
}

impl PinholeRays {
    /// The rays through raster points `p_film` at times `times` (as
    /// long), appended to `out`: [`Camera::generate_ray`]'s rays, computed
    /// [`SimdLevel::lanes`] at a time at `level`.
    pub fn rays(&self, level: SimdLevel, p_film: &[Point2f], times: &[Float], out: &mut Vec<Ray>) {
        debug_assert_eq!(p_film.len(), times.len());
        simd::dispatch(
            level,
            RaysKernel {
                cam: self,
                p_film,
                times,
                out,
            },
        );
    }
}

/// `m[0] x + m[1] y + m[2] z`, summed in that order. (A function, not a
/// closure: a closure is compiled without the kernel's instruction set,
/// and its lane operations become calls.)
#[inline(always)]
fn row<L: F32Lanes>(m: &[Float], x: L, y: L, z: L) -> L {
    L::splat(m[0])
        .mul(x)
        .add(L::splat(m[1]).mul(y))
        .add(L::splat(m[2]).mul(z))
}

struct RaysKernel<'a> {
    cam: &'a PinholeRays,
    p_film: &'a [Point2f],
    times: &'a [Float],
    out: &'a mut Vec<Ray>,
}

impl Kernel for RaysKernel<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let RaysKernel {
            cam,
            p_film,
            times,
            out,
        } = self;
        let n = L::N;
        let (m, r) = (&cam.raster, &cam.render);
        let s = L::splat;
        for (chunk, times) in p_film.chunks(n).zip(times.chunks(n)) {
            let mut xs = [0.0; MAX_LANES];
            let mut ys = [0.0; MAX_LANES];
            for (k, p) in chunk.iter().enumerate() {
                xs[k] = p.x;
                ys[k] = p.y;
            }
            let (x, y, z) = (L::load(&xs), L::load(&ys), s(0.0));
            // camera_from_raster.apply_point((x, y, 0)).
            let (xp, yp, zp, wp) = (
                row(&m[0], x, y, z).add(s(m[0][3])),
                row(&m[1], x, y, z).add(s(m[1][3])),
                row(&m[2], x, y, z).add(s(m[2][3])),
                row(&m[3], x, y, z).add(s(m[3][3])),
            );
            let affine = wp.eq(s(1.0));
            let pc = [
                L::select(affine, xp, xp.div(wp)),
                L::select(affine, yp, yp.div(wp)),
                L::select(affine, zp, zp.div(wp)),
            ];
            // The camera-space direction, normalized.
            let len = pc[0]
                .mul(pc[0])
                .add(pc[1].mul(pc[1]))
                .add(pc[2].mul(pc[2]))
                .sqrt();
            let dc = [pc[0].div(len), pc[1].div(len), pc[2].div(len)];
            // render_from_camera.apply_ray: the direction's image, and the
            // origin pushed past its error bound along it.
            let d = [
                row(&r[0], dc[0], dc[1], dc[2]),
                row(&r[1], dc[0], dc[1], dc[2]),
                row(&r[2], dc[0], dc[1], dc[2]),
            ];
            let len2 = d[0].mul(d[0]).add(d[1].mul(d[1])).add(d[2].mul(d[2]));
            let e = cam.origin_error;
            let dt = d[0]
                .abs()
                .mul(s(e.x))
                .add(d[1].abs().mul(s(e.y)))
                .add(d[2].abs().mul(s(e.z)))
                .div(len2);
            let offset = len2.gt(s(0.0));
            let o = cam.origin;
            let os = [
                L::select(offset, s(o.x).add(d[0].mul(dt)), s(o.x)),
                L::select(offset, s(o.y).add(d[1].mul(dt)), s(o.y)),
                L::select(offset, s(o.z).add(d[2].mul(dt)), s(o.z)),
            ];
            let mut lanes = [[0.0; MAX_LANES]; 6];
            for (v, dst) in os.iter().chain(&d).zip(lanes.iter_mut()) {
                v.store(dst);
            }
            out.extend(times.iter().enumerate().map(|(k, &time)| Ray {
                o: Point3f::new(lanes[0][k], lanes[1][k], lanes[2][k]),
                d: Vector3f::new(lanes[3][k], lanes[4][k], lanes[5][k]),
                time,
                medium: cam.medium,
            }));
        }
    }
}
