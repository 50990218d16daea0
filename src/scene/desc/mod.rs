//! The scene description: a plain-data form of a scene that maps one-to-one
//! onto the scene file format (TOML or JSON) and from which every built-in
//! scene is made.
//!
//! Numbers are `f64` here so that files round-trip exactly and print the way
//! people write them; the renderer converts them to `f32` when it compiles the
//! scene.

pub use crate::light::source::{
    DirectionalLightDesc, LightDesc, PointLightDesc, ProjectorLightDesc, SpotLightDesc,
};
pub use crate::light::LightSelection;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub use crate::material::param::{ColorDesc, RoughnessDesc, ScalarDesc, Triple};
pub use crate::material::{
    AttenuationDesc, BounceDesc, DielectricDesc, DiffuseDesc, EmissiveDesc, MaterialDesc, MetalDesc,
};

/// Largest seed (of a render or of a noise texture): 2⁶³−1, the largest
/// integer TOML can write, so that every scene, however it was made (JSON,
/// the command line, a program), can be exported to either format.
pub const MAX_SEED: u64 = i64::MAX as u64;

/// What is wrong with a seed above [`MAX_SEED`], for the scene reader and
/// the compiler alike.
pub(crate) fn seed_too_large(got: impl std::fmt::Display) -> String {
    format!("must be at most {MAX_SEED} (2^63-1, the largest integer TOML can hold), got {got}")
}

/// A whole scene: settings, camera, background, named materials and objects.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// A one-line description, shown by `lumen scenes`.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub caption: String,
    /// Image size, sampling and output settings.
    #[serde(default)]
    pub render: RenderDesc,
    /// Camera placement and lens.
    #[serde(default)]
    pub camera: CameraDesc,
    /// What rays that hit nothing see.
    #[serde(default)]
    pub background: BackgroundDesc,
    /// Textures by name; materials refer to them by name.
    #[serde(
        default,
        skip_serializing_if = "BTreeMap::is_empty",
        deserialize_with = "unique_names"
    )]
    pub textures: BTreeMap<String, TextureDesc>,
    /// Materials by name; objects refer to them by name.
    #[serde(default, deserialize_with = "unique_names")]
    pub materials: BTreeMap<String, MaterialDesc>,
    /// The objects of the scene.
    #[serde(default)]
    pub objects: Vec<ObjectDesc>,
    /// Lights that are no surface: point, spot, directional lights and
    /// projectors (a surface shines by its material's emission).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<LightDesc>,
    /// Participating media by name: materials name the medium inside and
    /// outside their surfaces (`interior`, `exterior`), the camera the one
    /// it stands in.
    #[serde(
        default,
        skip_serializing_if = "BTreeMap::is_empty",
        deserialize_with = "unique_names"
    )]
    pub media: BTreeMap<String, MediumDesc>,
}

/// A participating medium (see [`crate::volume`]): what fills the space a
/// surface encloses, entered and left through surfaces whose material
/// names it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    /// The extinction σt per unit length (before `scale`): a number, a
    /// colour, or a grid.
    pub sigma_t: FieldDesc,
    /// The share of the light meeting a particle that it scatters (the
    /// rest it absorbs), in [0, 1]: a number, a colour, or a grid.
    pub albedo: FieldDesc,
    /// A factor on `sigma_t` (for data in other units); 1 when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Where the medium is: nothing outside this box. A medium whose
    /// `sigma_t` is a grid fills that grid's box when no box is given;
    /// other media are everywhere.
    #[serde(default, skip_serializing_if = "Option::is_none", rename = "box")]
    pub bounds: Option<BoxDesc>,
    /// The asymmetry of the Henyey–Greenstein phase function, the mean
    /// cosine of the scattering angle, in (−1, 1): above 0 light scatters
    /// on, below 0 back; isotropic (0) when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g: Option<f64>,
}

/// A box from `min` to `max`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxDesc {
    /// The lowest corner.
    pub min: Triple,
    /// The highest corner.
    pub max: Triple,
}

