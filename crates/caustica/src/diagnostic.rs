//! Errors as a person reads them: `file:line:col: message`, a window of the line around the
//! column with a caret under the place, and the help. Everything here is bounded by the window,
//! not by the input: a glTF written on one line of megabytes, or a message quoting a huge token,
//! gives a report of a few lines, and nothing here can fail.

use crate::error::{line_col, Error, Span};
use serde::Serialize;
use std::borrow::Cow;

/// Characters of the line shown before the column.
const BEFORE: usize = 40;
/// Characters of the line shown from the column on.
const AFTER: usize = 60;
/// A message longer than this (in characters) keeps its start and end around an ellipsis.
const MAX_MESSAGE: usize = 400;

/// The place of an error in its file, and the line around it as it is shown.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Excerpt {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// The line, or a window of it with `…` where it was cut; tabs and control characters are
    /// shown as spaces so that the caret lines up.
    pub text: String,
    /// Characters of `text` before the caret.
    pub caret: usize,
    /// How many characters the caret underlines (at least one).
    pub width: usize,
}

impl Excerpt {
    /// The place `span` starts at in `text`, with the window of its line.
    pub fn new(text: &str, span: &Span) -> Excerpt {
        let (line, column) = line_col(text, span.start);
        let start = floor_boundary(text, span.start.min(text.len()));
        let bytes = text.as_bytes();
        let is_end = |b: &u8| *b == b'\n' || *b == b'\r';
        let line_start = bytes[..start].iter().rposition(is_end).map_or(0, |i| i + 1);
        let line_end = bytes[start..].iter().position(is_end).map_or(text.len(), |i| start + i);
        let whole = &text[line_start..line_end];
        // Counted here, not from `column`: at a CR LF's LF the two disagree by the line before.
        let at = text[line_start..start].chars().count();
        let chars = whole.chars().count();
        let (first, last) = if chars <= BEFORE + AFTER {
            (0, chars)
        } else {
            let first = at.saturating_sub(BEFORE);
            (first, (at + AFTER).min(chars))
        };
        let mut shown = String::with_capacity(4 * (last - first) + 6);
        if first > 0 {
            shown.push('…');
        }
        shown.extend(
            whole
                .chars()
                .skip(first)
                .take(last - first)
                .map(|c| if c.is_control() { ' ' } else { c }),
        );
        if last < chars {
            shown.push('…');
        }
        let caret = at - first + usize::from(first > 0);
        let end = floor_boundary(text, span.end.clamp(start, line_end));
        let spanned = text[start..end].chars().count();
        let width = spanned.min(last.saturating_sub(at)).max(1);
        Excerpt {
            line,
            column,
            text: shown,
            caret,
            width,
        }
    }

    /// The excerpt as the lines of a report: a gutter with the line number, the text, the caret.
    pub fn render(&self) -> String {
        let number = self.line.to_string();
        let pad = " ".repeat(number.len());
        format!(
            "{pad} |\n{number} | {}\n{pad} | {}{}",
            self.text,
            " ".repeat(self.caret),
            "^".repeat(self.width)
        )
    }
}

/// An error as data: what `--json` prints and what Python's exceptions carry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostic {
    /// `scene`, `io`, `image`, `settings` or `interrupted`.
    pub kind: &'static str,
    /// The file, where there is one.
    pub path: Option<String>,
    /// What is wrong, shortened if it is very long.
    pub message: String,
    /// A suggestion.
    pub help: Option<String>,
    /// Where in the file, for scene errors.
    pub excerpt: Option<Excerpt>,
}

impl Diagnostic {
    /// The diagnostic of a library error.
    pub fn new(error: &Error) -> Diagnostic {
        let plain = |kind, path: Option<&std::path::Path>, message: String| Diagnostic {
            kind,
            path: path.map(|p| p.display().to_string()),
            message: shorten(&message).into_owned(),
            help: None,
            excerpt: None,
        };
        match error {
            Error::Scene { path, text, error } => Diagnostic {
                kind: "scene",
                path: Some(path.display().to_string()),
                message: shorten(&error.message).into_owned(),
                help: error.help.as_deref().map(|h| shorten(h).into_owned()),
                excerpt: Some(Excerpt::new(text, &error.span)),
            },
            Error::Io { path, source } => plain("io", Some(path), source.to_string()),
            Error::Image { path, message } => plain("image", Some(path), message.clone()),
            Error::InvalidSettings(message) => plain("settings", None, message.clone()),
            Error::Interrupted => plain("interrupted", None, "interrupted".into()),
        }
    }

