//! Wavefront OBJ meshes with their MTL materials: as a whole scene (with a camera and light
//! given by options, or chosen to frame the mesh) and as a mesh named in a `.ray` file.
//!
//! caustica reads OBJ itself rather than through a crate so that every error names its file,
//! line and column (the common crates report a bare error kind) and the reader is fuzzed on
//! caustica's terms. What is read and how MTL maps to both models: docs/scene-formats.md.

use super::{SceneSource, SourceFiles};
use crate::description::{
    Alpha, CameraDesc, FovAxis, ImageMap, ImageSource, LightDesc, MaterialDesc, NormalMap, ObjectDesc, Param,
    PhysicalMaterial, SceneDescription, ShapeDesc, TrimeshDesc,
};
use crate::error::{Error, ParseError, Result, Span};
use crate::math::Affine2;
use crate::progress::Progress;
use crate::texture::{Encoding, Wrap};
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The camera and lights an OBJ scene is rendered with (OBJ has neither).
#[derive(Clone, Debug, Default)]
pub struct SceneOptions {
    /// The camera; `None` frames the mesh from its front (+z), a little above.
    pub camera: Option<CameraRequest>,
    /// The lights; empty puts a point light above and left of the camera.
    pub lights: Vec<LightDesc>,
}

/// A camera asked for by a front end; what it leaves out frames the mesh.
#[derive(Clone, Debug)]
pub struct CameraRequest {
    /// The eye (default: framing the mesh from +z, a little above).
    pub eye: Option<Vec3>,
    /// The point looked at (default: the mesh's centre).
    pub target: Option<Vec3>,
    /// The up direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_degrees: f32,
}

/// Largest count of vertices, normals, texture coordinates or faces a file may hold.
const MAX_ELEMENTS: usize = 1 << 28;

/// A face corner: 0-based indices of position, texture coordinate and normal.
type Corner = (u32, Option<u32>, Option<u32>);

/// The faces that share one material.
struct Group {
    material: Option<String>,
    /// Where `usemtl` (or the first face) is, for errors.
    span: Span,
    triangles: Vec<[Corner; 3]>,
}

/// What an OBJ file holds.
pub struct ObjMesh {
    positions: Vec<Vec3>,
    texcoords: Vec<Vec2>,
    normals: Vec<Vec3>,
    groups: Vec<Group>,
    materials: HashMap<String, MaterialDesc>,
    /// Non-fatal remarks, with spans.
    pub warnings: Vec<(String, Span)>,
}

/// A token and its span in the span space.
type Token<'a> = (&'a str, Span);

/// Splits `text` (placed at `base`) into logical lines of tokens: `#` starts a comment, a
/// trailing `\` joins the next line.
fn lines(text: &str, base: usize) -> impl Iterator<Item = Vec<Token<'_>>> {
    let mut offset = 0;
    std::iter::from_fn(move || {
        let mut tokens = Vec::new();
        loop {
            if offset >= text.len() {
                return (!tokens.is_empty()).then_some(tokens);
            }
            let rest = &text[offset..];
            let end = rest.find('\n').map_or(rest.len(), |i| i + 1);
            let line = &rest[..end];
            let line_start = offset;
            offset += end;
            let code = line.find('#').map_or(line, |i| &line[..i]);
            let (code, continued) = match code.trim_end().strip_suffix('\\') {
                Some(c) => (c, true),
                None => (code, false),
            };
            let mut pos = 0;
            for word in code.split(|c: char| c.is_ascii_whitespace()) {
                let start = pos;
                pos += word.len() + 1;
                if !word.is_empty() {
                    let s = base + line_start + start;
                    tokens.push((word, s..s + word.len()));
                }
            }
            if !continued {
                if tokens.is_empty() {
                    continue;
                }
                return Some(tokens);
            }
        }
    })
}

fn number(token: &Token, what: &str) -> Result<f32, ParseError> {
    match token.0.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(ParseError::new(
            format!("expected a number ({what}), found `{}`", token.0),
            token.1.clone(),
        )),
    }
}

fn vec3(tokens: &[Token], at: &Token, what: &str) -> Result<Vec3, ParseError> {
    if tokens.len() < 3 {
        return Err(ParseError::new(
            format!("`{}` needs 3 numbers ({what})", at.0),
            at.1.clone(),
        ));
    }
    Ok(Vec3::new(
        number(&tokens[0], what)?,
        number(&tokens[1], what)?,
        number(&tokens[2], what)?,
    ))
}

/// Where a line's tokens start and end.
fn line_span(tokens: &[Token]) -> Span {
    tokens[0].1.start..tokens[tokens.len() - 1].1.end
}

