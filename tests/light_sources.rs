//! Point, spot and directional lights: what each sheds on a matte floor
//! against the formula, a disc of the sky found alike by light sampling
//! and by the bounces, and scenes mixing them with surface lights and the
//! sky, whose images are the sums of each light's alone (the weights of
//! multiple importance sampling add up to one).

mod common;

use common::{assert_agree, compile_file, pixel_stats, scene_file_error, scratch_dir};
use lumen::scene::Scene;
use std::f64::consts::PI;

const ALBEDO: [f64; 3] = [0.5, 0.6, 0.7];
const SIZE: u32 = 24;

/// A matte floor (y = 0, albedo [`ALBEDO`]) seen from 4 units above, the
/// lights `lights` (`[[lights]]` tables), `extra` further tables, black
/// sky; one ray through each pixel's centre at `spp` 1, so that the
/// direct light of a delta light is exact.
fn floor(name: &str, render: &str, lights: &str, extra: &str) -> Scene {
    floor_under(name, render, lights, extra, [0.0; 3])
}

/// [`floor`] under a sky of colour `sky`.
fn floor_under(name: &str, render: &str, lights: &str, extra: &str, sky: [f64; 3]) -> Scene {
    let [r, g, b] = ALBEDO;
    let [sr, sg, sb] = sky;
    let text = format!(
        r#"[render]
width = {SIZE}
height = {SIZE}
{render}

[camera]
vfov = 100
lookfrom = [0, 4, 0]
lookat = [0, 0, 0]
vup = [0, 0, -1]

[background]
type = "solid"
color = [{sr}, {sg}, {sb}]

[materials.floor]
type = "diffuse"
albedo = [{r}, {g}, {b}]

[[objects]]
type = "quad"
corner = [-8, 0, 8]
u = [16, 0, 0]
v = [0, 0, -16]
material = "floor"

{extra}

{lights}
"#
    );
    compile_file(
        &scratch_dir(&format!("light_sources-{name}")),
        "scene.toml",
        &text,
    )
}

/// The floor point seen through the centre of pixel (x, y).
fn floor_point(scene: &Scene, x: u32, y: u32) -> [f64; 3] {
    let ray = scene.camera.central_ray(x, y);
    let (o, d) = (ray.origin(), ray.direction);
    let t = -f64::from(o.y) / f64::from(d.y);
    [
        f64::from(o.x) + t * f64::from(d.x),
        0.0,
        f64::from(o.z) + t * f64::from(d.z),
    ]
}

