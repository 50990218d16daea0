//! Parts: a render split by samples into shares rendered apart (the tasks
//! of a cluster's job array), and merged into the image one machine would
//! have made, to the bit.
//!
//! Part `K/N` takes sample indices `⌊K·spp/N⌋..⌊(K+1)·spp/N⌋` of every
//! pixel, so every part covers the whole image at nearly the same cost. A
//! part file is a checkpoint ([`crate::checkpoint`]) of that share: it
//! records the render's identity, the share, the samples done and the
//! film's sums, with a checksum, is rewritten atomically after every pass
//! (so a killed task resumes from it), and is complete once its share is
//! done. Pixels sum their samples in fixed point ([`crate::film::Sum`]),
//! whose addition is associative, so the parts' films add up to the
//! one-machine film exactly, in any order. See `docs/distributed.md`.

use crate::checkpoint::{describe_differences, same_render, Checkpoint, CheckpointError};
use crate::film::Film;
use crate::render::RenderStats;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use thiserror::Error;

/// Extension of part files.
pub const EXTENSION: &str = "lumen-part";

/// Part `index` of `count` equal shares of a render's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Part {
    /// Which share, from 0 (as job array task ids count).
    pub index: u32,
    /// How many shares.
    pub count: u32,
}

impl Part {
    /// The sample indices of this part in a render of `spp` samples per
    /// pixel: empty when there are more parts than samples.
    pub fn samples(&self, spp: u32) -> Range<u32> {
        let at = |k: u32| (u64::from(k) * u64::from(spp) / u64::from(self.count)) as u32;
        at(self.index)..at(self.index + 1)
    }
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Part {
    type Err = String;

    /// `K/N`, with `0 <= K < N`.
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || format!("'{text}': a part is K/N, its index K from 0 to N-1 (e.g. 3/8)");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if count == 0 {
            return Err(format!("'{text}': a render cannot be split into 0 parts"));
        }
        if index >= count {
            return Err(format!(
                "'{text}': part {index} of {count} does not exist (parts count from 0 to {})",
                count - 1
            ));
        }
        Ok(Part { index, count })
    }
}

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
    #[error("{} and {} both hold samples {}..{} of every pixel; give each part once", .first.display(), .other.display(), .common.start, .common.end)]
    Overlap {
        /// One part.
        first: PathBuf,
        /// The other.
        other: PathBuf,
        /// The samples they share.
        common: Range<u32>,
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
    #[error("no part holds samples {} of the {spp} spp render: {} (merge with --partial for a preview)", ranges_text(.missing), if .missing.len() == 1 { "a part is missing" } else { "parts are missing" })]
    Missing {
        /// The samples per pixel of the render.
        spp: u32,
        /// Sample ranges no part holds.
        missing: Vec<Range<u32>>,
    },
    /// A part's description does not say how many samples the render takes.
    #[error("{}: its scene description has no render.samples_per_pixel", .0.display())]
    NoSampleCount(PathBuf),
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
    /// The film of all the parts' samples.
    pub film: Film,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The sample ranges the film holds, in order, adjacent ones joined:
    /// `[0..spp]` for a complete merge.
    pub held: Vec<Range<u32>>,
    /// The parts' counts, added.
    pub stats: RenderStats,
    /// The display gamma of the render (the first part's).
    pub gamma: f32,
    /// [`crate::checkpoint::RENDERER_ID`] of the lumen that rendered the
    /// parts.
    pub renderer_id: String,
    /// The render's identity (canonical scene description).
    pub description: String,
}

impl Merged {
    /// Whether the film holds every sample of the render.
    pub fn is_complete(&self) -> bool {
        self.held.len() == 1 && self.held[0] == (0..self.spp)
    }

    /// Samples per pixel the film holds.
    pub fn held_spp(&self) -> u32 {
        self.held.iter().map(|r| r.end - r.start).sum()
    }
}

