//! A small, fast, seedable random number generator.
//!
//! Every camera sample owns a generator seeded from `(scene seed, pixel, sample
//! index)`, so an image does not depend on how work is split among threads or
//! passes: this is what makes renders bit-identical across thread counts and
//! resumable.

/// PCG-XSH-RR 64/32 (O'Neill, 2014): 64 bits of state, 32-bit outputs.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

const PCG_MULTIPLIER: u64 = 6364136223846793005;
const PCG_INCREMENT: u64 = 1442695040888963407;

/// SplitMix64 finaliser: a bijective mix that spreads nearby inputs apart.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A number in [0, 1) made from `values` alone: the same for the same
/// values whatever the thread or the order of the work, and spread evenly
/// over [0, 1) as they change (for choices made where a hit is, such as a
/// cut-out surface stopping a ray or a mix picking a material).
#[inline]
pub fn unit_hash<const N: usize>(values: [f32; N]) -> f32 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for x in values {
        h = (h ^ u64::from(x.to_bits())).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h ^= h >> 31;
    }
    // The top 24 bits: every such fraction is exact in an f32.
    (h >> 40) as f32 / (1u64 << 24) as f32
}

impl Rng {
    /// A generator whose sequence is fixed by `seed`.
    pub fn new(seed: u64) -> Self {
        let mut rng = Self {
            state: mix64(seed).wrapping_add(PCG_INCREMENT),
        };
        rng.next_u32();
        rng
    }

    /// The generator for one camera sample: independent of every other sample
    /// of the image, and of the order in which samples are taken.
    ///
    /// `pixel` and `sample` must be below 2³² (images are far smaller), so
    /// that `pixel · 2³² + sample` names the sample uniquely; the bijective
    /// [`mix64`] of that name, keyed by the mixed seed, starts its sequence.
    /// Two finalisers per sample, not five: seeding is a noticeable part of a
    /// camera sample's cost. (`mix64(seed)` is the same for every sample, so
    /// the optimiser can hoist it out of the render loop once this is inlined.)
    #[inline]
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        debug_assert!(pixel < 1 << 32 && sample < 1 << 32);
        Self {
            state: mix64(mix64(seed) ^ (pixel << 32 | sample)),
        }
    }

    /// A generator to be overwritten before use (filling arrays).
    pub const fn placeholder() -> Self {
        Self { state: 0 }
    }

    /// The next 32 uniformly distributed bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG_MULTIPLIER).wrapping_add(PCG_INCREMENT);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// A uniform `f32` in `[0, 1)`, with 24 bits of precision.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniform `f32`s in `[0, 1)`, in the order drawn.
    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        let u = self.next_f32();
        [u, self.next_f32()]
    }

    /// A uniform `f32` in `[min, max)`.
    #[inline]
    pub fn range_f32(&mut self, min: f32, max: f32) -> f32 {
        min + (max - min) * self.next_f32()
    }

    /// A uniform `f64` in `[0, 1)`, with 53 bits of precision.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        let hi = u64::from(self.next_u32()) << 21;
        let lo = u64::from(self.next_u32() >> 11);
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_sequence_and_different_seeds_differ() {
        let a: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::new(7), |r, _| Some(r.next_u32()))
            .collect();
        let b: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::new(7), |r, _| Some(r.next_u32()))
            .collect();
        let c: Vec<u32> = (0..8)
            .map(|_| 0)
            .scan(Rng::new(8), |r, _| Some(r.next_u32()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn uniform_floats_have_the_right_mean_and_range() {
        // Mean of U[0,1) is 1/2 with variance 1/12; allow 5 standard errors.
        let n = 200_000;
        let mut rng = Rng::new(42);
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = rng.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += f64::from(x);
        }
        let tolerance = 5.0 * (1.0f64 / 12.0 / n as f64).sqrt();
        assert!((sum / n as f64 - 0.5).abs() < tolerance);
    }
}
