//! Textures as a scene uses them: the colour a ray finds where it hits
//! (checker cells in space, an image by a quad's, a sphere's and a mesh's
//! (u, v), noise), textured lights (sampled by their texture), and the messages for bad textures.

mod common;

use common::{
    colour_at, colours_close as close, compile_file, pixel_stats, scene_file_error, scratch_dir,
    tiles_agree,
};
use lumen::math::{Color, Vec3};

#[test]
fn a_checker_alternates_cubes_of_its_scale_in_space() {
    let dir = scratch_dir("tex-checker");
    let scene = compile_file(
        &dir,
        "c.toml",
        r#"
[textures.cells]
type = "checker"
scale = 0.5
even = [1, 0, 0]
odd = "inner"

[textures.inner]
type = "checker"
scale = 0.25
even = [0, 1, 0]
odd = [0, 0, 1]

[materials.floor]
type = "diffuse"
albedo = "cells"

[[objects]]
type = "quad"
corner = [-4, 0.1, -4]
u = [0, 0, 8]
v = [8, 0, 0]
material = "floor"
"#,
    );
    // The floor at y = 0.1 lies in the cells ⌊y/s⌋ = 0 of both checkers.
    let at = |x: f32, z: f32| colour_at(&scene, Vec3::new(x, 1.0, z), -Vec3::Y);
    let parity = |x: f32, z: f32, s: f32| ((x / s).floor() + (z / s).floor()) as i64 % 2 == 0;
    let mut seen = [0; 3];
    for i in 0..40 {
        let (x, z) = (-2.0 + 0.1037 * i as f32, 1.9 - 0.0871 * i as f32);
        let want = if parity(x, z, 0.5) {
            Color::X
        } else if parity(x, z, 0.25) {
            Color::Y
        } else {
            Color::Z
        };
        assert_eq!(at(x, z), want, "({x}, {z})");
        seen[if want == Color::X {
            0
        } else if want == Color::Y {
            1
        } else {
            2
        }] += 1;
    }
    assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
}

/// Writes a 2 × 2 PNG: top row red, green; bottom row blue, grey 128.
fn write_png(path: &std::path::Path) {
    let img = image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128])
        .unwrap();
    img.save(path).unwrap();
}

#[test]
fn an_image_is_wrapped_by_a_quads_coordinates_with_v_upwards() {
    let dir = scratch_dir("tex-image-quad");
    write_png(&dir.join("four.png"));
    let scene = compile_file(
        &dir,
        "q.toml",
        r#"
[textures.four]
type = "image"
file = "four.png"

[materials.wall]
type = "diffuse"
albedo = "four"

[[objects]]
type = "quad"
corner = [0, 0, 0]
u = [1, 0, 0]
v = [0, 1, 0]
material = "wall"
"#,
    );
    let look = |u: f32, v: f32| colour_at(&scene, Vec3::new(u, v, 1.0), -Vec3::Z);
    // (α, β) = (u, v): the image's bottom row at β = 0, its top at β = 1;
    // texel centres at 1/4 and 3/4.
    assert!(close(look(0.25, 0.75), Color::X), "top left red");
    assert!(close(look(0.75, 0.75), Color::Y), "top right green");
    assert!(close(look(0.25, 0.25), Color::Z), "bottom left blue");
    // 8-bit texels are sRGB: 128 is 0.2158 in linear light.
    let grey = look(0.75, 0.25);
    assert!(close(grey, Color::splat(0.215_861)), "{grey:?}");
    // Halfway between red and green.
    assert!(close(look(0.5, 0.75), Color::new(0.5, 0.5, 0.0)));
}

