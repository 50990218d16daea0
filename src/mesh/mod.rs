//! Triangle meshes from files: Wavefront OBJ (with its MTL materials),
//! glTF 2.0 (`.gltf` with external or embedded buffers, and binary `.glb`),
//! Stanford PLY (ASCII or binary) and Mitsuba's `.serialized` meshes.
//!
//! [`load`] picks the loader by extension and returns a [`Model`]: indexed
//! [`TriangleMesh`]es, their [`MeshMaterial`]s and the [`Model::instances`]
//! that place each mesh. Every problem with a file is a [`MeshError`] naming
//! the file (and the line, for OBJ, MTL and ASCII PLY); no input makes the
//! loaders panic.
//!
//! Memory: a triangle costs its three `u32` indices and one `u32` material
//! index, 16 bytes; a vertex costs 12 bytes of position, plus 12 of normal and
//! 8 of texture coordinates when the file has them. The bundled bunny (1,839
//! vertices, 3,674 triangles, positions only) takes 80,852 bytes, 22.0 bytes
//! per triangle (checked by a test).
//!
//! ```no_run
//! let model = lumen::mesh::load(std::path::Path::new("assets/bunny.obj")).unwrap();
//! let triangles: usize = model.meshes.iter().map(|m| m.triangles.len()).sum();
//! println!("{triangles} triangles, {} skipped", model.skipped_degenerate);
//! ```

mod gltf;
pub mod loop_subdivision;
pub mod material;
mod obj;
mod ply;
mod serialized;
mod tangents;

pub use material::{AlphaMode, Mapped, MeshMaterial};

use glam::Mat4;
use std::fmt;
use std::path::{Path, PathBuf};

/// Material index of a triangle whose file gives it no material.
pub const NO_MATERIAL: u32 = u32::MAX;

/// Index of refraction used when a transmissive material states none.
pub const DEFAULT_IOR: f32 = 1.5;

/// An indexed triangle mesh: shared vertices stored once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions in object space.
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex normals as written in the file (not renormalised), indexed
    /// like `positions`, for smooth shading; `None` unless every vertex of the
    /// mesh has one.
    pub normals: Option<Vec<[f32; 3]>>,
    /// Per-vertex texture coordinates, indexed like `positions`; `None` unless
    /// every vertex of the mesh has them.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// A second set of texture coordinates (glTF `TEXCOORD_1`), indexed
    /// like `positions`; `None` unless every vertex has them.
    pub uvs1: Option<Vec<[f32; 2]>>,
    /// Per-vertex colours and alpha (glTF `COLOR_0`, linear), indexed like
    /// `positions`; `None` unless every vertex has one.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Per-vertex tangents (glTF `TANGENT`: xyz along +u, w ±1 the
    /// bitangent's side, the bitangent being w · normal × tangent), indexed
    /// like `positions`; `None` unless every vertex has one.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Vertex indices of each triangle, counter-clockwise seen from the front
    /// as in the file. No triangle has zero area.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle: index into [`Model::materials`], or [`NO_MATERIAL`].
    pub material: Vec<u32>,
}

impl TriangleMesh {
    /// Bytes held on the heap by the mesh's arrays (their capacity).
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.positions.capacity() * size_of::<[f32; 3]>()
            + self
                .normals
                .as_ref()
                .map_or(0, |n| n.capacity() * size_of::<[f32; 3]>())
            + self
                .uvs
                .as_ref()
                .map_or(0, |t| t.capacity() * size_of::<[f32; 2]>())
            + self
                .uvs1
                .as_ref()
                .map_or(0, |t| t.capacity() * size_of::<[f32; 2]>())
            + self
                .colors
                .as_ref()
                .map_or(0, |t| t.capacity() * size_of::<[f32; 4]>())
            + self
                .tangents
                .as_ref()
                .map_or(0, |t| t.capacity() * size_of::<[f32; 4]>())
            + self.triangles.capacity() * size_of::<[u32; 3]>()
            + self.material.capacity() * size_of::<u32>()
    }

    /// Appends triangle `tri` with material `material` unless it has zero
    /// area (a repeated index, or vertices on one line); returns whether it
    /// was kept. The indices must be in range.
    fn push_triangle(&mut self, tri: [u32; 3], material: u32) -> bool {
        if !has_area(&self.positions, tri) {
            return false;
        }
        self.triangles.push(tri);
        self.material.push(material);
        true
    }

    /// Releases spare capacity once loading is done.
    fn shrink_to_fit(&mut self) {
        self.positions.shrink_to_fit();
        if let Some(n) = &mut self.normals {
            n.shrink_to_fit();
        }
        if let Some(t) = &mut self.uvs {
            t.shrink_to_fit();
        }
        if let Some(t) = &mut self.uvs1 {
            t.shrink_to_fit();
        }
        if let Some(t) = &mut self.colors {
            t.shrink_to_fit();
        }
        if let Some(t) = &mut self.tangents {
            t.shrink_to_fit();
        }
        self.triangles.shrink_to_fit();
        self.material.shrink_to_fit();
    }
}

