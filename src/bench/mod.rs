//! Throughput benchmarks on fixed workloads: `lumen bench`.

pub mod efficiency;
#[cfg(feature = "embree")]
pub mod embree;
pub mod traversal;

use crate::render::{render, RenderStats};
use crate::rng::Rng;
use crate::scene::builtin;
use crate::scene::desc::{
    AttenuationDesc, BounceDesc, DielectricDesc, DiffuseDesc, MaterialDesc, MetalDesc, ObjectDesc,
    SceneDesc, TransformDesc,
};
use crate::scene::{Scene, SceneError};
use std::time::{Duration, Instant};

/// One benchmark workload.
#[derive(Clone, Debug)]
pub struct Workload {
    /// Short name.
    pub name: &'static str,
    /// The scene rendered.
    pub desc: SceneDesc,
}

/// The measured result of a workload: the median of several runs.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Workload name.
    pub name: &'static str,
    /// Counts of one run (identical in every run).
    pub stats: RenderStats,
    /// Median wall time.
    pub median: Duration,
    /// All run times, in run order.
    pub runs: Vec<Duration>,
}

impl Measurement {
    /// Median rays per second.
    pub fn rays_per_second(&self) -> f64 {
        self.stats.rays_per_second(self.median)
    }

    /// Median camera samples per second.
    pub fn samples_per_second(&self) -> f64 {
        self.stats.samples_per_second(self.median)
    }
}

/// The 235,136-triangle bunny of the mesh workload (the bunny split three
/// times by midpoint subdivision), in the source tree.
pub const BUNNY_235K: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny_235k.glb");

/// The mesh workload: the 235,136-triangle bunny (diffuse 0.7, flat
/// shading) on a 60×60 grey (0.5) floor quad at y = 0, under a uniform
/// white sky, seen from (0, 8, 22) looking at (0, 4.5, 0) with a 40° field
/// of view, 400×400, depth 8. `scripts/peers/mitsuba_bunny.py` renders the
/// same scene in Mitsuba 3.
pub fn bunny_scene(file: &str) -> SceneDesc {
    let mut desc = SceneDesc {
        caption: "the 235k-triangle bunny on a floor under a white sky".into(),
        ..SceneDesc::default()
    };
    desc.render.width = 400;
    desc.render.height = Some(400);
    desc.render.max_depth = 8;
    // The sampler its throughput has always been measured with.
    desc.render.sampler = crate::scene::Sampling::Sobol;
    desc.camera.vfov = 40.0;
    desc.camera.lookfrom = [0.0, 8.0, 22.0];
    desc.camera.lookat = [0.0, 4.5, 0.0];
    desc.background = crate::scene::desc::BackgroundDesc::Solid {
        color: [1.0, 1.0, 1.0],
    };
    let diffuse = |a: f64| {
        MaterialDesc::Diffuse(DiffuseDesc {
            albedo: [a; 3].into(),
            bounce: BounceDesc::Lambertian,
            attenuation: AttenuationDesc::Scale,
            ..Default::default()
        })
    };
    desc.materials.insert("bunny".into(), diffuse(0.7));
    desc.materials.insert("floor".into(), diffuse(0.5));
    desc.objects.push(ObjectDesc::Quad {
        flip_normals: false,
        corner: [-30.0, 0.0, -30.0],
        u: [0.0, 0.0, 60.0],
        v: [60.0, 0.0, 0.0],
        material: "floor".into(),
        transform: Vec::new(),
    });
    desc.objects.push(ObjectDesc::Mesh {
        flip_normals: false,
        file: file.into(),
        material: Some("bunny".into()),
        smooth: false,
        allow_outside: false,
        part: None,
        flip_v: false,
        transform: Vec::new(),
    });
    desc
}

