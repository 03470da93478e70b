//! Expression trees of the model file to symbolica expressions.
//!
//! Nothing of the model reaches symbolica as text: symbolica gives some bare
//! names meanings of its own (`euler_e` is its e, `coeff` and `der` are its
//! functions), so every model name becomes a symbol in a namespace of ours
//! ([`Namespace`]), and π and e are symbols of ours that the evaluation pass turns
//! into their values. `tan` is built as sin/cos and `sqrt` as a power ½, so
//! derivatives stay within the functions the emitted code evaluates; the
//! functions symbolica lacks (atan, asin, acos, sinh, cosh, tanh) are
//! functions of ours whose derivatives [`Differentiate::d`] writes out. Each
//! division, logarithm and root is checked on the way: an expression that
//! is undefined everywhere (`1/0`, `y/(x - x)`, `log(0)`, `sqrt(-1)`) is
//! reported at its place instead of reaching later passes as infinity.

use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::Range;

use symbolica::prelude::*;

use crate::function::Algebra;
use crate::ir::{Constant, Function, Node, NodeKind, Rational};

thread_local! {
    /// The namespace of the symbols made now (see [`Namespace`]).
    static NAMESPACE: RefCell<String> = RefCell::new("dalembert".into());
}

/// The namespace every symbol of one derivation is made in, for as long as
/// the value lives: `dalembert_` and a hash of the model file's text.
///
/// symbolica orders the terms of an expression, and so the instructions of
/// the emitted programs, by when their symbols were made. Symbols made by an
/// earlier derivation in the same process would otherwise make the
/// generated code depend on what else the process derived before (a build
/// script deriving every model, the CLI deriving one). In its own namespace
/// a model's symbols are made fresh, in the same order every time; the same
/// text derived again in one process meets the symbols its first derivation
/// made, in that same order.
pub struct Namespace {
    previous: String,
}

impl Namespace {
    /// Enters the namespace of the model file with text `source`.
    pub fn enter(source: &str) -> Self {
        // FNV-1a: stable across processes and Rust versions.
        let hash = source.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        let previous = NAMESPACE.with(|n| n.replace(format!("dalembert_{hash:016x}")));
        Self { previous }
    }
}

impl Drop for Namespace {
    fn drop(&mut self) {
        let previous = std::mem::take(&mut self.previous);
        NAMESPACE.with(|n| *n.borrow_mut() = previous);
    }
}

/// A symbol of ours: `name` in the current namespace.
pub fn own_symbol(name: &str) -> Symbol {
    NAMESPACE.with(|ns| symbol!(format!("{}::{name}", ns.borrow()).as_str()))
}

/// How many places [`make_places`] makes.
const PLACES: usize = 4096;

static MADE_PLACES: std::sync::OnceLock<Vec<Symbol>> = std::sync::OnceLock::new();

/// Makes the first places ([`place`]); called when a process first takes
/// the symbolic engine's lock, before any other symbol of ours is made.
pub fn make_places() {
    MADE_PLACES.get_or_init(|| (0..PLACES).map(made_place).collect());
}

/// The symbol of place `i`: the symbols expressions are written in for the
/// evaluator (`evaluate`, which says why). The first 4096 are made once per
/// process, at the same point in every process, so that they are the same
/// symbols everywhere; a place past them is made when first asked for, and
/// a program that reaches one can depend on what the process made before.
pub fn place(i: usize) -> Symbol {
    match MADE_PLACES.get().and_then(|p| p.get(i)) {
        Some(s) => *s,
        None => made_place(i),
    }
}

fn made_place(i: usize) -> Symbol {
    symbol!(format!("dalembert_places::x{i}").as_str())
}

/// The functions of the language symbolica has, or writes with its own
/// (tan as sin/cos, a root as a power ½): [`applied`] says how.
const NATIVE: [Function; 6] = [
    Function::Sin,
    Function::Cos,
    Function::Tan,
    Function::Exp,
    Function::Log,
    Function::Sqrt,
];

/// The functions of the language symbolica does not have: every other one
/// (atan, asin, acos and the hyperbolic functions and their inverses),
/// each a function of ours.
pub fn own_function_list() -> impl Iterator<Item = Function> {
    Function::ALL.into_iter().filter(|f| !NATIVE.contains(f))
}

