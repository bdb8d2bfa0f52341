//! Axis-aligned bounding boxes (book section 3.7).

use crate::float::*;
use crate::ray::Ray;
use crate::tuple::*;

/// A 3-D axis-aligned box. The default box is empty (pMin = +∞,
/// pMax = −∞), so that the union with anything is that thing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3f {
    /// Minimum corner.
    pub p_min: Point3f,
    /// Maximum corner.
    pub p_max: Point3f,
}

impl Default for Bounds3f {
    fn default() -> Self {
        Bounds3f::empty()
    }
}

impl Bounds3f {
    /// The empty box.
    #[inline]
    pub const fn empty() -> Self {
        Bounds3f {
            p_min: Point3f::new(Float::INFINITY, Float::INFINITY, Float::INFINITY),
            p_max: Point3f::new(
                Float::NEG_INFINITY,
                Float::NEG_INFINITY,
                Float::NEG_INFINITY,
            ),
        }
    }
    /// The box spanned by two corner points, in any order.
    #[inline]
    pub fn new(a: Point3f, b: Point3f) -> Self {
        Bounds3f {
            p_min: a.min(b),
            p_max: a.max(b),
        }
    }
    /// The degenerate box holding one point.
    #[inline]
    pub fn from_point(p: Point3f) -> Self {
        Bounds3f { p_min: p, p_max: p }
    }
    /// Corner `i` (bit 0 picks x, bit 1 y, bit 2 z from pMax).
    #[inline]
    pub fn corner(&self, i: usize) -> Point3f {
        Point3f::new(
            if i & 1 != 0 {
                self.p_max.x
            } else {
                self.p_min.x
            },
            if i & 2 != 0 {
                self.p_max.y
            } else {
                self.p_min.y
            },
            if i & 4 != 0 {
                self.p_max.z
            } else {
                self.p_min.z
            },
        )
    }
    /// `p_min` for 0, `p_max` for 1.
    #[inline]
    pub fn get(&self, i: usize) -> Point3f {
        if i == 0 {
            self.p_min
        } else {
            self.p_max
        }
    }
    /// True when the box contains no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.p_min.x > self.p_max.x || self.p_min.y > self.p_max.y || self.p_min.z > self.p_max.z
    }
    /// True when the box has zero volume (or is empty).
    #[inline]
    pub fn is_degenerate(&self) -> bool {
        self.p_min.x >= self.p_max.x || self.p_min.y >= self.p_max.y || self.p_min.z >= self.p_max.z
    }
    /// The box grown to hold `p`.
    #[inline]
    pub fn union_point(&self, p: Point3f) -> Bounds3f {
        Bounds3f {
            p_min: self.p_min.min(p),
            p_max: self.p_max.max(p),
        }
    }
    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, b: &Bounds3f) -> Bounds3f {
        Bounds3f {
            p_min: self.p_min.min(b.p_min),
            p_max: self.p_max.max(b.p_max),
        }
    }
    /// The intersection of two boxes (empty if they do not overlap).
    #[inline]
    pub fn intersect(&self, b: &Bounds3f) -> Bounds3f {
        Bounds3f {
            p_min: self.p_min.max(b.p_min),
            p_max: self.p_max.min(b.p_max),
        }
    }
    /// True if the boxes share at least one point.
    #[inline]
    pub fn overlaps(&self, b: &Bounds3f) -> bool {
        self.p_max.x >= b.p_min.x
            && self.p_min.x <= b.p_max.x
            && self.p_max.y >= b.p_min.y
            && self.p_min.y <= b.p_max.y
            && self.p_max.z >= b.p_min.z
            && self.p_min.z <= b.p_max.z
    }
    /// True if `p` lies inside or on the boundary.
    #[inline]
    pub fn inside(&self, p: Point3f) -> bool {
        p.x >= self.p_min.x
            && p.x <= self.p_max.x
            && p.y >= self.p_min.y
            && p.y <= self.p_max.y
            && p.z >= self.p_min.z
            && p.z <= self.p_max.z
    }
    /// True if `p` lies inside, excluding the upper boundary.
    #[inline]
    pub fn inside_exclusive(&self, p: Point3f) -> bool {
        p.x >= self.p_min.x
            && p.x < self.p_max.x
            && p.y >= self.p_min.y
            && p.y < self.p_max.y
            && p.z >= self.p_min.z
            && p.z < self.p_max.z
    }
    /// The box padded by `delta` on every side.
    #[inline]
    pub fn expand(&self, delta: Float) -> Bounds3f {
        let d = Vector3f::new(delta, delta, delta);
        Bounds3f {
            p_min: self.p_min - d,
            p_max: self.p_max + d,
        }
    }
    /// The vector from the minimum to the maximum corner.
    #[inline]
    pub fn diagonal(&self) -> Vector3f {
        self.p_max - self.p_min
    }
    /// Surface area (zero for an empty box).
    #[inline]
    pub fn surface_area(&self) -> Float {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.x * d.z + d.y * d.z)
    }
    /// Volume (zero for an empty box).
    #[inline]
    pub fn volume(&self) -> Float {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        d.x * d.y * d.z
    }
    /// The axis along which the box is longest.
    #[inline]
    pub fn max_dimension(&self) -> usize {
        self.diagonal().max_dimension()
    }
    /// The point at parametric position `t` ∈ [0,1]³ inside the box.
    #[inline]
    pub fn lerp(&self, t: Point3f) -> Point3f {
        Point3f::new(
            lerp(t.x, self.p_min.x, self.p_max.x),
            lerp(t.y, self.p_min.y, self.p_max.y),
            lerp(t.z, self.p_min.z, self.p_max.z),
        )
    }
    /// The position of `p` relative to the box: 0 at pMin, 1 at pMax.
    #[inline]
    pub fn offset(&self, p: Point3f) -> Vector3f {
        let mut o = p - self.p_min;
        for i in 0..3 {
            if self.p_max[i] > self.p_min[i] {
                o[i] /= self.p_max[i] - self.p_min[i];
            }
        }
        o
    }
    /// A sphere (centre, radius) that holds the box.
    #[inline]
    pub fn bounding_sphere(&self) -> (Point3f, Float) {
        let center = self.p_min + (self.p_max - self.p_min) / 2.0;
        let radius = if self.inside(center) {
            center.distance(self.p_max)
        } else {
            0.0
        };
        (center, radius)
    }
    /// Squared distance from `p` to the box (zero inside).
    #[inline]
    pub fn distance_squared(&self, p: Point3f) -> Float {
        let dx = (self.p_min.x - p.x).max(0.0).max(p.x - self.p_max.x);
        let dy = (self.p_min.y - p.y).max(0.0).max(p.y - self.p_max.y);
        let dz = (self.p_min.z - p.z).max(0.0).max(p.z - self.p_max.z);
        dx * dx + dy * dy + dz * dz
    }
    /// Distance from `p` to the box (zero inside).
    #[inline]
    pub fn distance(&self, p: Point3f) -> Float {
        self.distance_squared(p).sqrt()
    }

    /// Slab test: the parametric range `(t0, t1)` over which the ray
    /// `o + t d`, `t ∈ [0, t_max]`, is inside the box. tFar is grown by
    /// 2γ(3) so that rounding never misses a hit (book section 6.8.7).
    #[inline]
    pub fn intersect_p(&self, o: Point3f, d: Vector3f, t_max: Float) -> Option<(Float, Float)> {
        let mut t0 = 0.0;
        let mut t1 = t_max;
        for i in 0..3 {
            let inv = 1.0 / d[i];
            let mut t_near = (self.p_min[i] - o[i]) * inv;
            let mut t_far = (self.p_max[i] - o[i]) * inv;
            if t_near > t_far {
                std::mem::swap(&mut t_near, &mut t_far);
            }
            t_far *= 1.0 + 2.0 * gamma(3);
            // Written so that NaN (0 · ∞ for a ray in a slab plane) keeps
            // the previous bound.
            t0 = if t_near > t0 { t_near } else { t0 };
            t1 = if t_far < t1 { t_far } else { t1 };
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }

    /// The slab test with a precomputed reciprocal direction and its signs
    /// (`dir_is_neg[i]` is 1 when the direction's component `i` is negative):
    /// the form used inside accelerators.
    #[inline]
    pub fn intersect_p_inv(
        &self,
        o: Point3f,
        ray_t_max: Float,
        inv_dir: Vector3f,
        dir_is_neg: [usize; 3],
    ) -> bool {
        let mut t_min = (self.get(dir_is_neg[0]).x - o.x) * inv_dir.x;
        let mut t_max = (self.get(1 - dir_is_neg[0]).x - o.x) * inv_dir.x;
        let ty_min = (self.get(dir_is_neg[1]).y - o.y) * inv_dir.y;
        let mut ty_max = (self.get(1 - dir_is_neg[1]).y - o.y) * inv_dir.y;
        t_max *= 1.0 + 2.0 * gamma(3);
        ty_max *= 1.0 + 2.0 * gamma(3);
        if t_min > ty_max || ty_min > t_max {
            return false;
        }
        if ty_min > t_min {
            t_min = ty_min;
        }
        if ty_max < t_max {
            t_max = ty_max;
        }
        let tz_min = (self.get(dir_is_neg[2]).z - o.z) * inv_dir.z;
        let mut tz_max = (self.get(1 - dir_is_neg[2]).z - o.z) * inv_dir.z;
        tz_max *= 1.0 + 2.0 * gamma(3);
        if t_min > tz_max || tz_min > t_max {
            return false;
        }
        if tz_min > t_min {
            t_min = tz_min;
        }
        if tz_max < t_max {
            t_max = tz_max;
        }
        t_min < ray_t_max && t_max > 0.0
    }

    /// The slab test for a [`Ray`].
    #[inline]
    pub fn intersect_ray(&self, r: &Ray, t_max: Float) -> Option<(Float, Float)> {
        self.intersect_p(r.o, r.d, t_max)
    }
}

