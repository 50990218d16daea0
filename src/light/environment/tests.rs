use super::*;
use crate::rng::Rng;
use crate::testing::{chi_square, chi_square_bound};

/// z for a two-sided bound that a correct estimate exceeds about once in
/// 10⁴ runs.
const K: f64 = 3.9;

/// A map whose texels vary over four orders of magnitude, with black
/// texels and a bright "sun", so that the distribution has real structure.
fn test_map(rotation: f32) -> EnvironmentMap {
    let (w, h) = (16, 8);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (x, y) == (11, 2) {
                Color::new(400.0, 300.0, 200.0)
            } else if x % 5 == 0 && y > 3 {
                Color::ZERO
            } else {
                Color::new(0.1 + x as f32 * 0.05, 0.2 + y as f32 * 0.1, 0.3)
            }
        })
        .collect();
    EnvironmentMap::new(Image::new(w, h, texels), rotation, 1.5).expect("a map of light")
}

/// Directions drawn from `env` fall into cells of equal solid angle
/// (bands of y by sectors of azimuth) as often as its density, integrated
/// over each cell by the midpoint rule on a fine grid, says; and every
/// sample reports the density `pdf` gives its direction.
fn assert_samples_follow_pdf(what: &str, env: &Environment) {
    let (bands, sectors) = (16usize, 32usize);
    let cell = |d: Vec3| {
        let band = (((d.y + 1.0) * 0.5 * bands as f32) as usize).min(bands - 1);
        let azimuth = d.z.atan2(d.x).rem_euclid(2.0 * PI) / (2.0 * PI);
        let sector = ((azimuth * sectors as f32) as usize).min(sectors - 1);
        band * sectors + sector
    };
    let n = 300_000u64;
    let mut counts = vec![0u64; bands * sectors];
    let mut rng = Rng::new(17);
    for _ in 0..n {
        let Some(s) = env.sample([rng.next_f32(), rng.next_f32()]) else {
            continue;
        };
        assert!((s.direction.length() - 1.0).abs() < 1e-5, "{what}: unit");
        let pdf = env.pdf(s.direction);
        assert!(
            (s.pdf - pdf).abs() <= 2e-3 * pdf.max(1e-3),
            "{what}: sampled with {} but pdf says {pdf} at {:?}",
            s.pdf,
            s.direction
        );
        assert_eq!(s.radiance, env.color(s.direction), "{what}");
        counts[cell(s.direction)] += 1;
    }
    // Each cell's share: the pdf integrated over it, on a 40 × 40 grid of
    // equal-area points (uniform in y and azimuth).
    let m = 40;
    let cell_area = 4.0 * std::f64::consts::PI / (bands * sectors) as f64;
    let expected: Vec<f64> = (0..bands * sectors)
        .map(|c| {
            let (band, sector) = (c / sectors, c % sectors);
            let mut sum = 0.0;
            for i in 0..m {
                for j in 0..m {
                    let y = -1.0 + 2.0 * (band as f64 + (i as f64 + 0.5) / m as f64) / bands as f64;
                    let phi =
                        2.0 * std::f64::consts::PI * (sector as f64 + (j as f64 + 0.5) / m as f64)
                            / sectors as f64;
                    let r = (1.0 - y * y).sqrt();
                    let d = Vec3::new((r * phi.cos()) as f32, y as f32, (r * phi.sin()) as f32);
                    sum += f64::from(env.pdf(d));
                }
            }
            sum / (m * m) as f64 * cell_area * n as f64
        })
        .collect();
    let total: f64 = expected.iter().sum::<f64>() / n as f64;
    assert!(
        (total - 1.0).abs() < 0.01,
        "{what}: pdf integrates to {total}"
    );
    let (chi2, dof) = chi_square(&counts, &expected);
    assert!(
        chi2 < chi_square_bound(dof),
        "{what}: χ² {chi2:.1} for {dof} degrees of freedom"
    );
}