impl ObjMesh {
    /// Reads the OBJ text registered in `files` at `base`, and the MTL files it names
    /// (resolved against `dir`). A missing MTL file is a warning.
    pub fn parse(files: &mut SourceFiles, base: usize, text: &str, dir: &Path) -> Result<ObjMesh, ParseError> {
        let mut mesh = ObjMesh {
            positions: Vec::new(),
            texcoords: Vec::new(),
            normals: Vec::new(),
            groups: Vec::new(),
            materials: HashMap::new(),
            warnings: Vec::new(),
        };
        let mut current: Option<String> = None;
        let mut ignored: HashMap<String, (usize, Span)> = HashMap::new();
        let mut corners: Vec<Corner> = Vec::new();
        for tokens in lines(text, base) {
            let head = &tokens[0];
            let args = &tokens[1..];
            match head.0 {
                "v" => {
                    let p = vec3(args, head, "a vertex position x y z")?;
                    push_checked(&mut mesh.positions, p, head)?;
                }
                "vn" => {
                    let n = vec3(args, head, "a normal x y z")?;
                    push_checked(&mut mesh.normals, n, head)?;
                }
                "vt" => {
                    let u = args
                        .first()
                        .ok_or_else(|| ParseError::new("`vt` needs at least u", head.1.clone()))?;
                    let u = number(u, "a texture coordinate u")?;
                    let v = args.get(1).map(|t| number(t, "a texture coordinate v")).transpose()?;
                    push_checked(&mut mesh.texcoords, Vec2::new(u, v.unwrap_or(0.0)), head)?;
                }
                "f" | "fo" => {
                    if args.len() < 3 {
                        return Err(ParseError::new(
                            format!("a face needs at least 3 vertices, this one has {}", args.len()),
                            line_span(&tokens),
                        ));
                    }
                    corners.clear();
                    for token in args {
                        corners.push(mesh.corner(token)?);
                    }
                    if !matches!(mesh.groups.last(), Some(g) if g.material == current) {
                        mesh.groups.push(Group {
                            material: current.clone(),
                            span: head.1.clone(),
                            triangles: Vec::new(),
                        });
                    }
                    let group = mesh.groups.last_mut().expect("pushed above");
                    for k in 1..corners.len() - 1 {
                        group.triangles.push([corners[0], corners[k], corners[k + 1]]);
                    }
                    if group.triangles.len() > MAX_ELEMENTS {
                        return Err(ParseError::new("too many faces", head.1.clone()));
                    }
                }
                "usemtl" => {
                    current = args.first().map(|t| rest_of_line(text, base, t, &tokens));
                }
                "mtllib" => {
                    if args.is_empty() {
                        return Err(ParseError::new("`mtllib` needs a file name", head.1.clone()));
                    }
                    // A name may hold spaces (some exporters write them unquoted): try the whole
                    // rest of the line first, then each word as its own file.
                    let whole = windows_path(&rest_of_line(text, base, &args[0], &tokens));
                    let names: Vec<(String, Span)> = if args.len() > 1 && dir.join(&whole).is_file() {
                        vec![(whole, args[0].1.start..args[args.len() - 1].1.end)]
                    } else {
                        args.iter().map(|t| (windows_path(t.0), t.1.clone())).collect()
                    };
                    for (name, span) in names {
                        if args.iter().any(|t| t.0.contains('\\')) {
                            mesh.warnings
                                .push((format!("`{name}`: backslashes are read as /"), span.clone()));
                        }
                        mesh.read_mtl(files, &dir.join(&name), &span, dir)?;
                    }
                }
                "o" | "g" | "s" | "mg" => {}
                other => {
                    let entry = ignored.entry(other.to_string()).or_insert((0, head.1.clone()));
                    entry.0 += 1;
                }
            }
        }
        let mut ignored: Vec<_> = ignored.into_iter().collect();
        ignored.sort_by_key(|(_, (_, span))| span.start);
        for (word, (count, span)) in ignored {
            mesh.warnings.push((
                format!("`{word}` is not read ({count} line(s): lines, points and free-form geometry are left out)"),
                span,
            ));
        }
        // Positive indices may name vertices defined later in the file: check them now.
        for group in &mesh.groups {
            for tri in &group.triangles {
                for &(v, t, n) in tri {
                    let bad = v as usize >= mesh.positions.len()
                        || t.is_some_and(|t| t as usize >= mesh.texcoords.len())
                        || n.is_some_and(|n| n as usize >= mesh.normals.len());
                    if bad {
                        return Err(ParseError::new(
                            format!(
                                "a face in this group uses a vertex, texture coordinate or normal the file does not define ({} v, {} vt, {} vn)",
                                mesh.positions.len(),
                                mesh.texcoords.len(),
                                mesh.normals.len()
                            ),
                            group.span.clone(),
                        ));
                    }
                }
            }
        }
        Ok(mesh)
    }

