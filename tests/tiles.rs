//! A render split by pixel region (`render --tile`, `render --part K/N
//! --split tiles`) and merged is the render of one machine to the bit, with
//! each part's film holding its tile only; tiles that do not make one image
//! are refused, naming the files and the pixels.

mod common;
mod lumen_process;

use common::{builtin_desc as desc, write_share};
use lumen::checkpoint::Checkpoint;
use lumen::part::{self, MergeError, Part, Share, Split};
use lumen::progressive::Session;
use lumen::render::render;
use lumen::scene::{Scene, SceneDesc};
use lumen::tile::Tile;
use lumen_process::*;
use std::path::{Path, PathBuf};

fn one_machine(desc: &SceneDesc) -> lumen::film::Film {
    render(&Scene::from_desc(desc).unwrap(), &|_| {}).0
}

/// Band `index` of `count`.
fn band(index: u32, count: u32) -> Share {
    Share {
        part: Some(Part { index, count }),
        split: Split::Tiles,
        tile: None,
    }
}

/// Tile `t`, or part `part` of its samples.
fn tile(t: &str, part: Option<(u32, u32)>) -> Share {
    Share {
        part: part.map(|(index, count)| Part { index, count }),
        split: Split::Samples,
        tile: Some(t.parse().unwrap()),
    }
}

/// Writes `share` of `desc` as `dir/name.lumen-part`.
fn write(desc: &SceneDesc, share: Share, dir: &Path, name: &str) -> PathBuf {
    write_share(desc, share, &dir.join(format!("{name}.lumen-part")), None)
}

#[test]
fn merged_tiles_are_the_one_machine_film_for_any_count_and_order() {
    let dir = temp_dir("tiles-counts");
    for (name, width, spp, counts) in [
        ("cover", 24, 9, &[1, 2, 3, 7][..]),
        ("cornell-box", 20, 5, &[4, 20][..]),
    ] {
        let d = desc(name, width, spp, 5);
        let whole = one_machine(&d);
        let height = whole.height();
        for &count in counts {
            let sub = dir.join(format!("{name}-{count}"));
            let mut paths: Vec<PathBuf> = (0..count)
                .map(|k| write(&d, band(k, count), &sub, &format!("part-{k}")))
                .collect();
            // Each part's film is its band only.
            let rows: u32 = (paths.iter())
                .map(|p| {
                    let c = Checkpoint::read(p).unwrap();
                    assert_eq!(c.film.width(), whole.width());
                    assert_eq!(c.film.height(), c.tile.height());
                    c.film.height()
                })
                .sum();
            assert_eq!(rows, height);
            for turn in 0..3 {
                match turn {
                    1 => paths.reverse(),
                    2 => paths.rotate_left(count as usize / 2),
                    _ => {}
                }
                let merged = part::merge(&paths, false).unwrap();
                assert!(merged.is_complete());
                assert_eq!(merged.held, vec![0..spp]);
                assert!(
                    merged.film == whole,
                    "{name}: {count} bands, order {turn}: film differs"
                );
            }
        }
    }
}

#[test]
fn tiles_of_any_shape_and_tiles_split_by_samples_merge_exactly() {
    let dir = temp_dir("tiles-grid");
    let mut d = desc("cover", 30, 11, 8);
    // zsobol: a pixel's samples depend on where it is in the image, not in
    // its tile.
    d.render.sampler = lumen::scene::Sampling::ZSobol;
    let whole = one_machine(&d);
    let (w, h) = (whole.width(), whole.height());
    assert!(h > 10, "{h}");
    // An uneven grid: a left column, and the right side in two rows, the
    // lower one split again by samples into three.
    let paths = [
        write(&d, tile(&format!("0,0,7,{h}"), None), &dir, "left"),
        write(&d, tile(&format!("7,0,{w},5"), None), &dir, "top"),
        write(&d, tile(&format!("7,5,{w},{h}"), Some((2, 3))), &dir, "c"),
        write(&d, tile(&format!("7,5,{w},{h}"), Some((0, 3))), &dir, "a"),
        write(&d, tile(&format!("7,5,{w},{h}"), Some((1, 3))), &dir, "b"),
    ];
    let merged = part::merge(&paths, false).unwrap();
    assert!(merged.film == whole);
    assert_eq!(merged.tiles.len(), 3);
    assert_eq!(
        merged.stats.samples,
        u64::from(w) * u64::from(h) * 11,
        "every sample counted once"
    );
}

