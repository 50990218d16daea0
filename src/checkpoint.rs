//! Checkpoints: the state of an unfinished render (the film's raw sums and
//! counts, how many samples per pixel they hold, the counts gathered so far),
//! saved so that a later run can continue where this one stopped.
//!
//! A checkpoint also records the scene description it was made for, after
//! the command line's overrides, as canonical JSON: a render continues a
//! checkpoint only if its own description is the same, so that the image is
//! bit-identical to one rendered without a stop.
//!
//! # File format (version 2)
//!
//! All integers little-endian.
//!
//! | bytes | content |
//! | --- | --- |
//! | 8 | magic `LUMENCKP` |
//! | 4 | format version (2) |
//! | 8 | payload length *n* |
//! | 4 | CRC-32 of the payload |
//! | *n* | payload |
//!
//! The payload: the renderer identity and the description (each as a u32 length
//! and UTF-8 bytes), samples per pixel done (u32), width and height (u32),
//! samples, rays and dropped samples (u64 each), then every pixel's three
//! `f64` sums and every pixel's `u32` count (pixels row-major, top row
//! first), and last a byte saying whether the render samples adaptively (1)
//! or not (0), followed, if it does, by the same sums and counts for the
//! samples of odd index and a byte a pixel: 1 while the pixel is still being
//! sampled, 0 once it stopped.

use crate::film::Film;
use crate::output::{self, OutputError};
use crate::render::RenderStats;
use crate::scene::SceneDesc;
use std::io::Read;
use std::path::{Path, PathBuf};
use thiserror::Error;

mod consistency;
mod header;
mod identity;

pub use header::{inspect, remove, Existing};
pub use identity::{description_text, identity_text};

/// First bytes of every checkpoint file.
pub const MAGIC: &[u8; 8] = b"LUMENCKP";
/// The format version this lumen writes and reads.
pub const VERSION: u32 = 2;
/// Identifies the code that computes samples: the crate version and a
/// revision of the sample computation. Any change that alters the value of a
/// sample (random stream, sampling, intersection arithmetic, materials) must
/// bump the revision, so that a checkpoint written before it is refused
/// rather than mixed with different samples.
pub const RENDERER_ID: &str = concat!(env!("CARGO_PKG_VERSION"), "+samples.9");
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
    /// Samples per pixel held by the film: samples `0..spp_done` of every pixel.
    pub spp_done: u32,
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
#[derive(Clone, Copy, Debug)]
pub struct CheckpointView<'a> {
    /// [`RENDERER_ID`] of the lumen that writes it.
    pub renderer_id: &'a str,
    /// Canonical JSON of the scene description (see [`description_text`]).
    pub description: &'a str,
    /// Samples per pixel held by the film.
    pub spp_done: u32,
    /// Counts gathered while rendering those samples.
    pub stats: RenderStats,
    /// The accumulated samples.
    pub film: &'a Film,
    /// With adaptive sampling, which pixels are still being sampled.
    pub active: Option<&'a [bool]>,
}

impl CheckpointView<'_> {
    /// Feeds the payload to `sink` piece by piece, so that it can be hashed
    /// and written without being held in memory (a 1200×675 film is 23 MB).
    fn payload(&self, sink: &mut dyn FnMut(&[u8]) -> std::io::Result<()>) -> std::io::Result<()> {
        for text in [self.renderer_id, self.description] {
            sink(&(text.len() as u32).to_le_bytes())?;
            sink(text.as_bytes())?;
        }
        for v in [self.spp_done, self.film.width(), self.film.height()] {
            sink(&v.to_le_bytes())?;
        }
        for v in [self.stats.samples, self.stats.rays, self.stats.dropped] {
            sink(&v.to_le_bytes())?;
        }
        write_sums_and_counts(self.film.raw(), sink)?;
        match self.active {
            // Adaptive: the halves' sums and counts, and the pixels' flags.
            Some(active) if self.film.has_halves() => {
                sink(&[1])?;
                write_sums_and_counts(self.film.raw_odd(), sink)?;
                let flags: Vec<u8> = active.iter().map(|&a| u8::from(a)).collect();
                sink(&flags)
            }
            _ => sink(&[0]),
        }
    }

    /// Writes the checkpoint, header included, to `out`: one pass over the
    /// payload computes its checksum, a second writes it.
    pub fn encode_to(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        let mut hasher = crc32fast::Hasher::new();
        let mut len = 0u64;
        self.payload(&mut |bytes| {
            hasher.update(bytes);
            len += bytes.len() as u64;
            Ok(())
        })?;
        out.write_all(MAGIC)?;
        out.write_all(&VERSION.to_le_bytes())?;
        out.write_all(&len.to_le_bytes())?;
        out.write_all(&hasher.finalize().to_le_bytes())?;
        self.payload(&mut |bytes| out.write_all(bytes))
    }

    /// The checkpoint's bytes, header included.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.encode_to(&mut out)
            .expect("writing to memory cannot fail");
        out
    }

    /// Writes the checkpoint to `path` atomically (temporary file + rename),
    /// so a kill at any moment leaves the previous checkpoint or this one.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        output::write_atomic(path, |tmp| {
            let file = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
            let mut out = std::io::BufWriter::new(file);
            self.encode_to(&mut out)
                .and_then(|()| std::io::Write::flush(&mut out))
                .map_err(|e| e.to_string())
        })
    }
}

