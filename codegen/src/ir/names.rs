//! Names and expressions of the model file: each declared name checked and
//! recorded, each expression parsed (unknown names are checked once every
//! declaration is known).

use std::ops::Range;

use toml::Spanned;

use super::expr::{Node, NodeKind, parse};
use super::validate::Validator;
use super::{Expr, Function, RESERVED, RUST_KEYWORDS, Rational};
use crate::diag::ErrorKind;

impl Validator<'_> {
    pub(super) fn declare(&mut self, name: &Spanned<String>, what: &'static str) {
        let n = name.get_ref();
        self.check_ident(n, name.span(), true);
        if let Some(first) = self.names.get(n.as_str()) {
            self.cx.error(
                ErrorKind::Duplicate {
                    name: n.clone(),
                    first,
                },
                Some(name.span()),
            );
        } else {
            self.names.insert(n.clone(), what);
        }
    }

    pub(super) fn check_ident(&mut self, name: &str, span: Range<usize>, symbol: bool) {
        if let Some(why) = ident_problem(name, symbol) {
            self.cx.error(
                ErrorKind::BadName {
                    name: name.to_string(),
                    why,
                },
                Some(span),
            );
        }
    }

    /// Parses an expression; what is malformed is reported at its place.
    /// Unknown names are checked later, once every declaration is known
    /// ([`check_names`](super::check_names)).
    pub(super) fn expr(&mut self, s: &Spanned<String>) -> Expr {
        let text = s.get_ref().clone();
        let base = content_start(self.text, &text, s.span());
        let node = match parse(&text) {
            Ok(node) => node,
            Err(e) => {
                let kind = if e.limit {
                    ErrorKind::Limit(e.message)
                } else {
                    ErrorKind::Syntax(e.message)
                };
                let at = base.map(|b| b + e.span.start..b + e.span.end.max(e.span.start + 1));
                self.cx.error(kind, at.or(Some(s.span())));
                Node {
                    kind: NodeKind::Number(Rational { num: 0, den: 1 }),
                    span: 0..0,
                }
            }
        };
        Expr {
            text,
            span: s.span(),
            base,
            node,
        }
    }
}

/// Why `name` cannot name something of the model (a `symbol` also not a
/// reserved name), if it cannot.
pub(super) fn ident_problem(name: &str, symbol: bool) -> Option<String> {
    if name.is_empty() {
        Some("it is empty".to_string())
    } else if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        Some("a name starts with a letter".into())
    } else if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        Some("a name has only ASCII letters, digits and `_`".into())
    } else if name.ends_with('_') {
        Some("a name may not end with `_`".into())
    } else if name.contains("__") {
        Some("a name may not contain `__`".into())
    } else if RUST_KEYWORDS.contains(&name) {
        Some("it is a Rust keyword".into())
    } else if symbol && (RESERVED.contains(&name) || Function::from_name(name).is_some()) {
        Some("it is reserved (a function, a constant or a name the generated code uses)".into())
    } else {
        None
    }
}

/// Byte offset in the file of the first character of the string's content,
/// when the file's text of the string is its value verbatim (no escapes).
fn content_start(file: &str, text: &str, span: Range<usize>) -> Option<usize> {
    let raw = file.get(span.clone())?;
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
    rest.starts_with(text).then_some(span.start + open)
}
