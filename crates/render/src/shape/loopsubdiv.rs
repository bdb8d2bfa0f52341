//! Loop subdivision surfaces (pbrt-v3 section 3.8; pbrt-v4
//! `util/loopsubdiv.cpp` `LoopSubdivide`): a triangle mesh is refined by
//! splitting every triangle into four, with Loop's weights for the new edge
//! points and the updated old vertices, a chosen number of times; the
//! vertices are then moved to their limit positions and given limit-surface
//! normals, and the result is an ordinary triangle mesh.
//!
//! The topology is pbrt's: each face knows its three vertices and its three
//! neighbours (`f[i]` across the edge from `v[i]` to `v[i + 1]`), each vertex
//! one of its faces, so one-rings are found by walking from face to face
//! around the vertex. Here faces and vertices are indices into vectors
//! rather than pointers.

use std::collections::HashMap;

use super::ShapeError;
use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;

/// The most subdivision levels applied; each level multiplies the triangle
/// count by four.
pub const MAX_LOOP_LEVELS: i32 = 10;

/// The refined mesh: limit-surface positions and normals and the triangle
/// vertex indices (three per triangle, counter-clockwise as in the input).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoopSubdivResult {
    /// Vertex positions on the limit surface.
    pub p: Vec<Point3f>,
    /// Unit limit-surface normals, one per vertex, on the side from which
    /// the input triangles appear counter-clockwise.
    pub n: Vec<Normal3f>,
    /// Vertex indices, three per triangle.
    pub indices: Vec<u32>,
}

/// No face or vertex.
const NONE: u32 = u32::MAX;

#[inline]
fn next(i: usize) -> usize {
    (i + 1) % 3
}

#[inline]
fn prev(i: usize) -> usize {
    (i + 2) % 3
}

#[derive(Clone, Copy, Debug)]
struct SdVertex {
    p: Point3f,
    /// Any face using the vertex (for boundary vertices, any one; walks go
    /// both ways).
    start_face: u32,
    regular: bool,
    boundary: bool,
}

#[derive(Clone, Copy, Debug)]
struct SdFace {
    v: [u32; 3],
    /// Neighbour across the edge `v[i]`–`v[next(i)]`, or `NONE`.
    f: [u32; 3],
}

/// One level of the subdivision mesh.
#[derive(Clone, Debug)]
struct Topology {
    verts: Vec<SdVertex>,
    faces: Vec<SdFace>,
}

impl Topology {
    /// Where `v` sits in face `f` (0..3).
    fn vnum(&self, f: u32, v: u32) -> usize {
        let face = &self.faces[f as usize];
        let i = face.v.iter().position(|&x| x == v);
        debug_assert!(i.is_some(), "vertex {v} not in face {f}");
        i.unwrap_or(0)
    }
    fn next_face(&self, f: u32, v: u32) -> u32 {
        self.faces[f as usize].f[self.vnum(f, v)]
    }
    fn prev_face(&self, f: u32, v: u32) -> u32 {
        self.faces[f as usize].f[prev(self.vnum(f, v))]
    }
    fn next_vert(&self, f: u32, v: u32) -> u32 {
        self.faces[f as usize].v[next(self.vnum(f, v))]
    }
    fn prev_vert(&self, f: u32, v: u32) -> u32 {
        self.faces[f as usize].v[prev(self.vnum(f, v))]
    }
    fn other_vert(&self, f: u32, v0: u32, v1: u32) -> u32 {
        let face = &self.faces[f as usize];
        let o = face.v.iter().copied().find(|&x| x != v0 && x != v1);
        debug_assert!(o.is_some());
        o.unwrap_or(face.v[0])
    }

    /// Number of faces around `v`, walking forward (and, at a boundary,
    /// backward) from its start face.
    fn face_count(&self, v: u32) -> usize {
        let vert = &self.verts[v as usize];
        let start = vert.start_face;
        let mut n = 1;
        let mut f = self.next_face(start, v);
        while f != NONE && f != start {
            n += 1;
            f = self.next_face(f, v);
        }
        if f == NONE {
            f = self.prev_face(start, v);
            while f != NONE {
                n += 1;
                f = self.prev_face(f, v);
            }
        }
        n
    }

