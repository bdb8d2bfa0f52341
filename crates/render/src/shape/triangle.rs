//! Triangle meshes (book section 6.5; pbrt-v4 `util/mesh.h`, `shapes.h`,
//! `shapes.cpp`): a [`TriangleMesh`] holds rendering-space vertices shared by
//! its [`Triangle`]s, which are intersected with the watertight algorithm of
//! Woop et al. and sampled by solid angle with spherical triangles.
// `!(x > 0.0)` is deliberate throughout: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{
    area_sample_to_solid_angle, pdf_by_intersection, ShapeError, ShapeIntersection, ShapeMethods,
    ShapeSample, ShapeSampleContext,
};
use crate::sampling::spherical::{
    invert_spherical_triangle_sample_dirs, sample_spherical_lanes, spherical_triangle_area,
    spherical_triangle_area_lanes,
};
use crate::sampling::{bilinear_pdf, sample_uniform_triangle};
use crate::simd::math::{self, V3};
use crate::simd::{dispatch, F32Lanes, Kernel, Scalar1, SimdLevel};
use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::{ShadingGeometry, SurfaceInteraction};
use rpbrt_geometry::interval::Interval;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::spherical::DirectionCone;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;
use std::ops::Deref;
use std::sync::Arc;

/// Below this solid angle (steradians) a triangle is sampled by area:
/// spherical sampling is inaccurate and the triangle contributes little.
pub const MIN_SPHERICAL_SAMPLE_AREA: Float = 3e-4;
/// Above this solid angle (nearly a hemisphere) a triangle is sampled by
/// area: spherical sampling breaks down and BSDF sampling does better.
pub const MAX_SPHERICAL_SAMPLE_AREA: Float = 6.22;

/// A triangle mesh in rendering space (pbrt-v4's `TriangleMesh`).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
    /// Vertex positions in rendering space.
    pub p: Vec<Point3f>,
    /// Per-vertex shading normals in rendering space (already flipped when
    /// the orientation is reversed).
    pub n: Option<Vec<Normal3f>>,
    /// Per-vertex shading tangents in rendering space.
    pub s: Option<Vec<Vector3f>>,
    /// Per-vertex texture coordinates.
    pub uv: Option<Vec<Point2f>>,
    /// One face index per triangle (for ptex lookups).
    pub face_indices: Option<Vec<i32>>,
    /// Whether the surface normals are reversed (`ReverseOrientation`).
    pub reverse_orientation: bool,
    /// Whether the object-to-render transformation changes handedness.
    pub transform_swaps_handedness: bool,
}

