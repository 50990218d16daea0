//! Helpers for the tests that run the `lumen` binary and signal it.
#![allow(dead_code)]

// Also a module of `common`, which some tests include beside this one.
#[allow(clippy::duplicate_mod)]
#[path = "../common/stale.rs"]
mod stale;

use lumen::checkpoint::default_path;
use lumen::progressive::{Session, StopReason};
use lumen::scene::{builtin, Overrides};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The render every interrupt test uses: several passes, about a second.
pub const RENDER: &[&str] = &["render", "cover", "--width", "160", "--spp", "64"];

/// A fresh empty directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    stale::remove_stale_dirs(&format!("lumen-test-{name}-"));
    let dir = std::env::temp_dir().join(format!("lumen-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn lumen() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lumen"))
}

/// Runs lumen with `args` to the end.
pub fn lumen_output(args: &[&str]) -> Output {
    lumen().args(args).output().expect("the lumen binary runs")
}

/// A finished run's stderr as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts a run that failed without a panic; returns its stderr.
pub fn refused_stderr(out: &Output) -> String {
    let err = stderr(out);
    assert!(!out.status.success(), "succeeded: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    err
}

/// Asserts a run that failed, without a panic, with a first stderr line
/// containing every one of `words`.
pub fn assert_refused(out: &Output, words: &[&str]) {
    let err = refused_stderr(out);
    let first = err.lines().next().unwrap_or("");
    for w in words {
        assert!(first.contains(w), "{w:?} not in {first:?}\n{err}");
    }
}

/// Runs lumen to the end; returns its status and stderr.
pub fn run(args: &[&str], out: &Path, extra: &[&str]) -> (ExitStatus, String) {
    let o = lumen()
        .args(args)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    (o.status, String::from_utf8_lossy(&o.stderr).into_owned())
}

/// The bytes of an uninterrupted render of `args` to a PFM file in `dir`.
pub fn reference(dir: &Path, args: &[&str]) -> Vec<u8> {
    let out = dir.join("reference.pfm");
    let (status, err) = run(args, &out, &[]);
    assert!(status.success(), "{err}");
    std::fs::read(out).unwrap()
}

/// A running lumen whose stderr lines are collected as they come.
pub struct Running {
    pub child: Child,
    lines: Receiver<String>,
    pub stderr: Arc<Mutex<Vec<String>>>,
}

pub fn spawn(args: &[&str], out: &Path, extra: &[&str]) -> Running {
    let mut child = lumen()
        .args(args)
        .arg("-o")
        .arg(out)
        .args(extra)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let (tx, lines) = mpsc::channel();
    let stderr = Arc::new(Mutex::new(Vec::new()));
    let all = Arc::clone(&stderr);
    let pipe = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            all.lock().unwrap().push(line.clone());
            let _ = tx.send(line);
        }
    });
    Running {
        child,
        lines,
        stderr,
    }
}

impl Running {
    /// Waits (up to a minute) for a stderr line starting with `prefix`.
    pub fn wait_line(&self, prefix: &str) -> String {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if line.starts_with(prefix) => return line,
                Ok(_) => {}
                Err(e) => panic!(
                    "no line starting with {prefix:?}: {e}; stderr so far: {:?}",
                    self.stderr.lock().unwrap()
                ),
            }
        }
    }

    pub fn signal(&self, signal: i32) {
        // SAFETY: kill(2) on our own child's pid, which is not yet reaped.
        let r = unsafe { libc::kill(self.child.id() as libc::pid_t, signal) };
        assert_eq!(r, 0, "kill failed");
    }

    /// Waits for the exit; returns the status and the whole stderr.
    pub fn finish(mut self) -> (ExitStatus, String) {
        let status = self.child.wait().unwrap();
        // Let the reader thread drain the pipe.
        while self.lines.recv_timeout(Duration::from_secs(10)).is_ok() {}
        let text = self.stderr.lock().unwrap().join("\n");
        (status, text)
    }
}

