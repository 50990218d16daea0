//! The render loop: camera samples for every pixel, in parallel, into a film.

use crate::aov::{Features, Layers};
use crate::film::{Film, RowMut, UnitFeatures};
use crate::halt::Halt;
use crate::integrator::{first_hit_view, trace_paths, FeatureSearch, PATHS};
use crate::isa::Isa;
use crate::math::{Color, Vec3};
use crate::ray::Ray;
use crate::sampler::{PixelSample, PixelSampler};
use crate::scene::{Scene, Shading};
use rayon::prelude::*;
use std::ops::Range;
use std::time::Duration;

/// The share of dropped samples above which a render warns: a few in a
/// million are the rounding of extreme paths, more are a fault of the scene.
pub const DROPPED_WARNING: f64 = 1e-4;

/// Counts gathered while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera samples taken (including dropped ones).
    pub samples: u64,
    /// Ray segments traced (camera rays and bounces).
    pub rays: u64,
    /// Samples whose colour was NaN, infinite or too large for the film's
    /// sums (2⁶³ or more, see [`crate::film::Sum`]) and were left out of the
    /// image.
    pub dropped: u64,
}

impl RenderStats {
    /// Adds another set of counts to this one.
    pub fn add(&mut self, other: RenderStats) {
        // Saturating: counts read from files may be anything.
        self.samples = self.samples.saturating_add(other.samples);
        self.rays = self.rays.saturating_add(other.rays);
        self.dropped = self.dropped.saturating_add(other.dropped);
    }

    /// Counts a camera sample, as dropped unless the film `added` it.
    #[inline(always)]
    fn count(&mut self, added: bool) {
        self.samples += 1;
        if !added {
            self.dropped += 1;
        }
    }

    /// A warning when more than [`DROPPED_WARNING`] of the samples were
    /// dropped (NaN, infinite or too large), with their count and the
    /// likely causes.
    pub fn dropped_warning(&self) -> Option<String> {
        if self.dropped == 0 || (self.dropped as f64) <= DROPPED_WARNING * self.samples as f64 {
            return None;
        }
        let share = 100.0 * self.dropped as f64 / self.samples.max(1) as f64;
        let what = if self.all_dropped() {
            "every sample".to_string()
        } else {
            format!("{} of {} samples ({share:.2}%)", self.dropped, self.samples)
        };
        Some(format!(
            "{what} came out NaN, infinite or beyond 9.2e18 (more than a pixel's sum holds) \
             and left out of the image: likely a degenerate \
             camera (focus_dist or vfov tiny against the coordinates), geometry at the limits \
             of f32, or extreme radiance"
        ))
    }