/// The symbols of [`own_function_list`] in the current namespace.
pub fn own_functions() -> impl Iterator<Item = Symbol> {
    own_function_list().map(|f| own_symbol(f.name()))
}

/// Differentiation that knows the functions of ours: symbolica leaves
/// their derivatives unevaluated (`der(1, f, z)`), and [`Differentiate::d`]
/// writes each out by its rule.
pub trait Differentiate {
    /// ∂/∂`x`.
    fn d(&self, x: Symbol) -> Atom;
}

impl Differentiate for Atom {
    fn d(&self, x: Symbol) -> Atom {
        let d = self.derivative(x);
        resolved(d.as_view()).unwrap_or(d)
    }
}

/// `a` with every `der(1, f, z)` of a function of ours written out; `None`
/// where it has none.
fn resolved(a: AtomView) -> Option<Atom> {
    let or_same = |x: AtomView| resolved(x).unwrap_or_else(|| x.to_owned());
    match a {
        AtomView::Fun(f) => {
            let args: Vec<AtomView> = f.iter().collect();
            if f.get_symbol().get_stripped_name() == "der"
                && let [n, AtomView::Var(g), z] = args[..]
                && n.to_owned() == Atom::num(1)
                && let Some(rule) =
                    own_function_list().find(|h| own_symbol(h.name()) == g.get_symbol())
            {
                return Some(derivative_rule(rule, or_same(z)));
            }
            let [x] = args[..] else { return None };
            resolved(x).map(|x| function!(f.get_symbol(), x))
        }
        AtomView::Add(s) => {
            let parts: Vec<Option<Atom>> = s.iter().map(resolved).collect();
            if parts.iter().all(Option::is_none) {
                return None;
            }
            Some(s.iter().zip(parts).fold(Atom::num(0), |acc, (x, p)| {
                acc + p.unwrap_or_else(|| x.to_owned())
            }))
        }
        AtomView::Mul(m) => {
            let parts: Vec<Option<Atom>> = m.iter().map(resolved).collect();
            if parts.iter().all(Option::is_none) {
                return None;
            }
            Some(m.iter().zip(parts).fold(Atom::num(1), |acc, (x, p)| {
                acc * p.unwrap_or_else(|| x.to_owned())
            }))
        }
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            match (resolved(b), resolved(e)) {
                (None, None) => None,
                (rb, re) => Some(
                    rb.unwrap_or_else(|| b.to_owned())
                        .pow(re.unwrap_or_else(|| e.to_owned())),
                ),
            }
        }
        _ => None,
    }
}

/// f′(z) for a function of ours, by the language's rule
/// ([`derivative`]).
fn derivative_rule(f: Function, z: Atom) -> Atom {
    let y = applied(f, z.clone());
    let factors = f.derivative(&mut Atoms, z, y);
    factors.into_iter().fold(Atom::num(1), |acc, x| acc * x)
}

/// symbolica's expressions as the function rules' algebra.
pub(super) struct Atoms;

impl Algebra for Atoms {
    type E = Atom;
    fn number(&mut self, num: i64, den: i64) -> Atom {
        Atom::num(num) / Atom::num(den)
    }
    fn add(&mut self, terms: Vec<Atom>) -> Atom {
        terms.into_iter().fold(Atom::num(0), |acc, t| acc + t)
    }
    fn sub(&mut self, a: Atom, b: Atom) -> Atom {
        a - b
    }
    fn mul(&mut self, factors: Vec<Atom>) -> Atom {
        factors.into_iter().fold(Atom::num(1), |acc, f| acc * f)
    }
    fn pow(&mut self, x: Atom, num: i64, den: i64) -> Atom {
        x.pow(Atom::num(num) / Atom::num(den))
    }
    fn call(&mut self, f: Function, x: Atom) -> Atom {
        applied(f, x)
    }
}