    /// One face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`; 1-based, negative counts back from
    /// the last element so far.
    fn corner(&self, token: &Token) -> Result<Corner, ParseError> {
        let mut parts = token.0.split('/');
        let mut index = |count: usize, what: &str, required: bool| -> Result<Option<u32>, ParseError> {
            let part = parts.next().unwrap_or("");
            if part.is_empty() {
                return if required {
                    Err(ParseError::new(
                        format!("a face corner needs a vertex index, found `{}`", token.0),
                        token.1.clone(),
                    ))
                } else {
                    Ok(None)
                };
            }
            let bad = || {
                ParseError::new(
                    format!("`{}`: the {what} index must be a non-zero integer", token.0),
                    token.1.clone(),
                )
            };
            let i: i64 = part.parse().map_err(|_| bad())?;
            let resolved = match i {
                0 => return Err(bad()),
                i if i > 0 => i - 1,
                i => count as i64 + i,
            };
            if resolved < 0 || resolved >= MAX_ELEMENTS as i64 {
                return Err(ParseError::new(
                    format!(
                        "`{}`: {what} index {i} refers before the first one ({count} so far)",
                        token.0
                    ),
                    token.1.clone(),
                ));
            }
            Ok(Some(resolved as u32))
        };
        let v = index(self.positions.len(), "vertex", true)?.expect("required");
        let t = index(self.texcoords.len(), "texture coordinate", false)?;
        let n = index(self.normals.len(), "normal", false)?;
        if parts.next().is_some() {
            return Err(ParseError::new(
                format!("`{}`: a face corner has at most three parts v/vt/vn", token.0),
                token.1.clone(),
            ));
        }
        Ok((v, t, n))
    }

    fn read_mtl(&mut self, files: &mut SourceFiles, path: &Path, blame: &Span, dir: &Path) -> Result<(), ParseError> {
        if !path.is_file() {
            self.warnings.push((
                format!(
                    "the material library `{}` is missing: its materials are grey",
                    path.display()
                ),
                blame.clone(),
            ));
            return Ok(());
        }
        let (base, text, bad) = files.read_text_lossy(path, blame)?;
        let text = text.to_string();
        let mut warnings = Vec::new();
        if let Some(bad) = bad {
            warnings.push((super::NOT_UTF8.to_string(), bad));
        }
        for (name, material) in parse_mtl(&text, base, dir, &mut warnings)? {
            self.materials.insert(name, material);
        }
        self.warnings.extend(warnings);
        Ok(())
    }

    /// The mesh as objects: one per material group, or one in all with `material`.
    pub fn objects(
        &self,
        world_from_object: Mat4,
        material: Option<&MaterialDesc>,
        span: &Span,
        warnings: &mut Vec<(String, Span)>,
    ) -> Vec<ObjectDesc> {
        let mut out = Vec::new();
        let mut missing: Vec<(String, Span)> = Vec::new();
        let mut by_material: Vec<(Option<&str>, Vec<&Group>)> = Vec::new();
        for group in &self.groups {
            let key = if material.is_some() {
                None
            } else {
                group.material.as_deref()
            };
            match by_material.iter_mut().find(|(k, _)| *k == key) {
                Some((_, list)) => list.push(group),
                None => by_material.push((key, vec![group])),
            }
        }
        for (name, groups) in by_material {
            let desc = match (material, name) {
                (Some(m), _) => m.clone(),
                (None, Some(name)) => match self.materials.get(name) {
                    Some(m) => m.clone(),
                    None => {
                        if !missing.iter().any(|(n, _)| n == name) {
                            missing.push((name.to_string(), groups[0].span.clone()));
                        }
                        default_material()
                    }
                },
                (None, None) => default_material(),
            };
            if let Some(mesh) = self.trimesh(&groups) {
                out.push(ObjectDesc {
                    shape: ShapeDesc::Trimesh(Box::new(mesh)),
                    world_from_object,
                    material: desc,
                    span: groups[0].span.start.min(span.start)..groups[0].span.end.max(span.start),
                });
            }
        }
        for (name, span) in missing {
            warnings.push((
                format!("no material `{name}` in the material libraries: grey instead"),
                span,
            ));
        }
        out
    }

    /// One mesh of the groups' triangles, each distinct corner a vertex.
    fn trimesh(&self, groups: &[&Group]) -> Option<TrimeshDesc> {
        let mut ids: HashMap<Corner, u32> = HashMap::new();
        let mut corners: Vec<Corner> = Vec::new();
        let mut triangles = Vec::new();
        for group in groups {
            for tri in &group.triangles {
                let [a, b, c] = tri.map(|corner| {
                    *ids.entry(corner).or_insert_with(|| {
                        corners.push(corner);
                        (corners.len() - 1) as u32
                    })
                });
                let [pa, pb, pc] = [a, b, c].map(|i| self.positions[corners[i as usize].0 as usize]);
                if (pb - pa).cross(pc - pa).length_squared() > 0.0 {
                    triangles.push([a, b, c]);
                }
            }
        }
        if triangles.is_empty() {
            return None;
        }
        let points = corners.iter().map(|c| self.positions[c.0 as usize]).collect();
        let normals = corners.iter().all(|c| c.2.is_some()).then(|| {
            corners
                .iter()
                .map(|c| self.normals[c.2.unwrap_or(0) as usize])
                .collect()
        });
        let uvs = corners.iter().all(|c| c.1.is_some()).then(|| {
            corners
                .iter()
                .map(|c| self.texcoords[c.1.unwrap_or(0) as usize])
                .collect()
        });
        Some(TrimeshDesc {
            points,
            triangles,
            normals,
            materials: None,
            uvs,
            tangents: None,
        })
    }
}

