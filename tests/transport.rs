//! Light transport against analytic answers: the two attenuation forms agree,
//! white furnaces stay white, and a sphere in a uniform environment returns
//! exactly the energy its albedo says.
//!
//! Every comparison allows `K` standard errors computed from the per-pixel
//! sample variance of the render itself; seeds are fixed.

mod common;

use common::{
    assert_agree, builtin_scene, furnace, pixel_stats, FURNACE_CENTER, FURNACE_RADIUS, K,
};
use lumen::bsdf::diffuse::{Attenuation, BookDiffuse, BounceModel};
use lumen::bsdf::metal::FuzzyMetal;
use lumen::bsdf::{Bsdf, Frame, Lobe};
use lumen::math::{Color, Vec3};
use lumen::rng::Rng;
use lumen::scene::desc::{
    AttenuationDesc, BounceDesc, DielectricDesc, DiffuseDesc, MaterialDesc, MetalDesc,
};
use lumen::scene::{Sampling, Scene};

const W: u32 = 48;
const H: u32 = 32;

/// The lobe `lobe` on a flat surface facing up.
fn facing_up(lobe: Lobe) -> Bsdf {
    Bsdf::new(Frame::from_normal(Vec3::Y), Vec3::Y, lobe)
}

fn diffuse_desc(albedo: f64, bounce: BounceDesc, attenuation: AttenuationDesc) -> MaterialDesc {
    MaterialDesc::Diffuse(DiffuseDesc {
        albedo: [albedo; 3].into(),
        bounce,
        attenuation,
        ..Default::default()
    })
}

/// Fraction of the image plane covered by the furnace sphere. The default
/// camera (vfov 90°, looking down −z) sees it as a disk of radius tan α on the
/// plane at distance 1, sin α = R/d, and that plane's viewport is 2 high and
/// 2·W/H wide.
fn sphere_area_fraction() -> f64 {
    let d = -FURNACE_CENTER[2];
    let tan_alpha = (FURNACE_RADIUS / d).asin().tan();
    std::f64::consts::PI * tan_alpha * tan_alpha / (4.0 * f64::from(W) / f64::from(H))
}

#[test]
fn absorb_attenuation_has_expected_throughput_equal_to_the_albedo() {
    let n = 400_000;
    for albedo in [Color::splat(0.5), Color::new(0.8, 0.3, 0.1), Color::ZERO] {
        let m = facing_up(Lobe::Diffuse(BookDiffuse {
            albedo,
            bounce: BounceModel::Lambertian,
            attenuation: Attenuation::Absorb,
        }));
        let mut rng = Rng::new(5);
        let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
        let mut survivors = 0u32;
        for _ in 0..n {
            let t = m.sample(Vec3::Y, &mut rng).map_or(Color::ZERO, |s| s.value);
            survivors += u32::from(t != Color::ZERO);
            for c in 0..3 {
                sum[c] += f64::from(t[c]);
                sum2[c] += f64::from(t[c]) * f64::from(t[c]);
            }
        }
        for c in 0..3 {
            let mean = sum[c] / n as f64;
            let var = (sum2[c] / n as f64 - mean * mean).max(0.0);
            let se = (var / n as f64).sqrt();
            let expected = f64::from(albedo[c]);
            assert!(
                (mean - expected).abs() <= K * se,
                "albedo {albedo}, channel {c}: mean throughput {mean} ± {se}"
            );
        }
        if albedo == Color::ZERO {
            assert_eq!(survivors, 0, "a black surface absorbs everything");
        } else {
            // Survivors carry albedo / max(albedo): the brightest channel is
            // left unattenuated.
            let p = f64::from(albedo.max_element());
            let frac = f64::from(survivors) / n as f64;
            let se = (p * (1.0 - p) / n as f64).sqrt();
            assert!((frac - p).abs() <= K * se, "survival {frac} vs {p}");
        }
    }
    // The scaling form never absorbs and always multiplies by the albedo.
    let albedo = Color::new(0.8, 0.3, 0.1);
    let m = facing_up(Lobe::Diffuse(BookDiffuse::lambertian(albedo)));
    let mut rng = Rng::new(6);
    for _ in 0..1000 {
        assert_eq!(m.sample(Vec3::Y, &mut rng).unwrap().value, albedo);
    }
}

