//! pbrt's graphics state, and each directive turned into lumen's scene
//! description: the camera, film, sampler, integrator and filter before
//! `WorldBegin`; shapes, lights and instances after it.

use super::lex::At;
use super::params::{Param, Params, Problem, Spectral};
use super::{spectra, Input};
use crate::scene::desc::{
    BackgroundDesc, CameraDesc, ColorDesc, DirectionalLightDesc, EncodingDesc, IntegratorDesc,
    LightDesc, LightSelection, ObjectDesc, PixelFilterDesc, PointLightDesc, ProjectorLightDesc,
    SamplingDesc, SceneDesc, SpotLightDesc, TextureDesc, TransformDesc,
};
use crate::scene::file::import::Imported;
use crate::scene::file::matrix::{self, Mat4, IDENTITY};
use std::collections::HashMap;

/// The directives lumen reads, for messages.
const DIRECTIVES: &[&str] = &[
    "AttributeBegin",
    "AttributeEnd",
    "Attribute",
    "AreaLightSource",
    "Accelerator",
    "ActiveTransform",
    "Camera",
    "ColorSpace",
    "ConcatTransform",
    "CoordinateSystem",
    "CoordSysTransform",
    "Film",
    "Identity",
    "Import",
    "Include",
    "Integrator",
    "LightSource",
    "LookAt",
    "MakeNamedMaterial",
    "MakeNamedMedium",
    "Material",
    "MediumInterface",
    "NamedMaterial",
    "ObjectBegin",
    "ObjectEnd",
    "ObjectInstance",
    "Option",
    "PixelFilter",
    "ReverseOrientation",
    "Rotate",
    "Sampler",
    "Scale",
    "Shape",
    "Texture",
    "Transform",
    "TransformBegin",
    "TransformEnd",
    "TransformTimes",
    "Translate",
    "WorldBegin",
    "WorldEnd",
];

/// The kinds of directive `Attribute` sets default parameters for.
const ATTRIBUTE_TARGETS: &[&str] = &["shape", "light", "material", "medium", "texture"];

/// What `AttributeBegin` saves and `AttributeEnd` restores.
#[derive(Clone, Debug)]
pub(super) struct State {
    /// The current transform, object to world.
    pub ctm: Mat4,
    /// Whether shapes face the other way.
    pub reverse: bool,
    /// The current material's name in lumen's description (`None`: pbrt's
    /// default, a grey diffuse).
    pub material: Option<String>,
    /// Whether the current material is `interface` (no surface).
    pub interface: bool,
    /// The area light shapes get: radiance (a colour, or an image
    /// texture's name), two-sided.
    pub area: Option<(ColorDesc, bool)>,
    /// The power each light of a shape gives off (`power`): its radiance
    /// is then scaled to it by the light's area.
    pub area_power: Option<f64>,
    /// Transforms apply at the shutter's open (`ActiveTransform
    /// StartTime` or `All`).
    pub start: bool,
    /// The media `MediumInterface` set, inside and outside (pbrt's
    /// names, which are lumen's; `None`: no medium).
    pub media: [Option<String>; 2],
    /// Default parameters `Attribute` set, in the order written, each with
    /// the kind of directive it is for: "shape", "light", "material",
    /// "medium" or "texture".
    pub attributes: Vec<(&'static str, Param)>,
}

/// The camera as the `Camera` directive gave it.
struct Camera {
    camera_from_world: Mat4,
    fov: f64,
    lens_radius: f64,
    focal_distance: f64,
    /// Orthographic: where, and the `screenwindow` given.
    orthographic: Option<(At, Option<[f64; 4]>)>,
    /// The medium it stands in: the outside one when it was given.
    medium: Option<String>,
}

/// Turns directives into a scene description.
pub(super) struct Builder {
    pub approximate: bool,
    /// Substitutions `--approximate` made: where and what.
    pub warnings: Vec<(At, String)>,
    pub desc: SceneDesc,
    pub state: State,
    stack: Vec<(State, At, &'static str)>,
    coordinate_systems: HashMap<String, Mat4>,
    world: bool,
    camera: Option<Camera>,
    film: (u32, u32),
    /// Objects defined by `ObjectBegin`, placed as their shapes' transforms
    /// before the instance's.
    instances: HashMap<String, Vec<ObjectDesc>>,
    /// The object being defined, if any.
    defining: Option<(String, Vec<ObjectDesc>)>,
    pub counter: usize,
    /// Named materials: pbrt's name to lumen's, and whether it is an
    /// `interface`.
    pub named_materials: HashMap<String, (String, bool)>,
    /// Textures: pbrt's (name, is a float texture) to what lumen has.
    pub textures: HashMap<(String, bool), super::materials::Tex>,
    /// Emitting copies of materials, by material and light (its radiance's
    /// bits, or its texture's name).
    emitting: HashMap<(Option<String>, String, bool), String>,
    default_material: Option<String>,
    /// Copies of materials with media on their sides.
    pub media_copies: crate::scene::file::import::MediaCopies,
    /// The media `MediumInterface` named, and where: checked once the
    /// file is read.
    pub medium_uses: Vec<(String, At)>,
}

/// One number or three numbers, by parameter.
fn rgb_of(s: &Spectral, at: At) -> Result<[f64; 3], Problem> {
    match s {
        Spectral::Rgb(c) => Ok(*c),
        Spectral::Grey(v) => Ok([*v; 3]),
        Spectral::Blackbody(t) => {
            spectra::blackbody(*t).ok_or((at, format!("a blackbody of {t} K gives no light"), None))
        }
        Spectral::Samples(v) => spectra::light_samples(v).map_err(|m| (at, m, None)),
        Spectral::Named(n) => spectra::illuminant(n).ok_or((
            at,
            format!("the light spectrum `{n}` is not one lumen has; it has stdillum-D65"),
            None,
        )),
        Spectral::Texture(_) => Err((at, "a light's colour cannot be a texture".into(), None)),
    }
}

impl Builder {
    /// A directive's parameters `p`, with the defaults `Attribute` set for
    /// `target` after them.
    fn defaults(&self, target: &str, p: Params) -> Params {
        let set = self.state.attributes.iter().filter(|(t, _)| *t == target);
        p.with_defaults(set.map(|(_, param)| param))
    }

