//! Writing a description out as a scene file, one object at a time, and
//! the checks that keep an export from destroying its own input.

use super::Format;
use crate::scene::desc::{
    BackgroundDesc, CameraDesc, LightDesc, MaterialDesc, MediumDesc, ObjectDesc, RenderDesc,
    SceneDesc, TextureDesc,
};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The first line of every exported TOML file.
const TOML_HEADER: &str = "# A lumen scene. Every field is described in docs/scene-format.md.\n\n";

/// Writes `desc` as a scene file of `format` to `out`. Reading the text
/// back gives `desc` again, and writing that gives the same text. The
/// objects are written one by one: a scene of millions of them needs no
/// more memory than its description (the `toml` crate would build a
/// document of the whole file first, many times its size).
pub fn write_scene(desc: &SceneDesc, format: Format, out: &mut impl Write) -> io::Result<()> {
    match format {
        Format::Json => {
            // An error of the writer stays the writer's (a closed pipe).
            serde_json::to_writer_pretty(&mut *out, desc).map_err(io::Error::from)?;
            out.write_all(b"\n")
        }
        // Without objects, `toml` writes `objects = []` among the first
        // keys: the whole description is small, written at once.
        Format::Toml if desc.objects.is_empty() => {
            let body = toml::to_string(desc).map_err(io::Error::other)?;
            out.write_all(TOML_HEADER.as_bytes())?;
            out.write_all(body.as_bytes())
        }
        Format::Toml => {
            let head = Head {
                caption: &desc.caption,
                render: &desc.render,
                camera: &desc.camera,
                background: &desc.background,
                textures: &desc.textures,
                materials: &desc.materials,
                lights: &desc.lights,
                media: &desc.media,
            };
            out.write_all(TOML_HEADER.as_bytes())?;
            out.write_all(toml::to_string(&head).map_err(io::Error::other)?.as_bytes())?;
            // Written in order, made on every core a few thousand at a time.
            for chunk in desc.objects.chunks(4096) {
                let tables: Vec<String> = chunk
                    .par_iter()
                    .map(|object| toml::to_string(&One { objects: [object] }))
                    .collect::<Result<_, _>>()
                    .map_err(io::Error::other)?;
                for table in tables {
                    out.write_all(b"\n")?;
                    out.write_all(table.as_bytes())?;
                }
            }
            Ok(())
        }
    }
}

/// A [`SceneDesc`] without its objects, borrowed, written as the
/// description writes those fields.
#[derive(Serialize)]
struct Head<'a> {
    #[serde(skip_serializing_if = "String::is_empty")]
    caption: &'a String,
    render: &'a RenderDesc,
    camera: &'a CameraDesc,
    background: &'a BackgroundDesc,
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    textures: &'a BTreeMap<String, TextureDesc>,
    materials: &'a BTreeMap<String, MaterialDesc>,
    #[serde(skip_serializing_if = "<[LightDesc]>::is_empty")]
    lights: &'a [LightDesc],
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    media: &'a BTreeMap<String, MediumDesc>,
}

/// One object, as a `[[objects]]` table.
#[derive(Serialize)]
struct One<'a> {
    objects: [&'a ObjectDesc; 1],
}

/// An export would write over the scene file it reads: refused, since the
/// file would lose everything a description does not keep (its comments,
/// its layout) and, should the write fail half-way, the scene itself.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverwritesSource {
    /// The output asked for.
    pub output: PathBuf,
    /// The scene file it is.
    pub source: PathBuf,
}

impl fmt::Display for OverwritesSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: is the scene file being exported ({}); writing over it would lose its comments and layout, so choose another output",
            self.output.display(),
            self.source.display()
        )
    }
}

impl std::error::Error for OverwritesSource {}

/// Refuses to export the scene file `source` to `output` when both name the
/// same file, however written: `s.toml` and `./dir/../s.toml`, a symbolic
/// link to it, or a hard link (see [`crate::files::same_file`]).
pub fn check_not_source(source: &Path, output: &Path) -> Result<(), OverwritesSource> {
    if crate::files::same_file(source, output) {
        return Err(OverwritesSource {
            output: output.to_path_buf(),
            source: source.to_path_buf(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::files::same_file;

    #[test]
    fn objects_written_one_by_one_read_as_the_whole_document() {
        let mut descs: Vec<SceneDesc> = crate::scene::builtin::BUILTINS
            .iter()
            .map(|b| b.desc())
            .collect();
        descs.push(SceneDesc::default());
        for desc in descs {
            let mut text = Vec::new();
            write_scene(&desc, Format::Toml, &mut text).unwrap();
            let whole = format!("{TOML_HEADER}{}", toml::to_string(&desc).unwrap());
            assert_eq!(String::from_utf8(text).unwrap(), whole, "{}", desc.caption);
            let mut text = Vec::new();
            write_scene(&desc, Format::Json, &mut text).unwrap();
            let whole = serde_json::to_string_pretty(&desc).unwrap() + "\n";
            assert_eq!(String::from_utf8(text).unwrap(), whole);
        }
    }

    #[test]
    fn a_file_is_the_same_by_any_name_and_not_another() {
        let dir = std::env::temp_dir().join(format!("lumen-same-file-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let a = dir.join("a.toml");
        let b = dir.join("b.toml");
        std::fs::write(&a, "").unwrap();
        std::fs::write(&b, "").unwrap();
        assert!(same_file(&a, &a));
        assert!(same_file(&a, &dir.join("sub/../a.toml")));
        assert!(!same_file(&a, &b));
        assert!(!same_file(&a, &dir.join("missing.toml")));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&a, dir.join("link.toml")).unwrap();
            std::fs::hard_link(&a, dir.join("hard.toml")).unwrap();
            assert!(same_file(&a, &dir.join("link.toml")));
            assert!(same_file(&dir.join("hard.toml"), &a));
        }
        let err = check_not_source(&a, &a).unwrap_err().to_string();
        assert!(err.contains("choose another output"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