#[test]
fn scale_and_absorb_renders_converge_to_the_same_image() {
    // Independent seeds so that the two estimates are independent.
    let scale = pixel_stats(&builtin_scene("albedo-grey", W, 64, 1));
    let absorb = pixel_stats(&builtin_scene("albedo-grey-absorb", W, 64, 2));
    let (w, h) = (scale.width, scale.height);
    assert_eq!((w, h), (absorb.width, absorb.height));
    for c in 0..3 {
        assert_agree(
            &format!("image mean, channel {c}"),
            scale.image(c),
            absorb.image(c),
        );
        for ry in 0..3 {
            for rx in 0..4 {
                let xs = rx * w / 4..(rx + 1) * w / 4;
                let ys = ry * h / 3..(ry + 1) * h / 3;
                assert_agree(
                    &format!("region ({rx}, {ry}), channel {c}"),
                    scale.region(xs.clone(), ys.clone(), c),
                    absorb.region(xs, ys, c),
                );
            }
        }
    }
    // The two forms are really different estimators: absorbing gives 0-or-full
    // samples and so a larger variance.
    let var = |s: &common::PixelStats| s.var.iter().map(|v| v[0]).sum::<f64>();
    assert!(var(&absorb) > 1.5 * var(&scale));
}

/// Asserts that a furnace image has mean 1 within `K` standard errors (exactly
/// 1 when no sample differs from 1), and that the sphere was really hit.
/// With every sampler.
fn assert_white(what: &str, material: MaterialDesc, depth: u32) {
    for sampler in [Sampling::Sobol, Sampling::Independent] {
        let mut scene = furnace(material.clone(), W, H, 32, depth);
        scene.settings.sampler = sampler;
        assert_white_with(&format!("{what}, {sampler:?}"), &scene);
    }
}

fn assert_white_with(what: &str, scene: &Scene) {
    let stats = pixel_stats(scene);
    for c in 0..3 {
        let (mean, se) = stats.image(c);
        assert!(
            (mean - 1.0).abs() <= K * se,
            "{what}, channel {c}: furnace mean {mean} ± {se}, expected 1"
        );
        assert!(
            stats.max[c] <= 1.0,
            "{what}: a sample brighter than the light"
        );
    }
    let hits = stats.stats.rays as f64 / stats.stats.samples as f64 - 1.0;
    assert!(
        hits > 0.9 * sphere_area_fraction(),
        "{what}: only {hits} bounces per sample: the sphere is not in view"
    );
}

#[test]
fn white_furnace_diffuse_albedo_one_is_white() {
    // Seen from outside, a convex sphere sends every bounce that leaves its
    // surface upwards straight to the background: throughput 1·1 = 1 exactly.
    // The cube model also bounces into the sphere; such paths wander inside
    // (still with throughput 1) until they leave, so only paths cut at the
    // depth limit could darken the image, and with depth 500 there are none.
    for (bounce, depth) in [
        (BounceDesc::Lambertian, 50),
        (BounceDesc::Hemisphere, 50),
        (BounceDesc::SphereVolume, 50),
        (BounceDesc::Cube, 500),
    ] {
        for attenuation in [AttenuationDesc::Scale, AttenuationDesc::Absorb] {
            let m = diffuse_desc(1.0, bounce, attenuation);
            assert_white(&format!("{bounce:?}/{attenuation:?}"), m, depth);
        }
    }
}

#[test]
fn white_furnace_mirror_and_glass_are_white() {
    let mirror = MaterialDesc::Metal(MetalDesc {
        albedo: [1.0; 3].into(),
        fuzz: 0.0,
        ..Default::default()
    });
    assert_white("mirror", mirror, 50);
    // Glass never absorbs; light refracted into a sphere always meets the
    // inside at an angle below the critical angle, so it eventually leaves.
    for refract_only in [false, true] {
        let glass = MaterialDesc::Dielectric(DielectricDesc {
            ior: 1.5,
            refract_only,
            ..Default::default()
        });
        assert_white(&format!("glass refract_only={refract_only}"), glass, 500);
    }
}

/// P(absorbed) for fuzzy metal at incidence cosine `c`: the fuzzed direction
/// r̂ + f·u (u uniform on the unit sphere) falls below the surface when
/// c + f·(u·n) ≤ 0, and u·n is uniform on [−1, 1].
fn fuzz_absorption(c: f64, fuzz: f64) -> f64 {
    ((1.0 - c / fuzz) / 2.0).clamp(0.0, 1.0)
}

#[test]
fn fuzzy_metal_absorbs_the_analytic_fraction() {
    let n = 200_000;
    let m = facing_up(Lobe::Metal(FuzzyMetal {
        albedo: Color::ONE,
        fuzz: 0.5,
    }));
    for deg in [0.0f64, 45.0, 70.0, 85.0] {
        let th = deg.to_radians();
        let incoming = Vec3::new(th.sin() as f32, -th.cos() as f32, 0.0);
        let mut rng = Rng::new(9);
        let survived = (0..n)
            .filter(|_| m.sample(-incoming, &mut rng).is_some())
            .count();
        let p = 1.0 - fuzz_absorption(th.cos(), 0.5);
        let se = (p * (1.0 - p) / n as f64).sqrt().max(1.0 / n as f64);
        let frac = survived as f64 / n as f64;
        assert!((frac - p).abs() <= K * se, "at {deg}°: {frac} vs {p}");
    }
}

