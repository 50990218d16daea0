//! The dielectric material: clear glass, water, diamond.

use crate::bsdf::dielectric::SmoothDielectric;
use crate::geometry::HitRecord;

/// A clear refracting material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Index of refraction relative to the surrounding medium (glass ≈ 1.5).
    /// An inner sphere with 1/η models a hollow shell.
    pub ior: f32,
    /// Refract whenever Snell's law allows it and never reflect partially
    /// (no Schlick term): the notes' "only refracting" figure.
    pub refract_only: bool,
}

impl Dielectric {
    /// The lobe at `hit`: η/η′ by the side the ray arrives from.
    #[inline(always)]
    pub fn at(&self, hit: &HitRecord) -> SmoothDielectric {
        SmoothDielectric {
            eta_ratio: if hit.front_face {
                1.0 / self.ior
            } else {
                self.ior
            },
            refract_only: self.refract_only,
        }
    }
}
