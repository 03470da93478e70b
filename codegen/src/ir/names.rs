//! Names and expressions of the model file: each declared name checked and
//! recorded, each expression's tokens checked (unknown names are checked
//! once every declaration is known).

use std::ops::Range;

use toml::Spanned;

use super::lex::{Token, content_start, tokens};
use super::validate::Validator;
use super::{Expr, FUNCTIONS, RESERVED, RUST_KEYWORDS};
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
        let why = if name.is_empty() {
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
        } else if symbol && RESERVED.contains(&name) {
            Some("it is reserved (a function, a constant or a name the generated code uses)".into())
        } else {
            None
        };
        if let Some(why) = why {
            self.cx.error(
                ErrorKind::BadName {
                    name: name.to_string(),
                    why,
                },
                Some(span),
            );
        }
    }

    /// Checks an expression's tokens; unknown names are checked later, once
    /// every declaration is known ([`check_names`]).
    pub(super) fn expr(&mut self, s: &Spanned<String>) -> Expr {
        let expr = Expr {
            text: s.get_ref().clone(),
            span: s.span(),
        };
        let base = content_start(self.text, &expr);
        let mut depth: i64 = 0;
        let mut empty = true;
        for tok in tokens(&expr.text) {
            empty = false;
            let at = |r: &Range<usize>| base.map(|b| b + r.start..b + r.end).or(Some(s.span()));
            match tok {
                Token::Bad(c, r) => {
                    self.cx.error(
                        ErrorKind::Syntax(format!("unexpected character `{c}`")),
                        at(&r),
                    );
                }
                Token::Decimal(t, r) => {
                    self.cx.error(
                        ErrorKind::Syntax(format!(
                            "`{t}` is a decimal number; models are exact: write it as a fraction"
                        )),
                        at(&r),
                    );
                }
                Token::Open => depth += 1,
                Token::Close(r) => {
                    depth -= 1;
                    if depth < 0 {
                        self.cx
                            .error(ErrorKind::Syntax("unmatched `)`".into()), at(&r));
                        depth = 0;
                    }
                }
                Token::Call(n, r) if !FUNCTIONS.contains(&n) => {
                    self.cx.error(
                        ErrorKind::UnknownFunction {
                            name: n.to_string(),
                        },
                        at(&r),
                    );
                }
                _ => {}
            }
        }
        if empty {
            self.cx.error(
                ErrorKind::Syntax("the expression is empty".into()),
                Some(s.span()),
            );
        }
        if depth > 0 {
            self.cx
                .error(ErrorKind::Syntax("unclosed `(`".into()), Some(s.span()));
        }
        expr
    }
}
