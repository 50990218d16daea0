//! Feature buffers (AOVs) are what their definitions say on scenes whose
//! answers are known, change nothing in the image, are the same whatever
//! the thread count, and are written as EXR layers or PFM files beside the
//! image.

mod common;
mod lumen_process;

use common::{compile_file, render_with_threads, scratch_dir};
use lumen::aov::{Aov, Layer};
use lumen::math::{Color, Vec3};
use lumen_process::*;

/// An orthographic view straight down −z from z = 5 onto a 4 × 4 square,
/// 16 × 16 pixels at `spp`, every feature buffer kept, a black sky, and
/// `objects` (TOML of materials and objects).
fn looking_down(spp: u32, objects: &str) -> String {
    format!(
        r#"
[render]
width = 16
height = 16
samples_per_pixel = {spp}
max_depth = 50
aovs = ["albedo", "normal", "depth", "position", "variance", "spp"]

[camera]
lookfrom = [0, 0, 5]
lookat = [0, 0, 0]
vup = [0, 1, 0]
ortho_height = 4

[background]
type = "solid"
color = [0, 0, 0]
{objects}
"#
    )
}

/// A quad at height `z` covering the view, of material `material`, facing
/// up (+z) or down.
fn square(z: f32, material: &str, up: bool) -> String {
    let v = if up { "[0, 20, 0]" } else { "[0, -20, 0]" };
    let y = if up { -10 } else { 10 };
    format!(
        "[[objects]]\ntype = \"quad\"\ncorner = [-10, {y}, {z}]\nu = [20, 0, 0]\nv = {v}\nmaterial = \"{material}\"\n"
    )
}

#[test]
fn a_diffuse_plane_gives_its_albedo_normal_depth_and_position() {
    let dir = scratch_dir("aov-plane");
    let text = looking_down(
        4,
        &format!(
            "[materials.paint]\ntype = \"diffuse\"\nalbedo = [0.25, 0.5, 0.75]\n{}",
            square(0.0, "paint", true)
        ),
    );
    let scene = compile_file(&dir, "plane.toml", &text);
    let (film, _) = render_with_threads(&scene, 2);
    for i in 0..film.len() {
        assert_eq!(film.feature(Layer::Albedo, i), Vec3::new(0.25, 0.5, 0.75));
        assert_eq!(
            film.feature(Layer::Normal, i),
            Vec3::Z,
            "towards the camera"
        );
        let p = film.feature(Layer::Position, i);
        assert!(
            p.x.abs() <= 2.0 && p.y.abs() <= 2.0 && p.z.abs() < 1e-5,
            "{p}"
        );
        let depth = film.feature(Layer::Depth, i).x;
        assert!((depth - 5.0).abs() < 1e-5, "{depth}");
        assert_eq!(film.count(i), 4);
        // Black everywhere: no variance.
        assert_eq!(film.variance(i), Color::ZERO);
    }
    // The pixels' positions are where they look: the top left pixel's
    // centre at (−2 + 1/8, 2 − 1/8), give or take half a pixel.
    let p = film.feature(Layer::Position, 0);
    assert!(
        (p.x + 1.875).abs() <= 0.125 && (p.y - 1.875).abs() <= 0.125,
        "{p}"
    );
}

#[test]
fn a_mirror_passes_on_the_albedo_it_shows_times_its_tint() {
    let dir = scratch_dir("aov-mirror");
    // The mirror at z = 0 sends every camera ray back up to a wall at
    // z = 10, behind the camera, facing down.
    let text = looking_down(
        4,
        &format!(
            "[materials.mirror]\ntype = \"metal\"\nalbedo = [0.8, 0.8, 0.8]\nfuzz = 0\n\
             [materials.wall]\ntype = \"diffuse\"\nalbedo = [0.5, 0.25, 0.125]\n{}{}",
            square(0.0, "mirror", true),
            square(10.0, "wall", false)
        ),
    );
    let scene = compile_file(&dir, "mirror.toml", &text);
    let (film, _) = render_with_threads(&scene, 2);
    let expected = Color::splat(0.8) * Color::new(0.5, 0.25, 0.125);
    for i in 0..film.len() {
        assert_eq!(film.feature(Layer::Albedo, i), expected);
        assert_eq!(
            film.feature(Layer::Normal, i),
            -Vec3::Z,
            "the wall's, facing the path"
        );
        // Depth and position are the mirror's: the first surface seen.
        assert!((film.feature(Layer::Depth, i).x - 5.0).abs() < 1e-5);
        assert!(film.feature(Layer::Position, i).z.abs() < 1e-5);
    }
}