/// A 2-D axis-aligned box with float coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds2f {
    /// Minimum corner.
    pub p_min: Point2f,
    /// Maximum corner.
    pub p_max: Point2f,
}

impl Default for Bounds2f {
    fn default() -> Self {
        Bounds2f {
            p_min: Point2f::new(Float::INFINITY, Float::INFINITY),
            p_max: Point2f::new(Float::NEG_INFINITY, Float::NEG_INFINITY),
        }
    }
}

impl Bounds2f {
    /// The box spanned by two corners, in any order.
    #[inline]
    pub fn new(a: Point2f, b: Point2f) -> Self {
        Bounds2f {
            p_min: a.min(b),
            p_max: a.max(b),
        }
    }
    /// True when empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.p_min.x >= self.p_max.x || self.p_min.y >= self.p_max.y
    }
    /// The vector from pMin to pMax.
    #[inline]
    pub fn diagonal(&self) -> Vector2f {
        self.p_max - self.p_min
    }
    /// Area.
    #[inline]
    pub fn area(&self) -> Float {
        let d = self.diagonal();
        d.x * d.y
    }
    /// The box grown to hold `p`.
    #[inline]
    pub fn union_point(&self, p: Point2f) -> Bounds2f {
        Bounds2f {
            p_min: self.p_min.min(p),
            p_max: self.p_max.max(p),
        }
    }
    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, b: &Bounds2f) -> Bounds2f {
        Bounds2f {
            p_min: self.p_min.min(b.p_min),
            p_max: self.p_max.max(b.p_max),
        }
    }
    /// The intersection of two boxes.
    #[inline]
    pub fn intersect(&self, b: &Bounds2f) -> Bounds2f {
        Bounds2f {
            p_min: self.p_min.max(b.p_min),
            p_max: self.p_max.min(b.p_max),
        }
    }
    /// True if the boxes overlap.
    #[inline]
    pub fn overlaps(&self, b: &Bounds2f) -> bool {
        self.p_max.x >= b.p_min.x
            && self.p_min.x <= b.p_max.x
            && self.p_max.y >= b.p_min.y
            && self.p_min.y <= b.p_max.y
    }
    /// True if `p` is inside or on the boundary.
    #[inline]
    pub fn inside(&self, p: Point2f) -> bool {
        p.x >= self.p_min.x && p.x <= self.p_max.x && p.y >= self.p_min.y && p.y <= self.p_max.y
    }
    /// True if `p` is inside, excluding the upper boundary.
    #[inline]
    pub fn inside_exclusive(&self, p: Point2f) -> bool {
        p.x >= self.p_min.x && p.x < self.p_max.x && p.y >= self.p_min.y && p.y < self.p_max.y
    }
    /// The point at parametric position `t`.
    #[inline]
    pub fn lerp(&self, t: Point2f) -> Point2f {
        Point2f::new(
            lerp(t.x, self.p_min.x, self.p_max.x),
            lerp(t.y, self.p_min.y, self.p_max.y),
        )
    }
    /// The position of `p` relative to the box.
    #[inline]
    pub fn offset(&self, p: Point2f) -> Vector2f {
        let mut o = p - self.p_min;
        if self.p_max.x > self.p_min.x {
            o.x /= self.p_max.x - self.p_min.x;
        }
        if self.p_max.y > self.p_min.y {
            o.y /= self.p_max.y - self.p_min.y;
        }
        o
    }
    /// The box padded by `delta`.
    #[inline]
    pub fn expand(&self, delta: Float) -> Bounds2f {
        let d = Vector2f::new(delta, delta);
        Bounds2f {
            p_min: self.p_min - d,
            p_max: self.p_max + d,
        }
    }
    /// The longest axis.
    #[inline]
    pub fn max_dimension(&self) -> usize {
        let d = self.diagonal();
        if d.x > d.y {
            0
        } else {
            1
        }
    }
    /// A circle (centre, radius) holding the box.
    #[inline]
    pub fn bounding_sphere(&self) -> (Point2f, Float) {
        let c = self.p_min + (self.p_max - self.p_min) / 2.0;
        let r = if self.inside(c) {
            c.distance(self.p_max)
        } else {
            0.0
        };
        (c, r)
    }
}

