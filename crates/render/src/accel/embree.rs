//! Embree 3 as an acceleration structure (cargo feature `embree`; Debian's
//! `libembree-dev` 3.13): the role of pbrt-v4's `BVHAggregate` (book
//! section 7.3) played by Intel's kernels, with every hit decided by
//! rpbrt's own primitive tests.
//!
//! The scene holds two Embree geometries. Opaque, non-degenerate triangles
//! (what [`Accelerator::build_from_triangles`](super::Accelerator::build_from_triangles)
//! is told about) become Embree triangles, each grown outwards in its plane
//! by a few hundred ulps of its coordinates so that Embree's (non-watertight)
//! triangle test never misses a hit that pbrt-v4's watertight test makes.
//! An intersection filter then runs the caller's hit closure (rpbrt's
//! triangle test) on every Embree candidate: it rejects what rpbrt rejects
//! and keeps rpbrt's `t`. Every other entry (spheres, curves, bilinear
//! patches, alpha-masked triangles, object instances, animated primitives)
//! is Embree user geometry over its bounding box whose callbacks call the
//! hit closure directly. So the structure keeps the interface of the other
//! accelerators (bounds and a hit closure) and finds the same hits: the
//! closest hit among those the closure accepts, Embree only culling.
//!
//! Embree's own distances only prune the traversal: after each accepted hit
//! its `tfar` is set a little beyond rpbrt's `t` (see [`Query::pad`]), so a
//! candidate that rpbrt's test puts nearer is still offered to the closure.

use super::usable_bounds;
use embree3::sys::*;
use rpbrt_geometry::{Bounds3f, Float, Point3f, Ray};
use std::any::Any;
use std::ffi::CString;
use std::os::raw::{c_int, c_uint, c_void};
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::{Arc, OnceLock};

/// Why an Embree scene could not be made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AccelError {
    /// What failed, in words.
    pub message: String,
}

impl std::fmt::Display for AccelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Embree: {}", self.message)
    }
}

impl std::error::Error for AccelError {}

fn error(message: impl Into<String>) -> AccelError {
    AccelError {
        message: message.into(),
    }
}

/// The process's Embree device (one for all scenes: a device owns a pool
/// of build threads).
struct Device(RTCDevice);

// SAFETY: an Embree device handle may be used from any thread (Embree's
// API is thread safe per device; errors are kept per thread).
unsafe impl Send for Device {}
// SAFETY: as above.
unsafe impl Sync for Device {}

static DEVICE: OnceLock<Result<Device, AccelError>> = OnceLock::new();

fn device() -> Result<RTCDevice, AccelError> {
    let d = DEVICE.get_or_init(|| {
        let config = CString::new("").map_err(|e| error(e.to_string()))?;
        // SAFETY: a plain C call with a NUL-terminated configuration.
        let d = unsafe { rtcNewDevice(config.as_ptr()) };
        if d.is_null() {
            return Err(error(
                "rtcNewDevice failed (is this processor supported by libembree3?)",
            ));
        }
        // SAFETY: `d` is a live device.
        match unsafe { rtcGetDeviceError(d) } {
            RTCError::NONE => Ok(Device(d)),
            e => Err(error(format!("rtcNewDevice: {e:?}"))),
        }
    });
    d.as_ref().map(|d| d.0).map_err(Clone::clone)
}

/// Ok when Embree can be used in this process (its device could be made).
pub fn available() -> Result<(), AccelError> {
    device().map(|_| ())
}

fn check(device: RTCDevice, what: &str) -> Result<(), AccelError> {
    // SAFETY: `device` is a live device handle.
    match unsafe { rtcGetDeviceError(device) } {
        RTCError::NONE => Ok(()),
        e => Err(error(format!("{what}: {e:?}"))),
    }
}

/// Geometry ids in every scene.
const TRIANGLE_GEOMETRY: c_uint = 0;
const USER_GEOMETRY: c_uint = 1;

/// What the callbacks read (boxed: Embree keeps a pointer to it).
#[derive(Debug)]
struct Maps {
    /// The entry of each Embree triangle.
    triangle_entries: Vec<u32>,
    /// The entry of each user primitive.
    user_entries: Vec<u32>,
    /// The bounds of each user primitive.
    user_bounds: Vec<Bounds3f>,
    /// Entries with coordinates beyond [`FAR`]: Embree's arithmetic would
    /// overflow on them, so every query offers them to the closure itself.
    far_entries: Vec<u32>,
}

