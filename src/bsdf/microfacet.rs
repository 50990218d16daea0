//! Microfacet distributions: a rough surface as a field of tiny mirrors
//! whose normals `wm` follow a distribution D, each shadowing and masking
//! its neighbours (Smith's G, height-correlated).
//!
//! Two distributions, both anisotropic (α along the frame's tangent and
//! bitangent), each sampled by its visible normals: Trowbridge–Reitz
//! (GGX) with the spherical caps of Dupuy & Benyoub (2023); Beckmann by
//! inverting the distribution of its visible slopes (Heitz & d'Eon 2014,
//! as Mitsuba samples it), so that a grazing view draws the normals it
//! sees rather than normals it cannot, whose weights would spike.
//! Directions are in the local frame
//! (z along the macro-surface's normal). pbrt-v4's `scattering.h` is the
//! model.

use crate::math::Vec3;
use crate::sampling::sin_cos_turns;
use std::f32::consts::PI;

/// Below this α the surface is a mirror (a delta lobe): the distribution
/// would be too narrow for `f32`.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// The smallest α a rough distribution uses.
const MIN_ALPHA: f32 = 1e-4;

/// Which distribution of normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Model {
    /// Trowbridge–Reitz: long tails (glTF, Cycles, pbrt-v4).
    #[default]
    Ggx,
    /// Beckmann: a Gaussian of slopes (older scenes, Mitsuba's default).
    Beckmann,
}

/// A distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// α along the tangent (x).
    pub alpha_x: f32,
    /// α along the bitangent (y).
    pub alpha_y: f32,
    /// Which distribution.
    pub model: Model,
}

/// cos²φ and sin²φ of `w`'s azimuth (1, 0 along the normal).
#[inline(always)]
fn cos2_sin2_phi(w: Vec3) -> (f32, f32) {
    let sin2 = w.x * w.x + w.y * w.y;
    if sin2 <= 0.0 {
        (1.0, 0.0)
    } else {
        (w.x * w.x / sin2, w.y * w.y / sin2)
    }
}

/// tan²θ of `w` (infinite at grazing), from sin²θ = x² + y², which keeps
/// its precision near the normal where 1 − cos²θ would lose it (a lobe of
/// α = 0.0025 peaks within 10⁻³ of the normal).
#[inline(always)]
fn tan2_theta(w: Vec3) -> f32 {
    (w.x * w.x + w.y * w.y) / (w.z * w.z)
}

/// The error function, to within 1.5·10⁻⁷ (Abramowitz & Stegun 7.1.26).
#[inline]
fn erf(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_6
            + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152 + t * 1.061_405_4))));
    let y = 1.0 - poly * (-x * x).exp();
    y.copysign(x)
}

/// The widest microfacets (α, or √(αx αy) when anisotropic) that the
/// feature buffers still follow as a mirror (see [`crate::aov`]): what
/// such a surface shows is a sharp reflection of what lies beyond it, not
/// detail of its own. Blender Cycles' threshold for its denoising features;
/// a glTF roughness of about 0.27.
pub const NEAR_MIRROR_ALPHA: f32 = 0.075;

impl Microfacet {
    /// The distribution with widths α (each clamped to at least 10⁻⁴).
    pub fn new(alpha_x: f32, alpha_y: f32, model: Model) -> Self {
        Microfacet {
            alpha_x: alpha_x.max(MIN_ALPHA),
            alpha_y: alpha_y.max(MIN_ALPHA),
            model,
        }
    }

    /// Whether widths α make a mirror rather than a rough surface.
    #[inline]
    pub fn is_smooth(alpha_x: f32, alpha_y: f32) -> bool {
        alpha_x.max(alpha_y) < SMOOTH_ALPHA
    }

    /// Whether it is smooth enough for the feature buffers to look through
    /// it as through a mirror (see [`NEAR_MIRROR_ALPHA`]).
    #[inline]
    pub fn is_near_mirror(&self) -> bool {
        self.alpha_x * self.alpha_y <= NEAR_MIRROR_ALPHA * NEAR_MIRROR_ALPHA
    }

