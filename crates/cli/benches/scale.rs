//! The scale benchmark (issue 17, "Scale"): a 10-million-triangle binary PLY
//! rendered at 64×64 with one sample per pixel, so that reading the mesh and
//! building the BVH are nearly all the work; and (`--scene motion`) 200,000
//! spheres, each moving with its own `ActiveTransform StartTime`/`EndTime`
//! translations, rendered at 128×128 with one sample per pixel; and
//! (`--scene instances`) 1,000,000 `ObjectInstance`s, each with its own
//! `Translate` and `Rotate`, of one 19,602-triangle mesh (99 MB of text),
//! rendered the same way; and (`--scene textures`) 48 quads, each with its
//! own 4096×4096 8-bit PNG `imagemap` texture (generated once, 2.4 GB of
//! texels), rendered the same way.
//!
//!     cargo bench -p rpbrt --bench scale                  # generate, render, report
//!     cargo bench -p rpbrt --bench scale -- --write-only  # just write the files
//!     cargo bench -p rpbrt --bench scale -- --scene motion
//!     cargo bench -p rpbrt --bench scale -- --scene instances
//!     cargo bench -p rpbrt --bench scale -- --scene textures
//!
//! The mesh is a displaced grid of 2237×2237 vertices (9,999,392 triangles),
//! binary little-endian, positions and triangle indices only (`float x y z`,
//! `list uchar int vertex_indices`), written with `scene.pbrt` into a
//! directory (`--dir`, default `$TMPDIR/rpbrt-scale`); files already there
//! with the expected size are reused. Each run is
//! `/usr/bin/time -v rpbrt --nthreads 2 --quiet scene.pbrt`, and the wall
//! time and peak resident memory ("Maximum resident set size") are printed,
//! with a `RESULT` line giving the best wall time and the largest peak.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

/// Vertices along each side of the grid.
const DEFAULT_N: u32 = 2237;

/// The grid's height above (x, y) in [0, 1]²: a few waves of different
/// directions and frequencies, so that the BVH sees a surface that is
/// neither flat nor regular.
fn height(x: f32, y: f32) -> f32 {
    use std::f32::consts::TAU;
    0.06 * (TAU * (3.0 * x + 0.5 * y)).sin()
        + 0.04 * (TAU * (7.0 * y - 2.0 * x)).cos()
        + 0.015 * (TAU * 23.0 * x).sin() * (TAU * 19.0 * y).sin()
}

/// Size in bytes of the PLY body and header [`write_ply`] writes.
fn ply_size(n: u32) -> u64 {
    let v = u64::from(n) * u64::from(n);
    let f = 2 * u64::from(n - 1) * u64::from(n - 1);
    header(n).len() as u64 + v * 12 + f * 13
}

fn header(n: u32) -> String {
    let v = u64::from(n) * u64::from(n);
    let f = 2 * u64::from(n - 1) * u64::from(n - 1);
    format!(
        "ply\nformat binary_little_endian 1.0\ncomment rpbrt scale benchmark grid {n}x{n}\n\
         element vertex {v}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {f}\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

/// Writes the `n`×`n` grid, streaming (nothing but the output buffer is
/// held in memory).
fn write_ply(path: &Path, n: u32) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, File::create(path)?);
    w.write_all(header(n).as_bytes())?;
    let step = 1.0 / (n - 1) as f32;
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f32 * step, j as f32 * step);
            for c in [x, y, height(x, y)] {
                w.write_all(&c.to_le_bytes())?;
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            for tri in [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]] {
                w.write_all(&[3])?;
                for v in tri {
                    w.write_all(&(v as i32).to_le_bytes())?;
                }
            }
        }
    }
    w.flush()
}

