//! Rays and ray differentials (book section 3.6), and the robust spawning
//! of rays from surfaces (section 6.8.6).

use crate::float::*;
use crate::tuple::*;

/// The index of a participating medium in the scene's medium table.
pub type MediumId = u32;

/// A semi-infinite line `o + t d` at a moment in time, in a medium.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Point3f,
    /// Direction (not necessarily normalized).
    pub d: Vector3f,
    /// Time, for motion blur.
    pub time: Float,
    /// The medium containing the origin, if any.
    pub medium: Option<MediumId>,
}

impl Ray {
    /// A ray at time 0 in no medium.
    #[inline]
    pub fn new(o: Point3f, d: Vector3f) -> Self {
        Ray {
            o,
            d,
            time: 0.0,
            medium: None,
        }
    }
    /// A ray with time and medium.
    #[inline]
    pub fn with_time(o: Point3f, d: Vector3f, time: Float, medium: Option<MediumId>) -> Self {
        Ray { o, d, time, medium }
    }
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: Float) -> Point3f {
        self.o + self.d * t
    }
    /// True when origin or direction has a NaN.
    #[inline]
    pub fn has_nan(&self) -> bool {
        self.o.has_nan() || self.d.has_nan() || self.time.is_nan()
    }
}

/// A ray with two offset rays, one pixel over in x and in y, for texture
/// filtering (book section 10.1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayDifferential {
    /// The main ray.
    pub ray: Ray,
    /// Whether the offset rays are set.
    pub has_differentials: bool,
    /// Origin of the x-offset ray.
    pub rx_origin: Point3f,
    /// Origin of the y-offset ray.
    pub ry_origin: Point3f,
    /// Direction of the x-offset ray.
    pub rx_direction: Vector3f,
    /// Direction of the y-offset ray.
    pub ry_direction: Vector3f,
}

impl RayDifferential {
    /// A ray without differentials.
    #[inline]
    pub fn new(ray: Ray) -> Self {
        RayDifferential {
            ray,
            ..Default::default()
        }
    }
    /// Scales the offsets by `s` (for `s` samples per pixel, 1/√s).
    #[inline]
    pub fn scale_differentials(&mut self, s: Float) {
        let o = self.ray.o;
        let d = self.ray.d;
        self.rx_origin = o + (self.rx_origin - o) * s;
        self.ry_origin = o + (self.ry_origin - o) * s;
        self.rx_direction = d + (self.rx_direction - d) * s;
        self.ry_direction = d + (self.ry_direction - d) * s;
    }
    /// True when any component is NaN.
    #[inline]
    pub fn has_nan(&self) -> bool {
        self.ray.has_nan()
            || (self.has_differentials
                && (self.rx_origin.has_nan()
                    || self.ry_origin.has_nan()
                    || self.rx_direction.has_nan()
                    || self.ry_direction.has_nan()))
    }
}

impl From<Ray> for RayDifferential {
    fn from(r: Ray) -> Self {
        RayDifferential::new(r)
    }
}

/// Moves a point with error bounds `p_error` around `p` along the normal
/// `n` just far enough that a ray leaving toward `w` cannot re-intersect the
/// surface it came from, then rounds away from it (book section 6.8.6).
// Always inlined: called a few times per path vertex, and as a call its
// by-value vectors go through memory.
#[inline(always)]
pub fn offset_ray_origin(p: Point3f, p_error: Vector3f, n: Normal3f, w: Vector3f) -> Point3f {
    let d = dot(n.abs(), p_error);
    let offset = Vector3f::from(n) * d;
    // Which side to leave by, and the offset's signs below, are as good as
    // random: selected, not branched on (branches would mispredict).
    let offset = std::hint::select_unpredictable(dot(w, n) < 0.0, -offset, offset);
    let po = p + offset;
    Point3f::new(
        round_off(po.x, offset.x),
        round_off(po.y, offset.y),
        round_off(po.z, offset.z),
    )
}

/// `v` one float up where `o` is positive, one down where it is negative,
/// unchanged where it is zero or NaN: pbrt-v4's rounding of an offset ray
/// origin away from the surface.
#[inline(always)]
fn round_off(v: Float, o: Float) -> Float {
    let a = v.abs();
    if !(a > 0.0 && a < Float::INFINITY) {
        // Zeros, infinities and NaN: the general functions.
        return round_off_general(v, o);
    }
    // A finite nonzero `v` moves away from zero (bits + 1) when the offset
    // has its sign and toward zero (bits − 1) otherwise. Selected by bit
    // arithmetic: the signs are as good as random.
    let (bv, bo) = (v.to_bits(), o.to_bits());
    let step = 1u32.wrapping_sub(((bv ^ bo) >> 31) << 1);
    let step = step & ((o.abs() > 0.0) as u32).wrapping_neg();
    Float::from_bits(bv.wrapping_add(step))
}

/// [`round_off`] for any `v`, by [`next_float_up`] and [`next_float_down`].
#[inline]
fn round_off_general(v: Float, o: Float) -> Float {
    let (up, down) = (next_float_up(v), next_float_down(v));
    let v = std::hint::select_unpredictable(o < 0.0, down, v);
    std::hint::select_unpredictable(o > 0.0, up, v)
}

