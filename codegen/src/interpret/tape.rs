//! A [`Program`] made ready to run many times: slots become indices into one
//! register file (inputs, constants, temporaries, outputs), and every
//! instruction becomes the operation the emitted Rust performs, in the same
//! order, with the same libm functions (sin and cos of one value by one
//! `sincos`, as emitted) — so that the interpreted value and the compiled
//! one are the same floating-point number.

use dalembert_runtime::libm;

use crate::program::{Func, Instr, Program, Slot};

/// One operation on the register file (destination first).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    /// a + b
    Add(u32, u32, u32),
    /// Σ of `len` registers listed in `args` from `start`, left to right.
    Sum(u32, u32, u32),
    /// a · b
    Mul(u32, u32, u32),
    /// Π of `len` registers listed in `args` from `start`, left to right.
    Product(u32, u32, u32),
    /// −x
    Neg(u32, u32),
    /// x
    Copy(u32, u32),
    /// A constant.
    Set(u32, f64),
    /// x · x · … · x (`m` factors, 2 ≤ m ≤ 8), as the emitted code writes
    /// small powers.
    Power(u32, u32, u32),
    /// libm's pow(x, e).
    Pow(u32, u32, f64),
    /// 1 / x
    Recip(u32, u32),
    /// libm's sqrt.
    Sqrt(u32, u32),
    /// 1 / sqrt(x)
    RecipSqrt(u32, u32),
    /// libm's sin and cos of x together (sin, cos, x), as the emitted code
    /// computes a pair.
    SinCos(u32, u32, u32),
    /// libm's sin.
    Sin(u32, u32),
    /// libm's cos.
    Cos(u32, u32),
    /// libm's exp.
    Exp(u32, u32),
    /// libm's log.
    Log(u32, u32),
}

/// A program as register operations.
#[derive(Clone, Debug)]
pub(super) struct Tape {
    ops: Vec<Op>,
    /// Operands of `Sum` and `Product`.
    args: Vec<u32>,
    /// The register file before a run: zero inputs, the constants, zero
    /// temporaries and outputs.
    pub(super) init: Vec<f64>,
    /// Number of inputs (registers `0..inputs`).
    pub(super) inputs: usize,
    /// The first output's register.
    out_base: usize,
    /// Number of outputs.
    outputs: usize,
}

