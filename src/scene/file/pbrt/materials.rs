//! pbrt's materials and textures as lumen's: each material kind mapped
//! onto the nearest lumen kind (docs/pbrt.md says what differs), each
//! texture onto an image texture or a constant.

use super::lex::At;
use super::params::{Params, Problem, Spectral};
use super::scene::Builder;
use super::{spectra, Input};
use crate::material::dielectric::FresnelDesc;
use crate::material::roughness::DistributionDesc;
use crate::material::{ConductorDesc, MixDesc, PlasticDesc};
use crate::scene::desc::{
    ColorDesc, DielectricDesc, DiffuseDesc, EncodingDesc, FilterDesc, MaterialDesc, RoughnessDesc,
    ScalarDesc, TextureDesc, WrapDesc,
};
use crate::scene::file::matrix;

/// A texture as lumen has it.
#[derive(Clone, Debug, PartialEq)]
pub enum Tex {
    /// The same value everywhere.
    Constant([f64; 3]),
    /// A texture of the description, by name.
    Named(String),
}

impl From<Tex> for ColorDesc {
    fn from(t: Tex) -> ColorDesc {
        match t {
            Tex::Constant(c) => ColorDesc::Rgb(c),
            Tex::Named(n) => ColorDesc::Texture(n),
        }
    }
}

/// Whether image file `file` holds floating-point values (read linear),
/// by its name.
pub(super) fn float_image(file: &str) -> bool {
    let lower = file.to_ascii_lowercase();
    [".exr", ".pfm", ".hdr"].iter().any(|e| lower.ends_with(e))
}

/// The materials lumen reads.
const MATERIALS: &[&str] = &[
    "diffuse",
    "conductor",
    "dielectric",
    "thindielectric",
    "coateddiffuse",
    "coatedconductor",
    "interface",
    "mix",
];

/// The textures lumen reads.
const TEXTURES: &[&str] = &["imagemap", "constant", "scale", "checkerboard", "mix"];

/// pbrt's roughness to α: its square root when remapped.
fn alpha(r: f64, remap: bool) -> f64 {
    if remap {
        r.max(0.0).sqrt()
    } else {
        r
    }
}

