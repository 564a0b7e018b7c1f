//! The SBT-raytracer `.ray` format (placeholder until the reader lands).
#![allow(missing_docs)]
pub mod ast;

#[derive(Clone, Debug, Default)]
pub struct ParseOptions {
    pub dialect: Option<ast::Dialect>,
}

pub fn parse(_text: &str, _scene_dir: &std::path::Path, _options: &ParseOptions) -> Result<ast::SceneDescription, crate::ParseError> {
    Err(crate::ParseError::new("not yet", 0..0))
}
