//! The PLY loader: ASCII and binary files of each byte order agree, polygons
//! are fanned, what a renderer does not use is read past, bad files are
//! refused with the file (and the line, in ASCII), and mutated files never
//! make it panic.

use super::tests::{load_mutant, mutate, TempDir};
use super::{load, Model, TriangleMesh};
use std::path::Path;

/// A vertex of the test files: position, normal, texture coordinates, and a
/// colour that the loader ignores.
type TestVertex = ([f32; 3], [f32; 3], [f32; 2], u8);

const VERTICES: [TestVertex; 5] = [
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0], 10),
    ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0], 20),
    ([1.0, 1.0, 0.0], [0.0, 0.6, 0.8], [1.0, 1.0], 30),
    ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0], 40),
    ([0.5, 0.5, -1.5], [-0.6, 0.0, 0.8], [0.5, 0.25], 50),
];

/// A quad, then a triangle.
const FACES: [&[u32]; 2] = [&[0, 1, 2, 3], &[0, 1, 4]];

/// The header of a file in `format` with [`VERTICES`], [`FACES`] and an
/// `edge` element.
fn header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment made by hand\n\
         element vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float s\nproperty float t\nproperty uchar red\n\
         element face 2\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    )
}

fn ascii_ply() -> Vec<u8> {
    let mut text = header("ascii");
    for (p, n, uv, red) in VERTICES {
        let numbers: Vec<String> = p.iter().chain(&n).chain(&uv).map(f32::to_string).collect();
        text += &format!("{} {red}\n", numbers.join(" "));
    }
    for face in FACES {
        let indices: Vec<String> = face.iter().map(u32::to_string).collect();
        text += &format!("{} {}\n", face.len(), indices.join(" "));
    }
    text += "0 4\n";
    text.into_bytes()
}

fn binary_ply(little: bool) -> Vec<u8> {
    let format = if little {
        "binary_little_endian"
    } else {
        "binary_big_endian"
    };
    let mut bytes = header(format).into_bytes();
    let f32b = |x: f32| {
        if little {
            x.to_le_bytes()
        } else {
            x.to_be_bytes()
        }
    };
    let i32b = |x: i32| {
        if little {
            x.to_le_bytes()
        } else {
            x.to_be_bytes()
        }
    };
    for (p, n, uv, red) in VERTICES {
        for x in p.iter().chain(&n).chain(&uv) {
            bytes.extend(f32b(*x));
        }
        bytes.push(red);
    }
    for face in FACES {
        bytes.push(face.len() as u8);
        for &i in face {
            bytes.extend(i32b(i as i32));
        }
    }
    bytes.extend(i32b(0));
    bytes.extend(i32b(4));
    bytes
}

fn load_bytes(name: &str, bytes: &[u8]) -> Result<Model, super::MeshError> {
    let dir = TempDir::new();
    load(&dir.write(name, bytes))
}

#[test]
fn ascii_ply_gives_positions_normals_uvs_and_fanned_faces() {
    let m = load_bytes("t.ply", &ascii_ply()).unwrap();
    assert_eq!(m.meshes.len(), 1);
    assert_eq!(m.instances.len(), 1);
    assert!(m.materials.is_empty(), "PLY has no materials");
    let mesh = &m.meshes[0];
    assert_eq!(mesh.positions, VERTICES.map(|v| v.0).to_vec());
    assert_eq!(mesh.normals, Some(VERTICES.map(|v| v.1).to_vec()));
    assert_eq!(mesh.uvs, Some(VERTICES.map(|v| v.2).to_vec()));
    // The quad fanned from its first vertex, then the triangle.
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    assert_eq!(mesh.material, vec![super::NO_MATERIAL; 3]);
}

#[test]
fn binary_ply_of_either_byte_order_equals_the_ascii_file() {
    let ascii = load_bytes("a.ply", &ascii_ply()).unwrap();
    for little in [true, false] {
        let binary = load_bytes("b.PLY", &binary_ply(little)).unwrap();
        assert_eq!(binary.meshes, ascii.meshes, "little endian: {little}");
        assert_eq!(binary.instances, ascii.instances);
    }
}

#[test]
fn attributes_missing_on_any_vertex_are_left_out() {
    // Positions only, in doubles, and a face list of unsigned shorts.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\n\
                property double y\nproperty double z\nelement face 1\n\
                property list uchar ushort vertex_index\nend_header\n\
                0 0 0\n2 0 0\n0 2 0\n3 0 1 2\n";
    let m = load_bytes("d.ply", text.as_bytes()).unwrap();
    let mesh: &TriangleMesh = &m.meshes[0];
    assert_eq!(mesh.normals, None);
    assert_eq!(mesh.uvs, None);
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(mesh.positions[1], [2.0, 0.0, 0.0]);
}

