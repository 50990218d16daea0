//! Loop subdivision (Loop 1987), as pbrt's `loopsubdiv` shape: each level
//! splits every triangle in four and smooths the vertices; the result is
//! then moved onto the limit surface, with the limit surface's normals.
//!
//! Interior vertices are smoothed over their one-ring with Warren's β
//! (3/16 for valence 3, 3/(8n) otherwise), boundary vertices and edges by
//! the cubic B-spline rules along the boundary, so that open meshes keep
//! their rims.

use std::collections::HashMap;

/// The most triangles subdivision may make.
pub const MAX_TRIANGLES: usize = 1 << 26;

/// A triangle mesh: positions and counter-clockwise triangles.
pub type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A mesh on its limit surface: positions, triangles and unit normals.
pub type Limit = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 3]>);

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Warren's weight of each neighbour of an interior vertex of `valence`.
fn beta(valence: usize) -> f64 {
    if valence == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * valence as f64)
    }
}

/// The weight of each neighbour for the limit position.
fn limit_gamma(valence: usize) -> f64 {
    1.0 / (valence as f64 + 3.0 / (8.0 * beta(valence)))
}

/// Each vertex's neighbours in order around it (counter-clockwise as the
/// triangles wind) and whether it lies on the boundary (then the ring runs
/// from one boundary neighbour to the other).
struct Topology {
    rings: Vec<Vec<u32>>,
    boundary: Vec<bool>,
    /// Each edge (low, high) and the vertices opposite it (one on a
    /// boundary, two inside).
    edges: HashMap<(u32, u32), Vec<u32>>,
}

impl Topology {
    fn of(n: usize, triangles: &[[u32; 3]]) -> Result<Topology, String> {
        let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(triangles.len() * 2);
        // Per vertex: the directed pairs (next, previous) of its triangles.
        let mut around: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
        let mut directed = std::collections::HashSet::with_capacity(triangles.len() * 3);
        for t in triangles {
            for k in 0..3 {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                if !directed.insert((a, b)) {
                    return Err(format!(
                        "the edge from vertex {a} to vertex {b} belongs to two triangles wound the same way: \
                         Loop subdivision needs a consistently wound manifold mesh"
                    ));
                }
                // Each direction once: at most two triangles an edge.
                edges.entry((a.min(b), a.max(b))).or_default().push(c);
                around[a as usize].push((b, c));
            }
        }
        let mut rings = Vec::with_capacity(n);
        let mut boundary = Vec::with_capacity(n);
        for (v, pairs) in around.iter().enumerate() {
            // Start where no triangle ends (a boundary), else anywhere.
            let start = pairs
                .iter()
                .map(|&(next, _)| next)
                .find(|next| !pairs.iter().any(|&(_, prev)| prev == *next));
            let on_boundary = start.is_some();
            let Some(&(first, _)) = pairs.first() else {
                rings.push(Vec::new());
                boundary.push(false);
                continue;
            };
            let mut ring = vec![start.unwrap_or(first)];
            loop {
                let cur = *ring.last().expect("not empty");
                let Some(&(_, prev)) = pairs.iter().find(|&&(next, _)| next == cur) else {
                    break;
                };
                if prev == ring[0] {
                    break;
                }
                ring.push(prev);
                if ring.len() > pairs.len() + 1 {
                    return Err(format!("the triangles around vertex {v} do not form a fan"));
                }
            }
            if ring.len() != pairs.len() + usize::from(on_boundary) {
                return Err(format!(
                    "the triangles around vertex {v} form more than one fan: Loop subdivision needs a manifold mesh"
                ));
            }
            rings.push(ring);
            boundary.push(on_boundary);
        }
        Ok(Topology {
            rings,
            boundary,
            edges,
        })
    }
}

