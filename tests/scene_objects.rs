//! Scene files with quads, boxes, meshes and transform lists: every kind and
//! every step form reads the same from TOML and JSON, through lumen's own
//! reader and through serde, and `export` round-trips them.

mod common;

use common::{scene_file, scratch_dir};
use lumen::scene::desc::{
    BoundaryDesc, DiffuseDesc, MaterialDesc, MetalDesc, ObjectDesc, ScaleDesc, TransformDesc,
};
use lumen::scene::file::{export, Format, SceneFile};
use lumen::scene::{Overrides, SceneDesc};
use std::process::Command;

/// A tetrahedron, closed, faces counter-clockwise from outside.
const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

/// Every object kind and every step form, with the TOML array-of-tables form
/// of a transform list as well as inline lists.
const ALL_TOML: &str = r#"caption = "every object kind and transform step"

[render]
width = 24
height = 16
samples_per_pixel = 2
max_depth = 4

[camera]
lookfrom = [0, 1, 6]
lookat = [0, 0, 0]
shutter = [0.25, 0.75]

[materials.grey]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[materials.gold]
type = "metal"
albedo = [0.8, 0.6, 0.2]
fuzz = 0.1

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "gold"
transform = [{ scale = [1, 2, 1] }, { translate = [-2, 0, 0] }, { motion = [0, 0.5, 0] }]

[[objects]]
type = "medium"
boundary = { type = "box", min = [-1, -1, -1], max = [1, 1, 1] }
density = 0.5
albedo = [0.9, 0.9, 1]
transform = [{ translate = [0, 0, -3] }]

[[objects]]
type = "medium"
boundary = { type = "sphere", center = [1, 0, -1], radius = 0.5 }
density = 2
albedo = [0, 0, 0]

[[objects]]
type = "quad"
corner = [-5, -1, -5]
u = [10, 0, 0]
v = [0, 0, 10]
material = "grey"

[[objects]]
type = "box"
min = [-0.5, -0.5, -0.5]
max = [0.5, 0.5, 0.5]
material = "grey"
transform = [
  { rotate = { axis = [0, 1, 0], degrees = 30 } },
  { scale = 1.5 },
  { translate = [2, 0, 0] },
]

[[objects]]
type = "mesh"
file = "tetra.obj"
transform = [{ matrix = [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]] }]

[[objects]]
type = "mesh"
file = "tetra.obj"
material = "gold"
smooth = false

[[objects.transform]]
rotate = { axis = [1, 1, 0], degrees = -45.5 }

[[objects.transform]]
scale = 2
"#;

const ALL_JSON: &str = r#"{
  "caption": "every object kind and transform step",
  "render": { "width": 24, "height": 16, "samples_per_pixel": 2, "max_depth": 4 },
  "camera": { "lookfrom": [0, 1, 6], "lookat": [0, 0, 0], "shutter": [0.25, 0.75] },
  "materials": {
    "grey": { "type": "diffuse", "albedo": [0.5, 0.5, 0.5] },
    "gold": { "type": "metal", "albedo": [0.8, 0.6, 0.2], "fuzz": 0.1 }
  },
  "objects": [
    { "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "gold",
      "transform": [{ "scale": [1, 2, 1] }, { "translate": [-2, 0, 0] }, { "motion": [0, 0.5, 0] }] },
    { "type": "medium", "boundary": { "type": "box", "min": [-1, -1, -1], "max": [1, 1, 1] },
      "density": 0.5, "albedo": [0.9, 0.9, 1], "transform": [{ "translate": [0, 0, -3] }] },
    { "type": "medium", "boundary": { "type": "sphere", "center": [1, 0, -1], "radius": 0.5 },
      "density": 2, "albedo": [0, 0, 0] },
    { "type": "quad", "corner": [-5, -1, -5], "u": [10, 0, 0], "v": [0, 0, 10], "material": "grey" },
    { "type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "grey",
      "transform": [
        { "rotate": { "axis": [0, 1, 0], "degrees": 30 } },
        { "scale": 1.5 },
        { "translate": [2, 0, 0] }
      ] },
    { "type": "mesh", "file": "tetra.obj",
      "transform": [{ "matrix": [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]] }] },
    { "type": "mesh", "file": "tetra.obj", "material": "gold", "smooth": false,
      "transform": [{ "rotate": { "axis": [1, 1, 0], "degrees": -45.5 } }, { "scale": 2 }] }
  ]
}
"#;

