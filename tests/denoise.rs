//! Denoising with Open Image Denoise (the `oidn` feature): run by `.ci/run`
//! with `OIDN_DIR` pointing at the library.
#![cfg(feature = "oidn")]

use lumen::denoise::{self, Inputs, Options, Quality, IMAGE_QUALITY, PREFILTER};
use lumen::math::{Color, Vec3};
use lumen::rng::Rng;

/// A 64×64 image of two flat halves (0.2 and 0.8 grey), each sample of a
/// pixel's mean drawn with a noise of standard deviation `sigma`, with its
/// exact albedo and normal.
fn noisy(sigma: f32, seed: u64) -> (Vec<Color>, Vec<Color>, Vec<Vec3>, Vec<Vec3>) {
    let (w, h) = (64, 64);
    let mut rng = Rng::new(seed);
    let mut clean = Vec::new();
    let mut color = Vec::new();
    for _ in 0..h {
        for x in 0..w {
            let v = if x < w / 2 { 0.2 } else { 0.8 };
            clean.push(Color::splat(v));
            // A mean of uniform noise: zero mean, variance σ².
            let n = (rng.next_f32() - 0.5) * sigma * 12f32.sqrt();
            color.push(Color::splat((v + n).max(0.0)));
        }
    }
    let albedo = clean.clone();
    let normal = vec![Vec3::Z; w * h];
    (clean, color, albedo, normal)
}

/// The 64×64 image `color` denoised on two threads, with the buffers given.
fn denoised(
    color: &[Color],
    albedo: Option<&[Vec3]>,
    normal: Option<&[Vec3]>,
) -> Result<Vec<Color>, denoise::DenoiseError> {
    denoised_with(color, albedo, normal, None, Options::default())
}

/// [`denoised`], with a variance buffer and the filters' options.
fn denoised_with(
    color: &[Color],
    albedo: Option<&[Vec3]>,
    normal: Option<&[Vec3]>,
    variance: Option<&[Color]>,
    options: Options,
) -> Result<Vec<Color>, denoise::DenoiseError> {
    let inputs = Inputs {
        width: 64,
        height: 64,
        color,
        albedo,
        normal,
        variance,
        options,
    };
    denoise::denoise(&inputs, 2)
}

fn mse(a: &[Color], b: &[Color]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| f64::from((*a - *b).length_squared()) / 3.0)
        .sum::<f64>()
        / a.len() as f64
}

#[test]
fn a_noisy_image_comes_out_closer_to_the_clean_one_with_its_mean_kept() {
    let (clean, color, albedo, normal) = noisy(0.1, 7);
    let out = denoised(&color, Some(&albedo), Some(&normal)).expect("OIDN runs");
    assert_eq!(out.len(), color.len());
    assert!(out.iter().all(|c| c.min_element() >= 0.0 && c.is_finite()));
    let (before, after) = (mse(&color, &clean), mse(&out, &clean));
    assert!(
        after < before / 10.0,
        "error {before} before, {after} after"
    );
    let mean = |v: &[Color]| v.iter().map(|c| f64::from(c.x)).sum::<f64>() / v.len() as f64;
    let (m, m0) = (mean(&out), mean(&clean));
    assert!((m / m0 - 1.0).abs() < 0.01, "mean {m} against {m0}");
}

