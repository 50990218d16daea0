//! The gallery: every built-in scene rendered into one folder, with an
//! `index.html` that shows them book by book, in each book's order.

use crate::output::{self, OutputError};
use crate::render::{render, RenderStats};
use crate::scene::builtin::BUILTINS;
use crate::scene::{Overrides, Scene, SceneError};
use std::fmt::Write as _;
use std::path::Path;
use thiserror::Error;

/// A gallery that could not be made.
#[derive(Debug, Error)]
pub enum GalleryError {
    /// A scene could not be compiled with the given overrides.
    #[error("scene {name}: {source}")]
    Scene {
        /// Built-in scene name.
        name: &'static str,
        /// Why.
        source: SceneError,
    },
    /// A file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// `--denoise` was asked for, and the denoiser failed.
    #[error("--denoise: {0}")]
    Denoise(#[from] crate::denoise::DenoiseError),
    /// The folder could not be created.
    #[error("{path}: cannot create the gallery folder: {message}")]
    Folder {
        /// The folder.
        path: String,
        /// Why.
        message: String,
    },
}

/// Renders every built-in scene to `dir/NAME.png` and writes `dir/index.html`.
/// `on_scene` is told each scene's name and counts as it finishes.
pub fn make_gallery(
    dir: &Path,
    overrides: &Overrides,
    on_scene: &mut dyn FnMut(&str, RenderStats),
) -> Result<(), GalleryError> {
    std::fs::create_dir_all(dir).map_err(|e| GalleryError::Folder {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    if overrides.denoise {
        crate::denoise::check_available(crate::denoise::Denoiser::Oidn)?;
    }
    // Compile everything first so that a bad override fails before any render.
    let mut scenes = Vec::with_capacity(BUILTINS.len());
    for b in BUILTINS {
        let mut desc = b.desc();
        overrides.apply(&mut desc);
        let scene = Scene::from_desc(&desc).map_err(|source| GalleryError::Scene {
            name: b.name,
            source,
        })?;
        scenes.push((b, scene));
    }
    let mut html = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>lumen gallery</title>\n<style>\
         body{font-family:sans-serif;max-width:60em;margin:auto;background:#fafafa}\
         figure{display:inline-block;margin:1em;vertical-align:top}\
         figcaption{max-width:400px}img{max-width:400px}\
         </style>\n</head>\n<body>\n<h1>lumen gallery</h1>\n",
    );
    let mut book = None;
    for (i, (b, scene)) in scenes.iter().enumerate() {
        if book != Some(b.book) {
            book = Some(b.book);
            let _ = writeln!(html, "<h2>{}</h2>", b.book.title());
        }
        let (film, stats) = render(scene, &|_| {});
        let file = format!("{}.png", b.name);
        let path = dir.join(&file);
        let gamma = scene.settings.gamma;
        if scene.settings.denoise {
            let clean = crate::denoise::denoise_film(
                &film,
                rayon::current_num_threads(),
                Default::default(),
            )?;
            let beauty = output::Beauty::Colors {
                width: film.width(),
                height: film.height(),
                colors: &clean,
            };
            output::write_image_as(&path, beauty, &film, gamma, &[])?;
        } else {
            output::write_image(&path, &film, gamma, &[])?;
        }
        on_scene(b.name, stats);
        let _ = writeln!(
            html,
            "<figure><img src=\"{file}\" alt=\"{name}\"><figcaption>{n}. <b>{name}</b>: {caption}</figcaption></figure>",
            n = i + 1,
            name = b.name,
            caption = b.caption,
        );
    }
    html.push_str("</body>\n</html>\n");
    output::write_bytes_atomic(&dir.join("index.html"), html.as_bytes())?;
    Ok(())
}
