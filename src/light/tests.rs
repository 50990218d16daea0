use super::*;
use crate::rng::Rng;

/// Standard errors allowed between an estimate and its expected value.
const K: f64 = 5.0;

/// A light of `shape` emitting `radiance`, from both sides or one.
fn emitting(shape: Shape, radiance: Color, two_sided: bool) -> Light {
    Light {
        shape,
        emission: Emissive {
            radiance,
            two_sided,
        },
        texture: None,
        object: 0,
    }
}

fn light(shape: Shape) -> Light {
    emitting(shape, Color::ONE, true)
}

/// `lights` without an environment, chosen by power.
fn area_lights(lights: Vec<Light>) -> Lights {
    Lights::new(lights, Vec::new(), None, 0.0, LightSelection::Power)
}

/// Mean and standard error of `f` over `n` samples.
fn estimate(n: usize, mut f: impl FnMut() -> f64) -> (f64, f64) {
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..n {
        let x = f();
        s += x;
        s2 += x * x;
    }
    let mean = s / n as f64;
    let var = (s2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// Samples `shape` from `from`, checking each sample's density against
/// [`Lights::pdf`] at the point it reached, and returns the estimate of the
/// solid angle the light covers, E[1/pdf].
fn solid_angle_estimate(shape: Shape, from: Point3) -> (f64, f64) {
    let lights = area_lights(vec![light(shape)]);
    let mut rng = Rng::new(17);
    estimate(200_000, || {
        let s = lights.sample(from, &mut rng).expect("a sample");
        let point = from + s.distance * s.direction;
        let outward = match shape {
            Shape::Sphere { center, .. } => (point - center).normalize(),
            Shape::Quad { u, v, .. } => u.cross(v).normalize(),
            Shape::Triangle {
                vertices: [a, b, c],
            } => (b - a).cross(c - a).normalize(),
            Shape::Quadric(q) => {
                let ray = crate::ray::Ray::new(from, s.direction);
                q.surface(&ray, s.distance).outward
            }
        };
        let pdf = lights.pdf(0, from, point, outward);
        assert!(
            (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
            "pdf {pdf} at the sampled point, sampled with {}",
            s.pdf
        );
        1.0 / f64::from(s.pdf)
    })
}

fn assert_close(what: &str, (mean, se): (f64, f64), exact: f64) {
    assert!(
        (mean - exact).abs() <= K * se + 1e-6 * exact,
        "{what}: {mean} ± {se}, expected {exact}"
    );
}

#[test]
fn a_sphere_is_sampled_over_the_solid_angle_of_its_cap() {
    let (center, radius) = (Vec3::new(0.5, -1.0, 3.0), 1.5);
    for distance in [1.6f32, 2.0, 5.0, 100.0] {
        let from = center - Vec3::new(0.6, 0.0, 0.8) * distance;
        let sin2 = f64::from(radius / distance).powi(2);
        let exact = 2.0 * std::f64::consts::PI * (1.0 - (1.0 - sin2).sqrt());
        let e = solid_angle_estimate(Shape::Sphere { center, radius }, from);
        assert_close(&format!("distance {distance}"), e, exact);
        // Uniform over the cap, every sample has the same density.
        assert!(e.1 < 1e-6 * e.0, "{e:?}");
    }
}

#[test]
fn a_sphere_seen_from_inside_is_sampled_by_area() {
    let (center, radius) = (Vec3::ZERO, 2.0);
    // From inside a closed surface every direction meets it once.
    let e = solid_angle_estimate(Shape::Sphere { center, radius }, Vec3::new(0.3, 1.0, -0.5));
    assert_close("inside", e, 4.0 * std::f64::consts::PI);
}

/// A rectangle close by is sampled uniformly over its solid angle (every
/// sample of the same density, 1 / Ω), one farther off by area; both
/// estimate Ω, and each sample's density is the one [`Lights::pdf`] gives.
#[test]
fn a_rectangle_is_sampled_by_solid_angle_close_up_and_by_area_farther() {
    // A rectangle a × b seen from height h above one corner subtends
    // atan(ab / (h √(a² + b² + h²))).
    let (a, b) = (3.0f64, 2.0f64);
    for h in [0.5f64, 1.0, 4.0, 20.0] {
        let shape = Shape::Quad {
            corner: Vec3::ZERO,
            u: Vec3::new(a as f32, 0.0, 0.0),
            v: Vec3::new(0.0, 0.0, b as f32),
        };
        let from = Vec3::new(0.0, h as f32, 0.0);
        let exact = (a * b / (h * (a * a + b * b + h * h).sqrt())).atan();
        let e = solid_angle_estimate(shape, from);
        assert_close(&format!("h = {h}"), e, exact);
        let close = (a * a + b * b) / 4.0 + h * h < f64::from(SPHERICAL_WITHIN) * a * b;
        let uniform = e.1 < 1e-6 * e.0;
        assert_eq!(close, uniform, "h = {h}: {e:?}");
    }
    // A parallelogram is sampled by area however close.
    let slanted = Shape::Quad {
        corner: Vec3::ZERO,
        u: Vec3::new(3.0, 0.0, 0.0),
        v: Vec3::new(1.0, 0.0, 2.0),
    };
    let e = solid_angle_estimate(slanted, Vec3::new(0.0, 0.5, 0.0));
    assert!(e.1 > 1e-3 * e.0, "{e:?}");
}

#[test]
fn disks_and_cylinders_are_sampled_uniformly_by_area() {
    use crate::geometry::transform::{Transform, TransformStep};
    use crate::geometry::{Quadric, QuadricForm};
    let place = |form, steps: &[TransformStep]| {
        Shape::Quadric(Quadric::new(form, &Transform::from_steps(steps).unwrap()))
    };
    // A disk of radius R seen from its axis, at height h, covers
    // 2π(1 − h/√(h² + R²)), whichever way it is turned.
    let (radius, h) = (1.5f64, 2.0f64);
    let turn = TransformStep::Rotate {
        axis: [1.0, -2.0, 0.5],
        degrees: 70.0,
    };
    let disk = place(
        QuadricForm::Disk,
        &[TransformStep::Scale([radius; 3]), turn],
    );
    let from = Transform::from_steps(&[turn])
        .unwrap()
        .point(Vec3::new(0.0, 0.0, h as f32));
    let exact = 2.0 * std::f64::consts::PI * (1.0 - h / (h * h + radius * radius).sqrt());
    assert_close("disk", solid_angle_estimate(disk, from), exact);
    // A turned cylinder of radius r and length L: the area behind each
    // sample, d² / (|cos θ| pdf), is 2π r L (in every sample: the pdf is
    // uniform by area).
    let (r, length) = (0.4f64, 3.0f64);
    let tube = place(
        QuadricForm::Cylinder,
        &[
            TransformStep::Scale([r, r, length]),
            TransformStep::Rotate {
                axis: [0.3, 1.0, 0.2],
                degrees: 50.0,
            },
            TransformStep::Translate([1.0, 2.0, -1.0]),
        ],
    );
    let Shape::Quadric(q) = tube else {
        unreachable!()
    };
    let lights = area_lights(vec![light(tube)]);
    let mut rng = Rng::new(5);
    let from = Vec3::new(-1.0, 0.5, 2.0);
    let area = estimate(20_000, || {
        let s = lights.sample(from, &mut rng).expect("a sample");
        let ray = crate::ray::Ray::new(from, s.direction);
        let outward = q.surface(&ray, s.distance).outward;
        let pdf = lights.pdf(0, from, from + s.distance * s.direction, outward);
        let cos = f64::from(outward.dot(s.direction).abs());
        // The normal found again is rounded: grazing, the cosine is
        // relatively less exact.
        let tolerance = 1e-3 + 1e-6 / cos;
        assert!(
            f64::from((pdf - s.pdf).abs()) <= tolerance * f64::from(s.pdf),
            "pdf {pdf} at the sampled point, sampled with {}",
            s.pdf
        );
        f64::from(s.distance).powi(2) / (cos * f64::from(s.pdf))
    });
    let exact = 2.0 * std::f64::consts::PI * r * length;
    assert!(
        (area.0 - exact).abs() < 1e-3 * exact,
        "cylinder: {area:?}, expected {exact}"
    );
}

#[test]
fn a_triangle_is_sampled_uniformly_by_area() {
    let vertices = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.5),
        Vec3::new(-1.0, 0.2, 1.0),
    ];
    let from = Vec3::new(0.1, 0.3, -1.5);
    // Van Oosterom and Strackee's formula for the solid angle of a triangle.
    let [r1, r2, r3] = vertices.map(|v| (v - from).as_dvec3());
    let (l1, l2, l3) = (r1.length(), r2.length(), r3.length());
    let numerator = r1.dot(r2.cross(r3)).abs();
    let denominator = l1 * l2 * l3 + r1.dot(r2) * l3 + r1.dot(r3) * l2 + r2.dot(r3) * l1;
    let exact = 2.0 * numerator.atan2(denominator);
    let e = solid_angle_estimate(Shape::Triangle { vertices }, from);
    assert_close("triangle", e, exact);
}

/// Points drawn on a triangle light fall equally often into the n² equal
/// triangles of its regular subdivision, and points on a quad into the
/// cells of an n × n grid of it (χ², fixed seed): uniform by area.
#[test]
fn triangle_and_quad_points_are_uniform_by_area() {
    use crate::testing::{chi_square, chi_square_bound};
    let n = 12usize;
    let (a, b, c) = (
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.5),
        Vec3::new(-1.0, 0.2, 1.0),
    );
    let triangle = Shape::Triangle {
        vertices: [a, b, c],
    };
    let (corner, u, v) = (
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(2.0, 0.0, 0.5),
        Vec3::new(0.0, 0.3, 1.0),
    );
    let quad = Shape::Quad { corner, u, v };
    for (what, shape) in [("triangle", triangle), ("quad", quad)] {
        let draws = 200_000u64;
        let mut counts = vec![0u64; 2 * n * n];
        let mut rng = Rng::new(41);
        for _ in 0..draws {
            let (point, _, _) = sample_area(&shape, Surface::of(&shape).normal, rng.next_2d());
            // The point's coordinates along the two edges, solved from it.
            let (e1, e2, origin) = match shape {
                Shape::Triangle { .. } => (b - a, c - a, a),
                _ => (u, v, corner),
            };
            let p = point - origin;
            let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let (r1, r2) = (p.dot(e1), p.dot(e2));
            let det = g11 * g22 - g12 * g12;
            let (s, t) = ((r1 * g22 - r2 * g12) / det, (r2 * g11 - r1 * g12) / det);
            let (fs, ft) = (s * n as f32, t * n as f32);
            let (i, j) = ((fs as usize).min(n - 1), (ft as usize).min(n - 1));
            let upper = usize::from(fs - i as f32 + ft - j as f32 >= 1.0);
            counts[(i * n + j) * 2 + upper] += 1;
        }
        // A quad's cell is two halves of equal area; a triangle holds the
        // n² small triangles with i + j + upper < n.
        let cells: Vec<bool> = (0..2 * n * n)
            .map(|k| match shape {
                Shape::Triangle { .. } => (k / 2) / n + (k / 2) % n + k % 2 < n,
                _ => true,
            })
            .collect();
        let inside = cells.iter().filter(|&&c| c).count() as f64;
        let expected: Vec<f64> = cells
            .iter()
            .map(|&c| if c { draws as f64 / inside } else { 0.0 })
            .collect();
        assert_eq!(
            counts
                .iter()
                .zip(&cells)
                .filter(|(&k, &c)| k > 0 && !c)
                .count(),
            0,
            "{what}: points outside"
        );
        let (chi2, dof) = chi_square(&counts, &expected);
        assert!(chi2 < chi_square_bound(dof), "{what}: χ² {chi2}, {dof} dof");
    }
}

