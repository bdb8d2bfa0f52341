//! Tests of the preview server: request parsing, the Host check, the
//! image encoding and the status, and the routes over a real socket.

use super::*;
use rpbrt_render::integrator::{Progress, RenderObserver, Snapshot};
use std::io::Read;
use std::sync::atomic::{AtomicBool, Ordering};

fn get(addr: SocketAddr, path: &str, host: &str) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nUser-Agent: test\r\n\r\n"
    )
    .unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8(all[..split].to_vec()).unwrap();
    let body = all[split + 4..].to_vec();
    let len: usize = head
        .lines()
        .find_map(|l| l.strip_prefix("Content-Length: "))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(len, body.len(), "{head}");
    (head, body)
}

#[test]
fn request_heads_are_parsed_with_limits() {
    let mut r = "GET /status?x=1 HTTP/1.1\r\nhOsT:  127.0.0.1:80 \r\n\r\nrest".as_bytes();
    assert_eq!(
        read_request(&mut r),
        Ok(Request {
            method: "GET".into(),
            path: "/status".into(),
            query: "x=1".into(),
            host: Some("127.0.0.1:80".into()),
            ..Request::default()
        })
    );
    assert!(read_request(&mut "GET / HTTP/1.1\r\nHost: x".as_bytes()).is_err());
    assert!(read_request(&mut "NONSENSE\r\n\r\n".as_bytes()).is_err());
    assert!(read_request(&mut "GET / SPDY/9\r\n\r\n".as_bytes()).is_err());
    let huge = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
    assert_eq!(
        read_request(&mut huge.as_bytes()),
        Err("request head too large")
    );
}

#[test]
fn only_loopback_hosts_pass() {
    for ok in [
        "127.0.0.1:8000",
        "localhost:8000",
        "LOCALHOST:8000",
        "[::1]:8000",
        "127.1.2.3:8000",
    ] {
        assert!(loopback_host(ok, 8000), "{ok}");
    }
    for bad in [
        "evil.example:8000",
        "127.0.0.1:8001",
        "127.0.0.1",
        "[::1]",
        "10.0.0.1:8000",
        "[::1:8000",
        "",
    ] {
        assert!(!loopback_host(bad, 8000), "{bad}");
    }
    assert!(loopback_host("localhost", 80));
}

fn frame(version: u64, done: bool) -> Frame {
    Frame {
        version,
        snapshot: Snapshot {
            width: 2,
            height: 1,
            rgb: vec![0.0, 0.5, 1.0, 2.0, -1.0, f32::INFINITY],
            spp: 16,
            done,
            camera: 0,
        },
    }
}

#[test]
fn images_are_a_header_and_little_endian_floats() {
    let b = encode_image(&frame(7, true));
    assert_eq!(b.len(), IMAGE_HEADER + 6 * 4);
    assert_eq!(&b[..4], b"RPV1");
    let u32_at = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    assert_eq!(
        [u32_at(4), u32_at(8), u32_at(12), u32_at(16), u32_at(20)],
        [2, 1, 3, 16, 1]
    );
    assert_eq!(u64::from_le_bytes(b[24..32].try_into().unwrap()), 7);
    assert_eq!(f32::from_le_bytes(b[44..48].try_into().unwrap()), 2.0);
}

#[test]
fn status_reports_progress_and_eta() {
    let mut s = crate::watch::State {
        title: "a \"b\".exr".into(),
        ..Default::default()
    };
    let j = status_json(&s, 5);
    assert!(
        j.starts_with("{\"id\":5,\"title\":\"a \\\"b\\\".exr\",\"version\":0,"),
        "{j}"
    );
    assert!(j.contains("\"eta\":null"), "{j}");
    s.progress = Some(Progress {
        done: 25,
        total: 100,
        elapsed: Duration::from_secs(3),
    });
    s.frame = Some(Arc::new(frame(3, false)));
    s.title = "x</script>".into();
    let j = status_json(&s, 5);
    assert!(j.contains("\"title\":\"x\\u003c/script\\u003e\""), "{j}");
    assert!(
        j.contains(
            "\"version\":3,\"width\":2,\"height\":1,\"spp\":16,\"done\":false,\"finished\":false"
        ),
        "{j}"
    );
    assert!(
        j.contains("\"fraction\":0.250000,\"elapsed\":3.000,\"eta\":9.000}"),
        "{j}"
    );
}

