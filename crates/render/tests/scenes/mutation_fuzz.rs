//! A stable, seeded mutation fuzzer over the shared pbrt-v4 scenes (the
//! issue allows this in place of `cargo fuzz`, which needs nightly): each
//! scene file is mutated at the byte and token level and pushed through the
//! whole front end (tokenizer, parser, scene builder, shape creation). The
//! only requirement is that nothing panics or hangs: every outcome must be
//! a scene or located diagnostics.
//!
//! Resource claims are among the mutations: large resolutions, counts and
//! subdivision levels are spliced in, and every scene is built and
//! created against a memory budget of [`BUDGET`], so a claim past it must
//! end in a located error like any other mistake.
//!
//! Without `../shared` the test mutates a built-in scene only. The number
//! of mutations per scene is `RPBRT_FUZZ_ITERS` (default 150); with
//! `RPBRT_FUZZ_SECONDS` it runs rounds of fresh seeds for that long, from
//! round `RPBRT_FUZZ_FIRST_ROUND` (default 0), so that runs in chunks need
//! not repeat each other.
//! Crashes it ever finds are kept below as regression tests.

use rpbrt_parser::MemoryBudget;
use rpbrt_render::film::FilmOverrides;
use rpbrt_render::image::ImageMetadata;
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::rng::Rng;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::shapes::create_scene_shapes;
use rpbrt_render::scene::{build_scene_from_bytes, BuildOptions};
use std::path::{Path, PathBuf};

const BUILTIN: &str = r#"LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" 64 "integer yresolution" 64
Sampler "zsobol" "integer pixelsamples" 4
WorldBegin
LightSource "point" "rgb I" [ 1 1 1 ]
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
  Shape "sphere" "float radius" 1
AttributeEnd
AttributeBegin
  Translate 0 -1 0
  Shape "trianglemesh" "point3 P" [ -5 0 -5 5 0 -5 5 0 5 -5 0 5 ] "integer indices" [ 0 1 2 0 2 3 ]
  Shape "bilinearmesh" "point3 P" [ 0 0 0 1 0 0 0 1 0 1 1 1 ]
  Shape "curve" "point3 P" [ 0 0 0 1 1 0 2 -1 0 3 0 0 ] "float width" 0.1
  Shape "loopsubdiv" "integer levels" 2 "point3 P" [ 0 0 0 1 0 0 0 1 0 0 0 1 ] "integer indices" [ 0 2 1 0 1 3 0 3 2 1 2 3 ]
  Shape "disk" "float radius" 2
  Shape "cylinder" "float zmax" 2
ObjectBegin "thing"
  Shape "sphere" "float radius" 0.3
ObjectEnd
ObjectInstance "thing"
AttributeEnd
"#;

/// Media of every type, interfaces, a medium around the camera and
/// subsurface scattering (tabulated and Disney), rendered by volpath.
const BUILTIN_MEDIA: &str = r#"LookAt 0 0 -5  0 0 0  0 1 0
MediumInterface "" "fog"
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" 64 "integer yresolution" 64
Sampler "zsobol" "integer pixelsamples" 4
Integrator "volpath" "integer maxdepth" 8
WorldBegin
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [ 0.1 0.1 0.1 ] "rgb sigma_s" [ 0.2 0.3 0.4 ] "float g" 0.3 "rgb Le" [ 0.1 0.1 0.1 ]
MakeNamedMedium "milk" "string type" "homogeneous" "string preset" "Wholemilk" "float scale" 10
MakeNamedMedium "grid" "string type" "uniformgrid" "integer nx" 2 "integer ny" 2 "integer nz" 2 "float density" [ 0 1 2 3 4 5 6 7 ] "point3 p0" [ -1 -1 -1 ] "point3 p1" [ 1 1 1 ]
MakeNamedMedium "fire" "string type" "uniformgrid" "integer nx" 2 "integer ny" 1 "integer nz" 1 "float density" [ 1 2 ] "float temperature" [ 800 1500 ] "float Lescale" 0.01
MakeNamedMedium "rgb" "string type" "rgbgrid" "integer nx" 1 "integer ny" 1 "integer nz" 2 "rgb sigma_a" [ 1 0 0 0 1 0 ] "rgb sigma_s" [ 1 1 1 2 2 2 ]
MakeNamedMedium "cloud" "string type" "cloud" "float density" 2 "float wispiness" 1 "float frequency" 5
MakeNamedMedium "old" "string type" "heterogeneous" "integer nx" 1 "integer ny" 1 "integer nz" 2 "float density" [ 0.5 1 ]
LightSource "point" "rgb I" [ 5 5 5 ]
LightSource "infinite" "rgb L" [ 0.2 0.2 0.2 ]
AttributeBegin
  MediumInterface "grid" "fog"
  Material "interface"
  Shape "sphere" "float radius" 1
AttributeEnd
AttributeBegin
  Translate 2 0 0
  MediumInterface "cloud" "fog"
  Material "dielectric"
  Shape "sphere" "float radius" 0.8
AttributeEnd
AttributeBegin
  Translate -2 0 0
  MediumInterface "rgb" "fog"
  Material "interface"
  Shape "sphere" "float radius" 0.8
