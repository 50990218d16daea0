//! `render --denoise` and `lumen denoise` from the command line: in every
//! build, what is refused; with the `oidn` feature (`.ci/run` builds it,
//! with `OIDN_DIR` set), what they write.

mod lumen_process;

use lumen_process::*;
use std::path::Path;
use std::process::Output;

const SMALL: &[&str] = &[
    "render",
    "cornell-box",
    "--width",
    "48",
    "--spp",
    "8",
    "--threads",
    "2",
];

/// A render to `out` of [`SMALL`] with `extra` arguments, which must succeed.
fn render(out: &Path, extra: &[&str]) {
    let (status, err) = run(SMALL, out, extra);
    assert!(status.success(), "{err}");
}

/// The built-in Cornell box as a scene file `s.toml` in `dir`, with `keys`
/// (TOML lines) added to its `[render]` table.
fn cornell_box_file(dir: &Path, keys: &str) -> std::path::PathBuf {
    let scene = dir.join("s.toml");
    let o = lumen_output(&[
        "scenes",
        "export",
        "cornell-box",
        "-o",
        scene.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(
        &scene,
        text.replace("[render]\n", &format!("[render]\n{keys}")),
    )
    .unwrap();
    scene
}

/// `lumen denoise INPUT -o OUT`.
fn denoise(input: &Path, out: &Path) -> Output {
    denoise_with(input, out, &[])
}

/// `lumen denoise INPUT -o OUT EXTRA...`.
fn denoise_with(input: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["denoise", input.to_str().unwrap(), "-o"];
    args.push(out.to_str().unwrap());
    args.extend_from_slice(extra);
    lumen_output(&args)
}

#[test]
fn an_image_without_albedo_or_normal_is_refused_naming_its_channels() {
    let dir = temp_dir("denoise-layers");
    let noisy = dir.join("noisy.exr");
    render(&noisy, &["--aov", "depth"]);
    let out = dir.join("clean.exr");
    let o = denoise(&noisy, &out);
    assert_refused(
        &o,
        &[
            "noisy.exr",
            "has no albedo (albedo.R, albedo.G, albedo.B) layer",
            "its channels are B, G, R, depth.Z",
        ],
    );
    assert!(!out.exists());
    // A file that is not an EXR image.
    std::fs::write(dir.join("text.exr"), "not an image").unwrap();
    let o = denoise(&dir.join("text.exr"), &out);
    assert_refused(&o, &["text.exr", "cannot read it as an OpenEXR image"]);
    // Nothing there, or a directory.
    let o = denoise(&dir.join("none.exr"), &out);
    assert_refused(&o, &["none.exr: no such file"]);
    let o = denoise(&dir, &out);
    assert_refused(&o, &["not a regular file"]);
    // Its own input is not replaced.
    let o = denoise(&noisy, &noisy);
    assert_refused(&o, &["cannot replace its input"]);
    // A quality that does not exist, named with those that do.
    let o = denoise_with(&noisy, &out, &["--prefilter", "best"]);
    assert_refused(&o, &["`best`", "high, balanced, fast"]);
    assert!(!out.exists());
}

#[test]
fn denoised_previews_and_the_denoisers_options_need_a_denoised_render() {
    let dir = temp_dir("denoise-previews");
    for option in [
        &["--denoise-previews"][..],
        &["--denoiser", "atrous"],
        &["--denoise-quality", "fast"],
        &["--denoise-prefilter", "none"],
    ] {
        let (status, err) = run(SMALL, &dir.join("out.png"), option);
        assert_eq!(status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!(
                "{}: the render is not denoised; add --denoise",
                option[0]
            )),
            "{err}"
        );
        assert!(!dir.join("out.png").exists());
    }
    // A quality that does not exist, named with those that do.
    let (status, err) = run(SMALL, &dir.join("out.png"), &["--denoise-quality", "none"]);
    assert_eq!(status.code(), Some(2), "{err}");
    assert!(
        err.contains("no quality `none`; it is one of high, balanced, fast"),
        "{err}"
    );
    let (status, err) = run(SMALL, &dir.join("out.png"), &["--denoiser", "nfor"]);
    assert_eq!(status.code(), Some(2), "{err}");
    assert!(
        err.contains("no denoiser `nfor`; it is one of oidn, atrous"),
        "{err}"
    );
}

#[test]
fn the_built_in_filter_denoises_in_every_build_the_same_bits_on_any_threads() {
    let dir = temp_dir("denoise-atrous");
    let out = dir.join("out.exr");
    render(&out, &["--denoise", "--denoiser", "atrous"]);
    let noisy = dir.join("out.noisy.exr");
    let (clean, rendered) = (exr_rgb(&out), exr_rgb(&noisy));
    assert_ne!(clean, rendered);
    assert!(clean.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
    // Smoother: neighbours differ less than in the noisy image.
    let roughness = |image: &[[f32; 3]]| -> f64 {
        image
            .windows(2)
            .map(|p| f64::from((p[0][1] - p[1][1]).abs()))
            .sum()
    };
    assert!(roughness(&clean) < 0.7 * roughness(&rendered));
    // `lumen denoise` gives the render's file to the byte, on one thread
    // or on three.
    let bytes = std::fs::read(&out).unwrap();
    for threads in ["1", "3"] {
        let again = dir.join(format!("again-{threads}.exr"));
        let extra = ["--denoiser", "atrous", "--threads", threads];
        let o = denoise_with(&noisy, &again, &extra);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("by lumen's à-trous filter"),
            "{}",
            stderr(&o)
        );
        assert_eq!(std::fs::read(&again).unwrap(), bytes);
    }
    // OIDN's qualities are refused for it, naming the option.
    for (option, value) in [
        ("--denoise-quality", "fast"),
        ("--denoise-prefilter", "none"),
    ] {
        let extra = ["--denoise", "--denoiser", "atrous", option, value];
        let (status, err) = run(SMALL, &dir.join("q.exr"), &extra);
        assert_eq!(status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!(
                "{option}: a quality of Open Image Denoise; the atrous denoiser has none"
            )),
            "{err}"
        );
        assert!(!dir.join("q.exr").exists());
    }
    let o = denoise_with(
        &noisy,
        &dir.join("q.exr"),
        &["--denoiser", "atrous", "--quality", "fast"],
    );
    assert_refused(&o, &["--quality: a quality of Open Image Denoise"]);
}

