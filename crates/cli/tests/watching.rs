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
    let rect = page.eval(
        r#"(() => { const r = document.getElementById("view").getBoundingClientRect();
                    return [r.left, r.top, r.width, r.height]; })()"#,
    );
    let r: Vec<f64> = rect
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
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
