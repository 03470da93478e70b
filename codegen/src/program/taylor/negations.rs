//! Negations folded into their readers: a series x = −y costs an operation
//! per order (and, where a recurrence reads it, an array of coefficients),
//! though every reader but a few can take y and the sign instead. A sum
//! subtracts y; a product, quotient or reciprocal of y is the negation of
//! the same of y, which its own readers take in turn; a square drops the
//! sign; an output is written negated. Each of these is exact in floating
//! point (negation commutes with rounding), so the coefficients are the
//! same bits. Only the functions that are not odd (√, exp, ln, powers) and
//! sin/cos read the negation itself, made where they need it.

use std::collections::HashMap;

use super::{Op, Series, Summand, Term};
use crate::program::Slot;

/// `ops` with every negation (a scaling by the constant −1, `minus_one`)
/// folded into its readers, and `outputs` with the signs that reach them.
/// New temporaries (negations made for the readers that need them) are
/// numbered after every temporary of `ops`.
pub(super) fn fold(ops: Vec<Op>, outputs: &mut [Term], consts: &[f64], minus_one: Slot) -> Vec<Op> {
    let is_minus_one = |s: &Slot| matches!(s, Slot::Const(i) if consts[*i] == -1.0);
    let mut next = ops
        .iter()
        .flat_map(Op::writes)
        .filter_map(|s| match s {
            Series::Temp(i) => Some(i + 1),
            _ => None,
        })
        .max()
        .unwrap_or(0);
    // For a series read later: the series that holds it, and whether
    // negated.
    let mut held: HashMap<Series, (Series, bool)> = HashMap::new();
    // Negations made where they are needed, by the series negated.
    let mut made: HashMap<Series, Series> = HashMap::new();
    let mut out = Vec::with_capacity(ops.len());
    let look = |held: &HashMap<Series, (Series, bool)>, s: Series| {
        held.get(&s).copied().unwrap_or((s, false))
    };
    // The series itself, from what holds it (a negation made once).
    let mut plain = |s: Series, held: &HashMap<Series, (Series, bool)>, out: &mut Vec<Op>| {
        let (h, negated) = look(held, s);
        if !negated {
            return h;
        }
        *made.entry(h).or_insert_with(|| {
            let dst = Series::Temp(next);
            next += 1;
            out.push(Op::Scale {
                dst,
                a: h,
                by: minus_one,
            });
            dst
        })
    };
    for op in ops {
        match op {
            Op::Scale { dst, a, by } if is_minus_one(&by) => {
                let (h, negated) = look(&held, a);
                held.insert(dst, (h, !negated));
            }
            Op::Scale { dst, a, by } => {
                let (h, negated) = look(&held, a);
                out.push(Op::Scale { dst, a: h, by });
                held.insert(dst, (dst, negated));
            }
            Op::Add {
                dst,
                series,
                numbers,
            } => {
                let series = series
                    .into_iter()
                    .map(|t| {
                        let (h, negated) = look(&held, t.series);
                        Summand {
                            series: h,
                            minus: t.minus != negated,
                        }
                    })
                    .collect();
                out.push(Op::Add {
                    dst,
                    series,
                    numbers,
                });
            }
            Op::Mul { dst, a, b } | Op::Div { dst, a, b } => {
                let ((ha, na), (hb, nb)) = (look(&held, a), look(&held, b));
                out.push(match op {
                    Op::Mul { .. } => Op::Mul { dst, a: ha, b: hb },
                    _ => Op::Div { dst, a: ha, b: hb },
                });
                held.insert(dst, (dst, na != nb));
            }
            Op::Square { dst, a } => {
                let (h, _) = look(&held, a);
                out.push(Op::Square { dst, a: h });
            }
            Op::Recip { dst, a } => {
                let (h, negated) = look(&held, a);
                out.push(Op::Recip { dst, a: h });
                held.insert(dst, (dst, negated));
            }
            // Read as they are (an arc function's w is not odd).
            Op::Arc {
                dst,
                a,
                w,
                f,
                minus,
            } => {
                let (a, w) = (plain(a, &held, &mut out), plain(w, &held, &mut out));
                out.push(Op::Arc {
                    dst,
                    a,
                    w,
                    f,
                    minus,
                });
            }
            // Not odd functions (sin/cos, a pair of an odd and an even
            // one, too): they read the operand itself.
            mut op @ (Op::Sqrt { .. }
            | Op::Power { .. }
            | Op::Exp { .. }
            | Op::Log { .. }
            | Op::SinCos { .. }) => {
                let &[a] = op.reads().as_slice() else {
                    unreachable!("one operand")
                };
                let a_plain = plain(a, &held, &mut out);
                op.rename(&|s| if s == a { a_plain } else { s });
                out.push(op);
            }
        }
    }
    for t in outputs.iter_mut() {
        if let Term::Series(s) = *t {
            *t = match look(&held, s) {
                (h, false) => Term::Series(h),
                (h, true) => Term::Negated(h),
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::Evaluation;
    use super::*;
    use crate::program::{Function, Instr, Program};
    use dalembert_runtime::__private::taylor as tay;

    /// x₁ − x₁·sin x₀ and −(x₀·x₁)·cos x₀, the shapes of the Euler-angle
    /// ball's q̈: no negation is left (the first subtracts, the second is
    /// an output written negated), and the coefficients along a series of
    /// the inputs are those of the unfolded recurrences, bit for bit.
    #[test]
    fn negations_are_folded_into_their_readers() {
        let (x0, x1) = (Slot::Input(0), Slot::Input(1));
        let minus_one = Slot::Const(0);
        let p = Program {
            inputs: 2,
            consts: vec![-1.0],
            instrs: vec![
                Instr::Fun(Slot::Temp(0), Function::Sin, x0),
                Instr::Mul(Slot::Temp(1), vec![x1, Slot::Temp(0)]),
                Instr::Sub(Slot::Out(0), [x1, Slot::Temp(1)]),
                Instr::Fun(Slot::Temp(2), Function::Cos, x0),
                Instr::Mul(Slot::Temp(3), vec![minus_one, x0, x1]),
                Instr::Mul(Slot::Out(1), vec![Slot::Temp(3), Slot::Temp(2)]),
            ],
            outputs: 2,
        };
        let tr = p.taylor(0, 2);
        assert!(
            !tr.ops.iter().any(|op| matches!(op, Op::Scale { .. })),
            "{:?}",
            tr.ops
        );
        // sin/cos, x₁·sin, the difference, x₀·x₁ and its product with cos.
        assert_eq!(tr.ops.len(), 5, "{:?}", tr.ops);
        assert!(matches!(tr.outputs[0], Term::Series(_)));
        assert!(matches!(tr.outputs[1], Term::Negated(_)));
        // Along x₀ = 0.3 + t − t²/5, x₁ = −1.2 + 0.5t + t³.
        let mut a = [[0.0; tay::CAPACITY]; 2];
        (a[0][0], a[0][1], a[0][2]) = (0.3, 1.0, -0.2);
        (a[1][0], a[1][1], a[1][3]) = (-1.2, 0.5, 1.0);
        let order = 20;
        let mut e = Evaluation {
            q: a.to_vec(),
            v: vec![],
            temps: vec![[0.0; tay::CAPACITY]; tr.temps],
            ..Evaluation::default()
        };
        let mut got = [[0.0; tay::CAPACITY]; 2];
        for k in 0..=order {
            tr.order(&mut e, &[-1.0], k);
            for (o, g) in got.iter_mut().enumerate() {
                g[k] = tr.output(&e, &[-1.0], o, k);
            }
        }
        // The same by the unfolded recurrences, a negation as its own
        // series.
        let (mut s, mut c) = ([0.0; tay::CAPACITY], [0.0; tay::CAPACITY]);
        let (mut prod, mut neg, mut prod2, mut want) = (
            [0.0; tay::CAPACITY],
            [0.0; tay::CAPACITY],
            [0.0; tay::CAPACITY],
            [[0.0; tay::CAPACITY]; 2],
        );
        for k in 0..=order {
            (s[k], c[k]) = tay::sin_cos(&s, &c, &a[0], k);
            prod[k] = tay::mul(&a[1], &s, k);
            want[0][k] = a[1][k] + -prod[k];
            neg[k] = -a[0][k];
            prod2[k] = tay::mul(&neg, &a[1], k);
            want[1][k] = tay::mul(&prod2, &c, k);
        }
        for o in 0..2 {
            for k in 0..=order {
                assert_eq!(
                    got[o][k].to_bits(),
                    want[o][k].to_bits(),
                    "output {o}, order {k}"
                );
            }
        }
    }
}
