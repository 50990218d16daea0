//! Checkpoints: the state of an unfinished render (the film's raw sums and
//! counts, how many samples per pixel they hold, the counts gathered so far),
//! saved so that a later run can continue where this one stopped.
//!
//! A checkpoint also records the scene description it was made for, after
//! the command line's overrides, as canonical JSON: a render continues a
//! checkpoint only if its own description is the same, so that the image is
//! bit-identical to one rendered without a stop.
//!
//! # File format (version 4)
//!
//! All integers little-endian.
//!
//! | bytes | content |
//! | --- | --- |
//! | 8 | magic `LUMENCKP` |
//! | 4 | format version (4) |
//! | 8 | payload length *n* |
//! | 4 | CRC-32 of the payload |
//! | *n* | payload |
//!
//! The payload: the renderer identity and the description (each as a u32
//! length and UTF-8 bytes), the end of the samples done, the share of
//! sample indices the render takes (start and end: `0` and the spp for a
//! whole render, less for a part of one), the display gamma (f32), the
//! film's width and height, the column and row of its top left pixel in the
//! image and the image's width and height (u32 each: a film of the whole
//! image, or of a tile of it), samples, rays and dropped samples (u64 each),
//! then the film's pixels (row-major, top row first): every pixel's `u32`
//! count, and every row's sums in a compact form (see `pixels.rs`: each row
//! its length in bytes, then for each pixel the three sums of
//! [`crate::film::Sum`], shifted right past their common trailing zeros and
//! stored in as few bytes as they need). Last, a byte saying whether the
//! render samples adaptively (1) or not (0), followed, if it does, by the
//! same counts and sums for the samples of odd index and a byte a pixel: 1
//! while the pixel is still being sampled, 0 once it stopped.

use crate::film::Film;
use crate::output::{self, OutputError};
use crate::render::RenderStats;
use crate::scene::SceneDesc;
use crate::tile::Tile;
use std::io::Read;
use std::ops::Range;
use std::path::{Path, PathBuf};
use thiserror::Error;

mod canonical;
mod consistency;
mod format;
mod header;
mod identity;
mod pixels;

pub(crate) use format::Unpacked;
pub use header::{inspect, remove, Existing};
pub(crate) use identity::{describe_differences, same_render};
pub use identity::{description_text, identity_text};
pub(crate) use pixels::PixelError;

/// First bytes of every checkpoint file.
pub const MAGIC: &[u8; 8] = b"LUMENCKP";
/// The format version this lumen writes and reads.
pub const VERSION: u32 = 4;
/// Identifies the code that computes samples: the crate version and a
/// revision of the sample computation. Any change that alters the value of a
/// sample (random stream, sampling, intersection arithmetic, materials) must
/// bump the revision, so that a checkpoint written before it is refused
/// rather than mixed with different samples.
pub const RENDERER_ID: &str = concat!(env!("CARGO_PKG_VERSION"), "+samples.11");
/// Extension added to an output path to name its default checkpoint.
pub const EXTENSION: &str = "lumen-ckpt";

/// Length of the header: magic, version, payload length, checksum.
pub const HEADER_LEN: usize = 8 + 4 + 8 + 4;

/// The state of an unfinished render.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// [`RENDERER_ID`] of the lumen that wrote it; other code may compute
    /// other samples, so it is part of what must match.
    pub renderer_id: String,
    /// Canonical JSON of the scene description, overrides applied
    /// (see [`description_text`]).
    pub description: String,
    /// The sample indices this render takes in every pixel: `0..spp` for a
    /// whole render, a share of them for a part of one ([`crate::part`]).
    pub share: Range<u32>,
    /// The pixels of the image the film holds: all of them, or a part's
    /// tile.
    pub tile: Tile,
    /// The whole image's width and height.
    pub image: (u32, u32),
    /// End of the samples the film holds: samples `share.start..spp_done`
    /// of every pixel.
    pub spp_done: u32,
    /// The display gamma the render writes its image with: not part of
    /// what must match to resume, but what `lumen merge` writes parts with.
    pub gamma: f32,
    /// Counts gathered while rendering those samples.
    pub stats: RenderStats,
    /// The accumulated samples.
    pub film: Film,
    /// With adaptive sampling, which pixels are still being sampled.
    pub active: Option<Vec<bool>>,
}

