//! The built-in scenes: every figure of the notes, in their order, the
//! book's cover image, and the figures of *The Next Week* and *The Rest of
//! Your Life* that follow it.
//!
//! Each scene is a [`SceneDesc`], the same data a scene file holds, so any of
//! them can be exported and edited.

use super::desc::{
    AttenuationDesc, BackgroundDesc, BounceDesc, BoundaryDesc, CameraDesc, ColorDesc,
    DielectricDesc, DiffuseDesc, EmissiveDesc, IntegratorDesc, MaterialDesc, MetalDesc,
    NoisePatternDesc, ObjectDesc, RenderDesc, SamplingDesc, SceneDesc, ShadingDesc, TextureDesc,
    TransformDesc, Triple,
};
use crate::rng::Rng;

pub mod materials;

/// A named built-in scene.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Name used on the command line.
    pub name: &'static str,
    /// One-line caption.
    pub caption: &'static str,
    /// The book the figure is from.
    pub book: Book,
    make: fn() -> SceneDesc,
}

/// The books whose figures are built in, in reading order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Book {
    /// *Ray Tracing in One Weekend* (the notes).
    OneWeekend,
    /// *Ray Tracing: The Next Week*.
    NextWeek,
    /// *Ray Tracing: The Rest of Your Life*.
    RestOfYourLife,
    /// Beyond the books: physically based materials.
    Materials,
}

impl Book {
    /// The book's title.
    pub fn title(self) -> &'static str {
        match self {
            Book::OneWeekend => "Ray Tracing in One Weekend",
            Book::NextWeek => "Ray Tracing: The Next Week",
            Book::RestOfYourLife => "Ray Tracing: The Rest of Your Life",
            Book::Materials => "Beyond the books: physically based materials",
        }
    }
}

impl Builtin {
    /// The scene's description, with its caption filled in.
    pub fn desc(&self) -> SceneDesc {
        let mut d = (self.make)();
        d.caption = self.caption.to_string();
        d
    }
}

/// The notes' epsilon.
const BOOK_EPSILON: f64 = 0.001;

macro_rules! scenes {
    ($( $book:ident { $( $name:literal, $caption:literal => $make:expr; )* } )*) => {
        /// Every built-in scene, book by book, each in the book's order.
        pub const BUILTINS: &[Builtin] = &[
            $( $( Builtin { name: $name, caption: $caption, book: Book::$book, make: $make }, )* )*
        ];
    };
}