#[test]
fn tiles_that_do_not_make_one_image_are_refused_naming_files_and_pixels() {
    let dir = temp_dir("tiles-refused");
    let d = desc("cover", 16, 6, 1);
    let (w, h) = (16, 9);
    let top = write(&d, tile(&format!("0,0,{w},4"), None), &dir, "top");
    let bottom = write(&d, tile(&format!("0,4,{w},{h}"), None), &dir, "bottom");
    let err = |paths: &[PathBuf]| part::merge(paths, false).unwrap_err();

    // A tile missing: the first pixel no part holds, and how many more.
    match err(std::slice::from_ref(&top)) {
        MergeError::MissingPixels {
            image,
            example,
            others,
        } => {
            assert_eq!((image, example, others), ((w, h), (0, 4), 16 * 5 - 1));
        }
        e => panic!("{e}"),
    }
    let e = err(std::slice::from_ref(&top)).to_string();
    assert!(
        e.contains("no part holds pixel (0, 4) of the 16x9 image, nor 79 other pixels"),
        "{e}"
    );
    // A partial merge holds the top's samples; the rest is black.
    let partial = part::merge(std::slice::from_ref(&top), true).unwrap();
    assert!(!partial.is_complete());
    assert_eq!(partial.samples_held, 16 * 4 * 6);
    assert!(partial.held.is_empty());
    assert_eq!(partial.film.pixel(3, 7), lumen::math::Color::ZERO);
    assert_eq!(partial.film.pixel(3, 2), one_machine(&d).pixel(3, 2));

    // Overlapping tiles that are not the same tile.
    let middle = write(&d, tile(&format!("0,3,{w},6"), None), &dir, "middle");
    let e = err(&[top.clone(), middle.clone(), bottom.clone()]).to_string();
    assert!(
        e.contains("top.lumen-part and")
            && e.contains("middle.lumen-part hold overlapping tiles (0,0,16,4 and 0,3,16,6, sharing 0,3,16,4)"),
        "{e}"
    );
    // The same tile twice.
    let e = err(&[top.clone(), bottom.clone(), top.clone()]).to_string();
    assert!(
        e.contains("both hold samples 0..6 of the pixels of tile 0,0,16,4"),
        "{e}"
    );
    // A tile split by samples with a share missing.
    let half = write(
        &d,
        tile(&format!("0,4,{w},{h}"), Some((0, 2))),
        &dir,
        "half",
    );
    let e = err(&[top.clone(), half.clone()]).to_string();
    assert!(
        e.contains("no part holds samples 3..6 of the pixels of tile 0,4,16,9 of the 6 spp render"),
        "{e}"
    );
    // A tile and a band of the same image split another way.
    let other = write(&d, band(1, 3), &dir, "band");
    assert!(matches!(
        err(&[top.clone(), other]),
        MergeError::TilesOverlap { .. }
    ));
    // A part of a different image size is another render.
    let e = err(&[
        top.clone(),
        write(&desc("cover", 20, 6, 1), band(1, 2), &dir, "wide"),
    ]);
    assert!(matches!(e, MergeError::DifferentRenders { .. }), "{e}");
    assert!(part::merge(&[top, bottom], false).unwrap().is_complete());
}

#[test]
fn a_tile_must_lie_in_the_image_and_bands_must_hold_rows() {
    let d = desc("cover", 16, 4, 1);
    let start = |share: Share| {
        Session::with_share(&d, Scene::from_desc(&d).unwrap(), share)
            .err()
            .map(|e| e.to_string())
    };
    let e = start(tile("8,0,17,4", None)).unwrap();
    assert!(
        e.contains("tile 8,0,17,4 reaches beyond the 16x9 image"),
        "{e}"
    );
    let e = start(band(0, 10)).unwrap();
    assert!(
        e.contains("part 0/10 (tiles): the 9 rows of the image cannot be split into 10 bands"),
        "{e}"
    );
    let both = Share {
        split: Split::Tiles,
        ..tile("0,0,4,4", Some((0, 2)))
    };
    assert!(start(both).unwrap().contains("not both"));
    assert_eq!(start(band(8, 9)), None);
    // Adaptive sampling decides from neighbouring passes of every pixel:
    // refused for a tile as for a share of samples.
    let mut adaptive = d.clone();
    adaptive.render.sampler = lumen::scene::Sampling::Sobol;
    adaptive.render.noise_target = Some(0.05);
    let e = Session::with_share(
        &adaptive,
        Scene::from_desc(&adaptive).unwrap(),
        tile("0,0,4,4", None),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("tile 0,0,4,4") && e.contains("noise_target"),
        "{e}"
    );
}

