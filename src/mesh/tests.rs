use super::*;
use base64::Engine as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
}

/// A fresh directory under the system temporary directory, removed on drop.
pub(super) struct TempDir(pub(super) PathBuf);

impl TempDir {
    pub(super) fn new() -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "lumen-mesh-test-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub(super) fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Loads `text` written to a fresh file `name`.
fn load_text(name: &str, text: &str) -> Result<Model, MeshError> {
    let dir = TempDir::new();
    load(&dir.write(name, text))
}

/// The error of loading `text` as `name`; it must name the file.
fn error_of(name: &str, text: impl AsRef<[u8]>) -> MeshError {
    let dir = TempDir::new();
    let path = dir.write(name, text);
    let e = load(&path).expect_err("the file should be refused");
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    e
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

// ---------------------------------------------------------------- the bunnies

#[test]
fn bundled_bunny_obj_and_glb_load_and_agree() {
    let t = Instant::now();
    let obj = load(&asset("bunny.obj")).unwrap();
    let t_obj = t.elapsed();
    let t = Instant::now();
    let glb = load(&asset("bunny.glb")).unwrap();
    let t_glb = t.elapsed();
    eprintln!("bunny.obj loaded in {t_obj:?}, bunny.glb in {t_glb:?}");
    for m in [&obj, &glb] {
        assert_eq!(m.meshes.len(), 1);
        assert_eq!(m.vertex_count(), 1839);
        assert_eq!(m.triangle_count(), 3674);
        assert_eq!(m.skipped_degenerate, 0);
        assert_eq!(m.instances, vec![(0, Mat4::IDENTITY)]);
        assert!(m.materials.is_empty());
        assert!(m.meshes[0].material.iter().all(|&i| i == NO_MATERIAL));
        let (lo, hi) = m.bounds().unwrap();
        assert!(close(lo, [-4.96, -0.003, -3.73], 0.01), "{lo:?}");
        assert!(close(hi, [4.95, 9.65, 3.81], 0.01), "{hi:?}");
    }
    assert_eq!(obj.bounds(), glb.bounds());
    // The same triangles, whatever the vertex order: compare each triangle as
    // its corner positions, rotated to start at the smallest.
    let key = |m: &Model| {
        let mesh = &m.meshes[0];
        let mut tris: Vec<[[u32; 3]; 3]> = mesh
            .triangles
            .iter()
            .map(|t| {
                let c = t.map(|i| mesh.positions[i as usize].map(f32::to_bits));
                let first = (0..3).min_by_key(|&k| c[k]).unwrap();
                [c[first], c[(first + 1) % 3], c[(first + 2) % 3]]
            })
            .collect();
        tris.sort();
        tris
    };
    assert_eq!(key(&obj), key(&glb));
}

#[test]
fn bunny_memory_is_indices_and_material_per_triangle() {
    let model = load(&asset("bunny.obj")).unwrap();
    let mesh = &model.meshes[0];
    assert!(mesh.normals.is_none() && mesh.uvs.is_none());
    let bytes = mesh.heap_bytes();
    let per_triangle = bytes as f64 / mesh.triangles.len() as f64;
    eprintln!("bunny: {bytes} bytes, {per_triangle:.1} bytes per triangle");
    // 12 bytes of indices + 4 of material per triangle, 12 per vertex, and
    // no spare capacity.
    assert_eq!(bytes, 3674 * 16 + 1839 * 12);
    assert!(per_triangle < 22.1);
}

#[test]
fn bunny_235k_has_all_its_triangles() {
    let t = Instant::now();
    let model = load(&asset("bunny_235k.glb")).unwrap();
    eprintln!(
        "bunny_235k.glb loaded in {:?}: {} vertices, {} bytes per triangle",
        t.elapsed(),
        model.vertex_count(),
        model.meshes[0].heap_bytes() / model.triangle_count()
    );
    assert_eq!(model.triangle_count(), 235_136);
    assert_eq!(model.skipped_degenerate, 0);
    let small = load(&asset("bunny.glb")).unwrap();
    // Midpoint subdivision keeps the vertices on the original's hull.
    let (lo, hi) = model.bounds().unwrap();
    let (slo, shi) = small.bounds().unwrap();
    assert!(close(lo, slo, 1e-4) && close(hi, shi, 1e-4));
}

// ---------------------------------------------------------------------- OBJ

#[test]
fn single_triangle() {
    let m = load_text("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n").unwrap();
    assert_eq!(m.meshes.len(), 1);
    let mesh = &m.meshes[0];
    assert_eq!(
        mesh.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]
    );
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(mesh.material, vec![NO_MATERIAL]);
    assert_eq!((mesh.normals.as_ref(), mesh.uvs.as_ref()), (None, None));
    assert_eq!(m.instances, vec![(0, Mat4::IDENTITY)]);
}

/// Twice the area of triangle `t` of `mesh`, as a signed normal's z.
fn cross_z(mesh: &TriangleMesh, t: [u32; 3]) -> f32 {
    let [a, b, c] = t.map(|i| glam::Vec3::from_array(mesh.positions[i as usize]));
    (b - a).cross(c - a).z
}

#[test]
fn quad_and_pentagon_are_triangulated_with_their_winding() {
    let m = load_text(
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 3 0 0\nv 4 0 0\nv 4 1 0\nv 3.5 2 0\nv 3 1 0\n\
         f 1 2 3 4\nf 5 6 7 8 9\n",
    )
    .unwrap();
    let mesh = &m.meshes[0];
    assert_eq!(mesh.triangles.len(), 2 + 3);
    assert_eq!(mesh.positions.len(), 9);
    // Counter-clockwise faces give counter-clockwise triangles covering them.
    let area = |tris: &[[u32; 3]]| tris.iter().map(|&t| cross_z(mesh, t) / 2.0).sum::<f32>();
    assert!(mesh.triangles.iter().all(|&t| cross_z(mesh, t) > 0.0));
    assert!((area(&mesh.triangles[..2]) - 1.0).abs() < 1e-6);
    assert!((area(&mesh.triangles[2..]) - 1.5).abs() < 1e-6);
}

#[test]
fn normals_and_uvs_are_carried_per_vertex() {
    // Each corner's uv is its (x, y) and its normal is (x, y, 1): the pairing
    // survives only if normals and uvs follow their vertex.
    let text = "v 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\n\
                vt 2 3\nvt 0 0\nvt 0 3\nvt 2 0\n\
                vn 0 3 1\nvn 2 3 1\nvn 0 0 1\nvn 2 0 1\n\
                f 1/2/3 2/4/4 3/1/2\nf 1/2/3 3/1/2 4/3/1\n";
    let m = load_text("nuv.obj", text).unwrap();
    let mesh = &m.meshes[0];
    let normals = mesh.normals.as_ref().expect("normals");
    let uvs = mesh.uvs.as_ref().expect("uvs");
    assert_eq!(mesh.positions.len(), 4, "shared corners stored once");
    assert_eq!((normals.len(), uvs.len()), (4, 4));
    for i in 0..4 {
        let [x, y, _] = mesh.positions[i];
        assert_eq!(uvs[i], [x, y]);
        assert_eq!(normals[i], [x, y, 1.0]);
    }
    assert_eq!(mesh.triangles.len(), 2);

    // A face without normals: the mesh has none.
    let partial = text.replace("f 1/2/3 3/1/2 4/3/1", "f 1/2 3/1 4/3");
    let m = load_text("partial.obj", &partial).unwrap();
    assert!(m.meshes[0].normals.is_none());
    assert!(m.meshes[0].uvs.is_some());
}

#[test]
fn mtl_materials_map_to_lights_diffuse_metal_and_glass() {
    let dir = TempDir::new();
    dir.write(
        "m.mtl",
        "newmtl red\nKd 1 0.2 0\nKe 0 0 4\n\
         newmtl chrome\nKd 0 0 0\nKs 0.9 0.8 0.7\nNs 1000\n\
         newmtl glass\nKd 1 1 1\nNi 1.45\nd 0.1\n\
         newmtl water\nillum 7\nNi 1.33\n\
         newmtl grey\nKd 0.5\nTr 0\n\
         newmtl hot\nKd 3 -1 0.5\n",
    );
    let path = dir.write(
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
         usemtl red\nf 1 2 3\nusemtl chrome\nf 2 4 3\nusemtl glass\nf 1 2 4\n\
         usemtl water\nf 1 4 3\nusemtl grey\nf 3 2 1\nusemtl nosuch\nf 4 2 1\nusemtl hot\nf 3 4 2\n",
    );
    let m = load(&path).unwrap();
    let names: Vec<&str> = m.materials.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["red", "chrome", "glass", "water", "grey", "hot"]);
    assert_eq!(m.meshes.len(), 1, "usemtl does not split the object");
    let mesh = &m.meshes[0];
    assert_eq!(mesh.material, vec![0, 1, 2, 3, 4, NO_MATERIAL, 5]);
    let mat = |name: &str| m.materials.iter().find(|x| x.name == name).unwrap();

