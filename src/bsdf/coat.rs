//! What a rough dielectric coat of one roughness and index lets through
//! and reflects back, tabulated for that coat alone (as Mitsuba 3's
//! `roughplastic` tabulates it per material).
//!
//! The coat's transmittance T(μ) is the single-scattering power a rough
//! interface refracts from incidence cosine μ, the refracted light masked
//! by G₁ once more on its way down; its internal reflectance Ri is the
//! power it reflects back of light diffused uniformly from below,
//! 2∫ μ R(μ) dμ seen from inside (total internal reflection counted).
//! Both are integrals over the visible microfacet normals, done here by a
//! Gauss–Legendre product rule over the sampling routine's unit square
//! (32² nodes from outside, 128² from inside, where total internal
//! reflection makes the integrand jump), T at 64 cosines from 0 to 1
//! looked up linearly. A table takes about a million evaluations, so
//! tables are made once per distinct coat and kept for the process.

use super::fresnel;
use super::microfacet::{Microfacet, Model};
use crate::math::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// The cosines at which T is tabulated.
const RES: usize = 64;

/// A rough coat's transmittance over incidence cosine and its internal
/// reflectance.
#[derive(Debug, PartialEq)]
pub struct CoatTable {
    transmittance: [f32; RES],
    internal_reflectance: f32,
}

