//! The SBT-raytracer `.ray` format: lexer, both dialects' parsers, and the plain description.

pub mod ast;
