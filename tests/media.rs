//! Participating media that fill what surfaces enclose (`[media]`, a
//! material's `interior` and `exterior`): checked against what they must
//! give in closed form. Tolerances are K standard errors from each render's
//! own per-pixel sample variance; seeds are fixed.

mod common;

use common::{compile_file, pixel_stats, scratch_dir, K};
use lumen::scene::file::SceneFile;
use lumen::scene::Overrides;

/// A scene of a camera looking at a unit ball whose material is
/// `material` (TOML fields), with `media` (TOML tables), under a white
/// sky of radiance 1.
fn ball(media: &str, material: &str, camera: &str, depth: u32) -> String {
    format!(
        "[render]\nwidth = 8\nheight = 8\nsamples_per_pixel = 256\nmax_depth = {depth}\nseed = 5\n\
         [camera]\nlookfrom = [0, 0, 3]\nlookat = [0, 0, 0]\nvfov = 20\n{camera}\n\
         [background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\
         {media}\n\
         [materials.ball]\n{material}\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"ball\"\n"
    )
}

/// A white furnace: a medium that absorbs nothing, in a ball of no
/// surface under a sky of 1, returns exactly 1 wherever it is seen, for a
/// grey and a coloured extinction (whose channels are weighted apart).
#[test]
fn a_medium_that_absorbs_nothing_is_a_white_furnace() {
    let dir = scratch_dir("media-furnace");
    for sigma in ["2", "[0.5, 2, 6]"] {
        let media = format!("[media.fog]\nsigma_t = {sigma}\nalbedo = 1");
        let text = ball(&media, "type = \"interface\"\ninterior = \"fog\"", "", 1000);
        let scene = compile_file(&dir, "furnace.toml", &text);
        let stats = pixel_stats(&scene);
        for c in 0..3 {
            let (m, se) = stats.image(c);
            assert!(
                (m - 1.0).abs() <= K * se + 1e-6,
                "σt {sigma}, channel {c}: {m} ± {se}"
            );
            assert!(se > 0.0 || m == 1.0, "σt {sigma}: no noise and not 1");
        }
    }
}

/// A ball of pure absorber seen against the sky: the centre pixels show
/// e^(−σt·2) per channel (the chord through the centre is 2 long), with
/// the medium entered through an interface, through a thin sheet of glass
/// (whose two crossings let (1 − R′)² through at normal incidence) and
/// with the camera inside it.
#[test]
fn an_absorber_lets_through_what_beer_lambert_says() {
    let dir = scratch_dir("media-absorber");
    let sigma = [0.3f64, 1.0, 2.0];
    let media = format!("[media.ink]\nsigma_t = {sigma:?}\nalbedo = 0");
    let scene = compile_file(
        &dir,
        "ink.toml",
        &ball(&media, "type = \"interface\"\ninterior = \"ink\"", "", 8),
    );
    // The central pixels' chords are 2 to within 0.3 %.
    assert_through(&pixel_stats(&scene), sigma, 2.0, "interface");
    // The camera inside the ink sees the sky through 1 unit of it.
    let scene = compile_file(
        &dir,
        "inside.toml",
        &ball(
            &media,
            "type = \"interface\"\ninterior = \"ink\"",
            "medium = \"ink\"",
            8,
        )
        .replace("lookfrom = [0, 0, 3]", "lookfrom = [0, 0, 0.001]")
        .replace("lookat = [0, 0, 0]", "lookat = [0, 0, -1]"),
    );
    assert_through(&pixel_stats(&scene), sigma, 1.001, "camera inside");
}

/// The central pixels of `stats` show e^(−σt·`length`) per channel, within
/// K standard errors and 1 % (the spread of their chords' lengths).
fn assert_through(stats: &common::PixelStats, sigma: [f64; 3], length: f64, what: &str) {
    for (c, s) in sigma.iter().enumerate() {
        let (m, se) = stats.region(3..5, 3..5, c);
        let want = (-s * length).exp();
        assert!(
            (m - want).abs() <= K * se + 0.01 * want,
            "{what}, channel {c}: {m} ± {se} against {want}"
        );
    }
}

/// Thin glass around a medium lets shadow rays through: a ball of thin
/// glass holding a white fog, lit by the sky, gives the same image whether
/// paths find the sky by sampling it or only by their bounces.
#[test]
fn light_sampled_through_thin_glass_agrees_with_the_bounces() {
    let dir = scratch_dir("media-thin");
    let media = "[media.fog]\nsigma_t = 1.5\nalbedo = [0.9, 0.6, 0.3]";
    let material = "type = \"dielectric\"\nior = 1.5\nthin = true\ninterior = \"fog\"";
    assert_estimators_agree(&dir, media, material, "thin glass");
}

/// Particles that scatter forward or back (Henyey–Greenstein): light
/// found by sampling the sky and light found only by the bounces agree, so
/// the density a scattering is sampled with is the one light sampling
/// weighs it by.
#[test]
fn forward_and_back_scattering_agree_between_estimators() {
    let dir = scratch_dir("media-hg");
    for g in ["0.7", "-0.6"] {
        let media = format!("[media.fog]\nsigma_t = 2\nalbedo = [0.95, 0.8, 0.5]\ng = {g}");
        let material = "type = \"interface\"\ninterior = \"fog\"";
        assert_estimators_agree(&dir, &media, material, &format!("g = {g}"));
    }
}

