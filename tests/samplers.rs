//! The samplers keep their promises: every dimension uniform, dimensions
//! and pixels unrelated, and every sampler converging to the same image.

mod common;

use common::{assert_agree, assert_pixels_agree, builtin_desc, pixel_stats, render_with_threads};
use lumen::film::Film;
use lumen::render::{render, render_samples};
use lumen::sampler::{Dim, PixelSample, PixelSampler, Sampler, SamplerKind};
use lumen::scene::Scene;

/// Every dimension a path draws, in the order a path with a light sample
/// at each bounce would draw them.
const BOUNCE_DIMS: [Dim; 6] = [
    Dim::LightChoice,
    Dim::Light,
    Dim::BsdfChoice,
    Dim::Bsdf,
    Dim::BsdfExtra,
    Dim::Roulette,
];

/// The numbers one sample draws: pixel, lens, then three bounces of every
/// bounce dimension (2-D ones give two numbers).
fn draws(sampler: &PixelSampler, index: u32) -> Vec<f32> {
    let (mut s, (dx, dy)) = sampler.start(index);
    let mut out = vec![dx + 0.5, dy + 0.5];
    out.extend(s.get_2d(Dim::Lens));
    for bounce in 0..3 {
        s.start_bounce(bounce);
        for dim in BOUNCE_DIMS {
            draw(&mut s, dim, &mut out);
        }
    }
    out
}

fn draw(s: &mut PixelSample, dim: Dim, out: &mut Vec<f32>) {
    if matches!(dim, Dim::Light | Dim::Bsdf) {
        out.extend(s.get_2d(dim));
    } else {
        out.push(s.get_1d(dim));
    }
}

/// Pearson's correlation of two equally long series.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

#[test]
fn every_dimension_is_uniform_and_unrelated_to_the_others() {
    // 4,096 pixels × 16 samples. Each dimension: a chi-square test of 32
    // equal bins (31 degrees of freedom; 61.1 is the 0.999 quantile) and a
    // mean of 1/2 within 5 standard errors of independent points (stratified
    // points only do better). Each pair of dimensions: correlation within 5
    // standard errors of 0 (1/√n).
    for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for pixel in 0..4096u64 {
            let sampler = PixelSampler::new(kind, 5, pixel, 16);
            for index in 0..16 {
                let values = draws(&sampler, index);
                columns.resize(values.len(), Vec::new());
                for (column, v) in columns.iter_mut().zip(values) {
                    assert!((0.0..1.0).contains(&v), "{kind:?}: {v} outside [0, 1)");
                    column.push(f64::from(v));
                }
            }
        }
        let n = columns[0].len() as f64;
        for (d, column) in columns.iter().enumerate() {
            let mut bins = [0u32; 32];
            for &v in column {
                bins[(v * 32.0) as usize] += 1;
            }
            let expected = n / 32.0;
            let chi2: f64 = bins
                .iter()
                .map(|&o| (f64::from(o) - expected).powi(2) / expected)
                .sum();
            assert!(chi2 < 61.1, "{kind:?}, number {d}: chi2 {chi2}, {bins:?}");
            let mean = column.iter().sum::<f64>() / n;
            assert!(
                (mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / n).sqrt(),
                "{kind:?}, number {d}: mean {mean}"
            );
        }
        for a in 0..columns.len() {
            for b in a + 1..columns.len() {
                let r = correlation(&columns[a], &columns[b]);
                assert!(
                    r.abs() < 5.0 / n.sqrt(),
                    "{kind:?}: numbers {a} and {b} correlate: {r}"
                );
            }
        }
    }
}

#[test]
fn neighbouring_pixels_errors_are_unrelated() {
    // Each pixel estimates ∫∫ x·y = 1/4 over its position with 4 samples;
    // the errors of horizontal neighbours must not correlate (within 5
    // standard errors, 1/√n). A sampler that reused one scramble for every
    // pixel would make every error the same (correlation 1).
    let (width, height) = (128u64, 128u64);
    for kind in [SamplerKind::Sobol, SamplerKind::Stratified] {
        let error = |pixel: u64| {
            let sampler = PixelSampler::new(kind, 9, pixel, 4);
            let sum: f64 = (0..4)
                .map(|i| {
                    let (_, (dx, dy)) = sampler.start(i);
                    f64::from(dx + 0.5) * f64::from(dy + 0.5)
                })
                .sum();
            sum / 4.0 - 0.25
        };
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for y in 0..height {
            for x in 0..width - 1 {
                left.push(error(y * width + x));
                right.push(error(y * width + x + 1));
            }
        }
        let r = correlation(&left, &right);
        let n = left.len() as f64;
        assert!(
            r.abs() < 5.0 / n.sqrt(),
            "{kind:?}: neighbours correlate: {r}"
        );
        assert!(left.iter().any(|&e| e != 0.0), "{kind:?}: no error at all");
    }
}

