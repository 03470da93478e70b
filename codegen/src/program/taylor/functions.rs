//! The transform's builder as the recurrences the language's series rules
//! are written in (`function`): each operation one op of the transform,
//! sin and cos of one series one pair.

use super::{Builder, Op, Series, Summand, Term, constant};
use crate::function::{Function, Recurrences};

impl Recurrences for Builder<'_> {
    type Series = Series;

    fn sum(&mut self, series: &[Series], numbers: &[f64]) -> Series {
        let mut terms: Vec<Term> = series.iter().map(|s| Term::Series(*s)).collect();
        for x in numbers {
            terms.push(Term::Number(constant(&mut self.numbers.consts, *x)));
        }
        as_series(self.sum(&terms))
    }

    fn difference(&mut self, a: Series, b: Series) -> Series {
        self.op(|dst| Op::Add {
            dst,
            series: vec![
                Summand {
                    series: a,
                    minus: false,
                },
                Summand {
                    series: b,
                    minus: true,
                },
            ],
            numbers: Vec::new(),
        })
    }

    fn product(&mut self, a: Series, b: Series) -> Series {
        as_series(self.times(Term::Series(a), Term::Series(b)))
    }

    fn scale(&mut self, a: Series, x: f64) -> Series {
        let x = Term::Number(constant(&mut self.numbers.consts, x));
        as_series(self.times(Term::Series(a), x))
    }

    fn recip(&mut self, a: Series) -> Series {
        self.op(|dst| Op::Recip { dst, a })
    }

    fn sqrt(&mut self, a: Series) -> Series {
        self.op(|dst| Op::Sqrt { dst, a })
    }

    fn exp(&mut self, a: Series) -> Series {
        self.op(|dst| Op::Exp { dst, a })
    }

    fn log(&mut self, a: Series) -> Series {
        self.op(|dst| Op::Log { dst, a })
    }

    fn sin_cos(&mut self, a: Series) -> (Series, Series) {
        match self.trig.get(&a) {
            Some(pair) => *pair,
            None => {
                let (sin, cos) = (self.temp(), self.temp());
                self.ops.push(Op::SinCos { sin, cos, a });
                self.trig.insert(a, (sin, cos));
                (sin, cos)
            }
        }
    }

    fn arc(&mut self, f: Function, a: Series, w: Series, minus: bool) -> Series {
        self.op(|dst| Op::Arc {
            dst,
            a,
            w,
            f,
            minus,
        })
    }
}

/// A term the builder made from a series.
fn as_series(t: Term) -> Series {
    match t {
        Term::Series(s) => s,
        Term::Number(_) | Term::Negated(_) => unreachable!("an operation on a series is a series"),
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::along_a_line;
    use crate::function::Function;
    use crate::program::{Instr, Program, Slot};

    /// Every function of the language, through its own series rule: the
    /// transform of f(x) along x(t) = x₀ + t/2 against f's values (the
    /// libm function emitted code calls) at a few points of t.
    #[test]
    fn every_function_along_a_line() {
        for f in Function::ALL {
            let x = Slot::Input(1);
            let p = Program {
                inputs: 2,
                consts: vec![],
                instrs: vec![Instr::Fun(Slot::Out(0), f, x)],
                outputs: 1,
            };
            let x0 = if matches!(f, Function::Log | Function::Sqrt | Function::Acosh) {
                1.5
            } else {
                0.3
            };
            let c = along_a_line(&p, x0, 0.5, 30);
            for tau in [0.0, 0.1, -0.2, 0.3] {
                let got = dalembert_runtime::taylor::eval(&c, 30, tau);
                let want = f.value(x0 + 0.5 * tau);
                assert!(
                    (got - want).abs() <= 1e-13 * want.abs().max(1.0),
                    "{}({}): {got} {want}",
                    f.name(),
                    x0 + 0.5 * tau
                );
            }
        }
    }
}
