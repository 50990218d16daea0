//! Watertightness of the ray–triangle kernel on closed meshes.
//!
//! Rays are aimed exactly at the vertices and edges of closed meshes — the
//! Stanford bunny and two hand-built meshes whose vertices have small integer
//! coordinates, so that for rays with dyadic directions every number the
//! kernel computes is exact and the rays really pass through the vertices and
//! edges in the kernel's frame (zero edge functions). Each test counts, by
//! brute force over all triangles with the one-lane kernel `Triangle::hit`,
//! how many triangles a ray hits, and checks:
//!
//! * a ray crossing the surface at a vertex or an edge (all the triangles
//!   around it facing the same way along the ray) hits exactly one triangle
//!   there: no crack, no double hit;
//! * every ray hits a closed mesh an even number of times;
//! * `Bvh::hit` and `Bvh::occluded` agree with the brute force;
//! * on the hand-built meshes, the triangles hit are exactly those hit by the
//!   same ray displaced by a tiny (ε, δ), ε ≫ δ, along the kernel's first two
//!   axes, computed independently in `f64` (Möller–Trumbore): the tie rule
//!   behaves as one consistent symbolic perturbation of the ray;
//! * a naive inclusive rule (zero edge functions count on both sides) hits
//!   the same vertex or edge two or more times, so the tie rule is needed;
//! * rays grazing along edges or lying in triangles' planes do not panic and
//!   are treated as the displaced ray is.
//!
//! Run with `cargo test --release --test watertight -- --nocapture` to see
//! the numbers measured.

mod common;

use common::d3::{cross, d3, dot, sub, D3};
use lumen::geometry::triangle::TriangleRay;
use lumen::geometry::{Bvh, Primitive, Triangle};
use lumen::math::{Interval, Vec3};
use lumen::ray::Ray;
use std::collections::HashMap;
use std::path::Path;

// ---------------------------------------------------------------------------
// Helpers

/// SplitMix64: small, seeded, good enough to pick test cases.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// A uniformly distributed unit vector.
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                2.0 * self.f32() - 1.0,
                2.0 * self.f32() - 1.0,
                2.0 * self.f32() - 1.0,
            );
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }
}

/// A closed, consistently oriented triangle mesh with what the checks need.
struct Mesh {
    name: &'static str,
    pos: Vec<Vec3>,
    tris: Vec<[u32; 3]>,
    triangles: Vec<Triangle>,
    /// Triangles around each vertex.
    star: Vec<Vec<usize>>,
    /// Each undirected edge (low, high) once.
    edges: Vec<[u32; 2]>,
    bvh: Bvh,
}

