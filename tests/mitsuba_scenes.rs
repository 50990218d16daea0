//! Reading Mitsuba 3 scenes: a scene exported to lumen's TOML renders to
//! the same bits as the scene read directly; every kind of bad input is
//! refused with the file, line and column and what to do, and a render of
//! it writes nothing.

mod common;

use common::scratch_dir;
use lumen::scene::file::{mitsuba, Format, SceneFile};
use lumen::scene::Overrides;
use std::path::{Path, PathBuf};

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/mitsuba-data/tests/scenes")
}

fn spp(n: u32) -> mitsuba::Options {
    mitsuba::Options {
        defines: vec![("spp".into(), n.to_string())],
        ..Default::default()
    }
}

#[test]
fn a_scene_exported_to_toml_renders_to_the_same_bits() {
    for scene in [
        "bsdf_spheres/test_pointlight_path.xml",
        "bsdf_spheres/test_arealight_path.xml",
        "bsdf_spheres/test_envmap_path.xml",
        "bsdf_spheres/test_textured_diffuse_path.xml",
        "instancing/test_instancing_path.xml",
        "floating_sphere/test_directional_direct.xml",
    ] {
        let path = data().join(scene);
        let direct = SceneFile::read_with(&path, &spp(4)).unwrap_or_else(|e| panic!("{e}"));
        let text = lumen::scene::file::export(&direct.desc, Format::Toml).unwrap();
        let mut exported = SceneFile::parse("exported.toml", text, Format::Toml)
            .unwrap_or_else(|e| panic!("{scene}: {e}"));
        assert_eq!(exported.desc, direct.desc, "{scene}");
        exported.dir = direct.dir.clone();
        let render = |f: &SceneFile| {
            let scene = f.compile(&Overrides::default()).unwrap();
            let (film, _) = lumen::render::render(&scene, &|_| {});
            film.linear()
        };
        let (a, b) = (render(&direct), render(&exported));
        assert!(a.iter().any(|c| c.max_element() > 0.0), "{scene}: black");
        assert!(a == b, "{scene}: the exported scene renders differently");
    }
}

/// The message reading `text` (as `dir/name`, with `files` beside it)
/// gives, which must be refused.
fn refused(dir: &Path, name: &str, text: &str, options: &mitsuba::Options) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    match SceneFile::read_with(&path, options) {
        Err(e) => e.to_string(),
        Ok(f) => match f.compile(&Overrides::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{text}"),
        },
    }
}

fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>\n")
}