/// The `N` of "holds N of M spp" in lumen's report.
pub fn held_spp(stderr: &str) -> u32 {
    let at = stderr
        .find(" holds ")
        .unwrap_or_else(|| panic!("no 'holds' in: {stderr}"));
    stderr[at + 7..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// Checks that `bytes` is a complete PFM file of `w`×`h` pixels.
pub fn assert_valid_pfm(bytes: &[u8], w: usize, h: usize) {
    let header = format!("PF\n{w} {h}\n-1.0\n");
    assert!(bytes.starts_with(header.as_bytes()), "bad PFM header");
    assert_eq!(
        bytes.len(),
        header.len() + w * h * 12,
        "PFM has the wrong length"
    );
}

/// Names of the files in `dir` that end with `suffix`.
pub fn files_ending(dir: &Path, suffix: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(suffix))
        .collect()
}

/// Names of files in `dir` left by an atomic write that never finished.
pub fn temp_files(dir: &Path) -> Vec<String> {
    files_ending(dir, ".tmp")
}

/// Writes, through the library, the checkpoint that `lumen render cover
/// --width 48 --spp 16 -o out` leaves after `passes` passes.
pub fn make_checkpoint(out: &Path, passes: u32) -> Vec<u8> {
    let mut desc = builtin::find("cover").unwrap().desc();
    Overrides {
        width: Some(48),
        samples_per_pixel: Some(16),
        ..Overrides::default()
    }
    .apply(&mut desc);
    let mut session = Session::new(&desc).unwrap();
    let stop = AtomicBool::new(false);
    let run = session
        .run(&stop, None, &|_| {}, &mut |_, pass| {
            if pass.number == passes {
                stop.store(true, Ordering::SeqCst);
            }
            Ok::<(), ()>(())
        })
        .unwrap();
    assert_eq!(run.reason, StopReason::Interrupted);
    let path = default_path(out);
    session.checkpoint().write(&path).unwrap();
    std::fs::read(path).unwrap()
}

/// Runs `cmd` to the end; returns its output and its peak resident memory
/// in MB (`ru_maxrss` of this child alone, from `wait4`: unlike
/// `RUSAGE_CHILDREN`, not the largest of every child waited for so far).
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes, reason = "reaped by wait4, not by std")]
pub fn output_and_peak_mb(mut cmd: Command) -> (Output, f64) {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the lumen binary runs");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let stdout = std::thread::spawn(move || {
        let mut v = Vec::new();
        out.read_to_end(&mut v).unwrap();
        v
    });
    let mut stderr = Vec::new();
    err.read_to_end(&mut stderr).unwrap();
    let stdout = stdout.join().unwrap();
    let mut status = 0;
    // SAFETY: an all-zero rusage is valid (integers only); wait4 fills it
    // and the status for the child it reaps, which std has not waited for.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = child.id() as libc::pid_t;
    assert_eq!(unsafe { libc::wait4(pid, &mut status, 0, &mut usage) }, pid);
    let output = Output {
        status: ExitStatus::from_raw(status),
        stdout,
        stderr,
    };
    // ru_maxrss is in kilobytes on Linux.
    (output, usage.ru_maxrss as f64 / 1024.0)
}

/// Writes a binary PLY grid of `side` × `side` quads, two triangles each,
/// bent into a wave (`scripts/make_big_ply.py`), and a scene of it.
pub fn write_grid(dir: &Path, side: usize) -> std::path::PathBuf {
    use std::io::Write;
    let n = side + 1;
    let triangles = 2 * side * side;
    let mut out = std::io::BufWriter::new(std::fs::File::create(dir.join("grid.ply")).unwrap());
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {triangles}\n\
         property list uchar int vertex_indices\nend_header\n",
        n * n
    )
    .unwrap();
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (
                i as f32 / side as f32 * 2.0 - 1.0,
                j as f32 / side as f32 * 2.0 - 1.0,
            );
            for c in [u, 0.1 * (6.0 * u).sin() * (4.0 * v).cos(), v] {
                out.write_all(&c.to_le_bytes()).unwrap();
            }
        }
    }
    for j in 0..side {
        for i in 0..side {
            let a = (i + n * j) as i32;
            let (b, c, d) = (a + 1, a + n as i32 + 1, a + n as i32);
            for t in [[a, b, c], [a, c, d]] {
                out.write_all(&[3]).unwrap();
                t.iter()
                    .for_each(|x| out.write_all(&x.to_le_bytes()).unwrap());
            }
        }
    }
    out.flush().unwrap();
    let scene = dir.join("grid.toml");
    std::fs::write(&scene, mesh_scene("grid.ply")).unwrap();
    scene
}

/// A scene of the mesh `file` under the default sky.
pub fn mesh_scene(file: &str) -> String {
    format!(
        "[render]\nwidth = 64\nheight = 64\nsamples_per_pixel = 1\nmax_depth = 4\n\
         [camera]\nvfov = 40\nlookfrom = [0, 3, 4]\nlookat = [0, 0, 0]\n\
         [materials.clay]\ntype = \"diffuse\"\nalbedo = [0.7, 0.7, 0.7]\n\
         [[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"clay\"\n"
    )
}
