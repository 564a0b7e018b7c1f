//! Dialect T: the tokenizer-based reader of UT CS 384G (2012–2019) and UW CSE 457 (2009+).
//!
//! Nesting of transforms and groups is handled with an explicit frame stack, so input depth never
//! turns into call-stack depth.

use super::ast::{
    CameraBasis, Dialect, LightDesc, MaterialDesc, ObjectDesc, Param, RayCamera, RayScene, ShapeDesc, Span,
};
use super::cursor::{Cursor, Reach};
use super::fork_lights::{self, LightFields};
use super::fork_shapes::{self, MetaballFields, METABALL_FIELDS};
use super::keywords::{extension_error, is_extension, is_reserved, skipped_object, COLOUR_FIELDS, TOP_LEVEL};
use super::lexer::{self, Tok, Token};
use super::named_materials::NamedMaterials;
use super::quadric;
use super::skybox::{SkyboxFields, SKYBOX_FIELDS};
use super::suggest;
use super::transform_stack::{self, TransformStack};
use super::trimesh::{self, MeshInput};
use crate::description::{InterfaceDesc, MediumDesc, MediumSide};
use crate::ParseError;
use glam::{Vec2, Vec3, Vec4};
use std::path::Path;

const ELEMENTS: &[&str] = &[
    "sphere",
    "box",
    "square",
    "cylinder",
    "cone",
    "torus",
    "metaballs",
    "metaball",
    "quadric",
    "hyperboloid",
    "hyperbolic_paraboloid",
    "paraboloid",
    "trimesh",
    "polymesh",
    "translate",
    "scale",
    "rotate",
    "transform",
    "union",
    "intersection",
    "difference",
    "subtraction",
];
const MATERIAL_FIELDS: &[&str] = &[
    "emissive",
    "ambient",
    "specular",
    "reflective",
    "diffuse",
    "transmissive",
    "shininess",
    "index",
    "abbe",
    "absorption",
    "scattering",
    "phase",
    "boundary",
    "name",
];
const MEDIUM_FIELDS: &[&str] = &["absorption", "scattering", "phase"];
const CAMERA_FIELDS: &[&str] = &[
    "position",
    "viewdir",
    "updir",
    "fov",
    "aspectratio",
    "quaternian",
    "look_at",
];
const POINT_LIGHT_FIELDS: &[&str] = &[
    "position",
    "color",
    "colour",
    "constant_attenuation_coeff",
    "linear_attenuation_coeff",
    "quadratic_attenuation_coeff",
];
const DIRECTIONAL_LIGHT_FIELDS: &[&str] = &["direction", "color", "colour"];
const SUN_LIGHT_FIELDS: &[&str] = &["direction", "color", "colour", "angle"];
const ENVIRONMENT_LIGHT_FIELDS: &[&str] = &["color", "colour", "map"];
const MESH_FIELDS: &[&str] = &[
    "material",
    "name",
    "points",
    "faces",
    "normals",
    "materials",
    "gennormals",
    "texture_uv",
    "file",
    "objfile",
];

/// Parses a whole dialect-T file.
pub(crate) fn parse(text: &str, scene_dir: &Path, reach: &Reach<'_>) -> Result<RayScene, ParseError> {
    let tokens = lexer::lex(text, Dialect::Tokenizer)?;
    let mut parser = Parser {
        cur: Cursor::new(text, tokens, reach),
        scene_dir,
        default_material: MaterialDesc::default(),
        named: NamedMaterials::default(),
        transforms: TransformStack::new(),
        scene: RayScene {
            dialect: Dialect::Tokenizer,
            camera: None,
            lights: Vec::new(),
            ambient: Vec3::ZERO,
            objects: Vec::new(),
            warnings: Vec::new(),
            mesh_files: Vec::new(),
            media: Vec::new(),
            ambient_medium: None,
        },
    };
    parser.file()?;
    Ok(parser.scene)
}

/// An open transform or group while an element is being read.
enum Frame {
    /// A transform whose child is being read; `)` closes it.
    Transform { keyword: Token },
    /// A `{ … }` group; `}` closes it.
    Group,
    /// A CSG operation `union(a, b, …)`: its operands are the objects pushed since `start`,
    /// each ending where `splits` says; `)` closes it.
    Csg {
        keyword: Token,
        start: usize,
        splits: Vec<usize>,
    },
}

/// A medium's fields as read (a material's or the scene's `medium`).
#[derive(Default)]
struct MediumFields {
    absorption: Option<Vec3>,
    scattering: Option<Vec3>,
    phase: Option<f32>,
}

impl MediumFields {
    fn medium(&self, span: Span) -> MediumDesc {
        MediumDesc {
            name: None,
            sigma_a: self.absorption.unwrap_or(Vec3::ZERO),
            sigma_s: self.scattering.unwrap_or(Vec3::ZERO),
            g: self.phase.unwrap_or(0.0),
            grid: None,
            span,
        }
    }
}

struct Parser<'a> {
    cur: Cursor<'a>,
    scene_dir: &'a Path,
    /// The current default material (§6.2).
    default_material: MaterialDesc,
    named: NamedMaterials,
    transforms: TransformStack,
    scene: RayScene,
}

impl<'a> Parser<'a> {
    fn file(&mut self) -> Result<(), ParseError> {
        if !self.cur.at_word("SBT-raytracer") {
            return Err(self
                .cur
                .unexpected("the header `SBT-raytracer 1.0`")
                .with_help("every scene file starts with `SBT-raytracer 1.0`"));
        }
        self.cur.next();
        let (version, span) = self.cur.number("(the format version) after `SBT-raytracer`")?;
        if version > 1.1 {
            return Err(ParseError::new(
                format!("format version {version} is not supported; this reader accepts versions up to 1.1"),
                span,
            ));
        }
        loop {
            let token = self.cur.peek().clone();
            match token.tok {
                Tok::Eof => return Ok(()),
                Tok::Semicolon => {
                    self.cur.next();
                }
                Tok::Word => match self.cur.text_of(&token) {
                    "camera" => self.camera()?,
                    "point_light" => self.point_light()?,
                    "directional_light" => self.directional_light()?,
                    "sun_light" => self.sun_light()?,
                    "spot_light" => self.fork_light(fork_lights::SPOT_FIELDS)?,
                    "area_light" => self.fork_light(fork_lights::AREA_FIELDS)?,
                    "warn_light" | "warn_model_light" => self.fork_light(fork_lights::WARN_FIELDS)?,
                    "skybox" => self.skybox()?,
                    "csg" => {
                        return Err(ParseError::new(
                            "a `csg { … }` block is read in dialect-O files (the HKUST team fork's spelling); in dialect T write `union(a, b)`, `intersection(a, b)` or `difference(a, b)`",
                            token.span.clone(),
                        ))
                    }
                    "environment_light" => self.environment_light()?,
                    "ambient_light" => self.ambient_light()?,
                    "medium" => self.ambient_medium()?,
                    "material" => {
                        let base = self.default_material.clone();
                        self.default_material = self.material_stmt(&base)?;
                    }
                    _ => self.element(TOP_LEVEL)?,
                },
                _ => self.element(TOP_LEVEL)?,
            }
        }
    }

