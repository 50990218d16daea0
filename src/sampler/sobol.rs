//! Owen-scrambled Sobol points, scrambled by hashing (Burley 2020,
//! "Practical Hash-based Owen Scrambling").
//!
//! The first two dimensions of the Sobol sequence form a (0, 2)-sequence in
//! base 2: every aligned block of 2^k consecutive points puts exactly one
//! point in each elementary interval of area 2^-k (each of the k + 1 grids
//! of 2^a × 2^(k−a) cells). Every request for numbers (a dimension of a
//! bounce, see [`super::Dim`]) takes those two dimensions afresh:
//!
//! 1. the sample index is shuffled by a nested uniform scramble keyed by the
//!    request's seed: a permutation of the indices that maps each aligned
//!    block of 2^k indices onto an aligned block, so the first 2^k samples of
//!    a pixel are still a (0, k, 2)-net, and different requests of one
//!    sample get unrelated points (which is what makes high dimensions
//!    independent of each other);
//! 2. the point's coordinates are Owen-scrambled, each by its own seed, which
//!    keeps the net's stratification and makes the point set a random one
//!    (the estimate unbiased) whose error, with the `sobol` sampler, is
//!    unrelated to the neighbouring pixels' (each pixel has its own seeds;
//!    the `zsobol` sampler shares them, see [`super::zsobol`]).
//!
//! An Owen scramble flips each bit of a coordinate (read as a binary
//! fraction) depending on the bits above it. Hashing the bit-reversed value
//! with operations in which each output bit depends only on the input bits
//! below it (adding, multiplying, and xor with a multiple of an even
//! constant) does exactly that (Laine and Karras 2011), with Burley's
//! constants. (A later set of constants, tried too, flipped some bits too
//! predictably: the positions of 16-sample pixels within their strata were
//! visibly uneven over 4,096 pixels, which `tests/samplers.rs` checks.)
//!
//! Sample counts that are not powers of two work: the first n samples are a
//! prefix of the next power of two's net, less evenly spread than a full net
//! but still far better than independent points, and as unbiased.

/// Sobol dimension 1 of index `i`, bit by bit: its generator matrix is
/// Pascal's triangle modulo 2, each direction number `v ^ (v >> 1)` of the
/// one before, and bit `j` of the index adds (xor) direction number `j`.
const fn sobol1_bits(mut i: u32, mut v: u32) -> u32 {
    let mut x = 0;
    while i != 0 {
        if i & 1 != 0 {
            x ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    x
}

/// Direction number `j` of Sobol dimension 1.
const fn direction(j: u32) -> u32 {
    let mut v = 1u32 << 31;
    let mut k = 0;
    while k < j {
        v ^= v >> 1;
        k += 1;
    }
    v
}

/// [`sobol1_bits`] of each byte value in each of the four bytes of an index,
/// bit-reversed (see [`sample_2d`] for why). The generator matrix is linear
/// over GF(2), so an index's point is the xor of its bytes' points: four
/// loads instead of a branch per bit.
const SOBOL1_REVERSED_BYTES: [[u32; 256]; 4] = {
    let mut table = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            table[byte][b] = sobol1_bits(b as u32, direction(8 * byte as u32)).reverse_bits();
            b += 1;
        }
        byte += 1;
    }
    table
};

/// [`SOBOL1_REVERSED_BYTES`] for an index given bit-reversed: entry `[k][b]`
/// is for reversed-index byte `k` of value `b`, i.e. index byte `3 − k` of
/// value `b` reversed. The map from the reversed index to the reversed
/// point is linear over GF(2) too, so [`sample_2d`] can take Sobol's
/// dimension 1 straight from the shuffled index as it comes out of the
/// scramble, bit-reversed, without reversing it first.
const SOBOL1_FROM_REVERSED_BYTES: [[u32; 256]; 4] = {
    let mut table = [[0u32; 256]; 4];
    let mut k = 0;
    while k < 4 {
        let mut b = 0;
        while b < 256 {
            table[k][b] = SOBOL1_REVERSED_BYTES[3 - k][(b as u8).reverse_bits() as usize];
            b += 1;
        }
        k += 1;
    }
    table
};

