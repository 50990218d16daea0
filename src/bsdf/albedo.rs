//! Energy lost by single-scattering microfacets, and its return
//! (`multiscatter = true`).
//!
//! A microfacet model counts light that reflects once off a microfacet;
//! light that would have bounced between microfacets before leaving is
//! lost, up to a third of it for a white metal at roughness 1. The lost
//! energy is returned by scaling the lobe by how much it lost from the
//! direction seen (Turquin 2019, "Practical multiple scattering
//! compensation for microfacet models", as Cycles does): a conductor by
//! 1 + F₀(1 − E(μ))/E(μ), a dielectric's reflection and transmission by
//! 1/E(μ), where E(μ, α) is the single-scattering albedo from incidence
//! cosine μ. The scale depends on the outgoing direction only, so sampling
//! and densities are unchanged; what it loses is reciprocity, which a
//! compensated lobe gives up (the tests leave it out).
//!
//! The albedos are tabulated on first use, by deterministic quadrature of
//! the visible-normal sampling (a 48 × 48 grid of midpoints per entry for a
//! conductor, 32 × 32 for a dielectric), over a 32 × 32 grid of μ and √α
//! (and for dielectrics 12 indices of refraction
//! from 1 to 3, each from both sides), and interpolated linearly. An
//! anisotropic surface looks up √(αx αy).

use super::fresnel;
use super::microfacet::{Microfacet, Model};
use crate::math::Vec3;
use std::sync::OnceLock;

const N_MU: usize = 32;
const N_R: usize = 32;
const N_ETA: usize = 12;
const ETA_MAX: f32 = 3.0;

/// The most grazing μ of the tables.
const MU_MIN: f32 = 0.002;

/// μ at grid index `i`: from [`MU_MIN`] (grazing) to 1, closer together
/// near grazing, where the albedo changes fastest.
fn mu_at(i: usize) -> f32 {
    let t = i as f32 / (N_MU - 1) as f32;
    MU_MIN + (1.0 - MU_MIN) * t * t
}

/// √α at grid index `j`: from 0.02 to 1.
fn r_at(j: usize) -> f32 {
    0.02 + 0.98 * j as f32 / (N_R - 1) as f32
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

/// A table of albedos over (η, √α, μ).
struct Table {
    values: Vec<f32>,
}

impl Table {
    fn at(&self, k: usize, j: usize, i: usize) -> f32 {
        self.values[(k * N_R + j) * N_MU + i]
    }

    /// Linear interpolation in √α and μ (clamped to the grid) in layer `k`.
    fn lookup(&self, k: usize, r: f32, mu: f32) -> f32 {
        let fj = ((r - 0.02) / 0.98 * (N_R - 1) as f32).clamp(0.0, (N_R - 1) as f32);
        let t = ((mu - MU_MIN) / (1.0 - MU_MIN)).max(0.0).sqrt();
        let fi = (t * (N_MU - 1) as f32).clamp(0.0, (N_MU - 1) as f32);
        let (j0, i0) = ((fj as usize).min(N_R - 2), (fi as usize).min(N_MU - 2));
        let (tj, ti) = (fj - j0 as f32, fi - i0 as f32);
        let row = |j| self.at(k, j, i0) * (1.0 - ti) + self.at(k, j, i0 + 1) * ti;
        row(j0) * (1.0 - tj) + row(j0 + 1) * tj
    }
}

/// Tables of `C` albedos over `layers` layers, entry by entry from
/// `albedo(layer, microfacets, direction)`.
fn build<const C: usize>(
    layers: usize,
    albedo: impl Fn(usize, &Microfacet, Vec3) -> [f32; C] + Sync,
) -> [Table; C] {
    let entry = |n: usize| {
        let (k, j, i) = (n / (N_R * N_MU), n / N_MU % N_R, n % N_MU);
        let r = r_at(j);
        let model = if k % 2 == 0 {
            Model::Ggx
        } else {
            Model::Beckmann
        };
        let d = Microfacet::new(r * r, r * r, model);
        albedo(k, &d, direction(mu_at(i)))
    };
    // On threads of its own, not rayon's: a render's workers wait for the
    // table while it is made, and could not make it.
    let n = layers * N_R * N_MU;
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(16);
    let chunk = n.div_ceil(threads);
    let mut values = vec![[0.0f32; C]; n];
    std::thread::scope(|s| {
        for (c, part) in values.chunks_mut(chunk).enumerate() {
            let entry = &entry;
            s.spawn(move || {
                for (o, v) in part.iter_mut().enumerate() {
                    *v = entry(c * chunk + o);
                }
            });
        }
    });
    std::array::from_fn(|c| Table {
        values: values.iter().map(|v| v[c]).collect(),
    })
}

/// Layers: GGX, Beckmann.
fn conductor_table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let [t] = build(2, |_, d, wo| [conductor_albedo(d, wo).max(1e-3)]);
        t
    })
}

