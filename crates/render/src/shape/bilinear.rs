//! Bilinear patches (book section 6.6; pbrt-v4 `util/mesh.h`, `shapes.h`,
//! `shapes.cpp`): quadrilaterals `p(u,v) = lerp(u, lerp(v, p00, p01),
//! lerp(v, p10, p11))`, intersected exactly by Reshetov's method and sampled
//! by solid angle with spherical rectangles when they are rectangles.
// `!(x > 0.0)` is deliberate throughout: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{
    area_sample_to_solid_angle, ShapeError, ShapeIntersection, ShapeMethods, ShapeSample,
    ShapeSampleContext,
};
use crate::sampling::spherical::{
    invert_spherical_rectangle_sample, sample_spherical_rectangle, spherical_quad_area,
};
use crate::sampling::{bilinear_pdf, sample_bilinear};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use std::sync::Arc;

/// Below this solid angle (steradians) rectangles are sampled by area.
pub const MIN_SPHERICAL_SAMPLE_AREA: Float = 1e-4;

/// A mesh of bilinear patches in rendering space (pbrt-v4's
/// `BilinearPatchMesh`).
#[derive(Clone, Debug, PartialEq)]
pub struct BilinearPatchMesh {
    /// Four vertex indices per patch, in the order p00, p10, p01, p11.
    pub indices: Vec<u32>,
    /// Vertex positions in rendering space.
    pub p: Vec<Point3f>,
    /// Per-vertex shading normals in rendering space (already flipped when
    /// the orientation is reversed).
    pub n: Option<Vec<Normal3f>>,
    /// Per-vertex texture coordinates.
    pub uv: Option<Vec<Point2f>>,
    /// One face index per patch.
    pub face_indices: Option<Vec<i32>>,
    /// Whether the surface normals are reversed (`ReverseOrientation`).
    pub reverse_orientation: bool,
    /// Whether the object-to-render transformation changes handedness.
    pub transform_swaps_handedness: bool,
}

impl BilinearPatchMesh {
    /// Validates the parameters, transforms positions and normals to
    /// rendering space and returns the mesh with warnings (non-finite
    /// positions, degenerate patches that will be skipped).
    ///
    /// Empty `n`, `uv` or `face_indices` mean "not given"; empty `indices`
    /// is allowed only for exactly four vertices (one patch).
    pub fn new(
        render_from_object: &Transform,
        reverse_orientation: bool,
        indices: Vec<u32>,
        p: Vec<Point3f>,
        n: Vec<Normal3f>,
        uv: Vec<Point2f>,
        face_indices: Vec<i32>,
    ) -> Result<(Arc<BilinearPatchMesh>, Vec<String>), ShapeError> {
        let err = |m: String| Err(ShapeError(format!("bilinearmesh: {m}")));
        if p.len() < 3 {
            return err(format!(
                "at least 3 vertex positions \"P\" are required, {} given",
                p.len()
            ));
        }
        if p.len() > u32::MAX as usize {
            return err(format!("too many vertices ({})", p.len()));
        }
        let indices = if indices.is_empty() {
            if p.len() == 4 {
                vec![0, 1, 2, 3]
            } else {
                return err(format!("vertex indices \"indices\" must be given with {} vertices (only 4 vertices imply one patch)", p.len()));
            }
        } else {
            indices
        };
        if indices.len() % 4 != 0 {
            return err(format!(
                "number of vertex indices {} is not a multiple of 4",
                indices.len()
            ));
        }
        if let Some((i, &v)) = indices
            .iter()
            .enumerate()
            .find(|(_, &v)| v as usize >= p.len())
        {
            return err(format!(
                "vertex index {v} (at position {i}) is out of range: {} \"P\" values were given",
                p.len()
            ));
        }
        for (what, len) in [("\"N\" normals", n.len()), ("\"uv\" coordinates", uv.len())] {
            if len != 0 && len != p.len() {
                return err(format!(
                    "number of {what} ({len}) does not match the number of \"P\" values ({})",
                    p.len()
                ));
            }
        }
        let n_patches = indices.len() / 4;
        if !face_indices.is_empty() && face_indices.len() != n_patches {
            return err(format!(
                "number of face indices ({}) does not match the number of patches ({n_patches})",
                face_indices.len()
            ));
        }
        if let Some(i) = n.iter().position(|v| !v.is_finite()) {
            return err(format!("normal \"N\" {i} is not finite"));
        }
        if let Some(i) = uv
            .iter()
            .position(|v| !(v.x.is_finite() && v.y.is_finite()))
        {
            return err(format!("texture coordinate \"uv\" {i} is not finite"));
        }

        let mut warnings = Vec::new();
        let bad_p = p.iter().filter(|q| !q.is_finite()).count();
        if bad_p > 0 {
            warnings.push(format!(
                "bilinearmesh: {bad_p} vertex positions are not finite"
            ));
        }
        let flip = |v: Normal3f| if reverse_orientation { -v } else { v };
        let mesh = BilinearPatchMesh {
            indices,
            p: p.into_iter()
                .map(|q| render_from_object.apply_point(q))
                .collect(),
            n: (!n.is_empty()).then(|| {
                n.into_iter()
                    .map(|v| flip(render_from_object.apply_normal(v)))
                    .collect()
            }),
            uv: (!uv.is_empty()).then_some(uv),
            face_indices: (!face_indices.is_empty()).then_some(face_indices),
            reverse_orientation,
            transform_swaps_handedness: render_from_object.swaps_handedness(),
        };
        let skipped = (0..n_patches)
            .filter(|&i| !(patch_area(mesh.vertices(i)) > 0.0))
            .count();
        if skipped > 0 {
            warnings.push(format!("bilinearmesh: skipping {skipped} of {n_patches} patches that are degenerate (zero area) or have non-finite vertices"));
        }
        Ok((Arc::new(mesh), warnings))
    }