/// A map linear over GF(2) given by its value on each byte value of each of
/// the four bytes (`table[k][b]` for byte `k` of value `b`), applied to `x`:
/// the xor of its bytes' values.
#[inline(always)]
fn by_bytes(table: &[[u32; 256]; 4], x: u32) -> u32 {
    let [b0, b1, b2, b3] = x.to_le_bytes();
    table[0][b0 as usize] ^ table[1][b1 as usize] ^ table[2][b2 as usize] ^ table[3][b3 as usize]
}

/// Sobol dimension 1 of the index whose bit reversal is `r`, bit-reversed.
#[inline(always)]
fn sobol1_reversed_from_reversed(r: u32) -> u32 {
    by_bytes(&SOBOL1_FROM_REVERSED_BYTES, r)
}

/// Sobol dimension 1 of index `i`, bit-reversed.
#[cfg(test)]
fn sobol1_reversed(i: u32) -> u32 {
    by_bytes(&SOBOL1_REVERSED_BYTES, i)
}

/// A permutation of the 32-bit integers in which each output bit depends
/// only on the input bits at and below it (Laine–Karras), keyed by `seed`.
#[inline(always)]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// The Owen scramble of the binary fraction `x`, keyed by `seed`: each bit
/// flipped depending on the bits above it.
#[inline(always)]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The index of sample `index` in the scrambled order of `seed`: a nested
/// uniform shuffle, which maps each aligned block of 2^k indices onto an
/// aligned block of 2^k. ([`sample_1d`] and [`sample_2d`] do it on the
/// reversed index, without the reversals.)
#[cfg(test)]
fn shuffle(index: u32, seed: u32) -> u32 {
    // Each bit of the index flipped depending on the bits above it, so the
    // high bits (which block) depend on the high bits only.
    owen_scramble(index, seed)
}

/// Three 32-bit seeds from one well-mixed 64-bit one: its halves, and the
/// high half of its product with an odd constant (which mixes both halves).
#[inline(always)]
fn seeds(seed: u64) -> [u32; 3] {
    let more = (u128::from(seed) * 0x9E37_79B9_7F4A_7C15) >> 64;
    [seed as u32, (seed >> 32) as u32, more as u32]
}

/// Point `index` of the 1-D sequence of `seed`, as a 32-bit binary fraction,
/// given `reversed_index` = `index.reverse_bits()` (which a sample works out
/// once for all its draws): `owen_scramble(sobol0(shuffle(index, s0)), s1)`,
/// with the bit reversals that cancel left out (the scramble reverses its
/// input, Sobol dimension 0 is the reversed index), which halves the work
/// (a reversal is a dozen instructions on x86-64).
#[inline(always)]
pub fn sample_1d(reversed_index: u32, seed: u64) -> u32 {
    let [s0, s1, _] = seeds(seed);
    let i = laine_karras(reversed_index, s0).reverse_bits();
    laine_karras(i, s1).reverse_bits()
}

/// Point `index` of the 2-D sequence of `seed`, as 32-bit binary fractions,
/// given `reversed_index` as [`sample_1d`] is: the Owen scrambles of Sobol
/// dimensions 0 and 1 of the shuffled index, written, as there, without the
/// reversals that cancel. Dimension 1 is read from the shuffled index while
/// it is still reversed (byte tables of the reversed index): three reversals a
/// draw.
#[inline(always)]
pub fn sample_2d(reversed_index: u32, seed: u64) -> [u32; 2] {
    let [s0, s1, s2] = seeds(seed);
    let shuffled_reversed = laine_karras(reversed_index, s0);
    let i = shuffled_reversed.reverse_bits();
    [
        laine_karras(i, s1).reverse_bits(),
        laine_karras(sobol1_reversed_from_reversed(shuffled_reversed), s2).reverse_bits(),
    ]
}

