//! Sampling by solid angle (book sections 6.5.4 and 6.6.3; pbrt-v4
//! `util/sampling.cpp`): uniform sampling of the spherical triangle and the
//! spherical rectangle that a triangle or a rectangle subtends from a
//! reference point, with the inverse mappings that let the sampling density
//! be warped by a bilinear cos θ approximation, and the areas of spherical
//! polygons.
// `!(x > 0.0)` is deliberate throughout: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::simd::math::{self, V3};
use crate::simd::{F32Lanes, Scalar1};
use rpbrt_geometry::float::*;
use rpbrt_geometry::frame::Frame;
use rpbrt_geometry::tuple::*;

/// Area of the spherical triangle with unit-vector vertices `a`, `b`, `c`
/// (the solid angle it subtends), by the half-angle formula of Van
/// Oosterom and Strackee, which stays accurate for tiny triangles.
#[inline]
pub fn spherical_triangle_area(a: Vector3f, b: Vector3f, c: Vector3f) -> Float {
    spherical_triangle_area_lanes::<Scalar1>(lanes(a), lanes(b), lanes(c)).0
}

/// A vector as one lane.
#[inline(always)]
fn lanes(v: Vector3f) -> V3<Scalar1> {
    V3 {
        x: Scalar1(v.x),
        y: Scalar1(v.y),
        z: Scalar1(v.z),
    }
}

/// [`spherical_triangle_area`] of each lane (the scalar function is this
/// at width one, so both give the same bits).
#[inline(always)]
pub(crate) fn spherical_triangle_area_lanes<L: F32Lanes>(a: V3<L>, b: V3<L>, c: V3<L>) -> L {
    let num = a.dot(b.cross(c));
    let den = L::splat(1.0).add(a.dot(b)).add(a.dot(c)).add(b.dot(c));
    L::splat(2.0).mul(math::atan2(num, den)).abs()
}

/// Area of the spherical quadrilateral with unit-vector vertices `a`, `b`,
/// `c`, `d` in order around its boundary, from the spherical excess of its
/// interior angles; 0 when two consecutive vertices coincide.
pub fn spherical_quad_area(a: Vector3f, b: Vector3f, c: Vector3f, d: Vector3f) -> Float {
    let (axb, bxc, cxd, dxa) = (cross(a, b), cross(b, c), cross(c, d), cross(d, a));
    let (axb, bxc, cxd, dxa) = match (
        axb.try_normalize(),
        bxc.try_normalize(),
        cxd.try_normalize(),
        dxa.try_normalize(),
    ) {
        (Some(p), Some(q), Some(r), Some(s)) => (p, q, r, s),
        _ => return 0.0,
    };
    // Interior angle at each vertex: between the planes of its two edges.
    let alpha = dxa.angle_between(-axb);
    let beta = axb.angle_between(-bxc);
    let gamma = bxc.angle_between(-cxd);
    let delta = cxd.angle_between(-dxa);
    (alpha + beta + gamma + delta - 2.0 * PI).abs()
}

/// A triangle seen from a reference point: the unit directions to its
/// vertices and the solid angle it subtends.
struct SphericalTriangle {
    a: Vector3f,
    b: Vector3f,
    c: Vector3f,
    area: Float,
}

impl SphericalTriangle {
    fn new(v: &[Point3f; 3], p: Point3f) -> Option<Self> {
        let a = (v[0] - p).try_normalize()?;
        let b = (v[1] - p).try_normalize()?;
        let c = (v[2] - p).try_normalize()?;
        Self::from_dirs(a, b, c)
    }

    /// The spherical triangle of the unit directions `a`, `b`, `c`; `None`
    /// when it is degenerate.
    #[inline(always)]
    fn from_dirs(a: Vector3f, b: Vector3f, c: Vector3f) -> Option<Self> {
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            return None;
        }
        cross(b, c).try_normalize()?;
        Self::with_area(a, b, c, spherical_triangle_area(a, b, c))
    }

    /// The spherical triangle of the unit directions `a`, `b`, `c`, whose
    /// area the caller has computed with [`spherical_triangle_area`].
    #[inline(always)]
    fn with_area(a: Vector3f, b: Vector3f, c: Vector3f, area: Float) -> Option<Self> {
        if !(area > 0.0) {
            return None;
        }
        Some(SphericalTriangle { a, b, c, area })
    }
}

