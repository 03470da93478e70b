//! Forward-mode differentiation of a program: its tangent program computes
//! the outputs and their directional derivatives along a direction given as
//! extra inputs, one per differentiated input (a Jacobian–vector product).
//! Each instruction's derivative rule is here, once, and the functions'
//! are the language's (`ir/expr/derivative.rs`); the back ends run the
//! tangent program like any other, and a Jacobian is its columns.
//!
//! The cost is a small multiple of the program's: each instruction adds at
//! most a few for its tangent, and a value that does not depend on the
//! differentiated inputs has none (its tangent is known to be zero).

use std::collections::{HashMap, HashSet};

use super::{Function, Instr, Program, Slot, constant};
use crate::function::Algebra;

impl Program {
    /// The tangent program along the inputs `from..self.inputs`: its inputs
    /// are this program's followed by a direction, one input for each of
    /// those (in the same order); its outputs are this program's followed
    /// by their derivatives along the direction.
    ///
    /// Every value is written once (the program in static single
    /// assignment), so that a rule may read its operands and its result.
    pub fn tangent(&self, from: usize) -> Program {
        self.tangent_over(from..self.inputs)
    }

    /// The tangent program along the inputs `along` (a range of this
    /// program's inputs; the rest are held fixed): its inputs are this
    /// program's followed by a direction, one input for each of `along`
    /// (in the same order); its outputs are this program's followed by
    /// their derivatives along the direction. With `along` the parameters,
    /// the derivatives are by the parameters at a fixed state.
    pub fn tangent_over(&self, along: std::ops::Range<usize>) -> Program {
        assert!(
            along.end <= self.inputs,
            "a direction for each input differentiated"
        );
        let mut t = Tangent {
            consts: self.consts.clone(),
            instrs: Vec::new(),
            temps: 0,
            value: HashMap::new(),
            tangent: HashMap::new(),
            computed: HashMap::new(),
        };
        let directions = along.len();
        for (k, i) in along.enumerate() {
            let direction = Slot::Input(self.inputs + k);
            t.tangent.insert(Slot::Input(i), direction);
        }
        for ins in &self.instrs {
            t.instruction(ins);
        }
        let zero = constant(&mut t.consts, 0.0);
        for k in 0..self.outputs {
            let out = Slot::Out(k);
            let value = t.read(out);
            t.instrs.push(Instr::Assign(out, value));
            let derivative = t.tangent.get(&out).copied().unwrap_or(zero);
            t.instrs
                .push(Instr::Assign(Slot::Out(self.outputs + k), derivative));
        }
        Program {
            inputs: self.inputs + directions,
            consts: t.consts,
            instrs: t.instrs,
            outputs: 2 * self.outputs,
        }
    }
}

impl Program {
    /// The same program with `width` inputs: where a program was made over
    /// more inputs than its quantity takes (f(q) built over (q, v)), the
    /// tangent's direction then follows the inputs it does take.
    ///
    /// # Panics
    /// If the program reads an input at or past `width`.
    pub fn with_inputs(&self, width: usize) -> Program {
        let past = |s: &Slot| matches!(s, Slot::Input(k) if *k >= width);
        assert!(
            !self.instrs.iter().any(|i| i.sources().iter().any(past)),
            "the program reads an input past {width}"
        );
        Program {
            inputs: width,
            ..self.clone()
        }
    }
}

impl Program {
    /// The variational system of a tangent of q̈ (this program: inputs
    /// `params` parameters, then q, v, δq, δv, each `n` long; outputs q̈ then
    /// δq̈) as a second-order system of dimension 2n: inputs the parameters,
    /// then (q, δq) as its coordinates and (v, δv) as its velocities;
    /// outputs δq̈ alone, with the work only q̈ needed left out. Its Taylor
    /// transform ([`Program::taylor`] with `2n` coordinates) is the series
    /// of a column of the variational flow along the motion's.
    pub fn variational(&self, params: usize, n: usize) -> Program {
        assert!(
            self.inputs == params + 4 * n && self.outputs == 2 * n,
            "a tangent of q̈ over (q, v) of length {n}"
        );
        // Inputs (q, v, δq, δv) → (q, δq, v, δv): v and δq trade places.
        let input = |i: usize| match i.checked_sub(params) {
            Some(k) if (n..2 * n).contains(&k) => params + k + n,
            Some(k) if (2 * n..3 * n).contains(&k) => params + k - n,
            _ => i,
        };
        let slot = |s: Slot| match s {
            Slot::Input(i) => Slot::Input(input(i)),
            Slot::Out(k) if k >= n => Slot::Out(k - n),
            // q̈'s outputs: written by the instructions left out below.
            other => other,
        };
        let writes_q_dd = |ins: &Instr| matches!(ins.dst(), Slot::Out(k) if k < n);
        let kept: Vec<Instr> = (self.instrs.iter())
            .filter(|ins| !writes_q_dd(ins))
            .map(|ins| ins.map_slots(slot))
            .collect();
        Program {
            inputs: self.inputs,
            consts: self.consts.clone(),
            instrs: live(kept),
            outputs: n,
        }
    }
}

