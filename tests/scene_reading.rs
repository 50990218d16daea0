//! Scene files are read by a quick reader that gives up on anything it is
//! unsure of, and then by the precise reader that words every message: the
//! two agree on every file, valid or not, written plainly or not, small or
//! of many objects.

mod common;

use common::{read_both, scene_file_name};
use lumen::scene::builtin::BUILTINS;
use lumen::scene::file::{export, Format, SceneFile};

/// Both readers' results for `text`, which must agree; the quick one's.
fn read(text: &str, format: Format) -> Result<SceneFile, String> {
    read_both(scene_file_name(format), text, format).map_err(|e| e.to_string())
}

#[test]
fn every_built_in_reads_the_same_either_way() {
    for b in BUILTINS {
        for format in [Format::Toml, Format::Json] {
            let text = export(&b.desc(), format).unwrap();
            let file = read(&text, format).unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert_eq!(file.desc, b.desc(), "{}", b.name);
        }
    }
    for (text, format) in [
        (include_str!("../examples/glass-hollow.toml"), Format::Toml),
        (include_str!("../examples/still-life.toml"), Format::Toml),
        (include_str!("../examples/ring.json"), Format::Json),
    ] {
        read(text, format).unwrap();
    }
}

/// `n` objects of every kind, in turn, written in many of the ways TOML
/// allows: plain lines, sub-tables, arrays over several lines, comments,
/// other tables between the objects.
fn many_objects(n: usize) -> String {
    let mut text = String::from(
        "caption = \"many\"\n[render]\nwidth = 8\n\n[materials]\nm = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\n",
    );
    for i in 0..n {
        let x = i as f64 * 0.25 - 3.0;
        text += &match i % 7 {
            0 => format!("\n[[objects]]\ntype = \"sphere\"\ncenter = [{x}, 0, -1]\nradius = 0.1\nmaterial = \"m\"\n"),
            1 => format!("[[objects]] # a quad\ntype = 'quad'\ncorner = [{x}, 0, -2]\nu = [1, 0, 0,]\nv = [0, 1e0, 0]\nmaterial = \"m\"\ntransform = [{{ rotate = {{ axis = [0, 1, 0], degrees = 30 }} }}, {{ motion = [0, 0.5, 0] }}]\n"),
            2 => format!("[[objects]]\ntype = \"box\"\nmin = [{x}, 0, -3]\nmax = [{}, 1, -2]\nmaterial = \"m\"\n[[objects.transform]]\nscale = 2\n", x + 1.0),
            3 => format!("[[objects]]\ntype = \"medium\"\ndensity = 0.5\nalbedo = [0.5, 0.5, 0.5]\n[objects.boundary]\ntype = \"sphere\"\ncenter = [{x}, 0, -4]\nradius = 1_0\n"),
            4 => format!("[[objects]]\ntype = \"sphere\"\ncenter = [\n  {x},\n  0,\n  -5,\n]\nradius = 0.1\nmaterial = \"m\"\ntransform = [{{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] }}]\n"),
            5 => format!("[textures.t{i}]\ntype = \"noise\"\n\n[[objects]]\n\"type\" = \"sphere\"\ncenter = [{x}, 0, -6]\nradius = 0.1\nmaterial = \"m\"\n"),
            _ => format!("[[objects]]\ntype = \"medium\"\ndensity = 2\nalbedo = [1, 1, 1]\nboundary.type = \"box\"\nboundary.min = [{x}, 0, -7]\nboundary.max = [{}, 1, -6]\n", x + 1.0),
        };
    }
    text
}

#[test]
fn many_objects_written_every_way_read_the_same() {
    let text = many_objects(2000);
    let file = read(&text, Format::Toml).unwrap();
    assert_eq!(file.desc.objects.len(), 2000);
    assert_eq!(
        file.desc.textures.len(),
        (0..2000).filter(|i| i % 7 == 5).count()
    );
    let json = export(&file.desc, Format::Json).unwrap();
    assert_eq!(read(&json, Format::Json).unwrap().desc, file.desc);
    let toml = export(&file.desc, Format::Toml).unwrap();
    assert_eq!(read(&toml, Format::Toml).unwrap().desc, file.desc);
}

