//! Every file a scene names is read only if it is a regular file, and no
//! further than it can be: a named pipe, a device or a directory is refused
//! in one line naming it and what it is (never a hang, never all the
//! machine's memory), a glTF buffer is read to its `byteLength`, and the
//! files a model names stay inside the model's folder unless the scene
//! allows otherwise.

mod common;

use common::scratch_dir;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `lumen render SCENE -o out.png` (plus `extra`) in `dir`, killing it
/// after `limit`; gives whether it succeeded, and its stderr. A run that had
/// to be killed fails the test.
fn render(dir: &Path, scene: &str, extra: &[&str], limit: Duration) -> (bool, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lumen"))
        .current_dir(dir)
        .args(["render", scene, "-o", "out.png"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            assert!(!err.contains("panicked"), "{err}");
            return (status.success(), err);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("lumen render {scene} {extra:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

const LIMIT: Duration = Duration::from_secs(60);

/// A scene of one object (TOML text) under a grey sky.
fn scene(objects: &str) -> String {
    format!(
        "[render]\nwidth = 8\nheight = 8\nsamples_per_pixel = 1\n\n\
         [materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n{objects}"
    )
}

fn mesh(file: &str, extra: &str) -> String {
    format!("[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\n{extra}")
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

/// One triangle's positions, 36 bytes.
fn triangle_bytes() -> Vec<u8> {
    [0f32, 0., -2., 1., 0., -2., 0., 1., -2.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// A glTF file of one triangle whose 36-byte buffer is the file `uri`.
fn gltf(uri: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-2],"max":[1,1,-2]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

#[test]
fn a_scene_file_that_is_a_named_pipe_is_refused_without_waiting() {
    let dir = scratch_dir("input-fifo-scene");
    mkfifo(&dir.join("scene.toml"));
    let (ok, err) = render(&dir, "scene.toml", &[], LIMIT);
    assert!(!ok);
    assert!(
        err.contains("scene.toml") && err.contains("named pipe"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

#[test]
fn named_pipes_and_devices_named_by_a_scene_are_refused_in_one_line() {
    let dir = scratch_dir("input-fifo-files");
    std::fs::write(
        dir.join("tri.obj"),
        "mtllib m.mtl\nv 0 0 -2\nv 1 0 -2\nv 0 1 -2\nf 1 2 3\n",
    )
    .unwrap();
    let cases: Vec<(&str, String, &str)> = vec![
        ("pipe.obj", mesh("pipe.obj", ""), "named pipe"),
        ("pipe.ply", mesh("pipe.ply", ""), "named pipe"),
        ("pipe.glb", mesh("pipe.glb", ""), "named pipe"),
        (
            "pipe.png",
            "[textures.p]\ntype = \"image\"\nfile = \"pipe.png\"\n\
             [materials.t]\ntype = \"diffuse\"\nalbedo = \"p\"\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -2]\nradius = 0.5\nmaterial = \"t\"\n"
                .to_string(),
            "named pipe",
        ),
        (
            "pipe.hdr",
            "[background]\ntype = \"image\"\nfile = \"pipe.hdr\"\n".to_string(),
            "named pipe",
        ),
        ("m.mtl", mesh("tri.obj", ""), "named pipe"),
        ("zero.obj", mesh("zero.obj", ""), "character device"),
        ("folder.obj", mesh("folder.obj", ""), "a directory"),
    ];
    for (file, objects, kind) in cases {
        let path = dir.join(file);
        match kind {
            "named pipe" => mkfifo(&path),
            "character device" => std::os::unix::fs::symlink("/dev/zero", &path).unwrap(),
            _ => std::fs::create_dir(&path).unwrap(),
        }
        let toml = format!("{file}.toml");
        std::fs::write(dir.join(&toml), scene(&objects)).unwrap();
        let (ok, err) = render(&dir, &toml, &[], LIMIT);
        assert!(!ok, "{file}");
        // One line says it all; the scene's line is shown below it.
        let first = err
            .lines()
            .find(|l| l.starts_with("lumen: error"))
            .unwrap_or_default();
        assert!(
            first.contains(file) && first.contains(kind),
            "{file}: {err}"
        );
        assert!(!dir.join("out.png").exists());
        if kind == "a directory" {
            std::fs::remove_dir(&path).unwrap();
        } else {
            std::fs::remove_file(&path).unwrap();
        }
    }
}

#[test]
fn a_gltf_buffer_is_read_to_its_byte_length_only() {
    let dir = scratch_dir("input-buffer-length");
    std::fs::write(dir.join("tri.gltf"), gltf("tri.bin")).unwrap();
    // 36 bytes of triangle, then 64 GiB the buffer does not declare (a
    // sparse file: it takes no disk).
    let file = std::fs::File::create(dir.join("tri.bin")).unwrap();
    std::io::Write::write_all(&mut &file, &triangle_bytes()).unwrap();
    file.set_len(64 << 30).unwrap();
    std::fs::write(dir.join("s.toml"), scene(&mesh("tri.gltf", ""))).unwrap();
    let (ok, err) = render(&dir, "s.toml", &[], Duration::from_secs(30));
    assert!(ok, "{err}");
    // And a buffer file shorter than its byteLength is refused.
    std::fs::write(dir.join("tri.bin"), &triangle_bytes()[..30]).unwrap();
    let (ok, err) = render(&dir, "s.toml", &[], LIMIT);
    assert!(!ok);
    assert!(err.contains("shorter than the 36 bytes"), "{err}");
}

#[test]
fn a_model_reads_only_files_in_its_folder_unless_allowed() {
    let root = scratch_dir("input-confined");
    let dir = root.join("model");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(root.join("outside.bin"), triangle_bytes()).unwrap();
    std::os::unix::fs::symlink(root.join("outside.bin"), dir.join("link.bin")).unwrap();
    std::fs::write(dir.join("inside.bin"), triangle_bytes()).unwrap();
    let outside_abs = root.join("outside.bin").display().to_string();
    for (name, uri) in [
        ("up", "../outside.bin"),
        ("deep", "sub/../../outside.bin"),
        ("absolute", outside_abs.as_str()),
        ("link", "link.bin"),
        ("etc", "/etc/hostname"),
    ] {
        let model = format!("{name}.gltf");
        std::fs::write(dir.join(&model), gltf(uri)).unwrap();
        let file = format!("model/{model}");
        let refused = format!("{name}.toml");
        std::fs::write(root.join(&refused), scene(&mesh(&file, ""))).unwrap();
        let (ok, err) = render(&root, &refused, &[], LIMIT);
        assert!(!ok, "{uri}");
        assert!(err.contains("outside the model's folder"), "{uri}: {err}");
        // Nothing of the file outside shows: not even its size.
        assert!(!err.contains("bytes"), "{uri}: {err}");
        if name == "etc" {
            continue;
        }
        let (ok, err) = render(&root, &refused, &["--allow-outside"], LIMIT);
        assert!(ok, "{uri} with --allow-outside: {err}");
        let allowed = format!("{name}-allowed.toml");
        let objects = mesh(&file, "allow_outside = true\n");
        std::fs::write(root.join(&allowed), scene(&objects)).unwrap();
        let (ok, err) = render(&root, &allowed, &[], LIMIT);
        assert!(ok, "{uri} with allow_outside: {err}");
    }
    // Inside, through `.` and a folder that is left again: read.
    std::fs::write(dir.join("in.gltf"), gltf("./sub/../inside.bin")).unwrap();
    std::fs::write(root.join("in.toml"), scene(&mesh("model/in.gltf", ""))).unwrap();
    let (ok, err) = render(&root, "in.toml", &[], LIMIT);
    assert!(ok, "{err}");
}

#[test]
fn an_obj_model_reads_its_mtl_and_maps_only_in_its_folder() {
    let root = scratch_dir("input-confined-obj");
    let dir = root.join("model");
    std::fs::create_dir(&dir).unwrap();
    let tri = "v 0 0 -2\nv 1 0 -2\nv 0 1 -2\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n";
    std::fs::write(root.join("up.mtl"), "newmtl a\nKd 1 0 0\n").unwrap();
    std::fs::write(dir.join("up.obj"), format!("mtllib ../up.mtl\n{tri}")).unwrap();
    image::RgbImage::new(2, 2)
        .save(root.join("up.png"))
        .unwrap();
    std::fs::write(dir.join("map.mtl"), "newmtl a\nmap_Kd ../up.png\n").unwrap();
    std::fs::write(dir.join("map.obj"), format!("mtllib map.mtl\n{tri}")).unwrap();
    for model in ["up.obj", "map.obj"] {
        let toml = format!("{model}.toml");
        std::fs::write(
            root.join(&toml),
            scene(&mesh(&format!("model/{model}"), "")),
        )
        .unwrap();
        let (ok, err) = render(&root, &toml, &[], LIMIT);
        assert!(!ok, "{model}");
        assert!(err.contains("outside the model's folder"), "{model}: {err}");
        let (ok, err) = render(&root, &toml, &["--allow-outside"], LIMIT);
        assert!(ok, "{model}: {err}");
    }
}

/// The loaders to come (and those there are) read files through
/// `lumen::input` only, which checks what a file is and bounds what is
/// read: no other source file opens a file, except those that read the
/// system's own (`/proc`), lumen's own files (checkpoints, locks, the
/// temporary of an image being written), and tests.
#[test]
fn every_input_file_is_read_through_the_input_module() {
    const OWN_FILES: &[&str] = &[
        "input.rs",
        "memory.rs",
        "lock.rs",
        "output.rs",
        "checkpoint/header.rs",
        "bench/mod.rs",
    ];
    const OPENS: &[&str] = &[
        "fs::read(",
        "fs::read_to_string(",
        "File::open(",
        "ImageReader::open(",
        "image::open(",
        "OpenOptions::new(",
    ];
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut todo = vec![src.clone()];
    let mut found = Vec::new();
    while let Some(dir) = todo.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                todo.push(path);
                continue;
            }
            let rel = path
                .strip_prefix(&src)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let is_test = rel.ends_with("tests.rs") || rel.contains("/tests/");
            if !rel.ends_with(".rs") || is_test || OWN_FILES.contains(&rel.as_str()) {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            // Unit tests at the end of a file may read what they wrote.
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            for (n, line) in code.lines().enumerate() {
                if OPENS.iter().any(|o| line.contains(o)) {
                    found.push(format!("src/{rel}:{}: {}", n + 1, line.trim()));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "read without lumen::input:\n{}",
        found.join("\n")
    );
}
