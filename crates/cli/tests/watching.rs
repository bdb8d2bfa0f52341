//! Watching a render end to end: `--preview` in a real (headless
//! Chromium) browser, `--display-server` against a test server that reads
//! tev's protocol, and the mistakes (a port in use, a bad address).

mod cdp;

use rpbrt_render::image::Image;
use std::io::{BufRead, BufReader, Read};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

fn rpbrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rpbrt"))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rpbrt-watch-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A small box lit from above: `xres × yres` pixels, `spp` samples, a
/// float EXR (no half rounding).
fn scene(dir: &Path, (xres, yres): (u32, u32), spp: u32) -> PathBuf {
    let text = format!(
        r#"LookAt 0 1 3.4  0 1 0  0 1 0
Camera "perspective" "float fov" [ 39 ]
Film "rgb" "integer xresolution" [ {xres} ] "integer yresolution" [ {yres} ]
    "string filename" [ "out.exr" ] "bool savefp16" false
Sampler "zsobol" "integer pixelsamples" [ {spp} ]
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
AttributeBegin
    AreaLightSource "diffuse" "rgb L" [ 8 8 8 ]
    Shape "bilinearmesh" "point3 P" [ -0.4 1.99 -0.4  0.4 1.99 -0.4  -0.4 1.99 0.4  0.4 1.99 0.4 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1
                                  -1 2 -1  1 2 -1  1 2 1  -1 2 1
                                  -1 0 -1  1 0 -1  1 2 -1  -1 2 -1 ]
    "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  8 10 9 8 11 10 ]
Material "diffuse" "rgb reflectance" [ 0.6 0.1 0.1 ]
Shape "trianglemesh" "point3 P" [ 1 0 -1  1 0 1  1 2 1  1 2 -1 ] "integer indices" [ 0 1 2 0 2 3 ]
Material "diffuse" "rgb reflectance" [ 0.1 0.5 0.1 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  -1 2 -1  -1 2 1  -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ]
Material "dielectric"
AttributeBegin
    Translate 0.3 0.4 0.2
    Shape "sphere" "float radius" 0.4
AttributeEnd
"#
    );
    let p = dir.join("scene.pbrt");
    std::fs::write(&p, text).unwrap();
    p
}

/// Starts rpbrt with `args`; its stderr lines arrive on the receiver.
fn start(args: &[&std::ffi::OsStr]) -> (Child, mpsc::Receiver<String>) {
    let mut child = rpbrt()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    (child, rx)
}

/// The final image's RGB at pixel `(x, y)`.
fn exr_pixel(path: &Path, x: usize, y: usize) -> [f32; 3] {
    let im = Image::read(path, None).unwrap().image;
    let rgb = im.get_channel_desc(&["R", "G", "B"]).expect("R, G, B");
    let im = im.select_channels(&rgb);
    let nc = im.n_channels();
    let w = im.resolution().x as usize;
    let v = im.as_f32().expect("a float EXR");
    let i = nc * (y * w + x);
    [v[i], v[i + 1], v[i + 2]]
}

/// The image canvas's left, top, width and height in the viewport.
fn view_rect(page: &mut cdp::Page) -> Vec<f64> {
    let rect = page.eval(
        r#"(() => { const r = document.getElementById("view").getBoundingClientRect();
                    return [r.left, r.top, r.width, r.height]; })()"#,
    );
    rect.as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// What the page shows, as JSON, for the test to read.
const PAGE_STATE: &str = r#"(() => {
  const c = document.getElementById("view");
  if (!c || document.readyState === "loading") {
    return { state: "loading", width: 0, height: 0, sum: 0, progress: "" };
  }
  let sum = 0;
  if (c.width > 0) {
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    for (let i = 0; i < d.length; i++) sum = (sum * 31 + d[i]) % 1000000007;
  }
  return { state: document.getElementById("state").textContent, width: c.width,
           height: c.height, sum, progress: document.getElementById("progress").textContent };
})()"#;