/// The scene: the grid seen obliquely from above, a diffuse material,
/// a distant light and a uniform sky.
fn scene_text(ply: &str) -> String {
    format!(
        "LookAt 0.5 -0.6 0.9  0.5 0.5 0  0 0 1\n\
         Camera \"perspective\" \"float fov\" 45\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 64\n\
         \"string filename\" \"scale.exr\"\n\
         Sampler \"independent\" \"integer pixelsamples\" 1\n\
         WorldBegin\n\
         LightSource \"distant\" \"point3 from\" [0.3 -0.2 1] \"point3 to\" [0 0 0]\n\
         \"blackbody L\" 5500 \"float scale\" 2\n\
         LightSource \"infinite\" \"rgb L\" [0.1 0.1 0.12]\n\
         Material \"diffuse\" \"rgb reflectance\" [0.6 0.55 0.5]\n\
         Shape \"plymesh\" \"string filename\" \"{ply}\"\n"
    )
}

/// Writes `grid.ply` and `scene.pbrt` into `dir` (the PLY only when it is
/// missing or has another size) and returns the scene's path.
fn write_scene(dir: &Path, n: u32) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let ply = dir.join(format!("grid-{n}.ply"));
    let have = std::fs::metadata(&ply).map(|m| m.len()).ok();
    if have != Some(ply_size(n)) {
        let t = Instant::now();
        write_ply(&ply, n)?;
        eprintln!(
            "wrote {} ({:.0} MB) in {:.1} s",
            ply.display(),
            ply_size(n) as f64 / 1e6,
            t.elapsed().as_secs_f64()
        );
    }
    let scene = dir.join("scene.pbrt");
    std::fs::write(&scene, scene_text(&format!("grid-{n}.ply")))?;
    Ok(scene)
}

/// Creates `dir/{stem}.pbrt` and writes the generated scenes' common start:
/// a camera `distance` units from the origin down −z (with `camera_extra`
/// parameters), a 128×128 film named `{stem}.exr`, one independent sample
/// per pixel, a uniform white sky and a diffuse material.
fn generated_scene(
    dir: &Path,
    stem: &str,
    distance: u32,
    camera_extra: &str,
) -> std::io::Result<(PathBuf, BufWriter<File>)> {
    std::fs::create_dir_all(dir)?;
    let scene = dir.join(format!("{stem}.pbrt"));
    let mut w = BufWriter::with_capacity(1 << 20, File::create(&scene)?);
    write!(
        w,
        "LookAt 0 0 -{distance}  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" 45{camera_extra}\n\
         Film \"rgb\" \"integer xresolution\" 128 \"integer yresolution\" 128\n\
         \"string filename\" \"{stem}.exr\"\n\
         Sampler \"independent\" \"integer pixelsamples\" 1\n\
         WorldBegin\n\
         LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
         Material \"diffuse\"\n"
    )?;
    Ok((scene, w))
}

/// A uniform value in [lo, hi) from a fixed-seed xorshift64 step of `state`.
fn uniform(state: &mut u64, lo: f32, hi: f32) -> f32 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    lo + (hi - lo) * ((*state >> 40) as f32 / (1u64 << 24) as f32)
}

/// Spheres in the motion scene.
const MOTION_SPHERES: u32 = 200_000;

/// Writes `motion.pbrt` into `dir`: [`MOTION_SPHERES`] small spheres at
/// random places in a 40-unit cube (a fixed-seed xorshift, so the file is
/// the same every time), each translated by its own start and end
/// transforms, under a uniform sky.
fn write_motion_scene(dir: &Path) -> std::io::Result<PathBuf> {
    let (scene, mut w) = generated_scene(
        dir,
        "motion",
        60,
        " \"float shutteropen\" 0 \"float shutterclose\" 1",
    )?;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = |lo, hi| uniform(&mut state, lo, hi);
    for _ in 0..MOTION_SPHERES {
        let (x, y, z) = (
            uniform(-20.0, 20.0),
            uniform(-20.0, 20.0),
            uniform(-20.0, 20.0),
        );
        let (dx, dy) = (uniform(-0.5, 0.5), uniform(-0.5, 0.5));
        writeln!(
            w,
            "AttributeBegin\nActiveTransform StartTime\nTranslate {x:.4} {y:.4} {z:.4}\n\
             ActiveTransform EndTime\nTranslate {:.4} {:.4} {z:.4}\nActiveTransform All\n\
             Shape \"sphere\" \"float radius\" 0.1\nAttributeEnd",
            x + dx,
            y + dy
        )?;
    }
    w.flush()?;
    Ok(scene)
}

