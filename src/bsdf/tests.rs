//! The harness every lobe plugs into: χ² of its sampling against its pdf,
//! the consistency of `sample`, `eval` and `pdf`, energy, reciprocity, and
//! no NaN anywhere (pbrt-v4's `bsdfs_test.cpp` method).
//!
//! A lobe is added to the tests by one entry of [`lobes`].

use super::coat::CoatTable;
use super::conductor::Conductor;
use super::dielectric::ExactDielectric;
use super::microfacet::{Microfacet, Model};
use super::plastic::Plastic;
use super::principled::Principled;
use super::{BsdfSample, Lobe};
use crate::math::{Color, Vec3};
use crate::rng::Rng;
use rayon::prelude::*;
use std::f64::consts::PI;

/// A lobe under test and what it is called in messages.
struct Case {
    name: String,
    lobe: Lobe,
}

/// Gold's index of refraction (Mitsuba's RGB).
const GOLD_ETA: Vec3 = Vec3::new(0.143_036, 0.375_307, 1.442_045);
const GOLD_K: Vec3 = Vec3::new(3.982_997, 2.385_556, 1.603_359);

/// The roughnesses tested (α = roughness²), and the anisotropic pairs.
const ROUGHNESSES: [f32; 4] = [0.05, 0.3, 0.7, 1.0];

fn distributions() -> Vec<(String, Microfacet)> {
    let mut out = Vec::new();
    for model in [Model::Ggx, Model::Beckmann] {
        for r in ROUGHNESSES {
            let a = r * r;
            out.push((format!("{model:?} r {r}"), Microfacet::new(a, a, model)));
            // Anisotropic: half as rough along the bitangent.
            let b = 0.5 * r * (0.5 * r);
            out.push((
                format!("{model:?} r {r}/{}", 0.5 * r),
                Microfacet::new(a, b, model),
            ));
        }
    }
    out
}

/// Every lobe with a density, in every configuration the tests cover.
fn lobes() -> Vec<Case> {
    let mut cases = single_scattering_lobes();
    cases.extend(compensated_lobes());
    cases
}

/// The lobes without `multiscatter`: every one is reciprocal.
fn single_scattering_lobes() -> Vec<Case> {
    lobes_with(false)
}

/// The lobes with `multiscatter` (the χ² test needs them not: their
/// densities are the single-scattering ones).
fn compensated_lobes() -> Vec<Case> {
    lobes_with(true)
        .into_iter()
        .filter(|c| c.name.contains("Ggx r 0.7") || c.name.contains("Beckmann r 1"))
        .collect()
}

fn lobes_with(multiscatter: bool) -> Vec<Case> {
    let ms = if multiscatter { " multiscatter" } else { "" };
    let mut cases = Vec::new();
    for (what, d) in distributions() {
        cases.push(Case {
            name: format!("conductor {what}{ms}"),
            lobe: Lobe::Conductor(Conductor {
                eta: GOLD_ETA,
                k: GOLD_K,
                tint: Color::ONE,
                roughness: Some(d),
                multiscatter,
            }),
        });
        for (side, eta) in [("outside", 1.5), ("inside", 1.0 / 1.5)] {
            cases.push(Case {
                name: format!("dielectric {side} {what}{ms}"),
                lobe: Lobe::ExactDielectric(ExactDielectric {
                    eta,
                    roughness: Some(d),
                    multiscatter,
                }),
            });
        }
        // The coat's own table where the material would make one (one
        // isotropic roughness), else the shared tables.
        let tables = if d.alpha_x == d.alpha_y {
            vec![None, Some(CoatTable::of(&d, 1.5))]
        } else {
            vec![None]
        };
        for coat in tables {
            for nonlinear in [true, false] {
                let linear = if nonlinear { "" } else { " linear" };
                let own = if coat.is_some() { " own table" } else { "" };
                cases.push(Case {
                    name: format!("plastic {what}{ms}{linear}{own}"),
                    lobe: Lobe::Plastic(Plastic {
                        albedo: Color::new(0.8, 0.4, 0.2),
                        eta: 1.5,
                        roughness: Some(d),
                        coat,
                        multiscatter,
                        nonlinear,
                    }),
                });
            }
        }
    }
    if !multiscatter {
        cases.push(Case {
            name: "plastic smooth".into(),
            lobe: Lobe::Plastic(Plastic {
                albedo: Color::new(0.8, 0.4, 0.2),
                eta: 1.5,
                roughness: None,
                coat: None,
                multiscatter,
                nonlinear: true,
            }),
        });
    }
    for r in ROUGHNESSES {
        let d = Microfacet::new(r * r, r * r, Model::Ggx);
        for (what, p) in principled_configurations(d) {
            cases.push(Case {
                name: format!("principled {what} r {r}{ms}"),
                lobe: Lobe::Principled(Principled { multiscatter, ..p }),
            });
        }
    }
    cases
}

