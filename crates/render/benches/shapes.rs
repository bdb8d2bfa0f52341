//! Rays per second of `intersect` and `intersect_p` for each shape kind
//! (plain harness: `cargo bench -p rpbrt-render --bench shapes`).
//!
//! Each shape is hit by rays from random points on a sphere around it aimed
//! at random points inside its bounds, so roughly half hit. One thread.

use rpbrt_geometry::float::Float;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Ray;
use rpbrt_parser::{FileLoc, ParameterDictionary, ParsedParameter};
use rpbrt_render::params::ParamReader;
use rpbrt_render::rng::Rng;
use rpbrt_render::shape::create::create_shapes;
use rpbrt_render::shape::{Shape, ShapeMethods};
use std::hint::black_box;
use std::time::Instant;

fn loc() -> FileLoc {
    FileLoc::new("<bench>".into(), 0, 0)
}

fn floats(name: &str, ty: &str, v: &[f32]) -> ParsedParameter {
    ParsedParameter::with_floats(ty, name, loc(), v.to_vec())
}

fn ints(name: &str, v: &[i32]) -> ParsedParameter {
    let mut p = ParsedParameter::new("integer", name, loc());
    p.ints = v.to_vec();
    p
}

fn make(name: &str, params: Vec<ParsedParameter>) -> Vec<Shape> {
    let xf = Transform::rotate(30.0, Vector3f::new(1.0, 1.0, 0.0));
    let dict = ParameterDictionary::new(params);
    let at = loc();
    match create_shapes(name, &ParamReader::plain(&dict, &at), &xf, false, None) {
        Ok(shapes) => shapes,
        Err(e) => panic!("benchmark shape {name}: {}", e.message),
    }
}

fn main() {
    let cases: Vec<(&str, Vec<Shape>)> = vec![
        (
            "sphere",
            make("sphere", vec![floats("radius", "float", &[1.0])]),
        ),
        (
            "sphere-partial",
            make(
                "sphere",
                vec![
                    floats("zmin", "float", &[-0.5]),
                    floats("zmax", "float", &[0.8]),
                    floats("phimax", "float", &[270.0]),
                ],
            ),
        ),
        ("cylinder", make("cylinder", vec![])),
        (
            "disk",
            make("disk", vec![floats("innerradius", "float", &[0.3])]),
        ),
        ("cone", make("cone", vec![])),
        ("paraboloid", make("paraboloid", vec![])),
        (
            "hyperboloid",
            make(
                "hyperboloid",
                vec![
                    floats("p1", "point3", &[1.0, 0.0, -1.0]),
                    floats("p2", "point3", &[0.0, 1.0, 1.0]),
                ],
            ),
        ),
        (
            "triangle",
            make(
                "trianglemesh",
                vec![
                    floats(
                        "P",
                        "point3",
                        &[-1.0, -1.0, 0.0, 1.0, -1.0, 0.2, 0.0, 1.0, -0.1],
                    ),
                    ints("indices", &[0, 1, 2]),
                ],
            ),
        ),
        (
            "bilinear-planar",
            make(
                "bilinearmesh",
                vec![
                    floats(
                        "P",
                        "point3",
                        &[
                            -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, -1.0, 1.0, 0.0, 1.0, 1.0, 0.0,
                        ],
                    ),
                    ints("indices", &[0, 1, 2, 3]),
                ],
            ),
        ),
        (
            "bilinear-twisted",
            make(
                "bilinearmesh",
                vec![
                    floats(
                        "P",
                        "point3",
                        &[
                            -1.0, -1.0, 0.0, 1.0, -1.0, 1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 0.0,
                        ],
                    ),
                    ints("indices", &[0, 1, 2, 3]),
                ],
            ),
        ),
        (
            "curve-flat",
            make(
                "curve",
                vec![
                    floats(
                        "P",
                        "point3",
                        &[
                            -1.0, 0.0, 0.0, -0.3, 1.0, 0.2, 0.3, -1.0, -0.2, 1.0, 0.0, 0.0,
                        ],
                    ),
                    floats("width", "float", &[0.2]),
                ],
            ),
        ),
        (
            "curve-cylinder",
            make(
                "curve",
                vec![
                    floats(
                        "P",
                        "point3",
                        &[
                            -1.0, 0.0, 0.0, -0.3, 1.0, 0.2, 0.3, -1.0, -0.2, 1.0, 0.0, 0.0,
                        ],
                    ),
                    floats("width", "float", &[0.2]),
                    ParsedParameter::with_strings("string", "type", loc(), vec!["cylinder".into()]),
                ],
            ),
        ),
    ];
    let n_rays = 1_000_000;
    for (name, shapes) in &cases {
        let shape = &shapes[0];
        let b = shapes
            .iter()
            .fold(rpbrt_geometry::Bounds3f::empty(), |acc, s| {
                acc.union(&s.bounds())
            });
        let (c, r) = b.bounding_sphere();
        let mut rng = Rng::new(17, 0);
        let rays: Vec<Ray> = (0..n_rays)
            .map(|_| {
                let u = Point2f::new(rng.uniform_float(), rng.uniform_float());
                let o = c + rpbrt_render::sampling::sample_uniform_sphere(u) * (2.0 * r + 0.1);
                let t = b.lerp(Point3f::new(
                    rng.uniform_float(),
                    rng.uniform_float(),
                    rng.uniform_float(),
                ));
                Ray::new(o, t - o)
            })
            .collect();
        let start = Instant::now();
        let mut hits = 0usize;
        for ray in &rays {
            if shapes.len() == 1 {
                hits += shape.intersect(black_box(ray), Float::INFINITY).is_some() as usize;
            } else {
                hits += shapes
                    .iter()
                    .any(|s| s.intersect(ray, Float::INFINITY).is_some())
                    as usize;
            }
        }
        let t_isect = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let mut hits_p = 0usize;
        for ray in &rays {
            hits_p += shapes
                .iter()
                .any(|s| s.intersect_p(black_box(ray), Float::INFINITY))
                as usize;
        }
        let t_p = start.elapsed().as_secs_f64();
        println!(
            "RESULT shape={name} pieces={} hit_fraction={:.3} intersect_mrays_s={:.2} intersect_p_mrays_s={:.2}",
            shapes.len(),
            hits as f64 / n_rays as f64,
            n_rays as f64 / t_isect / 1e6,
            n_rays as f64 / t_p / 1e6
        );
        assert_eq!(hits, hits_p, "{name}: intersect and intersect_p disagree");
    }
}
