//! Wavefront OBJ and MTL, parsed by `tobj` with faces triangulated as fans and
//! one index shared by position, normal and texture coordinate.
//!
//! `tobj` reports errors without a line, so when it fails (or a value it
//! accepted turns out unusable, such as an infinite coordinate) a light scan
//! of the text finds the line at fault. One scan runs before `tobj`: it checks
//! the face lines, because `tobj` quietly turns faces of one or two vertices
//! into zero-area triangles and its index arithmetic can overflow on huge
//! relative indices.
//!
//! Each object or group (`o`, `g`) becomes one [`TriangleMesh`] with one
//! identity instance; `usemtl` switches only the per-triangle material.
//! Line (`l`) and point (`p`) elements have no surface and are ignored.

use super::{MeshError, MeshMaterial, Model, TriangleMesh, NO_MATERIAL};
use crate::texture::Image;
use glam::Mat4;
use std::borrow::Cow;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Loads an OBJ file and the MTL files it names.
/// `bytes` are the file's content.
pub(super) fn load(path: &Path, bytes: Vec<u8>) -> Result<Model, MeshError> {
    let text = utf8(path, &bytes)?;
    let text = check_faces(path, text)?;

    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mtl_error: RefCell<Option<MeshError>> = RefCell::new(None);
    // The MTL file read, whose directory its images are relative to.
    let mtl_path: RefCell<Option<PathBuf>> = RefCell::new(None);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = tobj::load_obj_buf(&mut text.as_bytes(), &options, |name| {
        if name.as_os_str().is_empty() {
            // `mtllib` without a file name: nothing to load.
            return Err(tobj::LoadError::OpenFileFailed);
        }
        let file = dir.join(name);
        *mtl_path.borrow_mut() = Some(file.clone());
        load_mtl(&file, &mtl_error)
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = result.map_err(|e| obj_error(path, &text, e))?;
    // A missing MTL file leaves the materials empty (or an error that only
    // says so); the triangles then have no material.
    let materials: Vec<MeshMaterial> = materials
        .unwrap_or_default()
        .iter()
        .map(|m| convert_material(m, mtl_path.borrow().as_deref().unwrap_or(path)))
        .collect::<Result<_, _>>()?;

    let mut model = Model {
        materials,
        ..Model::default()
    };
    let mut current: Option<(String, Builder)> = None;
    for m in &models {
        check_finite(path, &text, &m.mesh)?;
        // tobj splits an object at every `usemtl`; rejoin the pieces.
        match &mut current {
            Some((name, b)) if *name == m.name => b.append(&m.mesh, &mut model),
            _ => {
                if let Some((_, b)) = current.take() {
                    b.finish(&mut model);
                }
                let mut b = Builder::default();
                b.append(&m.mesh, &mut model);
                current = Some((m.name.clone(), b));
            }
        }
    }
    if let Some((_, b)) = current {
        b.finish(&mut model);
    }
    model.finish(path)
}

/// A mesh assembled from the consecutive tobj pieces of one object.
#[derive(Default)]
struct Builder {
    mesh: TriangleMesh,
    /// Set once a piece lacks normals (resp. texture coordinates).
    missing_normals: bool,
    missing_uvs: bool,
}

impl Builder {
    fn append(&mut self, piece: &tobj::Mesh, model: &mut Model) {
        let base = self.mesh.positions.len() as u32;
        let n = piece.positions.len() / 3;
        self.mesh
            .positions
            .extend(piece.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if piece.normals.len() == 3 * n && !self.missing_normals {
            self.mesh
                .normals
                .get_or_insert_with(Vec::new)
                .extend(piece.normals.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        } else {
            self.missing_normals = true;
        }
        if piece.texcoords.len() == 2 * n && !self.missing_uvs {
            self.mesh
                .uvs
                .get_or_insert_with(Vec::new)
                .extend(piece.texcoords.chunks_exact(2).map(|t| [t[0], t[1]]));
        } else {
            self.missing_uvs = true;
        }
        let material = match piece.material_id {
            Some(id) if id < model.materials.len() => id as u32,
            _ => NO_MATERIAL,
        };
        for t in piece.indices.chunks_exact(3) {
            // tobj indices are within the piece's own vertices.
            let tri = [t[0] + base, t[1] + base, t[2] + base];
            if !self.mesh.push_triangle(tri, material) {
                model.skipped_degenerate += 1;
            }
        }
    }

    fn finish(mut self, model: &mut Model) {
        if self.missing_normals {
            self.mesh.normals = None;
        }
        if self.missing_uvs {
            self.mesh.uvs = None;
        }
        if !self.mesh.triangles.is_empty() {
            model.instances.push((model.meshes.len(), Mat4::IDENTITY));
            model.meshes.push(self.mesh);
        }
    }
}

/// The text of a file, or an error at the first line that is not UTF-8.
fn utf8<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, MeshError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = line_of_offset(bytes, e.valid_up_to());
        MeshError::new(path, Some(line), "not UTF-8 text")
    })
}

/// 1-based line number of byte `offset`.
fn line_of_offset(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count()
}

/// The lines of `text` with their 1-based numbers, split on whitespace.
fn lines(text: &str) -> impl Iterator<Item = (usize, &str, std::str::SplitWhitespace<'_>)> {
    text.lines().enumerate().map(|(i, line)| {
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        (i + 1, keyword, words)
    })
}

/// Checks every face line: at least three vertices, each `v`, `v/vt`,
/// `v//vn` or `v/vt/vn` with integer indices that are not 0 and refer to an
/// existing element (negative ones counting back from the line). Returns the
/// text to give tobj: line and point elements blanked out, since tobj would
/// make a triangle of a three-point polyline.
fn check_faces<'a>(path: &Path, text: &'a str) -> Result<Cow<'a, str>, MeshError> {
    let mut totals = [0usize; 3];
    let mut has_polylines = false;
    for (_, keyword, _) in lines(text) {
        match keyword {
            "v" => totals[0] += 1,
            "vt" => totals[1] += 1,
            "vn" => totals[2] += 1,
            "l" | "p" => has_polylines = true,
            _ => {}
        }
    }
    const WHAT: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    const PLURAL: [&str; 3] = ["vertices", "texture coordinates", "normals"];
    let mut so_far = [0usize; 3];
    for (line, keyword, words) in lines(text) {
        let at = |msg: String| MeshError::new(path, Some(line), msg);
        match keyword {
            "v" => so_far[0] += 1,
            "vt" => so_far[1] += 1,
            "vn" => so_far[2] += 1,
            "f" => {
                let mut count = 0;
                for word in words {
                    count += 1;
                    let parts: Vec<&str> = word.split('/').collect();
                    if parts.len() > 3 || parts[0].is_empty() {
                        return Err(at(format!(
                            "face vertex `{word}` is not v, v/vt, v//vn or v/vt/vn"
                        )));
                    }
                    for (k, part) in parts.iter().enumerate() {
                        if part.is_empty() {
                            continue;
                        }
                        let Ok(i) = part.parse::<i64>() else {
                            return Err(at(format!("face index `{part}` is not an integer")));
                        };
                        let what = WHAT[k];
                        if i == 0 {
                            return Err(at(format!(
                                "face {what} index 0 is invalid (OBJ indices start at 1)"
                            )));
                        }
                        let in_range = if i > 0 {
                            i as u64 <= totals[k] as u64
                        } else {
                            i.unsigned_abs() <= so_far[k] as u64
                        };
                        if !in_range {
                            let (count, whence) = if i > 0 {
                                (totals[k], "the file has")
                            } else {
                                (so_far[k], "this line follows")
                            };
                            let label = if k == 0 {
                                "face index".to_string()
                            } else {
                                format!("face {what} index")
                            };
                            return Err(at(format!(
                                "{label} {i} out of range ({whence} {count} {})",
                                PLURAL[k]
                            )));
                        }
                    }
                }
                if count < 3 {
                    return Err(at(format!(
                        "face with {count} vertices; a face needs at least 3"
                    )));
                }
            }
            _ => {}
        }
    }
    if !has_polylines {
        return Ok(Cow::Borrowed(text));
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let keyword = line.split_whitespace().next().unwrap_or("");
        if keyword != "l" && keyword != "p" {
            out.push_str(line);
        }
        out.push('\n');
    }
    Ok(Cow::Owned(out))
}

