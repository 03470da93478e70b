//! The Taylor transform of a straight-line program: the same computation on
//! truncated power series in time, one order at a time.
//!
//! Coordinates and velocities are series (their coefficients filled in by
//! the integrator, or by the motion itself for q̈); parameters, constants
//! and whatever depends on them alone stay numbers, computed once per call
//! as a small program of their own. Every instruction that reads a series
//! becomes one or more [`Op`]s, each the recurrence for one coefficient of
//! its result (`dalembert_runtime::__private::taylor`): a product with a number is a
//! scaling, a product of series a convolution, a power xⁿ (n ≤ 8)
//! repeated products and, for n < 0, a reciprocal, sin and cos of one
//! series one pair. Slots that the program writes again get a fresh series
//! each time, so every coefficient can be kept.

use std::collections::{HashMap, HashSet};

use dalembert_runtime::taylor::Work;

use super::machine::{Machine, lower};
use super::{Instr, Program, Slot, constant};
use crate::function::Recurrences;

mod evaluate;
mod functions;
mod negations;
mod op;
mod quotients;
mod solve;
pub use evaluate::Evaluation;
pub use op::{Op, Summand};
pub use solve::Solve;

/// A series the transform reads or writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Series {
    /// Coordinate i.
    Q(usize),
    /// Velocity i.
    V(usize),
    /// An intermediate value, numbered from 0.
    Temp(usize),
}

/// A value of the transform: a number (a slot of [`Transform::numbers`]:
/// a parameter input, a constant or a temporary there) or a series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// Constant in time.
    Number(Slot),
    /// A series.
    Series(Series),
    /// A series negated: only as an output, where `negations.rs` moved
    /// the sign of a negation.
    Negated(Series),
}

/// A program's Taylor transform.
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    /// The time-constant values: a program over the original inputs
    /// (parameters only are read) and constants, writing temporaries and
    /// no outputs.
    pub numbers: Program,
    /// Intermediate series in use.
    pub temps: usize,
    /// The series operations, in order: run them all for order k, then for
    /// k + 1.
    pub ops: Vec<Op>,
    /// Each output of the program.
    pub outputs: Vec<Term>,
    /// For q̈ solved per order ([`Program::taylor_solve`]): the solve
    /// that follows the ops at each order and writes the series the
    /// outputs read.
    pub solve: Option<Solve>,
    /// For the variational system ([`Transform::shared`]): the first this
    /// many ops read no tangent series, and are run once for every column.
    pub shared: Option<usize>,
}

impl Program {
    /// The Taylor transform when the inputs are `params` parameters, then
    /// `coords` coordinates, then velocities.
    pub fn taylor(&self, params: usize, coords: usize) -> Transform {
        Builder::new(self, params, coords).run()
    }
}

struct Builder<'a> {
    p: &'a Program,
    numbers: Program,
    ops: Vec<Op>,
    temps: usize,
    bound: HashMap<Slot, Term>,
    /// sin and cos already taken of a series.
    trig: HashMap<Series, (Series, Series)>,
    params: usize,
    coords: usize,
}

impl<'a> Builder<'a> {
    fn new(p: &'a Program, params: usize, coords: usize) -> Self {
        Self {
            p,
            numbers: Program {
                inputs: p.inputs,
                consts: p.consts.clone(),
                instrs: Vec::new(),
                outputs: 0,
            },
            ops: Vec::new(),
            temps: 0,
            bound: HashMap::new(),
            trig: HashMap::new(),
            params,
            coords,
        }
    }

    fn run(mut self) -> Transform {
        // Powers and square roots as the machine form has them (every
        // instruction computed: the series has no kept values).
        let machine = lower(self.p, |_| true);
        for (ins, m) in self.p.instrs.iter().zip(machine) {
            let value = self.instr(ins, &m.expect("every instruction is computed"));
            self.bound.insert(ins.dst(), value);
        }
        let mut outputs: Vec<Term> = (0..self.p.outputs)
            .map(|k| {
                self.bound
                    .get(&Slot::Out(k))
                    .copied()
                    .unwrap_or_else(|| Term::Number(constant(&mut self.numbers.consts, 0.0)))
            })
            .collect();
        let ops = quotients::fuse(self.ops, &outputs);
        let minus_one = constant(&mut self.numbers.consts, -1.0);
        let ops = negations::fold(ops, &mut outputs, &self.numbers.consts, minus_one);
        let (ops, temps) = renumber(ops, &mut outputs);
        Transform {
            numbers: self.numbers,
            temps,
            ops,
            outputs,
            solve: None,
            shared: None,
        }
    }