impl Model {
    /// A model of one mesh given by its arrays (a mesh written out in a
    /// scene file), placed once as it is; triangles of zero area are
    /// skipped and counted. What is wrong is said in a sentence.
    pub fn from_arrays(
        positions: Vec<[f32; 3]>,
        triangles: &[[u32; 3]],
        normals: Option<Vec<[f32; 3]>>,
        uvs: Option<Vec<[f32; 2]>>,
    ) -> Result<Model, String> {
        let n = positions.len();
        if let Some(normals) = &normals {
            if normals.len() != n {
                return Err(format!(
                    "`normals` has {} entries for {n} positions: give one per position",
                    normals.len()
                ));
            }
        }
        if let Some(uvs) = &uvs {
            if uvs.len() != n {
                return Err(format!(
                    "`uvs` has {} entries for {n} positions: give one per position",
                    uvs.len()
                ));
            }
        }
        if let Some((t, i)) = triangles
            .iter()
            .enumerate()
            .find_map(|(t, tri)| tri.iter().find(|&&i| i as usize >= n).map(|&i| (t, i)))
        {
            return Err(format!(
                "`indices[{t}]` names vertex {i}, but there are {n} positions (0 to {})",
                n.saturating_sub(1)
            ));
        }
        let mut mesh = TriangleMesh {
            positions,
            normals,
            uvs,
            ..TriangleMesh::default()
        };
        let mut skipped = 0;
        for &tri in triangles {
            skipped += usize::from(!mesh.push_triangle(tri, NO_MATERIAL));
        }
        mesh.shrink_to_fit();
        Ok(Model {
            meshes: vec![mesh],
            instances: vec![(0, Mat4::IDENTITY)],
            skipped_degenerate: skipped,
            ..Model::default()
        })
    }
}

/// Whether triangle `tri` of vertices `positions` has an area: no repeated
/// index, vertices not on one line. The indices must be in range.
fn has_area(positions: &[[f32; 3]], tri: [u32; 3]) -> bool {
    let [a, b, c] = tri;
    if a == b || b == c || a == c {
        return false;
    }
    // In f64 so that small but valid triangles do not round to zero area.
    let p = |i: u32| positions[i as usize].map(f64::from);
    let (pa, pb, pc) = (p(a), p(b), p(c));
    let u = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
    let v = [pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]];
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    cross != [0.0; 3]
}

/// The triangles of a convex polygon (or a glTF triangle fan) fanned from
/// its first vertex: (v₀, v₁, v₂), (v₀, v₂, v₃), …; none for fewer than three
/// vertices.
fn fan(polygon: &[u32]) -> impl Iterator<Item = [u32; 3]> + '_ {
    polygon
        .get(1..)
        .unwrap_or(&[])
        .windows(2)
        .map(|w| [polygon[0], w[0], w[1]])
}

