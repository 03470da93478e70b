//! A [`Program`] made ready to run many times. Every instruction becomes the
//! operation the emitted Rust performs, in the same form and with the same
//! libm functions (sin and cos of one value by one `sincos`, as emitted), so
//! that the interpreted value and the compiled one are the same
//! floating-point number.
//!
//! For speed the operations are not run one by one in program order, where
//! each would be a hard-to-predict jump on its kind. Every value gets a
//! register of its own (the program's temporaries are reused slots; here no
//! register is written twice), each operation gets a level (one more than
//! the highest level of what it reads), and the operations are run level by
//! level, all of one kind of a level in one loop. Operations of one level do
//! not depend on each other, so the order among them cannot change a value.
//! A copy (`t = o`) costs nothing: the slot just names the value's register.

use std::collections::HashMap;
use std::ops::{Add, Mul, Neg, Sub};

use dalembert_runtime::interval::Interval;
use dalembert_runtime::libm;

use crate::program::machine::{Machine, Operand, lower};
use crate::program::{Function, Program, Slot};

/// What an operation does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Kind {
    /// a + b
    Add,
    /// a − b
    Sub,
    /// Σ of `b` registers listed in `args` from `a`, left to right.
    Sum,
    /// a · b
    Mul,
    /// Π of `b` registers listed in `args` from `a`, left to right.
    Product,
    /// −a
    Neg,
    /// The constant x.
    Set,
    /// a · a · … · a (`b` factors, 2 ≤ b ≤ 8), as the emitted code writes
    /// small powers.
    Power,
    /// libm's pow(a, x).
    Pow,
    /// 1 / a
    Recip,
    /// libm's sqrt.
    Sqrt,
    /// 1 / sqrt(a)
    RecipSqrt,
    /// libm's sincos(a): sin into d, cos into b.
    SinCos,
    /// libm's function of that name.
    Call(Function),
}

/// One operation: destination `d` and operands `a`, `b`, as its kind uses
/// them (a number, for `Set` and `Pow`, is `numbers[b]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Op {
    d: u32,
    a: u32,
    b: u32,
}

/// Operations of one kind and one level: `ops[start..end]`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Run {
    kind: Kind,
    start: u32,
    end: u32,
}

/// A program as register operations.
#[derive(Clone, Debug)]
pub(super) struct Tape {
    ops: Vec<Op>,
    runs: Vec<Run>,
    /// Operands of `Sum` and `Product`.
    args: Vec<u32>,
    /// Numbers of `Set` and `Pow`.
    numbers: Vec<f64>,
    /// The register file before a run: zero inputs, the constants, zeros.
    pub(super) init: Vec<f64>,
    /// Number of inputs (registers `0..inputs`).
    pub(super) inputs: usize,
    /// The register holding each output's final value.
    outputs: Vec<u32>,
    /// Where the outputs are gathered after a run.
    out_base: usize,
}

/// The operations in program order while they are being made, with each
/// register's level.
struct Builder {
    ops: Vec<(Kind, Op)>,
    args: Vec<u32>,
    numbers: Vec<f64>,
    level: Vec<u32>,
    /// The register of each slot's current value.
    current: HashMap<Slot, u32>,
    /// A register holding zero (an output never written).
    zero: u32,
}

impl Builder {
    fn read(&self, s: Slot) -> u32 {
        self.current.get(&s).copied().unwrap_or(self.zero)
    }

    /// A new register written by an operation that reads `sources`.
    fn fresh(&mut self, sources: &[u32]) -> u32 {
        let level = sources
            .iter()
            .map(|&r| self.level[r as usize])
            .max()
            .unwrap_or(0)
            + 1;
        self.level.push(level);
        (self.level.len() - 1) as u32
    }

    fn push(&mut self, kind: Kind, a: u32, b: u32, sources: &[u32]) -> u32 {
        let d = self.fresh(sources);
        self.ops.push((kind, Op { d, a, b }));
        d
    }

    fn unary(&mut self, kind: Kind, a: u32) -> u32 {
        self.push(kind, a, 0, &[a])
    }

    /// An operation of a number (`Set`, `Pow`).
    fn with_number(&mut self, kind: Kind, a: u32, x: f64, sources: &[u32]) -> u32 {
        self.numbers.push(x);
        let b = (self.numbers.len() - 1) as u32;
        self.push(kind, a, b, sources)
    }

