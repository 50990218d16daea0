//! Next-event estimation with multiple importance sampling (the `path`
//! integrator) against the notes' estimator (`bsdf`) and exact answers: both
//! converge to the same image with quad, sphere and (instanced, mirrored)
//! triangle lights, and the `path` integrator is the less noisy; its
//! Russian roulette leaves the image of a scene without lights unchanged.
//!
//! Tolerances are K standard errors from each render's own per-pixel sample
//! variance; seeds are fixed.

mod common;

use common::{
    assert_tiles_agree, ball_in_light, builtin_desc, compile_file, path_and_bsdf, pixel_stats,
    scratch_dir, tiles_agree, K,
};
use lumen::scene::{Integrator, Sampling, Scene};

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
fn sphere_light() -> String {
    common::on_dark_floor(
        4,
        "vfov = 50\nlookfrom = [0, 2, 6]\nlookat = [0, 0.5, 0]",
        r#"[materials.bulb]
type = "emissive"
radiance = [12, 10, 8]

[materials.panel]
type = "emissive"
radiance = [1, 2, 3]
two_sided = true

[materials.matte]
type = "diffuse"
albedo = [0.7, 0.6, 0.5]

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
"#,
    )
}

#[test]
fn path_and_bsdf_agree_under_sphere_and_quad_lights() {
    let dir = scratch_dir("lights-sphere");
    let (path, bsdf) = path_and_bsdf(&dir, &sphere_light());
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
    let text = sphere_light().replace(
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
    let (path, bsdf) = path_and_bsdf(&dir, &text);
    assert_tiles_agree("triangle lights", &path, &bsdf);
}

#[test]
fn a_ball_inside_a_light_returns_its_albedo_times_the_radiance() {
    // The camera and a matte ball inside a two-sided ball of light: every
    // bounce off the ball meets the light, so each pixel's expected value
    // is exactly albedo × radiance, and next-event estimation must keep it.
    let dir = scratch_dir("lights-enclosure");
    let render =
        "width = 16\nheight = 12\nsamples_per_pixel = 64\nmax_depth = 3\nintegrator = \"path\"";
    let scene = compile_file(
        &dir,
        "scene.toml",
        &ball_in_light(render, true, [0.5, 0.25, 1.0], true),
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
fn russian_roulette_keeps_the_image_of_a_scene_without_lights() {
    // The cover under its sky: glass and metal keep many paths going past
    // the bounces where the `path` integrator starts its roulette, which
    // must end them without changing the image.
    let stats = |integrator| {
        let mut desc = builtin_desc("cover", 48, 128, 6);
        desc.render.integrator = integrator;
        desc.render.sampler = Sampling::Sobol;
        let mut scene = Scene::from_desc(&desc).unwrap();
        // The sky is not sampled here, so that the segments counted are
        // the paths' own, and only the roulette shortens them.
        scene.lights = Default::default();
        pixel_stats(&scene)
    };
    let (path, bsdf) = (stats(Integrator::Path), stats(Integrator::Bsdf));
    tiles_agree("cover", &path, &bsdf);
    // The roulette did end paths: fewer segments were traced.
    assert!(
        path.stats.rays < bsdf.stats.rays,
        "{} segments with roulette, {} without",
        path.stats.rays,
        bsdf.stats.rays
    );
}

#[test]
fn the_figures_keep_the_books_estimator() {
    // Every built-in figure gathers light as its book does, so that it
    // renders as it always has: the first two books by the bounces alone,
    // The Rest of Your Life by sampling its light too.
    use lumen::scene::builtin::Book;
    for b in lumen::scene::builtin::BUILTINS {
        let expected = match b.book {
            Book::OneWeekend | Book::NextWeek => Integrator::Bsdf,
            Book::RestOfYourLife | Book::Materials => Integrator::Path,
        };
        assert_eq!(b.desc().render.integrator, expected, "{}", b.name);
    }
}

#[test]
fn an_integrating_sphere_reaches_its_analytic_radiance() {
    // A small ball of light (radius r, radiance Le, one-sided) at the centre
    // of a closed matte sphere (radius R, albedo a). Light leaving any point
    // of a sphere's inside towards it is spread evenly over it, and a
    // fraction f = r²/R² of each bounce's light returns to the ball, which
    // absorbs it; so the wall's irradiance is Φ / (A (1 − a (1 − f))) with
    // Φ = Le·π·4πr² and A = 4πR², and its radiance
    //   L = a Le r² / (R² (1 − a (1 − f))).
    // Most of it comes after many bounces, past those where the roulette
    // starts: an unweighted survivor would show at once.
    let (r, big_r, a, le) = (1.0f64, 10.0f64, 0.9f64, 100.0f64);
    let f = r * r / (big_r * big_r);
    let exact = a * le * r * r / (big_r * big_r * (1.0 - a * (1.0 - f)));
    let dir = scratch_dir("lights-integrating-sphere");
    let scene = compile_file(
        &dir,
        "scene.toml",
        &format!(
            r#"[render]
width = 16
height = 16
samples_per_pixel = 256
max_depth = 400

[camera]
vfov = 40
lookfrom = [0, 0, 5]
lookat = [0, 0, 10]

[background]
type = "solid"
color = [0, 0, 0]

[materials.light]
type = "emissive"
radiance = [{le}, {le}, {le}]

[materials.wall]
type = "diffuse"
albedo = [{a}, {a}, {a}]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = {r}
material = "light"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = {big_r}
material = "wall"
"#
        ),
    );
    assert_eq!(scene.settings.integrator, Integrator::Path);
    let stats = pixel_stats(&scene);
    let (mean, se) = stats.image(1);
    assert!(
        (mean - exact).abs() <= K * se,
        "{mean} ± {se}, expected {exact}"
    );
    assert!(se < 0.01 * exact, "too noisy to tell: {se}");
}

#[test]
fn black_lights_render_black_without_nan() {
    // Emissive objects of zero radiance are no lights to sample: the scene
    // renders, black, with either integrator.
    let dir = scratch_dir("lights-black");
    let text = sphere_light()
        .replace("radiance = [12, 10, 8]", "radiance = [0, 0, 0]")
        .replace("radiance = [1, 2, 3]", "radiance = [0, 0, 0]")
        .replace("samples_per_pixel = 128", "samples_per_pixel = 4");
    for integrator in [Integrator::Path, Integrator::Bsdf] {
        let mut scene = compile_file(&dir, "scene.toml", &text);
        scene.settings.integrator = integrator;
        assert!(scene.lights.is_empty());
        let (film, _) = lumen::render::render(&scene, &|_| {});
        assert!(
            film.pixels().all(|p| p == lumen::math::Color::ZERO),
            "{integrator:?}"
        );
    }
}

#[test]
fn a_light_close_to_a_surface_far_from_the_origin_still_lights_it() {
    // Far from the origin the hit point's rounding bound grows; the shadow
    // ray must still stop short of the light it was aimed at rather than
    // meet it and call the surface shadowed.
    let dir = scratch_dir("lights-far");
    let text = r#"[render]
width = 24
height = 24
samples_per_pixel = 64
max_depth = 2

[camera]
vfov = 30
lookfrom = [5000, 3, 5004]
lookat = [5000, 0, 5000]

[background]
type = "solid"
color = [0, 0, 0]

[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.lamp]
type = "emissive"
radiance = [4, 4, 4]

[[objects]]
type = "quad"
corner = [4990, 0, 4990]
u = [0, 0, 20]
v = [20, 0, 0]
material = "floor"

[[objects]]
type = "quad"
corner = [4999, 1, 4999]
u = [2, 0, 0]
v = [0, 0, 2]
material = "lamp"
"#;
    let (path, bsdf) = path_and_bsdf(&dir, text);
    assert_tiles_agree("light near a far floor", &path, &bsdf);
}

#[test]
fn lights_reflect_off_smooth_meshes_as_the_bounces_find_them() {
    // A floor of two triangles whose vertex normals lean 60° towards +x:
    // a third of the bounces about them dip under the true floor and are
    // mirrored above it, towards the low lamp on the +x side. Both
    // strategies' densities must count those directions.
    let dir = scratch_dir("lights-smooth");
    let (s, c) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
    std::fs::write(
        dir.join("floor.obj"),
        format!(
            "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nvn {s} {c} 0\n\
             f 1//1 3//1 2//1\nf 1//1 4//1 3//1\n"
        ),
    )
    .unwrap();
    let text = r#"[render]
width = 24
height = 24
samples_per_pixel = 256
max_depth = 2

[camera]
vfov = 40
lookfrom = [0, 6, 0.01]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0, 0, 0]

[materials.matte]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.lamp]
type = "emissive"
radiance = [5, 5, 5]
two_sided = true

[[objects]]
type = "mesh"
file = "floor.obj"
material = "matte"

[[objects]]
type = "quad"
corner = [3, 0.2, -1]
u = [0, 0, 2]
v = [0, 0.6, 0]
material = "lamp"
"#;
    let (path, bsdf) = path_and_bsdf(&dir, text);
    assert_tiles_agree("smooth mesh", &path, &bsdf);
}
