//! Small colour types: XYZ and RGB triples, 3×3 colour matrices and the
//! sigmoid-polynomial spectra of Jakob and Hanika (pbrt-v4 book sections
//! 4.6.1 and 4.6.5; pbrt-v4 `util/color.h`).

use std::ops::{Add, Div, Index, IndexMut, Mul, Sub};

use rpbrt_geometry::Float;

use super::{LAMBDA_MAX, LAMBDA_MIN};

macro_rules! triple {
    ($name:ident, $a:ident, $b:ident, $c:ident, $doc:literal) => {
        #[doc = $doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct $name {
            #[doc = "First component."]
            pub $a: Float,
            #[doc = "Second component."]
            pub $b: Float,
            #[doc = "Third component."]
            pub $c: Float,
        }

        impl $name {
            /// A triple from its components.
            #[inline]
            pub const fn new($a: Float, $b: Float, $c: Float) -> Self {
                $name { $a, $b, $c }
            }
            /// The components as an array.
            #[inline]
            pub const fn to_array(self) -> [Float; 3] {
                [self.$a, self.$b, self.$c]
            }
            /// A triple from an array.
            #[inline]
            pub const fn from_array(v: [Float; 3]) -> Self {
                $name {
                    $a: v[0],
                    $b: v[1],
                    $c: v[2],
                }
            }
            /// The mean of the components.
            #[inline]
            pub fn average(self) -> Float {
                (self.$a + self.$b + self.$c) / 3.0
            }
            /// The largest component.
            #[inline]
            pub fn max_component_value(self) -> Float {
                self.$a.max(self.$b).max(self.$c)
            }
            /// The smallest component.
            #[inline]
            pub fn min_component_value(self) -> Float {
                self.$a.min(self.$b).min(self.$c)
            }
        }

        impl Index<usize> for $name {
            type Output = Float;
            #[inline]
            fn index(&self, i: usize) -> &Float {
                match i {
                    0 => &self.$a,
                    1 => &self.$b,
                    _ => &self.$c,
                }
            }
        }
        impl IndexMut<usize> for $name {
            #[inline]
            fn index_mut(&mut self, i: usize) -> &mut Float {
                match i {
                    0 => &mut self.$a,
                    1 => &mut self.$b,
                    _ => &mut self.$c,
                }
            }
        }
        impl Add for $name {
            type Output = $name;
            #[inline]
            fn add(self, o: $name) -> $name {
                $name::new(self.$a + o.$a, self.$b + o.$b, self.$c + o.$c)
            }
        }
        impl Sub for $name {
            type Output = $name;
            #[inline]
            fn sub(self, o: $name) -> $name {
                $name::new(self.$a - o.$a, self.$b - o.$b, self.$c - o.$c)
            }
        }
        impl Mul for $name {
            type Output = $name;
            #[inline]
            fn mul(self, o: $name) -> $name {
                $name::new(self.$a * o.$a, self.$b * o.$b, self.$c * o.$c)
            }
        }
        impl Mul<Float> for $name {
            type Output = $name;
            #[inline]
            fn mul(self, s: Float) -> $name {
                $name::new(self.$a * s, self.$b * s, self.$c * s)
            }
        }
        impl Mul<$name> for Float {
            type Output = $name;
            #[inline]
            fn mul(self, v: $name) -> $name {
                v * self
            }
        }
        impl Div<Float> for $name {
            type Output = $name;
            #[inline]
            fn div(self, s: Float) -> $name {
                $name::new(self.$a / s, self.$b / s, self.$c / s)
            }
        }
        impl Div for $name {
            type Output = $name;
            #[inline]
            fn div(self, o: $name) -> $name {
                $name::new(self.$a / o.$a, self.$b / o.$b, self.$c / o.$c)
            }
        }
    };
}

triple!(XYZ, x, y, z, "A CIE XYZ tristimulus value.");
triple!(RGB, r, g, b, "An RGB colour in some colour space.");

impl XYZ {
    /// The xy chromaticity `(X / (X+Y+Z), Y / (X+Y+Z))`.
    #[inline]
    pub fn xy(self) -> [Float; 2] {
        let s = self.x + self.y + self.z;
        [self.x / s, self.y / s]
    }

