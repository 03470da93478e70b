//! The series operations of a Taylor transform ([`Op`]): what each reads
//! and writes, in one place for the passes over them (`negations.rs`,
//! `quotients.rs`) and the back ends.

use super::Series;
use crate::function::Function;
use crate::program::Slot;

/// A term of a sum: a series added, or subtracted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summand {
    pub series: Series,
    pub minus: bool,
}

/// One coefficient of one intermediate series from coefficients of others
/// (`dst` is always a [`Series::Temp`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Op {
    /// Σ ±series, in order, + Σ numbers (the numbers count at order 0
    /// only).
    Add {
        dst: Series,
        series: Vec<Summand>,
        numbers: Vec<Slot>,
    },
    /// a times a number.
    Scale { dst: Series, a: Series, by: Slot },
    /// a·b.
    Mul { dst: Series, a: Series, b: Series },
    /// a².
    Square { dst: Series, a: Series },
    /// 1/a.
    Recip { dst: Series, a: Series },
    /// a/b (a product with a reciprocal, fused: see `quotients.rs`).
    Div { dst: Series, a: Series, b: Series },
    /// √a.
    Sqrt { dst: Series, a: Series },
    /// a^α for a real α.
    Power { dst: Series, a: Series, alpha: f64 },
    /// exp(a).
    Exp { dst: Series, a: Series },
    /// ln(a).
    Log { dst: Series, a: Series },
    /// sin(a) and cos(a) together.
    SinCos { sin: Series, cos: Series, a: Series },
    /// c = f(a) for an arc function, from c′·w = a′ (−a′ when `minus`)
    /// and c₀ = f(a₀): atan with w = 1 + a², asin with w = √(1 − a²),
    /// acos with the same w and `minus`.
    Arc {
        dst: Series,
        a: Series,
        w: Series,
        f: Function,
        minus: bool,
    },
}

impl Op {
    /// The series it reads (its own lower coefficients not counted).
    pub(super) fn reads(&self) -> Vec<Series> {
        match self {
            Op::Add { series, .. } => series.iter().map(|t| t.series).collect(),
            Op::Mul { a, b, .. } | Op::Div { a, b, .. } => vec![*a, *b],
            Op::Arc { a, w, .. } => vec![*a, *w],
            Op::Scale { a, .. }
            | Op::Square { a, .. }
            | Op::Recip { a, .. }
            | Op::Sqrt { a, .. }
            | Op::Power { a, .. }
            | Op::Exp { a, .. }
            | Op::Log { a, .. }
            | Op::SinCos { a, .. } => vec![*a],
        }
    }

    /// Replaces each series it reads or writes by the one `rename` gives.
    pub(super) fn rename(&mut self, r: &impl Fn(Series) -> Series) {
        match self {
            Op::Add { dst, series, .. } => {
                *dst = r(*dst);
                series.iter_mut().for_each(|t| t.series = r(t.series));
            }
            Op::Mul { dst, a, b } | Op::Div { dst, a, b } => {
                (*dst, *a, *b) = (r(*dst), r(*a), r(*b));
            }
            Op::Scale { dst, a, .. }
            | Op::Square { dst, a }
            | Op::Recip { dst, a }
            | Op::Sqrt { dst, a }
            | Op::Power { dst, a, .. }
            | Op::Exp { dst, a }
            | Op::Log { dst, a } => (*dst, *a) = (r(*dst), r(*a)),
            Op::SinCos { sin, cos, a } => (*sin, *cos, *a) = (r(*sin), r(*cos), r(*a)),
            Op::Arc { dst, a, w, .. } => (*dst, *a, *w) = (r(*dst), r(*a), r(*w)),
        }
    }

    /// What it writes (both halves for a sin/cos pair).
    pub fn writes(&self) -> Vec<Series> {
        match self {
            Op::SinCos { sin, cos, .. } => vec![*sin, *cos],
            _ => self.dst().into_iter().collect(),
        }
    }

    /// The one series this op writes; `None` for a sin/cos pair, which
    /// writes two. (No allocation: the interpreter asks at every order.)
    pub fn dst(&self) -> Option<Series> {
        match self {
            Op::SinCos { .. } => None,
            Op::Add { dst, .. }
            | Op::Scale { dst, .. }
            | Op::Mul { dst, .. }
            | Op::Div { dst, .. }
            | Op::Square { dst, .. }
            | Op::Recip { dst, .. }
            | Op::Sqrt { dst, .. }
            | Op::Power { dst, .. }
            | Op::Exp { dst, .. }
            | Op::Log { dst, .. }
            | Op::Arc { dst, .. } => Some(*dst),
        }
    }
}
