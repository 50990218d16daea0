//! Motion blur and participating media: a moving sphere covers a pixel for
//! exactly its share of the shutter; bounce and shadow rays keep the camera
//! ray's time; an absorbing medium lets through e^{−σℓ}; a white furnace
//! filled with scattering fog stays white with next-event estimation on;
//! the `path` and `bsdf` integrators agree on the smoky Cornell box; the
//! new built-ins render the same with any number of threads; bad media and
//! shutters are refused with the field named.
//!
//! Tolerances are K standard errors of the estimator (binomial for hit
//! fractions, each render's own per-pixel sample variance otherwise); seeds
//! are fixed.

mod common;

use common::{
    builtin_desc, compile_file, pixel_stats, render_with_threads, scene_file_error, scratch_dir,
    tiles_agree, K,
};
use lumen::scene::{Integrator, Scene};

/// One pixel looking down −z at a red-when-hit sphere of radius 0.5 at
/// z = −5 that moves from x = −2 (time 0) to x = +2 (time 1), seen while
/// the shutter is open from `open` to `close`.
fn moving_ball(open: f64, close: f64, spp: u32) -> String {
    format!(
        r#"
[render]
width = 1
height = 1
samples_per_pixel = {spp}
shading = "hit"
sampler = "center"
gamma = 1.0
[camera]
vfov = 10
shutter = [{open}, {close}]
[background]
type = "solid"
color = [0, 0, 0]
[materials.m]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[objects]]
type = "sphere"
center = [-2, 0, -5]
radius = 0.5
material = "m"
transform = [{{ motion = [4, 0, 0] }}]
"#
    )
}

/// The red channel of the single pixel: the fraction of its rays that hit.
fn coverage(scene: &Scene) -> f64 {
    let (film, _) = lumen::render::render(scene, &|_| {});
    let (sums, counts) = film.raw();
    sums[0].to_f64()[0] / f64::from(counts[0])
}

#[test]
fn a_moving_sphere_covers_a_pixel_for_its_share_of_the_shutter() {
    let dir = scratch_dir("motion-coverage");
    // The ray along −z hits while the centre's x is within ±0.5, that is
    // for t in (0.375, 0.625): a quarter of the full shutter.
    let n = 4000;
    let scene = compile_file(&dir, "full.toml", &moving_ball(0.0, 1.0, n));
    let p: f64 = 0.25;
    let se = (p * (1.0 - p) / f64::from(n)).sqrt();
    let got = coverage(&scene);
    assert!(
        (got - p).abs() <= K * se,
        "coverage {got}, expected {p} ± {se}"
    );
    // A shutter inside that window sees it always; one after it, never; a
    // shutter closed at an instant sees the ball where it is then.
    let always = compile_file(&dir, "inside.toml", &moving_ball(0.4, 0.6, 64));
    assert_eq!(coverage(&always), 1.0);
    let never = compile_file(&dir, "after.toml", &moving_ball(0.7, 1.0, 64));
    assert_eq!(coverage(&never), 0.0);
    assert_eq!(
        coverage(&compile_file(
            &dir,
            "instant.toml",
            &moving_ball(0.5, 0.5, 4)
        )),
        1.0
    );
    assert_eq!(
        coverage(&compile_file(&dir, "start.toml", &moving_ball(0.0, 0.0, 4))),
        0.0
    );
}

/// A floor under a one-sided light, and a ball between them that is at
/// `center` at time 0 and moves by `motion`, seen at the instant `time`.
fn shadow_scene(center: [f64; 3], motion: [f64; 3], time: f64, integrator: &str) -> String {
    // The bounces find the light by chance: they need more samples.
    let spp = if integrator == "path" { 48 } else { 384 };
    format!(
        r#"
[render]
width = 32
height = 32
samples_per_pixel = {spp}
integrator = "{integrator}"
gamma = 1.0
seed = 5
[camera]
lookfrom = [0, 6, 0.01]
lookat = [0, 0, 0]
vfov = 70
shutter = [{time}, {time}]
[background]
type = "solid"
color = [0, 0, 0]
[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.ball]
type = "diffuse"
albedo = [0.3, 0.6, 0.3]
[materials.lamp]
type = "emissive"
radiance = [5, 5, 5]
[[objects]]
type = "quad"
corner = [-4, 0, 4]
u = [8, 0, 0]
v = [0, 0, -8]
material = "floor"
[[objects]]
type = "quad"
corner = [-1, 4, -1]
u = [2, 0, 0]
v = [0, 0, 2]
material = "lamp"
[[objects]]
type = "sphere"
center = {center:?}
radius = 0.7
material = "ball"
transform = [{{ motion = {motion:?} }}]
"#
    )
}

