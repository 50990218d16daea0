//! Writing images: plain-text PPM (the notes' format), 8-bit PNG, and linear
//! floating-point PFM and OpenEXR. Every file is written to a temporary name
//! beside its destination and renamed into place, so a reader never sees a
//! half-written file.
//!
//! Feature buffers ([`crate::aov`]) are written as layers of an EXR image
//! (channels `albedo.R`, `normal.X`, `depth.Z`, … beside the image's `R`,
//! `G`, `B`), or beside an image of another format as PFM files named after
//! it (`out.png` → `out.albedo.pfm`).

use crate::aov::{Aov, Layer};
use crate::film::Film;
use crate::math::{Color, Vec3};
use std::fs;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Image file formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.ppm`: plain-text P3, 8-bit, gamma applied.
    Ppm,
    /// `.png`: 8-bit RGB, gamma applied.
    Png,
    /// `.pfm`: portable float map, linear (no gamma, no clamping).
    Pfm,
    /// `.exr`: OpenEXR, 32-bit float, linear.
    Exr,
}

/// An image that could not be written.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The extension names no supported format.
    #[error("{path}: unknown image format; use a file name ending in .ppm, .png, .pfm or .exr")]
    UnknownFormat {
        /// The output path.
        path: PathBuf,
    },
    /// The destination cannot be written.
    #[error("{path}: {message}")]
    Io {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("ppm") => Ok(Self::Ppm),
            Some("png") => Ok(Self::Png),
            Some("pfm") => Ok(Self::Pfm),
            Some("exr") => Ok(Self::Exr),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

fn io_error(path: &Path, e: impl std::fmt::Display) -> OutputError {
    OutputError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Checks, before any work is done, that `path` can later be written: it
/// is a regular file or does not exist yet (see
/// [`crate::files::check_regular`]), and its directory exists and accepts
/// new files.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    crate::files::check_regular(path).map_err(|e| io_error(path, e))?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(io_error(
            path,
            format!("directory {} does not exist", dir.display()),
        ));
    }
    let probe = temp_path(path);
    fs::File::create(&probe)
        .and_then(|_| fs::remove_file(&probe))
        .map_err(|e| io_error(path, format!("cannot write in {}: {e}", dir.display())))
}

/// The directory `path` is in: its parent, or `.` for a bare file name.
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The temporary name [`write_atomic`] writes `path`'s content to before
/// renaming it into place: `.NAME.PID.tmp`, hidden, in the same directory,
/// unique per process (shortened to fit in a file name, see
/// [`crate::files::temp_path_of`]).
pub fn temp_path(path: &Path) -> PathBuf {
    crate::files::temp_path_of(path, std::process::id())
}

/// Writes a file atomically: `write` fills a temporary file in the same
/// directory, which is flushed to disk and then renamed over `path`. Only a
/// regular file is replaced: anything else at `path` (a device, a named
/// pipe, a directory) is refused before anything is written.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), OutputError> {
    crate::files::check_regular(path).map_err(|e| io_error(path, e))?;
    let tmp = temp_path(path);
    let result = write(&tmp)
        .and_then(|()| {
            fs::File::open(&tmp)
                .and_then(|f| f.sync_all())
                .map_err(|e| e.to_string())
        })
        .and_then(|()| fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if let Err(message) = result {
        let _ = fs::remove_file(&tmp);
        return Err(OutputError::Io {
            path: path.to_path_buf(),
            message,
        });
    }
    Ok(())
}

/// Writes a file atomically through a buffered writer that `write` fills
/// (see [`write_atomic`]).
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<fs::File>) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    write_atomic(path, |tmp| {
        let mut out = std::io::BufWriter::new(fs::File::create(tmp).map_err(|e| e.to_string())?);
        write(&mut out)
            .and_then(|()| std::io::Write::flush(&mut out))
            .map_err(|e| e.to_string())
    })
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomic(path, |tmp| fs::write(tmp, bytes).map_err(|e| e.to_string()))
}

/// The colours an image file shows: a film's means, or colours of a
/// film's size computed from them (a denoised image).
#[derive(Clone, Copy)]
pub enum Beauty<'a> {
    /// Each pixel's mean.
    Film(&'a Film),
    /// Given colours, row-major, top row first.
    Colors {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// `width × height` colours.
        colors: &'a [Color],
    },
}

impl Beauty<'_> {
    fn size(&self) -> (u32, u32) {
        match self {
            Beauty::Film(film) => (film.width(), film.height()),
            Beauty::Colors { width, height, .. } => (*width, *height),
        }
    }

    fn len(&self) -> usize {
        let (w, h) = self.size();
        w as usize * h as usize
    }

    /// Pixel `i`'s colour (row-major).
    fn at(&self, i: usize) -> Color {
        match self {
            Beauty::Film(film) => film.mean(i),
            Beauty::Colors { colors, .. } => colors[i],
        }
    }

    /// 8-bit bytes, three a pixel, as [`Film::to_rgb8`] makes them.
    fn rgb8(&self, gamma: f32) -> Vec<u8> {
        match self {
            Beauty::Film(film) => film.to_rgb8(gamma),
            Beauty::Colors { colors, .. } => {
                crate::film::rgb8(colors.iter().copied(), colors.len(), gamma)
            }
        }
    }
}

/// Writes the film to `path` in the format its extension names, with its
/// feature buffers `aovs` (see the module's documentation).
pub fn write_image(path: &Path, film: &Film, gamma: f32, aovs: &[Aov]) -> Result<(), OutputError> {
    write_image_as(path, Beauty::Film(film), film, gamma, aovs)
}

/// [`write_image`], showing `beauty` (of the film's size) as its image.
pub fn write_image_as(
    path: &Path,
    beauty: Beauty,
    film: &Film,
    gamma: f32,
    aovs: &[Aov],
) -> Result<(), OutputError> {
    assert_eq!(
        beauty.size(),
        (film.width(), film.height()),
        "an image of the film's size"
    );
    let format = ImageFormat::from_path(path)?;
    if aovs.is_empty() {
        return write_beauty(path, beauty, gamma, format);
    }
    if format == ImageFormat::Exr {
        let mut channels = beauty_channels(beauty);
        for &aov in aovs {
            for (name, values) in aov.channels().iter().zip(aov_values(film, aov)) {
                channels.push((format!("{}.{name}", aov.name()), values));
            }
        }
        return write_exr(path, beauty.size(), channels);
    }
    write_beauty(path, beauty, gamma, format)?;
    for &aov in aovs {
        write_bytes_atomic(&aov_path(path, aov), &encode_aov_pfm(film, aov))?;
    }
    Ok(())
}

/// Writes `beauty` alone to `path`, in the format its extension names.
pub fn write_colors(path: &Path, beauty: Beauty, gamma: f32) -> Result<(), OutputError> {
    write_beauty(path, beauty, gamma, ImageFormat::from_path(path)?)
}

/// Where the noisy image of a denoised render written to `path` goes:
/// `NAME.noisy.EXT` beside it.
pub fn noisy_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    match path.extension() {
        Some(ext) => path.with_file_name(format!("{stem}.noisy.{}", ext.to_string_lossy())),
        None => path.with_file_name(format!("{stem}.noisy")),
    }
}

/// Where feature buffer `aov` of an image written to `path` (not an EXR
/// file) goes: `NAME.AOV.pfm` beside it.
pub fn aov_path(path: &Path, aov: Aov) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{}.pfm", aov.name()))
}

/// Feature buffer `aov` of pixel `i` (row-major) of `film`: its channels
/// (of [`Aov::channels`]) first.
fn aov_pixel(film: &Film, aov: Aov, i: usize) -> Vec3 {
    match aov {
        Aov::Albedo => film.feature(Layer::Albedo, i),
        Aov::Normal => film.feature(Layer::Normal, i),
        Aov::Position => film.feature(Layer::Position, i),
        Aov::Depth => film.feature(Layer::Depth, i),
        Aov::Variance => film.variance(i),
        Aov::Spp => Vec3::new(film.count(i) as f32, 0.0, 0.0),
    }
}

/// The first `channels` channels of `value` over `n` pixels: a vector a
/// channel, each pixel's value computed once, on all threads (an image is
/// saved between passes, while they wait).
fn channel_vectors(
    n: usize,
    channels: usize,
    value: impl Fn(usize) -> Vec3 + Sync + Send,
) -> Vec<Vec<f32>> {
    use rayon::prelude::*;
    let values: Vec<Vec3> = (0..n).into_par_iter().map(value).collect();
    (0..channels)
        .map(|c| values.iter().map(|v| v[c]).collect())
        .collect()
}

/// Feature buffer `aov` of `film`: a vector of values a channel (of
/// [`Aov::channels`]), each row-major, top row first.
pub fn aov_values(film: &Film, aov: Aov) -> Vec<Vec<f32>> {
    channel_vectors(film.len(), aov.channels().len(), |i| {
        aov_pixel(film, aov, i)
    })
}

/// The image as channels `R`, `G`, `B`.
fn beauty_channels(beauty: Beauty) -> Vec<(String, Vec<f32>)> {
    let rgb = channel_vectors(beauty.len(), 3, |i| beauty.at(i));
    ["R", "G", "B"]
        .into_iter()
        .map(String::from)
        .zip(rgb)
        .collect()
}

/// Named channels of `size` pixels (each row-major, top row first) as
/// one EXR image of 32-bit floats, in the order EXR sorts them.
pub fn write_exr(
    path: &Path,
    (w, h): (u32, u32),
    channels: Vec<(String, Vec<f32>)>,
) -> Result<(), OutputError> {
    use exr::prelude::*;
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, values)| AnyChannel::new(name.as_str(), FlatSamples::F32(values)))
        .collect();
    let layer = Layer::new(
        (w as usize, h as usize),
        LayerAttributes::default(),
        exr_encoding(),
        AnyChannels::sort(channels),
    );
    write_atomic(path, |tmp| {
        Image::from_layer(layer)
            .write()
            .to_file(tmp)
            .map_err(|e| e.to_string())
    })
}

/// Feature buffer `aov` of `film` as a PFM file: colour (`PF`) for three
/// channels, grey (`Pf`) for one.
pub fn encode_aov_pfm(film: &Film, aov: Aov) -> Vec<u8> {
    let grey = aov.channels().len() == 1;
    pfm((film.width(), film.height()), grey, |i| {
        aov_pixel(film, aov, i)
    })
}

/// A PFM file of `size`, of `value` at each pixel (row-major index): its
/// first channel if `grey`, else all three; little-endian, bottom row
/// first.
fn pfm((w, h): (u32, u32), grey: bool, value: impl Fn(usize) -> Vec3) -> Vec<u8> {
    let (w, h) = (w as usize, h as usize);
    let (kind, channels) = if grey { ("Pf", 1) } else { ("PF", 3) };
    let mut out = format!("{kind}\n{w} {h}\n-1.0\n").into_bytes();
    out.reserve(w * h * 4 * channels);
    for y in (0..h).rev() {
        for x in 0..w {
            let v = value(y * w + x);
            for c in 0..channels {
                out.extend_from_slice(&v[c].to_le_bytes());
            }
        }
    }
    out
}

/// How lumen writes EXR files: blocks in increasing order, so that they
/// are also written in order (compressed in parallel) and the same image
/// gives the same file.
fn exr_encoding() -> exr::prelude::Encoding {
    exr::prelude::Encoding {
        line_order: exr::prelude::LineOrder::Increasing,
        ..exr::prelude::Encoding::default()
    }
}

/// Writes `beauty` alone to `path` in `format`.
fn write_beauty(
    path: &Path,
    beauty: Beauty,
    gamma: f32,
    format: ImageFormat,
) -> Result<(), OutputError> {
    let (w, h) = beauty.size();
    match format {
        ImageFormat::Ppm => write_bytes_atomic(path, &ppm(beauty, gamma)),
        ImageFormat::Pfm => write_bytes_atomic(path, &pfm((w, h), false, |i| beauty.at(i))),
        ImageFormat::Png => {
            let rgb = beauty.rgb8(gamma);
            write_atomic(path, |tmp| {
                image::save_buffer_with_format(
                    tmp,
                    &rgb,
                    w,
                    h,
                    image::ExtendedColorType::Rgb8,
                    image::ImageFormat::Png,
                )
                .map_err(|e| e.to_string())
            })
        }
        ImageFormat::Exr => write_atomic(path, |tmp| {
            use exr::prelude::*;
            let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                let c = beauty.at(y * w as usize + x);
                (c.x, c.y, c.z)
            });
            Image::from_encoded_channels((w as usize, h as usize), exr_encoding(), channels)
                .write()
                .to_file(tmp)
                .map_err(|e| e.to_string())
        }),
    }
}

/// Plain-text P3 PPM: a header, then one "r g b" line a pixel, top row first.
pub fn encode_ppm(film: &Film, gamma: f32) -> Vec<u8> {
    ppm(Beauty::Film(film), gamma)
}

fn ppm(beauty: Beauty, gamma: f32) -> Vec<u8> {
    use std::fmt::Write as _;
    const IN_MEMORY: &str = "writing to a String cannot fail";
    let bytes = beauty.rgb8(gamma);
    let (w, h) = beauty.size();
    let mut out = String::with_capacity(bytes.len() * 4 + 32);
    writeln!(out, "P3\n{w} {h}\n255").expect(IN_MEMORY);
    for p in bytes.chunks_exact(3) {
        writeln!(out, "{} {} {}", p[0], p[1], p[2]).expect(IN_MEMORY);
    }
    out.into_bytes()
}

/// Portable float map: linear RGB, little-endian, bottom row first.
pub fn encode_pfm(film: &Film) -> Vec<u8> {
    pfm((film.width(), film.height()), false, |i| film.mean(i))
}