/// Instances in the instances scene, and vertices along each side of the
/// instanced grid.
const INSTANCES: u32 = 1_000_000;
const INSTANCE_GRID: u32 = 100;

/// Writes `instances.pbrt` into `dir`: a wavy 100×100-vertex grid (19,602
/// triangles, inline) in an `ObjectBegin`, and [`INSTANCES`] instances of
/// it at random places and turns in a 200-unit cube (a fixed-seed
/// xorshift, so the file is the same every time), under a uniform sky.
fn write_instances_scene(dir: &Path) -> std::io::Result<PathBuf> {
    let (scene, mut w) = generated_scene(dir, "instances", 300, "")?;
    w.write_all(b"ObjectBegin \"m\"\nShape \"trianglemesh\" \"point3 P\" [")?;
    let n = INSTANCE_GRID;
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            let z = 0.1 * (6.0 * x).sin() * (5.0 * y).cos();
            write!(w, "{x:.4} {y:.4} {z:.4} ")?;
        }
    }
    w.write_all(b"] \"integer indices\" [")?;
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            write!(
                w,
                "{a} {} {} {a} {} {} ",
                a + 1,
                a + n + 1,
                a + n + 1,
                a + n
            )?;
        }
    }
    w.write_all(b"]\nObjectEnd\n")?;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = |lo, hi| uniform(&mut state, lo, hi);
    for _ in 0..INSTANCES {
        let (x, y, z) = (
            uniform(-100.0, 100.0),
            uniform(-100.0, 100.0),
            uniform(-100.0, 100.0),
        );
        let angle = uniform(0.0, 360.0);
        writeln!(
            w,
            "AttributeBegin\nTranslate {x:.3} {y:.3} {z:.3}\nRotate {angle:.2} 0 1 0\n\
             ObjectInstance \"m\"\nAttributeEnd"
        )?;
    }
    w.flush()?;
    Ok(scene)
}

/// Textures in the textures scene, and their side in pixels.
const TEXTURES: u32 = 48;
const TEXTURE_SIZE: u32 = 4096;