    /// One line: `file:line:col: message` (or `file: message`, or the message alone).
    pub fn headline(&self) -> String {
        match (&self.path, &self.excerpt) {
            (Some(path), Some(at)) => format!("{path}:{}:{}: {}", at.line, at.column, self.message),
            (Some(path), None) => format!("{path}: {}", self.message),
            (None, _) => self.message.clone(),
        }
    }

    /// The whole report: the headline, the excerpt and the help, one after another.
    pub fn render(&self) -> String {
        let mut out = format!("error: {}", self.headline());
        if let Some(excerpt) = &self.excerpt {
            out.push('\n');
            out.push_str(&excerpt.render());
        }
        if let Some(help) = &self.help {
            out.push_str("\nhelp: ");
            out.push_str(help);
        }
        out
    }
}

/// `message`, or its start and end around `…` when it is longer than a report should quote.
pub fn shorten(message: &str) -> Cow<'_, str> {
    let chars = message.chars().count();
    if chars <= MAX_MESSAGE {
        return Cow::Borrowed(message);
    }
    let keep = MAX_MESSAGE / 2;
    let head: String = message.chars().take(keep).collect();
    let tail: String = message.chars().skip(chars - keep).collect();
    Cow::Owned(format!("{head} … ({} characters left out) … {tail}", chars - 2 * keep))
}

fn floor_boundary(text: &str, mut offset: usize) -> usize {
    while offset > 0 && !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_line_is_shown_whole_with_the_caret_under_the_span() {
        let text = "SBT-raytracer 1.0\nsphere { radius = 2; }\n";
        let at = text.find("radius").unwrap();
        let e = Excerpt::new(text, &(at..at + 6));
        assert_eq!((e.line, e.column), (2, 10));
        assert_eq!(e.text, "sphere { radius = 2; }");
        assert_eq!((e.caret, e.width), (9, 6));
        assert_eq!(e.render(), "  |\n2 | sphere { radius = 2; }\n  |          ^^^^^^");
    }

    #[test]
    fn a_long_line_shows_a_window_around_the_column() {
        // One line of 200,000 characters, the error at column 150,001: past u16's range.
        let mut text = "x".repeat(150_000);
        text.push_str("BAD");
        text.push_str(&"y".repeat(50_000));
        let e = Excerpt::new(&text, &(150_000..150_003));
        assert_eq!((e.line, e.column), (1, 150_001));
        assert_eq!(e.text.chars().count(), 1 + BEFORE + AFTER + 1);
        assert!(e.text.starts_with('…') && e.text.ends_with('…'));
        let under: String = e.text.chars().skip(e.caret).take(e.width).collect();
        assert_eq!(under, "BAD");
        assert!(e.render().lines().all(|l| l.chars().count() < 200));
    }

    #[test]
    fn the_window_holds_at_both_ends_of_a_long_line() {
        let text = "é".repeat(1000);
        let start = Excerpt::new(&text, &(0..2));
        assert_eq!((start.caret, start.width), (0, 1));
        assert!(!start.text.starts_with('…') && start.text.ends_with('…'));
        let end = Excerpt::new(&text, &(text.len()..text.len()));
        assert_eq!(end.column, 1001);
        assert!(end.text.starts_with('…') && !end.text.ends_with('…'));
        assert_eq!(end.caret, end.text.chars().count());
        // A span starting inside a character and past the end is clamped, not a panic.
        let inside = Excerpt::new(&text, &(3..1_000_000));
        assert_eq!(inside.column, 2);
    }

    #[test]
    fn tabs_and_control_characters_keep_the_caret_aligned() {
        let text = "a\tb\u{7}c";
        let e = Excerpt::new(text, &(4..5));
        assert_eq!(e.text, "a b c");
        assert_eq!(e.caret, 4);
    }

    #[test]
    fn a_huge_message_is_shortened_around_an_ellipsis() {
        let message = format!("unknown keyword `{}`", "k".repeat(100_000));
        let short = shorten(&message);
        assert!(short.chars().count() < MAX_MESSAGE + 60);
        assert!(short.starts_with("unknown keyword `k") && short.ends_with("k`"));
        assert_eq!(shorten("fine"), "fine");
    }

    #[test]
    fn a_scene_error_renders_its_location_excerpt_and_help() {
        let error = Error::Scene {
            path: "a.ray".into(),
            text: "SBT-raytracer 1.0\nsphre { }\n".into(),
            error: crate::ParseError::new("unknown keyword `sphre`", 18..23).with_help("did you mean `sphere`?"),
        };
        let report = Diagnostic::new(&error).render();
        assert_eq!(
            report,
            "error: a.ray:2:1: unknown keyword `sphre`\n  |\n2 | sphre { }\n  | ^^^^^\nhelp: did you mean `sphere`?"
        );
    }
}
