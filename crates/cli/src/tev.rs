//! `--display-server host:port`: the image as it renders, streamed to the
//! tev viewer over tev's TCP protocol, as pbrt-v4 does
//! (`util/display.cpp`). Every message is framed by its total length,
//! the four length bytes included, as a little-endian `u32`. The image is
//! opened with `CreateImage` (type 4: grab-focus byte, title, width,
//! height and channel count as `i32`, then the channel names), then sent
//! as `UpdateImage` messages (type 3: grab-focus byte, title, one channel
//! name, the tile's x, y, width and height as `i32`, then its values as
//! `f32`), one per channel per 128×128 tile, and only for tiles that
//! changed since they were last sent. Strings are NUL-terminated; all
//! numbers little-endian. The title is the image file name and the
//! process id, as pbrt-v4's. When the connection fails the client
//! reconnects at the next snapshot and sends everything again.

use crate::watch::{Frame, Watch};
use std::io::Write;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::Arc;
use std::time::Duration;

/// Side of the square tiles of update messages (pbrt-v4's).
pub const TILE_SIZE: usize = 128;
/// tev's message types (its `IpcPacket::EType`).
pub const CREATE_IMAGE: u8 = 4;
/// One channel of a rectangle of pixels.
pub const UPDATE_IMAGE: u8 = 3;
/// The channels sent.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];
/// How long a connect or a send may take (pbrt-v4 sets 3 s on sends).
const NET_TIMEOUT: Duration = Duration::from_secs(3);

/// A message with its length prefix filled in.
fn message(body: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut m = vec![0u8; 4];
    body(&mut m);
    let n = m.len() as u32;
    m[..4].copy_from_slice(&n.to_le_bytes());
    m
}

fn put_str(m: &mut Vec<u8>, s: &str) {
    // tev reads up to the NUL: one inside the text would cut it short.
    m.extend(s.bytes().filter(|&b| b != 0));
    m.push(0);
}

/// The `CreateImage` message: an image of `width × height` pixels with
/// `channels`, focused in the viewer.
pub fn create_image(title: &str, width: i32, height: i32, channels: &[&str]) -> Vec<u8> {
    message(|m| {
        m.push(CREATE_IMAGE);
        m.push(1); // grab focus
        put_str(m, title);
        m.extend_from_slice(&width.to_le_bytes());
        m.extend_from_slice(&height.to_le_bytes());
        m.extend_from_slice(&(channels.len() as i32).to_le_bytes());
        for c in channels {
            put_str(m, c);
        }
    })
}

/// The `UpdateImage` message for one channel of the rectangle at
/// `(x, y)` of `width × height` pixels, `values` in rows from the top.
pub fn update_image(
    title: &str,
    channel: &str,
    [x, y, width, height]: [i32; 4],
    values: impl Iterator<Item = f32>,
) -> Vec<u8> {
    message(|m| {
        m.push(UPDATE_IMAGE);
        m.push(0); // do not grab focus
        put_str(m, title);
        put_str(m, channel);
        for v in [x, y, width, height] {
            m.extend_from_slice(&v.to_le_bytes());
        }
        for v in values {
            m.extend_from_slice(&v.to_le_bytes());
        }
    })
}

/// The tiles of a `width × height` image as `[x, y, w, h]`, rows of tiles
/// from the top.
fn tiles(width: usize, height: usize) -> impl Iterator<Item = [usize; 4]> {
    (0..height).step_by(TILE_SIZE).flat_map(move |y| {
        (0..width)
            .step_by(TILE_SIZE)
            .map(move |x| [x, y, TILE_SIZE.min(width - x), TILE_SIZE.min(height - y)])
    })
}

/// Channel `c` of the tile `[x, y, w, h]` of a frame.
fn tile_values(f: &Frame, [x, y, w, h]: [usize; 4], c: usize) -> impl Iterator<Item = f32> + '_ {
    let width = f.snapshot.width;
    (y..y + h)
        .flat_map(move |row| (x..x + w).map(move |col| f.snapshot.rgb[3 * (row * width + col) + c]))
}

/// A connection to tev that shows one image.
pub struct TevClient {
    address: String,
    title: String,
    stream: Option<TcpStream>,
    /// The frame tev was last sent in full (its tiles are what it shows).
    shown: Option<Arc<Frame>>,
    warned: bool,
    /// How long a connect or a send may take ([`NET_TIMEOUT`]).
    timeout: Duration,
}

