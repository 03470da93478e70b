//! Evaluating a Taylor transform in plain Rust, order by order, with the
//! runtime's recurrences: the time-constant values, one order of every
//! op, the series of the motion and of a function along it. The
//! interpreter and the tests use it; emitted code does the same in
//! straight-line Rust (`emit/taylor.rs`).

use std::ops::Range;

use dalembert_runtime::__private::taylor::{self as tay, Coefficients};

use super::{Op, Series, Term, Transform};
use crate::program::{Instr, Program, Slot};

/// The series state of an evaluation: coordinates, velocities, temporaries.
/// Reusable: an evaluation reads only coefficients it wrote in the same
/// run, so a buffer used before needs no clearing, and one large enough
/// needs no allocation.
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    /// Coefficients of each coordinate.
    pub q: Vec<Coefficients>,
    /// Coefficients of each velocity.
    pub v: Vec<Coefficients>,
    /// Coefficients of each intermediate series.
    pub temps: Vec<Coefficients>,
    /// G₀ factored, where the transform ends in a [`super::Solve`].
    pub factor: Vec<f64>,
    /// The solve's right-hand side.
    pub rhs: Vec<f64>,
    /// pₖ, where the series followed is the momentum's.
    pub momentum: Vec<f64>,
}

impl Evaluation {
    /// The coefficients of series `s`.
    pub(super) fn series(&self, s: Series) -> &Coefficients {
        match s {
            Series::Q(i) => &self.q[i],
            Series::V(i) => &self.v[i],
            Series::Temp(i) => &self.temps[i],
        }
    }
}

impl Transform {
    /// The time-constant values at the parameters `params`: a vector that
    /// [`Term::Number`] slots index by [`Transform::number_index`]. `eval`
    /// runs a program on its inputs (the interpreter passes its tape, which
    /// computes as emitted code does; [`Program::eval`] serves tests).
    pub fn number_values(
        &self,
        params: &[f64],
        eval: impl FnOnce(&Program, &[f64]) -> Vec<f64>,
    ) -> Vec<f64> {
        let mut inputs = vec![0.0; self.numbers.inputs];
        inputs[..params.len()].copy_from_slice(params);
        let mut p = self.numbers.clone();
        // The temporaries as outputs, to read them back (instruction j
        // writes temporary j).
        let written = p.instrs.len();
        p.instrs
            .extend((0..written).map(|k| Instr::Assign(Slot::Out(k), Slot::Temp(k))));
        p.outputs = written;
        let temps = eval(&p, &inputs);
        let mut all = inputs;
        all.extend(&self.numbers.consts);
        all.extend(temps);
        all
    }

    /// Where a number slot's value is in [`Transform::number_values`].
    pub fn number_index(&self, s: Slot) -> usize {
        match s {
            Slot::Input(i) => i,
            Slot::Const(i) => self.numbers.inputs + i,
            Slot::Temp(i) | Slot::Out(i) => self.numbers.inputs + self.numbers.consts.len() + i,
        }
    }

    /// Runs order k of every op on `e` (coefficients below k in place),
    /// and of a solve of h's.
    pub fn order(&self, e: &mut Evaluation, numbers: &[f64], k: usize) {
        self.run_ops(e, numbers, k, 0..self.ops.len());
        if let Some(solve) = self.solve.as_ref().filter(|s| !s.momentum) {
            solve.order(self, e, numbers, k);
        }
    }

    /// Runs order k of the ops in `range`.
    fn run_ops(&self, e: &mut Evaluation, numbers: &[f64], k: usize, range: Range<usize>) {
        for op in &self.ops[range] {
            // Operands by reference: a copy would move 256 bytes per operand.
            let get = |s: Series| e.series(s);
            let slot_value = |s: &Slot| numbers[self.number_index(*s)];
            let value = match op {
                Op::SinCos { sin, cos, a } => {
                    let (s, c) = tay::sin_cos(get(*sin), get(*cos), get(*a), k);
                    let (Series::Temp(si), Series::Temp(ci)) = (sin, cos) else {
                        unreachable!("pairs write temporaries")
                    };
                    e.temps[*si][k] = s;
                    e.temps[*ci][k] = c;
                    continue;
                }
                Op::Add {
                    series, numbers, ..
                } => {
                    // As emitted code sums: in order, from the first term.
                    let mut x = -0.0;
                    for t in series {
                        let c = get(t.series)[k];
                        x = if t.minus { x - c } else { x + c };
                    }
                    if k == 0 {
                        x += numbers.iter().map(slot_value).sum::<f64>();
                    }
                    x
                }
                Op::Scale { a, by, .. } => get(*a)[k] * slot_value(by),
                Op::Mul { a, b, .. } => tay::mul(get(*a), get(*b), k),
                Op::Square { a, .. } => tay::square(get(*a), k),
                Op::Recip { dst, a } => tay::recip(get(*dst), get(*a), k),
                Op::Div { dst, a, b } => tay::div(get(*dst), get(*a), get(*b), k),
                Op::Sqrt { dst, a } => tay::sqrt(get(*dst), get(*a), k),
                Op::Power { dst, a, alpha } => tay::power(get(*dst), get(*a), *alpha, k),
                Op::Exp { dst, a } => tay::exp(get(*dst), get(*a), k),
                Op::Log { dst, a } => tay::log(get(*dst), get(*a), k),
                Op::Arc {
                    dst,
                    a,
                    w,
                    f,
                    minus,
                    ..
                } => {
                    let (c, a, w) = (get(*dst), get(*a), get(*w));
                    let sign = if *minus { -1.0 } else { 1.0 };
                    if k == 0 {
                        f.libm()(a[0])
                    } else {
                        // As emitted: ln's finish on a, signed.
                        let h = tay::weighted_history(c, w, k);
                        tay::log_finish_by(a, sign * h, k, sign / w[0])
                    }
                }
            };
            let Some(Series::Temp(d)) = op.dst() else {
                unreachable!("ops other than sin/cos write one temporary")
            };
            e.temps[d][k] = value;
        }
    }