/// Samples a direction uniformly in the solid angle the triangle `v`
/// subtends from `p` (Arvo's method) and returns the barycentric
/// coordinates of the point it reaches on the triangle, with the density
/// per unit solid angle (1 / solid angle). `None` when the spherical
/// triangle is degenerate (zero area or `p` on the triangle's plane).
pub fn sample_spherical_triangle(
    v: [Point3f; 3],
    p: Point3f,
    u: Point2f,
) -> Option<([Float; 3], Float)> {
    let st = SphericalTriangle::new(&v, p)?;
    sample_spherical(&st, v, p, u)
}

#[inline(always)]
fn sample_spherical(
    st: &SphericalTriangle,
    v: [Point3f; 3],
    p: Point3f,
    u: Point2f,
) -> Option<([Float; 3], Float)> {
    let pt = |q: Point3f| lanes(Vector3f::new(q.x, q.y, q.z));
    let out = sample_spherical_lanes::<Scalar1>(
        [lanes(st.a), lanes(st.b), lanes(st.c)],
        Scalar1(st.area),
        [pt(v[0]), pt(v[1]), pt(v[2])],
        pt(p),
        [Scalar1(u.x), Scalar1(u.y)],
    );
    out.ok.then_some((out.b.map(|b| b.0), out.pdf.0))
}

/// A spherical triangle sample of each lane: barycentrics of the point
/// reached, the density per unit solid angle, and whether the lane has a
/// sample (the scalar code's `Some`).
pub(crate) struct SphericalSampleLanes<L: F32Lanes> {
    pub b: [L; 3],
    pub pdf: L,
    pub ok: L::Mask,
}

/// [`sample_spherical_triangle`] of each lane, given the unit directions
/// `dirs` to the vertices `v` from `p` and their solid angle `area`
/// (positive). Every lane runs every step; where the scalar code returns
/// early, the lane's `ok` is false.
#[inline(always)]
pub(crate) fn sample_spherical_lanes<L: F32Lanes>(
    dirs: [V3<L>; 3],
    area: L,
    v: [V3<L>; 3],
    p: V3<L>,
    u: [L; 2],
) -> SphericalSampleLanes<L> {
    let sp = L::splat;
    let [a, b, c] = dirs;
    let pdf = sp(1.0).div(area);

    // The interior angle α at a, between the planes of the edges ab and
    // ac, by its sine and cosine.
    let (n_ab, ok_ab) = a.cross(b).try_normalize();
    let (n_ac, ok_ac) = a.cross(c).try_normalize();
    let cos_alpha = math::clamp(n_ab.dot(n_ac), -1.0, 1.0);
    let sin_alpha = n_ab.cross(n_ac).length().min(sp(1.0));

    // Pick the area A' of the sub-triangle (a, b, c') uniformly, then find
    // cos of the arc length from a to c' that yields it. The sub-triangle's
    // angle sum is A' + π, whose sine and cosine are −sin A' and −cos A'.
    let (sin_a, cos_a) = math::sin_cos(u[0].mul(area));
    let (sin_ap, cos_ap) = (sin_a.neg(), cos_a.neg());
    let sin_phi = sin_ap.mul(cos_alpha).sub(cos_ap.mul(sin_alpha));
    let cos_phi = cos_ap.mul(cos_alpha).add(sin_ap.mul(sin_alpha));
    let k1 = cos_phi.add(cos_alpha);
    let k2 = sin_phi.sub(sin_alpha.mul(a.dot(b)));
    let cos_bp = k2
        .add(L::difference_of_products(k2, cos_phi, k1, sin_phi).mul(cos_alpha))
        .div(L::sum_of_products(k2, sin_phi, k1, cos_phi).mul(sin_alpha));
    // NaN when the triangle covers (nearly) a whole hemisphere.
    let ok_bp = L::not(cos_bp.is_nan());
    let cos_bp = math::clamp(cos_bp, -1.0, 1.0);
    let sin_bp = math::safe_sqrt(sp(1.0).sub(cos_bp.mul(cos_bp)));
    let (c_perp, ok_perp) = c.gram_schmidt(a).try_normalize();
    let cp = a.scale(cos_bp).add(c_perp.scale(sin_bp));

    // Sample uniformly in solid angle along the arc from b to c'.
    let cos_theta = sp(1.0).sub(u[1].mul(sp(1.0).sub(cp.dot(b))));
    let sin_theta = math::safe_sqrt(sp(1.0).sub(cos_theta.mul(cos_theta)));
    let (perp, has_perp) = cp.gram_schmidt(b).try_normalize();
    let w = V3::select(has_perp, b.scale(cos_theta).add(perp.scale(sin_theta)), b);

    // Barycentrics of the point where the ray (p, w) meets the triangle
    // (Möller–Trumbore with the ray's origin at p).
    let e1 = v[1].sub(v[0]);
    let e2 = v[2].sub(v[0]);
    let s1 = w.cross(e2);
    let divisor = s1.dot(e1);
    // The sampled ray grazes the triangle's plane: only possible for
    // triangles covering nearly a hemisphere.
    let graze = L::or(
        divisor.eq(sp(0.0)),
        L::not(divisor.abs().lt(sp(f32::INFINITY))),
    );
    let inv_divisor = sp(1.0).div(divisor);
    let s = p.sub(v[0]);
    let b1 = math::clamp(s.dot(s1).mul(inv_divisor), 0.0, 1.0);
    let b2 = math::clamp(w.dot(s.cross(e1)).mul(inv_divisor), 0.0, 1.0);
    let sum = b1.add(b2);
    let over = sum.gt(sp(1.0));
    let b1 = L::select(over, b1.div(sum), b1);
    let b2 = L::select(over, b2.div(sum), b2);
    let b0 = sp(1.0).sub(b1).sub(b2);
    let third = sp(1.0 / 3.0);
    SphericalSampleLanes {
        b: [
            L::select(graze, third, b0),
            L::select(graze, third, b1),
            L::select(graze, third, b2),
        ],
        pdf,
        ok: L::and(L::and(L::and(ok_ab, ok_ac), ok_bp), ok_perp),
    }
}

