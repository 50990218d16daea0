//! Sample placement within a pixel, and the depth and epsilon settings.

mod common;

use common::{assert_agree, builtin_scene, pixel_stats};
use lumen::render::render;
use lumen::sampler::{pixel_key, stratum, PixelSampler};
use lumen::scene::Sampling;

/// The offset from the pixel's centre of sample `index` of `spp` of `pixel`.
fn pixel_offset(kind: Sampling, seed: u64, pixel: u64, index: u32, spp: u32) -> (f32, f32) {
    let width = 4096;
    let at = ((pixel % width) as u32, (pixel / width) as u32);
    PixelSampler::new(kind, seed, at, width as u32, spp)
        .start(index)
        .1
}

/// Tolerance on stratum boundaries: the offset is computed in f32, so a
/// sample drawn at the very end of its cell may round onto the boundary.
const BOUNDARY: f64 = 1e-6;

#[test]
fn stratified_samples_fill_every_stratum_exactly_once() {
    for spp in [1u32, 4, 9, 16, 20, 100] {
        let k = (spp as f64).sqrt() as u32;
        for pixel in 0..2000u64 {
            let mut seen = vec![0u32; (k * k) as usize];
            for index in 0..spp {
                let key = pixel_key(1, pixel);
                let (dx, dy) = pixel_offset(Sampling::Stratified, 1, pixel, index, spp);
                assert!((-0.5..0.5).contains(&dx) && (-0.5..0.5).contains(&dy));
                if index >= k * k {
                    continue; // the samples beyond k² are uniform
                }
                let (u, v) = (f64::from(dx) + 0.5, f64::from(dy) + 0.5);
                let (cx, cy) = ((u * f64::from(k)) as u32, (v * f64::from(k)) as u32);
                let (cx, cy) = (cx.min(k - 1), cy.min(k - 1));
                // The cell the sample is in must be the one its index owns,
                // up to rounding at a cell boundary.
                let owned = stratum(index, k * k, key);
                let (ix, iy) = (owned % k, owned / k);
                let inside = |t: f64, c: u32| {
                    let lo = f64::from(c) / f64::from(k) - BOUNDARY;
                    let hi = f64::from(c + 1) / f64::from(k) + BOUNDARY;
                    (lo..hi).contains(&t)
                };
                assert!(
                    inside(u, ix) && inside(v, iy),
                    "spp {spp}, index {index}: ({dx}, {dy})"
                );
                seen[(cy * k + cx) as usize] += 1;
            }
            // Exactly one per stratum (a sample on a boundary may be counted
            // in the neighbouring cell only with probability ~1e-7).
            assert!(
                seen.iter().all(|&n| n == 1),
                "spp {spp}, pixel {pixel}: {seen:?}"
            );
        }
    }
}

#[test]
fn strata_are_permutations_and_every_prefix_is_spread_over_the_pixel() {
    for cells in [1u32, 2, 4, 9, 16, 25, 100, 1024] {
        for key in 0..50u64 {
            let key = lumen::rng::mix64(key);
            let mut seen = vec![false; cells as usize];
            for index in 0..cells {
                let c = stratum(index, cells, key);
                assert!(
                    c < cells && !seen[c as usize],
                    "cells {cells}: not a permutation"
                );
                seen[c as usize] = true;
            }
        }
    }
    // A render stopped after one sample per pixel must not be biased towards
    // a corner: over many pixels the first sample's offset has mean 0 and
    // variance 1/12 per axis (uniform over the pixel), 5 standard errors.
    let (spp, n) = (16u32, 100_000u64);
    let (mut sx, mut sy) = (0.0f64, 0.0f64);
    let mut first_cells = vec![0u64; 16];
    for pixel in 0..n {
        let key = pixel_key(9, pixel);
        let (dx, dy) = pixel_offset(Sampling::Stratified, 9, pixel, 0, spp);
        sx += f64::from(dx);
        sy += f64::from(dy);
        first_cells[stratum(0, 16, key) as usize] += 1;
    }
    let se = (1.0 / 12.0 / n as f64).sqrt();
    assert!(
        (sx / n as f64).abs() < 5.0 * se,
        "mean dx {}",
        sx / n as f64
    );
    assert!(
        (sy / n as f64).abs() < 5.0 * se,
        "mean dy {}",
        sy / n as f64
    );
    // Every cell is equally likely for the first sample: chi-square with 15
    // degrees of freedom; 44.3 is its 0.9999 quantile.
    let expected = n as f64 / 16.0;
    let chi2: f64 = first_cells
        .iter()
        .map(|&o| (o as f64 - expected).powi(2) / expected)
        .sum();
    assert!(
        chi2 < 44.3,
        "first-sample cells {first_cells:?}, chi2 {chi2}"
    );
}

