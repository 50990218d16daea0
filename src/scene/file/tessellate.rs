//! Disks and cylinders as triangles, for the readers of other renderers'
//! formats, which have them where lumen has none (`--approximate`). The
//! polygons are widened so that their area is the true shape's, which keeps
//! the light a disk or a cylinder sheds.

use crate::scene::desc::{ObjectDesc, TransformDesc};

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

/// `mesh` as an object of the scene.
pub fn object(
    (positions, indices, normals): Mesh,
    material: String,
    transform: Vec<TransformDesc>,
) -> ObjectDesc {
    ObjectDesc::Triangles {
        positions,
        indices,
        normals: Some(normals),
        uvs: None,
        material,
        transform,
    }
}

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

/// The side of a cylinder about z of `radius` from `z0` to `z1`, facing
/// outwards, with normals for smooth shading.
pub fn cylinder(radius: f64, z0: f64, z1: f64) -> Mesh {
    let n = f64::from(SEGMENTS);
    // A regular polygon of circumradius R has perimeter 2 n R sin(π/n).
    let widen = std::f64::consts::PI / (n * (std::f64::consts::PI / n).sin());
    let r = radius * widen;
    let mut positions: Vec<[f64; 3]> = ring(r, z0).collect();
    positions.extend(ring(r, z1));
    let normals = positions
        .iter()
        .map(|p| [p[0] / r, p[1] / r, 0.0])
        .collect();
    (positions, band(), normals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The triangles of a `triangles` object, each as twice its area
    /// along its normal (by the winding).
    fn normals(o: &ObjectDesc) -> Vec<DVec3> {
        let ObjectDesc::Triangles {
            positions, indices, ..
        } = o
        else {
            panic!()
        };
        indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| DVec3::from(positions[i as usize]));
                (b - a).cross(c - a)
            })
            .collect()
    }

    fn area(o: &ObjectDesc) -> f64 {
        normals(o).iter().map(|n| 0.5 * n.length()).sum()
    }

    #[test]
    fn tessellated_shapes_keep_their_area_and_face_out() {
        let pi = std::f64::consts::PI;
        let d = object(disk(2.0, 0.0, 1.0), "m".into(), Vec::new());
        assert!((area(&d) / (pi * 4.0) - 1.0).abs() < 1e-12);
        let ring = object(disk(2.0, 1.0, 0.0), "m".into(), Vec::new());
        assert!((area(&ring) / (pi * 3.0) - 1.0).abs() < 1e-12);
        let c = object(cylinder(0.5, -1.0, 2.0), "m".into(), Vec::new());
        assert!((area(&c) / (2.0 * pi * 0.5 * 3.0) - 1.0).abs() < 1e-12);
        // Winding: the disk's triangles face +z, the cylinder's outwards.
        for (o, outward) in [(&d, DVec3::Z), (&c, DVec3::X)] {
            let w = normals(o)[0];
            assert!(w.dot(outward) > 0.0, "{w:?}");
        }
    }
}
