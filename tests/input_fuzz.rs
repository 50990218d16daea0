//! Every input format a scene can name is fuzzed: small valid files of each
//! (OBJ, MTL, glTF, GLB, PLY ASCII and binary, and PNG, JPEG, OpenEXR and
//! Radiance HDR images as a texture and as a sky) mangled by random edits
//! (bytes flipped, cut, repeated, format words and numbers that reach error
//! paths inserted) are loaded, and rendered when they load: nothing may
//! panic, hang or abort, and every error names the file. A bounded number
//! of cases with a fixed seed keeps this to seconds; `tests/corpus/` holds
//! every input that was ever mishandled, each run through the same steps.

mod common;

use common::scratch_dir;
use lumen::scene::file::SceneFile;
use lumen::scene::Overrides;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use std::path::{Path, PathBuf};

/// What a fuzzed file is, and so how it is loaded.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// A mesh file (OBJ, glTF, GLB, PLY), loaded by itself.
    Mesh,
    /// An MTL file, named by an OBJ file beside it.
    Mtl,
    /// A glTF buffer, named by a glTF file beside it.
    Buffer,
    /// An image, read as a texture and as a sky.
    Image,
}

/// One triangle's positions, 36 bytes.
fn triangle() -> Vec<u8> {
    [0f32, 0., -2., 1., 0., -2., 0., 1., -2.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

fn gltf_json(uri: Option<&str>) -> String {
    let uri = uri.map_or(String::new(), |u| format!(r#""uri":"{u}","#));
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{{uri}"byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-2],"max":[1,1,-2]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0,"children":[]}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

fn glb() -> Vec<u8> {
    let mut json = gltf_json(None).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = triangle();
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn binary_ply() -> Vec<u8> {
    let mut out = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    out.extend(triangle());
    out.push(3);
    for i in 0..3i32 {
        out.extend_from_slice(&i.to_le_bytes());
    }
    out
}

fn image_bytes(format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    match format {
        image::ImageFormat::OpenExr | image::ImageFormat::Hdr => {
            let img = image::Rgb32FImage::from_fn(6, 4, |x, y| {
                image::Rgb([x as f32 * 0.3, y as f32 * 0.5, 1.0])
            });
            image::DynamicImage::ImageRgb32F(img)
                .write_to(&mut bytes, format)
                .unwrap();
        }
        _ => {
            let img = image::RgbaImage::from_fn(6, 4, |x, y| {
                image::Rgba([x as u8 * 40, y as u8 * 60, 200, 255])
            });
            let img = match format {
                image::ImageFormat::Jpeg => {
                    image::DynamicImage::ImageRgb8(image::DynamicImage::ImageRgba8(img).to_rgb8())
                }
                _ => image::DynamicImage::ImageRgba8(img),
            };
            img.write_to(&mut bytes, format).unwrap();
        }
    }
    bytes.into_inner()
}

/// The valid files mangled: each with its name and kind.
fn seeds() -> &'static [(&'static str, Kind, Vec<u8>)] {
    static SEEDS: std::sync::OnceLock<Vec<(&str, Kind, Vec<u8>)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(|| {
        let obj = "mtllib m.mtl\nv 0 0 -2\nv 1 0 -2\nv 0 1 -2\nv 1 1 -2\nvt 0 0\nvt 1 0\nvt 0 1\n\
                   vn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1\nusemtl b\nf 2//1 4//1 3//1\n";
        let mtl = "newmtl a\nKd 0.5 0.2 0.1\nKs 0.1 0.1 0.1\nNs 20\nd 1\nmap_Kd t.png\n\
                   newmtl b\nKe 1 1 1\nPr 0.5\nPm 1\nillum 2\nbump -bm 0.5 t.png\n";
        let ascii_ply = "ply\nformat ascii 1.0\ncomment a triangle\nelement vertex 3\n\
                         property float x\nproperty float y\nproperty float z\nproperty float nx\n\
                         property float ny\nproperty float nz\nelement face 1\n\
                         property list uchar int vertex_indices\nend_header\n\
                         0 0 -2 0 0 1\n1 0 -2 0 0 1\n0 1 -2 0 0 1\n3 0 1 2\n";
        vec![
            ("f.obj", Kind::Mesh, obj.as_bytes().to_vec()),
            ("m.mtl", Kind::Mtl, mtl.as_bytes().to_vec()),
            ("f.gltf", Kind::Mesh, gltf_json(Some("b.bin")).into_bytes()),
            ("b.bin", Kind::Buffer, triangle()),
            ("f.glb", Kind::Mesh, glb()),
            ("f.ply", Kind::Mesh, ascii_ply.as_bytes().to_vec()),
            ("g.ply", Kind::Mesh, binary_ply()),
            ("f.png", Kind::Image, image_bytes(image::ImageFormat::Png)),
            ("f.jpg", Kind::Image, image_bytes(image::ImageFormat::Jpeg)),
            (
                "f.exr",
                Kind::Image,
                image_bytes(image::ImageFormat::OpenExr),
            ),
            ("f.hdr", Kind::Image, image_bytes(image::ImageFormat::Hdr)),
        ]
    })
}

/// Words and numbers that tend to reach error paths in these formats.
const TOKENS: &[&[u8]] = &[
    b"\n",
    b" ",
    b"\0",
    b"-1",
    b"0",
    b"4294967295",
    b"1099511627776",
    b"1e39",
    b"nan",
    b"inf",
    b"-0",
    b"f 1 2 3\n",
    b"f 0 0 0\n",
    b"v 1e38 1e38 1e38\n",
    b"vt",
    b"usemtl",
    b"mtllib ../x.mtl\n",
    b"map_Kd /etc/hostname\n",
    b"newmtl",
    b"element vertex 1099511627776\n",
    b"element face 3\n",
    b"property float x\n",
    b"property list uint int vertex_indices\n",
    b"property double",
    b"end_header\n",
    b"format binary_big_endian 1.0\n",
    b"\"uri\":\"../../etc/hostname\"",
    b"\"byteLength\":4294967295",
    b"\"count\":1000000000",
    b"\"children\":[0]",
    b"\"componentType\":5123",
    b"\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]",
    b"\xff\xff\xff\xff",
    b"\x7f\xff\xff\xff",
    b"IHDR",
    b"IDAT",
    b"\xff\xd8\xff",
    b"-Y 30000 +X 30000\n",
    b"#?RADIANCE\n",
];

#[derive(Clone, Debug)]
enum Edit {
    Flip { at: usize, bits: u8 },
    Delete { at: usize, len: usize },
    Insert { at: usize, token: usize },
    Duplicate { at: usize, len: usize },
    Truncate { at: usize },
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(at, bits)| Edit::Flip { at, bits }),
        (any::<usize>(), 0usize..40).prop_map(|(at, len)| Edit::Delete { at, len }),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(at, token)| Edit::Insert { at, token }),
        (any::<usize>(), 0usize..200).prop_map(|(at, len)| Edit::Duplicate { at, len }),
        any::<usize>().prop_map(|at| Edit::Truncate { at }),
    ]
}

fn apply(bytes: &mut Vec<u8>, e: &Edit) {
    let at = |a: usize| a % (bytes.len() + 1);
    match *e {
        Edit::Flip { at: a, bits } => {
            if !bytes.is_empty() {
                let i = a % bytes.len();
                bytes[i] ^= bits;
            }
        }
        Edit::Delete { at: a, len } => {
            let a = at(a);
            let b = (a + len).min(bytes.len());
            bytes.drain(a..b);
        }
        Edit::Insert { at: a, token } => {
            let a = at(a);
            bytes.splice(a..a, TOKENS[token].iter().copied());
        }
        Edit::Duplicate { at: a, len } => {
            let a = at(a);
            let b = (a + len).min(bytes.len());
            let piece = bytes[a..b].to_vec();
            bytes.splice(b..b, piece);
        }
        Edit::Truncate { at: a } => {
            let a = at(a);
            bytes.truncate(a);
        }
    }
}

/// The folder every fuzzed file is written to, with the valid files the
/// fuzzed one is named by or names (an OBJ for an MTL, a glTF file for a
/// buffer, a texture for the MTL's maps).
fn folder(name: &str) -> PathBuf {
    let dir = scratch_dir(&format!("input-fuzz-{name}"));
    for (file, _, bytes) in seeds() {
        std::fs::write(dir.join(file), bytes).unwrap();
    }
    std::fs::write(dir.join("t.png"), image_bytes(image::ImageFormat::Png)).unwrap();
    dir
}

/// A scene of `objects` (TOML) at a few pixels.
fn tiny_scene(objects: &str) -> String {
    format!("[render]\nwidth = 4\nheight = 3\nsamples_per_pixel = 1\nmax_depth = 3\n\n{objects}")
}

/// Loads `bytes` as the file `name` of `kind` in `dir` and renders it when
/// it loads: nothing may panic, and every error names the file.
fn exercise(dir: &Path, name: &str, kind: Kind, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
    let (mesh, shown) = match kind {
        Kind::Mesh => (name, name),
        Kind::Mtl => ("f.obj", name),
        Kind::Buffer => ("f.gltf", name),
        Kind::Image => ("", name),
    };
    let objects = match kind {
        Kind::Image => format!(
            "[background]\ntype = \"image\"\nfile = \"{name}\"\n\n\
             [textures.t]\ntype = \"image\"\nfile = \"{name}\"\n\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = \"t\"\n\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -2]\nradius = 0.5\nmaterial = \"m\"\n"
        ),
        _ => format!("[[objects]]\ntype = \"mesh\"\nfile = \"{mesh}\"\n"),
    };
    let scene_path = dir.join("s.toml");
    std::fs::write(&scene_path, tiny_scene(&objects)).unwrap();
    let file = SceneFile::read(&scene_path).expect("the scene file itself is valid");
    match file.compile(&Overrides::default()) {
        Ok(scene) => {
            lumen::render::render(&scene, &|_| {});
        }
        Err(e) => {
            let message = e.to_string();
            assert!(
                message.contains(shown) || message.contains(mesh),
                "the error does not name the file: {message}"
            );
        }
    }
    // Restored for the next case: the files beside stay valid.
    if let Some((_, _, original)) = seeds().iter().find(|(f, _, _)| *f == name) {
        std::fs::write(dir.join(name), original).unwrap();
    }
}

proptest! {
    // A fixed seed: a failure seen in CI is reproduced by running the test
    // again; change the seed here to explore other cases.
    #![proptest_config(Config {
        cases: 2048,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x1F11E5),
        ..Config::default()
    })]

    #[test]
    fn mangled_input_files_never_panic(
        seed in 0..11usize,
        edits in proptest::collection::vec(edit(), 1..6),
    ) {
        static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
        let dir = DIR.get_or_init(|| folder("mangled"));
        let (name, kind, original) = &seeds()[seed];
        let mut bytes = original.clone();
        for e in &edits {
            apply(&mut bytes, e);
        }
        exercise(dir, name, *kind, &bytes);
    }
}

