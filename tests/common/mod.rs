//! Helpers shared by the integration tests: small scenes and per-pixel sample
//! statistics taken through the library's own render loop.
#![allow(dead_code)]

#[path = "d3.rs"]
pub mod d3;
#[path = "stale.rs"]
pub mod stale;

use lumen::film::Film;
use lumen::render::{render_samples, RenderStats};
use lumen::scene::builtin;
use lumen::scene::desc::{BackgroundDesc, MaterialDesc, ObjectDesc, RenderDesc};
use lumen::scene::{Overrides, Scene, SceneDesc};

/// Standard errors allowed between an estimate and its expected value.
pub const K: f64 = 5.0;

/// A built-in scene's description at a small size.
pub fn builtin_desc(name: &str, width: u32, spp: u32, seed: u64) -> SceneDesc {
    let mut desc = builtin::find(name)
        .unwrap_or_else(|| panic!("no built-in scene {name}"))
        .desc();
    Overrides {
        width: Some(width),
        samples_per_pixel: Some(spp),
        seed: Some(seed),
        ..Overrides::default()
    }
    .apply(&mut desc);
    desc
}

/// A built-in scene compiled at a small size.
pub fn builtin_scene(name: &str, width: u32, spp: u32, seed: u64) -> Scene {
    Scene::from_desc(&builtin_desc(name, width, spp, seed)).unwrap()
}

/// One sphere of `material`, radius 1 at distance 2 in front of the default
/// camera, inside a uniform white background ("white furnace"); gamma 1,
/// the notes' estimator (`bsdf`: every sample of a white sphere is at most
/// 1).
pub fn furnace(material: MaterialDesc, width: u32, height: u32, spp: u32, depth: u32) -> Scene {
    Scene::from_desc(&furnace_desc(material, width, height, spp, depth)).unwrap()
}

/// The description of [`furnace`]'s scene.
pub fn furnace_desc(
    material: MaterialDesc,
    width: u32,
    height: u32,
    spp: u32,
    depth: u32,
) -> SceneDesc {
    SceneDesc {
        caption: String::new(),
        render: RenderDesc {
            width,
            height: Some(height),
            samples_per_pixel: spp,
            max_depth: depth,
            gamma: 1.0,
            seed: 11,
            integrator: lumen::scene::Integrator::Bsdf,
            ..RenderDesc::default()
        },
        camera: Default::default(),
        background: BackgroundDesc::Solid {
            color: [1.0, 1.0, 1.0],
        },
        textures: Default::default(),
        materials: [("m".to_string(), material)].into_iter().collect(),
        objects: vec![ObjectDesc::Sphere {
            flip_normals: false,
            center: FURNACE_CENTER,
            radius: FURNACE_RADIUS,
            material: "m".into(),
            transform: Vec::new(),
        }],
        lights: Vec::new(),
        media: Default::default(),
    }
}

/// Centre of the furnace sphere.
pub const FURNACE_CENTER: [f64; 3] = [0.0, 0.0, -2.0];
/// Radius of the furnace sphere.
pub const FURNACE_RADIUS: f64 = 1.0;

/// Per-pixel statistics of every sample of a render.
pub struct PixelStats {
    pub width: u32,
    pub height: u32,
    /// Finite samples per pixel.
    pub counts: Vec<u32>,
    /// Mean of each pixel's finite samples, per channel.
    pub mean: Vec<[f64; 3]>,
    /// Unbiased sample variance of each pixel's samples, per channel.
    pub var: Vec<[f64; 3]>,
    /// Smallest and largest sample value seen, per channel.
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// The film the samples add up to.
    pub film: Film,
    pub stats: RenderStats,
}