/// A quantity of a medium: the same everywhere, or read from a grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum FieldDesc {
    /// The same value in every channel.
    Value(f64),
    /// A value per channel.
    Color(Triple),
    /// A voxel grid.
    Grid(GridDesc),
    /// A voxel grid written out in the scene.
    Voxels(VoxelsDesc),
}

/// A voxel grid of a medium's quantity given value by value (pbrt's
/// `uniformgrid`), filling the unit cube of its own space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoxelsDesc {
    /// Voxels along x, y and z.
    pub voxels: [u32; 3],
    /// One value per voxel (or three, red, green and blue), x fastest,
    /// then y, then z.
    pub values: Vec<f64>,
    /// Places the grid's unit cube in the world, applied in the order
    /// written.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub transform: Vec<TransformDesc>,
    /// What lies between the outer voxels' centres and the cube's faces:
    /// the outer voxels' values (`"clamp"`, Mitsuba's way, the default) or
    /// values falling towards 0, to half the outer voxels' at the faces,
    /// as if 0 lay beyond (`"zero"`, pbrt's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge: Option<EdgeDesc>,
}

/// How a voxel grid is read beyond its outer voxels' centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EdgeDesc {
    /// The outer voxels' values.
    Clamp,
    /// 0 beyond the grid: values fall towards it at its faces.
    Zero,
}

/// A voxel grid of a medium's quantity, read from a Mitsuba `.vol` file
/// (1 or 3 channels of float32), filling the unit cube of its own space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridDesc {
    /// The `.vol` file, relative to the scene file.
    pub grid: String,
    /// Places the grid's unit cube in the world, applied in the order
    /// written.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub transform: Vec<TransformDesc>,
}

/// A table of named entries in which no name is given twice (a JSON object
/// may repeat a key; serde would keep the last).
fn unique_names<'de, D, T>(deserializer: D) -> Result<BTreeMap<String, T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct Names<T>(std::marker::PhantomData<T>);
    impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Names<T> {
        type Value = BTreeMap<String, T>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a table of named entries")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some((name, value)) = map.next_entry::<String, T>()? {
                if out.contains_key(&name) {
                    return Err(serde::de::Error::custom(format!(
                        "`{name}` is defined twice"
                    )));
                }
                out.insert(name, value);
            }
            Ok(out)
        }
    }
    deserializer.deserialize_map(Names(std::marker::PhantomData))
}

impl SceneDesc {
    /// What is legal but probably not what was meant, one sentence each,
    /// for the reader to show as warnings: a scene without objects (such
    /// as an empty file) renders only its background.
    pub fn warnings(&self) -> Vec<String> {
        let mut warnings = Vec::new();
        if self.objects.is_empty() {
            warnings.push(
                "the scene has no objects: the image will show only its background".to_string(),
            );
        }
        if self.render.integrator == IntegratorDesc::Bsdf
            && self.lights.iter().any(LightDesc::is_delta)
        {
            warnings.push(
                "point, spot and directional lights (without angular_radius) and projectors are \
                 found only by the `path` integrator's light sampling: with `bsdf` they shed no \
                 light"
                    .to_string(),
            );
        }
        warnings
    }
}

