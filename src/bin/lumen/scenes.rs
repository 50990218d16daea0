//! Where scenes come from (built-in names or files) and `lumen scenes export`.

use crate::{write_stdout_with, FormatArg};
use anyhow::{anyhow, bail, Context, Result};
use lumen::output;
use lumen::scene::builtin::{self, BUILTINS};
use lumen::scene::export;
use lumen::scene::file::mitsuba::Options as ImportOptions;
use lumen::scene::file::{Format, SceneFile};
use lumen::scene::{hint, Overrides, Scene, SceneDesc};
use std::path::Path;

/// Where a scene comes from: a built-in name or a file.
pub(crate) enum SceneSource {
    Builtin(SceneDesc),
    File(SceneFile),
}

impl SceneSource {
    pub(crate) fn desc(&self) -> &SceneDesc {
        match self {
            SceneSource::Builtin(d) => d,
            SceneSource::File(f) => &f.desc,
        }
    }

    /// The description with the command-line overrides, and the scene
    /// compiled from it; a mistake in a file is reported with its line and
    /// column before any work starts. The description is moved, not
    /// copied: a file may hold millions of objects.
    pub(crate) fn resolve(self, name: &str, overrides: &Overrides) -> Result<(SceneDesc, Scene)> {
        match self {
            SceneSource::Builtin(mut desc) => {
                overrides.apply(&mut desc);
                let scene = Scene::from_desc(&desc).with_context(|| format!("scene '{name}'"))?;
                Ok((desc, scene))
            }
            SceneSource::File(f) => Ok(f.into_resolved(overrides)?),
        }
    }
}

/// A built-in scene by name, or else a scene file by path.
pub(crate) fn load_scene(name: &str, import: &ImportOptions) -> Result<SceneSource> {
    if let Some(b) = builtin::find(name) {
        return Ok(SceneSource::Builtin(b.desc()));
    }
    let path = Path::new(name);
    let looks_like_file = Format::from_extension(path).is_some()
        || lumen::scene::file::is_mitsuba(path)
        || lumen::scene::file::pbrt::is_pbrt(path)
        || name.contains(std::path::MAIN_SEPARATOR)
        || name.contains('/')
        || path.exists();
    if looks_like_file {
        let file = SceneFile::read_with(path, import)?;
        for warning in &file.import_warnings {
            errln!("lumen: warning: {warning}");
        }
        for warning in file.desc.warnings() {
            errln!("lumen: warning: {}: {warning}", file.name);
        }
        return Ok(SceneSource::File(file));
    }
    let closest = hint::closest(name, BUILTINS.iter().map(|b| b.name))
        .map(|n| format!(" (did you mean '{n}'?)"))
        .unwrap_or_default();
    bail!(
        "unknown scene '{name}'{closest}; `lumen scenes` lists the built-in scenes, \
         and scene files end in .toml, .json, .xml (Mitsuba 3) or .pbrt (pbrt-v4)"
    )
}

pub(crate) fn export_command(
    name: &str,
    out: Option<&Path>,
    format: FormatArg,
    import: &ImportOptions,
) -> Result<()> {
    // Checked before the file is read: a large scene takes a while.
    if let (None, Some(path)) = (builtin::find(name), out) {
        export::check_not_source(Path::new(name), path)?;
    }
    let source = load_scene(name, import)?;
    let format = match out {
        Some(path) => Format::from_extension(path)
            .ok_or_else(|| anyhow!("{}: scene files must end in .toml or .json", path.display()))?,
        None => match format {
            FormatArg::Toml => Format::Toml,
            FormatArg::Json => Format::Json,
        },
    };
    let desc = source.desc();
    match out {
        Some(path) => {
            output::check_writable(path)?;
            output::write_atomic_with(path, |w| export::write_scene(desc, format, w))?;
            errln!("{name}: written to {}", path.display());
        }
        None => write_stdout_with(|w| export::write_scene(desc, format, w))?,
    }
    Ok(())
}