impl Builder {
    /// The material of type `ty` with parameters `p`: its name in lumen's
    /// description, and whether it is an `interface`.
    pub(super) fn material(
        &mut self,
        ty: &str,
        at: At,
        p: &Params,
        input: &Input,
    ) -> Result<(String, bool), Problem> {
        p.ignore(&["type"]);
        let mut known: Vec<&str> = vec!["type", "displacement", "normalmap"];
        let mut interface = false;
        let mut desc = match ty {
            "diffuse" => {
                known.push("reflectance");
                let albedo = self.colour(p, "reflectance", 0.5)?;
                MaterialDesc::Diffuse(DiffuseDesc::new(albedo))
            }
            "conductor" => {
                known.extend([
                    "eta",
                    "k",
                    "reflectance",
                    "roughness",
                    "uroughness",
                    "vroughness",
                    "remaproughness",
                ]);
                let mut d = ConductorDesc::default();
                self.metal(p, "", at, &mut d)?;
                let (rough, distribution) = self.roughness(p, "", at)?;
                d.alpha = rough;
                d.distribution = distribution;
                MaterialDesc::Conductor(d)
            }
            "thindielectric" => {
                known.push("eta");
                let mut d = DielectricDesc::new(self.eta(p, "eta", at)?);
                d.thin = true;
                d.fresnel = Some(FresnelDesc::Exact);
                MaterialDesc::Dielectric(d)
            }
            "dielectric" => {
                known.extend([
                    "eta",
                    "roughness",
                    "uroughness",
                    "vroughness",
                    "remaproughness",
                ]);
                let eta = self.eta(p, "eta", at)?;
                let mut d = DielectricDesc::new(eta);
                let (rough, distribution) = self.roughness(p, "", at)?;
                if rough.is_none() {
                    d.fresnel = Some(FresnelDesc::Exact);
                }
                d.alpha = rough;
                d.distribution = distribution;
                MaterialDesc::Dielectric(d)
            }
            "coateddiffuse" => {
                known.extend([
                    "reflectance",
                    "roughness",
                    "uroughness",
                    "vroughness",
                    "remaproughness",
                    "eta",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                ]);
                let albedo = self.colour(p, "reflectance", 0.5)?;
                let eta = self.eta(p, "eta", at)?;
                self.clear_layer(p, at)?;
                let (rough, distribution) = self.roughness(p, "", at)?;
                let mut d = PlasticDesc::new(albedo, 0.0);
                d.roughness = None;
                d.ior = Some(eta);
                d.alpha = rough;
                d.distribution = distribution;
                MaterialDesc::Plastic(d)
            }
            "coatedconductor" => {
                known.extend([
                    "interface.roughness",
                    "interface.uroughness",
                    "interface.vroughness",
                    "interface.eta",
                    "conductor.eta",
                    "conductor.k",
                    "reflectance",
                    "conductor.roughness",
                    "conductor.uroughness",
                    "conductor.vroughness",
                    "remaproughness",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                ]);
                self.coated_conductor(p, at)?
            }
            "interface" => {
                interface = true;
                let mut d = DiffuseDesc::new([0.0; 3]);
                d.opacity = Some(ScalarDesc::Value(0.0));
                MaterialDesc::Diffuse(d)
            }
            "mix" => {
                known.extend(["materials", "amount"]);
                let names = match p.get("materials").map(|m| &m.values) {
                    Some(super::params::Values::Strs(v)) if v.len() == 2 => [&v[0], &v[1]],
                    _ => {
                        return Err((
                            at,
                            "a mix material needs \"string materials\" [ \"a\" \"b\" ]".into(),
                            None,
                        ))
                    }
                };
                let mut parts = Vec::with_capacity(2);
                for name in names {
                    match self.named_materials.get(name) {
                        None => return Err((at, format!("no material is named `{name}`"), None)),
                        Some((_, true)) => {
                            return Err((
                                at,
                                format!("`{name}` is an interface, which lumen cannot mix"),
                                None,
                            ))
                        }
                        Some((lumen, false)) => parts.push(lumen.clone()),
                    }
                }
                // pbrt takes the first material at amounts up to 0 and the
                // second from 1.
                let weight = match p.float_or_texture("amount")? {
                    None => ScalarDesc::Value(0.5),
                    Some((Ok(v), _)) => ScalarDesc::Value(v.clamp(0.0, 1.0)),
                    Some((Err(t), tat)) => ScalarDesc::Texture(self.scalar_texture(&t, tat)?),
                };
                MaterialDesc::Mix(MixDesc::new(&parts[0], &parts[1], weight))
            }
            "measured" | "hair" | "subsurface" | "diffusetransmission" => {
                p.ignore_all();
                self.lacks(at, &format!("`{ty}` material"), "a grey diffuse")?;
                MaterialDesc::Diffuse(DiffuseDesc::new([0.5; 3]))
            }
            other => {
                return Err((
                    at,
                    format!(
                        "material `{other}` is not one lumen reads; it reads {}",
                        MATERIALS.join(", ")
                    ),
                    crate::hint::closest(other, MATERIALS.iter().copied())
                        .map(|k| format!("did you mean `{k}`?")),
                ))
            }
        };
        // Every kind's: pbrt's displacement is a bump map.
        if let Some((v, vat)) = p.float_or_texture("displacement")? {
            match v {
                Ok(_) => self.lacks(vat, "constant displacement", "none")?,
                Err(t) => {
                    let name = self.scalar_texture(&t, vat)?;
                    let s = desc.surface_mut();
                    *s.bump_map = Some(name);
                }
            }
        }
        if let Some((file, fat)) = p.string_of("normalmap", "string")? {
            let file = input.file(file, fat)?;
            let name = self.name("normal-map");
            self.desc.textures.insert(
                name.clone(),
                image(file, EncodingDesc::Linear, None, [1.0, 1.0, 0.0, 0.0]),
            );
            *desc.surface_mut().normal_map = Some(name);
        }
        p.finish(&format!("a {ty} material"), &known)?;
        let name = self.name(ty);
        self.desc.materials.insert(name.clone(), desc);
        Ok((name, interface))
    }