#[test]
fn glints_come_out_as_rendered() {
    // Sun glints: single pixels a thousand times the image's mean, which
    // neither the albedo nor the normal announces. The filter alone
    // spreads or removes them.
    let (_, mut color, albedo, normal) = noisy(0.05, 5);
    let glints = [(10, 10), (40, 20), (50, 50), (20, 45)];
    for &(x, y) in &glints {
        color[y * 64 + x] = Color::new(500.0, 450.0, 400.0);
    }
    let out = denoised(&color, Some(&albedo), Some(&normal)).expect("OIDN runs");
    // What passes ten times the mean luminance is kept whole; the filter
    // sees the rest.
    let (_, highlights) = denoise::split_highlights(&color);
    for &(x, y) in &glints {
        let i = y * 64 + x;
        let (got, want, kept) = (out[i], color[i], highlights[i]);
        assert!(kept.min_element() > 0.9 * want.min_element(), "{kept}");
        assert!(
            got.cmpge(kept).all() && got.cmple(want * 1.01).all(),
            "glint ({x}, {y}): {got} against {want}, of which {kept} above the limit"
        );
    }
    let mean = |v: &[Color], c: usize| v.iter().map(|p| f64::from(p[c])).sum::<f64>() / 4096.0;
    for c in 0..3 {
        let (m, m0) = (mean(&out, c), mean(&color, c));
        assert!(
            (m / m0 - 1.0).abs() < 0.01,
            "channel {c}: mean {m} against {m0}"
        );
    }
}

#[test]
fn the_same_input_gives_the_same_bits() {
    let (_, color, albedo, normal) = noisy(0.2, 3);
    let run = || denoised(&color, Some(&albedo), Some(&normal)).expect("OIDN runs");
    let first = run();
    assert!(first == run(), "two runs on 2 threads differ");
}

#[test]
fn each_quality_runs_its_own_network_and_each_denoises() {
    // A noisy albedo, so that its prefilter has work to do.
    let (clean, color, mut albedo, normal) = noisy(0.1, 13);
    let mut rng = Rng::new(17);
    for a in &mut albedo {
        *a = (*a + Vec3::splat((rng.next_f32() - 0.5) * 0.2)).clamp(Vec3::ZERO, Vec3::ONE);
    }
    let run = |quality, prefilter| {
        let options = Options {
            quality,
            prefilter,
            ..Options::default()
        };
        denoised_with(&color, Some(&albedo), Some(&normal), None, options).expect("OIDN runs")
    };
    let before = mse(&color, &clean);
    let mut outputs = Vec::new();
    for (name, quality) in Quality::NAMES {
        let out = run(quality, PREFILTER);
        let after = mse(&out, &clean);
        assert!(
            after < before / 5.0,
            "{name}: error {before} before, {after} after"
        );
        assert!(out == run(quality, PREFILTER), "{name}: two runs differ");
        outputs.push(out);
    }
    assert!(outputs[0] != outputs[1] && outputs[1] != outputs[2] && outputs[0] != outputs[2]);
    // The prefilter's quality reaches OIDN too, and so does its absence.
    let high = run(IMAGE_QUALITY, Some(Quality::High));
    let none = run(IMAGE_QUALITY, None);
    assert!(high != run(IMAGE_QUALITY, Some(Quality::Balanced)));
    assert!(none != high && none != run(IMAGE_QUALITY, Some(Quality::Balanced)));
    for out in [&high, &none] {
        assert!(mse(out, &clean) < before / 5.0);
    }
}

#[test]
fn an_image_alone_is_denoised_too() {
    let (clean, color, _, _) = noisy(0.1, 11);
    let out = denoised(&color, None, None).expect("OIDN runs");
    assert!(mse(&out, &clean) < mse(&color, &clean) / 4.0);
}

#[test]
fn buffers_of_the_wrong_size_are_refused() {
    let (_, color, albedo, _) = noisy(0.1, 1);
    let e = denoised(&color, Some(&albedo[1..]), None).unwrap_err();
    assert!(e.to_string().contains("4096 pixels"), "{e}");
}

mod library {
    use lumen::denoise::oidn::{Library, FILE_NAME};
    use std::path::{Path, PathBuf};

