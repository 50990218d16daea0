//! Disks with a hole (pbrt's `innerradius`) as triangles, for the pbrt
//! reader, which has them where lumen's disks have none (`--approximate`).
//! The polygons are widened so that their area is the true shape's, which
//! keeps the light the ring sheds.

/// Sides of the polygons.
pub const SEGMENTS: u32 = 128;

/// The ring of radius `r` (before widening) at height `z`, `SEGMENTS`
/// points counter-clockwise seen from +z.
fn ring(r: f64, z: f64) -> impl Iterator<Item = [f64; 3]> {
    (0..SEGMENTS).map(move |i| {
        let phi = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(SEGMENTS);
        [r * phi.cos(), r * phi.sin(), z]
    })
}

/// A tessellated shape: positions, counter-clockwise triangles and unit
/// normals (as [`crate::mesh::loop_subdivision::Limit`]).
pub type Mesh = crate::mesh::loop_subdivision::Limit;

/// The triangles of the band between ring 0 (vertices 0 … SEGMENTS − 1)
/// and ring 1 (the next SEGMENTS), counter-clockwise seen from the side
/// the first ring's edge turns to.
fn band() -> Vec<[u32; 3]> {
    let s = SEGMENTS;
    (0..s)
        .flat_map(|i| {
            let j = (i + 1) % s;
            [[i, j, s + j], [i, s + j, s + i]]
        })
        .collect()
}

/// A disk of `radius` (with a hole of `inner`) at height `z`, facing +z.
pub fn disk(radius: f64, inner: f64, z: f64) -> Mesh {
    let n = f64::from(SEGMENTS);
    let angle = 2.0 * std::f64::consts::PI / n;
    // A regular polygon of circumradius R has area ½ n R² sin(2π/n).
    let widen = (2.0 * std::f64::consts::PI / (n * angle.sin())).sqrt();
    let mut positions: Vec<[f64; 3]> = ring(radius * widen, z).collect();
    let indices = if inner > 0.0 {
        positions.extend(ring(inner * widen, z));
        band()
    } else {
        let s = SEGMENTS;
        positions.push([0.0, 0.0, z]);
        (0..s).map(|i| [s, i, (i + 1) % s]).collect()
    };
    let normals = vec![[0.0, 0.0, 1.0]; positions.len()];
    (positions, indices, normals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Each triangle of `mesh` as twice its area along its normal (by the
    /// winding).
    fn normals((positions, indices, _): &Mesh) -> Vec<DVec3> {
        indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| DVec3::from(positions[i as usize]));
                (b - a).cross(c - a)
            })
            .collect()
    }

    fn area(mesh: &Mesh) -> f64 {
        normals(mesh).iter().map(|n| 0.5 * n.length()).sum()
    }

    #[test]
    fn tessellated_disks_keep_their_area_and_face_up() {
        let pi = std::f64::consts::PI;
        let d = disk(2.0, 0.0, 1.0);
        assert!((area(&d) / (pi * 4.0) - 1.0).abs() < 1e-12);
        let ring = disk(2.0, 1.0, 0.0);
        assert!((area(&ring) / (pi * 3.0) - 1.0).abs() < 1e-12);
        for mesh in [&d, &ring] {
            assert!(normals(mesh).iter().all(|w| w.dot(DVec3::Z) > 0.0));
        }
    }
}
