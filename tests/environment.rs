//! The environment as a light: white furnaces stay white with next-event
//! estimation and MIS on, under one colour and under an image; the `path`
//! and `bsdf` integrators agree under an image sky with a sun, and choosing
//! lights uniformly or by power changes only the noise; image backgrounds
//! read EXR and Radiance HDR, are part of a scene's identity, and bad ones
//! are refused with the field and the file named.
//!
//! Tolerances are K standard errors from each render's own per-pixel sample
//! variance; seeds are fixed.

mod common;

use common::{
    assert_tiles_agree, compile_file, furnace_desc, pixel_stats, scene_file, scene_file_error,
    scratch_dir, tiles_agree, PixelStats, K,
};
use lumen::scene::desc::{DiffuseDesc, MaterialDesc};
use lumen::scene::{Integrator, LightSelection, Overrides, Sampling, Scene};
use std::path::Path;

/// Writes a `w × h` OpenEXR image whose texel (x, y) is `f(x, y)`.
fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3] + Sync) {
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let [r, g, b] = f(x, y);
        (r, g, b)
    })
    .unwrap();
}

/// A sky of soft blue with a small, very bright sun above the horizon
/// (about a thousand times the sky), to the right of the view.
fn sunny_sky(x: usize, y: usize) -> [f32; 3] {
    if (20..22).contains(&x) && (5..7).contains(&y) {
        [3000.0, 2800.0, 2500.0]
    } else if y < 16 {
        [0.3, 0.5, 0.9]
    } else {
        [0.2, 0.18, 0.15]
    }
}

/// Asserts that every channel of the image has mean 1 within `K` standard
/// errors, and that the render did trace shadow rays.
fn assert_white(what: &str, stats: &PixelStats) {
    for c in 0..3 {
        let (mean, se) = stats.image(c);
        assert!(
            (mean - 1.0).abs() <= K * se && se < 0.01,
            "{what}, channel {c}: furnace mean {mean} ± {se}, expected 1"
        );
    }
    let segments = stats.stats.rays as f64 / stats.stats.samples as f64;
    assert!(
        segments > 1.2,
        "{what}: {segments} rays per sample: no NEE?"
    );
}

#[test]
fn white_furnace_with_next_event_estimation_and_mis_is_white() {
    let lambertian = MaterialDesc::Diffuse(DiffuseDesc {
        albedo: [1.0; 3].into(),
        bounce: Default::default(),
        attenuation: Default::default(),
        ..Default::default()
    });
    for sampler in [Sampling::Sobol, Sampling::Independent] {
        let mut desc = furnace_desc(lambertian.clone(), 32, 24, 32, 50);
        desc.render.integrator = Integrator::Path;
        desc.render.sampler = sampler;
        // One colour is not sampled unless asked for.
        assert!(Scene::from_desc(&desc).unwrap().lights.is_empty());
        desc.render.sample_background = Some(true);
        let scene = Scene::from_desc(&desc).unwrap();
        assert_eq!(scene.lights.len(), 1);
        let stats = pixel_stats(&scene);
        assert_white(&format!("solid sky, {sampler:?}"), &stats);
        // MIS makes single samples differ from 1 (the two strategies'
        // weights add up to 1 only on average), so this is a real test.
        assert!(stats.max[0] > 1.0, "no sample above 1: was NEE on?");
    }
}

/// The same furnace with the white sky given as an image (uneven texel
/// sizes on the sphere of directions, a Jacobian, a 2-D distribution) and
/// a convex mesh beside the sphere.
#[test]
fn white_furnace_under_a_white_image_is_white() {
    let dir = scratch_dir("env-furnace");
    write_exr(&dir.join("white.exr"), 32, 16, |_, _| [1.0; 3]);
    std::fs::write(dir.join("ball.obj"), common::icosphere_obj(2, 0.6, None)).unwrap();
    let text = r#"[render]
width = 32
height = 24
samples_per_pixel = 32
gamma = 1

[camera]
vfov = 90

[background]
type = "image"
file = "white.exr"
rotation = 30

[materials.white]
type = "diffuse"
albedo = [1, 1, 1]

[[objects]]
type = "sphere"
center = [-0.8, 0, -2]
radius = 0.7
material = "white"

[[objects]]
type = "mesh"
file = "ball.obj"
material = "white"
transform = [{ translate = [1, 0, -2.2] }]
"#;
    let scene = compile_file(&dir, "furnace.toml", text);
    assert_eq!(scene.settings.integrator, Integrator::Path);
    assert_white("white image sky", &pixel_stats(&scene));
}

