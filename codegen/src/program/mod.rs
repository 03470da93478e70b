//! Straight-line numeric programs: what the symbolic stage hands the emitter.
//!
//! A [`Program`] evaluates several outputs from a list of inputs in a fixed
//! sequence of instructions, with common subexpressions already shared (the
//! symbolic engine's evaluator optimisation produces it). It does not depend
//! on the symbolic engine, so the emitter and tests can use it freely.

mod elimination;
mod hoist;
mod linear;
pub mod machine;
mod tangent;
mod taylor;

use std::collections::HashMap;

pub use crate::function::Function;
pub use elimination::Layout;
pub use hoist::{Emit, Role, Split};
pub use linear::{Entry, stored_signs};
pub use taylor::{Evaluation, Op, Series, Solve, Term, Transform};

/// Where a value lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Slot {
    /// The i-th input.
    Input(usize),
    /// The i-th constant.
    Const(usize),
    /// A temporary.
    Temp(usize),
    /// The i-th output.
    Out(usize),
}

/// One instruction.
#[derive(Debug, Clone, PartialEq)]
pub enum Instr {
    /// dst = Σ srcs
    Add(Slot, Vec<Slot>),
    /// dst = a − b (a linear map's terms of opposite signs, so that a
    /// value and its negation can share one slot)
    Sub(Slot, [Slot; 2]),
    /// dst = Π srcs
    Mul(Slot, Vec<Slot>),
    /// dst = src^n
    Pow(Slot, Slot, i64),
    /// dst = src^x for a fractional constant x (½ is a square root)
    Powf(Slot, Slot, f64),
    /// dst = f(src)
    Fun(Slot, Function, Slot),
    /// dst = src
    Assign(Slot, Slot),
}

impl Instr {
    /// Where it writes.
    pub fn dst(&self) -> Slot {
        match self {
            Self::Add(o, _)
            | Self::Sub(o, _)
            | Self::Mul(o, _)
            | Self::Pow(o, _, _)
            | Self::Powf(o, _, _)
            | Self::Fun(o, _, _)
            | Self::Assign(o, _) => *o,
        }
    }

    /// What it reads.
    pub fn sources(&self) -> &[Slot] {
        match self {
            Self::Add(_, s) | Self::Mul(_, s) => s,
            Self::Sub(_, s) => s,
            Self::Pow(_, s, _) | Self::Powf(_, s, _) | Self::Fun(_, _, s) | Self::Assign(_, s) => {
                core::slice::from_ref(s)
            }
        }
    }
}

impl Instr {
    /// The instruction with every slot mapped by `f`.
    pub(crate) fn map_slots(&self, f: impl Fn(Slot) -> Slot) -> Instr {
        let all = |s: &[Slot]| s.iter().map(|&x| f(x)).collect();
        match self {
            Instr::Add(d, s) => Instr::Add(f(*d), all(s)),
            Instr::Sub(d, [a, b]) => Instr::Sub(f(*d), [f(*a), f(*b)]),
            Instr::Mul(d, s) => Instr::Mul(f(*d), all(s)),
            Instr::Pow(d, s, n) => Instr::Pow(f(*d), f(*s), *n),
            Instr::Powf(d, s, x) => Instr::Powf(f(*d), f(*s), *x),
            Instr::Fun(d, g, s) => Instr::Fun(f(*d), *g, f(*s)),
            Instr::Assign(d, s) => Instr::Assign(f(*d), f(*s)),
        }
    }
}

/// A straight-line program.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// Number of inputs.
    pub inputs: usize,
    /// Constant values.
    pub consts: Vec<f64>,
    /// Instructions in order.
    pub instrs: Vec<Instr>,
    /// Number of outputs.
    pub outputs: usize,
}

/// Arithmetic operations a program performs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions (negative powers).
    pub div: usize,
    /// Function calls (sin, cos, ..., and fractional powers).
    pub fun: usize,
}