/// Renders `scene` one sample index at a time with
/// [`lumen::render::render_samples`], so that every sample's value is seen,
/// and gathers each pixel's mean and variance.
pub fn pixel_stats(scene: &Scene) -> PixelStats {
    let s = &scene.settings;
    let n = (s.width * s.height) as usize;
    let mut sum = vec![[0.0f64; 3]; n];
    let mut sum2 = vec![[0.0f64; 3]; n];
    let mut counts = vec![0u32; n];
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut film = Film::new(s.width, s.height);
    let mut exact = vec![lumen::film::Sum::ZERO; n];
    let mut stats = RenderStats::default();
    for index in 0..s.samples_per_pixel {
        let mut one = Film::new(s.width, s.height);
        stats.add(render_samples(scene, &mut one, index..index + 1, &|_| {}));
        let (sums, cs) = one.raw();
        for (a, b) in exact.iter_mut().zip(sums) {
            *a = a.plus(*b);
        }
        for i in 0..n {
            if cs[i] == 0 {
                continue;
            }
            counts[i] += 1;
            for c in 0..3 {
                let v = sums[i].to_f64()[c];
                sum[i][c] += v;
                sum2[i][c] += v * v;
                min[c] = min[c].min(v);
                max[c] = max[c].max(v);
            }
        }
        render_samples(scene, &mut film, index..index + 1, &|_| {});
    }
    // The film adds the same samples (exactly, in fixed point): identical sums.
    assert_eq!(
        film.raw().0,
        &exact[..],
        "film sums differ from the samples"
    );
    assert_eq!(film.raw().1, &counts[..]);
    let mut mean = vec![[0.0; 3]; n];
    let mut var = vec![[0.0; 3]; n];
    for i in 0..n {
        let k = f64::from(counts[i]);
        for c in 0..3 {
            mean[i][c] = sum[i][c] / k;
            var[i][c] = if counts[i] > 1 {
                ((sum2[i][c] - k * mean[i][c] * mean[i][c]) / (k - 1.0)).max(0.0)
            } else {
                0.0
            };
        }
    }
    PixelStats {
        width: s.width,
        height: s.height,
        counts,
        mean,
        var,
        min,
        max,
        film,
        stats,
    }
}

impl PixelStats {
    /// Mean over the pixels `x0..x1` × `y0..y1` of channel `c`, and its
    /// standard error: the pixels are independent, each mean of `count`
    /// samples has variance var/count.
    pub fn region(
        &self,
        xs: std::ops::Range<u32>,
        ys: std::ops::Range<u32>,
        c: usize,
    ) -> (f64, f64) {
        let (mut m, mut v, mut n) = (0.0, 0.0, 0.0);
        for y in ys {
            for x in xs.clone() {
                let i = (y * self.width + x) as usize;
                m += self.mean[i][c];
                v += self.var[i][c] / f64::from(self.counts[i]);
                n += 1.0;
            }
        }
        (m / n, v.sqrt() / n)
    }

    /// Mean of the whole image in channel `c`, with its standard error.
    pub fn image(&self, c: usize) -> (f64, f64) {
        self.region(0..self.width, 0..self.height, c)
    }

    /// The mean of pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [f64; 3] {
        self.mean[(y * self.width + x) as usize]
    }
}

/// Asserts that two independent estimates agree within K combined standard errors.
pub fn assert_agree(what: &str, a: (f64, f64), b: (f64, f64)) {
    let se = (a.1 * a.1 + b.1 * b.1).sqrt();
    assert!(
        (a.0 - b.0).abs() <= K * se,
        "{what}: {:.5} ± {:.5} vs {:.5} ± {:.5} differ by more than {K} standard errors",
        a.0,
        a.1,
        b.0,
        b.1
    );
}

/// Reads an OpenEXR file's first RGBA layer: its size and its RGB pixels, row-major.
pub fn read_exr_rgb(path: &std::path::Path) -> ((usize, usize), Vec<[f32; 3]>) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0.0f32; 3]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    let size = img.layer_data.size;
    (
        (size.width(), size.height()),
        img.layer_data.channel_data.pixels.1,
    )
}