#[test]
fn preview_in_a_real_browser() {
    let Some(chromium) = cdp::find_chromium() else {
        eprintln!(
            "skipping preview_in_a_real_browser: no chromium found (install Debian's \
             `chromium` package, or set RPBRT_CHROMIUM)"
        );
        return;
    };
    let dir = temp_dir("browser");
    // One thread, 64 × 48 pixels in twelve tiles, 512 samples: several
    // seconds, the image changing as each tile finishes.
    const W: usize = 64;
    const H: usize = 48;
    let scene = scene(&dir, (W as u32, H as u32), 512);
    let out = dir.join("out.exr");
    let (mut child, lines) = start(&[
        "--preview".as_ref(),
        "--nthreads".as_ref(),
        "1".as_ref(),
        "--outfile".as_ref(),
        out.as_os_str(),
        scene.as_os_str(),
    ]);
    let url = loop {
        let line = lines
            .recv_timeout(Duration::from_secs(60))
            .expect("rpbrt printed no preview URL");
        if let Some(u) = line.strip_prefix("rpbrt: preview at ") {
            break u.to_string();
        }
    };
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    let browser = cdp::Browser::launch(&chromium, &url);
    let mut page = browser.page(&url);
    let minute = Duration::from_secs(60);

    // An image while rendering, then a different one, still rendering.
    let first = page.wait_for("a first image", minute, PAGE_STATE, |v| {
        v["state"] == "rendering" && v["width"] == W && v["height"] == H
    });
    let second = page.wait_for("the image to change", minute, PAGE_STATE, |v| {
        v["sum"] != first["sum"] || v["state"] != "rendering"
    });
    assert_eq!(
        second["state"], "rendering",
        "finished before the image changed: {second}"
    );
    assert!(
        second["progress"].as_str().unwrap().contains("ETA"),
        "{second}"
    );

    // The "denoised" toggle, mid-render: the denoised snapshot is shown
    // (or, without Open Image Denoise, the reason and the raw image);
    // unticked, the raw image again.
    let toggle = |on: bool| {
        format!(
            r#"(() => {{ const d = document.getElementById("denoised"); d.checked = {on};
                        d.dispatchEvent(new Event("change")); return 1; }})()"#
        )
    };
    const DENOISE_STATE: &str = r#"({ src: frameSrc,
        error: document.getElementById("denoise-error").textContent,
        checked: document.getElementById("denoised").checked })"#;
    page.eval(&toggle(true));
    let den = page.wait_for(
        "the denoised image, or why not",
        minute,
        DENOISE_STATE,
        |v| v["src"] == "/denoised" || v["error"].as_str().is_some_and(|e| !e.is_empty()),
    );
    if den["src"] != "/denoised" {
        let why = den["error"].as_str().unwrap_or_default();
        assert!(why.contains("pip install pyoidn"), "{den}");
        assert_eq!(den["checked"], false, "{den}");
        eprintln!("the denoised toggle said why it cannot denoise here: {why}");
    }
    page.eval(&toggle(false));
    page.wait_for("the raw image again", minute, DENOISE_STATE, |v| {
        v["src"] == "/image"
    });

    // Closed and reopened mid-render (a reload): it picks up again.
    page.eval("location.reload(), 1");
    let again = page.wait_for("the reloaded page's image", minute, PAGE_STATE, |v| {
        v["width"] == W && v["state"] != "connecting"
    });
    assert_ne!(again["sum"], 0, "{again}");

    // The end.
    let done = page.wait_for("the render to finish", 4 * minute, PAGE_STATE, |v| {
        v["state"].as_str().is_some_and(|s| s.starts_with("done"))
    });
    assert!(
        done["progress"].as_str().unwrap().starts_with("100.0%"),
        "{done}"
    );
    assert!(
        done["progress"].as_str().unwrap().contains("512 spp"),
        "{done}"
    );

    // The readout under the cursor is the film's float value.
    let (x, y) = (30usize, 17usize);
    let r = view_rect(&mut page);
    page.mouse_move(
        r[0] + (x as f64 + 0.5) * r[2] / W as f64,
        r[1] + (y as f64 + 0.5) * r[3] / H as f64,
    );
    let readout =
        page.eval(r#"["px", "r", "g", "b"].map((id) => document.getElementById(id).textContent)"#);
    assert_eq!(readout[0], format!("{x}, {y}"), "{readout}");
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}");
    let want = exr_pixel(&out, x, y);
    for c in 0..3 {
        let shown: f32 = readout[c + 1].as_str().unwrap().parse().unwrap();
        assert!(
            (shown - want[c]).abs() <= 1e-5 * want[c].abs() + 1e-7,
            "channel {c}: page {shown}, film {}",
            want[c]
        );
    }
    assert!(want.iter().all(|v| *v > 0.0), "{want:?}");

    // Exposure and tone mapping redraw; the PFM saved holds the floats.
    let before = page.eval(PAGE_STATE)["sum"].clone();
    page.eval(
        r#"(() => { const e = document.getElementById("exposure"); e.value = "2";
                    e.dispatchEvent(new Event("input")); return 1; })()"#,
    );
    assert_ne!(page.eval(PAGE_STATE)["sum"], before);
    let exposure = page.eval(r#"document.getElementById("exposure-value").textContent"#);
    assert_eq!(exposure, "+2.0");
    page.eval(
        r#"(() => { const t = document.getElementById("tonemap"); t.value = "aces";
                    t.dispatchEvent(new Event("change")); return 1; })()"#,
    );
    let pfm = page.eval(
        r#"pfmBlob().arrayBuffer().then((b) => {
             const head = new TextDecoder().decode(new Uint8Array(b, 0, 16));
             const f = new DataView(b);
             const at = head.indexOf("-1.0\n") + 5;
             return [b.byteLength - at, head.slice(0, at), f.getFloat32(at, true)];
           })"#,
    );
    assert_eq!(pfm[0], W * H * 12, "{pfm}");
    assert_eq!(pfm[1], format!("PF\n{W} {H}\n-1.0\n"));
    // The first value stored is the bottom-left pixel's red.
    let bottom_left = exr_pixel(&out, 0, H - 1)[0];
    assert!((pfm[2].as_f64().unwrap() as f32 - bottom_left).abs() <= 1e-6 * bottom_left.abs());
    let _ = std::fs::remove_dir_all(&dir);
}

