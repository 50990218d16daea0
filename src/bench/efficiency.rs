//! Efficiency: how soon a render is clean, not only how fast it traces.
//!
//! The efficiency of an estimator is 1 / (variance × time): twice as
//! efficient means the same noise in half the time. A workload is rendered
//! with two seeds; the mean over pixels and channels of (A − B)² / 2 is the
//! per-pixel variance of one render (A and B are independent estimates of
//! the same image), and the time is the median time of a render.

use super::{time_renders, BUNNY_235K};
use crate::film::Film;
use crate::render::render;
use crate::scene::builtin;
use crate::scene::desc::{BackgroundDesc, DielectricDesc, MaterialDesc, MetalDesc, SceneDesc};
use crate::scene::file::Format;
use crate::scene::{Integrator, Sampling, Scene, SceneError};
use std::time::Duration;

/// The spheres of the efficiency benchmark: the cover's field at 400×225
/// made diffuse and mirror under a white sky. Glass becomes a white mirror,
/// fuzzy metal a sharp one, the sky a uniform white 1, and the lens a
/// pinhole; depth 50. `scripts/peers/spheres-scene.toml` is this scene
/// for the peer renderers.
pub fn sky_spheres() -> SceneDesc {
    let mut desc = builtin::cover();
    desc.caption = "the cover's spheres, diffuse and mirror, under a white sky".into();
    desc.render.width = 400;
    desc.render.height = Some(225);
    desc.render.max_depth = 50;
    desc.camera.defocus_angle = 0.0;
    desc.background = BackgroundDesc::Solid {
        color: [1.0, 1.0, 1.0],
    };
    for material in desc.materials.values_mut() {
        match material {
            MaterialDesc::Dielectric(DielectricDesc { .. }) => {
                *material = MaterialDesc::Metal(MetalDesc {
                    albedo: [1.0, 1.0, 1.0].into(),
                    fuzz: 0.0,
                    ..Default::default()
                })
            }
            MaterialDesc::Metal(MetalDesc { fuzz, .. }) => *fuzz = 0.0,
            _ => {}
        }
    }
    // As a scene file renders it: `integrator` at its default.
    desc.render.integrator = Default::default();
    desc
}

/// The materials workload: spheres of gold at two roughnesses, a silver
/// mirror, frosted glass, red plastic and a diffuse control on a grey floor
/// under a white sky, 320 × 180. It is the scene the peer renderers
/// compare against, read from the same file
/// (`scripts/peers/materials-scene.toml`).
pub fn materials_spheres() -> SceneDesc {
    let text = include_str!("../../scripts/peers/materials-scene.toml");
    crate::scene::file::SceneFile::parse("materials-scene.toml", text.to_string(), Format::Toml)
        .expect("the materials workload's scene file is valid")
        .desc
}

/// The efficiency workloads: [`sky_spheres`], the mesh workload, the
/// Cornell box at 300 × 300 (lit by its ceiling light alone) and
/// [`materials_spheres`].
pub fn workloads() -> Vec<(&'static str, SceneDesc)> {
    let mut cornell = builtin::cornell_box();
    cornell.render.width = 300;
    vec![
        ("sky-spheres-400x225", sky_spheres()),
        ("bunny-235k-400x400", super::bunny_scene(BUNNY_235K)),
        ("cornell-box-300x300", cornell),
        ("materials-320x180", materials_spheres()),
    ]
}

/// The integrators compared on every workload: `path` (next-event
/// estimation where there are lights, Russian roulette) and `bsdf`.
pub fn integrators() -> [Integrator; 2] {
    [Integrator::Path, Integrator::Bsdf]
}

/// One workload's efficiency with one sampler.
#[derive(Clone, Debug)]
pub struct Efficiency {
    /// Median time of one render.
    pub seconds: f64,
    /// Mean per-pixel variance of one render (linear radiance, per channel).
    pub variance: f64,
}

impl Efficiency {
    /// 1 / (variance × seconds).
    pub fn efficiency(&self) -> f64 {
        1.0 / (self.variance * self.seconds)
    }
}

/// Renders `desc` with `sampler` at `spp`, with seeds 1 and 2, each `runs`
/// times after a warm-up (whose image gives the variance), and returns its
/// efficiency.
pub fn measure(
    desc: &SceneDesc,
    sampler: Sampling,
    spp: u32,
    runs: usize,
) -> Result<Efficiency, SceneError> {
    let mut films = Vec::new();
    let mut times: Vec<Duration> = Vec::new();
    for seed in [1, 2] {
        let mut desc = desc.clone();
        desc.render.sampler = sampler;
        desc.render.samples_per_pixel = spp;
        desc.render.seed = seed;
        let scene = Scene::from_desc(&desc)?;
        // The warm-up render's film is the seed's image.
        films.push(render(&scene, &|_| {}).0);
        times.extend(time_renders(&scene, runs).0);
    }
    Ok(Efficiency {
        seconds: super::median(&times).as_secs_f64(),
        variance: variance_between(&films[0], &films[1]),
    })
}

