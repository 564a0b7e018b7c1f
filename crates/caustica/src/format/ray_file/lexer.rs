//! Splits scene text into tokens; the two dialects differ only in how numbers are written.

use super::ast::{Dialect, Span};
use crate::ParseError;

/// The kind of a token; words and strings keep their text in the source (see [`Token::text`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A keyword or identifier (letters, digits, `_`, `-`; starts with a letter or `_`).
    Word,
    /// A `"quoted"` string; the span includes the quotes.
    Quoted,
    /// A number, already checked to be finite in `f32`.
    Number(f64),
    LParen,
    RParen,
    LBrace,
    RBrace,
    Comma,
    Equals,
    Semicolon,
    /// End of input; its span is empty and sits at the end of the text.
    Eof,
}

/// One token with its byte span.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    /// What it is.
    pub tok: Tok,
    /// Where it is.
    pub span: Span,
}

impl Token {
    /// The token's text; for a quoted string, the text between the quotes.
    pub fn text<'a>(&self, source: &'a str) -> &'a str {
        match self.tok {
            Tok::Quoted => &source[self.span.start + 1..self.span.end - 1],
            _ => &source[self.span.clone()],
        }
    }

    /// Whether this is the word `word` (unquoted: keywords are never quoted).
    pub fn is_word(&self, source: &str, word: &str) -> bool {
        self.tok == Tok::Word && &source[self.span.clone()] == word
    }

    /// A short description for "found …" in error messages.
    pub fn describe(&self, source: &str) -> String {
        match self.tok {
            Tok::Eof => "the end of the file".to_string(),
            Tok::Quoted => format!("string {}", &source[self.span.clone()]),
            _ => format!("`{}`", &source[self.span.clone()]),
        }
    }
}

/// Length in bytes of a UTF-8 byte-order mark at the start of `text`, if any.
pub(crate) fn bom_len(text: &str) -> usize {
    if text.starts_with('\u{feff}') {
        '\u{feff}'.len_utf8()
    } else {
        0
    }
}

/// Splits `text` into tokens, ending with one [`Tok::Eof`].
///
/// Dialect T numbers start with a digit, `-` or `.` and may only use a lower-case `e`; dialect O
/// additionally accepts `E` and a `+` after the exponent letter (the C library reads its numbers).
pub(crate) fn lex(text: &str, dialect: Dialect) -> Result<Vec<Token>, ParseError> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    let mut i = bom_len(text);
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        let punct = match c {
            b'(' => Some(Tok::LParen),
            b')' => Some(Tok::RParen),
            b'{' => Some(Tok::LBrace),
            b'}' => Some(Tok::RBrace),
            b',' => Some(Tok::Comma),
            b'=' => Some(Tok::Equals),
            b';' => Some(Tok::Semicolon),
            _ => None,
        };
        if let Some(tok) = punct {
            tokens.push(Token {
                tok,
                span: start..start + 1,
            });
            i += 1;
            continue;
        }
        match c {
            // C `isspace`: space, tab, LF, VT, FF, CR.
            b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r' => i += 1,
            b'/' => i = skip_comment(text, i)?,
            b'"' => {
                let rest = &bytes[i + 1..];
                // Old Mac files end lines with a lone CR: it ends a string's line too.
                match rest.iter().position(|&b| b == b'"' || b == b'\n' || b == b'\r') {
                    Some(n) if rest[n] == b'"' => {
                        i += n + 2;
                        tokens.push(Token {
                            tok: Tok::Quoted,
                            span: start..i,
                        });
                    }
                    _ => {
                        return Err(ParseError::new(
                            "unterminated string: a `\"` must be closed on the same line",
                            start..start + 1,
                        ))
                    }
                }
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                i += 1;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_' || bytes[i] == b'-') {
                    i += 1;
                }
                tokens.push(Token {
                    tok: Tok::Word,
                    span: start..i,
                });
            }
            b'0'..=b'9' | b'-' | b'.' => {
                i = number_end(bytes, i, dialect);
                let value = parse_number(&text[start..i], start..i)?;
                tokens.push(Token {
                    tok: Tok::Number(value),
                    span: start..i,
                });
            }
            b'+' => {
                let err = ParseError::new("unexpected character `+`", start..start + 1);
                return Err(if dialect == Dialect::Tokenizer {
                    err.with_help("numbers cannot carry a `+` sign in this format; leave it out")
                } else {
                    err
                });
            }
            _ => {
                let ch = text[start..].chars().next().unwrap_or('\u{fffd}');
                return Err(ParseError::new(
                    format!("unexpected character `{}`", ch.escape_debug()),
                    start..start + ch.len_utf8(),
                ));
            }
        }
    }
    tokens.push(Token {
        tok: Tok::Eof,
        span: text.len()..text.len(),
    });
    Ok(tokens)
}

