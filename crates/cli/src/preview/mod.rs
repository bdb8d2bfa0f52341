//! `--preview`: a live view of the render in the browser. A small HTTP
//! server (standard library only: a few GET routes, one short-lived
//! thread per connection, `Connection: close`) serves
//!
//! - `/`: the page ([`PAGE`]), which polls `/status` four times a second,
//!   fetches `/image` when a newer snapshot is there, and tone-maps it
//!   into a canvas itself (exposure, linear / sRGB / ACES-like), shows the
//!   film's float value under the cursor, progress and ETA, and saves the
//!   image (PNG as shown, PFM as the film's floats) without the server;
//! - `/status`: JSON: the snapshot's number, size and samples per pixel,
//!   whether it is the final image, the progress and the ETA (with
//!   `?after=N`, answered once a snapshot newer than N is there, or after
//!   [`LONG_POLL`]; `--interactive` adds the camera);
//! - `/image`: the latest snapshot, [`IMAGE_HEADER`] bytes of header then
//!   RGB `f32` values (see [`encode_image`]), and in an `X-Rpbrt-Camera`
//!   header the number of the camera it was rendered from;
//! - `POST /camera` (`--interactive` only): a JSON change to the camera
//!   ([`camera::parse_op`]), from the page's own origin; answered with the
//!   camera's JSON, or a 4xx and the reason.
//!
//! Connections are limited so that slow or many clients cannot lock the
//! page out (see [`Limits`]): the whole request head must arrive within
//! a deadline of the accept however its bytes are paced, one client
//! holds only a share of the slots, and some slots are kept for clients
//! holding none. Each snapshot is encoded once for all the requests
//! sending it, and slow readers hold at most [`MAX_IMAGE_BUFFERS`]
//! encodings alive.
//!
//! It stays std-only on purpose: a few small routes, plus the limits above.
//! tiny_http offers neither a head deadline nor per-client shares, and
//! hyper (which has a head timeout) would bring an async runtime along;
//! either would still need the per-client accounting written here.
//!
//! The server is stateless towards the browser, so a page closed and
//! reopened mid-render picks up where the render is. It binds to loopback
//! unless given another address, and then refuses requests whose `Host`
//! is not a loopback name (DNS rebinding). When the render ends the
//! process waits (at most [`FINAL_GRACE`]) until a page that was watching
//! has the final image, then exits: the page keeps showing it and can
//! still save it.

mod camera;

pub use camera::{CameraControl, CameraDirective};