impl TriangleMesh {
    /// Validates the mesh parameters, transforms positions, normals and
    /// tangents to rendering space and returns the mesh with warnings
    /// (non-finite positions, triangles that will be skipped).
    ///
    /// Empty `s`, `n`, `uv` or `face_indices` mean "not given"; empty
    /// `indices` is allowed only for exactly three vertices (one triangle).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        render_from_object: &Transform,
        reverse_orientation: bool,
        indices: Vec<u32>,
        p: Vec<Point3f>,
        s: Vec<Vector3f>,
        n: Vec<Normal3f>,
        uv: Vec<Point2f>,
        face_indices: Vec<i32>,
    ) -> Result<(Arc<TriangleMesh>, Vec<String>), ShapeError> {
        let err = |m: String| Err(ShapeError(format!("trianglemesh: {m}")));
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
            if p.len() == 3 {
                vec![0, 1, 2]
            } else {
                return err(format!("vertex indices \"indices\" must be given with {} vertices (only 3 vertices imply one triangle)", p.len()));
            }
        } else {
            indices
        };
        if indices.len() % 3 != 0 {
            return err(format!(
                "number of vertex indices {} is not a multiple of 3",
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
        let counts = [
            ("\"S\" tangents", s.len()),
            ("\"N\" normals", n.len()),
            ("\"uv\" coordinates", uv.len()),
        ];
        for (what, len) in counts {
            if len != 0 && len != p.len() {
                return err(format!(
                    "number of {what} ({len}) does not match the number of \"P\" values ({})",
                    p.len()
                ));
            }
        }
        let n_tris = indices.len() / 3;
        if !face_indices.is_empty() && face_indices.len() != n_tris {
            return err(format!(
                "number of face indices ({}) does not match the number of triangles ({n_tris})",
                face_indices.len()
            ));
        }
        let mut warnings = Vec::new();
        // Flawed per-vertex data renders with a warning, as pbrt-v4 renders
        // such files: normals are recomputed, tangents and uvs dropped.
        let (n, s, uv) = repair_vertex_data(&indices, &p, n, s, uv, &mut warnings);

        let bad_p = p.iter().filter(|q| !q.is_finite()).count();
        if bad_p > 0 {
            warnings.push(format!(
                "trianglemesh: {bad_p} vertex positions are not finite"
            ));
        }
        let p: Vec<Point3f> = p
            .into_iter()
            .map(|q| render_from_object.apply_point(q))
            .collect();
        let n = (!n.is_empty()).then(|| {
            n.into_iter()
                .map(|v| {
                    let v = render_from_object.apply_normal(v);
                    if reverse_orientation {
                        -v
                    } else {
                        v
                    }
                })
                .collect()
        });
        let s = (!s.is_empty()).then(|| {
            s.into_iter()
                .map(|v| render_from_object.apply_vector(v))
                .collect()
        });
        let mesh = TriangleMesh {
            indices,
            p,
            n,
            s,
            uv: (!uv.is_empty()).then_some(uv),
            face_indices: (!face_indices.is_empty()).then_some(face_indices),
            reverse_orientation,
            transform_swaps_handedness: render_from_object.swaps_handedness(),
        };
        let skipped = (0..n_tris).filter(|&i| !mesh.is_valid_triangle(i)).count();
        if skipped > 0 {
            warnings.push(format!("trianglemesh: skipping {skipped} of {n_tris} triangles that are degenerate (zero area) or have non-finite vertices"));
        }
        Ok((Arc::new(mesh), warnings))
    }

    /// Number of triangles (including degenerate ones).
    #[inline]
    pub fn n_triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// The vertex indices of triangle `i`.
    #[inline(always)]
    pub(crate) fn vertex_indices(&self, i: usize) -> [usize; 3] {
        [
            self.indices[3 * i] as usize,
            self.indices[3 * i + 1] as usize,
            self.indices[3 * i + 2] as usize,
        ]
    }

    /// The rendering-space vertices of triangle `i`.
    #[inline(always)]
    pub fn vertices(&self, i: usize) -> [Point3f; 3] {
        let v = self.vertex_indices(i);
        [self.p[v[0]], self.p[v[1]], self.p[v[2]]]
    }

    /// True when triangle `i` has finite vertices and a finite, nonzero
    /// area, so that it can be intersected and sampled.
    pub fn is_valid_triangle(&self, i: usize) -> bool {
        let [p0, p1, p2] = self.vertices(i);
        if !(p0.is_finite() && p1.is_finite() && p2.is_finite()) {
            return false;
        }
        let c = cross(p2 - p0, p1 - p0);
        let a2 = c.length_squared();
        a2 > 0.0 && a2.is_finite()
    }
}

/// True for a vector that can serve as a direction: finite and not zero.
fn usable_direction(x: Float, y: Float, z: Float) -> bool {
    let l2 = x * x + y * y + z * z;
    x.is_finite() && y.is_finite() && z.is_finite() && l2 > 0.0 && l2.is_finite()
}

/// Mends a mesh's per-vertex normals, tangents and uvs (object space, before
/// they are transformed), warning once per kind with the count:
/// - a non-finite or zero-length normal is replaced by the area-weighted
///   average of the geometric normals of the triangles around its vertex,
///   turned to the side the mesh's good normals there point to; when no
///   normal is usable, the mesh renders with geometric normals;
/// - a non-finite or zero-length tangent becomes zero (it then drops out
///   of the interpolation; where all three are zero the shading frame
///   falls back to ∂p/∂u, as without tangents);
/// - a non-finite uv becomes (0, 0).
fn repair_vertex_data(
    indices: &[u32],
    p: &[Point3f],
    mut n: Vec<Normal3f>,
    mut s: Vec<Vector3f>,
    mut uv: Vec<Point2f>,
    warnings: &mut Vec<String>,
) -> (Vec<Normal3f>, Vec<Vector3f>, Vec<Point2f>) {
    let bad_n: Vec<usize> = (0..n.len())
        .filter(|&i| !usable_direction(n[i].x, n[i].y, n[i].z))
        .collect();
    if !bad_n.is_empty() {
        if bad_n.len() == n.len() {
            warnings.push(format!(
                "trianglemesh: none of the {} normals \"N\" is usable (non-finite or zero length); rendering with geometric normals",
                n.len()
            ));
            n.clear();
        } else {
            let mut bad = vec![false; n.len()];
            for &i in &bad_n {
                bad[i] = true;
            }
            // Per vertex: the summed (area-weighted) geometric normals of
            // its triangles and the summed good normals around it.
            let mut geo = vec![Vector3f::default(); n.len()];
            let mut good = vec![Vector3f::default(); n.len()];
            for t in indices.chunks_exact(3) {
                let v = [t[0] as usize, t[1] as usize, t[2] as usize];
                let c = cross(p[v[1]] - p[v[0]], p[v[2]] - p[v[0]]);
                if !c.x.is_finite() || !c.y.is_finite() || !c.z.is_finite() {
                    continue;
                }
                let good_here = v
                    .iter()
                    .filter(|&&k| !bad[k])
                    .fold(Vector3f::default(), |acc, &k| acc + Vector3f::from(n[k]));
                for &k in &v {
                    if bad[k] {
                        geo[k] = geo[k] + c;
                        good[k] = good[k] + good_here;
                    }
                }
            }
            let mut unrepaired = 0;
            for &i in &bad_n {
                let g = geo[i];
                if usable_direction(g.x, g.y, g.z) {
                    let g = g.normalize();
                    n[i] = Normal3f::from(if dot(g, good[i]) < 0.0 { -g } else { g });
                } else {
                    unrepaired += 1;
                    n[i] = Normal3f::default();
                }
            }
            warnings.push(format!(
                "trianglemesh: {} of {} normals \"N\" are non-finite or zero length; recomputed from the surrounding triangles{}",
                bad_n.len(),
                n.len(),
                if unrepaired > 0 {
                    format!(" ({unrepaired} without a usable triangle left at zero)")
                } else {
                    String::new()
                }
            ));
        }
    }
    let bad_s = s
        .iter()
        .filter(|v| !usable_direction(v.x, v.y, v.z))
        .count();
    if bad_s > 0 {
        for v in s.iter_mut() {
            if !usable_direction(v.x, v.y, v.z) {
                *v = Vector3f::default();
            }
        }
        warnings.push(format!(
            "trianglemesh: {bad_s} of {} tangents \"S\" are non-finite or zero length; dropped at those vertices",
            s.len()
        ));
    }
    let bad_uv = uv
        .iter()
        .filter(|q| !(q.x.is_finite() && q.y.is_finite()))
        .count();
    if bad_uv > 0 {
        for q in uv.iter_mut() {
            if !(q.x.is_finite() && q.y.is_finite()) {
                *q = Point2f::new(0.0, 0.0);
            }
        }
        warnings.push(format!(
            "trianglemesh: {bad_uv} of {} texture coordinates \"uv\" are not finite; set to (0, 0)",
            uv.len()
        ));
    }
    (n, s, uv)
}

/// The usable triangles of `mesh`: degenerate ones (zero area, non-finite
/// vertices) are left out, as [`TriangleMesh::new`] warned.
pub fn triangles(mesh: &Arc<TriangleMesh>) -> Vec<Triangle> {
    (0..mesh.n_triangles())
        .filter(|&i| mesh.is_valid_triangle(i))
        .map(|i| Triangle::new(mesh.clone(), i as u32))
        .collect()
}

/// The watertight ray–triangle intersection of pbrt-v4 (Woop, Benthin and
/// Wald 2013): returns the barycentric coordinates `(b0, b1, b2)` of the
/// closest hit with `0 < t < t_max` and its `t`, which is conservatively
/// positive given floating-point error. Rays through a shared edge or
/// vertex hit at least one of the triangles that share it.
pub fn intersect_triangle(
    ray: &Ray,
    t_max: Float,
    p0: Point3f,
    p1: Point3f,
    p2: Point3f,
) -> Option<(Float, Float, Float, Float)> {
    // Degenerate triangles (and NaN vertices) never hit.
    if !triangle_is_nondegenerate(p0, p1, p2) {
        return None;
    }
    intersect_nondegenerate_triangle(ray, t_max, p0, p1, p2)
}

/// The test [`intersect_triangle`] starts with: false for triangles of zero
/// area (as computed in `f32`) and for NaN vertices, which never hit.
#[inline]
pub fn triangle_is_nondegenerate(p0: Point3f, p1: Point3f, p2: Point3f) -> bool {
    cross(p2 - p0, p1 - p0).length_squared() > 0.0
}

/// The per-ray part of the watertight test: the permutation that makes the
/// ray direction's largest component z and the shear that maps the ray to
/// the +z axis. Aggregates compute it once per ray instead of once per
/// triangle tested (the result is the same).
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    /// The ray origin with a zero fourth lane.
    pub(super) o: [Float; 4],
    /// Which components become x, y and z (each < 3).
    pub(super) perm: [usize; 3],
    pub(super) sx: Float,
    pub(super) sy: Float,
    pub(super) sz: Float,
}

