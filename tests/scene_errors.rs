//! Every class of mistake in a scene file is refused before rendering with a
//! message that names the file, the line and column, the field path, what was
//! expected and, where it helps, a hint. One test per class.

use lumen::scene::file::{Format, SceneFile};
use lumen::scene::Overrides;
use std::path::Path;
use std::process::Command;

/// A small valid scene; tests break one line of it. Line numbers matter.
const BASE: &str = r#"[render]
width = 32
samples_per_pixel = 2

[camera]
vfov = 90
lookfrom = [0, 0, 0]
lookat = [0, 0, -1]
vup = [0, 1, 0]

[materials.red]
type = "diffuse"
albedo = [0.8, 0.2, 0.2]

[materials.mirror]
type = "metal"
albedo = [0.9, 0.9, 0.9]
fuzz = 0.1

[materials.glass]
type = "dielectric"
ior = 1.5

[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "red"

[[objects]]
type = "sphere"
center = [0, -100.5, -1]
radius = 100
material = "glass"
"#;

/// The message for `text` (TOML), which must be refused.
fn refused(text: &str) -> String {
    refused_as(text, Format::Toml, "scene.toml")
}

fn refused_as(text: &str, format: Format, name: &str) -> String {
    match SceneFile::parse(name, text.to_string(), format) {
        Err(e) => e.to_string(),
        Ok(file) => match file.compile(&Overrides::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{text}"),
        },
    }
}

/// BASE with `from` (which must occur) replaced by `to`.
fn base_with(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "{from:?} not in the base scene");
    BASE.replacen(from, to, 1)
}

fn assert_mentions(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "message lacks {part:?}:\n{message}");
    }
}

#[test]
fn the_base_scene_is_valid() {
    let file = SceneFile::parse("scene.toml", BASE.into(), Format::Toml).unwrap();
    file.compile(&Overrides::default()).unwrap();
}

#[test]
fn syntax_error_toml() {
    let m = refused(&base_with("radius = 0.5", "radius = = 0.5"));
    assert_mentions(
        &m,
        &["scene.toml:27:10:", "syntax error", "radius = = 0.5", "^"],
    );
}

#[test]
fn syntax_error_json() {
    let m = refused_as(
        "{\n  \"render\": {\"width\": 32,}\n}",
        Format::Json,
        "s.json",
    );
    assert_mentions(&m, &["s.json:2:", "syntax error"]);
}

#[test]
fn unknown_field_suggests_the_closest_name() {
    let m = refused(&base_with("radius = 0.5", "radus = 0.5"));
    assert_mentions(
        &m,
        &[
            "scene.toml:27:1:",
            "objects[0].radus",
            "unknown field `radus`",
            "did you mean `radius`?",
        ],
    );
    let m = refused(&base_with("[camera]", "[camra]"));
    assert_mentions(&m, &["scene.toml:5:2:", "camra", "did you mean `camera`?"]);
    let m = refused(&base_with("samples_per_pixel = 2", "samples = 2"));
    assert_mentions(&m, &["render.samples", "did you mean `samples_per_pixel`?"]);
}

#[test]
fn unknown_field_of_another_kind_says_where_it_belongs() {
    let m = refused(&base_with("ior = 1.5", "ior = 1.5\nfuzz = 0.2"));
    assert_mentions(
        &m,
        &[
            "scene.toml:23:1:",
            "materials.glass.fuzz",
            "unknown field `fuzz` in a dielectric material",
            "`fuzz` belongs to metal materials",
        ],
    );
}

#[test]
fn repeated_json_field() {
    let m = refused_as(
        "{\"render\": {\"width\": 32,\n \"width\": 64}}",
        Format::Json,
        "s.json",
    );
    assert_mentions(&m, &["s.json:2:2:", "render.width", "given twice"]);
}

#[test]
fn unknown_kind_suggests_the_closest() {
    let m = refused(&base_with("type = \"metal\"", "type = \"metl\""));
    assert_mentions(
        &m,
        &[
            "scene.toml:16:8:",
            "materials.mirror.type",
            "unknown value \"metl\"",
            // More kinds than a message lists: the closest first.
            "expected one of \"metal\", ",
            "did you mean \"metal\"?",
        ],
    );
}