    /// Number of patches (including degenerate ones).
    #[inline]
    pub fn n_patches(&self) -> usize {
        self.indices.len() / 4
    }

    #[inline]
    fn vertex_indices(&self, i: usize) -> [usize; 4] {
        let v = &self.indices[4 * i..4 * i + 4];
        [v[0] as usize, v[1] as usize, v[2] as usize, v[3] as usize]
    }

    /// The rendering-space corners of patch `i`: p00, p10, p01, p11.
    #[inline]
    pub fn vertices(&self, i: usize) -> [Point3f; 4] {
        let v = self.vertex_indices(i);
        [self.p[v[0]], self.p[v[1]], self.p[v[2]], self.p[v[3]]]
    }
}

/// The usable patches of `mesh`: degenerate ones (zero area, non-finite
/// vertices) are left out, as [`BilinearPatchMesh::new`] warned.
pub fn patches(mesh: &Arc<BilinearPatchMesh>) -> Vec<BilinearPatch> {
    (0..mesh.n_patches())
        .map(|i| BilinearPatch::new(mesh.clone(), i as u32))
        .filter(|b| b.area > 0.0)
        .collect()
}

/// Bilinear interpolation of the four corners (p00, p10, p01, p11).
#[inline]
fn bilerp(p: &[Point3f; 4], u: Float, v: Float) -> Point3f {
    let a = p[0] + (p[2] - p[0]) * v;
    let b = p[1] + (p[3] - p[1]) * v;
    a + (b - a) * u
}

/// ∂p/∂u and ∂p/∂v at (u, v).
#[inline]
fn partials(p: &[Point3f; 4], u: Float, v: Float) -> (Vector3f, Vector3f) {
    let dpdu = (p[1] - p[0]) + ((p[3] - p[1]) - (p[2] - p[0])) * v;
    let dpdv = (p[2] - p[0]) + ((p[3] - p[2]) - (p[1] - p[0])) * u;
    (dpdu, dpdv)
}