#[test]
fn gradient_and_solid_skies_are_sampled_by_their_brightness() {
    let white_to_blue = Environment::Gradient {
        bottom: Color::ONE,
        top: Color::new(0.5, 0.7, 1.0),
    };
    assert_samples_follow_pdf("gradient", &white_to_blue);
    // Black below: no direction below the horizon... only at the very
    // bottom; the density falls to 0 there.
    let dark_below = Environment::Gradient {
        bottom: Color::ZERO,
        top: Color::new(2.0, 2.0, 2.0),
    };
    assert_samples_follow_pdf("black-bottomed gradient", &dark_below);
    assert_samples_follow_pdf("solid", &Environment::Solid(Color::splat(0.3)));
    // The density follows the luminance: 3× brighter straight up.
    let d = Environment::Gradient {
        bottom: Color::splat(1.0),
        top: Color::splat(3.0),
    };
    let ratio = d.pdf(Vec3::Y) / d.pdf(-Vec3::Y);
    assert!((ratio - 3.0).abs() < 1e-5, "{ratio}");
}

#[test]
fn an_image_sky_is_sampled_by_its_brightness() {
    for rotation in [0.0, 90.0, -33.0] {
        let env = Environment::Map(Arc::new(test_map(rotation)));
        assert_samples_follow_pdf(&format!("map turned {rotation}°"), &env);
    }
}

/// ∫ Y dω, as `integral` states it, against a Monte Carlo estimate from
/// uniform directions; and the density of the map integrates to 1 over the
/// sphere (the Jacobian of the (u, v) layout is right).
#[test]
fn the_map_integral_and_density_agree_with_uniform_estimates() {
    let env = Environment::Map(Arc::new(test_map(20.0)));
    let n = 400_000;
    let mut rng = Rng::new(5);
    let (mut y, mut y2, mut p, mut p2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..n {
        let d = crate::sampling::unit_vector(rng.next_2d());
        let a = 4.0 * std::f64::consts::PI * f64::from(luminance(env.color(d)));
        let b = 4.0 * std::f64::consts::PI * f64::from(env.pdf(d));
        y += a;
        y2 += a * a;
        p += b;
        p2 += b * b;
    }
    let n = n as f64;
    let se = |s: f64, s2: f64| ((s2 / n - (s / n).powi(2)) / n).sqrt();
    let (y_mean, y_se) = (y / n, se(y, y2));
    let (p_mean, p_se) = (p / n, se(p, p2));
    assert!((p_mean - 1.0).abs() < K * p_se, "∫ pdf = {p_mean} ± {p_se}");
    // `integral` sums texels rather than the bilinear blend: the two agree
    // to within the blend's smoothing of the sun, a few per cent here.
    let exact = env.integral();
    assert!(
        (y_mean - exact).abs() < K * y_se + 0.03 * exact,
        "∫ Y = {y_mean} ± {y_se}, integral() = {exact}"
    );
}

#[test]
fn the_map_is_laid_out_around_the_default_view() {
    // One bright texel per landmark: the centre of the image, a quarter to
    // the right, and the top row.
    let (w, h) = (8, 4);
    let mut texels = vec![Color::ZERO; w * h];
    texels[w + 4] = Color::new(1.0, 0.0, 0.0); // u 0.5+, just above the horizon
    texels[w + 6] = Color::new(0.0, 1.0, 0.0); // u 0.75+
    let image = Image::new(w, h, texels);
    let look = |rotation: f32, d: Vec3| {
        let map = EnvironmentMap::new(image.clone(), rotation, 2.0).unwrap();
        map.color(d.normalize())
    };
    // The centre of texel (4, 1): u = 4.5/8, v = 1.5/4, that is φ = π/8
    // from −z towards +x, θ = 3π/8 from +y.
    let toward = |u: f32, v: f32| {
        let (theta, phi) = (PI * v, 2.0 * PI * (u - 0.5));
        Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    };
    assert_eq!(
        look(0.0, toward(4.5 / 8.0, 1.5 / 4.0)),
        Color::new(2.0, 0.0, 0.0)
    );
    assert_eq!(
        look(0.0, toward(6.5 / 8.0, 1.5 / 4.0)),
        Color::new(0.0, 2.0, 0.0)
    );
    // Turned 90° counter-clockwise seen from above: what was to the right
    // (+x side) comes to the front (−z).
    let turned = toward(6.5 / 8.0, 1.5 / 4.0);
    let front = Vec3::new(turned.z, turned.y, -turned.x);
    let seen = look(90.0, front);
    assert!(
        (seen - Color::new(0.0, 2.0, 0.0)).length() < 1e-4,
        "{seen:?}"
    );
    // uv and direction are inverses.
    let map = EnvironmentMap::new(image.clone(), -47.0, 1.0).unwrap();
    for uv in [[0.1, 0.2], [0.5, 0.5], [0.93, 0.77]] {
        let (d, _) = map.direction(uv);
        let back = map.uv(d);
        assert!(
            (back[0] - uv[0]).abs() < 1e-5 && (back[1] - uv[1]).abs() < 1e-5,
            "{uv:?} → {back:?}"
        );
    }
}

#[test]
fn a_black_image_or_no_intensity_sheds_no_light() {
    let black = Image::new(4, 2, vec![Color::ZERO; 8]);
    assert!(EnvironmentMap::new(black, 0.0, 1.0).is_none());
    let grey = Image::new(4, 2, vec![Color::splat(0.5); 8]);
    assert!(EnvironmentMap::new(grey, 0.0, 0.0).is_none());
}

/// A square map in the equal-area layout with structure (a sun, black
/// texels), its frame turned so that its z is not the world's.
fn equal_area_map() -> EnvironmentMap {
    let n = 16;
    let texels = (0..n * n)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            if (x, y) == (3, 12) {
                Color::new(300.0, 200.0, 100.0)
            } else if (x + y) % 7 == 0 {
                Color::ZERO
            } else {
                Color::new(0.1 + x as f32 * 0.05, 0.2 + y as f32 * 0.02, 0.3)
            }
        })
        .collect();
    // pbrt's usual sky: the map's z is the world's +y.
    let frame = [Vec3::X, Vec3::NEG_Z, Vec3::Y];
    EnvironmentMap::equal_area(Image::new(n, n, texels), frame, 2.0)
        .unwrap()
        .expect("a map of light")
}

