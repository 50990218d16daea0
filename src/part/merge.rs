//! Merging part files into one film, streaming: a reader thread reads the
//! next part (and checks its checksum) while the rows of the one before
//! are added straight from its bytes into the film, in parallel. Memory is
//! the film of the image and at most three parts' bytes, whatever the
//! number of parts.

use crate::checkpoint::{
    describe_differences, same_render, Checkpoint, CheckpointError, PixelError, Unpacked,
    HEADER_LEN,
};
use crate::film::{Film, Sum};
use crate::render::RenderStats;
use crate::scene::desc::RenderDesc;
use crate::tile::Tile;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use thiserror::Error;

/// Parts that cannot be merged.
#[derive(Debug, Error)]
pub enum MergeError {
    /// No part was given.
    #[error("no part files to merge")]
    NoParts,
    /// A part file cannot be read, is damaged, or is not a part.
    #[error(transparent)]
    Read(#[from] CheckpointError),
    /// Two parts belong to different renders.
    #[error("{} and {} are parts of different renders ({differences}); merge parts of one render only", .first.display(), .other.display())]
    DifferentRenders {
        /// The first part read.
        first: PathBuf,
        /// The part that differs from it.
        other: PathBuf,
        /// What differs, in words.
        differences: String,
    },
    /// Two parts hold some of the same samples.
    #[error("{} and {} both hold samples {}..{} of {}; give each part once", .first.display(), .other.display(), .common.start, .common.end, pixels_text(.tile))]
    Overlap {
        /// One part.
        first: PathBuf,
        /// The other.
        other: PathBuf,
        /// The samples they share.
        common: Range<u32>,
        /// The pixels they share them in (`None`: every pixel).
        tile: Option<Tile>,
    },
    /// Two parts hold tiles that overlap without being the same.
    #[error("{} and {} hold overlapping tiles ({} and {}, sharing {}); merge the parts of one split of the image", .first.display(), .other.display(), .tiles.0, .tiles.1, .tiles.2)]
    TilesOverlap {
        /// One part.
        first: PathBuf,
        /// The other.
        other: PathBuf,
        /// Their tiles, and the pixels they share.
        tiles: (Tile, Tile, Tile),
    },
    /// A part has not finished its share.
    #[error("{}: part unfinished: it holds samples {}..{} of its share {}..{} (let it finish, or merge with --partial for a preview)", .path.display(), .share.start, .done, .share.start, .share.end)]
    Unfinished {
        /// The part.
        path: PathBuf,
        /// Its share.
        share: Range<u32>,
        /// End of the samples it holds.
        done: u32,
    },
    /// No part holds some samples.
    #[error("no part holds samples {}{} of the {spp} spp render: {} (merge with --partial for a preview)", ranges_text(.missing), match .tile { Some(t) => format!(" of the pixels of tile {t}"), None => String::new() }, if .missing.len() == 1 { "a part is missing" } else { "parts are missing" })]
    Missing {
        /// The samples per pixel of the render.
        spp: u32,
        /// Sample ranges no part holds.
        missing: Vec<Range<u32>>,
        /// The pixels that lack them (`None`: every pixel).
        tile: Option<Tile>,
    },
    /// No part holds some pixels.
    #[error("no part holds pixel ({}, {}) of the {}x{} image{}: a tile is missing (merge with --partial for a preview)", .example.0, .example.1, .image.0, .image.1, others_text(.others))]
    MissingPixels {
        /// The image's size.
        image: (u32, u32),
        /// The first pixel no part holds, in reading order.
        example: (u32, u32),
        /// How many more no part holds.
        others: u64,
    },
    /// A part's description has no render settings that can be read.
    #[error("{}: its scene description has no render settings that can be read", .0.display())]
    NoRenderSettings(PathBuf),
    /// The image has more pixels than lumen renders.
    #[error("{}: its image of {}x{} pixels has more than the {} pixels lumen renders", .path.display(), .image.0, .image.1, crate::scene::MAX_PIXELS)]
    TooManyPixels {
        /// The first part.
        path: PathBuf,
        /// The image's size.
        image: (u32, u32),
    },
    /// The image is too large for this machine's memory.
    #[error("{}: its image of {}x{} pixels is too large to merge in this machine's memory", .path.display(), .image.0, .image.1)]
    TooLarge {
        /// The first part.
        path: PathBuf,
        /// The image's size.
        image: (u32, u32),
    },
}

/// `, nor N other pixels`, or nothing when there are none.
fn others_text(others: &u64) -> String {
    match others {
        0 => String::new(),
        n => format!(", nor {n} other pixels"),
    }
}

/// Which pixels, in words: `every pixel` or `the pixels of tile X0,Y0,X1,Y1`.
fn pixels_text(tile: &Option<Tile>) -> String {
    match tile {
        None => "every pixel".into(),
        Some(t) => format!("the pixels of tile {t}"),
    }
}

/// Sample ranges in words: `a..b, c..d`, at most eight of them.
pub fn ranges_text(ranges: &[Range<u32>]) -> String {
    let shown: Vec<String> = ranges
        .iter()
        .take(8)
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    match ranges.len() {
        n if n > 8 => format!("{} and {} more ranges", shown.join(", "), n - 8),
        _ => shown.join(", "),
    }
}

/// Parts merged.
#[derive(Debug)]
pub struct Merged {
    /// The film of all the parts' samples, the size of the whole image.
    pub film: Film,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The sample ranges every pixel of the film holds, in order, adjacent
    /// ones joined: `[0..spp]` for a complete merge; empty when pixels
    /// hold different samples (a partial merge of tiles).
    pub held: Vec<Range<u32>>,
    /// Samples the film holds, over all its pixels.
    pub samples_held: u64,
    /// The distinct tiles of the parts (one, the whole image, for parts
    /// split by samples).
    pub tiles: Vec<Tile>,
    /// The parts' counts, added.
    pub stats: RenderStats,
    /// The display gamma of the render (the first part's).
    pub gamma: f32,
    /// The feature buffers the render writes (see [`crate::aov`]).
    pub aovs: Vec<crate::aov::Aov>,
    /// Whether the render's description asks for its image denoised.
    pub denoise: bool,
    /// The denoiser's settings its description chooses.
    pub denoise_choices: crate::denoise::Choices,
    /// [`crate::checkpoint::RENDERER_ID`] of the lumen that rendered the
    /// parts.
    pub renderer_id: String,
    /// The render's identity (canonical scene description).
    pub description: String,
}

impl Merged {
    /// Whether the film holds every sample of every pixel.
    pub fn is_complete(&self) -> bool {
        let pixels = u64::from(self.film.width()) * u64::from(self.film.height());
        self.samples_held == pixels * u64::from(self.spp)
    }