/// The albedo and normal features of a floor of `material` (TOML fields)
/// under a wall facing it (albedo [`WALL`]), seen straight down: their
/// means over the image.
fn floor_under_a_wall(name: &str, material: &str) -> (Color, Vec3) {
    let dir = scratch_dir(name);
    let text = looking_down(
        16,
        &format!(
            "[materials.floor]\n{material}\n\
             [materials.wall]\ntype = \"diffuse\"\nalbedo = [{}, {}, {}]\n{}{}",
            WALL.x,
            WALL.y,
            WALL.z,
            square(0.0, "floor", true),
            square(10.0, "wall", false)
        ),
    );
    let scene = compile_file(&dir, "floor.toml", &text);
    let (film, _) = render_with_threads(&scene, 2);
    let n = film.len() as f32;
    let albedo = (0..film.len())
        .map(|i| film.feature(Layer::Albedo, i))
        .sum::<Vec3>()
        / n;
    let normal = (0..film.len())
        .map(|i| film.feature(Layer::Normal, i))
        .sum::<Vec3>()
        / n;
    (albedo, normal)
}

const WALL: Color = Color::new(0.5, 0.25, 0.125);

#[test]
fn a_near_mirror_is_looked_through_and_a_rougher_surface_is_not() {
    // Roughness 0.2 is α = 0.04, a near mirror (α ≤ 0.075): the wall it
    // reflects is what the features show, tinted by the metal; at 0.5
    // (α = 0.25) the metal itself is.
    for (metal, colour) in [
        ("type = \"conductor\"\nmetal = \"Au\"", None),
        (
            "type = \"principled\"\nbase_color = [0.9, 0.6, 0.3]\nmetallic = 1",
            Some(Color::new(0.9, 0.6, 0.3)),
        ),
    ] {
        let (rough_albedo, rough_normal) =
            floor_under_a_wall("aov-rough-metal", &format!("{metal}\nroughness = 0.5"));
        assert!(
            rough_normal.abs_diff_eq(Vec3::Z, 1e-5),
            "{metal}: {rough_normal}"
        );
        if let Some(c) = colour {
            assert!(rough_albedo.abs_diff_eq(c, 1e-5), "{metal}: {rough_albedo}");
        }
        let (albedo, normal) =
            floor_under_a_wall("aov-near-mirror", &format!("{metal}\nroughness = 0.2"));
        assert!(normal.z < -0.99, "{metal}: the wall's normal, not {normal}");
        // The tint of a near mirror is its reflectance, the rough one's
        // albedo, give or take what its microfacets shadow.
        let expected = rough_albedo * WALL;
        for c in 0..3 {
            assert!(
                (albedo[c] / expected[c] - 1.0).abs() < 0.03,
                "{metal}: albedo {albedo}, expected about {expected}"
            );
        }
    }
    // A glTF dielectric of a coloured base reflects a little by a
    // near-mirror layer, and mostly diffuses: the surface itself is seen.
    let (albedo, normal) = floor_under_a_wall(
        "aov-red-gltf",
        "type = \"principled\"\nbase_color = [0.8, 0.1, 0.1]\nroughness = 0.2",
    );
    assert!(
        albedo.abs_diff_eq(Color::new(0.8, 0.1, 0.1), 1e-5),
        "{albedo}"
    );
    assert!(normal.abs_diff_eq(Vec3::Z, 1e-5), "{normal}");
}

#[test]
fn glass_over_a_floor_shows_the_floor_as_often_as_light_gets_through() {
    let dir = scratch_dir("aov-glass");
    // A slab of glass (η = 1.5) between z = 0.5 and z = 1 over a floor,
    // seen straight down under a black sky: a path reaches the floor with
    // probability T = (1 − R)/(1 + R), R = ((η − 1)/(η + 1))² (every
    // bounce between the faces counted), and then takes the floor's albedo;
    // otherwise it escapes, and takes the sky's, 0.
    let spp = 64;
    let text = looking_down(
        spp,
        &format!(
            "[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n\
             [materials.floor]\ntype = \"diffuse\"\nalbedo = [0.2, 0.4, 0.6]\n{}{}{}",
            square(1.0, "glass", true),
            square(0.5, "glass", false),
            square(0.0, "floor", true)
        ),
    );
    let scene = compile_file(&dir, "glass.toml", &text);
    let (film, _) = render_with_threads(&scene, 2);
    let r = (0.5f64 / 2.5).powi(2);
    let t = (1.0 - r) / (1.0 + r);
    let n = (film.len() as u32 * spp) as f64;
    let mut through = 0.0;
    for i in 0..film.len() {
        let a = film.feature(Layer::Albedo, i);
        // Each sample is the floor's albedo or 0, so every pixel is the
        // floor's times the share that got through.
        let share = f64::from(a.x) / 0.2;
        assert!((0.0..=1.0 + 1e-6).contains(&share), "{a}");
        assert!((f64::from(a.z) / 0.6 - share).abs() < 1e-5, "{a}");
        through += share;
        assert_eq!(film.feature(Layer::Normal, i).z.signum(), 1.0);
    }
    let mean = through / film.len() as f64;
    // A binomial share of n samples.
    let sigma = (t * (1.0 - t) / n).sqrt();
    assert!(
        (mean - t).abs() < 5.0 * sigma,
        "{mean} of the samples reached the floor, expected {t} ± {sigma}"
    );
}