#[test]
fn wrong_type() {
    let m = refused(&base_with("radius = 0.5", "radius = \"big\""));
    assert_mentions(
        &m,
        &[
            "scene.toml:27:10:",
            "objects[0].radius",
            "expected a number, got the string \"big\"",
        ],
    );
    let m = refused(&base_with("center = [0, 0, -1]", "center = [0, 0]"));
    assert_mentions(
        &m,
        &[
            "objects[0].center",
            "expected an array of 3 numbers [x, y, z], got an array of 2 values",
        ],
    );
    let m = refused(&base_with("width = 32", "width = 32.5"));
    assert_mentions(
        &m,
        &[
            "render.width",
            "expected a whole number, got the number 32.5",
        ],
    );
}

#[test]
fn missing_required_field() {
    let m = refused(&base_with("radius = 0.5\n", ""));
    assert_mentions(
        &m,
        &[
            "scene.toml:24:1:",
            "objects[0].radius",
            "missing field `radius`: a sphere needs it",
        ],
    );
    let m = refused(&base_with("ior = 1.5", ""));
    assert_mentions(&m, &["materials.glass.ior", "missing field `ior`"]);
}

#[test]
fn unknown_material_suggests_the_closest_name() {
    let m = refused(&base_with("material = \"red\"", "material = \"rde\""));
    assert_mentions(
        &m,
        &[
            "scene.toml:28:12:",
            "objects[0].material",
            "no material named \"rde\"",
            "defined materials: glass, mirror, red",
            "did you mean \"red\"?",
        ],
    );
}

#[test]
fn non_finite_numbers() {
    let m = refused(&base_with("radius = 0.5", "radius = nan"));
    assert_mentions(
        &m,
        &[
            "scene.toml:27:10:",
            "objects[0].radius",
            "expected a finite number, got NaN",
        ],
    );
    let m = refused(&base_with("vfov = 90", "vfov = -inf"));
    assert_mentions(&m, &["camera.vfov", "finite number, got -inf"]);
    // JSON has no infinity, but a number too large for f64 overflows to one.
    let m = refused_as(
        "{\"camera\": {\"lookat\": [0, 1e999, -1]}}",
        Format::Json,
        "s.json",
    );
    assert_mentions(
        &m,
        &[
            "s.json:1:",
            "camera.lookat[1]",
            "expected a finite number, got inf",
        ],
    );
    // Finite in f64 but infinite once converted to the renderer's f32.
    let m = refused(&base_with("radius = 0.5", "radius = 1e300"));
    assert_mentions(
        &m,
        &["scene.toml:27:10:", "objects[0].radius", "finite number"],
    );
}

#[test]
fn zero_or_negative_radius() {
    let m = refused(&base_with("radius = 0.5", "radius = 0"));
    assert_mentions(
        &m,
        &[
            "scene.toml:27:10:",
            "objects[0].radius",
            "must be greater than 0, got 0",
        ],
    );
    let m = refused(&base_with("radius = 100", "radius = -100"));
    assert_mentions(
        &m,
        &[
            "scene.toml:33:10:",
            "objects[1].radius",
            "must be greater than 0, got -100",
        ],
    );
}

#[test]
fn zero_or_negative_sizes_samples_and_depth() {
    let cases = [
        (
            "width = 32",
            "width = 0",
            "render.width",
            "must be at least 1, got 0",
        ),
        (
            "width = 32",
            "width = -4",
            "render.width",
            "must be at least 1, got -4",
        ),
        (
            "width = 32",
            "width = 32\nheight = 0",
            "render.height",
            "must be at least 1, got 0",
        ),
        (
            "samples_per_pixel = 2",
            "samples_per_pixel = 0",
            "render.samples_per_pixel",
            "must be at least 1, got 0",
        ),
        (
            "samples_per_pixel = 2",
            "samples_per_pixel = 2\nmax_depth = -1",
            "render.max_depth",
            "must be at least 1, got -1",
        ),
    ];
    for (from, to, field, message) in cases {
        let m = refused(&base_with(from, to));
        assert_mentions(&m, &["scene.toml:", field, message]);
    }
}