#[test]
fn the_seeds_load_and_render() {
    let dir = folder("seeds");
    for (name, kind, bytes) in seeds() {
        std::fs::write(dir.join(name), bytes).unwrap();
        let objects = match kind {
            Kind::Image => format!("[background]\ntype = \"image\"\nfile = \"{name}\"\n"),
            Kind::Mtl => "[[objects]]\ntype = \"mesh\"\nfile = \"f.obj\"\n".to_string(),
            Kind::Buffer => "[[objects]]\ntype = \"mesh\"\nfile = \"f.gltf\"\n".to_string(),
            Kind::Mesh => format!("[[objects]]\ntype = \"mesh\"\nfile = \"{name}\"\n"),
        };
        let path = dir.join("s.toml");
        std::fs::write(&path, tiny_scene(&objects)).unwrap();
        let file = SceneFile::read(&path).unwrap();
        if let Err(e) = file.compile(&Overrides::default()) {
            panic!("{name}: {e}");
        }
    }
}

/// Every input that was ever mishandled, kept in `tests/corpus/KIND/`
/// (`mesh`, `mtl`, `buffer`, `image`), goes through the same steps.
#[test]
fn the_corpus_of_past_failures_never_panics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let dir = folder("corpus");
    let mut seen = 0;
    for (sub, kind) in [
        ("mesh", Kind::Mesh),
        ("mtl", Kind::Mtl),
        ("buffer", Kind::Buffer),
        ("image", Kind::Image),
    ] {
        let Ok(entries) = std::fs::read_dir(root.join(sub)) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            // Named as the kind's file is named, keeping the extension.
            let name = match kind {
                Kind::Mtl => "m.mtl".to_string(),
                Kind::Buffer => "b.bin".to_string(),
                _ => format!(
                    "c.{}",
                    path.extension().and_then(|e| e.to_str()).unwrap_or("bin")
                ),
            };
            exercise(&dir, &name, kind, &bytes);
            seen += 1;
        }
    }
    assert!(seen > 0, "the corpus is empty");
}