    // `Ke` glows, one-sided (MTL has no two-sided materials), on top of
    // what the surface reflects.
    let red = mat("red");
    assert_eq!(red.emission.value, [0.0, 0.0, 4.0]);
    assert_eq!(red.base_color.value, [1.0, 0.2, 0.0]);
    assert!(!red.double_sided);
    // Black diffuse and strong specular: a metal of the specular colour.
    let chrome = mat("chrome");
    assert_eq!(chrome.metallic.value, 1.0);
    assert_eq!(chrome.base_color.value, [0.9, 0.8, 0.7]);
    let r = (2.0f32 / 1002.0).sqrt().sqrt();
    assert!((chrome.roughness.value - r).abs() < 1e-6);
    // `d` is opacity (as Blender reads it); glass is an illumination model.
    let glass = mat("glass");
    assert_eq!(glass.ior, 1.45);
    assert_eq!(glass.alpha.value, 0.1);
    assert_eq!(glass.alpha_mode, AlphaMode::Blend);
    assert_eq!(glass.transmission.value, 0.0);
    let water = mat("water");
    assert_eq!((water.transmission.value, water.ior), (1.0, 1.33));
    assert_eq!(water.alpha_mode, AlphaMode::Opaque);
    assert_eq!(mat("grey").base_color.value, [0.5; 3]);
    assert_eq!(mat("grey").metallic.value, 0.0);
    // Out of range as written; the scene clamps it.
    assert_eq!(mat("hot").base_color.value, [3.0, -1.0, 0.5]);
}