#[test]
fn spheres_and_meshes_give_textures_their_coordinates() {
    let dir = scratch_dir("tex-image-sphere");
    // 4 columns: the u of a sphere runs from −x round by +z... each column
    // its own colour, constant down the rows.
    let columns: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]];
    let raw: Vec<u8> = (0..2)
        .flat_map(|_| columns.iter().flatten().copied())
        .collect();
    image::RgbImage::from_raw(4, 2, raw)
        .unwrap()
        .save(dir.join("bands.png"))
        .unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.125 0.5\nvt 0.375 0.5\nvt 0.625 0.5\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let scene = compile_file(
        &dir,
        "s.toml",
        r#"
[textures.bands]
type = "image"
file = "bands.png"

[materials.globe]
type = "diffuse"
albedo = "bands"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "globe"

[[objects]]
type = "sphere"
center = [10, 0, 0]
radius = 1
material = "globe"
transform = [{ rotate = { axis = [0, 1, 0], degrees = 90 } }, { translate = [0, 0, 5] }]

[[objects]]
type = "mesh"
file = "tri.obj"
material = "globe"
transform = [{ translate = [0, 0, 20] }]
"#,
    );
    // The Next Week's sphere coordinates: u = φ/2π, φ measured from −x
    // towards −z... so that the point +z has u = 1/4: halfway between the
    // centres of columns 0 (red) and 1 (green), the rows all alike.
    let front = colour_at(&scene, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    assert!(close(front, Color::new(0.5, 0.5, 0.0)), "{front:?}");
    // The point −x has u = 0 ≡ 1: halfway between columns 3 (white) and 0.
    let left = colour_at(&scene, Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    assert!(close(left, Color::new(1.0, 0.5, 0.5)), "{left:?}");
    // The second sphere is turned 90° about y (and moved to (0, 0, −5)):
    // its texture turns with it, what faced +z now faces +x.
    let turned = colour_at(&scene, Vec3::new(5.0, 0.0, -5.0), -Vec3::X);
    assert!(close(turned, front), "{turned:?} instead of {front:?}");
    // The mesh's own coordinates: near its first corner (u = 0.125, the
    // centre of column 0), barycentrics 0.01 towards the others move u to
    // 0.1325, 3% of the way to column 1.
    let corner = colour_at(&scene, Vec3::new(0.01, 0.01, 25.0), -Vec3::Z);
    assert!(
        (corner - Color::new(0.97, 0.03, 0.0)).abs().max_element() < 2e-3,
        "{corner:?}"
    );
}

/// A 4 × 2 PNG: the top row red, green, blue, white; the bottom row black.
fn write_banded_png(path: &std::path::Path) {
    let top: [u8; 12] = [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255];
    let raw: Vec<u8> = top.iter().copied().chain([0u8; 12]).collect();
    image::RgbImage::from_raw(4, 2, raw)
        .unwrap()
        .save(path)
        .unwrap();
}

/// Mesh files bring their own textures: MTL `map_Kd` (times `Kd`) and glTF
/// `baseColorTexture` (times `baseColorFactor`), each read by the file's
/// texture coordinates (glTF's v running down the image, OBJ's up).
#[test]
fn mesh_files_bring_their_base_colour_textures() {
    let dir = scratch_dir("tex-mesh-files");
    write_banded_png(&dir.join("bands.png"));
    // One triangle facing +z, its first corner on the centre of the top
    // row's first texel (u = 1/8; v = 3/4 upwards, 1/4 downwards).
    std::fs::write(
        dir.join("tri.obj"),
        "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
         vt 0.125 0.75\nvt 0.375 0.75\nvt 0.625 0.75\nusemtl half\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tri.mtl"),
        "newmtl half\nKd 0.5 0.5 0.5\nmap_Kd bands.png\n",
    )
    .unwrap();
    let floats: Vec<f32> = vec![
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, // positions
        0.125, 0.25, 0.375, 0.25, 0.625, 0.25, // texture coordinates
    ];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    use base64::Engine as _;
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [1, 0.5, 1, 1],
      "baseColorTexture": {{"index": 0}}, "metallicFactor": 0}}}}],
  "textures": [{{"source": 0}}], "images": [{{"uri": "bands.png"}}],
  "buffers": [{{"byteLength": 60, "uri": "data:application/octet-stream;base64,{data}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
                  {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}]}}"#
    );
    std::fs::write(dir.join("tri.gltf"), gltf).unwrap();
    let scene = compile_file(
        &dir,
        "m.toml",
        r#"
[[objects]]
type = "mesh"
file = "tri.obj"

[[objects]]
type = "mesh"
file = "tri.gltf"
transform = [{ translate = [0, 0, 10] }]
"#,
    );
    // Near the first corner: 3% of the way from red to green (see
    // `spheres_and_meshes_give_textures_their_coordinates`), in the top row.
    let obj = colour_at(&scene, Vec3::new(0.01, 0.01, 5.0), -Vec3::Z);
    let want = Color::new(0.97, 0.03, 0.0);
    assert!(
        (obj - 0.5 * want).abs().max_element() < 2e-3,
        "OBJ: {obj:?}"
    );
    let gltf = colour_at(&scene, Vec3::new(0.01, 0.01, 15.0), -Vec3::Z);
    let factor = Color::new(1.0, 0.5, 1.0);
    assert!(
        (gltf - factor * want).abs().max_element() < 2e-3,
        "glTF: {gltf:?}"
    );
    // A missing image is named with its material.
    std::fs::write(dir.join("tri.mtl"), "newmtl half\nmap_Kd gone.png\n").unwrap();
    let message = scene_file_error(&dir, "[[objects]]\ntype = \"mesh\"\nfile = \"tri.obj\"\n");
    assert!(
        message.contains("map_Kd") && message.contains("gone.png"),
        "{message}"
    );
}

