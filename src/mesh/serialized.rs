//! Mitsuba's `.serialized` meshes: one or more indexed triangle meshes,
//! each a little-endian header (format 0x041C and a version) followed by a
//! zlib stream, and at the end of the file a table of where each mesh
//! starts and how many there are.
//!
//! Versions 3 and 4 (Mitsuba 0.5 to 3.x) store per-vertex arrays:
//! positions, then normals, texture coordinates and colours as the flags
//! say, in single or double precision, then the triangles' `u32` indices;
//! version 4 names the mesh. Version 5 (Mitsuba's packed records) stores
//! eight floats a vertex (position, normal, texture coordinates) and four
//! `u32`s a face (three indices and a BSDF index), maps lumen does not
//! need, and custom attributes, which are skipped. Every mesh of the file
//! becomes a mesh of the model, placed once where it is (a scene picks one
//! by its index, Mitsuba's `shape_index`).
//!
//! Texture coordinates are Mitsuba's, v down the image (v = 0 its top
//! row); lumen's v runs up the image, so v is turned over as it is read.

use super::{MeshError, Model};
use flate2::read::ZlibDecoder;
use glam::Mat4;
use std::io::Read;
use std::path::Path;

/// The first two bytes of every mesh: Mitsuba's file-format identifier.
const MAGIC: u16 = 0x041C;

/// Flags of versions 3 and 4.
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Version 5's vertex layout bits.
const V5_NORMALS: u32 = 0x1;
const V5_TANGENTS: u32 = 0x2;
const V5_TEXCOORDS: u32 = 0x4;

/// The most a deflate stream expands: 1,032 bytes out per byte in (a
/// block of 258-byte matches, each coded in two bits). A mesh declaring
/// more data than its compressed bytes could hold is refused before
/// anything is allocated for it.
const MAX_EXPANSION: u64 = 1032;

/// Reads the `.serialized` file `path` of contents `bytes`.
pub(super) fn load(path: &Path, bytes: Vec<u8>) -> Result<Model, MeshError> {
    let fail = |message: String| MeshError::new(path, None, message);
    let starts = mesh_starts(&bytes).map_err(fail)?;
    let mut model = Model::default();
    for (i, &(start, end)) in starts.iter().enumerate() {
        let mut one = read_mesh(&bytes[start..end]).map_err(|e| {
            let which = if starts.len() > 1 {
                format!("mesh {i} (at byte {start}): ")
            } else {
                String::new()
            };
            fail(format!("{which}{e}"))
        })?;
        model.skipped_degenerate += one.skipped_degenerate;
        model.instances.push((model.meshes.len(), Mat4::IDENTITY));
        model.meshes.append(&mut one.meshes);
    }
    Ok(model)
}

/// Where each mesh of the file lies: (first byte, one past the last).
fn mesh_starts(bytes: &[u8]) -> Result<Vec<(usize, usize)>, String> {
    let header = |at: usize| -> Option<(u16, u16)> {
        let b = bytes.get(at..at + 4)?;
        Some((
            u16::from_le_bytes([b[0], b[1]]),
            u16::from_le_bytes([b[2], b[3]]),
        ))
    };
    let Some((MAGIC, version)) = header(0) else {
        return Err("not a Mitsuba serialized mesh: it does not start with 0x041C".into());
    };
    if !(3..=5).contains(&version) {
        return Err(format!(
            "serialized format version {version}; lumen reads versions 3, 4 and 5"
        ));
    }
    // The table at the end: the offsets (u32 in version 3, u64 later),
    // then their count (u32).
    let n = bytes.len();
    let count = bytes
        .get(n.saturating_sub(4)..)
        .filter(|_| n >= 8)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        .ok_or("the file is too short for a mesh")?;
    let width = if version == 3 { 4 } else { 8 };
    let table = count
        .checked_mul(width)
        .and_then(|t| t.checked_add(4))
        .filter(|&t| count >= 1 && t < n)
        .ok_or_else(|| {
            format!(
                "the table at the end of the file names {count} meshes, which the file cannot hold"
            )
        })?;
    let table_start = n - table;
    let offsets: Vec<usize> = bytes[table_start..n - 4]
        .chunks_exact(width)
        .map(|c| {
            let mut b = [0u8; 8];
            b[..width].copy_from_slice(c);
            u64::from_le_bytes(b) as usize
        })
        .collect();
    let mut starts = Vec::with_capacity(count);
    for (i, &start) in offsets.iter().enumerate() {
        let end = offsets.get(i + 1).copied().unwrap_or(table_start);
        if start >= end || end > table_start || header(start) != Some((MAGIC, version)) {
            return Err(format!(
                "the table at the end of the file puts mesh {i} at byte {start}, where no mesh of version {version} starts"
            ));
        }
        starts.push((start, end));
    }
    Ok(starts)
}

