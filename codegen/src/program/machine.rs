//! A program's instructions in machine form: every arithmetic decision the
//! back ends would otherwise each make, made here once. A factor −1 is a
//! negation of the product; xⁿ is n − 1 products up to n = 8 and libm's pow
//! above; x^±½ is a square root; sin and cos of one value are one `sincos`
//! where both are computed; a product of −1s alone is the number ±1. The
//! emitter writes each [`Machine`] as one Rust statement and the
//! interpreter as register operations, neither deciding anything of its
//! own, so the two compute the same floating-point numbers.

use std::collections::HashMap;

use super::{Function, Instr, Program, Slot};

/// An operand: a slot of the program, or a parameter-only value kept in the
/// model (`pre[k]`, see [`super::Emit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Operand {
    /// A slot.
    Slot(Slot),
    /// The k-th kept value.
    Kept(usize),
}

/// One instruction in machine form.
#[derive(Debug, Clone, PartialEq)]
pub enum Machine {
    /// Σ operands, left to right (one operand: that value).
    Sum(Vec<Operand>),
    /// a − b
    Difference(Slot, Slot),
    /// Π factors, left to right (one factor: that value), negated when
    /// `negate`; never without factors (that is [`Machine::Number`]).
    Product {
        /// The factors, −1s removed.
        factors: Vec<Operand>,
        /// Whether the number of −1s removed was odd.
        negate: bool,
    },
    /// The number x.
    Number(f64),
    /// x · x · … · x (`n` factors, 1 ≤ n ≤ 8), or 1 over it.
    Power {
        /// The base.
        x: Slot,
        /// The number of factors.
        n: u32,
        /// 1 over the product.
        reciprocal: bool,
    },
    /// libm's pow(x, e), or 1 over it.
    Pow {
        /// The base.
        x: Slot,
        /// The exponent.
        e: f64,
        /// 1 over the power.
        reciprocal: bool,
    },
    /// libm's sqrt(x), or 1 over it.
    Sqrt {
        /// The argument.
        x: Slot,
        /// 1 over the root.
        reciprocal: bool,
    },
    /// libm's function of that name of x (never sqrt: that is
    /// [`Machine::Sqrt`]).
    Call(Function, Slot),
    /// The first of a sin/cos pair: libm's sincos(x) computes both, and
    /// this instruction takes the sine (`sin`) or the cosine.
    SinCos {
        /// The argument.
        x: Slot,
        /// The pair's number ([`Program::sincos_pairs`]).
        pair: usize,
        /// Whether this instruction is the sine.
        sin: bool,
    },
    /// The second of a sin/cos pair: the half its first computed.
    Half {
        /// The pair's number.
        pair: usize,
        /// Whether this instruction is the sine.
        sin: bool,
    },
    /// A copy of a slot.
    Copy(Slot),
}

impl Machine {
    /// The slots it reads (a pair's second half reads none: its first did).
    pub fn slots(&self) -> Vec<Slot> {
        let operands = |xs: &[Operand]| {
            (xs.iter())
                .filter_map(|o| match o {
                    Operand::Slot(s) => Some(*s),
                    Operand::Kept(_) => None,
                })
                .collect()
        };
        match self {
            Self::Sum(xs) | Self::Product { factors: xs, .. } => operands(xs),
            Self::Difference(a, b) => vec![*a, *b],
            Self::Number(_) | Self::Half { .. } => vec![],
            Self::Power { x, .. }
            | Self::Pow { x, .. }
            | Self::Sqrt { x, .. }
            | Self::Call(_, x)
            | Self::SinCos { x, .. }
            | Self::Copy(x) => vec![*x],
        }
    }
}

