//! Points and vectors with error intervals: [`Point3fi`] and [`Vector3fi`]
//! (book section 6.8.5 "Robust Spawned Ray Origins"; pbrt-v4
//! `util/vecmath.h` `Point3fi` / `Vector3fi`). Each coordinate is an
//! [`Interval`] bounding the rounding error of the computation that produced
//! it; intersection routines return their hit points this way so that spawned
//! rays can be offset past the error.

use crate::float::*;
use crate::interval::Interval;
use crate::tuple::{Point3f, Vector3f};
use std::ops::{Add, Div, Index, Mul, Sub};

/// A point whose coordinates are intervals bounding the rounding error of
/// the computation that produced it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point3fi {
    /// x interval.
    pub x: Interval,
    /// y interval.
    pub y: Interval,
    /// z interval.
    pub z: Interval,
}

/// A vector whose components are error intervals.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vector3fi {
    /// x interval.
    pub x: Interval,
    /// y interval.
    pub y: Interval,
    /// z interval.
    pub z: Interval,
}

macro_rules! interval_tuple {
    ($name:ident, $plain:ident) => {
        impl $name {
            /// Builds the tuple from three intervals.
            #[inline]
            pub const fn new(x: Interval, y: Interval, z: Interval) -> Self {
                $name { x, y, z }
            }
            /// A value with per-component absolute error bounds `e`.
            #[inline]
            pub fn from_value_and_error(p: $plain, e: Vector3f) -> Self {
                $name::new(
                    Interval::from_value_and_error(p.x, e.x),
                    Interval::from_value_and_error(p.y, e.y),
                    Interval::from_value_and_error(p.z, e.z),
                )
            }
            /// The midpoint of each interval: the best estimate of the value.
            #[inline]
            pub fn midpoint(self) -> $plain {
                $plain::new(self.x.midpoint(), self.y.midpoint(), self.z.midpoint())
            }
            /// Half-widths of the intervals: the absolute error bound.
            #[inline]
            pub fn error(self) -> Vector3f {
                Vector3f::new(
                    self.x.width() / 2.0,
                    self.y.width() / 2.0,
                    self.z.width() / 2.0,
                )
            }
            /// True when every component is exact.
            #[inline]
            pub fn is_exact(self) -> bool {
                self.x.is_exact() && self.y.is_exact() && self.z.is_exact()
            }
        }
        impl From<$plain> for $name {
            #[inline]
            fn from(p: $plain) -> Self {
                $name::new(Interval::new(p.x), Interval::new(p.y), Interval::new(p.z))
            }
        }
        impl Index<usize> for $name {
            type Output = Interval;
            #[inline]
            fn index(&self, i: usize) -> &Interval {
                match i {
                    0 => &self.x,
                    1 => &self.y,
                    _ => &self.z,
                }
            }
        }
        impl Mul<Interval> for $name {
            type Output = $name;
            #[inline]
            fn mul(self, s: Interval) -> $name {
                $name::new(self.x * s, self.y * s, self.z * s)
            }
        }
        impl Mul<Float> for $name {
            type Output = $name;
            #[inline]
            fn mul(self, s: Float) -> $name {
                $name::new(self.x * s, self.y * s, self.z * s)
            }
        }
        impl Div<Interval> for $name {
            type Output = $name;
            #[inline]
            fn div(self, s: Interval) -> $name {
                $name::new(self.x / s, self.y / s, self.z / s)
            }
        }
    };
}
interval_tuple!(Point3fi, Point3f);
interval_tuple!(Vector3fi, Vector3f);

impl Sub for Point3fi {
    type Output = Vector3fi;
    #[inline]
    fn sub(self, o: Point3fi) -> Vector3fi {
        Vector3fi::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Add<Vector3fi> for Point3fi {
    type Output = Point3fi;
    #[inline]
    fn add(self, v: Vector3fi) -> Point3fi {
        Point3fi::new(self.x + v.x, self.y + v.y, self.z + v.z)
    }
}
impl Add for Point3fi {
    type Output = Point3fi;
    #[inline]
    fn add(self, v: Point3fi) -> Point3fi {
        Point3fi::new(self.x + v.x, self.y + v.y, self.z + v.z)
    }
}
impl Sub<Vector3fi> for Point3fi {
    type Output = Point3fi;
    #[inline]
    fn sub(self, v: Vector3fi) -> Point3fi {
        Point3fi::new(self.x - v.x, self.y - v.y, self.z - v.z)
    }
}
impl Add for Vector3fi {
    type Output = Vector3fi;
    #[inline]
    fn add(self, v: Vector3fi) -> Vector3fi {
        Vector3fi::new(self.x + v.x, self.y + v.y, self.z + v.z)
    }
}

impl Vector3fi {
    /// The interval dot product.
    pub fn dot(self, o: Vector3fi) -> Interval {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// The interval cross product.
    pub fn cross(self, o: Vector3fi) -> Vector3fi {
        Vector3fi::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
}

impl Point3fi {
    /// Interval squared distance between two points.
    pub fn distance_squared(self, o: Point3fi) -> Interval {
        let d = self - o;
        d.x.sqr() + d.y.sqr() + d.z.sqr()
    }
    /// Interval distance between two points.
    pub fn distance(self, o: Point3fi) -> Interval {
        self.distance_squared(o).sqrt()
    }
}

#[cfg(test)]
mod tests;
