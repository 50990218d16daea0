//! The film: where samples accumulate, and how the accumulated light becomes
//! displayable pixels.

use crate::math::Color;

/// Linear accumulation of samples for every pixel.
///
/// Sums are kept in `f64` so that adding hundreds of samples loses nothing,
/// and always in sample order, so an image is the same however the samples
/// were split into passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Sum of the finite samples of each pixel, row-major, top row first.
    sums: Vec<[f64; 3]>,
    /// Number of finite samples in each pixel.
    counts: Vec<u32>,
}

impl Film {
    /// A black film of `width`×`height` pixels with no samples.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            sums: vec![[0.0; 3]; n],
            counts: vec![0; n],
        }
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Mutable access to the rows, for parallel rendering: each item is one
    /// row's sums and counts.
    pub fn rows_mut(
        &mut self,
    ) -> impl rayon::iter::IndexedParallelIterator<Item = (&mut [[f64; 3]], &mut [u32])> {
        use rayon::prelude::*;
        let w = self.width as usize;
        self.sums
            .par_chunks_mut(w)
            .zip(self.counts.par_chunks_mut(w))
    }

    /// Makes this film a copy of `other` (of the same size) without
    /// allocating: a pass keeps the film it started from this way.
    pub fn copy_from(&mut self, other: &Film) {
        self.width = other.width;
        self.height = other.height;
        self.sums.clone_from(&other.sums);
        self.counts.clone_from(&other.counts);
    }

    /// The raw per-pixel sums and counts (for checkpoints).
    pub fn raw(&self) -> (&[[f64; 3]], &[u32]) {
        (&self.sums, &self.counts)
    }

    /// Rebuilds a film from raw sums and counts; `None` if the sizes disagree.
    pub fn from_raw(
        width: u32,
        height: u32,
        sums: Vec<[f64; 3]>,
        counts: Vec<u32>,
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        (sums.len() == n && counts.len() == n).then_some(Self {
            width,
            height,
            sums,
            counts,
        })
    }

    /// The mean linear colour of pixel `(x, y)`; black if it has no samples.
    pub fn pixel(&self, x: u32, y: u32) -> Color {
        let i = y as usize * self.width as usize + x as usize;
        mean(&self.sums[i], self.counts[i])
    }

    /// All pixels' mean linear colours, row-major, top row first.
    pub fn linear(&self) -> Vec<Color> {
        self.pixels().collect()
    }

    /// 8-bit bytes, three a pixel: ⌊256·clamp(v, 0, 0.999)⌋ of the display value.
    /// Computed pixel by pixel, with no full-size intermediate image.
    pub fn to_rgb8(&self, gamma: f32) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(self.sums.len() * 3);
        for c in self.pixels() {
            for v in [c.x, c.y, c.z] {
                bytes.push((256.0 * to_display(v, gamma).clamp(0.0, 0.999)) as u8);
            }
        }
        bytes
    }

    /// The mean linear colour of every pixel, row-major, top row first.
    pub fn pixels(&self) -> impl Iterator<Item = Color> + '_ {
        self.sums.iter().zip(&self.counts).map(|(s, &n)| mean(s, n))
    }
}

/// The mean of `n` samples summing to `sum`; black if there are none.
#[inline]
fn mean(sum: &[f64; 3], n: u32) -> Color {
    if n == 0 {
        return Color::ZERO;
    }
    let n = f64::from(n);
    Color::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

/// Applies the display gamma (v^(1/γ)) and tone-maps by clamping to [0, 1].
#[inline]
pub fn to_display(linear: f32, gamma: f32) -> f32 {
    let v = linear.max(0.0);
    // Gamma 2 (the notes' choice, and the default) is a square root: exact,
    // and several times cheaper than `powf` when saving large images.
    let v = if gamma == 1.0 {
        v
    } else if gamma == 2.0 {
        v.sqrt()
    } else {
        v.powf(1.0 / gamma)
    };
    v.clamp(0.0, 1.0)
}
