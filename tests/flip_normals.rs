//! `flip_normals`: every kind of surface turned inside out. A one-sided
//! light then shines to its other side, seen directly and sampled by
//! next-event estimation (which agrees with the bounces alone, and with
//! the same light built facing that way); a glass sphere becomes a bubble
//! of air in glass.
//!
//! Tolerances are K standard errors from each render's own per-pixel
//! sample variance; seeds are fixed.

mod common;

use common::{
    assert_agree, assert_tiles_agree, compile_file, path_and_bsdf, pixel_stats, scratch_dir,
    tiles_agree, K,
};

/// A square of two triangles in the plane z = 0, wound to face +z, as an
/// OBJ file.
const SQUARE_OBJ: &str = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n";

/// The same square written out in the scene.
const SQUARE: &str = "positions = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]\n\
                      indices = [[0, 1, 2], [0, 2, 3]]";

/// One object of each kind, as a one-sided light, each with the camera
/// placed where it sees the object's outside: (kind, the object's fields,
/// the camera's lookfrom and lookat).
fn shapes() -> Vec<(&'static str, String, &'static str)> {
    vec![
        (
            "sphere",
            "center = [0, 0, 0]\nradius = 1".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "quad",
            "corner = [-1, -1, 0]\nu = [2, 0, 0]\nv = [0, 2, 0]".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "disk",
            "center = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = 1".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "cylinder",
            "p0 = [0, -1, 0]\np1 = [0, 1, 0]\nradius = 1".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "box",
            "min = [-1, -1, -1]\nmax = [1, 1, 1]".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "mesh",
            "file = \"square.obj\"".into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
        (
            "triangles",
            SQUARE.into(),
            "lookfrom = [0, 0, 5]\nlookat = [0, 0, 0]",
        ),
    ]
}

/// A scene of the one-sided light `kind` (`fields`) seen from `camera`
/// under a black sky, with light paths of one segment: a pixel shows the
/// light's radiance where it sees the light's outside, black elsewhere.
fn seen(kind: &str, fields: &str, flip: bool, camera: &str) -> String {
    format!(
        r#"[render]
width = 8
height = 8
samples_per_pixel = 4
max_depth = 1

[camera]
vfov = 20
{camera}

[background]
type = "solid"
color = [0, 0, 0]

[materials.lamp]
type = "emissive"
radiance = [3, 2, 1]

[[objects]]
type = "{kind}"
{fields}
material = "lamp"
flip_normals = {flip}
"#
    )
}

/// The mean colour of the middle 2 × 2 pixels of the 8 × 8 scene `text`
/// (written to `dir`).
fn centre(dir: &std::path::Path, text: &str) -> [f64; 3] {
    let stats = pixel_stats(&compile_file(dir, "scene.toml", text));
    [0, 1, 2].map(|c| stats.region(3..5, 3..5, c).0)
}

#[test]
fn a_flipped_light_shines_from_its_other_side() {
    // Seen from outside at the centre of the image, each kind shows its
    // radiance; flipped, it is black there. Seen from inside (the sphere,
    // the cylinder and the box), the other way round, in every pixel.
    let dir = scratch_dir("flip-normals-seen");
    std::fs::write(dir.join("square.obj"), SQUARE_OBJ).unwrap();
    let centre = |text: &str| centre(&dir, text);
    let whole = |text: &str| {
        let stats = pixel_stats(&compile_file(&dir, "scene.toml", text));
        [0, 1, 2].map(|c| stats.image(c).0)
    };
    for (kind, fields, camera) in shapes() {
        let outside = centre(&seen(kind, &fields, false, camera));
        assert_eq!(outside, [3.0, 2.0, 1.0], "{kind} from outside");
        let flipped = centre(&seen(kind, &fields, true, camera));
        assert_eq!(flipped, [0.0; 3], "{kind} flipped, from outside");
    }
    let inside = "lookfrom = [0, 0, 0.5]\nlookat = [0, 0, -1]";
    for (kind, fields, _) in shapes()
        .into_iter()
        .filter(|(k, _, _)| ["sphere", "cylinder", "box"].contains(k))
    {
        let fields = fields
            .replace("[0, -1, 0]", "[0, -9, 0]")
            .replace("[0, 1, 0]", "[0, 9, 0]");
        assert_eq!(
            whole(&seen(kind, &fields, false, inside)),
            [0.0; 3],
            "{kind} from inside"
        );
        let flipped = whole(&seen(kind, &fields, true, inside));
        for (c, want) in [3.0, 2.0, 1.0].into_iter().enumerate() {
            assert!(
                (flipped[c] - want).abs() < 1e-6,
                "{kind} flipped, from inside: {flipped:?}"
            );
        }
    }
}

#[test]
fn a_mirror_keeps_every_objects_outside() {
    // Mirrored in x, each kind still shows its light to the camera, and
    // flipped it does not: a mesh placed once (its triangles moved into
    // the world, their winding turned over) as a mesh placed twice (one
    // tree, placed by two instances).
    let dir = scratch_dir("flip-normals-mirrored");
    std::fs::write(dir.join("square.obj"), SQUARE_OBJ).unwrap();
    let centre = |text: &str| centre(&dir, text);
    let mirror = "transform = [ { scale = [-1, 1, 1] } ]";
    let again = "\n[[objects]]\ntype = \"mesh\"\nfile = \"square.obj\"\nmaterial = \"lamp\"\n\
                 transform = [ { scale = [-1, 1, 1] }, { translate = [0, 0, -50] } ]\n";
    for (kind, fields, camera) in shapes() {
        for twice in [false, true] {
            if twice && kind != "mesh" {
                continue;
            }
            let fields = format!("{fields}\n{mirror}");
            for flip in [false, true] {
                let mut text = seen(kind, &fields, flip, camera);
                if twice {
                    text += &format!("{again}flip_normals = {flip}\n");
                    let scene = compile_file(&dir, "scene.toml", &text);
                    assert_eq!(scene.stats.instances, 2, "instanced");
                }
                let want = if flip { [0.0; 3] } else { [3.0, 2.0, 1.0] };
                assert_eq!(
                    centre(&text),
                    want,
                    "{kind} mirrored, twice {twice}, flipped {flip}"
                );
            }
        }
    }
}

/// A floor lit from above by one-sided lights of each flat kind (and a
/// mesh file placed twice), built facing up and turned down by
/// `flip_normals` (`flipped`), or built facing down.
fn lit_floor(flipped: bool) -> String {
    let (up, down) = ("flip_normals = true", "");
    let (quad, disk, tri) = if flipped {
        (
            format!("corner = [-2.5, 2, -1]\nu = [1, 0, 0]\nv = [0, 0, -1]\n{up}"),
            format!("normal = [0, 1, 0]\n{up}"),
            up.to_string(),
        )
    } else {
        (
            format!("corner = [-2.5, 2, -2]\nu = [1, 0, 0]\nv = [0, 0, 1]\n{down}"),
            "normal = [0, -1, 0]".to_string(),
            String::new(),
        )
    };
    // The triangles face +z as written; turned by the transform to face up
    // (+y), flipped to face down; or wound the other way.
    let indices = if flipped {
        "indices = [[0, 1, 2], [0, 2, 3]]"
    } else {
        "indices = [[0, 2, 1], [0, 3, 2]]"
    };
    // A mesh file placed twice (held once, placed by two instances): turned
    // up and flipped, or turned down.
    let degrees = if flipped { -90 } else { 90 };
    let mesh = |x: f64| {
        format!(
            "[[objects]]\ntype = \"mesh\"\nfile = \"square.obj\"\nmaterial = \"panel\"\n{tri}\n\
             transform = [ {{ scale = 0.3 }}, {{ rotate = {{ axis = [1, 0, 0], degrees = {degrees} }} }}, {{ translate = [{x}, 2.1, -1.5] }} ]\n"
        )
    };
    let meshes = mesh(1.0) + &mesh(2.0);
    common::on_dark_floor(
        17,
        "vfov = 50\nlookfrom = [0, 1.5, 6]\nlookat = [0, 0.6, 0]",
        &format!(
            r#"[materials.lamp]
type = "emissive"
radiance = [6, 5, 4]

[materials.panel]
type = "emissive"
radiance = [6, 5, 4]

[materials.matte]
type = "diffuse"
albedo = [0.7, 0.6, 0.5]

[[objects]]
type = "quad"
{quad}
material = "lamp"

[[objects]]
type = "disk"
center = [0, 2.2, 0]
{disk}
radius = 0.5
material = "lamp"

[[objects]]
type = "triangles"
positions = [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]]
{indices}
material = "lamp"
{tri}
transform = [ {{ rotate = {{ axis = [1, 0, 0], degrees = -90 }} }}, {{ translate = [2, 1.8, 0] }} ]

[[objects]]
type = "sphere"
center = [0, 0.5, 1]
radius = 0.5
material = "matte"

{meshes}"#
        ),
    )
}

