//! Scene files: export/parse round trips, the examples folder, and rendering a
//! file against rendering the built-in it came from.

use lumen::render::render;
use lumen::scene::builtin::BUILTINS;
use lumen::scene::file::{export, Format, SceneFile};
use lumen::scene::{Integrator, LightSelection, Overrides, Sampling, Scene};
use std::path::{Path, PathBuf};

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")
}

fn tiny() -> Overrides {
    Overrides {
        width: Some(24),
        samples_per_pixel: Some(2),
        ..Overrides::default()
    }
}

#[test]
fn export_parse_export_is_identical_for_every_builtin() {
    for format in [Format::Toml, Format::Json] {
        for b in BUILTINS {
            let desc = b.desc();
            let text = export(&desc, format).unwrap();
            let file = SceneFile::parse(b.name, text.clone(), format)
                .unwrap_or_else(|e| panic!("{} ({format:?}): {e}", b.name));
            assert_eq!(file.desc, desc, "{} ({format:?}) parses back", b.name);
            assert_eq!(
                export(&file.desc, format).unwrap(),
                text,
                "{} ({format:?}) exports the same text again",
                b.name
            );
        }
    }
}

#[test]
fn examples_folder_holds_the_current_export_of_every_builtin() {
    for b in BUILTINS {
        let path = examples_dir().join(format!("{}.toml", b.name));
        let on_disk =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            on_disk,
            export(&b.desc(), Format::Toml).unwrap(),
            "{} is stale: run `lumen scenes export {} -o {}`",
            path.display(),
            b.name,
            path.display()
        );
    }
}

#[test]
fn an_exported_file_renders_bit_identically_to_its_builtin() {
    for b in BUILTINS {
        let mut desc = b.desc();
        tiny().apply(&mut desc);
        let direct = Scene::from_desc(&desc).unwrap();
        let text = export(&b.desc(), Format::Toml).unwrap();
        let from_file = SceneFile::parse(b.name, text, Format::Toml)
            .unwrap()
            .compile(&tiny())
            .unwrap();
        assert_eq!(direct.settings, from_file.settings, "{}", b.name);
        let (film_a, _) = render(&direct, &|_| {});
        let (film_b, _) = render(&from_file, &|_| {});
        assert!(film_a == film_b, "{}: images differ", b.name);
    }
}

#[test]
fn every_example_file_renders() {
    let mut count = 0;
    let mut handwritten = 0;
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let path = entry.unwrap().path();
        if Format::from_extension(&path).is_none() {
            continue;
        }
        let file = SceneFile::read(&path).unwrap_or_else(|e| panic!("{e}"));
        let overrides = Overrides {
            width: Some(32),
            samples_per_pixel: Some(2),
            ..Overrides::default()
        };
        let scene = file.compile(&overrides).unwrap_or_else(|e| panic!("{e}"));
        let (film, stats) = render(&scene, &|_| {});
        assert_eq!(scene.settings.width, 32);
        assert_eq!(
            stats.samples,
            u64::from(32 * scene.settings.height * 2),
            "{}",
            path.display()
        );
        let rgb = film.to_rgb8(scene.settings.gamma);
        assert!(
            rgb.iter().any(|&v| v > 0),
            "{}: the image is all black",
            path.display()
        );
        let name = path.file_stem().unwrap().to_str().unwrap();
        if lumen::scene::builtin::find(name).is_none() {
            handwritten += 1;
        }
        count += 1;
    }
    assert!(count > BUILTINS.len(), "found {count} example files");
    assert!(handwritten >= 1, "no hand-written example");
}

#[test]
fn a_field_left_out_takes_the_builtin_default() {
    let file = SceneFile::parse("empty.toml", String::new(), Format::Toml).unwrap();
    let gradient = lumen::scene::builtin::find("gradient").unwrap().desc();
    assert_eq!(file.desc.render.width, gradient.render.width);
    assert_eq!(file.desc.render.aspect_ratio, gradient.render.aspect_ratio);
    assert_eq!(file.desc.camera, gradient.camera);
    assert_eq!(file.desc.background, gradient.background);
    let json = SceneFile::parse("empty.json", "{}".into(), Format::Json).unwrap();
    assert_eq!(json.desc, file.desc);
}

