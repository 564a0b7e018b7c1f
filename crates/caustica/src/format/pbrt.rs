//! A subset of pbrt-v4's scene format (docs/scene-formats.md says which): directives are read
//! one by one into a graphics state (transform, material, area light) and every shape, light
//! and the camera are lowered into the format-neutral description.
//!
//! pbrt's camera space is left-handed (x right, y up, +z forward): the camera is built from the
//! columns of its world-from-camera matrix — right, up and forward as the file places them —
//! rather than recomputing "right" with a cross product, so images are not mirrored. Everything
//! else (points, matrices, rotations) reads the same in either convention.
//!
//! Directives and types caustica does not render give a warning naming file, line and column,
//! and reading goes on; malformed input is an error.

mod lexer;
mod orientation;
mod params;
mod spectra;
#[cfg(test)]
mod tests;

use self::lexer::{Kind, Lexer, Token};
use self::params::{Params, Spectrum, Values};
use super::{ply, SceneSource, SourceFiles};
use crate::description::{
    Alpha, CameraDesc, ClearCoat, Coating, FovAxis, GridDesc, ImageMap, ImageSource, IntegratorHint, InterfaceDesc,
    LightDesc, MaterialDesc, MediumDesc, MediumSide, MixDesc, NormalMap, ObjectDesc, Param, PhysicalMaterial,
    RoughnessMap, RoughnessRemap, SceneDescription, ShapeDesc, ThinLens, TrimeshDesc, SMOOTH_ALPHA,
};
use crate::error::{ParseError, Result, Span};
use crate::progress::Progress;
use crate::texture::{Encoding, Wrap};
use glam::{Affine2, Mat3, Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Include and Import nest at most this deep (a file including itself is caught here).
const MAX_INCLUDE_DEPTH: usize = 32;
/// Attribute blocks nest at most this deep.
const MAX_NESTING: usize = 10_000;
/// Largest mesh (vertices or indices) accepted from a parameter list.
const MAX_MESH_VALUES: usize = 1 << 28;

/// Reads a pbrt-v4 file (and the files it includes) into a scene description.
pub fn read(path: &Path, text: String, dir: &Path, progress: &dyn Progress) -> Result<SceneSource> {
    progress.start("parse", text.len() as u64);
    let len = text.len() as u64;
    let mut files = SourceFiles::new(path, text.clone());
    let result = Reader::new(&mut files, dir, text).and_then(|r| r.run());
    progress.advance(len);
    progress.finish();
    match result {
        Ok(description) => Ok(SceneSource::new(files, description)),
        Err(e) => Err(files.error(e)),
    }
}

/// A material as the graphics state holds it: the description, or a name to resolve.
#[derive(Clone, Debug)]
enum CurrentMaterial {
    Desc(Box<MaterialDesc>),
    /// No material (pbrt's `interface`): a boundary between media, not drawn.
    Interface,
}

/// `AreaLightSource "diffuse"`: radiance and sides.
#[derive(Clone, Debug)]
struct AreaLight {
    radiance: Vec3,
    power: Option<f32>,
    twosided: bool,
}

#[derive(Clone, Debug)]
struct GraphicsState {
    ctm: Mat4,
    material: CurrentMaterial,
    area_light: Option<AreaLight>,
    reverse_orientation: bool,
    /// `MediumInterface`: the media inside and outside the shapes that follow (indices into
    /// the description's media; `None`: vacuum).
    media: (Option<usize>, Option<usize>),
}

/// One entry of the attribute stack.
struct Saved {
    state: GraphicsState,
    /// Where the block opened, for an unclosed block's warning.
    span: Span,
    /// Only the transform (`TransformBegin`).
    transform_only: bool,
}

/// A texture by name: what a material slot can refer to.
#[derive(Clone, Debug)]
enum TextureValue {
    Param(Param),
    Float(f32),
}

/// One open file: its tokens and, for `Import`, the state to restore at its end.
struct Open {
    lexer: Lexer,
    restore: Option<(GraphicsState, usize)>,
}

struct Reader<'f> {
    files: &'f mut SourceFiles,
    dir: PathBuf,
    open: Vec<Open>,
    peeked: Option<Token>,
    /// States to restore from Imports whose file has ended, applied before the next directive
    /// (the last directive inside may have peeked past the end).
    ended_imports: Vec<(GraphicsState, usize)>,
    state: GraphicsState,
    stack: Vec<Saved>,
    named_systems: HashMap<String, Mat4>,
    named_materials: HashMap<String, MaterialDesc>,
    /// `MakeNamedMedium`'s names (`None`: a kind of medium that is not read).
    named_media: HashMap<String, Option<usize>>,
    textures: HashMap<String, TextureValue>,
    instances: HashMap<String, Vec<ObjectDesc>>,
    defining: Option<(String, Vec<ObjectDesc>, Span)>,
    in_world: bool,
    camera: Option<(Params, Mat4, Span)>,
    film: Option<Params>,
    desc: SceneDescription,
    /// Warnings given once per kind.
    said: std::collections::HashSet<String>,
}

impl<'f> Reader<'f> {
    fn new(files: &'f mut SourceFiles, dir: &Path, text: String) -> Result<Reader<'f>, ParseError> {
        let lexer = Lexer::new(text, 0);
        let state = GraphicsState {
            ctm: Mat4::IDENTITY,
            material: CurrentMaterial::Desc(Box::new(MaterialDesc::lambert(Param::grey(0.5)))),
            area_light: None,
            reverse_orientation: false,
            media: (None, None),
        };
        let mut desc = SceneDescription::default();
        desc.hints.physical = true;
        Ok(Reader {
            files,
            dir: dir.to_path_buf(),
            open: vec![Open { lexer, restore: None }],
            peeked: None,
            ended_imports: Vec::new(),
            state,
            stack: Vec::new(),
            named_systems: HashMap::new(),
            named_materials: HashMap::new(),
            named_media: HashMap::new(),
            textures: HashMap::new(),
            instances: HashMap::new(),
            defining: None,
            in_world: false,
            camera: None,
            film: None,
            desc,
            said: Default::default(),
        })
    }

    fn warn(&mut self, message: impl Into<String>, span: Span) {
        self.desc.warnings.push((message.into(), span));
    }

    /// A warning given only the first time its `key` comes up.
    fn warn_once(&mut self, key: &str, message: impl Into<String>, span: Span) {
        if self.said.insert(key.to_string()) {
            self.warn(message, span);
        }
    }

    // ---- tokens ------------------------------------------------------------------------------

    fn next(&mut self) -> Result<Option<Token>, ParseError> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        loop {
            let Some(top) = self.open.last_mut() else {
                return Ok(None);
            };
            if let Some(t) = top.lexer.next()? {
                return Ok(Some(t));
            }
            let done = self.open.pop().expect("checked above");
            if self.open.is_empty() {
                self.open.push(done);
                return Ok(None);
            }
            if let Some(restore) = done.restore {
                // The end of an Import: its state changes do not leak out.
                self.ended_imports.push(restore);
            }
        }
    }

    fn peek(&mut self) -> Result<Option<&Token>, ParseError> {
        if self.peeked.is_none() {
            self.peeked = self.next()?;
        }
        Ok(self.peeked.as_ref())
    }

    fn end_span(&self) -> Span {
        self.open.last().map_or(0..0, |o| o.lexer.end_span())
    }

    fn expect(&mut self, kind: Kind, what: &str, after: &Token) -> Result<Token, ParseError> {
        match self.next()? {
            Some(t) if t.kind == kind => Ok(t),
            Some(t) => Err(ParseError::new(format!("`{}` expects {what} here", after.text), t.span)),
            None => Err(ParseError::new(
                format!("the file ends where `{}` expects {what}", after.text),
                self.end_span(),
            )),
        }
    }

    fn string_arg(&mut self, after: &Token) -> Result<Token, ParseError> {
        self.expect(Kind::Str, "a quoted string", after)
    }

    fn number(&mut self, after: &Token) -> Result<f32, ParseError> {
        let t = self.expect(Kind::Word, "a number", after)?;
        parse_number(&t)
    }