/// Skips a comment starting at the `/` at `i`, returning the index after it.
fn skip_comment(text: &str, i: usize) -> Result<usize, ParseError> {
    let bytes = text.as_bytes();
    match bytes.get(i + 1) {
        // A line ends at LF, CR LF or a lone CR (old Mac files): otherwise the first comment of
        // a CR-only file would swallow the rest of it.
        Some(b'/') => Ok(bytes[i..]
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .map_or(bytes.len(), |n| i + n + 1)),
        Some(b'*') => match text[i + 2..].find("*/") {
            Some(n) => Ok(i + 2 + n + 2),
            None => Err(ParseError::new(
                "unterminated block comment: `/*` has no matching `*/`",
                i..i + 2,
            )),
        },
        _ => Err(ParseError::new(
            "a lone `/` is not allowed; comments start with `//` or `/*`",
            i..i + 1,
        )),
    }
}

/// The end of the number token starting at `i`: greedy over the number characters.
fn number_end(bytes: &[u8], mut i: usize, dialect: Dialect) -> usize {
    let start = i;
    while i < bytes.len() {
        let b = bytes[i];
        let ok = match b {
            b'0'..=b'9' | b'-' | b'.' | b'e' => true,
            b'E' => dialect != Dialect::Tokenizer,
            b'+' => dialect != Dialect::Tokenizer && i > start && matches!(bytes[i - 1], b'e' | b'E'),
            _ => false,
        };
        if !ok {
            break;
        }
        i += 1;
    }
    i
}

/// Reads the whole text of a number token, which must be a well-formed decimal.
///
/// The C readers would silently take the longest valid prefix (`1-2` as 1); a located error is
/// more useful, and no real scene writes such a token.
fn parse_number(text: &str, span: Span) -> Result<f64, ParseError> {
    if !is_decimal(text.as_bytes()) {
        return Err(ParseError::new(format!("malformed number `{text}`"), span));
    }
    let value: f64 = text
        .parse()
        .map_err(|_| ParseError::new(format!("malformed number `{text}`"), span.clone()))?;
    if !value.is_finite() || !(value as f32).is_finite() {
        return Err(ParseError::new(format!("number `{text}` is out of range"), span));
    }
    Ok(value)
}