scenes! {
  OneWeekend {
    "gradient", "Background only: a vertical lerp from white to sky blue by the ray's y direction" => gradient;
    "hit-sphere", "Hit or miss: red wherever a ray hits the sphere" => hit_sphere;
    "normals-unit", "The unit normal used directly as a colour" => || normals(ShadingDesc::NormalsUnit, false, 1);
    "normals-raw", "The un-normalised normal P - C as a colour: it looks dark" => || normals(ShadingDesc::NormalsRaw, false, 1);
    "normals-brightened", "Normals brightened with grey: 0.5 * (N + 1)" => || normals(ShadingDesc::NormalsBrightened, false, 1);
    "aa-1spp", "Antialiasing: one ray through each pixel centre shows jaggies" => || normals(ShadingDesc::NormalsBrightened, true, 1);
    "aa-100spp", "Antialiasing: 100 random samples per pixel, averaged" => || normals(ShadingDesc::NormalsBrightened, true, 100);
    "diffuse-first", "First diffuse attempt: one bounce, objects with an intrinsic colour" => diffuse_first;
    "diffuse-absorb-half", "One bounce, colour multiplied by a reflectivity of 0.5" => || diffuse_grey(1.0, false, 2);
    "diffuse-gamma2", "One bounce, gamma corrected (gamma = 2)" => || diffuse_grey(2.0, false, 2);
    "diffuse-blue-background", "One bounce, plain blue background" => || diffuse_grey(2.0, true, 2);
    "diffuse-zero-bounces", "Zero bounces (max depth 1): only the background lights anything" => || diffuse_grey(2.0, true, 1);
    "diffuse-recursive", "Bounces traced recursively up to depth 50, each halving the colour: contact shadows appear" => || diffuse_grey(2.0, true, 50);
    "shadow-acne", "Shadow acne: with epsilon 0 bounce rays hit their own surface" => || acne(0.0);
    "shadow-acne-fixed", "Shadow acne fixed by ignoring the surface a ray leaves within 0.001" => || acne(0.001);
    "bounce-cube", "Bounce towards a random point on a cube around p + N" => || bounce(BounceDesc::Cube);
    "bounce-sphere-volume", "Bounce towards a random point inside the tangent unit sphere" => || bounce(BounceDesc::SphereVolume);
    "bounce-lambertian", "Bounce towards a random point on the tangent unit sphere: true Lambertian" => || bounce(BounceDesc::Lambertian);
    "bounce-hemisphere", "Bounce in a uniformly random direction of the hemisphere around N" => || bounce(BounceDesc::Hemisphere);
    "albedo-grey", "Albedo 0.5 (small sphere) and 0.2 (big sphere), colour scaled" => || albedo_grey(AttenuationDesc::Scale);
    "albedo-grey-absorb", "The same albedos as absorption probabilities: converges to the same image" => || albedo_grey(AttenuationDesc::Absorb);
    "albedo-coloured", "Different base colours" => || albedo_colours([0.8, 0.3, 0.3], [0.8, 0.8, 0.0]);
    "albedo-same-colour", "The same base colour on both spheres" => || albedo_colours([0.8, 0.3, 0.3], [0.8, 0.3, 0.3]);
    "metal-mirror", "Metal: perfect mirror reflection, tinted by the albedo" => || metal_fuzz(0.0);
    "metal-fuzz-1", "Fuzzy metal, fuzz sphere of radius 1.0" => || metal_fuzz(1.0);
    "metal-fuzz-0.2", "Fuzzy metal, fuzz sphere of radius 0.2" => || metal_fuzz(0.2);
    "metal-fuzz-0.5", "Fuzzy metal, fuzz sphere of radius 0.5" => || metal_fuzz(0.5);
    "metal-albedo-1", "Mirror albedo 1: the ball reflects the exact colours" => || metal_albedo([1.0; 3], [0.8, 0.6, 0.2], false);
    "metal-albedo-0.9", "Mirror albedo 0.9: a little attenuation gives the ball definition" => || metal_albedo([0.9; 3], [0.8, 0.6, 0.2], false);
    "metal-albedo-0.2", "Mirror albedo 0.2" => || metal_albedo([0.2; 3], [0.8, 0.6, 0.2], false);
    "metal-albedo-black", "Mirror albedo black, fuzzy ball white" => || metal_albedo([0.0; 3], [1.0; 3], false);
    "metal-all-black", "All three albedos black" => || metal_albedo([0.0; 3], [0.0; 3], true);
    "glass-refract-only", "Glass that only refracts (no Fresnel reflection)" => || glass(true, false);
    "glass-refract-reflect", "Glass that refracts and reflects (Schlick), with total internal reflection" => || glass(false, false);
    "glass-hollow", "A hollow glass ball: an inner sphere with the inverse index" => || glass(false, true);
    "fov-90", "Vertical field of view 90 degrees" => || fov(90.0);
    "fov-135", "Vertical field of view 135 degrees" => || fov(135.0);
    "fov-170", "Vertical field of view 170 degrees" => || fov(170.0);
    "camera-lookfrom", "A positioned camera: lookfrom (-2, 2, 1), lookat (0, 0, -1), vfov 20" => || positioned(0.0);
    "depth-of-field", "Depth of field: defocus angle 10, focus distance 3.4" => || positioned(10.0);
    "cover", "The cover: a random field of spheres, glass, diffuse and metal" => cover;
  }
  NextWeek {
    "bouncing-spheres", "The Next Week: the cover's diffuse spheres bouncing while the shutter is open (motion blur)" => bouncing_spheres;
    "checkered-spheres", "The Next Week: two spheres under a 3-D checker texture" => checkered_spheres;
    "earth", "The Next Week: a planet's map wrapped on a sphere by its (u, v) (a made-up planet: lumen ships no photograph)" => earth;
    "perlin-spheres", "The Next Week: Perlin-noise marble on a ground sphere and a ball" => perlin_spheres;
    "quads", "The Next Week: five coloured quads, the sides of an open box, seen from the front" => quads;
    "simple-light", "The Next Week: Perlin marble lit by a ball and a panel of light in the dark" => simple_light;
    "cornell-box", "The Next Week: the Cornell box, its ceiling light found only by chance (noisy; --integrator path aims at it)" => cornell_box;
    "cornell-smoke", "The Next Week: the Cornell box's two blocks as black smoke and white fog" => cornell_smoke;
    "next-week-final", "The Next Week's final scene: boxes, a moving ball, glass, fog, a planet, marble and a cluster of spheres" => next_week_final;
  }
  RestOfYourLife {
    "cornell-glass-sphere", "The Rest of Your Life: the Cornell box with a glass ball, its light sampled directly (next-event estimation)" => cornell_glass_sphere;
  }
  Materials {
    "materials", "Physically based materials, roughness 0 to 1 across: gold (conductor), glass (rough dielectric), red plastic, blue principled, principled metal" => materials::materials;
  }
}

/// Looks up a built-in scene by name.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

struct Builder {
    desc: SceneDesc,
}

impl Builder {
    fn new(render: RenderDesc) -> Self {
        Builder {
            desc: SceneDesc {
                render,
                ..SceneDesc::default()
            },
        }
    }

    fn texture(mut self, name: &str, t: TextureDesc) -> Self {
        self.desc.textures.insert(name.to_string(), t);
        self
    }

    fn material(mut self, name: &str, m: MaterialDesc) -> Self {
        self.desc.materials.insert(name.to_string(), m);
        self
    }

