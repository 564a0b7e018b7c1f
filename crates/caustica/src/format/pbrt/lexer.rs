//! pbrt-v4's tokens: quoted strings (with escapes), `[` and `]`, and bare words (directive
//! names, numbers, `true`/`false`); `#` comments run to the end of the line.

use crate::error::{ParseError, Span};

/// A token's kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A quoted string; `text` holds it decoded.
    Str,
    /// A bare word.
    Word,
    /// `[`
    Open,
    /// `]`
    Close,
}

/// A token with its span in the scene's span space.
#[derive(Clone, Debug)]
pub struct Token {
    /// What it is.
    pub kind: Kind,
    /// The word, or the decoded string.
    pub text: String,
    /// Where it is.
    pub span: Span,
}

/// The tokens of one file.
pub struct Lexer {
    text: String,
    base: usize,
    pos: usize,
}

impl Lexer {
    /// A lexer over `text`, which starts at `base` in the span space.
    pub fn new(text: String, base: usize) -> Lexer {
        Lexer { text, base, pos: 0 }
    }

    /// Where the file ends.
    pub fn end_span(&self) -> Span {
        self.base + self.text.len()..self.base + self.text.len()
    }

    /// The next token, `None` at the end of the file.
    pub fn next(&mut self) -> Result<Option<Token>, ParseError> {
        let bytes = self.text.as_bytes();
        loop {
            while self.pos < bytes.len() && matches!(bytes[self.pos], b' ' | b'\n' | b'\t' | b'\r') {
                self.pos += 1;
            }
            if self.pos < bytes.len() && bytes[self.pos] == b'#' {
                while self.pos < bytes.len() && bytes[self.pos] != b'\n' && bytes[self.pos] != b'\r' {
                    self.pos += 1;
                }
                continue;
            }
            break;
        }
        if self.pos >= bytes.len() {
            return Ok(None);
        }
        let start = self.pos;
        let span = |end: usize| self.base + start..self.base + end;
        match bytes[start] {
            b'[' | b']' => {
                self.pos += 1;
                Ok(Some(Token {
                    kind: if bytes[start] == b'[' { Kind::Open } else { Kind::Close },
                    text: String::new(),
                    span: span(self.pos),
                }))
            }
            b'"' => {
                let mut out = String::new();
                let mut i = start + 1;
                loop {
                    let Some(c) = self.text[i..].chars().next() else {
                        return Err(ParseError::new("this string is not closed", span(start + 1)));
                    };
                    match c {
                        '"' => {
                            i += 1;
                            break;
                        }
                        '\n' | '\r' => {
                            return Err(ParseError::new(
                                "this string runs to the end of the line: close it with `\"`",
                                span(i),
                            ))
                        }
                        '\\' => {
                            let escaped = self.text[i + 1..].chars().next();
                            let decoded = match escaped {
                                Some('b') => '\u{8}',
                                Some('f') => '\u{c}',
                                Some('n') => '\n',
                                Some('r') => '\r',
                                Some('t') => '\t',
                                Some(c @ ('\\' | '\'' | '"')) => c,
                                _ => {
                                    return Err(ParseError::new(
                                        "unknown escape in a string (\\b \\f \\n \\r \\t \\\\ \\' \\\" are known)",
                                        span(i + 1 + escaped.map_or(0, char::len_utf8)),
                                    ))
                                }
                            };
                            out.push(decoded);
                            i += 1 + escaped.map_or(0, char::len_utf8);
                        }
                        c => {
                            out.push(c);
                            i += c.len_utf8();
                        }
                    }
                }
                self.pos = i;
                Ok(Some(Token {
                    kind: Kind::Str,
                    text: out,
                    span: span(i),
                }))
            }
            _ => {
                let mut i = start;
                while i < bytes.len() && !matches!(bytes[i], b' ' | b'\n' | b'\t' | b'\r' | b'"' | b'[' | b']' | b'#') {
                    i += 1;
                }
                // Stop on a character boundary (a stray multi-byte character is its own word).
                while !self.text.is_char_boundary(i) {
                    i += 1;
                }
                self.pos = i;
                Ok(Some(Token {
                    kind: Kind::Word,
                    text: self.text[start..i].to_string(),
                    span: span(i),
                }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Result<Vec<(Kind, String)>, ParseError> {
        let mut lexer = Lexer::new(text.into(), 10);
        let mut out = Vec::new();
        while let Some(t) = lexer.next()? {
            out.push((t.kind, t.text));
        }
        Ok(out)
    }

    #[test]
    fn tokens_brackets_strings_and_comments() {
        let t = all("Shape \"sphere\" \"float radius\" [2]# note\n\"a\\\"b\"[1 -2e3]").unwrap();
        let kinds: Vec<Kind> = t.iter().map(|t| t.0).collect();
        use Kind::*;
        assert_eq!(kinds, [Word, Str, Str, Open, Word, Close, Str, Open, Word, Word, Close]);
        assert_eq!(t[6].1, "a\"b");
        assert_eq!(t[9].1, "-2e3");
        let e = all("Shape \"sph\nere\"").unwrap_err();
        assert!(e.message.contains("end of the line"));
        assert_eq!(e.span.start, 16);
        assert!(all("\"a\\q\"").is_err());
        assert!(all("\"open").is_err());
    }
}