    /// The error for a word that is not allowed here: extension, misspelling or plain unexpected.
    fn bad_word(&self, what: &str, allowed: &[&str]) -> ParseError {
        let token = self.cur.peek();
        if token.tok == Tok::Word {
            let word = self.cur.text_of(token);
            if let Some(error) = extension_error(word, &token.span) {
                return error;
            }
            let error = self.cur.unexpected(what);
            if let Some(near) = suggest::nearest(word, allowed.iter().copied()) {
                return error.with_help(suggest::did_you_mean(near));
            }
            return error;
        }
        self.cur.unexpected(what)
    }

    /// One transformable element (object, transform or group), read without recursion.
    fn element(&mut self, allowed: &[&str]) -> Result<(), ParseError> {
        let mut frames: Vec<Frame> = Vec::new();
        loop {
            // Start of an element.
            let token = self.cur.peek().clone();
            let word = if token.tok == Tok::Word {
                self.cur.text_of(&token)
            } else {
                ""
            };
            match (token.tok, word) {
                (Tok::LBrace, _) => {
                    self.cur.next();
                    frames.push(Frame::Group);
                }
                (Tok::Word, "translate" | "scale" | "rotate" | "transform") => {
                    self.cur.next();
                    let local = self.transform_head(&token)?;
                    let span = token.span.start..self.cur.prev_end();
                    self.transforms.push(local, &span)?;
                    frames.push(Frame::Transform { keyword: token });
                    continue;
                }
                (Tok::Word, "sphere" | "box" | "square" | "cylinder" | "cone" | "torus") => {
                    self.cur.next();
                    self.simple_primitive(&token)?;
                }
                (Tok::Word, "trimesh" | "polymesh") => {
                    self.cur.next();
                    self.trimesh(&token)?;
                }
                (Tok::Word, "metaballs" | "metaball") => {
                    self.cur.next();
                    self.metaballs(&token)?;
                }
                (Tok::Word, "quadric" | "hyperboloid" | "hyperbolic_paraboloid" | "paraboloid") => {
                    self.cur.next();
                    self.quadric(&token)?;
                }
                // An object of some fork that is not read: skipped with a warning.
                (Tok::Word, _) if self.skippable_object(word, allowed) => {
                    self.cur.next();
                    let span = self.skip_group()?;
                    self.cur.eat(Tok::Semicolon);
                    let what = format!(
                        "{word} {}",
                        if self.cur.text[span.clone()].starts_with('{') {
                            "{ … }"
                        } else {
                            "( … )"
                        }
                    );
                    self.scene
                        .warnings
                        .push((skipped_object(word, &what), token.span.start..span.end));
                }
                (Tok::Word, "union" | "intersection" | "difference" | "subtraction") => {
                    self.cur.next();
                    self.cur.expect(Tok::LParen, &format!("after `{word}`"))?;
                    frames.push(Frame::Csg {
                        keyword: token,
                        start: self.scene.objects.len(),
                        splits: Vec::new(),
                    });
                    continue;
                }
                _ => {
                    let (what, allowed) = if frames.is_empty() && allowed.len() > ELEMENTS.len() {
                        ("a camera, light, `material`, object, transform or `{` group", allowed)
                    } else {
                        ("an object, a transform or a `{` group", ELEMENTS)
                    };
                    let error = self.bad_word(what, allowed);
                    return Err(if token.tok == Tok::Semicolon && !frames.is_empty() {
                        error.with_help("a `;` may only follow a transform's closing `)`")
                    } else {
                        error
                    });
                }
            }
            // An element is complete or a group has just opened: close what can be closed.
            loop {
                match frames.last() {
                    None => return Ok(()),
                    Some(Frame::Transform { keyword }) => {
                        let context = format!("to close `{}`", self.cur.text_of(keyword));
                        self.cur.expect(Tok::RParen, &context)?;
                        self.cur.eat(Tok::Semicolon);
                        self.transforms.pop();
                        frames.pop();
                    }
                    Some(Frame::Csg { .. }) => {
                        // Another operand follows a comma; `)` ends the operation.
                        if self.cur.eat(Tok::Comma) {
                            let at = self.scene.objects.len();
                            if let Some(Frame::Csg { splits, .. }) = frames.last_mut() {
                                splits.push(at);
                            }
                            break;
                        }
                        let Some(Frame::Csg { keyword, start, splits }) = frames.pop() else {
                            unreachable!("the top frame is a CSG operation")
                        };
                        let word = self.cur.text_of(&keyword);
                        self.cur.expect(Tok::RParen, &format!("or `,` in `{word}`"))?;
                        self.cur.eat(Tok::Semicolon);
                        let mut objects: Vec<_> = self.scene.objects.drain(start..).collect();
                        let mut operands = Vec::new();
                        for &split in splits.iter().rev() {
                            operands.push(objects.split_off(split - start));
                        }
                        operands.push(objects);
                        operands.reverse();
                        let op = fork_shapes::csg_op(word).expect("a CSG keyword");
                        let span = keyword.span.start..self.cur.prev_end();
                        let object = fork_shapes::csg_object(op, operands, span)?;
                        self.scene.objects.push(object);
                    }
                    Some(Frame::Group) => {
                        // Extension: `material = …` inside a group sets the default from here on.
                        while self.cur.at_word("material") {
                            let base = self.default_material.clone();
                            self.default_material = self.material_stmt(&base)?;
                        }
                        if self.cur.eat(Tok::RBrace) {
                            frames.pop();
                        } else if self.cur.peek().tok == Tok::Eof {
                            return Err(self.cur.unexpected("`}` to close the group"));
                        } else {
                            break;
                        }
                    }
                }
            }
        }
    }

