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
//! The albedos are tabulated by deterministic quadrature of the
//! visible-normal sampling (a 48 × 48 grid of midpoints per entry for a
//! conductor, 32 × 32 for a dielectric), over a 32 × 32 grid of μ and √α
//! (and for dielectrics 12 indices of refraction from 1 to 3, each from
//! both sides), and interpolated linearly. An anisotropic surface looks up
//! √(αx αy).
//!
//! The quadrature (`albedo/quadrature.rs`) takes 50 million evaluations,
//! seconds of CPU that every render using a coat or `multiscatter` paid
//! at its start, so its results ship in `albedo/tables.bin`
//! (little-endian `f32`: the conductor's table, then the dielectric's
//! reflected and then transmitted power, each layer by layer, √α by √α).
//! `cargo test --release --lib write_albedo_tables -- --ignored` makes
//! the file again; `tables_are_their_quadrature` recomputes a sample of
//! its entries on every test run.

use super::microfacet::{Microfacet, Model};
use crate::math::Vec3;
use std::sync::OnceLock;

const N_MU: usize = 32;
const N_R: usize = 32;
const N_ETA: usize = 12;
/// The largest index the dielectric tables cover (a rough coat of a
/// larger one would be looked up as this).
pub const ETA_MAX: f32 = 3.0;

/// The most grazing μ of the tables.
const MU_MIN: f32 = 0.002;

/// √α at grid index `j`: from 0.02 to 1.
fn r_at(j: usize) -> f32 {
    0.02 + 0.98 * j as f32 / (N_R - 1) as f32
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

/// Layers of the conductor's table (GGX, Beckmann) and of the
/// dielectric's (each η from outside and inside, GGX and Beckmann).
const CONDUCTOR_LAYERS: usize = 2;
const DIELECTRIC_LAYERS: usize = 4 * N_ETA;
/// Entries per layer.
const LAYER: usize = N_R * N_MU;

const DATA: &[u8] = include_bytes!("albedo/tables.bin");
const _: () = assert!(
    DATA.len() == 4 * (CONDUCTOR_LAYERS + 2 * DIELECTRIC_LAYERS) * LAYER,
    "albedo/tables.bin does not have the tables' size"
);

/// The albedos of white conductors, and the power that dielectric
/// interfaces reflect and transmit.
struct Tables {
    conductor: Table,
    reflected: Table,
    transmitted: Table,
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut floats = DATA
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        let mut take = |layers: usize| Table {
            values: floats.by_ref().take(layers * LAYER).collect(),
        };
        Tables {
            conductor: take(CONDUCTOR_LAYERS),
            reflected: take(DIELECTRIC_LAYERS),
            transmitted: take(DIELECTRIC_LAYERS),
        }
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
        let reflected = &tables().reflected;
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
    tables().conductor.lookup(model, r, mu)
}

/// The single-scattering albedo (as power) of a dielectric interface of
/// microfacets `d` and relative index `eta` (from the side seen) at
/// incidence cosine `mu`, interpolated between the tabulated indices.
pub fn dielectric(d: &Microfacet, eta: f32, mu: f32) -> f32 {
    let Tables {
        reflected,
        transmitted,
        ..
    } = tables();
    across_eta(d, eta, |k, r| {
        (reflected.lookup(k, r, mu) + transmitted.lookup(k, r, mu)).max(1e-3)
    })
}

/// The fraction of light arriving at incidence cosine `mu` that a rough
/// coat of microfacets `d` and index `eta` (> 1) lets through to what it
/// covers, counted as power.
pub fn coat_transmittance(d: &Microfacet, eta: f32, mu: f32) -> f32 {
    let transmitted = &tables().transmitted;
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
mod quadrature;

#[cfg(test)]
mod tests {
    use super::*;

    /// Makes `albedo/tables.bin` from the quadrature.
    #[test]
    #[ignore = "rewrites src/bsdf/albedo/tables.bin"]
    fn write_albedo_tables() {
        let bytes: Vec<u8> = quadrature::all()
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/bsdf/albedo/tables.bin");
        std::fs::write(path, bytes).unwrap();
    }

    /// The shipped tables are what the quadrature makes: a sample of their
    /// entries (every conductor's 37th, every dielectric's 53rd, spread
    /// over all layers, roughnesses and angles) made again. The quadrature
    /// is deterministic; the tolerance leaves room only for the last bits
    /// of another platform's sin and cos.
    #[test]
    fn tables_are_their_quadrature() {
        let t = tables();
        let close = |shipped: f32, made: f32, what: &str, n: usize| {
            assert!(
                (shipped - made).abs() <= 1e-5,
                "{what} entry {n}: shipped {shipped}, quadrature {made}"
            );
        };
        for n in (0..CONDUCTOR_LAYERS * LAYER).step_by(37) {
            close(
                t.conductor.values[n],
                quadrature::conductor_entry(n),
                "conductor",
                n,
            );
        }
        for n in (0..DIELECTRIC_LAYERS * LAYER).step_by(53) {
            let [r, tr] = quadrature::dielectric_entry(n);
            close(t.reflected.values[n], r, "reflected", n);
            close(t.transmitted.values[n], tr, "transmitted", n);
        }
    }

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