/// `v` with its components reordered by `perm` (each < 4; lane 3 holds
/// `w`): the components are picked by index from an array rather than by
/// a `match`, since the permutation depends on the ray's direction and
/// branches on it would mispredict.
#[inline(always)]
fn gather(v: [Float; 4], perm: [usize; 3]) -> Vector3f {
    Vector3f::new(v[perm[0] & 3], v[perm[1] & 3], v[perm[2] & 3])
}

impl TriangleRay {
    /// The permutation and shear for `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        // `max_dimension` of |d| (same ties), by selection.
        let a = ray.d.abs();
        let sel = std::hint::select_unpredictable;
        let kz: usize = sel(a.x > a.y, sel(a.x > a.z, 0, 2), sel(a.y > a.z, 1, 2));
        let kx = [1, 2, 0][kz];
        let ky = [2, 0, 1][kz];
        let perm = [kx, ky, kz];
        let d = gather([ray.d.x, ray.d.y, ray.d.z, 0.0], perm);
        TriangleRay {
            o: [ray.o.x, ray.o.y, ray.o.z, 0.0],
            perm,
            sx: -d.x / d.z,
            sy: -d.y / d.z,
            sz: 1.0 / d.z,
        }
    }

    /// `p − o`, permuted.
    #[inline(always)]
    fn relative(&self, p: Point3f) -> Vector3f {
        let o = self.o;
        gather([p.x - o[0], p.y - o[1], p.z - o[2], 0.0], self.perm)
    }
}

/// [`intersect_triangle`] for a triangle already known to pass
/// [`triangle_is_nondegenerate`] (aggregates check that once, at build
/// time).
#[inline(always)]
pub fn intersect_nondegenerate_triangle(
    ray: &Ray,
    t_max: Float,
    p0: Point3f,
    p1: Point3f,
    p2: Point3f,
) -> Option<(Float, Float, Float, Float)> {
    intersect_prepared_triangle(&TriangleRay::new(ray), t_max, p0, p1, p2)
}

/// [`intersect_nondegenerate_triangle`] with the ray's permutation and
/// shear already computed.
#[inline(always)]
pub fn intersect_prepared_triangle(
    tr: &TriangleRay,
    t_max: Float,
    p0: Point3f,
    p1: Point3f,
    p2: Point3f,
) -> Option<(Float, Float, Float, Float)> {
    debug_assert!(triangle_is_nondegenerate(p0, p1, p2));
    // Translate to the ray origin, permute so the ray's largest direction
    // component is z, and shear so the ray becomes the +z axis.
    let (sx, sy, sz) = (tr.sx, tr.sy, tr.sz);
    let mut p0t = tr.relative(p0);
    let mut p1t = tr.relative(p1);
    let mut p2t = tr.relative(p2);
    for q in [&mut p0t, &mut p1t, &mut p2t] {
        q.x += sx * q.z;
        q.y += sy * q.z;
    }

    // Edge functions. pbrt-v4 redoes them in double precision when one is
    // exactly zero, so that the sign test is exact for rays through edges;
    // `difference_of_products` already forms them in double precision
    // (exact products, one rounding), so the redo would give the same
    // values and is left out.
    let e0 = difference_of_products(p1t.x, p2t.y, p1t.y, p2t.x);
    let e1 = difference_of_products(p2t.x, p0t.y, p2t.y, p0t.x);
    let e2 = difference_of_products(p0t.x, p1t.y, p0t.y, p1t.x);
    // The tests are combined with `|` and `&`, not `||` and `&&`: whether a
    // ray hits is unpredictable, and one branch mispredicts less than six.
    let mixed_signs = (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) & (e0 > 0.0 || e1 > 0.0 || e2 > 0.0);
    let det = e0 + e1 + e2;
    if mixed_signs | (det == 0.0) | det.is_nan() {
        return None;
    }

    // Scaled hit distance, tested against (0, t_max) without dividing.
    p0t.z *= sz;
    p1t.z *= sz;
    p2t.z *= sz;
    let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
    let behind_neg = (det < 0.0) & ((t_scaled >= 0.0) | (t_scaled < t_max * det));
    let behind_pos = (det > 0.0) & ((t_scaled <= 0.0) | (t_scaled > t_max * det));
    if behind_neg | behind_pos {
        return None;
    }
    let inv_det = 1.0 / det;
    let (b0, b1, b2) = (e0 * inv_det, e1 * inv_det, e2 * inv_det);
    let t = t_scaled * inv_det;
    if t.is_nan() {
        return None;
    }

    // Conservative error bound on t (book section 6.8.7): reject hits too
    // close to the origin to be sure they are in front of it.
    let max_zt = Vector3f::new(p0t.z, p1t.z, p2t.z)
        .abs()
        .max_component_value();
    let delta_z = gamma(3) * max_zt;
    let max_xt = Vector3f::new(p0t.x, p1t.x, p2t.x)
        .abs()
        .max_component_value();
    let max_yt = Vector3f::new(p0t.y, p1t.y, p2t.y)
        .abs()
        .max_component_value();
    let delta_x = gamma(5) * (max_xt + max_zt);
    let delta_y = gamma(5) * (max_yt + max_zt);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = Vector3f::new(e0, e1, e2).abs().max_component_value();
    let delta_t =
        3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some((b0, b1, b2, t))
}

/// One triangle of a [`TriangleMesh`], reached through `M`: an
/// `Arc<TriangleMesh>` for the [`Triangle`] shape, or a plain reference for
/// the triangles an aggregate stores as a mesh and an index.
#[derive(Clone, Debug)]
pub struct TriangleOf<M> {
    /// The mesh holding the vertices.
    pub mesh: M,
    /// Which triangle of the mesh.
    pub tri_index: u32,
}

/// One triangle of a shared [`TriangleMesh`]: the triangle shape.
pub type Triangle = TriangleOf<Arc<TriangleMesh>>;

/// The parts of a triangle's surface interaction that do not depend on
/// where it is hit: the geometric normal (oriented), dp/du and dp/dv, and
/// dn/du and dn/dv from the vertex normals (zero without them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriangleFrame {
    /// The geometric normal, flipped for reverse orientation and
    /// handedness (before facing the shading normal).
    pub n: Normal3f,
    /// ∂p/∂u.
    pub dpdu: Vector3f,
    /// ∂p/∂v.
    pub dpdv: Vector3f,
    /// ∂n/∂u.
    pub dndu: Normal3f,
    /// ∂n/∂v.
    pub dndv: Normal3f,
}