    /// Number of neighbouring vertices.
    fn valence(&self, v: u32) -> usize {
        let n = self.face_count(v);
        if self.verts[v as usize].boundary {
            n + 1
        } else {
            n
        }
    }

    /// The neighbouring vertices of `v` in walk order; for a boundary vertex
    /// the ring starts and ends with the two boundary neighbours.
    fn one_ring(&self, v: u32, ring: &mut Vec<Point3f>) {
        ring.clear();
        let vert = &self.verts[v as usize];
        let p = |i: u32| self.verts[i as usize].p;
        if !vert.boundary {
            let mut f = vert.start_face;
            loop {
                ring.push(p(self.next_vert(f, v)));
                f = self.next_face(f, v);
                if f == vert.start_face || f == NONE {
                    break;
                }
            }
        } else {
            // Walk forward to the last face, then back across all of them.
            let mut f = vert.start_face;
            loop {
                let f2 = self.next_face(f, v);
                if f2 == NONE {
                    break;
                }
                f = f2;
            }
            ring.push(p(self.next_vert(f, v)));
            while f != NONE {
                ring.push(p(self.prev_vert(f, v)));
                f = self.prev_face(f, v);
            }
        }
    }

    /// (1 − n β) p + β Σ ring: the interior vertex rule with weight `beta`.
    fn weight_one_ring(&self, v: u32, beta: Float, ring: &mut Vec<Point3f>) -> Point3f {
        self.one_ring(v, ring);
        let n = ring.len() as Float;
        let mut sum = self.verts[v as usize].p * (1.0 - n * beta);
        for q in ring.iter() {
            sum = sum + *q * beta;
        }
        sum
    }

    /// (1 − 2β) p + β (first + last of ring): the boundary vertex rule,
    /// which only looks along the boundary.
    fn weight_boundary(&self, v: u32, beta: Float, ring: &mut Vec<Point3f>) -> Point3f {
        self.one_ring(v, ring);
        let (first, last) = match (ring.first(), ring.last()) {
            (Some(a), Some(b)) => (*a, *b),
            _ => return self.verts[v as usize].p,
        };
        self.verts[v as usize].p * (1.0 - 2.0 * beta) + first * beta + last * beta
    }

    /// Sets the boundary and regular flags from the neighbour pointers.
    fn classify_vertices(&mut self) {
        for i in 0..self.verts.len() {
            let v = i as u32;
            let start = self.verts[i].start_face;
            let mut f = self.next_face(start, v);
            while f != NONE && f != start {
                f = self.next_face(f, v);
            }
            self.verts[i].boundary = f == NONE;
            let valence = self.valence(v);
            self.verts[i].regular = (!self.verts[i].boundary && valence == 6)
                || (self.verts[i].boundary && valence == 4);
        }
    }

