//! Stanford PLY meshes (ASCII and binary, either byte order), as pbrt-v4's `plymesh` names them.
//!
//! Written here rather than taken from a crate: the maintained PLY crate needs a newer Rust than
//! the workspace's, the older one builds a map per vertex, and neither locates errors. Header
//! errors point at their line; errors in binary data name the element, its index and the byte
//! offset. Counts are checked against the bytes present before anything is allocated.

use super::SourceFiles;
use crate::description::repair_vertex_attributes;
use crate::error::{ParseError, Span};
use glam::{Vec2, Vec3};
use std::path::Path;

/// A triangle mesh read from a PLY file.
#[derive(Clone, Debug, Default)]
pub struct PlyMesh {
    /// Vertex positions.
    pub points: Vec<Vec3>,
    /// Triangles (quads split in two, larger polygons fanned), indices checked.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals, if the file has `nx ny nz`.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates (`u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`).
    pub uvs: Option<Vec<Vec2>>,
    /// Non-fatal remarks.
    pub warnings: Vec<(String, Span)>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// The count's type for a list.
    list: Option<Scalar>,
    kind: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
    span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// Reads the values of the body one at a time.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    encoding: Encoding,
}

impl Body<'_> {
    fn value(&mut self, kind: Scalar) -> Result<f64, String> {
        if self.encoding == Encoding::Ascii {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            let start = self.pos;
            while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if start == self.pos {
                return Err("the file ends early".into());
            }
            let word = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("?");
            // Not-finite values are read: counts and indices refuse them, vertex attributes
            // are repaired once the mesh is whole.
            return word.parse().map_err(|_| format!("expected a number, found `{word}`"));
        }
        let size = kind.size();
        let Some(raw) = self.bytes.get(self.pos..self.pos + size) else {
            return Err("the file ends early".into());
        };
        self.pos += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(raw);
        if self.encoding == Encoding::Big {
            b[..size].reverse();
        }
        let v = match kind {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        };
        Ok(v)
    }
}

/// Largest number of polygon corners accepted.
const MAX_CORNERS: f64 = 1024.0;

/// Reads the PLY file at `path` (named at `blame` in the file that refers to it); its header
/// (or, for ASCII files, all of it) is added to `files` for errors.
pub fn read(files: &mut SourceFiles, path: &Path, blame: &Span) -> Result<PlyMesh, ParseError> {
    let bytes = SourceFiles::read_bytes(path, blame)?;
    parse(files, path, &bytes)
}