fn push_checked<T>(list: &mut Vec<T>, value: T, at: &Token) -> Result<(), ParseError> {
    if list.len() >= MAX_ELEMENTS {
        return Err(ParseError::new("too many elements of this kind", at.1.clone()));
    }
    list.push(value);
    Ok(())
}

/// A file name as a Windows exporter may write it (`.\maps\wood.png`), with `/` between folders.
fn windows_path(name: &str) -> String {
    name.replace('\\', "/")
}

/// The text from `first` to the end of its logical line, trimmed.
fn rest_of_line(text: &str, base: usize, first: &Token, tokens: &[Token]) -> String {
    let last = &tokens[tokens.len() - 1];
    let (start, end) = (first.1.start - base, last.1.end - base);
    if end <= text.len() && text[start..end].find('\n').is_none() {
        text[start..end].to_string()
    } else {
        first.0.to_string()
    }
}

/// The material of faces without one: the MTL specification's default, a mid grey.
fn default_material() -> MaterialDesc {
    MaterialDesc {
        diffuse: Param::grey(0.8),
        ..MaterialDesc::default()
    }
}

/// The MTL statements that describe one material as written.
#[derive(Default)]
struct MtlEntry {
    ka: Option<Vec3>,
    kd: Option<Vec3>,
    ks: Option<Vec3>,
    ke: Option<Vec3>,
    tf: Option<Vec3>,
    ns: Option<f32>,
    ni: Option<f32>,
    d: Option<f32>,
    tr: Option<f32>,
    illum: Option<u32>,
    pr: Option<f32>,
    pm: Option<f32>,
    map_kd: Option<MtlMap>,
    map_ke: Option<MtlMap>,
    map_d: Option<MtlMap>,
    bump: Option<MtlMap>,
    norm: Option<MtlMap>,
}

/// A texture statement (`map_Kd`, `map_Ke`, `map_d`, `bump`/`map_Bump`, `norm`) with the
/// options caustica reads.
struct MtlMap {
    path: PathBuf,
    span: Span,
    /// `-s`: texture coordinates scaled by u, v.
    scale: Vec2,
    /// `-o`: then offset by u, v.
    offset: Vec2,
    /// `-clamp on`: the edge texels hold outside 0..1 (else the image repeats).
    clamp: bool,
    /// `-bm`: the bump's strength.
    bump: f32,
}

impl MtlMap {
    /// The image read with `encoding`, through its options.
    fn image_map(&self, encoding: Encoding) -> ImageMap {
        let mut map = ImageMap::colour(ImageSource::File(self.path.clone()), self.span.clone());
        map.encoding = encoding;
        if self.clamp {
            map.sampler.wrap = [Wrap::Clamp; 2];
        }
        map.sampler.transform = Affine2::from_scale_angle_translation(self.scale, 0.0, self.offset);
        map
    }
}

