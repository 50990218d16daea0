//! Emissive materials: surfaces that give off light, such as a lamp's shade,
//! a window or the light quad of a Cornell box.

use crate::geometry::HitRecord;
use crate::math::Color;

/// A surface that emits light and scatters none: a ray that meets it ends
/// there, carrying the emitted radiance back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emissive {
    /// Radiance emitted per channel (≥ 0; may exceed 1).
    pub radiance: Color,
    /// Emit from both sides; otherwise only from the side the surface's
    /// outward normal points to (a sphere's outside, the side of a quad
    /// its u × v points to, the counter-clockwise side of a triangle).
    pub two_sided: bool,
}

impl Emissive {
    /// The radiance leaving the surface towards a side of it: the side its
    /// outward normal points to when `front`, else the other.
    #[inline(always)]
    pub fn towards(&self, front: bool) -> Color {
        if front || self.two_sided {
            self.radiance
        } else {
            Color::ZERO
        }
    }

    /// The radiance leaving the surface at `hit` towards the ray that hit
    /// it.
    #[inline(always)]
    pub fn emitted(&self, hit: &HitRecord) -> Color {
        self.towards(hit.front_face)
    }
}