/// The 8-bit RGB texel (x, y) of texture `k`: a few waves of the texture's
/// own directions and frequencies with a hashed grain on top, so that every
/// texture is distinct and compresses about as well as a photograph (PNG
/// files of 20-30 MB).
fn texel(k: u32, x: u32, y: u32) -> [u8; 3] {
    use std::f32::consts::TAU;
    let (u, v) = (
        x as f32 / TEXTURE_SIZE as f32,
        y as f32 / TEXTURE_SIZE as f32,
    );
    let f = 2.0 + (k % 7) as f32;
    let g = 3.0 + (k % 5) as f32;
    let mut h =
        (x.wrapping_mul(0x9e37_79b9) ^ y.wrapping_mul(0x85eb_ca6b) ^ k.wrapping_mul(0xc2b2_ae35))
            .wrapping_mul(0x27d4_eb2f);
    h ^= h >> 15;
    let grain = (h & 15) as f32 / 15.0 - 0.5;
    let wave = |a: f32, b: f32, p: f32| 0.5 + 0.4 * (TAU * (a * u + b * v) + p).sin();
    let to8 = |c: f32| ((c + 0.06 * grain).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    [
        to8(wave(f, 0.5 * g, k as f32)),
        to8(wave(-0.7 * g, f, 0.5 * k as f32)),
        to8(wave(0.3 * f, 0.9 * g, 2.0)),
    ]
}

/// Writes `texture-{k}.png` (RGB, 8-bit, fast compression) into `dir`.
fn write_texture(dir: &Path, k: u32) -> std::io::Result<()> {
    let path = dir.join(format!("texture-{k}.png"));
    let tmp = dir.join(format!("texture-{k}.png.part"));
    let w = BufWriter::with_capacity(1 << 20, File::create(&tmp)?);
    let mut enc = png::Encoder::new(w, TEXTURE_SIZE, TEXTURE_SIZE);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().map_err(std::io::Error::other)?;
    let mut stream = writer.stream_writer().map_err(std::io::Error::other)?;
    let mut row = vec![0u8; 3 * TEXTURE_SIZE as usize];
    for y in 0..TEXTURE_SIZE {
        for (x, px) in row.chunks_exact_mut(3).enumerate() {
            px.copy_from_slice(&texel(k, x as u32, y));
        }
        stream.write_all(&row)?;
    }
    stream.finish().map_err(std::io::Error::other)?;
    std::fs::rename(&tmp, &path)
}

/// Writes `textures.pbrt` into `dir`: [`TEXTURES`] quads in a grid facing
/// the camera, each with its own [`TEXTURE_SIZE`]² 8-bit PNG `imagemap`
/// (generated once, on two threads; files already there are reused).
fn write_textures_scene(dir: &Path) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let missing: Vec<u32> = (0..TEXTURES)
        .filter(|k| !dir.join(format!("texture-{k}.png")).exists())
        .collect();
    if !missing.is_empty() {
        let t = Instant::now();
        let next = std::sync::atomic::AtomicUsize::new(0);
        std::thread::scope(|s| -> std::io::Result<()> {
            let workers: Vec<_> = (0..2)
                .map(|_| {
                    s.spawn(|| -> std::io::Result<()> {
                        loop {
                            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some(&k) = missing.get(i) else {
                                return Ok(());
                            };
                            write_texture(dir, k)?;
                        }
                    })
                })
                .collect();
            for w in workers {
                w.join()
                    .map_err(|_| std::io::Error::other("texture writer panicked"))??;
            }
            Ok(())
        })?;
        eprintln!(
            "wrote {} textures in {:.1} s",
            missing.len(),
            t.elapsed().as_secs_f64()
        );
    }
    let (scene, mut w) = generated_scene(dir, "textures", 16, "")?;
    // 8 columns by 6 rows of unit quads, 1.1 apart, in the plane z = 0.
    for k in 0..TEXTURES {
        let (x0, y0) = ((k % 8) as f32 * 1.1 - 4.4, (k / 8) as f32 * 1.1 - 3.3);
        let (x1, y1) = (x0 + 1.0, y0 + 1.0);
        writeln!(
            w,
            "Texture \"t{k}\" \"spectrum\" \"imagemap\" \"string filename\" \"texture-{k}.png\"\n\
             AttributeBegin\nMaterial \"diffuse\" \"texture reflectance\" \"t{k}\"\n\
             Shape \"bilinearmesh\" \"point3 P\" [{x0} {y0} 0 {x1} {y0} 0 {x0} {y1} 0 {x1} {y1} 0]\n\
             \"point2 uv\" [0 0 1 0 0 1 1 1]\nAttributeEnd"
        )?;
    }
    w.flush()?;
    Ok(scene)
}

/// One timed run: (wall seconds, peak RSS in KiB if `/usr/bin/time` gave it).
fn run_once(scene: &Path, threads: u32) -> Result<(f64, Option<u64>), String> {
    let rpbrt = env!("CARGO_BIN_EXE_rpbrt");
    let time = Path::new("/usr/bin/time");
    let mut cmd = if time.exists() {
        let mut c = Command::new(time);
        c.arg("-v").arg(rpbrt);
        c
    } else {
        Command::new(rpbrt)
    };
    cmd.arg("--nthreads")
        .arg(threads.to_string())
        .arg("--quiet")
        .arg(scene);
    if let Some(dir) = scene.parent() {
        cmd.current_dir(dir);
    }
    let t = Instant::now();
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {rpbrt}: {e}"))?;
    let wall = t.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(format!("rpbrt failed ({}):\n{stderr}", out.status));
    }
    let rss = stderr
        .lines()
        .find_map(|l| l.trim().strip_prefix("Maximum resident set size (kbytes):"))
        .and_then(|v| v.trim().parse().ok());
    Ok((wall, rss))
}