#[test]
fn bad_scenes_are_refused_with_the_place_and_what_to_do() {
    let dir = scratch_dir("mitsuba_scenes_bad");
    let none = mitsuba::Options::default();
    let cases: Vec<(String, Vec<&str>)> = vec![
        // Malformed XML.
        (
            scene("  <shape type=\"sphere\">\n"),
            vec!["bad.xml:", "malformed XML"],
        ),
        (
            scene("  <shape type=\"sphere\"><float name=\"radius\" value=\"&nope;\"/></shape>"),
            vec!["bad.xml:2:", "malformed XML"],
        ),
        // An entity bomb: no document type definition is read.
        (
            "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [\n <!ENTITY lol \"lol\">\n \
             <!ENTITY lol2 \"&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;\">\n \
             <!ENTITY lol3 \"&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;\">\n]>\n\
             <scene version=\"3.0.0\"><integer name=\"x\" value=\"&lol3;\"/></scene>\n"
                .to_string(),
            vec!["bad.xml:2:", "document type definition"],
        ),
        ("<scene>\n</scene>\n".to_string(), vec!["bad.xml:1:1", "version"]),
        (
            "<sceen version=\"3.0.0\"/>\n".to_string(),
            vec!["bad.xml:1:1", "root element is <sceen>"],
        ),
        // Parameters.
        (
            scene("  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>"),
            vec!["bad.xml:2:", "undefined parameter `$r`", "<default name=\"r\""],
        ),
        // Unknown plugins and parameters.
        (
            scene("  <shape type=\"sphere\"><bsdf type=\"difuse\"/></shape>"),
            vec!["bad.xml:2:", "bsdf type `difuse` is not supported", "did you mean `diffuse`?", "roughconductor"],
        ),
        (
            scene("  <shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectanse\" value=\"0.5\"/></bsdf></shape>"),
            vec!["bad.xml:2:", "has no parameter `reflectanse`", "did you mean `reflectance`?"],
        ),
        (
            scene("  <shape type=\"sphere\"><bsdf type=\"diffuse\"><string name=\"reflectance\" value=\"red\"/></bsdf></shape>"),
            vec!["bad.xml:2:", "`reflectance` must be a colour"],
        ),
        (
            scene("  <shape type=\"spere\"/>"),
            vec!["bad.xml:2:3", "shape type `spere`", "did you mean `sphere`?"],
        ),
        (
            scene("  <shapes type=\"sphere\"/>"),
            vec!["bad.xml:2:3", "<shapes> is not an element", "did you mean <shape>?"],
        ),
        // Values.
        (
            scene("  <shape type=\"sphere\"><float name=\"radius\" value=\"nan\"/></shape>"),
            vec!["bad.xml:2:", "finite number"],
        ),
        (
            scene("  <shape type=\"sphere\"><float name=\"radius\" value=\"1e999\"/></shape>"),
            vec!["bad.xml:2:", "finite number"],
        ),
        (
            scene("  <shape type=\"cube\"><transform name=\"to_world\"><scale value=\"1, 0, 1\"/></transform></shape>"),
            vec!["bad.xml:2:", "singular"],
        ),
        (
            scene("  <shape type=\"cube\"><transform name=\"to_world\"><matrix value=\"1 2 3\"/></transform></shape>"),
            vec!["bad.xml:2:", "16 or 9"],
        ),
        (
            scene("  <shape type=\"obj\"><string name=\"filename\" value=\"nowhere.obj\"/></shape>"),
            vec!["bad.xml:2:", "`nowhere.obj` not found"],
        ),
        (
            scene("  <shape type=\"sphere\"><ref id=\"nothing\"/></shape>"),
            vec!["bad.xml:2:", "no element has id `nothing`"],
        ),
        (
            scene("  <bsdf type=\"diffuse\" id=\"a\"/>\n  <bsdf type=\"diffuse\" id=\"a\"/>"),
            vec!["bad.xml:3:", "id `a` is given twice"],
        ),
        (
            scene("  <shape type=\"sphere\"><bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"glas\"/></bsdf></shape>"),
            vec!["bad.xml:2:", "unknown index of refraction `glas`", "bk7"],
        ),
        (
            scene("  <shape type=\"disk\"/>"),
            vec!["bad.xml:2:3", "a disk shape", "--approximate"],
        ),
        (
            scene("  <shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"500:0.5, 400:0.5\"/></bsdf></shape>"),
            vec!["bad.xml:2:", "wavelengths must increase"],
        ),
    ];
    for (text, wanted) in &cases {
        let message = refused(&dir, "bad.xml", text, &none);
        for w in wanted {
            assert!(
                message.contains(w),
                "{w:?} not in:\n{message}\nfor:\n{text}"
            );
        }
    }
}

#[test]
fn includes_that_loop_or_leave_the_folder_and_unused_parameters_are_refused() {
    let dir = scratch_dir("mitsuba_scenes_includes");
    let none = mitsuba::Options::default();
    std::fs::write(dir.join("a.xml"), scene("  <include filename=\"b.xml\"/>")).unwrap();
    std::fs::write(dir.join("b.xml"), scene("  <include filename=\"a.xml\"/>")).unwrap();
    let m = refused(
        &dir,
        "main.xml",
        &scene("  <include filename=\"a.xml\"/>"),
        &none,
    );
    assert!(
        m.contains("includes itself") && m.contains("b.xml:2:"),
        "{m}"
    );

    let outside = dir
        .parent()
        .unwrap()
        .join(format!("lumen-outside-{}.xml", std::process::id()));
    std::fs::write(&outside, scene("")).unwrap();
    let include = scene(&format!(
        "  <include filename=\"../{}\"/>",
        outside.file_name().unwrap().to_str().unwrap()
    ));
    let m = refused(&dir, "main.xml", &include, &none);
    assert!(
        m.contains("outside the scene's folder") && m.contains("--allow-outside"),
        "{m}"
    );
    let allowed = mitsuba::Options {
        allow_outside: true,
        ..Default::default()
    };
    let path = dir.join("main.xml");
    assert!(SceneFile::read_with(&path, &allowed).is_ok());
    std::fs::remove_file(&outside).unwrap();

    let unused = mitsuba::Options {
        defines: vec![("sp".into(), "4".into())],
        ..Default::default()
    };
    let m = refused(
        &dir,
        "plain.xml",
        &scene("  <default name=\"spp\" value=\"4\"/>"),
        &unused,
    );
    assert!(m.contains("-D sp=") && m.contains("no parameter"), "{m}");
}

