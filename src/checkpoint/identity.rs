//! Scene identity: the canonical text of what a render's samples depend on,
//! which a checkpoint records and a resumed render must match, and the
//! words that say how two of them differ.
//!
//! Only what changes the samples is part of it, and the scene's own
//! denoiser settings (`denoiser`, `denoise_quality`, `denoise_prefilter`),
//! which parts carry to `lumen merge` in it (the command line's options
//! are not). The caption is not, and neither is the
//! display gamma, which is applied when the image is written: a resumed
//! render writes its image with its own gamma.

use crate::scene::{MeshSource, SceneDesc};
use serde_json::Value;
use std::collections::BTreeSet;

/// The canonical text of a scene description that identifies a render:
/// compact JSON with keys sorted, without the caption and the display gamma.
pub fn description_text(desc: &SceneDesc) -> String {
    identity_text(desc, &[])
}

/// [`description_text`] with the content hashes of the mesh files the
/// scene reads (`mesh_sources`), so that a changed mesh file is a different
/// render.
pub fn identity_text(desc: &SceneDesc, sources: &[MeshSource]) -> String {
    #[derive(serde::Serialize)]
    struct Identity<'a> {
        #[serde(flatten)]
        desc: &'a SceneDesc,
        #[serde(skip_serializing_if = "<[MeshSource]>::is_empty")]
        mesh_sources: &'a [MeshSource],
    }
    // Written as it goes, not through a `serde_json::Value` of the whole
    // description: that took 700 MB for a million spheres.
    super::canonical::sorted_json(
        &Identity {
            desc,
            mesh_sources: sources,
        },
        &STRIPPED,
    )
    .expect("a scene description always serialises")
}

/// The fields of a description that do not change the samples.
const STRIPPED: [&[&str]; 2] = [&["caption"], &["render", "gamma"]];

/// Removes from a description's JSON what does not change the samples
/// ([`STRIPPED`]). Checkpoints written before the identity left these out
/// still hold them.
fn strip(value: &mut Value) {
    if let Value::Object(map) = value {
        map.remove("caption");
        if let Some(Value::Object(render)) = map.get_mut("render") {
            render.remove("gamma");
        }
    }
}

/// Whether two identity texts name the same render: equal texts, or equal
/// once parsed and stripped (a checkpoint of an earlier lumen recorded its
/// caption and gamma, and its keys in another order).
pub(crate) fn same_render(theirs: &str, ours: &str) -> bool {
    if theirs == ours {
        return true;
    }
    match (parse(theirs), parse(ours)) {
        (Value::Null, _) | (_, Value::Null) => false,
        (a, b) => a == b,
    }
}

fn parse(text: &str) -> Value {
    let mut v = serde_json::from_str::<Value>(text).unwrap_or(Value::Null);
    strip(&mut v);
    v
}

