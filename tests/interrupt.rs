//! Interrupting a real `lumen` process (SIGINT, SIGTERM, SIGKILL) and
//! resuming it gives the same image, bit for bit, as a render never stopped.

mod lumen_process;

use lumen::checkpoint::{default_path, Checkpoint};
use lumen::output::encode_pfm;
use lumen_process::*;
use std::path::Path;
use std::time::{Duration, Instant};

const W: usize = 160;
const H: usize = 90;

/// After a stop: the image and the checkpoint are complete, agree with each
/// other and with what lumen reported; returns the samples per pixel held.
fn check_saved(out: &Path, stderr: &str) -> u32 {
    let ckpt = Checkpoint::read(&default_path(out)).unwrap_or_else(|e| panic!("{e}"));
    let image = std::fs::read(out).unwrap();
    assert_valid_pfm(&image, W, H);
    assert_eq!(
        image,
        encode_pfm(&ckpt.film),
        "image and checkpoint disagree"
    );
    assert_eq!(ckpt.spp_done, held_spp(stderr), "{stderr}");
    assert!(ckpt.spp_done > 0 && ckpt.spp_done < 64);
    ckpt.spp_done
}

/// Resumes the render in `out`'s checkpoint to the end and compares it with
/// the reference; the finished render removes its checkpoint.
fn resume_to_end(out: &Path, reference: &[u8]) {
    let (status, err) = run(RENDER, out, &["--resume"]);
    assert!(status.success(), "{err}");
    assert!(err.contains("resuming at"), "{err}");
    assert!(
        std::fs::read(out).unwrap() == reference,
        "resumed image differs from the uninterrupted one"
    );
    assert!(
        !default_path(out).exists(),
        "checkpoint left after a finished render"
    );
}

#[test]
fn sigint_and_sigterm_at_several_moments_then_resume_bit_identical() {
    let dir = temp_dir("interrupt");
    let reference = reference(&dir, RENDER);
    // (signal, wait for the report of this pass before signalling)
    let moments = [
        (libc::SIGINT, "pass 1:"),
        (libc::SIGINT, "pass 6:"),
        (libc::SIGTERM, "pass 4:"),
    ];
    for (i, (signal, after)) in moments.into_iter().enumerate() {
        let out = dir.join(format!("moment{i}.pfm"));
        let r = spawn(RENDER, &out, &[]);
        r.wait_line(after);
        r.signal(signal);
        let (status, err) = r.finish();
        assert_eq!(status.code(), Some(130), "{err}");
        assert!(err.contains("interrupted"), "{err}");
        let held = check_saved(&out, &err);
        assert!(temp_files(&dir).is_empty(), "{:?}", temp_files(&dir));
        // Stop the resumed render too, once, then finish it.
        let r = spawn(RENDER, &out, &["--resume"]);
        r.wait_line("pass 1:");
        r.signal(libc::SIGINT);
        let (status, err) = r.finish();
        assert_eq!(status.code(), Some(130), "{err}");
        assert!(check_saved(&out, &err) > held);
        resume_to_end(&out, &reference);
    }
}

#[test]
fn a_second_interrupt_exits_at_once_leaving_complete_files() {
    let dir = temp_dir("twice");
    let reference = reference(&dir, RENDER);
    let out = dir.join("twice.pfm");
    // Saved after every pass, so that passes 1 and 2 are on disk.
    let r = spawn(RENDER, &out, &["--checkpoint-interval", "0"]);
    r.wait_line("pass 3:");
    // Two different signals, so that the kernel cannot merge them into one.
    r.signal(libc::SIGINT);
    r.signal(libc::SIGTERM);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("stopped at once"), "{err}");
    assert!(temp_files(&dir).is_empty(), "{:?}", temp_files(&dir));
    // Whatever was saved is whole and usable.
    let ckpt = Checkpoint::read(&default_path(&out)).unwrap_or_else(|e| panic!("{e}"));
    assert_valid_pfm(&std::fs::read(&out).unwrap(), W, H);
    assert!(ckpt.spp_done >= 2);
    resume_to_end(&out, &reference);
}

