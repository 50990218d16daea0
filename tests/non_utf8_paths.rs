//! Paths that are not UTF-8 (legal on Unix): an output image by such a name
//! is written, and a scene file by such a name is refused with a message of
//! lumen's own, not the argument parser's.

#![cfg(unix)]

mod lumen_process;

use lumen_process::{lumen, temp_dir};
use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;

#[test]
fn an_output_path_that_is_not_utf8_is_written() {
    let dir = temp_dir("non-utf8-out");
    let out = dir.join(OsStr::from_bytes(b"caf\xe9.png"));
    let run = lumen()
        .args(["render", "gradient", "--width", "8", "--spp", "1", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // Nothing else is left beside it (no temporary, no checkpoint).
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn a_scene_path_that_is_not_utf8_is_refused_clearly() {
    let dir = temp_dir("non-utf8-scene");
    let scene = dir.join(OsStr::from_bytes(b"sc\xe8ne.toml"));
    std::fs::write(&scene, "").unwrap();
    for command in [&["render"][..], &["scenes", "export"][..]] {
        let run = lumen()
            .args(command)
            .arg(&scene)
            .args(["-o", dir.join("out.png").to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains("is not valid UTF-8: rename the file"), "{err}");
        assert!(
            !err.contains("invalid UTF-8 was detected"),
            "clap's message: {err}"
        );
    }
    assert!(!dir.join("out.png").exists());
}
