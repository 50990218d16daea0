//! The `lumen` command: a thin layer over the library.

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use lumen::denoise::{Choices, Denoiser, Prefilter, Quality};
use lumen::progressive::parse_duration;
use lumen::render::RenderStats;
use lumen::scene::builtin::BUILTINS;
use lumen::scene::{Integrator, LightSelection, Overrides, Sampling};
use std::ffi::{OsStr, OsString};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Most worker threads accepted by `--threads` (far more than any machine
/// lumen runs on has cores; each thread costs a stack).
const MAX_THREADS: i64 = 1024;

/// The end of `lumen render --help`: what an interrupt does and the exit
/// status (see `render.rs` and `signals.rs`).
const RENDER_HELP: &str = "\
The image and a checkpoint (OUTPUT.lumen-ckpt unless --checkpoint says
otherwise) are saved after the first pass (unless the render is predicted
to end within a second), then after a pass once saving
takes at most 5 % of the time (or every --checkpoint-interval; 0: after
every pass); the checkpoint is removed when the render completes. While it
runs, the render holds a lock file beside each (.NAME.lumen-lock): a second
render to the same image or checkpoint is refused. Only regular files are
written.

Ctrl-C (or SIGTERM) stops the render: the pass in flight is abandoned and the
image and checkpoint of the passes finished so far are saved; continue with
--resume. Interrupted before the first pass finished, nothing is written. A
second Ctrl-C quits at once, leaving the files of the last save (a save in
progress is given up to two seconds to finish; a render that ends within a
second of its first pass may have made none).