impl CoatTable {
    /// The table of the coat of isotropic microfacets `d` and index
    /// `eta` (the coat's over the outside's, ≠ 1), made on first use.
    pub fn of(d: &Microfacet, eta: f32) -> &'static CoatTable {
        type Key = (bool, u32, u32);
        static MADE: OnceLock<Mutex<HashMap<Key, &'static CoatTable>>> = OnceLock::new();
        let key = (d.model == Model::Ggx, d.alpha_x.to_bits(), eta.to_bits());
        let made = MADE.get_or_init(Default::default);
        if let Some(t) = made.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return t;
        }
        // Made outside the lock: two threads may both make one, and the
        // first kept is as good as the second.
        let table: &'static CoatTable = Box::leak(Box::new(CoatTable::new(d, eta)));
        made.lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(key)
            .or_insert(table)
    }

    fn new(d: &Microfacet, eta: f32) -> CoatTable {
        let d = Microfacet::new(d.alpha_x, d.alpha_x, d.model);
        let mus: Vec<f32> = (0..RES)
            .map(|i| (i as f32 / (RES - 1) as f32).max(1e-6))
            .collect();
        let through: Vec<f32> = mus
            .par_iter()
            .map(|&mu| integrate(&d, mu, eta, Scattering::Refracted))
            .collect();
        let back: f64 = mus
            .par_iter()
            .map(|&mu| f64::from(integrate(&d, mu, 1.0 / eta, Scattering::Reflected) * mu))
            .collect::<Vec<f64>>()
            .iter()
            .sum();
        let mut transmittance = [0.0; RES];
        transmittance.copy_from_slice(&through);
        CoatTable {
            transmittance,
            internal_reflectance: (2.0 * back / RES as f64) as f32,
        }
    }

    /// The fraction of light arriving at cosine `mu` (in [0, 1]) that
    /// the coat lets through.
    #[inline]
    pub fn transmittance(&self, mu: f32) -> f32 {
        let x = mu.clamp(0.0, 1.0) * (RES - 1) as f32;
        let i = (x as usize).min(RES - 2);
        let t = x - i as f32;
        self.transmittance[i] * (1.0 - t) + self.transmittance[i + 1] * t
    }

    /// The fraction of light diffused from below that the coat reflects
    /// back down.
    #[inline]
    pub fn internal_reflectance(&self) -> f32 {
        self.internal_reflectance
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Scattering {
    Reflected,
    Refracted,
}

/// The single-scattering power an interface of microfacets `d` and
/// relative index `eta` reflects or refracts from incidence cosine `mu`.
fn integrate(d: &Microfacet, mu: f32, eta: f32, what: Scattering) -> f32 {
    // The two rules are made once for every table, not for each cosine.
    static OUTSIDE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    static INSIDE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    let (nodes, weights) = if eta > 1.0 {
        OUTSIDE.get_or_init(|| gauss_legendre(32))
    } else {
        INSIDE.get_or_init(|| gauss_legendre(128))
    };
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0f64;
    for (x, wx) in nodes.iter().zip(weights) {
        for (y, wy) in nodes.iter().zip(weights) {
            let u = [(0.5 * x + 0.5) as f32, (0.5 * y + 0.5) as f32];
            let m = d.sample_wm(wi, u);
            let cos_m = wi.dot(m);
            if !(cos_m > 0.0) {
                continue;
            }
            let f = fresnel::dielectric(cos_m, eta);
            let value = match what {
                Scattering::Reflected => {
                    let wo = fresnel::reflect(wi, m);
                    if wo.z > 0.0 {
                        f * d.g1(wo)
                    } else {
                        0.0
                    }
                }
                Scattering::Refracted => match fresnel::refract(wi, m, eta) {
                    Some((wt, _)) if wt.z < 0.0 => (1.0 - f) * d.g1(wt),
                    _ => 0.0,
                },
            };
            sum += f64::from(value) * wx * wy * 0.25;
        }
    }
    sum as f32
}

/// The nodes (in (−1, 1)) and weights of `n`-point Gauss–Legendre
/// quadrature, by Newton's method on the Legendre polynomial.
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Tricomi's first guess at the i-th root from the top.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        (nodes[i], weights[i]) = (x, w);
        (nodes[n - 1 - i], weights[n - 1 - i]) = (-x, w);
    }
    (nodes, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let (x, w) = gauss_legendre(5);
        // Exact up to degree 2n − 1 = 9: ∫ x⁸ = 2/9, ∫ x⁹ = 0.
        let integral = |p: i32| x.iter().zip(&w).map(|(x, w)| w * x.powi(p)).sum::<f64>();
        assert!((integral(8) - 2.0 / 9.0).abs() < 1e-13);
        assert!(integral(9).abs() < 1e-13);
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-13);
    }

    #[test]
    fn a_nearly_smooth_coat_is_fresnel() {
        // At α = 10⁻³ the coat is the smooth interface: T = 1 − F(μ), and
        // Ri the hemispherical reflectance from inside.
        for model in [Model::Ggx, Model::Beckmann] {
            let d = Microfacet::new(1e-3, 1e-3, model);
            let t = CoatTable::new(&d, 1.5);
            for mu in [1.0, 0.7, 0.3] {
                let want = 1.0 - fresnel::dielectric(mu, 1.5);
                assert!(
                    (t.transmittance(mu) - want).abs() < 2e-3,
                    "{model:?} μ {mu}"
                );
            }
            let ri = fresnel::diffuse_reflectance(1.0 / 1.5);
            assert!((t.internal_reflectance() - ri).abs() < 0.01, "{model:?}");
        }
    }

    #[test]
    fn single_scattering_loses_what_is_masked_and_makes_nothing() {
        // What the interface reflects and refracts once sums to at most
        // what arrives; masking loses more the rougher and the more
        // grazing the light.
        for model in [Model::Ggx, Model::Beckmann] {
            for alpha in [0.05, 0.3, 0.8] {
                let d = Microfacet::new(alpha, alpha, model);
                for mu in [0.05, 0.3, 0.7, 1.0] {
                    let sum = integrate(&d, mu, 1.5, Scattering::Refracted)
                        + integrate(&d, mu, 1.5, Scattering::Reflected);
                    assert!(
                        sum <= 1.0 + 1e-4 && sum > 0.3,
                        "{model:?} α {alpha} μ {mu}: {sum}"
                    );
                    if alpha == 0.8 && mu == 0.05 {
                        assert!(sum < 0.9, "{model:?}: {sum}");
                    }
                }
                let ri = CoatTable::new(&d, 1.5).internal_reflectance();
                assert!(ri > 0.0 && ri <= fresnel::diffuse_reflectance(1.0 / 1.5) + 0.01);
            }
        }
    }

    #[test]
    fn tables_are_made_once_per_coat() {
        let d = Microfacet::new(0.3, 0.3, Model::Ggx);
        assert!(std::ptr::eq(CoatTable::of(&d, 1.4), CoatTable::of(&d, 1.4)));
        assert!(!std::ptr::eq(
            CoatTable::of(&d, 1.4),
            CoatTable::of(&d, 1.41)
        ));
    }
}