    /// Samples per pixel every pixel holds (see [`Merged::held`]).
    pub fn held_spp(&self) -> u32 {
        self.held.iter().map(|r| r.end - r.start).sum()
    }

    /// Whether the parts were split by samples only (one tile, the whole
    /// image).
    pub fn is_whole_image(&self) -> bool {
        self.tiles.len() == 1 && self.tiles[0].is_whole(self.film.width(), self.film.height())
    }
}

/// Merges the part files `paths`, given in any order, streaming: memory is
/// the image's film and a few parts' bytes, whatever the number of parts.
/// Unless `partial`, the parts must be finished and together hold every
/// sample of every pixel; with `partial`, whatever they hold so far is
/// merged (a preview). Parts of different renders, parts holding the same
/// samples of the same pixels, and tiles overlapping other tiles are
/// refused either way.
pub fn merge(paths: &[PathBuf], partial: bool) -> Result<Merged, MergeError> {
    std::thread::scope(|scope| {
        // At most one part waits read while one is merged and one is read.
        let (parts, read) = mpsc::sync_channel(1);
        let (spent, spare) = mpsc::channel::<Vec<u8>>();
        scope.spawn(move || {
            for path in paths {
                let mut bytes = spare.try_recv().unwrap_or_default();
                let checked = Checkpoint::read_bytes(path, &mut bytes)
                    .and_then(|()| Checkpoint::verify(&bytes, path).map(|_| ()));
                if parts.send((path, checked.map(|()| bytes))).is_err() {
                    return;
                }
            }
        });
        let mut merger = Merger {
            partial,
            merged: None,
            seen: Vec::new(),
        };
        for (path, bytes) in read {
            let bytes = bytes?;
            merger.add(path, &bytes)?;
            // The reader may have gone: then nothing needs the buffer.
            let _ = spent.send(bytes);
        }
        merger.finish()
    })
}

/// A merge in progress.
struct Merger {
    partial: bool,
    merged: Option<Merged>,
    /// (tile, samples held, path) of every part read so far, the first
    /// first.
    seen: Vec<(Tile, Range<u32>, PathBuf)>,
}

impl Merger {
    /// Checks the part file `bytes` (read from `path`, its checksum
    /// checked) and adds its samples to the film.
    fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<(), MergeError> {
        let malformed = |message: String| CheckpointError::Malformed {
            path: path.to_path_buf(),
            message,
        };
        let unpacked =
            Checkpoint::unpack(&bytes[HEADER_LEN..]).map_err(|m| malformed(m.to_string()))?;
        let part = &unpacked.head;
        if unpacked.odd.is_some() {
            return Err(
                malformed("it is the checkpoint of an adaptive render, not a part".into()).into(),
            );
        }
        let done = (part.check_fields(part.tile.width(), part.tile.height())).map_err(malformed)?;
        if part.spp_done < part.share.end && !self.partial {
            return Err(MergeError::Unfinished {
                path: path.to_path_buf(),
                share: part.share.clone(),
                done: part.spp_done,
            });
        }
        let held = part.share.start..part.spp_done;
        self.check_fits(path, part, &held)?;
        if self.merged.is_none() {
            self.merged = Some(start(path, part)?);
        }
        let m = self.merged.as_mut().expect("made above");
        if part.share.end > m.spp {
            return Err(malformed(format!(
                "it holds samples {}..{} of a {} spp render",
                part.share.start, part.share.end, m.spp
            ))
            .into());
        }
        let layers = unpacked.layers.iter().map(|(l, _)| *l);
        if !layers.eq(crate::aov::Layer::ALL
            .into_iter()
            .filter(|&l| m.film.layers().has(l)))
        {
            return Err(malformed(
                "its feature layers (AOVs) are not those its scene description asks for".into(),
            )
            .into());
        }
        self.seen.push((part.tile, held, path.to_path_buf()));
        let counted = add_pixels(&mut m.film, &unpacked, done).map_err(malformed)?;
        part.check_counted(counted, done).map_err(malformed)?;
        m.stats.add(part.stats);
        Ok(())
    }

