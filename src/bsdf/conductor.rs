//! Conductors (metals): Fresnel reflection by a complex index of
//! refraction, off a mirror or a rough microfacet surface (pbrt-v4's
//! `ConductorBxDF`, Mitsuba 3's `roughconductor`). Nothing is transmitted.

use super::microfacet::Microfacet;
use super::{albedo, fresnel};
use super::{BsdfSample, LobeFlags};
use crate::math::{Color, Vec3};

/// A metal surface at one point, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// The real part of the index of refraction, per channel.
    pub eta: Color,
    /// The imaginary part (absorption), per channel.
    pub k: Color,
    /// A factor on the reflection (1 for a measured metal).
    pub tint: Color,
    /// The microfacets; `None` for a mirror.
    pub roughness: Option<Microfacet>,
    /// Return the energy single scattering loses (see [`super::albedo`]).
    pub multiscatter: bool,
}

impl Conductor {
    /// The Fresnel reflectance at incidence cosine `cos`.
    #[inline]
    fn fresnel(&self, cos: f32) -> Color {
        self.tint * fresnel::conductor(cos.abs(), self.eta, self.k)
    }

    /// What kind of scattering it does.
    pub fn flags(&self) -> LobeFlags {
        match self.roughness {
            None => LobeFlags::REFLECTION | LobeFlags::SPECULAR,
            Some(_) => LobeFlags::REFLECTION | LobeFlags::GLOSSY,
        }
    }

    /// A direction for light leaving along `wo`, from `u` uniform in [0, 1)².
    #[inline]
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let Some(d) = self.roughness else {
            return Some(BsdfSample {
                value: self.fresnel(wo.z),
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                pdf: 1.0,
                flags: self.flags(),
            });
        };
        let wm = d.sample_wm(wo, u);
        let wi = fresnel::reflect(wo, wm);
        // A microfacet seen from behind (drawn so only by rounding, at a
        // grazing view) reflects nothing.
        if !(wi.z > 0.0 && wo.dot(wm) > 0.0) {
            return None;
        }
        BsdfSample::evaluated(self.eval_and_pdf(wo, wi), wi, self.flags())
    }

    /// f·cos θi on the rough surface, through microfacet normal `wm`.
    #[inline]
    fn f_cos(&self, d: &Microfacet, wo: Vec3, wi: Vec3, wm: Vec3) -> Color {
        let single = self.fresnel(wo.dot(wm)) * (d.d(wm) * d.g(wo, wi) / (4.0 * wo.z));
        if self.multiscatter {
            single * albedo::conductor_compensation(d, wo, self.fresnel(1.0))
        } else {
            single
        }
    }

    /// f(wo, wi)·|cos θi| and the density of `wi`.
    #[inline]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let Some(d) = self.roughness else {
            return (Color::ZERO, 0.0);
        };
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return (Color::ZERO, 0.0);
        }
        let wm = (wo + wi).normalize_or_zero();
        if wm == Vec3::ZERO {
            return (Color::ZERO, 0.0);
        }
        let pdf = d.pdf(wo, wm) / (4.0 * wo.dot(wm).abs());
        (self.f_cos(&d, wo, wi, wm), pdf)
    }
}