#[test]
fn routes_over_a_socket() {
    let watch = Arc::new(Watch::new());
    let p = Preview::start("127.0.0.1:0".parse().unwrap(), Arc::clone(&watch)).unwrap();
    let addr = p.addr();
    assert!(p.url().starts_with("http://127.0.0.1:") && addr.port() != 0);
    let host = format!("127.0.0.1:{}", addr.port());
    let (head, body) = get(addr, "/", &host);
    assert!(
        head.starts_with("HTTP/1.1 200 OK") && head.contains("text/html"),
        "{head}"
    );
    assert_eq!(body, PAGE.as_bytes());
    // No image yet; asking makes a viewer, so snapshots become wanted.
    assert!(!watch.wants_image(false));
    let (head, _) = get(addr, "/image", &host);
    assert!(head.starts_with("HTTP/1.1 404"), "{head}");
    assert!(watch.wants_image(false));
    watch.image(frame(1, false).snapshot);
    let (head, body) = get(addr, "/image", &host);
    assert!(head.contains("application/octet-stream"), "{head}");
    assert_eq!(
        body,
        encode_image(&Frame {
            version: 1,
            ..frame(1, false)
        })
    );
    let (_, body) = get(addr, "/status", &host);
    let j = String::from_utf8(body).unwrap();
    assert!(
        j.contains("\"version\":1,") && j.contains("\"finished\":false"),
        "{j}"
    );
    // Elsewhere: not found; another Host: refused.
    assert!(get(addr, "/nope", &host).0.starts_with("HTTP/1.1 404"));
    assert!(get(addr, "/", &format!("rebound.example:{}", addr.port()))
        .0
        .starts_with("HTTP/1.1 403"));
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "POST / HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
    let mut r = String::new();
    s.read_to_string(&mut r).unwrap();
    assert!(r.starts_with("HTTP/1.1 405"), "{r}");

    // The end: linger returns once the page has the final image and status.
    watch.image(frame(2, true).snapshot);
    watch.finish();
    let t0 = Instant::now();
    let watcher = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        get(addr, "/status", &host);
        get(addr, "/image", &host);
    });
    p.linger();
    assert!(t0.elapsed() >= Duration::from_millis(200) && t0.elapsed() < FINAL_GRACE);
    watcher.join().unwrap();
}

#[test]
fn a_port_in_use_is_a_clear_error() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let e = Preview::start(addr, Arc::new(Watch::new())).err().unwrap();
    assert!(
        e.0.contains("already in use") && e.0.contains(&addr.to_string()),
        "{e}"
    );
}

/// A connection to `to` from the loopback address `from` (Linux routes
/// all of 127/8 to loopback). std's `TcpStream` cannot bind before it
/// connects, so the socket is made with libc and handed to std.
#[cfg(target_os = "linux")]
fn connect_from(from: std::net::Ipv4Addr, to: SocketAddr) -> TcpStream {
    use std::os::fd::FromRawFd;
    let SocketAddr::V4(to) = to else {
        panic!("an IPv4 server")
    };
    let sockaddr = |ip: std::net::Ipv4Addr, port: u16| libc::sockaddr_in {
        sin_family: libc::AF_INET as libc::sa_family_t,
        sin_port: port.to_be(),
        sin_addr: libc::in_addr {
            s_addr: u32::from(ip).to_be(),
        },
        sin_zero: [0; 8],
    };
    let len = std::mem::size_of::<libc::sockaddr_in>() as libc::socklen_t;
    // SAFETY: a fresh socket owned by the TcpStream at once; the addresses
    // are valid sockaddr_in values of the length given.
    unsafe {
        let fd = libc::socket(libc::AF_INET, libc::SOCK_STREAM | libc::SOCK_CLOEXEC, 0);
        assert!(fd >= 0, "{}", std::io::Error::last_os_error());
        let stream = TcpStream::from_raw_fd(fd);
        let local = sockaddr(from, 0);
        let r = libc::bind(fd, (&local as *const libc::sockaddr_in).cast(), len);
        assert_eq!(r, 0, "{}", std::io::Error::last_os_error());
        let remote = sockaddr(*to.ip(), to.port());
        let r = libc::connect(fd, (&remote as *const libc::sockaddr_in).cast(), len);
        assert_eq!(r, 0, "{}", std::io::Error::last_os_error());
        stream
    }
}