#[test]
fn a_scene_file_asks_for_denoising_and_gets_the_buffers_it_needs() {
    use lumen::aov::Aov;
    use lumen::denoise::{Denoiser, Quality};
    let dir = temp_dir("denoise-toml");
    let path = dir.join("s.toml");
    std::fs::write(&path, "[render]\ndenoise = true\naovs = [\"depth\"]\n").unwrap();
    let file = lumen::scene::file::SceneFile::read(&path).unwrap();
    assert!(file.desc.render.denoise);
    assert_eq!(
        file.desc.render.written_aovs(),
        [Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance]
    );
    assert_eq!(file.desc.render.denoiser, None);
    std::fs::write(&path, "[render]\ndenoise = true\ndenoiser = \"atrous\"\n").unwrap();
    let file = lumen::scene::file::SceneFile::read(&path).unwrap();
    assert_eq!(file.desc.render.denoiser, Some(Denoiser::Atrous));
    let text = "[render]\ndenoise_quality = \"fast\"\ndenoise_prefilter = \"none\"\n";
    std::fs::write(&path, text).unwrap();
    let file = lumen::scene::file::SceneFile::read(&path).unwrap();
    let options = file.desc.render.denoise_choices().options();
    assert_eq!((options.quality, options.prefilter), (Quality::Fast, None));
    // A wrong value is refused naming the file's line, the key and (for a
    // name) the valid ones.
    for (value, key, valid) in [
        (
            "denoise_prefilter = \"low\"",
            "render.denoise_prefilter",
            "none",
        ),
        ("denoiser = \"nfor\"", "render.denoiser", "atrous"),
        ("denoise = 1", "render.denoise", "true or false"),
    ] {
        std::fs::write(&path, format!("[render]\n{value}\n")).unwrap();
        let err = lumen::scene::file::SceneFile::read(&path)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("s.toml:2:") && err.contains(key) && err.contains(valid),
            "{err}"
        );
    }
}