/// One tev message as the viewer reads it, its framing checked.
#[derive(Debug)]
enum TevMessage {
    Create {
        title: String,
        size: (i32, i32),
        channels: Vec<String>,
    },
    Update {
        channel: String,
        rect: [i32; 4],
        values: Vec<f32>,
    },
}

fn tev_messages(bytes: &[u8]) -> Vec<TevMessage> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while !rest.is_empty() {
        assert!(rest.len() >= 4, "a length cut short");
        let len = u32::from_le_bytes(rest[..4].try_into().unwrap()) as usize;
        assert!(
            len >= 6 && len <= rest.len(),
            "length {len} of {}",
            rest.len()
        );
        let mut m = &rest[4..len];
        let mut take = |n: usize| {
            let (a, b) = m.split_at(n);
            m = b;
            a
        };
        let kind = take(1)[0];
        let focus = take(1)[0];
        let string = |m: &mut &[u8]| {
            let end = m.iter().position(|&b| b == 0).expect("NUL-terminated");
            let s = String::from_utf8(m[..end].to_vec()).unwrap();
            *m = &m[end + 1..];
            s
        };
        let i32s = |m: &mut &[u8], n: usize| -> Vec<i32> {
            let v = m[..4 * n]
                .chunks(4)
                .map(|b| i32::from_le_bytes(b.try_into().unwrap()))
                .collect();
            *m = &m[4 * n..];
            v
        };
        match kind {
            4 => {
                assert_eq!(focus, 1);
                let title = string(&mut m);
                let v = i32s(&mut m, 3);
                let channels = (0..v[2]).map(|_| string(&mut m)).collect();
                assert!(m.is_empty());
                out.push(TevMessage::Create {
                    title,
                    size: (v[0], v[1]),
                    channels,
                });
            }
            3 => {
                assert_eq!(focus, 0);
                let _title = string(&mut m);
                let channel = string(&mut m);
                let r = i32s(&mut m, 4);
                assert_eq!(m.len(), 4 * (r[2] * r[3]) as usize);
                let values = m
                    .chunks(4)
                    .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                    .collect();
                out.push(TevMessage::Update {
                    channel,
                    rect: [r[0], r[1], r[2], r[3]],
                    values,
                });
            }
            k => panic!("message type {k}"),
        }
        rest = &rest[len..];
    }
    out
}

