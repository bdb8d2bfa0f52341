//! Camera rays many at a time: the common camera (a pinhole perspective
//! camera whose transform does not move during the shutter) generating
//! the rays of a batch of film points lane-parallel, at the SIMD level's
//! width, with or without their differentials.
//!
//! Each lane performs the scalar code's operations in its order (no fused
//! multiply-adds: Rust does not contract them), so the rays are those of
//! [`PerspectiveCamera::generate_ray`](super::PerspectiveCamera::generate_ray)
//! and [`PerspectiveCamera::generate_ray_differential`](super::PerspectiveCamera::generate_ray_differential)
//! bit for bit, at every width.

use super::Camera;
use crate::simd::{self, F32Lanes, Kernel, SimdLevel, MAX_LANES};
use rpbrt_geometry::pointfi::Point3fi;
use rpbrt_geometry::ray::RayDifferential;
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
    /// The camera-space origin taken to render space as a point (the
    /// offset rays' origin, before scaling), and one raster pixel's
    /// camera-space offsets along x and y.
    origin_point: Point3f,
    dx_camera: Vector3f,
    dy_camera: Vector3f,
}

/// The offset rays [`PinholeRays::rays`] gives its rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OffsetRays {
    /// None (nothing reads them).
    None,
    /// One pixel's offsets, as the camera makes them.
    Unscaled,
    /// Those offsets scaled by this factor toward the main ray
    /// (`RayDifferential::scale_differentials`).
    Scaled(Float),
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
        let render = &rfc.start_transform();
        let o = render.apply_point_fi(Point3fi::from(Point3f::new(0.0, 0.0, 0.0)));
        Some(PinholeRays {
            raster: c.xf.camera_from_raster.matrix().m,
            render: render.matrix().m,
            origin: o.midpoint(),
            origin_error: o.error(),
            medium: c.base.medium,
            origin_point: render.apply_point(Point3f::new(0.0, 0.0, 0.0)),
            dx_camera: c.dx_camera,
            dy_camera: c.dy_camera,
        })
    }
}

impl PinholeRays {
    /// The rays through raster points `p_film` at times `times` (as
    /// long), with the offset rays `offsets` asks for, appended to `out`:
    /// [`Camera::generate_ray`]'s rays (without offset rays) or
    /// [`Camera::generate_ray_differential`]'s (then scaled as asked),
    /// computed [`SimdLevel::lanes`] at a time at `level`.
    pub fn rays(
        &self,
        level: SimdLevel,
        p_film: &[Point2f],
        times: &[Float],
        offsets: OffsetRays,
        out: &mut Vec<RayDifferential>,
    ) {
        debug_assert_eq!(p_film.len(), times.len());
        simd::dispatch(
            level,
            RaysKernel {
                cam: self,
                p_film,
                times,
                offsets,
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
    offsets: OffsetRays,
    out: &'a mut Vec<RayDifferential>,
}

/// `v` normalized as `Vector3f::normalize` does it (each component
/// divided by the length).
#[inline(always)]
fn normalize<L: F32Lanes>(v: [L; 3]) -> [L; 3] {
    let len = v[0]
        .mul(v[0])
        .add(v[1].mul(v[1]))
        .add(v[2].mul(v[2]))
        .sqrt();
    [v[0].div(len), v[1].div(len), v[2].div(len)]
}

/// `p + o`, component by component.
#[inline(always)]
fn plus<L: F32Lanes>(p: [L; 3], o: Vector3f) -> [L; 3] {
    [
        p[0].add(L::splat(o.x)),
        p[1].add(L::splat(o.y)),
        p[2].add(L::splat(o.z)),
    ]
}

/// `render_from_camera.apply_vector(v)`.
#[inline(always)]
fn to_render<L: F32Lanes>(r: &[[Float; 4]; 4], v: [L; 3]) -> [L; 3] {
    [
        row(&r[0], v[0], v[1], v[2]),
        row(&r[1], v[0], v[1], v[2]),
        row(&r[2], v[0], v[1], v[2]),
    ]
}

impl Kernel for RaysKernel<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let RaysKernel {
            cam,
            p_film,
            times,
            offsets,
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
            let dc = normalize(pc);
            // render_from_camera.apply_ray: the direction's image, and the
            // origin pushed past its error bound along it.
            let d = to_render(r, dc);
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
            let mut lanes = [[0.0; MAX_LANES]; 18];
            for (v, dst) in os.iter().chain(&d).zip(lanes.iter_mut()) {
                v.store(dst);
            }
            if offsets != OffsetRays::None {
                // The offset rays (`generate_ray_differential`): from the
                // camera-space origin, through the point one pixel over,
                // taken to render space (`apply_ray_differential`), then
                // scaled toward the main ray (`scale_differentials`).
                let op = cam.origin_point;
                let mut rx = [s(op.x), s(op.y), s(op.z)];
                let mut ry = rx;
                let mut dxr = to_render(r, normalize(plus(pc, cam.dx_camera)));
                let mut dyr = to_render(r, normalize(plus(pc, cam.dy_camera)));
                if let OffsetRays::Scaled(f) = offsets {
                    let f = s(f);
                    for a in 0..3 {
                        rx[a] = os[a].add(rx[a].sub(os[a]).mul(f));
                        ry[a] = os[a].add(ry[a].sub(os[a]).mul(f));
                        dxr[a] = d[a].add(dxr[a].sub(d[a]).mul(f));
                        dyr[a] = d[a].add(dyr[a].sub(d[a]).mul(f));
                    }
                }
                let rest = rx.iter().chain(&ry).chain(&dxr).chain(&dyr);
                for (v, dst) in rest.zip(lanes[6..].iter_mut()) {
                    v.store(dst);
                }
            }
            let has_differentials = offsets != OffsetRays::None;
            out.extend(times.iter().enumerate().map(|(k, &time)| {
                let p = |c: usize| Point3f::new(lanes[c][k], lanes[c + 1][k], lanes[c + 2][k]);
                let v = |c: usize| Vector3f::new(lanes[c][k], lanes[c + 1][k], lanes[c + 2][k]);
                let ray = Ray {
                    o: p(0),
                    d: v(3),
                    time,
                    medium: cam.medium,
                };
                if has_differentials {
                    RayDifferential {
                        ray,
                        has_differentials,
                        rx_origin: p(6),
                        ry_origin: p(9),
                        rx_direction: v(12),
                        ry_direction: v(15),
                    }
                } else {
                    RayDifferential::new(ray)
                }
            }));
        }
    }
}