use crate::watch::{Frame, Watch};
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{IpAddr, Ipv6Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The page.
pub const PAGE: &str = include_str!("page.html");
/// Size of the `/image` header: `RPV1`, then width, height, channels
/// (3), samples per pixel, a done flag (1: the final image) as `u32`, and
/// the snapshot's number as `u64`, all little-endian.
pub const IMAGE_HEADER: usize = 32;
/// How long the process waits after the render for a watching page to
/// fetch the final image.
pub const FINAL_GRACE: Duration = Duration::from_secs(5);
/// Longest request head read.
const MAX_HEAD: usize = 16 * 1024;
/// How long one write of the answer may wait for the client to read.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(10);
/// Most encoded `/image` answers alive at once. Requests for one
/// snapshot share its encoding; when slow readers still hold this many
/// (older snapshots), a request gets the newest of them rather than
/// another copy, so memory stays at the frame plus this many encodings
/// however many clients read slowly.
const MAX_IMAGE_BUFFERS: usize = 2;
/// Longest `/camera` request body.
const MAX_BODY: usize = 4096;
/// Longest a `/status?after=N` request waits for a newer snapshot.
const LONG_POLL: Duration = Duration::from_secs(1);
/// What a request head that missed [`Limits::head_deadline`] is told.
const HEAD_TOO_SLOW: &str = "request head not received in time";

/// How many connections are served, to whom, and for how long a request
/// head may trickle in. A connection over a limit is closed unanswered.
#[derive(Clone, Copy, Debug)]
struct Limits {
    /// Most connections served at once.
    connections: usize,
    /// Most connections one client (an IPv4 address, an IPv6 /64: what one
    /// host commonly has) holds at once. A browser opens a few per page.
    per_client: usize,
    /// Of `connections`, those only a client holding none may take: clients
    /// that filled their shares still leave room for a newcomer.
    reserved: usize,
    /// How long after the accept the whole request head must have arrived.
    /// A per-read timeout alone lets a client that sends a byte now and
    /// then hold its slot for ever (slowloris).
    head_deadline: Duration,
}

impl Limits {
    /// A browser sends its head at once; a few seconds allow for a slow
    /// link. 8 connections per client is more than a page uses (it polls
    /// one request at a time) and leaves 24 unreserved slots for others.
    const DEFAULT: Limits = Limits {
        connections: 32,
        per_client: 8,
        reserved: 8,
        head_deadline: Duration::from_secs(5),
    };
}

/// Why the server could not start.
#[derive(Debug)]
pub struct StartError(pub String);

impl std::fmt::Display for StartError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// The running server.
pub struct Preview {
    addr: SocketAddr,
    shared: Arc<Shared>,
}

/// What the connection threads share.
struct Shared {
    watch: Arc<Watch>,
    port: u16,
    /// Only loopback `Host`s are served.
    loopback: bool,
    /// Set once `/image` served the final image, and once `/status`
    /// said the render had finished.
    final_image_served: AtomicBool,
    final_status_served: AtomicBool,
    limits: Limits,
    /// Connections being served: in all, and per client (see
    /// [`client_key`]).
    clients: Mutex<Clients>,
    /// The encoded snapshots being sent (see [`MAX_IMAGE_BUFFERS`]).
    images: Mutex<Images>,
    /// `/denoised`: Open Image Denoise, loaded on the first request, and
    /// the latest denoised snapshot (denoised once per version; requests
    /// wait on the lock, so one denoise runs at a time).
    denoiser: Mutex<Denoiser>,
    /// `--interactive`: the camera the page moves (`None` until the scene
    /// is loaded, and in a render that is not interactive).
    control: Mutex<Option<CameraControl>>,
    /// The reasons camera requests were refused for, each logged once.
    refused: Mutex<std::collections::HashSet<String>>,
}

/// What `/denoised` keeps between requests.
#[derive(Default)]
struct Denoiser {
    oidn: Option<Result<crate::oidn::Oidn, String>>,
    latest: Option<Encoded>,
}

/// A snapshot encoded for `/image`, shared by every request sending it.
#[derive(Clone, Debug)]
struct Encoded {
    version: u64,
    done: bool,
    /// The camera the snapshot was rendered from.
    camera: u64,
    bytes: Arc<Vec<u8>>,
}

/// The encoded snapshots alive: the latest, and those still being sent.
#[derive(Debug, Default)]
struct Images {
    live: Vec<Encoded>,
    /// Snapshots encoded so far (one per version, unless readers made
    /// some skip).
    encodes: u64,
}

/// The connections being served.
#[derive(Debug, Default)]
struct Clients {
    total: usize,
    per_client: HashMap<IpAddr, usize>,
}

/// A claimed connection slot, given back when dropped (also when the
/// connection's thread panics).
struct Slot {
    shared: Arc<Shared>,
    client: IpAddr,
}

impl Drop for Slot {
    fn drop(&mut self) {
        let mut c = self.shared.clients();
        c.total -= 1;
        if let Some(n) = c.per_client.get_mut(&self.client) {
            *n -= 1;
            if *n == 0 {
                c.per_client.remove(&self.client);
            }
        }
    }
}

/// The key connections are counted under: the IPv4 address (IPv4-mapped
/// IPv6 ones included), or the /64 of an IPv6 one, since a host is
/// commonly given a whole /64 and could otherwise pose as many clients.
fn client_key(ip: IpAddr) -> IpAddr {
    match ip {
        IpAddr::V4(_) => ip,
        IpAddr::V6(v6) => match v6.to_ipv4_mapped() {
            Some(v4) => IpAddr::V4(v4),
            None => {
                let s = v6.segments();
                IpAddr::V6(Ipv6Addr::new(s[0], s[1], s[2], s[3], 0, 0, 0, 0))
            }
        },
    }
}

impl Shared {
    fn control(&self) -> std::sync::MutexGuard<'_, Option<CameraControl>> {
        self.control.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Logs a refused camera request's reason, the first time it is seen.
    fn refuse(&self, why: &str) {
        let mut seen = self.refused.lock().unwrap_or_else(|e| e.into_inner());
        if seen.len() < 100 && seen.insert(why.to_string()) {
            diagln!("rpbrt: refused a camera request: {why}");
        }
    }

    /// `POST /camera`: applies the request's change to the camera and
    /// hands the camera to the render; the camera's JSON, or the status
    /// and reason of a refusal.
    fn camera_request(&self, body: &[u8]) -> Result<String, (&'static str, String)> {
        let bad = |why: String| ("400 Bad Request", why);
        let mut control = self.control();
        let Some(c) = control.as_mut() else {
            return Err((
                "404 Not Found",
                "not an interactive render (start rpbrt with --interactive)".into(),
            ));
        };
        let op = camera::parse_op(body).map_err(bad)?;
        let change = c.apply(op).map_err(bad)?;
        self.watch.propose_camera(change);
        Ok(c.json())
    }

    fn clients(&self) -> std::sync::MutexGuard<'_, Clients> {
        self.clients.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The latest snapshot denoised (from its colour alone: a snapshot has
    /// no albedo or normal) and encoded as `/image` encodes it; `None`
    /// before the first snapshot, `Some(Err)` without Open Image Denoise.
    fn denoised(&self) -> Option<Result<Encoded, String>> {
        let frame = self.watch.state().frame.clone()?;
        let mut d = self.denoiser.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = d.latest.as_ref().filter(|e| e.version == frame.version) {
            return Some(Ok(e.clone()));
        }
        let oidn = match d.oidn.get_or_insert_with(crate::oidn::Oidn::load) {
            Ok(o) => o,
            Err(e) => return Some(Err(e.clone())),
        };
        let s = &frame.snapshot;
        let mut rgb = s.rgb.clone();
        crate::imgtool::denoise::zero_non_finite(&mut rgb);
        let out = oidn.denoise(crate::oidn::Inputs {
            width: s.width,
            height: s.height,
            color: &rgb,
            albedo: None,
            normal: None,
            quality: crate::oidn::Quality::High,
            prefilter: false,
        });
        let rgb = match out {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        let denoised = Frame {
            version: frame.version,
            snapshot: rpbrt_render::integrator::Snapshot {
                width: s.width,
                height: s.height,
                rgb,
                spp: s.spp,
                done: s.done,
                camera: s.camera,
            },
        };
        let e = Encoded {
            version: frame.version,
            done: frame.snapshot.done,
            camera: frame.snapshot.camera,
            bytes: Arc::new(encode_image(&denoised)),
        };
        d.latest = Some(e.clone());
        Some(Ok(e))
    }

    /// The latest snapshot encoded for `/image` (see
    /// [`MAX_IMAGE_BUFFERS`]), or `None` before the first one.
    fn image(&self) -> Option<Encoded> {
        let frame = self.watch.state().frame.clone()?;
        let mut im = self.images.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = im.live.iter().find(|e| e.version == frame.version) {
            return Some(e.clone());
        }
        // Encodings only this cache holds are sent by nobody: let them go.
        // (Counts only fall outside the lock, so this never drops one in use.)
        im.live.retain(|e| Arc::strong_count(&e.bytes) > 1);
        if im.live.len() >= MAX_IMAGE_BUFFERS {
            return im.live.iter().max_by_key(|e| e.version).cloned();
        }
        let e = Encoded {
            version: frame.version,
            done: frame.snapshot.done,
            camera: frame.snapshot.camera,
            bytes: Arc::new(encode_image(&frame)),
        };
        im.encodes += 1;
        im.live.push(e.clone());
        Some(e)
    }

    /// A slot for a connection from `peer`, or `None` when the limits
    /// say to close it.
    fn claim(self: &Arc<Self>, peer: IpAddr) -> Option<Slot> {
        let client = client_key(peer);
        let l = self.limits;
        let mut c = self.clients();
        let held = c.per_client.get(&client).copied().unwrap_or(0);
        let room = if held == 0 {
            l.connections
        } else {
            l.connections.saturating_sub(l.reserved)
        };
        if held >= l.per_client || c.total >= room {
            return None;
        }
        c.total += 1;
        *c.per_client.entry(client).or_insert(0) += 1;
        Some(Slot {
            shared: Arc::clone(self),
            client,
        })
    }
}

impl Preview {
    /// Binds `addr` and serves `watch` from a thread of its own.
    pub fn start(addr: SocketAddr, watch: Arc<Watch>) -> Result<Self, StartError> {
        Self::start_with(addr, watch, Limits::DEFAULT)
    }

    fn start_with(addr: SocketAddr, watch: Arc<Watch>, limits: Limits) -> Result<Self, StartError> {
        let listener = TcpListener::bind(addr).map_err(|e| {
            StartError(match e.kind() {
                std::io::ErrorKind::AddrInUse => format!(
                    "--preview: {addr} is already in use; give another port, or none for a \
                     free one"
                ),
                std::io::ErrorKind::AddrNotAvailable => {
                    format!("--preview: {addr} is not an address of this machine")
                }
                _ => format!("--preview: cannot listen on {addr}: {e}"),
            })
        })?;
        let addr = listener
            .local_addr()
            .map_err(|e| StartError(format!("--preview: {e}")))?;
        // A page opened mid-render is served the latest wave's end at once.
        watch.keep_wave_ends();
        let shared = Arc::new(Shared {
            watch,
            port: addr.port(),
            loopback: addr.ip().is_loopback(),
            final_image_served: AtomicBool::new(false),
            final_status_served: AtomicBool::new(false),
            limits,
            clients: Mutex::new(Clients::default()),
            denoiser: Mutex::new(Denoiser::default()),
            images: Mutex::new(Images::default()),
            control: Mutex::new(None),
            refused: Mutex::new(Default::default()),
        });
        let s = Arc::clone(&shared);
        std::thread::spawn(move || accept_loop(listener, s));
        Ok(Preview { addr, shared })
    }

    /// Lets the page move the camera (`--interactive`): requests to
    /// `/camera` change `control`, and the render takes the cameras from
    /// the watch.
    pub fn set_camera_control(&self, control: CameraControl) {
        self.shared.watch.set_interactive();
        *self.shared.control() = Some(control);
    }

    /// The address served.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// After the render (the watch finished): waits until a page that was
    /// watching has the final image and knows the render has ended, at
    /// most [`FINAL_GRACE`]. Returns at once when nobody watches.
    pub fn linger(&self) {
        let t0 = Instant::now();
        while t0.elapsed() < FINAL_GRACE && self.shared.watch.viewer_recent() {
            let has_frame = self.shared.watch.state().frame.is_some();
            let image = self.shared.final_image_served.load(Ordering::Relaxed) || !has_frame;
            if image && self.shared.final_status_served.load(Ordering::Relaxed) {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

fn accept_loop(listener: TcpListener, shared: Arc<Shared>) {
    for stream in listener.incoming() {
        let accepted = Instant::now();
        let Ok(stream) = stream else {
            // Out of descriptors and the like: let it pass.
            std::thread::sleep(Duration::from_millis(10));
            continue;
        };
        let Ok(peer) = stream.peer_addr() else {
            continue;
        };
        let Some(slot) = shared.claim(peer.ip()) else {
            continue;
        };
        let deadline = accepted + shared.limits.head_deadline;
        // A failed spawn drops the closure, and the slot with it.
        let _ = std::thread::Builder::new()
            .name("preview-http".into())
            .spawn(move || {
                // Errors are the client's going away: nothing to report.
                let _ = serve(stream, deadline, &slot.shared);
                drop(slot);
            });
    }
}

/// Reads a connection until a deadline, however the bytes are paced:
/// each read waits only for what is left of the time.
struct DeadlineReader<'a> {
    stream: &'a TcpStream,
    deadline: Instant,
}

impl Read for DeadlineReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self.deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(std::io::ErrorKind::TimedOut.into());
        }
        self.stream.set_read_timeout(Some(left))?;
        self.stream.read(buf)
    }
}

/// A parsed request head.
#[derive(Debug, Default, PartialEq)]
struct Request {
    method: String,
    path: String,
    /// What follows `?` in the target (without the fragment).
    query: String,
    host: Option<String>,
    /// `Origin`, `Content-Type` and `Content-Length`, when sent.
    origin: Option<String>,
    content_type: Option<String>,
    content_length: Option<String>,
}

/// Reads a request head (request line and headers) of at most
/// [`MAX_HEAD`] bytes.
fn read_request(r: &mut impl BufRead) -> Result<Request, &'static str> {
    let mut head = Vec::new();
    loop {
        let before = head.len();
        let limit = (MAX_HEAD - head.len()) as u64 + 1;
        let n = std::io::Read::take(&mut *r, limit)
            .read_until(b'\n', &mut head)
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock => HEAD_TOO_SLOW,
                _ => "unreadable request",
            })?;
        if n == 0 {
            return Err("incomplete request");
        }
        if head.len() > MAX_HEAD {
            return Err("request head too large");
        }
        let line = &head[before..];
        if line == b"\r\n" || line == b"\n" {
            break;
        }
    }
    let text = std::str::from_utf8(&head).map_err(|_| "request is not text")?;
    let mut lines = text.lines();
    let mut first = lines.next().unwrap_or("").split_whitespace();
    let (Some(method), Some(target), Some(version)) = (first.next(), first.next(), first.next())
    else {
        return Err("malformed request line");
    };
    if !version.starts_with("HTTP/1.") {
        return Err("unsupported HTTP version");
    }
    let mut req = Request {
        method: method.to_string(),
        ..Request::default()
    };
    for l in lines {
        let Some((name, value)) = l.split_once(':') else {
            continue;
        };
        let slot = match name.trim().to_ascii_lowercase().as_str() {
            "host" => &mut req.host,
            "origin" => &mut req.origin,
            "content-type" => &mut req.content_type,
            "content-length" => &mut req.content_length,
            _ => continue,
        };
        if slot.is_none() {
            *slot = Some(value.trim().to_string());
        }
    }
    let target = target.split('#').next().unwrap_or("/");
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    req.path = path.to_string();
    req.query = query.to_string();
    Ok(req)
}