/// Coordinates up to this magnitude go to Embree (its `FLT_LARGE` is
/// 1.8e18; squared extents in its builder must stay finite).
const FAR: Float = 1e15;

/// An owned, committed Embree scene.
struct SceneHandle {
    scene: RTCScene,
    maps: Box<Maps>,
}

// SAFETY: queries on a committed scene are thread safe (Embree's
// documentation); the handle is released only in `drop`.
unsafe impl Send for SceneHandle {}
// SAFETY: as above; `maps` is never written after the commit.
unsafe impl Sync for SceneHandle {}

impl Drop for SceneHandle {
    fn drop(&mut self) {
        // SAFETY: `scene` came from `rtcNewScene` and is released once.
        unsafe { rtcReleaseScene(self.scene) };
    }
}

/// Embree over a set of entries (see the module documentation).
#[derive(Clone)]
pub struct EmbreeAccel {
    handle: Arc<SceneHandle>,
    bounds: Bounds3f,
    /// The largest coordinate magnitude of `bounds`, for [`Query::pad`].
    scale: Float,
    n_prims: usize,
    skipped: usize,
}

impl std::fmt::Debug for EmbreeAccel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmbreeAccel")
            .field("bounds", &self.bounds)
            .field("triangles", &self.handle.maps.triangle_entries.len())
            .field("user_primitives", &self.handle.maps.user_entries.len())
            .field("far", &self.handle.maps.far_entries.len())
            .field("skipped", &self.skipped)
            .finish()
    }
}

/// The triangle as Embree gets it: every edge moved outwards in the
/// triangle's plane by `2^-16` of its largest coordinate magnitude (about
/// 128 ulps), so that Embree's test accepts every point pbrt-v4's
/// watertight test does (plus a thin rim that rpbrt's test then rejects).
/// `None` for triangles whose grown form cannot be trusted (huge or
/// non-finite coordinates, needle-like corners): they become user geometry.
fn grown_triangle(v: &[Point3f; 3]) -> Option<[[f32; 3]; 3]> {
    let p: [[f64; 3]; 3] = v.map(|p| [p.x as f64, p.y as f64, p.z as f64]);
    let max_abs = p.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    if !max_abs.is_finite() || max_abs > FAR as f64 {
        return None;
    }
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let unit = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
    };
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    // The outward in-plane normal of the edge opposite vertex k.
    let mut m = [[0.0f64; 3]; 3];
    for (k, mk) in m.iter_mut().enumerate() {
        let (a, b) = (p[(k + 1) % 3], p[(k + 2) % 3]);
        let mut o = unit(cross(sub(b, a), n))?;
        if dot(o, sub(p[k], a)) > 0.0 {
            o = o.map(|c| -c);
        }
        *mk = o;
    }
    let delta = max_abs * (1.0 / 65536.0);
    let mut out = [[0.0f32; 3]; 3];
    for k in 0..3 {
        // Vertex k lies on the edges opposite k+1 and k+2; moving both by
        // `delta` moves it along the miter by delta (ma + mb) / (1 + ma·mb).
        let (ma, mb) = (m[(k + 1) % 3], m[(k + 2) % 3]);
        let denom = 1.0 + dot(ma, mb);
        if denom < 1e-4 {
            return None;
        }
        for c in 0..3 {
            out[k][c] = (p[k][c] + delta * (ma[c] + mb[c]) / denom) as f32;
        }
    }
    out.iter().flatten().all(|c| c.is_finite()).then_some(out)
}

