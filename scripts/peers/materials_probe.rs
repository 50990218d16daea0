//! lumen's BSDF lobes evaluated at given directions, for the point checks
//! of scripts/peers/mitsuba_materials.py (`--check-lumen`), which builds
//! this file against the lumen library (a throw-away Cargo project in
//! /tmp whose only dependency is lumen at its path).
//!
//!     materials_probe conductor ALPHA ETA_R ETA_G ETA_B K_R K_G K_B
//!     materials_probe dielectric ALPHA ETA
//!     materials_probe plastic ALPHA ETA RHO_R RHO_G RHO_B
//!     materials_probe coat ALPHA ETA
//!     materials_probe sample N KIND ARGS...
//!     materials_probe trace SCENE.toml OBJECT SPP [normalize]
//!
//! GGX, single scattering (multiscatter off), the lobes as the materials
//! build them (src/bsdf/{conductor,dielectric,plastic}.rs). Standard input:
//! one direction pair a line, `wo.x wo.y wo.z wi.x wi.y wi.z` in the local
//! frame (lumen's naming: wo towards the camera, wi towards the light);
//! standard output: `f_r f_g f_b pdf`, f = f(wo, wi)·|cos θi|. `coat`
//! reads one μ a line and prints the coat's transmittance T(μ); its first
//! output line is the internal reflectance Ri. `sample N` reads one `wo` a
//! line and draws N samples of the lobe's `sample` (uniform random numbers
//! from a SplitMix64 stream): it prints the mean sample value per channel
//! (the directional albedo, as the sampling sees it), the same for the
//! reflected and the transmitted samples, and the fraction of draws that
//! returned no sample.
//!
//! `trace` is a diagnosis: the mean radiance of the pixels of `SCENE` that
//! object number `OBJECT` (a sphere, counted in the file's order) covers
//! entirely (its 4 × 4 sub-pixel camera rays all meet it first, as
//! materials_regions.py counts them), by lumen's own scene, camera, BSDFs and
//! ray spawning, in a copy of the `bsdf` integrator's loop (BSDF sampling
//! only, no roulette; the same expected image as `path`), SPP paths a pixel.
//! With `normalize` each sampled direction is made unit length before the
//! ray is spawned, which lumen does not do. Also counted: the hits on
//! spheres whose point lies farther than 1e-4 from every sphere's surface
//! (the ray–sphere test assumes a unit direction), the sampled
//! directions whose length is off 1 by more than 1e-4, and the hits closer
//! than 1e-3 on the sphere the ray just left (from outside a sphere these
//! are spurious: a convex surface cannot be met again).

use lumen::bsdf::albedo;
use lumen::bsdf::conductor::Conductor;
use lumen::bsdf::dielectric::ExactDielectric;
use lumen::bsdf::microfacet::{Microfacet, Model};
use lumen::bsdf::plastic::Plastic;
use lumen::bsdf::Lobe;
use lumen::integrator::hit_range;
use lumen::ray::Ray;
use lumen::rng::Rng;
use lumen::sampler::Sampler;
use lumen::scene::file::SceneFile;
use lumen::scene::Overrides;
use lumen::math::{Color, Vec3};
use std::io::{BufRead, Write};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize| -> f32 { args[i].parse().expect("a number") };
    let kind = args[1].as_str();
    let stdin = std::io::stdin();
    let mut out = std::io::BufWriter::new(std::io::stdout());
    if kind == "coat" {
        let alpha = num(2);
        let d = Microfacet::new(alpha, alpha, Model::Ggx);
        let eta = num(3);
        writeln!(out, "{}", albedo::coat_internal_reflectance(&d, eta)).unwrap();
        for line in stdin.lock().lines() {
            let mu: f32 = line.unwrap().trim().parse().expect("a cosine");
            writeln!(out, "{}", albedo::coat_transmittance(&d, eta, mu)).unwrap();
        }
        return;
    }
    if kind == "trace" {
        trace(&args[2], args[3].parse().expect("an object index"), args[4].parse().expect("spp"),
              args.get(5).is_some_and(|a| a == "normalize"));
        return;
    }
    if kind == "sample" {
        let n: usize = args[2].parse().expect("a count");
        let lobe = lobe(&args[3..]);
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 40) as f32 / (1u64 << 24) as f32
        };
        for line in stdin.lock().lines() {
            let v: Vec<f32> = line
                .unwrap()
                .split_whitespace()
                .map(|x| x.parse().expect("a number"))
                .collect();
            let wo = Vec3::new(v[0], v[1], v[2]);
            // (sums in f64: an f32 sum of millions of values loses percents)
            let (mut refl, mut trans, mut none) = ([0.0f64; 3], [0.0f64; 3], 0usize);
            for _ in 0..n {
                let (uc, u) = (next(), [next(), next()]);
                match lobe.sample_local(wo, uc, u) {
                    Some(s) => {
                        let sum = if s.wi.z * wo.z > 0.0 {
                            &mut refl
                        } else {
                            &mut trans
                        };
                        for (c, v) in s.value.to_array().into_iter().enumerate() {
                            sum[c] += f64::from(v);
                        }
                    }
                    None => none += 1,
                }
            }
            let k = 1.0 / n as f64;
            let (r, t) = (refl.map(|x| x * k), trans.map(|x| x * k));
            writeln!(
                out,
                "{} {} {} {} {} {} {} {} {} {}",
                r[0] + t[0],
                r[1] + t[1],
                r[2] + t[2],
                r[0], r[1], r[2], t[0], t[1], t[2],
                none as f64 * k
            )
            .unwrap();
        }
        return;
    }
    let lobe = lobe(&args[1..]);
    for line in stdin.lock().lines() {
        let v: Vec<f32> = line
            .unwrap()
            .split_whitespace()
            .map(|x| x.parse().expect("a number"))
            .collect();
        let (f, pdf) = lobe.eval_and_pdf_local(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
        writeln!(out, "{:e} {:e} {:e} {:e}", f.x, f.y, f.z, pdf).unwrap();
    }
}