impl OpCount {
    /// All operations.
    pub fn total(&self) -> usize {
        self.add + self.mul + self.div + self.fun
    }

    /// A rough cost in additions, for choosing between programs that
    /// compute the same thing: a division counts 4 (its throughput is a
    /// fraction of a multiplier's on current cores) and a function call 20
    /// (libm's sin, cos, exp, log and sqrt take tens of cycles).
    pub fn cost(&self) -> usize {
        self.add + self.mul + 4 * self.div + 20 * self.fun
    }
}

impl std::ops::Add for OpCount {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            add: self.add + o.add,
            mul: self.mul + o.mul,
            div: self.div + o.div,
            fun: self.fun + o.fun,
        }
    }
}

impl std::fmt::Display for OpCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} add, {} mul, {} div, {} fn ({} in all)",
            self.add,
            self.mul,
            self.div,
            self.fun,
            self.total()
        )
    }
}

impl Program {
    /// This program's instructions with its outputs turned into temporaries
    /// numbered past every temporary it writes (output k becomes
    /// `Temp(base + k)`), and that base: the start of a longer program that
    /// goes on from these values. Only written slots matter: a temporary
    /// is written before it is read.
    pub(crate) fn outputs_as_temps(&self) -> (Vec<Instr>, usize) {
        let base = self
            .instrs
            .iter()
            .filter_map(|ins| match ins.dst() {
                Slot::Temp(k) => Some(k + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        let instrs = self
            .instrs
            .iter()
            .map(|ins| {
                ins.map_slots(|s| match s {
                    Slot::Out(k) => Slot::Temp(base + k),
                    other => other,
                })
            })
            .collect();
        (instrs, base)
    }

    /// One program that runs `first` and then this one, whose inputs from
    /// `base` on are `first`'s outputs in order (`first` reads inputs below
    /// `base` only): the result has this program's outputs and `base`
    /// inputs.
    pub fn fed_by(&self, first: &Program, base: usize) -> Program {
        debug_assert!(first.inputs <= base && self.inputs == base + first.outputs);
        let (mut instrs, fed) = first.outputs_as_temps();
        let temps = fed + first.outputs;
        let consts = first.consts.len();
        instrs.extend(self.instrs.iter().map(|ins| {
            ins.map_slots(|s| match s {
                Slot::Input(i) if i >= base => Slot::Temp(fed + i - base),
                Slot::Temp(t) => Slot::Temp(temps + t),
                Slot::Const(c) => Slot::Const(consts + c),
                other => other,
            })
        }));
        Program {
            inputs: base,
            consts: first.consts.iter().chain(&self.consts).copied().collect(),
            instrs,
            outputs: self.outputs,
        }
    }

    /// Runs the program on `inputs`, with the emitted code's arithmetic
    /// ([`machine::run`]).
    pub fn eval(&self, inputs: &[f64]) -> Vec<f64> {
        machine::run(self, inputs)
    }

    /// sin and cos of the same value, to be computed together by `sincos` (one
    /// argument reduction instead of two): for each instruction, the number of
    /// its pair and whether it comes first. Slots may be reassigned, so a value
    /// is a slot together with how many times it has been written before.
    pub fn sincos_pairs(&self) -> Vec<Option<(usize, bool)>> {
        let mut writes: HashMap<Slot, usize> = HashMap::new();
        // (source value) → (index of its sin, index of its cos)
        let mut calls: HashMap<(Slot, usize), (Option<usize>, Option<usize>)> = HashMap::new();
        for (i, ins) in self.instrs.iter().enumerate() {
            let dst = ins.dst();
            if let Instr::Fun(_, f, src) = ins {
                let value = (*src, writes.get(src).copied().unwrap_or(0));
                let entry = calls.entry(value).or_default();
                match f {
                    Function::Sin if entry.0.is_none() => entry.0 = Some(i),
                    Function::Cos if entry.1.is_none() => entry.1 = Some(i),
                    _ => {}
                }
            }
            *writes.entry(dst).or_default() += 1;
        }
        let mut found: Vec<(usize, usize)> = calls
            .into_values()
            .filter_map(|(s, c)| Some((s?, c?)))
            .collect();
        found.sort_unstable_by_key(|&(s, c)| s.min(c));
        let mut out = vec![None; self.instrs.len()];
        for (k, (s, c)) in found.into_iter().enumerate() {
            out[s] = Some((k, s < c));
            out[c] = Some((k, c < s));
        }
        out
    }

    /// The operations it performs (a power xⁿ counts |n| − 1 multiplications,
    /// and one division when n < 0).
    pub fn op_count(&self) -> OpCount {
        self.op_count_by(|_, ins| Some(ins.sources().len()))
    }

    /// The operations when `operands` says, for each instruction (by index),
    /// with how many operands a sum or product is computed (`None`: not at
    /// all).
    pub fn op_count_by(&self, operands: impl Fn(usize, &Instr) -> Option<usize>) -> OpCount {
        let mut c = OpCount::default();
        for (i, ins) in self.instrs.iter().enumerate() {
            let Some(k) = operands(i, ins) else { continue };
            match ins {
                Instr::Add(..) | Instr::Sub(..) => c.add += k.saturating_sub(1),
                Instr::Mul(..) => c.mul += k.saturating_sub(1),
                Instr::Pow(_, _, n) => {
                    c.mul += (n.unsigned_abs() as usize).saturating_sub(1);
                    if *n < 0 {
                        c.div += 1;
                    }
                }
                Instr::Fun(..) | Instr::Powf(..) => c.fun += 1,
                Instr::Assign(..) => {}
            }
        }
        c
    }
}

/// The slot of constant `x` in `consts`, added if it is not there yet.
fn constant(consts: &mut Vec<f64>, x: f64) -> Slot {
    let k = consts.iter().position(|c| *c == x).unwrap_or_else(|| {
        consts.push(x);
        consts.len() - 1
    });
    Slot::Const(k)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sin and cos pair up only when they take the same value: a slot
    /// written again between them holds a different one.
    #[test]
    fn sincos_pairs_follow_values_not_slot_names() {
        let (x, t) = (Slot::Input(0), Slot::Temp(0));
        let p = Program {
            inputs: 1,
            consts: vec![1.0],
            instrs: vec![
                Instr::Add(t, vec![x, Slot::Const(0)]),
                Instr::Fun(Slot::Out(0), Function::Sin, t),
                Instr::Add(t, vec![x, x]),
                Instr::Fun(Slot::Out(1), Function::Cos, t),
                Instr::Fun(Slot::Out(2), Function::Cos, x),
                Instr::Fun(Slot::Out(3), Function::Sin, x),
            ],
            outputs: 4,
        };
        assert_eq!(
            p.sincos_pairs(),
            vec![None, None, None, None, Some((0, true)), Some((0, false))]
        );
    }

    /// A program fed by another computes what the two compute one after
    /// the other: the second's extra input is the first's output.
    #[test]
    fn fed_by_runs_both_in_turn() {
        // first: k = 2·p (p the only parameter); then: out = k·x + 1.
        let first = Program {
            inputs: 1,
            consts: vec![2.0],
            instrs: vec![
                Instr::Mul(Slot::Temp(0), vec![Slot::Const(0), Slot::Input(0)]),
                Instr::Assign(Slot::Out(0), Slot::Temp(0)),
            ],
            outputs: 1,
        };
        let then = Program {
            inputs: 3,
            consts: vec![1.0],
            instrs: vec![
                Instr::Mul(Slot::Temp(0), vec![Slot::Input(2), Slot::Input(1)]),
                Instr::Add(Slot::Out(0), vec![Slot::Temp(0), Slot::Const(0)]),
            ],
            outputs: 1,
        };
        let both = then.fed_by(&first, 2);
        assert_eq!(both.inputs, 2);
        assert_eq!(both.eval(&[3.0, 5.0]), vec![31.0]);
    }
}
