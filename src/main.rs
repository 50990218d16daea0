//! The `lumen` command: a thin layer over the library.

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use lumen::bench;
use lumen::checkpoint::{self, Checkpoint};
use lumen::output;
use lumen::progressive::{parse_duration, Session, SessionError, StopReason};
use lumen::render::RenderStats;
use lumen::scene::builtin::{self, BUILTINS};
use lumen::scene::file::{self, Format, SceneFile};
use lumen::scene::{hint, Overrides, Scene, SceneDesc};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

/// Most worker threads accepted by `--threads` (far more than any machine
/// lumen runs on has cores; each thread costs a stack).
const MAX_THREADS: i64 = 1024;

/// lumen: a physically based path tracer following Ray Tracing in One Weekend.
#[derive(Parser)]
#[command(name = "lumen", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a built-in scene or a scene file to an image file (.ppm, .png, .pfm or .exr).
    Render {
        /// Name of a built-in scene (see `lumen scenes`) or a scene file
        /// (.toml or .json, see docs/scene-format.md). Command-line settings
        /// override the scene's own.
        scene: String,
        /// Output image; the extension chooses the format.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        settings: SettingArgs,
        #[command(flatten)]
        progressive: ProgressiveArgs,
    },
    /// List the built-in scenes with their captions, or export one as a file.
    Scenes {
        #[command(subcommand)]
        action: Option<ScenesCommand>,
    },
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
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_THREADS))]
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

#[derive(Subcommand)]
enum ScenesCommand {
    /// Write a built-in scene (or convert a scene file) as a scene file.
    Export {
        /// Name of a built-in scene, or a scene file to convert.
        name: String,
        /// Output file (default: standard output); .toml or .json chooses the format.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Format when writing to standard output.
        #[arg(long, value_enum, default_value_t = FormatArg::Toml)]
        format: FormatArg,
    },
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FormatArg {
    Toml,
    Json,
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
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_THREADS))]
    threads: Option<u32>,
}

/// How a render is saved, stopped and resumed.
#[derive(Args, Clone, Default)]
struct ProgressiveArgs {
    /// Checkpoint file, saved during the render so that it can be resumed
    /// [default: the output path + .lumen-ckpt].
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Save the image and the checkpoint at most this often (e.g. 30s, 5m)
    /// instead of after every pass.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    checkpoint_interval: Option<Duration>,
    /// Continue the render saved in the checkpoint; the scene and settings
    /// must be the same as when it was made.
    #[arg(long)]
    resume: bool,
    /// Stop after the last pass that ends within this time (e.g. 90s, 10m,
    /// 2h) and write the image; --spp stays the upper bound.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    time_limit: Option<Duration>,
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

/// Exit status of a render stopped by Ctrl-C or SIGTERM (128 + SIGINT).
const EXIT_INTERRUPTED: u8 = 130;

/// Writes to standard output. A closed pipe (`lumen scenes | head -1`) ends
/// the output quietly; any other failure is an error, never a panic.
fn write_stdout(text: &str) -> Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        result => result.context("cannot write to standard output"),
    }
}