AttributeEnd
AttributeBegin
  Translate 0 2 0
  MediumInterface "fire" "fog"
  Material "interface"
  Shape "sphere" "float radius" 0.8
AttributeEnd
AttributeBegin
  Translate 0 -2 0
  Material "subsurface" "string name" "Ketchup" "float scale" 10
  Shape "sphere" "float radius" 0.8
AttributeEnd
AttributeBegin
  Translate 0 -2 2
  Material "disney" "rgb color" [ 0.8 0.5 0.3 ] "rgb scatterdistance" [ 0.1 0.05 0.02 ] "float spectrans" 0.2
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate 0 0 2
  MediumInterface "old" "fog"
  Material "interface"
  Shape "sphere" "float radius" 0.5
AttributeEnd
"#;

const TOKENS: &[&str] = &[
    "MakeNamedMedium",
    "MediumInterface",
    "\"homogeneous\"",
    "\"uniformgrid\"",
    "\"nanovdb\"",
    "\"float density\"",
    "\"integer nx\"",
    "\"rgb sigma_a\"",
    "\"float g\"",
    "\"interface\"",
    "\"volpath\"",
    "\"simplevolpath\"",
    "AttributeBegin",
    "AttributeEnd",
    "Shape",
    "\"sphere\"",
    "[",
    "]",
    "\"float radius\"",
    "-1e38",
    "1e400",
    "nan",
    "\"integer indices\"",
    "\"point3 P\"",
    "ObjectBegin",
    "ObjectInstance",
    "\"x\"",
    "Include",
    "\"",
    "#",
    "WorldBegin",
    "Transform",
    "TransformBegin",
    "ActiveTransform",
    "EndTime",
    "2147483647",
    "-2147483648",
    "0",
    // Resource claims.
    "16384",
    "65536",
    "1000000",
    "\"integer xresolution\"",
    "\"integer yresolution\"",
    "\"integer levels\"",
    "\"loopsubdiv\"",
    "\"integer nz\"",
    "\"integer nbuckets\"",
    "\"gbuffer\"",
    "\"spectral\"",
];

/// The memory budget each mutated scene is built and created with.
const BUDGET: u64 = 64 << 20;

fn mutate(src: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut v = src.to_vec();
    let n = 1 + rng.uniform_bounded(4);
    for _ in 0..n {
        if v.is_empty() {
            v.extend_from_slice(b"Shape");
        }
        let pos = rng.uniform_bounded(v.len() as u32) as usize;
        match rng.uniform_bounded(6) {
            0 => v[pos] = rng.uniform_u32() as u8,
            1 => {
                v.remove(pos);
            }
            2 => {
                let t = TOKENS[rng.uniform_bounded(TOKENS.len() as u32) as usize];
                let ins: Vec<u8> = format!(" {t} ").into_bytes();
                v.splice(pos..pos, ins);
            }
            3 => v.truncate(pos),
            4 => {
                // Duplicate a chunk.
                let end = (pos + 1 + rng.uniform_bounded(200) as usize).min(v.len());
                let chunk = v[pos..end].to_vec();
                let at = rng.uniform_bounded(v.len() as u32) as usize;
                v.splice(at..at, chunk);
            }
            _ => {
                // Delete a chunk.
                let end = (pos + 1 + rng.uniform_bounded(200) as usize).min(v.len());
                v.drain(pos..end);
            }
        }
    }
    v
}

fn run_one(name: &str, bytes: &[u8], dir: &Path) {
    let mut opts = BuildOptions::default();
    opts.parse.budget = MemoryBudget::new(BUDGET);
    if let Ok((mut desc, _)) = build_scene_from_bytes(name, bytes, dir, &opts) {
        // Skip shape creation for scenes whose meshes are huge (killeroos):
        // the parse is the point there, and creating them each time is slow.
        if desc.shapes.len() < 2000 {
            let _ = create_scene_shapes(&desc);
            // The whole render-object creation (film, camera, sampler,
            // textures, materials, lights, aggregate, integrator) must
            // also turn any input into a scene or located errors; a film,
            // mesh or texture past the budget is one of them. Each
            // creation gets a fresh budget (what the last one charged was
            // dropped with it).
            desc.budget = MemoryBudget::new(BUDGET);
            let _ = create_scene(&desc, &CreateOptions::default());
            // The few-pixel render below skips scenes the budget refused
            // (a large film, most often): it is about shading, and
            // creating their meshes again is slow.
            if !desc.budget.exhausted() {
                desc.budget = MemoryBudget::new(BUDGET);
                // And render a few pixels at one sample each: shading code
                // must not panic on whatever parameters the scene has.
                let out =
                    std::env::temp_dir().join(format!("rpbrt-fuzz-{}.exr", std::process::id()));
                let opts = CreateOptions {
                    spp: Some(1),
                    film: FilmOverrides {
                        outfile: Some(out.display().to_string()),
                        pixel_bounds: Some([0, 4, 0, 4]),
                        ..Default::default()
                    },
                    ..Default::default()
                };
                if let Ok(c) = create_scene(&desc, &opts) {
                    let mut scene = c.scene;
                    let ro = RenderOptions {
                        nthreads: 1,
                        ..Default::default()
                    };
                    let _ = c.integrator.render(
                        &mut scene,
                        &ro,
                        &mut ImageMetadata::default(),
                        &|_| {},
                    );
                }
            }
        }
    }
}

