//! A checkpoint knows the mesh files its scene read: `--resume` after a
//! mesh file changed is refused naming the file; unchanged, the resumed
//! render finishes bit-identical to one never stopped.

mod common;
mod lumen_process;

use common::{bunny_obj, icosphere_obj, scratch_dir};
use lumen::checkpoint::default_path;
use lumen::progressive::{Session, StopReason};
use lumen::scene::file::SceneFile;
use lumen::scene::Overrides;
use lumen_process::run;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

const SCENE: &str = r#"[render]
width = 40
height = 30
samples_per_pixel = 16
max_depth = 5

[camera]
lookfrom = [0, 1, 3]
lookat = [0, 0, -3]

[materials.clay]
type = "diffuse"
albedo = [0.7, 0.6, 0.5]

[[objects]]
type = "quad"
corner = [-10, -1, -20]
u = [20, 0, 0]
v = [0, 0, 30]
material = "clay"

[[objects]]
type = "mesh"
file = "bunny.obj"
material = "clay"
transform = [{ scale = 0.2 }, { translate = [0, -1, -4] }]

[[objects]]
type = "mesh"
file = "meshes/ball.obj"
transform = [{ translate = [-1.5, -0.5, -3] }]

[[objects]]
type = "mesh"
file = "meshes/ball.obj"
transform = [{ translate = [1.5, -0.5, -3] }]
"#;

/// Writes, through the library, the checkpoint `lumen render SCENE -o out`
/// leaves when stopped after `passes` passes.
fn make_checkpoint(scene: &Path, out: &Path, passes: u32) {
    let file = SceneFile::read(scene).unwrap();
    let (desc, compiled) = file.resolve(&Overrides::default()).unwrap();
    let mut session = Session::with_scene(&desc, compiled).unwrap();
    let stop = AtomicBool::new(false);
    let summary = session
        .run(&stop, None, &|_| {}, &mut |_, pass| {
            if pass.number == passes {
                stop.store(true, Ordering::SeqCst);
            }
            Ok::<(), ()>(())
        })
        .unwrap();
    assert_eq!(summary.reason, StopReason::Interrupted);
    session.checkpoint().write(&default_path(out)).unwrap();
}

#[test]
fn resume_refuses_a_changed_mesh_and_finishes_an_unchanged_one_bit_identically() {
    let dir = scratch_dir("mesh-ckpt");
    std::fs::create_dir(dir.join("meshes")).unwrap();
    std::fs::copy(bunny_obj(), dir.join("bunny.obj")).unwrap();
    let ball = icosphere_obj(2, 0.5, Some(1.0));
    std::fs::write(dir.join("meshes/ball.obj"), &ball).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let args = ["render", scene.to_str().unwrap()];

    let reference_out = dir.join("reference.pfm");
    let (status, err) = run(&args, &reference_out, &[]);
    assert!(status.success(), "{err}");
    let reference = std::fs::read(&reference_out).unwrap();

    let out = dir.join("out.pfm");
    let ckpt = default_path(&out);
    make_checkpoint(&scene, &out, 2);
    let saved = std::fs::read(&ckpt).unwrap();

    let bunny = std::fs::read(dir.join("bunny.obj")).unwrap();
    let nudged = String::from_utf8(bunny.clone())
        .unwrap()
        .replacen("v 1.301895", "v 1.301896", 1);
    assert_ne!(nudged.as_bytes(), &bunny[..]);
    let cases: [(&str, Vec<u8>, Vec<u8>); 3] = [
        ("bunny.obj", nudged.into_bytes(), bunny.clone()),
        // Same geometry, other bytes: the content is what counts.
        (
            "bunny.obj",
            [&bunny[..], b"# a comment\n"].concat(),
            bunny.clone(),
        ),
        // The mesh shared by two instances.
        (
            "meshes/ball.obj",
            ball.replacen("v ", "v  ", 1).into_bytes(),
            ball.clone().into_bytes(),
        ),
    ];
    for (name, changed, original) in cases {
        std::fs::write(dir.join(name), &changed).unwrap();
        let (status, err) = run(&args, &out, &["--resume"]);
        assert_eq!(status.code(), Some(1), "{name}: {err}");
        assert!(
            err.contains(&format!("file {name} has changed"))
                || err.contains(&format!("file \"{name}\" has changed")),
            "{name}: {err}"
        );
        assert!(
            !err.contains("pass "),
            "{name}: rendered before refusing: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{name}: image written");
        assert_eq!(
            std::fs::read(&ckpt).unwrap(),
            saved,
            "{name}: checkpoint changed"
        );
        std::fs::write(dir.join(name), &original).unwrap();
    }

    let (status, err) = run(&args, &out, &["--resume"]);
    assert!(status.success(), "{err}");
    assert!(err.contains("resuming at"), "{err}");
    assert!(
        std::fs::read(&out).unwrap() == reference,
        "resumed image differs"
    );
    assert!(!ckpt.exists(), "a finished render removes its checkpoint");
    std::fs::remove_dir_all(&dir).unwrap();
}