Exit status:
  0    the image is complete, or --time-limit stopped the render (saved)
  1    error: nothing rendered, or the render failed (e.g. every sample was
       dropped, or a file could not be written)
  2    the command line is wrong
  130  interrupted (Ctrl-C or SIGTERM)";

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
    #[command(after_help = RENDER_HELP)]
    Render {
        /// Name of a built-in scene (see `lumen scenes`) or a scene file
        /// (.toml or .json, see docs/scene-format.md; .xml, a Mitsuba 3
        /// scene, see docs/mitsuba.md; .pbrt, a pbrt-v4 scene, see
        /// docs/pbrt.md). Command-line settings override the scene's own.
        scene: OsString,
        /// Output image; the extension chooses the format.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        settings: SettingArgs,
        #[command(flatten)]
        progressive: ProgressiveArgs,
        #[command(flatten)]
        import: ImportArgs,
    },
    /// Merge the part files of a render split with `render --part K/N`
    /// (by samples or by tiles) or `render --tile` into its image (.ppm,
    /// .png, .pfm or .exr): the same to the bit as the render on one
    /// machine. See docs/distributed.md.
    Merge {
        /// The part files, in any order.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output image; the extension chooses the format.
        #[arg(short, long)]
        output: PathBuf,
        /// Merge whatever the parts hold so far, finished or not and with
        /// parts missing (a preview while they render); says which samples
        /// the image holds.
        #[arg(long)]
        partial: bool,
        /// Display gamma of PNG and PPM images [default: the render's, which
        /// every part records].
        #[arg(long, value_parser = parse_gamma)]
        gamma: Option<f32>,
        #[command(flatten)]
        denoise: DenoiseArgs,
    },
    /// Denoise an OpenEXR image that has albedo and normal layers (as
    /// `render --aov albedo,normal` or `--denoise` writes them) with Open
    /// Image Denoise or lumen's own filter: for split renders, merged
    /// first and denoised once.
    /// With a variance layer the result is blended back towards the
    /// samples where the filter changed more than the noise explains.
    /// See docs/denoising.md.
    Denoise {
        /// The noisy image: channels R, G, B, albedo.R/G/B and
        /// normal.X/Y/Z.
        input: PathBuf,
        /// The denoised image; the extension chooses the format. An EXR
        /// keeps the input's other channels.
        #[arg(short, long)]
        output: PathBuf,
        /// Display gamma of a PNG or PPM output.
        #[arg(long, default_value_t = 2.0, value_parser = parse_gamma)]
        gamma: f32,
        /// Threads of the denoiser (default: one per core); the output is
        /// the same bits for the same input and number of threads.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_THREADS))]
        threads: Option<u32>,
        /// The denoiser: oidn (Open Image Denoise, in builds with the
        /// `oidn` feature) or atrous (lumen's own filter, in every build)
        /// [default: oidn].
        #[arg(long, value_name = "NAME", value_parser = str::parse::<Denoiser>)]
        denoiser: Option<Denoiser>,
        /// The image filter's quality: high, balanced or fast (Open Image
        /// Denoise's `quality`) [default: high, as a render's `--denoise`].
        #[arg(long, value_name = "Q", value_parser = str::parse::<Quality>)]
        quality: Option<Quality>,
        /// The albedo's and normal's prefilters' quality: high, balanced or
        /// fast; or none: not prefiltered, passed to the image's filter as
        /// they are [default: balanced, as a render's `--denoise`].
        #[arg(long, value_name = "Q", value_parser = str::parse::<Prefilter>)]
        prefilter: Option<Prefilter>,
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
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100_000_000), conflicts_with = "instances")]
        field: Option<u64>,
        /// Instead of the standard workloads, render fields of 1, 10, 100,
        /// 1,000 and 10,000 instances of the 235k-triangle bunny (or only N
        /// with --instance-count N): rays/s, build time and memory.
        #[arg(long, conflicts_with = "scaling")]
        instances: bool,
        /// With --instances: only this many instances.
        #[arg(long, value_name = "N", requires = "instances", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
        instance_count: Option<u64>,
        /// Run only the workload of this name (cover-400x225,
        /// three-spheres-400x225, bunny-235k-400x400, materials-320x180;
        /// with --efficiency, sky-spheres-400x225, bunny-235k-400x400,
        /// cornell-box-300x300, materials-320x180).
        #[arg(long, value_name = "NAME", conflicts_with_all = ["scaling", "field", "instances"])]
        workload: Option<String>,
        /// Instead of throughput, measure efficiency, 1 / (variance × time):
        /// each workload rendered with two seeds by each sampler (or only
        /// by --sampler).
        #[arg(long, conflicts_with_all = ["scaling", "field", "instances"])]
        efficiency: bool,
        /// With --efficiency: only this sampler.
        #[arg(long, value_enum, requires = "efficiency")]
        sampler: Option<SamplerArg>,
        /// Instead of throughput, render the efficiency workloads with this
        /// noise target and without one (up to --spp, Sobol), and compare
        /// their time and error against a reference of 4 × --spp.
        #[arg(long, value_name = "ERROR", conflicts_with_all = ["scaling", "field", "instances", "efficiency"])]
        adaptive: Option<f64>,
        /// Instead of rendering, trace the camera and bounce rays of each
        /// workload's paths (--spp samples) through lumen's tree on one
        /// thread, and through Embree's in a build with the `embree`
        /// feature: rays/s of each and how far their hits agree.
        #[arg(long, conflicts_with_all = ["scaling", "field", "instances", "efficiency", "adaptive"])]
        traversal: bool,
    },
}

#[derive(Subcommand)]
enum ScenesCommand {
    /// Write a built-in scene (or convert a scene file) as a scene file.
    Export {
        /// Name of a built-in scene, or a scene file to convert.
        name: OsString,
        /// Output file (default: standard output); .toml or .json chooses the format.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Format when writing to standard output.
        #[arg(long, value_enum, default_value_t = FormatArg::Toml)]
        format: FormatArg,
        #[command(flatten)]
        import: ImportArgs,
    },
}

/// The samplers, as `--sampler` names them.
#[derive(Clone, Copy, clap::ValueEnum)]
enum SamplerArg {
    /// Owen-scrambled Sobol points, a sequence per pixel: little noise, spread as white noise.
    Sobol,
    /// Sobol points over the pixels in Morton order: as little noise, spread as blue noise.
    Zsobol,
    /// Independent random numbers.
    Independent,
    /// Independent, with the pixel's samples stratified over a √N×√N grid.
    Stratified,
    /// Independent, with every sample through the pixel's centre.
    Center,
}

