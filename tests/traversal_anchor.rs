//! The traversal anchor's rays and shapes (`lumen bench --traversal`):
//! lumen's tree finds, for recorded rays, the hits an independent brute-force
//! intersector in f64 finds over the exported shapes; and, in a build with
//! the `embree` feature, the hits Embree finds.

mod common;

use common::d3::{cross, dot, sub, D3};
use lumen::bench::traversal::{record_rays, trace_lumen, Agreement, Found};
use lumen::bench::{bunny_scene, standard_workloads, BUNNY_235K};
use lumen::ray::Ray;
use lumen::scene::{PlacedShapes, Scene};

/// A stored coordinate triple in f64.
fn v(a: [f32; 3]) -> D3 {
    a.map(f64::from)
}

/// The nearest hit from distance 0 of `ray` over every shape, tested one
/// by one in f64 (spheres by their quadratic, triangles and quads by their
/// plane and the point's coordinates in it).
fn brute_force(shapes: &PlacedShapes, ray: &Ray) -> Found {
    let o = v(ray.origin().to_array());
    let d = v(ray.direction.to_array());
    let mut best: Found = None;
    let mut keep = |t: f64, item: usize| {
        if t >= 0.0 && best.is_none_or(|(b, _)| t < f64::from(b)) {
            best = Some((t as f32, item as u32));
        }
    };
    for (i, s) in shapes.spheres.iter().enumerate() {
        let oc = sub(v([s[0], s[1], s[2]]), o);
        let h = dot(d, oc);
        let c = dot(oc, oc) - f64::from(s[3]) * f64::from(s[3]);
        let disc = h * h - dot(d, d) * c;
        if disc >= 0.0 {
            let root = disc.sqrt();
            let near = (h - root) / dot(d, d);
            keep(
                if near >= 0.0 {
                    near
                } else {
                    (h + root) / dot(d, d)
                },
                i,
            );
        }
    }
    // A planar polygon: the plane's distance, then the point's
    // coordinates (α, β) along the edges from `corner`.
    let mut polygon = |corner: D3, e1: D3, e2: D3, item: usize, quad: bool| {
        let n = cross(e1, e2);
        let denom = dot(n, d);
        if denom == 0.0 {
            return;
        }
        let t = dot(n, sub(corner, o)) / denom;
        let p = sub([o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]], corner);
        let nn = dot(n, n);
        let alpha = dot(cross(p, e2), n) / nn;
        let beta = dot(cross(e1, p), n) / nn;
        let inside = if quad {
            (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)
        } else {
            alpha >= 0.0 && beta >= 0.0 && alpha + beta <= 1.0
        };
        if inside {
            keep(t, item);
        }
    };
    let first_quad = shapes.spheres.len();
    for (i, q) in shapes.quads.iter().enumerate() {
        let c = v(q[0]);
        polygon(c, sub(v(q[1]), c), sub(v(q[3]), c), first_quad + i, true);
    }
    let first_triangle = first_quad + shapes.quads.len();
    for (i, t) in shapes.triangles.iter().enumerate() {
        let a = v(t[0]);
        polygon(
            a,
            sub(v(t[1]), a),
            sub(v(t[2]), a),
            first_triangle + i,
            false,
        );
    }
    best
}

/// Every `step`-th recorded ray of `scene` (at most `count`).
fn some_rays(scene: &Scene, spp: u32, step: usize, count: usize) -> Vec<Ray> {
    let recorded = record_rays(scene, spp, usize::MAX).unwrap();
    assert!(recorded.camera > 0 && recorded.rays.len() > recorded.camera);
    recorded
        .rays
        .into_iter()
        .step_by(step)
        .take(count)
        .collect()
}

/// `desc` at `width` pixels across, its shape kept.
fn small(mut desc: lumen::scene::SceneDesc, width: u32) -> Scene {
    if let Some(h) = desc.render.height.as_mut() {
        *h = (*h * width).div_ceil(desc.render.width);
    }
    desc.render.width = width;
    Scene::from_desc(&desc).unwrap()
}

#[test]
fn recorded_rays_are_camera_rays_then_their_bounces_as_the_paths_made_them() {
    let scene = small(lumen::scene::builtin::cover(), 24);
    let a = record_rays(&scene, 2, usize::MAX).unwrap();
    let pixels = (scene.settings.width * scene.settings.height) as usize;
    assert_eq!(a.camera, 2 * pixels);
    // Bounce rays start where the ray before them in the same path ended.
    let bounces = a.rays.len() - a.camera;
    assert!(bounces > a.camera / 2, "{bounces} bounce rays");
    // The same scene, settings and seed record the same rays.
    let b = record_rays(&scene, 2, usize::MAX).unwrap();
    assert_eq!(format!("{:?}", a.rays), format!("{:?}", b.rays));
    // A limit keeps the first rays.
    let c = record_rays(&scene, 2, 100).unwrap();
    assert_eq!(c.rays.len(), 100);
    assert_eq!(
        format!("{:?}", c.rays),
        format!("{:?}", &a.rays[..c.rays.len()])
    );
}