/// Image size, sampling and output settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderDesc {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels; when absent, `width / aspect_ratio` rounded down.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height: Option<u32>,
    /// Width over height, used when `height` is absent.
    pub aspect_ratio: f64,
    /// Render only the window `[x, y, width, height]` of the image (in
    /// pixels from its top left corner): the output is that window, as the
    /// full image would show it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crop: Option<[u32; 4]>,
    /// Camera samples per pixel.
    pub samples_per_pixel: u32,
    /// Maximum number of ray segments per path; 1 shows no bounce light.
    pub max_depth: u32,
    /// Seed of every random choice of the render, at most [`MAX_SEED`].
    pub seed: u64,
    /// Where the numbers of every random decision come from, the position
    /// in the pixel first (`sampling` in older scene files).
    #[serde(alias = "sampling")]
    pub sampler: SamplingDesc,
    /// How paths gather light.
    pub integrator: IntegratorDesc,
    /// How the `path` integrator chooses the light it samples.
    #[serde(skip_serializing_if = "is_power")]
    pub light_selection: LightSelection,
    /// Whether the `path` integrator samples the background as a light;
    /// absent, an image background is sampled and a gradient or one colour
    /// is not (the bounces find a smooth sky at least as well).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_background: Option<bool>,
    /// Adaptive sampling: a pixel stops taking samples once its estimated
    /// relative error is at most this; absent, every pixel takes them all.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_target: Option<f64>,
    /// Display gamma: output = linear^(1/gamma). 1 disables the correction.
    pub gamma: f64,
    /// How far along a ray leaving a surface that surface is not met again
    /// (the notes' fix for shadow acne; 0 shows the acne); other surfaces
    /// count at any distance. Absent, rays leave each surface by its
    /// rounding error alone, which holds at any scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<f64>,
    /// What a camera ray's colour shows.
    pub shading: ShadingDesc,
    /// How much each point near a pixel counts towards it.
    #[serde(skip_serializing_if = "is_box")]
    pub pixel_filter: PixelFilterDesc,
    /// A Gaussian filter's standard deviation in pixels, > 0 (its radius
    /// is four times it); ½ when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub filter_stddev: Option<f64>,
    /// Feature buffers written beside the image (see [`crate::aov`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aovs: Vec<crate::aov::Aov>,
    /// Whether the finished image is denoised (see [`crate::denoise`]);
    /// the film then keeps the albedo, normal and variance buffers the
    /// denoiser uses, and the image files carry them (see
    /// [`RenderDesc::written_aovs`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub denoise: bool,
    /// Which denoiser a denoised render uses (OIDN when absent); the
    /// command line's `--denoiser` overrides it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoiser: Option<crate::denoise::Denoiser>,
    /// OIDN's image filter's quality (`--denoise-quality` overrides it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoise_quality: Option<crate::denoise::Quality>,
    /// OIDN's prefilters' quality, or none (`--denoise-prefilter`
    /// overrides it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoise_prefilter: Option<crate::denoise::Prefilter>,
}

/// A pixel filter (see [`crate::filter`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PixelFilterDesc {
    /// The pixel's square, evenly: the default.
    #[default]
    Box,
    /// A Gaussian of `filter_stddev` pixels, out to four times it.
    Gaussian,
}

fn is_box(f: &PixelFilterDesc) -> bool {
    *f == PixelFilterDesc::Box
}

impl RenderDesc {
    /// The denoiser's settings the description chooses.
    pub fn denoise_choices(&self) -> crate::denoise::Choices {
        crate::denoise::Choices {
            denoiser: self.denoiser,
            quality: self.denoise_quality,
            prefilter: self.denoise_prefilter,
        }
    }

    /// The feature buffers the render keeps and writes: `aovs`, with the
    /// albedo, normal and variance a denoised render needs, in
    /// [`Aov::ALL`](crate::aov::Aov::ALL)'s order.
    pub fn written_aovs(&self) -> Vec<crate::aov::Aov> {
        use crate::aov::Aov;
        let needed: &[Aov] = if self.denoise {
            &[Aov::Albedo, Aov::Normal, Aov::Variance]
        } else {
            &[]
        };
        Aov::ALL
            .into_iter()
            .filter(|a| self.aovs.contains(a) || needed.contains(a))
            .collect()
    }

    /// The image's width and height: `height`, or else `width /
    /// aspect_ratio` rounded down (at least 1); `None` when they give no
    /// size (compiling the scene says why).
    pub fn size(&self) -> Option<(u32, u32)> {
        let height = match self.height {
            Some(h) => h,
            None => {
                let h = (f64::from(self.width) / self.aspect_ratio).floor();
                if !(h.is_finite() && h <= f64::from(u32::MAX)) {
                    return None;
                }
                (h as u32).max(1)
            }
        };
        (self.width > 0 && height > 0).then_some((self.width, height))
    }
}

