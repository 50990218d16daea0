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