/// A field of `n` bunnies (`file`) on a grid 12 units apart, each turned
/// about the vertical by its own angle: one mesh, `n` instances, seen from
/// above at 400×225, depth 8.
pub fn bunny_field(file: &str, n: usize) -> SceneDesc {
    let mut desc = bunny_scene(file);
    desc.caption = format!("a field of {n} instanced bunnies");
    desc.render.height = Some(225);
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let half = (side as f64 - 1.0) * 6.0;
    desc.camera.lookfrom = [0.0, 1.5 * half + 30.0, 2.0 * half + 40.0];
    desc.camera.lookat = [0.0, 0.0, 0.0];
    desc.camera.vfov = 45.0;
    let ObjectDesc::Quad { corner, u, v, .. } = &mut desc.objects[0] else {
        unreachable!("the floor comes first")
    };
    let size = 12.0 * side as f64 + 60.0;
    *corner = [-size / 2.0, 0.0, -size / 2.0];
    *u = [0.0, 0.0, size];
    *v = [size, 0.0, 0.0];
    desc.objects.truncate(1);
    let mut rng = Rng::new(FIELD_SEED);
    for k in 0..n {
        let (i, j) = ((k % side) as f64, (k / side) as f64);
        desc.objects.push(ObjectDesc::Mesh {
            flip_normals: false,
            file: file.into(),
            material: Some("bunny".into()),
            smooth: false,
            allow_outside: false,
            part: None,
            flip_v: false,
            transform: vec![
                TransformDesc::Rotate {
                    axis: [0.0, 1.0, 0.0],
                    degrees: 360.0 * rng.next_f64(),
                },
                TransformDesc::Translate([12.0 * i - half, 0.0, 12.0 * j - half]),
            ],
        });
    }
    desc
}

/// The standard workloads: the cover at 400×225 and the three-ball scene
/// (depth 50), the mesh workload ([`bunny_scene`], depth 8) and the
/// materials workload ([`efficiency::materials_spheres`], depth 16), at
/// `spp` samples per pixel.
pub fn standard_workloads(spp: u32) -> Vec<Workload> {
    let mut cover = builtin::cover();
    cover.render.width = 400;
    let mut three = builtin::find("metal-fuzz-0.2")
        .expect("built-in scene exists")
        .desc();
    three.render.width = 400;
    let mut list = vec![
        Workload {
            name: "cover-400x225",
            desc: cover,
        },
        Workload {
            name: "three-spheres-400x225",
            desc: three,
        },
    ];
    for w in &mut list {
        w.desc.render.max_depth = 50;
    }
    list.push(Workload {
        name: "bunny-235k-400x400",
        desc: bunny_scene(BUNNY_235K),
    });
    list.push(Workload {
        name: "materials-320x180",
        desc: efficiency::materials_spheres(),
    });
    for w in &mut list {
        w.desc.render.samples_per_pixel = spp;
    }
    list
}

/// One row of the instancing table.
#[derive(Clone, Debug)]
pub struct InstancePoint {
    /// Instances of the 235k-triangle bunny.
    pub instances: usize,
    /// Time to compile the scene (loading the mesh and building the trees).
    pub build: Duration,
    /// Bytes held by meshes and trees.
    pub geometry_bytes: u64,
    /// The process's peak resident memory after rendering, if known.
    pub peak_bytes: Option<u64>,
    /// The render measurement.
    pub measurement: Measurement,
}

/// Builds and renders a field of `n` instances of the 235k-triangle bunny.
pub fn measure_instances(n: usize, spp: u32, runs: usize) -> Result<InstancePoint, SceneError> {
    let mut desc = bunny_field(BUNNY_235K, n);
    desc.render.samples_per_pixel = spp;
    let start = Instant::now();
    let scene = Scene::from_desc(&desc)?;
    let build = start.elapsed();
    drop(desc);
    let measurement = measure_scene("instances", &scene, runs);
    Ok(InstancePoint {
        instances: n,
        build,
        geometry_bytes: scene.stats.geometry_bytes,
        peak_bytes: peak_memory(),
        measurement,
    })
}

/// The process's peak resident memory (Linux `VmHWM`), if known.
pub fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Renders `workload` `runs` times (after one warm-up) and takes the median time.
pub fn measure(workload: &Workload, runs: usize) -> Result<Measurement, SceneError> {
    let scene = Scene::from_desc(&workload.desc)?;
    Ok(measure_scene(workload.name, &scene, runs))
}

/// Renders `scene` `runs` times (after one warm-up) and takes the median time.
pub fn measure_scene(name: &'static str, scene: &Scene, runs: usize) -> Measurement {
    let _ = render(scene, &|_| {});
    let (times, stats) = time_renders(scene, runs);
    Measurement {
        name,
        stats,
        median: median(&times),
        runs: times,
    }
}

/// The median of `times` (the upper one of an even count), which must not
/// be empty.
pub fn median(times: &[Duration]) -> Duration {
    let mut sorted = times.to_vec();
    sorted.sort();
    sorted[sorted.len() / 2]
}