/// The instructions whose values reach an output, in order (a slot written
/// again is live from its last write before a read).
fn live(instrs: Vec<Instr>) -> Vec<Instr> {
    let mut needed: HashSet<Slot> = HashSet::new();
    let mut keep = vec![false; instrs.len()];
    for (i, ins) in instrs.iter().enumerate().rev() {
        let dst = ins.dst();
        if matches!(dst, Slot::Out(_)) || needed.remove(&dst) {
            keep[i] = true;
            needed.extend(ins.sources().iter().copied());
        }
    }
    (instrs.into_iter().zip(keep))
        .filter_map(|(ins, k)| k.then_some(ins))
        .collect()
}

/// The tangent program as it is built.
struct Tangent {
    consts: Vec<f64>,
    instrs: Vec<Instr>,
    temps: usize,
    /// The temporary now holding each slot the program wrote.
    value: HashMap<Slot, Slot>,
    /// Each value's tangent where it is not zero, by the slot of the
    /// original program (as last written).
    tangent: HashMap<Slot, Slot>,
    /// Every instruction written so far, by what it computes (its text
    /// with the destination left out), so that a value the program or
    /// another rule already computes (cos x for sin x's tangent, x·dx
    /// twice for x·x's) is computed once.
    computed: HashMap<String, Slot>,
}

impl Tangent {
    fn fresh(&mut self) -> Slot {
        self.temps += 1;
        Slot::Temp(self.temps - 1)
    }

    /// Where the value of the original program's slot `s` is now.
    fn read(&self, s: Slot) -> Slot {
        self.value.get(&s).copied().unwrap_or(s)
    }

    /// `ins` written to a fresh temporary, or the temporary that already
    /// holds its value.
    fn emit(&mut self, ins: impl Fn(Slot) -> Instr) -> Slot {
        let key = format!("{:?}", ins(Slot::Temp(usize::MAX)));
        if let Some(&done) = self.computed.get(&key) {
            return done;
        }
        let dst = self.fresh();
        self.instrs.push(ins(dst));
        self.computed.insert(key, dst);
        dst
    }

    /// Π factors (one factor: that slot).
    fn product(&mut self, factors: Vec<Slot>) -> Slot {
        match factors[..] {
            [one] => one,
            _ => self.emit(|d| Instr::Mul(d, factors.clone())),
        }
    }

    fn sum(&mut self, terms: Vec<Slot>) -> Slot {
        match terms[..] {
            [one] => one,
            _ => self.emit(|d| Instr::Add(d, terms.clone())),
        }
    }

    fn number(&mut self, x: f64) -> Slot {
        constant(&mut self.consts, x)
    }

    /// The original instruction on the current values, and its tangent.
    fn instruction(&mut self, ins: &Instr) {
        let dst = ins.dst();
        let sources: Vec<Slot> = ins.sources().to_vec();
        let value: Vec<Slot> = sources.iter().map(|&s| self.read(s)).collect();
        let dvalue: Vec<Option<Slot>> = sources
            .iter()
            .map(|s| self.tangent.get(s).copied())
            .collect();
        let result = match ins {
            Instr::Assign(..) => value[0],
            _ => self.emit(|d| rewrite(ins, d, &value)),
        };
        let derivative = if dvalue.iter().all(Option::is_none) {
            None
        } else {
            Some(self.rule(ins, result, &value, &dvalue))
        };
        self.value.insert(dst, result);
        match derivative {
            Some(d) => self.tangent.insert(dst, d),
            None => self.tangent.remove(&dst),
        };
    }