impl From<SamplerArg> for Sampling {
    fn from(s: SamplerArg) -> Self {
        match s {
            SamplerArg::Sobol => Sampling::Sobol,
            SamplerArg::Zsobol => Sampling::ZSobol,
            SamplerArg::Independent => Sampling::Independent,
            SamplerArg::Stratified => Sampling::Stratified,
            SamplerArg::Center => Sampling::Center,
        }
    }
}

/// The integrators, as `--integrator` names them.
#[derive(Clone, Copy, clap::ValueEnum)]
enum IntegratorArg {
    /// Bounces plus a shadow ray to a light at every diffuse bounce,
    /// weighted by multiple importance sampling.
    Path,
    /// Only the light the bounces happen to meet (the notes' estimator).
    Bsdf,
}

impl From<IntegratorArg> for Integrator {
    fn from(i: IntegratorArg) -> Self {
        match i {
            IntegratorArg::Path => Integrator::Path,
            IntegratorArg::Bsdf => Integrator::Bsdf,
        }
    }
}

/// How the `path` integrator chooses a light, as `--light-selection`
/// names it.
#[derive(Clone, Copy, clap::ValueEnum)]
enum LightSelectionArg {
    /// In proportion to each light's power.
    Power,
    /// Every light equally often (each triangle of a mesh one).
    Uniform,
    /// Every emitting object equally often (a mesh as one light, its
    /// triangles by area): Mitsuba's choice.
    Objects,
}

impl From<LightSelectionArg> for LightSelection {
    fn from(l: LightSelectionArg) -> Self {
        match l {
            LightSelectionArg::Power => LightSelection::Power,
            LightSelectionArg::Uniform => LightSelection::Uniform,
            LightSelectionArg::Objects => LightSelection::Objects,
        }
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum FormatArg {
    Toml,
    Json,
}

/// How a scene of another renderer's format (Mitsuba 3 `.xml`, pbrt-v4
/// `.pbrt`) is read.
#[derive(Args, Clone, Default)]
pub(crate) struct ImportArgs {
    /// A parameter of a Mitsuba scene (`$NAME` in its attributes), as
    /// Mitsuba's own -D.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    defines: Vec<(String, String)>,
    /// Render what lumen lacks with the nearest it has (one warning each)
    /// instead of refusing the scene.
    #[arg(long)]
    approximate: bool,
}

impl ImportArgs {
    /// The options of a Mitsuba or pbrt scene's reader; `allow_outside`
    /// lets its includes come from outside its folder.
    pub(crate) fn options(&self, allow_outside: bool) -> lumen::scene::file::mitsuba::Options {
        lumen::scene::file::mitsuba::Options {
            defines: self.defines.clone(),
            approximate: self.approximate,
            allow_outside,
        }
    }
}

/// `NAME=VALUE` of `-D`.
fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value)) if !name.is_empty() => Ok((name.to_string(), value.to_string())),
        _ => Err(format!("expected NAME=VALUE, got `{s}`")),
    }
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
    /// Random seed, 0 to 2^63-1 (as in scene files).
    #[arg(long, value_parser = clap::value_parser!(u64).range(..=lumen::scene::desc::MAX_SEED))]
    seed: Option<u64>,
    /// Where the random numbers come from [default: the scene's; `zsobol`
    /// unless it says otherwise].
    #[arg(long, value_enum)]
    sampler: Option<SamplerArg>,
    /// How paths gather light [default: the scene's; `path` unless it says
    /// otherwise].
    #[arg(long, value_enum)]
    integrator: Option<IntegratorArg>,
    /// How the `path` integrator chooses the light it samples [default: the
    /// scene's; `power` unless it says otherwise].
    #[arg(long, value_enum)]
    light_selection: Option<LightSelectionArg>,
    /// Adaptive sampling: stop sampling a pixel once its estimated relative
    /// error is at most this (e.g. 0.01); --spp stays the upper bound.
    #[arg(long, value_name = "ERROR")]
    noise_target: Option<f64>,
    /// Feature buffers to write beside the image, comma-separated: albedo,
    /// normal, depth, position, variance, spp (layers of an EXR image,
    /// NAME.AOV.pfm files beside any other).
    #[arg(long, value_name = "LIST", value_parser = parse_aovs)]
    aov: Option<AovList>,
    /// Denoise the finished image with Open Image Denoise (builds with the
    /// `oidn` feature; see docs/denoising.md) or lumen's own filter
    /// (`--denoiser atrous`), then blended back towards
    /// the samples where the filter changed more than their noise
    /// explains. The albedo, normal and variance buffers are kept and
    /// written, and the noisy image is written beside it as NAME.noisy.EXT.
    #[arg(long)]
    denoise: bool,
    /// Let mesh files read files outside their folder (glTF buffers and
    /// images, MTL files and maps), as `allow_outside = true` on every mesh
    /// object does, and a Mitsuba scene include files from outside its
    /// folder.
    #[arg(long)]
    allow_outside: bool,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_THREADS))]
    threads: Option<u32>,
}

