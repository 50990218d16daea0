//! Disks and cylinders: exact shapes, as lights and as surfaces. Lit by
//! them, next-event estimation (`path`) and the bounces alone (`bsdf`)
//! agree, and a disk light gives the floor under it its analytic radiance;
//! their texture coordinates are where the documentation puts them; bad
//! values are refused with the field named.
//!
//! Tolerances are K standard errors from each render's own per-pixel
//! sample variance; seeds are fixed.

mod common;

use common::{
    assert_tiles_agree, compile_file, path_and_bsdf, pixel_stats, scene_file_error, scratch_dir, K,
};
use lumen::scene::{Integrator, Scene};

/// A floor, a matte cylinder and a matte disk, lit by a one-sided disk
/// stretched into an ellipse and turned, and a two-sided cylinder of
/// light lying on its side; black sky.
fn shapes() -> String {
    common::on_dark_floor(
        5,
        "vfov = 55\nlookfrom = [0, 2.5, 6]\nlookat = [0, 0.5, 0]",
        r#"[materials.lamp]
type = "emissive"
radiance = [8, 7, 6]

[materials.tube]
type = "emissive"
radiance = [4, 6, 10]
two_sided = true

[materials.matte]
type = "diffuse"
albedo = [0.7, 0.5, 0.4]

[[objects]]
type = "cylinder"
p0 = [-1, 0, 0]
p1 = [-1, 1.2, 0.3]
radius = 0.5
material = "matte"

[[objects]]
type = "disk"
center = [1, 0.7, 0]
normal = [0.3, 0.2, 1]
radius = 0.6
material = "matte"

[[objects]]
type = "disk"
center = [0, 0, 0]
normal = [0, -1, 0]
radius = 1
material = "lamp"
transform = [ { scale = [1.5, 1, 0.6] }, { rotate = { axis = [0, 0, 1], degrees = 20 } }, { translate = [0.5, 3, 0.5] } ]

[[objects]]
type = "cylinder"
p0 = [-2, 2, -1.5]
p1 = [1, 2.5, -1.5]
radius = 0.2
material = "tube"
"#,
    )
}

#[test]
fn path_and_bsdf_agree_under_disk_and_cylinder_lights() {
    let dir = scratch_dir("quadrics-lights");
    let scene = compile_file(&dir, "scene.toml", &shapes());
    assert_eq!(scene.lights.len(), 2, "the disk and the tube are lights");
    let (path, bsdf) = path_and_bsdf(&dir, &shapes());
    assert_tiles_agree("disk and cylinder lights", &path, &bsdf);
    // Each light alone (the other made matte), so that neither hides the
    // other's error.
    for (light, alone) in [("lamp", "the disk light alone"), ("tube", "the tube alone")] {
        let other = if light == "lamp" { "tube" } else { "lamp" };
        let text = shapes().replace(&format!("material = \"{other}\""), "material = \"matte\"");
        assert_eq!(compile_file(&dir, "scene.toml", &text).lights.len(), 1);
        let (path, bsdf) = path_and_bsdf(&dir, &text);
        assert_tiles_agree(alone, &path, &bsdf);
    }
}

#[test]
fn a_moving_disk_renders_as_placed() {
    // The same scene with its matte disk moving (traced in a tree of its
    // own) still agrees between the estimators.
    let dir = scratch_dir("quadrics-moving");
    let text = shapes().replace(
        "radius = 0.6\nmaterial = \"matte\"\n",
        "radius = 0.6\nmaterial = \"matte\"\ntransform = [ { motion = [0, 0.3, 0] } ]\n",
    );
    assert_ne!(text, shapes());
    let (path, bsdf) = path_and_bsdf(&dir, &text);
    assert_tiles_agree("a moving disk", &path, &bsdf);
}