/// `println!` through [`write_stdout`].
macro_rules! outln {
    ($($arg:tt)*) => {
        write_stdout(&format!("{}\n", format_args!($($arg)*)))
    };
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("lumen: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Render {
            scene,
            output,
            settings,
            progressive,
        } => with_threads(settings.threads, || {
            render_command(&scene, &output, &settings, &progressive)
        }),
        Command::Scenes { action: None } => {
            let width = BUILTINS.iter().map(|b| b.name.len()).max().unwrap_or(0);
            for b in BUILTINS {
                outln!("{:width$}  {}", b.name, b.caption)?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Scenes {
            action:
                Some(ScenesCommand::Export {
                    name,
                    output,
                    format,
                }),
        } => {
            export_command(&name, output.as_deref(), format)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Gallery { dir, settings } => {
            with_threads(settings.threads, || gallery_command(&dir, &settings))?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench {
            spp,
            runs,
            threads,
            scaling,
            field,
        } => {
            with_threads(threads, || {
                let fields: Vec<usize> = match (scaling, field) {
                    (true, _) => vec![100, 1_000, 10_000, 100_000, 1_000_000],
                    (false, Some(n)) => vec![n as usize],
                    (false, None) => return bench_command(spp, runs),
                };
                scaling_command(&fields, spp, runs)
            })?;
            Ok(ExitCode::SUCCESS)
        }
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

/// Where a scene comes from: a built-in name or a file.
enum SceneSource {
    Builtin(SceneDesc),
    File(SceneFile),
}

impl SceneSource {
    fn desc(&self) -> &SceneDesc {
        match self {
            SceneSource::Builtin(d) => d,
            SceneSource::File(f) => &f.desc,
        }
    }

    /// The description with the command-line overrides, validated, so that
    /// a mistake in a file is reported with its line and column before any
    /// work starts.
    fn resolve(&self, name: &str, overrides: &Overrides) -> Result<SceneDesc> {
        let mut desc = self.desc().clone();
        overrides.apply(&mut desc);
        match self {
            SceneSource::Builtin(_) => {
                Scene::from_desc(&desc).with_context(|| format!("scene '{name}'"))?;
            }
            SceneSource::File(f) => {
                f.compile(overrides)?;
            }
        }
        Ok(desc)
    }
}

/// A built-in scene by name, or else a scene file by path.
fn load_scene(name: &str) -> Result<SceneSource> {
    if let Some(b) = builtin::find(name) {
        return Ok(SceneSource::Builtin(b.desc()));
    }
    let path = Path::new(name);
    let looks_like_file = Format::from_extension(path).is_some()
        || name.contains(std::path::MAIN_SEPARATOR)
        || name.contains('/')
        || path.exists();
    if looks_like_file {
        return Ok(SceneSource::File(SceneFile::read(path)?));
    }
    let closest = hint::closest(name, BUILTINS.iter().map(|b| b.name))
        .map(|n| format!(" (did you mean '{n}'?)"))
        .unwrap_or_default();
    bail!(
        "unknown scene '{name}'{closest}; `lumen scenes` lists the built-in scenes, \
         and scene files end in .toml or .json"
    )
}

fn export_command(name: &str, out: Option<&Path>, format: FormatArg) -> Result<()> {
    let source = load_scene(name)?;
    let format = match out {
        Some(path) => Format::from_extension(path)
            .ok_or_else(|| anyhow!("{}: scene files must end in .toml or .json", path.display()))?,
        None => match format {
            FormatArg::Toml => Format::Toml,
            FormatArg::Json => Format::Json,
        },
    };
    let text = file::export(source.desc(), format)?;
    match out {
        Some(path) => {
            output::check_writable(path)?;
            output::write_bytes_atomic(path, text.as_bytes())?;
            eprintln!("{name}: written to {}", path.display());
        }
        None => write_stdout(&text)?,
    }
    Ok(())
}

/// Where a path points once its directory is resolved (the file itself may
/// not exist yet): `./out.png`, `out.png` and `$PWD/out.png` are one place.
fn resolved(path: &Path) -> PathBuf {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    match path.file_name() {
        Some(name) => dir.join(name),
        None => dir,
    }
}

/// The checkpoint is overwritten after every pass and deleted at the end:
/// it must be neither the output image nor the scene file, and a file
/// already there must be a checkpoint, not something of the user's.
fn check_checkpoint_path(ckpt: &Path, out: &Path, scene: &str) -> Result<()> {
    let place = resolved(ckpt);
    if place == resolved(out) {
        bail!(
            "{}: the checkpoint cannot be the output image; choose another --checkpoint",
            ckpt.display()
        );
    }
    if Path::new(scene).is_file() && place == resolved(Path::new(scene)) {
        bail!(
            "{}: the checkpoint cannot be the scene file; choose another --checkpoint",
            ckpt.display()
        );
    }
    if ckpt.is_file() {
        let mut magic = [0u8; checkpoint::MAGIC.len()];
        let is_checkpoint = std::fs::File::open(ckpt)
            .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
            .is_ok_and(|()| &magic == checkpoint::MAGIC);
        if !is_checkpoint {
            bail!(
                "{}: exists and is not a lumen checkpoint; refusing to overwrite it (choose another --checkpoint)",
                ckpt.display()
            );
        }
    }
    Ok(())
}

fn render_command(
    name: &str,
    out: &Path,
    args: &SettingArgs,
    prog: &ProgressiveArgs,
) -> Result<ExitCode> {
    let desc = load_scene(name)?.resolve(name, &args.overrides())?;
    output::ImageFormat::from_path(out)?;
    let ckpt_path = prog
        .checkpoint
        .clone()
        .unwrap_or_else(|| checkpoint::default_path(out));
    check_checkpoint_path(&ckpt_path, out, name)?;
    // Refuse unwritable destinations now, not after a long render.
    output::check_writable(out)?;
    output::check_writable(&ckpt_path).context("checkpoint")?;
    let compile_error = |e: SessionError| match e {
        SessionError::Scene(e) => anyhow!("scene '{name}': {e}"),
        e => anyhow!(e),
    };
    let mut session = if prog.resume {
        if !ckpt_path.exists() {
            bail!(
                "--resume: there is no checkpoint at {}",
                ckpt_path.display()
            );
        }
        let ckpt = Checkpoint::read(&ckpt_path)?;
        Session::resume(&desc, ckpt, &ckpt_path).map_err(compile_error)?
    } else {
        let session = Session::new(&desc).map_err(compile_error)?;
        if ckpt_path.exists() {
            eprintln!(
                "lumen: note: starting afresh; the checkpoint {} will be replaced (--resume continues it)",
                ckpt_path.display()
            );
        }
        session
    };

    let stop = Arc::new(AtomicBool::new(false));
    install_stop_handler(
        &stop,
        [output::temp_path(out), output::temp_path(&ckpt_path)],
    )?;

    let s = session.scene().settings.clone();
    let resumed_from = session.spp_done();
    eprintln!(
        "{name}: {}x{} at {} spp, depth {}{}",
        s.width,
        s.height,
        s.samples_per_pixel,
        s.max_depth,
        if prog.resume {
            format!(
                ", resuming at {resumed_from} spp from {}",
                ckpt_path.display()
            )
        } else {
            String::new()
        }
    );
    let save = |session: &Session| -> Result<()> {
        let _saving = saving();
        output::write_image(out, session.film(), s.gamma)?;
        session
            .checkpoint()
            .write(&ckpt_path)
            .context("cannot save the checkpoint")?;
        quit_if_asked();
        Ok(())
    };
    let pixels = u64::from(s.width) * u64::from(s.height);
    let bar = progress_bar(pixels * u64::from(s.samples_per_pixel - resumed_from));
    let start = Instant::now();
    let mut last_save = start;
    let run = session.run(&stop, prog.time_limit, &|n| bar.inc(n), &mut |session,
                                                                          pass|
     -> Result<
        (),
    > {
        bar.suspend(|| {
            eprintln!(
                "pass {}: samples {}..{} in {:.3} s, {} of {} spp",
                pass.number,
                pass.samples.start,
                pass.samples.end,
                pass.duration.as_secs_f64(),
                session.spp_done(),
                session.spp_total()
            )
        });
        // The finished image is written once, below.
        let due = prog
            .checkpoint_interval
            .is_none_or(|every| last_save.elapsed() >= every);
        if !session.is_complete() && due {
            save(session)?;
            last_save = Instant::now();
        }
        Ok(())
    })?;
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    let (held, total) = (session.spp_done(), session.spp_total());
    let code = match run.reason {
        StopReason::Complete => {
            let _saving = saving();
            output::write_image(out, session.film(), s.gamma)?;
            quit_if_asked();
            match std::fs::remove_file(&ckpt_path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    eprintln!("lumen: warning: cannot remove {}: {e}", ckpt_path.display())
                }
                _ => {}
            }
            eprintln!("{name}: {total} spp written to {}", out.display());
            ExitCode::SUCCESS
        }
        reason if held == 0 => {
            debug_assert_eq!(reason, StopReason::Interrupted);
            eprintln!("lumen: interrupted before the first pass finished; nothing written");
            ExitCode::from(EXIT_INTERRUPTED)
        }
        reason => {
            save(&session)?;
            let why = if reason == StopReason::Interrupted {
                "interrupted"
            } else {
                "time limit reached"
            };
            eprintln!(
                "lumen: {why}: {} holds {held} of {total} spp; checkpoint {} (continue with --resume)",
                out.display(),
                ckpt_path.display()
            );
            if reason == StopReason::Interrupted {
                ExitCode::from(EXIT_INTERRUPTED)
            } else {
                ExitCode::SUCCESS
            }
        }
    };
    eprintln!("{}", summary(&run.stats, &session.stats(), elapsed));
    Ok(code)
}

/// Held while the image and the checkpoint are saved.
static SAVING: Mutex<()> = Mutex::new(());
/// Set by a second interrupt.
static QUIT: AtomicBool = AtomicBool::new(false);

fn saving() -> MutexGuard<'static, ()> {
    SAVING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Ends the process at once if a second interrupt came; called by the saver
/// at the end of a save, while it holds [`SAVING`].
fn quit_if_asked() {
    if QUIT.load(Ordering::SeqCst) {
        quit_now();
    }
}

fn quit_now() -> ! {
    eprintln!("lumen: stopped at once; the files on disk are those of the last save");
    std::process::exit(i32::from(EXIT_INTERRUPTED))
}

/// On the first Ctrl-C or SIGTERM, sets `stop`: the render abandons the pass
/// in flight and saves what it has. On the second, exits at once, leaving
/// the files of the last save, complete, since every file is renamed into
/// place only once written. A save in progress is let finish, so as not to
/// leave its temporary files behind (the saver exits after it); should it
/// take more than two seconds, its temporary files are removed and the
/// process exits anyway.
fn install_stop_handler(stop: &Arc<AtomicBool>, temps: [PathBuf; 2]) -> Result<()> {
    let stop = Arc::clone(stop);
    ctrlc::set_handler(move || {
        if !stop.swap(true, Ordering::SeqCst) {
            eprintln!(
                "lumen: stopping: saving the image and a checkpoint (interrupt again to quit at once)"
            );
            return;
        }
        QUIT.store(true, Ordering::SeqCst);
        let give_up = Instant::now() + Duration::from_secs(2);
        loop {
            match SAVING.try_lock() {
                // No save in progress; none starts again: the lock is kept.
                Ok(_gate) => quit_now(),
                Err(TryLockError::Poisoned(_gate)) => quit_now(),
                Err(TryLockError::WouldBlock) if Instant::now() < give_up => {
                    std::thread::sleep(Duration::from_millis(5))
                }
                Err(TryLockError::WouldBlock) => {
                    for t in &temps {
                        let _ = std::fs::remove_file(t);
                    }
                    quit_now()
                }
            }
        }
    })
    .context("cannot install the interrupt handler")
}

/// One line of counts: rates of this run (`run`) over `elapsed`, totals of
/// the whole image (`all`, which includes earlier runs when resumed).
fn summary(run: &RenderStats, all: &RenderStats, elapsed: Duration) -> String {
    format!(
        "time {:.2} s, {:.2} M samples/s, {:.2} M rays/s, {} rays, {} dropped samples",
        elapsed.as_secs_f64(),
        run.samples_per_second(elapsed) / 1e6,
        run.rays_per_second(elapsed) / 1e6,
        all.rays,
        all.dropped
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
    eprintln!("{}", summary(&total, &total, start.elapsed()));
    Ok(())
}

fn scaling_command(fields: &[usize], spp: u32, runs: u32) -> Result<()> {
    outln!(
        "lumen bench: cover-like sphere fields at 400x225, {} worker threads on {} cores ({} code), {spp} spp, depth 50, median of {runs} runs",
        rayon::current_num_threads(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        lumen::render::Isa::detect().name()
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

fn bench_command(spp: u32, runs: u32) -> Result<()> {
    outln!(
        "lumen bench: {} worker threads on {} cores ({} code), {spp} spp, depth 50, median of {runs} runs",
        rayon::current_num_threads(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        lumen::render::Isa::detect().name()
    )?;
    outln!(
        "{:<24} {:>10} {:>14} {:>16}",
        "workload",
        "median s",
        "M rays/s",
        "M samples/s"
    )?;
    for w in bench::standard_workloads(spp) {
        let m = bench::measure(&w, runs as usize).map_err(|e| anyhow!("{}: {e}", w.name))?;
        outln!(
            "{:<24} {:>10.3} {:>14.2} {:>16.2}",
            m.name,
            m.median.as_secs_f64(),
            m.rays_per_second() / 1e6,
            m.samples_per_second() / 1e6
        )?;
    }
    Ok(())
}