    fn term(&self, s: Slot) -> Term {
        match s {
            Slot::Input(i) if i < self.params => Term::Number(s),
            Slot::Input(i) if i < self.params + self.coords => {
                Term::Series(Series::Q(i - self.params))
            }
            Slot::Input(i) => Term::Series(Series::V(i - self.params - self.coords)),
            Slot::Const(_) => Term::Number(s),
            Slot::Temp(_) | Slot::Out(_) => self.bound[&s],
        }
    }

    fn temp(&mut self) -> Series {
        self.temps += 1;
        Series::Temp(self.temps - 1)
    }

    /// A number computed by `make(dst)`.
    fn number(&mut self, make: impl FnOnce(Slot) -> Instr) -> Term {
        // Instruction j of the numbers writes temporary j.
        let dst = Slot::Temp(self.numbers.instrs.len());
        self.numbers.instrs.push(make(dst));
        Term::Number(dst)
    }

    fn op(&mut self, make: impl FnOnce(Series) -> Op) -> Series {
        let dst = self.temp();
        self.ops.push(make(dst));
        dst
    }

    /// The series of `ins`, whose machine form is `m`.
    fn instr(&mut self, ins: &Instr, m: &Machine) -> Term {
        let terms: Vec<Term> = ins.sources().iter().map(|&s| self.term(s)).collect();
        let numbers: Option<Vec<Slot>> = terms
            .iter()
            .map(|t| match t {
                Term::Number(s) => Some(*s),
                Term::Series(_) | Term::Negated(_) => None,
            })
            .collect();
        if let Some(slots) = numbers {
            // Constant in time: the instruction itself, on numbers.
            return match ins {
                Instr::Assign(_, _) => Term::Number(slots[0]),
                _ => self.number(|dst| with_sources(ins, dst, &slots)),
            };
        }
        let series_of = |t: &Term| match t {
            Term::Series(s) => *s,
            Term::Number(_) | Term::Negated(_) => unreachable!("checked to be a series"),
        };
        match ins {
            Instr::Assign(_, _) => terms[0],
            Instr::Add(_, _) => self.sum(&terms),
            Instr::Sub(_, _) => {
                // a − b as a + (−1)·b.
                let minus_one = Term::Number(constant(&mut self.numbers.consts, -1.0));
                let b = self.times(terms[1], minus_one);
                self.sum(&[terms[0], b])
            }
            Instr::Mul(_, _) => {
                let mut acc = terms[0];
                for t in &terms[1..] {
                    acc = self.times(acc, *t);
                }
                acc
            }
            Instr::Pow(..) | Instr::Powf(..) | Instr::Fun(..) => {
                let a = series_of(&terms[0]);
                let over = |b: &mut Self, reciprocal: bool, x: Series| {
                    Term::Series(if reciprocal {
                        b.op(|dst| Op::Recip { dst, a: x })
                    } else {
                        x
                    })
                };
                match *m {
                    Machine::Number(x) => Term::Number(constant(&mut self.numbers.consts, x)),
                    Machine::Power { n, reciprocal, .. } => {
                        let mut acc = Term::Series(a);
                        for _ in 1..n {
                            acc = self.times(acc, Term::Series(a));
                        }
                        over(self, reciprocal, series_of(&acc))
                    }
                    Machine::Pow { e, reciprocal, .. } => {
                        let alpha = if reciprocal { -e } else { e };
                        Term::Series(self.op(|dst| Op::Power { dst, a, alpha }))
                    }
                    Machine::Sqrt { reciprocal, .. } => {
                        let root = self.op(|dst| Op::Sqrt { dst, a });
                        over(self, reciprocal, root)
                    }
                    // The function's own rule (`function`).
                    Machine::Call(f, _) => Term::Series(f.series(self, a)),
                    // sin and cos of one series share one pair of series,
                    // whichever slots they came through.
                    Machine::SinCos { sin, .. } | Machine::Half { sin, .. } => {
                        let (s, c) = self.sin_cos(a);
                        Term::Series(if sin { s } else { c })
                    }
                    _ => unreachable!("{m:?} is not the machine form of a power or function"),
                }
            }
        }
    }