impl EmbreeAccel {
    /// Builds a scene over `n` entries: entry `e` has bounds `bounds(e)`;
    /// when `triangle(e)` gives its vertices it is intersected by Embree's
    /// triangles (the hit closure then refines each candidate), otherwise
    /// it is user geometry over its bounds.
    pub fn build<B, T>(n: usize, bounds: B, triangle: T) -> Result<EmbreeAccel, AccelError>
    where
        B: Fn(u32) -> Bounds3f,
        T: Fn(u32) -> Option<[Point3f; 3]>,
    {
        let device = device()?;
        let mut maps = Box::new(Maps {
            triangle_entries: Vec::new(),
            user_entries: Vec::new(),
            user_bounds: Vec::new(),
            far_entries: Vec::new(),
        });
        let mut vertices: Vec<[[f32; 3]; 3]> = Vec::new();
        let mut total = Bounds3f::empty();
        // The bounds of what Embree holds.
        let mut near = Bounds3f::empty();
        let mut skipped = 0;
        for e in 0..n as u32 {
            let b = bounds(e);
            if !usable_bounds(&b) {
                skipped += 1;
                continue;
            }
            total = total.union(&b);
            let far = [b.p_min, b.p_max]
                .iter()
                .any(|p| p.x.abs().max(p.y.abs()).max(p.z.abs()) > FAR);
            if far {
                maps.far_entries.push(e);
                continue;
            }
            near = near.union(&b);
            match triangle(e).as_ref().and_then(grown_triangle) {
                Some(v) => {
                    maps.triangle_entries.push(e);
                    vertices.push(v);
                }
                None => {
                    maps.user_entries.push(e);
                    maps.user_bounds.push(b);
                }
            }
        }
        if maps.triangle_entries.len() > u32::MAX as usize / 3 {
            return Err(error("too many triangles for one Embree geometry"));
        }
        // SAFETY: plain C calls on handles made here. Buffer pointers come
        // from `rtcSetNewGeometryBuffer` with the element counts written;
        // `maps` is boxed and owned by the returned handle, so the user
        // pointers given to Embree outlive the scene.
        let handle = unsafe {
            let scene = rtcNewScene(device);
            check(device, "rtcNewScene")?;
            if scene.is_null() {
                return Err(error("rtcNewScene failed"));
            }
            let maps_ptr = &mut *maps as *mut Maps as *mut c_void;
            let handle = SceneHandle { scene, maps };
            let tris = vertices.len();
            if tris > 0 {
                let geom = rtcNewGeometry(device, RTCGeometryType::TRIANGLE);
                check(device, "rtcNewGeometry")?;
                let v = rtcSetNewGeometryBuffer(
                    geom,
                    RTCBufferType::VERTEX,
                    0,
                    RTCFormat::FLOAT3,
                    12,
                    3 * tris,
                ) as *mut f32;
                let ix = rtcSetNewGeometryBuffer(
                    geom,
                    RTCBufferType::INDEX,
                    0,
                    RTCFormat::UINT3,
                    12,
                    tris,
                ) as *mut u32;
                if let Err(e) = check(device, "rtcSetNewGeometryBuffer") {
                    rtcReleaseGeometry(geom);
                    return Err(e);
                }
                if v.is_null() || ix.is_null() {
                    rtcReleaseGeometry(geom);
                    return Err(error("no geometry buffer"));
                }
                let v = std::slice::from_raw_parts_mut(v, 9 * tris);
                let ix = std::slice::from_raw_parts_mut(ix, 3 * tris);
                for (i, t) in vertices.iter().enumerate() {
                    for (k, p) in t.iter().enumerate() {
                        v[9 * i + 3 * k..9 * i + 3 * k + 3].copy_from_slice(p);
                        ix[3 * i + k] = (3 * i + k) as u32;
                    }
                }
                rtcSetGeometryUserData(geom, maps_ptr);
                rtcSetGeometryIntersectFilterFunction(geom, Some(triangle_filter));
                rtcSetGeometryOccludedFilterFunction(geom, Some(triangle_filter));
                rtcCommitGeometry(geom);
                rtcAttachGeometryByID(scene, geom, TRIANGLE_GEOMETRY);
                rtcReleaseGeometry(geom);
                check(device, "triangle geometry")?;
            }
            drop(vertices);
            let users = handle.maps.user_entries.len();
            if users > 0 {
                let geom = rtcNewGeometry(device, RTCGeometryType::USER);
                check(device, "rtcNewGeometry")?;
                rtcSetGeometryUserPrimitiveCount(geom, users as c_uint);
                rtcSetGeometryUserData(geom, maps_ptr);
                rtcSetGeometryBoundsFunction(geom, Some(user_bounds), std::ptr::null_mut());
                rtcSetGeometryIntersectFunction(geom, Some(user_intersect));
                rtcSetGeometryOccludedFunction(geom, Some(user_occluded));
                rtcCommitGeometry(geom);
                rtcAttachGeometryByID(scene, geom, USER_GEOMETRY);
                rtcReleaseGeometry(geom);
                check(device, "user geometry")?;
            }
            rtcCommitScene(scene);
            check(device, "rtcCommitScene")?;
            handle
        };
        let scale = if near.is_empty() {
            0.0
        } else {
            [near.p_min, near.p_max]
                .iter()
                .flat_map(|p| [p.x.abs(), p.y.abs(), p.z.abs()])
                .fold(0.0, Float::max)
        };
        Ok(EmbreeAccel {
            handle: Arc::new(handle),
            bounds: total,
            scale,
            n_prims: n,
            skipped,
        })
    }