    pub fn new(approximate: bool) -> Builder {
        let mut desc = SceneDesc::default();
        // pbrt's defaults, where they are not lumen's.
        desc.render.width = 1280;
        desc.render.height = Some(720);
        desc.render.samples_per_pixel = 16;
        desc.render.max_depth = 6;
        desc.render.sampler = SamplingDesc::Sobol;
        desc.render.gamma = 2.2;
        desc.render.pixel_filter = PixelFilterDesc::Gaussian;
        desc.render.filter_stddev = Some(0.5);
        desc.background = BackgroundDesc::Solid { color: [0.0; 3] };
        Builder {
            approximate,
            warnings: Vec::new(),
            desc,
            state: State {
                ctm: IDENTITY,
                reverse: false,
                material: None,
                interface: false,
                area: None,
                area_power: None,
                start: true,
                media: [None, None],
                attributes: Vec::new(),
            },
            stack: Vec::new(),
            coordinate_systems: HashMap::new(),
            world: false,
            camera: None,
            film: (1280, 720),
            instances: HashMap::new(),
            defining: None,
            counter: 0,
            named_materials: HashMap::new(),
            textures: HashMap::new(),
            emitting: HashMap::new(),
            default_material: None,
            media_copies: Default::default(),
            medium_uses: Vec::new(),
        }
    }

    /// A fresh name starting with `stem`.
    pub fn name(&mut self, stem: &str) -> String {
        loop {
            self.counter += 1;
            let name = format!("{stem}-{}", self.counter);
            if !self.desc.materials.contains_key(&name) && !self.desc.textures.contains_key(&name) {
                return name;
            }
        }
    }

    /// What lumen lacks, at `at`: refused, or with `--approximate` a
    /// warning that `instead` is done.
    pub fn lacks(&mut self, at: At, what: &str, instead: &str) -> Result<(), Problem> {
        if self.approximate {
            self.warnings
                .push((at, format!("{what}; {instead} instead (--approximate)")));
            Ok(())
        } else {
            Err((
                at,
                format!("lumen has no {what}"),
                Some(format!("--approximate renders {instead} instead")),
            ))
        }
    }

    fn world_only(&self, name: &str, at: At) -> Result<(), Problem> {
        if self.world {
            Ok(())
        } else {
            Err((at, format!("{name} must come after WorldBegin"), None))
        }
    }

    fn options_only(&self, name: &str, at: At) -> Result<(), Problem> {
        if self.world {
            Err((at, format!("{name} must come before WorldBegin"), None))
        } else {
            Ok(())
        }
    }

    /// Multiplies the current transform by `m` (on the right), as every
    /// transform directive does.
    fn concat(&mut self, m: Mat4, at: At) -> Result<(), Problem> {
        if !self.state.start {
            return Ok(());
        }
        let ctm = matrix::mul(&self.state.ctm, &m);
        if ctm.iter().flatten().any(|v| !v.is_finite()) {
            return Err((at, "the transform overflows".into(), None));
        }
        self.state.ctm = ctm;
        Ok(())
    }

    /// The current transform as an object's placement.
    pub fn placement(&self) -> Vec<TransformDesc> {
        if self.state.ctm == IDENTITY {
            Vec::new()
        } else {
            vec![TransformDesc::Matrix(self.state.ctm)]
        }
    }