/// A fresh empty directory for one test (removed first if a previous run
/// left it behind).
pub fn scratch_dir(name: &str) -> std::path::PathBuf {
    stale::remove_stale_dirs(&format!("lumen-{name}-"));
    let dir = std::env::temp_dir().join(format!("lumen-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The path of the bundled Stanford bunny OBJ.
pub fn bunny_obj() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj")
}

/// Writes `text` to `dir/name` and reads it as a scene file.
pub fn scene_file(dir: &std::path::Path, name: &str, text: &str) -> lumen::scene::file::SceneFile {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    lumen::scene::file::SceneFile::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Writes `text` to `dir/name` and compiles it as a scene file.
pub fn compile_file(dir: &std::path::Path, name: &str, text: &str) -> Scene {
    scene_file(dir, name, text)
        .compile(&Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// An OBJ of an icosphere of radius `radius` centred at the origin:
/// the icosahedron with every face split `subdivisions` times, vertices
/// pushed onto the sphere, faces counter-clockwise seen from outside. With
/// `normals` the file gives every vertex its normal (`vn`), the unit radial
/// direction times `normals` (use −1 for normals pointing inwards).
pub fn icosphere_obj(subdivisions: u32, radius: f64, normals: Option<f64>) -> String {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let unit = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / l, p[1] / l, p[2] / l]
    };
    for p in &mut v {
        *p = unit(*p);
    }
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, v: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (v[a], v[b]);
                v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let ab = midpoint(a, b, &mut v);
            let bc = midpoint(b, c, &mut v);
            let ca = midpoint(c, a, &mut v);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    let mut obj = String::from("# icosphere\n");
    for p in &v {
        obj += &format!("v {} {} {}\n", p[0] * radius, p[1] * radius, p[2] * radius);
    }
    if let Some(s) = normals {
        for p in &v {
            obj += &format!("vn {} {} {}\n", p[0] * s, p[1] * s, p[2] * s);
        }
    }
    for [a, b, c] in f {
        let (a, b, c) = (a + 1, b + 1, c + 1);
        obj += &if normals.is_some() {
            format!("f {a}//{a} {b}//{b} {c}//{c}\n")
        } else {
            format!("f {a} {b} {c}\n")
        };
    }
    obj
}

/// Renders `scene` on a pool of `threads` threads.
pub fn render_with_threads(scene: &Scene, threads: usize) -> (Film, RenderStats) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| lumen::render::render(scene, &|_| {}))
}

/// Compares two renders of the same view pixel by pixel: every pixel's
/// means must agree within `k` combined standard errors (from each pixel's
/// own sample variance; the two estimates are treated as independent, which
/// over-states the noise when they share a seed). Returns the largest
/// |difference| / standard error seen and the number of pixels compared with
/// a non-zero standard error.
pub fn assert_pixels_agree(what: &str, a: &PixelStats, b: &PixelStats, k: f64) -> (f64, usize) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut worst: f64 = 0.0;
    let mut noisy = 0;
    for i in 0..a.mean.len() {
        for c in 0..3 {
            let d = (a.mean[i][c] - b.mean[i][c]).abs();
            let se = (a.var[i][c] / f64::from(a.counts[i]) + b.var[i][c] / f64::from(b.counts[i]))
                .sqrt();
            if se == 0.0 {
                // Both pixels are exact (every sample equal): so must be
                // their means, to rounding.
                assert!(
                    d <= 1e-6,
                    "{what}: pixel {i} channel {c}: {} vs {}, both without noise",
                    a.mean[i][c],
                    b.mean[i][c]
                );
                continue;
            }
            noisy += 1;
            worst = worst.max(d / se);
            assert!(
                d <= k * se,
                "{what}: pixel ({}, {}) channel {c}: {} vs {} differ by {:.2} standard errors",
                i as u32 % a.width,
                i as u32 / a.width,
                a.mean[i][c],
                b.mean[i][c],
                d / se
            );
        }
    }
    (worst, noisy)
}

/// A scene file's text: the camera at the centre of a ball of light (radius
/// 10, radiance (2, 3, 4), one- or `two_sided`; the camera sees its inside,
/// the back of its surface) that also holds a matte ball of `albedo`
/// (radius 1, 3 units down −z), which fills the camera's 20° view when it
/// looks down −z (`towards_ball`) and is out of view when it looks the other
/// way. `render` gives the lines of the `[render]` table.
pub fn ball_in_light(
    render: &str,
    two_sided: bool,
    albedo: [f64; 3],
    towards_ball: bool,
) -> String {
    let lookat_z = if towards_ball { -1 } else { 1 };
    let [r, g, b] = albedo;
    format!(
        r#"[render]
{render}

[camera]
vfov = 20
lookfrom = [0, 0, 0]
lookat = [0, 0, {lookat_z}]

[background]
type = "solid"
color = [0, 0, 0]

[materials.light]
type = "emissive"
radiance = [2, 3, 4]
two_sided = {two_sided}

[materials.matte]
type = "diffuse"
albedo = [{r}, {g}, {b}]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 10
material = "light"

[[objects]]
type = "sphere"
center = [0, 0, -3]
radius = 1
material = "matte"
"#
    )
}

/// Each 8 × 8 tile of two renders of one view agrees in every channel, and
/// the first (the `path` render) has the smaller standard error over the
/// image.
pub fn assert_tiles_agree(what: &str, path: &PixelStats, bsdf: &PixelStats) {
    let noise = tiles_agree(what, path, bsdf);
    assert!(
        noise.0 < noise.1,
        "{what}: path's tiles are noisier ({} against {})",
        noise.0,
        noise.1
    );
}

