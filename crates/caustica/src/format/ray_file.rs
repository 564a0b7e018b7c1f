//! The SBT-raytracer `.ray` format: lexer, both dialects' parsers, and the syntax tree, lowered to the format-neutral description.
//!
//! [`parse`] reads a whole file into an [`ast::RayScene`]; see `docs/scene-format.md`
//! for what is accepted.

pub mod ast;
mod cursor;
mod detect;
mod dictionary_dialect;
mod fork_lights;
mod fork_shapes;
mod keywords;
mod lexer;
mod named_materials;
mod quadric;
mod skybox;
mod suggest;
mod tokenizer_dialect;
mod transform_stack;
mod trimesh;

#[cfg(test)]
mod fork_tests;
#[cfg(test)]
mod tests;

use crate::progress::{NoProgress, Progress};
use crate::ParseError;
use std::path::Path;

/// `param` as read, unless it maps an image file that does not exist: then mid grey, with a
/// located warning, as a missing image reads in the other formats. An image that exists but
/// cannot be decoded is still refused when the scene is built.
fn present_or_grey(param: ast::Param, warnings: &mut Vec<(String, ast::Span)>) -> ast::Param {
    if let ast::Param::Texture(map) = &param {
        if let crate::description::ImageSource::File(path) = &map.source {
            if !path.is_file() {
                warnings.push((super::missing_image(path), map.span.clone()));
                return ast::Param::grey(0.5);
            }
        }
    }
    param
}

/// Options for reading a scene file.
#[derive(Clone, Debug, Default)]
pub struct ParseOptions {
    /// The dialect to read; `None` detects it from the file.
    pub dialect: Option<ast::Dialect>,
}

/// Parses a whole `.ray` file; `scene_dir` resolves `map("file")` paths (images are not loaded).
pub fn parse(text: &str, scene_dir: &Path, options: &ParseOptions) -> Result<ast::RayScene, ParseError> {
    parse_reporting(text, scene_dir, options, &NoProgress)
}

/// [`parse`], reporting a "parse" phase in bytes of `text` read by the parser (lexing comes
/// first and is not counted), every 64 kB and at the end.
pub fn parse_reporting(
    text: &str,
    scene_dir: &Path,
    options: &ParseOptions,
    progress: &dyn Progress,
) -> Result<ast::RayScene, ParseError> {
    progress.start("parse", text.len() as u64);
    let reach = cursor::Reach::new(progress);
    let result = match options.dialect {
        Some(ast::Dialect::Tokenizer) => tokenizer_dialect::parse(text, scene_dir, &reach),
        Some(dialect @ (ast::Dialect::Dictionary | ast::Dialect::Hkust)) => {
            dictionary_dialect::parse(text, scene_dir, &reach, dialect)
        }
        None => detect::parse_auto(text, scene_dir, &reach),
    };
    if result.is_ok() {
        reach.reached(text.len());
    }
    progress.finish();
    result
}
