//! pbrt-v3's `nurbs` shape (pbrt-v3 `shapes/nurbs.cpp`; pbrt-v2 book
//! section 3.9's non-uniform rational B-spline patch), which pbrt-v4
//! dropped, as the triangle mesh pbrt-v3 diced it into.
//!
//! pbrt-v3 evaluates the surface on a fixed 30 × 30 grid of parameter
//! values spanning [u0, u1] × [v0, v1], gives each vertex the surface
//! point, the normal ∂p/∂u × ∂p/∂v (normalized) and the parameter values
//! as its uv, and makes two triangles per grid cell. Control points are
//! given as `point3 P` (weight 1) or as homogeneous `float Pw` (x·w, y·w,
//! z·w, w), u varying fastest. The evaluation here uses the B-spline basis
//! functions and their first derivatives (the same surface and partial
//! derivatives pbrt-v3's de Boor evaluation gives) in `f64`.

use super::Edit;
use crate::loc::FileLoc;
use crate::params::ParsedParameter;

/// pbrt-v3's dicing rate in each parameter direction.
const DICE: usize = 30;

/// The largest order accepted. The evaluation is O(order²) per grid value;
/// real NURBS have orders below ten, so a larger one is a broken file.
const MAX_ORDER: usize = 1000;

/// One parameter direction of the patch, validated.
struct Direction {
    /// The order (degree + 1), at least 2.
    order: usize,
    /// The number of control points along this direction.
    n: usize,
    /// The knot vector, `n + order` non-decreasing values.
    knots: Vec<f64>,
    /// The diced parameter range.
    t0: f64,
    t1: f64,
}

/// The B-spline basis functions of one direction that are nonzero at a
/// parameter value, with their first derivatives.
struct Basis {
    /// Index of the first control point they weight.
    first: usize,
    values: Vec<f64>,
    derivs: Vec<f64>,
}

impl Direction {
    /// The knot span used at `t`: as pbrt-v3 does, the first span (from
    /// `order - 1` on) whose end is not before `t`, skipping empty spans
    /// (where pbrt-v3 would divide by zero). One exists: `t` lies in the
    /// validated range, whose last nonempty span ends at its end.
    fn span(&self, t: f64) -> usize {
        let k = &self.knots;
        (self.order - 1..self.n)
            .find(|&s| k[s] < k[s + 1] && t <= k[s + 1])
            .unwrap_or(self.n - 1)
    }

    /// The `order` basis functions nonzero at `t` (Cox–de Boor, in the
    /// triangular form of Piegl and Tiller's *The NURBS Book*, A2.2) and
    /// their derivatives from the basis one degree lower.
    fn basis(&self, t: f64) -> Basis {
        let (p, k) = (self.order - 1, &self.knots);
        let span = self.span(t);
        let mut left = vec![0.0; p + 1];
        let mut right = vec![0.0; p + 1];
        let mut n = vec![0.0; p + 1];
        let mut lower = Vec::new();
        n[0] = 1.0;
        for j in 1..=p {
            if j == p {
                lower = n[..p].to_vec();
            }
            left[j] = t - k[span + 1 - j];
            right[j] = k[span + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                let den = right[r + 1] + left[j - r];
                let tmp = if den != 0.0 { n[r] / den } else { 0.0 };
                n[r] = saved + right[r + 1] * tmp;
                saved = left[j - r] * tmp;
            }
            n[j] = saved;
        }
        // N'_{i,p} = p N_{i,p-1} / (k[i+p] - k[i]) - p N_{i+1,p-1} / (k[i+p+1] - k[i+1]);
        // the degree p-1 functions nonzero here are i = span-p+1 ..= span.
        let first = span - p;
        let pf = p as f64;
        let derivs = (0..=p)
            .map(|r| {
                let i = first + r;
                let mut d = 0.0;
                if r >= 1 {
                    let den = k[i + p] - k[i];
                    if den != 0.0 {
                        d += pf * lower[r - 1] / den;
                    }
                }
                if r < p {
                    let den = k[i + p + 1] - k[i + 1];
                    if den != 0.0 {
                        d -= pf * lower[r] / den;
                    }
                }
                d
            })
            .collect();
        Basis {
            first,
            values: n,
            derivs,
        }
    }