    /// The tangent of `ins`, whose result is in `y`, from its operands `x`
    /// and their tangents `dx` (at least one not zero).
    fn rule(&mut self, ins: &Instr, y: Slot, x: &[Slot], dx: &[Option<Slot>]) -> Slot {
        let x0 = x[0];
        let dx0 = || dx[0].expect("a one-operand instruction with a tangent");
        match ins {
            Instr::Add(..) => self.sum(dx.iter().flatten().copied().collect()),
            Instr::Sub(..) => match (dx[0], dx[1]) {
                (Some(a), Some(b)) => self.emit(|d| Instr::Sub(d, [a, b])),
                (Some(a), None) => a,
                (None, Some(b)) => {
                    let minus = self.number(-1.0);
                    self.product(vec![minus, b])
                }
                (None, None) => unreachable!("a tangent is not zero"),
            },
            // d(Π xᵢ) = Σᵢ (Π_{j≠i} xⱼ) dxᵢ, a factor repeated k times
            // taken once, times k.
            Instr::Mul(..) => {
                let mut terms = Vec::new();
                for (i, di) in dx.iter().enumerate() {
                    let Some(di) = *di else { continue };
                    if x[..i].contains(&x[i]) {
                        continue;
                    }
                    let k = x.iter().filter(|&&s| s == x[i]).count();
                    let mut factors: Vec<Slot> = x.to_vec();
                    factors.remove(i);
                    if k > 1 {
                        factors.insert(0, self.number(k as f64));
                    }
                    factors.push(di);
                    terms.push(self.product(factors));
                }
                self.sum(terms)
            }
            // d(xⁿ) = n xⁿ⁻¹ dx; d(1/x) = −(1/x)² dx, without a division.
            Instr::Pow(_, _, n) => {
                let n = *n;
                let coefficient = self.number(n as f64);
                match n - 1 {
                    -2 => self.product(vec![coefficient, y, y, dx0()]),
                    0 => self.product(vec![coefficient, dx0()]),
                    1 => self.product(vec![coefficient, x0, dx0()]),
                    m => {
                        let power = self.emit(|d| Instr::Pow(d, x0, m));
                        self.product(vec![coefficient, power, dx0()])
                    }
                }
            }
            // d(x^a) = a x^(a−1) dx; for a = ½, dx / (2√x).
            Instr::Powf(_, _, a) => {
                let coefficient = self.number(*a);
                if *a == 0.5 {
                    let over = self.emit(|d| Instr::Pow(d, y, -1));
                    self.product(vec![coefficient, over, dx0()])
                } else {
                    let a1 = a - 1.0;
                    let power = self.emit(|d| Instr::Powf(d, x0, a1));
                    self.product(vec![coefficient, power, dx0()])
                }
            }
            // The language's rule (`function`), times dx.
            Instr::Fun(_, f, _) => {
                let mut factors = f.derivative(self, x0, y);
                factors.push(dx0());
                self.product(factors)
            }
            Instr::Assign(..) => dx0(),
        }
    }
}

/// Program values as the derivative rules' algebra: each operation an
/// instruction (computed once, [`Tangent::emit`]).
impl Algebra for Tangent {
    type E = Slot;
    fn number(&mut self, num: i64, den: i64) -> Slot {
        self.number(num as f64 / den as f64)
    }
    fn add(&mut self, terms: Vec<Slot>) -> Slot {
        self.sum(terms)
    }
    fn sub(&mut self, a: Slot, b: Slot) -> Slot {
        self.emit(|d| Instr::Sub(d, [a, b]))
    }
    fn mul(&mut self, factors: Vec<Slot>) -> Slot {
        self.product(factors)
    }
    fn pow(&mut self, x: Slot, num: i64, den: i64) -> Slot {
        if den == 1 {
            self.emit(|d| Instr::Pow(d, x, num))
        } else {
            self.emit(|d| Instr::Powf(d, x, num as f64 / den as f64))
        }
    }
    fn call(&mut self, f: Function, x: Slot) -> Slot {
        self.emit(|d| Instr::Fun(d, f, x))
    }
}

