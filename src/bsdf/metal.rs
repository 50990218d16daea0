//! The notes' metal: mirror reflection, tinted by an albedo and blurred by
//! fuzz.

use super::{Bsdf, BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};
use crate::sampler::{Dim, Sampler};
use crate::sampling;

/// The notes' metal lobe at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzyMetal {
    /// Colour of the reflection.
    pub albedo: Color,
    /// Radius in [0, 1] of the sphere around the tip of the reflected direction
    /// from which the actual direction is drawn; 0 is a perfect mirror.
    pub fuzz: f32,
}

/// Mirror reflection of `v` about the unit normal `n`: v − 2(v·n)n.
///
/// (v·n)n is the projection of v on n; subtracting it once gives the part of v
/// along the surface, subtracting it twice flips v to the other side.
#[inline]
pub fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    v - 2.0 * v.dot(n) * n
}

impl FuzzyMetal {
    /// Reflects the ray that arrived against unit `wo` at the point of
    /// `bsdf`; rays fuzzed below the surface are absorbed.
    #[inline(always)]
    pub fn sample(&self, bsdf: &Bsdf, wo: Vec3, sampler: &mut impl Sampler) -> Option<BsdfSample> {
        let n = bsdf.frame.n;
        let mut reflected = reflect(-wo, n);
        if self.fuzz > 0.0 {
            reflected = reflected.normalize()
                + self.fuzz * sampling::unit_vector(sampler.get_2d(Dim::Bsdf));
        }
        if reflected.dot(n) <= 0.0 {
            return None;
        }
        let spread = if self.fuzz == 0.0 {
            LobeFlags::SPECULAR
        } else {
            LobeFlags::GLOSSY
        };
        Some(BsdfSample {
            value: self.albedo,
            wi: bsdf.reflected_above(reflected.normalize())?,
            pdf: 0.0,
            flags: LobeFlags::REFLECTION | spread,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_mirrors_about_the_normal() {
        // 45° in, 45° out.
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert_eq!(r, Vec3::new(1.0, 1.0, 0.0));
        // Head-on reverses; grazing is unchanged.
        assert_eq!(reflect(-Vec3::Y, Vec3::Y), Vec3::Y);
        assert_eq!(reflect(Vec3::X, Vec3::Y), Vec3::X);
    }

    #[test]
    fn reflect_keeps_length_and_the_tangential_part_and_flips_the_normal_part() {
        let n = Vec3::new(1.0, 2.0, 2.0) / 3.0;
        for v in [Vec3::new(0.3, -0.4, 2.0), Vec3::new(-1.0, -1.0, 0.5)] {
            let r = reflect(v, n);
            assert!((r.length() - v.length()).abs() < 1e-6);
            assert!((r.dot(n) + v.dot(n)).abs() < 1e-6);
            let tangential = |u: Vec3| u - u.dot(n) * n;
            assert!((tangential(r) - tangential(v)).length() < 1e-6);
            // Reflecting twice gives the original back.
            assert!((reflect(r, n) - v).length() < 1e-6);
        }
    }
}