impl<M: Deref<Target = TriangleMesh>> TriangleOf<M> {
    /// Triangle `tri_index` of `mesh` (which must be in range; use
    /// [`triangles`] to get only the valid ones).
    pub fn new(mesh: M, tri_index: u32) -> Self {
        debug_assert!((tri_index as usize) < mesh.n_triangles());
        TriangleOf { mesh, tri_index }
    }

    #[inline]
    fn vertices(&self) -> [Point3f; 3] {
        self.mesh.vertices(self.tri_index as usize)
    }

    #[inline(always)]
    fn vertex_indices(&self) -> [usize; 3] {
        self.mesh.vertex_indices(self.tri_index as usize)
    }

    /// The texture coordinates of the vertices, (0,0), (1,0), (1,1) when
    /// the mesh has none.
    #[inline(always)]
    fn uvs(&self) -> [Point2f; 3] {
        match &self.mesh.uv {
            Some(uv) => {
                let v = self.vertex_indices();
                [uv[v[0]], uv[v[1]], uv[v[2]]]
            }
            None => [
                Point2f::new(0.0, 0.0),
                Point2f::new(1.0, 0.0),
                Point2f::new(1.0, 1.0),
            ],
        }
    }

    /// The texture coordinates at barycentrics (b0, b1, b2), as the
    /// interaction interpolates them.
    #[inline(always)]
    pub(crate) fn uv_at(&self, b0: Float, b1: Float, b2: Float) -> Point2f {
        let uv = self.uvs();
        Point2f::new(
            b0 * uv[0].x + b1 * uv[1].x + b2 * uv[2].x,
            b0 * uv[0].y + b1 * uv[1].y + b2 * uv[2].y,
        )
    }

    /// The triangle's face index (ptex), 0 when the mesh has none.
    #[inline(always)]
    pub(crate) fn face_index(&self) -> i32 {
        self.mesh
            .face_indices
            .as_ref()
            .map_or(0, |f| f[self.tri_index as usize])
    }

    /// The solid angle the triangle subtends from `p`.
    pub fn solid_angle(&self, p: Point3f) -> Float {
        let [a, b, c] = self.directions_from(p);
        spherical_triangle_area(a, b, c)
    }

    /// The unit directions from `p` to the vertices.
    #[inline]
    fn directions_from(&self, p: Point3f) -> [Vector3f; 3] {
        directions_to(self.vertices(), p)
    }

    /// The geometric normal at barycentrics `b`, oriented as intersections
    /// orient it: toward the interpolated shading normal when there are
    /// per-vertex normals, else flipped by reverse orientation XOR a
    /// handedness change.
    fn oriented_normal(&self, b: [Float; 3]) -> Normal3f {
        let [p0, p1, p2] = self.vertices();
        let n = Normal3f::from(cross(p1 - p0, p2 - p0).normalize());
        if let Some(ns) = &self.mesh.n {
            let v = self.vertex_indices();
            n.face_forward(ns[v[0]] * b[0] + ns[v[1]] * b[1] + ns[v[2]] * b[2])
        } else if self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness {
            -n
        } else {
            n
        }
    }

    /// The normal [`Triangle::oriented_normal`] gives at every point of the
    /// triangle, when it is the same everywhere: always without vertex
    /// normals; with them, when all three lie clearly (by a margin far
    /// above rounding) on the same side of the face, so that their
    /// interpolation cannot flip it. `None` otherwise.
    pub fn uniform_oriented_normal(&self) -> Option<Normal3f> {
        let [p0, p1, p2] = self.vertices();
        let n = Normal3f::from(cross(p1 - p0, p2 - p0).normalize());
        if !(n.x.is_finite() && n.y.is_finite() && n.z.is_finite()) {
            return None;
        }
        match &self.mesh.n {
            Some(ns) => {
                let v = self.vertex_indices();
                let side = |i: usize| {
                    let m = ns[v[i]];
                    let d = dot(n, m);
                    let margin = 1e-3 * m.length();
                    if d > margin {
                        1
                    } else if d < -margin {
                        -1
                    } else {
                        0
                    }
                };
                match (side(0), side(1), side(2)) {
                    (1, 1, 1) => Some(n),
                    (-1, -1, -1) => Some(-n),
                    _ => None,
                }
            }
            None if self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness => {
                Some(-n)
            }
            None => Some(n),
        }
    }

    /// The closest hit along `ray` in (0, `t_max`) as barycentrics and
    /// `t`, without the surface interaction (which an aggregate needs only
    /// for the closest of its hits: see [`Triangle::interaction_at_hit`]).
    #[inline]
    pub fn intersect_barycentrics(
        &self,
        ray: &Ray,
        t_max: Float,
    ) -> Option<(Float, Float, Float, Float)> {
        let [p0, p1, p2] = self.vertices();
        intersect_triangle(ray, t_max, p0, p1, p2)
    }

    /// The rendering-space vertices.
    #[inline]
    pub fn vertex_positions(&self) -> [Point3f; 3] {
        self.vertices()
    }

    /// The surface interaction of a hit of `ray` found by
    /// [`Triangle::intersect_barycentrics`] at barycentrics (b0, b1, b2):
    /// what [`ShapeMethods::intersect`] returns for that hit.
    pub fn interaction_at_hit(
        &self,
        b0: Float,
        b1: Float,
        b2: Float,
        ray: &Ray,
    ) -> SurfaceInteraction {
        self.interaction_at_hit_with_frame(&self.frame(), b0, b1, b2, ray)
    }

    /// [`Triangle::interaction_at_hit`] with the triangle's
    /// [`TriangleFrame`] already computed (aggregates keep one per
    /// triangle): the same interaction.
    #[inline]
    pub fn interaction_at_hit_with_frame(
        &self,
        frame: &TriangleFrame,
        b0: Float,
        b1: Float,
        b2: Float,
        ray: &Ray,
    ) -> SurfaceInteraction {
        let wo = (-ray.d).try_normalize().unwrap_or_default();
        self.interaction(frame, b0, b1, b2, ray.time, wo)
    }