    /// A sum or product of `operands`: the one itself (no operation), the
    /// binary kind for two, the listed kind for more.
    fn nary(&mut self, operands: &[u32], two: Kind, many: Kind) -> u32 {
        match *operands {
            [] => self.with_number(Kind::Set, 0, 0.0, &[]),
            [a] => a,
            [a, b] => self.push(two, a, b, &[a, b]),
            _ => {
                let start = self.args.len() as u32;
                self.args.extend_from_slice(operands);
                self.push(many, start, operands.len() as u32, operands)
            }
        }
    }

    fn operand(&self, o: &Operand) -> u32 {
        match *o {
            Operand::Slot(s) => self.read(s),
            Operand::Kept(_) => unreachable!("the interpreter keeps no values per parameter set"),
        }
    }

    /// The register of an instruction's value, from its machine form: one
    /// operation for each the emitted statement performs, in its order.
    fn translate(&mut self, m: &Machine, pairs: &mut HashMap<usize, (u32, u32)>) -> u32 {
        let over = |b: &mut Self, reciprocal: bool, x: u32| {
            if reciprocal {
                b.unary(Kind::Recip, x)
            } else {
                x
            }
        };
        match m {
            Machine::Sum(terms) => {
                let s: Vec<u32> = terms.iter().map(|o| self.operand(o)).collect();
                self.nary(&s, Kind::Add, Kind::Sum)
            }
            Machine::Difference(x, y) => {
                let (a, b) = (self.read(*x), self.read(*y));
                self.push(Kind::Sub, a, b, &[a, b])
            }
            Machine::Product { factors, negate } => {
                let s: Vec<u32> = factors.iter().map(|o| self.operand(o)).collect();
                let product = self.nary(&s, Kind::Mul, Kind::Product);
                if *negate {
                    self.unary(Kind::Neg, product)
                } else {
                    product
                }
            }
            Machine::Number(x) => self.with_number(Kind::Set, 0, *x, &[]),
            Machine::Power { x, n, reciprocal } => {
                let a = self.read(*x);
                let power = match n {
                    1 => a,
                    _ => self.push(Kind::Power, a, *n, &[a]),
                };
                over(self, *reciprocal, power)
            }
            Machine::Pow { x, e, reciprocal } => {
                let a = self.read(*x);
                let power = self.with_number(Kind::Pow, a, *e, &[a]);
                over(self, *reciprocal, power)
            }
            Machine::Sqrt { x, reciprocal } => {
                let a = self.read(*x);
                let kind = if *reciprocal {
                    Kind::RecipSqrt
                } else {
                    Kind::Sqrt
                };
                self.unary(kind, a)
            }
            Machine::Call(f, x) => {
                let a = self.read(*x);
                self.unary(Kind::Call(*f), a)
            }
            Machine::SinCos { x, pair, sin } => {
                let a = self.read(*x);
                let (s, c) = (self.fresh(&[a]), self.fresh(&[a]));
                self.ops.push((Kind::SinCos, Op { d: s, a, b: c }));
                pairs.insert(*pair, (s, c));
                if *sin { s } else { c }
            }
            Machine::Half { pair, sin } => {
                let (s, c) = pairs[pair];
                if *sin { s } else { c }
            }
            // A copy needs no operation: the slot now names the value's register.
            Machine::Copy(x) => self.read(*x),
        }
    }
}

/// What a register holds: an f64 (the values the emitted code computes,
/// bit for bit), or an interval (bounds over a box of inputs, as the
/// emitted `_bounds` functions compute them).
pub(super) trait Register:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// A number.
    fn number(x: f64) -> Self;
    /// x · x · … · x, `n` factors.
    fn power(self, n: u32) -> Self;
    /// libm's pow(x, e).
    fn pow(self, e: f64) -> Self;
    /// 1 / x.
    fn recip(self) -> Self;
    /// √x.
    fn sqrt(self) -> Self;
    /// sin x and cos x.
    fn sincos(self) -> (Self, Self);
    /// The function `f` on this kind of value.
    fn function(f: Function) -> fn(Self) -> Self;
}

impl Register for f64 {
    fn number(x: f64) -> Self {
        x
    }
    fn power(self, n: u32) -> Self {
        let mut acc = self;
        for _ in 1..n {
            acc *= self;
        }
        acc
    }
    fn pow(self, e: f64) -> Self {
        libm::pow(self, e)
    }
    fn recip(self) -> Self {
        1.0 / self
    }
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    fn sincos(self) -> (Self, Self) {
        libm::sincos(self)
    }
    fn function(f: Function) -> fn(Self) -> Self {
        f.libm()
    }
}

