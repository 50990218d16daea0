//! A triangle mesh written out in the scene file (`type = "triangles"`):
//! it renders to the same bits as the same mesh read from an OBJ file,
//! survives export, and its mistakes are refused by name.

mod common;

use common::{icosphere_obj, scratch_dir};
use lumen::scene::file::{export, Format, SceneFile};
use lumen::scene::Overrides;

/// Positions, normals and triangles.
type Arrays = (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<[u32; 3]>);

/// The positions, normals and triangles of an OBJ written by
/// `icosphere_obj` (0-based).
fn arrays(obj: &str) -> Arrays {
    let (mut v, mut n, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for line in obj.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let num = |i: usize| w[i].parse::<f64>().unwrap();
        match w.first() {
            Some(&"v") => v.push([num(1), num(2), num(3)]),
            Some(&"vn") => n.push([num(1), num(2), num(3)]),
            Some(&"f") => f.push(
                [1, 2, 3].map(|i| w[i].split('/').next().unwrap().parse::<u32>().unwrap() - 1),
            ),
            _ => {}
        }
    }
    (v, n, f)
}

fn list<T: std::fmt::Debug>(items: &[T]) -> String {
    format!("{items:?}")
}

const HEAD: &str = r#"
[render]
width = 48
height = 36
samples_per_pixel = 4
max_depth = 4
[camera]
lookfrom = [0, 1, 4]
lookat = [0, 0, 0]
vfov = 40
[background]
type = "gradient"
bottom = [1, 1, 1]
top = [0.5, 0.7, 1.0]
[materials.red]
type = "diffuse"
albedo = [0.7, 0.2, 0.1]
"#;

fn render(file: &SceneFile) -> Vec<lumen::math::Color> {
    let scene = file
        .compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    lumen::render::render(&scene, &|_| {}).0.linear()
}

#[test]
fn triangles_in_the_scene_render_as_the_same_mesh_from_a_file() {
    let dir = scratch_dir("inline_triangles_same");
    for normals in [None, Some(1.0)] {
        let obj = icosphere_obj(2, 1.0, normals);
        std::fs::write(dir.join("ball.obj"), &obj).unwrap();
        let (v, n, f) = arrays(&obj);
        let place = "transform = [{ rotate = { axis = [1, 1, 0], degrees = 30 } }, { translate = [0.2, 0, 0] }]";
        let from_file = common::scene_file(
            &dir,
            "file.toml",
            &format!(
                "{HEAD}[[objects]]\ntype = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"red\"\nsmooth = {}\n{place}\n",
                normals.is_some()
            ),
        );
        let normals_line = if normals.is_some() {
            format!("normals = {}\n", list(&n))
        } else {
            String::new()
        };
        let inline = common::scene_file(
            &dir,
            "inline.toml",
            &format!(
                "{HEAD}[[objects]]\ntype = \"triangles\"\npositions = {}\nindices = {}\n{normals_line}material = \"red\"\n{place}\n",
                list(&v),
                list(&f)
            ),
        );
        let (a, b) = (render(&from_file), render(&inline));
        assert!(a.iter().any(|c| c.x > 0.5 * c.z), "the ball is seen");
        assert!(
            a == b,
            "normals {normals:?}: the inline mesh renders differently"
        );

        // Exported and read again, in both formats, it is the same scene.
        for format in [Format::Toml, Format::Json] {
            let text = export(&inline.desc, format).unwrap();
            let mut again =
                SceneFile::parse("again", text, format).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(again.desc, inline.desc);
            again.dir = inline.dir.clone();
            assert!(render(&again) == b);
        }
    }
}

#[test]
fn mistakes_in_written_out_triangles_are_refused_by_name() {
    let dir = scratch_dir("inline_triangles_bad");
    let refused = |object: &str| -> String {
        let path = dir.join("bad.toml");
        std::fs::write(
            &path,
            format!("{HEAD}[[objects]]\ntype = \"triangles\"\nmaterial = \"red\"\n{object}\n"),
        )
        .unwrap();
        match SceneFile::read(&path) {
            Err(e) => e.to_string(),
            Ok(f) => match f.compile(&Overrides::default()) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted: {object}"),
            },
        }
    };
    let tri = "positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]";
    for (object, expected) in [
        (
            format!("{tri}\nindices = [[0, 1, 3]]"),
            "`indices[0]` names vertex 3, but there are 3 positions",
        ),
        (format!("{tri}\nindices = [[0, 1, -1]]"), "indices[0][2]"),
        (
            format!("{tri}\nindices = [[0, 1]]"),
            "expected an array of 3 vertex indices",
        ),
        (
            format!("{tri}\nindices = [[0, 1, 2]]\nnormals = [[0, 0, 1]]"),
            "`normals` has 1 entries for 3 positions",
        ),
        (
            format!("{tri}\nindices = [[0, 1, 2]]\nuvs = [[0, 0], [1, 0]]"),
            "`uvs` has 2 entries for 3 positions",
        ),
        (
            format!("{tri}\nindices = [[0, 1, 2]]\nuvs = [[0, 0], [1, 0], [1]]"),
            "uvs[2]",
        ),
        (
            "positions = [[0, 0, 0], [1, 0, nan], [0, 1, 0]]\nindices = [[0, 1, 2]]".to_string(),
            "expected a finite number",
        ),
        (tri.to_string(), "indices"),
        (
            format!("{tri}\nindices = [[0, 1, 2]]\nfile = \"x.obj\""),
            "file",
        ),
    ] {
        let message = refused(&object);
        assert!(
            message.contains(expected),
            "{object}:\n{message}\nlacks: {expected}"
        );
    }
}
