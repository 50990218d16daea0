//! How much light a smooth interface reflects: exactly, between two
//! dielectrics and at a conductor (a complex index of refraction), and by
//! Schlick's approximation (glTF's).

use crate::math::{Color, Vec3};

/// The fraction of unpolarised light reflected where light meets a
/// dielectric interface at cosine `cos_i` (from the side the normal points
/// to when positive), `eta` being the index on the other side of the normal
/// over the index on its side (1.5 from air into glass). Total internal
/// reflection gives 1.
#[inline]
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (parallel * parallel + perpendicular * perpendicular)
}

/// The fraction reflected by a conductor of complex index `eta + i k` (per
/// channel) at incidence cosine `cos_i` in [0, 1] (from the outside).
#[inline]
pub fn conductor(cos_i: f32, eta: Color, k: Color) -> Color {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let c2 = cos_i * cos_i;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let one = |eta: f32, k: f32| {
        let t1 = eta * eta - k * k - s2;
        let a2pb2 = (t1 * t1 + 4.0 * k * k * eta * eta).max(0.0).sqrt();
        let a = (0.5 * (a2pb2 + t1)).max(0.0).sqrt();
        let term1 = a2pb2 + c2;
        let term2 = 2.0 * cos_i * a;
        let rs = (term1 - term2) / (term1 + term2);
        let term3 = a2pb2 * c2 + s4;
        let term4 = term2 * s2;
        let rp = rs * (term3 - term4) / (term3 + term4);
        let f = 0.5 * (rs + rp);
        // 0/0 at grazing incidence on a perfect conductor: it reflects all.
        if f.is_finite() {
            f
        } else {
            1.0
        }
    };
    Vec3::new(one(eta.x, k.x), one(eta.y, k.y), one(eta.z, k.z))
}

/// Schlick's approximation: `f0` at normal incidence rising to `f90` at
/// grazing, as (1 − cos)⁵.
#[inline]
pub fn schlick(cos: f32, f0: Color, f90: Color) -> Color {
    let m = (1.0 - cos.abs()).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (f90 - f0) * (m2 * m2 * m)
}

/// The reflectance at normal incidence of an interface of relative index
/// `eta`: ((η − 1)/(η + 1))².
#[inline]
pub fn f0_of_ior(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// `w` refracted through the microfacet of unit normal `n` (with `w` on
/// either side of it), `eta` being the index across `n` over the index on
/// its side; `None` under total internal reflection. Also gives the
/// relative index along the ray (η′/η, the one `eta` or its inverse).
#[inline]
pub fn refract(w: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(w);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * n, eta))
}

/// The fraction of light diffused uniformly over the hemisphere that a
/// smooth interface of relative index `eta` reflects, ∫ 2μ F(μ) dμ, by the
/// fits Mitsuba 3 uses: Egan & Hilgeman's for η < 1, d'Eon & Irving's
/// polynomial in 1/η otherwise.
#[inline]
pub fn diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        0.0636 / eta + eta * (-1.4399 * eta + 0.7099) + 0.6681
    } else {
        let x = 1.0 / eta;
        0.919_317
            + x * (-3.479_3 + x * (6.753_35 + x * (-7.809_89 + x * (4.985_54 + x * -1.368_81))))
    }
}

/// The relative index a rough interface of index `ior` (> 0) has seen
/// from its outside (`front`) or inside, kept at least 10⁻³ away from 1:
/// at exactly 1 light goes straight on, the generalised half vector of a
/// refraction is zero, and no microfacet could be said to refract it; so
/// near 1 the interface is an index of 1.001, whose refraction is as
/// straight as makes no difference.
#[inline]
pub fn rough_eta(ior: f32, front: bool) -> f32 {
    const LEAST: f32 = 1.001;
    let ior = if ior >= 1.0 {
        ior.max(LEAST)
    } else {
        ior.min(1.0 / LEAST)
    };
    if front {
        ior
    } else {
        1.0 / ior
    }
}