/// Meshes, their materials and where they are placed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Model {
    /// The distinct meshes; a mesh placed several times is stored once.
    pub meshes: Vec<TriangleMesh>,
    /// The materials that [`TriangleMesh::material`] indexes.
    pub materials: Vec<MeshMaterial>,
    /// Where each mesh is placed: (index into `meshes`, column-major
    /// object-to-model matrix). OBJ: one identity instance per mesh. glTF:
    /// one per node with a mesh, with the composed transform of the node and
    /// its ancestors.
    pub instances: Vec<(usize, Mat4)>,
    /// Zero-area triangles (repeated index or collinear vertices) skipped
    /// while loading.
    pub skipped_degenerate: usize,
    /// glTF primitives of point or line modes, which have no surface and are
    /// skipped (triangle strips and fans are converted to triangles).
    pub skipped_primitives: usize,
    /// CRC-32 of the file's bytes, as read (a scene's identity holds it).
    pub file_crc: u32,
    /// The file's length in bytes, as read.
    pub file_len: u64,
    /// What the file holds that lumen does not render, one line each.
    pub warnings: Vec<String>,
    /// The file's cameras (glTF), in the order of its nodes.
    pub cameras: Vec<ModelCamera>,
}

/// A camera of a model file.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelCamera {
    /// Its name in the file, if it has one.
    pub name: Option<String>,
    /// Camera to model space (column-major): the camera looks along −z,
    /// +y up.
    pub transform: Mat4,
    /// How it projects.
    pub view: ModelView,
}

/// How a model's camera projects the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelView {
    /// Perspective, with this vertical field of view in radians.
    Perspective {
        /// The vertical field of view.
        yfov: f32,
    },
    /// Orthographic, seeing ±`ymag` up and down its frame's y.
    Orthographic {
        /// Half the height seen, in camera space.
        ymag: f32,
    },
}

impl Model {
    /// Total number of triangles over the distinct meshes (not instances).
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangles.len()).sum()
    }

    /// Total number of vertices over the distinct meshes.
    pub fn vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.positions.len()).sum()
    }

    /// Axis-aligned bounds (min, max) of all instances in model space, or
    /// `None` for a model without vertices.
    pub fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let mut lo = glam::Vec3::splat(f32::INFINITY);
        let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
        for &(mesh, m) in &self.instances {
            for p in &self.meshes[mesh].positions {
                let q = m.transform_point3(glam::Vec3::from_array(*p));
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo.x <= hi.x).then(|| (lo.to_array(), hi.to_array()))
    }

    /// Gives tangents (MikkTSpace) to the meshes that a normal-mapped
    /// material covers and whose file gives none, in parallel.
    fn generate_tangents(&mut self) {
        use rayon::prelude::*;
        let materials = &self.materials;
        let needs = |m: &TriangleMesh| {
            m.material.iter().any(|&i| {
                materials
                    .get(i as usize)
                    .is_some_and(MeshMaterial::needs_tangents)
            })
        };
        self.meshes.par_iter_mut().for_each(|m| {
            if needs(m) {
                tangents::generate(m);
            }
        });
    }

    /// Refuses a model without triangles and trims the arrays.
    fn finish(mut self, path: &Path) -> Result<Model, MeshError> {
        if self.triangle_count() == 0 {
            let why = if self.skipped_degenerate > 0 {
                format!(
                    "no triangles with area ({} degenerate skipped)",
                    self.skipped_degenerate
                )
            } else {
                "no triangles".to_string()
            };
            return Err(MeshError::new(path, None, why));
        }
        for m in &mut self.meshes {
            m.shrink_to_fit();
        }
        Ok(self)
    }
}

/// Why a mesh file could not be loaded. Displays as `FILE[:LINE]: message`,
/// for example `bunny.obj:12: face index 2000 out of range (the file has 1839
/// vertices)`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct MeshError {
    file: PathBuf,
    line: Option<usize>,
    message: String,
}

impl MeshError {
    fn new(file: &Path, line: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    /// The file at fault (an OBJ's MTL file when the error is in it).
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The 1-based line at fault, for text formats when it is known.
    pub fn line(&self) -> Option<usize> {
        self.line
    }

    /// What is wrong, without the location.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": {}", self.message)
    }
}

/// The file extensions [`load`] accepts.
pub const SUPPORTED_EXTENSIONS: [&str; 5] = ["obj", "gltf", "glb", "ply", "serialized"];