/// The mesh (as a model of it alone) whose header and compressed data
/// are `bytes`.
fn read_mesh(bytes: &[u8]) -> Result<Model, String> {
    let version = u16::from_le_bytes([bytes[2], bytes[3]]);
    let budget = (bytes.len() as u64 - 4).saturating_mul(MAX_EXPANSION);
    let mut z = Stream {
        inner: ZlibDecoder::new(&bytes[4..]),
        budget,
    };
    let flags = z.u32()?;
    let arrays = if version == 5 {
        packed(&mut z, flags)?
    } else {
        legacy(&mut z, version, flags)?
    };
    // With face normals the mesh is shaded flat: its vertex normals unused.
    let normals = arrays.normals.filter(|_| flags & FACE_NORMALS == 0);
    Model::from_arrays(arrays.positions, &arrays.triangles, normals, arrays.uvs)
}

/// A mesh's arrays, texture coordinates turned to lumen's v up.
struct Arrays {
    positions: Vec<[f32; 3]>,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    triangles: Vec<[u32; 3]>,
}

/// The counts of vertices and triangles that follow in `z`, refused past
/// what a mesh's `u32` indices reach.
fn counts(z: &mut Stream) -> Result<(u64, u64), String> {
    let (vertices, faces) = (z.u64()?, z.u64()?);
    if vertices > u64::from(u32::MAX) || faces > u64::from(u32::MAX) {
        return Err(format!(
            "it declares {vertices} vertices and {faces} triangles; lumen reads up to {} of each",
            u32::MAX
        ));
    }
    Ok((vertices, faces))
}

/// A version 5 mesh after its flags: its name, counts, packed vertex and
/// face records, and the maps after them (read past, not kept).
fn packed(z: &mut Stream, flags: u32) -> Result<Arrays, String> {
    let name = z.u32()?;
    z.skip(u64::from(name))?;
    let layout = flags & 0x7;
    if layout & V5_TANGENTS != 0 {
        return Err("it stores tangent frames, which lumen does not read".into());
    }
    let (vertices, faces) = counts(z)?;
    let (points, groups) = (z.u64()?, z.u64()?);
    z.declares(vertices * 32 + faces * 16)?;
    let records = z.f32s(vertices * 8, false)?;
    let face_records = z.u32s(faces * 4)?;
    // The maps to surface points and normal groups: not needed.
    z.skip(if points > 0 { vertices * 4 } else { 0 } + if groups > 0 { vertices * 4 } else { 0 })?;
    let vertex = || records.chunks_exact(8);
    Ok(Arrays {
        positions: vertex().map(|r| [r[0], r[1], r[2]]).collect(),
        normals: (layout & V5_NORMALS != 0).then(|| vertex().map(|r| [r[3], r[4], r[5]]).collect()),
        uvs: (layout & V5_TEXCOORDS != 0).then(|| vertex().map(|r| [r[6], 1.0 - r[7]]).collect()),
        triangles: face_records
            .chunks_exact(4)
            .map(|f| [f[0], f[1], f[2]])
            .collect(),
    })
}

