//! `lumen merge`: the part files of a split render joined into its image.

use crate::render::resolved;
use anyhow::{bail, Result};
use lumen::lock::RenderLock;
use lumen::output;
use lumen::part::{self, Merged};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub(crate) fn merge_command(
    parts: &[PathBuf],
    out: &Path,
    partial: bool,
    gamma: Option<f32>,
    denoise_args: &crate::DenoiseArgs,
) -> Result<ExitCode> {
    output::ImageFormat::from_path(out)?;
    let place = resolved(out);
    if let Some(p) = parts.iter().find(|p| resolved(p) == place) {
        bail!(
            "{}: the merged image cannot be one of the parts; choose another -o",
            p.display()
        );
    }
    output::check_writable(out)?;
    let _lock = RenderLock::acquire(out)?;
    let merged: Merged = part::merge(parts, partial)?;
    if merged.samples_held == 0 {
        bail!("the parts hold no samples yet: nothing to merge");
    }
    if let (false, Some(option)) = (merged.denoise, denoise_args.any()) {
        return Err(crate::Usage(format!(
            "{option}: the parts' render is not denoised; `lumen denoise` denoises an EXR image"
        ))
        .into());
    }
    // A partial merge is a preview: denoised only once complete.
    let denoise = merged.denoise && merged.is_complete();
    let options = denoise_args.options(merged.denoise_choices)?;
    if denoise {
        crate::denoise::announce(options.denoiser)?;
    }
    crate::denoise::write_image(
        out,
        &merged.film,
        gamma.unwrap_or(merged.gamma),
        &merged.aovs,
        denoise.then_some(options),
    )?;
    if merged.is_complete() {
        errln!(
            "merged {} part{} ({} spp) into {}",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" },
            merged.spp,
            out.display()
        );
    } else if merged.is_whole_image() {
        errln!(
            "lumen: partial merge: {} holds {} of {} spp (samples {}) of every pixel",
            out.display(),
            merged.held_spp(),
            merged.spp,
            part::ranges_text(&merged.held)
        );
    } else {
        let (w, h) = (merged.film.width(), merged.film.height());
        let all = u64::from(w) * u64::from(h) * u64::from(merged.spp);
        errln!(
            "lumen: partial merge: {} holds {} of the {all} samples of the {w}x{h} image ({:.1}%) from {} tile{}; pixels no part holds are black",
            out.display(),
            merged.samples_held,
            100.0 * merged.samples_held as f64 / all as f64,
            merged.tiles.len(),
            if merged.tiles.len() == 1 { "" } else { "s" },
        );
    }
    Ok(ExitCode::SUCCESS)
}