#[test]
fn centre_sampling_always_hits_the_pixel_centre() {
    for index in 0..8 {
        assert_eq!(pixel_offset(Sampling::Center, 3, 7, index, 8), (0.0, 0.0));
    }
}

#[test]
fn offsets_stay_below_half_even_at_the_end_of_the_last_stratum() {
    // The largest uniform value, 1 − 2⁻²⁴, in the last cell of a 2×2 grid is
    // (1 + 0.99999994)·0.5, which rounds to 1 in f32: the offset must still be
    // below 0.5. Enough samples are drawn that this value occurs several
    // times (it has probability 2⁻²⁴ per draw).
    for sampling in [Sampling::Stratified, Sampling::Independent] {
        let mut max = f32::MIN;
        for pixel in 0..(1u64 << 24) {
            let (dx, dy) = pixel_offset(sampling, 0, pixel, 3, 4);
            max = max.max(dx).max(dy);
        }
        assert!(max < 0.5, "{sampling:?}: offset {max}");
        assert!(
            max > 0.4999,
            "{sampling:?}: the largest offsets were not reached"
        );
    }
}

#[test]
fn random_offsets_are_uniform_over_the_pixel() {
    // Mean 0 and variance 1/12 per axis; 5 standard errors.
    let n = 200_000u64;
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for i in 0..n {
        let (dx, _) = pixel_offset(Sampling::Independent, 2, i, 0, 16);
        s += f64::from(dx);
        s2 += f64::from(dx) * f64::from(dx);
    }
    let mean = s / n as f64;
    assert!(mean.abs() <= 5.0 * (1.0 / 12.0 / n as f64).sqrt());
    // Var(x²) for x uniform on [-1/2, 1/2] is 1/80 − 1/144.
    let se2 = ((1.0 / 80.0 - 1.0 / 144.0) / n as f64).sqrt();
    assert!((s2 / n as f64 - 1.0 / 12.0).abs() <= 5.0 * se2);
}

#[test]
fn max_depth_one_shows_every_surface_black() {
    // Depth 1: the camera ray is the only segment, so a ray that hits
    // anything never reaches the light. Each sample is either exactly black
    // or exactly the (plain blue) background.
    let scene = builtin_scene("diffuse-zero-bounces", 32, 16, 0);
    let background = lumen::math::Color::new(0.5, 0.7, 1.0);
    let (film, stats) = render(&scene, &|_| {});
    assert_eq!(stats.rays, stats.samples, "one segment per sample");
    let (w, h) = (film.width(), film.height());
    // The sphere at the centre and the ground at the bottom are black.
    assert_eq!(film.pixel(w / 2, h / 2), lumen::math::Color::ZERO);
    for x in 0..w {
        assert_eq!(
            film.pixel(x, h - 1),
            lumen::math::Color::ZERO,
            "ground at x = {x}"
        );
    }
    // Every pixel is a fraction of the background: the fraction of its
    // samples that missed everything.
    let mut black = 0;
    for c in film.linear() {
        let f = c.z / background.z;
        assert!((c - f * background).abs().max_element() < 1e-6, "{c}");
        black += usize::from(c == lumen::math::Color::ZERO);
    }
    assert!(black > (w * h) as usize / 4, "only {black} black pixels");
    // With one more segment the surfaces are lit.
    let mut desc = common::builtin_desc("diffuse-zero-bounces", 32, 16, 0);
    desc.render.max_depth = 2;
    let lit = render(&lumen::scene::Scene::from_desc(&desc).unwrap(), &|_| {}).0;
    assert!(lit.pixel(w / 2, h / 2).x > 0.0);
}

#[test]
fn epsilon_zero_shows_shadow_acne() {
    // With epsilon 0 bounce rays re-hit their own surface and lose half their
    // light each time: the image is darker. Independent seeds.
    let acne = pixel_stats(&builtin_scene("shadow-acne", 32, 16, 1));
    let fixed = pixel_stats(&builtin_scene("shadow-acne-fixed", 32, 16, 2));
    for c in 0..3 {
        let (a, sa) = acne.image(c);
        let (f, sf) = fixed.image(c);
        let se = (sa * sa + sf * sf).sqrt();
        assert!(
            f - a > 5.0 * se,
            "channel {c}: acne {a} ± {sa}, fixed {f} ± {sf}"
        );
    }
    // The sky is the same in both: the top rows see only the background.
    let w = acne.width;
    for c in 0..3 {
        assert_agree(
            "sky",
            acne.region(0..w, 0..2, c),
            fixed.region(0..w, 0..2, c),
        );
    }
}
