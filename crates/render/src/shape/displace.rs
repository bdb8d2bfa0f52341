//! Displaced triangle meshes (pbrt-v4 `TriQuadMesh::Displace`,
//! `ConvertToOnlyTriangles` and `ComputeNormals` in `util/mesh.h`/`.cpp`,
//! applied to `plymesh` shapes with a `displacement` texture).
//!
//! The mesh is cut into triangles, each triangle is split at the midpoint
//! of its longest edge until every edge is shorter than the edge length
//! (measured in rendering space; shared edges are split once), then every
//! vertex moves along its normal by the displacement texture's value at its
//! object-space position and uv, and vertex normals are recomputed from the
//! displaced faces.

use std::collections::HashMap;

use rayon::prelude::*;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;

/// A triangle mesh in object space, as displacement reads and writes it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DisplacedMesh {
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
    /// Vertex positions.
    pub p: Vec<Point3f>,
    /// Vertex normals (one per vertex).
    pub n: Vec<Normal3f>,
    /// Vertex uvs (one per vertex).
    pub uv: Vec<Point2f>,
    /// One face index per triangle, or none.
    pub face_indices: Vec<i32>,
}

/// The most triangles refinement may make: past this the edge length is
/// surely a mistake, and the mesh would not fit in memory anyway.
pub const MAX_REFINED_TRIANGLES: usize = 1 << 26;

/// Splits pbrt-v4's bilinear-patch-ordered quads (corners 0, 1, 3, 2 of
/// the face) into triangles (0, 1, 2) and (0, 2, 3) of the face, after the
/// given triangles; face indices follow (`tri_face_indices` then one per
/// quad, or none).
pub fn triangulate(
    tri_indices: &[u32],
    quad_indices: &[u32],
    face_indices: &[i32],
) -> (Vec<u32>, Vec<i32>) {
    let ntri = tri_indices.len() / 3;
    let mut indices = Vec::with_capacity(tri_indices.len() + quad_indices.len() / 4 * 6);
    indices.extend_from_slice(tri_indices);
    let mut faces = Vec::new();
    let has_faces = !face_indices.is_empty();
    if has_faces {
        faces.extend((0..ntri).map(|i| face_indices.get(i).copied().unwrap_or(0)));
    }
    for (k, q) in quad_indices.chunks_exact(4).enumerate() {
        indices.extend_from_slice(&[q[0], q[1], q[3], q[0], q[3], q[2]]);
        if has_faces {
            let f = face_indices.get(ntri + k).copied().unwrap_or(0);
            faces.extend_from_slice(&[f, f]);
        }
    }
    (indices, faces)
}

/// Area-independent vertex normals: the sum of the unit normals of the
/// faces around each vertex, normalized (zero where there are none).
pub fn compute_normals(indices: &[u32], p: &[Point3f]) -> Vec<Normal3f> {
    let mut n = vec![Normal3f::new(0.0, 0.0, 0.0); p.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let (v10, v21) = (p[b] - p[a], p[c] - p[b]);
        if let Some(fn_) = cross(v10, v21).try_normalize() {
            let fn_ = Normal3f::from(fn_);
            n[a] += fn_;
            n[b] += fn_;
            n[c] += fn_;
        }
    }
    for v in &mut n {
        if v.length_squared() > 0.0 {
            *v = v.normalize();
        }
    }
    n
}

/// Why a mesh could not be displaced.
#[derive(Clone, Debug, PartialEq)]
pub enum DisplaceError {
    /// The mesh has no vertex uvs (pbrt-v4 requires them too).
    NoUvs,
    /// Refinement would make more than [`MAX_REFINED_TRIANGLES`].
    TooManyTriangles {
        /// The edge length asked for.
        edge_length: Float,
    },
    /// The refined mesh would need more memory than the budget has left.
    OverBudget(rpbrt_parser::OverBudget),
}

impl std::fmt::Display for DisplaceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DisplaceError::NoUvs => f.write_str("vertex uvs are required for displacement"),
            DisplaceError::TooManyTriangles { edge_length } => write!(
                f,
                "edge length {edge_length} would refine the mesh into more than \
                 {MAX_REFINED_TRIANGLES} triangles"
            ),
            DisplaceError::OverBudget(e) => write!(f, "{e}"),
        }
    }
}