/// `a`, `a and b`, `a, b and c`.
fn list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// What differs between two description texts, in words: render settings
/// one by one, the rest by section. Both are parsed the same way, so that
/// equal numbers compare equal. `theirs_name` names where `theirs` comes
/// from ("the checkpoint"), `ours_at` where `ours` is ("here").
pub(crate) fn describe_differences(
    theirs: &str,
    ours: &str,
    theirs_name: &str,
    ours_at: &str,
) -> String {
    let (theirs, ours) = (parse(theirs), parse(ours));
    let (Value::Object(theirs), Value::Object(ours)) = (theirs, ours) else {
        return "a different scene description".into();
    };
    let absent = Value::String("unset".into());
    let show = |v: &Value| match v {
        Value::String(s) => s.clone(),
        v => v.to_string(),
    };
    let mut out = Vec::new();
    let empty = serde_json::Map::new();
    let section = |m| {
        serde_json::Map::get(m, "render")
            .and_then(Value::as_object)
            .unwrap_or(&empty)
    };
    let (a, b) = (section(&theirs), section(&ours));
    let keys: BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    for key in keys {
        let (x, y) = (a.get(key).unwrap_or(&absent), b.get(key).unwrap_or(&absent));
        if x != y {
            let name = match key.as_str() {
                "samples_per_pixel" => "spp".to_string(),
                "max_depth" => "depth".to_string(),
                k => k.replace('_', " "),
            };
            out.push(format!(
                "{name} {} in {theirs_name}, {} {ours_at}",
                show(x),
                show(y)
            ));
        }
    }
    let sections: BTreeSet<&String> = theirs.keys().chain(ours.keys()).collect();
    let differing: Vec<&str> = sections
        .into_iter()
        .filter(|k| *k != "render" && theirs.get(*k) != ours.get(*k))
        .map(String::as_str)
        .collect();
    if differing.contains(&"mesh_sources") {
        // Name the files whose content changed.
        let files = |m: &serde_json::Map<String, Value>| -> Vec<(String, Value)> {
            m.get("mesh_sources")
                .and_then(Value::as_array)
                .map(|list| list.iter().map(|s| (show(&s["file"]), s.clone())).collect())
                .unwrap_or_default()
        };
        let (a, b) = (files(&theirs), files(&ours));
        for (name, source) in &b {
            match a.iter().find(|(n, _)| n == name) {
                Some((_, old)) if old != source => {
                    out.push(format!("file {name} has changed since {theirs_name}"))
                }
                None => out.push(format!("file {name} is not in {theirs_name}")),
                _ => {}
            }
        }
    }
    let differing: Vec<&str> = differing
        .into_iter()
        .filter(|k| *k != "mesh_sources")
        .collect();
    if !differing.is_empty() {
        let verb = if differing.len() == 1 {
            "differs"
        } else {
            "differ"
        };
        out.push(format!(
            "a different scene (its {} {verb})",
            list(&differing)
        ));
    }
    if out.is_empty() {
        out.push("a different scene description".into());
    }
    out.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn caption_and_gamma_are_not_part_of_the_identity() {
        let desc = builtin::find("cover").unwrap().desc();
        let mut edited = desc.clone();
        edited.caption = "Another caption".into();
        edited.render.gamma = 2.2;
        assert_eq!(description_text(&desc), description_text(&edited));
        edited.render.seed += 1;
        assert_ne!(description_text(&desc), description_text(&edited));
        // A checkpoint of an earlier lumen recorded both.
        let old = serde_json::to_string(&edited).unwrap();
        edited.render.seed -= 1;
        assert!(!same_render(&old, &description_text(&desc)));
        let old = serde_json::to_string(&edited).unwrap();
        assert!(same_render(&old, &description_text(&desc)));
    }

    #[test]
    fn the_identity_is_the_stripped_json_value_with_sorted_keys() {
        // As the identity was made before it was written as it goes (and
        // as checkpoints of that time hold it).
        #[derive(serde::Serialize)]
        struct Identity<'a> {
            #[serde(flatten)]
            desc: &'a SceneDesc,
            #[serde(skip_serializing_if = "<[MeshSource]>::is_empty")]
            mesh_sources: &'a [MeshSource],
        }
        let sources = [MeshSource {
            file: "bunny \"1\".glb".into(),
            crc: 0xdead_beef,
            len: 1 << 40,
        }];
        for name in [
            "cover",
            "earth",
            "materials",
            "cornell-box",
            "next-week-final",
        ] {
            let desc = builtin::find(name).unwrap().desc();
            for sources in [&sources[..], &[]] {
                let mut value = serde_json::to_value(Identity {
                    desc: &desc,
                    mesh_sources: sources,
                })
                .unwrap();
                strip(&mut value);
                assert_eq!(identity_text(&desc, sources), value.to_string(), "{name}");
            }
        }
    }

    #[test]
    fn differing_sections_are_listed_in_words() {
        assert_eq!(list(&["camera"]), "camera");
        assert_eq!(list(&["camera", "objects"]), "camera and objects");
        assert_eq!(list(&["a", "b", "c"]), "a, b and c");
        let cover = builtin::find("cover").unwrap().desc();
        let mut moved = cover.clone();
        moved.camera.vfov += 1.0;
        let e = describe_differences(
            &description_text(&cover),
            &description_text(&moved),
            "the checkpoint",
            "here",
        );
        assert_eq!(e, "a different scene (its camera differs)");
    }
}
