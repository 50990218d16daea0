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

use super::{AlphaMode, Mapped, MeshError, MeshMaterial, Model, TriangleMesh, NO_MATERIAL};
use crate::material::param::MAX_LAYER_IOR;
use crate::texture::{Channels, Filter, Image, ImageMap, UvTransform, Wrap};
use glam::Mat4;
use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Loads an OBJ file and the MTL files it names.
/// `bytes` are the file's content.
pub(super) fn load(
    path: &Path,
    bytes: Vec<u8>,
    load_options: super::LoadOptions,
) -> Result<Model, MeshError> {
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
        if let Err(why) = super::confined(&dir, &file, &name.to_string_lossy(), load_options) {
            mtl_error.borrow_mut().get_or_insert(MeshError::new(
                path,
                None,
                format!("mtllib: {why}"),
            ));
            return Err(tobj::LoadError::GenericFailure);
        }
        *mtl_path.borrow_mut() = Some(file.clone());
        load_mtl(&file, &mtl_error)
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = result.map_err(|e| obj_error(path, &text, e))?;
    // A missing MTL file leaves the materials empty (or an error that only
    // says so); the triangles then have no material.
    let mtl = mtl_path.borrow().clone();
    let mut images = Images {
        read: HashMap::new(),
        folder: dir.clone(),
        options: load_options,
    };
    let materials: Vec<MeshMaterial> = materials
        .unwrap_or_default()
        .iter()
        .map(|m| convert_material(m, mtl.as_deref().unwrap_or(path), &mut images))
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
    let bytes = match crate::input::read(path, crate::input::MAX_MTL_BYTES) {
        Ok(b) => b,
        Err(crate::input::ReadError::NotFound) => return Err(tobj::LoadError::OpenFileFailed),
        Err(e) => return fail(MeshError::new(path, None, e.to_string())),
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
            // tobj keeps `Tr` as text, and reads `inf` and `nan` as numbers:
            // what it accepted is checked line by line all the same.
            if let Some((line, msg)) = bad_mtl_line(&text) {
                return fail(MeshError::new(path, Some(line), msg));
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
    match bad_mtl_line(text) {
        Some((line, msg)) => MeshError::new(path, Some(line), msg),
        None => MeshError::new(path, None, format!("invalid MTL: {e}")),
    }
}

/// The first line of an MTL file that is malformed, and what is wrong
/// with it.
fn bad_mtl_line(text: &str) -> Option<(usize, String)> {
    lines(text).find_map(|(line, keyword, words)| {
        let words: Vec<&str> = words.collect();
        let number =
            |w: Option<&&str>| w.is_some_and(|w| w.parse::<f32>().is_ok_and(f32::is_finite));
        let bad = match keyword {
            "newmtl" => words
                .is_empty()
                .then(|| "newmtl without a name".to_string()),
            "Ka" | "Kd" | "Ks" | "Ke" => (!words.iter().take(3).all(|w| number(Some(w))))
                .then(|| format!("{keyword} needs finite numbers")),
            "Ns" | "Ni" | "d" | "Tr" => {
                (!number(words.first())).then(|| format!("{keyword} needs a finite number"))
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
    })
}

/// The images an MTL file's materials name, each read once.
struct Images {
    read: HashMap<PathBuf, Arc<Image>>,
    /// The model's folder, which the images must be in.
    folder: PathBuf,
    options: super::LoadOptions,
}

impl Images {
    /// The image `file` (relative to `dir`).
    fn get(&mut self, dir: &Path, file: &str) -> Result<Arc<Image>, String> {
        let path = dir.join(file);
        if let Some(image) = self.read.get(&path) {
            return Ok(image.clone());
        }
        super::confined(&self.folder, &path, file, self.options)?;
        let image = Arc::new(Image::read(&path).map_err(|e| e.to_string())?);
        self.read.insert(path, image.clone());
        Ok(image)
    }
}

/// A texture statement's options and file: `-bm 0.5 -s 2 2 file.png`
/// gives the bump multiplier, the uv scale and offset, whether it clamps,
/// and the file.
struct MapStatement {
    file: String,
    bump: f32,
    scale: [f32; 2],
    offset: [f32; 2],
    clamp: bool,
}

impl MapStatement {
    fn parse(text: &str) -> Result<MapStatement, String> {
        let words: Vec<&str> = text.split_whitespace().collect();
        let mut out = MapStatement {
            file: String::new(),
            bump: 1.0,
            scale: [1.0; 2],
            offset: [0.0; 2],
            clamp: false,
        };
        let mut i = 0;
        // The numbers after an option (up to `max`).
        let numbers = |i: &mut usize, max: usize| -> Vec<f32> {
            let mut v = Vec::new();
            while v.len() < max {
                match words.get(*i).and_then(|w| w.parse::<f32>().ok()) {
                    Some(x) if x.is_finite() => {
                        v.push(x);
                        *i += 1;
                    }
                    _ => break,
                }
            }
            v
        };
        while i < words.len() && words[i].starts_with('-') && words[i].len() > 1 {
            let option = words[i];
            i += 1;
            match option {
                "-bm" => {
                    out.bump = numbers(&mut i, 1)
                        .first()
                        .copied()
                        .ok_or("-bm needs a number")?
                }
                "-s" => {
                    let v = numbers(&mut i, 3);
                    out.scale = [
                        *v.first().ok_or("-s needs numbers")?,
                        *v.get(1).unwrap_or(&1.0),
                    ];
                }
                "-o" => {
                    let v = numbers(&mut i, 3);
                    out.offset = [
                        *v.first().ok_or("-o needs numbers")?,
                        *v.get(1).unwrap_or(&0.0),
                    ];
                }
                "-clamp" => {
                    out.clamp = words.get(i) == Some(&"on");
                    i += 1;
                }
                "-blendu" | "-blendv" | "-cc" | "-imfchan" | "-type" => i += 1,
                "-mm" => {
                    numbers(&mut i, 2);
                }
                "-t" => {
                    numbers(&mut i, 3);
                }
                "-texres" | "-boost" => {
                    numbers(&mut i, 1);
                }
                other => return Err(format!("unknown texture option {other}")),
            }
        }
        out.file = words[i.min(words.len())..].join(" ");
        if out.file.is_empty() {
            return Err("no file name".to_string());
        }
        Ok(out)
    }
}

/// Maps an MTL material onto [`MeshMaterial`] (documented in
/// `docs/materials.md`):
///
/// - base colour = `Kd` (0.8 grey when absent) × `map_Kd`; `map_Ks` the
///   colour of a dielectric's specular reflection;
/// - the PBR extension where given: roughness `Pr` / `map_Pr`, metallic
///   `Pm` / `map_Pm`, sheen `Ps`, clear coat `Pc` and its roughness `Pcr`;
/// - else a metal when `Kd` is black (every channel < 0.01) and `Ks` is
///   strong (some channel ≥ 0.25), base colour `Ks`; roughness =
///   (2 / (Ns + 2))^¼ (`Ns` 0 when absent), or 1 − `map_Ns`;
/// - illumination models 0 and 1 have no specular reflection (and a `Ks`
///   of zero turns it off); 4, 6, 7 and 9 are glass (transmission 1,
///   index `Ni`); otherwise transmission is `Tr` (or 1 − `d` for glass);
/// - `d` < 1 or `map_d` elsewhere is opacity (cut-outs);
/// - emission `Ke` × `map_Ke`; `bump`/`map_Bump` a height map (`-bm` its
///   height), `norm` a tangent-space normal map; `-s`, `-o` and `-clamp on`
///   move and wrap any map.
fn convert_material(
    m: &tobj::Material,
    mtl: &Path,
    images: &mut Images,
) -> Result<MeshMaterial, MeshError> {
    let dir = mtl.parent().unwrap_or(Path::new(""));
    let fail = |what: &str, e: String| {
        MeshError::new(mtl, None, format!("material `{}`: {what}: {e}", m.name))
    };
    let param = |key: &str| -> Option<&str> { m.unknown_param.get(key).map(|s| s.trim()) };
    let number = |key: &str| -> Result<Option<f32>, MeshError> {
        match param(key) {
            None => Ok(None),
            Some(v) => v
                .split_whitespace()
                .next()
                .and_then(|w| w.parse::<f32>().ok())
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| fail(key, format!("needs a number, got `{v}`"))),
        }
    };
    // An image map of statement `text` (keyword `what`).
    let mut map = |what: &str, text: Option<&str>, channels: Channels, srgb: bool| {
        let Some(text) = text else {
            return Ok(None);
        };
        let statement = MapStatement::parse(text).map_err(|e| fail(what, e))?;
        let image = images
            .get(dir, &statement.file)
            .map_err(|e| fail(what, e))?;
        let channels = match channels {
            // A scalar map of a grey image is its grey; of an image with
            // alpha, its alpha.
            Channels::One(0) if image.has_alpha() && what == "map_d" => Channels::One(3),
            c => c,
        };
        let wrap = if statement.clamp {
            Wrap::Clamp
        } else {
            Wrap::Repeat
        };
        Ok(Some((
            ImageMap {
                image,
                srgb,
                channels,
                wrap: [wrap; 2],
                filter: Filter::Bilinear,
                transform: UvTransform::offset_rotation_scale(
                    statement.offset,
                    0.0,
                    statement.scale,
                ),
                uv_set: 0,
            },
            statement.bump,
        )))
    };
    let defaults = MeshMaterial::default();
    let kd = m.diffuse.unwrap_or(defaults.base_color.value);
    let ks = m.specular.unwrap_or([0.0; 3]);
    let max = |c: [f32; 3]| c[0].max(c[1]).max(c[2]);
    let pbr = param("Pr").is_some() || param("Pm").is_some() || param("map_Pr").is_some();
    let metal = !pbr && max(kd) < 0.01 && max(ks) >= 0.25;
    let ns = m.shininess.unwrap_or(0.0).max(0.0);
    let illum = m.illumination_model.unwrap_or(2);
    let glass = matches!(illum, 4 | 6 | 7 | 9);
    let tr = number("Tr")?.unwrap_or(0.0);
    let dissolve = m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0);
    let first = |m: Option<(ImageMap, f32)>| m.map(|(map, _)| map);
    let mut out = MeshMaterial {
        name: m.name.clone(),
        base_color: Mapped {
            value: if metal { ks } else { kd },
            map: first(map(
                "map_Kd",
                m.diffuse_texture.as_deref(),
                Channels::Rgb,
                true,
            )?),
        },
        metallic: Mapped::value(if metal { 1.0 } else { 0.0 }),
        roughness: Mapped::value((2.0 / (ns + 2.0)).sqrt().sqrt()),
        ior: m
            .optical_density
            .unwrap_or(defaults.ior)
            .clamp(1.0, MAX_LAYER_IOR as f32),
        emission: Mapped {
            value: m
                .emissive
                .unwrap_or([0.0; 3])
                .map(|e| if e > 0.0 { e } else { 0.0 }),
            map: first(map("map_Ke", param("map_Ke"), Channels::Rgb, true)?),
        },
        ..defaults
    };
    if let Some(gloss) = first(map(
        "map_Ns",
        m.shininess_texture.as_deref(),
        Channels::One(0),
        false,
    )?) {
        out.roughness = Mapped {
            value: 1.0,
            map: Some(gloss),
        };
        out.roughness_from_gloss = true;
    }
    if pbr {
        out.roughness = Mapped {
            value: number("Pr")?.unwrap_or(1.0).clamp(0.0, 1.0),
            map: first(map("map_Pr", param("map_Pr"), Channels::One(0), false)?),
        };
        out.roughness_from_gloss = false;
        out.metallic = Mapped {
            value: number("Pm")?.unwrap_or(0.0).clamp(0.0, 1.0),
            map: first(map("map_Pm", param("map_Pm"), Channels::One(0), false)?),
        };
        if let Some(ps) = number("Ps")? {
            out.sheen_color = Mapped::value([ps.clamp(0.0, 1.0); 3]);
            out.sheen_roughness = Mapped::value(0.5);
        }
        out.clearcoat = Mapped::value(number("Pc")?.unwrap_or(0.0).clamp(0.0, 1.0));
        out.clearcoat_roughness = Mapped::value(number("Pcr")?.unwrap_or(0.0).clamp(0.0, 1.0));
    }
    if matches!(illum, 0 | 1) || (m.specular.is_some() && max(ks) == 0.0 && !pbr) {
        out.specular = Mapped::value(0.0);
    } else if !metal {
        // A specular colour map tints the dielectric's reflection.
        out.specular_color.map = first(map(
            "map_Ks",
            m.specular_texture.as_deref(),
            Channels::Rgb,
            true,
        )?);
    }
    if glass {
        out.transmission = Mapped::value(1.0);
    } else {
        out.transmission = Mapped::value(tr.clamp(0.0, 1.0));
        let alpha = first(map(
            "map_d",
            m.dissolve_texture.as_deref(),
            Channels::One(0),
            false,
        )?);
        if dissolve < 1.0 || alpha.is_some() {
            out.alpha = Mapped {
                value: dissolve,
                map: alpha,
            };
            out.alpha_mode = AlphaMode::Blend;
        }
    }
    out.bump_map = map("bump", m.normal_texture.as_deref(), Channels::One(0), false)?;
    out.normal_map = map("norm", param("norm"), Channels::Rgb, false)?.map(|(n, _)| (n, 1.0));
    Ok(out)
}