/// The per-pixel variance of one of two independent renders `a` and `b` of
/// the same image: the mean over pixels and channels of (A − B)² / 2.
pub fn variance_between(a: &Film, b: &Film) -> f64 {
    assert_eq!(
        (a.width(), a.height()),
        (b.width(), b.height()),
        "films of different sizes"
    );
    let sum: f64 = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| f64::from((p - q).length_squared()))
        .sum();
    let n = f64::from(a.width()) * f64::from(a.height());
    sum / (2.0 * 3.0 * n)
}

/// A render with and without adaptive sampling, measured against a
/// reference (see [`measure_adaptive`]).
#[derive(Clone, Debug)]
pub struct AdaptivePoint {
    /// Seconds of the render.
    pub seconds: f64,
    /// Camera samples taken.
    pub samples: u64,
    /// Root mean square of the pixels' relative errors against the reference.
    pub rms_error: f64,
    /// The 95th percentile of the pixels' relative errors.
    pub p95_error: f64,
}

/// Renders `desc` at up to `spp` with `target` as its noise target and
/// without one (seed 1 each), and a reference at 4 × `spp` (seed 2), and
/// measures both renders' errors against it: relative errors as adaptive
/// sampling estimates them (channel mean of |difference|, over the
/// reference's channel mean, at least [`crate::adaptive::DARK`]).
pub fn measure_adaptive(
    desc: &SceneDesc,
    target: f64,
    spp: u32,
) -> Result<[AdaptivePoint; 2], SceneError> {
    use crate::progressive::Session;
    use std::sync::atomic::AtomicBool;
    use std::time::Instant;
    let mut desc = desc.clone();
    desc.render.samples_per_pixel = spp;
    desc.render.seed = 1;
    let mut reference = desc.clone();
    reference.render.samples_per_pixel = 4 * spp;
    reference.render.seed = 2;
    reference.render.noise_target = None;
    let reference = render(&Scene::from_desc(&reference)?, &|_| {}).0;
    let mut points = Vec::new();
    for noise_target in [Some(target), None] {
        desc.render.noise_target = noise_target;
        let mut session = Session::with_scene(&desc, Scene::from_desc(&desc)?).map_err(|e| {
            SceneError::Invalid {
                field: "render".into(),
                message: e.to_string(),
            }
        })?;
        let start = Instant::now();
        session
            .run(&AtomicBool::new(false), None, &|_| {}, &mut |_, _| {
                Ok::<(), ()>(())
            })
            .expect("the pass callback never fails");
        let seconds = start.elapsed().as_secs_f64();
        let film = session.film();
        let mut errors: Vec<f64> = (0..film.len())
            .map(|i| {
                let (a, r) = (film.mean(i), reference.mean(i));
                let level = (r.element_sum() / 3.0).max(crate::adaptive::DARK);
                f64::from((a - r).abs().element_sum() / 3.0 / level)
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        points.push(AdaptivePoint {
            seconds,
            samples: session.stats().samples,
            rms_error: rms,
            p95_error: errors[errors.len() * 95 / 100],
        });
    }
    Ok([points[0].clone(), points[1].clone()])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Sum;

    #[test]
    fn sky_spheres_has_no_glass_no_fuzz_and_a_white_sky() {
        let desc = sky_spheres();
        assert!(desc.materials.values().all(|m| match m {
            MaterialDesc::Metal(MetalDesc { fuzz, .. }) => *fuzz == 0.0,
            MaterialDesc::Diffuse(_) => true,
            _ => false,
        }));
        assert_eq!(
            desc.background,
            BackgroundDesc::Solid {
                color: [1.0, 1.0, 1.0]
            }
        );
        assert_eq!(desc.objects.len(), builtin::cover().objects.len());
    }

    #[test]
    fn adaptive_measurement_takes_fewer_samples_and_measures_errors() {
        let mut desc = sky_spheres();
        desc.render.width = 32;
        desc.render.height = Some(18);
        desc.render.sampler = Sampling::Sobol;
        let [adaptive, full] = measure_adaptive(&desc, 0.2, 64).unwrap();
        assert_eq!(full.samples, 32 * 18 * 64);
        assert!(adaptive.samples < full.samples, "{adaptive:?}");
        for p in [&adaptive, &full] {
            assert!(p.rms_error > 0.0 && p.rms_error.is_finite(), "{p:?}");
            assert!(p.p95_error >= 0.0 && p.p95_error <= 10.0 * p.rms_error + 1.0);
        }
    }

    #[test]
    fn variance_between_two_films_is_half_their_mean_squared_difference() {
        let sums = |v| vec![Sum::of([v; 3]).unwrap(), Sum::ZERO];
        let a = Film::from_raw(2, 1, sums(1.0), vec![1, 1]).unwrap();
        let b = Film::from_raw(2, 1, sums(3.0), vec![1, 1]).unwrap();
        // Differences 2, 2, 2, 0, 0, 0: mean square 2, half of it 1.
        assert_eq!(variance_between(&a, &b), 1.0);
    }
}