/// The surface area of a patch: ∫∫ |∂p/∂u × ∂p/∂v| du dv by adaptive
/// Gauss–Legendre quadrature in double precision; 0 for non-finite input.
fn patch_area(p: [Point3f; 4]) -> Float {
    if !p.iter().all(|q| q.is_finite()) {
        return 0.0;
    }
    let d = |a: Point3f, b: Point3f| {
        [
            a.x as f64 - b.x as f64,
            a.y as f64 - b.y as f64,
            a.z as f64 - b.z as f64,
        ]
    };
    let (e10, e00, e11) = (d(p[1], p[0]), d(p[2], p[0]), d(p[3], p[1]));
    // ∂p/∂u = e10 + k v and ∂p/∂v = e00 + k u with k = ∂²p/∂u∂v.
    let k = [e11[0] - e00[0], e11[1] - e00[1], e11[2] - e00[2]];
    let jac = |u: f64, v: f64| {
        let du = [e10[0] + k[0] * v, e10[1] + k[1] * v, e10[2] + k[2] * v];
        let dv = [e00[0] + k[0] * u, e00[1] + k[1] * u, e00[2] + k[2] * u];
        let c = [
            du[1] * dv[2] - du[2] * dv[1],
            du[2] * dv[0] - du[0] * dv[2],
            du[0] * dv[1] - du[1] * dv[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
    };
    // 4-point Gauss–Legendre nodes and weights on [-1, 1].
    const X: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const W: [f64; 4] = [
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ];
    let cell = |u0: f64, v0: f64, h: f64| {
        let mut s = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                s += W[i] * W[j] * jac(u0 + h * 0.5 * (X[i] + 1.0), v0 + h * 0.5 * (X[j] + 1.0));
            }
        }
        s * h * h * 0.25
    };
    fn refine(
        cell: &dyn Fn(f64, f64, f64) -> f64,
        u0: f64,
        v0: f64,
        h: f64,
        coarse: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let hh = h * 0.5;
        let parts = [
            cell(u0, v0, hh),
            cell(u0 + hh, v0, hh),
            cell(u0, v0 + hh, hh),
            cell(u0 + hh, v0 + hh, hh),
        ];
        let fine: f64 = parts.iter().sum();
        if depth == 0 || (fine - coarse).abs() <= tol {
            return fine;
        }
        let corners = [(u0, v0), (u0 + hh, v0), (u0, v0 + hh), (u0 + hh, v0 + hh)];
        corners
            .iter()
            .zip(parts)
            .map(|(&(u, v), c)| refine(cell, u, v, hh, c, tol * 0.25, depth - 1))
            .sum()
    }
    let coarse = cell(0.0, 0.0, 1.0);
    let area = refine(
        &cell,
        0.0,
        0.0,
        1.0,
        coarse,
        1e-9 * coarse.max(f64::MIN_POSITIVE),
        8,
    );
    let area = area as Float;
    if area.is_finite() {
        area
    } else {
        0.0
    }
}