    /// Reads directive `name`, written at `at`, and its arguments.
    pub fn directive(&mut self, name: &str, at: At, input: &mut Input) -> Result<(), Problem> {
        match name {
            "Include" | "Import" => {
                let (file, fat) = input.string(at)?;
                input.include(&file, fat)?;
            }
            "WorldBegin" => {
                self.options_only(name, at)?;
                self.world = true;
                self.state.ctm = IDENTITY;
                self.coordinate_systems.insert("world".into(), IDENTITY);
            }
            // pbrt-v3's end of the scene: nothing follows it.
            "WorldEnd" => {}
            "AttributeBegin" | "TransformBegin" => {
                self.stack.push((self.state.clone(), at, "AttributeBegin"));
            }
            "AttributeEnd" | "TransformEnd" => match self.stack.pop() {
                Some((state, _, "AttributeBegin")) => {
                    if name == "TransformEnd" {
                        self.state.ctm = state.ctm;
                    } else {
                        self.state = state;
                    }
                }
                Some((_, bat, what)) => {
                    return Err((
                        at,
                        format!("{name} closes the {what} at line {}", bat.line),
                        None,
                    ))
                }
                None => return Err((at, format!("{name} without an AttributeBegin"), None)),
            },
            "Identity" => self.state.ctm = IDENTITY,
            "Translate" => {
                let t = input.nums::<3>(at)?;
                self.concat(matrix::translation(t), at)?;
            }
            "Scale" => {
                let s = input.nums::<3>(at)?;
                self.concat(matrix::scaling(s), at)?;
            }
            "Rotate" => {
                let [angle, x, y, z] = input.nums::<4>(at)?;
                let axis = matrix::normalize([x, y, z]).ok_or((
                    at,
                    "Rotate needs a non-zero axis".into(),
                    None,
                ))?;
                self.concat(matrix::rotation(axis, angle), at)?;
            }
            "LookAt" => {
                let v = input.nums::<9>(at)?;
                let m = matrix::look_at(
                    [v[0], v[1], v[2]],
                    [v[3], v[4], v[5]],
                    Some([v[6], v[7], v[8]]),
                )
                .map_err(|m| (at, format!("LookAt: {m}"), None))?;
                if matrix::normalize([v[6], v[7], v[8]]).is_none() {
                    return Err((at, "LookAt: the up vector is zero".into(), None));
                }
                let camera_from_world =
                    matrix::inverse(&m).ok_or((at, "LookAt: degenerate".into(), None))?;
                self.concat(camera_from_world, at)?;
            }
            "Transform" | "ConcatTransform" => {
                let v = input.nums::<16>(at)?;
                // Written column by column.
                let m: Mat4 = std::array::from_fn(|i| std::array::from_fn(|j| v[j * 4 + i]));
                if m[3] != [0.0, 0.0, 0.0, 1.0] {
                    return Err((
                        at,
                        format!("{name}: a projective matrix (its last column is not 0 0 0 1); lumen places objects by affine transforms"),
                        None,
                    ));
                }
                if name == "Transform" {
                    if self.state.start {
                        self.state.ctm = m;
                    }
                } else {
                    self.concat(m, at)?;
                }
            }
            "CoordinateSystem" => {
                let (n, _) = input.string(at)?;
                self.coordinate_systems.insert(n, self.state.ctm);
            }
            "CoordSysTransform" => {
                let (n, nat) = input.string(at)?;
                match self.coordinate_systems.get(&n) {
                    Some(m) => self.state.ctm = *m,
                    None => {
                        let known: Vec<&str> =
                            self.coordinate_systems.keys().map(String::as_str).collect();
                        return Err((
                            nat,
                            format!(
                                "no coordinate system `{n}` is defined (there are: {})",
                                known.join(", ")
                            ),
                            crate::hint::closest(&n, known.iter().copied())
                                .map(|k| format!("did you mean `{k}`?")),
                        ));
                    }
                }
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "ActiveTransform" => {
                let (w, wat) = input.word(at)?;
                match w.as_str() {
                    "All" | "StartTime" => self.state.start = true,
                    "EndTime" => {
                        self.lacks(
                            wat,
                            "motion between two transforms",
                            "the transform at the shutter's opening",
                        )?;
                        self.state.start = false;
                    }
                    _ => {
                        return Err((
                            wat,
                            format!("ActiveTransform {w}: expected All, StartTime or EndTime"),
                            None,
                        ))
                    }
                }
            }
            "TransformTimes" => {
                input.nums::<2>(at)?;
            }
            "Option" => {
                // Renderer options (threads, seeds, coordinate systems for
                // rendering): none changes the image lumen makes.
                input.params(at)?.ignore_all();
            }
            "ColorSpace" => {
                let (cs, cat) = input.string(at)?;
                if !cs.eq_ignore_ascii_case("srgb") {
                    self.lacks(
                        cat,
                        &format!("colour space `{cs}` (lumen works in linear sRGB)"),
                        "sRGB",
                    )?;
                }
            }
            "Accelerator" => {
                input.string(at)?;
                input.params(at)?.ignore_all();
            }
            // The scene-wide settings: a type, then parameters.
            "Camera" | "Film" | "Sampler" | "Integrator" | "PixelFilter" => {
                self.options_only(name, at)?;
                let (ty, tat) = input.string(at)?;
                let p = input.params(at)?;
                match name {
                    "Camera" => self.camera(&ty, tat, &p)?,
                    "Film" => self.film(&ty, tat, &p)?,
                    "Sampler" => self.sampler(&ty, tat, &p)?,
                    "Integrator" => self.integrator(&ty, tat, &p)?,
                    _ => self.filter(&ty, tat, &p)?,
                }
            }
            "MakeNamedMedium" => {
                let (name, nat) = input.string(at)?;
                let p = self.defaults("medium", input.params(at)?);
                self.named_medium(&name, nat, &p)?;
            }
            "MediumInterface" => {
                let (inside, _) = input.string(at)?;
                let outside = if input.string_follows()? {
                    input.string(at)?.0
                } else {
                    inside.clone()
                };
                self.medium_interface(inside, outside, at);
            }
            "Attribute" => {
                let (target, tat) = input.string(at)?;
                let Some(&target) = ATTRIBUTE_TARGETS.iter().find(|&&t| t == target) else {
                    return Err((
                        tat,
                        format!(
                            "Attribute sets defaults for {}, not `{target}`",
                            ATTRIBUTE_TARGETS.join(", ")
                        ),
                        crate::hint::closest(&target, ATTRIBUTE_TARGETS.iter().copied())
                            .map(|k| format!("did you mean `{k}`?")),
                    ));
                };
                let p = input.params(at)?;
                self.state
                    .attributes
                    .extend(p.list.into_iter().map(|param| (target, param)));
            }
            "Texture" => {
                self.world_only(name, at)?;
                let (n, _) = input.string(at)?;
                let (class, cat) = input.string(at)?;
                let (ty, tat) = input.string(at)?;
                let p = self.defaults("texture", input.params(at)?);
                self.texture(&n, &class, cat, &ty, tat, &p, input)?;
            }
            "Material" => {
                self.world_only(name, at)?;
                let (ty, tat) = input.string(at)?;
                let p = self.defaults("material", input.params(at)?);
                let (material, interface) = self.material(&ty, tat, &p, input)?;
                self.state.material = Some(material);
                self.state.interface = interface;
            }
            "MakeNamedMaterial" => {
                self.world_only(name, at)?;
                let (n, nat) = input.string(at)?;
                let p = self.defaults("material", input.params(at)?);
                let (ty, tat) = p
                    .string_of("type", "string")?
                    .map(|(t, a)| (t.to_string(), a))
                    .ok_or((
                        nat,
                        format!("MakeNamedMaterial \"{n}\" needs a \"string type\""),
                        None,
                    ))?;
                let made = self.material(&ty, tat, &p, input)?;
                self.named_materials.insert(n, made);
            }
            "NamedMaterial" => {
                self.world_only(name, at)?;
                let (n, nat) = input.string(at)?;
                let Some((material, interface)) = self.named_materials.get(&n).cloned() else {
                    let known: Vec<&str> =
                        self.named_materials.keys().map(String::as_str).collect();
                    return Err((
                        nat,
                        format!("no material is named `{n}`"),
                        crate::hint::closest(&n, known.iter().copied())
                            .map(|k| format!("did you mean `{k}`?")),
                    ));
                };
                self.state.material = Some(material);
                self.state.interface = interface;
            }
            // The world's entities: a type, then parameters.
            "LightSource" | "AreaLightSource" | "Shape" => {
                self.world_only(name, at)?;
                let (ty, tat) = input.string(at)?;
                let target = if name == "Shape" { "shape" } else { "light" };
                let p = self.defaults(target, input.params(at)?);
                match name {
                    "LightSource" => self.light(&ty, tat, &p, input)?,
                    "AreaLightSource" => self.area_light(&ty, tat, &p, input)?,
                    _ => self.shape(&ty, tat, &p, input)?,
                }
            }
            "ObjectBegin" => {
                self.world_only(name, at)?;
                let (n, nat) = input.string(at)?;
                if self.defining.is_some() {
                    return Err((
                        at,
                        "ObjectBegin inside another object's definition".into(),
                        None,
                    ));
                }
                if self.instances.contains_key(&n) {
                    return Err((nat, format!("object `{n}` is defined twice"), None));
                }
                self.stack.push((self.state.clone(), at, "ObjectBegin"));
                self.defining = Some((n, Vec::new()));
            }
            "ObjectEnd" => {
                let Some((n, objects)) = self.defining.take() else {
                    return Err((at, "ObjectEnd without an ObjectBegin".into(), None));
                };
                match self.stack.pop() {
                    Some((state, _, "ObjectBegin")) => self.state = state,
                    Some((_, bat, what)) => {
                        return Err((
                            at,
                            format!("ObjectEnd closes the {what} at line {}", bat.line),
                            None,
                        ))
                    }
                    None => return Err((at, "ObjectEnd without an ObjectBegin".into(), None)),
                }
                self.instances.insert(n, objects);
            }
            "ObjectInstance" => {
                self.world_only(name, at)?;
                let (n, nat) = input.string(at)?;
                let Some(objects) = self.instances.get(&n) else {
                    let known: Vec<&str> = self.instances.keys().map(String::as_str).collect();
                    return Err((
                        nat,
                        format!("no object is named `{n}`"),
                        crate::hint::closest(&n, known.iter().copied())
                            .map(|k| format!("did you mean `{k}`?")),
                    ));
                };
                let placed: Vec<ObjectDesc> = objects
                    .iter()
                    .map(|o| {
                        let mut o = o.clone();
                        if self.state.ctm != IDENTITY {
                            o.transform_mut()
                                .push(TransformDesc::Matrix(self.state.ctm));
                        }
                        o
                    })
                    .collect();
                self.desc.objects.extend(placed);
            }
            other => {
                return Err((
                    at,
                    format!("unknown directive `{other}`"),
                    crate::hint::closest(other, DIRECTIVES.iter().copied())
                        .map(|k| format!("did you mean `{k}`?")),
                ))
            }
        }
        Ok(())
    }

    /// Adds `object`, to the scene or to the object being defined.
    pub fn add(&mut self, object: ObjectDesc) {
        match &mut self.defining {
            Some((_, objects)) => objects.push(object),
            None => self.desc.objects.push(object),
        }
    }

    /// Whether an object is being defined (its shapes cannot shine).
    pub fn in_definition(&self) -> bool {
        self.defining.is_some()
    }

    fn camera(&mut self, ty: &str, at: At, p: &Params) -> Result<(), Problem> {
        let orthographic = ty == "orthographic";
        if !orthographic && ty != "perspective" {
            self.lacks(
                at,
                &format!("`{ty}` camera"),
                "a perspective or orthographic camera",
            )?;
        }
        // An orthographic camera has no field of view: pbrt refuses one.
        let fov = if orthographic {
            90.0
        } else {
            p.float("fov")?.unwrap_or(90.0)
        };
        if !(fov > 0.0 && fov < 180.0) {
            return Err((
                at,
                format!("`fov` must lie between 0 and 180 degrees, got {fov}"),
                None,
            ));
        }
        let lens_radius = p.float("lensradius")?.unwrap_or(0.0);
        let focal_distance = p.float("focaldistance")?.unwrap_or(1e6);
        if !(lens_radius >= 0.0 && focal_distance > 0.0) {
            return Err((
                at,
                "`lensradius` must be ≥ 0 and `focaldistance` > 0".into(),
                None,
            ));
        }
        let open = p.float("shutteropen")?.unwrap_or(0.0);
        let close = p.float("shutterclose")?.unwrap_or(1.0);
        if close - open != 1.0 {
            // pbrt's film scales the image by the time the shutter is open.
            self.lacks(
                at,
                "an image scaled by a shutter open for other than 1 unit of time",
                "the image of a shutter open for 1",
            )?;
        }
        let ortho = if orthographic {
            if lens_radius > 0.0 {
                self.lacks(at, "an orthographic camera's lens", "a pinhole")?;
            }
            let window = match p.nums("screenwindow", &["float"])? {
                None => None,
                Some((&[x0, x1, y0, y1], _)) => Some([x0, x1, y0, y1]),
                Some((w, w_at)) => {
                    return Err((
                        w_at,
                        format!(
                            "`screenwindow` takes 4 numbers [x0 x1 y0 y1], got {}",
                            w.len()
                        ),
                        None,
                    ))
                }
            };
            Some((at, window))
        } else {
            None
        };
        for n in ["screenwindow", "frameaspectratio"] {
            if (!orthographic || n != "screenwindow") && p.nums(n, &["float"])?.is_some() {
                self.lacks(
                    at,
                    &format!("`{n}` (a shifted or stretched image)"),
                    "the centred image",
                )?;
            }
        }
        let known = [
            "lensradius",
            "focaldistance",
            "shutteropen",
            "shutterclose",
            "screenwindow",
            "frameaspectratio",
            "fov",
        ];
        if orthographic {
            p.finish("an orthographic camera", &known[..6])?;
        } else {
            p.finish("a perspective camera", &known)?;
        }
        let camera_from_world = self.state.ctm;
        let world_from_camera = matrix::inverse(&camera_from_world).ok_or((
            at,
            "the camera's transform is singular".into(),
            None,
        ))?;
        self.coordinate_systems
            .insert("camera".into(), world_from_camera);
        self.camera = Some(Camera {
            camera_from_world,
            fov,
            lens_radius: if orthographic { 0.0 } else { lens_radius },
            focal_distance,
            orthographic: ortho,
            medium: self.state.media[1].clone(),
        });
        Ok(())
    }

    /// The height of an orthographic camera's screen window: pbrt's
    /// default spans 2 across the image's shorter side; a `screenwindow`
    /// is taken when it is centred and keeps the image's aspect.
    fn ortho_height(&mut self, at: At, window: Option<[f64; 4]>) -> Result<f64, Problem> {
        let (width, height) = self.film;
        let aspect = f64::from(width) / f64::from(height);
        let default = if aspect >= 1.0 { 2.0 } else { 2.0 / aspect };
        let Some([x0, x1, y0, y1]) = window else {
            return Ok(default);
        };
        let (span_x, span_y) = (x1 - x0, y1 - y0);
        let centred = (x0 + x1).abs() <= 1e-6 * span_x && (y0 + y1).abs() <= 1e-6 * span_y;
        if span_x > 0.0 && span_y > 0.0 && centred && (span_x / span_y / aspect - 1.0).abs() <= 1e-3
        {
            return Ok(span_y);
        }
        self.lacks(
            at,
            "`screenwindow` shifted off centre or stretched from the image's shape",
            "a centred window of the image's shape",
        )?;
        Ok(default)
    }

    fn film(&mut self, ty: &str, at: At, p: &Params) -> Result<(), Problem> {
        if ty != "rgb" {
            self.lacks(at, &format!("`{ty}` film"), "an RGB film")?;
        }
        let size = |n: &str, default: i64| -> Result<u32, Problem> {
            let v = p.int(n)?.unwrap_or(default);
            u32::try_from(v).ok().filter(|v| *v > 0).ok_or((
                at,
                format!("`{n}` must be a whole number above 0, got {v}"),
                None,
            ))
        };
        self.film = (size("xresolution", 1280)?, size("yresolution", 720)?);
        // pbrt's window [x0 x1 y0 y1]: in pixels, or as fractions of the
        // image whose pixel bounds are their products rounded up.
        let (w, h) = (f64::from(self.film.0), f64::from(self.film.1));
        let window = match (
            p.nums("pixelbounds", &["integer"])?,
            p.nums("cropwindow", &["float"])?,
        ) {
            (Some((b, at)), _) => Some((b.to_vec(), at)),
            (None, Some((c, at))) if c.len() == 4 => Some((
                vec![
                    (c[0] * w).ceil(),
                    (c[1] * w).ceil(),
                    (c[2] * h).ceil(),
                    (c[3] * h).ceil(),
                ],
                at,
            )),
            (None, Some((_, at))) => return Err((at, "`cropwindow` takes 4 numbers".into(), None)),
            (None, None) => None,
        };
        if let Some((b, wat)) = window {
            let fits = b.len() == 4
                && b.iter().all(|v| v.is_finite())
                && 0.0 <= b[0]
                && b[0] < b[1]
                && b[1] <= w
                && 0.0 <= b[2]
                && b[2] < b[3]
                && b[3] <= h;
            if !fits {
                return Err((
                    wat,
                    format!(
                        "the window [{}] must hold x0 < x1 and y0 < y1 within the {}x{} image",
                        b.iter()
                            .map(|v| v.to_string())
                            .collect::<Vec<_>>()
                            .join(" "),
                        self.film.0,
                        self.film.1
                    ),
                    None,
                ));
            }
            let [x0, x1, y0, y1] = [b[0], b[1], b[2], b[3]].map(|v| v as u32);
            self.desc.render.crop = Some([x0, y0, x1 - x0, y1 - y0]);
        }
        if p.float("iso")?.is_some_and(|v| v != 100.0) {
            self.lacks(at, "film sensitivity other than ISO 100", "ISO 100")?;
        }
        if p.float("whitebalance")?.is_some_and(|v| v != 0.0) {
            self.lacks(at, "white balancing", "no white balance")?;
        }
        if p.string("sensor")?.is_some_and(|s| s != "cie1931") {
            self.lacks(at, "camera sensor response", "the CIE 1931 observer")?;
        }
        if p.float("maxcomponentvalue")?.is_some_and(f64::is_finite) {
            self.lacks(
                at,
                "clamping of samples (maxcomponentvalue)",
                "unclamped samples",
            )?;
        }
        // Where the image goes and how it is stored are the command line's.
        p.ignore(&["filename", "savefp16", "diagonal", "exposuretime"]);
        p.finish(
            "an RGB film",
            &[
                "xresolution",
                "yresolution",
                "cropwindow",
                "iso",
                "whitebalance",
                "sensor",
                "maxcomponentvalue",
                "filename",
                "savefp16",
                "diagonal",
            ],
        )?;
        self.desc.render.width = self.film.0;
        self.desc.render.height = Some(self.film.1);
        Ok(())
    }

    fn sampler(&mut self, ty: &str, at: At, p: &Params) -> Result<(), Problem> {
        let (sampler, spp) = match ty {
            "independent" => (SamplingDesc::Independent, p.int("pixelsamples")?.unwrap_or(4)),
            "stratified" => {
                let x = p.int("xsamples")?.unwrap_or(4);
                let y = p.int("ysamples")?.unwrap_or(4);
                if p.boolean("jitter")? == Some(false) {
                    self.lacks(at, "stratified sampling without jitter", "jittered strata")?;
                }
                (SamplingDesc::Stratified, x.saturating_mul(y))
            }
            "zsobol" | "sobol" | "paddedsobol" | "halton" | "pmj02bn" => {
                p.ignore(&["randomization", "seed"]);
                (SamplingDesc::Sobol, p.int("pixelsamples")?.unwrap_or(16))
            }
            other => {
                return Err((
                    at,
                    format!("sampler `{other}` is not one pbrt-v4 has; lumen reads independent, stratified, zsobol, sobol, paddedsobol, halton, pmj02bn"),
                    None,
                ))
            }
        };
        p.ignore(&["seed"]);
        p.finish(
            "a sampler",
            &[
                "pixelsamples",
                "xsamples",
                "ysamples",
                "jitter",
                "randomization",
                "seed",
            ],
        )?;
        let spp = u32::try_from(spp).ok().filter(|s| *s > 0).ok_or((
            at,
            format!("the sampler must take at least 1 sample per pixel, got {spp}"),
            None,
        ))?;
        self.desc.render.sampler = sampler;
        self.desc.render.samples_per_pixel = spp;
        Ok(())
    }

    fn integrator(&mut self, ty: &str, at: At, p: &Params) -> Result<(), Problem> {
        match ty {
            "path" | "volpath" => {}
            other => self.lacks(at, &format!("`{other}` integrator"), "the path integrator")?,
        }
        let depth = p.int("maxdepth")?.unwrap_or(5);
        let depth = u32::try_from(depth).ok().filter(|d| *d < u32::MAX).ok_or((
            at,
            format!("`maxdepth` must be a whole number ≥ 0, got {depth}"),
            None,
        ))?;
        // pbrt counts bounces; lumen counts segments, the camera's first.
        self.desc.render.max_depth = depth + 1;
        self.desc.render.integrator = IntegratorDesc::Path;
        if let Some(s) = p.string("lightsampler")? {
            self.desc.render.light_selection = match s {
                "uniform" => LightSelection::Uniform,
                "power" | "bvh" | "exhaustive" => LightSelection::Power,
                other => {
                    return Err((
                        at,
                        format!(
                            "lightsampler `{other}`: expected bvh, power, uniform or exhaustive"
                        ),
                        None,
                    ))
                }
            };
        }
        if p.boolean("regularize")? == Some(true) {
            self.lacks(at, "path regularization", "unregularized paths")?;
        }
        p.ignore(&["maxdepth", "lightsampler", "regularize"]);
        // Other integrators' parameters (bdpt's, sppm's) go with them.
        if ty != "path" && ty != "volpath" {
            p.ignore_all();
        }
        p.finish(
            "the path integrator",
            &["maxdepth", "lightsampler", "regularize"],
        )
    }

    fn filter(&mut self, ty: &str, at: At, p: &Params) -> Result<(), Problem> {
        match ty {
            "box" => {
                let r = p.nums("radius", &["float"])?;
                if r.is_some_and(|(v, _)| v.iter().any(|x| *x != 0.5)) {
                    self.lacks(
                        at,
                        "box filter other than one pixel wide",
                        "a one-pixel box",
                    )?;
                }
                self.desc.render.pixel_filter = PixelFilterDesc::Box;
                self.desc.render.filter_stddev = None;
                p.finish("a box filter", &["xradius", "yradius", "radius"])?;
            }
            "gaussian" => {
                let sigma = p.float("sigma")?.unwrap_or(0.5);
                if !(sigma > 0.0) {
                    return Err((at, format!("`sigma` must be above 0, got {sigma}"), None));
                }
                p.ignore(&["radius", "xradius", "yradius"]);
                self.desc.render.pixel_filter = PixelFilterDesc::Gaussian;
                self.desc.render.filter_stddev = Some(sigma);
                p.finish("a Gaussian filter", &["sigma", "radius"])?;
            }
            other => {
                p.ignore_all();
                self.lacks(
                    at,
                    &format!("`{other}` pixel filter"),
                    "pbrt's default Gaussian",
                )?;
                self.desc.render.pixel_filter = PixelFilterDesc::Gaussian;
                self.desc.render.filter_stddev = Some(0.5);
            }
        }
        Ok(())
    }

    /// pbrt's `projection` light: an image cast through the frustum of a
    /// perspective camera at the light's frame looking along +z, `fov`
    /// across the image's shorter side, its top row towards the frame's +y
    /// and its left column towards −x (pbrt turns the frame over in y
    /// and runs its screen along +x), the intensity `scale` × the image,
    /// its nearest texel.
    fn projection_light(&mut self, at: At, p: &Params, input: &Input) -> Result<(), Problem> {
        let scale = p.float("scale")?.unwrap_or(1.0);
        if p.float("power")?.is_some_and(|v| v > 0.0) {
            self.lacks(at, "a projection light given its `power`", "its `scale`")?;
        }
        let fov = p.float("fov")?.unwrap_or(90.0);
        if !(fov > 0.0 && fov < 180.0) {
            return Err((
                at,
                format!("`fov` must lie between 0 and 180 degrees, got {fov}"),
                None,
            ));
        }
        let (name, fat) = p.string_of("filename", "string")?.ok_or((
            at,
            "a projection light needs a \"string filename\"".into(),
            None,
        ))?;
        let file = input.file(name, fat)?;
        let (w, h) = crate::texture::image::Image::dimensions(&input.dir.join(&file))
            .map_err(|e| (fat, format!("image `{file}`: {e}"), None))?;
        let aspect = f64::from(w) / f64::from(h);
        p.finish("a projection light", &["scale", "power", "fov", "filename"])?;
        let m = self.state.ctm;
        // The frustum keeps its shape only under a turn, a move and a
        // uniform scale.
        let [x, y, z] =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|v| matrix::vector(&m, v));
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (lx, ly, lz) = (dot(x, x).sqrt(), dot(y, y).sqrt(), dot(z, z).sqrt());
        let similar = lx > 0.0
            && ((ly / lx - 1.0).abs() < 1e-6)
            && ((lz / lx - 1.0).abs() < 1e-6)
            && [dot(x, y), dot(y, z), dot(x, z)]
                .iter()
                .all(|d| d.abs() <= 1e-6 * lx * lx);
        if !similar {
            return Err((
                at,
                "the light's transform stretches or shears its frustum: a projection light may \
                 only be turned, moved and scaled alike along every axis"
                    .into(),
                None,
            ));
        }
        let (Some(axis), Some(up)) = (matrix::normalize(z), matrix::normalize(y)) else {
            return Err((at, "the light's transform is singular".into(), None));
        };
        // lumen's image runs along axis × up, which is the frame's −x
        // unless the frame mirrors: pbrt's runs along +x, so the image is
        // read mirrored left to right where the two differ.
        let mirrored = dot(x, matrix::cross(axis, up)) < 0.0;
        let texture = self.name("projection");
        let mut image = super::materials::image(
            file,
            crate::scene::desc::EncodingDesc::Srgb,
            None,
            [1.0, 1.0, 0.0, 0.0],
        );
        if let TextureDesc::Image {
            filter,
            encoding,
            uv_scale,
            uv_offset,
            ..
        } = &mut image
        {
            *filter = Some(crate::scene::desc::FilterDesc::Nearest);
            // As the file says: sRGB for 8-bit files, linear for
            // floating-point ones.
            *encoding = None;
            if mirrored {
                *uv_scale = Some([-1.0, 1.0]);
                *uv_offset = Some([1.0, 0.0]);
            }
        }
        self.desc.textures.insert(texture.clone(), image);
        let half = (fov.to_radians() / 2.0).tan();
        let across = if aspect > 1.0 {
            2.0 * (half * aspect).atan()
        } else {
            fov.to_radians()
        };
        self.desc
            .lights
            .push(LightDesc::Projector(ProjectorLightDesc {
                position: matrix::point(&m, [0.0; 3]),
                direction: Some(axis),
                target: None,
                up: Some(up),
                fov: across.to_degrees(),
                irradiance: None,
                intensity: Some([scale; 3]),
                texture: Some(texture),
                aspect: None,
            }));
        Ok(())
    }