impl Mesh {
    fn new(name: &'static str, pos: Vec<Vec3>, tris: Vec<[u32; 3]>) -> Mesh {
        // Closed and consistently oriented: every directed edge once, and its
        // reverse once.
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "{name}: directed edge {a}→{b} used {n} times");
            assert_eq!(
                directed.get(&(b, a)),
                Some(&1),
                "{name}: edge {a}→{b} has no opposite (the mesh is not closed)"
            );
        }
        let mut edges: Vec<[u32; 2]> = directed
            .keys()
            .filter(|(a, b)| a < b)
            .map(|&(a, b)| [a, b])
            .collect();
        edges.sort_unstable();
        let mut star = vec![Vec::new(); pos.len()];
        for (i, t) in tris.iter().enumerate() {
            for &v in t {
                star[v as usize].push(i);
            }
        }
        let triangles: Vec<Triangle> = tris
            .iter()
            .map(|t| Triangle::new(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]))
            .collect();
        for (i, t) in triangles.iter().enumerate() {
            let [a, b, c] = t.vertices.map(d3);
            assert_ne!(
                cross(sub(b, a), sub(c, a)),
                [0.0; 3],
                "{name}: triangle {i} is degenerate"
            );
        }
        let prims: Vec<Primitive> = triangles.iter().map(|&t| Primitive::Triangle(t)).collect();
        let bvh = Bvh::new(&prims);
        Mesh {
            name,
            pos,
            tris,
            triangles,
            star,
            edges,
            bvh,
        }
    }

    /// The geometric normal of triangle `i`, in `f64` (exact for the
    /// meshes on integer grids).
    fn normal(&self, i: usize) -> D3 {
        let [a, b, c] = self.triangles[i].vertices.map(d3);
        cross(sub(b, a), sub(c, a))
    }

    /// Every hit of `ray` (distance, triangle), by brute force with the
    /// one-lane kernel, nearest first.
    fn hits(&self, ray: &Ray) -> Vec<(f32, usize)> {
        let mut h: Vec<(f32, usize)> = self
            .triangles
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                t.hit(ray, Interval::new(0.0, f32::INFINITY))
                    .map(|t| (t, i))
            })
            .collect();
        h.sort_by(|a, b| a.partial_cmp(b).unwrap());
        h
    }

    /// Whether the kernel sees `ray` pass exactly through an edge or a
    /// vertex of some triangle: the vertices projected in the ray's sheared
    /// frame as the kernel projects them (in `f32`), then the three edge
    /// functions exactly (in `f64`): a zero among them, the others not of
    /// opposite signs.
    fn exactly_through_boundary(&self, ray: &Ray) -> bool {
        let axes = TriangleRay::axes_of(ray.direction);
        let r = TriangleRay::new(ray, axes, 0.0);
        let [sx, sy, _] = r.shear;
        self.triangles.iter().any(|t| {
            let p = t.lanes(&axes).vertices.map(|v| {
                let (x, y, z) = (v[0] - r.origin[0], v[1] - r.origin[1], v[2] - r.origin[2]);
                [(x - sx * z) as f64, (y - sy * z) as f64]
            });
            let e = |p: [f64; 2], q: [f64; 2]| q[0] * p[1] - q[1] * p[0];
            let f = [e(p[1], p[2]), e(p[2], p[0]), e(p[0], p[1])];
            let zero = f.contains(&0.0);
            let mixed = f.iter().any(|&x| x < 0.0) && f.iter().any(|&x| x > 0.0);
            zero && !mixed && f != [0.0; 3]
        })
    }

    /// Whether every triangle of `tris` faces the same way along `d`, none
    /// edge-on: a ray through their common vertex or edge crosses the surface.
    fn uniform(&self, tris: &[usize], d: Vec3) -> bool {
        let s: Vec<f64> = tris.iter().map(|&i| dot(self.normal(i), d3(d))).collect();
        s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0)
    }

    /// Whether some triangle contains the direction `d` in its plane.
    fn in_plane(&self, tris: &[usize], d: Vec3) -> bool {
        tris.iter().any(|&i| dot(self.normal(i), d3(d)) == 0.0)
    }

    /// Triangles around vertex `a` or vertex `b` (deduplicated).
    fn star_of(&self, vs: &[u32]) -> Vec<usize> {
        let mut s: Vec<usize> = vs
            .iter()
            .flat_map(|&v| self.star[v as usize].clone())
            .collect();
        s.sort_unstable();
        s.dedup();
        s
    }

    /// The smallest altitude of the triangles `tris`.
    fn min_altitude(&self, tris: &[usize]) -> f64 {
        tris.iter()
            .map(|&i| {
                let [a, b, c] = self.triangles[i].vertices.map(d3);
                let area2 = dot(self.normal(i), self.normal(i)).sqrt();
                let longest = [sub(b, a), sub(c, b), sub(a, c)]
                    .iter()
                    .map(|e| dot(*e, *e).sqrt())
                    .fold(0.0, f64::max);
                area2 / longest
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The largest distance of a vertex from the origin: rays start beyond
    /// it.
    fn radius(&self) -> f32 {
        self.pos.iter().map(|p| p.length()).fold(0.0, f32::max)
    }

    /// `Bvh::hit` and `Bvh::occluded` for `ray` (unit direction) against the
    /// brute force; returns the brute-force hits.
    fn check_bvh(&self, ray: &Ray, what: &dyn Fn() -> String) -> Vec<(f32, usize)> {
        let brute = self.hits(ray);
        let full = Interval::new(0.0, f32::INFINITY);
        let got = self.bvh.hit(ray, full).map(|h| (h.t, h.index as usize));
        // The nearest, the lowest index among equal distances.
        let want = brute.first().map(|&(t, _)| {
            let i = brute
                .iter()
                .filter(|h| h.0 == t)
                .map(|h| h.1)
                .min()
                .unwrap();
            (t, i)
        });
        assert_eq!(
            got,
            want,
            "{}: Bvh::hit against brute force, {}",
            self.name,
            what()
        );
        assert_eq!(
            self.bvh.occluded(ray, full),
            want.is_some(),
            "{}: Bvh::occluded, {}",
            self.name,
            what()
        );
        assert!(
            brute.len().is_multiple_of(2),
            "{}: {} crossings (odd) of the unit ray, {}: {:?}",
            self.name,
            brute.len(),
            what(),
            brute
        );
        brute
    }

    /// The triangles that `ray` displaced by ε along the kernel's axis kx and
    /// δ ≪ ε along ky hits, by an independent `f64` Möller–Trumbore test.
    fn displaced_hits(&self, ray: &Ray, eps: f64, delta: f64) -> Vec<(f64, usize)> {
        let [kx, ky, _] = TriangleRay::axes_of(ray.direction);
        let mut o = d3(ray.origin());
        o[kx] += eps;
        o[ky] += delta;
        let d = d3(ray.direction);
        let mut h: Vec<(f64, usize)> = self
            .triangles
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let [a, b, c] = t.vertices.map(d3);
                let (e1, e2) = (sub(b, a), sub(c, a));
                let p = cross(d, e2);
                let det = dot(e1, p);
                if det == 0.0 {
                    return None;
                }
                let s = sub(o, a);
                let u = dot(s, p) / det;
                let q = cross(s, e1);
                let v = dot(d, q) / det;
                let t = dot(e2, q) / det;
                (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some((t, i))
            })
            .collect();
        h.sort_by(|a, b| a.partial_cmp(b).unwrap());
        h
    }

    /// Triangles whose three edge functions of `ray`, computed exactly in
    /// `f64` in the ray's sheared frame, are all ≥ 0 or all ≤ 0 (not all
    /// zero): the naive inclusive rule, with the distance of each hit. Exact
    /// for the integer meshes and dyadic rays.
    fn naive_hits(&self, ray: &Ray) -> Vec<(f64, usize)> {
        let [kx, ky, kz] = TriangleRay::axes_of(ray.direction);
        let (o, d) = (d3(ray.origin()), d3(ray.direction));
        let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        self.triangles
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let p = t.vertices.map(|v| {
                    let r = sub(d3(v), o);
                    [r[kx] - sx * r[kz], r[ky] - sy * r[kz], sz * r[kz]]
                });
                let e = |p: [f64; 3], q: [f64; 3]| q[0] * p[1] - q[1] * p[0];
                let (u, v, w) = (e(p[1], p[2]), e(p[2], p[0]), e(p[0], p[1]));
                let inside =
                    (u >= 0.0 && v >= 0.0 && w >= 0.0) || (u <= 0.0 && v <= 0.0 && w <= 0.0);
                let det = u + v + w;
                (inside && det != 0.0).then(|| ((u * p[0][2] + v * p[1][2] + w * p[2][2]) / det, i))
            })
            .filter(|&(t, _)| t > 0.0)
            .collect()
    }
}