/// Slowloris: 40 connections from 127.0.0.1 send a request head a byte
/// at a time. They get at most their client's share of the slots, so a
/// page from another address (127.0.0.2, bound with libc: see
/// [`connect_from`]) still loads at once; the head deadline, tested on
/// its own below, frees even that share after a few seconds.
#[cfg(target_os = "linux")]
#[test]
fn preview_slowloris_leaves_the_page_loading() {
    let p = Preview::start("127.0.0.1:0".parse().unwrap(), Arc::new(Watch::new())).unwrap();
    let addr = p.addr();
    let host = format!("127.0.0.1:{}", addr.port());
    let attackers: Vec<TcpStream> = (0..40)
        .map(|_| {
            let mut s = TcpStream::connect(addr).unwrap();
            let _ = s.write_all(b"GET / HTTP/1.1\r\n");
            s
        })
        .collect();
    let stop = Arc::new(AtomicBool::new(false));
    let dribbler = {
        let stop = Arc::clone(&stop);
        let mut conns: Vec<TcpStream> = attackers.iter().map(|s| s.try_clone().unwrap()).collect();
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                for s in &mut conns {
                    let _ = s.write_all(b"X");
                }
                std::thread::sleep(Duration::from_millis(100));
            }
        })
    };
    // Let the server take in all the attackers it will.
    let t0 = Instant::now();
    let mut last = (0, Instant::now());
    while t0.elapsed() < Duration::from_secs(1) && last.1.elapsed() < Duration::from_millis(200) {
        let n = p.shared.clients().total;
        if n != last.0 {
            last = (n, Instant::now());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        last.0 <= Limits::DEFAULT.per_client,
        "{} slots held",
        last.0
    );

    let t0 = Instant::now();
    let mut s = connect_from([127, 0, 0, 2].into(), addr);
    s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    write!(s, "GET / HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
    let mut all = Vec::new();
    let r = s.read_to_end(&mut all);
    assert!(r.is_ok(), "{r:?} after {:?}", t0.elapsed());
    assert!(
        all.starts_with(b"HTTP/1.1 200 OK"),
        "{}",
        String::from_utf8_lossy(&all)
    );
    assert!(all.ends_with(PAGE.as_bytes()));
    assert!(t0.elapsed() < Duration::from_secs(2));
    stop.store(true, Ordering::Relaxed);
    dribbler.join().unwrap();
}

/// A request head sent a byte every 50 ms is cut off at the head
/// deadline (here 300 ms), not kept alive by each byte resetting a
/// per-read timeout.
#[test]
fn preview_dribbled_head_is_cut_off_at_its_deadline() {
    let limits = Limits {
        head_deadline: Duration::from_millis(300),
        ..Limits::DEFAULT
    };
    let p = Preview::start_with(
        "127.0.0.1:0".parse().unwrap(),
        Arc::new(Watch::new()),
        limits,
    )
    .unwrap();
    let mut s = TcpStream::connect(p.addr()).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(3))).unwrap();
    let t0 = Instant::now();
    let mut w = s.try_clone().unwrap();
    let dribbler = std::thread::spawn(move || {
        let _ = w.write_all(b"GET / HTTP/1.1\r\n");
        while t0.elapsed() < Duration::from_secs(4) && w.write_all(b"X").is_ok() {
            std::thread::sleep(Duration::from_millis(50));
        }
    });
    let mut all = Vec::new();
    let r = s.read_to_end(&mut all);
    let took = t0.elapsed();
    // The server answers 408 and closes; bytes that came after its last
    // read may turn the close into a reset, which ends the wait as well.
    match r {
        Ok(_) => assert!(
            all.starts_with(b"HTTP/1.1 408"),
            "{}",
            String::from_utf8_lossy(&all)
        ),
        Err(e) => assert_eq!(e.kind(), std::io::ErrorKind::ConnectionReset, "{e}"),
    }
    assert!(
        took >= Duration::from_millis(250) && took < Duration::from_secs(2),
        "{took:?}"
    );
    drop(s);
    dribbler.join().unwrap();
    // The slot was given back.
    let t0 = Instant::now();
    while p.shared.clients().total > 0 && t0.elapsed() < Duration::from_secs(1) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(p.shared.clients().total, 0);
}