#[test]
fn lights_are_chosen_in_proportion_to_their_power() {
    let quad = |x: f32, side: f32| Shape::Quad {
        corner: Vec3::new(x, 5.0, 0.0),
        u: Vec3::new(side, 0.0, 0.0),
        v: Vec3::new(0.0, 0.0, side),
    };
    // Powers 1 : 4 (twice the side) : 0 (black, never chosen) : 2 (one
    // side, but four times the radiance).
    let lights = area_lights(vec![
        light(quad(0.0, 1.0)),
        light(quad(5.0, 2.0)),
        emitting(quad(10.0, 1.0), Color::ZERO, true),
        emitting(quad(-5.0, 1.0), Color::splat(4.0), false),
    ]);
    assert_eq!(lights.len(), 4);
    let expected = [1.0 / 7.0, 4.0 / 7.0, 2.0 / 7.0, 0.0];
    let mut rng = Rng::new(3);
    let n = 70_000;
    let mut counts = [0usize; 4];
    for _ in 0..n {
        let s = lights.sample(Vec3::ZERO, &mut rng).expect("a sample");
        // Which light: by the x of the point reached.
        let x = s.distance * s.direction.x;
        let i = if x < 0.0 {
            2
        } else if x < 2.0 {
            0
        } else if x < 8.0 {
            1
        } else {
            3
        };
        counts[i] += 1;
    }
    for (i, &p) in expected.iter().enumerate() {
        let f = counts[i] as f64 / n as f64;
        let se = (p * (1.0 - p) / n as f64).sqrt();
        assert!((f - p).abs() <= K * se, "light {i}: {f} instead of {p}");
        assert_eq!(counts[i] == 0, p == 0.0, "light {i}");
    }
}

