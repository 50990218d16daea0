//! The `lumen` command: a thin layer over the library.

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use lumen::bench;
use lumen::output;
use lumen::render::{render, RenderStats};
use lumen::scene::builtin::{self, BUILTINS};
use lumen::scene::{Overrides, Scene, SceneDesc};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// lumen: a physically based path tracer following Ray Tracing in One Weekend.
#[derive(Parser)]
#[command(name = "lumen", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a built-in scene to an image file (.ppm, .png, .pfm or .exr).
    Render {
        /// Name of a built-in scene (see `lumen scenes`).
        scene: String,
        /// Output image; the extension chooses the format.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        settings: SettingArgs,
    },
    /// List the built-in scenes with their captions.
    Scenes,
    /// Render every built-in scene into DIR, with an index.html.
    Gallery {
        /// Folder for the images and index.html (created if missing).
        dir: PathBuf,
        #[command(flatten)]
        settings: SettingArgs,
    },
    /// Measure throughput (rays/s, samples/s) on fixed workloads.
    Bench {
        /// Samples per pixel of each workload.
        #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..))]
        spp: u32,
        /// Timed runs per workload; the median is reported.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
        runs: u32,
        /// Worker threads (default: one per core).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        threads: Option<u32>,
        /// Instead of the standard workloads, render cover-like fields of
        /// 10², 10³, 10⁴, 10⁵ and 10⁶ small spheres (how cost grows with the scene).
        #[arg(long, conflicts_with = "field")]
        scaling: bool,
        /// Render only the cover-like field of about N small spheres (to measure
        /// one size's peak memory with /usr/bin/time -v).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
        field: Option<u64>,
    },
}

#[derive(Args, Clone, Default)]
struct SettingArgs {
    /// Image width in pixels (the height follows the aspect ratio).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    width: Option<u32>,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    spp: Option<u32>,
    /// Maximum path depth in ray segments (1 = no bounces).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    depth: Option<u32>,
    /// Random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    threads: Option<u32>,
}

impl SettingArgs {
    fn overrides(&self) -> Overrides {
        Overrides {
            width: self.width,
            samples_per_pixel: self.spp,
            max_depth: self.depth,
            seed: self.seed,
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("lumen: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render {
            scene,
            output,
            settings,
        } => with_threads(settings.threads, || {
            render_command(&scene, &output, &settings)
        }),
        Command::Scenes => {
            let width = BUILTINS.iter().map(|b| b.name.len()).max().unwrap_or(0);
            for b in BUILTINS {
                println!("{:width$}  {}", b.name, b.caption);
            }
            Ok(())
        }
        Command::Gallery { dir, settings } => {
            with_threads(settings.threads, || gallery_command(&dir, &settings))
        }
        Command::Bench {
            spp,
            runs,
            threads,
            scaling,
            field,
        } => with_threads(threads, || {
            let fields: Vec<usize> = match (scaling, field) {
                (true, _) => vec![100, 1_000, 10_000, 100_000, 1_000_000],
                (false, Some(n)) => vec![n as usize],
                (false, None) => return bench_command(spp, runs),
            };
            scaling_command(&fields, spp, runs)
        }),
    }
}

/// Runs `f` on a thread pool of `threads` workers, or on rayon's default pool.
fn with_threads<T>(threads: Option<u32>, f: impl FnOnce() -> Result<T> + Send) -> Result<T>
where
    T: Send,
{
    match threads {
        None => f(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build()
            .context("cannot start worker threads")?
            .install(f),
    }
}

fn load_scene(name: &str) -> Result<SceneDesc> {
    if let Some(b) = builtin::find(name) {
        return Ok(b.desc());
    }
    let closest = BUILTINS
        .iter()
        .map(|b| (strsim_distance(name, b.name), b.name))
        .min()
        .filter(|(d, _)| *d <= 3)
        .map(|(_, n)| format!(" (did you mean '{n}'?)"))
        .unwrap_or_default();
    bail!("unknown scene '{name}'{closest}; `lumen scenes` lists the built-in scenes")
}

/// Levenshtein distance, for "did you mean" hints.
fn strsim_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

fn render_command(name: &str, out: &Path, args: &SettingArgs) -> Result<()> {
    let mut desc = load_scene(name)?;
    args.overrides().apply(&mut desc);
    let scene = Scene::from_desc(&desc).with_context(|| format!("scene '{name}'"))?;
    output::ImageFormat::from_path(out)?;
    output::check_writable(out)?;
    let s = &scene.settings;
    let total = u64::from(s.width) * u64::from(s.height) * u64::from(s.samples_per_pixel);
    let bar = progress_bar(total);
    let start = Instant::now();
    let (film, stats) = render(&scene, &|n| bar.inc(n));
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    output::write_image(out, &film, s.gamma)?;
    eprintln!(
        "{name}: {}x{} at {} spp, depth {}, written to {}",
        s.width,
        s.height,
        s.samples_per_pixel,
        s.max_depth,
        out.display()
    );
    eprintln!("{}", summary(&stats, elapsed));
    Ok(())
}

fn summary(stats: &RenderStats, elapsed: Duration) -> String {
    format!(
        "time {:.2} s, {:.2} M samples/s, {:.2} M rays/s, {} rays, {} dropped samples",
        elapsed.as_secs_f64(),
        stats.samples_per_second(elapsed) / 1e6,
        stats.rays_per_second(elapsed) / 1e6,
        stats.rays,
        stats.dropped
    )
}

fn progress_bar(total: u64) -> ProgressBar {
    // indicatif draws nothing when stderr is not a terminal.
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta}",
        )
        .expect("progress template is valid"),
    );
    bar
}

