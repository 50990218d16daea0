//! glTF materials, textures and images, read from the file's JSON as the
//! specification and its KHR extensions define them: every core material
//! parameter and texture (`occlusionTexture` aside: a path tracer computes
//! occlusion), each texture's sampler (wrap modes, nearest or linear) and
//! coordinate set, `KHR_texture_transform`, and the material extensions
//! `KHR_materials_ior`, `_specular`, `_transmission`, `_volume`,
//! `_clearcoat`, `_sheen` and `_emissive_strength`.
//!
//! Each image is decoded once, in parallel with the others, however many
//! materials use it; only PNG and JPEG images are read.

use super::super::material::{AlphaMode, Mapped};
use super::super::{MeshError, MeshMaterial, DEFAULT_IOR};
use crate::material::param::MAX_LAYER_IOR;
use crate::texture::{Channels, Filter, Image, ImageMap, UvTransform, Wrap};
use rayon::prelude::*;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;

/// The material extensions lumen renders (each as the extension defines
/// it), and the texture extension.
pub(super) const SUPPORTED: &[&str] = &[
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];

/// Extensions that change nothing lumen renders, accepted without a word.
pub(super) const HARMLESS: &[&str] = &["KHR_xmp", "KHR_xmp_json_ld", "KHR_materials_variants"];

/// A texture reference read from a material: the texture, its channel and
/// encoding, and how it is mapped.
struct TextureRef {
    texture: usize,
    uv_set: u8,
    transform: UvTransform,
}

