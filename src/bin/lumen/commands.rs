//! `lumen gallery` and `lumen bench`.

use crate::{progress_bar, summary, write_stdout, SettingArgs};
use anyhow::{anyhow, Result};
use lumen::bench;
use lumen::render::RenderStats;
use lumen::scene::builtin::BUILTINS;
use lumen::scene::desc::SceneDesc;
use lumen::scene::hint;
use lumen::scene::Sampling;
use std::path::Path;
use std::time::Instant;

pub(crate) fn gallery_command(dir: &Path, args: &SettingArgs) -> Result<()> {
    let start = Instant::now();
    let mut total = RenderStats::default();
    let bar = progress_bar(BUILTINS.len() as u64);
    lumen::gallery::make_gallery(dir, &args.overrides(), &mut |_name, stats| {
        bar.inc(1);
        total.add(stats);
    })?;
    bar.finish_and_clear();
    errln!(
        "gallery of {} scenes written to {}",
        BUILTINS.len(),
        dir.join("index.html").display()
    );
    errln!("{}", summary(&total, &total, start.elapsed()));
    Ok(())
}

/// What a benchmark ran on: worker threads, cores and the code version.
fn machine() -> String {
    format!(
        "{} worker threads on {} cores ({} code)",
        rayon::current_num_threads(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        lumen::isa::Isa::detect().name()
    )
}

pub(crate) fn scaling_command(fields: &[usize], spp: u32, runs: u32) -> Result<()> {
    outln!(
        "lumen bench: cover-like sphere fields at 400x225, {}, {spp} spp, depth 50, median of {runs} runs",
        machine()
    )?;
    outln!(
        "{:>9} {:>9} {:>9} {:>10} {:>10} {:>10} {:>12}",
        "spheres",
        "build s",
        "BVH MB",
        "rays",
        "median s",
        "M rays/s",
        "M samples/s"
    )?;
    for &n in fields {
        let p = bench::measure_field(n, spp, runs as usize)
            .map_err(|e| anyhow!("field of {n} spheres: {e}"))?;
        let m = &p.measurement;
        outln!(
            "{:>9} {:>9.3} {:>9.1} {:>10} {:>10.3} {:>10.2} {:>12.2}",
            p.spheres,
            p.build.as_secs_f64(),
            p.bvh_bytes as f64 / 1e6,
            m.stats.rays,
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6
        )?;
    }
    Ok(())
}

/// The standard workloads at `spp`, or the one named `only`.
fn standard_workloads(spp: u32, only: Option<&str>) -> Result<Vec<bench::Workload>> {
    let workloads: Vec<_> = bench::standard_workloads(spp)
        .into_iter()
        .filter(|w| only.is_none_or(|name| w.name == name))
        .collect();
    if workloads.is_empty() {
        let names: Vec<_> = bench::standard_workloads(1)
            .iter()
            .map(|w| w.name)
            .collect();
        let only = only.unwrap_or("");
        return Err(anyhow!(
            "no workload named '{only}'; the workloads are {}",
            hint::listing(only, names, str::to_string)
        ));
    }
    Ok(workloads)
}

pub(crate) fn bench_command(spp: u32, runs: u32, only: Option<&str>) -> Result<()> {
    let workloads = standard_workloads(spp, only)?;
    outln!(
        "lumen bench: {}, {spp} spp, median of {runs} runs",
        machine()
    )?;
    outln!(
        "{:<24} {:>10} {:>14} {:>16} {:>6}",
        "workload",
        "median s",
        "M rays/s",
        "M samples/s",
        "depth"
    )?;
    for w in workloads {
        let m = bench::measure(&w, runs as usize).map_err(|e| anyhow!("{}: {e}", w.name))?;
        outln!(
            "{:<24} {:>10.3} {:>14.2} {:>16.2} {:>6}",
            m.name,
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6,
            w.desc.render.max_depth
        )?;
    }
    Ok(())
}

pub(crate) fn instances_command(counts: &[usize], spp: u32, runs: u32) -> Result<()> {
    outln!(
        "lumen bench: fields of instanced 235,136-triangle bunnies at 400x225, {}, {spp} spp, depth 8, median of {runs} runs",
        machine()
    )?;
    outln!(
        "{:>9} {:>14} {:>9} {:>11} {:>11} {:>10} {:>10} {:>12}",
        "instances",
        "triangles",
        "build s",
        "geometry MB",
        "peak MB",
        "median s",
        "M rays/s",
        "M samples/s"
    )?;
    for &n in counts {
        let p = bench::measure_instances(n, spp, runs as usize)
            .map_err(|e| anyhow!("{n} instances: {e}"))?;
        let m = &p.measurement;
        outln!(
            "{:>9} {:>14} {:>9.3} {:>11.1} {:>11} {:>10.3} {:>10.2} {:>12.2}",
            p.instances,
            p.instances as u64 * 235_136,
            p.build.as_secs_f64(),
            p.geometry_bytes as f64 / 1e6,
            p.peak_bytes
                .map_or("n/a".to_string(), |b| format!("{:.1}", b as f64 / 1e6)),
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6
        )?;
    }
    Ok(())
}

/// The efficiency workloads, or the one named `only`.
fn efficiency_workloads(only: Option<&str>) -> Result<Vec<(&'static str, SceneDesc)>> {
    let all = bench::efficiency::workloads();
    let names: Vec<_> = all.iter().map(|(n, _)| *n).collect();
    let chosen: Vec<_> = all
        .iter()
        .filter(|(name, _)| only.is_none_or(|o| *name == o))
        .cloned()
        .collect();
    if chosen.is_empty() {
        let only = only.unwrap_or("");
        return Err(anyhow!(
            "no efficiency workload named '{only}'; they are {}",
            hint::listing(only, names, str::to_string)
        ));
    }
    Ok(chosen)
}

pub(crate) fn adaptive_command(target: f64, spp: u32, only: Option<&str>) -> Result<()> {
    let workloads = efficiency_workloads(only)?;
    outln!(
        "lumen bench --adaptive {target}: {}, up to {spp} spp (sobol), errors against {} spp",
        machine(),
        4 * spp
    )?;
    outln!(
        "{:<22} {:<10} {:>10} {:>10} {:>10} {:>10}",
        "workload",
        "noise",
        "seconds",
        "mean spp",
        "rms error",
        "95% error"
    )?;
    for (name, mut desc) in workloads {
        desc.render.sampler = Sampling::Sobol;
        let points = bench::efficiency::measure_adaptive(&desc, target, spp)
            .map_err(|e| anyhow!("{name}: {e}"))?;
        let pixels = f64::from(desc.render.width) * f64::from(desc.render.height.unwrap_or(1));
        for (label, p) in [
            (format!("{target}"), &points[0]),
            ("none".into(), &points[1]),
        ] {
            outln!(
                "{:<22} {:<10} {:>10.3} {:>10.1} {:>10.4} {:>10.4}",
                name,
                label,
                p.seconds,
                p.samples as f64 / pixels,
                p.rms_error,
                p.p95_error
            )?;
        }
    }
    Ok(())
}

pub(crate) fn efficiency_command(
    spp: u32,
    runs: u32,
    only: Option<&str>,
    samplers: &[Sampling],
) -> Result<()> {
    let workloads = efficiency_workloads(only)?;
    outln!(
        "lumen bench --efficiency: {}, {spp} spp, seeds 1 and 2, median of {runs} runs each",
        machine()
    )?;
    outln!(
        "{:<22} {:<12} {:<10} {:>10} {:>12} {:>12} {:>9} {:>14}",
        "workload",
        "sampler",
        "integrator",
        "median s",
        "variance",
        "efficiency",
        "relative",
        "s to rmse 0.01"
    )?;
    for (name, mut desc) in workloads {
        let mut first = None;
        for integrator in bench::efficiency::integrators() {
            desc.render.integrator = integrator;
            for &sampler in samplers {
                let e = bench::efficiency::measure(&desc, sampler, spp, runs as usize)
                    .map_err(|e| anyhow!("{name}: {e}"))?;
                let base = *first.get_or_insert(e.efficiency());
                outln!(
                    "{:<22} {:<12} {:<10} {:>10.3} {:>12.4e} {:>12.4e} {:>8.2}x {:>14.1}",
                    name,
                    format!("{sampler:?}").to_lowercase(),
                    format!("{integrator:?}").to_lowercase(),
                    e.seconds,
                    e.variance,
                    e.efficiency(),
                    e.efficiency() / base,
                    // Variance falls as 1/time: reaching a variance of
                    // 0.01² takes 1 / (efficiency × 0.01²) seconds.
                    1.0 / (e.efficiency() * 1e-4)
                )?;
            }
        }
    }
    Ok(())
}

/// `lumen bench --traversal`: each workload's recorded rays traced through
/// lumen's tree and, in a build with the `embree` feature, through Embree's
/// (see [`bench::traversal`]).
pub(crate) fn traversal_command(spp: u32, runs: u32, only: Option<&str>) -> Result<()> {
    use bench::median;
    use bench::traversal::{record_rays, trace_lumen, Agreement, MAX_RECORDED};
    let workloads = standard_workloads(spp, only)?;
    outln!(
        "lumen bench --traversal: the camera and bounce rays of {spp} spp, one thread, nearest hits one ray at a time, median of {runs} runs ({} code)",
        lumen::isa::Isa::detect().name()
    )?;
    let peers = traversal_peers();
    let mut header = format!(
        "{:<24} {:>10} {:>8} {:>11}",
        "workload", "rays", "camera", "lumen M/s"
    );
    for (name, _) in &peers {
        header += &format!(
            " {:>14} {:>6} {:>9}",
            format!("{name} M/s"),
            "lumen/",
            "agree"
        );
    }
    outln!("{header}")?;
    for w in workloads {
        let scene =
            lumen::scene::Scene::from_desc(&w.desc).map_err(|e| anyhow!("{}: {e}", w.name))?;
        let recorded =
            record_rays(&scene, spp, MAX_RECORDED).map_err(|e| anyhow!("{}: {e}", w.name))?;
        let rays = &recorded.rays;
        // Each tracer's hits, lumen's kept for the comparison.
        let found_bytes = std::mem::size_of::<bench::traversal::Found>() as u64;
        lumen::memory::check(
            rays.len() as u64 * found_bytes * (2 + peers.len() as u64),
            "keeping the rays' hits",
        )
        .map_err(|e| anyhow!("{}: {e}", w.name))?;
        let tracers: Vec<_> = peers
            .iter()
            .map(|(name, make)| make(&scene).map_err(|e| anyhow!("{}: {name}: {e}", w.name)))
            .collect::<Result<_>>()?;
        let (lumen_found, _) = trace_lumen(&scene, rays);
        let mut lumen_times = Vec::new();
        let mut peer_times = vec![Vec::new(); tracers.len()];
        let mut agreements = Vec::new();
        for run in 0..runs {
            lumen_times.push(trace_lumen(&scene, rays).1);
            for (k, trace) in tracers.iter().enumerate() {
                let (found, time) = trace(rays);
                peer_times[k].push(time);
                if run == 0 {
                    agreements.push(Agreement::of(&lumen_found, &found));
                }
            }
        }
        let per_second = |t: &[std::time::Duration]| rays.len() as f64 / median(t).as_secs_f64();
        let lumen_rate = per_second(&lumen_times);
        let mut line = format!(
            "{:<24} {:>10} {:>7.0}% {:>11.2}",
            w.name,
            rays.len(),
            100.0 * recorded.camera as f64 / rays.len().max(1) as f64,
            lumen_rate / 1e6
        );
        for (times, agreement) in peer_times.iter().zip(&agreements) {
            let rate = per_second(times);
            line += &format!(
                " {:>14.2} {:>6.3} {:>8.3}%",
                rate / 1e6,
                lumen_rate / rate,
                100.0 * agreement.fraction()
            );
        }
        outln!("{line}")?;
    }
    if peers.is_empty() {
        outln!("Embree is not in this build: build with `cargo build --release --features embree` (needs Embree 3, Debian's libembree-dev) to trace the same rays through it")?;
    }
    Ok(())
}

/// A peer's tracer of recorded rays, made for a scene.
type Tracer =
    Box<dyn Fn(&[lumen::ray::Ray]) -> (Vec<bench::traversal::Found>, std::time::Duration)>;
/// A peer's name and how to make its tracer.
type Peer = (
    &'static str,
    fn(&lumen::scene::Scene) -> Result<Tracer, String>,
);

/// The intersectors this build can trace recorded rays with besides
/// lumen's: Embree with AVX2, and with AVX-512 where the processor has it.
fn traversal_peers() -> Vec<Peer> {
    #[cfg(feature = "embree")]
    {
        use bench::embree::{EmbreeIsa, EmbreeScene};
        fn embree(scene: &lumen::scene::Scene, isa: EmbreeIsa) -> Result<Tracer, String> {
            let shapes = scene
                .placed_shapes()
                .ok_or("the scene places shapes by instances, which the anchor does not export")?;
            let embree = EmbreeScene::new(&shapes, isa)?;
            Ok(Box::new(move |rays| embree.trace(rays)))
        }
        let mut peers: Vec<Peer> = vec![("embree-avx2", |s| embree(s, EmbreeIsa::Avx2))];
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
        {
            peers.push(("embree-avx512", |s| embree(s, EmbreeIsa::Avx512)));
        }
        peers
    }
    #[cfg(not(feature = "embree"))]
    Vec::new()
}
