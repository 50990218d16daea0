//! No input sets the depth of a recursion or the length of a walk: chains
//! of textures are bounded and refused past the bound in one line, cycles
//! are named however long (and whether a material uses them or not), nested
//! checkers of one texture cost one look each, and a glTF file whose nodes
//! form a cycle without a root says so.

mod common;

use common::{scene_file_error, scratch_dir};
use std::fmt::Write as _;
use std::sync::mpsc;
use std::time::Duration;

/// A sphere of material `m`, whose albedo is texture `t0`.
const HEAD: &str = "[materials.m]\ntype = \"diffuse\"\nalbedo = \"t0\"\n\n\
[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -2]\nradius = 0.5\nmaterial = \"m\"\n\n";

/// Textures t0 … t(n-1), each a checker whose squares are `even(i)` and
/// `odd(i)` (texture names or colours).
fn checkers(n: usize, even: impl Fn(usize) -> String, odd: impl Fn(usize) -> String) -> String {
    let mut text = String::new();
    for i in 0..n {
        writeln!(
            text,
            "[textures.t{i}]\ntype = \"checker\"\nscale = 1\neven = {}\nodd = {}",
            even(i),
            odd(i)
        )
        .unwrap();
    }
    text
}

/// Runs `f` on a thread, failing the test if it takes more than 30 s.
fn within_30s<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || tx.send(f()).unwrap());
    rx.recv_timeout(Duration::from_secs(30))
        .expect("did not finish within 30 s")
}

const GREY: &str = "[0.5, 0.5, 0.5]";

#[test]
fn a_long_chain_of_textures_is_refused_in_one_line() {
    let dir = scratch_dir("depth-chain");
    for n in [65, 3000] {
        let text = HEAD.to_string()
            + &checkers(
                n,
                |i| match i + 1 < n {
                    true => format!("\"t{}\"", i + 1),
                    false => GREY.into(),
                },
                |_| GREY.into(),
            );
        let dir = dir.clone();
        let e = within_30s(move || scene_file_error(&dir, &text));
        assert!(
            e.contains("textures referring to each other, more than the 64"),
            "{n}: {e}"
        );
    }
    // 64 is followed, and renders.
    let text = HEAD.to_string()
        + &checkers(
            64,
            |i| match i + 1 < 64 {
                true => format!("\"t{}\"", i + 1),
                false => GREY.into(),
            },
            |_| GREY.into(),
        );
    common::compile_file(&dir, "ok.toml", &text);
}

#[test]
fn cycles_are_named_however_long_and_whether_used_or_not() {
    let dir = scratch_dir("depth-cycle");
    let n = 100_000;
    let text =
        HEAD.to_string() + &checkers(n, |i| format!("\"t{}\"", (i + 1) % n), |_| GREY.into());
    let e = within_30s({
        let dir = dir.clone();
        move || scene_file_error(&dir, &text)
    });
    assert!(
        e.contains("refers to itself: t0 → t1 → t2 → t3 → … (99993 more) … → t99997 → t99998 → t99999 → t0"),
        "{e}"
    );
    assert!(e.len() < 1000, "{} bytes", e.len());
    // A cycle no material uses is refused all the same.
    let unused = "[textures.a]\ntype = \"checker\"\nscale = 1\neven = \"b\"\nodd = [0, 0, 0]\n\
                  [textures.b]\ntype = \"checker\"\nscale = 1\neven = \"a\"\nodd = [0, 0, 0]\n";
    let text = unused.to_string() + &HEAD.replace("albedo = \"t0\"", "albedo = [0.5, 0.5, 0.5]");
    let e = scene_file_error(&dir, &text);
    assert!(e.contains("refers to itself: a → b → a"), "{e}");
}

#[test]
fn nested_checkers_of_one_texture_cost_one_look_each() {
    // Each level's squares are both the level below: following both
    // references of each would take 2^60 looks.
    let dir = scratch_dir("depth-dag");
    let n = 60;
    let below = |i: usize| match i + 1 < n {
        true => format!("\"t{}\"", i + 1),
        false => GREY.into(),
    };
    let text = "[render]\nwidth = 16\nsamples_per_pixel = 2\n".to_string()
        + HEAD
        + &checkers(n, below, below);
    let scene = within_30s(move || common::compile_file(&dir, "dag.toml", &text));
    // And a hit looks the nest up level by level.
    let (film, stats) = lumen::render::render(&scene, &|_| {});
    assert_eq!(stats.samples, film.len() as u64 * 2);
    assert_eq!(stats.dropped, 0);
}

#[test]
fn gltf_nodes_in_a_cycle_without_a_root_are_named() {
    let dir = scratch_dir("depth-gltf-cycle");
    let tri: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.join("t.bin"), tri).unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"t.bin","byteLength":36}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"nodes":[{"mesh":0,"children":[1]},{"children":[2]},{"children":[0]}]}"#;
    std::fs::write(dir.join("cycle.gltf"), gltf).unwrap();
    let e = lumen::mesh::load(&dir.join("cycle.gltf")).unwrap_err();
    assert!(e.to_string().contains("node 0 is in a cycle"), "{e}");
}
