//! `Accelerator "embree"` against `"bvh"` (cargo feature `embree`): the
//! same scenes built under both, random rays (fixed seeds) through each,
//! and the closest hit (entry, `t`, the whole interaction), the shadow
//! test and a small render compared. Embree only culls; rpbrt's tests
//! decide every hit, so the answers must be the same bit for bit.
#![cfg(feature = "embree")]

use crate::common;

use rpbrt_geometry::{Float, Point3f, Ray, Vector3f};
use rpbrt_render::accel::Accelerator;
use rpbrt_render::rng::Rng;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions, CreatedScene};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};

/// Random triangles in `[-2, 2]³` (sizes from needles to the whole
/// scene), degenerate ones among them, as a `trianglemesh`.
fn random_mesh(seed: u64, n: usize, size: Float) -> String {
    let mut r = Rng::with_sequence(seed);
    let mut p = Vec::new();
    for i in 0..n {
        let mut u = || 4.0 * r.uniform_float() - 2.0;
        let c = [u(), u(), u()];
        let mut v = [[0.0; 3]; 3];
        for (k, vk) in v.iter_mut().enumerate() {
            for a in 0..3 {
                vk[a] = c[a] + size * (r.uniform_float() - 0.5) * (1 + k % 2) as Float;
            }
        }
        match i % 17 {
            // Two equal vertices.
            0 => v[2] = v[1],
            // Collinear.
            1 => {
                for a in 0..3 {
                    v[2][a] = 2.0 * v[1][a] - v[0][a];
                }
            }
            // A needle.
            2 => {
                for a in 0..3 {
                    v[2][a] = v[1][a] + 1e-6 * (v[0][a] - v[1][a]);
                }
            }
            _ => {}
        }
        p.extend(v.iter().flatten().copied());
    }
    let idx: Vec<String> = (0..3 * n).map(|i| i.to_string()).collect();
    let pts: Vec<String> = p.iter().map(|x| format!("{x:e}")).collect();
    format!(
        "Shape \"trianglemesh\" \"integer indices\" [ {} ] \"point3 P\" [ {} ]\n",
        idx.join(" "),
        pts.join(" ")
    )
}

/// A scene with every kind of primitive the aggregate distinguishes.
fn scene_text(accel: &str) -> String {
    let mut s = format!(
        r#"Accelerator "{accel}"
Option "string rendercoordsys" "world"
LookAt 0 0.5 -9  0 0 0  0 1 0
Camera "perspective" "float fov" 35
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
  "string filename" "{out}"
Sampler "independent" "integer pixelsamples" 4
Integrator "path" "integer maxdepth" 3
TransformTimes 0 1
WorldBegin
LightSource "infinite" "rgb L" [ 0.4 0.45 0.5 ]
AttributeBegin
  Translate 0 4 0
  AreaLightSource "diffuse" "rgb L" [ 6 6 6 ]
  Shape "sphere" "float radius" 0.6
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.6 0.5 0.4 ]
"#,
        out = std::env::temp_dir()
            .join(format!(
                "rpbrt-embree-test-{accel}-{}.exr",
                std::process::id()
            ))
            .display()
    );
    s += &random_mesh(1, 1500, 0.25);
    s += &random_mesh(2, 40, 2.0);
    // Huge triangles (far beyond the scene) and a floor.
    s += r#"Shape "trianglemesh" "integer indices" [ 0 1 2  3 4 5 ]
  "point3 P" [ -1e7 -3 -1e7  1e7 -3 -1e7  0 -3 1e7   -1e20 -1e20 40  1e20 -1e20 40  0 1e20 40 ]