/// How a render is saved, stopped and resumed.
#[derive(Args, Clone, Default)]
struct ProgressiveArgs {
    /// Checkpoint file, saved during the render so that it can be resumed
    /// [default: the output path + .lumen-ckpt].
    #[arg(long, value_name = "FILE", conflicts_with = "part")]
    checkpoint: Option<PathBuf>,
    /// Render only part K of N (K from 0, as job array task ids count):
    /// an equal share of every pixel's samples, or with --split tiles a
    /// band of rows, into a part file (-o NAME.lumen-part), its own
    /// checkpoint; `lumen merge` joins the parts into the image of the
    /// whole render, to the bit. See docs/distributed.md.
    #[arg(long, value_name = "K/N")]
    part: Option<lumen::part::Part>,
    /// What --part splits: `samples` (every part a share of every pixel's
    /// samples, the default) or `tiles` (part K of N bands of whole rows,
    /// every sample: for an image whose film does not fit one machine).
    #[arg(long, value_name = "HOW", requires = "part")]
    split: Option<lumen::part::Split>,
    /// Render only the pixels X0..X1 x Y0..Y1 into a part file (-o
    /// NAME.lumen-part); with --part K/N, that share of their samples.
    #[arg(long, value_name = "X0,Y0,X1,Y1", conflicts_with = "checkpoint")]
    tile: Option<lumen::tile::Tile>,
    /// Save the image and the checkpoint at most this often (e.g. 30s, 5m),
    /// or after every pass (0) [default: after a pass once the render has
    /// run 19 times as long as the last save took, so that saving takes at
    /// most 5 % of the time].
    #[arg(long, value_name = "DURATION", value_parser = lumen::progressive::SaveSchedule::parse)]
    checkpoint_interval: Option<lumen::progressive::SaveSchedule>,
    /// Continue the render saved in the checkpoint; the scene and settings
    /// must be the same as when it was made.
    #[arg(long)]
    resume: bool,
    /// Stop after the last pass that ends within this time (e.g. 90s, 10m,
    /// 2h) and write the image; --spp stays the upper bound.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    time_limit: Option<Duration>,
    /// With --denoise (or `denoise = true` in the scene), denoise the
    /// images saved between passes too, not only the finished one.
    #[arg(long)]
    denoise_previews: bool,
    #[command(flatten)]
    denoise: DenoiseArgs,
    /// Serve the image so far on a local web page (http://127.0.0.1:PORT,
    /// printed at start), updated after every pass: docs/preview.md.
    #[arg(long)]
    preview: bool,
    /// The port of --preview's page (a port in use is refused) [default:
    /// a free one].
    #[arg(long, value_name = "PORT", requires = "preview")]
    preview_port: Option<u16>,
}

/// The feature buffers of `--aov` (a type of its own: clap would read a
/// `Vec` as an option given several times).
#[derive(Clone, Debug)]
struct AovList(Vec<lumen::aov::Aov>);

fn parse_aovs(list: &str) -> Result<AovList, String> {
    lumen::aov::Aov::parse_list(list).map(AovList)
}

