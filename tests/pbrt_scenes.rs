//! Reading pbrt-v4 scenes: each directive becomes the lumen description
//! pbrt's conventions call for (cameras, transforms, instances, lights,
//! materials, textures); a scene exported to lumen's TOML renders to the
//! same bits as the scene read directly; bad input is refused with the
//! file, line and column, and a render of it writes nothing.

mod common;

use common::scratch_dir;
use lumen::scene::desc::{
    BackgroundDesc, ColorDesc, LightDesc, MaterialDesc, ObjectDesc, SceneDesc, TextureDesc,
    TransformDesc,
};
use lumen::scene::file::{import::Options, Format, SceneFile};
use lumen::scene::Overrides;
use std::path::{Path, PathBuf};

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pbrt")
}

/// Reads `text` as a pbrt scene in `dir`.
fn read_in(dir: &Path, text: &str, options: &Options) -> Result<SceneFile, String> {
    let path = dir.join("s.pbrt");
    std::fs::write(&path, text).unwrap();
    SceneFile::read_with(&path, options).map_err(|e| e.to_string())
}

fn read(name: &str, text: &str) -> SceneDesc {
    let dir = scratch_dir(&format!("pbrt_scenes_{name}"));
    let image = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/khronos/TextureTransformTest/Correct.png");
    std::fs::copy(image, dir.join("t.png")).unwrap();
    read_in(&dir, text, &Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .desc
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9 * (1.0 + b[i].abs()))
}

#[test]
fn a_scene_exported_to_toml_renders_to_the_same_bits() {
    for scene in ["box.pbrt", "killeroos/killeroo-simple.pbrt"] {
        exported_renders_the_same(&assets().join(scene));
    }
    exported_renders_the_same(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peers/hg_media/hg_media.pbrt"),
    );
}