    /// Σ terms, at least one of them a series.
    fn sum(&mut self, terms: &[Term]) -> Term {
        let mut series = Vec::new();
        let mut numbers = Vec::new();
        for t in terms {
            match t {
                Term::Series(s) => series.push(Summand {
                    series: *s,
                    minus: false,
                }),
                Term::Number(n) => numbers.push(*n),
                Term::Negated(_) => unreachable!("only outputs are negated"),
            }
        }
        Term::Series(self.op(|dst| Op::Add {
            dst,
            series,
            numbers,
        }))
    }

    /// a·b, where at least one is a series or both are numbers.
    fn times(&mut self, a: Term, b: Term) -> Term {
        match (a, b) {
            (Term::Number(x), Term::Number(y)) => self.number(|dst| Instr::Mul(dst, vec![x, y])),
            (Term::Series(s), Term::Number(n)) | (Term::Number(n), Term::Series(s)) => {
                Term::Series(self.op(|dst| Op::Scale { dst, a: s, by: n }))
            }
            (Term::Series(x), Term::Series(y)) if x == y => {
                Term::Series(self.op(|dst| Op::Square { dst, a: x }))
            }
            (Term::Series(x), Term::Series(y)) => {
                Term::Series(self.op(|dst| Op::Mul { dst, a: x, b: y }))
            }
            (Term::Negated(_), _) | (_, Term::Negated(_)) => {
                unreachable!("only outputs are negated")
            }
        }
    }
}

/// The temporaries numbered again, without gaps, in the order they are
/// written; returns the ops and how many temporaries they use.
fn renumber(mut ops: Vec<Op>, outputs: &mut [Term]) -> (Vec<Op>, usize) {
    let mut renumbered = HashMap::new();
    for s in ops.iter().flat_map(Op::writes) {
        let next = renumbered.len();
        renumbered.entry(s).or_insert(Series::Temp(next));
    }
    let rename = |s: Series| renumbered.get(&s).copied().unwrap_or(s);
    for t in outputs.iter_mut() {
        if let Term::Series(s) | Term::Negated(s) = t {
            *s = rename(*s);
        }
    }
    ops.iter_mut().for_each(|op| op.rename(&rename));
    (ops, renumbered.len())
}

/// `ins` writing `dst` from `sources` (its own, renamed).
fn with_sources(ins: &Instr, dst: Slot, sources: &[Slot]) -> Instr {
    match ins {
        Instr::Add(..) => Instr::Add(dst, sources.to_vec()),
        Instr::Sub(..) => Instr::Sub(dst, [sources[0], sources[1]]),
        Instr::Mul(..) => Instr::Mul(dst, sources.to_vec()),
        Instr::Pow(_, _, n) => Instr::Pow(dst, sources[0], *n),
        Instr::Powf(_, _, x) => Instr::Powf(dst, sources[0], *x),
        Instr::Fun(_, f, _) => Instr::Fun(dst, *f, sources[0]),
        Instr::Assign(..) => Instr::Assign(dst, sources[0]),
    }
}

impl Transform {
    /// The same transform with the ops that read no series of coordinate
    /// or velocity `n` or beyond (directly or through other ops) moved
    /// first, in order, and their count in [`Transform::shared`]: for a
    /// variational system over (q, δq) with `n` coordinates, the motion's
    /// part, the same for every column of Φ. Values are unchanged: the ops
    /// moved read nothing the others write.
    pub fn shared(mut self, n: usize) -> Self {
        let mut tangent: HashSet<Series> = HashSet::new();
        let is_tangent = |s: &Series, tangent: &HashSet<Series>| match *s {
            Series::Q(i) | Series::V(i) => i >= n,
            Series::Temp(_) => tangent.contains(s),
        };
        let mut reads_tangent = Vec::with_capacity(self.ops.len());
        for op in &self.ops {
            let t = op.reads().iter().any(|s| is_tangent(s, &tangent));
            if t {
                tangent.extend(op.writes());
            }
            reads_tangent.push(t);
        }
        let (first, rest): (Vec<_>, Vec<_>) =
            (self.ops.into_iter().zip(reads_tangent)).partition(|(_, t)| !t);
        self.shared = Some(first.len());
        self.ops = first.into_iter().chain(rest).map(|(op, _)| op).collect();
        self
    }

