//! Stanford PLY, ASCII or binary of either byte order, read with `ply-rs-bw`.
//!
//! The `vertex` element gives the positions (`x`, `y`, `z`), and the normals
//! (`nx`, `ny`, `nz`) and texture coordinates (`u`/`v`, `s`/`t` or
//! `texture_u`/`texture_v`) when every vertex has them. Each `face`'s
//! `vertex_indices` (or `vertex_index`) list is a polygon, fanned into
//! triangles from its first vertex. Other elements and properties (colours,
//! edges, scanner data) are read past. PLY has no materials: its triangles
//! take the scene's material, or the default grey.

use super::{fan, MeshError, Model, TriangleMesh, NO_MATERIAL};
use glam::Mat4;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{Encoding, Property, PropertyAccess, PropertyAccessResult};
use std::path::Path;

/// One vertex as read: each field with the bits of the components found.
#[derive(Default)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    /// Bits 0–2: x, y, z; 3–5: nx, ny, nz; 6–7: u, v.
    found: u8,
}

impl Vertex {
    const POSITION: u8 = 0b111;
    const NORMAL: u8 = 0b111 << 3;
    const UV: u8 = 0b11 << 6;
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let (slot, bit) = match name {
            "x" => (&mut self.position[0], 0),
            "y" => (&mut self.position[1], 1),
            "z" => (&mut self.position[2], 2),
            "nx" => (&mut self.normal[0], 3),
            "ny" => (&mut self.normal[1], 4),
            "nz" => (&mut self.normal[2], 5),
            "u" | "s" | "texture_u" | "texture_s" => (&mut self.uv[0], 6),
            "v" | "t" | "texture_v" | "texture_t" => (&mut self.uv[1], 7),
            _ => return PropertyAccessResult::Ignored,
        };
        match property.to_f32_lossy() {
            Some(value) => {
                *slot = value;
                self.found |= 1 << bit;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::UnsupportedType,
        }
    }
}

/// One face as read: its vertex indices, or `None` when a list held a
/// negative index.
#[derive(Default)]
struct Face {
    indices: Option<Vec<u32>>,
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if name != "vertex_indices" && name != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        self.indices = property.to_u32_list();
        PropertyAccessResult::Set
    }
}

/// An element that is read past.
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

/// Reads a PLY file's `bytes` (named `path` in errors).
pub(super) fn load(path: &Path, bytes: Vec<u8>) -> Result<Model, MeshError> {
    let located = |e: ParseError| MeshError::new(path, e.line(), ply_message(&e));
    let mut reader = Reader::new(bytes.as_slice());
    let header = Parser::<Skipped>::new()
        .read_header(&mut reader)
        .map_err(located)?;
    // Lines mean something in the header and in an ASCII payload only.
    let ascii = header.encoding == Encoding::Ascii;
    let located = |e: ParseError| {
        let line = if ascii { e.line() } else { None };
        MeshError::new(path, line, ply_message(&e))
    };
    let mut vertices: Option<Vec<Vertex>> = None;
    let mut faces: Vec<Face> = Vec::new();
    for element in header.elements.values() {
        match element.name.as_str() {
            "vertex" => {
                let read = Parser::<Vertex>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(located)?;
                vertices = Some(read);
            }
            "face" => {
                faces = Parser::<Face>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(located)?;
            }
            _ => {
                Parser::<Skipped>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(located)?;
            }
        }
    }
    let Some(vertices) = vertices else {
        return Err(MeshError::new(path, None, "no `vertex` element"));
    };
    let (mesh, skipped_degenerate) =
        build_mesh(&vertices, &faces).map_err(|why| MeshError::new(path, None, why))?;
    Model {
        meshes: vec![mesh],
        materials: Vec::new(),
        instances: vec![(0, Mat4::IDENTITY)],
        skipped_degenerate,
        ..Model::default()
    }
    .finish(path)
}

/// The first line of the parser's message, without its own "Line N: "
/// prefix (the error's location is shown by [`MeshError`]); the rest is
/// the parser's grammar, of no help to a reader of the file.
fn ply_message(e: &ParseError) -> String {
    let text = e.to_string();
    let text = match (e.line(), text.split_once(": ")) {
        (Some(_), Some((prefix, rest))) if prefix.starts_with("Line ") => rest,
        _ => &text,
    };
    let first = text
        .lines()
        .next()
        .unwrap_or("")
        .trim()
        .trim_end_matches('.');
    format!("malformed PLY: {}", first.to_lowercase())
}

/// The mesh of `vertices` and `faces` and the number of zero-area
/// triangles skipped, or what is wrong with them.
fn build_mesh(vertices: &[Vertex], faces: &[Face]) -> Result<(TriangleMesh, usize), String> {
    let mut mesh = TriangleMesh::default();
    mesh.positions.reserve_exact(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        if v.found & Vertex::POSITION != Vertex::POSITION {
            return Err(format!("vertex {i} lacks one of x, y and z"));
        }
        if !v.position.iter().all(|c| c.is_finite()) {
            return Err(format!(
                "vertex {i}: position {:?} is not finite (NaN or infinite)",
                v.position
            ));
        }
        mesh.positions.push(v.position);
    }
    let every = |bits: u8| vertices.iter().all(|v| v.found & bits == bits);
    if every(Vertex::NORMAL) {
        mesh.normals = Some(vertices.iter().map(|v| v.normal).collect());
    }
    if every(Vertex::UV) {
        mesh.uvs = Some(vertices.iter().map(|v| v.uv).collect());
    }
    let count = vertices.len();
    let mut skipped = 0;
    for (f, face) in faces.iter().enumerate() {
        let Some(indices) = &face.indices else {
            return Err(format!(
                "face {f} has no vertex_indices list, or a negative index"
            ));
        };
        if indices.len() < 3 {
            return Err(format!(
                "face {f} has {} vertices; a face needs at least 3",
                indices.len()
            ));
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(format!(
                "face {f}: vertex index {bad} out of range (the file has {count} vertices)"
            ));
        }
        for triangle in fan(indices) {
            if !mesh.push_triangle(triangle, NO_MATERIAL) {
                skipped += 1;
            }
        }
    }
    Ok((mesh, skipped))
}