/// A 2-D box of integer coordinates (pixel ranges), half-open in use:
/// iteration visits `p_min ≤ p < p_max`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Bounds2i {
    /// Minimum corner (inclusive).
    pub p_min: Point2i,
    /// Maximum corner (exclusive when iterating).
    pub p_max: Point2i,
}

impl Default for Bounds2i {
    fn default() -> Self {
        Bounds2i {
            p_min: Point2i::new(i32::MAX, i32::MAX),
            p_max: Point2i::new(i32::MIN, i32::MIN),
        }
    }
}

impl Bounds2i {
    /// The box spanned by two corners, in any order.
    #[inline]
    pub fn new(a: Point2i, b: Point2i) -> Self {
        Bounds2i {
            p_min: a.min(b),
            p_max: a.max(b),
        }
    }
    /// True when the box holds no pixel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.p_min.x >= self.p_max.x || self.p_min.y >= self.p_max.y
    }
    /// The extent.
    #[inline]
    pub fn diagonal(&self) -> Vector2i {
        self.p_max - self.p_min
    }
    /// The number of pixels (zero when empty), as i64 to avoid overflow.
    #[inline]
    pub fn area(&self) -> i64 {
        if self.is_empty() {
            return 0;
        }
        let d = self.diagonal();
        d.x as i64 * d.y as i64
    }
    /// The intersection.
    #[inline]
    pub fn intersect(&self, b: &Bounds2i) -> Bounds2i {
        Bounds2i {
            p_min: self.p_min.max(b.p_min),
            p_max: self.p_max.min(b.p_max),
        }
    }
    /// The union.
    #[inline]
    pub fn union(&self, b: &Bounds2i) -> Bounds2i {
        Bounds2i {
            p_min: self.p_min.min(b.p_min),
            p_max: self.p_max.max(b.p_max),
        }
    }
    /// True if `p` is inside (excluding the upper boundary).
    #[inline]
    pub fn inside_exclusive(&self, p: Point2i) -> bool {
        p.x >= self.p_min.x && p.x < self.p_max.x && p.y >= self.p_min.y && p.y < self.p_max.y
    }
    /// Iterates over the pixels `p_min ≤ p < p_max`, row by row.
    #[inline]
    pub fn iter(&self) -> Bounds2iIter {
        Bounds2iIter {
            b: *self,
            p: self.p_min,
        }
    }
}

