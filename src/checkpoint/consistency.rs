//! A checkpoint's content checked against itself: the checksum only says
//! that the bytes are those that were written, not that the writer was
//! lumen, nor that it was right. A checkpoint whose counts, sums and flags
//! do not agree would silently change the image (a pixel with no samples
//! shows black, a NaN sum spreads), so it is refused on reading.

use super::Checkpoint;
use crate::film::Sum;

impl Checkpoint {
    /// Checks what a checkpoint can be checked against on its own: it holds
    /// samples; every pixel's count is at most the samples per pixel done;
    /// every sum is finite, and zero where there is no sample; the sample
    /// counts add up; the halves of an adaptive film fit in the whole.
    /// Whether it fits the render (size, pass schedule) is checked when it
    /// is resumed ([`crate::progressive::Session::restore`]).
    pub(crate) fn check_consistency(&self) -> Result<(), String> {
        let (w, h) = (self.film.width(), self.film.height());
        let done = self.check_fields(w, h)?;
        // Named by their place in the image.
        let (x0, y0) = (self.tile.x0 as usize, self.tile.y0 as usize);
        let at = |i: usize| {
            let (x, y) = (x0 + i % w as usize, y0 + i / w as usize);
            format!("pixel ({x}, {y})")
        };
        let (sums, counts) = self.film.raw();
        check_pixels(sums, counts, done, &at, "")?;
        let counted: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        self.check_counted(counted, done)?;
        let Some(active) = &self.active else {
            return Ok(());
        };
        let s = self.stats;
        let pixels = self.film.len() as u64;
        let most = pixels * u64::from(done);
        if s.samples > most {
            return Err(format!(
                "it counts {} samples, more than {pixels} pixels at {done} spp",
                s.samples
            ));
        }
        if done < crate::adaptive::MIN_SAMPLES && active.iter().any(|a| !a) {
            return Err(format!(
                "pixels stopped sampling before {} spp",
                crate::adaptive::MIN_SAMPLES
            ));
        }
        // A pixel still sampling took every sample so far: what its
        // count lacks was dropped.
        let lacking: u64 = counts
            .iter()
            .zip(active)
            .filter(|(_, &on)| on)
            .map(|(&c, _)| u64::from(done - c))
            .sum();
        if lacking > s.dropped {
            return Err(format!(
                "its pixels still sampling lack {lacking} of their {done} samples, but only {} were dropped",
                s.dropped
            ));
        }
        // Samples 0..done hold done / 2 of odd index.
        let (odd_sums, odd_counts) = self.film.raw_odd();
        check_pixels(odd_sums, odd_counts, done / 2, &at, " of odd index")?;
        match counts
            .iter()
            .zip(odd_counts)
            .position(|(c, o)| c - o > done - done / 2)
        {
            Some(i) => Err(format!(
                "{} has more samples of even index than {done} spp hold",
                at(i)
            )),
            None => Ok(()),
        }
    }

    /// The checks of [`Checkpoint::check_consistency`] that need no pixel,
    /// for a film of `w`×`h` pixels; returns the samples per pixel the
    /// checkpoint holds.
    pub(crate) fn check_fields(&self, w: u32, h: u32) -> Result<u32, String> {
        if w == 0 || h == 0 {
            return Err(format!("its film is {w}x{h} pixels"));
        }
        let (iw, ih) = self.image;
        if (self.tile.width(), self.tile.height()) != (w, h) {
            return Err(format!(
                "its film is {w}x{h} pixels, its tile {} {}x{}",
                self.tile,
                self.tile.width(),
                self.tile.height()
            ));
        }
        self.tile.check_within(iw, ih)?;
        if !(self.gamma > 0.0 && self.gamma.is_finite()) {
            return Err(format!("its display gamma is {}", self.gamma));
        }
        let share = &self.share;
        if share.start > share.end || !share.contains(&self.spp_done) && self.spp_done != share.end
        {
            return Err(format!(
                "it holds samples up to {}, outside its share {}..{}",
                self.spp_done, share.start, share.end
            ));
        }
        // Samples per pixel held; none only in a part whose share is empty
        // (more parts than samples per pixel).
        let done = self.spp_done - share.start;
        if done == 0 && !share.is_empty() {
            return Err("it holds no samples (0 spp done)".into());
        }
        if self.active.is_some() && share.start != 0 {
            return Err(
                "it samples adaptively, but holds a share of the samples not starting at 0".into(),
            );
        }
        Ok(done)
    }

    /// Checks that the `counted` samples of its pixels (`done` spp at
    /// most) agree with the statistics: samples taken less those dropped,
    /// and, without adaptive sampling, every pixel's samples.
    pub(crate) fn check_counted(&self, counted: u64, done: u32) -> Result<(), String> {
        let s = self.stats;
        if s.dropped > s.samples || counted != s.samples - s.dropped {
            return Err(format!(
                "its pixels hold {counted} samples, but it counts {} taken and {} dropped",
                s.samples, s.dropped
            ));
        }
        let pixels = self.tile.area();
        let most = pixels * u64::from(done);
        if self.active.is_none() && s.samples != most {
            return Err(format!(
                "it counts {} samples, but {pixels} pixels at {done} spp are {most}",
                s.samples
            ));
        }
        Ok(())
    }
}

/// Checks one set of per-pixel sums and counts: counts at most `most`, and
/// sums zero where the count is.
fn check_pixels(
    sums: &[Sum],
    counts: &[u32],
    most: u32,
    at: &dyn Fn(usize) -> String,
    which: &str,
) -> Result<(), String> {
    for (i, (sum, &count)) in sums.iter().zip(counts).enumerate() {
        check_pixel(sum, count, most, which).map_err(|e| format!("{} {e}", at(i)))?;
    }
    Ok(())
}

/// Checks one pixel's sum and count: at most `most` samples, and a sum of
/// zero without samples. The error follows the pixel's name.
pub(super) fn check_pixel(sum: &Sum, count: u32, most: u32, which: &str) -> Result<(), String> {
    if count > most {
        return Err(format!(
            "has {count} samples{which}, more than the {most} its spp allow"
        ));
    }
    if count == 0 && *sum != Sum::ZERO {
        return Err(format!("has no samples{which} but a sum that is not zero"));
    }
    Ok(())
}