#[test]
fn a_one_sided_light_sends_nothing_behind_it() {
    let shape = Shape::Quad {
        corner: Vec3::new(-1.0, 1.0, -1.0),
        u: Vec3::new(2.0, 0.0, 0.0),
        v: Vec3::new(0.0, 0.0, 2.0),
    };
    // u × v points down (−y): lit below, dark above.
    let lights = area_lights(vec![emitting(shape, Color::ONE, false)]);
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let below = lights.sample(Vec3::ZERO, &mut rng).unwrap();
        assert_eq!(below.radiance, Color::ONE);
        let above = lights.sample(Vec3::new(0.0, 2.0, 0.0), &mut rng).unwrap();
        assert_eq!(above.radiance, Color::ZERO);
    }
}

/// The chance of each light, checked against the rule: by power (the
/// environment's through the disc of the scene's bounding sphere), or
/// equally among lights that emit.
#[test]
fn lights_and_the_sky_are_chosen_by_power_or_uniformly() {
    let quad = Shape::Quad {
        corner: Vec3::ZERO,
        u: Vec3::X,
        v: Vec3::Z,
    };
    // A one-sided unit quad of radiance 1: power π. A grey sky of 0.5 round
    // a scene of radius 2: 0.5 · 4π · π · 2² = 8π².
    let lights = vec![
        emitting(quad, Color::ONE, false),
        emitting(quad, Color::ZERO, false),
    ];
    let sky = Environment::Solid(Color::splat(0.5));
    let by_power = Lights::new(
        lights.clone(),
        Vec::new(),
        Some(sky.clone()),
        2.0,
        LightSelection::Power,
    );
    assert_eq!(by_power.len(), 3);
    let (quad_power, sky_power) = (PI, 8.0 * PI * PI);
    let expected = quad_power / (quad_power + sky_power);
    assert!((by_power.chance(0) - expected).abs() < 1e-6);
    assert_eq!(by_power.chance(1), 0.0);
    assert!((by_power.chance(2) - (1.0 - expected)).abs() < 1e-6);
    let uniform = Lights::new(
        lights.clone(),
        Vec::new(),
        Some(sky),
        2.0,
        LightSelection::Uniform,
    );
    assert_eq!(
        [uniform.chance(0), uniform.chance(1), uniform.chance(2)],
        [0.5, 0.0, 0.5]
    );
    // A black sky is no light; nothing at all is no list.
    let black = Lights::new(
        lights,
        Vec::new(),
        Some(Environment::Solid(Color::ZERO)),
        2.0,
        LightSelection::Power,
    );
    assert_eq!((black.len(), black.chance(0)), (2, 1.0));
    assert_eq!(black.environment_pdf(Vec3::Y), 0.0);
    let none = Lights::new(
        Vec::new(),
        Vec::new(),
        Some(Environment::Solid(Color::ZERO)),
        2.0,
        LightSelection::Uniform,
    );
    assert!(none.is_empty());
}