#[test]
fn absurd_image_size_is_refused_not_attempted() {
    let m = refused(&base_with("width = 32", "width = 200000\nheight = 200000"));
    assert_mentions(
        &m,
        &[
            "scene.toml:1:1:",
            "render:",
            "image 200000x200000",
            "more than",
        ],
    );
    // The limit is 2^26 pixels: 8192x8192 compiles (no film is allocated
    // before rendering), one more column does not.
    let at_limit = base_with("width = 32", "width = 8192\nheight = 8192");
    SceneFile::parse("scene.toml", at_limit, Format::Toml)
        .unwrap()
        .compile(&Overrides::default())
        .unwrap();
    let m = refused(&base_with("width = 32", "width = 8193\nheight = 8192"));
    assert_mentions(&m, &["image 8193x8192", "more than"]);
    let m = refused(&base_with("width = 32", "width = 99999999999"));
    assert_mentions(&m, &["render.width", "must be at most 4294967295"]);
    // Too large only because of the command line: said so, no file position.
    let file = SceneFile::parse("scene.toml", BASE.into(), Format::Toml).unwrap();
    let too_wide = Overrides {
        width: Some(4_000_000),
        ..Overrides::default()
    };
    let m = file.compile(&too_wide).unwrap_err().to_string();
    assert_mentions(&m, &["scene.toml: render", "command line"]);
}

#[test]
fn vfov_outside_0_to_180() {
    for bad in ["0", "180", "-10", "270"] {
        let m = refused(&base_with("vfov = 90", &format!("vfov = {bad}")));
        assert_mentions(
            &m,
            &[
                "scene.toml:6:8:",
                "camera.vfov",
                "greater than 0 and less than 180 degrees",
            ],
        );
    }
}

#[test]
fn orthographic_views_without_a_height_or_with_a_lens() {
    for bad in ["0", "-2", "inf", "nan"] {
        let m = refused(&base_with(
            "vfov = 90",
            &format!("vfov = 90\northo_height = {bad}"),
        ));
        assert_mentions(&m, &["scene.toml:7:", "camera.ortho_height"]);
    }
    let m = refused(&base_with(
        "vfov = 90",
        "vfov = 90\northo_height = 2\ndefocus_angle = 1",
    ));
    assert_mentions(
        &m,
        &["camera.defocus_angle", "orthographic camera has no lens"],
    );
    // Out of its use, the field of view is not checked.
    let file = SceneFile::parse(
        "scene.toml",
        base_with("vfov = 90", "vfov = 0\northo_height = 2"),
        Format::Toml,
    )
    .unwrap();
    assert!(file.compile(&Overrides::default()).is_ok());
}

#[test]
fn lookfrom_equal_to_lookat() {
    let m = refused(&base_with("lookat = [0, 0, -1]", "lookat = [0, 0, 0]"));
    assert_mentions(
        &m,
        &[
            "scene.toml:8:10:",
            "camera.lookat",
            "lookfrom and lookat are the same point",
        ],
    );
}

#[test]
fn vup_parallel_to_the_view_direction() {
    for vup in ["[0, 0, 1]", "[0, 0, -3]", "[0, 0, 0]"] {
        let m = refused(&base_with("vup = [0, 1, 0]", &format!("vup = {vup}")));
        assert_mentions(
            &m,
            &[
                "scene.toml:9:7:",
                "camera.vup",
                "parallel to the view direction",
            ],
        );
    }
}

#[test]
fn index_of_refraction_not_positive() {
    for ior in ["0", "-1.5"] {
        let m = refused(&base_with("ior = 1.5", &format!("ior = {ior}")));
        assert_mentions(
            &m,
            &[
                "scene.toml:22:7:",
                "materials.glass.ior",
                "index of refraction must be greater than 0",
            ],
        );
    }
}