/// What both files say, written out by hand from the format's description.
fn expected() -> SceneDesc {
    let mut desc = SceneDesc {
        caption: "every object kind and transform step".into(),
        ..SceneDesc::default()
    };
    desc.render.width = 24;
    desc.render.height = Some(16);
    desc.render.samples_per_pixel = 2;
    desc.render.max_depth = 4;
    desc.camera.lookfrom = [0.0, 1.0, 6.0];
    desc.camera.lookat = [0.0, 0.0, 0.0];
    desc.camera.shutter = [0.25, 0.75];
    desc.materials.insert(
        "grey".into(),
        MaterialDesc::Diffuse(DiffuseDesc {
            albedo: [0.5; 3].into(),
            bounce: Default::default(),
            attenuation: Default::default(),
            ..Default::default()
        }),
    );
    desc.materials.insert(
        "gold".into(),
        MaterialDesc::Metal(MetalDesc {
            albedo: [0.8, 0.6, 0.2].into(),
            fuzz: 0.1,
            ..Default::default()
        }),
    );
    desc.objects = vec![
        ObjectDesc::Sphere {
            flip_normals: false,
            center: [0.0; 3],
            radius: 1.0,
            material: "gold".into(),
            transform: vec![
                TransformDesc::Scale(ScaleDesc::PerAxis([1.0, 2.0, 1.0])),
                TransformDesc::Translate([-2.0, 0.0, 0.0]),
                TransformDesc::Motion([0.0, 0.5, 0.0]),
            ],
        },
        ObjectDesc::Medium {
            boundary: BoundaryDesc::Box {
                min: [-1.0; 3],
                max: [1.0; 3],
            },
            density: 0.5,
            albedo: [0.9, 0.9, 1.0],
            transform: vec![TransformDesc::Translate([0.0, 0.0, -3.0])],
        },
        ObjectDesc::Medium {
            boundary: BoundaryDesc::Sphere {
                center: [1.0, 0.0, -1.0],
                radius: 0.5,
            },
            density: 2.0,
            albedo: [0.0; 3],
            transform: vec![],
        },
        ObjectDesc::Quad {
            flip_normals: false,
            corner: [-5.0, -1.0, -5.0],
            u: [10.0, 0.0, 0.0],
            v: [0.0, 0.0, 10.0],
            material: "grey".into(),
            transform: vec![],
        },
        ObjectDesc::Box {
            flip_normals: false,
            min: [-0.5; 3],
            max: [0.5; 3],
            material: "grey".into(),
            transform: vec![
                TransformDesc::Rotate {
                    axis: [0.0, 1.0, 0.0],
                    degrees: 30.0,
                },
                TransformDesc::Scale(ScaleDesc::Uniform(1.5)),
                TransformDesc::Translate([2.0, 0.0, 0.0]),
            ],
        },
        ObjectDesc::Mesh {
            flip_normals: false,
            file: "tetra.obj".into(),
            material: None,
            smooth: true,
            allow_outside: false,
            part: None,
            flip_v: false,
            transform: vec![TransformDesc::Matrix([
                [1.0, 0.0, 0.0, 0.5],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, -1.0],
                [0.0, 0.0, 0.0, 1.0],
            ])],
        },
        ObjectDesc::Mesh {
            flip_normals: false,
            file: "tetra.obj".into(),
            material: Some("gold".into()),
            smooth: false,
            allow_outside: false,
            part: None,
            flip_v: false,
            transform: vec![
                TransformDesc::Rotate {
                    axis: [1.0, 1.0, 0.0],
                    degrees: -45.5,
                },
                TransformDesc::Scale(ScaleDesc::Uniform(2.0)),
            ],
        },
    ];
    desc
}

