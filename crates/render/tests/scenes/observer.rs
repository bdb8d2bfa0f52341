//! The render observer (`RenderOptions::observer`, what `--preview` and
//! `--display-server` watch): every render loop (the tile loop with its
//! splatting integrators, MLT, SPPM) hands it snapshots while it runs and
//! the final image at the end, which is exactly the image written; and
//! watching changes no pixel.

use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::{RenderObserver, RenderOptions, Snapshot};
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};
use std::sync::{Arc, Mutex};

/// Takes every snapshot offered.
#[derive(Default)]
struct Recorder(Mutex<Vec<Snapshot>>);

impl RenderObserver for Recorder {
    fn wants_image(&self, _wave_end: bool) -> bool {
        true
    }
    fn image(&self, snapshot: Snapshot) {
        self.0.lock().unwrap().push(snapshot);
    }
}

const W: usize = 20;
const H: usize = 12;

/// Inside a closed sphere of reflectance 0.5 emitting 0.5: radiance 1
/// everywhere. 20 × 12 pixels: two tiles across, one of them partial.
fn scene(tag: &str, integrator: &str, spp: i32, extra: &str) -> String {
    let dir = std::env::temp_dir().join(format!("rpbrt-observer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!("{tag}.exr"));
    format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 60\n\
         Sampler \"zsobol\" \"integer pixelsamples\" {spp}\n\
         Film \"rgb\" \"integer xresolution\" {W} \"integer yresolution\" {H} \
         \"bool savefp16\" false \"string filename\" \"{}\"\n\
         Integrator \"{integrator}\" \"integer maxdepth\" 8 {extra}\n\
         WorldBegin\nAttributeBegin\nReverseOrientation\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n\
         AreaLightSource \"diffuse\" \"rgb L\" [ 0.5 0.5 0.5 ]\n\
         Shape \"sphere\" \"float radius\" 1\nAttributeEnd\n",
        out.display()
    )
}

/// Renders `text` on `threads` threads, watched by `observer`; the
/// written image's R, G, B.
fn render(text: &str, threads: usize, observer: Option<Arc<Recorder>>) -> Vec<f32> {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let created = create_scene(&desc, &CreateOptions::default())
        .unwrap_or_else(|e| panic!("{:?}", e.iter().map(|d| &d.message).collect::<Vec<_>>()));
    let mut scene = created.scene;
    let opts = RenderOptions {
        nthreads: threads,
        observer: observer.map(|o| o as Arc<dyn RenderObserver>),
        ..Default::default()
    };
    created
        .integrator
        .render(&mut scene, &opts, &mut ImageMetadata::default(), &|_| {})
        .unwrap();
    let im = Image::read(std::path::Path::new(scene.film.filename()), None)
        .unwrap()
        .image;
    let rgb = im.get_channel_desc(&["R", "G", "B"]).unwrap();
    im.select_channels(&rgb).as_f32().unwrap().to_vec()
}

fn mean(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

const CASES: [(&str, &str, i32); 5] = [
    ("path", "", 16),
    ("bdpt", "", 8),
    ("lightpath", "", 16),
    (
        "mlt",
        "\"integer bootstrapsamples\" 4000 \"integer chains\" 64 \"integer mutationsperpixel\" 64",
        1,
    ),
    (
        "sppm",
        "\"integer photonsperiteration\" 4000 \"float radius\" 0.2",
        16,
    ),
];

#[test]
fn every_loop_hands_over_snapshots_and_the_final_image() {
    for (integrator, extra, spp) in CASES {
        let rec = Arc::new(Recorder::default());
        let text = scene(&format!("snap-{integrator}"), integrator, spp, extra);
        let written = render(&text, 2, Some(Arc::clone(&rec)));
        let snaps = rec.0.lock().unwrap();
        let (last, during) = snaps.split_last().expect("no snapshot");
        assert!(
            !during.is_empty(),
            "{integrator}: no snapshot while rendering"
        );
        // The final image comes once, last, and is the image written.
        assert!(last.done && during.iter().all(|s| !s.done), "{integrator}");
        assert_eq!((last.width, last.height), (W, H), "{integrator}");
        assert_eq!(last.rgb, written, "{integrator}");
        for s in during {
            assert_eq!((s.width, s.height, s.rgb.len()), (W, H, 3 * W * H));
            assert!(
                s.rgb.iter().all(|v| v.is_finite() && *v >= 0.0),
                "{integrator}"
            );
        }
        assert!(
            snaps.windows(2).all(|w| w[0].spp <= w[1].spp),
            "{integrator}: samples per pixel went back"
        );
        // Splats are scaled by the work done so far: the last snapshot
        // before the end is already near the answer (1).
        let m = mean(&during[during.len() - 1].rgb);
        assert!(
            (m - 1.0).abs() < 0.2,
            "{integrator}: mean {m} just before the end"
        );
        assert!((mean(written.as_slice()) - 1.0).abs() < 0.1, "{integrator}");
    }
}

#[test]
fn watching_changes_no_pixel() {
    for (integrator, extra, spp) in CASES {
        let text = scene(&format!("same-{integrator}"), integrator, spp, extra);
        let unwatched = render(&text, 2, None);
        let watched = render(&text, 2, Some(Arc::new(Recorder::default())));
        assert_eq!(unwatched, watched, "{integrator}");
    }
}

/// Drives an interactive render as the browser page does: a camera change
/// while the file's camera renders (the pass stops mid-way), then, once
/// that camera's image is complete, the file's camera again, then Ctrl-C.
struct Driver {
    moved: rpbrt_render::camera::Camera,
    original: rpbrt_render::camera::Camera,
    pending: Mutex<Option<rpbrt_render::integrator::CameraChange>>,
    done: Mutex<Vec<Snapshot>>,
    interrupt: Arc<std::sync::atomic::AtomicBool>,
}

impl RenderObserver for Driver {
    fn wants_image(&self, _wave_end: bool) -> bool {
        true
    }
    fn image(&self, s: Snapshot) {
        use rpbrt_render::integrator::CameraChange;
        let propose = |number, camera: &rpbrt_render::camera::Camera| {
            *self.pending.lock().unwrap() = Some(CameraChange {
                number,
                camera: camera.clone(),
            });
        };
        match (s.camera, s.done) {
            (0, false) if s.spp >= 1 => propose(1, &self.moved),
            (1, true) => propose(2, &self.original),
            (2, true) => self
                .interrupt
                .store(true, std::sync::atomic::Ordering::Relaxed),
            _ => {}
        }
        if s.done {
            self.done.lock().unwrap().push(s);
        }
    }
    fn interactive(&self) -> bool {
        true
    }
    fn camera_pending(&self) -> bool {
        self.pending.lock().unwrap().is_some()
    }
    fn take_camera(
        &self,
        timeout: std::time::Duration,
    ) -> Option<rpbrt_render::integrator::CameraChange> {
        let t0 = std::time::Instant::now();
        loop {
            if let Some(c) = self.pending.lock().unwrap().take() {
                return Some(c);
            }
            if t0.elapsed() >= timeout {
                return None;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
}

/// The final snapshot of an ordinary render of `text` from `camera` (or
/// the file's), on `threads` threads.
fn ordinary(
    text: &str,
    camera: Option<&rpbrt_render::camera::Camera>,
    threads: usize,
    wavefront: bool,
) -> Snapshot {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default()).unwrap();
    let created = create_scene(&desc, &CreateOptions::default()).unwrap();
    let mut scene = created.scene;
    if let Some(c) = camera {
        scene.set_camera(c.clone());
    }
    let rec = Arc::new(Recorder::default());
    let opts = RenderOptions {
        nthreads: threads,
        wavefront,
        observer: Some(Arc::clone(&rec) as Arc<dyn RenderObserver>),
        ..Default::default()
    };
    created
        .integrator
        .render(&mut scene, &opts, &mut ImageMetadata::default(), &|_| {})
        .unwrap();
    let last = rec.0.lock().unwrap().pop().unwrap();
    assert!(last.done);
    last
}

/// An interactive render restarts on each camera, and the image it
/// completes for a camera is bit for bit the ordinary render's from that
/// camera, for both designs and any thread count; Ctrl-C ends it.
#[test]
fn interactive_renders_restart_per_camera_and_match_ordinary_renders() {
    use rpbrt_render::camera::LensChange;
    use rpbrt_render::geometry::{AnimatedTransform, Point3f, Transform, Vector3f};
    // A box of two colours around the camera, so that a moved camera sees
    // another image.
    let text = scene("interactive", "path", 32, "").replace(
        "AttributeEnd\n",
        "AttributeEnd\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.8 0.1 0.1 ]\n\
         Shape \"sphere\" \"float radius\" 0.3\n",
    );
    let text = text.replace(
        "LookAt 0 0 0  0 0 1  0 1 0",
        "LookAt 0 0 -0.8  0 0 1  0 1 0",
    );
    for (threads, wavefront) in [(1, false), (2, true), (2, false)] {
        let (desc, _) = build_scene_from_str(&text, &BuildOptions::default()).unwrap();
        let created = create_scene(&desc, &CreateOptions::default()).unwrap();
        let mut scene = created.scene;
        let original = scene.camera.clone();
        let wfc = Transform::look_at(
            Point3f::new(0.5, 0.2, -0.6),
            Point3f::new(0.0, 0.0, 0.0),
            Vector3f::new(0.0, 1.0, 0.0),
        )
        .unwrap()
        .inverse();
        let lens = LensChange {
            fov: Some(40.0),
            ..LensChange::default()
        };
        let moved = original
            .placed(&AnimatedTransform::fixed(wfc), &lens)
            .unwrap();
        let interrupt = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let driver = Arc::new(Driver {
            moved: moved.clone(),
            original: original.clone(),
            pending: Mutex::new(None),
            done: Mutex::new(Vec::new()),
            interrupt: Arc::clone(&interrupt),
        });
        let opts = RenderOptions {
            nthreads: threads,
            wavefront,
            interrupt: Some(interrupt),
            observer: Some(Arc::clone(&driver) as Arc<dyn RenderObserver>),
            ..Default::default()
        };
        let stats = created
            .integrator
            .render(&mut scene, &opts, &mut ImageMetadata::default(), &|_| {})
            .unwrap();
        assert!(!stats.interrupted, "ended on a complete image");
        let done = driver.done.lock().unwrap();
        let by = |n: u64| {
            done.iter()
                .find(|s| s.camera == n)
                .unwrap_or_else(|| panic!("no image for camera {n}"))
        };
        let (a, b) = (by(1), by(2));
        assert_eq!(a.spp, 32);
        assert_eq!(
            a.rgb,
            ordinary(&text, Some(&moved), 1, false).rgb,
            "{threads} {wavefront}"
        );
        assert_eq!(
            b.rgb,
            ordinary(&text, None, 2, true).rgb,
            "{threads} {wavefront}"
        );
        assert_ne!(a.rgb, b.rgb);
        // The file written last is the last camera's image.
        let im = Image::read(std::path::Path::new(scene.film.filename()), None)
            .unwrap()
            .image;
        let rgb = im.get_channel_desc(&["R", "G", "B"]).unwrap();
        assert_eq!(im.select_channels(&rgb).as_f32().unwrap(), b.rgb.as_slice());
    }
}

/// Integrators that splat or keep state across pixels refuse to render
/// interactively, with a reason.
#[test]
fn interactive_renders_refuse_other_integrators() {
    let text = scene("interactive-bdpt", "bdpt", 4, "");
    let (desc, _) = build_scene_from_str(&text, &BuildOptions::default()).unwrap();
    let created = create_scene(&desc, &CreateOptions::default()).unwrap();
    let mut scene = created.scene;
    let driver = Arc::new(Driver {
        moved: scene.camera.clone(),
        original: scene.camera.clone(),
        pending: Mutex::new(None),
        done: Mutex::new(Vec::new()),
        interrupt: Arc::new(std::sync::atomic::AtomicBool::new(false)),
    });
    let opts = RenderOptions {
        observer: Some(driver as Arc<dyn RenderObserver>),
        ..Default::default()
    };
    let e = created
        .integrator
        .render(&mut scene, &opts, &mut ImageMetadata::default(), &|_| {})
        .unwrap_err();
    assert!(e.to_string().contains("cannot render interactively"), "{e}");
}
