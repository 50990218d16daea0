//! Plastic: a diffuse base under a clear dielectric coat, smooth or rough
//! (the model of Mitsuba 3's `plastic` and `roughplastic`, after Weidlich
//! & Wilkie 2007).
//!
//! The coat reflects specularly by the exact Fresnel equations (off
//! microfacets when rough). What it lets through, a fraction T(μ) of the
//! light arriving at cosine μ, is diffused by the base of albedo ρ; of the
//! diffused light the coat sends a fraction Ri back down, where it is
//! diffused again, and so on: the base under its coat reflects
//!
//! f_d = ρ / (1 − ρ Ri) · T(μo) T(μi) / (π η²),
//!
//! the geometric series of those inner bounces (Mitsuba's `nonlinear =
//! true`: a darker base is more saturated under a coat, as real paint is).
//! The 1/η² is the radiance leaving the denser coat into a wider solid
//! angle. For a smooth coat T = 1 − F and Ri is the fit of d'Eon & Irving
//! to the hemispherical Fresnel reflectance, as Mitsuba's; for a rough one
//! both are tabulated from the rough interface (see [`super::albedo`]),
//! or, for a coat of one isotropic roughness, per material as Mitsuba
//! does (see [`super::coat`]). The coat's specular term uses Mitsuba's
//! separable Smith shadowing G₁(wo) G₁(wi), which its tables assume, where
//! the other lobes here use the height-correlated one.
//!
//! Nothing is absorbed by the coat, so the lobe reflects at most what
//! arrives: R(μo) + T(μo) ρ (1 − Ri)/(1 − ρ Ri) ≤ R + T ≤ 1.

use super::coat::CoatTable;
use super::microfacet::Microfacet;
use super::{albedo, fresnel};
use super::{BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};
use crate::sampling::cosine_hemisphere;
use std::f32::consts::FRAC_1_PI;

/// A coated diffuse surface at one point, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The base's albedo, each channel in [0, 1].
    pub albedo: Color,
    /// The coat's index of refraction over the outside's (> 0).
    pub eta: f32,
    /// The coat's microfacets; `None` for a smooth coat.
    pub roughness: Option<Microfacet>,
    /// The rough coat's own table, if made (else the shared tables of
    /// [`super::albedo`] are looked up).
    pub coat: Option<&'static CoatTable>,
    /// Return the energy the coat's single scattering loses.
    pub multiscatter: bool,
    /// Whether the light bouncing between base and coat is coloured at
    /// every bounce (ρ / (1 − ρ Ri), darker bases more saturated, as real
    /// paint), rather than once (ρ / (1 − Ri), Mitsuba's default).
    pub nonlinear: bool,
}

impl Plastic {
    /// What kind of scattering it does.
    pub fn flags(&self) -> LobeFlags {
        let coat = match self.roughness {
            None => LobeFlags::SPECULAR,
            Some(_) => LobeFlags::GLOSSY,
        };
        LobeFlags::REFLECTION | LobeFlags::DIFFUSE | coat
    }

    /// The fraction of light arriving at cosine `mu` the coat lets through.
    #[inline]
    fn transmittance(&self, mu: f32) -> f32 {
        match &self.roughness {
            // Rounding can put the reflectance a hair above 1 at large
            // indices.
            None => (1.0 - fresnel::dielectric(mu, self.eta)).max(0.0),
            Some(d) => match self.coat {
                Some(table) => table.transmittance(mu),
                None => albedo::coat_transmittance(d, self.eta, mu),
            },
        }
    }

    /// The share of what it reflects along `wo` that its coat reflects,
    /// if the coat is a near mirror (0 otherwise): the coat's reflectance
    /// against the base's albedo seen through it (see
    /// [`Lobe::feature_albedo_seen`](super::Lobe::feature_albedo_seen)).
    pub fn near_mirror_share(&self, wo: Vec3) -> f32 {
        if self.roughness.is_some_and(|m| !m.is_near_mirror()) {
            return 0.0;
        }
        let t = self.transmittance(wo.z.abs());
        let base = t * (self.albedo.x + self.albedo.y + self.albedo.z) / 3.0;
        let coat = 1.0 - t;
        if coat + base > 0.0 {
            coat / (coat + base)
        } else {
            0.0
        }
    }