/// Reads material `i` of `json`, its textures resolved against the decoded
/// `images`; `warn` collects what lumen reads but does not render.
fn material(
    json: &Value,
    i: usize,
    images: &[Option<Arc<Image>>],
    warn: &mut dyn FnMut(String),
) -> Result<MeshMaterial, String> {
    let m = &json["materials"][i];
    let name = m["name"]
        .as_str()
        .map_or_else(|| format!("material {i}"), str::to_string);
    let at = |what: &str| format!("material {i} ({name}): {what}");
    let mut out = MeshMaterial {
        name: name.clone(),
        vertex_color: true,
        // glTF's own defaults, where the file's material says nothing.
        base_color: Mapped::value([1.0; 3]),
        metallic: Mapped::value(1.0),
        roughness: Mapped::value(1.0),
        ..MeshMaterial::default()
    };
    // A map of texture info `info` (one field of the material JSON).
    let map = |info: &Value,
               field: &str,
               channels: Channels,
               srgb: bool|
     -> Result<Option<ImageMap>, String> {
        if info.is_null() {
            return Ok(None);
        }
        let r = texture_ref(info).map_err(|e| at(&format!("{field}: {e}")))?;
        let image = image_of(json, r.texture, images).map_err(|e| at(&format!("{field}: {e}")))?;
        let (wrap, filter) =
            sampler_of(json, r.texture).map_err(|e| at(&format!("{field}: {e}")))?;
        Ok(Some(ImageMap {
            image,
            srgb,
            channels,
            wrap,
            filter,
            transform: r.transform,
            uv_set: r.uv_set,
        }))
    };
    // A factor of `obj` within [0, hi] and its texture, one channel of the
    // image, read as it is.
    let scalar = |obj: &Value,
                  factor: &str,
                  default: f32,
                  hi: f32,
                  texture: &str,
                  channel: u8|
     -> Result<Mapped<f32>, String> {
        Ok(Mapped {
            value: number(&obj[factor], default, 0.0, hi)
                .map_err(|e| at(&format!("{factor} {e}")))?,
            map: map(&obj[texture], texture, Channels::One(channel), false)?,
        })
    };
    // A colour factor of `obj` within [0, hi] and its sRGB texture.
    let color = |obj: &Value,
                 factor: &str,
                 default: [f32; 3],
                 hi: f32,
                 texture: &str|
     -> Result<Mapped<[f32; 3]>, String> {
        Ok(Mapped {
            value: numbers::<3>(&obj[factor], default, 0.0, hi)
                .map_err(|e| at(&format!("{factor} {e}")))?,
            map: map(&obj[texture], texture, Channels::Rgb, true)?,
        })
    };
    // A normal texture of `obj` and its scale.
    let normal = |obj: &Value, texture: &str| -> Result<Option<(ImageMap, f32)>, String> {
        let info = &obj[texture];
        let Some(n) = map(info, texture, Channels::Rgb, false)? else {
            return Ok(None);
        };
        let scale = number(&info["scale"], 1.0, f32::MIN, f32::MAX)
            .map_err(|e| at(&format!("{texture}.scale {e}")))?;
        Ok(Some((n, scale)))
    };
    let pbr = &m["pbrMetallicRoughness"];
    let base = numbers::<4>(&pbr["baseColorFactor"], [1.0; 4], 0.0, 1.0)
        .map_err(|e| at(&format!("baseColorFactor {e}")))?;
    let base_map = &pbr["baseColorTexture"];
    out.base_color = Mapped {
        value: [base[0], base[1], base[2]],
        map: map(base_map, "baseColorTexture", Channels::Rgb, true)?,
    };
    out.alpha = Mapped {
        value: base[3],
        map: map(base_map, "baseColorTexture", Channels::One(3), false)?,
    };
    out.metallic = scalar(
        pbr,
        "metallicFactor",
        1.0,
        1.0,
        "metallicRoughnessTexture",
        2,
    )?;
    out.roughness = scalar(
        pbr,
        "roughnessFactor",
        1.0,
        1.0,
        "metallicRoughnessTexture",
        1,
    )?;
    out.normal_map = normal(m, "normalTexture")?;
    if let Some(problem) = out
        .normal_map
        .as_ref()
        .and_then(|(n, _)| n.image.normal_map_problem())
    {
        return Err(at(&format!("normalTexture: its image {problem}")));
    }
    let ext = &m["extensions"];
    let strength = number(
        &ext["KHR_materials_emissive_strength"]["emissiveStrength"],
        1.0,
        0.0,
        f32::MAX,
    )
    .map_err(|e| at(&format!("emissiveStrength {e}")))?;
    out.emission = color(m, "emissiveFactor", [0.0; 3], f32::MAX, "emissiveTexture")?;
    out.emission.value = out.emission.value.map(|e| e * strength);
    out.alpha_mode = match m["alphaMode"].as_str().unwrap_or("OPAQUE") {
        "OPAQUE" => AlphaMode::Opaque,
        "MASK" => AlphaMode::Mask(
            number(&m["alphaCutoff"], 0.5, 0.0, f32::MAX)
                .map_err(|e| at(&format!("alphaCutoff {e}")))?,
        ),
        "BLEND" => AlphaMode::Blend,
        other => {
            return Err(at(&format!(
                "unknown alphaMode \"{other}\" (OPAQUE, MASK or BLEND)"
            )))
        }
    };
    out.double_sided = m["doubleSided"].as_bool().unwrap_or(false);
    let ior = &ext["KHR_materials_ior"];
    out.ior = number(&ior["ior"], DEFAULT_IOR, 0.0, MAX_LAYER_IOR as f32)
        .map_err(|e| at(&format!("ior {e}")))?;
    if out.ior != 0.0 && out.ior < 1.0 {
        return Err(at(&format!("ior must be 0 or at least 1, got {}", out.ior)));
    }
    if out.ior == 0.0 {
        // The extension's "Fresnel 1" mode: a mirror-like dielectric; the
        // nearest lumen has is a very high index.
        warn(at(&format!(
            "KHR_materials_ior with ior 0 is read as ior {MAX_LAYER_IOR}"
        )));
        out.ior = MAX_LAYER_IOR as f32;
    }
    let s = &ext["KHR_materials_specular"];
    out.specular = scalar(s, "specularFactor", 1.0, 1.0, "specularTexture", 3)?;
    out.specular_color = color(
        s,
        "specularColorFactor",
        [1.0; 3],
        f32::MAX,
        "specularColorTexture",
    )?;
    let t = &ext["KHR_materials_transmission"];
    out.transmission = scalar(t, "transmissionFactor", 0.0, 1.0, "transmissionTexture", 0)?;
    let v = &ext["KHR_materials_volume"];
    out.thickness = scalar(v, "thicknessFactor", 0.0, f32::MAX, "thicknessTexture", 1)?;
    out.attenuation_color = numbers::<3>(&v["attenuationColor"], [1.0; 3], 0.0, 1.0)
        .map_err(|e| at(&format!("attenuationColor {e}")))?;
    out.attenuation_distance = number(&v["attenuationDistance"], f32::INFINITY, 0.0, f32::INFINITY)
        .map_err(|e| at(&format!("attenuationDistance {e}")))?;
    let c = &ext["KHR_materials_clearcoat"];
    out.clearcoat = scalar(c, "clearcoatFactor", 0.0, 1.0, "clearcoatTexture", 0)?;
    out.clearcoat_roughness = scalar(
        c,
        "clearcoatRoughnessFactor",
        0.0,
        1.0,
        "clearcoatRoughnessTexture",
        1,
    )?;
    out.clearcoat_normal_map = normal(c, "clearcoatNormalTexture")?;
    let sh = &ext["KHR_materials_sheen"];
    out.sheen_color = color(sh, "sheenColorFactor", [0.0; 3], 1.0, "sheenColorTexture")?;
    out.sheen_roughness = scalar(
        sh,
        "sheenRoughnessFactor",
        0.0,
        1.0,
        "sheenRoughnessTexture",
        3,
    )?;
    if let Some(exts) = ext.as_object() {
        for name in exts.keys() {
            if !SUPPORTED.contains(&name.as_str()) && !HARMLESS.contains(&name.as_str()) {
                warn(at(&format!("extension {name} is not rendered")));
            }
        }
    }
    Ok(out)
}