#[test]
fn a_textured_light_emits_its_texture_and_is_sampled() {
    let dir = scratch_dir("tex-light");
    let scene = compile_file(
        &dir,
        "l.toml",
        r#"
[textures.stripes]
type = "checker"
scale = 1
even = [4, 4, 4]
odd = [0, 0, 0]

[materials.lamp]
type = "emissive"
radiance = "stripes"

[materials.bulb]
type = "emissive"
radiance = [1, 1, 1]

[[objects]]
type = "quad"
corner = [-2, 3, -2]
u = [4, 0, 0]
v = [0, 0, 4]
material = "lamp"

[[objects]]
type = "sphere"
center = [0, -5, 0]
radius = 1
material = "bulb"
"#,
    );
    // Cells of side 1 at y = 3: (0.5, 3, 0.5) is in cell (0, 3, 0), odd.
    let up = Vec3::Y;
    assert_eq!(colour_at(&scene, Vec3::new(0.5, 0.0, 0.5), up), Color::ZERO);
    assert_eq!(
        colour_at(&scene, Vec3::new(1.5, 0.0, 0.5), up),
        Color::splat(4.0)
    );
    // The bulb and the textured lamp are sampled (not the gradient sky).
    assert_eq!(scene.lights.len(), 2);
}

/// A floor lit only by a lamp whose radiance is a checker (bright and dark
/// cells) and by a sphere of Perlin-noise light: the `path` integrator,
/// which samples both by their texture where the sample lands, converges
/// to the image of the `bsdf` integrator, which finds them by chance.
#[test]
fn textured_lights_sampled_agree_with_textured_lights_found() {
    let dir = scratch_dir("tex-light-agree");
    let text = |integrator: &str, spp: u32| {
        format!(
            r#"
[render]
width = 32
height = 32
samples_per_pixel = {spp}
integrator = "{integrator}"
gamma = 1.0
seed = 4
[camera]
lookfrom = [0, 5, 6]
lookat = [0, 0, 0]
vfov = 60
[background]
type = "solid"
color = [0, 0, 0]
[textures.stripes]
type = "checker"
scale = 0.5
even = [6, 5, 4]
odd = [0.2, 0.2, 0.2]
[textures.cloud]
type = "noise"
scale = 4
[materials.lamp]
type = "emissive"
radiance = "stripes"
two_sided = true
[materials.glow]
type = "emissive"
radiance = "cloud"
[materials.floor]
type = "diffuse"
albedo = [0.7, 0.7, 0.7]
[[objects]]
type = "quad"
corner = [-3, 0, -3]
u = [0, 0, 6]
v = [6, 0, 0]
material = "floor"
[[objects]]
type = "quad"
corner = [-1.5, 2.5, -2.5]
u = [3, 0, 0]
v = [0, 0, 2]
material = "lamp"
[[objects]]
type = "sphere"
center = [1.5, 0.8, 1]
radius = 0.5
material = "glow"
"#
        )
    };
    let scene = compile_file(&dir, "path.toml", &text("path", 128));
    assert_eq!(scene.lights.len(), 2, "both textured lights are sampled");
    let path = pixel_stats(&scene);
    let bsdf = pixel_stats(&compile_file(&dir, "bsdf.toml", &text("bsdf", 512)));
    tiles_agree("textured lights", &path, &bsdf);
}

