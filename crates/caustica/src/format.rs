//! Scene file formats. Each reader turns a file into the format-neutral
//! [`SceneDescription`](crate::description::SceneDescription); nothing outside its module knows
//! the file's syntax. The format is chosen by the file's extension or by [`ReadOptions::format`]
//! (docs/scene-formats.md).
//!
//! A scene may span several files (pbrt's `Include`, glTF's buffers, OBJ's `.mtl`, a mesh file
//! named in a `.ray` file): every file a reader opens is kept in the scene's [`SourceFiles`],
//! each at its own range of one byte-offset space, so a span anywhere in the description names
//! its file as well as its line.

pub mod gltf;
pub mod obj;
pub mod pbrt;
pub mod ply;
pub mod ray_file;

use crate::description::SceneDescription;
use crate::error::{Error, ParseError, Result, Span};
use crate::progress::Progress;
use std::path::{Path, PathBuf};

/// The scene formats caustica reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// The SBT-raytracer `.ray` format of the course (both dialects).
    Ray,
    /// A subset of pbrt-v4's scene format (`.pbrt`).
    Pbrt,
    /// glTF 2.0, as JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// A Wavefront OBJ mesh with its MTL materials, as a whole scene (`.obj`).
    Obj,
}

impl Format {
    /// The format a file's extension names; `None` for other extensions.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ray" => Some(Format::Ray),
            "pbrt" => Some(Format::Pbrt),
            "gltf" | "glb" => Some(Format::Gltf),
            "obj" => Some(Format::Obj),
            _ => None,
        }
    }

    /// A format by its name (`ray`, `pbrt`, `gltf`, `obj`).
    pub fn from_name(name: &str) -> Result<Format> {
        match name {
            "ray" => Ok(Format::Ray),
            "pbrt" => Ok(Format::Pbrt),
            "gltf" | "glb" => Ok(Format::Gltf),
            "obj" => Ok(Format::Obj),
            other => Err(Error::InvalidSettings(format!(
                "unknown scene format `{other}`: expected ray, pbrt, gltf or obj"
            ))),
        }
    }

    /// The format's name.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ray => "ray",
            Format::Pbrt => "pbrt",
            Format::Gltf => "gltf",
            Format::Obj => "obj",
        }
    }
}

/// Options for reading a scene file.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// How `.ray` files are read.
    pub ray: ray_file::ParseOptions,
    /// The format, instead of the one the extension names (`.ray` for unknown extensions).
    pub format: Option<Format>,
    /// The camera and light an OBJ scene is rendered with.
    pub obj: obj::SceneOptions,
}

impl ReadOptions {
    /// The format `path` is read as.
    pub fn format_of(&self, path: &Path) -> Format {
        self.format.or_else(|| Format::from_path(path)).unwrap_or(Format::Ray)
    }
}

/// One file of a scene, placed at `base` in the scene's span space.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// The file, as errors name it.
    pub path: PathBuf,
    /// Its text (for binary files, the part that is text: a PLY header, a GLB's JSON chunk).
    pub text: String,
    /// Offset of its first byte in the scene's span space.
    pub base: usize,
}

/// Every file a scene was read from; spans in its description are offsets into their
/// concatenation (with a one-byte gap after each file so end-of-file spans stay in their file).
#[derive(Clone, Debug, Default)]
pub struct SourceFiles {
    files: Vec<SourceFile>,
}

/// Files larger than this are refused before being read whole.
pub const MAX_FILE_BYTES: u64 = 4 << 30;

impl SourceFiles {
    /// The files of a scene whose main file is `path` with `text` (at offset 0).
    pub fn new(path: &Path, text: String) -> SourceFiles {
        SourceFiles {
            files: vec![SourceFile {
                path: path.to_path_buf(),
                text,
                base: 0,
            }],
        }
    }

    /// The main file.
    pub fn main(&self) -> &SourceFile {
        &self.files[0]
    }

    /// Every file, the main one first.
    pub fn files(&self) -> &[SourceFile] {
        &self.files
    }

    /// Adds a file's text; returns the offset its spans start at.
    pub fn add(&mut self, path: &Path, text: String) -> usize {
        let base = self.files.last().map_or(0, |f| f.base + f.text.len() + 1);
        self.files.push(SourceFile {
            path: path.to_path_buf(),
            text,
            base,
        });
        base
    }

    /// Reads the file at `path` as bytes; a failure is an error at `blame` (where the file is
    /// named).
    pub fn read_bytes(path: &Path, blame: &Span) -> Result<Vec<u8>, ParseError> {
        let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        if size > MAX_FILE_BYTES {
            return Err(ParseError::new(
                format!("`{}` is {size} bytes, more than caustica reads", path.display()),
                blame.clone(),
            ));
        }
        std::fs::read(path).map_err(|e| {
            ParseError::new(format!("cannot read `{}`: {e}", path.display()), blame.clone())
                .with_help("files a scene refers to are resolved against the scene file's folder")
        })
    }

    /// Reads the text file at `path` and adds it; returns its base offset and its text. A
    /// failure is an error at `blame`; bad UTF-8 an error in the file itself.
    pub fn read_text(&mut self, path: &Path, blame: &Span) -> Result<(usize, &str), ParseError> {
        let (base, _, bad) = self.read_text_lossy(path, blame)?;
        if let Some(bad) = bad {
            return Err(ParseError::new("the file is not valid UTF-8 text", bad));
        }
        Ok((base, &self.files.last().expect("just added").text))
    }