/// Reads a texture statement: options first, then the file, the rest of the line (names may
/// hold spaces, and Windows exporters write `\` between folders). A missing file is a warning
/// (`None`), as is an option caustica does not read.
fn texture_statement(
    text: &str,
    base: usize,
    tokens: &[Token],
    dir: &Path,
    warnings: &mut Vec<(String, Span)>,
) -> Result<Option<MtlMap>, ParseError> {
    let head = &tokens[0];
    let mut map = MtlMap {
        path: PathBuf::new(),
        span: head.1.clone(),
        scale: Vec2::ONE,
        offset: Vec2::ZERO,
        clamp: false,
        bump: 1.0,
    };
    let mut i = 1;
    // Up to `most` numbers after an option.
    let numbers = |i: &mut usize, most: usize| -> Result<Vec<f32>, ParseError> {
        let mut out = Vec::new();
        while out.len() < most && *i < tokens.len() && tokens[*i].0.parse::<f32>().is_ok() {
            out.push(number(&tokens[*i], "texture option")?);
            *i += 1;
        }
        Ok(out)
    };
    while i < tokens.len() && tokens[i].0.starts_with('-') && tokens[i].0.parse::<f32>().is_err() {
        let option = &tokens[i];
        i += 1;
        match option.0 {
            "-s" | "-o" => {
                let v = numbers(&mut i, 3)?;
                let uv = match v.as_slice() {
                    [u] => Vec2::new(*u, if option.0 == "-s" { 1.0 } else { 0.0 }),
                    [u, v, ..] => Vec2::new(*u, *v),
                    [] => {
                        return Err(ParseError::new(
                            format!("`{}` needs numbers u v", option.0),
                            option.1.clone(),
                        ))
                    }
                };
                if option.0 == "-s" {
                    map.scale = uv;
                } else {
                    map.offset = uv;
                }
            }
            "-bm" => {
                map.bump = *numbers(&mut i, 1)?
                    .first()
                    .ok_or_else(|| ParseError::new("`-bm` needs a number", option.1.clone()))?;
            }
            "-clamp" => {
                let on = tokens.get(i).map(|t| t.0);
                map.clamp = on == Some("on");
                i += usize::from(matches!(on, Some("on" | "off")));
            }
            _ => {
                // -blendu/-blendv/-cc on|off, -boost/-texres/-imfchan/-type one word,
                // -mm base gain and -t u v w numbers: skipped with their values.
                let skipped = numbers(&mut i, 3)?.len();
                if skipped == 0 && i + 1 < tokens.len() {
                    i += 1;
                }
                warnings.push((
                    format!("the texture option `{}` is not read", option.0),
                    option.1.clone(),
                ));
            }
        }
    }
    let Some(file) = tokens.get(i) else {
        return Err(ParseError::new(format!("`{}` needs a file", head.0), head.1.clone()));
    };
    let written = rest_of_line(text, base, file, tokens);
    let name = windows_path(&written);
    let path = dir.join(&name);
    map.span = file.1.start..tokens[tokens.len() - 1].1.end;
    if written.contains('\\') {
        warnings.push((format!("`{name}`: backslashes are read as /"), map.span.clone()));
    }
    if !path.is_file() {
        let instead = match head.0 {
            "map_Kd" => "the diffuse colour Kd is used",
            "map_Ke" => "the emitted colour Ke is used",
            "map_d" => "the dissolve d is used",
            _ => "the surface is shaded without it",
        };
        warnings.push((
            format!("the texture `{}` is missing: {instead}", path.display()),
            map.span.clone(),
        ));
        return Ok(None);
    }
    map.path = path;
    Ok(Some(map))
}

/// Reads an MTL file placed at `base`: each material mapped to both models.
pub fn parse_mtl(
    text: &str,
    base: usize,
    dir: &Path,
    warnings: &mut Vec<(String, Span)>,
) -> Result<Vec<(String, MaterialDesc)>, ParseError> {
    let mut out: Vec<(String, MtlEntry, Span)> = Vec::new();
    let mut ignored: HashMap<String, Span> = HashMap::new();
    for tokens in lines(text, base) {
        let head = &tokens[0];
        let args = &tokens[1..];
        if head.0 == "newmtl" {
            let name = match args.first() {
                Some(t) => rest_of_line(text, base, t, &tokens),
                None => return Err(ParseError::new("`newmtl` needs a name", head.1.clone())),
            };
            out.push((name, MtlEntry::default(), line_span(&tokens)));
            continue;
        }
        let Some((_, entry, _)) = out.last_mut() else {
            return Err(ParseError::new(
                format!("`{}` before any `newmtl`", head.0),
                head.1.clone(),
            ));
        };
        let scalar = |what: &str| -> Result<f32, ParseError> {
            let t = args
                .iter()
                .rfind(|t| !t.0.starts_with('-') || t.0.parse::<f32>().is_ok())
                .ok_or_else(|| ParseError::new(format!("`{}` needs a number ({what})", head.0), head.1.clone()))?;
            number(t, what)
        };
        let colour = |what: &str| -> Result<Vec3, ParseError> {
            match args.len() {
                0 => Err(ParseError::new(
                    format!("`{}` needs a colour r g b", head.0),
                    head.1.clone(),
                )),
                1 | 2 => Ok(Vec3::splat(number(&args[0], what)?)),
                _ => vec3(args, head, what),
            }
        };
        match head.0 {
            "Ka" => entry.ka = Some(colour("ambient colour")?),
            "Kd" => entry.kd = Some(colour("diffuse colour")?),
            "Ks" => entry.ks = Some(colour("specular colour")?),
            "Ke" => entry.ke = Some(colour("emitted colour")?),
            "Tf" => entry.tf = Some(colour("transmission filter")?),
            "Ns" => entry.ns = Some(scalar("specular exponent")?),
            "Ni" => entry.ni = Some(scalar("index of refraction")?),
            "d" => entry.d = Some(scalar("dissolve")?),
            "Tr" => entry.tr = Some(scalar("transparency")?),
            "Pr" => entry.pr = Some(scalar("roughness")?),
            "Pm" => entry.pm = Some(scalar("metallic")?),
            "illum" => {
                let v = scalar("illumination model")?;
                entry.illum = Some(v.clamp(0.0, 10.0) as u32);
            }
            "map_Kd" | "map_Ke" | "map_d" | "bump" | "map_Bump" | "map_bump" | "norm" => {
                let map = texture_statement(text, base, &tokens, dir, warnings)?;
                let slot = match head.0 {
                    "map_Kd" => &mut entry.map_kd,
                    "map_Ke" => &mut entry.map_ke,
                    "map_d" => &mut entry.map_d,
                    "norm" => &mut entry.norm,
                    _ => &mut entry.bump,
                };
                *slot = map;
            }
            other => {
                ignored.entry(other.to_string()).or_insert_with(|| head.1.clone());
            }
        }
    }
    let mut ignored: Vec<_> = ignored.into_iter().collect();
    ignored.sort_by_key(|(_, span)| span.start);
    for (word, span) in ignored {
        warnings.push((format!("`{word}` is not read"), span));
    }
    Ok(out
        .into_iter()
        .map(|(name, entry, span)| {
            let material = entry.material(&name, &span, warnings);
            (name, material)
        })
        .collect())
}