    /// Coefficient k of output `o`.
    pub fn output(&self, e: &Evaluation, numbers: &[f64], o: usize, k: usize) -> f64 {
        self.coefficient(e, numbers, &self.outputs[o], k)
    }

    /// Coefficient k of a term (an output, or an entry of a solve).
    pub(super) fn coefficient(
        &self,
        e: &Evaluation,
        numbers: &[f64],
        term: &Term,
        k: usize,
    ) -> f64 {
        match *term {
            Term::Number(s) if k == 0 => numbers[self.number_index(s)],
            Term::Number(_) => 0.0,
            Term::Series(s) => e.series(s)[k],
            Term::Negated(s) => -e.series(s)[k],
        }
    }

    /// The Taylor series of the motion q̈ = this program's outputs through
    /// (q, v), to `order` (for tests and the interpreter; emitted code does
    /// the same in straight-line Rust).
    pub fn motion(&self, numbers: &[f64], q: &[f64], v: &[f64], order: usize) -> Evaluation {
        let mut e = Evaluation::default();
        self.motion_into(&mut e, numbers, q, v, order);
        e
    }

    /// [`Transform::motion`] into `e`, reused (no allocation once it has
    /// held an evaluation of this size).
    pub fn motion_into(
        &self,
        e: &mut Evaluation,
        numbers: &[f64],
        q: &[f64],
        v: &[f64],
        order: usize,
    ) {
        e.q.resize(q.len(), [0.0; tay::CAPACITY]);
        e.v.resize(v.len(), [0.0; tay::CAPACITY]);
        e.temps.resize(self.temps, [0.0; tay::CAPACITY]);
        for (c, x) in e.q.iter_mut().zip(q) {
            c[0] = *x;
        }
        for (c, x) in e.v.iter_mut().zip(v) {
            c[0] = *x;
        }
        let order = order.min(tay::MAX_ORDER);
        if let Some(solve) = self.solve.as_ref().filter(|s| s.momentum) {
            // As emitted code: the ops before the solve, the solve, the
            // rest, then qₖ₊₁ and pₖ₊₁.
            e.momentum.resize(v.len(), 0.0);
            for k in 0..=order {
                self.run_ops(e, numbers, k, 0..solve.split);
                solve.order(self, e, numbers, k);
                if k == order {
                    break;
                }
                self.run_ops(e, numbers, k, solve.split..self.ops.len());
                let ik = tay::RECIPROCALS[k + 1];
                for i in 0..v.len() {
                    e.q[i][k + 1] = e.v[i][k] * ik;
                    let f = solve.rhs[i]
                        .as_ref()
                        .map_or(0.0, |f| self.coefficient(e, numbers, f, k));
                    e.momentum[i] = f * ik;
                }
            }
            return;
        }
        for k in 0..order {
            self.order(e, numbers, k);
            let ik = tay::RECIPROCALS[k + 1];
            for i in 0..v.len() {
                e.q[i][k + 1] = e.v[i][k] * ik;
                e.v[i][k + 1] = self.output(e, numbers, i, k) * ik;
            }
        }
    }

    /// The ops every column of the variational flow shares
    /// ([`Transform::shared`]) along the motion in `e` (its n series,
    /// then room for a column's n), to `order`.
    pub fn shared_into(&self, e: &mut Evaluation, numbers: &[f64], order: usize) {
        e.temps.resize(self.temps, [0.0; tay::CAPACITY]);
        let shared = self.shared.expect("a variational system");
        for k in 0..order.min(tay::MAX_ORDER) {
            self.run_ops(e, numbers, k, 0..shared);
        }
    }

    /// A column of the variational flow along a motion, this transform
    /// being the variational system's ([`Program::variational`]), after
    /// [`Transform::shared_into`]: `e.q` and `e.v` hold the motion's n
    /// series (to `order`) followed by the column's n, whose orders 1 to
    /// `order` it fills from order 0 (as emitted `tangent_series` does).
    pub fn tangent_into(&self, e: &mut Evaluation, numbers: &[f64], order: usize) {
        let n = e.q.len() / 2;
        let shared = self.shared.expect("a variational system");
        for k in 0..order.min(tay::MAX_ORDER) {
            self.run_ops(e, numbers, k, shared..self.ops.len());
            let ik = tay::RECIPROCALS[k + 1];
            for i in 0..n {
                e.q[n + i][k + 1] = e.v[n + i][k] * ik;
                e.v[n + i][k + 1] = self.output(e, numbers, i, k) * ik;
            }
        }
    }

    /// The coefficients of the first output along the coordinates' series
    /// in `e` (its temporaries overwritten), orders 0 to `order`.
    pub fn along(&self, numbers: &[f64], e: &mut Evaluation, order: usize) -> Coefficients {
        e.temps.resize(self.temps, [0.0; tay::CAPACITY]);
        let mut out = [0.0; tay::CAPACITY];
        for (k, o) in out
            .iter_mut()
            .enumerate()
            .take(order.min(tay::MAX_ORDER) + 1)
        {
            self.order(e, numbers, k);
            *o = self.output(e, numbers, 0, k);
        }
        out
    }
}