/// Splits triangles until every edge is shorter than `max_dist` in
/// rendering space (pbrt-v4 `TriQuadMesh::Refine`): the longest edge is
/// cut at its midpoint, the new vertex's normal is the normalized sum of
/// its ends' and its uv their mean.
struct Refiner<'a> {
    mesh: DisplacedMesh,
    render_from_object: &'a Transform,
    max_dist: Float,
    edge_split: HashMap<(u32, u32), u32>,
}

impl Refiner<'_> {
    fn distance(&self, a: u32, b: u32) -> Float {
        let pa = self.render_from_object.apply_point(self.mesh.p[a as usize]);
        let pb = self.render_from_object.apply_point(self.mesh.p[b as usize]);
        (pa - pb).length()
    }

    fn midpoint(&mut self, a: u32, b: u32) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&m) = self.edge_split.get(&key) {
            return m;
        }
        let m = self.mesh.p.len() as u32;
        self.edge_split.insert(key, m);
        let (ia, ib) = (a as usize, b as usize);
        let mesh = &mut self.mesh;
        let p = mesh.p[ia] + (mesh.p[ib] - mesh.p[ia]) * 0.5;
        mesh.p.push(p);
        let n = mesh.n[ia] + mesh.n[ib];
        mesh.n.push(if n.length_squared() > 0.0 {
            n.normalize()
        } else {
            n
        });
        let uv = mesh.uv[ia] + (mesh.uv[ib] - mesh.uv[ia]) * 0.5;
        mesh.uv.push(uv);
        m
    }

    /// Refines one triangle, depth first as pbrt-v4's recursion does
    /// (first the half holding the longest edge's first vertex).
    fn refine(
        &mut self,
        tri: [u32; 3],
        face: Option<i32>,
        out_indices: &mut Vec<u32>,
        out_faces: &mut Vec<i32>,
    ) -> Result<(), DisplaceError> {
        let mut stack = vec![tri];
        while let Some([v0, v1, v2]) = stack.pop() {
            let (d01, d12, d20) = (
                self.distance(v0, v1),
                self.distance(v1, v2),
                self.distance(v2, v0),
            );
            // A non-finite length can never get short: leave it.
            let done = (d01 < self.max_dist && d12 < self.max_dist && d20 < self.max_dist)
                || !(d01.is_finite() && d12.is_finite() && d20.is_finite());
            if done {
                if out_indices.len() / 3 >= MAX_REFINED_TRIANGLES {
                    return Err(DisplaceError::TooManyTriangles {
                        edge_length: self.max_dist,
                    });
                }
                out_indices.extend_from_slice(&[v0, v1, v2]);
                if let Some(f) = face {
                    out_faces.push(f);
                }
                continue;
            }
            // Order so that the first two vertices bound the longest edge.
            let v = if d01 > d12 {
                if d01 > d20 {
                    [v0, v1, v2]
                } else {
                    [v2, v0, v1]
                }
            } else if d12 > d20 {
                [v1, v2, v0]
            } else {
                [v2, v0, v1]
            };
            let mid = self.midpoint(v[0], v[1]);
            stack.push([mid, v[1], v[2]]);
            stack.push([v[0], mid, v[2]]);
        }
        Ok(())
    }
}

/// Displaces a triangle mesh (object space) by `displacement(p, uv)` along
/// its vertex normals after refining it to edges shorter than `edge_length`
/// in rendering space. Normals missing from the mesh are computed first;
/// normals are recomputed afterwards. Displacement values are evaluated in
/// parallel. The refined mesh is held against the default memory budget.
pub fn displace(
    mesh: DisplacedMesh,
    render_from_object: &Transform,
    edge_length: Float,
    displacement: &(dyn Fn(Point3f, Point2f) -> Float + Sync),
) -> Result<DisplacedMesh, DisplaceError> {
    let budget = rpbrt_parser::MemoryBudget::default();
    displace_within(mesh, render_from_object, edge_length, displacement, &budget)
}

