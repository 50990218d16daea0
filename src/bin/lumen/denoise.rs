//! Denoised images: a render's finished image (`--denoise`) and
//! `lumen denoise`, which denoises an EXR image that has its albedo and
//! normal layers.

use crate::render::resolved;
use anyhow::{bail, Context, Result};
use lumen::aov::Aov;
use lumen::denoise::{self, Denoiser, ExrChannels, Inputs, Options};
use lumen::film::Film;
use lumen::lock::RenderLock;
use lumen::math::Color;
use lumen::output::{self, Beauty, ImageFormat};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// Says which denoiser a render will use, or refuses before it starts.
pub(crate) fn announce(denoiser: Denoiser) -> Result<()> {
    let library = denoise::check_available(denoiser).context("--denoise")?;
    errln!("denoising with {library}");
    Ok(())
}

/// Writes the film to `out` with its feature buffers; when `denoise`, the
/// image denoised with those options, and the noisy one beside it (see
/// [`output::noisy_path`]), written first so that a failed denoise loses
/// nothing. Returns the denoised image, if it made one.
pub(crate) fn write_image(
    out: &Path,
    film: &Film,
    gamma: f32,
    aovs: &[Aov],
    denoise: Option<Options>,
) -> Result<Option<Vec<Color>>> {
    let Some(options) = denoise else {
        output::write_image(out, film, gamma, aovs)?;
        return Ok(None);
    };
    let noisy = output::noisy_path(out);
    // Another format's feature buffers are files of their own, written
    // once, beside the denoised image.
    let noisy_aovs = match ImageFormat::from_path(out)? {
        ImageFormat::Exr => aovs,
        _ => &[],
    };
    output::write_image(&noisy, film, gamma, noisy_aovs)?;
    let start = Instant::now();
    let clean =
        denoise::denoise_film(film, rayon::current_num_threads(), options).with_context(|| {
            format!(
                "cannot denoise the image; the noisy image is in {}",
                noisy.display()
            )
        })?;
    let beauty = Beauty::Colors {
        width: film.width(),
        height: film.height(),
        colors: &clean,
    };
    output::write_image_as(out, beauty, film, gamma, aovs)?;
    errln!(
        "denoised in {:.2} s; the noisy image is {}",
        start.elapsed().as_secs_f64(),
        noisy.display()
    );
    Ok(Some(clean))
}

/// `lumen denoise IN.exr -o OUT`: the image of `input` denoised with its
/// albedo and normal layers. An EXR output keeps every other channel of
/// the input; another format holds the image alone.
pub(crate) fn denoise_command(
    input: &Path,
    out: &Path,
    gamma: f32,
    options: Options,
) -> Result<ExitCode> {
    let format = ImageFormat::from_path(out)?;
    if resolved(input) == resolved(out) {
        bail!(
            "{}: the denoised image cannot replace its input; choose another -o",
            out.display()
        );
    }
    output::check_writable(out)?;
    let image = ExrChannels::read(input)?;
    let guided = image.denoiser_layers(input)?;
    let library = denoise::check_available(options.denoiser)?;
    let _lock = RenderLock::acquire(out)?;
    let start = Instant::now();
    let clean = denoise::denoise(
        &Inputs {
            width: image.width,
            height: image.height,
            color: &guided.color,
            albedo: Some(&guided.albedo),
            normal: Some(&guided.normal),
            variance: guided.variance.as_deref(),
            options,
        },
        rayon::current_num_threads(),
    )?;
    let seconds = start.elapsed().as_secs_f64();
    let (w, h) = (image.width as u32, image.height as u32);
    let beauty = Beauty::Colors {
        width: w,
        height: h,
        colors: &clean,
    };
    match format {
        ImageFormat::Exr => {
            let mut channels = image.channels;
            for (name, values) in &mut channels {
                let c = match name.as_str() {
                    "R" => 0,
                    "G" => 1,
                    "B" => 2,
                    _ => continue,
                };
                for (v, p) in values.iter_mut().zip(&clean) {
                    *v = p[c];
                }
            }
            output::write_exr(out, (w, h), channels)?;
        }
        _ => output::write_colors(out, beauty, gamma)?,
    }
    errln!(
        "{}: {w}x{h} denoised in {seconds:.2} s by {library}, written to {}",
        input.display(),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