    /// The work of the series to `order`, in multiply-adds
    /// ([`Work::multiply_adds`]: each convolution sums k − 1 products of its
    /// history at order k, and every operation is finished once per order;
    /// a whole number).
    pub fn cost(&self, order: usize) -> usize {
        self.work().multiply_adds(order) as usize
    }

    /// Its series operations per order and, of them, its convolutions: for
    /// the generated file's header and the model's `series_work`. A
    /// [`Solve`] counts a convolution per entry of G that varies (its
    /// history) and n² operations (the two triangular solves).
    pub fn work(&self) -> Work {
        let (entries, n) = self
            .solve
            .as_ref()
            .map_or((0, 0), |s| (s.varying().count(), s.x.len()));
        Work {
            operations: self.ops.len() + entries + n * n,
            convolutions: self.convolutions() + entries,
        }
    }

    /// How many of its series operations are convolutions (a loop over the
    /// coefficients so far, where the others take one step per order).
    fn convolutions(&self) -> usize {
        self.ops
            .iter()
            .filter(|op| !matches!(op, Op::Add { .. } | Op::Scale { .. }))
            .count()
    }

    /// For each temporary, whether only its current coefficient is ever
    /// read: it is written by a sum, a scaling or a product and read only
    /// by sums, scalings and the outputs, never by a recurrence (which
    /// reads an operand's lower coefficients, or its own).
    pub fn current_only(&self) -> Vec<bool> {
        let mut only = vec![true; self.temps];
        let mut keep = |s: &Series| {
            if let Series::Temp(i) = s {
                only[*i] = false;
            }
        };
        for op in &self.ops {
            // Sums and scalings read their operands' current coefficients
            // only; every other op reads its operands' lower ones, and all
            // but the plain products their own too.
            if matches!(op, Op::Add { .. } | Op::Scale { .. }) {
                continue;
            }
            op.reads().iter().for_each(&mut keep);
            if !matches!(op, Op::Mul { .. } | Op::Square { .. }) {
                op.writes().iter().for_each(&mut keep);
            }
        }
        // A solve reads G's and x's lower coefficients (h's current one).
        if let Some(solve) = &self.solve {
            solve.varying().for_each(|(_, _, s, _)| keep(&s));
            solve.x.iter().for_each(&mut keep);
        }
        // The shared ops run to the last order before the others start,
        // so what they write and the others read is kept whole.
        if let Some(shared) = self.shared {
            let early: HashSet<Series> = self.ops[..shared].iter().flat_map(Op::writes).collect();
            let outputs = self.outputs.iter().filter_map(|t| match *t {
                Term::Series(s) | Term::Negated(s) => Some(s),
                Term::Number(_) => None,
            });
            (self.ops[shared..].iter().flat_map(Op::reads))
                .chain(outputs)
                .filter(|s| early.contains(s))
                .for_each(|s| keep(&s));
        }
        only
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::function::Function;
    use dalembert_runtime::__private::taylor as tay;

    /// q̈ = −(g/l)·sin q (the pendulum): the transform's series of q is
    /// the solution's, checked against a tiny-step integration of the
    /// same equation through the Taylor polynomial's derivatives at 0
    /// (q₂ = −(g/l) sin q₀ / 2, q₃ = −(g/l) cos q₀ q₁ / 6, …) and by the
    /// energy staying constant along the polynomial.
    #[test]
    fn pendulum_series() {
        // inputs: g, l, q, v; q̈ = -(g * l^-1) * sin(q)
        let (g, l, q, v) = (
            Slot::Input(0),
            Slot::Input(1),
            Slot::Input(2),
            Slot::Input(3),
        );
        let _ = v;
        let p = Program {
            inputs: 4,
            consts: vec![-1.0],
            instrs: vec![
                Instr::Pow(Slot::Temp(0), l, -1),
                Instr::Fun(Slot::Temp(1), Function::Sin, q),
                Instr::Mul(
                    Slot::Out(0),
                    vec![Slot::Const(0), g, Slot::Temp(0), Slot::Temp(1)],
                ),
            ],
            outputs: 1,
        };
        let t = p.taylor(2, 1);
        // Only the product with sin q is series work.
        assert_eq!(t.ops.len(), 2, "{:?}", t.ops);
        // sin and cos q come from a recurrence (each reads the other's
        // lower coefficients); sin q scaled by −g/l is read by the output
        // alone.
        assert_eq!(t.current_only(), vec![false, false, true], "{:?}", t.ops);
        let (gv, lv, q0, v0) = (9.81, 2.0, 0.7, -0.4);
        let numbers = t.number_values(&[gv, lv], |p, x| p.eval(x));
        let e = t.motion(&numbers, &[q0], &[v0], 20);
        let w = gv / lv;
        assert_eq!(e.q[0][1], v0);
        assert!((e.q[0][2] - (-w * q0.sin() / 2.0)).abs() < 1e-16);
        assert!((e.q[0][3] - (-w * q0.cos() * v0 / 6.0)).abs() < 1e-16);
        // Energy ½v² − w cos q along the polynomial, at τ up to 0.2.
        let energy = |tau: f64| {
            let qq = dalembert_runtime::taylor::eval(&e.q[0], 20, tau);
            let vv = dalembert_runtime::taylor::eval(&e.v[0], 20, tau);
            0.5 * vv * vv - w * qq.cos()
        };
        for j in 1..=10 {
            let tau = 0.02 * j as f64;
            assert!((energy(tau) - energy(0.0)).abs() < 1e-14, "{tau}");
        }
    }

    /// The series of output 0 of `p` (inputs: one parameter, unused, then
    /// a coordinate x) along x(t) = `x0` + `slope`·t, to `order`.
    pub(super) fn along_a_line(
        p: &Program,
        x0: f64,
        slope: f64,
        order: usize,
    ) -> dalembert_runtime::taylor::Coefficients {
        let tr = p.taylor(1, 1);
        let mut e = Evaluation {
            q: vec![[0.0; tay::CAPACITY]],
            v: vec![],
            temps: vec![],
            ..Evaluation::default()
        };
        e.q[0][0] = x0;
        e.q[0][1] = slope;
        let numbers = tr.number_values(&[0.0], |p, x| p.eval(x));
        tr.along(&numbers, &mut e, order)
    }

    /// Every kind of instruction: the transform of
    /// o = exp(x)·log(x)·x^-2 + sqrt(x) + x^1.5 + x^10 + 1/sqrt(x) − cos(x)
    /// along x(t) = 2 + t agrees with its values at a few points of t.
    #[test]
    fn every_instruction_along_a_line() {
        let x = Slot::Input(1);
        let t = |k| Slot::Temp(k);
        let p = Program {
            inputs: 2,
            consts: vec![],
            instrs: vec![
                Instr::Fun(t(0), Function::Exp, x),
                Instr::Fun(t(1), Function::Log, x),
                Instr::Pow(t(2), x, -2),
                Instr::Mul(t(3), vec![t(0), t(1), t(2)]),
                Instr::Fun(t(4), Function::Sqrt, x),
                Instr::Powf(t(5), x, 1.5),
                Instr::Pow(t(6), x, 10),
                Instr::Powf(t(7), x, -0.5),
                Instr::Fun(t(8), Function::Cos, x),
                Instr::Add(t(9), vec![t(3), t(4), t(5), t(6), t(7)]),
                Instr::Sub(Slot::Out(0), [t(9), t(8)]),
            ],
            outputs: 1,
        };
        let f = |x: f64| {
            x.exp() * x.ln() / (x * x) + x.sqrt() + x.powf(1.5) + x.powi(10) + 1.0 / x.sqrt()
                - x.cos()
        };
        let c = along_a_line(&p, 2.0, 1.0, 30);
        for tau in [0.0, 0.1, -0.2, 0.3] {
            let got = dalembert_runtime::taylor::eval(&c, 30, tau);
            let want = f(2.0 + tau);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "{tau}: {got} {want}"
            );
        }
    }
}
