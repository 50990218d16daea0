//! `lumen render`: a progressive render with checkpoints, interrupts and a time limit.

use crate::scenes::load_scene;
use crate::signals::{install_stop_handler, quit_if_asked, saving, EXIT_INTERRUPTED};
use crate::{progress_bar, summary, ProgressiveArgs, SettingArgs, Usage};
use anyhow::{bail, Context, Result};
use lumen::checkpoint::{self, Checkpoint, Existing};
use lumen::lock::RenderLock;
use lumen::math::Color;
use lumen::part::{self, Share};
use lumen::preview::{Preview, Status};
use lumen::progressive::{Session, StopReason};
use lumen::{files, output};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// Where a path points once its directory is resolved (the file itself may
/// not exist yet): `./out.png`, `out.png` and `$PWD/out.png` are one place.
pub(crate) fn resolved(path: &Path) -> PathBuf {
    let dir = output::parent_dir(path);
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    match path.file_name() {
        Some(name) => dir.join(name),
        None => dir,
    }
}

/// The checkpoint is overwritten between passes and deleted at the end:
/// it must be neither the output image nor the scene file. (What is
/// already at its path is looked at once the render holds its lock.)
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
    Ok(())
}

/// Removes the temporaries of `paths` that killed renders left, saying so.
fn remove_stale_temps(paths: &[&Path]) {
    let removed: Vec<String> = paths
        .iter()
        .flat_map(|p| files::remove_stale_temps(p))
        .map(|p| p.display().to_string())
        .collect();
    if !removed.is_empty() {
        errln!(
            "lumen: note: removed {} temporary file{} left by a render that no longer runs: {}",
            removed.len(),
            if removed.len() == 1 { "" } else { "s" },
            removed.join(", ")
        );
    }
}