/// The principled material's layers, each alone and together.
fn principled_configurations(d: Microfacet) -> Vec<(&'static str, Principled)> {
    let base = Principled {
        base_color: Color::new(0.8, 0.4, 0.2),
        metallic: 0.0,
        specular: d,
        f0: Color::splat(0.04),
        f90: 1.0,
        transmission: 0.0,
        eta: 1.5,
        thin: true,
        clearcoat: 0.0,
        coat: Microfacet::new(0.09, 0.09, Model::Ggx),
        coat_normal: Vec3::Z,
        sheen_color: Color::ZERO,
        sheen_roughness: 0.5,
        multiscatter: false,
    };
    let glass = Principled {
        base_color: Color::ONE,
        transmission: 1.0,
        ..base
    };
    vec![
        ("dielectric", base),
        (
            "metal",
            Principled {
                metallic: 1.0,
                base_color: Color::new(1.0, 0.766, 0.336),
                ..base
            },
        ),
        ("thin glass", glass),
        (
            "glass outside",
            Principled {
                thin: false,
                ..glass
            },
        ),
        (
            "glass inside",
            Principled {
                thin: false,
                eta: 1.0 / 1.5,
                ..glass
            },
        ),
        (
            "sheen",
            Principled {
                sheen_color: Color::new(0.9, 0.9, 1.0),
                ..base
            },
        ),
        (
            "coat",
            Principled {
                clearcoat: 1.0,
                coat_normal: Vec3::new(0.2, -0.1, 1.0).normalize(),
                metallic: 0.5,
                ..base
            },
        ),
    ]
}

/// The directions light leaves along in the tests: near the normal,
/// oblique, grazing, and one with an azimuth (for the anisotropic lobes).
fn outgoing() -> [Vec3; 3] {
    let at = |theta: f32, phi: f32| {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    [at(10.0, 30.0), at(50.0, 100.0), at(80.0, 200.0)]
}

// ---------------------------------------------------------------- χ² ---

const THETA_RES: usize = 40;
const PHI_RES: usize = 80;
const SAMPLES: usize = 1_000_000;

/// A histogram of directions about an axis: θ from the axis warped as
/// θ = π t² (fine near the axis, where narrow lobes peak), φ uniform.
struct Histogram {
    frame: super::Frame,
}

impl Histogram {
    fn new(axis: Vec3) -> Self {
        Histogram {
            frame: super::Frame::from_normal(axis.normalize()),
        }
    }

    fn cell(&self, w: Vec3) -> usize {
        let l = self.frame.to_local(w);
        // From the sine, not acos(z): near the axis, where a narrow lobe
        // peaks, z = cos θ rounds to steps of 10⁻⁸ and θ to steps of 10⁻⁴.
        let (x, y, z) = (f64::from(l.x), f64::from(l.y), f64::from(l.z));
        let theta = (x * x + y * y).sqrt().atan2(z);
        let t = (theta / PI).sqrt();
        let phi = f64::from(l.y).atan2(f64::from(l.x)).rem_euclid(2.0 * PI);
        let i = ((t * THETA_RES as f64) as usize).min(THETA_RES - 1);
        let j = ((phi / (2.0 * PI) * PHI_RES as f64) as usize).min(PHI_RES - 1);
        i * PHI_RES + j
    }

    /// The direction at warped coordinates (t, φ).
    fn direction(&self, t: f64, phi: f64) -> Vec3 {
        let theta = PI * t * t;
        let l = Vec3::new(
            (theta.sin() * phi.cos()) as f32,
            (theta.sin() * phi.sin()) as f32,
            theta.cos() as f32,
        );
        self.frame.to_world(l)
    }

    /// ∫ pdf dω over every cell, by adaptive Simpson in t and φ.
    fn expected(&self, pdf: &(dyn Fn(Vec3) -> f64 + Sync)) -> Vec<f64> {
        (0..THETA_RES * PHI_RES)
            .into_par_iter()
            .map(|c| {
                let (i, j) = (c / PHI_RES, c % PHI_RES);
                let (t0, t1) = (
                    i as f64 / THETA_RES as f64,
                    (i + 1) as f64 / THETA_RES as f64,
                );
                let dp = 2.0 * PI / PHI_RES as f64;
                let (p0, p1) = (j as f64 * dp, (j + 1) as f64 * dp);
                let integrand = |t: f64, phi: f64| {
                    let theta = PI * t * t;
                    pdf(self.direction(t, phi)) * theta.sin() * 2.0 * PI * t
                };
                simpson_2d(&integrand, t0, t1, p0, p1)
            })
            .collect()
    }
}

/// Adaptive Simpson quadrature of `f` over [a, b] (Lyness's test, with
/// Richardson's correction), splitting at most `depth` times.
fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, eps: f64, depth: u32) -> f64 {
    /// An interval with f at its ends and middle, and its Simpson estimate.
    struct Piece {
        a: f64,
        b: f64,
        f: [f64; 3],
        whole: f64,
        eps: f64,
        depth: u32,
    }
    let fs = [f(a), f(0.5 * (a + b)), f(b)];
    let whole = (b - a) / 6.0 * (fs[0] + 4.0 * fs[1] + fs[2]);
    let mut stack = vec![Piece {
        a,
        b,
        f: fs,
        whole,
        eps: eps.max(1e-5 * whole.abs()),
        depth,
    }];
    let mut total = 0.0;
    while let Some(p) = stack.pop() {
        let m = 0.5 * (p.a + p.b);
        let (fl, fr) = (f(0.5 * (p.a + m)), f(0.5 * (m + p.b)));
        let left = (m - p.a) / 6.0 * (p.f[0] + 4.0 * fl + p.f[1]);
        let right = (p.b - m) / 6.0 * (p.f[1] + 4.0 * fr + p.f[2]);
        let both = left + right;
        if p.depth == 0 || (both - p.whole).abs() <= 15.0 * p.eps {
            total += both + (both - p.whole) / 15.0;
            continue;
        }
        let (eps, depth) = (0.5 * p.eps, p.depth - 1);
        stack.push(Piece {
            a: p.a,
            b: m,
            f: [p.f[0], fl, p.f[1]],
            whole: left,
            eps,
            depth,
        });
        stack.push(Piece {
            a: m,
            b: p.b,
            f: [p.f[1], fr, p.f[2]],
            whole: right,
            eps,
            depth,
        });
    }
    total
}

