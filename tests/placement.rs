//! Placed objects render consistently: a transformed box is the six quads it
//! stands for, moving the scene and the camera together changes nothing, a
//! mesh shared by instances renders as separate copies would, closed meshes
//! hold light exactly as a furnace says, and renders with meshes are
//! bit-identical across threads and passes.

mod common;

use common::{
    assert_pixels_agree, bunny_obj, compile_file, icosphere_obj, pixel_stats, render_with_threads,
    scratch_dir, K,
};
use lumen::film::Film;
use lumen::render::{render, render_samples};

type M3 = [[f64; 3]; 3];

/// The right-handed rotation by `degrees` about `axis` (Rodrigues), written
/// here independently of the library.
fn rotation(axis: [f64; 3], degrees: f64) -> M3 {
    let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let k = [axis[0] / l, axis[1] / l, axis[2] / l];
    let (s, c) = degrees.to_radians().sin_cos();
    let (s, c) = match degrees {
        90.0 => (1.0, 0.0),
        _ => (s, c),
    };
    let mut r = [[0.0; 3]; 3];
    let cross = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = if i == j { c } else { 0.0 } + s * cross[i][j] + (1.0 - c) * k[i] * k[j];
        }
    }
    r
}

fn apply(r: &M3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn triple(v: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

const HEAD: &str = r#"[render]
width = 32
height = 24
samples_per_pixel = 32
max_depth = 4
gamma = 1
seed = 7

[camera]
vfov = 50
lookfrom = [0, 1, 2]
lookat = [0, 0, -4]

[background]
type = "gradient"
bottom = [1, 1, 1]
top = [0.4, 0.6, 1]

[materials.grey]
type = "diffuse"
albedo = [0.6, 0.6, 0.6]

[materials.red]
type = "diffuse"
albedo = [0.8, 0.2, 0.1]

[[objects]]
type = "quad"
corner = [-10, -1.5, -20]
u = [20, 0, 0]
v = [0, 0, 30]
material = "grey"
"#;

/// The box from `min` to `max`, moved by x ↦ r·x + t, as six quads whose
/// corners and edges are worked out here; faces listed in an order and with
/// corners of this test's own choosing.
fn box_as_quads(min: [f64; 3], max: [f64; 3], r: &M3, t: [f64; 3]) -> String {
    let d = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
    let (dx, dy, dz) = ([d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]);
    let faces = [
        (min, dy, dx),                      // z = min
        ([min[0], min[1], max[2]], dx, dy), // z = max
        (min, dx, dz),                      // y = min
        ([min[0], max[1], min[2]], dz, dx), // y = max
        ([max[0], min[1], min[2]], dz, dy), // x = max
        (min, dy, dz),                      // x = min
    ];
    let mut text = String::new();
    for (corner, u, v) in faces {
        text += &format!(
            "\n[[objects]]\ntype = \"quad\"\ncorner = {}\nu = {}\nv = {}\nmaterial = \"red\"\n",
            triple(add(apply(r, corner), t)),
            triple(apply(r, u)),
            triple(apply(r, v))
        );
    }
    text
}

fn placed_box(min: [f64; 3], max: [f64; 3], axis: [f64; 3], degrees: f64, t: [f64; 3]) -> String {
    format!(
        "\n[[objects]]\ntype = \"box\"\nmin = {}\nmax = {}\nmaterial = \"red\"\ntransform = [{{ rotate = {{ axis = {}, degrees = {degrees:?} }} }}, {{ translate = {} }}]\n",
        triple(min),
        triple(max),
        triple(axis),
        triple(t)
    )
}

/// A quarter turn and a translation by small binary fractions are exact in
/// floating point: the placed box's quads lie in exactly the planes of the
/// quads written by hand (a quad's plane, hence every hit distance, does not
/// depend on which corner or edge order describes it), so the images are
/// bit-identical.
#[test]
fn a_box_turned_a_quarter_is_exactly_its_six_quads() {
    let dir = scratch_dir("box-exact");
    let (min, max) = ([-1.0, -0.5, -0.25], [0.5, 0.5, 0.75]);
    let t = [0.25, -0.5, -4.0];
    let r = rotation([0.0, 1.0, 0.0], 90.0);
    let a = compile_file(
        &dir,
        "box.toml",
        &(HEAD.to_string() + &placed_box(min, max, [0.0, 1.0, 0.0], 90.0, t)),
    );
    let b = compile_file(
        &dir,
        "quads.toml",
        &(HEAD.to_string() + &box_as_quads(min, max, &r, t)),
    );
    let (fa, sa) = render(&a, &|_| {});
    let (fb, sb) = render(&b, &|_| {});
    let red = fa.linear().iter().filter(|c| c.x > 2.0 * c.y).count();
    assert!(red > 20, "the box covers only {red} pixels");
    assert_eq!(sa, sb);
    assert!(fa == fb, "the placed box differs from its six quads");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A general rotation rounds differently from the quads computed here in
/// f64: the images agree within the estimator's noise, and almost every
/// pixel is identical or nearly so since both use the same seed.
#[test]
fn a_box_turned_at_any_angle_matches_its_six_quads_within_noise() {
    let dir = scratch_dir("box-any");
    let (min, max) = ([-1.0, -0.5, -0.25], [0.5, 0.5, 0.75]);
    let (axis, degrees, t) = ([1.0, 2.0, 3.0], 33.0, [0.2, -0.3, -4.0]);
    let r = rotation(axis, degrees);
    let a = compile_file(
        &dir,
        "box.toml",
        &(HEAD.to_string() + &placed_box(min, max, axis, degrees, t)),
    );
    let b = compile_file(
        &dir,
        "quads.toml",
        &(HEAD.to_string() + &box_as_quads(min, max, &r, t)),
    );
    let (pa, pb) = (pixel_stats(&a), pixel_stats(&b));
    let (worst, noisy) = assert_pixels_agree("box vs quads", &pa, &pb, K);
    let close = pa
        .mean
        .iter()
        .zip(&pb.mean)
        .filter(|(x, y)| (0..3).all(|c| (x[c] - y[c]).abs() <= 1e-4))
        .count();
    eprintln!("box vs quads: worst {worst:.2} standard errors over {noisy} pixel channels; {close} of {} pixels within 1e-4", pa.mean.len());
    assert!(
        close * 10 >= pa.mean.len() * 9,
        "only {close} pixels nearly identical"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Moving every object by a rigid T and the camera by the same T shows the
/// same picture. The background is uniform (a gradient would turn with the
/// camera but not with T) and materials are diffuse, whose bounces do not
/// depend on the frame in distribution, so the per-pixel means agree within
/// noise.
#[test]
fn moving_the_scene_and_the_camera_together_changes_nothing() {
    let dir = scratch_dir("move-both");
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    let (axis, degrees, shift) = ([1.0, 1.0, 0.0], 40.0, [3.0, -2.0, 5.0]);
    let r = rotation(axis, degrees);
    let t = |p: [f64; 3]| add(apply(&r, p), shift);
    let scene = |moved: bool| {
        let (from, at, up) = ([0.0, 1.0, 2.0], [0.0, 0.0, -4.0], [0.0, 1.0, 0.0]);
        let (from, at, up) = if moved {
            (t(from), t(at), apply(&r, up))
        } else {
            (from, at, up)
        };
        let step = if moved {
            format!(
                ", {{ rotate = {{ axis = {}, degrees = {degrees:?} }} }}, {{ translate = {} }}",
                triple(axis),
                triple(shift)
            )
        } else {
            String::new()
        };
        format!(
            r#"[render]
width = 32
height = 24
samples_per_pixel = 48
max_depth = 4
gamma = 1
seed = 7

[camera]
vfov = 50
lookfrom = {from}
lookat = {at}
vup = {up}

[background]
type = "solid"
color = [1, 0.9, 0.8]

[materials.grey]
type = "diffuse"
albedo = [0.6, 0.6, 0.6]

[materials.red]
type = "diffuse"
albedo = [0.8, 0.2, 0.1]

[[objects]]
type = "quad"
corner = [-10, -1.5, -20]
u = [20, 0, 0]
v = [0, 0, 30]
material = "grey"
transform = [{{ scale = 1 }}{step}]

[[objects]]
type = "box"
min = [-1.5, -1.5, -5]
max = [-0.5, -0.5, -4]
material = "red"
transform = [{{ rotate = {{ axis = [0, 1, 0], degrees = 20 }} }}{step}]

[[objects]]
type = "sphere"
center = [1.2, -0.9, -4]
radius = 0.6
material = "grey"
transform = [{{ scale = 1 }}{step}]

[[objects]]
type = "mesh"
file = "bunny.obj"
material = "red"
transform = [{{ scale = 0.15 }}, {{ translate = [0, -1.5, -5] }}{step}]
"#,
            from = triple(from),
            at = triple(at),
            up = triple(up),
        )
    };
    let still = compile_file(&dir, "still.toml", &scene(false));
    let moved = compile_file(&dir, "moved.toml", &scene(true));
    let (a, b) = (pixel_stats(&still), pixel_stats(&moved));
    let (worst, noisy) = assert_pixels_agree("moved vs still", &a, &b, K);
    eprintln!("moved vs still: worst {worst:.2} standard errors over {noisy} pixel channels");
    assert!(
        noisy > 1000,
        "too few noisy pixels ({noisy}) for the comparison to mean much"
    );
    // Not a flat image: the objects are in view.
    let distinct = a.mean.iter().filter(|m| (m[0] - 1.0).abs() > 0.05).count();
    assert!(distinct > 300, "only {distinct} pixels show an object");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn two_bunnies(first: &str, second: &str) -> String {
    format!(
        "{HEAD}\n[[objects]]\ntype = \"mesh\"\nfile = \"{first}\"\nmaterial = \"red\"\ntransform = [{{ scale = 0.15 }}, {{ rotate = {{ axis = [0, 1, 0], degrees = 30 }} }}, {{ translate = [-0.8, -1.5, -4] }}]\n\n[[objects]]\ntype = \"mesh\"\nfile = \"{second}\"\nmaterial = \"red\"\ntransform = [{{ scale = [0.1, 0.2, 0.1] }}, {{ rotate = {{ axis = [1, 0, 1], degrees = -15 }} }}, {{ translate = [0.9, -1.2, -5] }}]\n"
    )
}

/// A mesh file placed twice is stored once and drawn through instances (its
/// rays transformed into the mesh's space); two copies of the file are
/// placed in world space. Rounding differs, so the images agree within
/// noise, not bit for bit.
#[test]
fn a_mesh_shared_by_instances_renders_like_two_copies() {
    let dir = scratch_dir("instances");
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    std::fs::copy(bunny_obj(), dir.join("copy.obj")).unwrap();
    let shared = compile_file(&dir, "shared.toml", &two_bunnies("bunny.obj", "bunny.obj"));
    let copies = compile_file(&dir, "copies.toml", &two_bunnies("bunny.obj", "copy.obj"));
    assert_eq!(shared.stats.instances, 2);
    assert_eq!(shared.stats.triangles, 3674);
    assert_eq!(shared.stats.placed_triangles, 2 * 3674);
    assert_eq!(copies.stats.instances, 0);
    assert_eq!(copies.stats.triangles, 2 * 3674);
    let (a, b) = (pixel_stats(&shared), pixel_stats(&copies));
    let (worst, noisy) = assert_pixels_agree("instances vs copies", &a, &b, K);
    eprintln!("instances vs copies: worst {worst:.2} standard errors over {noisy} pixel channels");
    let red = a
        .mean
        .iter()
        .filter(|m| m[0] > 2.0 * m[1] && m[0] > 0.05)
        .count();
    assert!(red > 20, "the red bunnies cover only {red} pixels");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A closed furnace: the camera inside a closed mesh of diffuse albedo a
/// under a white sky. Lumen has no emitters, so every path that stays inside
/// carries a^k for D segments and then, cut at the depth limit, nothing: the
/// series of the enclosure's radiance has no source term and every sample is
/// exactly 0, and every path is exactly D segments long. A single ray that
/// slipped out between triangles, or a bounce that started on the wrong
/// side, would bring back white light (a^k > 0) and end a path early.
///
/// The notes' estimator (`bsdf`): the `path` integrator would also aim
/// shadow rays at the sky, which never reach it from inside.
///
/// With an epsilon (the books' 0.001, and a tiny one) and without: at the
/// inside of a crease the neighbouring triangle is nearer than 0.001 to
/// points along the shared edge, and ignoring it there let about 10⁻⁴ of
/// the bounces out through it (36 of 393,216 segments in the bunny).
#[test]
fn inside_a_closed_mesh_no_light_gets_in() {
    let dir = scratch_dir("inside");
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    std::fs::write(dir.join("smooth.obj"), icosphere_obj(3, 1.0, Some(1.0))).unwrap();
    let depth: u32 = 6;
    for (file, transform, from) in [
        ("bunny.obj", "[{ scale = 2 }]", [-1.0, 6.0, 1.0]),
        (
            "smooth.obj",
            "[{ scale = [3, 2, 2.5] }, { rotate = { axis = [1, 0, 0], degrees = 30 } }]",
            [0.3, 0.2, -0.4],
        ),
    ] {
        for epsilon in ["epsilon = 0.001\n", "epsilon = 1e-7\n", ""] {
            let text = format!(
                "[render]\nwidth = 32\nheight = 24\nsamples_per_pixel = 32\nmax_depth = {depth}\ngamma = 1\n{epsilon}integrator = \"bsdf\"\n\n[camera]\nvfov = 120\nlookfrom = {}\nlookat = {}\n\n[background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\n[materials.m]\ntype = \"diffuse\"\nalbedo = [0.7, 0.7, 0.7]\n\n[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"m\"\ntransform = {transform}\n",
                triple(from),
                triple(add(from, [0.0, -0.2, -1.0]))
            );
            let scene = compile_file(&dir, "inside.toml", &text);
            let (film, stats) = render(&scene, &|_| {});
            assert_eq!(
                stats.rays,
                stats.samples * u64::from(depth),
                "{file}, {}: {} of {} paths ended before the depth limit",
                epsilon.trim(),
                stats.samples * u64::from(depth) - stats.rays,
                stats.samples
            );
            let lit = film
                .linear()
                .iter()
                .filter(|c| c.max_element() > 0.0)
                .count();
            assert_eq!(
                lit,
                0,
                "{file}, {}: light got in at {lit} pixels",
                epsilon.trim()
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The OBJ of the cube from −2 to 2 on every axis, two triangles a face,
/// counter-clockwise seen from outside: a closed mesh.
const CUBE_OBJ: &str = "v -2 -2 -2\nv 2 -2 -2\nv 2 2 -2\nv -2 2 -2\nv -2 -2 2\nv 2 -2 2\nv 2 2 2\nv -2 2 2\n\
f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

/// A closed room: the camera inside a box of white (albedo 1) walls under a
/// white sky, whose every sample is exactly 0 (as in
/// `inside_a_closed_mesh_no_light_gets_in`): nothing inside emits, so a lit
/// sample is light that came through a wall. The room is six quads (a
/// `box`, axis-aligned and turned) or a closed OBJ cube, with the books'
/// epsilon of 0.001 and with none. With the epsilon, a bounce leaving a
/// wall near a corner meets the next wall closer than 0.001; counted as no
/// hit, the ray went out through that wall, and about 1.4·10⁻⁴ of the
/// bounces of this 4-unit room left it that way (0.7% of the samples lit at
/// depth 50). The `path` integrator also samples the sky (shadow rays),
/// which must find the walls in the way just as bounces do.
#[test]
fn a_closed_room_lets_no_light_in() {
    let dir = scratch_dir("room");
    std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
    let depth: u32 = 50;
    let rooms = [
        ("box", "type = \"box\"\nmin = [-2, -2, -2]\nmax = [2, 2, 2]\n"),
        ("turned box", "type = \"box\"\nmin = [-2, -2, -2]\nmax = [2, 2, 2]\ntransform = [{ rotate = { axis = [1, 2, 3], degrees = 40 } }, { translate = [0.3, -0.2, 0.1] }]\n"),
        ("cube.obj", "type = \"mesh\"\nfile = \"cube.obj\"\n"),
    ];
    let mut leaks = Vec::new();
    for (room, object) in rooms {
        for epsilon in ["epsilon = 0.001\n", ""] {
            for integrator in ["bsdf", "path"] {
                let text = format!(
                    "[render]\nwidth = 32\nheight = 32\nsamples_per_pixel = 32\nmax_depth = {depth}\ngamma = 1\n{epsilon}integrator = \"{integrator}\"\nsample_background = true\n\n[camera]\nvfov = 100\nlookfrom = [0.1, 0.2, 0.3]\nlookat = [0, 0, -1]\n\n[background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\n[materials.white]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\n[[objects]]\n{object}material = \"white\"\n"
                );
                let scene = compile_file(&dir, "room.toml", &text);
                let (film, stats) = render(&scene, &|_| {});
                let pixels = film.linear();
                let lit = pixels.iter().filter(|c| c.max_element() > 0.0).count();
                let mean = pixels
                    .iter()
                    .map(|c| f64::from(c.max_element()))
                    .sum::<f64>()
                    / pixels.len() as f64;
                // With `bsdf` every path bounces until the depth limit.
                let short = match integrator {
                    "bsdf" => stats.samples * u64::from(depth) - stats.rays,
                    _ => 0,
                };
                if lit > 0 || short > 0 {
                    leaks.push(format!(
                        "{room}, {}{integrator}: light got in at {lit} pixels (mean {mean:.2e}), {short} segments missing",
                        epsilon.replace('\n', ", ")
                    ));
                }
            }
        }
    }
    assert!(leaks.is_empty(), "{}", leaks.join("\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The rooms of [`rays_aimed_at_the_edges_of_a_room_meet_a_wall`] and
/// [`a_bounce_from_the_edge_of_a_wall_meets_the_next_wall`], each compiled
/// with the books' epsilon and with none: what they are, and the rotation
/// and translation that place the box from −2 to 2. Axis-aligned and
/// turned, near the origin and 1000 units from it, as six quads, as a mesh
/// in the world and as a mesh placed by an instance (the file placed a
/// second time elsewhere).
fn rooms(dir: &std::path::Path) -> Vec<(String, lumen::scene::Scene, M3, [f64; 3])> {
    std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
    let (axis, degrees) = ([1.0, 2.0, 3.0], 40.0);
    let turn = |shift: [f64; 3]| {
        format!(
            "transform = [{{ rotate = {{ axis = {}, degrees = {degrees:?} }} }}, {{ translate = {} }}]\n",
            triple(axis),
            triple(shift)
        )
    };
    let (near, far) = ([0.3, -0.2, 0.1], [1000.3, -0.2, 0.1]);
    let again = "\n[[objects]]\ntype = \"mesh\"\nfile = \"cube.obj\"\nmaterial = \"white\"\ntransform = [{ translate = [-1000, 0, 0] }]\n";
    let box_ = "type = \"box\"\nmin = [-2, -2, -2]\nmax = [2, 2, 2]\n";
    let cube = "type = \"mesh\"\nfile = \"cube.obj\"\n";
    let still = (rotation([0.0, 0.0, 1.0], 0.0), [0.0; 3]);
    let (turned, turned_far) = (
        (rotation(axis, degrees), near),
        (rotation(axis, degrees), far),
    );
    let kinds = [
        ("box", box_.to_string(), "", still),
        ("turned box", format!("{box_}{}", turn(near)), "", turned),
        (
            "far turned box",
            format!("{box_}{}", turn(far)),
            "",
            turned_far,
        ),
        ("cube.obj", cube.to_string(), "", still),
        (
            "turned cube.obj",
            format!("{cube}{}", turn(near)),
            "",
            turned,
        ),
        (
            "instanced cube.obj",
            format!("{cube}{}", turn(near)),
            again,
            turned,
        ),
        (
            "far instanced cube.obj",
            format!("{cube}{}", turn(far)),
            again,
            turned_far,
        ),
    ];
    let mut rooms = Vec::new();
    for (kind, object, more, (r, t)) in kinds {
        for epsilon in ["epsilon = 0.001\n", ""] {
            let text = format!(
                "[render]\nwidth = 8\nheight = 8\n{epsilon}\n[materials.white]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\n[[objects]]\n{object}material = \"white\"\n{more}"
            );
            let scene = compile_file(dir, "room.toml", &text);
            let epsilon = if epsilon.is_empty() {
                "no epsilon"
            } else {
                epsilon.trim()
            };
            rooms.push((format!("{kind}, {epsilon}"), scene, r, t));
        }
    }
    rooms
}

fn vec3(v: [f64; 3]) -> lumen::math::Vec3 {
    lumen::math::Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// Rays from a point inside a room placed by `r` and `t` aimed at points 0
/// to 4 steps of 1e-7 in from both walls along each of its twelve edges,
/// each with the outward normals of the two walls there.
fn rays_at_edges(r: &M3, t: [f64; 3]) -> Vec<(lumen::ray::Ray, [lumen::math::Vec3; 2])> {
    let axes: [[f64; 3]; 6] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let origin = vec3(add(apply(r, [0.1, 0.2, 0.3]), t));
    let mut rays = Vec::new();
    for (i, n1) in axes.iter().enumerate() {
        for n2 in &axes[i + 1..] {
            let dot: f64 = (0..3).map(|k| n1[k] * n2[k]).sum();
            if dot != 0.0 {
                continue;
            }
            let along = [
                n1[1] * n2[2] - n1[2] * n2[1],
                n1[2] * n2[0] - n1[0] * n2[2],
                n1[0] * n2[1] - n1[1] * n2[0],
            ];
            for k in 0..50 {
                let s = -1.9 + 3.8 * f64::from(k) / 50.0;
                for step in 0..25 {
                    let (d1, d2) = (f64::from(step % 5) * 1e-7, f64::from(step / 5) * 1e-7);
                    let p: [f64; 3] = std::array::from_fn(|c| {
                        2.0 * (n1[c] + n2[c]) + s * along[c] - d1 * n1[c] - d2 * n2[c]
                    });
                    let target = vec3(add(apply(r, p), t));
                    let ray = lumen::ray::Ray::new(origin, (target - origin).normalize());
                    rays.push((ray, [vec3(apply(r, *n1)), vec3(apply(r, *n2))]));
                }
            }
        }
    }
    rays
}

/// Rays from inside the rooms of [`rooms`] aimed within a few rounding
/// steps of the edges all meet a wall. The faces of a turned box are
/// placed each with its own rounding, so that two that share an edge in
/// the scene meet only to within it, and rays passed between
/// them (802 of these 15,000 rays went out).
#[test]
fn rays_aimed_at_the_edges_of_a_room_meet_a_wall() {
    let dir = scratch_dir("edges-aimed");
    let mut escapes = Vec::new();
    for (room, scene, r, t) in rooms(&dir) {
        let rays = rays_at_edges(&r, t);
        let out = rays
            .iter()
            .filter(|(ray, _)| scene.intersect_leaving(ray, None, f32::INFINITY).is_none())
            .count();
        if out > 0 {
            escapes.push(format!("{room}: {out} of {} rays went out", rays.len()));
        }
    }
    assert!(escapes.is_empty(), "{}", escapes.join("\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Rays from inside the rooms of [`rooms`] hit a wall within a few
/// rounding steps of an edge, and each bounces at 45° towards the other
/// wall there, which it must meet at once. A hit point rounded onto the
/// plane of that wall (or past it) let the bounce start there, and the
/// wall, met at distance 0 or behind, did not count: a fifth to a half of
/// these bounces went out (and half in the room far from the origin placed
/// by an instance, while the point was kept inside only by the rounding
/// of the object's own space).
#[test]
fn a_bounce_from_the_edge_of_a_wall_meets_the_next_wall() {
    let dir = scratch_dir("edges-bounce");
    let mut escapes = Vec::new();
    for (room, scene, r, t) in rooms(&dir) {
        let rays = rays_at_edges(&r, t);
        let mut out = 0;
        for (ray, walls) in &rays {
            let hit = scene
                .intersect_leaving(ray, None, f32::INFINITY)
                .expect("a ray from inside meets a wall");
            let record = scene.record(ray, hit);
            let outward = record.outward_normal();
            let other = if outward.dot(walls[0]) > outward.dot(walls[1]) {
                walls[1]
            } else {
                walls[0]
            };
            let d = (other - outward).normalize();
            let bounce = lumen::ray::Ray::new(record.spawn_origin(d), d);
            if scene
                .intersect_leaving(&bounce, Some(&hit), f32::INFINITY)
                .is_none()
            {
                out += 1;
            }
        }
        if out > 0 {
            escapes.push(format!("{room}: {out} of {} bounces went out", rays.len()));
        }
    }
    assert!(escapes.is_empty(), "{}", escapes.join("\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A white furnace around a convex closed mesh (the notes' estimator, whose
/// every sample is exact here): a camera ray that hits it
/// bounces once (one factor of the albedo a) and the bounce, leaving above
/// the surface, escapes to the white sky; one that misses sees the sky. So
/// every sample is exactly a or 1 (depth D ≥ 2; a path stopped at D = 1 on
/// the mesh is 0), the estimator has no variance where the mesh fills a
/// pixel, and no path is longer than two segments. With smooth shading the
/// bounce is drawn around the interpolated normal and mirrored above the
/// true surface when it points below it; normals written pointing inwards
/// must be turned outwards. Energy is conserved: no black and no
/// over-bright sample, placed once or through instances.
#[test]
fn a_convex_mesh_in_a_white_furnace_returns_its_albedo_exactly() {
    let dir = scratch_dir("furnace");
    std::fs::write(dir.join("flat.obj"), icosphere_obj(2, 1.0, None)).unwrap();
    std::fs::write(dir.join("smooth.obj"), icosphere_obj(2, 1.0, Some(1.0))).unwrap();
    std::fs::write(dir.join("inverted.obj"), icosphere_obj(2, 1.0, Some(-1.0))).unwrap();
    let a = 0.7f64;
    let a32 = f64::from(a as f32);
    for file in ["flat.obj", "smooth.obj", "inverted.obj"] {
        for instanced in [false, true] {
            for depth in [1u32, 2, 50] {
                // Instanced: a second placement, tiny and far away, so that
                // no bounce can meet it.
                let second = if instanced {
                    format!("\n[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"m\"\ntransform = [{{ scale = 0.001 }}, {{ translate = [0, 0, 1000] }}]\n")
                } else {
                    String::new()
                };
                let text = format!(
                    "[render]\nwidth = 24\nheight = 24\nsamples_per_pixel = 16\nmax_depth = {depth}\ngamma = 1\nintegrator = \"bsdf\"\n\n[camera]\nvfov = 60\nlookfrom = [0, 0, 0]\nlookat = [0, 0, -1]\n\n[background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\n[materials.m]\ntype = \"diffuse\"\nalbedo = [{a}, {a}, {a}]\n\n[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"m\"\ntransform = [{{ scale = [1.2, 1, 1.1] }}, {{ rotate = {{ axis = [1, 2, 3], degrees = 70 }} }}, {{ translate = [0, 0, -3] }}]\n{second}"
                );
                let scene = compile_file(&dir, "furnace.toml", &text);
                assert_eq!(scene.stats.instances, if instanced { 2 } else { 0 });
                let s = pixel_stats(&scene);
                let what = format!("{file}, instanced {instanced}, depth {depth}");
                let hit = if depth == 1 { 0.0 } else { a32 };
                for c in 0..3 {
                    assert_eq!(s.min[c], hit, "{what}: darkest sample");
                    assert_eq!(s.max[c], 1.0, "{what}: brightest sample");
                }
                // The centre pixel sees only the mesh: exactly `hit`.
                assert_eq!(s.pixel(12, 12), [hit; 3], "{what}");
                // Every sample is a or 1: each pixel's mean is a mix of them
                // with a whole number of hits.
                for (i, m) in s.mean.iter().enumerate() {
                    let hits = (1.0 - m[0]) / (1.0 - hit) * f64::from(s.counts[i]);
                    assert!(
                        (hits - hits.round()).abs() < 1e-3,
                        "{what}: pixel {i} mean {m:?}"
                    );
                }
                let segments = s.stats.rays as f64 / s.stats.samples as f64;
                let most = if depth == 1 { 1.0 } else { 2.0 };
                assert!(segments <= most, "{what}: {segments} segments a path");
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene with every kind: a mesh placed once, a mesh shared by two
/// instances, an ellipsoid (an instanced sphere), quads, a box and spheres.
fn mixed_scene(dir: &std::path::Path) -> lumen::scene::Scene {
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    std::fs::write(dir.join("ball.obj"), icosphere_obj(2, 0.4, Some(1.0))).unwrap();
    let text = format!(
        "{HEAD}\n[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n\n[materials.metal]\ntype = \"metal\"\nalbedo = [0.9, 0.8, 0.7]\nfuzz = 0.2\n\n\
[[objects]]\ntype = \"mesh\"\nfile = \"bunny.obj\"\nmaterial = \"grey\"\ntransform = [{{ scale = 0.15 }}, {{ translate = [0, -1.5, -5] }}]\n\n\
[[objects]]\ntype = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"metal\"\ntransform = [{{ translate = [-1, -0.8, -3.5] }}]\n\n\
[[objects]]\ntype = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"metal\"\ntransform = [{{ scale = [1, 1.5, 1] }}, {{ translate = [1.2, -0.8, -3.8] }}]\n\n\
[[objects]]\ntype = \"box\"\nmin = [-0.3, -0.3, -0.3]\nmax = [0.3, 0.3, 0.3]\nmaterial = \"red\"\ntransform = [{{ rotate = {{ axis = [1, 1, 1], degrees = 25 }} }}, {{ translate = [0.3, 0.4, -4.5] }}]\n\n\
[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.3\nmaterial = \"metal\"\ntransform = [{{ scale = [2, 1, 1] }}, {{ translate = [-1.2, 0.6, -5] }}]\n\n\
[[objects]]\ntype = \"sphere\"\ncenter = [1.5, 0.5, -5]\nradius = 0.4\nmaterial = \"glass\"\n"
    );
    let scene = compile_file(dir, "mixed.toml", &text);
    assert_eq!(scene.stats.instances, 3, "two of the ball, one ellipsoid");
    scene
}

#[test]
fn renders_with_meshes_are_bit_identical_across_threads_and_passes() {
    let dir = scratch_dir("mixed");
    let scene = mixed_scene(&dir);
    let (one, stats) = render_with_threads(&scene, 1);
    assert!(
        one.linear().iter().any(|c| *c != one.pixel(0, 0)),
        "flat image"
    );
    let (two, stats2) = render_with_threads(&scene, 2);
    assert!(one == two, "2 threads differ from 1");
    assert_eq!(stats, stats2);
    let spp = scene.settings.samples_per_pixel;
    for split in [1, 5, 17] {
        let mut film = Film::new(scene.settings.width, scene.settings.height);
        let mut passes = render_samples(&scene, &mut film, 0..split, &|_| {});
        passes.add(render_samples(&scene, &mut film, split..spp, &|_| {}));
        assert!(
            film == one,
            "0..{split} then {split}..{spp} differs from 0..{spp}"
        );
        assert_eq!(passes, stats);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The bunny read from a binary PLY file (written here from the OBJ's
/// vertices and faces) renders bit for bit as the bunny read from the OBJ.
#[test]
fn a_mesh_renders_the_same_from_obj_and_ply() {
    let dir = scratch_dir("ply");
    let model = lumen::mesh::load(&bunny_obj()).unwrap();
    let mesh = &model.meshes[0];
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    for p in &mesh.positions {
        p.iter().for_each(|c| ply.extend(c.to_le_bytes()));
    }
    for t in &mesh.triangles {
        ply.push(3);
        t.iter().for_each(|&i| ply.extend((i as i32).to_le_bytes()));
    }
    std::fs::write(dir.join("bunny.ply"), ply).unwrap();
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    let film = |file: &str| {
        let text = format!(
            "{HEAD}\n[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"red\"\n\
             transform = [{{ scale = 0.15 }}, {{ translate = [0, -1.5, -4] }}]\n"
        );
        let scene = compile_file(&dir, "scene.toml", &text);
        assert_eq!(scene.stats.triangles, 3674, "{file}");
        render(&scene, &|_| {}).0
    };
    let (obj, ply) = (film("bunny.obj"), film("bunny.ply"));
    assert!(
        obj.linear().iter().any(|c| c.x > 2.0 * c.y),
        "the bunny is not in view"
    );
    assert!(obj == ply, "the PLY bunny renders differently");
    std::fs::remove_dir_all(&dir).unwrap();
}