/// Each 8 × 8 tile of two renders of one view agrees in every channel;
/// returns the sums of the tiles' standard errors of each.
pub fn tiles_agree(what: &str, path: &PixelStats, bsdf: &PixelStats) -> (f64, f64) {
    let mut noise = (0.0, 0.0);
    for c in 0..3 {
        for ty in 0..path.height / 8 {
            for tx in 0..path.width / 8 {
                let tile = |s: &PixelStats| s.region(tx * 8..tx * 8 + 8, ty * 8..ty * 8 + 8, c);
                let (a, b) = (tile(path), tile(bsdf));
                assert_agree(&format!("{what}: tile ({tx}, {ty}), channel {c}"), a, b);
                noise.0 += a.1;
                noise.1 += b.1;
            }
        }
    }
    noise
}

/// The message of the scene file `text` (written to `dir/bad.toml`), which
/// must be refused, when read or when compiled.
pub fn scene_file_error(dir: &std::path::Path, text: &str) -> String {
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    match lumen::scene::file::SceneFile::read(&path) {
        Err(e) => e.to_string(),
        Ok(file) => match file.compile(&Overrides::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{text}"),
        },
    }
}

/// The name a scene file of `format` is read under: `s.toml` or `s.json`.
pub fn scene_file_name(format: lumen::scene::file::Format) -> &'static str {
    match format {
        lumen::scene::file::Format::Toml => "s.toml",
        lumen::scene::file::Format::Json => "s.json",
    }
}

/// Reads `text` (named `name`) with the quick reader and with the precise
/// one, which must agree: on the description, or on the error. Returns the
/// quick reader's result.
pub fn read_both(
    name: &str,
    text: &str,
    format: lumen::scene::file::Format,
) -> Result<lumen::scene::file::SceneFile, lumen::scene::file::SceneFileError> {
    use lumen::scene::file::SceneFile;
    let quick = SceneFile::parse(name, text.to_string(), format);
    let precise = SceneFile::parse_with_positions(name, text.to_string(), format);
    match (&quick, &precise) {
        (Ok(a), Ok(b)) => assert_eq!(a.desc, b.desc, "{text:?}"),
        (Err(a), Err(b)) => assert_eq!(a, b, "{text:?}"),
        _ => panic!("the readers disagree on {text:?}: {quick:?} {precise:?}"),
    }
    quick
}

/// Renders `share` of `desc` through the library, stopping after `passes`
/// passes if given, and writes its part file to `path`.
pub fn write_share(
    desc: &SceneDesc,
    share: lumen::part::Share,
    path: &std::path::Path,
    passes: Option<u32>,
) -> std::path::PathBuf {
    let scene = Scene::from_desc(desc).unwrap();
    let session = lumen::progressive::Session::with_share(desc, scene, share).unwrap();
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    run_and_write(session, path, passes);
    path.to_path_buf()
}

/// Resumes the part file at `path`, of `share` of `desc`, as a task run
/// again does: renders the rest of its share and rewrites it.
pub fn finish_share(desc: &SceneDesc, share: lumen::part::Share, path: &std::path::Path) {
    let ckpt = lumen::checkpoint::Checkpoint::read(path).unwrap();
    let scene = Scene::from_desc(desc).unwrap();
    let session = lumen::progressive::Session::with_share(desc, scene, share)
        .unwrap()
        .restore(ckpt, path)
        .unwrap();
    let run = run_and_write(session, path, None);
    assert_eq!(run.reason, lumen::progressive::StopReason::Complete);
}

/// Runs `session`, stopping after `passes` passes if given, and writes its
/// checkpoint to `path`.
fn run_and_write(
    mut session: lumen::progressive::Session,
    path: &std::path::Path,
    passes: Option<u32>,
) -> lumen::progressive::RunSummary {
    use std::sync::atomic::{AtomicBool, Ordering};
    let stop = AtomicBool::new(false);
    let run = session
        .run(&stop, None, &|_| {}, &mut |_, pass| {
            if Some(pass.number) == passes {
                stop.store(true, Ordering::SeqCst);
            }
            Ok::<(), ()>(())
        })
        .unwrap();
    session.checkpoint().write(path).unwrap();
    run
}

/// The peak resident memory, in MB, of the largest child process this test
/// process has waited for (`RUSAGE_CHILDREN`): a test that runs one child
/// measures that child.
pub fn children_peak_mb() -> f64 {
    // SAFETY: an all-zero rusage is valid (integers only), and getrusage
    // fills the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    assert_eq!(
        unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) },
        0
    );
    // ru_maxrss is in kilobytes on Linux.
    usage.ru_maxrss as f64 / 1024.0
}