/// `e` from a write to tev, said plainly when the write timed out: std
/// reports a send timeout on Unix as `WouldBlock`, whose text ("Resource
/// temporarily unavailable (os error 11)") says nothing of what happened.
fn writing(e: std::io::Error, timeout: Duration) -> std::io::Error {
    match e.kind() {
        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut => std::io::Error::new(
            std::io::ErrorKind::TimedOut,
            format!(
                "timed out writing to tev (it took no data for {} s)",
                timeout.as_secs_f32()
            ),
        ),
        _ => e,
    }
}

impl TevClient {
    /// A client for tev at `address` (`host:port`) showing `title`; it
    /// connects when it first has something to send.
    pub fn new(address: &str, title: &str) -> Self {
        TevClient {
            address: address.to_string(),
            title: title.to_string(),
            stream: None,
            shown: None,
            warned: false,
            timeout: NET_TIMEOUT,
        }
    }

    fn connect(&self) -> std::io::Result<TcpStream> {
        let mut last = None;
        for a in self.address.to_socket_addrs()? {
            match TcpStream::connect_timeout(&a, self.timeout) {
                Ok(s) => {
                    s.set_write_timeout(Some(self.timeout))?;
                    s.set_nodelay(true)?;
                    return Ok(s);
                }
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or_else(|| std::io::Error::other("the host has no address")))
    }

    /// Sends what changed between the frame tev shows and `frame`
    /// (everything, after a new connection). Errors drop the connection
    /// (the next call connects again) and are reported once.
    pub fn display(&mut self, frame: &Arc<Frame>) {
        if let Err(e) = self.try_display(frame) {
            self.stream = None;
            self.shown = None;
            if !self.warned {
                self.warned = true;
                diagln!(
                    "rpbrt: warning: --display-server {}: {e}; will keep trying",
                    self.address
                );
            }
        }
    }

    fn try_display(&mut self, frame: &Arc<Frame>) -> std::io::Result<()> {
        let (w, h) = (frame.snapshot.width, frame.snapshot.height);
        if frame.snapshot.rgb.len() != 3 * w * h || w == 0 || h == 0 {
            return Ok(());
        }
        if self.stream.is_none() {
            let mut s = self.connect()?;
            s.write_all(&create_image(&self.title, w as i32, h as i32, &CHANNELS))
                .map_err(|e| writing(e, self.timeout))?;
            self.stream = Some(s);
            self.shown = None;
        }
        let Some(stream) = self.stream.as_mut() else {
            return Ok(());
        };
        let shown = self
            .shown
            .as_ref()
            .filter(|s| (s.snapshot.width, s.snapshot.height) == (w, h));
        for t in tiles(w, h) {
            for (c, name) in CHANNELS.iter().enumerate() {
                // tev starts with zeros: unchanged tiles are not sent.
                let unchanged = match shown {
                    Some(s) => tile_values(s, t, c).eq(tile_values(frame, t, c)),
                    None => tile_values(frame, t, c).all(|v| v == 0.0),
                };
                if !unchanged {
                    let rect = t.map(|v| v as i32);
                    stream
                        .write_all(&update_image(
                            &self.title,
                            name,
                            rect,
                            tile_values(frame, t, c),
                        ))
                        .map_err(|e| writing(e, self.timeout))?;
                }
            }
        }
        stream.flush().map_err(|e| writing(e, self.timeout))?;
        self.shown = Some(Arc::clone(frame));
        Ok(())
    }
}

/// Streams `watch`'s frames to tev at `address` from a thread of its own
/// until the render has finished and its last frame has been sent.
pub fn spawn(address: &str, title: &str, watch: Arc<Watch>) -> std::thread::JoinHandle<()> {
    watch.always_want();
    let mut client = TevClient::new(address, title);
    std::thread::spawn(move || {
        let mut sent = 0;
        loop {
            let (frame, finished) = {
                let s = watch.wait_newer(sent, Duration::from_millis(250));
                (s.frame.clone(), s.finished)
            };
            if let Some(f) = frame.filter(|f| f.version > sent) {
                client.display(&f);
                sent = f.version;
            }
            if finished {
                return;
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_render::integrator::Snapshot;
    use std::io::Read;
    use std::net::TcpListener;

    /// A message as tev's reader takes it apart.
    #[derive(Debug, PartialEq)]
    enum Msg {
        Create {
            title: String,
            size: (i32, i32),
            channels: Vec<String>,
        },
        Update {
            title: String,
            channel: String,
            rect: [i32; 4],
            values: Vec<f32>,
        },
    }

    struct Reader<'a>(&'a [u8]);

    impl Reader<'_> {
        fn byte(&mut self) -> u8 {
            let (b, rest) = self.0.split_first().expect("message ends early");
            self.0 = rest;
            *b
        }
        fn i32(&mut self) -> i32 {
            let (b, rest) = self.0.split_at(4);
            self.0 = rest;
            i32::from_le_bytes(b.try_into().unwrap())
        }
        fn string(&mut self) -> String {
            let end = self.0.iter().position(|&b| b == 0).expect("no NUL");
            let s = String::from_utf8(self.0[..end].to_vec()).unwrap();
            self.0 = &self.0[end + 1..];
            s
        }
    }

    /// Reads every message from `stream` until it closes, checking the
    /// framing and each message's fields.
    fn read_messages(stream: &mut TcpStream) -> Vec<Msg> {
        let mut all = Vec::new();
        stream.read_to_end(&mut all).unwrap();
        let mut out = Vec::new();
        let mut rest = &all[..];
        while !rest.is_empty() {
            let len = u32::from_le_bytes(rest[..4].try_into().unwrap()) as usize;
            assert!(len > 6 && len <= rest.len(), "bad length {len}");
            let mut r = Reader(&rest[4..len]);
            let kind = r.byte();
            let focus = r.byte();
            let msg = match kind {
                CREATE_IMAGE => {
                    assert_eq!(focus, 1);
                    let title = r.string();
                    let size = (r.i32(), r.i32());
                    let n = r.i32();
                    let channels = (0..n).map(|_| r.string()).collect();
                    Msg::Create {
                        title,
                        size,
                        channels,
                    }
                }
                UPDATE_IMAGE => {
                    assert_eq!(focus, 0);
                    let title = r.string();
                    let channel = r.string();
                    let rect = [r.i32(), r.i32(), r.i32(), r.i32()];
                    let n = (rect[2] * rect[3]) as usize;
                    assert_eq!(r.0.len(), 4 * n, "values of {rect:?}");
                    let values =
                        r.0.chunks_exact(4)
                            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                            .collect();
                    r.0 = &[];
                    Msg::Update {
                        title,
                        channel,
                        rect,
                        values,
                    }
                }
                k => panic!("unknown message type {k}"),
            };
            assert!(r.0.is_empty(), "trailing bytes in {msg:?}");
            out.push(msg);
            rest = &rest[len..];
        }
        out
    }

    fn frame(version: u64, width: usize, height: usize, f: impl Fn(usize) -> f32) -> Arc<Frame> {
        Arc::new(Frame {
            version,
            snapshot: Snapshot {
                width,
                height,
                rgb: (0..3 * width * height).map(f).collect(),
                spp: 1,
                done: false,
                camera: 0,
            },
        })
    }

    #[test]
    fn messages_are_framed_as_tev_reads_them() {
        let m = create_image("a.exr (7)", 300, 200, &CHANNELS);
        assert_eq!(
            u32::from_le_bytes(m[..4].try_into().unwrap()) as usize,
            m.len()
        );
        assert_eq!(&m[4..6], &[4, 1]);
        assert_eq!(&m[6..16], b"a.exr (7)\0");
        assert_eq!(&m[16..28], &[44, 1, 0, 0, 200, 0, 0, 0, 3, 0, 0, 0]);
        assert_eq!(&m[28..], b"R\0G\0B\0");
        let u = update_image("t", "G", [128, 0, 2, 1], [1.0f32, -2.5].into_iter());
        assert_eq!(u.len(), 4 + 2 + 2 + 2 + 16 + 8);
        assert_eq!(
            u32::from_le_bytes(u[..4].try_into().unwrap()) as usize,
            u.len()
        );
        assert_eq!(&u[4..10], &[3, 0, b't', 0, b'G', 0]);
        assert_eq!(&u[10..14], &128i32.to_le_bytes());
        assert_eq!(
            &u[26..],
            [1.0f32.to_le_bytes(), (-2.5f32).to_le_bytes()].concat()
        );
    }

    #[test]
    fn client_sends_the_image_then_only_changed_tiles() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let server = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            read_messages(&mut s)
        });
        // 200 × 130: tiles of 128 × 128, 72 × 128, 128 × 2 and 72 × 2.
        let (w, h) = (200, 130);
        let first = frame(1, w, h, |i| i as f32 * 0.25);
        // Only pixel (150, 129)'s green changes: one message.
        let second = frame(2, w, h, |i| {
            if i == 3 * (129 * w + 150) + 1 {
                -1.0
            } else {
                i as f32 * 0.25
            }
        });
        let mut client = TevClient::new(&addr, "img.exr (1)");
        client.display(&first);
        client.display(&second);
        client.display(&second);
        drop(client);
        let msgs = server.join().unwrap();
        assert_eq!(
            msgs[0],
            Msg::Create {
                title: "img.exr (1)".into(),
                size: (200, 130),
                channels: vec!["R".into(), "G".into(), "B".into()],
            }
        );
        // The first frame: 4 tiles × 3 channels, rows of tiles from the top.
        assert_eq!(msgs.len(), 1 + 12 + 1, "{:?}", &msgs[13..]);
        let mut covered = vec![[false; 3]; w * h];
        for m in &msgs[1..13] {
            let Msg::Update {
                title,
                channel,
                rect,
                values,
            } = m
            else {
                panic!("{m:?}")
            };
            assert_eq!(title, "img.exr (1)");
            let c = CHANNELS.iter().position(|n| n == channel).unwrap();
            let [x, y, tw, th] = rect.map(|v| v as usize);
            assert!(tw <= TILE_SIZE && th <= TILE_SIZE && x + tw <= w && y + th <= h);
            for (k, v) in values.iter().enumerate() {
                let (px, py) = (x + k % tw, y + k / tw);
                assert_eq!(*v, first.snapshot.rgb[3 * (py * w + px) + c]);
                covered[py * w + px][c] = true;
            }
        }
        assert!(covered.iter().all(|c| c.iter().all(|&b| b)));
        let Msg::Update {
            channel,
            rect,
            values,
            ..
        } = &msgs[13]
        else {
            panic!()
        };
        assert_eq!((channel.as_str(), *rect), ("G", [128, 128, 72, 2]));
        assert_eq!(values[72 + 22], -1.0);
    }

