//! Adaptive sampling stops where the image is clean, and does not bias it.

mod common;

use lumen::bench::efficiency::sky_spheres;
use lumen::progressive::Session;
use lumen::render::render;
use lumen::scene::{Sampling, Scene};
use std::sync::atomic::AtomicBool;

#[test]
fn an_adaptive_render_is_within_its_target_and_unbiased() {
    // The cover's spheres under a white sky, 64×36, up to 512 spp with a 3%
    // noise target, against a 4096-spp reference of another seed (whose own
    // relative noise, about 0.3% a pixel, is small against the target).
    let target = 0.03;
    let mut desc = sky_spheres();
    desc.render.width = 64;
    desc.render.height = Some(36);
    desc.render.samples_per_pixel = 512;
    desc.render.sampler = Sampling::Sobol;
    desc.render.noise_target = Some(target);
    desc.render.seed = 1;
    let mut session = Session::new(&desc).unwrap();
    session
        .run(&AtomicBool::new(false), None, &|_| {}, &mut |_, _| {
            Ok::<(), ()>(())
        })
        .unwrap();
    let mut reference = desc.clone();
    reference.render.noise_target = None;
    reference.render.samples_per_pixel = 4096;
    reference.render.seed = 2;
    let reference = render(&Scene::from_desc(&reference).unwrap(), &|_| {}).0;

    let film = session.film();
    let (_, counts) = film.raw();
    let pixels = film.len();
    let full = pixels as u64 * 512;
    let taken = session.stats().samples;
    assert!(
        taken < full * 3 / 4,
        "adaptive sampling saved little: {taken} of {full} samples"
    );
    let brightness = |c: lumen::math::Color| f64::from(c.element_sum() / 3.0).max(1e-3);
    // Pixels that stopped early: their real relative error, against the
    // reference. The estimate is of one standard deviation, so most of
    // them (about 68% for a normal error; more, as the estimate is
    // cautious with Sobol points) are within the target, and almost none
    // beyond three times it. (Measured: 1,507 of 1,580 within, none beyond;
    // 54% of the samples taken.)
    let mut within = 0;
    let mut far = 0;
    let mut stopped = 0;
    for (i, &count) in counts.iter().enumerate() {
        if count >= 512 {
            continue;
        }
        stopped += 1;
        let (a, r) = (film.mean(i), reference.mean(i));
        let error = f64::from((a - r).abs().element_sum() / 3.0) / brightness(r);
        within += usize::from(error <= target);
        far += usize::from(error > 3.0 * target);
    }
    assert!(stopped > pixels / 4, "only {stopped} pixels stopped early");
    assert!(
        within as f64 >= 0.6 * stopped as f64,
        "{within} of {stopped} early-stopped pixels within the target"
    );
    assert!(
        far as f64 <= 0.02 * stopped as f64,
        "{far} of {stopped} early-stopped pixels beyond three times the target"
    );
    // No region systematically brighter or darker: in each 16×9 block the
    // mean relative difference is the average of 144 errors of about the
    // target each, so about target/12; half the target is 6 such errors.
    let width = 64;
    for by in 0..4 {
        for bx in 0..4 {
            let (mut diff, mut level) = (0.0, 0.0);
            for y in by * 9..by * 9 + 9 {
                for x in bx * 16..bx * 16 + 16 {
                    let i = y * width + x;
                    diff += f64::from(film.mean(i).element_sum() - reference.mean(i).element_sum());
                    level += f64::from(reference.mean(i).element_sum());
                }
            }
            let relative = diff / level;
            assert!(
                relative.abs() < target / 2.0,
                "block ({bx}, {by}) off by {relative:.4} relative"
            );
        }
    }
}

#[test]
fn noise_targets_outside_zero_to_one_are_refused() {
    for bad in [0.0, -0.1, 1.5, f64::NAN] {
        let mut desc = sky_spheres();
        desc.render.noise_target = Some(bad);
        let e = Scene::from_desc(&desc).unwrap_err().to_string();
        assert!(
            e.contains("render.noise_target") && e.contains("above 0 and at most 1"),
            "{bad}: {e}"
        );
    }
}