    /// Whether samples were taken and every one of them was dropped (the
    /// image holds nothing).
    pub fn all_dropped(&self) -> bool {
        self.samples > 0 && self.dropped == self.samples
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
    render_pixels(scene, film, (0, 0), samples, None, progress, should_stop)
}

/// [`render_samples_cancellable`] into a film of some of the image's
/// pixels, whose top left pixel is pixel `origin` of the image (a tile:
/// `(0, 0)` for a film of the whole image), and for the pixels whose entry
/// in `active` (row-major, one per film pixel) is `true` only, or for every
/// pixel when `active` is `None`; `progress` counts the samples of those
/// pixels. A pixel's samples are those it has in a render of the whole
/// image.
pub fn render_pixels(
    scene: &Scene,
    film: &mut Film,
    origin: (u32, u32),
    samples: Range<u32>,
    active: Option<&[bool]>,
    progress: &(dyn Fn(u64) + Sync),
    should_stop: &(dyn Fn() -> bool + Sync),
) -> Option<RenderStats> {
    let width = film.width() as usize;
    let per_pixel = u64::from(samples.len() as u32);
    if let Some(active) = active {
        assert_eq!(active.len(), film.len(), "one flag per pixel");
    }
    let isa = Isa::detect();
    // Asked before every row, every few pixels and every few hundred
    // bounces: see `Halt`.
    let halt = Halt::new(should_stop);
    let stats = film
        .rows_mut()
        .enumerate()
        .map(|(y, row)| {
            if halt.asked() {
                return None;
            }
            let active = active.map(|a| &a[y * width..(y + 1) * width]);
            let at = (origin.0, origin.1 + y as u32);
            let stats = render_row(isa, scene, at, samples.clone(), row, active, &halt);
            let pixels = active.map_or(width, |a| a.iter().filter(|&&on| on).count());
            progress(pixels as u64 * per_pixel);
            Some(stats)
        })
        .reduce(
            || Some(RenderStats::default()),
            |a, b| {
                let (mut a, b) = (a?, b?);
                a.add(b);
                Some(a)
            },
        );
    // A row cut short by the stop holds only some of its samples.
    stats.filter(|_| !halt.halted())
}

/// How many pixels a row renders between asks whether to stop: a pixel of
/// a single sample takes about a microsecond, an ask (a look at the clock)
/// a few tens of nanoseconds.
const ASK_EVERY_PIXELS: usize = 8;

/// Renders samples `samples` of every pixel of `row`, which holds the
/// pixels of image row `at.1` from column `at.0` on (of those whose `active`
/// flag is set, if given), with the code compiled for `isa` (which must be
/// supported: use [`Isa::detect`]).
fn render_row(
    isa: Isa,
    scene: &Scene,
    at: (u32, u32),
    samples: Range<u32>,
    row: RowMut,
    active: Option<&[bool]>,
    halt: &Halt,
) -> RenderStats {
    match isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => {
            // SAFETY: `Isa::Avx2` is only produced by `Isa::detect` when the
            // processor has every feature `render_row_avx2` is compiled for.
            #[allow(unsafe_code)]
            unsafe {
                render_row_avx2(scene, at, samples, row, active, halt)
            }
        }
        _ => render_row_generic(scene, at, samples, row, active, halt),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2")]
#[allow(unsafe_code)]
unsafe fn render_row_avx2(
    scene: &Scene,
    at: (u32, u32),
    samples: Range<u32>,
    row: RowMut,
    active: Option<&[bool]>,
    halt: &Halt,
) -> RenderStats {
    render_row_generic(scene, at, samples, row, active, halt)
}

/// The body of the row loop, inlined into each instruction-set version.
#[inline(always)]
fn render_row_generic(
    scene: &Scene,
    (x0, y): (u32, u32),
    samples: Range<u32>,
    mut row: RowMut,
    active: Option<&[bool]>,
    halt: &Halt,
) -> RenderStats {
    let s = &scene.settings;
    let mut stats = RenderStats::default();
    let width = row.sums.len();
    if s.shading != Shading::Path {
        // The debugging views trace one ray at a time.
        for x in 0..width {
            if active.is_some_and(|a| !a[x]) {
                continue;
            }
            if x % ASK_EVERY_PIXELS == 0 && halt.asked() {
                break;
            }
            // The pixel's column in the image, which addresses its samples.
            let column = x0 + x as u32;
            let pixel_sampler = pixel_sampler(scene, column, y);
            for index in samples.clone() {
                let (ray, _) = camera_sample(scene, column, y, &pixel_sampler, index);
                let c = first_hit_view(scene, ray, s.shading, &mut stats.rays);
                add_sample(&mut row, &mut stats, (x, index), c, &Features::default());
            }
        }
        return stats;
    }
    // Path tracing runs [`PATHS`] paths side by side (`trace_paths`): a
    // pixel's samples, in groups of that many, or when a pass holds fewer,
    // the samples of as many neighbouring pixels as fit, so that the
    // bundles cut from them stay full.
    let per_group = (PATHS / samples.len().max(1)).max(1);
    let chunk = PATHS / per_group;
    let mut paths = SideBySide::new();
    let mut members = [(0usize, 0u32); PATHS];
    let mut x = 0;
    while x < width {
        let mut m = 0;
        while x < width && m < per_group {
            if x % ASK_EVERY_PIXELS == 0 && halt.asked() {
                return stats;
            }
            if active.is_none_or(|a| a[x]) {
                // With the pixel's column in the image, which addresses
                // its samples.
                members[m] = (x, x0 + x as u32);
                m += 1;
            }
            x += 1;
        }
        if m == 0 {
            continue;
        }
        let reference = scene.camera.central_ray(members[m / 2].1, y);
        for start in samples.clone().step_by(chunk) {
            let group = (&members[..m], start..samples.end.min(start + chunk as u32));
            paths.trace(scene, y, group, &reference, &mut row, &mut stats, halt);
        }
    }
    stats
}

/// The sampler of the pixel in column `column` of image row `y`.
#[inline(always)]
fn pixel_sampler(scene: &Scene, column: u32, y: u32) -> PixelSampler {
    let s = &scene.settings;
    PixelSampler::new(s.sampler, s.seed, (column, y), s.width, s.samples_per_pixel)
}

/// Room for up to [`PATHS`] camera rays traced side by side
/// ([`trace_paths`]), with their samplers, colours and features.
struct SideBySide {
    rays: [Ray; PATHS],
    samplers: [PixelSample; PATHS],
    colours: [Color; PATHS],
    searches: [FeatureSearch; PATHS],
}

impl SideBySide {
    #[inline(always)]
    fn new() -> Self {
        SideBySide {
            rays: [Ray::new(Vec3::ZERO, Vec3::X); PATHS],
            samplers: [const { PixelSample::placeholder() }; PATHS],
            colours: [Color::ZERO; PATHS],
            searches: [FeatureSearch::start(Layers::NONE); PATHS],
        }
    }

    /// Traces samples `samples` of each pixel `(x, column)` of `pixels` (of
    /// image row `y`; at most [`PATHS`] paths in all) side by side, and adds
    /// each pixel's to `row` in sample order, as one at a time would.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &mut self,
        scene: &Scene,
        y: u32,
        (pixels, samples): (&[(usize, u32)], Range<u32>),
        reference: &Ray,
        row: &mut RowMut,
        stats: &mut RenderStats,
        halt: &Halt,
    ) {
        let mut n = 0;
        for &(_, column) in pixels {
            let pixel_sampler = pixel_sampler(scene, column, y);
            for index in samples.clone() {
                (self.rays[n], self.samplers[n]) =
                    camera_sample(scene, column, y, &pixel_sampler, index);
                n += 1;
            }
        }
        let searches = if scene.settings.layers.need_features() {
            let searches = &mut self.searches[..n];
            searches.fill(FeatureSearch::start(scene.settings.layers));
            searches
        } else {
            &mut []
        };
        trace_paths(
            scene,
            &mut self.rays[..n],
            &mut self.samplers[..n],
            reference,
            &mut self.colours[..n],
            searches,
            &mut stats.rays,
            halt,
        );
        let per_pixel = samples.len().max(1);
        if !row.layers.is_empty() {
            let searches = &self.searches[..n];
            add_samples_with_features(row, stats, pixels, samples, &self.colours[..n], searches);
            return;
        }
        for (&(x, _), colours) in pixels.iter().zip(self.colours[..n].chunks(per_pixel)) {
            for (index, &c) in samples.clone().zip(colours) {
                stats.count(row.add(x, index, c));
            }
        }
    }
}

/// Adds sample `index` of pixel `x`, of colour `c` (and `features`, when
/// the film keeps layers), to `row`, and counts it in `stats`: a sample
/// traced alone.
fn add_sample(
    row: &mut RowMut,
    stats: &mut RenderStats,
    (x, index): (usize, u32),
    c: Color,
    features: &Features,
) {
    if row.layers.is_empty() {
        stats.count(row.add(x, index, c));
        return;
    }
    let mut unit = UnitFeatures::default();
    stats.count(row.add_with(x, index, c, features, &mut unit));
    row.add_unit_features(x, &unit);
}

/// Adds the samples `samples` of each pixel `(x, _)` of `pixels`, their
/// colours and features side by side in `colours` and `searches`, to
/// `row` in sample order, and counts them in `stats`, as dropped if the
/// film leaves them out; each pixel's albedos and normals are gathered and
/// added at its end (see [`UnitFeatures`]). Out of line, and once for all
/// the pixels traced together, so that the layers' code does not weigh on
/// the registers of the loop around it.
#[inline(never)]
fn add_samples_with_features(
    row: &mut RowMut,
    stats: &mut RenderStats,
    pixels: &[(usize, u32)],
    samples: Range<u32>,
    colours: &[Color],
    searches: &[FeatureSearch],
) {
    let per_pixel = samples.len().max(1);
    let colours = colours.chunks(per_pixel);
    for ((&(x, _), colours), searches) in pixels.iter().zip(colours).zip(searches.chunks(per_pixel))
    {
        let mut unit = UnitFeatures::default();
        for ((index, &c), s) in samples.clone().zip(colours).zip(searches) {
            stats.count(row.add_with(x, index, c, &s.features, &mut unit));
        }
        row.add_unit_features(x, &unit);
    }
}

/// The camera ray of sample `index` of pixel `(x, y)`, whose sampler is
/// `pixel_sampler`, and the sampler that goes on to serve its path.
#[inline(always)]
pub(crate) fn camera_sample(
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

/// Renders the whole image at the scene's samples per pixel.
pub fn render(scene: &Scene, progress: &(dyn Fn(u64) + Sync)) -> (Film, RenderStats) {
    let s = &scene.settings;
    let mut film = Film::new(s.width, s.height).with_layers(s.layers);
    let stats = render_samples(scene, &mut film, 0..s.samples_per_pixel, progress);
    (film, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Sum;
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
        // A mesh: eight-wide nodes and triangle packets.
        let mut desc = crate::bench::bunny_scene(crate::bench::BUNNY_235K);
        desc.render.width = 32;
        desc.render.height = Some(32);
        desc.render.samples_per_pixel = 37;
        let scene = Scene::from_desc(&desc).expect("the bunny compiles");
        same_bits_on_every_instruction_set(&scene);
    }

    fn same_bits_on_every_instruction_set(scene: &Scene) {
        let width = scene.settings.width;
        let isa = Isa::detect();
        // Which versions were compared (`cargo test -- --nocapture`): on a
        // processor without AVX2 only the baseline runs.
        eprintln!(
            "render rows compared: {} and {}",
            Isa::Baseline.name(),
            isa.name()
        );
        for y in 0..scene.settings.height {
            let render_with = |isa| {
                let mut film = Film::with_halves(width, 1);
                let row = film.rows_mut().collect::<Vec<_>>().pop().unwrap();
                let stats = render_row(isa, scene, (0, y), 0..37, row, None, &Halt::never());
                (film, stats)
            };
            let (base, a) = render_with(Isa::Baseline);
            let (best, b) = render_with(isa);
            assert_eq!(a, b, "row {y}: counts differ between baseline and {isa:?}");
            assert!(
                film_bits(&base) == film_bits(&best),
                "row {y}: baseline and {isa:?} differ"
            );
        }
    }

    /// A film's sums (whole and odd-sample halves) and counts, to compare.
    fn film_bits(f: &Film) -> (Vec<i128>, Vec<u32>, Vec<u32>) {
        let (sums, counts) = f.raw();
        let (odd, odd_counts) = f.raw_odd();
        let bits = sums.iter().chain(odd).flat_map(|s| s.0);
        (bits.collect(), counts.to_vec(), odd_counts.to_vec())
    }

    /// A pass of fewer samples a pixel than fill a bundle traces the paths
    /// of neighbouring pixels side by side (groups of up to 32 paths, so
    /// 70 pixels wide makes several groups): every pixel gets, bit for bit,
    /// the samples its paths give one at a time, whichever pixels are left
    /// out (adaptive sampling) and however many samples the pass holds.
    #[test]
    fn neighbouring_pixels_side_by_side_equal_paths_one_at_a_time() {
        let mut bunny =
            crate::bench::bunny_scene(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny.glb"));
        bunny.render.height = Some(12);
        let moving = builtin::find("bouncing-spheres").expect("built-in").desc();
        for mut desc in [builtin::cover(), bunny, moving] {
            desc.render.width = 70;
            let scene = Scene::from_desc(&desc).expect("compiles");
            let s = &scene.settings;
            let width = s.width as usize;
            // Every third pixel left out, and the first.
            let active: Vec<bool> = (0..width).map(|x| x % 3 != 0 && x > 0).collect();
            for samples in [0..1, 5..7, 2..5, 0..4, 3..8, 1..8, 0..12, 3..43] {
                for y in [0, s.height / 2] {
                    let mut together = Film::with_halves(s.width, 1);
                    let row = together.rows_mut().collect::<Vec<_>>().pop().unwrap();
                    let stats = render_row(
                        Isa::detect(),
                        &scene,
                        (0, y),
                        samples.clone(),
                        row,
                        Some(&active),
                        &Halt::never(),
                    );
                    let mut alone = Film::with_halves(s.width, 1);
                    let mut row = alone.rows_mut().collect::<Vec<_>>().pop().unwrap();
                    let mut expected = RenderStats::default();
                    for x in (0..width).filter(|&x| active[x]) {
                        let ps = pixel_sampler(&scene, x as u32, y);
                        for index in samples.clone() {
                            let (ray, mut sampler) = camera_sample(&scene, x as u32, y, &ps, index);
                            let (c, f) = crate::integrator::trace_path_features(
                                &scene,
                                ray,
                                &mut sampler,
                                &mut expected.rays,
                            );
                            add_sample(&mut row, &mut expected, (x, index), c, &f);
                        }
                    }
                    assert_eq!(stats, expected, "{}: {samples:?}, row {y}", desc.caption);
                    assert!(
                        film_bits(&together) == film_bits(&alone),
                        "{}: {samples:?}, row {y}",
                        desc.caption
                    );
                }
            }
        }
    }

    #[test]
    fn dropping_more_than_a_few_samples_in_ten_thousand_warns() {
        let stats = |samples, dropped| RenderStats {
            samples,
            rays: samples,
            dropped,
        };
        assert_eq!(stats(100_000, 0).dropped_warning(), None);
        assert_eq!(stats(100_000, 10).dropped_warning(), None);
        let some = stats(100_000, 11).dropped_warning().expect("warns");
        assert!(some.contains("11 of 100000 samples (0.01%)"), "{some}");
        assert!(!stats(100_000, 11).all_dropped());
        let all = stats(500, 500);
        assert!(all.all_dropped());
        assert!(all
            .dropped_warning()
            .expect("warns")
            .starts_with("every sample"));
        assert!(!stats(0, 0).all_dropped());
    }

    #[test]
    fn non_finite_samples_are_dropped_and_finite_ones_added() {
        let mut film = Film::with_halves(1, 1);
        {
            let mut row = film.rows_mut().collect::<Vec<_>>().pop().unwrap();
            assert!(row.add(0, 0, Color::new(0.25, 0.5, 2.0)));
            for bad in [
                Color::new(f32::NAN, 0.0, 0.0),
                Color::new(0.0, f32::INFINITY, 0.0),
                Color::new(0.0, 0.0, f32::NEG_INFINITY),
                // Beyond what a fixed-point sum holds (2⁶³).
                Color::new(0.0, 1e19, 0.0),
            ] {
                assert!(!row.add(0, 1, bad));
            }
            assert!(row.add(0, 3, Color::new(0.25, 0.5, 2.0)));
            assert!(row.add(0, 4, Color::new(1.0, 1.0, 1.0)));
        }
        let sum = |c| Sum::of(c).unwrap();
        assert_eq!(film.raw(), (&[sum([1.5, 2.0, 5.0])][..], &[3][..]));
        // Only sample 3 has an odd index among those added.
        assert_eq!(film.raw_odd(), (&[sum([0.25, 0.5, 2.0])][..], &[1][..]));
    }
}