    /// Runs one Embree query with `query` as its context, passing on a
    /// panic raised by the hit closure once Embree has returned.
    fn run(&self, query: &mut Query, closest: bool) {
        let mut rh = RTCRayHit {
            ray: RTCRay {
                org_x: query.ray.o.x,
                org_y: query.ray.o.y,
                org_z: query.ray.o.z,
                tnear: 0.0,
                dir_x: query.ray.d.x,
                dir_y: query.ray.d.y,
                dir_z: query.ray.d.z,
                // No Embree geometry moves (motion is the closure's).
                time: 0.0,
                tfar: query.pad(query.t_best),
                mask: u32::MAX,
                id: 0,
                flags: 0,
            },
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
        let ctx = &mut query.rtc as *mut RTCIntersectContext;
        // SAFETY: a committed scene; `ctx` is the first field of the
        // `#[repr(C)]` `Query`, which lives across the call, so the
        // callbacks may cast it back.
        unsafe {
            if closest {
                rtcIntersect1(self.handle.scene, ctx, &mut rh);
            } else {
                rtcOccluded1(self.handle.scene, ctx, &mut rh.ray);
            }
        }
        if query.best.is_none() || closest {
            for &e in &self.handle.maps.far_entries {
                if query.offer(e).is_some() && !closest {
                    break;
                }
            }
        }
        if let Some(p) = query.panic.take() {
            resume_unwind(p);
        }
    }

    /// Offers every entry to the closure, for rays Embree cannot take.
    fn brute_force(&self, q: &mut Query) {
        let m = &self.handle.maps;
        for &e in m
            .triangle_entries
            .iter()
            .chain(&m.user_entries)
            .chain(&m.far_entries)
        {
            if q.offer(e).is_some() && matches!(q.hit, HitFn::Any(_)) {
                break;
            }
        }
        if let Some(p) = q.panic.take() {
            resume_unwind(p);
        }
    }

    fn query<'a>(&self, ray: &'a Ray, t_max: Float, hit: HitFn<'a>) -> Query<'a> {
        let len = (ray.d.x * ray.d.x + ray.d.y * ray.d.y + ray.d.z * ray.d.z).sqrt();
        let o = ray.o.x.abs().max(ray.o.y.abs()).max(ray.o.z.abs());
        // A few hundred ulps of the coordinates involved, as a distance
        // along the ray.
        let pad_abs = (self.scale.max(o) * (1.0 / 65536.0)) / len;
        Query {
            rtc: RTCIntersectContext {
                flags: RTCIntersectContextFlags::INCOHERENT,
                filter: None,
                instID: [u32::MAX; 1],
            },
            ray,
            t_best: t_max,
            best: None,
            pad_abs: if pad_abs.is_finite() { pad_abs } else { 0.0 },
            hit,
            panic: None,
        }
    }

    /// The nearest entry hit in `(0, t_max)` according to `hit`.
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: Float,
        hit: &mut dyn FnMut(u32, &Ray, Float) -> Option<Float>,
    ) -> Option<(u32, Float)> {
        if t_max.is_nan() || t_max <= 0.0 || self.bounds.is_empty() {
            return None;
        }
        let mut q = self.query(ray, t_max, HitFn::Closest(hit));
        if embree_ray_ok(ray) {
            self.run(&mut q, true);
        } else {
            self.brute_force(&mut q);
        }
        q.best.map(|p| (p, q.t_best))
    }

    /// Whether `hit` accepts any entry before `t_max`.
    pub fn intersect_p(
        &self,
        ray: &Ray,
        t_max: Float,
        hit: &mut dyn FnMut(u32, &Ray, Float) -> bool,
    ) -> bool {
        if t_max.is_nan() || t_max <= 0.0 || self.bounds.is_empty() {
            return false;
        }
        let mut q = self.query(ray, t_max, HitFn::Any(hit));
        if embree_ray_ok(ray) {
            self.run(&mut q, false);
        } else {
            self.brute_force(&mut q);
        }
        q.best.is_some()
    }

