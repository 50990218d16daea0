//! glTF 2.0 (`.gltf` with external or base64 data-URI buffers, and `.glb`),
//! parsed by the `gltf` crate without its image and file-import features:
//! buffers are resolved here.
//!
//! The default scene's node trees (or, without a default scene, every node
//! that is no other node's child) are walked from the roots, composing each
//! node's matrix or translation-rotation-scale with its parent's. Each node
//! with a mesh gives one instance; a glTF mesh becomes one [`TriangleMesh`]
//! (its primitives concatenated, each with its own material), stored once
//! however many nodes use it.
//!
//! Primitives of mode TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN become
//! triangles; POINTS and LINE* primitives have no surface and are skipped and
//! counted in [`Model::skipped_primitives`].
//!
//! The crate's accessor reader trusts byte offsets, strides and element types
//! (it can slice out of bounds or misread on a bad file), so every accessor is
//! checked against its buffer view and buffer before it is read.

use super::{fan, MeshError, Model, TriangleMesh, NO_MATERIAL};
use base64::Engine as _;
use glam::{Mat4, Quat, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use std::borrow::Cow;
use std::path::Path;

mod material;

/// Loads a `.gltf` or `.glb` file.
/// `bytes` are the file's content.
pub(super) fn load(
    path: &Path,
    bytes: Vec<u8>,
    options: super::LoadOptions,
) -> Result<Model, MeshError> {
    let err = |msg: String| MeshError::new(path, None, msg);
    check_glb_header(&bytes).map_err(err)?;
    // Some of the crate's messages say "invalid glTF" already.
    let invalid = |e: gltf::Error| {
        let e = e.to_string();
        err(if e.starts_with("invalid glTF: ") {
            e
        } else {
            format!("invalid glTF: {e}")
        })
    };
    // The JSON as written, for what the crate does not read (material
    // extensions) and for the extensions the file needs, checked first.
    let raw = raw_json(&bytes).map_err(err)?;
    let mut warnings = check_extensions(&raw).map_err(err)?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    drop(bytes);
    let mut json = document.into_json();
    check_attribute_indices(&json).map_err(err)?;
    // Checked above; the crate would refuse those it was not built for.
    json.extensions_required.clear();
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    let buffers = load_buffers(path, &document, blob, options)?;

    let dir = path.parent().unwrap_or(Path::new(""));
    let views: Vec<gltf::buffer::View> = document.views().collect();
    let view_bytes = |i: usize| -> Option<&[u8]> {
        let view = views.get(i)?;
        let data = buffers.get(view.buffer().index())?;
        data.get(view.offset()..view.offset().checked_add(view.length())?)
    };
    let uri_bytes = |uri: &str| read_uri(dir, uri, options, None);
    let materials = material::materials(path, &raw, &view_bytes, &uri_bytes, &mut warnings)?;
    warnings.extend(unrendered(&raw));
    let mut model = Model {
        materials,
        warnings,
        ..Model::default()
    };
    // glTF mesh index → index in model.meshes, for meshes already converted.
    let mut mesh_slot: Vec<Option<usize>> = vec![None; document.meshes().len()];
    for (node, transform) in walk_nodes(&document).map_err(err)? {
        if let Some(camera) = node.camera() {
            let view = match camera.projection() {
                gltf::camera::Projection::Perspective(p)
                    if p.yfov().is_finite() && p.yfov() > 0.0 =>
                {
                    Some(super::ModelView::Perspective { yfov: p.yfov() })
                }
                gltf::camera::Projection::Orthographic(o)
                    if o.ymag().is_finite() && o.ymag() > 0.0 =>
                {
                    Some(super::ModelView::Orthographic { ymag: o.ymag() })
                }
                _ => None,
            };
            match view {
                Some(view) => model.cameras.push(super::ModelCamera {
                    name: camera.name().map(str::to_string),
                    transform,
                    view,
                }),
                None => model.warnings.push(format!(
                    "camera {} has no field of view or magnification lumen can use",
                    camera.index()
                )),
            }
        }
        let Some(mesh) = node.mesh() else { continue };
        let slot = match mesh_slot[mesh.index()] {
            Some(slot) => slot,
            None => {
                let converted = convert_mesh(&mesh, &buffers, &mut model)
                    .map_err(|m| err(format!("mesh {}: {m}", mesh.index())))?;
                let slot = model.meshes.len();
                model.meshes.push(converted);
                mesh_slot[mesh.index()] = Some(slot);
                slot
            }
        };
        model.instances.push((slot, transform));
    }
    // Meshes left without triangles (all skipped) are dropped with their
    // instances.
    let keep: Vec<bool> = model
        .meshes
        .iter()
        .map(|m| !m.triangles.is_empty())
        .collect();
    if keep.contains(&false) {
        let mut new_index = Vec::with_capacity(keep.len());
        let mut next = 0;
        for &k in &keep {
            new_index.push(next);
            next += usize::from(k);
        }
        model.instances.retain(|&(i, _)| keep[i]);
        for inst in &mut model.instances {
            inst.0 = new_index[inst.0];
        }
        let mut k = keep.iter();
        model.meshes.retain(|_| *k.next().unwrap_or(&false));
    }
    model.finish(path)
}

/// Refuses a GLB header whose length fields are impossible, which the crate
/// would otherwise subtract from without checking.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 20 {
        return Err(format!(
            "truncated GLB: {} bytes, less than a header",
            bytes.len()
        ));
    }
    let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    if length < 20 || length > bytes.len() {
        return Err(format!(
            "truncated or corrupt GLB: the header says {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// Refuses vertex attributes that name a missing accessor. The crate's own
/// validation indexes the POSITION accessor before checking that it exists,
/// so this runs first.
fn check_attribute_indices(json: &gltf::json::Root) -> Result<(), String> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for index in primitive.attributes.values() {
                if index.value() >= json.accessors.len() {
                    return Err(format!(
                        "mesh {m} primitive {p}: attribute accessor {} does not exist (the file has {})",
                        index.value(),
                        json.accessors.len()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The bytes a URI of the file names: a base64 data URI, or a file in the
/// glTF file's folder `dir` (or anywhere, if `options` allow it). A buffer's
/// file is read to its declared `byteLength` (`length`) and no further; an
/// image's whole, up to [`MAX_IMAGE_BYTES`](crate::input::MAX_IMAGE_BYTES).
fn read_uri(
    dir: &Path,
    uri: &str,
    options: super::LoadOptions,
    length: Option<u64>,
) -> Result<Vec<u8>, String> {
    if uri.starts_with("data:") {
        let (_, payload) = uri
            .split_once(";base64,")
            .ok_or_else(|| "only base64 data URIs are supported".to_string())?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 data: {e}"));
    }
    if uri.contains("://") {
        return Err(format!(
            "`{uri}`: only files beside the glTF file are supported"
        ));
    }
    let file = dir.join(percent_decode(uri));
    super::confined(dir, &file, uri, options)?;
    let read = match length {
        Some(n) => crate::input::read_prefix(&file, n, crate::input::MAX_MESH_BYTES),
        None => crate::input::read(&file, crate::input::MAX_IMAGE_BYTES),
    };
    read.map_err(|e| format!("`{}`: {e}", file.display()))
}

/// The bytes of every buffer: the GLB's binary chunk, a base64 data URI, or a
/// file beside the glTF file.
fn load_buffers(
    path: &Path,
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    options: super::LoadOptions,
) -> Result<Vec<Vec<u8>>, MeshError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let err = |m: String| MeshError::new(path, None, format!("buffer {}: {m}", buffer.index()));
        let length = buffer.length() as u64;
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| err("refers to the GLB binary chunk, which is missing".into()))?,
            gltf::buffer::Source::Uri(uri) => {
                read_uri(dir, uri, options, Some(length)).map_err(err)?
            }
        };
        if data.len() < buffer.length() {
            return Err(err(format!(
                "holds {} bytes but declares {}",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Decodes the `%XX` escapes of a relative URI (for example `%20` for a
/// space); anything malformed is kept as it is.
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every node reachable from the roots with its composed object-to-model
/// matrix, parents before children. A node reached twice (a cycle, or a node
/// with two parents, which glTF forbids), or, in a file without a scene, a
/// node no root leads to (a cycle without a root), is an error.
fn walk_nodes(document: &gltf::Document) -> Result<Vec<(gltf::Node<'_>, Mat4)>, String> {
    let n = document.nodes().len();
    let roots: Vec<gltf::Node> = match document.default_scene() {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; n];
            for node in document.nodes() {
                for child in node.children() {
                    is_child[child.index()] = true;
                }
            }
            document
                .nodes()
                .filter(|node| !is_child[node.index()])
                .collect()
        }
    };
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    // An explicit stack: a long chain of nodes must not overflow the call stack.
    let mut stack: Vec<(gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|r| (r, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(format!(
                "node {} is reached twice (a cycle or a second parent)",
                node.index()
            ));
        }
        let world = parent * local_transform(&node);
        if !world.is_finite() {
            return Err(format!("node {} has a non-finite transform", node.index()));
        }
        let children: Vec<gltf::Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
        out.push((node, world));
    }
    // Without a scene every node is a root or some node's child, so a node
    // no root leads to is in a cycle of parents (or below one).
    if document.default_scene().is_none() {
        if let Some(lost) = seen.iter().position(|s| !s) {
            return Err(format!(
                "node {lost} is in a cycle of parents (or below one): no root node leads to it"
            ));
        }
    }
    Ok(out)
}

/// A node's own transform: its matrix, or translation · rotation · scale
/// (the rotation quaternion normalised, as glTF requires it to be unit).
fn local_transform(node: &gltf::Node) -> Mat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => Mat4::from_scale_rotation_translation(
            Vec3::from_array(scale),
            Quat::from_array(rotation).normalize(),
            Vec3::from_array(translation),
        ),
    }
}

/// Checks that `accessor` has one of the `types`, `dims` components, a
/// buffer view, no sparse part, and lies within its view and buffer.
fn check_accessor(
    accessor: &gltf::Accessor,
    what: &str,
    types: &[DataType],
    dims: Dimensions,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let name = format!("{what} accessor {}", accessor.index());
    if !types.contains(&accessor.data_type()) || accessor.dimensions() != dims {
        return Err(format!(
            "{name} is {:?} {:?}; expected {dims:?} of {types:?}",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    if accessor.sparse().is_some() {
        return Err(format!("{name} is sparse, which is not supported"));
    }
    let view = accessor
        .view()
        .ok_or_else(|| format!("{name} has no buffer view"))?;
    if accessor.count() == 0 {
        return Err(format!("{name} is empty"));
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "{name}: stride {stride} is less than the element size {size}"
        ));
    }
    let needed = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(size))
        .and_then(|x| x.checked_add(accessor.offset()));
    if needed.is_none_or(|end| end > view.length()) {
        return Err(format!(
            "{name} ({} elements from byte {}) runs past the end of buffer view {} ({} bytes)",
            accessor.count(),
            accessor.offset(),
            view.index(),
            view.length()
        ));
    }
    let buffer = &buffers[view.buffer().index()];
    if view
        .offset()
        .checked_add(view.length())
        .is_none_or(|end| end > buffer.len())
    {
        return Err(format!(
            "buffer view {} (bytes {}..+{}) runs past the end of buffer {} ({} bytes)",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index(),
            buffer.len()
        ));
    }
    Ok(())
}

/// Converts one glTF mesh, all its primitives, into a [`TriangleMesh`].
fn convert_mesh(
    mesh: &gltf::Mesh,
    buffers: &[Vec<u8>],
    model: &mut Model,
) -> Result<TriangleMesh, String> {
    let mut out = TriangleMesh::default();
    let (mut all_normals, mut all_uvs) = (true, true);
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    // Kept only when every primitive has them.
    let (mut all_uvs1, mut all_colors, mut all_tangents) = (true, true, true);
    let (mut uvs1, mut colors, mut tangents) = (Vec::new(), Vec::new(), Vec::new());
    for primitive in mesh.primitives() {
        let p = primitive.index();
        let in_primitive = |m: String| format!("primitive {p}: {m}");
        if !matches!(
            primitive.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            model.skipped_primitives += 1;
            continue;
        }
        let position = primitive
            .get(&Semantic::Positions)
            .ok_or_else(|| in_primitive("no POSITION attribute".into()))?;
        check_accessor(
            &position,
            "POSITION",
            &[DataType::F32],
            Dimensions::Vec3,
            buffers,
        )
        .map_err(in_primitive)?;
        let vertex_count = position.count();
        let normal = primitive.get(&Semantic::Normals);
        if let Some(a) = &normal {
            check_accessor(a, "NORMAL", &[DataType::F32], Dimensions::Vec3, buffers)
                .map_err(in_primitive)?;
        }
        let uv = primitive.get(&Semantic::TexCoords(0));
        if let Some(a) = &uv {
            let types = [DataType::F32, DataType::U8, DataType::U16];
            check_accessor(a, "TEXCOORD_0", &types, Dimensions::Vec2, buffers)
                .map_err(in_primitive)?;
        }
        let uv1 = primitive.get(&Semantic::TexCoords(1));
        if let Some(a) = &uv1 {
            let types = [DataType::F32, DataType::U8, DataType::U16];
            check_accessor(a, "TEXCOORD_1", &types, Dimensions::Vec2, buffers)
                .map_err(in_primitive)?;
        }
        let color = primitive.get(&Semantic::Colors(0));
        if let Some(a) = &color {
            let types = [DataType::F32, DataType::U8, DataType::U16];
            let dims = if a.dimensions() == Dimensions::Vec3 {
                Dimensions::Vec3
            } else {
                Dimensions::Vec4
            };
            check_accessor(a, "COLOR_0", &types, dims, buffers).map_err(in_primitive)?;
        }
        let tangent = primitive.get(&Semantic::Tangents);
        if let Some(a) = &tangent {
            check_accessor(a, "TANGENT", &[DataType::F32], Dimensions::Vec4, buffers)
                .map_err(in_primitive)?;
        }
        for (a, name) in [
            (&normal, "NORMAL"),
            (&uv, "TEXCOORD_0"),
            (&uv1, "TEXCOORD_1"),
            (&color, "COLOR_0"),
            (&tangent, "TANGENT"),
        ] {
            if let Some(a) = a {
                if a.count() != vertex_count {
                    return Err(in_primitive(format!(
                        "{name} has {} elements but POSITION has {vertex_count}",
                        a.count()
                    )));
                }
            }
        }
        if let Some(a) = primitive.indices() {
            let types = [DataType::U8, DataType::U16, DataType::U32];
            check_accessor(&a, "index", &types, Dimensions::Scalar, buffers)
                .map_err(in_primitive)?;
        }

        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let unreadable = |what: &str| in_primitive(format!("cannot read {what}"));
        let base = out.positions.len();
        if base + vertex_count > u32::MAX as usize {
            return Err(in_primitive("more than 2³² vertices".into()));
        }
        let positions = reader
            .read_positions()
            .ok_or_else(|| unreadable("POSITION"))?;
        out.positions.extend(positions);
        if out.positions.len() != base + vertex_count {
            return Err(unreadable("POSITION"));
        }
        if let Some(i) = out.positions[base..]
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            return Err(in_primitive(format!(
                "vertex {i} has a non-finite position"
            )));
        }
        match reader.read_normals() {
            Some(n) if all_normals => normals.extend(n),
            _ => all_normals = false,
        }
        match reader.read_tex_coords(0) {
            // glTF's v runs down the image; lumen's up.
            Some(t) if all_uvs => uvs.extend(t.into_f32().map(|[u, v]| [u, 1.0 - v])),
            _ => all_uvs = false,
        }
        match reader.read_tex_coords(1) {
            Some(t) if all_uvs1 => uvs1.extend(t.into_f32().map(|[u, v]| [u, 1.0 - v])),
            _ => all_uvs1 = false,
        }
        match reader.read_colors(0) {
            Some(c) if all_colors => colors.extend(c.into_rgba_f32()),
            _ => all_colors = false,
        }
        match reader.read_tangents() {
            Some(t) if all_tangents => tangents.extend(t),
            _ => all_tangents = false,
        }

        let indices: Vec<u32> = match reader.read_indices() {
            Some(ix) => ix.into_u32().collect(),
            None => (0..vertex_count as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(in_primitive(format!(
                "index {bad} out of range (the primitive has {vertex_count} vertices)"
            )));
        }
        let material = primitive
            .material()
            .index()
            .map_or(NO_MATERIAL, |i| i as u32);
        let mut add = |t: [u32; 3]| {
            let t = t.map(|i| i + base as u32);
            if !out.push_triangle(t, material) {
                model.skipped_degenerate += 1;
            }
        };
        match primitive.mode() {
            Mode::Triangles => {
                if !indices.len().is_multiple_of(3) {
                    return Err(in_primitive(format!(
                        "{} indices, not a multiple of 3",
                        indices.len()
                    )));
                }
                for t in indices.chunks_exact(3) {
                    add([t[0], t[1], t[2]]);
                }
            }
            // Every other strip triangle is flipped to keep the winding.
            Mode::TriangleStrip => {
                for (k, w) in indices.windows(3).enumerate() {
                    add(if k % 2 == 0 {
                        [w[0], w[1], w[2]]
                    } else {
                        [w[1], w[0], w[2]]
                    });
                }
            }
            _ => fan(&indices).for_each(add),
        }
    }
    if all_normals && normals.len() == out.positions.len() {
        out.normals = Some(normals);
    }
    if all_uvs && uvs.len() == out.positions.len() {
        out.uvs = Some(uvs);
    }
    let n = out.positions.len();
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if all_uvs1 && uvs1.len() == n && uvs1.iter().all(|t| finite(t)) {
        out.uvs1 = Some(uvs1);
    }
    if all_colors && colors.len() == n && colors.iter().all(|c| finite(c)) {
        out.colors = Some(colors);
    }
    if all_tangents && tangents.len() == n && tangents.iter().all(|t| finite(t)) {
        out.tangents = Some(tangents);
    }
    Ok(out)
}

/// The file's JSON as a value: a `.gltf` file itself, a GLB's JSON chunk.
fn raw_json(bytes: &[u8]) -> Result<serde_json::Value, String> {
    let json: Cow<[u8]> = if bytes.starts_with(b"glTF") {
        gltf::binary::Glb::from_slice(bytes)
            .map_err(|e| format!("invalid glTF: {e}"))?
            .json
    } else {
        Cow::Borrowed(bytes)
    };
    serde_json::from_slice(&json).map_err(|e| format!("invalid glTF JSON: {e}"))
}

/// Refuses a file that requires an extension lumen lacks, naming it (and
/// nothing else: what else is wrong with such a file is beside the point);
/// one warning for each extension the file uses and lumen does not render.
fn check_extensions(raw: &serde_json::Value) -> Result<Vec<String>, String> {
    let known = |e: &str| material::SUPPORTED.contains(&e) || material::HARMLESS.contains(&e);
    let names = |key: &str| -> Vec<String> {
        raw[key]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|e| e.as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default()
    };
    let required: Vec<String> = names("extensionsRequired")
        .into_iter()
        .filter(|e| !known(e))
        .collect();
    if !required.is_empty() {
        return Err(format!(
            "requires {} {}, which lumen does not support (it reads {})",
            if required.len() == 1 {
                "extension"
            } else {
                "extensions"
            },
            required.join(", "),
            material::SUPPORTED.join(", ")
        ));
    }
    Ok(names("extensionsUsed")
        .into_iter()
        .filter(|e| !known(e))
        .map(|e| format!("extension {e} is not rendered"))
        .collect())
}

/// One warning for each kind of thing in the file that lumen does not
/// render.
fn unrendered(raw: &serde_json::Value) -> Vec<String> {
    let count = |key: &str| raw[key].as_array().map_or(0, Vec::len);
    let mut out = Vec::new();
    for (key, what) in [
        ("animations", "animations (the rest pose is rendered)"),
        ("skins", "skins (the rest pose is rendered)"),
        ("cameras", "cameras (unless the scene's camera names one)"),
    ] {
        let n = count(key);
        if n > 0 {
            out.push(format!("{n} {what} not used"));
        }
    }
    let occlusion = raw["materials"].as_array().map_or(0, |m| {
        m.iter()
            .filter(|m| !m["occlusionTexture"].is_null())
            .count()
    });
    if occlusion > 0 {
        out.push(format!(
            "{occlusion} occlusion textures not used (a path tracer works occlusion out itself)"
        ));
    }
    let morphs = raw["meshes"].as_array().map_or(0, |m| {
        m.iter()
            .filter(|m| {
                m["primitives"]
                    .as_array()
                    .is_some_and(|p| p.iter().any(|p| !p["targets"].is_null()))
            })
            .count()
    });
    if morphs > 0 {
        out.push(format!("{morphs} meshes' morph targets not used"));
    }
    out
}
