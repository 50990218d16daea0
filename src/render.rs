//! The render loop: camera samples for every pixel, in parallel, into a film.

use crate::film::Film;
use crate::integrator::{first_hit_view, trace_paths, PATHS};
use crate::isa::Isa;
use crate::math::{Color, Vec3};
use crate::ray::Ray;
use crate::sampler::{PixelSample, PixelSampler};
use crate::scene::{Scene, Shading};
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

/// Adds samples `samples` (a range of sample indices, each in
/// `0..samples_per_pixel`) of every pixel to `film`, in parallel over rows.
///
/// Each sample draws its random numbers from its own sampler, addressed by the
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
    let width = film.width();
    let row_samples = u64::from(width) * u64::from(samples.len() as u32);
    let isa = Isa::detect();
    film.rows_mut()
        .enumerate()
        .map(|(y, (sums, counts))| {
            if should_stop() {
                return None;
            }
            let stats = render_row(isa, scene, y as u32, samples.clone(), sums, counts);
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

/// Renders samples `samples` of every pixel of row `y` with the code compiled
/// for `isa` (which must be supported: use [`Isa::detect`]).
fn render_row(
    isa: Isa,
    scene: &Scene,
    y: u32,
    samples: Range<u32>,
    sums: &mut [[f64; 3]],
    counts: &mut [u32],
) -> RenderStats {
    match isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => {
            // SAFETY: `Isa::Avx2` is only produced by `Isa::detect` when the
            // processor has every feature `render_row_avx2` is compiled for.
            #[allow(unsafe_code)]
            unsafe {
                render_row_avx2(scene, y, samples, sums, counts)
            }
        }
        _ => render_row_generic(scene, y, samples, sums, counts),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2")]
#[allow(unsafe_code)]
unsafe fn render_row_avx2(
    scene: &Scene,
    y: u32,
    samples: Range<u32>,
    sums: &mut [[f64; 3]],
    counts: &mut [u32],
) -> RenderStats {
    render_row_generic(scene, y, samples, sums, counts)
}

/// The body of the row loop, inlined into each instruction-set version.
#[inline(always)]
fn render_row_generic(
    scene: &Scene,
    y: u32,
    samples: Range<u32>,
    sums: &mut [[f64; 3]],
    counts: &mut [u32],
) -> RenderStats {
    let s = &scene.settings;
    let mut stats = RenderStats::default();
    let width = sums.len().min(counts.len());
    // Path tracing runs a pixel's samples side by side (`trace_paths`); the
    // debugging views trace one ray at a time.
    let side_by_side = s.shading == Shading::Path;
    // A pixel's camera rays, their samplers and colours, filled for each
    // group of samples.
    let mut rays = [Ray::new(Vec3::ZERO, Vec3::X); PATHS];
    let mut samplers = [const { PixelSample::placeholder() }; PATHS];
    let mut colours = [Color::ZERO; PATHS];
    for (x, (sum, count)) in sums.iter_mut().zip(counts.iter_mut()).enumerate() {
        let pixel = u64::from(y) * width as u64 + x as u64;
        let pixel_sampler = PixelSampler::new(s.sampler, s.seed, pixel, s.samples_per_pixel);
        let mut add = |c: Color| {
            stats.samples += 1;
            if !accumulate(sum, count, c) {
                stats.dropped += 1;
            }
        };
        if !side_by_side {
            for index in samples.clone() {
                let (ray, _) = camera_sample(scene, x as u32, y, &pixel_sampler, index);
                add(first_hit_view(scene, ray, s.shading, &mut stats.rays));
            }
            continue;
        }
        let reference = scene.camera.central_ray(x as u32, y);
        let mut start = samples.start;
        while start < samples.end {
            let n = (samples.end - start).min(PATHS as u32) as usize;
            for (i, (ray, sampler)) in rays.iter_mut().zip(&mut samplers).take(n).enumerate() {
                (*ray, *sampler) =
                    camera_sample(scene, x as u32, y, &pixel_sampler, start + i as u32);
            }
            trace_paths(
                scene,
                &mut rays[..n],
                &mut samplers[..n],
                &reference,
                &mut colours[..n],
                &mut stats.rays,
            );
            // In sample order, as one at a time would add them.
            for &c in &colours[..n] {
                add(c);
            }
            start += n as u32;
        }
    }
    stats
}

/// The camera ray of sample `index` of pixel `(x, y)`, whose sampler is
/// `pixel_sampler`, and the sampler that goes on to serve its path.
#[inline(always)]
fn camera_sample(
    scene: &Scene,
    x: u32,
    y: u32,
    pixel_sampler: &PixelSampler,
    index: u32,
) -> (Ray, PixelSample) {
    let (mut sampler, (dx, dy)) = pixel_sampler.start(index);
    let ray = scene.camera.ray(x, y, dx, dy, &mut sampler);
    (ray, sampler)
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
    use crate::scene::{builtin, Sampling};

    #[test]
    fn every_instruction_set_version_renders_the_same_bits() {
        for sampler in [Sampling::Independent, Sampling::Sobol] {
            let mut desc = builtin::cover();
            desc.render.width = 48;
            desc.render.sampler = sampler;
            // Enough samples for bundles of every size in every round.
            desc.render.samples_per_pixel = 37;
            let scene = Scene::from_desc(&desc).expect("the cover compiles");
            same_bits_on_every_instruction_set(&scene);
        }
    }

    fn same_bits_on_every_instruction_set(scene: &Scene) {
        let width = scene.settings.width as usize;
        let isa = Isa::detect();
        for y in 0..scene.settings.height {
            let mut base = (vec![[0.0f64; 3]; width], vec![0u32; width]);
            let mut best = base.clone();
            let a = render_row(Isa::Baseline, scene, y, 0..37, &mut base.0, &mut base.1);
            let b = render_row(isa, scene, y, 0..37, &mut best.0, &mut best.1);
            assert_eq!(a, b, "row {y}: counts differ between baseline and {isa:?}");
            let bits = |v: &[[f64; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&base.0),
                bits(&best.0),
                "row {y}: baseline and {isa:?} differ"
            );
            assert_eq!(base.1, best.1);
        }
    }

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
