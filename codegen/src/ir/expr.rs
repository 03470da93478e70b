//! The expression language, parsed to a small tree.
//!
//! Grammar (usual precedence, `^` binds tightest and to the right):
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = "-" unary | "+" unary | power
//! power   = atom ("^" unary)?
//! atom    = number | name | constant | function "(" sum ")" | "(" sum ")"
//! ```
//!
//! Numbers are exact (`3`, `0.25`, `1e-3`). `pi` and `e` are constants.
//! Every later stage walks this tree instead of text, so the limits below
//! bound their work: nesting depth (so no walk can overflow the stack),
//! exponents (constant, and small enough for exact polynomial arithmetic)
//! and the polynomial degree an expression can reach.

use std::ops::Range;

use super::Rational;
use super::number::{checked_add, checked_div, checked_mul, checked_pow, decimal};

/// Deepest nesting of parentheses, calls, signs and powers.
pub const MAX_DEPTH: usize = 64;
/// Largest |n| of an integer exponent.
pub const MAX_EXPONENT: i128 = 100;
/// Largest denominator of a fractional exponent (`x^(1/2)` has 2).
pub const MAX_ROOT: i128 = 12;
/// Largest polynomial degree an expression may reach (after definitions are
/// substituted); exact arithmetic later multiplies degrees, and this keeps it
/// far from the limits of the exact representation.
pub const MAX_DEGREE: u64 = 400;
/// Longest expression, in bytes.
pub const MAX_LEN: usize = 64 * 1024;

pub use crate::function::Function;

/// A constant of the language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Constant {
    /// π
    Pi,
    /// Euler's number e
    E,
}

impl Constant {
    /// Its value.
    pub fn value(self) -> f64 {
        match self {
            Self::Pi => std::f64::consts::PI,
            Self::E => std::f64::consts::E,
        }
    }
}

/// A node of an expression, with its byte range in the expression's text.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// What it is.
    pub kind: NodeKind,
    /// Where it is, relative to the start of the expression's text.
    pub span: Range<usize>,
}

/// The kinds of node.
#[derive(Debug, Clone, PartialEq)]
pub enum NodeKind {
    /// An exact number.
    Number(Rational),
    /// A declared name (checked against the declarations later).
    Name(String),
    /// pi or e.
    Constant(Constant),
    /// A sum of terms, each added (`false`) or subtracted (`true`).
    Sum(Vec<(bool, Node)>),
    /// A product of factors, each multiplied (`false`) or divided by (`true`).
    Product(Vec<(bool, Node)>),
    /// −x.
    Neg(Box<Node>),
    /// A power with a constant exponent.
    Pow(Box<Node>, Rational),
    /// A function call.
    Call(Function, Box<Node>),
}

/// A parse error: what and where (relative to the expression's text).
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    /// What is wrong.
    pub message: String,
    /// Where.
    pub span: Range<usize>,
    /// Whether a limit was exceeded (rather than the text being malformed).
    pub limit: bool,
}

/// Parses `text`.
pub fn parse(text: &str) -> Result<Node, ParseError> {
    if text.len() > MAX_LEN {
        return Err(ParseError {
            message: format!(
                "the expression is {} bytes long; the limit is {MAX_LEN}",
                text.len()
            ),
            span: 0..0,
            limit: true,
        });
    }
    let tokens = lex(text)?;
    let mut p = Parser {
        tokens,
        at: 0,
        depth: 0,
        end: text.len(),
    };
    if p.tokens.is_empty() {
        return Err(p.error("the expression is empty", 0..text.len()));
    }
    let node = p.sum()?;
    match p.peek() {
        None => Ok(node),
        Some((Tok::Close, r)) => Err(p.error("unmatched `)`", r)),
        Some((t, r)) => Err(p.error(&format!("unexpected {}", t.describe()), r)),
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Number(Rational),
    Name(String),
    Op(char),
    Open,
    Close,
    Comma,
}

impl Tok {
    fn describe(&self) -> String {
        match self {
            Tok::Number(_) => "number".into(),
            Tok::Name(n) => format!("name `{n}`"),
            Tok::Op(c) => format!("`{c}`"),
            Tok::Open => "`(`".into(),
            Tok::Close => "`)`".into(),
            Tok::Comma => "`,`".into(),
        }
    }
}

fn lex(s: &str) -> Result<Vec<(Tok, Range<usize>)>, ParseError> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let err = |message: String, span: Range<usize>| ParseError {
        message,
        span,
        limit: false,
    };
    while i < s.len() {
        let c = s[i..].chars().next().unwrap_or(' ');
        let start = i;
        if c.is_ascii_alphabetic() || c == '_' {
            while i < s.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Name(s[start..i].to_string()), start..i));
        } else if c.is_ascii_digit() || c == '.' {
            while i < s.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            // An exponent: 1e-3, 2.5E4 (but not the name `e` after a number).
            if i < s.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < s.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < s.len() && b[j].is_ascii_digit() {
                    while j < s.len() && b[j].is_ascii_digit() {
                        j += 1;
                    }
                    i = j;
                }
            }
            let value = decimal(&s[start..i]).map_err(|why| err(why, start..i))?;
            out.push((Tok::Number(value), start..i));
        } else {
            i += c.len_utf8();
            let tok = match c {
                // As symbolica prints them, so printed expressions read back.
                'π' | '𝜋' => Tok::Name("pi".into()),
                '𝑒' => Tok::Name("e".into()),
                '+' | '-' | '*' | '/' | '^' => Tok::Op(c),
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                c if c.is_whitespace() => continue,
                c => return Err(err(format!("unexpected character `{c}`"), start..i)),
            };
            out.push((tok, start..i));
        }
    }
    Ok(out)
}