impl Register for Interval {
    fn number(x: f64) -> Self {
        Interval::point(x)
    }
    fn power(self, n: u32) -> Self {
        self.powi(n)
    }
    fn pow(self, e: f64) -> Self {
        Interval::pow(self, e)
    }
    fn recip(self) -> Self {
        Interval::recip(self)
    }
    fn sqrt(self) -> Self {
        Interval::sqrt(self)
    }
    fn sincos(self) -> (Self, Self) {
        Interval::sincos(self)
    }
    fn function(f: Function) -> fn(Self) -> Self {
        f.interval()
    }
}

impl Tape {
    /// Translates the instructions and orders them by level and kind.
    pub(super) fn new(p: &Program) -> Self {
        // Registers: inputs, constants, a zero, then one per value.
        let zero = (p.inputs + p.consts.len()) as u32;
        let mut b = Builder {
            ops: Vec::with_capacity(p.instrs.len()),
            args: Vec::new(),
            numbers: Vec::new(),
            level: vec![0; zero as usize + 1],
            current: HashMap::new(),
            zero,
        };
        for i in 0..p.inputs {
            b.current.insert(Slot::Input(i), i as u32);
        }
        for k in 0..p.consts.len() {
            b.current.insert(Slot::Const(k), (p.inputs + k) as u32);
        }
        let mut pairs: HashMap<usize, (u32, u32)> = HashMap::new();
        for (ins, m) in p.instrs.iter().zip(lower(p, |_| true)) {
            let value = b.translate(&m.expect("every instruction is computed"), &mut pairs);
            b.current.insert(ins.dst(), value);
        }
        let outputs: Vec<u32> = (0..p.outputs).map(|i| b.read(Slot::Out(i))).collect();
        // Stable: within a level and kind, program order.
        let mut ordered = b.ops;
        ordered.sort_by_key(|(kind, op)| (b.level[op.d as usize], *kind));
        let mut runs: Vec<Run> = Vec::new();
        for (i, (kind, op)) in ordered.iter().enumerate() {
            let level = b.level[op.d as usize];
            match runs.last_mut() {
                Some(r)
                    if r.kind == *kind
                        && b.level[ordered[r.start as usize].1.d as usize] == level =>
                {
                    r.end = i as u32 + 1;
                }
                _ => runs.push(Run {
                    kind: *kind,
                    start: i as u32,
                    end: i as u32 + 1,
                }),
            }
        }
        let out_base = b.level.len();
        let mut init = vec![0.0; out_base + p.outputs];
        init[p.inputs..zero as usize].copy_from_slice(&p.consts);
        Self {
            ops: ordered.into_iter().map(|(_, op)| op).collect(),
            runs,
            args: b.args,
            numbers: b.numbers,
            init,
            inputs: p.inputs,
            outputs,
            out_base,
        }
    }

    /// Runs the operations on `r` (a copy of [`Tape::init`], as numbers or
    /// points, with the inputs filled in).
    pub(super) fn run<T: Register>(&self, r: &mut [T]) {
        let at = |i: u32| i as usize;
        for run in &self.runs {
            let ops = &self.ops[at(run.start)..at(run.end)];
            macro_rules! each {
                (|$op:ident| $body:expr) => {
                    for $op in ops {
                        $body;
                    }
                };
            }
            match run.kind {
                Kind::Add => each!(|o| r[at(o.d)] = r[at(o.a)] + r[at(o.b)]),
                Kind::Sub => each!(|o| r[at(o.d)] = r[at(o.a)] - r[at(o.b)]),
                Kind::Mul => each!(|o| r[at(o.d)] = r[at(o.a)] * r[at(o.b)]),
                Kind::Sum => each!(|o| {
                    let args = &self.args[at(o.a)..at(o.a) + at(o.b)];
                    let mut acc = r[at(args[0])];
                    for &a in &args[1..] {
                        acc = acc + r[at(a)];
                    }
                    r[at(o.d)] = acc
                }),
                Kind::Product => each!(|o| {
                    let args = &self.args[at(o.a)..at(o.a) + at(o.b)];
                    let mut acc = r[at(args[0])];
                    for &a in &args[1..] {
                        acc = acc * r[at(a)];
                    }
                    r[at(o.d)] = acc
                }),
                Kind::Neg => each!(|o| r[at(o.d)] = -r[at(o.a)]),
                Kind::Set => each!(|o| r[at(o.d)] = T::number(self.numbers[at(o.b)])),
                Kind::Power => each!(|o| r[at(o.d)] = r[at(o.a)].power(o.b)),
                Kind::Pow => each!(|o| r[at(o.d)] = r[at(o.a)].pow(self.numbers[at(o.b)])),
                Kind::Recip => each!(|o| r[at(o.d)] = r[at(o.a)].recip()),
                Kind::Sqrt => each!(|o| r[at(o.d)] = r[at(o.a)].sqrt()),
                Kind::RecipSqrt => each!(|o| r[at(o.d)] = r[at(o.a)].sqrt().recip()),
                Kind::SinCos => each!(|o| (r[at(o.d)], r[at(o.b)]) = r[at(o.a)].sincos()),
                Kind::Call(f) => {
                    let f = T::function(f);
                    each!(|o| r[at(o.d)] = f(r[at(o.a)]))
                }
            }
        }
        for (k, &o) in self.outputs.iter().enumerate() {
            r[self.out_base + k] = r[at(o)];
        }
    }

