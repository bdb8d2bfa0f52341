//! bdpt's multiple-importance weights: for one complete path, the weights
//! of all the strategies that could have sampled it sum to one.

use super::connect::mis_weight;
use super::vertex::{Vertex, VertexKind};
use super::walk::{generate_camera_subpath, WalkOptions};
use crate::camera::CameraSample;
use crate::integrator::Scene;
use crate::sampler::Sampler;
use crate::scene::assemble::{create_scene, CreateOptions};
use crate::scene::{build_scene_from_str, BuildOptions};
use crate::spectrum::SampledWavelengths;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// A closed box of diffuse walls lit by a quad on its ceiling facing
/// down, seen by a perspective camera inside it.
fn box_scene() -> Scene {
    let text = "LookAt 0 0 -0.9  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 60\n\
Sampler \"independent\" \"integer pixelsamples\" 1\n\
Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32 \"string filename\" \"unused.exr\"\n\
Integrator \"bdpt\"\nWorldBegin\n\
AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 4 4 4 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -0.3 0.99 -0.3  0.3 0.99 -0.3  0.3 0.99 0.3  -0.3 0.99 0.3 ] \"normal N\" [ 0 -1 0  0 -1 0  0 -1 0  0 -1 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n\
Material \"diffuse\" \"rgb reflectance\" [ 0.6 0.5 0.4 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -1 -1 -1  1 -1 -1  1 -1 1  -1 -1 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -1 1 -1  1 1 -1  1 1 1  -1 1 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -1 -1 -1  -1 1 -1  -1 1 1  -1 -1 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ 1 -1 -1  1 1 -1  1 1 1  1 -1 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -1 -1 1  1 -1 1  1 1 1  -1 1 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n\
Shape \"trianglemesh\" \"point3 P\" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    match create_scene(&desc, &CreateOptions::default()) {
        Ok(c) => c.scene,
        Err(e) => panic!("{:?}", e.iter().map(|d| &d.message).collect::<Vec<_>>()),
    }
}

/// The camera subpath of the (s, t) strategy over the complete path `y`
/// (camera first, emitter last), with its densities as the random walk
/// would have recorded them.
fn camera_subpath(scene: &Scene, y: &[Vertex], t: usize) -> Vec<Vertex> {
    let mut c: Vec<Vertex> = y[..t].to_vec();
    for i in 1..t {
        let prev = if i >= 2 { Some(&y[i - 2]) } else { None };
        c[i].pdf_fwd = y[i - 1].pdf(scene, prev, &y[i]);
    }
    for i in 0..t.saturating_sub(2) {
        c[i].pdf_rev = y[i + 1].pdf(scene, Some(&y[i + 2]), &y[i]);
    }
    c
}

/// The light subpath of the (s, t) strategy: the last `s` vertices of `y`
/// reversed, the emitter as a light vertex.
fn light_subpath(scene: &Scene, y: &[Vertex], s: usize) -> Vec<Vertex> {
    let n = y.len();
    let mut z: Vec<Vertex> = (0..s).map(|j| y[n - 1 - j]).collect();
    if s == 0 {
        return z;
    }
    z[0].kind = VertexKind::Light;
    z[0].bsdf = None;
    let toward = y[n - 2];
    z[0].pdf_fwd = z[0].pdf_light_origin(scene, &toward);
    for j in 1..s {
        z[j].pdf_fwd = if j == 1 {
            z[0].pdf_light(scene, &z[1])
        } else {
            z[j - 1].pdf(scene, Some(&z[j - 2]), &z[j])
        };
    }
    // The reverse densities, from the camera's side (walls only: the
    // emitter is never between two vertices).
    let full: Vec<Vertex> = (0..n).map(|j| y[n - 1 - j]).collect();
    for j in 0..s.saturating_sub(2) {
        z[j].pdf_rev = full[j + 1].pdf(scene, Some(&full[j + 2]), &full[j]);
    }
    z
}

#[test]
fn strategy_weights_of_a_path_sum_to_one() {
    let scene = box_scene();
    let mut sampler: Sampler = scene.sampler.clone();
    let opts = WalkOptions { regularize: false };
    let mut checked = 0;
    let mut path = Vec::new();
    for seed in 0..400 {
        sampler.start_pixel_sample(Point2i::new(seed % 32, seed / 32), seed, 0);
        let cs = CameraSample {
            p_film: Point2f::new(2.0 + 28.0 * sampler.get_1d(), 2.0 + 28.0 * sampler.get_1d()),
            p_lens: Point2f::new(0.5, 0.5),
            time: 0.0,
            filter_weight: 1.0,
        };
        let Some(cr) = scene.camera.generate_ray(&cs) else {
            continue;
        };
        let mut lambda = SampledWavelengths::sample_visible(0.3);
        let depth = 2 + (seed as usize % 4);
        let n_cam = generate_camera_subpath(
            &scene,
            RayDifferential::new(cr.ray),
            &mut lambda,
            &mut sampler,
            depth,
            opts,
            &mut path,
        );
        // Only walls: no emitter hit, no escape, then a point on the light.
        if n_cam != depth
            || path[1..]
                .iter()
                .any(|v| v.kind != VertexKind::Surface || v.light.is_some())
        {
            continue;
        }
        let last = path[n_cam - 1];
        let ctx = crate::light::LightSampleContext {
            pi: last.pi,
            n: last.n,
            ns: last.ns,
        };
        let u = sampler.get_2d();
        let Some(ls) = scene.lights[0].sample_li(&ctx, u, &lambda, false) else {
            continue;
        };
        let mut e = Vertex::new(VertexKind::Surface, ls.p_light, 0.0, ls.l);
        e.n = ls.n_light;
        e.ns = ls.n_light;
        e.light = Some(0);
        e.wo = -ls.wi;
        let mut y: Vec<Vertex> = path[..n_cam].to_vec();
        y.push(e);
        let n = y.len();
        // Paths some strategy cannot sample (grazing the light) are skipped.
        let mut sum = 0.0;
        let mut ok = true;
        let mut weights = Vec::new();
        for s in 0..n {
            let t = n - s;
            let c = camera_subpath(&scene, &y, t);
            let l = light_subpath(&scene, &y, s);
            let sampled = if s == 1 {
                Some(l[0])
            } else if t == 1 {
                let Some(cw) =
                    scene
                        .camera
                        .sample_wi(y[1].p(), 0.0, Point2f::new(0.5, 0.5), &lambda)
                else {
                    ok = false;
                    break;
                };
                let mut v = Vertex::new(
                    VertexKind::Camera,
                    Point3fi::from(cw.p_lens),
                    0.0,
                    cw.wi_importance,
                );
                v.n = cw.n_lens;
                v.ns = cw.n_lens;
                Some(v)
            } else {
                None
            };
            let unsampleable = |v: &Vertex| v.pdf_fwd.is_nan() || v.pdf_fwd <= 0.0;
            if c.iter().skip(1).any(unsampleable) || l.iter().any(unsampleable) {
                ok = false;
                break;
            }
            let w: Float = mis_weight(&scene, &l, &c, sampled.as_ref(), s, t);
            weights.push(w);
            sum += w;
        }
        if !ok {
            continue;
        }
        assert!(
            (sum - 1.0).abs() < 1e-3,
            "path of {n} vertices (seed {seed}): weights {weights:?} sum to {sum}"
        );
        checked += 1;
    }
    assert!(checked > 100, "only {checked} paths checked");
}