#[test]
fn every_kind_and_step_reads_the_same_from_toml_and_json() {
    let toml = SceneFile::parse("all.toml", ALL_TOML.into(), Format::Toml).unwrap();
    let json = SceneFile::parse("all.json", ALL_JSON.into(), Format::Json).unwrap();
    assert_eq!(toml.desc, expected());
    assert_eq!(json.desc, expected());
    // And the scene they describe compiles, with the mesh beside the file.
    let dir = scratch_dir("objects-parse");
    std::fs::write(dir.join("tetra.obj"), TETRA).unwrap();
    for (name, text) in [("all.toml", ALL_TOML), ("all.json", ALL_JSON)] {
        let scene = scene_file(&dir, name, text)
            .compile(&Overrides::default())
            .unwrap_or_else(|e| panic!("{e}"));
        // Two placements of the tetrahedron (4 triangles each), differing
        // in material: stored as two meshes.
        assert_eq!(scene.stats.placed_triangles, 8, "{name}");
        assert_eq!(scene.sources.len(), 1, "{name}: the file is read once");
        assert_eq!(scene.sources[0].file, "tetra.obj");
        assert_eq!(scene.sources[0].len, TETRA.len() as u64);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Each step form alone, inline in TOML and in JSON.
#[test]
fn every_step_form_reads_alone() {
    let cases: &[(&str, &str, TransformDesc)] = &[
        (
            "{ translate = [1, -2.5, 3e2] }",
            r#"{"translate": [1, -2.5, 3e2]}"#,
            TransformDesc::Translate([1.0, -2.5, 300.0]),
        ),
        (
            "{ rotate = { axis = [0, 0, 2], degrees = 90 } }",
            r#"{"rotate": {"axis": [0, 0, 2], "degrees": 90}}"#,
            TransformDesc::Rotate {
                axis: [0.0, 0.0, 2.0],
                degrees: 90.0,
            },
        ),
        (
            "{ rotate = { degrees = -0.25, axis = [1, 0, 0] } }",
            r#"{"rotate": {"degrees": -0.25, "axis": [1, 0, 0]}}"#,
            TransformDesc::Rotate {
                axis: [1.0, 0.0, 0.0],
                degrees: -0.25,
            },
        ),
        (
            "{ scale = 3 }",
            r#"{"scale": 3}"#,
            TransformDesc::Scale(ScaleDesc::Uniform(3.0)),
        ),
        (
            "{ scale = -0.5 }",
            r#"{"scale": -0.5}"#,
            TransformDesc::Scale(ScaleDesc::Uniform(-0.5)),
        ),
        (
            "{ scale = [1, 2, 0.5] }",
            r#"{"scale": [1, 2, 0.5]}"#,
            TransformDesc::Scale(ScaleDesc::PerAxis([1.0, 2.0, 0.5])),
        ),
        (
            "{ matrix = [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3.5], [0, 0, 0, 1]] }",
            r#"{"matrix": [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3.5], [0, 0, 0, 1]]}"#,
            TransformDesc::Matrix([
                [0.0, -1.0, 0.0, 1.0],
                [1.0, 0.0, 0.0, 2.0],
                [0.0, 0.0, 1.0, 3.5],
                [0.0, 0.0, 0.0, 1.0],
            ]),
        ),
        (
            "{ motion = [0, 0.5, -1] }",
            r#"{"motion": [0, 0.5, -1]}"#,
            TransformDesc::Motion([0.0, 0.5, -1.0]),
        ),
    ];
    let mats = "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    for (toml_step, json_step, step) in cases {
        let objects: [(String, String, ObjectDesc); 4] = [
            (
                "type = \"sphere\"\ncenter = [0, 0, -2]\nradius = 1\nmaterial = \"m\"".into(),
                r#""type": "sphere", "center": [0, 0, -2], "radius": 1, "material": "m""#.into(),
                ObjectDesc::Sphere {
                    flip_normals: false,
                    center: [0.0, 0.0, -2.0],
                    radius: 1.0,
                    material: "m".into(),
                    transform: vec![step.clone()],
                },
            ),
            (
                "type = \"quad\"\ncorner = [0, 0, -2]\nu = [1, 0, 0]\nv = [0, 1, 0]\nmaterial = \"m\"".into(),
                r#""type": "quad", "corner": [0, 0, -2], "u": [1, 0, 0], "v": [0, 1, 0], "material": "m""#.into(),
                ObjectDesc::Quad {
                    flip_normals: false,
                    corner: [0.0, 0.0, -2.0],
                    u: [1.0, 0.0, 0.0],
                    v: [0.0, 1.0, 0.0],
                    material: "m".into(),
                    transform: vec![step.clone()],
                },
            ),
            (
                "type = \"box\"\nmin = [0, 0, -3]\nmax = [1, 1, -2]\nmaterial = \"m\"".into(),
                r#""type": "box", "min": [0, 0, -3], "max": [1, 1, -2], "material": "m""#.into(),
                ObjectDesc::Box {
                    flip_normals: false,
                    min: [0.0, 0.0, -3.0],
                    max: [1.0, 1.0, -2.0],
                    material: "m".into(),
                    transform: vec![step.clone()],
                },
            ),
            (
                "type = \"mesh\"\nfile = \"t.obj\"".into(),
                r#""type": "mesh", "file": "t.obj""#.into(),
                ObjectDesc::Mesh {
                    flip_normals: false,
                    file: "t.obj".into(),
                    material: None,
                    smooth: true,
                    allow_outside: false,
                    part: None,
                    flip_v: false,
                    transform: vec![step.clone()],
                },
            ),
        ];
        for (toml_obj, json_obj, want) in objects {
            let toml_text = format!("{mats}\n[[objects]]\n{toml_obj}\ntransform = [{toml_step}]\n");
            let json_text = format!(
                "{{\"materials\": {{\"m\": {{\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}}}},\n \"objects\": [{{{json_obj}, \"transform\": [{json_step}]}}]}}"
            );
            let a = SceneFile::parse("s.toml", toml_text.clone(), Format::Toml)
                .unwrap_or_else(|e| panic!("{e}"));
            let b = SceneFile::parse("s.json", json_text.clone(), Format::Json)
                .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(a.desc.objects, vec![want.clone()], "{toml_text}");
            assert_eq!(b.desc.objects, vec![want.clone()], "{json_text}");
            // serde's derived reader agrees.
            let c: SceneDesc = toml::from_str(&toml_text).unwrap_or_else(|e| panic!("{e}"));
            let d: SceneDesc = serde_json::from_str(&json_text).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(c, a.desc, "serde TOML: {toml_text}");
            assert_eq!(d, b.desc, "serde JSON: {json_text}");
        }
    }
}

#[test]
fn export_round_trips_every_kind_and_step() {
    for format in [Format::Toml, Format::Json] {
        let text = export(&expected(), format).unwrap();
        let back =
            SceneFile::parse("x", text.clone(), format).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back.desc, expected(), "{format:?}:\n{text}");
        assert_eq!(export(&back.desc, format).unwrap(), text, "{format:?}");
        // The exported text also reads through serde.
        let theirs: SceneDesc = match format {
            Format::Toml => toml::from_str(&text).map_err(|e| e.to_string()),
            Format::Json => serde_json::from_str(&text).map_err(|e| e.to_string()),
        }
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(theirs, expected(), "{format:?}");
    }
    // Defaults are left out: `smooth = true` and an empty transform list.
    let toml = export(&expected(), Format::Toml).unwrap();
    assert!(!toml.contains("smooth = true"), "{toml}");
    assert!(toml.contains("smooth = false"), "{toml}");
}

