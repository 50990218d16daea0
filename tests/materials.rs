//! The physically based materials as scene files describe them: the kinds
//! and their fields, textures of the right kind, normal and bump maps,
//! cut-outs, and every mistake refused with the field it is in.

mod common;

use common::{compile_file, scene_file_error, scratch_dir};
use lumen::material::Kind;
use lumen::math::{Interval, Vec3};
use lumen::ray::Ray;
use lumen::scene::Scene;
use std::path::Path;

/// Writes a `w` × `h` 8-bit RGBA PNG whose texel (x, y) is `f(x, y)`.
fn png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) {
    let image = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
    image.save(path).unwrap();
}

/// The issue's own example, every kind with the names the interface
/// promises, compiles to the kinds it names.
#[test]
fn the_new_kinds_compile_from_their_documented_fields() {
    let dir = scratch_dir("materials-kinds");
    png(&dir.join("paint.png"), 4, 4, |x, _| {
        [40 * x as u8, 60, 200, 255]
    });
    png(&dir.join("flakes.png"), 4, 4, |x, y| {
        [128 + x as u8, 128 + y as u8, 250, 255]
    });
    let scene = compile_file(
        &dir,
        "kinds.toml",
        r#"
[textures.paint-texture]
type = "image"
file = "paint.png"

[textures.flakes-normal]
type = "image"
file = "flakes.png"

[materials.gold]
type = "conductor"
metal = "Au"
roughness = 0.3

[materials.gold-by-index]
type = "conductor"
eta = [0.143, 0.374, 1.442]
k = [3.983, 2.385, 1.603]
alpha = 0.09

[materials.frosted]
type = "dielectric"
ior = 1.5
roughness = 0.2

[materials.red-plastic]
type = "plastic"
albedo = [0.6, 0.05, 0.05]
ior = 1.5
roughness = 0.1

[materials.car-paint]
type = "principled"
base_color = "paint-texture"
metallic = 0.0
roughness = 0.4
clearcoat = 1.0
clearcoat_roughness = 0.05
normal_map = "flakes-normal"
clearcoat_normal_map = "flakes-normal"
clearcoat_normal_scale = 0.5

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 1
material = "gold"
"#,
    );
    let kind = |name: &str| {
        // Materials are compiled in the order of their names.
        let names = [
            "car-paint",
            "frosted",
            "gold",
            "gold-by-index",
            "red-plastic",
        ];
        let i = names.iter().position(|n| *n == name).unwrap();
        scene.materials[i].clone()
    };
    match kind("gold").kind {
        Kind::Conductor(c) => {
            let (lumen::material::ColorParam::Const(eta), lumen::material::ColorParam::Const(k)) =
                (c.eta, c.k)
            else {
                panic!("gold's index is a constant")
            };
            assert!((eta.x - 0.143).abs() < 0.01 && (k.x - 3.98).abs() < 0.01);
            assert!(c.roughness.squared);
        }
        other => panic!("gold is {other:?}"),
    }
    assert!(matches!(kind("gold-by-index").kind, Kind::Conductor(c) if !c.roughness.squared));
    assert!(matches!(kind("frosted").kind, Kind::Dielectric(d) if d.roughness.is_some()));
    assert!(matches!(kind("red-plastic").kind, Kind::Plastic(p) if p.ior == 1.5));
    let paint = kind("car-paint");
    match &paint.kind {
        Kind::Principled(p) => assert_eq!(p.coat_normal.map(|(_, s)| s), Some(0.5)),
        other => panic!("car-paint is {other:?}"),
    }
    assert!(paint.shape.is_some(), "the normal map");
}