/// Parses PLY bytes read from `path`.
pub fn parse(files: &mut SourceFiles, path: &Path, bytes: &[u8]) -> Result<PlyMesh, ParseError> {
    let header_end = find_header_end(bytes);
    let ascii_guess = bytes
        .get(..header_end.unwrap_or(0))
        .is_some_and(|h| std::str::from_utf8(h).is_ok_and(|h| h.contains("format ascii")));
    // ASCII files are kept whole, so data errors can point at their line too.
    let shown = if ascii_guess {
        bytes
    } else {
        &bytes[..header_end.unwrap_or(bytes.len().min(4096))]
    };
    let base = files.add(path, String::from_utf8_lossy(shown).into_owned());
    let at = |start: usize, end: usize| base + start..base + end;
    let Some(header_end) = header_end else {
        return Err(ParseError::new(
            "not a PLY file: no `end_header` line (a PLY file starts with `ply` and a header ending in `end_header`)",
            at(0, bytes.len().min(3)),
        ));
    };
    let header = std::str::from_utf8(&bytes[..header_end])
        .map_err(|e| ParseError::new("the PLY header is not text", at(e.valid_up_to(), e.valid_up_to() + 1)))?;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0;
    for (number, line) in header.split_inclusive('\n').enumerate() {
        let start = offset;
        offset += line.len();
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let span = at(start, start + line.trim_end().len());
        let bad = |message: String| Err(ParseError::new(message, span.clone()));
        match words.as_slice() {
            ["ply"] if number == 0 => {}
            _ if number == 0 => return bad("not a PLY file: the first line must be `ply`".into()),
            [] | ["comment", ..] | ["obj_info", ..] | ["end_header"] => {}
            ["format", kind, _version] => {
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return bad(format!("unknown PLY format `{other}`")),
                });
            }
            ["element", name, count] => {
                let count: usize = match count.parse() {
                    Ok(c) if c <= u32::MAX as usize => c,
                    _ => return bad(format!("`{count}` is not an element count")),
                };
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                    span,
                });
            }
            ["property", "list", count_type, item_type, name] => {
                let (Some(c), Some(i)) = (Scalar::parse(count_type), Scalar::parse(item_type)) else {
                    return bad(format!("unknown PLY type in `{}`", line.trim()));
                };
                let Some(element) = elements.last_mut() else {
                    return bad("a property before any element".into());
                };
                element.properties.push(Property {
                    name: name.to_string(),
                    list: Some(c),
                    kind: i,
                });
            }
            ["property", kind, name] => {
                let Some(kind) = Scalar::parse(kind) else {
                    return bad(format!("unknown PLY type `{kind}`"));
                };
                let Some(element) = elements.last_mut() else {
                    return bad("a property before any element".into());
                };
                element.properties.push(Property {
                    name: name.to_string(),
                    list: None,
                    kind,
                });
            }
            _ => return bad(format!("cannot read this PLY header line: `{}`", line.trim())),
        }
    }
    let Some(encoding) = encoding else {
        return Err(ParseError::new("the PLY header has no `format` line", at(0, 3)));
    };
    let mut body = Body {
        bytes,
        pos: header_end,
        encoding,
    };
    let mut mesh = PlyMesh::default();
    for element in &elements {
        // The smallest size each instance can have, checked against what is left.
        let min_size: usize = if encoding == Encoding::Ascii {
            element.properties.len()
        } else {
            element
                .properties
                .iter()
                .map(|p| p.list.map_or(p.kind.size(), Scalar::size))
                .sum()
        };
        if (element.count as u128) * (min_size as u128) > (bytes.len() - body.pos.min(bytes.len())) as u128 + 1 {
            return Err(ParseError::new(
                format!(
                    "the header promises {} `{}` elements, more than the file's {} bytes can hold",
                    element.count,
                    element.name,
                    bytes.len()
                ),
                element.span.clone(),
            ));
        }
        let located = |i: usize, pos: usize, message: String| {
            ParseError::new(
                format!("{} {i} (byte {pos}): {message}", element.name),
                element.span.clone(),
            )
        };
        match element.name.as_str() {
            "vertex" => read_vertices(&mut body, element, &mut mesh, &located)?,
            "face" => read_faces(&mut body, element, &mut mesh, &located)?,
            _ => {
                for i in 0..element.count {
                    for p in &element.properties {
                        let pos = body.pos;
                        read_property(&mut body, p, |_| {}).map_err(|m| located(i, pos, m))?;
                    }
                }
            }
        }
    }
    let n = mesh.points.len();
    if let Some(bad) = mesh.triangles.iter().flatten().find(|&&i| i as usize >= n) {
        let span = elements
            .iter()
            .find(|e| e.name == "face")
            .map_or(at(0, 3), |e| e.span.clone());
        return Err(ParseError::new(
            format!("a face uses vertex {bad} but the file has {n} vertices"),
            span,
        ));
    }
    let repaired = repair_vertex_attributes(&mesh.points, &mesh.triangles, &mut mesh.normals, &mut mesh.uvs);
    if !repaired.is_empty() {
        let span = elements
            .iter()
            .find(|e| e.name == "vertex")
            .map_or(at(0, 3), |e| e.span.clone());
        mesh.warnings.extend(repaired.into_iter().map(|w| (w, span.clone())));
    }
    Ok(mesh)
}

/// Reads one property of one element; list items go to `item`.
fn read_property(body: &mut Body, p: &Property, mut item: impl FnMut(f64)) -> Result<f64, String> {
    match p.list {
        None => body.value(p.kind),
        Some(count_kind) => {
            let count = body.value(count_kind)?;
            if !(0.0..=MAX_CORNERS).contains(&count) || count.fract() != 0.0 {
                return Err(format!("a list of {count} items"));
            }
            for _ in 0..count as usize {
                item(body.value(p.kind)?);
            }
            Ok(count)
        }
    }
}