/// The memory one triangle of a refined mesh takes while it is made, in
/// bytes: its indices, its share of the vertices (position, normal, uv,
/// displacement) and of the split-edge map.
const REFINED_TRIANGLE_BYTES: u64 = 96;

/// [`displace`], charging the refined mesh to `budget` (from the estimate
/// of its size, before it is refined).
pub fn displace_within(
    mesh: DisplacedMesh,
    render_from_object: &Transform,
    edge_length: Float,
    displacement: &(dyn Fn(Point3f, Point2f) -> Float + Sync),
    budget: &rpbrt_parser::MemoryBudget,
) -> Result<DisplacedMesh, DisplaceError> {
    if mesh.uv.len() != mesh.p.len() || mesh.p.is_empty() {
        return Err(DisplaceError::NoUvs);
    }
    let mut mesh = mesh;
    if mesh.n.len() != mesh.p.len() {
        mesh.n = compute_normals(&mesh.indices, &mesh.p);
    }
    let triangles = std::mem::take(&mut mesh.indices);
    let faces = std::mem::take(&mut mesh.face_indices);
    let mut r = Refiner {
        mesh,
        render_from_object,
        max_dist: edge_length,
        edge_split: HashMap::new(),
    };
    // Longest-edge bisection makes about (longest edge / edge length)²
    // triangles of each: refuse hopeless edge lengths before allocating.
    let estimate: f64 = triangles
        .chunks_exact(3)
        .map(|t| {
            let longest = r
                .distance(t[0], t[1])
                .max(r.distance(t[1], t[2]))
                .max(r.distance(t[2], t[0]));
            if longest.is_finite() {
                (longest as f64 / edge_length as f64).powi(2)
            } else {
                1.0
            }
        })
        .sum();
    if estimate > MAX_REFINED_TRIANGLES as f64 {
        return Err(DisplaceError::TooManyTriangles { edge_length });
    }
    let bytes =
        (estimate.max(triangles.len() as f64 / 3.0) as u64).saturating_mul(REFINED_TRIANGLE_BYTES);
    budget
        .charge(bytes, "this displaced mesh")
        .map_err(DisplaceError::OverBudget)?;
    let mut out_indices = Vec::with_capacity(triangles.len());
    let mut out_faces = Vec::new();
    for (i, t) in triangles.chunks_exact(3).enumerate() {
        let face = if faces.is_empty() {
            None
        } else {
            Some(faces.get(i).copied().unwrap_or(0))
        };
        r.refine([t[0], t[1], t[2]], face, &mut out_indices, &mut out_faces)?;
    }
    let mut mesh = r.mesh;
    let offsets: Vec<Vector3f> = mesh
        .p
        .par_iter()
        .zip(&mesh.uv)
        .zip(&mesh.n)
        .map(|((&p, &uv), &n)| Vector3f::from(n) * displacement(p, uv))
        .collect();
    for (p, d) in mesh.p.iter_mut().zip(offsets) {
        *p += d;
    }
    mesh.n = compute_normals(&out_indices, &mesh.p);
    mesh.indices = out_indices;
    mesh.face_indices = out_faces;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in z = 0 as two triangles, uv = (x, y).
    fn square() -> DisplacedMesh {
        DisplacedMesh {
            indices: vec![0, 1, 2, 0, 2, 3],
            p: vec![
                Point3f::new(0.0, 0.0, 0.0),
                Point3f::new(1.0, 0.0, 0.0),
                Point3f::new(1.0, 1.0, 0.0),
                Point3f::new(0.0, 1.0, 0.0),
            ],
            n: Vec::new(),
            uv: vec![
                Point2f::new(0.0, 0.0),
                Point2f::new(1.0, 0.0),
                Point2f::new(1.0, 1.0),
                Point2f::new(0.0, 1.0),
            ],
            face_indices: vec![7, 9],
        }
    }

    fn edges_shorter_than(m: &DisplacedMesh, xf: &Transform, len: Float) -> bool {
        m.indices.chunks_exact(3).all(|t| {
            (0..3).all(|k| {
                let a = xf.apply_point(m.p[t[k] as usize]);
                let b = xf.apply_point(m.p[t[(k + 1) % 3] as usize]);
                (a - b).length() < len
            })
        })
    }

    #[test]
    fn refinement_meets_the_edge_length_and_shares_vertices() {
        let xf = Transform::identity();
        let m = displace(square(), &xf, 0.1, &|_, _| 0.0).unwrap();
        assert!(edges_shorter_than(&m, &xf, 0.1));
        // Zero displacement leaves a flat square of the same area.
        let area: Float = m
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.p[i as usize]);
                cross(b - a, c - a).length() / 2.0
            })
            .sum();
        assert!((area - 1.0).abs() < 1e-5, "{area}");
        assert!(m.p.iter().all(|p| p.z == 0.0));
        // Shared edges are split once: no two vertices coincide.
        let mut keys: Vec<(i64, i64)> =
            m.p.iter()
                .map(|p| ((p.x * 1e5).round() as i64, (p.y * 1e5).round() as i64))
                .collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), m.p.len());
        // Face indices follow their triangles; normals point up.
        assert_eq!(m.face_indices.len(), m.indices.len() / 3);
        assert!(m.face_indices.iter().all(|&f| f == 7 || f == 9));
        assert!(m.n.iter().all(|n| (n.z - 1.0).abs() < 1e-5));
    }

    #[test]
    fn edge_length_is_measured_in_rendering_space() {
        let xf = Transform::scale(10.0, 10.0, 10.0);
        let coarse = displace(square(), &Transform::identity(), 0.5, &|_, _| 0.0).unwrap();
        let fine = displace(square(), &xf, 0.5, &|_, _| 0.0).unwrap();
        assert!(edges_shorter_than(&fine, &xf, 0.5));
        assert!(fine.indices.len() > 50 * coarse.indices.len());
    }

    #[test]
    fn vertices_move_along_normals_by_the_texture() {
        // d = 0.25 · u (object-space p and uv are passed to the texture).
        let m = displace(square(), &Transform::identity(), 0.2, &|p, uv| {
            assert!((p.x - uv.x).abs() < 1e-6 && (p.y - uv.y).abs() < 1e-6);
            0.25 * uv.x
        })
        .unwrap();
        for (p, uv) in m.p.iter().zip(&m.uv) {
            assert!((p.z - 0.25 * uv.x).abs() < 1e-6, "{p:?} {uv:?}");
        }
        // The displaced plane z = x/4 has normal (-1/4, 0, 1)/|.|.
        let want = Normal3f::new(-0.25, 0.0, 1.0).normalize();
        assert!(m.n.iter().all(|n| (*n - want).length() < 1e-4));
    }

    #[test]
    fn quads_become_two_triangles_each() {
        let (idx, faces) = triangulate(&[0, 1, 2], &[3, 4, 6, 5], &[1, 2]);
        assert_eq!(idx, vec![0, 1, 2, 3, 4, 5, 3, 5, 6]);
        assert_eq!(faces, vec![1, 2, 2]);
        let (_, none) = triangulate(&[], &[0, 1, 3, 2], &[]);
        assert!(none.is_empty());
    }

    #[test]
    fn bad_meshes_are_errors_not_hangs() {
        let mut m = square();
        m.uv.clear();
        assert_eq!(
            displace(m, &Transform::identity(), 0.1, &|_, _| 0.0),
            Err(DisplaceError::NoUvs)
        );
        // A vertex at infinity cannot be refined toward the edge length.
        let mut m = square();
        m.p[2] = Point3f::new(Float::INFINITY, 1.0, 0.0);
        assert!(displace(m, &Transform::identity(), 0.1, &|_, _| 0.0).is_ok());
        // A tiny edge length is refused before memory runs out.
        let e = displace(square(), &Transform::identity(), 1e-5, &|_, _| 0.0).unwrap_err();
        assert!(matches!(e, DisplaceError::TooManyTriangles { .. }));
    }
}