/// Nested adaptive Simpson over a rectangle, each direction split in two
/// first so that a narrow peak inside a cell is not stepped over.
fn simpson_2d(f: &dyn Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let halves = |a: f64, b: f64| [(a, 0.5 * (a + b)), (0.5 * (a + b), b)];
    let outer = |x: f64| {
        let inner = |y: f64| f(x, y);
        halves(y0, y1)
            .iter()
            .map(|&(a, b)| simpson(&inner, a, b, 1e-10, 6))
            .sum::<f64>()
    };
    halves(x0, x1)
        .iter()
        .map(|&(a, b)| simpson(&outer, a, b, 1e-10, 6))
        .sum()
}

/// The regularised upper incomplete gamma function Q(a, x) (Numerical
/// Recipes' series and continued fraction): the χ² p-value is
/// Q(dof/2, χ²/2).
fn gamma_q(a: f64, x: f64) -> f64 {
    let ln_gamma = |z: f64| {
        // Lanczos (g = 7, n = 9).
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let z = z - 1.0;
        let mut s = C[0];
        for (i, c) in C.iter().enumerate().skip(1) {
            s += c / (z + i as f64);
        }
        let t = z + 7.5;
        0.5 * (2.0 * PI).ln() + (z + 0.5) * t.ln() - t + s.ln()
    };
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut sum, mut term, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * front
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        front * h
    }
}

/// Pearson's χ² test of `observed` against `expected` (cells expected to
/// hold fewer than 5 pooled, as pbrt does): the p-value, or why the test
/// cannot pass.
fn chi2_p_value(observed: &[u64], expected: &[f64]) -> Result<f64, String> {
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut chsq, mut dof) = (0.0, 0i64);
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    for &c in &order {
        let (o, e) = (observed[c] as f64, expected[c]);
        if e <= 0.0 {
            if o > SAMPLES as f64 * 1e-5 {
                return Err(format!("{o} samples in a cell of expected frequency 0"));
            }
        } else if e < 5.0 || (pooled_exp > 0.0 && pooled_exp < 5.0) {
            pooled_obs += o;
            pooled_exp += e;
        } else {
            chsq += (o - e).powi(2) / e;
            dof += 1;
        }
    }
    if pooled_exp > 0.0 {
        chsq += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
        dof += 1;
    }
    // The counts add up to the samples drawn: one degree of freedom less.
    // All in one cell (a narrow lobe glass transmits from inside past the
    // critical angle) leaves none: that cell's count is then tested alone.
    dof = (dof - 1).max(1);
    Ok(gamma_q(dof as f64 / 2.0, chsq / 2.0))
}

/// The direction light from `wo` mirrors to, and the one it refracts to
/// through a smooth interface of `eta` (if it can).
fn peaks(lobe: &Lobe, wo: Vec3) -> (Vec3, Option<Vec3>) {
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let refracted = match lobe {
        Lobe::ExactDielectric(d) => super::fresnel::refract(wo, Vec3::Z, d.eta).map(|(w, _)| w),
        Lobe::Principled(p) if !p.thin => {
            super::fresnel::refract(wo, Vec3::Z, p.eta).map(|(w, _)| w)
        }
        _ => None,
    };
    (mirror, refracted)
}