/// Reshetov's ray–bilinear patch intersection as pbrt-v4 implements it:
/// the (u, v) of the closest hit with `0 < t < t_max`, and its `t`.
pub fn intersect_bilinear_patch(
    ray: &Ray,
    t_max: Float,
    p00: Point3f,
    p10: Point3f,
    p01: Point3f,
    p11: Point3f,
) -> Option<(Point2f, Float)> {
    // The distance from the ray to the segment at u, along lines of
    // constant u, is a quadratic a u² + b u + c.
    let qn = cross(p10 - p00, p01 - p11);
    let e11 = p11 - p10;
    let e00 = p01 - p00;
    let q00 = p00 - ray.o;
    let q10 = p10 - ray.o;
    let a = dot(qn, ray.d);
    let c = dot(cross(q00, ray.d), e00);
    let b = dot(cross(q10, ray.d), e11) - (a + c);
    let (u1, u2) = match quadratic(a, b, c) {
        Some(roots) => roots,
        None => {
            // A discriminant negative only by rounding (a ray grazing the
            // u-lines) still has its double root.
            let (af, bf, cf) = (a as f64, b as f64, c as f64);
            let disc = bf * bf - 4.0 * af * cf;
            if a != 0.0 && disc > -1e-5 * (bf * bf + (4.0 * af * cf).abs()) {
                let u = (-bf / (2.0 * af)) as Float;
                (u, u)
            } else {
                return None;
            }
        }
    };

    // Hits closer to the origin than a few times the rounding error of a
    // point on the patch cannot be told apart from the origin itself (a
    // ray leaving the patch from an offset origin).
    let p_max = p00.abs().max(p10.abs()).max(p01.abs().max(p11.abs()));
    let t_eps = 8.0 * gamma(6) * Vector3f::from(p_max).length() / ray.d.length();

    // For each root in [0, 1], the closest points of the ray and of the
    // u-line give v and t.
    let mut best: Option<(Point2f, Float)> = None;
    let mut t = t_max;
    for (k, ur) in [u1, u2].into_iter().enumerate() {
        if !(0.0..=1.0).contains(&ur) || (k == 1 && ur == u1) {
            continue;
        }
        let pa = q00 + (q10 - q00) * ur;
        let pb = e00 + (e11 - e00) * ur;
        let n = cross(ray.d, pb);
        let det = dot(n, n);
        if !(det > 0.0) {
            continue;
        }
        let n = cross(n, pa);
        let tr = dot(n, pb) / det;
        let vr = dot(n, ray.d);
        if (0.0..=det).contains(&vr) && tr > t_eps && tr < t {
            t = tr;
            best = Some((Point2f::new(ur, vr / det), tr));
        }
    }
    best.filter(|&(_, t)| t < t_max && t.is_finite())
}

/// One patch of a [`BilinearPatchMesh`].
#[derive(Clone, Debug)]
pub struct BilinearPatch {
    /// The mesh holding the vertices.
    pub mesh: Arc<BilinearPatchMesh>,
    /// Which patch of the mesh.
    pub blp_index: u32,
    area: Float,
    rectangle: bool,
}

impl BilinearPatch {
    /// Patch `blp_index` of `mesh` (which must be in range; use [`patches`]
    /// to get only the valid ones). Computes and caches its area.
    pub fn new(mesh: Arc<BilinearPatchMesh>, blp_index: u32) -> Self {
        debug_assert!((blp_index as usize) < mesh.n_patches());
        let p = mesh.vertices(blp_index as usize);
        let rectangle = is_rectangle(&p);
        let area = if rectangle {
            p[0].distance(p[2]) * p[0].distance(p[1])
        } else {
            patch_area(p)
        };
        BilinearPatch {
            mesh,
            blp_index,
            area,
            rectangle,
        }
    }

    #[inline]
    fn vertices(&self) -> [Point3f; 4] {
        self.mesh.vertices(self.blp_index as usize)
    }

    /// Whether the patch is a planar rectangle (sampled by solid angle).
    pub fn is_rectangle(&self) -> bool {
        self.rectangle
    }

    /// Corner weights for approximately uniform area sampling of
    /// non-rectangular patches: the area element at each corner.
    fn corner_weights(p: &[Point3f; 4]) -> [Float; 4] {
        [
            cross(p[1] - p[0], p[2] - p[0]).length(),
            cross(p[1] - p[0], p[3] - p[1]).length(),
            cross(p[2] - p[0], p[3] - p[2]).length(),
            cross(p[3] - p[1], p[3] - p[2]).length(),
        ]
    }

    /// Density per unit area of [`ShapeMethods::sample_area`] at patch
    /// parameters `uv` (uniform, 1/area, only for rectangles).
    pub fn pdf_area_at(&self, uv: Point2f) -> Float {
        let p = self.vertices();
        let pdf = if self.rectangle {
            1.0
        } else {
            bilinear_pdf(uv, Self::corner_weights(&p))
        };
        let (dpdu, dpdv) = partials(&p, uv.x, uv.y);
        pdf / cross(dpdu, dpdv).length()
    }

