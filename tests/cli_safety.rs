//! The command line never destroys a user's files and never panics on a
//! closed or full standard output.

mod lumen_process;

use lumen_process::{assert_valid_pfm, lumen, refused_stderr, temp_dir};
use std::path::Path;
use std::process::{Output, Stdio};

/// Runs lumen to the end in `dir`.
fn lumen_in(dir: &Path, args: &[&str]) -> Output {
    lumen().current_dir(dir).args(args).output().unwrap()
}

fn refused_with(out: &Output, words: &[&str]) {
    let err = refused_stderr(out);
    for w in words {
        assert!(err.contains(w), "{err:?} lacks {w:?}");
    }
}

#[test]
fn a_checkpoint_path_naming_the_output_the_scene_or_a_foreign_file_is_refused() {
    let dir = temp_dir("safety-ckpt");
    fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        [extra, &["--width", "8", "--spp", "2"][..]].concat()
    }

    // The output image, however it is spelled.
    let spelled = dir.join("out.png");
    for ckpt in ["out.png", "./out.png", spelled.to_str().unwrap()] {
        let out = lumen_in(
            &dir,
            &with(&["render", "gradient", "-o", "out.png", "--checkpoint", ckpt]),
        );
        refused_with(&out, &["checkpoint cannot be the output image"]);
        assert!(!dir.join("out.png").exists());
    }

    // The scene file being rendered.
    assert!(
        lumen_in(&dir, &["scenes", "export", "gradient", "-o", "g.toml"])
            .status
            .success()
    );
    let scene = std::fs::read(dir.join("g.toml")).unwrap();
    let out = lumen_in(
        &dir,
        &with(&[
            "render",
            "g.toml",
            "-o",
            "x.png",
            "--checkpoint",
            "./g.toml",
        ]),
    );
    refused_with(&out, &["checkpoint cannot be the scene file"]);
    assert_eq!(std::fs::read(dir.join("g.toml")).unwrap(), scene);

    // Any other existing file that is not a checkpoint.
    std::fs::write(dir.join("notes.txt"), "keep me").unwrap();
    let out = lumen_in(
        &dir,
        &with(&[
            "render",
            "gradient",
            "-o",
            "y.png",
            "--checkpoint",
            "notes.txt",
        ]),
    );
    refused_with(&out, &["notes.txt", "not a lumen checkpoint"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "keep me"
    );
    assert!(!dir.join("y.png").exists());

    // With nothing at the default checkpoint path, the same render goes ahead.
    let ok = lumen_in(&dir, &with(&["render", "gradient", "-o", "z.png"]));
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_closed_pipe_ends_output_quietly_and_a_full_device_is_an_error() {
    // Read one line, then close the pipe while lumen still writes.
    let mut child = lumen()
        .args(["scenes", "export", "cover"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 16];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(out.status.success(), "{err}");

    if Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = lumen().arg("scenes").stdout(full).output().unwrap();
        refused_with(&out, &["cannot write to standard output"]);
    }
}

#[test]
fn a_closed_standard_error_lets_the_render_finish() {
    // `lumen render … 2>&1 | head -5`: the reader goes away while lumen
    // still reports passes.
    let dir = temp_dir("closed-stderr");
    let out = dir.join("p.pfm");
    let mut child = lumen()
        .args([
            "render",
            "cover",
            "--width",
            "64",
            "--spp",
            "16",
            "--threads",
            "1",
        ])
        .arg("-o")
        .arg(&out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    let image = std::fs::read(&out).unwrap();
    assert_valid_pfm(&image, 64, 36);
    assert!(!lumen::checkpoint::default_path(&out).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