/// A roughness may differ along the tangent and the bitangent with either
/// or both given by a scalar texture, such as a checkerboard of numbers;
/// a checkerboard of colours is no roughness.
#[test]
fn anisotropic_roughness_takes_a_texture_on_either_axis() {
    use lumen::material::param::ScalarParam;
    let dir = scratch_dir("materials-anisotropic-textures");
    let scene = |alpha: &str, odd: &str| {
        format!(
            r#"
[textures.bumps]
type = "checkerboard"
even = [0.05, 0.05, 0.05]
odd = {odd}
uv_scale = [8, 8]

[materials.m]
type = "conductor"
metal = "Al"
alpha = {alpha}

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 1
material = "m"
"#
        )
    };
    let s = compile_file(
        &dir,
        "mixed.toml",
        &scene("[0.3, \"bumps\"]", "[0.3, 0.3, 0.3]"),
    );
    match &s.materials[0].kind {
        Kind::Conductor(c) => {
            assert_eq!(c.roughness.u, ScalarParam::Const(0.3));
            assert!(matches!(c.roughness.v, ScalarParam::Texture(_)));
        }
        other => panic!("{other:?}"),
    }
    let message = scene_file_error(&dir, &scene("[\"bumps\", 0.1]", "[0.9, 0.1, 0.1]"));
    assert!(
        message.contains("materials.m.alpha[0]") && message.contains("is a colour"),
        "{message}"
    );
    let message = scene_file_error(&dir, &scene("[0.1, 0.2, 0.3]", "[0.3, 0.3, 0.3]"));
    assert!(message.contains("materials.m.alpha"), "{message}");
}

/// Each mistake is refused before rendering, naming the field and what
/// was expected.
#[test]
fn bad_material_fields_are_refused_with_the_field_and_the_reason() {
    let dir = scratch_dir("materials-errors");
    png(&dir.join("colour.png"), 2, 2, |_, _| [200, 100, 50, 255]);
    png(&dir.join("inward.png"), 2, 2, |_, _| [128, 128, 10, 255]);
    let scene = |material: &str| {
        format!(
            r#"
[textures.colour]
type = "image"
file = "colour.png"

[textures.green]
type = "image"
file = "colour.png"
channel = "g"

[textures.inward]
type = "image"
file = "inward.png"

[materials.m]
{material}

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 1
material = "m"
"#
        )
    };
    let cases: &[(&str, &[&str])] = &[
        (
            "type = \"conductor\"\nmetal = \"Au\"\nroughness = 1.5",
            &["materials.m.roughness", "must be in [0, 1], got 1.5"],
        ),
        (
            "type = \"conductor\"\nmetal = \"Au\"\nalpha = -0.1",
            &["materials.m.alpha", "must not be negative"],
        ),
        (
            "type = \"dielectric\"\nior = 1.5\nroughness = 0.2\nalpha = 0.04",
            &["materials.m.alpha", "`roughness`", "not both"],
        ),
        (
            "type = \"conductor\"\nmetal = \"Au\"\neta = [1, 1, 1]\nk = [1, 1, 1]",
            &["materials.m.metal", "`metal` or `eta` and `k`, not both"],
        ),
        (
            "type = \"conductor\"\neta = [0.2, -1, 1]\nk = [3, 2, 1]",
            &["materials.m.eta", "finite and not negative"],
        ),
        (
            "type = \"conductor\"\neta = [0.2, nan, 1]\nk = [3, 2, 1]",
            &["materials.m.eta", "finite"],
        ),
        (
            "type = \"conductor\"\nmetal = \"Gold\"",
            &[
                "materials.m.metal",
                "unknown metal \"Gold\"",
                "Au",
                "Ag",
                "Cu",
            ],
        ),
        (
            "type = \"principled\"\nmetallic = \"colour\"",
            &[
                "materials.m.metallic",
                "is a colour; a scalar is expected",
                "`channel`",
            ],
        ),
        (
            "type = \"principled\"\nbase_color = \"green\"",
            &[
                "materials.m.base_color",
                "one channel of an image",
                "colour",
            ],
        ),
        (
            "type = \"plastic\"\nalbedo = [0.5, 0.5, 0.5]\nnormal_map = \"inward\"",
            &["materials.m.normal_map", "not a tangent-space normal map"],
        ),
        (
            "type = \"principled\"\nnormal_map = \"green\"",
            &["materials.m.normal_map", "not a normal map"],
        ),
        (
            "type = \"principled\"\nior = 0.8",
            &["materials.m.ior", "from 1 to 1000"],
        ),
        (
            "type = \"plastic\"\nior = 0.5\nroughness = 0.3",
            &["materials.m.ior", "from 1 to 3", "got 0.5"],
        ),
        (
            "type = \"plastic\"\nior = 4",
            &["materials.m.ior", "from 1 to 3", "got 4"],
        ),
        (
            "type = \"principled\"\nior = 1e30",
            &["materials.m.ior", "from 1 to 1000"],
        ),
        (
            "type = \"principled\"\nclearcoat = 1\nclearcoat_normal_scale = 0.5",
            &[
                "materials.m.clearcoat_normal_scale",
                "`clearcoat_normal_map`",
            ],
        ),
        (
            "type = \"principled\"\nopacity = 1.2",
            &["materials.m.opacity", "must be in [0, 1]"],
        ),
        (
            "type = \"principled\"\nalpha_cutoff = 0.5",
            &["materials.m.alpha_cutoff", "`opacity`"],
        ),
        (
            "type = \"principled\"\nnormal_scale = 2",
            &["materials.m.normal_scale", "`normal_map`"],
        ),
        (
            "type = \"plastic\"\nroughness = [0.1, 2]",
            &["materials.m.roughness[1]", "must be in [0, 1]"],
        ),
        (
            "type = \"principled\"\nattenuation_color = [0.5, 0.5, 0.5]",
            &["materials.m.attenuation_color", "attenuation_distance"],
        ),
    ];
    for (material, words) in cases {
        let message = scene_file_error(&dir, &scene(material));
        for w in *words {
            assert!(message.contains(w), "{material}:\n{message}\nlacks {w:?}");
        }
    }
}