impl Checkpoint {
    /// This checkpoint, ready to be written.
    pub fn view(&self) -> CheckpointView<'_> {
        CheckpointView {
            renderer_id: &self.renderer_id,
            description: &self.description,
            spp_done: self.spp_done,
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
        let head = &bytes[..bytes.len().min(HEADER_LEN)];
        header::check(head, bytes.len() as u64, path)?;
        let crc = u32::from_le_bytes(
            bytes[HEADER_LEN - 4..HEADER_LEN]
                .try_into()
                .expect("4 bytes"),
        );
        let payload = &bytes[HEADER_LEN..];
        if crc32fast::hash(payload) != crc {
            return Err(CheckpointError::Corrupted { path: path_buf() });
        }
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

    fn decode_payload(payload: &[u8]) -> Result<Self, &'static str> {
        let mut r = Reader(payload);
        let renderer_id = r.text().ok_or("bad renderer identity")?;
        let description = r.text().ok_or("bad description text")?;
        let spp_done = r.u32().ok_or("missing sample count")?;
        let width = r.u32().ok_or("missing width")?;
        let height = r.u32().ok_or("missing height")?;
        let mut stat = || r.u64().ok_or("missing statistics");
        let stats = RenderStats {
            samples: stat()?,
            rays: stat()?,
            dropped: stat()?,
        };
        // Checked: the size is read from the file, which may say anything.
        let pixels = u64::from(width) * u64::from(height);
        let bytes = |per_pixel: u64| pixels.checked_mul(per_pixel).and_then(|b| b.checked_add(1));
        let rest = Some(r.0.len() as u64);
        let adaptive = if rest == bytes(28) {
            false
        } else if rest == bytes(57) {
            true
        } else {
            return Err("pixel data does not match the image size");
        };
        let n = pixels as usize;
        let (whole, rest) = r.0.split_at(n * 28);
        let (sums, counts) = sums_and_counts(whole, n);
        let film = Film::from_raw(width, height, sums, counts).ok_or("bad pixel data")?;
        let (film, active) = match (adaptive, rest) {
            (false, [0]) => (film, None),
            (true, [1, rest @ ..]) => {
                let (odd, flags) = rest.split_at(n * 28);
                let (odd_sums, odd_counts) = sums_and_counts(odd, n);
                let film = film
                    .with_odd(odd_sums, odd_counts)
                    .ok_or("bad pixel data of the samples of odd index")?;
                let active = flags
                    .iter()
                    .map(|&b| match b {
                        0 => Ok(false),
                        1 => Ok(true),
                        _ => Err("bad adaptive sampling flags"),
                    })
                    .collect::<Result<Vec<bool>, _>>()?;
                (film, Some(active))
            }
            _ => return Err("bad adaptive sampling flags"),
        };
        Ok(Self {
            renderer_id,
            description,
            spp_done,
            stats,
            film,
            active,
        })
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
        let io = |e: std::io::Error| CheckpointError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let (mut file, len) = header::open_regular(path)?;
        let mut bytes = Vec::with_capacity(HEADER_LEN);
        (&mut file)
            .take(HEADER_LEN as u64)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        let payload_len = header::check(&bytes, len, path)?;
        bytes.reserve_exact(usize::try_from(payload_len).unwrap_or(0));
        (&mut file)
            .take(payload_len)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        Self::decode(&bytes, path)
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
            differences: identity::describe_differences(&self.description, ours),
        })
    }
}

/// Feeds every pixel's three `f64` sums and then every pixel's `u32` count
/// to `sink`, a few thousand pixels at a time.
fn write_sums_and_counts(
    (sums, counts): (&[[f64; 3]], &[u32]),
    sink: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(4096 * 24);
    for chunk in sums.chunks(4096) {
        buf.clear();
        for v in chunk.iter().flatten() {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        sink(&buf)?;
    }
    for chunk in counts.chunks(4096) {
        buf.clear();
        for c in chunk {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        sink(&buf)?;
    }
    Ok(())
}

/// The `n` pixels' three `f64` sums and then their `u32` counts, decoded
/// from `bytes` (28 bytes a pixel).
fn sums_and_counts(bytes: &[u8], n: usize) -> (Vec<[f64; 3]>, Vec<u32>) {
    let (sum_bytes, count_bytes) = bytes.split_at(n * 24);
    let sums = sum_bytes
        .chunks_exact(24)
        .map(|p| {
            let f = |i: usize| f64::from_le_bytes(p[i..i + 8].try_into().expect("8 bytes"));
            [f(0), f(8), f(16)]
        })
        .collect();
    let counts = count_bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    (sums, counts)
}

/// A cursor over little-endian bytes.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        if self.0.len() < n {
            return None;
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Some(head)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    fn text(&mut self) -> Option<String> {
        let n = self.u32()? as usize;
        String::from_utf8(self.take(n)?.to_vec()).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    /// A consistent checkpoint of 8×4 pixels at 16 spp, a quarter of the
    /// pixels with a dropped sample.
    fn sample() -> (SceneDesc, Checkpoint) {
        let mut desc = builtin::find("metal-mirror").unwrap().desc();
        desc.render.width = 8;
        let h = 4;
        desc.render.height = Some(h);
        let n = 8 * h as usize;
        let sums = (0..n).map(|i| [i as f64 * 0.1, -1.5, 1e300]).collect();
        let counts = (0..n).map(|i| if i % 4 == 0 { 15 } else { 16 }).collect();
        let ckpt = Checkpoint {
            renderer_id: RENDERER_ID.into(),
            description: description_text(&desc),
            spp_done: 16,
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
        // With adaptive sampling's flags too.
        let n = ckpt.film.len();
        let adaptive = Checkpoint {
            active: Some((0..n).map(|i| i % 3 == 0).collect()),
            film: ckpt
                .film
                .clone()
                .with_odd(vec![[0.25, 1.0, -2.0]; n], vec![8; n])
                .unwrap(),
            ..ckpt
        };
        let bytes = adaptive.encode();
        assert_eq!(Checkpoint::decode(&bytes, p).unwrap(), adaptive);
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
