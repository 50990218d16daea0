//! glTF materials, textures and images read as the specification and its
//! extensions define them, from small files made here.

use super::material::AlphaMode;
use super::{load, MeshError, Model};
use crate::math::Vec3;
use crate::texture::{Channels, Filter, TexCoords, Wrap};
use base64::Engine as _;
use std::sync::Arc;

/// A 2 × 2 PNG: top left red, top right green, bottom left blue, bottom
/// right white, each with alpha `alpha`.
fn quadrants_png(alpha: u8) -> Vec<u8> {
    let colours = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]];
    let image = image::RgbaImage::from_fn(2, 2, |x, y| {
        let [r, g, b] = colours[(y * 2 + x) as usize];
        image::Rgba([r, g, b, alpha])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// A unit quad (two triangles) with TEXCOORD_0, TEXCOORD_1 (= 1 − uv) and
/// COLOR_0, material 0, and the given `materials`, `textures`, `samplers`
/// and `images` arrays; `extra` adds top-level members.
fn quad_gltf(materials: &str, textures: &str, samplers: &str, images: &str, extra: &str) -> String {
    let mut b = Vec::new();
    let f =
        |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    f(&mut b, &[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]); // 48: positions
    f(&mut b, &[0., 1., 1., 1., 1., 0., 0., 0.]); // 32: uv (glTF's, v down)
    f(&mut b, &[1., 0., 0., 0., 0., 1., 1., 1.]); // 32: uv1
    f(
        &mut b,
        &[
            1., 0., 0., 1., 0., 1., 0., 1., 0., 0., 1., 0.5, 1., 1., 1., 1.,
        ],
    ); // 64: colours
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  {extra}
  "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2, "COLOR_0": 3}}, "indices": 4, "material": 0}}]}}],
  "materials": {materials},
  "textures": {textures},
  "samplers": {samplers},
  "images": {images},
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
    {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 112, "byteLength": 64}},
    {{"buffer": 0, "byteOffset": 176, "byteLength": 12}}
  ],
  "buffers": [{{"byteLength": 188, "uri": "{}"}}]
}}"#,
        data_uri("application/octet-stream", &b)
    )
}

fn load_json(name: &str, json: &str) -> Result<Model, MeshError> {
    let dir =
        std::env::temp_dir().join(format!("lumen-gltf-material-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, json).unwrap();
    let out = load(&path);
    let _ = std::fs::remove_dir_all(&dir);
    out
}

fn one_image() -> String {
    format!(
        r#"[{{"uri": "{}"}}]"#,
        data_uri("image/png", &quadrants_png(128))
    )
}

/// The quadrants, then a flat normal map (every texel (0.5, 0.5, 1)).
fn two_images() -> String {
    let flat = image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 255]));
    let mut png = std::io::Cursor::new(Vec::new());
    flat.write_to(&mut png, image::ImageFormat::Png).unwrap();
    format!(
        r#"[{{"uri": "{}"}}, {{"uri": "{}"}}]"#,
        data_uri("image/png", &quadrants_png(128)),
        data_uri("image/png", &png.into_inner())
    )
}

