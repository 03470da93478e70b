//! The series of the language's functions in the recurrences the
//! transform has: sin and cos of one series as one pair, atan, asin and
//! acos by [`Op::Arc`], sinh, cosh and tanh by exponentials.

use super::{Builder, Op, Series, Summand, Term, constant};
use crate::program::Func;

impl Builder<'_> {
    /// The sine (`sin`) or cosine of series `a`, both made at the first.
    pub(super) fn sin_cos(&mut self, a: Series, sin: bool) -> Series {
        let (s, c) = match self.trig.get(&a) {
            Some(pair) => *pair,
            None => {
                let (sin, cos) = (self.temp(), self.temp());
                self.ops.push(Op::SinCos { sin, cos, a });
                self.trig.insert(a, (sin, cos));
                (sin, cos)
            }
        };
        if sin { s } else { c }
    }

    /// atan, asin or acos of series `a` ([`Op::Arc`]).
    pub(super) fn arc(&mut self, a: Series, f: Func) -> Series {
        let one = Term::Number(constant(&mut self.numbers.consts, 1.0));
        let square = self.times(Term::Series(a), Term::Series(a));
        let w = if f == Func::Atan {
            self.sum(&[one, square])
        } else {
            let minus_one = Term::Number(constant(&mut self.numbers.consts, -1.0));
            let negated = self.times(square, minus_one);
            let Term::Series(rest) = self.sum(&[one, negated]) else {
                unreachable!("a sum with a series is a series")
            };
            Term::Series(self.op(|dst| Op::Sqrt { dst, a: rest }))
        };
        let Term::Series(w) = w else {
            unreachable!("a sum with a series is a series")
        };
        self.op(|dst| Op::Arc {
            dst,
            a,
            w,
            f,
            minus: f == Func::Acos,
        })
    }

    /// sinh, cosh or tanh of series `a`, in exponentials: (eᵃ ∓ 1/eᵃ)/2,
    /// and tanh a = 1 − 2/(e²ᵃ + 1), which stays finite where eᵃ does not.
    pub(super) fn hyperbolic(&mut self, a: Series, f: Func) -> Term {
        let number = |b: &mut Self, x: f64| Term::Number(constant(&mut b.numbers.consts, x));
        if f == Func::Tanh {
            let two = number(self, 2.0);
            let Term::Series(twice) = self.times(Term::Series(a), two) else {
                unreachable!("a series times a number is a series")
            };
            let e = self.op(|dst| Op::Exp { dst, a: twice });
            let one = number(self, 1.0);
            let Term::Series(d) = self.sum(&[Term::Series(e), one]) else {
                unreachable!("a sum with a series is a series")
            };
            let r = self.op(|dst| Op::Recip { dst, a: d });
            let minus_two = number(self, -2.0);
            let scaled = self.times(Term::Series(r), minus_two);
            return self.sum(&[one, scaled]);
        }
        let e = self.op(|dst| Op::Exp { dst, a });
        let r = self.op(|dst| Op::Recip { dst, a: e });
        let both = self.op(|dst| Op::Add {
            dst,
            series: vec![
                Summand {
                    series: e,
                    minus: false,
                },
                Summand {
                    series: r,
                    minus: f == Func::Sinh,
                },
            ],
            numbers: Vec::new(),
        });
        let half = number(self, 0.5);
        self.times(Term::Series(both), half)
    }
}
