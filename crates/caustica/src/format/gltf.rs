//! glTF 2.0 (`.gltf` JSON and `.glb` binary): the node hierarchy's meshes, perspective camera
//! and `KHR_lights_punctual` lights, with metallic-roughness materials and their transmission,
//! index, volume, specular, emissive-strength and dispersion extensions mapped to both models
//! (docs/scene-formats.md).
//!
//! The `gltf` crate parses and validates the JSON (its schema types); buffers and accessors are
//! read here, every offset and count checked first, so no malformed file can index out of
//! range. Errors name the JSON path and point at it in the file (for `.glb`, in its JSON chunk).

use super::{SceneSource, SourceFiles};
use crate::description::{
    repair_vertex_attributes, Alpha, CameraDesc, ClearCoat, ClearCoatMaps, Coating, EmittingFaces, FovAxis, ImageMap,
    ImageSource, LightDesc, MaterialDesc, MetallicRoughness, NormalMap, ObjectDesc, Param, PhysicalMaterial,
    SceneDescription, ShapeDesc, TrimeshDesc, SMOOTH_ALPHA,
};
use crate::error::{Error, ParseError, Result, Span};
use crate::progress::Progress;
use crate::texture::{Encoding, Wrap};
use ::gltf::json;
use glam::{Affine2, Mat3, Mat4, Quat, Vec2, Vec3, Vec4};
use json::validation::{Checked, Validate};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// Lumens per watt: glTF lights are photometric (candela, lux); Blender's exporter multiplies
/// its watts by this, so dividing gives back radiometric intensity and irradiance.
pub const LUMENS_PER_WATT: f32 = 683.0;
/// Node trees deeper than this are refused (a cycle would recurse forever).
const MAX_DEPTH: usize = 256;
/// Largest element count accepted from one accessor.
const MAX_COUNT: u64 = 1 << 28;

/// Extensions caustica reads (or reads in part) even when a file requires them.
const READ_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_materials_dispersion",
    "KHR_materials_clearcoat",
    "KHR_texture_transform",
];

/// Extensions that need no warning when unread: images caustica cannot decode (each such
/// image gets its own warning) and metadata, which changes nothing in the picture.
const UNSAID_EXTENSIONS: &[&str] = &["KHR_texture_basisu", "EXT_texture_webp", "KHR_xmp", "KHR_xmp_json_ld"];

/// Reads a glTF or GLB file's bytes.
pub fn read(path: &Path, bytes: Vec<u8>, dir: &Path, progress: &dyn Progress) -> Result<SceneSource> {
    progress.start("parse", bytes.len() as u64);
    let result = read_inner(path, &bytes, dir);
    progress.advance(bytes.len() as u64);
    progress.finish();
    result
}

fn read_inner(path: &Path, bytes: &[u8], dir: &Path) -> Result<SceneSource> {
    let glb = bytes.starts_with(b"glTF");
    let json_text = if glb {
        match ::gltf::binary::Glb::from_slice(bytes) {
            Ok(g) => String::from_utf8_lossy(&g.json).into_owned(),
            Err(e) => {
                return Err(Error::Scene {
                    path: path.to_path_buf(),
                    text: String::new(),
                    error: ParseError::new(format!("not a valid GLB file: {e}"), 0..0),
                })
            }
        }
    } else {
        String::from_utf8_lossy(bytes).into_owned()
    };
    let mut files = SourceFiles::new(path, json_text);
    let located = |files: &SourceFiles, e: ParseError| files.error(e);
    let gltf = match ::gltf::Gltf::from_slice_without_validation(bytes) {
        Ok(g) => g,
        Err(::gltf::Error::Deserialize(e)) => {
            let offset = offset_of(&files.main().text, e.line(), e.column());
            let what = if glb { " (in the GLB's JSON chunk)" } else { "" };
            return Err(located(
                &files,
                ParseError::new(format!("invalid glTF JSON{what}: {e}"), offset..offset + 1),
            ));
        }
        Err(e) => return Err(located(&files, ParseError::new(format!("invalid glTF: {e}"), 0..0))),
    };
    let root = gltf.document.as_json();
    // The crate's own checks, except that it refuses required extensions it does not parse
    // itself (volume, dispersion), which caustica reads.
    let mut problems = Vec::new();
    // The crate's validation indexes a primitive's POSITION accessor unchecked: check it first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(json::mesh::Semantic::Positions));
            if position.is_some_and(|i| i.value() >= root.accessors.len()) {
                let path = json::Path::new().field("meshes").index(m).field("primitives").index(p);
                problems.push((
                    path.field("attributes").key("POSITION"),
                    json::validation::Error::IndexOutOfBounds,
                ));
            }
        }
    }
    if problems.is_empty() {
        root.validate(root, json::Path::new, &mut |path, error| problems.push((path(), error)));
    }
    for (path, error) in problems {
        if let json::validation::Error::Unsupported = error {
            if path.as_str().starts_with("extensionsRequired") {
                continue;
            }
        }
        let span = locate(&files.main().text, path.as_str());
        return Err(located(
            &files,
            ParseError::new(format!("{}: {}", path.as_str(), describe(&error)), span),
        ));
    }
    for (i, name) in root.extensions_required.iter().enumerate() {
        if !READ_EXTENSIONS.contains(&name.as_str()) {
            let span = locate(&files.main().text, &format!("extensionsRequired[{i}]"));
            return Err(located(
                &files,
                ParseError::new(format!("the file requires {name}, which caustica does not read"), span),
            ));
        }
    }
    let mut reader = Reader {
        root,
        files: &mut files,
        dir: dir.to_path_buf(),
        buffers: Vec::new(),
        desc: SceneDescription::default(),
        said: HashSet::new(),
    };
    let result = reader.read(gltf.blob.as_deref());
    match result {
        Ok(desc) => Ok(SceneSource::new(files, desc)),
        Err(e) => Err(files.error(e)),
    }
}

fn describe(error: &json::validation::Error) -> &'static str {
    use json::validation::Error::*;
    match error {
        IndexOutOfBounds => "index out of bounds",
        Invalid => "invalid value",
        Missing => "required value missing",
        Oversize => "size too large",
        Unsupported => "not supported",
    }
}

/// The byte offset of a 1-based line and column.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut offset = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            return (offset + column.saturating_sub(1)).min(text.len());
        }
        offset += l.len();
    }
    text.len()
}

/// The span of the value at a JSON path (`meshes[0].primitives[1].attributes["POSITION"]`)
/// in `text`; as far as it can be followed.
pub fn locate(text: &str, path: &str) -> Span {
    let bytes = text.as_bytes();
    let mut pos = skip_ws(bytes, 0);
    let mut found = pos..value_end(bytes, pos);
    for segment in path_segments(path) {
        let next = match &segment {
            Segment::Key(k) => member(bytes, pos, k),
            Segment::Index(i) => element(bytes, pos, *i),
        };
        match next {
            Some(p) => {
                pos = p;
                found = p..value_end(bytes, p);
            }
            None => break,
        }
    }
    found.start..found.end.max(found.start + 1).min(text.len().max(found.start + 1))
}