#[test]
fn a_tile_stopped_and_resumed_merges_exactly_and_only_as_that_tile() {
    let dir = temp_dir("tiles-resume");
    let mut d = desc("cover", 24, 32, 2);
    // Feature buffers go into tiles and merge as the image does.
    d.render.aovs = vec![lumen::aov::Aov::Albedo, lumen::aov::Aov::Depth];
    let top = write(&d, band(0, 2), &dir, "part-0");
    let path = dir.join("part-1.lumen-part");
    write_share(&d, band(1, 2), &path, Some(2));
    assert!(matches!(
        part::merge(&[top.clone(), path.clone()], false),
        Err(MergeError::Unfinished { .. })
    ));
    // The same tile resumes; another tile is refused, naming both.
    let ckpt = Checkpoint::read(&path).unwrap();
    let other = Session::with_share(&d, Scene::from_desc(&d).unwrap(), band(0, 2)).unwrap();
    let e = other.restore(ckpt, &path).err().unwrap().to_string();
    assert!(
        e.contains("it holds the pixels 0,6,24,13, the render takes 0,0,24,6"),
        "{e}"
    );
    common::finish_share(&d, band(1, 2), &path);
    assert!(part::merge(&[path, top], false).unwrap().film == one_machine(&d));
}

#[test]
fn the_command_line_splits_by_tiles_and_merges_to_the_bit() {
    let dir = temp_dir("tiles-cli");
    let args = ["cover", "--width", "40", "--spp", "6", "--seed", "4"];
    let run = |extra: &[&str], out: &str| {
        let (status, said) = run(
            &[&["render"][..], &args, extra].concat(),
            &dir.join(out),
            &[],
        );
        (status.code(), said)
    };
    assert_eq!(run(&[], "one.pfm").0, Some(0));
    for k in [2, 0, 1] {
        let (code, said) = run(
            &["--part", &format!("{k}/3"), "--split", "tiles"],
            &format!("band-{k}.lumen-part"),
        );
        assert_eq!(code, Some(0), "{said}");
        assert!(
            said.contains(&format!("part {k}/3 (tiles): pixels 0,")),
            "{said}"
        );
    }
    // The image by explicit tiles, the right one split by samples.
    for (extra, name) in [
        (&["--tile", "0,0,25,22"][..], "left"),
        (&["--tile", "25,0,40,22", "--part", "0/2"][..], "right-0"),
        (&["--tile", "25,0,40,22", "--part", "1/2"][..], "right-1"),
    ] {
        let (code, said) = run(extra, &format!("{name}.lumen-part"));
        assert_eq!(code, Some(0), "{said}");
    }
    let merge = |parts: &[&str], extra: &[&str], to: &str| {
        let files: Vec<String> = (parts.iter())
            .map(|p| dir.join(format!("{p}.lumen-part")).display().to_string())
            .collect();
        let args: Vec<&str> = ["merge"]
            .into_iter()
            .chain(files.iter().map(|f| f.as_str()))
            .collect();
        let (status, said) = lumen_process::run(&args, &dir.join(to), extra);
        (status.code(), said)
    };
    let one = std::fs::read(dir.join("one.pfm")).unwrap();
    let (code, said) = merge(&["band-1", "band-2", "band-0"], &[], "bands.pfm");
    assert_eq!(code, Some(0), "{said}");
    assert_eq!(std::fs::read(dir.join("bands.pfm")).unwrap(), one);
    let (code, said) = merge(&["right-1", "left", "right-0"], &[], "tiles.pfm");
    assert_eq!(code, Some(0), "{said}");
    assert_eq!(std::fs::read(dir.join("tiles.pfm")).unwrap(), one);
    // Missing a tile: refused, nothing written; --partial says what it holds.
    let (code, said) = merge(&["left", "right-0"], &[], "some.png");
    assert_eq!(code, Some(1));
    assert!(
        said.contains("no part holds samples 3..6 of the pixels of tile 25,0,40,22"),
        "{said}"
    );
    assert!(!dir.join("some.png").exists());
    let (code, said) = merge(&["left"], &["--partial"], "some.png");
    assert_eq!(code, Some(0), "{said}");
    let held = 25 * 22 * 6;
    assert!(
        said.contains(&format!(
            "holds {held} of the 5280 samples of the 40x22 image (62.5%) from 1 tile"
        )),
        "{said}"
    );
    // Refusals on the command line: option mistakes, exit 2 and the reason.
    for (extra, expect) in [
        (
            &["--tile", "0,0,41,5"][..],
            "reaches beyond the 40x22 image",
        ),
        (
            &["--part", "0/23", "--split", "tiles"][..],
            "cannot be split into 23 bands",
        ),
        (
            &["--tile", "0,0,4,4", "--part", "0/2", "--split", "tiles"][..],
            "not both",
        ),
    ] {
        let (code, said) = run(extra, "x.lumen-part");
        assert_eq!(code, Some(2), "{extra:?}: {said}");
        assert!(said.contains(expect), "{extra:?}: {said}");
    }
    // A tile is written to a part file; malformed values are usage errors.
    let (code, said) = run(&["--tile", "0,0,4,4"], "x.png");
    assert_eq!(code, Some(2));
    assert!(said.contains("-o NAME.lumen-part"), "{said}");
    for extra in [
        &["--tile", "4,0,4,4"][..],
        &["--tile", "1,2,3"],
        &["--split", "tiles"],
    ] {
        assert_eq!(run(extra, "x.lumen-part").0, Some(2), "{extra:?}");
    }
}

