//! Tangents for normal maps where a file gives none: MikkTSpace (the
//! `bevy_mikktspace` crate), the algorithm normal maps are baked against (glTF
//! asks for it; Blender bakes with it), from the mesh's positions, vertex
//! normals and texture coordinates (v up the image, so that the bitangent's
//! sign points up the image as the maps' green channel does).
//!
//! MikkTSpace gives a tangent per corner of each triangle; a vertex whose
//! corners got different tangents (a seam where the texture is mirrored)
//! is split, its copies sharing everything else.

use super::TriangleMesh;

/// The mesh as MikkTSpace reads it, and the tangents it writes per corner.
struct Corners<'a> {
    mesh: &'a TriangleMesh,
    normals: &'a [[f32; 3]],
    uvs: &'a [[f32; 2]],
    tangents: Vec<[f32; 4]>,
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.triangles[face][vert] as usize]
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.mesh.triangles[face][vert] as usize]
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.mesh.triangles[face][vert] as usize]
    }

    fn set_tangent(
        &mut self,
        tangent: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        // A corner MikkTSpace could give nothing (a degenerate face alone)
        // keeps the default frame.
        self.tangents[face * 3 + vert] = tangent.unwrap_or_default().tangent_encoded();
    }
}

/// Gives `mesh` tangents, if it has vertex normals and texture coordinates
/// and no tangents yet; returns whether it did.
pub(super) fn generate(mesh: &mut TriangleMesh) -> bool {
    let (Some(normals), Some(uvs)) = (&mesh.normals, &mesh.uvs) else {
        return false;
    };
    if mesh.tangents.is_some() || mesh.triangles.is_empty() {
        return false;
    }
    let mut corners = Corners {
        mesh,
        normals,
        uvs,
        tangents: vec![[0.0; 4]; mesh.triangles.len() * 3],
    };
    if bevy_mikktspace::generate_tangents(&mut corners).is_err() {
        return false;
    }
    let per_corner = corners.tangents;
    // One tangent per vertex; a vertex whose corners disagree is split.
    let mut tangents: Vec<Option<[f32; 4]>> = vec![None; mesh.positions.len()];
    for (k, tangent) in per_corner.into_iter().enumerate() {
        let (t, c) = (k / 3, k % 3);
        let v = mesh.triangles[t][c] as usize;
        match tangents[v] {
            None => tangents[v] = Some(tangent),
            Some(existing) if same(existing, tangent) => {}
            Some(_) => {
                let copy = split_vertex(mesh, v);
                tangents.push(Some(tangent));
                mesh.triangles[t][c] = copy;
            }
        }
    }
    mesh.tangents = Some(
        tangents
            .into_iter()
            .map(|t| t.unwrap_or([1.0, 0.0, 0.0, 1.0]))
            .collect(),
    );
    true
}

/// Whether two corners' tangents are the same tangent.
fn same(a: [f32; 4], b: [f32; 4]) -> bool {
    a[3] == b[3] && a[0] * b[0] + a[1] * b[1] + a[2] * b[2] > 0.9999
}

/// Appends a copy of vertex `v` (every attribute), returning its index.
fn split_vertex(mesh: &mut TriangleMesh, v: usize) -> u32 {
    fn copy<T: Copy>(list: &mut Option<Vec<T>>, v: usize) {
        if let Some(l) = list {
            l.push(l[v]);
        }
    }
    mesh.positions.push(mesh.positions[v]);
    copy(&mut mesh.normals, v);
    copy(&mut mesh.uvs, v);
    copy(&mut mesh.uvs1, v);
    copy(&mut mesh.colors, v);
    (mesh.positions.len() - 1) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit quad in the xy plane facing +z, u along +x and v along +y:
    /// its tangent is +x, and the bitangent n × t = +y runs up the image
    /// (w = 1); mirrored in u, the tangent turns to −x and w stays.
    #[test]
    fn a_quads_tangent_runs_along_u() {
        let quad = |us: [f32; 4]| TriangleMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
            uvs: Some(vec![[us[0], 0.0], [us[1], 0.0], [us[2], 1.0], [us[3], 1.0]]),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            material: vec![0, 0],
            ..TriangleMesh::default()
        };
        let mut plain = quad([0.0, 1.0, 1.0, 0.0]);
        assert!(generate(&mut plain));
        for t in plain.tangents.as_ref().unwrap() {
            assert!((t[0] - 1.0).abs() < 1e-5 && t[3] == 1.0, "{t:?}");
        }
        let mut mirrored = quad([1.0, 0.0, 0.0, 1.0]);
        assert!(generate(&mut mirrored));
        for t in mirrored.tangents.as_ref().unwrap() {
            assert!((t[0] + 1.0).abs() < 1e-5 && t[3] == -1.0, "{t:?}");
        }
    }

    /// Two triangles sharing an edge whose texture is mirrored across it:
    /// the shared vertices are split, each copy with its side's tangent.
    #[test]
    fn a_mirror_seam_splits_its_vertices() {
        let mut mesh = TriangleMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
            ],
            normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
            // u runs right on the left triangle and left on the right one.
            uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.0]]),
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            material: vec![0, 0],
            ..TriangleMesh::default()
        };
        assert!(generate(&mut mesh));
        assert_eq!(mesh.positions.len(), 6, "vertices 1 and 2 split");
        let tangents = mesh.tangents.as_ref().unwrap();
        assert_eq!(tangents.len(), 6);
        let right = mesh.triangles[1].map(|v| tangents[v as usize][0]);
        assert!(right.iter().all(|x| *x < -0.9), "{right:?}");
        let left = mesh.triangles[0].map(|v| tangents[v as usize][0]);
        assert!(left.iter().all(|x| *x > 0.9), "{left:?}");
    }
}