    /// The patch parameters (u, v) of a point `q` on the patch: the
    /// least-squares solution of bilerp(u, v) = q by Gauss–Newton steps
    /// from the centre, kept in [0, 1]² (pbrt-v4 inverts the texture
    /// coordinates of the interaction instead; rpbrt is given the point).
    pub fn invert_point(&self, q: Point3f) -> Point2f {
        let p = self.vertices();
        let (mut u, mut v) = (0.5, 0.5);
        for _ in 0..24 {
            let r = bilerp(&p, u, v) - q;
            let (dpdu, dpdv) = partials(&p, u, v);
            let (a, b, c) = (dot(dpdu, dpdu), dot(dpdu, dpdv), dot(dpdv, dpdv));
            let det = a * c - b * b;
            if !(det.abs() > 0.0) {
                break;
            }
            let (ru, rv) = (dot(dpdu, r), dot(dpdv, r));
            let du = (c * ru - b * rv) / det;
            let dv = (a * rv - b * ru) / det;
            let (nu, nv) = (clamp(u - du, 0.0, 1.0), clamp(v - dv, 0.0, 1.0));
            let step = (nu - u).abs() + (nv - v).abs();
            (u, v) = (nu, nv);
            if !(step > 1e-7) {
                break;
            }
        }
        Point2f::new(u, v)
    }

    /// The texture coordinates at patch parameters (u, v).
    fn st(&self, u: Float, v: Float) -> Point2f {
        match &self.mesh.uv {
            Some(uv) => {
                let i = self.mesh.vertex_indices(self.blp_index as usize);
                let a = uv[i[0]] + (uv[i[2]] - uv[i[0]]) * v;
                let b = uv[i[1]] + (uv[i[3]] - uv[i[1]]) * v;
                a + (b - a) * u
            }
            None => Point2f::new(u, v),
        }
    }

    /// Orients a geometric normal at (u, v) as intersections do.
    fn orient(&self, n: Normal3f, u: Float, v: Float) -> Normal3f {
        match &self.mesh.n {
            Some(nn) => {
                let i = self.mesh.vertex_indices(self.blp_index as usize);
                let a = nn[i[0]] + (nn[i[2]] - nn[i[0]]) * v;
                let b = nn[i[1]] + (nn[i[3]] - nn[i[1]]) * v;
                n.face_forward(a + (b - a) * u)
            }
            None if self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness => -n,
            None => n,
        }
    }

    fn p_error(p: &[Point3f; 4]) -> Vector3f {
        Vector3f::from(p[0].abs() + p[1].abs() + p[2].abs() + p[3].abs()) * gamma(6)
    }

    /// The cos θ weights at the corners seen from `ctx` (p00, p10, p01, p11).
    fn cos_weights(ctx: &ShapeSampleContext, v: &[Vector3f; 4]) -> [Float; 4] {
        [0, 1, 2, 3].map(|i| abs_dot(v[i], ctx.ns).max(0.01))
    }

    /// Unit directions from `p` to the corners and the solid angle of the
    /// patch from there (meaningful only for rectangles).
    fn solid_angle_from(&self, p: Point3f) -> ([Vector3f; 4], Float) {
        let c = self.vertices().map(|q| (q - p).normalize());
        (c, spherical_quad_area(c[0], c[1], c[3], c[2]))
    }

