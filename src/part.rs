//! Parts: a render split into shares rendered apart (the tasks of a
//! cluster's job array), and merged into the image one machine would have
//! made, to the bit.
//!
//! By samples (the default), part `K/N` takes sample indices
//! `⌊K·spp/N⌋..⌊(K+1)·spp/N⌋` of every pixel, so every part covers the
//! whole image at nearly the same cost. By tiles (`--split tiles`, or an
//! explicit `--tile`), a part takes every sample of some pixels
//! ([`crate::tile`]), and its film holds those pixels only: for images whose
//! film is too large for one machine. A tile may itself be split by
//! samples. A part file is a checkpoint ([`crate::checkpoint`]) of its
//! share: it records the render's identity, the samples and pixels it
//! takes, the samples done and the film's sums, with a checksum, is
//! rewritten atomically between passes (so a killed task resumes from
//! it), and is complete once its share is done. Pixels sum their samples in fixed point ([`crate::film::Sum`]),
//! whose addition is associative, so the parts' films add up to the
//! one-machine film exactly, in any order. See `docs/distributed.md`.

use crate::tile::Tile;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;

mod merge;

pub use merge::{merge, ranges_text, MergeError, Merged};

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

/// What a render is split by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Split {
    /// Shares of every pixel's samples: parts of equal cost, each with a
    /// film of the whole image.
    #[default]
    Samples,
    /// Bands of whole rows, all samples: each part's film holds its band.
    Tiles,
}

impl FromStr for Split {
    type Err = String;

    /// `samples` or `tiles`.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "samples" => Ok(Split::Samples),
            "tiles" => Ok(Split::Tiles),
            _ => Err(format!(
                "'{text}': a render splits by samples or by tiles (--split samples|tiles)"
            )),
        }
    }
}

/// The share of a render one part takes: which of every pixel's samples,
/// and which pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Share {
    /// Part `K/N`, of the samples or of the bands of rows, as `split` says.
    pub part: Option<Part>,
    /// What `part` splits.
    pub split: Split,
    /// Only these pixels; with `part` splitting samples, that share of
    /// these pixels' samples. Not with `split` [`Split::Tiles`].
    pub tile: Option<Tile>,
}

impl Share {
    /// Whether this is the whole render (no part, no tile).
    pub fn is_whole(&self) -> bool {
        self.part.is_none() && self.tile.is_none()
    }

    /// The sample indices of every pixel this share takes in a render of
    /// `spp` samples per pixel.
    pub fn samples(&self, spp: u32) -> Range<u32> {
        match (self.part, self.split) {
            (Some(part), Split::Samples) => part.samples(spp),
            _ => 0..spp,
        }
    }

    /// The pixels this share takes of a `width`×`height` image; the error
    /// says why there are none.
    pub fn tile(&self, width: u32, height: u32) -> Result<Tile, String> {
        match (self.part, self.split, self.tile) {
            (Some(_), Split::Tiles, Some(_)) => {
                Err("a part split by tiles takes its own tile: give --tile or --split tiles, not both".into())
            }
            (Some(part), Split::Tiles, None) => {
                Tile::band(part.index, part.count, width, height).ok_or_else(|| {
                    format!(
                        "part {part} (tiles): the {height} rows of the image cannot be split into {} bands; split into at most {height} parts",
                        part.count
                    )
                })
            }
            (_, _, Some(tile)) => tile.check_within(width, height).map(|()| tile),
            _ => Ok(Tile::whole(width, height)),
        }
    }
}

impl fmt::Display for Share {
    /// `part 3/8`, `part 3/8 (tiles)`, `tile 0,0,64,64` or `part 1/2 of tile 0,0,64,64`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.part, self.split, self.tile) {
            (None, _, None) => write!(f, "the whole render"),
            (Some(p), Split::Tiles, _) => write!(f, "part {p} (tiles)"),
            (Some(p), Split::Samples, None) => write!(f, "part {p}"),
            (Some(p), Split::Samples, Some(t)) => write!(f, "part {p} of tile {t}"),
            (None, _, Some(t)) => write!(f, "tile {t}"),
        }
    }
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