enum Segment {
    Key(String),
    Index(usize),
}

fn path_segments(path: &str) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut chars = path.chars().peekable();
    let mut word = String::new();
    while let Some(c) = chars.next() {
        match c {
            '.' => {
                if !word.is_empty() {
                    out.push(Segment::Key(std::mem::take(&mut word)));
                }
            }
            '[' => {
                if !word.is_empty() {
                    out.push(Segment::Key(std::mem::take(&mut word)));
                }
                let mut inner = String::new();
                for c in chars.by_ref() {
                    if c == ']' {
                        break;
                    }
                    inner.push(c);
                }
                match inner.trim_matches('"').parse::<usize>() {
                    Ok(i) if !inner.starts_with('"') => out.push(Segment::Index(i)),
                    _ => out.push(Segment::Key(inner.trim_matches('"').to_string())),
                }
            }
            c => word.push(c),
        }
    }
    if !word.is_empty() {
        out.push(Segment::Key(word));
    }
    out
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// One past the end of the JSON value starting at `i`.
fn value_end(b: &[u8], i: usize) -> usize {
    let mut i = skip_ws(b, i);
    if i >= b.len() {
        return b.len();
    }
    match b[i] {
        b'"' => string_end(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'"' => {
                        i = string_end(b, i);
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            return i + 1;
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
            b.len()
        }
        _ => {
            while i < b.len() && !matches!(b[i], b',' | b'}' | b']') && !b[i].is_ascii_whitespace() {
                i += 1;
            }
            i
        }
    }
}

fn string_end(b: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    b.len()
}

/// The start of member `key`'s value in the object at `i`.
fn member(b: &[u8], i: usize, key: &str) -> Option<usize> {
    let mut i = skip_ws(b, i);
    if b.get(i) != Some(&b'{') {
        return None;
    }
    i += 1;
    loop {
        i = skip_ws(b, i);
        if b.get(i) != Some(&b'"') {
            return None;
        }
        let end = string_end(b, i);
        let name = std::str::from_utf8(&b[i + 1..end.saturating_sub(1).max(i + 1)]).ok()?;
        i = skip_ws(b, end);
        if b.get(i) != Some(&b':') {
            return None;
        }
        let value = skip_ws(b, i + 1);
        if name == key {
            return Some(value);
        }
        i = skip_ws(b, value_end(b, value));
        if b.get(i) != Some(&b',') {
            return None;
        }
        i += 1;
    }
}

/// The start of element `index` in the array at `i`.
fn element(b: &[u8], i: usize, index: usize) -> Option<usize> {
    let mut i = skip_ws(b, i);
    if b.get(i) != Some(&b'[') {
        return None;
    }
    i += 1;
    for k in 0.. {
        i = skip_ws(b, i);
        if b.get(i) == Some(&b']') {
            return None;
        }
        if k == index {
            return Some(i);
        }
        i = skip_ws(b, value_end(b, i));
        if b.get(i) != Some(&b',') {
            return None;
        }
        i += 1;
    }
    None
}

struct Reader<'a, 'f> {
    root: &'a json::Root,
    files: &'f mut SourceFiles,
    dir: PathBuf,
    buffers: Vec<Option<Vec<u8>>>,
    desc: SceneDescription,
    said: HashSet<String>,
}

impl Reader<'_, '_> {
    /// An error at a JSON path.
    fn error(&self, path: &str, message: impl std::fmt::Display) -> ParseError {
        ParseError::new(format!("{path}: {message}"), locate(&self.files.main().text, path))
    }

    fn warn(&mut self, path: &str, message: impl std::fmt::Display) {
        let span = locate(&self.files.main().text, path);
        self.desc.warnings.push((format!("{path}: {message}"), span));
    }

    fn warn_once(&mut self, key: &str, path: &str, message: impl std::fmt::Display) {
        if self.said.insert(key.to_string()) {
            self.warn(path, message);
        }
    }

    fn read(&mut self, blob: Option<&[u8]>) -> Result<SceneDescription, ParseError> {
        self.desc.hints.physical = true;
        // Every extension the file uses and caustica does not render is said (sheen,
        // iridescence, anisotropy, …): the picture may differ from the author's there.
        let unread: Vec<(usize, String)> = self
            .root
            .extensions_used
            .iter()
            .enumerate()
            .filter(|(_, name)| {
                !READ_EXTENSIONS.contains(&name.as_str()) && !UNSAID_EXTENSIONS.contains(&name.as_str())
            })
            .map(|(i, name)| (i, name.clone()))
            .collect();
        for (i, name) in unread {
            self.warn_once(
                &format!("extension {name}"),
                &format!("extensionsUsed[{i}]"),
                format!("{name} is not rendered: the file renders without it"),
            );
        }
        for (i, buffer) in self.root.buffers.iter().enumerate() {
            let path = format!("buffers[{i}]");
            let data = match &buffer.uri {
                None if i == 0 => blob.map(<[u8]>::to_vec),
                None => None,
                Some(uri) => Some(self.load_uri(uri, &format!("{path}.uri"))?),
            };
            let Some(data) = data else {
                return Err(self.error(&path, "the buffer has no data (no uri and no GLB binary chunk)"));
            };
            if (data.len() as u64) < buffer.byte_length.0 {
                return Err(self.error(
                    &path,
                    format!(
                        "byteLength is {} but the data has {} bytes",
                        buffer.byte_length.0,
                        data.len()
                    ),
                ));
            }
            self.buffers.push(Some(data));
        }
        for skin in 0..self.root.skins.len().min(1) {
            self.warn(
                &format!("skins[{skin}]"),
                "skins are not applied: meshes are drawn in their bind pose",
            );
        }
        if !self.root.animations.is_empty() {
            self.warn(
                "animations",
                "animations are not played: the scene is drawn as it stands",
            );
        }
        let roots: Vec<usize> = match self
            .root
            .scene
            .map(|s| s.value())
            .or((!self.root.scenes.is_empty()).then_some(0))
        {
            Some(s) => self.root.scenes[s].nodes.iter().map(|n| n.value()).collect(),
            None => {
                // No scene: every node that is nobody's child.
                let children: HashSet<usize> = self
                    .root
                    .nodes
                    .iter()
                    .flat_map(|n| n.children.iter().flatten().map(|c| c.value()))
                    .collect();
                (0..self.root.nodes.len()).filter(|i| !children.contains(i)).collect()
            }
        };
        let mut stack: Vec<(usize, Mat4, usize)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, 0)).collect();
        let mut visited = HashSet::new();
        while let Some((index, parent, depth)) = stack.pop() {
            let path = format!("nodes[{index}]");
            if depth > MAX_DEPTH || !visited.insert((index, depth)) && depth > 0 {
                return Err(self.error(&path, "the node hierarchy is too deep or has a cycle"));
            }
            let node = &self.root.nodes[index];
            let world = parent * local_matrix(node);
            if !world.is_finite() {
                return Err(self.error(&path, "the node's transform is not finite"));
            }
            if let Some(mesh) = node.mesh {
                self.mesh(mesh.value(), world, &path)?;
            }
            if let Some(camera) = node.camera {
                self.camera(camera.value(), world, &path);
            }
            if let Some(light) = node.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) {
                self.light(light.light.value(), world, &path)?;
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world, depth + 1));
            }
        }
        if self.desc.camera.is_none() && !self.desc.objects.is_empty() {
            self.warn("cameras", "the scene has no camera: one is placed to frame it from +z");
            self.desc.camera = Some(super::obj::frame(&self.desc.objects));
        }
        // Uniform emission lights a scene; an emissive texture (a screen, a dial, a sign) decorates
        // a model its viewer lights.
        let lit_by_emission = self.desc.objects.iter().any(|o| match &o.material.emissive {
            Param::Constant(c) => c.max_element() > 0.0,
            _ => false,
        });
        let decorated = self
            .desc
            .objects
            .iter()
            .any(|o| matches!(o.material.emissive, Param::Texture(_)));
        if self.desc.lights.is_empty() && !lit_by_emission && !self.desc.objects.is_empty() {
            // Many files leave lighting to the viewer; a viewer's neutral default.
            // A remark on the whole file: no place in it (an empty span at 0).
            let message = if decorated {
                "the scene has no lights but emissive textures: a uniform white sky of radiance 1 lights it"
            } else {
                "the scene has no lights: a uniform white sky of radiance 1 lights it"
            };
            self.desc.warnings.push((message.into(), 0..0));
            self.desc.lights.push(LightDesc::Environment {
                color: Vec3::ONE,
                map: None,
                rotation: glam::Mat3::IDENTITY,
                equal_area: false,
                span: 0..0,
            });
        }
        Ok(std::mem::take(&mut self.desc))
    }

    fn load_uri(&mut self, uri: &str, path: &str) -> Result<Vec<u8>, ParseError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((_, data)) = rest.split_once(";base64,") else {
                return Err(self.error(path, "only base64 data URIs are read"));
            };
            return base64(data).ok_or_else(|| self.error(path, "the data URI is not valid base64"));
        }
        let file = self.dir.join(percent_decode(uri));
        let span = locate(&self.files.main().text, path);
        SourceFiles::read_bytes(&file, &span)
    }

    /// The bytes an accessor's elements lie in: (data, offset of element 0, stride, count).
    fn accessor_data(&self, index: usize, comps: usize, path: &str) -> Result<(Vec<f32>, usize), ParseError> {
        let a = &self.root.accessors[index];
        let apath = format!("accessors[{index}]");
        let Checked::Valid(ty) = a.type_ else {
            return Err(self.error(&apath, "invalid type"));
        };
        let n = match ty {
            json::accessor::Type::Scalar => 1,
            json::accessor::Type::Vec2 => 2,
            json::accessor::Type::Vec3 => 3,
            json::accessor::Type::Vec4 => 4,
            _ => return Err(self.error(&apath, format!("{path} cannot be a matrix"))),
        };
        if comps != 0 && n != comps {
            return Err(self.error(
                &apath,
                format!("{path} needs {comps} components per element, the accessor has {n}"),
            ));
        }
        let Checked::Valid(json::accessor::GenericComponentType(ct)) = a.component_type else {
            return Err(self.error(&apath, "invalid componentType"));
        };
        use json::accessor::ComponentType as C;
        let size = match ct {
            C::I8 | C::U8 => 1,
            C::I16 | C::U16 => 2,
            C::U32 | C::F32 => 4,
        };
        let count = a.count.0;
        if count > MAX_COUNT {
            return Err(self.error(&apath, format!("count {count} is too large")));
        }
        let count = count as usize;
        if a.sparse.is_some() {
            return Err(self.error(&apath, "sparse accessors are not read"));
        }
        let Some(view_index) = a.buffer_view else {
            // No buffer view: all zeros, as the specification says.
            return Ok((vec![0.0; count * n], n));
        };
        let view = &self.root.buffer_views[view_index.value()];
        let vpath = format!("bufferViews[{}]", view_index.value());
        let buffer = self.buffers.get(view.buffer.value()).and_then(|b| b.as_ref());
        let Some(buffer) = buffer else {
            return Err(self.error(&vpath, "its buffer has no data"));
        };
        let view_offset = view.byte_offset.map_or(0, |o| o.0);
        let view_end = view_offset.checked_add(view.byte_length.0);
        if !matches!(view_end, Some(end) if end <= buffer.len() as u64) {
            return Err(self.error(&vpath, "the view runs past the end of its buffer"));
        }
        let element = size * n;
        let stride = view.byte_stride.map_or(element, |s| s.0);
        if stride < element {
            return Err(self.error(
                &vpath,
                format!("byteStride {stride} is smaller than an element ({element} bytes)"),
            ));
        }
        let start = a.byte_offset.map_or(0, |o| o.0);
        let needed = if count == 0 {
            0
        } else {
            start + (stride as u64) * (count as u64 - 1) + element as u64
        };
        if needed > view.byte_length.0 {
            return Err(self.error(
                &apath,
                format!(
                    "{count} elements need {needed} bytes of a view of {}",
                    view.byte_length.0
                ),
            ));
        }
        let data = &buffer[view_offset as usize..(view_offset + view.byte_length.0) as usize];
        let mut out = Vec::with_capacity(count * n);
        for i in 0..count {
            let at = start as usize + i * stride;
            for c in 0..n {
                let b = &data[at + c * size..at + (c + 1) * size];
                let v = match ct {
                    C::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                    C::U16 => u16::from_le_bytes([b[0], b[1]]) as f32 / if a.normalized { 65535.0 } else { 1.0 },
                    C::I16 => {
                        let v = i16::from_le_bytes([b[0], b[1]]) as f32;
                        if a.normalized {
                            (v / 32767.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                    C::U8 => b[0] as f32 / if a.normalized { 255.0 } else { 1.0 },
                    C::I8 => {
                        let v = (b[0] as i8) as f32;
                        if a.normalized {
                            (v / 127.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                };
                // Not-finite attributes are repaired once the primitive is whole.
                out.push(v);
            }
        }
        Ok((out, n))
    }

    /// Vertex indices (exact integers).
    fn indices(&self, index: usize, vertices: usize, path: &str) -> Result<Vec<u32>, ParseError> {
        let a = &self.root.accessors[index];
        use json::accessor::ComponentType as C;
        if !matches!(
            a.component_type,
            Checked::Valid(json::accessor::GenericComponentType(C::U8 | C::U16 | C::U32))
        ) {
            return Err(self.error(&format!("accessors[{index}]"), "indices must be unsigned integers"));
        }
        // u32 indices above 2^24 do not survive f32: read them as integers.
        let (values, _) = self.accessor_raw_u32(index, path)?;
        if let Some(bad) = values.iter().find(|&&i| i as usize >= vertices) {
            return Err(self.error(
                path,
                format!("index {bad} is out of range: the primitive has {vertices} vertices"),
            ));
        }
        Ok(values)
    }

    fn accessor_raw_u32(&self, index: usize, path: &str) -> Result<(Vec<u32>, usize), ParseError> {
        let a = &self.root.accessors[index];
        let is_u32 = matches!(
            a.component_type,
            Checked::Valid(json::accessor::GenericComponentType(json::accessor::ComponentType::U32))
        );
        if !is_u32 {
            let (v, n) = self.accessor_data(index, 1, path)?;
            return Ok((v.into_iter().map(|x| x as u32).collect(), n));
        }
        // Same checks as floats, then exact reads.
        self.accessor_data(index, 1, path)?;
        let Some(view_index) = a.buffer_view else {
            return Ok((vec![0; a.count.0 as usize], 1));
        };
        let view = &self.root.buffer_views[view_index.value()];
        let Some(buffer) = self.buffers.get(view.buffer.value()).and_then(|b| b.as_ref()) else {
            return Ok((vec![0; a.count.0 as usize], 1));
        };
        let base = (view.byte_offset.map_or(0, |o| o.0) + a.byte_offset.map_or(0, |o| o.0)) as usize;
        let stride = view.byte_stride.map_or(4, |s| s.0);
        Ok((
            (0..a.count.0 as usize)
                .map(|i| {
                    let b = &buffer[base + i * stride..base + i * stride + 4];
                    u32::from_le_bytes([b[0], b[1], b[2], b[3]])
                })
                .collect(),
            1,
        ))
    }

    fn mesh(&mut self, index: usize, world: Mat4, node_path: &str) -> Result<(), ParseError> {
        let mesh = &self.root.meshes[index];
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let path = format!("meshes[{index}].primitives[{p}]");
            let mode = match primitive.mode {
                Checked::Valid(m) => m,
                Checked::Invalid => return Err(self.error(&path, "invalid mode")),
            };
            use json::mesh::Mode;
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warn(&format!("{path}.mode"), "points and lines are not drawn");
                continue;
            }
            let mut position = None;
            let mut normal = None;
            let mut uv = None;
            let mut tangent = None;
            for (semantic, accessor) in &primitive.attributes {
                match semantic {
                    Checked::Valid(json::mesh::Semantic::Positions) => position = Some(accessor.value()),
                    Checked::Valid(json::mesh::Semantic::Normals) => normal = Some(accessor.value()),
                    Checked::Valid(json::mesh::Semantic::TexCoords(0)) => uv = Some(accessor.value()),
                    Checked::Valid(json::mesh::Semantic::Tangents) => tangent = Some(accessor.value()),
                    _ => {}
                }
            }
            let Some(position) = position else {
                return Err(self.error(&format!("{path}.attributes"), "a primitive needs POSITION"));
            };
            let (p3, _) = self.accessor_data(position, 3, &format!("{path}.attributes[\"POSITION\"]"))?;
            let points: Vec<Vec3> = p3.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
            let n = points.len();
            let normals = match normal {
                Some(a) => {
                    let (v, _) = self.accessor_data(a, 3, &format!("{path}.attributes[\"NORMAL\"]"))?;
                    (v.len() == 3 * n).then(|| v.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
                }
                None => None,
            };
            let uvs: Option<Vec<Vec2>> = match uv {
                Some(a) => {
                    let (v, _) = self.accessor_data(a, 2, &format!("{path}.attributes[\"TEXCOORD_0\"]"))?;
                    // glTF's v runs down the image; caustica's up.
                    (v.len() == 2 * n).then(|| v.chunks(2).map(|c| Vec2::new(c[0], 1.0 - c[1])).collect())
                }
                None => None,
            };
            // Read for normal maps; a tangent that is not finite and unit-ish is regenerated.
            let tangents: Option<Vec<Vec4>> = match tangent {
                Some(a) => {
                    let (v, _) = self.accessor_data(a, 4, &format!("{path}.attributes[\"TANGENT\"]"))?;
                    let ts: Vec<Vec4> = v.chunks(4).map(Vec4::from_slice).collect();
                    let usable = |t: &Vec4| t.is_finite() && t.truncate().length_squared() > 1e-6;
                    (ts.len() == n && ts.iter().all(usable)).then_some(ts)
                }
                None => None,
            };
            let list: Vec<u32> = match primitive.indices {
                Some(a) => self.indices(a.value(), n, &format!("{path}.indices"))?,
                None => (0..n as u32).collect(),
            };
            let mut triangles = Vec::new();
            match mode {
                Mode::Triangles => triangles.extend(list.chunks_exact(3).map(|t| [t[0], t[1], t[2]])),
                Mode::TriangleStrip => {
                    for i in 0..list.len().saturating_sub(2) {
                        let t = [list[i], list[i + 1], list[i + 2]];
                        triangles.push(if i % 2 == 0 { t } else { [t[1], t[0], t[2]] });
                    }
                }
                _ => {
                    for i in 1..list.len().saturating_sub(1) {
                        triangles.push([list[0], list[i], list[i + 1]]);
                    }
                }
            }
            triangles.retain(|t| {
                let [a, b, c] = t.map(|i| points[i as usize]);
                (b - a).cross(c - a).length_squared() > 0.0
            });
            if triangles.is_empty() {
                continue;
            }
            let (mut normals, mut uvs) = (normals, uvs);
            for warning in repair_vertex_attributes(&points, &triangles, &mut normals, &mut uvs) {
                self.warn(&format!("{path}.attributes"), warning);
            }
            let closed = is_closed(&points, &triangles);
            let mut material = self.material(primitive.material.map(|m| m.value()), closed, &path)?;
            // glTF's front is counter-clockwise, clockwise under a transform that swaps
            // handedness; caustica's is the side of the world winding's normal.
            if material.emitting_faces == EmittingFaces::Front && Mat3::from_mat4(world).determinant() < 0.0 {
                material.emitting_faces = EmittingFaces::Back;
            }
            self.desc.objects.push(ObjectDesc {
                shape: ShapeDesc::Trimesh(Box::new(TrimeshDesc {
                    points,
                    triangles,
                    normals,
                    materials: None,
                    uvs,
                    tangents,
                })),
                world_from_object: world,
                material,
                span: locate(&self.files.main().text, node_path),
            });
        }
        Ok(())
    }

    /// Both models' reading of a material (docs/scene-formats.md, "glTF").
    fn material(&mut self, index: Option<usize>, closed: bool, prim_path: &str) -> Result<MaterialDesc, ParseError> {
        let default = json::Material::default();
        let (m, path) = match index {
            Some(i) => (&self.root.materials[i], format!("materials[{i}]")),
            None => (&default, format!("{prim_path}.material")),
        };
        let pbr = &m.pbr_metallic_roughness;
        let base_factor = Vec3::from_slice(&pbr.base_color_factor.0[..3]).clamp(Vec3::ZERO, Vec3::ONE);
        let metallic = pbr.metallic_factor.0.clamp(0.0, 1.0);
        let roughness = pbr.roughness_factor.0.clamp(0.0, 1.0);
        let alpha = roughness * roughness;
        let ext = m.extensions.clone().unwrap_or_default();
        let transmission = ext
            .transmission
            .as_ref()
            .map_or(0.0, |t| t.transmission_factor.0)
            .clamp(0.0, 1.0);
        let ior = ext.ior.as_ref().map_or(1.5, |i| i.ior.0);
        let ior = if ior >= 1.0 { ior } else { 1.5 };
        // Textures of extensions read by their factors alone: said, never silently dropped.
        let unread = [
            (
                ext.transmission
                    .as_ref()
                    .is_some_and(|t| t.transmission_texture.is_some()),
                "KHR_materials_transmission.transmissionTexture",
                "the transmission texture is not read",
            ),
            (
                ext.volume.as_ref().is_some_and(|v| v.thickness_texture.is_some()),
                "KHR_materials_volume.thicknessTexture",
                "the thickness texture is not read",
            ),
        ];
        for (given, at, what) in unread {
            if given {
                self.warn_once(
                    at,
                    &format!("{path}.extensions.{at}"),
                    format!("{what}: the factor is used"),
                );
            }
        }
        let specular = ext.specular.as_ref().map_or(1.0, |s| s.specular_factor.0);
        let coat_tint = self.coat_tint(&ext, &path, transmission >= 0.5);
        // No specular layer: a factor of 0, or a colour of black (Blender's exporter writes its
        // Specular 0 so).
        let specular = if coat_tint == Param::grey(0.0) { 0.0 } else { specular };
        let emissive_strength = ext.emissive_strength.as_ref().map_or(1.0, |e| e.emissive_strength.0);
        let dispersion = ext
            .others
            .get("KHR_materials_dispersion")
            .and_then(|d| d.get("dispersion"))
            .and_then(|d| d.as_f64())
            .unwrap_or(0.0) as f32;
        let base = match &pbr.base_color_texture {
            Some(info) => self.texture(
                info,
                &format!("{path}.pbrMetallicRoughness.baseColorTexture"),
                base_factor,
            ),
            None => Param::Constant(base_factor),
        };
        // Linear data: blue is metalness, green roughness.
        let mr_texture = match &pbr.metallic_roughness_texture {
            Some(info) => {
                let mrpath = format!("{path}.pbrMetallicRoughness.metallicRoughnessTexture");
                let transform = info.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
                self.image_map(info.index.value(), info.tex_coord, transform, &mrpath)
                    .map(|mut map| {
                        map.encoding = Encoding::Linear;
                        Param::Texture(Box::new(map))
                    })
            }
            None => None,
        };
        // Glass with the texture decides metal or glass, and how rough, point by point.
        let glass_textured = transmission >= 0.5 && mr_texture.is_some();
        let normal_map = match &m.normal_texture {
            Some(n) => {
                let npath = format!("{path}.normalTexture");
                self.image_map(n.index.value(), n.tex_coord, None, &npath)
                    .map(|mut map| {
                        map.encoding = Encoding::Linear;
                        NormalMap { map, scale: n.scale }
                    })
            }
            None => None,
        };
        let emissive = Vec3::from(m.emissive_factor.0).max(Vec3::ZERO) * emissive_strength.max(0.0);
        let emissive_param = match &m.emissive_texture {
            Some(info) if emissive != Vec3::ZERO => self.texture(info, &format!("{path}.emissiveTexture"), emissive),
            _ => Param::Constant(emissive),
        };
        // Coverage: the base colour's alpha times its texture's alpha channel.
        let cutoff = match m.alpha_mode {
            Checked::Valid(json::material::AlphaMode::Mask) => Some(Some(m.alpha_cutoff.map_or(0.5, |c| c.0))),
            Checked::Valid(json::material::AlphaMode::Blend) => Some(None),
            _ => None,
        };
        let cut_outs = cutoff.map(|cutoff| {
            let factor = pbr.base_color_factor.0[3].clamp(0.0, 1.0);
            let coverage = match &base {
                Param::Texture(map) => {
                    let mut map = (**map).clone();
                    map.encoding = Encoding::Coverage;
                    map.sampler.scale = Vec3::splat(factor);
                    Param::Texture(Box::new(map))
                }
                _ => Param::grey(factor),
            };
            Alpha { coverage, cutoff }
        });
        let mut desc = MaterialDesc {
            emissive: emissive_param,
            normal_map,
            alpha: cut_outs,
            name: m.name.clone(),
            ..MaterialDesc::default()
        };
        // A single-sided material shows its front alone: an emissive one emits from it alone
        // (which face that is in the world, the node's handedness says: `primitives`).
        if emissive != Vec3::ZERO && !m.double_sided {
            desc.emitting_faces = EmittingFaces::Front;
        }
        (desc.clearcoat, desc.clearcoat_maps) = self.clearcoat(&ext, &path, transmission >= 0.5);
        if let Some(texture) = mr_texture.clone().filter(|_| !glass_textured) {
            desc.diffuse = base.clone();
            desc.metallic_roughness = Some(MetallicRoughness {
                base,
                texture,
                metallic,
                roughness,
                coat: (specular > 0.0).then_some(ior),
                coat_tint,
                glass: None,
            });
            return Ok(desc);
        }
        if metallic > 0.0 && metallic < 1.0 || transmission > 0.0 && transmission < 1.0 {
            self.warn_once(
                "fractional",
                &path,
                "metallic and transmission between 0 and 1 are read as the nearer of the two ends",
            );
        }
        if metallic >= 0.5 && !glass_textured {
            desc.physical = Some(PhysicalMaterial::Conductor {
                eta: Vec3::ONE,
                k: Vec3::ZERO,
                reflectance: Some(base.clone()),
                roughness: alpha,
            });
            let f0 = match &base {
                Param::Constant(c) => *c,
                _ => Vec3::splat(0.8),
            };
            if alpha < 1e-3 {
                desc.reflective = Param::Constant(f0);
            } else {
                desc.specular = Param::Constant(f0);
                desc.shininess = Param::grey((2.0 / (alpha * alpha) - 2.0).clamp(1.0, 10_000.0));
            }
        } else if transmission >= 0.5 {
            // The base colour tints the light that crosses, texture and all.
            let tint = base.clone();
            let thickness = ext.volume.as_ref().map(|v| v.thickness_factor.0);
            // Beer–Lambert inside: the colour light keeps after attenuationDistance (world units).
            let absorption = ext.volume.as_ref().and_then(|v| {
                let distance = v.attenuation_distance.0;
                (distance.is_finite() && distance > 0.0).then(|| {
                    let colour = Vec3::from(v.attenuation_color.0).clamp(Vec3::splat(1e-6), Vec3::ONE);
                    -Vec3::new(colour.x.ln(), colour.y.ln(), colour.z.ln()) / distance
                })
            });
            // Solid glass where the file says so (a volume of some thickness) or, without the
            // volume extension, where the mesh is closed: Blender exports glass that way.
            let solid = match thickness {
                Some(t) => t > 0.0,
                None => closed,
            };
            if absorption.is_some() && !solid {
                self.warn_once(
                    "attenuation",
                    &path,
                    "volume attenuation is not rendered in thin glass (a thickness of 0): it is clear",
                );
            }
            if solid {
                desc.absorption = absorption;
                if thickness.is_none() {
                    self.warn_once(
                        "solidglass",
                        &path,
                        "transmission without KHR_materials_volume on a closed mesh is read as solid glass",
                    );
                }
                desc.transmissive = tint.clone();
                desc.index = Param::grey(ior);
                if dispersion > 0.0 {
                    desc.abbe = Some(20.0 / dispersion);
                }
                if let Some(texture) = mr_texture {
                    desc.metallic_roughness = Some(MetallicRoughness {
                        base,
                        texture,
                        metallic,
                        roughness,
                        coat: None,
                        coat_tint: Param::grey(1.0),
                        glass: Some((ior, desc.abbe)),
                    });
                } else if alpha >= SMOOTH_ALPHA {
                    desc.physical = Some(PhysicalMaterial::RoughDielectric {
                        eta: ior,
                        roughness: alpha,
                        tint: tint.clone(),
                        abbe: desc.abbe,
                    });
                }
            } else {
                if alpha >= SMOOTH_ALPHA || glass_textured {
                    self.warn_once(
                        "roughglass",
                        &path,
                        "thin-walled transmission is rendered smooth, whatever its roughness and metalness say",
                    );
                }
                desc.transmissive = tint.clone();
                desc.index = Param::grey(1.0);
                desc.physical = Some(PhysicalMaterial::ThinDielectric {
                    eta: ior,
                    tint: tint.clone(),
                });
            }
        } else {
            desc.diffuse = base.clone();
            if specular > 0.0 {
                desc.physical = Some(PhysicalMaterial::CoatedDiffuse {
                    reflectance: base,
                    eta: ior,
                    roughness: alpha,
                    coat_tint,
                    layering: Coating::Fresnel,
                });
                let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2) * specular.min(1.0);
                if alpha < 1e-3 {
                    desc.reflective = Param::grey(f0);
                } else {
                    desc.specular = Param::grey(f0);
                    desc.shininess = Param::grey((2.0 / (alpha * alpha) - 2.0).clamp(1.0, 10_000.0));
                }
            }
        }
        Ok(desc)
    }

    /// `KHR_materials_specular` as what a dielectric's coat reflects per channel, times its
    /// Fresnel reflectance: `specularFactor` times the alpha of `specularTexture`, times
    /// `specularColorFactor` times `specularColorTexture` (sRGB). The extension tints the
    /// reflectance at normal incidence (F0) where caustica tints F(θ): the same at normal
    /// incidence, and a coloured tint stays coloured towards grazing, where the extension's
    /// tends to white. Metals take no
    /// specular layer (as the extension says), nor does glass (a warning when the extension
    /// would change it).
    fn coat_tint(&mut self, ext: &json::extensions::material::Material, path: &str, glass: bool) -> Param {
        let Some(s) = ext.specular.as_ref() else {
            return Param::grey(1.0);
        };
        let at = format!("{path}.extensions.KHR_materials_specular");
        let factor = Vec3::from(s.specular_color_factor.0).max(Vec3::ZERO) * s.specular_factor.0.max(0.0);
        let textured = s.specular_texture.is_some() || s.specular_color_texture.is_some();
        if glass {
            if factor != Vec3::ONE || textured {
                self.warn_once(
                    "KHR_materials_specular",
                    &at,
                    "a specular layer on glass is not rendered: its index alone sets its reflectance",
                );
            }
            return Param::grey(1.0);
        }
        match (&s.specular_texture, &s.specular_color_texture) {
            (weight, Some(colour)) => {
                if weight.is_some() {
                    self.warn_once(
                        "specularTexture",
                        &format!("{at}.specularTexture"),
                        "with a specular colour texture the specular texture is read by its factor",
                    );
                }
                self.texture(colour, &format!("{at}.specularColorTexture"), factor)
            }
            (Some(weight), None) => {
                let wpath = format!("{at}.specularTexture");
                let transform = weight.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
                match self.image_map(weight.index.value(), weight.tex_coord, transform, &wpath) {
                    // The weight is the texture's alpha, linear.
                    Some(mut map) => {
                        map.encoding = Encoding::Coverage;
                        map.sampler.scale = factor;
                        Param::Texture(Box::new(map))
                    }
                    None => Param::Constant(factor),
                }
            }
            (None, None) => Param::Constant(factor),
        }
    }

    /// `KHR_materials_clearcoat`: a clear coat of index 1.5 (the extension's), `clearcoatFactor`
    /// times the red of `clearcoatTexture` thick and `clearcoatRoughnessFactor` times the green
    /// of `clearcoatRoughnessTexture` rough (GGX α its square), both textures linear. The coat's
    /// normal texture is not read, and a coat on glass is not rendered (warnings).
    fn clearcoat(
        &mut self,
        ext: &json::extensions::material::Material,
        path: &str,
        transmissive: bool,
    ) -> (Option<ClearCoat>, Option<ClearCoatMaps>) {
        let Some(coat) = ext.others.get("KHR_materials_clearcoat") else {
            return (None, None);
        };
        let at = format!("{path}.extensions.KHR_materials_clearcoat");
        let number = |name: &str, default: f64| coat.get(name).and_then(|v| v.as_f64()).unwrap_or(default) as f32;
        let weight = number("clearcoatFactor", 0.0).clamp(0.0, 1.0);
        let roughness = number("clearcoatRoughnessFactor", 0.0).clamp(0.0, 1.0);
        if weight <= 0.0 {
            return (None, None);
        }
        if coat.get("clearcoatNormalTexture").is_some() {
            self.warn_once(
                "clearcoatnormal",
                &format!("{at}.clearcoatNormalTexture"),
                "the clear coat's normal texture is not read: the coat follows the base's normal",
            );
        }
        if transmissive {
            self.warn_once(
                "clearcoatglass",
                &at,
                "a clear coat on transmissive glass is not rendered",
            );
        }
        let maps = ClearCoatMaps {
            weight: self.extension_texture(coat.get("clearcoatTexture"), &format!("{at}.clearcoatTexture"), weight),
            roughness: self.extension_texture(
                coat.get("clearcoatRoughnessTexture"),
                &format!("{at}.clearcoatRoughnessTexture"),
                roughness,
            ),
        };
        let coat = ClearCoat {
            weight,
            eta: 1.5,
            alpha: roughness * roughness,
        };
        (
            Some(coat),
            (maps.weight.is_some() || maps.roughness.is_some()).then_some(maps),
        )
    }

    /// A linear data texture named in an extension the glTF crate leaves as JSON (`value`, at
    /// JSON path `path`), times `factor`; `None` (with a warning when something was given)
    /// where it cannot be used.
    fn extension_texture(&mut self, value: Option<&json::Value>, path: &str, factor: f32) -> Option<Param> {
        let info = match json::deserialize::from_value::<json::texture::Info>(value?.clone()) {
            Ok(info) if info.index.value() < self.root.textures.len() => info,
            _ => {
                self.warn(path, "not a valid texture reference: the factor is used");
                return None;
            }
        };
        let transform = info.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
        let mut map = self.image_map(info.index.value(), info.tex_coord, transform, path)?;
        map.encoding = Encoding::Linear;
        map.sampler.scale = Vec3::splat(factor);
        Some(Param::Texture(Box::new(map)))
    }

    /// A colour texture (`info` at JSON path `path`) times `factor`, sRGB-decoded: its image
    /// from a file, a data URI or a buffer view (a GLB's binary chunk), with the texture's
    /// sampler and `KHR_texture_transform`. An image that cannot be used (KTX2, WebP, a
    /// missing file) is a warning, and the factor stands in for the texture.
    fn texture(&mut self, info: &json::texture::Info, path: &str, factor: Vec3) -> Param {
        let transform = info.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
        let Some(mut map) = self.image_map(info.index.value(), info.tex_coord, transform, path) else {
            return Param::Constant(factor);
        };
        map.sampler.scale = factor;
        Param::Texture(Box::new(map))
    }

    /// Texture `index` as an sRGB colour map with its sampler and transform; `None` (with a
    /// warning) when its image cannot be used.
    fn image_map(
        &mut self,
        index: usize,
        tex_coord: u32,
        transform: Option<&json::extensions::texture::TextureTransform>,
        path: &str,
    ) -> Option<ImageMap> {
        let tex_coord = transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord);
        let texture = self.root.textures.get(index)?;
        let image = texture.source.value();
        let source = self.image_source(image, path)?;
        if tex_coord != 0 {
            self.warn_once(
                "texcoord",
                path,
                format!("texture coordinate set {tex_coord} is not read: TEXCOORD_0 is used"),
            );
        }
        let mut map = ImageMap::colour(source, locate(&self.files.main().text, path));
        if let Some(sampler) = texture.sampler.and_then(|i| self.root.samplers.get(i.value())) {
            use json::texture::{MagFilter, WrappingMode};
            let wrap = |mode: &Checked<WrappingMode>| match mode {
                Checked::Valid(WrappingMode::ClampToEdge) => Wrap::Clamp,
                Checked::Valid(WrappingMode::MirroredRepeat) => Wrap::Mirror,
                _ => Wrap::Repeat,
            };
            map.sampler.wrap = [wrap(&sampler.wrap_s), wrap(&sampler.wrap_t)];
            map.sampler.nearest = matches!(sampler.mag_filter, Some(Checked::Valid(MagFilter::Nearest)));
        }
        // glTF's v runs down the image and the reader flipped it (v ↦ 1 − v): the transform,
        // written for glTF's coordinates, is conjugated by that flip.
        if let Some(t) = transform {
            let (offset, scale, rotation) = (Vec2::from(t.offset.0), Vec2::from(t.scale.0), t.rotation.0);
            let (sin, cos) = rotation.sin_cos();
            // T · R · S, R = [[cos, sin], [−sin, cos]] (the extension's definition).
            let gltf = Affine2::from_cols(Vec2::new(cos, -sin) * scale.x, Vec2::new(sin, cos) * scale.y, offset);
            let flip = Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y);
            map.sampler.transform = flip * gltf * flip;
        }
        Some(map)
    }

    /// Where image `image`'s bytes are, or `None` with a warning naming `path` when the image
    /// cannot be read (a format caustica does not decode, a missing file or buffer).
    fn image_source(&mut self, image: usize, path: &str) -> Option<ImageSource> {
        let entry = self.root.images.get(image)?;
        let mime = entry.mime_type.as_ref().map(|m| m.0.to_ascii_lowercase());
        let uri = entry.uri.clone();
        let name = format!("{}#images[{image}]", self.files.main().path.display());
        let ext = uri
            .as_deref()
            .and_then(|u| u.rsplit('.').next())
            .map(str::to_ascii_lowercase);
        let unread = match (mime.as_deref(), ext.as_deref()) {
            (Some("image/ktx2"), _) | (_, Some("ktx2")) => Some("KTX2"),
            (Some("image/webp"), _) | (_, Some("webp")) => Some("WebP"),
            _ => None,
        };
        if let Some(kind) = unread {
            let what = uri.clone().unwrap_or(name);
            self.warn(
                path,
                format!("{kind} images are not read (`{what}`): the factor is used instead"),
            );
            return None;
        }
        match (uri, entry.buffer_view) {
            (Some(uri), _) if uri.starts_with("data:") => match self.load_uri(&uri, &format!("images[{image}].uri")) {
                Ok(bytes) => Some(ImageSource::Memory {
                    name,
                    bytes: bytes.into(),
                }),
                Err(e) => {
                    self.warn(path, format!("{}: the factor is used instead", e.message));
                    None
                }
            },
            (Some(uri), _) => {
                let file = self.dir.join(percent_decode(&uri));
                if !file.is_file() {
                    self.warn(
                        &format!("images[{image}].uri"),
                        format!("the image `{}` is missing: the factor is used instead", file.display()),
                    );
                    return None;
                }
                Some(ImageSource::File(file))
            }
            (None, Some(view)) => match self.view_bytes(view.value()) {
                Some(bytes) => Some(ImageSource::Memory {
                    name,
                    bytes: bytes.into(),
                }),
                None => {
                    self.warn(
                        &format!("images[{image}].bufferView"),
                        "the image's buffer view lies outside its buffer: the factor is used instead",
                    );
                    None
                }
            },
            (None, None) => {
                self.warn(
                    &format!("images[{image}]"),
                    "the image has neither a uri nor a buffer view",
                );
                None
            }
        }
    }

    /// The bytes of buffer view `view`, if they lie inside a loaded buffer.
    fn view_bytes(&self, view: usize) -> Option<Vec<u8>> {
        let v = self.root.buffer_views.get(view)?;
        let buffer = self.buffers.get(v.buffer.value())?.as_ref()?;
        let start = v.byte_offset.map_or(0, |o| o.0) as usize;
        let end = start.checked_add(v.byte_length.0 as usize)?;
        buffer.get(start..end).map(<[u8]>::to_vec)
    }

    fn camera(&mut self, index: usize, world: Mat4, node_path: &str) {
        if self.desc.camera.is_some() {
            self.warn_once("cameras", node_path, "more than one camera: the first is used");
            return;
        }
        let camera = &self.root.cameras[index];
        let Some(p) = &camera.perspective else {
            self.warn(
                &format!("cameras[{index}]"),
                "orthographic cameras are not supported: ignored",
            );
            return;
        };
        let aspect = p.aspect_ratio.filter(|a| *a > 0.0 && a.is_finite()).unwrap_or(1.0);
        let yfov = p.yfov.clamp(1e-4, 3.1);
        let eye = world.transform_point3(Vec3::ZERO);
        let view = world.transform_vector3(-Vec3::Z).normalize_or_zero();
        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
        let right = world.transform_vector3(Vec3::X).normalize_or_zero();
        if view == Vec3::ZERO || up == Vec3::ZERO {
            self.warn(node_path, "the camera's transform is degenerate: ignored");
            return;
        }
        self.desc.camera = Some(CameraDesc {
            position: eye,
            view,
            up,
            height: 2.0 * (yfov * 0.5).tan(),
            aspect_ratio: aspect,
            right: Some(right),
            fov_axis: FovAxis::Vertical,
            lens: None,
            span: locate(&self.files.main().text, &format!("cameras[{index}]")),
        });
    }

    fn light(&mut self, index: usize, world: Mat4, node_path: &str) -> Result<(), ParseError> {
        let Some(light) = self
            .root
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
            .and_then(|l| l.lights.get(index))
        else {
            return Err(self.error(node_path, format!("light {index} is not defined")));
        };
        let path = format!("extensions.KHR_lights_punctual.lights[{index}]");
        let span = locate(&self.files.main().text, &path);
        let color = Vec3::from(light.color).max(Vec3::ZERO) * (light.intensity.max(0.0) / LUMENS_PER_WATT);
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z);
        if light.range.is_some() {
            self.warn_once(
                "range",
                &path,
                "light ranges are not applied: light falls off with the inverse square",
            );
        }
        use json::extensions::scene::khr_lights_punctual::Type;
        let desc = match light.type_ {
            Checked::Valid(Type::Point) => LightDesc::Point {
                position,
                color,
                attenuation: [0.0, 0.0, 1.0],
                span,
            },
            Checked::Valid(Type::Directional) => LightDesc::Directional { direction, color, span },
            Checked::Valid(Type::Spot) => {
                let spot = light
                    .spot
                    .clone()
                    .unwrap_or(json::extensions::scene::khr_lights_punctual::Spot {
                        inner_cone_angle: 0.0,
                        outer_cone_angle: std::f32::consts::FRAC_PI_4,
                    });
                let outer = spot.outer_cone_angle.to_degrees().clamp(0.0, 90.0);
                LightDesc::Spot {
                    position,
                    direction,
                    color,
                    attenuation: [0.0, 0.0, 1.0],
                    inner_degrees: spot.inner_cone_angle.to_degrees().clamp(0.0, outer),
                    outer_degrees: outer,
                    exponent: 0.0,
                    span,
                }
            }
            Checked::Invalid => return Err(self.error(&path, "unknown light type")),
        };
        self.desc.lights.push(desc);
        Ok(())
    }
}