/// Turns a tobj error into one that names the line at fault, found by a scan
/// for the first line that breaks the rule tobj reports.
fn obj_error(path: &Path, text: &str, e: tobj::LoadError) -> MeshError {
    use tobj::LoadError as E;
    let parses = |w: &str| w.parse::<f32>().is_ok();
    let found = lines(text).find_map(|(line, keyword, words)| {
        let words: Vec<&str> = words.collect();
        let bad = match (e, keyword) {
            (E::PositionParseError | E::ScalingByZeroError | E::ColorParseError, "v") => {
                if words.len() < 3 || !words[..3].iter().all(|w| parses(w)) {
                    Some("vertex position needs three numbers".to_string())
                } else {
                    match words.len() {
                        3 | 6 => None,
                        4 => match words[3].parse::<f32>() {
                            Ok(w) if w != 0.0 => None,
                            Ok(_) => Some("vertex weight w is 0".to_string()),
                            Err(_) => Some(format!("vertex weight `{}` is not a number", words[3])),
                        },
                        n => Some(format!(
                            "vertex has {n} numbers; expected 3 (x y z), 4 (with w) or 6 (with r g b)"
                        )),
                    }
                }
            }
            (E::NormalParseError, "vn") => (words.len() < 3 || !words[..3].iter().all(|w| parses(w)))
                .then(|| "normal needs three numbers".to_string()),
            (E::TexcoordParseError, "vt") => (words.len() < 2 || !words[..2].iter().all(|w| parses(w)))
                .then(|| "texture coordinate needs two numbers".to_string()),
            (E::MaterialParseError, "usemtl") => words
                .is_empty()
                .then(|| "usemtl without a material name".to_string()),
            (E::FaceParseError, "l" | "p") => Some(format!("malformed `{keyword}` element")),
            _ => None,
        };
        bad.map(|msg| (line, msg))
    });
    match found {
        Some((line, msg)) => MeshError::new(path, Some(line), msg),
        None => MeshError::new(path, None, format!("invalid OBJ: {e}")),
    }
}

