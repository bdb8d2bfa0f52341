//! Quaternions for rotation interpolation (book section 3.11).

use crate::float::*;
use crate::transform::{SquareMatrix4, Transform};
use crate::tuple::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A quaternion `w + v·(i, j, k)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quaternion {
    /// The imaginary part.
    pub v: Vector3f,
    /// The real part.
    pub w: Float,
}

impl Default for Quaternion {
    /// The identity rotation.
    fn default() -> Self {
        Quaternion {
            v: Vector3f::default(),
            w: 1.0,
        }
    }
}

impl Quaternion {
    /// The dot product of two quaternions.
    #[inline]
    pub fn dot(self, q: Quaternion) -> Float {
        dot(self.v, q.v) + self.w * q.w
    }
    /// Unit-length copy.
    #[inline]
    pub fn normalize(self) -> Quaternion {
        self / self.dot(self).sqrt()
    }
    /// The angle between two unit quaternions, stable near 0 and π.
    pub fn angle_between(self, q: Quaternion) -> Float {
        if self.dot(q) < 0.0 {
            PI - 2.0 * safe_asin((self + q).length() / 2.0)
        } else {
            2.0 * safe_asin((q - self).length() / 2.0)
        }
    }
    fn length(self) -> Float {
        self.dot(self).sqrt()
    }

    /// The rotation quaternion of a transformation's rotation part
    /// (Shoemake's method).
    pub fn from_transform(t: &Transform) -> Quaternion {
        let m = &t.matrix().m;
        let trace = m[0][0] + m[1][1] + m[2][2];
        if trace > 0.0 {
            let mut s = (trace + 1.0).sqrt();
            let w = s / 2.0;
            s = 0.5 / s;
            Quaternion {
                v: Vector3f::new(
                    (m[2][1] - m[1][2]) * s,
                    (m[0][2] - m[2][0]) * s,
                    (m[1][0] - m[0][1]) * s,
                ),
                w,
            }
        } else {
            let nxt = [1usize, 2, 0];
            let mut q = [0.0; 3];
            let mut i = 0;
            if m[1][1] > m[0][0] {
                i = 1;
            }
            if m[2][2] > m[i][i] {
                i = 2;
            }
            let j = nxt[i];
            let k = nxt[j];
            let mut s = ((m[i][i] - (m[j][j] + m[k][k])) + 1.0).sqrt();
            q[i] = s * 0.5;
            if s != 0.0 {
                s = 0.5 / s;
            }
            let w = (m[k][j] - m[j][k]) * s;
            q[j] = (m[j][i] + m[i][j]) * s;
            q[k] = (m[k][i] + m[i][k]) * s;
            Quaternion {
                v: Vector3f::new(q[0], q[1], q[2]),
                w,
            }
        }
    }

    /// The rotation this unit quaternion represents.
    pub fn to_transform(self) -> Transform {
        let (xx, yy, zz) = (
            self.v.x * self.v.x,
            self.v.y * self.v.y,
            self.v.z * self.v.z,
        );
        let (xy, xz, yz) = (
            self.v.x * self.v.y,
            self.v.x * self.v.z,
            self.v.y * self.v.z,
        );
        let (wx, wy, wz) = (self.v.x * self.w, self.v.y * self.w, self.v.z * self.w);
        let mut m = SquareMatrix4::identity();
        m.m[0][0] = 1.0 - 2.0 * (yy + zz);
        m.m[0][1] = 2.0 * (xy + wz);
        m.m[0][2] = 2.0 * (xz - wy);
        m.m[1][0] = 2.0 * (xy - wz);
        m.m[1][1] = 1.0 - 2.0 * (xx + zz);
        m.m[1][2] = 2.0 * (yz + wx);
        m.m[2][0] = 2.0 * (xz + wy);
        m.m[2][1] = 2.0 * (yz - wx);
        m.m[2][2] = 1.0 - 2.0 * (xx + yy);
        // The matrix above is the transpose of the rotation (left-handed).
        Transform::from_matrices(m.transpose(), m)
    }

    /// Spherical linear interpolation between unit quaternions.
    pub fn slerp(t: Float, q1: Quaternion, q2: Quaternion) -> Quaternion {
        let theta = q1.angle_between(q2);
        let sin_theta_over_theta = sin_x_over_x(theta);
        q1 * ((1.0 - t) * sin_x_over_x((1.0 - t) * theta) / sin_theta_over_theta)
            + q2 * (t * sin_x_over_x(t * theta) / sin_theta_over_theta)
    }
}

impl Add for Quaternion {
    type Output = Quaternion;
    fn add(self, q: Quaternion) -> Quaternion {
        Quaternion {
            v: self.v + q.v,
            w: self.w + q.w,
        }
    }
}
impl Sub for Quaternion {
    type Output = Quaternion;
    fn sub(self, q: Quaternion) -> Quaternion {
        Quaternion {
            v: self.v - q.v,
            w: self.w - q.w,
        }
    }
}
impl Neg for Quaternion {
    type Output = Quaternion;
    fn neg(self) -> Quaternion {
        Quaternion {
            v: -self.v,
            w: -self.w,
        }
    }
}
impl Mul<Float> for Quaternion {
    type Output = Quaternion;
    fn mul(self, f: Float) -> Quaternion {
        Quaternion {
            v: self.v * f,
            w: self.w * f,
        }
    }
}
impl Div<Float> for Quaternion {
    type Output = Quaternion;
    fn div(self, f: Float) -> Quaternion {
        Quaternion {
            v: self.v / f,
            w: self.w / f,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_round_trip() {
        for (theta, axis) in [
            (30.0, Vector3f::new(1.0, 0.0, 0.0)),
            (170.0, Vector3f::new(0.2, 1.0, -0.4)),
            (-95.0, Vector3f::new(0.0, 0.0, 1.0)),
            (179.0, Vector3f::new(1.0, 1.0, 1.0)),
        ] {
            let r = Transform::rotate(theta, axis);
            let q = Quaternion::from_transform(&r);
            let back = q.normalize().to_transform();
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (r.matrix().m[i][j] - back.matrix().m[i][j]).abs() < 1e-5,
                        "{theta} {axis:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn slerp_halfway() {
        let q0 = Quaternion::from_transform(&Transform::rotate_z(0.0));
        let q1 = Quaternion::from_transform(&Transform::rotate_z(90.0));
        let h = Quaternion::slerp(0.5, q0, q1).to_transform();
        let v = h.apply_vector(Vector3f::new(1.0, 0.0, 0.0));
        let s = 0.5f32.sqrt();
        assert!((v - Vector3f::new(s, s, 0.0)).length() < 1e-5, "{v:?}");
        assert!((Quaternion::slerp(0.0, q0, q1).dot(q0) - 1.0).abs() < 1e-6);
    }
}