    /// The diced parameter values, `DICE` of them from `t0` to `t1`.
    fn grid(&self) -> Vec<f64> {
        (0..DICE)
            .map(|i| {
                let f = i as f64 / (DICE - 1) as f64;
                (1.0 - f) * self.t0 + f * self.t1
            })
            .collect()
    }
}

/// Rewrites the `nurbs` shape in `e` as the `trianglemesh` pbrt-v3 diced it
/// into; bad parameters are located errors and leave `e` unchanged.
pub(super) fn upgrade_nurbs(e: &mut Edit) {
    let Some(u) = direction(e, "u") else { return };
    let Some(v) = direction(e, "v") else { return };
    let Some(cp) = control_points(e, u.n, v.n) else {
        return;
    };
    let Some(mesh) = dice(&u, &v, &cp) else {
        e.error(
            None,
            "\"nurbs\" evaluates to a non-finite point (a zero or negative weight sum?)".into(),
        );
        return;
    };
    for n in ["nu", "nv", "uorder", "vorder"] {
        e.remove_all(n, &["integer"]);
    }
    for n in ["uknots", "vknots", "u0", "u1", "v0", "v1", "Pw"] {
        e.remove_all(n, &["float"]);
    }
    e.remove_all("P", &["point3"]);
    e.name = "trianglemesh".into();
    let loc = e.loc.clone();
    e.add_front(ParsedParameter::with_floats(
        "point3",
        "P",
        loc.clone(),
        mesh.p,
    ));
    if let Some(n) = mesh.n {
        e.add_front(ParsedParameter::with_floats("normal", "N", loc.clone(), n));
    }
    e.add_front(ParsedParameter::with_floats(
        "point2",
        "uv",
        loc.clone(),
        mesh.uv,
    ));
    let mut ip = ParsedParameter::new("integer", "indices", loc);
    ip.ints = mesh.indices;
    e.add_front(ip);
}

/// A single integer parameter and its location.
fn one_int(e: &Edit, name: &str) -> Option<(i32, FileLoc)> {
    let p = e.get(name, &["integer"])?;
    Some((*p.ints.first()?, p.loc.clone()))
}

/// Reads and checks `n{d}`, `{d}order`, `{d}knots`, `{d}0` and `{d}1` for
/// direction `d` ("u" or "v"); reports the first problem.
fn direction(e: &mut Edit, d: &str) -> Option<Direction> {
    let (n_name, order_name, knots_name) =
        (format!("n{d}"), format!("{d}order"), format!("{d}knots"));
    let Some((n, n_loc)) = one_int(e, &n_name) else {
        e.error(
            None,
            format!("\"nurbs\" needs the number of control points \"integer {n_name}\""),
        );
        return None;
    };
    let Some((order, order_loc)) = one_int(e, &order_name) else {
        e.error(
            None,
            format!("\"nurbs\" needs the order \"integer {order_name}\""),
        );
        return None;
    };
    let Some(kp) = e.get(&knots_name, &["float"]) else {
        e.error(
            None,
            format!("\"nurbs\" needs the knot vector \"float {knots_name}\""),
        );
        return None;
    };
    let (knots, knots_loc): (Vec<f64>, FileLoc) = (
        kp.floats.iter().map(|&x| x as f64).collect(),
        kp.loc.clone(),
    );
    if order < 2 || order as usize > MAX_ORDER {
        e.error(
            Some(&order_loc),
            format!("\"nurbs\" \"{order_name}\" is {order}; it must be between 2 and {MAX_ORDER}"),
        );
        return None;
    }
    if n < order {
        e.error(
            Some(&n_loc),
            format!("\"nurbs\" has {n} control points along {d}, fewer than its order {order}"),
        );
        return None;
    }
    let (n, order) = (n as usize, order as usize);
    if knots.len() != n + order {
        e.error(
            Some(&knots_loc),
            format!(
                "\"nurbs\" has {} values in \"{knots_name}\"; {n_name} + {order_name} = {} expected",
                knots.len(),
                n + order
            ),
        );
        return None;
    }
    if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
        e.error(
            Some(&knots_loc),
            format!("\"nurbs\" \"{knots_name}\" must be finite and non-decreasing"),
        );
        return None;
    }
    let (lo, hi) = (knots[order - 1], knots[n]);
    if lo >= hi {
        e.error(
            Some(&knots_loc),
            format!("\"nurbs\" \"{knots_name}\" spans an empty parameter range ({lo} to {hi})"),
        );
        return None;
    }
    let mut ends = [lo, hi];
    for (i, end) in ends.iter_mut().enumerate() {
        let name = format!("{d}{i}");
        if let Some(p) = e.get(&name, &["float"]) {
            let (Some(&x), loc) = (p.floats.first(), p.loc.clone()) else {
                continue;
            };
            let x = x as f64;
            if !(lo..=hi).contains(&x) {
                e.error(
                    Some(&loc),
                    format!(
                        "\"nurbs\" \"{name}\" is {x}, outside the knot vector's range [{lo}, {hi}]"
                    ),
                );
                return None;
            }
            *end = x;
        }
    }
    Some(Direction {
        order,
        n,
        knots,
        t0: ends[0],
        t1: ends[1],
    })
}

