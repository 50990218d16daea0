//! Dielectrics: the notes' glass (Snell refraction, total internal
//! reflection and Schlick's approximation of Fresnel reflectance), and
//! glass by the exact Fresnel equations, smooth or rough (Walter et al.
//! 2007; pbrt-v4's `DielectricBxDF`, Mitsuba 3's `roughdielectric`).

use super::metal::reflect;
use super::microfacet::Microfacet;
use super::{albedo, fresnel};
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
                bsdf.reflected_above(reflect(direction, n).normalize())?,
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

/// A dielectric interface at one point, in the local frame (z on the side
/// light leaves to along `wo`): the exact Fresnel equations choose between
/// reflection and transmission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactDielectric {
    /// The index of refraction below the surface (−z) over the index above
    /// it (+z): 1.5 for glass seen from the air, 1/1.5 from inside.
    pub eta: f32,
    /// The microfacets; `None` for a smooth interface.
    pub roughness: Option<Microfacet>,
    /// Return the energy single scattering loses (see [`super::albedo`]).
    pub multiscatter: bool,
}

impl ExactDielectric {
    /// What kind of scattering it does.
    pub fn flags(&self) -> LobeFlags {
        let spread = match self.roughness {
            Some(_) if self.eta != 1.0 => LobeFlags::GLOSSY,
            _ => LobeFlags::SPECULAR,
        };
        if self.eta == 1.0 {
            LobeFlags::TRANSMISSION | spread
        } else {
            LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | spread
        }
    }

    /// A direction for light leaving along `wo`, from `uc` (reflect or
    /// transmit) and `u` (the microfacet), uniform in [0, 1).
    #[inline]
    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let Some(d) = self.roughness.filter(|_| self.eta != 1.0) else {
            return self.sample_smooth(wo, uc);
        };
        // Sampled as seen from the side `wo` is on.
        let up = if wo.z < 0.0 { -wo } else { wo };
        let wm = d.sample_wm(up, u);
        // A microfacet seen from behind (drawn so only by rounding, at a
        // grazing view) scatters nothing.
        if !(up.dot(wm) > 0.0) {
            return None;
        }
        let r = fresnel::dielectric(wo.dot(wm), self.eta);
        let (wi, flags) = if uc < r {
            (fresnel::reflect(wo, wm), LobeFlags::REFLECTION)
        } else {
            (
                fresnel::refract(wo, wm, self.eta)?.0,
                LobeFlags::TRANSMISSION,
            )
        };
        let reflected = wi.z * wo.z > 0.0;
        if reflected != (flags == LobeFlags::REFLECTION) || wi.z == 0.0 {
            return None;
        }
        BsdfSample::evaluated(self.eval_and_pdf(wo, wi), wi, flags | LobeFlags::GLOSSY)
    }

    /// The smooth interface: mirror reflection or Snell refraction, chosen
    /// in proportion to the Fresnel reflectance.
    fn sample_smooth(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        let r = fresnel::dielectric(wo.z, self.eta);
        let t = 1.0 - r;
        if uc < r {
            return Some(BsdfSample {
                value: Color::ONE,
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                pdf: r,
                flags: LobeFlags::REFLECTION | LobeFlags::SPECULAR,
            });
        }
        let (wi, etap) = fresnel::refract(wo, Vec3::Z, self.eta)?;
        Some(BsdfSample {
            // Radiance is compressed into the smaller solid angle of the
            // denser side (divided by η² going in).
            value: Color::splat(1.0 / (etap * etap)),
            wi,
            pdf: t,
            flags: LobeFlags::TRANSMISSION | LobeFlags::SPECULAR,
        })
    }

    /// f(wo, wi)·|cos θi| and the density of `wi` (zero when smooth).
    #[inline]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let Some(d) = self.roughness.filter(|_| self.eta != 1.0) else {
            return (Color::ZERO, 0.0);
        };
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return (Color::ZERO, 0.0);
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = match (reflect, cos_o > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        // The generalised half vector, turned to +z.
        let wm = (wi * etap + wo).normalize_or_zero();
        if wm == Vec3::ZERO {
            return (Color::ZERO, 0.0);
        }
        let wm = if wm.z < 0.0 { -wm } else { wm };
        let (dot_o, dot_i) = (wo.dot(wm), wi.dot(wm));
        // Microfacets seen from behind reflect and transmit nothing.
        if dot_i * cos_i < 0.0 || dot_o * cos_o < 0.0 {
            return (Color::ZERO, 0.0);
        }
        let up = if cos_o < 0.0 { -wo } else { wo };
        let r = fresnel::dielectric(dot_o, self.eta);
        let scale = if self.multiscatter {
            let eta = if cos_o > 0.0 {
                self.eta
            } else {
                1.0 / self.eta
            };
            albedo::dielectric_compensation(&d, eta, wo)
        } else {
            1.0
        };
        let (f_cos, pdf) = self.single(&d, wo, wi, wm, up, r, reflect, etap);
        (Color::splat(f_cos * scale), pdf)
    }

    /// f·|cos θi| and the density of single scattering through microfacet
    /// `wm` (`up`: `wo` turned to +z; `r`: the Fresnel reflectance there).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn single(
        &self,
        d: &Microfacet,
        wo: Vec3,
        wi: Vec3,
        wm: Vec3,
        up: Vec3,
        r: f32,
        reflect: bool,
        etap: f32,
    ) -> (f32, f32) {
        let (cos_o, dot_o, dot_i) = (wo.z, wo.dot(wm), wi.dot(wm));
        if reflect {
            let f_cos = d.d(wm) * d.g(wo, wi) * r / (4.0 * cos_o.abs());
            let pdf = d.pdf(up, wm) / (4.0 * dot_o.abs()) * r;
            return (f_cos, pdf);
        }
        let t = 1.0 - r;
        let denom = (dot_i + dot_o / etap).powi(2);
        let f_cos =
            t * d.d(wm) * d.g(wo, wi) * (dot_i * dot_o / (cos_o * denom)).abs() / (etap * etap);
        let pdf = d.pdf(up, wm) * dot_i.abs() / denom * t;
        (f_cos, pdf)
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
