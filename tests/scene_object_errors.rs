//! Bad quads, boxes, meshes, mesh files and transforms are refused by
//! `lumen render` before rendering: exit status 1, one message naming the
//! scene file with line and column, the field path (and the mesh file with
//! its line, for OBJ), no image and no temporary file left, never a panic.

mod common;

use common::scratch_dir;
use std::path::Path;
use std::process::Command;

const HEAD: &str = r#"[render]
width = 8
height = 8
samples_per_pixel = 1

[materials.m]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 0.5
material = "m"
"#;

const QUAD: &str = "[[objects]]\ntype = \"quad\"\ncorner = [0, 0, -2]\nu = [1, 0, 0]\nv = [0, 1, 0]\nmaterial = \"m\"\n";
const BOX: &str =
    "[[objects]]\ntype = \"box\"\nmin = [0, 0, -3]\nmax = [1, 1, -2]\nmaterial = \"m\"\n";
const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn mesh(file: &str) -> String {
    format!("[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\n")
}

/// One refused scene: its objects (after HEAD, so they are objects[1..]),
/// files to write beside it, the text whose line the message must point at,
/// and what the message must say.
struct Case {
    name: &'static str,
    objects: String,
    files: Vec<(&'static str, Vec<u8>)>,
    at: &'static str,
    says: Vec<&'static str>,
}

fn case(
    name: &'static str,
    objects: impl Into<String>,
    at: &'static str,
    says: &[&'static str],
) -> Case {
    Case {
        name,
        objects: objects.into(),
        files: Vec::new(),
        at,
        says: says.to_vec(),
    }
}

impl Case {
    fn with(mut self, file: &'static str, bytes: impl Into<Vec<u8>>) -> Case {
        self.files.push((file, bytes.into()));
        self
    }
}

/// An ASCII PLY file of three vertices and one face, whose values (nine
/// header lines, then one line per vertex and the face) are `body`.
fn ascii_triangle_ply(body: &str) -> String {
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
     property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_string()
        + body
}

fn glb() -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.glb")).unwrap()
}

fn cases() -> Vec<Case> {
    let transformed = |step: &str| format!("{QUAD}transform = [{{ scale = 2 }}, {step}]\n");
    let mut corrupt = glb();
    // Inside the JSON chunk, which starts after the 20 bytes of headers.
    for b in &mut corrupt[20..60] {
        *b = b'#';
    }
    let nobuf = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"missing.bin","byteLength":36}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#;
    vec![
        case(
            "missing",
            mesh("nope.obj"),
            "file = \"nope.obj\"",
            &["objects[1].file", "nope.obj", "no such file"],
        ),
        case(
            "directory",
            mesh("folder.obj"),
            "file = \"folder.obj\"",
            &["objects[1].file", "folder.obj", "is a directory"],
        ),
        case(
            "bad-number",
            mesh("n.obj"),
            "file = \"n.obj\"",
            &["objects[1].file", "n.obj:3:"],
        )
        .with("n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n"),
        // Files read at once: still reported in the objects' order.
        case(
            "first-of-two-bad-files",
            mesh("a.obj") + &mesh("b.obj"),
            "file = \"a.obj\"",
            &["objects[1].file", "a.obj:3:"],
        )
        .with("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n")
        .with("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        case(
            "second-of-two-files",
            mesh("good.obj") + &mesh("bad.obj"),
            "file = \"bad.obj\"",
            &["objects[2].file", "bad.obj:4:", "out of range"],
        )
        .with("good.obj", TRI)
        .with("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        case(
            "index-range",
            mesh("r.obj"),
            "file = \"r.obj\"",
            &["objects[1].file", "r.obj:4:", "out of range"],
        )
        .with("r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        case(
            "index-zero",
            mesh("z.obj"),
            "file = \"z.obj\"",
            &["objects[1].file", "z.obj:4:", "index 0"],
        )
        .with("z.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        case(
            "short-face",
            mesh("s.obj"),
            "file = \"s.obj\"",
            &["objects[1].file", "s.obj:5:", "2 vertices"],
        )
        .with("s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n"),
        case(
            "truncated-glb",
            mesh("t.glb"),
            "file = \"t.glb\"",
            &["objects[1].file", "t.glb", "truncated"],
        )
        .with("t.glb", glb()[..100].to_vec()),
        case(
            "corrupt-glb",
            mesh("c.glb"),
            "file = \"c.glb\"",
            &["objects[1].file", "c.glb"],
        )
        .with("c.glb", corrupt),
        case(
            "ply-bad-value",
            mesh("v.ply"),
            "file = \"v.ply\"",
            &["objects[1].file", "v.ply:10:", "malformed PLY"],
        )
        .with(
            "v.ply",
            ascii_triangle_ply("0 0 x\n1 0 0\n0 1 0\n3 0 1 2\n"),
        ),
        case(
            "ply-index",
            mesh("i.ply"),
            "file = \"i.ply\"",
            &["objects[1].file", "i.ply", "vertex index 3 out of range"],
        )
        .with(
            "i.ply",
            ascii_triangle_ply("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
        ),
        case(
            "gltf-missing-buffer",
            mesh("b.gltf"),
            "file = \"b.gltf\"",
            &["objects[1].file", "b.gltf", "missing.bin"],
        )
        .with("b.gltf", nobuf),
        case(
            "no-triangles",
            mesh("e.obj"),
            "file = \"e.obj\"",
            &["objects[1].file", "e.obj", "no triangles"],
        )
        .with("e.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        case(
            "only-degenerate",
            mesh("d.obj"),
            "file = \"d.obj\"",
            &["objects[1].file", "d.obj", "no triangles"],
        )
        .with("d.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n"),
        case(
            "unsupported",
            mesh("m.stl"),
            "file = \"m.stl\"",
            &["objects[1].file", "m.stl", ".obj, .gltf, .glb, .ply"],
        )
        .with("m.stl", "solid s\nendsolid s\n"),
        case(
            "nan",
            transformed("{ translate = [0, nan, 0] }"),
            "nan",
            &["objects[1].transform[1].translate[1]", "finite"],
        ),
        case(
            "inf",
            transformed("{ rotate = { axis = [0, 1, 0], degrees = inf } }"),
            "inf",
            &["objects[1].transform[1].rotate.degrees", "finite"],
        ),
        case(
            "too-large",
            transformed("{ translate = [0, 1e39, 0] }"),
            "transform",
            &["objects[1].transform[1]", "f32"],
        ),
        case(
            "singular",
            transformed("{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]] }"),
            "transform",
            &["objects[1].transform[1]", "singular"],
        ),
        case(
            "last-row",
            transformed("{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]] }"),
            "transform",
            &["objects[1].transform[1]", "last row"],
        ),
        case(
            "zero-scale",
            transformed("{ scale = 0 }"),
            "transform",
            &["objects[1].transform[1]", "scale x is 0"],
        ),
        case(
            "zero-scale-axis",
            transformed("{ scale = [1, 0, 1] }"),
            "transform",
            &["objects[1].transform[1]", "scale y is 0"],
        ),
        case(
            "zero-axis",
            transformed("{ rotate = { axis = [0, 0, 0], degrees = 10 } }"),
            "transform",
            &["objects[1].transform[1]", "zero length"],
        ),
        case(
            "two-keys",
            transformed("{ translate = [0, 1, 0], scale = 3 }"),
            "transform",
            &["objects[1].transform[1]", "exactly one of"],
        ),
        case(
            "unknown-key",
            transformed("{ rotat = { axis = [0, 1, 0], degrees = 3 } }"),
            "transform",
            &["objects[1].transform[1].rotat", "did you mean `rotate`?"],
        ),
        case(
            "step-not-table",
            format!("{QUAD}transform = [3]\n"),
            "transform",
            &["objects[1].transform[0]", "transform step"],
        ),
        case(
            "parallel-edges",
            QUAD.replace("v = [0, 1, 0]", "v = [-2, 0, 0]"),
            "[[objects]]\ntype = \"quad\"",
            &["objects[1]", "parallel or zero"],
        ),
        case(
            "zero-edge",
            QUAD.replace("u = [1, 0, 0]", "u = [0, 0, 0]"),
            "[[objects]]\ntype = \"quad\"",
            &["objects[1]", "parallel or zero"],
        ),
        // What a scene may not write, its transforms may not make: every
        // coordinate and radius at most 1e18, the true reason given.
        case(
            "quad-too-large",
            QUAD.replace("corner = [0, 0, -2]", "corner = [2e18, 0, -2]"),
            "[[objects]]\ntype = \"quad\"",
            &["objects[1]", "corner and edges", "at most 1e18"],
        ),
        case(
            "quad-too-small",
            QUAD.replace("u = [1, 0, 0]", "u = [1e-20, 0, 0]")
                .replace("v = [0, 1, 0]", "v = [0, 1e-20, 0]"),
            "[[objects]]\ntype = \"quad\"",
            &["objects[1]", "too small for f32"],
        ),
        case(
            "box-too-large",
            BOX.replace("max = [1, 1, -2]", "max = [1, 2e18, -2]"),
            "[[objects]]\ntype = \"box\"",
            &["objects[1]", "min and max", "at most 1e18"],
        ),
        case(
            "sphere-scaled-too-large",
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\ntransform = [{ scale = 1e25 }]\n",
            "transform = [{ scale = 1e25 }]",
            &["objects[1].transform", "the sphere", "1.00e25", "1e18"],
        ),
        case(
            "sphere-stretched-too-large",
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\ntransform = [{ scale = [1e19, 2e19, 1e19] }]\n",
            "transform = [{ scale = [1e19",
            &["objects[1].transform", "the sphere", "1e18"],
        ),
        case(
            "quad-placed-too-large",
            transformed("{ translate = [5e18, 0, 0] }"),
            "transform = [{ scale = 2 }",
            &["objects[1].transform", "the quad", "1e18"],
        ),
        case(
            "box-placed-too-large",
            BOX.to_string() + "transform = [{ scale = 1e19 }]\n",
            "transform = [{ scale = 1e19 }]",
            &["objects[1].transform", "the box", "1e18"],
        ),
        case(
            "mesh-placed-too-large",
            mesh("tri.obj") + "transform = [{ scale = 1e19 }]\n",
            "[[objects]]\ntype = \"mesh\"",
            &["objects[1]", "vertices of", "tri.obj", "1e18"],
        )
        .with("tri.obj", TRI),
        case(
            "instanced-too-large",
            mesh("tri.obj") + &mesh("tri.obj") + "transform = [{ translate = [0, 3e18, 0] }]\n",
            "[[objects]]\ntype = \"mesh\"\nfile = \"tri.obj\"\ntransform",
            &["objects[2]", "vertices of", "tri.obj", "1e18"],
        )
        .with("tri.obj", TRI),
        case(
            "flat-box",
            BOX.replace("max = [1, 1, -2]", "max = [1, 0, -2]"),
            "max = ",
            &["objects[1].max", "greater than min"],
        ),
        case(
            "inverted-box",
            BOX.replace("max = [1, 1, -2]", "max = [-1, 1, -2]"),
            "max = ",
            &["objects[1].max", "greater than min"],
        ),
        case(
            "quad-material",
            QUAD.replace("\"m\"", "\"n\""),
            "material = \"n\"",
            &["objects[1].material", "no material named \"n\""],
        ),
        case(
            "box-material",
            BOX.replace("\"m\"", "\"n\""),
            "material = \"n\"",
            &["objects[1].material", "no material named \"n\""],
        ),
        case(
            "mesh-material",
            mesh("tri.obj") + "material = \"n\"\n",
            "material = \"n\"",
            &["objects[1].material", "no material named \"n\""],
        )
        .with("tri.obj", TRI),
        case(
            "mesh-smooth-type",
            mesh("tri.obj") + "smooth = 1\n",
            "smooth = 1",
            &["objects[1].smooth", "true or false"],
        )
        .with("tri.obj", TRI),
        case(
            "sphere-field-on-box",
            BOX.to_string() + "radius = 1\n",
            "radius = 1",
            &["objects[1].radius", "belongs to spheres"],
        ),
        // A mesh placed once far beyond f32 once transformed; and the same
        // mesh placed twice (shared by instances) must be refused alike.
        case(
            "mesh-out-of-range",
            mesh("tri.obj") + "transform = [{ scale = 1e38 }, { translate = [3e38, 0, 0] }]\n",
            "transform = [{ scale = 1e38 }",
            &["objects[1].transform", "tri.obj", "beyond the range of f32"],
        )
        .with("tri.obj", TRI),
        case(
            "instanced-out-of-range",
            mesh("tri.obj")
                + &mesh("tri.obj")
                + "transform = [{ scale = 1e38 }, { translate = [3e38, 0, 0] }]\n",
            "transform = [{ scale = 1e38 }",
            &["objects[2].transform", "tri.obj", "beyond the range of f32"],
        )
        .with("tri.obj", TRI),
    ]
}

/// 1-based line of the first occurrence of `at` in `text`.
fn line_of(text: &str, at: &str) -> usize {
    let i = text
        .find(at)
        .unwrap_or_else(|| panic!("{at:?} not in\n{text}"));
    text[..i].matches('\n').count() + 1
}

fn refuse(dir: &Path, scene_name: &str, text: &str, at: &str, says: &[&str]) {
    let scene = dir.join(scene_name);
    std::fs::write(&scene, text).unwrap();
    let out = dir.join(format!("{scene_name}.png"));
    let o = Command::new(env!("CARGO_BIN_EXE_lumen"))
        .arg("render")
        .arg(&scene)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{scene_name}: {err}");
    assert!(!err.contains("panicked"), "{scene_name}: {err}");
    assert!(
        !err.contains("pass 1"),
        "{scene_name}: rendered before refusing: {err}"
    );
    assert_eq!(
        err.matches("error:").count(),
        1,
        "{scene_name}: one message: {err}"
    );
    let first = err.lines().next().unwrap_or("");
    let line = line_of(text, at);
    let located = format!("{}:{line}:", scene.display());
    assert!(
        first.contains(&located),
        "{scene_name}: {located:?} not in {first:?}"
    );
    for s in says {
        assert!(
            first.contains(s) || err.contains(s),
            "{scene_name}: {s:?} not in: {err}"
        );
    }
    assert!(!out.exists(), "{scene_name}: image written");
}

#[test]
fn bad_objects_meshes_and_transforms_are_refused_before_rendering() {
    let dir = scratch_dir("object-errors");
    std::fs::create_dir(dir.join("folder.obj")).unwrap();
    for c in cases() {
        for (file, bytes) in &c.files {
            std::fs::write(dir.join(file), bytes).unwrap();
        }
        let text = format!("{HEAD}\n{}", c.objects);
        refuse(&dir, &format!("{}.toml", c.name), &text, c.at, &c.says);
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") || n.ends_with(".tmp") || n.ends_with("ckpt"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The same mistakes in JSON are located as well: JSON has no NaN, but
/// 1e999 overflows to infinity.
#[test]
fn bad_transforms_in_json_are_located() {
    let dir = scratch_dir("object-errors-json");
    let scene = |objects: &str| {
        format!(
            "{{\"render\": {{\"width\": 8, \"height\": 8, \"samples_per_pixel\": 1}},\n\"materials\": {{\"m\": {{\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}}}},\n\"objects\": [\n{objects}\n]}}\n"
        )
    };
    let quad = r#"{"type": "quad", "corner": [0, 0, -2], "u": [1, 0, 0], "v": [0, 1, 0], "material": "m","#;
    let cases: &[(&str, String, &str, &[&str])] = &[
        ("inf.json", format!("{quad} \"transform\": [{{\"translate\": [0, 1e999, 0]}}]}}"), "1e999", &["objects[0].transform[0].translate[1]", "finite"]),
        ("matrix.json", format!("{quad} \"transform\": [{{\"scale\": 1}}, {{\"matrix\": [[0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}]}}"), "{\"matrix\"", &["objects[0].transform[1]", "singular"]),
        ("rows.json", format!("{quad} \"transform\": [{{\"matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}}]}}"), "[[1, 0", &["objects[0].transform[0].matrix", "4 rows"]),
        ("keys.json", format!("{quad} \"transform\": [{{\"scale\": 1, \"translate\": [0, 0, 0]}}]}}"), "{\"scale\": 1,", &["objects[0].transform[0]", "exactly one of"]),
        ("mesh.json", "{\"type\": \"mesh\", \"file\": \"gone.glb\"}".to_string(), "\"gone.glb\"", &["objects[0].file", "gone.glb", "no such file"]),
    ];
    for (name, objects, at, says) in cases {
        refuse(&dir, name, &scene(objects), at, says);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
