//! Next-event estimation with multiple importance sampling (the `path`
//! integrator) against the notes' estimator (`bsdf`) and exact answers: both
//! converge to the same image with quad, sphere and (instanced, mirrored)
//! triangle lights, and the `path` integrator is the less noisy.
//!
//! Tolerances are K standard errors from each render's own per-pixel sample
//! variance; seeds are fixed.

mod common;

use common::{assert_agree, builtin_desc, compile_file, pixel_stats, scratch_dir, PixelStats, K};
use lumen::scene::{Integrator, Sampling, Scene};

/// Each 8 × 8 tile of two renders of one view agrees in every channel; the
/// first (the `path` render) has the smaller standard error over the image.
fn assert_tiles_agree(what: &str, path: &PixelStats, bsdf: &PixelStats) {
    let mut noise = (0.0, 0.0);
    for c in 0..3 {
        for ty in 0..path.height / 8 {
            for tx in 0..path.width / 8 {
                let tile = |s: &PixelStats| s.region(tx * 8..tx * 8 + 8, ty * 8..ty * 8 + 8, c);
                let (a, b) = (tile(path), tile(bsdf));
                assert_agree(&format!("{what}: tile ({tx}, {ty}), channel {c}"), a, b);
                noise.0 += a.1;
                noise.1 += b.1;
            }
        }
    }
    assert!(
        noise.0 < noise.1,
        "{what}: path's tiles are noisier ({} against {})",
        noise.0,
        noise.1
    );
}

/// `text`'s scene rendered with each integrator.
fn both(dir: &std::path::Path, text: &str) -> (PixelStats, PixelStats) {
    let mut path = compile_file(dir, "scene.toml", text);
    path.settings.integrator = Integrator::Path;
    let mut bsdf = path.clone();
    bsdf.settings.integrator = Integrator::Bsdf;
    (pixel_stats(&path), pixel_stats(&bsdf))
}

#[test]
fn path_and_bsdf_agree_on_the_cornell_box() {
    let stats = |integrator, spp| {
        let mut desc = builtin_desc("cornell-box", 32, spp, 9);
        desc.render.integrator = integrator;
        desc.render.sampler = Sampling::Sobol;
        pixel_stats(&Scene::from_desc(&desc).unwrap())
    };
    let path = stats(Integrator::Path, 64);
    let bsdf = stats(Integrator::Bsdf, 256);
    assert_tiles_agree("cornell box", &path, &bsdf);
}

/// A floor and a matte ball under a small one-sided ball of light (and a
/// two-sided panel), black sky: direct light dominates.
const SPHERE_LIGHT: &str = r#"[render]
width = 32
height = 24
samples_per_pixel = 128
max_depth = 6
seed = 4

[camera]
vfov = 50
lookfrom = [0, 2, 6]
lookat = [0, 0.5, 0]

[background]
type = "solid"
color = [0, 0, 0]

[materials.bulb]
type = "emissive"
radiance = [12, 10, 8]

[materials.panel]
type = "emissive"
radiance = [1, 2, 3]
two_sided = true

[materials.matte]
type = "diffuse"
albedo = [0.7, 0.6, 0.5]

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[objects]]
type = "quad"
corner = [-10, 0, -10]
u = [0, 0, 20]
v = [20, 0, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "matte"

[[objects]]
type = "sphere"
center = [1.5, 3, 1]
radius = 0.4
material = "bulb"

[[objects]]
type = "quad"
corner = [-3, 0.5, -2]
u = [0, 2, 0]
v = [0, 0, 2]
material = "panel"
"#;

#[test]
fn path_and_bsdf_agree_under_sphere_and_quad_lights() {
    let dir = scratch_dir("lights-sphere");
    let (path, bsdf) = both(&dir, SPHERE_LIGHT);
    assert_tiles_agree("sphere light", &path, &bsdf);
}

#[test]
fn path_and_bsdf_agree_under_instanced_mirrored_triangle_lights() {
    // A square lamp of two triangles (counter-clockwise seen from below, so
    // it shines down), placed twice: once as it is, once mirrored in x,
    // which reverses its corners' order but not the side it shines to.
    let dir = scratch_dir("lights-mesh");
    std::fs::write(
        dir.join("lamp.obj"),
        "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let text = SPHERE_LIGHT.replace(
        "material = \"panel\"\n",
        "material = \"panel\"\n\n\
         [[objects]]\ntype = \"mesh\"\nfile = \"lamp.obj\"\nmaterial = \"lamp\"\n\
         transform = [ { translate = [-1.5, 2.5, 0.5] } ]\n\n\
         [[objects]]\ntype = \"mesh\"\nfile = \"lamp.obj\"\nmaterial = \"lamp\"\n\
         transform = [ { scale = [-1, 1, 1] }, { translate = [1, 2.2, -1] } ]\n",
    ) + "\n[materials.lamp]\ntype = \"emissive\"\nradiance = [6, 6, 6]\n";
    let scene = compile_file(&dir, "scene.toml", &text);
    assert_eq!(scene.stats.instances, 2, "the lamp is instanced");
    // The sphere, the panel and four triangles.
    assert_eq!(scene.lights.len(), 6);
    let (path, bsdf) = both(&dir, &text);
    assert_tiles_agree("triangle lights", &path, &bsdf);
}

#[test]
fn a_ball_inside_a_light_returns_its_albedo_times_the_radiance() {
    // The camera and a matte ball inside a two-sided ball of light: every
    // bounce off the ball meets the light, so each pixel's expected value
    // is exactly albedo × radiance, and next-event estimation must keep it.
    let dir = scratch_dir("lights-enclosure");
    let scene = compile_file(
        &dir,
        "scene.toml",
        r#"[render]
width = 16
height = 12
samples_per_pixel = 64
max_depth = 3
integrator = "path"

[camera]
vfov = 20
lookfrom = [0, 0, 0]
lookat = [0, 0, -1]

[background]
type = "solid"
color = [0, 0, 0]

[materials.light]
type = "emissive"
radiance = [2, 3, 4]
two_sided = true

[materials.matte]
type = "diffuse"
albedo = [0.5, 0.25, 1.0]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 10
material = "light"

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 1
material = "matte"
"#,
    );
    assert_eq!(scene.lights.len(), 1);
    let stats = pixel_stats(&scene);
    for (c, exact) in [1.0, 0.75, 4.0].into_iter().enumerate() {
        let (mean, se) = stats.image(c);
        assert!(
            (mean - exact).abs() <= K * se + 1e-5,
            "channel {c}: {mean} ± {se}, expected {exact}"
        );
        // The two strategies share each sample: its value varies.
        assert!(se > 0.0, "channel {c}");
    }
}

#[test]
fn without_lights_path_and_bsdf_render_the_same_image() {
    // Nothing to sample: the `path` integrator draws nothing more and gives
    // the same bits, which keeps every figure of the notes as it was.
    for name in ["cover", "glass-hollow", "bounce-cube"] {
        let mut desc = builtin_desc(name, 40, 4, 2);
        desc.render.sampler = Sampling::Sobol;
        desc.render.integrator = Integrator::Path;
        let path = Scene::from_desc(&desc).unwrap();
        desc.render.integrator = Integrator::Bsdf;
        let bsdf = Scene::from_desc(&desc).unwrap();
        let render = |s: &Scene| lumen::render::render(s, &|_| {}).0;
        let (a, b) = (render(&path), render(&bsdf));
        assert!(a.pixels().eq(b.pixels()), "{name}");
    }
}