fn read_vertices(
    body: &mut Body,
    element: &Element,
    mesh: &mut PlyMesh,
    located: &dyn Fn(usize, usize, String) -> ParseError,
) -> Result<(), ParseError> {
    let index = |names: &[&str]| element.properties.iter().position(|p| names.contains(&p.name.as_str()));
    let (Some(x), Some(y), Some(z)) = (index(&["x"]), index(&["y"]), index(&["z"])) else {
        return Err(ParseError::new(
            "the vertex element has no x, y and z",
            element.span.clone(),
        ));
    };
    let normal = match (index(&["nx"]), index(&["ny"]), index(&["nz"])) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ]
    .iter()
    .find_map(|(u, v)| Some([index(&[u])?, index(&[v])?]));
    mesh.points.reserve(element.count);
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut values = vec![0.0f64; element.properties.len()];
    for i in 0..element.count {
        for (slot, p) in values.iter_mut().zip(&element.properties) {
            let pos = body.pos;
            *slot = read_property(body, p, |_| {}).map_err(|m| located(i, pos, m))?;
        }
        mesh.points
            .push(Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32));
        if let Some([a, b, c]) = normal {
            normals.push(Vec3::new(values[a] as f32, values[b] as f32, values[c] as f32));
        }
        if let Some([u, v]) = uv {
            uvs.push(Vec2::new(values[u] as f32, values[v] as f32));
        }
    }
    mesh.normals = normal.map(|_| normals);
    mesh.uvs = uv.map(|_| uvs);
    Ok(())
}

fn read_faces(
    body: &mut Body,
    element: &Element,
    mesh: &mut PlyMesh,
    located: &dyn Fn(usize, usize, String) -> ParseError,
) -> Result<(), ParseError> {
    let Some(list) = element
        .properties
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
    else {
        return Err(ParseError::new(
            "the face element has no `vertex_indices` list",
            element.span.clone(),
        ));
    };
    let mut corners: Vec<u32> = Vec::new();
    let mut larger = 0usize;
    mesh.triangles.reserve(element.count);
    for i in 0..element.count {
        for (k, p) in element.properties.iter().enumerate() {
            let pos = body.pos;
            if k == list {
                corners.clear();
                let mut bad = None;
                read_property(body, p, |v| {
                    if v < 0.0 || v > u32::MAX as f64 || v.fract() != 0.0 {
                        bad = Some(v);
                    }
                    corners.push(v as u32);
                })
                .map_err(|m| located(i, pos, m))?;
                if let Some(v) = bad {
                    return Err(located(i, pos, format!("{v} is not a vertex index")));
                }
            } else {
                read_property(body, p, |_| {}).map_err(|m| located(i, pos, m))?;
            }
        }
        if corners.len() < 3 {
            continue;
        }
        if corners.len() > 4 {
            larger += 1;
        }
        for k in 1..corners.len() - 1 {
            mesh.triangles.push([corners[0], corners[k], corners[k + 1]]);
        }
    }
    if larger > 0 {
        mesh.warnings.push((
            format!("{larger} face(s) with more than four corners were fanned into triangles"),
            element.span.clone(),
        ));
    }
    Ok(())
}

