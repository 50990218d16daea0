//! Denoising: a noisy image and its albedo and normal buffers
//! ([`crate::aov`]) in, a clean image out, by one of two [`Denoiser`]s:
//! Intel Open Image Denoise (OIDN), the default, or lumen's own
//! [`atrous`] filter, which every build has.
//!
//! OIDN is a C++ library, so it is never part of the default build: the
//! cargo feature `oidn` compiles [`oidn`], which loads the library when a
//! denoise is first asked for (see `docs/denoising.md` for where it is
//! looked for). A build without the feature, or a machine without the
//! library, gets a [`DenoiseError`] saying what to do, never a crash.
//!
//! The filter is OIDN's `RT` in HDR mode, with its auxiliary images
//! prefiltered first and then marked clean (`cleanAux`), OIDN's
//! recommended use for final frames; the prefilters run at a lower
//! [`Quality`] than the image's filter ([`PREFILTER`]). It runs on the CPU device with a
//! fixed number of threads, which makes its output the same bits for the
//! same input on the same machine.

// A foreign library's functions can only be called unsafely.
#[cfg(feature = "oidn")]
#[allow(unsafe_code)]
pub mod oidn;

pub mod atrous;

use crate::aov::Layer;
use crate::film::Film;
use crate::light::luminance;
use crate::math::{Color, Vec3};
use std::path::PathBuf;
use thiserror::Error;

/// What kept an image from being denoised.
#[derive(Clone, Debug, Error)]
pub enum DenoiseError {
    /// This build has no OIDN.
    #[error(
        "this lumen was built without Open Image Denoise; build it with \
         `OIDN_DIR=/path/to/oidn cargo build --release --features oidn` \
         (see docs/denoising.md), or choose lumen's own filter \
         (`--denoiser atrous` of render, merge and denoise)"
    )]
    NotBuilt,
    /// The OIDN library was not found, or would not load.
    #[error(
        "cannot load Open Image Denoise: {}; OIDN_DIR names the folder whose lib/ holds it \
         (see docs/denoising.md)",
        .tried.iter().map(|(p, why)| format!("{}: {why}", p.display())).collect::<Vec<_>>().join("; ")
    )]
    NotFound {
        /// Each file tried, with why it did not load.
        tried: Vec<(PathBuf, String)>,
    },
    /// The library loaded, but it is not a version lumen can use.
    #[error("{path}: {message}", path = .path.display())]
    Incompatible {
        /// The library's file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// OIDN reported an error.
    #[error("Open Image Denoise: {0}")]
    Oidn(String),
    /// The image has no pixels, or buffers of different sizes.
    #[error("{0}")]
    BadInput(String),
}

/// How much work OIDN puts into a filter: its `quality` parameter, and
/// Cycles' "Quality" setting. A lower quality runs a smaller network.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    /// OIDN's "high performance", for interactive previews.
    Fast,
    /// OIDN's "balanced quality/performance".
    Balanced,
    /// OIDN's "high quality", for final frames.
    High,
}

impl Quality {
    /// Each quality with its name, as options and messages spell it.
    pub const NAMES: [(&'static str, Quality); 3] = [
        ("high", Quality::High),
        ("balanced", Quality::Balanced),
        ("fast", Quality::Fast),
    ];

    /// Its name (see [`Quality::NAMES`]).
    pub fn name(self) -> &'static str {
        name_in(&Self::NAMES, self)
    }
}

impl std::str::FromStr for Quality {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        parse_in(&Self::NAMES, s, "quality")
    }
}

/// How the albedo and normal are prefiltered: at a quality, or not at all
/// (`none`; see [`Options::prefilter`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Prefilter(pub Option<Quality>);

impl Prefilter {
    /// Each prefilter with its name, as options and messages spell it.
    pub const NAMES: [(&'static str, Prefilter); 4] = [
        ("high", Prefilter(Some(Quality::High))),
        ("balanced", Prefilter(Some(Quality::Balanced))),
        ("fast", Prefilter(Some(Quality::Fast))),
        ("none", Prefilter(None)),
    ];

    /// Its name (see [`Prefilter::NAMES`]).
    pub fn name(self) -> &'static str {
        name_in(&Self::NAMES, self)
    }
}

impl std::str::FromStr for Prefilter {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        parse_in(&Self::NAMES, s, "prefilter")
    }
}