fn gallery_command(dir: &Path, args: &SettingArgs) -> Result<()> {
    let start = Instant::now();
    let mut total = RenderStats::default();
    let bar = progress_bar(BUILTINS.len() as u64);
    lumen::gallery::make_gallery(dir, &args.overrides(), &mut |name, stats| {
        bar.inc(1);
        bar.set_message(name.to_string());
        total.add(stats);
    })?;
    bar.finish_and_clear();
    eprintln!(
        "gallery of {} scenes written to {}",
        BUILTINS.len(),
        dir.join("index.html").display()
    );
    eprintln!("{}", summary(&total, start.elapsed()));
    Ok(())
}

fn scaling_command(fields: &[usize], spp: u32, runs: u32) -> Result<()> {
    println!(
        "lumen bench: cover-like sphere fields at 400x225, {} worker threads on {} cores, {spp} spp, depth 50, median of {runs} runs",
        rayon::current_num_threads(),
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    println!(
        "{:>9} {:>9} {:>9} {:>10} {:>10} {:>10} {:>12}",
        "spheres", "build s", "BVH MB", "rays", "median s", "M rays/s", "M samples/s"
    );
    for &n in fields {
        let p = bench::measure_field(n, spp, runs as usize)
            .map_err(|e| anyhow!("field of {n} spheres: {e}"))?;
        let m = &p.measurement;
        println!(
            "{:>9} {:>9.3} {:>9.1} {:>10} {:>10.3} {:>10.2} {:>12.2}",
            p.spheres,
            p.build.as_secs_f64(),
            p.bvh_bytes as f64 / 1e6,
            m.stats.rays,
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6
        );
    }
    Ok(())
}

fn bench_command(spp: u32, runs: u32) -> Result<()> {
    println!(
        "lumen bench: {} worker threads on {} cores, {spp} spp, depth 50, median of {runs} runs",
        rayon::current_num_threads(),
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    println!(
        "{:<24} {:>10} {:>14} {:>16}",
        "workload", "median s", "M rays/s", "M samples/s"
    );
    for w in bench::standard_workloads(spp) {
        let m = bench::measure(&w, runs as usize).map_err(|e| anyhow!("{}: {e}", w.name))?;
        println!(
            "{:<24} {:>10.3} {:>14.2} {:>16.2}",
            m.name,
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6
        );
    }
    Ok(())
}