/// The sample `u` for which [`sample_spherical_triangle`] returns the
/// direction `w` (unit length, pointing from `p` into the triangle).
/// Returns (0.5, 0.5) for degenerate spherical triangles.
pub fn invert_spherical_triangle_sample(v: [Point3f; 3], p: Point3f, w: Vector3f) -> Point2f {
    match SphericalTriangle::new(&v, p) {
        Some(st) => invert_spherical(&st, w),
        None => Point2f::new(0.5, 0.5),
    }
}

/// [`invert_spherical_triangle_sample`] given the unit directions `dirs`
/// from the reference point to the vertices (all finite) and the solid
/// angle `area` they subtend.
pub(crate) fn invert_spherical_triangle_sample_dirs(
    dirs: [Vector3f; 3],
    area: Float,
    w: Vector3f,
) -> Point2f {
    match SphericalTriangle::with_area(dirs[0], dirs[1], dirs[2], area) {
        Some(st) => invert_spherical(&st, w),
        None => Point2f::new(0.5, 0.5),
    }
}

#[inline]
fn invert_spherical(st: &SphericalTriangle, w: Vector3f) -> Point2f {
    let (a, b, c) = (st.a, st.b, st.c);

    // c' is where the great circle through b and w meets the arc a–c.
    let cp = match cross(cross(b, w), cross(c, a)).try_normalize() {
        Some(cp) => cp,
        None => return Point2f::new(0.5, 0.5),
    };
    let cp = if dot(cp, a + c) < 0.0 { -cp } else { cp };

    // u0 is the fraction of the area in the sub-triangle (a, b, c').
    // 0.99999847691 = cos(0.1°): below that the sub-triangle is too thin to
    // measure and u0 is 0.
    let u0 = if dot(a, cp) > 0.999_998_5 {
        0.0
    } else {
        spherical_triangle_area(a, b, cp) / st.area
    };
    let u1 = (1.0 - dot(w, b)) / (1.0 - dot(cp, b));
    let fix = |x: Float| if x.is_nan() { 0.5 } else { clamp(x, 0.0, 1.0) };
    Point2f::new(fix(u0), fix(u1))
}

