//! Embree 3 as a reference point for `benches/accel.rs` (cargo feature
//! `embree`; needs the system's `libembree3`, e.g. Debian's
//! `libembree-dev`).
//!
//! The `embree3` crate (0.4, for Embree 3.13) supplies the C declarations
//! and the link to `embree3`; its safe wrappers neither fix the build
//! thread count nor offer 8/16-wide packets, so this module calls
//! `embree3::sys` directly behind a small owner type. Embree intersects its own
//! triangles (its built-in triangle geometry, with its own SIMD triangle
//! tests), so its figures include triangle tests just as rpbrt's include
//! `intersect_triangle`.

use embree3::sys::*;
use rpbrt_geometry::{Float, Point3f, Ray};
use std::ffi::CString;
use std::time::Instant;

/// One packet query: fills the SoA ray struct (`valid` marks the lanes in
/// use), traces it, and counts hits.
macro_rules! packet {
    ($self:ident, $rays:ident, $n:literal, $rh:ident, $ray:ident, $hit:ident, $f:ident) => {{
        let mut rh = $rh {
            ray: $ray {
                org_x: [0.0; $n],
                org_y: [0.0; $n],
                org_z: [0.0; $n],
                tnear: [0.0; $n],
                dir_x: [0.0; $n],
                dir_y: [0.0; $n],
                dir_z: [1.0; $n],
                time: [0.0; $n],
                tfar: [Float::INFINITY; $n],
                mask: [u32::MAX; $n],
                id: [0; $n],
                flags: [0; $n],
            },
            hit: $hit {
                Ng_x: [0.0; $n],
                Ng_y: [0.0; $n],
                Ng_z: [0.0; $n],
                u: [0.0; $n],
                v: [0.0; $n],
                primID: [u32::MAX; $n],
                geomID: [u32::MAX; $n],
                instID: [[u32::MAX; $n]; 1],
            },
        };
        let mut valid = [0i32; $n];
        for (i, r) in $rays.iter().take($n).enumerate() {
            valid[i] = -1;
            rh.ray.org_x[i] = r.o.x;
            rh.ray.org_y[i] = r.o.y;
            rh.ray.org_z[i] = r.o.z;
            rh.ray.dir_x[i] = r.d.x;
            rh.ray.dir_y[i] = r.d.y;
            rh.ray.dir_z[i] = r.d.z;
        }
        let mut ctx = intersect_context(RTCIntersectContextFlags::COHERENT);
        // SAFETY: committed scene, initialised context, aligned packet
        // (the bindgen struct carries the alignment Embree requires).
        unsafe { $f(valid.as_ptr(), $self.scene, &mut ctx, &mut rh) };
        (0..$n)
            .filter(|&i| valid[i] != 0 && rh.hit.geomID[i] != u32::MAX)
            .count()
    }};
}

/// A committed Embree scene holding one triangle mesh, with its device.
pub struct EmbreeScene {
    device: RTCDevice,
    scene: RTCScene,
}

// SAFETY: Embree documents queries on a committed scene as thread safe, and
// the handles are only released in `drop`, which needs exclusive access.
unsafe impl Sync for EmbreeScene {}
// SAFETY: as above; the handles are plain reference-counted pointers.
unsafe impl Send for EmbreeScene {}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: both handles came from `rtcNew*` and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

fn check(device: RTCDevice, what: &str) -> Result<(), String> {
    // SAFETY: `device` is a live device handle.
    let e = unsafe { rtcGetDeviceError(device) };
    if e == RTCError::NONE {
        Ok(())
    } else {
        Err(format!("embree: {what}: {e:?}"))
    }
}

fn intersect_context(flags: RTCIntersectContextFlags) -> RTCIntersectContext {
    // What `rtcInitIntersectContext` (a header-only inline) does, for
    // `RTC_MAX_INSTANCE_LEVEL_COUNT` 1 (Debian's 3.13 build).
    RTCIntersectContext {
        flags,
        filter: None,
        instID: [u32::MAX; 1],
    }
}