    /// The outputs in a register file after [`Tape::run`].
    pub(super) fn outputs<'r, T>(&self, r: &'r [T]) -> &'r [T] {
        &r[self.out_base..self.out_base + self.outputs.len()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Instr;

    fn run(p: &Program, inputs: &[f64]) -> Vec<f64> {
        let t = Tape::new(p);
        let mut r = t.init.clone();
        r[..inputs.len()].copy_from_slice(inputs);
        t.run(&mut r);
        t.outputs(&r).to_vec()
    }

    /// Each instruction computes what the emitted code computes, bit for
    /// bit: sums and products left to right, a difference, −1 factors as a
    /// negation, small powers as products, large and negative ones through
    /// pow and a reciprocal, ±½ powers as square roots, sin and cos of one
    /// value by one sincos; a temporary written twice holds each value in
    /// turn.
    #[test]
    fn instructions_match_the_emitted_arithmetic() {
        let (x, y) = (Slot::Input(0), Slot::Input(1));
        let (t0, t1) = (Slot::Temp(0), Slot::Temp(1));
        let p = Program {
            inputs: 2,
            consts: vec![-1.0, 3.0],
            instrs: vec![
                Instr::Add(t0, vec![x, y, Slot::Const(1)]),
                Instr::Mul(Slot::Out(0), vec![Slot::Const(0), t0, y]),
                Instr::Pow(Slot::Out(1), x, 7),
                Instr::Pow(Slot::Out(2), x, -11),
                Instr::Powf(Slot::Out(3), y, -0.5),
                Instr::Powf(Slot::Out(4), y, 1.5),
                Instr::Fun(t1, Function::Sin, x),
                Instr::Fun(Slot::Out(5), Function::Exp, t1),
                Instr::Mul(Slot::Out(6), vec![Slot::Const(0), Slot::Const(0)]),
                Instr::Assign(Slot::Out(7), t0),
                Instr::Fun(Slot::Out(8), Function::Cos, x),
                Instr::Add(t0, vec![t0, t1]),
                Instr::Mul(Slot::Out(9), vec![t0, t0]),
                Instr::Sub(Slot::Out(11), [y, t1]),
            ],
            outputs: 12,
        };
        let (a, b) = (0.7312_f64, 2.25_f64);
        let got = run(&p, &[a, b]);
        let s = a + b + 3.0;
        let (sin, cos) = libm::sincos(a);
        let want = [
            -(s * b),
            a * a * a * a * a * a * a,
            1.0 / libm::pow(a, 11.0),
            1.0 / libm::sqrt(b),
            libm::pow(b, 1.5),
            libm::exp(sin),
            1.0,
            s,
            cos,
            (s + sin) * (s + sin),
            0.0,
            b - sin,
        ];
        for (g, w) in got.iter().zip(want) {
            assert_eq!(g.to_bits(), w.to_bits(), "{got:?} vs {want:?}");
        }
        // The reference evaluation reads the same machine form.
        let reference = p.eval(&[a, b]);
        for (g, r) in got.iter().zip(&reference) {
            assert_eq!(g.to_bits(), r.to_bits(), "{got:?} vs {reference:?}");
        }
    }
}