    /// The arguments of a transform up to and including the comma before its child.
    fn transform_head(&mut self, keyword: &Token) -> Result<glam::Mat4, ParseError> {
        let name = self.cur.text_of(keyword);
        self.cur.expect(Tok::LParen, &format!("after `{name}`"))?;
        let start = keyword.span.start;
        let ctx = format!("in `{name}`");
        match name {
            "translate" => {
                let v = self.numbers_then_comma::<3>(&ctx)?;
                Ok(transform_stack::translation(Vec3::from(v)))
            }
            "scale" => {
                let (first, _) = self.cur.number(&ctx)?;
                self.cur.expect(Tok::Comma, &format!("after the first factor {ctx}"))?;
                // A number after the first comma means three factors (§2).
                let factors = if matches!(self.cur.peek().tok, Tok::Number(_)) {
                    let [y, z] = self.numbers_then_comma::<2>(&ctx)?;
                    Vec3::new(first, y, z)
                } else {
                    Vec3::splat(first)
                };
                transform_stack::scaling(factors, &(start..self.cur.prev_end()))
            }
            "rotate" => {
                let [x, y, z, angle] = self.numbers_then_comma::<4>(&ctx)?;
                transform_stack::rotation(Vec3::new(x, y, z), angle, &(start..self.cur.prev_end()))
            }
            _ => {
                let mut rows = [Vec4::ZERO; 4];
                for row in &mut rows {
                    *row = Vec4::from(self.tuple::<4>(&ctx)?.0);
                    self.cur.expect(Tok::Comma, &format!("after a matrix row {ctx}"))?;
                }
                transform_stack::from_rows(rows, &(start..self.cur.prev_end()))
            }
        }
    }

    /// `N` numbers, each followed by a comma.
    fn numbers_then_comma<const N: usize>(&mut self, context: &str) -> Result<[f32; N], ParseError> {
        let mut values = [0.0; N];
        for value in &mut values {
            *value = self.cur.number(context)?.0;
            self.cur.expect(Tok::Comma, &format!("after a number {context}"))?;
        }
        Ok(values)
    }

    /// `( n, n, … )` with exactly `N` numbers; returns them and the span of the tuple.
    fn tuple<const N: usize>(&mut self, context: &str) -> Result<([f32; N], Span), ParseError> {
        let open = self
            .cur
            .expect(Tok::LParen, &format!("to start a {N}-tuple {context}"))?;
        let mut values = [0.0; N];
        for (i, value) in values.iter_mut().enumerate() {
            if i > 0 {
                self.cur
                    .expect(Tok::Comma, &format!("between the numbers of a {N}-tuple {context}"))?;
            }
            *value = self.cur.number(&format!("in a {N}-tuple {context}"))?.0;
        }
        self.cur
            .expect(Tok::RParen, &format!("to close a {N}-tuple {context}"))?;
        Ok((values, open.span.start..self.cur.prev_end()))
    }

    fn vec3(&mut self, context: &str) -> Result<Vec3, ParseError> {
        Ok(Vec3::from(self.tuple::<3>(context)?.0))
    }

    /// Consumes `key` (already peeked) and the `=` after it; returns the key token.
    fn key_equals(&mut self) -> Result<Token, ParseError> {
        let key = self.cur.next();
        let context = format!("after `{}`", self.cur.text_of(&key));
        self.cur.expect(Tok::Equals, &context)?;
        Ok(key)
    }

    /// An identifier or a quoted string (names and file names).
    fn identifier(&mut self, context: &str) -> Result<(String, Span), ParseError> {
        let token = self.cur.peek().clone();
        match token.tok {
            Tok::Quoted => {
                self.cur.next();
                Ok((self.cur.text_of(&token).to_string(), token.span))
            }
            Tok::Word if !is_reserved(self.cur.text_of(&token)) => {
                self.cur.next();
                Ok((self.cur.text_of(&token).to_string(), token.span))
            }
            Tok::Word => Err(self
                .cur
                .unexpected(&format!("a name {context}"))
                .with_help("keywords are reserved; put the name in double quotes")),
            _ => Err(self.cur.unexpected(&format!("a name {context}"))),
        }
    }

    /// `name = ID ;?` on an object (the value is ignored).
    fn name_attr(&mut self) -> Result<(), ParseError> {
        self.key_equals()?;
        self.identifier("after `name =`")?;
        self.cur.eat(Tok::Semicolon);
        Ok(())
    }

    /// A block `{ key = value … }` of some statement; calls `field` for each key.
    fn block(
        &mut self,
        keyword: &Token,
        mut field: impl FnMut(&mut Self, &Token, &str) -> Result<bool, ParseError>,
        allowed: &[&str],
    ) -> Result<(), ParseError> {
        let name = self.cur.text_of(keyword);
        self.cur.expect(Tok::LBrace, &format!("after `{name}`"))?;
        loop {
            let token = self.cur.peek().clone();
            if self.cur.eat(Tok::RBrace) {
                return Ok(());
            }
            let handled = token.tok == Tok::Word && field(self, &token, self.cur.text_of(&token))?;
            if !handled && self.skip_extension_field(name)? {
                continue;
            }
            if !handled {
                let list = allowed.iter().map(|f| format!("`{f}`")).collect::<Vec<_>>().join(", ");
                return Err(self.bad_word(&format!("a `{name}` field ({list}) or `}}`"), allowed));
            }
        }
    }

    /// Whether the next word starts an object to skip: a word followed by `{` or `(` that is no
    /// keyword of the format and no misspelling of one of `allowed`.
    fn skippable_object(&self, word: &str, allowed: &[&str]) -> bool {
        matches!(self.cur.peek_at(1).tok, Tok::LBrace | Tok::LParen)
            && !is_reserved(word)
            && (is_extension(word) || suggest::nearest(word, allowed.iter().copied()).is_none())
    }

    /// Consumes a bracketed group from its `{` or `(` to the matching closer; returns its span.
    fn skip_group(&mut self) -> Result<Span, ParseError> {
        let open = self.cur.next();
        let mut stack = vec![open.clone()];
        while let Some(top) = stack.last().cloned() {
            let token = self.cur.next();
            match token.tok {
                Tok::LBrace | Tok::LParen => stack.push(token),
                Tok::RBrace | Tok::RParen => {
                    let wanted = if top.tok == Tok::LBrace {
                        Tok::RBrace
                    } else {
                        Tok::RParen
                    };
                    if token.tok != wanted {
                        return Err(ParseError::new(
                            format!(
                                "{} does not close the {} opened here",
                                super::cursor::punct(token.tok),
                                super::cursor::punct(top.tok)
                            ),
                            top.span.start..token.span.end,
                        ));
                    }
                    stack.pop();
                }
                Tok::Eof => {
                    return Err(ParseError::new(
                        format!("{} is never closed", super::cursor::punct(top.tok)),
                        top.span,
                    ))
                }
                _ => {}
            }
        }
        Ok(open.span.start..self.cur.prev_end())
    }