/// `ins` writing `dst` from the operands `x` (its sources, in order).
fn rewrite(ins: &Instr, dst: Slot, x: &[Slot]) -> Instr {
    match ins {
        Instr::Add(..) => Instr::Add(dst, x.to_vec()),
        Instr::Sub(..) => Instr::Sub(dst, [x[0], x[1]]),
        Instr::Mul(..) => Instr::Mul(dst, x.to_vec()),
        Instr::Pow(_, _, n) => Instr::Pow(dst, x[0], *n),
        Instr::Powf(_, _, a) => Instr::Powf(dst, x[0], *a),
        Instr::Fun(_, f, _) => Instr::Fun(dst, *f, x[0]),
        Instr::Assign(..) => Instr::Assign(dst, x[0]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A program over (p, x, y) that uses every instruction and function,
    /// writes a temporary twice and reads a value it overwrites.
    fn sample() -> Program {
        let (p, x, y) = (Slot::Input(0), Slot::Input(1), Slot::Input(2));
        let t = Slot::Temp;
        Program {
            inputs: 3,
            consts: vec![2.0, 1.5],
            instrs: vec![
                Instr::Mul(t(0), vec![p, x, y, Slot::Const(0)]),
                Instr::Fun(t(1), Function::Sin, t(0)),
                Instr::Fun(t(2), Function::Cos, x),
                Instr::Add(t(3), vec![t(1), t(2), p]),
                Instr::Pow(t(0), t(3), 3),
                Instr::Pow(t(4), y, -2),
                Instr::Sub(t(5), [p, t(4)]),
                Instr::Powf(t(6), y, 1.5),
                Instr::Powf(t(7), y, 0.5),
                Instr::Fun(t(8), Function::Exp, t(6)),
                Instr::Fun(t(9), Function::Log, y),
                Instr::Fun(t(10), Function::Sqrt, t(8)),
                Instr::Mul(t(0), vec![t(0), t(5)]),
                Instr::Assign(Slot::Out(0), t(0)),
                Instr::Add(Slot::Out(1), vec![t(7), t(9), t(10)]),
                Instr::Pow(Slot::Out(2), p, 2),
                Instr::Sub(Slot::Out(3), [Slot::Const(1), x]),
            ],
            outputs: 4,
        }
    }

    /// The tangent against central differences, in several directions
    /// and at several points; a function of the parameter alone has a
    /// zero tangent.
    #[test]
    fn tangent_matches_central_differences() {
        let p = sample();
        let t = p.tangent(1);
        assert_eq!((t.inputs, t.outputs), (5, 8));
        for (point, direction) in [
            ([0.7, 0.3, 1.2], [1.0, 0.0]),
            ([0.7, 0.3, 1.2], [0.0, 1.0]),
            ([-1.1, 2.0, 0.4], [0.6, -0.8]),
        ] {
            let mut inputs = point.to_vec();
            inputs.extend(direction);
            let out = t.eval(&inputs);
            assert_eq!(out[..4], p.eval(&point)[..], "the values themselves");
            let h = 1e-5;
            let at = |s: f64| {
                let mut z = point;
                z[1] += s * direction[0];
                z[2] += s * direction[1];
                p.eval(&z)
            };
            let (plus, minus) = (at(h), at(-h));
            for k in 0..4 {
                let fd = (plus[k] - minus[k]) / (2.0 * h);
                let got = out[4 + k];
                assert!(
                    (got - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "output {k}: tangent {got}, differences {fd}"
                );
            }
            assert_eq!(out[6], 0.0, "p² does not move with x and y");
        }
    }

    /// Along the parameter alone, at a fixed (x, y): against central
    /// differences in p; 1.5 − x does not move with p.
    #[test]
    fn tangent_over_the_parameter() {
        let p = sample();
        let t = p.tangent_over(0..1);
        assert_eq!((t.inputs, t.outputs), (4, 8));
        for point in [[0.7, 0.3, 1.2], [-1.1, 2.0, 0.4]] {
            let mut inputs = point.to_vec();
            inputs.push(1.0);
            let out = t.eval(&inputs);
            assert_eq!(out[..4], p.eval(&point)[..], "the values themselves");
            let h = 1e-5;
            let at = |s: f64| {
                let mut z = point;
                z[0] += s;
                p.eval(&z)
            };
            let (plus, minus) = (at(h), at(-h));
            for k in 0..4 {
                let fd = (plus[k] - minus[k]) / (2.0 * h);
                let got = out[4 + k];
                assert!(
                    (got - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "output {k}: tangent {got}, differences {fd}"
                );
            }
            assert_eq!(out[6], 2.0 * point[0], "d(p²)/dp");
            assert_eq!(out[7], 0.0, "1.5 − x does not move with p");
        }
    }

    /// The variational system of q̈ = (p sin(x) ẏ, x + ẋ) over (x, y): its
    /// inputs reordered to (p, x, y, δx, δy, ẋ, ẏ, δẋ, δẏ), its outputs
    /// the tangent's δq̈, and the sum x + ẋ, which only q̈ reads, left out.
    #[test]
    fn variational_system_of_a_tangent() {
        let (p, x, vx, vy) = (
            Slot::Input(0),
            Slot::Input(1),
            Slot::Input(3),
            Slot::Input(4),
        );
        let q_dd = Program {
            inputs: 5,
            consts: vec![],
            instrs: vec![
                Instr::Fun(Slot::Temp(0), Function::Sin, x),
                Instr::Mul(Slot::Out(0), vec![p, Slot::Temp(0), vy]),
                Instr::Add(Slot::Out(1), vec![x, vx]),
            ],
            outputs: 2,
        };
        let t = q_dd.tangent(1);
        let v = t.variational(1, 2);
        assert_eq!((v.inputs, v.outputs), (9, 2));
        let sums = |p: &Program| {
            (p.instrs.iter())
                .filter(|i| matches!(i, Instr::Add(_, s) if s.contains(&x)))
                .count()
        };
        assert_eq!((sums(&t), sums(&v)), (1, 0), "x + ẋ is not needed");
        let (pq, pv, dq, dv) = ([0.4, -1.3], [0.8, 2.1], [0.3, -0.5], [1.7, 0.2]);
        let tangent_inputs: Vec<f64> = [&[1.5][..], &pq, &pv, &dq, &dv].concat();
        let inputs: Vec<f64> = [&[1.5][..], &pq, &dq, &pv, &dv].concat();
        assert_eq!(v.eval(&inputs), t.eval(&tangent_inputs)[2..]);
    }
}