    /// The parts of the surface interaction that are the same at every
    /// point of the triangle (pbrt-v4 computes them at each hit).
    pub fn frame(&self) -> TriangleFrame {
        let mesh = &*self.mesh;
        let v = self.vertex_indices();
        let [p0, p1, p2] = self.vertices();
        let uv = self.uvs();

        // dp/du and dp/dv from the uv parameterization, or any tangent
        // frame when the uv mapping is degenerate.
        let duv02 = uv[0] - uv[2];
        let duv12 = uv[1] - uv[2];
        let dp02 = p0 - p2;
        let dp12 = p1 - p2;
        let determinant = difference_of_products(duv02.x, duv12.y, duv02.y, duv12.x);
        let degenerate_uv = determinant.abs() < 1e-9;
        let (mut dpdu, mut dpdv) = (Vector3f::default(), Vector3f::default());
        if !degenerate_uv {
            let inv = 1.0 / determinant;
            dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv;
            dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
        }
        if degenerate_uv || !(cross(dpdu, dpdv).length_squared() > 0.0) {
            let mut ng = cross(p2 - p0, p1 - p0);
            if ng.length_squared() == 0.0 {
                // The f32 cross product underflowed; redo it in double.
                let (a, c) = (p2 - p0, p1 - p0);
                let f = |x: Float, y: Float, z: Float, w: Float| {
                    (x as f64 * y as f64 - z as f64 * w as f64) as Float
                };
                ng = Vector3f::new(
                    f(a.y, c.z, a.z, c.y),
                    f(a.z, c.x, a.x, c.z),
                    f(a.x, c.y, a.y, c.x),
                );
            }
            let (s, t) = ng
                .try_normalize()
                .unwrap_or(Vector3f::new(0.0, 0.0, 1.0))
                .coordinate_system();
            dpdu = s;
            dpdv = t;
        }

        // The geometric normal follows the vertex order, not dpdu × dpdv
        // (so that one is never computed).
        let mut n = Normal3f::from(cross(dp02, dp12).normalize());
        if mesh.reverse_orientation ^ mesh.transform_swaps_handedness {
            n = -n;
        }

        // dn/du and dn/dv from the vertex normals.
        let (dndu, dndv) = match &mesh.n {
            Some(nn) => {
                let dn1 = nn[v[0]] - nn[v[2]];
                let dn2 = nn[v[1]] - nn[v[2]];
                if degenerate_uv {
                    // Derivatives with respect to the same arbitrary
                    // frame used for dp/du, so that reflected ray
                    // differentials stay reasonable.
                    let dn = cross(
                        Vector3f::from(nn[v[2]] - nn[v[0]]),
                        Vector3f::from(nn[v[1]] - nn[v[0]]),
                    );
                    match dn.try_normalize() {
                        Some(dn) => {
                            let (a, c) = dn.coordinate_system();
                            (Normal3f::from(a), Normal3f::from(c))
                        }
                        None => (Normal3f::default(), Normal3f::default()),
                    }
                } else {
                    let inv = 1.0 / determinant;
                    (
                        (dn1 * duv12.y - dn2 * duv02.y) * inv,
                        (dn2 * duv02.x - dn1 * duv12.x) * inv,
                    )
                }
            }
            None => (Normal3f::default(), Normal3f::default()),
        };
        TriangleFrame {
            n,
            dpdu,
            dpdv,
            dndu,
            dndv,
        }
    }

    /// The full surface interaction at barycentrics (b0, b1, b2), given
    /// the triangle's frame.
    #[inline(always)]
    fn interaction(
        &self,
        frame: &TriangleFrame,
        b0: Float,
        b1: Float,
        b2: Float,
        time: Float,
        wo: Vector3f,
    ) -> SurfaceInteraction {
        let mesh = &*self.mesh;
        let v = self.vertex_indices();
        let [p0, p1, p2] = self.vertices();
        let TriangleFrame {
            n,
            dpdu,
            dpdv,
            dndu,
            dndv,
        } = *frame;

        let p_hit = p0 * b0 + p1 * b1 + p2 * b2;
        let uv_hit = self.uv_at(b0, b1, b2);
        let abs_sum = (p0 * b0).abs() + (p1 * b1).abs() + (p2 * b2).abs();
        let p_error = Vector3f::from(abs_sum) * gamma(7);

        // What `SurfaceInteraction::new` builds, except that the geometric
        // normal comes from the frame.
        let mut isect = SurfaceInteraction {
            pi: Point3fi::from_value_and_error(p_hit, p_error),
            time,
            wo,
            n,
            uv: uv_hit,
            dpdu,
            dpdv,
            dndu: Normal3f::default(),
            dndv: Normal3f::default(),
            shading: ShadingGeometry {
                n,
                dpdu,
                dpdv,
                dndu: Normal3f::default(),
                dndv: Normal3f::default(),
            },
            ..Default::default()
        };
        isect.face_index = self.face_index();

        if mesh.n.is_some() || mesh.s.is_some() {
            // Shading normal: interpolated vertex normals when usable.
            let ns = match &mesh.n {
                Some(nn) => {
                    let ns = nn[v[0]] * b0 + nn[v[1]] * b1 + nn[v[2]] * b2;
                    if ns.length_squared() > 0.0 {
                        ns.normalize()
                    } else {
                        isect.n
                    }
                }
                None => isect.n,
            };
            // Shading tangent: interpolated tangents or dp/du.
            let mut ss = match &mesh.s {
                Some(s) => {
                    let ss = s[v[0]] * b0 + s[v[1]] * b1 + s[v[2]] * b2;
                    if ss.length_squared() == 0.0 {
                        isect.dpdu
                    } else {
                        ss
                    }
                }
                None => isect.dpdu,
            };
            let mut ts = cross(ns, ss);
            if ts.length_squared() > 0.0 {
                ss = cross(ts, ns);
            } else {
                let (a, c) = Vector3f::from(ns).coordinate_system();
                ss = a;
                ts = c;
            }
            isect.set_shading_geometry(ns, ss, ts, dndu, dndv, true);
        }
        isect
    }
}

impl ShapeMethods for Triangle {
    fn bounds(&self) -> Bounds3f {
        let [p0, p1, p2] = self.vertices();
        Bounds3f::new(p0, p1).union_point(p2)
    }

    fn normal_bounds(&self) -> DirectionCone {
        let [p0, p1, p2] = self.vertices();
        let n = Normal3f::from(cross(p1 - p0, p2 - p0).normalize());
        let n = if let Some(ns) = &self.mesh.n {
            let v = self.vertex_indices();
            n.face_forward(ns[v[0]] + ns[v[1]] + ns[v[2]])
        } else if self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness {
            -n
        } else {
            n
        };
        DirectionCone::from_direction(Vector3f::from(n))
    }

    fn intersect(&self, ray: &Ray, t_max: Float) -> Option<ShapeIntersection> {
        let (b0, b1, b2, t) = self.intersect_barycentrics(ray, t_max)?;
        Some(ShapeIntersection {
            intr: self.interaction_at_hit(b0, b1, b2, ray),
            t_hit: t,
        })
    }

