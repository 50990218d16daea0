//! Scene files at the edges of what the formats allow: seeds at the top of
//! the range, empty files, a file exported over itself, very long lists of
//! names in messages. Each is read the same way in TOML and JSON, and a
//! refusal is one message naming the place, never a panic.

mod common;
mod lumen_process;

use lumen::scene::desc::{SceneDesc, MAX_SEED};
use lumen::scene::file::{export, Format, SceneFile};
use lumen::scene::{Overrides, Scene};
use lumen_process::{assert_refused, lumen_output, stderr, temp_dir};

fn parse(text: &str, format: Format) -> Result<SceneFile, String> {
    SceneFile::parse(common::scene_file_name(format), text.to_string(), format)
        .map_err(|e| e.to_string())
}

const SPHERE_JSON: &str = r#""materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
 "objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "material": "m"}]"#;

#[test]
fn the_largest_seed_is_the_same_in_both_formats_and_exports() {
    assert_eq!(MAX_SEED, i64::MAX as u64);
    let json = format!("{{\"render\": {{\"seed\": {MAX_SEED}}},\n {SPHERE_JSON}}}");
    let file = parse(&json, Format::Json).unwrap();
    assert_eq!(file.desc.render.seed, MAX_SEED);
    let toml = export(&file.desc, Format::Toml).unwrap();
    assert_eq!(parse(&toml, Format::Toml).unwrap().desc, file.desc);

    for (text, format, at) in [
        (
            json.replace(&MAX_SEED.to_string(), &(MAX_SEED + 1).to_string()),
            Format::Json,
            "s.json:1:21: render.seed: must be at most 9223372036854775807",
        ),
        (
            json.replace(&MAX_SEED.to_string(), &u64::MAX.to_string()),
            Format::Json,
            "s.json:1:21: render.seed: must be at most 9223372036854775807",
        ),
        (
            "[textures.n]\ntype = \"noise\"\nseed = 9223372036854775808\n".to_string(),
            Format::Toml,
            "s.toml:3:8: syntax error",
        ),
    ] {
        let err = parse(&text, format).unwrap_err();
        assert!(err.starts_with(at), "{err}");
    }
    let noise = format!(
        "{{\"textures\": {{\"n\": {{\"type\": \"noise\", \"seed\": {}}}}}}}",
        MAX_SEED + 1
    );
    let err = parse(&noise, Format::Json).unwrap_err();
    assert!(
        err.starts_with("s.json:1:46: textures.n.seed: must be at most 9223372036854775807"),
        "{err}"
    );
    assert!(err.contains("largest integer TOML can hold"), "{err}");
}

#[test]
fn a_seed_too_large_for_toml_is_refused_when_compiled() {
    let mut desc = lumen::scene::builtin::find("hit-sphere").unwrap().desc();
    desc.render.seed = MAX_SEED + 1;
    let err = Scene::from_desc(&desc).unwrap_err().to_string();
    assert!(
        err.starts_with("render.seed: must be at most 9223372036854775807"),
        "{err}"
    );
    desc.render.seed = MAX_SEED;
    assert!(Scene::from_desc(&desc).is_ok());
    // Every description that compiles can be written as TOML.
    let toml = export(&desc, Format::Toml).unwrap();
    let back: SceneDesc = parse(&toml, Format::Toml).unwrap().desc;
    assert_eq!(back.render.seed, MAX_SEED);

    let file = parse(&format!("{{{SPHERE_JSON}}}"), Format::Json).unwrap();
    let overrides = Overrides {
        seed: Some(u64::MAX),
        ..Overrides::default()
    };
    let err = file.compile(&overrides).unwrap_err().to_string();
    assert!(
        err.starts_with("s.json: render.seed: must be at most")
            && err.contains("(with the settings given on the command line)"),
        "{err}"
    );
}

#[test]
fn the_command_line_seed_has_the_scene_files_range() {
    let dir = temp_dir("seed");
    let out = dir.join("x.png");
    let out = out.to_str().unwrap();
    let big = (MAX_SEED + 1).to_string();
    let args = [
        "render",
        "hit-sphere",
        "-o",
        out,
        "--width",
        "8",
        "--spp",
        "1",
        "--seed",
    ];
    let refused = lumen_output(&[&args[..], &[big.as_str()]].concat());
    assert!(!refused.status.success());
    let err = stderr(&refused);
    assert!(err.contains("--seed") && err.contains(&big), "{err}");
    assert!(err.contains("9223372036854775807"), "{err}");
    let max = MAX_SEED.to_string();
    let ok = lumen_output(&[&args[..], &[max.as_str()]].concat());
    assert!(ok.status.success(), "{}", stderr(&ok));
}