#[test]
fn display_server_streams_the_render_to_tev() {
    let dir = temp_dir("tev");
    // 150 × 140: tiles of 128 and of 22 / 12 pixels.
    let scene = scene(&dir, (150, 140), 8);
    let out = dir.join("tev.exr");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let server = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut all = Vec::new();
        s.read_to_end(&mut all).unwrap();
        all
    });
    let mut child = rpbrt()
        .args(["--display-server", &addr, "--quiet", "--outfile"])
        .arg(&out)
        .arg(&scene)
        .spawn()
        .unwrap();
    let pid = child.id();
    assert!(child.wait().unwrap().success());
    let msgs = tev_messages(&server.join().unwrap());
    let TevMessage::Create {
        title,
        size,
        channels,
    } = &msgs[0]
    else {
        panic!("{:?}", msgs[0])
    };
    assert_eq!(title, &format!("{} ({pid})", out.display()));
    assert_eq!(*size, (150, 140));
    assert_eq!(channels, &["R", "G", "B"]);
    // The updates, applied in order, leave tev showing the final image.
    let mut shown = vec![0.0f32; 3 * 150 * 140];
    for m in &msgs[1..] {
        let TevMessage::Update {
            channel,
            rect,
            values,
        } = m
        else {
            panic!("a second CreateImage")
        };
        let c = ["R", "G", "B"].iter().position(|n| n == channel).unwrap();
        let [x, y, w, h] = rect.map(|v| v as usize);
        assert!(
            w <= 128 && h <= 128 && x % 128 == 0 && y % 128 == 0,
            "{rect:?}"
        );
        assert!(x + w <= 150 && y + h <= 140, "{rect:?}");
        for (k, v) in values.iter().enumerate() {
            shown[3 * ((y + k / w) * 150 + x + k % w) + c] = *v;
        }
    }
    for (x, y) in [(0, 0), (75, 70), (149, 139), (130, 10), (10, 130)] {
        let want = exr_pixel(&out, x, y);
        let got = &shown[3 * (y * 150 + x)..][..3];
        assert_eq!(got, want, "pixel ({x}, {y})");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn preview_port_in_use_is_a_clear_error() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let dir = temp_dir("inuse");
    let scene = scene(&dir, (8, 8), 1);
    let out = rpbrt()
        .args(["--preview", &addr])
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains(&format!(
            "rpbrt: error: --preview: {addr} is already in use"
        )),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_watch_addresses_are_clear_errors() {
    for (args, says) in [
        (
            &["--preview=here:now", "s.pbrt"][..],
            "--preview: \"here:now\"",
        ),
        (
            &["--preview=127.0.0.1:70000", "s.pbrt"][..],
            "no valid port",
        ),
        (
            &["--display-server", "localhost", "s.pbrt"][..],
            "expected \"host:port\"",
        ),
        (&["--display-server"][..], "--display-server needs a value"),
    ] {
        let out = rpbrt().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(
            e.starts_with("rpbrt: error: ") && e.contains(says),
            "{args:?}: {e}"
        );
    }
}

/// What an interactive page shows, for the test to read: the camera text,
/// the state, the camera number the page knows and the one its image was
/// rendered from, a hash of the image's floats, the latencies recorded.
const INTERACTIVE_STATE: &str = r#"(() => {
  let hash = 0;
  if (typeof frame !== "undefined" && frame) {
    const u = new Uint32Array(frame.rgb.buffer, frame.rgb.byteOffset, frame.rgb.length);
    for (let i = 0; i < u.length; i++) hash = (hash * 31 + u[i]) % 1000000007;
  }
  const t = document.getElementById("camera-text");
  return { text: t ? t.value : "", state: document.getElementById("state").textContent,
           cam: (typeof camera !== "undefined" && camera) ? camera.number : -1,
           frame: (typeof frame !== "undefined" && frame) ? frame.camera : -1,
           done: (typeof frame !== "undefined" && frame) ? frame.done : false,
           hash, lat: window.rpbrtLatencies ? window.rpbrtLatencies.length : 0,
           error: (document.getElementById("camera-error") || {}).textContent };
})()"#;