/// Every material of the file, their images decoded once each (in
/// parallel); `view_bytes` gives a buffer view's bytes, `dir` the folder
/// image files are read from.
pub(super) fn materials<'b>(
    path: &Path,
    json: &Value,
    view_bytes: &(dyn Fn(usize) -> Option<&'b [u8]> + Sync),
    read_uri: &(dyn Fn(&str) -> Result<Vec<u8>, String> + Sync),
    warnings: &mut Vec<String>,
) -> Result<Vec<MeshMaterial>, MeshError> {
    let err = |m: String| MeshError::new(path, None, m);
    let n = json["materials"].as_array().map_or(0, Vec::len);
    // The images the materials use (through their textures).
    let mut used = BTreeSet::new();
    for i in 0..n {
        let mut found = Vec::new();
        texture_indices(&json["materials"][i], &mut found);
        for t in found {
            let source = json["textures"][t]["source"].as_u64();
            let source = source.ok_or_else(|| {
                err(format!(
                    "material {i}: texture {t} {}",
                    if json["textures"][t].is_null() {
                        "does not exist"
                    } else {
                        "has no image (`source`), or one only an extension lumen lacks can read"
                    }
                ))
            })?;
            used.insert(source as usize);
        }
    }
    let count = json["images"].as_array().map_or(0, Vec::len);
    if let Some(&bad) = used.iter().find(|&&i| i >= count) {
        return Err(err(format!(
            "image {bad} does not exist (the file has {count})"
        )));
    }
    let decoded: Vec<(usize, Result<Image, String>)> = used
        .into_par_iter()
        .map(|i| (i, decode_image(json, i, view_bytes, read_uri, path)))
        .collect();
    let mut images: Vec<Option<Arc<Image>>> = vec![None; count];
    for (i, image) in decoded {
        images[i] = Some(Arc::new(image.map_err(|e| err(format!("image {i}: {e}")))?));
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut warn = |w: String| warnings.push(w);
        out.push(material(json, i, &images, &mut warn).map_err(err)?);
    }
    Ok(out)
}

/// The indices of every texture a material names.
fn texture_indices(v: &Value, out: &mut Vec<usize>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                if k.ends_with("Texture") {
                    if let Some(t) = x["index"].as_u64() {
                        out.push(t as usize);
                    }
                }
                texture_indices(x, out);
            }
        }
        Value::Array(a) => a.iter().for_each(|x| texture_indices(x, out)),
        _ => {}
    }
}

/// The bytes of image `i` decoded: from its buffer view or its URI; PNG
/// and JPEG only.
fn decode_image<'b>(
    json: &Value,
    i: usize,
    view_bytes: &(dyn Fn(usize) -> Option<&'b [u8]> + Sync),
    read_uri: &(dyn Fn(&str) -> Result<Vec<u8>, String> + Sync),
    path: &Path,
) -> Result<Image, String> {
    let image = &json["images"][i];
    let owned;
    let bytes: &[u8] = if let Some(view) = image["bufferView"].as_u64() {
        view_bytes(view as usize).ok_or_else(|| {
            format!("buffer view {view} does not exist or lies outside its buffer")
        })?
    } else if let Some(uri) = image["uri"].as_str() {
        owned = read_uri(uri)?;
        &owned
    } else {
        return Err("has neither a `uri` nor a `bufferView`".to_string());
    };
    let png = bytes.starts_with(b"\x89PNG\r\n\x1a\n");
    let jpeg = bytes.starts_with(&[0xff, 0xd8, 0xff]);
    if !(png || jpeg) {
        let mime = image["mimeType"].as_str().unwrap_or("unknown");
        return Err(format!(
            "is not a PNG or JPEG image (mimeType {mime}); lumen reads glTF images of those two formats"
        ));
    }
    let shown = format!("{} image {i}", path.display());
    Image::decode(bytes, &shown).map_err(|e| e.to_string())
}