/// The χ² test of one lobe from one direction: samples binned in one
/// histogram about the mirror direction (reflections) and one about the
/// refracted direction (transmissions); the p-values.
fn chi2(lobe: &Lobe, wo: Vec3, seed: u64) -> Result<Vec<f64>, String> {
    let (mirror, refracted) = peaks(lobe, wo);
    let reflect = Histogram::new(mirror);
    let transmit = Histogram::new(refracted.unwrap_or(-wo));
    let mut counts = [
        vec![0u64; THETA_RES * PHI_RES],
        vec![0u64; THETA_RES * PHI_RES],
    ];
    let mut rng = Rng::new(seed);
    for _ in 0..SAMPLES {
        let uc = rng.next_f32();
        let u = rng.next_2d();
        let Some(s) = lobe.sample_local(wo, uc, u) else {
            continue;
        };
        if s.flags.is_specular() {
            continue;
        }
        if s.wi.z * wo.z > 0.0 {
            counts[0][reflect.cell(s.wi)] += 1;
        } else {
            counts[1][transmit.cell(s.wi)] += 1;
        }
    }
    let mut p = Vec::new();
    for (k, h) in [&reflect, &transmit].into_iter().enumerate() {
        let pdf = |w: Vec3| {
            let same = w.z * wo.z > 0.0;
            if same != (k == 0) {
                return 0.0;
            }
            f64::from(lobe.eval_and_pdf_local(wo, w).1)
        };
        let expected: Vec<f64> = h
            .expected(&pdf)
            .iter()
            .map(|e| e * SAMPLES as f64)
            .collect();
        // Too few samples expected on a side for a χ² test (glass seen
        // from inside at grazing angles reflects nearly all): their number
        // is checked instead.
        let (observed, total) = (
            counts[k].iter().sum::<u64>() as f64,
            expected.iter().sum::<f64>(),
        );
        if total < 50.0 {
            if (observed - total).abs() > 4.0 * total.sqrt() + 5.0 {
                return Err(format!("{observed} samples on side {k}, {total} expected"));
            }
            continue;
        }
        p.push(chi2_p_value(&counts[k], &expected)?);
    }
    Ok(p)
}