    /// The bounds of the usable entries.
    pub fn bounds(&self) -> Bounds3f {
        self.bounds
    }

    /// An estimate of the scene's memory: Embree does not report it;
    /// about 120 bytes per triangle (vertices, indices and its BVH) and 64
    /// per user primitive, plus the entry maps.
    pub fn memory_bytes(&self) -> usize {
        let m = &self.handle.maps;
        std::mem::size_of::<Self>()
            + m.triangle_entries.len() * (120 + 4)
            + m.user_entries.len() * (64 + 4 + std::mem::size_of::<Bounds3f>())
            + m.far_entries.len() * 4
    }

    /// The number of entries given at build time.
    pub fn primitive_count(&self) -> usize {
        self.n_prims
    }

    /// Entries left out for unusable bounds.
    pub fn skipped_primitives(&self) -> usize {
        self.skipped
    }

    /// Entries that are Embree triangles (the others are user geometry).
    pub fn triangle_count(&self) -> usize {
        self.handle.maps.triangle_entries.len()
    }
}

/// Whether Embree accepts `ray`: its origin and direction must be finite
/// and below `FLT_LARGE` (1.8e18) in magnitude (`RayK::valid`, asserted
/// in Debian's build), and the direction not zero. Other rays (far beyond
/// any scene rpbrt renders) are answered by brute force.
#[inline]
fn embree_ray_ok(ray: &Ray) -> bool {
    const LARGE: Float = 1e18;
    let (o, d) = (ray.o, ray.d);
    [o.x, o.y, o.z, d.x, d.y, d.z]
        .iter()
        .all(|c| c.abs() <= LARGE)
        && (d.x != 0.0 || d.y != 0.0 || d.z != 0.0)
}

/// The caller's hit closure for one query.
enum HitFn<'a> {
    Closest(&'a mut dyn FnMut(u32, &Ray, Float) -> Option<Float>),
    Any(&'a mut dyn FnMut(u32, &Ray, Float) -> bool),
}

/// One query's state, reached from Embree's callbacks through the
/// intersection context (its first field).
#[repr(C)]
struct Query<'a> {
    rtc: RTCIntersectContext,
    ray: &'a Ray,
    /// The nearest accepted `t` so far (`t_max` at first).
    t_best: Float,
    /// The entry accepted last.
    best: Option<u32>,
    /// Absolute slack on Embree's `tfar` (see [`Query::pad`]).
    pad_abs: Float,
    hit: HitFn<'a>,
    /// A panic of the hit closure, raised again after Embree returns.
    panic: Option<Box<dyn Any + Send>>,
}

impl Query<'_> {
    /// Embree's `tfar` for rpbrt's bound `t`: a little beyond it, so that a
    /// candidate whose Embree distance rounds (or, on the grown triangles,
    /// lies) past rpbrt's still reaches the hit closure, which decides with
    /// the exact bound.
    #[inline]
    fn pad(&self, t: Float) -> Float {
        t + t * (1.0 / 4096.0) + self.pad_abs
    }

    /// Offers entry `e` to the closure; for the closest-hit query returns
    /// Embree's new `tfar` when accepted, for the shadow query `-inf`.
    #[inline]
    fn offer(&mut self, e: u32) -> Option<Float> {
        if self.panic.is_some() {
            return None;
        }
        let ray = self.ray;
        let t = self.t_best;
        let r = catch_unwind(AssertUnwindSafe(|| match &mut self.hit {
            HitFn::Closest(f) => f(e, ray, t),
            HitFn::Any(f) => f(e, ray, t).then_some(Float::NEG_INFINITY),
        }));
        match r {
            Ok(Some(t_hit)) => {
                self.best = Some(e);
                if matches!(self.hit, HitFn::Closest(_)) {
                    self.t_best = t_hit;
                    Some(self.pad(t_hit))
                } else {
                    Some(t_hit)
                }
            }
            Ok(None) => None,
            Err(p) => {
                self.panic = Some(p);
                None
            }
        }
    }
}

// Field offsets (in 4-byte words, times the lane count N) in Embree's
// SoA ray and hit layouts: `RTCRayN` then `RTCHitN` in `RTCRayHitN`.
const RAY_TFAR: usize = 8;
const RAY_WORDS: usize = 12;
const HIT_PRIM_ID: usize = 5;
const HIT_GEOM_ID: usize = 6;