#[test]
fn fuzz_outside_0_to_1() {
    for fuzz in ["-0.1", "1.5"] {
        let m = refused(&base_with("fuzz = 0.1", &format!("fuzz = {fuzz}")));
        assert_mentions(
            &m,
            &[
                "scene.toml:18:8:",
                "materials.mirror.fuzz",
                &format!("must be in [0, 1], got {fuzz}"),
            ],
        );
    }
}

#[test]
fn missing_file_and_directory() {
    let dir = std::env::temp_dir().join(format!("lumen-scene-errors-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("folder.toml")).unwrap();
    let missing = dir.join("missing.toml");
    let m = SceneFile::read(&missing).unwrap_err().to_string();
    assert_mentions(&m, &["missing.toml", "no such scene file"]);
    let m = SceneFile::read(&dir.join("folder.toml"))
        .unwrap_err()
        .to_string();
    assert_mentions(&m, &["folder.toml", "is a directory"]);
    std::fs::write(dir.join("scene.txt"), BASE).unwrap();
    let m = SceneFile::read(&dir.join("scene.txt"))
        .unwrap_err()
        .to_string();
    assert_mentions(
        &m,
        &[
            "scene.txt",
            "must end in .toml, .json, .xml (Mitsuba 3) or .pbrt",
        ],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The command refuses a bad file with one message on stderr, a non-zero exit
/// status, and no output image.
#[test]
fn the_command_refuses_bad_files_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("lumen-scene-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        ("typo.toml", base_with("radius = 0.5", "radus = 0.5")),
        ("fov.toml", base_with("vfov = 90", "vfov = 180")),
        ("syntax.json", "{\"render\": ".to_string()),
    ];
    for (name, text) in cases {
        let scene = dir.join(name);
        std::fs::write(&scene, text).unwrap();
        let out = dir.join(format!("{name}.png"));
        let result = Command::new(env!("CARGO_BIN_EXE_lumen"))
            .args(["render"])
            .arg(&scene)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(!result.status.success(), "{name} accepted");
        assert!(stderr.contains(name), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(!out.exists(), "{name}: an output file was left behind");
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| {
            !Path::new(n)
                .extension()
                .is_some_and(|e| e == "toml" || e == "json")
        })
        .collect();
    assert!(leftovers.is_empty(), "left behind: {leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_command_exports_and_renders_a_scene_file() {
    let dir = std::env::temp_dir().join(format!("lumen-scene-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let lumen = env!("CARGO_BIN_EXE_lumen");
    let stdout = Command::new(lumen)
        .args(["scenes", "export", "metal-mirror"])
        .output()
        .unwrap();
    assert!(stdout.status.success());
    let file = dir.join("m.json");
    let status = Command::new(lumen)
        .args(["scenes", "export", "metal-mirror", "-o"])
        .arg(&file)
        .status()
        .unwrap();
    assert!(status.success());
    let from_stdout = SceneFile::parse(
        "stdout",
        String::from_utf8(stdout.stdout).unwrap(),
        Format::Toml,
    )
    .unwrap();
    assert_eq!(SceneFile::read(&file).unwrap().desc, from_stdout.desc);
    let png = dir.join("m.png");
    let status = Command::new(lumen)
        .arg("render")
        .arg(&file)
        .args(["--width", "16", "--spp", "1", "-o"])
        .arg(&png)
        .status()
        .unwrap();
    assert!(status.success());
    assert!(png.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn numbers_too_large_or_small_for_f32_arithmetic() {
    // Far-apart camera points overflow the view vector in f32.
    let m = refused(&base_with(
        "lookfrom = [0, 0, 0]\nlookat = [0, 0, -1]",
        "lookfrom = [3e38, 0, 0]\nlookat = [-3e38, 0, 0]",
    ));
    assert_mentions(&m, &["scene.toml:", "camera:", "too large for f32"]);
    let m = refused(&base_with(
        "lookfrom = [0, 0, 0]",
        "lookfrom = [1e20, 0, 0]",
    ));
    assert_mentions(&m, &["camera:", "too large for f32"]);
    // A radius whose square overflows would make the sphere invisible.
    let m = refused(&base_with("radius = 0.5", "radius = 1e30"));
    assert_mentions(&m, &["scene.toml:", "objects[0]", "at most 1e18"]);
    // Positive in f64 but zero in f32.
    let m = refused(&base_with("ior = 1.5", "ior = 1e-60"));
    assert_mentions(&m, &["materials.glass.ior", "greater than 0"]);
    let m = refused(&base_with("width = 32", "width = 32\ngamma = 1e-60"));
    assert_mentions(&m, &["render.gamma", "greater than 0"]);
}

#[test]
fn emissive_materials_are_checked_like_the_others() {
    let lamp = |fields: &str| {
        base_with(
            "[materials.glass]",
            &format!("[materials.lamp]\ntype = \"emissive\"\n{fields}\n\n[materials.glass]"),
        )
    };
    // Line 22 is the lamp's first field.
    let m = refused(&lamp("radiance = [1, -2, 3]"));
    assert_mentions(
        &m,
        &[
            "scene.toml:22:12:",
            "materials.lamp.radiance",
            "must not be negative",
        ],
    );
    let m = refused(&lamp("two_sided = true"));
    assert_mentions(&m, &["materials.lamp", "radiance"]);
    let m = refused(&lamp("radiance = [1, 1, 1]\nalbedo = [0.5, 0.5, 0.5]"));
    assert_mentions(
        &m,
        &[
            "materials.lamp.albedo",
            "unknown field `albedo` in an emissive material",
            "`albedo` belongs to diffuse, metal and plastic materials",
        ],
    );
    let m = refused(&lamp("radiance = [1, 1, 1]\ntwo_sided = 2"));
    assert_mentions(&m, &["materials.lamp.two_sided"]);
    // Radiance above 1 is a bright light, not a mistake.
    let file = SceneFile::parse("s.toml", lamp("radiance = [15, 15, 15]"), Format::Toml).unwrap();
    file.compile(&Overrides::default()).unwrap();
}

/// serde would take an array for a table, its fields by position; the scene
/// format has tables there, and says so, wherever the table is.
#[test]
fn json_arrays_are_refused_where_tables_belong() {
    for (json, at) in [
        (r#"{"render": [24, 8]}"#, "render"),
        (r#"{"camera": [[0, 0, 5]]}"#, "camera"),
        (r#"{"background": ["solid", [1, 1, 1]]}"#, "background"),
        (
            r#"{"materials": {"m": ["diffuse", [0.5, 0.5, 0.5]]}}"#,
            "materials.m",
        ),
        (
            r#"{"textures": {"t": ["checker", 1, [0, 0, 0], [1, 1, 1]]}}"#,
            "textures.t",
        ),
        (
            r#"{"objects": [["sphere", [0, 0, -1], 0.5, "m"]]}"#,
            "objects[0]",
        ),
        (
            r#"{"materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
"objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "material": "m",
"transform": [[1, 2, 3]]}]}"#,
            "objects[0].transform[0]",
        ),
        (
            r#"{"materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
"objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "material": "m",
"transform": [{"rotate": [[0, 1, 0], 90]}]}]}"#,
            "objects[0].transform[0].rotate",
        ),
    ] {
        let m = refused_as(json, Format::Json, "s.json");
        assert_mentions(&m, &[&format!("{at}: expected"), "(a table), got an array"]);
    }
}

/// A triple has three numbers: a fourth element is refused, not dropped,
/// in every table and in both formats.
#[test]
fn triples_with_extra_elements_are_refused() {
    for (from, to) in [
        ("lookfrom = [0, 0, 0]", "lookfrom = [0, 0, 0, 7]"),
        ("lookfrom = [0, 0, 0]", "lookfrom = [0, 0, 0, \"x\"]"),
    ] {
        let m = refused(&base_with(from, to));
        assert_mentions(&m, &["camera.lookfrom", "got an array of 4 values"]);
    }
    let sphere = "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                  [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -1, 9]\nradius = 0.5\nmaterial = \"m\"\n";
    assert_mentions(
        &refused(sphere),
        &["objects[0].center", "got an array of 4 values"],
    );
}