/// The eye, look point and up vector of the camera text's first `LookAt`.
fn look_at(text: &str) -> [f32; 9] {
    let line = text
        .lines()
        .find(|l| l.starts_with("LookAt"))
        .unwrap_or_else(|| panic!("no LookAt in {text:?}"));
    let v: Vec<f32> = line
        .split_whitespace()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    v.try_into().unwrap()
}

/// Presses (and releases) a key in the page, as a user would.
fn press(page: &mut cdp::Page, key: &str, code: &str, vk: u32) {
    for ty in ["keyDown", "keyUp"] {
        page.call(
            "Input.dispatchKeyEvent",
            serde_json::json!({ "type": ty, "key": key, "code": code,
                                "windowsVirtualKeyCode": vk }),
        );
    }
}

/// The key presses that move the camera: key, code, virtual key code.
const KEYS: [(&str, &str, u32); 10] = [
    ("w", "KeyW", 87),
    ("s", "KeyS", 83),
    ("a", "KeyA", 65),
    ("d", "KeyD", 68),
    ("q", "KeyQ", 81),
    ("e", "KeyE", 69),
    ("ArrowLeft", "ArrowLeft", 37),
    ("ArrowRight", "ArrowRight", 39),
    ("ArrowUp", "ArrowUp", 38),
    ("ArrowDown", "ArrowDown", 40),
];

/// Starts `rpbrt --interactive ARGS` and opens its page once it serves.
fn interactive(args: &[&std::ffi::OsStr], chromium: &Path) -> (Running, cdp::Browser, cdp::Page) {
    let mut all: Vec<&std::ffi::OsStr> = vec!["--interactive".as_ref()];
    all.extend_from_slice(args);
    let (child, lines) = start(&all);
    let child = Running(child);
    let url = loop {
        let line = lines
            .recv_timeout(Duration::from_secs(120))
            .expect("rpbrt printed no preview URL");
        if let Some(u) = line.strip_prefix("rpbrt: preview at ") {
            break u.to_string();
        }
    };
    let browser = cdp::Browser::launch(chromium, &url);
    let page = browser.page(&url);
    (child, browser, page)
}

/// Waits until the page shows the image with every sample for the camera
/// it knows of.
fn converged(page: &mut cdp::Page, what: &str) -> serde_json::Value {
    page.wait_for(what, Duration::from_secs(120), INTERACTIVE_STATE, |v| {
        v["cam"].as_i64().is_some_and(|c| c >= 0)
            && v["done"] == true
            && v["frame"] == v["cam"]
            && v["state"] == "converged"
    })
}

