//! The render loop: camera samples for every pixel, in parallel, into a film.

use crate::film::Film;
use crate::integrator::radiance;
use crate::math::Color;
use crate::rng::Rng;
use crate::scene::{Sampling, Scene};
use rayon::prelude::*;
use std::ops::Range;
use std::time::Duration;

/// Counts gathered while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera samples taken (including dropped ones).
    pub samples: u64,
    /// Ray segments traced (camera rays and bounces).
    pub rays: u64,
    /// Samples whose colour was NaN or infinite and were left out of the image.
    pub dropped: u64,
}

impl RenderStats {
    /// Adds another set of counts to this one.
    pub fn add(&mut self, other: RenderStats) {
        self.samples += other.samples;
        self.rays += other.rays;
        self.dropped += other.dropped;
    }

    /// Rays per second over `elapsed`.
    pub fn rays_per_second(&self, elapsed: Duration) -> f64 {
        self.rays as f64 / elapsed.as_secs_f64().max(1e-9)
    }

    /// Camera samples per second over `elapsed`.
    pub fn samples_per_second(&self, elapsed: Duration) -> f64 {
        self.samples as f64 / elapsed.as_secs_f64().max(1e-9)
    }
}

/// The sub-pixel offset in [-0.5, 0.5)² of sample `index` of `spp`.
///
/// Stratified sampling puts the first k² samples (k = ⌊√spp⌋) one in each cell
/// of a k×k grid over the pixel; any remaining samples, and all samples of
/// random sampling, are uniform over the pixel.
#[inline]
pub fn pixel_offset(sampling: Sampling, index: u32, spp: u32, rng: &mut Rng) -> (f32, f32) {
    let (jx, jy) = (rng.next_f32(), rng.next_f32());
    if sampling == Sampling::Stratified {
        let k = (spp as f64).sqrt() as u32;
        if index < k * k {
            let inv = 1.0 / k as f32;
            let (cx, cy) = ((index % k) as f32, (index / k) as f32);
            // In f32, (c + j)·(1/k) rounds to 1 when j is the largest value
            // below 1 in the last cell: keep it below 1 so the offset stays < 0.5.
            let below_one = 1.0 - f32::EPSILON / 2.0;
            let cell = |c: f32, j: f32| ((c + j) * inv).min(below_one) - 0.5;
            return (cell(cx, jx), cell(cy, jy));
        }
    }
    (jx - 0.5, jy - 0.5)
}

/// Adds samples `samples` (a range of sample indices, each in
/// `0..samples_per_pixel`) of every pixel to `film`, in parallel over rows.
///
/// Each sample draws its random numbers from its own generator, seeded by the
/// scene seed, the pixel and the sample index, and each pixel adds its samples
/// in index order: the film is bit-identical whatever the thread count, and
/// rendering `0..a` then `a..b` gives the same film as `0..b`.
///
/// `progress` is called with the number of samples finished, once per row.
pub fn render_samples(
    scene: &Scene,
    film: &mut Film,
    samples: Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderStats {
    render_samples_cancellable(scene, film, samples, progress, &|| false)
        .expect("a render that is never stopped completes")
}

/// [`render_samples`] that can be abandoned: `should_stop` is asked before
/// each row (rows are the units of work), and once it answers `true` the
/// remaining rows are skipped and `None` is returned. The film then holds the
/// new samples in some rows only; the caller must put back its copy.
pub fn render_samples_cancellable(
    scene: &Scene,
    film: &mut Film,
    samples: Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    should_stop: &(dyn Fn() -> bool + Sync),
) -> Option<RenderStats> {
    let s = &scene.settings;
    let width = film.width();
    let row_samples = u64::from(width) * u64::from(samples.len() as u32);
    film.rows_mut()
        .enumerate()
        .map(|(y, (sums, counts))| {
            if should_stop() {
                return None;
            }
            let mut stats = RenderStats::default();
            for x in 0..width {
                let pixel = y as u64 * u64::from(width) + u64::from(x);
                let (sum, count) = (&mut sums[x as usize], &mut counts[x as usize]);
                for index in samples.clone() {
                    let mut rng = Rng::for_sample(s.seed, pixel, u64::from(index));
                    let (dx, dy) = pixel_offset(s.sampling, index, s.samples_per_pixel, &mut rng);
                    let ray = scene.camera.ray(x, y as u32, dx, dy, &mut rng);
                    let c = radiance(scene, ray, &mut rng, &mut stats.rays);
                    stats.samples += 1;
                    if !accumulate(sum, count, c) {
                        stats.dropped += 1;
                    }
                }
            }
            progress(row_samples);
            Some(stats)
        })
        .reduce(
            || Some(RenderStats::default()),
            |a, b| {
                let (mut a, b) = (a?, b?);
                a.add(b);
                Some(a)
            },
        )
}

/// Adds one sample's colour to a pixel's sum and count, unless it is NaN or
/// infinite: such a sample is left out and `false` is returned so the caller
/// can count it.
#[inline]
fn accumulate(sum: &mut [f64; 3], count: &mut u32, c: Color) -> bool {
    if !c.is_finite() {
        return false;
    }
    sum[0] += f64::from(c.x);
    sum[1] += f64::from(c.y);
    sum[2] += f64::from(c.z);
    *count += 1;
    true
}

/// Renders the whole image at the scene's samples per pixel.
pub fn render(scene: &Scene, progress: &(dyn Fn(u64) + Sync)) -> (Film, RenderStats) {
    let s = &scene.settings;
    let mut film = Film::new(s.width, s.height);
    let stats = render_samples(scene, &mut film, 0..s.samples_per_pixel, progress);
    (film, stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_samples_are_dropped_and_finite_ones_added() {
        let (mut sum, mut count) = ([0.0f64; 3], 0u32);
        assert!(accumulate(&mut sum, &mut count, Color::new(0.25, 0.5, 2.0)));
        for bad in [
            Color::new(f32::NAN, 0.0, 0.0),
            Color::new(0.0, f32::INFINITY, 0.0),
            Color::new(0.0, 0.0, f32::NEG_INFINITY),
        ] {
            assert!(!accumulate(&mut sum, &mut count, bad));
        }
        assert!(accumulate(&mut sum, &mut count, Color::new(0.25, 0.5, 2.0)));
        assert_eq!((sum, count), ([0.5, 1.0, 4.0], 2));
    }
}