#[test]
fn a_disk_light_gives_the_floor_below_its_analytic_radiance() {
    // A one-sided disk of radius R and radiance Le at height h facing down
    // gives the floor point below its centre the irradiance
    // E = π Le R² / (h² + R²), and a floor of albedo a the radiance
    // a E / π. The camera looks at that point from the side, under the
    // disk, through a field of view narrow enough that E barely varies.
    let (r, h, le, a) = (0.5f64, 1.0f64, 10.0f64, 0.6f64);
    let exact = a * le * r * r / (h * h + r * r);
    let text = format!(
        r#"[render]
width = 4
height = 4
samples_per_pixel = 512
max_depth = 4
seed = 9

[camera]
vfov = 0.2
lookfrom = [4, 0.5, 0]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0, 0, 0]

[materials.lamp]
type = "emissive"
radiance = [{le}, {le}, {le}]

[materials.floor]
type = "diffuse"
albedo = [{a}, {a}, {a}]

[[objects]]
type = "quad"
corner = [-50, 0, -50]
u = [0, 0, 100]
v = [100, 0, 0]
material = "floor"

[[objects]]
type = "disk"
center = [0, {h}, 0]
normal = [0, -1, 0]
radius = {r}
material = "lamp"
"#
    );
    let dir = scratch_dir("quadrics-analytic");
    for integrator in [Integrator::Path, Integrator::Bsdf] {
        let mut scene = compile_file(&dir, "scene.toml", &text);
        scene.settings.integrator = integrator;
        let stats = pixel_stats(&scene);
        let (mean, se) = stats.image(1);
        assert!(
            (mean - exact).abs() <= K * se + 1e-3 * exact,
            "{integrator:?}: {mean} ± {se}, expected {exact}"
        );
        assert!(se < 0.03 * exact, "{integrator:?}: too noisy to tell: {se}");
    }
    // Turned over, the disk shines up: the floor is dark.
    let mut scene = compile_file(&dir, "scene.toml", &text.replace("[0, -1, 0]", "[0, 1, 0]"));
    scene.settings.samples_per_pixel = 16;
    assert_eq!(pixel_stats(&scene).image(1).0, 0.0);
}

/// The colour `scene` renders at each pixel (x, y).
fn pixel_grid(scene: &Scene) -> impl Fn(u32, u32) -> [f64; 3] {
    let stats = pixel_stats(scene);
    move |x, y| [0, 1, 2].map(|c| stats.region(x..x + 1, y..y + 1, c).0)
}

#[test]
fn texture_coordinates_run_as_documented() {
    // Seen straight on under a white sky that it does not reflect (an
    // emissive texture shows its value): a disk textured by a checker in
    // u, v gives the colour of (r, φ/2π); a cylinder, of (φ/2π, share of
    // the way from p0 to p1).
    let dir = scratch_dir("quadrics-uv");
    let scene = |object: &str| {
        compile_file(
            &dir,
            "scene.toml",
            &format!(
                r#"[render]
width = 8
height = 8
samples_per_pixel = 4
max_depth = 1

[camera]
vfov = 40
lookfrom = [0, 0, 5]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0, 0, 0]

[textures.halves]
type = "image"
file = "halves.png"
filter = "nearest"

[materials.shown]
type = "emissive"
radiance = "halves"

{object}"#
            ),
        )
    };
    // A 2 × 2 image: (u < ½, v < ½) red, (u ≥ ½, v < ½) green, (u < ½,
    // v ≥ ½) blue, (u ≥ ½, v ≥ ½) white; v runs up the image.
    let image = image::RgbImage::from_fn(2, 2, |x, y| match (x, y) {
        (0, 1) => image::Rgb([255, 0, 0]),
        (1, 1) => image::Rgb([0, 255, 0]),
        (0, 0) => image::Rgb([0, 0, 255]),
        _ => image::Rgb([255, 255, 255]),
    });
    image.save(dir.join("halves.png")).unwrap();
    let (red, green, blue, white) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0; 3]);
    let close = |got: [f64; 3], want: [f64; 3], what: &str| {
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-3),
            "{what}: {got:?}, expected {want:?}"
        );
    };
    // The camera's pixels are 0.455 wide where it looks, at z = 0, and a
    // pixel's samples stay inside it (box filter).
    //
    // A disk of radius 2 facing the camera, whose frame for +z is (x, y):
    // u = r/2 and v = φ/2π. Pixel (4, 3) spans x, y ∈ [0, 0.455] (u below
    // 0.33, φ in the first quarter): red. (7, 3) spans x ∈ [1.37, 1.82],
    // y ∈ [0, 0.455] (u above 0.68, φ below 18°): green. (3, 4) spans
    // x, y ∈ [−0.455, 0] (φ in the third quarter, v in [½, ¾]): blue.
    // (7, 4), below (7, 3) (φ above 344°): white.
    let disk = scene(
        "[[objects]]\ntype = \"disk\"\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = 2\nmaterial = \"shown\"\n",
    );
    let pixels = pixel_grid(&disk);
    close(pixels(4, 3), red, "disk, near the centre, first quarter");
    close(pixels(7, 3), green, "disk, near the rim, first quarter");
    close(pixels(3, 4), blue, "disk, near the centre, third quarter");
    close(pixels(7, 4), white, "disk, near the rim, fourth quarter");
    // A cylinder of radius 1 from y = −2 to y = 2: its frame about +y has
    // x along x and y along −z, so the half facing the camera (+z) has φ
    // in (π, 2π), u above ½; v is (y + 2)/4. Pixel (4, 6) sees y ≈ −0.9
    // on it: green; (4, 1), y ≈ 0.9: white.
    let tube = scene(
        "[[objects]]\ntype = \"cylinder\"\np0 = [0, -2, 0]\np1 = [0, 2, 0]\nradius = 1\nmaterial = \"shown\"\n",
    );
    let pixels = pixel_grid(&tube);
    close(pixels(4, 6), green, "cylinder, lower front");
    close(pixels(4, 1), white, "cylinder, upper front");
}