    /// The fraction of the base's diffuse light the coat reflects back.
    #[inline]
    fn internal_reflectance(&self) -> f32 {
        match &self.roughness {
            None => fresnel::diffuse_reflectance(1.0 / self.eta).clamp(0.0, 1.0),
            Some(d) => match self.coat {
                Some(table) => table.internal_reflectance(),
                None => albedo::coat_internal_reflectance(d, self.eta),
            },
        }
    }

    /// The probability of sampling the coat rather than the base, seen at
    /// coat transmittance `t_o`: Mitsuba's, the coat's reflectance against
    /// the base's weighted by 1 and the base's mean albedo.
    #[inline]
    fn coat_probability(&self, t_o: f32) -> f32 {
        let base = (self.albedo.x + self.albedo.y + self.albedo.z) / 3.0;
        let ws = 1.0 / (1.0 + base);
        let r = 1.0 - t_o;
        let p = r * ws / (r * ws + t_o * (1.0 - ws));
        if p.is_finite() {
            p
        } else {
            1.0
        }
    }

    /// A direction for light leaving along `wo`, from `uc` (coat or base)
    /// and `u`, uniform in [0, 1).
    #[inline]
    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let p_coat = self.coat_probability(self.transmittance(wo.z));
        let (wi, part) = if uc < p_coat {
            match &self.roughness {
                None => {
                    let f = fresnel::dielectric(wo.z, self.eta);
                    return Some(BsdfSample {
                        value: Color::splat(f / p_coat),
                        wi: Vec3::new(-wo.x, -wo.y, wo.z),
                        pdf: p_coat,
                        flags: LobeFlags::REFLECTION | LobeFlags::SPECULAR,
                    });
                }
                Some(d) => (fresnel::reflect(wo, d.sample_wm(wo, u)), LobeFlags::GLOSSY),
            }
        } else {
            (cosine_hemisphere(u), LobeFlags::DIFFUSE)
        };
        if !(wi.z > 0.0) {
            return None;
        }
        BsdfSample::evaluated(self.eval_and_pdf(wo, wi), wi, LobeFlags::REFLECTION | part)
    }

    /// f(wo, wi)·|cos θi| and the density of `wi` (the coat's mirror
    /// reflection, a delta, left out).
    #[inline]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return (Color::ZERO, 0.0);
        }
        let t_o = self.transmittance(wo.z);
        let p_coat = self.coat_probability(t_o);
        let ri = self.internal_reflectance();
        let through = t_o * self.transmittance(wi.z) * wi.z * FRAC_1_PI / (self.eta * self.eta);
        let bounces = if self.nonlinear {
            Color::ONE - self.albedo * ri
        } else {
            Color::splat(1.0 - ri)
        };
        let base = self.albedo / bounces * through;
        let mut f_cos = base;
        let mut pdf = (1.0 - p_coat) * wi.z * FRAC_1_PI;
        if let Some(d) = &self.roughness {
            let wm = (wo + wi).normalize_or_zero();
            if wm != Vec3::ZERO && wo.dot(wm) > 0.0 {
                let f = fresnel::dielectric(wo.dot(wm), self.eta);
                let mut coat = f * d.d(wm) * d.g1(wo) * d.g1(wi) / (4.0 * wo.z);
                if self.multiscatter {
                    coat *= albedo::dielectric_compensation(d, self.eta, wo);
                }
                f_cos += Color::splat(coat);
                pdf += p_coat * d.pdf(wo, wm) / (4.0 * wo.dot(wm));
            }
        }
        (f_cos, pdf)
    }
}