/// Each instruction of `p` in machine form, `None` where `computed` says it
/// is not computed here; sin and cos of one value are a pair where both are
/// computed.
pub fn lower(p: &Program, computed: impl Fn(usize) -> bool) -> Vec<Option<Machine>> {
    let pairs = p.sincos_pairs();
    // How many halves of each pair are computed.
    let mut halves = vec![0usize; pairs.iter().flatten().count() / 2];
    for (i, pair) in pairs.iter().enumerate() {
        if let Some((k, _)) = pair.filter(|_| computed(i)) {
            halves[k] += 1;
        }
    }
    (p.instrs.iter().zip(&pairs).enumerate())
        .map(|(i, (ins, pair))| {
            if !computed(i) {
                return None;
            }
            Some(match (ins, pair) {
                (Instr::Fun(_, f, x), Some((k, first))) if halves[*k] == 2 => {
                    let sin = *f == Function::Sin;
                    if *first {
                        Machine::SinCos {
                            x: *x,
                            pair: *k,
                            sin,
                        }
                    } else {
                        Machine::Half { pair: *k, sin }
                    }
                }
                _ => instruction(p, ins),
            })
        })
        .collect()
}

/// `ins` alone in machine form (sin and cos not paired).
fn instruction(p: &Program, ins: &Instr) -> Machine {
    match ins {
        Instr::Add(_, s) => Machine::Sum(s.iter().map(|&x| Operand::Slot(x)).collect()),
        Instr::Sub(_, [a, b]) => Machine::Difference(*a, *b),
        Instr::Mul(_, s) => product(p, None, s),
        Instr::Pow(_, x, n) => {
            let (m, reciprocal) = (n.unsigned_abs(), *n < 0);
            match m {
                0 => Machine::Number(1.0),
                1..=8 => Machine::Power {
                    x: *x,
                    n: m as u32,
                    reciprocal,
                },
                _ => Machine::Pow {
                    x: *x,
                    e: m as f64,
                    reciprocal,
                },
            }
        }
        Instr::Powf(_, x, e) if e.abs() == 0.5 => Machine::Sqrt {
            x: *x,
            reciprocal: *e < 0.0,
        },
        Instr::Powf(_, x, e) => Machine::Pow {
            x: *x,
            e: *e,
            reciprocal: false,
        },
        Instr::Fun(_, Function::Sqrt, x) => Machine::Sqrt {
            x: *x,
            reciprocal: false,
        },
        Instr::Fun(_, f, x) => Machine::Call(*f, *x),
        Instr::Assign(_, x) => Machine::Copy(*x),
    }
}

/// The sum or product `ins` computes over the kept value `first` (standing
/// for operands computed once per parameter set), if any, and `operands`.
pub fn split(p: &Program, ins: &Instr, first: Option<usize>, operands: &[Slot]) -> Machine {
    match ins {
        Instr::Add(..) => Machine::Sum(
            (first.map(Operand::Kept).into_iter())
                .chain(operands.iter().map(|&x| Operand::Slot(x)))
                .collect(),
        ),
        Instr::Mul(..) => product(p, first, operands),
        _ => unreachable!("only sums and products are split at leading operands"),
    }
}

/// A product of `first` (if any) and `factors`: factors −1 dropped, the
/// product negated when their number is odd, ±1 when nothing is left.
fn product(p: &Program, first: Option<usize>, factors: &[Slot]) -> Machine {
    let minus_one = |s: &Slot| matches!(s, Slot::Const(i) if p.consts[*i] == -1.0);
    let negate = factors.iter().filter(|s| minus_one(s)).count() % 2 == 1;
    let factors: Vec<Operand> = (first.map(Operand::Kept).into_iter())
        .chain(
            factors
                .iter()
                .filter(|s| !minus_one(s))
                .map(|&x| Operand::Slot(x)),
        )
        .collect();
    if factors.is_empty() {
        Machine::Number(if negate { -1.0 } else { 1.0 })
    } else {
        Machine::Product { factors, negate }
    }
}