#[test]
fn approximate_renders_what_lumen_lacks_with_a_warning_each() {
    let dir = scratch_dir("mitsuba_scenes_approximate");
    let text = scene("  <shape type=\"disk\"/>\n  <shape type=\"serialized\"/>");
    let path = dir.join("s.xml");
    std::fs::write(&path, &text).unwrap();
    let options = mitsuba::Options {
        approximate: true,
        ..Default::default()
    };
    let file = SceneFile::read_with(&path, &options).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.import_warnings.len(), 2, "{:?}", file.import_warnings);
    assert!(file
        .import_warnings
        .iter()
        .any(|w| w.contains("s.xml:2:3: a disk shape")));
    assert!(file
        .import_warnings
        .iter()
        .any(|w| w.contains("s.xml:3:3: a serialized shape")));
    file.compile(&Overrides::default()).unwrap();
}

#[test]
fn a_render_of_a_bad_scene_writes_nothing_and_fails() {
    let dir = scratch_dir("mitsuba_scenes_cli");
    let path = dir.join("bad.xml");
    std::fs::write(&path, scene("  <shape type=\"spere\"/>")).unwrap();
    let out = dir.join("out.png");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args([
            "render",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("bad.xml:2:3") && stderr.contains("spere"),
        "{stderr}"
    );
    assert!(!out.exists());
    // -D fills a parameter; a define that names nothing is refused.
    let good = dir.join("good.xml");
    std::fs::write(
        &good,
        scene("  <default name=\"n\" value=\"1\"/>\n  <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/><rfilter type=\"box\"/></film><sampler type=\"independent\"><integer name=\"sample_count\" value=\"$n\"/></sampler></sensor>\n  <shape type=\"sphere\"/>"),
    )
    .unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args([
            "render",
            good.to_str().unwrap(),
            "-D",
            "n=2",
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(String::from_utf8_lossy(&run.stderr).contains("8x8 at 2 spp"));
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args([
            "render",
            good.to_str().unwrap(),
            "-D",
            "m=2",
            "-o",
            dir.join("x.png").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(!dir.join("x.png").exists());
}

#[test]
fn a_sensor_whose_transform_mirrors_mirrors_the_image() {
    let dir = scratch_dir("mitsuba_scenes_mirror");
    let read = |scale: &str| {
        let text = scene(&format!(
            "  <sensor type=\"perspective\"><transform name=\"to_world\"><scale {scale}/>\
             <lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>"
        ));
        let path = dir.join("s.xml");
        std::fs::write(&path, &text).unwrap();
        SceneFile::read_with(&path, &mitsuba::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
            .desc
            .camera
    };
    let (plain, mirrored) = (read("x=\"1\""), read("x=\"-1\""));
    assert!(!plain.mirror && mirrored.mirror);
    assert_eq!(plain.lookfrom, [0.0, 0.0, 5.0]);
    assert_eq!(mirrored.lookfrom, [0.0, 0.0, 5.0]);
}

/// `thindielectric` is lumen's thin sheet of index int_ior / ext_ior.
#[test]
fn a_thin_dielectric_is_a_thin_sheet() {
    use lumen::scene::desc::{MaterialDesc, ObjectDesc};
    let dir = scratch_dir("mitsuba_scenes_thin");
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene(
            "  <shape type=\"sphere\"><bsdf type=\"thindielectric\">\
             <string name=\"int_ior\" value=\"water\"/></bsdf></shape>",
        ),
    )
    .unwrap();
    let file =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let ObjectDesc::Sphere { material, .. } = &file.desc.objects[0] else {
        panic!("{:?}", file.desc.objects[0]);
    };
    let MaterialDesc::Dielectric(d) = &file.desc.materials[material] else {
        panic!("{:?}", file.desc.materials[material]);
    };
    assert!(d.thin && (d.ior - 1.333 / 1.000277).abs() < 1e-3, "{d:?}");
    file.compile(&Overrides::default()).unwrap();
}

/// A film's crop window renders that window of the image; the sensor's
/// near clipping plane (10⁻² by default) is where camera rays start.
#[test]
fn crop_windows_and_near_clipping_planes_are_read() {
    let dir = scratch_dir("mitsuba_scenes_crop");
    let path = dir.join("s.xml");
    let sensor = |film: &str, clip: &str| {
        scene(&format!(
            "  <sensor type=\"perspective\">{clip}<film type=\"hdrfilm\">\
             <integer name=\"width\" value=\"64\"/><integer name=\"height\" value=\"48\"/>\
             {film}</film></sensor>\n  <shape type=\"sphere\"/>"
        ))
    };
    std::fs::write(
        &path,
        sensor(
            "<integer name=\"crop_offset_x\" value=\"8\"/><integer name=\"crop_width\" value=\"16\"/>",
            "<float name=\"near_clip\" value=\"0.5\"/>",
        ),
    )
    .unwrap();
    let file =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.desc.render.crop, Some([8, 0, 16, 48]));
    assert_eq!(file.desc.camera.near_clip, 0.5);
    let compiled = file.compile(&Overrides::default()).unwrap();
    assert_eq!(
        (compiled.settings.width, compiled.settings.height),
        (16, 48)
    );

    std::fs::write(&path, sensor("", "")).unwrap();
    let file = SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap();
    assert_eq!(
        (file.desc.render.crop, file.desc.camera.near_clip),
        (None, 1e-2)
    );

    // A window that leaves the image: Mitsuba's default width is the
    // image's, so an offset alone does not fit.
    std::fs::write(
        &path,
        sensor("<integer name=\"crop_offset_y\" value=\"4\"/>", ""),
    )
    .unwrap();
    let e = SceneFile::read_with(&path, &mitsuba::Options::default())
        .unwrap()
        .compile(&Overrides::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.crop") && e.contains("[0, 4, 64, 48]"),
        "{e}"
    );
}

/// `blendbsdf` is a mix of its two BSDFs, the second with share `weight`
/// (a number or a texture); each BSDF keeps its own sides, and `twosided`
/// around a blend makes both of them scatter on both sides (copies, as
/// another shape uses one of them one-sided). Exported to TOML, it renders
/// to the same bits.
#[test]
fn a_blendbsdf_is_a_mix_of_its_bsdfs() {
    use lumen::scene::desc::{MaterialDesc, ObjectDesc, ScalarDesc};
    let dir = scratch_dir("mitsuba_scenes_blend");
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene(
            "  <sensor type=\"perspective\"><transform name=\"to_world\">\
             <lookat origin=\"0, 0, 6\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>\
             <film type=\"hdrfilm\"><integer name=\"width\" value=\"24\"/>\
             <integer name=\"height\" value=\"16\"/></film>\
             <sampler type=\"independent\"><integer name=\"sample_count\" value=\"4\"/></sampler>\
             </sensor>\n\
             <emitter type=\"constant\"/>\n\
             <bsdf type=\"diffuse\" id=\"matte\"/>\n\
             <bsdf type=\"roughconductor\" id=\"gold\"><string name=\"material\" value=\"Au\"/></bsdf>\n\
             <shape type=\"sphere\"><point name=\"center\" x=\"-1.2\" y=\"0\" z=\"0\"/>\
             <bsdf type=\"twosided\"><bsdf type=\"blendbsdf\">\
             <texture type=\"checkerboard\" name=\"weight\"/>\
             <ref id=\"matte\"/><ref id=\"gold\"/></bsdf></bsdf></shape>\n\
             <shape type=\"sphere\"><point name=\"center\" x=\"1.2\" y=\"0\" z=\"0\"/>\
             <bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.2\"/>\
             <ref id=\"matte\"/><ref id=\"gold\"/></bsdf></shape>",
        ),
    )
    .unwrap();
    let file =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let mix = |i: usize| {
        let ObjectDesc::Sphere { material, .. } = &file.desc.objects[i] else {
            panic!("{:?}", file.desc.objects[i]);
        };
        let MaterialDesc::Mix(m) = &file.desc.materials[material] else {
            panic!("{:?}", file.desc.materials[material]);
        };
        m.clone()
    };
    let sides = |m: &lumen::material::MixDesc| {
        m.materials
            .clone()
            .map(|name| match &file.desc.materials[&name] {
                MaterialDesc::Diffuse(d) => d.one_sided,
                MaterialDesc::Conductor(c) => c.one_sided,
                other => panic!("{other:?}"),
            })
    };
    let (two, one) = (mix(0), mix(1));
    assert!(
        matches!(two.weight, Some(ScalarDesc::Texture(_))),
        "{two:?}"
    );
    assert_eq!(sides(&two), [false, false]);
    assert!(!two.one_sided);
    assert_eq!(one.weight, Some(ScalarDesc::Value(0.2)));
    assert_eq!(one.materials, ["matte".to_string(), "gold".to_string()]);
    assert_eq!(sides(&one), [true, true]);

    let text = lumen::scene::file::export(&file.desc, Format::Toml).unwrap();
    let mut exported =
        SceneFile::parse("exported.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(exported.desc, file.desc);
    exported.dir = file.dir.clone();
    let render = |f: &SceneFile| {
        let scene = f.compile(&Overrides::default()).unwrap();
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let (a, b) = (render(&file), render(&exported));
    assert!(a.iter().any(|c| c.max_element() > 0.0));
    assert!(a == b, "the exported scene renders differently");
}