#[test]
fn a_tile_is_read_back_as_written() {
    let dir = temp_dir("tiles-read");
    let d = desc("cover", 16, 3, 1);
    let path = write(&d, tile("3,2,11,7", None), &dir, "t");
    let c = Checkpoint::read(&path).unwrap();
    assert_eq!(
        c.tile,
        Tile {
            x0: 3,
            y0: 2,
            x1: 11,
            y1: 7
        }
    );
    assert_eq!(c.image, (16, 9));
    assert_eq!((c.film.width(), c.film.height()), (8, 5));
    let whole = one_machine(&d);
    for y in 0..5 {
        for x in 0..8 {
            assert_eq!(c.film.pixel(x, y), whole.pixel(x + 3, y + 2));
        }
    }
}

#[test]
fn crafted_parts_are_refused_naming_the_field_and_the_pixel() {
    let dir = temp_dir("tiles-crafted");
    let d = desc("cover", 16, 8, 1);
    let whole = write(&d, Share::default(), &dir, "whole");
    let err = |paths: &[PathBuf]| part::merge(paths, false).unwrap_err().to_string();
    let rewrite = |c: &Checkpoint, name: &str| {
        let path = dir.join(format!("{name}.lumen-part"));
        c.view().write(&path).unwrap();
        path
    };

    // A share beyond the render's samples: samples 8..16 of a 16 spp
    // render, given the 8 spp render's description.
    let mut more = d.clone();
    more.render.samples_per_pixel = 16;
    let second_half = write(&more, band_of_samples(1, 2), &dir, "second-half");
    let mut beyond = Checkpoint::read(&second_half).unwrap();
    beyond.description = Checkpoint::read(&whole).unwrap().description;
    let beyond = rewrite(&beyond, "beyond");
    let e = err(&[whole.clone(), beyond.clone()]);
    assert!(
        e.contains("beyond.lumen-part: malformed: it holds samples 8..16 of a 8 spp render"),
        "{e}"
    );

    // An image size other than the description's, first or not.
    let mut wider = Checkpoint::read(&whole).unwrap();
    wider.image.0 += 1;
    let wider = rewrite(&wider, "wider");
    let e = err(&[wider.clone(), whole.clone()]);
    assert!(
        e.contains("wider.lumen-part: malformed: its image is 17x9, which is not the size its scene description gives"),
        "{e}"
    );
    let e = err(&[whole.clone(), wider]);
    assert!(e.contains("an image of 16x9 and of 17x9"), "{e}");

    // A pixel of a tile with more samples than its share: named by its
    // place in the image.
    let t = write(&d, tile("4,3,12,9", None), &dir, "tile");
    let mut c = Checkpoint::read(&t).unwrap();
    let (sums, counts) = c.film.raw();
    let (sums, mut counts) = (sums.to_vec(), counts.to_vec());
    counts[8 + 2] += 1;
    c.film = lumen::film::Film::from_raw(8, 6, sums, counts).unwrap();
    let bad = rewrite(&c, "bad-pixel");
    let rest = write(&d, tile("0,0,16,3", None), &dir, "rest");
    let e = err(&[rest, bad]);
    assert!(
        e.contains("bad-pixel.lumen-part: malformed: pixel (6, 4) has 9 samples, more than the 8 its spp allow"),
        "{e}"
    );
}

/// Part `index` of `count` shares of the samples.
fn band_of_samples(index: u32, count: u32) -> Share {
    Share {
        part: Some(Part { index, count }),
        ..Share::default()
    }
}

/// A part file can declare any image size: the merge applies the render's
/// pixel limit to it before taking memory for the film.
#[test]
fn a_part_declaring_an_image_past_the_pixel_limit_is_refused() {
    let dir = temp_dir("tiles-huge");
    let d = desc("cover", 16, 2, 1);
    let t = write(&d, tile("4,3,12,9", None), &dir, "tile");
    let mut c = Checkpoint::read(&t).unwrap();
    let mut description: serde_json::Value = serde_json::from_str(&c.description).unwrap();
    description["render"]["width"] = 9000.into();
    description["render"]["height"] = 9000.into();
    c.description = description.to_string();
    c.image = (9000, 9000);
    let huge = dir.join("huge.lumen-part");
    c.view().write(&huge).unwrap();
    for partial in [false, true] {
        let e = part::merge(std::slice::from_ref(&huge), partial)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("huge.lumen-part: its image of 9000x9000 pixels has more than the 67108864"),
            "{e}"
        );
    }
}
