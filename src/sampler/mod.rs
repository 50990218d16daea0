//! Samplers: where every random decision of a path gets its number.
//!
//! A path draws its uniform numbers through the [`Sampler`] trait, naming
//! what each is for (a [`Dim`]): the position in the pixel, the point on the
//! lens, and at every bounce the material's 2-D sample, its 1-D choice and
//! room for the light to be sampled. Naming the dimensions lets a
//! low-discrepancy sampler give the same bounce's same decision the same
//! sequence in every sample of a pixel, which is what spreads those samples
//! evenly.
//!
//! A render takes one [`PixelSample`] per camera sample, addressed by (render
//! seed, pixel, sample index, and for `stratified` and `zsobol` the render's
//! samples per pixel): whatever the thread count, however the samples are
//! split into passes, runs, tiles or parts, a sample draws exactly the same
//! numbers.
//! The kinds ([`SamplerKind`]):
//!
//! - `independent`: a PCG stream per sample (see [`crate::rng`]); the
//!   dimension names are ignored and numbers are drawn in call order.
//! - `stratified`: independent, except the position in the pixel, which is
//!   one per cell of a √N×√N grid (see [`stratum`]).
//! - `center`: independent, with every sample through the pixel's centre.
//! - `sobol`: Owen-scrambled Sobol points (see [`sobol`]), scrambled
//!   afresh for every pixel and dimension.
//! - `zsobol`: the same points, but each pixel's samples are a block of one
//!   sequence shared by the whole image, the pixels taken in Morton (Z)
//!   order (see [`zsobol`]): neighbouring pixels' samples fill each other's
//!   gaps, so their errors cancel and what is left of the noise is
//!   spread as blue noise, at the same cost and variance per pixel.
//!
//! A plain [`Rng`] is a sampler too (an independent one), for tests and
//! tools that need random directions outside a render.

pub mod sobol;
pub mod zsobol;

use crate::rng::{mix64, Rng};
pub use crate::scene::Sampling as SamplerKind;

/// What a number drawn from a [`Sampler`] is used for.
///
/// The camera's dimensions are drawn once per sample; the others once per
/// bounce, after [`Sampler::start_bounce`]. A dimension drawn again within
/// the same bounce (a rejection loop trying again) gets fresh numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    /// The position in the pixel (2-D).
    Pixel,
    /// The point on the lens (2-D).
    Lens,
    /// The time within the shutter interval (1-D).
    Time,
    /// The material's scattering direction (2-D).
    Bsdf,
    /// A third coordinate for materials sampled in three dimensions (1-D).
    BsdfExtra,
    /// The material's discrete choice: reflect or refract, absorb or go on (1-D).
    BsdfChoice,
    /// Which light to sample (1-D).
    LightChoice,
    /// The point on the chosen light (2-D).
    Light,
    /// Whether Russian roulette ends the path (1-D).
    Roulette,
    /// How far a ray gets into a medium (1-D).
    Medium,
}

/// Slots of one bounce (or of the camera) that are named by a [`Dim`]; a
/// dimension drawn again goes to slots past these.
const NAMED_SLOTS: u32 = 8;

impl Dim {
    /// The dimension's slot within its bounce (or within the camera's dimensions).
    fn slot(self) -> u32 {
        match self {
            Dim::Pixel | Dim::Bsdf => 0,
            Dim::Lens | Dim::BsdfExtra => 1,
            Dim::Time | Dim::BsdfChoice => 2,
            Dim::LightChoice => 3,
            Dim::Light => 4,
            Dim::Roulette => 5,
            Dim::Medium => 6,
        }
    }
}

/// A source of uniform numbers in [0, 1) for one path.
pub trait Sampler {
    /// A number for `dim`.
    fn get_1d(&mut self, dim: Dim) -> f32;
    /// Two numbers for `dim`, which together are well spread over [0, 1)².
    fn get_2d(&mut self, dim: Dim) -> [f32; 2];
    /// A uniform integer below `n` (> 0) for `dim`.
    fn get_below(&mut self, dim: Dim, n: u32) -> u32 {
        below(self.get_1d(dim), n)
    }
    /// Marks the start of bounce `bounce` (0 at the first surface a camera
    /// ray meets): the dimensions drawn next are that bounce's. Marking the
    /// same bounce again changes nothing.
    fn start_bounce(&mut self, bounce: u32);
}

/// `u` in [0, 1) scaled to an integer below `n`.
#[inline(always)]
fn below(u: f32, n: u32) -> u32 {
    ((u * n as f32) as u32).min(n - 1)
}

/// A generator is an independent sampler: numbers in call order.
impl Sampler for Rng {
    #[inline(always)]
    fn get_1d(&mut self, _: Dim) -> f32 {
        self.next_f32()
    }

