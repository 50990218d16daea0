//! An image named by many materials is decoded and held once: a 2048²
//! atlas (16 MB as 8-bit RGBA) that 40 MTL materials and 40 scene textures
//! name keeps the render's peak memory far below 40 copies (640 MB).
//! This file holds one test only: `RUSAGE_CHILDREN` reports the largest
//! child this test process has waited for.

#![cfg(target_os = "linux")]

mod common;
mod lumen_process;

#[test]
fn an_atlas_shared_by_many_materials_is_held_once() {
    let dir = lumen_process::temp_dir("memory-atlas");
    let atlas = image::RgbImage::from_fn(2048, 2048, |x, y| {
        image::Rgb([(x % 256) as u8, (y % 256) as u8, ((x ^ y) % 256) as u8])
    });
    atlas.save(dir.join("atlas.png")).unwrap();
    let mut mtl = String::new();
    let mut obj =
        "mtllib atlas.mtl\nv 0 0 -2\nv 1 0 -2\nv 0 1 -2\nvt 0 0\nvt 1 0\nvt 0 1\n".to_string();
    let mut scene = "[render]\nwidth = 16\nheight = 16\nsamples_per_pixel = 1\n\n\
                     [[objects]]\ntype = \"mesh\"\nfile = \"atlas.obj\"\n"
        .to_string();
    for i in 0..40 {
        mtl += &format!("newmtl m{i}\nKd 1 1 1\nmap_Kd atlas.png\n");
        obj += &format!("usemtl m{i}\nf 1/1 2/2 3/3\n");
        scene += &format!(
            "[textures.t{i}]\ntype = \"image\"\nfile = \"atlas.png\"\n\
             [materials.s{i}]\ntype = \"diffuse\"\nalbedo = \"t{i}\"\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [{}, 0, -5]\nradius = 0.4\nmaterial = \"s{i}\"\n",
            i - 20
        );
    }
    std::fs::write(dir.join("atlas.mtl"), mtl).unwrap();
    std::fs::write(dir.join("atlas.obj"), obj).unwrap();
    std::fs::write(dir.join("atlas.toml"), scene).unwrap();
    let scene = dir.join("atlas.toml");
    let (status, stderr) = lumen_process::run(
        &["render", scene.to_str().unwrap()],
        &dir.join("out.png"),
        &[],
    );
    assert!(status.success(), "{stderr}");

    let peak_mb = common::children_peak_mb();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        peak_mb > 16.0,
        "peak {peak_mb:.1} MB is below the atlas's own size: not measured"
    );
    assert!(
        peak_mb < 150.0,
        "peak memory {peak_mb:.1} MB: the atlas is held more than once"
    );
}