    /// A light's colour `name` (its default white) times `scale`.
    fn emitted(&self, p: &Params, name: &str) -> Result<[f64; 3], Problem> {
        let c = match p.spectral(name, false)? {
            None => [1.0; 3],
            Some((s, at)) => rgb_of(&s, at)?,
        };
        let scale = p.float("scale")?.unwrap_or(1.0);
        Ok(c.map(|x| x * scale))
    }

    fn light(&mut self, ty: &str, at: At, p: &Params, input: &Input) -> Result<(), Problem> {
        let point = |p: &Params, n: &str, default: [f64; 3]| -> Result<[f64; 3], Problem> {
            Ok(p.triple(n, &["point3"])?.unwrap_or(default))
        };
        match ty {
            "point" => {
                let mut intensity = self.emitted(p, "I")?;
                if let Some(power) = p.float("power")?.filter(|v| *v > 0.0) {
                    intensity = intensity.map(|x| x * power / (4.0 * std::f64::consts::PI));
                }
                let from = point(p, "from", [0.0; 3])?;
                p.finish("a point light", &["I", "scale", "power", "from"])?;
                self.desc.lights.push(LightDesc::Point(PointLightDesc {
                    position: matrix::point(&self.state.ctm, from),
                    intensity,
                }));
            }
            "spot" => {
                let mut intensity = self.emitted(p, "I")?;
                let from = point(p, "from", [0.0; 3])?;
                let to = point(p, "to", [0.0, 0.0, 1.0])?;
                let cone = p.float("coneangle")?.unwrap_or(30.0);
                let delta = p.float("conedeltaangle")?.unwrap_or(5.0);
                if !(cone > 0.0 && cone < 180.0 && delta >= 0.0 && delta < cone) {
                    return Err((at, format!("a spot light needs 0 < coneangle < 180 and 0 ≤ conedeltaangle < coneangle, got {cone} and {delta}"), None));
                }
                if let Some(power) = p.float("power")?.filter(|v| *v > 0.0) {
                    let (cos_e, cos_s) = (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                    let solid = 2.0 * std::f64::consts::PI * ((1.0 - cos_s) + (cos_s - cos_e) / 2.0);
                    intensity = intensity.map(|x| x * power / solid);
                }
                p.finish("a spot light", &["I", "scale", "power", "from", "to", "coneangle", "conedeltaangle"])?;
                let direction = matrix::vector(&self.state.ctm, [to[0] - from[0], to[1] - from[1], to[2] - from[2]]);
                if matrix::normalize(direction).is_none() {
                    return Err((at, "a spot light's `from` and `to` are the same point".into(), None));
                }
                self.desc.lights.push(LightDesc::Spot(SpotLightDesc {
                    position: matrix::point(&self.state.ctm, from),
                    direction: Some(direction),
                    intensity,
                    cutoff_angle: Some(cone),
                    beam_width: Some(cone - delta),
                    falloff: Some(crate::light::source::SpotFalloffDesc::Smoothstep),
                    ..SpotLightDesc::default()
                }));
            }
            "projection" => self.projection_light(at, p, input)?,
            "distant" => {
                let mut irradiance = self.emitted(p, "L")?;
                if let Some(e) = p.float("illuminance")?.filter(|v| *v > 0.0) {
                    irradiance = irradiance.map(|x| x * e);
                }
                let from = point(p, "from", [0.0; 3])?;
                let to = point(p, "to", [0.0, 0.0, 1.0])?;
                p.finish("a distant light", &["L", "scale", "illuminance", "from", "to"])?;
                let direction = matrix::vector(&self.state.ctm, [to[0] - from[0], to[1] - from[1], to[2] - from[2]]);
                if matrix::normalize(direction).is_none() {
                    return Err((at, "a distant light's `from` and `to` are the same point".into(), None));
                }
                self.desc.lights.push(LightDesc::Directional(DirectionalLightDesc {
                    direction,
                    irradiance,
                    ..DirectionalLightDesc::default()
                }));
            }
            "infinite" => {
                if let Some((file, fat)) = p.string_of("filename", "string")? {
                    let file = input.file(file, fat)?;
                    if p.has("L") {
                        return Err((fat, "an infinite light takes `L` or `filename`, not both".into(), None));
                    }
                    let mut scale = p.float("scale")?.unwrap_or(1.0);
                    if let Some(e) = p.float("illuminance")?.filter(|v| *v > 0.0) {
                        scale *= e / upper_illuminance(&input.dir.join(&file), at)?;
                    }
                    p.ignore(&["portal"]);
                    p.finish("an infinite light", &["L", "scale", "illuminance", "filename", "portal"])?;
                    // The light's frame: the transform's axes, which must
                    // turn and not stretch.
                    let m = &{ self.state.ctm };
                    let axes = [0, 1, 2].map(|j| matrix::normalize([m[0][j], m[1][j], m[2][j]]));
                    let [Some(x), Some(y), Some(z)] = axes else {
                        return Err((at, "the environment's transform is singular".into(), None));
                    };
                    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                    if dot(x, y).abs() > 1e-6 || dot(y, z).abs() > 1e-6 || dot(x, z).abs() > 1e-6 {
                        return Err((at, "the environment's transform shears it: it may only turn it".into(), None));
                    }
                    // A mirroring transform: the map's axes as the
                    // transform has them, which no rotation gives.
                    if matrix::det3(m) < 0.0 {
                        self.lacks(at, "environment map mirrored by its transform", "the map unmirrored")?;
                    }
                    let z = if matrix::det3(m) < 0.0 { z.map(|c| -c) } else { z };
                    if !matches!(self.desc.background, BackgroundDesc::Solid { color: [0.0, 0.0, 0.0] }) {
                        self.lacks(at, "second environment light", "the last one")?;
                    }
                    self.desc.background = BackgroundDesc::Image {
                        file,
                        rotation: 0.0,
                        intensity: scale,
                        rows_at_poles: false,
                        layout: crate::scene::desc::EnvironmentLayoutDesc::EqualArea,
                        frame: Some([x, y, z]),
                    };
                    self.desc.render.sample_background = Some(true);
                    return Ok(());
                }
                let mut radiance = self.emitted(p, "L")?;
                if let Some(e) = p.float("illuminance")?.filter(|v| *v > 0.0) {
                    radiance = radiance.map(|x| x * e / std::f64::consts::PI);
                }
                if p.has("portal") {
                    let _ = p.get("portal");
                }
                p.finish("an infinite light", &["L", "scale", "illuminance", "filename", "portal"])?;
                let color = match &self.desc.background {
                    BackgroundDesc::Solid { color } => [0, 1, 2].map(|i| color[i] + radiance[i]),
                    _ => {
                        self.lacks(at, "second environment light", "the last one")?;
                        radiance
                    }
                };
                self.desc.background = BackgroundDesc::Solid { color };
            }
            "goniometric" => {
                p.ignore_all();
                self.lacks(at, &format!("`{ty}` light"), "no light")?;
            }
            other => {
                return Err((
                    at,
                    format!("light `{other}` is not one lumen reads; it reads point, spot, distant, infinite, projection"),
                    crate::hint::closest(other, ["point", "spot", "distant", "infinite", "projection"])
                        .map(|k| format!("did you mean `{k}`?")),
                ))
            }
        }
        Ok(())
    }

    fn area_light(&mut self, ty: &str, at: At, p: &Params, input: &Input) -> Result<(), Problem> {
        if ty != "diffuse" {
            return Err((
                at,
                format!("area light `{ty}`: pbrt-v4 has only \"diffuse\""),
                None,
            ));
        }
        let two_sided = p.boolean("twosided")?.unwrap_or(false);
        let power = p.float("power")?.filter(|v| *v > 0.0);
        if power.is_some() && p.has("filename") {
            self.lacks(
                at,
                "an image area light given by its power",
                "the image times `scale`",
            )?;
        }
        let radiance = match p.string_of("filename", "string")? {
            None => ColorDesc::Rgb(self.emitted(p, "L")?),
            Some((file, fat)) => {
                if p.has("L") {
                    return Err((
                        fat,
                        "an area light takes `L` or `filename`, not both".into(),
                        None,
                    ));
                }
                // The image over the shape's (u, v), its top row at v = 1,
                // as pbrt looks it up; an 8-bit image is sRGB, a float one
                // linear.
                let file = input.file(file, fat)?;
                let encoding = if super::materials::float_image(&file) {
                    EncodingDesc::Linear
                } else {
                    EncodingDesc::Srgb
                };
                let name = self.name("area-light-image");
                self.desc.textures.insert(
                    name.clone(),
                    super::materials::image(file, encoding, None, [1.0, 1.0, 0.0, 0.0]),
                );
                match p.float("scale")?.unwrap_or(1.0) {
                    s if !(s >= 0.0) => {
                        return Err((at, format!("`scale` must be ≥ 0, got {s}"), None))
                    }
                    1.0 => ColorDesc::Texture(name),
                    s => self.scaled(name, [s; 3]).into(),
                }
            }
        };
        p.finish(
            "a diffuse area light",
            &["L", "scale", "twosided", "power", "filename"],
        )?;
        self.state.area_power = power.filter(|_| matches!(radiance, ColorDesc::Rgb(_)));
        self.state.area = Some((radiance, two_sided));
        Ok(())
    }

    /// The material a shape is made of now: the current one, shining with
    /// the current area light. `area` is the area pbrt gives each of the
    /// shape's lights (`None` where lumen does not know it): an area light
    /// given by its `power` Φ has its radiance L scaled by
    /// Φ / (sides · area · π), as pbrt-v4's (which leaves an RGB L's own
    /// brightness in).
    pub fn shape_material(&mut self, at: At, area: Option<f64>) -> Result<String, Problem> {
        let base = match &self.state.material {
            Some(m) => m.clone(),
            None => self.default_material(),
        };
        let Some((radiance, two_sided)) = self.state.area.clone() else {
            return Ok(base);
        };
        // pbrt gives no light to an interface, nor to instanced shapes.
        if self.state.interface || radiance == ColorDesc::Rgb([0.0; 3]) {
            return Ok(base);
        }
        let radiance = match (self.state.area_power, &radiance, area) {
            (Some(power), ColorDesc::Rgb(c), Some(area)) if area > 0.0 => {
                let sides = if two_sided { 2.0 } else { 1.0 };
                let k = power / (sides * area * std::f64::consts::PI);
                ColorDesc::Rgb(c.map(|x| x * k))
            }
            (Some(_), _, _) => {
                self.lacks(
                    at,
                    "area light given by its power on a shape whose lights' areas lumen does not know (a PLY mesh, triangles of different areas)",
                    "the radiance `L` gives",
                )?;
                radiance
            }
            _ => radiance,
        };
        if self.in_definition() {
            // As pbrt: the shapes of an instanced object give no light.
            self.warnings.push((
                at,
                "an area light on a shape of an instanced object gives no light (as in pbrt)"
                    .into(),
            ));
            return Ok(base);
        }
        let key = (
            self.state.material.clone(),
            match &radiance {
                ColorDesc::Rgb(c) => format!("{:?}", c.map(f64::to_bits)),
                ColorDesc::Texture(t) => format!("texture {t}"),
            },
            two_sided,
        );
        if let Some(name) = self.emitting.get(&key) {
            return Ok(name.clone());
        }
        let mut desc = self.desc.materials[&base].clone();
        let s = desc.surface_mut();
        *s.emission = Some(radiance);
        *s.two_sided = two_sided;
        let name = self.name("light");
        self.desc.materials.insert(name.clone(), desc);
        self.emitting.insert(key, name.clone());
        Ok(name)
    }

    fn default_material(&mut self) -> String {
        if let Some(m) = &self.default_material {
            return m.clone();
        }
        let name = self.name("pbrt-default");
        self.desc.materials.insert(
            name.clone(),
            crate::scene::desc::MaterialDesc::Diffuse(crate::scene::desc::DiffuseDesc::new(
                [0.5; 3],
            )),
        );
        self.default_material = Some(name.clone());
        name
    }

    /// The scene, once every directive is read.
    pub fn finish(mut self, input: &Input) -> Result<Imported, Problem> {
        if let Some((_, at, what)) = self.stack.last() {
            return Err((*at, format!("this {what} is never closed"), None));
        }
        self.check_media()?;
        let (width, height) = self.film;
        if let Some(c) = self.camera.take() {
            let m = matrix::inverse(&c.camera_from_world).expect("checked at Camera");
            let origin = matrix::point(&m, [0.0; 3]);
            let forward = matrix::normalize(matrix::vector(&m, [0.0, 0.0, 1.0]));
            let up = matrix::normalize(matrix::vector(&m, [0.0, 1.0, 0.0]));
            let (Some(forward), Some(up)) = (forward, up) else {
                return Err((
                    super::NOWHERE,
                    "the camera's transform is singular".into(),
                    None,
                ));
            };
            // pbrt's fov spans the shorter side of the image.
            let aspect = f64::from(width) / f64::from(height);
            let half = (c.fov.to_radians() / 2.0).tan();
            let vfov = if aspect >= 1.0 {
                c.fov
            } else {
                (2.0 * (half / aspect).atan()).to_degrees()
            };
            let ortho_height = match c.orthographic {
                None => None,
                Some((at, window)) => {
                    let height = self.ortho_height(at, window)?;
                    // The window is in camera space: the frame's scale
                    // sizes it, alike across and up for square pixels.
                    let length = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
                    let x_scale = length(matrix::vector(&m, [1.0, 0.0, 0.0]));
                    let y_scale = length(matrix::vector(&m, [0.0, 1.0, 0.0]));
                    if (y_scale / x_scale - 1.0).abs() > 1e-3 {
                        return Err((
                            at,
                            format!(
                                "the camera's transform scales x by {x_scale} and y by \
                                 {y_scale}: an orthographic view must scale both alike"
                            ),
                            None,
                        ));
                    }
                    Some(height * y_scale)
                }
            };
            let (defocus_angle, focus_dist) = if c.lens_radius > 0.0 {
                (
                    (2.0 * (c.lens_radius / c.focal_distance).atan()).to_degrees(),
                    Some(c.focal_distance),
                )
            } else {
                (0.0, None)
            };
            self.desc.camera = CameraDesc {
                vfov,
                lookfrom: origin,
                lookat: [0, 1, 2].map(|i| origin[i] + forward[i]),
                vup: up,
                defocus_angle,
                focus_dist,
                // pbrt's image runs along the camera's +x: a frame that
                // does not mirror (as LookAt's) mirrors the image.
                mirror: matrix::det3(&m) > 0.0,
                medium: c.medium,
                ortho_height,
                ..CameraDesc::default()
            };
        } else {
            // pbrt's default camera sits at the origin looking down +z.
            self.desc.camera = CameraDesc {
                vfov: 90.0,
                lookfrom: [0.0; 3],
                lookat: [0.0, 0.0, 1.0],
                vup: [0.0, 1.0, 0.0],
                mirror: true,
                ..CameraDesc::default()
            };
        }
        let warnings = self
            .warnings
            .iter()
            .map(|(at, w)| format!("{}: {w}", input.place(*at)))
            .collect();
        Ok(Imported {
            desc: self.desc,
            warnings,
        })
    }
}

/// The illuminance an equal-area environment image (the file at `path`)
/// gives a surface facing its +z, as pbrt-v4 computes it to scale a map to
/// an `illuminance`: the luminance of the texels above the horizon times
/// their cosine, summed, times 2π over the number of texels (pbrt's
/// factor, which this reproduces so that a scene is as bright as pbrt
/// makes it).
fn upper_illuminance(path: &std::path::Path, at: At) -> Result<f64, Problem> {
    let image = crate::texture::Image::read(path).map_err(|e| (at, e.to_string(), None))?;
    let (w, h) = (image.width(), image.height());
    let mut sum = 0.0f64;
    for y in 0..h {
        let v = (y as f32 + 0.5) / h as f32;
        for x in 0..w {
            let u = (x as f32 + 0.5) / w as f32;
            let d = crate::light::environment::equal_area_sphere([u, v]);
            if d.z <= 0.0 {
                continue;
            }
            sum += f64::from(crate::light::luminance(image.texel(x, y)) * d.z);
        }
    }
    let illuminance = sum * 2.0 * std::f64::consts::PI / (w * h) as f64;
    if !(illuminance > 0.0) {
        return Err((
            at,
            "the map is black above its horizon: no scale gives it an illuminance".into(),
            None,
        ));
    }
    Ok(illuminance)
}
