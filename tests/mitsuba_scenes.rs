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
        "orthographic_sensor/test_orthographic_path.xml",
        "projector/test_projector_textured_direct.xml",
        "various_emitters/test_various_emitters_ptracer.xml",
        "participating_media/test_homo_area_light_volpath.xml",
        "participating_media/test_hetero_sigmat_albedo_volpath.xml",
        "participating_media/test_hetero_spectral_sigmat_no_scattering_volpath.xml",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/peers/flip_normals/flip_normals.xml"
        ),
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/peers/hg_media/hg_media.xml"
        ),
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

#[test]
fn flip_normals_turns_every_kind_of_shape_inside_out() {
    // The scene compared with Mitsuba: its floor as it is; a rectangle
    // light, a sphere, a cylinder, a cube and an OBJ flipped; a rectangle
    // flipped and mirrored, whose mirror keeps its side in both.
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peers/flip_normals/flip_normals.xml");
    let file = SceneFile::read_with(&path, &spp(4)).unwrap_or_else(|e| panic!("{e}"));
    use lumen::scene::desc::ObjectDesc as O;
    let flips: Vec<(&str, bool)> = file
        .desc
        .objects
        .iter()
        .map(|o| match o {
            O::Sphere { flip_normals, .. } => ("sphere", *flip_normals),
            O::Quad { flip_normals, .. } => ("quad", *flip_normals),
            O::Cylinder { flip_normals, .. } => ("cylinder", *flip_normals),
            O::Box { flip_normals, .. } => ("box", *flip_normals),
            O::Mesh { flip_normals, .. } => ("mesh", *flip_normals),
            O::Triangles { flip_normals, .. } => ("triangles", *flip_normals),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        flips,
        [
            ("triangles", false),
            ("quad", true),
            ("sphere", true),
            ("cylinder", true),
            ("box", true),
            ("mesh", true),
            ("triangles", true),
        ]
    );
}

#[test]
fn a_mirrored_mesh_turns_over_as_in_mitsuba_but_not_in_an_instance() {
    // Mitsuba takes a mesh's side from its winding in the world: its own
    // to_world, mirroring, turns it over (lumen's mirror keeps it, so the
    // reader flips it), and an instance's does not.
    let dir = scratch_dir("mitsuba_scenes_mirrored_mesh");
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let mirror = "<transform name=\"to_world\"><scale x=\"-1\"/></transform>";
    let text = scene(&format!(
        "  <shape type=\"obj\"><string name=\"filename\" value=\"tri.obj\"/>{mirror}</shape>\n\
         <shape type=\"obj\"><string name=\"filename\" value=\"tri.obj\"/>{mirror}\
         <boolean name=\"flip_normals\" value=\"true\"/></shape>\n\
         <shape type=\"shapegroup\" id=\"g\"><shape type=\"obj\"><string name=\"filename\" value=\"tri.obj\"/></shape></shape>\n\
         <shape type=\"instance\"><ref id=\"g\"/>{mirror}</shape>"
    ));
    std::fs::write(dir.join("m.xml"), &text).unwrap();
    let file = SceneFile::read_with(&dir.join("m.xml"), &mitsuba::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let flips: Vec<bool> = file
        .desc
        .objects
        .iter()
        .map(|o| match o {
            lumen::scene::desc::ObjectDesc::Mesh { flip_normals, .. } => *flip_normals,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(flips, [true, false, false]);
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
        // An orthographic view must keep its pixels square, and has no
        // field of view.
        (
            scene("  <sensor type=\"orthographic\"><transform name=\"to_world\"><scale x=\"1\" y=\"2\"/></transform></sensor>"),
            vec!["bad.xml:2:3", "scales x by 1 and y by 2", "must scale both alike"],
        ),
        (
            scene("  <sensor type=\"orthographic\"><float name=\"fov\" value=\"40\"/></sensor>"),
            vec!["bad.xml:2:", "has no parameter `fov`"],
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
            scene("  <shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf></shape>"),
            vec!["bad.xml:2:", "two BSDFs", "--approximate"],
        ),
        (
            scene("  <shape type=\"cylinder\"><point name=\"p1\" value=\"0, 0, 0\"/></shape>"),
            vec!["bad.xml:2:3", "p0 and p1 must differ"],
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
    let two = "<bsdf type=\"twosided\"><bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf>";
    let text = scene(&format!(
        "  <shape type=\"sphere\">{two}</shape>\n  <shape type=\"cylinder\">{two}</shape>"
    ));
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
        .any(|w| w.contains("s.xml:2:") && w.contains("two BSDFs")));
    assert!(file
        .import_warnings
        .iter()
        .any(|w| w.contains("s.xml:3:") && w.contains("two BSDFs")));
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

/// The sensor's far clipping plane (10⁴ by default) is read, and hides
/// what lies beyond it from the camera, not from the light.
#[test]
fn far_clipping_planes_are_read_and_hide_what_lies_beyond() {
    let dir = scratch_dir("mitsuba_scenes_far");
    let path = dir.join("s.xml");
    let text = |clip: &str| {
        scene(&format!(
            "  <sensor type=\"perspective\">{clip}<film type=\"hdrfilm\">\
             <integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/>\
             </film><sampler type=\"independent\"><integer name=\"sample_count\" value=\"4\"/></sampler></sensor>\n\
             <shape type=\"sphere\"><point name=\"center\" value=\"0, 0, 10\"/><float name=\"radius\" value=\"2\"/>\
             <emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>"
        ))
    };
    let centre = |clip: &str| {
        std::fs::write(&path, text(clip)).unwrap();
        let file = SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap();
        let far = file.desc.camera.far_clip;
        let scene = file.compile(&Overrides::default()).unwrap();
        let (film, _) = lumen::render::render(&scene, &|_| {});
        (far, film.linear()[4 * 8 + 4])
    };
    let (far, seen) = centre("");
    assert_eq!(far, Some(1e4));
    assert!(seen.x > 0.5, "{seen}");
    let (far, hidden) = centre("<float name=\"far_clip\" value=\"7\"/>");
    assert_eq!(far, Some(7.0));
    assert_eq!(hidden.max_element(), 0.0);
    let (_, seen) = centre("<float name=\"far_clip\" value=\"9\"/>");
    assert!(seen.x > 0.5, "{seen}");
    // A thin lens focuses on the far plane unless told otherwise, as
    // Mitsuba's does.
    std::fs::write(
        &path,
        text("<float name=\"far_clip\" value=\"50\"/>").replace(
            "type=\"perspective\">",
            "type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.1\"/>",
        ),
    )
    .unwrap();
    let file = SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap();
    assert_eq!(file.desc.camera.focus_dist, Some(50.0));
    // Not beyond the near plane: refused.
    let e = refused(
        &dir,
        "s.xml",
        &text("<float name=\"near_clip\" value=\"2\"/><float name=\"far_clip\" value=\"1\"/>"),
        &mitsuba::Options::default(),
    );
    assert!(
        e.contains("camera.far_clip") && e.contains("beyond near_clip"),
        "{e}"
    );
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

fn mitsuba_data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/mitsuba-data")
}

/// Mitsuba's test meshes in `.serialized` form (version 4) read as their
/// PLY twins do: the same positions, normals and triangles, and the same
/// texture coordinates. The serialized files were written from OBJs, so
/// they store v down the image, as Mitsuba reads OBJs (its
/// `test_mesh_io.py` checks 1 − v); turned into lumen's v up the image,
/// they are the PLY's as written.
#[test]
fn serialized_meshes_read_as_their_ply_twins() {
    for name in ["rectangle_normals", "rectangle_uv", "rectangle_normals_uv"] {
        let dir = mitsuba_data().join("tests");
        let a = lumen::mesh::load(&dir.join(format!("serialized/{name}.serialized")))
            .unwrap_or_else(|e| panic!("{e}"));
        let b = lumen::mesh::load(&dir.join(format!("ply/{name}.ply")))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(a.meshes.len(), 1, "{name}");
        let (a, b) = (&a.meshes[0], &b.meshes[0]);
        assert_eq!(a.positions, b.positions, "{name}");
        assert_eq!(a.normals, b.normals, "{name}");
        let close = match (&a.uvs, &b.uvs) {
            (Some(a), Some(b)) => a
                .iter()
                .zip(b)
                .all(|(p, q)| (p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6),
            (None, None) => true,
            _ => false,
        };
        assert!(close, "{name}: {:?} against {:?}", a.uvs, b.uvs);
        assert_eq!(a.triangles, b.triangles, "{name}");
        assert!(a.uvs.is_some() == name.contains("uv"), "{name}");
    }
}

/// A `.serialized` file of several meshes (Mitsuba's material preview,
/// version 3) is read whole, and each shape takes the mesh its
/// `shape_index` names; an index past the last is refused.
#[test]
fn a_serialized_shape_takes_the_mesh_its_index_names() {
    let file = mitsuba_data().join("scenes/matpreview/matpreview.serialized");
    let model = lumen::mesh::load(&file).unwrap_or_else(|e| panic!("{e}"));
    assert!(model.meshes.len() >= 3, "{} meshes", model.meshes.len());
    assert!(model.meshes.iter().all(|m| !m.triangles.is_empty()));

    let dir = scratch_dir("mitsuba_scenes_serialized");
    std::fs::copy(&file, dir.join("m.serialized")).unwrap();
    let shape = |index: usize| {
        scene(&format!(
            "  <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/>\
             <integer name=\"shape_index\" value=\"{index}\"/></shape>"
        ))
    };
    let path = dir.join("s.xml");
    std::fs::write(&path, shape(1)).unwrap();
    let read =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let compiled = read
        .compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        compiled.stats.placed_triangles as usize,
        model.meshes[1].triangles.len()
    );
    let past = model.meshes.len();
    let e = refused(&dir, "s.xml", &shape(past), &mitsuba::Options::default());
    assert!(
        e.contains("objects[0].part") && e.contains(&format!("no mesh {past}")),
        "{e}"
    );
}

/// Broken `.serialized` files are refused, naming the file and what is
/// wrong: another format, a cut file, a table that points nowhere, and
/// counts its compressed data could not hold (refused before anything is
/// allocated for them).
#[test]
fn broken_serialized_files_are_refused() {
    use flate2::{write::ZlibEncoder, Compression};
    use std::io::Write;
    let dir = scratch_dir("mitsuba_scenes_serialized_bad");
    let good =
        std::fs::read(mitsuba_data().join("tests/serialized/rectangle_normals_uv.serialized"))
            .unwrap();
    // A version 4 mesh declaring two billion vertices in a few bytes.
    let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
    z.write_all(&1u32.to_le_bytes()).unwrap();
    z.write_all(b"bomb\0").unwrap();
    z.write_all(&2_000_000_000u64.to_le_bytes()).unwrap();
    z.write_all(&1u64.to_le_bytes()).unwrap();
    let mut bomb = vec![0x1C, 0x04, 0x04, 0x00];
    bomb.extend(z.finish().unwrap());
    bomb.extend(0u64.to_le_bytes());
    bomb.extend(1u32.to_le_bytes());
    let mut bad_table = good.clone();
    let n = bad_table.len();
    bad_table[n - 12..n - 4].copy_from_slice(&7u64.to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "ply",
            b"ply\nformat ascii 1.0\n".to_vec(),
            "does not start with 0x041C",
        ),
        ("cut", good[..good.len() / 2].to_vec(), "m.serialized"),
        ("table", bad_table, "where no mesh of version 4 starts"),
        ("bomb", bomb, "more than its compressed data can hold"),
    ];
    for (what, bytes, expected) in cases {
        let path = dir.join("m.serialized");
        std::fs::write(&path, &bytes).unwrap();
        let e = lumen::mesh::load(&path)
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.serialized") && e.contains(expected),
            "{what}: {e}"
        );
    }
}

/// A version 5 file (Mitsuba's packed records: eight floats a vertex, four
/// `u32`s a face, maps and attributes after them) reads as the mesh it
/// packs; one that stores tangent frames is refused.
#[test]
fn version_5_serialized_meshes_read_their_packed_records() {
    use flate2::{write::ZlibEncoder, Compression};
    use std::io::Write;
    let twin = lumen::mesh::load(&mitsuba_data().join("tests/ply/rectangle_normals_uv.ply"))
        .unwrap_or_else(|e| panic!("{e}"));
    let mesh = &twin.meshes[0];
    let pack = |layout: u32| {
        let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
        let mut put = |b: &[u8]| z.write_all(b).unwrap();
        put(&(0x1000 | layout).to_le_bytes());
        put(&4u32.to_le_bytes());
        put(b"rect");
        let (v, f) = (mesh.positions.len() as u64, mesh.triangles.len() as u64);
        for n in [v, f, v, 0] {
            put(&n.to_le_bytes());
        }
        let normals = mesh.normals.as_ref().unwrap();
        let uvs = mesh.uvs.as_ref().unwrap();
        for i in 0..mesh.positions.len() {
            // Mitsuba's v runs down the image, lumen's up.
            let uv = [uvs[i][0], 1.0 - uvs[i][1]];
            for x in mesh.positions[i].iter().chain(&normals[i]).chain(&uv) {
                put(&x.to_le_bytes());
            }
        }
        for t in &mesh.triangles {
            for i in t.iter().chain(&[0]) {
                put(&i.to_le_bytes());
            }
        }
        // The vertex-to-surface-point map (P = V), then one attribute.
        for i in 0..v as u32 {
            put(&i.to_le_bytes());
        }
        put(&1u32.to_le_bytes());
        put(&11u32.to_le_bytes());
        put(b"vertex_mark");
        put(&[0u8]);
        put(&1u32.to_le_bytes());
        for _ in 0..v {
            put(&0.5f32.to_le_bytes());
        }
        let mut bytes = vec![0x1C, 0x04, 0x05, 0x00];
        bytes.extend(z.finish().unwrap());
        bytes.extend(0u64.to_le_bytes());
        bytes.extend(1u32.to_le_bytes());
        bytes
    };
    let dir = scratch_dir("mitsuba_scenes_serialized_v5");
    let path = dir.join("r.serialized");
    std::fs::write(&path, pack(0x1 | 0x4)).unwrap();
    let read = lumen::mesh::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let got = &read.meshes[0];
    assert_eq!(got.positions, mesh.positions);
    assert_eq!(got.normals, mesh.normals);
    let uvs = |m: &lumen::mesh::TriangleMesh| m.uvs.clone().unwrap_or_default();
    assert!(
        uvs(got)
            .iter()
            .zip(&uvs(mesh))
            .all(|(p, q)| (p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6),
        "{:?} against {:?}",
        got.uvs,
        mesh.uvs
    );
    assert_eq!(uvs(got).len(), 4);
    assert_eq!(got.triangles, mesh.triangles);

    std::fs::write(&path, pack(0x1 | 0x2 | 0x4)).unwrap();
    let e = lumen::mesh::load(&path)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("tangent frames"), "{e}");
}

/// An envmap's `to_world` of any rotation is lumen's map in that frame:
/// turned about +y it is a `rotation` (as before); turned otherwise (a
/// z-up scene's sky) a `frame`, which shows the same sky along the same
/// directions as the rotation would; a scale or a mirror is refused.
#[test]
fn an_envmap_turned_any_way_keeps_its_orientation() {
    use lumen::scene::desc::BackgroundDesc;
    let dir = scratch_dir("mitsuba_scenes_envmap_frame");
    let museum = data().join("../../common/textures/museum.exr");
    std::fs::copy(museum, dir.join("sky.exr")).unwrap();
    let read = |turn: &str| {
        let path = dir.join("s.xml");
        std::fs::write(
            &path,
            scene(&format!(
                "  <emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/>\
                 <transform name=\"to_world\">{turn}</transform></emitter>"
            )),
        )
        .unwrap();
        SceneFile::read_with(&path, &mitsuba::Options::default())
    };
    let background = |f: &SceneFile| match &f.desc.background {
        BackgroundDesc::Image {
            rotation, frame, ..
        } => (*rotation, *frame),
        other => panic!("{other:?}"),
    };
    let about_y = read("<rotate y=\"1\" angle=\"30\"/>").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(background(&about_y), (210.0, None));

    let up_z = read("<rotate x=\"1\" angle=\"90\"/>").unwrap_or_else(|e| panic!("{e}"));
    let (rotation, frame) = background(&up_z);
    let frame = frame.expect("a frame");
    assert_eq!(rotation, 180.0);
    let want = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]];
    for (a, b) in frame.iter().flatten().zip(want.iter().flatten()) {
        assert!((a - b).abs() < 1e-9, "{frame:?}");
    }

    // The turn about +y written as a frame shows the same sky.
    let mut framed = about_y.clone();
    let t = 30f64.to_radians();
    framed.desc.background = match &about_y.desc.background {
        BackgroundDesc::Image {
            file,
            intensity,
            rows_at_poles,
            layout,
            ..
        } => BackgroundDesc::Image {
            file: file.clone(),
            rotation: 180.0,
            intensity: *intensity,
            rows_at_poles: *rows_at_poles,
            layout: *layout,
            frame: Some([
                [t.cos(), 0.0, -t.sin()],
                [0.0, 1.0, 0.0],
                [t.sin(), 0.0, t.cos()],
            ]),
        },
        other => panic!("{other:?}"),
    };
    let (a, b) = (
        about_y.compile(&Overrides::default()).unwrap(),
        framed.compile(&Overrides::default()).unwrap(),
    );
    for i in 0..200 {
        let (y, phi) = (-0.99 + 1.98 * (i as f32 / 200.0), i as f32 * 2.39996);
        let r = (1.0 - y * y).sqrt();
        let d = lumen::math::Vec3::new(r * phi.cos(), y, r * phi.sin());
        let (p, q) = (a.background.color(d), b.background.color(d));
        assert!(
            (p - q).abs().max_element() < 1e-3 * (1.0 + p.max_element()),
            "{d:?}: {p:?} against {q:?}"
        );
    }

    for bad in ["<scale value=\"2\"/>", "<scale x=\"-1\"/>"] {
        let e = read(bad).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("must turn it"), "{bad}: {e}");
    }
}

