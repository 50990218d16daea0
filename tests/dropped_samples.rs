//! Renders whose samples come out NaN, infinite or too large to sum say so: a camera that
//! would make every ray NaN is refused before rendering, and a render that
//! drops more than a few samples in ten thousand warns with the count.

mod lumen_process;

use lumen_process::{lumen, temp_dir};

#[test]
fn a_focus_plane_too_close_to_resolve_is_refused_naming_the_field() {
    let dir = temp_dir("dropped-camera");
    let scene = dir.join("tiny-focus.toml");
    std::fs::write(
        &scene,
        "[camera]\nfocus_dist = 1e-30\n\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -1]\n\
         radius = 0.5\nmaterial = \"m\"\n\n[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n",
    )
    .unwrap();
    let out_png = dir.join("out.png");
    let out = lumen()
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            out_png.to_str().unwrap(),
        ])
        .args(["--width", "32", "--spp", "2"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for words in [
        "tiny-focus.toml:2:14",
        "camera.focus_dist",
        "make focus_dist at least",
    ] {
        assert!(err.contains(words), "{err:?} lacks {words:?}");
    }
    assert!(!out_png.exists(), "nothing is written");
}

#[test]
fn dropping_samples_warns_with_the_count() {
    let dir = temp_dir("dropped-warning");
    // A sky brighter than a pixel's fixed-point sum holds (2^63, about
    // 9.2e18): the samples that see it are dropped, the others kept.
    let scene = dir.join("hot-sky.toml");
    std::fs::write(
        &scene,
        "[render]\nintegrator = \"path\"\nsample_background = true\n\n[background]\n\
         type = \"solid\"\ncolor = [1e19, 1e19, 1e19]\n\n[[objects]]\ntype = \"sphere\"\n\
         center = [0, -100.5, -1]\nradius = 100\nmaterial = \"m\"\n\n[materials.m]\n\
         type = \"diffuse\"\nalbedo = [0.9, 0.9, 0.9]\n",
    )
    .unwrap();
    let run = |name: &str| {
        let out_png = dir.join(name);
        let out = lumen()
            .args([
                "render",
                scene.to_str().unwrap(),
                "-o",
                out_png.to_str().unwrap(),
            ])
            .args(["--width", "32", "--spp", "4"])
            .output()
            .unwrap();
        (out, out_png)
    };
    let (out, png) = run("hot.png");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "some samples are left: {err}");
    assert!(png.exists());
    let warning = err
        .lines()
        .find(|l| l.starts_with("lumen: warning: "))
        .unwrap_or_else(|| panic!("no warning in {err:?}"));
    assert!(
        warning.contains("samples (") && warning.contains("NaN, infinite or beyond"),
        "{warning}"
    );
    // The count in the warning is the summary's.
    let dropped: u64 = warning["lumen: warning: ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(dropped > 0);
    assert!(err.contains(&format!("{dropped} dropped samples")), "{err}");
}