/// A quad of material `m` facing +z across (−1, −1, 0)–(1, 1, 0), its
/// texture coordinates running along +x and +y (or, `mirrored`, along −x
/// and −y), seen from (0, 0, 5): the shading normal near its centre.
fn normal_at_centre(dir: &Path, material: &str, mirrored: bool) -> Vec3 {
    let (corner, u, v) = if mirrored {
        ("[1, 1, 0]", "[-2, 0, 0]", "[0, -2, 0]")
    } else {
        ("[-1, -1, 0]", "[2, 0, 0]", "[0, 2, 0]")
    };
    let scene = compile_file(
        dir,
        "quad.toml",
        &format!(
            r#"
{material}

[[objects]]
type = "quad"
corner = {corner}
u = {u}
v = {v}
material = "m"
"#
        ),
    );
    let ray = Ray::new(Vec3::new(0.1, 0.1, 5.0), -Vec3::Z);
    let hit = scene.hit(&ray, Interval::new(1e-4, f32::INFINITY)).unwrap();
    let bsdf = scene
        .material(&hit)
        .bsdf(&hit, -ray.direction, &scene.textures)
        .unwrap();
    bsdf.frame.n
}

/// A normal map's red tilts the normal along +u, its green along +v (up
/// the image, OpenGL's and glTF's convention), whichever way the surface's
/// coordinates run; `normal_scale` scales the tilt.
#[test]
fn normal_maps_tilt_along_u_and_v() {
    let dir = scratch_dir("materials-normal-map");
    // Tilted by about 0.5 towards +u, then towards +v.
    png(&dir.join("u.png"), 2, 2, |_, _| [192, 128, 221, 255]);
    png(&dir.join("v.png"), 2, 2, |_, _| [128, 192, 221, 255]);
    let material = |file: &str, scale: f64| {
        format!(
            "[textures.n]\ntype = \"image\"\nfile = \"{file}\"\n\n\
             [materials.m]\ntype = \"principled\"\nnormal_map = \"n\"\nnormal_scale = {scale}\n"
        )
    };
    // 128 of 255 is a tilt of 0.004, not 0.
    let n = normal_at_centre(&dir, &material("u.png", 1.0), false);
    assert!(n.x > 0.4 && n.y.abs() < 0.01 && n.z > 0.8, "{n}");
    let n = normal_at_centre(&dir, &material("u.png", 1.0), true);
    assert!(n.x < -0.4 && n.y.abs() < 0.01, "u runs along −x: {n}");
    let n = normal_at_centre(&dir, &material("v.png", 1.0), false);
    assert!(n.y > 0.4 && n.x.abs() < 0.01, "v runs along +y: {n}");
    let mirrored = normal_at_centre(&dir, &material("v.png", 1.0), true);
    assert!(
        mirrored.y < -0.4 && mirrored.x.abs() < 0.01,
        "v runs along −y: {mirrored}"
    );
    let half = normal_at_centre(&dir, &material("v.png", 0.5), false);
    assert!(half.y > 0.2 && half.y < n.y, "{half} against {n}");
    let flat = normal_at_centre(&dir, &material("v.png", 0.0), false);
    assert!((flat - Vec3::Z).length() < 1e-5, "{flat}");
}