#[test]
fn degenerate_faces_are_skipped_and_counted() {
    let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n\
                property float y\nproperty float z\nelement face 3\n\
                property list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 0 1\n3 0 1 3\n";
    let m = load_bytes("g.ply", text.as_bytes()).unwrap();
    assert_eq!(m.triangle_count(), 1);
    assert_eq!(m.skipped_degenerate, 2);
}

#[test]
fn bad_ply_files_are_refused_naming_the_file_and_what_is_wrong() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                property float y\nproperty float z\nelement face 1\n\
                property list uchar int vertex_indices\nend_header\n";
    let cases: Vec<(String, &str, Option<usize>)> = vec![
        (
            format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
            "vertex index 7 out of range (the file has 3 vertices)",
            None,
        ),
        (
            format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
            "negative index",
            None,
        ),
        (
            format!("{head}0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
            "face 0 has 2 vertices",
            None,
        ),
        (format!("{head}0 0 0\n1 zero 0\n"), "malformed PLY", Some(11)),
        (format!("{head}0 0 0\n1 0 0\n"), "", None),
        (
            "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
                .to_string(),
            "no `vertex` element",
            None,
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"
                .to_string(),
            "vertex 0 lacks one of x, y and z",
            None,
        ),
        (
            format!("{head}0 0 0\n1 0 0\n0 1 0\n").replace("element face 1", "element face 0"),
            "no triangles",
            None,
        ),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_hedaer\n".to_string(), "", None),
        ("solid not a ply\n".to_string(), "", None),
    ];
    for (text, expected, line) in cases {
        let dir = TempDir::new();
        let path = dir.write("bad.ply", &text);
        let e = load(&path).expect_err(&text);
        let shown = e.to_string();
        assert!(shown.starts_with(&path.display().to_string()), "{shown}");
        assert!(shown.contains(expected), "{shown} lacks {expected:?}");
        if line.is_some() {
            assert_eq!(e.line(), line, "{shown}");
        }
    }
    // A position that is not finite (binary: ASCII has no spelling for it).
    let mut nan = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for x in [0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0] {
        nan.extend(f32::to_le_bytes(x));
    }
    nan.push(3);
    [0i32, 1, 2]
        .iter()
        .for_each(|i| nan.extend(i.to_le_bytes()));
    let e = load_bytes("nan.ply", &nan).unwrap_err();
    assert!(e.to_string().contains("vertex 1: position"), "{e}");
    // A binary file cut short.
    let mut cut = binary_ply(true);
    cut.truncate(cut.len() - 12);
    let e = load_bytes("cut.ply", &cut).unwrap_err();
    assert!(e.to_string().contains("cut.ply"), "{e}");
    assert!(e.to_string().contains("end of file"), "{e}");
    assert_eq!(e.line(), None, "a binary payload has no lines: {e}");
}

/// The bundled bunny written as PLY (binary little endian).
fn bunny_ply(ascii: bool) -> (Vec<u8>, Model) {
    let obj = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj")).unwrap();
    let mesh = &obj.meshes[0];
    let format = if ascii {
        "ascii"
    } else {
        "binary_little_endian"
    };
    let mut bytes = format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    for p in &mesh.positions {
        if ascii {
            bytes.extend(format!("{} {} {}\n", p[0], p[1], p[2]).bytes());
        } else {
            p.iter().for_each(|c| bytes.extend(c.to_le_bytes()));
        }
    }
    for t in &mesh.triangles {
        if ascii {
            bytes.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
        } else {
            bytes.push(3);
            t.iter().for_each(|i| bytes.extend(i.to_le_bytes()));
        }
    }
    (bytes, obj)
}

#[test]
fn the_bunny_as_ply_is_the_bunny_as_obj() {
    for ascii in [true, false] {
        let (bytes, obj) = bunny_ply(ascii);
        let ply = load_bytes("bunny.ply", &bytes).unwrap();
        assert_eq!(ply.meshes[0].positions, obj.meshes[0].positions);
        assert_eq!(ply.meshes[0].triangles, obj.meshes[0].triangles);
        assert_eq!(ply.triangle_count(), 3674);
    }
}

#[test]
fn mutated_ply_bunnies_never_panic() {
    let dir = TempDir::new();
    let mut rng = crate::rng::Rng::new(0x706c_7921);
    for ascii in [true, false] {
        let (original, _) = bunny_ply(ascii);
        let header_end = original
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let (mut ok, mut refused) = (0, 0);
        for round in 0..600 {
            let mut bytes = original.clone();
            for _ in 0..1 + rng.next_u32() % 4 {
                // Half the changes in the header, where they matter most.
                mutate(&mut rng, &mut bytes, header_end);
            }
            let name = format!("mutant-{round}.ply");
            if load_mutant(&dir, &name, &bytes) {
                ok += 1;
            } else {
                refused += 1;
            }
            let _ = std::fs::remove_file(dir.0.join(&name));
        }
        assert!(
            ok > 0 && refused > 0,
            "ascii {ascii}: {ok} loaded, {refused} refused"
        );
    }
}
