//! The `lumen` command, run as a separate process: errors are one clear line
//! and a non-zero exit with no output file; successful renders write images
//! that decode to the right size and the same pixels the library renders.

mod common;
mod lumen_process;

use lumen::render::render;
use lumen::scene::builtin::BUILTINS;
use lumen::scene::Scene;
use lumen_process::{lumen_output, refused_stderr, stderr, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Output;

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Asserts a failed run: non-zero exit, no panic, and a first stderr line
/// that mentions every one of `words`.
fn assert_fails(out: &Output, words: &[&str]) {
    let err = refused_stderr(out);
    let first = err.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    assert!(first.contains("error"), "no error line: {err}");
    for w in words {
        assert!(first.contains(w), "{w:?} not named in {first:?}");
    }
}

#[test]
fn unknown_scene_is_one_clear_line() {
    let dir = temp_dir("unknown");
    let out_path = dir.join("x.png");
    let out = lumen_output(&["render", "no-such-scene", "-o", out_path.to_str().unwrap()]);
    assert_fails(&out, &["no-such-scene"]);
    assert_eq!(
        stderr(&out).trim_end().lines().count(),
        1,
        "{}",
        stderr(&out)
    );
    assert!(listing(&dir).is_empty());
}

#[test]
fn bad_option_values_are_refused_by_name() {
    let dir = temp_dir("bad-options");
    let o = dir.join("x.png");
    let o = o.to_str().unwrap();
    for (args, words) in [
        (vec!["--spp", "0"], vec!["--spp", "0"]),
        (vec!["--width", "abc"], vec!["--width", "abc"]),
        (vec!["--width", "-3"], vec!["-3"]),
        (vec!["--threads", "0"], vec!["--threads", "0"]),
        (vec!["--depth", "0"], vec!["--depth", "0"]),
        (vec!["--seed", "x1"], vec!["--seed", "x1"]),
        (vec!["--width", "4000000000"], vec!["cover", "pixels"]),
    ] {
        let mut all = vec!["render", "cover", "-o", o];
        all.extend(&args);
        assert_fails(&lumen_output(&all), &words);
    }
    // clap names a missing argument on the line after its error line.
    let missing = lumen_output(&["render", "cover"]);
    assert_fails(&missing, &[]);
    assert!(
        stderr(&missing).contains("--output"),
        "{}",
        stderr(&missing)
    );
    assert_fails(&lumen_output(&["paint", "cover"]), &["paint"]);
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn unwritable_outputs_fail_before_rendering_and_leave_no_file() {
    let dir = temp_dir("unwritable");
    std::fs::create_dir(dir.join("taken.png")).unwrap();
    let before = listing(&dir);
    for (path, words) in [
        (
            dir.join("missing").join("x.png"),
            vec!["missing", "does not exist"],
        ),
        (dir.join("taken.png"), vec!["taken.png", "directory"]),
        (dir.join("x.jpg"), vec!["x.jpg", "format"]),
        (dir.join("x"), vec!["format"]),
    ] {
        let out = lumen_output(&[
            "render",
            "gradient",
            "-o",
            path.to_str().unwrap(),
            "--width",
            "8",
        ]);
        assert_fails(&out, &words);
        assert_eq!(
            stderr(&out).trim_end().lines().count(),
            1,
            "{}",
            stderr(&out)
        );
        assert_eq!(listing(&dir), before, "a file was left behind");
    }
}

/// The film the library renders for a built-in scene with these overrides.
fn library_film(name: &str, width: u32, spp: u32, seed: u64) -> (lumen::film::Film, f32) {
    let scene = Scene::from_desc(&common::builtin_desc(name, width, spp, seed)).unwrap();
    (render(&scene, &|_| {}).0, scene.settings.gamma)
}

fn render_to(dir: &Path, file: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(file);
    let mut args = vec![
        "render",
        "albedo-coloured",
        "-o",
        path.to_str().unwrap(),
        "--width",
        "24",
        "--spp",
        "2",
        "--seed",
        "5",
    ];
    args.extend(extra);
    let out = lumen_output(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("0 dropped samples"), "summary: {err}");
    assert!(!err.contains("panicked"));
    path
}

#[test]
fn renders_every_format_with_the_librarys_pixels() {
    let dir = temp_dir("formats");
    let (film, gamma) = library_film("albedo-coloured", 24, 2, 5);
    let (w, h) = (film.width(), film.height());
    assert_eq!((w, h), (24, 13));

    let ppm = std::fs::read_to_string(render_to(&dir, "a.ppm", &[])).unwrap();
    let mut tokens = ppm.split_whitespace();
    assert_eq!(tokens.next(), Some("P3"));
    let header: Vec<u32> = tokens
        .by_ref()
        .take(3)
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(header, [w, h, 255]);
    let values: Vec<u8> = tokens.map(|t| t.parse().unwrap()).collect();
    assert_eq!(values.len(), (w * h * 3) as usize, "one triple per pixel");
    assert_eq!(values, film.to_rgb8(gamma));

    let png = image::open(render_to(&dir, "a.png", &[]))
        .unwrap()
        .into_rgb8();
    assert_eq!(png.dimensions(), (w, h));
    assert_eq!(png.into_raw(), film.to_rgb8(gamma));

    let pfm = std::fs::read(render_to(&dir, "a.pfm", &[])).unwrap();
    let header = format!("PF\n{w} {h}\n-1.0\n");
    assert!(pfm.starts_with(header.as_bytes()));
    assert_eq!(pfm.len(), header.len() + (w * h * 12) as usize);
    assert_eq!(pfm, lumen::output::encode_pfm(&film));

    let exr_path = render_to(&dir, "a.exr", &[]);
    let (size, exr_pixels) = common::read_exr_rgb(&exr_path);
    assert_eq!(size, (w as usize, h as usize));
    let linear: Vec<[f32; 3]> = film.linear().iter().map(|c| [c.x, c.y, c.z]).collect();
    assert_eq!(exr_pixels, linear);

    // Nothing but the four images: no temporary files.
    assert_eq!(listing(&dir), ["a.exr", "a.pfm", "a.png", "a.ppm"]);
}

#[test]
fn the_thread_count_does_not_change_the_file() {
    let dir = temp_dir("threads");
    let one = std::fs::read(render_to(&dir, "one.pfm", &["--threads", "1"])).unwrap();
    let two = std::fs::read(render_to(&dir, "two.pfm", &["--threads", "2"])).unwrap();
    let three = std::fs::read(render_to(&dir, "three.pfm", &["--threads", "3"])).unwrap();
    assert!(one == two && two == three);
}

#[test]
fn scenes_lists_every_builtin_in_order_with_its_caption() {
    let out = lumen_output(&["scenes"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), BUILTINS.len());
    for (line, b) in lines.iter().zip(BUILTINS) {
        assert_eq!(line.split_whitespace().next(), Some(b.name));
        assert!(line.ends_with(b.caption), "{line}");
    }
}

#[test]
fn gallery_writes_every_image_and_an_index_in_order() {
    let dir = temp_dir("gallery").join("new-folder");
    let out = lumen_output(&[
        "gallery",
        dir.to_str().unwrap(),
        "--width",
        "32",
        "--spp",
        "1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let index = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let mut last = 0;
    for b in BUILTINS {
        let file = format!("{}.png", b.name);
        let img = image::open(dir.join(&file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(img.width(), 32, "{file}");
        let at = index
            .find(&format!("src=\"{file}\""))
            .unwrap_or_else(|| panic!("{file} not in index.html"));
        assert!(at > last, "{file} out of order in index.html");
        // Under its book's heading, which comes after the previous book's figures.
        let heading = index
            .find(&format!("<h2>{}</h2>", b.book.title()))
            .unwrap_or_else(|| panic!("no heading for {:?}", b.book));
        assert!(heading < at, "{file} before its book's heading");
        assert!(
            BUILTINS
                .iter()
                .filter(|o| o.book < b.book)
                .all(|o| index.find(&format!("src=\"{}.png\"", o.name)).unwrap() < heading),
            "{:?}'s heading among the previous book's figures",
            b.book
        );
        last = at;
        assert!(index.contains(b.caption), "caption of {}", b.name);
    }
    assert_eq!(
        listing(&dir).len(),
        BUILTINS.len() + 1,
        "{:?}",
        listing(&dir)
    );
}

#[test]
fn gallery_with_a_bad_value_fails_cleanly() {
    let dir = temp_dir("gallery-bad");
    let target = dir.join("g");
    assert_fails(
        &lumen_output(&["gallery", target.to_str().unwrap(), "--spp", "0"]),
        &["--spp"],
    );
    assert!(!target.exists());
}

#[test]
fn sampler_and_noise_target_flags_render_and_refuse_bad_values() {
    let dir = temp_dir("adaptive");
    let out_path = dir.join("a.pfm");
    let out_str = out_path.to_str().unwrap();
    let args = [
        "render", "cover", "-o", out_str, "--width", "48", "--spp", "64",
    ];
    let out =
        lumen_output(&[&args[..], &["--sampler", "sobol", "--noise-target", "0.05"]].concat());
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("pixels still sampling"), "{err}");
    assert!(err.contains("on average, noise target 0.05"), "{err}");
    assert_eq!(listing(&dir), ["a.pfm"], "no checkpoint left behind");
    // The flag chooses the sampler: the image differs from the scene's own.
    let sobol = std::fs::read(&out_path).unwrap();
    let out = lumen_output(&[&args[..], &["--noise-target", "0.05"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_ne!(std::fs::read(&out_path).unwrap(), sobol);
    let out = lumen_output(&[&args[..], &["--noise-target", "0"]].concat());
    assert_fails(&out, &["render.noise_target", "above 0"]);
    let out = lumen_output(&[&args[..], &["--sampler", "halton"]].concat());
    assert!(!out.status.success());
    assert!(stderr(&out).contains("sobol"), "{}", stderr(&out));
}

#[test]
fn the_integrator_flag_chooses_how_light_is_found() {
    let dir = temp_dir("integrator");
    let image = |integrator: Option<&str>| {
        let path = dir.join("c.pfm");
        let mut args = vec![
            "render",
            "cornell-box",
            "-o",
            path.to_str().unwrap(),
            "--width",
            "32",
            "--spp",
            "4",
        ];
        if let Some(i) = integrator {
            args.extend(["--integrator", i]);
        }
        let out = lumen_output(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read(&path).unwrap()
    };
    // The figure's own estimator is the book's.
    assert_eq!(image(None), image(Some("bsdf")));
    assert_ne!(image(Some("path")), image(Some("bsdf")));
    let out = lumen_output(&[
        "render",
        "cornell-box",
        "-o",
        "x.png",
        "--integrator",
        "nee",
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("path") && err.contains("bsdf"), "{err}");
}

/// Options that cannot work, together or with the scene, exit with status 2
/// as clap's own usage errors do (a job engine then fails the task at once
/// instead of retrying it), naming the mistake, writing nothing.
#[test]
fn option_mistakes_exit_with_status_2() {
    let dir = temp_dir("usage-exit");
    let path = |name: &str| dir.join(name).display().to_string();
    let part = path("a.lumen-part");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["--part", "0/1000", "--split", "tiles", "-o", &part],
            "cannot be split into 1000 bands",
        ),
        (vec!["--tile", "0,0,1000,10", "-o", &part], "reaches beyond"),
        (
            vec!["--part", "0/2", "--noise-target", "0.1", "-o", &part],
            "cannot sample adaptively",
        ),
        (vec!["--part", "0/2", "-o", &path("x.png")], "part file"),
        (vec!["-o", &path("x.lumen-part")], "give --part"),
        (vec!["-o", &path("out.jpg")], "unknown image format"),
    ]
    .into_iter()
    .map(|(a, says)| (a.into_iter().map(String::from).collect(), says))
    .collect();
    for (args, says) in cases {
        let out = lumen_process::lumen()
            .args(["render", "cover", "--width", "64", "--spp", "1"])
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_fails(&out, &[says]);
        assert!(listing(&dir).is_empty(), "{args:?}: {:?}", listing(&dir));
    }
    let out = lumen_process::lumen()
        .args(["merge", "nothing.lumen-part", "-o", &path("m.jpg")])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}
