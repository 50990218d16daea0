//! Peak memory of rendering large scenes, measured on the real binary at a
//! size that keeps the test quick: the bounds docs/performance.md gives.
#![cfg(target_os = "linux")]

mod lumen_process;

use std::fmt::Write as _;
use std::path::Path;

/// Writes the JSON scene of `scripts/make_field.py`: a floor sphere and
/// `n` small spheres on a grid, each its own object.
fn write_field(path: &Path, n: usize) {
    let mut text = String::from(
        r#"{"render": {"width": 400, "samples_per_pixel": 16, "max_depth": 8},
"camera": {"vfov": 40, "lookfrom": [0, 40, 120], "lookat": [0, 0, 0]},
"materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
"matte": {"type": "diffuse", "albedo": [0.7, 0.3, 0.2]},
"metal": {"type": "metal", "albedo": [0.8, 0.8, 0.9], "fuzz": 0.1},
"glass": {"type": "dielectric", "ior": 1.5}},
"objects": [
{"type": "sphere", "center": [0, -10000, 0], "radius": 10000, "material": "floor"}"#,
    );
    let side = (n as f64).sqrt().ceil() as usize;
    let names = ["matte", "metal", "glass"];
    for i in 0..n {
        // Radii and positions of four decimals, as the script writes them.
        let r = 0.05 + 0.15 * ((i * 7919) % 1000) as f64 / 1000.0;
        let x = (i % side) as f64 * 0.5 - side as f64 * 0.25 + 0.0001 * (i % 997) as f64;
        let z = (i / side) as f64 * 0.5 - side as f64 * 0.25 + 0.0001 * (i % 991) as f64;
        write!(
            text,
            ",\n{{\"type\": \"sphere\", \"center\": [{x:.4}, {r:.4}, {z:.4}], \"radius\": {r:.4}, \"material\": \"{}\"}}",
            names[i % 3]
        )
        .unwrap();
    }
    text.push_str("\n]}\n");
    std::fs::write(path, text).unwrap();
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