pub(crate) fn render_command(
    name: &str,
    out: &Path,
    args: &SettingArgs,
    prog: &ProgressiveArgs,
    import: &lumen::scene::file::mitsuba::Options,
) -> Result<ExitCode> {
    let (desc, scene) = load_scene(name, import)?.resolve(name, &args.overrides())?;
    for report in &scene.reports {
        errln!("{report}");
        for warning in &report.warnings {
            errln!("lumen: warning: {}: {warning}", report.file);
        }
    }
    let is_part_file = out.extension().is_some_and(|e| e == part::EXTENSION);
    let share = Share {
        part: prog.part,
        split: prog.split.unwrap_or_default(),
        tile: prog.tile,
    };
    let is_part = !share.is_whole();
    match is_part {
        true if !is_part_file => {
            return Err(Usage(format!(
                "{}: a part of a render is written to a part file: -o NAME.{}",
                out.display(),
                part::EXTENSION
            ))
            .into())
        }
        false if is_part_file => {
            return Err(Usage(format!(
                "{}: a part file holds a part of a render: give --part K/N or --tile X0,Y0,X1,Y1",
                out.display()
            ))
            .into())
        }
        true => {}
        false => {
            output::ImageFormat::from_path(out)?;
        }
    }
    // What the render saves: the image and its checkpoint, or a part file,
    // which is its own checkpoint.
    let image = (!is_part).then_some(out);
    let ckpt_path = match image {
        None => out.to_path_buf(),
        Some(_) => {
            let ckpt_path = prog
                .checkpoint
                .clone()
                .unwrap_or_else(|| checkpoint::default_path(out));
            check_checkpoint_path(&ckpt_path, out, name)?;
            ckpt_path
        }
    };
    let denoise = scene.settings.denoise && image.is_some();
    if scene.settings.denoise && image.is_none() {
        // How the merged image is denoised is `lumen merge`'s to say.
        if let Some(option) = prog.denoise.any() {
            return Err(Usage(format!(
                "{option}: a part is not denoised; give it to `lumen merge`"
            ))
            .into());
        }
        errln!("lumen: note: a part is not denoised; `lumen merge` denoises the merged image");
    } else if !denoise {
        let previews = prog.denoise_previews.then_some("--denoise-previews");
        if let Some(option) = previews.or(prog.denoise.any()) {
            return Err(Usage(format!(
                "{option}: the render is not denoised; add --denoise"
            ))
            .into());
        }
    }
    let options = prog.denoise.options(scene.settings.denoise_choices)?;
    let noisy = output::noisy_path(out);
    let mut targets: Vec<&Path> = match image {
        Some(image) => vec![image, &ckpt_path],
        None => vec![&ckpt_path],
    };
    if denoise {
        // Refused before the render, not after it: a build or a machine
        // without the denoiser.
        crate::denoise::announce(options.denoiser)?;
        output::check_writable(&noisy)?;
        targets.push(&noisy);
    }
    // Refuse unwritable destinations now, not after a long render.
    output::check_writable(out)?;
    if image.is_some() {
        output::check_writable(&ckpt_path).context("checkpoint")?;
    }
    // Held to the end: no other render writes these files meanwhile.
    let _locks = targets
        .iter()
        .map(|t| RenderLock::acquire(t))
        .collect::<Result<Vec<_>, _>>()?;
    remove_stale_temps(&targets);
    let session = Session::with_share(&desc, scene, share)?;
    let mut session = if prog.resume {
        if !ckpt_path.exists() {
            bail!(
                "--resume: there is no checkpoint at {}",
                ckpt_path.display()
            );
        }
        let ckpt = Checkpoint::read(&ckpt_path)?;
        session.restore(ckpt, &ckpt_path)?
    } else {
        match checkpoint::inspect(&ckpt_path)? {
            Existing::Nothing => {}
            Existing::Checkpoint => errln!(
                "lumen: note: starting afresh; the checkpoint {} will be replaced (--resume continues it)",
                ckpt_path.display()
            ),
            Existing::Damaged => errln!(
                "lumen: note: starting afresh; the damaged checkpoint {} will be replaced",
                ckpt_path.display()
            ),
        }
        session
    };

    // Started once everything else is checked: a port in use is refused
    // before any sample is taken.
    let preview = match prog.preview {
        true => {
            let preview = Preview::start(prog.preview_port.unwrap_or(0))?;
            errln!("preview: {}", preview.url());
            Some(preview)
        }
        false => None,
    };
    let stop = Arc::new(AtomicBool::new(false));
    install_stop_handler(&stop, &targets)?;

    let s = session.scene().settings.clone();
    let resumed_from = session.spp_done();
    let tile = session.tile();
    let samples = session.share();
    let pixels_text = match tile.is_whole(s.width, s.height) {
        true => String::new(),
        false => format!("pixels {tile}, "),
    };
    let part_text = format!(
        "{share}: {pixels_text}samples {}..{}",
        samples.start, samples.end
    );
    let of_part = match is_part {
        true => format!(", {part_text}"),
        false => String::new(),
    };
    errln!(
        "{name}: {}x{} at {} spp, depth {}{of_part}{}",
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
    // Saves the image, and the checkpoint unless the render is complete, as
    // one step that a second interrupt lets finish (see `signals`).
    // `last`: the render's final image (denoised, when asked), not a
    // preview after a pass.
    // Returns the denoised image when it made one.
    let save = |session: &Session, last: bool| -> Result<Option<Vec<Color>>> {
        // An image of nothing but dropped samples is black, and replacing the
        // file there with it would lose what it held for no image at all.
        if session.stats().all_dropped() {
            return Ok(None);
        }
        let _saving = saving();
        let mut denoised = None;
        if let Some(image) = image {
            let now = denoise && (last || prog.denoise_previews);
            let denoise = now.then_some(options);
            denoised =
                crate::denoise::write_image(image, session.film(), s.gamma, &s.aovs, denoise)?;
        }
        if image.is_none() || !session.is_complete() {
            session
                .checkpoint()
                .write(&ckpt_path)
                .context(match image {
                    Some(_) => "cannot save the checkpoint",
                    None => "cannot save the part",
                })?;
        }
        quit_if_asked();
        Ok(denoised)
    };
    // The page's status after a pass: the ETA from this run's pace.
    let status = |session: &Session, pass: u32, elapsed: std::time::Duration| {
        let done = session.spp_done() - resumed_from;
        let left = session.spp_left();
        Status {
            pass,
            spp_done: session.spp_done(),
            spp_total: session.spp_total(),
            elapsed: elapsed.as_secs_f64(),
            eta: (done > 0).then(|| elapsed.as_secs_f64() * f64::from(left) / f64::from(done)),
            gamma: s.gamma,
        }
    };
    let pixels = tile.area();
    let bar = progress_bar(pixels * u64::from(samples.end - resumed_from));
    let start = Instant::now();
    let mut last_save = start;
    let mut last_save_took = None;
    let run = session.run(&stop, prog.time_limit, &|n| bar.inc(n), &mut |session,
                                                                          pass|
     -> Result<
        (),
    > {
        bar.suspend(|| {
            let adaptive = session.active_pixels().map_or(String::new(), |n| {
                format!(
                    ", {n} of {pixels} pixels still sampling ({:.1} spp on average)",
                    session.stats().samples as f64 / pixels as f64
                )
            });
            errln!(
                "pass {}: samples {}..{} in {:.3} s, {} of {} spp{adaptive}",
                pass.number,
                pass.samples.start,
                pass.samples.end,
                pass.duration.as_secs_f64(),
                session.spp_done(),
                session.spp_total()
            )
        });
        // The finished image is written once, below.
        let predicted = pass
            .duration
            .mul_f64(f64::from(session.spp_left()) / pass.samples.len().max(1) as f64);
        let due = prog.checkpoint_interval.unwrap_or_default().due(
            last_save.elapsed(),
            last_save_took,
            predicted,
        );
        let mut denoised = None;
        if !session.is_complete() && due {
            let saving = Instant::now();
            denoised = save(session, false)?;
            last_save = Instant::now();
            last_save_took = Some(last_save - saving);
        }
        if let Some(preview) = &preview {
            let status = status(session, pass.number, start.elapsed());
            let film = session.film();
            preview.publish(status, film, &s.aovs, denoised.as_deref(), false);
        }
        Ok(())
    })?;
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    let mut last_denoised = None;
    let (held, total) = (session.spp_done(), session.spp_total());
    if session.stats().all_dropped() {
        errln!("{}", summary(&run.stats, &session.stats(), elapsed));
        errln!(
            "lumen: error: every sample came out NaN, infinite or beyond 9.2e18 (more than a \
             pixel's sum holds); {} was not written, and what was there is as it was",
            out.display()
        );
        return Ok(ExitCode::FAILURE);
    }
    let code = match (run.reason, is_part) {
        (StopReason::Complete, true) => {
            last_denoised = save(&session, true)?;
            errln!(
                "{name}: {part_text} of {total} spp written to {}",
                out.display()
            );
            ExitCode::SUCCESS
        }
        (StopReason::Complete, false) => {
            last_denoised = save(&session, true)?;
            if let Err(e) = checkpoint::remove(&ckpt_path) {
                errln!("lumen: warning: cannot remove {}: {e}", ckpt_path.display())
            }
            let spp = match session.active_pixels() {
                None => format!("{total} spp"),
                Some(_) => format!(
                    "up to {total} spp ({:.1} on average, noise target {})",
                    session.stats().samples as f64 / pixels as f64,
                    s.noise_target.unwrap_or_default()
                ),
            };
            errln!("{name}: {spp} written to {}", out.display());
            ExitCode::SUCCESS
        }
        (reason, _) if held == samples.start => {
            debug_assert_eq!(reason, StopReason::Interrupted);
            errln!("lumen: interrupted before the first pass finished; nothing written");
            ExitCode::from(EXIT_INTERRUPTED)
        }
        (reason, _) => {
            last_denoised = save(&session, true)?;
            let (why, code) = match reason {
                StopReason::Interrupted => ("interrupted", ExitCode::from(EXIT_INTERRUPTED)),
                // An unfinished part is not a finished task: a job engine
                // must see it fail, and the merge refuses it.
                _ if is_part => ("time limit reached", ExitCode::FAILURE),
                _ => ("time limit reached", ExitCode::SUCCESS),
            };
            if is_part {
                errln!(
                    "lumen: {why}: part {} holds samples {}..{held} of its share {}..{}; continue with --resume",
                    out.display(),
                    samples.start,
                    samples.start,
                    samples.end
                );
            } else {
                errln!(
                    "lumen: {why}: {} holds {held} of {total} spp; checkpoint {} (continue with --resume)",
                    out.display(),
                    ckpt_path.display()
                );
            }
            code
        }
    };
    if let Some(preview) = &preview {
        let status = status(&session, run.passes, elapsed);
        let film = session.film();
        preview.publish(status, film, &s.aovs, last_denoised.as_deref(), true);
        preview.finish();
    }
    errln!("{}", summary(&run.stats, &session.stats(), elapsed));
    let all = session.stats();
    if let Some(warning) = all.dropped_warning() {
        errln!("lumen: warning: {warning}");
    }
    Ok(code)
}