/// Renders `scene` `runs` times (at least once): each run's time, in run
/// order, and the counts of one run (identical in every run).
pub fn time_renders(scene: &Scene, runs: usize) -> (Vec<Duration>, RenderStats) {
    let mut times = Vec::with_capacity(runs);
    let mut stats = RenderStats::default();
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let (_, s) = render(scene, &|_| {});
        times.push(start.elapsed());
        stats = s;
    }
    (times, stats)
}

/// Seed of the sphere fields' layout.
const FIELD_SEED: u64 = 0xF1E1D;

/// A cover-like scene with about `n` small spheres (exactly `n` unless `n` is
/// tiny), at the cover's density: the spheres fill a square of about √n × √n
/// unit cells around the cover's three big spheres, so the area grows with `n`.
/// Materials come from a palette of 16 (80% diffuse, 15% metal, 5% glass, as on
/// the cover), so the scene's memory is the spheres', not the materials'.
pub fn sphere_field(n: usize) -> SceneDesc {
    let mut desc = builtin::cover_with_grid(0);
    desc.caption = format!("cover-like field of {n} small spheres");
    desc.render.width = 400;
    let mut rng = Rng::new(FIELD_SEED);
    let palette: Vec<(String, MaterialDesc)> = (0..16)
        .map(|i| match i {
            0..=11 => (
                format!("field-diffuse{i}"),
                MaterialDesc::Diffuse(DiffuseDesc {
                    albedo: [0; 3].map(|_| rng.next_f64() * rng.next_f64()).into(),
                    bounce: BounceDesc::Lambertian,
                    attenuation: AttenuationDesc::Scale,
                    ..Default::default()
                }),
            ),
            12..=14 => (
                format!("field-metal{i}"),
                MaterialDesc::Metal(MetalDesc {
                    albedo: [0; 3].map(|_| 0.5 + 0.5 * rng.next_f64()).into(),
                    fuzz: 0.5 * rng.next_f64(),
                    ..Default::default()
                }),
            ),
            _ => (
                "glass".to_string(),
                MaterialDesc::Dielectric(DielectricDesc {
                    ior: 1.5,
                    refract_only: false,
                    ..Default::default()
                }),
            ),
        })
        .collect();
    for (name, m) in &palette {
        desc.materials.insert(name.clone(), m.clone());
    }
    // Cells of a side×side grid, skipping those under the big spheres.
    let side = ((n as f64).sqrt().ceil() as i64).max(1) + 2;
    let half = side / 2;
    let big = [[0.0, 0.2, 0.0], [-4.0, 0.2, 0.0], [4.0, 0.2, 0.0]];
    let mut placed = 0;
    'grid: for a in -half..side - half {
        for c in -half..side - half {
            if placed == n {
                break 'grid;
            }
            let center = [
                a as f64 + 0.9 * rng.next_f64(),
                0.2,
                c as f64 + 0.9 * rng.next_f64(),
            ];
            let pick = rng.next_f64();
            if big.iter().any(|b| {
                let d = [center[0] - b[0], center[2] - b[2]];
                (d[0] * d[0] + d[1] * d[1]).sqrt() <= 1.2
            }) {
                continue;
            }
            let k = if pick < 0.8 {
                (pick / 0.8 * 12.0) as usize
            } else if pick < 0.95 {
                12 + ((pick - 0.8) / 0.15 * 3.0) as usize
            } else {
                15
            };
            desc.objects.push(ObjectDesc::Sphere {
                flip_normals: false,
                center,
                radius: 0.2,
                material: palette[k.min(15)].0.clone(),
                transform: Vec::new(),
            });
            placed += 1;
        }
    }
    desc
}

/// One row of the scaling table.
#[derive(Clone, Debug)]
pub struct ScalingPoint {
    /// Spheres in the scene (the field plus ground and three big ones).
    pub spheres: usize,
    /// Time to compile the scene (mostly the BVH build).
    pub build: Duration,
    /// Bytes held by the BVH.
    pub bvh_bytes: usize,
    /// The render measurement.
    pub measurement: Measurement,
}

/// Peak memory a sphere of a field takes while the field is described,
/// built and rendered (about 400 bytes measured at 10⁶ spheres, with room).
const FIELD_BYTES_PER_SPHERE: u64 = 512;

