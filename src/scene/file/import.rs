//! What the readers of other renderers' scene formats share: how they
//! read, and what they give.

use crate::scene::desc::SceneDesc;

/// How a scene of another renderer (Mitsuba 3, pbrt-v4) is read.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// Values of a Mitsuba scene's parameters (`$name`), as Mitsuba's
    /// `-D name=value`; each must be used.
    pub defines: Vec<(String, String)>,
    /// Render what lumen lacks with the nearest it has, with a warning
    /// for each substitution, rather than refuse the scene.
    pub approximate: bool,
    /// Read included files (`<include>`, `Include`, `Import`) outside
    /// the scene file's folder.
    pub allow_outside: bool,
}

/// A scene of another renderer read: its description, and a warning for every
/// substitution `--approximate` made.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The scene.
    pub desc: SceneDesc,
    /// One line each.
    pub warnings: Vec<String>,
}

/// The copies a reader makes of its materials for surfaces between media
/// (lumen sets a surface's media on its material, the formats it reads on
/// the shape): one per material and pair of media.
#[derive(Debug, Default)]
pub(super) struct MediaCopies(
    std::collections::HashMap<(String, Option<String>, Option<String>), String>,
);

impl MediaCopies {
    /// The name of material `material` of `desc` with `interior` and
    /// `exterior` media (an `interface` in their place where `interface`),
    /// added to `desc` under `fresh(desc, stem)` the first time it is asked for.
    pub fn of(
        &mut self,
        desc: &mut SceneDesc,
        material: String,
        [interior, exterior]: [Option<String>; 2],
        interface: bool,
        fresh: impl FnOnce(&SceneDesc, &str) -> String,
    ) -> String {
        let key = (material, interior, exterior);
        if let Some(name) = self.0.get(&key) {
            return name.clone();
        }
        let mut copy = if interface {
            crate::material::MaterialDesc::Interface(Default::default())
        } else {
            desc.materials[&key.0].clone()
        };
        let sides = copy.surface_mut();
        sides.interior.clone_from(&key.1);
        sides.exterior.clone_from(&key.2);
        let name = fresh(desc, &format!("{}-in-media", key.0));
        desc.materials.insert(name.clone(), copy);
        self.0.insert(key, name.clone());
        name
    }
}