    /// One level of refinement: every face becomes four (children `4 f ..
    /// 4 f + 3`, the last one central), old vertex `i` keeps index `i` and
    /// edge vertices follow.
    fn refine(&self) -> Topology {
        let nv = self.verts.len();
        let mut ring = Vec::with_capacity(16);
        let mut verts: Vec<SdVertex> = Vec::with_capacity(nv + self.faces.len() * 3 / 2 + 8);

        // Even vertices: the old ones, moved by the vertex rules.
        for i in 0..nv {
            let v = i as u32;
            let old = &self.verts[i];
            let p = if !old.boundary {
                let beta = if old.regular {
                    1.0 / 16.0
                } else {
                    beta(self.valence(v))
                };
                self.weight_one_ring(v, beta, &mut ring)
            } else {
                self.weight_boundary(v, 1.0 / 8.0, &mut ring)
            };
            let start = old.start_face;
            verts.push(SdVertex {
                p,
                start_face: 4 * start + self.vnum(start, v) as u32,
                regular: old.regular,
                boundary: old.boundary,
            });
        }

        // Odd vertices: one per edge.
        let mut edge_verts: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(self.faces.len() * 3 / 2);
        for (fi, face) in self.faces.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (face.v[k], face.v[next(k)]);
                let key = (a.min(b), a.max(b));
                if edge_verts.contains_key(&key) {
                    continue;
                }
                let pa = self.verts[a as usize].p;
                let pb = self.verts[b as usize].p;
                let boundary = face.f[k] == NONE;
                let p = if boundary {
                    pa * 0.5 + pb * 0.5
                } else {
                    let c = self.verts[self.other_vert(fi as u32, a, b) as usize].p;
                    let d = self.verts[self.other_vert(face.f[k], a, b) as usize].p;
                    pa * (3.0 / 8.0) + pb * (3.0 / 8.0) + c * (1.0 / 8.0) + d * (1.0 / 8.0)
                };
                edge_verts.insert(key, verts.len() as u32);
                verts.push(SdVertex {
                    p,
                    start_face: 4 * fi as u32 + 3,
                    regular: true,
                    boundary,
                });
            }
        }
        let edge_vert = |a: u32, b: u32| -> u32 {
            let v = edge_verts.get(&(a.min(b), a.max(b))).copied();
            debug_assert!(v.is_some());
            v.unwrap_or(0)
        };

        // Children: neighbours and vertices.
        let mut faces = vec![
            SdFace {
                v: [NONE; 3],
                f: [NONE; 3],
            };
            4 * self.faces.len()
        ];
        for (fi, face) in self.faces.iter().enumerate() {
            let child = |k: usize| 4 * fi + k;
            for j in 0..3 {
                faces[child(3)].f[j] = child(next(j)) as u32;
                faces[child(j)].f[next(j)] = child(3) as u32;
                let vj = face.v[j];
                for side in [j, prev(j)] {
                    let f2 = face.f[side];
                    faces[child(j)].f[side] = if f2 == NONE {
                        NONE
                    } else {
                        4 * f2 + self.vnum(f2, vj) as u32
                    };
                }
                faces[child(j)].v[j] = vj;
                let ev = edge_vert(vj, face.v[next(j)]);
                faces[child(j)].v[next(j)] = ev;
                faces[child(next(j))].v[j] = ev;
                faces[child(3)].v[j] = ev;
            }
        }
        Topology { verts, faces }
    }

    /// Limit positions, then limit normals from the limit tangents.
    fn limit(&self) -> (Vec<Point3f>, Vec<Normal3f>) {
        let mut ring = Vec::with_capacity(16);
        let p: Vec<Point3f> = (0..self.verts.len())
            .map(|i| {
                let v = i as u32;
                if self.verts[i].boundary {
                    self.weight_boundary(v, 1.0 / 5.0, &mut ring)
                } else {
                    self.weight_one_ring(v, loop_gamma(self.valence(v)), &mut ring)
                }
            })
            .collect();
        let mut limit = self.clone();
        for (v, q) in limit.verts.iter_mut().zip(&p) {
            v.p = *q;
        }
        let n = limit.normals();
        (p, n)
    }

    /// Unit normals from the tangent formulas, at the current positions.
    fn normals(&self) -> Vec<Normal3f> {
        let mut ring = Vec::with_capacity(16);
        (0..self.verts.len())
            .map(|i| {
                let v = i as u32;
                let vert = &self.verts[i];
                self.one_ring(v, &mut ring);
                let valence = ring.len();
                let pv = Vector3f::from(vert.p);
                let r = |k: usize| Vector3f::from(ring[k]);
                let (s, t) = if !vert.boundary {
                    let mut s = Vector3f::default();
                    let mut t = Vector3f::default();
                    for j in 0..valence {
                        let angle = 2.0 * PI * j as Float / valence as Float;
                        s += r(j) * angle.cos();
                        t += r(j) * angle.sin();
                    }
                    (s, t)
                } else {
                    // Along the boundary, and across it with weights that
                    // depend on the valence.
                    let s = r(valence - 1) - r(0);
                    let t = match valence {
                        2 => r(0) + r(1) - pv * 2.0,
                        3 => r(1) - pv,
                        4 => r(0) * -1.0 + r(1) * 2.0 + r(2) * 2.0 + r(3) * -1.0 - pv * 2.0,
                        _ => {
                            let theta = PI / (valence - 1) as Float;
                            let mut t = (r(0) + r(valence - 1)) * theta.sin();
                            for k in 1..valence - 1 {
                                let wt = (2.0 * theta.cos() - 2.0) * (k as Float * theta).sin();
                                t += r(k) * wt;
                            }
                            -t
                        }
                    };
                    (s, t)
                };
                // The walk order makes S × T point to the side from which
                // the faces appear clockwise; negate it so normals agree with
                // counter-clockwise input winding (the triangles' own
                // geometric normals).
                let n = -cross(s, t);
                let n = n
                    .try_normalize()
                    .unwrap_or_else(|| self.face_normal(vert.start_face));
                Normal3f::from(n)
            })
            .collect()
    }

    /// Unit normal of a face by its winding (zero if degenerate).
    fn face_normal(&self, f: u32) -> Vector3f {
        let v = self.faces[f as usize].v.map(|i| self.verts[i as usize].p);
        cross(v[1] - v[0], v[2] - v[0])
            .try_normalize()
            .unwrap_or_default()
    }
}