/// Checks every pixel of a one-sample render through pixel centres against
/// `expected(point)`: the irradiance (per channel, before the albedo) at
/// the floor point, or `None` for a pixel not to be checked (on an edge of
/// a spot's cone, where rounding decides).
fn assert_floor(what: &str, scene: &Scene, expected: impl Fn([f64; 3]) -> Option<[f64; 3]>) {
    let stats = pixel_stats(scene);
    let mut checked = 0;
    let mut lit = 0;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let Some(e) = expected(floor_point(scene, x, y)) else {
                continue;
            };
            checked += 1;
            lit += usize::from(e[0] > 0.0);
            let got = stats.pixel(x, y);
            for c in 0..3 {
                let want = ALBEDO[c] / PI * e[c];
                assert!(
                    (got[c] - want).abs() <= 1e-4 * want + 1e-7,
                    "{what}: pixel ({x}, {y}) channel {c}: {} instead of {want}",
                    got[c]
                );
            }
        }
    }
    assert!(
        checked > 400 && lit > 50,
        "{what}: {checked} pixels checked, {lit} lit"
    );
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn length(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

const CENTRE: &str = "sampler = \"center\"\nsamples_per_pixel = 1\nmax_depth = 2";

#[test]
fn a_point_light_lights_a_floor_by_the_inverse_square_and_the_cosine() {
    let position = [1.0, 1.5, -0.5];
    let intensity = [3.0, 2.0, 1.0];
    let scene = floor(
        "point",
        CENTRE,
        "[[lights]]\ntype = \"point\"\nposition = [1, 1.5, -0.5]\nintensity = [3, 2, 1]",
        "",
    );
    assert_floor("point light", &scene, |p| {
        let to = sub(position, p);
        let d = length(to);
        let cos = to[1] / d;
        Some(intensity.map(|i| i * cos / (d * d)))
    });
}

#[test]
fn a_spot_light_is_full_in_its_beam_and_falls_off_linearly_in_angle_to_its_cutoff() {
    spot_falloff("", |angle, cutoff, beam| (cutoff - angle) / (cutoff - beam));
}

#[test]
fn a_smoothstep_spot_light_falls_off_as_pbrts() {
    spot_falloff("\nfalloff = \"smoothstep\"", |angle, cutoff, beam| {
        let t = (angle.cos() - cutoff.cos()) / (beam.cos() - cutoff.cos());
        t * t * (3.0 - 2.0 * t)
    });
}

/// A spot light (with `extra` fields) on a floor, checked pixel by pixel
/// against `falloff(angle, cutoff, beam)` between its beam and cut-off.
fn spot_falloff(extra: &str, falloff: impl Fn(f64, f64, f64) -> f64) {
    let position = [0.5, 2.0, 0.0];
    // Aimed at a point of the floor off to the side, so that the cone's
    // section is an ellipse across the image.
    let target = [-0.5, 0.0, 0.5];
    let (cutoff, beam) = (40f64.to_radians(), 25f64.to_radians());
    // Each variant in a folder of its own: the tests run at once.
    let scene = floor(
        &format!("spot{}", extra.len()),
        CENTRE,
        &format!(
            "[[lights]]\ntype = \"spot\"\nposition = [0.5, 2, 0]\ntarget = [-0.5, 0, 0.5]\n\
             intensity = [4, 4, 2]\ncutoff_angle = 40\nbeam_width = 25{extra}"
        ),
        "",
    );
    let axis = sub(target, position);
    let between = std::cell::Cell::new(0);
    assert_floor("spot light", &scene, |p| {
        let to = sub(p, position);
        let d = length(to);
        let angle = ((to[0] * axis[0] + to[1] * axis[1] + to[2] * axis[2]) / (d * length(axis)))
            .clamp(-1.0, 1.0)
            .acos();
        if (angle - cutoff).abs() < 1e-3 || (angle - beam).abs() < 1e-3 {
            return None;
        }
        let falloff = if angle <= beam {
            1.0
        } else if angle < cutoff {
            between.set(between.get() + 1);
            falloff(angle, cutoff, beam)
        } else {
            0.0
        };
        let cos = -to[1] / d;
        Some([4.0, 4.0, 2.0].map(|i| i * falloff * cos / (d * d)))
    });
    assert!(
        between.get() > 20,
        "only {} pixels in the falloff",
        between.get()
    );
}

#[test]
fn a_directional_light_lights_a_floor_by_its_irradiance_times_the_cosine() {
    let scene = floor(
        "directional",
        CENTRE,
        "[[lights]]\ntype = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [2, 1, 3]",
        "",
    );
    let cos = 2.0 / length([1.0, -2.0, 0.5]);
    assert_floor("directional light", &scene, |_| {
        Some([2.0, 1.0, 3.0].map(|e| e * cos))
    });
}

#[test]
fn light_below_the_floor_or_behind_a_wall_sheds_nothing() {
    // A point light under the floor and a sun shining up from below.
    let scene = floor(
        "below",
        CENTRE,
        "[[lights]]\ntype = \"point\"\nposition = [0, -1, 0]\nintensity = [5, 5, 5]\n\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nirradiance = [1, 1, 1]",
        "",
    );
    let stats = pixel_stats(&scene);
    assert!(stats.max.iter().all(|m| *m == 0.0), "{:?}", stats.max);
}

/// The floor under a sun of angular radius 10° straight overhead, whose
/// irradiance on the floor is exactly the light's (a uniform disc of
/// radiance L gives L π sin²α on a surface facing it).
const SUN: &str = "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\n\
                   irradiance = [2, 3, 4]\nangular_radius = 10";

#[test]
fn a_disc_sun_gives_its_irradiance_found_by_light_sampling_or_by_the_bounces_alone() {
    for integrator in ["path", "bsdf"] {
        let scene = floor(
            &format!("sun-{integrator}"),
            &format!(
                "samples_per_pixel = 64\nsampler = \"independent\"\nmax_depth = 2\n\
                 integrator = \"{integrator}\""
            ),
            SUN,
            "",
        );
        let stats = pixel_stats(&scene);
        for (c, e) in [2.0, 3.0, 4.0].into_iter().enumerate() {
            assert_agree(
                &format!("{integrator}: image mean, channel {c}"),
                stats.image(c),
                (ALBEDO[c] / PI * e, 0.0),
            );
        }
    }
}

/// The lights that are no surface of the mixed scene, each as its own
/// `[[lights]]` table.
const MIXED: [&str; 4] = [
    "[[lights]]\ntype = \"point\"\nposition = [1, 1, 0]\nintensity = [2, 2, 2]",
    "[[lights]]\ntype = \"spot\"\nposition = [-1, 1.5, 0.5]\ndirection = [0, -1, 0]\n\
     intensity = [3, 1, 1]\ncutoff_angle = 50",
    "[[lights]]\ntype = \"directional\"\ndirection = [-1, -3, 1]\nirradiance = [0.5, 1, 0.5]\n\
     angular_radius = 5",
    "[[lights]]\ntype = \"projector\"\nposition = [1, 2, 1]\ntarget = [0.5, 0, 0.5]\nfov = 50\n\
     irradiance = [1, 2, 3]\naspect = 1.5",
];

#[test]
fn a_scene_of_every_kind_of_light_is_the_sum_of_each_light_alone() {
    let render = "samples_per_pixel = 48\nsampler = \"independent\"\nmax_depth = 4\n\
                  sample_background = true\nlight_selection = \"uniform\"";
    // A ball casting shadows and throwing light back onto the floor, and a
    // lamp (a quad shining down) that is there in every render, shining or
    // black, so that it hides the same sky. The sky is sampled as a light
    // too; every light is chosen equally often (by power, the sky, which
    // lights everything, would leave the spot a chance so small that its
    // few samples would make the estimate's spread unreliable).
    let scene = |name: &str, lights: &[&str], lamp: bool, sky: bool| {
        let radiance = if lamp { "[1, 2, 3]" } else { "[0, 0, 0]" };
        let extra = format!(
            "[materials.ball]\ntype = \"plastic\"\nalbedo = [0.6, 0.5, 0.4]\nroughness = 0.3\n\n\
             [materials.lamp]\ntype = \"emissive\"\nradiance = {radiance}\n\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0.5, 0]\nradius = 0.5\nmaterial = \"ball\"\n\n\
             [[objects]]\ntype = \"quad\"\ncorner = [-0.5, 1.2, -1]\nu = [0, 0, 1]\nv = [1, 0, 0]\n\
             material = \"lamp\""
        );
        let sky = if sky { [0.2, 0.2, 0.3] } else { [0.0; 3] };
        pixel_stats(&floor_under(
            name,
            render,
            &lights.join("\n\n"),
            &extra,
            sky,
        ))
    };
    let all = scene("mixed-all", &MIXED, true, true);
    let mut alone: Vec<_> = MIXED
        .iter()
        .enumerate()
        .map(|(i, l)| scene(&format!("mixed-{i}"), &[l], false, false))
        .collect();
    alone.push(scene("mixed-lamp", &[], true, false));
    alone.push(scene("mixed-sky", &[], false, true));
    let half = SIZE / 2;
    for c in 0..3 {
        let sum = |part: &dyn Fn(&common::PixelStats) -> (f64, f64)| {
            alone.iter().map(part).fold((0.0, 0.0), |a, b| {
                (a.0 + b.0, (a.1 * a.1 + b.1 * b.1).sqrt())
            })
        };
        let image = |s: &common::PixelStats| s.image(c);
        assert_agree(&format!("channel {c}"), image(&all), sum(&image));
        // And in the quarter of the image under the spot and the lamp.
        let quarter = |s: &common::PixelStats| s.region(0..half, 0..half, c);
        assert_agree(
            &format!("a quarter, channel {c}"),
            quarter(&all),
            sum(&quarter),
        );
    }
}

#[test]
fn mistakes_in_lights_are_refused_with_the_field_and_a_hint() {
    let dir = scratch_dir("light_sources_errors");
    let cases: &[(&str, &[&str])] = &[
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensty = [1, 1, 1]",
            &["lights[0].intensty", "did you mean `intensity`?"],
        ),
        (
            "[[lights]]\ntype = \"pointlight\"\nposition = [0, 1, 0]",
            &["lights[0].type", "\"point\""],
        ),
        (
            "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             target = [0, 0, 0]\nintensity = [1, 1, 1]",
            &["lights[0].target", "not both"],
        ),
        (
            "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\nintensity = [1, 1, 1]",
            &["lights[0].direction", "`direction` or `target`"],
        ),
        (
            "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             intensity = [1, 1, 1]\ncutoff_angle = 20\nbeam_width = 30",
            &["lights[0].beam_width", "at most cutoff_angle"],
        ),
        (
            "[[lights]]\ntype = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]",
            &["lights[0].direction", "not all zero"],
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, -1, 1]",
            &["lights[0].intensity", "none negative"],
        ),
        (
            "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\n\
             angular_radius = 90",
            &["lights[0].angular_radius", "below 90"],
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, nan, 0]\nintensity = [1, 1, 1]",
            &["lights[0].position"],
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nirradiance = [1, 1, 1]",
            &["lights[0].irradiance", "directional and projector lights"],
        ),
        (
            "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             intensity = [1, 1, 1]\nup = [0, 0, 1]",
            &["lights[0].up", "projected `texture`"],
        ),
        (
            "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             intensity = [1, 1, 1]\ntexture = \"nothing\"",
            &["lights[0].texture", "nothing"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 180",
            &["lights[0].fov", "below 180 degrees"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 40\naspect = 0",
            &["lights[0].aspect", "positive"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 40\naspect = 1e-9",
            &["lights[0].aspect", "from 1e-6"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 1e-12",
            &["lights[0].fov", "too small or too large"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ntarget = [0, 1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 40",
            &["lights[0].target", "own position"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]",
            &["lights[0]", "fov"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             fov = 40",
            &["lights[0].irradiance", "`irradiance` or `intensity`"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             fov = 40\nirradiance = [1, 1, 1]\nintensity = [1, 1, 1]",
            &["lights[0].intensity", "not both"],
        ),
        (
            "[[lights]]\ntype = \"projector\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
             irradiance = [1, 1, 1]\nfov = 40\nup = [0, 2, 0]",
            &["lights[0].up", "along the light's axis"],
        ),
    ];
    for (text, wanted) in cases {
        let message = scene_file_error(&dir, text);
        for w in *wanted {
            assert!(message.contains(w), "{w:?} not in:\n{message}");
        }
    }
}

#[test]
fn lights_survive_export_and_json() {
    let dir = scratch_dir("light_sources_export");
    let text = MIXED.join("\n\n");
    let file = common::scene_file(&dir, "lights.toml", &text);
    let desc = file.desc;
    assert_eq!(desc.lights.len(), 4);
    for format in [
        lumen::scene::file::Format::Toml,
        lumen::scene::file::Format::Json,
    ] {
        let mut written = Vec::new();
        lumen::scene::file::export::write_scene(&desc, format, &mut written).unwrap();
        let written = String::from_utf8(written).unwrap();
        let again = lumen::scene::file::SceneFile::parse("again", written, format)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(again.desc, desc, "{format:?}");
    }
}

#[test]
fn a_spot_projects_its_texture_upright_through_its_cone() {
    // A 2 × 2 image, red on the left, blue on the right, nearest texels.
    let dir = scratch_dir("light_sources-projected");
    let mut img = image::RgbImage::new(2, 2);
    for y in 0..2 {
        img.put_pixel(0, y, image::Rgb([255, 0, 0]));
        img.put_pixel(1, y, image::Rgb([0, 0, 255]));
    }
    img.save(dir.join("slide.png")).unwrap();
    // Up the image -z puts its left at -x; turned about, at +x.
    for (up, red_side) in [(-1.0, -1.0), (1.0, 1.0)] {
        let text = format!(
            "[render]\nwidth = {SIZE}\nheight = {SIZE}\nsampler = \"center\"\n\
             samples_per_pixel = 1\nmax_depth = 2\n\n\
             [camera]\nvfov = 100\nlookfrom = [0, 4, 0]\nlookat = [0, 0, 0]\nvup = [0, 0, -1]\n\n\
             [background]\ntype = \"solid\"\ncolor = [0, 0, 0]\n\n\
             [textures.slide]\ntype = \"image\"\nfile = \"slide.png\"\nfilter = \"nearest\"\n\n\
             [materials.floor]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\n\
             [[objects]]\ntype = \"quad\"\ncorner = [-8, 0, 8]\nu = [16, 0, 0]\nv = [0, 0, -16]\n\
             material = \"floor\"\n\n\
             [[lights]]\ntype = \"spot\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
             intensity = [4, 4, 4]\ncutoff_angle = 40\nbeam_width = 40\ntexture = \"slide\"\n\
             up = [0, 0, {up}]\n"
        );
        let scene = compile_file(&dir, "s.toml", &text);
        let stats = pixel_stats(&scene);
        let (mut red, mut blue) = (0, 0);
        for y in 0..SIZE {
            for x in 0..SIZE {
                let p = floor_point(&scene, x, y);
                let c = stats.pixel(x, y);
                let reach = 2.0 * 40f64.to_radians().tan() - 0.1;
                if (p[0] * p[0] + p[2] * p[2]).sqrt() > reach || p[0].abs() < 0.1 {
                    continue;
                }
                if p[0] * red_side > 0.0 {
                    assert!(
                        c[0] > 0.0 && c[1] == 0.0 && c[2] == 0.0,
                        "({x}, {y}) at {p:?}: {c:?}"
                    );
                    red += 1;
                } else {
                    assert!(
                        c[2] > 0.0 && c[0] == 0.0 && c[1] == 0.0,
                        "({x}, {y}) at {p:?}: {c:?}"
                    );
                    blue += 1;
                }
            }
        }
        assert!(red > 20 && blue > 20, "{red} red and {blue} blue pixels");
    }
}

/// A projector lights a plane across its axis evenly, with its
/// irradiance at unit distance over the distance squared, within the
/// rectangle its field of view and aspect make, and nothing outside.
#[test]
fn a_projector_lights_a_plane_across_its_axis_evenly_within_its_rectangle() {
    let scene = floor(
        "projector",
        CENTRE,
        "[[lights]]\ntype = \"projector\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         up = [0, 0, -1]\nfov = 100\naspect = 2\nirradiance = [3, 2, 1]",
        "",
    );
    // Its right is axis × up = +x: 2 tan 50° either side of the axis at
    // distance 2, and half that either way along z.
    let (half_x, half_z) = (2.0 * 50f64.to_radians().tan(), 50f64.to_radians().tan());
    assert_floor("projector", &scene, |p| {
        let (dx, dz) = (half_x - p[0].abs(), half_z - p[2].abs());
        if dx.abs() < 0.05 || dz.abs() < 0.05 {
            return None;
        }
        let inside = dx > 0.0 && dz > 0.0;
        Some([3.0, 2.0, 1.0].map(|e: f64| if inside { e / 4.0 } else { 0.0 }))
    });
}

/// A projector's image lies upright: its top towards `up`, its left to
/// the left seen from the light; its shape (2 × 1 here) sets the height
/// of the lit rectangle.
#[test]
fn a_projector_casts_its_image_upright_and_of_its_shape() {
    let dir = scratch_dir("light_sources-projector-image");
    // Top left red, top right green, bottom left blue, bottom right white:
    // four texels, each two of the image's pixels wide.
    let mut img = image::RgbImage::new(4, 2);
    for (x, y, c) in [
        (0, 0, [255, 0, 0]),
        (1, 0, [255, 0, 0]),
        (2, 0, [0, 255, 0]),
        (3, 0, [0, 255, 0]),
        (0, 1, [0, 0, 255]),
        (1, 1, [0, 0, 255]),
        (2, 1, [255, 255, 255]),
        (3, 1, [255, 255, 255]),
    ] {
        img.put_pixel(x, y, image::Rgb(c));
    }
    img.save(dir.join("slide.png")).unwrap();
    const N: u32 = 64;
    let text = format!(
        "[render]\nwidth = {N}\nheight = {N}\nsampler = \"center\"\n\
         samples_per_pixel = 1\nmax_depth = 2\n\n\
         [camera]\nvfov = 100\nlookfrom = [0, 4, 0]\nlookat = [0, 0, 0]\nvup = [0, 0, -1]\n\n\
         [background]\ntype = \"solid\"\ncolor = [0, 0, 0]\n\n\
         [textures.slide]\ntype = \"image\"\nfile = \"slide.png\"\nfilter = \"nearest\"\n\
         encoding = \"linear\"\n\n\
         [materials.floor]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [-8, 0, 8]\nu = [16, 0, 0]\nv = [0, 0, -16]\n\
         material = \"floor\"\n\n\
         [[lights]]\ntype = \"projector\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         up = [0, 0, -1]\nfov = 90\nirradiance = [4, 4, 4]\ntexture = \"slide\"\n"
    );
    let scene = compile_file(&dir, "s.toml", &text);
    let stats = pixel_stats(&scene);
    // Seen from above with -z up the image, the light's left is -x. The
    // image is 4 wide and 2 high across at distance 2 (fov 90°), so it
    // reaches x = ±2 and z = ±1; each texel lights 1 π⁻¹ of radiance.
    let mut counts = [0; 5];
    for y in 0..N {
        for x in 0..N {
            let p = floor_point(&scene, x, y);
            let c = stats.pixel(x, y);
            let (ax, az) = (p[0].abs(), p[2].abs());
            if ax < 0.1 || az < 0.1 || (ax - 2.0).abs() < 0.1 || (az - 1.0).abs() < 0.1 {
                continue;
            }
            let (want, slot) = if ax > 2.0 || az > 1.0 {
                ([0.0; 3], 4)
            } else {
                match (p[0] < 0.0, p[2] < 0.0) {
                    (true, true) => ([1.0, 0.0, 0.0], 0),
                    (false, true) => ([0.0, 1.0, 0.0], 1),
                    (true, false) => ([0.0, 0.0, 1.0], 2),
                    (false, false) => ([1.0, 1.0, 1.0], 3),
                }
            };
            counts[slot] += 1;
            for k in 0..3 {
                let w = want[k] / PI;
                assert!(
                    (c[k] - w).abs() <= 1e-4 * w + 1e-7,
                    "({x}, {y}) at {p:?}: {c:?}, expected {w} in channel {k}"
                );
            }
        }
    }
    assert!(counts.iter().all(|&n| n > 50), "{counts:?}");
}

/// A projector given its intensity (as pbrt's `projection` light) sheds
/// that intensity in every direction of its frustum: a floor across its
/// axis is lit by intensity · cos θ / d², dimmer towards the edges.
#[test]
fn a_projector_given_its_intensity_sheds_it_evenly_over_its_frustum() {
    let scene = floor(
        "projector-intensity",
        CENTRE,
        "[[lights]]\ntype = \"projector\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         up = [0, 0, -1]\nfov = 100\naspect = 2\nintensity = [3, 2, 1]",
        "",
    );
    let (half_x, half_z) = (2.0 * 50f64.to_radians().tan(), 50f64.to_radians().tan());
    assert_floor("projector by intensity", &scene, |p| {
        let (dx, dz) = (half_x - p[0].abs(), half_z - p[2].abs());
        if dx.abs() < 0.05 || dz.abs() < 0.05 {
            return None;
        }
        let d2 = p[0] * p[0] + 4.0 + p[2] * p[2];
        let cos = 2.0 / d2.sqrt();
        let inside = dx > 0.0 && dz > 0.0;
        Some([3.0, 2.0, 1.0].map(|i: f64| if inside { i * cos / d2 } else { 0.0 }))
    });
}

/// A projector of a field near 180° and the narrowest image lumen takes
/// still lights what it covers, with the irradiance asked: its power stays
/// finite (an image of unbounded shape once made it infinite, which
/// emptied the scene of lights).
#[test]
fn a_projector_of_extreme_shape_still_lights_the_floor() {
    let scene = floor(
        "projector-extreme",
        CENTRE,
        "[[lights]]\ntype = \"projector\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\n\
         fov = 179.9999\naspect = 1e-6\nirradiance = [3, 2, 1]",
        "",
    );
    assert_floor("extreme projector", &scene, |_| {
        Some([3.0, 2.0, 1.0].map(|e: f64| e / 4.0))
    });
}