/// Refuses NaN or infinite positions, normals and texture coordinates
/// (Rust's number parsing accepts `nan`, `inf` and `1e999`).
fn check_finite(path: &Path, text: &str, mesh: &tobj::Mesh) -> Result<(), MeshError> {
    let all_finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    for (values, keyword, what) in [
        (&mesh.positions, "v", "vertex position"),
        (&mesh.normals, "vn", "normal"),
        (&mesh.texcoords, "vt", "texture coordinate"),
    ] {
        if all_finite(values) {
            continue;
        }
        let line = lines(text).find_map(|(line, k, words)| {
            if k != keyword {
                return None;
            }
            let v: Vec<f32> = words.filter_map(|w| w.parse().ok()).collect();
            // A position's w divides x, y and z.
            let w = if keyword == "v" && v.len() == 4 {
                v[3]
            } else {
                1.0
            };
            let n = if keyword == "vt" { 2 } else { 3 };
            v.iter()
                .take(n)
                .any(|x| !(x / w).is_finite())
                .then_some(line)
        });
        return Err(MeshError::new(
            path,
            line,
            format!("{what} is not finite (NaN or infinite)"),
        ));
    }
    Ok(())
}

/// Loads one MTL file for tobj. A missing file only means no materials; any
/// other problem is stored in `error` and ends the load.
fn load_mtl(path: &Path, error: &RefCell<Option<MeshError>>) -> tobj::MTLLoadResult {
    let fail = |e: MeshError| {
        error.borrow_mut().get_or_insert(e);
        Err(tobj::LoadError::GenericFailure)
    };
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(tobj::LoadError::OpenFileFailed)
        }
        Err(e) => return fail(MeshError::new(path, None, format!("cannot read: {e}"))),
    };
    let text = match utf8(path, &bytes) {
        Ok(t) => t,
        Err(e) => return fail(e),
    };
    let text = match check_mtl(path, text) {
        Ok(t) => t,
        Err(e) => return fail(e),
    };
    match tobj::load_mtl_buf(&mut text.as_bytes()) {
        Ok(r) => {
            // tobj keeps `Tr` as text; check it here, where the line is known.
            for (line, keyword, mut words) in lines(&text) {
                if keyword == "Tr" && words.next().and_then(|w| w.parse::<f32>().ok()).is_none() {
                    return fail(MeshError::new(path, Some(line), "Tr needs a number"));
                }
            }
            Ok(r)
        }
        Err(e) => fail(mtl_error(path, &text, e)),
    }
}

