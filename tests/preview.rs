//! `lumen render --preview`: the page, its routes and what it refuses, and
//! the page itself in headless Chromium (Debian's `chromium`, which
//! `.ci/run` installs; without it the browser test is skipped unless
//! `LUMEN_REQUIRE_CHROMIUM` is set).

mod lumen_process;

use lumen_process::*;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::Command;

/// A render of a few seconds and about ten passes.
const RENDER_SLOW: &[&str] = &[
    "render",
    "cover",
    "--width",
    "240",
    "--spp",
    "256",
    "--threads",
    "2",
];

/// Starts `args` with `--preview` and returns it with its page's address
/// (`127.0.0.1:PORT`).
fn start(args: &[&str], out: &Path, extra: &[&str]) -> (Running, String) {
    let mut all = vec!["--preview"];
    all.extend_from_slice(extra);
    let r = spawn(args, out, &all);
    let line = r.wait_line("preview: ");
    let url = line
        .trim_start_matches("preview: http://")
        .trim_end_matches('/')
        .to_string();
    (r, url)
}

/// One HTTP/1.1 request; returns the status code and the body.
fn request(addr: &str, method: &str, path: &str) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(addr).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = Vec::new();
    stream.read_to_end(&mut response).unwrap();
    let end = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a header");
    let head = String::from_utf8_lossy(&response[..end]).into_owned();
    let code = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    let mut body = response[end + 4..].to_vec();
    if head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        body = unchunk(&body);
    }
    (code, body)
}

fn unchunk(mut data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let line = data.windows(2).position(|w| w == b"\r\n").unwrap();
        let size =
            usize::from_str_radix(std::str::from_utf8(&data[..line]).unwrap().trim(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&data[line + 2..line + 2 + size]);
        data = &data[line + 2 + size + 2..];
    }
}

#[test]
fn the_page_its_status_and_its_images_are_served_and_nothing_else() {
    let dir = temp_dir("preview-routes");
    let out = dir.join("out.png");
    let (r, addr) = start(RENDER_SLOW, &out, &["--aov", "albedo,depth"]);
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");
    let (code, page) = request(&addr, "GET", "/");
    assert_eq!(code, 200);
    assert!(String::from_utf8_lossy(&page).contains("<title>lumen preview</title>"));
    // The status after the first pass: waits for it.
    let (code, status) = request(&addr, "GET", "/status?after=0");
    assert_eq!(code, 200);
    let status: serde_json::Value = serde_json::from_slice(&status).unwrap();
    assert_eq!(status["width"], 240);
    assert_eq!(status["spp_total"], 256);
    assert_eq!(
        status["layers"],
        serde_json::json!(["beauty", "albedo", "depth"])
    );
    assert!(status["pass"].as_u64().unwrap() >= 1);
    let (w, h) = (240, 135);
    for layer in ["beauty", "albedo", "depth"] {
        let (code, bytes) = request(&addr, "GET", &format!("/image/{layer}"));
        assert_eq!((code, bytes.len()), (200, w * h * 12), "{layer}");
    }
    // Nothing else, and no file at all.
    for path in [
        "/image/normal",
        "/../Cargo.toml",
        "/..%2f..%2fetc%2fpasswd",
        "/etc/passwd",
        "/index.htm",
    ] {
        let (code, body) = request(&addr, "GET", path);
        assert_eq!(code, 404, "{path}");
        assert!(
            String::from_utf8_lossy(&body).starts_with("not found"),
            "{path}"
        );
    }
    assert_eq!(request(&addr, "POST", "/status").0, 405);
    let (status, err) = r.finish();
    assert!(status.success(), "{err}");
}