#[test]
fn a_mistake_among_many_objects_gets_the_precise_message() {
    let text = many_objects(1500);
    let lines: Vec<&str> = text.lines().collect();
    // The radius of a sphere far down the file, broken in turn.
    let at = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with("radius = 0.1"))
        .nth(600)
        .unwrap()
        .0;
    for (bad, message) in [
        (
            "radius = \"0.1\"",
            "expected a number, got the string \"0.1\"",
        ),
        ("radius = nan", "expected a finite number, got NaN"),
        ("radius = 1e999", ""),
        ("radus = 0.1", "unknown field `radus`"),
    ] {
        let mut broken = lines.clone();
        broken[at] = bad;
        let broken = broken.join("\n");
        let err = read(&broken, Format::Toml).unwrap_err();
        let place = format!("s.toml:{}:", at + 1);
        assert!(err.starts_with(&place) && err.contains(message), "{err}");
    }
    // The same in JSON.
    let desc = read(&text, Format::Toml).unwrap().desc;
    let json = export(&desc, Format::Json).unwrap();
    let broken = json.replacen("\"radius\": 0.1", "\"radius\": null", 700);
    let err = read(&broken, Format::Json).unwrap_err();
    assert!(err.contains("expected a number, got null"), "{err}");
}

#[test]
fn what_serde_would_take_and_the_precise_reader_refuses_is_refused() {
    let sphere =
        "\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = \"m\"\n";
    let materials = "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    for (toml, message) in [
        ("[render]\nwidth = 0\n", "must be at least 1, got 0"),
        ("[render]\nheight = 0\n", "must be at least 1, got 0"),
        ("[render]\nsamples_per_pixel = 0\n", "must be at least 1"),
        ("[render]\nmax_depth = 0\n", "must be at least 1"),
        ("[render]\ngamma = nan\n", "expected a finite number"),
        (
            "[camera]\nlookfrom = [0, inf, 0]\n",
            "expected a finite number",
        ),
        (
            "[render]\nsampler = \"sobol\"\nsampling = \"sobol\"\n",
            "not both",
        ),
        // `objects` spelled with an escape, then given again as tables.
        ("\"\\u006fbjects\" = []\n", "duplicate key `objects`"),
    ] {
        let err = read(&format!("{toml}{materials}{sphere}"), Format::Toml).unwrap_err();
        assert!(err.contains(message), "{err}");
    }
    let body =
        r#""objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "material": "m"}]"#;
    let m = r#"{"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}"#;
    for (json, message) in [
        (
            format!(r#"{{"materials": {{"m": {m}, "m": {m}}}, {body}}}"#),
            "material `m` is defined twice",
        ),
        (
            format!(
                r#"{{"render": {{"width": 8, "width": 9}}, "materials": {{"m": {m}}}, {body}}}"#
            ),
            "given twice",
        ),
        (
            format!(r#"{{"render": {{"height": null}}, "materials": {{"m": {m}}}, {body}}}"#),
            "got null",
        ),
        (
            format!(r#"{{"caption": "{}", {body}}}"#, "[".repeat(70)),
            "no material",
        ),
        (
            format!(r#"{{"a": {}{}}}"#, "[".repeat(70), "]".repeat(70)),
            "nested more than 64 deep",
        ),
    ] {
        let err = read(&json, Format::Json).map(|f| {
            f.compile(&lumen::scene::Overrides::default())
                .map(|_| ())
                .unwrap_err()
                .to_string()
        });
        let err = err.unwrap_or_else(|e| e);
        assert!(err.contains(message), "{err}");
    }
}

#[test]
fn negative_zero_reads_as_the_precise_reader_reads_it() {
    let m = "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    let toml = format!("{m}[[objects]]\ntype = \"sphere\"\ncenter = [-0, -0.0, -1]\nradius = 1\nmaterial = \"m\"\n");
    let json = r#"{"materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
        "objects": [{"type": "sphere", "center": [-0, -0.0, -1], "radius": 1, "material": "m"}]}"#;
    for (text, format) in [(toml.as_str(), Format::Toml), (json, Format::Json)] {
        let quick = read(text, format).unwrap().desc;
        let precise =
            SceneFile::parse_with_positions(scene_file_name(format), text.to_string(), format)
                .unwrap()
                .desc;
        // Equal as numbers is not enough: the sign of a zero is written out.
        assert_eq!(
            export(&quick, Format::Json).unwrap(),
            export(&precise, Format::Json).unwrap()
        );
    }
}