/// A version 3 or 4 mesh after its flags: its name (version 4), counts,
/// and arrays of positions, normals, texture coordinates and colours (read
/// past, not kept) as the flags say, then the triangles' indices.
fn legacy(z: &mut Stream, version: u16, flags: u32) -> Result<Arrays, String> {
    if version == 4 {
        // The name, ended by a NUL.
        while z.u8()? != 0 {}
    }
    let (vertices, faces) = counts(z)?;
    let (normals, uvs, colors) = (
        flags & HAS_NORMALS != 0,
        flags & HAS_TEXCOORDS != 0,
        flags & HAS_COLORS != 0,
    );
    let double = flags & DOUBLE_PRECISION != 0;
    let real = if double { 8 } else { 4 };
    let per_vertex = 3 + 3 * u64::from(normals) + 2 * u64::from(uvs) + 3 * u64::from(colors);
    z.declares(vertices * per_vertex * real + faces * 12)?;
    let triples = |v: Vec<f32>| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let positions = triples(z.f32s(vertices * 3, double)?);
    let normals = if normals {
        Some(triples(z.f32s(vertices * 3, double)?))
    } else {
        None
    };
    let uvs = if uvs {
        let values = z.f32s(vertices * 2, double)?;
        Some(values.chunks_exact(2).map(|c| [c[0], 1.0 - c[1]]).collect())
    } else {
        None
    };
    if colors {
        z.skip(vertices * 3 * real)?;
    }
    let indices = z.u32s(faces * 3)?;
    Ok(Arrays {
        positions,
        normals,
        uvs,
        triangles: indices
            .chunks_exact(3)
            .map(|f| [f[0], f[1], f[2]])
            .collect(),
    })
}

/// A mesh's decompressed data, read in order.
struct Stream<'a> {
    inner: ZlibDecoder<&'a [u8]>,
    /// The most bytes the compressed data can expand to.
    budget: u64,
}

impl Stream<'_> {
    /// Refuses a mesh whose arrays (`bytes` of them) its compressed data
    /// could not hold, and one the memory cannot.
    fn declares(&self, bytes: u64) -> Result<(), String> {
        if bytes > self.budget {
            return Err(format!(
                "it declares {bytes} bytes of vertices and triangles, more than its compressed data can hold ({} at most)",
                self.budget
            ));
        }
        // Read data is held about twice while converted.
        crate::memory::check(bytes.saturating_mul(2), "the mesh").map_err(|e| e.to_string())
    }

    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut b = [0u8; N];
        self.inner.read_exact(&mut b).map_err(truncated)?;
        Ok(b)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.bytes::<1>()?[0])
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }

    /// Passes over `n` bytes.
    fn skip(&mut self, n: u64) -> Result<(), String> {
        let copied = std::io::copy(&mut (&mut self.inner).take(n), &mut std::io::sink())
            .map_err(truncated)?;
        if copied < n {
            return Err(truncated(std::io::ErrorKind::UnexpectedEof.into()));
        }
        Ok(())
    }

    /// `n` little-endian `u32`s.
    fn u32s(&mut self, n: u64) -> Result<Vec<u32>, String> {
        let mut out = Vec::with_capacity(n as usize);
        self.chunks(n, 4, |b| {
            out.push(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        })?;
        Ok(out)
    }

    /// `n` little-endian reals, as `f32` (from `f64`s when `double`).
    fn f32s(&mut self, n: u64, double: bool) -> Result<Vec<f32>, String> {
        let mut out = Vec::with_capacity(n as usize);
        if double {
            self.chunks(n, 8, |b| {
                let mut a = [0u8; 8];
                a.copy_from_slice(b);
                out.push(f64::from_le_bytes(a) as f32);
            })?;
        } else {
            self.chunks(n, 4, |b| {
                out.push(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            })?;
        }
        if let Some(bad) = out.iter().position(|v| !v.is_finite()) {
            return Err(format!("value {bad} of an array is not a finite number"));
        }
        Ok(out)
    }

    /// Reads `n` values of `size` bytes, a block at a time, handing each
    /// value's bytes to `each`.
    fn chunks(&mut self, n: u64, size: usize, mut each: impl FnMut(&[u8])) -> Result<(), String> {
        let mut buffer = vec![0u8; 1 << 16];
        let mut left = n as usize * size;
        while left > 0 {
            let take = left.min(buffer.len());
            self.inner
                .read_exact(&mut buffer[..take])
                .map_err(truncated)?;
            buffer[..take].chunks_exact(size).for_each(&mut each);
            left -= take;
        }
        Ok(())
    }
}

/// The message for compressed data that ends early or is not zlib data.
fn truncated(e: std::io::Error) -> String {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        "its compressed data ends before the mesh does".into()
    } else {
        format!("its compressed data is corrupt ({e})")
    }
}