    #[test]
    fn client_reconnects_and_resends_everything() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let mut client = TevClient::new(&addr, "x");
        client.display(&frame(1, 4, 4, |i| i as f32));
        // The viewer goes away.
        drop(listener.accept().unwrap());
        // Sends fail (not always the first one after the close)...
        let mut version = 1;
        while client.shown.is_some() {
            version += 1;
            assert!(version < 1000, "sends never failed");
            client.display(&frame(version, 4, 4, |i| (i as u64 * version) as f32));
            std::thread::sleep(Duration::from_millis(5));
        }
        // ...and the next frame goes to a new connection, in full.
        let last = frame(version + 1, 4, 4, |i| 1.0 + i as f32);
        client.display(&last);
        drop(client);
        let (mut s, _) = listener.accept().unwrap();
        let msgs = read_messages(&mut s);
        assert!(
            matches!(msgs[0], Msg::Create { size: (4, 4), .. }),
            "{msgs:?}"
        );
        assert_eq!(msgs.len(), 4);
        for (c, m) in msgs[1..].iter().enumerate() {
            let Msg::Update { values, .. } = m else {
                panic!("{m:?}")
            };
            let want: Vec<f32> = (0..16).map(|k| last.snapshot.rgb[3 * k + c]).collect();
            assert_eq!(values, &want);
        }
    }

    /// A tev that stops reading: the send timeout is reported as a
    /// timeout, not as "Resource temporarily unavailable (os error 11)".
    #[test]
    fn tev_write_timeout_is_reported_as_a_timeout() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        // Accepts and holds the connection without reading it.
        let holder = std::thread::spawn(move || listener.accept().map(|(s, _)| s));
        let mut client = TevClient::new(&addr, "t");
        client.timeout = Duration::from_millis(200);
        // 25 MB of non-zero tiles: more than loopback's socket buffers.
        let (width, height) = (2048, 1024);
        let frame = Arc::new(Frame {
            version: 1,
            snapshot: Snapshot {
                width,
                height,
                rgb: vec![1.0; 3 * width * height],
                spp: 1,
                done: false,
                camera: 0,
            },
        });
        let e = client.try_display(&frame).unwrap_err();
        let text = e.to_string();
        assert_eq!(e.kind(), std::io::ErrorKind::TimedOut, "{text}");
        assert!(
            text.contains("timed out writing to tev") && !text.contains("os error"),
            "{text}"
        );
        drop(holder.join().unwrap());
    }

    #[test]
    fn no_viewer_is_not_an_error() {
        // Nothing listens there: the client warns once and goes on.
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let mut client = TevClient::new(&format!("127.0.0.1:{port}"), "x");
        client.display(&frame(1, 2, 2, |_| 1.0));
        assert!(client.warned && client.stream.is_none());
    }
}