/// Merges the part files `paths`, given in any order, reading one at a
/// time (memory: two films, whatever the number of parts). Unless
/// `partial`, the parts must be finished and together hold every sample of
/// the render; with `partial`, whatever they hold so far is merged (a
/// preview). Parts of different renders, and parts holding the same
/// samples, are refused either way.
pub fn merge(paths: &[PathBuf], partial: bool) -> Result<Merged, MergeError> {
    let mut merged: Option<Merged> = None;
    // (samples held, path) of every part read so far, the first first.
    let mut seen: Vec<(Range<u32>, PathBuf)> = Vec::new();
    for path in paths {
        let part = Checkpoint::read(path)?;
        if part.active.is_some() {
            return Err(CheckpointError::Malformed {
                path: path.clone(),
                message: "it is the checkpoint of an adaptive render, not a part".into(),
            }
            .into());
        }
        if part.spp_done < part.share.end && !partial {
            return Err(MergeError::Unfinished {
                path: path.clone(),
                share: part.share,
                done: part.spp_done,
            });
        }
        if let (Some(m), Some((_, first))) = (&merged, seen.first()) {
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
            } else {
                String::new()
            };
            if !differences.is_empty() {
                return Err(MergeError::DifferentRenders {
                    first: first.clone(),
                    other: path.clone(),
                    differences,
                });
            }
        }
        let held = part.share.start..part.spp_done;
        for (other, other_path) in &seen {
            // A part with an empty share (more parts than samples) holds
            // nothing, so it cannot hold anything twice.
            let common = held.start.max(other.start)..held.end.min(other.end);
            if !common.is_empty() {
                return Err(MergeError::Overlap {
                    first: other_path.clone(),
                    other: path.clone(),
                    common,
                });
            }
        }
        seen.push((held, path.clone()));
        match &mut merged {
            Some(m) => {
                // Same description, so the same image size.
                let added = m.film.add_film(&part.film);
                debug_assert!(added, "parts of one render have one film size");
                m.stats.add(part.stats);
            }
            None => {
                let spp = samples_per_pixel(&part.description)
                    .ok_or_else(|| MergeError::NoSampleCount(path.clone()))?;
                merged = Some(Merged {
                    film: part.film,
                    spp,
                    held: Vec::new(),
                    stats: part.stats,
                    gamma: part.gamma,
                    renderer_id: part.renderer_id,
                    description: part.description,
                });
            }
        }
    }
    let mut m = merged.ok_or(MergeError::NoParts)?;
    let mut ranges: Vec<Range<u32>> = seen.into_iter().map(|(r, _)| r).collect();
    ranges.sort_by_key(|r| r.start);
    let mut missing = Vec::new();
    let mut at = 0;
    for r in ranges.iter().filter(|r| !r.is_empty()) {
        if r.start > at {
            missing.push(at..r.start);
        }
        match m.held.last_mut() {
            Some(last) if last.end == r.start => last.end = r.end,
            _ => m.held.push(r.clone()),
        }
        at = r.end;
    }
    if at < m.spp {
        missing.push(at..m.spp);
    }
    if !missing.is_empty() && !partial {
        return Err(MergeError::Missing {
            spp: m.spp,
            missing,
        });
    }
    Ok(m)
}

/// The samples per pixel a render identity text names.
fn samples_per_pixel(description: &str) -> Option<u32> {
    let value: serde_json::Value = serde_json::from_str(description).ok()?;
    let spp = value.get("render")?.get("samples_per_pixel")?.as_u64()?;
    u32::try_from(spp).ok()
}

/// The part file a render of `part` of the samples would write in `dir`:
/// `part-K.lumen-part` (the name the deployment scripts use).
pub fn file_name(dir: &Path, part: Part) -> PathBuf {
    dir.join(format!("part-{}.{EXTENSION}", part.index))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_cover_every_sample_once() {
        for spp in [0, 1, 2, 3, 7, 64, 1000, u32::MAX] {
            for count in [1, 2, 3, 7, 8, 100, 5000] {
                let mut at = 0;
                for index in 0..count {
                    let s = Part { index, count }.samples(spp);
                    assert_eq!(s.start, at, "{index}/{count} of {spp}");
                    assert!(s.end >= s.start);
                    assert!(s.len() as u64 <= u64::from(spp) / u64::from(count) + 1);
                    at = s.end;
                }
                assert_eq!(at, spp);
            }
        }
    }

    #[test]
    fn parts_parse_and_refuse_with_the_reason() {
        assert_eq!("3/8".parse(), Ok(Part { index: 3, count: 8 }));
        assert_eq!("0/1".parse(), Ok(Part { index: 0, count: 1 }));
        let err = |t: &str| t.parse::<Part>().unwrap_err();
        assert!(err("8/8").contains("does not exist"), "{}", err("8/8"));
        assert!(err("0/0").contains("0 parts"));
        for bad in ["", "3", "a/8", "3/b", "-1/4", "3/8/2", "1.5/4"] {
            assert!(err(bad).contains("a part is K/N"), "{bad}: {}", err(bad));
        }
    }
}