#[test]
fn checkpoint_interval_saves_less_often_but_always_on_interrupt() {
    let dir = temp_dir("interval");
    let out = dir.join("interval.pfm");
    let r = spawn(RENDER, &out, &["--checkpoint-interval", "1h"]);
    r.wait_line("pass 4:");
    assert!(!default_path(&out).exists(), "saved before the interval");
    assert!(!out.exists(), "saved before the interval");
    r.signal(libc::SIGINT);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(check_saved(&out, &err) >= 8);
}

/// SIGKILL at any moment, including while a checkpoint is being written,
/// leaves the previous complete checkpoint, from which the render resumes.
#[test]
fn sigkill_during_checkpoint_writes_leaves_a_usable_checkpoint() {
    let dir = temp_dir("sigkill");
    let reference = reference(&dir, RENDER);
    let out = dir.join("killed.pfm");
    let ckpt_path = default_path(&out);
    let mut kills_during_a_write = 0;
    let mut last_spp = 0;
    let mut rounds = 0;
    // Eight rounds, or more (up to 24) until a kill lands mid-write: whether
    // one does depends on timing, which a loaded machine can stretch.
    for round in 0..24 {
        if round >= 8 && kills_during_a_write > 0 {
            break;
        }
        rounds += 1;
        let resume = ckpt_path.exists();
        // Saved after every pass: as many writes to land in as there are.
        let all = ["--checkpoint-interval", "0", "--resume"];
        let extra = if resume { &all[..] } else { &all[..2] };
        let r = spawn(RENDER, &out, extra);
        // The name lumen::output::temp_path gives in the child process.
        let tmp = dir.join(format!(".killed.pfm.lumen-ckpt.{}.tmp", r.child.id()));
        // Kill during the (round % 3 + 1)-th checkpoint write of this run,
        // seen as the temporary file's appearance; or after a while.
        let wanted = round % 3 + 1;
        let (mut seen, mut present) = (0, false);
        let give_up = Instant::now() + Duration::from_secs(20);
        while seen < wanted && Instant::now() < give_up {
            let now = tmp.exists();
            if now && !present {
                seen += 1;
            }
            present = now;
            // Poll often enough to see a write, without taking a core.
            std::thread::sleep(Duration::from_micros(100));
        }
        r.signal(libc::SIGKILL);
        let (status, err) = r.finish();
        if status.success() {
            // It finished before the kill (a write was missed): start again.
            assert!(std::fs::read(&out).unwrap() == reference, "{err}");
            last_spp = 0;
            continue;
        }
        if tmp.exists() {
            kills_during_a_write += 1;
            std::fs::remove_file(&tmp).unwrap();
        }
        if ckpt_path.exists() {
            let ckpt =
                Checkpoint::read(&ckpt_path).unwrap_or_else(|e| panic!("round {round}: {e}"));
            assert!(ckpt.spp_done >= last_spp, "checkpoint went back");
            last_spp = ckpt.spp_done;
        }
    }
    eprintln!(
        "{kills_during_a_write} of {rounds} kills landed during a checkpoint write; {last_spp} spp saved"
    );
    assert!(
        kills_during_a_write > 0,
        "no kill landed during a checkpoint write"
    );
    for name in temp_files(&dir) {
        std::fs::remove_file(dir.join(name)).unwrap();
    }
    if ckpt_path.exists() {
        resume_to_end(&out, &reference);
    }
}

#[test]
fn an_interrupt_during_the_first_pass_writes_nothing() {
    let dir = temp_dir("first-pass");
    let out = dir.join("first.pfm");
    // A first pass long enough (most of a second) to be interrupted in.
    let r = spawn(
        &["render", "cover", "--width", "1200", "--spp", "4"],
        &out,
        &[],
    );
    r.wait_line("cover:");
    r.signal(libc::SIGINT);
    let (status, err) = r.finish();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(
        err.contains("before the first pass finished; nothing written"),
        "{err}"
    );
    assert!(!out.exists() && !default_path(&out).exists());
    assert!(temp_files(&dir).is_empty());
}
