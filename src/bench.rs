//! Throughput benchmarks on fixed workloads: `lumen bench`.

use crate::render::{render, RenderStats};
use crate::scene::builtin;
use crate::scene::desc::SceneDesc;
use crate::scene::{Scene, SceneError};
use std::time::{Duration, Instant};

/// One benchmark workload.
#[derive(Clone, Debug)]
pub struct Workload {
    /// Short name.
    pub name: &'static str,
    /// The scene rendered.
    pub desc: SceneDesc,
}

/// The measured result of a workload: the median of several runs.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Workload name.
    pub name: &'static str,
    /// Counts of one run (identical in every run).
    pub stats: RenderStats,
    /// Median wall time.
    pub median: Duration,
    /// All run times, in run order.
    pub runs: Vec<Duration>,
}

impl Measurement {
    /// Median rays per second.
    pub fn rays_per_second(&self) -> f64 {
        self.stats.rays_per_second(self.median)
    }

    /// Median camera samples per second.
    pub fn samples_per_second(&self) -> f64 {
        self.stats.samples_per_second(self.median)
    }
}

/// The standard workloads: the cover at 400×225 and the three-ball scene,
/// at `spp` samples per pixel and depth 50.
pub fn standard_workloads(spp: u32) -> Vec<Workload> {
    let mut cover = builtin::cover();
    cover.render.width = 400;
    let mut three = builtin::find("metal-fuzz-0.2")
        .expect("built-in scene exists")
        .desc();
    three.render.width = 400;
    let mut list = vec![
        Workload {
            name: "cover-400x225",
            desc: cover,
        },
        Workload {
            name: "three-spheres-400x225",
            desc: three,
        },
    ];
    for w in &mut list {
        w.desc.render.samples_per_pixel = spp;
        w.desc.render.max_depth = 50;
    }
    list
}

/// Renders `workload` `runs` times (after one warm-up) and takes the median time.
pub fn measure(workload: &Workload, runs: usize) -> Result<Measurement, SceneError> {
    let scene = Scene::from_desc(&workload.desc)?;
    let _ = render(&scene, &|_| {});
    let mut times = Vec::with_capacity(runs);
    let mut stats = RenderStats::default();
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let (_, s) = render(&scene, &|_| {});
        times.push(start.elapsed());
        stats = s;
    }
    let mut sorted = times.clone();
    sorted.sort();
    Ok(Measurement {
        name: workload.name,
        stats,
        median: sorted[sorted.len() / 2],
        runs: times,
    })
}