/// Whether a `Host` header names this machine's loopback at `port`.
fn loopback_host(host: &str, port: u16) -> bool {
    let (name, rest) = match host.strip_prefix('[') {
        Some(v6) => match v6.split_once(']') {
            Some((name, rest)) => (name, rest),
            None => return false,
        },
        None => match host.rsplit_once(':') {
            Some((name, _)) => (name, &host[name.len()..]),
            None => (host, ""),
        },
    };
    let port_ok = match rest.strip_prefix(':') {
        Some(p) => p.parse::<u16>() == Ok(port),
        None => rest.is_empty() && port == 80,
    };
    port_ok
        && (name.eq_ignore_ascii_case("localhost")
            || name
                .parse::<std::net::IpAddr>()
                .is_ok_and(|ip| ip.is_loopback()))
}

fn respond(
    w: &mut impl Write,
    status: &str,
    content_type: &str,
    body: &[u8],
    head_only: bool,
) -> std::io::Result<()> {
    respond_with(w, status, content_type, body, head_only, "")
}

/// [`respond`] with `extra` header lines (each ending in CRLF).
fn respond_with(
    w: &mut impl Write,
    status: &str,
    content_type: &str,
    body: &[u8],
    head_only: bool,
    extra: &str,
) -> std::io::Result<()> {
    write!(
        w,
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n{extra}Connection: close\r\n\r\n",
        body.len()
    )?;
    if !head_only {
        w.write_all(body)?;
    }
    w.flush()
}

