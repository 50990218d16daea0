//! The pixel filter: across a sharp edge, a Gaussian-filtered image
//! falls off as the filter's integral, a box-filtered one in one pixel.

mod common;

use common::{compile_file, pixel_stats, scene_file_error, scratch_dir};

/// The fraction of a Gaussian filter (σ = `stddev`, radius 4σ) beyond
/// `d` pixels from its centre, by the midpoint rule.
fn beyond(d: f64, stddev: f64) -> f64 {
    let r = 4.0 * stddev;
    let s2 = 2.0 * stddev * stddev;
    let w = |x: f64| ((-x * x / s2).exp() - (-r * r / s2).exp()).max(0.0);
    let n = 100_000;
    let (mut total, mut part) = (0.0, 0.0);
    for i in 0..n {
        let x = -r + (i as f64 + 0.5) * 2.0 * r / n as f64;
        total += w(x);
        if x >= d {
            part += w(x);
        }
    }
    part / total
}

/// A white light filling the right half of a 16 × 2 view (its edge on
/// the boundary between columns 7 and 8), black elsewhere.
fn edge(name: &str, filter: &str) -> common::PixelStats {
    let text = format!(
        "[render]\nwidth = 16\nheight = 2\nsamples_per_pixel = 4096\nmax_depth = 1\n\
         sampler = \"independent\"\n{filter}\n\n\
         [camera]\nvfov = 10\nlookfrom = [0, 0, 10]\nlookat = [0, 0, 0]\n\n\
         [background]\ntype = \"solid\"\ncolor = [0, 0, 0]\n\n\
         [materials.light]\ntype = \"emissive\"\nradiance = [1, 1, 1]\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [0, -50, 0]\nu = [50, 0, 0]\nv = [0, 100, 0]\n\
         material = \"light\"\n"
    );
    pixel_stats(&compile_file(
        &scratch_dir(&format!("pixel_filter-{name}")),
        "s.toml",
        &text,
    ))
}

#[test]
fn a_gaussian_filter_spreads_an_edge_as_its_integral() {
    for stddev in [0.5, 1.0] {
        let stats = edge(
            &format!("gaussian-{stddev}"),
            &format!("pixel_filter = \"gaussian\"\nfilter_stddev = {stddev}"),
        );
        for x in 0..16u32 {
            // Column x's centre lies x + ½ − 8 pixels from the edge.
            let want = beyond(8.0 - (f64::from(x) + 0.5), stddev);
            let got = stats.pixel(x, 0)[0];
            // Each sample is 0 or 1: a binomial proportion.
            let se = (want * (1.0 - want) / 4096.0).sqrt().max(1e-9);
            assert!(
                (got - want).abs() <= 5.0 * se + 1e-6,
                "σ {stddev}, column {x}: {got} instead of {want}"
            );
        }
        // The blur reaches past the neighbouring columns.
        assert!(stats.pixel(6, 0)[0] > 0.0 && stats.pixel(9, 0)[0] < 1.0);
    }
}

#[test]
fn a_box_filter_keeps_an_edge_within_a_pixel() {
    let stats = edge("box", "");
    for x in 0..16u32 {
        let want = if x < 8 { 0.0 } else { 1.0 };
        // Beside the edge a sample a rounding away from it may land on
        // either side.
        let slack = if x == 7 || x == 8 { 1e-3 } else { 0.0 };
        let got = stats.pixel(x, 0)[0];
        assert!((got - want).abs() <= slack, "column {x}: {got}");
    }
}

#[test]
fn filter_settings_are_checked() {
    let dir = scratch_dir("pixel_filter_errors");
    for (lines, wanted) in [
        (
            "filter_stddev = 0.5",
            "render.filter_stddev: is a Gaussian filter's",
        ),
        (
            "pixel_filter = \"gaussian\"\nfilter_stddev = 0",
            "must be above 0",
        ),
        (
            "pixel_filter = \"gaussian\"\nfilter_stddev = nan",
            "filter_stddev",
        ),
        ("pixel_filter = \"gausian\"", "did you mean \"gaussian\"?"),
    ] {
        let message = scene_file_error(&dir, &format!("[render]\n{lines}\n"));
        assert!(message.contains(wanted), "{wanted:?} not in {message}");
    }
}
