//! A film's pixels in a checkpoint: every pixel's count as a `u32`, then
//! the sums, row by row, in a compact form.
//!
//! A sum is an `i128` in 64.64 fixed point ([`Sum`]), but few of its 128
//! bits carry anything: the integer part is small, and the fraction ends
//! where the least significant bit of the smallest sample added ends (a
//! sample near 0.5 ends at 2⁻²⁵, so the last 39 bits of its sum are zero).
//! Each pixel is stored as a shift (the fewest trailing zeros of its three
//! sums), a length L (in bytes, 0 to 16), and the three sums shifted right
//! and zigzag-encoded (so that small negative values are short too), L
//! bytes each, little-endian: about 20 bytes a pixel instead of 48. Each row
//! starts with its length in bytes, so rows can be found without being
//! decoded, and decoded in parallel straight into a film (`lumen merge`).

use crate::film::Sum;
use rayon::prelude::*;

/// Feeds the pixels of a film `width` pixels wide to `sink`, as
/// [`Pixels::split`] finds them: every count (`u32`), then the sums row by
/// row, each row after its byte length (`u32`). `sum(i)` is pixel `i`'s
/// sum (a layer kept otherwise than as [`Sum`]s is converted a pixel at a
/// time, taking no memory of the image's size).
pub(super) fn write_pixels(
    (sum, counts): (impl Fn(usize) -> Sum + Sync, &[u32]),
    width: usize,
    sink: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(4096 * 4);
    for chunk in counts.chunks(4096) {
        buf.clear();
        for c in chunk {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        sink(&buf)?;
    }
    // Rows are encoded on all threads (a checkpoint is saved between
    // passes, while they wait), a batch at a time to bound the memory.
    const BATCH_PIXELS: usize = 1 << 16;
    let width = width.max(1);
    let batch_rows = (BATCH_PIXELS / width).max(1);
    let n = counts.len();
    for batch in (0..n).step_by(width * batch_rows) {
        let end = (batch + width * batch_rows).min(n);
        let starts: Vec<usize> = (batch..end).step_by(width).collect();
        let rows: Vec<Vec<u8>> = starts
            .into_par_iter()
            .map(|start| {
                let row = start..(start + width).min(end);
                let mut out = Vec::with_capacity(row.len() * (2 + 3 * 16));
                for i in row {
                    put_sum(&mut out, &sum(i));
                }
                out
            })
            .collect();
        for row in rows {
            sink(&(row.len() as u32).to_le_bytes())?;
            sink(&row)?;
        }
    }
    Ok(())
}

/// Appends one pixel's sums: shift, length, and three values.
#[inline]
fn put_sum(out: &mut Vec<u8>, sum: &Sum) {
    let shift = match sum.0.iter().map(|v| v.trailing_zeros()).min() {
        Some(128) | None => 0,
        Some(tz) => tz,
    };
    let values = sum.0.map(|v| zigzag(v >> shift));
    let bits = values.iter().map(|z| 128 - z.leading_zeros()).max();
    let len = bits.unwrap_or(0).div_ceil(8) as usize;
    // Each value's 16 bytes are appended whole and cut to length: a copy
    // of a variable length would be a library call, slower than the
    // encoding.
    out.extend_from_slice(&[shift as u8, len as u8]);
    for z in values {
        out.extend_from_slice(&z.to_le_bytes());
        out.truncate(out.len() - 16 + len);
    }
}

/// `v` as an unsigned number whose size follows `|v|`: 0, −1, 1, −2, … ↦
/// 0, 1, 2, 3, …
fn zigzag(v: i128) -> u128 {
    (v.wrapping_shl(1) ^ (v >> 127)) as u128
}

/// The inverse of [`zigzag`].
fn unzigzag(z: u128) -> i128 {
    ((z >> 1) as i128) ^ -((z & 1) as i128)
}

/// The pixel data of a `width`×`height` film in a payload, found but not
/// decoded.
pub(crate) struct Pixels<'a> {
    width: usize,
    /// Every pixel's count, `u32` little-endian.
    counts: &'a [u8],
    /// Every row's sums.
    rows: Vec<&'a [u8]>,
}