/// A checkpoint that cannot be read or does not belong to this render.
#[derive(Debug, Error)]
pub enum CheckpointError {
    /// The file cannot be read.
    #[error("checkpoint {path}: cannot read: {message}")]
    Io {
        /// The checkpoint path.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// Something other than a regular file is at the path: lumen neither
    /// reads (a device or a pipe may never end) nor replaces it.
    #[error("checkpoint {path}: {message}; choose another --checkpoint")]
    NotRegular {
        /// The checkpoint path.
        path: PathBuf,
        /// What is there.
        message: String,
    },
    /// The file is not a checkpoint at all: it is someone's file, which
    /// lumen neither reads nor replaces.
    #[error("checkpoint {path}: not a lumen checkpoint but {what}; lumen will neither resume from it nor replace it: move or delete it if it is not needed, or choose another --checkpoint")]
    NotACheckpoint {
        /// The checkpoint path.
        path: PathBuf,
        /// What the file seems to be, e.g. `a PNG image of 1234 bytes`.
        what: String,
    },
    /// The magic bytes are wrong, but the rest is laid out as a checkpoint:
    /// a checkpoint damaged on disk.
    #[error("checkpoint {path}: damaged (its first bytes are wrong, but the rest is laid out as a lumen checkpoint); it cannot be resumed: render without --resume to start afresh, which replaces it")]
    Damaged {
        /// The checkpoint path.
        path: PathBuf,
    },
    /// The file has a format version this lumen does not read.
    #[error("checkpoint {path}: format version {found}, but this lumen reads version {VERSION}")]
    Version {
        /// The checkpoint path.
        path: PathBuf,
        /// The version found.
        found: u32,
    },
    /// The file is shorter or longer than its header says.
    #[error("checkpoint {path}: truncated or damaged: {found} bytes, the header says {expected}; refusing to use it (render without --resume to start afresh, which replaces it)")]
    Truncated {
        /// The checkpoint path.
        path: PathBuf,
        /// Length the header announces.
        expected: u64,
        /// Actual length.
        found: u64,
    },
    /// The payload does not match its checksum.
    #[error("checkpoint {path}: corrupted (checksum mismatch); refusing to use it (render without --resume to start afresh, which replaces it)")]
    Corrupted {
        /// The checkpoint path.
        path: PathBuf,
    },
    /// The checksum matches but the content makes no sense, or does not
    /// fit the render.
    #[error("checkpoint {path}: malformed: {message}; refusing to use it (render without --resume to start afresh, which replaces it)")]
    Malformed {
        /// The checkpoint path.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The checkpoint was made for another scene or other settings.
    #[error("checkpoint {path} was made for a different render: {differences}; render with the same scene and settings to resume, or without --resume to start afresh")]
    Mismatch {
        /// The checkpoint path.
        path: PathBuf,
        /// What differs, e.g. `width 160 in the checkpoint, 200 here`.
        differences: String,
    },
}

/// The default checkpoint path of an output image: `out.png` →
/// `out.png.lumen-ckpt`, in the same directory (with the output's name
/// shortened if the whole would not fit in a file name, see
/// [`crate::files::fit_name`]).
pub fn default_path(output: &Path) -> PathBuf {
    crate::files::sibling(output, "", &format!(".{EXTENSION}"))
}

/// A checkpoint to be written, borrowing the state it saves: a render in
/// progress saves its film without copying it.
#[derive(Clone, Debug)]
pub struct CheckpointView<'a> {
    /// [`RENDERER_ID`] of the lumen that writes it.
    pub renderer_id: &'a str,
    /// Canonical JSON of the scene description (see [`description_text`]).
    pub description: &'a str,
    /// The sample indices this render takes (see [`Checkpoint::share`]).
    pub share: Range<u32>,
    /// The pixels the film holds (see [`Checkpoint::tile`]).
    pub tile: Tile,
    /// The whole image's width and height.
    pub image: (u32, u32),
    /// End of the samples the film holds.
    pub spp_done: u32,
    /// The display gamma (see [`Checkpoint::gamma`]).
    pub gamma: f32,
    /// Counts gathered while rendering those samples.
    pub stats: RenderStats,
    /// The accumulated samples.
    pub film: &'a Film,
    /// With adaptive sampling, which pixels are still being sampled.
    pub active: Option<&'a [bool]>,
}

impl CheckpointView<'_> {
    /// Writes the checkpoint to `path` atomically (temporary file + rename),
    /// so a kill at any moment leaves the previous checkpoint or this one.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        output::write_atomic_with(path, |out| self.encode_to(out))
    }
}

