//! Progressive rendering: the image is rendered in passes, each adding some
//! samples to every pixel, so that after any pass the film is a complete,
//! viewable image of the samples so far and can be saved as a checkpoint.
//!
//! Because every sample has its own random numbers and every pixel adds its
//! samples in index order (see [`crate::render::render_samples`]), the way
//! the samples are split into passes, and where a render was stopped and
//! resumed, never changes the image: it is bit-identical to one rendered in a
//! single pass.
//!
//! A [`Session`] holds a render in progress; [`Session::run`] renders passes
//! until the image is complete, a stop is asked for through an [`AtomicBool`]
//! (lumen's command sets it on Ctrl-C), or a time budget would be exceeded.
//!
//! ```
//! use lumen::progressive::{Session, StopReason};
//! use lumen::scene::builtin;
//! use std::sync::atomic::AtomicBool;
//!
//! let mut desc = builtin::find("metal-mirror").unwrap().desc();
//! desc.render.width = 16;
//! desc.render.samples_per_pixel = 24;
//! let mut session = Session::new(&desc).unwrap();
//! let stop = AtomicBool::new(false);
//! let mut passes = 0;
//! let run = session
//!     .run(&stop, None, &|_| {}, &mut |_, _| -> Result<(), ()> {
//!         passes += 1;
//!         Ok(())
//!     })
//!     .unwrap();
//! assert_eq!(run.reason, StopReason::Complete);
//! // Samples 0..1, 1..2, 2..4, then passes of 3 (an eighth of 24), 22..24.
//! assert_eq!(passes, 10);
//! assert_eq!(session.spp_done(), 24);
//! ```

use crate::checkpoint::{identity_text, Checkpoint, CheckpointError, CheckpointView};
use crate::film::Film;
use crate::part::{Part, Share};
use crate::render::{render_pixels, RenderStats};
use crate::scene::{Scene, SceneDesc, SceneError};
use crate::tile::Tile;
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Largest pass, in samples per pixel.
pub const MAX_PASS_SPP: u32 = 64;

/// Size in samples per pixel of the pass that follows `done` samples of
/// `spp`: passes double (1, 1, 2, 4, 8, …) so that a first image appears at
/// once, up to an eighth of the render (at most [`MAX_PASS_SPP`]) so that a
/// stop or a time limit loses little. It depends on `done` and `spp` only,
/// so a resumed render takes the same passes as one never stopped.
pub fn pass_size(done: u32, spp: u32) -> u32 {
    share_pass_size(done, spp, spp)
}

/// [`pass_size`] for a share of `len` samples per pixel of a render of
/// `spp` (a part, see [`crate::part`]). A part shows no image while it
/// renders, so its passes do not start small: they are all the whole
/// render's largest, which keeps as many paths side by side as the whole
/// render traces (passes of a sample or two are markedly slower per sample).
pub fn share_pass_size(done: u32, len: u32, spp: u32) -> u32 {
    let cap = (spp / 8).clamp(1, MAX_PASS_SPP);
    let first = if len == spp { done.max(1) } else { cap };
    first.min(cap).min(len.saturating_sub(done))
}

/// All passes of a render of `spp` samples per pixel, as sample ranges.
pub fn schedule(spp: u32) -> Vec<Range<u32>> {
    let mut passes = Vec::new();
    let mut done = 0;
    while done < spp {
        let n = pass_size(done, spp);
        passes.push(done..done + n);
        done += n;
    }
    passes
}

/// Whether a pass of a render of `spp` samples per pixel ends at `done`
/// (see [`pass_size`]): lumen saves checkpoints between passes only.
pub fn ends_a_pass(done: u32, spp: u32) -> bool {
    ends_a_share_pass(done, spp, spp)
}

/// Whether a pass of a share of `len` samples per pixel of a render of
/// `spp` ends `done` samples into the share (see [`share_pass_size`]); an
/// empty share ends at 0.
pub fn ends_a_share_pass(done: u32, len: u32, spp: u32) -> bool {
    let mut at = 0;
    while at < done && at < len {
        at += share_pass_size(at, len, spp);
    }
    at == done
}