/// The mesh subdivided `levels` times and moved onto its limit surface:
/// positions, triangles and unit normals (on the side the triangles wind
/// towards).
pub fn subdivide(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    levels: u32,
) -> Result<Limit, String> {
    let grown = (triangles.len() as u128) << (2 * u128::from(levels.min(40)));
    if grown > MAX_TRIANGLES as u128 {
        return Err(format!(
            "{levels} levels of subdivision would make {grown} triangles, more than the {MAX_TRIANGLES} lumen allows"
        ));
    }
    let (mut p, mut t): Mesh = (positions.to_vec(), triangles.to_vec());
    for _ in 0..levels {
        (p, t) = one_level(&p, &t)?;
    }
    let topology = Topology::of(p.len(), &t)?;
    let mut limit = Vec::with_capacity(p.len());
    let mut normals = Vec::with_capacity(p.len());
    for (v, ring) in topology.rings.iter().enumerate() {
        let here = p[v];
        if ring.is_empty() {
            limit.push(here);
            normals.push([0.0; 3]);
            continue;
        }
        let n = ring.len();
        let q = |i: usize| p[ring[i] as usize];
        let (position, s, tangent) = if topology.boundary[v] {
            let ends = add(q(0), q(n - 1));
            let position = add(scale(here, 1.0 - 2.0 / 5.0), scale(ends, 1.0 / 5.0));
            let s = sub(q(n - 1), q(0));
            let t = match n {
                2 => sub(add(q(0), q(1)), scale(here, 2.0)),
                3 => sub(q(1), here),
                4 => sub(
                    add(
                        add(scale(q(0), -1.0), scale(q(1), 2.0)),
                        sub(scale(q(2), 2.0), q(3)),
                    ),
                    scale(here, 2.0),
                ),
                _ => {
                    let theta = std::f64::consts::PI / (n - 1) as f64;
                    let mut t = scale(add(q(0), q(n - 1)), theta.sin());
                    for i in 1..n - 1 {
                        let w = (2.0 * theta.cos() - 2.0) * (i as f64 * theta).sin();
                        t = add(t, scale(q(i), w));
                    }
                    scale(t, -1.0)
                }
            };
            (position, s, t)
        } else {
            let g = limit_gamma(n);
            let sum = (0..n).fold([0.0; 3], |acc, i| add(acc, q(i)));
            let position = add(scale(here, 1.0 - n as f64 * g), scale(sum, g));
            let mut s = [0.0; 3];
            let mut t = [0.0; 3];
            for i in 0..n {
                let angle = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                s = add(s, scale(q(i), angle.cos()));
                t = add(t, scale(q(i), angle.sin()));
            }
            (position, s, t)
        };
        limit.push(position);
        normals.push(cross(s, tangent));
    }
    // Each normal on the side its triangles wind towards, of unit length
    // (the faces' own where the tangents vanish).
    let mut face_sum = vec![[0.0; 3]; p.len()];
    for tri in &t {
        let [a, b, c] = tri.map(|i| limit[i as usize]);
        let n = cross(sub(b, a), sub(c, a));
        for &i in tri {
            face_sum[i as usize] = add(face_sum[i as usize], n);
        }
    }
    for (n, f) in normals.iter_mut().zip(&face_sum) {
        let mut m = if dot(*n, *f) < 0.0 {
            scale(*n, -1.0)
        } else {
            *n
        };
        let len = dot(m, m).sqrt();
        if !(len > 1e-12 * dot(*f, *f).sqrt().max(f64::MIN_POSITIVE)) {
            m = *f;
        }
        let len = dot(m, m).sqrt();
        *n = if len > 0.0 {
            scale(m, 1.0 / len)
        } else {
            [0.0, 0.0, 1.0]
        };
    }
    Ok((limit, t, normals))
}

