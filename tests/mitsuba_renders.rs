//! Mitsuba 3's own render regression tests, passed by lumen: each scene
//! of `assets/mitsuba-data` that lumen reads is rendered at its
//! reference's size with the budget Mitsuba's test gives (2·10⁶ samples
//! an image) and compared with Mitsuba's reference by Mitsuba's test
//! (`src/render/tests/test_renders.py`): per pixel and channel, in XYZ,
//! z = |lumen − reference| · √(spp / max(variance, 10⁻⁴)) with the
//! reference's per-sample variance; a value passes when its two-sided
//! p-value is above the Šidák-corrected level 1 − 0.99^(1/pixels), and the
//! image passes when at least 99.75 % of its values do.

mod common;

use common::read_exr_rgb;
use lumen::scene::file::{mitsuba, SceneFile};
use lumen::scene::Overrides;
use std::path::{Path, PathBuf};

/// Mitsuba's samples per image.
const SAMPLE_BUDGET: usize = 2_000_000;

/// sRGB (linear) to XYZ, as Mitsuba converts both images.
const RGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.412453, 0.357580, 0.180423],
    [0.212671, 0.715160, 0.072169],
    [0.019334, 0.119193, 0.950227],
];

fn xyz(c: [f32; 3]) -> [f64; 3] {
    RGB_TO_XYZ.map(|r| r[0] * f64::from(c[0]) + r[1] * f64::from(c[1]) + r[2] * f64::from(c[2]))
}

/// erfc(x), x ≥ 0, to a relative error below 1.2·10⁻⁷ (Chebyshev fit,
/// Numerical Recipes' `erfcc`).
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * x);
    let poly = -x * x - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    t * poly.exp()
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/mitsuba-data/tests/scenes")
}

/// The outcome of Mitsuba's test on one scene.
struct Outcome {
    /// The fraction of pixel values that pass.
    passed: f64,
    /// Samples per pixel rendered.
    spp: u32,
    /// The mean of lumen's image and the reference's, per XYZ channel.
    means: ([f64; 3], [f64; 3]),
}

/// Renders `scene` (a file of folder `dir` of the data) as Mitsuba's test
/// does and applies the test.
fn run(dir: &str, scene: &str) -> Outcome {
    let path = data().join(dir).join(scene);
    let stem = scene.rsplit_once('_').unwrap().0;
    let refs = data().join(dir).join("refs");
    let ((w, h), reference) = read_exr_rgb(&refs.join(format!("{stem}_ref_rgb.exr")));
    let (_, variance) = read_exr_rgb(&refs.join(format!("{stem}_ref_rgb_var.exr")));
    let pixels = w * h;
    let spp = (SAMPLE_BUDGET / pixels) as u32;
    let options = mitsuba::Options {
        defines: vec![("spp".into(), spp.to_string())],
        ..Default::default()
    };
    let file = SceneFile::read_with(&path, &options).unwrap_or_else(|e| panic!("{e}"));
    let scene = file
        .compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (
            scene.settings.width as usize,
            scene.settings.height as usize
        ),
        (w, h)
    );
    let (film, _) = lumen::render::render(&scene, &|_| {});
    let alpha = 1.0 - 0.99f64.powf(1.0 / pixels as f64);
    let mut good = 0usize;
    let mut sums = ([0.0; 3], [0.0; 3]);
    for i in 0..pixels {
        let c = film.mean(i);
        let ours = xyz([c.x, c.y, c.z]);
        let theirs = xyz(reference[i]);
        let var = xyz(variance[i]);
        for k in 0..3 {
            let z = (ours[k] - theirs[k]).abs() * (f64::from(spp) / var[k].max(1e-4)).sqrt();
            good += usize::from(erfc(z / std::f64::consts::SQRT_2) > alpha);
            sums.0[k] += ours[k] / pixels as f64;
            sums.1[k] += theirs[k] / pixels as f64;
        }
    }
    Outcome {
        passed: good as f64 / (3 * pixels) as f64,
        spp,
        means: sums,
    }
}

/// Mitsuba's pass mark.
const PASS: f64 = 0.9975;

fn check(dir: &str, scene: &str) {
    let o = run(dir, scene);
    eprintln!(
        "{dir}/{scene}: {:.2} % of values pass at {} spp; means {:?} vs {:?}",
        100.0 * o.passed,
        o.spp,
        o.means.0,
        o.means.1
    );
    assert!(
        o.passed >= PASS,
        "{dir}/{scene}: only {:.2} % of the values pass Mitsuba's test (needs {:.2} %)",
        100.0 * o.passed,
        100.0 * PASS
    );
}

#[test]
fn bsdf_spheres_point_light() {
    check("bsdf_spheres", "test_pointlight_path.xml");
}

#[test]
fn bsdf_spheres_area_light() {
    check("bsdf_spheres", "test_arealight_path.xml");
}

