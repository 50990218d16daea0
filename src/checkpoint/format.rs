//! The bytes of a checkpoint's payload (see the table in [`super`]):
//! written piece by piece, so that a large film is neither copied nor held
//! twice, and read back with every length checked, since the file may say
//! anything.

use super::pixels::{write_pixels, Pixels};
use super::{Checkpoint, CheckpointView, MAGIC, VERSION};
use crate::aov::{Layer, Layers};
use crate::film::Film;
use crate::render::RenderStats;
use crate::tile::Tile;

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
            self.tile.x0,
            self.tile.y0,
            self.image.0,
            self.image.1,
        ] {
            sink(&v.to_le_bytes())?;
        }
        for v in [self.stats.samples, self.stats.rays, self.stats.dropped] {
            sink(&v.to_le_bytes())?;
        }
        let width = self.film.width() as usize;
        let (sums, counts) = self.film.raw();
        write_pixels((|i| sums[i], counts), width, sink)?;
        match self.active {
            // Adaptive: the halves' sums and counts, and the pixels' flags.
            Some(active) if self.film.has_halves() => {
                sink(&[1])?;
                let (odd_sums, odd_counts) = self.film.raw_odd();
                write_pixels((|i| odd_sums[i], odd_counts), width, sink)?;
                let flags: Vec<u8> = active.iter().map(|&a| u8::from(a)).collect();
                sink(&flags)?;
            }
            _ => sink(&[0])?,
        }
        // The feature layers, when the film keeps any (a checkpoint
        // without them ends above).
        let layers = self.film.layers();
        if !layers.is_empty() {
            sink(&[layers.bits()])?;
            let counts = self.film.raw().1;
            for layer in Layer::ALL.into_iter().filter(|&l| layers.has(l)) {
                let sum = |i| self.film.layer_sum(layer, i);
                write_pixels((sum, counts), width, sink)?;
            }
        }
        Ok(())
    }

    /// Writes the checkpoint, header included, to `out`, encoding the
    /// payload once: the header's length and checksum, which come first,
    /// are written after it, in the room left for them.
    pub fn encode_to<W: std::io::Write + std::io::Seek>(&self, out: &mut W) -> std::io::Result<()> {
        use std::io::SeekFrom;
        out.write_all(MAGIC)?;
        out.write_all(&VERSION.to_le_bytes())?;
        let room = out.stream_position()?;
        out.write_all(&[0; 12])?;
        let mut hasher = crc32fast::Hasher::new();
        let mut len = 0u64;
        self.payload(&mut |bytes| {
            hasher.update(bytes);
            len += bytes.len() as u64;
            out.write_all(bytes)
        })?;
        let end = out.stream_position()?;
        out.seek(SeekFrom::Start(room))?;
        out.write_all(&len.to_le_bytes())?;
        out.write_all(&hasher.finalize().to_le_bytes())?;
        out.seek(SeekFrom::Start(end))?;
        Ok(())
    }

    /// The checkpoint's bytes, header included.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        self.encode_to(&mut out)
            .expect("writing to memory cannot fail");
        out.into_inner()
    }
}

/// A checkpoint's payload read, its pixels found but not decoded: what
/// `lumen merge` adds straight into its film.
pub(crate) struct Unpacked<'a> {
    /// Every field but the film, which is empty (0×0): its size is the
    /// tile's.
    pub(crate) head: Checkpoint,
    /// The film's sums and counts.
    pub(crate) pixels: Pixels<'a>,
    /// With adaptive sampling: the sums and counts of the samples of odd
    /// index, and a flag a pixel.
    pub(crate) odd: Option<(Pixels<'a>, &'a [u8])>,
    /// The sums of the feature layers the film keeps, each with its layer.
    pub(crate) layers: Vec<(Layer, Pixels<'a>)>,
}

impl Checkpoint {
    /// Reads a payload's fields and finds its pixels.
    pub(crate) fn unpack(payload: &[u8]) -> Result<Unpacked<'_>, &'static str> {
        let mut r = Reader(payload);
        let renderer_id = r.text().ok_or("bad renderer identity")?;
        let description = r.text().ok_or("bad description text")?;
        let mut field = |what| r.u32().ok_or(what);
        let spp_done = field("missing sample count")?;
        let start = field("missing share of samples")?;
        let end = field("missing share of samples")?;
        let gamma = f32::from_bits(field("missing gamma")?);
        let width = field("missing width")?;
        let height = field("missing height")?;
        let (x0, y0) = (field("missing tile")?, field("missing tile")?);
        let image = (field("missing image size")?, field("missing image size")?);
        let tile = Tile {
            x0,
            y0,
            x1: x0.checked_add(width).ok_or("bad tile")?,
            y1: y0.checked_add(height).ok_or("bad tile")?,
        };
        let mut stat = || r.u64().ok_or("missing statistics");
        let stats = RenderStats {
            samples: stat()?,
            rays: stat()?,
            dropped: stat()?,
        };
        let (pixels, rest) = Pixels::split(r.0, width, height)?;
        let (odd, rest) = match rest {
            [0, rest @ ..] => (None, rest),
            [1, rest @ ..] => {
                let (odd, rest) = Pixels::split(rest, width, height)?;
                let n = u64::from(width) * u64::from(height);
                if (rest.len() as u64) < n {
                    return Err("pixel data does not match the image size");
                }
                let (flags, rest) = rest.split_at(n as usize);
                (Some((odd, flags)), rest)
            }
            [] => return Err("pixel data does not match the image size"),
            _ => return Err("bad adaptive sampling flags"),
        };
        let mut layers = Vec::new();
        if let [bits, after @ ..] = rest {
            let mut rest = after;
            let kept = Layers::from_bits(*bits)
                .filter(|l| !l.is_empty())
                .ok_or("bad feature layers")?;
            for layer in Layer::ALL.into_iter().filter(|&l| kept.has(l)) {
                let (sums, after) = Pixels::split(rest, width, height)?;
                layers.push((layer, sums));
                rest = after;
            }
            if !rest.is_empty() {
                return Err("pixel data does not match the image size");
            }
        }
        let head = Self {
            renderer_id,
            description,
            share: start..end,
            tile,
            image,
            spp_done,
            gamma,
            stats,
            film: Film::new(0, 0),
            active: None,
        };
        Ok(Unpacked {
            head,
            pixels,
            odd,
            layers,
        })
    }

    pub(super) fn decode_payload(payload: &[u8]) -> Result<Self, &'static str> {
        let u = Self::unpack(payload)?;
        let (sums, counts) = u.pixels.decode()?;
        let (w, h) = (u.head.tile.width(), u.head.tile.height());
        let mut film = Film::from_raw(w, h, sums, counts).ok_or("bad pixel data")?;
        for (layer, pixels) in &u.layers {
            let (sums, layer_counts) = pixels.decode()?;
            if layer_counts != film.raw().1 {
                return Err("bad pixel data of a feature layer");
            }
            // Another version's layers may be held otherwise: say so,
            // rather than that the data is bad.
            let why = match u.head.renderer_id == super::RENDERER_ID {
                true => "bad pixel data",
                false => "feature layers written by another version of lumen",
            };
            film = film.with_layer(*layer, sums).ok_or(why)?;
        }
        let (film, active) = match u.odd {
            None => (film, None),
            Some((odd, flags)) => {
                let (odd_sums, odd_counts) = odd.decode()?;
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
        };
        Ok(Self {
            film,
            active,
            ..u.head
        })
    }
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