#[test]
fn a_port_in_use_is_refused_before_the_render() {
    let dir = temp_dir("preview-port");
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = dir.join("out.png");
    let o = lumen()
        .args([
            "render",
            "cornell-box",
            "--width",
            "20",
            "--spp",
            "2",
            "--preview",
            "--preview-port",
            &port,
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_refused(
        &o,
        &[&format!(
            "--preview-port {port}: cannot listen on 127.0.0.1:{port}"
        )],
    );
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "nothing is written"
    );
    // A port without the page is a usage error.
    let (status, err) = run(
        &["render", "cornell-box", "--width", "20"],
        &out,
        &["--preview-port", "1"],
    );
    assert_eq!(status.code(), Some(2), "{err}");
}

#[test]
fn an_interrupt_with_the_page_saves_as_without_it_and_resumes_to_the_same_bits() {
    let dir = temp_dir("preview-interrupt");
    let reference = reference(&dir, RENDER);
    let out = dir.join("out.pfm");
    let (r, addr) = start(RENDER, &out, &[]);
    r.wait_line("pass 4:");
    // A page waiting on the status while the render stops.
    let waiting = std::thread::spawn(move || request(&addr, "GET", "/status?after=1000000"));
    r.signal(libc::SIGINT);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    drop(waiting);
    let (status, err) = run(RENDER, &out, &["--resume", "--preview"]);
    assert!(status.success(), "{err}");
    assert!(
        std::fs::read(&out).unwrap() == reference,
        "the resumed image differs"
    );
}

/// Headless Chromium, as root needs it and without its network chatter.
fn chromium() -> Option<Command> {
    let found = Path::new("/usr/bin/chromium").exists();
    if !found {
        assert!(
            std::env::var_os("LUMEN_REQUIRE_CHROMIUM").is_none(),
            "LUMEN_REQUIRE_CHROMIUM is set and /usr/bin/chromium is missing"
        );
        eprintln!("skipped: no /usr/bin/chromium (Debian's chromium package)");
        return None;
    }
    let mut c = Command::new("/usr/bin/chromium");
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
    ]);
    Some(c)
}

/// The value of attribute `name` of the first element `tag` in `dom`.
fn attribute<'a>(dom: &'a str, tag: &str, name: &str) -> &'a str {
    let start = dom
        .find(&format!("<{tag}"))
        .unwrap_or_else(|| panic!("no <{tag}> in {dom}"));
    let element = &dom[start..start + dom[start..].find('>').unwrap()];
    let at = element
        .find(&format!(" {name}=\""))
        .unwrap_or_else(|| panic!("no {name} in {element}"));
    let value = &element[at + name.len() + 3..];
    &value[..value.find('"').unwrap()]
}

#[test]
fn the_page_in_a_browser_shows_the_image_and_follows_the_passes_to_the_end() {
    let Some(mut browser) = chromium() else {
        return;
    };
    let dir = temp_dir("preview-browser");
    let out = dir.join("out.png");
    let (r, addr) = start(RENDER_SLOW, &out, &["--aov", "normal"]);
    // The page asks for the status again as soon as it has one, and the
    // server answers when the next pass is done: virtual time stands still
    // meanwhile, so the page is dumped once the render has ended.
    let dom = browser
        .arg(format!("--user-data-dir={}", dir.join("profile").display()))
        .args(["--virtual-time-budget=120000", "--dump-dom"])
        .arg(format!("http://{addr}/#layer=normal"))
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&dom.stdout).into_owned();
    let (status, err) = r.finish();
    assert!(status.success(), "{err}");
    let passes: Vec<u32> = attribute(&dom, "body", "data-passes")
        .split(',')
        .map(|p| p.parse().unwrap_or_else(|_| panic!("passes in {dom}")))
        .collect();
    assert!(passes.len() >= 2, "the page saw one pass: {passes:?}");
    assert!(passes.windows(2).all(|w| w[0] < w[1]), "{passes:?}");
    let last = err.lines().filter(|l| l.starts_with("pass ")).count() as u32;
    assert_eq!(
        passes.last(),
        Some(&last),
        "the page ends with the last pass"
    );
    assert_eq!(attribute(&dom, "body", "data-ended"), "true");
    assert!(dom.contains("256 of 256 spp"), "{dom}");
    // The image drawn, every pixel lit, in the layer the address asked for.
    assert_eq!(attribute(&dom, "canvas", "width"), "240");
    assert_eq!(attribute(&dom, "canvas", "data-layer"), "normal");
    let drawn: u32 = attribute(&dom, "canvas", "data-drawn").parse().unwrap();
    assert_eq!(drawn, 240 * 135, "{dom}");
}