#[test]
fn bsdf_spheres_constant() {
    check("bsdf_spheres", "test_constant_path.xml");
}

#[test]
fn bsdf_spheres_envmap() {
    check("bsdf_spheres", "test_envmap_path.xml");
}

#[test]
fn bsdf_spheres_textured_diffuse() {
    check("bsdf_spheres", "test_textured_diffuse_path.xml");
}

#[test]
fn bsdf_spheres_rough_dielectric() {
    check("bsdf_spheres", "test_roughdielectric_path.xml");
}

#[test]
fn floating_sphere_directional() {
    check("floating_sphere", "test_directional_direct.xml");
}

#[test]
fn instancing() {
    check("instancing", "test_instancing_path.xml");
}

#[test]
fn bsdf_spheres_rough_plastic() {
    check("bsdf_spheres", "test_roughplastic_linear_path.xml");
    check("bsdf_spheres", "test_roughplastic_nonlinear_path.xml");
}

#[test]
fn bsdf_spheres_normal_map_rough_conductor() {
    check("bsdf_spheres", "test_normalmap_roughconductor_path.xml");
}

#[test]
fn bsdf_spheres_normal_and_bump_maps() {
    check("bsdf_spheres", "test_normalmap_path.xml");
    check("bsdf_spheres", "test_bumpmap_path.xml");
}

#[test]
fn spot_light_projecting_a_texture() {
    check("spot_light", "test_spot_direct.xml");
}

#[test]
fn bsdf_spheres_identity_normal_map_anisotropic_conductor() {
    check(
        "bsdf_spheres",
        "test_normalmap_identity_roughconductor_path.xml",
    );
}

/// Anisotropic roughness from two scalar checkerboards.
#[test]
fn bsdf_spheres_textured_rough_conductor() {
    check("bsdf_spheres", "test_textured_roughconductor_path.xml");
}

/// The surfaces of the media scenes, without media: Mitsuba's volumetric
/// path tracer on plastic under an area light and a sky.
#[test]
fn participating_media_surfaces_only() {
    check("participating_media", "test_surf_area_light_volpath.xml");
}

/// Homogeneous media of grey and coloured extinction inside spheres of
/// null, thin-glass, glass and rough-glass boundaries, lit by a sky, an
/// area light, a spot light and a light inside the medium.
#[test]
fn participating_media_homogeneous() {
    for scene in [
        "test_homo_null_envmap_volpath.xml",
        "test_homo_spectral_sigmat_volpathmis.xml",
        "test_homo_area_light_volpath.xml",
        "test_homo_emitter_inside_medium_volpath.xml",
        "test_homo_obj_inside_medium_volpath.xml",
    ] {
        check("participating_media", scene);
    }
}

/// Homogeneous media behind index-mismatched boundaries: smooth glass
/// under a sky, rough glass under a spot light.
#[test]
fn participating_media_behind_glass() {
    check(
        "participating_media",
        "test_homo_dielectric_envmap_volpath.xml",
    );
    check(
        "participating_media",
        "test_homo_roughdielectric_spot_volpath.xml",
    );
}

/// Heterogeneous media: voxel grids of extinction and albedo (delta and
/// ratio tracking), and a constant coloured extinction filling only its
/// volume's box.
#[test]
fn participating_media_heterogeneous() {
    for scene in [
        "test_hetero_spectral_sigmat_no_scattering_volpath.xml",
        "test_hetero_sigmat_volpath.xml",
        "test_hetero_sigmat_albedo_volpath.xml",
        "test_hetero_spectral_sigmat_volpathmis.xml",
    ] {
        check("participating_media", scene);
    }
}

/// A bitmap under each of Mitsuba's wrap modes (repeat, mirror, clamp) and
/// both filters (bilinear, nearest), its coordinates scaled past [0, 1].
#[test]
fn texture_wrap_modes_and_filters() {
    check("texture_interp", "test_texture_interp_direct.xml");
}

/// An orthographic sensor whose transform's scale sizes its view, looking
/// obliquely at a checkerboard under a constant sky.
#[test]
fn orthographic_sensor() {
    check("orthographic_sensor", "test_orthographic_path.xml");
}

/// Projectors of an even light and of an image, seen over a wide field on
/// the plane they light.
#[test]
fn projectors() {
    check("projector", "test_projector_constant_direct.xml");
    check("projector", "test_projector_textured_direct.xml");
}

/// Every light kind in a row, as Mitsuba's particle tracer renders them
/// (the same image as its path tracer's, by which lumen renders it): area
/// lights of a colour and of an image on a rectangle and a sphere, spot
/// lights plain and projecting an image, a projector and a point light.
#[test]
fn various_emitters() {
    check("various_emitters", "test_various_emitters_ptracer.xml");
}