    /// [`SourceFiles::read_text`], with bytes that are not UTF-8 read as U+FFFD: the span of the
    /// first such byte is returned, for a warning.
    pub fn read_text_lossy(&mut self, path: &Path, blame: &Span) -> Result<(usize, &str, Option<Span>), ParseError> {
        let bytes = Self::read_bytes(path, blame)?;
        let (text, bad) = decode_text(bytes);
        let base = self.add(path, text);
        let bad = bad.map(|offset| base + offset..base + offset + 1);
        Ok((base, &self.files.last().expect("just added").text, bad))
    }

    /// The file a span starts in, and the span relative to that file (`None` without files).
    pub fn locate(&self, span: &Span) -> Option<(&SourceFile, Span)> {
        let file = self.files.iter().rev().find(|f| f.base <= span.start)?;
        let start = span.start - file.base;
        let end = span.end.saturating_sub(file.base).max(start);
        Some((file, start..end))
    }

    /// An error located in the file its span falls in.
    pub fn error(&self, error: ParseError) -> Error {
        match self.locate(&error.span) {
            Some((file, span)) => Error::Scene {
                path: file.path.clone(),
                text: file.text.clone(),
                error: ParseError { span, ..error },
            },
            None => Error::Scene {
                path: PathBuf::new(),
                text: String::new(),
                error,
            },
        }
    }

    /// A hash of every file's text (FNV-1a), the same on every machine.
    pub fn hash(&self) -> u64 {
        self.files
            .iter()
            .flat_map(|f| f.text.bytes().chain([0]))
            .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
                (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
            })
    }
}

/// A scene file read and described; it keeps the files' text so that errors found later
/// (while building) can still point into them.
#[derive(Clone, Debug)]
pub struct SceneSource {
    /// The main file, as errors name it.
    pub path: PathBuf,
    /// The main file's text.
    pub text: String,
    /// What the files describe.
    pub description: SceneDescription,
    /// Every file read, the main one first.
    pub files: SourceFiles,
}

impl SceneSource {
    /// The source of a description read from `files`.
    pub fn new(files: SourceFiles, description: SceneDescription) -> SceneSource {
        SceneSource {
            path: files.main().path.clone(),
            text: files.main().text.clone(),
            description,
            files,
        }
    }

    /// An error located in the file its span falls in.
    pub fn error(&self, error: ParseError) -> Error {
        self.files.error(error)
    }
}

/// Reads the scene file at `path`, reporting a "parse" phase to `progress`.
pub fn read_file(path: &Path, options: &ReadOptions, progress: &dyn Progress) -> Result<SceneSource> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_FILE_BYTES {
        return Err(Error::InvalidSettings(format!(
            "{}: {size} bytes is more than caustica reads",
            path.display()
        )));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let dir = path.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let dir = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir
    };
    if options.format_of(path) == Format::Gltf {
        return gltf::read(path, bytes, &dir, progress);
    }
    let (text, bad) = decode_text(bytes);
    match bad {
        // Exporters on Windows write OBJ names in the local code page: read, with a warning.
        Some(offset) if options.format_of(path) == Format::Obj => {
            let mut source = read_text(path, text, &dir, options, progress)?;
            source
                .description
                .warnings
                .insert(0, (NOT_UTF8.into(), offset..offset + 1));
            Ok(source)
        }
        Some(offset) => Err(Error::Scene {
            path: path.to_path_buf(),
            text,
            error: ParseError::new("the file is not valid UTF-8 text", offset..offset + 1),
        }),
        None => read_text(path, text, &dir, options, progress),
    }
}

/// The warning for text read with bytes that are not UTF-8.
pub(crate) const NOT_UTF8: &str = "the file is not valid UTF-8 text: bytes that are not were read as \u{FFFD}";

/// The warning for an image a texture names that is not there; the texture reads mid grey, in
/// every format that reads images by name.
pub(crate) fn missing_image(path: &std::path::Path) -> String {
    format!("the image `{}` is missing: the texture reads mid grey", path.display())
}

/// Text from bytes, those that are not UTF-8 read as U+FFFD; the offset of the first of them.
fn decode_text(bytes: Vec<u8>) -> (String, Option<usize>) {
    match String::from_utf8(bytes) {
        Ok(text) => (text, None),
        Err(e) => {
            let offset = e.utf8_error().valid_up_to();
            (String::from_utf8_lossy(e.as_bytes()).into_owned(), Some(offset))
        }
    }
}

/// Reads scene text, reporting a "parse" phase; `path` names it in errors (and chooses its
/// format unless the options do) and files it refers to resolve against `scene_dir`.
pub fn read_text(
    path: &Path,
    text: String,
    scene_dir: &Path,
    options: &ReadOptions,
    progress: &dyn Progress,
) -> Result<SceneSource> {
    match options.format_of(path) {
        Format::Ray => {
            let mut files = SourceFiles::new(path, text);
            let parsed = ray_file::parse_reporting(&files.main().text.clone(), scene_dir, &options.ray, progress)
                .and_then(|scene| scene.into_description(&mut files, scene_dir));
            match parsed {
                Ok(description) => Ok(SceneSource::new(files, description)),
                Err(error) => Err(files.error(error)),
            }
        }
        Format::Pbrt => pbrt::read(path, text, scene_dir, progress),
        Format::Obj => obj::read_scene(path, text, scene_dir, &options.obj, progress),
        Format::Gltf => gltf::read(path, text.into_bytes(), scene_dir, progress),
    }
}