/// The homogeneous control points (x·w, y·w, z·w, w), `nu × nv` of them.
fn control_points(e: &mut Edit, nu: usize, nv: usize) -> Option<Vec<[f64; 4]>> {
    let (cp, loc): (Vec<[f64; 4]>, FileLoc) = if let Some(p) = e.get("P", &["point3"]) {
        let cp = p
            .floats
            .chunks_exact(3)
            .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64, 1.0])
            .collect();
        (cp, p.loc.clone())
    } else if let Some(p) = e.get("Pw", &["float"]) {
        if p.floats.len() % 4 != 0 {
            let loc = p.loc.clone();
            e.error(
                Some(&loc),
                format!(
                    "\"nurbs\" has {} \"Pw\" values, not a multiple of four",
                    p.floats.len()
                ),
            );
            return None;
        }
        let cp = p
            .floats
            .chunks_exact(4)
            .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64, c[3] as f64])
            .collect();
        (cp, p.loc.clone())
    } else {
        e.error(
            None,
            "\"nurbs\" needs control points \"point3 P\" or \"float Pw\"".into(),
        );
        return None;
    };
    if nu.checked_mul(nv) != Some(cp.len()) {
        e.error(
            Some(&loc),
            format!(
                "\"nurbs\" has {} control points; nu × nv = {nu} × {nv} expected",
                cp.len()
            ),
        );
        return None;
    }
    if cp.iter().flatten().any(|x| !x.is_finite()) {
        e.error(Some(&loc), "\"nurbs\" control points must be finite".into());
        return None;
    }
    Some(cp)
}

/// The diced mesh, in the parameter lists' layouts.
struct Mesh {
    p: Vec<f32>,
    /// `None` when some vertex has no usable normal even from its
    /// neighbours (a fully degenerate patch).
    n: Option<Vec<f32>>,
    uv: Vec<f32>,
    indices: Vec<i32>,
}

/// Evaluates the surface on pbrt-v3's grid; `None` if a point is not
/// finite.
fn dice(u: &Direction, v: &Direction, cp: &[[f64; 4]]) -> Option<Mesh> {
    let (ut, vt) = (u.grid(), v.grid());
    let ub: Vec<Basis> = ut.iter().map(|&t| u.basis(t)).collect();
    let vb: Vec<Basis> = vt.iter().map(|&t| v.basis(t)).collect();
    let mut p = Vec::with_capacity(3 * DICE * DICE);
    let mut normals: Vec<Option<[f64; 3]>> = Vec::with_capacity(DICE * DICE);
    let mut uv = Vec::with_capacity(2 * DICE * DICE);
    for (j, bv) in vb.iter().enumerate() {
        for (i, bu) in ub.iter().enumerate() {
            // The homogeneous point and its two partial derivatives.
            let (mut s, mut su, mut sv) = ([0.0; 4], [0.0; 4], [0.0; 4]);
            for (b, (&nv, &dv)) in bv.values.iter().zip(&bv.derivs).enumerate() {
                let row = (bv.first + b) * u.n;
                for (a, (&nu, &du)) in bu.values.iter().zip(&bu.derivs).enumerate() {
                    let c = &cp[row + bu.first + a];
                    for k in 0..4 {
                        s[k] += nu * nv * c[k];
                        su[k] += du * nv * c[k];
                        sv[k] += nu * dv * c[k];
                    }
                }
            }
            let w = s[3];
            let pt = [s[0] / w, s[1] / w, s[2] / w];
            if pt
                .iter()
                .any(|x| !x.is_finite() || x.abs() > f32::MAX as f64)
            {
                return None;
            }
            // d(x/w) = (x' - w' x/w) / w.
            let dpdu: [f64; 3] = std::array::from_fn(|k| (su[k] - su[3] * pt[k]) / w);
            let dpdv: [f64; 3] = std::array::from_fn(|k| (sv[k] - sv[3] * pt[k]) / w);
            // A vanishing cross product (a pole, a collapsed edge) has no
            // direction; rounding leaves a tiny one pointing anywhere.
            let n = cross(dpdu, dpdv);
            let scale = length(dpdu) * length(dpdv);
            normals.push(if length(n) > 1e-9 * scale {
                normalize(n)
            } else {
                None
            });
            p.extend(pt.map(|x| x as f32));
            uv.extend([ut[i] as f32, vt[j] as f32]);
        }
    }
    let vert = |i: usize, j: usize| (j * DICE + i) as i32;
    let mut indices = Vec::with_capacity(6 * (DICE - 1) * (DICE - 1));
    for j in 0..DICE - 1 {
        for i in 0..DICE - 1 {
            indices.extend([vert(i, j), vert(i + 1, j), vert(i + 1, j + 1)]);
            indices.extend([vert(i, j), vert(i + 1, j + 1), vert(i, j + 1)]);
        }
    }
    Some(Mesh {
        p,
        n: fill_normals(&normals),
        uv,
        indices,
    })
}

