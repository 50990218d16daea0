//! A live look at a render in progress: a small web server on the
//! loopback interface that serves one page, the render's status and its
//! latest images (the beauty, each feature buffer, and the denoised image
//! when there is one).
//!
//! The render publishes a snapshot after each pass
//! ([`Preview::publish`]); the server never touches the film itself, so
//! it cannot change the render, and slows it by that copy alone. The copy
//! is made only while a page is watching (it has a request open, or made
//! one in the last ten seconds), at most twice a second but for the
//! render's last image. Its routes are
//! fixed: `/` (the page), `/status` (JSON; `?after=V` waits, up to 20 s,
//! for a snapshot newer than version `V`), and `/image/NAME` (the layer's
//! pixels as little-endian 32-bit float RGB triples, row-major, top row
//! first). It reads no files: any other path is a 404.

use crate::aov::Aov;
use crate::film::Film;
use crate::math::Color;
use rayon::prelude::*;
use serde::Serialize;
use std::net::{Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};
use thiserror::Error;

/// The page, with its script and style (no other files are served).
const PAGE: &str = include_str!("preview/page.html");

/// How long `/status?after=V` waits for a newer snapshot.
const LONG_POLL: Duration = Duration::from_secs(20);

/// A preview server that could not start.
#[derive(Debug, Error)]
pub enum PreviewError {
    /// The port is taken, or cannot be bound.
    #[error("--preview-port {port}: cannot listen on 127.0.0.1:{port}: {message}")]
    Bind {
        /// The port asked for.
        port: u16,
        /// Why.
        message: String,
    },
}

/// Where a render stands, as the page shows it.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Status {
    /// Passes finished in this run.
    pub pass: u32,
    /// Samples per pixel done, and to do in all.
    pub spp_done: u32,
    /// See `spp_done`.
    pub spp_total: u32,
    /// Seconds since the render started.
    pub elapsed: f64,
    /// Seconds it is expected to take still, once a pass has finished.
    pub eta: Option<f64>,
    /// The display gamma of the render's images.
    pub gamma: f32,
}

/// What the server holds: the latest snapshot.
#[derive(Default)]
struct Snapshot {
    /// Increased by every publish; 0 before the first.
    version: u64,
    status: Status,
    width: u32,
    height: u32,
    /// Each layer's name and its RGB floats.
    layers: Vec<(String, Arc<Vec<f32>>)>,
    /// Whether the render has ended (the page stops asking).
    finished: bool,
    /// When the latest snapshot was taken.
    taken: Option<Instant>,
}

#[derive(Serialize)]
struct StatusJson<'a> {
    version: u64,
    width: u32,
    height: u32,
    layers: Vec<&'a str>,
    finished: bool,
    #[serde(flatten)]
    status: &'a Status,
}

struct Shared {
    snapshot: Mutex<Snapshot>,
    changed: Condvar,
    /// When the server started: the clock of `last_request`.
    started: Instant,
    /// Milliseconds from `started` to the latest request's arrival
    /// ([`NEVER`] before the first).
    last_request: AtomicU64,
    /// Requests being answered (a page's waiting `/status` among them).
    open_requests: AtomicUsize,
    /// The newest snapshot version a `/status` has answered with.
    served: AtomicU64,
}

/// How long [`Preview::finish`] waits for a watching page.
const DRAIN: Duration = Duration::from_secs(2);

/// `Shared::last_request` before any request.
const NEVER: u64 = u64::MAX;

/// A page is watching while it has a request open or made one this
/// recently.
const WATCHING: Duration = Duration::from_secs(10);
/// Snapshots are made at most this often, but for the last.
const SPACING: Duration = Duration::from_millis(500);

impl Shared {
    fn watched(&self) -> bool {
        let now = self.started.elapsed().as_millis() as u64;
        let recent = match self.last_request.load(Ordering::Relaxed) {
            NEVER => false,
            last => now.saturating_sub(last) < WATCHING.as_millis() as u64,
        };
        recent || self.open_requests.load(Ordering::Relaxed) > 0
    }
}