    /// Checks that `part` (read from `path`), holding samples `held`,
    /// belongs with the parts read so far and holds none of their samples.
    fn check_fits(
        &self,
        path: &Path,
        part: &Checkpoint,
        held: &Range<u32>,
    ) -> Result<(), MergeError> {
        if let (Some(m), Some((_, _, first))) = (&self.merged, self.seen.first()) {
            let differences = if part.renderer_id != m.renderer_id {
                format!(
                    "written by lumen {} and {}",
                    m.renderer_id, part.renderer_id
                )
            } else if !same_render(&part.description, &m.description) {
                describe_differences(
                    &m.description,
                    &part.description,
                    &first.display().to_string(),
                    &format!("in {}", path.display()),
                )
            } else if part.image != (m.film.width(), m.film.height()) {
                format!(
                    "an image of {}x{} and of {}x{}",
                    m.film.width(),
                    m.film.height(),
                    part.image.0,
                    part.image.1
                )
            } else {
                String::new()
            };
            if !differences.is_empty() {
                return Err(MergeError::DifferentRenders {
                    first: first.clone(),
                    other: path.to_path_buf(),
                    differences,
                });
            }
        }
        for (tile, other, other_path) in &self.seen {
            if *tile != part.tile {
                if let Some(common) = tile.overlap(&part.tile) {
                    return Err(MergeError::TilesOverlap {
                        first: other_path.clone(),
                        other: path.to_path_buf(),
                        tiles: (*tile, part.tile, common),
                    });
                }
                continue;
            }
            // A part with an empty share (more parts than samples) holds
            // nothing, so it cannot hold anything twice.
            let common = held.start.max(other.start)..held.end.min(other.end);
            if !common.is_empty() {
                return Err(MergeError::Overlap {
                    first: other_path.clone(),
                    other: path.to_path_buf(),
                    common,
                    tile: unless_whole(*tile, part.image),
                });
            }
        }
        Ok(())
    }