impl Tape {
    /// Lays out the registers and translates the instructions.
    pub(super) fn new(p: &Program) -> Self {
        let temps = p
            .instrs
            .iter()
            .flat_map(slots)
            .filter_map(|s| match s {
                Slot::Temp(i) => Some(i + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        let const_base = p.inputs;
        let temp_base = const_base + p.consts.len();
        let out_base = temp_base + temps;
        let pairs = p.sincos_pairs();
        let npairs = pairs
            .iter()
            .flatten()
            .map(|&(k, _)| k + 1)
            .max()
            .unwrap_or(0);
        let pair_base = out_base + p.outputs;
        let mut init = vec![0.0; pair_base + 2 * npairs];
        init[const_base..temp_base].copy_from_slice(&p.consts);
        let reg = |s: Slot| {
            (match s {
                Slot::Input(i) => i,
                Slot::Const(i) => const_base + i,
                Slot::Temp(i) => temp_base + i,
                Slot::Out(i) => out_base + i,
            }) as u32
        };
        let mut t = Self {
            ops: Vec::with_capacity(p.instrs.len()),
            args: Vec::new(),
            init,
            inputs: p.inputs,
            out_base,
            outputs: p.outputs,
        };
        for (ins, pair) in p.instrs.iter().zip(pairs) {
            match (ins, pair) {
                (Instr::Fun(d, f, x), Some((k, first))) => {
                    // The pair's sin and cos live in two registers of their own.
                    let (sin, cos) = ((pair_base + 2 * k) as u32, (pair_base + 2 * k + 1) as u32);
                    if first {
                        t.ops.push(Op::SinCos(sin, cos, reg(*x)));
                    }
                    let mine = if *f == Func::Sin { sin } else { cos };
                    t.ops.push(Op::Copy(reg(*d), mine));
                }
                _ => t.translate(p, ins, &reg),
            }
        }
        t
    }

    fn translate(&mut self, p: &Program, ins: &Instr, reg: &impl Fn(Slot) -> u32) {
        match ins {
            Instr::Add(d, s) => {
                let s: Vec<u32> = s.iter().map(|&x| reg(x)).collect();
                self.nary(reg(*d), &s, Op::Add, Op::Sum);
            }
            Instr::Mul(d, s) => {
                // As emitted: factors −1 dropped, the product negated when
                // their number is odd.
                let minus_one = |x: &Slot| matches!(x, Slot::Const(i) if p.consts[*i] == -1.0);
                let rest: Vec<u32> = s
                    .iter()
                    .filter(|x| !minus_one(x))
                    .map(|&x| reg(x))
                    .collect();
                let negate = (s.len() - rest.len()) % 2 == 1;
                let d = reg(*d);
                if rest.is_empty() {
                    self.ops.push(Op::Set(d, if negate { -1.0 } else { 1.0 }));
                    return;
                }
                self.nary(d, &rest, Op::Mul, Op::Product);
                if negate {
                    self.ops.push(Op::Neg(d, d));
                }
            }
            Instr::Pow(d, s, n) => {
                let (d, s, m) = (reg(*d), reg(*s), n.unsigned_abs());
                self.ops.push(match m {
                    0 => Op::Set(d, 1.0),
                    1 => Op::Copy(d, s),
                    2..=8 => Op::Power(d, s, m as u32),
                    _ => Op::Pow(d, s, m as f64),
                });
                if *n < 0 {
                    self.ops.push(Op::Recip(d, d));
                }
            }
            Instr::Powf(d, s, e) => {
                let (d, s) = (reg(*d), reg(*s));
                self.ops.push(if *e == 0.5 {
                    Op::Sqrt(d, s)
                } else if *e == -0.5 {
                    Op::RecipSqrt(d, s)
                } else {
                    Op::Pow(d, s, *e)
                });
            }
            Instr::Fun(d, f, s) => {
                let (d, s) = (reg(*d), reg(*s));
                self.ops.push(match f {
                    Func::Sin => Op::Sin(d, s),
                    Func::Cos => Op::Cos(d, s),
                    Func::Exp => Op::Exp(d, s),
                    Func::Log => Op::Log(d, s),
                    Func::Sqrt => Op::Sqrt(d, s),
                });
            }
            Instr::Assign(d, s) => self.ops.push(Op::Copy(reg(*d), reg(*s))),
        }
    }

    /// A sum or product of `operands`: a copy of one, the binary op for
    /// two, the listed op for more.
    fn nary(
        &mut self,
        d: u32,
        operands: &[u32],
        two: fn(u32, u32, u32) -> Op,
        many: fn(u32, u32, u32) -> Op,
    ) {
        match *operands {
            [] => self.ops.push(Op::Set(d, 0.0)),
            [a] => self.ops.push(Op::Copy(d, a)),
            [a, b] => self.ops.push(two(d, a, b)),
            _ => {
                let start = self.args.len() as u32;
                self.args.extend_from_slice(operands);
                self.ops.push(many(d, start, operands.len() as u32));
            }
        }
    }

    /// Runs the operations on `r` (a copy of [`Tape::init`] with the inputs
    /// filled in).
    pub(super) fn run(&self, r: &mut [f64]) {
        let at = |i: u32| i as usize;
        for op in &self.ops {
            match *op {
                Op::Add(d, a, b) => r[at(d)] = r[at(a)] + r[at(b)],
                Op::Sum(d, s, n) => {
                    let args = &self.args[at(s)..at(s) + at(n)];
                    let mut acc = r[at(args[0])];
                    for &a in &args[1..] {
                        acc += r[at(a)];
                    }
                    r[at(d)] = acc;
                }
                Op::Mul(d, a, b) => r[at(d)] = r[at(a)] * r[at(b)],
                Op::Product(d, s, n) => {
                    let args = &self.args[at(s)..at(s) + at(n)];
                    let mut acc = r[at(args[0])];
                    for &a in &args[1..] {
                        acc *= r[at(a)];
                    }
                    r[at(d)] = acc;
                }
                Op::Neg(d, x) => r[at(d)] = -r[at(x)],
                Op::Copy(d, x) => r[at(d)] = r[at(x)],
                Op::Set(d, c) => r[at(d)] = c,
                Op::Power(d, x, m) => {
                    let x = r[at(x)];
                    let mut acc = x;
                    for _ in 1..m {
                        acc *= x;
                    }
                    r[at(d)] = acc;
                }
                Op::Pow(d, x, e) => r[at(d)] = libm::pow(r[at(x)], e),
                Op::Recip(d, x) => r[at(d)] = 1.0 / r[at(x)],
                Op::Sqrt(d, x) => r[at(d)] = libm::sqrt(r[at(x)]),
                Op::RecipSqrt(d, x) => r[at(d)] = 1.0 / libm::sqrt(r[at(x)]),
                Op::SinCos(s, c, x) => (r[at(s)], r[at(c)]) = libm::sincos(r[at(x)]),
                Op::Sin(d, x) => r[at(d)] = libm::sin(r[at(x)]),
                Op::Cos(d, x) => r[at(d)] = libm::cos(r[at(x)]),
                Op::Exp(d, x) => r[at(d)] = libm::exp(r[at(x)]),
                Op::Log(d, x) => r[at(d)] = libm::log(r[at(x)]),
            }
        }
    }

    /// The outputs in a register file after [`Tape::run`].
    pub(super) fn outputs<'r>(&self, r: &'r [f64]) -> &'r [f64] {
        &r[self.out_base..self.out_base + self.outputs]
    }
}

/// Every slot an instruction reads or writes.
fn slots(ins: &Instr) -> Vec<Slot> {
    match ins {
        Instr::Add(d, s) | Instr::Mul(d, s) => {
            std::iter::once(*d).chain(s.iter().copied()).collect()
        }
        Instr::Pow(d, s, _) | Instr::Powf(d, s, _) | Instr::Fun(d, _, s) | Instr::Assign(d, s) => {
            vec![*d, *s]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(p: &Program, inputs: &[f64]) -> Vec<f64> {
        let t = Tape::new(p);
        let mut r = t.init.clone();
        r[..inputs.len()].copy_from_slice(inputs);
        t.run(&mut r);
        t.outputs(&r).to_vec()
    }

    /// Each instruction computes what the emitted code computes, bit for
    /// bit: sums and products left to right, −1 factors as a negation,
    /// small powers as products, large and negative ones through pow and a
    /// reciprocal, ±½ powers as square roots, sin and cos of one value by
    /// one sincos.
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
                Instr::Fun(t1, Func::Sin, x),
                Instr::Fun(Slot::Out(5), Func::Exp, t1),
                Instr::Mul(Slot::Out(6), vec![Slot::Const(0), Slot::Const(0)]),
                Instr::Assign(Slot::Out(7), t0),
                Instr::Fun(Slot::Out(8), Func::Cos, x),
            ],
            outputs: 9,
        };
        let (a, b) = (0.7312_f64, 2.25_f64);
        let got = run(&p, &[a, b]);
        let s = a + b + 3.0;
        let want = [
            -(s * b),
            a * a * a * a * a * a * a,
            1.0 / libm::pow(a, 11.0),
            1.0 / libm::sqrt(b),
            libm::pow(b, 1.5),
            libm::exp(libm::sincos(a).0),
            1.0,
            s,
            libm::sincos(a).1,
        ];
        for (g, w) in got.iter().zip(want) {
            assert_eq!(g.to_bits(), w.to_bits(), "{got:?} vs {want:?}");
        }
    }
}