#[test]
fn a_scene_that_names_the_built_in_filter_is_denoised_by_it_unless_told_otherwise() {
    let dir = temp_dir("denoise-scene-atrous");
    let scene = cornell_box_file(&dir, "denoise = true\ndenoiser = \"atrous\"\n");
    let args = [&["render", scene.to_str().unwrap()][..], &SMALL[2..]].concat();
    let (status, err) = run(&args, &dir.join("a.exr"), &[]);
    assert!(status.success(), "{err}");
    assert!(
        err.contains("denoising with lumen's à-trous filter"),
        "{err}"
    );
    // The file it gives is `lumen denoise --denoiser atrous`'s of its noisy
    // image.
    let again = dir.join("again.exr");
    let o = denoise_with(&dir.join("a.noisy.exr"), &again, &["--denoiser", "atrous"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(dir.join("a.exr")).unwrap()
    );
    // Its parts are merged and denoised with it; a part is not denoised,
    // so the denoiser's options are refused for one.
    let mut parts = Vec::new();
    for k in ["0/2", "1/2"] {
        let part = dir.join(format!("p{}.lumen-part", &k[..1]));
        let (status, err) = run(&[&args[..], &["--part", k]].concat(), &part, &[]);
        assert!(status.success(), "{err}");
        parts.push(part.to_str().unwrap().to_string());
    }
    let (status, err) = run(
        &[&args[..], &["--part", "0/2", "--denoiser", "atrous"]].concat(),
        &dir.join("p.lumen-part"),
        &[],
    );
    assert_eq!(status.code(), Some(2), "{err}");
    assert!(
        err.contains("--denoiser: a part is not denoised; give it to `lumen merge`"),
        "{err}"
    );
    let merged = dir.join("m.exr");
    let o = lumen_output(&[
        "merge",
        &parts[0],
        &parts[1],
        "-o",
        merged.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("denoising with lumen's à-trous filter"),
        "{}",
        stderr(&o)
    );
    let again = dir.join("m-again.exr");
    let o = denoise_with(&dir.join("m.noisy.exr"), &again, &["--denoiser", "atrous"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&merged).unwrap()
    );
    // The command line's --denoiser wins: OIDN, where the build has it.
    let (status, err) = run(&args, &dir.join("b.exr"), &["--denoiser", "oidn"]);
    if cfg!(feature = "oidn") {
        assert!(status.success(), "{err}");
        assert!(err.contains("denoising with Open Image Denoise"), "{err}");
    } else {
        assert_eq!(status.code(), Some(1), "{err}");
        assert!(err.contains("built without Open Image Denoise"), "{err}");
    }
}

#[cfg(not(feature = "oidn"))]
#[test]
fn a_build_without_the_denoiser_says_how_to_get_one_before_rendering() {
    let dir = temp_dir("denoise-none");
    let out = dir.join("out.exr");
    let (status, err) = run(SMALL, &out, &["--denoise"]);
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(err.contains("built without Open Image Denoise"), "{err}");
    assert!(err.contains("--features oidn"), "{err}");
    assert!(err.contains("--denoiser atrous"), "{err}");
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "nothing is written"
    );
    // `lumen denoise` on a good file says the same.
    let noisy = dir.join("noisy.exr");
    render(&noisy, &["--aov", "albedo,normal"]);
    let o = denoise(&noisy, &out);
    assert_refused(&o, &["built without Open Image Denoise"]);
    assert!(!out.exists());
}

#[cfg(feature = "oidn")]
mod with_oidn {
    use super::*;

    fn rgb(path: &Path) -> Vec<[f32; 3]> {
        exr_rgb(path)
    }

    #[test]
    fn a_denoised_render_keeps_its_noisy_image_and_is_reproduced_by_lumen_denoise() {
        let dir = temp_dir("denoise-render");
        let out = dir.join("out.exr");
        render(&out, &["--denoise"]);
        render(&dir.join("plain.exr"), &[]);
        // The noisy image is the render without --denoise.
        let noisy = output_noisy(&out);
        assert_eq!(rgb(&noisy), rgb(&dir.join("plain.exr")));
        let clean = rgb(&out);
        assert_ne!(clean, rgb(&noisy));
        assert!(clean.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
        let exr = std::fs::read(&out).unwrap();
        for name in ["albedo.R", "normal.Z"] {
            assert!(
                exr.windows(name.len()).any(|w| w == name.as_bytes()),
                "no {name}"
            );
        }
        // The same input gives the same bits, from the render or from its
        // noisy image.
        let with = |name: &str, args: &[&str]| {
            let path = dir.join(name);
            let extra = [&["--threads", "2"], args].concat();
            let o = denoise_with(&noisy, &path, &extra);
            assert!(o.status.success(), "{}", stderr(&o));
            std::fs::read(&path).unwrap()
        };
        assert_eq!(with("again.exr", &[]), exr);
        // The render's qualities named are its own; others give another
        // image.
        assert_eq!(
            with(
                "named.exr",
                &["--quality", "high", "--prefilter", "balanced"]
            ),
            exr
        );
        assert_ne!(with("high.exr", &["--prefilter", "high"]), exr);
        assert_ne!(with("fast.exr", &["--quality", "fast"]), exr);
        // A render asks for them as `lumen denoise` does.
        let none = with(
            "none.exr",
            &["--prefilter", "none", "--quality", "balanced"],
        );
        assert_ne!(none, exr);
        let asked = dir.join("asked.exr");
        let extra = [
            "--denoise",
            "--denoise-prefilter",
            "none",
            "--denoise-quality",
            "balanced",
        ];
        render(&asked, &extra);
        assert_eq!(std::fs::read(&asked).unwrap(), none);
        // So does a scene file.
        let keys = "denoise = true\ndenoise_prefilter = \"none\"\ndenoise_quality = \"balanced\"\n";
        let scene = cornell_box_file(&dir, keys);
        let from_file = dir.join("from-file.exr");
        let args = [&["render", scene.to_str().unwrap()][..], &SMALL[2..]].concat();
        let (status, err) = run(&args, &from_file, &[]);
        assert!(status.success(), "{err}");
        assert_eq!(std::fs::read(&from_file).unwrap(), none);
        // The command line's options win over the file's.
        let (status, err) = run(
            &args,
            &dir.join("cli.exr"),
            &[
                "--denoise-prefilter",
                "balanced",
                "--denoise-quality",
                "high",
            ],
        );
        assert!(status.success(), "{err}");
        assert_eq!(std::fs::read(dir.join("cli.exr")).unwrap(), exr);
        render(&dir.join("second.exr"), &["--denoise"]);
        assert_eq!(std::fs::read(dir.join("second.exr")).unwrap(), exr);
        // Another format: the denoised image, the noisy one, the buffers.
        render(&dir.join("out.png"), &["--denoise"]);
        for f in [
            "out.png",
            "out.noisy.png",
            "out.albedo.pfm",
            "out.normal.pfm",
        ] {
            assert!(dir.join(f).exists(), "{f}");
        }
        assert!(!dir.join("out.noisy.albedo.pfm").exists());
    }

    #[test]
    fn a_render_resumed_with_denoise_it_was_not_started_with_is_refused_naming_it() {
        let dir = temp_dir("denoise-resume");
        let out = dir.join("out.pfm");
        make_checkpoint(&out, 2);
        let args = [
            "render",
            "cover",
            "--width",
            "48",
            "--spp",
            "16",
            "--resume",
            "--denoise",
        ];
        let (status, err) = run(&args, &out, &[]);
        assert_eq!(status.code(), Some(1), "{err}");
        assert!(
            err.contains("denoise unset in the checkpoint, true here"),
            "{err}"
        );
        assert!(!out.exists(), "nothing is written");
    }

    fn output_noisy(out: &Path) -> std::path::PathBuf {
        lumen::output::noisy_path(out)
    }

    #[test]
    fn a_missing_library_is_refused_before_rendering_naming_the_files_tried() {
        let dir = temp_dir("denoise-missing");
        let empty = dir.join("oidn");
        std::fs::create_dir_all(&empty).unwrap();
        let out = dir.join("out.exr");
        let o = lumen()
            .args(SMALL)
            .args(["--denoise", "-o"])
            .arg(&out)
            .env("OIDN_DIR", &empty)
            .output()
            .unwrap();
        assert_refused(
            &o,
            &[
                "--denoise: cannot load Open Image Denoise",
                "oidn/lib/libOpenImageDenoise",
                "no such file",
            ],
        );
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["oidn"], "nothing is written");
    }
}

/// The R, G, B channels of an EXR file.
fn exr_rgb(path: &Path) -> Vec<[f32; 3]> {
    let image = lumen::denoise::ExrChannels::read(path).unwrap();
    let channel = |name: &str| &image.channels.iter().find(|(n, _)| n == name).unwrap().1;
    let (r, g, b) = (channel("R"), channel("G"), channel("B"));
    (0..r.len()).map(|i| [r[i], g[i], b[i]]).collect()
}
