//! Mitsuba 3 scenes (`.xml`): read into a [`SceneDesc`](crate::scene::desc::SceneDesc), the description
//! every lumen scene has, so that a Mitsuba scene renders as it is and
//! exports to lumen's TOML unchanged.
//!
//! The XML layer (`xml`) reads the files; `props` reads a plugin's
//! parameters by type; `plugins` turns each plugin into lumen's
//! description, one function a tag. Colours are read as Mitsuba's RGB
//! variants read them ([`spectrum`]). What lumen does not have is refused
//! with the element's file, line and column and the list of what it has,
//! unless [`Options::approximate`] asks for the nearest it has instead,
//! with one warning a substitution. docs/mitsuba.md lists the plugins and
//! what differs.

mod cie;
mod plugins;
mod props;
pub mod spectrum;
mod transform;
mod xml;

use super::{excerpt, Diagnostic, SceneFileError};
use std::path::Path;
use xml::{At, Files};

pub(crate) use plugins::Convert;

pub use super::import::{Imported, Options};

/// What went wrong, located.
pub(super) type Failure = SceneFileError;

fn plain(file: String, message: String) -> Failure {
    Diagnostic::plain(&file, message).into()
}

/// A failure at `at` of the files read.
fn located(files: &Files, at: At, message: String) -> Failure {
    let (name, text) = &files.files[at.file as usize];
    let mut d = Diagnostic::plain(name, message);
    let lc = (at.line as usize, at.col as usize);
    d.line_col = Some(lc);
    d.excerpt = Some(excerpt(text, lc, None));
    d.into()
}

/// Reads the Mitsuba scene at `path`.
pub fn read(path: &Path, options: &Options) -> Result<Imported, Failure> {
    let doc = xml::load(path, options)?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut cx = Convert::new(&doc, options, dir)?;
    cx.scene()?;
    Ok(cx.finish())
}
