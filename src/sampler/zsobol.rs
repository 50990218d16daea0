//! Sobol points shared by the whole image, the pixels in Morton order
//! (after pbrt-v4's `ZSobolSampler`; Ahmed and Wonka 2020, "Screen-Space
//! Blue-Noise Diffusion of Monte Carlo Sampling Error via Hierarchical
//! Ordering of Pixels").
//!
//! The `sobol` sampler gives every pixel a sequence of its own: the samples
//! of one pixel are well spread, but its error is unrelated to its
//! neighbours', so the noise is white. Here every dimension has one Sobol
//! sequence for the whole image, and pixel `(x, y)` takes the block of 2^k
//! indices (2^k ≥ spp) that starts at its Morton code times 2^k: the
//! interleaved bits of x and y, so that each aligned square of 2^j × 2^j
//! pixels owns an aligned block of 2^(2j + k) indices.
//!
//! The draws are [`super::sobol`]'s: the index shuffled by a nested uniform
//! scramble (which maps aligned blocks onto aligned blocks) and the point
//! Owen-scrambled, with seeds per dimension, now the same for every pixel.
//! So a pixel's samples are still a (0, k, 2)-net in the two coordinates
//! of each 2-D draw, randomly scrambled, with the variance of `sobol`'s;
//! and a
//! square of 2 × 2 pixels holds together a (0, k + 2, 2)-net, 4 × 4 pixels
//! a (0, k + 4, 2)-net, and so on: where one pixel's samples leave a gap, a
//! neighbour's fill it, their errors cancel, and the image's error is left
//! at high frequencies (blue noise), which the eye forgives and a filter or
//! denoiser removes.
//!
//! The points are 32-bit, so the structure spans 2^32 indices: an image
//! whose Morton codes times 2^k need more bits is cut into squares that
//! fit, each scrambled by a seed of its own.
//!
//! The scramble of the index decides which pixel of a pair gets which half
//! of their block. Bit by bit (as [`super::sobol`] scrambles) that is
//! decided for y before x in every square, the same way everywhere: a
//! pixel's partner at the finest level is always its horizontal neighbour.
//! That tied a pixel's error to that neighbour's more than to the vertical
//! one's (correlations −0.176 ± 0.030 across and −0.125 ± 0.021 down on the
//! tests' integrand, 16 images) and made the pattern vary from image to
//! image; so the pixel's coordinates are first swapped at each level of
//! the Morton order with probability 1/2, by a hash of the square above it
//! (−0.144 ± 0.009 and −0.148 ± 0.009; pbrt-v4 permutes each base-4 digit
//! for the same reason).

use super::sobol::owen_scramble;
use crate::rng::mix64;

/// ⌈log₂ spp⌉: the bits of a sample's index within its pixel.
#[inline]
pub fn sample_bits(spp: u32) -> u32 {
    32 - (spp.max(1) - 1).leading_zeros()
}

/// The bits of a sample's index within its pixel's block: the low
/// [`sample_bits`] of them.
#[inline]
pub fn sample_mask(spp: u32) -> u32 {
    u32::MAX.checked_shr(32 - sample_bits(spp)).unwrap_or(0)
}

/// The Morton code of `(x, y)`: bit i of x at bit 2i, bit i of y at 2i + 1.
#[inline]
pub fn morton(x: u32, y: u32) -> u64 {
    spread(x) | spread(y) << 1
}

/// The bits of `v` at the even positions of a 64-bit word.
#[inline]
fn spread(v: u32) -> u64 {
    let mut v = u64::from(v);
    v = (v | v << 16) & 0x0000_ffff_0000_ffff;
    v = (v | v << 8) & 0x00ff_00ff_00ff_00ff;
    v = (v | v << 4) & 0x0f0f_0f0f_0f0f_0f0f;
    v = (v | v << 2) & 0x3333_3333_3333_3333;
    (v | v << 1) & 0x5555_5555_5555_5555
}

/// The Morton code of `(x, y)` with the two bits of each level swapped or
/// not, by a hash (keyed by `seed`) of the levels above it: a random one of
/// the two orders of the pixels of each square, which makes the blue noise
/// isotropic.
///
/// One Owen scramble of the code decides every level at once: the flip it
/// gives a bit depends only on the bits above, so the flip of each level's
/// upper bit is a coin tossed by the squares that hold it. Levels 16 and up
/// (coordinates of 65,536 and more) keep their order.
#[inline]
pub fn shuffled_morton(x: u32, y: u32, seed: u32) -> u64 {
    let code = morton(x, y);
    let low = code as u32;
    let flips = u64::from(owen_scramble(low, seed) ^ low);
    // At each level's lower (x) bit: whether to swap, and whether the two
    // bits differ (else swapping changes nothing).
    let swap = (flips >> 1) & 0x5555_5555;
    let differ = (code ^ code >> 1) & 0x5555_5555_5555_5555;
    let m = swap & differ;
    code ^ m ^ m << 1
}