impl serde::Serialize for Prefilter {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> serde::Deserialize<'de> for Prefilter {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

/// The denoiser's settings a scene or a command line chooses, each absent
/// where it chooses none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Choices {
    /// The denoiser.
    pub denoiser: Option<Denoiser>,
    /// OIDN's image filter's quality.
    pub quality: Option<Quality>,
    /// OIDN's prefilters.
    pub prefilter: Option<Prefilter>,
}

impl Choices {
    /// These choices, with `base`'s where these make none.
    pub fn over(self, base: Choices) -> Choices {
        Choices {
            denoiser: self.denoiser.or(base.denoiser),
            quality: self.quality.or(base.quality),
            prefilter: self.prefilter.or(base.prefilter),
        }
    }

    /// The options chosen, the defaults ([`Options::default`]) where none
    /// is.
    pub fn options(self) -> Options {
        let default = Options::default();
        Options {
            denoiser: self.denoiser.unwrap_or(default.denoiser),
            quality: self.quality.unwrap_or(default.quality),
            prefilter: self.prefilter.map_or(default.prefilter, |p| p.0),
        }
    }
}

/// Which filter denoises the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Denoiser {
    /// Intel Open Image Denoise (builds with the `oidn` feature): a neural
    /// network trained on rendered images, the best there is on a CPU.
    #[default]
    Oidn,
    /// lumen's own edge-avoiding à-trous filter ([`atrous`]): in every
    /// build, much quicker and much less clean.
    Atrous,
}

impl Denoiser {
    /// Each denoiser with its name, as options and messages spell it.
    pub const NAMES: [(&'static str, Denoiser); 2] =
        [("oidn", Denoiser::Oidn), ("atrous", Denoiser::Atrous)];

    /// Its name (see [`Denoiser::NAMES`]).
    pub fn name(self) -> &'static str {
        name_in(&Self::NAMES, self)
    }
}

impl std::str::FromStr for Denoiser {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        parse_in(&Self::NAMES, s, "denoiser")
    }
}

/// The name of `value` in `names`.
fn name_in<T: Copy + PartialEq>(names: &[(&'static str, T)], value: T) -> &'static str {
    names
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("", |(name, _)| name)
}

/// The value named `s` in `names`, or a message naming them all.
fn parse_in<T: Copy>(names: &[(&'static str, T)], s: &str, what: &str) -> Result<T, String> {
    names
        .iter()
        .find(|(name, _)| *name == s)
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let all: Vec<&str> = names.iter().map(|(name, _)| *name).collect();
            format!("no {what} `{s}`; it is one of {}", all.join(", "))
        })
}

/// The quality of the image's filter in lumen's denoised renders.
pub const IMAGE_QUALITY: Quality = Quality::High;

/// How the albedo and normal are prefiltered in lumen's denoised renders
/// (see [`Inputs::prefilter`]). Balanced: the guides are far less noisy than the
/// image, and on the benchmark scenes it gives denoised images within
/// 2.5 % of high prefilters' FLIP (the same to the fourth decimal on three
/// of four) in about two fifths less time (docs/denoising.md, "Quality").
pub const PREFILTER: Option<Quality> = Some(Quality::Balanced);

/// An image to denoise: its linear colours and, when known, its albedo and
/// shading normals, each row-major, top row first; and how hard the
/// filters work.
#[derive(Clone, Copy, Debug)]
pub struct Inputs<'a> {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The noisy image (HDR, linear).
    pub color: &'a [Color],
    /// The albedo buffer, in [0, 1].
    pub albedo: Option<&'a [Vec3]>,
    /// The normal buffer (unit or zero vectors); only with an albedo.
    pub normal: Option<&'a [Vec3]>,
    /// The variance of each pixel's value (the `variance` feature buffer):
    /// with it the filter's output is blended back towards the noisy
    /// image where the two differ by more than the noise explains (see
    /// [`blend`]).
    pub variance: Option<&'a [Color]>,
    /// How hard the filters work.
    pub options: Options,
}

/// Which denoiser runs, and how hard it works.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// The filter ([`Denoiser::Oidn`] by default); the qualities below
    /// are OIDN's, and the built-in filter has none.
    pub denoiser: Denoiser,
    /// The quality of the image's filter ([`IMAGE_QUALITY`] by default).
    pub quality: Quality,
    /// The quality of the albedo's and normal's prefilters ([`PREFILTER`]
    /// by default). `None`: they go to the image's filter as they are, and
    /// it is not told they are clean (OIDN without `cleanAux`, Cycles'
    /// "Fast" prefilter): one filter run in place of three.
    pub prefilter: Option<Quality>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            denoiser: Denoiser::Oidn,
            quality: IMAGE_QUALITY,
            prefilter: PREFILTER,
        }
    }
}