/// Builds and renders the field of about `n` spheres (400×225, `spp`, depth 50).
pub fn measure_field(n: usize, spp: u32, runs: usize) -> Result<ScalingPoint, SceneError> {
    // Counted before the field is made: its description alone would take
    // more than the machine has for a large `n`.
    crate::memory::check(
        n as u64 * FIELD_BYTES_PER_SPHERE,
        &format!("a field of {n} spheres"),
    )
    .map_err(|e| SceneError::Invalid {
        field: "--field".into(),
        message: e.to_string(),
    })?;
    let mut desc = sphere_field(n);
    desc.render.samples_per_pixel = spp;
    desc.render.max_depth = 50;
    let spheres = desc.objects.len();
    let start = Instant::now();
    let scene = Scene::from_desc(&desc)?;
    let build = start.elapsed();
    drop(desc);
    let measurement = measure_scene("field", &scene, runs);
    Ok(ScalingPoint {
        spheres,
        build,
        bvh_bytes: scene.bvh_memory_bytes(),
        measurement,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn sphere_fields_have_the_asked_count_at_constant_density() {
        for n in [1, 100, 2_000] {
            let desc = sphere_field(n);
            let small: Vec<[f64; 3]> = desc
                .objects
                .iter()
                .filter_map(|o| match o {
                    ObjectDesc::Sphere { center, radius, .. } if *radius == 0.2 => Some(*center),
                    _ => None,
                })
                .collect();
            assert_eq!(small.len(), n);
            // Spread over about n unit cells: the bounding square's area is
            // n plus at most the border cells and those skipped under the big spheres.
            let extent = |k: usize| {
                let lo = small.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min);
                let hi = small.iter().map(|c| c[k]).fold(f64::NEG_INFINITY, f64::max);
                hi - lo
            };
            let area = extent(0) * extent(2);
            assert!(
                area <= n as f64 + 6.0 * (n as f64).sqrt() + 40.0,
                "n = {n}: area {area}"
            );
            Scene::from_desc(&desc).expect("field compiles");
        }
        let big = sphere_field(10_000);
        let xs = big.objects.iter().filter_map(|o| match o {
            ObjectDesc::Sphere { center, radius, .. } if *radius == 0.2 => Some(center[0]),
            _ => None,
        });
        let width = xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min);
        assert!(
            (95.0..110.0).contains(&width),
            "10⁴ spheres span {width} units"
        );
    }

    #[test]
    fn empty_and_one_sphere_scenes_render() {
        let mut desc = builtin::cover_with_grid(0);
        desc.render.width = 16;
        desc.render.samples_per_pixel = 2;
        desc.objects.clear();
        let scene = Scene::from_desc(&desc).expect("empty scene compiles");
        let (film, stats) = render(&scene, &|_| {});
        // Every camera ray escapes: one segment each, and the sky's colour.
        assert_eq!(stats.rays, stats.samples);
        let ray = scene.camera.ray(8, 4, 0.0, 0.0, &mut Rng::new(1));
        let sky = scene.background.color(ray.direction);
        assert!((film.pixel(8, 4) - sky).abs().max_element() < 0.02);

        desc.objects.push(ObjectDesc::Sphere {
            flip_normals: false,
            center: [0.0, 0.0, 0.0],
            radius: 2.0,
            material: "big-diffuse".to_string(),
            transform: Vec::new(),
        });
        let scene = Scene::from_desc(&desc).expect("one-sphere scene compiles");
        let (film, stats) = render(&scene, &|_| {});
        assert!(
            stats.rays > stats.samples,
            "camera rays hit the sphere and bounce"
        );
        // The sphere fills the centre of the view and is darker than the sky.
        let (w, h) = (film.width(), film.height());
        let centre = film.pixel(w / 2, h / 2);
        assert!(centre.length() < sky.length() && centre != Vec3::ZERO);
    }

    #[test]
    fn bunny_fields_place_one_mesh_many_times() {
        let small = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny.obj");
        let mut desc = bunny_field(small, 9);
        desc.render.width = 16;
        desc.render.height = Some(9);
        desc.render.samples_per_pixel = 1;
        let scene = Scene::from_desc(&desc).expect("the field compiles");
        assert_eq!(scene.stats.instances, 9);
        assert_eq!(scene.stats.triangles, 3_674);
        assert_eq!(scene.stats.placed_triangles, 9 * 3_674);
        let (_, stats) = render(&scene, &|_| {});
        assert!(stats.rays > stats.samples, "camera rays hit the field");
        let one = Scene::from_desc(&bunny_scene(small)).expect("the bench scene compiles");
        assert_eq!((one.stats.instances, one.stats.triangles), (0, 3_674));
    }
}