    /// A coated conductor as lumen's principled material: a metal of the
    /// conductor's reflectance at normal incidence under a clear coat.
    fn coated_conductor(&mut self, p: &Params, at: At) -> Result<MaterialDesc, Problem> {
        let mut metal = ConductorDesc::default();
        self.metal(p, "conductor.", at, &mut metal)?;
        let (eta, k) = match &metal.metal {
            Some(m) => {
                let m = crate::material::metals::find(m).expect("checked");
                (m.eta.map(f64::from), m.k.map(f64::from))
            }
            // `metal` gives colours only (a textured index is refused).
            None => {
                let rgb = |c: &Option<ColorDesc>, default| match c {
                    Some(ColorDesc::Rgb(v)) => *v,
                    _ => default,
                };
                (rgb(&metal.eta, [1.0; 3]), rgb(&metal.k, [0.0; 3]))
            }
        };
        let f0 = [0, 1, 2].map(|i| {
            let (n, k) = (eta[i], k[i]);
            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
        });
        let coat_eta = p.float("interface.eta")?.unwrap_or(1.5);
        if coat_eta != 1.5 {
            self.lacks(
                at,
                "clear coat of an index other than 1.5",
                "a coat of index 1.5",
            )?;
        }
        self.clear_layer(p, at)?;
        let (rough, distribution) = self.roughness(p, "conductor.", at)?;
        let (coat, _) = self.roughness(p, "interface.", at)?;
        let d = crate::material::PrincipledDesc {
            base_color: Some(ColorDesc::Rgb(f0)),
            metallic: Some(ScalarDesc::Value(1.0)),
            alpha: Some(rough.unwrap_or(RoughnessDesc::Value(0.0))),
            distribution,
            clearcoat: Some(ScalarDesc::Value(1.0)),
            // glTF's clear-coat roughness is perceptual: α = roughness².
            clearcoat_roughness: Some(ScalarDesc::Value(match coat {
                Some(RoughnessDesc::Value(a)) => a.sqrt(),
                Some(RoughnessDesc::Pair([u, v])) => (u * v).sqrt().sqrt(),
                _ => 0.0,
            })),
            ..Default::default()
        };
        Ok(MaterialDesc::Principled(d))
    }

    /// A coated material's layer between coat and base: lumen's is clear
    /// and thin.
    fn clear_layer(&mut self, p: &Params, at: At) -> Result<(), Problem> {
        let albedo = p.spectral("albedo", true)?;
        if albedo.is_some_and(|(s, _)| {
            !matches!(s, Spectral::Rgb([0.0, 0.0, 0.0]) | Spectral::Grey(0.0))
        }) {
            self.lacks(
                at,
                "scattering medium between a coat and its base",
                "a clear layer",
            )?;
        }
        p.ignore(&["thickness", "g", "maxdepth", "nsamples"]);
        Ok(())
    }