/// One level: every triangle split in four, old vertices smoothed, a new
/// vertex on every edge.
fn one_level(p: &[[f64; 3]], t: &[[u32; 3]]) -> Result<Mesh, String> {
    let topology = Topology::of(p.len(), t)?;
    let mut next: Vec<[f64; 3]> = Vec::with_capacity(p.len() + topology.edges.len());
    for (v, ring) in topology.rings.iter().enumerate() {
        let here = p[v];
        let n = ring.len();
        next.push(if n == 0 {
            here
        } else if topology.boundary[v] {
            let ends = add(p[ring[0] as usize], p[ring[n - 1] as usize]);
            add(scale(here, 0.75), scale(ends, 1.0 / 8.0))
        } else {
            let b = beta(n);
            let sum = ring
                .iter()
                .fold([0.0; 3], |acc, &i| add(acc, p[i as usize]));
            add(scale(here, 1.0 - n as f64 * b), scale(sum, b))
        });
    }
    // A new vertex on each edge, numbered in the order edges are met.
    let mut edge_vertex: HashMap<(u32, u32), u32> = HashMap::with_capacity(topology.edges.len());
    let mut triangles = Vec::with_capacity(t.len() * 4);
    for tri in t {
        let mut mid = [0u32; 3];
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            mid[k] = *edge_vertex.entry(key).or_insert_with(|| {
                let opposite = &topology.edges[&key];
                let ends = add(p[a as usize], p[b as usize]);
                let point = if opposite.len() == 2 {
                    let far = add(p[opposite[0] as usize], p[opposite[1] as usize]);
                    add(scale(ends, 3.0 / 8.0), scale(far, 1.0 / 8.0))
                } else {
                    scale(ends, 0.5)
                };
                next.push(point);
                (next.len() - 1) as u32
            });
        }
        // mid[k] lies on the edge from corner k to corner k + 1.
        let [a, b, c] = *tri;
        triangles.push([a, mid[0], mid[2]]);
        triangles.push([mid[0], b, mid[1]]);
        triangles.push([mid[2], mid[1], c]);
        triangles.push([mid[0], mid[1], mid[2]]);
    }
    Ok((next, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat triangular lattice of `n` × `n` quads on z = 0, each split
    /// in two, counter-clockwise from +z.
    fn lattice(n: u32) -> Mesh {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push([
                    f64::from(i) + 0.5 * f64::from(j),
                    f64::from(j) * 0.75f64.sqrt(),
                    0.0,
                ]);
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                t.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (p, t)
    }

    fn octahedron() -> Mesh {
        let p = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, t)
    }

    #[test]
    fn a_flat_mesh_stays_flat_and_its_normals_face_the_winding() {
        let (p, t) = lattice(4);
        let (q, u, n) = subdivide(&p, &t, 2).unwrap();
        assert_eq!(u.len(), t.len() * 16);
        assert!(q.iter().all(|x| x[2].abs() < 1e-12));
        assert!(n.iter().all(|x| (x[2] - 1.0).abs() < 1e-9), "{n:?}");
        // Loop's rules reproduce linear functions: an interior vertex of a
        // regular lattice stays where it is.
        let centre = q
            .iter()
            .position(|x| (x[0] - 4.0).abs() < 1e-9 && (x[1] - 2.0 * 0.75f64.sqrt()).abs() < 1e-9);
        assert!(centre.is_some(), "the lattice's centre vertex stays");
    }

    #[test]
    fn a_closed_mesh_stays_closed_and_smooth() {
        let (p, t) = octahedron();
        for levels in 0..4 {
            let (q, u, n) = subdivide(&p, &t, levels).unwrap();
            assert_eq!(u.len(), t.len() << (2 * levels));
            // Euler: V − E + F = 2, each edge shared by two triangles.
            assert_eq!(
                q.len() as i64 - (u.len() * 3 / 2) as i64 + u.len() as i64,
                2
            );
            let topology = Topology::of(q.len(), &u).unwrap();
            assert!(topology.boundary.iter().all(|b| !b));
            // Symmetric about the origin, inside the octahedron, and
            // every normal points outwards.
            for (x, m) in q.iter().zip(&n) {
                let r = dot(*x, *x).sqrt();
                assert!(r <= 1.0 + 1e-12 && r > 0.4, "{x:?}");
                assert!(dot(*x, *m) > 0.0);
            }
            let c = q.iter().fold([0.0; 3], |a, x| add(a, *x));
            assert!(dot(c, c).sqrt() < 1e-9, "{c:?}");
        }
        // The octahedron's corners go in by the limit rule for valence 4.
        let (q, _, _) = subdivide(&p, &t, 0).unwrap();
        let g = limit_gamma(4);
        assert!((q[0][0] - (1.0 - 4.0 * g)).abs() < 1e-12);
    }

    #[test]
    fn meshes_loop_subdivision_cannot_take_are_refused() {
        let p = vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        // Three triangles on one edge (two of them then wind it alike).
        let fin = vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert!(subdivide(&p, &fin, 1).unwrap_err().contains("manifold"));
        // Two triangles wound against each other.
        let flipped = vec![[0, 1, 2], [0, 1, 3]];
        assert!(subdivide(&p, &flipped, 1).unwrap_err().contains("wound"));
        let (p, t) = octahedron();
        assert!(subdivide(&p, &t, 12).unwrap_err().contains("more than"));
    }
}
