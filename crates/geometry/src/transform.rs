//! Transformations (book section 3.9–3.10; pbrt-v4 `util/transform.h`):
//! a 4×4 matrix kept with its inverse, applied to points (with homogeneous
//! divide and error bounds), vectors, normals, rays and boxes.

use crate::bounds::Bounds3f;
use crate::float::*;
use crate::interval::Interval;
use crate::ray::{Ray, RayDifferential};
use crate::tuple::*;
use std::fmt;
use std::ops::Mul;

/// A 4×4 matrix, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SquareMatrix4 {
    /// The entries, `m[row][column]`.
    pub m: [[Float; 4]; 4],
}

impl Default for SquareMatrix4 {
    fn default() -> Self {
        SquareMatrix4::identity()
    }
}

impl SquareMatrix4 {
    /// Applies this matrix as a transformation to a ray, as
    /// [`Transform::apply_ray`] does (which reads only the forward matrix):
    /// for a transformation known by one matrix alone.
    #[inline]
    pub fn apply_ray(&self, r: &Ray, t_max: Float) -> (Ray, Float) {
        Transform {
            m: *self,
            m_inv: *self,
        }
        .apply_ray(r, t_max)
    }

    /// The identity matrix.
    #[inline]
    pub const fn identity() -> Self {
        SquareMatrix4 {
            m: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
        }
    }
    /// A matrix from its rows.
    #[inline]
    pub const fn new(m: [[Float; 4]; 4]) -> Self {
        SquareMatrix4 { m }
    }
    /// True for the identity.
    pub fn is_identity(&self) -> bool {
        *self == SquareMatrix4::identity()
    }
    /// The transpose.
    pub fn transpose(&self) -> SquareMatrix4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.m[j][i];
            }
        }
        SquareMatrix4 { m: r }
    }
    /// The inverse, or `None` when the matrix is singular (or not finite).
    /// Gauss–Jordan elimination with full pivoting in double precision.
    pub fn inverse(&self) -> Option<SquareMatrix4> {
        let mut a = [[0.0f64; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] = self.m[i][j] as f64;
            }
        }
        let mut indxc = [0usize; 4];
        let mut indxr = [0usize; 4];
        let mut ipiv = [0u8; 4];
        for i in 0..4 {
            let mut irow = 0;
            let mut icol = 0;
            let mut big = 0.0f64;
            for j in 0..4 {
                if ipiv[j] != 1 {
                    for k in 0..4 {
                        if ipiv[k] == 0 {
                            if a[j][k].abs() >= big {
                                big = a[j][k].abs();
                                irow = j;
                                icol = k;
                            }
                        } else if ipiv[k] > 1 {
                            return None;
                        }
                    }
                }
            }
            ipiv[icol] += 1;
            if irow != icol {
                a.swap(irow, icol);
            }
            indxr[i] = irow;
            indxc[i] = icol;
            if a[icol][icol] == 0.0 || !a[icol][icol].is_finite() {
                return None;
            }
            let pivinv = 1.0 / a[icol][icol];
            a[icol][icol] = 1.0;
            for j in 0..4 {
                a[icol][j] *= pivinv;
            }
            for j in 0..4 {
                if j != icol {
                    let save = a[j][icol];
                    a[j][icol] = 0.0;
                    for k in 0..4 {
                        a[j][k] -= a[icol][k] * save;
                    }
                }
            }
        }
        for j in (0..4).rev() {
            if indxr[j] != indxc[j] {
                for row in a.iter_mut() {
                    row.swap(indxr[j], indxc[j]);
                }
            }
        }
        let mut r = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                r[i][j] = a[i][j] as Float;
                if !r[i][j].is_finite() {
                    return None;
                }
            }
        }
        Some(SquareMatrix4 { m: r })
    }
    /// `d` if this is exactly the translation by `d` (the identity but for
    /// the last column's first three entries).
    #[inline]
    fn translation(&self) -> Option<[Float; 3]> {
        let m = &self.m;
        let is = m[0][0] == 1.0
            && m[0][1] == 0.0
            && m[0][2] == 0.0
            && m[1][0] == 0.0
            && m[1][1] == 1.0
            && m[1][2] == 0.0
            && m[2][0] == 0.0
            && m[2][1] == 0.0
            && m[2][2] == 1.0
            && m[3] == [0.0, 0.0, 0.0, 1.0];
        is.then(|| [m[0][3], m[1][3], m[2][3]])
    }

    /// True when every entry is finite.
    #[inline]
    fn is_finite(&self) -> bool {
        self.m.iter().flatten().all(|v| v.is_finite())
    }

    /// `self * t`, for `t` the translation by `d` and `self` finite: the
    /// bits of the full product. Each entry of the product is the
    /// compensated [`inner_product`] of a row and a column, and a term
    /// that is an exact zero (a finite value times one of `t`'s zeros)
    /// changes neither the sum nor its error term there, so only the
    /// other terms are summed, in the same order.
    fn times_translation(&self, d: [Float; 3]) -> SquareMatrix4 {
        let mut r = [[0.0; 4]; 4];
        for (row, out) in self.m.iter().zip(r.iter_mut()) {
            for j in 0..3 {
                out[j] = inner_product(&[row[j]], &[1.0]);
            }
            out[3] = inner_product(row, &[d[0], d[1], d[2], 1.0]);
        }
        SquareMatrix4 { m: r }
    }

    /// `t * n`, for `t` the translation by `d` and `n` finite, as
    /// [`Self::times_translation`] computes its product.
    fn translation_times(d: [Float; 3], n: &SquareMatrix4) -> SquareMatrix4 {
        let n = &n.m;
        let mut r = [[0.0; 4]; 4];
        for j in 0..4 {
            for i in 0..3 {
                r[i][j] = inner_product(&[1.0, d[i]], &[n[i][j], n[3][j]]);
            }
            r[3][j] = inner_product(&[1.0], &[n[3][j]]);
        }
        SquareMatrix4 { m: r }
    }

    /// The determinant of the upper-left 3×3 block.
    pub fn determinant3(&self) -> Float {
        let m = &self.m;
        let minor12 = difference_of_products(m[1][1], m[2][2], m[1][2], m[2][1]);
        let minor02 = difference_of_products(m[1][0], m[2][2], m[1][2], m[2][0]);
        let minor01 = difference_of_products(m[1][0], m[2][1], m[1][1], m[2][0]);
        m[0][2].mul_add(
            minor01,
            difference_of_products(m[0][0], minor12, m[0][1], minor02),
        )
    }
}