#[test]
fn mtl_roughness_falls_as_the_phong_exponent_rises() {
    let roughness = |ns: f32| {
        let text = format!("newmtl m\nKd 0 0 0\nKs 1 1 1\nNs {ns}\n");
        let dir = TempDir::new();
        dir.write("m.mtl", text);
        let p = dir.write(
            "m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
        );
        load(&p).unwrap().materials[0].roughness.value
    };
    let r: Vec<f32> = [0.0, 10.0, 100.0, 10000.0].map(roughness).to_vec();
    assert!((r[0] - 1.0).abs() < 1e-6);
    assert!(r.windows(2).all(|w| w[1] < w[0]), "{r:?}");
    assert!(r[3] < 0.12);
}

#[test]
fn a_missing_mtl_file_only_means_no_materials() {
    let m = load_text(
        "nomtl.obj",
        "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
    )
    .unwrap();
    assert!(m.materials.is_empty());
    assert_eq!(m.meshes[0].material, vec![NO_MATERIAL]);
}

#[test]
fn objects_become_separate_meshes_and_polylines_are_ignored() {
    let m = load_text(
        "two.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\no a\nf 1 2 3\nl 1 2 4\np 4\no b\nf -4 -3 -1\n",
    )
    .unwrap();
    assert_eq!(m.meshes.len(), 2);
    assert_eq!(m.instances, vec![(0, Mat4::IDENTITY), (1, Mat4::IDENTITY)]);
    assert_eq!(
        m.triangle_count(),
        2,
        "the three-point polyline is no triangle"
    );
    assert!(m.meshes[1].positions.contains(&[5.0, 5.0, 5.0]));
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let m = load_text(
        "deg.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 1 0 0\n\
         f 1 2 3\nf 1 1 2\nf 1 2 4\nf 2 5 3\nf 3 2 1\n",
    )
    .unwrap();
    // 1 1 2 repeats an index; 1 2 4 lies on the x axis; 2 5 3 repeats a
    // position under two indices.
    assert_eq!(m.skipped_degenerate, 3);
    assert_eq!(m.meshes[0].triangles.len(), 2);
    // A tiny but real triangle is kept.
    let m = load_text("tiny.obj", "v 0 0 0\nv 1e-20 0 0\nv 0 1e-20 0\nf 1 2 3\n").unwrap();
    assert_eq!((m.triangle_count(), m.skipped_degenerate), (1, 0));
}

// ------------------------------------------------------------- bad OBJ input