/// pbrt-v4's own killeroo scene (from `mmp/pbrt-v4-scenes`) reads as
/// written: a sphere light, a floor and a wall, and the loopsubdiv
/// killeroo subdivided once (four triangles for each of its 8,316) and
/// placed twice, coated as lumen reads pbrt's `coateddiffuse`.
#[test]
fn pbrts_killeroo_scene_reads_as_written() {
    let file = SceneFile::read(&assets().join("killeroos/killeroo-simple.pbrt"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        file.import_warnings.is_empty(),
        "{:?}",
        file.import_warnings
    );
    let d = &file.desc;
    let triangles: Vec<usize> = d
        .objects
        .iter()
        .filter_map(|o| match o {
            ObjectDesc::Triangles { indices, .. } => Some(indices.len()),
            _ => None,
        })
        .collect();
    assert_eq!(triangles, [2, 2, 4 * 8316, 4 * 8316]);
    let alphas: Vec<f64> = d
        .materials
        .values()
        .filter_map(|m| match m {
            MaterialDesc::Plastic(p) => match p.alpha {
                Some(lumen::material::param::RoughnessDesc::Value(a)) => Some(a),
                _ => None,
            },
            _ => None,
        })
        .collect();
    assert_eq!(alphas.len(), 2, "the two coated killeroos");
    for r in [0.025f64, 0.15] {
        assert!(
            alphas.iter().any(|a| (a - r.sqrt()).abs() < 1e-12),
            "{alphas:?}"
        );
    }
    let (width, height) = (d.render.width, d.render.height);
    assert_eq!((width, height), (700, Some(700)));
    let overrides = Overrides {
        width: Some(32),
        samples_per_pixel: Some(8),
        ..Overrides::default()
    };
    let scene = file.compile(&overrides).unwrap();
    assert_eq!(scene.lights.len(), 1, "the sphere");
    let image = lumen::render::render(&scene, &|_| {}).0.linear();
    // The floor, lit bluish (reflectance 0.5, 0.5, 0.8), fills the bottom.
    let bottom = &image[image.len() * 3 / 4..];
    let mean = bottom.iter().fold(lumen::math::Color::ZERO, |s, c| s + *c) / bottom.len() as f32;
    assert!(mean.z > mean.x && mean.x > 0.01, "{mean}");
}

/// `path`'s scene exported to lumen's TOML renders to the same bits as
/// read directly.
fn exported_renders_the_same(path: &Path) {
    let direct = SceneFile::read(path).unwrap_or_else(|e| panic!("{e}"));
    let text = lumen::scene::file::export(&direct.desc, Format::Toml).unwrap();
    let mut exported =
        SceneFile::parse("exported.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(exported.desc, direct.desc);
    exported.dir = direct.dir.clone();
    let overrides = Overrides {
        width: Some(40),
        samples_per_pixel: Some(4),
        ..Overrides::default()
    };
    let render = |f: &SceneFile| {
        let scene = f.compile(&overrides).unwrap();
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let (a, b) = (render(&direct), render(&exported));
    assert!(a.iter().any(|c| c.max_element() > 0.05), "black");
    assert!(a == b, "the exported scene renders differently");
}

#[test]
fn cameras_follow_pbrts_conventions() {
    // LookAt alone: pbrt's image runs along up × forward, mirrored to
    // lumen's; a Scale -1 1 1 before it (as converted scenes have) is not.
    let plain = read(
        "camera_plain",
        "LookAt 1 2 3  1 2 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 100\nWorldBegin\n",
    );
    assert!(plain.camera.mirror);
    assert!(close(plain.camera.lookfrom, [1.0, 2.0, 3.0]));
    assert!(close(plain.camera.lookat, [1.0, 2.0, 2.0]));
    assert!(close(plain.camera.vup, [0.0, 1.0, 0.0]));
    // fov spans the shorter side: here the height.
    assert!((plain.camera.vfov - 30.0).abs() < 1e-9);
    assert_eq!((plain.render.width, plain.render.height), (200, Some(100)));
    let flipped = read(
        "camera_flipped",
        "Scale -1 1 1\nLookAt 1 2 3  1 2 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200\nWorldBegin\n",
    );
    assert!(!flipped.camera.mirror);
    assert!(close(flipped.camera.lookfrom, [1.0, 2.0, 3.0]));
    // A portrait image: fov spans the width.
    let want = 2.0 * ((15f64.to_radians()).tan() * 2.0).atan();
    assert!((flipped.camera.vfov - want.to_degrees()).abs() < 1e-9);
    // Defaults: pbrt's film, sampler and depth (5 bounces: 6 segments).
    assert_eq!(plain.render.samples_per_pixel, 16);
    assert_eq!(plain.render.max_depth, 6);
}

/// An orthographic camera sees pbrt's screen window: 2 across the
/// image's shorter side, or the `screenwindow` given, sized by the
/// camera's transform; and the same view written for Mitsuba (whose
/// sensor plane is 2 across the image's width, sized by its transform's
/// scale) reads as the same camera.
#[test]
fn orthographic_cameras_see_the_window_each_format_gives_them() {
    let camera = |name: &str, before: &str, params: &str, (w, h): (u32, u32)| {
        read(
            name,
            &format!(
                "{before}LookAt 1 2 3  1 2 0  0 1 0\nCamera \"orthographic\" {params}\n\
                 Film \"rgb\" \"integer xresolution\" {w} \"integer yresolution\" {h}\nWorldBegin\n"
            ),
        )
        .camera
    };
    let landscape = camera("ortho_landscape", "", "", (200, 100));
    assert_eq!(landscape.ortho_height, Some(2.0));
    assert!(landscape.mirror && close(landscape.lookfrom, [1.0, 2.0, 3.0]));
    assert!(close(landscape.lookat, [1.0, 2.0, 2.0]));
    assert_eq!(
        camera("ortho_portrait", "", "", (100, 200)).ortho_height,
        Some(4.0)
    );
    let window = camera(
        "ortho_window",
        "",
        "\"float screenwindow\" [ -3 3 -1.5 1.5 ]",
        (200, 100),
    );
    assert_eq!(window.ortho_height, Some(3.0));
    // The camera's frame shrunk by half sees twice as much of the world.
    let scaled = camera("ortho_scaled", "Scale 0.5 0.5 1\n", "", (200, 100));
    assert!((scaled.ortho_height.unwrap() - 4.0).abs() < 1e-12);

    let dir = scratch_dir("pbrt_scenes_ortho_mitsuba");
    let xml = dir.join("ortho.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\"><sensor type=\"orthographic\"><transform name=\"to_world\">\
         <scale x=\"3\" y=\"3\"/><lookat origin=\"1, 2, 3\" target=\"1, 2, 0\" up=\"0, 1, 0\"/>\
         </transform><float name=\"near_clip\" value=\"0.01\"/>\
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/>\
         <integer name=\"height\" value=\"100\"/></film></sensor></scene>",
    )
    .unwrap();
    let mitsuba = SceneFile::read(&xml)
        .unwrap_or_else(|e| panic!("{e}"))
        .desc
        .camera;
    assert_eq!(mitsuba.ortho_height, window.ortho_height);
    assert!(close(mitsuba.lookfrom, window.lookfrom) && close(mitsuba.lookat, window.lookat));
    assert!(close(mitsuba.vup, window.vup));
    // Mitsuba's image runs along the frame's −x, pbrt's along its +x.
    assert!(!mitsuba.mirror && window.mirror);
}

/// pbrt's `projection` light is a projector given its intensity (`scale`
/// times the image, nearest texel), `fov` across the image's shorter side,
/// the image's top towards the light frame's +y and its left towards −x:
/// a slide of red and green above blue and white, cast down from a frame
/// whose +y is the world's +z, lights the floor red at (−x, +z), green at
/// (+x, +z), blue at (−x, −z) and white at (+x, −z).
#[test]
fn a_projection_light_casts_its_image_as_pbrt_casts_it() {
    let dir = scratch_dir("pbrt_scenes_projection");
    let mut img = image::RgbImage::new(4, 2);
    for (x, y, c) in [
        (0, 0, [255, 0, 0]),
        (1, 0, [0, 255, 0]),
        (0, 1, [0, 0, 255]),
        (1, 1, [255; 3]),
    ] {
        for dx in 0..2 {
            img.put_pixel(2 * x + dx, y, image::Rgb(c));
        }
    }
    img.save(dir.join("slide.png")).unwrap();
    let text = "LookAt 0 6 0  0 0 0  0 0 -1\nCamera \"perspective\" \"float fov\" 60\n\
                Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 64\n\
                Sampler \"independent\" \"integer pixelsamples\" 4\nWorldBegin\n\
                AttributeBegin\nTranslate 0 2 0\nRotate 90 1 0 0\n\
                LightSource \"projection\" \"string filename\" \"slide.png\" \"float fov\" 40 \
                \"float scale\" 2\nAttributeEnd\n\
                Material \"diffuse\" \"rgb reflectance\" [ 1 1 1 ]\n\
                Shape \"bilinearmesh\" \"point3 P\" [ -4 0 -4  4 0 -4  -4 0 4  4 0 4 ]\n";
    let file = read_in(&dir, text, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let [LightDesc::Projector(l)] = &file.desc.lights[..] else {
        panic!("{:?}", file.desc.lights);
    };
    assert_eq!(l.intensity, Some([2.0; 3]));
    assert!(close(l.position, [0.0, 2.0, 0.0]));
    assert!(close(l.direction.unwrap(), [0.0, -1.0, 0.0]));
    assert!(close(l.up.unwrap(), [0.0, 0.0, 1.0]));
    // 40° up the image, which is twice as wide.
    let across = 2.0 * (20f64.to_radians().tan() * 2.0).atan();
    assert!((l.fov - across.to_degrees()).abs() < 1e-9, "{}", l.fov);
    let scene = file.compile(&Overrides::default()).unwrap();
    let film = lumen::render::render(&scene, &|_| {}).0;
    let mut seen = [0; 4];
    for y in 0..64 {
        for x in 0..64 {
            let ray = scene.camera.central_ray(x, y);
            let t = -ray.origin().y / ray.direction.y;
            let at = ray.origin() + t * ray.direction;
            let c = film.mean((y * 64 + x) as usize);
            // Within the lit rectangle, away from its edges and middle.
            if at.x.abs() < 0.25 || at.x.abs() > 1.2 || at.z.abs() < 0.25 || at.z.abs() > 0.5 {
                continue;
            }
            let (quarter, lit) = match (at.x < 0.0, at.z > 0.0) {
                (true, true) => (0, [true, false, false]),
                (false, true) => (1, [false, true, false]),
                (true, false) => (2, [false, false, true]),
                (false, false) => (3, [true, true, true]),
            };
            for (k, on) in lit.into_iter().enumerate() {
                assert_eq!(c[k] > 0.0, on, "({x}, {y}) at {at}: {c}");
            }
            seen[quarter] += 1;
        }
    }
    assert!(seen.iter().all(|&n| n > 15), "{seen:?}");
    exported_renders_the_same(&dir.join("s.pbrt"));
    let stretched =
        "WorldBegin\nScale 1 2 1\nLightSource \"projection\" \"string filename\" \"slide.png\"\n";
    let e = read_in(&dir, stretched, &Options::default()).unwrap_err();
    assert!(
        e.contains("s.pbrt:3:1") && e.contains("stretches or shears"),
        "{e}"
    );
}

#[test]
fn transforms_instances_and_materials_are_placed_as_pbrt_places_them() {
    let mut d = read(
        "transforms",
        r#"WorldBegin
MakeNamedMaterial "gold" "string type" "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.04
Texture "checks" "spectrum" "imagemap" "string filename" "t.png" "float uscale" 2 "float vdelta" 0.25
Texture "board" "spectrum" "checkerboard" "texture tex1" "checks" "rgb tex2" [ 0 0 1 ] "float uscale" 8 "float vscale" 4
Material "diffuse" "texture reflectance" "board"
Shape "sphere"
Material "diffuse" "texture reflectance" "checks"
AttributeBegin
  Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]
  Shape "sphere" "float radius" 2
AttributeEnd
ObjectBegin "thing"
  NamedMaterial "gold"
  Translate 1 0 0
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ]
ObjectEnd
AttributeBegin
  Rotate 90 0 0 1
  ObjectInstance "thing"
AttributeEnd
ObjectInstance "thing"
AttributeBegin
  ReverseOrientation
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ] "normal N" [ 0 0 -1  0 0 -1  0 0 -1 ]
AttributeEnd
"#,
    );
    // The checkerboard: its squares the image and blue.
    let ObjectDesc::Sphere { material, .. } = d.objects.remove(0) else {
        panic!()
    };
    let MaterialDesc::Diffuse(board) = &d.materials[&material] else {
        panic!()
    };
    let ColorDesc::Texture(board) = &board.albedo else {
        panic!()
    };
    let TextureDesc::Checkerboard {
        even,
        odd,
        uv_scale,
        uv_offset,
    } = &d.textures[board]
    else {
        panic!("{:?}", d.textures[board])
    };
    assert!(matches!(even, ColorDesc::Texture(_)));
    assert_eq!(*odd, ColorDesc::Rgb([0.0, 0.0, 1.0]));
    assert_eq!(
        (*uv_scale, *uv_offset),
        (Some([8.0, 4.0]), Some([0.0, 0.0]))
    );
    assert_eq!(d.objects.len(), 4);
    // Transform is written column by column.
    let ObjectDesc::Sphere {
        radius,
        transform,
        material,
        ..
    } = &d.objects[0]
    else {
        panic!("{:?}", d.objects[0])
    };
    assert_eq!(*radius, 2.0);
    let TransformDesc::Matrix(m) = &transform[0] else {
        panic!("{transform:?}")
    };
    assert_eq!([m[0][3], m[1][3], m[2][3]], [5.0, 6.0, 7.0]);
    // The textured diffuse, its image mapped with t up the image.
    let MaterialDesc::Diffuse(diffuse) = &d.materials[material] else {
        panic!()
    };
    let ColorDesc::Texture(t) = &diffuse.albedo else {
        panic!()
    };
    let TextureDesc::Image {
        uv_scale,
        uv_offset,
        ..
    } = &d.textures[t]
    else {
        panic!()
    };
    assert_eq!(*uv_scale, Some([2.0, 1.0]));
    assert_eq!(*uv_offset, Some([0.0, 1.0 - 1.0 - 0.25]));
    // An instance: the shape's own transform, then the instance's.
    let ObjectDesc::Triangles {
        transform,
        material,
        ..
    } = &d.objects[1]
    else {
        panic!()
    };
    assert_eq!(transform.len(), 2, "{transform:?}");
    let MaterialDesc::Conductor(gold) = &d.materials[material] else {
        panic!()
    };
    assert_eq!(gold.metal.as_deref(), Some("Au"));
    assert!(gold.alpha.is_some(), "α = √0.04");
    let ObjectDesc::Triangles { transform, .. } = &d.objects[2] else {
        panic!()
    };
    assert_eq!(transform.len(), 1, "placed where defined");
    // Reversed, with normals: the winding follows the negated normals
    // (+z), so the triangle stays counter-clockwise from +z.
    let ObjectDesc::Triangles {
        indices, normals, ..
    } = &d.objects[3]
    else {
        panic!()
    };
    assert_eq!(indices, &vec![[0, 1, 2]]);
    assert_eq!(normals.as_ref().unwrap()[0], [0.0, 0.0, 1.0]);
}

#[test]
fn lights_carry_pbrts_units() {
    let d = read(
        "lights",
        r#"WorldBegin
LightSource "point" "rgb I" [ 1 2 3 ] "float scale" 2 "point3 from" [ 0 1 0 ]
LightSource "point" "float power" 100
Translate 0 5 0
LightSource "spot" "point3 from" [ 0 0 0 ] "point3 to" [ 0 -1 0 ] "float coneangle" 40 "float conedeltaangle" 10
LightSource "distant" "point3 from" [ 0 0 0 ] "point3 to" [ 1 -1 0 ] "blackbody L" 6500 "float scale" 3
LightSource "infinite" "rgb L" [ 0.5 0.5 0.5 ] "float illuminance" 3.14159265358979
AttributeBegin
  AreaLightSource "diffuse" "blackbody L" 2700 "float scale" 4 "bool twosided" true
  Shape "sphere"
AttributeEnd
"#,
    );
    let [LightDesc::Point(a), LightDesc::Point(b), LightDesc::Spot(s), LightDesc::Directional(sun)] =
        &d.lights[..]
    else {
        panic!("{:?}", d.lights)
    };
    assert_eq!(
        (a.position, a.intensity),
        ([0.0, 1.0, 0.0], [2.0, 4.0, 6.0])
    );
    let i = 100.0 / (4.0 * std::f64::consts::PI);
    assert!(close(b.intensity, [i; 3]));
    assert!(close(s.position, [0.0, 5.0, 0.0]));
    assert_eq!((s.cutoff_angle, s.beam_width), (Some(40.0), Some(30.0)));
    assert_eq!(
        s.falloff,
        Some(lumen::light::source::SpotFalloffDesc::Smoothstep)
    );
    assert!(close(sun.direction, [1.0, -1.0, 0.0]));
    // A blackbody light has the luminance `scale` gives it.
    let y = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    assert!((y(sun.irradiance) - 3.0).abs() < 1e-9);
    let BackgroundDesc::Solid { color } = d.background else {
        panic!()
    };
    assert!(close(color, [0.5; 3]), "illuminance / π × L: {color:?}");
    let (glow, e) = glow(&d, 0);
    assert!((y(e) - 4.0).abs() < 1e-9 && e[0] > e[2], "warm: {e:?}");
    assert!(glow.two_sided);
}

/// The material of object `i` of `d`, a pbrt area light read as a
/// glowing diffuse material, and its radiance.
fn glow(d: &SceneDesc, i: usize) -> (&lumen::scene::desc::DiffuseDesc, [f64; 3]) {
    let material = match &d.objects[i] {
        ObjectDesc::Sphere { material, .. }
        | ObjectDesc::Disk { material, .. }
        | ObjectDesc::Triangles { material, .. } => material,
        other => panic!("{other:?}"),
    };
    let MaterialDesc::Diffuse(glow) = &d.materials[material] else {
        panic!("{:?}", d.materials[material])
    };
    let Some(ColorDesc::Rgb(e)) = glow.emission else {
        panic!("{:?}", glow.emission)
    };
    (glow, e)
}

/// An area light given by its `power` Φ shines with L · Φ / (sides · A ·
/// π), A the area pbrt gives each of its lights: a sphere's (in its own
/// space), a disk's, each triangle's as placed, each bilinear patch's.
#[test]
fn area_lights_given_by_their_power_shine_with_it() {
    let pi = std::f64::consts::PI;
    let d = read(
        "area_power",
        r#"WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 2 3 ] "float power" 100
  Shape "sphere" "float radius" 2
  Shape "disk" "float radius" 0.5
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "float power" 10 "bool twosided" true
  Scale 2 2 2
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  1 1 0  0 1 0 ] "integer indices" [ 0 1 2  0 2 3 ]
  Shape "bilinearmesh" "point3 P" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]
AttributeEnd
"#,
    );
    let radiance = |i: usize| glow(&d, i).1;
    let k = 100.0 / (4.0 * pi * 4.0 * pi);
    assert!(
        close(radiance(0), [k, 2.0 * k, 3.0 * k]),
        "{:?}",
        radiance(0)
    );
    let k = 100.0 / (pi * 0.25 * pi);
    assert!(
        close(radiance(1), [k, 2.0 * k, 3.0 * k]),
        "{:?}",
        radiance(1)
    );
    // Each triangle of area 2 (the square of side 2, halved), two-sided.
    let k = 10.0 / (2.0 * 2.0 * pi);
    assert!(close(radiance(2), [k; 3]), "{:?}", radiance(2));
    // The patch, of area 4, as two triangles.
    let k = 10.0 / (2.0 * 4.0 * pi);
    assert!(close(radiance(3), [k; 3]), "{:?}", radiance(3));
    // Triangles of different areas would each shine differently in pbrt:
    // refused.
    let dir = scratch_dir("pbrt_scenes_area_power");
    let e = read_in(
        &dir,
        "WorldBegin\nAreaLightSource \"diffuse\" \"float power\" 10\n\
         Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  3 3 0 ] \"integer indices\" [ 0 1 2  1 3 2 ]\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(
        e.contains("s.pbrt:3:7") && e.contains("by its power"),
        "{e}"
    );
}