#[test]
fn preview_connection_limits_keep_slots_for_new_clients() {
    let limits = Limits {
        connections: 6,
        per_client: 3,
        reserved: 2,
        head_deadline: Duration::from_secs(1),
    };
    let p = Preview::start_with(
        "127.0.0.1:0".parse().unwrap(),
        Arc::new(Watch::new()),
        limits,
    )
    .unwrap();
    let sh = &p.shared;
    let a: IpAddr = [10, 0, 0, 1].into();
    let b: IpAddr = [10, 0, 0, 2].into();
    let held: Vec<Slot> = (0..3).filter_map(|_| sh.claim(a)).collect();
    assert_eq!(held.len(), 3);
    assert!(sh.claim(a).is_none(), "over the per-client share");
    let b1 = sh.claim(b).unwrap();
    // 4 of 6 taken: b, now holding one, is left out of the 2 reserved…
    assert!(sh.claim(b).is_none());
    // …which newcomers get; an IPv6 /64 counts as one client.
    let c1 = sh.claim("2001:db8::1".parse().unwrap()).unwrap();
    assert!(sh.claim("2001:db8::2".parse().unwrap()).is_none());
    let d1 = sh.claim("::ffff:10.0.0.9".parse().unwrap()).unwrap();
    assert!(sh.claim([10, 0, 0, 9].into()).is_none(), "full");
    drop((held, b1, c1, d1));
    assert_eq!(sh.clients().total, 0);
    assert!(sh.clients().per_client.is_empty());
}

