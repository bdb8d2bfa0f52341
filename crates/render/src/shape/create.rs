//! Creating shapes from scene-file parameters (pbrt-v4 `Shape::Create` in
//! `shapes.cpp`): parameter names and defaults as pbrt-v4 (and pbrt-v3 for
//! the quadrics pbrt-v4 dropped), PLY files, Loop subdivision, and located
//! messages for everything a user can get wrong.

use super::bilinear::{self, BilinearPatchMesh};
use super::curve::create_curves;
use super::displace::{displace_within, triangulate, DisplacedMesh};
use super::loopsubdiv::{loop_subdivide, MAX_LOOP_LEVELS};
use super::triangle::{self, TriangleMesh};
use super::{Cone, Cylinder, Disk, Hyperboloid, Paraboloid, Shape, ShapeError, Sphere};
use crate::params::{unknown_type, ParamReader};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::ply::PlyMesh;
use rpbrt_parser::{Diagnostic, FileLoc};
use std::sync::Arc;

/// The shape type names rpbrt knows.
pub const SHAPE_NAMES: &[&str] = &[
    "bilinearmesh",
    "cone",
    "curve",
    "cylinder",
    "disk",
    "hyperboloid",
    "loopsubdiv",
    "paraboloid",
    "plymesh",
    "sphere",
    "trianglemesh",
];

/// The memory one triangle of a Loop-subdivided mesh takes while it is
/// made, in bytes: its face and vertex records at the last two levels and
/// the limit positions, normals and indices.
const LOOP_TRIANGLE_BYTES: u64 = 96;

/// The memory one triangle of a mesh with a vertex per two triangles
/// keeps, in bytes: three indices and half a position and normal.
const MESH_TRIANGLE_BYTES: u64 = 24;

fn serr(loc: &FileLoc, name: &str, e: ShapeError) -> Diagnostic {
    let msg = e.to_string();
    if msg.starts_with(name) {
        Diagnostic::error(loc.clone(), msg)
    } else {
        Diagnostic::error(loc.clone(), format!("{name}: {msg}"))
    }
}

fn p3(v: Vec<[f32; 3]>) -> Vec<Point3f> {
    v.into_iter().map(Point3f::from).collect()
}

fn n3(v: Vec<[f32; 3]>) -> Vec<Normal3f> {
    v.into_iter().map(Normal3f::from).collect()
}

fn indices(sp: &ParamReader, name: &str) -> Result<Vec<u32>, Diagnostic> {
    let raw = sp.ints(name)?;
    raw.iter()
        .map(|&i| {
            u32::try_from(i).map_err(|_| sp.error_at(name, format!("vertex index {i} is negative")))
        })
        .collect()
}

/// A `plymesh` shape's `displacement` texture, looked up by the caller
/// (who has the scene's textures): its value at an object-space point and
/// uv, and the scene's `displacementedgescale` option.
pub struct Displacement<'a> {
    /// The texture's value at (p, uv).
    pub eval: &'a (dyn Fn(Point3f, Point2f) -> Float + Sync),
    /// Multiplies the shape's `edgelength`.
    pub edge_scale: Float,
}

/// What one `Shape` directive creates: the triangle mesh it makes, if any,
/// whose usable triangles come first, then its other shapes (a `plymesh`
/// with quads gives both, curves and quadrics only shapes).
#[derive(Debug, Default)]
pub struct ShapeSet {
    /// The triangle mesh; [`triangle::triangles`] gives its usable
    /// triangles (degenerate ones left out, as the mesh's warning said).
    pub mesh: Option<Arc<TriangleMesh>>,
    /// The other shapes, in order.
    pub shapes: Vec<Shape>,
}

impl ShapeSet {
    /// Every shape, the mesh's triangles first (one shape per triangle).
    pub fn into_shapes(self) -> Vec<Shape> {
        match self.mesh {
            None => self.shapes,
            Some(mesh) => {
                let mut out: Vec<Shape> = triangle::triangles(&mesh)
                    .into_iter()
                    .map(Shape::Triangle)
                    .collect();
                out.extend(self.shapes);
                out
            }
        }
    }
}