/// Bounce rays (the `bsdf` integrator) and shadow rays (the `path`
/// integrator) see the ball where it is at the camera ray's time: a ball
/// moving through the middle of its path at t = 0.5 casts the shadow of a
/// ball standing there.
#[test]
fn bounces_and_shadow_rays_keep_the_camera_rays_time() {
    let dir = scratch_dir("motion-shadow");
    for integrator in ["path", "bsdf"] {
        let moving = compile_file(
            &dir,
            "moving.toml",
            &shadow_scene([-3.0, 1.5, 0.0], [6.0, 0.0, 0.0], 0.5, integrator),
        );
        let still = compile_file(
            &dir,
            "still.toml",
            &shadow_scene([0.0, 1.5, 0.0], [0.0; 3], 0.5, integrator),
        );
        let (a, b) = (pixel_stats(&moving), pixel_stats(&still));
        tiles_agree(&format!("{integrator}: moving vs still"), &a, &b);
        // And the test can tell: the ball where it starts casts its shadow
        // elsewhere, and some tile disagrees.
        let start = compile_file(
            &dir,
            "start.toml",
            &shadow_scene([-3.0, 1.5, 0.0], [6.0, 0.0, 0.0], 0.0, integrator),
        );
        let c = pixel_stats(&start);
        let differs = std::panic::catch_unwind(|| tiles_agree("start vs still", &c, &b)).is_err();
        assert!(differs, "{integrator}: the shadow did not move");
    }
}

/// A ball of black smoke (albedo 0) of density σ and radius 1 in front of a
/// white background: the central ray gets through with probability
/// e^{−2σ}, with both integrators.
#[test]
fn an_absorbing_medium_lets_through_e_to_the_minus_sigma_l() {
    let dir = scratch_dir("media-absorb");
    let sigma = 0.7;
    let n = 20_000;
    for integrator in ["path", "bsdf"] {
        let text = format!(
            r#"
[render]
width = 1
height = 1
samples_per_pixel = {n}
sampler = "center"
integrator = "{integrator}"
gamma = 1.0
[camera]
vfov = 1
[background]
type = "solid"
color = [1, 1, 1]
[[objects]]
type = "medium"
boundary = {{ type = "sphere", center = [0, 0, -3], radius = 1 }}
density = {sigma}
albedo = [0, 0, 0]
"#
        );
        let scene = compile_file(&dir, "smoke.toml", &text);
        let p = (-2.0f64 * sigma).exp();
        let se = (p * (1.0 - p) / f64::from(n)).sqrt();
        let got = coverage(&scene);
        assert!(
            (got - p).abs() <= K * se,
            "{integrator}: {got}, expected {p} ± {se}"
        );
    }
}

/// A white furnace full of fog: a ball of scattering medium of albedo 1
/// under a sky of 1 everywhere, the sky sampled as a light from inside the
/// fog (shadow rays carry the medium's transmittance, MIS weighs them
/// against the phase function's bounces). Every pixel is 1 within its
/// standard error; leaving the transmittance out of the shadow rays makes
/// the ball brighter than its surroundings.
#[test]
fn a_white_furnace_full_of_fog_stays_white() {
    let dir = scratch_dir("media-furnace");
    for integrator in ["path", "bsdf"] {
        let text = format!(
            r#"
[render]
width = 8
height = 8
samples_per_pixel = 256
max_depth = 200
integrator = "{integrator}"
sample_background = true
gamma = 1.0
seed = 3
[camera]
vfov = 40
[background]
type = "solid"
color = [1, 1, 1]
[[objects]]
type = "medium"
boundary = {{ type = "box", min = [-1, -1, -4], max = [1, 1, -2] }}
density = 1.5
albedo = [1, 1, 1]
transform = [{{ rotate = {{ axis = [1, 1, 0], degrees = 30 }} }}]
"#
        );
        let scene = compile_file(&dir, "fog.toml", &text);
        let stats = pixel_stats(&scene);
        for c in 0..3 {
            let (mean, se) = stats.image(c);
            assert!(
                (mean - 1.0).abs() <= K * se && se < 0.01,
                "{integrator}, channel {c}: furnace {mean} ± {se}"
            );
        }
        if integrator == "path" {
            let segments = stats.stats.rays as f64 / stats.stats.samples as f64;
            assert!(
                segments > 1.5,
                "{segments} rays per sample: no NEE in the fog?"
            );
        }
    }
}

