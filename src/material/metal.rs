//! Metal: mirror reflection, tinted by an albedo and blurred by fuzz.

use super::Scatter;
use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::rng::Rng;
use crate::sampling;

/// A reflective metal surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
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

impl Metal {
    /// Reflects the unit `direction` at `hit`; rays fuzzed below the surface
    /// are absorbed.
    #[inline]
    pub fn scatter(&self, direction: Vec3, hit: &HitRecord, rng: &mut Rng) -> Option<Scatter> {
        let mut reflected = reflect(direction, hit.normal);
        if self.fuzz > 0.0 {
            reflected = reflected.normalize() + self.fuzz * sampling::unit_vector(rng);
        }
        if reflected.dot(hit.normal) <= 0.0 {
            return None;
        }
        Some(Scatter {
            attenuation: self.albedo,
            direction: reflected.normalize(),
        })
    }
}
