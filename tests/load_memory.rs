//! Peak memory of rendering large scenes, measured on the real binary at a
//! size that keeps the test quick: the bounds docs/performance.md gives.
#![cfg(target_os = "linux")]

mod lumen_process;

use lumen_process::write_grid;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes the JSON scene of `scripts/make_field.py`: a floor sphere and
/// `n` small spheres on a grid, each its own object. (Written as it goes:
/// a child's peak as `wait4` reports it is at least this process's peak
/// when it started the child, which must stay small.)
fn write_field(path: &Path, n: usize) {
    let mut out = BufWriter::new(File::create(path).unwrap());
    out.write_all(
        br#"{"render": {"width": 400, "samples_per_pixel": 16, "max_depth": 8},
"camera": {"vfov": 40, "lookfrom": [0, 40, 120], "lookat": [0, 0, 0]},
"materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
"matte": {"type": "diffuse", "albedo": [0.7, 0.3, 0.2]},
"metal": {"type": "metal", "albedo": [0.8, 0.8, 0.9], "fuzz": 0.1},
"glass": {"type": "dielectric", "ior": 1.5}},
"objects": [
{"type": "sphere", "center": [0, -10000, 0], "radius": 10000, "material": "floor"}"#,
    )
    .unwrap();
    let side = (n as f64).sqrt().ceil() as usize;
    let names = ["matte", "metal", "glass"];
    for i in 0..n {
        // Radii and positions of four decimals, as the script writes them.
        let r = 0.05 + 0.15 * ((i * 7919) % 1000) as f64 / 1000.0;
        let x = (i % side) as f64 * 0.5 - side as f64 * 0.25 + 0.0001 * (i % 997) as f64;
        let z = (i / side) as f64 * 0.5 - side as f64 * 0.25 + 0.0001 * (i % 991) as f64;
        write!(
            out,
            ",\n{{\"type\": \"sphere\", \"center\": [{x:.4}, {r:.4}, {z:.4}], \"radius\": {r:.4}, \"material\": \"{}\"}}",
            names[i % 3]
        )
        .unwrap();
    }
    out.write_all(b"\n]}\n").unwrap();
    out.flush().unwrap();
}

#[test]
fn a_field_of_spheres_renders_in_under_700_bytes_a_sphere() {
    let dir = lumen_process::temp_dir("load-memory-field");
    let n = 200_000;
    let scene = dir.join("field.json");
    write_field(&scene, n);
    let file_mb = std::fs::metadata(&scene).unwrap().len() as f64 / (1024.0 * 1024.0);
    let mut cmd = lumen_process::lumen();
    cmd.arg("render")
        .arg(&scene)
        .args(["--spp", "1", "--width", "16", "-o"])
        .arg(dir.join("field.png"));
    let (out, peak_mb) = lumen_process::output_and_peak_mb(cmd);
    assert!(out.status.success(), "{}", lumen_process::stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
    let per_sphere = peak_mb * 1024.0 * 1024.0 / n as f64;
    eprintln!("{n} spheres ({file_mb:.1} MB of JSON): peak {peak_mb:.1} MB, {per_sphere:.0} bytes a sphere");
    assert!(
        peak_mb > file_mb,
        "peak {peak_mb:.1} MB is below the file's own size: not measured"
    );
    // The file's text (about 100 bytes a sphere), its description (150),
    // the compiled scene with the build's temporaries (250) and the
    // render's identity (the description as JSON again, 100).
    assert!(
        per_sphere < 700.0,
        "peak {peak_mb:.1} MB, {per_sphere:.0} bytes a sphere"
    );
}

/// Peak memory in MB of rendering `scene` (a file, or a built-in scene's
/// name) at 16 pixels wide and 1 spp, and its stderr.
fn render_peak_mb(scene: &std::ffi::OsStr, out: &Path) -> f64 {
    let mut cmd = lumen_process::lumen();
    cmd.arg("render")
        .arg(scene)
        .args(["--spp", "1", "--width", "16", "-o"])
        .arg(out);
    let (output, peak_mb) = lumen_process::output_and_peak_mb(cmd);
    assert!(
        output.status.success(),
        "{}",
        lumen_process::stderr(&output)
    );
    peak_mb
}

/// Bytes a triangle at the peak of loading the mesh of `scene` (beyond the
/// peak of a scene with nothing to load) and building its tree.
fn bytes_per_triangle(dir: &Path, scene: &Path, triangles: usize) -> f64 {
    let base = render_peak_mb("gradient".as_ref(), &dir.join("base.png"));
    let peak = render_peak_mb(scene.as_os_str(), &dir.join("mesh.png"));
    let per_triangle = (peak - base) * 1024.0 * 1024.0 / triangles as f64;
    eprintln!(
        "{}: {triangles} triangles, peak {peak:.1} MB, {base:.1} MB without them: {per_triangle:.1} bytes a triangle",
        scene.display()
    );
    per_triangle
}

#[test]
fn a_large_ply_mesh_loads_in_under_100_bytes_a_triangle() {
    let dir = lumen_process::temp_dir("load-memory-ply");
    let side = 1000;
    let scene = write_grid(&dir, side);
    let per_triangle = bytes_per_triangle(&dir, &scene, 2 * side * side);
    std::fs::remove_dir_all(&dir).unwrap();
    // The mesh (18 bytes a triangle), its tree (about 55) and, while the
    // tree is built, its binary form and the order of the triangles (13).
    assert!(
        per_triangle > 50.0,
        "{per_triangle:.1} bytes a triangle: not measured"
    );
    assert!(per_triangle < 100.0, "{per_triangle:.1} bytes a triangle");
}
