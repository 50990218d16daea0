//! The bytes of a checkpoint's payload (see the table in [`super`]):
//! written piece by piece, so that a large film is neither copied nor held
//! twice, and read back with every length checked, since the file may say
//! anything.

use super::{Checkpoint, CheckpointView, MAGIC, VERSION};
use crate::film::{Film, Sum};
use crate::render::RenderStats;

impl CheckpointView<'_> {
    /// Feeds the payload to `sink` piece by piece, so that it can be hashed
    /// and written without being held in memory (a 1200×675 film is 23 MB).
    fn payload(&self, sink: &mut dyn FnMut(&[u8]) -> std::io::Result<()>) -> std::io::Result<()> {
        for text in [self.renderer_id, self.description] {
            sink(&(text.len() as u32).to_le_bytes())?;
            sink(text.as_bytes())?;
        }
        for v in [
            self.spp_done,
            self.share.start,
            self.share.end,
            self.gamma.to_bits(),
            self.film.width(),
            self.film.height(),
        ] {
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
}

impl Checkpoint {
    pub(super) fn decode_payload(payload: &[u8]) -> Result<Self, &'static str> {
        let mut r = Reader(payload);
        let renderer_id = r.text().ok_or("bad renderer identity")?;
        let description = r.text().ok_or("bad description text")?;
        let spp_done = r.u32().ok_or("missing sample count")?;
        let start = r.u32().ok_or("missing share of samples")?;
        let end = r.u32().ok_or("missing share of samples")?;
        let gamma = f32::from_bits(r.u32().ok_or("missing gamma")?);
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
        let adaptive = if rest == bytes(PIXEL_LEN as u64) {
            false
        } else if rest == bytes(2 * PIXEL_LEN as u64 + 1) {
            true
        } else {
            return Err("pixel data does not match the image size");
        };
        let n = pixels as usize;
        let (whole, rest) = r.0.split_at(n * PIXEL_LEN);
        let (sums, counts) = sums_and_counts(whole, n);
        let film = Film::from_raw(width, height, sums, counts).ok_or("bad pixel data")?;
        let (film, active) = match (adaptive, rest) {
            (false, [0]) => (film, None),
            (true, [1, rest @ ..]) => {
                let (odd, flags) = rest.split_at(n * PIXEL_LEN);
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
            share: start..end,
            spp_done,
            gamma,
            stats,
            film,
            active,
        })
    }
}

/// Bytes a pixel takes: three `i128` sums and a `u32` count.
const PIXEL_LEN: usize = 3 * 16 + 4;

/// Feeds every pixel's three sums and then every pixel's `u32` count to
/// `sink`, a few thousand pixels at a time.
fn write_sums_and_counts(
    (sums, counts): (&[Sum], &[u32]),
    sink: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(4096 * 48);
    for chunk in sums.chunks(4096) {
        buf.clear();
        for v in chunk.iter().flat_map(|s| s.0) {
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

/// The `n` pixels' three sums and then their `u32` counts, decoded from
/// `bytes` ([`PIXEL_LEN`] bytes a pixel).
fn sums_and_counts(bytes: &[u8], n: usize) -> (Vec<Sum>, Vec<u32>) {
    let (sum_bytes, count_bytes) = bytes.split_at(n * 48);
    let sums = sum_bytes
        .chunks_exact(48)
        .map(|p| {
            let f = |i: usize| i128::from_le_bytes(p[i..i + 16].try_into().expect("16 bytes"));
            Sum([f(0), f(16), f(32)])
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
