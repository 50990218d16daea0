//! The traversal anchor: a fixed set of rays recorded from a render, traced
//! through lumen's tree and, when built with the `embree` feature, through
//! Intel's Embree over the same shapes (`lumen bench --traversal`).
//!
//! A render's speed mixes the search for hits with everything else a path
//! does; this measures the search alone, against the intersector that sets
//! the bar for it, on the same rays and the same core. The rays are the
//! camera and bounce rays of the workload's paths (shadow rays are not
//! recorded), traced one at a time for their nearest hit in the order the
//! paths made them.

use crate::geometry::bvh::Hit;
use crate::isa::Isa;
use crate::math::Interval;
use crate::memory::{self, MemoryError};
use crate::ray::Ray;
use crate::render::camera_sample;
use crate::sampler::{PixelSampler, Sampler};
use crate::scene::Scene;
use std::time::{Duration, Instant};

/// Rays recorded from a render's paths.
#[derive(Clone, Debug, Default)]
pub struct RecordedRays {
    /// Every ray, in the order the paths made them.
    pub rays: Vec<Ray>,
    /// How many of them are camera rays.
    pub camera: usize,
}

/// The most rays [`record_rays`] keeps (512 MiB of them).
pub const MAX_RECORDED: usize = 1 << 24;

/// The camera and bounce rays of `scene`'s paths at `spp` samples per pixel
/// (the scene's own sampler, seed and depth), pixel after pixel, each path
/// followed to its end: what a render traces, less the shadow rays; the
/// first `limit` of them (at most [`MAX_RECORDED`]). Their memory is
/// counted and taken before the first is recorded.
pub fn record_rays(scene: &Scene, spp: u32, limit: usize) -> Result<RecordedRays, MemoryError> {
    let s = &scene.settings;
    let most = u64::from(s.width)
        .saturating_mul(u64::from(s.height))
        .saturating_mul(u64::from(spp))
        .saturating_mul(u64::from(s.max_depth.max(1)));
    let limit = most.min(limit.min(MAX_RECORDED) as u64) as usize;
    let mut recorded = RecordedRays {
        rays: memory::vec_for(limit as u64, "recording the rays")?,
        camera: 0,
    };
    for y in 0..s.height {
        for x in 0..s.width {
            let pixel_sampler = PixelSampler::new(s.sampler, s.seed, (x, y), s.width, spp);
            for index in 0..spp {
                if recorded.rays.len() == limit {
                    return Ok(recorded);
                }
                let (ray, mut sampler) = camera_sample(scene, x, y, &pixel_sampler, index);
                recorded.camera += 1;
                follow_path(scene, ray, &mut sampler, &mut recorded.rays, limit);
            }
        }
    }
    Ok(recorded)
}

/// Follows one path from its camera ray, as the path integrator does but
/// without sampling lights, pushing each segment's ray while `rays` holds
/// fewer than `limit`.
fn follow_path(
    scene: &Scene,
    mut ray: Ray,
    sampler: &mut impl Sampler,
    rays: &mut Vec<Ray>,
    limit: usize,
) {
    let mut from: Option<Hit> = None;
    for depth in 0..scene.settings.max_depth {
        if rays.len() == limit {
            return;
        }
        rays.push(ray);
        let Some(hit) = scene.intersect_leaving(&ray, from.as_ref(), f32::INFINITY) else {
            return;
        };
        let record = scene.record(&ray, hit);
        let material = scene.material(&record);
        let wo = -ray.direction;
        let Some(bsdf) = material.bsdf(&record, wo, &scene.textures) else {
            return;
        };
        sampler.start_bounce(depth);
        let Some(sample) = bsdf.sample(wo, sampler) else {
            return;
        };
        ray = Ray::timed(record.spawn_origin(sample.wi), sample.wi, ray.time());
        from = Some(hit);
    }
}

/// The nearest hit of each ray from distance 0: its distance and the shape
/// item it meets (numbered as [`crate::scene::PlacedShapes`]), or `None`.
pub type Found = Option<(f32, u32)>;

/// Traces `rays` through `scene`'s tree, one at a time, for their nearest
/// hits from distance 0, with the code a render would use on this
/// processor; returns them and the time taken.
pub fn trace_lumen(scene: &Scene, rays: &[Ray]) -> (Vec<Found>, Duration) {
    let mut found = Vec::with_capacity(rays.len());
    let start = Instant::now();
    match Isa::detect() {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => {
            // SAFETY: `Isa::Avx2` is only produced by `Isa::detect` when the
            // processor has every feature `trace_avx2` is compiled for.
            #[allow(unsafe_code)]
            unsafe {
                trace_avx2(scene, rays, &mut found)
            }
        }
        _ => trace(scene, rays, &mut found),
    }
    (found, start.elapsed())
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2")]
#[allow(unsafe_code)]
unsafe fn trace_avx2(scene: &Scene, rays: &[Ray], found: &mut Vec<Found>) {
    trace(scene, rays, found)
}

/// The loop of [`trace_lumen`], inlined into each instruction-set version.
#[inline(always)]
fn trace(scene: &Scene, rays: &[Ray], found: &mut Vec<Found>) {
    let all = Interval::new(0.0, f32::INFINITY);
    for ray in rays {
        found.push(scene.intersect(ray, all).map(|h| (h.t, h.index)));
    }
}

/// How far two intersectors agree on the same rays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Agreement {
    /// Rays compared.
    pub rays: usize,
    /// Rays both found to miss, or to hit the same shape at distances
    /// within a relative 10⁻³ of each other.
    pub same: usize,
    /// Rays one found to hit and the other to miss.
    pub hit_or_miss: usize,
    /// Rays both found to hit, at other shapes or distances.
    pub elsewhere: usize,
}

impl Agreement {
    /// Compares two lists of hits of the same rays.
    pub fn of(a: &[Found], b: &[Found]) -> Agreement {
        let mut agreement = Agreement {
            rays: a.len().min(b.len()),
            ..Agreement::default()
        };
        for (x, y) in a.iter().zip(b) {
            match (x, y) {
                (None, None) => agreement.same += 1,
                (Some((ta, ia)), Some((tb, ib)))
                    if ia == ib && (ta - tb).abs() <= 1e-3 * ta.abs().max(tb.abs()).max(1.0) =>
                {
                    agreement.same += 1
                }
                (Some(_), Some(_)) => agreement.elsewhere += 1,
                _ => agreement.hit_or_miss += 1,
            }
        }
        agreement
    }

    /// The share of rays on which both agree.
    pub fn fraction(&self) -> f64 {
        if self.rays == 0 {
            1.0
        } else {
            self.same as f64 / self.rays as f64
        }
    }
}