impl Checkpoint {
    /// This checkpoint, ready to be written.
    pub fn view(&self) -> CheckpointView<'_> {
        CheckpointView {
            renderer_id: &self.renderer_id,
            description: &self.description,
            share: self.share.clone(),
            tile: self.tile,
            image: self.image,
            spp_done: self.spp_done,
            gamma: self.gamma,
            stats: self.stats,
            film: &self.film,
            active: self.active.as_deref(),
        }
    }

    /// The checkpoint's bytes, header included.
    pub fn encode(&self) -> Vec<u8> {
        self.view().encode()
    }

    /// Reads a checkpoint from `bytes`; `path` only names it in errors.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Self, CheckpointError> {
        let path_buf = || path.to_path_buf();
        let payload = Self::verify(bytes, path)?;
        let ckpt = Self::decode_payload(payload).map_err(|message| CheckpointError::Malformed {
            path: path_buf(),
            message: message.to_string(),
        })?;
        ckpt.check_consistency()
            .map_err(|message| CheckpointError::Malformed {
                path: path_buf(),
                message,
            })?;
        Ok(ckpt)
    }

    /// The payload of the checkpoint file `bytes` (read from `path`, which
    /// names it in errors), once its header and checksum are checked.
    pub(crate) fn verify<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a [u8], CheckpointError> {
        let head = &bytes[..bytes.len().min(HEADER_LEN)];
        header::check(head, bytes.len() as u64, path)?;
        let crc = u32::from_le_bytes(
            bytes[HEADER_LEN - 4..HEADER_LEN]
                .try_into()
                .expect("4 bytes"),
        );
        let payload = &bytes[HEADER_LEN..];
        if crc32fast::hash(payload) != crc {
            return Err(CheckpointError::Corrupted {
                path: path.to_path_buf(),
            });
        }
        Ok(payload)
    }

    /// Writes the checkpoint to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        self.view().write(path)
    }

    /// Reads and verifies the checkpoint at `path`. Only a regular file is
    /// read, and no more of it than its header announces (which must be
    /// its size): a device or a pipe given as a checkpoint is refused
    /// rather than read for ever.
    pub fn read(path: &Path) -> Result<Self, CheckpointError> {
        let mut bytes = Vec::new();
        Self::read_bytes(path, &mut bytes)?;
        Self::decode(&bytes, path)
    }

    /// Reads the checkpoint file at `path` into `bytes` (replacing what it
    /// held, and keeping its allocation when it is large enough), checking
    /// the header as [`Checkpoint::read`] does; the payload is not checked.
    pub(crate) fn read_bytes(path: &Path, bytes: &mut Vec<u8>) -> Result<(), CheckpointError> {
        let io = |e: std::io::Error| CheckpointError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let (mut file, len) = header::open_regular(path)?;
        bytes.clear();
        (&mut file)
            .take(HEADER_LEN as u64)
            .read_to_end(bytes)
            .map_err(io)?;
        let payload_len = header::check(bytes, len, path)?;
        let room = usize::try_from(payload_len).unwrap_or(usize::MAX);
        bytes
            .try_reserve_exact(room)
            .map_err(|_| CheckpointError::Io {
                path: path.to_path_buf(),
                message: format!("{payload_len} bytes do not fit in memory"),
            })?;
        (&mut file)
            .take(payload_len)
            .read_to_end(bytes)
            .map_err(io)?;
        Ok(())
    }

    /// Checks that this checkpoint was made for a render of `desc` (overrides
    /// applied) by this version of lumen; the error names what differs.
    pub fn check_matches(&self, desc: &SceneDesc, path: &Path) -> Result<(), CheckpointError> {
        self.check_description(&description_text(desc), path)
    }

    /// Checks that this checkpoint was made by this renderer for the render
    /// whose canonical description (see [`description_text`]) is `ours`.
    pub fn check_description(&self, ours: &str, path: &Path) -> Result<(), CheckpointError> {
        if self.renderer_id != RENDERER_ID {
            return Err(CheckpointError::Mismatch {
                path: path.to_path_buf(),
                differences: format!(
                    "written by lumen {}, this is lumen {RENDERER_ID}",
                    self.renderer_id
                ),
            });
        }
        if identity::same_render(&self.description, ours) {
            return Ok(());
        }
        Err(CheckpointError::Mismatch {
            path: path.to_path_buf(),
            differences: identity::describe_differences(
                &self.description,
                ours,
                "the checkpoint",
                "here",
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aov::Layer;
    use crate::film::Sum;
    use crate::scene::builtin;

    /// A consistent checkpoint of 8×4 pixels at 16 spp, a quarter of the
    /// pixels with a dropped sample.
    fn sample() -> (SceneDesc, Checkpoint) {
        let mut desc = builtin::find("metal-mirror").unwrap().desc();
        desc.render.width = 8;
        let h = 4;
        desc.render.height = Some(h);
        let n = 8 * h as usize;
        let sums = (0..n as i128)
            .map(|i| Sum([i * 7, -15, i128::MAX - i]))
            .collect();
        let counts = (0..n).map(|i| if i % 4 == 0 { 15 } else { 16 }).collect();
        let ckpt = Checkpoint {
            renderer_id: RENDERER_ID.into(),
            description: description_text(&desc),
            share: 0..16,
            tile: Tile::whole(8, h),
            image: (8, h),
            spp_done: 16,
            gamma: 2.0,
            stats: RenderStats {
                samples: 16 * n as u64,
                rays: 1234,
                dropped: n as u64 / 4,
            },
            film: Film::from_raw(8, h, sums, counts).unwrap(),
            active: None,
        };
        (desc, ckpt)
    }

    #[test]
    fn round_trips_exactly() {
        let (desc, ckpt) = sample();
        let p = Path::new("x");
        let back = Checkpoint::decode(&ckpt.encode(), p).unwrap();
        assert_eq!(back, ckpt);
        back.check_matches(&desc, p).unwrap();
        // With feature layers (after the adaptive section when there is
        // one, below).
        let layered = |film: Film| {
            let n = film.len();
            let moment = (0..n).map(|i| Sum([i as i128, 0, -1])).collect();
            film.with_layer(Layer::Albedo, vec![Sum([5 << 34, -6 << 34, 7 << 34]); n])
                .and_then(|f| f.with_layer(Layer::Moment, moment))
                .unwrap()
        };
        let with_layers = Checkpoint {
            film: layered(ckpt.film.clone()),
            ..ckpt.clone()
        };
        let decoded = Checkpoint::decode(&with_layers.encode(), p).unwrap();
        assert_eq!(decoded, with_layers);
        assert_ne!(decoded, ckpt, "the layers were read");
        // With adaptive sampling's flags too.
        let n = ckpt.film.len();
        let adaptive = Checkpoint {
            active: Some((0..n).map(|i| i % 3 == 0).collect()),
            film: ckpt
                .film
                .clone()
                .with_odd(vec![Sum([1, 2, -3]); n], vec![8; n])
                .unwrap(),
            ..ckpt
        };
        let bytes = adaptive.encode();
        assert_eq!(Checkpoint::decode(&bytes, p).unwrap(), adaptive);
        let both = Checkpoint {
            film: layered(adaptive.film.clone()),
            ..adaptive.clone()
        };
        assert_eq!(Checkpoint::decode(&both.encode(), p).unwrap(), both);
        // A flag other than 0 or 1 is refused, even with a valid checksum.
        let mut bad = Checkpoint::decode(&bytes, p).unwrap().encode();
        *bad.last_mut().unwrap() = 2;
        let crc = crc32fast::hash(&bad[HEADER_LEN..]);
        bad[HEADER_LEN - 4..HEADER_LEN].copy_from_slice(&crc.to_le_bytes());
        let e = Checkpoint::decode(&bad, p).unwrap_err().to_string();
        assert!(e.contains("adaptive sampling flags"), "{e}");
    }

    #[test]
    fn every_flipped_byte_and_every_truncation_is_refused() {
        let (_, ckpt) = sample();
        let bytes = ckpt.encode();
        let p = Path::new("x");
        for i in 0..bytes.len() {
            let mut bad = bytes.clone();
            bad[i] ^= 0x10;
            assert!(Checkpoint::decode(&bad, p).is_err(), "flip at {i} accepted");
            assert!(
                Checkpoint::decode(&bytes[..i], p).is_err(),
                "truncation to {i} accepted"
            );
        }
    }

    #[test]
    fn mismatches_are_named() {
        let (mut desc, ckpt) = sample();
        let p = Path::new("x");
        let spp = desc.render.samples_per_pixel;
        desc.render.seed = 7;
        desc.render.samples_per_pixel = 5;
        let e = ckpt.check_matches(&desc, p).unwrap_err().to_string();
        assert!(e.contains("seed 0 in the checkpoint, 7 here"), "{e}");
        assert!(
            e.contains(&format!("spp {spp} in the checkpoint, 5 here")),
            "{e}"
        );
        let other = builtin::find("cover").unwrap().desc();
        let e = ckpt.check_matches(&other, p).unwrap_err().to_string();
        assert!(e.contains("a different scene (its camera, "), "{e}");
        assert!(e.contains(" and objects differ)"), "{e}");
    }

    #[test]
    fn a_settings_change_alone_is_not_called_a_different_scene() {
        // The cover has hundreds of numbers that must compare equal after
        // parsing, whatever the JSON parser's rounding.
        let mut desc = builtin::find("cover").unwrap().desc();
        let ckpt = Checkpoint {
            description: description_text(&desc),
            ..sample().1
        };
        desc.render.seed += 1;
        let e = ckpt.check_matches(&desc, Path::new("x")).unwrap_err();
        assert!(!e.to_string().contains("different scene"), "{e}");
        assert!(e.to_string().contains("seed"), "{e}");
    }

    #[test]
    fn default_path_is_beside_the_output() {
        assert_eq!(
            default_path(Path::new("dir/out.png")),
            PathBuf::from("dir/out.png.lumen-ckpt")
        );
    }
}