/// A running preview server; it stops serving when dropped.
pub struct Preview {
    shared: Arc<Shared>,
    server: Arc<tiny_http::Server>,
    addr: SocketAddr,
}

impl Preview {
    /// Starts serving on `127.0.0.1:port` (0: a free port the system
    /// picks). A port in use is refused, never replaced by another.
    pub fn start(port: u16) -> Result<Preview, PreviewError> {
        let bind = SocketAddr::from((Ipv4Addr::LOCALHOST, port));
        let server = tiny_http::Server::http(bind).map_err(|e| PreviewError::Bind {
            port,
            message: e.to_string(),
        })?;
        let addr = server
            .server_addr()
            .to_ip()
            .expect("a TCP server has an IP address");
        let server = Arc::new(server);
        let shared = Arc::new(Shared {
            snapshot: Mutex::new(Snapshot::default()),
            changed: Condvar::new(),
            started: Instant::now(),
            last_request: AtomicU64::new(NEVER),
            open_requests: AtomicUsize::new(0),
            served: AtomicU64::new(0),
        });
        let (s, sh) = (Arc::clone(&server), Arc::clone(&shared));
        std::thread::Builder::new()
            .name("preview".into())
            .spawn(move || {
                for request in s.incoming_requests() {
                    let sh = Arc::clone(&sh);
                    let now = sh.started.elapsed().as_millis() as u64;
                    sh.last_request.store(now, Ordering::Relaxed);
                    sh.open_requests.fetch_add(1, Ordering::Relaxed);
                    // One thread a request: a waiting `/status` must not
                    // hold up an image.
                    let _ = std::thread::Builder::new()
                        .name("preview request".into())
                        .spawn(move || {
                            respond(&sh, request);
                            sh.open_requests.fetch_sub(1, Ordering::Relaxed);
                        });
                }
            })
            .expect("a thread can be started");
        Ok(Preview {
            shared,
            server,
            addr,
        })
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// The port served.
    pub fn port(&self) -> u16 {
        self.addr.port()
    }

    /// Publishes the film's image, its feature buffers `aovs` and, when
    /// given, a denoised image (kept until the next one), with `status`:
    /// when a page is watching, and the last snapshot is not too recent
    /// or this is the render's `last` image (see the module's
    /// documentation).
    pub fn publish(
        &self,
        status: Status,
        film: &Film,
        aovs: &[Aov],
        denoised: Option<&[Color]>,
        last: bool,
    ) {
        let due = {
            let snapshot = self.shared.snapshot.lock().expect("the preview's lock");
            snapshot.taken.is_none_or(|t| t.elapsed() >= SPACING)
        };
        if !(due || last) || !self.shared.watched() {
            return;
        }
        // On the render's threads, which wait for the next pass meanwhile.
        let rgb = |n: usize, at: &(dyn Fn(usize) -> [f32; 3] + Sync)| -> Arc<Vec<f32>> {
            let mut values = vec![0.0; 3 * n];
            values
                .par_chunks_mut(3 * 1024)
                .enumerate()
                .for_each(|(k, chunk)| {
                    for (j, v) in chunk.chunks_exact_mut(3).enumerate() {
                        v.copy_from_slice(&at(k * 1024 + j));
                    }
                });
            Arc::new(values)
        };
        let n = film.len();
        let mut layers = vec![("beauty".to_string(), rgb(n, &|i| film.mean(i).to_array()))];
        for &aov in aovs {
            let channels = crate::output::aov_values(film, aov);
            let at = |i: usize| std::array::from_fn(|c| channels[c.min(channels.len() - 1)][i]);
            layers.push((aov.name().to_string(), rgb(n, &at)));
        }
        let mut snapshot = self.shared.snapshot.lock().expect("the preview's lock");
        let kept = snapshot
            .layers
            .iter()
            .find(|(name, _)| name == "denoised")
            .map(|(_, d)| Arc::clone(d));
        let denoised = denoised.map(|d| rgb(n, &|i| d[i].to_array())).or(kept);
        if let Some(d) = denoised {
            layers.push(("denoised".to_string(), d));
        }
        snapshot.version += 1;
        snapshot.taken = Some(Instant::now());
        snapshot.status = status;
        snapshot.width = film.width();
        snapshot.height = film.height();
        snapshot.layers = layers;
        self.shared.changed.notify_all();
    }

    /// Tells the page that the render has ended, and gives a watching
    /// page up to [`DRAIN`] to fetch the last status and image before the
    /// process, and the server with it, ends.
    pub fn finish(&self) {
        let version = {
            let mut snapshot = self.shared.snapshot.lock().expect("the preview's lock");
            snapshot.finished = true;
            snapshot.version += 1;
            self.shared.changed.notify_all();
            snapshot.version
        };
        if !self.shared.watched() {
            return;
        }
        let deadline = Instant::now() + DRAIN;
        while Instant::now() < deadline {
            let served = self.shared.served.load(Ordering::Relaxed) >= version;
            if served && self.shared.open_requests.load(Ordering::Relaxed) == 0 {
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Preview {
    fn drop(&mut self) {
        self.server.unblock();
    }
}

/// Answers one request (see the module's documentation).
fn respond(shared: &Shared, request: tiny_http::Request) {
    use tiny_http::{Header, Method, Response};
    let header = |k: &str, v: &str| Header::from_bytes(k, v).expect("a valid header");
    if !matches!(request.method(), Method::Get | Method::Head) {
        let _ = request.respond(Response::from_string("only GET is served").with_status_code(405));
        return;
    }
    let url = request.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    let no_store = header("Cache-Control", "no-store");
    match path {
        "/" | "/index.html" => {
            let response = Response::from_string(PAGE)
                .with_header(header("Content-Type", "text/html; charset=utf-8"))
                .with_header(no_store);
            let _ = request.respond(response);
        }
        "/status" => {
            let after = query
                .split('&')
                .find_map(|kv| kv.strip_prefix("after="))
                .and_then(|v| v.parse::<u64>().ok());
            let snapshot = shared.snapshot.lock().expect("the preview's lock");
            let snapshot = match after {
                Some(after) => {
                    shared
                        .changed
                        .wait_timeout_while(snapshot, LONG_POLL, |s| s.version <= after)
                        .expect("the preview's lock")
                        .0
                }
                None => snapshot,
            };
            shared.served.fetch_max(snapshot.version, Ordering::Relaxed);
            let json = serde_json::to_string(&StatusJson {
                version: snapshot.version,
                width: snapshot.width,
                height: snapshot.height,
                layers: snapshot.layers.iter().map(|(n, _)| n.as_str()).collect(),
                finished: snapshot.finished,
                status: &snapshot.status,
            })
            .expect("a status serialises");
            drop(snapshot);
            let response = Response::from_string(json)
                .with_header(header("Content-Type", "application/json"))
                .with_header(no_store);
            let _ = request.respond(response);
        }
        _ => {
            let layer = path.strip_prefix("/image/").and_then(|name| {
                let snapshot = shared.snapshot.lock().expect("the preview's lock");
                snapshot
                    .layers
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| Arc::clone(v))
            });
            match layer {
                Some(values) => {
                    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
                    let response = Response::from_data(bytes)
                        .with_header(header("Content-Type", "application/octet-stream"))
                        .with_header(no_store);
                    let _ = request.respond(response);
                }
                None => {
                    let response = Response::from_string(format!(
                        "not found: {path}; the preview serves /, /status and /image/NAME \
                         for the layers /status lists"
                    ))
                    .with_status_code(404);
                    let _ = request.respond(response);
                }
            }
        }
    }
}