/// When a render saves its image and checkpoint between passes (the
/// finished image is always written).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SaveSchedule {
    /// After a pass once the time since the last save is at least
    /// [`SAVE_SPACING`] times what that save took, so that saving takes at
    /// most about a twentieth of the render's time however short its passes
    /// and however large its image. The first pass is saved, so that an
    /// image is there at once, unless the rest of the render is predicted
    /// to take less than [`QUICK_RENDER`]: then the finished image comes as
    /// soon, and an interrupt still saves what is done.
    #[default]
    Bounded,
    /// After every pass.
    EveryPass,
    /// After a pass once this long has passed since the last save.
    Every(Duration),
}

/// What is left of a render after its first pass, predicted, below which
/// [`SaveSchedule::Bounded`] does not save that pass: a render of a few
/// samples a pixel saved its image and checkpoint after the first pass
/// only to write the image again a tenth of a second later.
pub const QUICK_RENDER: Duration = Duration::from_secs(1);

/// How many times as long as its last save a render with
/// [`SaveSchedule::Bounded`] renders before it saves again: saves then take
/// at most 1/(1 + 19) = 5 % of the time.
pub const SAVE_SPACING: u32 = 19;

impl SaveSchedule {
    /// Whether a pass that ends `since` after the last save ended (or the
    /// run started), which took `took` (`None` before the run's first save),
    /// is saved, when the rest of the render is predicted to take `left`.
    pub fn due(self, since: Duration, took: Option<Duration>, left: Duration) -> bool {
        match (self, took) {
            (SaveSchedule::EveryPass, _) => true,
            (SaveSchedule::Bounded, None) => left >= QUICK_RENDER,
            (SaveSchedule::Every(every), _) => since >= every,
            (SaveSchedule::Bounded, Some(took)) => since >= took * SAVE_SPACING,
        }
    }

    /// Parses `--checkpoint-interval`'s value: a duration (see
    /// [`parse_duration`]), or `0` for every pass.
    pub fn parse(text: &str) -> Result<SaveSchedule, String> {
        let zero = text.trim().trim_end_matches(['s', 'm', 'h']).trim();
        if zero.parse::<f64>().is_ok_and(|v| v == 0.0) {
            return Ok(SaveSchedule::EveryPass);
        }
        parse_duration(text).map(SaveSchedule::Every)
    }
}