/// A 32-bit binary fraction as an `f32` in [0, 1): its top 24 bits, which
/// an `f32` holds exactly.
#[inline(always)]
pub fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::mix64;

    /// Sobol dimension 0 (the van der Corput sequence) of index `i`.
    fn sobol0(i: u32) -> u32 {
        i.reverse_bits()
    }

    /// Sobol dimension 1 of index `i`, from its definition.
    fn sobol1(i: u32) -> u32 {
        sobol1_bits(i, 1 << 31)
    }

    /// Indices to check: a walk over the 32-bit integers, and the extremes.
    fn indices() -> impl Iterator<Item = u32> {
        let mut i = 1u32;
        (0..100_000)
            .map(move |_| {
                i = i.wrapping_mul(0x2C1B_3C6D).wrapping_add(0x297A_2D39);
                i
            })
            .chain([0, u32::MAX])
    }

    #[test]
    fn byte_tables_give_the_bit_by_bit_points() {
        for i in indices() {
            assert_eq!(sobol1_reversed(i).reverse_bits(), sobol1(i), "index {i}");
            let from_reversed = sobol1_reversed_from_reversed(i.reverse_bits());
            assert_eq!(from_reversed.reverse_bits(), sobol1(i), "index {i}");
        }
    }

    #[test]
    fn samples_are_the_scrambles_of_the_shuffled_points() {
        for (n, i) in indices().enumerate() {
            let seed = mix64(n as u64);
            let [s0, s1, s2] = seeds(seed);
            let j = shuffle(i, s0);
            let expected = [owen_scramble(sobol0(j), s1), owen_scramble(sobol1(j), s2)];
            let r = i.reverse_bits();
            assert_eq!(sample_2d(r, seed), expected, "index {i}");
            assert_eq!(sample_1d(r, seed), expected[0], "index {i}");
        }
    }

    /// Whether the points (as 32-bit fractions) put exactly one point in
    /// every elementary interval of area 1/n, n = points.len() = 2^k.
    fn is_net(points: &[[u32; 2]]) -> bool {
        let k = points.len().trailing_zeros();
        (0..=k).all(|a| {
            let b = k - a;
            let mut seen = vec![false; points.len()];
            points.iter().all(|p| {
                // The top a bits of x and top b bits of y name the cell.
                let cx = if a == 0 { 0 } else { p[0] >> (32 - a) } as usize;
                let cy = if b == 0 { 0 } else { p[1] >> (32 - b) } as usize;
                let cell = (cx << b) | cy;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn unscrambled_first_points_are_a_zero_two_sequence() {
        // Every aligned block of 2^k consecutive points is a (0, k, 2)-net.
        let points: Vec<[u32; 2]> = (0..1024u32).map(|i| [sobol0(i), sobol1(i)]).collect();
        for k in 0..=10 {
            let n = 1 << k;
            for block in points.chunks(n) {
                assert!(is_net(block), "block of {n} is not a net");
            }
        }
    }

    #[test]
    fn scrambled_and_shuffled_prefixes_are_nets_for_every_seed() {
        for seed in 0..200u64 {
            let seed = mix64(seed);
            let points: Vec<[u32; 2]> = (0..256u32)
                .map(|i| sample_2d(i.reverse_bits(), seed))
                .collect();
            for k in 0..=8 {
                assert!(is_net(&points[..1 << k]), "seed {seed}: prefix 2^{k}");
            }
            // In one dimension: the first 2^k points fall one in each of
            // 2^k equal intervals.
            for k in 0..=8u32 {
                let mut cells: Vec<u32> = (0..1u32 << k)
                    .map(|i| {
                        let x = sample_1d(i.reverse_bits(), seed);
                        if k == 0 {
                            0
                        } else {
                            x >> (32 - k)
                        }
                    })
                    .collect();
                cells.sort_unstable();
                assert!(cells.iter().enumerate().all(|(i, &c)| c == i as u32));
            }
        }
    }

    #[test]
    fn shuffle_maps_aligned_blocks_onto_aligned_blocks() {
        for seed in [1u32, 0xdead_beef, 12345] {
            let mut all: Vec<u32> = (0..4096).map(|i| shuffle(i, seed)).collect();
            for k in 0..=12 {
                let block: Vec<u32> = all[..1 << k].to_vec();
                let high = block[0] >> k;
                assert!(block.iter().all(|&j| j >> k == high), "2^{k}");
            }
            all.sort_unstable();
            all.dedup();
            assert_eq!(all.len(), 4096, "a permutation");
        }
    }

    #[test]
    fn owen_scramble_is_a_bijection_that_keeps_leading_bits_together() {
        // Numbers that share their top bits still share them (possibly
        // flipped) after scrambling: nested intervals go to nested intervals.
        for seed in [3u32, 0x1234_5678] {
            let mut seen: Vec<u32> = (0..1u32 << 16)
                .map(|i| owen_scramble(i << 16, seed) >> 16)
                .collect();
            for i in 0..1u32 << 16 {
                let (a, b) = (i << 16, (i << 16) | 0xffff);
                assert_eq!(owen_scramble(a, seed) >> 16, owen_scramble(b, seed) >> 16);
            }
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), 1 << 16);
        }
    }
}