    fn sphere(mut self, center: Triple, radius: f64, material: &str) -> Self {
        self.desc.objects.push(ObjectDesc::Sphere {
            flip_normals: false,
            center,
            radius,
            material: material.to_string(),
            transform: Vec::new(),
        });
        self
    }

    /// A sphere at `center` at time 0 that moves by `motion` until time 1.
    fn moving_sphere(
        mut self,
        center: Triple,
        radius: f64,
        material: &str,
        motion: Triple,
    ) -> Self {
        self.desc.objects.push(ObjectDesc::Sphere {
            flip_normals: false,
            center,
            radius,
            material: material.to_string(),
            transform: vec![TransformDesc::Motion(motion)],
        });
        self
    }

    fn quad(mut self, corner: Triple, u: Triple, v: Triple, material: &str) -> Self {
        self.desc.objects.push(ObjectDesc::Quad {
            flip_normals: false,
            corner,
            u,
            v,
            material: material.to_string(),
            transform: Vec::new(),
        });
        self
    }

    /// A box from the origin to `size`, turned by `degrees` about the y axis
    /// and then moved by `offset` (the books' `rotate_y` and `translate`).
    fn turned_box(mut self, size: Triple, degrees: f64, offset: Triple, material: &str) -> Self {
        self.desc.objects.push(ObjectDesc::Box {
            flip_normals: false,
            min: [0.0; 3],
            max: size,
            material: material.to_string(),
            transform: turn_and_move(degrees, offset),
        });
        self
    }

    /// Constant-density fog of `albedo` filling the box from the origin to
    /// `size`, turned and moved as [`turned_box`](Self::turned_box) does.
    fn turned_fog(
        mut self,
        size: Triple,
        degrees: f64,
        offset: Triple,
        density: f64,
        albedo: Triple,
    ) -> Self {
        self.desc.objects.push(ObjectDesc::Medium {
            boundary: BoundaryDesc::Box {
                min: [0.0; 3],
                max: size,
            },
            density,
            albedo,
            transform: turn_and_move(degrees, offset),
        });
        self
    }

    /// Constant-density fog of `albedo` filling a ball.
    fn fog_ball(mut self, center: Triple, radius: f64, density: f64, albedo: Triple) -> Self {
        self.desc.objects.push(ObjectDesc::Medium {
            boundary: BoundaryDesc::Sphere { center, radius },
            density,
            albedo,
            transform: Vec::new(),
        });
        self
    }

    fn background(mut self, b: BackgroundDesc) -> Self {
        self.desc.background = b;
        self
    }

    fn camera(mut self, c: CameraDesc) -> Self {
        self.desc.camera = c;
        self
    }

    fn build(self) -> SceneDesc {
        self.desc
    }
}

/// Turned by `degrees` about the y axis, then moved by `offset`.
fn turn_and_move(degrees: f64, offset: Triple) -> Vec<TransformDesc> {
    vec![
        TransformDesc::Rotate {
            axis: [0.0, 1.0, 0.0],
            degrees,
        },
        TransformDesc::Translate(offset),
    ]
}

/// Settings of a figure: a single sample goes through the pixel's centre, as
/// in the notes' figures before antialiasing; more samples are jittered;
/// light is gathered as the notes do (see [`figure`]).
fn render(spp: u32, gamma: f64) -> RenderDesc {
    figure(RenderDesc {
        samples_per_pixel: spp,
        gamma,
        sampler: if spp == 1 {
            SamplingDesc::Center
        } else {
            SamplingDesc::Independent
        },
        ..RenderDesc::default()
    })
}

/// A figure's settings: the books' estimator, which finds light only where
/// the bounces meet it and plays no Russian roulette, and their epsilon of
/// 0.001 against shadow acne, as their figures were made.
fn figure(render: RenderDesc) -> RenderDesc {
    RenderDesc {
        integrator: IntegratorDesc::Bsdf,
        epsilon: render.epsilon.or(Some(BOOK_EPSILON)),
        ..render
    }
}

fn diffuse(albedo: Triple, bounce: BounceDesc) -> MaterialDesc {
    MaterialDesc::Diffuse(DiffuseDesc {
        albedo: albedo.into(),
        bounce,
        attenuation: AttenuationDesc::Scale,
        ..Default::default()
    })
}

fn lambertian(albedo: Triple) -> MaterialDesc {
    diffuse(albedo, BounceDesc::Lambertian)
}

fn metal(albedo: Triple, fuzz: f64) -> MaterialDesc {
    MaterialDesc::Metal(MetalDesc {
        albedo: albedo.into(),
        fuzz,
        ..Default::default()
    })
}

fn glass_material(ior: f64, refract_only: bool) -> MaterialDesc {
    MaterialDesc::Dielectric(DielectricDesc {
        ior,
        refract_only,
        ..Default::default()
    })
}

const BLUE: BackgroundDesc = BackgroundDesc::Solid {
    color: [0.5, 0.7, 1.0],
};