/// A matte floor, a matte ball and a mirror ball under [`sunny_sky`]; the
/// sun lies outside the view. Most of the light comes from a sun that the
/// bounces rarely find.
fn sunny_scene(dir: &Path, rotation: f64) -> String {
    write_exr(&dir.join("sky.exr"), 32, 32, sunny_sky);
    format!(
        r#"[render]
width = 32
height = 24
samples_per_pixel = 64
seed = 3
gamma = 1

[camera]
lookfrom = [0, 1, 4]
lookat = [0, 0.5, 0]
vfov = 40

[background]
type = "image"
file = "sky.exr"
rotation = {rotation}
intensity = 0.5

[materials.ground]
type = "diffuse"
albedo = [0.6, 0.6, 0.6]

[materials.matte]
type = "diffuse"
albedo = [0.8, 0.3, 0.2]

[materials.mirror]
type = "metal"
albedo = [0.9, 0.9, 0.9]

[[objects]]
type = "quad"
corner = [-20, 0, -20]
u = [0, 0, 40]
v = [40, 0, 0]
material = "ground"

[[objects]]
type = "sphere"
center = [-0.6, 0.5, 0]
radius = 0.5
material = "matte"

[[objects]]
type = "sphere"
center = [0.7, 0.5, -0.3]
radius = 0.5
material = "mirror"
"#
    )
}

#[test]
fn path_and_bsdf_agree_under_an_image_sky_with_a_sun() {
    let dir = scratch_dir("env-sun");
    let path = compile_file(&dir, "sun.toml", &sunny_scene(&dir, 40.0));
    let mut bsdf = path.clone();
    bsdf.settings.integrator = Integrator::Bsdf;
    bsdf.settings.samples_per_pixel = 512;
    let (path, bsdf) = (pixel_stats(&path), pixel_stats(&bsdf));
    assert_tiles_agree("sunny sky", &path, &bsdf);
    // The sun is found: the shadowed and the lit ground differ, and the
    // image is far brighter than the sky alone would make it.
    let (mean, _) = path.image(0);
    assert!(mean > 1.0, "mean {mean}: the sun is missing");
}

#[test]
fn choosing_lights_uniformly_or_by_power_gives_the_same_image() {
    // A sky and a small bright lamp: by power the sky is chosen far more
    // often; uniformly, half the time each.
    let dir = scratch_dir("env-selection");
    let mut text = sunny_scene(&dir, -60.0);
    text.push_str(
        r#"
[materials.lamp]
type = "emissive"
radiance = [40, 30, 20]

[[objects]]
type = "sphere"
center = [0, 1.6, 0.5]
radius = 0.1
material = "lamp"
"#,
    );
    let power = compile_file(&dir, "lamp.toml", &text);
    assert_eq!(power.lights.len(), 2);
    let mut uniform = power.clone();
    uniform.settings.light_selection = LightSelection::Uniform;
    let overrides = Overrides {
        light_selection: Some(LightSelection::Uniform),
        ..Overrides::default()
    };
    let from_file = scene_file(&dir, "lamp.toml", &text)
        .compile(&overrides)
        .unwrap();
    assert_eq!(from_file.lights.chance(0), 0.5, "--light-selection uniform");
    assert!(power.lights.chance(0) < 0.2, "{}", power.lights.chance(0));
    tiles_agree(
        "light selection",
        &pixel_stats(&power),
        &pixel_stats(&from_file),
    );
}