    /// A conductor's index of refraction (`prefix`eta, `prefix`k) or its
    /// `reflectance`, into `d`; pbrt's default is copper.
    fn metal(
        &mut self,
        p: &Params,
        prefix: &str,
        at: At,
        d: &mut ConductorDesc,
    ) -> Result<(), Problem> {
        let eta = p.spectral(&format!("{prefix}eta"), true)?;
        let k = p.spectral(&format!("{prefix}k"), true)?;
        if let Some((r, rat)) = p.spectral("reflectance", true)? {
            if eta.is_some() || k.is_some() {
                return Err((
                    rat,
                    "give `reflectance` or `eta` and `k`, not both".into(),
                    None,
                ));
            }
            let r = match r {
                Spectral::Rgb(c) => c,
                Spectral::Grey(v) => [v; 3],
                Spectral::Samples(v) => {
                    spectra::reflectance_samples(&v).map_err(|m| (rat, m, None))?
                }
                _ => {
                    self.lacks(
                        rat,
                        "textured or named conductor reflectance",
                        "a reflectance of 0.8",
                    )?;
                    [0.8; 3]
                }
            };
            // pbrt's metal of that reflectance at normal incidence.
            d.eta = Some(ColorDesc::Rgb([1.0; 3]));
            d.k = Some(ColorDesc::Rgb(r.map(|r| {
                let r = r.clamp(0.0, 0.9999);
                2.0 * r.sqrt() / (1.0 - r).sqrt()
            })));
            return Ok(());
        }
        let part = |cx: &mut Builder,
                    s: Option<(Spectral, At)>,
                    want_k: bool|
         -> Result<Result<[f64; 3], Option<&'static str>>, Problem> {
            Ok(match s {
                None => Err(None),
                Some((Spectral::Named(n), nat)) => {
                    let (metal, is_k) = spectra::metal(&n).map_err(|m| (nat, m, None))?;
                    if is_k != want_k {
                        return Err((
                            nat,
                            format!("`{n}` is the other part of a metal's index"),
                            None,
                        ));
                    }
                    Err(Some(metal))
                }
                Some((Spectral::Rgb(c), _)) => Ok(c),
                Some((Spectral::Grey(v), _)) => Ok([v; 3]),
                Some((Spectral::Samples(v), sat)) => {
                    let (w, x): (Vec<f64>, Vec<f64>) =
                        v.chunks_exact(2).map(|p| (p[0], p[1])).unzip();
                    if w.windows(2).any(|p| p[1] <= p[0]) {
                        return Err((sat, "a spectrum's wavelengths must increase".into(), None));
                    }
                    Ok(crate::scene::file::mitsuba::spectrum::list_to_srgb(
                        &w, &x, false, true,
                    ))
                }
                Some((_, sat)) => {
                    cx.lacks(sat, "textured or blackbody index of refraction", "copper's")?;
                    Err(Some("Cu"))
                }
            })
        };
        let eta = part(self, eta, false)?;
        let k = part(self, k, true)?;
        match (eta, k) {
            (Err(a), Err(b)) => {
                let (a, b) = (a.unwrap_or("Cu"), b.unwrap_or("Cu"));
                if a != b {
                    return Err((at, format!("`eta` is metal-{a}'s and `k` metal-{b}'s: lumen's conductors pair them"), None));
                }
                d.metal = Some(a.to_string());
            }
            (eta, k) => {
                let named = |r: Result<[f64; 3], Option<&str>>, k: bool| match r {
                    Ok(c) => c,
                    Err(m) => {
                        let m =
                            crate::material::metals::find(m.unwrap_or("Cu")).expect("in the table");
                        (if k { m.k } else { m.eta }).map(f64::from)
                    }
                };
                d.eta = Some(ColorDesc::Rgb(named(eta, false)));
                d.k = Some(ColorDesc::Rgb(named(k, true)));
            }
        }
        Ok(())
    }

    /// A dielectric's index of refraction `name`: a number or a named glass.
    fn eta(&mut self, p: &Params, name: &str, at: At) -> Result<f64, Problem> {
        let eta = match p.spectral(name, false)? {
            None => 1.5,
            Some((Spectral::Grey(v), _)) => v,
            Some((Spectral::Named(n), nat)) => spectra::glass(&n).ok_or_else(|| {
                (
                    nat,
                    format!(
                        "`{n}` is not a glass lumen knows; it knows {}",
                        spectra::glass_names().join(", ")
                    ),
                    crate::hint::closest(&n, spectra::glass_names())
                        .map(|k| format!("did you mean `{k}`?")),
                )
            })?,
            Some((Spectral::Samples(v), sat)) => {
                // Its index at 550 nm.
                let pairs: Vec<(f64, f64)> = v.chunks_exact(2).map(|p| (p[0], p[1])).collect();
                let i = pairs.partition_point(|(w, _)| *w < 550.0);
                match (pairs.get(i.wrapping_sub(1)), pairs.get(i)) {
                    (Some(a), Some(b)) if b.0 > a.0 => {
                        a.1 + (b.1 - a.1) * (550.0 - a.0) / (b.0 - a.0)
                    }
                    (_, Some(b)) => b.1,
                    (Some(a), None) => a.1,
                    _ => return Err((sat, "an empty spectrum".into(), None)),
                }
            }
            Some((_, sat)) => {
                return Err((
                    sat,
                    format!("`{name}` must be a number or a named glass"),
                    None,
                ))
            }
        };
        if !(eta > 0.0) {
            return Err((at, format!("`{name}` must be above 0, got {eta}"), None));
        }
        Ok(eta)
    }

    /// The microfacets of `prefix`roughness (or its u and v parts) as α
    /// for GGX; none when smooth.
    fn roughness(
        &mut self,
        p: &Params,
        prefix: &str,
        at: At,
    ) -> Result<(Option<RoughnessDesc>, Option<DistributionDesc>), Problem> {
        let remap = p.boolean("remaproughness")?.unwrap_or(true);
        let one = p.float_or_texture(&format!("{prefix}roughness"))?;
        let u = p.float_or_texture(&format!("{prefix}uroughness"))?;
        let v = p.float_or_texture(&format!("{prefix}vroughness"))?;
        let value = |x: Option<(Result<f64, String>, At)>| x.map(|(v, _)| v);
        let (one, u, v) = (value(one), value(u), value(v));
        let u = u.or_else(|| one.clone()).unwrap_or(Ok(0.0));
        let v = v.or(one).unwrap_or(Ok(0.0));
        let rough = match (u, v) {
            (Ok(u), Ok(v)) => {
                let (au, av) = (alpha(u, remap), alpha(v, remap));
                // pbrt treats α below 1e-3 as perfectly smooth.
                if au.max(av) < 1e-3 {
                    return Ok((None, None));
                }
                if au == av {
                    RoughnessDesc::Value(au)
                } else {
                    RoughnessDesc::Pair([au, av])
                }
            }
            (u, v) => {
                if remap {
                    self.lacks(
                        at,
                        "remapped roughness texture (α = √texture)",
                        "the texture read as α",
                    )?;
                }
                let mut each = |x: Result<f64, String>| -> Result<ScalarDesc, Problem> {
                    Ok(match x {
                        Ok(x) => ScalarDesc::Value(alpha(x, remap)),
                        Err(t) => ScalarDesc::Texture(self.scalar_texture(&t, at)?),
                    })
                };
                match (each(u)?, each(v)?) {
                    (ScalarDesc::Texture(t), ScalarDesc::Texture(t2)) if t == t2 => {
                        RoughnessDesc::Texture(t)
                    }
                    (u, v) => RoughnessDesc::Each([u, v]),
                }
            }
        };
        Ok((Some(rough), Some(DistributionDesc::Ggx)))
    }

    /// A colour parameter: a value, a spectrum, or a texture (`default`
    /// grey when absent).
    fn colour(&mut self, p: &Params, name: &str, default: f64) -> Result<ColorDesc, Problem> {
        Ok(match p.spectral(name, true)? {
            None => ColorDesc::Rgb([default; 3]),
            Some((Spectral::Rgb(c), _)) => ColorDesc::Rgb(c),
            Some((Spectral::Grey(v), _)) => ColorDesc::Rgb([v; 3]),
            Some((Spectral::Samples(v), sat)) => {
                ColorDesc::Rgb(spectra::reflectance_samples(&v).map_err(|m| (sat, m, None))?)
            }
            Some((Spectral::Texture(t), tat)) => self.texture_of(&t, false, tat)?.into(),
            Some((_, sat)) => {
                return Err((sat, format!("`{name}` must be a colour or a texture"), None))
            }
        })
    }

    fn texture_of(&self, name: &str, float: bool, at: At) -> Result<Tex, Problem> {
        self.textures
            .get(&(name.to_string(), float))
            .cloned()
            .ok_or_else(|| {
                let known: Vec<&str> = self
                    .textures
                    .keys()
                    .filter(|(_, f)| *f == float)
                    .map(|(n, _)| n.as_str())
                    .collect();
                (
                    at,
                    format!(
                        "no {} texture is named `{name}`",
                        if float { "float" } else { "spectrum" }
                    ),
                    crate::hint::closest(name, known.iter().copied())
                        .map(|k| format!("did you mean `{k}`?")),
                )
            })
    }

    /// The lumen texture of float texture `name`; a constant one becomes
    /// an image-free texture lumen cannot have, so it is refused.
    fn scalar_texture(&mut self, name: &str, at: At) -> Result<String, Problem> {
        match self.texture_of(name, true, at)? {
            Tex::Named(n) => Ok(n),
            Tex::Constant(_) => Err((
                at,
                format!("float texture `{name}` is a constant where lumen needs an image"),
                None,
            )),
        }
    }

    /// `Texture "name" "class" "type" params`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn texture(
        &mut self,
        name: &str,
        class: &str,
        cat: At,
        ty: &str,
        at: At,
        p: &Params,
        input: &Input,
    ) -> Result<(), Problem> {
        let float = match class {
            "float" => true,
            "spectrum" | "color" => false,
            other => {
                return Err((
                    cat,
                    format!("texture class `{other}`: expected \"float\" or \"spectrum\""),
                    None,
                ))
            }
        };
        let mapping = |p: &Params| -> Result<[f64; 4], Problem> {
            if p.string("mapping")?.is_some_and(|m| m != "uv") {
                return Err((at, "lumen maps textures by (u, v) only".into(), None));
            }
            Ok([
                p.float("uscale")?.unwrap_or(1.0),
                p.float("vscale")?.unwrap_or(1.0),
                p.float("udelta")?.unwrap_or(0.0),
                p.float("vdelta")?.unwrap_or(0.0),
            ])
        };
        let value = |cx: &mut Builder, n: &str, default: f64| -> Result<Tex, Problem> {
            if float {
                return Ok(match p.float_or_texture(n)? {
                    None => Tex::Constant([default; 3]),
                    Some((Ok(v), _)) => Tex::Constant([v; 3]),
                    Some((Err(t), tat)) => cx.texture_of(&t, true, tat)?,
                });
            }
            Ok(match p.spectral(n, true)? {
                None => Tex::Constant([default; 3]),
                Some((Spectral::Texture(t), tat)) => cx.texture_of(&t, false, tat)?,
                Some(_) => match cx.colour(p, n, default)? {
                    ColorDesc::Rgb(c) => Tex::Constant(c),
                    ColorDesc::Texture(t) => Tex::Named(t),
                },
            })
        };
        let tex = match ty {
            "imagemap" => {
                let (file, fat) = p.string_of("filename", "string")?.ok_or((
                    at,
                    "an imagemap needs a `filename`".into(),
                    None,
                ))?;
                let file = input.file(file, fat)?;
                let encoding = match p.string("encoding")? {
                    _ if float_image(&file) => EncodingDesc::Linear,
                    None | Some("sRGB") => EncodingDesc::Srgb,
                    Some("linear") => EncodingDesc::Linear,
                    Some(other) => {
                        self.lacks(at, &format!("image encoding `{other}`"), "sRGB")?;
                        EncodingDesc::Srgb
                    }
                };
                let scale = p.float("scale")?.unwrap_or(1.0);
                if !(scale >= 0.0) {
                    return Err((at, format!("`scale` must be ≥ 0, got {scale}"), None));
                }
                if p.boolean("invert")? == Some(true) {
                    self.lacks(at, "inverted image texture", "the image as it is")?;
                }
                let wrap = match p.string("wrap")?.unwrap_or("repeat") {
                    "repeat" => WrapDesc::Repeat,
                    "clamp" => WrapDesc::Clamp,
                    other => {
                        self.lacks(at, &format!("wrap mode `{other}`"), "repeat")?;
                        WrapDesc::Repeat
                    }
                };
                let filter = match p.string("filter")?.unwrap_or("bilinear") {
                    "point" => FilterDesc::Nearest,
                    _ => FilterDesc::Bilinear,
                };
                p.ignore(&["maxanisotropy"]);
                let m = mapping(p)?;
                p.finish(
                    "an imagemap texture",
                    &[
                        "filename",
                        "encoding",
                        "scale",
                        "invert",
                        "wrap",
                        "filter",
                        "maxanisotropy",
                        "mapping",
                        "uscale",
                        "vscale",
                        "udelta",
                        "vdelta",
                    ],
                )?;
                let mut desc = image(
                    file,
                    encoding,
                    float.then_some(crate::scene::desc::ChannelDesc::R),
                    m,
                );
                if let TextureDesc::Image {
                    wrap: w, filter: f, ..
                } = &mut desc
                {
                    *w = Some(wrap);
                    *f = Some(filter);
                }
                let lumen = self.name(if float { "float-texture" } else { "texture" });
                self.desc.textures.insert(lumen.clone(), desc);
                if scale == 1.0 {
                    Tex::Named(lumen)
                } else {
                    self.scaled(lumen, [scale; 3])
                }
            }
            "constant" => {
                let v = value(self, "value", 1.0)?;
                p.finish("a constant texture", &["value"])?;
                v
            }
            "scale" => {
                let t = value(self, "tex", 1.0)?;
                let s = if float {
                    value(self, "scale", 1.0)?
                } else {
                    match p.float_or_texture("scale")? {
                        None => Tex::Constant([1.0; 3]),
                        Some((Ok(v), _)) => Tex::Constant([v; 3]),
                        Some((Err(t), tat)) => self.texture_of(&t, true, tat)?,
                    }
                };
                p.finish("a scale texture", &["tex", "scale"])?;
                match (t, s) {
                    (Tex::Constant(a), Tex::Constant(b)) => {
                        Tex::Constant([0, 1, 2].map(|i| a[i] * b[i]))
                    }
                    (t, Tex::Constant([1.0, 1.0, 1.0])) | (Tex::Constant([1.0, 1.0, 1.0]), t) => t,
                    (Tex::Named(t), Tex::Constant(c)) | (Tex::Constant(c), Tex::Named(t)) => {
                        self.scaled(t, c)
                    }
                    // s·t as a blend from black to t by s (which lumen does
                    // not clamp).
                    (t, Tex::Named(s)) => {
                        let lumen = self.name("product");
                        self.desc.textures.insert(
                            lumen.clone(),
                            TextureDesc::Mix {
                                first: ColorDesc::Rgb([0.0; 3]),
                                second: t.into(),
                                amount: ScalarDesc::Texture(s),
                            },
                        );
                        Tex::Named(lumen)
                    }
                }
            }
            // A float checkerboard is a checkerboard of greys: lumen's
            // scalar checkerboard.
            "checkerboard" if p.int("dimension")?.unwrap_or(2) == 2 => {
                let even = value(self, "tex1", 1.0)?.into();
                let odd = value(self, "tex2", 0.0)?.into();
                let [su, sv, du, dv] = mapping(p)?;
                p.finish(
                    "a checkerboard texture",
                    &[
                        "tex1",
                        "tex2",
                        "dimension",
                        "mapping",
                        "uscale",
                        "vscale",
                        "udelta",
                        "vdelta",
                    ],
                )?;
                let lumen = self.name("checkerboard");
                self.desc.textures.insert(
                    lumen.clone(),
                    TextureDesc::Checkerboard {
                        even,
                        odd,
                        uv_scale: Some([su, sv]),
                        uv_offset: Some([du, dv]),
                    },
                );
                Tex::Named(lumen)
            }
            "mix" => {
                let first = value(self, "tex1", 0.0)?;
                let second = value(self, "tex2", 1.0)?;
                let amount = match p.float_or_texture("amount")? {
                    None => ScalarDesc::Value(0.5),
                    Some((Ok(v), vat)) if !(0.0..=1.0).contains(&v) => {
                        return Err((
                            vat,
                            format!("`amount` must be within [0, 1], got {v}"),
                            None,
                        ))
                    }
                    Some((Ok(v), _)) => ScalarDesc::Value(v),
                    Some((Err(t), tat)) => ScalarDesc::Texture(self.scalar_texture(&t, tat)?),
                };
                p.finish("a mix texture", &["tex1", "tex2", "amount"])?;
                match (first, second, amount) {
                    (Tex::Constant(a), Tex::Constant(b), ScalarDesc::Value(t)) => {
                        Tex::Constant([0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t))
                    }
                    (first, second, amount) => {
                        let lumen = self.name("mix");
                        self.desc.textures.insert(
                            lumen.clone(),
                            TextureDesc::Mix {
                                first: first.into(),
                                second: second.into(),
                                amount,
                            },
                        );
                        Tex::Named(lumen)
                    }
                }
            }
            // In three dimensions: cubes of side 1 in the space the
            // transform of the texture's definition places, which lumen's
            // checker draws in the world, scaled.
            "checkerboard" if p.int("dimension")? == Some(3) => {
                let even = value(self, "tex1", 1.0)?.into();
                let odd = value(self, "tex2", 0.0)?.into();
                p.finish("a checkerboard texture", &["tex1", "tex2", "dimension"])?;
                let side = match uniform_scale(&self.state.ctm) {
                    Some(side) => side,
                    None => {
                        self.lacks(
                            at,
                            "three-dimensional `checkerboard` placed by a transform that moves or turns it",
                            "its cubes in the world, of the transform's size",
                        )?;
                        let side = matrix::det3(&self.state.ctm).abs().cbrt();
                        if side.is_normal() {
                            side
                        } else {
                            1.0
                        }
                    }
                };
                let lumen = self.name("checker");
                self.desc.textures.insert(
                    lumen.clone(),
                    TextureDesc::Checker {
                        scale: side,
                        even,
                        odd,
                    },
                );
                Tex::Named(lumen)
            }
            "checkerboard" => {
                let d = p.int("dimension")?.unwrap_or(2);
                return Err((
                    at,
                    format!("a checkerboard's `dimension` is 2 or 3, got {d}"),
                    None,
                ));
            }
            other => {
                p.ignore_all();
                if [
                    "bilerp",
                    "directionmix",
                    "dots",
                    "fbm",
                    "wrinkled",
                    "windy",
                    "marble",
                    "ptex",
                ]
                .contains(&other)
                {
                    self.lacks(at, &format!("`{other}` texture"), "grey 0.5")?;
                    Tex::Constant([0.5; 3])
                } else {
                    return Err((
                        at,
                        format!(
                            "texture `{other}` is not one lumen reads; it reads {}",
                            TEXTURES.join(", ")
                        ),
                        crate::hint::closest(other, TEXTURES.iter().copied())
                            .map(|k| format!("did you mean `{k}`?")),
                    ));
                }
            }
        };
        self.textures.insert((name.to_string(), float), tex);
        Ok(())
    }

    /// Texture `t` times `factor`, as a texture of its own.
    pub(super) fn scaled(&mut self, t: String, factor: [f64; 3]) -> Tex {
        let name = self.name("scaled");
        self.desc.textures.insert(
            name.clone(),
            TextureDesc::Scale {
                texture: ColorDesc::Texture(t),
                factor,
            },
        );
        Tex::Named(name)
    }

    /// A shape's material (the current one, shining with the current area
    /// light, each of whose lights has `area`; see `shape_material`), cut
    /// by its `alpha`.
    pub(super) fn surface(
        &mut self,
        p: &Params,
        at: At,
        area: Option<f64>,
    ) -> Result<String, Problem> {
        let material = self.shape_material(at, area)?;
        let material = self.in_media(material);
        let Some((a, aat)) = p.float_or_texture("alpha")? else {
            return Ok(material);
        };
        let opacity = match a {
            Ok(v) if v >= 1.0 => return Ok(material),
            Ok(v) => ScalarDesc::Value(v.max(0.0)),
            Err(t) => ScalarDesc::Texture(self.scalar_texture(&t, aat)?),
        };
        let mut desc = self.desc.materials[&material].clone();
        *desc.surface_mut().opacity = Some(opacity);
        let name = self.name("cut");
        self.desc.materials.insert(name.clone(), desc);
        Ok(name)
    }
}