/// `w` mirrored about unit `n`: 2(w·n)n − w (both pointing away).
#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values of Mitsuba 3's `fresnel` (the same formula, from its wheel).
    #[test]
    fn dielectric_matches_the_reference_values() {
        for (cos, eta, f) in [
            (1.0, 1.5, 0.04),
            (0.5, 1.5, 0.089_186_7),
            (0.1, 1.5, 0.571_592_6),
            (-0.5, 1.5, 1.0),
            (-0.9, 1.5, 0.046_332_6),
        ] {
            assert!((dielectric(cos, eta) - f).abs() < 2e-6, "F({cos}, {eta})");
        }
        assert!(dielectric(0.3, 1.0) < 1e-12);
    }

    /// At normal incidence a conductor reflects ((n−1)² + k²)/((n+1)² + k²);
    /// gold's (Mitsuba's RGB) agrees with its tabulated R0, and at 57.3° with
    /// Mitsuba's evaluation; a perfect conductor (k → ∞) reflects all.
    #[test]
    fn conductor_matches_the_reference_values() {
        let eta = Vec3::new(0.143_036, 0.375_307, 1.442_045);
        let k = Vec3::new(3.982_997, 2.385_556, 1.603_359);
        let r0 = |n: f32, k: f32| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let f = conductor(1.0, eta, k);
        for c in 0..3 {
            assert!((f[c] - r0(eta[c], k[c])).abs() < 1e-5);
        }
        let g = conductor(1.0f32.cos(), eta, k);
        let mitsuba = Vec3::new(0.962_951, 0.802_766, 0.361_269);
        assert!((g - mitsuba).abs().max_element() < 2e-5, "{g}");
        assert!(conductor(0.0, eta, k).min_element() > 0.999);
        assert!(conductor(0.7, Vec3::ZERO, Vec3::splat(1e4)).min_element() > 0.999);
    }

    /// Refraction obeys Snell's law both ways and agrees with reflecting at
    /// the critical angle.
    #[test]
    fn refraction_obeys_snells_law() {
        let n = Vec3::Z;
        for deg in [0.0f32, 20.0, 40.0, 60.0, 85.0] {
            let th = deg.to_radians();
            let w = Vec3::new(th.sin(), 0.0, th.cos());
            let (t, eta) = refract(w, n, 1.5).unwrap();
            assert_eq!(eta, 1.5);
            assert!((t.length() - 1.0).abs() < 1e-5 && t.z < 0.0);
            assert!((t.x.abs() * 1.5 - th.sin()).abs() < 1e-5, "at {deg}°");
            // Back through the same interface from below.
            let (back, eta) = refract(t, n, 1.5).unwrap();
            assert!((eta - 1.0 / 1.5).abs() < 1e-7);
            assert!((back - w).length() < 1e-4);
        }
        let critical = (1.0f32 / 1.5).asin();
        let from_glass = |th: f32| Vec3::new(th.sin(), 0.0, -th.cos());
        assert!(refract(from_glass(critical - 0.01), n, 1.5).is_some());
        assert!(refract(from_glass(critical + 0.01), n, 1.5).is_none());
        assert_eq!(dielectric(-(critical + 0.01).cos(), 1.5), 1.0);
    }

    #[test]
    fn schlick_runs_from_f0_to_f90() {
        let f0 = Vec3::splat(0.04);
        assert_eq!(schlick(1.0, f0, Vec3::ONE), f0);
        assert_eq!(schlick(0.0, f0, Vec3::ONE), Vec3::ONE);
        assert!((f0_of_ior(1.5) - 0.04).abs() < 1e-7);
    }

    /// Mitsuba 3's values of its fits (`fresnel_diffuse_reflectance`), and
    /// a midpoint quadrature of ∫ 2μ F(μ) dμ that they approximate.
    #[test]
    fn diffuse_reflectance_matches_its_fits_and_the_integral() {
        assert!((diffuse_reflectance(1.5) - 0.091_774_3).abs() < 2e-6);
        assert!((diffuse_reflectance(1.0 / 1.5) - 0.596_811_1).abs() < 2e-6);
        for eta in [1.3f32, 1.5, 2.0, 1.0 / 1.5] {
            let n = 20_000;
            let integral: f32 = (0..n)
                .map(|i| {
                    let mu = (i as f32 + 0.5) / n as f32;
                    2.0 * mu * dielectric(mu, eta)
                })
                .sum::<f32>()
                / n as f32;
            assert!(
                (integral - diffuse_reflectance(eta)).abs() < 0.01,
                "η {eta}: {integral} against {}",
                diffuse_reflectance(eta)
            );
        }
    }
}
