//! pbrt-v4 parameter lists: `"type name" value` or `"type name" [ values ]`, looked up by name
//! and type (the last one given wins), each remembered once read so the rest can be reported.

use crate::error::{ParseError, Span};
use glam::Vec3;
use std::cell::Cell;

/// The values of one parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// Numbers.
    Numbers(Vec<f64>),
    /// Quoted strings.
    Strings(Vec<String>),
    /// `true` / `false`.
    Bools(Vec<bool>),
}

/// One parameter.
#[derive(Clone, Debug)]
pub struct Param {
    /// Its type as written (`float`, `rgb`, `point3` …; v3's `point`, `color` … mapped).
    pub ty: String,
    /// Its name.
    pub name: String,
    /// Its values.
    pub values: Values,
    /// From the declaration to the last value.
    pub span: Span,
    used: Cell<bool>,
}

/// A colour-like value: what an `rgb`, `spectrum`, `blackbody`, `float` or `texture`
/// parameter gives.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// Linear RGB.
    Rgb(Vec3),
    /// A named spectrum (`glass-BK7`, `metal-Au-eta` …) or a spectrum file.
    Named(String),
    /// Interleaved (wavelength in nm, value) pairs.
    Sampled(Vec<(f32, f32)>),
    /// A black body of this temperature in kelvin.
    Blackbody(f32),
    /// A named texture.
    Texture(String),
}

/// A parameter list.
#[derive(Clone, Debug, Default)]
pub struct Params {
    list: Vec<Param>,
}

/// Types pbrt-v4 knows, and v3's older names it upgrades.
const TYPES: &[&str] = &[
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal",
    "normal3",
    "bool",
    "string",
    "texture",
    "rgb",
    "spectrum",
    "blackbody",
    "point",
    "vector",
    "color",
];