    /// The XYZ value with chromaticity `xy` and luminance `y_lum`; black
    /// when `xy[1]` is zero.
    #[inline]
    pub fn from_xyy(xy: [Float; 2], y_lum: Float) -> XYZ {
        if xy[1] == 0.0 {
            return XYZ::new(0.0, 0.0, 0.0);
        }
        XYZ::new(
            xy[0] * y_lum / xy[1],
            y_lum,
            (1.0 - xy[0] - xy[1]) * y_lum / xy[1],
        )
    }
}

/// A 3×3 matrix acting on colour triples, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorMatrix {
    /// The rows.
    pub m: [[Float; 3]; 3],
}

impl ColorMatrix {
    /// The identity.
    pub const IDENTITY: ColorMatrix = ColorMatrix {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    /// A matrix from its rows.
    #[inline]
    pub const fn new(m: [[Float; 3]; 3]) -> Self {
        ColorMatrix { m }
    }

    /// A diagonal matrix.
    #[inline]
    pub const fn diag(a: Float, b: Float, c: Float) -> Self {
        ColorMatrix {
            m: [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]],
        }
    }

    /// The product with a column vector.
    #[inline]
    pub fn apply(&self, v: [Float; 3]) -> [Float; 3] {
        let m = &self.m;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }

    /// The matrix product `self * o`.
    pub fn mul(&self, o: &ColorMatrix) -> ColorMatrix {
        let mut r = [[0.0; 3]; 3];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| self.m[i][k] * o.m[k][j]).sum();
            }
        }
        ColorMatrix { m: r }
    }

    /// The inverse (computed in double precision), or `None` when singular.
    pub fn inverse(&self) -> Option<ColorMatrix> {
        let a = self.m.map(|r| r.map(f64::from));
        let cof = |r0: usize, r1: usize, c0: usize, c1: usize| {
            a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
        };
        let det = a[0][0] * cof(1, 2, 1, 2) - a[0][1] * cof(1, 2, 0, 2) + a[0][2] * cof(1, 2, 0, 1);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = [
            [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
            [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
            [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
        ];
        Some(ColorMatrix {
            m: inv.map(|r| r.map(|v| (v / det) as Float)),
        })
    }
}

/// A reflectance-like spectrum `s(c0 λ² + c1 λ + c2)` with the sigmoid
/// `s(x) = 1/2 + x / (2 sqrt(1 + x²))`, always in `[0, 1]` (Jakob and
/// Hanika 2019; pbrt-v4 `RGBSigmoidPolynomial`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RgbSigmoidPolynomial {
    /// Coefficient of λ².
    pub c0: Float,
    /// Coefficient of λ.
    pub c1: Float,
    /// Constant term.
    pub c2: Float,
}

impl RgbSigmoidPolynomial {
    /// A polynomial from its coefficients.
    #[inline]
    pub const fn new(c0: Float, c1: Float, c2: Float) -> Self {
        RgbSigmoidPolynomial { c0, c1, c2 }
    }

    /// The spectrum's value at `lambda` nm.
    #[inline]
    pub fn evaluate(&self, lambda: Float) -> Float {
        sigmoid((self.c0 * lambda + self.c1) * lambda + self.c2)
    }

    /// [`RgbSigmoidPolynomial::evaluate`] at each of `lambda`, bit for bit,
    /// written without branches so that the lanes are computed together.
    #[inline(always)]
    pub fn evaluate_n<const N: usize>(&self, lambda: &[Float; N]) -> [Float; N] {
        let mut out = [0.0; N];
        for i in 0..N {
            let x = (self.c0 * lambda[i] + self.c1) * lambda[i] + self.c2;
            let y = 0.5 + x / (2.0 * (1.0 + x * x).sqrt());
            let at_infinity = if x > 0.0 { 1.0 } else { 0.0 };
            out[i] = if x.is_infinite() { at_infinity } else { y };
        }
        out
    }

    /// The largest value over `[LAMBDA_MIN, LAMBDA_MAX]`: at an end or at the
    /// polynomial's extremum.
    pub fn max_value(&self) -> Float {
        let mut result = self.evaluate(LAMBDA_MIN).max(self.evaluate(LAMBDA_MAX));
        let lambda = -self.c1 / (2.0 * self.c0);
        if (LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
            result = result.max(self.evaluate(lambda));
        }
        result
    }
}

/// The sigmoid mapping the real line onto `(0, 1)`, exact at ±∞.
#[inline]
pub fn sigmoid(x: Float) -> Float {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}
