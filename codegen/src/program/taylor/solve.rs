//! The motion's series with a linear solve at each order (the runtime's
//! `taylor::ldl_factor` / `ldl_solve`), without constraint rows, where it
//! costs less than the transform of q̈'s own program (closed form or
//! elimination).
//! Either G q̈ + h = 0: the transform of the program that computes G's
//! lower triangle and h, followed by xₖ = G₀⁻¹(hₖ − Σⱼ₌₁..ₖ Gⱼ xₖ₋ⱼ) and
//! q̈ₖ = −xₖ. Or, without constraints, the momentum p = G q̇ with
//! ṗ = ∂L/∂q, which needs G and ∂L/∂q only (h carries the time derivative
//! of G q̇ as well): q̇ₖ = G₀⁻¹(pₖ − Σⱼ₌₁..ₖ Gⱼ q̇ₖ₋ⱼ). Where the elimination
//! written out as straight-line code (`program/elimination.rs`) makes every
//! pivot and multiplier of G's factorisation a series of its own, this
//! factors G₀ once per series and costs per order one history for each
//! entry of G that varies, and two triangular solves.

use std::collections::HashSet;

use dalembert_runtime::__private::taylor as tay;

use super::evaluate::Evaluation;
use super::{Series, Term, Transform};
use crate::program::{Layout, Program};

/// The solve inside a transform's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Solve {
    /// G's entries, row by row, both triangles (G is symmetric): a term,
    /// or `None` where exactly zero.
    pub g: Vec<Vec<Option<Term>>>,
    /// The right-hand side's entries, the same way: h's, or ∂L/∂q's with
    /// [`Solve::momentum`].
    pub rhs: Vec<Option<Term>>,
    /// What is solved for: x = G⁻¹h, one intermediate series per
    /// coordinate, the transform's outputs being −x; or with
    /// [`Solve::momentum`] the velocities.
    pub x: Vec<Series>,
    /// Whether the series followed is the momentum p = G q̇ (ṗ = ∂L/∂q, no
    /// constraints): then q̇ₖ = G₀⁻¹(pₖ − Σⱼ₌₁..ₖ Gⱼ q̇ₖ₋ⱼ) with
    /// pₖ = (∂L/∂q)ₖ₋₁/k is solved at each order k ≥ 1 between the ops
    /// that read coordinates only (`ops[..split]`, G's among them) and the
    /// rest. Otherwise G q̈ = −h is solved after all the ops.
    pub momentum: bool,
    /// How many of the ops come before the solve.
    pub split: usize,
}

impl Program {
    /// The Taylor transform of the motion with a solve per order, where
    /// this program's outputs are the entries of G and of a right-hand
    /// side that `layout` and `rhs` place (inputs: `params` parameters,
    /// `coords` coordinates, then velocities): h of G q̈ + h = 0, or with
    /// `momentum` ∂L/∂q (see [`Solve::momentum`]). `None` with constraint
    /// rows (q̈ then also needs the multipliers: the elimination's
    /// transform serves), or with `momentum` where an entry of G reads a
    /// velocity.
    pub fn taylor_solve(
        &self,
        params: usize,
        coords: usize,
        layout: &Layout,
        rhs: &[Option<usize>],
        momentum: bool,
    ) -> Option<Transform> {
        if !layout.rows.is_empty() {
            return None;
        }
        let mut t = self.taylor(params, coords);
        let n = layout.n;
        let mut split = t.ops.len();
        if momentum {
            // The ops that read a velocity, and all that read them, after
            // the others (a stable partition keeps each op after what it
            // reads).
            let mut moving: HashSet<Series> = (0..n).map(Series::V).collect();
            let (mut first, mut then) = (Vec::new(), Vec::new());
            for op in std::mem::take(&mut t.ops) {
                if op.reads().iter().any(|s| moving.contains(s)) {
                    moving.extend(op.writes());
                    then.push(op);
                } else {
                    first.push(op);
                }
            }
            let reads_velocity = |k: &usize| match t.outputs[*k] {
                Term::Series(s) | Term::Negated(s) => moving.contains(&s),
                Term::Number(_) => false,
            };
            if layout.g.iter().flatten().any(reads_velocity) {
                return None;
            }
            split = first.len();
            first.extend(then);
            t.ops = first;
        }
        let entry = |e: Option<usize>| e.map(|k| t.outputs[k]);
        let g = (0..n)
            .map(|i| (0..n).map(|j| entry(layout.entry(i, j))).collect())
            .collect();
        let rhs = rhs.iter().map(|e| entry(*e)).collect();
        let x: Vec<Series> = if momentum {
            t.outputs = Vec::new();
            (0..n).map(Series::V).collect()
        } else {
            let x: Vec<Series> = (0..n).map(|i| Series::Temp(t.temps + i)).collect();
            t.temps += n;
            t.outputs = x.iter().map(|s| Term::Negated(*s)).collect();
            x
        };
        t.solve = Some(Solve {
            g,
            rhs,
            x,
            momentum,
            split,
        });
        Some(t)
    }
}

