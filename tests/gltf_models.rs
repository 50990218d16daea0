//! Khronos glTF sample models (`assets/khronos`): each loads, reports what
//! it holds and renders; normal maps reflect the sky as the geometry they
//! were baked from does.

mod common;

use common::{compile_file, scratch_dir};
use lumen::mesh;
use std::path::{Path, PathBuf};

/// The shipped model `name`: its `.glb`, or its `.gltf`.
fn model(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/khronos")
        .join(name);
    for ext in ["glb", "gltf"] {
        let p = dir.join(format!("{name}.{ext}"));
        if p.exists() {
            return p;
        }
    }
    panic!("no model {name}");
}

/// The JSON of a glTF file, read here independently of lumen's loader.
fn json_of(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let json = if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        bytes[20..20 + len].to_vec()
    } else {
        bytes
    };
    serde_json::from_slice(&json).unwrap()
}

const MODELS: [&str; 11] = [
    "AttenuationTest",
    "ClearCoatTest",
    "EmissiveStrengthTest",
    "MetalRoughSpheresNoTextures",
    "NormalTangentMirrorTest",
    "NormalTangentTest",
    "SpecularTest",
    "TextureCoordinateTest",
    "TextureSettingsTest",
    "TextureTransformTest",
    "VertexColorTest",
];

/// Every shipped model loads with as many materials as the file has,
/// reads each image it uses once, and renders without a dropped sample.
#[test]
fn every_model_loads_reports_and_renders() {
    let dir = scratch_dir("gltf-models");
    for name in MODELS {
        let path = model(name);
        let json = json_of(&path);
        let m = mesh::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let count = |key: &str| json[key].as_array().map_or(0, Vec::len);
        assert_eq!(m.materials.len(), count("materials"), "{name}");
        assert!(m.triangle_count() > 0, "{name}");
        let scene = compile_file(
            &dir,
            "m.toml",
            &format!(
                r#"
[render]
width = 12
height = 12
samples_per_pixel = 2
integrator = "path"

[camera]
vfov = 60
lookfrom = [0, 0.3, 4]
lookat = [0, 0, 0]

[background]
type = "solid"
color = [0.8, 0.8, 0.8]

[[objects]]
type = "mesh"
file = "{}"
"#,
                path.display()
            ),
        );
        let report = &scene.reports[0];
        // Images used by textures, each counted once.
        let mut used: Vec<u64> = json["textures"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|t| t["source"].as_u64())
            .collect();
        used.sort();
        used.dedup();
        assert!(report.images <= used.len(), "{name}: {report}");
        assert_eq!(report.materials, count("materials"), "{name}");
        let stats = common::pixel_stats(&scene);
        assert_eq!(stats.stats.dropped, 0, "{name}");
    }
}

/// The gold test cells of NormalTangentMirrorTest (the file's tangents,
/// mirrored texture coordinates) and NormalTangentTest (tangents made by
/// MikkTSpace), under a sky bright above and dark below: each cell's bump,
/// real or normal-mapped, reflects the bright sky in its upper half and
/// the dark below in its lower half, as much in every column of a row as
/// in the real geometry's. A flipped green channel or tangent turns the
/// normal-mapped cells upside down.
#[test]
fn normal_maps_reflect_as_the_geometry_they_stand_for() {
    let dir = scratch_dir("gltf-normal-maps");
    // The gold cells' boxes in this view (columns and rows of pixels, from
    // each model's layout): the geometry first, then the normal-mapped
    // ones (normal, mirrored in v, mirrored in u; or normal alone).
    let mirror_test: &[(u32, u32)] = &[(109, 127), (128, 146), (148, 166), (168, 186)];
    let tangent_test: &[(u32, u32)] = &[(130, 148), (149, 167)];
    for (name, columns) in [
        ("NormalTangentMirrorTest", mirror_test),
        ("NormalTangentTest", tangent_test),
    ] {
        let scene = compile_file(
            &dir,
            "n.toml",
            &format!(
                r#"
[render]
width = 200
height = 200
samples_per_pixel = 16
max_depth = 4
integrator = "path"

[camera]
vfov = 40
lookfrom = [0, 0, 4.5]
lookat = [0, 0, 0]

[background]
type = "gradient"
bottom = [0.02, 0.02, 0.02]
top = [1, 1, 1]

[[objects]]
type = "mesh"
file = "{}"
"#,
                model(name).display()
            ),
        );
        let stats = common::pixel_stats(&scene);
        let lum = |x: u32, y: u32| {
            let p = stats.pixel(x, y);
            0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
        };
        let rows = [(42, 59), (66, 84), (91, 109), (115, 133), (139, 157)];
        for (r, &(y0, y1)) in rows.iter().enumerate() {
            let contrast: Vec<f64> = columns
                .iter()
                .map(|&(x0, x1)| {
                    // The middle of the cell: the bump.
                    let (cx, cy) = ((x0 + x1) / 2, (y0 + y1) / 2);
                    let half = (x1 - x0) / 4;
                    let mean = |ys: std::ops::Range<u32>| {
                        let mut s = 0.0;
                        let mut n = 0.0;
                        for y in ys {
                            for x in cx - half..=cx + half {
                                s += lum(x, y);
                                n += 1.0;
                            }
                        }
                        s / n
                    };
                    let (top, bottom) = (mean(cy - half..cy), mean(cy + 1..cy + half + 1));
                    (top - bottom) / (top + bottom)
                })
                .collect();
            for (c, k) in contrast.iter().enumerate() {
                assert!(*k > 0.2, "{name} row {r} column {c}: {contrast:?}");
                assert!(
                    (k - contrast[0]).abs() < 0.3,
                    "{name} row {r} column {c} against the geometry: {contrast:?}"
                );
            }
        }
    }
}

