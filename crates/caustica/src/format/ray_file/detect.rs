//! Choosing the dialect of a file: decisive markers first, then whichever reader accepts it.

use super::ast::{Dialect, RayScene};
use super::cursor::Reach;
use super::dictionary_dialect::{self, IGNORED_KEY};
use super::keywords::{is_extension_error, COLOUR_FIELDS};
use super::lexer::{self, Tok};
use super::tokenizer_dialect;
use crate::ParseError;
use std::path::Path;

/// Counts of constructs that only one dialect accepts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Markers {
    /// Dialect-O-only constructs (top-level `material {`, `quaternion`, `E` exponents, …) and
    /// spellings of the HKUST forks.
    pub dictionary: usize,
    /// Dialect-T-only constructs (`.5` numbers, groups, bare `gennormals;`, top-level `material =`).
    pub tokenizer: usize,
}

/// Scans the file for constructs that decide the dialect; a file that does not lex gives none.
pub(crate) fn markers(text: &str) -> Markers {
    let mut found = Markers::default();
    let Ok(tokens) = lexer::lex(text, Dialect::Dictionary) else {
        return found;
    };
    let mut depth = 0usize;
    for (i, token) in tokens.iter().enumerate() {
        let next = tokens.get(i + 1).map(|t| t.tok);
        let prev = i.checked_sub(1).map(|p| tokens[p].tok);
        let source = &text[token.span.clone()];
        match token.tok {
            Tok::Number(_) => {
                if source.contains(['E', '+']) {
                    found.dictionary += 1;
                }
                if source.starts_with('.') || source.starts_with("-.") {
                    found.tokenizer += 1;
                }
            }
            Tok::Word => match (source, next) {
                // Spellings only HKUST forks use (their spot and Warn lights, metaballs).
                (
                    "quaternion" | "focaldistance" | "central_direction" | "warn_light" | "warn_model_light"
                    | "metaballs",
                    _,
                ) => found.dictionary += 1,
                ("blend", Some(Tok::Equals)) => found.dictionary += 1,
                ("texture", Some(Tok::Equals)) if tokens.get(i + 2).map(|t| t.tok) == Some(Tok::Quoted) => {
                    found.dictionary += 1
                }
                ("quaternian", _) => found.tokenizer += 1,
                ("gennormals", Some(Tok::Equals)) => found.dictionary += 1,
                ("gennormals", Some(Tok::Semicolon)) => found.tokenizer += 1,
                ("material", Some(Tok::LBrace)) if depth == 0 => found.dictionary += 1,
                // The HKUST team fork's CSG block.
                ("csg", Some(Tok::LBrace)) if depth == 0 => found.dictionary += 1,
                ("material", Some(Tok::Equals)) if depth == 0 => found.tokenizer += 1,
                // HKUST textures: `diffuse = "file.bmp"`.
                (field, Some(Tok::Equals))
                    if COLOUR_FIELDS.contains(&field) && tokens.get(i + 2).map(|t| t.tok) == Some(Tok::Quoted) =>
                {
                    found.dictionary += 1
                }
                _ => {}
            },
            Tok::LBrace | Tok::LParen => {
                // A `{` after `)`, `}`, `;` or the header number opens a dialect-T group.
                let group = token.tok == Tok::LBrace
                    && matches!(prev, Some(Tok::RParen | Tok::RBrace | Tok::Semicolon | Tok::Number(_)));
                if group {
                    found.tokenizer += 1;
                }
                depth += 1;
            }
            Tok::RBrace | Tok::RParen => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    found
}

/// Parses `text` in whichever dialect it is written for.
///
/// Dialect T is tried first unless the file has dialect-O markers and no dialect-T ones. When
/// dialect T fails, dialect O is only taken if the file has O markers, or if T stopped at a key
/// that O ignores and that is no misspelling of a known field (e.g. `focaldistance`). When both
/// readers fail, a student-extension error (one used where it cannot be skipped) wins, then the
/// error of the marked dialect, then the one found further into the file (dialect T on a tie).
pub(crate) fn parse_auto(text: &str, scene_dir: &Path, reach: &Reach<'_>) -> Result<RayScene, ParseError> {
    let found = markers(text);
    let o_first = found.dictionary > 0 && found.tokenizer == 0;
    if o_first {
        let o_error = match dictionary_dialect::parse(text, scene_dir, reach, Dialect::Hkust) {
            Ok(scene) => return Ok(scene),
            Err(error) => error,
        };
        let t_error = match tokenizer_dialect::parse(text, scene_dir, reach) {
            Ok(scene) => return Ok(scene),
            Err(error) => error,
        };
        return Err(choose(t_error, o_error, true));
    }
    let t_error = match tokenizer_dialect::parse(text, scene_dir, reach) {
        Ok(scene) => return Ok(scene),
        Err(error) => error,
    };
    match dictionary_dialect::parse(text, scene_dir, reach, Dialect::Hkust) {
        Ok(scene) => {
            // A key close to any keyword of the format is a misspelling in a T file, not an
            // old modeller's extra key: report it rather than reading the file as dialect O.
            let misspelt = text
                .get(t_error.span.clone())
                .is_some_and(|word| super::suggest::nearest(word, super::keywords::RESERVED.iter().copied()).is_some());
            let stopped_at_ignored_key = t_error.help.is_none()
                && !misspelt
                && scene
                    .warnings
                    .iter()
                    .any(|(message, span)| message.starts_with(IGNORED_KEY) && *span == t_error.span);
            if found.dictionary > 0 || stopped_at_ignored_key {
                Ok(scene)
            } else {
                Err(t_error)
            }
        }
        Err(o_error) if found.dictionary > 0 => Err(choose(t_error, o_error, false)),
        Err(_) => Err(t_error),
    }
}

/// The more useful of the two readers' errors.
fn choose(t_error: ParseError, o_error: ParseError, o_marked: bool) -> ParseError {
    // An extension named where neither reader can skip it (as a value) is the best answer.
    let o_wins = is_extension_error(&o_error) || o_marked || o_error.span.start > t_error.span.start;
    if is_extension_error(&t_error) || !o_wins {
        t_error
    } else {
        o_error
    }
}
