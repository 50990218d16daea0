//! Perlin noise, as *Ray Tracing: The Next Week* builds it: random unit
//! vectors at the points of an integer lattice, hashed by three permutation
//! tables, blended by Hermite-smoothed trilinear interpolation of their dot
//! products with the offsets; turbulence as a sum of octaves.

use crate::math::{Point3, Vec3};
use crate::rng::Rng;

/// Lattice points per axis before the pattern repeats.
const POINTS: usize = 256;

/// A Perlin noise function, made from a seed: the same seed gives the same
/// noise on every machine.
#[derive(Clone, Debug, PartialEq)]
pub struct Perlin {
    vectors: Vec<Vec3>,
    perm: [Vec<u8>; 3],
}

impl Perlin {
    /// The noise made from `seed`.
    pub fn new(seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let vectors = (0..POINTS)
            .map(|_| loop {
                // Uniform in the cube, kept when inside the unit ball: an
                // even spread of directions once normalised.
                let v = Vec3::new(
                    rng.range_f32(-1.0, 1.0),
                    rng.range_f32(-1.0, 1.0),
                    rng.range_f32(-1.0, 1.0),
                );
                let l2 = v.length_squared();
                if l2 > 1e-6 && l2 <= 1.0 {
                    break v / l2.sqrt();
                }
            })
            .collect();
        let mut permutation = || {
            let mut p: Vec<u8> = (0..POINTS).map(|i| i as u8).collect();
            for i in (1..POINTS).rev() {
                let j = (rng.next_u32() as usize) % (i + 1);
                p.swap(i, j);
            }
            p
        };
        let perm = [permutation(), permutation(), permutation()];
        Perlin { vectors, perm }
    }

    /// The noise at `p`, in about [−1, 1]; 0 at every lattice point.
    pub fn noise(&self, p: Point3) -> f32 {
        let floor = p.floor();
        let f = p - floor;
        let (i, j, k) = (floor.x as i64, floor.y as i64, floor.z as i64);
        // Hermite smoothing of the weights.
        let s = f * f * (Vec3::splat(3.0) - 2.0 * f);
        let mut sum = 0.0;
        for di in 0..2 {
            for dj in 0..2 {
                for dk in 0..2 {
                    let hash = self.perm[0][wrap(i + di)]
                        ^ self.perm[1][wrap(j + dj)]
                        ^ self.perm[2][wrap(k + dk)];
                    let gradient = self.vectors[hash as usize];
                    let corner = Vec3::new(di as f32, dj as f32, dk as f32);
                    let weight = Vec3::select(corner.cmpeq(Vec3::ONE), s, Vec3::ONE - s);
                    sum += weight.x * weight.y * weight.z * gradient.dot(f - corner);
                }
            }
        }
        sum
    }

    /// Turbulence: |Σ 2⁻ⁱ noise(2ⁱ p)| over `octaves` octaves, in about
    /// [0, 2).
    pub fn turbulence(&self, p: Point3, octaves: u32) -> f32 {
        let (mut sum, mut weight, mut p) = (0.0, 1.0, p);
        for _ in 0..octaves {
            sum += weight * self.noise(p);
            weight *= 0.5;
            p *= 2.0;
        }
        sum.abs()
    }
}

/// A lattice coordinate's index into the tables (the pattern repeats every
/// [`POINTS`]).
#[inline]
fn wrap(i: i64) -> usize {
    i.rem_euclid(POINTS as i64) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_zero_on_the_lattice_bounded_and_continuous() {
        let perlin = Perlin::new(7);
        for p in [Vec3::ZERO, Vec3::new(3.0, -2.0, 17.0), Vec3::splat(-255.0)] {
            assert!(perlin.noise(p).abs() < 1e-6, "{p:?}");
        }
        let mut rng = Rng::new(1);
        let (mut lo, mut hi) = (0.0f32, 0.0f32);
        for _ in 0..20_000 {
            let p = Vec3::new(
                rng.range_f32(-50.0, 50.0),
                rng.range_f32(-50.0, 50.0),
                rng.range_f32(-50.0, 50.0),
            );
            let n = perlin.noise(p);
            // Each of the eight terms is at most |g·(f − c)| ≤ √3 times its
            // weight, and the weights add up to 1.
            assert!(n.abs() <= 3f32.sqrt(), "{n}");
            (lo, hi) = (lo.min(n), hi.max(n));
            // Continuous: a tiny step changes it by a tiny amount.
            let step = perlin.noise(p + Vec3::splat(1e-3));
            assert!((step - n).abs() < 0.02, "{n} then {step}");
        }
        // Both signs, and a real spread.
        assert!(lo < -0.4 && hi > 0.4, "[{lo}, {hi}]");
    }

    #[test]
    fn the_same_seed_gives_the_same_noise_and_another_seed_another() {
        let p = Vec3::new(1.3, 2.7, -0.4);
        assert_eq!(Perlin::new(3).noise(p), Perlin::new(3).noise(p));
        assert_ne!(Perlin::new(3).noise(p), Perlin::new(4).noise(p));
        let t = Perlin::new(3).turbulence(p, 7);
        assert!((0.0..2.0).contains(&t));
    }
}