impl Default for RenderDesc {
    fn default() -> Self {
        Self {
            width: 400,
            height: None,
            aspect_ratio: 16.0 / 9.0,
            crop: None,
            samples_per_pixel: 100,
            max_depth: 50,
            seed: 0,
            sampler: SamplingDesc::ZSobol,
            integrator: IntegratorDesc::Path,
            light_selection: LightSelection::Power,
            sample_background: None,
            noise_target: None,
            gamma: 2.0,
            epsilon: None,
            shading: ShadingDesc::Path,
            pixel_filter: PixelFilterDesc::Box,
            filter_stddev: None,
            aovs: Vec::new(),
            denoise: false,
            denoiser: None,
            denoise_quality: None,
            denoise_prefilter: None,
        }
    }
}

/// The sampler: where the numbers of a render's random decisions come from
/// (see [`crate::sampler`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SamplingDesc {
    /// Independent random numbers: a uniformly random point of the pixel
    /// for every sample (`"random"` in older scene files).
    #[serde(alias = "random")]
    Independent,
    /// Independent, but one point of the pixel in each cell of a √N×√N grid
    /// (the remaining samples, when N is not square, are random).
    Stratified,
    /// Independent, but the pixel's centre for every sample: no
    /// antialiasing (the notes' one-sample figures).
    Center,
    /// Owen-scrambled Sobol points for every decision, a sequence per pixel.
    Sobol,
    /// Sobol points as `Sobol`, each pixel's a block of one sequence over
    /// the pixels in Morton order: the error spread as blue noise; the
    /// default.
    #[serde(rename = "zsobol")]
    ZSobol,
}

/// How a path gathers light (see [`crate::integrator`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorDesc {
    /// At every diffuse bounce, also aim a shadow ray at a light chosen by
    /// power (next-event estimation), the two estimates weighted by
    /// multiple importance sampling: the default.
    #[default]
    Path,
    /// Only what the bounces happen to meet (the notes' estimator).
    Bsdf,
}

/// What the colour of a camera ray shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadingDesc {
    /// Full path tracing with materials.
    Path,
    /// Red where the ray hits anything, background elsewhere.
    Hit,
    /// The unit normal used directly as a colour (negative parts show black).
    NormalsUnit,
    /// The un-normalised normal P − C (its length is the radius).
    NormalsRaw,
    /// The unit normal mapped to colour by 0.5·(N + 1).
    NormalsBrightened,
}

/// Camera placement and lens.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraDesc {
    /// Vertical field of view in degrees.
    pub vfov: f64,
    /// Eye position.
    pub lookfrom: Triple,
    /// Point looked at.
    pub lookat: Triple,
    /// Up direction.
    pub vup: Triple,
    /// Aperture as the angle in degrees of the cone from the focus plane to the lens.
    pub defocus_angle: f64,
    /// Distance to the plane in focus; when absent, the distance to `lookat`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub focus_dist: Option<f64>,
    /// The interval of time the shutter is open, within [0, 1]: moving
    /// objects are blurred along the part of their motion it covers.
    #[serde(default = "full_shutter", skip_serializing_if = "is_full_shutter")]
    pub shutter: [f64; 2],
    /// A camera of the scene's glTF models, by number (counting the
    /// cameras of every glTF mesh object in order) or by name: its place,
    /// direction and projection replace `lookfrom`, `lookat`, `vup`,
    /// `vfov` and `ortho_height`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gltf: Option<GltfCamera>,
    /// Show the image mirrored left to right: +x of the image is
    /// `vup × view` instead of `view × vup`, as a left-handed camera (pbrt's
    /// `LookAt`, a Mitsuba sensor whose transform mirrors) sees it.
    #[serde(default, skip_serializing_if = "is_false")]
    pub mirror: bool,
    /// Nothing nearer than this along the view direction is seen: camera
    /// rays start on the plane this far in front of the lens.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub near_clip: f64,
    /// Nothing farther than this along the view direction is seen: what
    /// lies beyond shows the background to the camera (it still casts
    /// light and shadows). None: no limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far_clip: Option<f64>,
    /// The medium the camera stands in (a name in `media`); none when
    /// absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<String>,
    /// An orthographic camera seeing a rectangle this high, in scene units,
    /// through `lookfrom` (its width follows the image's aspect): parallel
    /// rays along the view direction, and `vfov` unused. None: perspective.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ortho_height: Option<f64>,
}