/// The Next Week's smoky Cornell box: `path` (lights sampled from surfaces
/// and from inside the smoke) and `bsdf` (the book's estimator) converge
/// to the same image, tile by tile.
#[test]
fn path_and_bsdf_agree_on_the_smoky_cornell_box() {
    let render = |integrator: Integrator, spp: u32| {
        let mut desc = builtin_desc("cornell-smoke", 32, spp, 9);
        desc.render.integrator = integrator;
        desc.render.max_depth = 20;
        pixel_stats(&Scene::from_desc(&desc).unwrap())
    };
    let path = render(Integrator::Path, 96);
    let bsdf = render(Integrator::Bsdf, 384);
    let noise = tiles_agree("cornell-smoke", &path, &bsdf);
    assert!(
        noise.0 < noise.1,
        "path is noisier than bsdf ({} against {})",
        noise.0,
        noise.1
    );
}

#[test]
fn the_new_built_ins_render_the_same_with_any_number_of_threads() {
    for name in [
        "bouncing-spheres",
        "cornell-smoke",
        "next-week-final",
        "cornell-glass-sphere",
        "earth",
    ] {
        let scene = Scene::from_desc(&builtin_desc(name, 40, 3, 7)).unwrap();
        let (one, _) = render_with_threads(&scene, 1);
        let (three, _) = render_with_threads(&scene, 3);
        assert!(one == three, "{name}: 1 and 3 threads differ");
        let (sums, _) = one.raw();
        assert!(
            sums.iter().flat_map(|s| s.0).any(|v| v > 0),
            "{name}: not a lit image"
        );
    }
}

#[test]
fn bad_media_and_shutters_are_refused_with_the_field_named() {
    let dir = scratch_dir("media-bad");
    let medium = |fields: &str| {
        format!(
            "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [[objects]]\ntype = \"medium\"\n{fields}\n"
        )
    };
    let ball = "boundary = { type = \"sphere\", center = [0, 0, -2], radius = 1 }";
    for (text, expected) in [
        (
            medium(&format!("{ball}\ndensity = 0\nalbedo = [1, 1, 1]")),
            "objects[0].density: must be greater than 0",
        ),
        (
            medium(&format!("{ball}\ndensity = -1\nalbedo = [1, 1, 1]")),
            "objects[0].density: must be greater than 0",
        ),
        (
            medium(&format!("{ball}\ndensity = 1\nalbedo = [1, 2, 1]")),
            "objects[0].albedo",
        ),
        (
            medium("boundary = { type = \"sphere\", center = [0, 0, -2], radius = 0 }\ndensity = 1\nalbedo = [1, 1, 1]"),
            "objects[0].boundary.radius: must be greater than 0",
        ),
        (
            medium("boundary = { type = \"box\", min = [0, 0, 0], max = [1, 0, 1] }\ndensity = 1\nalbedo = [1, 1, 1]"),
            "objects[0].boundary.max: must be greater than min",
        ),
        (
            medium("boundary = { type = \"cone\" }\ndensity = 1\nalbedo = [1, 1, 1]"),
            "objects[0].boundary.type",
        ),
        (
            medium(&format!("{ball}\nalbedo = [1, 1, 1]")),
            "density",
        ),
        (
            medium(&format!("{ball}\ndensity = 1\nalbedo = [1, 1, 1]\nmaterial = \"m\"")),
            "objects[0].material",
        ),
        (
            medium(&format!(
                "{ball}\ndensity = 1\nalbedo = [1, 1, 1]\ntransform = [{{ motion = [1, 0, 0] }}]"
            )),
            "objects[0].transform: a medium cannot move",
        ),
        (
            "[camera]\nshutter = [0.6, 0.4]\n".to_string(),
            "camera.shutter: shutter must be [open, close] with 0 <= open <= close <= 1",
        ),
        (
            "[camera]\nshutter = [0, 2]\n".to_string(),
            "camera.shutter",
        ),
        (
            "[camera]\nshutter = [0]\n".to_string(),
            "camera.shutter: expected an array of 2 numbers [open, close]",
        ),
        (
            moving_sphere("[1, 0]"),
            "objects[0].transform[0].motion: expected an array of 3 numbers",
        ),
        (
            moving_sphere("[1e300, 0, 0]"),
            "objects[0].transform[0].motion",
        ),
    ] {
        let message = scene_file_error(&dir, &text);
        assert!(
            message.contains(expected),
            "expected {expected:?} in:\n{message}\nfor:\n{text}"
        );
    }
}

/// A sphere with a `motion` step of `motion`.
fn moving_sphere(motion: &str) -> String {
    format!(
        "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -2]\nradius = 1\nmaterial = \"m\"\n\
         transform = [{{ motion = {motion} }}]\n"
    )
}