/// Memory amplification: slow `/image` readers (each reads 64 bytes and
/// stalls) share one encoding per snapshot, and once they hold
/// [`MAX_IMAGE_BUFFERS`] of them a newer request gets the newest of those
/// rather than a new copy; the page loads meanwhile.
#[test]
fn preview_slow_image_readers_share_one_encoding() {
    let watch = Arc::new(Watch::new());
    let p = Preview::start("127.0.0.1:0".parse().unwrap(), Arc::clone(&watch)).unwrap();
    let addr = p.addr();
    let host = format!("127.0.0.1:{}", addr.port());
    // 25 MB: more than loopback's socket buffers take in, so the server
    // threads stay in their writes holding the encoding.
    let (w, h) = (2048, 1024);
    let snap = |spp| Snapshot {
        width: w,
        height: h,
        rgb: vec![0.25; 3 * w * h],
        spp,
        done: false,
        camera: 0,
    };
    let stalled_reader = || {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        write!(s, "GET /image HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
        let mut first = [0u8; 64];
        s.read_exact(&mut first).unwrap();
        s
    };
    let images = || {
        let im = p.shared.images.lock().unwrap();
        (
            im.encodes,
            im.live.len(),
            im.live.iter().map(|e| e.version).max(),
        )
    };
    watch.image(snap(1));
    let mut readers: Vec<TcpStream> = (0..4).map(|_| stalled_reader()).collect();
    assert_eq!(images(), (1, 1, Some(1)), "four readers, one encoding");
    watch.image(snap(2));
    readers.push(stalled_reader());
    assert_eq!(images(), (2, 2, Some(2)));
    // Both encodings are being read: version 3 is answered with 2.
    watch.image(snap(3));
    let (head, body) = {
        let mut s = stalled_reader();
        let mut rest = vec![0u8; 512];
        s.read_exact(&mut rest).unwrap();
        (s, rest)
    };
    drop(head);
    let at = body.windows(4).position(|w| w == b"RPV1").unwrap();
    let version = u64::from_le_bytes(body[at + 24..at + 32].try_into().unwrap());
    assert_eq!(version, 2);
    assert_eq!(images(), (2, 2, Some(2)));
    let t0 = Instant::now();
    let (head, page) = get(addr, "/", &host);
    assert!(head.starts_with("HTTP/1.1 200") && page == PAGE.as_bytes());
    assert!(t0.elapsed() < Duration::from_secs(2));
    // Once the readers go, the next request encodes the latest snapshot.
    drop(readers);
    let t0 = Instant::now();
    let mut latest = 0;
    while latest != 3 && t0.elapsed() < Duration::from_secs(3) {
        let (_, b) = get(addr, "/image", &host);
        latest = u64::from_le_bytes(b[24..32].try_into().unwrap());
    }
    assert_eq!(latest, 3);
    assert_eq!(images().0, 3);
}

/// A page opened after the first wave: the server keeps the ends of waves
/// while nobody watches, so the page's first `/image` has the latest one
/// rather than "no image yet" until a tile of the current (long) wave
/// ends; snapshots inside a wave still wait for a viewer.
#[test]
fn preview_late_page_gets_the_last_wave_end_at_once() {
    let watch = Arc::new(Watch::new());
    let p = Preview::start("127.0.0.1:0".parse().unwrap(), Arc::clone(&watch)).unwrap();
    assert!(!watch.viewer_recent());
    assert!(
        !watch.wants_image(false),
        "inside a wave: only for a viewer"
    );
    assert!(
        watch.wants_image(true),
        "a wave's end: kept for a later page"
    );
    watch.image(frame(1, false).snapshot);
    let host = format!("127.0.0.1:{}", p.addr().port());
    let (head, body) = get(p.addr(), "/image", &host);
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    assert_eq!(u64::from_le_bytes(body[24..32].try_into().unwrap()), 1);
}

/// `/denoised`: the latest snapshot denoised from its colour (non-finite
/// pixels zeroed first), in `/image`'s encoding, the same bytes for every
/// request of one version; without Open Image Denoise, 503 with the reason
/// (the page then shows it and the raw image). The page has the toggle.
#[test]
fn denoised_route_serves_the_snapshot_denoised() {
    assert!(PAGE.contains("id=\"denoised\"") && PAGE.contains("\"/denoised\""));
    let watch = Arc::new(Watch::new());
    let p = Preview::start("127.0.0.1:0".parse().unwrap(), Arc::clone(&watch)).unwrap();
    let addr = p.addr();
    let host = format!("127.0.0.1:{}", addr.port());
    assert!(get(addr, "/denoised", &host).0.starts_with("HTTP/1.1 404"));
    // A noisy 32x32 grey with one infinite pixel.
    let (w, h) = (32, 32);
    let mut seed = 3u64;
    let mut rgb = Vec::new();
    for _ in 0..w * h * 3 {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        rgb.push(((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 * 0.4);
    }
    rgb[5] = f32::INFINITY;
    watch.image(Snapshot {
        width: w,
        height: h,
        rgb,
        spp: 4,
        done: false,
        camera: 0,
    });
    let (head, body) = get(addr, "/denoised", &host);
    if head.starts_with("HTTP/1.1 503") {
        let why = String::from_utf8_lossy(&body);
        assert!(why.contains("pip install pyoidn"), "{why}");
        eprintln!("skipping the denoised preview check: no Open Image Denoise here ({why})");
        return;
    }
    assert!(head.contains("application/octet-stream"), "{head}");
    assert_eq!(body.len(), IMAGE_HEADER + 4 * w * h * 3);
    assert_eq!(&body[..4], b"RPV1");
    let v: Vec<f32> = body[IMAGE_HEADER..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert!(v.iter().all(|x| x.is_finite()));
    // Much closer to the grey than the noise (variance 0.16/3 ≈ 0.053).
    let mse = v.iter().map(|x| (x - 0.4).powi(2)).sum::<f32>() / v.len() as f32;
    assert!(mse < 0.01, "denoised MSE {mse}");
    assert_eq!(get(addr, "/denoised", &host).1, body);
}