impl Mul for SquareMatrix4 {
    type Output = SquareMatrix4;
    /// Each entry is the compensated [`inner_product`] of a row and a
    /// column, its operations in the same order, but the sixteen entries
    /// are taken a term at a time together (straight loops over sixteen
    /// lanes that the compiler vectorizes), not one after another: a
    /// scene of a million object instances composes millions of these.
    fn mul(self, o: SquareMatrix4) -> SquareMatrix4 {
        // Entry e is row e / 4 of `self` times column e % 4 of `o`.
        let mut v = [0.0 as Float; 16];
        let mut err = [0.0 as Float; 16];
        for k in 0..4 {
            let a: [Float; 16] = std::array::from_fn(|e| self.m[e / 4][k]);
            let b: [Float; 16] = std::array::from_fn(|e| o.m[k][e % 4]);
            for e in 0..16 {
                // `two_prod`, `two_sum` and the error sum of
                // `inner_product`, written out.
                let ab = a[e] * b[e];
                let p_err = (a[e] as f64 * b[e] as f64 - ab as f64) as Float;
                let s = v[e] + ab;
                let delta = s - v[e];
                let s_err = (v[e] - (s - delta)) + (ab - delta);
                err[e] = err[e] + p_err + s_err;
                v[e] = s;
            }
        }
        SquareMatrix4 {
            m: std::array::from_fn(|i| std::array::from_fn(|j| v[4 * i + j] + err[4 * i + j])),
        }
    }
}

/// Why a transformation could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum TransformError {
    /// The matrix has no inverse.
    Singular,
    /// `LookAt` with an up vector parallel to the viewing direction, or with
    /// the eye at the look-at point.
    DegenerateLookAt,
    /// A rotation about the zero vector.
    ZeroAxis,
    /// Invalid perspective parameters (fov out of (0,180), near ≥ far...).
    BadProjection,
}

impl fmt::Display for TransformError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransformError::Singular => {
                write!(f, "transformation matrix is singular (not invertible)")
            }
            TransformError::DegenerateLookAt => {
                write!(f, "\"up\" vector and viewing direction are parallel, or eye and look-at points coincide")
            }
            TransformError::ZeroAxis => write!(f, "rotation axis has zero length"),
            TransformError::BadProjection => write!(f, "invalid projection parameters"),
        }
    }
}

impl std::error::Error for TransformError {}

/// A transformation: its matrix and the matrix's inverse.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Transform {
    m: SquareMatrix4,
    m_inv: SquareMatrix4,
}

impl Transform {
    /// Whether `self` and `o` hold the same bits (unlike `==`, which takes
    /// −0 for 0 and no NaN for itself): then any computation gives the
    /// same result for either.
    pub fn same_bits(&self, o: &Transform) -> bool {
        let same = |a: &SquareMatrix4, b: &SquareMatrix4| {
            let mut differ = 0;
            for (ra, rb) in a.m.iter().zip(&b.m) {
                for (x, y) in ra.iter().zip(rb) {
                    differ |= x.to_bits() ^ y.to_bits();
                }
            }
            differ == 0
        };
        same(&self.m, &o.m) && same(&self.m_inv, &o.m_inv)
    }

