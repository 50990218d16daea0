//! Peak memory of a full-size cover render, measured on the real binary.

#![cfg(target_os = "linux")]
//!
//! The film of a 1200×675 image takes 52 bytes a pixel (three `i128`
//! fixed-point sums and a u32 count, 42 MB); a pass in flight keeps a copy to restore if it is abandoned, and
//! checkpoints and images are encoded without full-size intermediate copies.
//! This file holds one test only: `RUSAGE_CHILDREN` reports the largest child
//! this test process has waited for.

mod common;
mod lumen_process;

#[test]
fn full_size_cover_render_stays_under_100_mb() {
    let dir = lumen_process::temp_dir("memory");
    let out = dir.join("cover.png");
    let (status, stderr) = lumen_process::run(
        &["render", "cover", "--spp", "2", "--depth", "8"],
        &out,
        &[],
    );
    assert!(status.success(), "{stderr}");
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (1200, 675));

    let peak_mb = common::children_peak_mb();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        peak_mb > 42.0,
        "peak {peak_mb:.1} MB is below the film's own size: not measured"
    );
    assert!(peak_mb < 100.0, "peak memory {peak_mb:.1} MB");
}