#[test]
fn bad_disks_and_cylinders_are_refused_with_the_field_named() {
    let dir = scratch_dir("quadrics-bad");
    let base = "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                [materials.glow]\ntype = \"emissive\"\nradiance = [1, 1, 1]\n\n[[objects]]\n";
    let disk =
        "type = \"disk\"\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = 1\nmaterial = \"m\"\n";
    let tube =
        "type = \"cylinder\"\np0 = [0, 0, 0]\np1 = [0, 0, 1]\nradius = 1\nmaterial = \"m\"\n";
    for (object, expected) in [
        (
            disk.replace("radius = 1", "radius = 0"),
            "objects[0].radius",
        ),
        (disk.replace("radius = 1", "radius = -2"), "greater than 0"),
        (disk.replace("[0, 0, 1]", "[0, 0, 0]"), "objects[0].normal"),
        (disk.replace("radius = 1\n", ""), "radius"),
        (disk.replace("normal", "p1"), "cylinders"),
        (tube.replace("[0, 0, 1]", "[0, 0, 0]"), "objects[0].p1"),
        (
            tube.replace("radius = 1", "radius = nan"),
            "objects[0].radius",
        ),
        (tube.replace("p0", "center"), "spheres and disks"),
        (
            disk.to_string() + "transform = [ { scale = [1, 1e30, 1] } ]\n",
            "objects[0].transform",
        ),
    ] {
        let message = scene_file_error(&dir, &format!("{base}{object}"));
        assert!(
            message.contains(expected),
            "`{object}`: expected {expected:?} in: {message}"
        );
    }
    // A cylinder stretched across its axis is fine as a surface, and as a
    // light is found by the bounces alone (not sampled).
    let stretched = format!("{tube}transform = [ {{ scale = [1, 2, 1] }} ]\n");
    let scene = compile_file(&dir, "ok.toml", &format!("{base}{stretched}"));
    assert_eq!(scene.lights.len(), 0);
    let glowing = stretched.replace("\"m\"", "\"glow\"");
    let scene = compile_file(&dir, "ok.toml", &format!("{base}{glowing}"));
    assert_eq!(scene.lights.len(), 0, "not sampled");
    assert!(scene.materials.iter().any(|m| m.emits()));
}

#[test]
fn a_cylinder_light_stretched_across_its_axis_is_found_by_the_bounces() {
    // The tube of the scene above flattened across its axis: not a
    // sampled light, and both estimators still agree.
    let dir = scratch_dir("quadrics-stretched-light");
    let text = shapes().replace(
        "radius = 0.2\nmaterial = \"tube\"\n",
        "radius = 0.2\nmaterial = \"tube\"\ntransform = [ { scale = [1, 1, 2.5] } ]\n",
    );
    assert_ne!(text, shapes());
    assert_eq!(
        compile_file(&dir, "scene.toml", &text).lights.len(),
        1,
        "the disk alone"
    );
    let (path, bsdf) = path_and_bsdf(&dir, &text);
    common::tiles_agree("a stretched tube", &path, &bsdf);
}

#[test]
fn a_mitsuba_scene_of_disks_and_cylinders_exported_to_toml_renders_to_the_same_bits() {
    use lumen::scene::file::{mitsuba, Format, SceneFile};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scripts/peers/disks_cylinders/disks_cylinders.xml");
    let options = mitsuba::Options {
        defines: [("spp", "4"), ("width", "64"), ("height", "48")]
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .to_vec(),
        ..Default::default()
    };
    let direct = SceneFile::read_with(&path, &options).unwrap_or_else(|e| panic!("{e}"));
    let kinds = |d: &lumen::scene::SceneDesc| {
        d.objects
            .iter()
            .filter(|o| {
                matches!(
                    o,
                    lumen::scene::desc::ObjectDesc::Disk { .. }
                        | lumen::scene::desc::ObjectDesc::Cylinder { .. }
                )
            })
            .count()
    };
    assert_eq!(kinds(&direct.desc), 4, "three disks and a cylinder");
    let text = lumen::scene::file::export(&direct.desc, Format::Toml).unwrap();
    let mut exported = SceneFile::parse("exported.toml", text, Format::Toml).unwrap();
    assert_eq!(exported.desc, direct.desc);
    exported.dir = direct.dir.clone();
    let render = |f: &SceneFile| {
        let scene = f.compile(&lumen::scene::Overrides::default()).unwrap();
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let (a, b) = (render(&direct), render(&exported));
    assert!(a.iter().any(|c| c.max_element() > 0.0), "black");
    assert!(a == b, "the exported scene renders differently");
}