AttributeBegin
  Translate 1 0.5 0
  Shape "sphere" "float radius" 0.7
  Translate -2.5 0 0.5
  Shape "sphere" "float radius" 0.5 "float zmin" -0.2 "float zmax" 0.3 "float phimax" 270
  Translate 0 -1.5 0
  Shape "cylinder" "float radius" 0.3 "float zmin" -0.5 "float zmax" 0.5
  Translate 1 0 -1
  Shape "disk" "float radius" 0.6 "float innerradius" 0.2
  Translate 1 1 0
  Shape "bilinearmesh" "point3 P" [ -0.5 0 -0.5  0.5 0.2 -0.5  -0.5 0 0.5  0.5 -0.3 0.5 ]
  Translate -1 1 0
  Shape "curve" "point3 P" [ 0 0 0  1 1 0  2 -1 0  3 0 0 ] "float width" 0.2
  Translate 0 -2 0
  Shape "curve" "point3 P" [ 0 0 0  1 1 0  2 -1 0  3 0 0 ] "float width" 0.1
    "string type" "ribbon" "normal N" [ 0 0 -1  0 0 -1 ]
AttributeEnd
AttributeBegin
  Translate 0 -1 -1
  Shape "trianglemesh" "float alpha" 0.5 "integer indices" [ 0 1 2 ]
    "point3 P" [ -1 0 0  1 0 0  0 1.5 0 ]
AttributeEnd
ObjectBegin "thing"
  Shape "sphere" "float radius" 0.3
"#;
    s += &random_mesh(3, 200, 0.3).replace("Shape", "  Shape");
    s += r#"ObjectEnd
AttributeBegin
  Translate 2 -1 1
  Scale 0.3 0.3 0.3
  ObjectInstance "thing"
  Translate -8 3 2
  Rotate 40 1 1 0
  ObjectInstance "thing"
AttributeEnd
AttributeBegin
  ActiveTransform StartTime
  Translate -1 1.5 -1
  ActiveTransform EndTime
  Translate -0.5 2 -1.2
  ActiveTransform All
  Shape "sphere" "float radius" 0.4
  Shape "trianglemesh" "integer indices" [ 0 1 2 ] "point3 P" [ -1 0 0  1 0 0  0 1 0.5 ]
AttributeEnd
AttributeBegin
  Translate 0 -2 2
  ActiveTransform EndTime
  Rotate 30 0 1 0
  ActiveTransform All
  ObjectInstance "thing"
AttributeEnd
"#;
    s
}

/// Rays from around the scene: random directions, rays aimed at its
/// middle, axis-parallel ones, finite and infinite `t_max`, times in
/// `[0, 1]`.
fn random_rays(seed: u64, n: usize) -> Vec<(Ray, Float)> {
    let mut r = Rng::with_sequence(seed);
    (0..n)
        .map(|i| {
            let mut u = |lo: Float, hi: Float| lo + (hi - lo) * r.uniform_float();
            let o = Point3f::new(u(-4.0, 4.0), u(-4.0, 4.0), u(-4.0, 4.0));
            let mut d = match i % 3 {
                0 => Vector3f::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)),
                _ => Point3f::new(u(-2.0, 2.0), u(-2.0, 2.0), u(-2.0, 2.0)) - o,
            };
            if i % 29 == 0 {
                d = Vector3f::new(0.0, 0.0, 0.0);
                d[(i / 29) % 3] = if i % 2 == 0 { 1.0 } else { -1.0 };
            }
            let t_max = match i % 7 {
                0 => u(0.0, 3.0),
                _ => Float::INFINITY,
            };
            let time = u(0.0, 1.0);
            (Ray::with_time(o, d, time, None), t_max)
        })
        .collect()
}