/// A glTF file's cameras frame the view: a perspective camera its place,
/// direction and field of view; an orthographic one its place and twice
/// its `ymag` up, scaled by the transforms above it. Each is found by
/// number and by name.
#[test]
fn gltf_cameras_frame_the_view_perspective_and_orthographic() {
    use base64::Engine;
    let dir = scratch_dir("gltf-cameras");
    let mut bytes = Vec::new();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},
"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"cameras":[{{"name":"wide","type":"perspective","perspective":{{"yfov":0.5,"znear":0.1}}}},
           {{"name":"plan","type":"orthographic","orthographic":{{"xmag":3,"ymag":2,"znear":0.1,"zfar":100}}}}],
"nodes":[{{"mesh":0}},{{"camera":0,"translation":[0,0,5]}},
         {{"camera":1,"translation":[1,2,6]}},{{"camera":1,"scale":[1,2,1]}}],
"scenes":[{{"nodes":[0,1,2,3]}}],"scene":0}}"#
    );
    std::fs::write(dir.join("cams.gltf"), gltf).unwrap();
    let scene = |camera: &str| {
        compile_file(
            &dir,
            "s.toml",
            &format!(
                "[render]\nwidth = 20\nheight = 10\n[camera]\n{camera}\n\
                 [[objects]]\ntype = \"mesh\"\nfile = \"cams.gltf\"\n\
                 transform = [{{ scale = 2 }}]\n"
            ),
        )
        .camera
    };
    // Perspective: from (0, 0, 10) (the node's place scaled by 2) down −z,
    // the pixel rows 0.5 rad apart top to bottom.
    for pick in ["gltf = 0", "gltf = \"wide\""] {
        let c = scene(pick);
        let (top, bottom) = (c.central_ray(10, 0), c.central_ray(10, 9));
        assert!((top.origin() - lumen::math::Vec3::new(0.0, 0.0, 10.0)).length() < 1e-5);
        let spread = top.direction.angle_between(bottom.direction);
        assert!((spread - 0.5 * 9.0 / 10.0).abs() < 2e-3, "{pick}: {spread}");
    }
    // Orthographic: parallel rays down −z from a rectangle 2·2·2 = 8 high
    // (and 16 wide) about (2, 4, 12).
    for pick in ["gltf = 1", "gltf = \"plan\""] {
        let c = scene(pick);
        let (a, b) = (c.central_ray(0, 0), c.central_ray(19, 9));
        assert_eq!(a.direction, b.direction);
        assert!((a.direction.z + 1.0).abs() < 1e-6);
        let span = b.origin() - a.origin();
        assert!((span.x - 16.0 * 19.0 / 20.0).abs() < 1e-4, "{pick}: {span}");
        assert!((span.y + 8.0 * 9.0 / 10.0).abs() < 1e-4, "{pick}: {span}");
        let centre = 0.5 * (a.origin() + b.origin());
        assert!((centre - lumen::math::Vec3::new(2.0, 4.0, 12.0)).length() < 1e-4);
    }
    // A node stretching the view (pixels that would not be square).
    let e = common::scene_file(
        &dir,
        "stretched.toml",
        "[render]\nwidth = 20\nheight = 10\n[camera]\ngltf = 2\n\
         [[objects]]\ntype = \"mesh\"\nfile = \"cams.gltf\"\n",
    )
    .compile(&lumen::scene::Overrides::default())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("camera.gltf") && e.contains("scales its x by 1 and its y by 2"),
        "{e}"
    );
}