/// What is wrong with a row's pixels.
pub(crate) enum PixelError {
    /// The bytes are not pixel data.
    Malformed(&'static str),
    /// Pixel `x` of the row holds a count or sum it cannot have.
    Pixel {
        /// Its column in the film.
        x: usize,
        /// What is wrong (following "pixel (x, y) ").
        message: String,
    },
}

impl<'a> Pixels<'a> {
    /// Finds the pixel data of a `width`×`height` film at the front of
    /// `bytes`; returns it and the bytes after it.
    pub(super) fn split(
        bytes: &'a [u8],
        width: u32,
        height: u32,
    ) -> Result<(Self, &'a [u8]), &'static str> {
        const SHORT: &str = "pixel data does not match the image size";
        let n = u64::from(width) * u64::from(height);
        let count_len = n.checked_mul(4).filter(|&l| l <= bytes.len() as u64);
        let (counts, mut rest) = bytes.split_at(count_len.ok_or(SHORT)? as usize);
        // A row takes at least 2 bytes a pixel: don't trust `height` for
        // the allocation.
        let mut rows = Vec::with_capacity((height as usize).min(rest.len() / 4));
        for _ in 0..height {
            if rest.len() < 4 {
                return Err(SHORT);
            }
            let (len, after) = rest.split_at(4);
            let len = u32::from_le_bytes(len.try_into().expect("4 bytes")) as usize;
            if after.len() < len {
                return Err(SHORT);
            }
            let (row, after) = after.split_at(len);
            rows.push(row);
            rest = after;
        }
        let pixels = Pixels {
            width: width as usize,
            counts,
            rows,
        };
        Ok((pixels, rest))
    }

    /// Adds every row to `rows` (its sums and counts, a row of this film
    /// each, top first), in parallel, and returns the samples they count.
    /// With `most`, every pixel is checked first: at most `most` samples,
    /// and a sum of zero without samples. The error is the first in reading
    /// order, with its row, whichever thread found it.
    pub(crate) fn add_rows<'r>(
        &self,
        rows: impl IndexedParallelIterator<Item = (&'r mut [Sum], &'r mut [u32])>,
        most: Option<u32>,
    ) -> Result<u64, (usize, PixelError)> {
        let counted: Vec<Result<u64, PixelError>> = rows
            .enumerate()
            .map(|(y, (sums, counts))| self.add_row(y, sums, counts, most))
            .collect();
        counted
            .into_iter()
            .enumerate()
            .map(|(y, row)| row.map_err(|e| (y, e)))
            .sum()
    }

    /// Adds the pixels of row `y` to `sums` and `counts` (the row's width
    /// long) and returns the samples they count, checking them against
    /// `most` as [`Pixels::add_rows`] does.
    fn add_row(
        &self,
        y: usize,
        sums: &mut [Sum],
        counts: &mut [u32],
        most: Option<u32>,
    ) -> Result<u64, PixelError> {
        const BAD: PixelError = PixelError::Malformed("bad pixel data");
        let w = self.width;
        let count_bytes = &self.counts[y * w * 4..(y + 1) * w * 4];
        let row = self.rows[y];
        let mut at = 0;
        let mut counted = 0;
        for (x, (c, (sum_out, count_out))) in count_bytes
            .chunks_exact(4)
            .zip(sums.iter_mut().zip(counts.iter_mut()))
            .enumerate()
        {
            let count = u32::from_le_bytes(c.try_into().expect("4 bytes"));
            let [shift, len] = *row.get(at..at + 2).ok_or(BAD)? else {
                return Err(BAD);
            };
            let (shift, len) = (u32::from(shift), usize::from(len));
            if shift > 127 || len > 16 || row.len() < at + 2 + 3 * len {
                return Err(BAD);
            }
            at += 2;
            let mut sum = Sum::ZERO;
            for v in &mut sum.0 {
                *v = unzigzag(read_le(row, at, len)).wrapping_shl(shift);
                at += len;
            }
            if let Some(most) = most {
                super::consistency::check_pixel(&sum, count, most, "")
                    .map_err(|message| PixelError::Pixel { x, message })?;
            }
            // Parts whose sums together pass what a pixel holds are refused
            // rather than wrapped into a wrong (often negative) pixel.
            let (Some(total), Some(n)) = (sum_out.checked_plus(sum), count_out.checked_add(count))
            else {
                return Err(PixelError::Pixel {
                    x,
                    message: "would pass what a pixel's sum holds (about 9.2e18 a channel) \
                              once added to the parts before it"
                        .into(),
                });
            };
            *sum_out = total;
            *count_out = n;
            counted += u64::from(count);
        }
        if at != row.len() {
            return Err(PixelError::Malformed("bad pixel data (a row is too long)"));
        }
        Ok(counted)
    }

