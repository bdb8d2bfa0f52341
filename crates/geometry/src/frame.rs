//! Orthonormal frames (book section 3.3.3): conversion between a local
//! coordinate system and the one it is expressed in.

use crate::tuple::*;

/// Three orthonormal vectors x, y, z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First basis vector.
    pub x: Vector3f,
    /// Second basis vector.
    pub y: Vector3f,
    /// Third basis vector.
    pub z: Vector3f,
}

impl Default for Frame {
    fn default() -> Self {
        Frame {
            x: Vector3f::new(1.0, 0.0, 0.0),
            y: Vector3f::new(0.0, 1.0, 0.0),
            z: Vector3f::new(0.0, 0.0, 1.0),
        }
    }
}

impl Frame {
    /// A frame from three orthonormal vectors.
    #[inline]
    pub fn new(x: Vector3f, y: Vector3f, z: Vector3f) -> Self {
        Frame { x, y, z }
    }
    /// The frame whose x axis is `x` and y axis is `y` (z = x × y).
    #[inline]
    pub fn from_xy(x: Vector3f, y: Vector3f) -> Self {
        Frame {
            x,
            y,
            z: cross(x, y),
        }
    }
    /// The frame whose x and z axes are given (y = z × x).
    #[inline]
    pub fn from_xz(x: Vector3f, z: Vector3f) -> Self {
        Frame {
            x,
            y: cross(z, x),
            z,
        }
    }
    /// A frame with z axis `z` (unit length), the others chosen robustly.
    #[inline]
    pub fn from_z(z: Vector3f) -> Self {
        let (x, y) = z.coordinate_system();
        Frame { x, y, z }
    }
    /// A frame with x axis `x`.
    #[inline]
    pub fn from_x(x: Vector3f) -> Self {
        let (y, z) = x.coordinate_system();
        Frame { x, y, z }
    }
    /// A frame with z axis along normal `n`.
    #[inline]
    pub fn from_normal(n: Normal3f) -> Self {
        Frame::from_z(Vector3f::from(n))
    }
    /// Expresses `v` in the frame's local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vector3f) -> Vector3f {
        Vector3f::new(dot(v, self.x), dot(v, self.y), dot(v, self.z))
    }
    /// Expresses a normal in local coordinates.
    #[inline]
    pub fn to_local_normal(&self, n: Normal3f) -> Normal3f {
        Normal3f::new(dot(n, self.x), dot(n, self.y), dot(n, self.z))
    }
    /// Converts local coordinates back.
    #[inline]
    pub fn from_local(&self, v: Vector3f) -> Vector3f {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
    /// Converts a local normal back.
    #[inline]
    pub fn from_local_normal(&self, n: Normal3f) -> Normal3f {
        Normal3f::from(self.x * n.x + self.y * n.y + self.z * n.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let f = Frame::from_z(Vector3f::new(1.0, 2.0, 3.0).normalize());
        let v = Vector3f::new(0.3, -0.7, 2.0);
        let back = f.from_local(f.to_local(v));
        assert!((back - v).length() < 1e-5);
        assert!((f.to_local(f.z) - Vector3f::new(0.0, 0.0, 1.0)).length() < 1e-5);
        let g = Frame::from_xz(f.x, f.z);
        assert!((g.y - f.y).length() < 1e-5);
    }
}
