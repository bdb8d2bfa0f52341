//! A headless Chromium driven through the Chrome DevTools Protocol, for
//! tests of `--preview` in a real browser: the browser is started with
//! `--remote-debugging-port=0`, the page's target found through
//! `/json/list`, and commands sent over a WebSocket (RFC 6455, a client
//! of the few frames CDP needs, written here to keep dependencies out).

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Chromium on this machine: `$RPBRT_CHROMIUM`, or the first of the
/// usual names on `PATH`.
pub fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RPBRT_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    let names = [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
        "chrome-headless-shell",
    ];
    std::env::split_paths(&path)
        .flat_map(|dir| names.iter().map(move |n| dir.join(n)))
        .find(|p| p.is_file())
}

/// A running headless browser (killed on drop).
pub struct Browser {
    child: Child,
    profile: PathBuf,
    /// `host:port` of its DevTools endpoint.
    pub devtools: String,
}

impl Browser {
    /// Starts `chromium` headless on `url`, with a fresh profile.
    pub fn launch(chromium: &Path, url: &str) -> Browser {
        // A profile per browser: tests of one process run at once, and a
        // profile in use by another browser keeps this one from starting.
        static LAUNCHED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = LAUNCHED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let profile =
            std::env::temp_dir().join(format!("rpbrt-chromium-{}-{n}", std::process::id()));
        let mut child = Command::new(chromium)
            .args([
                "--headless",
                // Tests run as root in CI; the sandbox refuses root.
                "--no-sandbox",
                "--disable-gpu",
                "--disable-dev-shm-usage",
                "--no-first-run",
                "--no-default-browser-check",
                "--remote-debugging-port=0",
                "--window-size=900,700",
            ])
            .arg(format!("--user-data-dir={}", profile.display()))
            .arg(url)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {}: {e}", chromium.display()));
        // It prints "DevTools listening on ws://127.0.0.1:PORT/..." on
        // stderr; the rest of stderr is drained so that it never blocks.
        let stderr = child.stderr.take().expect("piped stderr");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if let Some(rest) = line.split("ws://").nth(1) {
                    if line.contains("DevTools listening") {
                        let _ = tx.send(rest.split('/').next().unwrap_or("").to_string());
                    }
                }
            }
        });
        let devtools = match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(d) => d,
            Err(_) => {
                let _ = child.kill();
                panic!("chromium did not open its DevTools port");
            }
        };
        Browser {
            child,
            profile,
            devtools,
        }
    }

    /// The page showing `url_prefix…`, connected.
    pub fn page(&self, url_prefix: &str) -> Page {
        let t0 = Instant::now();
        loop {
            let list = http_get(&self.devtools, "/json/list");
            let targets: Value = serde_json::from_str(&list).expect("/json/list is JSON");
            let found = targets.as_array().and_then(|ts| {
                ts.iter().find(|t| {
                    t["type"] == "page"
                        && t["url"].as_str().is_some_and(|u| u.starts_with(url_prefix))
                })
            });
            if let Some(ws) = found.and_then(|t| t["webSocketDebuggerUrl"].as_str()) {
                return Page {
                    ws: WebSocket::connect(ws),
                    next_id: 1,
                };
            }
            assert!(
                t0.elapsed() < Duration::from_secs(30),
                "no page at {url_prefix}: {list}"
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// A plain HTTP GET of `path` from `host:port`; the body. (Chromium
/// keeps the connection open whatever the request says: the body is read
/// by its length.)
fn http_get(host: &str, path: &str) -> String {
    let s = TcpStream::connect(host).expect("DevTools HTTP");
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    write!(&s, "GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
    let mut r = BufReader::new(s);
    let mut length = 0;
    loop {
        let mut line = String::new();
        r.read_line(&mut line).expect("DevTools HTTP answer");
        if line.trim().is_empty() {
            break;
        }
        if let Some((name, value)) = line.split_once(':') {
            if name.trim().eq_ignore_ascii_case("content-length") {
                length = value.trim().parse().expect("a length");
            }
        }
    }
    let mut body = vec![0u8; length];
    r.read_exact(&mut body).expect("DevTools HTTP body");
    String::from_utf8(body).expect("UTF-8")
}

/// A client WebSocket: text messages only, as CDP uses.
struct WebSocket {
    stream: TcpStream,
}

impl WebSocket {
    fn connect(url: &str) -> WebSocket {
        let rest = url.strip_prefix("ws://").expect("a ws:// URL");
        let (host, path) = rest.split_at(rest.find('/').unwrap_or(rest.len()));
        let mut stream = TcpStream::connect(host).expect("DevTools WebSocket");
        stream
            .set_read_timeout(Some(Duration::from_secs(60)))
            .unwrap();
        // The key is any 16 bytes in base64 (RFC 6455's example nonce).
        write!(
            stream,
            "GET {path} HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
        )
        .unwrap();
        let mut head = Vec::new();
        let mut byte = [0u8];
        while !head.ends_with(b"\r\n\r\n") {
            stream.read_exact(&mut byte).expect("handshake answer");
            head.push(byte[0]);
        }
        let head = String::from_utf8_lossy(&head);
        assert!(
            head.starts_with("HTTP/1.1 101"),
            "handshake refused: {head}"
        );
        // The accept key is RFC 6455's answer to the nonce above.
        assert!(head.contains("s3pPLMBiTxaQ9kYGzzhZRbK+xOo="), "{head}");
        WebSocket { stream }
    }

    fn send_frame(&mut self, opcode: u8, payload: &[u8]) {
        let mut f = vec![0x80 | opcode];
        let n = payload.len();
        if n < 126 {
            f.push(0x80 | n as u8);
        } else if n < 65536 {
            f.push(0x80 | 126);
            f.extend_from_slice(&(n as u16).to_be_bytes());
        } else {
            f.push(0x80 | 127);
            f.extend_from_slice(&(n as u64).to_be_bytes());
        }
        // Clients mask every frame; any key will do.
        let mask = [0x37, 0xfa, 0x21, 0x3d];
        f.extend_from_slice(&mask);
        f.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
        self.stream.write_all(&f).expect("WebSocket send");
    }

    fn send_text(&mut self, text: &str) {
        self.send_frame(0x1, text.as_bytes());
    }

    /// The next text message (fragments joined; pings answered).
    fn recv_text(&mut self) -> String {
        let mut message = Vec::new();
        loop {
            let mut h = [0u8; 2];
            self.stream.read_exact(&mut h).expect("WebSocket receive");
            let (fin, opcode) = (h[0] & 0x80 != 0, h[0] & 0x0f);
            let mut n = (h[1] & 0x7f) as u64;
            if n == 126 {
                let mut b = [0u8; 2];
                self.stream.read_exact(&mut b).unwrap();
                n = u16::from_be_bytes(b) as u64;
            } else if n == 127 {
                let mut b = [0u8; 8];
                self.stream.read_exact(&mut b).unwrap();
                n = u64::from_be_bytes(b);
            }
            let mask = if h[1] & 0x80 != 0 {
                let mut m = [0u8; 4];
                self.stream.read_exact(&mut m).unwrap();
                Some(m)
            } else {
                None
            };
            let mut payload = vec![0u8; n as usize];
            self.stream.read_exact(&mut payload).unwrap();
            if let Some(m) = mask {
                payload
                    .iter_mut()
                    .enumerate()
                    .for_each(|(i, b)| *b ^= m[i % 4]);
            }
            match opcode {
                0x0..=0x2 => {
                    message.extend_from_slice(&payload);
                    if fin {
                        return String::from_utf8(message).expect("UTF-8 message");
                    }
                }
                0x8 => panic!("the browser closed the DevTools connection"),
                0x9 => self.send_frame(0xA, &payload),
                _ => {}
            }
        }
    }
}

/// A page's DevTools session.
pub struct Page {
    ws: WebSocket,
    next_id: u64,
}

impl Page {
    /// Calls `method` and returns its result (events in between are
    /// dropped); a protocol error fails the test.
    pub fn call(&mut self, method: &str, params: Value) -> Value {
        match self.try_call(method, params) {
            Ok(v) => v,
            Err(reply) => panic!("{method}: {reply}"),
        }
    }

    /// Calls `method`: its result, or the whole reply when it is a
    /// protocol error (e.g. no execution context while a page loads).
    pub fn try_call(&mut self, method: &str, params: Value) -> Result<Value, Value> {
        let id = self.next_id;
        self.next_id += 1;
        let msg = json!({ "id": id, "method": method, "params": params });
        self.ws.send_text(&msg.to_string());
        loop {
            let reply: Value = serde_json::from_str(&self.ws.recv_text()).expect("CDP JSON");
            if reply["id"] == id {
                if reply.get("error").is_some() {
                    return Err(reply);
                }
                return Ok(reply["result"].clone());
            }
        }
    }

    /// Evaluates `expression` in the page (promises awaited); its value.
    pub fn eval(&mut self, expression: &str) -> Value {
        let r = self.call(
            "Runtime.evaluate",
            json!({ "expression": expression, "returnByValue": true, "awaitPromise": true }),
        );
        assert!(
            r.get("exceptionDetails").is_none(),
            "{expression} threw: {}",
            r["exceptionDetails"]
        );
        r["result"]["value"].clone()
    }

    /// Moves the mouse to `(x, y)` in the viewport's CSS pixels.
    pub fn mouse_move(&mut self, x: f64, y: f64) {
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": "mouseMoved", "x": x, "y": y }),
        );
    }

    /// Evaluates `expression` every 50 ms until `done` accepts its value
    /// (which is returned); fails with `what` after `timeout`.
    pub fn wait_for(
        &mut self,
        what: &str,
        timeout: Duration,
        expression: &str,
        done: impl Fn(&Value) -> bool,
    ) -> Value {
        let t0 = Instant::now();
        loop {
            // While a page (re)loads there may be no context to evaluate
            // in, or its script may not have run yet: poll again.
            let r = self.try_call(
                "Runtime.evaluate",
                json!({ "expression": expression, "returnByValue": true, "awaitPromise": true }),
            );
            let v = match r {
                Ok(r) if r.get("exceptionDetails").is_none() => r["result"]["value"].clone(),
                Ok(r) => r["exceptionDetails"].clone(),
                Err(reply) => reply,
            };
            if done(&v) {
                return v;
            }
            assert!(
                t0.elapsed() < timeout,
                "timed out waiting for {what}; last: {v}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}