#[test]
fn flipped_lights_are_sampled_on_the_side_they_shine_to() {
    // Next-event estimation draws flipped lights as the bounces find them,
    // and the floor is lit as by the same lights built facing down.
    let dir = scratch_dir("flip-normals-lights");
    std::fs::write(dir.join("square.obj"), SQUARE_OBJ).unwrap();
    let flipped = compile_file(&dir, "scene.toml", &lit_floor(true));
    assert_eq!(flipped.lights.len(), 8, "a quad, a disk and six triangles");
    let (path, bsdf) = path_and_bsdf(&dir, &lit_floor(true));
    assert_tiles_agree("flipped lights", &path, &bsdf);
    // The placed mesh's lights alone, which the others would hide.
    let panels = lit_floor(true).replace("material = \"lamp\"", "material = \"matte\"");
    let (alone, bounces) = path_and_bsdf(&dir, &panels);
    assert_tiles_agree("flipped lights of a placed mesh", &alone, &bounces);
    let built = pixel_stats(&compile_file(&dir, "scene.toml", &lit_floor(false)));
    for c in 0..3 {
        assert_agree(
            &format!("flipped and built facing down, channel {c}"),
            path.image(c),
            built.image(c),
        );
    }
    // Not flipped, the same lights shine up: the floor is far darker.
    let up = lit_floor(true).replace("flip_normals = true", "");
    let dark = pixel_stats(&compile_file(&dir, "scene.toml", &up));
    assert!(
        dark.image(1).0 < 0.2 * path.image(1).0,
        "{:?} vs {:?}",
        dark.image(1),
        path.image(1)
    );
}

