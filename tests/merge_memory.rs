//! Peak memory of `lumen merge`, measured on the real binary: the film of
//! the image and a few parts' files, however many parts there are.
#![cfg(target_os = "linux")]
//!
//! The parts are rendered in this process, through the library, so that the
//! merge is the only child: `RUSAGE_CHILDREN` reports the largest child this
//! test process has waited for. This file holds one test only.

mod common;
mod lumen_process;

use lumen::part::{Part, Share};

#[test]
fn merging_many_parts_holds_the_film_and_a_few_parts_only() {
    let dir = lumen_process::temp_dir("merge-memory");
    let count = 24;
    let desc = common::builtin_desc("gradient", 1200, count, 1);
    let parts: Vec<_> = (0..count)
        .map(|index| {
            let share = Share {
                part: Some(Part { index, count }),
                ..Share::default()
            };
            let path = lumen::part::file_name(&dir, share.part.unwrap());
            common::write_share(&desc, share, &path, None)
        })
        .collect();
    let part_mb = (parts.iter())
        .map(|p| std::fs::metadata(p).unwrap().len())
        .max()
        .unwrap() as f64
        / (1024.0 * 1024.0);
    let out = dir.join("merged.pfm");
    let o = lumen_process::lumen()
        .arg("merge")
        .args(&parts)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let peak_mb = common::children_peak_mb();
    std::fs::remove_dir_all(&dir).unwrap();
    // The image's film: 52 bytes a pixel.
    let film_mb = 1200.0 * 675.0 * 52.0 / (1024.0 * 1024.0);
    assert!(
        peak_mb > film_mb,
        "peak {peak_mb:.1} MB is below the film's own size: not measured"
    );
    // The film, at most three parts' files (one merged, one waiting, one
    // being read), and 16 MB for the program itself; holding every part
    // would take 24 of them.
    let bound = film_mb + 3.0 * part_mb + 16.0;
    eprintln!("peak {peak_mb:.1} MB: film {film_mb:.1} MB, parts of {part_mb:.1} MB");
    assert!(
        peak_mb < bound,
        "peak {peak_mb:.1} MB, more than {bound:.1} MB (film {film_mb:.1} MB, parts of {part_mb:.1} MB)"
    );
}