/// Makes `n` camera changes (A and D in turn, each waited for) and
/// returns the page's latency for each: from sending the change to
/// drawing the first image rendered from it, in milliseconds.
fn latencies(page: &mut cdp::Page, n: usize) -> Vec<f64> {
    for i in 0..n {
        let before = page.eval(INTERACTIVE_STATE)["lat"].as_u64().unwrap();
        let (key, code, vk) = KEYS[2 + i % 2];
        press(page, key, code, vk);
        page.wait_for(
            "a new image after a key",
            Duration::from_secs(60),
            INTERACTIVE_STATE,
            |v| v["lat"].as_u64().is_some_and(|l| l > before),
        );
    }
    let v = page.eval("window.rpbrtLatencies");
    let all: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    all[all.len() - n..].to_vec()
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// An rpbrt process killed when dropped (a failed test leaves none
/// behind: it would hold the build lock's descriptor, among others).
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Ends an interactive render as a user does (Ctrl-C); its exit status:
/// success when the image written has all its samples, 130 (interrupted)
/// when not.
fn interrupt(mut child: Running) -> std::process::ExitStatus {
    // SAFETY: a signal to the child process started above.
    unsafe { libc::kill(child.0.id() as libc::pid_t, libc::SIGINT) };
    child.0.wait().unwrap()
}

#[test]
fn interactive_camera_in_a_real_browser() {
    let Some(chromium) = cdp::find_chromium() else {
        eprintln!("skipping interactive_camera_in_a_real_browser: no chromium found");
        return;
    };
    let dir = temp_dir("interactive");
    let scene = scene(&dir, (48, 36), 16);
    let out = dir.join("out.exr");
    // World render space: there the camera text pasted into the file gives
    // the same pixels bit for bit (elsewhere render space follows the
    // camera, and the scene's numbers round differently).
    let (child, _browser, mut page) = interactive(
        &[
            "--nthreads".as_ref(),
            "2".as_ref(),
            "--render-coord-sys".as_ref(),
            "world".as_ref(),
            "--outfile".as_ref(),
            out.as_os_str(),
            scene.as_os_str(),
        ],
        &chromium,
    );
    let first = converged(&mut page, "the file's camera, converged");
    assert_eq!(first["cam"], 0, "{first}");
    let text0 = first["text"].as_str().unwrap().to_string();
    assert!(
        text0.starts_with("LookAt 0 1 3.4  0 1 2.4  0 1 0\nCamera \"perspective\""),
        "{text0}"
    );

    // Each key moves the camera its way: the scene's camera looks down −z
    // with +y up, so the image's right is world −x.
    let mut text = text0.clone();
    for (key, code, vk) in KEYS {
        let before = look_at(&text);
        press(&mut page, key, code, vk);
        let v = page.wait_for(
            "the camera text to change",
            Duration::from_secs(60),
            INTERACTIVE_STATE,
            |v| v["text"].as_str().is_some_and(|t| t != text),
        );
        text = v["text"].as_str().unwrap().to_string();
        let [ex, ey, ez, lx, ly, ..] = look_at(&text);
        let [bx, by, bz, blx, bly, ..] = before;
        // The turns compare the view direction's x and y with before.
        let ok = match key {
            "w" => ez < bz,
            "s" => ez > bz,
            "a" => ex > bx,
            "d" => ex < bx,
            "q" => ey < by,
            "e" => ey > by,
            "ArrowLeft" => lx - ex > blx - bx,
            "ArrowRight" => lx - ex < blx - bx,
            "ArrowUp" => ly - ey > bly - by,
            _ => ly - ey < bly - by,
        };
        assert!(ok, "{key}: {before:?} -> {text}");
    }

    // A drag to the right orbits the camera to the left about the point
    // under the cursor.
    let r = view_rect(&mut page);
    let (cx, cy) = (r[0] + r[2] / 2.0, r[1] + r[3] / 2.0);
    let before = look_at(&text);
    for (ty, x) in [
        ("mousePressed", cx),
        ("mouseMoved", cx + 6.0),
        ("mouseReleased", cx + 6.0),
    ] {
        page.call(
            "Input.dispatchMouseEvent",
            serde_json::json!({ "type": ty, "x": x, "y": cy, "button": "left", "buttons": 1, "clickCount": 1 }),
        );
    }
    let v = page.wait_for(
        "the orbit",
        Duration::from_secs(60),
        INTERACTIVE_STATE,
        |v| v["text"].as_str().is_some_and(|t| t != text),
    );
    text = v["text"].as_str().unwrap().to_string();
    assert!(look_at(&text)[0] > before[0], "{before:?} -> {text}");

    // Malformed requests are refused with a reason; the render goes on.
    let post = |body: &str| {
        format!(
            r#"fetch("/camera", {{ method: "POST", headers: {{ "Content-Type": "application/json" }},
                                   body: {body:?} }}).then(async (r) => [r.status, await r.text()])"#
        )
    };
    for (body, why) in [
        (r#"{"op":"key","key":"w","speed":2}"#, "unknown field"),
        (r#"{"op":"lens","fov":1e400}"#, "not JSON"),
        (r#"{"op":"lens","fov":-3}"#, "field of view"),
        (r#"{"op":"orbit","dx":"far","dy":0}"#, "must be a number"),
    ] {
        let reply = page.eval(&post(body));
        assert_eq!(reply[0], 400, "{body}: {reply}");
        assert!(reply[1].as_str().unwrap().contains(why), "{body}: {reply}");
    }
    let wrong_type = page.eval(
        r#"fetch("/camera", { method: "POST", body: '{"op":"reset"}' }).then((r) => r.status)"#,
    );
    assert_eq!(wrong_type, 415);
    assert_eq!(page.eval(INTERACTIVE_STATE)["text"], text.as_str());

    // The converged image is the image of a fresh render of the file with
    // the camera text pasted in place of its camera.
    let moved = converged(&mut page, "the moved camera, converged");
    assert_eq!(moved["text"], text.as_str());
    let moved_exr = dir.join("moved.exr");
    std::fs::copy(&out, &moved_exr).unwrap();
    let original = std::fs::read_to_string(&scene).unwrap();
    let pasted = original.replacen(
        "LookAt 0 1 3.4  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 39 ]\n",
        &text,
        1,
    );
    assert_ne!(pasted, original);
    let pasted_scene = dir.join("pasted.pbrt");
    std::fs::write(&pasted_scene, pasted).unwrap();
    let fresh = dir.join("fresh.exr");
    let st = rpbrt()
        .args([
            "--quiet",
            "--nthreads",
            "2",
            "--render-coord-sys",
            "world",
            "--outfile",
        ])
        .arg(&fresh)
        .arg(&pasted_scene)
        .status()
        .unwrap();
    assert!(st.success());
    let (a, b) = (
        Image::read(&moved_exr, None).unwrap().image,
        Image::read(&fresh, None).unwrap().image,
    );
    let (a, b) = (a.as_f32().unwrap(), b.as_f32().unwrap());
    assert_eq!(a.len(), b.len());
    let differing = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    assert_eq!(
        differing, 0,
        "values differing from the pasted camera's render"
    );

    // Reset: the file's camera, bit for bit.
    page.eval(r#"document.getElementById("reset").click(), 1"#);
    let back = page.wait_for(
        "the reset",
        Duration::from_secs(60),
        INTERACTIVE_STATE,
        |v| v["cam"].as_i64() > moved["cam"].as_i64(),
    );
    assert_eq!(back["text"], text0.as_str());
    let back = converged(&mut page, "the file's camera again, converged");
    assert_eq!(back["hash"], first["hash"], "{back} {first}");

    // Changes reach the page within the issue's budget, 150 ms (the
    // figure for the bundled scene and the Cornell box comes from the
    // ignored `interactive_latency` below; this 48 × 36 image takes
    // about 15 ms, so the bound holds on a loaded machine).
    let l = latencies(&mut page, 15);
    assert!(median(&l) < 150.0, "{l:?}");
    // Ctrl-C once the image is complete: a clean exit, the image written.
    converged(&mut page, "the last camera, converged");
    let status = interrupt(child);
    assert!(status.success(), "{status}");
    assert!(out.exists());
}

/// The issue's latency figure: the median time from a camera change to
/// the first new image on the page over 50 changes (headless Chromium, 2
/// threads), for the bundled scene and, when `../shared` is there, the
/// Cornell box. `cargo test --release -p rpbrt --test watching --
/// --ignored interactive_latency --nocapture`.
#[test]
#[ignore]
fn interactive_latency() {
    let Some(chromium) = cdp::find_chromium() else {
        eprintln!("no chromium found");
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scenes = [
        root.join("scenes/default.pbrt"),
        root.join("../shared/scenes/cornell-box/scene-v4.pbrt"),
    ];
    let dir = temp_dir("latency");
    for s in scenes.iter().filter(|s| s.exists()) {
        let out = dir.join("out.exr");
        let (child, _browser, mut page) = interactive(
            &[
                "--nthreads".as_ref(),
                "2".as_ref(),
                "--outfile".as_ref(),
                out.as_os_str(),
                s.as_os_str(),
            ],
            &chromium,
        );
        page.wait_for(
            "a first image",
            Duration::from_secs(120),
            INTERACTIVE_STATE,
            |v| v["cam"] == 0 && v["frame"] == 0,
        );
        let l = latencies(&mut page, 50);
        let mut sorted = l.clone();
        sorted.sort_by(f64::total_cmp);
        eprintln!(
            "{}: camera change to new image, 50 changes: median {:.1} ms, min {:.1}, max {:.1}",
            s.display(),
            median(&l),
            sorted[0],
            sorted[sorted.len() - 1]
        );
        let _ = interrupt(child);
    }
}