#[test]
fn sobol_points_of_a_pixel_fill_every_elementary_interval() {
    // The first 2^k positions of a pixel put one sample in each cell of each
    // 2^a × 2^(k−a) grid, whatever the pixel and seed.
    for pixel in [0u64, 1, 77, 123_456] {
        for seed in [0u64, 3] {
            let sampler = PixelSampler::new(SamplerKind::Sobol, seed, pixel, 64);
            let points: Vec<(f32, f32)> = (0..64)
                .map(|i| {
                    let (_, (dx, dy)) = sampler.start(i);
                    (dx + 0.5, dy + 0.5)
                })
                .collect();
            for k in 0..=6u32 {
                for a in 0..=k {
                    let (nx, ny) = (1u32 << a, 1u32 << (k - a));
                    let mut seen = vec![false; 1 << k];
                    for &(x, y) in &points[..1 << k] {
                        let cell =
                            (x * nx as f32) as usize * ny as usize + (y * ny as f32) as usize;
                        assert!(
                            !std::mem::replace(&mut seen[cell], true),
                            "pixel {pixel}, seed {seed}: two of the first {} samples in one {nx}×{ny} cell",
                            1 << k
                        );
                    }
                }
            }
        }
    }
}

/// A built-in scene with `kind` as its sampler.
fn scene_with(name: &str, width: u32, spp: u32, seed: u64, kind: SamplerKind) -> Scene {
    let mut desc = builtin_desc(name, width, spp, seed);
    desc.render.sampler = kind;
    Scene::from_desc(&desc).unwrap()
}

#[test]
fn every_sampler_converges_to_the_same_image() {
    // Sobol and stratified against independent sampling, pixel by pixel (5
    // standard errors from each pixel's sample variance, which over-states a
    // stratified estimate's noise) and over the image, on scenes with depth
    // of field, glass, fuzzy metal and the notes' cube bounce.
    for name in ["depth-of-field", "metal-fuzz-0.5", "bounce-cube"] {
        let reference = pixel_stats(&scene_with(name, 24, 96, 1, SamplerKind::Independent));
        for kind in [SamplerKind::Sobol, SamplerKind::Stratified] {
            let other = pixel_stats(&scene_with(name, 24, 96, 2, kind));
            let (worst, noisy) =
                assert_pixels_agree(&format!("{name} {kind:?}"), &reference, &other, 5.0);
            assert!(
                noisy > 100,
                "{name}: only {noisy} noisy pixels (worst {worst})"
            );
            for c in 0..3 {
                assert_agree(
                    &format!("{name} {kind:?} channel {c}"),
                    reference.image(c),
                    other.image(c),
                );
            }
        }
    }
}

#[test]
fn sobol_renders_are_less_noisy_than_independent_ones() {
    // The point of the sampler: on the cover's spheres the same samples give
    // less variance. Measured as (A − B)²/2 between two seeds; at 64 spp
    // Sobol's is about a third of independent sampling's, so "below two
    // thirds" can only fail if the points lose their stratification.
    let variance = |kind| {
        let films: Vec<Film> = [1, 2]
            .map(|seed| render(&scene_with("cover", 64, 64, seed, kind), &|_| {}).0)
            .into();
        lumen::bench::efficiency::variance_between(&films[0], &films[1])
    };
    let (sobol, independent) = (
        variance(SamplerKind::Sobol),
        variance(SamplerKind::Independent),
    );
    assert!(
        sobol < 0.67 * independent,
        "Sobol variance {sobol} vs independent {independent}"
    );
}

#[test]
fn sobol_renders_are_bit_identical_across_threads_and_passes() {
    // 37 samples: not a power of two, and passes that split the nets.
    let scene = scene_with("cover", 40, 37, 4, SamplerKind::Sobol);
    let (whole, stats) = render_with_threads(&scene, 1);
    for threads in [2, 3] {
        assert!(
            render_with_threads(&scene, threads).0 == whole,
            "{threads} threads"
        );
    }
    for split in [1, 16, 33] {
        let mut film = Film::new(scene.settings.width, scene.settings.height);
        let mut passes = render_samples(&scene, &mut film, 0..split, &|_| {});
        passes.add(render_samples(&scene, &mut film, split..37, &|_| {}));
        assert!(film == whole, "0..{split} then {split}..37");
        assert_eq!(passes, stats);
    }
}