struct Args {
    dir: PathBuf,
    n: u32,
    runs: u32,
    threads: u32,
    write_only: bool,
    scene: Scene,
}

/// Which generated scene the bench renders.
#[derive(Clone, Copy, PartialEq)]
enum Scene {
    Triangles,
    Motion,
    Instances,
    Textures,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        dir: std::env::temp_dir().join("rpbrt-scale"),
        n: DEFAULT_N,
        runs: 3,
        threads: 2,
        write_only: false,
        scene: Scene::Triangles,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        let number = |name: &str, v: String| {
            v.parse::<u32>()
                .map_err(|_| format!("{name}: not a count: {v}"))
        };
        match arg.as_str() {
            "--dir" => a.dir = PathBuf::from(value("--dir")?),
            "--n" => a.n = number("--n", value("--n")?)?,
            "--runs" => a.runs = number("--runs", value("--runs")?)?,
            "--nthreads" => a.threads = number("--nthreads", value("--nthreads")?)?,
            "--write-only" => a.write_only = true,
            "--scene" => {
                a.scene = match value("--scene")?.as_str() {
                    "triangles" => Scene::Triangles,
                    "motion" => Scene::Motion,
                    "instances" => Scene::Instances,
                    "textures" => Scene::Textures,
                    other => {
                        return Err(format!(
                            "--scene {other:?}: triangles, motion, instances or textures"
                        ))
                    }
                }
            }
            // `cargo bench` passes this to every bench target.
            "--bench" => {}
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if a.n < 2 || a.n > 40_000 {
        return Err(format!("--n {}: must be in [2, 40000]", a.n));
    }
    Ok(a)
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("scale: {e}");
            return ExitCode::FAILURE;
        }
    };
    let written = match args.scene {
        Scene::Triangles => write_scene(&args.dir, args.n),
        Scene::Motion => write_motion_scene(&args.dir),
        Scene::Instances => write_instances_scene(&args.dir),
        Scene::Textures => write_textures_scene(&args.dir),
    };
    let scene = match written {
        Ok(s) => s,
        Err(e) => {
            eprintln!("scale: writing the scene in {}: {e}", args.dir.display());
            return ExitCode::FAILURE;
        }
    };
    println!("scene: {}", scene.display());
    if args.write_only {
        return ExitCode::SUCCESS;
    }
    let (mut best, mut peak) = (f64::INFINITY, None::<u64>);
    for run in 0..args.runs {
        match run_once(&scene, args.threads) {
            Ok((wall, rss)) => {
                let rss_text = rss.map_or("n/a (no /usr/bin/time)".into(), |k| {
                    format!("{:.2} GB", k as f64 * 1024.0 / 1e9)
                });
                println!("run {run}: {wall:.2} s, peak RSS {rss_text}");
                best = best.min(wall);
                peak = peak.max(rss);
            }
            Err(e) => {
                eprintln!("scale: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    let peak_gb = peak.map_or("n/a".into(), |k| format!("{:.2}", k as f64 * 1024.0 / 1e9));
    let what = match args.scene {
        Scene::Triangles => format!(
            "triangles={}",
            2 * u64::from(args.n - 1) * u64::from(args.n - 1)
        ),
        Scene::Motion => format!("motion spheres={MOTION_SPHERES}"),
        Scene::Instances => format!("instances instances={INSTANCES}"),
        Scene::Textures => format!("textures textures={TEXTURES} size={TEXTURE_SIZE}"),
    };
    println!(
        "RESULT scale {what} threads={} best_wall_s={best:.2} peak_rss_gb={peak_gb}",
        args.threads
    );
    ExitCode::SUCCESS
}