impl Inputs<'_> {
    fn check(&self) -> Result<(), DenoiseError> {
        let n = self.width * self.height;
        if n == 0 {
            return Err(DenoiseError::BadInput("an image without pixels".into()));
        }
        let sizes = [
            Some(self.color.len()),
            self.albedo.map(<[Vec3]>::len),
            self.normal.map(<[Vec3]>::len),
            self.variance.map(<[Color]>::len),
        ];
        if sizes.iter().flatten().any(|&len| len != n) {
            return Err(DenoiseError::BadInput(format!(
                "buffers of a {}x{} image must hold {n} pixels each",
                self.width, self.height
            )));
        }
        if self.normal.is_some() && self.albedo.is_none() {
            return Err(DenoiseError::BadInput(
                "a normal buffer needs an albedo buffer beside it".into(),
            ));
        }
        Ok(())
    }
}

/// Whether this build has `denoiser` and its library loads: asked before
/// a render that ends in a denoise starts, so that a missing library is
/// found out at once and not after hours of rendering. Returns the
/// denoiser's description (OIDN's path and version).
pub fn check_available(denoiser: Denoiser) -> Result<String, DenoiseError> {
    if denoiser == Denoiser::Atrous {
        return Ok("lumen's à-trous filter".into());
    }
    #[cfg(feature = "oidn")]
    {
        oidn::Library::get().map(|lib| lib.describe())
    }
    #[cfg(not(feature = "oidn"))]
    {
        Err(DenoiseError::NotBuilt)
    }
}

/// How many times the image's mean luminance a channel must pass to be a
/// highlight, which [`denoise`] keeps out of the filter.
pub const HIGHLIGHT_FACTOR: f64 = 10.0;

/// The denoised image of `inputs`, OIDN with `threads` threads (the
/// built-in filter runs on the current rayon pool). Its values are finite
/// and non-negative.
///
/// Highlights are kept out of the filter: what a channel holds beyond
/// [`HIGHLIGHT_FACTOR`] times the image's mean luminance is taken off
/// before the filter and added back after it, as rendered. OIDN treats a
/// small, very bright highlight (a glint of the sun) as noise and spreads
/// or removes it: on `examples/materials.toml` the image lost 1.3 % of its
/// red even at 256 samples, nearly all of it in the brightest 0.1 % of the
/// pixels (docs/denoising.md, "Means").
pub fn denoise(inputs: &Inputs, threads: usize) -> Result<Vec<Color>, DenoiseError> {
    inputs.check()?;
    let (base, highlights) = split_highlights(inputs.color);
    let base = Inputs {
        color: &base,
        ..*inputs
    };
    let mut out = match inputs.options.denoiser {
        Denoiser::Oidn => oidn_filter(&base, threads)?,
        Denoiser::Atrous => atrous::filter(&base),
    };
    // The HDR filter can leave tiny negative values and, given values it
    // cannot represent, NaN, and a highlight is NaN where the input was:
    // neither belongs in an image.
    for (c, h) in out.iter_mut().zip(&highlights) {
        *c = clean(clean(*c) + *h);
    }
    if let Some(variance) = inputs.variance {
        blend(&mut out, inputs.color, variance, inputs.width);
    }
    Ok(out)
}

/// `inputs` through OIDN's filter, if this build has it.
fn oidn_filter(inputs: &Inputs, threads: usize) -> Result<Vec<Color>, DenoiseError> {
    #[cfg(feature = "oidn")]
    {
        oidn::Library::get()?.denoise(inputs, threads)
    }
    #[cfg(not(feature = "oidn"))]
    {
        let _ = (inputs, threads);
        Err(DenoiseError::NotBuilt)
    }
}

/// Half the side of the square of pixels over which [`blend`] averages
/// the noise and the change (5 × 5).
pub const BLEND_RADIUS: usize = 2;

