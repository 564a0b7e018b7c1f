//! The table of named materials (`name foo;` / `material { name = foo; }`) and lookups into it.

use super::ast::{MaterialDesc, Span};
use super::suggest;
use crate::ParseError;
use std::collections::BTreeMap;

/// Materials registered so far, by name.
#[derive(Debug, Default)]
pub(crate) struct NamedMaterials {
    by_name: BTreeMap<String, MaterialDesc>,
}

impl NamedMaterials {
    /// Registers `material` under `name`; a name can be registered once.
    pub fn register(&mut self, name: &str, material: MaterialDesc, span: &Span) -> Result<(), ParseError> {
        if self.by_name.contains_key(name) {
            return Err(
                ParseError::new(format!("material `{name}` is defined twice"), span.clone())
                    .with_help("give each named material its own name"),
            );
        }
        self.by_name.insert(name.to_string(), material);
        Ok(())
    }

    /// A copy of the material registered under `name`.
    pub fn get(&self, name: &str, span: &Span) -> Result<MaterialDesc, ParseError> {
        if let Some(material) = self.by_name.get(name) {
            return Ok(material.clone());
        }
        let error = ParseError::new(format!("unknown material `{name}`"), span.clone());
        Err(match suggest::nearest(name, self.by_name.keys().map(String::as_str)) {
            Some(near) => error.with_help(suggest::did_you_mean(near)),
            None if self.by_name.is_empty() => error.with_help("no named material is defined before this point"),
            None => error.with_help("a material must be named before it is used"),
        })
    }
}