#[test]
fn serde_derive_and_the_scene_reader_agree_on_hand_written_files() {
    let theirs: SceneDesc = toml::from_str(ALL_TOML).unwrap();
    assert_eq!(theirs, expected());
    let theirs: SceneDesc = serde_json::from_str(ALL_JSON).unwrap();
    assert_eq!(theirs, expected());
    let bunny = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bunny.toml");
    let text = std::fs::read_to_string(&bunny).unwrap();
    let theirs: SceneDesc = toml::from_str(&text).unwrap();
    assert_eq!(theirs, SceneFile::read(&bunny).unwrap().desc);
}

/// `lumen scenes export FILE` converts between the formats, keeping the
/// description, and the text is what the library writes.
#[test]
fn the_command_exports_scene_files_with_every_kind() {
    let dir = scratch_dir("objects-export");
    std::fs::write(dir.join("tetra.obj"), TETRA).unwrap();
    std::fs::write(dir.join("all.toml"), ALL_TOML).unwrap();
    let lumen = env!("CARGO_BIN_EXE_lumen");
    let run = |args: &[&std::ffi::OsStr]| {
        let o = Command::new(lumen).args(args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o
    };
    let (toml_in, json_out, toml_out) = (
        dir.join("all.toml"),
        dir.join("all.json"),
        dir.join("again.toml"),
    );
    run(&[
        "scenes".as_ref(),
        "export".as_ref(),
        toml_in.as_os_str(),
        "-o".as_ref(),
        json_out.as_os_str(),
    ]);
    run(&[
        "scenes".as_ref(),
        "export".as_ref(),
        json_out.as_os_str(),
        "-o".as_ref(),
        toml_out.as_os_str(),
    ]);
    let json_text = std::fs::read_to_string(&json_out).unwrap();
    assert_eq!(json_text, export(&expected(), Format::Json).unwrap());
    let toml_text = std::fs::read_to_string(&toml_out).unwrap();
    assert_eq!(toml_text, export(&expected(), Format::Toml).unwrap());
    assert_eq!(SceneFile::read(&toml_out).unwrap().desc, expected());
    // The converted files render (the mesh is found beside them).
    let png = dir.join("all.png");
    run(&[
        "render".as_ref(),
        toml_out.as_os_str(),
        "-o".as_ref(),
        png.as_os_str(),
    ]);
    assert!(png.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A mirroring transform keeps the outside of quads and boxes outside:
/// rays from outside meet the front face, a one-sided light still shines
/// the way it did (a mirror in x leaves a light facing down facing down),
/// and a glass box mirrored onto itself refracts as the box does.
#[test]
fn mirroring_keeps_the_outside_of_quads_and_boxes() {
    use lumen::math::{Interval, Vec3};
    use lumen::ray::Ray;
    let dir = scratch_dir("mirrored-quads");
    let range = Interval::new(1e-4, f32::INFINITY);
    for mirror in [
        "{ scale = [-1, 1, 1] }",
        "{ matrix = [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] }",
    ] {
        let text = format!(
            r#"
[materials.glass]
type = "dielectric"
ior = 1.5
[materials.lamp]
type = "emissive"
radiance = [2, 2, 2]
[[objects]]
type = "box"
min = [-1, -1, -1]
max = [1, 1, 1]
material = "glass"
transform = [{mirror}]
[[objects]]
type = "quad"
corner = [-1, 3, -1]
u = [2, 0, 0]
v = [0, 0, 2]
material = "lamp"
transform = [{{ scale = [-1, 1, 1] }}]
"#
        );
        let scene = scene_file(&dir, "m.toml", &text)
            .compile(&Overrides::default())
            .unwrap();
        for (from, towards) in [
            (Vec3::new(0.2, 0.1, 5.0), -Vec3::Z),
            (Vec3::new(5.0, 0.1, 0.3), -Vec3::X),
            (Vec3::new(0.1, -5.0, 0.2), Vec3::Y),
        ] {
            let hit = scene.hit(&Ray::new(from, towards), range).unwrap();
            assert!(
                hit.front_face,
                "{mirror}: the box is hit from inside along {towards}"
            );
            assert!(
                (hit.outward_normal() + towards).length() < 1e-5,
                "{mirror}: outward normal {} for a ray along {towards}",
                hit.outward_normal()
            );
        }
        // The lamp, u × v = −y, faces down both before and after a mirror
        // that keeps y.
        let up = Ray::new(Vec3::new(0.3, 2.0, 0.3), Vec3::Y);
        let lamp = scene.hit(&up, range).unwrap();
        assert!(lamp.front_face, "the lamp is seen from behind");
        let mut sampler = lumen::rng::Rng::new(1);
        let sample = scene
            .lights
            .sample(Vec3::new(0.0, 2.0, 0.0), &mut sampler)
            .expect("a light sample");
        assert!(sample.radiance.x > 0.0, "the lamp does not shine down");
    }
}