/// The sphere at (0, 0, -1) resting on a radius-100 "ground" sphere.
fn sphere_on_ground(render: RenderDesc, sphere: MaterialDesc, ground: MaterialDesc) -> Builder {
    Builder::new(render)
        .material("sphere", sphere)
        .material("ground", ground)
        .sphere([0.0, 0.0, -1.0], 0.5, "sphere")
        .sphere([0.0, -100.5, -1.0], 100.0, "ground")
}

fn gradient() -> SceneDesc {
    Builder::new(render(1, 1.0)).build()
}

fn hit_sphere() -> SceneDesc {
    let mut r = render(1, 1.0);
    r.shading = ShadingDesc::Hit;
    Builder::new(r)
        .material("sphere", lambertian([1.0, 0.0, 0.0]))
        .sphere([0.0, 0.0, -1.0], 0.5, "sphere")
        .build()
}

fn normals(shading: ShadingDesc, ground: bool, spp: u32) -> SceneDesc {
    let mut r = render(spp, 1.0);
    r.shading = shading;
    let b = Builder::new(r)
        .material("surface", lambertian([0.5; 3]))
        .sphere([0.0, 0.0, -1.0], 0.5, "surface");
    if ground {
        b.sphere([0.0, -100.5, -1.0], 100.0, "surface").build()
    } else {
        b.build()
    }
}

fn diffuse_first() -> SceneDesc {
    let mut r = render(100, 1.0);
    r.max_depth = 2;
    sphere_on_ground(
        r,
        diffuse([0.8, 0.3, 0.3], BounceDesc::SphereVolume),
        diffuse([0.8, 0.8, 0.0], BounceDesc::SphereVolume),
    )
    .build()
}

fn diffuse_grey(gamma: f64, blue: bool, depth: u32) -> SceneDesc {
    let mut r = render(100, gamma);
    r.max_depth = depth;
    let b = sphere_on_ground(
        r,
        diffuse([0.5; 3], BounceDesc::SphereVolume),
        diffuse([0.5; 3], BounceDesc::SphereVolume),
    );
    if blue {
        b.background(BLUE).build()
    } else {
        b.build()
    }
}

fn acne(epsilon: f64) -> SceneDesc {
    let mut r = render(100, 2.0);
    r.epsilon = Some(epsilon);
    sphere_on_ground(
        r,
        diffuse([0.5; 3], BounceDesc::SphereVolume),
        diffuse([0.5; 3], BounceDesc::SphereVolume),
    )
    .build()
}

fn bounce(model: BounceDesc) -> SceneDesc {
    sphere_on_ground(
        render(100, 2.0),
        diffuse([0.5; 3], model),
        diffuse([0.5; 3], model),
    )
    .build()
}

fn albedo_grey(attenuation: AttenuationDesc) -> SceneDesc {
    let m = |a: f64| {
        MaterialDesc::Diffuse(DiffuseDesc {
            albedo: [a; 3].into(),
            bounce: BounceDesc::Lambertian,
            attenuation,
            ..Default::default()
        })
    };
    sphere_on_ground(render(100, 2.0), m(0.5), m(0.2)).build()
}

fn albedo_colours(sphere: Triple, ground: Triple) -> SceneDesc {
    sphere_on_ground(render(100, 2.0), lambertian(sphere), lambertian(ground)).build()
}

/// The book's three balls on a yellow ground: diffuse in the centre, a mirror
/// on the left and a (possibly fuzzy) metal on the right.
fn three_balls(
    center: MaterialDesc,
    left: MaterialDesc,
    right: MaterialDesc,
    ground: Triple,
) -> Builder {
    Builder::new(render(100, 2.0))
        .material("ground", lambertian(ground))
        .material("center", center)
        .material("left", left)
        .material("right", right)
        .sphere([0.0, -100.5, -1.0], 100.0, "ground")
        .sphere([0.0, 0.0, -1.2], 0.5, "center")
        .sphere([-1.0, 0.0, -1.0], 0.5, "left")
        .sphere([1.0, 0.0, -1.0], 0.5, "right")
}

fn metal_fuzz(fuzz: f64) -> SceneDesc {
    three_balls(
        lambertian([0.1, 0.2, 0.5]),
        metal([0.8, 0.8, 0.8], 0.0),
        metal([0.8, 0.6, 0.2], fuzz),
        [0.8, 0.8, 0.0],
    )
    .build()
}

fn metal_albedo(mirror: Triple, fuzzy: Triple, all_black: bool) -> SceneDesc {
    let center = if all_black { [0.0; 3] } else { [0.1, 0.2, 0.5] };
    three_balls(
        lambertian(center),
        metal(mirror, 0.0),
        metal(fuzzy, 0.3),
        [0.8, 0.8, 0.0],
    )
    .build()
}