    /// The identity transformation.
    #[inline]
    pub const fn identity() -> Self {
        Transform {
            m: SquareMatrix4::identity(),
            m_inv: SquareMatrix4::identity(),
        }
    }
    /// A transform from a matrix, inverting it.
    pub fn from_matrix(m: SquareMatrix4) -> Result<Self, TransformError> {
        let m_inv = m.inverse().ok_or(TransformError::Singular)?;
        Ok(Transform { m, m_inv })
    }
    /// A transform from a matrix and its known inverse.
    #[inline]
    pub const fn from_matrices(m: SquareMatrix4, m_inv: SquareMatrix4) -> Self {
        Transform { m, m_inv }
    }
    /// The matrix.
    #[inline]
    pub fn matrix(&self) -> &SquareMatrix4 {
        &self.m
    }
    /// The inverse matrix.
    #[inline]
    pub fn inverse_matrix(&self) -> &SquareMatrix4 {
        &self.m_inv
    }
    /// The inverse transformation.
    #[inline]
    pub fn inverse(&self) -> Transform {
        Transform {
            m: self.m_inv,
            m_inv: self.m,
        }
    }
    /// The transpose.
    #[inline]
    pub fn transpose(&self) -> Transform {
        Transform {
            m: self.m.transpose(),
            m_inv: self.m_inv.transpose(),
        }
    }
    /// True for the identity.
    #[inline]
    pub fn is_identity(&self) -> bool {
        self.m.is_identity()
    }
    /// True when the transformation scales lengths along some axis.
    pub fn has_scale(&self, tolerance: Float) -> bool {
        let la2 = self
            .apply_vector(Vector3f::new(1.0, 0.0, 0.0))
            .length_squared();
        let lb2 = self
            .apply_vector(Vector3f::new(0.0, 1.0, 0.0))
            .length_squared();
        let lc2 = self
            .apply_vector(Vector3f::new(0.0, 0.0, 1.0))
            .length_squared();
        (la2 - 1.0).abs() > tolerance
            || (lb2 - 1.0).abs() > tolerance
            || (lc2 - 1.0).abs() > tolerance
    }
    /// True when the transformation turns a left-handed frame right-handed
    /// (negative determinant of the linear part).
    #[inline]
    pub fn swaps_handedness(&self) -> bool {
        self.m.determinant3() < 0.0
    }