    /// A student-extension field `key = value` in a block of `owner`: skipped with a warning.
    /// Returns whether the next field was one.
    fn skip_extension_field(&mut self, owner: &str) -> Result<bool, ParseError> {
        let token = self.cur.peek().clone();
        let word = self.cur.text_of(&token);
        if token.tok != Tok::Word || !is_extension(word) || self.cur.peek_at(1).tok != Tok::Equals {
            return Ok(false);
        }
        self.cur.next();
        self.cur.next();
        // The value runs to the `;` (or the block's `}`) at its own depth.
        loop {
            match self.cur.peek().tok {
                Tok::Semicolon => {
                    self.cur.next();
                    break;
                }
                Tok::RBrace | Tok::Eof => break,
                Tok::LBrace | Tok::LParen => {
                    self.skip_group()?;
                }
                Tok::RParen => return Err(self.cur.unexpected(&format!("`;` after the value of `{word}`"))),
                _ => {
                    self.cur.next();
                }
            }
        }
        self.scene.warnings.push((
            format!(
                "skipped `{word}` in `{owner}`: a student extension of the course format that caustica does not read"
            ),
            token.span.start..self.cur.prev_end(),
        ));
        Ok(true)
    }

    fn camera(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        // Later camera blocks modify the same camera, as in the skeleton.
        let mut camera = self.scene.camera.take().unwrap_or(RayCamera {
            position: Vec3::ZERO,
            viewdir: None,
            updir: None,
            look_at: None,
            quaternion: None,
            fov_degrees: None,
            aspect_ratio: None,
            basis: CameraBasis::AsGiven,
            span: keyword.span.clone(),
        });
        let (mut viewdir, mut updir) = (None, None);
        self.block(
            &keyword,
            |p, _, key| {
                match key {
                    "position" | "viewdir" | "updir" | "look_at" => {
                        p.key_equals()?;
                        let v = p.vec3(&format!("for the camera `{key}`"))?;
                        match key {
                            "position" => camera.position = v,
                            "viewdir" => viewdir = Some(v),
                            "updir" => updir = Some(v),
                            _ => camera.look_at = Some(v),
                        }
                    }
                    "fov" | "aspectratio" => {
                        p.key_equals()?;
                        let (v, _) = p.cur.number(&format!("for `{key}`"))?;
                        if key == "fov" {
                            camera.fov_degrees = Some(v);
                        } else {
                            camera.aspect_ratio = Some(v);
                        }
                    }
                    "quaternian" => {
                        p.key_equals()?;
                        camera.quaternion = Some(p.tuple::<4>("for `quaternian`")?.0);
                    }
                    _ => return Ok(false),
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            CAMERA_FIELDS,
        )?;
        camera.span = keyword.span.start..self.cur.prev_end();
        match (viewdir, updir, camera.look_at) {
            (Some(_), None, None) | (None, Some(_), None) => {
                return Err(ParseError::new(
                    "the camera needs `viewdir` and `updir` together",
                    camera.span,
                ))
            }
            (Some(_), _, Some(_)) => {
                return Err(ParseError::new(
                    "the camera has both `viewdir` and `look_at`; give only one",
                    camera.span,
                ))
            }
            _ => {}
        }
        if viewdir.is_some() {
            camera.viewdir = viewdir;
        }
        if updir.is_some() {
            camera.updir = updir;
        }
        if camera.look_at.is_some() {
            camera.basis = CameraBasis::Orthonormal;
        }
        self.scene.camera = Some(camera);
        Ok(())
    }

    fn point_light(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let (mut position, mut color) = (None, None);
        let mut attenuation = [0.0, 0.0, 1.0];
        self.block(
            &keyword,
            |p, token, key| {
                match key {
                    "position" | "color" | "colour" => {
                        let slot = if key == "position" { &mut position } else { &mut color };
                        if slot.is_some() {
                            return Err(ParseError::new(
                                format!("`point_light` has a second `{key}`"),
                                token.span.clone(),
                            ));
                        }
                        p.key_equals()?;
                        *slot = Some(p.vec3(&format!("for `{key}`"))?);
                    }
                    "constant_attenuation_coeff" | "linear_attenuation_coeff" | "quadratic_attenuation_coeff" => {
                        p.key_equals()?;
                        let i = match key {
                            "constant_attenuation_coeff" => 0,
                            "linear_attenuation_coeff" => 1,
                            _ => 2,
                        };
                        attenuation[i] = p.cur.number(&format!("for `{key}`"))?.0;
                    }
                    _ => return Ok(false),
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            POINT_LIGHT_FIELDS,
        )?;
        let span = keyword.span.start..self.cur.prev_end();
        let (position, color) = match (position, color) {
            (Some(position), Some(color)) => (position, color),
            (None, _) => return Err(ParseError::new("`point_light` needs a `position`", span)),
            (_, None) => return Err(ParseError::new("`point_light` needs a `color`", span)),
        };
        self.scene.lights.push(LightDesc::Point {
            position,
            color,
            attenuation,
            span,
        });
        Ok(())
    }

    fn directional_light(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let (mut direction, mut color) = (None, None);
        self.block(
            &keyword,
            |p, token, key| {
                if !matches!(key, "direction" | "color" | "colour") {
                    return Ok(false);
                }
                let slot = if key == "direction" { &mut direction } else { &mut color };
                if slot.is_some() {
                    return Err(ParseError::new(
                        format!("`directional_light` has a second `{key}`"),
                        token.span.clone(),
                    ));
                }
                p.key_equals()?;
                *slot = Some(p.vec3(&format!("for `{key}`"))?);
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            DIRECTIONAL_LIGHT_FIELDS,
        )?;
        let span = keyword.span.start..self.cur.prev_end();
        let (direction, color) = match (direction, color) {
            (Some(direction), Some(color)) => (direction, color),
            (None, _) => return Err(ParseError::new("`directional_light` needs a `direction`", span)),
            (_, None) => return Err(ParseError::new("`directional_light` needs a `color`", span)),
        };
        self.scene
            .lights
            .push(LightDesc::Directional { direction, color, span });
        Ok(())
    }

    /// `spot_light`, `area_light`, `warn_light` or `warn_model_light { … }` in any course fork's
    /// spelling (fork_lights.rs).
    fn fork_light(&mut self, allowed: &'static [&'static str]) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let mut fields = LightFields::default();
        self.block(
            &keyword,
            |p, token, key| {
                if !allowed.contains(&key) {
                    return Ok(false);
                }
                p.key_equals()?;
                let start = token.span.start;
                if fork_lights::is_vector_field(key) {
                    let v = p.vec3(&format!("for `{key}`"))?;
                    fields.vector(allowed, key, v, start..p.cur.prev_end())?;
                } else {
                    let (v, span) = p.cur.number(&format!("for `{key}`"))?;
                    fields.number(allowed, key, v, start..span.end)?;
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            allowed,
        )?;
        let span = keyword.span.start..self.cur.prev_end();
        let light = match self.cur.text_of(&keyword) {
            "spot_light" => {
                let (light, warnings) = fields.spot(span, [0.0, 0.0, 1.0], false)?;
                self.scene.warnings.extend(warnings);
                light
            }
            "area_light" => fields.area(span, [0.0, 0.0, 1.0], false)?,
            warn => {
                let (light, warnings) = fields.warn(warn, span, [0.0, 0.0, 1.0], false)?;
                self.scene.warnings.extend(warnings);
                light
            }
        };
        self.scene.lights.push(light);
        Ok(())
    }

    /// `skybox { front = "file"; … }` (skybox.rs).
    fn skybox(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let mut fields = SkyboxFields::default();
        let scene_dir = self.scene_dir;
        self.block(
            &keyword,
            |p, token, key| {
                if !SKYBOX_FIELDS.contains(&key) {
                    return Ok(false);
                }
                p.key_equals()?;
                if matches!(key, "color" | "colour") {
                    let color = p.vec3("for `color`")?;
                    fields.color(color, token.span.start..p.cur.prev_end())?;
                } else {
                    let (file, span) = p.identifier(&format!("(the image file, in quotes) for `{key}`"))?;
                    fields.face(key, &file, scene_dir, span)?;
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            SKYBOX_FIELDS,
        )?;
        self.scene.warnings.append(&mut fields.warnings);
        let light = fields.finish(keyword.span.start..self.cur.prev_end())?;
        self.scene.lights.push(light);
        Ok(())
    }

    /// `sun_light { direction; color; angle }`: a caustica extension (docs/scene-format.md).
    fn sun_light(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let (mut direction, mut color, mut angle) = (None, None, None);
        self.block(
            &keyword,
            |p, token, key| {
                let duplicate = match key {
                    "direction" => direction.is_some(),
                    "color" | "colour" => color.is_some(),
                    "angle" => angle.is_some(),
                    _ => return Ok(false),
                };
                if duplicate {
                    return Err(ParseError::new(
                        format!("`sun_light` has a second `{key}`"),
                        token.span.clone(),
                    ));
                }
                p.key_equals()?;
                match key {
                    "direction" => direction = Some(p.vec3("for `direction`")?),
                    "angle" => {
                        let (value, span) = p.cur.number("(the sun's angular diameter in degrees) for `angle`")?;
                        if !(0.0..=90.0).contains(&value) {
                            return Err(ParseError::new(
                                format!(
                                    "`angle` is the sun's angular diameter in degrees, between 0 and 90, not {value}"
                                ),
                                span,
                            ));
                        }
                        angle = Some(value);
                    }
                    _ => color = Some(p.vec3(&format!("for `{key}`"))?),
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            SUN_LIGHT_FIELDS,
        )?;
        let span = keyword.span.start..self.cur.prev_end();
        let (direction, color) = match (direction, color) {
            (Some(direction), Some(color)) => (direction, color),
            (None, _) => return Err(ParseError::new("`sun_light` needs a `direction`", span)),
            (_, None) => return Err(ParseError::new("`sun_light` needs a `color`", span)),
        };
        self.scene.lights.push(LightDesc::Sun {
            direction,
            color,
            angle_degrees: angle.unwrap_or(0.53),
            span,
        });
        Ok(())
    }

    /// `environment_light { color; map = "sky.exr"; }`: a caustica extension.
    fn environment_light(&mut self) -> Result<(), ParseError> {
        let keyword = self.cur.next();
        let (mut color, mut map) = (None, None);
        let scene_dir = self.scene_dir;
        self.block(
            &keyword,
            |p, token, key| {
                let duplicate = match key {
                    "color" | "colour" => color.is_some(),
                    "map" => map.is_some(),
                    _ => return Ok(false),
                };
                if duplicate {
                    return Err(ParseError::new(
                        format!("`environment_light` has a second `{key}`"),
                        token.span.clone(),
                    ));
                }
                p.key_equals()?;
                if key == "map" {
                    let (file, _) = p.identifier("(the image file, in quotes) for `map`")?;
                    map = Some(crate::texture::ImageSource::File(scene_dir.join(file)));
                } else {
                    color = Some(p.vec3(&format!("for `{key}`"))?);
                }
                p.cur.eat(Tok::Semicolon);
                Ok(true)
            },
            ENVIRONMENT_LIGHT_FIELDS,
        )?;
        let span = keyword.span.start..self.cur.prev_end();
        self.scene.lights.push(LightDesc::Environment {
            color: color.unwrap_or(Vec3::ONE),
            map,
            rotation: glam::Mat3::IDENTITY,
            equal_area: false,
            span,
        });
        Ok(())
    }

    fn ambient_light(&mut self) -> Result<(), ParseError> {
        self.cur.next();
        self.cur.expect(Tok::LBrace, "after `ambient_light`")?;
        if !(self.cur.at_word("color") || self.cur.at_word("colour")) {
            return Err(self.bad_word("`color` in `ambient_light`", &["color", "colour"]));
        }
        self.key_equals()?;
        let color = self.vec3("for the ambient `color`")?;
        self.scene.ambient += color;
        self.cur.eat(Tok::Semicolon);
        self.cur
            .expect(Tok::RBrace, "to close `ambient_light` (it has exactly one `color`)")?;
        Ok(())
    }

    /// `medium { absorption = …; scattering = …; phase = g; }` at the top level (a caustica
    /// extension): a medium that fills the scene where no object's says otherwise.
    fn ambient_medium(&mut self) -> Result<(), ParseError> {
        let start = self.cur.next().span.start;
        self.cur.expect(Tok::LBrace, "after `medium`")?;
        let mut fields = MediumFields::default();
        while !self.cur.eat(Tok::RBrace) {
            if !self.medium_field(&mut fields)? {
                return Err(self.bad_word(
                    "a medium field (`absorption`, `scattering`, `phase`) or `}`",
                    MEDIUM_FIELDS,
                ));
            }
        }
        if self.scene.ambient_medium.is_some() {
            return Err(ParseError::new(
                "the scene has a second `medium`",
                start..self.cur.prev_end(),
            ));
        }
        let medium = fields.medium(start..self.cur.prev_end());
        self.scene.media.push(medium);
        self.scene.ambient_medium = Some(self.scene.media.len() - 1);
        Ok(())
    }

    /// One field of a medium (the key is next): `false` when the word is not one.
    fn medium_field(&mut self, fields: &mut MediumFields) -> Result<bool, ParseError> {
        let token = self.cur.peek().clone();
        let key = if token.tok == Tok::Word {
            self.cur.text_of(&token)
        } else {
            ""
        };
        match key {
            "absorption" | "scattering" => {
                let key = key.to_string();
                self.key_equals()?;
                let (value, span) = self.tuple::<3>(&format!("(per unit of length) for `{key}`"))?;
                let value = Vec3::from(value);
                if !(value.cmpge(Vec3::ZERO).all() && value.is_finite()) {
                    return Err(ParseError::new(
                        format!("`{key}` is per unit of length, each value zero or more, not {value}"),
                        span,
                    ));
                }
                if key == "absorption" {
                    fields.absorption = Some(value);
                } else {
                    fields.scattering = Some(value);
                }
            }
            "phase" => {
                self.key_equals()?;
                let (g, span) = self
                    .cur
                    .number("(the mean cosine g of the scattering, from −1 to 1) for `phase`")?;
                if !(g > -1.0 && g < 1.0) {
                    return Err(ParseError::new(
                        format!("`phase` is the mean cosine g, strictly between −1 and 1, not {g}"),
                        span,
                    ));
                }
                fields.phase = Some(g);
            }
            _ => return Ok(false),
        }
        self.cur.eat(Tok::Semicolon);
        Ok(true)
    }

    /// `material = body ;?` (the `material` word is next); the body starts from `base`.
    fn material_stmt(&mut self, base: &MaterialDesc) -> Result<MaterialDesc, ParseError> {
        self.key_equals()?;
        let material = self.material_body(base)?;
        self.cur.eat(Tok::Semicolon);
        Ok(material)
    }

    /// `{ fields }` starting from `base`, or a named material's name.
    fn material_body(&mut self, base: &MaterialDesc) -> Result<MaterialDesc, ParseError> {
        let token = self.cur.peek().clone();
        if token.tok == Tok::Quoted || (token.tok == Tok::Word && !is_reserved(self.cur.text_of(&token))) {
            if let Some(error) = extension_error(self.cur.text_of(&token), &token.span) {
                return Err(error);
            }
            let (name, span) = self.identifier("")?;
            return self.named.get(&name, &span);
        }
        if token.tok != Tok::LBrace {
            return Err(self.cur.unexpected("`{` or a material name after `material =`"));
        }
        self.cur.next();
        let mut material = base.clone();
        material.name = None;
        let mut name: Option<(String, Span)> = None;
        // The medium inside the object, where the body gives one.
        let mut medium = MediumFields::default();
        let mut medium_span: Option<Span> = None;
        loop {
            let token = self.cur.peek().clone();
            if self.cur.eat(Tok::RBrace) {
                break;
            }
            let key = if token.tok == Tok::Word {
                self.cur.text_of(&token)
            } else {
                ""
            };
            match key {
                "name" => {
                    self.cur.next();
                    // `name ID;` is the skeleton's form; `name = ID` is accepted as well.
                    let with_equals = self.cur.eat(Tok::Equals);
                    let (value, span) = self.identifier("after `name`")?;
                    if with_equals {
                        self.cur.eat(Tok::Semicolon);
                    } else {
                        self.cur.expect(Tok::Semicolon, "after `name ID` in a material")?;
                    }
                    if name.is_some() {
                        return Err(ParseError::new("this material has a second `name`", span));
                    }
                    name = Some((value, span));
                }
                "abbe" => {
                    self.key_equals()?;
                    let (value, span) = self
                        .cur
                        .number("(the Abbe number V_d of a dispersive glass) for `abbe`")?;
                    if !(value > 0.0 && value.is_finite()) {
                        return Err(ParseError::new(
                            format!("`abbe` is an Abbe number, positive (about 20 to 90 for glasses), not {value}"),
                            span,
                        ));
                    }
                    self.cur.eat(Tok::Semicolon);
                    material.abbe = Some(value);
                }
                "absorption" | "scattering" | "phase" => {
                    let start = token.span.start;
                    self.medium_field(&mut medium)?;
                    medium_span.get_or_insert(start..self.cur.prev_end());
                }
                "boundary" => {
                    self.key_equals()?;
                    material.boundary = self.boolean("for `boundary`")?;
                    self.cur.eat(Tok::Semicolon);
                }
                _ if COLOUR_FIELDS.contains(&key) || key == "shininess" || key == "index" => {
                    self.key_equals()?;
                    let value = if self.cur.at_word("map") {
                        self.texture()?
                    } else if key == "shininess" || key == "index" {
                        Param::grey(self.cur.number(&format!("or `map(…)` for `{key}`"))?.0)
                    } else {
                        Param::Constant(self.vec3(&format!("(or `map(…)`) for `{key}`"))?)
                    };
                    self.cur.eat(Tok::Semicolon);
                    *field_mut(&mut material, key) = value;
                }
                _ if self.skip_extension_field("material")? => {}
                _ => {
                    let list = "`diffuse`, `specular`, `reflective`, `transmissive`, `emissive`, `ambient`, `shininess`, `index`, `abbe`, `absorption`, `scattering`, `phase`, `boundary`, `name`";
                    return Err(self.bad_word(&format!("a material field ({list}) or `}}`"), MATERIAL_FIELDS));
                }
            }
        }
        if let Some(span) = medium_span {
            if medium.scattering.is_none() && medium.phase.is_none() {
                // Only absorption: a coloured glass, as before media.
                material.absorption = medium.absorption;
            } else {
                self.scene.media.push(medium.medium(span));
                material.absorption = None;
                material.interface = Some(InterfaceDesc {
                    inside: MediumSide::Medium(Some(self.scene.media.len() - 1)),
                    outside: MediumSide::Surrounding,
                });
            }
        }
        if let Some((value, span)) = name {
            material.name = Some(value.clone());
            self.named.register(&value, material.clone(), &span)?;
        }
        Ok(material)
    }

    /// `map ( ID )` with the path resolved against the scene directory.
    fn texture(&mut self) -> Result<Param, ParseError> {
        let start = self.cur.next().span.start;
        self.cur.expect(Tok::LParen, "after `map`")?;
        let (file, _) = self.identifier("(the image file) in `map(…)`")?;
        self.cur.expect(Tok::RParen, "to close `map(…)`")?;
        let map = Param::Texture(Box::new(crate::description::ImageMap::course(
            self.scene_dir.join(file),
            start..self.cur.prev_end(),
        )));
        Ok(super::present_or_grey(map, &mut self.scene.warnings))
    }

    fn push_object(&mut self, shape: ShapeDesc, material: MaterialDesc, span: Span) {
        self.scene.objects.push(ObjectDesc {
            shape,
            world_from_object: self.transforms.current(),
            material,
            span,
        });
    }

    /// sphere, box, square, cylinder, cone (the keyword is consumed).
    fn simple_primitive(&mut self, keyword: &Token) -> Result<(), ParseError> {
        let kind = self.cur.text_of(keyword);
        let mut material = None;
        let (mut height, mut bottom, mut top, mut capped) = (1.0f32, 1.0f32, 0.0f32, true);
        // The UT 2019 fork's torus has radii 1 and 0.3 and no fields for them; the HKUST
        // fork's `a` and `b` (or caustica's names) set them.
        let (mut major, mut minor) = (1.0f32, 0.3f32);
        let allowed: &[&str] = match kind {
            "cone" => &["material", "name", "capped", "height", "bottom_radius", "top_radius"],
            "cylinder" => &["material", "name", "capped"],
            "torus" => &["material", "name", "major_radius", "minor_radius", "a", "b"],
            _ => &["material", "name"],
        };
        self.block(
            keyword,
            |p, _, key| {
                match key {
                    "material" => {
                        let base = p.default_material.clone();
                        material = Some(p.material_stmt(&base)?);
                    }
                    "name" => p.name_attr()?,
                    "capped" if kind == "cone" || kind == "cylinder" => {
                        p.key_equals()?;
                        capped = p.boolean("after `capped =`")?;
                        p.cur.eat(Tok::Semicolon);
                    }
                    "major_radius" | "minor_radius" | "a" | "b" if kind == "torus" => {
                        p.key_equals()?;
                        let (value, span) = p.cur.number(&format!("for `{key}`"))?;
                        if !(value > 0.0 && value.is_finite()) {
                            return Err(ParseError::new(
                                format!("a torus radius must be positive, not {value}"),
                                span,
                            ));
                        }
                        if matches!(key, "major_radius" | "a") {
                            major = value;
                        } else {
                            minor = value;
                        }
                        p.cur.eat(Tok::Semicolon);
                    }
                    "height" | "bottom_radius" | "top_radius" if kind == "cone" => {
                        p.key_equals()?;
                        let value = p.cur.number(&format!("for `{key}`"))?.0;
                        match key {
                            "height" => height = value,
                            // Radii are kept as magnitudes, as the course reader does.
                            "bottom_radius" => bottom = value.abs(),
                            _ => top = value.abs(),
                        }
                        p.cur.eat(Tok::Semicolon);
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            },
            allowed,
        )?;
        let shape = match kind {
            "sphere" => ShapeDesc::Sphere,
            "box" => ShapeDesc::Box,
            "square" => ShapeDesc::Square,
            "cylinder" => ShapeDesc::Cylinder { capped },
            "torus" => ShapeDesc::Torus {
                major_radius: major,
                minor_radius: minor,
            },
            _ => ShapeDesc::Cone {
                height,
                bottom_radius: bottom,
                top_radius: top,
                capped,
            },
        };
        let material = material.unwrap_or_else(|| self.default_material.clone());
        self.push_object(shape, material, keyword.span.clone());
        Ok(())
    }

    /// `metaballs { … }` or `metaball { … }` (the keyword is consumed; fork_shapes.rs).
    fn metaballs(&mut self, keyword: &Token) -> Result<(), ParseError> {
        let kind = self.cur.text_of(keyword);
        let mut material = None;
        let mut fields = MetaballFields::default();
        let mut allowed = vec!["material", "name"];
        allowed.extend_from_slice(METABALL_FIELDS);
        self.block(
            keyword,
            |p, token, key| {
                match key {
                    "material" => {
                        let base = p.default_material.clone();
                        material = Some(p.material_stmt(&base)?);
                    }
                    "name" => p.name_attr()?,
                    "balls" | "ball" => {
                        p.key_equals()?;
                        let mut balls = Vec::new();
                        let span = p.list(key, |p| {
                            let open = p
                                .cur
                                .expect(Tok::LParen, "to start a ball `(x, y, z)` or `(x, y, z, radius)`")?;
                            let mut values = Vec::with_capacity(4);
                            loop {
                                values.push(p.cur.number("in a ball")?.0);
                                if p.cur.eat(Tok::RParen) {
                                    break;
                                }
                                p.cur.expect(Tok::Comma, "or `)` in a ball")?;
                            }
                            if !(3..=4).contains(&values.len()) {
                                return Err(ParseError::new(
                                    format!(
                                        "a ball is `(x, y, z)` or `(x, y, z, radius)`, not {} numbers",
                                        values.len()
                                    ),
                                    open.span.start..p.cur.prev_end(),
                                ));
                            }
                            balls.push((Vec3::new(values[0], values[1], values[2]), values.get(3).copied()));
                            Ok(())
                        })?;
                        fields.balls(balls, span)?;
                    }
                    "radius" | "size" | "threshold" | "blend" => {
                        p.key_equals()?;
                        let (value, span) = p.cur.number(&format!("for `{key}`"))?;
                        fields.number(key, value, token.span.start..span.end)?;
                        p.cur.eat(Tok::Semicolon);
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            },
            &allowed,
        )?;
        let block = keyword.span.start..self.cur.prev_end();
        let Some(shape) = fields.finish(kind, &block, &mut self.scene.warnings)? else {
            return Ok(());
        };
        let material = material.unwrap_or_else(|| self.default_material.clone());
        self.push_object(shape, material, keyword.span.clone());
        Ok(())
    }

    /// `quadric`, `hyperboloid`, `hyperbolic_paraboloid` or `paraboloid { … }` (the keyword is
    /// consumed; quadric.rs): a triangle mesh of the surface inside [-1, 1]³.
    fn quadric(&mut self, keyword: &Token) -> Result<(), ParseError> {
        let kind = self.cur.text_of(keyword);
        let mut material = None;
        let mut coefficients = quadric::named(kind).expect("a quadric keyword");
        let allowed: &[&str] = if kind == "quadric" {
            &["material", "name", "points"]
        } else {
            &["material", "name"]
        };
        self.block(
            keyword,
            |p, _, key| {
                match key {
                    "material" => {
                        let base = p.default_material.clone();
                        material = Some(p.material_stmt(&base)?);
                    }
                    "name" => p.name_attr()?,
                    "points" if kind == "quadric" => {
                        p.key_equals()?;
                        let mut pairs = Vec::new();
                        let span = p.list(key, |p| {
                            pairs.push(p.tuple::<2>("in the quadric's `points`")?.0);
                            Ok(())
                        })?;
                        coefficients = quadric::from_pairs(&pairs).ok_or_else(|| {
                            ParseError::new(
                                format!(
                                    "a quadric's `points` are its ten coefficients A…J as five pairs ((A, B), (C, D), (E, F), (G, H), (I, J)), not {} pairs",
                                    pairs.len()
                                ),
                                span,
                            )
                        })?;
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            },
            allowed,
        )?;
        let block = keyword.span.start..self.cur.prev_end();
        let material = material.unwrap_or_else(|| self.default_material.clone());
        match quadric::tessellate(&coefficients) {
            Some(mesh) => self.push_object(ShapeDesc::Trimesh(Box::new(mesh)), material, keyword.span.clone()),
            None => self.scene.warnings.push((
                format!("the `{kind}` has no surface inside the cube [-1, 1]³ it is bounded by; nothing is drawn"),
                block,
            )),
        }
        Ok(())
    }

    fn boolean(&mut self, context: &str) -> Result<bool, ParseError> {
        if self.cur.at_word("true") {
            self.cur.next();
            Ok(true)
        } else if self.cur.at_word("false") {
            self.cur.next();
            Ok(false)
        } else {
            Err(self.cur.unexpected(&format!("`true` or `false` {context}")))
        }
    }

    /// `( item, item, … )` where `item` reads one entry; `;` after the `)` is required.
    fn list(
        &mut self,
        key: &str,
        mut item: impl FnMut(&mut Self) -> Result<(), ParseError>,
    ) -> Result<Span, ParseError> {
        let open = self.cur.expect(Tok::LParen, &format!("to start the `{key}` list"))?;
        if !self.cur.eat(Tok::RParen) {
            loop {
                item(self)?;
                if self.cur.eat(Tok::RParen) {
                    break;
                }
                self.cur
                    .expect(Tok::Comma, &format!("or `)` between entries of `{key}`"))?;
            }
        }
        let span = open.span.start..self.cur.prev_end();
        self.cur
            .expect(Tok::Semicolon, &format!("after the `{key}` list (it is required here)"))?;
        Ok(span)
    }

    fn trimesh(&mut self, keyword: &Token) -> Result<(), ParseError> {
        let mut material: Option<MaterialDesc> = None;
        let mut mesh = MeshInput::default();
        let mut file: Option<(std::path::PathBuf, Span)> = None;
        let scene_dir = self.scene_dir;
        self.block(
            keyword,
            |p, _, key| {
                match key {
                    // `objfile` is the UT 2016 photon-mapping fork's name for it.
                    "file" | "objfile" => {
                        p.key_equals()?;
                        let (name, span) = p.identifier("(the OBJ or PLY file, in quotes) for `file`")?;
                        file = Some((scene_dir.join(name), span));
                        p.cur.eat(Tok::Semicolon);
                    }
                    "material" => {
                        let base = p.default_material.clone();
                        material = Some(p.material_stmt(&base)?);
                    }
                    "name" => p.name_attr()?,
                    "gennormals" => {
                        p.cur.next();
                        p.cur.expect(Tok::Semicolon, "after `gennormals`")?;
                        mesh.gennormals = true;
                    }
                    "points" => {
                        p.key_equals()?;
                        let mut points = Vec::new();
                        p.list(key, |p| {
                            points.push(p.vec3("in `points`")?);
                            Ok(())
                        })?;
                        mesh.points = points;
                    }
                    "normals" => {
                        p.key_equals()?;
                        let mut normals = Vec::new();
                        let span = p.list(key, |p| {
                            normals.push(p.vec3("in `normals`")?);
                            Ok(())
                        })?;
                        mesh.normals = Some((normals, span));
                    }
                    "texture_uv" => {
                        p.key_equals()?;
                        let mut uvs = Vec::new();
                        let span = p.list(key, |p| {
                            uvs.push(Vec2::from(p.tuple::<2>("in `texture_uv`")?.0));
                            Ok(())
                        })?;
                        mesh.uvs = Some((uvs, span));
                    }
                    "faces" => {
                        p.key_equals()?;
                        // A later `faces` replaces an earlier one, like any repeated attribute.
                        mesh.face_indices.clear();
                        mesh.faces.clear();
                        p.list(key, |p| {
                            let open = p.cur.expect(Tok::LParen, "to start a face")?;
                            let first = mesh.face_indices.len();
                            loop {
                                mesh.face_indices.push(p.cur.number_f64("(a vertex index) in a face")?);
                                if p.cur.eat(Tok::RParen) {
                                    break;
                                }
                                p.cur.expect(Tok::Comma, "or `)` between the indices of a face")?;
                            }
                            let span = open.span.start..p.cur.prev_end();
                            mesh.faces.push((first..mesh.face_indices.len(), span));
                            Ok(())
                        })?;
                    }
                    "materials" => {
                        p.key_equals()?;
                        // Each entry starts from the mesh's material as it is at this point.
                        let base = material.clone().unwrap_or_else(|| p.default_material.clone());
                        let mut materials = Vec::new();
                        let span = p.list(key, |p| {
                            materials.push(p.material_body(&base)?);
                            Ok(())
                        })?;
                        mesh.materials = Some((materials, span));
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            },
            MESH_FIELDS,
        )?;
        let span = keyword.span.clone();
        let block_span = keyword.span.start..self.cur.prev_end();
        if let Some((path, file_span)) = file {
            if !mesh.points.is_empty() || !mesh.faces.is_empty() {
                return Err(ParseError::new(
                    "a mesh read from a `file` takes no `points` or `faces`",
                    block_span,
                ));
            }
            let given = material.is_some();
            let material = material.unwrap_or_else(|| self.default_material.clone());
            self.push_object(ShapeDesc::Trimesh(Box::default()), material, span);
            self.scene.mesh_files.push(super::ast::MeshFile {
                object: self.scene.objects.len() - 1,
                path,
                span: file_span,
                material_given: given,
            });
            return Ok(());
        }
        if let Some(desc) = trimesh::finish(mesh, &block_span, &mut self.scene.warnings)? {
            let material = material.unwrap_or_else(|| self.default_material.clone());
            self.push_object(ShapeDesc::Trimesh(Box::new(desc)), material, span);
        }
        Ok(())
    }
}

/// The material field named `key` (one of the colour fields, `shininess` or `index`).
pub(crate) fn field_mut<'m>(material: &'m mut MaterialDesc, key: &str) -> &'m mut Param {
    match key {
        "emissive" => &mut material.emissive,
        "ambient" => &mut material.ambient,
        "specular" => &mut material.specular,
        "reflective" => &mut material.reflective,
        "diffuse" => &mut material.diffuse,
        "transmissive" => &mut material.transmissive,
        "shininess" => &mut material.shininess,
        _ => &mut material.index,
    }
}