/// The albedos of dielectric interfaces: what they reflect and what they
/// transmit. Layers: for each η of the grid, seen from outside (η) and
/// from inside (1/η), GGX and Beckmann.
fn dielectric_tables() -> &'static [Table; 2] {
    static TABLES: OnceLock<[Table; 2]> = OnceLock::new();
    TABLES.get_or_init(|| {
        build(4 * N_ETA, |k, d, wo| {
            let eta = eta_at(k / 4);
            let eta = if (k / 2) % 2 == 0 { eta } else { 1.0 / eta };
            dielectric_albedo(d, wo, eta)
        })
    })
}

/// Where a relative index falls in the tables: from inside or outside,
/// the layer below and the fraction of the way to the next.
fn eta_place(eta: f32) -> (usize, usize, f32) {
    let (inside, e) = if eta >= 1.0 { (0, eta) } else { (1, 1.0 / eta) };
    let fk = ((e - 1.0) / (ETA_MAX - 1.0) * (N_ETA - 1) as f32).clamp(0.0, (N_ETA - 1) as f32);
    let k0 = (fk as usize).min(N_ETA - 2);
    (inside, k0, fk - k0 as f32)
}

/// Interpolates between the tabulated indices: `at(layer)` looked up in
/// the two layers around `eta`.
fn across_eta(d: &Microfacet, eta: f32, at: impl Fn(usize, f32) -> f32) -> f32 {
    let (model, r) = layer(d);
    let (inside, k0, t) = eta_place(eta);
    let of = |k: usize| at(k * 4 + inside * 2 + model, r);
    of(k0) * (1.0 - t) + of(k0 + 1) * t
}

/// Points of the quadrature of a coat's internal reflectance over μ.
const RI_POINTS: usize = 64;

/// The fraction of light diffused from below that a rough coat reflects
/// back, ∫₀¹ 2μ R(μ) dμ seen from inside, over (η, model, √α).
fn internal_reflectance_table() -> &'static Vec<f32> {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let [reflected, _] = dielectric_tables();
        let mut out = Vec::with_capacity(N_ETA * 2 * N_R);
        for k in 0..N_ETA {
            for model in 0..2 {
                for j in 0..N_R {
                    let mut sum = 0.0f64;
                    for p in 0..RI_POINTS {
                        let mu = (p as f32 + 0.5) / RI_POINTS as f32;
                        sum +=
                            f64::from(2.0 * mu * reflected.lookup(k * 4 + 2 + model, r_at(j), mu));
                    }
                    out.push((sum / RI_POINTS as f64) as f32);
                }
            }
        }
        out
    })
}

fn layer(d: &Microfacet) -> (usize, f32) {
    let model = match d.model {
        Model::Ggx => 0,
        Model::Beckmann => 1,
    };
    (model, (d.alpha_x * d.alpha_y).sqrt().sqrt())
}