impl Solve {
    /// The entries of G that vary, each with its row, column and series
    /// (and whether the series is negated): one history each per order.
    pub fn varying(&self) -> impl Iterator<Item = (usize, usize, Series, bool)> + '_ {
        self.g.iter().enumerate().flat_map(|(i, row)| {
            row.iter().enumerate().filter_map(move |(m, e)| match e {
                Some(Term::Series(s)) => Some((i, m, *s, false)),
                Some(Term::Negated(s)) => Some((i, m, *s, true)),
                _ => None,
            })
        })
    }

    /// Order k of x into `e` (the ops before it already run at order k):
    /// at order 0 G₀ is factored into `e.factor` (and with
    /// [`Solve::momentum`] x₀, the state's velocity, is left as it is);
    /// with [`Solve::momentum`] the right-hand side is pₖ, `e.momentum`.
    pub(super) fn order(&self, t: &Transform, e: &mut Evaluation, numbers: &[f64], k: usize) {
        let n = self.x.len();
        let coefficient = |e: &Evaluation, term: &Option<Term>, k: usize| {
            term.as_ref()
                .map_or(0.0, |term| t.coefficient(e, numbers, term, k))
        };
        // The right-hand side in a buffer kept with the evaluation.
        let mut rhs = std::mem::take(&mut e.rhs);
        rhs.clear();
        if self.momentum {
            rhs.extend(&e.momentum);
        } else {
            rhs.extend(self.rhs.iter().map(|h| coefficient(e, h, k)));
        }
        if k == 0 {
            e.factor.clear();
            for i in 0..n {
                for j in 0..=i {
                    e.factor.push(coefficient(e, &self.g[i][j], 0));
                }
            }
            tay::ldl_factor(&mut e.factor, n);
            if self.momentum {
                e.rhs = rhs;
                return;
            }
        } else {
            // As emitted code: hₖ − (history + Gₖ x₀), entry by entry in
            // row order, a negated entry added.
            for (i, m, s, minus) in self.varying() {
                let (g, x) = (e.series(s), e.series(self.x[m]));
                let term = tay::history(g, x, k) + g[k] * x[0];
                rhs[i] = if minus { rhs[i] + term } else { rhs[i] - term };
            }
        }
        tay::ldl_solve(&e.factor, &mut rhs);
        for (x, value) in self.x.iter().zip(&rhs) {
            match *x {
                Series::Temp(j) => e.temps[j][k] = *value,
                Series::V(i) => e.v[i][k] = *value,
                Series::Q(_) => unreachable!("a solve is for velocities or temporaries"),
            }
        }
        e.rhs = rhs;
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // matrices by index, as written on paper
mod tests {
    use crate::program::{Function, Instr, Layout, Program, Slot, Transform};

    /// (q₀, q₁, v₀, v₁).
    const INPUTS: [Slot; 4] = [
        Slot::Input(0),
        Slot::Input(1),
        Slot::Input(2),
        Slot::Input(3),
    ];

    /// G of the two links below: G₀₀ = 3, G₁₀ = cos(q₀ − q₁), G₁₁ = 2 as
    /// outputs 0 to 2 (constants 0 and 1 are 3 and 2; temporaries 0 to 2
    /// are q₀ − q₁, its cos and its sin).
    fn g_part() -> Vec<Instr> {
        let ([q0, q1, ..], t) = (INPUTS, Slot::Temp);
        let (three, two) = (Slot::Const(0), Slot::Const(1));
        vec![
            Instr::Sub(t(0), [q0, q1]),
            Instr::Fun(t(1), Function::Cos, t(0)),
            Instr::Fun(t(2), Function::Sin, t(0)),
            Instr::Assign(Slot::Out(0), three),
            Instr::Assign(Slot::Out(1), t(1)),
            Instr::Assign(Slot::Out(2), two),
        ]
    }

    /// The series of `a` and `b` from the same state agree to rounding at
    /// every order to 20.
    fn assert_same_series(a: &Transform, b: &Transform) {
        let (q, v) = ([0.7, -0.4], [1.3, -0.6]);
        let x = a.motion(&a.number_values(&[], |p, x| p.eval(x)), &q, &v, 20);
        let y = b.motion(&b.number_values(&[], |p, x| p.eval(x)), &q, &v, 20);
        for i in 0..2 {
            for k in 0..=20 {
                for (x, y) in [(x.q[i][k], y.q[i][k]), (x.v[i][k], y.v[i][k])] {
                    assert!((x - y).abs() <= 1e-13 * (1.0 + y.abs()), "{i} {k}: {x} {y}");
                }
            }
        }
    }

    /// A two-link chain's G and h over (q₀, q₁, v₀, v₁) (no parameters):
    /// G = [[3, c], [c, 2]] with c = cos(q₀ − q₁), and
    /// h = (s v₁² + 2 sin q₀, −s v₀² + sin q₁) with s = sin(q₀ − q₁). Its
    /// outputs: G₀₀, G₁₀, G₁₁, h₀, h₁.
    fn two_links() -> (Program, Layout, Vec<Option<usize>>) {
        let ([q0, q1, v0, v1], t) = (INPUTS, Slot::Temp);
        let (two, minus_one) = (Slot::Const(1), Slot::Const(2));
        let mut instrs = g_part();
        instrs.extend([
            Instr::Pow(t(3), v1, 2),
            Instr::Fun(t(4), Function::Sin, q0),
            Instr::Mul(t(5), vec![two, t(4)]),
            Instr::Mul(t(6), vec![t(2), t(3)]),
            Instr::Add(Slot::Out(3), vec![t(6), t(5)]),
            Instr::Pow(t(7), v0, 2),
            Instr::Mul(t(8), vec![minus_one, t(2), t(7)]),
            Instr::Fun(t(9), Function::Sin, q1),
            Instr::Add(Slot::Out(4), vec![t(8), t(9)]),
        ]);
        let program = Program {
            inputs: 4,
            consts: vec![3.0, 2.0, -1.0],
            instrs,
            outputs: 5,
        };
        let layout = Layout {
            n: 2,
            g: vec![Some(0), Some(1), Some(2)],
            rows: vec![],
        };
        (program, layout, vec![Some(3), Some(4)])
    }

    /// The series with the solve per order are the elimination's series
    /// (the same motion, another order of operations) to rounding, at
    /// every order, and q̈ at order 0 is −G⁻¹h.
    #[test]
    fn the_same_series_as_the_elimination() {
        let (program, layout, forcing) = two_links();
        let solved = program
            .taylor_solve(0, 2, &layout, &forcing, false)
            .expect("no rows");
        let eliminated = program
            .motion_by_elimination(&layout, &forcing, &[])
            .expect("pivots")
            .taylor(0, 2);
        assert!(eliminated.solve.is_none() && solved.solve.is_some());
        assert_same_series(&solved, &eliminated);
        // Order 0: G q̈ = −h.
        let (q, v) = ([0.7, -0.4], [1.3, -0.6]);
        let a = solved.motion(&solved.number_values(&[], |p, x| p.eval(x)), &q, &v, 1);
        let (c, s) = ((q[0] - q[1]).cos(), (q[0] - q[1]).sin());
        let h = [
            s * v[1] * v[1] + 2.0 * q[0].sin(),
            -s * v[0] * v[0] + q[1].sin(),
        ];
        let det = 6.0 - c * c;
        let want = [
            -(2.0 * h[0] - c * h[1]) / det,
            -(3.0 * h[1] - c * h[0]) / det,
        ];
        for i in 0..2 {
            assert!((a.v[i][1] - want[i]).abs() <= 1e-15, "{i}");
        }
        // Constraint rows: not offered.
        let rows = Layout {
            rows: vec![vec![Some(0), None]],
            ..layout
        };
        assert!(program.taylor_solve(0, 2, &rows, &forcing, false).is_none());
    }

    /// The same two links with ∂L/∂q for the right-hand side (T = ½q̇ᵀGq̇,
    /// V = −2 cos q₀ − cos q₁): ∂L/∂q = (−s v₀v₁ − 2 sin q₀, s v₀v₁ − sin q₁).
    /// Outputs: G₀₀, G₁₀, G₁₁, ∂L/∂q₀, ∂L/∂q₁.
    fn two_links_gradient() -> Program {
        let ([q0, q1, v0, v1], t) = (INPUTS, Slot::Temp);
        let (minus_one, minus_two) = (Slot::Const(2), Slot::Const(3));
        let mut instrs = g_part();
        instrs.extend([
            Instr::Mul(t(3), vec![t(2), v0, v1]),
            Instr::Fun(t(4), Function::Sin, q0),
            Instr::Mul(t(5), vec![minus_two, t(4)]),
            Instr::Mul(t(6), vec![minus_one, t(3)]),
            Instr::Add(Slot::Out(3), vec![t(6), t(5)]),
            Instr::Fun(t(7), Function::Sin, q1),
            Instr::Mul(t(8), vec![minus_one, t(7)]),
            Instr::Add(Slot::Out(4), vec![t(3), t(8)]),
        ]);
        Program {
            inputs: 4,
            consts: vec![3.0, 2.0, -1.0, -2.0],
            instrs,
            outputs: 5,
        }
    }

    /// Following the momentum gives the same series as solving G q̈ = −h
    /// at each order, to rounding; the ops that read velocities come after
    /// the solve, G's before it.
    #[test]
    fn the_momentum_gives_the_same_series() {
        let (program, layout, forcing) = two_links();
        let by_h = program
            .taylor_solve(0, 2, &layout, &forcing, false)
            .unwrap();
        let by_p = two_links_gradient()
            .taylor_solve(0, 2, &layout, &[Some(3), Some(4)], true)
            .unwrap();
        let solve = by_p.solve.as_ref().unwrap();
        assert!(solve.momentum && solve.split < by_p.ops.len());
        for op in &by_p.ops[..solve.split] {
            assert!(!op.reads().iter().any(|s| matches!(s, super::Series::V(_))));
        }
        assert_same_series(&by_p, &by_h);
    }

    /// The solve's work: one convolution per entry of G that varies (G₁₀
    /// and G₀₁) and n² operations for the triangular solves.
    #[test]
    fn work_counts_the_solve() {
        let (program, layout, forcing) = two_links();
        let solved = program
            .taylor_solve(0, 2, &layout, &forcing, false)
            .unwrap();
        let plain = program.taylor(0, 2);
        let (w, p) = (solved.work(), plain.work());
        assert_eq!(w.convolutions, p.convolutions + 2);
        assert_eq!(w.operations, p.operations + 2 + 4);
    }
}