/// A bump map rising along u tilts the normal back, against +u, by the
/// slope its scale gives it.
#[test]
fn bump_maps_tilt_the_normal_down_the_slope() {
    let dir = scratch_dir("materials-bump");
    // Height rising linearly along u (16 texels), grey.
    png(&dir.join("ramp.png"), 16, 1, |x, _| {
        let v = (x * 16) as u8;
        [v, v, v, 255]
    });
    let material = |scale: f64| {
        format!(
            "[textures.h]\ntype = \"image\"\nfile = \"ramp.png\"\nchannel = \"r\"\n\n\
             [materials.m]\ntype = \"plastic\"\nbump_map = \"h\"\nbump_scale = {scale}\n"
        )
    };
    let n = normal_at_centre(&dir, &material(0.5), false);
    // The value rises 16/255 a texel, 1/16 of u: 256/255 along u, times
    // the scale, over the quad's width of 2.
    let slope = -n.x / n.z;
    let expected = 0.5 * 256.0 / 255.0 / 2.0;
    assert!(
        (slope - expected).abs() < 0.005,
        "{n}: slope {slope}, not {expected}"
    );
    assert!(n.y.abs() < 1e-3, "{n}");
    let mirrored = normal_at_centre(&dir, &material(0.5), true);
    assert!(mirrored.x > 0.1, "u runs along −x: {mirrored}");
}

/// Rays pass through a surface where it is cut out (opacity below the
/// cutoff), camera rays and shadow rays alike, and stop where it is there.
#[test]
fn cut_outs_let_rays_through_where_the_surface_is_not() {
    let dir = scratch_dir("materials-cutout");
    // Left half transparent, right half opaque.
    png(&dir.join("mask.png"), 2, 1, |x, _| {
        [255, 255, 255, if x == 0 { 0 } else { 255 }]
    });
    let scene = compile_file(
        &dir,
        "cutout.toml",
        r#"
[textures.mask]
type = "image"
file = "mask.png"
channel = "a"
filter = "nearest"

[materials.leaf]
type = "diffuse"
albedo = [0.2, 0.8, 0.2]
opacity = "mask"
alpha_cutoff = 0.5

[materials.wall]
type = "diffuse"
albedo = [0.8, 0.2, 0.2]

[[objects]]
type = "quad"
corner = [-1, -1, 0]
u = [2, 0, 0]
v = [0, 2, 0]
material = "leaf"

[[objects]]
type = "quad"
corner = [-1, -1, -1]
u = [2, 0, 0]
v = [0, 2, 0]
material = "wall"
"#,
    );
    let leaf = 0; // materials in name order: leaf, wall
    let first = |x: f32| {
        let ray = Ray::new(Vec3::new(x, 0.0, 5.0), -Vec3::Z);
        scene
            .hit(&ray, Interval::new(1e-4, f32::INFINITY))
            .unwrap()
            .material
    };
    assert_ne!(first(-0.5), leaf, "through the cut-out half");
    assert_eq!(first(0.5), leaf, "stopped by the solid half");
    let shadow = |x: f32| {
        let ray = Ray::new(Vec3::new(x, 0.0, -0.5), Vec3::Z);
        scene.occluded(&ray, Interval::new(1e-4, 10.0))
    };
    assert!(!shadow(-0.5), "a shadow ray passes the cut-out");
    assert!(shadow(0.5));
}

