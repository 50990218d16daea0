//! A render split into parts by samples (`render --part K/N`) and merged
//! (`lumen merge`) is the render of one machine to the bit, whatever the
//! number of parts and the order they are merged in; parts that do not make
//! one render are refused, naming the files.

mod common;
mod lumen_process;

use common::builtin_desc as desc;
use lumen::part::{self, MergeError, Part, Share};
use lumen::progressive::Session;
use lumen::render::render;
use lumen::scene::{Scene, SceneDesc};
use lumen_process::*;
use std::path::{Path, PathBuf};

/// Renders `part` of `desc` through the library, stopping after `passes`
/// passes if given, and writes its part file into `dir`.
fn write_part(desc: &SceneDesc, part: Part, dir: &Path, passes: Option<u32>) -> PathBuf {
    let share = Share {
        part: Some(part),
        ..Share::default()
    };
    common::write_share(desc, share, &part::file_name(dir, part), passes)
}

fn one_machine(desc: &SceneDesc) -> lumen::film::Film {
    render(&Scene::from_desc(desc).unwrap(), &|_| {}).0
}

#[test]
fn merged_parts_are_the_one_machine_film_for_any_count_and_order() {
    let dir = temp_dir("parts-counts");
    // 5 spp and 7 parts: more parts than samples, some parts empty. The
    // feature buffers merge to the bit as the image does.
    let all = lumen::aov::Aov::ALL.to_vec();
    for (name, spp, counts, aovs) in [
        ("cover", 13, &[1, 2, 3, 7][..], vec![]),
        ("cornell-box", 5, &[2, 7][..], vec![]),
        ("cornell-box", 5, &[3][..], all),
    ] {
        let mut d = desc(name, 24, spp, 11);
        d.render.aovs = aovs;
        let whole = one_machine(&d);
        for &count in counts {
            let sub = dir.join(format!("{name}-{count}"));
            let mut paths: Vec<PathBuf> = (0..count)
                .map(|index| write_part(&d, Part { index, count }, &sub, None))
                .collect();
            // Merged forwards, backwards and shuffled: the same bits.
            for turn in 0..3 {
                match turn {
                    1 => paths.reverse(),
                    2 => paths.rotate_left(count as usize / 2),
                    _ => {}
                }
                let merged = part::merge(&paths, false).unwrap();
                assert!(merged.is_complete());
                assert_eq!(merged.aovs, d.render.aovs);
                assert_eq!(merged.film.layers(), whole.layers());
                assert!(
                    merged.film == whole,
                    "{name}: {count} parts, order {turn}: film differs"
                );
                assert_eq!(
                    merged.stats.samples,
                    merged.film.len() as u64 * u64::from(spp)
                );
            }
        }
    }
}

#[test]
fn a_part_stopped_and_resumed_merges_exactly() {
    let dir = temp_dir("parts-resume");
    let mut d = desc("cover", 24, 32, 2);
    // With every feature buffer: they are in the part files too.
    d.render.aovs = lumen::aov::Aov::ALL.to_vec();
    let (a, b) = (Part { index: 0, count: 2 }, Part { index: 1, count: 2 });
    let first = write_part(&d, a, &dir, None);
    // Part 1 stopped after two passes, as a killed task leaves it.
    let second = write_part(&d, b, &dir, Some(2));
    let paths = [first.clone(), second.clone()];
    match part::merge(&paths, false) {
        Err(MergeError::Unfinished { path, share, done }) => {
            assert_eq!(path, second);
            assert_eq!(share, 16..32);
            assert!(done > 16 && done < 32, "{done}");
        }
        other => panic!("an unfinished part was merged: {other:?}"),
    }
    // A preview holds what is done so far.
    let preview = part::merge(&paths, true).unwrap();
    assert!(!preview.is_complete());
    assert_eq!(preview.held.len(), 1);
    assert_eq!(preview.held[0].start, 0);
    // The task run again resumes from its part file.
    let share = Share {
        part: Some(b),
        ..Share::default()
    };
    common::finish_share(&d, share, &second);
    assert!(part::merge(&paths, false).unwrap().film == one_machine(&d));
}

