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
        (
            format!("{head}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
            "malformed PLY: vertex 1: `zero` is not a float (property `y`)",
            Some(11),
        ),
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
            "element `vertex` has no `z` property",
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

/// A PLY header of `format` with `elements` (each a line `element …` and
/// its property lines), then `payload`.
fn ply_file(format: &str, elements: &str, payload: &[u8]) -> Vec<u8> {
    let mut bytes = format!("ply\nformat {format} 1.0\n{elements}end_header\n").into_bytes();
    bytes.extend_from_slice(payload);
    bytes
}

/// One triangle's worth of binary little-endian payload: three float
/// vertices and a face.
fn one_triangle_le() -> Vec<u8> {
    let mut payload = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        payload.extend(x.to_le_bytes());
    }
    payload.push(3);
    [0i32, 1, 2]
        .iter()
        .for_each(|i| payload.extend(i.to_le_bytes()));
    payload
}

const XYZ: &str = "property float x\nproperty float y\nproperty float z\n";
const INDICES: &str = "property list uchar int vertex_indices\n";

/// Loads `bytes` as `name`, expecting a refusal whose message contains
/// every one of `words`; returns the error.
fn refused(name: &str, bytes: &[u8], words: &[&str]) -> super::MeshError {
    let t = std::time::Instant::now();
    let e = load_bytes(name, bytes).expect_err(name);
    let shown = e.to_string();
    assert!(shown.contains(name), "{shown}");
    for w in words {
        assert!(shown.contains(w), "{shown:?} lacks {w:?}");
    }
    assert!(
        t.elapsed().as_secs_f64() < 1.0,
        "{name} took {:?} to refuse",
        t.elapsed()
    );
    e
}

#[test]
fn elements_that_cannot_fit_in_the_file_are_refused_before_reading() {
    for format in ["binary_little_endian", "binary_big_endian", "ascii"] {
        // No properties: nothing to read, however many records.
        let e = refused(
            "empty-element.ply",
            &ply_file(
                format,
                &format!(
                    "element vertex 3\n{XYZ}element junk 4000000000\nelement face 1\n{INDICES}"
                ),
                &one_triangle_le(),
            ),
            &["`junk`", "4000000000", "no properties"],
        );
        assert_eq!(e.line(), Some(7), "{e}");
        // A vertex element of a thousand times more records than bytes.
        let e = refused(
            "huge-count.ply",
            &ply_file(
                format,
                &format!("element vertex 100000000\n{XYZ}element face 1\n{INDICES}"),
                &one_triangle_le(),
            ),
            &["`vertex`", "100000000", "bytes"],
        );
        assert_eq!(e.line(), Some(3), "{e}");
        // Faces that need more bytes than are left after the vertices.
        refused(
            "huge-faces.ply",
            &ply_file(
                format,
                &format!("element vertex 3\n{XYZ}element face 50000000\n{INDICES}"),
                &one_triangle_le(),
            ),
            &["`face`", "50000000", "bytes"],
        );
        // 2^40 records and no properties (it looped, or allocated 9.6 GB
        // and aborted): refused at once.
        refused(
            "no-properties.ply",
            &ply_file(format, "element vertex 1099511627776\n", &one_triangle_le()),
            &["`vertex`", "1099511627776"],
        );
    }
}

#[test]
fn counts_above_the_documented_maximum_are_refused() {
    let e = refused(
        "many.ply",
        &ply_file(
            "binary_little_endian",
            &format!("element vertex 4294967296\n{XYZ}element face 1\n{INDICES}"),
            &one_triangle_le(),
        ),
        &["`vertex`", "4294967296", "at most 4294967295"],
    );
    assert_eq!(e.line(), Some(3), "{e}");
    refused(
        "overflow.ply",
        &ply_file(
            "ascii",
            &format!("element vertex 99999999999999999999999\n{XYZ}"),
            b"",
        ),
        &["99999999999999999999999"],
    );
}