/// Without a cutoff, a surface of opacity a stops a fraction a of the rays
/// (within four standard errors of the binomial count), the same rays
/// every time.
#[test]
fn partial_opacity_stops_its_fraction_of_rays() {
    let dir = scratch_dir("materials-blend");
    let scene = compile_file(
        &dir,
        "blend.toml",
        r#"
[materials.veil]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
opacity = 0.3

[[objects]]
type = "quad"
corner = [-1, -1, 0]
u = [2, 0, 0]
v = [0, 2, 0]
material = "veil"
"#,
    );
    let n = 20_000;
    let hits = |scene: &Scene| {
        (0..n)
            .filter(|&i| {
                let x = (i % 141) as f32 / 141.0 * 1.8 - 0.9;
                let y = (i / 141) as f32 / 142.0 * 1.8 - 0.9;
                let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
                scene
                    .hit(&ray, Interval::new(1e-4, f32::INFINITY))
                    .is_some()
            })
            .count()
    };
    let stopped = hits(&scene);
    let expected = 0.3 * n as f64;
    let sigma = (n as f64 * 0.3 * 0.7).sqrt();
    assert!(
        (stopped as f64 - expected).abs() < 4.0 * sigma,
        "{stopped} of {n} stopped"
    );
    assert_eq!(hits(&scene), stopped, "the same rays stop");
}

/// A scene file: a ball of radius 1 at the origin in `material` (the body
/// of its table), under a white sky, seen from 10 away across a field of
/// `vfov` degrees, 8 × 8 pixels at `spp` samples and paths of `depth`.
fn ball_under_white_sky(material: &str, spp: u32, depth: u32, vfov: f64) -> String {
    format!(
        r#"
[render]
width = 8
height = 8
samples_per_pixel = {spp}
max_depth = {depth}
integrator = "path"

[camera]
vfov = {vfov}
lookfrom = [0, 0, 10]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [1, 1, 1]

[materials.ball]
{material}

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "ball"
"#
    )
}

/// Principled glass with a volume darkens light by Beer–Lambert over the
/// distance it travels inside: a white sky seen through a ball of
/// attenuation colour c at distance d takes a tint of about c^(2r/d).
#[test]
fn principled_volumes_absorb_along_the_path_inside() {
    let dir = scratch_dir("materials-volume");
    let glass = "type = \"principled\"\nbase_color = [1, 1, 1]\ntransmission = 1\nroughness = 0\nspecular = 0\nthickness = 1";
    let text =
        |attenuation: &str| ball_under_white_sky(&format!("{glass}\n{attenuation}"), 64, 32, 2.0);
    let mean = |scene: &Scene| {
        let stats = common::pixel_stats(scene);
        let n = stats.mean.len() as f64;
        [0, 1, 2].map(|c| stats.mean.iter().map(|p| p[c]).sum::<f64>() / n)
    };
    let clear = mean(&compile_file(&dir, "clear.toml", &text("")));
    let tinted = mean(&compile_file(
        &dir,
        "tinted.toml",
        &text("attenuation_color = [0.5, 1, 1]\nattenuation_distance = 2"),
    ));
    // Through the centre the path inside is 2: 0.5^(2/2) of the light.
    let ratio = tinted[0] / clear[0];
    assert!((ratio - 0.5).abs() < 0.03, "red kept {ratio}");
    assert!((tinted[1] - clear[1]).abs() < 1e-6, "green untouched");

    // Where a thickness texture is 0 the surface is a thin wall, not the
    // side of a volume: light crosses the ball straight and nothing on the
    // way absorbs it (it was tinted as if inside a volume).
    image::GrayImage::from_pixel(2, 2, image::Luma([0]))
        .save(dir.join("zero.png"))
        .unwrap();
    let thin = mean(&compile_file(
        &dir,
        "thin.toml",
        &text("attenuation_color = [0.5, 1, 1]\nattenuation_distance = 2")
            .replace("thickness = 1", "thickness = \"zero\"")
            .replace(
                "[materials.ball]",
                "[textures.zero]\ntype = \"image\"\nfile = \"zero.png\"\nchannel = \"r\"\n\n[materials.ball]",
            ),
    ));
    assert!(
        (thin[0] / thin[1] - 1.0).abs() < 1e-3,
        "a thin wall tints red by {}",
        thin[0] / thin[1]
    );
}

