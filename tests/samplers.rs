//! The samplers keep their promises: every dimension uniform, dimensions
//! and pixels unrelated, and every sampler converging to the same image.

mod common;

use common::{assert_agree, assert_pixels_agree, builtin_desc, pixel_stats, render_with_threads};
use lumen::film::Film;
use lumen::render::{render, render_samples};
use lumen::sampler::{Dim, PixelSample, PixelSampler, Sampler, SamplerKind};
use lumen::scene::Scene;

/// The width of the image the tests' pixel indices are in.
const WIDTH: u32 = 128;

/// Pixel `pixel` (row-major) of an image [`WIDTH`] wide.
fn at(pixel: u64) -> (u32, u32) {
    let w = u64::from(WIDTH);
    ((pixel % w) as u32, (pixel / w) as u32)
}

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
    for kind in [
        SamplerKind::Sobol,
        SamplerKind::ZSobol,
        SamplerKind::Independent,
    ] {
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for pixel in 0..4096u64 {
            let sampler = PixelSampler::new(kind, 5, at(pixel), WIDTH, 16);
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
            let sampler = PixelSampler::new(kind, 9, at(pixel), WIDTH, 4);
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

/// Whether `points` (2^k of them, in [0, 1)²) put one in each cell of each
/// 2^a × 2^(k−a) grid: a (0, k, 2)-net.
fn is_net(points: &[(f32, f32)]) -> bool {
    let k = points.len().trailing_zeros();
    (0..=k).all(|a| {
        let (nx, ny) = (1u32 << a, 1u32 << (k - a));
        let mut seen = vec![false; points.len()];
        points.iter().all(|&(x, y)| {
            let cell = (x * nx as f32) as usize * ny as usize + (y * ny as f32) as usize;
            !std::mem::replace(&mut seen[cell], true)
        })
    })
}

/// The positions in their pixel of samples `samples` of pixel `(x, y)`.
fn positions(sampler: &PixelSampler, samples: std::ops::Range<u32>) -> Vec<(f32, f32)> {
    samples
        .map(|i| {
            let (_, (dx, dy)) = sampler.start(i);
            (dx + 0.5, dy + 0.5)
        })
        .collect()
}

#[test]
fn sobol_points_of_a_pixel_fill_every_elementary_interval() {
    // The first 2^k positions of a pixel put one sample in each cell of each
    // 2^a × 2^(k−a) grid, whatever the pixel and seed.
    for kind in [SamplerKind::Sobol, SamplerKind::ZSobol] {
        for pixel in [0u64, 1, 77, 123_456] {
            for seed in [0u64, 3] {
                let sampler = PixelSampler::new(kind, seed, at(pixel), WIDTH, 64);
                let points = positions(&sampler, 0..64);
                for k in 0..=6u32 {
                    assert!(
                        is_net(&points[..1 << k]),
                        "{kind:?}, pixel {pixel}, seed {seed}: the first {} samples",
                        1 << k
                    );
                }
            }
        }
    }
}

#[test]
fn zsobol_squares_of_pixels_fill_every_elementary_interval_together() {
    // A 2^j × 2^j square of pixels (aligned) at 16 spp: their positions in
    // their pixels, together, are a (0, 4 + 2j, 2)-net. With `sobol` they
    // are not.
    for seed in [0u64, 5] {
        for j in 1..=3u32 {
            let side = 1 << j;
            for (sx, sy) in [(0u32, 0u32), (8, 24), (40, 16)] {
                let square = |kind| {
                    let mut points = Vec::new();
                    for y in sy..sy + side {
                        for x in sx..sx + side {
                            let sampler = PixelSampler::new(kind, seed, (x, y), 64, 16);
                            points.extend(positions(&sampler, 0..16));
                        }
                    }
                    points
                };
                assert!(
                    is_net(&square(SamplerKind::ZSobol)),
                    "seed {seed}, {side}×{side} at ({sx}, {sy})"
                );
                assert!(
                    !is_net(&square(SamplerKind::Sobol)),
                    "sobol, {side}×{side} at ({sx}, {sy})"
                );
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
        for kind in [
            SamplerKind::Sobol,
            SamplerKind::ZSobol,
            SamplerKind::Stratified,
        ] {
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
fn sobol_and_zsobol_renders_are_less_noisy_than_independent_ones() {
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
    let independent = variance(SamplerKind::Independent);
    for kind in [SamplerKind::Sobol, SamplerKind::ZSobol] {
        let v = variance(kind);
        assert!(
            v < 0.67 * independent,
            "{kind:?} variance {v} vs independent {independent}"
        );
    }
}

#[test]
fn sobol_and_zsobol_renders_are_bit_identical_across_threads_and_passes() {
    // 37 samples: not a power of two, and passes that split the nets.
    for kind in [SamplerKind::Sobol, SamplerKind::ZSobol] {
        let scene = scene_with("cover", 40, 37, 4, kind);
        let (whole, stats) = render_with_threads(&scene, 1);
        for threads in [2, 3] {
            assert!(
                render_with_threads(&scene, threads).0 == whole,
                "{kind:?}, {threads} threads"
            );
        }
        for split in [1, 16, 33] {
            let mut film = Film::new(scene.settings.width, scene.settings.height);
            let mut passes = render_samples(&scene, &mut film, 0..split, &|_| {});
            passes.add(render_samples(&scene, &mut film, split..37, &|_| {}));
            assert!(film == whole, "{kind:?}: 0..{split} then {split}..37");
            assert_eq!(passes, stats);
        }
    }
}

/// The error of each pixel of a `size`×`size` image estimating the mean of
/// f(u, v) = u·v + sin(6u)·cos(4v) over its position in the pixel with `spp`
/// samples (render seed `seed`), row-major.
fn pixel_errors(kind: SamplerKind, size: u32, spp: u32, seed: u64) -> Vec<f64> {
    let f = |u: f64, v: f64| u * v + (6.0 * u).sin() * (4.0 * v).cos();
    // ∫∫ u·v = 1/4; ∫ sin(6u) du = (1 − cos 6)/6; ∫ cos(4v) dv = sin(4)/4.
    let exact = 0.25 + (1.0 - 6f64.cos()) / 6.0 * 4f64.sin() / 4.0;
    let mut errors = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let sampler = PixelSampler::new(kind, seed, (x, y), size, spp);
            let sum: f64 = (0..spp)
                .map(|i| {
                    let (_, (dx, dy)) = sampler.start(i);
                    f(f64::from(dx) + 0.5, f64::from(dy) + 0.5)
                })
                .sum();
            errors.push(sum / f64::from(spp) - exact);
        }
    }
    errors
}

/// The correlation of each pixel's error with its right-hand and its lower
/// neighbour's in one 64×64 image at `spp` with seed `seed`.
fn neighbour_correlations(kind: SamplerKind, spp: u32, seed: u64) -> (f64, f64) {
    let size = 64usize;
    let (mut a, mut right, mut b, mut below) = (vec![], vec![], vec![], vec![]);
    let e = pixel_errors(kind, size as u32, spp, seed);
    for y in 0..size {
        for x in 0..size {
            if x + 1 < size {
                a.push(e[y * size + x]);
                right.push(e[y * size + x + 1]);
            }
            if y + 1 < size {
                b.push(e[y * size + x]);
                below.push(e[(y + 1) * size + x]);
            }
        }
    }
    (correlation(&a, &right), correlation(&b, &below))
}

/// The mean of `values` and its standard error.
fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn zsobol_neighbours_errors_cancel_alike_across_and_down() {
    // Blue noise: a pixel's error and its neighbour's are of opposite signs
    // more often than not, as much along rows as along columns; with
    // `sobol` they are unrelated. A zsobol image's pixels share their
    // scrambles, so the images (16 seeds) are the independent trials: the
    // bounds are 4 standard errors of the mean over them (measured: −0.144
    // ± 0.009 across, −0.148 ± 0.009 down). The order of each square's
    // pixels, which makes the two alike, is checked where it is made
    // (`sampler::zsobol`'s tests): without it the correlations were −0.176
    // ± 0.030 and −0.125 ± 0.021, a difference too small against the
    // spread between images to show here.
    let mut trials = [vec![], vec![], vec![], vec![]];
    for seed in 0..16 {
        let (across, down) = neighbour_correlations(SamplerKind::ZSobol, 4, seed);
        let (white_across, white_down) = neighbour_correlations(SamplerKind::Sobol, 4, seed);
        let values = [across, down, across - down, white_across + white_down];
        for (t, v) in trials.iter_mut().zip(values) {
            t.push(v);
        }
    }
    let [across, down, difference, white] = trials.map(|t| mean_and_error(&t));
    eprintln!(
        "neighbours' error correlation (mean, standard error): zsobol {across:.3?} across, \
         {down:.3?} down; sobol across + down {white:.3?}"
    );
    assert!(
        across.0 + 4.0 * across.1 < 0.0 && across.0 < -0.07,
        "zsobol across: {across:?}"
    );
    assert!(
        down.0 + 4.0 * down.1 < 0.0 && down.0 < -0.07,
        "zsobol down: {down:?}"
    );
    assert!(
        difference.0.abs() < 4.0 * difference.1,
        "zsobol anisotropic: {difference:?}"
    );
    assert!(
        white.0.abs() < 4.0 * white.1,
        "sobol's neighbours correlate: {white:?}"
    );
}

/// The radially averaged power spectrum of the pixels' errors over `seeds`
/// 64×64 images at `spp`, normalised by the errors' variance (white noise
/// is 1 at every frequency): bands of radius 0–4, 4–8, …, 28–32 cycles per
/// image.
fn error_spectrum(kind: SamplerKind, spp: u32, seeds: u64) -> Vec<f64> {
    let n = 64usize;
    let mut power = vec![0.0; n * n];
    let mut variance = 0.0;
    for seed in 0..seeds {
        let e = pixel_errors(kind, n as u32, spp, seed);
        let mean = e.iter().sum::<f64>() / e.len() as f64;
        variance += e.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / e.len() as f64;
        // The 2-D discrete Fourier transform, rows then columns.
        let twiddle = |k: usize| {
            let a = -2.0 * std::f64::consts::PI * k as f64 / n as f64;
            (a.cos(), a.sin())
        };
        let mut rows = vec![(0.0, 0.0); n * n];
        for y in 0..n {
            for k in 0..n {
                let (mut re, mut im) = (0.0, 0.0);
                for x in 0..n {
                    let (c, s) = twiddle(k * x % n);
                    re += (e[y * n + x] - mean) * c;
                    im += (e[y * n + x] - mean) * s;
                }
                rows[y * n + k] = (re, im);
            }
        }
        for kx in 0..n {
            for ky in 0..n {
                let (mut re, mut im) = (0.0, 0.0);
                for y in 0..n {
                    let (c, s) = twiddle(ky * y % n);
                    let (a, b) = rows[y * n + kx];
                    re += a * c - b * s;
                    im += a * s + b * c;
                }
                power[ky * n + kx] += (re * re + im * im) / (n * n) as f64;
            }
        }
    }
    let mut bands = [(0.0, 0usize); 8];
    for ky in 0..n {
        for kx in 0..n {
            // Frequencies from −n/2 to n/2 − 1 cycles per image.
            let f = |k: usize| {
                if k < n / 2 {
                    k as f64
                } else {
                    k as f64 - n as f64
                }
            };
            let r = f(kx).hypot(f(ky));
            if (kx, ky) != (0, 0) && r < 32.0 {
                let band = &mut bands[(r / 4.0) as usize];
                band.0 += power[ky * n + kx];
                band.1 += 1;
            }
        }
    }
    bands
        .iter()
        .map(|&(p, count)| p / count as f64 / variance)
        .collect()
}

#[test]
fn zsobol_errors_are_blue_noise() {
    // The error's power at the lowest frequencies is a fraction of white
    // noise's, and rises towards the highest; `sobol`'s is flat.
    // The smallest ring holds 44 frequencies, half of them independent (a
    // real image's spectrum is symmetric), × 8 images: white noise's
    // estimate there has a relative standard deviation of 1/√176 ≈ 0.075,
    // less in the larger rings, so 0.7–1.3 is four of them.
    let spectrum = error_spectrum(SamplerKind::ZSobol, 4, 8);
    let white = error_spectrum(SamplerKind::Sobol, 4, 8);
    eprintln!("error spectrum, zsobol: {spectrum:.3?}\nerror spectrum, sobol: {white:.3?}");
    assert!(
        spectrum[0] < 0.2 && spectrum[1] < 0.5 && spectrum[7] > 1.1,
        "zsobol: {spectrum:.3?}"
    );
    assert!(
        white.iter().all(|p| (0.7..1.3).contains(p)),
        "sobol: {white:.3?}"
    );
}

#[test]
fn zsobol_pixels_have_sobols_variance() {
    // The same kind of net in every pixel, so the same error per pixel on
    // average over renders: the mean squared error over 1,024 images of
    // 8 × 8 pixels at 4 and 16 spp within 10% of `sobol`'s (measured 1.005
    // and 1.013 times it). One image is not enough: all of a zsobol image's
    // pixels share their scrambles, so its mean squared error varies from
    // seed to seed by tens of percent (64 × 64 pixels, 8 seeds: 1.14 and
    // 0.74 times sobol's).
    for spp in [4, 16] {
        let mse = |kind| {
            let e: Vec<f64> = (0..1024)
                .flat_map(|s| pixel_errors(kind, 8, spp, s))
                .collect();
            e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64
        };
        let (z, s) = (mse(SamplerKind::ZSobol), mse(SamplerKind::Sobol));
        eprintln!("{spp} spp: zsobol {z:e}, sobol {s:e}");
        assert!(
            (z / s - 1.0).abs() < 0.1,
            "{spp} spp: zsobol {z:e}, sobol {s:e}"
        );
        let independent = mse(SamplerKind::Independent);
        assert!(
            z < 0.5 * independent,
            "{spp} spp: zsobol {z:e}, independent {independent:e}"
        );
    }
}