    fn numbers<const N: usize>(&mut self, after: &Token) -> Result<[f32; N], ParseError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.number(after)?;
        }
        Ok(out)
    }

    /// Numbers in brackets (`Transform [ … ]`); pbrt also takes them bare.
    fn bracketed<const N: usize>(&mut self, after: &Token) -> Result<[f32; N], ParseError> {
        let bracket = matches!(self.peek()?, Some(t) if t.kind == Kind::Open);
        if bracket {
            self.next()?;
        }
        let v = self.numbers::<N>(after)?;
        if bracket {
            self.expect(Kind::Close, &format!("`]` after {N} numbers"), after)?;
        }
        Ok(v)
    }

    /// A parameter list: pairs of a quoted declaration and values, up to the next directive.
    fn params(&mut self) -> Result<Params, ParseError> {
        let mut params = Params::default();
        while let Some(t) = self.peek()? {
            if t.kind != Kind::Str {
                break;
            }
            let decl = self.next()?.expect("peeked");
            let first = self.next()?.ok_or_else(|| {
                ParseError::new(
                    format!("the parameter \"{}\" has no value", decl.text),
                    decl.span.clone(),
                )
            })?;
            let mut tokens = Vec::new();
            let end;
            match first.kind {
                Kind::Open => loop {
                    match self.next()? {
                        Some(t) if t.kind == Kind::Close => {
                            end = t.span.end;
                            break;
                        }
                        Some(t) if t.kind == Kind::Open => {
                            return Err(ParseError::new("brackets do not nest in a parameter list", t.span))
                        }
                        Some(t) => tokens.push(t),
                        None => {
                            return Err(ParseError::new(
                                "this `[` is not closed before the end of the file",
                                first.span,
                            ))
                        }
                    }
                },
                Kind::Close => return Err(ParseError::new("a `]` without its `[`", first.span)),
                _ => {
                    end = first.span.end;
                    tokens.push(first);
                }
            }
            let span = decl.span.start..end;
            let values = if tokens.iter().all(|t| t.kind == Kind::Str) && !tokens.is_empty() {
                Values::Strings(tokens.into_iter().map(|t| t.text).collect())
            } else if tokens
                .iter()
                .all(|t| t.kind == Kind::Word && (t.text == "true" || t.text == "false"))
                && !tokens.is_empty()
            {
                Values::Bools(tokens.iter().map(|t| t.text == "true").collect())
            } else if tokens.iter().all(|t| t.kind == Kind::Word) {
                if tokens.len() > MAX_MESH_VALUES {
                    return Err(ParseError::new("too many values", span));
                }
                Values::Numbers(
                    tokens
                        .iter()
                        .map(|t| parse_number(t).map(f64::from))
                        .collect::<Result<_, _>>()?,
                )
            } else if tokens.len() == 1 && tokens[0].text == "true" || tokens.iter().any(|t| t.kind == Kind::Str) {
                return Err(ParseError::new(
                    "a parameter's values are all numbers, all strings or all true/false",
                    span,
                ));
            } else {
                Values::Numbers(Vec::new())
            };
            params.push(&decl.text, &decl.span, values, span)?;
        }
        Ok(params)
    }

    fn report_unused(&mut self, params: &Params, what: &str) {
        for (name, span) in params.unused() {
            self.warn(format!("`{name}` of {what} is not read"), span);
        }
    }

    // ---- the directive loop ------------------------------------------------------------------

    fn run(mut self) -> Result<SceneDescription, ParseError> {
        while let Some(t) = self.next()? {
            if t.kind != Kind::Word {
                return Err(ParseError::new(
                    match t.kind {
                        Kind::Str => format!("\"{}\" is not a directive: a directive name comes first", t.text),
                        _ => "a bracket where a directive is expected".into(),
                    },
                    t.span,
                ));
            }
            for (state, depth) in std::mem::take(&mut self.ended_imports) {
                self.stack.truncate(depth);
                self.state = state;
            }
            self.directive(t)?;
        }
        if let Some((name, _, span)) = self.defining.take() {
            self.warn(format!("`ObjectBegin \"{name}\"` is not closed"), span);
        }
        if !self.in_world {
            return Err(ParseError::new(
                "the file ends before `WorldBegin`: a pbrt-v4 scene describes its world after it",
                self.end_span(),
            ));
        }
        if let Some(open) = self.stack.last() {
            let span = open.span.clone();
            self.warn("an `AttributeBegin` is not closed", span);
        }
        self.finish_camera()?;
        Ok(self.desc)
    }

    fn concat(&mut self, m: Mat4) {
        self.state.ctm *= m;
    }

    fn directive(&mut self, t: Token) -> Result<(), ParseError> {
        match t.text.as_str() {
            "Identity" => self.state.ctm = Mat4::IDENTITY,
            "Translate" => {
                let [x, y, z] = self.numbers(&t)?;
                self.concat(Mat4::from_translation(Vec3::new(x, y, z)));
            }
            "Scale" => {
                let [x, y, z] = self.numbers(&t)?;
                self.concat(Mat4::from_scale(Vec3::new(x, y, z)));
            }
            "Rotate" => {
                let [angle, x, y, z] = self.numbers(&t)?;
                let axis = Vec3::new(x, y, z);
                if axis.length_squared() == 0.0 {
                    return Err(ParseError::new("`Rotate` needs a non-zero axis", t.span));
                }
                self.concat(Mat4::from_axis_angle(axis.normalize(), angle.to_radians()));
            }
            "LookAt" => {
                let [ex, ey, ez, lx, ly, lz, ux, uy, uz] = self.numbers(&t)?;
                let (eye, look, up) = (Vec3::new(ex, ey, ez), Vec3::new(lx, ly, lz), Vec3::new(ux, uy, uz));
                let dir = (look - eye).normalize_or_zero();
                let right = up.normalize_or_zero().cross(dir);
                if dir == Vec3::ZERO || right.length() < 1e-6 {
                    return Err(ParseError::new(
                        "`LookAt`: the eye and the target coincide, or the up vector lies along the view",
                        t.span,
                    ));
                }
                let right = right.normalize();
                let new_up = dir.cross(right);
                let world_from_camera =
                    Mat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), eye.extend(1.0));
                self.concat(world_from_camera.inverse());
            }
            "Transform" | "ConcatTransform" => {
                let m = Mat4::from_cols_array(&self.bracketed::<16>(&t)?);
                if t.text == "Transform" {
                    self.state.ctm = m;
                } else {
                    self.concat(m);
                }
            }
            "CoordinateSystem" => {
                let name = self.string_arg(&t)?;
                self.named_systems.insert(name.text, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = self.string_arg(&t)?;
                match self.named_systems.get(&name.text) {
                    Some(m) => self.state.ctm = *m,
                    None => self.warn(format!("no coordinate system named \"{}\"", name.text), name.span),
                }
            }
            "ReverseOrientation" => self.state.reverse_orientation = !self.state.reverse_orientation,
            "TransformTimes" => {
                self.numbers::<2>(&t)?;
                self.warn_once(
                    "motion",
                    "motion blur is not rendered: the start transform is used",
                    t.span,
                );
            }
            "ActiveTransform" => {
                let which = self.expect(Kind::Word, "StartTime, EndTime or All", &t)?;
                self.warn_once(
                    "motion",
                    "motion blur is not rendered: the start transform is used",
                    which.span,
                );
            }
            "Option" | "Accelerator" => {
                if t.text == "Accelerator" {
                    self.string_arg(&t)?;
                }
                self.params()?;
            }
            "ColorSpace" => {
                let name = self.string_arg(&t)?;
                if name.text != "srgb" {
                    self.warn(format!("colour space \"{}\" is read as sRGB", name.text), name.span);
                }
            }
            "Camera" => {
                let kind = self.string_arg(&t)?;
                let params = self.params()?;
                if kind.text != "perspective" {
                    self.warn(
                        format!(
                            "the {} camera is not supported: a perspective camera is used",
                            kind.text
                        ),
                        kind.span.clone(),
                    );
                }
                let world_from_camera = self.state.ctm.inverse();
                if !world_from_camera.is_finite() {
                    return Err(ParseError::new("the camera's transform is singular", t.span));
                }
                self.named_systems.insert("camera".into(), world_from_camera);
                // The camera is in the medium outside the interface in effect; so is anything
                // no interface encloses.
                self.desc.camera_medium = self.state.media.1;
                self.desc.ambient_medium = self.state.media.1;
                self.camera = Some((params, world_from_camera, t.span.start..kind.span.end));
            }
            "Film" => {
                let kind = self.string_arg(&t)?;
                let params = self.params()?;
                if !matches!(kind.text.as_str(), "rgb" | "gbuffer" | "spectral") {
                    self.warn(format!("unknown film \"{}\": read as rgb", kind.text), kind.span);
                }
                self.film = Some(params);
            }
            "Sampler" => {
                self.string_arg(&t)?;
                let params = self.params()?;
                let samples = params.int("pixelsamples")?;
                let (x, y) = (params.int("xsamples")?, params.int("ysamples")?);
                let samples = samples.or(x.zip(y).map(|(x, y)| x * y));
                if let Some(n) = samples {
                    if n > 0 {
                        self.desc.hints.samples = Some(n.min(u32::MAX as i64) as u32);
                    }
                }
            }
            "PixelFilter" => {
                self.string_arg(&t)?;
                self.params()?;
                self.warn_once(
                    "filter",
                    "pixel filters are not emulated: caustica averages the samples of each pixel",
                    t.span,
                );
            }
            "Integrator" => self.integrator(&t)?,
            "MakeNamedMedium" => {
                let name = self.string_arg(&t)?;
                let params = self.params()?;
                self.named_medium(name, &params)?;
                self.report_unused(&params, "the medium");
            }
            "MediumInterface" => {
                let inside = self.string_arg(&t)?;
                let outside = if matches!(self.peek()?, Some(n) if n.kind == Kind::Str) {
                    self.string_arg(&t)?
                } else {
                    inside.clone()
                };
                self.state.media = (self.medium_named(&inside), self.medium_named(&outside));
            }
            "WorldBegin" => {
                self.in_world = true;
                self.state.ctm = Mat4::IDENTITY;
                self.named_systems.insert("world".into(), Mat4::IDENTITY);
            }
            "WorldEnd" => self.warn_once(
                "worldend",
                "`WorldEnd` is pbrt-v3 syntax; the scene ends at the end of the file",
                t.span,
            ),
            "AttributeBegin" | "TransformBegin" => {
                if self.stack.len() >= MAX_NESTING {
                    return Err(ParseError::new("attribute blocks nest too deep", t.span));
                }
                let transform_only = t.text == "TransformBegin";
                if transform_only {
                    self.warn_once(
                        "transformbegin",
                        "`TransformBegin` is deprecated in pbrt-v4 (read as saving the transform)",
                        t.span.clone(),
                    );
                }
                self.stack.push(Saved {
                    state: self.state.clone(),
                    span: t.span,
                    transform_only,
                });
            }
            "AttributeEnd" | "TransformEnd" => match self.stack.pop() {
                Some(saved) => {
                    if saved.transform_only {
                        self.state.ctm = saved.state.ctm;
                    } else {
                        self.state = saved.state;
                    }
                }
                None => self.warn(format!("`{}` without a matching begin", t.text), t.span),
            },
            "Attribute" => {
                self.string_arg(&t)?;
                self.params()?;
                self.warn(
                    "`Attribute` defaults are not applied: give the parameters to each directive",
                    t.span,
                );
            }
            "Shape" => self.shape(&t)?,
            "LightSource" => self.light(&t)?,
            "AreaLightSource" => self.area_light(&t)?,
            "Material" => {
                let kind = self.string_arg(&t)?;
                let params = self.params()?;
                self.state.material = self.material(&kind.text, &params, &kind.span)?;
                self.report_unused(&params, &format!("the {} material", kind.text));
            }
            "MakeNamedMaterial" => {
                let name = self.string_arg(&t)?;
                let params = self.params()?;
                let kind = params.string("type")?.map(|s| s.0).unwrap_or_default();
                let material = match self.material(&kind, &params, &name.span)? {
                    CurrentMaterial::Desc(m) => *m,
                    CurrentMaterial::Interface => MaterialDesc {
                        name: Some("interface".into()),
                        ..MaterialDesc::default()
                    },
                };
                self.report_unused(&params, &format!("the material \"{}\"", name.text));
                self.named_materials.insert(name.text, material);
            }
            "NamedMaterial" => {
                let name = self.string_arg(&t)?;
                match self.named_materials.get(&name.text) {
                    Some(m) if m.name.as_deref() == Some("interface") => {
                        self.state.material = CurrentMaterial::Interface
                    }
                    Some(m) => self.state.material = CurrentMaterial::Desc(Box::new(m.clone())),
                    None => {
                        return Err(ParseError::new(
                            format!("no material named \"{}\" has been made", name.text),
                            name.span,
                        ))
                    }
                }
            }
            "Texture" => self.texture(&t)?,
            "ObjectBegin" => {
                let name = self.string_arg(&t)?;
                if self.defining.is_some() {
                    return Err(ParseError::new(
                        "`ObjectBegin` inside another object definition",
                        t.span,
                    ));
                }
                self.stack.push(Saved {
                    state: self.state.clone(),
                    span: t.span.clone(),
                    transform_only: false,
                });
                self.defining = Some((name.text, Vec::new(), t.span));
            }
            "ObjectEnd" => match self.defining.take() {
                Some((name, objects, _)) => {
                    self.instances.insert(name, objects);
                    if let Some(saved) = self.stack.pop() {
                        self.state = saved.state;
                    }
                }
                None => self.warn("`ObjectEnd` without `ObjectBegin`", t.span),
            },
            "ObjectInstance" => {
                let name = self.string_arg(&t)?;
                if self.defining.is_some() {
                    return Err(ParseError::new("`ObjectInstance` inside an object definition", t.span));
                }
                let Some(objects) = self.instances.get(&name.text) else {
                    return Err(ParseError::new(format!("no object named \"{}\"", name.text), name.span));
                };
                let ctm = self.state.ctm;
                let placed: Vec<ObjectDesc> = objects
                    .iter()
                    .map(|o| ObjectDesc {
                        world_from_object: ctm * o.world_from_object,
                        span: t.span.start..name.span.end,
                        ..o.clone()
                    })
                    .collect();
                self.desc.objects.extend(placed);
            }
            "Include" | "Import" => {
                let name = self.string_arg(&t)?;
                if self.open.len() >= MAX_INCLUDE_DEPTH {
                    return Err(ParseError::new(
                        "files include each other too deep (or include themselves)",
                        name.span,
                    ));
                }
                let path = self.dir.join(&name.text);
                if path.extension().is_some_and(|e| e == "gz") {
                    return Err(ParseError::new(
                        "gzip-compressed files are not read: decompress it first",
                        name.span,
                    ));
                }
                let (base, text) = self.files.read_text(&path, &name.span)?;
                let text = text.to_string();
                let restore = (t.text == "Import").then(|| (self.state.clone(), self.stack.len()));
                self.open.push(Open {
                    lexer: Lexer::new(text, base),
                    restore,
                });
            }
            _ => {
                self.warn(
                    format!("unknown directive `{}`: skipped with its parameters", t.text),
                    t.span,
                );
                // Skip its arguments: everything up to the next bare word that is not a value.
                while let Some(next) = self.peek()? {
                    let value = next.kind != Kind::Word
                        || next.text == "true"
                        || next.text == "false"
                        || next.text.parse::<f64>().is_ok();
                    if !value {
                        break;
                    }
                    self.next()?;
                }
            }
        }
        Ok(())
    }

    fn integrator(&mut self, t: &Token) -> Result<(), ParseError> {
        let kind = self.string_arg(t)?;
        let params = self.params()?;
        let hint = match kind.text.as_str() {
            "sppm" => IntegratorHint::Ppm,
            "lightpath" => IntegratorHint::LightTracer,
            "path" | "volpath" | "simplepath" | "simplevolpath" => IntegratorHint::Path,
            "bdpt" | "mlt" => {
                self.warn(
                    format!(
                        "the {} integrator is not in caustica: rendered with vcm, whose strategies include \
                         bidirectional path tracing's and add photon merging (consistent, not unbiased)",
                        kind.text
                    ),
                    kind.span.clone(),
                );
                IntegratorHint::Bidirectional
            }
            other => {
                self.warn(
                    format!("the {other} integrator is not in caustica: rendered with path"),
                    kind.span.clone(),
                );
                IntegratorHint::Path
            }
        };
        self.desc.hints.integrator = Some(hint);
        if let Some(depth) = params.int("maxdepth")? {
            self.desc.hints.max_depth = Some(depth.clamp(0, 10_000) as u32);
        }
        if let Some(n) = params.int("photonsperiteration")? {
            if n > 0 {
                self.desc.hints.photons_per_pass = Some(n as usize);
            }
        }
        if let Some(r) = params.float("radius")? {
            if r > 0.0 && r.is_finite() {
                self.desc.hints.radius = Some(r);
            }
        }
        if let Some(n) = params.int("iterations")?.or(params.int("numiterations")?) {
            if n > 0 {
                self.desc.hints.samples = Some(n.min(u32::MAX as i64) as u32);
            }
        }
        self.report_unused(&params, &format!("the {} integrator", kind.text));
        Ok(())
    }

    /// The camera, once the film's size is known (pbrt's fov spans the shorter image axis).
    fn finish_camera(&mut self) -> Result<(), ParseError> {
        let film = self.film.take().unwrap_or_default();
        let xres = film.int("xresolution")?.unwrap_or(1280).clamp(1, 1 << 15) as usize;
        let yres = film.int("yresolution")?.unwrap_or(720).clamp(1, 1 << 15) as usize;
        self.desc.hints.width = Some(xres);
        self.desc.hints.height = Some(yres);
        if let Some((name, _)) = film.string("filename")? {
            self.desc.hints.output = Some(PathBuf::from(name));
        }
        for (what, name) in [("cropwindow", "a crop window"), ("pixelbounds", "pixel bounds")] {
            if let Some(span) = film.span_of(what) {
                self.warn(format!("{name} is not applied: the whole image is rendered"), span);
            }
        }
        // Sensor settings scale pbrt's image; left unread they are warned about.
        film.float("diagonal")?;
        film.float("maxcomponentvalue")?;
        film.bool_or("savefp16", true)?;
        self.report_unused(&film, "the film");
        let Some((params, w, span)) = self.camera.take() else {
            return Ok(());
        };
        let frame = params.float_or("frameaspectratio", xres as f32 / yres as f32)?;
        let mut window = if frame > 1.0 {
            [-frame, frame, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / frame, 1.0 / frame]
        };
        if let Some((v, s)) = params.list("screenwindow", &["float"], 4)? {
            if v.len() != 4 || v[0] >= v[1] || v[2] >= v[3] {
                return Err(ParseError::new("`screenwindow` takes xmin xmax ymin ymax", s));
            }
            window = [v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32];
        }
        let fov = params.float_or("fov", 90.0)?;
        if !(fov > 0.0 && fov < 180.0) {
            let s = params.span_of("fov").unwrap_or(span.clone());
            return Err(ParseError::new("`fov` must lie between 0 and 180 degrees", s));
        }
        // pbrt-v4's defaults: no aperture, focus a million units away.
        let lens_radius = params.float("lensradius")?.unwrap_or(0.0);
        let focus = params.float("focaldistance")?.unwrap_or(1e6);
        let lens = (lens_radius > 0.0 && focus > 0.0).then_some(ThinLens {
            radius: lens_radius,
            focus,
        });
        params.float("shutteropen")?;
        params.float("shutterclose")?;
        self.report_unused(&params, "the camera");
        let t = (fov.to_radians() * 0.5).tan();
        let eye = w.transform_point3(Vec3::ZERO);
        let forward = w.transform_vector3(Vec3::Z);
        let up = w.transform_vector3(Vec3::Y);
        let right = w.transform_vector3(Vec3::X);
        let (forward, up, right) = (
            forward.normalize_or_zero(),
            up.normalize_or_zero(),
            right.normalize_or_zero(),
        );
        let centre = Vec2::new(window[0] + window[1], window[2] + window[3]) * 0.5 * t;
        self.desc.camera = Some(CameraDesc {
            position: eye,
            view: forward + right * centre.x + up * centre.y,
            up,
            height: (window[3] - window[2]) * t,
            aspect_ratio: (window[1] - window[0]) / (window[3] - window[2]),
            right: Some(right),
            fov_axis: FovAxis::Shorter,
            lens,
            span,
        });
        Ok(())
    }

    // ---- media ----------------------------------------------------------------------------------

    /// `MakeNamedMedium`: a homogeneous medium or a `uniformgrid` density in the current
    /// transform's space; other kinds are named but left out (vacuum) with a warning.
    fn named_medium(&mut self, name: Token, params: &Params) -> Result<(), ParseError> {
        let (kind, kind_span) = params.string("type")?.unwrap_or_default();
        let scale = params.float_or("scale", 1.0)?;
        let g = params.float_or("g", 0.0)?;
        if !(-1.0 < g && g < 1.0) {
            return Err(ParseError::new(
                format!("the medium's `g` must lie strictly between −1 and 1, not {g}"),
                params.span_of("g").unwrap_or(name.span),
            ));
        }
        if params.has("preset") {
            self.warn(
                "measured medium presets are not known: `sigma_a` and `sigma_s` are used".to_string(),
                params.span_of("preset").unwrap_or(name.span.clone()),
            );
        }
        for emission in ["Le", "Lescale", "temperature", "temperaturescale"] {
            if let Some(span) = params.span_of(emission) {
                self.warn_once("mediumle", "emitting media are not rendered: `Le` is ignored", span);
            }
        }
        let grid = match kind.as_str() {
            "homogeneous" => None,
            "uniformgrid" => Some(self.density_grid(params, &name)?),
            _ => {
                self.warn(
                    format!(
                        "the {kind} medium is not supported: \"{}\" is left out (clear)",
                        name.text
                    ),
                    kind_span,
                );
                self.named_media.insert(name.text, None);
                return Ok(());
            }
        };
        let sigma_a = self.constant_colour(params, "sigma_a", Vec3::ONE)? * scale;
        let sigma_s = self.constant_colour(params, "sigma_s", Vec3::ONE)? * scale;
        self.desc.media.push(MediumDesc {
            name: Some(name.text.clone()),
            sigma_a,
            sigma_s,
            g,
            grid,
            span: name.span,
        });
        self.named_media.insert(name.text, Some(self.desc.media.len() - 1));
        Ok(())
    }

    /// A `uniformgrid`'s densities (`nx`×`ny`×`nz`, x fastest) over the box from `p0` to `p1` in
    /// the current transform's space.
    fn density_grid(&mut self, params: &Params, name: &Token) -> Result<GridDesc, ParseError> {
        let dim = |axis: &str| -> Result<usize, ParseError> {
            match params.int(axis)? {
                None => Ok(1),
                Some(n) if (1..=1 << 16).contains(&n) => Ok(n as usize),
                Some(n) => Err(ParseError::new(
                    format!("`{axis}` must be from 1 to 65536, not {n}"),
                    params.span_of(axis).unwrap_or(name.span.clone()),
                )),
            }
        };
        let dims = [dim("nx")?, dim("ny")?, dim("nz")?];
        let Some((values, span)) = params.list("density", &["float"], 1)? else {
            return Err(ParseError::new(
                "a uniformgrid medium needs `density` values",
                name.span.clone(),
            ));
        };
        let count = dims[0] * dims[1] * dims[2];
        if values.len() != count {
            return Err(ParseError::new(
                format!("{} density values for a grid of {count}", values.len()),
                span,
            ));
        }
        if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err(ParseError::new("densities must be finite and not negative", span));
        }
        let p0 = params.vec3("p0", &["point3", "point"])?.unwrap_or(Vec3::ZERO);
        let p1 = params.vec3("p1", &["point3", "point"])?.unwrap_or(Vec3::ONE);
        let size = p1 - p0;
        if !size.cmpgt(Vec3::ZERO).all() {
            return Err(ParseError::new(
                "the grid's `p1` must lie above `p0` on every axis",
                params.span_of("p1").unwrap_or(name.span.clone()),
            ));
        }
        let medium_from_world = self.state.ctm.inverse();
        if !medium_from_world.is_finite() {
            return Err(ParseError::new("the medium's transform is singular", name.span.clone()));
        }
        Ok(GridDesc {
            dims,
            values: values.iter().map(|&v| v as f32).collect(),
            grid_from_world: Mat4::from_scale(size.recip()) * Mat4::from_translation(-p0) * medium_from_world,
        })
    }

    /// The medium a `MediumInterface` names ("": vacuum; an unknown name warns and is vacuum).
    fn medium_named(&mut self, name: &Token) -> Option<usize> {
        if name.text.is_empty() {
            return None;
        }
        match self.named_media.get(&name.text) {
            Some(&m) => m,
            None => {
                self.warn(
                    format!("no medium named \"{}\": read as clear", name.text),
                    name.span.clone(),
                );
                None
            }
        }
    }

    // ---- materials and textures ----------------------------------------------------------------

    /// A colour slot: a constant, a named texture, or `default`.
    fn colour(&mut self, params: &Params, name: &str, default: Vec3) -> Result<Param, ParseError> {
        let Some((value, span)) = params.spectrum(name)? else {
            return Ok(Param::Constant(default));
        };
        Ok(match value {
            Spectrum::Rgb(c) => {
                if c.min_element() < 0.0 {
                    return Err(ParseError::new(format!("`{name}` cannot be negative"), span));
                }
                Param::Constant(c)
            }
            Spectrum::Texture(t) => match self.textures.get(&t) {
                Some(TextureValue::Param(p)) => p.clone(),
                Some(TextureValue::Float(f)) => Param::grey(*f),
                None => return Err(ParseError::new(format!("no texture named \"{t}\""), span)),
            },
            Spectrum::Blackbody(k) => Param::Constant(spectra::blackbody(k)),
            Spectrum::Sampled(pairs) => Param::Constant(spectra::sampled_to_rgb(&pairs)),
            Spectrum::Named(n) => {
                self.warn(
                    format!("the spectrum \"{n}\" is not a reflectance caustica knows: grey 0.5"),
                    span,
                );
                Param::grey(0.5)
            }
        })
    }

    /// A constant colour (textures are refused with a warning: `what` reads constants only).
    fn constant_colour(&mut self, params: &Params, name: &str, default: Vec3) -> Result<Vec3, ParseError> {
        match self.colour(params, name, default)? {
            Param::Constant(c) => Ok(c),
            _ => {
                let span = params.span_of(name).unwrap_or(0..0);
                self.warn(format!("`{name}` cannot be a texture here: its default is used"), span);
                Ok(default)
            }
        }
    }

    /// A float slot (a texture reference to a constant float texture is read too).
    fn float_slot(&mut self, params: &Params, name: &str, default: f32) -> Result<f32, ParseError> {
        if let Some((Spectrum::Texture(t), span)) = params.spectrum(name)? {
            return match self.textures.get(&t) {
                Some(TextureValue::Float(f)) => Ok(*f),
                Some(TextureValue::Param(Param::Constant(c))) => Ok(c.x),
                _ => {
                    self.warn(
                        format!("`{name}` from an image texture is not read: {default} instead"),
                        span,
                    );
                    Ok(default)
                }
            };
        }
        params.float_or(name, default)
    }

    /// pbrt's roughness from an image texture (`uroughness`, else `roughness`, else
    /// `vroughness`, each with `prefix`), read at each point by the physical lobe.
    fn roughness_map(
        &mut self,
        params: &Params,
        span: &Span,
        prefix: &str,
    ) -> Result<Option<RoughnessMap>, ParseError> {
        let mut found = Vec::new();
        for name in ["uroughness", "roughness", "vroughness"] {
            if let Some((Spectrum::Texture(t), _)) = params.spectrum(&format!("{prefix}{name}"))? {
                if let Some(TextureValue::Param(p @ Param::Texture(_))) = self.textures.get(&t) {
                    found.push(p.clone());
                }
            }
        }
        let Some(texture) = found.first().cloned() else {
            return Ok(None);
        };
        if found.iter().any(|t| *t != texture) {
            self.warn_once(
                "anisotropictexture",
                "anisotropic roughness textures are read as `uroughness`'s",
                span.clone(),
            );
        }
        Ok(Some(RoughnessMap {
            texture,
            remap: if params.bool_or("remaproughness", true)? {
                RoughnessRemap::Sqrt
            } else {
                RoughnessRemap::Alpha
            },
        }))
    }

    /// GGX α from pbrt's `roughness` (or the mean of `uroughness`/`vroughness`), `default`
    /// when neither is given (0 in pbrt-v4; pbrt-v3's materials have their own).
    fn roughness(&mut self, params: &Params, span: &Span, default: f32) -> Result<f32, ParseError> {
        self.roughness_of(params, span, "", default)
    }

    /// [`Parser::roughness`] of the parameters named with `prefix` (`coatedconductor`'s
    /// `interface.` and `conductor.`).
    fn roughness_of(&mut self, params: &Params, span: &Span, prefix: &str, default: f32) -> Result<f32, ParseError> {
        // An image texture is read point by point (`roughness_map`; the coat of a coated
        // conductor has no such reading): the constant only picks the lobe and the course
        // model's gloss.
        if prefix != "interface." && self.roughness_map(params, span, prefix)?.is_some() {
            return Ok(TEXTURED_ALPHA);
        }
        let r = self.float_slot(params, &format!("{prefix}roughness"), default)?;
        let u = self.float_slot(params, &format!("{prefix}uroughness"), r)?;
        let v = self.float_slot(params, &format!("{prefix}vroughness"), r)?;
        if (u - v).abs() > 1e-6 {
            self.warn("anisotropic roughness is read as the mean of u and v", span.clone());
        }
        let r = (0.5 * (u + v)).max(0.0);
        Ok(if params.bool_or("remaproughness", true)? {
            r.sqrt()
        } else {
            r
        })
    }

    fn material(&mut self, kind: &str, params: &Params, span: &Span) -> Result<CurrentMaterial, ParseError> {
        let m = match kind {
            "diffuse" => MaterialDesc::lambert(self.colour(params, "reflectance", Vec3::splat(0.5))?),
            "dielectric" | "thindielectric" | "glass" => {
                // pbrt-v3 glass may give its index as `index`.
                let (index, abbe) = if kind == "glass" && params.has("index") && !params.has("eta") {
                    (self.float_slot(params, "index", 1.5)?, None)
                } else {
                    self.eta(params)?
                };
                let alpha = self.roughness(params, span, 0.0)?;
                if kind == "glass" {
                    self.v3_tints(params, span, &["Kr", "Kt"])?;
                }
                let mut m = MaterialDesc {
                    transmissive: Param::grey(1.0),
                    index: Param::grey(index),
                    abbe,
                    ..MaterialDesc::default()
                };
                if alpha >= SMOOTH_ALPHA && kind != "thindielectric" {
                    m.physical = Some(PhysicalMaterial::RoughDielectric {
                        eta: index,
                        roughness: alpha,
                        tint: Param::grey(1.0),
                        abbe,
                    });
                }
                if kind == "thindielectric" {
                    m.index = Param::grey(1.0);
                    m.physical = Some(PhysicalMaterial::ThinDielectric {
                        eta: index,
                        tint: Param::grey(1.0),
                    });
                }
                m
            }
            "conductor" | "metal" => {
                // pbrt-v3's metal is a little rough by default.
                let alpha = self.roughness(params, span, if kind == "metal" { 0.01 } else { 0.0 })?;
                let (physical, f0) = self.conductor(params, span, "", alpha, 1.0)?;
                let mut m = MaterialDesc {
                    physical: Some(physical),
                    ..MaterialDesc::default()
                };
                m.course_gloss(f0, alpha);
                m
            }
            "coatedconductor" => {
                // A conductor under a clear coat, the conductor's index taken relative to the
                // coat's (pbrt-v4 divides it so); light bouncing between them is not followed.
                let coat_alpha = self.roughness_of(params, span, "interface.", 0.0)?;
                let coat_eta = self.float_slot(params, "interface.eta", 1.5)?.max(1.0);
                let alpha = self.roughness_of(params, span, "conductor.", 0.0)?;
                let (physical, f0) = self.conductor(params, span, "conductor.", alpha, coat_eta)?;
                for unused in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                    if let Some(s) = params.span_of(unused) {
                        self.warn(format!("`{unused}` of the coated conductor is not modelled"), s);
                    }
                }
                let mut m = MaterialDesc {
                    physical: Some(physical),
                    clearcoat: Some(ClearCoat {
                        weight: 1.0,
                        eta: coat_eta,
                        alpha: coat_alpha,
                    }),
                    ..MaterialDesc::default()
                };
                m.course_gloss(f0, alpha);
                m
            }
            "coateddiffuse" => {
                let base = self.colour(params, "reflectance", Vec3::splat(0.5))?;
                let alpha = self.roughness(params, span, 0.0)?;
                let eta = self.float_slot(params, "eta", 1.5)?.max(1.0);
                MaterialDesc::coated(base, eta, alpha, Coating::Layered)
            }
            "matte" | "plastic" | "substrate" | "mirror" | "uber" | "translucent" => {
                self.v3_material(kind, params, span)?
            }
            "diffusetransmission" => {
                let scale = params.float_or("scale", 1.0)?;
                let r = self.colour(params, "reflectance", Vec3::splat(0.25))?;
                let t = self.colour(params, "transmittance", Vec3::splat(0.25))?;
                diffuse_transmission(scaled(r, scale), scaled(t, scale))
            }
            "interface" | "" | "none" => return Ok(CurrentMaterial::Interface),
            "mix" => {
                let amount = self.float_slot(params, "amount", 0.5)?;
                let Some((names, s)) = params.strings("materials") else {
                    return Err(ParseError::new("a mix material needs `string materials`", span.clone()));
                };
                if names.len() != 2 {
                    return Err(ParseError::new("`materials` names two materials", s));
                }
                let mut parts = Vec::with_capacity(2);
                for name in &names {
                    match self.named_materials.get(name) {
                        Some(m) => parts.push(m.clone()),
                        None => return Err(ParseError::new(format!("no material named \"{name}\""), s)),
                    }
                }
                let second = parts.pop().expect("two parts");
                let first = parts.pop().expect("two parts");
                // The course model reads the larger part.
                let mut m = if amount >= 0.5 { second.clone() } else { first.clone() };
                m.mix = Some(Box::new(MixDesc {
                    materials: [first, second],
                    amount: Param::grey(amount.clamp(0.0, 1.0)),
                }));
                m
            }
            other => {
                self.warn(
                    format!("the {other} material is not supported: grey diffuse instead"),
                    span.clone(),
                );
                MaterialDesc::lambert(Param::grey(0.5))
            }
        };
        let mut m = m;
        let prefix = if kind == "coatedconductor" { "conductor." } else { "" };
        m.roughness_map = self.roughness_map(params, span, prefix)?;
        if let Some(s) = params.span_of("displacement") {
            let _ = params.spectrum("displacement");
            self.warn("`displacement` is not applied", s);
        }
        // pbrt-v4's normal map: a linear image whose texels 2c − 1 are the normal in the frame
        // of the surface's u direction and normal, repeating.
        if let Some((file, s)) = params.string("normalmap")? {
            let image = self.dir.join(&file);
            if image.is_file() {
                let mut map = ImageMap::colour(ImageSource::File(image), s);
                map.encoding = Encoding::Linear;
                m.normal_map = Some(NormalMap { map, scale: 1.0 });
            } else {
                self.warn(
                    format!(
                        "the normal map `{}` is missing: the surface is shaded without it",
                        image.display()
                    ),
                    s,
                );
            }
        }
        Ok(CurrentMaterial::Desc(Box::new(m)))
    }

    /// pbrt-v3's materials, read onto caustica's (docs/scene-formats.md says how; where the
    /// reading is approximate, a warning says what is left out).
    fn v3_material(&mut self, kind: &str, params: &Params, span: &Span) -> Result<MaterialDesc, ParseError> {
        Ok(match kind {
            "matte" => {
                if self.float_slot(params, "sigma", 0.0)? > 0.0 {
                    self.warn(
                        "matte's Oren–Nayar roughness (sigma) is not modelled: Lambert",
                        span.clone(),
                    );
                }
                MaterialDesc::lambert(self.colour(params, "Kd", Vec3::splat(0.5))?)
            }
            // Lambert under a highlight: a diffuse base under a clear coat of index 1.5 (the
            // index pbrt-v3's plastic gives its Fresnel term); without Ks, the base alone.
            "plastic" => {
                let base = self.colour(params, "Kd", Vec3::splat(0.25))?;
                let ks = self.colour(params, "Ks", Vec3::splat(0.25))?;
                let alpha = self.roughness(params, span, 0.1)?;
                if ks == Param::grey(0.0) {
                    MaterialDesc::lambert(base)
                } else {
                    self.warn_once(
                        "plastic",
                        "plastic is read as a diffuse base under a clear coat of index 1.5: Ks does not scale its highlight",
                        span.clone(),
                    );
                    MaterialDesc::coated(base, 1.5, alpha, Coating::Fresnel)
                }
            }
            // Ashikhmin–Shirley: a base under a coat whose normal reflectance is Ks.
            "substrate" => {
                let base = self.colour(params, "Kd", Vec3::splat(0.5))?;
                let f0 = match self.colour(params, "Ks", Vec3::splat(0.5))? {
                    Param::Constant(c) => c.dot(Vec3::splat(1.0 / 3.0)).clamp(0.0, 0.9),
                    _ => {
                        self.warn("a textured Ks of substrate is read as 0.04", span.clone());
                        0.04
                    }
                };
                let alpha = self.roughness(params, span, 0.1)?;
                MaterialDesc::coated(base, (1.0 + f0.sqrt()) / (1.0 - f0.sqrt()), alpha, Coating::Fresnel)
            }
            "mirror" => {
                let kr = self.colour(params, "Kr", Vec3::splat(0.9))?;
                MaterialDesc::mirror(kr)
            }
            // Its main lobe: glass where it transmits, a mirror where it only reflects, else a
            // coated base; `opacity` below one lets rays through.
            "uber" => {
                let kd = self.colour(params, "Kd", Vec3::splat(0.25))?;
                let ks = self.colour(params, "Ks", Vec3::splat(0.25))?;
                let kr = self.colour(params, "Kr", Vec3::ZERO)?;
                let kt = self.colour(params, "Kt", Vec3::ZERO)?;
                let alpha = self.roughness(params, span, 0.1)?;
                let index = if params.has("index") && !params.has("eta") {
                    self.float_slot(params, "index", 1.5)?
                } else {
                    self.eta(params)?.0
                };
                let black = Param::grey(0.0);
                let mut m = if kt != black {
                    MaterialDesc {
                        transmissive: kt,
                        index: Param::grey(index),
                        ..MaterialDesc::default()
                    }
                } else if kr != black && kd == black {
                    MaterialDesc::mirror(kr)
                } else if ks == black {
                    MaterialDesc::lambert(kd)
                } else {
                    MaterialDesc::coated(kd, index.max(1.0), alpha, Coating::Fresnel)
                };
                self.warn_once(
                    "uber",
                    "uber is read as its main lobe (glass where Kt, a mirror where only Kr, else a coated diffuse base)",
                    span.clone(),
                );
                match self.colour(params, "opacity", Vec3::ONE)? {
                    Param::Constant(c) if c.min_element() >= 1.0 => {}
                    coverage => m.alpha = Some(Alpha { coverage, cutoff: None }),
                }
                m
            }
            "translucent" => {
                let kd = self.colour(params, "Kd", Vec3::splat(0.25))?;
                let reflect = self.colour(params, "reflect", Vec3::splat(0.5))?;
                let transmit = self.colour(params, "transmit", Vec3::splat(0.5))?;
                let times = |a: &Param, b: &Param| match (a, b) {
                    (Param::Constant(a), Param::Constant(b)) => Param::Constant(*a * *b),
                    (textured, _) => textured.clone(),
                };
                let (r, t) = (times(&kd, &reflect), times(&kd, &transmit));
                self.warn(
                    "translucent's glossy part (Ks) is not modelled: diffuse reflection and transmission",
                    span.clone(),
                );
                diffuse_transmission(r, t)
            }
            _ => unreachable!("only pbrt-v3's materials are read here"),
        })
    }

    /// pbrt-v3 glass's Kr and Kt: other than white, a warning (caustica's glass is clear).
    fn v3_tints(&mut self, params: &Params, span: &Span, names: &[&str]) -> Result<(), ParseError> {
        for name in names {
            if self.colour(params, name, Vec3::ONE)? != Param::grey(1.0) {
                self.warn(
                    format!("glass's {name} is not applied: the glass is clear"),
                    span.clone(),
                );
            }
        }
        Ok(())
    }

    /// A pbrt-v3 spectrum file (wavelength–value pairs, `#` comments) at about 650, 550 and
    /// 450 nm. A file that is not there is read by its name where it names a metal pbrt-v4
    /// tabulates (`Au.eta.spd` as `metal-Au-eta`), else `default`, with a warning either way.
    fn spd(&mut self, name: &str, span: Span, default: Vec3) -> Result<Vec3, ParseError> {
        let path = self.dir.join(name);
        if let Ok(text) = std::fs::read_to_string(&path) {
            let numbers: Vec<f32> = text
                .lines()
                .map(|l| l.split('#').next().unwrap_or(""))
                .flat_map(str::split_whitespace)
                .map(str::parse)
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| {
                    ParseError::new(
                        format!("`{}` holds something other than numbers", path.display()),
                        span.clone(),
                    )
                })?;
            let chunks = numbers.chunks_exact(2);
            let unpaired = !chunks.remainder().is_empty();
            let pairs: Vec<(f32, f32)> = chunks.map(|p| (p[0], p[1])).collect();
            if pairs.is_empty() || unpaired || pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
                return Err(ParseError::new(
                    format!(
                        "`{}` is not a list of wavelength–value pairs in rising order",
                        path.display()
                    ),
                    span,
                ));
            }
            return Ok(Vec3::new(
                spectra::sample(&pairs, 650.0),
                spectra::sample(&pairs, 550.0),
                spectra::sample(&pairs, 450.0),
            ));
        }
        let stem = Path::new(name).file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let tabulated = stem
            .split_once('.')
            .and_then(|(metal, part)| spectra::metal_part(&format!("metal-{metal}-{part}")).map(|v| (v, metal, part)));
        Ok(match tabulated {
            Some((v, metal, part)) => {
                self.warn(
                    format!(
                        "`{}` is missing: pbrt-v4's metal-{metal}-{part} is used",
                        path.display()
                    ),
                    span,
                );
                v
            }
            None => {
                self.warn(format!("`{}` is missing: the default is used", path.display()), span);
                default
            }
        })
    }

    /// A dielectric's `eta`: n_d, and V_d for named or sampled glasses.
    /// A conductor from `reflectance`, or from `eta` and `k` named with `prefix` (copper by
    /// default), with GGX α `alpha`, in a medium of index `outside` (its index is
    /// taken relative to it); also its normal reflectance, for the course reading.
    fn conductor(
        &mut self,
        params: &Params,
        span: &Span,
        prefix: &str,
        alpha: f32,
        outside: f32,
    ) -> Result<(PhysicalMaterial, Vec3), ParseError> {
        // `reflectance` has no prefix in pbrt-v4's coated conductor either.
        let (reflectance_name, eta_name, k_name) = ("reflectance", format!("{prefix}eta"), format!("{prefix}k"));
        let (eta, k, r) = if params.has(reflectance_name) {
            if params.has(&eta_name) || params.has(&k_name) {
                return Err(ParseError::new(
                    "a conductor takes `reflectance` or `eta` and `k`, not both",
                    span.clone(),
                ));
            }
            let r = self.colour(params, reflectance_name, Vec3::ONE)?;
            (Vec3::ONE, Vec3::ZERO, Some(r))
        } else {
            let (cu_eta, cu_k) = spectra::metal("metal-Cu").expect("copper is known");
            (
                self.index_rgb(params, &eta_name, cu_eta)? / outside,
                self.index_rgb(params, &k_name, cu_k)? / outside,
                None,
            )
        };
        let f0 = match &r {
            Some(Param::Constant(c)) => *c,
            Some(_) => Vec3::splat(0.8),
            None => ((eta - Vec3::ONE).powf(2.0) + k * k) / ((eta + Vec3::ONE).powf(2.0) + k * k),
        };
        let physical = PhysicalMaterial::Conductor {
            eta,
            k,
            reflectance: r,
            roughness: alpha,
        };
        Ok((physical, f0))
    }

    fn eta(&mut self, params: &Params) -> Result<(f32, Option<f32>), ParseError> {
        let (eta, abbe) = match params.spectrum("eta")? {
            None => (1.5, None),
            Some((Spectrum::Rgb(c), _)) => (c.x, None),
            Some((Spectrum::Named(name), span)) => match spectra::glass(&name) {
                Some((n, v)) => (n, Some(v)),
                None => return Err(ParseError::new(format!("unknown glass \"{name}\""), span)
                    .with_help("pbrt-v4's glasses: glass-BK7, glass-BAF10, glass-FK51A, glass-LASF9, glass-F5, glass-F10, glass-F11")),
            },
            Some((Spectrum::Sampled(pairs), _)) => spectra::sampled_index(&pairs),
            Some((Spectrum::Texture(t), span)) => match self.textures.get(&t) {
                Some(TextureValue::Float(f)) => (*f, None),
                _ => return Err(ParseError::new("`eta` must be a constant", span)),
            },
            Some((_, span)) => return Err(ParseError::new("`eta` must be a number or a spectrum", span)),
        };
        if !(eta > 0.0 && eta.is_finite()) {
            let span = params.span_of("eta").unwrap_or(0..0);
            return Err(ParseError::new("`eta` must be positive", span));
        }
        Ok((eta, abbe))
    }

    /// A conductor's `eta` or `k`: RGB, a named metal spectrum, or sampled.
    fn index_rgb(&mut self, params: &Params, name: &str, default: Vec3) -> Result<Vec3, ParseError> {
        Ok(match params.spectrum(name)? {
            None => default,
            Some((Spectrum::Rgb(c), _)) => c,
            // pbrt-v3 names tabulated files, `spds/metals/Au.eta.spd`.
            Some((Spectrum::Named(n), span)) if n.ends_with(".spd") => self.spd(&n, span, default)?,
            Some((Spectrum::Named(n), span)) => match spectra::metal_part(&n) {
                Some(v) => v,
                None => {
                    return Err(ParseError::new(format!("unknown spectrum \"{n}\""), span)
                        .with_help("pbrt-v4's metals: metal-{Ag,Al,Au,Cu,CuZn,MgO,TiO2}-{eta,k}"))
                }
            },
            Some((Spectrum::Sampled(pairs), _)) => Vec3::new(
                spectra::sample(&pairs, 650.0),
                spectra::sample(&pairs, 550.0),
                spectra::sample(&pairs, 450.0),
            ),
            Some((_, span)) => return Err(ParseError::new(format!("`{name}` must be a spectrum or rgb"), span)),
        })
    }

    fn texture(&mut self, t: &Token) -> Result<(), ParseError> {
        let name = self.string_arg(t)?;
        let ty = self.string_arg(t)?;
        let class = self.string_arg(t)?;
        let params = self.params()?;
        if !matches!(ty.text.as_str(), "spectrum" | "float" | "color") {
            return Err(ParseError::new(
                format!("a texture's type is \"spectrum\" or \"float\", not \"{}\"", ty.text),
                ty.span,
            ));
        }
        let float = ty.text == "float";
        let value = match class.text.as_str() {
            "imagemap" => {
                let Some((file, span)) = params.string("filename")? else {
                    return Err(ParseError::new("an imagemap needs `string filename`", class.span));
                };
                let image = self.dir.join(file);
                if !image.is_file() {
                    self.warn(super::missing_image(&image), span.clone());
                    self.textures.insert(name.text, TextureValue::Param(Param::grey(0.5)));
                    return Ok(());
                }
                let mut map = ImageMap::colour(ImageSource::File(image), span.clone());
                // pbrt's UV mapping: (su·u + du, sv·v + dv).
                let (su, sv) = (params.float_or("uscale", 1.0)?, params.float_or("vscale", 1.0)?);
                let (du, dv) = (params.float_or("udelta", 0.0)?, params.float_or("vdelta", 0.0)?);
                map.sampler.transform =
                    Affine2::from_scale_angle_translation(Vec2::new(su, sv), 0.0, Vec2::new(du, dv));
                map.sampler.scale = Vec3::splat(params.float_or("scale", 1.0)?);
                if params.bool_or("invert", false)? {
                    self.warn("`invert` of an image texture is not applied", class.span.clone());
                }
                if let Some((filter, s)) = params.string("filter")? {
                    match filter.as_str() {
                        "point" => map.sampler.nearest = true,
                        "bilinear" | "trilinear" | "ewa" | "EWA" => {}
                        other => self.warn(format!("unknown filter \"{other}\": bilinear is used"), s),
                    }
                }
                if let Some((wrap, s)) = params.string("wrap")? {
                    map.sampler.wrap = [match wrap.as_str() {
                        "repeat" => Wrap::Repeat,
                        "black" => Wrap::Black,
                        "clamp" => Wrap::Clamp,
                        other => {
                            let what = if other == "octahedralsphere" {
                                "is not read"
                            } else {
                                "is unknown"
                            };
                            self.warn(format!("wrap \"{other}\" {what}: repeat is used"), s);
                            Wrap::Repeat
                        }
                    }; 2];
                }
                if let Some((encoding, s)) = params.string("encoding")? {
                    map.encoding = match encoding.as_str() {
                        "sRGB" => Encoding::Srgb,
                        "linear" => Encoding::Linear,
                        g => match g.strip_prefix("gamma ").map(|v| v.trim().parse::<f32>()) {
                            Some(Ok(g)) if g > 0.0 && g.is_finite() => Encoding::Gamma(g),
                            _ => {
                                return Err(ParseError::new(
                                    format!("`encoding` is \"sRGB\", \"linear\" or \"gamma G\", not \"{g}\""),
                                    s,
                                ))
                            }
                        },
                    };
                }
                let _ = params.float("maxanisotropy");
                TextureValue::Param(Param::Texture(Box::new(map)))
            }
            "checkerboard" => {
                let (a, b) = if float {
                    (
                        Vec3::splat(self.float_slot(&params, "tex1", 1.0)?),
                        Vec3::splat(self.float_slot(&params, "tex2", 0.0)?),
                    )
                } else {
                    (
                        self.constant_colour(&params, "tex1", Vec3::ONE)?,
                        self.constant_colour(&params, "tex2", Vec3::ZERO)?,
                    )
                };
                let us = params.float_or("uscale", 1.0)?;
                let vs = params.float_or("vscale", 1.0)?;
                if params.int("dimension")?.is_some_and(|d| d != 2) {
                    self.warn("a 3D checkerboard is read as a 2D one", class.span.clone());
                }
                let _ = params.string("mapping");
                TextureValue::Param(Param::Checkerboard {
                    even: a,
                    odd: b,
                    scale: Vec2::new(us, vs),
                })
            }
            "constant" => {
                if float {
                    TextureValue::Float(params.float_or("value", 1.0)?)
                } else {
                    TextureValue::Param(Param::Constant(self.constant_colour(&params, "value", Vec3::ONE)?))
                }
            }
            "scale" => {
                let s = self.float_slot(&params, "scale", 1.0)?;
                if float {
                    TextureValue::Float(self.float_slot(&params, "tex", 1.0)? * s)
                } else {
                    TextureValue::Param(scaled(self.colour(&params, "tex", Vec3::ONE)?, s))
                }
            }
            other => {
                self.warn(
                    format!("the {other} texture is not supported: a constant 0.5 instead"),
                    class.span,
                );
                if float {
                    TextureValue::Float(0.5)
                } else {
                    TextureValue::Param(Param::grey(0.5))
                }
            }
        };
        self.report_unused(&params, &format!("the texture \"{}\"", name.text));
        self.textures.insert(name.text, value);
        Ok(())
    }

    // ---- lights ----------------------------------------------------------------------------------

    /// A light's spectrum as RGB times `scale`: RGB values keep their size; black bodies and
    /// other spectra are normalised to luminance 1 as pbrt-v4 does.
    fn light_colour(&mut self, params: &Params, name: &str) -> Result<Vec3, ParseError> {
        let scale = params.float_or("scale", 1.0)?;
        let c = match params.spectrum(name)? {
            None => Vec3::ONE,
            Some((Spectrum::Rgb(c), span)) => {
                if c.min_element() < 0.0 {
                    return Err(ParseError::new("a light's colour cannot be negative", span));
                }
                c
            }
            Some((Spectrum::Blackbody(k), _)) => spectra::blackbody(k),
            Some((Spectrum::Sampled(pairs), _)) => {
                let c = spectra::sampled_to_rgb(&pairs);
                c / luminance(c).max(1e-9)
            }
            Some((Spectrum::Named(n), span)) => {
                if !n.starts_with("stdillum-") && !n.starts_with("illum-") {
                    return Err(ParseError::new(format!("unknown spectrum \"{n}\" for a light"), span));
                }
                if n != "stdillum-D65" {
                    self.warn(format!("the illuminant \"{n}\" is read as white (D65)"), span);
                }
                Vec3::ONE
            }
            Some((Spectrum::Texture(_), span)) => {
                return Err(ParseError::new("a light's colour cannot be a texture", span))
            }
        };
        Ok(c * scale)
    }

    fn light(&mut self, t: &Token) -> Result<(), ParseError> {
        let kind = self.string_arg(t)?;
        let params = self.params()?;
        let span = t.span.start..kind.span.end;
        let ctm = self.state.ctm;
        let light = match kind.text.as_str() {
            "point" => {
                let mut color = self.light_colour(&params, "I")?;
                if let Some(power) = params.float("power")?.filter(|p| *p > 0.0) {
                    color *= power
                        / (4.0 * std::f32::consts::PI)
                        / luminance(color / params.float_or("scale", 1.0)?).max(1e-9);
                }
                let from = params.vec3("from", &["point3"])?.unwrap_or(Vec3::ZERO);
                Some(LightDesc::Point {
                    position: ctm.transform_point3(from),
                    color,
                    attenuation: [0.0, 0.0, 1.0],
                    span: span.clone(),
                })
            }
            "spot" => {
                let mut color = self.light_colour(&params, "I")?;
                let from = params.vec3("from", &["point3"])?.unwrap_or(Vec3::ZERO);
                let to = params.vec3("to", &["point3"])?.unwrap_or(Vec3::Z);
                let cone = params.float_or("coneangle", 30.0)?.clamp(0.0, 180.0);
                let delta = params.float_or("conedeltaangle", 5.0)?.clamp(0.0, cone);
                if let Some(power) = params.float("power")?.filter(|p| *p > 0.0) {
                    let (c0, c1) = ((cone - delta).to_radians().cos(), cone.to_radians().cos());
                    let k = 2.0 * std::f32::consts::PI * ((1.0 - c0) + (c0 - c1) / 2.0);
                    color *= power / k.max(1e-9) / luminance(color / params.float_or("scale", 1.0)?).max(1e-9);
                }
                Some(LightDesc::Spot {
                    position: ctm.transform_point3(from),
                    direction: ctm.transform_vector3(to - from),
                    color,
                    attenuation: [0.0, 0.0, 1.0],
                    inner_degrees: cone - delta,
                    outer_degrees: cone,
                    exponent: 0.0,
                    span: span.clone(),
                })
            }
            "distant" => {
                let mut color = self.light_colour(&params, "L")?;
                if let Some(e) = params.float("illuminance")?.filter(|e| *e > 0.0) {
                    color *= e / luminance(color / params.float_or("scale", 1.0)?).max(1e-9);
                }
                let from = params.vec3("from", &["point3"])?.unwrap_or(Vec3::ZERO);
                let to = params.vec3("to", &["point3"])?.unwrap_or(Vec3::Z);
                Some(LightDesc::Directional {
                    direction: ctm.transform_vector3(to - from),
                    color,
                    span: span.clone(),
                })
            }
            "infinite" => {
                let mut color = self.light_colour(&params, "L")?;
                let file = params.string("filename")?;
                if let Some(e) = params.float("illuminance")?.filter(|e| *e > 0.0) {
                    if file.is_some() {
                        self.warn("`illuminance` of an image sky is not applied", span.clone());
                    } else {
                        color *= e / std::f32::consts::PI / luminance(color / params.float_or("scale", 1.0)?).max(1e-9);
                    }
                }
                if params.has("portal") {
                    self.warn("portals are not used: the sky is sampled everywhere", span.clone());
                    let _ = params.list("portal", &["point3"], 3);
                }
                let rotation = Mat3::from_mat4(ctm);
                let map = file.map(|(name, s)| (self.dir.join(name), s));
                Some(LightDesc::Environment {
                    color,
                    map: map.as_ref().map(|m| ImageSource::File(m.0.clone())),
                    rotation: orthonormal(rotation),
                    equal_area: map.is_some(),
                    span: map.map_or(span.clone(), |m| m.1),
                })
            }
            other => {
                self.warn(
                    format!("the {other} light is not supported: left out"),
                    kind.span.clone(),
                );
                None
            }
        };
        self.report_unused(&params, &format!("the {} light", kind.text));
        if let Some(light) = light {
            if self.defining.is_some() {
                self.warn(
                    "a light inside an object definition is placed once, where it is defined",
                    span,
                );
            }
            self.desc.lights.push(light);
            // pbrt's lights shine into the medium outside the interface in effect.
            if let Some(medium) = self.state.media.1 {
                self.desc.light_media.push((self.desc.lights.len() - 1, Some(medium)));
            }
        }
        Ok(())
    }

    fn area_light(&mut self, t: &Token) -> Result<(), ParseError> {
        let kind = self.string_arg(t)?;
        let params = self.params()?;
        // pbrt-v3 calls it "area" (and takes a sample count).
        let _ = params.int("nsamples");
        if kind.text != "diffuse" && kind.text != "area" {
            self.warn(
                format!("the {} area light is not supported", kind.text),
                kind.span.clone(),
            );
            self.report_unused(&params, "the area light");
            return Ok(());
        }
        let radiance = self.light_colour(&params, "L")?;
        let power = params.float("power")?.filter(|p| *p > 0.0);
        let twosided = params.bool_or("twosided", false)?;
        if params.has("filename") {
            let _ = params.string("filename");
            self.warn(
                "an image on an area light is not applied: its colour is used",
                kind.span.clone(),
            );
        }
        self.report_unused(&params, "the area light");
        self.state.area_light = Some(AreaLight {
            radiance,
            power,
            twosided,
        });
        Ok(())
    }

    // ---- shapes ----------------------------------------------------------------------------------

    fn shape(&mut self, t: &Token) -> Result<(), ParseError> {
        let kind = self.string_arg(t)?;
        let params = self.params()?;
        let span = t.span.start..kind.span.end;
        let ctm = self.state.ctm;
        if !self.in_world {
            return Err(ParseError::new("shapes come after `WorldBegin`", span));
        }
        let partial = |reader: &mut Self, params: &Params, what: &str| -> Result<(), ParseError> {
            let phimax = params.float_or("phimax", 360.0)?;
            if phimax < 360.0 {
                reader.warn(
                    format!("a partial {what} (phimax {phimax}) is drawn whole"),
                    span.clone(),
                );
            }
            Ok(())
        };
        let mut shapes: Vec<(ShapeDesc, Mat4)> = Vec::new();
        match kind.text.as_str() {
            "sphere" => {
                let r = params.float_or("radius", 1.0)?;
                let (zmin, zmax) = (params.float_or("zmin", -r)?, params.float_or("zmax", r)?);
                if zmin > -r || zmax < r {
                    self.warn("a sphere cut by zmin/zmax is drawn whole", span.clone());
                }
                partial(self, &params, "sphere")?;
                shapes.push((ShapeDesc::Sphere, ctm * Mat4::from_scale(Vec3::splat(r))));
            }
            "disk" => {
                let r = params.float_or("radius", 1.0)?;
                let inner = params.float_or("innerradius", 0.0)?;
                let h = params.float_or("height", 0.0)?;
                partial(self, &params, "disk")?;
                if r.is_nan() || r <= 0.0 || !(0.0..r).contains(&inner) {
                    return Err(ParseError::new("a disk needs 0 ≤ innerradius < radius", span));
                }
                shapes.push((
                    ShapeDesc::Disk { inner: inner / r },
                    ctm * Mat4::from_translation(Vec3::new(0.0, 0.0, h)) * Mat4::from_scale(Vec3::new(r, r, 1.0)),
                ));
            }
            "cylinder" => {
                let r = params.float_or("radius", 1.0)?;
                let (z0, z1) = (params.float_or("zmin", -1.0)?, params.float_or("zmax", 1.0)?);
                let (z0, z1) = (z0.min(z1), z0.max(z1));
                partial(self, &params, "cylinder")?;
                if !(r > 0.0 && z1 > z0) {
                    return Err(ParseError::new(
                        "a cylinder needs a positive radius and zmax > zmin",
                        span,
                    ));
                }
                shapes.push((
                    ShapeDesc::Cylinder { capped: false },
                    ctm * Mat4::from_translation(Vec3::new(0.0, 0.0, z0)) * Mat4::from_scale(Vec3::new(r, r, z1 - z0)),
                ));
            }
            "trianglemesh" | "loopsubdiv" => {
                if kind.text == "loopsubdiv" {
                    self.warn("a subdivision surface is drawn as its control mesh", span.clone());
                    let _ = params.int("levels");
                }
                if let Some(mesh) = self.triangle_mesh(&params, &span, 3)? {
                    shapes.push((ShapeDesc::Trimesh(Box::new(mesh)), ctm));
                }
            }
            "bilinearmesh" => {
                if let Some(mesh) = self.triangle_mesh(&params, &span, 4)? {
                    shapes.push((ShapeDesc::Trimesh(Box::new(mesh)), ctm));
                }
            }
            "plymesh" => {
                let Some((file, fspan)) = params.string("filename")? else {
                    return Err(ParseError::new("a plymesh needs `string filename`", span));
                };
                if params.has("displacement") {
                    let _ = params.spectrum("displacement");
                    let _ = params.float("edgelength");
                    self.warn("displacement is not applied", span.clone());
                }
                let path = self.dir.join(&file);
                let ply = ply::read(self.files, &path, &fspan)?;
                self.desc.warnings.extend(ply.warnings);
                let n = ply.points.len();
                let mesh = TrimeshDesc {
                    points: ply.points,
                    triangles: ply.triangles,
                    normals: ply.normals.filter(|v| v.len() == n),
                    materials: None,
                    uvs: ply.uvs.filter(|v| v.len() == n),
                    tangents: None,
                };
                if !mesh.triangles.is_empty() {
                    shapes.push((ShapeDesc::Trimesh(Box::new(mesh)), ctm));
                }
            }
            other => {
                self.warn(
                    format!("the {other} shape is not supported: left out"),
                    kind.span.clone(),
                );
            }
        }
        // pbrt-v4's alpha: a ray passes where it is below one with the chance 1 − alpha; a
        // shape of alpha 0 is not drawn at all.
        let alpha = match self.colour(&params, "alpha", Vec3::ONE)? {
            Param::Constant(a) if a.x >= 1.0 => None,
            Param::Constant(a) if a.x <= 0.0 => return Ok(()),
            coverage => Some(Alpha { coverage, cutoff: None }),
        };
        self.report_unused(&params, &format!("the {} shape", kind.text));
        let (inside, outside) = self.state.media;
        let interface = (inside != outside).then_some(InterfaceDesc {
            inside: MediumSide::Medium(inside),
            outside: MediumSide::Medium(outside),
        });
        let material = match &self.state.material {
            CurrentMaterial::Desc(m) => MaterialDesc {
                interface,
                ..(**m).clone()
            },
            // Only a boundary between media: paths pass it, and it is not drawn.
            CurrentMaterial::Interface if interface.is_some() => MaterialDesc {
                name: Some("interface".into()),
                interface,
                boundary: true,
                ..MaterialDesc::default()
            },
            CurrentMaterial::Interface => {
                self.warn_once(
                    "interface",
                    "shapes with the `interface` material and no change of medium are not drawn",
                    span,
                );
                return Ok(());
            }
        };
        let one_sided = self.state.area_light.as_ref().is_some_and(|l| !l.twosided);
        for (mut shape, world_from_object) in shapes {
            let front = orientation::orient(
                &mut shape,
                &world_from_object,
                self.state.reverse_orientation,
                one_sided,
            );
            let mut material = material.clone();
            if alpha.is_some() {
                material.alpha = alpha.clone();
            }
            if let Some(light) = self.state.area_light.clone() {
                let mut radiance = light.radiance;
                if let Some(power) = light.power {
                    let area = shape_area(&shape, &world_from_object);
                    let sides = if light.twosided { 2.0 } else { 1.0 };
                    radiance *=
                        power / (sides * std::f32::consts::PI * area * luminance(radiance).max(1e-9)).max(1e-12);
                }
                if !light.twosided {
                    material.emitting_faces = front;
                }
                if self.defining.is_some() {
                    self.warn_once(
                        "instancedlight",
                        "area lights inside object instances do not emit (as in pbrt)",
                        span.clone(),
                    );
                } else {
                    material.emissive = Param::Constant(radiance);
                }
            }
            let object = ObjectDesc {
                shape,
                world_from_object,
                material,
                span: span.clone(),
            };
            match &mut self.defining {
                Some((_, objects, _)) => objects.push(object),
                None => self.desc.objects.push(object),
            }
        }
        Ok(())
    }

    /// A `trianglemesh` (`corners` 3) or `bilinearmesh` (4: p00 p10 p01 p11 per patch).
    fn triangle_mesh(
        &mut self,
        params: &Params,
        span: &Span,
        corners: usize,
    ) -> Result<Option<TrimeshDesc>, ParseError> {
        let Some((p, pspan)) = params.list("P", &["point3"], 3)? else {
            return Err(ParseError::new("a mesh needs `point3 P`", span.clone()));
        };
        let points: Vec<Vec3> = p
            .chunks(3)
            .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
            .collect();
        let n = points.len();
        let indices: Vec<f64> = match params.list("indices", &["integer"], 1)? {
            Some((v, _)) => v,
            None if n == corners => (0..corners).map(|i| i as f64).collect(),
            None => return Err(ParseError::new("a mesh needs `integer indices`", pspan)),
        };
        let ispan = params.span_of("indices").unwrap_or(pspan);
        if !indices.chunks_exact(corners).remainder().is_empty() {
            self.warn(
                format!("`indices` is not a multiple of {corners}: the extra ones are dropped"),
                ispan.clone(),
            );
        }
        if let Some(bad) = indices.iter().find(|&&i| i < 0.0 || i >= n as f64 || i.fract() != 0.0) {
            return Err(ParseError::new(
                format!("index {bad} is out of range: the mesh has {n} points"),
                ispan,
            ));
        }
        let mut triangles = Vec::new();
        for f in indices.chunks_exact(corners) {
            let f: Vec<u32> = f.iter().map(|&i| i as u32).collect();
            if corners == 3 {
                triangles.push([f[0], f[1], f[2]]);
            } else {
                triangles.push([f[0], f[1], f[3]]);
                triangles.push([f[0], f[3], f[2]]);
            }
        }
        let normals = match params.list("N", &["normal"], 3)? {
            Some((v, s)) if v.len() != 3 * n => {
                self.warn("`N` does not have one normal per point: left out", s);
                None
            }
            Some((v, _)) => Some(
                v.chunks(3)
                    .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                    .collect(),
            ),
            None => None,
        };
        let uv = match params.list("uv", &["point2"], 2)? {
            Some(v) => Some(v),
            None => params.list("st", &["point2"], 2)?,
        };
        let uvs = match uv {
            Some((v, s)) if v.len() != 2 * n => {
                self.warn("`uv` does not have one pair per point: left out", s);
                None
            }
            Some((v, _)) => Some(v.chunks(2).map(|c| Vec2::new(c[0] as f32, c[1] as f32)).collect()),
            None => None,
        };
        let _ = params.list("S", &["vector3"], 3);
        let _ = params.list("faceIndices", &["integer"], 1);
        Ok((!triangles.is_empty()).then_some(TrimeshDesc {
            points,
            triangles,
            normals,
            materials: None,
            uvs,
            tangents: None,
        }))
    }
}