/// The colour of the material where the ray from `from` along `towards`
/// first hits: its albedo, or its radiance for a light.
pub fn colour_at(
    scene: &Scene,
    from: lumen::math::Vec3,
    towards: lumen::math::Vec3,
) -> lumen::math::Color {
    use lumen::bsdf::Lobe;
    let ray = lumen::ray::Ray::new(from, towards.normalize());
    let record = scene
        .hit(&ray, lumen::math::Interval::new(1e-4, f32::INFINITY))
        .expect("a hit");
    let material = scene.material(&record);
    if material.emits() {
        return material.emitted(&record, &scene.textures);
    }
    match material
        .bsdf(&record, -ray.direction, &scene.textures)
        .map(|b| b.lobe)
    {
        Some(Lobe::Diffuse(d)) => d.albedo,
        Some(Lobe::Metal(m)) => m.albedo,
        Some(Lobe::Principled(p)) => p.base_color,
        other => panic!("no colour: {other:?}"),
    }
}

/// Whether two colours agree to 10⁻⁴ in every channel.
pub fn colours_close(a: lumen::math::Color, b: lumen::math::Color) -> bool {
    (a - b).abs().max_element() < 1e-4
}

/// Writes `path`, a 4 × 2 PNG of eight pure colours (8-bit 0 and 255,
/// which sRGB decodes to exactly 0 and 1), and returns them row by row
/// from the top, as linear colours.
pub fn eight_colours_png(path: &std::path::Path) -> [lumen::math::Color; 8] {
    let texels: [[u8; 3]; 8] = [
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [255, 255, 0],
        [0, 255, 255],
        [255, 0, 255],
        [255, 255, 255],
        [0, 0, 0],
    ];
    image::RgbImage::from_fn(4, 2, |x, y| image::Rgb(texels[(y * 4 + x) as usize]))
        .save(path)
        .unwrap();
    texels.map(|t| lumen::math::Color::from_array(t.map(|c| f32::from(c) / 255.0)))
}

/// Checks that the sphere of radius below 3 about `centre`, textured by
/// [`eight_colours_png`], shows each texel at its centre where Mitsuba and
/// pbrt put it: u round the sphere's z from +x towards +y, the image's top
/// row at +z.
pub fn assert_texels_round_z(
    scene: &Scene,
    centre: lumen::math::Vec3,
    colours: &[lumen::math::Color; 8],
) {
    for column in 0..4 {
        let phi = (0.125 + 0.25 * column as f32) * std::f32::consts::TAU;
        for (row, theta) in [(0, 0.25), (1, 0.75)] {
            let theta = theta * std::f32::consts::PI;
            let d = lumen::math::Vec3::new(
                phi.cos() * theta.sin(),
                phi.sin() * theta.sin(),
                theta.cos(),
            );
            let seen = colour_at(scene, centre + d * 3.0, -d);
            let want = colours[row * 4 + column];
            assert!(
                colours_close(seen, want),
                "sphere column {column} row {row}: {seen:?}, want {want:?}"
            );
        }
    }
}

/// The scene `text` (written to `dir/scene.toml`) rendered with each
/// integrator: (`path`, `bsdf`).
pub fn path_and_bsdf(dir: &std::path::Path, text: &str) -> (PixelStats, PixelStats) {
    let mut path = compile_file(dir, "scene.toml", text);
    path.settings.integrator = lumen::scene::Integrator::Path;
    let mut bsdf = path.clone();
    bsdf.settings.integrator = lumen::scene::Integrator::Bsdf;
    (pixel_stats(&path), pixel_stats(&bsdf))
}

/// A scene of 32 × 24 pixels at 128 samples a pixel (paths of up to six
/// segments, seed `seed`) seen by `camera` (the `[camera]` table's lines),
/// under a black sky, on a grey floor 20 wide at y = 0 (material
/// `floor`), with `rest` (more materials and objects) after the floor:
/// where direct light dominates, to compare estimators.
pub fn on_dark_floor(seed: u64, camera: &str, rest: &str) -> String {
    format!(
        r#"[render]
width = 32
height = 24
samples_per_pixel = 128
max_depth = 6
seed = {seed}

[camera]
{camera}

[background]
type = "solid"
color = [0, 0, 0]

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[objects]]
type = "quad"
corner = [-10, 0, -10]
u = [0, 0, 20]
v = [20, 0, 0]
material = "floor"

{rest}"#
    )
}