/// The byte after the `end_header` line's newline.
fn find_header_end(bytes: &[u8]) -> Option<usize> {
    let limit = bytes.len().min(1 << 20);
    let mut line_start = 0;
    for i in 0..limit {
        if bytes[i] == b'\n' {
            let line = &bytes[line_start..i];
            let line = line.strip_suffix(b"\r").unwrap_or(line);
            if line.trim_ascii() == b"end_header" {
                return Some(i + 1);
            }
            line_start = i + 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_bytes(bytes: &[u8]) -> Result<PlyMesh, ParseError> {
        let mut files = SourceFiles::new(Path::new("main.pbrt"), "x".into());
        parse(&mut files, Path::new("m.ply"), bytes)
    }

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a quad and a triangle\nelement vertex 5\n\
        property float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\n\
        element face 2\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n2 0 0 1 0\n4 0 1 2 3\n3 1 4 2\n";

    #[test]
    fn ascii_quads_split_and_uvs_are_read() {
        let m = read_bytes(ASCII.as_bytes()).unwrap();
        assert_eq!(m.points.len(), 5);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert_eq!(m.uvs.as_ref().unwrap()[2], Vec2::new(1.0, 1.0));
        assert!(m.normals.is_none());
    }

    /// The same mesh in both byte orders, with an extra element to skip.
    #[test]
    fn binary_in_either_order_matches_ascii() {
        for (name, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut bytes = format!(
                "ply\nformat {name} 1.0\nelement vertex 3\nproperty double x\nproperty float y\nproperty float z\n\
                 element edge 1\nproperty int a\nproperty list uchar short b\n\
                 element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            )
            .into_bytes();
            let f32b = |v: f32| {
                if big {
                    v.to_be_bytes().to_vec()
                } else {
                    v.to_le_bytes().to_vec()
                }
            };
            for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
                let x = p[0] as f64;
                bytes.extend(if big { x.to_be_bytes() } else { x.to_le_bytes() });
                bytes.extend(f32b(p[1]));
                bytes.extend(f32b(p[2]));
            }
            bytes.extend([0u8; 4]);
            bytes.extend([2u8, 0, 0, 0, 0]);
            bytes.push(3);
            for i in [0u32, 1, 2] {
                bytes.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
            }
            let m = read_bytes(&bytes).unwrap();
            assert_eq!(m.points[2], Vec3::new(0.0, 2.0, 0.0), "{name}");
            assert_eq!(m.triangles, vec![[0, 1, 2]], "{name}");
        }
    }

    /// Not-finite normals are recomputed from their faces and not-finite texture coordinates
    /// read as (0, 0), each kind with a warning counting them; a NaN vertex index is refused.
    #[test]
    fn not_finite_attributes_are_repaired_with_a_count() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                    property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
                    element face 2\nproperty list uchar int vertex_indices\nend_header\n\
                    0 0 0 nan 0 1 0 0\n2 0 0 0 0 1 inf 0\n2 2 0 0 0 1 1 1\n0 2 0 0 0 1 0 nan\n3 0 1 2\n3 0 2 3\n";
        let m = read_bytes(text.as_bytes()).unwrap();
        let normals = m.normals.as_ref().unwrap();
        assert!(normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6), "{normals:?}");
        let uvs = m.uvs.as_ref().unwrap();
        assert_eq!((uvs[1], uvs[3]), (Vec2::ZERO, Vec2::ZERO));
        let warnings: Vec<&str> = m.warnings.iter().map(|(w, _)| w.as_str()).collect();
        assert!(
            warnings.iter().any(|w| w.starts_with("1 of 4 vertex normals")),
            "{warnings:?}"
        );
        assert!(
            warnings.iter().any(|w| w.starts_with("2 of 4 texture coordinates")),
            "{warnings:?}"
        );
        let bad_index = text.replace("3 0 2 3", "3 0 nan 3");
        assert!(read_bytes(bad_index.as_bytes())
            .unwrap_err()
            .message
            .contains("not a vertex index"));
    }

    #[test]
    fn bad_files_are_refused_with_their_place() {
        let e = read_bytes(
            b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n",
        )
        .unwrap_err();
        assert!(e.message.contains("more than the file"), "{e:?}");
        let short = ASCII.replace("3 1 4 2\n", "3 1 9 2\n");
        let e = read_bytes(short.as_bytes()).unwrap_err();
        assert!(e.message.contains("vertex 9"), "{e:?}");
        let e = read_bytes(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0\n")
            .unwrap_err();
        assert!(
            e.message.contains("vertex 0") && e.message.contains("ends early"),
            "{e:?}"
        );
        assert!(read_bytes(b"not a ply").is_err());
        let e =
            read_bytes(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n").unwrap_err();
        assert!(e.message.contains("quaternion"), "{e:?}");
    }
}