fn parse_number(t: &Token) -> Result<f32, ParseError> {
    let bad = || ParseError::new(format!("expected a number, found `{}`", t.text), t.span.clone());
    let first = t.text.chars().next().ok_or_else(bad)?;
    if !(first.is_ascii_digit() || matches!(first, '-' | '+' | '.')) {
        return Err(bad());
    }
    let v: f64 = t.text.parse().map_err(|_| bad())?;
    if !v.is_finite() || v.abs() > f32::MAX as f64 {
        return Err(ParseError::new(format!("`{}` is out of range", t.text), t.span.clone()));
    }
    Ok(v as f32)
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Lambert reflection `r` and Lambert transmission `t` (the course model's `diffuse` and
/// `transmissive` at index 1).
fn diffuse_transmission(r: Param, t: Param) -> MaterialDesc {
    MaterialDesc {
        diffuse: r.clone(),
        transmissive: t.clone(),
        index: Param::grey(1.0),
        physical: Some(PhysicalMaterial::DiffuseTransmission {
            reflectance: r,
            transmittance: t,
        }),
        ..MaterialDesc::default()
    }
}

/// The GGX α a material with an image texture for its roughness takes where one number is
/// needed: it makes a dielectric rough (points the texture makes smooth are smooth) and gives
/// the course model a middling gloss.
const TEXTURED_ALPHA: f32 = 0.1;

fn scaled(p: Param, s: f32) -> Param {
    match p {
        Param::Constant(c) => Param::Constant(c * s),
        other => other,
    }
}

/// The rotation part of a matrix (its scale removed), for the sky's frame.
fn orthonormal(m: Mat3) -> Mat3 {
    let x = m.x_axis.normalize_or_zero();
    let y = (m.y_axis - x * x.dot(m.y_axis)).normalize_or_zero();
    let z = x.cross(y);
    if x == Vec3::ZERO || y == Vec3::ZERO {
        return Mat3::IDENTITY;
    }
    // Keep a mirrored frame mirrored.
    let z = if m.determinant() < 0.0 { -z } else { z };
    Mat3::from_cols(x, y, z)
}

/// World area of a shape, for area lights given by `power`.
fn shape_area(shape: &ShapeDesc, m: &Mat4) -> f32 {
    let pi = std::f32::consts::PI;
    let linear = Mat3::from_mat4(*m);
    let scale2 = |a: Vec3, b: Vec3| (linear * a).cross(linear * b).length();
    match shape {
        ShapeDesc::Sphere => 4.0 * pi * scale2(Vec3::X, Vec3::Y).max(scale2(Vec3::Y, Vec3::Z)),
        ShapeDesc::Disk { inner } => pi * (1.0 - inner * inner) * scale2(Vec3::X, Vec3::Y),
        ShapeDesc::Cylinder { .. } => 2.0 * pi * (linear * Vec3::X).length() * (linear * Vec3::Z).length(),
        ShapeDesc::Trimesh(mesh) => mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.transform_point3(mesh.points[i as usize]));
                0.5 * (b - a).cross(c - a).length()
            })
            .sum(),
        _ => 1.0,
    }
}