    fn intersect_p(&self, ray: &Ray, t_max: Float) -> bool {
        let [p0, p1, p2] = self.vertices();
        intersect_triangle(ray, t_max, p0, p1, p2).is_some()
    }

    fn area(&self) -> Float {
        let [p0, p1, p2] = self.vertices();
        0.5 * cross(p1 - p0, p2 - p0).length()
    }

    fn sample_area(&self, u: Point2f) -> Option<ShapeSample> {
        sample_area(self, u)
    }

    #[inline(always)]
    fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        sample_solid_angle(self, ctx, u)
    }

    fn pdf(&self, ctx: &ShapeSampleContext, wi: Vector3f) -> Float {
        let dirs = self.directions_from(ctx.p());
        let sa = spherical_triangle_area(dirs[0], dirs[1], dirs[2]);
        if !(MIN_SPHERICAL_SAMPLE_AREA..=MAX_SPHERICAL_SAMPLE_AREA).contains(&sa) {
            return pdf_by_intersection(self, ctx, wi);
        }
        if !self.intersect_p(&ctx.spawn_ray(wi), Float::INFINITY) {
            return 0.0;
        }
        let mut pdf = 1.0 / sa;
        if !ctx.ns.is_zero() {
            let w = cos_weights(ctx, &dirs);
            let u = invert_spherical_triangle_sample_dirs(dirs, sa, wi.normalize());
            pdf *= bilinear_pdf(u, w);
        }
        pdf
    }
}

/// What sampling a point on a triangle reads: a mesh triangle's data, or
/// an emitter's copy of it ([`SampledTriangle`]).
trait TriangleGeometry {
    fn corners(&self) -> [Point3f; 3];
    fn corner_uvs(&self) -> [Point2f; 3];
    fn normal_at(&self, b: [Float; 3]) -> Normal3f;
    fn surface_area(&self) -> Float;
}

impl TriangleGeometry for Triangle {
    #[inline(always)]
    fn corners(&self) -> [Point3f; 3] {
        Triangle::vertices(self)
    }
    #[inline(always)]
    fn corner_uvs(&self) -> [Point2f; 3] {
        Triangle::uvs(self)
    }
    #[inline(always)]
    fn normal_at(&self, b: [Float; 3]) -> Normal3f {
        Triangle::oriented_normal(self, b)
    }
    #[inline(always)]
    fn surface_area(&self) -> Float {
        ShapeMethods::area(self)
    }
}

/// A triangle's sampling data copied out of its mesh, for an emitter whose
/// oriented normal is the same everywhere
/// ([`Triangle::uniform_oriented_normal`]): light samples are taken at
/// nearly every path vertex, and reading the copy saves the index
/// lookups and the per-sample normal computation. Samples are the ones
/// the mesh triangle gives, bit for bit.
#[derive(Clone, Debug)]
pub struct SampledTriangle {
    v: [Point3f; 3],
    uv: [Point2f; 3],
    n: Normal3f,
    area: Float,
}

impl SampledTriangle {
    /// The copy of `tri`, when its oriented normal is uniform.
    pub fn new(tri: &Triangle) -> Option<SampledTriangle> {
        Some(SampledTriangle {
            n: tri.uniform_oriented_normal()?,
            v: tri.vertices(),
            uv: tri.uvs(),
            area: ShapeMethods::area(tri),
        })
    }

    /// [`ShapeMethods::sample`] of the triangle (by solid angle).
    #[inline]
    pub fn sample(&self, ctx: &ShapeSampleContext, u: Point2f) -> Option<ShapeSample> {
        sample_solid_angle(self, ctx, u)
    }

    /// [`SampledTriangle::sample`] in two steps, so that many samples'
    /// lane-parallel parts run together ([`sample_solid_angle_points`]):
    /// the query of a sample ...
    #[inline]
    pub(crate) fn solid_angle_query(
        &self,
        ctx: &ShapeSampleContext,
        u: Point2f,
    ) -> SolidAngleQuery {
        SolidAngleQuery {
            v: self.v,
            p: ctx.p(),
            ns: ctx.ns,
            u,
        }
    }

    /// The normal of every point on the triangle.
    #[inline(always)]
    pub(crate) fn normal(&self) -> Normal3f {
        self.n
    }

    /// ... and the sample, given its query's core (the same value as
    /// [`SampledTriangle::sample`]).
    #[inline]
    pub(crate) fn finish_sample(
        &self,
        ctx: &ShapeSampleContext,
        u: Point2f,
        core: SolidAngleCore,
    ) -> Option<ShapeSample> {
        finish_solid_angle(self, ctx, u, core)
    }
}

impl TriangleGeometry for SampledTriangle {
    #[inline(always)]
    fn corners(&self) -> [Point3f; 3] {
        self.v
    }
    #[inline(always)]
    fn corner_uvs(&self) -> [Point2f; 3] {
        self.uv
    }
    #[inline(always)]
    fn normal_at(&self, _b: [Float; 3]) -> Normal3f {
        self.n
    }
    #[inline(always)]
    fn surface_area(&self) -> Float {
        self.area
    }
}

/// The unit directions from `p` to the vertices (NaN components when `p`
/// is a vertex), shared by the solid angle, the cos θ weights and
/// spherical sampling so that each is normalised once.
#[inline(always)]
fn directions_to(v: [Point3f; 3], p: Point3f) -> [Vector3f; 3] {
    let [p0, p1, p2] = v;
    [
        (p0 - p).normalize(),
        (p1 - p).normalize(),
        (p2 - p).normalize(),
    ]
}

/// The weights of the bilinear cos θ warp for spherical sampling from
/// `ctx`: corner (0,0) and (1,0) map to vertex 1, (0,1) to vertex 0 and
/// (1,1) to vertex 2, as the spherical triangle sampler lays them out.
/// `dirs` are the unit directions from the reference point to the
/// vertices.
#[inline(always)]
fn cos_weights(ctx: &ShapeSampleContext, dirs: &[Vector3f; 3]) -> [Float; 4] {
    let w = |d: Vector3f| abs_dot(ctx.ns, d).max(0.01);
    let (w0, w1, w2) = (w(dirs[0]), w(dirs[1]), w(dirs[2]));
    [w1, w1, w0, w2]
}

/// The sample at barycentrics `b` with density `pdf`.
#[inline(always)]
fn sample_at<T: TriangleGeometry>(t: &T, b: [Float; 3], pdf: Float, time: Float) -> ShapeSample {
    let [p0, p1, p2] = t.corners();
    let p = p0 * b[0] + p1 * b[1] + p2 * b[2];
    let abs_sum = (p0 * b[0]).abs() + (p1 * b[1]).abs() + (p2 * b[2]).abs();
    let p_error = Vector3f::from(abs_sum) * gamma(6);
    let uv = t.corner_uvs();
    let uv = Point2f::new(
        b[0] * uv[0].x + b[1] * uv[1].x + b[2] * uv[2].x,
        b[0] * uv[0].y + b[1] * uv[1].y + b[2] * uv[2].y,
    );
    ShapeSample {
        pi: Point3fi::from_value_and_error(p, p_error),
        n: t.normal_at(b),
        uv,
        time,
        pdf,
    }
}