#[test]
fn bad_scenes_are_refused_with_the_place_and_what_to_do() {
    let dir = scratch_dir("pbrt_scenes_bad");
    std::fs::write(dir.join("loop.pbrt"), "Include \"loop.pbrt\"\n").unwrap();
    let cases: &[(&str, &str)] = &[
        ("WorldBegin\nShap \"sphere\"\n", "s.pbrt:2:1: unknown directive `Shap`"),
        ("WorldBegin\nShap \"sphere\"\n", "did you mean `Shape`?"),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1 2 ]\n", "`radius` takes one number, got 2"),
        ("WorldBegin\nShape \"sphere\" \"integer radius\" 1\n", "expected \"float radius\""),
        ("WorldBegin\nShape \"sphere\" \"float radus\" 1\n", "did you mean `radius`?"),
        ("WorldBegin\nShape \"spere\"\n", "did you mean `sphere`?"),
        ("WorldBegin\nShape \"sphere\" \"float radius\" 1e999\n", "s.pbrt:2:31: `1e999` is not a finite number"),
        ("WorldBegin\nShape \"sphere\n", "s.pbrt:2:7: this string is not closed"),
        ("Shape \"sphere\"\n", "Shape must come after WorldBegin"),
        ("WorldBegin\nCamera \"perspective\"\n", "Camera must come before WorldBegin"),
        ("WorldBegin\nAttributeEnd\n", "AttributeEnd without an AttributeBegin"),
        ("WorldBegin\nAttributeBegin\n", "s.pbrt:2:1: this AttributeBegin is never closed"),
        ("WorldBegin\nNamedMaterial \"glod\"\n", "no material is named `glod`"),
        ("WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" \"nope\"\n", "no spectrum texture is named `nope`"),
        ("WorldBegin\nMaterial \"difuse\"\n", "did you mean `diffuse`?"),
        ("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 3 ]\n", "names point 3, but there are 3 points"),
        ("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 ] \"integer indices\" [ 0 1 2 ]\n", "not a multiple of 3"),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" \"missing.ply\"\n", "s.pbrt:2:17: file `missing.ply` not found"),
        ("Include \"loop.pbrt\"\n", "loop.pbrt: includes itself"),
        ("Include \"../outside.pbrt\"\n", "no such file"),
        ("ConcatTransform [ 1 0 0 1  0 1 0 0  0 0 1 0  0 0 0 1 ]\n", "a projective matrix"),
        ("WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-Zn-eta\"\n", "is not among lumen's conductors"),
        ("WorldBegin\nMaterial \"dielectric\" \"spectrum eta\" \"glass-BK8\"\n", "did you mean `glass-BK7`?"),
        ("WorldBegin\nShape \"disk\" \"float innerradius\" 0.5\n", "--approximate renders a polygon of 128 sides of its area instead"),
        ("WorldBegin\nShape \"cylinder\" \"float zmin\" 1 \"float zmax\" 1\n", "zmin and zmax are both 1"),
        ("WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\"\n", "file `sky.exr` not found"),
        ("WorldBegin\nCoordSysTransform \"camra\"\n", "no coordinate system `camra`"),
        ("WorldBegin\n\"float x\" 1\n", "expected a directive"),
        ("WorldBegin\nTranslate 1 2\n", "expected a number, but the file ends"),
        ("MediumInterface \"fgo\" \"\"\nWorldBegin\n", "s.pbrt:1:1: no medium is named `fgo`; no medium is defined"),
        ("MakeNamedMedium \"m\"\n", "a medium needs a \"string type\""),
        ("Camera \"orthographic\" \"float screenwindow\" [ -1 1 -1 ]\n", "s.pbrt:1:23: `screenwindow` takes 4 numbers [x0 x1 y0 y1], got 3"),
        ("Camera \"orthographic\" \"float screenwindow\" [ 0 2 -1 1 ]\nFilm \"rgb\" \"integer xresolution\" 10 \"integer yresolution\" 10\nWorldBegin\n", "s.pbrt:1:8: lumen has no `screenwindow` shifted off centre"),
        ("Scale 1 2 1\nCamera \"orthographic\"\nWorldBegin\n", "s.pbrt:2:8: the camera's transform scales x by 1 and y by 0.5"),
        ("Camera \"orthographic\" \"float lensradius\" 0.1\n", "an orthographic camera's lens"),
        ("Camera \"orthographic\" \"float fov\" 30\n", "`fov`"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogenous\"\n", "no medium kind is called `homogenous`; pbrt has homogeneous"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 1\n", "s.pbrt:1:49: `g` must lie between −0.999 and 0.999"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [1 -1 1]\n", "s.pbrt:1:49: `sigma_a` must be finite and ≥ 0"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float sigma_z\" 1\n", "did you mean `sigma_a`?"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n", "s.pbrt:2:17: the medium `m` is defined twice"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n", "needs its \"float density\" values"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 2 3]\n", "s.pbrt:1:64: the grid has 3 density values where nx × ny × nz = 2"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 0 \"float density\" [1]\n", "`nx` must be at least 1, got 0"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [-1]\n", "a density must be finite and ≥ 0"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] \"point3 p1\" [1 0 1]\n", "must lie above `p0`"),
        ("MakeNamedMedium \"m\" \"string type\" \"cloud\"\n", "--approximate renders a medium of its sigma_a and sigma_s"),
        ("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Wholemilk\"\n", "table of measured media"),
    ];
    for (text, expected) in cases {
        let message = read_in(&dir, text, &Options::default())
            .and_then(|f| {
                f.compile(&Overrides::default())
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            })
            .err()
            .unwrap_or_else(|| panic!("accepted:\n{text}"));
        assert!(
            message.contains(expected),
            "{text}\n{message}\nlacks: {expected}"
        );
    }
    // Includes outside the scene's folder only when asked.
    let inner = dir.join("inner");
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::write(dir.join("shared.pbrt"), "WorldBegin\n").unwrap();
    let outside = read_in(&inner, "Include \"../shared.pbrt\"\n", &Options::default()).unwrap_err();
    assert!(
        outside.contains("lies outside the scene's folder"),
        "{outside}"
    );
    let allowed = Options {
        allow_outside: true,
        ..Options::default()
    };
    read_in(&inner, "Include \"../shared.pbrt\"\n", &allowed).unwrap();
    // -D is for Mitsuba's parameters.
    let defined = Options {
        defines: vec![("x".into(), "1".into())],
        ..Options::default()
    };
    assert!(read_in(&dir, "WorldBegin\n", &defined)
        .unwrap_err()
        .contains("-D x"));
}