/// The rectangle `s + [0,1]·ex + [0,1]·ey` expressed in a frame aligned with
/// its edges, whose z axis points away from the reference point.
struct SphericalRectangle {
    frame: Frame,
    x0: Float,
    y0: Float,
    x1: Float,
    y1: Float,
    z0: Float,
    b0: Float,
    b1: Float,
    g2: Float,
    g3: Float,
    solid_angle: Float,
}

impl SphericalRectangle {
    fn new(p_ref: Point3f, s: Point3f, ex: Vector3f, ey: Vector3f) -> Self {
        let exl = ex.length();
        let eyl = ey.length();
        let mut frame = Frame::from_xy(ex / exl, ey / eyl);
        let d = frame.to_local(s - p_ref);
        let mut z0 = d.z;
        // Make z point toward the rectangle's far side so that z0 ≤ 0.
        if z0 > 0.0 {
            frame.z = -frame.z;
            z0 = -z0;
        }
        let (x0, y0) = (d.x, d.y);
        let (x1, y1) = (x0 + exl, y0 + eyl);
        let v00 = Vector3f::new(x0, y0, z0);
        let v01 = Vector3f::new(x0, y1, z0);
        let v10 = Vector3f::new(x1, y0, z0);
        let v11 = Vector3f::new(x1, y1, z0);
        let nz = |a: Vector3f, b: Vector3f| cross(a, b).try_normalize().unwrap_or_default();
        let n0 = nz(v00, v10);
        let n1 = nz(v10, v11);
        let n2 = nz(v11, v01);
        let n3 = nz(v01, v00);
        let g0 = (-n0).angle_between(n1);
        let g1 = (-n1).angle_between(n2);
        let g2 = (-n2).angle_between(n3);
        let g3 = (-n3).angle_between(n0);
        // Summed in double: the excess is a small difference of large terms.
        let solid_angle =
            (g0 as f64 + g1 as f64 + g2 as f64 + g3 as f64 - 2.0 * std::f64::consts::PI) as Float;
        SphericalRectangle {
            frame,
            x0,
            y0,
            x1,
            y1,
            z0,
            b0: n0.z,
            b1: n2.z,
            g2,
            g3,
            solid_angle,
        }
    }
}

