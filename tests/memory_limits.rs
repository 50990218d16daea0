//! What an input makes lumen hold is counted before it is taken: past what
//! the machine has (here a limit on the address space, `ulimit -v`, which
//! makes allocations fail as a full machine would), lumen says how much was
//! needed and exits with status 1, never aborting (SIGABRT, status 134) and
//! never writing a file.

mod lumen_process;

use lumen_process::temp_dir;
use std::path::Path;
use std::process::{Command, Output};

/// Runs lumen with `args` in `dir` under an address-space limit of `kib`.
fn lumen_limited(dir: &Path, kib: u64, args: &str) -> Output {
    let script = format!("ulimit -v {kib} && exec \"$0\" {args}");
    Command::new("sh")
        .current_dir(dir)
        .args(["-c", &script, env!("CARGO_BIN_EXE_lumen")])
        .output()
        .unwrap()
}

/// Asserts a refusal for want of memory: status 1, one line saying how
/// much was needed, nothing written.
fn assert_refused_for_memory(out: &Output, dir: &Path, what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{what}: {err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("lumen: error:"))
        .unwrap_or_else(|| panic!("{what}: no error line: {err}"));
    assert!(
        line.contains(what) && line.contains("GiB of memory"),
        "{line}"
    );
    assert!(!dir.join("out.png").exists());
}

#[test]
fn a_film_past_the_memory_is_refused_not_aborted() {
    let dir = temp_dir("limits-film");
    // 8192 × 4608 with adaptive sampling: 3.7 GB, twice with a pass's copy.
    let out = lumen_limited(
        &dir,
        1_500_000,
        "render cover --width 8192 --spp 4 --noise-target 0.01 -o out.png",
    );
    assert_refused_for_memory(&out, &dir, "the 8192x4608 film");
}

#[test]
fn mesh_instances_that_multiply_are_refused_not_aborted() {
    let dir = temp_dir("limits-instances");
    let tri: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.join("tri.bin"), tri).unwrap();
    // 10⁴ nodes, each placing the triangle, placed by 10³ objects: 10⁷.
    let nodes: Vec<String> = (0..10_000)
        .map(|i| format!(r#"{{"mesh":0,"translation":[{},{},0]}}"#, i % 100, i / 100))
        .collect();
    let roots: Vec<String> = (0..10_000).map(|i| i.to_string()).collect();
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"tri.bin","byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{}],"scenes":[{{"nodes":[{}]}}],"scene":0}}"#,
        nodes.join(","),
        roots.join(",")
    );
    std::fs::write(dir.join("many.gltf"), gltf).unwrap();
    let mut scene = "[render]\nwidth = 8\nheight = 8\nsamples_per_pixel = 1\n".to_string();
    for i in 0..1000 {
        scene += &format!(
            "[[objects]]\ntype = \"mesh\"\nfile = \"many.gltf\"\ntransform = [{{ translate = [0, 0, {}] }}]\n",
            -1 - i
        );
    }
    std::fs::write(dir.join("many.toml"), scene).unwrap();
    let out = lumen_limited(&dir, 1_200_000, "render many.toml -o out.png");
    assert_refused_for_memory(&out, &dir, "meshes needs");
}

#[test]
fn a_benchmark_field_past_the_memory_is_refused_before_it_is_made() {
    let dir = temp_dir("limits-field");
    let out = lumen_limited(&dir, 1_500_000, "bench --field 10000000 --runs 1");
    assert_refused_for_memory(&out, &dir, "a field of 10000000 spheres");
}

#[test]
fn recorded_rays_past_the_memory_are_refused_before_they_are_taken() {
    // The cover at 64 spp records the most rays lumen keeps (512 MiB).
    let dir = temp_dir("limits-traversal");
    let out = lumen_limited(
        &dir,
        600_000,
        "bench --traversal --workload cover-400x225 --spp 64 --runs 1",
    );
    assert_refused_for_memory(&out, &dir, "recording the rays");
}

#[test]
fn a_tree_past_the_memory_is_refused_before_it_is_built() {
    let dir = temp_dir("limits-tree");
    // 2·10⁶ triangles: a 38 MB file, read and placed in about 120 MB; its
    // tree's build needs at least 152 MB more. Under 264 MB of address
    // space (threads and the binary take some), loading fits and the tree
    // does not: before, the build aborted half-way.
    let scene = lumen_process::write_grid(&dir, 1000);
    let out = lumen_limited(
        &dir,
        270_000,
        &format!("render {} -o out.png", scene.display()),
    );
    assert_refused_for_memory(&out, &dir, "building the tree of 2000000 shapes");
}