impl MtlEntry {
    /// Both models' reading (docs/scene-formats.md, "OBJ and MTL").
    fn material(&self, name: &str, span: &Span, warnings: &mut Vec<(String, Span)>) -> MaterialDesc {
        let kd = self.kd.unwrap_or(Vec3::splat(0.8));
        let ks = self.ks.unwrap_or(Vec3::ZERO);
        let illum = self.illum.unwrap_or(2);
        let dissolve = match (self.d, self.tr) {
            (Some(d), _) => d,
            (None, Some(tr)) => 1.0 - tr,
            (None, None) => 1.0,
        }
        .clamp(0.0, 1.0);
        let index = self.ni.filter(|n| *n >= 1.0).unwrap_or(1.0);
        // Blender's exporter writes glass as `illum 2` with Tf and the PBR keys Pr/Pm.
        let blender_glass = (self.pr.is_some() || self.pm.is_some()) && self.tf.is_some_and(|t| t.max_element() > 0.0);
        let glass = matches!(illum, 4 | 6 | 7 | 9) || blender_glass;
        let mut m = MaterialDesc {
            diffuse: Param::Constant(kd),
            ambient: Param::Constant(self.ka.unwrap_or(Vec3::ZERO)),
            specular: Param::Constant(ks),
            shininess: Param::grey(self.ns.unwrap_or(0.0).clamp(0.0, 10_000.0)),
            emissive: Param::Constant(self.ke.unwrap_or(Vec3::ZERO).max(Vec3::ZERO)),
            name: Some(name.to_string()),
            ..MaterialDesc::default()
        };
        if illum <= 1 {
            m.specular = Param::grey(0.0);
        }
        if let Some(map) = &self.map_kd {
            m.diffuse = Param::Texture(Box::new(map.image_map(Encoding::Srgb)));
        }
        if let Some(map) = &self.map_ke {
            // The texture times Ke when given (a black Ke keeps the surface dark).
            let mut image = map.image_map(Encoding::Srgb);
            image.sampler.scale = self.ke.unwrap_or(Vec3::ONE).max(Vec3::ZERO);
            m.emissive = Param::Texture(Box::new(image));
        }
        // `norm` is a normal map; `bump` holds heights or, from Blender, a normal map.
        m.normal_map = match (&self.norm, &self.bump) {
            (Some(map), _) => Some(NormalMap {
                map: map.image_map(Encoding::Linear),
                scale: map.bump,
            }),
            (None, Some(map)) => Some(NormalMap {
                map: map.image_map(Encoding::Bump(map.bump)),
                scale: 1.0,
            }),
            (None, None) => None,
        };
        if matches!(illum, 3 | 5 | 8) {
            m.reflective = Param::Constant(ks);
        }
        if glass {
            let tint = match self.tf {
                Some(t) if t.max_element() > 0.0 => t,
                _ if dissolve < 1.0 => Vec3::splat(1.0 - dissolve),
                _ => Vec3::ONE,
            };
            m.transmissive = Param::Constant(tint.min(Vec3::ONE));
            m.index = Param::grey(if self.ni.is_some() { index } else { 1.5 });
            m.diffuse = Param::grey(0.0);
            m.specular = Param::grey(0.0);
        } else if let Some(map) = &self.map_d {
            // A cut-out: the mask times d is the chance a ray meets the surface.
            let mut coverage = map.image_map(Encoding::Mask);
            coverage.sampler.scale = Vec3::splat(dissolve);
            m.alpha = Some(Alpha {
                coverage: Param::Texture(Box::new(coverage)),
                cutoff: None,
            });
        } else if dissolve < 1.0 {
            // See-through without bending: the opaque part keeps its colour.
            m.transmissive = Param::grey(1.0 - dissolve);
            m.diffuse = match m.diffuse {
                Param::Constant(c) => Param::Constant(c * dissolve),
                textured => textured,
            };
            m.index = Param::grey(1.0);
        }
        if let Some(metal) = self.pm.filter(|m| *m >= 0.5) {
            let roughness = self.pr.unwrap_or(0.0).clamp(0.0, 1.0);
            m.physical = Some(PhysicalMaterial::Conductor {
                eta: Vec3::ONE,
                k: Vec3::ZERO,
                reflectance: Some(m.diffuse.clone()),
                roughness: roughness * roughness,
            });
            m.reflective = m.diffuse.clone();
            m.diffuse = Param::grey(0.0);
            if metal < 1.0 {
                warnings.push((
                    format!("`{name}`: metallic {metal} is read as a metal (caustica has no blend of the two)"),
                    span.clone(),
                ));
            }
        }
        m
    }
}