/// Answers one request on `stream`, whose head must have arrived by
/// `deadline`.
fn serve(stream: TcpStream, deadline: Instant, shared: &Shared) -> std::io::Result<()> {
    stream.set_write_timeout(Some(CLIENT_TIMEOUT))?;
    let mut reader = BufReader::new(DeadlineReader {
        stream: &stream,
        deadline,
    });
    let req = read_request(&mut reader);
    let mut out = std::io::BufWriter::new(&stream);
    let text = "text/plain; charset=utf-8";
    let req = match req {
        Ok(r) => r,
        Err(HEAD_TOO_SLOW) => {
            let why = HEAD_TOO_SLOW.as_bytes();
            return respond(&mut out, "408 Request Timeout", text, why, false);
        }
        Err(why) => return respond(&mut out, "400 Bad Request", text, why.as_bytes(), false),
    };
    if shared.loopback
        && !req
            .host
            .as_deref()
            .is_some_and(|h| loopback_host(h, shared.port))
    {
        let why = b"this server answers only requests addressed to the loopback interface";
        return respond(&mut out, "403 Forbidden", text, why, false);
    }
    if req.method == "POST" && req.path == "/camera" {
        return match camera_post(&req, &mut reader, shared) {
            Ok(json) => respond(
                &mut out,
                "200 OK",
                "application/json",
                json.as_bytes(),
                false,
            ),
            Err((status, why)) => {
                shared.refuse(&why);
                respond(&mut out, status, text, why.as_bytes(), false)
            }
        };
    }
    let head_only = req.method == "HEAD";
    if req.method != "GET" && !head_only {
        return respond(&mut out, "405 Method Not Allowed", text, b"GET only", false);
    }
    match req.path.as_str() {
        "/" | "/index.html" => respond(
            &mut out,
            "200 OK",
            "text/html; charset=utf-8",
            PAGE.as_bytes(),
            head_only,
        ),
        "/status" => {
            shared.watch.viewer_seen();
            // `?after=N`: answered once there is a snapshot newer than N
            // (or the render ended), or after LONG_POLL.
            let after = req
                .query
                .split('&')
                .find_map(|kv| kv.strip_prefix("after="))
                .and_then(|v| v.parse::<u64>().ok());
            let (json, finished) = {
                let s = match after {
                    Some(v) => shared.watch.wait_newer(v, LONG_POLL),
                    None => shared.watch.state(),
                };
                // Read after the wait: the camera as of the answer.
                let camera = shared.control().as_ref().map(CameraControl::json);
                let mut json = status_json(&s, std::process::id());
                if let Some(c) = camera {
                    // The camera and the one the snapshot was rendered from.
                    let from = s.frame.as_ref().map_or(0, |f| f.snapshot.camera);
                    json.pop();
                    json += &format!(",\"camera\":{c},\"frame_camera\":{from}}}");
                }
                (json, s.finished)
            };
            respond(
                &mut out,
                "200 OK",
                "application/json",
                json.as_bytes(),
                head_only,
            )?;
            if finished && !head_only {
                shared.final_status_served.store(true, Ordering::Relaxed);
            }
            Ok(())
        }
        "/image" => {
            shared.watch.viewer_seen();
            match shared.image() {
                Some(e) => {
                    let body = e.bytes.as_slice();
                    respond_with(
                        &mut out,
                        "200 OK",
                        "application/octet-stream",
                        body,
                        head_only,
                        &format!("X-Rpbrt-Camera: {}\r\n", e.camera),
                    )?;
                    if e.done && !head_only {
                        shared.final_image_served.store(true, Ordering::Relaxed);
                    }
                    Ok(())
                }
                None => respond(&mut out, "404 Not Found", text, b"no image yet", head_only),
            }
        }
        "/denoised" => {
            shared.watch.viewer_seen();
            match shared.denoised() {
                Some(Ok(e)) => respond(
                    &mut out,
                    "200 OK",
                    "application/octet-stream",
                    e.bytes.as_slice(),
                    head_only,
                ),
                Some(Err(why)) => respond(
                    &mut out,
                    "503 Service Unavailable",
                    text,
                    why.as_bytes(),
                    head_only,
                ),
                None => respond(&mut out, "404 Not Found", text, b"no image yet", head_only),
            }
        }
        "/favicon.ico" => respond(&mut out, "204 No Content", text, b"", true),
        _ => respond(&mut out, "404 Not Found", text, b"not found", head_only),
    }
}