    /// D(wm): the density of microfacet normals per unit projected area of
    /// the macro-surface (∫ D(wm) cos θm dωm = 1).
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        let cos2 = wm.z * wm.z;
        let cos4 = cos2 * cos2;
        if wm.z <= 0.0 || cos4 < 1e-16 {
            return 0.0;
        }
        let tan2 = tan2_theta(wm);
        let (c2, s2) = cos2_sin2_phi(wm);
        let e = tan2 * (c2 / (self.alpha_x * self.alpha_x) + s2 / (self.alpha_y * self.alpha_y));
        match self.model {
            Model::Ggx => 1.0 / (PI * self.alpha_x * self.alpha_y * cos4 * (1.0 + e) * (1.0 + e)),
            Model::Beckmann => (-e).exp() / (PI * self.alpha_x * self.alpha_y * cos4),
        }
    }

    /// Λ(w): the masked microfacet area per visible area, along `w`.
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let tan2 = tan2_theta(w);
        if !tan2.is_finite() {
            return f32::INFINITY;
        }
        let (c2, s2) = cos2_sin2_phi(w);
        let alpha2 = c2 * self.alpha_x * self.alpha_x + s2 * self.alpha_y * self.alpha_y;
        match self.model {
            Model::Ggx => 0.5 * ((1.0 + alpha2 * tan2).sqrt() - 1.0),
            Model::Beckmann => {
                let a = 1.0 / (alpha2 * tan2).sqrt();
                if !a.is_finite() {
                    return 0.0;
                }
                0.5 * (erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt())
            }
        }
    }

    /// G₁(w): the fraction of microfacets seen from `w`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// G(wo, wi): the fraction seen from both `wo` and `wi`
    /// (height-correlated Smith).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density with which [`sample_wm`](Self::sample_wm) draws `wm`
    /// seen from `w` (with `w.z > 0`): that of the visible normals,
    /// G₁(w)/cos θ · D(wm) · max(0, w·wm).
    #[inline]
    pub fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        self.g1(w) / w.z.abs() * self.d(wm) * w.dot(wm).max(0.0)
    }

    /// A microfacet normal seen from `w` (with `w.z > 0`), from `u`
    /// uniform in [0, 1)².
    #[inline]
    pub fn sample_wm(&self, w: Vec3, u: [f32; 2]) -> Vec3 {
        match self.model {
            Model::Ggx => {
                // The visible normals of the stretched (α = 1) surface are
                // a spherical cap's directions plus the view.
                let ws = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
                let z = (1.0 - u[1]) * (1.0 + ws.z) - ws.z;
                let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
                let (s, c) = sin_cos_turns(u[0]);
                let h = Vec3::new(sin_theta * c, sin_theta * s, z) + ws;
                Vec3::new(self.alpha_x * h.x, self.alpha_y * h.y, h.z.max(1e-6)).normalize()
            }
            Model::Beckmann => {
                // Stretched to α = 1, the visible slopes along the view's
                // azimuth and across it are drawn, turned to the view's
                // azimuth, and stretched back.
                let ws = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
                let (x, y) = beckmann_visible_slopes(ws.z, u);
                let r = ws.x.hypot(ws.y);
                let (c, s) = if r > 0.0 {
                    (ws.x / r, ws.y / r)
                } else {
                    (1.0, 0.0)
                };
                let (sx, sy) = (c * x - s * y, s * x + c * y);
                Vec3::new(-self.alpha_x * sx, -self.alpha_y * sy, 1.0).normalize()
            }
        }
    }
}