fn glass(refract_only: bool, hollow: bool) -> SceneDesc {
    let b = three_balls(
        lambertian([0.1, 0.2, 0.5]),
        glass_material(1.5, refract_only),
        metal([0.8, 0.6, 0.2], 1.0),
        [0.8, 0.8, 0.0],
    );
    if hollow {
        b.material("bubble", glass_material(1.0 / 1.5, false))
            .sphere([-1.0, 0.0, -1.0], 0.4, "bubble")
            .build()
    } else {
        b.build()
    }
}

fn fov(vfov: f64) -> SceneDesc {
    let r = std::f64::consts::FRAC_PI_4.cos();
    Builder::new(render(100, 2.0))
        .material("left", lambertian([0.0, 0.0, 1.0]))
        .material("right", lambertian([1.0, 0.0, 0.0]))
        .sphere([-r, 0.0, -1.0], r, "left")
        .sphere([r, 0.0, -1.0], r, "right")
        .camera(CameraDesc {
            vfov,
            ..CameraDesc::default()
        })
        .build()
}

fn positioned(defocus_angle: f64) -> SceneDesc {
    let b = three_balls(
        lambertian([0.1, 0.2, 0.5]),
        glass_material(1.5, false),
        metal([0.8, 0.6, 0.2], 1.0),
        [0.8, 0.8, 0.0],
    )
    .material("bubble", glass_material(1.0 / 1.5, false))
    .sphere([-1.0, 0.0, -1.0], 0.4, "bubble");
    b.camera(CameraDesc {
        vfov: 20.0,
        lookfrom: [-2.0, 2.0, 1.0],
        lookat: [0.0, 0.0, -1.0],
        vup: [0.0, 1.0, 0.0],
        defocus_angle,
        focus_dist: Some(3.4),
        ..CameraDesc::default()
    })
    .build()
}

/// Seed of the cover scene's layout: fixed, so the cover is the same every run.
const COVER_LAYOUT_SEED: u64 = 0x00C0_FFEE;

/// The book's final scene: a 22×22 grid of small random spheres around three
/// big ones, at the book's full quality (1200 wide, 500 samples per pixel).
pub fn cover() -> SceneDesc {
    cover_with_grid(11)
}

/// A cover-style field on a (2·half)² grid of small spheres; `half = 11` is the
/// cover itself. Used to measure how cost grows with the number of spheres.
pub fn cover_with_grid(half: i32) -> SceneDesc {
    sphere_field(
        figure(RenderDesc {
            width: 1200,
            samples_per_pixel: 500,
            max_depth: 50,
            sampler: SamplingDesc::Independent,
            ..RenderDesc::default()
        }),
        half,
        false,
        0.6,
    )
}

/// The first figure of *The Next Week*: the cover's field, its diffuse
/// spheres bouncing up by a random height of up to half a unit while the
/// shutter is open.
fn bouncing_spheres() -> SceneDesc {
    sphere_field(next_week(400, 100, 16.0 / 9.0), 11, true, 0.02)
}

/// The cover's random field of small spheres around three big ones on a
/// (2·half)² grid, with `render` settings and lens `defocus_angle`; the
/// diffuse spheres move up when `bouncing`.
fn sphere_field(render: RenderDesc, half: i32, bouncing: bool, defocus_angle: f64) -> SceneDesc {
    let mut rng = Rng::new(COVER_LAYOUT_SEED);
    let mut b = Builder::new(render)
        .material("ground", lambertian([0.5, 0.5, 0.5]))
        .material("glass", glass_material(1.5, false))
        .sphere([0.0, -1000.0, 0.0], 1000.0, "ground");
    let mut count = 0usize;
    for a in -half..half {
        for c in -half..half {
            let choose = rng.next_f64();
            let center = [
                f64::from(a) + 0.9 * rng.next_f64(),
                0.2,
                f64::from(c) + 0.9 * rng.next_f64(),
            ];
            let d = [center[0] - 4.0, center[1] - 0.2, center[2]];
            if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() <= 0.9 {
                continue;
            }
            if choose < 0.8 {
                let albedo = [0; 3].map(|_| rng.next_f64() * rng.next_f64());
                let name = format!("diffuse{count}");
                b = b.material(&name, lambertian(albedo));
                b = if bouncing {
                    let up = 0.5 * rng.next_f64();
                    b.moving_sphere(center, 0.2, &name, [0.0, up, 0.0])
                } else {
                    b.sphere(center, 0.2, &name)
                };
            } else if choose < 0.95 {
                let albedo = [0; 3].map(|_| 0.5 + 0.5 * rng.next_f64());
                let fuzz = 0.5 * rng.next_f64();
                let name = format!("metal{count}");
                b = b
                    .material(&name, metal(albedo, fuzz))
                    .sphere(center, 0.2, &name);
            } else {
                b = b.sphere(center, 0.2, "glass");
            }
            count += 1;
        }
    }
    b.material("big-diffuse", lambertian([0.4, 0.2, 0.1]))
        .material("big-metal", metal([0.7, 0.6, 0.5], 0.0))
        .sphere([0.0, 1.0, 0.0], 1.0, "glass")
        .sphere([-4.0, 1.0, 0.0], 1.0, "big-diffuse")
        .sphere([4.0, 1.0, 0.0], 1.0, "big-metal")
        .camera(CameraDesc {
            vfov: 20.0,
            lookfrom: [13.0, 2.0, 3.0],
            lookat: [0.0, 0.0, 0.0],
            vup: [0.0, 1.0, 0.0],
            defocus_angle,
            focus_dist: Some(10.0),
            ..CameraDesc::default()
        })
        .build()
}