/// Creates the shapes of one `Shape "name" ...` directive (a mesh gives
/// one per triangle or patch); file names resolve against the scene file
/// they were written in. `displacement` is the `plymesh` shape's
/// displacement texture (`None`: the directive names none, or the caller
/// has no textures, which is then an error). Warnings (skipped degenerate
/// elements...) go to `sp`; unused parameters are the caller's to report,
/// since primitives and area lights read some of the same parameters.
pub fn create_shapes(
    name: &str,
    sp: &ParamReader,
    render_from_object: &Transform,
    reverse_orientation: bool,
    displacement: Option<&Displacement>,
) -> Result<Vec<Shape>, Diagnostic> {
    create_shape_set(
        name,
        sp,
        render_from_object,
        reverse_orientation,
        displacement,
    )
    .map(ShapeSet::into_shapes)
}

/// [`create_shapes`] with a triangle mesh kept whole rather than cut into
/// one shape per triangle (what aggregates store).
pub fn create_shape_set(
    name: &str,
    sp: &ParamReader,
    render_from_object: &Transform,
    reverse_orientation: bool,
    displacement: Option<&Displacement>,
) -> Result<ShapeSet, Diagnostic> {
    let loc = sp.loc();
    let mut set = ShapeSet::default();
    let rfo = *render_from_object;
    let ro = reverse_orientation;
    let f = |n: &str, d: Float| sp.float(n, d);
    match name {
        "sphere" => {
            let radius = f("radius", 1.0)?;
            let s = Sphere::new(
                rfo,
                ro,
                radius,
                f("zmin", -radius)?,
                f("zmax", radius)?,
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Sphere(Box::new(s)));
        }
        "cylinder" => {
            let s = Cylinder::new(
                rfo,
                ro,
                f("radius", 1.0)?,
                f("zmin", -1.0)?,
                f("zmax", 1.0)?,
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Cylinder(Box::new(s)));
        }
        "disk" => {
            let s = Disk::new(
                rfo,
                ro,
                f("height", 0.0)?,
                f("radius", 1.0)?,
                f("innerradius", 0.0)?,
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Disk(Box::new(s)));
        }
        "cone" => {
            let s = Cone::new(
                rfo,
                ro,
                f("height", 1.0)?,
                f("radius", 1.0)?,
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Cone(Box::new(s)));
        }
        "paraboloid" => {
            let s = Paraboloid::new(
                rfo,
                ro,
                f("radius", 1.0)?,
                f("zmin", 0.0)?,
                f("zmax", 1.0)?,
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Paraboloid(Box::new(s)));
        }
        "hyperboloid" => {
            let p1 = sp.point3("p1", [0.0, 0.0, 0.0])?;
            let p2 = sp.point3("p2", [1.0, 1.0, 1.0])?;
            let s = Hyperboloid::new(
                rfo,
                ro,
                Point3f::from(p1),
                Point3f::from(p2),
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            set.shapes.push(Shape::Hyperboloid(Box::new(s)));
        }
        "trianglemesh" => {
            let p = p3(sp.point3s("P")?);
            let mut idx = indices(sp, "indices")?;
            if idx.is_empty() {
                if p.len() == 3 {
                    idx = vec![0, 1, 2];
                } else {
                    return Err(Diagnostic::error(loc.clone(), "\"trianglemesh\" shape: \"indices\" is required unless exactly three vertices are given"));
                }
            }
            let n = n3(sp.normals("N")?);
            let s: Vec<Vector3f> = sp.vector3s("S")?.into_iter().map(Vector3f::from).collect();
            let uv: Vec<Point2f> = sp.point2s("uv")?.into_iter().map(Point2f::from).collect();
            let fi = sp.ints("faceIndices")?;
            push_triangles(&mut set, sp, &rfo, ro, idx, p, s, n, uv, fi, name)?;
        }
        "plymesh" => {
            let file = sp.string("filename", "")?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "\"plymesh\" shape: \"filename\" is required",
                ));
            }
            let edge_length = f("edgelength", 1.0)?;
            if !(edge_length > 0.0 && edge_length.is_finite()) {
                return Err(sp.error_at(
                    "edgelength",
                    format!("\"plymesh\" shape: \"edgelength\" {edge_length} must be positive"),
                ));
            }
            let displacement = match (sp.texture_name("displacement")?, displacement) {
                (None, _) => None,
                (Some(_), Some(d)) => Some(d),
                (Some(t), None) => {
                    return Err(sp.error_at(
                        "displacement",
                        format!(
                            "\"plymesh\" shape: displacement texture \"{t}\" needs the \
                             scene's textures, which geometry-only creation does not make"
                        ),
                    ))
                }
            };
            let path = sp.resolve("filename", &file);
            let mesh = rpbrt_parser::ply::read_ply_within(&path, sp.budget())
                .map_err(|e| Diagnostic::error(loc.clone(), format!("\"plymesh\" shape: {e}")))?;
            for w in &mesh.warnings {
                sp.warn(format!("{}: {w}", path.display()));
            }
            if let Some(d) = displacement {
                let (indices, face_indices) =
                    triangulate(&mesh.tri_indices, &mesh.quad_indices, &mesh.face_indices);
                let m = DisplacedMesh {
                    indices,
                    p: p3(mesh.positions),
                    n: n3(mesh.normals),
                    uv: mesh.uvs.into_iter().map(Point2f::from).collect(),
                    face_indices,
                };
                let edge = edge_length * d.edge_scale;
                let m = displace_within(m, &rfo, edge, d.eval, sp.budget()).map_err(|e| {
                    Diagnostic::error(
                        loc.clone(),
                        format!("\"plymesh\" shape: {}: {e}", path.display()),
                    )
                })?;
                push_triangles(
                    &mut set,
                    sp,
                    &rfo,
                    ro,
                    m.indices,
                    m.p,
                    Vec::new(),
                    m.n,
                    m.uv,
                    m.face_indices,
                    name,
                )?;
                return Ok(set);
            }
            // The file's arrays become the mesh's, moved and converted in
            // place: a large mesh is never held twice.
            let PlyMesh {
                positions,
                normals,
                uvs,
                tri_indices,
                quad_indices,
                face_indices: mut tri_fi,
                ..
            } = mesh;
            let p = p3(positions);
            let n = n3(normals);
            let uv: Vec<Point2f> = uvs.into_iter().map(Point2f::from).collect();
            let quad_fi = if tri_fi.is_empty() {
                Vec::new()
            } else {
                tri_fi.split_off((tri_indices.len() / 3).min(tri_fi.len()))
            };
            if quad_indices.is_empty() {
                if !tri_indices.is_empty() {
                    let s = Vec::new();
                    push_triangles(
                        &mut set,
                        sp,
                        &rfo,
                        ro,
                        tri_indices,
                        p,
                        s,
                        n,
                        uv,
                        tri_fi,
                        name,
                    )?;
                }
            } else {
                if !tri_indices.is_empty() {
                    // Triangles and quads share the vertices.
                    let (tp, tn, tuv, s) = (p.clone(), n.clone(), uv.clone(), Vec::new());
                    push_triangles(
                        &mut set,
                        sp,
                        &rfo,
                        ro,
                        tri_indices,
                        tp,
                        s,
                        tn,
                        tuv,
                        tri_fi,
                        name,
                    )?;
                }
                push_patches(
                    &mut set,
                    sp,
                    &rfo,
                    ro,
                    quad_indices,
                    p,
                    n,
                    uv,
                    quad_fi,
                    name,
                )?;
            }
        }
        "bilinearmesh" => {
            let p = p3(sp.point3s("P")?);
            let mut idx = indices(sp, "indices")?;
            if idx.is_empty() {
                if p.len() == 4 {
                    idx = vec![0, 1, 2, 3];
                } else {
                    return Err(Diagnostic::error(loc.clone(), "\"bilinearmesh\" shape: \"indices\" is required unless exactly four vertices are given"));
                }
            }
            let n = n3(sp.normals("N")?);
            let uv: Vec<Point2f> = sp.point2s("uv")?.into_iter().map(Point2f::from).collect();
            let fi = sp.ints("faceIndices")?;
            push_patches(&mut set, sp, &rfo, ro, idx, p, n, uv, fi, name)?;
        }
        "loopsubdiv" => {
            let levels = sp.int("levels", 3)?;
            let idx = indices(sp, "indices")?;
            let p = p3(sp.point3s("P")?);
            if idx.is_empty() || p.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "\"loopsubdiv\" shape: \"P\" and \"indices\" are required",
                ));
            }
            if levels > MAX_LOOP_LEVELS {
                sp.warn_at(
                    "levels",
                    format!(
                        "\"loopsubdiv\" shape: \"levels\" {levels} is more than the \
                         {MAX_LOOP_LEVELS} rpbrt applies; using {MAX_LOOP_LEVELS}"
                    ),
                );
            }
            let levels = levels.min(MAX_LOOP_LEVELS);
            // Each level makes four triangles of one; the refinement's
            // working copies and the result, before any is made.
            let triangles = (idx.len() as u64 / 3).saturating_mul(1 << (2 * levels.max(0)));
            let what = format!("this subdivision ({triangles} triangles after {levels} levels)");
            sp.budget()
                .check(triangles.saturating_mul(LOOP_TRIANGLE_BYTES), &what)
                .map_err(|e| sp.error(e.to_string()))?;
            sp.charge(triangles.saturating_mul(MESH_TRIANGLE_BYTES), &what)?;
            let r = loop_subdivide(levels, &idx, &p).map_err(|e| serr(loc, name, e))?;
            push_triangles(
                &mut set,
                sp,
                &rfo,
                ro,
                r.indices,
                r.p,
                Vec::new(),
                r.n,
                Vec::new(),
                Vec::new(),
                name,
            )?;
        }
        "curve" => {
            let p = p3(sp.point3s("P")?);
            let basis = sp.string("basis", "bezier")?;
            let degree = sp.int("degree", 3)?;
            let ty = sp.string("type", "flat")?;
            let n = n3(sp.normals("N")?);
            let width = f("width", 1.0)?;
            let width0 = f("width0", width)?;
            let width1 = f("width1", width)?;
            let split_depth = sp.int("splitdepth", 3)?;
            let (curves, warnings) = create_curves(
                &rfo,
                ro,
                &p,
                &basis,
                degree,
                &ty,
                &n,
                width0,
                width1,
                split_depth,
            )
            .map_err(|e| serr(loc, name, e))?;
            for w in warnings {
                sp.warn(format!("\"curve\" shape: {w}"));
            }
            set.shapes.extend(curves.into_iter().map(Shape::Curve));
        }
        _ => return Err(unknown_type("shape", name, SHAPE_NAMES, loc)),
    }
    Ok(set)
}