    #[inline(always)]
    fn get_2d(&mut self, _: Dim) -> [f32; 2] {
        self.next_2d()
    }

    #[inline(always)]
    fn get_below(&mut self, _: Dim, n: u32) -> u32 {
        self.next_u32() % n
    }

    #[inline(always)]
    fn start_bounce(&mut self, _: u32) {}
}

/// The sampler of a render for one pixel: makes the [`PixelSample`] of each
/// of its sample indices.
#[derive(Clone, Copy, Debug)]
pub struct PixelSampler {
    kind: SamplerKind,
    seed: u64,
    pixel: u64,
    /// Samples per pixel of the render (for stratification).
    spp: u32,
    /// The pixel's stratum permutation key, or its scrambling seed.
    key: u64,
    /// The index its sample 0 has in the Sobol sequence it draws from: 0,
    /// except with `zsobol` (see [`zsobol::pixel_start`]).
    first: u32,
    /// The bits of a sample's index within that sequence's block for the
    /// pixel: all of them, except with `zsobol`.
    mask: u32,
}

impl PixelSampler {
    /// The sampler of pixel `(x, y)` of an image `width` pixels wide in a
    /// render of `spp` samples per pixel with seed `seed`.
    #[inline]
    pub fn new(kind: SamplerKind, seed: u64, (x, y): (u32, u32), width: u32, spp: u32) -> Self {
        let pixel = u64::from(y) * u64::from(width) + u64::from(x);
        let (key, first, mask) = match kind {
            SamplerKind::ZSobol => {
                let (key, first) = zsobol::pixel_start(seed, (x, y), spp);
                (key, first, zsobol::sample_mask(spp))
            }
            _ => (pixel_key(seed, pixel), 0, u32::MAX),
        };
        Self {
            kind,
            seed,
            pixel,
            spp,
            key,
            first,
            mask,
        }
    }

    /// The sampler of sample `index`, and its position in the pixel as an
    /// offset in [-0.5, 0.5)² from the pixel's centre (drawn first).
    #[inline(always)]
    pub fn start(&self, index: u32) -> (PixelSample, (f32, f32)) {
        let sobol = matches!(self.kind, SamplerKind::Sobol | SamplerKind::ZSobol);
        debug_assert!(index < self.spp.max(1), "sample {index} of {}", self.spp);
        let mut sample = PixelSample {
            rng: if sobol {
                Rng::placeholder()
            } else {
                Rng::for_sample(self.seed, self.pixel, u64::from(index))
            },
            sobol,
            key: self.key,
            // A zsobol pixel's samples are the block of 2^k indices from
            // `first` (spp ≤ 2^k), so `|` is `+`; the mask keeps a sample
            // past spp (which no caller draws) in its own pixel's block.
            // Kept bit-reversed, as the draws take it.
            reversed_index: (self.first | (index & self.mask)).reverse_bits(),
            bounce: 0,
            used: 0,
            again: 0,
        };
        let offset = match self.kind {
            SamplerKind::Center => (0.0, 0.0),
            SamplerKind::Independent => {
                let [jx, jy] = sample.rng.get_2d(Dim::Pixel);
                (jx - 0.5, jy - 0.5)
            }
            SamplerKind::Stratified => {
                let j = sample.rng.get_2d(Dim::Pixel);
                stratified_offset(index, self.spp, self.key, j)
            }
            SamplerKind::Sobol | SamplerKind::ZSobol => {
                let [jx, jy] = sample.get_2d(Dim::Pixel);
                (jx - 0.5, jy - 0.5)
            }
        };
        (sample, offset)
    }
}

/// The sampler of one camera sample of a render (see [`PixelSampler`]).
#[derive(Clone, Debug)]
pub struct PixelSample {
    /// The independent stream (not seeded for Sobol samples, which never
    /// draw from it).
    rng: Rng,
    sobol: bool,
    /// The pixel's scrambling seed (with `zsobol`, the image's).
    key: u64,
    /// The sample's index in its pixel's Sobol sequence, bit-reversed.
    reversed_index: u32,
    /// 0 for the camera's dimensions, 1 + b for bounce b's.
    bounce: u32,
    /// The named slots of the current bounce drawn so far (bit per slot).
    used: u32,
    /// Slots drawn again in the current bounce.
    again: u32,
}

impl PixelSample {
    /// A sample to be overwritten before use (filling arrays).
    pub const fn placeholder() -> Self {
        Self {
            rng: Rng::placeholder(),
            sobol: false,
            key: 0,
            reversed_index: 0,
            bounce: 0,
            used: 0,
            again: 0,
        }
    }