#[test]
fn toml_and_json_of_the_same_scene_agree() {
    let toml = SceneFile::read(&examples_dir().join("cover.toml")).unwrap();
    let json_text = export(&toml.desc, Format::Json).unwrap();
    let json = SceneFile::parse("cover.json", json_text, Format::Json).unwrap();
    assert_eq!(toml.desc, json.desc);
}

#[test]
fn overrides_replace_the_files_settings() {
    let text =
        "[render]\nwidth = 100\nheight = 50\nsamples_per_pixel = 7\nmax_depth = 3\nseed = 9\n";
    let file = SceneFile::parse("s.toml", text.into(), Format::Toml).unwrap();
    let own = file.compile(&Overrides::default()).unwrap();
    assert_eq!(
        (own.settings.width, own.settings.height),
        (100, 50),
        "the file's values without overrides"
    );
    assert_eq!(
        (own.settings.samples_per_pixel, own.settings.max_depth),
        (7, 3)
    );
    let o = Overrides {
        width: Some(40),
        samples_per_pixel: Some(3),
        max_depth: Some(5),
        seed: Some(11),
        sampler: Some(Sampling::Stratified),
        integrator: Some(Integrator::Bsdf),
        light_selection: Some(LightSelection::Uniform),
        noise_target: Some(0.25),
        aovs: Some(vec![lumen::aov::Aov::Normal, lumen::aov::Aov::Spp]),
        denoise: true,
        allow_outside: false,
    };
    let s = file.compile(&o).unwrap().settings;
    assert_eq!((s.width, s.height), (40, 20), "height keeps the proportion");
    assert_eq!((s.samples_per_pixel, s.max_depth, s.seed), (3, 5, 11));
    assert_eq!(
        (s.sampler, s.noise_target),
        (Sampling::Stratified, Some(0.25))
    );
    assert_eq!(
        (own.settings.integrator, s.integrator),
        (Integrator::Path, Integrator::Bsdf)
    );
    assert_eq!(
        (own.settings.light_selection, s.light_selection),
        (LightSelection::Power, LightSelection::Uniform)
    );
    assert_eq!(own.settings.aovs, []);
    // Denoising keeps the albedo, normal and variance it needs beside
    // those asked for.
    assert!(!own.settings.denoise && s.denoise);
    assert_eq!(
        s.aovs,
        [
            lumen::aov::Aov::Albedo,
            lumen::aov::Aov::Normal,
            lumen::aov::Aov::Variance,
            lumen::aov::Aov::Spp
        ]
    );
}

/// `SceneDesc` also derives serde's `Deserialize` for library users; it must
/// read every example exactly as lumen's own reader does.
#[test]
fn serde_derive_and_the_scene_reader_agree_on_every_example() {
    let mut checked = 0;
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let path = entry.unwrap().path();
        let Some(format) = Format::from_extension(&path) else {
            continue;
        };
        let ours = SceneFile::read(&path).unwrap().desc;
        let text = std::fs::read_to_string(&path).unwrap();
        let theirs: lumen::scene::SceneDesc = match format {
            Format::Toml => toml::from_str(&text).map_err(|e| e.to_string()),
            Format::Json => serde_json::from_str(&text).map_err(|e| e.to_string()),
        }
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(ours, theirs, "{}", path.display());
        checked += 1;
    }
    assert!(checked > BUILTINS.len());
}

/// The peers render `scripts/peers/spheres-scene.toml`; lumen's efficiency
/// benchmark renders `sky_spheres()`: they must be the same scene.
#[test]
fn the_peers_spheres_scene_is_the_efficiency_workload() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peers/spheres-scene.toml");
    let mut file = SceneFile::read(&path).unwrap().desc;
    let mut ours = lumen::bench::efficiency::sky_spheres();
    file.caption.clear();
    ours.caption.clear();
    ours.render.samples_per_pixel = file.render.samples_per_pixel;
    ours.render.aspect_ratio = file.render.aspect_ratio;
    assert_eq!(file, ours);
}
