//! A small lexer for the expression language, and where an expression's
//! text starts in the file (for errors at the offending character).

use std::ops::Range;

use super::Expr;

/// Byte offset in the file of the first character of the string's content,
/// when the file's text of the string is its value verbatim (no escapes).
pub(super) fn content_start(file: &str, e: &Expr) -> Option<usize> {
    let raw = file.get(e.span.clone())?;
    let (open, rest) = if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
        let rest = &raw[3..];
        let skip = if rest.starts_with("\r\n") {
            2
        } else if rest.starts_with('\n') {
            1
        } else {
            0
        };
        (3 + skip, &rest[skip..])
    } else if raw.starts_with('"') || raw.starts_with('\'') {
        (1, &raw[1..])
    } else {
        return None;
    };
    rest.starts_with(e.text.as_str())
        .then_some(e.span.start + open)
}

#[derive(Debug)]
pub(super) enum Token<'a> {
    Name(&'a str, Range<usize>),
    Call(&'a str, Range<usize>),
    Number,
    Decimal(&'a str, Range<usize>),
    Op,
    Open,
    Close(Range<usize>),
    Bad(char, Range<usize>),
}

/// A small lexer for the expression language: names, calls, integers,
/// + - * / ^ ( ) and white space.
pub(super) fn tokens(s: &str) -> Vec<Token<'_>> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i..].chars().next().unwrap_or(' ');
        let start = i;
        if c.is_ascii_alphabetic() || c == '_' {
            while i < s.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let name = &s[start..i];
            let mut j = i;
            while j < s.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if j < s.len() && b[j] == b'(' {
                out.push(Token::Call(name, start..i));
            } else {
                out.push(Token::Name(name, start..i));
            }
        } else if c.is_ascii_digit() || c == '.' {
            let mut decimal = false;
            while i < s.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                decimal |= b[i] == b'.';
                i += 1;
            }
            if i < s.len() && (b[i] == b'e' || b[i] == b'E') && decimal {
                i += 1;
            }
            if decimal {
                out.push(Token::Decimal(&s[start..i], start..i));
            } else {
                out.push(Token::Number);
            }
        } else {
            i += c.len_utf8();
            out.push(match c {
                '+' | '-' | '*' | '/' | '^' | ',' => Token::Op,
                '(' => Token::Open,
                ')' => Token::Close(start..i),
                c if c.is_whitespace() => continue,
                c => Token::Bad(c, start..i),
            });
        }
    }
    out
}