/// Runs `p` on `inputs` with the arithmetic of its machine form, the
/// operations of the emitted code in its order with the same libm
/// functions: the reference evaluation the generator's own checks use.
pub fn run(p: &Program, inputs: &[f64]) -> Vec<f64> {
    use dalembert_runtime::libm;
    let mut temps: Vec<f64> = Vec::new();
    let mut outs = vec![0.0; p.outputs];
    let mut pairs: HashMap<usize, (f64, f64)> = HashMap::new();
    for (ins, m) in p.instrs.iter().zip(lower(p, |_| true)) {
        let get = |s: Slot| match s {
            Slot::Input(i) => inputs[i],
            Slot::Const(i) => p.consts[i],
            Slot::Temp(i) => temps[i],
            Slot::Out(i) => outs[i],
        };
        let operand = |o: &Operand| match *o {
            Operand::Slot(s) => get(s),
            Operand::Kept(_) => unreachable!("every instruction is computed"),
        };
        let fold = |xs: &[Operand], f: fn(f64, f64) -> f64| {
            (xs.iter().map(operand)).reduce(f).unwrap_or(0.0)
        };
        let over = |reciprocal: bool, x: f64| if reciprocal { 1.0 / x } else { x };
        let value = match m.expect("every instruction is computed") {
            Machine::Sum(terms) => fold(&terms, |a, b| a + b),
            Machine::Difference(a, b) => get(a) - get(b),
            Machine::Product { factors, negate } => {
                let product = fold(&factors, |a, b| a * b);
                if negate { -product } else { product }
            }
            Machine::Number(x) => x,
            Machine::Power { x, n, reciprocal } => {
                let x = get(x);
                over(reciprocal, (1..n).fold(x, |acc, _| acc * x))
            }
            Machine::Pow { x, e, reciprocal } => over(reciprocal, libm::pow(get(x), e)),
            Machine::Sqrt { x, reciprocal } => over(reciprocal, libm::sqrt(get(x))),
            Machine::Call(f, x) => f.libm()(get(x)),
            Machine::SinCos { x, pair, sin } => {
                let both = libm::sincos(get(x));
                pairs.insert(pair, both);
                if sin { both.0 } else { both.1 }
            }
            Machine::Half { pair, sin } => {
                let both = pairs[&pair];
                if sin { both.0 } else { both.1 }
            }
            Machine::Copy(x) => get(x),
        };
        match ins.dst() {
            Slot::Temp(i) => {
                if temps.len() <= i {
                    temps.resize(i + 1, 0.0);
                }
                temps[i] = value;
            }
            Slot::Out(i) => outs[i] = value,
            Slot::Input(_) | Slot::Const(_) => {
                unreachable!("instructions write temporaries and outputs")
            }
        }
    }
    outs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every decision in one place: −1 factors, powers by size and sign,
    /// ±½ powers, and sin/cos pairs only where both halves are computed.
    #[test]
    fn decisions() {
        let (x, y) = (Slot::Input(0), Slot::Input(1));
        let p = Program {
            inputs: 2,
            consts: vec![-1.0],
            instrs: vec![
                Instr::Mul(Slot::Out(0), vec![Slot::Const(0), x, Slot::Const(0), y]),
                Instr::Mul(Slot::Out(1), vec![Slot::Const(0)]),
                Instr::Pow(Slot::Out(2), x, -3),
                Instr::Pow(Slot::Out(3), x, 9),
                Instr::Powf(Slot::Out(4), x, -0.5),
                Instr::Fun(Slot::Out(5), Function::Cos, y),
                Instr::Fun(Slot::Out(6), Function::Sin, y),
            ],
            outputs: 7,
        };
        let all = lower(&p, |_| true);
        let slots = |s: &[Slot]| s.iter().map(|&s| Operand::Slot(s)).collect();
        assert_eq!(
            all,
            vec![
                Some(Machine::Product {
                    factors: slots(&[x, y]),
                    negate: false
                }),
                Some(Machine::Number(-1.0)),
                Some(Machine::Power {
                    x,
                    n: 3,
                    reciprocal: true
                }),
                Some(Machine::Pow {
                    x,
                    e: 9.0,
                    reciprocal: false
                }),
                Some(Machine::Sqrt {
                    x,
                    reciprocal: true
                }),
                Some(Machine::SinCos {
                    x: y,
                    pair: 0,
                    sin: false
                }),
                Some(Machine::Half { pair: 0, sin: true }),
            ]
        );
        // The cosine computed elsewhere (kept once per parameter set): the
        // sine is a call of its own.
        let some = lower(&p, |i| i != 5);
        assert_eq!(some[5], None);
        assert_eq!(some[6], Some(Machine::Call(Function::Sin, y)));
        // A product split after a kept value.
        let ins = &p.instrs[0];
        assert_eq!(
            split(&p, ins, Some(3), &[Slot::Const(0), y]),
            Machine::Product {
                factors: vec![Operand::Kept(3), Operand::Slot(y)],
                negate: true
            }
        );
    }
}