/// A transmitting surface of index 1 (glTF's "air") bounds nothing: a
/// white sky seen through a ball of it is white, as principled glass and
/// as rough glass (it was black: at index 1 no microfacet refracts).
#[test]
fn glass_of_index_one_lets_light_straight_through() {
    let dir = scratch_dir("materials-ior-one");
    for material in [
        "type = \"principled\"\ntransmission = 1\nthickness = 1\nbase_color = [1, 1, 1]\nroughness = 0\nspecular = 0\nior = 1",
        "type = \"dielectric\"\nior = 1\nroughness = 0.05",
    ] {
        let scene = compile_file(&dir, "one.toml", &ball_under_white_sky(material, 32, 16, 5.0));
        let stats = common::pixel_stats(&scene);
        let mean: f64 = stats.mean.iter().map(|p| p[0]).sum::<f64>() / stats.mean.len() as f64;
        assert!((mean - 1.0).abs() < 0.02, "{material}: {mean}");
    }
}

/// A thin dielectric sheet absorbs nothing: under a white sky a ball of
/// it is invisible, every sample carrying exactly the sky. In front of a
/// light seen straight on it lets through 1 − 2R/(1 + R) (R = 0.04 for
/// one face of index 1.5), its inner bounces counted: not the 0.96 of one
/// face.
#[test]
fn a_thin_sheet_mirrors_or_lets_through_and_keeps_all_the_light() {
    let dir = scratch_dir("materials-thin-sheet");
    let sheet = "type = \"dielectric\"\nior = 1.5\nthin = true";
    let furnace = compile_file(
        &dir,
        "furnace.toml",
        &ball_under_white_sky(sheet, 16, 32, 12.0),
    );
    for p in common::pixel_stats(&furnace).mean {
        assert!(p.iter().all(|c| (c - 1.0).abs() < 1e-5), "{p:?}");
    }

    let spp = 64u32;
    let window = compile_file(
        &dir,
        "window.toml",
        &format!(
            r#"[render]
width = 16
height = 16
samples_per_pixel = {spp}
max_depth = 8

[camera]
vfov = 1
lookfrom = [0, 0, 0]
lookat = [0, 0, -1]

[background]
type = "solid"
color = [0, 0, 0]

[materials.pane]
{sheet}

[materials.panel]
type = "emissive"
radiance = [1, 1, 1]

[[objects]]
type = "quad"
corner = [-1, -1, -2]
u = [2, 0, 0]
v = [0, 2, 0]
material = "pane"

[[objects]]
type = "quad"
corner = [-1, -1, -3]
u = [2, 0, 0]
v = [0, 2, 0]
material = "panel"
"#
        ),
    );
    let stats = common::pixel_stats(&window);
    let n = stats.mean.len() as f64;
    let mean = stats.mean.iter().map(|p| p[1]).sum::<f64>() / n;
    let r = 0.04f64;
    let expected = 1.0 - 2.0 * r / (1.0 + r);
    // Each sample is 1 (through) or 0 (mirrored into the black behind).
    let sigma = (expected * (1.0 - expected) / (n * f64::from(spp))).sqrt();
    assert!(
        (mean - expected).abs() < 4.0 * sigma,
        "through the pane {mean}, expected {expected} ± {sigma}"
    );
}

/// A scene of a ball of `ball` (with `extra` materials and textures
/// beside it) lit by a small light above it and a dim grey sky, seen
/// whole against the sky.
fn ball_under_a_light(ball: &str, extra: &str, spp: u32) -> String {
    format!(
        r#"
[render]
width = 12
height = 12
samples_per_pixel = {spp}
max_depth = 6
integrator = "path"

[camera]
vfov = 14
lookfrom = [0, 0, 10]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0.2, 0.2, 0.2]

{extra}

[materials.ball]
{ball}

[materials.lamp]
type = "emissive"
radiance = [8, 8, 8]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "ball"

[[objects]]
type = "quad"
corner = [-0.5, 3, -0.5]
u = [1, 0, 0]
v = [0, 0, 1]
material = "lamp"
"#
    )
}

