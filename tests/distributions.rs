//! Statistical tests of the four diffuse bounce models.
//!
//! Each model is checked against its analytic distribution of cosθ (θ the angle
//! between the bounce direction and the normal): the mean, a second statistic
//! (a Kolmogorov–Smirnov distance or a second moment), and the absence of any
//! preferred tangential direction. Tolerances come from the sample variance
//! (a fixed number of standard errors) or from the DKW inequality; the seeds
//! are fixed, so every run draws the same samples.

use lumen::bsdf::diffuse::bounce_direction;
use lumen::material::BounceModel;
use lumen::math::Vec3;
use lumen::rng::Rng;

/// Standard errors allowed between an estimate and its expected value.
const K: f64 = 5.0;
const N: usize = 1 << 20;

fn normals() -> [Vec3; 2] {
    // The axis-aligned normal the cube model was designed around, and an
    // oblique one (the cube is not rotated with the normal).
    [Vec3::Z, Vec3::new(1.0, -2.0, 3.0).normalize()]
}

/// Mean and standard error of the mean, from the sample variance.
fn mean_and_se(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut n, mut sum, mut sum2) = (0.0f64, 0.0f64, 0.0f64);
    for v in values {
        n += 1.0;
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n;
    let var = (sum2 / n - mean * mean).max(0.0) * n / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// `N` values of cosθ for `model` around `normal`, checking on the way that
/// every direction has unit length.
fn cosines(model: BounceModel, normal: Vec3, seed: u64) -> Vec<f64> {
    let mut rng = Rng::new(seed);
    (0..N)
        .map(|_| {
            let d = bounce_direction(model, normal, &mut rng);
            assert!(
                (d.length() - 1.0).abs() < 1e-5,
                "{model:?}: |d| = {}",
                d.length()
            );
            f64::from(d.dot(normal))
        })
        .collect()
}

fn assert_close(what: &str, estimate: f64, se: f64, expected: f64, extra: f64) {
    let tolerance = K * se + extra;
    assert!(
        (estimate - expected).abs() <= tolerance,
        "{what}: estimate {estimate:.6} vs expected {expected:.6} (tolerance {tolerance:.2e}, se {se:.2e})"
    );
}

/// Largest distance between the empirical CDF of `samples` and `cdf`.
fn ks_distance(mut samples: Vec<f64>, cdf: impl Fn(f64) -> f64) -> f64 {
    samples.sort_by(f64::total_cmp);
    let n = samples.len() as f64;
    samples
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            (f - i as f64 / n).abs().max(((i + 1) as f64 / n - f).abs())
        })
        .fold(0.0, f64::max)
}

/// The DKW inequality P(sup|Fₙ − F| > ε) ≤ 2·exp(−2nε²), solved for ε at a
/// false-alarm probability of 1e-6.
fn ks_threshold(n: usize) -> f64 {
    ((2.0f64 / 1e-6).ln() / (2.0 * n as f64)).sqrt()
}

/// Checks a rotation-invariant model: mean cosθ, the full CDF of cosθ, and
/// that the tangential part of the direction averages to zero.
fn check_model(model: BounceModel, mean_cos: f64, cdf: impl Fn(f64) -> f64 + Copy) {
    for (i, normal) in normals().into_iter().enumerate() {
        let cos = cosines(model, normal, 100 + i as u64);
        // Near-tangent directions come from N + u with u ≈ −N, a sum that
        // cancels in f32; bounce_direction falls back to N before rounding
        // can tip them under the surface.
        let below: Vec<f64> = cos.iter().copied().filter(|&c| c < 0.0).collect();
        assert!(below.is_empty(), "{model:?}: below the surface: {below:?}");
        let (m, se) = mean_and_se(cos.iter().copied());
        assert_close(
            &format!("{model:?} mean cos, N={normal}"),
            m,
            se,
            mean_cos,
            0.0,
        );
        let d = ks_distance(cos, cdf);
        let threshold = ks_threshold(N);
        assert!(
            d < threshold,
            "{model:?}, N={normal}: KS distance {d:.5} above {threshold:.5}"
        );
    }
    // No preferred direction along the surface.
    let normal = normals()[1];
    let tangent = normal.any_orthonormal_vector();
    let bitangent = normal.cross(tangent);
    let mut rng = Rng::new(7);
    let dirs: Vec<Vec3> = (0..N)
        .map(|_| bounce_direction(model, normal, &mut rng))
        .collect();
    for axis in [tangent, bitangent] {
        let (m, se) = mean_and_se(dirs.iter().map(|d| f64::from(d.dot(axis))));
        assert_close(&format!("{model:?} tangential mean"), m, se, 0.0, 0.0);
    }
}