/// Loop's β for an interior vertex of valence `n`.
#[inline]
fn beta(valence: usize) -> Float {
    if valence == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * valence as Float)
    }
}

/// The weight of each neighbour in the interior limit-position rule.
#[inline]
fn loop_gamma(valence: usize) -> Float {
    1.0 / (valence as Float + 3.0 / (8.0 * beta(valence)))
}

/// Builds the level-0 topology, checking the input: index count and range,
/// finite positions, no repeated vertex in a triangle, every edge shared by
/// at most two triangles with opposite directions, and every vertex's
/// triangles forming a single fan. Unused vertices are dropped.
fn build_topology(indices: &[u32], p: &[Point3f]) -> Result<Topology, ShapeError> {
    let err = |m: String| Err(ShapeError(m));
    if indices.is_empty() {
        return err("loopsubdiv: no triangles given (\"indices\" is empty)".into());
    }
    if !indices.len().is_multiple_of(3) {
        return err(format!(
            "loopsubdiv: number of vertex indices {} is not a multiple of 3",
            indices.len()
        ));
    }
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= p.len()) {
        return err(format!(
            "loopsubdiv: vertex index {i} out of range ({} positions \"P\" given)",
            p.len()
        ));
    }
    // Renumber the used vertices in order of first use.
    let mut remap = vec![NONE; p.len()];
    let mut verts = Vec::new();
    for &i in indices {
        if remap[i as usize] == NONE {
            let q = p[i as usize];
            if !q.is_finite() {
                return err(format!("loopsubdiv: position {i} is not finite ({q:?})"));
            }
            remap[i as usize] = verts.len() as u32;
            verts.push(SdVertex {
                p: q,
                start_face: NONE,
                regular: false,
                boundary: false,
            });
        }
    }
    let n_faces = indices.len() / 3;
    let mut faces = Vec::with_capacity(n_faces);
    let mut incident = vec![0usize; verts.len()];
    for (fi, tri) in indices.chunks_exact(3).enumerate() {
        let v = [
            remap[tri[0] as usize],
            remap[tri[1] as usize],
            remap[tri[2] as usize],
        ];
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
            return err(format!(
                "loopsubdiv: triangle {fi} uses a vertex twice ({}, {}, {})",
                tri[0], tri[1], tri[2]
            ));
        }
        for &x in &v {
            verts[x as usize].start_face = fi as u32;
            incident[x as usize] += 1;
        }
        faces.push(SdFace { v, f: [NONE; 3] });
    }

    // Pair up the faces across each edge.
    struct EdgeUse {
        face: u32,
        edge: usize,
        from: u32,
        uses: u32,
    }
    let mut edges: HashMap<(u32, u32), EdgeUse> = HashMap::with_capacity(n_faces * 3 / 2);
    for fi in 0..n_faces {
        for k in 0..3 {
            let (a, b) = (faces[fi].v[k], faces[fi].v[next(k)]);
            let key = (a.min(b), a.max(b));
            match edges.get_mut(&key) {
                None => {
                    edges.insert(
                        key,
                        EdgeUse {
                            face: fi as u32,
                            edge: k,
                            from: a,
                            uses: 1,
                        },
                    );
                }
                Some(e) => {
                    e.uses += 1;
                    if e.uses > 2 {
                        return err(format!(
                            "loopsubdiv: non-manifold mesh: the edge between vertices {} and {} \
                             is shared by more than two triangles",
                            orig(&remap, a),
                            orig(&remap, b)
                        ));
                    }
                    if e.from == a {
                        return err(format!(
                            "loopsubdiv: triangles {} and {fi} have opposite orientations \
                             (both run from vertex {} to {})",
                            e.face,
                            orig(&remap, a),
                            orig(&remap, b)
                        ));
                    }
                    faces[e.face as usize].f[e.edge] = fi as u32;
                    faces[fi].f[k] = e.face;
                }
            }
        }
    }

    let mut topo = Topology { verts, faces };
    topo.classify_vertices();
    // A vertex whose triangles form two or more fans (a "bow tie") cannot be
    // walked around.
    for (i, &count) in incident.iter().enumerate() {
        if topo.face_count(i as u32) != count {
            return err(format!(
                "loopsubdiv: non-manifold mesh: the triangles around vertex {} do not form a \
                 single fan",
                orig(&remap, i as u32)
            ));
        }
    }
    Ok(topo)
}