/// Which camera of the scene's glTF models.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum GltfCamera {
    /// The camera's number.
    Index(u32),
    /// The camera's name.
    Name(String),
}

/// The default shutter: open from time 0 to time 1.
pub const FULL_SHUTTER: [f64; 2] = [0.0, 1.0];

fn full_shutter() -> [f64; 2] {
    FULL_SHUTTER
}

fn is_full_shutter(s: &[f64; 2]) -> bool {
    *s == FULL_SHUTTER
}

impl Default for CameraDesc {
    fn default() -> Self {
        Self {
            vfov: 90.0,
            lookfrom: [0.0, 0.0, 0.0],
            lookat: [0.0, 0.0, -1.0],
            vup: [0.0, 1.0, 0.0],
            defocus_angle: 0.0,
            focus_dist: None,
            shutter: FULL_SHUTTER,
            gltf: None,
            mirror: false,
            near_clip: 0.0,
            far_clip: None,
            medium: None,
            ortho_height: None,
        }
    }
}

/// What rays that hit nothing see.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum BackgroundDesc {
    /// A vertical blend from `bottom` (ray pointing down) to `top` (up) by the
    /// ray direction's y component.
    Gradient {
        /// Colour straight down.
        bottom: Triple,
        /// Colour straight up.
        top: Triple,
    },
    /// One colour in every direction.
    Solid {
        /// The colour.
        color: Triple,
    },
    /// An equirectangular image around the scene (see
    /// [`EnvironmentMap`](crate::light::EnvironmentMap) for its layout).
    Image {
        /// The image file (`.exr`, `.hdr`, `.png`, `.jpg`, `.bmp`), relative to
        /// the scene file.
        file: String,
        /// Turn about +y, in degrees (counter-clockwise seen from above).
        #[serde(default, skip_serializing_if = "is_zero")]
        rotation: f64,
        /// Factor on every texel, ≥ 0.
        #[serde(default = "one", skip_serializing_if = "is_one")]
        intensity: f64,
        /// The first and last rows lie exactly at the poles (Mitsuba's
        /// convention) rather than half a row from them.
        #[serde(default, skip_serializing_if = "is_false")]
        rows_at_poles: bool,
        /// How the image wraps the scene: "equirectangular" (the
        /// default) or "equal-area" (pbrt's square octahedral map).
        #[serde(default, skip_serializing_if = "is_equirectangular")]
        layout: EnvironmentLayoutDesc,
        /// For an equal-area map: its x, y and z axes in the world (a
        /// rotation; the image's centre looks along z). The world's axes
        /// when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        frame: Option<[Triple; 3]>,
    },
}

/// How an environment image wraps the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvironmentLayoutDesc {
    /// Longitude across, latitude down, +y up (see
    /// [`EnvironmentMap`](crate::light::EnvironmentMap)).
    #[default]
    Equirectangular,
    /// A square, the sphere's octahedron unfolded with equal areas (pbrt's
    /// layout, [`equal_area_square`](crate::light::environment::equal_area_square)).
    EqualArea,
}

fn is_equirectangular(l: &EnvironmentLayoutDesc) -> bool {
    *l == EnvironmentLayoutDesc::Equirectangular
}