    /// Translation by `d`.
    pub fn translate(d: Vector3f) -> Transform {
        let m = SquareMatrix4::new([
            [1.0, 0.0, 0.0, d.x],
            [0.0, 1.0, 0.0, d.y],
            [0.0, 0.0, 1.0, d.z],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let mi = SquareMatrix4::new([
            [1.0, 0.0, 0.0, -d.x],
            [0.0, 1.0, 0.0, -d.y],
            [0.0, 0.0, 1.0, -d.z],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform { m, m_inv: mi }
    }
    /// Non-uniform scale. A zero factor gives a transform whose inverse has
    /// infinities, as in pbrt.
    pub fn scale(x: Float, y: Float, z: Float) -> Transform {
        let m = SquareMatrix4::new([
            [x, 0.0, 0.0, 0.0],
            [0.0, y, 0.0, 0.0],
            [0.0, 0.0, z, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let mi = SquareMatrix4::new([
            [1.0 / x, 0.0, 0.0, 0.0],
            [0.0, 1.0 / y, 0.0, 0.0],
            [0.0, 0.0, 1.0 / z, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform { m, m_inv: mi }
    }
    /// Rotation about the x axis by `theta` degrees.
    pub fn rotate_x(theta: Float) -> Transform {
        let (s, c) = radians(theta).sin_cos();
        let m = SquareMatrix4::new([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c, -s, 0.0],
            [0.0, s, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform {
            m,
            m_inv: m.transpose(),
        }
    }
    /// Rotation about the y axis by `theta` degrees.
    pub fn rotate_y(theta: Float) -> Transform {
        let (s, c) = radians(theta).sin_cos();
        let m = SquareMatrix4::new([
            [c, 0.0, s, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [-s, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform {
            m,
            m_inv: m.transpose(),
        }
    }
    /// Rotation about the z axis by `theta` degrees.
    pub fn rotate_z(theta: Float) -> Transform {
        let (s, c) = radians(theta).sin_cos();
        let m = SquareMatrix4::new([
            [c, -s, 0.0, 0.0],
            [s, c, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform {
            m,
            m_inv: m.transpose(),
        }
    }
    /// Rotation by `theta` degrees about `axis` (normalized here). A zero
    /// axis yields the identity; use [`Transform::try_rotate`] to detect it.
    pub fn rotate(theta: Float, axis: Vector3f) -> Transform {
        Transform::try_rotate(theta, axis).unwrap_or_default()
    }
    /// Rotation by `theta` degrees about `axis`, failing on a zero axis.
    pub fn try_rotate(theta: Float, axis: Vector3f) -> Result<Transform, TransformError> {
        let a = axis.try_normalize().ok_or(TransformError::ZeroAxis)?;
        let (s, c) = radians(theta).sin_cos();
        Ok(Transform::rotate_sc(s, c, a))
    }
    /// Rotation with given sine and cosine about unit axis `a`.
    pub fn rotate_sc(sin_theta: Float, cos_theta: Float, a: Vector3f) -> Transform {
        let (s, c) = (sin_theta, cos_theta);
        let mut m = SquareMatrix4::identity();
        m.m[0][0] = a.x * a.x + (1.0 - a.x * a.x) * c;
        m.m[0][1] = a.x * a.y * (1.0 - c) - a.z * s;
        m.m[0][2] = a.x * a.z * (1.0 - c) + a.y * s;
        m.m[1][0] = a.x * a.y * (1.0 - c) + a.z * s;
        m.m[1][1] = a.y * a.y + (1.0 - a.y * a.y) * c;
        m.m[1][2] = a.y * a.z * (1.0 - c) - a.x * s;
        m.m[2][0] = a.x * a.z * (1.0 - c) - a.y * s;
        m.m[2][1] = a.y * a.z * (1.0 - c) + a.x * s;
        m.m[2][2] = a.z * a.z + (1.0 - a.z * a.z) * c;
        Transform {
            m,
            m_inv: m.transpose(),
        }
    }
    /// The rotation taking unit vector `from` to unit vector `to`
    /// (reflection-based construction, robust when they are nearly equal
    /// or opposite).
    pub fn rotate_from_to(from: Vector3f, to: Vector3f) -> Transform {
        let refl = if from.x.abs() < 0.72 && to.x.abs() < 0.72 {
            Vector3f::new(1.0, 0.0, 0.0)
        } else if from.y.abs() < 0.72 && to.y.abs() < 0.72 {
            Vector3f::new(0.0, 1.0, 0.0)
        } else {
            Vector3f::new(0.0, 0.0, 1.0)
        };
        let u = refl - from;
        let v = refl - to;
        let (uu, vv, uv) = (dot(u, u), dot(v, v), dot(u, v));
        let mut r = SquareMatrix4::identity();
        for i in 0..3 {
            for j in 0..3 {
                let kd = if i == j { 1.0 } else { 0.0 };
                r.m[i][j] = kd - 2.0 / uu * u[i] * u[j] - 2.0 / vv * v[i] * v[j]
                    + 4.0 * uv / (uu * vv) * v[i] * u[j];
            }
        }
        Transform {
            m: r,
            m_inv: r.transpose(),
        }
    }
    /// The camera-from-world transformation of a camera at `pos` looking at
    /// `look` with the given `up` direction (left-handed, as pbrt).
    pub fn look_at(pos: Point3f, look: Point3f, up: Vector3f) -> Result<Transform, TransformError> {
        let dir = (look - pos)
            .try_normalize()
            .ok_or(TransformError::DegenerateLookAt)?;
        let upn = up.try_normalize().ok_or(TransformError::DegenerateLookAt)?;
        let right = cross(upn, dir);
        if right.length() < 1e-6 {
            return Err(TransformError::DegenerateLookAt);
        }
        let right = right.normalize();
        let new_up = cross(dir, right);
        let world_from_camera = SquareMatrix4::new([
            [right.x, new_up.x, dir.x, pos.x],
            [right.y, new_up.y, dir.y, pos.y],
            [right.z, new_up.z, dir.z, pos.z],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let camera_from_world = world_from_camera
            .inverse()
            .ok_or(TransformError::Singular)?;
        Ok(Transform {
            m: camera_from_world,
            m_inv: world_from_camera,
        })
    }
    /// Orthographic projection: z in [near, far] maps to [0, 1].
    pub fn orthographic(z_near: Float, z_far: Float) -> Result<Transform, TransformError> {
        if z_far == z_near || !(z_far - z_near).is_finite() {
            return Err(TransformError::BadProjection);
        }
        Ok(Transform::scale(1.0, 1.0, 1.0 / (z_far - z_near))
            * Transform::translate(Vector3f::new(0.0, 0.0, -z_near)))
    }
    /// Perspective projection with field of view `fov` degrees: points at
    /// z = near map to 0 and z = far to 1, x and y divided by z.
    pub fn perspective(fov: Float, n: Float, f: Float) -> Result<Transform, TransformError> {
        if !(fov > 0.0 && fov < 180.0) || f <= n || n <= 0.0 && f <= 0.0 {
            return Err(TransformError::BadProjection);
        }
        let persp = SquareMatrix4::new([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, f / (f - n), -f * n / (f - n)],
            [0.0, 0.0, 1.0, 0.0],
        ]);
        let inv_tan = 1.0 / (radians(fov) / 2.0).tan();
        Ok(Transform::scale(inv_tan, inv_tan, 1.0) * Transform::from_matrix(persp)?)
    }

    /// Applies the transformation to a point, with the homogeneous divide.
    #[inline]
    pub fn apply_point(&self, p: Point3f) -> Point3f {
        let m = &self.m.m;
        let xp = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
        let yp = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
        let zp = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
        let wp = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
        if wp == 1.0 {
            Point3f::new(xp, yp, zp)
        } else {
            Point3f::new(xp, yp, zp) / wp
        }
    }
    /// Applies the inverse transformation to a point.
    #[inline]
    pub fn apply_inverse_point(&self, p: Point3f) -> Point3f {
        self.inverse().apply_point(p)
    }
    /// Applies the transformation to a vector (no translation).
    #[inline]
    pub fn apply_vector(&self, v: Vector3f) -> Vector3f {
        let m = &self.m.m;
        Vector3f::new(
            m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
        )
    }
    /// Applies the inverse to a vector.
    #[inline]
    pub fn apply_inverse_vector(&self, v: Vector3f) -> Vector3f {
        self.inverse().apply_vector(v)
    }
    /// Applies the transformation to a normal: multiplication by the
    /// inverse transpose keeps it perpendicular to transformed tangents.
    #[inline]
    pub fn apply_normal(&self, n: Normal3f) -> Normal3f {
        let mi = &self.m_inv.m;
        Normal3f::new(
            mi[0][0] * n.x + mi[1][0] * n.y + mi[2][0] * n.z,
            mi[0][1] * n.x + mi[1][1] * n.y + mi[2][1] * n.z,
            mi[0][2] * n.x + mi[1][2] * n.y + mi[2][2] * n.z,
        )
    }
    /// Applies the inverse to a normal.
    #[inline]
    pub fn apply_inverse_normal(&self, n: Normal3f) -> Normal3f {
        self.inverse().apply_normal(n)
    }

    /// Applies the transformation to a point carrying error intervals; the
    /// result bounds the rounding error of the transformation too
    /// (book section 6.8.5).
    pub fn apply_point_fi(&self, p: Point3fi) -> Point3fi {
        let m = &self.m.m;
        let (x, y, z) = (p.x.midpoint(), p.y.midpoint(), p.z.midpoint());
        let xp = (m[0][0] * x + m[0][1] * y) + (m[0][2] * z + m[0][3]);
        let yp = (m[1][0] * x + m[1][1] * y) + (m[1][2] * z + m[1][3]);
        let zp = (m[2][0] * x + m[2][1] * y) + (m[2][2] * z + m[2][3]);
        let wp = (m[3][0] * x + m[3][1] * y) + (m[3][2] * z + m[3][3]);
        let mut err = Vector3f::new(
            gamma(3)
                * ((m[0][0] * x).abs() + (m[0][1] * y).abs() + (m[0][2] * z).abs() + m[0][3].abs()),
            gamma(3)
                * ((m[1][0] * x).abs() + (m[1][1] * y).abs() + (m[1][2] * z).abs() + m[1][3].abs()),
            gamma(3)
                * ((m[2][0] * x).abs() + (m[2][1] * y).abs() + (m[2][2] * z).abs() + m[2][3].abs()),
        );
        if !p.is_exact() {
            let e = p.error();
            for (i, row) in m.iter().enumerate().take(3) {
                err[i] += (gamma(3) + 1.0)
                    * (row[0].abs() * e.x + row[1].abs() * e.y + row[2].abs() * e.z);
            }
        }
        let pt = Point3f::new(xp, yp, zp);
        if wp == 1.0 {
            Point3fi::from_value_and_error(pt, err)
        } else {
            // A projective transform: fall back to interval arithmetic.
            let w = Interval::from_value_and_error(wp, gamma(3) * wp.abs());
            Point3fi::from_value_and_error(pt, err) / w
        }
    }

    /// Applies the transformation to a vector with error intervals.
    pub fn apply_vector_fi(&self, v: Vector3fi) -> Vector3fi {
        let m = &self.m.m;
        let (x, y, z) = (v.x.midpoint(), v.y.midpoint(), v.z.midpoint());
        let mut err = Vector3f::default();
        for (i, row) in m.iter().enumerate().take(3) {
            err[i] = gamma(3) * ((row[0] * x).abs() + (row[1] * y).abs() + (row[2] * z).abs());
        }
        if !v.is_exact() {
            let e = v.error();
            for (i, row) in m.iter().enumerate().take(3) {
                err[i] += (gamma(3) + 1.0)
                    * (row[0].abs() * e.x + row[1].abs() * e.y + row[2].abs() * e.z);
            }
        }
        Vector3fi::from_value_and_error(self.apply_vector(Vector3f::new(x, y, z)), err)
    }

    /// Applies the transformation to a ray. The new origin carries rounding
    /// error, so it is advanced along the direction to the edge of its error
    /// bounds, and `t_max` shortened to match; returns the ray and the new
    /// `t_max`.
    pub fn apply_ray(&self, r: &Ray, t_max: Float) -> (Ray, Float) {
        let o = self.apply_point_fi(Point3fi::from(r.o));
        let d = self.apply_vector(r.d);
        let len2 = d.length_squared();
        let mut origin = o.midpoint();
        let mut t_max = t_max;
        if len2 > 0.0 {
            let dt = dot(d.abs(), o.error()) / len2;
            origin += d * dt;
            if t_max.is_finite() {
                t_max -= dt;
            }
        }
        (
            Ray {
                o: origin,
                d,
                time: r.time,
                medium: r.medium,
            },
            t_max,
        )
    }

    /// Applies the inverse transformation to a ray (see [`Transform::apply_ray`]).
    pub fn apply_inverse_ray(&self, r: &Ray, t_max: Float) -> (Ray, Float) {
        self.inverse().apply_ray(r, t_max)
    }

    /// Applies the transformation to a ray differential.
    pub fn apply_ray_differential(
        &self,
        r: &RayDifferential,
        t_max: Float,
    ) -> (RayDifferential, Float) {
        let (ray, t) = self.apply_ray(&r.ray, t_max);
        (
            RayDifferential {
                ray,
                has_differentials: r.has_differentials,
                rx_origin: self.apply_point(r.rx_origin),
                ry_origin: self.apply_point(r.ry_origin),
                rx_direction: self.apply_vector(r.rx_direction),
                ry_direction: self.apply_vector(r.ry_direction),
            },
            t,
        )
    }

    /// The offset, when the transformation is a translation by a finite
    /// offset (or the identity).
    #[inline]
    fn finite_translation(&self) -> Option<Vector3f> {
        self.m
            .translation()
            .filter(|t| t.iter().all(|v| v.is_finite()))
            .map(|[x, y, z]| Vector3f::new(x, y, z))
    }

    /// The tight bounds of a transformed box: the box of its eight
    /// transformed corners (exact for affine transformations).
    pub fn apply_bounds(&self, b: &Bounds3f) -> Bounds3f {
        if b.is_empty() {
            return *b;
        }
        if let Some(t) = self.finite_translation() {
            let finite = |p: &Point3f| p.x.is_finite() && p.y.is_finite() && p.z.is_finite();
            if finite(&b.p_min) && finite(&b.p_max) {
                // A corner moved by a translation is the corner plus the
                // offset (the other products are by 1 and 0, exact), and
                // rounding keeps the corners' order: the same box as the
                // eight corners give (a zero's sign aside), a seventh of
                // the work (the bounds of every moving and instanced
                // shape).
                return Bounds3f {
                    p_min: b.p_min + t,
                    p_max: b.p_max + t,
                };
            }
        }
        let mut r = Bounds3f::empty();
        for i in 0..8 {
            r = r.union_point(self.apply_point(b.corner(i)));
        }
        r
    }
}

impl Mul for Transform {
    type Output = Transform;
    /// Composition: `(a * b)` applies `b` first.
    #[inline]
    fn mul(self, t2: Transform) -> Transform {
        // A translation (`Translate`, and the render space's offset from
        // world space) composes in under half the operations, to the
        // same bits.
        let finite = |t: &Transform| t.m.is_finite() && t.m_inv.is_finite();
        if let (Some(d), Some(di)) = (t2.m.translation(), t2.m_inv.translation()) {
            if finite(&self) {
                return Transform {
                    m: self.m.times_translation(d),
                    m_inv: SquareMatrix4::translation_times(di, &self.m_inv),
                };
            }
        }
        if let (Some(d), Some(di)) = (self.m.translation(), self.m_inv.translation()) {
            if finite(&t2) {
                return Transform {
                    m: SquareMatrix4::translation_times(d, &t2.m),
                    m_inv: t2.m_inv.times_translation(di),
                };
            }
        }
        Transform {
            m: self.m * t2.m,
            m_inv: t2.m_inv * self.m_inv,
        }
    }
}

impl fmt::Display for Transform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[")?;
        for (i, row) in self.m.m.iter().enumerate() {
            if i > 0 {
                write!(f, " ")?;
            }
            write!(f, "[{} {} {} {}]", row[0], row[1], row[2], row[3])?;
        }
        write!(f, "]")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Values the product tests mix in: signed zeros, ones, a subnormal,
    /// huge values of both signs, infinity and NaN (the last two).
    const SPECIAL_VALUES: [Float; 9] = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1e-40,
        -3e38,
        3e38,
        Float::INFINITY,
        Float::NAN,
    ];

    /// Composing with a translation on either side (the short path of
    /// `Transform * Transform`) gives the full products' bits (fixed seed;
    /// signed zeros, tiny and huge values; infinities and NaNs on either
    /// side, where the full products are taken; NaN for NaN).
    /// Translated boxes are what their eight transformed corners give
    /// (fixed-seed boxes and offsets over many magnitudes); infinite
    /// coordinates take the corners' way.
    #[test]
    fn translated_bounds_as_corners() {
        let mut state = 0x510e_527f_ade6_82d1u64;
        let mut next = || crate::float::spread_value(&mut state, 30, -12);
        for k in 0..3000 {
            let mut v = || Vector3f::new(next(), next(), next());
            let (t, p, q) = (v(), v(), v());
            let mut b = Bounds3f::new(Point3f::from(p), Point3f::from(q));
            if k % 100 == 0 {
                b.p_max.y = Float::INFINITY;
            }
            let xf = Transform::translate(t);
            assert_eq!(xf.finite_translation(), Some(t));
            let mut corners = Bounds3f::empty();
            for i in 0..8 {
                corners = corners.union_point(xf.apply_point(b.corner(i)));
            }
            let got = xf.apply_bounds(&b);
            let same = |a: Point3f, c: Point3f| {
                [(a.x, c.x), (a.y, c.y), (a.z, c.z)]
                    .iter()
                    .all(|&(u, w)| u == w || (u.is_nan() && w.is_nan()))
            };
            assert!(
                same(got.p_min, corners.p_min) && same(got.p_max, corners.p_max),
                "{got:?} against {corners:?}"
            );
        }
        assert!(Transform::scale(2.0, 1.0, 1.0)
            .finite_translation()
            .is_none());
    }

    #[test]
    fn translations_compose_to_the_full_products_bits() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let specials = SPECIAL_VALUES;
        let same = |a: &SquareMatrix4, b: &SquareMatrix4| {
            a.m.iter()
                .flatten()
                .zip(b.m.iter().flatten())
                .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
        };
        let mut quick = 0;
        for round in 0..20_000 {
            let mut entry = || {
                let r = crate::float::xorshift64(&mut state);
                match (r >> 58, round % 3) {
                    // Any special, infinities and NaN included (about one
                    // transform in ten holds a non-finite entry).
                    (0, _) => specials[(r % 9) as usize],
                    (1..=8, _) => specials[(r % 7) as usize],
                    (_, 0) => Float::from_bits(r as u32 & 0xbfff_ffff),
                    _ => ((r % 20_001) as Float - 10_000.0) / 997.0,
                }
            };
            let mut matrix = || SquareMatrix4 {
                m: std::array::from_fn(|_| std::array::from_fn(|_| entry())),
            };
            let other = Transform {
                m: matrix(),
                m_inv: matrix(),
            };
            let t = Transform::translate(Vector3f::new(entry(), entry(), entry()));
            quick += usize::from(other.m.is_finite() && other.m_inv.is_finite());
            for (a, b) in [(other, t), (t, other)] {
                let c = a * b;
                assert!(same(&c.m, &(a.m * b.m)), "{a} * {b}");
                assert!(same(&c.m_inv, &(b.m_inv * a.m_inv)), "{a} * {b} (inverses)");
            }
        }
        // Most rounds took the short path.
        assert!(quick > 10_000, "{quick}");
    }

    /// The product taken sixteen entries at a time is, bit for bit, the
    /// compensated inner product of each row and column (fixed seed;
    /// ordinary values, signed zeros, tiny and huge ones, infinities and
    /// NaNs, whose results must be NaN too).
    #[test]
    fn products_are_the_inner_products_bit_for_bit() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let specials = SPECIAL_VALUES;
        for round in 0..20_000 {
            let mut entry = || {
                let r = crate::float::xorshift64(&mut state);
                match (r >> 60, round % 4) {
                    (0..=1, _) => specials[(r % 9) as usize],
                    (_, 0) => Float::from_bits(r as u32),
                    _ => ((r % 20_001) as Float - 10_000.0) / 997.0,
                }
            };
            let a = SquareMatrix4 {
                m: std::array::from_fn(|_| std::array::from_fn(|_| entry())),
            };
            let b = SquareMatrix4 {
                m: std::array::from_fn(|_| std::array::from_fn(|_| entry())),
            };
            let p = a * b;
            for i in 0..4 {
                for j in 0..4 {
                    let col = [b.m[0][j], b.m[1][j], b.m[2][j], b.m[3][j]];
                    let want = inner_product(&a.m[i], &col);
                    let got = p.m[i][j];
                    assert!(
                        got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                        "{a:?} * {b:?} at ({i}, {j}): {got} against {want}"
                    );
                }
            }
        }
    }

    fn close(a: Vector3f, b: Vector3f, eps: Float) -> bool {
        (a - b).length() <= eps * (1.0 + b.length())
    }

    fn v3() -> impl Strategy<Value = Vector3f> {
        (-10.0f32..10.0, -10.0f32..10.0, -10.0f32..10.0)
            .prop_map(|(x, y, z)| Vector3f::new(x, y, z))
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 1000, rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha, ..ProptestConfig::default() })]
        #[test]
        fn rotation_inverse_is_transpose(theta in -360.0f32..360.0, axis in v3()) {
            prop_assume!(axis.length() > 1e-2);
            let r = Transform::rotate(theta, axis);
            let inv = r.matrix().inverse().unwrap();
            let t = r.matrix().transpose();
            for i in 0..4 { for j in 0..4 {
                prop_assert!((inv.m[i][j] - t.m[i][j]).abs() < 1e-4);
            }}
        }

        #[test]
        fn normals_stay_perpendicular(sx in 0.1f32..10.0, sy in 0.1f32..10.0, sz in 0.1f32..10.0,
                                      theta in -180.0f32..180.0, axis in v3(), a in v3(), b in v3()) {
            prop_assume!(axis.length() > 1e-2 && a.length() > 1e-2 && b.length() > 1e-2);
            let (a, b) = (a.normalize(), b.normalize());
            let n = cross(a, b);
            prop_assume!(n.length() > 1e-2);
            let t = Transform::rotate(theta, axis) * Transform::scale(sx, sy, sz);
            let tn = t.apply_normal(Normal3f::from(n)).normalize();
            let ta = t.apply_vector(a).normalize();
            let tb = t.apply_vector(b).normalize();
            prop_assert!(dot(tn, ta).abs() < 1e-3 && dot(tn, tb).abs() < 1e-3);
        }

        #[test]
        fn transformed_box_contains_points(theta in -180.0f32..180.0, axis in v3(), d in v3(),
                                           lo in v3(), ext in v3(), t in (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0)) {
            prop_assume!(axis.length() > 1e-2);
            let xf = Transform::translate(d) * Transform::rotate(theta, axis) * Transform::scale(2.0, 0.5, 1.5);
            let b = Bounds3f::new(Point3f::from(lo), Point3f::from(lo + ext.abs()));
            let p = b.lerp(Point3f::new(t.0, t.1, t.2));
            let tb = xf.apply_bounds(&b).expand(1e-4 * (1.0 + d.length() + lo.length() + ext.length()));
            prop_assert!(tb.inside(xf.apply_point(p)));
        }

        #[test]
        fn point_error_bounds_hold(theta in -180.0f32..180.0, axis in v3(), d in v3(), p in v3()) {
            prop_assume!(axis.length() > 1e-2);
            let xf = Transform::translate(d) * Transform::rotate(theta, axis);
            let pf = xf.apply_point_fi(Point3fi::from(Point3f::from(p)));
            // Exact result in f64.
            let m = xf.matrix().m;
            for i in 0..3 {
                let exact = m[i][0] as f64 * p.x as f64 + m[i][1] as f64 * p.y as f64 + m[i][2] as f64 * p.z as f64 + m[i][3] as f64;
                prop_assert!(pf[i].low as f64 <= exact && exact <= pf[i].high as f64);
            }
        }
    }

    #[test]
    fn rotate_120_about_diagonal_maps_x_to_y() {
        let r = Transform::rotate(120.0, Vector3f::new(1.0, 1.0, 1.0));
        let v = r.apply_vector(Vector3f::new(1.0, 0.0, 0.0));
        assert!(close(v, Vector3f::new(0.0, 1.0, 0.0), 1e-5), "{v:?}");
    }

    #[test]
    fn axis_rotations_match_general() {
        for (a, b) in [
            (
                Transform::rotate_x(30.0),
                Transform::rotate(30.0, Vector3f::new(1.0, 0.0, 0.0)),
            ),
            (
                Transform::rotate_y(30.0),
                Transform::rotate(30.0, Vector3f::new(0.0, 1.0, 0.0)),
            ),
            (
                Transform::rotate_z(30.0),
                Transform::rotate(30.0, Vector3f::new(0.0, 0.0, 1.0)),
            ),
        ] {
            for i in 0..4 {
                for j in 0..4 {
                    assert!((a.matrix().m[i][j] - b.matrix().m[i][j]).abs() < 1e-6);
                }
            }
        }
        assert!(Transform::try_rotate(10.0, Vector3f::default()).is_err());
    }

    #[test]
    fn rotate_from_to_works() {
        let pairs = [
            (Vector3f::new(1.0, 0.0, 0.0), Vector3f::new(0.0, 1.0, 0.0)),
            (Vector3f::new(0.0, 0.0, 1.0), Vector3f::new(0.0, 0.0, -1.0)),
            (
                Vector3f::new(1.0, 2.0, 3.0).normalize(),
                Vector3f::new(1.0, 2.0, 3.0).normalize(),
            ),
            (
                Vector3f::new(0.3, -0.4, 0.5).normalize(),
                Vector3f::new(-1.0, 0.2, 0.1).normalize(),
            ),
        ];
        for (from, to) in pairs {
            let r = Transform::rotate_from_to(from, to);
            assert!(close(r.apply_vector(from), to, 1e-5));
            assert!(!r.swaps_handedness());
        }
    }

    #[test]
    fn look_at_conventions() {
        // Camera at the origin looking down +z with +y up is the identity.
        let t = Transform::look_at(
            Point3f::new(0.0, 0.0, 0.0),
            Point3f::new(0.0, 0.0, 1.0),
            Vector3f::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        assert!(
            t.is_identity()
                || t.matrix()
                    .m
                    .iter()
                    .flatten()
                    .zip(SquareMatrix4::identity().m.iter().flatten())
                    .all(|(a, b)| (a - b).abs() < 1e-6)
        );
        // Left-handed: looking down +z with +y up, +x is to the right.
        let t = Transform::look_at(
            Point3f::new(0.0, 0.0, -5.0),
            Point3f::new(0.0, 0.0, 0.0),
            Vector3f::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        let p = t.apply_point(Point3f::new(1.0, 0.0, 0.0));
        assert!(
            close(Vector3f::from(p), Vector3f::new(1.0, 0.0, 5.0), 1e-5),
            "{p:?}"
        );
        assert_eq!(
            Transform::look_at(
                Point3f::new(0.0, 0.0, 0.0),
                Point3f::new(0.0, 1.0, 0.0),
                Vector3f::new(0.0, 1.0, 0.0)
            ),
            Err(TransformError::DegenerateLookAt)
        );
        assert_eq!(
            Transform::look_at(
                Point3f::new(1.0, 1.0, 1.0),
                Point3f::new(1.0, 1.0, 1.0),
                Vector3f::new(0.0, 1.0, 0.0)
            ),
            Err(TransformError::DegenerateLookAt)
        );
    }

    #[test]
    fn projections() {
        let p = Transform::perspective(90.0, 1.0, 100.0).unwrap();
        let near = p.apply_point(Point3f::new(1.0, 0.0, 1.0));
        assert!((near.x - 1.0).abs() < 1e-5 && near.z.abs() < 1e-5);
        let far = p.apply_point(Point3f::new(0.0, 0.0, 100.0));
        assert!((far.z - 1.0).abs() < 1e-5);
        assert!(Transform::perspective(0.0, 1.0, 10.0).is_err());
        let o = Transform::orthographic(0.0, 2.0).unwrap();
        assert_eq!(
            o.apply_point(Point3f::new(3.0, 4.0, 1.0)),
            Point3f::new(3.0, 4.0, 0.5)
        );
    }

    #[test]
    fn predicates() {
        assert!(Transform::scale(1.0, 1.0, -1.0).swaps_handedness());
        assert!(!Transform::rotate_x(45.0).swaps_handedness());
        assert!(Transform::scale(2.0, 1.0, 1.0).has_scale(1e-3));
        assert!(!Transform::rotate_y(70.0).has_scale(1e-3));
        let t = Transform::translate(Vector3f::new(1.0, 2.0, 3.0)) * Transform::rotate_z(30.0);
        let id = t * t.inverse();
        assert!(id
            .matrix()
            .m
            .iter()
            .flatten()
            .zip(SquareMatrix4::identity().m.iter().flatten())
            .all(|(a, b)| (a - b).abs() < 1e-6));
        assert!(Transform::from_matrix(SquareMatrix4::new([[0.0; 4]; 4])).is_err());
        assert_eq!(
            Transform::translate(Vector3f::new(1.0, 0.0, 0.0))
                .transpose()
                .transpose(),
            Transform::translate(Vector3f::new(1.0, 0.0, 0.0))
        );
    }

    #[test]
    fn ray_origin_moves_to_error_edge() {
        let t = Transform::rotate(33.0, Vector3f::new(1.0, 1.0, 0.3))
            * Transform::translate(Vector3f::new(100.0, -3.0, 7.0));
        let r = Ray::new(Point3f::new(1.0, 2.0, 3.0), Vector3f::new(0.0, 0.0, 1.0));
        let (tr, tmax) = t.apply_ray(&r, 10.0);
        assert!(tmax <= 10.0);
        let expected = t.apply_point(r.o);
        assert!((tr.o - expected).length() < 1e-3);
        let (_, inf) = t.apply_ray(&r, Float::INFINITY);
        assert_eq!(inf, Float::INFINITY);
    }
}