#[test]
fn flipped_tubes_and_spheres_light_their_inside() {
    // A camera inside a one-sided tube of light, flipped to face its axis,
    // looking at a matte ball inside: the tube is sampled (path and bsdf
    // agree); a flipped sphere of light around the scene is found by the
    // bounces alone and lights it as the bounces say.
    let dir = scratch_dir("flip-normals-inside");
    let scene = |light: &str| {
        format!(
            r#"[render]
width = 24
height = 16
samples_per_pixel = 128
max_depth = 4
seed = 3

[camera]
vfov = 60
lookfrom = [0, 0, 3]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0, 0, 0]

[materials.lamp]
type = "emissive"
radiance = [1.5, 1.2, 1]

[materials.matte]
type = "diffuse"
albedo = [0.7, 0.6, 0.5]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 0.6
material = "matte"

{light}
"#
        )
    };
    let tube = scene(
        "[[objects]]\ntype = \"cylinder\"\np0 = [0, 0, -4]\np1 = [0, 0, 4]\nradius = 2\nmaterial = \"lamp\"\nflip_normals = true",
    );
    assert_eq!(compile_file(&dir, "scene.toml", &tube).lights.len(), 1);
    let (path, bsdf) = path_and_bsdf(&dir, &tube);
    // Not less noisy than the bounces here: the tube is all around.
    tiles_agree("inside a flipped tube", &path, &bsdf);
    assert!(
        path.image(0).0 > 0.2,
        "the ball is lit: {:?}",
        path.image(0)
    );
    let ball = scene(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 5\nmaterial = \"lamp\"\nflip_normals = true",
    );
    assert!(compile_file(&dir, "scene.toml", &ball).lights.is_empty());
    // Shining to both sides, it is sampled, as any sphere light.
    let both = ball.replace(
        "radiance = [1.5, 1.2, 1]",
        "radiance = [1.5, 1.2, 1]\ntwo_sided = true",
    );
    assert_eq!(compile_file(&dir, "scene.toml", &both).lights.len(), 1);
    let (path, bsdf) = path_and_bsdf(&dir, &ball);
    tiles_agree("inside a flipped sphere of light", &path, &bsdf);
    // Every direction from the (convex) ball sees the sphere of light: a
    // pixel on the ball shows a·Le.
    for (c, want) in [0.7 * 1.5, 0.6 * 1.2, 0.5 * 1.0].into_iter().enumerate() {
        for (name, stats) in [("path", &path), ("bsdf", &bsdf)] {
            let (mean, se) = stats.region(10..14, 6..10, c);
            assert!(
                (mean - want).abs() <= K * se + 1e-5,
                "{name}, channel {c}: {mean} ± {se}, expected {want}"
            );
        }
    }
}

#[test]
fn a_flipped_glass_sphere_is_a_bubble() {
    // Turned inside out, a sphere of glass of index n bends light as a
    // sphere of index 1/n: the same rays, to the bit.
    let dir = scratch_dir("flip-normals-bubble");
    let scene = |ior: f64, flip: bool| {
        common::on_dark_floor(
            23,
            "vfov = 40\nlookfrom = [0, 1.5, 5]\nlookat = [0, 0.8, 0]",
            &format!(
                r#"[materials.glass]
type = "dielectric"
ior = {ior}

[materials.lamp]
type = "emissive"
radiance = [4, 4, 4]

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "glass"
flip_normals = {flip}

[[objects]]
type = "quad"
corner = [-1, 4, -1]
u = [2, 0, 0]
v = [0, 0, 2]
material = "lamp"
"#
            ),
        )
    };
    let render = |text: &str| {
        let scene = compile_file(&dir, "scene.toml", text);
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let bubble = render(&scene(1.5, true));
    assert!(
        bubble == render(&scene(1.0 / 1.5, false)),
        "flipped n differs from 1/n"
    );
    assert!(
        bubble != render(&scene(1.5, false)),
        "flipping changed nothing"
    );
}
