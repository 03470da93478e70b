//! Quotients: a product with a reciprocal, a·(1/b), as one division a/b
//! (`dalembert_runtime::__private::taylor::div`), whose recurrence is one convolution
//! where the reciprocal and the product take two.

use std::collections::{HashMap, HashSet};

use super::{Op, Series, Term};

/// Every product with a reciprocal, a·(1/b), made a quotient a/b: one
/// convolution where the reciprocal and the product take two. A
/// reciprocal no longer read is dropped.
pub(super) fn fuse(ops: Vec<Op>, outputs: &[Term]) -> Vec<Op> {
    let recips: HashMap<Series, Series> = ops
        .iter()
        .filter_map(|op| match op {
            Op::Recip { dst, a } => Some((*dst, *a)),
            _ => None,
        })
        .collect();
    let fused: Vec<Op> = ops
        .into_iter()
        .map(|op| match op {
            Op::Mul { dst, a, b } => match (recips.get(&a), recips.get(&b)) {
                (_, Some(&den)) => Op::Div { dst, a, b: den },
                (Some(&den), None) => Op::Div { dst, a: b, b: den },
                (None, None) => op,
            },
            _ => op,
        })
        .collect();
    let mut read: HashSet<Series> = fused.iter().flat_map(Op::reads).collect();
    read.extend(outputs.iter().filter_map(|t| match t {
        Term::Series(s) | Term::Negated(s) => Some(*s),
        Term::Number(_) => None,
    }));
    fused
        .into_iter()
        .filter(|op| !matches!(op, Op::Recip { dst, .. } if !read.contains(dst)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::Evaluation;
    use super::*;
    use crate::program::{Function, Instr, Program, Slot};
    use dalembert_runtime::__private::taylor as tay;

    /// A product with a reciprocal is one quotient: sin(x)·x⁻¹ is a sin/cos
    /// pair and a division (no reciprocal left, temporaries numbered
    /// without gaps), and its series is sin(x)/x's along x(t) = 2 + t.
    #[test]
    fn products_with_reciprocals_are_quotients() {
        let x = Slot::Input(0);
        let p = Program {
            inputs: 1,
            consts: vec![],
            instrs: vec![
                Instr::Fun(Slot::Temp(0), Function::Sin, x),
                Instr::Pow(Slot::Temp(1), x, -1),
                Instr::Mul(Slot::Out(0), vec![Slot::Temp(1), Slot::Temp(0)]),
            ],
            outputs: 1,
        };
        let tr = p.taylor(0, 1);
        assert_eq!(
            tr.ops,
            vec![
                Op::SinCos {
                    sin: Series::Temp(0),
                    cos: Series::Temp(1),
                    a: Series::Q(0)
                },
                Op::Div {
                    dst: Series::Temp(2),
                    a: Series::Temp(0),
                    b: Series::Q(0)
                },
            ]
        );
        assert_eq!((tr.temps, tr.convolutions()), (3, 2));
        // To order 20: 19·18/2 products in each history, 20 finishes each.
        assert_eq!(tr.cost(20), 2 * 171 + 2 * 20);
        assert_eq!(tr.outputs, vec![Term::Series(Series::Temp(2))]);
        let mut e = Evaluation {
            q: vec![[0.0; tay::CAPACITY]],
            v: vec![],
            temps: vec![],
            ..Evaluation::default()
        };
        e.q[0][0] = 2.0;
        e.q[0][1] = 1.0;
        let c = tr.along(&[], &mut e, 25);
        for tau in [0.0, 0.1, -0.2, 0.3] {
            let (got, want) = (
                dalembert_runtime::taylor::eval(&c, 25, tau),
                (2.0 + tau).sin() / (2.0 + tau),
            );
            assert!((got - want).abs() <= 1e-15, "{tau}: {got} {want}");
        }
    }
}
