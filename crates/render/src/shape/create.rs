//! Creating shapes from scene-file parameters (pbrt-v4 `Shape::Create` in
//! `shapes.cpp`): parameter names and defaults as pbrt-v4 (and pbrt-v3 for
//! the quadrics pbrt-v4 dropped), PLY files, Loop subdivision, and located
//! messages for everything a user can get wrong.

use super::bilinear::{self, BilinearPatchMesh};
use super::curve::create_curves;
use super::loopsubdiv::loop_subdivide;
use super::triangle::{self, TriangleMesh};
use super::{Cone, Cylinder, Disk, Hyperboloid, Paraboloid, Shape, ShapeError, Sphere};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::{Diagnostic, FileLoc, ParamError, ParameterDictionary};
use std::path::Path;

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

/// Shapes created from one `Shape` directive, and the warnings it raised.
#[derive(Debug, Default)]
pub struct CreatedShapes {
    /// The shapes (a mesh gives one per triangle or patch).
    pub shapes: Vec<Shape>,
    /// Located warnings (skipped degenerate elements, unused parameters...).
    pub warnings: Vec<Diagnostic>,
}

fn perr(e: ParamError) -> Diagnostic {
    Diagnostic::from(e)
}

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

fn indices(
    params: &ParameterDictionary,
    name: &str,
    loc: &FileLoc,
) -> Result<Vec<u32>, Diagnostic> {
    let raw = params.get_int_array(name).map_err(perr)?;
    raw.iter()
        .map(|&i| {
            u32::try_from(i).map_err(|_| {
                Diagnostic::error(
                    params.loc(name).cloned().unwrap_or_else(|| loc.clone()),
                    format!("vertex index {i} is negative"),
                )
            })
        })
        .collect()
}

/// Creates the shapes of one `Shape "name" ...` directive. `base_dir` is the
/// directory of the scene file, against which file names resolve. Unused
/// parameters are reported as warnings, except those the caller still
/// reads (`alpha`, `emissionfilename`, displacement settings), which it
/// passes in `reserved`.
pub fn create_shapes(
    name: &str,
    params: &ParameterDictionary,
    render_from_object: &Transform,
    reverse_orientation: bool,
    base_dir: &Path,
    loc: &FileLoc,
) -> Result<CreatedShapes, Diagnostic> {
    let mut out = CreatedShapes::default();
    let rfo = *render_from_object;
    let ro = reverse_orientation;
    let f = |n: &str, d: Float| params.get_one_float(n, d).map_err(perr);
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
            out.shapes.push(Shape::Sphere(Box::new(s)));
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
            out.shapes.push(Shape::Cylinder(Box::new(s)));
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
            out.shapes.push(Shape::Disk(Box::new(s)));
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
            out.shapes.push(Shape::Cone(Box::new(s)));
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
            out.shapes.push(Shape::Paraboloid(Box::new(s)));
        }
        "hyperboloid" => {
            let p1 = params.get_one_point3("p1", [0.0, 0.0, 0.0]).map_err(perr)?;
            let p2 = params.get_one_point3("p2", [1.0, 1.0, 1.0]).map_err(perr)?;
            let s = Hyperboloid::new(
                rfo,
                ro,
                Point3f::from(p1),
                Point3f::from(p2),
                f("phimax", 360.0)?,
            )
            .map_err(|e| serr(loc, name, e))?;
            out.shapes.push(Shape::Hyperboloid(Box::new(s)));
        }
        "trianglemesh" => {
            let p = p3(params.get_point3_array("P").map_err(perr)?);
            let mut idx = indices(params, "indices", loc)?;
            if idx.is_empty() {
                if p.len() == 3 {
                    idx = vec![0, 1, 2];
                } else {
                    return Err(Diagnostic::error(loc.clone(), "\"trianglemesh\" shape: \"indices\" is required unless exactly three vertices are given"));
                }
            }
            let n = n3(params.get_normal3_array("N").map_err(perr)?);
            let s: Vec<Vector3f> = params
                .get_vector3_array("S")
                .map_err(perr)?
                .into_iter()
                .map(Vector3f::from)
                .collect();
            let uv: Vec<Point2f> = params
                .get_point2_array("uv")
                .map_err(perr)?
                .into_iter()
                .map(Point2f::from)
                .collect();
            let fi = params.get_int_array("faceIndices").map_err(perr)?;
            push_triangles(&mut out, &rfo, ro, idx, p, s, n, uv, fi, loc, name)?;
        }
        "plymesh" => {
            let file = params.get_one_string("filename", "").map_err(perr)?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "\"plymesh\" shape: \"filename\" is required",
                ));
            }
            if let Some(d) = params.get_texture("displacement").map_err(perr)? {
                return Err(Diagnostic::error(
                    params
                        .loc("displacement")
                        .cloned()
                        .unwrap_or_else(|| loc.clone()),
                    format!("\"plymesh\" shape: displacement texture \"{d}\" is not supported yet"),
                ));
            }
            let path = base_dir.join(&file);
            let mesh = rpbrt_parser::ply::read_ply(&path)
                .map_err(|e| Diagnostic::error(loc.clone(), format!("\"plymesh\" shape: {e}")))?;
            for w in &mesh.warnings {
                out.warnings.push(Diagnostic::warning(
                    loc.clone(),
                    format!("{}: {w}", path.display()),
                ));
            }
            let p: Vec<Point3f> = mesh.positions.iter().map(|&a| Point3f::from(a)).collect();
            let n: Vec<Normal3f> = mesh.normals.iter().map(|&a| Normal3f::from(a)).collect();
            let uv: Vec<Point2f> = mesh.uvs.iter().map(|&a| Point2f::from(a)).collect();
            let ntri = mesh.tri_indices.len() / 3;
            let (tri_fi, quad_fi) = if mesh.face_indices.is_empty() {
                (Vec::new(), Vec::new())
            } else {
                let fi = &mesh.face_indices;
                (
                    fi[..ntri.min(fi.len())].to_vec(),
                    fi[ntri.min(fi.len())..].to_vec(),
                )
            };
            if !mesh.tri_indices.is_empty() {
                push_triangles(
                    &mut out,
                    &rfo,
                    ro,
                    mesh.tri_indices.clone(),
                    p.clone(),
                    Vec::new(),
                    n.clone(),
                    uv.clone(),
                    tri_fi,
                    loc,
                    name,
                )?;
            }
            if !mesh.quad_indices.is_empty() {
                push_patches(
                    &mut out,
                    &rfo,
                    ro,
                    mesh.quad_indices.clone(),
                    p,
                    n,
                    uv,
                    quad_fi,
                    loc,
                    name,
                )?;
            }
        }
        "bilinearmesh" => {
            let p = p3(params.get_point3_array("P").map_err(perr)?);
            let mut idx = indices(params, "indices", loc)?;
            if idx.is_empty() {
                if p.len() == 4 {
                    idx = vec![0, 1, 2, 3];
                } else {
                    return Err(Diagnostic::error(loc.clone(), "\"bilinearmesh\" shape: \"indices\" is required unless exactly four vertices are given"));
                }
            }
            let n = n3(params.get_normal3_array("N").map_err(perr)?);
            let uv: Vec<Point2f> = params
                .get_point2_array("uv")
                .map_err(perr)?
                .into_iter()
                .map(Point2f::from)
                .collect();
            let fi = params.get_int_array("faceIndices").map_err(perr)?;
            push_patches(&mut out, &rfo, ro, idx, p, n, uv, fi, loc, name)?;
        }
        "loopsubdiv" => {
            let levels = params.get_one_int("levels", 3).map_err(perr)?;
            let idx = indices(params, "indices", loc)?;
            let p = p3(params.get_point3_array("P").map_err(perr)?);
            if idx.is_empty() || p.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "\"loopsubdiv\" shape: \"P\" and \"indices\" are required",
                ));
            }
            let r = loop_subdivide(levels, &idx, &p).map_err(|e| serr(loc, name, e))?;
            push_triangles(
                &mut out,
                &rfo,
                ro,
                r.indices,
                r.p,
                Vec::new(),
                r.n,
                Vec::new(),
                Vec::new(),
                loc,
                name,
            )?;
        }
        "curve" => {
            let p = p3(params.get_point3_array("P").map_err(perr)?);
            let basis = params.get_one_string("basis", "bezier").map_err(perr)?;
            let degree = params.get_one_int("degree", 3).map_err(perr)?;
            let ty = params.get_one_string("type", "flat").map_err(perr)?;
            let n = n3(params.get_normal3_array("N").map_err(perr)?);
            let width = f("width", 1.0)?;
            let width0 = f("width0", width)?;
            let width1 = f("width1", width)?;
            let split_depth = params.get_one_int("splitdepth", 3).map_err(perr)?;
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
            out.warnings.extend(
                warnings
                    .into_iter()
                    .map(|w| Diagnostic::warning(loc.clone(), format!("\"curve\" shape: {w}"))),
            );
            out.shapes
                .extend(curves.into_iter().map(|c| Shape::Curve(c)));
        }
        _ => {
            return Err(Diagnostic::error(
                loc.clone(),
                format!(
                    "unknown shape type \"{name}\"; known types: {}",
                    SHAPE_NAMES.join(", ")
                ),
            ));
        }
    }
    Ok(out)
}