/// Parses a duration such as `90s`, `1.5m`, `2h` or `45` (seconds).
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let (number, unit) = match t.char_indices().last() {
        Some((i, 's')) => (&t[..i], 1.0),
        Some((i, 'm')) => (&t[..i], 60.0),
        Some((i, 'h')) => (&t[..i], 3600.0),
        _ => (t, 1.0),
    };
    let bad = || format!("'{text}' is not a duration; write e.g. 90s, 1.5m or 2h");
    let value: f64 = number.trim().parse().map_err(|_| bad())?;
    let seconds = value * unit;
    if !(seconds > 0.0) {
        return Err(format!("'{text}': a duration must be positive"));
    }
    if !(seconds <= 1e9) {
        return Err(format!(
            "'{text}': a duration must be at most 1e9 seconds (31 years)"
        ));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// A render in progress: the scene and the samples rendered so far.
pub struct Session {
    scene: Scene,
    description: String,
    film: Film,
    /// The film as the pass in flight found it, to put back if the pass is
    /// abandoned; kept between passes so that no pass allocates one.
    backup: Film,
    stats: RenderStats,
    /// The sample indices this session renders in every pixel: all of them,
    /// or a part's share ([`Session::with_share`]).
    share: Range<u32>,
    /// The pixels of the image the film holds: all of them, or a part's
    /// tile.
    tile: Tile,
    /// End of the samples rendered: the film holds `share.start..spp_done`.
    spp_done: u32,
    /// With adaptive sampling, the pixels still being sampled.
    active: Option<Vec<bool>>,
}

/// A session that cannot be started.
#[derive(Debug, Error)]
pub enum SessionError {
    /// The scene does not compile.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The checkpoint cannot be used.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// Adaptive sampling decides each pass from all the samples before it,
    /// which a part of the samples does not have; its parts are not split
    /// by tiles either.
    #[error("{share}: a render split into parts cannot sample adaptively (render.noise_target is set); leave out the noise target")]
    AdaptivePart {
        /// The share asked for.
        share: Share,
    },
    /// This machine's memory cannot hold the film.
    #[error(transparent)]
    Memory(#[from] crate::memory::MemoryError),
    /// The share's pixels are not in the image.
    #[error("{message}")]
    Tile {
        /// The share asked for.
        share: Share,
        /// What is wrong.
        message: String,
    },
}

/// One finished pass.
#[derive(Clone, Debug)]
pub struct PassReport {
    /// Pass number within this run, from 1.
    pub number: u32,
    /// The sample indices it rendered in every pixel.
    pub samples: Range<u32>,
    /// How long it took.
    pub duration: Duration,
    /// Its counts.
    pub stats: RenderStats,
}

/// Why [`Session::run`] returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Every sample is rendered.
    Complete,
    /// A stop was asked for.
    Interrupted,
    /// The next pass would not fit in the time budget.
    TimeLimit,
}

/// What [`Session::run`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunSummary {
    /// Why it returned.
    pub reason: StopReason,
    /// Passes finished in this run.
    pub passes: u32,
    /// Counts of this run's finished passes only.
    pub stats: RenderStats,
}

impl Session {
    /// A new render of `desc` with no samples yet.
    pub fn new(desc: &SceneDesc) -> Result<Self, SessionError> {
        Self::with_scene(desc, Scene::from_desc(desc)?)
    }

    /// A new render of `desc` already compiled into `scene` (which must be
    /// `Scene::from_desc(desc)`): spares building the scene twice. Refused
    /// when this machine's free memory cannot hold the film.
    pub fn with_scene(desc: &SceneDesc, scene: Scene) -> Result<Self, SessionError> {
        let (w, h) = (scene.settings.width, scene.settings.height);
        let samples = 0..scene.settings.samples_per_pixel;
        Self::of_share(desc, scene, samples, Tile::whole(w, h))
    }

    /// A new render of samples `samples` of the pixels `tile` of `desc`,
    /// compiled into `scene`: a film of the tile only, whose memory (with
    /// the copy a pass in flight keeps) is counted and taken without
    /// aborting.
    fn of_share(
        desc: &SceneDesc,
        scene: Scene,
        samples: Range<u32>,
        tile: Tile,
    ) -> Result<Self, SessionError> {
        let (w, h) = (tile.width(), tile.height());
        let halves = scene.settings.noise_target.is_some();
        let layers = scene.settings.layers;
        let bytes = Film::bytes(w, h, halves) + Film::layer_bytes(w, h, layers);
        crate::memory::check(
            2 * bytes,
            &format!("the {w}x{h} film (with the copy a pass keeps)"),
        )?;
        let film = match halves {
            true => Film::try_with_halves(w, h),
            false => Film::try_new(w, h),
        }
        .and_then(|film| film.try_with_layers(layers))
        .ok_or_else(|| crate::memory::MemoryError {
            what: format!("the {w}x{h} film"),
            bytes,
            available: None,
        })?;
        let active = scene.settings.noise_target.map(|_| vec![true; film.len()]);
        Ok(Self {
            description: identity_text(desc, &scene.sources),
            tile,
            scene,
            film,
            backup: Film::new(0, 0),
            stats: RenderStats::default(),
            spp_done: samples.start,
            share: samples,
            active,
        })
    }