/// Mitsuba's material preview scene (three meshes of one `.serialized`
/// file, a sky turned to z up, a checkerboard floor) reads, renders, and
/// renders to the same bits from its TOML export.
#[test]
fn the_material_preview_scene_renders_and_exports() {
    let path = mitsuba_data().join("scenes/matpreview/matpreview.xml");
    let options = mitsuba::Options {
        defines: vec![
            ("spp".into(), "2".into()),
            ("width".into(), "68".into()),
            ("height".into(), "51".into()),
        ],
        ..Default::default()
    };
    let direct = SceneFile::read_with(&path, &options).unwrap_or_else(|e| panic!("{e}"));
    let text = lumen::scene::file::export(&direct.desc, Format::Toml).unwrap();
    let mut exported =
        SceneFile::parse("exported.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(exported.desc, direct.desc);
    exported.dir = direct.dir.clone();
    let model = lumen::mesh::load(&mitsuba_data().join("scenes/matpreview/matpreview.serialized"))
        .unwrap_or_else(|e| panic!("{e}"));
    // Shapes 0, 1 and 2 of the file, each placed once.
    let parts: usize = model.meshes[..3].iter().map(|m| m.triangles.len()).sum();
    let render = |f: &SceneFile| {
        let scene = f.compile(&Overrides::default()).unwrap();
        assert_eq!(scene.stats.placed_triangles as usize, parts);
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let (a, b) = (render(&direct), render(&exported));
    assert!(a.iter().any(|c| c.max_element() > 0.1), "black");
    assert!(a == b, "the exported scene renders differently");
}

/// Mitsuba takes a PLY's texture coordinates as written, v down the image;
/// lumen's v runs up it, so a Mitsuba `ply` shape is read with `flip_v`,
/// which turns every v over (1 − v), and an OBJ's without.
#[test]
fn a_ply_shapes_texture_coordinates_are_turned_over() {
    use lumen::scene::desc::ObjectDesc;
    let dir = scratch_dir("mitsuba_scenes_ply_uv");
    let ply = mitsuba_data().join("tests/ply/rectangle_uv.ply");
    std::fs::copy(&ply, dir.join("r.ply")).unwrap();
    std::fs::write(
        dir.join("r.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0.25\nvt 1 0.25\nvt 1 1\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene(
            "  <shape type=\"ply\"><string name=\"filename\" value=\"r.ply\"/></shape>\n\
             <shape type=\"obj\"><string name=\"filename\" value=\"r.obj\"/></shape>",
        ),
    )
    .unwrap();
    let file =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let flips: Vec<bool> = file
        .desc
        .objects
        .iter()
        .map(|o| match o {
            ObjectDesc::Mesh { flip_v, .. } => *flip_v,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(flips, [true, false]);
    file.compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));

    let load = |flip_v| {
        let options = lumen::mesh::LoadOptions {
            flip_v,
            ..Default::default()
        };
        lumen::mesh::load_with(&ply, options).unwrap().meshes[0]
            .uvs
            .clone()
            .unwrap()
    };
    let (plain, turned) = (load(false), load(true));
    assert!(plain
        .iter()
        .zip(&turned)
        .all(|(a, b)| a[0] == b[0] && (a[1] + b[1] - 1.0).abs() < 1e-6));
}

/// Textures on Mitsuba's `sphere` and `rectangle` fall where Mitsuba puts
/// them: (u, v) round the sphere's z (u from +x towards +y, v = 0 at +z,
/// the image's top row) and across the rectangle from (−1, −1) (the
/// image's top-left corner). A 4 × 2 image of eight pure colours is looked
/// up at its texel centres.
#[test]
fn textures_on_spheres_and_rectangles_fall_where_mitsuba_puts_them() {
    use lumen::math::Vec3;
    let dir = scratch_dir("mitsuba_scenes_shape_uv");
    let colours = common::eight_colours_png(&dir.join("t.png"));
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene(
            "  <texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"t.png\"/></texture>\n\
             <shape type=\"sphere\"><point name=\"center\" x=\"0\" y=\"0\" z=\"0\"/>\
             <bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"t\"/></bsdf></shape>\n\
             <shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"5\"/></transform>\
             <bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"t\"/></bsdf></shape>\n\
             <shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"-5\"/></transform>\
             <emitter type=\"area\"><ref name=\"radiance\" id=\"t\"/></emitter></shape>",
        ),
    )
    .unwrap();
    let scene = SceneFile::read_with(&path, &mitsuba::Options::default())
        .and_then(|f| f.compile(&Overrides::default()))
        .unwrap_or_else(|e| panic!("{e}"));
    common::assert_texels_round_z(&scene, Vec3::ZERO, &colours);
    for (x, y, i) in [
        (-0.75, -0.5, 0),
        (0.75, -0.5, 3),
        (-0.75, 0.5, 4),
        (0.25, 0.5, 6),
    ] {
        // The lit rectangle, a quad, as the other, two triangles.
        for centre in [5.0, -5.0] {
            let p = Vec3::new(centre + x, y, 0.0);
            let seen = common::colour_at(&scene, p + Vec3::Z, -Vec3::Z);
            assert!(
                common::colours_close(seen, colours[i]),
                "rectangle at ({centre} + {x}, {y}): {seen:?}, want texel {i}"
            );
        }
    }
    // The lit one shines towards +z only, as Mitsuba's.
    let behind = common::colour_at(&scene, Vec3::new(-5.0, 0.0, -1.0), Vec3::Z);
    assert_eq!(behind, lumen::math::Color::ZERO);
}

/// No `.serialized` file makes the reader panic: every cut of a real file,
/// and every byte of it set to values that matter to a reader (0, 1, 0xFF,
/// 0x7F and its own value plus one), reads or is refused.
#[test]
fn no_broken_serialized_file_makes_the_reader_panic() {
    let good =
        std::fs::read(mitsuba_data().join("tests/serialized/rectangle_normals_uv.serialized"))
            .unwrap();
    let dir = scratch_dir("mitsuba_scenes_serialized_fuzz");
    let path = dir.join("m.serialized");
    let mut variants: Vec<Vec<u8>> = (0..good.len()).map(|n| good[..n].to_vec()).collect();
    for i in 0..good.len() {
        for v in [0u8, 1, 0xFF, 0x7F, good[i].wrapping_add(1)] {
            let mut bytes = good.clone();
            bytes[i] = v;
            variants.push(bytes);
        }
    }
    let mut refused = 0;
    for bytes in &variants {
        std::fs::write(&path, bytes).unwrap();
        let read = std::panic::catch_unwind(|| lumen::mesh::load(&path).is_ok());
        match read {
            Ok(true) => {}
            Ok(false) => refused += 1,
            Err(_) => panic!("the reader panicked on {bytes:?}"),
        }
    }
    // Most changes are caught (the zlib stream's checksum among them).
    assert!(
        refused > variants.len() / 2,
        "{refused} of {}",
        variants.len()
    );
}

/// A conductor's `eta` and `k` may be textures, as any Mitsuba parameter:
/// each point of the surface takes the index its texture gives there.
#[test]
fn a_conductors_index_of_refraction_may_be_textured() {
    use lumen::bsdf::Lobe;
    use lumen::math::Vec3;
    let dir = scratch_dir("mitsuba_scenes_textured_eta");
    let path = dir.join("s.xml");
    // A checkerboard in u (two squares across the rectangle): eta 0.2 or
    // 0.9, and k 0.7 or 0.5, on the two halves (a checkerboard's squares
    // are read as reflectances, within [0, 1]).
    let board = |name: &str, a: f64, b: f64| {
        format!(
            "<texture name=\"{name}\" type=\"checkerboard\"><rgb name=\"color0\" value=\"{a}\"/>\
             <rgb name=\"color1\" value=\"{b}\"/><transform name=\"to_uv\"><scale x=\"1\" y=\"0.5\"/></transform></texture>"
        )
    };
    std::fs::write(
        &path,
        scene(&format!(
            "  <shape type=\"rectangle\"><bsdf type=\"conductor\">{}{}</bsdf></shape>",
            board("eta", 0.2, 0.9),
            board("k", 0.7, 0.5)
        )),
    )
    .unwrap();
    let scene = SceneFile::read_with(&path, &mitsuba::Options::default())
        .and_then(|f| f.compile(&Overrides::default()))
        .unwrap_or_else(|e| panic!("{e}"));
    let mut seen = Vec::new();
    for x in [-0.5f32, 0.5] {
        let ray = lumen::ray::Ray::new(Vec3::new(x, 0.0, 1.0), -Vec3::Z);
        let record = scene
            .hit(&ray, lumen::math::Interval::new(1e-4, f32::INFINITY))
            .expect("a hit");
        let lobe = scene
            .material(&record)
            .bsdf(&record, -ray.direction, &scene.textures)
            .map(|b| b.lobe);
        let Some(Lobe::Conductor(c)) = lobe else {
            panic!("{lobe:?}")
        };
        seen.push((c.eta.x, c.k.x));
    }
    seen.sort_by(|a, b| a.0.total_cmp(&b.0));
    let close = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-5;
    assert!(close(seen[0].0, 0.2) && close(seen[0].1, 0.7), "{seen:?}");
    assert!(close(seen[1].0, 0.9) && close(seen[1].1, 0.5), "{seen:?}");
}

/// A medium's Henyey–Greenstein phase (`hg`, its `g` 0.8 when absent) and
/// the medium a sensor stands in are read, exported and read back alike;
/// other phase functions are refused with what lumen has.
#[test]
fn phase_functions_and_the_sensors_medium_are_read() {
    let dir = scratch_dir("mitsuba_scenes_phase");
    let body = |phase: &str| {
        scene(&format!(
            "  <medium type=\"homogeneous\" id=\"fog\">\
             <float name=\"sigma_t\" value=\"0.5\"/>{phase}</medium>\
             <medium type=\"homogeneous\" id=\"mist\">\
             <float name=\"sigma_t\" value=\"0.1\"/><phase type=\"hg\"/></medium>\
             <sensor type=\"perspective\"><ref id=\"mist\"/>\
             <film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>\
             <integer name=\"height\" value=\"4\"/></film></sensor>\
             <emitter type=\"constant\"/>\
             <shape type=\"sphere\"><bsdf type=\"null\"/>\
             <ref name=\"interior\" id=\"fog\"/><ref name=\"exterior\" id=\"mist\"/></shape>"
        ))
    };
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        body("<phase type=\"hg\"><float name=\"g\" value=\"-0.3\"/></phase>"),
    )
    .unwrap();
    let file =
        SceneFile::read_with(&path, &mitsuba::Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let desc = &file.desc;
    assert_eq!(desc.media["fog"].g, Some(-0.3));
    assert_eq!(desc.media["mist"].g, Some(0.8));
    assert_eq!(desc.camera.medium.as_deref(), Some("mist"));
    let text = lumen::scene::file::export(desc, Format::Toml).unwrap();
    assert!(text.contains("g = -0.3"), "{text}");
    let exported = SceneFile::parse("exported.toml", text, Format::Toml).unwrap();
    assert_eq!(&exported.desc, desc);
    file.compile(&Overrides::default()).unwrap();
    let e = refused(
        &dir,
        "rayleigh.xml",
        &body("<phase type=\"rayleigh\"/>"),
        &mitsuba::Options::default(),
    );
    assert!(
        e.contains("rayleigh")
            && e.contains("`isotropic` and `hg`")
            && e.contains("rayleigh.xml:2:"),
        "{e}"
    );
}

/// A projector reads as lumen's: its irradiance π · scale · the colour,
/// its image's top towards the frame's +y, its field of view across the
/// image's width worked out for the image's shape (carrot.png is 10 × 9)
/// as Mitsuba's camera does for its film; one that scales is refused.
#[test]
fn a_projector_frames_its_image_as_mitsubas_camera_frames_its_film() {
    use lumen::light::source::LightDesc;
    let dir = scratch_dir("mitsuba_scenes_projector");
    let read = |name: &str, body: &str| {
        let path = dir.join(name);
        std::fs::write(&path, scene(body)).unwrap();
        SceneFile::read_with(&path, &mitsuba::Options::default())
    };
    let carrot = mitsuba_data().join("common/textures/carrot.png");
    let lookat = "<transform name=\"to_world\"><lookat origin=\"0, 0, 1\" target=\"0, 0, 0\" \
                  up=\"1, 0, 0\"/></transform>";
    let image = format!(
        "<texture type=\"bitmap\" name=\"irradiance\">\
         <string name=\"filename\" value=\"{}\"/></texture>",
        carrot.display()
    );
    let file = read(
        "projector-test.xml",
        &format!(
            "<emitter type=\"projector\">{lookat}{image}<float name=\"scale\" value=\"3\"/>\
             <float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"y\"/></emitter>\
             <emitter type=\"projector\">{lookat}<rgb name=\"irradiance\" value=\"0.5, 1, 2\"/>\
             <float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"y\"/></emitter>"
        ),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let [LightDesc::Projector(textured), LightDesc::Projector(plain)] = &file.desc.lights[..]
    else {
        panic!("{:?}", file.desc.lights);
    };
    let pi = std::f64::consts::PI;
    assert_eq!(textured.irradiance, Some([3.0 * pi; 3]));
    assert_eq!(plain.irradiance, Some([0.5 * pi, pi, 2.0 * pi]));
    assert!(textured.texture.is_some() && plain.texture.is_none());
    assert_eq!(textured.direction, Some([0.0, 0.0, -1.0]));
    let up = textured.up.unwrap();
    assert!((up[0] - 1.0).abs() < 1e-12 && up[1].abs() < 1e-12, "{up:?}");
    // 40° up the image: across, 2 atan(tan 20° · 10/9) for the carrot, 40°
    // for a colour (a single texel).
    let across = |aspect: f64| (2.0 * (20f64.to_radians().tan() * aspect).atan()).to_degrees();
    assert!(
        (textured.fov - across(10.0 / 9.0)).abs() < 1e-9,
        "{}",
        textured.fov
    );
    assert!((plain.fov - across(1.0)).abs() < 1e-9, "{}", plain.fov);
    for (body, wanted) in [
        (
            "<emitter type=\"projector\"><float name=\"fov\" value=\"40\"/></emitter>",
            "needs an `irradiance`",
        ),
        (
            "<emitter type=\"projector\"><rgb name=\"irradiance\" value=\"1\"/>\
             <transform name=\"to_world\"><scale value=\"2\"/></transform></emitter>",
            "may only turn and move it",
        ),
        (
            "<emitter type=\"projector\"><rgb name=\"irradiance\" value=\"1\"/>\
             <transform name=\"to_world\"><matrix value=\"1 0.6 0 0  0 0.8 0 0  0 0 1 0  0 0 0 1\"/>\
             </transform></emitter>",
            "no scale, shear or mirror",
        ),
    ] {
        let e = read("projector-bad.xml", body).unwrap_err().to_string();
        assert!(
            e.contains("projector-bad.xml:2:") && e.contains(wanted),
            "{e}"
        );
    }
}
