//! q̈ of G q̈ + h = 0 solved order by order inside the series (the
//! runtime's `taylor::ldl_factor` / `ldl_solve`): the transform of the
//! program that computes G's lower triangle and h, followed by
//! xₖ = G₀⁻¹(hₖ − Σⱼ₌₁..ₖ Gⱼ xₖ₋ⱼ) and q̈ₖ = −xₖ. Where the elimination
//! written out as straight-line code (`program/elimination.rs`) makes every
//! pivot and multiplier of G's factorisation a series of its own, this
//! factors G₀ once per series and costs per order one history for each
//! entry of G that varies, and two triangular solves.

use dalembert_runtime::taylor as tay;

use super::evaluate::Evaluation;
use super::{Series, Term, Transform};
use crate::program::{Layout, Program};

/// The solve that ends a transform's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Solve {
    /// G's entries, row by row, both triangles (G is symmetric): a term,
    /// or `None` where exactly zero.
    pub g: Vec<Vec<Option<Term>>>,
    /// h's entries, the same way.
    pub h: Vec<Option<Term>>,
    /// x = G⁻¹h, one intermediate series per coordinate; the transform's
    /// outputs are −x.
    pub x: Vec<Series>,
}

impl Program {
    /// The Taylor transform of q̈ with G q̈ + h = 0 solved per order, where
    /// this program's outputs are the entries of G and h that `layout` and
    /// `forcing` place (inputs: `params` parameters, `coords` coordinates,
    /// then velocities). `None` with constraint rows (q̈ then also needs
    /// the multipliers: the elimination's transform serves).
    pub fn taylor_solve(
        &self,
        params: usize,
        coords: usize,
        layout: &Layout,
        forcing: &[Option<usize>],
    ) -> Option<Transform> {
        if !layout.rows.is_empty() {
            return None;
        }
        let mut t = self.taylor(params, coords);
        let n = layout.n;
        let entry = |e: Option<usize>| e.map(|k| t.outputs[k]);
        let g = (0..n)
            .map(|i| (0..n).map(|j| entry(layout.entry(i, j))).collect())
            .collect();
        let h = forcing.iter().map(|e| entry(*e)).collect();
        let x: Vec<Series> = (0..n).map(|i| Series::Temp(t.temps + i)).collect();
        t.temps += n;
        t.outputs = x.iter().map(|s| Term::Negated(*s)).collect();
        t.solve = Some(Solve { g, h, x });
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

    /// Order k of x into `e` (every op's order k already run): at order 0
    /// G₀ is factored into `e.factor`.
    pub(super) fn order(&self, t: &Transform, e: &mut Evaluation, numbers: &[f64], k: usize) {
        let n = self.x.len();
        let coefficient = |e: &Evaluation, term: &Option<Term>, k: usize| {
            term.as_ref()
                .map_or(0.0, |term| t.coefficient(e, numbers, term, k))
        };
        // The right-hand side in a buffer kept with the evaluation.
        let mut rhs = std::mem::take(&mut e.rhs);
        rhs.clear();
        rhs.extend(self.h.iter().map(|h| coefficient(e, h, k)));
        if k == 0 {
            e.factor.clear();
            for i in 0..n {
                for j in 0..=i {
                    e.factor.push(coefficient(e, &self.g[i][j], 0));
                }
            }
            tay::ldl_factor(&mut e.factor, n);
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
            let Series::Temp(j) = *x else {
                unreachable!("x is intermediate")
            };
            e.temps[j][k] = *value;
        }
        e.rhs = rhs;
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // matrices by index, as written on paper
mod tests {
    use crate::program::{Func, Instr, Layout, Program, Slot};

    /// A two-link chain's G and h over (q₀, q₁, v₀, v₁) (no parameters):
    /// G = [[3, c], [c, 2]] with c = cos(q₀ − q₁), and
    /// h = (s v₁² + 2 sin q₀, −s v₀² + sin q₁) with s = sin(q₀ − q₁). Its
    /// outputs: G₀₀, G₁₀, G₁₁, h₀, h₁.
    fn two_links() -> (Program, Layout, Vec<Option<usize>>) {
        let (q0, q1, v0, v1) = (
            Slot::Input(0),
            Slot::Input(1),
            Slot::Input(2),
            Slot::Input(3),
        );
        let t = Slot::Temp;
        let (three, two, minus_one) = (Slot::Const(0), Slot::Const(1), Slot::Const(2));
        let instrs = vec![
            Instr::Sub(t(0), [q0, q1]),
            Instr::Fun(t(1), Func::Cos, t(0)),
            Instr::Fun(t(2), Func::Sin, t(0)),
            Instr::Assign(Slot::Out(0), three),
            Instr::Assign(Slot::Out(1), t(1)),
            Instr::Assign(Slot::Out(2), two),
            Instr::Pow(t(3), v1, 2),
            Instr::Fun(t(4), Func::Sin, q0),
            Instr::Mul(t(5), vec![two, t(4)]),
            Instr::Mul(t(6), vec![t(2), t(3)]),
            Instr::Add(Slot::Out(3), vec![t(6), t(5)]),
            Instr::Pow(t(7), v0, 2),
            Instr::Mul(t(8), vec![minus_one, t(2), t(7)]),
            Instr::Fun(t(9), Func::Sin, q1),
            Instr::Add(Slot::Out(4), vec![t(8), t(9)]),
        ];
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
            .taylor_solve(0, 2, &layout, &forcing)
            .expect("no rows");
        let eliminated = program
            .motion_by_elimination(&layout, &forcing, &[])
            .expect("pivots")
            .taylor(0, 2);
        assert!(eliminated.solve.is_none() && solved.solve.is_some());
        let (q, v) = ([0.7, -0.4], [1.3, -0.6]);
        let a = solved.motion(&solved.number_values(&[], |p, x| p.eval(x)), &q, &v, 20);
        let b = eliminated.motion(&eliminated.number_values(&[], |p, x| p.eval(x)), &q, &v, 20);
        for i in 0..2 {
            for k in 0..=20 {
                for (x, y) in [(a.q[i][k], b.q[i][k]), (a.v[i][k], b.v[i][k])] {
                    assert!((x - y).abs() <= 1e-13 * (1.0 + y.abs()), "{i} {k}: {x} {y}");
                }
            }
        }
        // Order 0: G q̈ = −h.
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
        assert!(program.taylor_solve(0, 2, &rows, &forcing).is_none());
    }

    /// The solve's work: one convolution per entry of G that varies (G₁₀
    /// and G₀₁) and n² operations for the triangular solves.
    #[test]
    fn work_counts_the_solve() {
        let (program, layout, forcing) = two_links();
        let solved = program.taylor_solve(0, 2, &layout, &forcing).unwrap();
        let plain = program.taylor(0, 2);
        let (w, p) = (solved.work(), plain.work());
        assert_eq!(w.convolutions, p.convolutions + 2);
        assert_eq!(w.operations, p.operations + 2 + 4);
    }
}