/// Moves each `denoised` pixel back towards the `noisy` one where the
/// filter changed the image by more than its noise explains.
///
/// The noisy pixel n is unbiased with variance σ² (`variance`, averaged
/// over the channels); the denoised d has little variance but a bias b.
/// Of the blends n + α(d − n), the one of least expected squared error has
/// α = σ² / (σ² + b²), and E[(d − n)²] ≈ σ² + b² estimates the
/// denominator. Both are averaged over the [`BLEND_RADIUS`] square around
/// the pixel, as a single pixel's are too noisy to weigh by:
/// α = ⟨σ²⟩ / max(⟨(d − n)²⟩, ⟨σ²⟩). Where the filter only took noise away,
/// α is near 1 and the denoised image stays; where it smoothed detail
/// that the samples had already resolved (fine texture, normal-mapped
/// bumps, reflections at many samples per pixel), the difference dwarfs
/// the noise and the pixel goes back towards the samples'.
///
/// A variance buffer that is 0 everywhere (one sample a pixel, or a
/// constant image) says nothing about the noise; the image is left as
/// denoised.
pub fn blend(denoised: &mut [Color], noisy: &[Color], variance: &[Color], width: usize) {
    // The channels' mean; what is not finite (in a file's variance, or
    // where the image is not a number) says nothing, and counts as 0.
    let mean = |c: Color| {
        let m = (f64::from(c.x) + f64::from(c.y) + f64::from(c.z)) / 3.0;
        if m.is_finite() {
            m
        } else {
            0.0
        }
    };
    let noise: Vec<f64> = variance.iter().map(|&v| mean(v).max(0.0)).collect();
    if !noise.iter().any(|&v| v > 0.0) {
        return;
    }
    let change: Vec<f64> = denoised
        .iter()
        .zip(noisy)
        .map(|(&d, &n)| mean((d - n) * (d - n)))
        .collect();
    let noise = box_mean(&noise, width, BLEND_RADIUS);
    let change = box_mean(&change, width, BLEND_RADIUS);
    for (i, (d, &n)) in denoised.iter_mut().zip(noisy).enumerate() {
        // Where every sample agreed (no noise), any change is the
        // filter's own and α is 0.
        let alpha = if change[i] > noise[i] {
            (noise[i] / change[i]).clamp(0.0, 1.0) as f32
        } else {
            1.0
        };
        *d = clean(n + (*d - n) * alpha);
    }
}

/// The mean of `values` (an image `width` wide) over the square of side
/// 2 `radius` + 1 around each pixel, the edge pixels repeated beyond the
/// image: along the rows, then along the columns, each window summed
/// afresh (a running sum would carry a firefly's rounding, or a NaN, on
/// down the row).
fn box_mean(values: &[f64], width: usize, radius: usize) -> Vec<f64> {
    let height = values.len() / width;
    let r = radius as isize;
    // The index `d` away from `i`, within 0..len.
    let near =
        |i: usize, d: isize, len: usize| (i as isize + d).clamp(0, len as isize - 1) as usize;
    let rows: Vec<f64> = (0..values.len())
        .map(|i| {
            let (x, y) = (i % width, i / width);
            (-r..=r)
                .map(|d| values[y * width + near(x, d, width)])
                .sum()
        })
        .collect();
    let k = (2 * radius + 1) as f64;
    (0..values.len())
        .map(|i| {
            let (x, y) = (i % width, i / width);
            (-r..=r)
                .map(|d| rows[near(y, d, height) * width + x])
                .sum::<f64>()
                / (k * k)
        })
        .collect()
}

/// `color` split into what the filter sees, each channel at most
/// [`HIGHLIGHT_FACTOR`] times the mean luminance, and the highlights above
/// that (0 elsewhere).
pub fn split_highlights(color: &[Color]) -> (Vec<Color>, Vec<Color>) {
    // In a fixed order, so that the same image gives the same bits.
    let luminances = color.iter().map(|&c| f64::from(luminance(c)));
    let sum: f64 = luminances.filter(|l| l.is_finite()).sum();
    let limit = (HIGHLIGHT_FACTOR * sum / color.len().max(1) as f64).max(0.0) as f32;
    let base: Vec<Color> = color.iter().map(|c| c.min(Color::splat(limit))).collect();
    let highlights = color.iter().zip(&base).map(|(c, b)| *c - *b).collect();
    (base, highlights)
}

/// `c` with every channel that is not finite and positive made 0.
fn clean(c: Color) -> Color {
    let v = |v: f32| if v > 0.0 && v.is_finite() { v } else { 0.0 };
    Color::new(v(c.x), v(c.y), v(c.z))
}

