//! The files around a render: only regular files are read or replaced, a
//! second render to the same files is refused, derived names fit however
//! long the output's name, a stray file at the checkpoint path is told from
//! a damaged checkpoint, and temporaries of killed renders are removed.

mod lumen_process;

use lumen::checkpoint::{default_path, Checkpoint};
use lumen_process::*;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, ExitStatus};
use std::time::{Duration, Instant};

const SMALL: &[&str] = &["render", "cover", "--width", "48", "--spp", "16"];

/// Runs lumen, killing it if it has not ended within 30 s (a read of a
/// named pipe would wait for ever).
fn run_bounded(args: &[&str], out: &Path, extra: &[&str]) -> (ExitStatus, String) {
    let r = spawn(args, out, extra);
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut child = r.child;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            std::thread::sleep(Duration::from_millis(50));
            let text = r.stderr.lock().unwrap().join("\n");
            return (status, text);
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("lumen {args:?} {extra:?} hangs");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn refused(status: ExitStatus, err: &str, words: &[&str]) {
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!err.contains("pass 1"), "rendered before refusing: {err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in: {err}");
    }
}

#[test]
fn devices_pipes_and_directories_are_never_replaced_nor_read() {
    let dir = temp_dir("non-regular");
    let fifo = dir.join("pipe");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    std::fs::create_dir(dir.join("folder")).unwrap();
    let out = dir.join("out.pfm");
    let fifo_s = fifo.to_str().unwrap();
    let folder = dir.join("folder");
    let folder_s = folder.to_str().unwrap();
    for extra in [
        &["--checkpoint", fifo_s][..],
        &["--checkpoint", fifo_s, "--resume"],
        &["--checkpoint", "/dev/zero", "--resume"],
        &["--checkpoint", folder_s],
        &["--checkpoint", folder_s, "--resume"],
    ] {
        let (status, err) = run_bounded(SMALL, &out, extra);
        let what = match extra[1] {
            "/dev/zero" => "a character device",
            s if s == fifo_s => "a named pipe",
            _ => "a directory",
        };
        refused(status, &err, &[what, "not a regular file"]);
        assert!(!out.exists());
    }
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // The library reads no pipe either.
    let e = lumen::checkpoint::Checkpoint::read(&fifo)
        .unwrap_err()
        .to_string();
    assert!(e.contains("a named pipe"), "{e}");
    // A pipe as the image.
    let pipe_image = dir.join("image-pipe.pfm");
    assert!(Command::new("mkfifo")
        .arg(&pipe_image)
        .status()
        .unwrap()
        .success());
    let (status, err) = run_bounded(SMALL, &pipe_image, &[]);
    refused(status, &err, &["a named pipe"]);
    assert!(std::fs::metadata(&pipe_image)
        .unwrap()
        .file_type()
        .is_fifo());

    // A null device of our own, as root may make one: what `--checkpoint
    // /dev/null` did to /dev/null (replaced, then removed) it would do here.
    let null = dir.join("null");
    let made = Command::new("mknod")
        .arg(&null)
        .args(["c", "1", "3"])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        let (status, err) = run_bounded(SMALL, &out, &["--checkpoint", null.to_str().unwrap()]);
        refused(status, &err, &["a character device"]);
        assert!(std::fs::metadata(&null)
            .unwrap()
            .file_type()
            .is_char_device());
    }
    // /dev/null itself is only asked about, never written to.
    let e = lumen::output::check_writable(Path::new("/dev/null"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a character device"), "{e}");
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

#[test]
fn a_second_render_to_the_same_files_is_refused_naming_the_first() {
    let dir = temp_dir("two-renders");
    let out = dir.join("out.pfm");
    let b = spawn(
        &[
            "render", "cover", "--width", "160", "--spp", "4096", "--seed", "5",
        ],
        &out,
        &[],
    );
    // The checkpoint is saved after a pass is reported, before the next.
    b.wait_line("pass 3:");
    let ckpt = default_path(&out);
    let saved = Checkpoint::read(&ckpt).unwrap();
    let holder = format!("process {}", b.child.id());
    let (status, err) = run(&["render", "gradient", "--spp", "4"], &out, &[]);
    refused(status, &err, &["in use by another lumen render", &holder]);
    // The same checkpoint for another image.
    let other = dir.join("other.pfm");
    let (status, err) = run(
        &["render", "gradient", "--spp", "4"],
        &other,
        &["--checkpoint", ckpt.to_str().unwrap()],
    );
    refused(status, &err, &["in use by another lumen render", &holder]);
    assert!(!other.exists());
    assert!(ckpt.exists(), "the running render's checkpoint was removed");
    // Still the running render's (rewritten between passes, its size
    // changing with the samples it holds).
    let now = Checkpoint::read(&ckpt).unwrap();
    assert_eq!(now.description, saved.description);
    assert!(now.spp_done >= saved.spp_done);
    b.signal(libc::SIGINT);
    let (status, err) = b.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    let left = files_ending(&dir, ".lumen-lock");
    assert!(left.is_empty(), "lock files left: {left:?}");
    // Now free, the files can be rendered to again.
    let (status, err) = run(&["render", "gradient", "--spp", "4"], &out, &[]);
    assert!(status.success(), "{err}");
}

#[test]
fn output_names_up_to_the_file_system_limit_work() {
    let dir = temp_dir("long-names");
    for len in [234, 240, 250, 255] {
        let name = format!("{}.pfm", "n".repeat(len - 4));
        let out = dir.join(&name);
        let (status, err) = run(
            &["render", "gradient", "--width", "16", "--spp", "8"],
            &out,
            &[],
        );
        assert!(status.success(), "{len} bytes: {err}");
        assert!(out.exists());
        let mut left = files_ending(&dir, "");
        left.retain(|n| *n != name && !n.ends_with(".pfm"));
        assert!(left.is_empty(), "{len} bytes: files left: {left:?}");
    }
    // Interrupted and resumed under a 255-byte name: the checkpoint is
    // found again by its shortened name.
    let out = dir.join(format!("{}.pfm", "r".repeat(251)));
    let r = spawn(RENDER, &out, &[]);
    r.wait_line("pass 3:");
    r.signal(libc::SIGINT);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(default_path(&out).exists());
    let (status, err) = run(RENDER, &out, &["--resume"]);
    assert!(status.success(), "{err}");
    assert!(err.contains("resuming at"), "{err}");
    assert!(!default_path(&out).exists());
}

#[test]
fn a_stray_file_is_told_from_a_damaged_checkpoint() {
    let dir = temp_dir("stray");
    let out = dir.join("out.pfm");
    let ckpt = default_path(&out);
    // Someone's file where the checkpoint goes: kept, and said what it is.
    std::fs::write(&ckpt, "my notes\n").unwrap();
    for extra in [&[][..], &["--resume"]] {
        let (status, err) = run(SMALL, &out, extra);
        refused(
            status,
            &err,
            &[
                "not a lumen checkpoint but a text file of 9 bytes",
                "move or delete it",
                "--checkpoint",
            ],
        );
        assert_eq!(std::fs::read_to_string(&ckpt).unwrap(), "my notes\n");
    }
    // A checkpoint whose magic bytes were damaged.
    let mut damaged = make_checkpoint(&out, 3);
    damaged[..8].copy_from_slice(b"XXXXXXXX");
    std::fs::write(&ckpt, &damaged).unwrap();
    let (status, err) = run(SMALL, &out, &["--resume"]);
    refused(status, &err, &["damaged", "without --resume"]);
    assert!(!err.contains("not a lumen checkpoint"), "{err}");
    let (status, err) = run(SMALL, &out, &[]);
    assert!(status.success(), "{err}");
    assert!(err.contains("the damaged checkpoint"), "{err}");
}

#[test]
fn temporaries_of_killed_renders_are_removed() {
    let dir = temp_dir("stale");
    let out = dir.join("out.pfm");
    // Process ids above the kernel's limit (2^22) never run.
    let stale = [
        ".out.pfm.4000000000.tmp",
        ".out.pfm.lumen-ckpt.4000000001.tmp",
    ];
    let live = format!(".out.pfm.{}.tmp", std::process::id());
    let kept = [
        live.as_str(),
        ".out.pfm.12ab.tmp",
        ".other.pfm.4000000002.tmp",
    ];
    for name in stale.iter().chain(&kept) {
        std::fs::write(dir.join(name), "partial").unwrap();
    }
    let (status, err) = run(SMALL, &out, &[]);
    assert!(status.success(), "{err}");
    assert!(err.contains("removed 2 temporary files"), "{err}");
    for name in stale {
        assert!(!dir.join(name).exists(), "{name} left");
    }
    for name in kept {
        assert!(dir.join(name).exists(), "{name} removed");
    }
}

#[test]
fn help_documents_interrupts_and_exit_status() {
    let o = lumen().args(["render", "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&o.stdout);
    for words in ["Ctrl-C", "--resume", "Exit status", "130", "lock file"] {
        assert!(help.contains(words), "{words:?} not in: {help}");
    }
}

#[test]
fn editing_the_caption_or_the_gamma_keeps_the_checkpoint() {
    let dir = temp_dir("caption");
    let scene = dir.join("c.toml");
    let o = lumen()
        .args(["scenes", "export", "cover", "-o"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = std::fs::read_to_string(&scene).unwrap();
    let args = [
        "render",
        scene.to_str().unwrap(),
        "--width",
        "160",
        "--spp",
        "64",
    ];
    let out = dir.join("c.pfm");
    let r = spawn(&args, &out, &[]);
    r.wait_line("pass 3:");
    r.signal(libc::SIGINT);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    let edited = text
        .replace("caption = \"The cover", "caption = \"Edited: the cover")
        .replace("gamma = 2.0", "gamma = 2.2");
    assert_ne!(edited, text);
    std::fs::write(&scene, edited).unwrap();
    let (status, err) = run(&args, &out, &["--resume"]);
    assert!(status.success(), "{err}");
    assert!(err.contains("resuming at"), "{err}");
}