/// The mean of an image and the standard deviation of that mean, from
/// its pixels' sample variances.
fn image_mean(scene: &Scene) -> ([f64; 3], [f64; 3]) {
    let stats = common::pixel_stats(scene);
    let n = stats.mean.len() as f64;
    let mean = [0, 1, 2].map(|c| stats.mean.iter().map(|p| p[c]).sum::<f64>() / n);
    let sigma = [0, 1, 2].map(|c| {
        let var: f64 = stats
            .var
            .iter()
            .zip(&stats.counts)
            .map(|(v, &k)| v[c] / f64::from(k))
            .sum();
        var.sqrt() / n
    });
    (mean, sigma)
}

/// A mix is its two materials blended by its weight: the image of a ball
/// of a rough gold and red diffuse mix, lit by a small light (light
/// samples and BSDF samples weighed by MIS) is (1 − w) times the gold
/// ball's image plus w times the red ball's, within 4σ of the three
/// renders' noise.
#[test]
fn a_mix_renders_as_its_materials_blended_by_its_weight() {
    let dir = scratch_dir("materials-mix-blend");
    let gold = "[materials.gold]\ntype = \"conductor\"\nmetal = \"Au\"\nroughness = 0.4";
    let red = "[materials.red]\ntype = \"diffuse\"\nalbedo = [0.7, 0.1, 0.1]";
    let both = format!("{gold}\n\n{red}");
    let spp = 256;
    let render = |name: &str, ball: &str| {
        image_mean(&compile_file(
            &dir,
            name,
            &ball_under_a_light(ball, &both, spp),
        ))
    };
    let w = 0.3;
    let (a, sa) = render("a.toml", &gold.replace("[materials.gold]\n", ""));
    let (b, sb) = render("b.toml", &red.replace("[materials.red]\n", ""));
    let (m, sm) = render(
        "mix.toml",
        &format!("type = \"mix\"\nmaterials = [\"gold\", \"red\"]\nweight = {w}"),
    );
    for c in 0..3 {
        let expected = (1.0 - w) * a[c] + w * b[c];
        let sigma = (sm[c].powi(2) + ((1.0 - w) * sa[c]).powi(2) + (w * sb[c]).powi(2)).sqrt();
        assert!(
            (m[c] - expected).abs() < 4.0 * sigma,
            "channel {c}: mix {} against {expected} ± {sigma}",
            m[c]
        );
    }
    // Not merely the mean of the two: the weight moves it.
    assert!(
        (m[1] - 0.5 * (a[1] + b[1])).abs() > 4.0 * sm[1],
        "{m:?} {a:?} {b:?}"
    );
}

/// A textured weight chooses per point: a quad under a white sky whose
/// weight is 0 on its left half and 1 on its right shows the first
/// material's albedo on the left and the second's on the right, exactly
/// in every sample.
#[test]
fn a_textured_weight_chooses_the_material_per_point() {
    let dir = scratch_dir("materials-mix-texture");
    png(&dir.join("halves.png"), 2, 1, |x, _| {
        let v = if x == 0 { 0 } else { 255 };
        [v, v, v, 255]
    });
    let scene = compile_file(
        &dir,
        "halves.toml",
        r#"
[render]
width = 8
height = 8
samples_per_pixel = 8
max_depth = 4

[camera]
vfov = 20
lookfrom = [0, 0, 5]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [1, 1, 1]

[textures.halves]
type = "image"
file = "halves.png"
channel = "r"
filter = "nearest"

[materials.dark]
type = "diffuse"
albedo = [0.2, 0.2, 0.2]

[materials.light]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.halves]
type = "mix"
materials = ["dark", "light"]
weight = "halves"
one_sided = true

[[objects]]
type = "quad"
corner = [-2, -2, 0]
u = [4, 0, 0]
v = [0, 4, 0]
material = "halves"
"#,
    );
    let stats = common::pixel_stats(&scene);
    for y in 0..8 {
        for x in 0..8 {
            let i = y * 8 + x;
            let expected = if x < 4 { 0.2 } else { 0.8 };
            for c in 0..3 {
                assert!(
                    (stats.mean[i][c] - expected).abs() < 1e-5 && stats.var[i][c] < 1e-9,
                    "pixel ({x}, {y}): {:?} ± {:?}, expected {expected}",
                    stats.mean[i],
                    stats.var[i]
                );
            }
        }
    }
}

