//! The SBT-raytracer `.ray` format: lexer, both dialects' parsers, and the plain description.
//!
//! [`parse`] reads a whole file into an [`ast::SceneDescription`]; see `docs/scene-format.md`
//! for what is accepted.

pub mod ast;
mod cursor;
mod detect;
mod dictionary_dialect;
mod keywords;
mod lexer;
mod named_materials;
mod suggest;
mod tokenizer_dialect;
mod transform_stack;
mod trimesh;

#[cfg(test)]
mod tests;

use crate::ParseError;
use std::path::Path;

/// Options for reading a scene file.
#[derive(Clone, Debug, Default)]
pub struct ParseOptions {
    /// The dialect to read; `None` detects it from the file.
    pub dialect: Option<ast::Dialect>,
}

/// Parses a whole `.ray` file; `scene_dir` resolves `map("file")` paths (images are not loaded).
pub fn parse(text: &str, scene_dir: &Path, options: &ParseOptions) -> Result<ast::SceneDescription, ParseError> {
    match options.dialect {
        Some(ast::Dialect::Tokenizer) => tokenizer_dialect::parse(text, scene_dir),
        Some(ast::Dialect::Dictionary) => dictionary_dialect::parse(text, scene_dir),
        None => detect::parse_auto(text, scene_dir),
    }
}
