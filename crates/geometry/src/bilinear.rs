//! Inverting a bilinear map: the (u, v) parameters of a point inside a
//! quadrilateral with given corners (pbrt-v4 `util/math.h` `InvertBilinear`,
//! used by bilinear patches, book section 6.6, and bilinear sampling).

use crate::float::*;
use crate::tuple::Point2f;

/// The parametric coordinates (u, v) of `p` in the bilinear patch with
/// corners `v = [v00, v10, v01, v11]` (so that `p = lerp(u, lerp(v, v00,
/// v01), lerp(v, v10, v11))`), by Newton's method from the centre.
pub fn invert_bilinear(p: Point2f, v: [Point2f; 4]) -> Point2f {
    let mut u = 0.5f64;
    let mut w = 0.5f64;
    let c = |q: Point2f| (q.x as f64, q.y as f64);
    let (p00, p10, p01, p11) = (c(v[0]), c(v[1]), c(v[2]), c(v[3]));
    let (px, py) = c(p);
    for _ in 0..32 {
        let fx = (1.0 - u) * (1.0 - w) * p00.0
            + u * (1.0 - w) * p10.0
            + (1.0 - u) * w * p01.0
            + u * w * p11.0
            - px;
        let fy = (1.0 - u) * (1.0 - w) * p00.1
            + u * (1.0 - w) * p10.1
            + (1.0 - u) * w * p01.1
            + u * w * p11.1
            - py;
        let dxu = (1.0 - w) * (p10.0 - p00.0) + w * (p11.0 - p01.0);
        let dyu = (1.0 - w) * (p10.1 - p00.1) + w * (p11.1 - p01.1);
        let dxw = (1.0 - u) * (p01.0 - p00.0) + u * (p11.0 - p10.0);
        let dyw = (1.0 - u) * (p01.1 - p00.1) + u * (p11.1 - p10.1);
        let det = dxu * dyw - dxw * dyu;
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let du = (fx * dyw - fy * dxw) / det;
        let dw = (fy * dxu - fx * dyu) / det;
        u -= du;
        w -= dw;
        if du.abs() < 1e-12 && dw.abs() < 1e-12 {
            break;
        }
    }
    Point2f::new(u as Float, w as Float)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_the_parameters_of_a_bilinear_point() {
        let v = [
            Point2f::new(0.0, 0.0),
            Point2f::new(2.0, 0.2),
            Point2f::new(0.1, 1.0),
            Point2f::new(1.8, 1.5),
        ];
        let (u, w) = (0.3f32, 0.7f32);
        let lerp2 = |t: Float, a: Point2f, b: Point2f| {
            Point2f::new((1.0 - t) * a.x + t * b.x, (1.0 - t) * a.y + t * b.y)
        };
        let p = lerp2(u, lerp2(w, v[0], v[2]), lerp2(w, v[1], v[3]));
        let uv = invert_bilinear(p, v);
        assert!((uv.x - u).abs() < 1e-5 && (uv.y - w).abs() < 1e-5, "{uv:?}");
    }
}