#[test]
fn noise_textures_are_grey_deterministic_and_seeded() {
    let dir = scratch_dir("tex-noise");
    let text = |seed: u64| {
        format!(
            r#"
[textures.n]
type = "noise"
scale = 3
pattern = "turbulence"
seed = {seed}

[materials.m]
type = "metal"
albedo = "n"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
"#
        )
    };
    let a = compile_file(&dir, "a.toml", &text(1));
    let b = compile_file(&dir, "b.toml", &text(1));
    let c = compile_file(&dir, "c.toml", &text(2));
    let mut differ = 0;
    for i in 0..20 {
        let d = Vec3::new(0.02 * i as f32 - 0.2, 0.1, -1.0);
        let from = Vec3::new(0.0, 0.0, 3.0);
        let (x, y, z) = (
            colour_at(&a, from, d),
            colour_at(&b, from, d),
            colour_at(&c, from, d),
        );
        assert_eq!(x, y);
        assert!(x.x == x.y && x.y == x.z && (0.0..=1.0).contains(&x.x));
        differ += usize::from(x != z);
    }
    assert!(differ > 10, "seeds 1 and 2 gave the same noise");
}

#[test]
fn bad_textures_are_refused_with_the_field_named() {
    let dir = scratch_dir("tex-errors");
    let cases: [(&str, &str, &str); 8] = [
        (
            "[materials.m]\ntype = \"diffuse\"\nalbedo = \"nothing\"",
            "materials.m.albedo",
            "no texture named \"nothing\"",
        ),
        (
            "[textures.a]\ntype = \"checker\"\nscale = 1\neven = \"b\"\nodd = [0, 0, 0]\n\
             [textures.b]\ntype = \"checker\"\nscale = 1\neven = [1, 1, 1]\nodd = \"a\"\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = \"a\"",
            "textures.a",
            "a → b → a",
        ),
        (
            "[textures.a]\ntype = \"checker\"\nscale = 0\neven = [1, 1, 1]\nodd = [0, 0, 0]\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = \"a\"",
            "textures.a.scale",
            "greater than 0",
        ),
        (
            "[textures.a]\ntype = \"image\"\nfile = \"gone.png\"\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = \"a\"",
            "textures.a.file",
            "gone.png",
        ),
        ("[textures.a]\ntype = \"wood\"", "textures.a.type", "wood"),
        (
            "[textures.a]\ntype = \"noise\"\nfile = \"x.png\"",
            "textures.a",
            "image textures",
        ),
        (
            "[materials.m]\ntype = \"diffuse\"\nalbedo = 3",
            "materials.m.albedo",
            "name of a texture",
        ),
        (
            "[textures.a]\ntype = \"checker\"\nscale = 1\neven = [2, 0, 0]\nodd = [0, 0, 0]\n\
             [materials.m]\ntype = \"emissive\"\nradiance = \"a\"\n\
             [materials.n]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [textures.b]\ntype = \"checker\"\nscale = 1\neven = [-1, 0, 0]\nodd = [0, 0, 0]\n\
             [materials.o]\ntype = \"diffuse\"\nalbedo = \"b\"",
            "textures.b.even",
            "negative",
        ),
    ];
    for (text, field, words) in cases {
        let message = scene_file_error(&dir, text);
        assert!(
            message.contains(field) && message.contains(words),
            "{text}\n→ {message}"
        );
    }
}