#[test]
fn the_equal_area_layout_is_pbrts_and_round_trips() {
    // Landmarks: +z at the centre, −z at every corner, +x at the middle of
    // the right edge, +y at the middle of the bottom edge (the last row).
    let close = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
    assert!(close(equal_area_square(Vec3::Z), [0.5, 0.5]));
    assert!(close(equal_area_square(Vec3::X), [1.0, 0.5]));
    assert!(close(equal_area_square(Vec3::NEG_X), [0.0, 0.5]));
    assert!(close(equal_area_square(Vec3::Y), [0.5, 1.0]));
    assert!(close(equal_area_square(Vec3::NEG_Y), [0.5, 0.0]));
    let corner = equal_area_square(Vec3::NEG_Z);
    assert!([0.0, 1.0].contains(&corner[0]) && [0.0, 1.0].contains(&corner[1]));
    let mut rng = Rng::new(3);
    for _ in 0..10_000 {
        let d = crate::sampling::unit_vector(rng.next_2d());
        let back = equal_area_sphere(equal_area_square(d));
        assert!((back - d).length() < 1e-5, "{d} → {back}");
        let uv = [rng.next_f32(), rng.next_f32()];
        let again = equal_area_square(equal_area_sphere(uv));
        assert!(
            close(again, uv) || (uv[0] - 0.5).abs() + (uv[1] - 0.5).abs() > 0.49999,
            "{uv:?} → {again:?}"
        );
    }
    // Equal area: as many uniform directions land in each texel of a
    // 4 × 4 square, within the counts' noise.
    let n = 160_000u64;
    let mut counts = [0u64; 16];
    for _ in 0..n {
        let [u, v] = equal_area_square(crate::sampling::unit_vector(rng.next_2d()));
        counts[((v * 4.0) as usize).min(3) * 4 + ((u * 4.0) as usize).min(3)] += 1;
    }
    let expected = vec![n as f64 / 16.0; 16];
    let (chi2, cells) = chi_square(&counts, &expected);
    assert!(chi2 < chi_square_bound(cells - 1), "χ² {chi2}: {counts:?}");
    // Not square: refused.
    let image = Image::new(4, 2, vec![Color::ONE; 8]);
    assert!(EnvironmentMap::equal_area(image, [Vec3::X, Vec3::Y, Vec3::Z], 1.0).is_err());
}