/// A uniform sample by area.
#[inline]
fn sample_area<T: TriangleGeometry>(t: &T, u: Point2f) -> Option<ShapeSample> {
    let b = sample_uniform_triangle(u);
    let pdf = 1.0 / t.surface_area();
    pdf.is_finite().then(|| sample_at(t, b, pdf, 0.0))
}

/// pbrt-v4's `Triangle::Sample(ctx, u)`: uniform in the solid angle the
/// triangle subtends, warped by the cos θ approximation at the reference
/// point; by area when the solid angle is too small or too large. The
/// arithmetic is [`solid_angle_lanes`] at width one, the same that
/// [`sample_solid_angle_points`] runs on many samples at once.
#[inline(always)]
fn sample_solid_angle<T: TriangleGeometry>(
    t: &T,
    ctx: &ShapeSampleContext,
    u: Point2f,
) -> Option<ShapeSample> {
    let q = SolidAngleQuery {
        v: t.corners(),
        p: ctx.p(),
        ns: ctx.ns,
        u,
    };
    let mut core = SolidAngleCore::default();
    SolidAngleCore::each_lane(&solid_angle_lanes::<Scalar1>(&[q]), 1, |c| core = c);
    finish_solid_angle(t, ctx, u, core)
}

/// The shape sample of a solid-angle sample's core: by area where the
/// core says so, else at its barycentrics.
#[inline(always)]
fn finish_solid_angle<T: TriangleGeometry>(
    t: &T,
    ctx: &ShapeSampleContext,
    u: Point2f,
    core: SolidAngleCore,
) -> Option<ShapeSample> {
    if core.by_area {
        let mut ss = sample_area(t, u)?;
        ss.time = ctx.time;
        return area_sample_to_solid_angle(ctx, ss);
    }
    core.ok.then(|| sample_at(t, core.b, core.pdf, ctx.time))
}

/// One solid-angle sample of a triangle to take: its corners, the
/// reference point, its shading normal (zero: no cos θ warp) and the
/// sample.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SolidAngleQuery {
    pub v: [Point3f; 3],
    pub p: Point3f,
    pub ns: Normal3f,
    pub u: Point2f,
}

/// The part of a solid-angle sample that runs lane-parallel: the
/// barycentrics and density of the sample (`ok`: there is one), or the
/// verdict that the triangle is sampled by area instead.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SolidAngleCore {
    pub b: [Float; 3],
    pub pdf: Float,
    pub ok: bool,
    pub by_area: bool,
}

/// Lane results of [`solid_angle_lanes`].
pub(crate) struct SolidAngleLanes<L: F32Lanes> {
    b: [L; 3],
    pdf: L,
    ok: L::Mask,
    by_area: L::Mask,
    /// The queries' corners and reference points.
    v: [V3<L>; 3],
    p: V3<L>,
}

impl SolidAngleCore {
    /// The first `n` lanes of `l`, in order, to `out`.
    #[inline(always)]
    fn each_lane<L: F32Lanes>(
        l: &SolidAngleLanes<L>,
        n: usize,
        mut out: impl FnMut(SolidAngleCore),
    ) {
        let mut a = [[0.0; 16]; 4];
        l.b[0].store(&mut a[0]);
        l.b[1].store(&mut a[1]);
        l.b[2].store(&mut a[2]);
        l.pdf.store(&mut a[3]);
        let (ok, by_area) = (L::bits(l.ok), L::bits(l.by_area));
        // Lane i of several stored rows: indexing reads best.
        #[allow(clippy::needless_range_loop)]
        for i in 0..n {
            out(SolidAngleCore {
                b: [a[0][i], a[1][i], a[2][i]],
                pdf: a[3][i],
                ok: (ok >> i) & 1 != 0,
                by_area: (by_area >> i) & 1 != 0,
            });
        }
    }
}

/// The solid-angle sampling of `q[..L::N]` (shorter: the first query
/// fills the rest), one per lane, in the operations of the scalar code it
/// replaced: the solid angle, the bilinear cos θ warp and the spherical
/// triangle sample.
#[inline(always)]
fn solid_angle_lanes<L: F32Lanes>(q: &[SolidAngleQuery]) -> SolidAngleLanes<L> {
    let sp = L::splat;
    let mut cols = [[[0.0f32; 3]; 16]; 5];
    let mut us = [[0.0f32; 16]; 2];
    for i in 0..L::N {
        let x = q.get(i).unwrap_or(&q[0]);
        for (k, c) in x.v.iter().enumerate() {
            cols[k][i] = [c.x, c.y, c.z];
        }
        cols[3][i] = [x.p.x, x.p.y, x.p.z];
        cols[4][i] = [x.ns.x, x.ns.y, x.ns.z];
        us[0][i] = x.u.x;
        us[1][i] = x.u.y;
    }
    let v = [
        V3::<L>::gather(&cols[0]),
        V3::gather(&cols[1]),
        V3::gather(&cols[2]),
    ];
    let p = V3::<L>::gather(&cols[3]);
    let ns = V3::<L>::gather(&cols[4]);
    let u = [L::load(&us[0]), L::load(&us[1])];

    let dirs = [
        v[0].sub(p).normalize(),
        v[1].sub(p).normalize(),
        v[2].sub(p).normalize(),
    ];
    let sa = spherical_triangle_area_lanes(dirs[0], dirs[1], dirs[2]);
    let in_range = L::and(
        sa.ge(sp(MIN_SPHERICAL_SAMPLE_AREA)),
        sa.le(sp(MAX_SPHERICAL_SAMPLE_AREA)),
    );
    // Warp u by an approximation of the cos θ factor at the reference
    // point (where there is a normal), then sample the spherical
    // triangle uniformly.
    let zero = sp(0.0);
    let no_normal = L::and(L::and(ns.x.eq(zero), ns.y.eq(zero)), ns.z.eq(zero));
    let w0 = ns.dot(dirs[0]).abs().max(sp(0.01));
    let w1 = ns.dot(dirs[1]).abs().max(sp(0.01));
    let w2 = ns.dot(dirs[2]).abs().max(sp(0.01));
    let weights = [w1, w1, w0, w2];
    let warped = sample_bilinear_lanes(u, weights);
    let warp_pdf = bilinear_pdf_lanes(warped, weights);
    let u = [
        L::select(no_normal, u[0], warped[0]),
        L::select(no_normal, u[1], warped[1]),
    ];
    let pdf = L::select(no_normal, sp(1.0), sp(1.0).mul(warp_pdf));
    // In range the solid angle is finite and positive, so the directions
    // are the ones `try_normalize` would give.
    let tri = sample_spherical_lanes(dirs, sa, v, p, u);
    let ok = L::and(tri.ok, tri.pdf.gt(zero));
    SolidAngleLanes {
        b: tri.b,
        pdf: pdf.mul(tri.pdf),
        ok,
        by_area: L::not(in_range),
        v,
        p,
    }
}