#[allow(clippy::too_many_arguments)]
fn push_triangles(
    out: &mut ShapeSet,
    sp: &ParamReader,
    rfo: &Transform,
    ro: bool,
    idx: Vec<u32>,
    p: Vec<Point3f>,
    s: Vec<Vector3f>,
    n: Vec<Normal3f>,
    uv: Vec<Point2f>,
    fi: Vec<i32>,
    name: &str,
) -> Result<(), Diagnostic> {
    let loc = sp.loc();
    let (mesh, warnings) =
        TriangleMesh::new(rfo, ro, idx, p, s, n, uv, fi).map_err(|e| serr(loc, name, e))?;
    for w in warnings {
        sp.warn(format!("\"{name}\" shape: {w}"));
    }
    debug_assert!(out.mesh.is_none() && out.shapes.is_empty());
    out.mesh = Some(mesh);
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn push_patches(
    out: &mut ShapeSet,
    sp: &ParamReader,
    rfo: &Transform,
    ro: bool,
    idx: Vec<u32>,
    p: Vec<Point3f>,
    n: Vec<Normal3f>,
    uv: Vec<Point2f>,
    fi: Vec<i32>,
    name: &str,
) -> Result<(), Diagnostic> {
    let loc = sp.loc();
    let (mesh, warnings) =
        BilinearPatchMesh::new(rfo, ro, idx, p, n, uv, fi).map_err(|e| serr(loc, name, e))?;
    for w in warnings {
        sp.warn(format!("\"{name}\" shape: {w}"));
    }
    out.shapes.extend(
        bilinear::patches(&mesh)
            .into_iter()
            .map(Shape::BilinearPatch),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_parser::ply::{write_ply, PlyMesh};
    use rpbrt_parser::{ParameterDictionary, ParsedParameter};
    use std::sync::Arc;

    fn at(line: u32) -> FileLoc {
        FileLoc::new(Arc::from("test.pbrt"), line, 7)
    }

    /// A unit square in z = 0 as one quad, uv = (x, y), written to a PLY.
    fn square_ply(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("rpbrt-displace-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("square.ply");
        let mesh = PlyMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            quad_indices: vec![0, 1, 3, 2],
            ..PlyMesh::default()
        };
        write_ply(&path, &mesh).unwrap();
        path
    }

    fn plymesh_params(path: &std::path::Path, edge: Option<f32>) -> Vec<ParsedParameter> {
        let mut v = vec![
            ParsedParameter::with_strings(
                "string",
                "filename",
                at(2),
                vec![path.display().to_string()],
            ),
            ParsedParameter::with_strings("texture", "displacement", at(3), vec!["d".into()]),
        ];
        if let Some(e) = edge {
            v.push(ParsedParameter::with_floats(
                "float",
                "edgelength",
                at(4),
                vec![e],
            ));
        }
        v
    }

    #[test]
    fn displaced_plymesh_matches_the_explicitly_displaced_surface() {
        let path = square_ply("surface");
        let dict = ParameterDictionary::new(plymesh_params(&path, Some(0.1)));
        let loc = at(1);
        let sp = ParamReader::plain(&dict, &loc);
        let f = |u: Float, v: Float| 0.1 * (2.0 * rpbrt_geometry::PI * u).sin() * v;
        let eval = |p: Point3f, uv: Point2f| {
            assert!((p.x - uv.x).abs() < 1e-6 && (p.y - uv.y).abs() < 1e-6);
            f(uv.x, uv.y)
        };
        // Rendering space is twice object space; with the edge scale of
        // one half, edges end below 0.05 there.
        let xf = Transform::scale(2.0, 2.0, 2.0);
        let d = Displacement {
            eval: &eval,
            edge_scale: 0.5,
        };
        let shapes = create_shapes("plymesh", &sp, &xf, false, Some(&d)).unwrap();
        assert!(shapes.len() > 1000, "{} triangles", shapes.len());
        let mut area = 0.0;
        for s in &shapes {
            let Shape::Triangle(t) = s else {
                panic!("displaced meshes are triangles")
            };
            assert!(t.mesh.n.is_some(), "normals are recomputed");
            let v = t.mesh.vertices(t.tri_index as usize);
            for k in 0..3 {
                // Every vertex lies on the displaced surface z = f(x, y)
                // (object space: rendering space halved).
                let o = Point3f::new(v[k].x / 2.0, v[k].y / 2.0, v[k].z / 2.0);
                assert!((o.z - f(o.x, o.y)).abs() < 1e-5, "{o:?}");
                // The flat mesh's edges (the displacement is along z) are
                // shorter than the edge length in rendering space.
                let w = v[(k + 1) % 3] - v[k];
                assert!((w.x * w.x + w.y * w.y).sqrt() < 0.05 + 1e-6);
            }
            let e1 = v[1] - v[0];
            let e2 = v[2] - v[0];
            area += (e1.x * e2.y - e1.y * e2.x).abs() / 2.0;
        }
        // The triangles tile the 2 × 2 square exactly once.
        assert!((area - 4.0).abs() < 1e-3, "{area}");
        assert!(sp.take_warnings().is_empty());
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }

    #[test]
    fn displacement_errors_are_located() {
        let path = square_ply("errors");
        let eval = |_: Point3f, _: Point2f| 0.0;
        let d = Displacement {
            eval: &eval,
            edge_scale: 1.0,
        };
        let loc = at(1);
        for bad in [0.0, -1.0, f32::NAN] {
            let dict = ParameterDictionary::new(plymesh_params(&path, Some(bad)));
            let sp = ParamReader::plain(&dict, &loc);
            let e =
                create_shapes("plymesh", &sp, &Transform::identity(), false, Some(&d)).unwrap_err();
            assert!(e.message.contains("edgelength"), "{}", e.message);
            assert_eq!(e.loc.as_ref().map(|l| l.line), Some(4), "{e:?}");
        }
        // Without the scene's textures, a displacement texture is refused
        // at its parameter.
        let dict = ParameterDictionary::new(plymesh_params(&path, None));
        let sp = ParamReader::plain(&dict, &loc);
        let e = create_shapes("plymesh", &sp, &Transform::identity(), false, None).unwrap_err();
        assert!(e.message.contains("displacement"), "{}", e.message);
        assert_eq!(e.loc.as_ref().map(|l| l.line), Some(3), "{e:?}");
        // A mesh without uvs cannot be displaced (pbrt-v4 requires them).
        let no_uv = path.with_file_name("nouv.ply");
        let mesh = PlyMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            tri_indices: vec![0, 1, 2],
            ..PlyMesh::default()
        };
        write_ply(&no_uv, &mesh).unwrap();
        let dict = ParameterDictionary::new(plymesh_params(&no_uv, None));
        let sp = ParamReader::plain(&dict, &loc);
        let e = create_shapes("plymesh", &sp, &Transform::identity(), false, Some(&d)).unwrap_err();
        assert!(e.message.contains("uvs"), "{}", e.message);
        assert_eq!(e.loc.as_ref().map(|l| l.line), Some(1), "{e:?}");
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }
}