impl IntoIterator for Bounds2i {
    type Item = Point2i;
    type IntoIter = Bounds2iIter;
    fn into_iter(self) -> Bounds2iIter {
        self.iter()
    }
}

/// Iterator over the integer points of a [`Bounds2i`].
#[derive(Clone, Debug)]
pub struct Bounds2iIter {
    b: Bounds2i,
    p: Point2i,
}

impl Iterator for Bounds2iIter {
    type Item = Point2i;
    #[inline]
    fn next(&mut self) -> Option<Point2i> {
        if self.b.is_empty() || self.p.y >= self.b.p_max.y {
            return None;
        }
        let cur = self.p;
        self.p.x += 1;
        if self.p.x >= self.b.p_max.x {
            self.p.x = self.b.p_min.x;
            self.p.y += 1;
        }
        Some(cur)
    }
}

/// A 3-D box of integer coordinates (voxel ranges).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Bounds3i {
    /// Minimum corner.
    pub p_min: Point3i,
    /// Maximum corner.
    pub p_max: Point3i,
}

impl Bounds3i {
    /// The box spanned by two corners, in any order.
    #[inline]
    pub fn new(a: Point3i, b: Point3i) -> Self {
        Bounds3i {
            p_min: a.min(b),
            p_max: a.max(b),
        }
    }
    /// True when the box holds no voxel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.p_min.x >= self.p_max.x || self.p_min.y >= self.p_max.y || self.p_min.z >= self.p_max.z
    }
    /// Iterates over `p_min ≤ p < p_max`, x fastest.
    pub fn iter(&self) -> impl Iterator<Item = Point3i> {
        let b = *self;
        let empty = b.is_empty();
        (b.p_min.z..b.p_max.z)
            .flat_map(move |z| {
                (b.p_min.y..b.p_max.y)
                    .flat_map(move |y| (b.p_min.x..b.p_max.x).map(move |x| Point3i::new(x, y, z)))
            })
            .filter(move |_| !empty)
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
    fn empty_by_default() {
        let b = Bounds3f::default();
        assert!(b.is_empty());
        let p = Point3f::new(1.0, 2.0, 3.0);
        assert_eq!(b.union_point(p), Bounds3f::from_point(p));
        assert_eq!(b.surface_area(), 0.0);
        assert_eq!(b.volume(), 0.0);
        assert!(!b.inside(p));
    }

    #[test]
    fn basic_ops() {
        let a = Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(2.0, 1.0, 1.0));
        let b = Bounds3f::new(Point3f::new(1.0, 0.5, -1.0), Point3f::new(3.0, 3.0, 0.5));
        assert!(a.overlaps(&b));
        let i = a.intersect(&b);
        assert_eq!(
            i,
            Bounds3f::new(Point3f::new(1.0, 0.5, 0.0), Point3f::new(2.0, 1.0, 0.5))
        );
        assert_eq!(a.surface_area(), 2.0 * (2.0 + 2.0 + 1.0));
        assert_eq!(a.volume(), 2.0);
        assert_eq!(a.max_dimension(), 0);
        assert_eq!(
            a.lerp(Point3f::new(0.5, 0.5, 0.5)),
            Point3f::new(1.0, 0.5, 0.5)
        );
        assert_eq!(
            a.offset(Point3f::new(1.0, 0.5, 0.5)),
            Vector3f::new(0.5, 0.5, 0.5)
        );
        assert!(a.inside(Point3f::new(2.0, 1.0, 1.0)));
        assert!(!a.inside_exclusive(Point3f::new(2.0, 1.0, 1.0)));
        assert_eq!(a.distance(Point3f::new(5.0, 0.5, 0.5)), 3.0);
        assert_eq!(a.distance(Point3f::new(1.0, 0.5, 0.5)), 0.0);
        let (c, r) = a.bounding_sphere();
        for i in 0..8 {
            assert!(c.distance(a.corner(i)) <= r + 1e-6);
        }
        let far = Bounds3f::new(Point3f::new(5.0, 5.0, 5.0), Point3f::new(6.0, 6.0, 6.0));
        assert!(!a.overlaps(&far) && a.intersect(&far).is_empty());
    }

    #[test]
    fn ray_box_slab() {
        let b = Bounds3f::new(Point3f::new(-1.0, -1.0, -1.0), Point3f::new(1.0, 1.0, 1.0));
        let (t0, t1) = b
            .intersect_p(
                Point3f::new(-5.0, 0.0, 0.0),
                Vector3f::new(1.0, 0.0, 0.0),
                Float::INFINITY,
            )
            .unwrap();
        assert!((t0 - 4.0).abs() < 1e-6 && t1 >= 6.0);
        // Ray starting inside.
        let (t0, _) = b
            .intersect_p(
                Point3f::new(0.0, 0.0, 0.0),
                Vector3f::new(0.0, 1.0, 0.0),
                Float::INFINITY,
            )
            .unwrap();
        assert_eq!(t0, 0.0);
        // Miss, and tMax too short.
        assert!(b
            .intersect_p(
                Point3f::new(-5.0, 2.0, 0.0),
                Vector3f::new(1.0, 0.0, 0.0),
                Float::INFINITY
            )
            .is_none());
        assert!(b
            .intersect_p(
                Point3f::new(-5.0, 0.0, 0.0),
                Vector3f::new(1.0, 0.0, 0.0),
                3.0
            )
            .is_none());
        // Agreement of the two forms on random rays.
        let mut s = 99u64;
        for _ in 0..20000 {
            let o = Point3f::new(
                rng(&mut s) * 8.0 - 4.0,
                rng(&mut s) * 8.0 - 4.0,
                rng(&mut s) * 8.0 - 4.0,
            );
            let d = Vector3f::new(rng(&mut s) - 0.5, rng(&mut s) - 0.5, rng(&mut s) - 0.5);
            let t_max = rng(&mut s) * 10.0;
            let inv = Vector3f::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
            let neg = [
                (d.x < 0.0) as usize,
                (d.y < 0.0) as usize,
                (d.z < 0.0) as usize,
            ];
            let a = b.intersect_p(o, d, t_max).is_some();
            let c = b.intersect_p_inv(o, t_max, inv, neg);
            if a != c {
                // Only allowed to disagree at grazing boundaries.
                let (t0, t1) = b.intersect_p(o, d, Float::INFINITY).unwrap_or((0.0, 0.0));
                assert!((t0 - t_max).abs() < 1e-3 || t1.abs() < 1e-3 || (t1 - t0).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn axis_parallel_rays() {
        let b = Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(1.0, 1.0, 1.0));
        let d = Vector3f::new(0.0, 0.0, 1.0);
        let inv = Vector3f::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        assert!(b
            .intersect_p(Point3f::new(0.5, 0.5, -1.0), d, Float::INFINITY)
            .is_some());
        assert!(b.intersect_p_inv(
            Point3f::new(0.5, 0.5, -1.0),
            Float::INFINITY,
            inv,
            [0, 0, 0]
        ));
        assert!(b
            .intersect_p(Point3f::new(1.5, 0.5, -1.0), d, Float::INFINITY)
            .is_none());
        assert!(!b.intersect_p_inv(
            Point3f::new(1.5, 0.5, -1.0),
            Float::INFINITY,
            inv,
            [0, 0, 0]
        ));
    }

    #[test]
    fn integer_iteration() {
        let b = Bounds2i::new(Point2i::new(1, 2), Point2i::new(3, 4));
        let pts: Vec<_> = b.iter().collect();
        assert_eq!(
            pts,
            vec![
                Point2i::new(1, 2),
                Point2i::new(2, 2),
                Point2i::new(1, 3),
                Point2i::new(2, 3)
            ]
        );
        assert_eq!(b.area(), 4);
        let e = Bounds2i::new(Point2i::new(1, 2), Point2i::new(1, 4));
        assert_eq!(e.iter().count(), 0);
        let b3 = Bounds3i::new(Point3i::new(0, 0, 0), Point3i::new(2, 2, 2));
        assert_eq!(b3.iter().count(), 8);
    }

    #[test]
    fn bounds2f_ops() {
        let b = Bounds2f::new(Point2f::new(0.0, 0.0), Point2f::new(2.0, 1.0));
        assert_eq!(b.area(), 2.0);
        assert!(b.inside(Point2f::new(2.0, 1.0)));
        assert!(!b.inside_exclusive(Point2f::new(2.0, 1.0)));
        assert_eq!(b.max_dimension(), 0);
        assert!(Bounds2f::default()
            .union_point(Point2f::new(1.0, 1.0))
            .inside(Point2f::new(1.0, 1.0)));
    }
}