fn bunny() -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj");
    let model = lumen::mesh::load(&path).expect("assets/bunny.obj loads");
    assert_eq!(model.meshes.len(), 1);
    let mesh = &model.meshes[0];
    let (_, m) = model.instances[0];
    assert_eq!(model.instances.len(), 1);
    let pos: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|p| Vec3::from(m.transform_point3(glam_vec(*p))))
        .collect();
    assert_eq!((pos.len(), mesh.triangles.len()), (1839, 3674));
    Mesh::new("bunny", pos, mesh.triangles.clone())
}

fn glam_vec(p: [f32; 3]) -> glam::Vec3 {
    glam::Vec3::from_array(p)
}

/// The surface of the cube [−n, n]³ cut into unit squares, each split into
/// two triangles along alternating diagonals, counter-clockwise seen from
/// outside; `place` maps each grid point to its position.
fn grid_mesh(name: &'static str, n: i32, place: impl Fn([i32; 3]) -> [i32; 3]) -> Mesh {
    let mut index: HashMap<[i32; 3], u32> = HashMap::new();
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    let mut vertex = |g: [i32; 3]| {
        *index.entry(g).or_insert_with(|| {
            let p = place(g);
            pos.push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
            (pos.len() - 1) as u32
        })
    };
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [-1, 1] {
            for i in -n..n {
                for j in -n..n {
                    let corner = |du: i32, dv: i32| {
                        let mut g = [0; 3];
                        g[axis] = side * n;
                        g[b] = i + du;
                        g[c] = j + dv;
                        g
                    };
                    let [q00, q10, q11, q01] =
                        [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)].map(&mut vertex);
                    // e_b × e_c = e_axis: counter-clockwise seen from +axis.
                    let pair = if (i + j).rem_euclid(2) == 0 {
                        [[q00, q10, q11], [q00, q11, q01]]
                    } else {
                        [[q00, q10, q01], [q10, q11, q01]]
                    };
                    for [x, y, z] in pair {
                        tris.push(if side > 0 { [x, y, z] } else { [x, z, y] });
                    }
                }
            }
        }
    }
    let mesh = Mesh::new(name, pos, tris);
    // Outward: the mesh is star-shaped about the origin.
    for i in 0..mesh.tris.len() {
        let c = mesh.triangles[i].vertices.iter().fold([0.0; 3], |s, v| {
            let v = d3(*v);
            [s[0] + v[0], s[1] + v[1], s[2] + v[2]]
        });
        assert!(
            dot(mesh.normal(i), c) > 0.0,
            "{name}: triangle {i} faces inwards"
        );
    }
    mesh
}