/// `-?(digits[.digits?] | .digits)([eE][+-]?digits)?`
fn is_decimal(b: &[u8]) -> bool {
    let mut i = 0;
    if b.first() == Some(&b'-') {
        i += 1;
    }
    let int_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i - int_start;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        digits += i - frac_start;
    }
    if digits == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
            i += 1;
        }
        let exp_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == exp_start {
            return false;
        }
    }
    i == b.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str, dialect: Dialect) -> Vec<Tok> {
        lex(text, dialect).expect("lexes").into_iter().map(|t| t.tok).collect()
    }

    fn numbers(text: &str) -> Vec<f64> {
        lex(text, Dialect::Tokenizer)
            .expect("lexes")
            .into_iter()
            .filter_map(|t| match t.tok {
                Tok::Number(v) => Some(v),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn numbers_in_all_course_spellings() {
        assert_eq!(
            numbers(".5 -.3 1e-005 1.4e-05 7 -2. 0.25"),
            vec![0.5, -0.3, 1e-5, 1.4e-5, 7.0, -2.0, 0.25]
        );
    }

    #[test]
    fn upper_case_exponent_splits_in_dialect_t() {
        let tokens = lex("1E5", Dialect::Tokenizer).expect("lexes");
        assert_eq!(tokens[0].tok, Tok::Number(1.0));
        assert_eq!(tokens[1].tok, Tok::Word);
        assert_eq!(tokens[1].text("1E5"), "E5");
        assert_eq!(tokens[1].span, 1..3);
    }

    #[test]
    fn upper_case_exponent_is_a_number_in_dialect_o() {
        assert_eq!(
            kinds("1E5 2.5E-1 3e+2", Dialect::Dictionary),
            vec![Tok::Number(1e5), Tok::Number(0.25), Tok::Number(300.0), Tok::Eof]
        );
    }

    #[test]
    fn plus_sign_is_an_error_with_help() {
        let err = lex("(+1, 2, 3)", Dialect::Tokenizer).expect_err("rejects +");
        assert_eq!(err.span, 1..2);
        assert!(err.message.contains('+'));
        assert!(err.help.is_some());
    }

    #[test]
    fn malformed_and_huge_numbers_are_errors() {
        assert_eq!(lex("1-2", Dialect::Tokenizer).expect_err("malformed").span, 0..3);
        assert!(lex("-", Dialect::Tokenizer).is_err());
        assert!(lex("1.2.3", Dialect::Tokenizer).is_err());
        let err = lex("x 1e999", Dialect::Tokenizer).expect_err("overflow");
        assert_eq!(err.span, 2..7);
        assert!(err.message.contains("out of range"));
        // Finite as f64 but not as f32.
        assert!(lex("1e39", Dialect::Tokenizer).is_err());
    }

    #[test]
    fn comments_are_skipped_and_checked() {
        assert_eq!(
            kinds("a // x ( \n /* y \n ) */ b", Dialect::Tokenizer),
            vec![Tok::Word, Tok::Word, Tok::Eof]
        );
        let err = lex("a /* never closed", Dialect::Tokenizer).expect_err("unterminated");
        assert_eq!(err.span, 2..4);
        assert!(lex("a / b", Dialect::Tokenizer).is_err());
        assert_eq!(kinds("a //", Dialect::Tokenizer), vec![Tok::Word, Tok::Eof]);
    }

    #[test]
    fn a_lone_cr_ends_comments_and_strings_like_lf() {
        for text in ["a // x\rb", "a // x\nb", "a // x\r\nb"] {
            assert_eq!(
                kinds(text, Dialect::Tokenizer),
                vec![Tok::Word, Tok::Word, Tok::Eof],
                "{text:?}"
            );
        }
        assert!(
            lex("\"abc\r\"", Dialect::Dictionary).is_err(),
            "a string ends at a CR line end"
        );
    }

    #[test]
    fn header_word_is_one_token() {
        let text = "SBT-raytracer 1.0";
        let tokens = lex(text, Dialect::Tokenizer).expect("lexes");
        assert_eq!(tokens[0].text(text), "SBT-raytracer");
        assert_eq!(tokens[1].tok, Tok::Number(1.0));
    }

    #[test]
    fn strings_keep_backslashes_and_end_on_the_line() {
        let text = r#"map("a\b // c.png")"#;
        let tokens = lex(text, Dialect::Tokenizer).expect("lexes");
        assert_eq!(tokens[2].tok, Tok::Quoted);
        assert_eq!(tokens[2].text(text), r"a\b // c.png");
        assert!(lex("\"abc\n\"", Dialect::Tokenizer).is_err());
    }

    #[test]
    fn bom_is_skipped_and_odd_characters_are_errors() {
        assert_eq!(kinds("\u{feff}a", Dialect::Tokenizer), vec![Tok::Word, Tok::Eof]);
        let err = lex("a é", Dialect::Tokenizer).expect_err("non-ascii");
        assert_eq!(err.span, 2..4);
        assert!(lex("a # b", Dialect::Tokenizer).is_err());
    }
}