#[test]
fn the_vertex_and_face_elements_are_checked_against_the_header_first() {
    // x, y and z: named by the header, whatever follows (here, nothing).
    for (properties, missing) in [
        ("property float x\nproperty float y\n", "`z`"),
        ("property float y\nproperty float z\n", "`x`"),
        ("property float x\nproperty float z\n", "`y`"),
    ] {
        let e = refused(
            "no-z.ply",
            &ply_file(
                "binary_little_endian",
                &format!("element vertex 3\n{properties}element face 1\n{INDICES}"),
                b"",
            ),
            &["element `vertex`", missing],
        );
        assert_eq!(e.line(), Some(3), "{e}");
    }
    // x as a list.
    refused(
        "list-x.ply",
        &ply_file(
            "ascii",
            "element vertex 1\nproperty list uchar float x\nproperty float y\nproperty float z\n",
            b"1 0 0 0\n",
        ),
        &["`x`", "list"],
    );
    // Faces without their list, or with a number instead, or floats.
    for (face, words) in [
        (
            "property list uchar int vertex_indexes\n",
            &["element `face`", "vertex_indices"][..],
        ),
        (
            "property int vertex_indices\n",
            &["`vertex_indices`", "list"],
        ),
        (
            "property list uchar float vertex_indices\n",
            &["`vertex_indices`", "float"],
        ),
        (
            "property list float int vertex_indices\n",
            &["`vertex_indices`", "float"],
        ),
    ] {
        refused(
            "faces.ply",
            &ply_file(
                "binary_little_endian",
                &format!("element vertex 3\n{XYZ}element face 1\n{face}"),
                &one_triangle_le(),
            ),
            words,
        );
    }
}

#[test]
fn ascii_records_with_values_left_over_are_refused_with_their_line() {
    let head = format!("element vertex 3\n{XYZ}element face 1\n{INDICES}");
    for (payload, line) in [
        ("0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n", 11),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1 2 5\n", 13),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\t \r\n", 0),
    ] {
        let bytes = ply_file("ascii", &head, payload.as_bytes());
        if line == 0 {
            // Trailing blanks and a CR are not values.
            assert_eq!(load_bytes("ok.ply", &bytes).unwrap().triangle_count(), 1);
            continue;
        }
        let e = refused("extra.ply", &bytes, &["more values"]);
        assert_eq!(e.line(), Some(line), "{e}");
    }
}

/// The reader this one replaced, on `ply-rs-bw`: what every valid file
/// must still load to, bit for bit.
mod reference {
    use super::super::{fan, Model, TriangleMesh, NO_MATERIAL};
    use ply_rs_bw::parser::{Parser, Reader};
    use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

    #[derive(Default)]
    struct Vertex {
        position: [f32; 3],
        normal: [f32; 3],
        uv: [f32; 2],
        found: u8,
    }

    impl PropertyAccess for Vertex {
        fn new() -> Self {
            Self::default()
        }

        fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
            let (slot, bit) = match name {
                "x" => (&mut self.position[0], 0),
                "y" => (&mut self.position[1], 1),
                "z" => (&mut self.position[2], 2),
                "nx" => (&mut self.normal[0], 3),
                "ny" => (&mut self.normal[1], 4),
                "nz" => (&mut self.normal[2], 5),
                "u" | "s" | "texture_u" | "texture_s" => (&mut self.uv[0], 6),
                "v" | "t" | "texture_v" | "texture_t" => (&mut self.uv[1], 7),
                _ => return PropertyAccessResult::Ignored,
            };
            match property.to_f32_lossy() {
                Some(value) => {
                    *slot = value;
                    self.found |= 1 << bit;
                    PropertyAccessResult::Set
                }
                None => PropertyAccessResult::UnsupportedType,
            }
        }
    }

    #[derive(Default)]
    struct Face {
        indices: Option<Vec<u32>>,
    }

    impl PropertyAccess for Face {
        fn new() -> Self {
            Self::default()
        }

        fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
            if name != "vertex_indices" && name != "vertex_index" {
                return PropertyAccessResult::Ignored;
            }
            self.indices = property.to_u32_list();
            PropertyAccessResult::Set
        }
    }

    struct Skipped;

    impl PropertyAccess for Skipped {
        fn new() -> Self {
            Skipped
        }
    }

    /// The mesh of a valid file, and its zero-area triangles skipped.
    pub(super) fn load(bytes: &[u8]) -> (TriangleMesh, usize) {
        let mut reader = Reader::new(bytes);
        let header = Parser::<Skipped>::new().read_header(&mut reader).unwrap();
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut faces: Vec<Face> = Vec::new();
        for element in header.elements.values() {
            match element.name.as_str() {
                "vertex" => {
                    vertices = Parser::<Vertex>::new()
                        .read_payload_for_element(&mut reader, element, &header)
                        .unwrap()
                }
                "face" => {
                    faces = Parser::<Face>::new()
                        .read_payload_for_element(&mut reader, element, &header)
                        .unwrap()
                }
                _ => {
                    Parser::<Skipped>::new()
                        .read_payload_for_element(&mut reader, element, &header)
                        .unwrap();
                }
            }
        }
        let mut mesh = TriangleMesh {
            positions: vertices.iter().map(|v| v.position).collect(),
            ..TriangleMesh::default()
        };
        let every = |bits: u8| vertices.iter().all(|v| v.found & bits == bits);
        if every(0b111 << 3) {
            mesh.normals = Some(vertices.iter().map(|v| v.normal).collect());
        }
        if every(0b11 << 6) {
            mesh.uvs = Some(vertices.iter().map(|v| v.uv).collect());
        }
        let mut skipped = 0;
        for face in &faces {
            for triangle in fan(face.indices.as_ref().unwrap()) {
                if !mesh.push_triangle(triangle, NO_MATERIAL) {
                    skipped += 1;
                }
            }
        }
        (mesh, skipped)
    }

    /// The mesh and skipped count of a model loaded by the new reader.
    pub(super) fn of(model: &Model) -> (TriangleMesh, usize) {
        (model.meshes[0].clone(), model.skipped_degenerate)
    }
}