fn scenes() -> Vec<(String, Vec<u8>, PathBuf)> {
    let mut out = vec![
        (
            "<builtin>".to_string(),
            BUILTIN.as_bytes().to_vec(),
            PathBuf::from("."),
        ),
        (
            "<builtin media>".to_string(),
            BUILTIN_MEDIA.as_bytes().to_vec(),
            PathBuf::from("."),
        ),
    ];
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if let Ok(dirs) = std::fs::read_dir(&root) {
        let mut files: Vec<PathBuf> = dirs
            .flatten()
            .filter(|d| d.path().is_dir())
            .flat_map(|d| {
                std::fs::read_dir(d.path())
                    .into_iter()
                    .flatten()
                    .flatten()
                    .map(|e| e.path())
            })
            .filter(|p| p.extension().is_some_and(|e| e == "pbrt"))
            .filter(|p| {
                std::fs::metadata(p)
                    .map(|m| m.len() < 1 << 20)
                    .unwrap_or(false)
            })
            .collect();
        files.sort();
        for f in files {
            if let Ok(b) = std::fs::read(&f) {
                let dir = f.parent().map(Path::to_path_buf).unwrap_or_default();
                out.push((f.display().to_string(), b, dir));
            }
        }
    }
    out
}

#[test]
fn mutated_scenes_never_panic() {
    let iters: u32 = std::env::var("RPBRT_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(150);
    // With RPBRT_FUZZ_SECONDS, keep going over fresh seeds until that much
    // time has passed, and print the count.
    let budget = std::env::var("RPBRT_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .map(std::time::Duration::from_secs);
    let start = std::time::Instant::now();
    let inputs = scenes();
    let mut total = 0u64;
    // Rounds of fresh seeds start here: runs in chunks continue where the
    // last one stopped.
    let first_round: u64 = std::env::var("RPBRT_FUZZ_FIRST_ROUND")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let mut round = first_round;
    loop {
        for (k, (name, bytes, dir)) in inputs.iter().enumerate() {
            let mut rng = Rng::new(0x5eed + k as u64, round);
            for _ in 0..iters {
                let m = mutate(bytes, &mut rng);
                run_one(name, &m, dir);
                total += 1;
            }
        }
        round += 1;
        match budget {
            Some(b) if start.elapsed() < b => continue,
            _ => break,
        }
    }
    if budget.is_some() {
        println!(
            "scene fuzz: {total} mutated scenes over {} inputs in {:.0} s (rounds {first_round} to {})",
            inputs.len(),
            start.elapsed().as_secs_f64(),
            round - 1
        );
    }
}

/// Inputs that once crashed or hung the front end.
#[test]
fn fuzz_regressions() {
    let cases: &[&str] = &[
        // Deep nesting must not overflow the stack.
        &"AttributeBegin\n".repeat(100_000),
        // A film of 2e9 x 2e9 pixels and negative sample counts parse; the
        // renderer rejects them when it creates the film and sampler.
        "Film \"rgb\" \"integer xresolution\" 2000000000 \"integer yresolution\" 2000000000\nSampler \"halton\" \"integer pixelsamples\" -5\nWorldBegin\n",
        // Claims past the budget: a 16384² film (20 GiB of sums), a
        // subdivision to 4^10 times its triangles, an image texture of
        // a million pixels a side that is not there.
        "Film \"rgb\" \"integer xresolution\" 16384 \"integer yresolution\" 16384\nWorldBegin\nShape \"sphere\"\n",
        "Film \"gbuffer\" \"integer xresolution\" 8000 \"integer yresolution\" 8000 \"string filename\" \"x.exr\"\nWorldBegin\nShape \"sphere\"\n",
        "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 10 \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1] \"integer indices\" [0 1 2 2 1 3 0 2 3 0 3 1]\n",
        // Absurd numbers in shapes.
        "WorldBegin\nShape \"sphere\" \"float radius\" 1e38 \"float zmin\" -1e38\nShape \"loopsubdiv\" \"integer levels\" 2147483647 \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n",
        "WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3] \"integer splitdepth\" 2147483647\n",
        "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 -7]\n",
        // A majorant far above the density it bounds (a spike next to
        // empty space) must not make delta tracking hang.
        "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nIntegrator \"volpath\"\nWorldBegin\nMakeNamedMedium \"g\" \"string type\" \"uniformgrid\" \"integer nx\" 3 \"integer ny\" 1 \"integer nz\" 1 \"float density\" [ 0 0 1e30 ] \"point3 p0\" [ -100 -100 -100 ] \"point3 p1\" [ 100 100 100 ]\nMediumInterface \"g\" \"\"\nMaterial \"interface\"\nShape \"sphere\" \"float radius\" 50\n",
    ];
    for c in cases {
        run_one("<regression>", c.as_bytes(), Path::new("."));
    }
}