/// Asserts that the OBJ `text` is refused at `line` with a message containing
/// `words`.
fn refused_at(text: &str, line: usize, words: &str) {
    let e = error_of("bad.obj", text);
    assert_eq!(e.line(), Some(line), "{e}");
    assert!(e.to_string().contains(&format!("bad.obj:{line}: ")), "{e}");
    assert!(e.message().contains(words), "{e}");
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn malformed_obj_is_refused_with_file_and_line() {
    refused_at("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", 2, "three numbers");
    refused_at("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", 2, "three numbers");
    refused_at("v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 1, "w is 0");
    refused_at(&format!("{TRI}vn 0 0\nf 1 2 3\n"), 4, "normal");
    refused_at(&format!("{TRI}vt zero 0\nf 1 2 3\n"), 4, "texture");
    refused_at(
        &format!("{TRI}f 1 2 3\nf 1 2 4\n"),
        5,
        "face index 4 out of range (the file has 3 vertices)",
    );
    refused_at(&format!("{TRI}\nf 1 2 2000\n"), 5, "2000 out of range");
    refused_at(&format!("{TRI}f 0 1 2\n"), 4, "index 0");
    refused_at(&format!("{TRI}f 1 2 -4\n"), 4, "-4 out of range");
    refused_at(&format!("{TRI}f 1 2\n"), 4, "at least 3");
    refused_at(&format!("{TRI}f 1\n"), 4, "at least 3");
    refused_at(&format!("{TRI}f\n"), 4, "at least 3");
    refused_at(&format!("{TRI}f 1 2 3.5\n"), 4, "not an integer");
    refused_at(&format!("{TRI}f 1 2 x\n"), 4, "not an integer");
    refused_at(&format!("{TRI}f 1/1/1/1 2 3\n"), 4, "v/vt/vn");
    refused_at(
        &format!("{TRI}f 1/1 2/1 3/1\n"),
        4,
        "texture coordinate index 1 out of range",
    );
    refused_at(
        &format!("{TRI}f 1//9 2//9 3//9\n"),
        4,
        "normal index 9 out of range",
    );
    refused_at(
        &format!("{TRI}f 1 2 -9223372036854775808\n"),
        4,
        "out of range",
    );
    refused_at(&format!("{TRI}usemtl\nf 1 2 3\n"), 4, "usemtl");
}

#[test]
fn non_finite_numbers_are_refused_with_their_line() {
    refused_at("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", 2, "not finite");
    refused_at("v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n", 3, "not finite");
    refused_at("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n", 2, "not finite");
    refused_at(
        "v 0 0 0\nv 1 0 0 1e-45\nv 0 1 0 1e-45\nf 1 2 3\n",
        2,
        "not finite",
    );
    refused_at(
        &format!("{TRI}vn 0 0 1\nvn NaN 0 1\nf 1//1 2//2 3//1\n"),
        5,
        "normal",
    );
    refused_at(&format!("{TRI}vt 0 -inf\nf 1/1 2/1 3/1\n"), 4, "texture");
}

#[test]
fn obj_without_triangles_is_refused() {
    for text in [
        "",
        "# nothing\n",
        TRI,
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    ] {
        let e = error_of("empty.obj", text);
        assert!(e.message().contains("no triangles"), "{e}");
        assert_eq!(e.line(), None);
    }
}

#[test]
fn text_that_is_not_utf8_is_refused_at_its_line() {
    let mut bytes = TRI.as_bytes().to_vec();
    bytes.extend_from_slice(b"f 1 2 \xff\n");
    let e = error_of("bin.obj", bytes);
    assert_eq!(e.line(), Some(4), "{e}");
}

#[test]
fn malformed_mtl_is_refused_naming_the_mtl_file_and_line() {
    for (mtl, line, words) in [
        (&b"newmtl a\nKd 1 1\n"[..], 2, "Kd has 2 numbers"),
        (b"newmtl a\n\nKs\n", 3, "Ks has 0 numbers"),
        (
            b"newmtl a\nKd 1 1 1\nNs shiny\n",
            3,
            "Ns needs a finite number",
        ),
        (b"newmtl a\nNi inf\n", 2, "Ni needs a finite number"),
        (b"newmtl a\nKd 1 nan 1\n", 2, "Kd needs finite numbers"),
        (b"newmtl a\nillum x\n", 2, "illum"),
        (b"newmtl a\nTr clear\n", 2, "Tr"),
        (b"newmtl a\nKd 1 1 1\xff\n", 2, "UTF-8"),
    ] {
        let dir = TempDir::new();
        let mtl_path = dir.write("bad.mtl", mtl);
        let obj = dir.write("ok.obj", format!("mtllib bad.mtl\n{TRI}f 1 2 3\n"));
        let e = load(&obj).expect_err(words);
        assert_eq!(e.file(), mtl_path, "{e}");
        assert_eq!(e.line(), Some(line), "{e}");
        assert!(e.to_string().contains(&format!("bad.mtl:{line}: ")), "{e}");
        assert!(e.message().contains(words), "{e}");
    }
}

#[test]
fn missing_files_directories_and_unknown_formats_are_refused() {
    let dir = TempDir::new();
    for name in ["absent.obj", "absent.glb", "absent.gltf"] {
        let path = dir.0.join(name);
        let e = load(&path).unwrap_err();
        assert_eq!(e.file(), path);
        assert!(
            e.to_string().contains(name) && e.message().contains("no such file"),
            "{e}"
        );
    }
    let sub = dir.0.join("folder.obj");
    std::fs::create_dir(&sub).unwrap();
    let e = load(&sub).unwrap_err();
    assert!(e.message().contains("directory"), "{e}");
    for name in ["mesh.stl", "mesh", "mesh.obj.bak"] {
        let path = dir.write(name, TRI);
        let e = load(&path).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
        assert!(e.message().contains(".obj, .gltf, .glb"), "{e}");
    }
    // The extension is matched without regard to case.
    let upper = dir.write("TRI.OBJ", format!("{TRI}f 1 2 3\n"));
    assert_eq!(load(&upper).unwrap().triangle_count(), 1);
}

// --------------------------------------------------------------------- glTF

/// A buffer with the triangle (0,0,0), (1,0,0), (0,1,0) as f32 positions
/// (36 bytes) followed by u16 indices 0 1 2 (6 bytes, 2 of padding).
fn triangle_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// A glTF document: `nodes` and `scene` as given, one mesh (the triangle of
/// [`triangle_buffer`]) with material 0, in buffer `uri`.
fn gltf_json(uri: &str, nodes: &str, extra: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  {extra}
  "nodes": {nodes},
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "materials": [{{"name": "steel", "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.6, 0.7, 1], "metallicFactor": 1, "roughnessFactor": 0.5}}, "emissiveFactor": [0.1, 0.2, 0.3], "doubleSided": true}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}
  ],
  "buffers": [{{"byteLength": 44, "uri": "{uri}"}}]
}}"#
    )
}

/// Parent (translation 10,0,0) with two children using mesh 0: one scaled by
/// 2 and turned 90° about z, one placed by a matrix (translation 0,5,0).
const HIERARCHY: &str = r#"[
    {"translation": [10, 0, 0], "children": [1, 2]},
    {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, 0, 0.70710678, 0.70710678]},
    {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,5,0,1]}
  ]"#;