/// Radiance HDR files are read as well as EXR, and give the same image.
#[test]
fn radiance_hdr_and_exr_skies_render_alike() {
    let dir = scratch_dir("env-hdr");
    let (w, h) = (16, 8);
    let texels: Vec<image::Rgb<f32>> = (0..w * h)
        .map(|i| image::Rgb([0.25 + (i % w) as f32 / 8.0, 1.0, 0.5 + (i / w) as f32]))
        .collect();
    let file = std::fs::File::create(dir.join("sky.hdr")).unwrap();
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&texels, w, h)
        .unwrap();
    // RGBE keeps 8 bits of mantissa: write the EXR from what the HDR holds.
    let hdr = lumen::texture::Image::read(&dir.join("sky.hdr")).unwrap();
    write_exr(&dir.join("sky.exr"), w, h, |x, y| {
        hdr.texel(x, y).to_array()
    });
    for (x, y) in [(0, 0), (5, 3), (15, 7)] {
        let want = texels[y * w + x].0;
        let got = hdr.texel(x, y).to_array();
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= want[c] / 64.0,
                "{got:?} {want:?}"
            );
        }
    }
    let scene = |file: &str| {
        let text = format!(
            "[render]\nwidth = 16\nheight = 8\nsamples_per_pixel = 2\n\n\
             [background]\ntype = \"image\"\nfile = \"{file}\"\n"
        );
        let scene = compile_file(&dir, "sky.toml", &text);
        lumen::render::render(&scene, &|_| {}).0
    };
    assert_eq!(scene("sky.hdr").raw().0, scene("sky.exr").raw().0);
}

/// The image is part of the scene's identity, by content: a checkpoint of
/// one sky does not resume under another.
#[test]
fn an_image_sky_is_part_of_the_scene_identity() {
    let dir = scratch_dir("env-identity");
    let text = "[background]\ntype = \"image\"\nfile = \"sky.exr\"\n";
    write_exr(&dir.join("sky.exr"), 8, 4, |_, _| [0.5; 3]);
    let first = compile_file(&dir, "s.toml", text);
    write_exr(&dir.join("sky.exr"), 8, 4, |x, _| [0.5, 0.5, x as f32]);
    let second = compile_file(&dir, "s.toml", text);
    assert_eq!(first.sources.len(), 1);
    assert_eq!(first.sources[0].file, "sky.exr");
    assert_ne!(first.sources, second.sources);
    let desc = scene_file(&dir, "s.toml", text).desc;
    let identity = |s: &Scene| lumen::checkpoint::identity_text(&desc, &s.sources);
    assert_ne!(identity(&first), identity(&second));
}

/// Each bad image background gives one message naming the field and what
/// is wrong.
#[test]
fn bad_image_backgrounds_are_refused_with_the_field_named() {
    let dir = scratch_dir("env-errors");
    std::fs::write(dir.join("notes.txt"), "not an image").unwrap();
    write_exr(&dir.join("nan.exr"), 4, 2, |x, y| {
        if (x, y) == (3, 1) {
            [1.0, f32::NAN, 0.0]
        } else {
            [1.0; 3]
        }
    });
    write_exr(&dir.join("ok.exr"), 4, 2, |_, _| [1.0; 3]);
    let cases = [
        ("file = \"missing.exr\"", "background.file", "missing.exr"),
        ("file = \"notes.txt\"", "background.file", "notes.txt"),
        ("file = \"nan.exr\"", "background.file", "texel (3, 1)"),
        (
            "file = \"ok.exr\"\nintensity = -1",
            "background.intensity",
            "negative",
        ),
        (
            "file = \"ok.exr\"\nrotation = 1e300",
            "background.rotation",
            "finite",
        ),
        ("rotation = 3", "background.file", "missing"),
        (
            "file = \"ok.exr\"\ncolor = [1, 1, 1]",
            "background.color",
            "solid",
        ),
        ("file = 3", "background.file", "string"),
    ];
    for (fields, field, words) in cases {
        let text = format!("[background]\ntype = \"image\"\n{fields}\n");
        let message = scene_file_error(&dir, &text);
        assert!(
            message.contains(field) && message.contains(words),
            "{fields}: {message}"
        );
    }
}
