//! How the albedo tables are made: deterministic quadrature of the
//! visible-normal sampling at every entry of the grid. Run by the tests
//! only; the results ship in `albedo_tables.bin`.

use super::{r_at, CONDUCTOR_LAYERS, DIELECTRIC_LAYERS, ETA_MAX, LAYER, MU_MIN, N_ETA, N_MU, N_R};
use crate::bsdf::fresnel;
use crate::bsdf::microfacet::{Microfacet, Model};
use crate::math::Vec3;

/// μ at grid index `i`: from [`MU_MIN`] (grazing) to 1, closer together
/// near grazing, where the albedo changes fastest.
fn mu_at(i: usize) -> f32 {
    let t = i as f32 / (N_MU - 1) as f32;
    MU_MIN + (1.0 - MU_MIN) * t * t
}

/// η at grid index `k`: from 1 to [`ETA_MAX`].
fn eta_at(k: usize) -> f32 {
    1.0 + (ETA_MAX - 1.0) * k as f32 / (N_ETA - 1) as f32
}

/// The direction at incidence cosine `mu` in the x–z plane.
fn direction(mu: f32) -> Vec3 {
    Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu)
}

/// The midpoints of an n × n grid over [0, 1)²: fine enough that the
/// directions cut off by the horizon, a step in u, cost under 0.5%.
fn grid(n: usize) -> impl Iterator<Item = [f32; 2]> {
    (0..n * n).map(move |k| {
        [
            ((k % n) as f32 + 0.5) / n as f32,
            ((k / n) as f32 + 0.5) / n as f32,
        ]
    })
}

/// Quadrature points per side for a conductor's entry and a dielectric's.
const CONDUCTOR_GRID: usize = 48;
const DIELECTRIC_GRID: usize = 32;

/// The albedo of a white (F = 1) single-scattering conductor seen from
/// `wo`: the mean of G(wo, wi)/G₁(wo) over visible normals, 1 − the lost
/// energy (Beckmann's normals are drawn by D cos θ, weighted accordingly).
fn conductor_albedo(d: &Microfacet, wo: Vec3) -> f32 {
    let mut sum = 0.0f64;
    for u in grid(CONDUCTOR_GRID) {
        let wm = d.sample_wm(wo, u);
        let wi = fresnel::reflect(wo, wm);
        if wi.z <= 0.0 || wo.dot(wm) <= 0.0 {
            continue;
        }
        let pdf = d.pdf(wo, wm) / (4.0 * wo.dot(wm));
        let f_cos = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z);
        if pdf > 0.0 {
            sum += f64::from(f_cos / pdf);
        }
    }
    (sum / (CONDUCTOR_GRID * CONDUCTOR_GRID) as f64) as f32
}

/// The albedo, counted as power (without the η² of radiance), of a
/// single-scattering dielectric interface of relative index `eta` seen
/// from `wo`: what it reflects and what it transmits.
fn dielectric_albedo(d: &Microfacet, wo: Vec3, eta: f32) -> [f32; 2] {
    let (mut reflected, mut transmitted) = (0.0f64, 0.0f64);
    for u in grid(DIELECTRIC_GRID) {
        let wm = d.sample_wm(wo, u);
        let dot_o = wo.dot(wm);
        if dot_o <= 0.0 {
            continue;
        }
        let r = fresnel::dielectric(dot_o, eta);
        let pdf_m = d.pdf(wo, wm);
        if !(pdf_m > 0.0) {
            continue;
        }
        // Per microfacet drawn, what reaches each side: D G |wo·wm|/wo.z
        // over the density of wm (the Jacobians of reflection and
        // refraction cancel against the BSDF's own).
        let weight = |wi: Vec3| d.d(wm) * d.g(wo, wi) * dot_o / (wo.z * pdf_m);
        let wr = fresnel::reflect(wo, wm);
        if wr.z > 0.0 {
            reflected += f64::from(r * weight(wr));
        }
        if let Some((wt, _)) = fresnel::refract(wo, wm, eta) {
            if wt.z < 0.0 {
                transmitted += f64::from((1.0 - r) * weight(wt));
            }
        }
    }
    let n = (DIELECTRIC_GRID * DIELECTRIC_GRID) as f64;
    [(reflected / n) as f32, (transmitted / n) as f32]
}

/// The grid point of entry `n` of a table: its layer (odd layers are
/// Beckmann's), microfacets and direction.
fn place(n: usize) -> (usize, Microfacet, Vec3) {
    let (k, j, i) = (n / (N_R * N_MU), n / N_MU % N_R, n % N_MU);
    let r = r_at(j);
    let model = if k % 2 == 0 {
        Model::Ggx
    } else {
        Model::Beckmann
    };
    (k, Microfacet::new(r * r, r * r, model), direction(mu_at(i)))
}

/// Entry `n` of the conductor's table (layers: GGX, Beckmann).
pub fn conductor_entry(n: usize) -> f32 {
    let (_, d, wo) = place(n);
    conductor_albedo(&d, wo).max(1e-3)
}

/// Entry `n` of the dielectric's tables, reflected and transmitted. Layers:
/// for each η of the grid, seen from outside (η) and from inside (1/η),
/// GGX and Beckmann.
pub fn dielectric_entry(n: usize) -> [f32; 2] {
    let (k, d, wo) = place(n);
    let eta = eta_at(k / 4);
    let eta = if (k / 2) % 2 == 0 { eta } else { 1.0 / eta };
    dielectric_albedo(&d, wo, eta)
}

/// Every table, in the order of `tables.bin`.
pub fn all() -> Vec<f32> {
    use rayon::prelude::*;
    let conductor: Vec<f32> = (0..CONDUCTOR_LAYERS * LAYER)
        .into_par_iter()
        .map(conductor_entry)
        .collect();
    let dielectric: Vec<[f32; 2]> = (0..DIELECTRIC_LAYERS * LAYER)
        .into_par_iter()
        .map(dielectric_entry)
        .collect();
    let mut out = conductor;
    out.extend(dielectric.iter().map(|v| v[0]));
    out.extend(dielectric.iter().map(|v| v[1]));
    out
}
