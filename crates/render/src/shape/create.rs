//! Creating shapes from scene-file parameters (pbrt-v4 `Shape::Create` in
//! `shapes.cpp`): parameter names and defaults as pbrt-v4 (and pbrt-v3 for
//! the quadrics pbrt-v4 dropped), PLY files, Loop subdivision, and located
//! messages for everything a user can get wrong.

use super::bilinear::{self, BilinearPatchMesh};
use super::curve::create_curves;
use super::loopsubdiv::loop_subdivide;
use super::triangle::{self, TriangleMesh};
use super::{Cone, Cylinder, Disk, Hyperboloid, Paraboloid, Shape, ShapeError, Sphere};
use crate::params::{unknown_type, ParamReader};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::{Diagnostic, FileLoc};

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

/// Creates the shapes of one `Shape "name" ...` directive (a mesh gives
/// one per triangle or patch); file names resolve against the scene file
/// they were written in. Warnings (skipped degenerate elements...) go to
/// `sp`; unused parameters are the caller's to report, since primitives
/// and area lights read some of the same parameters.
pub fn create_shapes(
    name: &str,
    sp: &ParamReader,
    render_from_object: &Transform,
    reverse_orientation: bool,
) -> Result<Vec<Shape>, Diagnostic> {
    let loc = sp.loc();
    let mut out = Vec::new();
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
            out.push(Shape::Sphere(Box::new(s)));
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
            out.push(Shape::Cylinder(Box::new(s)));
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
            out.push(Shape::Disk(Box::new(s)));
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
            out.push(Shape::Cone(Box::new(s)));
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
            out.push(Shape::Paraboloid(Box::new(s)));
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
            out.push(Shape::Hyperboloid(Box::new(s)));
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
            push_triangles(&mut out, sp, &rfo, ro, idx, p, s, n, uv, fi, name)?;
        }
        "plymesh" => {
            let file = sp.string("filename", "")?;
            if file.is_empty() {
                return Err(Diagnostic::error(
                    loc.clone(),
                    "\"plymesh\" shape: \"filename\" is required",
                ));
            }
            if let Some(d) = sp.texture_name("displacement")? {
                return Err(sp.error_at(
                    "displacement",
                    format!("\"plymesh\" shape: displacement texture \"{d}\" is not supported yet"),
                ));
            }
            let path = sp.resolve("filename", &file);
            let mesh = rpbrt_parser::ply::read_ply(&path)
                .map_err(|e| Diagnostic::error(loc.clone(), format!("\"plymesh\" shape: {e}")))?;
            for w in &mesh.warnings {
                sp.warn(format!("{}: {w}", path.display()));
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
                    sp,
                    &rfo,
                    ro,
                    mesh.tri_indices.clone(),
                    p.clone(),
                    Vec::new(),
                    n.clone(),
                    uv.clone(),
                    tri_fi,
                    name,
                )?;
            }
            if !mesh.quad_indices.is_empty() {
                push_patches(
                    &mut out,
                    sp,
                    &rfo,
                    ro,
                    mesh.quad_indices.clone(),
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
            push_patches(&mut out, sp, &rfo, ro, idx, p, n, uv, fi, name)?;
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
            let r = loop_subdivide(levels, &idx, &p).map_err(|e| serr(loc, name, e))?;
            push_triangles(
                &mut out,
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
            out.extend(curves.into_iter().map(Shape::Curve));
        }
        _ => return Err(unknown_type("shape", name, SHAPE_NAMES, loc)),
    }
    Ok(out)
}

#[allow(clippy::too_many_arguments)]
fn push_triangles(
    out: &mut Vec<Shape>,
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
    out.extend(triangle::triangles(&mesh).into_iter().map(Shape::Triangle));
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn push_patches(
    out: &mut Vec<Shape>,
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
    out.extend(
        bilinear::patches(&mesh)
            .into_iter()
            .map(Shape::BilinearPatch),
    );
    Ok(())
}