/// The ball of `material` holding `media` under the sky gives the same
/// middle of the image whether paths sample the sky or only find it by
/// their bounces.
fn assert_estimators_agree(dir: &std::path::Path, media: &str, material: &str, what: &str) {
    let text = ball(media, material, "", 12);
    let sampled = text.replace("seed = 5", "seed = 5\nsample_background = true");
    let bounces = text.replace("seed = 5", "seed = 9\nintegrator = \"bsdf\"");
    let a = pixel_stats(&compile_file(dir, "a.toml", &sampled));
    let b = pixel_stats(&compile_file(dir, "b.toml", &bounces));
    for c in 0..3 {
        common::assert_agree(
            &format!("{what}, channel {c}"),
            a.region(2..6, 2..6, c),
            b.region(2..6, 2..6, c),
        );
    }
}

/// Single scattering of sunlight in a slab, seen from the camera through
/// it: with paths of two segments (the camera's and the shadow ray), the
/// image is ∫ σs E p(θ) e^(−σt t) e^(−σt (1 − t)/cos θ) dt over the slab's
/// depth, θ the angle between the sunlight and the view. Forward
/// scattering (g > 0, the sun behind the slab) brightens it by the
/// Henyey–Greenstein factor, back scattering dims it.
#[test]
fn sunlight_scattered_once_in_a_slab_follows_the_phase_function() {
    let dir = scratch_dir("media-slab");
    let (sigma_t, albedo, irradiance) = (0.5f64, 0.8f64, 2.0f64);
    // The sun 30° off the view axis, behind the slab.
    let cos = 30f64.to_radians().cos();
    for g in [0.0f64, 0.6, -0.6] {
        let text = format!(
            "[render]\nwidth = 4\nheight = 4\nsamples_per_pixel = 1024\nmax_depth = 2\nseed = 3\n\
             [camera]\nlookfrom = [0, 0, -5]\nlookat = [0, 0, 0]\nvfov = 1\nmedium = \"slab\"\n\
             [background]\ntype = \"solid\"\ncolor = [0, 0, 0]\n\
             [media.slab]\nsigma_t = {sigma_t}\nalbedo = {albedo}\ng = {g}\n\
             box = {{ min = [-100, -100, 0], max = [100, 100, 1] }}\n\
             [[lights]]\ntype = \"directional\"\ndirection = [{}, 0, {}]\nirradiance = [{irradiance}, {irradiance}, {irradiance}]\n",
            (1.0 - cos * cos).sqrt(),
            -cos
        );
        let stats = pixel_stats(&compile_file(&dir, "slab.toml", &text));
        let phase =
            (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5));
        let k = sigma_t * (1.0 / cos - 1.0);
        let depth_integral = (-sigma_t / cos).exp() * (k.exp() - 1.0) / k;
        let want = sigma_t * albedo * irradiance * phase * depth_integral;
        let (m, se) = stats.image(1);
        assert!(
            (m - want).abs() <= K * se,
            "g = {g}: {m} ± {se} against {want}"
        );
    }
}

/// What is wrong with a medium or a reference to one is named.
#[test]
fn bad_media_are_refused_with_the_field() {
    let dir = scratch_dir("media-errors");
    let fail = |media: &str, material: &str, camera: &str| -> String {
        let path = dir.join("bad.toml");
        std::fs::write(&path, ball(media, material, camera, 4)).unwrap();
        match SceneFile::read(&path).and_then(|f| f.compile(&Overrides::default())) {
            Ok(_) => panic!("accepted: {media} / {material} / {camera}"),
            Err(e) => e.to_string(),
        }
    };
    let fog = "[media.fog]\nsigma_t = 1\nalbedo = 0.5";
    let e = fail(fog, "type = \"interface\"\ninterior = \"smoke\"", "");
    assert!(
        e.contains("materials.ball.interior") && e.contains("smoke") && e.contains("fog"),
        "{e}"
    );
    let e = fail(
        fog,
        "type = \"diffuse\"\nalbedo = [1, 1, 1]",
        "medium = \"mist\"",
    );
    assert!(e.contains("camera.medium") && e.contains("mist"), "{e}");
    let e = fail(
        "[media.fog]\nsigma_t = 1\nalbedo = 1.5",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(e.contains("media.fog.albedo"), "{e}");
    let e = fail(
        "[media.fog]\nsigma_t = -1\nalbedo = 0.5",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(e.contains("media.fog.sigma_t"), "{e}");
    let e = fail(
        "[media.fog]\nsigma_t = { grid = \"missing.vol\" }\nalbedo = 0.5",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(
        e.contains("media.fog.sigma_t.grid") && e.contains("missing.vol"),
        "{e}"
    );
    let e = fail(
        "[media.fog]\nsigma_t = 1\nalbedo = 0.5\ncolour = 3",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(e.contains("colour"), "{e}");
    let e = fail(
        "[media.fog]\nsigma_t = 1\nalbedo = 0.5\ng = 1",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(e.contains("media.fog.g") && e.contains("0.999"), "{e}");
    let e = fail(
        "[media.fog]\nsigma_t = { voxels = [2, 1, 1], values = [1, 2, 3, 4] }\nalbedo = 0.5",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(
        e.contains("media.fog.sigma_t.values") && e.contains("holds 4 values for 2×1×1 voxels"),
        "{e}"
    );
    let e = fail(
        "[media.fog]\nsigma_t = { voxels = [1, 1, 1], values = [-1] }\nalbedo = 0.5",
        "type = \"interface\"\ninterior = \"fog\"",
        "",
    );
    assert!(
        e.contains("media.fog.sigma_t.values") && e.contains("≥ 0"),
        "{e}"
    );
}