/// A sky sample is infinitely far, carries the sky's radiance, and its
/// density is the sky's times the sky's chance, as `environment_pdf` says.
#[test]
fn a_sky_sample_is_infinitely_far_and_weighted_by_its_chance() {
    let quad = Shape::Quad {
        corner: Vec3::new(0.0, 3.0, 0.0),
        u: Vec3::X,
        v: Vec3::Z,
    };
    let sky = Environment::Gradient {
        bottom: Color::ZERO,
        top: Color::splat(2.0),
    };
    let lights = Lights::new(
        vec![light(quad)],
        Vec::new(),
        Some(sky.clone()),
        1.0,
        LightSelection::Uniform,
    );
    let mut rng = Rng::new(9);
    let mut seen_sky = 0;
    for _ in 0..1000 {
        let Some(s) = lights.sample(Vec3::ZERO, &mut rng) else {
            continue;
        };
        if s.distance.is_infinite() {
            seen_sky += 1;
            assert_eq!(s.radiance, sky.color(s.direction));
            assert_eq!(s.pdf, 0.5 * sky.pdf(s.direction));
            assert_eq!(s.pdf, lights.environment_pdf(s.direction));
        } else {
            assert!(s.distance.is_finite() && s.point.y == 3.0);
        }
    }
    assert!(
        (400..600).contains(&seen_sky),
        "{seen_sky} of 1000 from the sky"
    );
}

#[test]
fn areas_of_quads_and_triangles_whose_squares_overflow_f32() {
    // |u × v|² overflows f32 from edges of about 4e9.
    let (u, v) = (Vec3::new(6e9, 0.0, 0.0), Vec3::new(0.0, 0.0, 6e9));
    let quad = Shape::Quad {
        corner: Vec3::ZERO,
        u,
        v,
    };
    assert_eq!(quad.area(), 3.6e19);
    let triangle = Shape::Triangle {
        vertices: [Vec3::ZERO, u, v],
    };
    assert_eq!(triangle.area(), 1.8e19);
}
