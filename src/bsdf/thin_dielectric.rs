//! A thin dielectric sheet: a window pane, a soap film, a bubble. Light
//! meets two parallel smooth interfaces so close together that it leaves
//! where it entered: reflected as a mirror, or transmitted straight
//! through, undeviated (the two refractions cancel). Between them it
//! bounces back and forth: with R the reflectance of one interface at the
//! incidence angle and T = 1 − R, the sheet reflects
//!
//! R′ = R + T²R/(1 − R²) = 2R/(1 + R)
//!
//! (the geometric series of inner bounces) and transmits 1 − R′, absorbing
//! nothing (pbrt-v4's `ThinDielectricBxDF`, Mitsuba 3's `thindielectric`).

use super::{fresnel, BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};

/// A thin dielectric sheet at one point, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// The sheet's index of refraction over the outside's (> 0).
    pub eta: f32,
}

impl ThinDielectric {
    /// What kind of scattering it does.
    pub fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | LobeFlags::SPECULAR
    }

    /// The fraction of light arriving at cosine `mu` that the sheet
    /// reflects, its inner bounces counted.
    #[inline]
    pub fn reflectance(&self, mu: f32) -> f32 {
        let r = fresnel::dielectric(mu.abs(), self.eta);
        if r < 1.0 {
            2.0 * r / (1.0 + r)
        } else {
            1.0
        }
    }

    /// Mirror reflection or straight transmission for light leaving along
    /// `wo`, chosen by `uc` (uniform in [0, 1)) in proportion to what each
    /// carries.
    #[inline]
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = self.reflectance(wo.z);
        let (wi, pdf, side) = if uc < r {
            (Vec3::new(-wo.x, -wo.y, wo.z), r, LobeFlags::REFLECTION)
        } else {
            (-wo, 1.0 - r, LobeFlags::TRANSMISSION | LobeFlags::STRAIGHT)
        };
        Some(BsdfSample {
            value: Color::ONE,
            wi,
            pdf,
            flags: side | LobeFlags::SPECULAR,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sheet_reflects_more_than_one_face_and_keeps_all_the_light() {
        let sheet = ThinDielectric { eta: 1.5 };
        // At normal incidence one face reflects 4 %; the sheet 2·0.04/1.04.
        assert!((sheet.reflectance(1.0) - 0.08 / 1.04).abs() < 1e-6);
        for mu in [1.0f32, 0.7, 0.3, 0.05] {
            let one = fresnel::dielectric(mu, 1.5);
            let r = sheet.reflectance(mu);
            assert!(r >= one && r <= 1.0, "μ {mu}: {r} against {one}");
            // Seen from either side alike.
            assert_eq!(r, sheet.reflectance(-mu));
        }
        // Sampling splits in proportion: the fraction reflected over a
        // uniform grid of uc is R′ to its resolution, and every sample
        // carries weight 1 (nothing absorbed).
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let n = 10_000;
        let mut reflected = 0;
        for i in 0..n {
            let s = sheet.sample(wo, (i as f32 + 0.5) / n as f32).unwrap();
            assert_eq!(s.value, Color::ONE);
            if s.flags.contains(LobeFlags::REFLECTION) {
                assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8));
                reflected += 1;
            } else {
                assert_eq!(s.wi, -wo, "straight through");
            }
        }
        let r = sheet.reflectance(0.8);
        assert!((reflected as f32 / n as f32 - r).abs() <= 1.0 / n as f32);
    }
}