/// [`crate::sampling::sample_linear`] of each lane.
#[inline(always)]
fn sample_linear_lanes<L: F32Lanes>(u: L, a: L, b: L) -> L {
    let zero = L::splat(0.0);
    let x = u
        .mul(a.add(b))
        .div(a.add(math::lerp(u, a.mul(a), b.mul(b)).sqrt()));
    let x = x.min(L::splat(ONE_MINUS_EPSILON));
    L::select(L::and(u.eq(zero), a.eq(zero)), zero, x)
}

/// [`sample_bilinear`] of each lane.
#[inline(always)]
fn sample_bilinear_lanes<L: F32Lanes>(u: [L; 2], w: [L; 4]) -> [L; 2] {
    let y = sample_linear_lanes(u[1], w[0].add(w[1]), w[2].add(w[3]));
    let x = sample_linear_lanes(u[0], math::lerp(y, w[0], w[2]), math::lerp(y, w[1], w[3]));
    [x, y]
}

/// [`bilinear_pdf`] of each lane.
#[inline(always)]
fn bilinear_pdf_lanes<L: F32Lanes>(p: [L; 2], w: [L; 4]) -> L {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let sum = w[0].add(w[1]).add(w[2]).add(w[3]);
    let (x, y) = (p[0], p[1]);
    let (nx, ny) = (one.sub(x), one.sub(y));
    let f = nx
        .mul(ny)
        .mul(w[0])
        .add(x.mul(ny).mul(w[1]))
        .add(nx.mul(y).mul(w[2]))
        .add(x.mul(y).mul(w[3]));
    let pdf = L::splat(4.0).mul(f).div(sum);
    let pdf = L::select(sum.eq(zero), one, pdf);
    let inside = L::and(L::and(x.ge(zero), x.le(one)), L::and(y.ge(zero), y.le(one)));
    L::select(inside, pdf, zero)
}

/// A solid-angle sample taken to its point in lanes: the core and, where
/// the core has a sample by solid angle (`ok` and not `by_area`), the
/// sampled point's interval ([`sample_at`]'s) and, when its density is
/// positive and its midpoint is not the reference point (`toward`), the
/// unit direction to that midpoint: what a triangle light's `sample_li`
/// computes before its emission.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SolidAnglePoint {
    pub core: SolidAngleCore,
    pub pi: Point3fi,
    pub wi: Vector3f,
    pub toward: bool,
}

/// Runs [`solid_angle_lanes`] and the sampled points over every query.
struct SolidAnglePointKernel<'a> {
    queries: &'a [SolidAngleQuery],
    out: &'a mut Vec<SolidAnglePoint>,
}

impl Kernel for SolidAnglePointKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: F32Lanes>(self) {
        let zero = L::splat(0.0);
        for chunk in self.queries.chunks(L::N) {
            let l = solid_angle_lanes::<L>(chunk);
            // `sample_at`: the point, its error bound and interval.
            let [b0, b1, b2] = l.b;
            let (pb0, pb1, pb2) = (l.v[0].scale(b0), l.v[1].scale(b1), l.v[2].scale(b2));
            let p = pb0.add(pb1).add(pb2);
            let g = L::splat(gamma(6));
            let err = [
                pb0.x.abs().add(pb1.x.abs()).add(pb2.x.abs()).mul(g),
                pb0.y.abs().add(pb1.y.abs()).add(pb2.y.abs()).mul(g),
                pb0.z.abs().add(pb1.z.abs()).add(pb2.z.abs()).mul(g),
            ];
            let (lx, hx) = math::interval_from_value_and_error(p.x, err[0]);
            let (ly, hy) = math::interval_from_value_and_error(p.y, err[1]);
            let (lz, hz) = math::interval_from_value_and_error(p.z, err[2]);
            // `li_sample_from`: the direction from the reference point to
            // the point's midpoint.
            let two = L::splat(2.0);
            let mid = V3 {
                x: lx.add(hx).div(two),
                y: ly.add(hy).div(two),
                z: lz.add(hz).div(two),
            };
            let d = mid.sub(l.p);
            let len2 = d.dot(d);
            let wi = d.normalize();
            let toward = L::bits(L::and(L::not(l.pdf.eq(zero)), L::not(len2.eq(zero))));
            let mut a = [[0.0 as Float; 16]; 13];
            for (row, x) in a
                .iter_mut()
                .zip([b0, b1, b2, l.pdf, lx, ly, lz, hx, hy, hz, wi.x, wi.y, wi.z])
            {
                x.store(row);
            }
            let (ok, by_area) = (L::bits(l.ok), L::bits(l.by_area));
            // Lane i of several stored rows: indexing reads best.
            #[allow(clippy::needless_range_loop)]
            for i in 0..chunk.len() {
                let interval = |lo: usize| Interval {
                    low: a[lo][i],
                    high: a[lo + 3][i],
                };
                self.out.push(SolidAnglePoint {
                    core: SolidAngleCore {
                        b: [a[0][i], a[1][i], a[2][i]],
                        pdf: a[3][i],
                        ok: (ok >> i) & 1 != 0,
                        by_area: (by_area >> i) & 1 != 0,
                    },
                    pi: Point3fi::new(interval(4), interval(5), interval(6)),
                    wi: Vector3f::new(a[10][i], a[11][i], a[12][i]),
                    toward: (toward >> i) & 1 != 0,
                });
            }
        }
    }
}

/// The solid-angle samples of many queries (of any triangles) at once,
/// taken on to their points ([`SolidAnglePoint`]), at `level`'s width,
/// into `out` (cleared first): the same values [`Triangle`]'s and
/// [`SampledTriangle`]'s `sample` compute one by one.
pub(crate) fn sample_solid_angle_points(
    level: SimdLevel,
    queries: &[SolidAngleQuery],
    out: &mut Vec<SolidAnglePoint>,
) {
    out.clear();
    out.reserve(queries.len());
    dispatch(level, SolidAnglePointKernel { queries, out });
}

#[cfg(test)]
mod tests;
