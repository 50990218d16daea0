//! Diffuse materials: the four ways of bouncing and the two ways of attenuating
//! that the notes compare.

use super::Scatter;
use crate::geometry::HitRecord;
use crate::math::{Color, Vec3};
use crate::sampler::{Dim, Sampler};
use crate::sampling;

/// How a diffuse bounce chooses its direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BounceModel {
    /// Towards a random point on the surface of the cube [-1, 1]³ centred at p + N.
    /// Cube corners bias the directions, and some point into the surface.
    Cube,
    /// Towards a random point inside the unit sphere tangent at p (centre p + N).
    /// Biased towards the normal: pdf ∝ cos³θ.
    SphereVolume,
    /// Towards a random point on the surface of that sphere: true Lambertian
    /// scattering, pdf = cosθ/π.
    Lambertian,
    /// A uniform direction in the hemisphere around N: pdf = 1/(2π).
    Hemisphere,
}

/// How a diffuse surface removes light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Attenuation {
    /// Every ray scatters and its colour is multiplied by the albedo.
    Scale,
    /// A ray survives with probability p = the albedo's largest component and
    /// is otherwise absorbed; survivors are multiplied by albedo / p, which is
    /// 1 (unattenuated) for a grey albedo. Same expected value as `Scale`.
    Absorb,
}

/// A diffuse (matte) surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Fraction of light reflected per channel.
    pub albedo: Color,
    /// How bounce directions are chosen.
    pub bounce: BounceModel,
    /// How the albedo is applied.
    pub attenuation: Attenuation,
}

impl Diffuse {
    /// A Lambertian surface that scales by its albedo.
    pub fn lambertian(albedo: Color) -> Self {
        Self {
            albedo,
            bounce: BounceModel::Lambertian,
            attenuation: Attenuation::Scale,
        }
    }

    /// Whether it scatters exactly as a Lambertian surface does (cosine
    /// distributed bounces, the albedo applied to every one): the one
    /// diffuse form whose density the integrator can weigh against a
    /// light's. The other bounce models and absorption are sampled only.
    #[inline(always)]
    pub fn is_lambertian(&self) -> bool {
        self.bounce == BounceModel::Lambertian && self.attenuation == Attenuation::Scale
    }

    /// Scatters at `hit`; `None` when the ray is absorbed.
    #[inline(always)]
    pub fn scatter(&self, hit: &HitRecord, sampler: &mut impl Sampler) -> Option<Scatter> {
        let attenuation = match self.attenuation {
            Attenuation::Scale => self.albedo,
            Attenuation::Absorb => {
                let p = self.albedo.max_element();
                if !(p > 0.0) || sampler.get_1d(Dim::BsdfChoice) >= p {
                    return None;
                }
                self.albedo / p
            }
        };
        Some(Scatter {
            attenuation,
            direction: hit.reflected_above(bounce_direction(
                self.bounce,
                hit.shading_normal,
                sampler,
            )),
        })
    }
}

/// The density per unit solid angle with which a Lambertian bounce at
/// `hit` leaves along unit `w`: cosine-distributed about the shading
/// normal, and on a smoothly shaded surface also the directions that fell
/// below the true surface and were mirrored above it (see
/// [`HitRecord::reflected_above`]).
#[inline]
pub fn lambertian_pdf(hit: &HitRecord, w: Vec3) -> f32 {
    let mut cos = hit.shading_normal.dot(w).max(0.0);
    if hit.is_smooth() {
        cos += hit
            .shading_normal
            .dot(super::reflect(w, hit.normal))
            .max(0.0);
    }
    cos * std::f32::consts::FRAC_1_PI
}

/// A unit bounce direction around unit `normal` following `model`.
#[inline(always)]
pub fn bounce_direction(model: BounceModel, normal: Vec3, sampler: &mut impl Sampler) -> Vec3 {
    let d = match model {
        BounceModel::Cube => normal + sampling::on_cube_surface(sampler),
        BounceModel::SphereVolume => normal + sampling::in_unit_sphere(sampler),
        BounceModel::Lambertian => {
            normal + sampling::unit_vector_around(sampler.get_2d(Dim::Bsdf), normal)
        }
        BounceModel::Hemisphere => sampling::on_hemisphere(sampler.get_2d(Dim::Bsdf), normal),
    };
    // A sample opposite the normal cancels it. For N + u with unit u, the exact
    // cosθ of the result is |d|/2, while f32 cancellation tilts a short d by
    // up to ~1e-7/|d| radians: below |d|² = 1e-6 rounding could tip the
    // direction under the surface (or to NaN at zero), so take the normal.
    // The fallback is hit with probability 2.5e-7 (|d|² is uniform on [0, 4]);
    // it is normalised because the hit normal is unit only to within ~1e-4.
    let len2 = d.length_squared();
    if len2 < 1e-6 {
        normal.normalize()
    } else {
        d / len2.sqrt()
    }
}