fn is_power(s: &LightSelection) -> bool {
    *s == LightSelection::Power
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn one() -> f64 {
    1.0
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

impl Default for BackgroundDesc {
    fn default() -> Self {
        BackgroundDesc::Gradient {
            bottom: [1.0, 1.0, 1.0],
            top: [0.5, 0.7, 1.0],
        }
    }
}

/// A texture (see [`crate::texture::Texture`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum TextureDesc {
    /// Alternating cubes in space, as in *The Next Week*.
    Checker {
        /// The side of a cube, > 0.
        scale: f64,
        /// The colour (or texture) of the cubes whose integer coordinates
        /// add up to an even number.
        even: ColorDesc,
        /// The colour (or texture) of the others.
        odd: ColorDesc,
    },
    /// Squares on the surface by its texture coordinates: `even` where
    /// ⌊s⌋ + ⌊t⌋ is even, (s, t) = uv_scale · (u, v) + uv_offset, `odd`
    /// elsewhere (pbrt's and Mitsuba's `checkerboard`).
    Checkerboard {
        /// The colour (or texture) of the even squares.
        even: ColorDesc,
        /// The colour (or texture) of the others.
        odd: ColorDesc,
        /// Factors on (u, v): [2, 2] makes squares of ½; 1 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_scale: Option<[f64; 2]>,
        /// Added to (u, v) after scaling; 0 when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_offset: Option<[f64; 2]>,
    },
    /// Another texture (or a colour) times a factor per channel (pbrt's
    /// `scale`).
    Scale {
        /// The texture scaled: a texture's name or a colour.
        texture: ColorDesc,
        /// The factor, per channel, each ≥ 0.
        factor: Triple,
    },
    /// Two textures (or colours) blended: (1 − amount)·first +
    /// amount·second (pbrt's `mix`).
    Mix {
        /// What amount 0 shows: a texture's name or a colour.
        first: ColorDesc,
        /// What amount 1 shows.
        second: ColorDesc,
        /// How much of `second`: a number or a scalar texture.
        amount: ScalarDesc,
    },
    /// An image wrapped by the surface's texture coordinates.
    Image {
        /// The image file, relative to the scene file.
        file: String,
        /// One channel of the image ("r", "g", "b" or "a"), making it a
        /// scalar texture (a roughness, an opacity); all three colour
        /// channels when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        channel: Option<ChannelDesc>,
        /// How 8- and 16-bit values are read: "srgb" (colours, the default
        /// without `channel`) or "linear" (data, the default with it).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        encoding: Option<EncodingDesc>,
        /// What coordinates outside [0, 1] read: "repeat" (the default),
        /// "clamp" or "mirror".
        #[serde(default, skip_serializing_if = "Option::is_none")]
        wrap: Option<WrapDesc>,
        /// "bilinear" (the default) or "nearest".
        #[serde(default, skip_serializing_if = "Option::is_none")]
        filter: Option<FilterDesc>,
        /// Which texture coordinates: 0 (the default) or 1 (a mesh's
        /// second set).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_set: Option<u32>,
        /// Added to the texture coordinates (after rotating and scaling
        /// them), in image widths, u rightwards and v down the image.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_offset: Option<[f64; 2]>,
        /// Rotation of the texture coordinates in degrees.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_rotation: Option<f64>,
        /// Factors on the texture coordinates: [2, 2] repeats the image
        /// twice each way.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uv_scale: Option<[f64; 2]>,
    },
    /// Perlin noise.
    Noise {
        /// Frequency: the point in space is multiplied by it; > 0.
        #[serde(default = "one", skip_serializing_if = "is_one")]
        scale: f64,
        /// How the noise becomes a grey level.
        #[serde(default)]
        pattern: NoisePatternDesc,
        /// The seed the noise is made from, at most [`MAX_SEED`].
        #[serde(default, skip_serializing_if = "is_zero_u64")]
        seed: u64,
    },
}

fn is_zero_u64(x: &u64) -> bool {
    *x == 0
}

impl TextureDesc {
    /// The image in `file`, as a colour, with every option at its default.
    pub fn image(file: impl Into<String>) -> TextureDesc {
        TextureDesc::Image {
            file: file.into(),
            channel: None,
            encoding: None,
            wrap: None,
            filter: None,
            uv_set: None,
            uv_offset: None,
            uv_rotation: None,
            uv_scale: None,
        }
    }
}

/// A channel of an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChannelDesc {
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha.
    A,
}