/// A pinhole at `eye` looking at `target` with vertical field of view `fov_degrees`.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_degrees: f32, aspect_ratio: f32) -> CameraDesc {
    let view = (target - eye).normalize_or_zero();
    let right = view.cross(up).normalize_or_zero();
    CameraDesc {
        position: eye,
        view,
        up: right.cross(view),
        height: 2.0 * (fov_degrees.to_radians() * 0.5).tan(),
        aspect_ratio,
        right: None,
        fov_axis: FovAxis::Vertical,
        lens: None,
        span: 0..0,
    }
}

/// Reads an OBJ file as a whole scene: its mesh with its materials, the camera and lights of
/// `options` or ones chosen to frame it.
pub fn read_scene(
    path: &Path,
    text: String,
    dir: &Path,
    options: &SceneOptions,
    progress: &dyn Progress,
) -> Result<SceneSource> {
    progress.start("parse", text.len() as u64);
    let mut files = SourceFiles::new(path, text);
    let main = files.main().text.clone();
    let result = ObjMesh::parse(&mut files, 0, &main, dir);
    progress.advance(main.len() as u64);
    progress.finish();
    let mesh = result.map_err(|e| files.error(e))?;
    let mut description = SceneDescription {
        warnings: mesh.warnings.clone(),
        ..SceneDescription::default()
    };
    let whole = 0..main.len().min(1);
    description.objects = mesh.objects(Mat4::IDENTITY, None, &whole, &mut description.warnings);
    if description.objects.is_empty() {
        return Err(Error::Scene {
            path: path.to_path_buf(),
            text: main,
            error: ParseError::new("the file has no faces to render", 0..0),
        });
    }
    let (min, max) = mesh_bounds(&description.objects);
    let center = 0.5 * (min + max);
    let radius = (0.5 * (max - min).length()).max(1e-3);
    let camera = match &options.camera {
        None => frame(&description.objects),
        Some(request) => {
            let framed = frame_with(&description.objects, request.fov_degrees);
            let eye = request.eye.unwrap_or(framed.position);
            let target = request.target.unwrap_or(center);
            if (target - eye).cross(request.up).length_squared() < 1e-12 {
                return Err(Error::InvalidSettings(
                    "the OBJ camera's up direction lies along its view (or the eye is the target)".into(),
                ));
            }
            look_at(eye, target, request.up, request.fov_degrees, 1.0)
        }
    };
    // A mesh with emissive materials brings its own light (the physical model's area lights).
    let emits = description.objects.iter().any(|o| match &o.material.emissive {
        Param::Constant(c) => c.max_element() > 0.0,
        _ => true,
    });
    description.lights = if options.lights.is_empty() && emits {
        description.warnings.push((
            "the mesh's emissive materials (Ke) are its only lights: the physical model (--model physical) \
             lights with them, the course model does not (give it --point-light)"
                .into(),
            0..0,
        ));
        Vec::new()
    } else if options.lights.is_empty() {
        // A point light over the camera's left shoulder, of unit irradiance at the centre.
        let right = camera.view.cross(camera.up).normalize_or_zero();
        let eye_distance = (center - camera.position).length().max(radius);
        let position = camera.position + (camera.up.normalize_or_zero() - right) * (0.5 * eye_distance);
        let d2 = (center - position).length_squared();
        vec![LightDesc::Point {
            position,
            color: Vec3::splat(d2),
            attenuation: [0.0, 0.0, 1.0],
            span: 0..0,
        }]
    } else {
        options.lights.clone()
    };
    description.camera = Some(camera);
    Ok(SceneSource::new(files, description))
}

/// A camera framing `objects` (their mesh vertices): 40° vertically, from the front (+z, the
/// usual export's forward) and a little above.
pub fn frame(objects: &[ObjectDesc]) -> CameraDesc {
    frame_with(objects, 40.0)
}