/// Settings of a figure of *The Next Week*: random samples, gamma 2.
fn next_week(width: u32, spp: u32, aspect_ratio: f64) -> RenderDesc {
    figure(RenderDesc {
        width,
        aspect_ratio,
        samples_per_pixel: spp,
        max_depth: 50,
        sampler: SamplingDesc::Independent,
        ..RenderDesc::default()
    })
}

/// A pinhole camera.
fn pinhole(vfov: f64, lookfrom: Triple, lookat: Triple) -> CameraDesc {
    CameraDesc {
        vfov,
        lookfrom,
        lookat,
        vup: [0.0, 1.0, 0.0],
        defocus_angle: 0.0,
        focus_dist: None,
        ..CameraDesc::default()
    }
}

/// The sky-blue background of *The Next Week*'s figures.
const NEXT_WEEK_SKY: BackgroundDesc = BackgroundDesc::Solid {
    color: [0.7, 0.8, 1.0],
};

/// A diffuse material whose albedo is texture `texture`.
fn textured(texture: &str) -> MaterialDesc {
    MaterialDesc::Diffuse(DiffuseDesc {
        albedo: ColorDesc::Texture(texture.to_string()),
        bounce: BounceDesc::Lambertian,
        attenuation: AttenuationDesc::Scale,
        ..Default::default()
    })
}

/// Two spheres of radius 10, one above the other, touching at the origin,
/// both of a checker of 0.8-unit cubes.
fn checkered_spheres() -> SceneDesc {
    Builder::new(next_week(400, 100, 16.0 / 9.0))
        .texture(
            "checker",
            TextureDesc::Checker {
                scale: 0.8,
                even: [0.2, 0.3, 0.1].into(),
                odd: [0.9, 0.9, 0.9].into(),
            },
        )
        .material("checker", textured("checker"))
        .sphere([0.0, -10.0, 0.0], 10.0, "checker")
        .sphere([0.0, 10.0, 0.0], 10.0, "checker")
        .background(NEXT_WEEK_SKY)
        .camera(pinhole(20.0, [13.0, 2.0, 3.0], [0.0; 3]))
        .build()
}

/// The planet texture built into lumen.
const EARTH_MAP: &str = "lumen:earth.png";

/// A globe of radius 2 wrapped in the planet map, seen from the front.
fn earth() -> SceneDesc {
    Builder::new(next_week(400, 100, 16.0 / 9.0))
        .texture("earth", TextureDesc::image(EARTH_MAP))
        .material("earth", textured("earth"))
        .sphere([0.0; 3], 2.0, "earth")
        .background(NEXT_WEEK_SKY)
        .camera(pinhole(20.0, [0.0, 0.0, 12.0], [0.0; 3]))
        .build()
}

/// A ball of radius 2 on a ground sphere, both of Perlin marble at
/// frequency 4.
fn perlin_spheres() -> SceneDesc {
    Builder::new(next_week(400, 100, 16.0 / 9.0))
        .texture(
            "marble",
            TextureDesc::Noise {
                scale: 4.0,
                pattern: NoisePatternDesc::Marble,
                seed: 0,
            },
        )
        .material("marble", textured("marble"))
        .sphere([0.0, -1000.0, 0.0], 1000.0, "marble")
        .sphere([0.0, 2.0, 0.0], 2.0, "marble")
        .background(NEXT_WEEK_SKY)
        .camera(pinhole(20.0, [13.0, 2.0, 3.0], [0.0; 3]))
        .build()
}

