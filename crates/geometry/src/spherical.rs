//! Spherical geometry (book section 3.8; pbrt-v4 `util/vecmath.h`,
//! `util/math.h`): spherical coordinates, the shading-frame trigonometry,
//! the equal-area square↔sphere mapping, octahedral encoding and direction
//! cones.

use crate::bounds::Bounds3f;
use crate::float::*;
use crate::tuple::*;

/// The unit direction with polar angle θ (given by its sine and cosine) and
/// azimuth φ.
#[inline]
pub fn spherical_direction(sin_theta: Float, cos_theta: Float, phi: Float) -> Vector3f {
    Vector3f::new(
        clamp(sin_theta, -1.0, 1.0) * phi.cos(),
        clamp(sin_theta, -1.0, 1.0) * phi.sin(),
        clamp(cos_theta, -1.0, 1.0),
    )
}

/// The polar angle θ ∈ [0, π] of a unit vector.
#[inline]
pub fn spherical_theta(v: Vector3f) -> Float {
    safe_acos(v.z)
}

/// The azimuth φ ∈ [0, 2π) of a vector.
#[inline]
pub fn spherical_phi(v: Vector3f) -> Float {
    let p = v.y.atan2(v.x);
    if p < 0.0 {
        p + 2.0 * PI
    } else {
        p
    }
}

/// cos θ of a unit vector in a local shading frame (z is the normal).
#[inline]
pub fn cos_theta(w: Vector3f) -> Float {
    w.z
}
/// cos² θ in a local frame.
#[inline]
pub fn cos2_theta(w: Vector3f) -> Float {
    w.z * w.z
}
/// |cos θ| in a local frame.
#[inline]
pub fn abs_cos_theta(w: Vector3f) -> Float {
    w.z.abs()
}
/// sin² θ in a local frame.
#[inline]
pub fn sin2_theta(w: Vector3f) -> Float {
    (1.0 - cos2_theta(w)).max(0.0)
}
/// sin θ in a local frame.
#[inline]
pub fn sin_theta(w: Vector3f) -> Float {
    sin2_theta(w).sqrt()
}
/// tan θ in a local frame.
#[inline]
pub fn tan_theta(w: Vector3f) -> Float {
    sin_theta(w) / cos_theta(w)
}
/// tan² θ in a local frame.
#[inline]
pub fn tan2_theta(w: Vector3f) -> Float {
    sin2_theta(w) / cos2_theta(w)
}
/// cos φ in a local frame (1 at the pole).
#[inline]
pub fn cos_phi(w: Vector3f) -> Float {
    let st = sin_theta(w);
    if st == 0.0 {
        1.0
    } else {
        clamp(w.x / st, -1.0, 1.0)
    }
}
/// sin φ in a local frame (0 at the pole).
#[inline]
pub fn sin_phi(w: Vector3f) -> Float {
    let st = sin_theta(w);
    if st == 0.0 {
        0.0
    } else {
        clamp(w.y / st, -1.0, 1.0)
    }
}
/// cos of the azimuthal angle between two local-frame directions.
#[inline]
pub fn cos_d_phi(wa: Vector3f, wb: Vector3f) -> Float {
    let waxy = wa.x * wa.x + wa.y * wa.y;
    let wbxy = wb.x * wb.x + wb.y * wb.y;
    if waxy == 0.0 || wbxy == 0.0 {
        return 1.0;
    }
    clamp(
        (wa.x * wb.x + wa.y * wb.y) / (waxy * wbxy).sqrt(),
        -1.0,
        1.0,
    )
}
/// True if two local-frame directions lie in the same hemisphere.
#[inline]
pub fn same_hemisphere(w: Vector3f, wp: Vector3f) -> bool {
    w.z * wp.z > 0.0
}

