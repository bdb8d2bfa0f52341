//! Tests of the preview server: request parsing, the Host check, the
//! image encoding and the status, and the routes over a real socket.

use super::*;
use rpbrt_render::integrator::{Progress, RenderObserver, Snapshot};
use std::io::Read;

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
            host: Some("127.0.0.1:80".into()),
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