#[test]
fn blank_files_and_byte_order_marks_mean_the_same_in_both_formats() {
    let bom = "\u{feff}";
    for body in ["", " ", "\n", "\r\n\t \n"] {
        for format in [Format::Toml, Format::Json] {
            for text in [body.to_string(), format!("{bom}{body}")] {
                let file = parse(&text, format).unwrap_or_else(|e| panic!("{text:?}: {e}"));
                assert_eq!(file.desc, SceneDesc::default(), "{text:?}");
            }
        }
    }
    let json = format!("{bom}{{{SPHERE_JSON}}}");
    let toml = export(&parse(&json, Format::Json).unwrap().desc, Format::Toml).unwrap();
    assert_eq!(
        parse(&format!("{bom}{toml}"), Format::Toml).unwrap().desc,
        parse(&json, Format::Json).unwrap().desc
    );
    // Columns on the first line count from after the mark.
    let err = parse(&format!("{bom}{{\"render\": 5}}"), Format::Json).unwrap_err();
    assert!(err.starts_with("s.json:1:12: render:"), "{err}");
    let err = parse(&format!("{bom}render = 5"), Format::Toml).unwrap_err();
    assert!(err.starts_with("s.toml:1:10: render:"), "{err}");
}

#[test]
fn a_scene_without_objects_is_rendered_with_a_warning() {
    assert_eq!(SceneDesc::default().warnings().len(), 1);
    let dir = temp_dir("empty");
    // The built-in `gradient` is meant to show the background only.
    let png = dir.join("gradient.png");
    let args = [
        "render",
        "gradient",
        "-o",
        png.to_str().unwrap(),
        "--width",
        "8",
    ];
    let out = lumen_output(&args);
    assert!(out.status.success() && !stderr(&out).contains("warning"));
    for (name, text) in [("e.json", ""), ("e.toml", "\u{feff}\n"), ("c.json", "{}")] {
        let scene = dir.join(name);
        std::fs::write(&scene, text).unwrap();
        let png = dir.join(format!("{name}.png"));
        let out = lumen_output(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--width",
            "8",
            "--spp",
            "1",
        ]);
        let err = stderr(&out);
        assert!(out.status.success(), "{err}");
        let warning = format!(
            "lumen: warning: {}: the scene has no objects",
            scene.display()
        );
        assert_eq!(err.matches(&warning).count(), 1, "{err}");
        assert!(png.is_file());
    }
    let scene = dir.join("one.json");
    std::fs::write(&scene, format!("{{{SPHERE_JSON}}}")).unwrap();
    let out = lumen_output(&["scenes", "export", scene.to_str().unwrap()]);
    assert!(out.status.success() && !stderr(&out).contains("warning"));
}

#[test]
fn a_scene_file_is_never_exported_over_itself() {
    let dir = temp_dir("in-place");
    let text = "# a comment export would drop\n[render]\nwidth = 8\n";
    let scene = dir.join("s.toml");
    std::fs::write(&scene, text).unwrap();
    let s = scene.to_str().unwrap();
    let dotted = dir.join("sub/../s.toml");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let mut outputs = vec![s.to_string(), dotted.to_str().unwrap().to_string()];
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&scene, dir.join("link.toml")).unwrap();
        std::fs::hard_link(&scene, dir.join("hard.toml")).unwrap();
        outputs.push(dir.join("link.toml").to_str().unwrap().to_string());
        outputs.push(dir.join("hard.toml").to_str().unwrap().to_string());
    }
    for output in &outputs {
        let out = lumen_output(&["scenes", "export", s, "-o", output]);
        assert_refused(&out, &[output, "is the scene file being exported"]);
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    }
    // Through a link the other way round, and to JSON by another name.
    #[cfg(unix)]
    {
        let link = dir.join("link.toml");
        let out = lumen_output(&["scenes", "export", link.to_str().unwrap(), "-o", s]);
        assert_refused(&out, &["is the scene file being exported"]);
    }
    let json = dir.join("s.json");
    let out = lumen_output(&["scenes", "export", s, "-o", json.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let back = lumen_output(&["scenes", "export", json.to_str().unwrap(), "-o", s]);
    assert!(back.status.success(), "{}", stderr(&back));
    assert!(!std::fs::read_to_string(&scene)
        .unwrap()
        .contains("a comment"));
}

/// Materials `m0`, `m1`, … and one sphere of material `wanted`.
fn many_materials(n: usize, wanted: &str) -> String {
    let mut text = String::from("[materials]\n");
    for i in 0..n {
        text += &format!("m{i} = {{ type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }}\n");
    }
    text + &format!(
        "\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = \"{wanted}\"\n"
    )
}

#[test]
fn messages_list_a_few_of_many_names() {
    let text = many_materials(200_000, "m1234x");
    let file = parse(&text, Format::Toml).unwrap();
    let err = file.compile(&Overrides::default()).unwrap_err().to_string();
    assert!(err.len() < 600, "{} bytes: {}", err.len(), &err[..600]);
    assert!(
        err.starts_with("s.toml:200007:12: objects[0].material: no material named \"m1234x\"; defined materials: m1234, "),
        "{err}"
    );
    assert!(err.contains(" and 199992 more"), "{err}");
    assert!(err.contains("did you mean \"m1234\"?"), "{err}");

    let mut text = String::new();
    for i in 0..20 {
        text += &format!("[textures.t{i}]\ntype = \"noise\"\n");
    }
    text += "[materials.m]\ntype = \"diffuse\"\nalbedo = \"t17x\"\n";
    let err = parse(&text, Format::Toml)
        .unwrap()
        .compile(&Overrides::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no texture named \"t17x\" (defined: t17, ") && err.contains(" and 12 more)"),
        "{err}"
    );
}