    /// The surface interaction at patch parameters `uv`.
    fn interaction(&self, uv: Point2f, time: Float, wo: Vector3f) -> SurfaceInteraction {
        let mesh = &*self.mesh;
        let vi = mesh.vertex_indices(self.blp_index as usize);
        let p = self.vertices();
        let p_hit = bilerp(&p, uv.x, uv.y);
        let (mut dpdu, mut dpdv) = partials(&p, uv.x, uv.y);
        if !(cross(dpdu, dpdv).length_squared() > 0.0) {
            // At a collapsed edge: use the frame of the diagonals' normal.
            let ng = cross(p[3] - p[0], p[2] - p[1])
                .try_normalize()
                .unwrap_or(Vector3f::new(0.0, 0.0, 1.0));
            (dpdu, dpdv) = ng.coordinate_system();
        }

        let mut st = uv;
        if let Some(tc) = &mesh.uv {
            // Re-express the partials with respect to the texture
            // coordinates (s, t) when that mapping is invertible.
            let (t00, t10, t01, t11) = (tc[vi[0]], tc[vi[1]], tc[vi[2]], tc[vi[3]]);
            st = self.st(uv.x, uv.y);
            let dsdu = -t00.x + t10.x + uv.y * (t00.x - t01.x - t10.x + t11.x);
            let dsdv = -t00.x + t01.x + uv.x * (t00.x - t01.x - t10.x + t11.x);
            let dtdu = -t00.y + t10.y + uv.y * (t00.y - t01.y - t10.y + t11.y);
            let dtdv = -t00.y + t01.y + uv.x * (t00.y - t01.y - t10.y + t11.y);
            let inv = |x: Float| if x.abs() < 1e-8 { 0.0 } else { 1.0 / x };
            let dpds = dpdu * inv(dsdu) + dpdv * inv(dsdv);
            let mut dpdt = dpdu * inv(dtdu) + dpdv * inv(dtdv);
            let c = cross(dpds, dpdt);
            if c != Vector3f::default() && c.is_finite() {
                if dot(cross(dpdu, dpdv), c) < 0.0 {
                    dpdt = -dpdt;
                }
                dpdu = dpds;
                dpdv = dpdt;
            }
        }

        // dn/du, dn/dv from the fundamental forms; only ∂²p/∂u∂v is nonzero.
        let d2pduv = Vector3f::new(
            p[0].x - p[2].x - p[1].x + p[3].x,
            p[0].y - p[2].y - p[1].y + p[3].y,
            p[0].z - p[2].z - p[1].z + p[3].z,
        );
        let e_ = dot(dpdu, dpdu);
        let f_ = dot(dpdu, dpdv);
        let g_ = dot(dpdv, dpdv);
        let nn = cross(dpdu, dpdv).try_normalize().unwrap_or_default();
        let f2 = dot(nn, d2pduv);
        let egf2 = difference_of_products(e_, g_, f_, f_);
        let (dndu, dndv) = if egf2 != 0.0 && egf2.is_finite() {
            let inv = 1.0 / egf2;
            (
                Normal3f::from((dpdu * (f2 * f_) - dpdv * (f2 * e_)) * inv),
                Normal3f::from((dpdv * (f2 * f_) - dpdu * (f2 * g_)) * inv),
            )
        } else {
            (Normal3f::default(), Normal3f::default())
        };

        let flip = mesh.reverse_orientation ^ mesh.transform_swaps_handedness;
        let p_error =
            Vector3f::from(p[0].abs().max(p[1].abs()).max(p[2].abs().max(p[3].abs()))) * gamma(6);
        let mut isect = SurfaceInteraction::new(
            Point3fi::from_value_and_error(p_hit, p_error),
            st,
            wo,
            dpdu,
            dpdv,
            dndu,
            dndv,
            time,
            flip,
        );
        isect.face_index = mesh
            .face_indices
            .as_ref()
            .map_or(0, |f| f[self.blp_index as usize]);

        if let Some(nv) = &mesh.n {
            let (n00, n10, n01, n11) = (nv[vi[0]], nv[vi[1]], nv[vi[2]], nv[vi[3]]);
            let (u, v) = (uv.x, uv.y);
            let a = n00 + (n01 - n00) * v;
            let b = n10 + (n11 - n10) * v;
            let ns = a + (b - a) * u;
            if ns.length_squared() > 0.0 {
                let ns = ns.normalize();
                let n = isect.n;
                let axis = cross(Vector3f::from(n), ns);
                if axis.length_squared() > 1e-14 {
                    // Rotate dp/du, dp/dv by the rotation taking n to ns so
                    // that their cross product is the shading normal.
                    let dndu = b - a;
                    let dndv = (n01 + (n11 - n01) * u) - (n00 + (n10 - n00) * u);
                    let cos_theta = dot(n, ns);
                    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
                    let r = Transform::rotate_sc(sin_theta, cos_theta, axis.normalize());
                    let mut sdpdu = r.apply_vector(dpdu);
                    let sdpdv = r.apply_vector(dpdv);
                    sdpdu -= Vector3f::from(ns) * dot(sdpdu, ns);
                    isect.set_shading_geometry(ns, sdpdu, sdpdv, dndu, dndv, true);
                }
            }
        }
        isect
    }