/// A `mix` texture is (1 − amount)·first + amount·second: a constant
/// amount blends two colours everywhere; an amount that is a texture (an
/// image's red channel, 0 on the left and 1 on the right of a quad)
/// shows the first on the left, the second on the right, half and half
/// between the texel centres. A mix of greys gives a number (a roughness).
#[test]
fn a_mix_texture_blends_by_its_amount() {
    let dir = scratch_dir("tex-mix");
    image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255])
        .unwrap()
        .save(dir.join("ramp.png"))
        .unwrap();
    let scene = compile_file(
        &dir,
        "m.toml",
        r#"
[textures.ramp]
type = "image"
file = "ramp.png"
channel = "r"

[textures.even]
type = "mix"
first = [0.8, 0.2, 0.0]
second = [0.0, 0.2, 0.8]
amount = 0.25

[textures.by-ramp]
type = "mix"
first = [1, 0, 0]
second = "even"
amount = "ramp"

[textures.grey]
type = "mix"
first = [0.1, 0.1, 0.1]
second = [0.5, 0.5, 0.5]
amount = "ramp"

[materials.flat]
type = "diffuse"
albedo = "even"

[materials.ramped]
type = "diffuse"
albedo = "by-ramp"

[materials.rough]
type = "conductor"
metal = "Au"
roughness = "grey"

[[objects]]
type = "quad"
corner = [0, 0, 0]
u = [1, 0, 0]
v = [0, 1, 0]
material = "flat"

[[objects]]
type = "quad"
corner = [2, 0, 0]
u = [1, 0, 0]
v = [0, 1, 0]
material = "ramped"

[[objects]]
type = "quad"
corner = [4, 0, 0]
u = [1, 0, 0]
v = [0, 1, 0]
material = "rough"
"#,
    );
    let look = |x: f32, y: f32| colour_at(&scene, Vec3::new(x, y, 1.0), -Vec3::Z);
    let even = Color::new(0.6, 0.2, 0.2);
    assert!(close(look(0.3, 0.6), even), "{:?}", look(0.3, 0.6));
    // Texel centres at u = ¼ and ¾: the amount 0 and 1 there, ½ midway.
    assert!(close(look(2.25, 0.5), Color::X), "{:?}", look(2.25, 0.5));
    assert!(close(look(2.75, 0.5), even), "{:?}", look(2.75, 0.5));
    let half = (Color::X + even) * 0.5;
    assert!(close(look(2.5, 0.5), half), "{:?}", look(2.5, 0.5));
}

#[test]
fn bad_mix_textures_are_refused_with_the_field_named() {
    let dir = scratch_dir("tex-mix-bad");
    let scene = |mix: &str| {
        format!(
            "[textures.m]\ntype = \"mix\"\n{mix}\n\n\
             [textures.colour]\ntype = \"checkerboard\"\neven = [1, 0, 0]\nodd = [0, 0, 1]\n\n\
             [materials.a]\ntype = \"diffuse\"\nalbedo = \"m\"\n\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"a\"\n"
        )
    };
    for (mix, expected) in [
        (
            "first = [1, 1, 1]\nsecond = [0, 0, 0]\namount = 1.5",
            &["textures.m.amount", "[0, 1]"][..],
        ),
        (
            "first = [1, 1, 1]\nsecond = [0, 0, 0]\namount = \"colour\"",
            &["textures.m.amount", "is a colour"][..],
        ),
        (
            "first = [1, 1, 1]\nsecond = [0, 0, 0]\namount = \"m\"",
            &["textures.m", "refers to itself"][..],
        ),
        (
            "first = [1, 1, 1]\nsecond = [0, 0, 0]\namount = [0.5, 0.5, 0.5]",
            &["textures.m.amount", "a number or the name of a texture"][..],
        ),
        (
            "first = [1, 1, 1]\namount = 0.5",
            &["textures.m", "second"][..],
        ),
    ] {
        let message = scene_file_error(&dir, &scene(mix));
        for e in expected {
            assert!(message.contains(e), "{mix}\ngave: {message}\nmissing: {e}");
        }
    }
}