impl Params {
    /// Adds a parameter from its declaration string and values; the type is checked.
    pub fn push(&mut self, decl: &str, decl_span: &Span, values: Values, span: Span) -> Result<(), ParseError> {
        let mut words = decl.split_ascii_whitespace();
        let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
            return Err(ParseError::new(
                format!("a parameter is declared as \"type name\", not \"{decl}\""),
                decl_span.clone(),
            ));
        };
        if !TYPES.contains(&ty) {
            return Err(ParseError::new(
                format!("unknown parameter type `{ty}`"),
                decl_span.clone(),
            )
            .with_help("types are integer, float, point2, vector2, point3, vector3, normal, bool, string, texture, rgb, spectrum, blackbody"));
        }
        let ty = match ty {
            "point" => "point3",
            "vector" => "vector3",
            "normal3" => "normal",
            "color" => "rgb",
            other => other,
        };
        let expects_strings =
            matches!(ty, "string" | "texture") || (ty == "spectrum" && matches!(values, Values::Strings(_)));
        let ok = match &values {
            Values::Numbers(_) => !expects_strings && ty != "bool",
            Values::Strings(_) => expects_strings,
            Values::Bools(_) => ty == "bool",
        };
        if !ok {
            return Err(ParseError::new(format!("`{ty} {name}` cannot take these values"), span));
        }
        self.list.push(Param {
            ty: ty.to_string(),
            name: name.to_string(),
            values,
            span,
            used: Cell::new(false),
        });
        Ok(())
    }

    /// The last parameter named `name` whose type is one of `types`.
    fn find(&self, name: &str, types: &[&str]) -> Option<&Param> {
        let p = self
            .list
            .iter()
            .rev()
            .find(|p| p.name == name && types.contains(&p.ty.as_str()))?;
        p.used.set(true);
        Some(p)
    }

    /// Where the parameter `name` is, if given.
    pub fn span_of(&self, name: &str) -> Option<Span> {
        self.list.iter().rev().find(|p| p.name == name).map(|p| p.span.clone())
    }

    /// Whether `name` is given, with any type.
    pub fn has(&self, name: &str) -> bool {
        self.list.iter().any(|p| p.name == name)
    }

    fn numbers(&self, name: &str, types: &[&str]) -> Option<(&[f64], &Span)> {
        let p = self.find(name, types)?;
        match &p.values {
            Values::Numbers(v) => Some((v, &p.span)),
            _ => None,
        }
    }

    /// A single float.
    pub fn float(&self, name: &str) -> Result<Option<f32>, ParseError> {
        self.one(name, &["float"]).map(|v| v.map(|v| v as f32))
    }

    /// A float with a default.
    pub fn float_or(&self, name: &str, default: f32) -> Result<f32, ParseError> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    /// A single integer.
    pub fn int(&self, name: &str) -> Result<Option<i64>, ParseError> {
        let Some((v, span)) = self.numbers(name, &["integer"]) else {
            return Ok(None);
        };
        let x = single(v, span, name)?;
        if x.fract() != 0.0 || x.abs() > i32::MAX as f64 {
            return Err(ParseError::new(format!("`{name}` must be an integer"), span.clone()));
        }
        Ok(Some(x as i64))
    }

    fn one(&self, name: &str, types: &[&str]) -> Result<Option<f64>, ParseError> {
        match self.numbers(name, types) {
            Some((v, span)) => single(v, span, name).map(Some),
            None => Ok(None),
        }
    }

    /// A single bool.
    pub fn bool_or(&self, name: &str, default: bool) -> Result<bool, ParseError> {
        let Some(p) = self.find(name, &["bool"]) else {
            return Ok(default);
        };
        match &p.values {
            Values::Bools(b) if b.len() == 1 => Ok(b[0]),
            _ => Err(ParseError::new(
                format!("`{name}` takes one true or false"),
                p.span.clone(),
            )),
        }
    }

    /// A single string.
    pub fn string(&self, name: &str) -> Result<Option<(String, Span)>, ParseError> {
        let Some(p) = self.find(name, &["string"]) else {
            return Ok(None);
        };
        match &p.values {
            Values::Strings(s) if s.len() == 1 => Ok(Some((s[0].clone(), p.span.clone()))),
            _ => Err(ParseError::new(format!("`{name}` takes one string"), p.span.clone())),
        }
    }

    /// Strings.
    pub fn strings(&self, name: &str) -> Option<(Vec<String>, Span)> {
        let p = self.find(name, &["string"])?;
        match &p.values {
            Values::Strings(s) => Some((s.clone(), p.span.clone())),
            _ => None,
        }
    }

    /// A list of numbers of one of `types`, its length a multiple of `arity`.
    pub fn list(&self, name: &str, types: &[&str], arity: usize) -> Result<Option<(Vec<f64>, Span)>, ParseError> {
        let Some((v, span)) = self.numbers(name, types) else {
            return Ok(None);
        };
        if !v.chunks_exact(arity).remainder().is_empty() {
            return Err(ParseError::new(
                format!("`{name}` needs a multiple of {arity} numbers, not {}", v.len()),
                span.clone(),
            ));
        }
        Ok(Some((v.to_vec(), span.clone())))
    }

    /// One 3-vector of one of `types`.
    pub fn vec3(&self, name: &str, types: &[&str]) -> Result<Option<Vec3>, ParseError> {
        let Some((v, span)) = self.numbers(name, types) else {
            return Ok(None);
        };
        if v.len() != 3 {
            return Err(ParseError::new(format!("`{name}` takes 3 numbers"), span.clone()));
        }
        Ok(Some(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)))
    }

    /// A colour-like parameter.
    pub fn spectrum(&self, name: &str) -> Result<Option<(Spectrum, Span)>, ParseError> {
        let Some(p) = self.find(name, &["rgb", "spectrum", "blackbody", "float", "texture"]) else {
            return Ok(None);
        };
        let span = p.span.clone();
        let value = match (&p.values, p.ty.as_str()) {
            (Values::Numbers(v), "rgb") if v.len() == 3 => {
                Spectrum::Rgb(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
            }
            (Values::Numbers(v), "float") if v.len() == 1 => Spectrum::Rgb(Vec3::splat(v[0] as f32)),
            (Values::Numbers(v), "blackbody") if !v.is_empty() => Spectrum::Blackbody(v[0] as f32),
            (Values::Numbers(v), "spectrum") if v.len() >= 2 && v.chunks_exact(2).remainder().is_empty() => {
                let pairs: Vec<(f32, f32)> = v.chunks(2).map(|c| (c[0] as f32, c[1] as f32)).collect();
                if pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
                    return Err(ParseError::new(
                        "a sampled spectrum lists (wavelength, value) pairs with increasing wavelengths",
                        span,
                    ));
                }
                Spectrum::Sampled(pairs)
            }
            (Values::Strings(s), "spectrum") if s.len() == 1 => Spectrum::Named(s[0].clone()),
            (Values::Strings(s), "texture") if s.len() == 1 => Spectrum::Texture(s[0].clone()),
            _ => {
                return Err(ParseError::new(
                    format!("`{} {name}` has the wrong number of values", p.ty),
                    span,
                ))
            }
        };
        Ok(Some((value, span)))
    }

    /// Parameters given but never read, for warnings.
    pub fn unused(&self) -> Vec<(String, Span)> {
        self.list
            .iter()
            .filter(|p| !p.used.get())
            .map(|p| (format!("{} {}", p.ty, p.name), p.span.clone()))
            .collect()
    }
}

fn single(v: &[f64], span: &Span, name: &str) -> Result<f64, ParseError> {
    match v {
        [x] => Ok(*x),
        _ => Err(ParseError::new(
            format!("`{name}` takes one value, not {}", v.len()),
            span.clone(),
        )),
    }
}
