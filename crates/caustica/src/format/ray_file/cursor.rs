//! A read position in a token list, with the "expected …, found …" error helpers both parsers use.

use super::ast::Span;
use super::lexer::{Tok, Token};
use crate::progress::Progress;
use crate::ParseError;
use std::cell::Cell;

/// Bytes of the file between two reports of the parse position.
const REPORT_STEP: usize = 1 << 16;

/// How far parsing got, in bytes of the file, for a progress bar. Detection may read the file
/// twice: the second reading moves the bar only once it passes the furthest point.
pub(crate) struct Reach<'p> {
    progress: &'p dyn Progress,
    furthest: Cell<usize>,
}

impl<'p> Reach<'p> {
    pub fn new(progress: &'p dyn Progress) -> Reach<'p> {
        Reach {
            progress,
            furthest: Cell::new(0),
        }
    }

    pub fn reached(&self, offset: usize) {
        let furthest = self.furthest.get();
        if offset > furthest {
            self.progress.advance((offset - furthest) as u64);
            self.furthest.set(offset);
        }
    }
}

/// How a punctuation token is written.
pub(crate) fn punct(tok: Tok) -> &'static str {
    match tok {
        Tok::LParen => "`(`",
        Tok::RParen => "`)`",
        Tok::LBrace => "`{`",
        Tok::RBrace => "`}`",
        Tok::Comma => "`,`",
        Tok::Equals => "`=`",
        Tok::Semicolon => "`;`",
        Tok::Word => "a word",
        Tok::Quoted => "a string",
        Tok::Number(_) => "a number",
        Tok::Eof => "the end of the file",
    }
}

/// Tokens of one file and the position of the next one.
pub(crate) struct Cursor<'a> {
    /// The scene text the spans point into.
    pub text: &'a str,
    tokens: Vec<Token>,
    pos: usize,
    reach: &'a Reach<'a>,
    /// The byte offset past which the position is reported next.
    next_report: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor at the first token; `tokens` must end with [`Tok::Eof`].
    pub fn new(text: &'a str, tokens: Vec<Token>, reach: &'a Reach<'a>) -> Cursor<'a> {
        Cursor {
            text,
            tokens,
            pos: 0,
            reach,
            next_report: REPORT_STEP,
        }
    }

    /// The next token, without consuming it.
    pub fn peek(&self) -> &Token {
        self.peek_at(0)
    }

    /// The token `n` places ahead (the end-of-file token past the end).
    pub fn peek_at(&self, n: usize) -> &Token {
        let last = self.tokens.len().saturating_sub(1);
        &self.tokens[(self.pos + n).min(last)]
    }

    /// Consumes and returns the next token (the end-of-file token repeats forever).
    pub fn next(&mut self) -> Token {
        let token = self.peek().clone();
        if token.span.start >= self.next_report {
            self.report(token.span.start);
        }
        if self.pos + 1 < self.tokens.len() {
            self.pos += 1;
        }
        token
    }

    #[cold]
    fn report(&mut self, offset: usize) {
        self.reach.reached(offset);
        self.next_report = offset + REPORT_STEP;
    }

    /// The end of the previously consumed token.
    pub fn prev_end(&self) -> usize {
        self.pos.checked_sub(1).map_or(0, |p| self.tokens[p].span.end)
    }

    /// The text of a token.
    pub fn text_of(&self, token: &Token) -> &'a str {
        token.text(self.text)
    }

    /// Whether the next token is the word `word`.
    pub fn at_word(&self, word: &str) -> bool {
        self.peek().is_word(self.text, word)
    }

    /// Consumes the next token if it is `tok`.
    pub fn eat(&mut self, tok: Tok) -> bool {
        if self.peek().tok == tok {
            self.next();
            true
        } else {
            false
        }
    }

    /// An error at the next token: "expected {what}, found {it}".
    pub fn unexpected(&self, what: &str) -> ParseError {
        let token = self.peek();
        ParseError::new(
            format!("expected {what}, found {}", token.describe(self.text)),
            token.span.clone(),
        )
    }

    /// Consumes the punctuation `tok` or fails with "expected `tok` {context}, found …".
    pub fn expect(&mut self, tok: Tok, context: &str) -> Result<Token, ParseError> {
        if self.peek().tok == tok {
            Ok(self.next())
        } else {
            Err(self.unexpected(&format!("{} {context}", punct(tok))))
        }
    }

    /// Consumes a number at full precision (face indices) or fails like [`Cursor::number`].
    pub fn number_f64(&mut self, context: &str) -> Result<f64, ParseError> {
        match self.peek().tok {
            Tok::Number(v) => {
                self.next();
                Ok(v)
            }
            _ => Err(self.unexpected(&format!("a number {context}"))),
        }
    }

    /// Consumes a number or fails with "expected a number {context}, found …".
    pub fn number(&mut self, context: &str) -> Result<(f32, Span), ParseError> {
        match self.peek().tok {
            Tok::Number(v) => Ok((v as f32, self.next().span)),
            _ => Err(self.unexpected(&format!("a number {context}"))),
        }
    }
}