    /// Checks that every sample of every pixel is held, unless partial,
    /// and says what is.
    fn finish(self) -> Result<Merged, MergeError> {
        let mut m = self.merged.ok_or(MergeError::NoParts)?;
        let (w, h) = (m.film.width(), m.film.height());
        for (tile, _, _) in &self.seen {
            if !m.tiles.contains(tile) {
                m.tiles.push(*tile);
            }
        }
        m.tiles.sort_by_key(|t| (t.y0, t.x0));
        let mut common: Option<Vec<Range<u32>>> = None;
        for &tile in &m.tiles {
            let mut ranges: Vec<Range<u32>> = (self.seen.iter())
                .filter(|(t, _, _)| *t == tile)
                .map(|(_, r, _)| r.clone())
                .collect();
            ranges.sort_by_key(|r| r.start);
            let (held, missing) = joined(&ranges, m.spp);
            if !missing.is_empty() && !self.partial {
                return Err(MergeError::Missing {
                    spp: m.spp,
                    missing,
                    tile: unless_whole(tile, (w, h)),
                });
            }
            let spp: u64 = held.iter().map(|r| u64::from(r.end - r.start)).sum();
            m.samples_held += tile.area() * spp;
            common = match common {
                None => Some(held),
                Some(c) if c == held => Some(c),
                Some(_) => Some(Vec::new()),
            };
        }
        let covered: u64 = m.tiles.iter().map(Tile::area).sum();
        let pixels = u64::from(w) * u64::from(h);
        if covered < pixels {
            if !self.partial {
                return Err(MergeError::MissingPixels {
                    image: (w, h),
                    example: first_uncovered(&m.tiles, w, h),
                    others: pixels - covered - 1,
                });
            }
            common = Some(Vec::new());
        }
        m.held = common.unwrap_or_default();
        Ok(m)
    }
}

/// The merge of the first part, `part` (read from `path`): an empty film of
/// its image.
fn start(path: &Path, part: &Checkpoint) -> Result<Merged, MergeError> {
    let render = render_settings(&part.description)
        .ok_or_else(|| MergeError::NoRenderSettings(path.to_path_buf()))?;
    let spp = render.samples_per_pixel;
    let (w, h) = part.image;
    if render.size() != Some(part.image) {
        return Err(CheckpointError::Malformed {
            path: path.to_path_buf(),
            message: format!(
                "its image is {w}x{h}, which is not the size its scene description gives"
            ),
        }
        .into());
    }
    // A part file can declare any size: the render's own limit applies, and
    // the film is counted against free memory before it is taken.
    if u64::from(w) * u64::from(h) > crate::scene::MAX_PIXELS {
        return Err(MergeError::TooManyPixels {
            path: path.to_path_buf(),
            image: part.image,
        });
    }
    let too_large = || MergeError::TooLarge {
        path: path.to_path_buf(),
        image: part.image,
    };
    let aovs = render.written_aovs();
    let layers = crate::aov::Layers::for_aovs(&aovs);
    // With the albedo or normal, a part's layer is read into a block of
    // 128-bit sums before it is packed.
    let scratch = match layers.meets(Film::PACKED) {
        true => u64::from(w) * u64::from(h) * std::mem::size_of::<Sum>() as u64,
        false => 0,
    };
    let bytes = Film::bytes(w, h, false) + Film::layer_bytes(w, h, layers) + scratch;
    crate::memory::check(bytes, "the film").map_err(|_| too_large())?;
    let film = Film::try_new(w, h)
        .and_then(|f| f.try_with_layers(layers))
        .ok_or_else(too_large)?;
    Ok(Merged {
        film,
        spp,
        held: Vec::new(),
        samples_held: 0,
        tiles: Vec::new(),
        stats: RenderStats::default(),
        gamma: part.gamma,
        aovs,
        denoise: render.denoise,
        denoise_choices: render.denoise_choices(),
        renderer_id: part.renderer_id.clone(),
        description: part.description.clone(),
    })
}

/// `tile`, unless it is every pixel of an `image`-sized image (a part
/// split by samples only), for naming the pixels in messages.
fn unless_whole(tile: Tile, (w, h): (u32, u32)) -> Option<Tile> {
    (!tile.is_whole(w, h)).then_some(tile)
}

/// Adds the pixels of `part` to `film`, the whole image's, at its tile,
/// rows in parallel, checking each pixel against the `done` samples per
/// pixel the part holds; returns the samples they count. The error names
/// the first pixel in reading order that is wrong.
fn add_pixels(film: &mut Film, part: &Unpacked, done: u32) -> Result<u64, String> {
    use rayon::prelude::*;
    let tile = part.head.tile;
    let (x0, x1) = (tile.x0 as usize, tile.x1 as usize);
    // The layers' counts are the image's: added into a scratch row.
    let mut scratch = vec![0u32; (x1 - x0) * tile.height() as usize];
    for (layer, pixels) in &part.layers {
        scratch.fill(0);
        let named = |(y, e): (usize, PixelError)| match e {
            PixelError::Malformed(m) => m.to_string(),
            PixelError::Pixel { x, message } => format!(
                "pixel ({}, {}) of its {} layer {message}",
                tile.x0 as usize + x,
                tile.y0 as usize + y,
                layer.name()
            ),
        };
        let same_counts = |scratch: &[u32]| {
            if scratch.iter().copied().ne(part.pixels.counts()) {
                return Err(format!(
                    "its {} layer's counts are not its pixels'",
                    layer.name()
                ));
            }
            Ok(())
        };
        if Film::PACKED.has(*layer) {
            // Read into a scratch block (counted with the film against
            // free memory), then checked and added.
            let w = (x1 - x0).max(1);
            let mut sums = Vec::new();
            sums.try_reserve_exact(scratch.len())
                .map_err(|_| format!("its {} layer does not fit in memory", layer.name()))?;
            sums.resize(scratch.len(), Sum::ZERO);
            let rows = sums.par_chunks_mut(w).zip(scratch.par_chunks_mut(w));
            pixels.add_rows(rows, None).map_err(named)?;
            same_counts(&scratch)?;
            let origin = (x0, tile.y0 as usize);
            film.add_packed_layer(*layer, (origin, w), &sums, &scratch)
                .map_err(|(x, y, problem)| {
                    let message = problem.message().into();
                    named((y, PixelError::Pixel { x, message }))
                })?;
            continue;
        }
        let rows = (film.rows_mut())
            .skip(tile.y0 as usize)
            .take(tile.height() as usize)
            .zip(scratch.par_chunks_mut((x1 - x0).max(1)))
            .map(|(row, counts)| (&mut row.layer_sums[*layer as usize][x0..x1], counts));
        pixels.add_rows(rows, None).map_err(named)?;
        same_counts(&scratch)?;
    }
    let rows = (film.rows_mut())
        .skip(tile.y0 as usize)
        .take(tile.height() as usize)
        .map(|row| (&mut row.sums[x0..x1], &mut row.counts[x0..x1]));
    part.pixels
        .add_rows(rows, Some(done))
        .map_err(|(y, e)| match e {
            PixelError::Malformed(m) => m.into(),
            PixelError::Pixel { x, message } => {
                format!(
                    "pixel ({}, {}) {message}",
                    tile.x0 as usize + x,
                    tile.y0 as usize + y
                )
            }
        })
}

/// The sorted sample ranges `ranges` (disjoint), adjacent ones joined, and
/// the ranges of `0..spp` none of them holds.
fn joined(ranges: &[Range<u32>], spp: u32) -> (Vec<Range<u32>>, Vec<Range<u32>>) {
    let (mut held, mut missing) = (Vec::<Range<u32>>::new(), Vec::new());
    let mut at = 0;
    for r in ranges.iter().filter(|r| !r.is_empty()) {
        if r.start > at {
            missing.push(at..r.start);
        }
        match held.last_mut() {
            Some(last) if last.end == r.start => last.end = r.end,
            _ => held.push(r.clone()),
        }
        at = r.end;
    }
    if at < spp {
        missing.push(at..spp);
    }
    (held, missing)
}

/// The first pixel, in reading order, of a `w`×`h` image that none of the
/// disjoint `tiles` holds (there must be one).
fn first_uncovered(tiles: &[Tile], w: u32, h: u32) -> (u32, u32) {
    for y in 0..h {
        let mut spans: Vec<(u32, u32)> = (tiles.iter())
            .filter(|t| t.y0 <= y && y < t.y1)
            .map(|t| (t.x0, t.x1))
            .collect();
        spans.sort_unstable();
        let mut x = 0;
        for (x0, x1) in spans {
            if x0 > x {
                return (x, y);
            }
            x = x1;
        }
        if x < w {
            return (x, y);
        }
    }
    (0, 0)
}

/// The render settings a render identity text names.
fn render_settings(description: &str) -> Option<RenderDesc> {
    let mut value: serde_json::Value = serde_json::from_str(description).ok()?;
    serde_json::from_value(value.get_mut("render")?.take()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_missing_pixel_is_found_in_reading_order() {
        let t = |s: &str| s.parse::<Tile>().unwrap();
        assert_eq!(first_uncovered(&[t("0,0,4,2")], 4, 3), (0, 2));
        assert_eq!(first_uncovered(&[t("0,0,2,3"), t("3,0,4,3")], 4, 3), (2, 0));
        assert_eq!(first_uncovered(&[t("0,0,4,1"), t("0,1,3,3")], 4, 3), (3, 1));
    }

    #[test]
    fn ranges_join_and_gaps_are_missing() {
        let (held, missing) = joined(&[0..2, 2..4, 6..8], 10);
        assert_eq!(held, [0..4, 6..8]);
        assert_eq!(missing, [4..6, 8..10]);
    }
}