#[test]
fn an_equal_area_sky_is_sampled_by_its_brightness_and_integrates_to_its_integral() {
    let env = Environment::Map(Arc::new(equal_area_map()));
    assert_samples_follow_pdf("equal-area map", &env);
    let n = 400_000;
    let mut rng = Rng::new(9);
    let (mut y, mut y2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let d = crate::sampling::unit_vector(rng.next_2d());
        let a = 4.0 * std::f64::consts::PI * f64::from(luminance(env.color(d)));
        y += a;
        y2 += a * a;
    }
    let n = n as f64;
    let (mean, se) = (y / n, ((y2 / n - (y / n).powi(2)) / n).sqrt());
    // Texels looked up as they are: the integral is exact.
    let exact = env.integral();
    assert!(
        (mean - exact).abs() < K * se,
        "∫ Y = {mean} ± {se}, integral() = {exact}"
    );
    // The sun (texel 3, 12: below the centre, left) is seen towards the
    // map's frame: z = world +y, x = world +x, y = world −z.
    let sun = equal_area_sphere([3.5 / 16.0, 12.5 / 16.0]);
    let world = Vec3::X * sun.x + Vec3::NEG_Z * sun.y + Vec3::Y * sun.z;
    assert_eq!(env.color(world), Color::new(600.0, 400.0, 200.0));
}

/// A map turned by a frame (its axes in the world: here its top along +z,
/// as a z-up scene has it) shows along F·d what the unturned map shows
/// along d, with the density it has there; its samples are the unturned
/// map's turned, and follow its pdf.
#[test]
fn a_framed_map_is_the_map_turned_into_its_frame() {
    let frame = [
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.8, -0.6, 0.0),
    ];
    let plain = test_map(30.0);
    let framed = test_map(30.0).with_frame(frame);
    let turn = |d: Vec3| frame[0] * d.x + frame[1] * d.y + frame[2] * d.z;
    let mut rng = Rng::new(5);
    for _ in 0..1000 {
        // Uniform on the sphere: y uniform in [-1, 1], azimuth uniform.
        let (y, phi) = (2.0 * rng.next_f32() - 1.0, 2.0 * PI * rng.next_f32());
        let r = (1.0 - y * y).max(0.0).sqrt();
        let d = Vec3::new(r * phi.cos(), y, r * phi.sin());
        let (a, b) = (plain.color(d), framed.color(turn(d)));
        assert!(
            (a - b).abs().max_element() < 1e-3 * (1.0 + a.max_element()),
            "{a:?} {b:?}"
        );
        let (p, q) = (plain.pdf(d), framed.pdf(turn(d)));
        assert!((p - q).abs() < 1e-3 * p.max(1e-3), "{p} {q}");
        let u = [rng.next_f32(), rng.next_f32()];
        if let (Some((x, _)), Some((y, _))) = (plain.sample(u), framed.sample(u)) {
            assert!((turn(x) - y).length() < 1e-5, "{x:?} {y:?}");
        }
    }
    assert_samples_follow_pdf("framed map", &Environment::Map(Arc::new(framed)));
}