/// A node's local matrix: `matrix` (column-major) or translation · rotation · scale.
fn local_matrix(node: &json::Node) -> Mat4 {
    if let Some(m) = node.matrix {
        return Mat4::from_cols_array(&m);
    }
    let t = Vec3::from(node.translation.unwrap_or([0.0; 3]));
    let r = node.rotation.as_ref().map_or([0.0, 0.0, 0.0, 1.0], |q| q.0);
    let q = Quat::from_xyzw(r[0], r[1], r[2], r[3]);
    let q = if q.length_squared() > 0.0 {
        q.normalize()
    } else {
        Quat::IDENTITY
    };
    let s = Vec3::from(node.scale.unwrap_or([1.0; 3]));
    Mat4::from_scale_rotation_translation(s, q, t)
}

/// Whether every edge of the mesh (vertices welded by position) borders exactly two triangles.
fn is_closed(points: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let welded: Vec<u32> = points
        .iter()
        .map(|p| {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (welded[t[k] as usize], welded[t[(k + 1) % 3] as usize]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    !edges.is_empty() && edges.values().all(|&c| c == 2)
}

fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Ok(v) = u8::from_str_radix(std::str::from_utf8(&b[i + 1..i + 3]).unwrap_or("zz"), 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (padding optional).
fn base64(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let digits: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    let digits = digits
        .strip_suffix(b"==")
        .or_else(|| digits.strip_suffix(b"="))
        .unwrap_or(&digits);
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * k);
        }
        let bytes = acc.to_be_bytes();
        match chunk.len() {
            4 => out.extend(&bytes[1..4]),
            3 => out.extend(&bytes[1..3]),
            2 => out.push(bytes[1]),
            _ => return None,
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_paths_are_located() {
        let text = "{\n \"asset\": {\"version\": \"2.0\"},\n \"meshes\": [ {\"primitives\": [ {\"attributes\": {\"NORMAL\": 1, \"POSITION\": 7}} ]} ]\n}";
        let span = locate(text, "meshes[0].primitives[0].attributes[\"POSITION\"]");
        assert_eq!(&text[span], "7");
        let span = locate(text, "asset.version");
        assert_eq!(&text[span], "\"2.0\"");
        // A path that cannot be followed stops at what exists.
        let span = locate(text, "meshes[3]");
        assert!(text[span].starts_with('['));
    }

    #[test]
    fn base64_and_percent_decoding() {
        assert_eq!(base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64("aGVsbG8gd29ybGQ").unwrap(), b"hello world");
        assert!(base64("a$==").is_none());
        assert_eq!(percent_decode("my%20file.bin"), "my file.bin");
        assert_eq!(percent_decode("100%"), "100%");
    }

    #[test]
    fn closed_meshes_are_told_from_open_ones() {
        // A tetrahedron is closed; drop a face and it is open.
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let mut t = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert!(is_closed(&p, &t));
        t.pop();
        assert!(!is_closed(&p, &t));
    }
}