/// How a mesh file is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Whether the files a model names (glTF buffers and images, MTL files
    /// and their maps) may lie outside the model's folder. Off by default:
    /// scene files and models travel, and a model must not read the machine
    /// it is rendered on (`"uri": "/etc/passwd"`).
    pub allow_outside: bool,
    /// Turn texture coordinates over (v becomes 1 − v) for a file written
    /// with v down the image, as Mitsuba reads PLY files, where lumen's v
    /// runs up it.
    pub flip_v: bool,
}

/// Loads a mesh file, choosing the format by extension (case-insensitive):
/// `.obj` (with the MTL files it names; a missing MTL file only means no
/// materials), `.gltf`, `.glb` or `.ply` (no materials). The files the model
/// names must be inside its folder; see [`load_with`].
pub fn load(path: &Path) -> Result<Model, MeshError> {
    load_with(path, LoadOptions::default())
}

/// [`load`] with the given options.
pub fn load_with(path: &Path, options: LoadOptions) -> Result<Model, MeshError> {
    // What the file is matters before what it is called.
    crate::input::check(path).map_err(|e| MeshError::new(path, None, e.to_string()))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    type Reader = fn(&Path, Vec<u8>, LoadOptions) -> Result<Model, MeshError>;
    let format: Reader = match ext.as_deref() {
        Some("obj") => obj::load,
        Some("gltf") | Some("glb") => gltf::load,
        // PLY names no other file.
        Some("ply") => |path, bytes, _| ply::load(path, bytes),
        Some("serialized") => |path, bytes, _| serialized::load(path, bytes),
        _ => {
            return Err(MeshError::new(
                path,
                None,
                format!(
                    "unsupported mesh format; the supported extensions are {}",
                    SUPPORTED_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
                ),
            ))
        }
    };
    let bytes = read_file(path)?;
    let (file_crc, file_len) = (crc32fast::hash(&bytes), bytes.len() as u64);
    let mut model = Model {
        file_crc,
        file_len,
        ..format(path, bytes, options)?
    };
    if options.flip_v {
        for mesh in &mut model.meshes {
            for uv in mesh.uvs.iter_mut().chain(&mut mesh.uvs1).flatten() {
                uv[1] = 1.0 - uv[1];
            }
        }
    }
    model.generate_tangents();
    Ok(model)
}

/// Reads a whole mesh file: a regular file of at most
/// [`MAX_MESH_BYTES`](crate::input::MAX_MESH_BYTES).
fn read_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    crate::input::read(path, crate::input::MAX_MESH_BYTES)
        .map_err(|e| MeshError::new(path, None, e.to_string()))
}

/// Checks that the model whose folder is `folder` may read `path` (a file
/// it names, written `shown`): inside `folder`, once links and `..` are
/// resolved, unless `options` allow files outside. A file that does not
/// exist passes, for the reader to report.
pub(crate) fn confined(
    folder: &Path,
    path: &Path,
    shown: &str,
    options: LoadOptions,
) -> Result<(), String> {
    if options.allow_outside {
        return Ok(());
    }
    let outside = || {
        format!(
            "`{shown}` is outside the model's folder; a model reads only files in its folder \
             unless its mesh object sets `allow_outside = true` (or lumen is given --allow-outside)"
        )
    };
    // Refused as written, before anything is looked up.
    let inside = path.strip_prefix(folder).ok().and_then(|rel| {
        rel.components().try_fold(0usize, |depth, c| match c {
            std::path::Component::ParentDir => depth.checked_sub(1),
            std::path::Component::Normal(_) => Some(depth + 1),
            std::path::Component::CurDir => Some(depth),
            _ => None,
        })
    });
    if inside.is_none() {
        return Err(outside());
    }
    // And as found: a link inside the folder may lead out of it.
    let dir = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    match (std::fs::canonicalize(dir), std::fs::canonicalize(path)) {
        (Ok(dir), Ok(found)) if !found.starts_with(&dir) => Err(outside()),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod gltf_material_tests;
#[cfg(test)]
mod ply_tests;
#[cfg(test)]
mod tests;