/// Every core parameter and every KHR material extension is read into
/// the material, each texture with its channel, encoding, set of
/// coordinates, sampler and transform.
#[test]
fn every_parameter_and_extension_is_read() {
    let materials = r#"[{
      "name": "all",
      "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 0.8], "baseColorTexture": {"index": 0},
        "metallicFactor": 0.3, "roughnessFactor": 0.4, "metallicRoughnessTexture": {"index": 1, "texCoord": 1}},
      "normalTexture": {"index": 1, "scale": 0.7},
      "occlusionTexture": {"index": 1},
      "emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": {"index": 0},
      "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true,
      "extensions": {
        "KHR_materials_emissive_strength": {"emissiveStrength": 4},
        "KHR_materials_ior": {"ior": 1.33},
        "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.9, 0.8]},
        "KHR_materials_transmission": {"transmissionFactor": 0.6, "transmissionTexture": {"index": 1}},
        "KHR_materials_volume": {"thicknessFactor": 2, "attenuationDistance": 3, "attenuationColor": [0.9, 0.8, 0.7]},
        "KHR_materials_clearcoat": {"clearcoatFactor": 0.9, "clearcoatRoughnessFactor": 0.1},
        "KHR_materials_sheen": {"sheenColorFactor": [0.2, 0.3, 0.4], "sheenRoughnessFactor": 0.5,
          "sheenRoughnessTexture": {"index": 0,
            "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0, "scale": [2, 2]}}}}
      }
    }]"#;
    let textures = r#"[{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1}]"#;
    let samplers = r#"[{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}, {}]"#;
    let m = load_json(
        "all",
        &quad_gltf(materials, textures, samplers, &two_images(), ""),
    )
    .unwrap();
    let mat = &m.materials[0];
    assert_eq!(mat.name, "all");
    assert_eq!(mat.base_color.value, [0.5, 0.6, 0.7]);
    assert_eq!(mat.alpha.value, 0.8);
    assert_eq!(mat.alpha_mode, AlphaMode::Mask(0.3));
    assert!(mat.double_sided && mat.vertex_color);
    let base = mat.base_color.map.as_ref().unwrap();
    assert!(base.srgb && base.channels == Channels::Rgb && base.uv_set == 0);
    assert_eq!(base.wrap, [Wrap::Clamp, Wrap::Mirror]);
    assert_eq!(base.filter, Filter::Nearest);
    let alpha = mat.alpha.map.as_ref().unwrap();
    assert!(!alpha.srgb && alpha.channels == Channels::One(3));
    let (metal, rough) = (
        mat.metallic.map.as_ref().unwrap(),
        mat.roughness.map.as_ref().unwrap(),
    );
    assert_eq!(
        (metal.channels, rough.channels),
        (Channels::One(2), Channels::One(1))
    );
    assert_eq!((metal.uv_set, metal.srgb), (1, false));
    assert_eq!(rough.wrap, [Wrap::Repeat; 2]);
    assert_eq!(rough.filter, Filter::Bilinear);
    assert_eq!((mat.metallic.value, mat.roughness.value), (0.3, 0.4));
    let (normal, scale) = mat.normal_map.as_ref().unwrap();
    assert!(!normal.srgb && *scale == 0.7);
    assert_eq!(mat.emission.value, [4.0, 2.0, 1.0]);
    assert!(mat.emission.map.as_ref().unwrap().srgb);
    assert_eq!(mat.ior, 1.33);
    assert_eq!(mat.specular.value, 0.5);
    assert_eq!(mat.specular_color.value, [1.0, 0.9, 0.8]);
    assert_eq!(mat.transmission.value, 0.6);
    assert_eq!(
        mat.transmission.map.as_ref().unwrap().channels,
        Channels::One(0)
    );
    assert_eq!(mat.thickness.value, 2.0);
    assert_eq!(
        (mat.attenuation_distance, mat.attenuation_color),
        (3.0, [0.9, 0.8, 0.7])
    );
    assert_eq!(
        (mat.clearcoat.value, mat.clearcoat_roughness.value),
        (0.9, 0.1)
    );
    assert_eq!(mat.sheen_color.value, [0.2, 0.3, 0.4]);
    let sheen = mat.sheen_roughness.map.as_ref().unwrap();
    assert_eq!(sheen.channels, Channels::One(3));
    assert_eq!(sheen.transform.rows, [[2.0, 0.0, 0.5], [0.0, 2.0, 0.0]]);
    // Each image decoded once, shared by every map of it.
    let maps: Vec<_> = mat.maps().collect();
    assert_eq!(maps.len(), 8);
    let shared = |a: &crate::texture::ImageMap| Arc::ptr_eq(&a.image, &base.image);
    assert_eq!(
        maps.iter().filter(|m| shared(m)).count(),
        4,
        "base, alpha, emission, sheen"
    );
    assert!(maps
        .iter()
        .filter(|m| !shared(m))
        .all(|m| Arc::ptr_eq(&m.image, &normal.image)));
    assert!(
        m.warnings.iter().any(|w| w.contains("occlusion")),
        "{:?}",
        m.warnings
    );
    // The mesh's extra attributes.
    let mesh = &m.meshes[0];
    assert_eq!(
        mesh.uvs1.as_ref().unwrap()[0],
        [1.0, 1.0],
        "glTF (1, 0), v flipped up"
    );
    assert_eq!(mesh.colors.as_ref().unwrap()[2], [0.0, 0.0, 1.0, 0.5]);
}

