//! Dialect O: the older object/dictionary reader (UW ≤ 2008, UT ≤ 2010, HKUST COMP 4411).
//!
//! The file is first read into a flat tree of generic objects (numbers, strings, words, named
//! objects, tuples, dictionaries) with an explicit stack, then interpreted. Transform chains are
//! walked in a loop, so neither step recurses with the input's nesting.

use super::ast::{
    CameraBasis, Dialect, LightDesc, MaterialDesc, ObjectDesc, Param, RayCamera, RayScene, ShapeDesc, Span,
};
use super::cursor::{Cursor, Reach};
use super::fork_lights::{self, LightFields};
use super::fork_shapes::{self, MetaballFields};
use super::keywords::{extension_error, is_extension, skipped_object, COLOUR_FIELDS, TOP_LEVEL};
use super::lexer::{self, Tok};
use super::named_materials::NamedMaterials;
use super::quadric;
use super::skybox::{SkyboxFields, SKYBOX_FIELDS};
use super::suggest;
use super::tokenizer_dialect::field_mut;
use super::transform_stack;
use super::trimesh::{self, MeshInput};
use crate::ParseError;
use glam::{Mat4, Vec3, Vec4};
use std::path::Path;

/// How deep CSG operations may nest (each level is a recursion of the reader).
const MAX_CSG_DEPTH: usize = 64;

/// Prefix of the warning for an ignored dictionary key (detection looks for it).
pub(crate) const IGNORED_KEY: &str = "ignored unknown key";

