//! Scenes at any scale with the default settings: no shadow acne on a
//! model in micrometres or in thousands of kilometres, far from the origin
//! or at it, and no light leaking through walls thinner than the notes'
//! epsilon of 0.001.

mod common;

use common::{compile_file, icosphere_obj, pixel_stats, scratch_dir};

/// A grey convex ball (albedo 0.5) under a white sky reflects exactly 0.5
/// on every path with the notes' estimator: each bounce leaves it for the
/// sky. A path that hits the ball it leaves (acne) brings back 0.25 or
/// less. At scale `s` (radius `s`, centred `offset` radii from the origin),
/// as a sphere and as a flat-shaded icosphere mesh, every sample that hits
/// the ball must be 0.5 — with no epsilon given.
#[test]
fn a_ball_at_any_scale_and_place_has_no_acne() {
    let dir = scratch_dir("scale-acne");
    std::fs::write(dir.join("ball.obj"), icosphere_obj(3, 1.0, None)).unwrap();
    for scale in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for offset in [0.0, 1000.0] {
            let c = offset * scale;
            let camera =
                |z: f64| format!("lookfrom = [{c}, {c}, {}]\nlookat = [{c}, {c}, {c}]", c + z);
            for object in [
                format!("type = \"sphere\"\ncenter = [{c}, {c}, {c}]\nradius = {scale}"),
                format!(
                    "type = \"mesh\"\nfile = \"ball.obj\"\nsmooth = false\n\
                     transform = [{{ scale = {scale} }}, {{ translate = [{c}, {c}, {c}] }}]"
                ),
            ] {
                let scene = compile_file(
                    &dir,
                    "s.toml",
                    &format!(
                        r#"
[render]
width = 16
height = 16
samples_per_pixel = 8
max_depth = 8
integrator = "bsdf"
gamma = 1

[camera]
vfov = 0.8
{}

[background]
type = "solid"
color = [1, 1, 1]

[materials.grey]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[objects]]
{object}
material = "grey"
"#,
                        // Far away, as cameras often are: the rounding of
                        // a hit point grows with the ray's length.
                        camera(200.0 * scale)
                    ),
                );
                let stats = pixel_stats(&scene);
                // Every sample is 1 (sky) or 0.5 (the ball, once): a pixel
                // below 0.5 held a path that met the ball twice.
                let darkest = stats.min[0];
                assert!(
                    darkest >= 0.5 - 1e-6,
                    "scale {scale}, {offset} radii out, {}: a sample of {darkest}",
                    object.lines().next().unwrap()
                );
                assert!(stats.mean.iter().any(|p| p[0] < 0.99), "the ball is seen");
            }
        }
    }
}

/// A camera inside a closed box of side 2 mm (six quads, walls of no
/// thickness) under a white sky sees black: no ray slips through a
/// wall it starts next to or meets within 0.001.
#[test]
fn a_millimetre_box_does_not_leak() {
    let dir = scratch_dir("scale-leak");
    let scene = compile_file(
        &dir,
        "box.toml",
        r#"
[render]
width = 16
height = 16
samples_per_pixel = 8
max_depth = 8
integrator = "path"

[camera]
vfov = 90
lookfrom = [0.0003, 0.0002, 0.0001]
lookat = [0.0003, 0.0002, -1]

[background]
type = "solid"
color = [1, 1, 1]

[materials.wall]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[[objects]]
type = "box"
min = [-0.001, -0.001, -0.001]
max = [0.001, 0.001, 0.001]
material = "wall"
"#,
    );
    let stats = pixel_stats(&scene);
    assert_eq!(stats.max, [0.0; 3], "light leaked in");
}