/// The subdivided cube [−4, 4]³ (768 triangles).
fn cube() -> Mesh {
    grid_mesh("cube", 4, |g| g)
}

/// The subdivided cube's grid points pushed onto the sphere of radius 16
/// and rounded to integers: a closed, curved mesh with integer vertices
/// (768 triangles of many orientations, vertices of valence 3 to 8).
fn ball() -> Mesh {
    grid_mesh("ball", 4, |g| {
        let l = ((g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) as f64).sqrt();
        g.map(|x| (16.0 * x as f64 / l).round() as i32)
    })
}

/// Integer directions whose largest component is 1, 2 or 4 in magnitude:
/// the shear of the kernel's frame (ratios to that component) is then exact.
fn dyadic_directions() -> Vec<[i32; 3]> {
    let mut v = Vec::new();
    for x in -4..=4 {
        for y in -4..=4 {
            for z in -4..=4 {
                let m = [x, y, z].map(i32::abs).into_iter().max().unwrap();
                if [1, 2, 4].contains(&m) {
                    v.push([x, y, z]);
                }
            }
        }
    }
    v
}

fn vec_i(d: [i32; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// The unit ray from `origin` along `d`.
fn unit_ray(origin: Vec3, d: Vec3) -> Ray {
    Ray::new(origin, d.normalize())
}

#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    /// Rays through an edge or a vertex exactly (a zero edge function).
    exact: usize,
    /// Aimed crossings (all triangles around facing one way) hit exactly once.
    crossings: usize,
    /// Aimed points where the surface folds along the ray or lies in it.
    folded: usize,
    /// Hits along whole rays.
    total_hits: usize,
}

/// Checks one ray aimed at a point of the mesh at distance 1 along the
/// (unnormalised) direction: `around` are the triangles around the aimed
/// vertex or edge and `window` a distance (in units of t) within which only
/// they can be hit.
fn check_aimed(
    mesh: &Mesh,
    ray: &Ray,
    t_aim: f32,
    around: &[usize],
    window: f32,
    tally: &mut Tally,
    what: &dyn Fn() -> String,
) {
    tally.rays += 1;
    let hits = mesh.hits(ray);
    tally.total_hits += hits.len();
    assert!(
        hits.len().is_multiple_of(2),
        "{}: {} crossings (odd) along the ray, {}: {:?}",
        mesh.name,
        hits.len(),
        what(),
        hits
    );
    if mesh.exactly_through_boundary(ray) {
        tally.exact += 1;
    }
    let local: Vec<(f32, usize)> = hits
        .iter()
        .copied()
        .filter(|h| (h.0 - t_aim).abs() <= window)
        .collect();
    if mesh.uniform(around, ray.direction) {
        tally.crossings += 1;
        assert_eq!(
            local.len(),
            1,
            "{}: the aimed crossing is hit {} times (0 = crack, 2+ = double hit), {}: {:?}",
            mesh.name,
            local.len(),
            what(),
            local
        );
        assert!(
            around.contains(&local[0].1),
            "{}: hit triangle {} is not around the aimed point, {}",
            mesh.name,
            local[0].1,
            what()
        );
    } else {
        tally.folded += 1;
    }
}

// ---------------------------------------------------------------------------
// 1. The bunny: shared vertices and edges hit exactly once.

#[test]
fn bunny_vertices_and_edges_are_hit_exactly_once() {
    let mesh = bunny();
    let mut rng = Rng(0x5EED_B0B1);
    let reach = 2.0 * mesh.radius() + 1.0;
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let (mut at_vertices, mut at_edges) = (Tally::default(), Tally::default());
    let mut folded_parity_checked = 0;
    let mut bvh_rays = 0;

    // Vertices: along the six axes (then the vertex projects exactly to the
    // ray) and in random directions (the direction computed as vertex −
    // origin, as close as f32 allows).
    for _ in 0..450 {
        let v = rng.below(mesh.pos.len());
        let p = mesh.pos[v];
        let around = &mesh.star[v];
        let window = (0.25 * mesh.min_altitude(around)) as f32;
        let mut dirs: Vec<Vec3> = axes.to_vec();
        dirs.extend((0..4).map(|_| rng.unit()));
        for u in dirs {
            let origin = p - reach * u;
            let d = p - origin;
            let ray = Ray::new(origin, d);
            let what = || format!("ray from {origin} along {d} at vertex {v} {p}");
            check_aimed(
                &mesh,
                &ray,
                1.0,
                around,
                window / d.length(),
                &mut at_vertices,
                &what,
            );
            if !mesh.uniform(around, d) && !mesh.in_plane(around, d) {
                // Where the surface folds (a silhouette), whether the ray
                // crosses there must agree with a ray displaced a little.
                let nudged = Ray::new(origin + 1e-4 * window * rng.unit(), d);
                let near = |r: &Ray| {
                    mesh.hits(r)
                        .iter()
                        .filter(|h| (h.0 - 1.0).abs() <= window / d.length())
                        .count()
                };
                assert_eq!(
                    near(&ray) % 2,
                    near(&nudged) % 2,
                    "bunny: parity at a fold, {}",
                    what()
                );
                folded_parity_checked += 1;
            }
            mesh.check_bvh(&unit_ray(origin, d), &what);
            bvh_rays += 1;
        }
    }

    // Edges: the midpoint and random points along the edge, as f32 computes
    // them, in random directions.
    for _ in 0..450 {
        let [a, b] = mesh.edges[rng.below(mesh.edges.len())];
        let (pa, pb) = (mesh.pos[a as usize], mesh.pos[b as usize]);
        let around = mesh.star_of(&[a, b]);
        let window = (0.25 * mesh.min_altitude(&around)) as f32;
        let points = [
            (pa + pb) * 0.5,
            pa + rng.f32() * (pb - pa),
            pa + rng.f32() * (pb - pa),
        ];
        for p in points {
            let u = rng.unit();
            let origin = p - reach * u;
            let d = p - origin;
            let ray = Ray::new(origin, d);
            let what = || format!("ray from {origin} along {d} at {p} on edge {a}–{b}");
            check_aimed(
                &mesh,
                &ray,
                1.0,
                &around,
                window / d.length(),
                &mut at_edges,
                &what,
            );
            mesh.check_bvh(&unit_ray(origin, d), &what);
            bvh_rays += 1;
        }
    }

    println!("bunny, rays at vertices: {at_vertices:?}");
    println!("bunny, rays at edges:    {at_edges:?}");
    println!("bunny: {folded_parity_checked} folds checked against a displaced ray, {bvh_rays} unit rays checked with the BVH");
    // The test exercises the tie rule only if many rays pass exactly through
    // a vertex or an edge.
    assert!(
        at_vertices.exact * 2 >= at_vertices.rays,
        "too few exact vertex hits: {at_vertices:?}"
    );
    assert!(
        at_vertices.crossings * 4 >= at_vertices.rays * 3,
        "{at_vertices:?}"
    );
    assert!(at_edges.crossings * 3 >= at_edges.rays * 2, "{at_edges:?}");
}

// ---------------------------------------------------------------------------
// 1b. Integer meshes: every ray exactly through a vertex or an edge.

/// Rays at every vertex, every edge midpoint and the quarter points of the
/// edges of `mesh`, in random dyadic directions; the hits must be those of
/// the displaced ray.
fn integer_mesh_rays(mesh: &Mesh, seed: u64) -> (Tally, usize) {
    let dirs = dyadic_directions();
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    // Far enough that the origin is outside the mesh's bounding box whatever
    // the direction (its largest component is at least 1).
    let k = (2.0 * mesh.radius()).ceil() + 2.0;
    let mut checked_displaced = 0;
    let mut aim = |p: Vec3, around: &[usize], what: &str, rng: &mut Rng| {
        let window = (0.25 * mesh.min_altitude(around)) as f32;
        for _ in 0..4 {
            let d = vec_i(dirs[rng.below(dirs.len())]);
            let origin = p - k * d;
            let ray = Ray::new(origin, d);
            assert_eq!(ray.origin() + k * d, p, "the origin is computed exactly");
            let what = || format!("ray from {origin} along {d} at {what} {p}");
            check_aimed(
                mesh,
                &ray,
                k,
                around,
                window / d.length(),
                &mut tally,
                &what,
            );
            // The same triangles as the ray displaced by (ε, δ).
            let got: Vec<usize> = {
                let mut v: Vec<usize> = mesh.hits(&ray).iter().map(|h| h.1).collect();
                v.sort_unstable();
                v
            };
            let want: Vec<usize> = {
                let mut v: Vec<usize> = mesh
                    .displaced_hits(&ray, 1e-6, 1e-9)
                    .iter()
                    .map(|h| h.1)
                    .collect();
                v.sort_unstable();
                v
            };
            assert_eq!(
                got,
                want,
                "{}: triangles hit, against the displaced ray, {}",
                mesh.name,
                what()
            );
            checked_displaced += 1;
            mesh.check_bvh(&unit_ray(origin, d), &what);
        }
    };
    for v in 0..mesh.pos.len() {
        aim(mesh.pos[v], &mesh.star[v], &format!("vertex {v}"), &mut rng);
    }
    for &[a, b] in &mesh.edges {
        let (pa, pb) = (mesh.pos[a as usize], mesh.pos[b as usize]);
        let around = mesh.star_of(&[a, b]);
        for s in [0.5, 0.25, 0.75] {
            aim(
                pa + s * (pb - pa),
                &around,
                &format!("edge {a}–{b} at {s}"),
                &mut rng,
            );
        }
    }
    (tally, checked_displaced)
}

#[test]
fn integer_meshes_vertices_and_edges_are_hit_exactly_once() {
    for (mesh, seed) in [(ball(), 1), (cube(), 2)] {
        let (tally, displaced) = integer_mesh_rays(&mesh, seed);
        println!(
            "{}: {tally:?}, {displaced} rays matched the displaced ray",
            mesh.name
        );
        // Every ray here passes exactly through a vertex or an edge.
        assert_eq!(tally.exact, tally.rays, "{}: {tally:?}", mesh.name);
        assert!(
            tally.crossings * 2 >= tally.rays,
            "{}: {tally:?}",
            mesh.name
        );
    }
}

// ---------------------------------------------------------------------------
// 2. The tie rule matters: a naive inclusive rule double-counts.

#[test]
fn a_naive_inclusive_rule_would_count_vertices_and_edges_several_times() {
    let mesh = ball();
    let dirs = dyadic_directions();
    let mut rng = Rng(3);
    let k = (2.0 * mesh.radius()).ceil() + 2.0;
    let (mut rays, mut kernel_hits, mut naive_hits, mut vertex_rays, mut edge_rays) =
        (0, 0, 0, 0, 0);
    let mut targets: Vec<(Vec3, Vec<usize>, usize)> = Vec::new();
    for v in 0..mesh.pos.len() {
        // At a vertex the naive rule takes every triangle around it.
        targets.push((mesh.pos[v], mesh.star[v].clone(), mesh.star[v].len()));
    }
    for &[a, b] in &mesh.edges {
        let (pa, pb) = (mesh.pos[a as usize], mesh.pos[b as usize]);
        // Inside an edge it takes both triangles of the edge.
        targets.push(((pa + pb) * 0.5, mesh.star_of(&[a, b]), 2));
    }
    for (p, around, expected_naive) in &targets {
        let window = 0.25 * mesh.min_altitude(around);
        // A direction along which the surface there is crossed.
        let Some(d) = (0..64)
            .map(|_| vec_i(dirs[rng.below(dirs.len())]))
            .find(|&d| mesh.uniform(around, d))
        else {
            continue;
        };
        let ray = Ray::new(*p - k * d, d);
        let w = window / d3(d).iter().map(|x| x * x).sum::<f64>().sqrt();
        let kernel = mesh
            .hits(&ray)
            .iter()
            .filter(|h| ((h.0 - k).abs() as f64) <= w)
            .count();
        let naive = mesh
            .naive_hits(&ray)
            .iter()
            .filter(|h| (h.0 - k as f64).abs() <= w)
            .count();
        assert_eq!(kernel, 1, "kernel hits at {p} along {d}");
        assert_eq!(naive, *expected_naive, "naive hits at {p} along {d}");
        assert!(naive >= 2);
        rays += 1;
        kernel_hits += kernel;
        naive_hits += naive;
        if *expected_naive == 2 {
            edge_rays += 1;
        } else {
            vertex_rays += 1;
        }
    }
    println!(
        "ball: {rays} crossings ({vertex_rays} at vertices, {edge_rays} at edges): \
         kernel {kernel_hits} hits, naive inclusive rule {naive_hits} hits"
    );
    assert!(vertex_rays > 300 && edge_rays > 1000);
}

// ---------------------------------------------------------------------------
// 3. Grazing rays: along edges and in triangles' planes.

#[test]
fn rays_along_edges_and_in_planes_are_treated_as_a_displaced_ray() {
    for mesh in [cube(), ball()] {
        let k = (2.0 * mesh.radius()).ceil() + 2.0;
        let (mut rays, mut in_plane_triangles, mut zero, mut nonzero, mut hits_total) =
            (0, 0, 0, 0, 0);
        let mut check = |origin: Vec3, d: Vec3, what: String| {
            let ray = Ray::new(origin, d);
            let what = || format!("{what}: ray from {origin} along {d}");
            let hits = mesh.hits(&ray);
            assert!(
                hits.len() % 2 == 0,
                "{}: odd crossings {hits:?}, {}",
                mesh.name,
                what()
            );
            let mut got: Vec<usize> = hits.iter().map(|h| h.1).collect();
            got.sort_unstable();
            let mut want: Vec<usize> = mesh
                .displaced_hits(&ray, 1e-6, 1e-9)
                .iter()
                .map(|h| h.1)
                .collect();
            want.sort_unstable();
            assert_eq!(
                got,
                want,
                "{}: against the displaced ray, {}",
                mesh.name,
                what()
            );
            // A triangle containing the ray in its plane is never hit.
            let all: Vec<usize> = (0..mesh.tris.len()).collect();
            for &i in &all {
                if dot(mesh.normal(i), d3(d)) == 0.0 {
                    let [a, ..] = mesh.triangles[i].vertices.map(d3);
                    if dot(mesh.normal(i), sub(d3(origin), a)) == 0.0 {
                        in_plane_triangles += 1;
                        assert!(!got.contains(&i));
                    }
                }
            }
            if hits.is_empty() {
                zero += 1;
            } else {
                nonzero += 1;
            }
            hits_total += hits.len();
            rays += 1;
            if d.abs().max_element() == d.length() {
                // Axis-aligned: the unit ray is the same ray.
                mesh.check_bvh(&ray, &what);
            } else {
                mesh.check_bvh(&unit_ray(origin, d), &what);
            }
        };
        for (i, t) in mesh.tris.iter().enumerate() {
            let p = t.map(|v| mesh.pos[v as usize]);
            // Along each edge (when its direction is dyadic), and from each
            // vertex through the opposite edge's midpoint, in the plane.
            for j in 0..3 {
                let (a, b, c) = (p[j], p[(j + 1) % 3], p[(j + 2) % 3]);
                for d in [b - a, (b + c) - 2.0 * a] {
                    let di = [d.x as i32, d.y as i32, d.z as i32];
                    let m = di.map(i32::abs).into_iter().max().unwrap();
                    if [1, 2, 4, 8].contains(&m) {
                        check(
                            a - k * d / m as f32,
                            d / m as f32,
                            format!("triangle {i}, vertex {j}"),
                        );
                    }
                }
            }
        }
        if mesh.name == "cube" {
            // Axis-aligned rays in the faces' planes: along grid lines, and
            // through the middle of the squares (crossing diagonals).
            for axis in 0..3 {
                for &d in &[1.0f32, -1.0] {
                    let mut dir = Vec3::ZERO;
                    dir[axis] = d;
                    for i in -8..=8 {
                        for face in [-4.0f32, 4.0] {
                            let mut o = Vec3::ZERO;
                            o[axis] = -d * 20.0;
                            o[(axis + 1) % 3] = face;
                            o[(axis + 2) % 3] = i as f32 * 0.5;
                            check(o, dir, "in the plane of a face".to_string());
                            o[(axis + 2) % 3] = face;
                            o[(axis + 1) % 3] = i as f32 * 0.5;
                            check(o, dir, "in the plane of a face".to_string());
                        }
                    }
                }
            }
        }
        println!(
            "{}: {rays} grazing rays, {in_plane_triangles} (ray, triangle) pairs with the ray in the triangle's plane (never hit); \
             {zero} rays hit nothing, {nonzero} rays hit (total {hits_total} hits)",
            mesh.name
        );
        assert!(rays > 500 && in_plane_triangles > 500);
    }
}
