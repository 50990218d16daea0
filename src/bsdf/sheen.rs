//! Sheen: the soft glow at grazing angles of cloth and dust, the Charlie
//! distribution of Estevez & Kulla 2017 with its fitted visibility term,
//! exactly as KHR_materials_sheen gives them, and its directional albedo
//! E(μ), tabulated here by quadrature, which scales down the layers below.

use crate::math::Vec3;
use std::f32::consts::PI;
use std::sync::OnceLock;

/// The smallest sheen roughness used: the distribution narrows to nothing
/// at 0 (a power of 1/r²).
pub const MIN_ROUGHNESS: f32 = 0.07;

/// The Charlie distribution of normals at roughness `r`:
/// (2 + 1/α) sin^(1/α)θm / 2π with α = r².
#[inline]
pub fn d(r: f32, cos_m: f32) -> f32 {
    let inv = 1.0 / (r * r);
    let sin2 = (1.0 - cos_m * cos_m).max(0.0);
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// The fit l(x) of the Charlie shadowing at roughness `r`.
#[inline]
fn l(x: f32, r: f32) -> f32 {
    let t = (1.0 - r * r) * (1.0 - r * r);
    let mix = |a: f32, b: f32| a + t * (b - a);
    let (a, b, c) = (
        mix(21.5473, 25.3245),
        mix(3.82987, 3.32435),
        mix(0.19823, 0.16801),
    );
    let (dd, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
    a / (1.0 + b * x.powf(c)) + dd * x + e
}

/// Λ of the Charlie shadowing at incidence cosine `cos`.
#[inline]
fn lambda(cos: f32, r: f32) -> f32 {
    let c = cos.abs();
    if c < 0.5 {
        l(c, r).exp()
    } else {
        (2.0 * l(0.5, r) - l(1.0 - c, r)).exp()
    }
}

/// The sheen BRDF with a white colour: D(h)·V(wo, wi), V = 1/((1 + Λo + Λi)
/// 4 cos θo cos θi).
#[inline]
pub fn brdf(r: f32, wo: Vec3, wi: Vec3) -> f32 {
    let h = (wo + wi).normalize_or_zero();
    if h == Vec3::ZERO || wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let v = 1.0 / ((1.0 + lambda(wo.z, r) + lambda(wi.z, r)) * 4.0 * wo.z * wi.z);
    d(r, h.z) * v
}

const N_MU: usize = 32;
const N_R: usize = 32;

/// The table's entries, made by [`integrate`] at roughness `r_at(j)` and
/// μ `mu_at(i)`, row by row of roughness; shipped as little-endian `f32`
/// (`cargo test --release --lib write_sheen_table -- --ignored` makes it
/// again, `table_is_its_quadrature` checks a sample on every test run)
/// rather than made at each start, a tenth of a second of CPU.
const DATA: &[u8] = include_bytes!("sheen_table.bin");
const _: () = assert!(
    DATA.len() == 4 * N_R * N_MU,
    "sheen_table.bin has the wrong size"
);

/// The roughness of the table's row `j`.
#[cfg(test)]
fn r_at(j: usize) -> f32 {
    MIN_ROUGHNESS + (1.0 - MIN_ROUGHNESS) * j as f32 / (N_R - 1) as f32
}

/// The μ of the table's column `i`.
#[cfg(test)]
fn mu_at(i: usize) -> f32 {
    (i as f32 / (N_MU - 1) as f32).max(0.01)
}

/// The directional albedo of white sheen of roughness `r` seen at cosine
/// `mu`, ∫ f cos θi dωi, interpolated in the table.
pub fn albedo(r: f32, mu: f32) -> f32 {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        DATA.chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    });
    let fj = ((r - MIN_ROUGHNESS) / (1.0 - MIN_ROUGHNESS) * (N_R - 1) as f32)
        .clamp(0.0, (N_R - 1) as f32);
    let fi = (mu * (N_MU - 1) as f32).clamp(0.0, (N_MU - 1) as f32);
    let (j0, i0) = ((fj as usize).min(N_R - 2), (fi as usize).min(N_MU - 2));
    let (tj, ti) = (fj - j0 as f32, fi - i0 as f32);
    let at = |j: usize, i: usize| table[j * N_MU + i];
    let row = |j| at(j, i0) * (1.0 - ti) + at(j, i0 + 1) * ti;
    row(j0) * (1.0 - tj) + row(j0 + 1) * tj
}

/// ∫ f cos θi dωi by midpoints over (cos θi, φ).
#[cfg(test)]
fn integrate(r: f32, mu: f32) -> f32 {
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (nc, np) = (96, 48);
    let mut sum = 0.0f64;
    for a in 0..nc {
        let c = (a as f32 + 0.5) / nc as f32;
        let s = (1.0 - c * c).max(0.0).sqrt();
        for b in 0..np {
            // The lobe is symmetric about the plane of incidence: half the
            // azimuths, counted twice.
            let phi = PI * (b as f32 + 0.5) / np as f32;
            let wi = Vec3::new(s * phi.cos(), s * phi.sin(), c);
            sum += f64::from(brdf(r, wo, wi) * c);
        }
    }
    (sum * (2.0 * std::f64::consts::PI) / (nc * np) as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(n: usize) -> f32 {
        integrate(r_at(n / N_MU), mu_at(n % N_MU))
    }

    /// Makes `sheen_table.bin` from the quadrature.
    #[test]
    #[ignore = "rewrites src/bsdf/sheen_table.bin"]
    fn write_sheen_table() {
        let bytes: Vec<u8> = (0..N_R * N_MU)
            .flat_map(|n| entry(n).to_le_bytes())
            .collect();
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/bsdf/sheen_table.bin");
        std::fs::write(path, bytes).unwrap();
    }

    /// The shipped table is what the quadrature makes (every 29th entry made
    /// again; the tolerance leaves room only for another platform's last
    /// bits of powf and exp).
    #[test]
    fn table_is_its_quadrature() {
        for n in (0..N_R * N_MU).step_by(29) {
            let shipped = f32::from_le_bytes(DATA[4 * n..4 * n + 4].try_into().unwrap());
            let made = entry(n);
            assert!(
                (shipped - made).abs() <= 1e-5,
                "entry {n}: shipped {shipped}, quadrature {made}"
            );
        }
    }

    /// The distribution is normalised (∫ D cos θm dωm = 1).
    #[test]
    fn charlie_is_normalised() {
        for r in [0.1f32, 0.3, 0.7, 1.0] {
            let n = 200_000;
            let s: f64 = (0..n)
                .map(|i| {
                    let c = (i as f32 + 0.5) / n as f32;
                    f64::from(d(r, c) * c)
                })
                .sum::<f64>()
                * 2.0
                * std::f64::consts::PI
                / n as f64;
            assert!((s - 1.0).abs() < 2e-3, "r {r}: {s}");
        }
    }

    /// The table agrees with a finer quadrature of the same integral
    /// (1024 × 512 midpoints in double precision, made separately).
    #[test]
    fn albedo_matches_an_independent_quadrature() {
        for (r, mu, e) in [
            (0.3, 0.5, 0.0870),
            (0.5, 0.2, 0.4202),
            (0.7, 1.0, 0.0852),
            (1.0, 0.3, 0.4909),
            (0.2, 0.1, 0.5597),
        ] {
            let a = albedo(r, mu);
            assert!((a - e).abs() < 0.01, "E({r}, {mu}) = {a}, not {e}");
        }
    }
}