struct Parser {
    tokens: Vec<(Tok, Range<usize>)>,
    at: usize,
    depth: usize,
    end: usize,
}

impl Parser {
    fn peek(&self) -> Option<(Tok, Range<usize>)> {
        self.tokens.get(self.at).cloned()
    }

    fn error(&self, message: &str, span: Range<usize>) -> ParseError {
        ParseError {
            message: message.to_string(),
            span,
            limit: false,
        }
    }

    fn here(&self) -> Range<usize> {
        self.peek().map(|(_, r)| r).unwrap_or(self.end..self.end)
    }

    /// Enters one level of nesting.
    fn enter(&mut self) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ParseError {
                message: format!("the expression is nested more than {MAX_DEPTH} levels deep"),
                span: self.here(),
                limit: true,
            });
        }
        Ok(())
    }

    fn op(&mut self, ops: &[char]) -> Option<char> {
        match self.peek() {
            Some((Tok::Op(c), _)) if ops.contains(&c) => {
                self.at += 1;
                Some(c)
            }
            _ => None,
        }
    }

    fn sum(&mut self) -> Result<Node, ParseError> {
        let first = self.product()?;
        let mut terms = vec![(false, first)];
        while let Some(c) = self.op(&['+', '-']) {
            terms.push((c == '-', self.product()?));
        }
        Ok(collect(terms, NodeKind::Sum))
    }

    fn product(&mut self) -> Result<Node, ParseError> {
        let first = self.unary()?;
        let mut factors = vec![(false, first)];
        while let Some(c) = self.op(&['*', '/']) {
            factors.push((c == '/', self.unary()?));
        }
        Ok(collect(factors, NodeKind::Product))
    }

    fn unary(&mut self) -> Result<Node, ParseError> {
        let start = self.here().start;
        if let Some(c) = self.op(&['-', '+']) {
            self.enter()?;
            let inner = self.unary()?;
            self.depth -= 1;
            let span = start..inner.span.end;
            return Ok(if c == '-' {
                Node {
                    kind: NodeKind::Neg(Box::new(inner)),
                    span,
                }
            } else {
                inner
            });
        }
        self.power()
    }

    fn power(&mut self) -> Result<Node, ParseError> {
        let base = self.atom()?;
        if self.op(&['^']).is_none() {
            return Ok(base);
        }
        self.enter()?;
        let exponent = self.unary()?;
        self.depth -= 1;
        let n = exponent_value(&exponent)?;
        let span = base.span.start..exponent.span.end;
        Ok(Node {
            kind: NodeKind::Pow(Box::new(base), n),
            span,
        })
    }

    fn atom(&mut self) -> Result<Node, ParseError> {
        let Some((tok, r)) = self.peek() else {
            return Err(self.error(
                "the expression ends where a value was expected",
                self.here(),
            ));
        };
        self.at += 1;
        let kind = match tok {
            Tok::Number(n) => NodeKind::Number(n),
            Tok::Open => {
                self.enter()?;
                let inner = self.sum()?;
                self.depth -= 1;
                let close = self.expect_close(&r)?;
                return Ok(Node {
                    kind: inner.kind,
                    span: r.start..close.end,
                });
            }
            Tok::Name(name) if matches!(self.peek(), Some((Tok::Open, _))) => {
                return self.call(&name, r);
            }
            Tok::Name(name) => match name.as_str() {
                "pi" => NodeKind::Constant(Constant::Pi),
                "e" => NodeKind::Constant(Constant::E),
                _ if Function::from_name(&name).is_some() => {
                    return Err(
                        self.error(&format!("`{name}` is a function: write `{name}(…)`"), r)
                    );
                }
                _ => NodeKind::Name(name),
            },
            other => {
                return Err(self.error(
                    &format!("unexpected {} where a value was expected", other.describe()),
                    r,
                ));
            }
        };
        Ok(Node { kind, span: r })
    }

    fn call(&mut self, name: &str, r: Range<usize>) -> Result<Node, ParseError> {
        let Some(f) = Function::from_name(name) else {
            return Err(ParseError {
                message: format!(
                    "unknown function `{name}`: models may use {}",
                    Function::listed()
                ),
                span: r,
                limit: false,
            });
        };
        let (_, open) = self.peek().unwrap_or((Tok::Open, r.clone()));
        self.at += 1;
        if matches!(self.peek(), Some((Tok::Close, _))) {
            return Err(self.error(&format!("`{name}` takes one argument"), r));
        }
        self.enter()?;
        let arg = self.sum()?;
        self.depth -= 1;
        if let Some((Tok::Comma, c)) = self.peek() {
            return Err(self.error(&format!("`{name}` takes one argument"), c));
        }
        let close = self.expect_close(&open)?;
        Ok(Node {
            kind: NodeKind::Call(f, Box::new(arg)),
            span: r.start..close.end,
        })
    }

    fn expect_close(&mut self, open: &Range<usize>) -> Result<Range<usize>, ParseError> {
        match self.peek() {
            Some((Tok::Close, r)) => {
                self.at += 1;
                Ok(r)
            }
            Some((t, r)) => Err(self.error(&format!("expected `)`, found {}", t.describe()), r)),
            None => Err(self.error("unclosed `(`", open.clone())),
        }
    }
}