impl SettingArgs {
    fn overrides(&self) -> Overrides {
        Overrides {
            width: self.width,
            samples_per_pixel: self.spp,
            max_depth: self.depth,
            seed: self.seed,
            sampler: self.sampler.map(Sampling::from),
            integrator: self.integrator.map(Integrator::from),
            light_selection: self.light_selection.map(LightSelection::from),
            noise_target: self.noise_target,
            aovs: self.aov.clone().map(|l| l.0),
            denoise: self.denoise,
            allow_outside: self.allow_outside,
        }
    }
}

/// Writes to standard output. A closed pipe (`lumen scenes | head -1`) ends
/// the output quietly; any other failure is an error, never a panic.
fn write_stdout(text: &str) -> Result<()> {
    write_stdout_with(|out| out.write_all(text.as_bytes()))
}

/// [`write_stdout`] of what `write` writes, through a buffer.
fn write_stdout_with(
    write: impl FnOnce(&mut std::io::BufWriter<std::io::StdoutLock>) -> std::io::Result<()>,
) -> Result<()> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    match write(&mut out).and_then(|()| out.flush()) {
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

/// Writes to standard error, ignoring failures: progress and messages are
/// for a person watching, and a closed pipe (`lumen render … 2>&1 | head`)
/// must neither stop the render nor leave its image half-saved.
fn write_stderr(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

/// `eprintln!` through [`write_stderr`]: never panics.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::write_stderr(&format!("{}\n", format_args!($($arg)*)))
    };
}

mod commands;
mod denoise;
mod merge;
mod render;
mod scenes;
mod signals;

use commands::{
    adaptive_command, bench_command, efficiency_command, gallery_command, instances_command,
    scaling_command, traversal_command,
};
use render::render_command;
use scenes::export_command;

/// A display gamma: a finite number greater than 0.
fn parse_gamma(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(g) if g > 0.0 && g.is_finite() => Ok(g),
        _ => Err(format!("'{text}': a gamma is a number greater than 0")),
    }
}

/// How a denoised render's image is denoised (`render`, `merge`).
#[derive(Args, Clone, Default)]
struct DenoiseArgs {
    /// With --denoise: the denoiser, oidn (Open Image Denoise, in builds
    /// with the `oidn` feature) or atrous (lumen's own filter, in every
    /// build) [default: oidn].
    #[arg(long, value_name = "NAME", value_parser = str::parse::<Denoiser>)]
    denoiser: Option<Denoiser>,
    /// With --denoise: the quality of the image's filter, high, balanced
    /// or fast (Open Image Denoise's `quality`) [default: high].
    #[arg(long, value_name = "Q", value_parser = str::parse::<Quality>)]
    denoise_quality: Option<Quality>,
    /// With --denoise: the quality of the albedo's and normal's
    /// prefilters, high, balanced or fast; or none: passed to the image's
    /// filter as they are [default: balanced].
    #[arg(long, value_name = "Q", value_parser = str::parse::<Prefilter>)]
    denoise_prefilter: Option<Prefilter>,
}

impl DenoiseArgs {
    /// Whether any is given.
    fn any(&self) -> Option<&'static str> {
        if self.denoiser.is_some() {
            Some("--denoiser")
        } else if self.denoise_quality.is_some() {
            Some("--denoise-quality")
        } else if self.denoise_prefilter.is_some() {
            Some("--denoise-prefilter")
        } else {
            None
        }
    }

    /// The denoiser's options these arguments ask for, over the scene's
    /// `scene`.
    fn options(&self, scene: Choices) -> Result<lumen::denoise::Options, Usage> {
        let given = Choices {
            denoiser: self.denoiser,
            quality: self.denoise_quality,
            prefilter: self.denoise_prefilter,
        };
        denoise_options(given, scene, ["--denoise-quality", "--denoise-prefilter"])
    }
}

/// The denoiser's options `given` on the command line chooses, over
/// `scene`'s; refused when OIDN's qualities (given as the options `names`)
/// are given for the built-in filter, which has none.
fn denoise_options(
    given: Choices,
    scene: Choices,
    names: [&str; 2],
) -> Result<lumen::denoise::Options, Usage> {
    let options = given.over(scene).options();
    if options.denoiser != Denoiser::Oidn {
        let asked = [given.quality.is_some(), given.prefilter.is_some()];
        if let Some(i) = asked.iter().position(|&g| g) {
            return Err(Usage(format!(
                "{}: a quality of Open Image Denoise; the {} denoiser has none",
                names[i],
                options.denoiser.name()
            )));
        }
    }
    Ok(options)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            errln!("lumen: error: {e:#}");
            exit_code(&e)
        }
    }
}

