//! Errors of the library: scene-file errors carry a source span; everything else a plain message.

/// A byte range into a scene file's text.
pub type Span = std::ops::Range<usize>;
use std::path::PathBuf;

/// A syntax or content error in a scene file, located by a byte span.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ParseError {
    /// What is wrong, and what was expected.
    pub message: String,
    /// Where in the file.
    pub span: Span,
    /// A suggestion, e.g. the nearest keyword for a misspelling.
    pub help: Option<String>,
}

impl ParseError {
    /// An error at `span` without a suggestion.
    pub fn new(message: impl Into<String>, span: Span) -> ParseError {
        ParseError {
            message: message.into(),
            span,
            help: None,
        }
    }

    /// The same error with a suggestion.
    pub fn with_help(mut self, help: impl Into<String>) -> ParseError {
        self.help = Some(help.into());
        self
    }
}

/// 1-based line and column (in characters) of a byte offset in `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..floor_char_boundary(text, offset)];
    // Lines end at LF, CR LF or a lone CR (old Mac files).
    let bytes = before.as_bytes();
    let mut line = 1;
    let mut line_start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        let ends = b == b'\n' || (b == b'\r' && text.as_bytes().get(i + 1) != Some(&b'\n'));
        if ends {
            line += 1;
            line_start = i + 1;
        }
    }
    let col = before[line_start..].chars().count() + 1;
    (line, col)
}

fn floor_char_boundary(text: &str, mut offset: usize) -> usize {
    while offset > 0 && !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// Any failure of the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file is malformed; `text` is its content, for diagnostics.
    #[error("{path}:{line}:{col}: {error}", path = path.display(), line = line_col(text, error.span.start).0, col = line_col(text, error.span.start).1)]
    Scene {
        /// The file.
        path: PathBuf,
        /// Its text.
        text: String,
        /// What is wrong and where.
        error: ParseError,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}", path = path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// An image could not be decoded or encoded.
    #[error("{path}: {message}", path = path.display())]
    Image {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// A setting is out of range or contradicts another.
    #[error("{0}")]
    InvalidSettings(String),
    /// The render was interrupted before anything could be saved.
    #[error("interrupted")]
    Interrupted,
}

impl Error {
    /// Whether the error is the user's input (exit code 2) rather than an internal failure.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            Error::Scene { .. } | Error::InvalidSettings(_) | Error::Image { .. } | Error::Io { .. }
        )
    }
}

/// Result with the library's error.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_are_one_based() {
        let text = "ab\ncdé\nx";
        assert_eq!(line_col(text, 0), (1, 1));
        assert_eq!(line_col(text, 3), (2, 1));
        assert_eq!(line_col(text, text.find('x').unwrap()), (3, 1));
        assert_eq!(line_col(text, 5), (2, 3));
    }

    #[test]
    fn a_lone_cr_ends_a_line_and_cr_lf_ends_one() {
        let text = "ab\rcd\r\nx";
        assert_eq!(line_col(text, 3), (2, 1));
        assert_eq!(line_col(text, text.find('x').unwrap()), (3, 1));
    }
}
