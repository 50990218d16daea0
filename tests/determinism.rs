//! The same scene, settings and seed give a bit-identical film whatever the
//! thread count and however the samples are split into passes.

mod common;

use common::builtin_scene;
use lumen::film::Film;
use lumen::render::{render, render_samples};
use lumen::scene::Scene;

fn render_with_threads(scene: &Scene, threads: usize) -> Film {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| render(scene, &|_| {}).0)
}

#[test]
fn films_are_bit_identical_across_thread_counts() {
    for (name, width, spp) in [
        ("cover", 64, 4),
        ("glass-hollow", 48, 8),
        ("depth-of-field", 48, 4),
    ] {
        let scene = builtin_scene(name, width, spp, 3);
        let one = render_with_threads(&scene, 1);
        assert!(
            one.linear().iter().any(|c| *c != one.pixel(0, 0)),
            "{name}: flat image"
        );
        for threads in [2, 4] {
            let other = render_with_threads(&scene, threads);
            assert!(
                one == other,
                "{name}: {threads} threads differ from 1 thread"
            );
        }
    }
}

#[test]
fn rendering_in_passes_equals_rendering_at_once() {
    // Passes group a pixel's samples differently into paths traced side by
    // side and into bundles of rays (up to 32 and 8): no difference may show.
    for (name, spp, splits) in [
        ("glass-refract-reflect", 9, &[1, 4, 8][..]),
        ("cover", 37, &[1, 3, 20, 33][..]),
    ] {
        let scene = builtin_scene(name, 40, spp, 4);
        let (whole, stats) = render(&scene, &|_| {});
        for &split in splits {
            let mut film = Film::new(scene.settings.width, scene.settings.height);
            let mut passes = render_samples(&scene, &mut film, 0..split, &|_| {});
            passes.add(render_samples(&scene, &mut film, split..spp, &|_| {}));
            assert!(
                film == whole,
                "{name}: 0..{split} then {split}..{spp} differs from 0..{spp}"
            );
            assert_eq!(passes, stats);
        }
    }
}

#[test]
fn a_different_seed_gives_a_different_image() {
    let a = render(&builtin_scene("cover", 32, 2, 1), &|_| {}).0;
    let b = render(&builtin_scene("cover", 32, 2, 2), &|_| {}).0;
    let a2 = render(&builtin_scene("cover", 32, 2, 1), &|_| {}).0;
    assert!(a == a2, "same seed, same image");
    assert!(a != b, "different seeds gave the same image");
    // Not just one pixel: most pixels with any noise change.
    let changed = a
        .linear()
        .iter()
        .zip(b.linear())
        .filter(|(p, q)| **p != *q)
        .count();
    assert!(
        changed > a.linear().len() / 2,
        "only {changed} pixels changed"
    );
}

#[test]
fn the_progress_callback_counts_every_sample() {
    use std::sync::atomic::{AtomicU64, Ordering};
    let scene = builtin_scene("bounce-lambertian", 24, 3, 0);
    let done = AtomicU64::new(0);
    let (_, stats) = render(&scene, &|n| {
        done.fetch_add(n, Ordering::Relaxed);
    });
    assert_eq!(done.into_inner(), stats.samples);
    let s = &scene.settings;
    assert_eq!(
        stats.samples,
        u64::from(s.width * s.height * s.samples_per_pixel)
    );
}