/// The film's image denoised with `options`, with its albedo and normal
/// layers as the auxiliary images when it keeps them.
pub fn denoise_film(
    film: &Film,
    threads: usize,
    options: Options,
) -> Result<Vec<Color>, DenoiseError> {
    let layers = film.layers();
    let layer = |l: Layer| -> Option<Vec<Vec3>> {
        layers
            .has(l)
            .then(|| (0..film.len()).map(|i| film.feature(l, i)).collect())
    };
    let color = film.linear();
    let albedo = layer(Layer::Albedo);
    let normal = albedo.as_ref().and(layer(Layer::Normal));
    let variance = layers.has(Layer::Moment).then(|| {
        (0..film.len())
            .map(|i| film.variance(i))
            .collect::<Vec<_>>()
    });
    denoise(
        &Inputs {
            width: film.width() as usize,
            height: film.height() as usize,
            color: &color,
            albedo: albedo.as_deref(),
            normal: normal.as_deref(),
            variance: variance.as_deref(),
            options,
        },
        threads,
    )
}

/// What a file to denoise lacks or holds wrong.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The file is missing, not a regular file, or too large.
    #[error("{path}: {source}", path = .path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// Why it was not read.
        source: crate::input::ReadError,
    },
    /// The file cannot be read as an OpenEXR image.
    #[error("{path}: cannot read it as an OpenEXR image: {message}", path = .path.display())]
    Exr {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The image would not fit the memory there is.
    #[error("{path}: {source}", path = .path.display())]
    Memory {
        /// The file.
        path: PathBuf,
        /// The refusal.
        source: crate::memory::MemoryError,
    },
    /// Layers the denoiser needs are missing.
    #[error(
        "{path}: has no {missing} layer; its channels are {found}",
        path = .path.display(),
        found = .found.join(", ")
    )]
    MissingLayers {
        /// The file.
        path: PathBuf,
        /// The layers missing, as channel names (`albedo.R, albedo.G, …`).
        missing: String,
        /// Every channel the file has.
        found: Vec<String>,
    },
    /// Its layers are not all of one size, or subsampled.
    #[error("{path}: {message}", path = .path.display())]
    Layout {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// An OpenEXR image's channels, by their full names (`R`, `albedo.R`:
/// the layer's name, a dot, the channel's), each as 32-bit floats,
/// row-major, top row first.
#[derive(Clone, Debug)]
pub struct ExrChannels {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The channels, in the file's order.
    pub channels: Vec<(String, Vec<f32>)>,
}

/// An image with the buffers that guide its denoising, each row-major.
#[derive(Clone, Debug)]
pub struct Guided {
    /// The noisy image.
    pub color: Vec<Color>,
    /// Its albedo.
    pub albedo: Vec<Vec3>,
    /// Its shading normals.
    pub normal: Vec<Vec3>,
    /// The variance of its pixels, if the file has a `variance` layer.
    pub variance: Option<Vec<Color>>,
}

/// The three channels of a layer the denoiser reads, as lumen writes them
/// and as other renderers' names allow: the image's `R`, `G`, `B`; the
/// albedo's `albedo.R`…; the normal's `normal.X`… or `normal.R`….
const BEAUTY: [&[&str]; 1] = [&["R", "G", "B"]];
const ALBEDO: [&[&str]; 1] = [&["albedo.R", "albedo.G", "albedo.B"]];
const VARIANCE: [&[&str]; 1] = [&["variance.R", "variance.G", "variance.B"]];
const NORMAL: [&[&str]; 2] = [
    &["normal.X", "normal.Y", "normal.Z"],
    &["normal.R", "normal.G", "normal.B"],
];

impl ExrChannels {
    /// Reads every channel of every layer of `path` (its full resolution),
    /// after checking that they fit in memory. All layers must be of one
    /// size. The file is read as every input is ([`crate::input::read`]):
    /// a regular file of at most [`crate::input::MAX_IMAGE_BYTES`].
    pub fn read(path: &std::path::Path) -> Result<ExrChannels, ReadError> {
        use exr::prelude::ReadChannels as _;
        use exr::prelude::ReadLayers as _;
        let bytes = crate::input::read(path, crate::input::MAX_IMAGE_BYTES).map_err(|source| {
            ReadError::Input {
                path: path.to_path_buf(),
                source,
            }
        })?;
        let exr_error = |e: exr::error::Error| ReadError::Exr {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let layout = |message: String| ReadError::Layout {
            path: path.to_path_buf(),
            message,
        };
        let cursor = || std::io::Cursor::new(&bytes[..]);
        let meta = exr::meta::MetaData::read_from_buffered(cursor(), false).map_err(exr_error)?;
        let bytes: u64 = meta
            .headers
            .iter()
            .map(|h| h.layer_size.area() as u64 * h.channels.list.len() as u64 * 4)
            .sum();
        crate::memory::check(bytes, "the image's channels").map_err(|source| {
            ReadError::Memory {
                path: path.to_path_buf(),
                source,
            }
        })?;
        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_buffered(cursor())
            .map_err(exr_error)?;
        let mut size = None;
        let mut channels = Vec::new();
        for layer in &image.layer_data {
            let (w, h) = (layer.size.x(), layer.size.y());
            if *size.get_or_insert((w, h)) != (w, h) {
                return Err(layout(format!(
                    "its layers are of different sizes ({}x{} and {w}x{h})",
                    size.unwrap_or_default().0,
                    size.unwrap_or_default().1
                )));
            }
            let prefix = layer
                .attributes
                .layer_name
                .as_ref()
                .map_or(String::new(), |n| format!("{n}."));
            for channel in &layer.channel_data.list {
                let name = format!("{prefix}{}", channel.name);
                let values: Vec<f32> = match &channel.sample_data {
                    exr::prelude::FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
                    exr::prelude::FlatSamples::F32(v) => v.clone(),
                    exr::prelude::FlatSamples::U32(v) => v.iter().map(|&x| x as f32).collect(),
                };
                if values.len() != w * h {
                    return Err(layout(format!(
                        "channel {name} is subsampled, which the denoiser cannot read"
                    )));
                }
                channels.push((name, values));
            }
        }
        let (width, height) = size.unwrap_or_default();
        Ok(ExrChannels {
            width,
            height,
            channels,
        })
    }

    /// The names of its channels.
    pub fn names(&self) -> Vec<String> {
        self.channels.iter().map(|(n, _)| n.clone()).collect()
    }

    /// The layer named by one of `spellings` (three channel names each,
    /// matched without regard to case), as vectors.
    fn layer(&self, spellings: &[&[&str]]) -> Option<Vec<Vec3>> {
        let find = |name: &str| {
            self.channels
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(name))
                .map(|(_, v)| v)
        };
        spellings.iter().find_map(|names| {
            let [x, y, z] = [find(names[0])?, find(names[1])?, find(names[2])?];
            Some((0..x.len()).map(|i| Vec3::new(x[i], y[i], z[i])).collect())
        })
    }

    /// The image and its albedo and normal, as the denoiser takes them;
    /// refused, naming the channels found, when any is missing.
    pub fn denoiser_layers(&self, path: &std::path::Path) -> Result<Guided, ReadError> {
        let missing = |what: &str| ReadError::MissingLayers {
            path: path.to_path_buf(),
            missing: what.to_string(),
            found: self.names(),
        };
        let beauty = self
            .layer(&BEAUTY)
            .ok_or_else(|| missing("image (R, G, B)"))?;
        let albedo = self
            .layer(&ALBEDO)
            .ok_or_else(|| missing("albedo (albedo.R, albedo.G, albedo.B)"))?;
        let normal = self
            .layer(&NORMAL)
            .ok_or_else(|| missing("normal (normal.X, normal.Y, normal.Z)"))?;
        Ok(Guided {
            color: beauty,
            albedo,
            normal,
            variance: self.layer(&VARIANCE),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qualities_are_named_as_options_spell_them() {
        for (name, quality) in Quality::NAMES {
            assert_eq!(name.parse::<Quality>(), Ok(quality));
            assert_eq!(quality.name(), name);
        }
        let e = "best".parse::<Quality>().unwrap_err();
        assert!(
            e.contains("`best`") && e.contains("high, balanced, fast"),
            "{e}"
        );
    }

    #[test]
    fn box_mean_is_the_mean_over_the_square_with_edges_repeated() {
        let (w, h) = (7, 5);
        let values: Vec<f64> = (0..w * h).map(|i| ((i * 37) % 11) as f64).collect();
        let out = box_mean(&values, w, 2);
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut sum = 0.0;
                for dy in -2..=2 {
                    for dx in -2..=2 {
                        let (xx, yy) = (
                            (x + dx).clamp(0, w as isize - 1),
                            (y + dy).clamp(0, h as isize - 1),
                        );
                        sum += values[yy as usize * w + xx as usize];
                    }
                }
                let got = out[y as usize * w + x as usize];
                assert!((got - sum / 25.0).abs() < 1e-12, "({x}, {y}): {got}");
            }
        }
    }

    #[test]
    fn the_blend_keeps_what_took_noise_away_and_undoes_what_took_detail() {
        let (w, h) = (32, 32);
        let mut rng = crate::rng::Rng::new(3);
        let sigma = 0.05f32;
        // A flat truth: the "filter" returned it exactly, the noisy image
        // is it plus noise of variance σ². The change is all noise: α ≈ 1.
        let truth = vec![Color::splat(0.5); w * h];
        let noisy: Vec<Color> = truth
            .iter()
            .map(|c| *c + Color::splat((rng.next_f32() - 0.5) * sigma * 12f32.sqrt()))
            .collect();
        let variance = vec![Color::splat(sigma * sigma); w * h];
        let mut out = truth.clone();
        blend(&mut out, &noisy, &variance, w);
        let err = |a: &[Color]| {
            a.iter()
                .zip(&truth)
                .map(|(a, b)| f64::from((*a - *b).length_squared()))
                .sum::<f64>()
        };
        assert!(
            err(&out) < err(&noisy) / 5.0,
            "{} against {}",
            err(&out),
            err(&noisy)
        );
        // A "filter" that flattened a resolved pattern (±0.3, six σ): the
        // change dwarfs the noise, and the blend goes back to the samples.
        let pattern: Vec<Color> = (0..w * h)
            .map(|i| Color::splat(if i % 2 == 0 { 0.2 } else { 0.8 }))
            .collect();
        let mut out = vec![Color::splat(0.5); w * h];
        blend(&mut out, &pattern, &variance, w);
        for (o, p) in out.iter().zip(&pattern) {
            assert!((o.x - p.x).abs() < 0.02, "{o} against {p}");
        }
        // A pixel that is not a number, in the image or its variance,
        // leaves the output finite, and the blend goes on past it as
        // before: far from it, the same pixels as without it.
        let mut broken = pattern.clone();
        broken[w + 1] = Color::splat(f32::NAN);
        let mut broken_variance = variance.clone();
        broken_variance[2 * w + 2] = Color::splat(f32::INFINITY);
        let mut out = vec![Color::splat(0.5); w * h];
        blend(&mut out, &broken, &broken_variance, w);
        assert!(out.iter().all(|c| c.is_finite() && c.min_element() >= 0.0));
        let mut reference = vec![Color::splat(0.5); w * h];
        blend(&mut reference, &pattern, &variance, w);
        assert_eq!(out[10 * w..], reference[10 * w..]);
        // No variance (a render of one sample a pixel): left as filtered.
        let mut out = vec![Color::splat(0.5); w * h];
        blend(&mut out, &pattern, &vec![Color::ZERO; w * h], w);
        assert!(out.iter().all(|c| *c == Color::splat(0.5)));
    }

    #[test]
    fn highlights_are_what_passes_ten_times_the_mean_luminance() {
        // 99 grey pixels of luminance 0.5 and a glint: mean luminance 1.495,
        // so the limit is 14.95.
        let mut color = vec![Color::splat(0.5); 99];
        color.push(Color::new(100.0, 100.0, 100.0));
        color[3] = Color::new(20.0, 0.0, 0.0);
        let (base, highlights) = split_highlights(&color);
        let mean = color.iter().map(|&c| f64::from(luminance(c))).sum::<f64>() / 100.0;
        let limit = (HIGHLIGHT_FACTOR * mean) as f32;
        for ((c, b), h) in color.iter().zip(&base).zip(&highlights) {
            assert!(b.max_element() <= limit, "{b}");
            assert_eq!(*b + *h, *c);
            if c.max_element() <= limit {
                assert_eq!(*h, Color::ZERO);
            }
        }
        assert_eq!(base[99], Color::splat(limit));
        assert_eq!(highlights[3], Color::new(20.0 - limit, 0.0, 0.0));
        // A black image has none.
        let (base, highlights) = split_highlights(&[Color::ZERO; 4]);
        assert!(base.iter().chain(&highlights).all(|&c| c == Color::ZERO));
    }
}