/// The caller's index of renumbered vertex `v` (for messages).
fn orig(remap: &[u32], v: u32) -> usize {
    remap.iter().position(|&r| r == v).unwrap_or(v as usize)
}

/// Loop-subdivides the triangle mesh (`indices`, three per triangle, into
/// `p`) `levels` times (clamped to [`MAX_LOOP_LEVELS`]) and returns the
/// mesh with vertices on the limit surface and limit normals, as pbrt-v4's
/// `LoopSubdivide`. With `levels` ≤ 0 the positions and triangles are
/// returned unchanged, with normals from the same tangent formulas.
/// Vertices no triangle uses are dropped (indices renumbered).
pub fn loop_subdivide(
    levels: i32,
    indices: &[u32],
    p: &[Point3f],
) -> Result<LoopSubdivResult, ShapeError> {
    let mut topo = build_topology(indices, p)?;
    let levels = levels.min(MAX_LOOP_LEVELS);
    let (p, n) = if levels <= 0 {
        let p = topo.verts.iter().map(|v| v.p).collect();
        (p, topo.normals())
    } else {
        for _ in 0..levels {
            topo = topo.refine();
        }
        topo.limit()
    };
    let indices = topo.faces.iter().flat_map(|f| f.v).collect();
    Ok(LoopSubdivResult { p, n, indices })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use rpbrt_geometry::Bounds3f;

    fn pt(x: Float, y: Float, z: Float) -> Point3f {
        Point3f::new(x, y, z)
    }

    /// A regular octahedron, counter-clockwise seen from outside.
    fn octahedron() -> (Vec<u32>, Vec<Point3f>) {
        let p = vec![
            pt(1.0, 0.0, 0.0),
            pt(-1.0, 0.0, 0.0),
            pt(0.0, 1.0, 0.0),
            pt(0.0, -1.0, 0.0),
            pt(0.0, 0.0, 1.0),
            pt(0.0, 0.0, -1.0),
        ];
        let idx = vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
        ];
        (idx, p)
    }

    fn tetrahedron() -> (Vec<u32>, Vec<Point3f>) {
        let p = vec![
            pt(1.0, 1.0, 1.0),
            pt(1.0, -1.0, -1.0),
            pt(-1.0, 1.0, -1.0),
            pt(-1.0, -1.0, 1.0),
        ];
        (vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2], p)
    }

    /// An n × n grid of squares in the z = 0 plane, two triangles each.
    fn grid(n: u32, rng: &mut Rng) -> (Vec<u32>, Vec<Point3f>) {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                // Jitter interior points within the plane.
                let mut jitter = |k: u32| {
                    if k > 0 && k < n {
                        0.3 * (rng.uniform_float() - 0.5)
                    } else {
                        0.0
                    }
                };
                let (dx, dy) = (jitter(i), jitter(j));
                p.push(pt(i as Float + dx, j as Float + dy, 0.0));
            }
        }
        let mut idx = Vec::new();
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                idx.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                idx.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (idx, p)
    }

    fn check_valid(r: &LoopSubdivResult) {
        assert_eq!(r.p.len(), r.n.len());
        assert_eq!(r.indices.len() % 3, 0);
        assert!(r.indices.iter().all(|&i| (i as usize) < r.p.len()));
        for t in r.indices.chunks(3) {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        }
        for n in &r.n {
            assert!((n.length() - 1.0).abs() < 1e-4, "{n:?}");
        }
    }

    #[test]
    fn closed_meshes_converge_to_a_smooth_outward_surface() {
        for (idx, p) in [octahedron(), tetrahedron()] {
            let hull = p.iter().fold(Bounds3f::empty(), |b, q| b.union_point(*q));
            for levels in 1..=4 {
                let r = loop_subdivide(levels, &idx, &p).unwrap();
                check_valid(&r);
                assert_eq!(r.indices.len(), idx.len() * 4usize.pow(levels as u32));
                // Euler: V - E + F = 2 for a closed genus-0 surface.
                let f = r.indices.len() / 3;
                assert_eq!(r.p.len() + f - 3 * f / 2, 2);
                for (q, n) in r.p.iter().zip(&r.n) {
                    assert!(hull.expand(1e-5).inside(*q));
                    // Outward: away from the centre (these are star-shaped
                    // around the origin).
                    assert!(
                        dot(*n, Vector3f::from(*q).normalize()) > 0.3,
                        "{n:?} at {q:?}"
                    );
                }
                // The normals agree with the triangles' own normals.
                for t in r.indices.chunks(3) {
                    let v = [r.p[t[0] as usize], r.p[t[1] as usize], r.p[t[2] as usize]];
                    let ng = cross(v[1] - v[0], v[2] - v[0]).normalize();
                    for &i in t {
                        assert!(dot(r.n[i as usize], ng) > 0.5);
                    }
                }
            }
            // Smoothness: at 4 levels neighbouring normals are close.
            let r = loop_subdivide(4, &idx, &p).unwrap();
            for t in r.indices.chunks(3) {
                let a = r.n[t[0] as usize];
                assert!(dot(a, r.n[t[1] as usize]) > 0.9 && dot(a, r.n[t[2] as usize]) > 0.9);
            }
        }
    }

    #[test]
    fn planar_grid_stays_planar() {
        let mut rng = Rng::with_sequence(1);
        let (idx, p) = grid(4, &mut rng);
        for levels in 0..=3 {
            let r = loop_subdivide(levels, &idx, &p).unwrap();
            check_valid(&r);
            assert_eq!(r.indices.len(), idx.len() * 4usize.pow(levels as u32));
            for (q, n) in r.p.iter().zip(&r.n) {
                assert!(q.z.abs() < 1e-5);
                assert!(n.z > 0.9999, "{n:?} at {q:?}");
                assert!(q.x > -1e-5 && q.x < 4.0 + 1e-5 && q.y > -1e-5 && q.y < 4.0 + 1e-5);
            }
            // The boundary is a cubic B-spline of the boundary vertices, so
            // between x = 1 and x = 3 (away from the corners, which are
            // rounded) the y = 0 boundary stays on its line, with
            // 2 * 2^levels + 1 vertices.
            let on_edge =
                r.p.iter()
                    .filter(|q| q.y.abs() < 1e-5 && q.x > 1.0 - 1e-4 && q.x < 3.0 + 1e-4)
                    .count();
            assert_eq!(on_edge, 2 * (1 << levels) + 1);
        }
    }

    #[test]
    fn vertex_and_edge_rules_use_loop_weights() {
        // A hexagonal fan: an interior vertex 0 of valence 6 and a ring of
        // boundary vertices.
        let mut rng = Rng::with_sequence(2);
        let mut p = vec![pt(0.0, 0.0, 0.3)];
        for k in 0..6 {
            let a = PI / 3.0 * k as Float;
            p.push(pt(a.cos(), a.sin(), rng.uniform_float()));
        }
        let mut idx = Vec::new();
        for k in 0..6u32 {
            idx.extend([0, 1 + k, 1 + (k + 1) % 6]);
        }
        let topo = build_topology(&idx, &p).unwrap();
        assert!(!topo.verts[0].boundary && topo.verts[0].regular);
        assert_eq!(topo.valence(0), 6);
        assert!(topo.verts[1].boundary && topo.valence(1) == 3);
        let next = topo.refine();
        let close = |a: Point3f, b: Point3f| assert!(a.distance(b) < 1e-5, "{a:?} vs {b:?}");
        // Even interior vertex: 10/16 of itself and 1/16 of each neighbour.
        let ring_sum = p[1..].iter().fold(Point3f::default(), |s, q| s + *q);
        close(
            next.verts[0].p,
            p[0] * (10.0 / 16.0) + ring_sum * (1.0 / 16.0),
        );
        // Even boundary vertex: 3/4 of itself, 1/8 of each boundary neighbour.
        close(next.verts[1].p, p[1] * 0.75 + p[2] * 0.125 + p[6] * 0.125);
        // Interior edge 0–1: 3/8, 3/8 and 1/8 of the two opposite vertices.
        let expect_interior = p[0] * 0.375 + p[1] * 0.375 + p[2] * 0.125 + p[6] * 0.125;
        // Boundary edge 1–2: the midpoint.
        let expect_boundary = p[1] * 0.5 + p[2] * 0.5;
        let new = &next.verts[7..];
        assert_eq!(new.len(), 12);
        assert!(new
            .iter()
            .any(|v| v.p.distance(expect_interior) < 1e-5 && !v.boundary));
        assert!(new
            .iter()
            .any(|v| v.p.distance(expect_boundary) < 1e-5 && v.boundary));
        // Irregular valence: beta = 3 / (8 n), and 3/16 for n = 3.
        assert!((beta(5) - 3.0 / 40.0).abs() < 1e-7 && (beta(3) - 3.0 / 16.0).abs() < 1e-7);
        // The refined topology walks consistently.
        assert_eq!(next.valence(0), 6);
        assert_eq!(next.faces.len(), 24);
    }

    #[test]
    fn unused_vertices_are_dropped() {
        let (idx, mut p) = octahedron();
        p.push(pt(10.0, 10.0, 10.0));
        let r = loop_subdivide(1, &idx, &p).unwrap();
        check_valid(&r);
        assert!(r.p.iter().all(|q| Vector3f::from(*q).length() < 1.01));
        let levels = loop_subdivide(
            100,
            &[0, 1, 2],
            &[pt(0.0, 0.0, 0.0), pt(1.0, 0.0, 0.0), pt(0.0, 1.0, 0.0)],
        )
        .unwrap();
        assert_eq!(levels.indices.len(), 3 * 4usize.pow(MAX_LOOP_LEVELS as u32));
    }

    #[test]
    fn bad_input_is_an_error() {
        let (idx, p) = octahedron();
        assert!(loop_subdivide(1, &idx[..4], &p).is_err());
        assert!(loop_subdivide(1, &[], &p).is_err());
        assert!(loop_subdivide(1, &[0, 1, 6], &p).is_err());
        assert!(loop_subdivide(1, &[0, 1, 1], &p).is_err());
        let mut q = p.clone();
        q[0].x = Float::NAN;
        assert!(loop_subdivide(1, &idx, &q).is_err());
        // Three triangles on one edge.
        let fan = [0, 1, 2, 1, 0, 3, 0, 1, 4];
        let e = loop_subdivide(1, &fan, &p).unwrap_err();
        assert!(e.0.contains("non-manifold"), "{e}");
        // Two triangles with the same edge direction.
        let e = loop_subdivide(1, &[0, 1, 2, 0, 1, 3], &p).unwrap_err();
        assert!(e.0.contains("orientation"), "{e}");
        // Two fans meeting at one vertex (a bow tie).
        let e = loop_subdivide(1, &[0, 1, 2, 0, 3, 4], &p).unwrap_err();
        assert!(e.0.contains("fan"), "{e}");
    }
}
