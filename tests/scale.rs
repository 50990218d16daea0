//! Scenes at any scale with the default settings: no shadow acne on a
//! model in micrometres or in thousands of kilometres, far from the origin
//! or at it, and no light leaking through walls thinner than the notes'
//! epsilon of 0.001.

mod common;

use common::d3::{cross, dot, sub, D3};
use common::{compile_file, icosphere_obj, pixel_stats, scene_file, scratch_dir};
use lumen::scene::Overrides;

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

/// SplitMix64, for the rays of the tests below.
struct Rng(u64);

impl Rng {
    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `v` rounded to f32, as the scene holds it.
fn f32s(v: D3) -> D3 {
    v.map(|x| f64::from(x as f32))
}

/// A square floor of half-size `size` seen from 0.1 to 3 units above its
/// middle, far larger than the distances it is seen at: two triangles of a
/// mesh and a quad, flat (up to 1e17) or turned about (1, 2, 3) by 30° (up
/// to 1e10; its corners written in the files, rounded to f32 as the scene
/// holds them, and the rays start above the true plane through them).
/// Every ray that meets a plane of the floor hits it there, to within
/// 10⁻⁵ of the ray's origin and length. The triangle test's distance is a
/// mean of its vertices' distances, each rounded to their size, and the hit
/// point was rebuilt from the vertices: flat, 36% of these rays missed the
/// mesh of 1e8 and the rest hit it off the floor (62% missed at 1e9 and at
/// 1e10), and even at 1e4 nearly all hit it off; the turned quad's plane
/// was as far off, and a quad of edges 2e10, whose |u × v|² overflows f32,
/// was refused as having parallel edges.
#[test]
fn floors_far_larger_than_the_view_are_hit_where_the_rays_meet_them() {
    let dir = scratch_dir("scale-floors");
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let k = [1.0 / 14f64.sqrt(), 2.0 / 14f64.sqrt(), 3.0 / 14f64.sqrt()];
    // Rodrigues' rotation about k by 30°.
    let turn = |v: D3| -> D3 {
        let kv = cross(k, v);
        let kd = dot(k, v);
        std::array::from_fn(|i| v[i] * c + kv[i] * s + k[i] * kd * (1.0 - c))
    };
    let mut failures = Vec::new();
    // Turned, double precision runs out about 1e12 (2⁻⁵³ of the size).
    let sizes = [1e4, 1e8, 1e9, 1e10, 1e17];
    for size in sizes {
        for turned in [false, true].into_iter().filter(|&t| !t || size <= 1e10) {
            let place = |v: D3| f32s(if turned { turn(v) } else { v });
            let corners = [
                [-1.0, 0.0, -1.0],
                [1.0, 0.0, -1.0],
                [1.0, 0.0, 1.0],
                [-1.0, 0.0, 1.0],
            ]
            .map(|p: D3| place(p.map(|x| x * size)));
            let obj: String = corners
                .iter()
                .map(|p| format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]))
                .collect::<String>()
                + "f 1 4 3\nf 1 3 2\n";
            std::fs::write(dir.join("floor.obj"), obj).unwrap();
            let (q, u, v) = (
                corners[0],
                place([0.0, 0.0, 2.0 * size]),
                place([2.0 * size, 0.0, 0.0]),
            );
            let triple = |p: D3| format!("[{:?}, {:?}, {:?}]", p[0], p[1], p[2]);
            let head = "[render]\nwidth = 8\nheight = 8\n\n[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n[[objects]]\n";
            // The planes each holds: the mesh's two triangles, the quad's.
            let mesh_planes = [
                [corners[0], corners[3], corners[2]],
                [corners[0], corners[2], corners[1]],
            ]
            .map(|[a, b, c]| (a, cross(sub(b, a), sub(c, a))))
            .to_vec();
            let quad_plane = vec![(q, cross(u, v))];
            for (what, object, planes) in [
                (
                    "mesh",
                    "type = \"mesh\"\nfile = \"floor.obj\"\nmaterial = \"m\"\n".to_string(),
                    mesh_planes,
                ),
                (
                    "quad",
                    format!(
                        "type = \"quad\"\ncorner = {}\nu = {}\nv = {}\nmaterial = \"m\"\n",
                        triple(q),
                        triple(u),
                        triple(v)
                    ),
                    quad_plane,
                ),
            ] {
                let scene = match scene_file(&dir, "floor.toml", &format!("{head}{object}"))
                    .compile(&Overrides::default())
                {
                    Ok(scene) => scene,
                    Err(e) => {
                        failures.push(format!("{what} of half-size {size:e}: refused: {e}"));
                        continue;
                    }
                };
                // Rounded to f32, the corners of a turned floor lie off the
                // plane through the origin by their rounding (some 1000 at
                // 1e10): the rays start above the point of the floor's
                // plane nearest the origin.
                let (a, n) = planes[0];
                let middle = n.map(|x| x * dot(n, a) / dot(n, n));
                let mut rng = Rng(7);
                let (mut missed, mut off) = (0, 0);
                let rays = 2000;
                for _ in 0..rays {
                    let local = [
                        rng.next() * 10.0 - 5.0,
                        0.1 + rng.next() * 2.9,
                        rng.next() * 10.0 - 5.0,
                    ];
                    let offset = if turned { turn(local) } else { local };
                    let o = f32s(std::array::from_fn(|i| middle[i] + offset[i]));
                    let d = [
                        rng.next() * 2.0 - 1.0,
                        -0.05 - rng.next(),
                        rng.next() * 2.0 - 1.0,
                    ];
                    let d = place(d.map(|x| x / dot(d, d).sqrt()));
                    let ray = lumen::ray::Ray::new(
                        lumen::math::Vec3::new(o[0] as f32, o[1] as f32, o[2] as f32),
                        lumen::math::Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32),
                    );
                    let Some(hit) = scene.hit(&ray, lumen::math::Interval::new(0.0, f32::INFINITY))
                    else {
                        missed += 1;
                        continue;
                    };
                    // The nearest of the planes where the ray meets them.
                    let error = planes
                        .iter()
                        .map(|(a, n)| {
                            let t = dot(*n, sub(*a, o)) / dot(*n, d);
                            let p: D3 = std::array::from_fn(|i| o[i] + t * d[i]);
                            let got = [hit.point.x, hit.point.y, hit.point.z].map(f64::from);
                            let miss = sub(got, p);
                            let scale = o[0].abs().max(o[1].abs()).max(o[2].abs()) + t;
                            dot(miss, miss).sqrt().max((f64::from(hit.t) - t).abs()) / scale
                        })
                        .fold(f64::INFINITY, f64::min);
                    // NaN counts as off the floor.
                    if error.is_nan() || error > 1e-5 {
                        off += 1;
                    }
                }
                if missed + off > 0 {
                    failures.push(format!(
                        "{what} of half-size {size:e}, turned {turned}: {missed} of {rays} rays missed, {off} hit off the floor"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}
