//! Peak memory of a full-size cover render, measured on the real binary.
#![cfg(target_os = "linux")]
//!
//! The film of a 1200×675 image takes 28 bytes a pixel (f64 sums and a u32
//! count); a pass in flight keeps a copy to restore if it is abandoned, and
//! checkpoints and images are encoded without full-size intermediate copies.
//! This file holds one test only: `RUSAGE_CHILDREN` reports the largest child
//! this test process has waited for.

use std::process::Command;

#[test]
fn full_size_cover_render_stays_under_64_mb() {
    let dir = std::env::temp_dir().join(format!("lumen-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("cover.png");
    let status = Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args(["render", "cover", "--spp", "2", "--depth", "8", "-o"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (1200, 675));

    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage fills the struct it is given; zeroed is a valid rusage.
    #[allow(unsafe_code)]
    let usage = unsafe {
        assert_eq!(
            libc::getrusage(libc::RUSAGE_CHILDREN, usage.as_mut_ptr()),
            0
        );
        usage.assume_init()
    };
    // ru_maxrss is in kilobytes on Linux.
    let peak_mb = usage.ru_maxrss as f64 / 1024.0;
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        peak_mb > 22.0,
        "peak {peak_mb:.1} MB is below the film's own size: not measured"
    );
    assert!(peak_mb < 64.0, "peak memory {peak_mb:.1} MB");
}
