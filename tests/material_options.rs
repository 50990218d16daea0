//! Options of the material kinds that scenes of other renderers need:
//! one-sided surfaces, smooth glass by the exact Fresnel equations, and a
//! plastic coloured once between base and coat.

mod common;

use common::{compile_file, furnace, pixel_stats, scratch_dir};
use lumen::material::dielectric::FresnelDesc;
use lumen::scene::desc::{DielectricDesc, MaterialDesc};

/// A quad facing away from the camera (its u × v side points away),
/// under a white sky, with `material`'s extra lines.
fn back_of_quad(name: &str, lines: &str) -> lumen::scene::Scene {
    let text = format!(
        "[render]\nwidth = 8\nheight = 8\nsamples_per_pixel = 4\nmax_depth = 3\n\n\
         [camera]\nvfov = 20\nlookfrom = [0, 0, 3]\nlookat = [0, 0, 0]\n\n\
         [background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\n\
         [materials.m]\n{lines}\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [-1, -1, 0]\nu = [0, 2, 0]\nv = [2, 0, 0]\nmaterial = \"m\"\n"
    );
    compile_file(
        &scratch_dir(&format!("material_options-{name}")),
        "s.toml",
        &text,
    )
}

#[test]
fn a_one_sided_surface_is_black_from_behind_and_lit_from_its_front() {
    for kind in [
        "type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]",
        "type = \"plastic\"\nroughness = 0.3",
        "type = \"conductor\"\nmetal = \"Au\"\nroughness = 0.2",
    ] {
        let behind = pixel_stats(&back_of_quad("one", &format!("{kind}\none_sided = true")));
        assert!(
            behind.max.iter().all(|m| *m == 0.0),
            "{kind}: {:?}",
            behind.max
        );
        let both = pixel_stats(&back_of_quad("two", kind));
        assert!(
            both.mean.iter().flatten().all(|m| *m > 0.0),
            "{kind}: a pixel of the back is black without one_sided"
        );
    }
}

#[test]
fn smooth_glass_by_the_exact_fresnel_equations_keeps_all_the_light() {
    for ior in [1.5, 2.4, 1.0 / 1.33] {
        let mut glass = DielectricDesc::new(ior);
        glass.fresnel = Some(FresnelDesc::Exact);
        let stats = pixel_stats(&furnace(MaterialDesc::Dielectric(glass), 16, 16, 32, 64));
        // Every sample carries all of it: reflection or refraction is
        // chosen by the Fresnel reflectance, and each weighs 1.
        for c in 0..3 {
            assert!(
                (stats.min[c] - 1.0).abs() < 1e-4 && (stats.max[c] - 1.0).abs() < 1e-4,
                "ior {ior}: samples from {} to {}",
                stats.min[c],
                stats.max[c]
            );
        }
    }
}

#[test]
fn exact_and_schlick_glass_differ_where_schlick_is_an_approximation() {
    // A diamond floor seen at 80° from its normal, under a sky white
    // above and black below; two segments: the reflected ray reaches the
    // bright sky, the refracted one the dark, so the image measures the
    // reflectance at 80° (0.43 by the Fresnel equations, 0.49 by
    // Schlick's approximation).
    let mean = |fresnel: &str| {
        let text = format!(
            "[render]\nwidth = 16\nheight = 16\nsamples_per_pixel = 64\nmax_depth = 2\n\
             sampler = \"independent\"\n\n\
             [camera]\nvfov = 2\nlookfrom = [0, 0.868, 4.924]\nlookat = [0, 0, 0]\n\n\
             [background]\ntype = \"gradient\"\nbottom = [0, 0, 0]\ntop = [1, 1, 1]\n\n\
             [materials.m]\ntype = \"dielectric\"\nior = 2.4\nfresnel = \"{fresnel}\"\n\n\
             [[objects]]\ntype = \"quad\"\ncorner = [-50, 0, -50]\nu = [0, 0, 100]\n\
             v = [100, 0, 0]\nmaterial = \"m\"\n"
        );
        let dir = scratch_dir(&format!("material_options-{fresnel}"));
        pixel_stats(&compile_file(&dir, "s.toml", &text)).image(0)
    };
    let (exact, schlick) = (mean("exact"), mean("schlick"));
    assert!(
        schlick.0 > exact.0 + 5.0 * (exact.1 * exact.1 + schlick.1 * schlick.1).sqrt(),
        "{exact:?} vs {schlick:?}"
    );
}

#[test]
fn a_plastic_coloured_once_is_brighter_than_one_coloured_at_every_bounce() {
    let mean = |nonlinear: bool| {
        let scene = back_of_quad(
            if nonlinear { "nonlinear" } else { "linear" },
            &format!(
                "type = \"plastic\"\nalbedo = [0.3, 0.3, 0.3]\nior = 1.9\nnonlinear = {nonlinear}"
            ),
        );
        pixel_stats(&scene).image(1)
    };
    let (linear, nonlinear) = (mean(false), mean(true));
    assert!(
        linear.0 > nonlinear.0 + 5.0 * (linear.1 + nonlinear.1),
        "{linear:?} {nonlinear:?}"
    );
}

#[test]
fn the_bumps_shadow_grazing_light_and_none_from_above_or_when_untilted() {
    use lumen::bsdf::Terminator;
    use lumen::math::Vec3;
    let up = Vec3::Z;
    let tilted = Vec3::new(0.5, 0.0, 1.0).normalize();
    let t = Terminator::new(up, tilted);
    // α² = ⅛ tan² of the tilt.
    assert!((t.alpha2 - 0.125 * 0.25).abs() < 1e-6, "{}", t.alpha2);
    let from = |deg: f32| {
        let r = deg.to_radians();
        Vec3::new(r.sin(), 0.0, r.cos())
    };
    assert!((t.factor(tilted, from(0.0)) - 1.0).abs() < 1e-6);
    let (mid, low) = (t.factor(tilted, from(60.0)), t.factor(tilted, from(85.0)));
    // Smith's G₁ for α² = 1/32: 2 / (1 + √(1 + α² tan²θ)).
    let g1 = |deg: f32| 2.0 / (1.0 + (1.0 + t.alpha2 * deg.to_radians().tan().powi(2)).sqrt());
    assert!((mid - g1(60.0)).abs() < 1e-5 && (low - g1(85.0)).abs() < 1e-5);
    assert!(1.0 > mid && mid > low && low > 0.0);
    // Below either normal: nothing.
    assert_eq!(t.factor(tilted, from(100.0)), 0.0);
    assert_eq!(t.factor(tilted, from(-80.0)), 0.0);
    // An untilted surface is not shadowed.
    assert_eq!(Terminator::new(up, up).factor(up, from(80.0)), 1.0);
}

#[test]
fn bump_shadowing_needs_a_map() {
    let dir = scratch_dir("material_options-bump");
    let message = common::scene_file_error(
        &dir,
        "[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\nbump_shadowing = true\n\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, -2]\nradius = 1\nmaterial = \"m\"\n",
    );
    assert!(
        message.contains("materials.m.bump_shadowing")
            && message.contains("normal_map or bump_map"),
        "{message}"
    );
}
