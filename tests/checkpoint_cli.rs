//! `lumen render` refuses checkpoints that are damaged or belong to another
//! render, refuses unwritable outputs before rendering, and keeps to a time
//! limit.

mod lumen_process;

use lumen::checkpoint::{default_path, Checkpoint};
use lumen_process::*;
use std::path::Path;

const SMALL: &[&str] = &["render", "cover", "--width", "48", "--spp", "16"];

/// Runs `--resume` expecting a refusal that mentions every one of `words`;
/// the checkpoint must be left as it was and no image written.
fn assert_refused(args: &[&str], out: &Path, words: &[&str]) {
    let before = std::fs::read(default_path(out)).ok();
    let (status, err) = run(args, out, &["--resume"]);
    assert_eq!(status.code(), Some(1), "{err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in: {err}");
    }
    assert!(!err.contains("pass 1"), "rendered before refusing: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        std::fs::read(default_path(out)).ok(),
        before,
        "checkpoint changed"
    );
    assert!(!out.exists(), "image written");
}

#[test]
fn a_checkpoint_made_by_the_library_resumes_bit_identically() {
    let dir = temp_dir("library-ckpt");
    let reference = reference(&dir, SMALL);
    let out = dir.join("out.pfm");
    make_checkpoint(&out, 3);
    let (status, err) = run(SMALL, &out, &["--resume"]);
    assert!(status.success(), "{err}");
    assert!(err.contains("resuming at 4 spp"), "{err}");
    assert!(std::fs::read(&out).unwrap() == reference);
}

#[test]
fn corrupted_and_truncated_checkpoints_are_refused() {
    let dir = temp_dir("corrupt");
    let out = dir.join("out.pfm");
    let good = make_checkpoint(&out, 3);
    let path = default_path(&out);
    // A flipped bit in the header, in the description, in the pixels.
    for at in [9, 40, good.len() / 2, good.len() - 1] {
        let mut bad = good.clone();
        bad[at] ^= 0x04;
        std::fs::write(&path, &bad).unwrap();
        let expected: &[&str] = match at {
            9 => &["format version"],
            _ => &["corrupted", "checksum"],
        };
        assert_refused(SMALL, &out, expected);
    }
    for len in [0, 10, 30, good.len() - 1] {
        std::fs::write(&path, &good[..len]).unwrap();
        let expected: &[&str] = if len < 8 {
            &["not a lumen checkpoint"]
        } else {
            &["truncated"]
        };
        assert_refused(SMALL, &out, expected);
    }
    std::fs::write(&path, b"P3\n1 1\n255\n0 0 0\n").unwrap();
    assert_refused(SMALL, &out, &["not a lumen checkpoint"]);
    std::fs::remove_file(&path).unwrap();
    assert_refused(SMALL, &out, &["no checkpoint at"]);
}

#[test]
fn checkpoints_of_other_renders_are_refused_naming_the_difference() {
    let dir = temp_dir("mismatch");
    let out = dir.join("out.pfm");
    make_checkpoint(&out, 3);
    let with = |extra: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = SMALL.iter().map(|s| s.to_string()).collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["--seed", "5"],
            &["different render", "seed 0 in the checkpoint, 5 here"],
        ),
        (&["--depth", "7"], &["depth 50 in the checkpoint, 7 here"]),
    ];
    for (extra, words) in cases {
        let args = with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_refused(&args, &out, words);
    }
    assert_refused(
        &["render", "cover", "--width", "48", "--spp", "32"],
        &out,
        &["spp 16 in the checkpoint, 32 here"],
    );
    assert_refused(
        &["render", "cover", "--width", "64", "--spp", "16"],
        &out,
        &["width 48 in the checkpoint, 64 here"],
    );
    assert_refused(
        &["render", "metal-mirror", "--width", "48", "--spp", "16"],
        &out,
        &["a different scene"],
    );
}

#[test]
fn unwritable_outputs_are_refused_before_rendering() {
    let dir = temp_dir("unwritable");
    std::fs::create_dir(dir.join("folder.png")).unwrap();
    let cases = [
        (dir.join("missing/out.png"), "does not exist"),
        (dir.join("folder.png"), "is a directory"),
    ];
    for (out, words) in cases {
        let (status, err) = run(SMALL, &out, &[]);
        assert_eq!(status.code(), Some(1), "{err}");
        assert!(err.contains(words), "{err}");
        assert!(!err.contains("pass 1"), "{err}");
    }
    let out = dir.join("out.png");
    let (status, err) = run(SMALL, &out, &["--checkpoint", "/nonexistent-dir/c.ckpt"]);
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(
        err.contains("checkpoint") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!out.exists());
    // Permissions do not hold back root, so this part needs another user.
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } != 0 {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.join("locked");
        std::fs::create_dir(&locked).unwrap();
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
        let (status, err) = run(SMALL, &locked.join("out.png"), &[]);
        assert_eq!(status.code(), Some(1), "{err}");
        assert!(err.contains("cannot write"), "{err}");
    }
}

/// Reported pass lines: (samples in the pass, seconds it took).
fn passes(stderr: &str) -> Vec<(u32, f64)> {
    stderr
        .lines()
        .filter(|l| l.starts_with("pass "))
        .map(|l| {
            let range = l.split_whitespace().nth(3).unwrap();
            let (a, b) = range.split_once("..").unwrap();
            let secs = l.split(" in ").nth(1).unwrap().split(' ').next().unwrap();
            let n = b.parse::<u32>().unwrap() - a.parse::<u32>().unwrap();
            (n, secs.parse().unwrap())
        })
        .collect()
}

#[test]
fn time_limit_stops_at_the_last_pass_within_budget() {
    let dir = temp_dir("time-limit");
    let out = dir.join("out.pfm");
    let args = ["render", "cover", "--width", "160", "--spp", "100000"];
    let started = std::time::Instant::now();
    let (status, err) = run(&args, &out, &["--time-limit", "1s"]);
    let wall = started.elapsed().as_secs_f64();
    assert!(status.success(), "{err}");
    assert!(err.contains("time limit reached"), "{err}");
    let done = passes(&err);
    // The whole process, saves and start-up included, ends within the budget
    // plus one pass plus a generous allowance for start-up and saving: a
    // render that ignored the limit would run for minutes.
    let longest = done.iter().map(|p| p.1).fold(0.0, f64::max);
    assert!(wall < 1.0 + longest + 3.0, "ran {wall} s: {err}");
    let held: u32 = done.iter().map(|p| p.0).sum();
    assert_eq!(held, held_spp(&err));
    assert!(held > 0 && held < 100_000);
    // Every pass kept finished within the budget, by lumen's own clock.
    let rendering: f64 = done.iter().map(|p| p.1).sum();
    assert!(rendering <= 1.0, "passes took {rendering} s: {err}");
    assert_valid_pfm(&std::fs::read(&out).unwrap(), 160, 90);
    let ckpt = Checkpoint::read(&default_path(&out)).unwrap();
    assert_eq!(ckpt.spp_done, held);
    // A second budget continues from there.
    let (status, err) = run(&args, &out, &["--time-limit", "1s", "--resume"]);
    assert!(status.success(), "{err}");
    assert!(held_spp(&err) > held, "{err}");
}

#[test]
fn bad_durations_are_refused() {
    for bad in ["0s", "soon", "-3m", "5d"] {
        let arg = format!("--time-limit={bad}");
        let (status, err) = run(SMALL, Path::new("x.png"), &[&arg]);
        assert_eq!(status.code(), Some(2), "{err}");
        assert!(err.contains("--time-limit"), "{err}");
    }
}