/// The inverse of the error function on (−1, 1), to about 10⁻⁶ relative
/// (Giles 2010's single-precision fit).
#[inline]
fn erf_inv(x: f32) -> f32 {
    let x = x.clamp(-0.99999, 0.99999);
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        [
            3.432_739_4e-7,
            -3.523_387_7e-6,
            -4.391_506_5e-6,
            2.185_808_7e-4,
            -1.253_725e-3,
            -4.177_681_6e-3,
            0.246_640_73,
            1.501_409_4,
        ]
        .iter()
        .fold(2.810_226_4e-8, |p, &k| k + p * w)
    } else {
        let w = w.sqrt() - 3.0;
        [
            1.009_505_6e-4,
            1.349_343_2e-3,
            -3.673_428_4e-3,
            5.739_507_7e-3,
            -7.622_461_3e-3,
            9.438_870_5e-3,
            1.001_674,
            2.832_976_8,
        ]
        .iter()
        .fold(-2.002_142_6e-4, |p, &k| k + p * w)
    };
    p * x
}

/// Slopes (along the view's azimuth, across it) of the visible normals of
/// the Beckmann surface of α = 1 seen at cosine `cos_theta`, from `u`
/// uniform in [0, 1)²: the first by inverting its distribution (Newton's
/// method kept within a bisection bracket, in the domain of erf), the
/// second a Gaussian.
fn beckmann_visible_slopes(cos_theta: f32, u: [f32; 2]) -> (f32, f32) {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    if sin_theta < 1e-4 {
        // Seen from straight above, the visible slopes are the slopes (a
        // view only a little off would skew them measurably: by tan θ).
        let r = (-(1.0 - u[0]).ln()).sqrt();
        let (s, c) = sin_cos_turns(u[1]);
        return (r * c, r * s);
    }
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = 1.0 / tan_theta;
    // The distribution of b = erf(slope) over [−1, erf(cot θ)]:
    // F(b) = (1 + b + tan θ e^(−erf⁻¹(b)²)/√π) / (1 + c + tan θ e^(−cot²θ)/√π).
    let (mut lo, mut hi) = (-1.0f32, erf(cot_theta));
    let target = u[0].max(1e-6);
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let norm = 1.0 / (1.0 + hi + inv_sqrt_pi * tan_theta * (-cot_theta * cot_theta).exp());
    // A first guess close to the inverse.
    let theta = cos_theta.acos();
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = hi - (1.0 + hi) * (1.0 - target).powf(fit);
    for _ in 0..10 {
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        let slope = erf_inv(b);
        let value = norm * (1.0 + b + inv_sqrt_pi * tan_theta * (-slope * slope).exp()) - target;
        if value.abs() < 1e-5 {
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        b -= value / (norm * (1.0 - slope * tan_theta));
    }
    (erf_inv(b), erf_inv(2.0 * u[1].max(1e-6) - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// ∫ D(wm) cos θm dωm = 1 over the hemisphere, and the visible
    /// normals' density integrates to 1 from every direction: midpoint sums
    /// over a fine grid of θ and φ.
    #[test]
    fn distributions_are_normalised() {
        for model in [Model::Ggx, Model::Beckmann] {
            for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (0.7, 0.2), (1.0, 1.0)] {
                let d = Microfacet::new(ax, ay, model);
                let w = Vec3::new(0.5, 0.2, 0.8).normalize();
                let (nt, np) = (4000, 256);
                let (mut area, mut visible) = (0.0f64, 0.0f64);
                for i in 0..nt {
                    // θ = (π/2)·t², fine near the normal for narrow lobes.
                    let t = (i as f64 + 0.5) / nt as f64;
                    let theta = std::f64::consts::FRAC_PI_2 * t * t;
                    let dtheta = std::f64::consts::PI * t / nt as f64;
                    for j in 0..np {
                        let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
                        let wm = Vec3::new(
                            (theta.sin() * phi.cos()) as f32,
                            (theta.sin() * phi.sin()) as f32,
                            theta.cos() as f32,
                        );
                        let dw = theta.sin() * dtheta * 2.0 * std::f64::consts::PI / np as f64;
                        area += f64::from(d.d(wm)) * theta.cos() * dw;
                        visible += f64::from(d.pdf(w, wm)) * dw;
                    }
                }
                assert!(
                    (area - 1.0).abs() < 3e-3,
                    "{model:?} {ax},{ay}: ∫D cos = {area}"
                );
                assert!(
                    (visible - 1.0).abs() < 3e-3,
                    "{model:?} {ax},{ay}: ∫pdf = {visible}"
                );
            }
        }
    }

    /// The visible slopes of the Beckmann surface (α = 1) seen at θ have
    /// density ∝ max(0, cot θ − x)·e^(−x²) along the view (slope x, the
    /// normal's x being −x): their sampled mean and spread match it.
    #[test]
    fn beckmann_visible_slopes_follow_their_density() {
        for theta in [0.3f64, 1.0, 1.4, 1.55] {
            let cot = 1.0 / theta.tan();
            // The moments by quadrature over x in (−8, cot θ).
            let (mut m0, mut m1, mut m2) = (0.0, 0.0, 0.0);
            let n = 200_000;
            for i in 0..n {
                let x = -8.0 + (cot + 8.0) * (i as f64 + 0.5) / n as f64;
                let p = (cot - x) * (-x * x).exp();
                m0 += p;
                m1 += p * x;
                m2 += p * x * x;
            }
            let (mean, var) = (m1 / m0, m2 / m0 - (m1 / m0).powi(2));
            let mut rng = Rng::new(3);
            let k = 200_000;
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..k {
                let (x, _) =
                    beckmann_visible_slopes(theta.cos() as f32, [rng.next_f32(), rng.next_f32()]);
                assert!(
                    f64::from(x) <= cot + 1e-3,
                    "θ {theta}: slope {x} beyond cot θ {cot}"
                );
                s1 += f64::from(x);
                s2 += f64::from(x) * f64::from(x);
            }
            let got = s1 / k as f64;
            let got_var = s2 / k as f64 - got * got;
            let se = (var / k as f64).sqrt();
            assert!(
                (got - mean).abs() < 5.0 * se,
                "θ {theta}: mean {got} against {mean}"
            );
            assert!(
                (got_var / var - 1.0).abs() < 0.03,
                "θ {theta}: variance {got_var} against {var}"
            );
        }
    }

    /// erf⁻¹ undoes erf across its range.
    #[test]
    fn erf_inv_inverts_erf() {
        for x in [-2.5f32, -1.0, -0.3, 0.0, 0.2, 0.9, 1.7, 2.6] {
            let back = erf_inv(erf(x));
            assert!(
                (back - x).abs() < 2e-3 * (1.0 + x.abs()),
                "erf⁻¹(erf({x})) = {back}"
            );
        }
    }

    /// The error function at known points.
    #[test]
    fn erf_matches_tables() {
        for (x, e) in [
            (0.0, 0.0),
            (0.5, 0.520_499_9),
            (1.0, 0.842_700_8),
            (-2.0, -0.995_322_3),
        ] {
            assert!((erf(x) - e).abs() < 3e-7, "erf({x}) = {}", erf(x));
        }
    }

    /// Sampled normals face up and have the density `pdf` says where they
    /// land (a coarse check; the lobes' χ² tests are the fine one).
    #[test]
    fn sampled_normals_are_in_the_upper_hemisphere() {
        let mut rng = Rng::new(1);
        for model in [Model::Ggx, Model::Beckmann] {
            let d = Microfacet::new(0.4, 0.1, model);
            for _ in 0..10_000 {
                let w = Vec3::new(0.9, -0.3, 0.2).normalize();
                let wm = d.sample_wm(w, rng.next_2d());
                assert!(wm.z > 0.0 && (wm.length() - 1.0).abs() < 1e-5, "{wm}");
                assert!(d.pdf(w, wm) >= 0.0);
            }
        }
    }
}