/// `f(x)` in symbolica's terms: tan as sin/cos, a root as a power ½, the
/// functions symbolica lacks as functions of ours.
fn applied(f: Function, x: Atom) -> Atom {
    match f {
        Function::Sin => function!(Symbol::SIN, x),
        Function::Cos => function!(Symbol::COS, x),
        Function::Tan => function!(Symbol::SIN, x.clone()) / function!(Symbol::COS, x),
        Function::Exp => function!(Symbol::EXP, x),
        Function::Log => function!(Symbol::LOG, x),
        Function::Sqrt => x.pow(Atom::num(1) / Atom::num(2)),
        _ => function!(own_symbol(f.name()), x),
    }
}

/// The symbol of a model name.
pub fn model_symbol(name: &str) -> Symbol {
    own_symbol(name)
}

/// The symbol standing for a constant until evaluation (`e` is reserved in
/// model files and `π` is no identifier, so neither meets a model name).
pub fn constant_symbol(c: Constant) -> Symbol {
    match c {
        Constant::Pi => own_symbol("π"),
        Constant::E => own_symbol("e"),
    }
}

/// Symbolica's own constants replaced by ours: `exp(1)` is normalised to its
/// e, which must reach the emitted code as the number.
pub fn own_constants(a: &Atom) -> Atom {
    a.replace(Atom::from(Symbol::E))
        .with(Atom::from(constant_symbol(Constant::E)))
        .replace(Atom::from(Symbol::PI))
        .with(Atom::from(constant_symbol(Constant::Pi)))
}

/// Why a tree cannot be built, and where (in the expression's text).
#[derive(Debug, Clone, PartialEq)]
pub struct BuildError {
    /// What is undefined.
    pub message: String,
    /// Where.
    pub span: Range<usize>,
}

/// `node` as an expression; a name in `definitions` stands for its
/// expression, any other for its model symbol.
pub fn build(node: &Node, definitions: &HashMap<String, Atom>) -> Result<Atom, BuildError> {
    let fail = |message: &str, span: &Range<usize>| BuildError {
        message: message.to_string(),
        span: span.clone(),
    };
    Ok(match &node.kind {
        NodeKind::Number(r) => number(*r),
        NodeKind::Name(n) => definitions
            .get(n)
            .cloned()
            .unwrap_or_else(|| Atom::from(model_symbol(n))),
        NodeKind::Constant(c) => Atom::from(constant_symbol(*c)),
        NodeKind::Neg(x) => -build(x, definitions)?,
        NodeKind::Sum(terms) => {
            let mut out = Atom::num(0);
            for (minus, t) in terms {
                let t = build(t, definitions)?;
                out = if *minus { out - t } else { out + t };
            }
            out
        }
        NodeKind::Product(factors) => {
            let mut out = Atom::num(1);
            for (divide, f) in factors {
                let x = build(f, definitions)?;
                if *divide {
                    if x.is_zero() {
                        return Err(fail("division by zero (the denominator is 0)", &f.span));
                    }
                    out /= x;
                } else {
                    out *= x;
                }
            }
            out
        }
        NodeKind::Pow(b, n) => {
            let base = build(b, definitions)?;
            if n.num < 0 && base.is_zero() {
                return Err(fail("0 raised to a negative power", &node.span));
            }
            if n.den != 1 && negative_number(&base) {
                return Err(fail(
                    "a fractional power of a negative number is not real",
                    &node.span,
                ));
            }
            base.pow(number(*n))
        }
        NodeKind::Call(f, x) => {
            let arg = build(x, definitions)?;
            match f {
                Function::Log if arg.is_zero() || negative_number(&arg) => {
                    return Err(fail(
                        "the logarithm of a number ≤ 0 is not real",
                        &node.span,
                    ));
                }
                Function::Sqrt if negative_number(&arg) => {
                    return Err(fail(
                        "the square root of a negative number is not real",
                        &node.span,
                    ));
                }
                _ => applied(*f, arg),
            }
        }
    })
}

fn number(r: Rational) -> Atom {
    // Validation keeps both parts within 2⁶⁰.
    Atom::num(r.num as i64) / Atom::num(r.den as i64)
}

/// Whether `a` is a number below zero.
fn negative_number(a: &Atom) -> bool {
    matches!(a.as_view(), AtomView::Num(_)) && *a < Atom::num(0)
}