#[allow(clippy::too_many_arguments)]
fn push_triangles(
    out: &mut CreatedShapes,
    rfo: &Transform,
    ro: bool,
    idx: Vec<u32>,
    p: Vec<Point3f>,
    s: Vec<Vector3f>,
    n: Vec<Normal3f>,
    uv: Vec<Point2f>,
    fi: Vec<i32>,
    loc: &FileLoc,
    name: &str,
) -> Result<(), Diagnostic> {
    let (mesh, warnings) =
        TriangleMesh::new(rfo, ro, idx, p, s, n, uv, fi).map_err(|e| serr(loc, name, e))?;
    out.warnings.extend(
        warnings
            .into_iter()
            .map(|w| Diagnostic::warning(loc.clone(), format!("\"{name}\" shape: {w}"))),
    );
    out.shapes
        .extend(triangle::triangles(&mesh).into_iter().map(Shape::Triangle));
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn push_patches(
    out: &mut CreatedShapes,
    rfo: &Transform,
    ro: bool,
    idx: Vec<u32>,
    p: Vec<Point3f>,
    n: Vec<Normal3f>,
    uv: Vec<Point2f>,
    fi: Vec<i32>,
    loc: &FileLoc,
    name: &str,
) -> Result<(), Diagnostic> {
    let (mesh, warnings) =
        BilinearPatchMesh::new(rfo, ro, idx, p, n, uv, fi).map_err(|e| serr(loc, name, e))?;
    out.warnings.extend(
        warnings
            .into_iter()
            .map(|w| Diagnostic::warning(loc.clone(), format!("\"{name}\" shape: {w}"))),
    );
    out.shapes.extend(
        bilinear::patches(&mesh)
            .into_iter()
            .map(Shape::BilinearPatch),
    );
    Ok(())
}