#[test]
fn gltf_hierarchy_composes_transforms_and_shares_the_mesh() {
    let text = gltf_json(
        &data_uri(&triangle_buffer()),
        HIERARCHY,
        r#""scene": 0, "scenes": [{"nodes": [0]}],"#,
    );
    let dir = TempDir::new();
    let m = load(&dir.write("h.gltf", text)).unwrap();
    assert_eq!(m.meshes.len(), 1, "a mesh used by two nodes is stored once");
    assert_eq!(m.instances.len(), 2);
    assert!(m.instances.iter().all(|&(i, _)| i == 0));
    let mesh = &m.meshes[0];
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(mesh.material, vec![0]);
    let v = glam::Vec3::from_array(mesh.positions[1]);
    assert_eq!(v, glam::Vec3::X);
    let placed: Vec<glam::Vec3> = m
        .instances
        .iter()
        .map(|(_, t)| t.transform_point3(v))
        .collect();
    // (1,0,0) scaled to (2,0,0), turned to (0,2,0), moved to (10,2,0).
    assert!(
        placed[0].abs_diff_eq(glam::Vec3::new(10.0, 2.0, 0.0), 1e-5),
        "{placed:?}"
    );
    assert!(
        placed[1].abs_diff_eq(glam::Vec3::new(11.0, 5.0, 0.0), 1e-6),
        "{placed:?}"
    );

    let steel = &m.materials[0];
    assert_eq!(steel.name, "steel");
    assert!(steel.double_sided);
    assert_eq!(steel.emission.value, [0.1, 0.2, 0.3]);
    assert_eq!(steel.base_color.value, [0.5, 0.6, 0.7]);
    assert_eq!((steel.metallic.value, steel.roughness.value), (1.0, 0.5));
    assert!(
        steel.vertex_color,
        "glTF colours by COLOR_0 where a mesh has it"
    );
}

#[test]
fn gltf_without_a_default_scene_uses_every_root_node() {
    // Node 3 is a second root; node 4 is referenced by no one and so a root too.
    let nodes = HIERARCHY.trim_end().trim_end_matches(']').to_string()
        + r#", {"mesh": 0, "translation": [0, 0, 7]}, {"children": []}]"#;
    let dir = TempDir::new();
    let m = load(&dir.write(
        "roots.gltf",
        gltf_json(&data_uri(&triangle_buffer()), &nodes, ""),
    ))
    .unwrap();
    assert_eq!(m.instances.len(), 3);
    let z: Vec<f32> = m.instances.iter().map(|(_, t)| t.w_axis.z).collect();
    assert!(z.contains(&7.0), "{z:?}");
}

#[test]
fn gltf_external_buffer_and_glb_container() {
    let dir = TempDir::new();
    dir.write("tri data.bin", triangle_buffer());
    let nodes = r#"[{"mesh": 0}]"#;
    let json = gltf_json("tri%20data.bin", nodes, "");
    let m = load(&dir.write("ext.gltf", &json)).unwrap();
    assert_eq!(m.triangle_count(), 1);

    // The same document as GLB: the buffer becomes the binary chunk.
    let json = json.replace(r#", "uri": "tri%20data.bin""#, "");
    let glb = make_glb(&json, &triangle_buffer());
    let g = load(&dir.write("tri.glb", glb)).unwrap();
    // The same model from different files: only the files' checksums differ.
    assert_ne!((g.file_crc, g.file_len), (m.file_crc, m.file_len));
    assert_eq!(
        (g.meshes, g.materials, g.instances),
        (m.meshes, m.materials, m.instances)
    );
}

/// Packs a JSON document and a binary chunk into GLB.
fn make_glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

#[test]
fn gltf_transmission_and_strips_and_fans() {
    let mut buf = Vec::new();
    // A unit square as a strip (0 1 2 3) and as a fan (0 1 3 2).
    for v in [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0,
    ] {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u8, 1, 2, 3, 0, 1, 3, 2] {
        buf.push(i);
    }
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": 5, "material": 0}},
    {{"attributes": {{"POSITION": 0}}, "indices": 2, "mode": 6}},
    {{"attributes": {{"POSITION": 0}}, "mode": 1}}]}}],
  "materials": [{{"extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}, "KHR_materials_ior": {{"ior": 1.7}}}}}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5121, "count": 4, "type": "SCALAR"}},
    {{"bufferView": 1, "byteOffset": 4, "componentType": 5121, "count": 4, "type": "SCALAR"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 8}}],
  "buffers": [{{"byteLength": 56, "uri": "{}"}}]}}"#,
        data_uri(&buf)
    );
    let m = load_text("sf.gltf", &json).unwrap();
    assert_eq!(m.skipped_primitives, 1, "the LINES primitive");
    let mesh = &m.meshes[0];
    assert_eq!(mesh.triangles.len(), 4);
    assert_eq!(
        mesh.positions.len(),
        8,
        "each primitive brings its vertices"
    );
    assert!(
        mesh.triangles.iter().all(|&t| cross_z(mesh, t) > 0.0),
        "winding kept"
    );
    assert_eq!(mesh.material, vec![0, 0, NO_MATERIAL, NO_MATERIAL]);
    assert_eq!(m.materials[0].name, "material 0");
    assert_eq!(m.materials[0].transmission.value, 1.0);
    assert_eq!(m.materials[0].ior, 1.7);
}