/// Checks and reads a `POST /camera` request: same origin only (a page
/// from elsewhere may not move the camera: its `Origin` differs, and its
/// JSON content type needs a CORS preflight this server never grants), a
/// JSON body of at most [`MAX_BODY`] bytes within the head's deadline.
fn camera_post(
    req: &Request,
    reader: &mut impl Read,
    shared: &Shared,
) -> Result<String, (&'static str, String)> {
    if let Some(origin) = &req.origin {
        let own = req.host.as_deref().map(|h| format!("http://{h}"));
        if own.as_deref() != Some(origin.as_str()) {
            return Err((
                "403 Forbidden",
                format!("requests from {origin} may not move the camera"),
            ));
        }
    }
    let json = req.content_type.as_deref().is_some_and(|t| {
        t.split(';')
            .next()
            .is_some_and(|m| m.trim().eq_ignore_ascii_case("application/json"))
    });
    if !json {
        return Err((
            "415 Unsupported Media Type",
            "the body must be application/json".into(),
        ));
    }
    let len = req
        .content_length
        .as_deref()
        .and_then(|v| v.parse::<usize>().ok())
        .ok_or((
            "411 Length Required",
            "Content-Length is missing or not a number".to_string(),
        ))?;
    if len > MAX_BODY {
        return Err((
            "413 Payload Too Large",
            format!("the body is over {MAX_BODY} bytes"),
        ));
    }
    let mut body = vec![0; len];
    reader.read_exact(&mut body).map_err(|_| {
        (
            "408 Request Timeout",
            "the body did not arrive in time".to_string(),
        )
    })?;
    shared.camera_request(&body)
}

