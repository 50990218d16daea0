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

/// A scene of nothing but a sky of `radiance`: every camera sample is it.
fn sky_scene(dir: &std::path::Path, radiance: &str) -> std::path::PathBuf {
    let scene = dir.join("sky.toml");
    std::fs::write(
        &scene,
        format!("[background]\ntype = \"solid\"\ncolor = [{radiance}, {radiance}, {radiance}]\n"),
    )
    .unwrap();
    scene
}

/// The values of a PFM file written by lumen (little-endian).
fn pfm_values(bytes: &[u8]) -> Vec<f32> {
    let mut lines = 0;
    let start = bytes
        .iter()
        .position(|&b| {
            lines += usize::from(b == b'\n');
            lines == 3
        })
        .unwrap()
        + 1;
    bytes[start..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn samples_that_would_take_a_pixel_past_its_sum_are_dropped_not_wrapped() {
    let dir = temp_dir("dropped-overflow");
    // 5e18 is below what one sample may be, but two of them pass the 9.2e18
    // a pixel's sum holds: the second of each pixel is dropped and counted.
    let scene = sky_scene(&dir, "5e18");
    let out_pfm = dir.join("out.pfm");
    let out = lumen()
        .args(["render", scene.to_str().unwrap(), "-o"])
        .arg(&out_pfm)
        .args(["--width", "8", "--spp", "2"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let pixels = 8 * 4;
    assert!(err.contains(&format!("{pixels} dropped samples")), "{err}");
    assert!(err.contains("lumen: warning:"), "{err}");
    for v in pfm_values(&std::fs::read(&out_pfm).unwrap()) {
        assert!((v / 5e18 - 1.0).abs() < 1e-6, "a pixel is {v}");
    }
}

#[test]
fn parts_whose_sums_would_pass_a_pixel_are_refused_by_the_merge() {
    let dir = temp_dir("dropped-merge");
    let scene = sky_scene(&dir, "5e18");
    let mut parts = Vec::new();
    for k in 0..2 {
        let part = dir.join(format!("p{k}.lumen-part"));
        let out = lumen()
            .args(["render", scene.to_str().unwrap(), "-o"])
            .arg(&part)
            .args(["--width", "8", "--spp", "2", "--part", &format!("{k}/2")])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        parts.push(part);
    }
    let merged = dir.join("merged.pfm");
    let out = lumen()
        .arg("merge")
        .args(&parts)
        .arg("-o")
        .arg(&merged)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("would pass what a pixel's sum holds"), "{err}");
    assert!(!merged.exists());
}

#[test]
fn a_render_whose_every_sample_is_dropped_leaves_the_old_output_alone() {
    let dir = temp_dir("dropped-all");
    let scene = sky_scene(&dir, "1e19");
    // An image there stays as it was; a part file is not written (an old one
    // is a checkpoint, guarded as such).
    for name in ["old.png", "new.lumen-part"] {
        let out_path = dir.join(name);
        let before = b"what was there";
        if name.ends_with("png") {
            std::fs::write(&out_path, before).unwrap();
        }
        let mut cmd = lumen();
        cmd.args(["render", scene.to_str().unwrap(), "-o"])
            .arg(&out_path)
            .args(["--width", "8", "--spp", "4"]);
        if name.ends_with("part") {
            cmd.args(["--part", "0/2"]);
        }
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("every sample came out NaN"), "{err}");
        assert!(err.contains("was not written"), "{err}");
        if name.ends_with("png") {
            assert_eq!(std::fs::read(&out_path).unwrap(), before, "{name}");
        } else {
            assert!(!out_path.exists());
        }
        assert!(
            lumen_process::temp_files(&dir).is_empty(),
            "{:?}",
            lumen_process::temp_files(&dir)
        );
    }
    assert!(!dir.join("old.png.lumen-ckpt").exists());
}