/// The decoded image of texture `t`.
fn image_of(json: &Value, t: usize, images: &[Option<Arc<Image>>]) -> Result<Arc<Image>, String> {
    let source = json["textures"][t]["source"]
        .as_u64()
        .ok_or_else(|| format!("texture {t} has no image"))? as usize;
    images
        .get(source)
        .cloned()
        .flatten()
        .ok_or_else(|| format!("image {source} was not read"))
}

/// The wrap modes and filter of texture `t`'s sampler (repeat and linear
/// without one).
fn sampler_of(json: &Value, t: usize) -> Result<([Wrap; 2], Filter), String> {
    let Some(s) = json["textures"][t]["sampler"].as_u64() else {
        return Ok(([Wrap::Repeat; 2], Filter::Bilinear));
    };
    let sampler = &json["samplers"][s as usize];
    if sampler.is_null() {
        return Err(format!("texture {t}: sampler {s} does not exist"));
    }
    let wrap = |field: &str| match sampler[field].as_u64() {
        None | Some(10497) => Ok(Wrap::Repeat),
        Some(33071) => Ok(Wrap::Clamp),
        Some(33648) => Ok(Wrap::Mirror),
        Some(other) => Err(format!("sampler {s}: unknown {field} {other}")),
    };
    let filter = match sampler["magFilter"].as_u64() {
        Some(9728) => Filter::Nearest,
        _ => Filter::Bilinear,
    };
    Ok(([wrap("wrapS")?, wrap("wrapT")?], filter))
}

/// A texture info: its texture, coordinate set and transform.
fn texture_ref(info: &Value) -> Result<TextureRef, String> {
    let texture = info["index"].as_u64().ok_or("has no texture `index`")? as usize;
    let mut uv_set = info["texCoord"].as_u64().unwrap_or(0);
    let mut transform = UvTransform::IDENTITY;
    let t = &info["extensions"]["KHR_texture_transform"];
    if !t.is_null() {
        let offset = numbers::<2>(&t["offset"], [0.0; 2], f32::MIN, f32::MAX)
            .map_err(|e| format!("KHR_texture_transform offset {e}"))?;
        let rotation = number(&t["rotation"], 0.0, f32::MIN, f32::MAX)
            .map_err(|e| format!("KHR_texture_transform rotation {e}"))?;
        let scale = numbers::<2>(&t["scale"], [1.0; 2], f32::MIN, f32::MAX)
            .map_err(|e| format!("KHR_texture_transform scale {e}"))?;
        transform = UvTransform::offset_rotation_scale(offset, rotation, scale);
        if let Some(set) = t["texCoord"].as_u64() {
            uv_set = set;
        }
    }
    if uv_set > 1 {
        return Err(format!(
            "uses TEXCOORD_{uv_set}; lumen reads the first two sets of texture coordinates"
        ));
    }
    Ok(TextureRef {
        texture,
        uv_set: uv_set as u8,
        transform,
    })
}

/// A number of the JSON within [lo, hi], `default` where absent.
fn number(v: &Value, default: f32, lo: f32, hi: f32) -> Result<f32, String> {
    if v.is_null() {
        return Ok(default);
    }
    let x = v
        .as_f64()
        .ok_or_else(|| format!("must be a number, got {v}"))? as f32;
    if !(x >= lo && x <= hi) || x.is_nan() {
        return Err(if !x.is_finite() {
            format!("must be finite, got {v}")
        } else {
            format!("must be in [{lo}, {hi}], got {x}")
        });
    }
    Ok(x)
}

/// An array of `N` numbers within [lo, hi], `default` where absent.
fn numbers<const N: usize>(
    v: &Value,
    default: [f32; N],
    lo: f32,
    hi: f32,
) -> Result<[f32; N], String> {
    if v.is_null() {
        return Ok(default);
    }
    let a = v
        .as_array()
        .filter(|a| a.len() == N)
        .ok_or_else(|| format!("must be an array of {N} numbers, got {v}"))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = number(x, 0.0, lo, hi)?;
    }
    Ok(out)
}