/// The scrambling seed of a pixel's draws and the index of its sample 0 in
/// the image's Sobol sequence, for pixel `(x, y)` of a render of `spp`
/// samples per pixel with seed `seed`.
#[inline]
pub fn pixel_start(seed: u64, (x, y): (u32, u32), spp: u32) -> (u64, u32) {
    let image_seed = mix64(seed ^ 0x5a53_4f42_4f4c);
    let index = u128::from(shuffled_morton(x, y, image_seed as u32)) << sample_bits(spp);
    // The square of 2^32 indices the pixel is in has its own seed (the
    // index has at most 64 + 32 bits).
    let square = (index >> 32) as u64;
    let key = mix64(image_seed ^ square);
    (key, index as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_interleave_the_coordinates() {
        assert_eq!(morton(0, 0), 0);
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(3, 3), 15);
        assert_eq!(morton(u32::MAX, 0), 0x5555_5555_5555_5555);
        assert_eq!(morton(0, u32::MAX), 0xaaaa_aaaa_aaaa_aaaa);
        for (x, y) in [(5u32, 9u32), (1000, 77), (65_535, 1)] {
            let code = morton(x, y);
            let (mut bx, mut by) = (0, 0);
            for i in 0..32 {
                bx |= ((code >> (2 * i)) & 1) << i;
                by |= ((code >> (2 * i + 1)) & 1) << i;
            }
            assert_eq!((bx as u32, by as u32), (x, y));
        }
    }

    #[test]
    fn shuffled_codes_keep_every_square_together() {
        // Over a 64 × 64 image: a bijection onto 0..4096, and each aligned
        // 2^j × 2^j square gets an aligned block of 4^j codes.
        let seed = 0x1234_5678;
        let mut seen = vec![false; 4096];
        for j in 0..=6u32 {
            let side = 1u32 << j;
            for sy in (0..64).step_by(side as usize) {
                for sx in (0..64).step_by(side as usize) {
                    let block = shuffled_morton(sx, sy, seed) >> (2 * j);
                    for y in sy..sy + side {
                        for x in sx..sx + side {
                            assert_eq!(shuffled_morton(x, y, seed) >> (2 * j), block);
                        }
                    }
                }
            }
        }
        for y in 0..64 {
            for x in 0..64 {
                let c = shuffled_morton(x, y, seed) as usize;
                assert!(!std::mem::replace(&mut seen[c], true), "({x}, {y})");
            }
        }
        // Both orders occur at the finest level.
        let swapped = (0..32u32)
            .filter(|&i| shuffled_morton(2 * i, 1, seed) & 3 == 1)
            .count();
        assert!(
            (4..=28).contains(&swapped),
            "{swapped} of 32 squares swapped"
        );
    }

    #[test]
    fn a_pixels_samples_are_its_own_block() {
        for spp in [1u32, 2, 3, 16, 37, 64] {
            let k = sample_bits(spp);
            assert!(spp <= 1 << k && (k == 0 || spp > 1 << (k - 1)));
            let mut firsts: Vec<u32> = (0..16)
                .flat_map(|y| (0..16).map(move |x| pixel_start(3, (x, y), spp).1))
                .collect();
            assert!(firsts.iter().all(|f| f % (1 << k) == 0));
            firsts.sort_unstable();
            firsts.dedup();
            assert_eq!(firsts.len(), 256, "spp {spp}");
        }
    }

    #[test]
    fn sample_bits_cover_every_sample_count() {
        for (spp, k) in [(1, 0), (2, 1), (3, 2), (4, 2), (5, 3), (1 << 31, 31)] {
            assert_eq!(sample_bits(spp), k, "{spp}");
            assert_eq!(sample_mask(spp), ((1u64 << k) - 1) as u32, "{spp}");
        }
        for spp in [(1 << 31) + 1, u32::MAX] {
            assert_eq!((sample_bits(spp), sample_mask(spp)), (32, u32::MAX));
        }
    }

    #[test]
    fn pixels_far_apart_in_a_huge_image_draw_different_samples() {
        // 2^17 pixels wide at 2^20 spp: 54 bits of index, so pixels share
        // a key only within a square of 2^32 indices, where their blocks
        // differ.
        let spp = 1 << 20;
        let mut seen = std::collections::HashSet::new();
        for y in [0u32, 1, 77, 65_535, 65_536, 131_071] {
            for x in [0u32, 1, 4_096, 65_535, 65_536, 131_071] {
                assert!(seen.insert(pixel_start(9, (x, y), spp)), "({x}, {y})");
            }
        }
    }

    #[test]
    fn large_images_get_a_seed_per_square_of_indices() {
        // 2^16 × 2^16 pixels at 4 spp need 34 bits: pixels in different
        // squares of 2^32 indices have different keys, pixels in one the same.
        let (a, _) = pixel_start(1, (0, 0), 4);
        let (b, _) = pixel_start(1, (1, 1), 4);
        let (c, _) = pixel_start(1, (65_535, 65_535), 4);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