/// A random valid PLY file: every scalar type for positions, normals and
/// texture coordinates of either spelling, other properties and lists to
/// read past, polygons of 3 to 6 vertices (some with repeated indices),
/// other elements before, between and after, faces before vertices at
/// times, in ASCII or either byte order.
fn random_ply(rng: &mut crate::rng::Rng) -> Vec<u8> {
    let mut pick = |n: u32| rng.next_u32() % n;
    const SCALARS: [&str; 8] = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
    ];
    const INTEGERS: [&str; 6] = ["char", "uchar", "short", "ushort", "int", "uint"];
    let encoding = ["ascii", "binary_little_endian", "binary_big_endian"][pick(3) as usize];
    // (name, type, list length type) of the vertex properties, in order.
    let mut vertex: Vec<(String, &str, Option<&str>)> = ["x", "y", "z"]
        .iter()
        .map(|n| (n.to_string(), SCALARS[pick(8) as usize], None))
        .collect();
    if pick(2) == 0 {
        for n in ["nx", "ny", "nz"] {
            vertex.push((n.into(), ["float", "double"][pick(2) as usize], None));
        }
    }
    if pick(2) == 0 {
        let names = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]][pick(3) as usize];
        for n in names {
            vertex.push((n.into(), SCALARS[pick(8) as usize], None));
        }
    }
    if pick(2) == 0 {
        vertex.push(("red".into(), "uchar", None));
    }
    if pick(3) == 0 {
        vertex.push(("extra".into(), "float", Some(INTEGERS[pick(6) as usize])));
    }
    // Shuffle.
    for i in (1..vertex.len()).rev() {
        vertex.swap(i, pick(i as u32 + 1) as usize);
    }
    let vertices = 3 + pick(40) as usize;
    let faces = 1 + pick(40) as usize;
    let length = ["uchar", "ushort", "int", "uint", "char", "short"][pick(6) as usize];
    let item = ["int", "uint", "ushort", "short", "uchar", "char"][pick(6) as usize];
    let mut face: Vec<(String, &str, Option<&str>)> = vec![(
        ["vertex_indices", "vertex_index"][pick(2) as usize].into(),
        item,
        Some(length),
    )];
    if pick(2) == 0 {
        face.insert(
            pick(2) as usize,
            ("flags".into(), INTEGERS[pick(6) as usize], None),
        );
    }
    let edge: Vec<(String, &str, Option<&str>)> = vec![
        ("vertex1".into(), "int", None),
        ("crease".into(), "uchar", Some("uchar")),
    ];
    let mut elements = vec![("vertex", vertices, vertex), ("face", faces, face)];
    if pick(4) == 0 {
        elements.swap(0, 1);
    }
    elements.insert(pick(3) as usize, ("edge", pick(4) as usize, edge));

    let mut header = format!("ply\nformat {encoding} 1.0\ncomment random\n");
    for (name, count, properties) in &elements {
        header += &format!("element {name} {count}\n");
        for (p, ty, list) in properties {
            match list {
                Some(l) => header += &format!("property list {l} {ty} {p}\n"),
                None => header += &format!("property {ty} {p}\n"),
            }
        }
    }
    header += "end_header\n";
    let mut bytes = header.into_bytes();

    // A value of type `ty`, written in the file's encoding.
    let write = |bytes: &mut Vec<u8>, ty: &str, v: f64, last: bool| {
        if encoding == "ascii" {
            let text = match ty {
                "float" => format!("{}", v as f32),
                "double" => format!("{v}"),
                _ => format!("{}", v as i64),
            };
            bytes.extend(text.bytes());
            bytes.push(if last { b'\n' } else { b' ' });
            return;
        }
        let big = encoding == "binary_big_endian";
        macro_rules! put {
            ($x:expr) => {{
                let x = $x;
                if big {
                    bytes.extend(x.to_be_bytes())
                } else {
                    bytes.extend(x.to_le_bytes())
                }
            }};
        }
        match ty {
            "char" => put!(v as i8),
            "uchar" => put!(v as u8),
            "short" => put!(v as i16),
            "ushort" => put!(v as u16),
            "int" => put!(v as i32),
            "uint" => put!(v as u32),
            "float" => put!(v as f32),
            _ => put!(v),
        }
    };
    for (name, count, properties) in &elements {
        for _ in 0..*count {
            for (k, (_, ty, list)) in properties.iter().enumerate() {
                let last = k + 1 == properties.len();
                let value = |rng: &mut crate::rng::Rng| match *ty {
                    "float" | "double" => {
                        (rng.next_f64() - 0.5) * 10f64.powi(rng.next_u32() as i32 % 7 - 3)
                    }
                    "char" | "short" | "int" => (rng.next_u32() % 100) as f64 - 50.0,
                    _ => (rng.next_u32() % 100) as f64,
                };
                match (*name, list) {
                    ("face", Some(l)) => {
                        let n = 3 + rng.next_u32() % 4;
                        write(&mut bytes, l, n as f64, false);
                        for i in 0..n {
                            // Fewer distinct indices than vertices now
                            // and then: repeated ones.
                            let spread = if rng.next_u32().is_multiple_of(8) {
                                3
                            } else {
                                vertices
                            };
                            let index = rng.next_u32() as usize % spread.min(100);
                            write(&mut bytes, ty, index as f64, last && i + 1 == n);
                        }
                    }
                    (_, Some(l)) => {
                        let n = rng.next_u32() % 3;
                        write(&mut bytes, l, n as f64, last && n == 0);
                        for i in 0..n {
                            let v = value(rng);
                            write(&mut bytes, ty, v, last && i + 1 == n);
                        }
                    }
                    (_, None) => {
                        let v = value(rng);
                        write(&mut bytes, ty, v, last);
                    }
                }
            }
        }
    }
    bytes
}