/// A ray leaving a surface point toward `d` that never hits that surface
/// again.
#[inline]
pub fn spawn_ray(p: Point3f, p_error: Vector3f, n: Normal3f, time: Float, d: Vector3f) -> Ray {
    Ray::with_time(offset_ray_origin(p, p_error, n, d), d, time, None)
}

/// A ray from a surface point toward `p_to`, with direction `p_to − origin`
/// so that `t = 1` reaches the target; shadow rays use `t < 1 − ε`.
#[inline]
pub fn spawn_ray_to(
    p_from: Point3f,
    p_error: Vector3f,
    n: Normal3f,
    time: Float,
    p_to: Point3f,
) -> Ray {
    let d = p_to - p_from;
    let o = offset_ray_origin(p_from, p_error, n, d);
    Ray::with_time(o, p_to - o, time, None)
}

/// A ray between two surface points, each offset from its surface.
#[inline]
pub fn spawn_ray_to_surface(
    p_from: Point3f,
    err_from: Vector3f,
    n_from: Normal3f,
    time: Float,
    p_to: Point3f,
    err_to: Vector3f,
    n_to: Normal3f,
) -> Ray {
    let pf = offset_ray_origin(p_from, err_from, n_from, p_to - p_from);
    spawn_ray_from_origin_to_surface(pf, time, p_to, err_to, n_to)
}

/// [`spawn_ray_to_surface`] given the start point's offset origin `pf`.
#[inline]
pub fn spawn_ray_from_origin_to_surface(
    pf: Point3f,
    time: Float,
    p_to: Point3f,
    err_to: Vector3f,
    n_to: Normal3f,
) -> Ray {
    let pt = offset_ray_origin(p_to, err_to, n_to, pf - p_to);
    Ray::with_time(pf, pt - pf, time, None)
}

/// The parametric fraction of a spawned-to ray below which a hit blocks
/// the target (pbrt's `ShadowEpsilon`).
pub const SHADOW_EPSILON: Float = 0.0001;

#[cfg(test)]
mod tests {
    use super::*;

    /// The bit-arithmetic rounding equals the general one, bit for bit,
    /// on special values and a fixed-seed sweep of random bit patterns.
    #[test]
    fn round_off_matches_next_float() {
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            Float::MIN_POSITIVE,
            -Float::MIN_POSITIVE,
            1e-45,
            -1e-45,
            Float::MAX,
            -Float::MAX,
            Float::INFINITY,
            -Float::INFINITY,
            Float::NAN,
            3.5e7,
        ];
        let mut values: Vec<Float> = specials.to_vec();
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(Float::from_bits(x as u32));
        }
        for (i, &v) in values.iter().enumerate() {
            for &o in specials.iter().chain(&values[i..(i + 3).min(values.len())]) {
                let (a, b) = (round_off(v, o), round_off_general(v, o));
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "v {v:e} ({:#x}) o {o:e}: {a:e} vs {b:e}",
                    v.to_bits()
                );
            }
        }
    }

    #[test]
    fn offset_moves_off_surface() {
        let p = Point3f::new(1.0, 2.0, 3.0);
        let err = Vector3f::new(1e-6, 1e-6, 1e-6);
        let n = Normal3f::new(0.0, 0.0, 1.0);
        let up = offset_ray_origin(p, err, n, Vector3f::new(0.0, 0.0, 1.0));
        assert!(up.z > p.z + 1e-6);
        let down = offset_ray_origin(p, err, n, Vector3f::new(0.0, 0.0, -1.0));
        assert!(down.z < p.z - 1e-6);
        // An exact point needs no offset.
        let exact = offset_ray_origin(p, Vector3f::default(), n, Vector3f::new(0.0, 0.0, 1.0));
        assert_eq!(exact.z, p.z);
        let r = spawn_ray_to(p, err, n, 0.5, Point3f::new(1.0, 2.0, 10.0));
        assert!((r.at(1.0) - Point3f::new(1.0, 2.0, 10.0)).length() < 1e-5);
        assert_eq!(r.time, 0.5);
    }

    #[test]
    fn differentials_scale() {
        let mut rd =
            RayDifferential::new(Ray::new(Point3f::default(), Vector3f::new(0.0, 0.0, 1.0)));
        rd.has_differentials = true;
        rd.rx_origin = Point3f::new(1.0, 0.0, 0.0);
        rd.ry_origin = Point3f::new(0.0, 1.0, 0.0);
        rd.rx_direction = Vector3f::new(0.1, 0.0, 1.0);
        rd.ry_direction = Vector3f::new(0.0, 0.1, 1.0);
        rd.scale_differentials(0.5);
        assert_eq!(rd.rx_origin, Point3f::new(0.5, 0.0, 0.0));
        assert_eq!(rd.ry_direction, Vector3f::new(0.0, 0.05, 1.0));
        assert!(!rd.has_nan());
    }
}