/// Parses a whole dialect-O file, with the defaults of `dialect` (`Dictionary` or `Hkust`).
pub(crate) fn parse(text: &str, scene_dir: &Path, reach: &Reach<'_>, dialect: Dialect) -> Result<RayScene, ParseError> {
    let tokens = lexer::lex(text, dialect)?;
    let mut cur = Cursor::new(text, tokens, reach);
    if !cur.at_word("SBT-raytracer") {
        return Err(cur
            .unexpected("the header `SBT-raytracer 1.0`")
            .with_help("every scene file starts with `SBT-raytracer 1.0`"));
    }
    cur.next();
    let (version, span) = cur.number("(the format version) after `SBT-raytracer`")?;
    if version != 1.0 {
        return Err(ParseError::new(
            format!("format version {version} is not supported; this dialect requires 1.0"),
            span,
        ));
    }
    let mut reader = Reader {
        text,
        tree: Vec::new(),
        scene_dir,
        named: NamedMaterials::default(),
        hkust: dialect == Dialect::Hkust,
        scene: RayScene {
            dialect,
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
    loop {
        if cur.peek().tok == Tok::Eof {
            return Ok(reader.scene);
        }
        if cur.eat(Tok::Semicolon) {
            continue;
        }
        reader.tree.clear();
        let root = read_object(&mut cur, &mut reader.tree)?;
        reader.top_level(root)?;
    }
}

/// A generic object of the dictionary syntax.
#[derive(Debug)]
enum Kind {
    Number(f64),
    Str,
    Word,
    /// A word followed by an object, e.g. `sphere { … }`; the word is the node's `head`.
    Named(usize),
    Tuple(Vec<usize>),
    /// Entries with the key's span.
    Dict(Vec<(Span, usize)>),
}

#[derive(Debug)]
struct Node {
    kind: Kind,
    /// The whole object.
    span: Span,
    /// For a named object, its word; otherwise the same as `span`.
    head: Span,
}

/// A partly read container while the object tree is built.
enum Open {
    Named {
        head: Span,
    },
    Tuple {
        start: usize,
        items: Vec<usize>,
    },
    Dict {
        start: usize,
        entries: Vec<(Span, usize)>,
        key: Span,
    },
}

fn push(tree: &mut Vec<Node>, kind: Kind, span: Span, head: Option<Span>) -> usize {
    let head = head.unwrap_or_else(|| span.clone());
    tree.push(Node { kind, span, head });
    tree.len() - 1
}

fn starts_object(tok: Tok) -> bool {
    matches!(
        tok,
        Tok::Number(_) | Tok::Quoted | Tok::Word | Tok::LParen | Tok::LBrace
    )
}

/// `key =` at the start of a dictionary entry; returns the key's span.
fn dict_key(cur: &mut Cursor<'_>) -> Result<Span, ParseError> {
    if cur.peek().tok != Tok::Word {
        return Err(cur.unexpected("a key (`name = value;`) or `}` in a dictionary"));
    }
    let key = cur.next();
    cur.expect(Tok::Equals, &format!("after `{}`", cur.text_of(&key)))?;
    Ok(key.span)
}

/// Reads one generic object into `tree`, returning its index.
fn read_object(cur: &mut Cursor<'_>, tree: &mut Vec<Node>) -> Result<usize, ParseError> {
    let mut stack: Vec<Open> = Vec::new();
    loop {
        let token = cur.next();
        let start = token.span.start;
        let mut done = match token.tok {
            Tok::Number(v) => push(tree, Kind::Number(v), token.span, None),
            Tok::Quoted => push(tree, Kind::Str, token.span, None),
            Tok::Word if starts_object(cur.peek().tok) => {
                stack.push(Open::Named { head: token.span });
                continue;
            }
            Tok::Word => push(tree, Kind::Word, token.span, None),
            Tok::LParen if cur.eat(Tok::RParen) => push(tree, Kind::Tuple(Vec::new()), start..cur.prev_end(), None),
            Tok::LParen => {
                stack.push(Open::Tuple {
                    start,
                    items: Vec::new(),
                });
                continue;
            }
            Tok::LBrace if cur.eat(Tok::RBrace) => push(tree, Kind::Dict(Vec::new()), start..cur.prev_end(), None),
            Tok::LBrace => {
                let key = dict_key(cur)?;
                stack.push(Open::Dict {
                    start,
                    entries: Vec::new(),
                    key,
                });
                continue;
            }
            _ => {
                return Err(ParseError::new(
                    format!(
                        "expected a value (number, string, word, `(` or `{{`), found {}",
                        token.describe(cur.text)
                    ),
                    token.span,
                ))
            }
        };
        // A value is complete: attach it to the containers it closes.
        loop {
            let end = tree[done].span.end;
            match stack.last_mut() {
                None => return Ok(done),
                Some(Open::Named { head }) => {
                    let head = head.clone();
                    stack.pop();
                    done = push(tree, Kind::Named(done), head.start..end, Some(head));
                }
                Some(Open::Tuple { start, items }) => {
                    items.push(done);
                    if cur.eat(Tok::Comma) {
                        break;
                    }
                    if cur.peek().tok != Tok::RParen {
                        return Err(cur.unexpected("`,` or `)` in a tuple"));
                    }
                    cur.next();
                    let (start, items) = (*start, std::mem::take(items));
                    stack.pop();
                    done = push(tree, Kind::Tuple(items), start..cur.prev_end(), None);
                }
                Some(Open::Dict { start, entries, key }) => {
                    entries.push((key.clone(), done));
                    let closed = if cur.eat(Tok::Semicolon) {
                        if cur.eat(Tok::RBrace) {
                            true
                        } else {
                            *key = dict_key(cur)?;
                            false
                        }
                    } else if cur.eat(Tok::RBrace) {
                        true
                    } else {
                        let key_text = &cur.text[key.clone()];
                        return Err(cur.unexpected(&format!("`;` or `}}` after the value of `{key_text}`")));
                    };
                    if !closed {
                        break;
                    }
                    let (start, entries) = (*start, std::mem::take(entries));
                    stack.pop();
                    done = push(tree, Kind::Dict(entries), start..cur.prev_end(), None);
                }
            }
        }
    }
}

struct Reader<'a> {
    text: &'a str,
    tree: Vec<Node>,
    scene_dir: &'a Path,
    named: NamedMaterials,
    /// HKUST defaults: point lights without coefficients keep f = 1; `texture` is a diffuse map.
    hkust: bool,
    scene: RayScene,
}

impl<'a> Reader<'a> {
    fn word(&self, span: &Span) -> &'a str {
        &self.text[span.clone()]
    }

    /// A short quote of a node for "found …".
    fn describe(&self, id: usize) -> String {
        let text = &self.text[self.tree[id].span.clone()];
        let mut quoted: String = text.chars().take(40).collect();
        if quoted.len() < text.len() {
            quoted.push('…');
        }
        format!("`{quoted}`")
    }

    fn expected(&self, what: &str, id: usize) -> ParseError {
        let node = &self.tree[id];
        if let Kind::Named(_) = node.kind {
            if let Some(error) = extension_error(self.word(&node.head), &node.head) {
                return error;
            }
        }
        ParseError::new(
            format!("expected {what}, found {}", self.describe(id)),
            self.tree[id].span.clone(),
        )
    }

    fn top_level(&mut self, id: usize) -> Result<(), ParseError> {
        let Kind::Named(child) = self.tree[id].kind else {
            return Err(self.expected("an object such as `camera { … }` or `sphere { … }`", id));
        };
        let head = self.tree[id].head.clone();
        match self.word(&head) {
            "camera" => self.camera(child, head),
            "point_light" => self.point_light(child, head),
            "directional_light" => self.directional_light(child, head),
            "spot_light" => self.fork_light(child, head, fork_lights::SPOT_FIELDS),
            "area_light" => self.fork_light(child, head, fork_lights::AREA_FIELDS),
            "warn_light" | "warn_model_light" => self.fork_light(child, head, fork_lights::WARN_FIELDS),
            "skybox" => self.skybox(child, head),
            "csg" => self.csg_block(child, head),
            "ambient_light" => {
                for (key, value) in self.entries(child, "ambient_light")? {
                    match self.word(&key) {
                        "color" | "colour" => self.scene.ambient += self.vec3(value, "for `color`")?,
                        _ => self.ignore_key(&key, "ambient_light")?,
                    }
                }
                Ok(())
            }
            "material" => {
                let material = self.material_dict(child)?;
                match material.name.clone() {
                    Some(name) => self.named.register(&name, material, &head),
                    None => Err(ParseError::new(
                        "a top-level `material` definition needs a `name`",
                        head,
                    )),
                }
            }
            _ => self.object(id),
        }
    }

    /// The entries of a dictionary node (cloned, so the reader can be borrowed mutably).
    fn entries(&self, id: usize, owner: &str) -> Result<Vec<(Span, usize)>, ParseError> {
        match &self.tree[id].kind {
            Kind::Dict(entries) => Ok(entries.clone()),
            _ => Err(self.expected(&format!("`{{ … }}` after `{owner}`"), id)),
        }
    }

    /// An unknown key, ignored with a warning (which names a student extension as one).
    fn ignore_key(&mut self, key: &Span, owner: &str) -> Result<(), ParseError> {
        let word = self.word(key);
        let message = if is_extension(word) {
            format!("{IGNORED_KEY} `{word}` in `{owner}`: a student extension of the course format that caustica does not read")
        } else {
            format!("{IGNORED_KEY} `{word}` in `{owner}`")
        };
        self.scene.warnings.push((message, key.clone()));
        Ok(())
    }

    fn number(&self, id: usize, context: &str) -> Result<f32, ParseError> {
        match self.tree[id].kind {
            Kind::Number(v) => Ok(v as f32),
            _ => Err(self.expected(&format!("a number {context}"), id)),
        }
    }

    fn tuple<const N: usize>(&self, id: usize, context: &str) -> Result<[f32; N], ParseError> {
        let what = || format!("a tuple of {N} numbers {context}");
        let Kind::Tuple(items) = &self.tree[id].kind else {
            return Err(self.expected(&what(), id));
        };
        if items.len() != N {
            return Err(self.expected(&what(), id));
        }
        let mut values = [0.0; N];
        for (value, &item) in values.iter_mut().zip(items) {
            *value = self.number(item, context)?;
        }
        Ok(values)
    }

    fn vec3(&self, id: usize, context: &str) -> Result<Vec3, ParseError> {
        Ok(Vec3::from(self.tuple::<3>(id, context)?))
    }

    fn boolean(&self, id: usize, context: &str) -> Result<bool, ParseError> {
        match self.tree[id].kind {
            Kind::Word if self.word(&self.tree[id].span) == "true" => Ok(true),
            Kind::Word if self.word(&self.tree[id].span) == "false" => Ok(false),
            Kind::Number(v) => Ok(v != 0.0),
            _ => Err(self.expected(&format!("`true` or `false` {context}"), id)),
        }
    }

    fn camera(&mut self, id: usize, head: Span) -> Result<(), ParseError> {
        let mut camera = self.scene.camera.take().unwrap_or(RayCamera {
            position: Vec3::ZERO,
            viewdir: None,
            updir: None,
            look_at: None,
            quaternion: None,
            fov_degrees: None,
            aspect_ratio: None,
            basis: CameraBasis::Normalized,
            span: head.clone(),
        });
        let (mut viewdir, mut updir) = (None, None);
        for (key, value) in self.entries(id, "camera")? {
            match self.word(&key) {
                "position" => camera.position = self.vec3(value, "for `position`")?,
                "viewdir" => viewdir = Some(self.vec3(value, "for `viewdir`")?),
                "updir" => updir = Some(self.vec3(value, "for `updir`")?),
                "fov" => camera.fov_degrees = Some(self.number(value, "for `fov`")?),
                "aspectratio" => camera.aspect_ratio = Some(self.number(value, "for `aspectratio`")?),
                "quaternion" => camera.quaternion = Some(self.tuple::<4>(value, "for `quaternion`")?),
                _ => self.ignore_key(&key, "camera")?,
            }
        }
        camera.span = head.start..self.tree[id].span.end;
        if viewdir.is_some() != updir.is_some() {
            return Err(ParseError::new(
                "the camera needs `viewdir` and `updir` together",
                camera.span,
            ));
        }
        if viewdir.is_some() {
            camera.viewdir = viewdir;
            camera.updir = updir;
        }
        self.scene.camera = Some(camera);
        Ok(())
    }

    fn point_light(&mut self, id: usize, head: Span) -> Result<(), ParseError> {
        let (mut position, mut color) = (None, None);
        // The HKUST skeleton reads no coefficients and its lights do not fall off; its forks
        // that read them use them only when one is positive.
        let mut attenuation = if self.hkust { [0.0; 3] } else { [0.0, 0.0, 1.0] };
        for (key, value) in self.entries(id, "point_light")? {
            match self.word(&key) {
                "position" => position = Some(self.vec3(value, "for `position`")?),
                "color" | "colour" => color = Some(self.vec3(value, "for `color`")?),
                "constant_attenuation_coeff" => attenuation[0] = self.number(value, "")?,
                "linear_attenuation_coeff" => attenuation[1] = self.number(value, "")?,
                "quadratic_attenuation_coeff" => attenuation[2] = self.number(value, "")?,
                _ => self.ignore_key(&key, "point_light")?,
            }
        }
        let span = head.start..self.tree[id].span.end;
        let (Some(position), Some(color)) = (position, color) else {
            let missing = if position.is_none() { "position" } else { "color" };
            return Err(ParseError::new(format!("`point_light` needs a `{missing}`"), span));
        };
        if attenuation.iter().all(|&c| c <= 0.0) {
            attenuation = [1.0, 0.0, 0.0];
        }
        self.scene.lights.push(LightDesc::Point {
            position,
            color,
            attenuation,
            span,
        });
        Ok(())
    }

    fn directional_light(&mut self, id: usize, head: Span) -> Result<(), ParseError> {
        let (mut direction, mut color) = (None, None);
        for (key, value) in self.entries(id, "directional_light")? {
            match self.word(&key) {
                "direction" => direction = Some(self.vec3(value, "for `direction`")?),
                "color" | "colour" => color = Some(self.vec3(value, "for `color`")?),
                _ => self.ignore_key(&key, "directional_light")?,
            }
        }
        let span = head.start..self.tree[id].span.end;
        let (Some(direction), Some(color)) = (direction, color) else {
            let missing = if direction.is_none() { "direction" } else { "color" };
            return Err(ParseError::new(
                format!("`directional_light` needs a `{missing}`"),
                span,
            ));
        };
        self.scene
            .lights
            .push(LightDesc::Directional { direction, color, span });
        Ok(())
    }

    /// `spot_light`, `area_light`, `warn_light` or `warn_model_light { … }` in any course fork's
    /// spelling; other keys are ignored with a warning, as the dictionary reader does.
    fn fork_light(&mut self, id: usize, head: Span, allowed: &'static [&'static str]) -> Result<(), ParseError> {
        let owner = self.word(&head);
        let mut fields = LightFields::default();
        for (key, value) in self.entries(id, owner)? {
            let word = self.word(&key);
            if !allowed.contains(&word) {
                self.ignore_key(&key, owner)?;
                continue;
            }
            let span = key.start..self.tree[value].span.end;
            if fork_lights::is_vector_field(word) {
                let v = self.vec3(value, &format!("for `{word}`"))?;
                fields.vector(allowed, word, v, span)?;
            } else {
                let v = self.number(value, &format!("for `{word}`"))?;
                fields.number(allowed, word, v, span)?;
            }
        }
        let span = head.start..self.tree[id].span.end;
        let falloff = if self.hkust { [1.0, 0.0, 0.0] } else { [0.0, 0.0, 1.0] };
        let light = match owner {
            "spot_light" => {
                let (light, warnings) = fields.spot(span, falloff, self.hkust)?;
                self.scene.warnings.extend(warnings);
                light
            }
            "area_light" => fields.area(span, falloff, self.hkust)?,
            warn => {
                let (light, warnings) = fields.warn(warn, span, falloff, self.hkust)?;
                self.scene.warnings.extend(warnings);
                light
            }
        };
        self.scene.lights.push(light);
        Ok(())
    }

    /// `skybox { front = "file"; … }` (skybox.rs); other keys are ignored with a warning.
    fn skybox(&mut self, id: usize, head: Span) -> Result<(), ParseError> {
        let mut fields = SkyboxFields::default();
        for (key, value) in self.entries(id, "skybox")? {
            let word = self.word(&key);
            if !SKYBOX_FIELDS.contains(&word) {
                self.ignore_key(&key, "skybox")?;
                continue;
            }
            let span = self.tree[value].span.clone();
            if matches!(word, "color" | "colour") {
                let color = self.vec3(value, "for `color`")?;
                fields.color(color, span)?;
            } else {
                let Kind::Str = self.tree[value].kind else {
                    return Err(self.expected(&format!("the image file, in quotes, for `{word}`"), value));
                };
                let file = &self.text[span.start + 1..span.end - 1];
                fields.face(word, file, self.scene_dir, span)?;
            }
        }
        self.scene.warnings.append(&mut fields.warnings);
        let light = fields.finish(head.start..self.tree[id].span.end)?;
        self.scene.lights.push(light);
        Ok(())
    }

    /// A material value: an inline dictionary or the name of a defined material.
    fn material_value(&mut self, id: usize) -> Result<MaterialDesc, ParseError> {
        match self.tree[id].kind {
            Kind::Word | Kind::Str => {
                let node = &self.tree[id];
                let span = node.span.clone();
                let name = match node.kind {
                    Kind::Str => &self.text[span.start + 1..span.end - 1],
                    _ => self.word(&span),
                };
                self.named.get(name, &span)
            }
            Kind::Dict(_) => {
                let mut material = self.material_dict(id)?;
                // Names matter only for top-level definitions.
                material.name = None;
                Ok(material)
            }
            _ => Err(self.expected("a material (`{ … }` or a material name)", id)),
        }
    }

    /// A material dictionary: starts from all zeros; `reflective` defaults to `specular`;
    /// constant shininess is on the 0–1 scale and multiplied by 128.
    fn material_dict(&mut self, id: usize) -> Result<MaterialDesc, ParseError> {
        let mut material = MaterialDesc::default();
        let mut has_reflective = false;
        for (key, value) in self.entries(id, "material")? {
            let word = self.word(&key);
            match word {
                "name" => {
                    let span = self.tree[value].span.clone();
                    material.name = Some(match self.tree[value].kind {
                        Kind::Str => self.text[span.start + 1..span.end - 1].to_string(),
                        Kind::Word => self.word(&span).to_string(),
                        _ => return Err(self.expected("a material name", value)),
                    });
                }
                // An HKUST fork's procedural marble: its base colour stands in for it.
                _ if COLOUR_FIELDS.contains(&word) && self.is_named(value, "marble") => {
                    let color = self.marble_color(value)?;
                    let message = match color {
                        Some(color) => {
                            *field_mut(&mut material, word) = Param::Constant(color);
                            format!("the procedural `marble` texture of `{word}` is not modelled: its `color` is used")
                        }
                        None => {
                            format!("the procedural `marble` texture of `{word}` is not modelled: `{word}` is unset")
                        }
                    };
                    has_reflective |= word == "reflective";
                    self.scene.warnings.push((message, self.tree[value].span.clone()));
                }
                _ if COLOUR_FIELDS.contains(&word) || word == "shininess" || word == "index" => {
                    let mut param = super::present_or_grey(self.param(value, word)?, &mut self.scene.warnings);
                    if word == "shininess" {
                        if let Param::Constant(c) = &mut param {
                            *c *= 128.0;
                        }
                    }
                    has_reflective |= word == "reflective";
                    *field_mut(&mut material, word) = param;
                }
                // An HKUST fork's image texture: the diffuse colour read from a file.
                "texture" if self.hkust => match self.tree[value].kind {
                    Kind::Str => {
                        let map = self.texture(value, self.tree[value].span.clone());
                        material.diffuse = super::present_or_grey(map, &mut self.scene.warnings);
                    }
                    _ => return Err(self.expected("a file name in quotes for `texture`", value)),
                },
                _ => self.ignore_key(&key, "material")?,
            }
        }
        if !has_reflective {
            material.reflective = material.specular.clone();
        }
        Ok(material)
    }

    /// The `color` of a `marble { … }` value, if it gives one.
    fn marble_color(&self, id: usize) -> Result<Option<Vec3>, ParseError> {
        let Kind::Named(body) = self.tree[id].kind else {
            return Ok(None);
        };
        let entries = self.entries(body, "marble")?;
        match entries.iter().find(|(k, _)| matches!(self.word(k), "color" | "colour")) {
            Some(&(_, color)) => Ok(Some(self.vec3(color, "for the marble's `color`")?)),
            None => Ok(None),
        }
    }

    /// Whether node `id` is the named object `word { … }`.
    fn is_named(&self, id: usize, word: &str) -> bool {
        matches!(self.tree[id].kind, Kind::Named(_)) && self.word(&self.tree[id].head) == word
    }

    /// A colour or scalar: `(r, g, b)`, a number, `map("file")` or a bare `"file"` string.
    fn param(&self, id: usize, key: &str) -> Result<Param, ParseError> {
        let node = &self.tree[id];
        match &node.kind {
            Kind::Number(v) => Ok(Param::grey(*v as f32)),
            Kind::Tuple(_) => Ok(Param::Constant(self.vec3(id, &format!("for `{key}`"))?)),
            Kind::Str => Ok(self.texture(id, node.span.clone())),
            Kind::Named(child) if self.word(&node.head) == "map" => {
                let file = match &self.tree[*child].kind {
                    Kind::Str => *child,
                    Kind::Tuple(items) if items.len() == 1 => items[0],
                    _ => return Err(self.expected("`map(\"file\")`", id)),
                };
                match self.tree[file].kind {
                    Kind::Str | Kind::Word => Ok(self.texture(file, node.span.clone())),
                    _ => Err(self.expected("`map(\"file\")`", id)),
                }
            }
            _ => Err(self.expected(&format!("`(r, g, b)`, a number or `map(\"file\")` for `{key}`"), id)),
        }
    }

    fn texture(&self, file: usize, span: Span) -> Param {
        let s = &self.tree[file].span;
        let name = match self.tree[file].kind {
            Kind::Str => &self.text[s.start + 1..s.end - 1],
            _ => self.word(s),
        };
        Param::Texture(Box::new(crate::description::ImageMap::course(
            self.scene_dir.join(name),
            span,
        )))
    }

    /// A transform chain ending in a primitive, walked iteratively.
    fn object(&mut self, id: usize) -> Result<(), ParseError> {
        self.object_at(id, Mat4::IDENTITY, 0)
    }

    /// [`Reader::object`] under the transform `world`; `depth` counts enclosing CSG operations.
    fn object_at(&mut self, id: usize, mut world: Mat4, depth: usize) -> Result<(), ParseError> {
        let mut node = id;
        loop {
            let Kind::Named(child) = self.tree[node].kind else {
                return Err(self.expected("an object such as `sphere { … }` or `translate(…)`", node));
            };
            let head = self.tree[node].head.clone();
            let word = self.word(&head);
            let span = head.start..self.tree[child].span.end;
            let (local, next) = match word {
                "translate" => {
                    let (args, obj) = self.args(child, word, "(x, y, z, object)", &[3])?;
                    (transform_stack::translation(Vec3::from_slice(&args)), obj)
                }
                "scale" => {
                    let (args, obj) = self.args(child, word, "(s, object) or (x, y, z, object)", &[1, 3])?;
                    let factors = if args.len() == 1 {
                        Vec3::splat(args[0])
                    } else {
                        Vec3::from_slice(&args)
                    };
                    (transform_stack::scaling(factors, &span)?, obj)
                }
                "rotate" => {
                    let (args, obj) = self.args(child, word, "(x, y, z, angle, object)", &[4])?;
                    let axis = Vec3::from_slice(&args[..3]);
                    (transform_stack::rotation(axis, args[3], &span)?, obj)
                }
                "transform" => {
                    let usage = "four rows `(a, b, c, d)` and an object";
                    let items = match &self.tree[child].kind {
                        Kind::Tuple(items) if items.len() == 5 => items.clone(),
                        _ => return Err(self.expected(&format!("`transform` with {usage}"), child)),
                    };
                    let mut rows = [Vec4::ZERO; 4];
                    for (row, &item) in rows.iter_mut().zip(&items) {
                        *row = Vec4::from(self.tuple::<4>(item, "as a matrix row")?);
                    }
                    (transform_stack::from_rows(rows, &span)?, items[4])
                }
                "sphere"
                | "box"
                | "square"
                | "cylinder"
                | "cone"
                | "torus"
                | "metaballs"
                | "metaball"
                | "trimesh"
                | "polymesh"
                | "quadric"
                | "hyperboloid"
                | "hyperbolic_paraboloid"
                | "paraboloid" => {
                    return self.primitive(word, head, child, world);
                }
                // `subtraction(a, b)`, `intersection(a, b)`, `union(a, b, …)` (HKUST 2019).
                "union" | "intersection" | "difference" | "subtraction" => {
                    let Kind::Tuple(items) = &self.tree[child].kind else {
                        return Err(self.expected(&format!("`{word}(a, b, …)` with two or more objects"), child));
                    };
                    let items = items.clone();
                    let operands = self.csg_operands(&items, world, depth, &span)?;
                    let op = fork_shapes::csg_op(word).expect("a CSG keyword");
                    let object = fork_shapes::csg_object(op, operands, span)?;
                    self.scene.objects.push(object);
                    return Ok(());
                }
                _ => {
                    let error = ParseError::new(format!("unknown object `{word}`"), head.clone());
                    if let Some(near) =
                        suggest::nearest(word, TOP_LEVEL.iter().copied()).filter(|_| !is_extension(word))
                    {
                        return Err(error.with_help(suggest::did_you_mean(near)));
                    }
                    // Another fork's object: the rest of the scene is read without it.
                    let what = format!(
                        "{word} {}",
                        if matches!(self.tree[child].kind, Kind::Dict(_)) {
                            "{ … }"
                        } else {
                            "( … )"
                        }
                    );
                    self.scene.warnings.push((skipped_object(word, &what), span));
                    return Ok(());
                }
            };
            world = transform_stack::compose(world, local, &span)?;
            node = next;
        }
    }

    /// The objects each of `items` makes under `world`, for a CSG operation at `span`.
    fn csg_operands(
        &mut self,
        items: &[usize],
        world: Mat4,
        depth: usize,
        span: &Span,
    ) -> Result<Vec<Vec<ObjectDesc>>, ParseError> {
        if depth >= MAX_CSG_DEPTH {
            return Err(ParseError::new(
                format!("CSG operations are nested more than {MAX_CSG_DEPTH} deep"),
                span.clone(),
            ));
        }
        let mut operands = Vec::with_capacity(items.len());
        for &item in items {
            let start = self.scene.objects.len();
            self.object_at(item, world, depth + 1)?;
            operands.push(self.scene.objects.drain(start..).collect());
        }
        Ok(operands)
    }

    /// `csg { primitives = ("a", "b"); a = object; b = object; operation = ("a", "sub", "b"); }`
    /// (COMP4411-Team/Trace): named operands and an operation on them, `sub`, `and` or `or`,
    /// whose operands may themselves be operations.
    fn csg_block(&mut self, id: usize, head: Span) -> Result<(), ParseError> {
        let span = head.start..self.tree[id].span.end;
        let entries = self.entries(id, "csg")?;
        let mut named: Vec<(&str, usize)> = Vec::new();
        let mut operation = None;
        for (key, value) in &entries {
            match self.word(key) {
                "primitives" => {}
                "operation" => operation = Some(*value),
                name => named.push((name, *value)),
            }
        }
        let Some(operation) = operation else {
            // Without an operation the operands are still solids of the scene: their union.
            let start = self.scene.objects.len();
            for &(_, object) in &named {
                self.object_at(object, Mat4::IDENTITY, 1)?;
            }
            let objects: Vec<ObjectDesc> = self.scene.objects.drain(start..).collect();
            let count = objects.len();
            if count > 1 {
                let union = fork_shapes::csg_object(
                    crate::description::CsgOpDesc::Union,
                    objects.into_iter().map(|o| vec![o]).collect(),
                    span.clone(),
                )?;
                self.scene.objects.push(union);
            } else {
                self.scene.objects.extend(objects);
            }
            self.scene.warnings.push((
                format!("`csg` has no `operation` (such as `(\"a\", \"sub\", \"b\")`): its {count} operand(s) are drawn as their union"),
                span,
            ));
            return Ok(());
        };
        let object = self.csg_operation(operation, &named, 0)?;
        self.scene.objects.push(object);
        Ok(())
    }

    /// One `(operand, op, operand)` of a `csg` block, or an operand's name.
    fn csg_operation(&mut self, id: usize, named: &[(&str, usize)], depth: usize) -> Result<ObjectDesc, ParseError> {
        let span = self.tree[id].span.clone();
        if depth >= MAX_CSG_DEPTH {
            return Err(ParseError::new(
                format!("CSG operations are nested more than {MAX_CSG_DEPTH} deep"),
                span,
            ));
        }
        match &self.tree[id].kind {
            Kind::Str | Kind::Word => {
                let name = match self.tree[id].kind {
                    Kind::Str => &self.text[span.start + 1..span.end - 1],
                    _ => self.word(&span),
                };
                let Some(&(_, object)) = named.iter().find(|(n, _)| *n == name) else {
                    return Err(ParseError::new(format!("`csg` has no operand named `{name}`"), span));
                };
                let start = self.scene.objects.len();
                self.object_at(object, Mat4::IDENTITY, depth + 1)?;
                let mut objects: Vec<ObjectDesc> = self.scene.objects.drain(start..).collect();
                match objects.len() {
                    1 => Ok(objects.pop().expect("one")),
                    _ => fork_shapes::csg_object(
                        crate::description::CsgOpDesc::Union,
                        objects.into_iter().map(|o| vec![o]).collect(),
                        span,
                    ),
                }
            }
            Kind::Tuple(items) if items.len() == 3 => {
                let (a, op, b) = (items[0], items[1], items[2]);
                let op_span = self.tree[op].span.clone();
                let op_name = match self.tree[op].kind {
                    Kind::Str => &self.text[op_span.start + 1..op_span.end - 1],
                    _ => self.word(&op_span),
                };
                let op = match op_name {
                    "sub" => crate::description::CsgOpDesc::Difference,
                    "and" => crate::description::CsgOpDesc::Intersection,
                    "or" => crate::description::CsgOpDesc::Union,
                    other => {
                        return Err(ParseError::new(
                            format!("unknown CSG operation `{other}`: the `csg` block knows `sub`, `and` and `or`"),
                            op_span,
                        ))
                    }
                };
                let a = self.csg_operation(a, named, depth + 1)?;
                let b = self.csg_operation(b, named, depth + 1)?;
                fork_shapes::csg_object(op, vec![vec![a], vec![b]], span)
            }
            _ => Err(self.expected("`(\"a\", \"sub\", \"b\")` or an operand's name", id)),
        }
    }

    /// The numbers of a transform tuple and its last element (the child object).
    fn args(&self, tuple: usize, name: &str, usage: &str, counts: &[usize]) -> Result<(Vec<f32>, usize), ParseError> {
        let usage_error = || self.expected(&format!("`{name}` with {usage}"), tuple);
        let Kind::Tuple(items) = &self.tree[tuple].kind else {
            return Err(usage_error());
        };
        let Some((&obj, numbers)) = items.split_last() else {
            return Err(usage_error());
        };
        if !counts.contains(&numbers.len()) {
            return Err(usage_error());
        }
        let args = numbers
            .iter()
            .map(|&n| self.number(n, &format!("in `{name}`")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((args, obj))
    }

    fn primitive(&mut self, kind: &str, head: Span, id: usize, world: Mat4) -> Result<(), ParseError> {
        let mut material = None;
        let (mut height, mut bottom, mut top, mut capped) = (1.0f32, 1.0f32, 0.0f32, true);
        // The HKUST 2019 fork's torus: `a` = 1 and `b` = 0.2 unless given.
        let (mut major, mut minor) = (1.0f32, 0.2f32);
        let mut blobs = MetaballFields::default();
        let blobby = kind.starts_with("metaball");
        let mut mesh = MeshInput::default();
        let is_mesh = kind == "trimesh" || kind == "polymesh";
        let mut coefficients = quadric::named(kind);
        for (key, value) in self.entries(id, kind)? {
            let word = self.word(&key);
            match word {
                "material" => material = Some(self.material_value(value)?),
                "name" => {}
                "balls" | "ball" if blobby => {
                    let mut balls = Vec::new();
                    for item in self.list(value, word)? {
                        let values = match &self.tree[item].kind {
                            Kind::Tuple(items) if (3..=4).contains(&items.len()) => items
                                .iter()
                                .map(|&n| self.number(n, "in a ball"))
                                .collect::<Result<Vec<f32>, ParseError>>()?,
                            _ => return Err(self.expected("a ball `(x, y, z)` or `(x, y, z, radius)`", item)),
                        };
                        balls.push((Vec3::new(values[0], values[1], values[2]), values.get(3).copied()));
                    }
                    blobs.balls(balls, self.tree[value].span.clone())?;
                }
                "radius" | "size" | "threshold" | "blend" if blobby => {
                    let number = self.number(value, &format!("for `{word}`"))?;
                    blobs.number(word, number, key.start..self.tree[value].span.end)?;
                }
                "a" | "b" | "major_radius" | "minor_radius" if kind == "torus" => {
                    let node = value;
                    let value = self.number(node, &format!("for `{word}`"))?;
                    if !(value > 0.0 && value.is_finite()) {
                        return Err(ParseError::new(
                            format!("a torus radius must be positive, not {value}"),
                            self.tree[node].span.clone(),
                        ));
                    }
                    if matches!(word, "a" | "major_radius") {
                        major = value;
                    } else {
                        minor = value;
                    }
                }
                "height" | "bottom_radius" | "top_radius" | "capped" if kind == "cone" => match word {
                    "height" => height = self.number(value, "for `height`")?,
                    "bottom_radius" => bottom = self.number(value, "for `bottom_radius`")?.abs(),
                    "top_radius" => top = self.number(value, "for `top_radius`")?.abs(),
                    _ => capped = self.boolean(value, "for `capped`")?,
                },
                "points" | "normals" if is_mesh => {
                    let mut list = Vec::new();
                    for item in self.list(value, word)? {
                        list.push(self.vec3(item, &format!("in `{word}`"))?);
                    }
                    if word == "points" {
                        mesh.points = list;
                    } else {
                        mesh.normals = Some((list, self.tree[value].span.clone()));
                    }
                }
                "faces" if is_mesh => {
                    mesh.face_indices.clear();
                    mesh.faces.clear();
                    for face in self.list(value, word)? {
                        let first = mesh.face_indices.len();
                        for index in self.list(face, "a face")? {
                            match self.tree[index].kind {
                                Kind::Number(v) => mesh.face_indices.push(v),
                                _ => return Err(self.expected("a vertex index", index)),
                            }
                        }
                        mesh.faces
                            .push((first..mesh.face_indices.len(), self.tree[face].span.clone()));
                    }
                }
                "materials" if is_mesh => {
                    let mut list = Vec::new();
                    for item in self.list(value, word)? {
                        list.push(self.material_value(item)?);
                    }
                    mesh.materials = Some((list, self.tree[value].span.clone()));
                }
                "gennormals" if is_mesh => mesh.gennormals = self.boolean(value, "for `gennormals`")?,
                "points" if kind == "quadric" => {
                    let mut pairs = Vec::new();
                    for item in self.list(value, word)? {
                        pairs.push(self.tuple::<2>(item, "in the quadric's `points`")?);
                    }
                    coefficients = Some(quadric::from_pairs(&pairs).ok_or_else(|| {
                        ParseError::new(
                            format!(
                                "a quadric's `points` are its ten coefficients A…J as five pairs ((A, B), (C, D), (E, F), (G, H), (I, J)), not {} pairs",
                                pairs.len()
                            ),
                            self.tree[value].span.clone(),
                        )
                    })?);
                }
                _ => self.ignore_key(&key, kind)?,
            }
        }
        let shape = match kind {
            "sphere" => ShapeDesc::Sphere,
            "box" => ShapeDesc::Box,
            "square" => ShapeDesc::Square,
            "cylinder" => ShapeDesc::Cylinder { capped: true },
            "torus" => ShapeDesc::Torus {
                major_radius: major,
                minor_radius: minor,
            },
            "metaballs" | "metaball" => {
                let block = head.start..self.tree[id].span.end;
                match blobs.finish(kind, &block, &mut self.scene.warnings)? {
                    Some(shape) => shape,
                    None => return Ok(()),
                }
            }
            _ if coefficients.is_some() => {
                let block = head.start..self.tree[id].span.end;
                match quadric::tessellate(&coefficients.expect("a quadric")) {
                    Some(mesh) => ShapeDesc::Trimesh(Box::new(mesh)),
                    None => {
                        self.scene.warnings.push((
                            format!("the `{kind}` has no surface inside the cube [-1, 1]³ it is bounded by; nothing is drawn"),
                            block,
                        ));
                        return Ok(());
                    }
                }
            }
            "cone" => ShapeDesc::Cone {
                height,
                bottom_radius: bottom,
                top_radius: top,
                capped,
            },
            _ => {
                let block = head.start..self.tree[id].span.end;
                match trimesh::finish(mesh, &block, &mut self.scene.warnings)? {
                    Some(desc) => ShapeDesc::Trimesh(Box::new(desc)),
                    None => return Ok(()),
                }
            }
        };
        let material = match material {
            Some(material) => material,
            None if is_mesh => MaterialDesc::default(),
            None => {
                return Err(ParseError::new(
                    format!("`{kind}` needs a `material` in this dialect"),
                    head,
                ))
            }
        };
        self.scene.objects.push(ObjectDesc {
            shape,
            world_from_object: world,
            material,
            span: head,
        });
        Ok(())
    }

    /// The items of a tuple node.
    fn list(&self, id: usize, what: &str) -> Result<Vec<usize>, ParseError> {
        match &self.tree[id].kind {
            Kind::Tuple(items) => Ok(items.clone()),
            _ => Err(self.expected(&format!("a `( … )` list for `{what}`"), id)),
        }
    }
}
