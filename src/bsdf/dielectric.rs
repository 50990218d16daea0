//! The notes' dielectric: Snell refraction, total internal reflection and
//! Schlick's approximation of Fresnel reflectance.

use super::metal::reflect;
use super::{Bsdf, BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};
use crate::sampler::{Dim, Sampler};

/// The notes' glass at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// η/η′: the index of refraction on the side the ray came from over
    /// the one on the other side (1/1.5 entering glass from air).
    pub eta_ratio: f32,
    /// Refract whenever Snell's law allows it and never reflect partially
    /// (no Schlick term): the notes' "only refracting" figure.
    pub refract_only: bool,
}

/// Refracts the unit vector `uv` through a surface with unit normal `n`
/// (facing against `uv`), with `eta_ratio` = η/η′. Returns `None` when
/// η/η′·sinθ > 1: no refracted ray exists (total internal reflection).
///
/// Snell's law η·sinθ = η′·sinθ′ fixes the refracted ray's component along the
/// surface, r⊥ = η/η′·(uv + cosθ·n); its normal component makes it unit length,
/// r∥ = −√(1 − |r⊥|²)·n.
#[inline]
pub fn refract(uv: Vec3, n: Vec3, eta_ratio: f32) -> Option<Vec3> {
    let cos_theta = (-uv).dot(n).min(1.0);
    let sin_theta2 = (1.0 - cos_theta * cos_theta).max(0.0);
    if eta_ratio * eta_ratio * sin_theta2 > 1.0 {
        return None;
    }
    let perp = eta_ratio * (uv + cos_theta * n);
    let parallel = -(1.0 - perp.length_squared()).abs().sqrt() * n;
    Some(perp + parallel)
}

/// Schlick's approximation of the fraction of light reflected at incidence
/// cosine `cosine` with η/η′ = `eta_ratio`: R₀ + (1 − R₀)(1 − cosθ)⁵,
/// R₀ = ((1 − η/η′)/(1 + η/η′))².
#[inline]
pub fn reflectance(cosine: f32, eta_ratio: f32) -> f32 {
    let r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
    let r0 = r0 * r0;
    r0 + (1.0 - r0) * (1.0 - cosine).powi(5)
}

impl SmoothDielectric {
    /// Reflects or refracts the ray that arrived against unit `wo` at the
    /// point of `bsdf`; never absorbs.
    #[inline]
    pub fn sample(&self, bsdf: &Bsdf, wo: Vec3, sampler: &mut impl Sampler) -> Option<BsdfSample> {
        let n = bsdf.frame.n;
        let direction = -wo;
        let eta_ratio = self.eta_ratio;
        let cos_theta = wo.dot(n).min(1.0);
        let refracted = refract(direction, n, eta_ratio);
        let (wi, side) = match refracted {
            Some(r)
                if self.refract_only
                    || reflectance(cos_theta, eta_ratio) <= sampler.get_1d(Dim::BsdfChoice) =>
            {
                (r.normalize(), LobeFlags::TRANSMISSION)
            }
            // The normal (P − C)/R is unit only to within ~1e-4 on small
            // spheres far from the origin; the sphere tests need unit rays.
            _ => (
                bsdf.reflected_above(reflect(direction, n).normalize()),
                LobeFlags::REFLECTION,
            ),
        };
        Some(BsdfSample {
            value: Color::ONE,
            wi,
            pdf: 0.0,
            flags: side | LobeFlags::SPECULAR,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_passes_straight_through() {
        let r = refract(-Vec3::Y, Vec3::Y, 1.0 / 1.5).unwrap();
        assert!((r - -Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn refraction_obeys_snells_law() {
        let eta = 1.0 / 1.5;
        for deg in [10.0f32, 30.0, 60.0, 85.0] {
            let th = deg.to_radians();
            let uv = Vec3::new(th.sin(), -th.cos(), 0.0);
            let r = refract(uv, Vec3::Y, eta).unwrap();
            assert!((r.length() - 1.0).abs() < 1e-5);
            let sin_out = r.x;
            assert!((sin_out - eta * th.sin()).abs() < 1e-5, "at {deg}°");
            assert!(r.y < 0.0, "continues into the surface");
        }
    }

    #[test]
    fn total_internal_reflection_starts_at_the_critical_angle() {
        // Leaving glass (η/η′ = 1.5): critical angle asin(1/1.5) ≈ 41.81°.
        let critical = (1.0f32 / 1.5).asin();
        let at = |th: f32| refract(Vec3::new(th.sin(), -th.cos(), 0.0), Vec3::Y, 1.5);
        assert!(at(critical - 0.01).is_some());
        assert!(at(critical + 0.01).is_none());
    }

    #[test]
    fn schlick_limits() {
        // Normal incidence: R0 = ((1 − 1.5)/(1 + 1.5))² = 0.04.
        assert!((reflectance(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((reflectance(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        // Grazing incidence reflects everything.
        assert!((reflectance(0.0, 1.5) - 1.0).abs() < 1e-6);
    }
}