/// Every lobe's directions fall where its pdf says, from several
/// directions, at every roughness, isotropic and anisotropic, from outside
/// and inside for dielectrics: p-values above 0.01, Šidák-corrected for
/// the number of tests.
#[test]
fn every_lobe_samples_its_pdf() {
    let cases = single_scattering_lobes();
    let runs: Vec<(usize, usize)> = (0..cases.len())
        .flat_map(|c| (0..outgoing().len()).map(move |w| (c, w)))
        .collect();
    let results: Vec<(String, Result<Vec<f64>, String>)> = runs
        .par_iter()
        .map(|&(c, w)| {
            let wo = outgoing()[w];
            let name = format!("{} from {wo}", cases[c].name);
            (name, chi2(&cases[c].lobe, wo, (c * 7 + w) as u64))
        })
        .collect();
    let tests: usize = results
        .iter()
        .map(|(_, r)| r.as_ref().map_or(1, Vec::len))
        .sum();
    let level = 1.0 - (1.0f64 - 0.01).powf(1.0 / tests as f64);
    let failures: Vec<String> = results
        .iter()
        .filter_map(|(name, r)| match r {
            Err(e) => Some(format!("{name}: {e}")),
            Ok(ps) if ps.iter().any(|&p| !(p >= level)) => Some(format!("{name}: p = {ps:?}")),
            Ok(_) => None,
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {tests} χ² tests below p = {level:.2e}:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

// ------------------------------------------------ consistency, energy ---

/// Directions spread over the sphere (and a few grazing ones).
fn directions(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = (0..n)
        .map(|_| crate::sampling::unit_vector(rng.next_2d()))
        .collect();
    out.extend([
        Vec3::new(1.0, 0.0, 1e-6).normalize(),
        Vec3::new(0.0, 1.0, -1e-6).normalize(),
        Vec3::Z,
        -Vec3::Z,
    ]);
    out
}

/// The value a sample carries is eval·|cos|/pdf at its direction, its pdf
/// is `pdf` there, and nothing is NaN or negative, from any direction
/// (grazing ones too).
#[test]
fn samples_agree_with_eval_and_pdf() {
    let mut rng = Rng::new(11);
    for case in lobes() {
        for wo in directions(&mut rng, 40) {
            for _ in 0..200 {
                let (uc, u) = (rng.next_f32(), rng.next_2d());
                let Some(s) = case.lobe.sample_local(wo, uc, u) else {
                    continue;
                };
                let BsdfSample { value, wi, pdf, .. } = s;
                assert!(
                    value.is_finite() && value.min_element() >= 0.0 && pdf > 0.0,
                    "{}: wo {wo}: {s:?}",
                    case.name
                );
                // A delta (a smooth coat's mirror) has no density to agree
                // with.
                if s.flags.is_specular() {
                    continue;
                }
                assert!(
                    (wi.length() - 1.0).abs() < 1e-4,
                    "{}: |wi| {}",
                    case.name,
                    wi.length()
                );
                let (f, p) = case.lobe.eval_and_pdf_local(wo, wi);
                let close = |a: f32, b: f32| (a - b).abs() <= 2e-3 * a.abs().max(b.abs()) + 1e-6;
                assert!(
                    close(p, pdf),
                    "{}: wo {wo} wi {wi}: pdf {p} vs {pdf}",
                    case.name
                );
                let expect = f / p;
                for c in 0..3 {
                    assert!(
                        close(expect[c], value[c]),
                        "{}: wo {wo} wi {wi}: eval/pdf {expect} vs value {value}",
                        case.name
                    );
                }
            }
            // Any direction at all: finite, not negative.
            for wi in directions(&mut rng, 20) {
                let (f, p) = case.lobe.eval_and_pdf_local(wo, wi);
                assert!(
                    f.is_finite() && f.min_element() >= 0.0 && p.is_finite() && p >= 0.0,
                    "{}: wo {wo} wi {wi}: {f} {p}",
                    case.name
                );
            }
        }
    }
}

/// The factor that turns radiance carried from `wi` to `wo` back into the
/// power it is: a transmission compresses radiance by (η_o/η_i)², which
/// energy does not see.
fn importance(lobe: &Lobe, wo: Vec3, wi: Vec3) -> f32 {
    match lobe {
        Lobe::ExactDielectric(d) if wo.z * wi.z < 0.0 => {
            let etap = if wo.z > 0.0 { d.eta } else { 1.0 / d.eta };
            etap * etap
        }
        Lobe::Principled(p) if !p.thin && wo.z * wi.z < 0.0 => p.eta * p.eta,
        _ => 1.0,
    }
}

/// The mean of f·cos/pdf over samples (the directional albedo) is at most
/// 1 in every channel, within three standard errors, from random
/// directions (transmitted radiance counted as power).
#[test]
fn no_lobe_reflects_more_than_it_receives() {
    let mut rng = Rng::new(12);
    // An anisotropic surface's compensation is looked up at its mean
    // width, which returns too much at some views (see `albedo`).
    let cases = lobes()
        .into_iter()
        .filter(|c| !(c.name.contains("multiscatter") && c.name.contains('/')));
    for case in cases {
        // The glTF BRDF weighs its base by 1 − F at the half vector, not at
        // the view: at grazing views it reflects more than it receives.
        let least = if case.name.starts_with("principled") {
            PRINCIPLED_GRAZING.to_radians().cos()
        } else {
            1e-3
        };
        for wo in directions(&mut rng, 6).into_iter().filter(|w| w.z > least) {
            let n = 20_000;
            let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
            for _ in 0..n {
                let v = case
                    .lobe
                    .sample_local(wo, rng.next_f32(), rng.next_2d())
                    .map_or(Color::ZERO, |s| s.value * importance(&case.lobe, wo, s.wi));
                for c in 0..3 {
                    sum[c] += f64::from(v[c]);
                    sum2[c] += f64::from(v[c]) * f64::from(v[c]);
                }
            }
            for c in 0..3 {
                let mean = sum[c] / n as f64;
                let se = ((sum2[c] / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
                assert!(
                    mean <= 1.0 + 3.0 * se + 1e-3,
                    "{}: wo {wo}: albedo {mean} ± {se} in channel {c}",
                    case.name
                );
            }
        }
    }
}

/// Beyond this angle of view (degrees) the glTF BRDF may reflect more
/// than it receives: its base is weighed by 1 − F at the half vector, and
/// a near-smooth surface of base colour 0.8 seen at 80° reflects 1.17 of
/// the light, at 87° 1.52 (docs/materials.md).
const PRINCIPLED_GRAZING: f32 = 70.0;

/// f(wo, wi) = f(wi, wo) for every reflection (eval gives f·|cos θi|).
#[test]
fn reflection_is_reciprocal() {
    let mut rng = Rng::new(13);
    // The coat's weight is its Fresnel at the view alone, as glTF defines
    // it: not reciprocal.
    let cases = single_scattering_lobes()
        .into_iter()
        .filter(|c| !c.name.contains("coat"));
    for case in cases {
        for _ in 0..2000 {
            let wo = crate::sampling::on_hemisphere(rng.next_2d(), Vec3::Z);
            let wi = crate::sampling::on_hemisphere(rng.next_2d(), Vec3::Z);
            if wo.z < 1e-3 || wi.z < 1e-3 {
                continue;
            }
            let a = case.lobe.eval_and_pdf_local(wo, wi).0 / wi.z;
            let b = case.lobe.eval_and_pdf_local(wi, wo).0 / wo.z;
            assert!(
                (a - b).abs().max_element() <= 1e-3 * a.max_element().max(1e-3),
                "{}: f({wo}, {wi}) = {a} but f({wi}, {wo}) = {b}",
                case.name
            );
        }
    }
}

/// Directional albedo by quadrature of eval over the sphere, an estimate
/// independent of the sampling routine.
pub(crate) fn albedo_by_quadrature(lobe: &Lobe, wo: Vec3) -> Color {
    let (mirror, refracted) = peaks(lobe, wo);
    let mut total = Color::ZERO;
    let below = refracted.unwrap_or(Vec3::new(wo.x, wo.y, -wo.z));
    for (k, axis) in [mirror, below].into_iter().enumerate() {
        let h = Histogram::new(axis);
        let (nt, np) = (400, 400);
        for i in 0..nt {
            let t = (i as f64 + 0.5) / nt as f64;
            let theta = PI * t * t;
            let dw = theta.sin() * 2.0 * PI * t / nt as f64 * (2.0 * PI / np as f64);
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let wi = h.direction(t, phi);
                if (wi.z * wo.z > 0.0) == (k == 0) {
                    total += lobe.eval_and_pdf_local(wo, wi).0 * dw as f32;
                }
            }
        }
    }
    total
}

/// The sampled albedo (the mean value of the samples) agrees with the
/// albedo by quadrature of eval: the single-scattering loss of each rough
/// lobe, measured two independent ways.
#[test]
fn sampled_albedo_matches_quadrature() {
    let cases: Vec<Case> = lobes()
        .into_iter()
        .filter(|c| !c.name.contains("r 0.05"))
        .collect();
    let failures: Vec<String> = cases
        .par_iter()
        .flat_map(|case| {
            let mut out = Vec::new();
            for wo in [
                Vec3::new(0.3, 0.1, 0.9).normalize(),
                Vec3::new(0.9, 0.0, 0.3).normalize(),
            ] {
                let quad = albedo_by_quadrature(&case.lobe, wo);
                let mut rng = Rng::new(case.name.len() as u64);
                let n = 100_000;
                let (mut sum, mut sum2) = (Color::ZERO, Color::ZERO);
                for _ in 0..n {
                    // The deltas are not in the quadrature of eval.
                    let v = case
                        .lobe
                        .sample_local(wo, rng.next_f32(), rng.next_2d())
                        .filter(|s| !s.flags.is_specular())
                        .map_or(Color::ZERO, |s| s.value);
                    sum += v;
                    sum2 += v * v;
                }
                let mean = sum / n as f32;
                let se = ((sum2 / n as f32 - mean * mean).max(Color::ZERO) / n as f32).powf(0.5);
                for c in 0..3 {
                    if (mean[c] - quad[c]).abs() > 4.0 * se[c] + 2e-3 {
                        out.push(format!(
                            "{} wo {wo}: sampled {mean} ± {se}, quadrature {quad}",
                            case.name
                        ));
                        break;
                    }
                }
            }
            out
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A white conductor with `multiscatter` reflects everything it receives,
/// within 1%, at every roughness and from near the normal to 80°; without
/// it, it loses what the albedo table says it loses (the table built by
/// quadrature of the sampling, compared here with independent sampling).
#[test]
fn white_furnace_with_multiscatter() {
    for model in [Model::Ggx, Model::Beckmann] {
        for r in [0.05f32, 0.3, 0.5, 0.7, 0.9, 1.0] {
            let d = Microfacet::new(r * r, r * r, model);
            for theta in [0.0f32, 30.0, 60.0, 80.0] {
                let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
                let albedo = |multiscatter| {
                    let lobe = Lobe::Conductor(Conductor {
                        eta: Vec3::ZERO,
                        k: Vec3::ONE,
                        tint: Color::ONE,
                        roughness: Some(d),
                        multiscatter,
                    });
                    // Jittered on a 300 × 300 grid: the estimate's own
                    // error is far below the 1% tested.
                    let mut rng = Rng::new(u64::from(theta.to_bits()));
                    let n = 300;
                    let sum: f64 = (0..n * n)
                        .map(|k| {
                            let [a, b] = rng.next_2d();
                            let u = [
                                ((k % n) as f32 + a) / n as f32,
                                ((k / n) as f32 + b) / n as f32,
                            ];
                            lobe.sample_local(wo, 0.5, u)
                                .map_or(0.0, |s| f64::from(s.value.x))
                        })
                        .sum();
                    sum / (n * n) as f64
                };
                let (with, without) = (albedo(true), albedo(false));
                assert!(
                    (with - 1.0).abs() < 0.01,
                    "{model:?} r {r} at {theta}°: white furnace {with}"
                );
                let table = f64::from(super::albedo::conductor(&d, wo.z));
                assert!(
                    (without - table).abs() < 0.01,
                    "{model:?} r {r} at {theta}°: sampled loss {without}, table {table}"
                );
            }
        }
    }
}

/// A clear rough dielectric with `multiscatter` transmits and reflects,
/// counted as power, everything it receives, from outside and inside.
#[test]
fn white_furnace_of_glass_with_multiscatter() {
    for r in [0.3f32, 0.7, 1.0] {
        let d = Microfacet::new(r * r, r * r, Model::Ggx);
        for eta in [1.5f32, 1.0 / 1.5, 2.4] {
            let lobe = Lobe::ExactDielectric(ExactDielectric {
                eta,
                roughness: Some(d),
                multiscatter: true,
            });
            for theta in [10.0f32, 50.0] {
                let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
                let mut rng = Rng::new(7);
                let n = 40_000;
                let sum: f64 = (0..n)
                    .map(|_| {
                        lobe.sample_local(wo, rng.next_f32(), rng.next_2d())
                            .map_or(0.0, |s| f64::from(s.value.x * importance(&lobe, wo, s.wi)))
                    })
                    .sum();
                let e = sum / n as f64;
                assert!((e - 1.0).abs() < 0.015, "r {r} η {eta} at {theta}°: {e}");
            }
        }
    }
}

/// The glTF BRDF with metallic 1 is the conductor the specification
/// gives: GGX microfacets, height-correlated Smith, Schlick's Fresnel from
/// the base colour, evaluated here from those terms directly (with the
/// Trowbridge–Reitz D and Smith Λ written out, not the lobe's code).
#[test]
fn principled_metal_is_the_specifications_conductor() {
    let mut rng = Rng::new(21);
    for r in [0.2f32, 0.5, 0.9] {
        let a = r * r;
        let d = Microfacet::new(a, a, Model::Ggx);
        let base_color = Color::new(0.95, 0.64, 0.54);
        let lobe = Lobe::Principled(Principled {
            metallic: 1.0,
            base_color,
            ..principled_configurations(d)[0].1
        });
        for _ in 0..500 {
            let wo = crate::sampling::on_hemisphere(rng.next_2d(), Vec3::Z);
            let wi = crate::sampling::on_hemisphere(rng.next_2d(), Vec3::Z);
            if wo.z < 0.05 || wi.z < 0.05 {
                continue;
            }
            let h = (wo + wi).normalize();
            let a2 = f64::from(a * a);
            let cos_h = f64::from(h.z);
            let dd = a2 / (PI * (cos_h * cos_h * (a2 - 1.0) + 1.0).powi(2));
            let lambda = |c: f32| {
                let c = f64::from(c);
                let t2 = (1.0 - c * c) / (c * c);
                0.5 * ((1.0 + a2 * t2).sqrt() - 1.0)
            };
            let g = 1.0 / (1.0 + lambda(wo.z) + lambda(wi.z));
            let f5 = (1.0 - f64::from(wo.dot(h))).powi(5);
            let expect: [f64; 3] = std::array::from_fn(|c| {
                let f0 = f64::from(base_color[c]);
                let fresnel = f0 + (1.0 - f0) * f5;
                fresnel * dd * g / (4.0 * f64::from(wo.z))
            });
            let got = lobe.eval_and_pdf_local(wo, wi).0;
            for c in 0..3 {
                let e = expect[c];
                assert!(
                    (f64::from(got[c]) - e).abs() <= 2e-4 * e.max(1e-3),
                    "r {r}: wo {wo} wi {wi}: {got} against {expect:?}"
                );
            }
        }
    }
}

/// A clear coat whose normal is tilted from the base's (a normal-mapped
/// base under an unmapped coat) reflects its Fresnel weight, whatever the
/// tilt and the view: over a black base, a near-mirror coat returns
/// 0.04 + 0.96 (1 − wo·n_coat)⁵ of the light (its microfacets lose
/// nothing at roughness 0.05). A coat taking the base's cosine instead of
/// its own reflects 0.023 seen along the base's normal with a 30° tilt.
#[test]
fn a_tilted_coat_reflects_its_fresnel_weight() {
    let tilt = 30f32.to_radians();
    let coat_normal = Vec3::new(tilt.sin(), 0.0, tilt.cos());
    let lobe = Lobe::Principled(Principled {
        base_color: Color::ZERO,
        f0: Color::ZERO,
        f90: 0.0,
        clearcoat: 1.0,
        coat: Microfacet::new(0.0025, 0.0025, Model::Ggx),
        coat_normal,
        ..principled_configurations(Microfacet::new(0.25, 0.25, Model::Ggx))[0].1
    });
    let mut rng = Rng::new(5);
    for view in [0f32, 30.0, 60.0] {
        let v = view.to_radians();
        let wo = Vec3::new(v.sin(), 0.0, v.cos());
        let c = wo.dot(coat_normal);
        let expect = 0.04 + 0.96 * (1.0 - c).powi(5);
        let n = 20_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let v = lobe
                .sample_local(wo, rng.next_f32(), rng.next_2d())
                .map_or(0.0, |s| f64::from(s.value.x));
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        assert!(
            (mean - f64::from(expect)).abs() <= 4.0 * se + 2e-3 * f64::from(expect),
            "seen at {view}°: reflects {mean} ± {se}, its Fresnel weight is {expect}"
        );
    }
}

/// As its roughness falls to zero, a conductor's samples close in on the
/// mirror direction and its reflectance on the mirror's Fresnel
/// reflectance.
#[test]
fn a_conductor_smooths_into_its_mirror() {
    let wo = Vec3::new(0.5, 0.2, 0.8).normalize();
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let fresnel = super::fresnel::conductor(wo.z, GOLD_ETA, GOLD_K);
    let mut last_angle = f64::INFINITY;
    for alpha in [0.1f32, 0.03, 0.01, 0.003] {
        let lobe = Lobe::Conductor(Conductor {
            eta: GOLD_ETA,
            k: GOLD_K,
            tint: Color::ONE,
            roughness: Some(Microfacet::new(alpha, alpha, Model::Ggx)),
            multiscatter: false,
        });
        let mut rng = Rng::new(5);
        let n = 20_000;
        let (mut angle, mut value, mut m) = (0.0f64, Color::ZERO, 0);
        for _ in 0..n {
            // (A sample below the horizon reflects nothing.)
            if let Some(s) = lobe.sample_local(wo, 0.5, rng.next_2d()) {
                angle += f64::from(s.wi.dot(mirror).clamp(-1.0, 1.0).acos());
                value += s.value;
                m += 1;
            }
        }
        let (angle, value) = (angle / m as f64, value / n as f32);
        // The mean deviation is a few α (in radians: reflection doubles the
        // microfacet's tilt, and GGX has long tails); the reflectance
        // within the shadowing lost at that width.
        assert!(
            angle < last_angle && angle < 4.0 * f64::from(alpha),
            "α {alpha}: {angle}"
        );
        assert!(
            (value - fresnel).abs().max_element() < 2.0 * alpha + 1e-3,
            "α {alpha}: {value} against the mirror's {fresnel}"
        );
        last_angle = angle;
    }
}

/// No lobe gives a NaN, an infinity or a negative value at the edges of
/// its parameters: roughness 0 and 1, an index of 1 (no interface), views
/// and lights at grazing angles, and a shading normal tilted below the
/// true surface (a normal map's, a smoothed mesh's) seen from either side.
#[test]
fn no_nan_at_the_edges() {
    let smooth = Microfacet::new(0.0, 0.0, Model::Ggx);
    let rough = Microfacet::new(1.0, 1.0, Model::Beckmann);
    let mut lobes = vec![
        Lobe::Conductor(Conductor {
            eta: GOLD_ETA,
            k: GOLD_K,
            tint: Color::ONE,
            roughness: Some(smooth),
            multiscatter: true,
        }),
        Lobe::Conductor(Conductor {
            eta: Vec3::ZERO,
            k: Vec3::ZERO,
            tint: Color::ONE,
            roughness: None,
            multiscatter: false,
        }),
    ];
    // Roughness 0 given as no microfacets at all (a delta), as well as the
    // smallest and the largest α.
    for d in [None, Some(smooth), Some(rough)] {
        for eta in [1.0f32, 1.0 + 1e-6, 1.5, 1000.0] {
            lobes.push(Lobe::ExactDielectric(ExactDielectric {
                eta,
                roughness: d,
                multiscatter: d.is_some(),
            }));
            if d.is_none() {
                lobes.push(Lobe::ThinDielectric(
                    super::thin_dielectric::ThinDielectric { eta },
                ));
            }
            lobes.push(Lobe::Plastic(Plastic {
                albedo: Color::ONE,
                eta: eta.min(super::albedo::ETA_MAX),
                roughness: d,
                coat: None,
                multiscatter: d.is_some(),
                nonlinear: true,
            }));
            let Some(d) = d else {
                continue;
            };
            for (_, p) in principled_configurations(d) {
                lobes.push(Lobe::Principled(Principled {
                    eta,
                    multiscatter: true,
                    sheen_color: Color::ONE,
                    sheen_roughness: super::sheen::MIN_ROUGHNESS,
                    ..p
                }));
            }
        }
    }
    let mut rng = Rng::new(31);
    // Frames whose normal is tilted up to 89° from the true surface's, so
    // that some views are above one and below the other.
    let frames: Vec<(super::Frame, Vec3)> = [0.0f32, 1.2, 1.55]
        .iter()
        .map(|&tilt| {
            let n = Vec3::new(tilt.sin(), 0.0, tilt.cos());
            (super::Frame::from_normal_tangent(n, Vec3::X), Vec3::Z)
        })
        .collect();
    for lobe in &lobes {
        for &(frame, ng) in &frames {
            let bsdf = super::Bsdf::new(frame, ng, *lobe);
            for wo in directions(&mut rng, 30) {
                for wi in directions(&mut rng, 10) {
                    let (f, pdf) = bsdf.eval_and_pdf(wo, wi);
                    assert!(
                        f.is_finite() && f.min_element() >= 0.0 && pdf.is_finite() && pdf >= 0.0,
                        "{lobe:?}: wo {wo} wi {wi}: {f} {pdf}"
                    );
                }
                for _ in 0..20 {
                    if let Some(s) =
                        lobe.sample_local(frame.to_local(wo), rng.next_f32(), rng.next_2d())
                    {
                        assert!(
                            s.value.is_finite() && s.value.min_element() >= 0.0 && s.pdf >= 0.0,
                            "{lobe:?}: wo {wo}: {s:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn feature_buffers_look_through_near_mirrors_only() {
    let wo = Vec3::new(0.3, 0.0, 0.954).normalize();
    let plastic = |albedo: f32, roughness: Option<Microfacet>| {
        Lobe::Plastic(Plastic {
            albedo: Color::splat(albedo),
            eta: 1.5,
            roughness,
            coat: None,
            multiscatter: false,
            nonlinear: true,
        })
    };
    let near = Microfacet::new(0.05, 0.05, Model::Ggx);
    let rough = Microfacet::new(0.2, 0.2, Model::Ggx);
    // A black base under a smooth or near-mirror coat shows only its
    // coat's reflection; a white one is mostly its base; a rough coat is
    // never looked through.
    for coat in [None, Some(near)] {
        assert_eq!(plastic(0.0, coat).feature_albedo_seen(wo), None);
        assert!(plastic(0.8, coat).feature_albedo_seen(wo).is_some());
    }
    assert!(plastic(0.0, Some(rough)).feature_albedo_seen(wo).is_some());
    let gold = |m| {
        Lobe::Conductor(Conductor {
            eta: Color::new(0.2, 0.4, 1.4),
            k: Color::new(3.6, 2.4, 1.8),
            tint: Color::ONE,
            roughness: Some(m),
            multiscatter: false,
        })
    };
    assert_eq!(gold(near).feature_albedo_seen(wo), None);
    assert_eq!(
        gold(rough).feature_albedo_seen(wo),
        Some(gold(rough).feature_albedo())
    );
    // The anisotropic width is the geometric mean: 0.2 × 0.02 is a near
    // mirror (√0.004 ≈ 0.063).
    assert_eq!(
        gold(Microfacet::new(0.2, 0.02, Model::Ggx)).feature_albedo_seen(wo),
        None
    );
}