#[test]
fn lambertian_cosine_is_distributed_as_sqrt_of_uniform() {
    // pdf(ω) = cosθ/π ⇒ pdf(μ = cosθ) = 2μ on [0, 1]: mean 2/3, CDF μ².
    check_model(BounceModel::Lambertian, 2.0 / 3.0, |x| {
        x.clamp(0.0, 1.0).powi(2)
    });
}

#[test]
fn hemisphere_cosine_is_uniform() {
    // pdf(ω) = 1/(2π) ⇒ cosθ uniform on [0, 1]: mean 1/2, CDF μ.
    check_model(BounceModel::Hemisphere, 0.5, |x| x.clamp(0.0, 1.0));
}

#[test]
fn sphere_volume_cosine_follows_cos_cubed() {
    // The direction ω from the tangent point p hits the unit ball centred at
    // p + N along a chord of length 2cosθ, so the probability of ω is the
    // ball's volume in that thin cone, ∫₀^{2cosθ} r² dr ∝ cos³θ. Normalised over
    // the hemisphere (∫cos³θ dω = π/2): pdf(ω) = 2cos³θ/π, hence
    // pdf(μ) = 2π·2μ³/π = 4μ³ on [0, 1]: mean 4/5, CDF μ⁴.
    check_model(BounceModel::SphereVolume, 0.8, |x| {
        x.clamp(0.0, 1.0).powi(4)
    });
}

/// E[f(unit(N + c))] for c uniform on the surface of [-1, 1]³, by the midpoint
/// rule on an m×m grid over each of the six (equal-area) faces, in f64.
fn cube_expectation(normal: Vec3, m: usize, f: impl Fn([f64; 3]) -> f64) -> f64 {
    let n = [
        f64::from(normal.x),
        f64::from(normal.y),
        f64::from(normal.z),
    ];
    let h = 2.0 / m as f64;
    let mut total = 0.0;
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut face = 0.0;
            for i in 0..m {
                let a = -1.0 + (i as f64 + 0.5) * h;
                for j in 0..m {
                    let b = -1.0 + (j as f64 + 0.5) * h;
                    let mut c = [a, b, a];
                    c[axis] = sign;
                    c[(axis + 1) % 3] = a;
                    c[(axis + 2) % 3] = b;
                    let q = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
                    let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                    face += f([q[0] / len, q[1] / len, q[2] / len]);
                }
            }
            total += face / (m * m) as f64;
        }
    }
    total / 6.0
}

#[test]
fn cube_moments_match_numeric_integration() {
    for (i, normal) in normals().into_iter().enumerate() {
        let n = [
            f64::from(normal.x),
            f64::from(normal.y),
            f64::from(normal.z),
        ];
        let cos = move |d: [f64; 3]| d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        // The integration error is bounded by comparing two grid sizes (the
        // midpoint rule's error shrinks 4× when the grid doubles).
        let integrate = |f: &dyn Fn([f64; 3]) -> f64| {
            let coarse = cube_expectation(normal, 400, f);
            let fine = cube_expectation(normal, 800, f);
            (fine, (fine - coarse).abs())
        };
        let (mean_cos, err1) = integrate(&|d| cos(d));
        let (mean_cos2, err2) = integrate(&|d| cos(d) * cos(d));

        let samples = cosines(BounceModel::Cube, normal, 200 + i as u64);
        let (m1, se1) = mean_and_se(samples.iter().copied());
        let (m2, se2) = mean_and_se(samples.iter().map(|c| c * c));
        assert_close(
            &format!("cube mean cos, N={normal}"),
            m1,
            se1,
            mean_cos,
            err1,
        );
        assert_close(
            &format!("cube mean cos², N={normal}"),
            m2,
            se2,
            mean_cos2,
            err2,
        );
        if i == 0 {
            // With N = +z the cube [-1,1]²×[0,2] lies above the surface; its
            // bottom face (1/6 of the area) gives exactly tangent directions.
            assert!(samples.iter().all(|&c| c >= 0.0));
            let (p, se) = mean_and_se(samples.iter().map(|&c| f64::from(u8::from(c == 0.0))));
            assert_close("cube tangent fraction", p, se, 1.0 / 6.0, 0.0);
        } else {
            // An oblique normal tilts the axis-aligned cube: some directions
            // point into the surface.
            assert!(samples.iter().any(|&c| c < 0.0));
        }
    }
}

#[test]
fn the_four_models_are_really_different() {
    // The means 1/2 (hemisphere), 2/3 (Lambertian), 4/5 (sphere volume) are
    // far apart compared with the standard errors; the cube lies elsewhere.
    let normal = Vec3::Z;
    let mean = |model| mean_and_se(cosines(model, normal, 300).into_iter()).0;
    let cube = mean(BounceModel::Cube);
    for model in [
        BounceModel::Hemisphere,
        BounceModel::Lambertian,
        BounceModel::SphereVolume,
    ] {
        assert!((mean(model) - cube).abs() > 0.01, "{model:?} vs cube");
    }
}