unsafe extern "C" fn user_bounds(args: *const RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments; the user pointer is the
    // scene's `Maps` and `primID` is below the user primitive count.
    unsafe {
        let a = &*args;
        let maps = &*(a.geometryUserPtr as *const Maps);
        let b = maps
            .user_bounds
            .get(a.primID as usize)
            .copied()
            .unwrap_or(Bounds3f::empty());
        // Grown by a few ulps of its coordinates: Embree's box tests are
        // not conservative for rays lying in a face or boxes of zero size,
        // and a box too large only costs the closure a call.
        let m = [b.p_min, b.p_max]
            .iter()
            .flat_map(|p| [p.x.abs(), p.y.abs(), p.z.abs()])
            .fold(0.0, Float::max);
        let g = m * (1.0 / 262144.0) + 1e-30;
        let b = Bounds3f {
            p_min: Point3f::new(b.p_min.x - g, b.p_min.y - g, b.p_min.z - g),
            p_max: Point3f::new(b.p_max.x + g, b.p_max.y + g, b.p_max.z + g),
        };
        *a.bounds_o = RTCBounds {
            lower_x: b.p_min.x,
            lower_y: b.p_min.y,
            lower_z: b.p_min.z,
            align0: 0.0,
            upper_x: b.p_max.x,
            upper_y: b.p_max.y,
            upper_z: b.p_max.z,
            align1: 0.0,
        };
    }
}

/// The entry of Embree primitive `prim` of a geometry, from `maps`.
#[inline]
fn entry(list: &[u32], prim: u32) -> Option<u32> {
    list.get(prim as usize).copied()
}

unsafe extern "C" fn user_intersect(args: *const RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes valid arguments for `N` lanes; the context is
    // a `Query`'s first field (only `EmbreeAccel::run` queries these
    // scenes), the user pointer is the scene's `Maps`.
    unsafe {
        let a = &*args;
        let n = a.N as usize;
        let q = &mut *(a.context as *mut Query);
        let maps = &*(a.geometryUserPtr as *const Maps);
        let Some(e) = entry(&maps.user_entries, a.primID) else {
            return;
        };
        let words = a.rayhit as *mut f32;
        for lane in 0..n {
            if *a.valid.add(lane) == 0 {
                continue;
            }
            if let Some(tfar) = q.offer(e) {
                *words.add(RAY_TFAR * n + lane) = tfar;
                let hit = words.add(RAY_WORDS * n) as *mut u32;
                *hit.add(HIT_PRIM_ID * n + lane) = a.primID;
                *hit.add(HIT_GEOM_ID * n + lane) = a.geomID;
            }
        }
    }
}

unsafe extern "C" fn user_occluded(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as for `user_intersect`.
    unsafe {
        let a = &*args;
        let n = a.N as usize;
        let q = &mut *(a.context as *mut Query);
        let maps = &*(a.geometryUserPtr as *const Maps);
        let Some(e) = entry(&maps.user_entries, a.primID) else {
            return;
        };
        let words = a.ray as *mut f32;
        for lane in 0..n {
            if *a.valid.add(lane) == 0 {
                continue;
            }
            if let Some(tfar) = q.offer(e) {
                *words.add(RAY_TFAR * n + lane) = tfar;
            }
        }
    }
}

/// The intersection and occlusion filter of the triangle geometry: runs
/// rpbrt's test (the hit closure) on Embree's candidate.
unsafe extern "C" fn triangle_filter(args: *const RTCFilterFunctionNArguments) {
    // SAFETY: Embree passes valid arguments for `N` lanes; context and
    // user pointer as for `user_intersect`. Embree reads `tfar` back after
    // the filter accepts (it has set it to its own distance before).
    unsafe {
        let a = &*args;
        let n = a.N as usize;
        let q = &mut *(a.context as *mut Query);
        let maps = &*(a.geometryUserPtr as *const Maps);
        let ray = a.ray as *mut f32;
        let hit = a.hit as *const u32;
        for lane in 0..n {
            let valid = a.valid.add(lane) as *mut c_int;
            if *valid == 0 {
                continue;
            }
            let prim = *hit.add(HIT_PRIM_ID * n + lane);
            match entry(&maps.triangle_entries, prim).and_then(|e| q.offer(e)) {
                Some(tfar) => *ray.add(RAY_TFAR * n + lane) = tfar,
                None => *valid = 0,
            }
        }
    }
}