// ------------------------------------------------------------ bad glTF input

fn gltf_refused(name: &str, bytes: impl AsRef<[u8]>, words: &str) {
    let e = error_of(name, bytes);
    assert!(e.message().contains(words), "{e}");
}

#[test]
fn corrupt_or_inconsistent_gltf_is_refused() {
    let buf = triangle_buffer();
    let nodes = r#"[{"mesh": 0}]"#;
    let good = gltf_json(&data_uri(&buf), nodes, "");
    assert!(load_text("good.gltf", &good).is_ok());

    gltf_refused("empty.gltf", "", "invalid glTF");
    gltf_refused("cut.gltf", &good[..good.len() / 2], "invalid glTF");
    gltf_refused(
        "missing.gltf",
        gltf_json("nowhere.bin", nodes, ""),
        "nowhere.bin",
    );
    gltf_refused(
        "nobin.gltf",
        good.replace(&format!(r#", "uri": "{}""#, data_uri(&buf)), ""),
        "binary chunk, which is missing",
    );
    gltf_refused(
        "short.gltf",
        gltf_json(&data_uri(&buf[..40]), nodes, ""),
        "declares 44",
    );
    gltf_refused(
        "b64.gltf",
        gltf_json("data:application/octet-stream;base64,@@@@", nodes, ""),
        "base64",
    );
    gltf_refused(
        "web.gltf",
        gltf_json("https://example.invalid/x.bin", nodes, ""),
        "only files",
    );
    gltf_refused(
        "count.gltf",
        good.replace(
            r#""count": 3, "type": "VEC3""#,
            r#""count": 4, "type": "VEC3""#,
        ),
        "runs past",
    );
    gltf_refused(
        "huge.gltf",
        good.replace(
            r#""count": 3, "type": "VEC3""#,
            r#""count": 4611686018427387904, "type": "VEC3""#,
        ),
        "runs past",
    );
    gltf_refused(
        "view.gltf",
        good.replace(
            r#""byteOffset": 36, "byteLength": 6"#,
            r#""byteOffset": 40, "byteLength": 6"#,
        ),
        "runs past the end of buffer 0",
    );
    gltf_refused(
        "acc.gltf",
        good.replace(r#""indices": 1"#, r#""indices": 7"#),
        "invalid glTF",
    );
    gltf_refused(
        "type.gltf",
        good.replace(r#""type": "VEC3""#, r#""type": "VEC2""#),
        "expected Vec3",
    );
    gltf_refused(
        "cycle.gltf",
        gltf_json(
            &data_uri(&buf),
            r#"[{"mesh": 0, "children": [1]}, {"children": [0]}]"#,
            r#""scene": 0, "scenes": [{"nodes": [0]}],"#,
        ),
        "reached twice",
    );
    gltf_refused(
        "nomesh.gltf",
        gltf_json(&data_uri(&buf), r#"[{}]"#, ""),
        "no triangles",
    );

    gltf_refused(
        "attr.gltf",
        good.replace(r#""POSITION": 0"#, r#""POSITION": 9"#),
        "attribute accessor 9 does not exist",
    );
    // An index past the vertices.
    let mut bad = buf.clone();
    bad[38..40].copy_from_slice(&3u16.to_le_bytes());
    gltf_refused(
        "index.gltf",
        gltf_json(&data_uri(&bad), nodes, ""),
        "index 3 out of range (the primitive has 3 vertices)",
    );
    // A NaN position (JSON cannot hold one, a buffer can).
    let mut nan = buf.clone();
    nan[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    gltf_refused(
        "nan.gltf",
        gltf_json(&data_uri(&nan), nodes, ""),
        "vertex 1 has a non-finite position",
    );
    // A transform beyond f32: JSON numbers are read exactly (serde_json's
    // `float_roundtrip`, which scene files need), so it is refused where
    // it is written, with its line and column.
    gltf_refused(
        "inf.gltf",
        gltf_json(
            &data_uri(&buf),
            r#"[{"mesh": 0, "scale": [1e39, 1, 1]}]"#,
            "",
        ),
        "number out of range at line",
    );
    // Only degenerate triangles.
    let mut flat = buf.clone();
    flat[16..20].copy_from_slice(&0.0f32.to_le_bytes());
    flat[28..32].copy_from_slice(&0.0f32.to_le_bytes());
    gltf_refused(
        "flat.gltf",
        gltf_json(&data_uri(&flat), nodes, ""),
        "no triangles with area",
    );
}

#[test]
fn truncated_or_corrupt_glb_is_refused() {
    let glb = std::fs::read(asset("bunny.glb")).unwrap();
    for cut in [0, 3, 4, 12, 19, 20, 100, glb.len() / 2, glb.len() - 1] {
        let e = error_of("cut.glb", &glb[..cut]);
        assert!(!e.message().is_empty());
    }
    let mut lying = glb.clone();
    lying[8..12].copy_from_slice(&5u32.to_le_bytes());
    gltf_refused("len.glb", &lying, "header says 5 bytes");
    let mut version = glb.clone();
    version[4] = 7;
    gltf_refused("ver.glb", &version, "invalid glTF");
}

// --------------------------------------------------------------------- fuzz

/// Loads `bytes` as `name` in `dir`; a panic fails the test, and an error
/// must name the file.
pub(super) fn load_mutant(dir: &TempDir, name: &str, bytes: &[u8]) -> bool {
    let path = dir.write(name, bytes);
    match load(&path) {
        Ok(m) => {
            assert!(m.triangle_count() > 0);
            true
        }
        Err(e) => {
            assert!(
                e.to_string().starts_with(&path.display().to_string()),
                "{e}"
            );
            false
        }
    }
}

/// One random change: flip bits of a byte, overwrite a byte with one that
/// matters to the format, truncate, or delete or duplicate a line.
/// Half the changes fall in the first `head` bytes (a GLB's JSON chunk).
pub(super) fn mutate(rng: &mut crate::rng::Rng, bytes: &mut Vec<u8>, head: usize) {
    let n = bytes.len().max(1);
    let span = if rng.next_u32().is_multiple_of(2) {
        n.min(head)
    } else {
        n
    };
    let at = rng.next_u32() as usize % span;
    let line_start = |at: usize, b: &[u8]| {
        b[..at]
            .iter()
            .rposition(|&c| c == b'\n')
            .map_or(0, |p| p + 1)
    };
    let line_end = |at: usize, b: &[u8]| {
        b[at..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(b.len(), |p| at + p + 1)
    };
    match rng.next_u32() % 6 {
        0 if !bytes.is_empty() => bytes[at] ^= 1 << (rng.next_u32() % 8),
        1 if !bytes.is_empty() => {
            const SPECIAL: &[u8] = b"0123456789-./ \n\0\xff{}[]\":,efvnatx";
            bytes[at] = SPECIAL[rng.next_u32() as usize % SPECIAL.len()];
        }
        2 => bytes.truncate(at),
        3 if !bytes.is_empty() => {
            let (s, e) = (line_start(at, bytes), line_end(at, bytes));
            bytes.drain(s..e);
        }
        4 if !bytes.is_empty() => {
            let (s, e) = (line_start(at, bytes), line_end(at, bytes));
            let line = bytes[s..e].to_vec();
            bytes.splice(s..s, line);
        }
        _ if !bytes.is_empty() => {
            // A random 32-bit value, which in a GLB hits lengths and offsets.
            let end = (at + 4).min(bytes.len());
            let word = rng.next_u32().to_le_bytes();
            bytes[at..end].copy_from_slice(&word[..end - at]);
        }
        _ => {}
    }
}

#[test]
fn mutated_bunnies_never_panic() {
    let t = Instant::now();
    let dir = TempDir::new();
    let mut rng = crate::rng::Rng::new(0x6d65_7368);
    let glb = std::fs::read(asset("bunny.glb")).unwrap();
    let json_end = 20 + u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let gltf = gltf_json(
        &data_uri(&triangle_buffer()),
        HIERARCHY,
        r#""scene": 0, "scenes": [{"nodes": [0]}],"#,
    );
    dir.write("m.mtl", RICH_MTL);
    // The texture the MTL names.
    ::image::RgbImage::new(1, 1)
        .save(dir.0.join("tex.png"))
        .unwrap();
    for (name, original, head, rounds) in [
        (
            "bunny.obj",
            std::fs::read(asset("bunny.obj")).unwrap(),
            usize::MAX,
            1500,
        ),
        ("rich.obj", RICH_OBJ.as_bytes().to_vec(), usize::MAX, 1000),
        ("bunny.glb", glb, json_end, 2000),
        ("tree.gltf", gltf.into_bytes(), usize::MAX, 1500),
    ] {
        let (mut ok, mut refused) = (0, 0);
        for round in 0..rounds {
            let mut bytes = original.clone();
            for _ in 0..1 + rng.next_u32() % 4 {
                mutate(&mut rng, &mut bytes, head);
            }
            let mutant = format!("mutant-{round}.{}", name.rsplit('.').next().unwrap());
            if load_mutant(&dir, &mutant, &bytes) {
                ok += 1;
            } else {
                refused += 1;
            }
            let _ = std::fs::remove_file(dir.0.join(&mutant));
        }
        eprintln!("{name}: {ok} mutants loaded, {refused} refused");
        // Both outcomes occur: the mutations neither always break the file
        // nor never do.
        assert!(
            ok > 0 && refused > 0,
            "{name}: {ok} loaded, {refused} refused"
        );
    }
    // The MTL file of a fixed OBJ.
    let obj = dir.write("rich.obj", RICH_OBJ);
    let mtl = dir.0.join("m.mtl");
    let (mut ok, mut refused) = (0, 0);
    for _ in 0..1000 {
        let mut bytes = RICH_MTL.as_bytes().to_vec();
        for _ in 0..1 + rng.next_u32() % 4 {
            mutate(&mut rng, &mut bytes, usize::MAX);
        }
        std::fs::write(&mtl, &bytes).unwrap();
        match load(&obj) {
            Ok(m) => {
                assert_eq!(m.triangle_count(), 7);
                ok += 1;
            }
            Err(e) => {
                assert_eq!(e.file(), mtl, "{e}");
                refused += 1;
            }
        }
    }
    eprintln!("m.mtl: {ok} mutants loaded, {refused} refused");
    assert!(ok > 0 && refused > 0);
    eprintln!("fuzzing took {:?}", t.elapsed());
}

/// An OBJ with objects, groups, materials, texture coordinates, normals,
/// quads and relative indices, for the mutation test.
const RICH_OBJ: &str = "mtllib m.mtl\n# a comment\n\
    v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1 1\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\n\
    o first\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/1/1\nusemtl glass\nf 1//2 2//2 5//2\n\
    g second\ns 1\nusemtl chrome\nf -5/-3 -4/-2 -3/-1\nf 1 3 5\nl 1 2 3\n\
    o third\nusemtl nosuch\nf 2 3 4 5\n";

const RICH_MTL: &str = "newmtl red\nKd 1 0.2 0\nKe 0 0 4\n\
    newmtl chrome\nKd 0 0 0\nKs 0.9 0.8 0.7\nNs 1000\nillum 3\n\
    newmtl glass\nKd 1 1 1\nNi 1.45\nd 0.1\nTr 0.9\nmap_Kd tex.png\n";

/// An MTL file's maps and the PBR extension are read into the material:
/// each map's channel and encoding, the options on its line, each image
/// read once.
#[test]
fn mtl_maps_and_the_pbr_extension_are_read() {
    use crate::texture::{Channels, Wrap};
    let dir = TempDir::new();
    let png = |name: &str, rgba: [u8; 4]| {
        let image = ::image::RgbaImage::from_pixel(2, 2, ::image::Rgba(rgba));
        image.save(dir.0.join(name)).unwrap();
    };
    png("colour.png", [200, 100, 50, 255]);
    png("grey.png", [128, 128, 128, 255]);
    png("cut.png", [255, 255, 255, 100]);
    png("normal.png", [128, 128, 255, 255]);
    dir.write(
        "m.mtl",
        "newmtl painted\nKd 1 1 1\nKs 0.5 0.5 0.5\nNs 50\n\
         map_Kd -s 2 2 -clamp on colour.png\nmap_Ks colour.png\nmap_Ns grey.png\n\
         map_d cut.png\nbump -bm 0.5 grey.png\nKe 1 1 1\nmap_Ke colour.png\n\
         newmtl pbr\nKd 0.5 0.5 0.5\nPr 0.3\nPm 1\nmap_Pr grey.png\nPc 0.8\nPcr 0.1\nnorm normal.png\n",
    );
    let path = dir.write(
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
         usemtl painted\nf 1/1/1 2/2/1 3/3/1\nusemtl pbr\nf 3/3/1 2/2/1 1/1/1\n",
    );
    let m = load(&path).unwrap();
    let painted = &m.materials[0];
    let base = painted.base_color.map.as_ref().unwrap();
    assert!(base.srgb && base.channels == Channels::Rgb);
    assert_eq!(base.wrap, [Wrap::Clamp; 2]);
    assert_eq!(base.transform.rows, [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    assert!(painted.specular_color.map.is_some(), "map_Ks");
    assert!(
        painted.roughness_from_gloss && painted.roughness.map.is_some(),
        "map_Ns"
    );
    let alpha = painted.alpha.map.as_ref().unwrap();
    assert_eq!(
        alpha.channels,
        Channels::One(3),
        "an image with alpha cuts by it"
    );
    assert_eq!(painted.alpha_mode, AlphaMode::Blend);
    let (bump, height) = painted.bump_map.as_ref().unwrap();
    assert_eq!((*height, bump.srgb), (0.5, false));
    assert!(painted.emission.map.is_some() && painted.emission.value == [1.0; 3]);
    // The same file named by three maps is read once.
    assert!(std::sync::Arc::ptr_eq(
        &base.image,
        &painted.emission.map.as_ref().unwrap().image
    ));
    let pbr = &m.materials[1];
    assert_eq!((pbr.roughness.value, pbr.metallic.value), (0.3, 1.0));
    assert_eq!(
        pbr.roughness.map.as_ref().unwrap().channels,
        Channels::One(0)
    );
    assert_eq!(
        (pbr.clearcoat.value, pbr.clearcoat_roughness.value),
        (0.8, 0.1)
    );
    assert!(!pbr.normal_map.as_ref().unwrap().0.srgb);
    // A normal map asks for tangents, which MikkTSpace made from the
    // vertex normals and coordinates.
    assert!(m.meshes[0].tangents.is_some());
}