#[test]
fn lumen_finds_the_hits_a_brute_force_f64_intersector_finds_on_the_cover() {
    let scene = small(lumen::scene::builtin::cover(), 60);
    let shapes = scene
        .placed_shapes()
        .expect("the cover places no instances");
    assert_eq!(shapes.spheres.len(), scene.spheres.len());
    let rays = some_rays(&scene, 2, 3, 4000);
    let (found, _) = trace_lumen(&scene, &rays);
    let truth: Vec<Found> = rays.iter().map(|r| brute_force(&shapes, r)).collect();
    let agreement = Agreement::of(&found, &truth);
    assert!(agreement.fraction() >= 0.999, "{agreement:?}");
    assert!(truth.iter().filter(|f| f.is_some()).count() > rays.len() / 2);
}

#[test]
fn lumen_finds_the_hits_a_brute_force_f64_intersector_finds_on_the_bunny() {
    let scene = small(bunny_scene(BUNNY_235K), 40);
    let shapes = scene.placed_shapes().expect("the bunny is placed once");
    assert_eq!((shapes.quads.len(), shapes.triangles.len()), (1, 235_136));
    let rays = some_rays(&scene, 1, 7, 300);
    let (found, _) = trace_lumen(&scene, &rays);
    let truth: Vec<Found> = rays.iter().map(|r| brute_force(&shapes, r)).collect();
    let agreement = Agreement::of(&found, &truth);
    assert!(agreement.fraction() >= 0.995, "{agreement:?}");
    // Both the floor and the bunny are met.
    let on_bunny = truth
        .iter()
        .filter(|f| f.is_some_and(|(_, i)| i > 0))
        .count();
    let on_floor = truth
        .iter()
        .filter(|f| f.is_some_and(|(_, i)| i == 0))
        .count();
    assert!(on_bunny > 30 && on_floor > 30, "{on_bunny} {on_floor}");
}

#[test]
fn an_instanced_scene_exports_no_flat_shapes() {
    let scene = Scene::from_desc(&lumen::bench::bunny_field(BUNNY_235K, 2)).unwrap();
    assert!(scene.placed_shapes().is_none());
    assert!(standard_workloads(1).iter().all(|w| {
        let mut desc = w.desc.clone();
        desc.render.width = 8;
        Scene::from_desc(&desc).unwrap().placed_shapes().is_some()
    }));
}

#[test]
fn the_bench_command_traces_a_workloads_rays_and_names_what_it_compared() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args(["bench", "--traversal", "--spp", "1", "--runs", "1"])
        .args(["--workload", "three-spheres-400x225"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    let row = text
        .lines()
        .find(|l| l.starts_with("three-spheres-400x225"))
        .unwrap_or_else(|| panic!("no row in {text}"));
    let fields: Vec<f64> = row
        .split_whitespace()
        .skip(1)
        .map(|f| f.trim_end_matches('%').parse().unwrap())
        .collect();
    // 400 × 225 camera rays at 1 spp and their bounces; a rate above zero.
    assert!(
        fields[0] > 90_000.0 && fields[1] > 20.0 && fields[1] < 100.0,
        "{row}"
    );
    assert!(fields[2] > 0.0, "{row}");
    if cfg!(feature = "embree") {
        assert!(text.contains("embree-avx2"), "{text}");
    } else {
        assert!(text.contains("Embree is not in this build"), "{text}");
    }
    // An unknown workload is refused with the names of those there are.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lumen"))
        .args(["bench", "--traversal", "--workload", "bunny"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("bunny-235k-400x400"), "{err}");
}

#[cfg(feature = "embree")]
mod embree {
    use super::*;
    use lumen::bench::embree::{EmbreeIsa, EmbreeScene};

    fn agree_with_embree(scene: &Scene, spp: u32) {
        let shapes = scene.placed_shapes().unwrap();
        let rays = record_rays(scene, spp, usize::MAX).unwrap().rays;
        let (found, _) = trace_lumen(scene, &rays);
        let embree = EmbreeScene::new(&shapes, EmbreeIsa::Avx2).unwrap();
        let (theirs, _) = embree.trace(&rays);
        let agreement = Agreement::of(&found, &theirs);
        eprintln!("{agreement:?}");
        assert!(agreement.fraction() >= 0.9995, "{agreement:?}");
    }

    #[test]
    fn lumen_and_embree_find_the_same_hits_on_the_cover() {
        agree_with_embree(&small(lumen::scene::builtin::cover(), 100), 2);
    }

    #[test]
    fn lumen_and_embree_find_the_same_hits_on_the_bunny() {
        agree_with_embree(&small(bunny_scene(BUNNY_235K), 100), 2);
    }
}