/// Checks the colour lines of an MTL file, which tobj would panic on with
/// fewer than three numbers, and expands the one-number form `Kd r`, which
/// means grey (r, r, r).
fn check_mtl<'a>(path: &Path, text: &'a str) -> Result<Cow<'a, str>, MeshError> {
    let mut grey_lines = Vec::new();
    for (line, keyword, words) in lines(text) {
        if matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke" | "Tf") {
            match words.count() {
                1 => grey_lines.push(line),
                n if n >= 3 => {}
                n => {
                    return Err(MeshError::new(
                        path,
                        Some(line),
                        format!("{keyword} has {n} numbers; expected 3 (r g b) or 1 (grey)"),
                    ))
                }
            }
        }
    }
    if grey_lines.is_empty() {
        return Ok(Cow::Borrowed(text));
    }
    let mut out = String::with_capacity(text.len() + 16 * grey_lines.len());
    let mut grey = grey_lines.into_iter().peekable();
    for (i, line) in text.lines().enumerate() {
        if grey.peek() == Some(&(i + 1)) {
            grey.next();
            let mut words = line.split_whitespace();
            let (keyword, r) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
            out.push_str(&format!("{keyword} {r} {r} {r}"));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    Ok(Cow::Owned(out))
}

/// Turns a tobj MTL error into one that names the line at fault.
fn mtl_error(path: &Path, text: &str, e: tobj::LoadError) -> MeshError {
    let found = lines(text).find_map(|(line, keyword, words)| {
        let words: Vec<&str> = words.collect();
        let number = |w: Option<&&str>| w.is_some_and(|w| w.parse::<f32>().is_ok());
        let bad = match keyword {
            "newmtl" => words
                .is_empty()
                .then(|| "newmtl without a name".to_string()),
            "Ka" | "Kd" | "Ks" | "Ke" => (!words.iter().take(3).all(|w| number(Some(w))))
                .then(|| format!("{keyword} needs numbers")),
            "Ns" | "Ni" | "d" => {
                (!number(words.first())).then(|| format!("{keyword} needs a number"))
            }
            "illum" => words
                .first()
                .is_none_or(|w| w.parse::<u8>().is_err())
                .then(|| "illum needs an illumination model number 0–10".to_string()),
            k if k.starts_with("map_") || k == "bump" => words
                .is_empty()
                .then(|| format!("{keyword} without a file name")),
            _ => None,
        };
        bad.map(|msg| (line, msg))
    });
    match found {
        Some((line, msg)) => MeshError::new(path, Some(line), msg),
        None => MeshError::new(path, None, format!("invalid MTL: {e}")),
    }
}

/// Maps an MTL material onto [`MeshMaterial`]:
///
/// - base colour = `Kd` (0.8 grey when absent);
/// - a metal when `Kd` is black (every channel < 0.01) and `Ks` is strong
///   (some channel ≥ 0.25): metallic = 1, base colour = `Ks`;
/// - roughness = (2 / (Ns + 2))^¼ (`Ns` 0 when absent), so a metal's fuzz
///   roughness² is √(2 / (Ns + 2));
/// - ior = `Ni` (1.5 when absent); transmission = the larger of 1 − `d` and
///   `Tr`, and 1 for illumination models 4, 6 and 7 (glass, refraction);
/// - emission = `Ke`;
/// - `map_Kd`: an image (relative to the MTL file `mtl`) the base colour is
///   multiplied by.
fn convert_material(m: &tobj::Material, mtl: &Path) -> Result<MeshMaterial, MeshError> {
    let base_color_texture = match &m.diffuse_texture {
        Some(file) => {
            let dir = mtl.parent().unwrap_or(Path::new(""));
            let image = Image::read(&dir.join(file)).map_err(|e| {
                MeshError::new(mtl, None, format!("material `{}`: map_Kd: {e}", m.name))
            })?;
            Some(Arc::new(image))
        }
        None => None,
    };
    let defaults = MeshMaterial::default();
    let kd = m.diffuse.unwrap_or(defaults.base_color);
    let ks = m.specular.unwrap_or([0.0; 3]);
    let max = |c: [f32; 3]| c[0].max(c[1]).max(c[2]);
    let metal = max(kd) < 0.01 && max(ks) >= 0.25;
    let ns = m.shininess.unwrap_or(0.0).max(0.0);
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse::<f32>().ok())
        .unwrap_or(0.0);
    let mut transmission = (1.0 - m.dissolve.unwrap_or(1.0)).max(tr).clamp(0.0, 1.0);
    if matches!(m.illumination_model, Some(4 | 6 | 7)) {
        transmission = 1.0;
    }
    Ok(MeshMaterial {
        name: m.name.clone(),
        base_color: if metal { ks } else { kd },
        base_color_texture,
        metallic: if metal { 1.0 } else { 0.0 },
        roughness: (2.0 / (ns + 2.0)).sqrt().sqrt(),
        ior: m.optical_density.unwrap_or(defaults.ior),
        transmission,
        emission: m.emissive.unwrap_or([0.0; 3]),
        double_sided: false,
    })
}