#[test]
fn approximate_renders_what_lumen_lacks_with_a_warning_each() {
    let dir = scratch_dir("pbrt_scenes_approximate");
    let options = Options {
        approximate: true,
        ..Options::default()
    };
    let file = read_in(
        &dir,
        "WorldBegin\nShape \"disk\" \"float innerradius\" 0.5\nMaterial \"hair\"\nShape \"sphere\"\n",
        &options,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.import_warnings.len(), 2, "{:?}", file.import_warnings);
    assert!(file.import_warnings[0].contains("s.pbrt:2:7: a disk with a hole"));
    assert!(file.import_warnings[1].contains("`hair` material"));
    file.compile(&Overrides::default()).unwrap();
}

#[test]
fn a_render_of_a_bad_scene_writes_nothing_and_fails() {
    let dir = scratch_dir("pbrt_scenes_cli");
    let path = dir.join("bad.pbrt");
    std::fs::write(&path, "WorldBegin\nShape \"spere\"\n").unwrap();
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
        stderr.contains("bad.pbrt:2:7") && stderr.contains("spere"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn a_light_shines_from_the_side_pbrt_gives_it_whatever_the_transform() {
    // A square facing +z (counter-clockwise seen from +z), written out or
    // in a PLY file, shines towards the camera at +z; mirrored by Scale -1
    // 1 1, it still does in pbrt; ReverseOrientation turns it away.
    let dir = scratch_dir("pbrt_scenes_sides");
    std::fs::write(
        dir.join("square.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
         -1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let shine = |before: &str, shape: &str| {
        let text = format!(
            "LookAt 0 0 3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
             Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
             Sampler \"independent\" \"integer pixelsamples\" 2\nWorldBegin\n{before}\n\
             AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\nMaterial \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n\
             {shape}\n"
        );
        let file = read_in(&dir, &text, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
        let scene = file.compile(&Overrides::default()).unwrap();
        let image = lumen::render::render(&scene, &|_| {}).0.linear();
        image.iter().map(|c| f64::from(c.x)).sum::<f64>() / image.len() as f64
    };
    let mesh = "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]";
    for shape in [mesh, "Shape \"plymesh\" \"string filename\" \"square.ply\""] {
        let brightness = |before: &str| shine(before, shape);
        assert!((brightness("") - 1.0).abs() < 1e-6, "{shape}");
        assert!((brightness("Scale -1 1 1") - 1.0).abs() < 1e-6, "{shape}");
        assert_eq!(brightness("ReverseOrientation"), 0.0, "{shape}");
        assert_eq!(
            brightness("Scale -1 1 1\nReverseOrientation"),
            0.0,
            "{shape}"
        );
    }
    // pbrt's spheres and cylinders (seen from outside, filling the view)
    // are turned inside out by ReverseOrientation and, as pbrt finds them,
    // by a transform that mirrors.
    for shape in [
        "Shape \"sphere\" \"float radius\" 2",
        "Rotate 90 1 0 0\nShape \"cylinder\" \"float radius\" 2 \"float zmin\" -2 \"float zmax\" 2",
    ] {
        let brightness = |before: &str| shine(before, shape);
        assert!((brightness("") - 1.0).abs() < 1e-6, "{shape}");
        assert_eq!(brightness("Scale -1 1 1"), 0.0, "{shape}");
        assert_eq!(brightness("ReverseOrientation"), 0.0, "{shape}");
        assert!(
            (brightness("Scale -1 1 1\nReverseOrientation") - 1.0).abs() < 1e-6,
            "{shape}"
        );
    }
}

#[test]
fn a_loop_subdivision_surface_becomes_its_limit_mesh() {
    let d = read(
        "loop",
        "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 2 \
         \"point3 P\" [ 1 0 0  -1 0 0  0 1 0  0 -1 0  0 0 1  0 0 -1 ] \
         \"integer indices\" [ 0 2 4  2 1 4  1 3 4  3 0 4  2 0 5  1 2 5  3 1 5  0 3 5 ]\n",
    );
    let ObjectDesc::Triangles {
        positions,
        indices,
        normals,
        ..
    } = &d.objects[0]
    else {
        panic!("{:?}", d.objects)
    };
    assert_eq!(indices.len(), 8 * 16);
    let normals = normals.as_ref().expect("the limit surface's normals");
    for (p, n) in positions.iter().zip(normals) {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!(r > 0.4 && r < 1.0, "{p:?}");
        assert!(p[0] * n[0] + p[1] * n[1] + p[2] * n[2] > 0.0, "outwards");
    }
}

#[test]
fn an_environment_image_is_an_equal_area_map_in_the_lights_frame() {
    let dir = scratch_dir("pbrt_scenes_sky");
    // A white square sky: a grey ball under it is as bright as its
    // albedo (a white furnace), and the sky itself is 1 wherever seen.
    exr::prelude::write_rgb_file(dir.join("sky.exr"), 4, 4, |_, _| (1.0f32, 1.0f32, 1.0f32))
        .unwrap();
    let text = "LookAt 0 0 4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
                Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24\n\
                PixelFilter \"box\"\nSampler \"independent\" \"integer pixelsamples\" 64\n\
                Integrator \"path\" \"integer maxdepth\" 20\nWorldBegin\n\
                AttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 1\nAttributeEnd\n\
                Material \"diffuse\" \"rgb reflectance\" [ 0.8 0.8 0.8 ]\nShape \"sphere\" \"float radius\" 0.6\n";
    let file = read_in(&dir, text, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let BackgroundDesc::Image { layout, frame, .. } = &file.desc.background else {
        panic!("{:?}", file.desc.background)
    };
    assert_eq!(
        *layout,
        lumen::scene::desc::EnvironmentLayoutDesc::EqualArea
    );
    let frame = frame.unwrap();
    assert!(
        close(frame[1], [0.0, 0.0, -1.0]) && close(frame[2], [0.0, 1.0, 0.0]),
        "{frame:?}"
    );
    let scene = file.compile(&Overrides::default()).unwrap();
    let image = lumen::render::render(&scene, &|_| {}).0.linear();
    assert!(
        close(image[0].as_dvec3().to_array(), [1.0; 3]),
        "{:?}",
        image[0]
    );
    let centre = image[12 * 24 + 12];
    for c in [centre.x, centre.y, centre.z] {
        assert!((c - 0.8).abs() < 0.03, "{centre:?}");
    }
    // Not square: refused when the scene is compiled.
    exr::prelude::write_rgb_file(dir.join("sky.exr"), 4, 2, |_, _| (1.0f32, 1.0f32, 1.0f32))
        .unwrap();
    let file = read_in(&dir, text, &Options::default()).unwrap();
    let message = file
        .compile(&Overrides::default())
        .err()
        .unwrap()
        .to_string();
    assert!(
        message.contains("is square; this image is 4 × 2"),
        "{message}"
    );
}

#[test]
fn a_scaled_texture_scales_what_it_shows() {
    // One bounce of light from a white sky off a textured floor: its
    // brightness is the texture's, so halving the texture halves it.
    let dir = scratch_dir("pbrt_scenes_scale");
    let image = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/khronos/TextureTransformTest/Correct.png");
    std::fs::copy(image, dir.join("t.png")).unwrap();
    let render = |texture: &str| {
        let text = format!(
            "LookAt 0 0 3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
             Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\nPixelFilter \"box\"\n\
             Sampler \"independent\" \"integer pixelsamples\" 4\nIntegrator \"path\" \"integer maxdepth\" 1\nWorldBegin\n\
             LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n\
             Texture \"image\" \"spectrum\" \"imagemap\" \"string filename\" \"t.png\"\n{texture}\n\
             Material \"diffuse\" \"texture reflectance\" \"shown\"\n\
             Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \"integer indices\" [ 0 1 2  0 2 3 ] \
             \"point2 uv\" [ 0 0  1 0  1 1  0 1 ]\n"
        );
        let file = read_in(&dir, &text, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
        let scene = file.compile(&Overrides::default()).unwrap();
        lumen::render::render(&scene, &|_| {}).0.linear()
    };
    let plain = render("Texture \"shown\" \"spectrum\" \"scale\" \"texture tex\" \"image\"");
    let half = render(
        "Texture \"shown\" \"spectrum\" \"scale\" \"texture tex\" \"image\" \"float scale\" 0.5",
    );
    // Times a float texture: a checkerboard whose one square covers the
    // floor's (u, v), 0.5 there.
    let product = render(
        "Texture \"m\" \"float\" \"checkerboard\" \"float tex1\" 0.5 \"float tex2\" 0.25\n\
         Texture \"shown\" \"spectrum\" \"scale\" \"texture tex\" \"image\" \"texture scale\" \"m\"",
    );
    // Pixels wholly on the floor (it fills the middle 14 × 14).
    let inside: Vec<usize> = (0..plain.len())
        .filter(|&i| (2..14).contains(&(i % 16)) && (2..14).contains(&(i / 16)))
        .collect();
    assert!(
        inside.iter().any(|&i| plain[i].max_element() > 0.05),
        "the floor is seen"
    );
    for i in inside {
        let (a, b, c) = (plain[i], half[i], product[i]);
        assert!(
            (b * 2.0 - a).abs().max_element() < 1e-5 * a.max_element().max(1.0),
            "{a:?} vs {b:?}"
        );
        assert!(
            (c * 2.0 - a).abs().max_element() < 1e-5 * a.max_element().max(1.0),
            "{a:?} vs {c:?}"
        );
    }
}

/// `Attribute` sets default parameters for the directives of its kind
/// until the scope it was written in ends; a directive's own parameters
/// win, and a default one does not read is not refused.
#[test]
fn attributes_set_default_parameters_within_their_scope() {
    let d = read(
        "attributes",
        "WorldBegin\nAttributeBegin\n\
         Attribute \"shape\" \"float radius\" 0.25\n\
         Attribute \"material\" \"rgb reflectance\" [ 0.1 0.2 0.3 ]\n\
         Attribute \"light\" \"rgb L\" [ 2 3 4 ]\n\
         Material \"diffuse\"\nShape \"sphere\"\nShape \"sphere\" \"float radius\" 2\n\
         Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ]\n\
         AreaLightSource \"diffuse\"\nShape \"sphere\"\n\
         AttributeEnd\nShape \"sphere\"\n",
    );
    let radius = |i: usize| match &d.objects[i] {
        ObjectDesc::Sphere { radius, .. } => *radius,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        [0, 1, 3, 4].map(radius),
        [0.25, 2.0, 0.25, 1.0],
        "{:?}",
        d.objects
    );
    let ObjectDesc::Sphere { material, .. } = &d.objects[0] else {
        unreachable!()
    };
    let MaterialDesc::Diffuse(diffuse) = &d.materials[material] else {
        panic!("{:?}", d.materials[material]);
    };
    assert_eq!(diffuse.albedo, ColorDesc::Rgb([0.1, 0.2, 0.3]));
    let (_, light) = glow(&d, 3);
    assert!(close(light, [2.0, 3.0, 4.0]), "{light:?}");

    let dir = scratch_dir("pbrt_scenes_attributes_bad");
    let e = read_in(
        &dir,
        "WorldBegin\nAttribute \"shapes\" \"float radius\" 1\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(
        e.contains("s.pbrt:2:")
            && e.contains("not `shapes`")
            && e.contains("did you mean `shape`?"),
        "{e}"
    );
}

/// A spectrum may be a file of wavelength–value pairs (pbrt's `.spd`):
/// read as the same pairs written in the scene; a malformed one is refused
/// with the file and line.
#[test]
fn spectrum_files_read_as_their_samples() {
    let dir = scratch_dir("pbrt_scenes_spd");
    let pairs = "400 0.2 500 0.6 600 0.4 700 0.3";
    std::fs::write(
        dir.join("paint.spd"),
        "# a paint\n400 0.2\n500 0.6 # peak\n600 0.4\n700 0.3\n",
    )
    .unwrap();
    let scene = |value: &str| {
        format!(
            "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" {value}\nShape \"sphere\"\n\
             AttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" {value}\nShape \"sphere\"\nAttributeEnd\n"
        )
    };
    let from_file = read_in(&dir, &scene("\"paint.spd\""), &Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .desc;
    let written = read_in(&dir, &scene(&format!("[ {pairs} ]")), &Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .desc;
    assert_eq!(from_file.materials, written.materials);
    let ObjectDesc::Sphere { material, .. } = &from_file.objects[0] else {
        panic!("{:?}", from_file.objects[0]);
    };
    let MaterialDesc::Diffuse(paint) = &from_file.materials[material] else {
        panic!("{:?}", from_file.materials[material]);
    };
    let ColorDesc::Rgb(c) = paint.albedo else {
        panic!("{:?}", paint.albedo)
    };
    assert!(c[1] > c[0] && c[1] > c[2], "green-yellow paint: {c:?}");

    for (text, says) in [
        ("400 0.2\n500\n", "pairs of a wavelength and a value"),
        (
            "400 0.2\n500 x\n",
            "paint.spd:2: `x` is not a finite number",
        ),
        ("500 0.2\n400 0.3\n", "its wavelengths must increase"),
    ] {
        std::fs::write(dir.join("paint.spd"), text).unwrap();
        let e = read_in(&dir, &scene("\"paint.spd\""), &Options::default()).unwrap_err();
        assert!(e.contains("s.pbrt:2:") && e.contains(says), "{e}");
    }
    let outside = format!("lumen-outside-{}.spd", std::process::id());
    std::fs::write(dir.parent().unwrap().join(&outside), pairs).unwrap();
    let e = read_in(
        &dir,
        &scene(&format!("\"../{outside}\"")),
        &Options::default(),
    )
    .unwrap_err();
    std::fs::remove_file(dir.parent().unwrap().join(&outside)).unwrap();
    assert!(
        e.contains("outside the scene's folder") && e.contains("--allow-outside"),
        "{e}"
    );
}

/// A three-dimensional checkerboard is lumen's checker of cubes in the
/// world, of the side the transform at its definition scales it to; one
/// moved or turned is refused (`--approximate`: not moved).
#[test]
fn three_dimensional_checkerboards_are_checkers_in_space() {
    let text = |before: &str| {
        format!(
            "WorldBegin\n{before}\nTexture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3 \
             \"rgb tex1\" [ 0.9 0.1 0.1 ] \"rgb tex2\" [ 0.1 0.1 0.9 ]\n\
             Material \"diffuse\" \"texture reflectance\" \"c\"\nShape \"sphere\"\n"
        )
    };
    for (before, side) in [("", 1.0), ("Scale 0.25 0.25 0.25", 0.25)] {
        let d = read("checker3d", &text(before));
        let ObjectDesc::Sphere { material, .. } = &d.objects[0] else {
            panic!("{:?}", d.objects[0]);
        };
        let MaterialDesc::Diffuse(diffuse) = &d.materials[material] else {
            panic!("{:?}", d.materials[material]);
        };
        let ColorDesc::Texture(name) = &diffuse.albedo else {
            panic!("{:?}", diffuse.albedo);
        };
        assert_eq!(
            d.textures[name],
            TextureDesc::Checker {
                scale: side,
                even: ColorDesc::Rgb([0.9, 0.1, 0.1]),
                odd: ColorDesc::Rgb([0.1, 0.1, 0.9]),
            }
        );
    }
    let dir = scratch_dir("pbrt_scenes_checker3d_moved");
    let e = read_in(&dir, &text("Translate 0.5 0 0"), &Options::default()).unwrap_err();
    assert!(
        e.contains("s.pbrt:3:") && e.contains("moves or turns"),
        "{e}"
    );
    let e = read_in(
        &dir,
        &text("").replace("dimension\" 3", "dimension\" 4"),
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("`dimension` is 2 or 3, got 4"), "{e}");
}

/// A thin dielectric is lumen's thin sheet of its index (pbrt's takes no
/// roughness); anisotropic roughness may come from a texture on either
/// axis.
#[test]
fn thin_dielectrics_and_textured_anisotropic_roughness() {
    use lumen::scene::desc::RoughnessDesc;
    let d = read(
        "thin",
        "WorldBegin\n\
         Material \"thindielectric\" \"float eta\" 1.33\nShape \"sphere\"\n\
         Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"t.png\"\n\
         Material \"conductor\" \"float uroughness\" 0.04 \"texture vroughness\" \"t\" \
         \"bool remaproughness\" false\nShape \"sphere\"\n",
    );
    let material = |i: usize| match &d.objects[i] {
        ObjectDesc::Sphere { material, .. } => &d.materials[material],
        other => panic!("{other:?}"),
    };
    let MaterialDesc::Dielectric(sheet) = material(0) else {
        panic!("{:?}", material(0));
    };
    assert!(sheet.thin && sheet.ior == 1.33 && sheet.alpha.is_none());
    let MaterialDesc::Conductor(metal) = material(1) else {
        panic!("{:?}", material(1));
    };
    assert!(
        matches!(&metal.alpha, Some(RoughnessDesc::Each([u, v]))
            if *u == lumen::material::param::ScalarDesc::Value(0.04)
                && matches!(v, lumen::material::param::ScalarDesc::Texture(_))),
        "{:?}",
        metal.alpha
    );
    let dir = scratch_dir("pbrt_scenes_thin_refused");
    let e = read_in(
        &dir,
        "WorldBegin\nMaterial \"thindielectric\" \"float roughness\" 0.1\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("s.pbrt:2:") && e.contains("roughness"), "{e}");
}

/// `cropwindow` (fractions, rounded up to pixels as pbrt does) and
/// `pixelbounds` render a window of the image.
#[test]
fn crop_windows_render_a_part_of_the_image() {
    let film = |window: &str| {
        format!(
            "Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 50 {window}\n\
             WorldBegin\nShape \"sphere\"\n"
        )
    };
    let d = read("crop", &film("\"float cropwindow\" [0.255 0.5 0 1]"));
    assert_eq!(d.render.crop, Some([26, 0, 24, 50]));
    let d = read("bounds", &film("\"integer pixelbounds\" [10 20 5 45]"));
    assert_eq!(d.render.crop, Some([10, 5, 10, 40]));
    let dir = scratch_dir("pbrt_scenes_crop_bad");
    let e = read_in(
        &dir,
        &film("\"integer pixelbounds\" [10 120 5 45]"),
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("s.pbrt:1:") && e.contains("100x50"), "{e}");
}

/// `mix` is a mix of two named materials, the second with share `amount`
/// (a number, clamped to [0, 1] as pbrt's choice is, or a float texture);
/// an `interface` in a mix is refused where it is written.
#[test]
fn mix_materials_mix_two_named_materials() {
    use lumen::material::param::ScalarDesc;
    let d = read(
        "mix",
        "WorldBegin\n\
         MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.7 0.1 0.1]\n\
         MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \
         \"spectrum k\" \"metal-Au-k\"\n\
         Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"t.png\"\n\
         Material \"mix\" \"string materials\" [\"red\" \"gold\"] \"float amount\" 1.7\nShape \"sphere\"\n\
         Material \"mix\" \"string materials\" [\"gold\" \"red\"] \"texture amount\" \"t\"\nShape \"sphere\"\n",
    );
    let mix = |i: usize| match &d.objects[i] {
        ObjectDesc::Sphere { material, .. } => match &d.materials[material] {
            MaterialDesc::Mix(m) => m.clone(),
            other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    };
    let (a, b) = (mix(0), mix(1));
    assert_eq!(a.weight, Some(ScalarDesc::Value(1.0)));
    assert!(matches!(
        d.materials[&a.materials[0]],
        MaterialDesc::Diffuse(_)
    ));
    assert!(matches!(
        d.materials[&a.materials[1]],
        MaterialDesc::Conductor(_)
    ));
    assert_eq!(
        b.materials,
        [a.materials[1].clone(), a.materials[0].clone()]
    );
    assert!(matches!(b.weight, Some(ScalarDesc::Texture(_))), "{b:?}");

    let dir = scratch_dir("pbrt_scenes_mix_refused");
    let e = read_in(
        &dir,
        "WorldBegin\nMakeNamedMaterial \"air\" \"string type\" \"interface\"\n\
         MakeNamedMaterial \"red\" \"string type\" \"diffuse\"\n\
         Material \"mix\" \"string materials\" [\"air\" \"red\"]\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(
        e.contains("s.pbrt:4:") && e.contains("`air` is an interface"),
        "{e}"
    );
}

/// A float `checkerboard` is a checkerboard of greys, which lumen's
/// scalar parameters (a roughness here) take.
#[test]
fn float_checkerboards_are_grey_checkerboards() {
    use lumen::material::param::RoughnessDesc;
    let dir = scratch_dir("pbrt_scenes_float_checkerboard");
    let file = read_in(
        &dir,
        "WorldBegin\n\
         Texture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.1 \"float tex2\" 0.4 \
         \"float uscale\" 8 \"float vscale\" 8\n\
         Material \"conductor\" \"texture roughness\" \"r\" \"bool remaproughness\" false\n\
         Shape \"sphere\"\n",
        &Options::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let d = &file.desc;
    let ObjectDesc::Sphere { material, .. } = &d.objects[0] else {
        panic!("{:?}", d.objects[0]);
    };
    let MaterialDesc::Conductor(metal) = &d.materials[material] else {
        panic!("{:?}", d.materials[material]);
    };
    let Some(RoughnessDesc::Texture(name)) = &metal.alpha else {
        panic!("{:?}", metal.alpha);
    };
    assert_eq!(
        d.textures[name],
        TextureDesc::Checkerboard {
            even: ColorDesc::Rgb([0.1; 3]),
            odd: ColorDesc::Rgb([0.4; 3]),
            uv_scale: Some([8.0, 8.0]),
            uv_offset: Some([0.0, 0.0]),
        }
    );
    file.compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
}

/// A `mix` texture is lumen's mix texture; of constants it is their blend;
/// an amount outside [0, 1] is refused where it is written.
#[test]
fn mix_textures_blend_their_two_textures() {
    use lumen::material::param::ScalarDesc;
    let d = read(
        "mix_texture",
        "WorldBegin\n\
         Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"t.png\"\n\
         Texture \"a\" \"float\" \"imagemap\" \"string filename\" \"t.png\"\n\
         Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"t\" \"rgb tex2\" [0 0 1] \
         \"texture amount\" \"a\"\n\
         Texture \"c\" \"spectrum\" \"mix\" \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1] \
         \"float amount\" 0.25\n\
         Material \"diffuse\" \"texture reflectance\" \"m\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"c\"\nShape \"sphere\"\n",
    );
    let albedo = |i: usize| match &d.objects[i] {
        ObjectDesc::Sphere { material, .. } => match &d.materials[material] {
            MaterialDesc::Diffuse(m) => m.albedo.clone(),
            other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    };
    let ColorDesc::Texture(name) = albedo(0) else {
        panic!("{:?}", albedo(0));
    };
    let TextureDesc::Mix {
        first,
        second,
        amount,
    } = &d.textures[&name]
    else {
        panic!("{:?}", d.textures[&name]);
    };
    assert!(matches!(first, ColorDesc::Texture(_)), "{first:?}");
    assert_eq!(*second, ColorDesc::Rgb([0.0, 0.0, 1.0]));
    assert!(matches!(amount, ScalarDesc::Texture(_)), "{amount:?}");
    assert_eq!(albedo(1), ColorDesc::Rgb([0.75, 0.0, 0.25]));

    let dir = scratch_dir("pbrt_scenes_mix_texture_refused");
    let e = read_in(
        &dir,
        "WorldBegin\nTexture \"c\" \"float\" \"mix\"\n  \"float amount\" 2\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("s.pbrt:3:") && e.contains("amount"), "{e}");
}

/// A texture on a pbrt `sphere` falls where pbrt puts it: u round the
/// sphere's z from +x towards +y, the image's top row at +z. A 4 × 2 image
/// of eight pure colours is looked up at its texel centres.
#[test]
fn textures_on_spheres_fall_where_pbrt_puts_them() {
    let dir = scratch_dir("pbrt_scenes_sphere_uv");
    let colours = common::eight_colours_png(&dir.join("t.png"));
    let scene = read_in(
        &dir,
        "WorldBegin\n\
         Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"t.png\"\n\
         Material \"diffuse\" \"texture reflectance\" \"t\"\n\
         Translate 1 2 3\nShape \"sphere\"\n",
        &Options::default(),
    )
    .and_then(|f| f.compile(&Overrides::default()).map_err(|e| e.to_string()))
    .unwrap_or_else(|e| panic!("{e}"));
    common::assert_texels_round_z(&scene, lumen::math::Vec3::new(1.0, 2.0, 3.0), &colours);
}

/// An area light given by an image (`filename`) shines the image over the
/// shape's (u, v), its top row at v = 1 as pbrt looks it up, times
/// `scale`; `L` with `filename` is refused.
#[test]
fn an_image_area_light_shines_its_image() {
    use lumen::math::Vec3;
    let dir = scratch_dir("pbrt_scenes_image_area_light");
    let colours = common::eight_colours_png(&dir.join("t.png"));
    let scene = read_in(
        &dir,
        "WorldBegin\n\
         AreaLightSource \"diffuse\" \"string filename\" \"t.png\" \"float scale\" 2 \
         \"bool twosided\" true\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \
         \"integer indices\" [0 1 2 0 2 3] \"point2 uv\" [0 0 1 0 1 1 0 1]\n",
        &Options::default(),
    )
    .and_then(|f| f.compile(&Overrides::default()).map_err(|e| e.to_string()))
    .unwrap_or_else(|e| panic!("{e}"));
    for (x, y, i) in [
        (0.125, 0.75, 0),
        (0.375, 0.75, 1),
        (0.625, 0.25, 6),
        (0.875, 0.25, 7),
    ] {
        let seen = common::colour_at(&scene, Vec3::new(x, y, 1.0), -Vec3::Z);
        let want = colours[i] * 2.0;
        assert!(
            common::colours_close(seen, want),
            "({x}, {y}): {seen:?}, want {want:?}"
        );
    }
    let e = read_in(
        &dir,
        "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n  \"string filename\" \"t.png\"\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("s.pbrt:3:") && e.contains("not both"), "{e}");
}

/// An image sky given an `illuminance` is scaled as pbrt-v4 scales it: by
/// the illuminance over the sum of its texels above the horizon, each
/// luminance times cosine, times 2π over the texel count. A white map
/// sums to π/2 there (z is uniform on the equal-area sphere), so an
/// illuminance of π makes its intensity 2, times its `scale`; a map black
/// above the horizon is refused.
#[test]
fn an_image_sky_takes_its_illuminance_as_pbrt_computes_it() {
    use lumen::scene::desc::BackgroundDesc;
    let dir = scratch_dir("pbrt_scenes_sky_illuminance");
    image::RgbImage::from_pixel(32, 32, image::Rgb([255, 255, 255]))
        .save(dir.join("sky.png"))
        .unwrap();
    let file = read_in(
        &dir,
        "WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.png\" \
         \"float illuminance\" 3.14159265 \"float scale\" 1.5\n",
        &Options::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let BackgroundDesc::Image { intensity, .. } = file.desc.background else {
        panic!("{:?}", file.desc.background);
    };
    // Within 1 %: the texels the horizon crosses count whole or not at all.
    assert!((intensity - 3.0).abs() < 0.03, "{intensity}");

    image::RgbImage::from_pixel(32, 32, image::Rgb([0; 3]))
        .save(dir.join("black.png"))
        .unwrap();
    let e = read_in(
        &dir,
        "WorldBegin\nLightSource \"infinite\" \"string filename\" \"black.png\" \
         \"float illuminance\" 2\n",
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.contains("black above its horizon"), "{e}");
}

/// `MakeNamedMedium`'s homogeneous media become lumen's (σt = σa + σs
/// with pbrt's scale beside it, the albedo σs / σt, g); the outside medium
/// given before `Camera` is the camera's; `MediumInterface` puts media on
/// the materials of the shapes that follow, except where both sides are
/// the same (no boundary, in pbrt); a grid medium is refused, or with
/// `--approximate` its σs and σa fill its box.
#[test]
fn media_are_read_with_the_sides_pbrt_gives_them() {
    let d = read(
        "media",
        "MakeNamedMedium \"mist\" \"string type\" \"homogeneous\" \"float sigma_a\" 0.5\n\
         \"rgb sigma_s\" [1.5 0.5 0] \"float scale\" 2 \"float g\" 0.4\n\
         MediumInterface \"\" \"mist\"\nCamera \"perspective\"\nWorldBegin\n\
         AttributeBegin\nMediumInterface \"mist\"\nShape \"sphere\"\nAttributeEnd\n\
         Material \"interface\"\nShape \"sphere\"\n\
         Material \"dielectric\"\nMediumInterface \"mist\" \"\"\nShape \"sphere\"\n",
    );
    let m = &d.media["mist"];
    use lumen::scene::desc::FieldDesc;
    assert_eq!(m.sigma_t, FieldDesc::Color([2.0, 1.0, 0.5]));
    assert_eq!(m.albedo, FieldDesc::Color([0.75, 0.5, 0.0]));
    assert_eq!((m.scale, m.g, &m.bounds), (Some(2.0), Some(0.4), &None));
    assert_eq!(d.camera.medium.as_deref(), Some("mist"));
    let sides: Vec<(&str, Option<&str>, Option<&str>)> = d
        .objects
        .iter()
        .map(|o| {
            let ObjectDesc::Sphere { material, .. } = o else {
                panic!("{o:?}")
            };
            let m = &d.materials[material];
            let kind = match m {
                MaterialDesc::Interface(_) => "interface",
                MaterialDesc::Dielectric(_) => "dielectric",
                _ => "other",
            };
            let s = m.surface();
            (kind, s.interior, s.exterior)
        })
        .collect();
    assert_eq!(
        sides,
        [
            ("other", None, None),
            ("interface", None, Some("mist")),
            ("dielectric", Some("mist"), None),
        ]
    );
    let dir = scratch_dir("pbrt_scenes_grid_medium");
    let options = Options {
        approximate: true,
        ..Options::default()
    };
    let file = read_in(
        &dir,
        "MakeNamedMedium \"smoke\" \"string type\" \"cloud\" \"float sigma_s\" 3\n\
         \"point3 p0\" [-1 0 0] \"point3 p1\" [1 2 3]\nWorldBegin\n",
        &options,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.import_warnings.len(), 1, "{:?}", file.import_warnings);
    let b = file.desc.media["smoke"].bounds.as_ref().unwrap();
    assert_eq!((b.min, b.max), ([-1.0, 0.0, 0.0], [1.0, 2.0, 3.0]));
    file.compile(&Overrides::default()).unwrap();
}

/// A `uniformgrid` medium is its density grid, x fastest, over `p0`–`p1`
/// placed by the transform at its definition, times σa + σs (a coloured
/// sum makes RGB voxels), read as 0 beyond the outer voxels as pbrt reads
/// it: a pure absorber of density 1 in 4 × 4 × 2 voxels over the unit cube
/// lets e^(−σa · 0.875) through along z at its middle (the density rises
/// from ½ at the faces to 1 at the outer centres, a quarter in), where
/// clamped voxels would let e^(−σa) through.
#[test]
fn uniform_grid_media_are_their_densities_zero_beyond_the_grid() {
    let d = read(
        "uniformgrid",
        "Translate 0 1 0\n\
         MakeNamedMedium \"tint\" \"string type\" \"uniformgrid\" \"rgb sigma_a\" [1 2 3]\n\
         \"float sigma_s\" 0 \"integer nx\" 2 \"float density\" [0.5 1] \"point3 p0\" [0 0 -1]\n\
         WorldBegin\n",
    );
    use lumen::scene::desc::{EdgeDesc, FieldDesc, ScaleDesc, VoxelsDesc};
    let FieldDesc::Voxels(VoxelsDesc {
        voxels,
        values,
        transform,
        edge,
    }) = &d.media["tint"].sigma_t
    else {
        panic!("{:?}", d.media["tint"])
    };
    assert_eq!((voxels, edge), (&[2, 1, 1], &Some(EdgeDesc::Zero)));
    assert_eq!(values, &[0.5, 1.0, 1.5, 1.0, 2.0, 3.0]);
    assert_eq!(transform.len(), 3, "{transform:?}");
    assert_eq!(
        transform[0],
        TransformDesc::Scale(ScaleDesc::PerAxis([1.0, 1.0, 2.0]))
    );
    let (sigma_a, want_depth) = (2.0f64, 0.875f64);
    let text = format!(
        "LookAt 0.5 0.5 -2  0.5 0.5 0.5  0 1 0\n\
         Camera \"perspective\" \"float fov\" 1\n\
         Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\n\
         Sampler \"independent\" \"integer pixelsamples\" 1024\n\
         WorldBegin\n\
         MakeNamedMedium \"ink\" \"string type\" \"uniformgrid\" \"float sigma_a\" {sigma_a}\n\
         \"float sigma_s\" 0 \"integer nx\" 4 \"integer ny\" 4 \"integer nz\" 2\n\
         \"float density\" [{}]\n\
         LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
         AttributeBegin\nMediumInterface \"ink\" \"\"\nMaterial \"interface\"\n\
         Translate 0.5 0.5 0.5\nShape \"sphere\" \"float radius\" 2\nAttributeEnd\n",
        vec!["1"; 32].join(" ")
    );
    let dir = scratch_dir("pbrt_scenes_uniformgrid_render");
    let file = read_in(&dir, &text, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    // The grid is written out in lumen's TOML and read back the same.
    let toml = lumen::scene::file::export(&file.desc, Format::Toml).unwrap();
    let back = SceneFile::parse("exported.toml", toml, Format::Toml).unwrap();
    assert_eq!(back.desc, file.desc);
    let scene = file.compile(&Overrides::default()).unwrap();
    let stats = common::pixel_stats(&scene);
    let want = (-sigma_a * want_depth).exp();
    for c in 0..3 {
        let (m, se) = stats.image(c);
        assert!(
            (m - want).abs() <= common::K * se + 1e-3,
            "channel {c}: {m} ± {se} against {want}"
        );
    }
}
