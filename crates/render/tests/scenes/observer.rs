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