impl EmbreeScene {
    /// Builds a scene over `tris` (one triangle geometry, unindexed
    /// vertices) with `threads` build threads; returns it and the seconds
    /// spent filling the buffers and committing.
    pub fn build(tris: &[[Point3f; 3]], threads: usize) -> Result<(EmbreeScene, f64), String> {
        let config = CString::new(format!("threads={threads}")).map_err(|e| e.to_string())?;
        // SAFETY: plain C calls on handles created here; buffer pointers
        // come from `rtcSetNewGeometryBuffer` with the sizes written below.
        unsafe {
            let device = rtcNewDevice(config.as_ptr());
            if device.is_null() {
                return Err("embree: rtcNewDevice failed".into());
            }
            let scene = rtcNewScene(device);
            let me = EmbreeScene { device, scene };
            check(device, "rtcNewScene")?;
            let t0 = Instant::now();
            let geom = rtcNewGeometry(device, RTCGeometryType::TRIANGLE);
            check(device, "rtcNewGeometry")?;
            let n = tris.len();
            let v = rtcSetNewGeometryBuffer(
                geom,
                RTCBufferType::VERTEX,
                0,
                RTCFormat::FLOAT3,
                12,
                3 * n,
            ) as *mut f32;
            let ix = rtcSetNewGeometryBuffer(geom, RTCBufferType::INDEX, 0, RTCFormat::UINT3, 12, n)
                as *mut u32;
            check(device, "rtcSetNewGeometryBuffer")?;
            if v.is_null() || ix.is_null() {
                return Err("embree: no geometry buffer".into());
            }
            let v = std::slice::from_raw_parts_mut(v, 9 * n);
            let ix = std::slice::from_raw_parts_mut(ix, 3 * n);
            for (i, t) in tris.iter().enumerate() {
                for (k, p) in t.iter().enumerate() {
                    v[9 * i + 3 * k..9 * i + 3 * k + 3].copy_from_slice(&[p.x, p.y, p.z]);
                    ix[3 * i + k] = (3 * i + k) as u32;
                }
            }
            rtcCommitGeometry(geom);
            rtcAttachGeometry(scene, geom);
            rtcReleaseGeometry(geom);
            rtcCommitScene(scene);
            check(device, "rtcCommitScene")?;
            Ok((me, t0.elapsed().as_secs_f64()))
        }
    }

    fn rtc_ray(r: &Ray, t_max: Float) -> RTCRay {
        RTCRay {
            org_x: r.o.x,
            org_y: r.o.y,
            org_z: r.o.z,
            tnear: 0.0,
            dir_x: r.d.x,
            dir_y: r.d.y,
            dir_z: r.d.z,
            time: 0.0,
            tfar: t_max,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// `rtcIntersect1`: the nearest hit's primitive and distance.
    pub fn intersect1(&self, r: &Ray) -> Option<(u32, Float)> {
        let mut ctx = intersect_context(RTCIntersectContextFlags::INCOHERENT);
        let mut rh = RTCRayHit {
            ray: Self::rtc_ray(r, Float::INFINITY),
            hit: RTCHit {
                Ng_x: 0.0,
                Ng_y: 0.0,
                Ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                primID: u32::MAX,
                geomID: u32::MAX,
                instID: [u32::MAX; 1],
            },
        };
        // SAFETY: committed scene, initialised context and ray.
        unsafe { rtcIntersect1(self.scene, &mut ctx, &mut rh) };
        (rh.hit.geomID != u32::MAX).then_some((rh.hit.primID, rh.ray.tfar))
    }

    /// `rtcOccluded1`: whether anything blocks the ray.
    pub fn occluded1(&self, r: &Ray) -> bool {
        let mut ctx = intersect_context(RTCIntersectContextFlags::INCOHERENT);
        let mut ray = Self::rtc_ray(r, Float::INFINITY);
        // SAFETY: committed scene, initialised context and ray.
        unsafe { rtcOccluded1(self.scene, &mut ctx, &mut ray) };
        // Embree sets `tfar` to −∞ for an occluded ray.
        ray.tfar < 0.0
    }

    /// `rtcIntersect8` on up to eight coherent rays; returns how many hit.
    pub fn intersect8(&self, rays: &[Ray]) -> usize {
        packet!(self, rays, 8, RTCRayHit8, RTCRay8, RTCHit8, rtcIntersect8)
    }

    /// `rtcIntersect16` on up to sixteen coherent rays; returns how many
    /// hit.
    pub fn intersect16(&self, rays: &[Ray]) -> usize {
        packet!(
            self,
            rays,
            16,
            RTCRayHit16,
            RTCRay16,
            RTCHit16,
            rtcIntersect16
        )
    }
}