/// A sum or product of one unsigned item is the item itself.
fn collect(mut items: Vec<(bool, Node)>, make: fn(Vec<(bool, Node)>) -> NodeKind) -> Node {
    if items.len() == 1 && !items[0].0 {
        return items.remove(0).1;
    }
    let span = items[0].1.span.start..items[items.len() - 1].1.span.end;
    Node {
        kind: make(items),
        span,
    }
}

/// The value of a constant exponent, within the limits.
fn exponent_value(node: &Node) -> Result<Rational, ParseError> {
    let n = constant_value(node)?;
    let bad = |message: String| ParseError {
        message,
        span: node.span.clone(),
        limit: true,
    };
    if n.den == 1 && n.num.abs() > MAX_EXPONENT {
        return Err(bad(format!(
            "the exponent {n} is too large: at most {MAX_EXPONENT} in size"
        )));
    }
    if n.den > MAX_ROOT || n.num.abs() > MAX_EXPONENT * n.den {
        return Err(bad(format!(
            "the exponent {n} is out of range: fractional exponents p/q need q ≤ {MAX_ROOT} and |p/q| ≤ {MAX_EXPONENT}"
        )));
    }
    Ok(n)
}

/// The exact value of a constant expression (numbers and arithmetic only).
fn constant_value(node: &Node) -> Result<Rational, ParseError> {
    let overflow = || ParseError {
        message: "the exponent's value is too large".into(),
        span: node.span.clone(),
        limit: true,
    };
    match &node.kind {
        NodeKind::Number(n) => Ok(*n),
        NodeKind::Neg(x) => {
            let v = constant_value(x)?;
            checked_mul(v, Rational { num: -1, den: 1 }).ok_or_else(overflow)
        }
        NodeKind::Sum(terms) => terms.iter().try_fold(Rational { num: 0, den: 1 }, |acc, (neg, t)| {
            let v = constant_value(t)?;
            let v = if *neg { Rational { num: -v.num, den: v.den } } else { v };
            checked_add(acc, v).ok_or_else(overflow)
        }),
        NodeKind::Product(factors) => {
            factors
                .iter()
                .try_fold(Rational { num: 1, den: 1 }, |acc, (div, f)| {
                    let v = constant_value(f)?;
                    if *div {
                        if v.num == 0 {
                            return Err(ParseError {
                                message: "division by zero".into(),
                                span: f.span.clone(),
                                limit: false,
                            });
                        }
                        checked_div(acc, v).ok_or_else(overflow)
                    } else {
                        checked_mul(acc, v).ok_or_else(overflow)
                    }
                })
        }
        NodeKind::Pow(base, n) if n.den == 1 => {
            let b = constant_value(base)?;
            if b.num == 0 && n.num < 0 {
                return Err(ParseError {
                    message: "0 raised to a negative power".into(),
                    span: node.span.clone(),
                    limit: false,
                });
            }
            checked_pow(b, n.num).ok_or_else(overflow)
        }
        _ => Err(ParseError {
            message: "an exponent must be a constant number (for a variable exponent y^x write exp(x*log(y)))".into(),
            span: node.span.clone(),
            limit: false,
        }),
    }
}

mod constant;
mod walk;
pub(crate) use walk::multinomial;

#[cfg(test)]
mod tests;