/// The lobe `args` describe (`KIND ALPHA ...`, as on the command line).
fn lobe(args: &[String]) -> Lobe {
    let num = |i: usize| -> f32 { args[i].parse().expect("a number") };
    let alpha = num(1);
    let d = Microfacet::new(alpha, alpha, Model::Ggx);
    let rough = (!Microfacet::is_smooth(alpha, alpha)).then_some(d);
    match args[0].as_str() {
        "conductor" => Lobe::Conductor(Conductor {
            eta: Color::new(num(2), num(3), num(4)),
            k: Color::new(num(5), num(6), num(7)),
            tint: Color::ONE,
            roughness: rough,
            multiscatter: false,
        }),
        "dielectric" => Lobe::ExactDielectric(ExactDielectric {
            eta: num(2),
            roughness: rough,
            multiscatter: false,
        }),
        "plastic" => Lobe::Plastic(Plastic {
            albedo: Color::new(num(3), num(4), num(5)),
            eta: num(2),
            roughness: rough,
            multiscatter: false,
        }),
        kind => panic!("kind {kind}: conductor, dielectric, plastic, coat or sample"),
    }
}

/// See the module's `trace`.
fn trace(path: &str, object: u32, spp: usize, normalize: bool) {
    let (_, scene) = SceneFile::read(std::path::Path::new(path))
        .expect("a scene file")
        .into_resolved(&Overrides::default())
        .expect("a valid scene");
    let range = hit_range(&scene);
    let (w, h) = (scene.settings.width, scene.settings.height);
    let first = |ray: &Ray| scene.intersect(ray, range).map(|hit| scene.record(ray, hit).object);
    let mut rng = Rng::new(1);
    let mut sum = [0.0f64; 3];
    let (mut pixels, mut sphere_hits, mut off_surface, mut directions, mut non_unit) = (0u64, 0u64, 0u64, 0u64, 0u64);
    let mut rehits = 0u64;
    for y in 0..h {
        for x in 0..w {
            let covered = (0..16).all(|k| {
                let (dx, dy) = (((k % 4) as f32 + 0.5) / 4.0 - 0.5, ((k / 4) as f32 + 0.5) / 4.0 - 0.5);
                first(&scene.camera.ray(x, y, dx, dy, &mut rng)) == Some(object)
            });
            if !covered {
                continue;
            }
            pixels += 1;
            let mut pixel = [0.0f64; 3];
            for i in 0..spp {
                let mut s = Rng::new((u64::from(y) * u64::from(w) + u64::from(x)) * 1_000_003 + i as u64);
                let [dx, dy] = s.next_2d();
                let mut ray = scene.camera.ray(x, y, dx - 0.5, dy - 0.5, &mut s);
                let mut throughput = Color::ONE;
                let mut radiance = Color::ZERO;
                let mut left: Option<u32> = None;
                for depth in 0..scene.settings.max_depth {
                    let Some(hit) = scene.intersect(&ray, range) else {
                        radiance = throughput * scene.background.color(ray.direction);
                        break;
                    };
                    let record = scene.record(&ray, hit);
                    if scene.sphere_radius(record.object).is_some() && left == Some(record.object) && hit.t < 1e-3 {
                        rehits += 1;
                    }
                    if scene.sphere_radius(record.object).is_some() {
                        // a hit on a sphere: is the point on one?
                        let p = record.point;
                        let gap = scene.spheres.iter().map(|sp| ((p - sp.center).length() - sp.radius).abs());
                        sphere_hits += 1;
                        off_surface += u64::from(gap.fold(f32::INFINITY, f32::min) > 1e-4);
                    }
                    let wo = -ray.direction;
                    let Some(bsdf) = scene.material(&record).bsdf(&record, wo, &scene.textures) else {
                        break;
                    };
                    s.start_bounce(depth);
                    let Some(sample) = bsdf.sample(wo, &mut s) else {
                        break;
                    };
                    directions += 1;
                    non_unit += u64::from((sample.wi.length() - 1.0).abs() > 1e-4);
                    throughput *= sample.value;
                    let wi = if normalize { sample.wi.normalize() } else { sample.wi };
                    left = Some(record.object);
                    ray = Ray::timed(record.spawn_origin(wi), wi, ray.time());
                }
                for (c, v) in radiance.to_array().into_iter().enumerate() {
                    pixel[c] += f64::from(v);
                }
            }
            for c in 0..3 {
                sum[c] += pixel[c] / spp as f64;
            }
        }
    }
    let n = pixels as f64;
    let mean = sum.map(|x| x / n);
    println!(
        "object {object}: {pixels} pixels, {spp} paths each{}: mean {:.5} {:.5} {:.5}; \
         hits on a sphere computed off its surface (> 1e-4): {off_surface} of {sphere_hits}; \
         sampled directions of length off 1 by > 1e-4: {non_unit} of {directions}; \
         hits within 1e-3 on the sphere just left: {rehits}",
        if normalize { ", directions normalised" } else { "" },
        mean[0], mean[1], mean[2]
    );
}