/// An image texture of `file` with pbrt's (u, v) mapping `[uscale, vscale,
/// udelta, vdelta]`. pbrt's t runs up the image, as lumen's v; lumen's
/// transform works on v down the image, where pbrt's t = vscale·v + vdelta
/// reads 1 − t.
pub(super) fn image(
    file: String,
    encoding: EncodingDesc,
    channel: Option<crate::scene::desc::ChannelDesc>,
    [su, sv, du, dv]: [f64; 4],
) -> TextureDesc {
    let identity = [su, sv, du, dv] == [1.0, 1.0, 0.0, 0.0];
    TextureDesc::Image {
        file,
        channel,
        encoding: Some(encoding),
        wrap: None,
        filter: None,
        uv_set: None,
        uv_offset: (!identity).then_some([du, 1.0 - sv - dv]),
        uv_rotation: None,
        uv_scale: (!identity).then_some([su, sv]),
    }
}

/// The factor s of a transform that is s times the identity (no turn, no
/// move), if it is one.
fn uniform_scale(m: &matrix::Mat4) -> Option<f64> {
    let s = m[0][0];
    let uniform = (0..3).all(|r| (0..4).all(|c| m[r][c] == if r == c { s } else { 0.0 }));
    (uniform && s > 0.0 && s.is_finite()).then_some(s)
}