/// Exit status of options that cannot work together or with the scene, as
/// clap's own usage errors: running again cannot mend them, and a job
/// engine (a Kubernetes Indexed Job) fails such a task at once instead of
/// retrying it.
const EXIT_USAGE: u8 = 2;

/// A mistake in the options given (see [`EXIT_USAGE`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct Usage(pub String);

/// The exit status of a failed command: [`EXIT_USAGE`] for mistakes in the
/// options, whether found here or by the library; 1 for anything else.
fn exit_code(e: &anyhow::Error) -> ExitCode {
    use lumen::output::OutputError;
    use lumen::progressive::SessionError;
    let usage = e.chain().any(|cause| {
        cause.is::<Usage>()
            || matches!(
                cause.downcast_ref::<SessionError>(),
                Some(SessionError::AdaptivePart { .. } | SessionError::Tile { .. })
            )
            || matches!(
                cause.downcast_ref::<OutputError>(),
                Some(OutputError::UnknownFormat { .. })
            )
    });
    match usage {
        true => ExitCode::from(EXIT_USAGE),
        false => ExitCode::FAILURE,
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Render {
            scene,
            output,
            settings,
            progressive,
            import,
        } => with_threads(settings.threads, || {
            let import = import.options(settings.allow_outside);
            render_command(
                scene_name(&scene)?,
                &output,
                &settings,
                &progressive,
                &import,
            )
        }),
        Command::Merge {
            parts,
            output,
            partial,
            gamma,
            denoise,
        } => merge::merge_command(&parts, &output, partial, gamma, &denoise),
        Command::Denoise {
            input,
            output,
            gamma,
            threads,
            denoiser,
            quality,
            prefilter,
        } => with_threads(threads, || {
            let given = Choices {
                denoiser,
                quality,
                prefilter,
            };
            let options = denoise_options(given, Choices::default(), ["--quality", "--prefilter"])?;
            denoise::denoise_command(&input, &output, gamma, options)
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
                    import,
                }),
        } => {
            export_command(
                scene_name(&name)?,
                output.as_deref(),
                format,
                &import.options(false),
            )?;
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
            instances,
            instance_count,
            workload,
            efficiency,
            sampler,
            adaptive,
            traversal,
        } => {
            with_threads(threads, || {
                if traversal {
                    return traversal_command(spp, runs, workload.as_deref());
                }
                if let Some(target) = adaptive {
                    return adaptive_command(target, spp, workload.as_deref());
                }
                if efficiency {
                    let samplers = match sampler {
                        Some(s) => vec![Sampling::from(s)],
                        None => vec![
                            Sampling::Independent,
                            Sampling::Stratified,
                            Sampling::Sobol,
                            Sampling::ZSobol,
                        ],
                    };
                    return efficiency_command(spp, runs, workload.as_deref(), &samplers);
                }
                if instances {
                    let counts = match instance_count {
                        Some(n) => vec![n as usize],
                        None => vec![1, 10, 100, 1_000, 10_000],
                    };
                    return instances_command(&counts, spp, runs);
                }
                let fields: Vec<usize> = match (scaling, field) {
                    (true, _) => vec![100, 1_000, 10_000, 100_000, 1_000_000],
                    (false, Some(n)) => vec![n as usize],
                    (false, None) => return bench_command(spp, runs, workload.as_deref()),
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

/// A scene argument as text: built-in names and the scene files' own
/// references to meshes and images are UTF-8, so a scene path must be too.
fn scene_name(arg: &OsStr) -> Result<&str> {
    arg.to_str().ok_or_else(|| {
        anyhow::anyhow!(
            "scene path {} is not valid UTF-8: rename the file (or its folder) to a UTF-8 name",
            arg.to_string_lossy()
        )
    })
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