    fn dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lumen-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("lib")).unwrap();
        dir
    }

    fn refusal(dir: &Path) -> String {
        let Err(e) = Library::open(Some(dir.to_path_buf())) else {
            panic!("{} holds no OIDN library", dir.display())
        };
        std::fs::remove_dir_all(dir).unwrap();
        e.to_string()
    }

    #[test]
    fn a_directory_without_the_library_names_each_file_tried() {
        let dir = dir("no-oidn");
        let lib = dir.join("lib").join(FILE_NAME).display().to_string();
        let text = refusal(&dir);
        assert!(text.contains(&format!("{lib}: no such file")), "{text}");
    }

    #[test]
    fn a_file_that_is_not_a_library_is_refused_with_the_loaders_reason() {
        let dir = dir("bad-oidn");
        std::fs::write(dir.join("lib").join(FILE_NAME), b"not a library").unwrap();
        let text = refusal(&dir);
        assert!(text.starts_with("cannot load Open Image Denoise"), "{text}");
        assert!(text.contains(FILE_NAME), "{text}");
    }

    #[test]
    fn a_library_without_oidns_functions_is_refused_as_incompatible() {
        // A shared library of the system's that is not OIDN.
        let other = [
            "/lib/x86_64-linux-gnu/libm.so.6",
            "/usr/lib/x86_64-linux-gnu/libm.so.6",
        ]
        .into_iter()
        .find(|p| Path::new(p).exists())
        .expect("the C library's libm");
        let dir = dir("other-oidn");
        std::fs::copy(other, dir.join("lib").join(FILE_NAME)).unwrap();
        let text = refusal(&dir);
        assert!(text.contains("has no function oidnNewDevice"), "{text}");
    }

    #[test]
    fn the_library_of_oidn_dir_is_version_2() {
        let lib = Library::get().expect("OIDN_DIR names a library");
        assert!(
            lib.describe().starts_with("Open Image Denoise 2."),
            "{}",
            lib.describe()
        );
    }
}

#[test]
fn with_the_variance_detail_the_filter_smooths_comes_back_and_noise_stays_away() {
    // A 64×64 checkerboard of single pixels (0.3 and 0.7) that neither the
    // albedo nor the normal shows, with a little noise: the filter takes
    // most of the checkerboard for noise. With the variance, the blend
    // sees that it changed the image by far more than the noise explains.
    let (w, h) = (64, 64);
    let sigma = 0.02f32;
    let mut rng = Rng::new(11);
    let clean: Vec<Color> = (0..w * h)
        .map(|i| Color::splat(if (i % w + i / w) % 2 == 0 { 0.3 } else { 0.7 }))
        .collect();
    let color: Vec<Color> = clean
        .iter()
        .map(|c| *c + Color::splat((rng.next_f32() - 0.5) * sigma * 12f32.sqrt()))
        .collect();
    let albedo = vec![Vec3::splat(0.5); w * h];
    let normal = vec![Vec3::Z; w * h];
    let variance = vec![Color::splat(sigma * sigma); w * h];
    let run = |variance: Option<&[Color]>| {
        let inputs = Inputs {
            width: w,
            height: h,
            color: &color,
            albedo: Some(&albedo),
            normal: Some(&normal),
            variance,
            options: Options::default(),
        };
        denoise::denoise(&inputs, 2).expect("OIDN runs")
    };
    let (plain, blended) = (run(None), run(Some(&variance)));
    let (noisy, smoothed, kept) = (
        mse(&color, &clean),
        mse(&plain, &clean),
        mse(&blended, &clean),
    );
    assert!(
        kept < smoothed / 4.0,
        "error: noisy {noisy}, filtered {smoothed}, blended {kept}"
    );
    assert!(kept <= noisy * 1.05, "error: noisy {noisy}, blended {kept}");
    // Where the filter only removed noise (the flat image of the first
    // test, its true variance given), the blend keeps its work.
    let (clean, color, albedo, normal) = noisy_flat();
    let variance = vec![Color::splat(0.01); color.len()];
    let out = denoised_with(
        &color,
        Some(&albedo),
        Some(&normal),
        Some(&variance),
        Options::default(),
    )
    .expect("OIDN runs");
    let (before, after) = (mse(&color, &clean), mse(&out, &clean));
    assert!(after < before / 5.0, "error {before} before, {after} after");
}

fn noisy_flat() -> (Vec<Color>, Vec<Color>, Vec<Vec3>, Vec<Vec3>) {
    noisy(0.1, 7)
}