fn quads() -> SceneDesc {
    Builder::new(next_week(400, 100, 1.0))
        .material("left-red", lambertian([1.0, 0.2, 0.2]))
        .material("back-green", lambertian([0.2, 1.0, 0.2]))
        .material("right-blue", lambertian([0.2, 0.2, 1.0]))
        .material("upper-orange", lambertian([1.0, 0.5, 0.0]))
        .material("lower-teal", lambertian([0.2, 0.8, 0.8]))
        .quad(
            [-3.0, -2.0, 5.0],
            [0.0, 0.0, -4.0],
            [0.0, 4.0, 0.0],
            "left-red",
        )
        .quad(
            [-2.0, -2.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            "back-green",
        )
        .quad(
            [3.0, -2.0, 1.0],
            [0.0, 0.0, 4.0],
            [0.0, 4.0, 0.0],
            "right-blue",
        )
        .quad(
            [-2.0, 3.0, 1.0],
            [4.0, 0.0, 0.0],
            [0.0, 0.0, 4.0],
            "upper-orange",
        )
        .quad(
            [-2.0, -3.0, 5.0],
            [4.0, 0.0, 0.0],
            [0.0, 0.0, -4.0],
            "lower-teal",
        )
        .background(NEXT_WEEK_SKY)
        .camera(pinhole(80.0, [0.0, 0.0, 9.0], [0.0; 3]))
        .build()
}

/// The marble spheres of [`perlin_spheres`] in the dark, lit by a ball of
/// light above them and a square panel beside them (radiance 4, emitting
/// from both sides, as the book's diffuse light does).
fn simple_light() -> SceneDesc {
    Builder {
        desc: perlin_spheres(),
    }
    .material(
        "light",
        MaterialDesc::Emissive(EmissiveDesc {
            radiance: [4.0; 3].into(),
            two_sided: true,
            ..Default::default()
        }),
    )
    .sphere([0.0, 7.0, 0.0], 2.0, "light")
    .quad([3.0, 1.0, -2.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], "light")
    .background(BackgroundDesc::Solid { color: [0.0; 3] })
    .camera(pinhole(20.0, [26.0, 3.0, 6.0], [0.0, 2.0, 0.0]))
    .build()
}

/// The Cornell box of *The Next Week*: a 555-unit box, red on the left,
/// green on the right, a 130 × 105 light of radiance 15 just under the
/// ceiling (emitting from both sides, as the book's diffuse light does), and
/// two white boxes turned about their corners.
pub fn cornell_box() -> SceneDesc {
    let light = (
        [343.0, 554.0, 332.0],
        [-130.0, 0.0, 0.0],
        [0.0, 0.0, -105.0],
    );
    cornell_walls(next_week(600, 200, 1.0), 15.0, true, light)
        .turned_box([165.0, 330.0, 165.0], 15.0, [265.0, 0.0, 295.0], "white")
        .turned_box([165.0; 3], -18.0, [130.0, 0.0, 65.0], "white")
        .build()
}

/// The empty Cornell box with `render` settings: its five walls (red,
/// green, three white), the quad `light` (corner, u, v) of `radiance`,
/// `two_sided` or emitting along u × v, a black background and the books'
/// camera.
fn cornell_walls(
    render: RenderDesc,
    radiance: f64,
    two_sided: bool,
    (corner, u, v): (Triple, Triple, Triple),
) -> Builder {
    Builder::new(render)
        .material("red", lambertian([0.65, 0.05, 0.05]))
        .material("white", lambertian([0.73, 0.73, 0.73]))
        .material("green", lambertian([0.12, 0.45, 0.15]))
        .material(
            "light",
            MaterialDesc::Emissive(EmissiveDesc {
                radiance: [radiance; 3].into(),
                two_sided,
                ..Default::default()
            }),
        )
        .quad(
            [555.0, 0.0, 0.0],
            [0.0, 555.0, 0.0],
            [0.0, 0.0, 555.0],
            "green",
        )
        .quad([0.0; 3], [0.0, 555.0, 0.0], [0.0, 0.0, 555.0], "red")
        .quad(corner, u, v, "light")
        .quad([0.0; 3], [555.0, 0.0, 0.0], [0.0, 0.0, 555.0], "white")
        .quad([555.0; 3], [-555.0, 0.0, 0.0], [0.0, 0.0, -555.0], "white")
        .quad(
            [0.0, 0.0, 555.0],
            [555.0, 0.0, 0.0],
            [0.0, 555.0, 0.0],
            "white",
        )
        .background(BackgroundDesc::Solid { color: [0.0; 3] })
        .camera(pinhole(40.0, [278.0, 278.0, -800.0], [278.0, 278.0, 0.0]))
}

/// The Cornell box filled with smoke and fog: the two boxes of
/// [`cornell_box`] as constant media of density 0.01, black and white, and
/// a larger, dimmer light (330 × 305, radiance 7).
fn cornell_smoke() -> SceneDesc {
    let light = ([113.0, 554.0, 127.0], [330.0, 0.0, 0.0], [0.0, 0.0, 305.0]);
    cornell_walls(next_week(600, 200, 1.0), 7.0, true, light)
        .turned_fog(
            [165.0, 330.0, 165.0],
            15.0,
            [265.0, 0.0, 295.0],
            0.01,
            [0.0; 3],
        )
        .turned_fog([165.0; 3], -18.0, [130.0, 0.0, 65.0], 0.01, [1.0; 3])
        .build()
}

/// Seed of the final scene's random boxes and spheres.
const FINAL_LAYOUT_SEED: u64 = 0x00F1_7A1E;

/// The last figure of *The Next Week*, at the book's quality (800 × 800,
/// 10,000 samples, 40 bounces): a floor of 20 × 20 boxes of random height,
/// a light above, a ball moving sideways, glass, fuzzy metal, a glass ball
/// full of blue smoke, a thin fog over everything, the planet, Perlin
/// marble, and 1,000 small white spheres in a turned cube.
fn next_week_final() -> SceneDesc {
    let mut rng = Rng::new(FINAL_LAYOUT_SEED);
    let mut b = Builder::new(figure(RenderDesc {
        width: 800,
        aspect_ratio: 1.0,
        samples_per_pixel: 10_000,
        max_depth: 40,
        sampler: SamplingDesc::Independent,
        ..RenderDesc::default()
    }))
    .material("ground", lambertian([0.48, 0.83, 0.53]));
    for i in 0..20 {
        for j in 0..20 {
            let (x0, z0) = (
                -1000.0 + 100.0 * f64::from(i),
                -1000.0 + 100.0 * f64::from(j),
            );
            let y1 = 1.0 + 100.0 * rng.next_f64();
            b.desc.objects.push(ObjectDesc::Box {
                flip_normals: false,
                min: [x0, 0.0, z0],
                max: [x0 + 100.0, y1, z0 + 100.0],
                material: "ground".to_string(),
                transform: Vec::new(),
            });
        }
    }
    b = b
        .material(
            "light",
            MaterialDesc::Emissive(EmissiveDesc {
                radiance: [7.0; 3].into(),
                two_sided: true,
                ..Default::default()
            }),
        )
        .quad(
            [123.0, 554.0, 147.0],
            [300.0, 0.0, 0.0],
            [0.0, 0.0, 265.0],
            "light",
        )
        .material("orange", lambertian([0.7, 0.3, 0.1]))
        .moving_sphere([400.0, 400.0, 200.0], 50.0, "orange", [30.0, 0.0, 0.0])
        .material("glass", glass_material(1.5, false))
        .sphere([260.0, 150.0, 45.0], 50.0, "glass")
        .material("fuzzy", metal([0.8, 0.8, 0.9], 1.0))
        .sphere([0.0, 150.0, 145.0], 50.0, "fuzzy")
        .sphere([360.0, 150.0, 145.0], 70.0, "glass")
        .fog_ball([360.0, 150.0, 145.0], 70.0, 0.2, [0.2, 0.4, 0.9])
        .fog_ball([0.0; 3], 5000.0, 0.0001, [1.0; 3])
        .texture("earth", TextureDesc::image(EARTH_MAP))
        .material("earth", textured("earth"))
        .sphere([400.0, 200.0, 400.0], 100.0, "earth")
        .texture(
            "marble",
            TextureDesc::Noise {
                scale: 0.1,
                pattern: NoisePatternDesc::Marble,
                seed: 0,
            },
        )
        .material("marble", textured("marble"))
        .sphere([220.0, 280.0, 300.0], 80.0, "marble")
        .material("white", lambertian([0.73; 3]));
    for _ in 0..1000 {
        let center = [0; 3].map(|_| 165.0 * rng.next_f64());
        b.desc.objects.push(ObjectDesc::Sphere {
            flip_normals: false,
            center,
            radius: 10.0,
            material: "white".to_string(),
            transform: turn_and_move(15.0, [-100.0, 270.0, 395.0]),
        });
    }
    b.background(BackgroundDesc::Solid { color: [0.0; 3] })
        .camera(pinhole(40.0, [478.0, 278.0, -600.0], [278.0, 278.0, 0.0]))
        .build()
}

/// The last figure of *The Rest of Your Life*: the Cornell box with the tall
/// box and a glass ball of radius 90 in place of the short box, lit by a
/// one-sided light facing down, traced with next-event estimation (the
/// book aims part of its samples at the light, as this does).
fn cornell_glass_sphere() -> SceneDesc {
    let mut render = next_week(600, 100, 1.0);
    render.integrator = IntegratorDesc::Path;
    let light = ([213.0, 554.0, 227.0], [130.0, 0.0, 0.0], [0.0, 0.0, 105.0]);
    cornell_walls(render, 15.0, false, light)
        .material("glass", glass_material(1.5, false))
        .turned_box([165.0, 330.0, 165.0], 15.0, [265.0, 0.0, 295.0], "white")
        .sphere([190.0, 90.0, 190.0], 90.0, "glass")
        .build()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn names_are_unique_and_every_scene_compiles() {
        let mut names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), BUILTINS.len());
        for b in BUILTINS {
            Scene::from_desc(&b.desc()).unwrap_or_else(|e| panic!("{}: {e}", b.name));
        }
    }

    #[test]
    fn books_come_in_reading_order() {
        assert!(BUILTINS.windows(2).all(|w| w[0].book <= w[1].book));
        assert_eq!(find("cover").unwrap().book, Book::OneWeekend);
        assert_eq!(find("cornell-box").unwrap().book, Book::NextWeek);
    }

    #[test]
    fn cover_has_the_books_layout() {
        let d = cover();
        // 22×22 candidates minus those too close to the big metal ball, plus
        // the ground and the three big spheres.
        assert!(d.objects.len() > 400 && d.objects.len() <= 22 * 22 + 4);
        assert_eq!(d, cover(), "the layout is the same every time");
    }
}