    /// A new render of `part` of the samples of `desc`, already compiled
    /// into `scene`: [`Session::with_share`] of that part.
    pub fn with_part(desc: &SceneDesc, scene: Scene, part: Part) -> Result<Self, SessionError> {
        let share = Share {
            part: Some(part),
            ..Share::default()
        };
        Self::with_share(desc, scene, share)
    }

    /// A new render of `share` of `desc`, already compiled into `scene`:
    /// a film of the share's pixels, to which the share's samples of every
    /// pixel are added. Refused with adaptive sampling (unless the share is
    /// the whole render), and when the share's pixels are not in the image.
    pub fn with_share(desc: &SceneDesc, scene: Scene, share: Share) -> Result<Self, SessionError> {
        if share.is_whole() {
            return Self::with_scene(desc, scene);
        }
        if scene.settings.noise_target.is_some() {
            return Err(SessionError::AdaptivePart { share });
        }
        let s = &scene.settings;
        let tile = share
            .tile(s.width, s.height)
            .map_err(|message| SessionError::Tile { share, message })?;
        let samples = share.samples(s.samples_per_pixel);
        Self::of_share(desc, scene, samples, tile)
    }

    /// The sample indices this session renders in every pixel.
    pub fn share(&self) -> Range<u32> {
        self.share.clone()
    }

    /// The pixels of the image this session renders (its film's).
    pub fn tile(&self) -> Tile {
        self.tile
    }

    /// Continues the render of `desc` saved in `checkpoint` (read from
    /// `path`, which names it in errors). Refused unless the checkpoint was
    /// made for the same description, overrides included.
    pub fn resume(
        desc: &SceneDesc,
        checkpoint: Checkpoint,
        path: &Path,
    ) -> Result<Self, SessionError> {
        // A description that does not compile any more is still reported
        // as a mismatch when it is one.
        let scene = match Scene::from_desc(desc) {
            Ok(scene) => scene,
            Err(e) => {
                checkpoint.check_matches(desc, path)?;
                return Err(e.into());
            }
        };
        Self::with_scene(desc, scene)?.restore(checkpoint, path)
    }

    /// Continues this new session from `checkpoint` (read from `path`, which
    /// names it in errors). Refused unless the checkpoint was made for the
    /// same description, overrides included.
    pub fn restore(self, checkpoint: Checkpoint, path: &Path) -> Result<Self, SessionError> {
        checkpoint.check_description(&self.description, path)?;
        self.adopt(checkpoint, path)
    }

    /// Takes the samples of `checkpoint`, whose description is known to be
    /// this session's, after checking that its film fits the render.
    fn adopt(mut self, checkpoint: Checkpoint, path: &Path) -> Result<Self, SessionError> {
        let s = &self.scene.settings;
        let malformed = |message: String| CheckpointError::Malformed {
            path: path.to_path_buf(),
            message,
        };
        // Checked on decoding too; a checkpoint built in memory is not.
        checkpoint.check_consistency().map_err(malformed)?;
        if checkpoint.image != (s.width, s.height) {
            return Err(malformed(format!(
                "its image is {}x{}, the render's {}x{}",
                checkpoint.image.0, checkpoint.image.1, s.width, s.height
            ))
            .into());
        }
        if checkpoint.tile != self.tile {
            return Err(malformed(format!(
                "it holds the pixels {}, the render takes {}",
                checkpoint.tile, self.tile
            ))
            .into());
        }
        if checkpoint.share != self.share {
            return Err(malformed(format!(
                "it holds samples {}..{} of every pixel, the render takes {}..{}",
                checkpoint.share.start, checkpoint.share.end, self.share.start, self.share.end
            ))
            .into());
        }
        if checkpoint.spp_done > s.samples_per_pixel {
            return Err(malformed(format!(
                "it holds {} spp of a {} spp render",
                checkpoint.spp_done, s.samples_per_pixel
            ))
            .into());
        }
        let (done, len) = (
            checkpoint.spp_done - self.share.start,
            self.share.len() as u32,
        );
        if !ends_a_share_pass(done, len, s.samples_per_pixel) {
            return Err(malformed(format!(
                "it holds {} spp, where no pass of a {} spp render ends",
                checkpoint.spp_done, s.samples_per_pixel
            ))
            .into());
        }
        if checkpoint.film.layers() != s.layers {
            return Err(
                malformed("its feature layers (AOVs) do not match the render's".into()).into(),
            );
        }
        if checkpoint.active.is_some() != self.active.is_some() {
            return Err(malformed(
                "its adaptive sampling state does not match the render's".into(),
            )
            .into());
        }
        self.film = checkpoint.film;
        self.stats = checkpoint.stats;
        self.spp_done = checkpoint.spp_done;
        self.active = checkpoint.active;
        Ok(self)
    }