#[test]
fn features_change_nothing_in_the_image_and_are_the_same_on_any_thread_count() {
    let mut desc = common::builtin_desc("cornell-box", 24, 9, 3);
    let plain = lumen::scene::Scene::from_desc(&desc).unwrap();
    desc.render.aovs = Aov::ALL.to_vec();
    let with = lumen::scene::Scene::from_desc(&desc).unwrap();
    let (a, _) = render_with_threads(&plain, 2);
    let (b, _) = render_with_threads(&with, 1);
    let (c, _) = render_with_threads(&with, 2);
    assert!(a.raw() == b.raw(), "features changed the image");
    assert!(b == c, "features differ between thread counts");
    for i in 0..b.len() {
        let n = b.feature(Layer::Normal, i);
        let a = b.feature(Layer::Albedo, i);
        // Averages of unit normals, of albedos in [0, 1].
        assert!(n.length() <= 1.0 + 1e-5, "{n}");
        assert!(a.min_element() >= 0.0 && a.max_element() <= 1.0, "{a}");
    }
}

#[test]
fn the_command_line_writes_exr_layers_and_pfm_files_beside_other_images() {
    let dir = temp_dir("aov-cli");
    let args = ["render", "cornell-box", "--width", "20", "--spp", "4"];
    let (status, err) = run(&args, &dir.join("out.exr"), &["--aov", "albedo,spp"]);
    assert!(status.success(), "{err}");
    let exr = std::fs::read(dir.join("out.exr")).unwrap();
    for name in ["albedo.R", "albedo.G", "albedo.B", "spp.Y"] {
        let found = exr
            .windows(name.len() + 1)
            .any(|w| w == [name.as_bytes(), &[0]].concat());
        assert!(found, "no channel {name}");
    }
    assert!(!exr.windows(8).any(|w| w == b"normal.X"));
    // Another format: the image as it was, and one PFM file an AOV.
    let (status, err) = run(&args, &dir.join("out.png"), &["--aov", "depth,normal"]);
    assert!(status.success(), "{err}");
    let (status, err) = run(&args, &dir.join("plain.png"), &[]);
    assert!(status.success(), "{err}");
    assert_eq!(
        std::fs::read(dir.join("out.png")).unwrap(),
        std::fs::read(dir.join("plain.png")).unwrap()
    );
    let depth = std::fs::read(dir.join("out.depth.pfm")).unwrap();
    let grey = b"Pf\n20 20\n-1.0\n";
    assert!(depth.starts_with(grey) && depth.len() == grey.len() + 20 * 20 * 4);
    let normal = std::fs::read(dir.join("out.normal.pfm")).unwrap();
    assert_valid_pfm(&normal, 20, 20);
    assert!(!dir.join("out.albedo.pfm").exists());
    // An unknown name is refused with the list, before rendering.
    let (status, err) = run(&args, &dir.join("bad.exr"), &["--aov", "albedo,normals"]);
    assert_eq!(status.code(), Some(2), "{err}");
    assert!(
        err.contains("unknown AOV `normals`; the AOVs are albedo, normal, depth"),
        "{err}"
    );
    assert!(!dir.join("bad.exr").exists());
}

#[test]
fn a_scene_file_names_its_aovs_and_unknown_ones_are_refused_where_they_stand() {
    let dir = scratch_dir("aov-file");
    let good = "[render]\naovs = [\"normal\", \"albedo\", \"normal\"]\n";
    let file = common::scene_file(&dir, "good.toml", good);
    assert_eq!(file.desc.render.aovs, [Aov::Albedo, Aov::Normal]);
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "[render]\nwidth = 10\naovs = [\"albedo\", \"glow\"]\n",
    )
    .unwrap();
    let err = lumen::scene::file::SceneFile::read(&bad)
        .unwrap_err()
        .to_string();
    assert!(err.contains("bad.toml:3:"), "{err}");
    assert!(err.contains("render.aovs[1]"), "{err}");
    assert!(err.contains("\"albedo\", \"normal\""), "{err}");
}