/// Casts `rays` through both scenes' aggregates: every closest hit (entry,
/// `t` bit for bit, the interaction) and every shadow test must agree.
/// Returns how many rays hit.
fn assert_same_hits(bvh: &CreatedScene, embree: &CreatedScene, rays: &[(Ray, Float)]) -> usize {
    assert!(
        matches!(embree.scene.aggregate.accelerator(), Accelerator::Embree(_)),
        "the scene did not get Embree: {:?}",
        embree.warnings
    );
    let (a, b) = (&bvh.scene.aggregate, &embree.scene.aggregate);
    assert_eq!(a.entry_count(), b.entry_count());
    let (mut hits, mut differing, mut shadow_differing, mut occluded) = (0, 0, 0, 0);
    for (k, (ray, t_max)) in rays.iter().enumerate() {
        let ra = a.intersect_record(ray, *t_max);
        let rb = b.intersect_record(ray, *t_max);
        let ia = a.intersect(ray, *t_max);
        let ib = b.intersect(ray, *t_max);
        hits += ra.is_some() as usize;
        let same = match (ra, rb) {
            (None, None) => ib.is_none() && ia.is_none(),
            (Some(x), Some(y)) => {
                x.primitive == y.primitive && x.t_hit.to_bits() == y.t_hit.to_bits() && ia == ib
            }
            _ => false,
        };
        if !same {
            differing += 1;
            if differing <= 5 {
                eprintln!("ray {k} {ray:?} t_max {t_max}: bvh {ra:?}, embree {rb:?}");
            }
        }
        let (pa, pb) = (a.intersect_p(ray, *t_max), b.intersect_p(ray, *t_max));
        occluded += pa as usize;
        if pa != pb {
            shadow_differing += 1;
            if shadow_differing <= 5 {
                eprintln!("ray {k} {ray:?} t_max {t_max}: intersect_p bvh {pa}, embree {pb}");
            }
        }
    }
    eprintln!(
        "embree vs bvh: {} rays compared, {hits} hit, {occluded} occluded; \
         {differing} closest hits and {shadow_differing} shadow tests differ",
        rays.len()
    );
    assert_eq!(differing, 0);
    assert_eq!(shadow_differing, 0);
    hits
}

#[test]
fn embree_finds_the_bvh_hits() {
    let bvh = common::created(&scene_text("bvh"));
    let embree = common::created(&scene_text("embree"));
    if let Accelerator::Embree(e) = embree.scene.aggregate.accelerator() {
        assert!(e.triangle_count() > 1000, "{e:?}");
    }
    let rays = random_rays(7, 60_000);
    let hits = assert_same_hits(&bvh, &embree, &rays);
    assert!(hits > rays.len() / 2, "test too weak: {hits} hits");
}

/// A billion units from the origin, where Embree's single-precision
/// culling is coarsest: random meshes (degenerate triangles among them)
/// scaled by 1e9, and the rays with them.
#[test]
fn embree_finds_the_bvh_hits_far_away() {
    const SCALE: Float = 1e9;
    let text = |accel: &str| {
        format!(
            "Accelerator \"{accel}\"\nCamera \"perspective\"\nWorldBegin\nScale 1e9 1e9 1e9\n{}{}",
            random_mesh(11, 800, 0.25),
            random_mesh(12, 30, 2.0)
        )
    };
    let (bvh, embree) = (
        common::created(&text("bvh")),
        common::created(&text("embree")),
    );
    let rays: Vec<(Ray, Float)> = random_rays(13, 20_000)
        .into_iter()
        .map(|(r, t)| {
            let o = Point3f::new(r.o.x * SCALE, r.o.y * SCALE, r.o.z * SCALE);
            (Ray::with_time(o, r.d, r.time, None), t * SCALE)
        })
        .collect();
    let hits = assert_same_hits(&bvh, &embree, &rays);
    assert!(hits > rays.len() / 4, "test too weak: {hits} hits");
}

#[test]
fn embree_renders_the_bvh_image() {
    let a = common::render_with(&scene_text("bvh"), 2, false).0;
    let b = common::render_with(&scene_text("embree"), 2, false).0;
    let (va, vb) = (a.to_f32_vec(), b.to_f32_vec());
    assert_eq!(va.len(), vb.len());
    let differing = va
        .iter()
        .zip(&vb)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    assert!(va.iter().any(|&v| v > 0.0), "black image");
    // The same hits give the same samples: bit-identical pixels.
    assert_eq!(differing, 0, "{differing} of {} values differ", va.len());
}

#[test]
fn embree_takes_no_parameters() {
    let text = scene_text("embree").replace(
        "Accelerator \"embree\"",
        "Accelerator \"embree\" \"integer maxnodeprims\" 4",
    );
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let e = match create_scene(&desc, &CreateOptions::default()) {
        Ok(_) => panic!("an Embree parameter was accepted"),
        Err(e) => e,
    };
    assert!(
        e.iter().any(|d| d.message.contains("maxnodeprims")),
        "{:?}",
        e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
    );
}