/// The normals with each missing one (a degenerate point such as the pole
/// of a NURBS sphere, where pbrt-v3 would store NaN) replaced by the
/// normalized sum of its grid neighbours' normals; `None` if that fails.
fn fill_normals(normals: &[Option<[f64; 3]>]) -> Option<Vec<f32>> {
    let mut out = Vec::with_capacity(3 * normals.len());
    for j in 0..DICE {
        for i in 0..DICE {
            let n = normals[j * DICE + i].or_else(|| {
                let mut sum = [0.0; 3];
                for jj in j.saturating_sub(1)..(j + 2).min(DICE) {
                    for ii in i.saturating_sub(1)..(i + 2).min(DICE) {
                        if let Some(m) = normals[jj * DICE + ii] {
                            sum = std::array::from_fn(|k| sum[k] + m[k]);
                        }
                    }
                }
                normalize(sum)
            })?;
            out.extend(n.map(|x| x as f32));
        }
    }
    Some(out)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn length(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// `a` scaled to unit length; `None` for a zero or non-finite vector.
fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let len = length(a);
    (len > 0.0 && len.is_finite()).then(|| a.map(|x| x / len))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::upgrade::{upgrade_shape, Upgraded};

    fn loc() -> FileLoc {
        FileLoc::new("t.pbrt".into(), 3, 1)
    }

    fn int(name: &str, v: i32) -> ParsedParameter {
        let mut p = ParsedParameter::new("integer", name, loc());
        p.ints = vec![v];
        p
    }

    fn floats(ty: &str, name: &str, v: &[f32]) -> ParsedParameter {
        ParsedParameter::with_floats(ty, name, loc(), v.to_vec())
    }

    /// A patch with the given orders, knots and control points ("P" with
    /// three values per point, "Pw" with four).
    fn patch(
        (nu, uorder, uknots): (i32, i32, &[f32]),
        (nv, vorder, vknots): (i32, i32, &[f32]),
        cp: ParsedParameter,
    ) -> Vec<ParsedParameter> {
        vec![
            int("nu", nu),
            int("uorder", uorder),
            floats("float", "uknots", uknots),
            int("nv", nv),
            int("vorder", vorder),
            floats("float", "vknots", vknots),
            cp,
        ]
    }

    fn param<'a>(u: &'a Upgraded, name: &str) -> &'a ParsedParameter {
        u.params.iter().find(|p| p.name == name).expect(name)
    }

    fn vec3(v: &[f32], i: usize) -> [f64; 3] {
        [v[3 * i] as f64, v[3 * i + 1] as f64, v[3 * i + 2] as f64]
    }

    #[test]
    fn bilinear_patch_is_the_flat_quad() {
        // Corners (-1,-1,0), (1,-1,0), (-1,1,0), (1,1,0), u fastest.
        let u = upgrade_shape(
            "nurbs",
            patch(
                (2, 2, &[0., 0., 1., 1.]),
                (2, 2, &[0., 0., 1., 1.]),
                floats(
                    "point",
                    "P",
                    &[-1., -1., 0., 1., -1., 0., -1., 1., 0., 1., 1., 0.],
                ),
            ),
            &loc(),
        );
        assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
        assert_eq!(u.name, "trianglemesh");
        let (p, n, uv) = (param(&u, "P"), param(&u, "N"), param(&u, "uv"));
        assert_eq!((&*p.ty, &*n.ty, &*uv.ty), ("point3", "normal", "point2"));
        assert_eq!(p.floats.len(), 3 * DICE * DICE);
        assert_eq!(param(&u, "indices").ints.len(), 6 * (DICE - 1) * (DICE - 1));
        for i in 0..DICE * DICE {
            let (s, t) = (uv.floats[2 * i] as f64, uv.floats[2 * i + 1] as f64);
            assert_eq!(
                (s, t),
                (
                    ((i % DICE) as f64 / 29.0) as f32 as f64,
                    ((i / DICE) as f64 / 29.0) as f32 as f64
                )
            );
            let q = vec3(&p.floats, i);
            assert!((q[0] - (2.0 * s - 1.0)).abs() < 1e-6 && (q[1] - (2.0 * t - 1.0)).abs() < 1e-6);
            assert_eq!(q[2], 0.0);
            assert_eq!(vec3(&n.floats, i), [0.0, 0.0, 1.0]);
        }
        // Nothing of the NURBS description is left.
        assert_eq!(u.params.len(), 4);
    }

    #[test]
    fn rational_quarter_circle_lies_on_the_circle() {
        // The quadratic rational arc from (1,0) to (0,1) (middle weight
        // √2/2), extruded linearly along z, as homogeneous "Pw".
        let w = std::f32::consts::FRAC_1_SQRT_2;
        let mut pw = Vec::new();
        for z in [0.0, 2.0] {
            for (x, y, wt) in [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0)] {
                pw.extend([x * wt, y * wt, z * wt, wt]);
            }
        }
        let u = upgrade_shape(
            "nurbs",
            patch(
                (3, 3, &[0., 0., 0., 1., 1., 1.]),
                (2, 2, &[0., 0., 1., 1.]),
                floats("float", "Pw", &pw),
            ),
            &loc(),
        );
        assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
        let (p, n) = (param(&u, "P"), param(&u, "N"));
        let mut angles = Vec::new();
        for i in 0..DICE * DICE {
            let q = vec3(&p.floats, i);
            let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
            assert!((r - 1.0).abs() < 1e-6, "radius {r} at vertex {i}");
            assert!((q[2] - 2.0 * (i / DICE) as f64 / 29.0).abs() < 1e-6);
            // ∂p/∂u × ∂p/∂v points outward (u runs counter-clockwise, v
            // up).
            let m = vec3(&n.floats, i);
            assert!((m[0] - q[0]).abs() < 1e-5 && (m[1] - q[1]).abs() < 1e-5 && m[2].abs() < 1e-6);
            angles.push(q[1].atan2(q[0]));
        }
        // The arc's parameterization is not uniform in angle, but covers
        // the quarter circle monotonically.
        assert!(angles[..DICE].windows(2).all(|a| a[1] > a[0]));
        assert!(angles[0].abs() < 1e-6);
        assert!((angles[DICE - 1] - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn cubic_bspline_with_greville_points_reproduces_the_plane() {
        // Linear precision: control points at the Greville abscissae give
        // p(u, v) = (u, v, 0) for any knot vector, here non-uniform with a
        // double interior knot, diced over a sub-range.
        let uk: [f32; 10] = [0., 0., 0., 0., 0.3, 0.5, 0.5, 1., 1., 1.];
        let vk: [f32; 6] = [0., 0., 0., 2., 2., 2.];
        let greville = |k: &[f32], n: usize, p: usize| -> Vec<f32> {
            (0..n)
                .map(|i| k[i + 1..=i + p].iter().sum::<f32>() / p as f32)
                .collect()
        };
        let (gu, gv) = (greville(&uk, 6, 3), greville(&vk, 3, 2));
        let mut pts = Vec::new();
        for &y in &gv {
            for &x in &gu {
                pts.extend([x, y, 0.0]);
            }
        }
        let mut params = patch((6, 4, &uk), (3, 3, &vk), floats("point3", "P", &pts));
        params.push(floats("float", "u0", &[0.1]));
        params.push(floats("float", "v1", &[1.5]));
        let u = upgrade_shape("nurbs", params, &loc());
        assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
        let (p, uv) = (param(&u, "P"), param(&u, "uv"));
        assert!((uv.floats[0] - 0.1).abs() < 1e-7 && uv.floats[2 * DICE * DICE - 1] == 1.5);
        for i in 0..DICE * DICE {
            let q = vec3(&p.floats, i);
            assert!((q[0] - uv.floats[2 * i] as f64).abs() < 1e-5, "{q:?}");
            assert!((q[1] - uv.floats[2 * i + 1] as f64).abs() < 1e-5, "{q:?}");
        }
    }

    #[test]
    fn collapsed_edge_takes_its_neighbours_normals() {
        // The v = 1 edge collapses to a point: ∂p/∂u vanishes there.
        let u = upgrade_shape(
            "nurbs",
            patch(
                (2, 2, &[0., 0., 1., 1.]),
                (2, 2, &[0., 0., 1., 1.]),
                floats(
                    "point3",
                    "P",
                    &[-1., -1., 0., 1., -1., 0., 0., 1., 0., 0., 1., 0.],
                ),
            ),
            &loc(),
        );
        assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
        let n = param(&u, "N");
        for i in 0..DICE * DICE {
            assert_eq!(vec3(&n.floats, i), [0.0, 0.0, 1.0], "vertex {i}");
        }
    }

    #[test]
    fn bad_patches_are_located_errors() {
        let quad = || floats("point3", "P", &[0.; 12]);
        let k4: &[f32] = &[0., 0., 1., 1.];
        let bad = |params: Vec<ParsedParameter>, what: &str| {
            let u = upgrade_shape("nurbs", params, &loc());
            assert_eq!(u.name, "nurbs", "{what}");
            let d = u.diagnostics.iter().find(|d| d.is_error()).expect(what);
            assert!(d.message.contains(what), "{}: {what}", d.message);
            assert_eq!(d.loc.as_ref().map(|l| l.line), Some(3));
        };
        bad(
            patch((2, 2, &[0., 1., 1.]), (2, 2, k4), quad()),
            "3 values in \"uknots\"",
        );
        bad(
            patch((2, 0, &[0., 1.]), (2, 2, k4), quad()),
            "\"uorder\" is 0",
        );
        bad(
            patch((2, 1, &[0., 1., 1.]), (2, 2, k4), quad()),
            "\"uorder\" is 1",
        );
        bad(
            patch((2, 2, k4), (2, 3, &[0.; 5]), quad()),
            "fewer than its order 3",
        );
        bad(
            patch((2, 2, k4), (2, 2, k4), floats("point3", "P", &[0.; 9])),
            "3 control points",
        );
        bad(
            patch((2, 2, k4), (2, 2, k4), floats("float", "Pw", &[1.; 15])),
            "not a multiple of four",
        );
        bad(
            patch((2, 2, &[0., 1., 0., 1.]), (2, 2, k4), quad()),
            "non-decreasing",
        );
        bad(
            patch((2, 2, &[0., 1., 1., 1.]), (2, 2, &[1.; 4]), quad()),
            "empty parameter range",
        );
        bad(
            patch((2, 2, k4), (2, 2, k4), floats("float", "Pw", &[0.; 16])),
            "non-finite point",
        );
        bad(
            patch((2, 2, k4), (2, 2, k4), floats("float", "Pw", &[1.; 16]))
                .into_iter()
                .filter(|p| p.name != "Pw")
                .collect(),
            "\"float Pw\"",
        );
        let mut far = patch((2, 2, k4), (2, 2, k4), quad());
        far.push(floats("float", "v1", &[1.5]));
        bad(far, "outside the knot vector's range");
        bad(
            patch((2, 2, k4), (1_000_000, 2_000_000, &[0.; 4]), quad()),
            "\"vorder\" is 2000000",
        );
        bad(
            patch((i32::MAX, 2, k4), (2, 2, k4), quad()),
            "values in \"uknots\"",
        );
        bad(vec![int("nu", 2)], "\"integer uorder\"");
    }
}