    /// The closest hit and its patch parameters (u, v).
    fn intersect_uv(&self, ray: &Ray, t_max: Float) -> Option<(ShapeIntersection, Point2f)> {
        if !(self.area > 0.0) {
            return None;
        }
        let [p00, p10, p01, p11] = self.vertices();
        let (uv, t) = intersect_bilinear_patch(ray, t_max, p00, p10, p01, p11)?;
        let wo = (-ray.d).try_normalize().unwrap_or_default();
        Some((
            ShapeIntersection {
                intr: self.interaction(uv, ray.time, wo),
                t_hit: t,
            },
            uv,
        ))
    }
}

/// pbrt-v4's rectangle test: no repeated corners, coplanar, and all
/// corners equidistant from the centre.
fn is_rectangle(p: &[Point3f; 4]) -> bool {
    let [p00, p10, p01, p11] = *p;
    if p00 == p01 || p01 == p11 || p11 == p10 || p10 == p00 {
        return false;
    }
    match (
        cross(p10 - p00, p01 - p00).try_normalize(),
        (p11 - p00).try_normalize(),
    ) {
        (Some(n), Some(d)) if n.is_finite() && d.is_finite() && abs_dot(d, n) <= 1e-5 => {}
        _ => return false,
    }
    let center = Point3f::from(
        (Vector3f::from(p00) + Vector3f::from(p01) + Vector3f::from(p10) + Vector3f::from(p11))
            * 0.25,
    );
    let d2 = [p00, p01, p10, p11].map(|q| q.distance_squared(center));
    d2[1..].iter().all(|&d| ((d - d2[0]) / d2[0]).abs() <= 1e-4)
}

impl ShapeMethods for BilinearPatch {
    fn bounds(&self) -> Bounds3f {
        let p = self.vertices();
        Bounds3f::new(p[0], p[2]).union(&Bounds3f::new(p[1], p[3]))
    }

    fn normal_bounds(&self) -> DirectionCone {
        let [p00, p10, p01, p11] = self.vertices();
        let vi = self.mesh.vertex_indices(self.blp_index as usize);
        let flip = self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness;
        let orient = |n: Vector3f, ns: Option<Normal3f>| match ns {
            Some(ns) => n.face_forward(ns),
            None if flip => -n,
            None => n,
        };
        let vn = |i: usize| self.mesh.n.as_ref().map(|nn| nn[vi[i]]);
        // A patch with a collapsed edge is a planar triangle.
        if p00 == p10 || p10 == p11 || p11 == p01 || p01 == p00 {
            let (dpdu, dpdv) = partials(&[p00, p10, p01, p11], 0.5, 0.5);
            let n = cross(dpdu, dpdv).normalize();
            let avg = self
                .mesh
                .n
                .as_ref()
                .map(|nn| (nn[vi[0]] + nn[vi[1]] + nn[vi[2]] + nn[vi[3]]) * 0.25);
            return DirectionCone::from_direction(orient(n, avg));
        }
        let n00 = orient(cross(p10 - p00, p01 - p00).normalize(), vn(0));
        let n10 = orient(cross(p11 - p10, p00 - p10).normalize(), vn(1));
        let n01 = orient(cross(p00 - p01, p11 - p01).normalize(), vn(2));
        let n11 = orient(cross(p01 - p11, p10 - p11).normalize(), vn(3));
        let n = (n00 + n10 + n01 + n11).normalize();
        let cos_theta = dot(n, n00)
            .min(dot(n, n01))
            .min(dot(n, n10))
            .min(dot(n, n11));
        DirectionCone::new(n, clamp(cos_theta, -1.0, 1.0))
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        self.intersect_uv(ray, t_max).map(|(si, _)| si)
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        let [p00, p10, p01, p11] = self.vertices();
        self.area > 0.0 && intersect_bilinear_patch(ray, t_max, p00, p10, p01, p11).is_some()
    }