    /// The scrambling seed of the next Sobol draw for `dim`: one per
    /// (pixel, bounce, slot), the slot being `dim`'s the first time it is
    /// drawn in a bounce, and one past the named ones after that.
    #[inline(always)]
    fn dimension_seed(&mut self, dim: Dim) -> u64 {
        let slot = dim.slot();
        let slot = if self.used & (1 << slot) == 0 {
            self.used |= 1 << slot;
            slot
        } else {
            self.again += 1;
            NAMED_SLOTS + self.again
        };
        mix64(self.key ^ (u64::from(self.bounce) << 32 | u64::from(slot)))
    }
}

impl Sampler for PixelSample {
    #[inline(always)]
    fn get_1d(&mut self, dim: Dim) -> f32 {
        if self.sobol {
            let seed = self.dimension_seed(dim);
            sobol::to_unit(sobol::sample_1d(self.reversed_index, seed))
        } else {
            self.rng.get_1d(dim)
        }
    }

    #[inline(always)]
    fn get_2d(&mut self, dim: Dim) -> [f32; 2] {
        if self.sobol {
            let seed = self.dimension_seed(dim);
            sobol::sample_2d(self.reversed_index, seed).map(sobol::to_unit)
        } else {
            self.rng.get_2d(dim)
        }
    }

    #[inline(always)]
    fn get_below(&mut self, dim: Dim, n: u32) -> u32 {
        if self.sobol {
            below(self.get_1d(dim), n)
        } else {
            self.rng.get_below(dim, n)
        }
    }

    #[inline(always)]
    fn start_bounce(&mut self, bounce: u32) {
        // Started again for the same bounce (a path that passed through a
        // medium before meeting a surface), it keeps the slots drawn.
        if self.bounce != bounce + 1 {
            self.bounce = bounce + 1;
            self.used = 0;
            self.again = 0;
        }
    }
}

/// The offset in [-0.5, 0.5)² of stratified sample `index` of `spp`, given
/// its jitter `j` in [0, 1)²: the first k² samples (k = ⌊√spp⌋) fall one in
/// each cell of a k×k grid over the pixel, uniform within its cell; any
/// remaining samples are uniform over the pixel. Which cell a sample index
/// gets is a permutation drawn by `key` (see [`stratum`]), so that the
/// samples of an unfinished render (a pass, a stop) are spread over the
/// pixel rather than all in its first rows of cells.
#[inline]
pub fn stratified_offset(index: u32, spp: u32, key: u64, j: [f32; 2]) -> (f32, f32) {
    let [jx, jy] = j;
    let k = (spp as f64).sqrt() as u32;
    if index < k * k {
        let cell_index = stratum(index, k * k, key);
        let inv = 1.0 / k as f32;
        let (cx, cy) = ((cell_index % k) as f32, (cell_index / k) as f32);
        // In f32, (c + j)·(1/k) rounds to 1 when j is the largest value
        // below 1 in the last cell: keep it below 1 so the offset stays < 0.5.
        let below_one = 1.0 - f32::EPSILON / 2.0;
        let cell = |c: f32, j: f32| ((c + j) * inv).min(below_one) - 0.5;
        return (cell(cx, jx), cell(cy, jy));
    }
    (jx - 0.5, jy - 0.5)
}

/// The key of a pixel's stratum permutation (and of its Sobol scrambling),
/// from the render seed and the pixel index.
#[inline]
pub fn pixel_key(seed: u64, pixel: u64) -> u64 {
    mix64(seed ^ mix64(pixel ^ 0x5354_5241_5441))
}

/// The grid cell, in `0..cells`, of stratified sample `index < cells`: a
/// permutation of the indices chosen by `key`.
///
/// A keyed bijection of the `b`-bit integers (xor, multiplications by odd
/// constants and xor-shifts are each invertible modulo 2^b) is applied until
/// the value falls below `cells` ("cycle walking", which keeps it a
/// bijection of `0..cells`), then rotated by a keyed amount, so that for a
/// random key every index is equally likely to get every cell.
#[inline]
pub fn stratum(index: u32, cells: u32, key: u64) -> u32 {
    debug_assert!(index < cells);
    let mask = cells.next_power_of_two() - 1;
    let (k0, k1) = (key as u32, (key >> 32) as u32);
    let mut i = index;
    loop {
        i ^= k0 & mask;
        i = i.wrapping_mul(0x2C1B_3C6D) & mask;
        i ^= i >> 3;
        i = i.wrapping_add(k0 >> 16) & mask;
        i = i.wrapping_mul(0x297A_2D39) & mask;
        i ^= i >> 2;
        if i < cells {
            break;
        }
    }
    ((u64::from(i) + u64::from(k1)) % u64::from(cells)) as u32
}