/// The single-scattering albedo of a white conductor of microfacets `d`
/// seen at incidence cosine `mu`.
pub fn conductor(d: &Microfacet, mu: f32) -> f32 {
    let (model, r) = layer(d);
    conductor_table().lookup(model, r, mu)
}

/// The single-scattering albedo (as power) of a dielectric interface of
/// microfacets `d` and relative index `eta` (from the side seen) at
/// incidence cosine `mu`, interpolated between the tabulated indices.
pub fn dielectric(d: &Microfacet, eta: f32, mu: f32) -> f32 {
    let [reflected, transmitted] = dielectric_tables();
    across_eta(d, eta, |k, r| {
        (reflected.lookup(k, r, mu) + transmitted.lookup(k, r, mu)).max(1e-3)
    })
}

/// The fraction of light arriving at incidence cosine `mu` that a rough
/// coat of microfacets `d` and index `eta` (> 1) lets through to what it
/// covers, counted as power.
pub fn coat_transmittance(d: &Microfacet, eta: f32, mu: f32) -> f32 {
    let [_, transmitted] = dielectric_tables();
    across_eta(d, eta.max(1.0), |k, r| transmitted.lookup(k, r, mu)).clamp(0.0, 1.0)
}

/// The fraction of light diffused from below that a rough coat of
/// microfacets `d` and index `eta` (> 1) reflects back down.
pub fn coat_internal_reflectance(d: &Microfacet, eta: f32) -> f32 {
    let table = internal_reflectance_table();
    let (model, r) = layer(d);
    let (_, k0, t) = eta_place(eta.max(1.0));
    let fj = ((r - 0.02) / 0.98 * (N_R - 1) as f32).clamp(0.0, (N_R - 1) as f32);
    let j0 = (fj as usize).min(N_R - 2);
    let tj = fj - j0 as f32;
    let at = |k: usize, j: usize| table[(k * 2 + model) * N_R + j];
    let row = |k: usize| at(k, j0) * (1.0 - tj) + at(k, j0 + 1) * tj;
    (row(k0) * (1.0 - t) + row(k0 + 1) * t).clamp(0.0, 1.0)
}

/// The factor returning a conductor's lost energy (Turquin 2019) seen
/// along `wo`, for reflectance `f0` at normal incidence: 1 + f₀(1 − E)/E.
pub fn conductor_compensation(d: &Microfacet, wo: Vec3, f0: Vec3) -> Vec3 {
    let e = conductor(d, wo.z.abs());
    Vec3::ONE + f0 * ((1.0 - e) / e)
}

/// The factor returning a dielectric's lost energy seen along `wo`: 1/E.
pub fn dielectric_compensation(d: &Microfacet, eta: f32, wo: Vec3) -> f32 {
    1.0 / dielectric(d, eta, wo.z.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A white conductor loses nothing when smooth, more as it roughens,
    /// and about a third at roughness 1 seen from above (Kulla & Conty's
    /// figure for GGX: E ≈ 0.65-0.7 at α = 1); a dielectric loses
    /// less than a conductor.
    #[test]
    fn albedos_fall_with_roughness() {
        for model in [Model::Ggx, Model::Beckmann] {
            let e = |a: f32| conductor(&Microfacet::new(a, a, model), 1.0);
            assert!(e(0.001) > 0.995, "{model:?}: {}", e(0.001));
            assert!(e(0.1) > e(0.5) && e(0.5) > e(1.0), "{model:?}");
            if model == Model::Ggx {
                // At α = 1, D = 1/π and G = 2μ/(1 + μ) from the normal:
                // E = ∫₀¹ μ/(1 + μ) dμ = 1 − ln 2.
                let exact = 1.0 - std::f32::consts::LN_2;
                assert!((e(1.0) - exact).abs() < 2e-3, "E(α = 1) = {}", e(1.0));
            }
            let d = Microfacet::new(0.5, 0.5, model);
            assert!(dielectric(&d, 1.5, 0.7) > conductor(&d, 0.7));
        }
    }
}