/// Texel lookups through the file's maps: glTF's v runs down the image
/// (lumen's up), and KHR_texture_transform offsets, rotates and scales
/// in the image's coordinates.
#[test]
fn maps_look_up_the_texels_the_file_means() {
    let materials = r#"[
      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
        "extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}}}},
      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
        "extensions": {"KHR_texture_transform": {"rotation": 1.5707963, "texCoord": 1}}}}}
    ]"#;
    let samplers = r#"[{"magFilter": 9728}]"#;
    let m = load_json(
        "lookup",
        &quad_gltf(
            materials,
            r#"[{"source": 0, "sampler": 0}]"#,
            samplers,
            &one_image(),
            "",
        ),
    )
    .unwrap();
    // glTF (0.25, 0.25), the top-left quadrant: lumen's (0.25, 0.75).
    let at = |u: f32, v: f32| TexCoords {
        uv: [u, 1.0 - v],
        uv1: [u, 1.0 - v],
        point: Vec3::ZERO,
    };
    let rgb = |k: usize, u: f32, v: f32| {
        let [r, g, b, _] = m.materials[k]
            .base_color
            .map
            .as_ref()
            .unwrap()
            .rgba(&at(u, v));
        [r, g, b]
    };
    assert_eq!(rgb(0, 0.25, 0.25), [1.0, 0.0, 0.0], "top left red");
    assert_eq!(rgb(0, 0.75, 0.25), [0.0, 1.0, 0.0], "top right green");
    assert_eq!(rgb(0, 0.25, 0.75), [0.0, 0.0, 1.0], "bottom left blue");
    assert_eq!(rgb(1, 0.25, 0.25), [0.0, 1.0, 0.0], "moved right by half");
    // A quarter turn: (u, v) ↦ (v, −u); glTF (0.75, 0.25) reads (0.25,
    // −0.75) ≡ (0.25, 0.25), red; the second set of coordinates is asked.
    assert_eq!(m.materials[2].base_color.map.as_ref().unwrap().uv_set, 1);
    assert_eq!(rgb(2, 0.75, 0.25), [1.0, 0.0, 0.0]);
}

/// A file that requires an extension lumen lacks is refused with that
/// alone, before anything else wrong with it; an optional one is a warning.
#[test]
fn required_extensions_lumen_lacks_are_the_one_cause_given() {
    let json = quad_gltf(
        "[{}]",
        "[]",
        "[]",
        "[]",
        r#""extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],"#,
    )
    // Broken as well: a buffer that does not hold what it says.
    .replace(r#""byteLength": 188"#, r#""byteLength": 100000"#);
    let e = load_json("required", &json).unwrap_err().to_string();
    assert!(
        e.contains("requires extension KHR_draco_mesh_compression"),
        "{e}"
    );
    assert!(!e.contains("buffer"), "{e}");
    let json = quad_gltf(
        "[{}]",
        "[]",
        "[]",
        "[]",
        r#""extensionsUsed": ["KHR_materials_anisotropy"],"#,
    );
    let m = load_json("used", &json).unwrap();
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("KHR_materials_anisotropy")),
        "{:?}",
        m.warnings
    );
}

/// Missing, corrupt or foreign images, texture coordinates past the
/// second set, non-finite transforms and normal maps that are not
/// tangent-space maps are refused, naming the material or image.
#[test]
fn bad_textures_and_images_are_refused_with_where_they_are() {
    let texture = r#"[{"source": 0}]"#;
    let base =
        |info: &str| format!(r#"[{{"pbrMetallicRoughness": {{"baseColorTexture": {info}}}}}]"#);
    let cases = [
        (
            base(r#"{"index": 0}"#),
            r#"[{"uri": "missing.png"}]"#.to_string(),
            "missing.png",
        ),
        (
            base(r#"{"index": 0}"#),
            format!(
                r#"[{{"uri": "{}"}}]"#,
                data_uri("image/png", b"\x89PNG\r\n\x1a\nnot really")
            ),
            "image 0",
        ),
        (
            base(r#"{"index": 0}"#),
            format!(
                r#"[{{"uri": "{}", "mimeType": "image/ktx2"}}]"#,
                data_uri("image/ktx2", b"\xabKTX 20\xbb")
            ),
            "not a PNG or JPEG",
        ),
        (
            base(r#"{"index": 0, "texCoord": 2}"#),
            one_image(),
            "TEXCOORD_2",
        ),
        (
            base(r#"{"index": 0, "extensions": {"KHR_texture_transform": {"scale": [1e39, 1]}}}"#),
            one_image(),
            "must be finite",
        ),
        (
            base(r#"{"index": 3}"#),
            one_image(),
            "baseColorTexture.index: Index out of bounds",
        ),
        (
            r#"[{"normalTexture": {"index": 0}}]"#.to_string(),
            one_image(),
            "not a tangent-space normal map",
        ),
    ];
    for (materials, images, words) in cases {
        let json = quad_gltf(&materials, texture, "[]", &images, "");
        let e = load_json("bad", &json).expect_err(words).to_string();
        assert!(e.contains(words), "{words}: {e}");
    }
}
