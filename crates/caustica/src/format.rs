//! Scene file formats. Each reader turns a file into the format-neutral
//! [`SceneDescription`](crate::description::SceneDescription); nothing outside its module knows
//! the file's syntax.

pub mod ray_file;

use crate::description::SceneDescription;
use crate::error::{Error, ParseError, Result};
use crate::progress::Progress;
use std::path::{Path, PathBuf};

/// Options for reading a scene file.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// How `.ray` files are read.
    pub ray: ray_file::ParseOptions,
}

/// A scene file read and described; it keeps the text so that errors found later (while
/// building) can still point into it.
#[derive(Clone, Debug)]
pub struct SceneSource {
    /// The file, as errors name it.
    pub path: PathBuf,
    /// The file's text.
    pub text: String,
    /// What the file describes.
    pub description: SceneDescription,
}

impl SceneSource {
    /// An error located in this file.
    pub fn error(&self, error: ParseError) -> Error {
        Error::Scene {
            path: self.path.clone(),
            text: self.text.clone(),
            error,
        }
    }
}

/// Reads the scene file at `path`, reporting a "parse" phase to `progress`.
pub fn read_file(path: &Path, options: &ReadOptions, progress: &dyn Progress) -> Result<SceneSource> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let offset = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            return Err(Error::Scene {
                path: path.to_path_buf(),
                text,
                error: ParseError::new("the file is not valid UTF-8 text", offset..offset + 1),
            });
        }
    };
    let dir = path.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    read_text(path, text, &dir, options, progress)
}

/// Reads scene text, reporting a "parse" phase; `path` names it in errors and files it refers
/// to (textures) resolve against `scene_dir`.
pub fn read_text(
    path: &Path,
    text: String,
    scene_dir: &Path,
    options: &ReadOptions,
    progress: &dyn Progress,
) -> Result<SceneSource> {
    match ray_file::parse_reporting(&text, scene_dir, &options.ray, progress) {
        Ok(scene) => Ok(SceneSource {
            path: path.to_path_buf(),
            text,
            description: scene.into_description(),
        }),
        Err(error) => Err(Error::Scene {
            path: path.to_path_buf(),
            text,
            error,
        }),
    }
}