#[test]
fn parts_that_do_not_make_one_render_are_refused_naming_the_files() {
    let dir = temp_dir("parts-refused");
    let d = desc("cover", 16, 8, 1);
    let parts: Vec<PathBuf> = (0..3)
        .map(|index| write_part(&d, Part { index, count: 3 }, &dir, None))
        .collect();
    let err = |paths: &[PathBuf]| part::merge(paths, false).unwrap_err().to_string();

    let missing = err(&[parts[0].clone(), parts[2].clone()]);
    assert!(
        missing.contains("no part holds samples 2..5 of the 8 spp render"),
        "{missing}"
    );
    // --partial merges what there is.
    let partial = part::merge(&[parts[0].clone(), parts[2].clone()], true).unwrap();
    assert_eq!(partial.held, [0..2, 5..8]);

    let twice = err(&[parts[0].clone(), parts[1].clone(), parts[0].clone()]);
    assert!(twice.contains("both hold samples 0..2"), "{twice}");
    let other_split = write_part(&d, Part { index: 1, count: 2 }, &dir.join("halves"), None);
    let overlap = err(&[parts[1].clone(), other_split.clone()]);
    assert!(
        overlap.contains("both hold samples 4..5") && overlap.contains("part-1.lumen-part"),
        "{overlap}"
    );

    let other_seed = write_part(
        &desc("cover", 16, 8, 2),
        Part { index: 1, count: 3 },
        &dir.join("seed"),
        None,
    );
    let different = err(&[parts[0].clone(), other_seed, parts[2].clone()]);
    assert!(
        different.contains("are parts of different renders (seed 1 in"),
        "{different}"
    );

    // Parts of another lumen are another render, whichever comes first.
    let mut older = lumen::checkpoint::Checkpoint::read(&parts[0]).unwrap();
    older.renderer_id = "0.0.1+samples.1".into();
    let older_path = dir.join("older.lumen-part");
    older.view().write(&older_path).unwrap();
    let e = err(&[older_path, parts[1].clone(), parts[2].clone()]);
    assert!(e.contains("written by lumen 0.0.1+samples.1 and"), "{e}");

    let truncated = dir.join("truncated.lumen-part");
    let bytes = std::fs::read(&parts[1]).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() - 100]).unwrap();
    let e = err(&[parts[0].clone(), truncated.clone(), parts[2].clone()]);
    assert!(e.contains("truncated.lumen-part"), "{e}");
    let mut flipped = bytes.clone();
    let at = flipped.len() - 40;
    flipped[at] ^= 4;
    std::fs::write(&truncated, &flipped).unwrap();
    let e = err(&[parts[0].clone(), truncated.clone(), parts[2].clone()]);
    assert!(e.contains("truncated.lumen-part: corrupted"), "{e}");
    assert!(matches!(part::merge(&[], false), Err(MergeError::NoParts)));
}

#[test]
fn adaptive_renders_cannot_be_split_by_samples() {
    let mut d = desc("cover", 16, 32, 1);
    d.render.sampler = lumen::scene::Sampling::Sobol;
    d.render.noise_target = Some(0.05);
    let scene = Scene::from_desc(&d).unwrap();
    let e = Session::with_part(&d, scene, Part { index: 0, count: 2 })
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("part 0/2") && e.contains("noise_target"), "{e}");
}

#[test]
fn the_command_line_splits_and_merges_to_the_bit() {
    let dir = temp_dir("parts-cli");
    let args = ["cover", "--width", "32", "--spp", "9", "--seed", "6"];
    let status = lumen()
        .args(["render"])
        .args(args)
        .arg("-o")
        .arg(dir.join("one.pfm"))
        .status()
        .unwrap();
    assert!(status.success());
    for k in [2, 0, 1, 3] {
        let out = lumen()
            .args(["render"])
            .args(args)
            .args(["--part", &format!("{k}/4"), "-o"])
            .arg(dir.join(format!("part-{k}.lumen-part")))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let merge = |extra: &[&str], parts: &[u32], to: &str| {
        lumen()
            .arg("merge")
            .args(
                parts
                    .iter()
                    .map(|k| dir.join(format!("part-{k}.lumen-part"))),
            )
            .args(extra)
            .arg("-o")
            .arg(dir.join(to))
            .output()
            .unwrap()
    };
    let out = merge(&[], &[3, 1, 0, 2], "merged.pfm");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(dir.join("merged.pfm")).unwrap(),
        std::fs::read(dir.join("one.pfm")).unwrap()
    );
    // Missing a part: refused, nothing written; --partial says what it holds.
    let out = merge(&[], &[0, 2], "some.png");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no part holds samples 2..4"));
    assert!(!dir.join("some.png").exists());
    let out = merge(&["--partial"], &[0, 2], "some.png");
    assert!(out.status.success());
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("holds 4 of 9 spp (samples 0..2, 4..6)"),
        "{said}"
    );
    assert!(dir.join("some.png").exists());
    // The denoiser's options of a render that is not denoised: refused.
    for option in [["--denoise-prefilter", "none"], ["--denoiser", "atrous"]] {
        let out = merge(&option, &[3, 1, 0, 2], "d.pfm");
        assert_eq!(out.status.code(), Some(2));
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(
            said.contains(&format!("{}: the parts' render is not denoised", option[0])),
            "{said}"
        );
        assert!(!dir.join("d.pfm").exists());
    }

    // A part needs a part file, and a part file needs --part: option mistakes,
    // exit status 2.
    let out = lumen()
        .args(["render", "cover", "--part", "0/2", "-o"])
        .arg(dir.join("x.png"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("-o NAME.lumen-part"));
    let out = lumen()
        .args(["render", "cover", "-o"])
        .arg(dir.join("x.lumen-part"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("give --part K/N"));
    for bad in ["4/4", "1/0", "x"] {
        let out = lumen()
            .args(["render", "cover", "--part", bad, "-o"])
            .arg(dir.join("x.lumen-part"))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
}
