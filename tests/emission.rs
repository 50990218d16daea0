//! Emissive surfaces: what a light gives off, on which side, and what the
//! surfaces it lights return, against exact answers; the Cornell box of *The
//! Next Week* sees its light at the light's radiance and converges to the
//! same image with every sampler.

mod common;

use common::{assert_agree, ball_in_light, builtin_desc, pixel_stats};
use lumen::math::Color;
use lumen::render::render;
use lumen::scene::file::{Format, SceneFile};
use lumen::scene::{Overrides, Sampling, Scene};

/// A scene from TOML text.
fn scene(text: &str) -> Scene {
    SceneFile::parse("emission.toml", text.to_string(), Format::Toml)
        .and_then(|f| f.compile(&Overrides::default()))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The distinct pixel values of a render, with how many pixels have each.
fn values(scene: &Scene) -> Vec<(Color, usize)> {
    let (film, _) = render(scene, &|_| {});
    let mut seen: Vec<(Color, usize)> = Vec::new();
    for p in film.pixels() {
        match seen.iter_mut().find(|(c, _)| *c == p) {
            Some((_, n)) => *n += 1,
            None => seen.push((p, 1)),
        }
    }
    seen
}

/// The camera inside a light enclosing a diffuse sphere (see
/// [`ball_in_light`]), albedo (0.5, 0.25, 0.75). Lights are met only by
/// chance (the `bsdf` integrator), so that every sample of a pixel has the
/// same value.
fn enclosure(two_sided: bool, max_depth: u32, sampler: &str, towards_sphere: bool) -> Scene {
    let render = format!(
        "width = 32\nheight = 24\nsamples_per_pixel = 4\nmax_depth = {max_depth}\n\
         sampler = \"{sampler}\"\nintegrator = \"bsdf\""
    );
    scene(&ball_in_light(
        &render,
        two_sided,
        [0.5, 0.25, 0.75],
        towards_sphere,
    ))
}

#[test]
fn a_light_all_around_lights_a_sphere_by_exactly_its_albedo() {
    let light = Color::new(2.0, 3.0, 4.0);
    let lit = Color::new(0.5, 0.25, 0.75) * light;
    let all = |c: Color| vec![(c, 32 * 24)];
    for sampler in ["independent", "sobol"] {
        // Every bounce off the convex sphere meets the light: each sample is
        // exactly albedo × radiance, whatever its direction.
        assert_eq!(values(&enclosure(true, 2, sampler, true)), all(lit));
        assert_eq!(values(&enclosure(true, 50, sampler, true)), all(lit));
        // With one segment, the sphere's bounce is never traced.
        assert_eq!(values(&enclosure(true, 1, sampler, true)), all(Color::ZERO));
        // Looking away, the camera sees the light itself.
        assert_eq!(values(&enclosure(true, 1, sampler, false)), all(light));
    }
}

#[test]
fn a_one_sided_light_is_dark_from_behind() {
    // The camera sees the inside of the enclosure, against its outward
    // normal: a one-sided light gives nothing there, and nothing else does.
    for towards_sphere in [true, false] {
        let seen = values(&enclosure(false, 5, "sobol", towards_sphere));
        assert_eq!(seen, vec![(Color::ZERO, 32 * 24)]);
    }
}

/// A camera looking down −z at an emissive quad in the z = −1 plane whose
/// u × v points along `normal_z`.
fn quad(normal_z: f64, two_sided: bool) -> Scene {
    let (u, v) = if normal_z > 0.0 {
        ("[4, 0, 0]", "[0, 4, 0]")
    } else {
        ("[0, 4, 0]", "[4, 0, 0]")
    };
    scene(&format!(
        r#"[render]
width = 16
height = 16
samples_per_pixel = 2

[camera]
vfov = 30
lookfrom = [0, 0, 0]
lookat = [0, 0, -1]

[background]
type = "solid"
color = [0, 0, 0]

[materials.panel]
type = "emissive"
radiance = [7, 7, 7]
two_sided = {two_sided}

[[objects]]
type = "quad"
corner = [-2, -2, -1]
u = {u}
v = {v}
material = "panel"
"#
    ))
}

#[test]
fn a_quad_light_shines_towards_its_normal_or_both_ways_when_two_sided() {
    let bright = vec![(Color::splat(7.0), 16 * 16)];
    // u × v towards the camera (+z): seen lit.
    assert_eq!(values(&quad(1.0, false)), bright);
    // Turned away: dark, unless two-sided.
    assert_eq!(values(&quad(-1.0, false)), vec![(Color::ZERO, 16 * 16)]);
    assert_eq!(values(&quad(-1.0, true)), bright);
}

#[test]
fn the_cornell_box_shows_its_light_at_its_radiance() {
    let mut desc = builtin_desc("cornell-box", 64, 1, 3);
    desc.render.sampler = Sampling::Center;
    let scene = Scene::from_desc(&desc).unwrap();
    let (film, _) = render(&scene, &|_| {});
    // The light is seen from below near the top of the image: some pixels
    // see it directly and carry exactly its radiance.
    let light = film.pixels().filter(|&p| p == Color::splat(15.0)).count();
    assert!(light > 10, "{light} pixels see the light");
    assert!(film
        .pixels()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
}

#[test]
fn the_cornell_box_converges_to_the_same_image_with_every_sampler() {
    // Tiles of 8 × 8 pixels compared between samplers: the light is found
    // by chance, so each render is noisy, but all estimate the same image.
    let stats = |sampler| {
        let mut desc = builtin_desc("cornell-box", 32, 64, 5);
        desc.render.sampler = sampler;
        pixel_stats(&Scene::from_desc(&desc).unwrap())
    };
    let independent = stats(Sampling::Independent);
    let sobol = stats(Sampling::Sobol);
    let stratified = stats(Sampling::Stratified);
    for c in 0..3 {
        for ty in 0..4 {
            for tx in 0..4 {
                let tile =
                    |s: &common::PixelStats| s.region(tx * 8..tx * 8 + 8, ty * 8..ty * 8 + 8, c);
                let what = format!("tile ({tx}, {ty}), channel {c}");
                assert_agree(&what, tile(&independent), tile(&sobol));
                assert_agree(&what, tile(&independent), tile(&stratified));
            }
        }
        // The box is lit: its mean is well above zero in every channel.
        let (mean, se) = independent.image(c);
        assert!(mean > 10.0 * se, "channel {c}: {mean} ± {se}");
    }
}