/// [`frame`] with a vertical field of view of `fov` degrees.
fn frame_with(objects: &[ObjectDesc], fov: f32) -> CameraDesc {
    let (min, max) = mesh_bounds(objects);
    let center = 0.5 * (min + max);
    let radius = (0.5 * (max - min).length()).max(1e-3);
    let distance = 1.1 * radius / (fov.to_radians() * 0.5).sin();
    let eye = center + Vec3::new(0.0, 0.35, 1.0).normalize() * distance;
    look_at(eye, center, Vec3::Y, fov, 1.0)
}

fn mesh_bounds(objects: &[ObjectDesc]) -> (Vec3, Vec3) {
    let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for o in objects {
        match &o.shape {
            ShapeDesc::Trimesh(mesh) => {
                for p in &mesh.points {
                    let p = o.world_from_object.transform_point3(*p);
                    min = min.min(p);
                    max = max.max(p);
                }
            }
            _ => {
                let c = o.world_from_object.transform_point3(Vec3::ZERO);
                min = min.min(c);
                max = max.max(c);
            }
        }
    }
    if !min.is_finite() || !max.is_finite() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    (min, max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ObjMesh, ParseError> {
        let mut files = SourceFiles::new(Path::new("t.obj"), text.to_string());
        ObjMesh::parse(&mut files, 0, text, Path::new("."))
    }

    #[test]
    fn faces_of_every_form_and_negative_indices() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
                    f 1 2 3\nf -4/1 -3/2 -1/3\nf 1//1 3//1 4//1\nf 1/1/1 2/2/1 3/3/1 4/3/1\n";
        let mesh = parse(text).unwrap();
        let mut warnings = Vec::new();
        let objects = mesh.objects(Mat4::IDENTITY, None, &(0..1), &mut warnings);
        assert_eq!(objects.len(), 1);
        let ShapeDesc::Trimesh(m) = &objects[0].shape else {
            panic!()
        };
        // 1 + 1 + 1 + 2 triangles (the quad fans into two).
        assert_eq!(m.triangles.len(), 5);
        // Mixed corners: neither every normal nor every uv is known.
        assert!(m.normals.is_none() && m.uvs.is_none());
    }

    #[test]
    fn errors_are_located() {
        let e = parse("v 0 0 0\nv 1 0 0\nf 1 2 x\n").err().unwrap();
        assert_eq!(e.span, 22..23, "{e:?}");
        let e = parse("v 0 0 0\nf 1 2 3\n").err().unwrap();
        assert!(e.message.contains("does not define"), "{e:?}");
        let e = parse("v 0 0 0\nf -2 1 1\n").err().unwrap();
        assert!(e.message.contains("before the first"), "{e:?}");
        let e = parse("v 0 zero 0\n").err().unwrap();
        assert_eq!(e.span, 4..8);
        assert!(parse("f 0 1 2\n").is_err());
    }

    #[test]
    fn mtl_maps_glass_mirrors_and_metals() {
        let mtl = "newmtl glass\nKd 0 0 0\nNi 1.5\nillum 7\nTf 1 1 1\n\
                   newmtl mirror\nKd 0 0 0\nKs 0.9 0.9 0.9\nillum 3\n\
                   newmtl blender_glass\nKd 1 1 1\nNi 1.45\nPr 0\nPm 0\nTf 1 1 1\nillum 2\n\
                   newmtl gold\nKd 1 0.8 0.3\nPm 1\nPr 0.5\n\
                   newmtl cloth\nKd 0.5 0.2 0.1\nd 0.25\n";
        let mut warnings = Vec::new();
        let m: HashMap<_, _> = parse_mtl(mtl, 0, Path::new("."), &mut warnings)
            .unwrap()
            .into_iter()
            .collect();
        assert_eq!(m["glass"].transmissive, Param::grey(1.0));
        assert_eq!(m["glass"].index, Param::grey(1.5));
        assert_eq!(m["mirror"].reflective, Param::grey(0.9));
        assert_eq!(m["blender_glass"].transmissive, Param::grey(1.0));
        assert_eq!(m["blender_glass"].index, Param::grey(1.45));
        assert!(matches!(
            m["gold"].physical,
            Some(PhysicalMaterial::Conductor { roughness, .. }) if (roughness - 0.25).abs() < 1e-6
        ));
        assert_eq!(m["cloth"].transmissive, Param::grey(0.75));
        assert_eq!(m["cloth"].diffuse, Param::Constant(Vec3::new(0.125, 0.05, 0.025)));
        assert!(parse_mtl("Kd 1 1 1\n", 0, Path::new("."), &mut warnings).is_err());
    }

    #[test]
    fn continued_lines_and_comments() {
        let mesh = parse("v 0 0 0 # a comment\nv 1 \\\n 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(mesh.positions.len(), 3);
        assert_eq!(mesh.positions[1], Vec3::X);
    }
}