/// Maps a point of [0,1]² to the unit sphere preserving area (Clarici's
/// equal-area mapping, as pbrt-v4's `EqualAreaSquareToSphere`).
pub fn equal_area_square_to_sphere(p: Point2f) -> Vector3f {
    let u = 2.0 * p.x - 1.0;
    let v = 2.0 * p.y - 1.0;
    let up = u.abs();
    let vp = v.abs();
    let signed_distance = 1.0 - (up + vp);
    let d = signed_distance.abs();
    let r = 1.0 - d;
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * PI / 4.0;
    let z = (1.0 - r * r).copysign(signed_distance);
    let cos_phi = phi.cos().copysign(u);
    let sin_phi = phi.sin().copysign(v);
    Vector3f::new(
        cos_phi * r * safe_sqrt(2.0 - r * r),
        sin_phi * r * safe_sqrt(2.0 - r * r),
        z,
    )
}

/// The inverse of [`equal_area_square_to_sphere`] for a unit vector.
pub fn equal_area_sphere_to_square(d: Vector3f) -> Point2f {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = safe_sqrt(1.0 - z);
    let a = x.max(y);
    let b = x.min(y);
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * 2.0 / PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    u = u.copysign(d.x);
    v = v.copysign(d.y);
    Point2f::new(0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

/// Wraps an integer pixel coordinate outside [0, resolution) back into an
/// equal-area octahedral image, mirroring across the edges as pbrt-v4 does.
pub fn wrap_equal_area_square(mut p: Point2i, resolution: Point2i) -> Point2i {
    if p.x < 0 {
        p.x = -p.x;
        p.y = resolution.y - 1 - p.y;
    } else if p.x >= resolution.x {
        p.x = 2 * resolution.x - 1 - p.x;
        p.y = resolution.y - 1 - p.y;
    }
    if p.y < 0 {
        p.x = resolution.x - 1 - p.x;
        p.y = -p.y;
    } else if p.y >= resolution.y {
        p.x = resolution.x - 1 - p.x;
        p.y = 2 * resolution.y - 1 - p.y;
    }
    p
}

/// Wraps a point outside [0,1]² back into the equal-area octahedral square,
/// so that points just across an edge map to nearby directions.
pub fn wrap_equal_area_square_f(mut uv: Point2f) -> Point2f {
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

/// A unit vector stored in 32 bits (octahedral encoding, 16 bits a
/// coordinate; book section 3.8.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OctahedralVector {
    x: u16,
    y: u16,
}

impl OctahedralVector {
    #[inline]
    fn encode(f: Float) -> u16 {
        ((clamp((f + 1.0) / 2.0, 0.0, 1.0) * 65535.0).round()) as u16
    }

    /// Encodes a unit vector.
    pub fn new(v: Vector3f) -> Self {
        let v = v / (v.x.abs() + v.y.abs() + v.z.abs());
        if v.z >= 0.0 {
            OctahedralVector {
                x: Self::encode(v.x),
                y: Self::encode(v.y),
            }
        } else {
            OctahedralVector {
                x: Self::encode((1.0 - v.y.abs()).copysign(v.x)),
                y: Self::encode((1.0 - v.x.abs()).copysign(v.y)),
            }
        }
    }

    /// Decodes to a unit vector.
    pub fn to_vector(self) -> Vector3f {
        let mut v = Vector3f::new(
            -1.0 + 2.0 * (self.x as Float / 65535.0),
            -1.0 + 2.0 * (self.y as Float / 65535.0),
            0.0,
        );
        v.z = 1.0 - (v.x.abs() + v.y.abs());
        if v.z < 0.0 {
            let xo = v.x;
            v.x = (1.0 - v.y.abs()).copysign(xo);
            v.y = (1.0 - xo.abs()).copysign(v.y);
        }
        v.normalize()
    }
}

/// A cone of directions about a central unit vector (book section 3.9.2):
/// used to bound the normals of shapes for the light BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionCone {
    /// The central direction (unit length).
    pub w: Vector3f,
    /// Cosine of the half-angle of the cone.
    pub cos_theta: Float,
}

impl Default for DirectionCone {
    /// The empty cone.
    fn default() -> Self {
        DirectionCone {
            w: Vector3f::new(0.0, 0.0, 1.0),
            cos_theta: Float::INFINITY,
        }
    }
}

impl DirectionCone {
    /// A cone around `w` with the given half-angle cosine.
    #[inline]
    pub fn new(w: Vector3f, cos_theta: Float) -> Self {
        DirectionCone {
            w: w.normalize(),
            cos_theta,
        }
    }
    /// A cone holding the single direction `w`.
    #[inline]
    pub fn from_direction(w: Vector3f) -> Self {
        DirectionCone::new(w, 1.0)
    }
    /// The cone of all directions.
    #[inline]
    pub fn entire_sphere() -> Self {
        DirectionCone {
            w: Vector3f::new(0.0, 0.0, 1.0),
            cos_theta: -1.0,
        }
    }
    /// True for the empty cone.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.cos_theta == Float::INFINITY
    }
    /// True when unit vector `w` lies inside the cone.
    #[inline]
    pub fn inside(&self, w: Vector3f) -> bool {
        !self.is_empty() && dot(self.w, w.normalize()) >= self.cos_theta
    }

    /// The direction inside the cone closest to `wp` (`wp` itself when it is
    /// inside): `w` rotated toward `wp` by the cone's half-angle.
    pub fn closest_vector_in_cone(&self, wp: Vector3f) -> Vector3f {
        let wp = wp.normalize();
        if dot(wp, self.w) > self.cos_theta {
            return wp;
        }
        let perp = wp - self.w * dot(wp, self.w);
        let sin_theta = safe_sqrt(1.0 - self.cos_theta * self.cos_theta);
        match perp.try_normalize() {
            Some(u) => self.w * self.cos_theta + u * sin_theta,
            // wp is exactly opposite w: any boundary direction is closest.
            None => {
                let (u, _) = self.w.coordinate_system();
                self.w * self.cos_theta + u * sin_theta
            }
        }
    }

    /// The cone of directions from points `p` toward the box `b`.
    pub fn bound_subtended_directions(b: &Bounds3f, p: Point3f) -> DirectionCone {
        let (center, radius) = b.bounding_sphere();
        let d2 = p.distance_squared(center);
        if d2 < radius * radius {
            return DirectionCone::entire_sphere();
        }
        let w = (center - p).normalize();
        let sin2_max = radius * radius / d2;
        let cos_max = safe_sqrt(1.0 - sin2_max);
        DirectionCone::new(w, cos_max)
    }

    /// The smallest cone bounding both cones.
    pub fn union(a: &DirectionCone, b: &DirectionCone) -> DirectionCone {
        if a.is_empty() {
            return *b;
        }
        if b.is_empty() {
            return *a;
        }
        let theta_a = safe_acos(a.cos_theta);
        let theta_b = safe_acos(b.cos_theta);
        let theta_d = a.w.angle_between(b.w);
        if (theta_d + theta_b).min(PI) <= theta_a {
            return *a;
        }
        if (theta_d + theta_a).min(PI) <= theta_b {
            return *b;
        }
        let theta_o = (theta_a + theta_d + theta_b) / 2.0;
        if theta_o >= PI {
            return DirectionCone::entire_sphere();
        }
        let theta_r = theta_o - theta_a;
        let wr = cross(a.w, b.w);
        if wr.length_squared() == 0.0 {
            return DirectionCone::entire_sphere();
        }
        let w = crate::transform::Transform::rotate(degrees(theta_r), wr).apply_vector(a.w);
        DirectionCone::new(w, theta_o.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: &mut u64) -> Float {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        ((*seed >> 40) as Float) / (1u64 << 24) as Float
    }

    #[test]
    fn equal_area_round_trip() {
        let mut s = 7u64;
        for _ in 0..10000 {
            let p = Point2f::new(rng(&mut s), rng(&mut s));
            let v = equal_area_square_to_sphere(p);
            assert!((v.length() - 1.0).abs() < 1e-5);
            let q = equal_area_sphere_to_square(v);
            assert!((p - q).length() < 1e-3, "{p:?} {q:?}");
        }
    }

    #[test]
    fn equal_area_is_equal_area() {
        // Each quadrant of the square maps to a quarter of the sphere by
        // solid angle: count hits of uniform directions.
        let mut s = 11u64;
        let mut counts = [0u32; 4];
        let n = 40000;
        for _ in 0..n {
            let p = Point2f::new(rng(&mut s), rng(&mut s));
            let v = equal_area_square_to_sphere(p);
            let idx = (v.z > 0.0) as usize * 2 + (v.x > 0.0) as usize;
            counts[idx] += 1;
        }
        for c in counts {
            assert!((c as f32 / n as f32 - 0.25).abs() < 0.01, "{counts:?}");
        }
    }

    #[test]
    fn wrap_equal_area() {
        let res = Point2i::new(8, 8);
        assert_eq!(
            wrap_equal_area_square(Point2i::new(3, 4), res),
            Point2i::new(3, 4)
        );
        assert_eq!(
            wrap_equal_area_square(Point2i::new(-1, 2), res),
            Point2i::new(1, 5)
        );
        assert_eq!(
            wrap_equal_area_square(Point2i::new(8, 2), res),
            Point2i::new(7, 5)
        );
    }

    #[test]
    fn octahedral_round_trip() {
        let mut s = 3u64;
        for _ in 0..10000 {
            let p = Point2f::new(rng(&mut s), rng(&mut s));
            let v = equal_area_square_to_sphere(p);
            let o = OctahedralVector::new(v).to_vector();
            assert!((o - v).length() < 1e-3);
        }
    }

    #[test]
    fn spherical_coordinates() {
        let v = spherical_direction(0.6, 0.8, 1.0);
        assert!((spherical_theta(v) - 0.6f32.asin()).abs() < 1e-5);
        assert!((spherical_phi(v) - 1.0).abs() < 1e-5);
        assert!((cos_phi(v) - 1.0f32.cos()).abs() < 1e-5);
        assert!((sin_phi(v) - 1.0f32.sin()).abs() < 1e-5);
        assert!((tan_theta(v) - 0.75).abs() < 1e-5);
        assert!(same_hemisphere(v, Vector3f::new(0.0, 0.0, 1.0)));
    }

    #[test]
    fn cone_union_bounds_both() {
        let mut s = 5u64;
        for _ in 0..2000 {
            let a = DirectionCone::new(
                equal_area_square_to_sphere(Point2f::new(rng(&mut s), rng(&mut s))),
                rng(&mut s) * 2.0 - 1.0,
            );
            let b = DirectionCone::new(
                equal_area_square_to_sphere(Point2f::new(rng(&mut s), rng(&mut s))),
                rng(&mut s) * 2.0 - 1.0,
            );
            let u = DirectionCone::union(&a, &b);
            for c in [a, b] {
                // Sample directions inside c; all must lie in u.
                for _ in 0..20 {
                    let w = equal_area_square_to_sphere(Point2f::new(rng(&mut s), rng(&mut s)));
                    if c.inside(w) {
                        assert!(dot(u.w, w) >= u.cos_theta - 1e-3, "{a:?} {b:?} {u:?}");
                    }
                }
            }
        }
        let e = DirectionCone::default();
        assert!(e.is_empty());
        let a = DirectionCone::from_direction(Vector3f::new(1.0, 0.0, 0.0));
        assert_eq!(DirectionCone::union(&e, &a), a);
    }

    #[test]
    fn subtended_directions() {
        let b = Bounds3f::new(Point3f::new(-1.0, -1.0, -1.0), Point3f::new(1.0, 1.0, 1.0));
        let c = DirectionCone::bound_subtended_directions(&b, Point3f::new(0.0, 0.0, 10.0));
        assert!(c.inside(Vector3f::new(0.0, 0.0, -1.0)));
        assert!(!c.inside(Vector3f::new(0.0, 0.0, 1.0)));
        let inside = DirectionCone::bound_subtended_directions(&b, Point3f::new(0.0, 0.0, 0.0));
        assert_eq!(inside.cos_theta, -1.0);
    }
}