/// `/image`'s bytes for a frame: the [`IMAGE_HEADER`]-byte header, then
/// `3 × width × height` little-endian `f32`s, rows from the top.
pub fn encode_image(f: &Frame) -> Vec<u8> {
    let s = &f.snapshot;
    let mut b = Vec::with_capacity(IMAGE_HEADER + 4 * s.rgb.len());
    b.extend_from_slice(b"RPV1");
    for v in [
        s.width as u32,
        s.height as u32,
        3,
        s.spp.max(0) as u32,
        s.done as u32,
    ] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&f.version.to_le_bytes());
    for v in &s.rgb {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

/// A JSON string literal.
fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 || c == '<' || c == '>' => {
                out.push_str(&format!("\\u{:04x}", c as u32))
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `/status`'s JSON for the watch's state.
fn status_json(s: &crate::watch::State, id: u32) -> String {
    let (version, width, height, spp, done) = match &s.frame {
        Some(f) => (
            f.version,
            f.snapshot.width,
            f.snapshot.height,
            f.snapshot.spp,
            f.snapshot.done,
        ),
        None => (0, 0, 0, 0, false),
    };
    let (work_done, total, elapsed) = s
        .progress
        .map_or((0, 0, 0.0), |p| (p.done, p.total, p.elapsed.as_secs_f64()));
    let frac = if total > 0 {
        work_done as f64 / total as f64
    } else {
        0.0
    };
    let eta = if frac > 0.0 && !s.finished {
        format!("{:.3}", elapsed / frac - elapsed)
    } else if s.finished {
        "0".to_string()
    } else {
        "null".to_string()
    };
    format!(
        "{{\"id\":{id},\"title\":{},\"version\":{version},\"width\":{width},\
         \"height\":{height},\"spp\":{spp},\"done\":{done},\"finished\":{},\
         \"progress\":{{\"done\":{work_done},\"total\":{total},\"fraction\":{frac:.6},\
         \"elapsed\":{elapsed:.3},\"eta\":{eta}}}}}",
        json_string(&s.title),
        s.finished
    )
}

#[cfg(test)]
mod tests;