/// How an image's integer values are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EncodingDesc {
    /// Decoded from sRGB (colours).
    Srgb,
    /// As they are, scaled to [0, 1] (data).
    Linear,
}

/// What texture coordinates outside [0, 1] read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WrapDesc {
    /// The image again.
    Repeat,
    /// The edge.
    Clamp,
    /// The image mirrored every other time.
    Mirror,
}

/// How an image is blended between texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FilterDesc {
    /// The four nearest texels, weighted.
    Bilinear,
    /// The nearest texel.
    Nearest,
}

/// How noise becomes a grey level (see [`crate::texture::NoisePattern`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoisePatternDesc {
    /// ½(1 + noise).
    #[default]
    Smooth,
    /// A sum of seven octaves.
    Turbulence,
    /// Veined marble along z.
    Marble,
}

/// An object of the scene. Every kind may be placed with a `transform`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ObjectDesc {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Triple,
        /// Radius, > 0.
        radius: f64,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// A parallelogram with corners Q, Q + u, Q + u + v, Q + v.
    Quad {
        /// The corner Q.
        corner: Triple,
        /// The first edge u.
        u: Triple,
        /// The second edge v (not parallel to u).
        v: Triple,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// A flat disk (an ellipse once stretched by its transform), one-sided
    /// for one-sided materials and lights: its outside is along `normal`.
    /// Texture coordinates (u, v) = (r/radius, φ/2π), φ measured about the
    /// normal from the first axis of the normal's frame (see
    /// `docs/scene-format.md`).
    Disk {
        /// Centre.
        center: Triple,
        /// The side it faces (any length but zero).
        normal: Triple,
        /// Radius, > 0.
        radius: f64,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// The curved side of a cylinder from the centre of one end, `p0`, to
    /// the other, `p1`, open at both ends; its outside faces away from the
    /// axis. Texture coordinates (u, v) = (φ/2π, the share of the way from
    /// `p0` to `p1`).
    Cylinder {
        /// The centre of the first end.
        p0: Triple,
        /// The centre of the second end (not `p0`).
        p1: Triple,
        /// Radius, > 0.
        radius: f64,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// An axis-aligned box from `min` to `max` (six quads), before its
    /// transform.
    Box {
        /// The lowest corner.
        min: Triple,
        /// The highest corner: above `min` on every axis.
        max: Triple,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// A triangle mesh read from a file (.obj, .gltf, .glb, .ply or
    /// Mitsuba's .serialized).
    Mesh {
        /// The file, relative to the scene file.
        file: String,
        /// Name of a material in `materials` for the whole mesh; when
        /// absent, the file's own materials (and a grey diffuse where the
        /// file gives none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        material: Option<String>,
        /// Interpolate the file's vertex normals (smooth shading); false
        /// shades every triangle flat.
        #[serde(default = "yes", skip_serializing_if = "is_true")]
        smooth: bool,
        /// Whether the files the mesh file names (glTF buffers and images,
        /// MTL files and their maps) may lie outside its folder; see
        /// [`LoadOptions`](crate::mesh::LoadOptions).
        #[serde(default, skip_serializing_if = "is_false")]
        allow_outside: bool,
        /// Only the file's mesh of this index (from 0), placed where the
        /// file places it: one of the meshes of a Mitsuba `.serialized`
        /// file (its `shape_index`); all when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        part: Option<u32>,
        /// Turn the file's texture coordinates over (v becomes 1 − v): for
        /// a file written with v down the image (Mitsuba's PLY files),
        /// where lumen's v runs up it.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_v: bool,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// A triangle mesh written out in the scene itself (as pbrt's
    /// `trianglemesh`), rather than read from a file.
    Triangles {
        /// Vertex positions.
        positions: Vec<Triple>,
        /// Each triangle's three vertices, indices into `positions`,
        /// counter-clockwise seen from the front.
        indices: Vec<[u32; 3]>,
        /// A normal per vertex, for smooth shading; flat shading when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        normals: Option<Vec<Triple>>,
        /// Texture coordinates (u, v) per vertex; when absent, a triangle's
        /// corners have (0, 0), (1, 0) and (0, 1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uvs: Option<Vec<[f64; 2]>>,
        /// Name of a material in `materials`.
        material: String,
        /// Turn the outside in: one-sided materials and lights face the
        /// other way, and a glass's inside becomes its outside.
        #[serde(default, skip_serializing_if = "is_false")]
        flip_normals: bool,
        /// Placement, applied to the object in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
    /// Fog or smoke of constant density filling a sphere or a box, which
    /// scatters light equally in every direction. The boundary is not a
    /// surface.
    Medium {
        /// The region it fills.
        boundary: BoundaryDesc,
        /// The chance per unit length that a ray meets a particle, > 0.
        density: f64,
        /// The fraction of light a particle scatters, per channel, in [0, 1].
        albedo: Triple,
        /// Placement of the boundary, applied in the order written.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        transform: Vec<TransformDesc>,
    },
}

/// The region a medium fills.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum BoundaryDesc {
    /// A ball.
    Sphere {
        /// Centre.
        center: Triple,
        /// Radius, > 0.
        radius: f64,
    },
    /// An axis-aligned box from `min` to `max`.
    Box {
        /// The lowest corner.
        min: Triple,
        /// The highest corner: above `min` on every axis.
        max: Triple,
    },
}

fn yes() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
}

fn is_false(b: &bool) -> bool {
    !*b
}

impl ObjectDesc {
    /// The object's transform steps, to be changed.
    pub fn transform_mut(&mut self) -> &mut Vec<TransformDesc> {
        match self {
            ObjectDesc::Sphere { transform, .. }
            | ObjectDesc::Quad { transform, .. }
            | ObjectDesc::Disk { transform, .. }
            | ObjectDesc::Cylinder { transform, .. }
            | ObjectDesc::Box { transform, .. }
            | ObjectDesc::Mesh { transform, .. }
            | ObjectDesc::Triangles { transform, .. }
            | ObjectDesc::Medium { transform, .. } => transform,
        }
    }

    /// The object's transform steps.
    pub fn transform(&self) -> &[TransformDesc] {
        match self {
            ObjectDesc::Sphere { transform, .. }
            | ObjectDesc::Quad { transform, .. }
            | ObjectDesc::Disk { transform, .. }
            | ObjectDesc::Cylinder { transform, .. }
            | ObjectDesc::Box { transform, .. }
            | ObjectDesc::Mesh { transform, .. }
            | ObjectDesc::Triangles { transform, .. }
            | ObjectDesc::Medium { transform, .. } => transform,
        }
    }
}

/// One step of an object's placement; a list of steps is applied in the
/// order written, the first entry first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum TransformDesc {
    /// Move by this vector.
    Translate(Triple),
    /// Turn about an axis through the origin, counter-clockwise looking
    /// down the axis towards the origin.
    Rotate {
        /// The axis (any length but zero).
        axis: Triple,
        /// The angle in degrees.
        degrees: f64,
    },
    /// Scale about the origin, by one factor or one per axis (none zero).
    Scale(ScaleDesc),
    /// A 4×4 affine matrix, row by row; the last row must be [0, 0, 0, 1].
    Matrix([[f64; 4]; 4]),
    /// Motion: the object is where the other steps place it at time 0, and
    /// moves in a straight line by this vector (turned and scaled by the
    /// steps after this one) until time 1. The camera's shutter shows part
    /// of that movement, blurred.
    Motion(Triple),
}

/// A scale factor: one for every axis, or one per axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ScaleDesc {
    /// The same factor on every axis.
    Uniform(f64),
    /// A factor per axis.
    PerAxis(Triple),
}