#[test]
fn white_furnace_fuzzy_metal_loses_exactly_the_absorbed_light() {
    // Not white: fuzzed rays that point below the surface are absorbed. A
    // camera ray through the image-plane point at radius ρ from the centre
    // meets the sphere at incidence cosine c = √(1 − (d·sin(atan ρ)/R)²); the
    // image mean is 1 − ∫_disk P_abs(c) dA / viewport area.
    let fuzz = 0.5;
    let d = -FURNACE_CENTER[2];
    let r = FURNACE_RADIUS;
    let rho_max = (r / d).asin().tan();
    let steps = 100_000;
    let h = rho_max / steps as f64;
    let lost: f64 = (0..steps)
        .map(|i| {
            let rho = (i as f64 + 0.5) * h;
            let b = d * rho.atan().sin() / r;
            let c = (1.0 - b * b).max(0.0).sqrt();
            fuzz_absorption(c, fuzz) * 2.0 * std::f64::consts::PI * rho * h
        })
        .sum();
    let expected = 1.0 - lost / (4.0 * f64::from(W) / f64::from(H));

    let material = MaterialDesc::Metal(MetalDesc {
        albedo: [1.0; 3].into(),
        fuzz,
        ..Default::default()
    });
    let stats = pixel_stats(&furnace(material, W, H, 64, 50));
    let (mean, se) = stats.image(0);
    assert!(
        (mean - expected).abs() <= K * se,
        "fuzzy metal furnace {mean} ± {se}, expected {expected}"
    );
    assert!(1.0 - mean > 10.0 * se, "the absorbed light is measurable");
    // Near the centre of the sphere c > fuzz: nothing is ever absorbed.
    assert_eq!(stats.pixel(W / 2, H / 2), [1.0; 3]);
}

#[test]
fn grey_sphere_in_a_white_furnace_returns_its_albedo() {
    // A camera ray that hits the convex sphere bounces once and escapes: it
    // brings back exactly the albedo, 0.5; a ray that misses brings back 1.
    // The image mean is therefore 1 − 0.5·(fraction of the image covered).
    let expected = 1.0 - 0.5 * sphere_area_fraction();
    for attenuation in [AttenuationDesc::Scale, AttenuationDesc::Absorb] {
        for bounce in [BounceDesc::Lambertian, BounceDesc::SphereVolume] {
            let m = diffuse_desc(0.5, bounce, attenuation);
            let stats = pixel_stats(&furnace(m, W, H, 32, 50));
            let what = format!("{bounce:?}/{attenuation:?}");
            for c in 0..3 {
                let (mean, se) = stats.image(c);
                assert!(
                    (mean - expected).abs() <= K * se,
                    "{what}, channel {c}: {mean} ± {se}, expected {expected}"
                );
            }
            if attenuation == AttenuationDesc::Scale {
                // Deterministic per sample: the centre sees only the sphere,
                // the corner only the background.
                assert_eq!(stats.pixel(W / 2, H / 2), [0.5; 3], "{what}");
                assert_eq!(stats.pixel(0, 0), [1.0; 3], "{what}");
            }
        }
    }
}

/// A ray leaving a convex sphere can never meet it again. The cover's
/// ground (radius 1000) alone, lit by the sky: with depth 2 every sample
/// traces its camera ray and, where the ground is hit, one bounce; any
/// segment more at depth 50 is a bounce that found the ground it left,
/// through rounding. Before bounce rays were moved off the surface by the
/// hit point's error bound, 2.5% of bounces did; now none may.
#[test]
fn bounces_do_not_hit_the_huge_ground_sphere_they_leave() {
    let mut desc = common::builtin_desc("cover", 160, 16, 3);
    desc.objects.truncate(1);
    let rays = |depth: u32| {
        let mut d = desc.clone();
        d.render.max_depth = depth;
        let scene = lumen::scene::Scene::from_desc(&d).expect("compiles");
        let stats = lumen::render::render(&scene, &|_| {}).1;
        (stats.rays, stats.samples)
    };
    let ((two, samples), (fifty, _)) = (rays(2), rays(50));
    let bounces = two - samples;
    assert!(
        bounces > samples / 2,
        "the ground is not in view: {bounces} bounces"
    );
    assert!(
        fifty - two <= bounces / 100_000,
        "{} of {bounces} bounces hit the ground again",
        fifty - two
    );
}