    /// Every pixel's count, row by row.
    pub(crate) fn counts(&self) -> impl Iterator<Item = u32> + '_ {
        (self.counts.chunks_exact(4)).map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
    }

    /// The sums and counts, decoded into new vectors (rows in parallel).
    pub(super) fn decode(&self) -> Result<(Vec<Sum>, Vec<u32>), &'static str> {
        let n = self.width * self.rows.len();
        let (mut sums, mut counts) = (vec![Sum::ZERO; n], vec![0u32; n]);
        if n > 0 {
            let rows = (sums.par_chunks_mut(self.width)).zip(counts.par_chunks_mut(self.width));
            // Unchecked, so no pixel error: the caller checks the film.
            self.add_rows(rows, None).map_err(|(_, e)| match e {
                PixelError::Malformed(m) => m,
                PixelError::Pixel { .. } => "bad pixel data",
            })?;
        }
        Ok((sums, counts))
    }
}

/// The `len` bytes of `row` from `at`, little-endian (`len` ≤ 16, and
/// within the row).
#[inline(always)]
fn read_le(row: &[u8], at: usize, len: usize) -> u128 {
    match row.get(at..at + 16) {
        // Sixteen bytes at hand: one load, masked.
        Some(b) => {
            let v = u128::from_le_bytes(b.try_into().expect("16 bytes"));
            if len == 16 {
                v
            } else {
                v & ((1u128 << (8 * len)) - 1)
            }
        }
        None => {
            let mut b = [0u8; 16];
            b[..len].copy_from_slice(&row[at..at + len]);
            u128::from_le_bytes(b)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_is_a_bijection_at_the_edges() {
        for v in [
            0,
            1,
            -1,
            2,
            -2,
            i128::MAX,
            i128::MIN,
            i128::MAX - 1,
            1 << 100,
        ] {
            assert_eq!(unzigzag(zigzag(v)), v);
        }
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
    }

    #[test]
    fn sums_round_trip_and_are_compact() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut sums = vec![
            Sum::ZERO,
            Sum([i128::MAX, i128::MIN, -1]),
            Sum([1, 0, -(1 << 90)]),
        ];
        // Sums of 64 samples of 0..1 as f32s: the usual case.
        for _ in 0..997 {
            let mut s = Sum::ZERO;
            for _ in 0..64 {
                let v = (next() >> 40) as f32 / (1u64 << 24) as f32;
                s = s.plus(Sum::of([f64::from(v); 3]).unwrap());
            }
            sums.push(s);
        }
        let width = 20;
        let mut bytes = Vec::new();
        write_pixels((|i| sums[i], &vec![7; sums.len()]), width, &mut |b| {
            bytes.extend_from_slice(b);
            Ok(())
        })
        .unwrap();
        bytes.push(42);
        let (pixels, rest) = Pixels::split(&bytes, width as u32, 50).unwrap();
        assert_eq!(rest, [42]);
        let (decoded, counts) = pixels.decode().unwrap_or_else(|m| panic!("{m}"));
        assert_eq!(decoded, sums);
        assert!(counts.iter().all(|&c| c == 7));
        // Counts and sums of those 1,000 pixels: well under 48 + 4 bytes.
        let per_pixel = bytes.len() as f64 / sums.len() as f64;
        assert!(per_pixel < 22.0, "{per_pixel} bytes a pixel");
        // A row cut short, or a length beyond 16, is refused.
        let mut bad = bytes.clone();
        let first_row = 4 * sums.len() + 4;
        bad[first_row + 1] = 17;
        let (pixels, _) = Pixels::split(&bad, width as u32, 50).unwrap();
        assert!(pixels.decode().is_err());
        assert!(Pixels::split(&bytes[..bytes.len() - 2], width as u32, 50).is_err());
    }
}