    /// The compiled scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The film: samples `0..spp_done()` of every pixel.
    pub fn film(&self) -> &Film {
        &self.film
    }

    /// Counts of all samples in the film, including those of earlier runs.
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// Samples per pixel in the film.
    pub fn spp_done(&self) -> u32 {
        self.spp_done
    }

    /// Samples per pixel of the finished image.
    pub fn spp_total(&self) -> u32 {
        self.scene.settings.samples_per_pixel
    }

    /// Samples per pixel of this session's share not yet rendered.
    pub fn spp_left(&self) -> u32 {
        self.share.end.saturating_sub(self.spp_done)
    }

    /// Whether every sample is rendered (with adaptive sampling: every
    /// sample of the pixels that have not stopped).
    pub fn is_complete(&self) -> bool {
        self.spp_done >= self.share.end || self.active_pixels() == Some(0)
    }

    /// With adaptive sampling, the number of pixels still being sampled.
    pub fn active_pixels(&self) -> Option<usize> {
        self.active
            .as_ref()
            .map(|a| a.iter().filter(|&&on| on).count())
    }

    /// With adaptive sampling, which pixels are still being sampled
    /// (row-major).
    pub fn active(&self) -> Option<&[bool]> {
        self.active.as_deref()
    }

    /// The state to save so that a later run can continue this one.
    pub fn checkpoint(&self) -> CheckpointView<'_> {
        CheckpointView {
            renderer_id: crate::checkpoint::RENDERER_ID,
            description: &self.description,
            share: self.share.clone(),
            tile: self.tile,
            image: (self.scene.settings.width, self.scene.settings.height),
            spp_done: self.spp_done,
            gamma: self.scene.settings.gamma,
            stats: self.stats,
            film: &self.film,
            active: self.active.as_deref(),
        }
    }

    /// Samples per pixel of the next pass: the schedule of
    /// [`share_pass_size`] over this session's share.
    fn next_pass_size(&self) -> u32 {
        share_pass_size(
            self.spp_done - self.share.start,
            self.share.end - self.share.start,
            self.spp_total(),
        )
    }

    /// Renders the next pass. `should_stop` is asked before every row; if it
    /// answers `true` the pass is abandoned, the film is left as it was
    /// before the pass, and `None` is returned.
    pub fn render_pass(
        &mut self,
        progress: &(dyn Fn(u64) + Sync),
        should_stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<(Range<u32>, Duration, RenderStats)> {
        let n = self.next_pass_size();
        let samples = self.spp_done..self.spp_done + n;
        // A pass abandoned half-way has added samples to some rows only:
        // keep the film as it was to put it back.
        self.backup.copy_from(&self.film);
        let start = Instant::now();
        let result = render_pixels(
            &self.scene,
            &mut self.film,
            (self.tile.x0, self.tile.y0),
            samples.clone(),
            self.active.as_deref(),
            progress,
            should_stop,
        );
        match result {
            Some(stats) => {
                self.stats.add(stats);
                self.spp_done = samples.end;
                if let (Some(active), Some(target)) =
                    (&mut self.active, self.scene.settings.noise_target)
                {
                    crate::adaptive::update(&self.film, active, target, self.spp_done);
                }
                let duration = start.elapsed();
                Some((samples, duration, stats))
            }
            None => {
                std::mem::swap(&mut self.film, &mut self.backup);
                None
            }
        }
    }

    /// Renders passes until the image is complete, `stop` is set (the pass
    /// in flight is abandoned), or the time budget `time_limit` would be
    /// exceeded: the next pass is started only if, predicted from the
    /// previous pass's time per sample, it ends within the budget, and a
    /// pass still running when the budget is spent is abandoned. The first
    /// pass of every run is always finished: an image needs a sample, and a
    /// resumed render must progress even if one pass outgrows the budget.
    ///
    /// `on_pass` is called after every finished pass (to save the image and
    /// a checkpoint); its error ends the run.
    pub fn run<E>(
        &mut self,
        stop: &AtomicBool,
        time_limit: Option<Duration>,
        progress: &(dyn Fn(u64) + Sync),
        on_pass: &mut dyn FnMut(&Session, &PassReport) -> Result<(), E>,
    ) -> Result<RunSummary, E> {
        let deadline = time_limit.map(|t| Instant::now() + t);
        let mut summary = RunSummary {
            reason: StopReason::Complete,
            passes: 0,
            stats: RenderStats::default(),
        };
        let mut last: Option<(u32, Duration)> = None;
        while !self.is_complete() {
            if stop.load(Ordering::SeqCst) {
                summary.reason = StopReason::Interrupted;
                return Ok(summary);
            }
            let next = self.next_pass_size();
            if let (Some(deadline), Some((n, took))) = (deadline, last) {
                let predicted = took.mul_f64(f64::from(next) / f64::from(n));
                if Instant::now() + predicted > deadline {
                    summary.reason = StopReason::TimeLimit;
                    return Ok(summary);
                }
            }
            // Every run adds at least one pass, or a resumed render whose
            // passes outgrow the budget would never progress.
            let must_finish = summary.passes == 0;
            let should_stop = || {
                stop.load(Ordering::Relaxed)
                    || (!must_finish && deadline.is_some_and(|d| Instant::now() >= d))
            };
            let Some((samples, duration, stats)) = self.render_pass(progress, &should_stop) else {
                summary.reason = if stop.load(Ordering::SeqCst) {
                    StopReason::Interrupted
                } else {
                    StopReason::TimeLimit
                };
                return Ok(summary);
            };
            last = Some((samples.len() as u32, duration));
            summary.passes += 1;
            summary.stats.add(stats);
            let report = PassReport {
                number: summary.passes,
                samples,
                duration,
                stats,
            };
            on_pass(self, &report)?;
        }
        Ok(summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render;
    use crate::scene::builtin;

    #[test]
    fn schedule_covers_every_sample_once_in_order() {
        for spp in [1, 2, 3, 7, 8, 64, 100, 1000, 5000] {
            let passes = schedule(spp);
            assert_eq!(passes[0], 0..1);
            assert_eq!(passes.last().unwrap().end, spp);
            for w in passes.windows(2) {
                assert_eq!(w[0].end, w[1].start);
            }
            let cap = (spp / 8).clamp(1, MAX_PASS_SPP) as usize;
            assert!(passes.iter().all(|p| !p.is_empty() && p.len() <= cap));
        }
        assert_eq!(schedule(64).len(), 11);
        assert!(ends_a_pass(4, 64) && ends_a_pass(64, 64));
        assert!(!ends_a_pass(3, 64) && !ends_a_pass(65, 64));
    }

    #[test]
    fn bounded_saves_take_at_most_a_twentieth_of_the_time() {
        let ms = Duration::from_millis;
        let bounded = SaveSchedule::Bounded;
        let long = Duration::from_secs(3600);
        // The first pass is saved, however short, unless the render is
        // about to end.
        assert!(bounded.due(ms(1), None, long));
        assert!(bounded.due(ms(1), None, QUICK_RENDER));
        assert!(!bounded.due(ms(1), None, QUICK_RENDER - ms(1)));
        assert!(!bounded.due(ms(1), None, ms(0)));
        // Then only once 19 times the last save's duration has passed,
        // whatever is left.
        assert!(!bounded.due(ms(1899), Some(ms(100)), long));
        assert!(bounded.due(ms(1900), Some(ms(100)), long));
        assert!(bounded.due(ms(1900), Some(ms(100)), ms(0)));
        // A simulated render after its first save: passes of 10 ms, saves
        // of 40 ms.
        let (pass, save) = (ms(10), ms(40));
        let (mut since, mut took, mut rendering, mut saving) = (ms(0), Some(save), ms(0), ms(0));
        for _ in 0..10_000 {
            rendering += pass;
            since += pass;
            if bounded.due(since, took, long) {
                saving += save;
                (since, took) = (ms(0), Some(save));
            }
        }
        let share = saving.as_secs_f64() / (saving + rendering).as_secs_f64();
        assert!(share <= 0.05 && share > 0.049, "{share}");
        // Every pass, or at most every interval, counted from the start.
        assert!(SaveSchedule::EveryPass.due(ms(0), Some(ms(100)), ms(0)));
        assert!(SaveSchedule::EveryPass.due(ms(0), None, ms(0)));
        let every = SaveSchedule::Every(Duration::from_secs(60));
        assert!(!every.due(ms(59_999), None, long) && every.due(ms(60_000), Some(ms(1)), ms(0)));
    }

    #[test]
    fn a_checkpoint_interval_is_a_duration_or_zero() {
        let every = |s| SaveSchedule::Every(Duration::from_secs(s));
        assert_eq!(SaveSchedule::parse("90s"), Ok(every(90)));
        assert_eq!(SaveSchedule::parse("2m"), Ok(every(120)));
        for zero in ["0", "0s", " 0.0m "] {
            assert_eq!(SaveSchedule::parse(zero), Ok(SaveSchedule::EveryPass));
        }
        for bad in ["-1s", "soon", "", "s"] {
            assert!(SaveSchedule::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_share_renders_in_the_whole_renders_largest_passes() {
        // 500 spp in 8 parts: shares of 62 or 63 in passes of 62.
        let sizes = |len: u32, spp: u32| {
            let (mut done, mut out) = (0, Vec::new());
            while done < len {
                let n = share_pass_size(done, len, spp);
                assert!(ends_a_share_pass(done, len, spp));
                out.push(n);
                done += n;
            }
            assert!(ends_a_share_pass(len, len, spp));
            assert!(len == 0 || !ends_a_share_pass(len - 1, len, spp) || out.last() == Some(&1));
            out
        };
        assert_eq!(sizes(62, 500), [62]);
        assert_eq!(sizes(63, 500), [62, 1]);
        assert_eq!(sizes(16, 128), [16]);
        assert_eq!(sizes(40, 128), [16, 16, 8]);
        assert_eq!(sizes(0, 5), Vec::<u32>::new());
        // A whole render keeps its schedule.
        assert_eq!(
            sizes(64, 64),
            schedule(64)
                .iter()
                .map(|p| p.len() as u32)
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn durations_parse_with_units() {
        assert_eq!(parse_duration("90s"), Ok(Duration::from_secs(90)));
        assert_eq!(parse_duration("1.5m"), Ok(Duration::from_secs(90)));
        assert_eq!(parse_duration("2h"), Ok(Duration::from_secs(7200)));
        assert_eq!(parse_duration("45"), Ok(Duration::from_secs(45)));
        for bad in ["", "s", "0s", "-1m", "ten", "5d", "nan", "inf"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
        assert!(parse_duration("2e9s").unwrap_err().contains("at most"));
        assert!(parse_duration("-1m").unwrap_err().contains("positive"));
    }

    fn small_desc() -> SceneDesc {
        let mut desc = builtin::find("glass-hollow").unwrap().desc();
        desc.render.width = 24;
        desc.render.samples_per_pixel = 40;
        desc
    }

    #[test]
    fn passes_and_resume_equal_one_render_bit_for_bit() {
        let desc = small_desc();
        let (reference, ref_stats) = render(&Scene::from_desc(&desc).unwrap(), &|_| {});
        let stop = AtomicBool::new(false);
        // Stop after the third pass, save, resume from the saved bytes.
        let mut first = Session::new(&desc).unwrap();
        let run = first
            .run(&stop, None, &|_| {}, &mut |_, r| {
                if r.number == 3 {
                    stop.store(true, Ordering::SeqCst);
                }
                Ok::<(), ()>(())
            })
            .unwrap();
        assert_eq!(run.reason, StopReason::Interrupted);
        assert_eq!(first.spp_done(), 4);
        let path = Path::new("mem");
        let ckpt = Checkpoint::decode(&first.checkpoint().encode(), path).unwrap();
        let mut second = Session::resume(&desc, ckpt, path).unwrap();
        stop.store(false, Ordering::SeqCst);
        let run = second
            .run(&stop, None, &|_| {}, &mut |_, _| Ok::<(), ()>(()))
            .unwrap();
        assert_eq!(run.reason, StopReason::Complete);
        assert_eq!(second.film(), &reference);
        assert_eq!(second.stats(), ref_stats);
    }

    #[test]
    fn adaptive_passes_and_resume_equal_one_run_whatever_the_threads() {
        let mut desc = small_desc();
        desc.render.samples_per_pixel = 96;
        desc.render.sampler = crate::scene::Sampling::Sobol;
        desc.render.noise_target = Some(0.05);
        let stop = AtomicBool::new(false);
        let run_all = |threads: usize| {
            let mut session = Session::new(&desc).unwrap();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| session.run(&stop, None, &|_| {}, &mut |_, _| Ok::<(), ()>(())))
                .unwrap();
            session
        };
        let whole = run_all(1);
        let active = whole.active_pixels().unwrap();
        let pixels = whole.film().len();
        assert!(
            active < pixels && whole.stats().samples < pixels as u64 * 96,
            "no pixel stopped ({active} of {pixels} active)"
        );
        let other = run_all(2);
        assert_eq!(other.film(), whole.film());
        assert_eq!(other.active(), whole.active());
        // Stopped after the sixth pass (past the minimum: some pixels have
        // stopped), saved, resumed.
        let mut first = Session::new(&desc).unwrap();
        first
            .run(&stop, None, &|_| {}, &mut |_, r| {
                if r.number == 6 {
                    stop.store(true, Ordering::SeqCst);
                }
                Ok::<(), ()>(())
            })
            .unwrap();
        assert!(first.spp_done() >= crate::adaptive::MIN_SAMPLES);
        assert!(first.active_pixels().unwrap() < pixels, "none stopped yet");
        let path = Path::new("mem");
        let ckpt = Checkpoint::decode(&first.checkpoint().encode(), path).unwrap();
        let mut second = Session::resume(&desc, ckpt, path).unwrap();
        stop.store(false, Ordering::SeqCst);
        second
            .run(&stop, None, &|_| {}, &mut |_, _| Ok::<(), ()>(()))
            .unwrap();
        assert_eq!(second.film(), whole.film());
        assert_eq!(second.active(), whole.active());
        assert_eq!(second.stats(), whole.stats());
    }

    #[test]
    fn an_abandoned_pass_leaves_the_film_as_it_was() {
        let desc = small_desc();
        let mut session = Session::new(&desc).unwrap();
        session.render_pass(&|_| {}, &|| false).unwrap();
        let before = session.film().clone();
        let rows = std::sync::atomic::AtomicU32::new(0);
        let stop_after_some_rows = || rows.fetch_add(1, Ordering::SeqCst) >= 3;
        assert!(session
            .render_pass(&|_| {}, &stop_after_some_rows)
            .is_none());
        assert_eq!(session.film(), &before);
        assert_eq!(session.spp_done(), 1);
    }
}