/// A mix's mistakes are refused with the field they are in: a material
/// that is not there, a mix of itself, materials that give off light or
/// have their own map where the mix has one, a weight outside [0, 1], and
/// mixes of mixes past the limit.
#[test]
fn a_mix_refuses_what_it_cannot_be() {
    let dir = scratch_dir("materials-mix-errors");
    let base = "[materials.a]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
                [materials.b]\ntype = \"diffuse\"\nalbedo = [0.1, 0.1, 0.1]\n\n\
                [textures.h]\ntype = \"checkerboard\"\neven = [0, 0, 0]\nodd = [1, 1, 1]\n\n\
                [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    let cases: Vec<(String, &[&str])> =
        vec![
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"bb\"]\n".into(),
            &["materials.m.materials[1]", "no material is named \"bb\"", "did you mean \"b\""],
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"n\"]\n\n\
             [materials.n]\ntype = \"mix\"\nmaterials = [\"m\", \"b\"]\n"
                .into(),
            &["materials.n.materials[0]", "\"m\" is mixed into itself"],
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"glow\"]\n\n\
             [materials.glow]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\nemission = [1, 1, 1]\n"
                .into(),
            &["materials.m.materials[1]", "gives off light", "give it to the mix"],
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"bumpy\"]\nbump_map = \"h\"\n\n\
             [materials.bumpy]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\nbump_map = \"h\"\n"
                .into(),
            &["materials.m.materials[1]", "normal or bump map of its own"],
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"b\"]\nweight = 1.5\n".into(),
            &["materials.m.weight"],
        ),
        (
            "[materials.m]\ntype = \"mix\"\nmaterials = [\"a\"]\n".into(),
            &["materials.m"],
        ),
    ];
    for (text, expected) in cases {
        let message = common::scene_file_error(&dir, &format!("{base}\n{text}"));
        for e in expected {
            assert!(message.contains(e), "{text}\ngave: {message}\nmissing: {e}");
        }
    }
    // Seven levels of mixes of mixes hold 2⁷ = 128 materials: refused
    // before they are copied.
    let mut text = String::from(base).replace("material = \"m\"", "material = \"m7\"");
    text.push_str("\n[materials.m0]\ntype = \"mix\"\nmaterials = [\"a\", \"b\"]\n");
    for level in 1..=7 {
        let below = level - 1;
        text.push_str(&format!(
            "\n[materials.m{level}]\ntype = \"mix\"\nmaterials = [\"m{below}\", \"m{below}\"]\n"
        ));
    }
    let message = common::scene_file_error(&dir, &text);
    assert!(message.contains("at most 64"), "{message}");
}

/// A mix's normal or bump map tilts the normal of both its materials.
#[test]
fn a_mixs_bump_map_is_its_materials() {
    let dir = scratch_dir("materials-mix-bump");
    let scene = compile_file(
        &dir,
        "bump.toml",
        &ball_under_white_sky(
            "type = \"mix\"\nmaterials = [\"a\", \"b\"]\nbump_map = \"h\"\n\n\
             [materials.a]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
             [materials.b]\ntype = \"conductor\"\nmetal = \"Au\"\n\n\
             [textures.h]\ntype = \"checkerboard\"\neven = [0, 0, 0]\nodd = [1, 1, 1]",
            1,
            1,
            10.0,
        ),
    );
    let mix = scene
        .materials
        .iter()
        .find_map(|m| match &m.kind {
            Kind::Mix(mix) => Some(mix),
            _ => None,
        })
        .expect("a mix");
    assert!(mix.materials.iter().all(|m| m.shape.is_some()), "{mix:?}");
}