/// Samples a point on the rectangle `s + [0,1]·ex + [0,1]·ey` (with `ex` ⟂
/// `ey`) uniformly in the solid angle it subtends from `p_ref` (Ureña,
/// Fajardo and King 2013). Returns the point and its density per unit solid
/// angle; the density is 0 when the rectangle subtends no solid angle, and
/// for tiny solid angles the point is chosen by area (the density is then
/// approximate).
pub fn sample_spherical_rectangle(
    p_ref: Point3f,
    s: Point3f,
    ex: Vector3f,
    ey: Vector3f,
    u: Point2f,
) -> (Point3f, Float) {
    let r = SphericalRectangle::new(p_ref, s, ex, ey);
    let by_area = s + ex * u.x + ey * u.y;
    if !(r.solid_angle > 0.0) {
        return (by_area, 0.0);
    }
    let pdf = 1.0 / r.solid_angle;
    if r.solid_angle < 1e-3 {
        return (by_area, pdf);
    }

    // Pick the sub-rectangle area au, then the x coordinate xu giving it.
    let au = u.x * r.solid_angle - r.g2 - r.g3;
    let fu = (au.cos() * r.b0 - r.b1) / au.sin();
    let cu = (1.0 / (sqr(fu) + sqr(r.b0)).sqrt()).copysign(fu);
    let cu = clamp(cu, -ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
    let xu = clamp(-(cu * r.z0) / safe_sqrt(1.0 - sqr(cu)), r.x0, r.x1);

    // Then y uniformly in the projected height along that column.
    let dd = (sqr(xu) + sqr(r.z0)).sqrt();
    let h0 = r.y0 / (sqr(dd) + sqr(r.y0)).sqrt();
    let h1 = r.y1 / (sqr(dd) + sqr(r.y1)).sqrt();
    let hv = h0 + u.y * (h1 - h0);
    let hvsq = sqr(hv);
    let yv = if hvsq < 1.0 - 1e-6 {
        (hv * dd) / (1.0 - hvsq).sqrt()
    } else {
        r.y1
    };
    let p = p_ref + r.frame.from_local(Vector3f::new(xu, yv, r.z0));
    if p.is_finite() {
        (p, pdf)
    } else {
        (by_area, pdf)
    }
}

/// The sample `u` for which [`sample_spherical_rectangle`] returns the
/// point `p_rect` on the rectangle.
pub fn invert_spherical_rectangle_sample(
    p_ref: Point3f,
    s: Point3f,
    ex: Vector3f,
    ey: Vector3f,
    p_rect: Point3f,
) -> Point2f {
    let r = SphericalRectangle::new(p_ref, s, ex, ey);
    if !(r.solid_angle >= 1e-3) {
        let pq = p_rect - s;
        return Point2f::new(
            clamp(dot(pq, ex) / ex.length_squared(), 0.0, 1.0),
            clamp(dot(pq, ey) / ey.length_squared(), 0.0, 1.0),
        );
    }
    let z0sq = sqr(r.z0);
    let local = r.frame.to_local(p_rect - p_ref);
    let mut xu = clamp(local.x, r.x0, r.x1);
    let yv = local.y;
    if xu == 0.0 {
        xu = 1e-10;
    }

    // Invert the x step: recover fu from xu, then the sub-area au.
    let fusq = 1.0 + z0sq / sqr(xu) - sqr(r.b0);
    let fu = fusq.sqrt().copysign(xu);
    let root = safe_sqrt(difference_of_products(r.b0, r.b0, r.b1, r.b1) + fusq);
    let mut au =
        (-(r.b1 * fu) - (r.b0 * root).copysign(fu * r.b0)).atan2(r.b0 * r.b1 - root * fu.abs());
    if au > 0.0 {
        au -= 2.0 * PI;
    }
    if fu == 0.0 {
        au = PI;
    }
    let u0 = (au + r.g2 + r.g3) / r.solid_angle;

    // Invert the y step: hv is linear in u1; of the two roots of the
    // quadratic pick the one that maps back to yv.
    let ddsq = sqr(xu) + z0sq;
    let dd = ddsq.sqrt();
    let h0 = r.y0 / (ddsq + sqr(r.y0)).sqrt();
    let h1 = r.y1 / (ddsq + sqr(r.y1)).sqrt();
    let yvsq = sqr(yv);
    let disc = (h0 - h1).abs() * (yvsq * (ddsq + yvsq)).sqrt() / (ddsq + yvsq);
    let base = difference_of_products(h0, h0, h0, h1);
    let den = sqr(h0 - h1);
    let cands = [(base - disc) / den, (base + disc) / den];
    let y_of = |u1: Float| {
        let hv = lerp(u1, h0, h1);
        (hv * dd) / (1.0 - sqr(hv)).sqrt()
    };
    let u1 = if (y_of(cands[0]) - yv).abs() < (y_of(cands[1]) - yv).abs() {
        cands[0]
    } else {
        cands[1]
    };
    let fix = |x: Float| if x.is_nan() { 0.5 } else { clamp(x, 0.0, 1.0) };
    Point2f::new(fix(u0), fix(u1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sampling::sample_uniform_sphere;

    fn rp(r: &mut Rng, s: Float) -> Point3f {
        Point3f::new(
            s * (2.0 * r.uniform_float() - 1.0),
            s * (2.0 * r.uniform_float() - 1.0),
            s * (2.0 * r.uniform_float() - 1.0),
        )
    }
    fn ru(r: &mut Rng) -> Point2f {
        Point2f::new(r.uniform_float(), r.uniform_float())
    }

    /// Double-precision ray–triangle test (Möller–Trumbore), for checks.
    fn hits_triangle(v: &[Point3f; 3], o: Point3f, d: Vector3f) -> bool {
        let f = |p: Point3f| [p.x as f64, p.y as f64, p.z as f64];
        let (p0, p1, p2) = (f(v[0]), f(v[1]), f(v[2]));
        let (o, d) = (f(o), [d.x as f64, d.y as f64, d.z as f64]);
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cr = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dt = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (e1, e2) = (sub(p1, p0), sub(p2, p0));
        let pv = cr(d, e2);
        let det = dt(e1, pv);
        if det == 0.0 {
            return false;
        }
        let tv = sub(o, p0);
        let u = dt(tv, pv) / det;
        let q = cr(tv, e1);
        let v = dt(d, q) / det;
        let t = dt(e2, q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0
    }

    fn random_triangle(r: &mut Rng) -> ([Point3f; 3], Point3f) {
        loop {
            let v = [rp(r, 1.0), rp(r, 1.0), rp(r, 1.0)];
            let p = rp(r, 2.0);
            let n = cross(v[1] - v[0], v[2] - v[0]);
            let d = dot(n.normalize(), p - v[0]).abs();
            if n.length() > 0.1 && d > 0.2 {
                return (v, p);
            }
        }
    }

    #[test]
    fn triangle_area_matches_monte_carlo() {
        let mut r = Rng::new(1, 0);
        for _ in 0..5 {
            let (v, p) = random_triangle(&mut r);
            let sa = spherical_triangle_area(
                (v[0] - p).normalize(),
                (v[1] - p).normalize(),
                (v[2] - p).normalize(),
            );
            let n = 200_000;
            let mut hits = 0;
            for _ in 0..n {
                if hits_triangle(&v, p, sample_uniform_sphere(ru(&mut r))) {
                    hits += 1;
                }
            }
            let frac = hits as Float / n as Float;
            let mc = 4.0 * PI * frac;
            // Four standard deviations of the binomial estimate.
            let sigma = 4.0 * PI * (frac * (1.0 - frac) / n as Float).sqrt();
            assert!((mc - sa).abs() < 4.0 * sigma + 1e-3, "mc {mc} sa {sa}");
        }
    }

    #[test]
    fn triangle_samples_are_uniform_and_invert() {
        let mut r = Rng::new(2, 0);
        for _ in 0..20 {
            let (v, p) = random_triangle(&mut r);
            let sa = spherical_triangle_area(
                (v[0] - p).normalize(),
                (v[1] - p).normalize(),
                (v[2] - p).normalize(),
            );
            // The sub-triangle (v0, v1, midpoint of v1v2) is where b1 ≥ b2.
            let m = v[1] + (v[2] - v[1]) * 0.5;
            let sub = spherical_triangle_area(
                (v[0] - p).normalize(),
                (v[1] - p).normalize(),
                (m - p).normalize(),
            );
            let n = 20_000;
            let mut inside = 0;
            for _ in 0..n {
                let u = ru(&mut r);
                let (b, pdf) = sample_spherical_triangle(v, p, u).expect("valid triangle");
                assert!(b.iter().all(|&x| (-1e-6..=1.0 + 1e-6).contains(&x)));
                assert!((b[0] + b[1] + b[2] - 1.0).abs() < 1e-5);
                assert!((pdf * sa - 1.0).abs() < 1e-3, "pdf {pdf} sa {sa}");
                if b[1] >= b[2] {
                    inside += 1;
                }
                let q = v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
                let w = (q - p).normalize();
                let back = invert_spherical_triangle_sample(v, p, w);
                if u.x > 0.01 && u.x < 0.99 && u.y > 0.01 && u.y < 0.99 {
                    assert!((back - u).length() < 2e-2, "u {u:?} back {back:?}");
                }
            }
            let frac = inside as Float / n as Float;
            assert!(
                (frac - sub / sa).abs() < 0.02,
                "frac {frac} expected {}",
                sub / sa
            );
        }
    }

    #[test]
    fn degenerate_triangles_return_none() {
        let v = [
            Point3f::new(0.0, 0.0, 0.0),
            Point3f::new(1.0, 0.0, 0.0),
            Point3f::new(2.0, 0.0, 0.0),
        ];
        assert!(
            sample_spherical_triangle(v, Point3f::new(0.0, 1.0, 1.0), Point2f::new(0.3, 0.3))
                .is_none()
        );
        // Reference point on the triangle's plane.
        let v = [
            Point3f::new(0.0, 0.0, 0.0),
            Point3f::new(1.0, 0.0, 0.0),
            Point3f::new(0.0, 1.0, 0.0),
        ];
        assert!(
            sample_spherical_triangle(v, Point3f::new(3.0, 3.0, 0.0), Point2f::new(0.3, 0.3))
                .is_none()
        );
        assert!(sample_spherical_triangle(v, v[0], Point2f::new(0.3, 0.3)).is_none());
        let nan = Point3f::new(Float::NAN, 0.0, 0.0);
        assert!(sample_spherical_triangle(
            [nan, v[1], v[2]],
            Point3f::new(0.0, 0.0, 1.0),
            Point2f::new(0.3, 0.3)
        )
        .is_none());
        let back = invert_spherical_triangle_sample(v, v[0], Vector3f::new(0.0, 0.0, 1.0));
        assert!(!back.has_nan());
    }

    fn random_rectangle(r: &mut Rng) -> (Point3f, Vector3f, Vector3f, Point3f) {
        loop {
            let s = rp(r, 1.0);
            let ex = Vector3f::from(rp(r, 1.0));
            let ey = cross(ex, Vector3f::from(rp(r, 1.0)));
            let p = rp(r, 2.0);
            let n = cross(ex, ey);
            if ex.length() > 0.2 && ey.length() > 0.2 && dot(n.normalize(), p - s).abs() > 0.2 {
                return (s, ex, ey, p);
            }
        }
    }

    #[test]
    fn rectangle_samples_are_uniform_and_invert() {
        let mut r = Rng::new(3, 0);
        for _ in 0..20 {
            let (s, ex, ey, p) = random_rectangle(&mut r);
            let c = |q: Point3f| (q - p).normalize();
            let (a, b, cc, d) = (c(s), c(s + ex), c(s + ex + ey), c(s + ey));
            let sa = spherical_quad_area(a, b, cc, d);
            // Two triangles make up the rectangle.
            let tri = spherical_triangle_area(a, b, cc) + spherical_triangle_area(a, cc, d);
            assert!(
                (sa - tri).abs() < 1e-3 * sa.max(1e-2),
                "quad {sa} tris {tri}"
            );
            let half = spherical_quad_area(a, c(s + ex * 0.5), c(s + ex * 0.5 + ey), d);
            let n = 20_000;
            let mut left = 0;
            for _ in 0..n {
                let u = ru(&mut r);
                let (q, pdf) = sample_spherical_rectangle(p, s, ex, ey, u);
                assert!((pdf * sa - 1.0).abs() < 2e-3, "pdf {pdf} sa {sa}");
                let l = q - s;
                let (x, y) = (
                    dot(l, ex) / ex.length_squared(),
                    dot(l, ey) / ey.length_squared(),
                );
                assert!(
                    (-1e-3..=1.001).contains(&x) && (-1e-3..=1.001).contains(&y),
                    "{x} {y}"
                );
                if x < 0.5 {
                    left += 1;
                }
                let back = invert_spherical_rectangle_sample(p, s, ex, ey, q);
                if u.x > 0.01 && u.x < 0.99 && u.y > 0.01 && u.y < 0.99 {
                    assert!((back - u).length() < 2e-2, "u {u:?} back {back:?}");
                }
            }
            let frac = left as Float / n as Float;
            assert!(
                (frac - half / sa).abs() < 0.02,
                "frac {frac} expected {}",
                half / sa
            );
        }
    }

    #[test]
    fn areas_of_known_spherical_polygons() {
        let x = Vector3f::new(1.0, 0.0, 0.0);
        let y = Vector3f::new(0.0, 1.0, 0.0);
        let z = Vector3f::new(0.0, 0.0, 1.0);
        // One octant of the sphere.
        assert!((spherical_triangle_area(x, y, z) - PI / 2.0).abs() < 1e-5);
        // A face of a cube seen from its centre: 4π / 6.
        let k = |a: Float, b: Float| Vector3f::new(a, b, 1.0).normalize();
        let q = spherical_quad_area(k(-1.0, -1.0), k(1.0, -1.0), k(1.0, 1.0), k(-1.0, 1.0));
        assert!((q - 4.0 * PI / 6.0).abs() < 1e-4, "{q}");
        assert_eq!(spherical_quad_area(x, x, y, z), 0.0);
    }
}