    fn area(&self) -> Float {
        self.area
    }

    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        let p = self.vertices();
        let (uv, pdf) = if self.rectangle {
            (u, 1.0)
        } else {
            // Approximately uniform: warp by the corner area elements.
            let w = Self::corner_weights(&p);
            if !(w.iter().sum::<Float>() > 0.0) {
                return None;
            }
            let uv = sample_bilinear(u, w);
            (uv, bilinear_pdf(uv, w))
        };
        let (dpdu, dpdv) = partials(&p, uv.x, uv.y);
        let c = cross(dpdu, dpdv);
        let len = c.length();
        if !(len > 0.0) || !(pdf > 0.0) {
            return None;
        }
        let n = self.orient(Normal3f::from(c / len), uv.x, uv.y);
        let pi = Point3fi::from_value_and_error(bilerp(&p, uv.x, uv.y), Self::p_error(&p));
        let pdf = pdf / len;
        pdf.is_finite().then(|| ShapeSample {
            pi,
            n,
            uv: self.st(uv.x, uv.y),
            time: 0.0,
            pdf,
        })
    }

    /// The density of [`ShapeMethods::sample_area`] at `p`: uniform
    /// (1/area) on rectangles, the warped density elsewhere.
    fn pdf_area_at_point(&self, p: Point3f) -> Float {
        if self.rectangle {
            return 1.0 / self.area;
        }
        self.pdf_area_at(self.invert_point(p))
    }

    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        let (corners, sa) = self.solid_angle_from(ctx.p());
        if !self.rectangle || !(sa > MIN_SPHERICAL_SAMPLE_AREA) {
            let mut ss = self.sample_area(u)?;
            ss.time = ctx.time;
            return area_sample_to_solid_angle(ctx, ss);
        }
        let mut pdf = 1.0;
        let mut u = u;
        if !ctx.ns.is_zero() {
            let w = Self::cos_weights(ctx, &corners);
            u = sample_bilinear(u, w);
            pdf *= bilinear_pdf(u, w);
        }
        let p = self.vertices();
        let (eu, ev) = (p[1] - p[0], p[2] - p[0]);
        let (ps, quad_pdf) = sample_spherical_rectangle(ctx.p(), p[0], eu, ev, u);
        if !(quad_pdf > 0.0) {
            return None;
        }
        let uv = Point2f::new(
            clamp(dot(ps - p[0], eu) / eu.length_squared(), 0.0, 1.0),
            clamp(dot(ps - p[0], ev) / ev.length_squared(), 0.0, 1.0),
        );
        let n = self.orient(Normal3f::from(cross(eu, ev).normalize()), uv.x, uv.y);
        let pi = Point3fi::from_value_and_error(ps, Self::p_error(&p));
        Some(ShapeSample {
            pi,
            n,
            uv: self.st(uv.x, uv.y),
            time: ctx.time,
            pdf: pdf * quad_pdf,
        })
    }

    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        let Some((isect, uv)) = self.intersect_uv(&ctx.spawn_ray(wi), Float::INFINITY) else {
            return 0.0;
        };
        let (corners, sa) = self.solid_angle_from(ctx.p());
        if !self.rectangle || !(sa > MIN_SPHERICAL_SAMPLE_AREA) {
            let wi = wi.normalize();
            let pdf = self.pdf_area_at(uv) * ctx.p().distance_squared(isect.intr.p())
                / abs_dot(isect.intr.n, -wi);
            return if pdf.is_finite() { pdf } else { 0.0 };
        }
        let mut pdf = 1.0 / sa;
        if !ctx.ns.is_zero() {
            let p = self.vertices();
            let w = Self::cos_weights(ctx, &corners);
            let u = invert_spherical_rectangle_sample(
                ctx.p(),
                p[0],
                p[1] - p[0],
                p[2] - p[0],
                isect.intr.p(),
            );
            pdf *= bilinear_pdf(u, w);
        }
        pdf
    }
}

#[cfg(test)]
mod tests;
