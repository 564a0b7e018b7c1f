//! `skybox { front = "…"; back; left; right; top; bottom; }` (an HKUST team fork,
//! COMP4411-Team/Trace) or with the faces named `posx`, `negx`, `posy`, `negy`, `posz`, `negz`:
//! six images seen from inside a box around the scene (docs/scene-format.md), for both readers.

use super::ast::{LightDesc, Span};
use crate::description::SkyboxLayout;
use crate::ParseError;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The face keys, each with the index of the direction it looks along (+x, −x, +y, −y, +z, −z).
const FACES: &[(&str, usize)] = &[
    ("right", 0),
    ("left", 1),
    ("top", 2),
    ("bottom", 3),
    ("back", 4),
    ("front", 5),
    ("posx", 0),
    ("negx", 1),
    ("posy", 2),
    ("negy", 3),
    ("posz", 4),
    ("negz", 5),
];

/// Every field of a `skybox` block.
pub(crate) const SKYBOX_FIELDS: &[&str] = &[
    "front", "back", "left", "right", "top", "bottom", "posx", "negx", "posy", "negy", "posz", "negz", "color",
    "colour",
];

/// The values of a `skybox` block as read.
#[derive(Default)]
pub(crate) struct SkyboxFields {
    faces: [Option<(String, PathBuf, Span)>; 6],
    color: Option<Vec3>,
    /// Remarks for the scene's warnings.
    pub warnings: Vec<(String, Span)>,
}

impl SkyboxFields {
    /// `key = "file"`; the path resolves against `scene_dir` (see [`resolve`]).
    pub fn face(&mut self, key: &str, file: &str, scene_dir: &Path, span: Span) -> Result<(), ParseError> {
        let (_, index) = FACES.iter().find(|(k, _)| *k == key).copied().expect("a face key");
        if let Some((other, ..)) = &self.faces[index] {
            return Err(ParseError::new(
                format!("`{key}` and `{other}` name the same face of the skybox"),
                span,
            ));
        }
        let (path, note) = resolve(scene_dir, file);
        if let Some(note) = note {
            self.warnings.push((note, span.clone()));
        }
        self.faces[index] = Some((key.to_string(), path, span));
        Ok(())
    }

    /// `color = (r, g, b)`: a scale on the images.
    pub fn color(&mut self, color: Vec3, span: Span) -> Result<(), ParseError> {
        if self.color.replace(color).is_some() {
            return Err(ParseError::new("the skybox has a second `color`", span));
        }
        Ok(())
    }

    /// The skybox, once all six faces are named.
    pub fn finish(self, block: Span) -> Result<LightDesc, ParseError> {
        let names = [
            "right (posx)",
            "left (negx)",
            "top (posy)",
            "bottom (negy)",
            "back (posz)",
            "front (negz)",
        ];
        let mut faces = Vec::with_capacity(6);
        for (slot, name) in self.faces.into_iter().zip(names) {
            match slot {
                Some((_, path, _)) => faces.push(path),
                None => {
                    return Err(ParseError::new(format!("the skybox needs its `{name}` face"), block)
                        .with_help("a skybox names six images: front, back, left, right, top and bottom"))
                }
            }
        }
        Ok(LightDesc::Skybox {
            faces: faces.try_into().expect("six faces"),
            layout: SkyboxLayout::Inside,
            color: self.color.unwrap_or(Vec3::ONE),
            span: block,
        })
    }
}

/// Where a skybox image named `file` is: against the scene's folder, with `\` read as a
/// folder separator (the fork ran on Windows) and, when that file is missing, the shortest
/// tail of the path that exists there (the fork named images from its project's root). The
/// note says which file was taken instead of the one written.
fn resolve(scene_dir: &Path, file: &str) -> (PathBuf, Option<String>) {
    let normal = file.replace('\\', "/");
    let parts: Vec<&str> = normal.split('/').filter(|p| !p.is_empty() && *p != ".").collect();
    let written = scene_dir.join(parts.join("/"));
    if written.exists() || parts.len() < 2 {
        return (written, None);
    }
    for skip in 1..parts.len() {
        let tail = parts[skip..].join("/");
        let candidate = scene_dir.join(&tail);
        if candidate.is_file() {
            return (
                candidate,
                Some(format!(
                    "skybox image `{file}` is not beside the scene; using `{tail}`, which is"
                )),
            );
        }
    }
    (written, None)
}