#[test]
fn every_file_loads_to_the_mesh_of_the_reader_before() {
    let dir = TempDir::new();
    let mut rng = crate::rng::Rng::new(0x706c_7932);
    let (mut loaded, mut refused) = (0, 0);
    for round in 0..400 {
        let bytes = random_ply(&mut rng);
        let name = format!("random-{round}.ply");
        let path = dir.write(&name, &bytes);
        match load(&path) {
            Ok(model) => {
                assert_eq!(reference::of(&model), reference::load(&bytes), "{name}");
                loaded += 1;
            }
            Err(e) => {
                // Only a file of no triangles with area.
                assert!(e.to_string().contains("no triangles"), "{name}: {e}");
                assert_eq!(reference::load(&bytes).0.triangles.len(), 0, "{name}");
                refused += 1;
            }
        }
        let _ = std::fs::remove_file(&path);
    }
    assert!(loaded > 350, "{loaded} loaded, {refused} refused");
    // A double is rounded to f32 from its f64 value, not from its text:
    // 1 + 2⁻²⁴ + 2⁻⁶⁰ is 1 + 2⁻²⁴ in f64, a tie, 1 in f32; read as an f32
    // at once, it would round up.
    let near_tie = "1.00000005960464477625798673798840354720596224069595336914062";
    let text = format!(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         {near_tie} 0 0\n0 {near_tie} 0\n0 0 1\n3 0 1 2\n"
    );
    let model = load(&dir.write("tie.ply", &text)).unwrap();
    assert_eq!(model.meshes[0].positions[0], [1.0, 0.0, 0.0]);
    assert_eq!(reference::of(&model), reference::load(text.as_bytes()));
}

#[test]
fn long_headers_and_long_lists_are_read_in_linear_time() {
    // 200,000 properties of an element read past.
    let mut elements = String::from("element junk 1\n");
    for i in 0..200_000 {
        elements += &format!("property uchar p{i}\n");
    }
    elements += &format!("element vertex 3\n{XYZ}element face 1\n{INDICES}");
    let mut payload = vec![0u8; 200_000];
    payload.extend(one_triangle_le());
    let t = std::time::Instant::now();
    let model = load_bytes(
        "long.ply",
        &ply_file("binary_little_endian", &elements, &payload),
    );
    assert_eq!(model.unwrap().triangle_count(), 1);
    assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
    // A list that claims more values than its line or the file holds.
    let head = format!("element vertex 3\n{XYZ}element face 1\n{INDICES}");
    let e = refused(
        "long-list.ply",
        &ply_file("ascii", &head, b"0 0 0\n1 0 0\n0 1 0\n200 0 1 2\n"),
        &["face 0 has too few values"],
    );
    assert_eq!(e.line(), Some(13), "{e}");
    let mut cut = one_triangle_le();
    cut[36] = 255;
    refused(
        "long-list.ply",
        &ply_file("binary_little_endian", &head, &cut),
        &["end of file at face 0 of 1"],
    );
}
